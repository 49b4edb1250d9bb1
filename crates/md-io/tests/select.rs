//! Selections evaluated by our reader + selection language against MDAnalysis's own
//! `select_atoms` on the PDB it wrote (tests/data/gen_select.py writes both), and on gemmi's
//! PDBx/mmCIF conversion of that PDB (tests/data/gen_mmcif.py): the same atoms either way.

use texmap_md_io::{Frame, Selection, Trajectory};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A reference selection: MDAnalysis's atom indices.
fn indices(v: &serde_json::Value) -> Vec<usize> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|i| i.as_u64().unwrap() as usize)
        .collect()
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
            let want = indices(want);
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

fn strings(v: &serde_json::Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect()
}

/// Chain and segment selections against MDAnalysis on the PDB it wrote with chain identifiers
/// and segment names (tests/data/gen_chains.py); VMD's spellings select the same atoms.
#[test]
fn chain_and_segment_selections_match_mdanalysis() {
    let text = std::fs::read_to_string(data("chains_reference.json")).unwrap();
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut traj = Trajectory::open(data("chains_mda.pdb")).unwrap();
    let mut frame = Frame::new();
    traj.read_frame(0, &mut frame).unwrap();
    let labels = |l: &[texmap_md_io::Label]| l.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert_eq!(labels(&frame.chains), strings(&reference["chains"]));
    assert_eq!(labels(&frame.segments), strings(&reference["segments"]));
    let select = |text: &str| {
        Selection::parse(text)
            .unwrap_or_else(|e| panic!("{e}"))
            .indices(&frame)
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let sels = reference["selections"].as_object().unwrap();
    assert_eq!(sels.len(), 12);
    for (text, want) in sels {
        let want = indices(want);
        assert!(!want.is_empty(), "{text}");
        assert_eq!(select(text), want, "{text:?}");
        // VMD: `chain` and `segname`.
        let vmd = text.replace("chainID", "chain").replace("segid", "segname");
        assert_eq!(select(&vmd), want, "{vmd:?}");
    }
}

/// A PDB whose chain and segment fields are all blank has neither column: selecting by chain
/// is an error that says so, not an empty selection.
#[test]
fn chain_selection_on_a_file_without_chains_is_an_error() {
    let mut traj = Trajectory::open(data("mda_noelem.pdb")).unwrap();
    let mut frame = Frame::new();
    traj.read_frame(0, &mut frame).unwrap();
    assert!(!frame.chains.is_empty(), "MDAnalysis writes chain X");
    assert!(frame.segments.is_empty());
    let err = Selection::parse("segid PROA")
        .unwrap()
        .indices(&frame)
        .unwrap_err();
    assert!(err.message.contains("no segment identifiers"), "{err}");
    assert_eq!(err.column, 1);
    frame.chains.clear();
    let err = Selection::parse("name CA and chain A")
        .unwrap()
        .indices(&frame)
        .unwrap_err();
    assert!(err.message.contains("no chain identifiers"), "{err}");
    assert_eq!(err.column, 13);
}
