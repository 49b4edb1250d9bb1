//! Models and tree billboards on the terrain, against independent answers: the reference ray
//! tracer (reftrace) for a textured model, the analytic ground of a tilted plane for placement,
//! the analytic projection of the tree's alpha mask for billboards, and error messages for bad
//! input. Fixtures: `tests/data/models/` (written by `make_models.py` there).

use std::path::{Path, PathBuf};

use glam::Vec3;
use texmap_core::frame::Frame;
use texmap_core::sample::Sampler;
use texmap_core::shade::{Lighting, Material};
use texmap_mesh::TriMesh;
use texmap_raster::Framebuffer;
use texmap_reftrace::{RenderOptions, SceneBuilder, SurfaceMaterial, Texture};
use texmap_terrain::chunks;
use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::models::{
    self, Model, ModelError, Placed, PlacedTree, Placement, Tree, TreeBillboard,
};
use texmap_terrain::view::{self, FlightCamera, FlightTerrain, FrameScratch, ViewOptions};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/models")
        .join(name)
}

/// A terrain of `n²` samples `cell` metres apart with heights `h(col, row)` and a smooth photo.
fn terrain(n: u32, cell: f64, h: impl Fn(u32, u32) -> f32) -> FlightTerrain {
    let heights = (0..n * n).map(|i| h(i % n, i / n)).collect();
    let grid = Grid::new("t", n, n, heights, Georef::local(cell)).unwrap();
    let tree = chunks::build(&grid, 0.05, 33).unwrap();
    let photo = image::RgbaImage::from_fn(128, 128, |x, y| {
        image::Rgba([(60 + x / 2) as u8, (100 + y / 4) as u8, 70, 255])
    });
    FlightTerrain::new(grid, tree, view::texture_from_rgba(&photo).unwrap())
}

/// The map position of fractional sample `(col, row)`.
fn xy(t: &FlightTerrain, col: f64, row: f64) -> (f64, f64) {
    t.grid().georef().sample_xy(col, row)
}

fn render_terrain(t: &FlightTerrain, eye: &FlightCamera, sampler: Sampler) -> Framebuffer {
    let mut fb = Framebuffer::new(eye.width, eye.height).unwrap();
    let opts = ViewOptions {
        sampler,
        ..ViewOptions::default()
    };
    t.render(eye, &opts, &mut fb, &mut FrameScratch::default())
        .unwrap();
    fb
}

/// Pixels whose depth is nearer than `base`'s by more than 0.1 % (what was drawn over it).
fn nearer(depth: &[f32], base: &[f32]) -> Vec<bool> {
    depth
        .iter()
        .zip(base)
        .map(|(&d, &b)| d.is_finite() && (!b.is_finite() || d < b * 0.999))
        .collect()
}

fn count(mask: &[bool]) -> usize {
    mask.iter().filter(|&&m| m).count()
}

/// PSNR (dB) of the RGB of `a` against `b` over `mask`.
fn psnr_over(a: &Frame, b: &Frame, mask: &[bool]) -> f64 {
    let (mut sse, mut n) = (0.0f64, 0usize);
    for ((p, q), &m) in a.color.iter().zip(&b.color).zip(mask) {
        if m {
            for c in 0..3 {
                let d = p[c] as f64 - q[c] as f64;
                sse += d * d;
            }
            n += 3;
        }
    }
    let mse = sse / n.max(1) as f64;
    10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10()
}

#[test]
fn textured_model_matches_the_reference_ray_tracer() {
    let t = terrain(129, 2.0, |_, _| 50.0);
    let model = Model::load(fixture("box.obj")).unwrap();
    assert!(model.is_textured(), "box.obj names box.png through box.mtl");
    let (x, y) = xy(&t, 64.0, 64.0);
    let at = Placement {
        x,
        y,
        heading_deg: 30.0,
        scale: 24.0,
        ..Placement::default()
    };
    let placed = Placed::new(&model, t.grid(), &at).unwrap();
    // 70 m south of the box, 35 m up, looking north and down.
    let (ex, ey) = xy(&t, 64.0, 99.0);
    let eye = FlightCamera {
        eye_x: ex,
        eye_y: ey,
        altitude: 85.0,
        pitch_deg: -22.0,
        width: 240,
        height: 180,
        ..FlightCamera::over(t.grid())
    };
    let cam = eye.camera(t.grid()).unwrap();

    // The reference: the terrain's full-resolution mesh and the placed box, each with level 0 of
    // the texture the rasteriser samples, traced with 4x4 samples per pixel, unlit.
    let texels = |m: &texmap_core::mip::MipTexture| {
        let n = (m.width() * m.height()) as usize;
        Texture::new(
            m.width(),
            m.height(),
            m.texels()[..n].iter().map(|v| v.to_array()).collect(),
        )
        .unwrap()
    };
    let ground = texmap_terrain::db::whole_mesh(t.grid(), 0.0).unwrap();
    let scene = |with_model: bool| {
        let mut b = SceneBuilder::new();
        b.add_mesh(
            &ground.positions,
            ground.indices(),
            ground.uvs.as_deref(),
            0,
        )
        .unwrap();
        if with_model {
            let idx: Vec<u32> = placed.triangles.iter().flatten().copied().collect();
            b.add_mesh(&placed.positions, &idx, placed.uvs.as_deref(), 1)
                .unwrap();
        }
        b.build()
    };
    let textures = [
        texels(t.texture()),
        texels(placed.texture.as_ref().unwrap()),
    ];
    let white = Material::matte(Vec3::ONE);
    let materials = [
        SurfaceMaterial::opaque(white).with_texture(0),
        SurfaceMaterial::opaque(white).with_texture(1),
    ];
    let mut opts = RenderOptions::new(Lighting::new(Vec3::ONE, &[]).unwrap(), &materials);
    opts.textures = &textures;
    opts.samples_per_axis = 4;
    opts.max_depth = 0;
    let full = scene(true);
    let reference = full.render(&cam, &opts).unwrap();
    let ref_ground = scene(false).depth_image(&cam);

    // The box's texels are magnified about 1.4x: the reference's pixel-footprint integral of the
    // texels is closer to trilinear (bilinear here) than to nearest's hard texel edges (measured:
    // 29.0 and 24.2 dB).
    for (sampler, bound) in [(Sampler::Trilinear, 27.0), (Sampler::Nearest, 22.0)] {
        let mut fb = render_terrain(&t, &eye, sampler);
        let ground_only = fb.to_frame().depth;
        let stats =
            models::draw_models(&cam, std::slice::from_ref(&placed), sampler, &mut fb).unwrap();
        assert_eq!((stats.models_drawn, stats.models_culled), (1, 0));
        assert_eq!(stats.model_triangles, 12);
        let frame = fb.to_frame();

        let ours = nearer(&frame.depth, &ground_only);
        let theirs = nearer(&reference.depth, &ref_ground);
        let (a, b) = (count(&ours), count(&theirs));
        assert!(b > 2000, "the box covers {b} reference pixels");
        let rel = (a as f64 - b as f64).abs() / b as f64;
        assert!(
            rel < 0.02,
            "box pixels: raster {a}, reference {b} ({:.2} %, bound 2 %)",
            100.0 * rel
        );
        // Colour over the box's inner pixels (both frames cover them and their four neighbours), where
        // the reference's anti-aliased silhouette plays no part.
        let (w, h) = (eye.width as usize, eye.height as usize);
        let inner: Vec<bool> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                x > 0
                    && y > 0
                    && x + 1 < w
                    && y + 1 < h
                    && [i, i - 1, i + 1, i - w, i + w]
                        .iter()
                        .all(|&j| ours[j] && theirs[j])
            })
            .collect();
        assert!(count(&inner) > 1500, "{} inner pixels", count(&inner));
        let p = psnr_over(&frame, &reference, &inner);
        eprintln!(
            "box vs reftrace, {sampler:?}: {a} / {b} pixels, PSNR {p:.1} dB over {} inner pixels",
            count(&inner)
        );
        assert!(
            p > bound,
            "{sampler:?}: PSNR over the box {p:.1} dB, bound {bound} dB"
        );
        // The same box untextured would be flat grey: the texture must matter.
        let grey = Frame::new(eye.width, eye.height, [188, 188, 188, 255]);
        assert!(psnr_over(&grey, &reference, &inner) < p - 10.0);
    }
}

/// A long box, 1 x 1 x 4 model units (north–south), on the model origin, for the heading test.
fn long_box() -> TriMesh {
    let p: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                (i & 1) as f32 - 0.5,
                ((i >> 1) & 1) as f32,
                4.0 * ((i >> 2) as f32 - 0.5),
            )
        })
        .collect();
    let t = vec![
        [0, 1, 3],
        [0, 3, 2],
        [4, 6, 7],
        [4, 7, 5],
        [0, 4, 5],
        [0, 5, 1],
        [2, 3, 7],
        [2, 7, 6],
        [0, 2, 6],
        [0, 6, 4],
        [1, 5, 7],
        [1, 7, 3],
    ];
    TriMesh::new(p, t).unwrap()
}

#[test]
fn placement_sits_on_the_ground_and_heading_turns_the_model() {
    // A tilted plane: ground = 100 + 0.3·col + 0.1·row, exact under bilinear interpolation.
    let t = terrain(65, 10.0, |c, r| 100.0 + 0.3 * c as f32 + 0.1 * r as f32);
    let model = Model::from_mesh("long box", long_box(), None).unwrap();
    assert!(!model.is_textured());
    for (col, row, hag) in [(20.25, 31.5, 0.0), (40.0, 12.75, 5.0), (0.0, 64.0, 0.0)] {
        let (x, y) = xy(&t, col, row);
        let at = Placement {
            x,
            y,
            height_above_ground: hag,
            heading_deg: 17.0,
            scale: 3.0,
        };
        let p = Placed::new(&model, t.grid(), &at).unwrap();
        let low = p
            .positions
            .iter()
            .map(|v| v.y)
            .fold(f32::INFINITY, f32::min);
        let want = 100.0 + 0.3 * col + 0.1 * row + hag;
        assert!(
            (low as f64 - want).abs() < 1e-3,
            "lowest vertex at {low}, ground + {hag} = {want} at ({col}, {row})"
        );
    }

    // Seen straight down (image up = north), the 10 x 40 m footprint is tall at heading 0 and
    // wide at heading 90; the nose (model −z) points north, then east.
    let (x, y) = xy(&t, 32.0, 32.0);
    let (cx, cz) = (320.0f32, 320.0f32);
    let eye = FlightCamera {
        eye_x: x,
        eye_y: y,
        altitude: 300.0,
        pitch_deg: -90.0,
        hfov_deg: 40.0,
        width: 200,
        height: 200,
        ..FlightCamera::over(t.grid())
    };
    let cam = eye.camera(t.grid()).unwrap();
    let mut extents = Vec::new();
    for heading in [0.0, 90.0] {
        let at = Placement {
            x,
            y,
            heading_deg: heading,
            scale: 10.0,
            ..Placement::default()
        };
        let p = Placed::new(&model, t.grid(), &at).unwrap();
        // The nose vertex (model z = −2, the first four corners' far end) in world space.
        let nose = p.positions[..4]
            .iter()
            .fold(Vec3::ZERO, |s, &v| s + v * 0.25);
        if heading == 0.0 {
            assert!(nose.z < cz - 15.0 && (nose.x - cx).abs() < 1e-3, "{nose}");
        } else {
            assert!(nose.x > cx + 15.0 && (nose.z - cz).abs() < 1e-3, "{nose}");
        }
        let mut fb = render_terrain(&t, &eye, Sampler::Bilinear);
        let base = fb.to_frame().depth;
        models::draw_models(&cam, &[p], Sampler::Bilinear, &mut fb).unwrap();
        let mask = nearer(&fb.to_frame().depth, &base);
        let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
        for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
            let (px, py) = (i % 200, i / 200);
            (x0, x1, y0, y1) = (x0.min(px), x1.max(px), y0.min(py), y1.max(py));
        }
        extents.push((x1 + 1 - x0, y1 + 1 - y0));
    }
    let ((w0, h0), (w90, h90)) = (extents[0], extents[1]);
    // Analytic: the roof (10 m up) 190 m from the eye: k = 100 / tan 20° px, so 10 m is
    // about 14.4 px and 40 m about 57.6 px (the walls add a little perspective spread).
    let k = 100.0 / 20f64.to_radians().tan();
    let (short, long) = (10.0 * k / 190.0, 40.0 * k / 190.0);
    for (got, want) in [(w0, short), (h0, long), (w90, long), (h90, short)] {
        assert!(
            (got as f64 - want).abs() <= 0.12 * want + 2.0,
            "footprint {extents:?}, expected about {short:.1} x {long:.1} then turned"
        );
    }
}

/// Pixels the trees drew: depth nearer than the frame before them.
fn tree_pixels(
    t: &FlightTerrain,
    eye: &FlightCamera,
    trees: &[PlacedTree],
    bb: &TreeBillboard,
) -> (Vec<bool>, Framebuffer, models::ModelStats) {
    let cam = eye.camera(t.grid()).unwrap();
    let mut fb = render_terrain(t, eye, Sampler::Trilinear);
    let base = fb.to_frame().depth;
    let s = models::draw_trees(&cam, trees, bb, Sampler::Trilinear, &mut fb).unwrap();
    (nearer(&fb.to_frame().depth, &base), fb, s)
}

#[test]
fn tree_billboard_covers_its_projected_alpha_mask_from_any_heading() {
    let t = terrain(65, 10.0, |_, _| 20.0);
    let bb = TreeBillboard::new();
    let (tx, ty) = xy(&t, 32.0, 32.0);
    let trees = models::place_trees(
        t.grid(),
        &[Tree {
            x: tx,
            y: ty,
            height: 20.0,
        }],
    )
    .unwrap();
    let dist = 100.0f64;
    let (w, h, fov) = (320u32, 240u32, 30.0f64);
    let k = w as f64 / (2.0 * (fov / 2.0).to_radians().tan());
    // Eye level with the tree's middle, looking level at it: the quad faces the camera square on
    // at depth `dist`, an axis-aligned k·W/d x k·H/d rectangle of which the mask covers its share.
    let want = bb.coverage() * (k * 10.0 / dist) * (k * 20.0 / dist);
    for heading in [0.0f64, 90.0, 210.0, 301.0] {
        let hr = heading.to_radians();
        // The eye stands `dist` behind the tree along the heading (north = −y in the map).
        let eye = FlightCamera {
            eye_x: tx - dist * hr.sin(),
            eye_y: ty - dist * hr.cos(),
            altitude: 30.0,
            heading_deg: heading,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            hfov_deg: fov,
            width: w,
            height: h,
        };
        let (mask, fb, s) = tree_pixels(&t, &eye, &trees, &bb);
        assert_eq!((s.trees_drawn, s.trees_culled), (1, 0));
        let got = count(&mask) as f64;
        let rel = (got - want).abs() / want;
        eprintln!("tree at heading {heading}: {got} pixels, analytic {want:.0}");
        assert!(
            rel < 0.03,
            "heading {heading}: {got} tree pixels, analytic {want:.0} ({:.2} %, bound 3 %)",
            100.0 * rel
        );
        // The billboard writes its plane's depth: `dist` at the image centre column.
        let d = fb.depth_at(w / 2, h / 2 + 20).unwrap();
        assert!(
            (d as f64 - dist).abs() < 1e-3 * dist,
            "depth {d} at the tree, expected {dist}"
        );
    }

    // Terrain in front hides it: a 60 m ridge across rows 38–40 between the eye and the tree.
    let ridge = terrain(
        65,
        10.0,
        |_, r| if (38..=40).contains(&r) { 60.0 } else { 20.0 },
    );
    let eye = FlightCamera {
        eye_x: tx,
        eye_y: ty - dist,
        altitude: 30.0,
        heading_deg: 0.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        hfov_deg: fov,
        width: w,
        height: h,
    };
    let (mask, _, s) = tree_pixels(&ridge, &eye, &trees, &bb);
    assert_eq!(s.trees_drawn, 1, "the tree is in the frustum");
    assert_eq!(count(&mask), 0, "the ridge must hide the tree");
    // And a tree behind the camera is culled, not drawn.
    let behind = FlightCamera {
        heading_deg: 180.0,
        ..eye
    };
    let (_, _, s) = tree_pixels(&t, &behind, &trees, &bb);
    assert_eq!((s.trees_drawn, s.trees_culled), (0, 1));
}

#[test]
fn forest_is_deterministic_and_on_data() {
    let mut t = terrain(65, 10.0, |c, _| if c < 32 { f32::NAN } else { 5.0 });
    let trees = models::forest(t.grid(), 200, 3);
    assert_eq!(trees, models::forest(t.grid(), 200, 3));
    assert_ne!(trees, models::forest(t.grid(), 200, 4));
    assert_eq!(trees.len(), 200);
    let placed = models::place_trees(t.grid(), &trees).unwrap();
    assert!(placed.iter().all(|p| p.base.x >= 320.0 && p.base.y == 5.0));
    assert!(trees.iter().all(|r| (8.0..20.0).contains(&r.height)));
    // Data in the last column only: no cell has four samples, so no tree.
    t = terrain(65, 10.0, |c, _| if c == 64 { 5.0 } else { f32::NAN });
    assert!(models::forest(t.grid(), 10, 3).is_empty());
}

#[test]
fn bad_input_gives_errors_naming_the_file_or_value() {
    let t = terrain(33, 10.0, |_, _| 0.0);
    let e = Model::load(fixture("missing.obj")).unwrap_err();
    assert!(e.to_string().contains("missing.obj"), "{e}");
    let e = Model::load(fixture("broken.obj")).unwrap_err();
    assert!(
        e.to_string().contains("broken.obj") && e.to_string().contains("index"),
        "{e}"
    );
    let e = Model::load(fixture("box.mtl")).unwrap_err();
    assert!(matches!(e, ModelError::UnknownFormat { .. }), "{e}");
    // A glTF without texture loads and is drawn flat.
    let g = Model::load(fixture("notex.gltf")).unwrap();
    assert!(!g.is_textured());
    // An OBJ whose material names a texture that is not there.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(fixture("box.obj"), dir.path().join("box.obj")).unwrap();
    std::fs::write(dir.path().join("box.mtl"), "newmtl a\nmap_Kd gone.png\n").unwrap();
    let e = Model::load(dir.path().join("box.obj")).unwrap_err();
    assert!(e.to_string().contains("gone.png"), "{e}");
    std::fs::remove_file(dir.path().join("box.mtl")).unwrap();
    let e = Model::load(dir.path().join("box.obj")).unwrap_err();
    assert!(e.to_string().contains("box.mtl"), "{e}");

    let model = Model::load(fixture("box.obj")).unwrap();
    let (x, y) = xy(&t, 16.0, 16.0);
    let ok = Placement {
        x,
        y,
        ..Placement::default()
    };
    for (bad, word) in [
        (
            Placement {
                scale: f64::NAN,
                ..ok
            },
            "scale",
        ),
        (Placement { scale: 0.0, ..ok }, "scale"),
        (Placement { scale: -2.0, ..ok }, "scale"),
        (
            Placement {
                heading_deg: f64::INFINITY,
                ..ok
            },
            "heading",
        ),
        (Placement { x: 1e6, ..ok }, "outside"),
        (Placement { y: 5.0, ..ok }, "outside"),
        (Placement { x: f64::NAN, ..ok }, "x = NaN"),
    ] {
        let e = Placed::new(&model, t.grid(), &bad).unwrap_err();
        assert!(
            e.to_string().contains(word) && e.to_string().contains("box.obj"),
            "{bad:?}: {e}"
        );
    }
    let e = models::place_trees(t.grid(), &[Tree { x, y, height: 0.0 }]).unwrap_err();
    assert!(e.to_string().contains("tree 0: height = 0"), "{e}");
    // Over no-data.
    let hole = terrain(33, 10.0, |c, _| if c < 24 { f32::NAN } else { 0.0 });
    let e = Placed::new(&model, hole.grid(), &ok).unwrap_err();
    assert!(e.to_string().contains("no ground"), "{e}");
    // A non-finite vertex.
    let nan = TriMesh::new(vec![Vec3::NAN, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
    let e = Model::from_mesh("nan", nan, None).unwrap_err();
    assert!(e.to_string().contains("vertex 0"), "{e}");
}

#[test]
fn gltf_models_carry_their_base_colour_texture_and_factor() {
    let boxed =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../mesh/tests/data/BoxTextured.gltf");
    let m = Model::load(&boxed).unwrap();
    assert!(m.is_textured());
    let tex = m.texture.as_ref().unwrap();
    assert_eq!((tex.width(), tex.height()), (211, 211));
    // The base colour factor multiplies the texture in linear light: halve the red channel.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(&boxed).unwrap().replace(
        "\"baseColorTexture\": {",
        "\"baseColorFactor\": [0.5, 1.0, 1.0, 1.0],\n                \"baseColorTexture\": {",
    );
    let p = dir.path().join("red_half.gltf");
    std::fs::write(&p, text).unwrap();
    let half = Model::load(&p).unwrap();
    let (a, b) = (tex.texels()[0], half.texture.as_ref().unwrap().texels()[0]);
    assert!(
        (b.x - 0.5 * a.x).abs() < 0.01 && (b.y - a.y).abs() < 0.01,
        "{a:?} {b:?}"
    );
    // A material without a texture gives the flat colour its factor names.
    let text = std::fs::read_to_string(fixture("notex.gltf"))
        .unwrap()
        .replace(
            "\"primitives\":[{\"attributes\":{\"POSITION\":0}}]",
            "\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]",
        )
        .replace(
            "\"buffers\"",
            "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.2,0.4,0.6,1]}}],\"buffers\"",
        );
    let p = dir.path().join("blue.gltf");
    std::fs::write(&p, text).unwrap();
    let flat = Model::load(&p).unwrap();
    assert!(!flat.is_textured());
    assert_eq!(flat.color, glam::Vec3::new(0.2, 0.4, 0.6));
}
