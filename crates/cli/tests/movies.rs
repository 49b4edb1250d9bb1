//! `texmap render -o movie.{apng,mp4}` and `texmap movie DIR -o ...`: the extension decides, the
//! movie holds every frame (checked by decoding it with ffmpeg, another program), bad extensions
//! are usage errors, and a failed render leaves no movie behind.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::texmap;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(name)
}

fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Frame count of a movie as ffprobe counts it.
fn ffprobe_frames(path: &Path) -> usize {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args(["-show_entries", "stream=nb_read_frames", "-of", "csv=p=0"])
        .arg(path)
        .output()
        .expect("ffprobe runs");
    String::from_utf8_lossy(&out.stdout).trim().parse().unwrap()
}

#[test]
fn a_trajectory_renders_straight_to_a_movie() {
    let dir = tempfile::tempdir().unwrap();
    let traj = data("mda_multi.pdb");
    let traj = traj.to_str().unwrap();
    // Animated PNG: no external program.
    let apng = dir.path().join("m.apng");
    let out = texmap(&[
        "render",
        traj,
        "--size",
        "96x64",
        "-o",
        apng.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("m.apng"));
    let frames_in_file = {
        let o = texmap(&["info", traj]);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["frames"].as_u64().unwrap() as usize
    };
    assert!(frames_in_file >= 2);
    if !ffmpeg_available() {
        eprintln!("SKIPPED the MP4 and the frame count check: ffmpeg is not installed");
        return;
    }
    assert_eq!(ffprobe_frames(&apng), frames_in_file);
    let mp4 = dir.path().join("m.mp4");
    let out = texmap(&[
        "render",
        traj,
        "--size",
        "96x64",
        "-o",
        mp4.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(ffprobe_frames(&mp4), frames_in_file);
    // Nothing but the two movies in the directory (no frames, no temporary files).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn png_frames_assemble_into_a_movie() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    std::fs::create_dir(&frames).unwrap();
    let traj = data("mda_multi.pdb");
    let pattern = frames.join("f%d.png");
    let out = texmap(&[
        "render",
        traj.to_str().unwrap(),
        "--size",
        "64x48",
        "-o",
        pattern.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let n = std::fs::read_dir(&frames).unwrap().count();
    let movie = dir.path().join("all.apng");
    let out = texmap(&[
        "movie",
        frames.to_str().unwrap(),
        "-o",
        movie.to_str().unwrap(),
        "--fps",
        "10",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    if ffmpeg_available() {
        assert_eq!(ffprobe_frames(&movie), n);
    }
    // An empty directory is a runtime error, a non-movie extension a usage error.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let out = texmap(&[
        "movie",
        empty.to_str().unwrap(),
        "-o",
        movie.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let out = texmap(&["movie", frames.to_str().unwrap(), "-o", "x.png"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn unknown_extensions_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let traj = data("mda_multi.pdb");
    for name in ["movie.jpg", "noext", "frames.mp4.tmp"] {
        let target = dir.path().join(name);
        let out = texmap(&[
            "render",
            traj.to_str().unwrap(),
            "--size",
            "32x32",
            "-o",
            target.to_str().unwrap(),
        ]);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stderr).contains(".apng"));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // --depth cannot go into a movie.
    let out = texmap(&[
        "render",
        traj.to_str().unwrap(),
        "--depth",
        "-o",
        dir.path().join("m.gif").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn the_demo_writes_its_animation_as_a_movie() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let o = texmap(&[
        "demo",
        "--out",
        out.to_str().unwrap(),
        "--steps",
        "40",
        "--every",
        "10",
        "--size",
        "96x96",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("md.apng"));
    // The page explains itself: the methods, the metrics, the element and error colours, and
    // it shows the environment-mapping section with an image per method.
    for needle in [
        "Seed 002",
        "Seed 004",
        "<dt>PSNR (dB)</dt>",
        "<dt>SSIM</dt>",
        "<dt>silhouette px</dt>",
        "Element colours",
        "Error images:",
        "Environment mapping (Seed 003)",
        "envmap/sphere-dynamic.png",
        "Terrain flight view (Seed 000)",
        "terrain/flight.apng",
    ] {
        assert!(html.contains(needle), "index.html lacks {needle:?}");
    }
    // Every image and chart the page links to exists.
    for src in html.split("src=\"").skip(1) {
        let path = src.split('"').next().unwrap();
        if path.starts_with("frames/") {
            continue; // the animation's frames are swapped in by the page's script
        }
        assert!(
            out.join(path).is_file(),
            "index.html links to a missing {path}"
        );
    }
    let movie = out.join("md.apng");
    let frames = std::fs::read_dir(out.join("frames/raycast"))
        .unwrap()
        .count();
    assert!(frames >= 4);
    if ffmpeg_available() {
        assert_eq!(ffprobe_frames(&movie), frames);
    } else {
        assert!(image::open(&movie).is_ok(), "the first frame decodes");
    }
}
