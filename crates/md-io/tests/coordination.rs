//! Coordination numbers (`texmap_md_io::coordination`) against OVITO 3.17's Coordination
//! analysis modifier on the five crystals of the CNA fixture (tests/data/cna/, written by ASE;
//! reference by gen_coordination.py): jiggled FCC with a vacancy cluster, BCC, HCP in a
//! triclinic cell, FCC with a stacking fault and free surfaces, an icosahedral cluster without
//! a cell, each at three cutoffs, two of which cut through a noisy neighbour shell. Every
//! atom's count must be OVITO's.

use std::path::Path;

use texmap_md_io::coordination::{CoordinationError, coordination};
use texmap_md_io::{Frame, Trajectory, UnitCell};

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/cna")
        .join(name)
}

#[test]
fn every_atom_has_ovitos_coordination() {
    let text = std::fs::read_to_string(data("coordination_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let cutoffs: Vec<f64> = v["cutoffs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect();
    let mut t = Trajectory::open(data("crystals.xyz.gz")).unwrap();
    let mut frame = Frame::new();
    let mut checked = 0;
    for (k, want) in v["frames"].as_array().unwrap().iter().enumerate() {
        assert!(t.read_next(&mut frame).unwrap(), "frame {k}");
        for c in &cutoffs {
            let want: Vec<u32> = want[format!("{c:.1}")]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_u64().unwrap() as u32)
                .collect();
            let got = coordination(&frame, *c as f32).unwrap();
            let wrong: Vec<(usize, u32, u32)> = (0..got.len())
                .filter(|&i| got[i] != want[i])
                .map(|i| (i, got[i], want[i]))
                .take(10)
                .collect();
            assert!(
                wrong.is_empty(),
                "frame {k}, cutoff {c}: (atom, ours, OVITO's) {wrong:?}"
            );
            checked += got.len();
        }
    }
    assert_eq!(checked, 3 * 4076);
}

#[test]
fn a_cell_too_small_for_the_nearest_image_is_an_error() {
    let mut frame = Frame::new();
    frame.positions = vec![[0.0, 0.0, 0.0], [1.5, 0.0, 0.0]];
    frame.cell = Some(UnitCell::orthorhombic(20.0, 20.0, 8.0).unwrap());
    assert_eq!(coordination(&frame, 2.0).unwrap(), [1, 1]);
    let e = coordination(&frame, 3.0).unwrap_err();
    assert_eq!(
        e,
        CoordinationError::CellTooSmall {
            width: 8.0,
            cutoff: 3.0
        }
    );
    assert!(e.to_string().contains("--replicate"), "{e}");
    for bad in [0.0, -1.0, f32::NAN, 25.0] {
        assert!(matches!(
            coordination(&frame, bad),
            Err(CoordinationError::BadCutoff(_))
        ));
    }
}
