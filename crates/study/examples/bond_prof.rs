//! Profiling driver of the bond pass on the two scenes `benches/bonds.rs` measures:
//!
//! `cargo run --release -p texmap-study --example bond_prof -- <molecule-bs|chains> [iters] [nobonds]`
//!
//! renders the scene `iters` times (after one untimed frame) and prints the wall time per frame
//! and the stats. `chains` is the bench's chains-100k (1,000 random-walk chains of 100 atoms,
//! 99,000 bonds, 1920x1080). For instruction counts of the bond pass alone run it under
//! callgrind, collecting inside the bond pass only:
//!
//! `valgrind --tool=callgrind --toggle-collect='*bonds*' <binary> chains 1`

use std::time::Instant;
use texmap_core::frame::Frame;
use texmap_impostor::{Method, Options, Renderer};
use texmap_study::scenes::{SceneId, build, chains_100k};

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
