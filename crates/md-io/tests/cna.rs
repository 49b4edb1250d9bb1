//! Adaptive common neighbour analysis (`texmap_md_io::cna`) against OVITO 3.17's Common
//! Neighbor Analysis modifier (adaptive mode) on five systems written by ASE
//! (tests/data/cna/, by gen_cna.py): jiggled FCC with a vacancy cluster, BCC, HCP in a
//! triclinic cell, FCC with a stacking fault and free surfaces, an icosahedral cluster
//! without a cell. Every atom's type must be OVITO's.

use std::path::Path;

use texmap_md_io::cna::{StructureType, classify, counts};
use texmap_md_io::{Frame, Trajectory};

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/cna")
        .join(name)
}

#[test]
fn every_atom_has_ovitos_structure_type() {
    let text = std::fs::read_to_string(data("cna_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 5);
    let mut t = Trajectory::open(data("crystals.xyz.gz")).unwrap();
    let mut frame = Frame::new();
    let mut seen = [0usize; 5];
    for (k, want) in frames.iter().enumerate() {
        assert!(t.read_next(&mut frame).unwrap(), "frame {k}");
        assert_eq!(frame.n_atoms() as u64, want["atoms"].as_u64().unwrap());
        assert_eq!(
            frame.cell.is_some(),
            want["pbc"].as_bool().unwrap(),
            "frame {k}"
        );
        let got = classify(&frame);
        let codes: Vec<u8> = want["types"]
            .as_str()
            .unwrap()
            .bytes()
            .map(|b| b - b'0')
            .collect();
        let wrong: Vec<(usize, u8, u8)> = got
            .iter()
            .zip(&codes)
            .enumerate()
            .filter(|(_, (g, w))| **g as u8 != **w)
            .map(|(i, (g, w))| (i, *g as u8, *w))
            .take(10)
            .collect();
        assert!(
            wrong.is_empty(),
            "frame {k}: (atom, ours, OVITO's) {wrong:?}"
        );
        let c = counts(&got);
        for (s, n) in seen.iter_mut().zip(c) {
            *s += n;
        }
    }
    // Every type occurs, and the defects (vacancy, fault, surfaces) give plenty of "other".
    assert!(seen.iter().all(|&n| n > 0), "{seen:?}");
    assert!(seen[StructureType::Other as usize] > 100, "{seen:?}");
}

#[test]
fn names_round_trip_and_codes_are_ovitos() {
    for (code, t) in StructureType::ALL.into_iter().enumerate() {
        assert_eq!(t as usize, code);
        assert_eq!(StructureType::from_name(&t.name().to_uppercase()), Some(t));
    }
    assert_eq!(StructureType::from_name("diamond"), None);
}

#[test]
fn the_cna_keyword_selects_ovitos_types() {
    use texmap_md_io::Selection;
    let text = std::fs::read_to_string(data("cna_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut t = Trajectory::open(data("crystals.xyz.gz")).unwrap();
    let mut frame = Frame::new();
    // Frame 3: FCC with a stacking fault (HCP layers) and free surfaces (other).
    for _ in 0..4 {
        assert!(t.read_next(&mut frame).unwrap());
    }
    let codes: Vec<u8> = v["frames"][3]["types"]
        .as_str()
        .unwrap()
        .bytes()
        .map(|b| b - b'0')
        .collect();
    for (sel, want) in [
        ("cna fcc", vec![1u8]),
        ("not cna fcc", vec![0, 2, 3, 4]),
        ("cna HCP other", vec![0, 2]),
        ("cna bcc", vec![3]),
    ] {
        let got = Selection::parse(sel).unwrap().evaluate(&frame).unwrap();
        for (i, (g, c)) in got.iter().zip(&codes).enumerate() {
            assert_eq!(*g, want.contains(c), "{sel}: atom {i} of type {c}");
        }
    }
    let e = Selection::parse("cna diamond").unwrap_err();
    assert!(e.to_string().contains("diamond"), "{e}");
}

#[test]
fn a_flat_sheet_and_a_far_atom_without_a_cell_are_other() {
    // A hexagonal monolayer (6 neighbours each: no 3D crystal) 300 Å wide, and one atom
    // 10 km away: the grid sizes itself to the sheet, not to the empty bounding box.
    let mut frame = Frame::new();
    let a = 2.5f32;
    for j in 0..120 {
        for i in 0..120 {
            let x = (i as f32 + 0.5 * (j % 2) as f32) * a;
            frame.positions.push([x, j as f32 * a * 0.866, 0.0]);
        }
    }
    frame.positions.push([1.0e4, 1.0e4, 1.0e4]);
    frame.positions.push([f32::NAN, 0.0, 0.0]);
    let types = classify(&frame);
    assert_eq!(types.len(), frame.n_atoms());
    assert!(types.iter().all(|t| *t == StructureType::Other));
}
