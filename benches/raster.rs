//! Rasteriser speed on named scenes at 1920x1080 (all threads of the rayon pool):
//!
//! - `fill_large`: two flat triangles covering the whole image (fill rate);
//! - `small_tris_1m`: 1,000,000 flat-shaded triangles of ~10 px area scattered over the image at
//!   random depths (the polygon-sphere and terrain regime), depth test on;
//! - `small_tris_1m_lit`: the same with per-pixel Phong lighting (`Shading::LitSmooth`);
//! - `terrain_*`: a 512x512-vertex heightfield (522k triangles) seen from a low flight view,
//!   textured from a 2048² pyramid with texmap-core's trilinear and Seed 000 span (K = 3) samplers;
//! - `sprites_100k`: 100,000 sphere-impostor sprites (disc discard + per-fragment depth).
//!
//! Each iteration clears the framebuffer and draws the scene (no resolve to `Frame`).
//! Run: `cargo bench --bench raster -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use texmap_core::camera::Camera;
use texmap_core::glam::{Vec2, Vec3, Vec4};
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::{Banks, Sampler};
use texmap_core::shade::{Lighting, Material};
use texmap_raster::{
    Cull, DrawState, Framebuffer, Mesh, MipSampler, QuadOut, Shading, Sprite, SpriteQuad,
};

const W: u32 = 1920;
const H: u32 = 1080;

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Camera at the origin looking down −z with a 60° horizontal field of view.
fn front_camera() -> Camera {
    Camera::perspective_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 60.0, W, H)
        .unwrap()
        .with_clip(0.1, 1000.0)
        .unwrap()
}

/// `n` front-facing triangles of about `area_px` pixels each, uniformly over the image, at depths
/// 5..50 (sized in world units so their screen area is `area_px`).
fn small_triangles(n: usize, area_px: f32) -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>) {
    let cam = front_camera();
    let k = cam.scale();
    let mut r = Rng(42);
    let mut pos = Vec::with_capacity(3 * n);
    let mut nrm = Vec::with_capacity(3 * n);
    let mut idx = Vec::with_capacity(n);
    // An equilateral-ish triangle of side s has area 0.433 s².
    let side_px = (area_px / 0.433).sqrt();
    for t in 0..n {
        let depth = 5.0 + 45.0 * r.f();
        let sx = (r.f() - 0.5) * W as f32;
        let sy = (r.f() - 0.5) * H as f32;
        let c = Vec3::new(sx * depth / k, sy * depth / k, -depth);
        let s = side_px * depth / k;
        let a = r.f() * std::f32::consts::TAU;
        for j in 0..3 {
            let ang = a + j as f32 * std::f32::consts::TAU / 3.0;
            pos.push(c + Vec3::new(ang.cos(), ang.sin(), 0.0) * (s * 0.577));
            nrm.push(Vec3::new(ang.cos() * 0.5, ang.sin() * 0.5, 1.0));
        }
        let b = 3 * t as u32;
        idx.push([b, b + 1, b + 2]);
    }
    (pos, nrm, idx)
}

/// A 512x512 heightfield over [-256, 256]² (world units) with uvs over [0, 1]², seen from a low
/// flight view.
fn terrain() -> (Camera, Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>) {
    let n = 512usize;
    let mut pos = Vec::with_capacity(n * n);
    let mut uv = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let x = i as f32 - 256.0;
            let z = j as f32 - 256.0;
            let y = 6.0 * (x * 0.05).sin() * (z * 0.043).cos() + 2.0 * (x * 0.21 + z * 0.17).sin();
            pos.push(Vec3::new(x, y, z));
            uv.push(Vec2::new(
                i as f32 / (n - 1) as f32,
                j as f32 / (n - 1) as f32,
            ));
        }
    }
    let mut idx = Vec::with_capacity(2 * (n - 1) * (n - 1));
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            let b = a + 1;
            let c = a + n as u32;
            let d = c + 1;
            idx.push([a, c, b]);
            idx.push([b, c, d]);
        }
    }
    let cam = Camera::perspective_look_at(
        Vec3::new(0.0, 30.0, 250.0),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::Y,
        60.0,
        W,
        H,
    )
    .unwrap();
    (cam, pos, uv, idx)
}

fn texture() -> MipTexture {
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
    MipTexture::from_linear(s, s, &data, Reduction::Box, Wrap::Repeat).unwrap()
}

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

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("raster");
    g.sample_size(10);
    let mut fb = Framebuffer::new(W, H).unwrap();
    let state = DrawState::default();

    // Fill rate: two triangles covering the image.
    {
        let cam =
            Camera::orthographic_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 2.0, W, H)
                .unwrap();
        let e = 2.0;
        let pos = [
            Vec3::new(-e, -e, 0.0),
            Vec3::new(e, -e, 0.0),
            Vec3::new(e, e, 0.0),
            Vec3::new(-e, e, 0.0),
        ];
        let idx = [[0, 1, 2], [0, 2, 3]];
        let mesh = Mesh::new(&pos, &idx).unwrap();
        g.throughput(Throughput::Elements((W * H) as u64));
        g.bench_function("fill_large", |b| {
            b.iter(|| {
                fb.clear([0, 0, 0, 255]);
                black_box(
                    fb.draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::ONE), &state)
                        .unwrap(),
                )
            })
        });
    }

    // Many small triangles.
    {
        let cam = front_camera();
        let (pos, nrm, idx) = small_triangles(1_000_000, 10.0);
        let mesh = Mesh::new(&pos, &idx).unwrap().with_normals(&nrm).unwrap();
        let lit = Shading::LitSmooth {
            lighting: Lighting::default_for(&cam),
            material: Material::plastic(Vec3::new(0.3, 0.5, 0.8)),
        };
        g.throughput(Throughput::Elements(idx.len() as u64));
        g.bench_function("small_tris_1m", |b| {
            b.iter(|| {
                fb.clear([0, 0, 0, 255]);
                black_box(
                    fb.draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::ONE), &state)
                        .unwrap(),
                )
            })
        });
        g.bench_function("small_tris_1m_lit", |b| {
            b.iter(|| {
                fb.clear([0, 0, 0, 255]);
                black_box(fb.draw_mesh(&cam, &mesh, &lit, &state).unwrap())
            })
        });
    }

    // Textured terrain.
    {
        let (cam, pos, uv, idx) = terrain();
        let mesh = Mesh::new(&pos, &idx).unwrap().with_uvs(&uv).unwrap();
        let tex = texture();
        let st = DrawState {
            cull: Cull::None,
            ..DrawState::default()
        };
        g.throughput(Throughput::Elements(idx.len() as u64));
        for (name, sampler) in [
            ("terrain_trilinear", Sampler::Trilinear),
            ("terrain_span_k3", Sampler::Span(Banks::K3)),
        ] {
            let s = MipSampler {
                texture: &tex,
                sampler,
            };
            g.bench_function(name, |b| {
                b.iter(|| {
                    fb.clear([0, 0, 0, 255]);
                    black_box(fb.draw_textured(&cam, &mesh, &s, &st).unwrap())
                })
            });
        }
    }

    // Sprites.
    {
        let mut r = Rng(5);
        let sprites: Vec<Sprite> = (0..100_000u32)
            .map(|id| {
                let c = Vec2::new(r.f() * W as f32, r.f() * H as f32);
                let rad = 2.0 + 6.0 * r.f();
                Sprite {
                    min: c - rad,
                    max: c + rad,
                    depth_min: 10.0 + (id % 97) as f32 * 0.1 - 0.3,
                    id,
                }
            })
            .collect();
        g.throughput(Throughput::Elements(sprites.len() as u64));
        g.bench_function("sprites_100k", |b| {
            b.iter(|| {
                fb.clear([0, 0, 0, 255]);
                black_box(fb.draw_sprites(&sprites, &sphere_shader, &state).unwrap())
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
