//! Shared helpers of the integration tests: the same scene traced by texmap-reftrace (the oracle)
//! and PSNR over the target's pixels.

#![allow(dead_code)] // each test binary uses a subset

use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::shade::Material;
use texmap_envmap::{EnvScene, Surface, TargetShape};
use texmap_reftrace::glam::Vec3;
use texmap_reftrace::{MeshShading, Optics, RenderOptions, SceneBuilder, SurfaceMaterial};

/// The reference frame: objects flat-shaded, the target a perfect mirror or clear dielectric,
/// escaped rays and primary misses take the environment. `with_objects = false` leaves the
/// objects out of the traced scene (the ideal a static map of the environment approximates).
/// 3 x 3 samples per pixel: the reference is antialiased, as a filtered map lookup is.
pub fn reference(scene: &EnvScene, cam: &Camera, with_objects: bool) -> Frame {
    reference_ss(scene, cam, with_objects, 3)
}

/// [`reference`] with `n × n` samples per pixel.
pub fn reference_ss(scene: &EnvScene, cam: &Camera, with_objects: bool, n: u32) -> Frame {
    let mut b = SceneBuilder::new();
    let mut materials = Vec::new();
    if with_objects {
        for o in scene.objects() {
            b.add_mesh(
                &o.mesh.positions,
                o.mesh.indices(),
                None,
                materials.len() as u32,
            )
            .unwrap();
            materials.push(SurfaceMaterial::opaque(o.material));
        }
    }
    add_target(&mut b, scene, materials.len() as u32);
    materials.push(target_material(scene));
    let traced = b.build();
    let mut opts = RenderOptions::new(*scene.lighting(), &materials);
    opts.environment_on_primary_miss = true;
    opts.max_depth = 4;
    opts.samples_per_axis = n;
    let env = scene.environment();
    traced
        .render_with_environment(cam, &opts, &|d: Vec3| env.radiance(d))
        .unwrap()
}

fn add_target(b: &mut SceneBuilder, scene: &EnvScene, id: u32) {
    match &scene.target().shape {
        TargetShape::Sphere { centre, radius } => {
            b.add_sphere(*centre, *radius, id);
        }
        TargetShape::Mesh(m) => {
            // Smooth, with the normals the renderer interpolates.
            b.add_mesh_shaded(
                &m.positions,
                m.indices(),
                None,
                Some(scene.target_normals()),
                MeshShading::VertexNormals,
                id,
            )
            .unwrap();
        }
    }
}

fn target_material(scene: &EnvScene) -> SurfaceMaterial {
    match scene.target().surface {
        Surface::Mirror => SurfaceMaterial::mirror(Material::matte(Vec3::ZERO), 1.0),
        Surface::Refractive { ior } => SurfaceMaterial {
            shading: Material::matte(Vec3::ZERO),
            optics: Optics::Refractive {
                ior,
                fresnel: false,
            },
            texture: None,
        },
    }
}

/// Pixels where the reference sees the target (its depth with the target alone equals the depth
/// with everything).
pub fn target_mask(scene: &EnvScene, cam: &Camera) -> Vec<bool> {
    let mut all = SceneBuilder::new();
    for o in scene.objects() {
        all.add_mesh(&o.mesh.positions, o.mesh.indices(), None, 0)
            .unwrap();
    }
    add_target(&mut all, scene, 0);
    let mut only = SceneBuilder::new();
    add_target(&mut only, scene, 0);
    let da = all.build().depth_image(cam);
    let dt = only.build().depth_image(cam);
    da.iter()
        .zip(&dt)
        .map(|(a, t)| t.is_finite() && (a - t).abs() <= 1e-5 * t.abs())
        .collect()
}

/// PSNR (dB, sRGB8 RGB, peak 255) over the masked pixels.
pub fn masked_psnr(a: &Frame, b: &Frame, mask: &[bool]) -> f64 {
    let mut se = 0.0f64;
    let mut n = 0usize;
    for ((ca, cb), &m) in a.color.iter().zip(&b.color).zip(mask) {
        if m {
            for k in 0..3 {
                let d = ca[k] as f64 - cb[k] as f64;
                se += d * d;
            }
            n += 3;
        }
    }
    assert!(n > 0, "empty mask");
    let mse = se / n as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}
