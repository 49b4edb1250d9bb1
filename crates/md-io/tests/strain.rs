//! Atomic strain (`texmap_md_io::strain`) and the centrosymmetry parameter
//! (`texmap_md_io::centrosymmetry`) against OVITO 3.17's Atomic strain and Centrosymmetry
//! modifiers on a copper slab OVITO wrote (tests/data/strain, gen_strain.py): a noisy FCC crystal
//! with two free surfaces and five atoms alone or paired in the vacuum, then sheared, locally
//! bulged and wrapped back into its sheared cell (atoms cross the periodic faces between the two
//! files). Every atom's values must be OVITO's within the precision of f32 coordinates.

use texmap_md_io::centrosymmetry::{CspMode, centrosymmetry};
use texmap_md_io::strain::atomic_strain;

use crate::support;
use support::ovito::*;

const DATA: Fixtures = Fixtures("strain");

/// The largest difference between ours and theirs, and where.
fn worst(ours: &[f32], theirs: &[f64]) -> (f64, usize) {
    assert_eq!(ours.len(), theirs.len());
    ours.iter()
        .zip(theirs)
        .enumerate()
        .map(|(i, (&a, &b))| ((a as f64 - b).abs(), i))
        .fold((0.0, 0), |m, x| if x.0 > m.0 { x } else { m })
}

#[test]
fn strain_is_ovitos_atom_for_atom() {
    let want = DATA.json("strain_reference.json");
    let (reference, current) = (DATA.frame("ref.xyz"), DATA.frame("cur.xyz"));
    let cutoff = want["cutoff"].as_f64().unwrap() as f32;
    let s = atomic_strain(&reference, &current, cutoff).unwrap();
    let invalid: Vec<bool> = want["invalid"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_bool().unwrap())
        .collect();
    assert_eq!(s.invalid, invalid);
    assert_eq!(
        s.invalid.iter().filter(|v| **v).count() as u64,
        want["invalid_count"].as_u64().unwrap()
    );
    let shear = numbers(&want["shear"]);
    let volumetric = numbers(&want["volumetric"]);
    let d2min = numbers(&want["d2min"]);
    let (e_shear, at_shear) = worst(&s.shear, &shear);
    let (e_vol, at_vol) = worst(&s.volumetric, &volumetric);
    let (e_d2, at_d2) = worst(&s.d2min, &d2min);
    println!(
        "shear max {:.4} (worst difference {e_shear:.2e} at atom {at_shear}), volumetric worst \
         {e_vol:.2e} at {at_vol}, D2min max {:.4} (worst {e_d2:.2e} at {at_d2})",
        shear.iter().cloned().fold(0.0, f64::max),
        d2min.iter().cloned().fold(0.0, f64::max)
    );
    // Coordinates read as f32 (~2e-6 Å at 30 Å) against OVITO's f64: strains of a few
    // percent agree to ~1e-6.
    assert!(e_shear < 5e-6, "shear strain of atom {at_shear}");
    assert!(e_vol < 5e-6, "volumetric strain of atom {at_vol}");
    assert!(e_d2 < 3e-5, "D2min of atom {at_d2}");
    // The bump is there: strains well above the uniform shear's 0.03 near it.
    assert!(shear.iter().cloned().fold(0.0, f64::max) > 0.05);
}

#[test]
fn strain_refuses_other_atoms_and_a_bad_cutoff() {
    let (reference, mut current) = (DATA.frame("ref.xyz"), DATA.frame("cur.xyz"));
    assert!(atomic_strain(&reference, &reference, 0.2).is_err());
    current.positions.pop();
    let e = atomic_strain(&reference, &current, 3.0).unwrap_err();
    assert!(
        e.to_string().contains("1541 atoms and this frame 1540"),
        "{e}"
    );
}

#[test]
fn centrosymmetry_is_ovitos_in_both_modes() {
    let cases = DATA.json("centro_reference.json");
    for case in cases.as_array().unwrap() {
        let file = case["file"].as_str().unwrap();
        let n = case["neighbours"].as_u64().unwrap() as usize;
        let mode = match case["mode"].as_str().unwrap() {
            "matching" => CspMode::Matching,
            _ => CspMode::Conventional,
        };
        let want = numbers(&case["csp"]);
        let csp = centrosymmetry(&DATA.frame(file), n, mode).unwrap();
        let (e, at) = worst(&csp, &want);
        let rel = e / want[at].abs().max(1.0);
        println!("{file}, {n} neighbours, {mode:?}: worst {e:.2e} Å² at atom {at}");
        assert!(
            rel < 1e-5,
            "{file} {n} {mode:?}: atom {at}: {} vs {}",
            csp[at],
            want[at]
        );
    }
}

#[test]
fn the_matching_never_sums_more_than_the_conventional_pairs_allow() {
    // The conventional sum takes the N/2 smallest weights with no constraint: it is a lower
    // bound of any pairing, so of the matching.
    let frame = DATA.frame("cur.xyz");
    let c = centrosymmetry(&frame, 12, CspMode::Conventional).unwrap();
    let m = centrosymmetry(&frame, 12, CspMode::Matching).unwrap();
    assert!(c.iter().zip(&m).all(|(c, m)| *c <= m * (1.0 + 1e-6) + 1e-9));
    // They differ where neighbours share the best pairs (surfaces), and agree in the bulk.
    let equal = c
        .iter()
        .zip(&m)
        .filter(|(c, m)| (*c - *m).abs() < 1e-6)
        .count();
    assert!(equal > frame.n_atoms() / 2 && equal < frame.n_atoms());
}

#[test]
fn centrosymmetry_refuses_odd_and_oversized_counts() {
    let frame = DATA.frame("ref.xyz");
    for n in [0, 7, 34] {
        assert!(centrosymmetry(&frame, n, CspMode::Conventional).is_err());
    }
    let e = centrosymmetry(&frame, 18, CspMode::Matching).unwrap_err();
    assert!(e.to_string().contains("at most 16"), "{e}");
    assert!(centrosymmetry(&frame, 18, CspMode::Conventional).is_ok());
}
