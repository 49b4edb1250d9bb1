//! A real SRTM tile, `N44W072.hgt` (3 arc-seconds, 1201², the White Mountains of New Hampshire with
//! Mount Washington), from tkrajina/srtm.py's test files; SRTM heights are public domain
//! (NASA/USGS). Our reader is compared with GDAL's SRTMHGT driver (`tests/data/srtm_facts.sh`: its
//! georeference, statistics over all 1.44 M samples and 260 sample values), its spacing in metres
//! with the WGS 84 ellipsoid's radii of curvature, and its meshes with every sample by brute force.
//! Viewsheds from its summit and valleys are compared with `gdal_viewshed`'s cell by cell
//! (`tests/data/viewshed/gen.sh`).

use std::path::PathBuf;

use texmap_terrain::dem::{CrsKind, ReadOptions, read_dem};
use texmap_terrain::rtin::{ErrorMap, extract, pad_to_rtin};

use crate::common;
use common::true_error;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn tile() -> texmap_terrain::dem::Grid {
    read_dem(data("N44W072.hgt"), &ReadOptions::default()).unwrap()
}

#[test]
fn the_tile_reads_as_gdal_reads_it() {
    let g = tile();
    assert_eq!((g.width(), g.height()), (1201, 1201));
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("N44W072.gdalinfo.json")).unwrap())
            .unwrap();
    // GDAL's geoTransform gives the corner of pixel (0, 0); SRTM samples are points, so the
    // centre of sample (0, 0) is half a pixel in from it.
    let t: Vec<f64> = info["geoTransform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let r = g.georef();
    assert_eq!(r.crs, CrsKind::Geographic);
    assert_eq!(r.epsg, Some(4326));
    assert!((r.dx - t[1]).abs() < 1e-12 && (r.dy - t[5]).abs() < 1e-12);
    assert!(
        (r.origin_x - (t[0] + 0.5 * t[1])).abs() < 1e-9,
        "{r:?} vs {t:?}"
    );
    assert!(
        (r.origin_y - (t[3] + 0.5 * t[5])).abs() < 1e-9,
        "{r:?} vs {t:?}"
    );

    let samples = std::fs::read_to_string(data("N44W072.gdal_samples.txt")).unwrap();
    let mut n = 0;
    for line in samples.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let (col, row) = (v[0] as u32, v[1] as u32);
        assert_eq!(g.at(col, row) as f64, v[2], "sample ({col}, {row})");
        n += 1;
    }
    assert_eq!(n, 260);

    // Statistics over every sample, against GDAL's.
    let meta = &info["bands"][0]["metadata"][""];
    let stat = |k: &str| meta[k].as_str().unwrap().parse::<f64>().unwrap();
    assert_eq!(g.nodata_count(), 0);
    assert_eq!(stat("STATISTICS_VALID_PERCENT"), 100.0);
    let (lo, hi) = g.height_range();
    assert_eq!(
        (lo as f64, hi as f64),
        (stat("STATISTICS_MINIMUM"), stat("STATISTICS_MAXIMUM"))
    );
    let mean = g.heights().iter().map(|&h| h as f64).sum::<f64>() / g.heights().len() as f64;
    assert!((mean - stat("STATISTICS_MEAN")).abs() < 1e-6, "{mean}");
    // Mount Washington, 1,917 m, is the tile's summit (the 3″ grid misses its top by a few metres).
    assert!((1_880.0..=1_917.0).contains(&hi), "{hi}");
}

#[test]
fn its_spacing_in_metres_follows_the_wgs84_ellipsoid() {
    let g = tile();
    let (east, north) = g.georef().spacing_metres(g.height());
    // Radii of curvature of the WGS 84 ellipsoid at the tile's centre latitude (44.5° N):
    // meridian M = a(1 − e²)/(1 − e² sin²φ)^{3/2}, prime vertical N = a/(1 − e² sin²φ)^{1/2}.
    let (a, f) = (6_378_137.0f64, 1.0 / 298.257_223_563);
    let e2 = f * (2.0 - f);
    let phi = 44.5f64.to_radians();
    let w = 1.0 - e2 * phi.sin().powi(2);
    let m = a * (1.0 - e2) / w.powf(1.5);
    let nrad = a / w.sqrt();
    let step = (1.0f64 / 1200.0).to_radians();
    let (want_e, want_n) = (nrad * phi.cos() * step, m * step);
    assert!((east / want_e - 1.0).abs() < 2e-4, "{east} vs {want_e}");
    assert!((north / want_n - 1.0).abs() < 2e-4, "{north} vs {want_n}");
}

#[test]
fn its_meshes_stay_within_their_error_bound_on_every_sample() {
    let g = tile();
    let (padded, n) = pad_to_rtin(g.heights(), g.width(), g.height());
    assert_eq!(n, 2049);
    let map = ErrorMap::new(&padded, n);
    let mut last = usize::MAX;
    for max_error in [2.0f32, 10.0, 30.0] {
        let mesh = extract(&map, &padded, 0, 0, n - 1, max_error, 1);
        let e = true_error(&padded, n, (1201, 1201), &mesh.vertices, &mesh.triangles);
        assert!(e <= max_error + 1e-3, "{max_error} m: true error {e} m");
        assert!(mesh.triangles.len() < last);
        last = mesh.triangles.len();
        eprintln!(
            "N44W072 RTIN, {max_error} m: {} triangles, true error {e:.2} m",
            mesh.triangles.len()
        );
    }
    let rtin10 = extract(&map, &padded, 0, 0, n - 1, 10.0, 1).triangles.len();
    let greedy = texmap_terrain::greedy::greedy(&g, 10.0).unwrap();
    let e = true_error(
        g.heights(),
        1201,
        (1201, 1201),
        &greedy.vertices,
        &greedy.triangles,
    );
    eprintln!(
        "N44W072 greedy, 10 m: {} triangles (RTIN {rtin10}), true error {e:.2} m",
        greedy.triangles.len()
    );
    assert!(e <= 10.0 + 1e-3, "greedy: true error {e} m");
    assert!(greedy.triangles.len() < rtin10);
}

/// Our hillshade (the texture of a database without a photo) against `gdaldem hillshade` with
/// its defaults (`tests/data/hillshade.sh`): the tile around Mount Washington warped by GDAL to
/// UTM 19N at 90 m, and GDAL's bytes `1 + 254·cos` (1 where the cosine is ≤ 0) for it.
#[test]
fn hillshade_matches_gdaldem() {
    use texmap_terrain::relief::{Hillshade, Light};
    let dem = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let gdal = read_dem(data("hillshade_gdal.asc"), &ReadOptions::default()).unwrap();
    assert_eq!((dem.width(), dem.height()), (64, 64));
    assert_eq!(dem.georef().crs, CrsKind::Projected);
    let hs = Hillshade::new(&dem, Light::default());
    let (mut worst, mut lit) = (0.0f64, 0);
    // The interior: at the edges GDAL's -compute_edges fills the missing neighbours its own way,
    // ours extrapolates them exactly on a plane (unit tests in relief.rs).
    for row in 1..63 {
        for col in 1..63 {
            let cos = hs.at(col, row).unwrap();
            let ours = if cos <= 0.0 { 1.0 } else { 1.0 + 254.0 * cos };
            worst = worst.max((ours - gdal.at(col, row) as f64).abs());
            lit += (cos > 0.0) as u32;
        }
    }
    // GDAL rounds to a byte: within half a unit (and a float's slack).
    assert!(worst <= 0.501, "differs from gdaldem by {worst}");
    assert!(lit > 3000, "{lit} of 3844 samples lit");
    eprintln!("hillshade vs gdaldem: max |diff| {worst:.3}");
}

// ---- Viewsheds against GDAL's gdal_viewshed (tests/data/viewshed/gen.sh, GDAL 3.6.2) ----------

mod viewshed_vs_gdal {
    use super::data;
    use std::process::Command;
    use texmap_terrain::dem::{Grid, ReadOptions, read_dem};
    use texmap_terrain::viewshed::{
        MaskValues, Method, Observer, Output, Seen, Viewshed, ViewshedOptions, viewshed,
    };

    fn vdata(name: &str) -> std::path::PathBuf {
        data("viewshed").join(name)
    }

    fn dem(name: &str) -> Grid {
        read_dem(vdata(name), &ReadOptions::default()).unwrap()
    }

    /// One committed gdal_viewshed run: its DEM, observer, options and output.
    struct Case {
        dem: &'static str,
        observer: Observer,
        opts: ViewshedOptions,
        gdal: &'static str,
    }

    fn cases() -> Vec<Case> {
        let summit = Observer::Map {
            x: 316135.0,
            y: 4904505.0,
        };
        let notch = Observer::Map {
            x: 320185.0,
            y: 4902795.0,
        };
        let d = ViewshedOptions::default();
        vec![
            Case {
                dem: "dem_utm.tif",
                observer: summit,
                opts: d,
                gdal: "summit.tif",
            },
            Case {
                dem: "dem_utm.tif",
                observer: summit,
                opts: ViewshedOptions {
                    curvature: 0.0,
                    target_height: 5.0,
                    ..d
                },
                gdal: "summit_cc0_tz5.tif",
            },
            Case {
                dem: "dem_utm.tif",
                observer: notch,
                opts: ViewshedOptions {
                    observer_height: 10.0,
                    max_distance: Some(5000.0),
                    ..d
                },
                gdal: "notch_oz10_md5000.tif",
            },
            Case {
                dem: "dem_utm.tif",
                observer: notch,
                opts: ViewshedOptions {
                    output: Output::Height,
                    max_distance: Some(2500.0),
                    ..d
                },
                gdal: "notch_ground_md2500.tif",
            },
            Case {
                dem: "dem_geo.tif",
                observer: Observer::Map {
                    x: -71.3366667,
                    y: 44.25,
                },
                opts: ViewshedOptions {
                    curvature: 0.0,
                    ..d
                },
                gdal: "geo_slope_cc0.tif",
            },
        ]
    }

    /// A differing cell: (column, row, ours, GDAL's).
    type Diff = (u32, u32, f32, f32);

    /// Cells where `ours` and GDAL's output `theirs` (read as a grid, possibly cut to a window of
    /// ours) agree, of all our cells. Masks compare bytes (our defaults are GDAL's); heights
    /// within 2.5e-4 m (GDAL writes float64, we float32: half an f32 ulp at 2048 m), our `NaN`
    /// beyond the range against GDAL's out-of-range value 0. Our cells outside GDAL's window must
    /// be out of range. Returns (agreeing, cells, up to 10 differences as (col, row, ours,
    /// theirs)).
    fn agreement(ours: &Viewshed, theirs: &Grid) -> (u64, u64, Vec<Diff>) {
        let (g, t) = (&ours.georef, theirs.georef());
        let ox = (t.origin_x - g.origin_x) / g.dx;
        let oy = (t.origin_y - g.origin_y) / g.dy;
        assert!(
            (ox - ox.round()).abs() < 1e-6 && (oy - oy.round()).abs() < 1e-6,
            "GDAL's window is not on our lattice: offset ({ox}, {oy})"
        );
        let (ox, oy) = (ox.round() as i64, oy.round() as i64);
        let mask = ours.mask(&MaskValues::default());
        let (mut agree, mut diffs) = (0u64, Vec::new());
        for row in 0..ours.height {
            for col in 0..ours.width {
                let i = (row * ours.width + col) as usize;
                let ours_v = match &ours.heights {
                    Some(h) => h[i],
                    None => mask[i] as f32,
                };
                let (tc, tr) = (col as i64 - ox, row as i64 - oy);
                let inside =
                    tc >= 0 && tr >= 0 && tc < theirs.width() as i64 && tr < theirs.height() as i64;
                let ok = if !inside {
                    ours.at(col, row) == Seen::OutOfRange
                } else {
                    let v = theirs.at(tc as u32, tr as u32);
                    if ours.heights.is_some() {
                        if ours_v.is_nan() {
                            v == 0.0
                        } else {
                            (ours_v - v).abs() <= 2.5e-4
                        }
                    } else {
                        ours_v == v
                    }
                };
                if ok {
                    agree += 1;
                } else if diffs.len() < 10 {
                    let v = if inside {
                        theirs.at(tc as u32, tr as u32)
                    } else {
                        f32::NAN
                    };
                    diffs.push((col, row, ours_v, v));
                }
            }
        }
        (agree, ours.width as u64 * ours.height as u64, diffs)
    }

    /// The `Gdal` method against every committed gdal_viewshed output: 100 % of the cells
    /// (the brief's floor is 99.9 %; the sweep does GDAL's float64 arithmetic in GDAL's order, so
    /// there are no ties to explain). `Wang` and `Exact` are printed beside it.
    #[test]
    fn the_gdal_method_matches_gdal_viewshed_cell_for_cell() {
        for case in cases() {
            let grid = dem(case.dem);
            let theirs = dem(case.gdal);
            let mut line = format!("{:<24}", case.gdal);
            for method in [Method::Gdal, Method::Wang, Method::Exact] {
                let opts = ViewshedOptions {
                    method,
                    ..case.opts
                };
                let ours = viewshed(&grid, case.observer, &opts).unwrap();
                let (agree, cells, diffs) = agreement(&ours, &theirs);
                let share = 100.0 * agree as f64 / cells as f64;
                line += &format!(" {}: {share:.3} % ({agree}/{cells})", method.name());
                if method == Method::Gdal {
                    assert_eq!(agree, cells, "{}: differences {diffs:?}", case.gdal);
                    let visible = ours.counts().visible;
                    assert!(visible > 50, "{}: {visible} visible cells", case.gdal);
                }
            }
            eprintln!("viewshed vs gdal_viewshed 3.6.2, {line}");
        }
    }

    /// `Wang` (the same sweep with the observer's neighbours seen as they are) against the exact
    /// sight lines, on every fixture's observer: at least 98.5 % of the cells agree (measured:
    /// 99.38–99.92 %, printed). The differences are the sweep's approximation (Wang 2000): a
    /// cell's horizon height is interpolated between the horizons of the two cells its sight line
    /// passes between, each the highest obstruction on *their own* sight lines, so it errs both
    /// ways (the counts of each are printed), in cells at the edges of shadows.
    #[test]
    fn the_sweep_agrees_with_exact_sight_lines() {
        for case in cases() {
            let grid = dem(case.dem);
            let run = |method| {
                let opts = ViewshedOptions {
                    method,
                    output: Output::Visibility,
                    ..case.opts
                };
                viewshed(&grid, case.observer, &opts).unwrap()
            };
            let (wang, exact) = (run(Method::Wang), run(Method::Exact));
            let agree = wang
                .seen
                .iter()
                .zip(&exact.seen)
                .filter(|(a, b)| a == b)
                .count();
            let share = agree as f64 / wang.seen.len() as f64;
            let only = |a: &Viewshed, b: &Viewshed| {
                a.seen
                    .iter()
                    .zip(&b.seen)
                    .filter(|&(x, y)| *x == Seen::Visible && *y == Seen::Invisible)
                    .count()
            };
            eprintln!(
                "wang vs exact, {}: {:.3} % of {} cells agree (the sweep alone sees {}, the \
                 sight lines alone {})",
                case.gdal,
                100.0 * share,
                wang.seen.len(),
                only(&wang, &exact),
                only(&exact, &wang)
            );
            assert!(share >= 0.985, "{}: {share}", case.gdal);
        }
    }

    /// Every method gives the same bytes on one thread as on four.
    #[test]
    fn viewsheds_are_the_same_for_any_thread_count() {
        let grid = dem("dem_utm.tif");
        let case = &cases()[3];
        for method in [Method::Gdal, Method::Wang, Method::Exact] {
            let opts = ViewshedOptions {
                method,
                max_distance: None,
                ..case.opts
            };
            let on = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| viewshed(&grid, case.observer, &opts).unwrap())
            };
            let (a, b) = (on(1), on(4));
            assert_eq!(a.seen, b.seen, "{method:?}");
            let bits = |v: &Viewshed| -> Vec<u32> {
                v.heights
                    .as_ref()
                    .unwrap()
                    .iter()
                    .map(|h| h.to_bits())
                    .collect()
            };
            assert_eq!(bits(&a), bits(&b), "{method:?}");
        }
    }

    /// gdal_viewshed run now on the fixture DEM from seeded observers with seeded options,
    /// against the `Gdal` method; SKIPPED without GDAL (CI has none).
    #[test]
    fn live_gdal_viewshed_agrees() {
        if Command::new("gdal_viewshed")
            .arg("--version")
            .output()
            .is_err()
        {
            eprintln!("SKIPPED live gdal_viewshed check: gdal_viewshed is not installed");
            return;
        }
        let grid = dem("dem_utm.tif");
        let dir = tempfile::tempdir().unwrap();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            // xorshift64*
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        };
        let g = *grid.georef();
        for k in 0..6 {
            let col = (next() * grid.width() as f64) as u32;
            let row = (next() * grid.height() as f64) as u32;
            let (x, y) = g.sample_xy(col as f64, row as f64);
            let opts = ViewshedOptions {
                observer_height: [2.0, 10.0, 50.0][k % 3],
                target_height: [0.0, 3.0][k % 2],
                max_distance: (k % 3 == 1).then_some(3000.0 + 5000.0 * next()),
                curvature: [0.85714, 0.0, 1.0][(k / 2) % 3],
                method: Method::Gdal,
                output: Output::Visibility,
            };
            let out = dir.path().join(format!("live{k}.tif"));
            let mut cmd = Command::new("gdal_viewshed");
            cmd.args(["-q", "-ox", &x.to_string(), "-oy", &y.to_string()])
                .args(["-oz", &opts.observer_height.to_string()])
                .args(["-tz", &opts.target_height.to_string()])
                .args(["-cc", &opts.curvature.to_string()]);
            if let Some(md) = opts.max_distance {
                cmd.args(["-md", &md.to_string()]);
            }
            let o = cmd.arg(vdata("dem_utm.tif")).arg(&out).output().unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let theirs = read_dem(&out, &ReadOptions::default()).unwrap();
            let ours = viewshed(&grid, Observer::Map { x, y }, &opts).unwrap();
            let (agree, cells, diffs) = agreement(&ours, &theirs);
            eprintln!(
                "live gdal_viewshed, observer ({col}, {row}) {opts:?}: {agree}/{cells} cells agree"
            );
            assert!(
                agree as f64 >= 0.999 * cells as f64,
                "({col}, {row}): {diffs:?}"
            );
        }
    }
}
