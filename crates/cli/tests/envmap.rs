//! `texmap envmap` end to end: the Seed 003 options reach the renderer (checked against what they
//! must give, not against stored images), movie output, and bad values refused as usage errors.
//! (The methods' accuracy against the reference ray tracer is tested in crates/study.)

use std::path::Path;

use crate::common;
use common::texmap;

/// `texmap envmap --size 160x120 -o dir/name extra...`; the image's RGB bytes.
fn envmap(dir: &Path, name: &str, extra: &[&str]) -> Vec<u8> {
    let out = dir.join(name);
    let mut args = vec![
        "envmap",
        "--size",
        "160x120",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = texmap(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    image::open(&out).unwrap().to_rgb8().into_raw()
}

fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let se: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - *y as f64).powi(2))
        .sum();
    if se == 0.0 {
        return f64::INFINITY;
    }
    10.0 * (255.0f64 * 255.0 / (se / a.len() as f64)).log10()
}

#[test]
fn seed_003_options_reach_the_renderer() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dynamic = envmap(d, "dyn.png", &[]);
    let stat = envmap(d, "static.png", &["--method", "sphere-static"]);
    // With every object nearer than --min-distance, the dynamic map holds the environment alone:
    // the static map's image, up to the two maps' resampling (measured 60 dB).
    let far = envmap(d, "far.png", &["--min-distance", "1e6"]);
    let p_far_static = psnr(&far, &stat);
    let p_dyn_static = psnr(&dynamic, &stat);
    assert!(
        p_far_static > 45.0 && p_dyn_static < 30.0,
        "far vs static {p_far_static:.1} dB, dynamic vs static {p_dyn_static:.1} dB"
    );
    // The 1998 rim handling and bilinear filtering change the image, but not wholesale.
    for extra in [&["--rim", "naive"][..], &["--filter", "bilinear"][..]] {
        let img = envmap(d, "x.png", extra);
        let p = psnr(&img, &dynamic);
        assert!(p.is_finite() && p > 25.0, "{extra:?}: {p:.1} dB");
    }
    // A background colour replaces the environment behind the target, not on it.
    // Every pixel it changes turns white, and the target keeps reflecting the environment.
    let white = envmap(d, "white.png", &["--background", "255,255,255"]);
    let (mut changed, mut same) = (0, 0);
    for (w, o) in white.chunks(3).zip(dynamic.chunks(3)) {
        if w != o {
            assert_eq!(w, [255, 255, 255]);
            changed += 1;
        } else {
            same += 1;
        }
    }
    assert!(
        changed > 500 && same > 500,
        "{changed} changed, {same} kept"
    );
}

#[test]
fn an_animation_goes_into_a_movie() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tunnel.apng");
    let o = texmap(&[
        "envmap",
        "--size",
        "96x64",
        "--frames",
        "6",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // An APNG with 6 frames: the acTL chunk's frame count.
    let bytes = std::fs::read(&out).unwrap();
    let at = bytes
        .windows(4)
        .position(|w| w == b"acTL")
        .expect("acTL chunk");
    let frames = u32::from_be_bytes(bytes[at + 4..at + 8].try_into().unwrap());
    assert_eq!(frames, 6);
}

#[test]
fn faces_per_frame_slices_the_cube_map_of_one_renderer_across_frames() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Three frames of the animation, PNG bytes per frame, for a given --faces-per-frame.
    let run = |name: &str, extra: &[&str]| -> Vec<Vec<u8>> {
        let pat = d.join(format!("{name}_%04d.png"));
        let mut args = vec![
            "envmap",
            "--method",
            "cube",
            "--size",
            "96x72",
            "--map-size",
            "64",
            "--frames",
            "3",
            "-q",
            "-o",
            pat.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (0..3)
            .map(|i| std::fs::read(d.join(format!("{name}_{i:04}.png"))).unwrap())
            .collect()
    };
    let every = run("six", &[]);
    assert_eq!(run("six_explicit", &["--faces-per-frame", "6"]), every);
    let one = run("one", &["--faces-per-frame", "1"]);
    // The first frame draws the whole map; the next ones keep the renderer's map and redraw one
    // face, so the moving objects' reflections differ from the full update's.
    assert_eq!(one[0], every[0]);
    assert_ne!(one[1], every[1]);
    assert_ne!(one[2], every[2]);
}

#[test]
fn bad_values_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let out = out.to_str().unwrap();
    for (flag, value) in [
        ("--min-distance", "-1"),
        ("--min-distance", "nan"),
        ("--background", "1,2"),
        ("--background", "transparent"),
        ("--reference-samples", "0"),
        ("--faces-per-frame", "0"),
        ("--faces-per-frame", "7"),
        ("--fps", "0"),
    ] {
        let mut args = vec!["envmap", "--size", "32x32", "-o", out, flag, value];
        if flag == "--fps" {
            args.extend(["--frames", "2"]);
            args[4] = "x.mp4";
        }
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(flag), "{flag} {value}: {err}");
    }
}

/// A Radiance `.hdr` environment (RGBE, written by OpenCV: tests/data/env/gen_env.py) reads as
/// OpenCV decodes it, sun brighter than white included: the image drawn with it equals the one
/// drawn with OpenCV's decoded floats written as an EXR.
#[test]
fn a_radiance_hdr_environment_reads_as_opencv_decodes_it() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/env");
    let raw = std::fs::read(data.join("sky_opencv.f32")).unwrap();
    let v: Vec<f32> = raw
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let (w, h) = (128usize, 64usize);
    assert_eq!(v.len(), w * h * 3);
    assert!(v.iter().copied().fold(0.0f32, f32::max) > 4.0, "an HDR sun");
    let dir = tempfile::tempdir().unwrap();
    let exr_path = dir.path().join("sky.exr");
    exr::prelude::write_rgb_file(&exr_path, w, h, |x, y| {
        let k = (y * w + x) * 3;
        (v[k], v[k + 1], v[k + 2])
    })
    .unwrap();
    let hdr = data.join("sky.hdr");
    let with = |env: &Path, name: &str| envmap(dir.path(), name, &["--env", env.to_str().unwrap()]);
    let a = with(&hdr, "hdr.png");
    let b = with(&exr_path, "exr.png");
    assert_eq!(a, b, "PSNR {}", psnr(&a, &b));
    // And it is not the built-in sky.
    let builtin = envmap(dir.path(), "sky.png", &[]);
    assert!(psnr(&a, &builtin) < 30.0);
}

fn ffmpeg_available() -> bool {
    std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `texmap envmap bake -q extra... -o out`, which must succeed.
fn bake(out: &Path, extra: &[&str]) {
    let mut args = vec!["envmap", "bake", "-q", "-o", out.to_str().unwrap()];
    args.extend(extra);
    let o = texmap(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// ffmpeg's v360 turning our c3x2 into an equirect agrees with our own equirect of the same
/// probe: ffmpeg reads the faces by its own table, so a face in the wrong place or orientation
/// would differ by tens of levels over a whole face.
#[test]
fn bake_c3x2_through_ffmpeg_matches_our_equirect() {
    if !ffmpeg_available() {
        eprintln!("SKIPPED: ffmpeg not found");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (c3x2, ours, theirs) = (
        dir.path().join("a.png"),
        dir.path().join("e.png"),
        dir.path().join("b.png"),
    );
    let n = 64;
    let common = ["--size", "64", "--time", "0.5"];
    bake(&c3x2, &[&common[..], &["--layout", "c3x2"]].concat());
    bake(&ours, &[&common[..], &["--layout", "equirect"]].concat());
    let o = std::process::Command::new("ffmpeg")
        .args(["-loglevel", "error", "-y", "-i"])
        .arg(&c3x2)
        .args(["-vf", &format!("v360=c3x2:e:w={}:h={}", 4 * n, 2 * n)])
        .arg(&theirs)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a = image::open(&ours).unwrap().to_rgb8();
    let b = image::open(&theirs).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), (4 * n, 2 * n));
    assert_eq!(a.dimensions(), b.dimensions());
    let mad = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| (*x as f64 - *y as f64).abs())
        .sum::<f64>()
        / a.as_raw().len() as f64;
    // Both resample bilinearly, ffmpeg on the 8-bit sRGB codes and we in linear light, so
    // edges differ by a few levels. Measured (ffmpeg 5.1): 0.93 levels of 255; the c3x2 image
    // mirrored left-right before ffmpeg reads it: 47.
    assert!(
        mad < 2.0,
        "mean absolute difference {mad:.3} levels, bound 2"
    );
}

/// Read an EXR's RGB as floats.
fn read_exr(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0.0f32; 3]; res.width() * res.height()]),
        |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )
    .unwrap();
    let size = img.layer_data.size;
    (
        size.width(),
        size.height(),
        img.layer_data.channel_data.pixels.1,
    )
}

/// The EXR files hold the library's floats bit for bit, the faces under their px..nz names, and
/// `--frame 12` is `--time 0.5` (frames 1/24 s apart, as `texmap envmap --frames`).
#[test]
fn bake_exr_holds_the_librarys_floats() {
    use texmap_envmap::address::Face;
    use texmap_envmap::bake::{BakeOptions, Layout, bake as bake_probe, face_name};
    use texmap_envmap::scene::{TunnelParams, tunnel_scene};

    let dir = tempfile::tempdir().unwrap();
    let n = 32u32;
    let scene = tunnel_scene(TunnelParams {
        time: 0.5,
        ..Default::default()
    })
    .unwrap();
    let at = texmap_envmap::glam::Vec3::new(0.5, -0.25, -2.0);
    let probe = bake_probe(
        &scene,
        &BakeOptions {
            at: Some(at),
            size: n,
        },
    )
    .unwrap();
    let bits = |v: &[[f32; 3]]| -> Vec<u32> { v.iter().flatten().map(|c| c.to_bits()).collect() };
    let lib_bits = |v: &[texmap_envmap::glam::Vec3]| -> Vec<u32> {
        v.iter()
            .flat_map(|c| c.to_array())
            .map(f32::to_bits)
            .collect()
    };
    let cross = dir.path().join("cross.exr");
    bake(
        &cross,
        &["--size", "32", "--frame", "12", "--at", "0.5,-0.25,-2"],
    );
    let (w, h, px) = read_exr(&cross);
    let want = probe.layout(Layout::Cross).remove(0);
    assert_eq!((w as u32, h as u32), (want.width, want.height));
    assert_eq!(bits(&px), lib_bits(&want.texels));
    let pattern = dir.path().join("faces/probe_{face}.exr");
    bake(
        &pattern,
        &[
            "--size",
            "32",
            "--time",
            "0.5",
            "--at",
            "0.5,-0.25,-2",
            "--layout",
            "faces",
        ],
    );
    for face in Face::ALL {
        let path = dir
            .path()
            .join(format!("faces/probe_{}.exr", face_name(face)));
        let (w, h, px) = read_exr(&path);
        assert_eq!((w as u32, h as u32), (n, n));
        assert_eq!(bits(&px), lib_bits(probe.face(face)), "{face:?}");
    }
}

#[test]
fn bad_bake_options_are_usage_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    for (args, what) in [
        (vec!["--size", "0", "-o", &p("a.png")], "--size"),
        (vec!["--layout", "faces", "-o", &p("f.exr")], "{face}"),
        (vec!["-o", &p("probe.jpg")], ".exr"),
        (vec!["-o", &p("probe_{face}.exr")], "{face}"),
        (vec!["--at", "1,2", "-o", &p("a.exr")], "--at"),
    ] {
        let mut all = vec!["envmap", "bake"];
        if !args.contains(&"--size") {
            all.extend(["--size", "8"]);
        }
        all.extend(args.iter().copied());
        let o = texmap(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(what), "{args:?}: {err}");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
}
