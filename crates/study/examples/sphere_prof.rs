//! Profiling driver on texmap-study's canonical scenes (the ones `benches/spheres.rs` measures):
//!
//! `cargo run --release -p texmap-study --example sphere_prof -- <s1|s2|s3|empty> <method> [iters]`
//!
//! renders the scene `iters` times (after one untimed frame that builds the tables) and prints
//! the wall and CPU time per frame and the covered fraction. `empty` is S1's camera with no
//! sphere: the fixed per-frame cost at 500x500. For instruction counts per stage run it under
//! callgrind, collecting inside the frames only:
//!
//! `valgrind --tool=callgrind --toggle-collect='*Renderer*render_into*' <binary> s1 raycast 5`
//!
//! The printed `hash` (FNV-1a over the colour bytes and the depth bits of the last frame) shows
//! whether an optimisation changed any output byte: compare it before and after.

use std::time::Instant;
use texmap_core::frame::Frame;
use texmap_impostor::{Method, Options, Renderer, SphereScene};
use texmap_study::scenes::{SceneId, build};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("s2");
    let Some(method) = Method::from_name(args.get(2).map(String::as_str).unwrap_or("raycast"))
    else {
        eprintln!("method: polygon, lut, template or raycast");
        std::process::exit(2);
    };
    let iters: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(10);
    let (id, empty) = match name {
        "empty" => (SceneId::S1, true),
        n => match SceneId::from_name(&n.to_lowercase()) {
            Some(id) => (id, false),
            None => {
                eprintln!("scene: s1, s2, s3, molecule or empty");
                std::process::exit(2);
            }
        },
    };
    let mut s = build(id);
    if empty {
        s.spheres = SphereScene::new(s.spheres.materials.clone());
    }
    let (w, h) = (s.camera.width(), s.camera.height());
    let opts = Options::new(method, s.lighting);
    let mut rend = Renderer::new();
    let mut frame = Frame::new(w, h, opts.background);
    let st = rend.render_into(&s.spheres, &s.camera, &opts, &mut frame);
    let cpu0 = cpu_ms();
    let t = Instant::now();
    for _ in 0..iters {
        rend.render_into(&s.spheres, &s.camera, &opts, &mut frame);
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / iters.max(1) as f64;
    let cpu = (cpu_ms() - cpu0) / iters.max(1) as f64;
    println!(
        "{name} {} {ms:.3} ms/frame wall, {cpu:.2} ms/frame CPU (all threads), coverage {:.3}, hash {:016x}, {st:?}",
        method.name(),
        frame.coverage_count() as f64 / frame.len() as f64,
        frame_hash(&frame)
    );
}

/// FNV-1a over the colour bytes and the depth bit patterns.
fn frame_hash(f: &Frame) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |b: u8| {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    };
    for px in &f.color {
        px.iter().for_each(|&b| eat(b));
    }
    for d in &f.depth {
        d.to_bits().to_le_bytes().iter().for_each(|&b| eat(b));
    }
    h
}

/// User + system CPU time of this process in ms (Linux `/proc/self/stat`, 10 ms ticks).
fn cpu_ms() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11).and_then(|v| v.parse().ok()).unwrap_or(0.0)
        + f.get(12).and_then(|v| v.parse().ok()).unwrap_or(0.0);
    ticks * 10.0
}
