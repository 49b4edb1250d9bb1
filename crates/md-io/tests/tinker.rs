//! Tinker coordinates: Open Babel's `.txyz` molecules (one named `.xyz`, as Tinker names its
//! files) and a periodic `.arc` in Tinker's layout, compared with MDAnalysis's reading
//! (tests/data/tinker/gen_tinker.py, reference.json); a plain XYZ stays XYZ.

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Format, Frame, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn texts(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect()
}

/// Names, types, bonds, positions and boxes of every frame, as MDAnalysis reads them; the
/// `.xyz` copy is told from XYZ by its content.
#[test]
fn frames_as_mdanalysis_reads_them() {
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(path("tinker/reference.json")).unwrap())
            .unwrap();
    for name in ["caffeine.txyz", "ethanol.xyz", "water_box.arc"] {
        let want = &r[name];
        let mut t = Trajectory::open(path(&format!("tinker/{name}"))).unwrap();
        assert_eq!(t.format(), Format::Tinker, "{name}");
        let frames = want["positions"].as_array().unwrap();
        assert_eq!(t.n_frames().unwrap(), frames.len(), "{name}");
        let bonds: Vec<[u32; 2]> = want["bonds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| [b[0].as_u64().unwrap() as u32, b[1].as_u64().unwrap() as u32])
            .collect();
        let mut f = Frame::new();
        for (k, pos) in frames.iter().enumerate().rev() {
            t.read_frame(k, &mut f).unwrap();
            let names: Vec<String> = f.names.iter().map(|l| l.as_str().to_string()).collect();
            let types: Vec<String> = f.types.iter().map(|l| l.as_str().to_string()).collect();
            assert_eq!(names, texts(&want["names"]), "{name}");
            assert_eq!(types, texts(&want["types"]), "{name}");
            assert_eq!(f.bonds, bonds, "{name} frame {k}");
            assert!(f.bond_orders.is_empty());
            for (i, p) in pos.as_array().unwrap().iter().enumerate() {
                let p: Vec<f32> = (0..3).map(|c| p[c].as_f64().unwrap() as f32).collect();
                assert_eq!(&f.positions[i][..], &p[..], "{name} frame {k} atom {i}");
            }
            match want["boxes"][k].as_array() {
                None => assert!(f.cell.is_none(), "{name}"),
                Some(b) => {
                    let c = f.cell.unwrap();
                    for j in 0..3 {
                        assert!((c.lengths()[j] - b[j].as_f64().unwrap()).abs() < 1e-5); // MDAnalysis: f32
                        assert!((c.angles()[j] - b[3 + j].as_f64().unwrap()).abs() < 1e-9);
                    }
                }
            }
        }
    }
}

/// A plain XYZ file (ASE's) is still XYZ; Tinker's layout is recognised from its first bytes
/// whatever the name.
#[test]
fn layout_tells_tinker_from_xyz() {
    let plain = std::fs::read(path("ase_plain.xyz")).unwrap();
    assert!(!Format::tinker_xyz(&plain));
    assert_eq!(
        Trajectory::open(path("ase_plain.xyz")).unwrap().format(),
        Format::Xyz
    );
    for name in ["caffeine.txyz", "water_box.arc"] {
        let bytes = std::fs::read(path(&format!("tinker/{name}"))).unwrap();
        assert!(Format::tinker_xyz(&bytes), "{name}");
    }
}

/// A bonded index beyond the atoms, and a frame cut short, are errors naming line and frame.
#[test]
fn damage_is_located() {
    let text = std::fs::read_to_string(path("tinker/caffeine.txyz")).unwrap();
    let bad = text.replacen("     2    15    16    17", "     2    15    16    99", 1);
    assert_ne!(bad, text);
    let mut t = Trajectory::from_reader(Cursor::new(bad), Format::Tinker, "c.txyz").unwrap();
    let e = t.read_next(&mut Frame::new()).unwrap_err().to_string();
    assert!(e.starts_with("c.txyz: frame 0, line 2"), "{e}");
    assert!(e.contains("atom 1 bonded to 99"), "{e}");
    let cut: String = text.lines().take(10).map(|l| format!("{l}\n")).collect();
    let mut t = Trajectory::from_reader(Cursor::new(cut), Format::Tinker, "c.txyz").unwrap();
    let e = t.n_frames().unwrap_err().to_string();
    assert!(e.contains("15 more atom lines"), "{e}");
}
