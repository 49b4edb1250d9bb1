//! Camera paths of `texmap render`: `--orbit`, `--orbit-turns`, `--keyframes`, `--follow`, and
//! `--quiet`. Each path is checked against renders with an explicit camera at the pose the path
//! must reach (the camera a user would have given by hand), not against stored images.

use std::path::Path;
use std::process::Output;

use crate::common;
use common::texmap;

/// `texmap render TRAJ FLAGS -o OUT`, which must succeed.
fn render_ok(traj: &str, out: &str, flags: &[&str]) {
    let mut args = vec!["render", traj];
    args.extend(flags);
    args.extend(["-o", out]);
    ok(&texmap(&args));
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// An extended-XYZ-free plain XYZ trajectory: a fixed, asymmetric cluster of 40 atoms, moved by
/// `shift` Å per frame along x.
fn write_cluster(path: &Path, frames: usize, shift: f32) {
    let mut text = String::new();
    for f in 0..frames {
        text.push_str("40\ncluster\n");
        for i in 0..40 {
            // A deterministic, lopsided arrangement (so that a turned view looks different).
            let t = i as f32;
            let (x, y, z) = (
                (t * 1.7).sin() * 6.0 + t * 0.15,
                (t * 0.9).cos() * 4.0,
                (t * 2.3).sin() * 3.0 - t * 0.1,
            );
            let el = ["C", "O", "N", "H"][i % 4];
            text.push_str(&format!("{el} {:.4} {y:.4} {z:.4}\n", x + f as f32 * shift));
        }
    }
    std::fs::write(path, text).unwrap();
}

fn pixels(path: &Path) -> Vec<u8> {
    image::open(path).unwrap().to_rgba8().into_raw()
}

/// Fraction of pixels whose colour differs by more than 8 levels in some channel.
fn differing(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len());
    let n = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    n as f64 / (a.len() / 4) as f64
}

#[test]
fn an_orbit_reaches_the_pose_of_the_turned_camera() {
    let dir = tempfile::tempdir().unwrap();
    let traj = dir.path().join("c.xyz");
    write_cluster(&traj, 3, 0.0);
    let traj = traj.to_str().unwrap();
    let cam = [
        "--eye", "0,0,40", "--target", "0,0,0", "--up", "0,1,0", "--size", "120x90",
    ];
    let pat = dir.path().join("o%02d.png");
    let mut args = vec!["render", traj, "--orbit", "90", "-o", pat.to_str().unwrap()];
    args.extend(cam);
    ok(&texmap(&args));
    // +90° about +y takes the eye from +z to +x; frame 2 is at −z.
    for (frame, eye) in [(1, "40,0,0"), (2, "0,0,-40")] {
        let out = dir.path().join(format!("ref{frame}.png"));
        let frames = format!("{frame}");
        render_ok(
            traj,
            out.to_str().unwrap(),
            &[
                "--frames", &frames, "--eye", eye, "--target", "0, 0, 0", "--up", "0, 1, 0",
                "--size", "120x90",
            ],
        );
        let a = pixels(&dir.path().join(format!("o{frame:02}.png")));
        let b = pixels(&out);
        let d = differing(&a, &b);
        assert!(d < 0.002, "frame {frame}: {d} of the pixels differ");
        // And the turned view really is another picture.
        assert!(differing(&a, &pixels(&dir.path().join("o00.png"))) > 0.05);
    }
}

#[test]
fn one_orbit_turn_over_the_movie_loops_without_repeating_a_frame() {
    let dir = tempfile::tempdir().unwrap();
    let traj = dir.path().join("c.xyz");
    write_cluster(&traj, 4, 0.0);
    let pat = dir.path().join("t%02d.png");
    render_ok(
        traj.to_str().unwrap(),
        pat.to_str().unwrap(),
        &["--orbit-turns", "1", "--size", "96x72"],
    );
    let imgs: Vec<Vec<u8>> = (0..4)
        .map(|k| pixels(&dir.path().join(format!("t{k:02}.png"))))
        .collect();
    for k in 1..4 {
        assert!(
            differing(&imgs[0], &imgs[k]) > 0.02,
            "frame {k} repeats frame 0"
        );
    }
    // 360° over 4 frames: frame 2 is the half turn, which --orbit 180 reaches at its second
    // rendered frame (files are named by trajectory frame; the still cluster gives every run the
    // same automatic camera).
    let pair = dir.path().join("p%02d.png");
    render_ok(
        traj.to_str().unwrap(),
        pair.to_str().unwrap(),
        &["--frames", "1:3", "--orbit", "180", "--size", "96x72"],
    );
    let d = differing(&imgs[2], &pixels(&dir.path().join("p02.png")));
    assert!(d < 0.002, "{d}");
}

#[test]
fn keyframes_pass_through_their_keys_and_errors_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let traj = dir.path().join("c.xyz");
    write_cluster(&traj, 4, 0.0);
    let traj = traj.to_str().unwrap();
    let keys = dir.path().join("keys.csv");
    std::fs::write(
        &keys,
        "frame,ex,ey,ez,tx,ty,tz,ux,uy,uz,fov\n0, 0,0,40, 0,0,0, 0,1,0, 40\n3, 30,10,20, 1,0,0, 0,1,0, 25 # closer\n",
    )
    .unwrap();
    let pat = dir.path().join("k%02d.png");
    render_ok(
        traj,
        pat.to_str().unwrap(),
        &["--keyframes", keys.to_str().unwrap(), "--size", "120x90"],
    );
    for (frame, eye, target, fov) in [(0, "0,0,40", "0,0,0", "40"), (3, "30,10,20", "1,0,0", "25")]
    {
        let out = dir.path().join(format!("ref{frame}.png"));
        let frames = format!("{frame}");
        render_ok(
            traj,
            out.to_str().unwrap(),
            &[
                "--frames", &frames, "--eye", eye, "--target", target, "--up", "0, 1, 0", "--fov",
                fov, "--size", "120x90",
            ],
        );
        assert_eq!(
            pixels(&dir.path().join(format!("k{frame:02}.png"))),
            pixels(&out),
            "key frame {frame}"
        );
    }
    // Between the keys the camera is somewhere else than either key.
    let mid = pixels(&dir.path().join("k01.png"));
    assert!(differing(&mid, &pixels(&dir.path().join("k00.png"))) > 0.01);
    assert!(differing(&mid, &pixels(&dir.path().join("k03.png"))) > 0.01);

    let bad = dir.path().join("bad.txt");
    std::fs::write(&bad, "0 0 0 40 0 0 0\n\n2 1 2 oops 0 0 0\n").unwrap();
    let out = texmap(&[
        "render",
        traj,
        "--keyframes",
        bad.to_str().unwrap(),
        "-o",
        dir.path().join("b.png").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.txt") && err.contains("line 3, column 7"),
        "{err}"
    );
    // --orbit and --keyframes exclude one another: a usage error.
    let out = texmap(&[
        "render",
        traj,
        "--orbit",
        "3",
        "--keyframes",
        keys.to_str().unwrap(),
        "-o",
        "x.png",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn follow_keeps_a_moving_molecule_still_in_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let traj = dir.path().join("drift.xyz");
    write_cluster(&traj, 4, 2.5);
    let traj = traj.to_str().unwrap();
    let still = dir.path().join("s%02d.png");
    render_ok(
        traj,
        still.to_str().unwrap(),
        &["--follow", "all", "--size", "120x90"],
    );
    let drift = dir.path().join("d%02d.png");
    render_ok(traj, drift.to_str().unwrap(), &["--size", "120x90"]);
    let s0 = pixels(&dir.path().join("s00.png"));
    let s3 = pixels(&dir.path().join("s03.png"));
    let d3 = pixels(&dir.path().join("d03.png"));
    assert!(differing(&s0, &s3) < 0.002, "{}", differing(&s0, &s3));
    assert!(differing(&s0, &d3) > 0.05, "{}", differing(&s0, &d3));
    let out = texmap(&[
        "render",
        traj,
        "--follow",
        "name XX",
        "-o",
        dir.path().join("n.png").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("selects none"));
}

#[test]
fn quiet_prints_nothing_on_success() {
    let dir = tempfile::tempdir().unwrap();
    let traj = dir.path().join("c.xyz");
    write_cluster(&traj, 2, 0.0);
    let out = texmap(&[
        "render",
        traj.to_str().unwrap(),
        "--quiet",
        "--size",
        "64x48",
        "-o",
        dir.path().join("q.png").to_str().unwrap(),
    ]);
    ok(&out);
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = texmap(&[
        "render",
        traj.to_str().unwrap(),
        "--size",
        "64x48",
        "-o",
        dir.path().join("q.png").to_str().unwrap(),
    ]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("wrote 2 frame"));
}
