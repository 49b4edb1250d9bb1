//! The 3D Tiles export against other programs' numbers: GDAL's reading of the real SRTM tile
//! N44W072.hgt (its georeference and corner heights, tests/data/srtm_facts.sh); the geodesy under
//! it is checked against PROJ in tests/geodesy.rs.

use std::collections::HashMap;
use std::path::PathBuf;

use glam::DVec3;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{ReadOptions, read_dem};
use texmap_terrain::geodesy::ecef;
use texmap_terrain::geoid::Geoid;
use texmap_terrain::photo::PhotoOptions;
use texmap_terrain::tiles3d::{TilesetOptions, write_tileset, write_tileset_with};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The database built from `grid` (and `photo`) in `dir/name`, opened.
fn built(
    dir: &std::path::Path,
    name: &str,
    grid: &texmap_terrain::dem::Grid,
    photo: Option<&texmap_terrain::gst::Orthophoto>,
    opts: BuildOptions,
) -> Database {
    let path = dir.join(name);
    db::build(grid, name, photo, &opts, &path, |_, _| {}).unwrap();
    Database::open(&path).unwrap()
}

/// A tile of the tree with its absolute transform (translations compose from the root).
struct Seen {
    origin: DVec3,
    centre: DVec3,
    half: DVec3,
    depth: u32,
    uri: Option<String>,
}

fn walk(v: &serde_json::Value, parent: DVec3, depth: u32, parent_error: f64, out: &mut Vec<Seen>) {
    let t: Vec<f64> = v["transform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(t.len(), 16);
    let origin = parent + DVec3::new(t[12], t[13], t[14]);
    let b: Vec<f64> = v["boundingVolume"]["box"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let error = v["geometricError"].as_f64().unwrap();
    assert!(
        error <= parent_error,
        "a child's geometricError {error} above its parent's {parent_error}"
    );
    out.push(Seen {
        origin,
        centre: origin + DVec3::new(b[0], b[1], b[2]),
        half: DVec3::new(b[3], b[7], b[11]),
        depth,
        uri: v["content"]["uri"].as_str().map(String::from),
    });
    for c in v["children"].as_array().into_iter().flatten() {
        walk(c, origin, depth + 1, error, out);
    }
}

/// The SRTM tile as a tileset: the quadtree (1 + 4 + 9 + 25 chunks) with monotone errors, every
/// glTF vertex inside its tile's box, the texture in each tile, and the grid's four corners —
/// always mesh vertices — exactly where GDAL's georeference and heights put them on the ellipsoid.
#[test]
fn srtm_tileset_is_placed_where_gdal_puts_the_tile() {
    let dir = tempfile::tempdir().unwrap();
    let grid = read_dem(data("N44W072.hgt"), &ReadOptions::default()).unwrap();
    let d = built(dir.path(), "srtm.db", &grid, None, BuildOptions::default());
    let out = dir.path().join("tiles");
    let s = write_tileset(&d, &out, 1024).unwrap();
    let chunks: usize = d.manifest.levels.iter().map(|l| l.chunks.len()).sum();
    assert_eq!((s.tiles, s.with_content), (chunks, chunks));
    // Writing again over it is refused, the tileset untouched.
    assert!(write_tileset(&d, &out, 1024).is_err());

    let (ts, seen) = read_tileset(&out);
    assert_eq!(ts["asset"]["version"], "1.1");
    assert_eq!(seen.len(), chunks);
    // Leaving the whole terrain out is at least as wrong as its extent (CesiumJS draws nothing
    // while the tileset's error projects under its pixel tolerance: an error of only twice the
    // root's hid this tile from 70 km).
    let root_radius = seen[0].half.length();
    assert!(
        ts["geometricError"].as_f64().unwrap() >= root_radius,
        "{}",
        ts["geometricError"]
    );

    // GDAL's corners: geoTransform (pixel corners) + half a pixel, and its heights.
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("N44W072.gdalinfo.json")).unwrap())
            .unwrap();
    let gt: Vec<f64> = info["geoTransform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let samples = std::fs::read_to_string(data("N44W072.gdal_samples.txt")).unwrap();
    let corners: Vec<DVec3> = samples
        .lines()
        .take(4)
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            let lon = gt[0] + (v[0] + 0.5) * gt[1];
            let lat = gt[3] + (v[1] + 0.5) * gt[5];
            DVec3::from(ecef(lon, lat, v[2]))
        })
        .collect();
    let mut nearest = [f64::INFINITY; 4];
    let mut per_depth: HashMap<u32, usize> = HashMap::new();
    let finest = seen.iter().map(|t| t.depth).max().unwrap();
    for t in &seen {
        *per_depth.entry(t.depth).or_default() += 1;
        let uri = t.uri.as_ref().unwrap();
        let (vertices, images) = tile_vertices(&out, t);
        assert_eq!(images, 1, "{uri}: one texture");
        for w in vertices {
            let off = (w - t.centre).abs() - t.half;
            assert!(
                off.max_element() < 0.05,
                "{uri}: vertex {w} outside its box by {off}"
            );
            if t.depth == finest {
                for (k, c) in corners.iter().enumerate() {
                    nearest[k] = nearest[k].min(w.distance(*c));
                }
            }
        }
    }
    assert_eq!(per_depth.len(), d.manifest.levels.len());
    // Single-precision offsets from tile centres some 10 km away: within a few centimetres.
    eprintln!("corners: nearest finest-tile vertices {nearest:?} m away");
    for (k, n) in nearest.iter().enumerate() {
        assert!(*n < 0.03, "corner {k}: nearest vertex {n} m away");
    }
}

/// The tileset.json written into `out`, and its tiles in walk order (checked by `walk`).
fn read_tileset(out: &std::path::Path) -> (serde_json::Value, Vec<Seen>) {
    let ts: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("tileset.json")).unwrap()).unwrap();
    let mut seen = Vec::new();
    walk(
        &ts["root"],
        DVec3::ZERO,
        0,
        ts["geometricError"].as_f64().unwrap(),
        &mut seen,
    );
    (ts, seen)
}

/// A tile's vertices in earth-centred metres (glTF y-up read as z-up, `(x, y, z) -> (x, −z, y)`,
/// then the tile's transform), and how many images its glTF holds.
fn tile_vertices(out: &std::path::Path, t: &Seen) -> (Vec<DVec3>, usize) {
    let (doc, buffers, images) = gltf::import(out.join(t.uri.as_ref().unwrap())).unwrap();
    let mut v = Vec::new();
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let r = prim.reader(|b| Some(&buffers[b.index()]));
            v.extend(
                r.read_positions()
                    .unwrap()
                    .map(|p| t.origin + DVec3::new(p[0] as f64, -p[2] as f64, p[1] as f64)),
            );
        }
    }
    (v, images.len())
}

/// The same files, byte for byte, for any thread count (tiles are written in parallel).
#[test]
fn tileset_bytes_do_not_depend_on_threads() {
    let dir = tempfile::tempdir().unwrap();
    let grid = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let opts = BuildOptions {
        chunk: 17,
        ..BuildOptions::default()
    };
    let d = built(dir.path(), "utm.db", &grid, None, opts);
    let files = |threads: usize| {
        let out = dir.path().join(format!("t{threads}"));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let s = pool.install(|| write_tileset(&d, &out, 1024)).unwrap();
        assert!(s.tiles > 5, "{s:?}");
        let mut all = vec![(
            "tileset.json".to_string(),
            std::fs::read(out.join("tileset.json")).unwrap(),
        )];
        for level in &d.manifest.levels {
            for c in &level.chunks {
                let rel = format!("tiles/{}/{}_{}.glb", level.depth, c.ix, c.iy);
                all.push((rel.clone(), std::fs::read(out.join(&rel)).unwrap()));
            }
        }
        all
    };
    assert!(files(1) == files(2));
}

/// Tile textures come from the database at the finest resolution that fits: a root tile over the
/// whole grid carries exactly the photo's GST level that `Database::texture` assembles (a GDAL-
/// written UTM photo), or exactly the relief image at one texel per sample.
#[test]
fn tile_textures_are_the_databases_texels() {
    use texmap_terrain::gst;
    let dir = tempfile::tempdir().unwrap();
    let root_image = |tiles: &std::path::Path| {
        let (_, _, images) = gltf::import(tiles.join("tiles/0/0_0.glb")).unwrap();
        let img = &images[0];
        assert_eq!(img.format, gltf::image::Format::R8G8B8A8);
        (img.width, img.height, img.pixels.clone())
    };
    // A photo placed by its georeference (UTM 54N, as the grid).
    let grid = read_dem(data("ramp_i16_lzw.tif"), &ReadOptions::default()).unwrap();
    let photo = gst::read_photo(&data("photo_rgb.tif"), &PhotoOptions::bands(None)).unwrap();
    let d = built(
        dir.path(),
        "photo.db",
        &grid,
        Some(&photo),
        BuildOptions::default(),
    );
    assert_eq!(d.manifest.levels[0].chunks.len(), 1);
    let out = dir.path().join("photo_tiles");
    write_tileset(&d, &out, 1024).unwrap();
    let want = d.texture(1024).unwrap().unwrap();
    assert_eq!(
        root_image(&out),
        (want.width(), want.height(), want.into_raw())
    );
    // Shaded relief.
    let grid = read_dem(data("hillshade_dem_utm.tif"), &ReadOptions::default()).unwrap();
    let relief = built(
        dir.path(),
        "relief.db",
        &grid,
        None,
        BuildOptions::default(),
    );
    let out = dir.path().join("relief_tiles");
    write_tileset(&relief, &out, 1024).unwrap();
    let want = texmap_terrain::relief::relief_image(&grid, 4096);
    assert_eq!(root_image(&out), (64, 64, want.into_raw()));
}

/// A Web Mercator grid (GDAL's EPSG:3857 warp of an SRTM cut) goes on the globe through its
/// inverse projection: the finest tiles' vertices reach the earth-centred position of each valid
/// corner sample (longitude and latitude by `web_mercator_to_lonlat`, checked against PROJ in
/// tests/geodesy.rs; its height as ellipsoidal).
#[test]
fn web_mercator_tileset_is_placed_through_its_projection() {
    use texmap_terrain::geodesy::web_mercator_to_lonlat;
    let dir = tempfile::tempdir().unwrap();
    let grid = read_dem(data("dem_merc.tif"), &ReadOptions::default()).unwrap();
    let opts = BuildOptions {
        chunk: 33,
        ..BuildOptions::default()
    };
    let d = built(dir.path(), "merc.db", &grid, None, opts);
    let out = dir.path().join("tiles");
    write_tileset(&d, &out, 1024).unwrap();
    let (_, seen) = read_tileset(&out);
    let (w, h) = (grid.width() - 1, grid.height() - 1);
    let g = grid.georef();
    let corners: Vec<DVec3> = [(0, 0), (w, 0), (0, h), (w, h)]
        .into_iter()
        .filter_map(|(c, r)| {
            let z = grid.heights()[(r * grid.width() + c) as usize];
            let (x, y) = g.sample_xy(c as f64, r as f64);
            let (lon, lat) = web_mercator_to_lonlat(x, y);
            (!z.is_nan()).then(|| DVec3::from(ecef(lon, lat, z as f64)))
        })
        .collect();
    assert!(corners.len() >= 2, "valid corners: {}", corners.len());
    let finest = seen.iter().map(|t| t.depth).max().unwrap();
    let mut nearest = vec![f64::INFINITY; corners.len()];
    for t in seen.iter().filter(|t| t.depth == finest) {
        for v in tile_vertices(&out, t).0 {
            for (k, c) in corners.iter().enumerate() {
                nearest[k] = nearest[k].min(v.distance(*c));
            }
        }
    }
    for (k, n) in nearest.iter().enumerate() {
        assert!(*n < 0.03, "corner {k}: nearest vertex {n} m away");
    }
}

/// Heights above EGM96 (SRTM's) become ellipsoidal through the geoid grid: the tile's corners
/// land where PROJ puts them (`gdaltransform -s_srs EPSG:4326+5773 -t_srs EPSG:4979` with
/// proj-data's egm96_15.gtx, tests/data/geoid.sh), 26.5-28 m below the heights taken as
/// ellipsoidal; a grid that does not cover the terrain is refused by name.
#[test]
fn geoid_heights_land_where_proj_puts_them() {
    let dir = tempfile::tempdir().unwrap();
    let grid = read_dem(data("N44W072.hgt"), &ReadOptions::default()).unwrap();
    let d = built(dir.path(), "srtm.db", &grid, None, BuildOptions::default());
    let geoid = Geoid::open(data("egm96_cut.gtx")).unwrap();
    let out = dir.path().join("tiles");
    let options = TilesetOptions {
        geoid: Some(&geoid),
        ..TilesetOptions::default()
    };
    write_tileset_with(&d, &out, &options).unwrap();
    let (ts, seen) = read_tileset(&out);
    let heights = ts["asset"]["extras"]["heights"].as_str().unwrap();
    assert!(heights.contains("egm96_cut.gtx"), "{heights}");
    // PROJ's ellipsoidal heights of the four corner samples: "corner lon lat H h".
    let proj = std::fs::read_to_string(data("geoid_proj.txt")).unwrap();
    let corners: Vec<(DVec3, f64)> = proj
        .lines()
        .filter_map(|l| l.strip_prefix("corner "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (DVec3::from(ecef(v[0], v[1], v[3])), v[2] - v[3])
        })
        .collect();
    assert_eq!(corners.len(), 4);
    let finest = seen.iter().map(|t| t.depth).max().unwrap();
    let mut nearest = [f64::INFINITY; 4];
    for t in seen.iter().filter(|t| t.depth == finest) {
        for w in tile_vertices(&out, t).0 {
            for (k, (c, _)) in corners.iter().enumerate() {
                nearest[k] = nearest[k].min(w.distance(*c));
            }
        }
    }
    eprintln!("geoid corners: nearest finest-tile vertices {nearest:?} m away");
    for (k, n) in nearest.iter().enumerate() {
        assert!(*n < 0.03, "corner {k}: nearest vertex {n} m away");
        let lift = corners[k].1;
        assert!((26.0..29.0).contains(&lift), "corner {k}: H - h = {lift}");
    }
    // A geoid grid away from the terrain: refused, naming the grid and the point.
    let mut far = std::fs::read(data("egm96_cut.gtx")).unwrap();
    far[8..16].copy_from_slice(&10.0f64.to_be_bytes()); // west edge at 10°E
    let far = Geoid::from_gtx(&far, "far.gtx").unwrap();
    let options = TilesetOptions {
        geoid: Some(&far),
        ..TilesetOptions::default()
    };
    let e = write_tileset_with(&d, &dir.path().join("far"), &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("far.gtx: ") && e.contains("no undulation at longitude -7"),
        "{e}"
    );
    assert!(!dir.path().join("far").exists());
}
