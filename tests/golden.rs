//! Golden images: every sphere method and the reference ray tracer on one small scene (the
//! ball-and-stick molecule, 300 atoms and 299 bonds, at 200x200), compared pixel by pixel with
//! PNGs kept in `tests/golden/`.
//!
//! These tests do not judge accuracy (the study and the `vs_reftrace` tests do, against the
//! reference); they make a change of pixels visible. Every build (SSE2, AVX2, AVX-512) must give
//! the same bytes, so the tolerance is small: a pixel counts as changed when a channel differs by
//! more than [`CHANNEL_TOLERANCE`]. On a failure the test writes the image it drew, and a diff
//! image (changed pixels in magenta over a dimmed copy of the golden one) to
//! `target/golden-diff/`, and names them.
//!
//! A change of pixels made on purpose is accepted with `TEXMAP_BLESS=1 cargo test --test golden`,
//! which rewrites the PNGs; review them before committing.

use std::path::{Path, PathBuf};

use texmap::core::frame::Frame;
use texmap::impostor::{Method, Renderer};
use texmap::study::harness;
use texmap::study::scenes::{self, SceneId};

/// A channel may differ by this much (sRGB 8-bit steps) before a pixel counts as changed.
const CHANNEL_TOLERANCE: u8 = 1;

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

fn diff_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("target/golden-diff")
}

fn scene() -> scenes::NamedScene {
    scenes::build_sized(SceneId::MoleculeBallStick, 200, 200).expect("scene at 200x200")
}

fn to_rgba(frame: &Frame) -> image::RgbaImage {
    let bytes: Vec<u8> = frame.color.iter().flatten().copied().collect();
    image::RgbaImage::from_raw(frame.width(), frame.height(), bytes).expect("frame size")
}

/// Compare `frame` with `tests/golden/{name}.png` (or write it when blessing).
fn check(name: &str, frame: &Frame) {
    let path = golden_dir().join(format!("{name}.png"));
    let actual = to_rgba(frame);
    if std::env::var_os("TEXMAP_BLESS").is_some() {
        std::fs::create_dir_all(golden_dir()).unwrap();
        actual.save(&path).unwrap();
        return;
    }
    let golden = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (run TEXMAP_BLESS=1 cargo test --test golden)",
                path.display()
            )
        })
        .to_rgba8();
    assert_eq!(
        golden.dimensions(),
        actual.dimensions(),
        "{name}: image size changed"
    );
    let mut diff = image::RgbaImage::new(golden.width(), golden.height());
    let mut changed = 0usize;
    let mut worst = 0u8;
    for ((g, a), d) in golden.pixels().zip(actual.pixels()).zip(diff.pixels_mut()) {
        let delta = (0..4).map(|c| g[c].abs_diff(a[c])).max().unwrap();
        worst = worst.max(delta);
        *d = if delta > CHANNEL_TOLERANCE {
            changed += 1;
            image::Rgba([255, 0, 255, 255])
        } else {
            image::Rgba([g[0] / 3, g[1] / 3, g[2] / 3, 255])
        };
    }
    if changed > 0 {
        std::fs::create_dir_all(diff_dir()).unwrap();
        let got = diff_dir().join(format!("{name}-actual.png"));
        let dif = diff_dir().join(format!("{name}-diff.png"));
        actual.save(&got).unwrap();
        diff.save(&dif).unwrap();
        panic!(
            "{name}: {changed} pixels differ from {} by more than {CHANNEL_TOLERANCE} \
             (largest channel difference {worst}); drawn: {}, diff: {}",
            path.display(),
            got.display(),
            dif.display()
        );
    }
}

#[test]
fn every_sphere_method_draws_the_golden_image() {
    let scene = scene();
    let mut renderer = Renderer::new();
    for method in Method::ALL {
        let mut opts = harness::study_options(method, scene.lighting);
        opts.draw_bonds = scene.draw_bonds;
        let out = renderer.render(&scene.spheres, &scene.camera, &opts);
        check(&format!("molecule-bs-{}", method.name()), &out.frame);
    }
}

#[test]
fn the_reference_draws_the_golden_image() {
    let scene = scene();
    let reference = harness::render_reference(
        &harness::reference_scene_with_bonds(&scene.spheres, scene.draw_bonds),
        &harness::reference_materials(&scene.spheres),
        &scene.camera,
        scene.lighting,
        [0, 0, 0, 255],
        1,
    )
    .expect("reference renders");
    check("molecule-bs-reference", &reference);
}

#[test]
fn a_changed_pixel_is_reported_with_a_diff_image() {
    // The comparison itself must fail on a change: draw the reference, change one pixel by more
    // than the tolerance, and expect the panic to name the diff image.
    if std::env::var_os("TEXMAP_BLESS").is_some() {
        return;
    }
    let scene = scene();
    let mut frame = harness::render_reference(
        &harness::reference_scene_with_bonds(&scene.spheres, scene.draw_bonds),
        &harness::reference_materials(&scene.spheres),
        &scene.camera,
        scene.lighting,
        [0, 0, 0, 255],
        1,
    )
    .unwrap();
    let i = frame.index(100, 100);
    frame.color[i][1] = frame.color[i][1].wrapping_add(CHANNEL_TOLERANCE + 1);
    let caught = std::panic::catch_unwind(|| check("molecule-bs-reference", &frame));
    let message = caught
        .expect_err("a changed pixel must fail")
        .downcast::<String>()
        .expect("panic message");
    assert!(
        message.contains("1 pixels differ") && message.contains("-diff.png"),
        "{message}"
    );
}
