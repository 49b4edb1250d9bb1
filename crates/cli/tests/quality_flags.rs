//! `texmap render` quality flags: presets, transparent background with anti-aliased alpha, soft
//! shadows, reference outlines, and bad values refused as usage errors. (The quality pass's
//! accuracy against the reference ray tracer is tested in crates/quality.)

use std::path::{Path, PathBuf};

use crate::common;
use common::texmap;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(name)
}

fn rgba(path: &Path) -> image::RgbaImage {
    image::open(path).unwrap().to_rgba8()
}

/// `texmap render topo_mda.gro` at `size` into `dir/name` with `extra` flags; the image.
fn render(dir: &Path, size: &str, name: &str, extra: &[&str]) -> image::RgbaImage {
    let gro = data("topo_mda.gro");
    let out = dir.join(name);
    let mut args = vec![
        "render",
        gro.to_str().unwrap(),
        "--size",
        size,
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = texmap(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    rgba(&out)
}

#[test]
fn presets_change_the_image_and_transparency_gives_partial_alpha_on_edges() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| render(dir.path(), "160x120", name, extra);
    let plain = run("plain.png", &[]);
    let draft = run("draft.png", &["--quality", "draft"]);
    // The draft preset adds nothing: the exact ray-cast image, byte for byte.
    assert_eq!(plain, draft);
    let good = run("good.png", &["--quality", "good"]);
    let differing = plain
        .pixels()
        .zip(good.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differing > 100,
        "AO and shadows changed only {differing} pixels"
    );
    let clear = run("clear.png", &["--aa", "16", "--background", "transparent"]);
    assert_eq!(clear.get_pixel(0, 0)[3], 0, "background is transparent");
    let partial = clear.pixels().filter(|p| p[3] > 0 && p[3] < 255).count();
    let opaque = clear.pixels().filter(|p| p[3] == 255).count();
    assert!(
        partial > 20 && opaque > partial,
        "{partial} partial, {opaque} opaque"
    );
}

#[test]
fn soft_shadows_and_reference_outlines_render() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| render(dir.path(), "160x120", name, extra);
    let hard = run("hard.png", &["--shadows"]);
    // A 0° light is the hard shadow; a 10° one softens it.
    let point = run("point.png", &["--soft-shadows", "4", "--light-size", "0"]);
    assert_eq!(hard, point);
    let soft = run("soft.png", &["--soft-shadows", "16", "--light-size", "10"]);
    assert_ne!(hard, soft);
    // The reference draws the same outline as the ray-cast method.
    let args = ["--aa", "16", "--outline", "1"];
    let ours = run("ours.png", &args);
    let mut r = args.to_vec();
    r.extend(["--method", "reference"]);
    let reference = run("reference.png", &r);
    let far = ours
        .pixels()
        .zip(reference.pixels())
        .filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 16))
        .count();
    assert!(
        far * 100 <= (160 * 120),
        "{far} pixels differ by more than 16 levels"
    );
}

#[test]
fn bad_quality_values_are_usage_errors() {
    let gro = data("topo_mda.gro");
    let gro = gro.to_str().unwrap();
    for bad in [
        vec!["--aa", "0"],
        vec!["--aa", "100000"],
        vec!["--ao", "999999"],
        vec!["--ao-distance", "-1"],
        vec!["--outline", "0"],
        vec!["--method", "lut", "--shadows"],
        vec!["--background", "transparentish"],
        vec!["--soft-shadows", "0"],
        vec!["--soft-shadows", "1000000"],
        vec!["--soft-shadows", "16", "--light-size", "-1"],
        vec!["--soft-shadows", "16", "--light-size", "45"],
        vec!["--light-size", "4"],
    ] {
        let mut args = vec!["render", gro, "-o", "/nonexistent/x.png"];
        args.extend(&bad);
        let o = texmap(&args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{bad:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        // A range problem names the allowed range.
        let err = String::from_utf8_lossy(&o.stderr);
        if bad[0] == "--soft-shadows" {
            let range = if bad.len() == 2 { "1..=1024" } else { "0..=30" };
            assert!(err.contains(range), "{bad:?}: {err}");
        }
    }
}

/// `compare --quality-axis`: every setting against the converged reference with the same
/// effects; more edge samples must come closer to it (a reference traced independently).
#[test]
fn compare_quality_axis_orders_the_settings_by_error() {
    let dir = tempfile::tempdir().unwrap();
    let o = texmap(&[
        "compare",
        "--scene",
        "S1",
        "--runs",
        "1",
        "--quality-axis",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.path().join("quality.csv")).unwrap();
    let psnr = |method: &str| -> f64 {
        let line = csv
            .lines()
            .find(|l| l.split(',').nth(1) == Some(method))
            .unwrap_or_else(|| panic!("{method} missing from quality.csv"));
        line.split(',').nth(6).unwrap().parse().unwrap()
    };
    assert!(psnr("aa4") > psnr("aa1") + 3.0);
    assert!(psnr("aa16") > psnr("aa4") + 3.0);
    assert!(psnr("aa16-ao32-shadows") > psnr("aa1-ao8-shadows") + 3.0);
    assert!(dir.path().join("quality.svg").is_file());
    assert!(dir.path().join("s1/quality_aa4-ao8-shadows.png").is_file());
}

/// `--method reference` takes the same quality flags: the ray-cast `good` image lies close to
/// the reference traced with the same AO, shadows and samples (and far from the plain one).
#[test]
fn the_reference_draws_the_same_quality_settings() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| render(dir.path(), "200x150", name, extra);
    let psnr = |a: &image::RgbaImage, b: &image::RgbaImage| -> f64 {
        let mut se = 0f64;
        for (p, q) in a.pixels().zip(b.pixels()) {
            for c in 0..3 {
                se += (p[c] as f64 - q[c] as f64).powi(2);
            }
        }
        let mse = se / (3 * a.width() * a.height()) as f64;
        10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10()
    };
    let ours = run("good.png", &["--quality", "good", "--ao", "64"]);
    let reference = run(
        "ref.png",
        &["--quality", "good", "--ao", "64", "--method", "reference"],
    );
    let plain_reference = run("plain_ref.png", &["--method", "reference"]);
    let close = psnr(&ours, &reference);
    let far = psnr(&plain_reference, &reference);
    assert!(close > 35.0, "quality pass vs its reference: {close} dB");
    assert!(
        close > far + 3.0,
        "{close} dB vs {far} dB without the effects"
    );
}

/// Cartoons (and every mesh) take the quality flags: traced by the reference ray tracer with
/// the spheres, the same bytes whichever method is asked for; ambient occlusion only darkens
/// (each pixel at most as bright as the plain trace, the grooves between helices darker),
/// and shadows darken more.
#[test]
fn a_cartoon_takes_ambient_occlusion_and_shadows() {
    let dir = tempfile::tempdir().unwrap();
    let pdb = data("dssp/3gwiA.pdb.gz");
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            "render",
            pdb.to_str().unwrap(),
            "--style",
            "cartoon",
            "--size",
            "240x180",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = texmap(&args);
        assert!(
            o.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        (rgba(&out), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (plain, _) = run("plain.png", &["--method", "reference"]);
    let (ao, said) = run("ao.png", &["--aa", "1", "--ao", "16"]);
    assert!(said.contains("reference ray tracer"), "{said}");
    let (ao_ref, _) = run(
        "ao_ref.png",
        &["--aa", "1", "--ao", "16", "--method", "reference"],
    );
    assert!(ao == ao_ref, "the same trace whichever method is asked for");
    let (shadowed, _) = run("shadows.png", &["--aa", "1", "--ao", "16", "--shadows"]);
    let luma = |p: &image::Rgba<u8>| p[0] as i32 * 3 + p[1] as i32 * 6 + p[2] as i32;
    let (mut brighter, mut darker, mut sum_plain, mut sum_ao, mut sum_shadow) =
        (0, 0, 0i64, 0i64, 0i64);
    for ((p, q), r) in plain.pixels().zip(ao.pixels()).zip(shadowed.pixels()) {
        brighter += (luma(q) > luma(p) + 10) as usize;
        darker += (luma(q) + 30 < luma(p)) as usize;
        sum_plain += luma(p) as i64;
        sum_ao += luma(q) as i64;
        sum_shadow += luma(r) as i64;
    }
    eprintln!(
        "AO: {darker} pixels darker, {brighter} brighter; mean luma {sum_plain} -> {sum_ao} -> {sum_shadow} (shadows)"
    );
    assert_eq!(brighter, 0, "occlusion never brightens");
    assert!(darker > 200, "{darker} pixels darkened");
    assert!(sum_shadow < sum_ao && sum_ao < sum_plain);
}
