//! The flight view at 1024 x 768 (Seed 000's 1024-pixel scanlines): a 1025² rolling terrain,
//! 10 m between samples, chunks of 65 samples at 0.5 m, a 2048² texture, seen from 300 m above
//! the ground at pitch −15° looking across the grid to its far edge.
//!
//! - `select`: the quadtree walk (frustum culling + screen-space error) alone;
//! - `select_and_gather`: plus the concatenation of the chosen chunk meshes into one mesh;
//! - `raster_only`: selection, mesh concatenation and rasterisation with a constant-colour
//!   sampler (no texture reads): the frame's cost without sampling;
//! - `trilinear`, `span3`, `span4`, `aniso`, `quadratic3`: whole frames (camera, selection,
//!   clear, draw) with each sampler; sampling costs the difference to `raster_only`.
//!   `quadratic3` (3x3 Lagrange per level on trilinear's levels, the higher-order interpolation
//!   the paper suggests) measures what it costs against trilinear.
//!
//! - `streamed/whole_db`, `streamed/streamed`: the same terrain and texture built into a database
//!   (a temporary directory), drawn with trilinear from the whole finest level and from the
//!   streamed per-chunk textures (`texmap_terrain::stream`, 512 MiB, cache warm: the steady
//!   state of a slow flight; the first frame's loads are printed).
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

fn grid_and_photo() -> (Grid, image::RgbaImage) {
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
    let img = image::RgbaImage::from_fn(2048, 2048, |x, y| {
        let c = if ((x / 32) + (y / 32)) % 2 == 0 {
            200
        } else {
            60
        };
        image::Rgba([(x / 8) as u8, c, (y / 8) as u8, 255])
    });
    (grid, img)
}

fn terrain() -> FlightTerrain {
    let (grid, img) = grid_and_photo();
    let tree = chunks::build(&grid, 0.5, 65).unwrap();
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
    {
        let sel = t.select(&cam, 1.0);
        let flat = |_: &TexQuad| [Vec3::new(0.5, 0.6, 0.4); 4];
        let d = t.draw(&cam, &sel, &flat, &mut fb, &mut scratch).unwrap();
        eprintln!(
            "raster: {} submitted, {} binned, {} back-facing, {} degenerate, {} on no pixel centre, {} clipped",
            d.submitted, d.binned, d.culled, d.degenerate, d.no_pixels, d.clipped
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
        ("quadratic3", Sampler::Quadratic3),
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

fn bench_streamed(c: &mut Criterion) {
    use texmap_terrain::db::{self, BuildOptions, Database};
    let (grid, img) = grid_and_photo();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("db");
    let photo = texmap_terrain::gst::Orthophoto {
        image: img,
        georef: None,
        source: "bench".into(),
        stretch: None,
    };
    let opts = BuildOptions {
        max_error: 0.5,
        chunk: 65,
        map_texels: 256,
        max_texture_levels: 4,
        ..Default::default()
    };
    db::build(&grid, "bench", Some(&photo), &opts, &out, |_, _| {}).unwrap();
    let db = Database::open(&out).unwrap();
    let whole = FlightTerrain::from_database(&db, 2048).unwrap();
    let streamed = FlightTerrain::from_database(&db, 1).unwrap();
    let mut stream = texmap_terrain::stream::TextureStream::new(&db, 512 << 20).unwrap();
    let view = FlightCamera {
        eye_x: 5120.0,
        eye_y: -9800.0,
        altitude: 300.0 + texmap_terrain::view::ground_height(&grid, 512.0, 980.0).unwrap(),
        heading_deg: 0.0,
        pitch_deg: -15.0,
        roll_deg: 0.0,
        hfov_deg: 45.0,
        width: 1024,
        height: 768,
    };
    let opts = ViewOptions::default();
    let mut fb = Framebuffer::new(1024, 768).unwrap();
    let mut scratch = FrameScratch::default();
    let t0 = std::time::Instant::now();
    let s = streamed
        .render_streamed(&view, &opts, &mut stream, &mut fb, &mut scratch)
        .unwrap();
    eprintln!(
        "streamed first frame: {:.1} ms, {} chunks, {:?} maps loaded, {:?} bytes resident, {:?}",
        t0.elapsed().as_secs_f64() * 1e3,
        s.chunks_drawn,
        s.maps_loaded,
        s.cache_bytes,
        stream.stats()
    );
    let mut g = c.benchmark_group("flight_1024x768_streamed");
    g.sample_size(20);
    g.bench_function("whole_db", |b| {
        b.iter(|| black_box(whole.render(&view, &opts, &mut fb, &mut scratch).unwrap()))
    });
    g.bench_function("streamed", |b| {
        b.iter(|| {
            black_box(
                streamed
                    .render_streamed(&view, &opts, &mut stream, &mut fb, &mut scratch)
                    .unwrap(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench, bench_streamed);
criterion_main!(benches);
