//! DL_POLY CONFIGs written by ASE 3.29 and a DL_POLY 4 HISTORY (tests/data/dlpoly/
//! gen_dlpoly.py), compared with MDAnalysis's and ASE's readings.

use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Format, Frame, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/dlpoly")
        .join(name)
}

fn vectors(v: &Value) -> Vec<[f32; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| std::array::from_fn(|c| p[c].as_f64().unwrap() as f32))
        .collect()
}

/// Positions, velocities, forces, cells, names and ids of every frame as MDAnalysis reads them
/// (atoms in index order, though the HISTORY's frame 1 lists them backwards), positions and
/// cell vectors as ASE reads them, and each HISTORY frame's step and time.
#[test]
fn frames_as_mdanalysis_and_ase_read_them() {
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(path("reference.json")).unwrap()).unwrap();
    for name in ["CONFIG", "CONFIG_molecule", "HISTORY"] {
        let want = &r[name];
        let mut t = Trajectory::open(path(name)).unwrap();
        assert_eq!(t.format(), Format::DlPoly, "{name}");
        let frames = want["frames"].as_array().unwrap();
        assert_eq!(t.n_frames().unwrap(), frames.len(), "{name}");
        let mut f = Frame::new();
        for (k, w) in frames.iter().enumerate() {
            t.read_frame(k, &mut f).unwrap();
            let names: Vec<&str> = f.names.iter().map(|l| l.as_str()).collect();
            let want_names: Vec<&str> = want["names"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_str().unwrap())
                .collect();
            assert_eq!(names, want_names, "{name}");
            let ids: Vec<i64> = (1..=f.n_atoms() as i64).collect();
            assert_eq!(f.ids, ids, "{name} frame {k}: index order");
            assert_eq!(f.positions, vectors(&w["positions"]), "{name} frame {k}");
            // ASE keeps the file's order: HISTORY's frame 1 lists its atoms backwards.
            let mut ase = vectors(&want["ase_positions"][k]);
            if name == "HISTORY" && k == 1 {
                ase.reverse();
            }
            assert_eq!(f.positions, ase, "{name} frame {k}");
            match w["velocities"].as_array() {
                Some(_) => assert_eq!(f.velocities, vectors(&w["velocities"]), "{name} {k}"),
                None => assert!(f.velocities.is_empty(), "{name}"),
            }
            match w["forces"].as_array() {
                Some(forces) => {
                    for (c, key) in ["fx", "fy", "fz"].iter().enumerate() {
                        let got = f.property(key).unwrap();
                        for (i, fw) in forces.iter().enumerate() {
                            assert_eq!(got[i], fw[c].as_f64().unwrap() as f32, "{name} {k} {i}");
                        }
                    }
                }
                None => assert!(f.property("fx").is_none(), "{name}"),
            }
            match w["box"].as_array() {
                None => assert!(f.cell.is_none(), "{name}"),
                Some(_) => {
                    let m = f.cell.unwrap().matrix();
                    let a = &want["ase_cells"][k];
                    for (i, row) in m.iter().enumerate() {
                        for (j, x) in row.iter().enumerate() {
                            assert!((x - a[i][j].as_f64().unwrap()).abs() < 1e-9, "{name} {k}");
                        }
                    }
                }
            }
            if name == "HISTORY" {
                assert_eq!(f.step, Some(100 * (k as i64 + 1)));
                assert!((f.time.unwrap() - 0.1 * (k as f64 + 1.0)).abs() < 1e-9);
                assert_eq!(f.property("charge").unwrap()[0], 1.0);
                assert_eq!(f.property("mass").unwrap()[1], 35.453);
            }
        }
    }
}

/// A HISTORY cut inside a frame names the frame and what is missing; a CONFIG followed by text
/// that is no frame is an error, not a silent second frame.
#[test]
fn damage_is_located() {
    let text = std::fs::read_to_string(path("HISTORY")).unwrap();
    let cut: String = text
        .lines()
        .take(2 + 4 + 4 * 24 + 10)
        .map(|l| format!("{l}\n"))
        .collect();
    let mut t =
        Trajectory::from_reader(std::io::Cursor::new(cut), Format::DlPoly, "HISTORY").unwrap();
    let e = t.n_frames().unwrap_err().to_string();
    assert!(e.starts_with("HISTORY: frame 1"), "{e}");
    let config = std::fs::read_to_string(path("CONFIG_molecule")).unwrap() + "\nnot a frame\n";
    let mut t =
        Trajectory::from_reader(std::io::Cursor::new(config), Format::DlPoly, "CONFIG").unwrap();
    let e = t.n_frames().unwrap_err().to_string();
    assert!(e.contains("'timestep'"), "{e}");
}
