//! The exact method against an independent f64 ray–sphere reference.

use crate::common;

use common::{random_scene, reference};
use texmap_core::camera::Camera;
use texmap_core::glam::Vec3;
use texmap_core::metrics::{depth_error, psnr, silhouette_error};
use texmap_core::shade::Lighting;
use texmap_impostor::{Method, Options, Renderer, SphereScene, render};

fn check(scene: &SphereScene, cam: &Camera, what: &str) {
    let opts = Options::new(Method::Raycast, Lighting::default_for(cam));
    let out = render(scene, cam, &opts);
    let refr = reference(scene, cam, &opts.lighting, opts.background);
    let sil = silhouette_error(&out.frame, &refr).unwrap();
    let dep = depth_error(&out.frame, &refr).unwrap();
    let p = psnr(&out.frame, &refr).unwrap();
    // Depth range of the reference.
    let (mut lo, mut hi) = (f32::INFINITY, 0f32);
    for &d in refr.depth.iter().filter(|d| d.is_finite()) {
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let range = (hi - lo).max(1e-6) as f64;
    assert!(
        refr.coverage_count() > 0,
        "{what}: the reference covers nothing"
    );
    // Only pixel centres within f32 rounding of the silhouette may disagree.
    assert!(
        sil.mean_displacement_px <= 0.02,
        "{what}: silhouette expected ≤ 0.02 px, got {} ({} px of {} edges)",
        sil.mean_displacement_px,
        sil.mismatched_pixels,
        sil.outline_edges
    );
    assert!(
        dep.max_abs <= 1e-4 * range,
        "{what}: depth error expected ≤ {} (1e-4 of range {range}), got {}",
        1e-4 * range,
        dep.max_abs
    );
    assert!(p >= 45.0, "{what}: PSNR expected ≥ 45 dB, got {p}");
}

#[test]
fn perspective_matches_f64_reference_at_several_fovs() {
    let scene = random_scene(7, 300, 10.0, 0.3, 2.0);
    for fov in [20.0f32, 60.0, 100.0, 150.0] {
        let dist = 12.0 / (fov.to_radians() * 0.5).tan() + 12.0;
        let cam = Camera::perspective_look_at(
            Vec3::new(0.3, 0.5, dist),
            Vec3::ZERO,
            Vec3::Y,
            fov,
            160,
            120,
        )
        .unwrap();
        check(&scene, &cam, &format!("fov {fov}"));
    }
}

#[test]
fn orthographic_matches_f64_reference() {
    let scene = random_scene(8, 300, 10.0, 0.3, 2.0);
    let cam = Camera::orthographic_look_at(
        Vec3::new(5.0, 3.0, 40.0),
        Vec3::ZERO,
        Vec3::Y,
        26.0,
        150,
        110,
    )
    .unwrap();
    check(&scene, &cam, "ortho");
}

#[test]
fn camera_inside_the_scene_and_spheres_cut_by_the_near_plane() {
    let scene = random_scene(9, 400, 10.0, 0.5, 3.0);
    // Eye in the middle of the cloud with a near plane that cuts spheres.
    let cam =
        Camera::perspective_look_at(Vec3::new(0.5, 0.2, 1.0), Vec3::ZERO, Vec3::Y, 90.0, 128, 96)
            .unwrap()
            .with_clip(0.8, f32::INFINITY)
            .unwrap();
    check(&scene, &cam, "inside");
}

#[test]
fn single_sphere_depth_and_coverage_are_analytic() {
    let mut scene = SphereScene::new(common::materials());
    scene.push(Vec3::ZERO, 1.0, 0);
    let cam = Camera::perspective_look_at(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        30.0,
        101,
        101,
    )
    .unwrap();
    let out = render(
        &scene,
        &cam,
        &Options::new(Method::Raycast, Lighting::default_for(&cam)),
    );
    let c = out.frame.index(50, 50);
    // Pixel centre (50.5, 50.5) is the image centre: the ray hits the pole at depth 9.
    assert!(
        (out.frame.depth[c] - 9.0).abs() < 1e-5,
        "expected 9, got {}, tolerance 1e-5",
        out.frame.depth[c]
    );
    // The silhouette is a circle of angular radius asin(1/10): screen radius k·tan(asin 0.1).
    let k = cam.scale() as f64;
    let rad = k * (0.1f64.asin()).tan();
    let mut wrong = 0;
    for y in 0..101u32 {
        for x in 0..101u32 {
            let dx = x as f64 + 0.5 - 50.5;
            let dy = y as f64 + 0.5 - 50.5;
            let dist = (dx * dx + dy * dy).sqrt();
            if (dist - rad).abs() < 1e-3 {
                continue;
            }
            if (dist < rad) != out.frame.covered(out.frame.index(x, y)) {
                wrong += 1;
            }
        }
    }
    assert_eq!(wrong, 0, "pixels off the analytic disc of radius {rad}");
    assert_eq!(out.stats.drawn, 1);
}

#[test]
fn invalid_spheres_are_counted_not_drawn() {
    let mut scene = SphereScene::new(common::materials());
    scene.push(Vec3::new(f32::NAN, 0.0, 0.0), 1.0, 0);
    scene.push(Vec3::new(0.0, f32::INFINITY, 0.0), 1.0, 0);
    scene.push(Vec3::ZERO, -1.0, 0);
    scene.push(Vec3::ZERO, f32::NAN, 0);
    scene.push(Vec3::ZERO, 0.0, 0);
    scene.push(Vec3::ZERO, 1.0, 99);
    scene.push(Vec3::new(0.0, 0.0, 20.0), 1.0, 0); // behind the camera
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 40.0, 32, 32)
            .unwrap();
    for m in Method::ALL {
        let out = render(&scene, &cam, &Options::new(m, Lighting::default_for(&cam)));
        assert_eq!(out.stats.skipped_invalid, 6, "{m:?}");
        assert_eq!(out.stats.culled, 1, "{m:?}");
        assert_eq!(out.stats.drawn, 0, "{m:?}");
        assert_eq!(out.frame.coverage_count(), 0, "{m:?}");
        assert!(
            out.frame.color.iter().all(|&c| c == [0, 0, 0, 255]),
            "{m:?}"
        );
    }
}

#[test]
fn empty_scene_gives_background_frame() {
    let scene = SphereScene::new(vec![]);
    let cam = Camera::perspective_look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 70, 33).unwrap();
    for m in Method::ALL {
        let mut o = Options::new(m, Lighting::default_for(&cam));
        o.background = [10, 20, 30, 255];
        let out = Renderer::new().render(&scene, &cam, &o);
        assert!(out.frame.color.iter().all(|&c| c == [10, 20, 30, 255]));
        assert!(out.frame.depth.iter().all(|d| *d == f32::INFINITY));
        assert_eq!(out.stats, Default::default());
    }
}

#[test]
fn output_is_identical_for_one_and_two_threads() {
    let scene = random_scene(11, 40_000, 30.0, 0.2, 1.0);
    let cam = Camera::perspective_look_at(
        Vec3::new(10.0, 20.0, 90.0),
        Vec3::ZERO,
        Vec3::Y,
        50.0,
        300,
        200,
    )
    .unwrap();
    for m in Method::ALL {
        let o = Options::new(m, Lighting::default_for(&cam));
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Renderer::new().render(&scene, &cam, &o))
        };
        let a = run(1);
        let b = run(2);
        assert!(a.frame.coverage_count() > 1000, "{m:?}");
        assert!(a.frame.color == b.frame.color, "{m:?}: colour differs");
        assert!(
            a.frame
                .depth
                .iter()
                .map(|d| d.to_bits())
                .eq(b.frame.depth.iter().map(|d| d.to_bits())),
            "{m:?}: depth differs"
        );
        assert_eq!(a.stats, b.stats);
    }
}
