//! Trajectories in several files (`Sequence`, `sequence::expand`) against OVITO 3.17.2 reading
//! its own one-file-per-frame LAMMPS export as a file sequence, and MDAnalysis 2.11's
//! ChainReader reading a run written in two XTC parts (tests/data/sequence/gen_sequence.py).

use std::path::PathBuf;

use texmap_md_io::sequence::expand;
use texmap_md_io::{Error, Frame, ReadOptions, Sequence};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/sequence")
}

fn reference(key: &str) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(dir().join("sequence_read.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json[key].as_array().unwrap().clone()
}

fn assert_positions(frame: &Frame, want: &serde_json::Value, tol: f32, at: &str) {
    let want = want.as_array().unwrap();
    assert_eq!(frame.n_atoms(), want.len(), "{at}");
    for (i, (p, w)) in frame.positions.iter().zip(want).enumerate() {
        for k in 0..3 {
            let w = w[k].as_f64().unwrap() as f32;
            assert!((p[k] - w).abs() <= tol, "{at}, atom {i}: {p:?} vs {w}");
        }
    }
}

#[test]
fn a_wildcard_reads_ovitos_file_sequence_in_natural_order() {
    let pattern = dir().join("ovito/dump.*.lammpstrj");
    let parts = expand(pattern.to_str().unwrap()).unwrap();
    let names: Vec<String> = parts
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    let want: Vec<String> = (0..12).map(|k| format!("dump.{k}.lammpstrj")).collect();
    assert_eq!(names, want, "dump.10 after dump.9, not after dump.1");
    let ovito = reference("ovito");
    let mut seq = Sequence::open(&parts, None, ReadOptions::new()).unwrap();
    assert_eq!(seq.n_frames().unwrap(), ovito.len());
    assert!(seq.name().contains("+11 more files"), "{}", seq.name());
    // Streaming across the twelve files.
    let mut frame = Frame::new();
    let mut k = 0;
    while seq.read_next(&mut frame).unwrap() {
        assert_eq!(frame.step, ovito[k]["timestep"].as_i64(), "frame {k}");
        assert_positions(&frame, &ovito[k]["positions"], 1e-4, &format!("frame {k}"));
        k += 1;
    }
    assert_eq!(k, 12);
    // Random access, out of order, then streaming on from there across a part boundary.
    for n in [7, 0, 11, 3] {
        seq.read_frame(n, &mut frame).unwrap();
        assert_positions(&frame, &ovito[n]["positions"], 1e-4, &format!("frame {n}"));
    }
    seq.read_frame(5, &mut frame).unwrap();
    for want in &ovito[6..9] {
        assert!(seq.read_next(&mut frame).unwrap());
        assert_eq!(
            frame.step,
            want["timestep"].as_i64(),
            "read_next after frame 5"
        );
    }
    assert_eq!(seq.locate(10).unwrap(), Some((10, 0)));
    assert!(matches!(
        seq.read_frame(12, &mut frame),
        Err(Error::FrameOutOfRange {
            requested: 12,
            n_frames: 12,
            ..
        })
    ));
}

#[test]
fn xtc_parts_read_as_mdanalysis_chains_them() {
    let parts = [dir().join("part1.xtc"), dir().join("part2.xtc")];
    let mda = reference("mdanalysis");
    let mut seq = Sequence::open(&parts, None, ReadOptions::new()).unwrap();
    assert_eq!(seq.n_frames().unwrap(), mda.len());
    assert_eq!(seq.locate(6).unwrap(), Some((0, 6)));
    assert_eq!(seq.locate(7).unwrap(), Some((1, 0)));
    let mut frame = Frame::new();
    for (n, want) in mda.iter().enumerate() {
        seq.read_frame(n, &mut frame).unwrap();
        // XTC keeps 1e-3 nm: 0.01 Å.
        assert_positions(&frame, &want["positions"], 6e-3, &format!("frame {n}"));
        let t = frame.time.unwrap();
        assert!(
            (t - want["time"].as_f64().unwrap()).abs() < 1e-3,
            "frame {n}: time {t}"
        );
    }
}

#[test]
fn missing_parts_and_patterns_are_named() {
    let tmp = tempfile::tempdir().unwrap();
    let gone = tmp.path().join("part3.xtc");
    let parts = [dir().join("part1.xtc"), gone.clone()];
    let mut seq = Sequence::open(&parts, None, ReadOptions::new()).unwrap();
    let e = seq.n_frames().unwrap_err().to_string();
    assert!(e.contains("part3.xtc"), "{e}");
    let pattern = tmp.path().join("dump.*.lammpstrj");
    let e = expand(pattern.to_str().unwrap()).unwrap_err().to_string();
    assert!(e.contains("no file matches"), "{e}");
    assert!(Sequence::open(&[], None, ReadOptions::new()).is_err());
    // A path without wildcards is itself, whether it exists or not.
    assert_eq!(expand(gone.to_str().unwrap()).unwrap(), [gone]);
}
