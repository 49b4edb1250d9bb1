//! Bonds by distance against ASE 3.29.0's neighbour list with the same rule (covalent radii of
//! Cordero 2008 + 0.45 Å), periodic (minimum image) and open (tests/data/gen_bonds.py).

use std::collections::BTreeSet;

use serde_json::Value;
use texmap_md_io::bonds::{BOND_TOLERANCE, bonds_with_radii};
use texmap_md_io::{Element, UnitCell};

fn reference() -> Value {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bonds_ase.json");
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn pairs(v: &Value) -> BTreeSet<[u32; 2]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| [p[0].as_u64().unwrap() as u32, p[1].as_u64().unwrap() as u32])
        .collect()
}

#[test]
fn same_bonds_as_ase_periodic_and_open() {
    let r = reference();
    let pos: Vec<[f32; 3]> = r["positions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| std::array::from_fn(|k| p[k].as_f64().unwrap() as f32))
        .collect();
    let radii: Vec<f32> = r["symbols"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            Element::from_symbol(s.as_str().unwrap())
                .unwrap()
                .covalent_radius()
        })
        .collect();
    let cp: Vec<f64> = r["cellpar"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let cell = UnitCell::from_lengths_angles([cp[0], cp[1], cp[2]], [cp[3], cp[4], cp[5]]).unwrap();
    let m = cell.matrix();
    let inv_frac = |p: [f32; 3]| -> [f64; 3] {
        // Solve f · M = p for the upper-triangular-by-rows M of the usual orientation.
        let z = p[2] as f64 / m[2][2];
        let y = (p[1] as f64 - z * m[2][1]) / m[1][1];
        let x = (p[0] as f64 - z * m[2][0] - y * m[1][0]) / m[0][0];
        [x, y, z]
    };
    for (key, periodic) in [("periodic", true), ("open", false)] {
        let want = pairs(&r[key]);
        let got_v = bonds_with_radii(&pos, &radii, periodic.then_some(cell));
        assert_eq!(got_v.periodic, periodic);
        let got: BTreeSet<[u32; 2]> = got_v.pairs.iter().copied().collect();
        assert_eq!(got.len(), got_v.pairs.len(), "each bond once");
        assert!(got_v.pairs.windows(2).all(|w| w[0] < w[1]), "sorted");
        // Pairs on which the two disagree may only be within f32 rounding of the threshold.
        for p in want.symmetric_difference(&got) {
            let (i, j) = (p[0] as usize, p[1] as usize);
            let d = if periodic {
                let (a, b) = (inv_frac(pos[i]), inv_frac(pos[j]));
                let f: [f64; 3] = std::array::from_fn(|k| {
                    let x = b[k] - a[k];
                    x - x.round()
                });
                let v: [f64; 3] = std::array::from_fn(|k| (0..3).map(|r| f[r] * m[r][k]).sum());
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
            } else {
                (0..3)
                    .map(|k| (pos[i][k] as f64 - pos[j][k] as f64).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            let lim = (radii[i] + radii[j] + BOND_TOLERANCE) as f64;
            assert!(
                (d - lim).abs() < 1e-4 || (d - 0.4).abs() < 1e-4,
                "{key} {p:?}: d {d} limit {lim}"
            );
        }
        assert!(want.len() > 1000);
        let same = want.intersection(&got).count();
        assert!(same + 2 >= want.len(), "{key}: {same} of {}", want.len());
    }
}

#[test]
fn the_same_bonds_for_one_and_two_threads() {
    let r = reference();
    let pos: Vec<[f32; 3]> = r["positions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| std::array::from_fn(|k| p[k].as_f64().unwrap() as f32))
        .collect();
    let radii = vec![0.76f32; pos.len()];
    let run = |t: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
            .install(|| bonds_with_radii(&pos, &radii, None))
    };
    assert_eq!(run(1), run(2));
}
