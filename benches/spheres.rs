//! Speed of every sphere method on the named scenes S1, S2, S3 (PERFORMANCE-NOTES.md).
//!
//! S1 = 1,115 spheres (Seed 004's silicate composition) at 500x500; S2 = 100,000 spheres r 0.5 in a
//! 100³ box at 1920x1080; S3 = 1,000,000 spheres r 0.3 in a 200³ box at 1920x1080; perspective
//! camera (65° horizontal field of view, ~28% of the pixels covered) looking at the box centre
//! from 2.4 box lengths. Scenes come from a small seeded RNG
//! here. S3 runs only with `--bench` (test mode stays quick).
//!
//! `CARGO_TARGET_DIR=/work/target-impostor cargo bench --bench spheres -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, criterion_group};
use glam::Vec3;
use texmap::core::camera::Camera;
use texmap::core::frame::Frame;
use texmap::core::shade::{Lighting, Material};
use texmap::impostor::{Method, Options, Renderer, SphereScene};

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Scene + camera of a named sphere scene.
pub fn scene(name: &str) -> (SphereScene, Camera) {
    let mut rng = Lcg(0x5eed_0000 + name.len() as u64);
    let mats = vec![
        Material::plastic(Vec3::new(0.9, 0.15, 0.1)),  // O
        Material::plastic(Vec3::new(0.85, 0.75, 0.2)), // Si
        Material::plastic(Vec3::new(0.6, 0.6, 0.65)),  // Al
        Material::plastic(Vec3::new(0.2, 0.8, 0.2)),   // Mg
        Material::plastic(Vec3::new(0.9, 0.9, 0.9)),   // H
        Material::plastic(Vec3::new(0.3, 0.6, 0.95)),  // He
    ];
    let mut s = SphereScene::new(mats);
    let (side, w, h) = match name {
        "S1" => {
            // Seed 004's composition: counts and radii per element.
            let table = [
                (409, 1.30),
                (50, 1.00),
                (6, 0.53),
                (50, 0.71),
                (500, 0.80),
                (100, 0.70),
            ];
            let side = 24.0;
            for (kind, &(count, r)) in table.iter().enumerate() {
                for _ in 0..count {
                    let c = (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * side;
                    s.push(c, r, kind as u16);
                }
            }
            (side, 500, 500)
        }
        "S2" | "S3" => {
            let (n, side, r) = if name == "S2" {
                (100_000, 100.0, 0.5)
            } else {
                (1_000_000, 200.0, 0.3)
            };
            for i in 0..n {
                let c = (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * side;
                s.push(c, r, (i % 6) as u16);
            }
            (side, 1920, 1080)
        }
        _ => unreachable!("unknown scene {name}"),
    };
    let eye = Vec3::new(0.55, 0.35, 0.76).normalize() * (2.4 * side);
    let cam = Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, 65.0, w, h).expect("camera");
    (s, cam)
}

fn bench(c: &mut Criterion) {
    let full = std::env::args().any(|a| a == "--bench");
    let mut names = vec!["S1", "S2"];
    if full {
        names.push("S3");
    }
    for name in names {
        let (s, cam) = scene(name);
        let mut g = c.benchmark_group(format!("spheres/{name}"));
        g.sample_size(10);
        for m in Method::ALL {
            let opts = Options::new(m, Lighting::default_for(&cam));
            let mut r = Renderer::new();
            let mut frame = Frame::new(cam.width(), cam.height(), opts.background);
            g.bench_function(m.name(), |b| {
                b.iter(|| r.render_into(&s, &cam, &opts, &mut frame))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
