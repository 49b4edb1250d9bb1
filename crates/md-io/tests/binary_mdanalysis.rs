//! DCD, XTC and TRR files written by another program (MDAnalysis 2.11.0, see
//! tests/data/binary_generate.py), read with the public API and compared with the values
//! MDAnalysis itself reports (tests/data/binary_expected.json).

use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Format, Frame, Trajectory, UnitCell, Writer};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn expected() -> Value {
    let text = std::fs::read_to_string(data("binary_expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn close(what: &str, actual: f64, expected: f64, tol: f64) {
    assert!(
        (actual - expected).abs() <= tol,
        "{what}: expected {expected}, actual {actual}, tolerance {tol}"
    );
}

/// Compares every frame of `file` with MDAnalysis's report.
///
/// Positions: MDAnalysis computes nm → Å with the same f32 operations, so they must agree
/// exactly (DCD: no conversion at all). Cells: MDAnalysis reports f32 lengths and angles
/// computed from the f32 box; we compute in f64, so 1e-4 Å / 1e-3 degrees.
fn compare(file: &str, with_time: bool) {
    let all = expected();
    let want = &all[file];
    let mut traj = Trajectory::open(data(file)).unwrap();
    let n = want["n_frames"].as_u64().unwrap() as usize;
    assert_eq!(traj.n_frames().unwrap(), n, "{file}: frame count");
    let mut frame = Frame::new();
    let mut k = 0;
    while traj.read_next(&mut frame).unwrap() {
        let w = &want["frames"][k];
        let pos = w["positions"].as_array().unwrap();
        assert_eq!(frame.n_atoms(), pos.len(), "{file} frame {k}");
        for (i, (a, e)) in frame.positions.iter().zip(pos).enumerate() {
            for d in 0..3 {
                // The JSON holds f32 values printed in full; serde_json's parse may be 1 ulp off
                // in f64, which rounding back to f32 removes.
                let e = e[d].as_f64().unwrap() as f32;
                assert_eq!(
                    a[d].to_bits(),
                    e.to_bits(),
                    "{file} frame {k} atom {i} axis {d}: expected {e}, actual {} (exact)",
                    a[d]
                );
            }
        }
        let dims: Vec<f64> = w["dimensions"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let cell = frame.cell.expect("a cell");
        for d in 0..3 {
            close(
                &format!("{file} frame {k} length {d}"),
                cell.lengths()[d],
                dims[d],
                1e-4,
            );
            close(
                &format!("{file} frame {k} angle {d}"),
                cell.angles()[d],
                dims[3 + d],
                1e-3,
            );
        }
        if with_time {
            close(
                &format!("{file} frame {k} time"),
                frame.time.unwrap(),
                w["time"].as_f64().unwrap(),
                1e-5,
            );
            assert_eq!(frame.step, w["step"].as_i64(), "{file} frame {k} step");
        }
        if let Some(v) = w.get("velocities") {
            match v.as_array() {
                None => assert!(
                    frame.velocities.is_empty(),
                    "{file} frame {k}: no velocities"
                ),
                Some(v) => {
                    for (a, e) in frame.velocities.iter().zip(v) {
                        for d in 0..3 {
                            let e = e[d].as_f64().unwrap() as f32;
                            assert_eq!(a[d], e, "{file} frame {k} velocity (exact)");
                        }
                    }
                }
            }
        }
        k += 1;
    }
    assert_eq!(k, n, "{file}: frames streamed");
}

#[test]
fn dcd_written_by_mdanalysis() {
    compare("dcd_mda.dcd", false);
}

#[test]
fn xtc_written_by_mdanalysis() {
    compare("xtc_mda.xtc", true);
}

#[test]
fn trr_written_by_mdanalysis_with_blocks_missing_per_frame() {
    compare("trr_mda.trr", true);
}

#[test]
fn random_access_matches_streaming() {
    for file in ["dcd_mda.dcd", "xtc_mda.xtc", "trr_mda.trr"] {
        let mut traj = Trajectory::open(data(file)).unwrap();
        let mut streamed = Vec::new();
        let mut f = Frame::new();
        while traj.read_next(&mut f).unwrap() {
            streamed.push(f.clone());
        }
        for k in (0..streamed.len()).rev() {
            traj.read_frame(k, &mut f).unwrap();
            assert_eq!(f, streamed[k], "{file} frame {k}");
        }
        assert!(traj.read_frame(streamed.len(), &mut f).is_err());
    }
}

#[test]
fn dcd_and_xtc_writers_round_trip_through_the_public_api() {
    let dir = tempfile::tempdir().unwrap();
    let mut src = Trajectory::open(data("xtc_mda.xtc")).unwrap();
    let mut frames = Vec::new();
    let mut f = Frame::new();
    while src.read_next(&mut f).unwrap() {
        frames.push(f.clone());
    }
    for (format, tol) in [(Format::Dcd, 0.0f32), (Format::Xtc, 0.0051)] {
        let path = dir.path().join(format!("out.{}", format.name()));
        let mut w = Writer::create(&path, format).unwrap();
        for f in &frames {
            w.write_frame(f).unwrap();
        }
        w.finish().unwrap();
        let mut back = Trajectory::open(&path).unwrap();
        assert_eq!(back.n_frames().unwrap(), frames.len());
        for (k, want) in frames.iter().enumerate() {
            back.read_frame(k, &mut f).unwrap();
            for (a, e) in f.positions.iter().zip(&want.positions) {
                for d in 0..3 {
                    assert!(
                        (a[d] - e[d]).abs() <= tol,
                        "{format:?} frame {k}: expected {}, actual {}, tolerance {tol}",
                        e[d],
                        a[d]
                    );
                }
            }
            let (a, e): (UnitCell, UnitCell) = (f.cell.unwrap(), want.cell.unwrap());
            for d in 0..3 {
                close("length", a.lengths()[d], e.lengths()[d], 1e-4);
                close("angle", a.angles()[d], e.angles()[d], 1e-4);
            }
            close("time", f.time.unwrap(), want.time.unwrap(), 1e-4);
        }
    }
}
