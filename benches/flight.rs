//! The flight view at 1024 x 768 (Seed 000's 1024-pixel scanlines): a 1025² rolling terrain,
//! 10 m between samples, chunks of 65 samples at 0.5 m, a 2048² texture, seen from 300 m above
//! the ground at pitch −15° looking across the grid to its far edge.
//!
//! - `select`: the quadtree walk (frustum culling + screen-space error) alone;
//! - `select_and_gather`: plus the concatenation of the chosen chunk meshes into one mesh;
//! - `raster_only`: selection, mesh concatenation and rasterisation with a constant-colour
//!   sampler (no texture reads): the frame's cost without sampling;
//! - `trilinear`, `span3`, `span4`, `aniso`: whole frames (camera, selection, clear, draw) with
//!   each sampler; sampling costs the difference to `raster_only`.
//!
//! Targets (issue): trilinear ≤ 16 ms on 2 cores, span3 ≤ 0.8x trilinear, aniso ≤ 3x trilinear.
//!
//!     cargo bench --bench flight

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use texmap_core::glam::Vec3;
use texmap_core::sample::{Banks, Sampler};
use texmap_raster::{Framebuffer, TexQuad};
use texmap_terrain::chunks;
use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::view::{FlightCamera, FlightTerrain, FrameScratch, ViewOptions};

fn terrain() -> FlightTerrain {
    let n = 1025u32;
    let h = (0..n * n)
        .map(|i| {
            let (x, z) = ((i % n) as f32 * 10.0, (i / n) as f32 * 10.0);
            300.0
                + 120.0 * (x / 470.0).sin() * (z / 310.0).cos()
                + 40.0 * (x / 130.0 + z / 170.0).sin()
                + 8.0 * (x / 23.0).sin() * (z / 29.0).sin()
        })
        .collect();
    let grid = Grid::new("bench hills", n, n, h, Georef::local(10.0)).unwrap();
    let tree = chunks::build(&grid, 0.5, 65).unwrap();
    let img = image::RgbaImage::from_fn(2048, 2048, |x, y| {
        let c = if ((x / 32) + (y / 32)) % 2 == 0 {
            200
        } else {
            60
        };
        image::Rgba([(x / 8) as u8, c, (y / 8) as u8, 255])
    });
    let tex = texmap_terrain::view::texture_from_rgba(&img).unwrap();
    FlightTerrain::new(grid, tree, tex)
}

fn bench(c: &mut Criterion) {
    let t = terrain();
    let view = FlightCamera {
        eye_x: 5120.0,
        eye_y: -9800.0,
        altitude: 300.0 + texmap_terrain::view::ground_height(t.grid(), 512.0, 980.0).unwrap(),
        heading_deg: 0.0,
        pitch_deg: -15.0,
        roll_deg: 0.0,
        hfov_deg: 45.0,
        width: 1024,
        height: 768,
    };
    let cam = view.camera(t.grid()).unwrap();
    let mut fb = Framebuffer::new(1024, 768).unwrap();
    let mut scratch = FrameScratch::default();
    {
        let s = t
            .render(&view, &ViewOptions::default(), &mut fb, &mut scratch)
            .unwrap();
        let f = fb.to_frame();
        eprintln!(
            "flight view: {} chunks {:?}, {} triangles ({} binned), {} of {} pixels covered",
            s.chunks_drawn,
            s.chunks_per_level,
            s.triangles,
            s.triangles_binned,
            f.coverage_count(),
            f.len()
        );
    }
    let mut g = c.benchmark_group("flight_1024x768");
    g.sample_size(20);
    g.bench_function("select", |b| b.iter(|| black_box(t.select(&cam, 1.0))));
    g.bench_function("select_and_gather", |b| {
        b.iter(|| {
            let sel = t.select(&cam, 1.0);
            black_box(t.gather(&sel, &mut scratch))
        })
    });
    let flat = |_: &TexQuad| [Vec3::new(0.5, 0.6, 0.4); 4];
    g.bench_function("raster_only", |b| {
        b.iter(|| {
            let sel = t.select(&cam, 1.0);
            fb.clear([0, 0, 0, 0]);
            black_box(t.draw(&cam, &sel, &flat, &mut fb, &mut scratch).unwrap())
        })
    });
    for (name, sampler) in [
        ("trilinear", Sampler::Trilinear),
        ("span3", Sampler::Span(Banks::K3)),
        ("span4", Sampler::Span(Banks::K4)),
        ("aniso", Sampler::Anisotropic { max_taps: 16 }),
    ] {
        let opts = ViewOptions {
            sampler,
            ..ViewOptions::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| black_box(t.render(&view, &opts, &mut fb, &mut scratch).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
