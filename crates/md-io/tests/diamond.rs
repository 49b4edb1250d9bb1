//! Diamond structure identification (`texmap_md_io::cna::classify_diamond`) against OVITO
//! 3.17's Identify diamond structure modifier on silicon OVITO wrote (tests/data/diamond,
//! gen_diamond.py): cubic diamond with a vacancy, hexagonal diamond, and a slab with free
//! surfaces, all with thermal noise. Every atom's type must be OVITO's.

use texmap_md_io::cna::{DiamondType, classify_diamond};

use crate::support;
use support::ovito::*;

const DATA: Fixtures = Fixtures("diamond");

#[test]
fn every_atom_is_ovitos_type() {
    let cases = DATA.json("diamond_reference.json");
    for case in cases.as_array().unwrap() {
        let file = case["file"].as_str().unwrap();
        let frame = DATA.frame(file);
        let ours = classify_diamond(&frame);
        let theirs = integers(&case["structure"]);
        assert_eq!(ours.len(), theirs.len(), "{file}");
        let mut counts = [0usize; 7];
        for (i, (o, t)) in ours.iter().zip(&theirs).enumerate() {
            assert_eq!(*o as i64, *t, "{file}: atom {i} is {o:?}, OVITO's type {t}");
            counts[*o as usize] += 1;
        }
        println!("{file}: {counts:?}");
        // Each file shows what it was made for.
        let wanted = match file {
            "cubic.xyz" => [DiamondType::Cubic, DiamondType::CubicFirstNeighbour],
            "hexagonal.xyz" => [DiamondType::Hexagonal, DiamondType::Hexagonal],
            _ => [
                DiamondType::CubicFirstNeighbour,
                DiamondType::CubicSecondNeighbour,
            ],
        };
        assert!(
            wanted.iter().all(|t| counts[*t as usize] > 0),
            "{file}: {counts:?}"
        );
    }
}

#[test]
fn types_do_not_depend_on_the_thread_count() {
    let frame = DATA.frame("slab.xyz");
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    assert_eq!(
        one.install(|| classify_diamond(&frame)),
        two.install(|| classify_diamond(&frame))
    );
}
