//! The frames of one movie rendered as a real Slurm job array (examples/slurm/render.sbatch on
//! the single-node cluster of examples/slurm/local-cluster.sh, which .ci/run starts) are byte for
//! byte the frames of one render, and `texmap movie` assembles them. Where Slurm is not installed
//! or no node is up, the test says SKIPPED and why.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn data(name: &str) -> String {
    repo()
        .join("crates/md-io/tests/data")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn slurm_up() -> Result<(), String> {
    let sinfo = Command::new("sinfo").args(["-h", "-o", "%t"]).output();
    let Ok(out) = sinfo else {
        return Err("Slurm is not installed (Debian: apt-get install slurm-wlm munge)".into());
    };
    let states = String::from_utf8_lossy(&out.stdout);
    if out.status.success() && (states.contains("idle") || states.contains("mix")) {
        Ok(())
    } else {
        Err(format!(
            "Slurm is installed but no node is up (run examples/slurm/local-cluster.sh as root): {}{}",
            states.trim(),
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
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
fn a_slurm_job_array_renders_the_frames_of_one_render() {
    if let Err(why) = slurm_up() {
        eprintln!("SKIPPED the Slurm job-array test: {why}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_texmap"))
        .parent()
        .unwrap()
        .to_path_buf();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let (traj, top) = (data("topo_mda.xtc"), data("topo_mda.pdb"));
    let start = Instant::now();
    let out = Command::new("sbatch")
        .args(["--wait", "--array=0-2", "--chdir"])
        .arg(dir.path())
        .arg(repo().join("examples/slurm/render.sbatch"))
        .args([&traj, &top])
        .arg(&frames)
        .env("PATH", &path)
        .output()
        .expect("sbatch runs");
    assert!(
        out.status.success(),
        "sbatch: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(start.elapsed() < Duration::from_secs(600));
    // The same frames from one process, with the script's options.
    let whole = dir.path().join("whole");
    std::fs::create_dir(&whole).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_texmap"))
        .args(["--threads", "2", "render", &traj, "--topology", &top])
        .args([
            "--select",
            "not resname SOL",
            "--style",
            "ball-stick",
            "--size",
            "1920x1080",
            "-o",
        ])
        .arg(whole.join("f%05d.png"))
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_ARRAY_TASK_COUNT")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (got, want) = (files(&frames), files(&whole));
    assert!(want.len() >= 3);
    assert_eq!(got.len(), want.len(), "frames from the array");
    for ((n1, b1), (n2, b2)) in got.iter().zip(&want) {
        assert_eq!(n1, n2);
        assert!(b1 == b2, "{n1} differs from the one-process render");
    }
    // The last step: one movie from the parts' frames.
    let movie = dir.path().join("movie.apng");
    let o = Command::new(env!("CARGO_BIN_EXE_texmap"))
        .arg("movie")
        .arg(&frames)
        .arg("-o")
        .arg(&movie)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(movie.exists());
}
