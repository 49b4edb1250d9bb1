//! Bonds drawn as cylinders against the workspace's reference ray tracer (texmap-reftrace), which
//! traces the same spheres and capped cylinders with the same shading at 1 spp: PSNR, depth error
//! and silhouette mismatch of ball-and-stick molecules at several fields of view and
//! orthographic, thick bonds with visible caps, a near plane cutting bonds, bonds behind the eye,
//! invalid bonds counted, and the same bytes for 1 and 2 threads.

use crate::common;

use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::glam::Vec3;
use texmap_core::metrics::{depth_error, psnr, silhouette_error};
use texmap_core::shade::Lighting;
use texmap_impostor::{Method, Options, Render, Renderer, SphereScene, render};
use texmap_reftrace::{RenderOptions, SceneBuilder, SurfaceMaterial};

/// A ball-and-stick molecule: a helical chain of `n` atoms (radius 0.4, bond length ≈ 1.5) with
/// a side atom (radius 0.3) on every third atom, some of them straight along ±z so that a few
/// bonds are seen nearly end-on; kinds cycle over the three test materials.
fn molecule(n: usize, bond_radius: f32) -> SphereScene {
    let mut s = SphereScene::new(common::materials());
    s.bond_radius = bond_radius;
    let mut prev = None;
    for i in 0..n {
        let a = i as f32 * 100f32.to_radians();
        let c = Vec3::new(
            1.0 * a.cos(),
            0.45 * i as f32 - 0.225 * n as f32,
            1.0 * a.sin(),
        );
        let id = s.len() as u32;
        s.push(c, 0.4, (i % 3) as u16);
        if let Some(p) = prev {
            s.bonds.push([p, id]);
        }
        prev = Some(id);
        if i % 3 == 1 {
            // Side atom: radially outward, or along z for every other one.
            let dir = if i % 2 == 0 {
                Vec3::new(a.cos(), 0.0, a.sin())
            } else {
                Vec3::Z
            };
            let sid = s.len() as u32;
            s.push(c + dir * 1.3, 0.3, ((i + 1) % 3) as u16);
            s.bonds.push([id, sid]);
        }
    }
    s
}

/// The reference: spheres, and each bond as two capped half-cylinders (atom i's material from
/// its centre to the midpoint, atom j's from there on), or as one cylinder when `halves` is off.
fn oracle(scene: &SphereScene, cam: &Camera, lighting: &Lighting, halves: bool) -> Frame {
    let mut b = SceneBuilder::new();
    for i in 0..scene.len() {
        b.add_sphere(scene.centers[i], scene.radii[i], scene.kinds[i] as u32);
    }
    for (k, &[i, j]) in scene.bonds.iter().enumerate() {
        let (i, j) = (i as usize, j as usize);
        let (pa, pb) = (scene.centers[i], scene.centers[j]);
        let r = scene.bond_radius_of(k);
        if halves {
            let mid = (pa + pb) * 0.5;
            b.add_cylinder(pa, mid, r, scene.kinds[i] as u32);
            b.add_cylinder(mid, pb, r, scene.kinds[j] as u32);
        } else {
            b.add_cylinder(pa, pb, r, scene.kinds[i] as u32);
        }
    }
    let s = b.build();
    let mats: Vec<SurfaceMaterial> = scene
        .materials
        .iter()
        .map(|&m| SurfaceMaterial::opaque(m))
        .collect();
    s.render(cam, &RenderOptions::new(*lighting, &mats))
        .expect("reference renders")
}

/// Accuracy of one render against the reference.
struct Acc {
    psnr: f64,
    depth_mean_rel: f64,
    depth_outliers: usize,
    silhouette_px: f64,
    mismatched: usize,
}

fn measure(out: &Frame, refr: &Frame, what: &str) -> Acc {
    let (mut lo, mut hi) = (f32::INFINITY, 0f32);
    for &d in refr.depth.iter().filter(|d| d.is_finite()) {
        lo = lo.min(d);
        hi = hi.max(d);
    }
    assert!(lo < hi, "{what}: reference covers too little");
    let range = (hi - lo) as f64;
    let d = depth_error(out, refr).unwrap();
    let s = silhouette_error(out, refr).unwrap();
    // Pixels where the depths differ by more than 1e-4 of the range: the front surface differs
    // (a pixel centre within f32 rounding of an atom/bond outline or of a cap rim).
    let tol = 1e-4 * range;
    let outliers = out
        .depth
        .iter()
        .zip(&refr.depth)
        .filter(|&(&a, &b)| a.is_finite() && b.is_finite() && (a as f64 - b as f64).abs() > tol)
        .count();
    Acc {
        psnr: psnr(out, refr).unwrap(),
        depth_mean_rel: d.mean_abs / range,
        depth_outliers: outliers,
        silhouette_px: s.mean_displacement_px,
        mismatched: s.mismatched_pixels,
    }
}

fn assert_no_nan(r: &Render, what: &str) {
    assert!(
        r.frame.depth.iter().all(|d| !d.is_nan() && *d > 0.0),
        "{what}: a depth is NaN or not positive"
    );
}

/// Render with and without bonds, compare the bonded render with the reference and check that
/// bonds made a difference (so the comparison can fail).
fn check(scene: &SphereScene, cam: &Camera, halves: bool, what: &str) -> Acc {
    let lighting = Lighting::default_for(cam);
    let opts = Options::new(Method::Raycast, lighting);
    let out = render(scene, cam, &opts);
    assert_no_nan(&out, what);
    assert_eq!(out.stats.bonds_skipped, 0, "{what}");
    assert!(out.stats.bonds_drawn > 0, "{what}: no bond drawn");
    let mut no_bonds = opts.clone();
    no_bonds.draw_bonds = false;
    let spheres_only = render(scene, cam, &no_bonds);
    assert_eq!(spheres_only.stats.bonds_drawn, 0);
    let refr = oracle(scene, cam, &lighting, halves);
    let with = measure(&out.frame, &refr, what);
    eprintln!(
        "{what}: PSNR {:.2} dB, mean depth error {:.2e} of the range, {} depth outliers, \
         silhouette {:.4} px ({} px)",
        with.psnr, with.depth_mean_rel, with.depth_outliers, with.silhouette_px, with.mismatched
    );
    if std::env::var_os("BONDS_DEBUG").is_some() {
        debug_diff(&out.frame, &refr, what);
    }
    let without = measure(&spheres_only.frame, &refr, what);
    assert!(
        without.mismatched > 50,
        "{what}: bonds should cover pixels the atoms do not ({} mismatched without bonds)",
        without.mismatched
    );
    assert!(
        with.psnr >= 45.0,
        "{what}: PSNR expected ≥ 45 dB, got {:.2} (spheres only: {:.2})",
        with.psnr,
        without.psnr
    );
    assert!(
        with.silhouette_px <= 0.05,
        "{what}: silhouette expected ≤ 0.05 px, got {} ({} px)",
        with.silhouette_px,
        with.mismatched
    );
    assert!(
        with.depth_mean_rel <= 1e-5,
        "{what}: mean depth error expected ≤ 1e-5 of the range, got {:e}",
        with.depth_mean_rel
    );
    assert!(
        with.depth_outliers <= 3,
        "{what}: expected ≤ 3 pixels off by more than 1e-4 of the depth range, got {}",
        with.depth_outliers
    );
    with
}

/// Print the pixels whose colour differs from the reference by more than 2 levels (debugging
/// aid, `BONDS_DEBUG=1`), and write both images as PPM into the temp directory.
fn debug_diff(out: &Frame, refr: &Frame, what: &str) {
    let w = out.width() as usize;
    let mut n = 0;
    for (i, (a, b)) in out.color.iter().zip(&refr.color).enumerate() {
        let d = (0..3)
            .map(|k| (a[k] as i32 - b[k] as i32).abs())
            .max()
            .unwrap();
        if d > 2 {
            if n < 12 {
                eprintln!(
                    "{what}: ({}, {}) got {:?} depth {} want {:?} depth {}",
                    i % w,
                    i / w,
                    a,
                    out.depth[i],
                    b,
                    refr.depth[i]
                );
            }
            n += 1;
        }
    }
    eprintln!("{what}: {n} pixels differ by more than 2 levels");
    for (i, (a, b)) in out.depth.iter().zip(&refr.depth).enumerate() {
        if a.is_finite() && b.is_finite() && (a - b).abs() > 1e-3 {
            eprintln!("{what}: depth ({}, {}) got {a} want {b}", i % w, i / w);
        }
    }
    for (f, tag) in [(out, "ours"), (refr, "ref")] {
        let mut bytes = format!("P6 {} {} 255\n", f.width(), f.height()).into_bytes();
        for c in &f.color {
            bytes.extend_from_slice(&c[..3]);
        }
        let name: String = what.chars().filter(|c| c.is_alphanumeric()).collect();
        let _ = std::fs::write(
            std::env::temp_dir().join(format!("bonds-{name}-{tag}.ppm")),
            bytes,
        );
    }
}

fn persp(eye: Vec3, fov: f32, w: u32, h: u32) -> Camera {
    Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, fov, w, h).unwrap()
}

#[test]
fn ball_and_stick_matches_reftrace_at_several_fovs() {
    let scene = molecule(24, 0.2);
    let dir = Vec3::new(0.5, 0.3, 1.0).normalize();
    for fov in [10.0f32, 40.0, 90.0, 150.0] {
        let dist = 6.5 / (fov.to_radians() * 0.5).tan() + 2.0;
        let cam = persp(dir * dist, fov, 240, 240);
        check(&scene, &cam, true, &format!("fov {fov}"));
    }
}

#[test]
fn ball_and_stick_matches_reftrace_orthographic() {
    let scene = molecule(24, 0.2);
    for eye in [Vec3::new(3.0, 2.0, 30.0), Vec3::new(30.0, 0.5, 0.2)] {
        let cam = Camera::orthographic_look_at(eye, Vec3::ZERO, Vec3::Y, 13.0, 200, 220).unwrap();
        check(&scene, &cam, true, &format!("ortho from {eye}"));
    }
}

#[test]
fn bonds_thicker_than_atoms_show_flat_caps_like_reftrace() {
    // Bond radius 0.5 > atom radii 0.4 and 0.3: the caps stick out of the atoms.
    let scene = molecule(12, 0.5);
    let cam = persp(Vec3::new(2.0, 3.0, 9.0), 50.0, 200, 200);
    check(&scene, &cam, true, "thick bonds, perspective");
    let cam = Camera::orthographic_look_at(
        Vec3::new(0.2, 0.1, 20.0),
        Vec3::ZERO,
        Vec3::Y,
        9.0,
        180,
        180,
    )
    .unwrap();
    check(
        &scene,
        &cam,
        true,
        "thick bonds, orthographic (end-on caps)",
    );
}

#[test]
fn near_plane_cutting_bonds_and_bonds_behind_the_eye() {
    // One material so that the reference can trace each bond as one solid cylinder (two halves
    // would show the inner cap at the midpoint once the near plane opens the bond).
    let mut scene = molecule(24, 0.25);
    scene.kinds.iter_mut().for_each(|k| *k = 1);
    // Eye inside the helix, near plane cutting atoms and bonds; some bonds run behind the eye.
    let cam = Camera::perspective_look_at(
        Vec3::new(0.1, 0.3, 0.05),
        Vec3::new(0.3, -5.0, 0.2),
        Vec3::Z,
        120.0,
        200,
        160,
    )
    .unwrap()
    .with_clip(0.6, f32::INFINITY)
    .unwrap();
    let a = check(&scene, &cam, false, "eye inside, near plane cutting bonds");
    assert!(a.psnr.is_finite());
    // A lone bond from behind the eye to in front of it, through the near plane.
    let mut s = SphereScene::new(common::materials());
    s.bond_radius = 0.3;
    s.push(Vec3::new(0.5, -0.2, 3.0), 0.35, 0);
    s.push(Vec3::new(-0.4, 0.3, -6.0), 0.35, 0);
    s.bonds.push([0, 1]);
    let cam = Camera::perspective_look_at(
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        90.0,
        160,
        120,
    )
    .unwrap()
    .with_clip(0.1, f32::INFINITY)
    .unwrap();
    check(&s, &cam, false, "bond crossing the eye plane");
    // Entirely behind the eye: culled, nothing drawn.
    let mut behind = s.clone();
    behind.centers = vec![Vec3::new(0.0, 0.0, 3.0), Vec3::new(1.0, 0.0, 5.0)];
    let out = render(
        &behind,
        &cam,
        &Options::new(Method::Raycast, Lighting::default_for(&cam)),
    );
    assert_no_nan(&out, "behind");
    assert_eq!(
        (out.stats.bonds_drawn, out.stats.bonds_culled),
        (0, 1),
        "a bond behind the eye is culled"
    );
    assert_eq!(out.frame.coverage_count(), 0);
}

#[test]
fn invalid_bonds_are_skipped_and_counted() {
    let mut s = molecule(6, 0.2);
    let good = s.bonds.len();
    let n = s.len() as u32;
    s.push(Vec3::new(f32::NAN, 0.0, 0.0), 0.4, 0); // atom n: non-finite centre
    s.push(Vec3::new(0.0, 5.0, 0.0), -1.0, 0); // atom n + 1: negative radius
    s.push(Vec3::new(0.0, 6.0, 0.0), 0.4, 99); // atom n + 2: unknown kind
    s.push(s.centers[0], 0.3, 1); // atom n + 3: same centre as atom 0
    s.bonds.extend([
        [0, n + 10],
        [u32::MAX, 1],
        [0, n],
        [n + 1, 1],
        [2, n + 2],
        [0, n + 3],
        [3, 3],
    ]);
    let cam = persp(Vec3::new(0.0, 0.0, 12.0), 50.0, 96, 96);
    let opts = Options::new(Method::Raycast, Lighting::default_for(&cam));
    let out = render(&s, &cam, &opts);
    assert_no_nan(&out, "invalid bonds");
    assert_eq!(out.stats.bonds_skipped, 7, "{:?}", out.stats);
    assert_eq!(out.stats.bonds_drawn + out.stats.bonds_culled, good);
    // A bad radius skips every bond and draws the spheres alone.
    for r in [0.0, -0.1, f32::NAN, f32::INFINITY] {
        let mut t = molecule(6, r);
        t.bonds.push([0, 2]);
        let out = render(&t, &cam, &opts);
        assert_eq!(out.stats.bonds_skipped, t.bonds.len(), "radius {r}");
        let mut no = opts.clone();
        no.draw_bonds = false;
        assert_eq!(out.frame, render(&t, &cam, &no).frame, "radius {r}");
    }
}

#[test]
fn every_method_draws_bonds_depth_tested_against_its_spheres() {
    let scene = molecule(18, 0.2);
    let cam = persp(Vec3::new(1.0, 2.0, 14.0), 45.0, 128, 128);
    let lighting = Lighting::default_for(&cam);
    let refr = oracle(&scene, &cam, &lighting, true);
    for m in Method::ALL {
        let mut opts = Options::new(m, lighting);
        let out = render(&scene, &cam, &opts);
        assert_no_nan(&out, m.name());
        opts.draw_bonds = false;
        let bare = render(&scene, &cam, &opts);
        let a = measure(&out.frame, &refr, m.name());
        let b = measure(&bare.frame, &refr, m.name());
        // Bonds are exact whatever drew the atoms: coverage gets much closer to the reference.
        assert!(
            a.mismatched * 4 < b.mismatched,
            "{}: silhouette mismatch with bonds {} should be far below without {}",
            m.name(),
            a.mismatched,
            b.mismatched
        );
        assert_eq!(out.stats.bonds_drawn, scene.bonds.len(), "{}", m.name());
    }
}

#[test]
fn same_bytes_for_one_and_two_threads() {
    // Enough bonds for several projection chunks, overlapping in many tiles.
    let mut scene = SphereScene::new(common::materials());
    scene.bond_radius = 0.12;
    let mut rng = common::Lcg(5);
    for i in 0..6000 {
        let c = Vec3::new(
            rng.range(-8.0, 8.0),
            rng.range(-8.0, 8.0),
            rng.range(-8.0, 8.0),
        );
        scene.push(c, rng.range(0.15, 0.3), (i % 3) as u16);
    }
    for i in 0..20_000u32 {
        let a = (rng.next_f32() * 6000.0) as u32 % 6000;
        let b = (a + 1 + i % 7) % 6000;
        scene.bonds.push([a, b]);
    }
    let cam = persp(Vec3::new(3.0, 5.0, 30.0), 60.0, 300, 200);
    for m in [Method::Raycast, Method::Lut] {
        let opts = Options::new(m, Lighting::default_for(&cam));
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Renderer::new().render(&scene, &cam, &opts))
        };
        let (one, two) = (run(1), run(2));
        assert!(one.stats.bonds_drawn > 19_000, "{:?}", one.stats);
        assert_eq!(one.stats, two.stats);
        assert!(
            one.frame == two.frame,
            "{}: 1 and 2 threads differ",
            m.name()
        );
    }
}

#[test]
fn per_bond_radii_match_reftrace() {
    // Three radii along the chain (thin, medium, thicker than the atoms: flat caps), the
    // reference built with each bond's own radius.
    let mut scene = molecule(24, 0.2);
    scene.bond_radii = (0..scene.bonds.len())
        .map(|k| [0.1, 0.25, 0.45][k % 3])
        .collect();
    let dir = Vec3::new(0.5, 0.3, 1.0).normalize();
    let cam = persp(dir * 16.0, 40.0, 240, 240);
    check(&scene, &cam, true, "per-bond radii");
    // A wrong-length list falls back to bond_radius for every bond.
    let mut fallback = scene.clone();
    fallback.bond_radii.pop();
    let uniform = molecule(24, 0.2);
    let lighting = Lighting::default_for(&cam);
    let mut r = Renderer::new();
    let a = r
        .render(&fallback, &cam, &Options::new(Method::Raycast, lighting))
        .frame;
    let b = r
        .render(&uniform, &cam, &Options::new(Method::Raycast, lighting))
        .frame;
    assert!(a == b);
}
