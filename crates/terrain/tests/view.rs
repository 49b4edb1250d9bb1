//! The flight view against analytic expectations: a checkerboard photo on a plane seen from
//! several poses (each pixel's colour from an independent ray–plane intersection), chunk
//! selection against its refinement rule, no background through the terrain where chunks of
//! different depths meet, determinism across thread counts, and the camera's errors.

use glam::{DVec3, Vec3};
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::{Banks, Sampler};
use texmap_raster::Framebuffer;
use texmap_terrain::chunks::{self, screen_space_error};
use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::view::{
    ChunkRef, FlightCamera, FlightTerrain, FrameScratch, SAMPLER_NAMES, ViewError, ViewOptions,
    sampler_by_name,
};

const CHECK: u32 = 16;

/// A flat grid at `z0` metres, 257², 1 m spacing, with a 256² black/white checkerboard of
/// 16-texel squares: texel `i` covers `[i, i+1)` metres.
fn checker_plane(z0: f32) -> FlightTerrain {
    let n = 257;
    let grid = Grid::new(
        "plane",
        n,
        n,
        vec![z0; (n * n) as usize],
        Georef::local(1.0),
    )
    .unwrap();
    let tree = chunks::build(&grid, 0.01, 33).unwrap();
    let mut data = Vec::with_capacity(256 * 256 * 4);
    for y in 0..256u32 {
        for x in 0..256u32 {
            let v = if (x / CHECK + y / CHECK).is_multiple_of(2) {
                255
            } else {
                0
            };
            data.extend_from_slice(&[v, v, v, 255]);
        }
    }
    let tex =
        MipTexture::from_srgb8(256, 256, &data, Reduction::GammaCorrect, Wrap::Clamp).unwrap();
    FlightTerrain::new(grid, tree, tex)
}

/// Where the ray through screen point `(sx, sy)` meets the plane `y = z0`, as (east, south)
/// metres, from heading/pitch/roll written out independently of the library's camera.
fn plane_hit(v: &FlightCamera, z0: f64, sx: f64, sy: f64) -> Option<(f64, f64)> {
    let (h, p, r) = (
        v.heading_deg.to_radians(),
        v.pitch_deg.to_radians(),
        v.roll_deg.to_radians(),
    );
    // North is −z, east +x; heading turns from north toward east.
    let fwd = DVec3::new(h.sin() * p.cos(), p.sin(), -h.cos() * p.cos());
    let right0 = DVec3::new(h.cos(), 0.0, h.sin());
    let up0 = DVec3::new(-h.sin() * p.sin(), p.cos(), h.cos() * p.sin());
    // Rolling right wing down turns right and up about the forward axis.
    let right = right0 * r.cos() - up0 * r.sin();
    let up = up0 * r.cos() + right0 * r.sin();
    let k = v.width as f64 / (2.0 * (0.5 * v.hfov_deg.to_radians()).tan());
    let d =
        fwd + right * ((sx - 0.5 * v.width as f64) / k) + up * ((0.5 * v.height as f64 - sy) / k);
    // Local grid with origin 0 and 1 m cells: east = x, south = −y.
    let eye = DVec3::new(v.eye_x, v.altitude, -v.eye_y);
    if d.y >= -1e-9 {
        return None;
    }
    let t = (z0 - eye.y) / d.y;
    let q = eye + d * t;
    Some((q.x, q.z))
}

/// The checker square `(column, row)` under (east, south) metres, if on the texture.
fn square_at(e: f64, s: f64) -> Option<(u32, u32)> {
    if !(0.0..256.0).contains(&e) || !(0.0..256.0).contains(&s) {
        return None;
    }
    Some((e.floor() as u32 / CHECK, s.floor() as u32 / CHECK))
}

/// Compare every pixel whose four corners land in the same checker square; returns
/// (pixels compared, mismatches).
fn compare_with_plane(t: &FlightTerrain, v: &FlightCamera, z0: f64) -> (usize, usize) {
    let mut fb = Framebuffer::new(v.width, v.height).unwrap();
    let opts = ViewOptions {
        sampler: Sampler::Nearest,
        ..ViewOptions::default()
    };
    t.render(v, &opts, &mut fb, &mut FrameScratch::default())
        .unwrap();
    let frame = fb.to_frame();
    let (mut compared, mut bad) = (0, 0);
    for py in 0..v.height {
        for px in 0..v.width {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(a, b)| {
                plane_hit(v, z0, px as f64 + a, py as f64 + b).and_then(|(e, s)| square_at(e, s))
            });
            // The pixel's footprint is convex and so is the square: four corners inside it
            // put the whole pixel inside it.
            let Some(sq) = corners[0] else { continue };
            if corners.iter().any(|&c| c != Some(sq)) {
                continue;
            }
            let c0 = if (sq.0 + sq.1).is_multiple_of(2) {
                255
            } else {
                0
            };
            compared += 1;
            let got = frame.color[frame.index(px, py)];
            if !frame.covered(frame.index(px, py)) || got[0].abs_diff(c0) > 2 {
                bad += 1;
            }
        }
    }
    (compared, bad)
}

#[test]
fn checkerboard_plane_matches_ray_plane_intersection() {
    let z0 = 10.0;
    let t = checker_plane(z0);
    let base = FlightCamera {
        eye_x: 128.0,
        eye_y: -128.0,
        altitude: 70.0,
        heading_deg: 0.0,
        pitch_deg: -90.0,
        roll_deg: 0.0,
        hfov_deg: 45.0,
        width: 256,
        height: 192,
    };
    let views = [
        base.clone(),
        FlightCamera {
            heading_deg: 90.0,
            ..base.clone()
        },
        FlightCamera {
            eye_x: 40.0,
            eye_y: -220.0,
            altitude: 30.0,
            heading_deg: 30.0,
            pitch_deg: -35.0,
            roll_deg: 10.0,
            hfov_deg: 60.0,
            ..base.clone()
        },
        FlightCamera {
            eye_x: 200.0,
            eye_y: -30.0,
            altitude: 12.0,
            heading_deg: 215.0,
            pitch_deg: -12.0,
            roll_deg: -25.0,
            ..base.clone()
        },
    ];
    for v in &views {
        let (compared, bad) = compare_with_plane(&t, v, z0 as f64);
        assert!(
            compared > (v.width * v.height) as usize / 4,
            "{v:?}: only {compared} pixels compared"
        );
        assert!(
            bad == 0,
            "{v:?}: {bad} of {compared} pixels differ from the analytic checkerboard"
        );
    }
}

/// Rolling terrain, 513², 5 m spacing: two sine families, ±55 m.
fn hills() -> Grid {
    let n = 513u32;
    let h = (0..n * n)
        .map(|i| {
            let (x, z) = ((i % n) as f32 * 5.0, (i / n) as f32 * 5.0);
            100.0 + 40.0 * (x / 97.0).sin() * (z / 61.0).cos() + 15.0 * (x / 23.0 + z / 31.0).sin()
        })
        .collect();
    Grid::new("hills", n, n, h, Georef::local(5.0)).unwrap()
}

fn hills_terrain() -> FlightTerrain {
    let grid = hills();
    let tree = chunks::build(&grid, 0.25, 17).unwrap();
    let img = image::RgbaImage::from_fn(512, 512, |x, y| {
        image::Rgba([(x / 2) as u8, (y / 2) as u8, 128, 255])
    });
    let tex = texmap_terrain::view::texture_from_rgba(&img).unwrap();
    FlightTerrain::new(grid, tree, tex)
}

fn is_ancestor(t: &FlightTerrain, a: ChunkRef, b: ChunkRef) -> bool {
    let ca = t.chunk(a);
    let cb = t.chunk(b);
    a.depth < b.depth
        && cb.ix >> (b.depth - a.depth) == ca.ix
        && cb.iy >> (b.depth - a.depth) == ca.iy
}

#[test]
fn selection_refines_near_the_eye_and_coarsens_far_away() {
    let t = hills_terrain();
    let v = FlightCamera {
        eye_x: 1280.0,
        eye_y: -2450.0,
        altitude: 220.0,
        heading_deg: 0.0,
        pitch_deg: -8.0,
        roll_deg: 0.0,
        hfov_deg: 45.0,
        width: 512,
        height: 384,
    };
    let cam = v.camera(t.grid()).unwrap();
    let tol = 1.0;
    let sel = t.select(&cam, tol);
    let max_depth = t.max_depth();
    assert!(sel.chunks.len() > 4);
    // The rule, checked on every drawn chunk: its error is within tolerance unless it is a
    // finest chunk, and its parent's was not.
    let k = cam.scale();
    for &c in &sel.chunks {
        let ch = t.chunk(c);
        let sse = screen_space_error(ch.geometric_error, t.bounds(c).distance(cam.eye()), k);
        assert!(sse <= tol || c.depth == max_depth, "{c:?} sse {sse}");
        if c.depth > 0 {
            let l = &t.levels()[c.depth as usize - 1];
            let pi = l
                .iter()
                .position(|p| p.ix == ch.ix / 2 && p.iy == ch.iy / 2)
                .unwrap();
            let pr = ChunkRef {
                depth: c.depth - 1,
                index: pi,
            };
            let psse =
                screen_space_error(l[pi].geometric_error, t.bounds(pr).distance(cam.eye()), k);
            assert!(
                psse > tol,
                "{c:?}: parent within tolerance ({psse}) yet refined"
            );
        }
    }
    // Never a chunk together with one of its ancestors.
    for &a in &sel.chunks {
        for &b in &sel.chunks {
            assert!(
                !is_ancestor(&t, a, b),
                "{a:?} drawn with its descendant {b:?}"
            );
        }
    }
    // Depth falls with distance: the nearest drawn chunk is the finest, the farthest is coarser.
    let dist = |c: ChunkRef| t.bounds(c).distance(cam.eye());
    let near = *sel
        .chunks
        .iter()
        .min_by(|a, b| dist(**a).total_cmp(&dist(**b)))
        .unwrap();
    let far = *sel
        .chunks
        .iter()
        .max_by(|a, b| dist(**a).total_cmp(&dist(**b)))
        .unwrap();
    assert_eq!(near.depth, max_depth);
    assert!(far.depth < near.depth, "far {far:?} near {near:?}");
    // Looking north from the south edge: the chunks behind the eye are culled.
    assert!(sel.culled > 0);
    for &c in &sel.chunks {
        assert!(t.bounds(c).max.z >= 0.0 && t.bounds(c).min.z <= 2450.0 + 1.0);
    }
    // A tighter tolerance draws more, finer chunks.
    let fine = t.select(&cam, 0.25);
    let tris = |s: &texmap_terrain::view::Selection| -> usize {
        s.chunks
            .iter()
            .map(|c| t.mesh(*c).unwrap().triangles.len())
            .sum()
    };
    assert!(tris(&fine) > tris(&sel));
}

#[test]
fn no_background_through_terrain_at_mixed_levels_and_deterministic() {
    let t = hills_terrain();
    let views = [
        FlightCamera {
            eye_x: 1280.0,
            eye_y: -1280.0,
            altitude: 400.0,
            heading_deg: 20.0,
            pitch_deg: -60.0,
            roll_deg: 5.0,
            hfov_deg: 45.0,
            width: 320,
            height: 240,
        },
        FlightCamera {
            eye_x: 600.0,
            eye_y: -1900.0,
            altitude: 260.0,
            heading_deg: 45.0,
            pitch_deg: -35.0,
            roll_deg: 0.0,
            hfov_deg: 60.0,
            width: 320,
            height: 240,
        },
    ];
    // The same terrain with the skirts cut off: the check must see the cracks they close.
    let bare = {
        let grid = hills();
        let mut tree = chunks::build(&grid, 0.25, 17).unwrap();
        for c in tree.levels.iter_mut().flatten() {
            c.mesh.triangles.truncate(c.surface_triangles as usize);
        }
        FlightTerrain::new(grid, tree, t.texture().clone())
    };
    let mut bare_holes = 0;
    for v in &views {
        let opts = ViewOptions {
            pixel_error: 1.0,
            ..ViewOptions::default()
        };
        let render = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut fb = Framebuffer::new(v.width, v.height).unwrap();
                let s = t
                    .render(v, &opts, &mut fb, &mut FrameScratch::default())
                    .unwrap();
                (s, fb.to_frame())
            })
        };
        let (stats, frame) = render(1);
        let levels = stats.chunks_per_level.iter().filter(|&&n| n > 0).count();
        assert!(levels >= 2, "{:?}: one level only", stats.chunks_per_level);
        // Every pixel ray of these views meets the terrain inside the grid (the views look down
        // from well inside it), so a pixel left at the background is a crack.
        let holes = frame.len() - frame.coverage_count();
        assert_eq!(
            holes, 0,
            "{v:?}: {holes} background pixels, stats {stats:?}"
        );
        let mut fb = Framebuffer::new(v.width, v.height).unwrap();
        bare.render(v, &opts, &mut fb, &mut FrameScratch::default())
            .unwrap();
        bare_holes += frame.len() - fb.to_frame().coverage_count();
        let (stats2, frame2) = render(2);
        assert_eq!(stats, stats2);
        assert!(frame.color == frame2.color && frame.depth == frame2.depth);
    }
    assert!(
        bare_holes > 0,
        "without skirts no crack was seen: the check is blind"
    );
}

#[test]
fn every_sampler_draws_the_same_scene() {
    let t = hills_terrain();
    let v = FlightCamera {
        width: 256,
        height: 192,
        ..FlightCamera::over(t.grid())
    };
    let mut means = Vec::new();
    for name in SAMPLER_NAMES {
        let sampler = sampler_by_name(name).unwrap();
        let opts = ViewOptions {
            sampler,
            ..ViewOptions::default()
        };
        let mut fb = Framebuffer::new(v.width, v.height).unwrap();
        t.render(&v, &opts, &mut fb, &mut FrameScratch::default())
            .unwrap();
        let f = fb.to_frame();
        assert!(f.coverage_count() > f.len() / 4);
        let m: f64 = f.color.iter().map(|c| c[0] as f64).sum::<f64>() / f.len() as f64;
        means.push(m);
    }
    // The texture's red is a smooth ramp: every filter gives about the same mean.
    for m in &means {
        assert!((m - means[2]).abs() < 3.0, "{means:?}");
    }
    assert_eq!(sampler_by_name("span3"), Some(Sampler::Span(Banks::K3)));
    assert_eq!(sampler_by_name("quadratic3"), Some(Sampler::Quadratic3));
    assert_eq!(sampler_by_name("cubic"), None);
}

#[test]
fn camera_errors_and_pitch_limits() {
    let t = hills_terrain();
    let g = t.grid();
    let ok = FlightCamera::over(g);
    assert!(ok.camera(g).is_ok());
    let outside = FlightCamera {
        eye_x: -10.0,
        ..ok.clone()
    };
    assert!(matches!(
        outside.camera(g),
        Err(ViewError::EyeOutside { .. })
    ));
    let low = FlightCamera {
        altitude: 50.0,
        ..ok.clone()
    };
    let e = low.camera(g).unwrap_err();
    assert!(matches!(e, ViewError::BelowGround { .. }), "{e}");
    assert!(e.to_string().contains("ground"));
    let nan = FlightCamera {
        heading_deg: f64::NAN,
        ..ok.clone()
    };
    assert!(matches!(
        nan.camera(g),
        Err(ViewError::NonFinite {
            field: "heading",
            ..
        })
    ));
    for p in [90.0, -90.0] {
        let c = FlightCamera {
            pitch_deg: p,
            ..ok.clone()
        }
        .camera(g)
        .unwrap();
        assert!((c.forward().y - p.signum() as f32).abs() < 1e-6);
        // Straight down with heading 0: the image's up is north (−z).
        if p < 0.0 {
            assert!((c.up() - Vec3::NEG_Z).length() < 1e-5);
        }
    }
    let over = FlightCamera {
        pitch_deg: 90.5,
        ..ok.clone()
    };
    assert!(matches!(
        over.camera(g),
        Err(ViewError::BadParameter { name: "pitch", .. })
    ));
    let fov = FlightCamera {
        hfov_deg: 180.0,
        ..ok.clone()
    };
    assert!(fov.camera(g).is_err());
    let mut fb = Framebuffer::new(ok.width, ok.height).unwrap();
    let bad_tol = ViewOptions {
        pixel_error: 0.0,
        ..ViewOptions::default()
    };
    assert!(
        t.render(&ok, &bad_tol, &mut fb, &mut FrameScratch::default())
            .is_err()
    );
}

#[test]
fn database_view_puts_the_photo_where_it_belongs() {
    // A 129² plane at 50 m, 10 m spacing, no georeference on the photo (stretched over the DEM):
    // west half red, east half blue, a green band along the north edge.
    let n = 129u32;
    let grid = Grid::new(
        "flat",
        n,
        n,
        vec![50.0; (n * n) as usize],
        Georef::local(10.0),
    )
    .unwrap();
    let photo = image::RgbaImage::from_fn(512, 512, |x, y| {
        image::Rgba(if y < 64 {
            [0, 255, 0, 255]
        } else if x < 256 {
            [255, 0, 0, 255]
        } else {
            [0, 0, 255, 255]
        })
    });
    let photo = texmap_terrain::gst::Orthophoto {
        stretch: None,
        image: photo,
        georef: None,
        source: "test photo".into(),
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("db");
    let opts = texmap_terrain::db::BuildOptions {
        max_error: 0.1,
        chunk: 33,
        map_texels: 64,
        max_texture_levels: 4,
        ..Default::default()
    };
    texmap_terrain::db::build(&grid, "flat", Some(&photo), &opts, &out, |_, _| {}).unwrap();
    let db = texmap_terrain::db::Database::open(&out).unwrap();
    let t = FlightTerrain::from_database(&db, 1024).unwrap();
    // Straight down over the centre, heading north, seeing about 530 m of the 1280 m square.
    let v = FlightCamera {
        eye_x: 640.0,
        eye_y: -640.0,
        altitude: 50.0 + 640.0,
        heading_deg: 0.0,
        pitch_deg: -90.0,
        roll_deg: 0.0,
        hfov_deg: 45.0,
        width: 128,
        height: 96,
    };
    let mut fb = Framebuffer::new(128, 96).unwrap();
    let stats = t
        .render(
            &v,
            &ViewOptions::default(),
            &mut fb,
            &mut FrameScratch::default(),
        )
        .unwrap();
    assert!(stats.maps_needed.is_some_and(|m| m > 0));
    // Residency through the cache: the first frame loads every needed map, the same frame again
    // loads none; a budget of two maps keeps two.
    let mut cache = texmap_terrain::gst::GstCache::new(1 << 30);
    let r1 = t.make_resident(&v, &db, &mut cache).unwrap();
    assert_eq!(Some(r1.needed), stats.maps_needed);
    assert_eq!(r1.loaded, r1.needed);
    assert_eq!(r1.cache.resident_bytes, r1.needed * 64 * 64 * 4);
    let r2 = t.make_resident(&v, &db, &mut cache).unwrap();
    assert_eq!((r2.loaded, r2.cache.hits), (0, r1.needed));
    let mut small = texmap_terrain::gst::GstCache::new(2 * 64 * 64 * 4);
    let r3 = t.make_resident(&v, &db, &mut small).unwrap();
    assert_eq!(r3.cache.resident, 2.min(r3.needed));
    let f = fb.to_frame();
    assert_eq!(f.coverage_count(), f.len());
    // West of the centre line red, east blue (columns well away from the seam).
    assert_eq!(f.color[f.index(20, 48)], [255, 0, 0, 255]);
    assert_eq!(f.color[f.index(107, 48)], [0, 0, 255, 255]);
    // Turned to look east, straight down: the image's up is east and its bottom west.
    let east = FlightCamera {
        heading_deg: 90.0,
        ..v.clone()
    };
    t.render(
        &east,
        &ViewOptions::default(),
        &mut fb,
        &mut FrameScratch::default(),
    )
    .unwrap();
    let f = fb.to_frame();
    assert_eq!(f.color[f.index(64, 90)], [255, 0, 0, 255]);
    assert_eq!(f.color[f.index(64, 5)], [0, 0, 255, 255]);
    // Near the north edge looking north and down: the green band is at the top of the image.
    let north = FlightCamera {
        eye_y: -200.0,
        altitude: 50.0 + 300.0,
        pitch_deg: -80.0,
        ..v.clone()
    };
    t.render(
        &north,
        &ViewOptions::default(),
        &mut fb,
        &mut FrameScratch::default(),
    )
    .unwrap();
    let f = fb.to_frame();
    let top = f.color[f.index(64, 2)];
    assert_eq!(top, [0, 255, 0, 255], "top {top:?}");
}

#[test]
fn haze_follows_koschmieder() {
    use texmap_core::camera::Camera;
    use texmap_core::frame::Frame;
    // Two pixels of a 2x1 frame: one black surface at depth 100 m on the axis-near ray, one
    // uncovered. Visibility 1000 m: transmittance exp(−3.912 · d / 1000).
    let cam = Camera::perspective_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 90.0, 2, 1).unwrap();
    let mut f = Frame::from_parts(
        2,
        1,
        vec![[0, 0, 0, 255], [0, 0, 0, 0]],
        vec![100.0, f32::INFINITY],
    )
    .unwrap();
    texmap_terrain::view::apply_haze(&mut f, &cam, [255, 255, 255], 1000.0).unwrap();
    // Pixel 0's centre is at x = 0.5: eye ray (−0.5, 0, −1) for k = 1 (90° over 2 pixels).
    let d = 100.0 * (1.0f64 + 0.25).sqrt();
    let t = (-3.912 * d / 1000.0).exp();
    let want = texmap_core::color::linear_to_srgb8_exact((1.0 - t) as f32);
    assert!(
        f.color[0][0].abs_diff(want) <= 1,
        "{:?} vs {want}",
        f.color[0]
    );
    assert_eq!(f.color[1], [255, 255, 255, 255]);
    assert!(texmap_terrain::view::apply_haze(&mut f, &cam, [0; 3], 0.0).is_err());
}
