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

/// Each selection picks on `frame` the atoms MDAnalysis picked (its indices in `sels`).
fn assert_selects_as_mdanalysis(
    frame: &Frame,
    sels: &serde_json::Map<String, serde_json::Value>,
    file: &str,
) {
    for (text, want) in sels {
        let want = indices(want);
        let got = Selection::parse(text)
            .unwrap_or_else(|e| panic!("{e}"))
            .indices(frame)
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
        assert_selects_as_mdanalysis(&frame, sels, file);
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

/// The peptide system of tests/data/tpr (GROMACS 2022.5: two chains, TIP4P water, ions, a
/// rhombic dodecahedron) with its positions, box, charges, masses and bonds.
fn peptide() -> Frame {
    let path = data("tpr/peptide.tpr.gz");
    let mut traj = Trajectory::open(&path).unwrap();
    let mut frame = Frame::new();
    traj.read_frame(0, &mut frame).unwrap();
    let top = texmap_md_io::Topology::open(&path).unwrap();
    top.apply(&mut frame, "peptide.tpr.gz", 0).unwrap();
    frame.bonds = top.bonds.clone();
    frame
}

fn ndx_reference() -> serde_json::Value {
    let mut text = String::new();
    std::io::Read::read_to_string(
        &mut flate2::read::GzDecoder::new(
            std::fs::File::open(data("ndx/reference.json.gz")).unwrap(),
        ),
        &mut text,
    )
    .unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn bonded_fragment_geometric_and_range_keywords_match_mdanalysis() {
    // MDAnalysis 2.11's select_atoms on the same .tpr (tests/data/ndx/gen_ndx.py): bonds
    // (SETTLE's O-H included), fragments, spheres and cylinders through the triclinic box,
    // isolayers, masses and charges from the file.
    let reference = ndx_reference();
    let frame = peptide();
    let r = &reference["peptide"];
    assert_eq!(frame.n_atoms() as u64, r["n_atoms"].as_u64().unwrap());
    let sels = r["selections"].as_object().unwrap();
    assert!(sels.len() >= 25);
    assert_selects_as_mdanalysis(&frame, sels, "peptide.tpr");
    // VMD's `fragment N` against MDAnalysis's fragindices.
    let frags: Vec<u64> = r["fragindices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    for n in [0u64, 1, 2, 7, 500, *frags.iter().max().unwrap()] {
        let want: Vec<usize> = (0..frags.len()).filter(|&i| frags[i] == n).collect();
        let got = Selection::parse(&format!("fragment {n}"))
            .unwrap()
            .indices(&frame)
            .unwrap();
        assert_eq!(got, want, "fragment {n}");
    }
}

#[test]
fn nucleic_acid_keywords_match_mdanalysis() {
    let reference = ndx_reference();
    let r = &reference["dna"];
    let mut traj = Trajectory::open(data("1uqc.cif")).unwrap();
    let mut frame = Frame::new();
    traj.read_frame(0, &mut frame).unwrap();
    assert_eq!(frame.n_atoms() as u64, r["n_atoms"].as_u64().unwrap());
    assert_selects_as_mdanalysis(&frame, r["selections"].as_object().unwrap(), "1uqc.cif");
}

#[test]
fn gromacs_index_groups_select_as_gmx_made_them() {
    use texmap_md_io::ndx::{IndexGroups, write_ndx};
    let frame = peptide();
    let groups = IndexGroups::read(data("ndx/make_ndx.ndx")).unwrap();
    assert_eq!(groups.len(), 17);
    // Written back as make_ndx writes: the same bytes.
    let mut out = Vec::new();
    write_ndx(groups.groups(), &mut out).unwrap();
    assert_eq!(out, std::fs::read(data("ndx/make_ndx.ndx")).unwrap());
    // make_ndx's default groups are our keywords' atoms (gmx's residuetypes.dat and ours agree
    // on these residues), by name, any case, prefix and number.
    let pick = |sel: &str| {
        Selection::parse_with(sel, Some(&groups))
            .unwrap_or_else(|e| panic!("{e}"))
            .indices(&frame)
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let ours = |sel: &str| Selection::parse(sel).unwrap().indices(&frame).unwrap();
    for (group, same) in [
        ("System", "all"),
        ("Protein", "protein"),
        ("protein-h", "protein and not element H"),
        ("C-alpha", "protein and name CA"),
        ("Backbone", "protein and name N CA C"),
        ("SOL", "resname SOL"),
        ("Ion", "resname NA CL"),
        ("Water_and", "resname SOL NA CL"),
        ("12", "water"),
        ("\"non-Protein\"", "not protein"),
    ] {
        assert_eq!(pick(&format!("group {group}")), ours(same), "group {group}");
    }
    assert_eq!(
        pick("group C-alpha and resid 3:5 or group Ion"),
        ours("(protein and name CA and resid 3:5) or resname NA CL")
    );
    // gmx select's groups (names with parentheses reached by number or in quotes), against
    // the same selections in our language: distances through the box, whole residues.
    let sel = IndexGroups::read(data("ndx/select.ndx")).unwrap();
    let pick = |s: &str| {
        Selection::parse_with(s, Some(&sel))
            .unwrap_or_else(|e| panic!("{e}"))
            .indices(&frame)
            .unwrap()
    };
    assert_eq!(
        pick("group near_ions"),
        ours("resname SOL and within 5 of resname NA CL")
    );
    assert_eq!(pick("group 1"), ours("name CA and chain B"));
    assert_eq!(
        pick("group \"same_residue_as_(resname\""),
        ours("same residue as (resname SOL and within 6 of (chain A and name CA))")
    );
}

#[test]
fn group_errors_name_the_file_and_the_group() {
    use texmap_md_io::ndx::IndexGroups;
    let groups = IndexGroups::from_bytes(
        b"[ SideChain ]\n1 2\n[ SideChain-H ]\n2\n[ Far ]\n7000\n",
        "idx.ndx",
    )
    .unwrap();
    let e = Selection::parse("group Protein").unwrap_err();
    assert!(e.message.contains("--index"), "{e}");
    let e = Selection::parse_with("name CA and group Prot", Some(&groups)).unwrap_err();
    assert_eq!(e.column, 19);
    assert!(
        e.message.contains("idx.ndx has no group 'Prot'") && e.message.contains("0 SideChain"),
        "{e}"
    );
    let e = Selection::parse_with("group Side", Some(&groups)).unwrap_err();
    assert!(e.message.contains("several groups"), "{e}");
    let frame = peptide();
    let far = Selection::parse_with("group Far", Some(&groups)).unwrap();
    let e = far.evaluate(&frame).unwrap_err();
    assert!(
        e.message.contains("atom 7000 but the frame has 6206"),
        "{e}"
    );
    // A quoted keyword is a word, and a quoted word cannot stand for a keyword.
    assert!(Selection::parse("\"name\" CA").is_err());
    let q = Selection::parse("name \"CA\" \"or\"").unwrap();
    assert_eq!(q.indices(&frame).unwrap(), ours_ca(&frame));
}

fn ours_ca(frame: &Frame) -> Vec<usize> {
    Selection::parse("name CA").unwrap().indices(frame).unwrap()
}

#[test]
fn new_keywords_report_bad_numbers_at_their_column() {
    for (text, column) in [
        ("sphzone x name CA", 9),
        ("sphzone -2 name CA", 9),
        ("point 1 2 name CA", 11),
        ("cyzone 5 3 name CA", 12),
        ("mass 10 to", 11),
        ("mass 20:10", 6),
        ("charge abc", 1),
        ("sphlayer 1 2", 13),
    ] {
        let e = Selection::parse(text).unwrap_err();
        assert_eq!(e.column, column, "{text:?}: {e}");
    }
    // A cylinder wider than the box is refused, as MDAnalysis refuses it.
    let e = Selection::parse("cyzone 30 5 -5 resname NA")
        .unwrap()
        .evaluate(&peptide())
        .unwrap_err();
    assert!(e.message.contains("larger than the cell"), "{e}");
}
