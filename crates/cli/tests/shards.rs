//! `texmap render --shard I/N` (and Slurm's job-array variables): the parts together write
//! exactly the frames, byte for byte, that one render writes, and `texmap movie` assembles them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn render(out: &Path, extra: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_texmap"));
    c.args([
        "render",
        &data("topo_mda.xtc"),
        "--topology",
        &data("topo_mda.pdb"),
    ])
    .args(["--size", "80x60", "--style", "ball-stick", "-o"])
    .arg(out.join("f%04d.png"))
    .args(extra)
    .env_remove("SLURM_ARRAY_TASK_ID")
    .env_remove("SLURM_ARRAY_TASK_COUNT")
    .env_remove("SLURM_ARRAY_TASK_MIN");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("texmap runs")
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p: PathBuf = e.unwrap().path();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn parts_write_the_frames_of_one_render_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let parts = dir.path().join("parts");
    let slurm = dir.path().join("slurm");
    for d in [&whole, &parts, &slurm] {
        std::fs::create_dir(d).unwrap();
    }
    let o = render(&whole, &[], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = files(&whole);
    assert!(want.len() >= 3, "{} frames", want.len());
    // Three parts by flag, in any order.
    for i in [2, 0, 1] {
        let o = render(&parts, &["--shard", &format!("{i}/3")], &[]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(files(&parts), want);
    // The same from Slurm's variables (an array 1-3: MIN 1).
    for id in ["1", "2", "3"] {
        let env = [
            ("SLURM_ARRAY_TASK_ID", id),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
        ];
        let o = render(&slurm, &[], &env);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(files(&slurm), want);
    // Bad specifications and a movie output are usage errors.
    for bad in ["3/3", "1", "a/b", "0/0"] {
        let o = render(&parts, &["--shard", bad], &[]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_texmap"))
        .args(["render", &data("topo_mda.xtc"), "--shard", "0/2", "-o"])
        .arg(dir.path().join("m.mp4"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// Squared displacements are followed frame by frame across the cell's faces: a part reads
/// every frame before its own, so `--color-by msd` colours its frames as one render does
/// (random walks wrapped into an 18 Å box, md-io's dynamics fixture).
#[test]
fn parts_follow_squared_displacements_from_the_first_frame() {
    let dir = tempfile::tempdir().unwrap();
    let run = |out: &Path, shard: Option<&str>| {
        std::fs::create_dir_all(out).unwrap();
        let mut c = Command::new(env!("CARGO_BIN_EXE_texmap"));
        c.args([
            "render",
            &data("dynamics/walk.dcd"),
            "--topology",
            &data("dynamics/walk.gro"),
            "--color-by",
            "msd",
            "--color-range",
            "0:60",
            "--frames",
            "0:40:3",
            "--size",
            "80x60",
            "-q",
            "-o",
        ])
        .arg(out.join("f%04d.png"))
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_ARRAY_TASK_COUNT");
        if let Some(s) = shard {
            c.args(["--shard", s]);
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let whole = dir.path().join("whole");
    run(&whole, None);
    let parts = dir.path().join("parts");
    for i in ["0/3", "1/3", "2/3"] {
        run(&parts, Some(i));
    }
    let want = files(&whole);
    assert_eq!(want.len(), 14);
    assert_eq!(files(&parts), want);
}
