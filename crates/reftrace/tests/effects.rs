//! The reference's ambient occlusion, shadows and depth cueing against analytic answers, and
//! their bad options.

use texmap_core::camera::Camera;
use texmap_core::color::srgb8_to_linear;
use texmap_core::shade::{Lighting, Material};
use texmap_reftrace::glam::Vec3;
use texmap_reftrace::{
    AmbientOcclusion, DepthCue, RenderError, RenderOptions, SceneBuilder, SurfaceMaterial,
};

/// A white matte ground (a sphere of radius 1000 touching y = 0 at the origin) and a unit
/// sphere centred 2 above the origin, seen from the side under ambient light 1 only.
fn setup() -> (texmap_reftrace::Scene, Camera, Vec<SurfaceMaterial>) {
    let mut b = SceneBuilder::new();
    b.add_sphere(Vec3::new(0.0, -1000.0, 0.0), 1000.0, 0);
    b.add_sphere(Vec3::new(0.0, 2.0, 0.0), 1.0, 0);
    let cam =
        Camera::perspective_look_at(Vec3::new(10.0, 0.5, 0.0), Vec3::ZERO, Vec3::Y, 20.0, 33, 33)
            .unwrap();
    (
        b.build(),
        cam,
        vec![SurfaceMaterial::opaque(Material::matte(Vec3::ONE))],
    )
}

#[test]
fn ao_under_a_sphere_is_one_minus_sin_squared() {
    // Cosine-weighted visibility at a point under a sphere of radius r whose centre is at
    // height h on the normal: the sphere hides a cone of half-angle α, sin α = r/h, whose
    // projected solid angle is π sin²α, so AO = 1 − (r/h)² = 0.75 here.
    let (scene, cam, mats) = setup();
    let mut o = RenderOptions::new(Lighting::new(Vec3::ONE, &[]).unwrap(), &mats);
    o.ambient_occlusion = Some(AmbientOcclusion {
        samples_per_axis: 64,
        distance: 100.0,
    });
    let f = scene.render(&cam, &o).unwrap();
    let ao = srgb8_to_linear(f.color[f.index(16, 16)][0]);
    eprintln!("AO under the sphere: {ao} (analytic 0.75)");
    assert!((ao - 0.75).abs() < 0.015, "AO {ao}");
    // Off: the ambient-only image is uniformly white where covered.
    let plain = scene
        .render(
            &cam,
            &RenderOptions::new(Lighting::new(Vec3::ONE, &[]).unwrap(), &mats),
        )
        .unwrap();
    assert_eq!(plain.color[plain.index(16, 16)], [255, 255, 255, 255]);
    // A short reach ignores the sphere: the nearest point of it is 1 away.
    o.ambient_occlusion = Some(AmbientOcclusion {
        samples_per_axis: 8,
        distance: 0.9,
    });
    let short = scene.render(&cam, &o).unwrap();
    assert_eq!(short.color[short.index(16, 16)], [255, 255, 255, 255]);
}

#[test]
fn shadow_below_a_sphere_and_fog_by_depth() {
    let (scene, cam, mats) = setup();
    // Light straight down: the origin is in the sphere's shadow.
    let light = Lighting::new(Vec3::ZERO, &[(Vec3::Y, Vec3::ONE)]).unwrap();
    let mut o = RenderOptions::new(light, &mats);
    let lit = scene.render(&cam, &o).unwrap();
    assert_eq!(lit.color[lit.index(16, 16)], [255, 255, 255, 255]);
    o.shadows = true;
    let shadowed = scene.render(&cam, &o).unwrap();
    assert_eq!(shadowed.color[shadowed.index(16, 16)], [0, 0, 0, 255]);
    // Fog: the centre pixel's depth is ~10; full strength beyond `end` gives the fog colour.
    o.shadows = false;
    o.fog = Some(DepthCue {
        start: 1.0,
        end: 2.0,
        color: Vec3::new(0.0, 0.0, 1.0),
        strength: 1.0,
    });
    let fogged = scene.render(&cam, &o).unwrap();
    assert_eq!(fogged.color[fogged.index(16, 16)], [0, 0, 255, 255]);
}

#[test]
fn bad_effect_options_are_errors() {
    let (scene, cam, mats) = setup();
    let l = Lighting::new(Vec3::ONE, &[]).unwrap();
    for (n, d) in [
        (0, 1.0),
        (65, 1.0),
        (4, 0.0),
        (4, f32::NAN),
        (4, f32::INFINITY),
    ] {
        let mut o = RenderOptions::new(l, &mats);
        o.ambient_occlusion = Some(AmbientOcclusion {
            samples_per_axis: n,
            distance: d,
        });
        assert!(matches!(
            scene.render(&cam, &o),
            Err(RenderError::BadAmbientOcclusion { .. })
        ));
    }
    let mut o = RenderOptions::new(l, &mats);
    o.fog = Some(DepthCue {
        start: 2.0,
        end: 1.0,
        color: Vec3::ZERO,
        strength: 0.5,
    });
    assert_eq!(scene.render(&cam, &o).unwrap_err(), RenderError::BadFog);
}
