//! Streamed texturing (`texmap_terrain::stream`) against the whole-texture frame of the same
//! database: image error, no seams at chunk borders, memory under the budget, bad budgets.

use texmap_core::frame::Frame;
use texmap_core::metrics::psnr;
use texmap_raster::Framebuffer;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::gst::Orthophoto;
use texmap_terrain::stream::TextureStream;
use texmap_terrain::view::{FlightCamera, FlightTerrain, FrameScratch, ViewError, ViewOptions};

/// Rolling hills over `n x n` samples, 10 m apart.
fn hills(n: u32) -> Grid {
    let h = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32, (i / n) as f32);
            200.0 + 40.0 * (x / 30.0).sin() * (y / 40.0).cos() + 0.05 * y
        })
        .collect();
    Grid::new("hills", n, n, h, Georef::local(10.0)).unwrap()
}

fn build(
    grid: &Grid,
    photo: image::RgbaImage,
    opts: &BuildOptions,
) -> (tempfile::TempDir, Database) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("db");
    let photo = Orthophoto {
        stretch: None,
        image: photo,
        georef: None,
        source: "procedural".into(),
    };
    db::build(grid, "hills", Some(&photo), opts, &out, |_, _| {}).unwrap();
    let db = Database::open(&out).unwrap();
    (dir, db)
}

fn frames(
    whole: &FlightTerrain,
    streamed: &FlightTerrain,
    stream: &mut TextureStream,
    v: &FlightCamera,
    pixel_error: f32,
) -> (Frame, Frame, texmap_terrain::view::FrameStats) {
    let opts = ViewOptions {
        pixel_error,
        ..ViewOptions::default() // trilinear
    };
    let mut fb = Framebuffer::new(v.width, v.height).unwrap();
    let mut scratch = FrameScratch::default();
    whole.render(v, &opts, &mut fb, &mut scratch).unwrap();
    let a = fb.to_frame();
    let st = streamed
        .render_streamed(v, &opts, stream, &mut fb, &mut scratch)
        .unwrap();
    (a, fb.to_frame(), st)
}

/// Largest per-channel difference over pixels both frames cover (and whether coverage agrees).
fn max_diff(a: &Frame, b: &Frame) -> (u8, usize) {
    let mut worst = 0u8;
    let mut coverage_mismatch = 0;
    for i in 0..a.len() {
        let (ca, cb) = (a.depth[i].is_finite(), b.depth[i].is_finite());
        if ca != cb {
            coverage_mismatch += 1;
            continue;
        }
        if ca {
            for k in 0..3 {
                worst = worst.max(a.color[i][k].abs_diff(b.color[i][k]));
            }
        }
    }
    (worst, coverage_mismatch)
}

#[test]
fn streamed_matches_whole_texture_without_seams() {
    let grid = hills(257);
    // Smooth gradients: neighbouring texels differ by at most one code per channel, so a seam
    // (a chunk sampling the wrong texels at its border) shows as a jump of many codes.
    let photo = image::RgbaImage::from_fn(512, 512, |x, y| {
        let (u, v) = (x as f32 / 511.0, y as f32 / 511.0);
        image::Rgba([
            (40.0 + 200.0 * u) as u8,
            (30.0 + 200.0 * v) as u8,
            (128.0 + 90.0 * (3.0 * u + 2.0 * v).sin()) as u8,
            255,
        ])
    });
    let opts = BuildOptions {
        max_error: 0.5,
        chunk: 33,
        map_texels: 64,
        max_texture_levels: 4,
        ..Default::default()
    };
    let (_dir, db) = build(&grid, photo, &opts);
    assert_eq!(db.manifest.texture.as_ref().unwrap().levels, 4); // finest 512²
    let whole = FlightTerrain::from_database(&db, 512).unwrap();
    assert_eq!(whole.texture().width(), 512);
    let streamed = FlightTerrain::from_database(&db, 64).unwrap();
    let mut stream = TextureStream::new(&db, 64 << 20).unwrap();
    let base = FlightCamera {
        width: 320,
        height: 240,
        ..FlightCamera::over(&grid)
    };
    let mut mixed = 0;
    let corner = FlightCamera {
        eye_x: 50.0,
        eye_y: -50.0,
        altitude: 600.0,
        ..base.clone()
    };
    for (heading, pitch, alt, width, v0) in [
        (0.0, -30.0, 0.0, 320, &base),
        (60.0, -12.0, -300.0, 320, &base),
        (200.0, -60.0, 200.0, 320, &base),
        // Across the diagonal from a corner, in a smaller image: far chunks are drawn from
        // coarser levels than near ones.
        (135.0, -10.0, 0.0, 160, &corner),
        (120.0, -14.0, 0.0, 200, &corner),
    ] {
        let v = FlightCamera {
            heading_deg: heading,
            pitch_deg: pitch,
            altitude: v0.altitude + alt,
            width,
            height: width * 3 / 4,
            ..v0.clone()
        };
        let (a, b, st) = frames(&whole, &streamed, &mut stream, &v, 0.1);
        assert!(st.chunks_drawn > 4, "{st:?}");
        assert!(st.maps_loaded.is_some() && st.chunk_texture_bytes.is_some());
        let p = psnr(&a, &b).unwrap();
        let (worst, mismatch) = max_diff(&a, &b);
        assert_eq!(mismatch, 0, "same geometry, same coverage");
        eprintln!(
            "heading {heading}: PSNR {p:.1} dB, worst {worst}, {:?}",
            stream.stats()
        );
        let ss = stream.stats();
        if ss.coarsest_level < ss.finest_level {
            mixed += 1;
        }
        assert!(p > 40.0, "heading {heading}: PSNR {p:.1} dB");
        assert!(
            worst <= 8,
            "heading {heading}: a pixel differs by {worst} codes"
        );
    }
    assert!(mixed >= 1, "some frame mixes levels");
    // The same frame again loads nothing new.
    let v = base.clone();
    let (_, _, st) = frames(&whole, &streamed, &mut stream, &v, 0.1);
    let (_, _, st2) = frames(&whole, &streamed, &mut stream, &v, 0.1);
    assert_eq!(st2.maps_loaded, Some(0));
    assert_eq!(st.chunk_texture_bytes, st2.chunk_texture_bytes);
    // Same bytes on one thread as on several, from a cold stream.
    let render_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut s = TextureStream::new(&db, 64 << 20).unwrap();
            let mut fb = Framebuffer::new(v.width, v.height).unwrap();
            streamed
                .render_streamed(
                    &v,
                    &ViewOptions::default(),
                    &mut s,
                    &mut fb,
                    &mut FrameScratch::default(),
                )
                .unwrap();
            fb.to_frame()
        })
    };
    let (one, four) = (render_on(1), render_on(4));
    assert_eq!(one.color, four.color);
    assert_eq!(one.depth, four.depth);
}

#[test]
fn streamed_stays_within_a_budget_the_whole_texture_exceeds() {
    // A 2048² photo-like texture (sums of sines at several scales): its whole mip pyramid is
    // 2048² x 16 B x 4/3 ≈ 89 MB; the stream gets 16 MB.
    let grid = hills(1025);
    let photo = image::RgbaImage::from_fn(2048, 2048, |x, y| {
        let (u, v) = (x as f32, y as f32);
        let n = (u / 97.0).sin() * (v / 131.0).cos()
            + 0.5 * (u / 23.0 + v / 41.0).sin()
            + 0.25 * (u / 5.3).sin() * (v / 7.1).sin();
        let t = 0.5 + 0.28 * n;
        image::Rgba([
            (255.0 * t * 0.8) as u8,
            (255.0 * t) as u8,
            (255.0 * (1.0 - t) * 0.6) as u8,
            255,
        ])
    });
    let opts = BuildOptions {
        max_error: 1.0,
        chunk: 65,
        map_texels: 256,
        max_texture_levels: 4,
        ..Default::default()
    };
    let (_dir, db) = build(&grid, photo, &opts);
    let whole = FlightTerrain::from_database(&db, 2048).unwrap();
    let whole_bytes = std::mem::size_of_val(whole.texture().texels()) as u64;
    let budget = 16u64 << 20;
    assert!(whole_bytes > 5 * budget, "{whole_bytes}");
    let streamed = FlightTerrain::from_database(&db, 256).unwrap();
    let mut stream = TextureStream::new(&db, budget).unwrap();
    let base = FlightCamera {
        width: 512,
        height: 384,
        ..FlightCamera::over(&grid)
    };
    let mut loaded = 0;
    for (i, heading) in [0.0, 45.0, 90.0, 135.0].into_iter().enumerate() {
        let v = FlightCamera {
            heading_deg: heading,
            pitch_deg: -20.0,
            ..base.clone()
        };
        let (a, b, st) = frames(&whole, &streamed, &mut stream, &v, 1.0);
        let bytes = st.cache_bytes.unwrap();
        assert!(bytes <= budget, "frame {i}: {bytes} bytes resident");
        assert!(
            st.texture_side == 2048,
            "the finest level is drawn near the eye: {st:?}"
        );
        loaded += st.maps_loaded.unwrap();
        let p = psnr(&a, &b).unwrap();
        eprintln!("frame {i}: PSNR {p:.1} dB, {st:?}");
        assert!(p > 30.0, "frame {i}: PSNR {p:.1} dB");
    }
    assert!(loaded > 0);
    let s = stream.stats();
    assert!(s.chunk_textures_evicted > 0, "turning around evicts: {s:?}");
    // A budget too small for the levels Eq. (7) asks for: chunks fall back to coarser levels,
    // the frame stays within the budget and close to the whole-texture frame.
    let small = 4u64 << 20;
    let mut stream = TextureStream::new(&db, small).unwrap();
    let v = FlightCamera {
        pitch_deg: -20.0,
        ..base.clone()
    };
    let (a, b, st) = frames(&whole, &streamed, &mut stream, &v, 1.0);
    let s = stream.stats();
    assert!(s.chunks_fallen_back > 0 && s.finest_level < 3, "{s:?}");
    assert!(st.cache_bytes.unwrap() <= small, "{st:?}");
    let p = psnr(&a, &b).unwrap();
    eprintln!("fallback: PSNR {p:.1} dB, {s:?}");
    assert!(p > 20.0, "fallback PSNR {p:.1} dB");
}

#[test]
fn budgets_too_small_are_errors() {
    let grid = hills(129);
    let photo =
        image::RgbaImage::from_fn(128, 128, |x, y| image::Rgba([x as u8, y as u8, 90, 255]));
    let opts = BuildOptions {
        max_error: 0.5,
        chunk: 17,
        map_texels: 64,
        max_texture_levels: 2,
        ..Default::default()
    };
    let (_dir, db) = build(&grid, photo, &opts);
    // Not even one map and one level-0 texture.
    match TextureStream::new(&db, 1000) {
        Err(e @ ViewError::TextureBudget { .. }) => {
            assert!(e.to_string().contains("too small"), "{e}")
        }
        other => panic!("expected a budget error, got {:?}", other.err()),
    }
    // Enough to open, not enough for a frame's chunks even at level 0.
    let t = FlightTerrain::from_database(&db, 64).unwrap();
    let mut stream = TextureStream::new(&db, 160 << 10).unwrap();
    let v = FlightCamera {
        width: 160,
        height: 120,
        ..FlightCamera::over(&grid)
    };
    let mut fb = Framebuffer::new(160, 120).unwrap();
    let r = t.render_streamed(
        &v,
        &ViewOptions::default(),
        &mut stream,
        &mut fb,
        &mut FrameScratch::default(),
    );
    assert!(matches!(r, Err(ViewError::TextureBudget { .. })), "{r:?}");
    // A database without a photo has nothing to stream.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bare");
    db::build(&grid, "bare", None, &opts, &out, |_, _| {}).unwrap();
    let bare = Database::open(&out).unwrap();
    assert!(TextureStream::new(&bare, 1 << 30).is_err());
}

/// Builds a large database for measuring a streamed flight by hand (not run by default):
/// `TEXMAP_STREAM_DB=DIR TEXMAP_STREAM_SIDE=8193 cargo test --release -p texmap-terrain --test
/// stream -- --ignored big_database` writes an analytic `SIDE²` DEM (10 m) with a procedural
/// photo of `2·(SIDE − 1)` texels a side, GST levels up to one texel per sample (the finest
/// `256·2^⌈log2(SIDE/256)⌉` a side), then `texmap terrain fly DIR --texture streamed ...`.
#[test]
#[ignore]
fn big_database() {
    use rayon::prelude::*;
    let (Ok(dir), side) = (
        std::env::var("TEXMAP_STREAM_DB"),
        std::env::var("TEXMAP_STREAM_SIDE")
            .ok()
            .and_then(|s| s.parse::<u32>().ok())
            .unwrap_or(8193),
    ) else {
        eprintln!("set TEXMAP_STREAM_DB to the output directory");
        return;
    };
    let t0 = std::time::Instant::now();
    let n = side as usize;
    let mut h = vec![0f32; n * n];
    h.par_chunks_mut(n).enumerate().for_each(|(r, row)| {
        for (c, v) in row.iter_mut().enumerate() {
            let (x, z) = (c as f32 * 10.0, r as f32 * 10.0);
            *v = 300.0
                + 120.0 * (x / 4700.0).sin() * (z / 3100.0).cos()
                + 40.0 * (x / 1300.0 + z / 1700.0).sin()
                + 8.0 * (x / 230.0).sin() * (z / 290.0).sin();
        }
    });
    let grid = Grid::new("big", side, side, h, Georef::local(10.0)).unwrap();
    let p = 2 * (side - 1);
    let mut raw = vec![0u8; 4 * p as usize * p as usize];
    raw.par_chunks_mut(4 * p as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, px) in row.chunks_exact_mut(4).enumerate() {
                let (u, v) = (x as f32, y as f32);
                let t = 0.5
                    + 0.28
                        * ((u / 970.0).sin() * (v / 1310.0).cos()
                            + 0.5 * (u / 230.0 + v / 410.0).sin()
                            + 0.25 * (u / 5.3).sin() * (v / 7.1).sin());
                px.copy_from_slice(&[
                    (255.0 * t * 0.8) as u8,
                    (255.0 * t) as u8,
                    (255.0 * (1.0 - t) * 0.6) as u8,
                    255,
                ]);
            }
        });
    let photo = Orthophoto {
        stretch: None,
        image: image::RgbaImage::from_raw(p, p, raw).unwrap(),
        georef: None,
        source: "procedural".into(),
    };
    eprintln!("generated in {:.1} s", t0.elapsed().as_secs_f64());
    let opts = BuildOptions {
        max_error: 1.0,
        chunk: 257,
        map_texels: 256,
        max_texture_levels: 8,
        ..Default::default()
    };
    let m = db::build(
        &grid,
        "big",
        Some(&photo),
        &opts,
        std::path::Path::new(&dir),
        |_, _| {},
    )
    .unwrap();
    eprintln!(
        "built in {:.1} s: {:?}",
        t0.elapsed().as_secs_f64(),
        m.texture
    );
}
