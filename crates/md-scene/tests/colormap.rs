//! The colour maps against matplotlib: `tests/data/colormaps_matplotlib.json` holds each map's
//! colour at t = i/255, i = 0..=255, as matplotlib 3.11 gives it in 8-bit sRGB codes
//! (`tests/data/gen_colormaps.py`). Every channel of ours, rounded to a code, must be within
//! [`TOLERANCE`] codes of matplotlib's.

use texmap_md_scene::Colormap;

/// Largest allowed difference per channel, in 8-bit codes: two codes are below what the eye
/// tells apart in a smooth gradient, and the fit stays within one (see `colormap.rs`).
const TOLERANCE: i32 = 2;

const JSON: &str = include_str!("data/colormaps_matplotlib.json");

/// The 256 colours of `name` in the JSON. The file is the generator's own fixed layout, one
/// line per map: `"name": [[r, g, b], [r, g, b], ...]`; this reads that layout, not JSON at
/// large (the crate has no JSON dependency).
fn reference(name: &str) -> Vec<[i32; 3]> {
    let key = format!("\"{name}\": [");
    let line = JSON
        .lines()
        .find(|l| l.trim_start().starts_with(&key))
        .unwrap_or_else(|| panic!("{name} missing from colormaps_matplotlib.json"));
    let body = &line.trim_start()[key.len()..];
    let numbers: Vec<i32> = body
        .split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!(numbers.len(), 256 * 3, "{name}: expected 256 colours");
    numbers.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn codes(c: [f32; 3]) -> [i32; 3] {
    c.map(|v| (v * 255.0).round() as i32)
}

#[test]
fn every_map_is_within_two_codes_of_matplotlib() {
    for map in Colormap::ALL {
        let reference = reference(map.name());
        let mut worst = (0, 0, 0); // (difference, i, channel)
        for (i, want) in reference.iter().enumerate() {
            let got = codes(map.srgb(i as f32 / 255.0));
            for c in 0..3 {
                let d = (got[c] - want[c]).abs();
                if d > worst.0 {
                    worst = (d, i, c);
                }
            }
        }
        let (d, i, c) = worst;
        println!(
            "{}: worst {d} code(s) (t = {i}/255, channel {c})",
            map.name()
        );
        assert!(
            d <= TOLERANCE,
            "{}: at t = {i}/255 channel {c}: expected {}, got {}, tolerance {TOLERANCE}",
            map.name(),
            reference[i][c],
            codes(map.srgb(i as f32 / 255.0))[c],
        );
    }
}

#[test]
fn the_reference_covers_every_map() {
    for map in Colormap::ALL {
        assert_eq!(reference(map.name()).len(), 256);
    }
}

#[test]
fn values_outside_the_range_clamp() {
    for map in Colormap::ALL {
        for t in [-0.001, -1.0, -1e30, f32::NEG_INFINITY] {
            assert_eq!(map.srgb(t), map.srgb(0.0), "{} at t = {t}", map.name());
        }
        for t in [1.001, 2.0, 1e30, f32::INFINITY] {
            assert_eq!(map.srgb(t), map.srgb(1.0), "{} at t = {t}", map.name());
        }
        assert_eq!(map.srgb(f32::NAN), map.srgb(0.0), "{} at NaN", map.name());
    }
}

#[test]
fn endpoints_are_matplotlibs() {
    for map in Colormap::ALL {
        let reference = reference(map.name());
        for (t, want) in [(0.0, reference[0]), (1.0, reference[255])] {
            let got = codes(map.srgb(t));
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() <= 1,
                    "{} at t = {t}: expected {want:?}, got {got:?}, tolerance 1",
                    map.name()
                );
            }
        }
    }
    // Gray is exact: black and white.
    assert_eq!(Colormap::Gray.srgb(0.0), [0.0; 3]);
    assert_eq!(Colormap::Gray.srgb(1.0), [1.0; 3]);
}

#[test]
fn every_channel_stays_in_the_unit_range() {
    for map in Colormap::ALL {
        for i in 0..=4096 {
            let t = i as f32 / 4096.0;
            let c = map.srgb(t);
            assert!(
                c.iter().all(|v| (0.0..=1.0).contains(v)),
                "{} at t = {t}: {c:?}",
                map.name()
            );
        }
    }
}

#[test]
fn names_are_matplotlibs_and_case_insensitive() {
    let names: Vec<&str> = Colormap::ALL.iter().map(|m| m.name()).collect();
    assert_eq!(names, ["viridis", "plasma", "coolwarm", "turbo", "gray"]);
    assert_eq!(Colormap::from_name("Viridis"), Some(Colormap::Viridis));
    assert_eq!(Colormap::from_name("COOLWARM"), Some(Colormap::Coolwarm));
    assert_eq!(Colormap::from_name("grey"), None);
}

/// Colour coding end to end: the B-factors of the wwPDB's 3JQH (md-io's reader, checked against
/// gemmi there) through `ColorBy::Scalar` with viridis give every atom the material matplotlib's
/// viridis gives its B-factor over the structure's range, at the quantised t of
/// `SCALAR_LEVELS` steps, within the fit's tolerance plus one code for the sRGB round trip.
#[test]
fn b_factors_take_matplotlib_viridis_colours_through_the_scene_builder() {
    use texmap_md_io::{Frame, Trajectory};
    use texmap_md_scene::{
        ColorBy, SCALAR_LEVELS, ScalarColor, ScalarSource, SceneBuilder, SphereScene, StyleOptions,
    };
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-io/tests/data/3jqh.cif");
    let mut traj = Trajectory::open(path).unwrap();
    let mut frame = Frame::new();
    assert!(traj.read_next(&mut frame).unwrap());
    let b: Vec<f32> = frame.property("bfactor").unwrap().to_vec();
    let options = StyleOptions {
        color_by: ColorBy::Scalar,
        scalar: ScalarColor {
            source: ScalarSource::Property("bfactor".into()),
            map: Colormap::Viridis,
            range: None,
        },
        ..StyleOptions::default()
    };
    let mut builder = SceneBuilder::new(&options).unwrap();
    let mut scene = SphereScene::default();
    builder.build(&mut frame, &mut scene);
    let lo = b.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = b.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert_eq!(builder.scalar().range, Some((lo, hi)));
    let table = reference("viridis");
    let steps = (SCALAR_LEVELS - 1) as f64;
    let mut distinct = std::collections::HashSet::new();
    for (i, v) in b.iter().enumerate() {
        let t = ((*v - lo) / (hi - lo)) as f64;
        let x = (t * steps).round() / steps * 255.0;
        let (k, f) = (x.floor() as usize, x - x.floor());
        let want: Vec<f64> = (0..3)
            .map(|c| {
                let next = table[(k + 1).min(255)][c] as f64;
                table[k][c] as f64 * (1.0 - f) + next * f
            })
            .collect();
        let m = scene.materials[scene.kinds[i] as usize].base_color;
        let got = [m.x, m.y, m.z].map(|c| texmap_core::color::linear_to_srgb8_exact(c) as f64);
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= (TOLERANCE + 1) as f64,
                "atom {i} (B = {v}) channel {c}: matplotlib {}, ours {}",
                want[c],
                got[c]
            );
        }
        distinct.insert(scene.kinds[i]);
    }
    assert!(distinct.len() > 20, "{} colours", distinct.len());
}
