//! End-to-end tests of the `texmap` binary: what a script sees (stdout JSON, files, exit codes).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn texmap(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_texmap"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn info_matches_what_mdanalysis_reported() {
    // binary_expected.json was written by MDAnalysis when it made these files (md-io's tests/data).
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("binary_expected.json")).unwrap())
            .unwrap();
    for (file, fmt) in [
        ("dcd_mda.dcd", "dcd"),
        ("xtc_mda.xtc", "xtc"),
        ("trr_mda.trr", "trr"),
    ] {
        let o = texmap(&["info", data(file).to_str().unwrap()]);
        assert!(o.status.success(), "{file}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["format"], fmt);
        let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
        assert_eq!(
            keys,
            ["atoms", "box", "first_positions", "format", "frames"],
            "{file}: exactly the documented keys"
        );
        assert_eq!(v["atoms"], 12, "{file}");
        assert_eq!(v["frames"], 4, "{file}");
        let b = v["box"].as_array().unwrap();
        assert_eq!(b.len(), 6);
        assert!(
            (b[0].as_f64().unwrap() - 21.0).abs() < 1e-4,
            "{file}: {b:?}"
        );
        assert!(
            (b[5].as_f64().unwrap() - 90.0).abs() < 1e-4,
            "{file}: {b:?}"
        );
        assert_eq!(v["first_positions"].as_array().unwrap().len(), 3);
    }
    // Cross-check the first position of the DCD against the independent JSON when it lists it.
    let s = expected.to_string();
    assert!(
        s.contains("12.72"),
        "expected values mention the first atom"
    );
}

#[test]
fn info_on_a_text_format_and_no_box() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("w.xyz");
    std::fs::write(&p, "3\nwater\nO 0 0 0\nH 0.96 0 0\nH -0.24 0.93 0\n").unwrap();
    let o = texmap(&["info", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "xyz");
    assert_eq!(v["atoms"], 3);
    assert_eq!(v["frames"], 1);
    assert!(v["box"].is_null());
    // Positions are f32 in Å; JSON carries them to within f32 precision.
    let x = v["first_positions"][1][0].as_f64().unwrap();
    assert!((x - 0.96).abs() < 1e-6, "expected 0.96 ± 1e-6, got {x}");
}

#[test]
fn bad_input_gives_exit_1_and_names_the_place() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cut.xyz");
    std::fs::write(&p, "3\nwater\nO 0 0 0\nH 0.96 0\n").unwrap();
    let o = texmap(&["info", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("cut.xyz")
            && e.contains("frame 0")
            && e.contains("line ")
            && e.contains("byte "),
        "{e}"
    );

    let o = texmap(&["info", "/definitely/not/here.pdb"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no such file"));

    // A render that fails writes no partial image.
    let out = dir.path().join("img.png");
    let o = texmap(&["render", p.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(!out.exists());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

#[test]
fn bad_usage_gives_exit_2() {
    for args in [
        vec!["render"],
        vec!["render", "x.pdb", "-o", "y.png", "--size", "0x5"],
        vec!["render", "x.pdb", "-o", "y.png", "--method", "magic"],
        vec!["nonsense"],
        vec!["compare", "--out", "d"],
    ] {
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("w.xyz");
    std::fs::write(&p, "1\nx\nC 0 0 0\n").unwrap();
    let o = texmap(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        dir.path().join("a.png").to_str().unwrap(),
        "--fov",
        "180",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = texmap(&[
        "render",
        p.to_str().unwrap(),
        "-o",
        "a.png",
        "--eye",
        "1,2,3",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(texmap(&["--help"]).status.success());
}

#[test]
fn render_writes_every_frame_and_threads_do_not_change_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let pdb = data("mda_multi.pdb");
    let mut outs = Vec::new();
    for threads in ["1", "2"] {
        let pat = dir.path().join(format!("t{threads}_%03d.png"));
        let o = texmap(&[
            "render",
            pdb.to_str().unwrap(),
            "--size",
            "160x120",
            "--threads",
            threads,
            "--depth",
            "--box-outline",
            "-o",
            pat.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let files: Vec<Vec<u8>> = (0..3)
            .map(|i| std::fs::read(dir.path().join(format!("t{threads}_{i:03}.png"))).unwrap())
            .collect();
        for i in 0..3 {
            assert!(dir.path().join(format!("t{threads}_{i:03}.exr")).exists());
        }
        outs.push(files);
    }
    assert_eq!(outs[0], outs[1], "1 and 2 threads give the same PNG bytes");
    // The image is not empty: some pixel differs from the black background.
    let img = image::open(dir.path().join("t1_000.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(img.dimensions(), (160, 120));
    assert!(img.pixels().any(|p| p.0[0] > 0 || p.0[1] > 0 || p.0[2] > 0));
}

#[test]
fn every_method_renders_with_an_explicit_camera() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("one.xyz");
    std::fs::write(&p, "1\none carbon\nC 0 0 0\n").unwrap();
    for m in ["raycast", "lut", "template", "polygon", "reference"] {
        let out = dir.path().join(format!("{m}.png"));
        let o = texmap(&[
            "render",
            p.to_str().unwrap(),
            "--method",
            m,
            "--size",
            "64x64",
            "--eye",
            "0,0,10",
            "--target",
            "0,0,0",
            "--up",
            "0,1,0",
            "--fov",
            "30",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{m}: {}", stderr(&o));
        let img = image::open(&out).unwrap().to_rgba8();
        // A carbon (r = 1.77 Å in the Alvarez table) at 10 Å with k = 64/(2 tan 15°) = 119.4 px
        // covers the centre pixel but not the corners.
        assert!(img.get_pixel(32, 32).0[..3] != [0, 0, 0], "{m}: centre");
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0, 255], "{m}: corner");
    }
}

#[test]
fn compare_a_trajectory_file_writes_results_images_and_charts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let o = texmap(&[
        "compare",
        data("mda_multi.pdb").to_str().unwrap(),
        "--size",
        "200x150",
        "--runs",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let recs = v.as_array().unwrap();
    for key in [
        "scene",
        "method",
        "width",
        "height",
        "ms_per_frame",
        "psnr_db",
        "ssim",
        "depth_err_mean",
        "depth_err_max",
        "silhouette_px",
    ] {
        assert!(
            recs.iter().all(|r| r.get(key).is_some()),
            "every record has {key}"
        );
    }
    let raycast = recs
        .iter()
        .find(|r| r["method"] == "raycast" && r["reference"] == "reftrace-1spp")
        .expect("a raycast record");
    assert_eq!(raycast["scene"], "mda_multi");
    assert!(raycast["psnr_db"].is_null() || raycast["psnr_db"].as_f64().unwrap() >= 45.0);
    for f in [
        "results.csv",
        "speed_accuracy.svg",
        "speed_accuracy.png",
        "mda_multi/reference.png",
        "mda_multi/raycast.png",
        "mda_multi/lut_error.png",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
}
