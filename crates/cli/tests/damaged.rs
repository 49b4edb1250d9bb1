//! The binary on damaged trajectories (mutants of files MDAnalysis wrote, md-io's tests/data):
//! a cut last frame is an error naming the file, frame and byte unless --allow-truncated, which
//! warns and keeps the complete frames; a header claiming 2^31 atoms is a clean error; a render
//! that fails at frame k says which images of the frames before it are on disk.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use common::texmap;

fn data(name: &str) -> Vec<u8> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(name);
    std::fs::read(p).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// dcd_mda.dcd: 12 atoms, 4 frames of a 56-byte cell record and three 56-byte coordinate
/// records after the header.
const DCD_FRAME: usize = 56 + 3 * 56;

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn info_on_a_cut_dcd_is_an_error_or_with_allow_truncated_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let good = data("dcd_mda.dcd");
    let header = good.len() - 4 * DCD_FRAME;
    let cut = header + 2 * DCD_FRAME + 100;
    let p = write(dir.path(), "cut.dcd", &good[..cut]);
    let path = p.to_str().unwrap();

    let o = texmap(&["info", path]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains(&format!(
            "cut.dcd: frame 2, byte {cut}: file ends inside the frame"
        )),
        "{e}"
    );
    assert!(o.stdout.is_empty());

    let o = texmap(&["info", path, "--allow-truncated"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["frames"], 2);
    let e = stderr(&o);
    assert!(e.contains("warning") && e.contains("frame 2, byte"), "{e}");
}

#[test]
fn info_on_an_xtc_claiming_2_pow_31_atoms_is_a_clean_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = data("xtc_mda.xtc");
    // Both copies of frame 0's atom count (bytes 4 and 52) to 2^31 - 1.
    for at in [4, 52] {
        b[at..at + 4].copy_from_slice(&i32::MAX.to_be_bytes());
    }
    let p = write(dir.path(), "huge.xtc", &b);
    let o = texmap(&["info", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("huge.xtc: frame 0, byte 4: expected an atom count"),
        "{e}"
    );
}

#[test]
fn render_failing_at_frame_1_names_the_images_already_written() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = data("dcd_mda.dcd");
    let header = b.len() - 4 * DCD_FRAME;
    // Frame 1, atom 5, x = 1e38: finite, absurd.
    let x5 = header + DCD_FRAME + 56 + 4 + 4 * 5;
    b[x5..x5 + 4].copy_from_slice(&1e38f32.to_le_bytes());
    let p = write(dir.path(), "bad.dcd", &b);
    let out = dir.path().join("f%04d.png");
    let o = texmap(&[
        "render",
        p.to_str().unwrap(),
        "--frames",
        "0:3",
        "--size",
        "32x24",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    let first = dir.path().join("f0000.png");
    assert!(first.exists(), "{e}");
    assert!(!dir.path().join("f0001.png").exists(), "{e}");
    assert!(
        e.contains("frame 1: stopped after 1 complete image(s)")
            && e.contains(first.to_str().unwrap()),
        "{e}"
    );
    assert!(
        e.contains(&format!("bad.dcd: frame 1, byte {x5}")) && e.contains("atom 5"),
        "{e}"
    );
    // The image on disk is a whole PNG of the asked size.
    let img = image::open(&first).unwrap();
    assert_eq!((img.width(), img.height()), (32, 24));
}

/// A gzip trajectory whose stream ends early (GNU gzip's copy of a LAMMPS dump, cut in the
/// second frame's compressed data): an error naming the file, "gzip" and the compressed
/// offset; with --allow-truncated, two warnings (the gzip cut, the cut frame) and the complete
/// frames rendered.
#[test]
fn a_cut_gz_renders_its_complete_frames_with_allow_truncated() {
    let dir = tempfile::tempdir().unwrap();
    let gz = data("lmp_tri.lammpstrj.gz");
    let p = write(dir.path(), "cut.lammpstrj.gz", &gz[..gz.len() * 2 / 3]);
    let path = p.to_str().unwrap();
    let o = texmap(&["info", path]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(path) && stderr(&o).contains("gzip"),
        "{}",
        stderr(&o)
    );
    let out = dir.path().join("f-%d.png");
    let o = texmap(&[
        "render",
        path,
        "--quiet",
        "--allow-truncated",
        "--size",
        "64x48",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let warnings = stderr(&o);
    assert!(warnings.contains("gzip stream"), "{warnings}");
    assert!(
        warnings.contains("file ends inside the frame"),
        "{warnings}"
    );
    let written = (0..3)
        .filter(|f| dir.path().join(format!("f-{f}.png")).exists())
        .count();
    assert!((1..3).contains(&written), "{written} frames written");
}
