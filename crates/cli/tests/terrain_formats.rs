//! `texmap terrain build` and `info` on a DTED cell and an ESRI GridFloat that GDAL wrote
//! (crates/terrain/tests/data/dem_formats.sh): the databases report the grids' size,
//! georeference and no-data; a DTED record whose checksum fails is a runtime error naming it,
//! read anyway with --ignore-checksums. Web-map Terrarium tiles (z/x/y PNGs that numpy encoded
//! from GDAL's EPSG:3857 reprojection of the SRTM tile, crates/terrain/tests/data/xyz_tiles.sh)
//! join into one Web Mercator grid placed where gdalbuildvrt places them; bad addresses and mixed
//! zooms are runtime errors naming the files.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use common::texmap;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../terrain/tests/data")
        .join(name)
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn info(path: &Path) -> serde_json::Value {
    let o = texmap(&["terrain", "info", path.to_str().unwrap()]);
    ok(&o);
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Width and height as `terrain info` reports them.
fn size(j: &serde_json::Value) -> (Option<u64>, Option<u64>) {
    (j["width"].as_u64(), j["height"].as_u64())
}

fn build(dem: &Path, out: &Path, extra: &[&str]) -> Output {
    let (dem, out) = (dem.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec!["terrain", "build", "--dem", dem, "--out", out, "-q"];
    args.extend(extra);
    texmap(&args)
}

#[test]
fn a_dted_cell_builds_a_database() {
    let dir = tempfile::tempdir().unwrap();
    // The level 1 cell GDAL wrote (heights in a 256² window of the SRTM tile, void elsewhere).
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(data("n44w072.dt1.gz")).unwrap())
        .read_to_end(&mut bytes)
        .unwrap();
    let dt1 = dir.path().join("n44w072.dt1");
    std::fs::write(&dt1, &bytes).unwrap();
    let grid = info(&dt1);
    assert_eq!(size(&grid), (Some(1201), Some(1201)));
    assert_eq!(grid["nodata"].as_u64(), Some(1201 * 1201 - 256 * 256));
    let db = dir.path().join("dt1.db");
    ok(&build(&dt1, &db, &[]));
    let j = info(&db);
    assert_eq!(size(&j), (Some(1201), Some(1201)));
    // The SRTM tile's georeference: sample (0, 0) on 72° W 45° N, 3″ apart (gdalinfo: corner
    // −72.000416…, 45.000416…).
    let g = &j["georef"];
    assert_eq!(g["crs"], "geographic");
    assert_eq!(g["epsg"], 4326);
    assert_eq!(
        (g["origin_x"].as_f64(), g["origin_y"].as_f64()),
        (Some(-72.0), Some(45.0))
    );
    assert!(
        (g["dx"].as_f64().unwrap() - 1.0 / 1200.0).abs() < 1e-15,
        "{g}"
    );
    // Mount Washington, 1908 m in this grid, and the window's lowest sample (gdalinfo -stats).
    assert_eq!(
        (j["height_min"].as_f64(), j["height_max"].as_f64()),
        (Some(256.0), Some(1908.0))
    );
    assert_eq!(j["nodata"], grid["nodata"]);
    assert!(j["levels"].as_array().unwrap().len() >= 2, "{j}");
}

#[test]
fn a_damaged_dted_record_is_named_or_read_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let mut cell = std::fs::read(data("n44w072.dt0")).unwrap();
    // One height of record 57 changed under its checksum (bytes 18156..18160).
    let record = 12 + 2 * 121;
    cell[3428 + 57 * record + 69] ^= 0x04;
    let bad = dir.path().join("n44w072.dt0");
    std::fs::write(&bad, &cell).unwrap();
    let db = dir.path().join("bad.db");
    let o = build(&bad, &db, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("n44w072.dt0: byte 18156, record 57") && err.contains("--ignore-checksums"),
        "{err}"
    );
    assert!(!db.exists(), "no partial database");
    ok(&build(&bad, &db, &["--ignore-checksums"]));
    assert_eq!(info(&db)["width"], 121);
}

#[test]
fn a_gridfloat_builds_a_database() {
    let dir = tempfile::tempdir().unwrap();
    // GDAL's GridFloat of the UTM 54N ramp: 37 x 29 samples 30 m apart, one no-data sample.
    let flt = data("ramp_utm.flt");
    let db = dir.path().join("flt.db");
    ok(&build(&flt, &db, &[]));
    let j = info(&db);
    assert_eq!(size(&j), (Some(37), Some(29)));
    assert_eq!(j["nodata"], 1);
    let g = &j["georef"];
    assert_eq!(
        (g["crs"].as_str(), g["epsg"].as_u64()),
        (Some("projected"), Some(32654))
    );
    // gdalinfo: corner (500000, 3900870), 30 m pixels: the first centre 15 m in.
    assert_eq!(
        (g["origin_x"].as_f64(), g["origin_y"].as_f64()),
        (Some(500015.0), Some(3900855.0))
    );
    assert_eq!(
        (j["height_min"].as_f64(), j["height_max"].as_f64()),
        (Some(100.0), Some(256.0))
    );
    // The USGS-style header over geographic samples, read directly.
    let usgs = info(&data("ramp_usgs.flt"));
    assert_eq!(usgs["georef"]["crs"], "geographic");
    assert_eq!(usgs["nodata"], 1);
    // A GridFloat without its header: named.
    let lone = dir.path().join("lone.flt");
    std::fs::copy(&flt, &lone).unwrap();
    let o = build(&lone, &dir.path().join("lone.db"), &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("lone.hdr"), "{err}");
}

fn xyz(name: &str) -> PathBuf {
    data("xyz").join(name)
}

#[test]
fn web_map_tiles_build_a_web_mercator_database() {
    let dir = tempfile::tempdir().unwrap();
    let tiles = ["10/308/370.png", "10/309/370.png", "10/309/371.png"]
        .map(|t| xyz("terrarium").join(t).to_str().unwrap().to_string());
    let db = dir.path().join("tiles.db");
    let mut args = vec![
        "terrain",
        "build",
        "--terrarium",
        "--out",
        db.to_str().unwrap(),
        "-q",
    ];
    args.push("--dem");
    args.extend(tiles.iter().map(String::as_str));
    ok(&texmap(&args));
    let j = info(&db);
    // gdalbuildvrt of the three tiles: 512 x 512, corner (-7983694.730330089, 5557277.704445455),
    // 152.87405657035197 m pixels; 10/308/371 is missing, its 256² samples no-data.
    let gdal: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(xyz("joined_terrarium.gdalinfo.json")).unwrap(),
    )
    .unwrap();
    let t: Vec<f64> = serde_json::from_value(gdal["geoTransform"].clone()).unwrap();
    assert_eq!(size(&j), (Some(512), Some(512)));
    assert_eq!(j["nodata"], 256 * 256);
    let g = &j["georef"];
    assert_eq!(
        (g["crs"].as_str(), g["epsg"].as_u64()),
        (Some("projected"), Some(3857))
    );
    for (key, want) in [
        ("origin_x", t[0] + 0.5 * t[1]),
        ("origin_y", t[3] + 0.5 * t[5]),
        ("dx", t[1]),
        ("dy", t[5]),
    ] {
        let ours = g[key].as_f64().unwrap();
        assert!((ours - want).abs() < 1e-6, "{key}: {ours}, GDAL {want}");
    }
    // The same tiles as Terrain-RGB: mutually exclusive flags are a usage error.
    let o = texmap(&[
        "terrain",
        "build",
        "--terrarium",
        "--terrain-rgb",
        "--dem",
        &tiles[0],
        "--out",
        dir.path().join("x.db").to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn bad_tile_addresses_and_mixed_zooms_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let tile = xyz("terrarium/10/308/370.png");
    let put = |rel: &str| {
        let p = dir.path().join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::copy(&tile, &p).unwrap();
        p.to_str().unwrap().to_string()
    };
    let run = |dems: &[&str], extra: &[&str]| {
        let out = dir.path().join("bad.db");
        let mut args = vec![
            "terrain",
            "build",
            "--terrarium",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        args.push("--dem");
        args.extend(dems);
        let o = texmap(&args);
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).to_string(),
        )
    };
    // x ≥ 2^z: a runtime error naming the file.
    let bad = put("10/1024/370.png");
    let (code, err) = run(&[&bad], &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("10/1024/370.png") && err.contains("tile address"),
        "{err}"
    );
    // Mixed zooms: both files named.
    let z11 = put("11/616/740.png");
    let (code, err) = run(&[tile.to_str().unwrap(), &z11], &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("11/616/740.png") && err.contains("10/308/370.png"),
        "{err}"
    );
    // --tile: a malformed address, or several files, are usage errors; a good one places a file
    // whose path has none.
    let (code, err) = run(&[tile.to_str().unwrap()], &["--tile", "10/308"]);
    assert_eq!(code, Some(2), "{err}");
    let (code, err) = run(&[tile.to_str().unwrap(), &z11], &["--tile", "10/308/370"]);
    assert_eq!(code, Some(2), "{err}");
    let plain = dir.path().join("plain.png");
    std::fs::copy(&tile, &plain).unwrap();
    let db = dir.path().join("plain.db");
    ok(&texmap(&[
        "terrain",
        "build",
        "--terrarium",
        "--tile",
        "10/308/370",
        "--dem",
        plain.to_str().unwrap(),
        "--out",
        db.to_str().unwrap(),
        "-q",
    ]));
    assert_eq!(info(&db)["georef"]["epsg"], 3857);
}
