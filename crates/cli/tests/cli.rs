//! End-to-end tests of the `texmap` binary: what a script sees (stdout JSON, files, exit codes).

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use common::texmap;

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
        let mut documented = vec!["atoms", "box", "first_positions", "format", "frames", "pbc"];
        if fmt == "trr" {
            // MDAnalysis wrote forces into the TRR: the per-atom properties fx fy fz.
            documented.push("properties");
            assert_eq!(
                v["properties"],
                serde_json::json!(["fx", "fy", "fz"]),
                "{file}"
            );
        }
        assert_eq!(keys, documented, "{file}: exactly the documented keys");
        // MDAnalysis's files are periodic along every edge of their box.
        if v["box"].is_null() {
            assert!(v["pbc"].is_null(), "{file}");
        } else {
            assert_eq!(v["pbc"], serde_json::json!([true, true, true]), "{file}");
        }
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

#[test]
fn compare_the_ball_and_stick_scene_draws_and_traces_its_bonds() {
    // The reference traces the 299 bonds as capped cylinders: a method that left them out would
    // lose whole bond silhouettes (hundreds of pixels) and fall far below 45 dB.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bs");
    let o = texmap(&[
        "compare",
        "--scene",
        "Molecule-BS", // scene names are case-insensitive (the README writes S1)
        "--runs",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let raycast = v
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["method"] == "raycast" && r["reference"] == "reftrace-1spp")
        .expect("a raycast record");
    assert_eq!(raycast["scene"], "molecule-bs");
    let psnr = raycast["psnr_db"].as_f64().unwrap_or(f64::INFINITY);
    assert!(
        psnr >= 45.0,
        "raycast + bonds vs reftrace: {psnr} dB, expected >= 45"
    );
    let sil = raycast["silhouette_px"].as_f64().unwrap();
    assert!(sil <= 0.5, "silhouette mismatch {sil} px, expected <= 0.5");
}

// ---------------------------------------------------------------- atom style flags

/// Render `file` at 65x65 (odd, so pixel 32 is centred on the axis) looking down -z from
/// (0, 0, 10) at the origin with a 30° horizontal field of view; extra flags appended.
fn render_axis(file: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        file.to_str().unwrap(),
        "--size",
        "65x65",
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
    ];
    args.extend_from_slice(extra);
    texmap(&args)
}

fn pixel(png: &Path, x: u32, y: u32) -> [u8; 3] {
    let img = image::open(png).unwrap().to_rgba8();
    let p = img.get_pixel(x, y).0;
    [p[0], p[1], p[2]]
}

/// A pixel as wide integers, for channel arithmetic.
fn wide(p: [u8; 3]) -> [u32; 3] {
    p.map(u32::from)
}

/// The expected 8-bit sRGB colour where a sphere of sRGB colour `srgb` faces the camera head-on
/// (normal = view direction), worked out in f64 from the project's one shading model as
/// texmap-core's shade.rs documents it: `Lighting::default_for` (ambient 0.12; key light
/// 0.85 toward eye-space (-0.4, 0.55, 1); fill 0.2 toward (0.6, -0.2, 0.8)) and
/// `Material::plastic` (specular 0.35, shininess 40), Blinn-Phong, linear RGB, then sRGB.
fn head_on(srgb: [u8; 3]) -> [f64; 3] {
    let to_linear = |c: f64| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let to_srgb = |c: f64| {
        let c = c.clamp(0.0, 1.0);
        255.0
            * if c <= 0.0031308 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            }
    };
    let norm = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / l)
    };
    // n = v = +z (eye space): n·l = l.z, n·h = h.z with h = normalize(l + v).
    let mut diffuse = 0.12;
    let mut spec = 0.0;
    for (dir, power) in [([-0.4, 0.55, 1.0], 0.85), ([0.6, -0.2, 0.8], 0.2)] {
        let l = norm(dir);
        let h = norm([l[0], l[1], l[2] + 1.0]);
        diffuse += power * l[2];
        spec += power * 0.35 * h[2].powf(40.0);
    }
    srgb.map(|c| to_srgb(to_linear(c as f64 / 255.0) * diffuse + spec))
}

fn assert_rgb_close(what: &str, expected: [f64; 3], actual: [u8; 3], tol: f64) {
    for k in 0..3 {
        assert!(
            (expected[k] - actual[k] as f64).abs() <= tol,
            "{what}: channel {k}: expected {expected:?}, actual {actual:?}, tolerance {tol}"
        );
    }
}

#[test]
fn type_color_sets_the_pixel_colour_at_the_atom() {
    let dir = tempfile::tempdir().unwrap();
    // "X1" is no element: without a rule it is drawn in the unknown-element pink.
    let xyz = dir.path().join("one.xyz");
    std::fs::write(&xyz, "1\nunknown atom\nX1 0 0 0\n").unwrap();
    let cases: [(&[&str], [u8; 3]); 5] = [
        (&[], [255, 20, 147]),
        (&["--type-color", "X1=#ff0000"], [255, 0, 0]),
        (&["--type-color", "X1=40,90,255"], [40, 90, 255]),
        // Later flags for the same NAME replace earlier ones.
        (
            &["--type-color", "X1=#ff0000", "--type-color", "X1=#00ff00"],
            [0, 255, 0],
        ),
        // The name rule beats the element rule; "x1" is another name (names are exact).
        (
            &["--type-color", "x1=#0000ff", "--type-color", "X1=#ffff00"],
            [255, 255, 0],
        ),
    ];
    for (i, (flags, rgb)) in cases.iter().enumerate() {
        for method in ["raycast", "reference"] {
            let out = dir.path().join(format!("c{i}_{method}.png"));
            let mut extra = flags.to_vec();
            extra.extend(["--method", method]);
            let o = render_axis(&xyz, &out, &extra);
            assert!(o.status.success(), "{flags:?}: {}", stderr(&o));
            // 8-bit output of an f32 pipeline: within 2 levels of the f64 value.
            assert_rgb_close(
                &format!("{flags:?} {method}"),
                head_on(*rgb),
                pixel(&out, 32, 32),
                2.0,
            );
            assert_eq!(pixel(&out, 0, 0), [0, 0, 0], "{flags:?}: background");
        }
    }
    // An element NAME (any case) colours every atom of that element, here oxygen by name "OW".
    let gro = dir.path().join("w.xyz");
    std::fs::write(&gro, "1\nwater oxygen\nOW 0 0 0\n").unwrap();
    let out = dir.path().join("ow.png");
    let o = render_axis(&gro, &out, &["--type-color", "o=#00ff00"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_rgb_close(
        "element rule",
        head_on([0, 255, 0]),
        pixel(&out, 32, 32),
        2.0,
    );
}

/// A LAMMPS dump with colour columns (atom 1 blue at x = -2, atom 2 green at x = +2), types 1, 2.
fn coloured_dump(dir: &Path) -> PathBuf {
    let p = dir.join("c.lammpstrj");
    std::fs::write(
        &p,
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n-5 5\n-5 5\n-5 5\n\
         ITEM: ATOMS id ColorB type x ColorR y z ColorG\n\
         2 0 2 2.0 0 0 0 1\n\
         1 1 1 -2.0 0 0 0 0\n",
    )
    .unwrap();
    p
}

#[test]
fn file_colour_columns_win_unless_colouring_by_element() {
    let dir = tempfile::tempdir().unwrap();
    let dump = coloured_dump(dir.path());
    // Atom centres project to x = 32.5 ± k·2/10 with k = 65 / (2 tan 15°) = 121.3 px: 24.3 px.
    let (left, right) = (32 - 24, 32 + 24);
    let flags = [
        "--type-color",
        "1=#ff0000",
        "--type-radius",
        "1=1",
        "--type-radius",
        "2=1",
    ];
    // Default (--color-by property): the file's colours win over --type-color.
    let out = dir.path().join("prop.png");
    let o = render_axis(&dump, &out, &flags);
    assert!(o.status.success(), "{}", stderr(&o));
    // Off-centre atoms are not seen head-on: check the dominant channel only.
    let l = wide(pixel(&out, left, 32));
    let r = wide(pixel(&out, right, 32));
    assert!(
        l[2] > 2 * l[0].max(l[1]),
        "atom 1 blue from the file: {l:?}"
    );
    assert!(
        r[1] > 2 * r[0].max(r[2]),
        "atom 2 green from the file: {r:?}"
    );
    // --color-by element: the file's colours are ignored, --type-color wins over the table.
    let out = dir.path().join("elem.png");
    let mut f = flags.to_vec();
    f.extend(["--color-by", "element"]);
    let o = render_axis(&dump, &out, &f);
    assert!(o.status.success(), "{}", stderr(&o));
    let l = wide(pixel(&out, left, 32));
    let r = wide(pixel(&out, right, 32));
    assert!(
        l[0] > 2 * l[1].max(l[2]),
        "atom 1 red from --type-color: {l:?}"
    );
    // Type 2 has no element and no rule: the unknown-element pink (255, 20, 147).
    assert!(
        r[0] > r[2] && r[2] > r[1] + 40,
        "atom 2 unknown pink: {r:?}"
    );
    // --color-by type: --type-color for type 1, a palette colour for type 2.
    let out = dir.path().join("type.png");
    let mut f = flags.to_vec();
    f.extend(["--color-by", "type"]);
    let o = render_axis(&dump, &out, &f);
    assert!(o.status.success(), "{}", stderr(&o));
    let l = wide(pixel(&out, left, 32));
    assert!(
        l[0] > 2 * l[1].max(l[2]),
        "atom 1 red from --type-color: {l:?}"
    );
}

/// Half-width in pixels of the lit run through the centre row.
fn half_width(png: &Path) -> f64 {
    let img = image::open(png).unwrap().to_rgba8();
    let lit = (0..img.width())
        .filter(|x| img.get_pixel(*x, 32).0[..3] != [0, 0, 0])
        .count();
    lit as f64 / 2.0
}

#[test]
fn type_radius_and_radius_scale_set_the_disc_size() {
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("one.xyz");
    std::fs::write(&xyz, "1\ncarbon\nC 0 0 0\n").unwrap();
    // A sphere of radius r at distance d = 10 has a silhouette of radius k·r / sqrt(d² − r²)
    // pixels (tangent cone), k = 65 / (2 tan 15°).
    let k = 65.0 / (2.0 * 15f64.to_radians().tan());
    let expect = |r: f64| k * r / (100.0 - r * r).sqrt();
    for (flags, r) in [
        (vec![], 1.77),
        (vec!["--type-radius", "C=0.5"], 0.5),
        (vec!["--type-radius", "c=2"], 2.0),
        (vec!["--type-radius", "C=2", "--radius-scale", "0.5"], 1.0),
        (vec!["--radius-scale", "0.5"], 0.885),
        // A colour for the same NAME keeps the radius (flags merge field by field).
        (
            vec!["--type-radius", "C=2", "--type-color", "C=#ffffff"],
            2.0,
        ),
    ] {
        let out = dir.path().join("r.png");
        let o = render_axis(&xyz, &out, &flags);
        assert!(o.status.success(), "{flags:?}: {}", stderr(&o));
        let (e, a) = (expect(r), half_width(&out));
        // Pixel counting: the run's ends are each within one pixel of the silhouette.
        assert!(
            (e - a).abs() <= 1.0,
            "{flags:?}: expected {e} px, actual {a}, tolerance 1"
        );
    }
}

#[test]
fn bad_style_values_exit_2_naming_the_flag_and_value() {
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("one.xyz");
    std::fs::write(&xyz, "1\ncarbon\nC 0 0 0\n").unwrap();
    let out = dir.path().join("x.png");
    for (flag, value) in [
        ("--type-radius", "O=-1"),
        ("--type-radius", "O=0"),
        ("--type-radius", "O=nan"),
        ("--type-radius", "O"),
        ("--type-radius", "=1"),
        ("--type-radius", "O=abc"),
        ("--type-color", "O=#12345"),
        ("--type-color", "O=#gg0000"),
        ("--type-color", "O=300,0,0"),
        ("--type-color", "O=1,2"),
        ("--type-color", "O=red"),
        ("--type-color", "ABCDEFGHIJKLMNOP=#ffffff"),
        ("--radius-scale", "0"),
        ("--colormap", "jet"),
        ("--color-range", "5:1"),
        ("--color-range", "0:inf"),
    ] {
        let o = render_axis(&xyz, &out, &[flag, value]);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains(flag),
            "{flag} {value}: message names the flag: {e}"
        );
        let shown = value.split('=').next_back().unwrap();
        assert!(
            e.contains(shown),
            "{flag} {value}: message shows the value: {e}"
        );
        assert!(!out.exists(), "{flag} {value}: no image");
    }
    // Style flags belong to a trajectory FILE, not to a built-in --scene.
    let o = texmap(&[
        "compare",
        "--scene",
        "S1",
        "--out",
        "d",
        "--type-color",
        "O=#ffffff",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // A NAME that selects nothing is a warning, not an error.
    let o = render_axis(&xyz, &out, &["--type-color", "Zz9=#ffffff"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: --type-color Zz9: no atom"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn render_help_lists_every_flag_the_issue_names() {
    let o = texmap(&["render", "--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout);
    for flag in [
        "--frames",
        "--method",
        "--size",
        "--ortho",
        "--fov",
        "--view",
        "--eye",
        "--target",
        "--up",
        "--color-by",
        "--radius-scale",
        "--background",
        "--output",
        "--depth",
        "--box-outline",
        "--threads",
        "--type-radius",
        "--type-color",
        "raycast",
        "lut",
        "template",
        "polygon",
        "reference",
        "element",
        "property",
        "Examples:",
    ] {
        assert!(
            help.contains(flag),
            "render --help mentions {flag}:\n{help}"
        );
    }
    let o = texmap(&["compare", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout);
    assert!(
        help.contains("--type-color") && help.contains("--type-radius"),
        "{help}"
    );
}

#[test]
fn compare_a_file_honours_the_style_flags() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let o = texmap(&[
        "compare",
        data("lmp_color.lammpstrj").to_str().unwrap(),
        "--size",
        "80x60",
        "--runs",
        "1",
        "--color-by",
        "element",
        "--type-color",
        "1=#00ff00",
        "--type-color",
        "2=#00ff00",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Every atom is green in the reference image: lit pixels are green-dominant.
    let img = image::open(out.join("lmp_color/reference.png"))
        .unwrap()
        .to_rgba8();
    let lit: Vec<_> = img.pixels().filter(|p| p.0[..3] != [0, 0, 0]).collect();
    assert!(lit.len() > 100, "atoms are drawn");
    assert!(
        lit.iter().all(|p| p.0[1] >= p.0[0] && p.0[1] >= p.0[2]),
        "all lit pixels green-dominant"
    );
}

#[test]
fn ortho_view_and_background_work() {
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("two.xyz");
    // Two atoms along z: seen from the x axis (--view x) they are side by side.
    std::fs::write(&xyz, "2\npair\nC 0 0 -3\nO 0 0 3\n").unwrap();
    for view in ["x", "-y", "auto"] {
        let out = dir.path().join(format!("o{view}.png"));
        let o = texmap(&[
            "render",
            xyz.to_str().unwrap(),
            "--ortho",
            "--view",
            view,
            "--background",
            "10,20,30",
            "--size",
            "64x48",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{view}: {}", stderr(&o));
        // The auto-fitted camera frames the atoms: the corner is background, the atoms cover
        // a good part of the 64x48 image.
        assert_eq!(pixel(&out, 0, 0), [10, 20, 30], "{view}: background");
        let img = image::open(&out).unwrap().to_rgba8();
        let lit = img.pixels().filter(|p| p.0[..3] != [10, 20, 30]).count();
        assert!(lit > 200, "{view}: atoms drawn ({lit} px)");
    }
    let o = texmap(&[
        "render",
        xyz.to_str().unwrap(),
        "--view",
        "diagonal",
        "-o",
        dir.path().join("v.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--view"), "{}", stderr(&o));
}
