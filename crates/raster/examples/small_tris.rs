//! Timing and profiling probe for the many-small-triangles path: 1M triangles of ~10 px at
//! 1080p, the scene of the `small_tris_1m` bench (same generator, same seed).
//!
//! `cargo run --release -p texmap-raster --example small_tris -- [flat|lit] [draws]`
//! prints wall-clock ms per draw on stderr. Under callgrind use one draw and
//! `RAYON_NUM_THREADS=1`.

use std::time::Instant;

use glam::Vec3;
use texmap_core::camera::Camera;
use texmap_core::shade::{Lighting, Material};
use texmap_raster::{DrawState, Framebuffer, Mesh, Shading};

fn main() {
    let mut args = std::env::args().skip(1);
    let lit = args.next().is_some_and(|a| a == "lit");
    let draws: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(8);
    let (w, h) = (1920u32, 1080u32);
    let cam = Camera::perspective_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 60.0, w, h)
        .and_then(|c| c.with_clip(0.1, 1000.0))
        .expect("camera");
    let k = cam.scale();
    let mut s = 42u64;
    let mut r = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let n = 1_000_000usize;
    let side_px = (10.0f32 / 0.433).sqrt();
    let mut pos = Vec::with_capacity(3 * n);
    let mut nrm = Vec::with_capacity(3 * n);
    let mut idx = Vec::with_capacity(n);
    for t in 0..n {
        let depth = 5.0 + 45.0 * r();
        let sx = (r() - 0.5) * w as f32;
        let sy = (r() - 0.5) * h as f32;
        let c = Vec3::new(sx * depth / k, sy * depth / k, -depth);
        let sz = side_px * depth / k * 0.577;
        let a = r() * std::f32::consts::TAU;
        for j in 0..3 {
            let ang = a + j as f32 * std::f32::consts::TAU / 3.0;
            pos.push(c + Vec3::new(ang.cos(), ang.sin(), 0.0) * sz);
            nrm.push(Vec3::new(ang.cos() * 0.5, ang.sin() * 0.5, 1.0));
        }
        idx.push([3 * t as u32, 3 * t as u32 + 1, 3 * t as u32 + 2]);
    }
    let mesh = Mesh::new(&pos, &idx)
        .and_then(|m| m.with_normals(&nrm))
        .expect("mesh");
    let shading = if lit {
        Shading::LitSmooth {
            lighting: Lighting::default_for(&cam),
            material: Material::plastic(Vec3::new(0.3, 0.5, 0.8)),
        }
    } else {
        Shading::Flat(Vec3::ONE)
    };
    let mut fb = Framebuffer::new(w, h).expect("fb");
    let mut times = Vec::new();
    for _ in 0..draws {
        let t0 = Instant::now();
        fb.clear([0, 0, 0, 255]);
        let t1 = Instant::now();
        let st = fb
            .draw_mesh(&cam, &mesh, &shading, &DrawState::default())
            .expect("draw");
        let t2 = Instant::now();
        times.push((
            (t1 - t0).as_secs_f64() * 1e3,
            (t2 - t1).as_secs_f64() * 1e3,
            st.binned,
        ));
    }
    for (c, d, b) in times {
        eprintln!("clear {c:.1} ms  draw {d:.1} ms  ({b} binned)");
    }
    let f = fb.to_frame();
    eprintln!("covered pixels: {}", f.coverage_count());
}
