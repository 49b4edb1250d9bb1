//! Selections evaluated by our reader + selection language against MDAnalysis's own
//! `select_atoms` on the PDB it wrote (tests/data/gen_select.py writes both), and on gemmi's
//! PDBx/mmCIF conversion of that PDB (tests/data/gen_mmcif.py): the same atoms either way.

use texmap_md_io::{Frame, Selection, Trajectory};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn selections_match_mdanalysis_atom_for_atom() {
    let text = std::fs::read_to_string(data("select_reference.json")).unwrap();
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    for file in ["select_mda.pdb", "gemmi_select.cif"] {
        let mut traj = Trajectory::open(data(file)).unwrap();
        let mut frame = Frame::new();
        traj.read_frame(0, &mut frame).unwrap();
        assert_eq!(
            frame.n_atoms() as u64,
            reference["n_atoms"].as_u64().unwrap()
        );
        let sels = reference["selections"].as_object().unwrap();
        assert!(sels.len() >= 10);
        for (text, want) in sels {
            let want: Vec<usize> = want
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap() as usize)
                .collect();
            let got = Selection::parse(text)
                .unwrap_or_else(|e| panic!("{e}"))
                .indices(&frame)
                .unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                got,
                want,
                "{file} {text:?}: {} atoms selected, MDAnalysis selects {}",
                got.len(),
                want.len()
            );
        }
    }
}
