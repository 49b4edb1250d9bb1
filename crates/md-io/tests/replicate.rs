//! Periodic images (`texmap_md_io::replicate`) against OVITO 3.17's Replicate modifier on 60
//! waters in a triclinic cell with an origin, many of them bonded across a face of the box
//! (tests/data/replicate/, by gen_replicate.py: a LAMMPS data file and dump written by OVITO).
//! Every atom's position, id and molecule id, the cell and the set of bonds must be OVITO's.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use texmap_md_io::pbc::drop_crossing;
use texmap_md_io::replicate::{ReplicateError, replicate};
use texmap_md_io::{Frame, Topology, Trajectory, UnitCell};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/replicate")
        .join(name)
}

/// The water frame, labelled by its data file, and the data file's bonds.
fn water() -> (Frame, Vec<[u32; 2]>) {
    let mut t = Trajectory::open(data("water.lammpstrj")).unwrap();
    let mut frame = Frame::new();
    assert!(t.read_next(&mut frame).unwrap());
    let top = Topology::open(data("water.data")).unwrap();
    top.apply(&mut frame, "water.lammpstrj", 0).unwrap();
    (frame, top.bonds.clone())
}

#[test]
fn copies_atoms_ids_cell_and_bonds_as_ovito_does() {
    let text = std::fs::read_to_string(data("replicate_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let (mut frame, mut bonds) = water();
    // The input holds bonds across the box, which is what makes the bond images worth testing.
    let mut whole = bonds.clone();
    drop_crossing(&mut whole, &frame.positions, frame.cell.as_ref());
    assert!(
        bonds.len() - whole.len() >= 5,
        "{} crossing",
        bonds.len() - whole.len()
    );

    replicate(&mut frame, &mut bonds, [2, 3, 2]).unwrap();
    let want_pos = v["positions"].as_array().unwrap();
    assert_eq!(frame.n_atoms(), want_pos.len());
    assert_eq!(frame.n_atoms(), 180 * 12);
    for (i, (p, w)) in frame.positions.iter().zip(want_pos).enumerate() {
        for k in 0..3 {
            let w = w[k].as_f64().unwrap();
            assert!((p[k] as f64 - w).abs() < 1e-4, "atom {i}: {p:?} vs {w}");
        }
    }
    let ints = |key: &str| -> Vec<i64> {
        v[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_i64().unwrap())
            .collect()
    };
    assert_eq!(frame.ids, ints("ids"));
    assert_eq!(frame.res_ids, ints("molecules"));
    // Every copy keeps its labels.
    assert_eq!(frame.types.len(), frame.n_atoms());
    assert_eq!(frame.types[180..360], frame.types[..180]);

    let cell = frame.cell.unwrap();
    for (k, row) in cell.matrix().iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            let w = v["cell"][k][j].as_f64().unwrap();
            assert!((x - w).abs() < 1e-9, "cell[{k}][{j}] {x} vs {w}");
        }
    }
    for (k, x) in cell.origin().iter().enumerate() {
        assert!((x - v["origin"][k].as_f64().unwrap()).abs() < 1e-9);
    }

    let want: BTreeSet<[u32; 2]> = v["bonds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| [b[0].as_u64().unwrap() as u32, b[1].as_u64().unwrap() as u32])
        .collect();
    let got: BTreeSet<[u32; 2]> = bonds.iter().copied().collect();
    assert_eq!(got.len(), bonds.len(), "bonds listed once each");
    let only_ours: Vec<_> = got.difference(&want).take(8).collect();
    let only_ovitos: Vec<_> = want.difference(&got).take(8).collect();
    assert!(
        only_ours.is_empty() && only_ovitos.is_empty(),
        "bonds only ours {only_ours:?}, only OVITO's {only_ovitos:?}"
    );
    // Inside the block every bond is a whole stick: only those across its outer faces cross
    // the enlarged box, fewer than the original's crossings times the outer copies.
    let mut inner = bonds.clone();
    drop_crossing(&mut inner, &frame.positions, frame.cell.as_ref());
    assert!(
        inner.len() > whole.len() * 12,
        "{} of {}",
        inner.len(),
        bonds.len()
    );
    for &[i, j] in &inner {
        let (a, b) = (frame.positions[i as usize], frame.positions[j as usize]);
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        assert!((d - 0.96).abs() < 1e-3, "bond {i}-{j} is {d} A long");
    }
}

#[test]
fn one_image_changes_nothing_and_bad_requests_change_nothing() {
    let (frame, bonds) = water();
    let (mut f, mut b) = (frame.clone(), bonds.clone());
    replicate(&mut f, &mut b, [1, 1, 1]).unwrap();
    assert_eq!((&f, &b), (&frame, &bonds));

    assert_eq!(
        replicate(&mut f, &mut b, [2, 0, 1]),
        Err(ReplicateError::ZeroCount)
    );
    let err = replicate(&mut f, &mut b, [1000, 1000, 1000]).unwrap_err();
    assert_eq!(
        err,
        ReplicateError::TooLarge {
            atoms: 180_000_000_000
        }
    );
    assert!(err.to_string().contains("180000000000 atoms"), "{err}");
    f.cell = None;
    assert_eq!(
        replicate(&mut f, &mut b, [2, 2, 2]),
        Err(ReplicateError::NoCell)
    );
    f.cell = frame.cell;
    assert_eq!((&f, &b), (&frame, &bonds));
}

#[test]
fn a_three_by_three_block_is_centred_on_the_original() {
    let mut frame = Frame::new();
    frame.positions = vec![[1.0, 2.0, 3.0]];
    frame.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
    let mut bonds = Vec::new();
    replicate(&mut frame, &mut bonds, [3, 1, 3]).unwrap();
    let xs: BTreeSet<i32> = frame.positions.iter().map(|p| p[0] as i32).collect();
    let zs: BTreeSet<i32> = frame.positions.iter().map(|p| p[2] as i32).collect();
    assert_eq!(xs, [-9, 1, 11].into());
    assert_eq!(zs, [-7, 3, 13].into());
    assert_eq!(frame.cell.unwrap().origin(), [-10.0, 0.0, -10.0]);
    assert_eq!(frame.cell.unwrap().lengths(), [30.0, 10.0, 30.0]);
}

/// A frame's own bonds keep their orders in every copy: the water file's bonds given orders
/// by their first atom's parity, replicated 2x3x2, each copy's order is its original's.
#[test]
fn bond_orders_follow_the_copies() {
    let (mut frame, mut bonds) = water();
    frame.bonds = bonds.clone();
    frame.bond_orders = frame.bonds.iter().map(|b| 1 + (b[0] % 2) as u8).collect();
    let atoms = frame.n_atoms() as u32;
    replicate(&mut frame, &mut bonds, [2, 3, 2]).unwrap();
    assert_eq!(frame.check(), Ok(()));
    assert_eq!(frame.bonds.len(), 12 * 120);
    for (b, o) in frame.bonds.iter().zip(&frame.bond_orders) {
        let (i, j) = (b[0] % atoms, b[1] % atoms);
        assert_eq!(*o, 1 + (i.min(j) % 2) as u8, "{b:?}");
    }
}
