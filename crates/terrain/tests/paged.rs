//! Paged terrains (`FlightTerrain::open`): chunk meshes read from the database's files on demand
//! under a byte budget and the grid mapped, against the same terrain held in memory (the quadtree
//! rebuilt from the grid): identical selections and frames byte for byte, the cache's counters,
//! and damaged chunk files.

use texmap_raster::Framebuffer;
use texmap_terrain::chunks;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::gst::Orthophoto;
use texmap_terrain::stream::TextureStream;
use texmap_terrain::view::{
    self, FlightCamera, FlightTerrain, FrameScratch, ViewError, ViewOptions, sampler_by_name,
};

/// Rolling hills over `n x n` samples, 10 m apart, with a no-data hole.
fn hills(n: u32) -> Grid {
    let h = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32, (i / n) as f32);
            if (x - 40.0).hypot(y - 200.0) < 6.0 {
                f32::NAN
            } else {
                150.0 + 35.0 * (x / 23.0).sin() * (y / 31.0).cos() + 0.08 * y
            }
        })
        .collect();
    Grid::new("hills", n, n, h, Georef::local(10.0)).unwrap()
}

fn photo() -> Orthophoto {
    Orthophoto {
        stretch: None,
        image: image::RgbaImage::from_fn(512, 512, |x, y| {
            image::Rgba([(x / 2) as u8, (y / 2) as u8, ((x ^ y) & 0xff) as u8, 255])
        }),
        georef: None,
        source: "procedural".into(),
    }
}

fn build(grid: &Grid) -> (tempfile::TempDir, Database) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("db");
    let opts = BuildOptions {
        max_error: 0.5,
        chunk: 33,
        ..BuildOptions::default()
    };
    db::build(grid, "hills", Some(&photo()), &opts, &out, |_, _| {}).unwrap();
    (dir, Database::open(&out).unwrap())
}

/// The same database held in memory: grid read, quadtree rebuilt, the same texture.
fn resident(db: &Database, max_texture: u32) -> FlightTerrain {
    let grid = db.grid().unwrap();
    let tree = chunks::build(&grid, db.manifest.max_error, db.manifest.chunk).unwrap();
    let img = db.texture(max_texture).unwrap().unwrap();
    FlightTerrain::new(grid, tree, view::texture_from_rgba(&img).unwrap())
}

/// A slow pass north over the hills, low and grazing, then a steep look down and a turn.
fn views() -> Vec<FlightCamera> {
    let base = FlightCamera {
        eye_x: 1280.0,
        eye_y: -2500.0,
        altitude: 260.0,
        heading_deg: 0.0,
        pitch_deg: -12.0,
        roll_deg: 0.0,
        hfov_deg: 45.0,
        width: 256,
        height: 192,
    };
    let mut v: Vec<FlightCamera> = (0..6)
        .map(|i| FlightCamera {
            eye_y: -2500.0 + 300.0 * i as f64,
            ..base
        })
        .collect();
    v.push(FlightCamera {
        pitch_deg: -90.0,
        altitude: 600.0,
        ..base
    });
    v.push(FlightCamera {
        heading_deg: 120.0,
        roll_deg: 15.0,
        eye_y: -1200.0,
        ..base
    });
    v
}

#[test]
fn paged_frames_are_the_resident_frames_byte_for_byte() {
    let grid = hills(257);
    let (_dir, db) = build(&grid);
    assert!(
        db.manifest
            .levels
            .iter()
            .all(|l| l.chunks.iter().all(|c| c.bounds.is_some()))
    );
    let whole = resident(&db, 512);
    // A budget far under the whole tree, so chunks are evicted and read again along the path.
    let paged = FlightTerrain::open(&db, 512, 64 << 10).unwrap();
    assert!(paged.is_paged() && !whole.is_paged());
    assert_eq!(paged.max_depth(), whole.max_depth());
    // The same chunks with the same errors and boxes (only the file names differ).
    for (a, b) in paged.levels().iter().zip(whole.levels()) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert_eq!(
                (x.ix, x.iy, x.geometric_error, x.bounds),
                (y.ix, y.iy, y.geometric_error, y.bounds)
            );
        }
    }
    // The mapped grid is the grid.
    let bits = |g: &Grid| g.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
    assert!(bits(paged.grid()) == bits(&grid));
    assert_eq!(paged.grid().height_range(), grid.height_range());

    let mut fa = Framebuffer::new(256, 192).unwrap();
    let mut fb = Framebuffer::new(256, 192).unwrap();
    let (mut sa, mut sb) = (FrameScratch::default(), FrameScratch::default());
    let mut drawn = 0;
    for name in ["trilinear", "span3"] {
        let opts = ViewOptions {
            sampler: sampler_by_name(name).unwrap(),
            ..ViewOptions::default()
        };
        for v in views() {
            let a = whole.render(&v, &opts, &mut fa, &mut sa).unwrap();
            let b = paged.render(&v, &opts, &mut fb, &mut sb).unwrap();
            assert_eq!(a.chunks_per_level, b.chunks_per_level);
            assert_eq!(a.triangles, b.triangles);
            assert!(a.chunk_cache.is_none());
            let cache = b.chunk_cache.unwrap();
            // The cache keeps at most this frame's chunks beyond its budget.
            let frame_bytes: u64 = paged
                .select(&v.camera(paged.grid()).unwrap(), 1.0)
                .chunks
                .iter()
                .map(|c| {
                    let m = paged.mesh(*c).unwrap();
                    (m.positions.len() * 20 + m.triangles.len() * 12) as u64
                })
                .sum();
            assert!(cache.resident_bytes <= (64 << 10) + frame_bytes);
            let (x, y) = (fa.to_frame(), fb.to_frame());
            assert!(x.color == y.color && x.depth == y.depth, "{name} {v:?}");
            drawn += x.depth.iter().filter(|d| d.is_finite()).count();
        }
    }
    assert!(drawn > 8 * 256 * 192 / 2, "the views see terrain");
    let c = paged.chunk_cache().unwrap();
    assert!(c.loads > 0 && c.hits > 0 && c.evictions > 0, "{c:?}");
    // Loads never exceed what the frames selected, and every selection was served.
    assert!(c.loads + c.hits >= c.loads);
}

#[test]
fn a_generous_budget_reads_each_chunk_once() {
    let grid = hills(129);
    let (_dir, db) = build(&grid);
    let paged = FlightTerrain::open(&db, 256, u64::MAX).unwrap();
    let mut fb = Framebuffer::new(256, 192).unwrap();
    let mut s = FrameScratch::default();
    let mut selected = std::collections::HashSet::new();
    let views: Vec<FlightCamera> = views()
        .into_iter()
        .map(|v| FlightCamera {
            eye_x: 640.0,
            eye_y: -1200.0 + (v.eye_y + 2500.0) / 3.0,
            altitude: 260.0,
            ..v
        })
        .collect();
    for _ in 0..2 {
        for v in &views {
            paged
                .render(v, &ViewOptions::default(), &mut fb, &mut s)
                .unwrap();
            let cam = v.camera(paged.grid()).unwrap();
            selected.extend(paged.select(&cam, 1.0).chunks);
        }
    }
    let c = paged.chunk_cache().unwrap();
    assert_eq!(c.loads, selected.len() as u64);
    assert_eq!(c.evictions, 0);
    assert_eq!(c.resident, selected.len() as u64);
}

#[test]
fn streamed_textures_over_paged_chunks_match_resident_chunks() {
    let grid = hills(257);
    let (_dir, db) = build(&grid);
    let whole = resident(&db, 512);
    let paged = FlightTerrain::open(&db, 256, 32 << 10).unwrap();
    let mut stream_a = TextureStream::new(&db, 8 << 20).unwrap();
    let mut stream_b = TextureStream::new(&db, 8 << 20).unwrap();
    let mut fa = Framebuffer::new(256, 192).unwrap();
    let mut fb = Framebuffer::new(256, 192).unwrap();
    let (mut sa, mut sb) = (FrameScratch::default(), FrameScratch::default());
    let opts = ViewOptions::default();
    for v in views() {
        whole
            .render_streamed(&v, &opts, &mut stream_a, &mut fa, &mut sa)
            .unwrap();
        let st = paged
            .render_streamed(&v, &opts, &mut stream_b, &mut fb, &mut sb)
            .unwrap();
        assert!(st.chunk_cache.is_some());
        let (x, y) = (fa.to_frame(), fb.to_frame());
        assert!(x.color == y.color && x.depth == y.depth, "{v:?}");
    }
}

#[test]
fn an_older_manifest_without_boxes_opens_in_memory() {
    let grid = hills(129);
    let (_dir, db) = build(&grid);
    let path = db.dir.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for l in m["levels"].as_array_mut().unwrap() {
        for c in l["chunks"].as_array_mut().unwrap() {
            c.as_object_mut().unwrap().remove("bounds");
        }
    }
    std::fs::write(&path, serde_json::to_vec(&m).unwrap()).unwrap();
    let old = Database::open(&db.dir).unwrap();
    let t = FlightTerrain::from_database(&old, 256).unwrap();
    assert!(!t.is_paged());
    let paged = FlightTerrain::open(&db, 256, u64::MAX).unwrap();
    assert!(paged.is_paged());
    let v = FlightCamera {
        width: 200,
        height: 150,
        ..FlightCamera::over(t.grid())
    };
    let mut fa = Framebuffer::new(200, 150).unwrap();
    let mut fb = Framebuffer::new(200, 150).unwrap();
    let opts = ViewOptions::default();
    t.render(&v, &opts, &mut fa, &mut FrameScratch::default())
        .unwrap();
    paged
        .render(&v, &opts, &mut fb, &mut FrameScratch::default())
        .unwrap();
    assert_eq!(fa.to_frame().color, fb.to_frame().color);
}

/// Render the default view of a freshly opened paged terrain (so every chunk is read).
fn render_fresh(db: &Database) -> Result<(), ViewError> {
    let t = FlightTerrain::open(db, 256, u64::MAX)?;
    let v = FlightCamera {
        width: 128,
        height: 96,
        ..FlightCamera::over(t.grid())
    };
    let mut fb = Framebuffer::new(128, 96)?;
    t.render(
        &v,
        &ViewOptions::default(),
        &mut fb,
        &mut FrameScratch::default(),
    )?;
    Ok(())
}

#[test]
fn damaged_chunk_files_are_named_errors() {
    let grid = hills(129);
    let (_dir, db) = build(&grid);
    // Damage every chunk file, so whatever the default view selects meets one.
    let files: Vec<String> = db
        .manifest
        .levels
        .iter()
        .flat_map(|l| l.chunks.iter().map(|c| c.file.clone()))
        .collect();
    let originals: Vec<Vec<u8>> = files
        .iter()
        .map(|f| std::fs::read(db.dir.join(f)).unwrap())
        .collect();
    let restore = || {
        for (f, b) in files.iter().zip(&originals) {
            std::fs::write(db.dir.join(f), b).unwrap();
        }
    };
    let damage = |f: &dyn Fn(&mut Vec<u8>)| {
        for (name, b) in files.iter().zip(&originals) {
            let mut b = b.clone();
            f(&mut b);
            std::fs::write(db.dir.join(name), b).unwrap();
        }
    };
    render_fresh(&db).unwrap();

    // Truncated: the counts no longer match the length.
    damage(&|b| b.truncate(b.len() - 7));
    let e = render_fresh(&db).unwrap_err().to_string();
    assert!(
        e.contains(".bin") && e.contains("byte 8") && e.contains("bytes for"),
        "{e}"
    );
    // A wrong magic.
    damage(&|b| b[0] = b'X');
    let e = render_fresh(&db).unwrap_err().to_string();
    assert!(e.contains("TMCK") && e.contains("byte 0"), "{e}");
    // A header claiming 2^32 - 1 vertices: refused before anything is allocated.
    damage(&|b| b[8..12].copy_from_slice(&u32::MAX.to_le_bytes()));
    let e = render_fresh(&db).unwrap_err().to_string();
    assert!(e.contains("4294967295 vertices"), "{e}");
    // A triangle index past the vertices.
    damage(&|b| {
        let n = b.len();
        b[n - 4..].copy_from_slice(&1_000_000u32.to_le_bytes());
    });
    let e = render_fresh(&db).unwrap_err().to_string();
    assert!(
        e.contains("vertex indices below") && e.contains("1000000"),
        "{e}"
    );
    // A NaN position.
    damage(&|b| b[20..24].copy_from_slice(&f32::NAN.to_le_bytes()));
    let e = render_fresh(&db).unwrap_err().to_string();
    assert!(
        e.contains("byte 20") && e.contains("finite position"),
        "{e}"
    );
    restore();
    render_fresh(&db).unwrap();

    // A manifest pointing outside the directory.
    let path = db.dir.join("manifest.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("\"chunks/", "\"../../chunks/")).unwrap();
    let bad = Database::open(&db.dir).unwrap();
    let e = render_fresh(&bad).unwrap_err().to_string();
    assert!(e.contains("inside the database directory"), "{e}");
    std::fs::write(&path, text).unwrap();

    // A grid file of the wrong size.
    let g = db.dir.join("grid.f32");
    let bytes = std::fs::read(&g).unwrap();
    std::fs::write(&g, &bytes[..bytes.len() - 4]).unwrap();
    let e = render_fresh(&db).unwrap_err().to_string();
    assert!(e.contains("grid.f32") && e.contains("file size"), "{e}");
}
