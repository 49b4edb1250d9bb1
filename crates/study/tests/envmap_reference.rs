//! The environment-mapping methods against the reference ray tracer (texmap-reftrace, through
//! `texmap_study::envmap::reference`: the same scene, mirror and refraction rays traced, 3x3
//! samples per pixel): PSNR over the target's pixels on the built-in tunnel, the parallax bound,
//! refraction, a mesh target, and the camera-roll check. They live in the study crate, which owns
//! the conversion of an environment-mapping scene into the oracle's, so envmap's own tests need
//! no copy of it.

use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_envmap::glam::{Quat, Vec3};
use texmap_envmap::scene::{TunnelParams, tunnel_camera, tunnel_scene};
use texmap_envmap::shapes;
use texmap_envmap::{
    EnvScene, Environment, Method, Options, Renderer, Surface, Target, TargetShape,
};

fn reference(scene: &EnvScene, cam: &Camera, with_objects: bool) -> Frame {
    texmap_study::envmap::reference(scene, cam, with_objects, 3).unwrap()
}

fn target_mask(scene: &EnvScene, cam: &Camera) -> Vec<bool> {
    texmap_study::envmap::target_mask(scene, cam).unwrap()
}

/// PSNR (dB, sRGB8 RGB, peak 255) over the masked pixels.
fn masked_psnr(a: &Frame, b: &Frame, mask: &[bool]) -> f64 {
    let (psnr, _, n) = texmap_study::envmap::masked_error(a, b, mask);
    assert!(n > 0, "empty mask");
    psnr
}

#[test]
fn methods_against_the_reference_on_the_tunnel() {
    let scene = tunnel_scene(TunnelParams::default()).unwrap();
    let cam = tunnel_camera(200, 150).unwrap();
    let full = reference(&scene, &cam, true);
    let env_only = reference(&scene, &cam, false);
    let mask = target_mask(&scene, &cam);
    assert!(mask.iter().filter(|&&m| m).count() > 1500);
    dump("ref-full", &full);
    dump("ref-env", &env_only);
    let mut r = Renderer::new();
    let mut psnr = std::collections::HashMap::new();
    for m in Method::ALL {
        let out = r.render(&scene, &cam, &Options::new(m)).unwrap();
        let p_full = masked_psnr(&out.frame, &full, &mask);
        let p_env = masked_psnr(&out.frame, &env_only, &mask);
        eprintln!(
            "{:22} vs full {p_full:6.2} dB, vs env-only {p_env:6.2} dB",
            m.name()
        );
        psnr.insert(m, (p_full, p_env));
        dump(m.name(), &out.frame);
    }
    // Measured at 200x150 (3x3-sample reference): static 28.2 / vertex 26.3 dB against the
    // environment alone; dynamic maps 15.7-15.8 dB and cube-box 25.1 dB against the full scene.
    let full = |m| psnr[&m].0;
    let env = |m| psnr[&m].1;
    assert!(env(Method::SphereStatic) > 25.0, "{psnr:?}");
    // Per-vertex interpolation across the rim (the "sparkle") costs accuracy.
    assert!(
        env(Method::SphereStatic) > env(Method::SphereStaticVertex) + 1.0,
        "{psnr:?}"
    );
    for m in [Method::SphereDynamic, Method::Cube, Method::Paraboloid] {
        assert!(full(m) > 14.0, "{}: {psnr:?}", m.name());
        // The dynamic maps hold the objects: they beat the static map on the full scene.
        assert!(
            full(m) > full(Method::SphereStatic) + 3.0,
            "{}: {psnr:?}",
            m.name()
        );
    }
    // The tunnel is 4 radii away: parallax dominates, and box projection removes most of it.
    assert!(full(Method::CubeBox) > full(Method::Cube) + 6.0, "{psnr:?}");
}

/// With `ENVMAP_DUMP=dir`, write the frames as PNG for a look.
fn dump(name: &str, f: &texmap_core::frame::Frame) {
    let Ok(dir) = std::env::var("ENVMAP_DUMP") else {
        return;
    };
    image::save_buffer(
        format!("{dir}/{name}.png"),
        f.color_bytes(),
        f.width(),
        f.height(),
        image::ColorType::Rgba8,
    )
    .unwrap();
}

/// The rolled camera's image is the unrolled one turned: pixel (x, y) of the rolled camera
/// shows what the unrolled camera shows at the projection of the same ray.
#[test]
fn reflections_turn_when_the_camera_rolls() {
    let scene = tunnel_scene(TunnelParams::default()).unwrap();
    let eye = Vec3::new(0.3, 0.4, 5.0);
    let s = 128;
    let a = Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, 40.0, s, s).unwrap();
    let fwd = a.forward();
    let b = Camera::perspective_look_at(
        eye,
        Vec3::ZERO,
        Quat::from_axis_angle(fwd, 1.0) * Vec3::Y,
        40.0,
        s,
        s,
    )
    .unwrap();
    let mask = target_mask(&scene, &b);
    for method in [Method::SphereStatic, Method::SphereDynamic, Method::Cube] {
        let mut r = Renderer::new();
        let fa = r.render(&scene, &a, &Options::new(method)).unwrap().frame;
        let fb = r.render(&scene, &b, &Options::new(method)).unwrap().frame;
        let (mut turned, mut same, mut n) = (0.0f64, 0.0f64, 0usize);
        for y in 0..s {
            for x in 0..s {
                let i = (y * s + x) as usize;
                if !mask[i] {
                    continue;
                }
                let d = b.ray(x as f32 + 0.5, y as f32 + 0.5).dir;
                let (p, _) = a.project(eye + d).unwrap();
                let (xa, ya) = (p.x.floor() as i64, p.y.floor() as i64);
                if !(0..s as i64).contains(&xa) || !(0..s as i64).contains(&ya) {
                    continue;
                }
                let ca = fa.color[(ya * s as i64 + xa) as usize];
                let diff = |c: [u8; 4]| {
                    (0..3)
                        .map(|k| (c[k] as f64 - fb.color[i][k] as f64).abs())
                        .sum::<f64>()
                        / 3.0
                };
                turned += diff(ca);
                same += diff(fa.color[i]);
                n += 1;
            }
        }
        let (turned, same) = (turned / n as f64, same / n as f64);
        eprintln!(
            "{}: mean |rolled − turned| {turned:.2}, |rolled − unturned| {same:.2} codes",
            method.name()
        );
        // Nearest-pixel resampling of a 57° roll costs a few codes on stripes; an unturned
        // reflection is several times further off.
        assert!(
            n > 2000 && turned < 12.0 && same > 2.0 * turned,
            "{}: {turned} vs {same}",
            method.name()
        );
    }
}

/// Seed 003's parallax error: exact only at the target's centre. One object of constant angular
/// size at k target radii (`texmap_study::envmap::distance_scene`): the dynamic maps' error falls as k grows, and beyond 12 radii it is
/// small.
#[test]
fn parallax_error_is_bounded_for_distant_objects() {
    let cam = Camera::perspective_look_at(
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        40.0,
        160,
        160,
    )
    .unwrap();
    let mut by_k = Vec::new();
    for k in [2.0f32, 4.0, 12.0, 30.0] {
        // The distance study's scene: a unit mirror sphere and one box at k radii.
        let scene = texmap_study::envmap::distance_scene(k).unwrap();
        let reference = reference(&scene, &cam, true);
        let mask = target_mask(&scene, &cam);
        let mut row = Vec::new();
        for method in [Method::SphereDynamic, Method::Cube, Method::Paraboloid] {
            let f = Renderer::new()
                .render(&scene, &cam, &Options::new(method))
                .unwrap()
                .frame;
            row.push(masked_psnr(&f, &reference, &mask));
        }
        eprintln!("k = {k:4}: sphere-dynamic, cube, paraboloid PSNR {row:.2?}");
        by_k.push(row);
    }
    for m in 0..3 {
        assert!(by_k[0][m] + 3.0 < by_k[2][m], "method {m}: {by_k:?}");
        // Beyond 12 target radii the error stays below the 31 dB bound (measured 33.4-33.7).
        assert!(
            by_k[2][m] > 31.0 && by_k[3][m] > 35.0,
            "method {m}: {by_k:?}"
        );
    }
}

#[test]
fn refraction_follows_the_reference() {
    let cam = tunnel_camera(160, 120).unwrap();
    for ior in [1.5f32, 1.05] {
        let scene = tunnel_scene(TunnelParams {
            surface: Surface::Refractive { ior },
            ..Default::default()
        })
        .unwrap();
        let reference = reference(&scene, &cam, true);
        let mask = target_mask(&scene, &cam);
        for method in [Method::Cube, Method::CubeBox, Method::SphereDynamic] {
            let f = Renderer::new()
                .render(&scene, &cam, &Options::new(method))
                .unwrap()
                .frame;
            let p = masked_psnr(&f, &reference, &mask);
            eprintln!("ior {ior}: {} PSNR {p:.2}", method.name());
            // Measured at 160x120: ior 1.5 cube 16.5, cube-box 23.4, sphere-dynamic 18.1;
            // ior 1.05: 17.1, 19.9, 17.4 dB.
            let bound = match method {
                Method::CubeBox => 18.5,
                _ => 15.0,
            };
            assert!(
                p > bound,
                "ior {ior} {}: {p} dB, bound {bound}",
                method.name()
            );
        }
    }
    // An index below 1 has total internal reflection at the entry: no NaN, no panic.
    let scene = tunnel_scene(TunnelParams {
        surface: Surface::Refractive { ior: 0.7 },
        ..Default::default()
    })
    .unwrap();
    let f = Renderer::new()
        .render(&scene, &cam, &Options::new(Method::Cube))
        .unwrap()
        .frame;
    assert!(f.depth.iter().all(|d| !d.is_nan()));
}

#[test]
fn a_mesh_target_matches_the_reference() {
    let cam = tunnel_camera(160, 120).unwrap();
    let base = tunnel_scene(TunnelParams::default()).unwrap();
    let mesh = shapes::uv_sphere(Vec3::ZERO, 1.0, 96, 48);
    let scene = EnvScene::new(
        base.objects().to_vec(),
        Target {
            shape: TargetShape::Mesh(mesh),
            surface: Surface::Mirror,
        },
        Environment::Sky,
        *base.lighting(),
    )
    .unwrap();
    let reference = reference(&scene, &cam, true);
    let mask = target_mask(&scene, &cam);
    let f = Renderer::new()
        .render(&scene, &cam, &Options::new(Method::CubeBox))
        .unwrap()
        .frame;
    let p = masked_psnr(&f, &reference, &mask);
    let fs = Renderer::new()
        .render(&base, &cam, &Options::new(Method::CubeBox))
        .unwrap()
        .frame;
    let ps = masked_psnr(&fs, &reference, &mask);
    eprintln!("mesh target cube-box PSNR {p:.2} (analytic sphere {ps:.2})");
    // The 96x48 tessellation with interpolated normals is within 1 dB of the analytic sphere.
    assert!(
        p > 23.0 && (p - ps).abs() < 1.0,
        "mesh {p} dB, sphere {ps} dB"
    );
}
