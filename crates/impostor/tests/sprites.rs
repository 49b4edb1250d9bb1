//! The sprite methods (Seed 002 LUT, Seed 004 template) against the f64 ray-sphere reference.

use crate::common;

use common::{random_scene, reference};
use texmap_core::camera::Camera;
use texmap_core::glam::Vec3;
use texmap_core::metrics::{depth_error, psnr, silhouette_error};
use texmap_core::shade::Lighting;
use texmap_impostor::{Method, Options, SphereScene, TemplateColoring, TemplateDepth, render};

fn ortho() -> Camera {
    Camera::orthographic_look_at(
        Vec3::new(5.0, 3.0, 40.0),
        Vec3::ZERO,
        Vec3::Y,
        26.0,
        200,
        150,
    )
    .unwrap()
}

#[test]
fn lut_is_exact_for_orthographic_views() {
    let scene = random_scene(21, 200, 10.0, 0.5, 2.0);
    let cam = ortho();
    let opts = Options::new(Method::Lut, Lighting::default_for(&cam));
    let out = render(&scene, &cam, &opts);
    let refr = reference(&scene, &cam, &opts.lighting, opts.background);
    let sil = silhouette_error(&out.frame, &refr).unwrap();
    // Nearest-texel mask at ≥ 1 texel per pixel: the outline moves by under one pixel; the
    // metric's mean displacement must stay far below that.
    assert!(
        sil.mean_displacement_px <= 0.25,
        "silhouette expected ≤ 0.25 px, got {} ({} px)",
        sil.mean_displacement_px,
        sil.mismatched_pixels
    );
    let p = psnr(&out.frame, &refr).unwrap();
    assert!(p >= 30.0, "PSNR expected ≥ 30 dB, got {p}");
    let d = depth_error(&out.frame, &refr).unwrap();
    // Depth is read from the nearest texel of D: on average a small fraction of the radius.
    // (No bound on the maximum: where a mask texel drops a rim pixel, the sphere behind wins it.)
    assert!(
        d.mean_abs <= 0.05,
        "mean depth error expected ≤ 0.05, got {}",
        d.mean_abs
    );
}

/// Mismatched pixels of one sphere drawn by `m`, placed at `offset` (pixels from the image centre).
fn single_sphere_mismatch(m: Method, screen_dir: Vec3) -> usize {
    let cam = Camera::perspective_look_at(
        Vec3::new(0.0, 0.0, 20.0),
        Vec3::ZERO,
        Vec3::Y,
        100.0,
        200,
        200,
    )
    .unwrap();
    let mut scene = SphereScene::new(common::materials());
    // A point at depth 10 in the given eye direction.
    let p = cam.eye() + cam.dir_to_world(screen_dir) * (10.0 / -screen_dir.z);
    scene.push(p, 1.5, 0);
    let opts = Options::new(m, Lighting::default_for(&cam));
    let out = render(&scene, &cam, &opts);
    let refr = reference(&scene, &cam, &opts.lighting, opts.background);
    silhouette_error(&out.frame, &refr)
        .unwrap()
        .mismatched_pixels
}

#[test]
fn lut_perspective_error_grows_off_axis() {
    let centre = single_sphere_mismatch(Method::Lut, Vec3::new(0.0, 0.0, -1.0));
    let corner = single_sphere_mismatch(Method::Lut, Vec3::new(0.9, 0.6, -1.0));
    assert!(
        corner > 3 * centre.max(1),
        "off-axis error expected to dominate: centre {centre} px, corner {corner} px"
    );
}

#[test]
fn template_disc_is_exact_for_orthographic_views_and_depth_options_differ() {
    let scene = random_scene(22, 150, 10.0, 0.5, 2.0);
    let cam = ortho();
    let mut opts = Options::new(Method::Template, Lighting::default_for(&cam));
    let refr = reference(&scene, &cam, &opts.lighting, opts.background);
    let bill = render(&scene, &cam, &opts);
    opts.template_depth = TemplateDepth::DepthImage;
    let dimg = render(&scene, &cam, &opts);
    for (name, out) in [("billboard", &bill), ("depth image", &dimg)] {
        let sil = silhouette_error(&out.frame, &refr).unwrap();
        assert!(
            sil.mean_displacement_px <= 0.25,
            "{name}: silhouette expected ≤ 0.25 px, got {}",
            sil.mean_displacement_px
        );
    }
    let db = depth_error(&bill.frame, &refr).unwrap();
    let dd = depth_error(&dimg.frame, &refr).unwrap();
    // Billboard depth is the centre plane: off by up to R; the depth image is near exact.
    assert!(
        db.mean_abs > 0.3,
        "billboard mean depth error {} expected > 0.3",
        db.mean_abs
    );
    assert!(
        dd.mean_abs < 0.05,
        "depth-image mean depth error {} expected < 0.05",
        dd.mean_abs
    );
}

#[test]
fn template_highlight_sits_toward_the_light() {
    let cam = Camera::orthographic_look_at(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        3.0,
        101,
        101,
    )
    .unwrap();
    let mut scene = SphereScene::new(common::materials());
    scene.push(Vec3::ZERO, 1.0, 1);
    // One light from the upper left, in front.
    let light =
        Lighting::new(Vec3::splat(0.05), &[(Vec3::new(-1.0, 1.0, 1.5), Vec3::ONE)]).unwrap();
    for coloring in [TemplateColoring::HueRecolor, TemplateColoring::PerKind] {
        let mut opts = Options::new(Method::Template, light);
        opts.template_coloring = coloring;
        let out = render(&scene, &cam, &opts);
        let mut best = (0u32, 0u32, 0u32);
        for y in 0..101 {
            for x in 0..101 {
                let c = out.frame.color[out.frame.index(x, y)];
                let s = c[0] as u32 + c[1] as u32 + c[2] as u32;
                if s > best.0 {
                    best = (s, x, y);
                }
            }
        }
        // Blinn highlight of the exact sphere: at the half vector h = normalize(l + v).
        let h = (Vec3::new(-1.0, 1.0, 1.5).normalize() + Vec3::Z).normalize();
        let want_x = 50.5 + h.x * 101.0 / 3.0;
        let want_y = 50.5 - h.y * 101.0 / 3.0;
        let (bx, by) = (best.1 as f32 + 0.5, best.2 as f32 + 0.5);
        assert!(
            (bx - want_x).abs() <= 4.0 && (by - want_y).abs() <= 4.0,
            "{coloring:?}: brightest pixel expected near ({want_x}, {want_y}) ± 4, got ({bx}, {by})"
        );
    }
}

#[test]
fn sprites_skip_spheres_behind_the_near_plane_and_clip_fragments() {
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 60.0, 64, 64)
            .unwrap()
            .with_clip(2.0, 100.0)
            .unwrap();
    let mut scene = SphereScene::new(common::materials());
    scene.push(Vec3::new(0.0, 0.0, 9.0), 0.5, 0); // centre at depth 1 < near: skipped
    scene.push(Vec3::new(0.0, 0.0, 7.8), 0.5, 0); // centre at depth 2.2, front cap clipped
    for m in [Method::Lut, Method::Template] {
        let mut o = Options::new(m, Lighting::default_for(&cam));
        o.template_depth = TemplateDepth::DepthImage;
        let out = render(&scene, &cam, &o);
        assert_eq!(out.stats.culled, 1, "{m:?}");
        assert_eq!(out.stats.drawn, 1, "{m:?}");
        let min = out
            .frame
            .depth
            .iter()
            .cloned()
            .fold(f32::INFINITY, f32::min);
        assert!(
            min >= 2.0,
            "{m:?}: depth {min} nearer than the near plane 2"
        );
        assert!(out.frame.coverage_count() > 0, "{m:?}");
    }
}

/// Issue #4: spheres crossing the near plane are drawn by every method, their fragments in front
/// of the near plane only, including a sphere whose centre is behind the near plane and one the
/// eye is inside. Compared with the exact ray-cast method (independent of the sprite code): the
/// sprites must cover most pixels the ray caster covers. Not all: Seed 002 scales a sphere by
/// `R/z0`, which for a sphere 2.3 radii away is ~10% narrower than its true silhouette (the
/// documented perspective error of the method), so 75% is required, 98% on the view axis where
/// the tangent-length square of a sphere whose centre is behind the near plane is exact.
#[test]
fn sprites_draw_spheres_crossing_the_near_plane_in_front_of_it() {
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 60.0, 64, 64)
            .unwrap()
            .with_clip(2.0, 100.0)
            .unwrap();
    let cases = [
        // Centre at depth 1.5 < near 2, reaching to depth 2.5: a cap beyond the near plane.
        (
            "centre behind the near plane",
            Vec3::new(0.0, 0.0, 8.5),
            1.0,
            false,
            0.98,
        ),
        // Centre at depth 2.3, front cut by the near plane.
        (
            "centre just past the near plane",
            Vec3::new(0.3, 0.0, 7.7),
            1.0,
            false,
            0.75,
        ),
        // The eye inside the sphere: the whole image shows its far side.
        ("eye inside", Vec3::new(0.0, 0.0, 9.0), 3.0, true, 0.98),
    ];
    for (what, c, r, whole, share) in cases {
        let mut scene = SphereScene::new(common::materials());
        scene.push(c, r, 0);
        let exact = render(
            &scene,
            &cam,
            &Options::new(Method::Raycast, Lighting::default_for(&cam)),
        );
        let n_exact = exact.frame.coverage_count();
        assert!(n_exact > 0, "{what}: raycast covers nothing");
        for (m, depth) in [
            (Method::Lut, TemplateDepth::Billboard),
            (Method::Template, TemplateDepth::Billboard),
            (Method::Template, TemplateDepth::DepthImage),
        ] {
            let mut o = Options::new(m, Lighting::default_for(&cam));
            o.template_depth = depth;
            let out = render(&scene, &cam, &o);
            assert_eq!(out.stats.culled, 0, "{what} {m:?}");
            assert_eq!(out.stats.drawn, 1, "{what} {m:?}");
            let min = out
                .frame
                .depth
                .iter()
                .cloned()
                .fold(f32::INFINITY, f32::min);
            assert!(
                min >= 2.0,
                "{what} {m:?}: depth {min} nearer than the near plane 2"
            );
            // The pixels the exact method covers are covered (`share` of them).
            let both = (0..exact.frame.len())
                .filter(|&i| exact.frame.depth[i].is_finite() && out.frame.depth[i].is_finite())
                .count();
            assert!(
                both as f64 >= share * n_exact as f64,
                "{what} {m:?} {depth:?}: covers {both} of the {n_exact} pixels raycast covers, \
                 expected ≥ {share}"
            );
            if whole {
                assert_eq!(
                    out.frame.coverage_count(),
                    out.frame.len(),
                    "{what} {m:?}: the whole image"
                );
            }
        }
    }
}
