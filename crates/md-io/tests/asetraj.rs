//! ASE trajectories (.traj) read as ASE 3.29 reads them (tests/data/asetraj/gen_asetraj.py):
//! numbers, positions, cells and periodic edges, masses, velocities from momenta, forces,
//! per-atom energies, tags, charges and magnetic moments, frame by frame; and damaged files.

use std::io::Read;
use texmap_md_io::{Format, Frame, Trajectory};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/asetraj")
        .join(name)
}

fn reference() -> serde_json::Value {
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(data("reference.json.gz")).unwrap())
        .read_to_string(&mut text)
        .unwrap();
    serde_json::from_str(&text).unwrap()
}

fn flat(v: &serde_json::Value) -> Vec<f64> {
    match v {
        serde_json::Value::Array(a) => a.iter().flat_map(flat).collect(),
        serde_json::Value::Bool(b) => vec![f64::from(u8::from(*b))],
        x => vec![x.as_f64().unwrap()],
    }
}

fn close(got: &[f64], want: &[f64], tol: f64, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= tol * w.abs().max(1.0),
            "{what}[{k}]: {g} vs ASE {w}"
        );
    }
}

fn prop(f: &Frame, name: &str) -> Vec<f64> {
    f.property(name)
        .unwrap_or_else(|| panic!("no property {name}"))
        .iter()
        .map(|&v| v as f64)
        .collect()
}

#[test]
fn frames_read_as_ase_reads_them() {
    let r = reference();
    for name in ["cu_md.traj", "slab.traj", "mixed.traj"] {
        let mut t = Trajectory::open(data(name)).unwrap();
        assert_eq!(t.format(), Format::AseTraj);
        let want = r[name].as_array().unwrap();
        assert_eq!(t.n_frames().unwrap(), want.len(), "{name}");
        let mut f = Frame::new();
        for (i, w) in want.iter().enumerate() {
            assert!(t.read_next(&mut f).unwrap(), "{name} frame {i}");
            let what = |k: &str| format!("{name} frame {i} {k}");
            let z: Vec<f64> = f.elements.iter().map(|e| e.z() as f64).collect();
            assert_eq!(z, flat(&w["numbers"]), "{}", what("numbers"));
            let pos: Vec<f64> = f.positions.iter().flatten().map(|&v| v as f64).collect();
            close(&pos, &flat(&w["positions"]), 1e-7, &what("positions"));
            let cell = flat(&w["cell"]);
            match f.cell {
                Some(c) => {
                    let m: Vec<f64> = c.matrix().iter().flatten().copied().collect();
                    close(&m, &cell, 1e-12, &what("cell"));
                    let pbc: Vec<f64> = c
                        .periodic()
                        .iter()
                        .map(|&p| f64::from(u8::from(p)))
                        .collect();
                    assert_eq!(pbc, flat(&w["pbc"]), "{}", what("pbc"));
                }
                None => assert!(cell.iter().all(|&v| v == 0.0), "{}", what("cell")),
            }
            let masses: Vec<f64> = (0..f.n_atoms())
                .map(|k| texmap_md_io::atom_mass(&f, k))
                .collect();
            close(&masses, &flat(&w["masses"]), 1e-4, &what("masses"));
            if w.get("velocities").is_some() {
                let v: Vec<f64> = f.velocities.iter().flatten().map(|&v| v as f64).collect();
                close(&v, &flat(&w["velocities"]), 1e-4, &what("velocities"));
            } else {
                assert!(f.velocities.is_empty());
            }
            if let Some(e) = w.get("energy") {
                assert!(
                    f.comment
                        .starts_with(&format!("energy={}", e.as_f64().unwrap())),
                    "{}: {}",
                    what("energy"),
                    f.comment
                );
                let forces: Vec<f64> = (0..f.n_atoms())
                    .flat_map(|k| ["fx", "fy", "fz"].map(|c| prop(&f, c)[k]))
                    .collect();
                close(&forces, &flat(&w["forces"]), 1e-6, &what("forces"));
                close(
                    &prop(&f, "energies"),
                    &flat(&w["energies"]),
                    1e-6,
                    &what("energies"),
                );
            }
            let tags = flat(&w["tags"]);
            if tags.iter().any(|&t| t != 0.0) {
                close(&prop(&f, "tag"), &tags, 0.0, &what("tags"));
            }
            for (key, p) in [("charges", "charge"), ("magmoms", "magmom")] {
                let want = flat(&w[key]);
                if want.iter().any(|&c| c != 0.0) {
                    close(&prop(&f, p), &want, 1e-6, &what(key));
                }
            }
        }
        assert!(!t.read_next(&mut f).unwrap(), "{name}: past the end");
    }
}

#[test]
fn frames_are_reached_in_any_order() {
    let mut t = Trajectory::open(data("mixed.traj")).unwrap();
    let mut f = Frame::new();
    t.read_frame(2, &mut f).unwrap();
    assert_eq!(f.n_atoms(), 3);
    t.read_frame(1, &mut f).unwrap();
    assert_eq!(f.n_atoms(), 5);
    assert!(t.read_frame(3, &mut f).is_err());
}

#[test]
fn damaged_files_are_errors_never_panics() {
    let bytes = std::fs::read(data("cu_md.traj")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.traj");
    let read_all = |b: &[u8]| -> Result<usize, texmap_md_io::Error> {
        std::fs::write(&path, b).unwrap();
        let mut t = Trajectory::open_as(&path, Format::AseTraj)?;
        let mut f = Frame::new();
        let mut n = 0;
        while t.read_next(&mut f)? {
            n += 1;
        }
        Ok(n)
    };
    assert_eq!(read_all(&bytes).unwrap(), 4);
    // Cut anywhere: an error (the table sits at the end), never a panic or a partial frame.
    for cut in (0..bytes.len()).step_by(37) {
        assert!(read_all(&bytes[..cut]).is_err(), "cut at {cut}");
    }
    // Every byte of the header and of the first item's JSON flipped in turn.
    let mut errors = 0;
    for at in (0..48).chain(2880..2990) {
        let mut b = bytes.clone();
        b[at] ^= 0x5a;
        errors += usize::from(read_all(&b).is_err());
    }
    assert!(errors > 40, "{errors}");
    // A count and an array claiming more than the file holds.
    let mut b = bytes.clone();
    b[32..40].copy_from_slice(&(1i64 << 40).to_le_bytes());
    let e = read_all(&b).unwrap_err().to_string();
    assert!(e.contains("item count"), "{e}");
    let needle = b"\"positions.\": {\"ndarray\": [[32, 3],";
    let k = bytes
        .windows(needle.len())
        .position(|w| w == needle)
        .unwrap()
        + needle.len()
        - 9;
    let mut b = bytes.clone();
    b[k..k + 9].copy_from_slice(b"[[99, 3],");
    let e = read_all(&b).unwrap_err().to_string();
    assert!(e.contains("positions"), "{e}");
    // Not an ASE trajectory.
    let e = read_all(b"AFFormat").unwrap_err().to_string();
    assert!(e.contains("48-byte") || e.contains("before ASE"), "{e}");
}
