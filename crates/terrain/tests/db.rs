//! The database: build from a GDAL-written GeoTIFF with a georeferenced photo, reopen, export.

use std::path::PathBuf;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{ReadOptions, read_dem};
use texmap_terrain::gst;
use texmap_terrain::photo::PhotoOptions;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn build_reopen_export_glb() {
    let grid = read_dem(data("ramp_i16_lzw.tif"), &ReadOptions::default()).unwrap();
    let photo = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::bands(None)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("db");
    let opts = BuildOptions {
        max_error: 0.5,
        chunk: 17,
        map_texels: 16,
        max_texture_levels: 3,
        ..Default::default()
    };
    let mut calls = 0;
    let m = db::build(&grid, "ramp", Some(&photo), &opts, &out, |_, _| calls += 1).unwrap();
    assert!(calls >= 3);
    assert_eq!(m.nodata, 1);
    assert_eq!(m.texture.as_ref().unwrap().placed_by, "georeference");
    // 37 x 29 pads to 65²: chunks of 16 cells -> depths 0..=2.
    assert_eq!(m.levels.len(), 3);
    // A second build to the same place is refused, and leaves no temporary behind.
    assert!(matches!(
        db::build(&grid, "ramp", None, &opts, &out, |_, _| {}),
        Err(texmap_terrain::TerrainError::Exists { .. })
    ));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    let d = Database::open(&out).unwrap();
    let g2 = d.grid().unwrap();
    assert_eq!(g2.georef(), grid.georef());
    // The photo covers columns 18..=36 (x from 500540 m); west of it the texture is the grid's
    // shaded relief, as without a photo.
    let tex = d.texture(4096).unwrap().unwrap();
    let w = tex.width();
    let u_of_col = |c: f64| c / 36.0;
    let tx = |c: f64| (u_of_col(c) * (w - 1) as f64).round() as u32;
    let shade = texmap_terrain::relief::Hillshade::new(&grid, Default::default());
    assert_eq!(
        tex.get_pixel(tx(5.0), w / 2).0,
        texmap_terrain::relief::relief_texel(&grid, &shade, w, tx(5.0), w / 2),
        "west of the photo: the shaded relief"
    );
    let p = tex.get_pixel(tx(30.0), w / 2);
    assert_eq!(p[3], 255);
    assert_eq!(p[2], 77, "band 3 is 77 everywhere");

    // Export: a plane's ramp meshes to few triangles; bounds are the grid's extent in metres.
    let mesh = db::whole_mesh(&g2, 0.5).unwrap();
    let glb = dir.path().join("t.glb");
    texmap_mesh::write_glb(&glb, &mesh, Some(&tex)).unwrap();
    let back = texmap_mesh::read_gltf(&glb).unwrap();
    assert_eq!(back[0].positions.len(), mesh.positions.len());
    let (lo, hi) = back[0].bounds().unwrap();
    assert_eq!((lo.x, hi.x), (0.0, 36.0 * 30.0));
    assert_eq!((lo.z, hi.z), (0.0, 28.0 * 30.0));
    assert_eq!((lo.y, hi.y), (100.0, 100.0 + 72.0 + 84.0));
    let (_, _, images) = gltf::import(&glb).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(images[0].width, w);

    // The greedy export refuses no-data, and meshes the filled plane with two triangles.
    assert!(db::whole_mesh_greedy(&g2, 0.5).is_err());
    let mut filled = g2.clone();
    filled.fill_nodata();
    let m = db::whole_mesh_greedy(&filled, 0.5).unwrap();
    assert!(m.triangles.len() <= 8, "{}", m.triangles.len());
    let obj = dir.path().join("g.obj");
    texmap_mesh::write_obj(&obj, &m, None).unwrap();
    assert_eq!(
        texmap_mesh::read_obj(&obj).unwrap()[0].triangles.len(),
        m.triangles.len()
    );
}

#[test]
fn photo_outside_the_grid_is_an_error() {
    let grid = read_dem(data("ramp_f32_geo.tif"), &ReadOptions::default()).unwrap();
    // The UTM photo's coordinates are nowhere near 138° E 36° N in degrees.
    let photo = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::bands(None)).unwrap();
    let e = gst::place(&photo, &grid, 16).unwrap_err();
    assert!(e.to_string().contains("does not overlap"), "{e}");
}

#[test]
fn a_failed_build_leaves_nothing_behind() {
    // The photo does not overlap: the build fails after the chunks are written, and neither the
    // database nor its temporary directory remains.
    let grid = read_dem(data("ramp_f32_geo.tif"), &ReadOptions::default()).unwrap();
    let photo = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::bands(None)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("db");
    let opts = BuildOptions {
        max_error: 0.5,
        chunk: 17,
        map_texels: 16,
        max_texture_levels: 2,
        ..Default::default()
    };
    let e = db::build(&grid, "geo", Some(&photo), &opts, &out, |_, _| {}).unwrap_err();
    assert!(e.to_string().contains("does not overlap"), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Contour lines without a photo: the database's texture is the shaded relief with brown lines
/// where the heights cross the levels, and nowhere else. The ramp GeoTIFF rises along its
/// rows; a line every 25 m crosses it, so the finest level's texels near a level are brown.
#[test]
fn contours_are_drawn_into_the_relief_texture() {
    use texmap_terrain::relief::{CONTOUR_COLOUR, Contours};
    let grid = read_dem(data("ramp_i16_lzw.tif"), &ReadOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let build = |name: &str, contours: Option<Contours>| {
        let out = dir.path().join(name);
        let opts = BuildOptions {
            max_error: 0.5,
            chunk: 17,
            map_texels: 64,
            max_texture_levels: 2,
            contours,
            ..BuildOptions::default()
        };
        let m = db::build(&grid, "ramp", None, &opts, &out, |_, _| {}).unwrap();
        (out, m)
    };
    let (plain, m0) = build("plain", None);
    assert!(m0.texture.is_none());
    let c = Contours::every(25.0);
    let (lined, m) = build("lined", Some(c));
    let tex = m.texture.unwrap();
    assert_eq!(tex.placed_by, "stretched");
    assert!(!plain.join("tiles").exists());
    // Every texel of the finest level: brown exactly where the coverage says so.
    let finest = tex.levels - 1;
    let n = 1u32 << finest;
    let size = tex.map_texels * n;
    let per = [
        (grid.width() - 1) as f64 / (size - 1) as f64,
        (grid.height() - 1) as f64 / (size - 1) as f64,
    ];
    let (mut lit, mut checked) = (0, 0);
    for (x, y) in (0..n).flat_map(|x| (0..n).map(move |y| (x, y))) {
        let map = image::open(lined.join(format!("tiles/{finest}/{x}_{y}.png")))
            .unwrap()
            .to_rgba8();
        for (i, j, px) in map.enumerate_pixels() {
            let (gx, gy) = (x * tex.map_texels + i, y * tex.map_texels + j);
            let cover = c.coverage(&grid, gx as f64 * per[0], gy as f64 * per[1], per);
            let brown = px.0[..3] == CONTOUR_COLOUR;
            if cover == 1.0 {
                assert!(brown, "texel ({gx}, {gy}) on a line: {:?}", px.0);
                lit += 1;
            } else if cover == 0.0 {
                assert!(!brown, "texel ({gx}, {gy}) off the lines is brown");
            }
            checked += 1;
        }
    }
    assert!(
        lit > 100 && lit < checked / 4,
        "{lit} of {checked} texels on a line"
    );
}

/// GeoJSON overlays go into the finest maps as `vector::Overlay` draws them, are averaged into
/// the coarser ones, are listed in the manifest; a layer off the terrain fails the build before
/// anything is left on disk.
#[test]
fn overlays_are_drawn_into_the_texture() {
    use texmap_terrain::vector::{Overlay, Style, read_geojson};
    let grid = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let layer = read_geojson(data("vector_wgs84.geojson")).unwrap();
    let style = Style::default()
        .with_keys("fill=#0000ff,fill-opacity=1,stroke=none,marker-color=none")
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    // A plain grey photo stretched over the grid, large enough for three texture levels.
    let png = dir.path().join("grey.png");
    image::RgbaImage::from_pixel(300, 300, image::Rgba([128, 128, 128, 255]))
        .save(&png)
        .unwrap();
    let photo = gst::read_photo(&png, &PhotoOptions::bands(None)).unwrap();
    let out = dir.path().join("v.db");
    let opts = BuildOptions {
        max_error: 1.0,
        chunk: 33,
        map_texels: 64,
        max_texture_levels: 3,
        overlays: vec![layer.clone()],
        overlay_style: style,
        ..BuildOptions::default()
    };
    let m = db::build(&grid, "utm", Some(&photo), &opts, &out, |_, _| {}).unwrap();
    let tex = m.texture.clone().unwrap();
    assert_eq!(tex.levels, 3);
    assert_eq!(tex.overlays.len(), 1);
    // Drawn: the lake and the forest (filled), the road (its own red stroke); not the trail
    // (no stroke), the points (no colour) nor the feature without geometry.
    assert_eq!((tex.overlays[0].features, tex.overlays[0].drawn), (7, 3));
    let finest = tex.levels - 1;
    let n = 1u32 << finest;
    let o = Overlay::place(std::slice::from_ref(&layer), &style, &grid, 64 * n, 64).unwrap();
    let (mut same, mut blue) = (0, 0);
    for my in 0..n {
        for mx in 0..n {
            let tile = image::open(out.join(format!("tiles/{finest}/{mx}_{my}.png")))
                .unwrap()
                .to_rgba8();
            let mut drawn = tile.clone();
            // Drawing the overlay again over the tile changes nothing where it is opaque.
            o.draw(mx, my, &mut drawn);
            for (a, b) in tile.pixels().zip(drawn.pixels()) {
                if a.0 == [0, 0, 255, 255] {
                    blue += 1;
                    same += (a == b) as usize;
                }
            }
        }
    }
    // The lake and the forest: about a quarter of the 256² texels (tests/vector.rs).
    assert!(blue > 14_000 && same == blue, "{blue} {same}");
    let coarse = image::open(out.join("tiles/0/0_0.png")).unwrap().to_rgba8();
    assert!(
        coarse
            .pixels()
            .filter(|p| p.0[2] > 200 && p.0[0] < 60)
            .count()
            > 50
    );
    let back = Database::open(&out).unwrap();
    assert_eq!(back.manifest.texture.unwrap().overlays, tex.overlays);

    // A layer far from the grid: an error naming it, and no database.
    let far = texmap_terrain::vector::parse_geojson(
        br#"{"type":"Point","coordinates":[10.0, 50.0]}"#,
        "far.geojson",
    )
    .unwrap();
    let bad = dir.path().join("bad.db");
    let opts = BuildOptions {
        overlays: vec![far],
        ..opts
    };
    let e = db::build(&grid, "utm", Some(&photo), &opts, &bad, |_, _| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("far.geojson") && e.contains("does not overlap"),
        "{e}"
    );
    assert!(!bad.exists());
}

/// A gdaldem colour file tints the relief where the photo does not cover: each texel west of
/// the photo is the file's colour of its nearest sample's height, interpolated here by hand
/// (gdaldem's linear rule, channels rounded as `⌊0.45 + c⌋`), times the hillshade factor
/// `0.35 + 0.9·shade`. The resolved table is in the manifest: a reopened database colours the
/// same texels without the file, and a database built without it keeps the built-in ramp.
#[test]
fn relief_colors_tint_the_relief_texture() {
    use texmap_terrain::dem_products::ColorTable;
    use texmap_terrain::relief::{Hillshade, Tint, TintTable, relief_texel};
    let grid = read_dem(data("ramp_i16_lzw.tif"), &ReadOptions::default()).unwrap();
    let photo = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::bands(None)).unwrap();
    let (lo, hi) = grid.height_range();
    let (lo, hi) = (lo as f64, hi as f64);
    // One absolute height (inside the range) between two percentages.
    let mid = lo + 0.3 * (hi - lo);
    let text = format!("0% 0 0 0\n{mid} 200 100 0\n100% 255 255 255\nnv 0 0 255\n");
    let table = ColorTable::parse(&text, "colors.txt").unwrap();
    let tint = Tint::Table(TintTable::resolve(&table, &grid));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("db");
    let opts = BuildOptions {
        max_error: 0.5,
        chunk: 17,
        map_texels: 16,
        max_texture_levels: 3,
        tint: tint.clone(),
        ..Default::default()
    };
    let m = db::build(&grid, "ramp", Some(&photo), &opts, &out, |_, _| {}).unwrap();
    let saved = m.relief_tint.clone().expect("the table is in the manifest");
    assert_eq!(Tint::Table(saved), tint);

    // The colour file's linear interpolation, by hand.
    let stops = [
        (lo, [0.0, 0.0, 0.0]),
        (mid, [200.0, 100.0, 0.0]),
        (hi, [255.0; 3]),
    ];
    let by_hand = |v: f64| -> [f64; 3] {
        let i = stops.iter().position(|s| s.0 >= v).unwrap_or(2).max(1);
        let (a, b) = (stops[i - 1], stops[i]);
        let t = ((v - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
        [0, 1, 2].map(|k| (0.45 + a.1[k] + t * (b.1[k] - a.1[k])).floor())
    };
    let shade = Hillshade::new(&grid, Default::default());
    let d = Database::open(&out).unwrap();
    let tex = d.texture(4096).unwrap().unwrap();
    let w = tex.width();
    assert_eq!(w, 64, "the finest level: 16 · 2² texels");
    let nearest =
        |t: u32, n: u32| (((t as f64 + 0.5) / w as f64 * (n - 1) as f64).round() as u32).min(n - 1);
    // The photo covers columns 18..=36: texels west of column 15 are all relief.
    let west = (15.0 / 36.0 * (w - 1) as f64) as u32;
    let (mut checked, mut unlike_ramp) = (0, 0);
    for y in 0..tex.height() {
        for x in 0..west {
            let (col, row) = (nearest(x, grid.width()), nearest(y, grid.height()));
            let got = tex.get_pixel(x, y).0;
            let want = match shade.at(col, row) {
                None => [0.0, 0.0, 255.0],
                Some(s) => {
                    let k = 0.35 + 0.9 * s;
                    by_hand(grid.at(col, row) as f64).map(|c| (c * k).round().min(255.0))
                }
            };
            // 1 level: the texture scales the colour by `k` in f32, the reference in f64, and
            // a product within an ulp of a half rounds either way.
            for i in 0..3 {
                assert!(
                    (got[i] as f64 - want[i]).abs() <= 1.0,
                    "texel ({x}, {y}) channel {i}: expected {want:?}, got {got:?}, tolerance 1"
                );
            }
            assert_eq!(got[3], 255);
            if got != relief_texel(&grid, &shade, w, x, y) {
                unlike_ramp += 1;
            }
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked} texels checked");
    assert!(
        unlike_ramp > checked / 2,
        "{unlike_ramp} of {checked} unlike the ramp"
    );

    // Reopened, without the file: the manifest's table colours the same texels, and the maps a
    // streamed texture reads are the ones the texture was assembled from.
    let again = Database::open(&out).unwrap();
    assert_eq!(again.tint(), tint);
    let g2 = again.grid().unwrap();
    let shade2 = Hillshade::new(&g2, Default::default());
    for (x, y) in [(0, 0), (3, 40), (west - 1, 63), (10, 20)] {
        assert_eq!(
            again.tint().texel(&g2, &shade2, w, x, y),
            tex.get_pixel(x, y).0,
            "texel ({x}, {y})"
        );
    }
    let finest = m.texture.as_ref().unwrap().levels - 1;
    for (mx, my) in [(0, 0), (0, 3), (1, 2)] {
        let map = again
            .map(gst::MapKey {
                level: finest,
                x: mx,
                y: my,
            })
            .unwrap();
        for (i, j, px) in map.enumerate_pixels() {
            assert_eq!(*px, *tex.get_pixel(mx * 16 + i, my * 16 + j));
        }
    }

    // The no-data sample takes the nv colour; without a table it is the ramp's grey.
    let (nc, nr) = (0..grid.height())
        .flat_map(|r| (0..grid.width()).map(move |c| (c, r)))
        .find(|&(c, r)| grid.at(c, r).is_nan())
        .unwrap();
    assert_eq!(tint.colour(&grid, &shade, nc, nr), [0, 0, 255, 255]);
    assert_eq!(
        Tint::Ramp.colour(&grid, &shade, nc, nr),
        [128, 128, 128, 255]
    );

    // Without a photo the tinted relief is the texture; without a table the manifest has no
    // tint and a relief-only database no texture, as before.
    let bare = dir.path().join("bare");
    let m = db::build(&grid, "ramp", None, &opts, &bare, |_, _| {}).unwrap();
    assert_eq!(m.texture.as_ref().unwrap().placed_by, "stretched");
    assert!(m.relief_tint.is_some());
    let plain = dir.path().join("plain");
    let plain_opts = BuildOptions {
        tint: Tint::Ramp,
        ..opts
    };
    let m = db::build(&grid, "ramp", None, &plain_opts, &plain, |_, _| {}).unwrap();
    assert!(m.texture.is_none() && m.relief_tint.is_none());
    let json = std::fs::read_to_string(plain.join("manifest.json")).unwrap();
    assert!(!json.contains("relief_tint"), "{json}");
}
