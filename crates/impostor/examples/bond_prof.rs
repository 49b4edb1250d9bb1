//! Profiling driver of the bond pass on the two scenes `benches/bonds.rs` measures:
//!
//! `cargo run --release -p texmap-impostor --example bond_prof -- <molecule-bs|chains> [iters] [nobonds]`
//!
//! renders the scene `iters` times (after one untimed frame) and prints the wall time per frame
//! and the stats. `chains` is the bench's chains-100k (1,000 random-walk chains of 100 atoms,
//! 99,000 bonds, 1920x1080). For instruction counts of the bond pass alone run it under
//! callgrind, collecting inside the bond pass only:
//!
//! `valgrind --tool=callgrind --toggle-collect='*bonds*' <binary> chains 1`

use std::time::Instant;
use texmap_core::frame::Frame;
use texmap_core::glam::Vec3;
use texmap_core::shade::{Lighting, Material};
use texmap_impostor::{Method, Options, Renderer, SphereScene};
use texmap_study::scenes::{NamedScene, SceneId, box_camera, build};

/// The bench's chains-100k: random walks of step 1.5 reflected into the box `[0, 100]³`.
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
            let dir = loop {
                let v = Vec3::new(next(), next(), next()) * 2.0 - Vec3::ONE;
                let l = v.length();
                if l > 0.1 && l <= 1.0 {
                    break v / l;
                }
            };
            p += dir * 1.5;
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

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("chains");
    let iters: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let bonds = args.get(3).map(String::as_str) != Some("nobonds");
    let s = match name {
        "chains" => chains_100k(),
        _ => build(SceneId::MoleculeBallStick),
    };
    let mut opts = Options::new(Method::Raycast, s.lighting);
    opts.draw_bonds = bonds;
    let mut rend = Renderer::new();
    let mut frame = Frame::new(s.camera.width(), s.camera.height(), opts.background);
    let st = rend.render_into(&s.spheres, &s.camera, &opts, &mut frame);
    let t = Instant::now();
    for _ in 0..iters {
        rend.render_into(&s.spheres, &s.camera, &opts, &mut frame);
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / iters.max(1) as f64;
    // FNV-1a of the colour and depth bytes: the same image gives the same hash.
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    let bytes = frame
        .color
        .iter()
        .flatten()
        .copied()
        .chain(frame.depth.iter().flat_map(|d| d.to_le_bytes()));
    for byte in bytes {
        hash = (hash ^ byte as u64).wrapping_mul(0x100_0000_01b3);
    }
    println!(
        "{} bonds={bonds} {ms:.3} ms/frame wall, coverage {:.4}, image hash {hash:016x}, {st:?}",
        s.name,
        frame.coverage_count() as f64 / frame.len() as f64
    );
}
