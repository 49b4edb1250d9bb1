//! Profiling probe for the other bench scenes (same generators as `benches/raster.rs`):
//! `cargo run --release -p texmap-raster --example scenes -- [sprites|terrain] [draws]`.
//! Prints wall-clock ms per draw on stderr; under callgrind use one draw and
//! `RAYON_NUM_THREADS=1`.

use std::time::Instant;

use glam::{Vec2, Vec3, Vec4};
use texmap_core::camera::Camera;
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::Sampler;
use texmap_raster::{Cull, DrawState, Framebuffer, Mesh, MipSampler, QuadOut, Sprite, SpriteQuad};

const W: u32 = 1920;
const H: u32 = 1080;

fn sphere_shader(id: u32, q: &SpriteQuad) -> QuadOut {
    let z = 10.0 + (id % 97) as f32 * 0.1;
    let mut out = QuadOut {
        color: [Vec3::ZERO; 4],
        depth: [0.0; 4],
        mask: 0,
    };
    for l in 0..4 {
        let u = q.s[l] * 2.0 - 1.0;
        let v = q.t[l] * 2.0 - 1.0;
        let rr = u * u + v * v;
        if rr < 1.0 {
            let nz = (1.0 - rr).sqrt();
            out.mask |= 1 << l;
            out.depth[l] = z - nz * 0.3;
            out.color[l] = Vec3::splat(0.1 + 0.9 * nz);
        }
    }
    out
}

fn main() {
    let mut args = std::env::args().skip(1);
    let scene = args.next().unwrap_or_else(|| "sprites".into());
    let draws: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(4);
    let mut fb = Framebuffer::new(W, H).expect("fb");
    let mut times = Vec::new();
    if scene == "terrain" {
        let n = 512usize;
        let mut pos = Vec::with_capacity(n * n);
        let mut uv = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let x = i as f32 - 256.0;
                let z = j as f32 - 256.0;
                let y =
                    6.0 * (x * 0.05).sin() * (z * 0.043).cos() + 2.0 * (x * 0.21 + z * 0.17).sin();
                pos.push(Vec3::new(x, y, z));
                uv.push(Vec2::new(
                    i as f32 / (n - 1) as f32,
                    j as f32 / (n - 1) as f32,
                ));
            }
        }
        let mut idx = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                let (b, c) = (a + 1, a + n as u32);
                idx.push([a, c, b]);
                idx.push([b, c, c + 1]);
            }
        }
        let cam = Camera::perspective_look_at(
            Vec3::new(0.0, 30.0, 250.0),
            Vec3::ZERO,
            Vec3::Y,
            60.0,
            W,
            H,
        )
        .expect("camera");
        let s = 2048u32;
        let mut data = Vec::with_capacity((s * s) as usize);
        for y in 0..s {
            for x in 0..s {
                let c = (((x >> 4) ^ (y >> 4)) & 1) as f32;
                data.push(Vec4::new(
                    0.2 + 0.6 * c,
                    (x & 255) as f32 / 255.0,
                    (y & 255) as f32 / 255.0,
                    1.0,
                ));
            }
        }
        let tex = MipTexture::from_linear(s, s, &data, Reduction::Box, Wrap::Repeat).expect("tex");
        let mesh = Mesh::new(&pos, &idx)
            .and_then(|m| m.with_uvs(&uv))
            .expect("mesh");
        let sampler = MipSampler {
            texture: &tex,
            sampler: Sampler::Trilinear,
        };
        let st = DrawState {
            cull: Cull::None,
            ..DrawState::default()
        };
        for _ in 0..draws {
            fb.clear([0, 0, 0, 255]);
            let t = Instant::now();
            fb.draw_textured(&cam, &mesh, &sampler, &st).expect("draw");
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    } else {
        let mut seed = 5u64;
        let mut r = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        let sprites: Vec<Sprite> = (0..100_000u32)
            .map(|id| {
                let c = Vec2::new(r() * W as f32, r() * H as f32);
                let rad = 2.0 + 6.0 * r();
                Sprite {
                    min: c - rad,
                    max: c + rad,
                    depth_min: 10.0 + (id % 97) as f32 * 0.1 - 0.3,
                    id,
                }
            })
            .collect();
        for _ in 0..draws {
            fb.clear([0, 0, 0, 255]);
            let t = Instant::now();
            fb.draw_sprites(&sprites, &sphere_shader, &DrawState::default())
                .expect("draw");
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    for t in times {
        eprintln!("{scene}: draw {t:.1} ms");
    }
    eprintln!("covered pixels: {}", fb.to_frame().coverage_count());
}
