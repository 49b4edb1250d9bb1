//! Molecular surfaces (`md_scene::surface`) against analytic spheres, scikit-image's marching
//! cubes on a protein, the exact density, and the reference ray tracer drawing the same mesh.

use glam::Vec3;
use std::collections::HashMap;
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::metrics::psnr;
use texmap_core::shade::{Lighting, Material};
use texmap_md_scene::surface::{
    MAX_VOXELS, MolMesh, SurfaceAtoms, SurfaceError, SurfaceOptions, draw_mesh,
};

use crate::common;

fn one_atom(c: Vec3, r: f32) -> SurfaceAtoms {
    let mut a = SurfaceAtoms::default();
    a.push(c, r, 0);
    a
}

/// 2XCJ chain A with ASE's radii, and scikit-image's areas and volumes (`data/gen_surface.py`).
fn protein() -> (SurfaceAtoms, serde_json::Value) {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/surface_reference.json"
    ))
    .unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut atoms = SurfaceAtoms::default();
    let centers = v["centers"].as_array().unwrap();
    for (c, r) in centers.iter().zip(v["radii"].as_array().unwrap()) {
        let c: Vec<f32> = c
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        atoms.push(
            Vec3::new(c[0], c[1], c[2]),
            r.as_f64().unwrap() as f32,
            (atoms.len() % 5) as u16,
        );
    }
    (atoms, v)
}

fn build(atoms: &SurfaceAtoms, spacing: f32) -> MolMesh {
    let o = SurfaceOptions {
        spacing,
        ..Default::default()
    };
    MolMesh::surface(atoms, &o).unwrap()
}

/// Every directed edge as often as its reverse: closed (no border), and wound one way
/// throughout. Returns how many edges are used more than once each way (surface nets join two
/// sheets that pass through one cell at its vertex: the mesh is closed, not always a manifold).
fn assert_closed_and_consistent(s: &MolMesh) -> usize {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &s.triangles {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &edges {
        assert_eq!(
            edges.get(&(b, a)),
            Some(&n),
            "edge {a}-{b} used {n} times, its twin not"
        );
    }
    edges.values().filter(|&&n| n > 1).count()
}

#[test]
fn an_isolated_atom_is_its_van_der_waals_sphere() {
    let (c, r) = (Vec3::new(1.0, -2.0, 3.5), 1.7);
    for spacing in [0.5, 0.25] {
        let s = build(&one_atom(c, r), spacing);
        assert!(s.positions.len() > 50);
        for (p, n) in s.positions.iter().zip(&s.normals) {
            let d = *p - c;
            assert!(
                (d.length() - r).abs() < 2e-5,
                "vertex at {} from the centre",
                d.length()
            );
            assert!((*n - d.normalize()).length() < 1e-4, "normal {n} at {d}");
        }
        assert_eq!(assert_closed_and_consistent(&s), 0);
        // Inscribed triangles: a little less area and volume than the sphere's, converging with
        // the spacing as the square of the edge length over the radius.
        let area = 4.0 * std::f64::consts::PI * (r as f64).powi(2);
        let volume = area * r as f64 / 3.0;
        let bound = 0.6 * (spacing as f64 / r as f64).powi(2);
        let (ea, ev) = (1.0 - s.area() / area, 1.0 - s.volume() / volume);
        assert!(
            ea > 0.0 && ea < bound,
            "spacing {spacing}: area {:.4} of the sphere's",
            1.0 - ea
        );
        assert!(
            ev > 0.0 && ev < bound,
            "spacing {spacing}: volume {:.4}",
            1.0 - ev
        );
    }
}

#[test]
fn a_protein_surface_matches_scikit_images_marching_cubes() {
    let (atoms, v) = protein();
    let reference = v["reference"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["spacing"].as_f64() == Some(0.15))
        .unwrap();
    let (area, volume) = (
        reference["area"].as_f64().unwrap(),
        reference["volume"].as_f64().unwrap(),
    );
    for (spacing, tolerance) in [(0.5, 0.003), (0.3, 0.0012)] {
        let s = build(&atoms, spacing);
        let shared = assert_closed_and_consistent(&s);
        assert!(
            shared * 1000 < s.triangles.len(),
            "{shared} edges shared by four triangles"
        );
        let (ea, ev) = (s.area() / area - 1.0, s.volume() / volume - 1.0);
        eprintln!(
            "spacing {spacing}: {} triangles, area {:.2} ({ea:+.5}), volume {:.2} ({ev:+.5})",
            s.triangles.len(),
            s.area(),
            s.volume()
        );
        assert!(ea.abs() < tolerance, "area {} against {area}", s.area());
        assert!(
            ev.abs() < tolerance,
            "volume {} against {volume}",
            s.volume()
        );
    }
}

#[test]
fn vertices_lie_on_the_exact_isosurface_with_its_normals() {
    let (atoms, _) = protein();
    let s = build(&atoms, 0.5);
    let k = (2.0 * 2f64.ln()).sqrt();
    // The density without a cut-off, in f64, brute force over every atom.
    let rho = |p: Vec3| -> (f64, glam::DVec3) {
        let mut sum = (0.0, glam::DVec3::ZERO);
        for (c, &r) in atoms.centers.iter().zip(&atoms.radii) {
            let sigma = r as f64 / k;
            let d = (p - *c).as_dvec3();
            let w = (-d.length_squared() / (2.0 * sigma * sigma)).exp();
            sum.0 += w;
            sum.1 -= d * (w / (sigma * sigma));
        }
        sum
    };
    let (mut worst, mut worst_normal): (f64, f64) = (0.0, 0.0);
    for (p, n) in s.positions.iter().zip(&s.normals) {
        let (value, grad) = rho(*p);
        worst = worst.max((value - 0.5).abs());
        worst_normal = worst_normal.max((n.as_dvec3() - (-grad).normalize()).length());
    }
    eprintln!("density within {worst:.2e} of the isovalue, normals within {worst_normal:.2e}");
    assert!(worst_normal < 1e-3, "normals {worst_normal} off");
    // What is left is the cut-off (each Gaussian below 1e-6 of its peak is dropped) and f32.
    assert!(worst < 1e-4, "density {worst} off the isovalue");
}

#[test]
fn the_surface_is_the_same_for_any_thread_count() {
    let (atoms, _) = protein();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| build(&atoms, 0.4))
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn bad_options_are_errors_and_a_huge_box_is_sampled_coarser() {
    let atoms = one_atom(Vec3::ZERO, 1.5);
    for (spacing, radius_scale, isovalue) in [(0.0, 1.0, 0.5), (0.5, -1.0, 0.5), (0.5, 1.0, 1.0)] {
        let o = SurfaceOptions {
            spacing,
            radius_scale,
            isovalue,
        };
        let e = MolMesh::surface(&atoms, &o).unwrap_err();
        assert!(matches!(e, SurfaceError::BadOption { .. }), "{e}");
    }
    // Two atoms 2 km apart at 0.1 Å would need 10^21 samples: the spacing grows instead.
    let mut far = one_atom(Vec3::ZERO, 1.5);
    far.push(Vec3::new(2e4, 2e4, 2e4), 1.5, 0);
    let s = build(&far, 0.1);
    let side = 2e4 / s.spacing as f64;
    assert!(side.powi(3) <= MAX_VOXELS as f64, "spacing {}", s.spacing);
    assert!(s.spacing > 60.0);
    // Atoms at the ends of the f32 range: still bounded, still one surface per drawable atom.
    let mut extreme = one_atom(Vec3::splat(-3e38), 1.5);
    extreme.push(Vec3::splat(3e38), 1.5, 0);
    extreme.push(Vec3::ZERO, 1e38, 0);
    let s = build(&extreme, 0.5);
    assert!(s.spacing.is_finite() && s.positions.iter().all(|p| p.is_finite()));
    // Atoms it cannot draw are left out, and none at all is an empty surface.
    let mut bad = SurfaceAtoms::default();
    bad.push(Vec3::NAN, 1.0, 0);
    bad.push(Vec3::ZERO, 0.0, 0);
    assert!(build(&bad, 0.5).triangles.is_empty());
}

#[test]
fn the_drawn_surface_matches_the_ray_traced_mesh() {
    let (atoms, _) = protein();
    let s = build(&atoms, 0.5);
    let centre = atoms.centers.iter().copied().sum::<Vec3>() / atoms.len() as f32;
    let cam = Camera::perspective_look_at(
        centre + Vec3::new(30.0, 20.0, 60.0),
        centre,
        Vec3::Y,
        45.0,
        400,
        300,
    )
    .unwrap();
    let lighting = Lighting::default_for(&cam);
    let materials: Vec<Material> = (0..5)
        .map(|k| Material::plastic(Vec3::new(0.2 + 0.15 * k as f32, 0.5, 0.9 - 0.15 * k as f32)))
        .collect();
    let bg = [10, 20, 30, 255];
    let mut drawn = Frame::new(400, 300, bg);
    let n = draw_mesh(&s, &materials, &cam, &lighting, 1.0, &mut drawn).unwrap();
    assert!(n > 10_000);
    // The reference: the same mesh traced.
    let reference = common::traced(&s, &materials, &cam, lighting, 1, bg);
    let db = psnr(&drawn, &reference).unwrap();
    let covered = (0..drawn.len()).filter(|&i| drawn.covered(i)).count();
    let agree = (0..drawn.len())
        .filter(|&i| drawn.covered(i) == reference.covered(i))
        .count();
    eprintln!("PSNR {db:.2} dB, {covered} pixels, silhouettes agree on {agree}");
    assert!(db > 40.0, "PSNR {db}");
    assert!(drawn.len() - agree < drawn.len() / 500);
    // Drawn over a nearer frame, the surface hides nothing in front of it.
    let mut front = Frame::new(400, 300, bg);
    front.depth.iter_mut().for_each(|d| *d = 1.0);
    draw_mesh(&s, &materials, &cam, &lighting, 1.0, &mut front).unwrap();
    assert!(front.color.iter().all(|&c| c == bg));
}

/// Two equal atoms of different colours: the surface's colour boundary is the plane midway
/// between them (where both contribute equally). Triangles whose vertices differ are cut where
/// their edges cross it, so the area drawn in the wrong colour (measured on a barycentric grid
/// of 55 points per triangle) is 1.6 % of the area within 0.5 Å of the plane, where whole
/// triangles coloured by the majority of their vertices left 9.5 %.
#[test]
fn a_colour_boundary_runs_through_triangles_not_along_their_edges() {
    let mut atoms = SurfaceAtoms::default();
    atoms.push(Vec3::new(-1.2, 0.3, 0.1), 1.7, 0);
    atoms.push(Vec3::new(1.2, 0.3, 0.1), 1.7, 1);
    let s = MolMesh::surface(&atoms, &SurfaceOptions::default()).unwrap();
    let (mut wrong, mut total, mut band) = (0.0f64, 0.0f64, 0.0f64);
    for (t, &k) in s.triangles.iter().zip(&s.kinds) {
        let p = t.map(|i| s.positions[i as usize]);
        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length() as f64;
        total += area;
        let n = 9;
        let mut bad = 0;
        let mut count = 0;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                let q = p[0] + (p[1] - p[0]) * u + (p[2] - p[0]) * v;
                bad += ((q.x > 0.0) != (k == 1)) as u32;
                count += 1;
            }
        }
        wrong += area * bad as f64 / count as f64;
        if p.iter().any(|q| q.x.abs() < 0.5) {
            band += area;
        }
    }
    eprintln!(
        "wrong colour: {wrong:.4} Å² of {total:.1} Å² ({:.2} % of the 0.5 Å band's {band:.2} Å²)",
        100.0 * wrong / band
    );
    assert!(wrong < 0.03 * band, "{wrong} of the band's {band}");
}
