//! Solvent-accessible areas (`texmap_md_io::sasa`) against MDTraj 1.11.1's Shrake–Rupley
//! (tests/data/sasa/gen_sasa.py: probe 1.4 Å, 960 points, its radii) on three wwPDB protein
//! chains and MDAnalysis's solvated peptide with hydrogens, water and sodium ions. The points
//! and radii are the same, so every atom's area must agree to one of its 960 points (MDTraj
//! works in single precision: a point on a neighbour's sphere may fall either way), and the
//! totals to 0.01 %. The peptide's file has two atoms 0.12 Å apart, which bury each other.

use std::path::Path;

use texmap_md_io::sasa::{POINTS, PROBE, radius, sasa};
use texmap_md_io::{Frame, Trajectory};

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn every_atoms_area_is_mdtrajs() {
    let text = std::fs::read_to_string(data("sasa/sasa_reference.json")).unwrap();
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    for (file, name) in [
        ("dssp/1ahsA.pdb.gz", "1ahsA.pdb.gz"),
        ("dssp/2cviA.pdb.gz", "2cviA.pdb.gz"),
        ("dssp/3gwiA.pdb.gz", "3gwiA.pdb.gz"),
        ("select_mda.pdb", "select_mda.pdb"),
    ] {
        let want = &reference[name];
        let mut t = Trajectory::open(data(file)).unwrap();
        let mut frame = Frame::new();
        assert!(t.read_next(&mut frame).unwrap());
        let elements: Vec<&str> = want["elements"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_str().unwrap())
            .collect();
        assert_eq!(frame.n_atoms(), elements.len(), "{name}");
        for (i, e) in elements.iter().enumerate() {
            assert_eq!(
                texmap_md_io::atom_element(&frame, i).symbol(),
                *e,
                "{name} atom {i}"
            );
        }
        let got = sasa(&frame, None, PROBE).unwrap();
        let want_areas: Vec<f64> = want["sasa"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_f64().unwrap())
            .collect();
        let mut worst = (0.0f64, 0usize);
        for (i, (g, w)) in got.iter().zip(&want_areas).enumerate() {
            let r = f64::from(radius(texmap_md_io::atom_element(&frame, i)) + PROBE);
            let point = 4.0 * std::f64::consts::PI * r * r / POINTS as f64;
            let off = (f64::from(*g) - w).abs() / point;
            if off > worst.0 {
                worst = (off, i);
            }
        }
        assert!(
            worst.0 <= 3.01,
            "{name}: atom {} off by {:.1} points",
            worst.1,
            worst.0
        );
        let total: f64 = got.iter().map(|a| f64::from(*a)).sum();
        let want_total = want["total"].as_f64().unwrap();
        assert!(
            (total - want_total).abs() < 1e-4 * want_total,
            "{name}: {total} against MDTraj's {want_total}"
        );
        eprintln!(
            "{name}: total {total:.2} Å² (MDTraj {want_total:.2}), worst atom {:.1} points",
            worst.0
        );
    }
}
