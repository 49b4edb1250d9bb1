//! `texmap terrain ...` end to end on DEMs GDAL wrote (crates/terrain/tests/data): what a script
//! sees — files, JSON, exit codes; and lidar point clouds gridded to GeoTIFF and built into
//! databases.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use common::texmap;

fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../terrain/tests/data")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Asserts that `texmap` exited with `code` (2: bad usage, 1: a runtime failure), showing its
/// stderr otherwise.
fn exits(o: &Output, code: i32) {
    assert_eq!(
        o.status.code(),
        Some(code),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn build_info_maps_export_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let db = small_db(dir.path());
    let db_s = db.to_str().unwrap();
    // The database reports the grid GDAL wrote (37 x 29 samples, one no-data sample).
    let o = texmap(&["terrain", "info", db_s]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["width"], 37);
    assert_eq!(v["height"], 29);
    assert_eq!(v["nodata"], 1);
    assert_eq!(v["texture"]["placed_by"], "georeference");
    // Seed 000's worked example: 324 maps.
    let o = texmap(&[
        "terrain",
        "maps",
        "--fov",
        "45",
        "--pixels",
        "1024",
        "--map-texels",
        "256",
        "--levels",
        "9",
    ]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["total"], 324);
    // Export: a .glb that the gltf crate reads back, and an OBJ.
    let glb = dir.path().join("area.glb");
    ok(&texmap(&[
        "terrain",
        "export",
        db_s,
        "--max-error",
        "1",
        "-o",
        glb.to_str().unwrap(),
    ]));
    let (doc, _, images) = gltf::import(&glb).expect("a valid glTF");
    assert_eq!(doc.meshes().count(), 1);
    assert_eq!(images.len(), 1);
    let obj = dir.path().join("area.obj");
    ok(&texmap(&[
        "terrain",
        "export",
        db_s,
        "-o",
        obj.to_str().unwrap(),
    ]));
    assert!(obj.exists() && dir.path().join("area.mtl").exists());
    // A flight view with each sampler family, and its statistics as JSON.
    for sampler in ["trilinear", "span3", "quadratic3"] {
        let png = dir.path().join(format!("{sampler}.png"));
        let o = texmap(&[
            "terrain",
            "render",
            db_s,
            "--sampler",
            sampler,
            "--size",
            "160x120",
            "--stats",
            "-o",
            png.to_str().unwrap(),
        ]);
        ok(&o);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert!(v["frame"]["chunks_drawn"].as_u64().unwrap() >= 1, "{v}");
        assert!(png.exists());
    }
}

#[test]
fn bad_input_gets_exit_codes_scripts_can_trust() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("a.db");
    let db_s = db.to_str().unwrap();
    ok(&texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("ramp_gdal.asc"),
        "--out",
        db_s,
    ]));
    // Building over an existing database: a runtime failure, the old one untouched.
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("ramp_gdal.asc"),
        "--out",
        db_s,
    ]);
    exits(&o, 1);
    // A missing DEM names the file.
    let missing = dir.path().join("nope.tif");
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        missing.to_str().unwrap(),
        "--out",
        dir.path().join("b.db").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.tif"));
    assert!(!dir.path().join("b.db").exists(), "no partial database");
    // An eye outside the grid and a pitch past the vertical are usage errors.
    let out = dir.path().join("v.png");
    for bad in [&["--eye", "1e9,1e9"][..], &["--pitch", "-95"][..]] {
        let mut args = vec!["terrain", "render", db_s, "-o", out.to_str().unwrap()];
        args.extend_from_slice(bad);
        let o = texmap(&args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{bad:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    assert!(!out.exists());
}

#[test]
fn photos_in_another_system_are_reprojected_or_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    // A UTM 18N photo over a grid in degrees: reprojected, the build succeeds.
    let db = dir.path().join("geo.db");
    ok(&texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("dem_geo.tif"),
        "--photo",
        &data("photo_utm18.tif"),
        "--out",
        db.to_str().unwrap(),
        "-q",
    ]));
    let info = texmap(&["terrain", "info", db.to_str().unwrap()]);
    ok(&info);
    let j: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(j["texture"]["placed_by"], "georeference", "{j}");
    // A photo in UTM 54N (Japan) over the UTM 19N grid (New Hampshire): no overlap once both are
    // on the globe; a runtime failure naming the photo, and no database left behind.
    let bad = dir.path().join("far.db");
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("hillshade_dem_utm.tif"),
        "--photo",
        &data("photo_rgb.tif"),
        "--out",
        bad.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    for part in [
        "photo_rgb.tif",
        "does not overlap",
        "EPSG:32654, reprojected",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
    assert!(!bad.exists(), "no partial database");
}

#[test]
fn several_dems_join_into_one_database_or_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("m.db");
    let pieces = ["mosaic_nw.tif", "mosaic_ne.tif", "mosaic_s.tif"].map(data);
    let mut args = vec!["terrain", "build", "--dem"];
    args.extend(pieces.iter().map(String::as_str));
    args.extend(["--out", db.to_str().unwrap()]);
    let o = texmap(&args);
    ok(&o);
    // The overlaps are reported, not replaced silently.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("mosaic_s.tif overlaps the grids before it on 70 samples"),
        "{err}"
    );
    let info = texmap(&["terrain", "info", db.to_str().unwrap()]);
    ok(&info);
    let j: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    // GDAL's mosaic of the same pieces is 109 x 69 (tests/data/mosaic.sh).
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(109), Some(69))
    );
    // A grid in another system: exit 1, named, no database.
    let bad = dir.path().join("bad.db");
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &pieces[0],
        &data("hillshade_dem_utm.tif"),
        "--out",
        bad.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("hillshade_dem_utm.tif") && err.contains("gdalwarp -t_srs EPSG:4326"));
    assert!(!bad.exists());
}

#[test]
fn the_eye_can_be_given_in_longitude_and_latitude() {
    let dir = tempfile::tempdir().unwrap();
    let db = relief_db(dir.path(), "utm.db");
    let out = dir.path().join("v.png");
    let render = |eye: &str| {
        texmap(&[
            "terrain",
            "render",
            db.to_str().unwrap(),
            eye,
            "--stats",
            "-o",
            out.to_str().unwrap(),
        ])
    };
    // Mount Washington's summit on the UTM 19N grid: where PROJ puts it (gdaltransform,
    // terrain/tests/data/geodesy.sh: 316174.999893 E, 4904508.425352 N).
    let o = render("--eye-lonlat=-71.3033,44.2706");
    ok(&o);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let e = [j["eye"][0].as_f64().unwrap(), j["eye"][1].as_f64().unwrap()];
    assert!(
        (e[0] - 316174.999893).abs() < 1e-3 && (e[1] - 4904508.425352).abs() < 1e-3,
        "{e:?}"
    );
    // Off the grid, or not a longitude and latitude: usage errors.
    for bad in ["--eye-lonlat=-171.3,44.27", "--eye-lonlat=-71.3,94"] {
        assert_eq!(render(bad).status.code(), Some(2), "{bad}");
    }
}

/// A small database from the GDAL test grid and photo.
/// A database without a photo (shaded relief) from the GDAL-warped UTM crop of the SRTM tile.
fn relief_db(dir: &Path, name: &str) -> PathBuf {
    let db = dir.join(name);
    ok(&texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("hillshade_dem_utm.tif"),
        "--out",
        db.to_str().unwrap(),
        "-q",
    ]));
    db
}

fn small_db(dir: &Path) -> PathBuf {
    let db = dir.join("area.db");
    ok(&texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("ramp_i16_lzw.tif"),
        "--photo",
        &data("photo_rgb.tif"),
        "--max-error",
        "0.5",
        "--out",
        db.to_str().unwrap(),
    ]));
    db
}

#[test]
fn fly_writes_frames_and_names_a_bad_path_line() {
    let dir = tempfile::tempdir().unwrap();
    let db = small_db(dir.path());
    let db_s = db.to_str().unwrap();
    // An orbit to numbered PNG frames, one per view.
    let pattern = dir.path().join("frames/%04d.png");
    std::fs::create_dir_all(dir.path().join("frames")).unwrap();
    ok(&texmap(&[
        "terrain",
        "fly",
        db_s,
        "--orbit",
        "3,0.3,0.2,-30",
        "--size",
        "64x48",
        "--sampler",
        "span3",
        "-o",
        pattern.to_str().unwrap(),
    ]));
    for f in 0..3 {
        let p = dir.path().join(format!("frames/{f:04}.png"));
        let img = image::open(&p).expect("a frame").to_rgba8();
        assert_eq!(img.dimensions(), (64, 48));
    }
    // Per-frame statistics along the flight: one JSON line per frame with the GST residency.
    let stats = dir.path().join("fly.jsonl");
    ok(&texmap(&[
        "terrain",
        "fly",
        db_s,
        "--orbit",
        "3",
        "--size",
        "32x24",
        "--stats",
        stats.to_str().unwrap(),
        "-o",
        dir.path().join("s.apng").to_str().unwrap(),
    ]));
    let text = std::fs::read_to_string(&stats).unwrap();
    assert_eq!(text.lines().count(), 3);
    for l in text.lines() {
        let v: serde_json::Value = serde_json::from_str(l).unwrap();
        assert!(v["stats"]["chunks_drawn"].as_u64().unwrap() >= 1, "{v}");
        assert!(v["residency"]["needed"].as_u64().is_some(), "{v}");
    }
    // The same orbit as an animated PNG, and with the ray-traced reference.
    let apng = dir.path().join("orbit.apng");
    ok(&texmap(&[
        "terrain",
        "fly",
        db_s,
        "--orbit",
        "2",
        "--size",
        "48x36",
        "--sampler",
        "reference",
        "--samples",
        "2",
        "-o",
        apng.to_str().unwrap(),
    ]));
    assert!(std::fs::metadata(&apng).unwrap().len() > 100);
    // A path file whose second data line has four fields: the error names file and line.
    let path = dir.path().join("path.csv");
    std::fs::write(&path, "x,y,altitude,heading,pitch\n1,2,3,4,5\n1,2,3,4\n").unwrap();
    let o = texmap(&[
        "terrain",
        "fly",
        db_s,
        "--path",
        path.to_str().unwrap(),
        "-o",
        dir.path().join("p.apng").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("path.csv:3:"), "{err}");
    assert!(!dir.path().join("p.apng").exists(), "no partial movie");
    // Neither --path nor --orbit: a usage error.
    let o = texmap(&["terrain", "fly", db_s, "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn compare_writes_the_study_with_no_bank_conflicts() {
    let dir = tempfile::tempdir().unwrap();
    let db = small_db(dir.path());
    let out = dir.path().join("study");
    let o = texmap(&[
        "terrain",
        "compare",
        db.to_str().unwrap(),
        "--size",
        "48x36",
        "--samples",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    ok(&o);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    // The built-in path (26 views) times the seven samplers, plus the header.
    assert_eq!(csv.lines().count(), 1 + 26 * 7);
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(v["claims"]["conflicts_span3"], 0);
    assert!(v["claims"]["spans_span3"].as_u64().unwrap() > 0);
    for chart in ["error_vs_pitch.svg", "error_vs_altitude.svg"] {
        let svg = std::fs::read_to_string(out.join(chart)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("trilinear"));
    }
    assert!(String::from_utf8_lossy(&o.stdout).contains("| span3 |"));
}

#[test]
fn render_draws_models_and_trees_and_names_bad_ones() {
    let dir = tempfile::tempdir().unwrap();
    let db = small_db(dir.path());
    let db_s = db.to_str().unwrap();
    let model = data("models/box.obj");
    let out = dir.path().join("m.png");
    let out_s = out.to_str().unwrap();
    // The grid: 37 x 29 samples 30 m apart from (500015, 3900855); the default eye looks north
    // from the centre (500555, 3900435).
    let render = |extra: &[&str]| {
        let mut args = vec![
            "terrain", "render", db_s, "--size", "160x120", "--stats", "-o", out_s,
        ];
        args.extend_from_slice(extra);
        texmap(&args)
    };
    let spec = format!("{model}@500555,3900735,30,40");
    let o = render(&[
        "--model",
        &spec,
        "--tree",
        "500455,3900655,25",
        "--trees",
        "20",
    ]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["models"]["models_drawn"], 1, "{v}");
    assert_eq!(v["models"]["model_triangles"], 12, "{v}");
    let trees = v["models"]["trees_drawn"].as_u64().unwrap()
        + v["models"]["trees_culled"].as_u64().unwrap();
    assert_eq!(trees, 21, "{v}");
    assert!(v["models"]["trees_drawn"].as_u64().unwrap() >= 1, "{v}");
    assert!(out.exists());
    std::fs::remove_file(&out).unwrap();
    // A missing model file names it (runtime error); a placement off the grid, a zero scale and
    // a malformed spec are usage errors; no image is written.
    let missing = format!("{}@500555,3900735", dir.path().join("nope.obj").display());
    let o = render(&["--model", &missing]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.obj"));
    for (flag, bad, word) in [
        ("--model", format!("{model}@1,2"), "outside"),
        ("--model", format!("{model}@500555,3900735,0,0"), "scale"),
        ("--model", model.clone(), "FILE@X,Y"),
        ("--tree", "500555,3900735,-3".to_string(), "height"),
    ] {
        let o = render(&[flag, &bad]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {bad}: {err}");
        assert!(err.contains(word), "{flag} {bad}: {err}");
    }
    assert!(!out.exists());
}

/// A database built without a photo exports the shaded relief the views draw: the .glb embeds
/// exactly `relief_image` of the grid, and `--quiet` leaves stderr empty.
#[test]
fn export_without_a_photo_embeds_the_shaded_relief() {
    let dir = tempfile::tempdir().unwrap();
    let db = relief_db(dir.path(), "relief.db");
    let glb = dir.path().join("relief.glb");
    let o = texmap(&[
        "terrain",
        "export",
        db.to_str().unwrap(),
        "--max-error",
        "2",
        "-o",
        glb.to_str().unwrap(),
        "-q",
    ]);
    ok(&o);
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let (_, _, images) = gltf::import(&glb).expect("a valid glTF");
    assert_eq!(images.len(), 1);
    let grid =
        texmap_terrain::dem::read_dem(data("hillshade_dem_utm.tif"), &Default::default()).unwrap();
    let want = texmap_terrain::relief::relief_image(&grid, 4096);
    let img = &images[0];
    assert_eq!((img.width, img.height), want.dimensions());
    assert_eq!(img.format, gltf::image::Format::R8G8B8A8);
    assert!(img.pixels == want.as_raw()[..], "embedded texture differs");
}

/// The exports open in any glTF viewer: the Khronos glTF-Validator (the reference checker every
/// viewer is tested with; `.ci/run` installs it under target/gltf-validator) reports no error and
/// no warning for a textured export (photo placed by georeference, with a no-data hole), a
/// shaded-relief one and a 3D Tiles tile. Without node or the validator the test says SKIPPED.
#[test]
fn glb_exports_pass_the_khronos_gltf_validator() {
    let dir = tempfile::tempdir().unwrap();
    let photo_db = small_db(dir.path());
    let relief_db = relief_db(dir.path(), "relief.db");
    let mut files = Vec::new();
    for (db, name) in [(&photo_db, "photo.glb"), (&relief_db, "relief.glb")] {
        let out = dir.path().join(name);
        ok(&texmap(&[
            "terrain",
            "export",
            db.to_str().unwrap(),
            "--max-error",
            "1",
            "-o",
            out.to_str().unwrap(),
            "-q",
        ]));
        files.push(out);
    }
    // And the finest tile of a 3D Tiles export (UTM grid: placed through the inverse projection).
    let tiles = dir.path().join("tiles");
    ok(&texmap(&[
        "terrain",
        "export",
        relief_db.to_str().unwrap(),
        "--3d-tiles",
        "-o",
        tiles.to_str().unwrap(),
        "-q",
    ]));
    files.push(tiles.join("tiles/0/0_0.glb"));
    let Some(lines) = common::gltf_validator_reports(&files) else {
        return;
    };
    assert_eq!(lines.len(), 3);
    for r in &lines {
        assert_eq!(r["errors"], 0, "{r}");
        assert_eq!(r["warnings"], 0, "{r}");
        eprintln!("glTF-Validator: {r}");
    }
}

/// `terrain export --3d-tiles`: a tileset from a UTM grid, refused over an existing directory
/// and for a grid with no place on the ellipsoid (exit 1, the reason named, nothing written).
#[test]
fn export_3d_tiles_and_its_refusals() {
    let dir = tempfile::tempdir().unwrap();
    let utm = relief_db(dir.path(), "utm.db");
    let tiles = dir.path().join("tiles");
    let t = tiles.to_str().unwrap();
    ok(&texmap(&[
        "terrain",
        "export",
        utm.to_str().unwrap(),
        "--3d-tiles",
        "-o",
        t,
        "-q",
    ]));
    let ts: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tiles.join("tileset.json")).unwrap())
            .unwrap();
    assert_eq!(ts["asset"]["version"], "1.1");
    assert_eq!(ts["root"]["content"]["uri"], "tiles/0/0_0.glb");
    assert!(tiles.join("tiles/0/0_0.glb").exists());
    let heights = ts["asset"]["extras"]["heights"].as_str().unwrap();
    assert!(heights.contains("taken as ellipsoidal"), "{heights}");
    // With PROJ's EGM96 (a GDAL cut of it): the root tile's box sits lower by the undulation
    // there (about 27.5 m, tests/data/geoid_proj.txt), along the local vertical.
    let geoid_tiles = dir.path().join("geoid_tiles");
    ok(&texmap(&[
        "terrain",
        "export",
        utm.to_str().unwrap(),
        "--3d-tiles",
        "--geoid",
        &data("egm96_cut.gtx"),
        "-o",
        geoid_tiles.to_str().unwrap(),
        "-q",
    ]));
    let gs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(geoid_tiles.join("tileset.json")).unwrap())
            .unwrap();
    let heights = gs["asset"]["extras"]["heights"].as_str().unwrap();
    assert!(heights.contains("egm96_cut.gtx"), "{heights}");
    let centre = |v: &serde_json::Value| -> [f64; 3] {
        let t = &v["root"]["transform"];
        let b = &v["root"]["boundingVolume"]["box"];
        [0, 1, 2].map(|k| t[12 + k].as_f64().unwrap() + b[k].as_f64().unwrap())
    };
    let (a, g) = (centre(&ts), centre(&gs));
    let r = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let drop = r(a) - r(g);
    assert!(
        (26.0..29.0).contains(&drop),
        "the box centre moved {drop} m inwards"
    );
    // --geoid without --3d-tiles is a usage error.
    let o = texmap(&[
        "terrain",
        "export",
        utm.to_str().unwrap(),
        "--geoid",
        &data("egm96_cut.gtx"),
        "-o",
        dir.path().join("x.glb").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let o = texmap(&[
        "terrain",
        "export",
        utm.to_str().unwrap(),
        "--3d-tiles",
        "-o",
        t,
    ]);
    assert_eq!(o.status.code(), Some(1));
    // An ESRI grid without a .prj has a local georeference: no place on the globe.
    let local = dir.path().join("local.db");
    ok(&texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("ramp_gdal.asc"),
        "--out",
        local.to_str().unwrap(),
        "-q",
    ]));
    let out = dir.path().join("local_tiles");
    let o = texmap(&[
        "terrain",
        "export",
        local.to_str().unwrap(),
        "--3d-tiles",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("3D Tiles need"), "{err}");
    assert!(!out.exists());
}

/// `terrain export --quantized-mesh`: layer.json and the tile pyramid from a UTM grid; the
/// finest level by --max-level; --gzip tiles; --geoid without a globe export, --quantized-mesh
/// with --3d-tiles and --max-level or --gzip without --quantized-mesh are usage errors (exit 2).
#[test]
fn export_quantized_mesh_and_its_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let utm = relief_db(dir.path(), "utm.db");
    let out = dir.path().join("qm");
    ok(&texmap(&[
        "terrain",
        "export",
        utm.to_str().unwrap(),
        "--quantized-mesh",
        "--max-level",
        "9",
        "--geoid",
        &data("egm96_cut.gtx"),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]));
    let layer: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("layer.json")).unwrap()).unwrap();
    assert_eq!(layer["maxzoom"], 9);
    assert_eq!(layer["available"].as_array().unwrap().len(), 10);
    assert!(out.join("0/0/0.terrain").exists() && out.join("0/1/0.terrain").exists());
    let last = &layer["available"][9][0];
    let x = last["startX"].as_u64().unwrap();
    let y = last["startY"].as_u64().unwrap();
    assert!(out.join(format!("9/{x}/{y}.terrain")).exists());
    // --gzip: the same tile names, each a gzip member (the library test inflates them).
    let gz = dir.path().join("qmgz");
    ok(&texmap(&[
        "terrain",
        "export",
        utm.to_str().unwrap(),
        "--quantized-mesh",
        "--max-level",
        "9",
        "--gzip",
        "-o",
        gz.to_str().unwrap(),
        "-q",
    ]));
    let tile = std::fs::read(gz.join(format!("9/{x}/{y}.terrain"))).unwrap();
    assert_eq!(tile[..2], [0x1f, 0x8b]);
    for bad in [
        vec!["--quantized-mesh", "--3d-tiles"],
        vec!["--max-level", "9"],
        vec!["--gzip"],
    ] {
        let mut args = vec!["terrain", "export", utm.to_str().unwrap()];
        args.extend(bad.iter().copied());
        let o = dir.path().join("x");
        args.extend(["-o", o.to_str().unwrap()]);
        assert_eq!(texmap(&args).status.code(), Some(2), "{bad:?}");
    }
}

/// `--contours`: a database built without a photo gets the shaded relief with contour lines as
/// its texture (brown texels where the heights cross the 50 m levels, as the library's rule
/// gives them), the flight view draws it, and a bad interval or width is a usage error.
#[test]
fn contours_drape_the_relief_and_bad_intervals_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lined.db");
    let build = |extra: &[&str], out: &Path| {
        let mut args = vec![
            "terrain",
            "build",
            "--dem",
            data_hillshade(),
            "--max-error",
            "2",
            "--chunk",
            "33",
            "--texture-levels",
            "2",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ];
        args.extend(extra);
        texmap(&args)
    };
    ok(&build(&["--contours", "50"], &db));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(db.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["texture"]["placed_by"], "stretched");
    let finest = manifest["texture"]["levels"].as_u64().unwrap() - 1;
    let tile = image::open(db.join(format!("tiles/{finest}/0_0.png")))
        .unwrap()
        .to_rgba8();
    let brown = tile
        .pixels()
        .filter(|p| p.0[..3] == texmap_terrain::relief::CONTOUR_COLOUR)
        .count();
    assert!(brown > 50, "{brown} texels on a line");
    let png = dir.path().join("view.png");
    ok(&texmap(&[
        "terrain",
        "render",
        db.to_str().unwrap(),
        "--size",
        "320x240",
        "-o",
        png.to_str().unwrap(),
        "-q",
    ]));
    assert!(png.exists());
    for bad in [["--contours", "0"], ["--contours", "-5"]] {
        let o = build(&bad, &dir.path().join("bad.db"));
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
    }
    let o = build(
        &["--contours", "50", "--contour-width", "100"],
        &dir.path().join("bad.db"),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(!dir.path().join("bad.db").exists());
}

/// `--overlay`: GeoJSON written by ogr2ogr drawn into the relief texture in the style given
/// (the road in its own red), listed by `terrain info`; a damaged file is a runtime error naming
/// the feature, a bad style a usage error, and neither leaves a database.
#[test]
fn overlays_drape_geojson_and_bad_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("roads.db");
    let build = |extra: &[&str], out: &Path| {
        let mut args = vec![
            "terrain",
            "build",
            "--dem",
            data_hillshade(),
            "--chunk",
            "33",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ];
        args.extend(extra);
        texmap(&args)
    };
    let geojson = data("vector_wgs84.geojson");
    ok(&build(
        &[
            "--overlay",
            &geojson,
            "--overlay-style",
            "fill=#0000ff,fill-opacity=1,stroke-width=3",
        ],
        &db,
    ));
    let o = texmap(&["terrain", "info", db.to_str().unwrap()]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let layer = &v["texture"]["overlays"][0];
    assert_eq!(
        (layer["features"].as_u64(), layer["drawn"].as_u64()),
        (Some(7), Some(6))
    );
    let finest = v["texture"]["levels"].as_u64().unwrap() - 1;
    let tile = image::open(db.join(format!("tiles/{finest}/0_0.png")))
        .unwrap()
        .to_rgba8();
    let count = |c: [u8; 3]| tile.pixels().filter(|p| p.0[..3] == c).count();
    assert!(count([0, 0, 255]) > 1000 && count([255, 0, 0]) > 50);

    let broken = dir.path().join("broken.geojson");
    let text = std::fs::read_to_string(&geojson).unwrap();
    std::fs::write(&broken, text.replacen("\"Polygon\"", "\"Polygan\"", 1)).unwrap();
    let bad = dir.path().join("bad.db");
    let o = build(&["--overlay", broken.to_str().unwrap()], &bad);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("features[0].geometry.type") && err.contains("Polygan"),
        "{err}"
    );
    let o = build(
        &["--overlay", &geojson, "--overlay-style", "stroke=red"],
        &bad,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(!bad.exists());
}

/// `fly --path flight.gpx`: a glider's flight (GPX written by GDAL) replayed at 20x and 5 frames a
/// second over the relief of its grid: one PNG per frame on the track's clock, those past the
/// grid's edge left out with a note; a track option on a CSV path is a usage error.
#[test]
fn fly_replays_a_gpx_flight() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("wash.db");
    ok(&texmap(&[
        "terrain",
        "build",
        "--dem",
        data_hillshade(),
        "--contours",
        "100",
        "--chunk",
        "33",
        "--out",
        db.to_str().unwrap(),
        "-q",
    ]));
    std::fs::create_dir_all(dir.path().join("f")).unwrap();
    let pattern = dir.path().join("f/%04d.png");
    let gpx = data("track_ogr.gpx");
    let o = texmap(&[
        "terrain",
        "fly",
        db.to_str().unwrap(),
        "--path",
        &gpx,
        "--speedup",
        "20",
        "--fps",
        "5",
        "--above",
        "30",
        "--size",
        "96x64",
        "-o",
        pattern.to_str().unwrap(),
    ]);
    ok(&o);
    // The library's views of the same flight: 70 frames on the clock, some off the grid.
    let grid = texmap_terrain::dem::read_dem(data_hillshade(), &Default::default()).unwrap();
    let track = texmap_terrain::track::read_track(Path::new(&gpx)).unwrap();
    let v = texmap_terrain::track::track_views(
        &track,
        &grid,
        &texmap_terrain::view::FlightCamera::over(&grid),
        &texmap_terrain::track::TrackOptions {
            speedup: Some(20.0),
            fps: 5.0,
            ..Default::default()
        },
    )
    .unwrap();
    let frames = std::fs::read_dir(dir.path().join("f")).unwrap().count();
    assert_eq!(frames, v.views.len());
    assert_eq!(v.views.len() + v.outside, 70);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("{} of 70 frames left out", v.outside)),
        "{err}"
    );
    let csv = dir.path().join("p.csv");
    std::fs::write(&csv, "x,y,altitude,heading,pitch\n").unwrap();
    let o = texmap(&[
        "terrain",
        "fly",
        db.to_str().unwrap(),
        "--path",
        csv.to_str().unwrap(),
        "--speedup",
        "2",
        "-o",
        pattern.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
}

fn data_hillshade() -> &'static str {
    static PATH: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    PATH.get_or_init(|| data("hillshade_dem_utm.tif"))
}

/// `terrain viewshed` on a DEM and on a database: a GeoTIFF mask equal to gdal_viewshed's
/// (terrain/tests/data/viewshed/gen.sh), the share of cells seen on stderr, a picture; bad
/// observers and options are usage errors (exit 2) that leave no file behind.
#[test]
fn viewshed_writes_gdals_mask_and_refuses_bad_observers() {
    use texmap_terrain::dem::read_dem;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("vs.tif");
    let png = dir.path().join("vs.png");
    let dem = data("viewshed/dem_utm.tif");
    let o = texmap(&[
        "terrain",
        "viewshed",
        &dem,
        "--observer",
        "316135,4904505",
        "--method",
        "gdal",
        "-o",
        out.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
    ]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("% of the 30720 cells visible"), "{err}");
    let ours = read_dem(&out, &Default::default()).unwrap();
    let gdal = read_dem(data("viewshed/summit.tif"), &Default::default()).unwrap();
    assert_eq!(
        ours.heights(),
        gdal.heights(),
        "the mask gdal_viewshed wrote"
    );
    assert_eq!(ours.georef(), gdal.georef());
    let img = image::open(&png).unwrap();
    assert_eq!(
        (img.width(), img.height()),
        (960, 800),
        "192 x 160 cells, 5 pixels each"
    );

    // A database: the same viewshed as its source grid, the observer in degrees.
    let db = relief_db(dir.path(), "vs.db");
    let (from_db, from_tif) = (dir.path().join("db.tif"), dir.path().join("tif.tif"));
    for (input, o) in [
        (db.to_str().unwrap().to_string(), &from_db),
        (data_hillshade().to_string(), &from_tif),
    ] {
        ok(&texmap(&[
            "terrain",
            "viewshed",
            &input,
            "--observer-lonlat=-71.3033,44.2706",
            "--max-distance",
            "2000",
            "--mode",
            "ground",
            "-q",
            "-o",
            o.to_str().unwrap(),
        ]));
    }
    assert_eq!(
        std::fs::read(&from_db).unwrap(),
        std::fs::read(&from_tif).unwrap()
    );
    let needed = read_dem(&from_db, &Default::default()).unwrap();
    assert!(needed.nodata_count() > 0, "beyond 2 km: no-data");
    assert!(needed.heights().iter().all(|h| h.is_nan() || *h >= 0.0));

    // Usage errors: exit 2, the problem named, no file written.
    let bad = dir.path().join("bad.tif");
    let run = |args: &[&str]| {
        let mut v = vec!["terrain", "viewshed"];
        v.extend_from_slice(args);
        v.extend_from_slice(&["-o", bad.to_str().unwrap()]);
        texmap(&v)
    };
    let ramp = data("ramp_i16_lzw.tif");
    for (args, says) in [
        (
            vec![dem.as_str(), "--observer", "1e9,1e9"],
            "outside the 192 x 160 grid",
        ),
        (vec![dem.as_str(), "--observer-cell", "192,0"], "outside"),
        (
            vec![dem.as_str(), "--observer", "316135"],
            "expected two numbers",
        ),
        (
            vec![dem.as_str(), "--observer", "a,b"],
            "expected two numbers",
        ),
        (vec![ramp.as_str(), "--observer-cell", "5,3"], "no-data"),
        (
            vec![dem.as_str(), "--observer-cell", "1,1", "--method", "fast"],
            "--method fast",
        ),
        (
            vec![
                dem.as_str(),
                "--observer-cell",
                "1,1",
                "--max-distance",
                "0",
            ],
            "--max-distance",
        ),
        (vec![dem.as_str()], "--observer"),
    ] {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
    // An output that is not a GeoTIFF, and a missing input (a runtime failure: exit 1).
    let o = texmap(&[
        "terrain",
        "viewshed",
        &dem,
        "--observer-cell",
        "1,1",
        "-o",
        "x.png",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let o = run(&[
        dir.path().join("nope.tif").to_str().unwrap(),
        "--observer-cell",
        "1,1",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.tif"));
    assert!(!bad.exists(), "no partial output");
    assert_no_partial_files(dir.path());
}

#[test]
fn lidar_clouds_grid_to_geotiffs_and_build_databases() {
    use texmap_terrain::dem::lidar::{LidarMethod, LidarOptions, read_lidar};
    use texmap_terrain::dem::{ReadOptions, read_dem};
    let dir = tempfile::tempdir().unwrap();
    let laz = data("lidar/lidar_12.laz");
    // `terrain grid` writes the grid the library makes, with its georeference.
    let tif = dir.path().join("dem.tif");
    let tif_s = tif.to_str().unwrap();
    let o = texmap(&[
        "terrain",
        "grid",
        &laz,
        "-o",
        tif_s,
        "--lidar-cell",
        "10",
        "--lidar-method",
        "idw",
    ]);
    ok(&o);
    let back = read_dem(&tif, &ReadOptions::default()).unwrap();
    let opts = LidarOptions {
        cell: Some(10.0),
        method: LidarMethod::Idw,
        ..LidarOptions::default()
    };
    let (direct, _, _) = read_lidar(&[PathBuf::from(&laz)], &opts).unwrap();
    let (a, b) = (back.georef(), direct.georef());
    assert_eq!((a.crs, a.epsg, a.dx, a.dy), (b.crs, b.epsg, b.dx, b.dy));
    assert!((a.origin_x - b.origin_x).abs() < 1e-6 && (a.origin_y - b.origin_y).abs() < 1e-6);
    let bits =
        |g: &texmap_terrain::dem::Grid| g.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
    assert_eq!(
        bits(&back),
        bits(&direct),
        "the GeoTIFF holds the grid's f32 heights"
    );
    assert_eq!(back.nodata_count(), 6);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("1803 gridded: ground (class 2)"), "{err}");
    assert!(
        err.contains("30 x 24 cells of 10 m, the idw of the points"),
        "{err}"
    );

    // A density grid for quality control: the points' counts, 0 where none reaches (numpy's
    // counts by PDAL's rule, lidar/stats_numpy.py); not a terrain, so `build` refuses it.
    let density = dir.path().join("density.tif");
    let o = texmap(&[
        "terrain",
        "grid",
        &laz,
        "-o",
        density.to_str().unwrap(),
        "--lidar-cell",
        "10",
        "--lidar-method",
        "count",
    ]);
    ok(&o);
    let counts = read_dem(&density, &ReadOptions::default()).unwrap();
    let numpy: Vec<f32> = std::fs::read_to_string(data("lidar/lidar_numpy_stats.txt"))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().nth(2).unwrap().parse().unwrap())
        .collect();
    assert_eq!(counts.heights(), &numpy[..]);
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &laz,
        "--lidar-method",
        "count",
        "--out",
        dir.path().join("count.db").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("texmap terrain grid"), "{err}");
    assert!(!dir.path().join("count.db").exists());

    // `terrain build --dem x.laz`: a database of the gridded cloud, holes filled.
    let db = dir.path().join("area.db");
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("lidar/lidar_14.laz"),
        "--lidar-fill",
        "2",
        "--out",
        db.to_str().unwrap(),
    ]);
    ok(&o);
    let o = texmap(&["terrain", "info", db.to_str().unwrap()]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(30), Some(24))
    );
    assert_eq!(v["nodata"], 0);
    assert_eq!(v["georef"]["epsg"], 32619);

    // Bad options are usage errors (exit 2); a damaged file is a runtime error naming it (1).
    let las = data("lidar/lidar_12.las");
    let png = dir.path().join("x.png");
    for bad in [
        vec!["terrain", "grid", &las, "-o", png.to_str().unwrap()],
        vec![
            "terrain",
            "grid",
            &las,
            "-o",
            tif_s,
            "--lidar-method",
            "median",
        ],
        vec!["terrain", "grid", &las, "-o", tif_s, "--lidar-cell", "0"],
        vec![
            "terrain",
            "grid",
            &las,
            "-o",
            tif_s,
            "--lidar-classes",
            "2,x",
        ],
        vec!["terrain", "grid", &las, "-o", tif_s, "--lidar-fill", "1000"],
        vec!["terrain", "grid", &las, "-o", tif_s, "--lidar-radius", "-1"],
        vec!["terrain", "grid", "-o", tif_s],
    ] {
        let o = texmap(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
    }
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("hillshade_dem_utm.tif"),
        "--lidar-cell",
        "2",
        "--out",
        dir.path().join("x.db").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let cut = dir.path().join("cut.laz");
    let bytes = std::fs::read(&laz).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let o = texmap(&["terrain", "grid", cut.to_str().unwrap(), "-o", tif_s]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cut.laz"));
}

#[test]
fn a_16_bit_photo_is_stretched_by_percentiles_and_the_ranges_carry_to_the_next_build() {
    let dir = tempfile::tempdir().unwrap();
    let build = |name: &str, extra: &[&str]| {
        let db = dir.path().join(name);
        let (dem, photo) = (data("sat_dem.tif"), data("sat_u16.tif"));
        let mut args = vec!["terrain", "build", "--dem", &dem, "--photo", &photo];
        args.extend_from_slice(extra);
        let db_s = db.to_str().unwrap().to_string();
        args.extend_from_slice(&["--out", &db_s]);
        let o = texmap(&args);
        (o, db)
    };
    // 2-98 % with a gamma: the ranges are numpy's percentiles (tests/data/stretch.py), printed
    // as the --stretch that reproduces them, and kept in the manifest.
    let (o, a) = build("a.db", &["--stretch", "percent:2,98", "--gamma", "1.5"]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    let again = "--stretch range:582,1162,788,1572,734,2036";
    assert!(err.contains(again), "{err}");
    let info = texmap(&["terrain", "info", a.to_str().unwrap()]);
    ok(&info);
    let j: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let s = &j["texture"]["stretch"];
    assert_eq!(s["rule"], "percent:2,98", "{j}");
    assert_eq!(s["gamma"], 1.5, "{j}");
    assert_eq!(
        s["ranges"],
        serde_json::json!([[582.0, 1162.0], [788.0, 1572.0], [734.0, 2036.0]])
    );
    // The printed ranges give a neighbouring build the same texture, map for map.
    let range = again.trim_start_matches("--stretch ");
    let (o, b) = build("b.db", &["--stretch", range, "--gamma", "1.5"]);
    ok(&o);
    let maps = |db: &Path| {
        let mut files: Vec<PathBuf> = walk(&db.join("tiles"));
        files.sort();
        files
            .iter()
            .map(|f| std::fs::read(f).unwrap())
            .collect::<Vec<_>>()
    };
    let (ma, mb) = (maps(&a), maps(&b));
    assert!(!ma.is_empty());
    assert!(
        ma == mb,
        "the range build's maps differ from the percentile build's"
    );
    // Without a photo there are no colours to stretch.
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("sat_dem.tif"),
        "--stretch",
        "percent:2,98",
        "--out",
        dir.path().join("relief.db").to_str().unwrap(),
    ]);
    exits(&o, 2);
    // Bad rules and gammas are usage errors (exit 2) naming the option.
    for bad in [
        &["--stretch", "percent:98,2"][..],
        &["--stretch", "histogram"][..],
        &["--gamma", "0"][..],
    ] {
        let (o, db) = build("bad.db", bad);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {err}");
        assert!(err.contains(bad[0]), "{bad:?}: {err}");
        assert!(!db.exists());
    }
}

/// Every file under `dir`, recursively.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// `--cog` on `terrain grid` and `terrain viewshed`: Cloud-Optimized GeoTIFFs (GDAL's ghost area
/// after the header; gdalinfo's LAYOUT=COG when GDAL is installed) holding the same samples as
/// the strip files; the help says what a COG is for.
#[test]
fn grid_and_viewshed_write_cloud_optimized_geotiffs() {
    use texmap_terrain::dem::read_dem;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = |n: &str| d.join(n).to_string_lossy().into_owned();
    let laz = data("lidar/lidar_12.laz");
    let dem = data("viewshed/dem_utm.tif");
    let grid = |out: &str, cog: bool| {
        let mut a = vec!["terrain", "grid", &laz, "-o", out, "--lidar-cell", "10"];
        if cog {
            a.push("--cog");
        }
        ok(&texmap(&a));
    };
    let viewshed = |out: &str, cog: bool| {
        let mut a = vec!["terrain", "viewshed", &dem, "--observer", "316135,4904505"];
        a.extend(["--method", "gdal", "-o", out]);
        if cog {
            a.push("--cog");
        }
        ok(&texmap(&a));
    };
    grid(&path("g.tif"), false);
    grid(&path("g_cog.tif"), true);
    viewshed(&path("v.tif"), false);
    viewshed(&path("v_cog.tif"), true);
    let gdal = std::process::Command::new("gdalinfo")
        .arg("--version")
        .output()
        .is_ok();
    if !gdal {
        eprintln!("SKIPPED gdalinfo LAYOUT=COG check: gdalinfo is not installed");
    }
    for (strips, cog) in [("g.tif", "g_cog.tif"), ("v.tif", "v_cog.tif")] {
        let (a, b) = (d.join(strips), d.join(cog));
        let (a, b) = (
            read_dem(&a, &Default::default()).unwrap(),
            read_dem(&b, &Default::default()).unwrap(),
        );
        let bits = |g: &texmap_terrain::dem::Grid| {
            g.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>()
        };
        assert!(bits(&a) == bits(&b), "{cog}: samples differ from {strips}");
        assert_eq!(a.georef(), b.georef(), "{cog}");
        let bytes = std::fs::read(d.join(cog)).unwrap();
        assert!(
            bytes[8..].starts_with(b"GDAL_STRUCTURAL_METADATA_SIZE="),
            "{cog}"
        );
        if gdal {
            let o = std::process::Command::new("gdalinfo")
                .arg(d.join(cog))
                .output()
                .unwrap();
            let text = String::from_utf8_lossy(&o.stdout);
            assert!(
                text.contains("LAYOUT=COG") && text.contains("Block=512x512"),
                "{text}"
            );
        }
    }
    for cmd in ["grid", "viewshed"] {
        let o = texmap(&["terrain", cmd, "--help"]);
        let help = String::from_utf8_lossy(&o.stdout);
        assert!(
            help.contains("--cog") && help.contains("Cloud-Optimized"),
            "{help}"
        );
    }
}

/// `terrain dem slope`: a float32 GeoTIFF with the input's georeference and gdaldem's no-data
/// (checked by our reader, and by gdalinfo when it is installed); a bad colour-file line is a
/// runtime error (exit 1) naming the file and the line, and leaves no output file.
#[test]
fn dem_products_keep_the_georeference_and_name_a_bad_colour_line() {
    use texmap_terrain::dem::read_dem;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("slope.tif");
    let dem = data("hillshade_dem_utm.tif");
    let o = texmap(&[
        "terrain",
        "dem",
        "slope",
        &dem,
        "-o",
        out.to_str().unwrap(),
        "--compute-edges",
    ]);
    ok(&o);
    let input = read_dem(&dem, &Default::default()).unwrap();
    let slope = read_dem(&out, &Default::default()).unwrap();
    assert_eq!(slope.georef(), input.georef());
    assert_eq!(
        (slope.width(), slope.height()),
        (input.width(), input.height())
    );
    assert!(slope.heights().iter().all(|s| (0.0..90.0).contains(s)));
    match std::process::Command::new("gdalinfo")
        .args(["-json", out.to_str().unwrap()])
        .output()
    {
        Ok(g) if g.status.success() => {
            let ours: serde_json::Value = serde_json::from_slice(&g.stdout).unwrap();
            let theirs = std::process::Command::new("gdalinfo")
                .args(["-json", &dem])
                .output()
                .unwrap();
            let theirs: serde_json::Value = serde_json::from_slice(&theirs.stdout).unwrap();
            assert_eq!(ours["geoTransform"], theirs["geoTransform"]);
            assert_eq!(ours["stac"]["proj:epsg"], theirs["stac"]["proj:epsg"]);
            assert_eq!(ours["stac"]["proj:epsg"], 32619);
            assert_eq!(ours["bands"][0]["type"], "Float32");
            assert_eq!(ours["bands"][0]["noDataValue"], -9999.0);
        }
        _ => eprintln!("SKIPPED gdalinfo georeference check: gdalinfo is not installed"),
    }

    // A colour file whose third line has two channels: exit 1, file and line named, no output.
    let colors = dir.path().join("colors.txt");
    std::fs::write(&colors, "0% 0 0 0\n# a comment\n1000 10 20\n100% white\n").unwrap();
    let tint = dir.path().join("tint.tif");
    let o = texmap(&[
        "terrain",
        "dem",
        "color-relief",
        colors.to_str().unwrap(),
        &dem,
        "-o",
        tint.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("colors.txt: line 3"), "{err}");
    assert!(!tint.exists(), "no output file");
    // Usage errors: exit 2, nothing written.
    for args in [
        vec!["slope", dem.as_str(), "--alg", "Sobel"],
        vec!["hillshade", dem.as_str(), "-z", "0"],
        vec!["tri", dem.as_str(), "--alg", "Nope"],
        vec!["slope", dem.as_str(), "--scale", "-1"],
    ] {
        let mut v = vec!["terrain", "dem"];
        v.extend_from_slice(&args);
        v.extend_from_slice(&["-o", tint.to_str().unwrap()]);
        let o = texmap(&v);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    assert!(!tint.exists(), "no output file");
    assert_no_partial_files(dir.path());
}

/// `terrain dem` on a database directory reads its full-resolution grid: the slope and colour
/// relief are byte for byte those of the DEM the database was built from. A database given with
/// other DEMs is refused (exit 2) with nothing written.
#[test]
fn dem_products_of_a_database_equal_those_of_its_source_dem() {
    let dir = tempfile::tempdir().unwrap();
    let db = relief_db(dir.path(), "src.db");
    let colors = dir.path().join("colors.txt");
    std::fs::write(
        &colors,
        "0% 0 0 80\n50% 40 160 40\n100% white\nnv 0 0 0 0\n",
    )
    .unwrap();
    for mode in [
        vec!["slope"],
        vec!["color-relief", colors.to_str().unwrap()],
    ] {
        let (from_db, from_tif) = (dir.path().join("db.tif"), dir.path().join("tif.tif"));
        for (input, out) in [
            (db.to_str().unwrap().to_string(), &from_db),
            (data_hillshade().to_string(), &from_tif),
        ] {
            let mut v = vec!["terrain", "dem"];
            v.extend_from_slice(&mode);
            v.extend_from_slice(&[input.as_str(), "-q", "-o", out.to_str().unwrap()]);
            ok(&texmap(&v));
        }
        assert_eq!(
            std::fs::read(&from_db).unwrap(),
            std::fs::read(&from_tif).unwrap(),
            "{mode:?}"
        );
    }
    let out = dir.path().join("both.tif");
    let o = texmap(&[
        "terrain",
        "dem",
        "slope",
        db.to_str().unwrap(),
        data_hillshade(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("src.db: a database directory is read alone"),
        "{err}"
    );
    assert!(!out.exists());
}

/// `terrain build --relief-colors`: the resolved table is in the manifest `terrain info`
/// prints, and the relief-only database gets the tinted texture; a bad line in the file exits
/// 1 naming `colors.txt: line N`, and no database directory is left.
#[test]
fn relief_colors_tint_the_build_and_a_bad_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let colors = dir.path().join("colors.txt");
    std::fs::write(
        &colors,
        "# hypsometric\n0% 0 0 0\n100% 255 255 255\nnv red\n",
    )
    .unwrap();
    let db = dir.path().join("db");
    ok(&texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("ramp_i16_lzw.tif"),
        "--relief-colors",
        colors.to_str().unwrap(),
        "--out",
        db.to_str().unwrap(),
        "-q",
    ]));
    let o = texmap(&["terrain", "info", db.to_str().unwrap()]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let tint = &v["relief_tint"];
    let entries = tint["entries"].as_array().expect("relief_tint entries");
    assert_eq!(entries.len(), 2, "{tint}");
    assert_eq!(entries[0][0], v["height_min"].as_f64().unwrap());
    assert_eq!(entries[1][0], v["height_max"].as_f64().unwrap());
    assert_eq!(entries[1][1], serde_json::json!([255, 255, 255, 255]));
    assert_eq!(tint["nodata"], serde_json::json!([255, 0, 0, 255]));
    assert_eq!(v["texture"]["placed_by"], "stretched");
    // Without the option: no tint in the manifest.
    let plain = relief_db(dir.path(), "plain");
    let o = texmap(&["terrain", "info", plain.to_str().unwrap()]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v.get("relief_tint").is_none(), "{v}");

    std::fs::write(&colors, "0% 0 0 0\n\n50% 10 20\n100% white\n").unwrap();
    let bad = dir.path().join("bad");
    let o = texmap(&[
        "terrain",
        "build",
        "--dem",
        &data("ramp_i16_lzw.tif"),
        "--relief-colors",
        colors.to_str().unwrap(),
        "--out",
        bad.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("colors.txt: line 3"), "{err}");
    assert!(!bad.exists(), "no database directory");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("bad"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// No temporary `*partial*` file is left in `dir` (outputs are written under such a name and
/// renamed only when complete).
fn assert_no_partial_files(dir: &Path) {
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn contour_writes_gdals_lines_and_refuses_bad_levels() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.geojson");
    let out_s = out.to_str().unwrap();
    // The same lines as gdal_contour's (crates/terrain/tests/data/gdal_contour.sh).
    let o = texmap(&[
        "terrain",
        "contour",
        &data("contour_rings.asc"),
        "-i",
        "10",
        "--attr",
        "-o",
        out_s,
    ]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("10 lines"), "{err}");
    let ours: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    let gdal: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data("gdal_contour/rings_i10.geojson")).unwrap())
            .unwrap();
    let props = |v: &serde_json::Value| {
        v["features"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["properties"].clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(props(&ours), props(&gdal));
    assert_no_partial_files(dir.path());
    // A shapefile by its extension (gdal_contour's default format), .prj included for degrees.
    let shp = dir.path().join("c.shp");
    ok(&texmap(&[
        "terrain",
        "contour",
        &data("gdaldem_geo.tif"),
        "-i",
        "100",
        "--attr",
        "-o",
        shp.to_str().unwrap(),
    ]));
    for ext in ["shp", "shx", "dbf", "prj"] {
        assert!(shp.with_extension(ext).exists(), ".{ext}");
    }
    // An output format we do not write is bad usage.
    let o = texmap(&[
        "terrain",
        "contour",
        &data("gdaldem_geo.tif"),
        "-i",
        "100",
        "-o",
        dir.path().join("c.gpkg").to_str().unwrap(),
    ]);
    exits(&o, 2);

    // A bad level list is bad usage (exit 2) and writes nothing.
    let bad = dir.path().join("bad.geojson");
    for levels in ["100,abc", "", "100,inf"] {
        let o = texmap(&[
            "terrain",
            "contour",
            &data("contour_rings.asc"),
            "--levels",
            levels,
            "-o",
            bad.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--levels {levels:?}: {err}");
        assert!(err.contains("level"), "{err}");
        assert!(!bad.exists());
    }
    // No levels, two kinds of levels, a zero interval: exit 2 as well.
    for args in [
        &[][..],
        &["-i", "10", "--exp-base", "2"][..],
        &["-i", "0"][..],
    ] {
        let mut a = vec!["terrain", "contour", "-o", bad.to_str().unwrap()];
        let dem = data("contour_rings.asc");
        a.push(&dem);
        a.extend_from_slice(args);
        let o = texmap(&a);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!bad.exists());
    }

    // An unreadable DEM exits 1 and names the file.
    let junk = dir.path().join("junk.tif");
    std::fs::write(&junk, b"not a tiff").unwrap();
    let o = texmap(&[
        "terrain",
        "contour",
        junk.to_str().unwrap(),
        "-i",
        "10",
        "-o",
        bad.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("junk.tif"), "{err}");
    assert!(!bad.exists());
    assert_no_partial_files(dir.path());
}
