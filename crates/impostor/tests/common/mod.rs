//! Shared helpers of the impostor tests: an independent f64 ray–sphere reference and small
//! seeded scenes.
#![allow(dead_code)]

use texmap_core::camera::Camera;
use texmap_core::color::linear_to_srgb8_exact;
use texmap_core::frame::Frame;
use texmap_core::glam::{DVec3, Vec3};
use texmap_core::shade::{Lighting, Material};
use texmap_impostor::SphereScene;

/// A tiny deterministic RNG (LCG), so the tests need no crate.
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next_f32(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }
}

pub fn materials() -> Vec<Material> {
    vec![
        Material::plastic(Vec3::new(0.8, 0.1, 0.1)),
        Material::plastic(Vec3::new(0.1, 0.6, 0.9)),
        Material::matte(Vec3::new(0.7, 0.7, 0.2)),
    ]
}

/// `n` random spheres in the cube `[-half, half]³` with radii in `[rmin, rmax]`.
pub fn random_scene(seed: u64, n: usize, half: f32, rmin: f32, rmax: f32) -> SphereScene {
    let mut rng = Lcg(seed);
    let mut s = SphereScene::new(materials());
    for i in 0..n {
        let c = Vec3::new(
            rng.range(-half, half),
            rng.range(-half, half),
            rng.range(-half, half),
        );
        s.push(c, rng.range(rmin, rmax), (i % 3) as u16);
    }
    s
}

/// The reference: per pixel centre, the nearest f64 ray–sphere hit at depth ≥ near, outward
/// normal (flipped on the interior), shaded with `Lighting::shade` in world space and encoded
/// with the exact sRGB encoder.
pub fn reference(scene: &SphereScene, cam: &Camera, lighting: &Lighting, bg: [u8; 4]) -> Frame {
    let (w, h) = (cam.width(), cam.height());
    let mut f = Frame::new(w, h, bg);
    let eye = cam.eye().as_dvec3();
    let (right, up, fwd) = (
        cam.right().as_dvec3(),
        cam.up().as_dvec3(),
        cam.forward().as_dvec3(),
    );
    let k = cam.scale() as f64;
    let near = cam.near() as f64;
    for y in 0..h {
        for x in 0..w {
            let dx = (x as f64 + 0.5 - w as f64 * 0.5) / k;
            let dy = (h as f64 * 0.5 - (y as f64 + 0.5)) / k;
            // Ray with parameter = depth along the view axis.
            let (o, d) = if cam.is_orthographic() {
                (eye + right * dx + up * dy, fwd)
            } else {
                (eye, right * dx + up * dy + fwd)
            };
            let mut best = f64::INFINITY;
            let mut best_n = DVec3::ZERO;
            let mut best_k = 0usize;
            for i in 0..scene.len() {
                if !scene.is_valid(i) {
                    continue;
                }
                let c = scene.centers[i].as_dvec3();
                let r = scene.radii[i] as f64;
                let oc = o - c;
                let a = d.dot(d);
                let b = oc.dot(d);
                let cc = oc.dot(oc) - r * r;
                let disc = b * b - a * cc;
                if disc < 0.0 {
                    continue;
                }
                let s = disc.sqrt();
                for (t, sign) in [((-b - s) / a, 1.0), ((-b + s) / a, -1.0)] {
                    if t >= near {
                        if t < best {
                            best = t;
                            best_n = (o + d * t - c).normalize() * sign;
                            best_k = scene.kinds[i] as usize;
                        }
                        break;
                    }
                }
            }
            if best.is_finite() {
                let i = f.index(x, y);
                f.depth[i] = best as f32;
                let v = (-d).normalize();
                let c = lighting.shade(&scene.materials[best_k], best_n.as_vec3(), v.as_vec3());
                f.color[i] = [
                    linear_to_srgb8_exact(c.x),
                    linear_to_srgb8_exact(c.y),
                    linear_to_srgb8_exact(c.z),
                    255,
                ];
            }
        }
    }
    f
}
