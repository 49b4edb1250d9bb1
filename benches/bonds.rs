//! Speed of the bond pass (exact ray-cast cylinder impostors drawn after the spheres), as the
//! difference between spheres only and spheres + bonds on two scenes:
//! - `molecule-bs`: texmap-study's ball-and-stick α-helix (300 atoms, 299 bonds) at 500x500;
//! - `chains-100k`: 1,000 random-walk chains of 100 atoms (100,000 atoms r 0.4, 99,000 bonds
//!   r 0.2, step 1.5) in a 100³ box at 1920x1080, seen by the study's box camera (as S2).
//!
//! Each case draws with a [`Renderer`] and a frame reused across iterations.
//!
//! `CARGO_TARGET_DIR=/work/target-bonds cargo bench --bench bonds -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, criterion_group};
use texmap::core::frame::Frame;
use texmap::core::glam::Vec3;
use texmap::core::shade::{Lighting, Material};
use texmap::impostor::{Method, Options, Renderer, SphereScene};
use texmap::study::scenes::{NamedScene, SceneId, box_camera, build};

/// 1,000 chains x 100 atoms: random walks of step 1.5 reflected into the box `[0, 100]³`.
fn chains_100k() -> NamedScene {
    let mats = [
        Vec3::new(0.75, 0.12, 0.10),
        Vec3::new(0.12, 0.35, 0.80),
        Vec3::new(0.85, 0.75, 0.20),
    ]
    .map(Material::plastic)
    .to_vec();
    let mut s = SphereScene::new(mats);
    s.bond_radius = 0.2;
    // A small LCG: deterministic and dependency free.
    let mut state = 0x5eed_b0d5_u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for _ in 0..1000 {
        let mut p = Vec3::new(next(), next(), next()) * 100.0;
        for k in 0..100 {
            let id = s.len() as u32;
            s.push(p, 0.4, (k % 3) as u16);
            if k > 0 {
                s.bonds.push([id - 1, id]);
            }
            // Next step: a random direction (rejection sampling in the unit ball).
            let dir = loop {
                let v = Vec3::new(next(), next(), next()) * 2.0 - Vec3::ONE;
                let l = v.length();
                if l > 0.1 && l <= 1.0 {
                    break v / l;
                }
            };
            p += dir * 1.5;
            // Reflect into the box.
            p = p.abs().map(|c| if c > 100.0 { 200.0 - c } else { c });
        }
    }
    let camera = box_camera(Vec3::splat(50.0), 100.0, 1920, 1080).expect("valid camera");
    NamedScene {
        name: "chains-100k".into(),
        lighting: Lighting::default_for(&camera),
        spheres: s,
        camera,
        draw_bonds: true,
    }
}

fn bench(c: &mut Criterion) {
    for s in [build(SceneId::MoleculeBallStick), chains_100k()] {
        let mut g = c.benchmark_group(format!("bonds/{}", s.name()));
        g.sample_size(10);
        for (m, bonds) in [
            (Method::Raycast, false),
            (Method::Raycast, true),
            (Method::Lut, true),
        ] {
            let mut opts = Options::new(m, s.lighting);
            opts.draw_bonds = bonds;
            let mut r = Renderer::new();
            let mut frame = Frame::new(s.camera.width(), s.camera.height(), opts.background);
            let name = format!("{}{}", m.name(), if bonds { "+bonds" } else { "" });
            g.bench_function(name, |b| {
                b.iter(|| r.render_into(&s.spheres, &s.camera, &opts, &mut frame))
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
