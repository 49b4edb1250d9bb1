//! `texmap terrain ...` end to end on DEMs GDAL wrote (crates/terrain/tests/data): what a script
//! sees — files, JSON, exit codes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn texmap(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_texmap"))
        .args(args)
        .output()
        .expect("texmap runs")
}

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

#[test]
fn build_info_maps_export_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let db: PathBuf = dir.path().join("area.db");
    let db_s = db.to_str().unwrap();
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
        db_s,
    ]));
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
    for sampler in ["trilinear", "span3"] {
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
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
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
