//! LAMMPS data files as one-frame trajectories: files ASE 3.29 and MDAnalysis 2.11 wrote
//! (tests/data/gen_lammps_data.py) against what those programs read back
//! (lammps_data_reference.json), OVITO 3.17's general-triclinic file against its dump of the
//! same atoms, and synthetic files for the atom styles, image flags, ids out of order, type
//! labels, elements, and each damage error with its line and byte.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use serde_json::Value;
use texmap_md_io::{Error, Format, Frame, Topology, TopologyFormat, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn json(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path(name)).unwrap()).unwrap()
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(f64s).collect()
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect()
}

/// `|expected - actual| <= tol`, with both and the tolerance in the message.
fn close(expected: f64, actual: f64, tol: f64, what: &str) {
    assert!(
        (expected - actual).abs() <= tol,
        "{what}: expected {expected}, actual {actual}, tolerance {tol}"
    );
}

/// The one frame of `text` read as a LAMMPS data file named `t.data`.
fn read(text: &str) -> Result<Frame, Error> {
    let mut t =
        Trajectory::from_reader(Cursor::new(text.as_bytes()), Format::LammpsData, "t.data")?;
    let mut f = Frame::new();
    assert!(t.read_next(&mut f)?, "no frame");
    let mut g = Frame::new();
    assert!(!t.read_next(&mut g)?, "a second frame");
    Ok(f)
}

/// The error `text` gives, checked to name the file, frame 0, `line` and a byte.
fn error(text: &str, line: u64) -> String {
    let e = read(text).unwrap_err();
    let at = e.location().unwrap_or_else(|| panic!("no location: {e}"));
    assert_eq!(at.frame, Some(0), "{e}");
    assert_eq!(at.line, Some(line), "{e}");
    assert!(at.byte.is_some(), "{e}");
    e.to_string()
}

fn labels(f: &Frame) -> Vec<&str> {
    f.types.iter().map(|t| t.as_str()).collect()
}

fn symbols(f: &Frame) -> Vec<&str> {
    f.elements.iter().map(|e| e.symbol()).collect()
}

/// Positions to 1e-5 Å: f32 rounding of coordinates below 100 Å is at most 4e-6 Å.
const POS_TOL: f64 = 1e-5;

#[test]
fn files_ase_and_mdanalysis_wrote_read_as_they_read_them() {
    let r = json("lammps_data_reference.json");
    let files = r.as_object().unwrap();
    assert_eq!(files.len(), 5);
    for (name, want) in files {
        let file = if name == "topo_mda.data" {
            path(name)
        } else {
            path(&format!("lammps_data/{name}"))
        };
        let mut t = Trajectory::open(&file).unwrap();
        assert_eq!(t.format(), Format::LammpsData, "{name}");
        assert_eq!(t.n_frames().unwrap(), 1, "{name}");
        let mut f = Frame::new();
        assert!(t.read_next(&mut f).unwrap());
        assert_eq!(f.check(), Ok(()), "{name}");
        let n = want["n_atoms"].as_u64().unwrap() as usize;
        assert_eq!(f.n_atoms(), n, "{name}");
        for (i, p) in rows(&want["positions"]).iter().enumerate() {
            for (k, x) in p.iter().enumerate() {
                close(
                    *x,
                    f.positions[i][k] as f64,
                    POS_TOL,
                    &format!("{name} atom {i}"),
                );
            }
        }
        // MDAnalysis's cell went through its f32 box angles: 1e-4 Å.
        let cell = f.cell.unwrap_or_else(|| panic!("{name}: no cell"));
        for (a, row) in rows(&want["cell"]).iter().enumerate() {
            for (k, x) in row.iter().enumerate() {
                close(
                    *x,
                    cell.matrix()[a][k],
                    1e-4,
                    &format!("{name} cell[{a}][{k}]"),
                );
            }
        }
        for (k, o) in f64s(&want["origin"]).iter().enumerate() {
            close(*o, cell.origin()[k], 1e-12, &format!("{name} origin"));
        }
        assert_eq!(labels(&f), strings(&want["types"]), "{name}");
        if let Some(e) = want.get("elements") {
            assert_eq!(symbols(&f), strings(e), "{name}");
        }
        let mass = f.property("mass").unwrap();
        for (i, m) in f64s(&want["masses"]).iter().enumerate() {
            close(*m, mass[i] as f64, 1e-5 * m, &format!("{name} mass {i}"));
        }
        match want.get("charges") {
            Some(q) => {
                let ours = f.property("charge").unwrap();
                for (i, q) in f64s(q).iter().enumerate() {
                    close(*q, ours[i] as f64, 1e-6, &format!("{name} charge {i}"));
                }
            }
            None => assert!(f.property("charge").is_none(), "{name}"),
        }
        match want.get("mol_ids") {
            Some(m) => {
                let m: Vec<i64> = m
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_i64().unwrap())
                    .collect();
                assert_eq!(f.res_ids, m, "{name}");
            }
            None => assert!(f.res_ids.is_empty(), "{name}"),
        }
        let bonds: Vec<[u32; 2]> = want
            .get("bonds")
            .map(|b| rows(b).iter().map(|p| [p[0] as u32, p[1] as u32]).collect())
            .unwrap_or_default();
        assert_eq!(f.bonds, bonds, "{name}");
        // Velocities as written, as properties (the file does not state its units).
        assert!(f.velocities.is_empty(), "{name}");
        match want.get("velocities") {
            Some(v) => {
                let c = ["vx", "vy", "vz"].map(|p| f.property(p).unwrap());
                for (i, v) in rows(v).iter().enumerate() {
                    for k in 0..3 {
                        let tol = 1e-6 * v[k].abs().max(1e-3);
                        close(v[k], c[k][i] as f64, tol, &format!("{name} v{k} {i}"));
                    }
                }
            }
            None => assert!(f.property("vx").is_none(), "{name}"),
        }
    }
}

/// Elements from masses: MDAnalysis's topo_mda.data has no comments, and its masses give the
/// elements MDAnalysis wrote into topo_mda.pdb for the same atoms; in mda_full_tri.data the
/// united-atom CH2 (14.027) and the bead (72.0) are of no element, and drawn by type.
#[test]
fn elements_from_masses_match_the_pdb_and_leave_beads_unknown() {
    let pdb = &json("topology_reference.json")["pdb"];
    let mut t = Trajectory::open(path("topo_mda.data")).unwrap();
    let mut f = Frame::new();
    t.read_next(&mut f).unwrap();
    assert_eq!(symbols(&f), strings(&pdb["elements"]));
    // The topology of the same file: the same parse, its labels.
    let top = Topology::open(path("topo_mda.data")).unwrap();
    assert_eq!(top.elements, f.elements);
    assert_eq!(top.types, f.types);
    assert_eq!(top.bonds, f.bonds);
    assert_eq!(top.charges, f.property("charge").unwrap());

    let mut t = Trajectory::open(path("lammps_data/mda_full_tri.data")).unwrap();
    t.read_next(&mut f).unwrap();
    for (ty, el) in f.types.iter().zip(&f.elements) {
        let want = match ty.as_str() {
            "1" => "C",
            "2" => "O",
            _ => "X",
        };
        assert_eq!(el.symbol(), want, "type {ty}");
    }
}

/// OVITO 3.17 writes the general triclinic box (`avec bvec cvec abc origin`) and `Atoms # bond`;
/// its LAMMPS dump of the same atoms (replicate/gen_replicate.py) holds the same cell, ids,
/// molecules and positions.
#[test]
fn ovito_general_triclinic_file_matches_its_dump() {
    let mut data = Frame::new();
    let mut t = Trajectory::open(path("replicate/water.data")).unwrap();
    assert!(t.read_next(&mut data).unwrap());
    let mut dump = Frame::new();
    let mut t = Trajectory::open(path("replicate/water.lammpstrj")).unwrap();
    assert!(t.read_next(&mut dump).unwrap());
    assert_eq!(data.n_atoms(), 180);
    assert_eq!(data.ids, dump.ids);
    assert_eq!(data.types, dump.types);
    let mol: Vec<i64> = dump
        .property("mol")
        .unwrap()
        .iter()
        .map(|m| *m as i64)
        .collect();
    assert_eq!(data.res_ids, mol);
    assert_eq!(data.positions, dump.positions);
    let (a, b) = (data.cell.unwrap(), dump.cell.unwrap());
    assert_eq!(
        a.matrix(),
        [[18.0, 0.0, 0.0], [4.0, 16.0, 0.0], [3.0, -2.0, 15.0]]
    );
    assert_eq!(a.matrix(), b.matrix());
    assert_eq!(a.origin(), [-2.0, 1.0, 0.5]);
    assert_eq!(a.origin(), b.origin());
    assert_eq!(data.bonds.len(), 120);
    // Each water's O bonded to its two H.
    assert!(data.bonds.iter().all(|[i, j]| i % 3 == 0 && j - i <= 2));
    assert!(
        data.elements.is_empty(),
        "no masses, no type names: drawn by type"
    );
}

#[test]
fn every_atom_style_and_the_column_count_rule() {
    let one = |style: &str, line: &str| read(&format!("t\n1 atoms\nAtoms # {style}\n\n{line}\n"));
    let cases: &[(&str, &str, &[&str], bool)] = &[
        ("atomic", "1 1 1.5 2.5 3.5", &[], false),
        ("charge", "1 1 -0.5 1.5 2.5 3.5", &["charge"], false),
        ("molecular", "1 7 1 1.5 2.5 3.5", &[], true),
        ("bond", "1 7 1 1.5 2.5 3.5", &[], true),
        ("angle", "1 7 1 1.5 2.5 3.5", &[], true),
        ("full", "1 7 1 -0.5 1.5 2.5 3.5", &["charge"], true),
        (
            "sphere",
            "1 1 0.0 1.2 1.5 2.5 3.5",
            &["diameter", "density"],
            false,
        ),
        (
            "ellipsoid",
            "1 1 1 1.2 1.5 2.5 3.5",
            &["ellipsoidflag", "density"],
            false,
        ),
        (
            "dipole",
            "1 1 -0.5 1.5 2.5 3.5 0.1 0.2 0.3",
            &["charge", "mux", "muy", "muz"],
            false,
        ),
        (
            "peri",
            "1 1 0.8 1.2 1.5 2.5 3.5",
            &["volume", "density"],
            false,
        ),
        ("dpd", "1 1 300 1.5 2.5 3.5", &["theta"], false),
    ];
    for (style, line, props, mol) in cases {
        let f = one(style, line).unwrap_or_else(|e| panic!("{style}: {e}"));
        assert_eq!(f.positions, [[1.5, 2.5, 3.5]], "{style}");
        let names: Vec<&str> = f.properties.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, *props, "{style}");
        assert_eq!(f.res_ids, if *mol { vec![7] } else { vec![] }, "{style}");
        // With the three image flags: the same plus `ix iy iz`, positions not moved.
        let f = one(style, &format!("{line} 1 -2 0")).unwrap();
        assert_eq!(f.positions, [[1.5, 2.5, 3.5]], "{style}");
        assert_eq!(f.property("iy"), Some(&[-2.0][..]), "{style}");
    }
    // A sphere whose diameters are all positive: radii.
    let f = one("sphere", "1 1 2.0 1.2 1.5 2.5 3.5").unwrap();
    assert_eq!(f.radii, [1.0]);
    assert!(f.property("diameter").is_none());
    // No comment: 5 and 8 columns are atomic, 7 and 10 full; 6 is ambiguous.
    let bare = |line: &str| read(&format!("t\n1 atoms\nAtoms\n\n{line}\n"));
    assert!(bare("1 1 0 0 0").unwrap().property("charge").is_none());
    assert_eq!(
        bare("1 1 0 0 0 0 0 1").unwrap().property("iz"),
        Some(&[1.0][..])
    );
    assert_eq!(
        bare("1 4 1 0.25 0 0 0").unwrap().property("charge"),
        Some(&[0.25][..])
    );
    assert_eq!(bare("1 4 1 0.25 0 0 0 0 0 0").unwrap().res_ids, [4]);
    let e = bare("1 1 1 0 0 0").unwrap_err().to_string();
    assert!(e.contains("line 5") && e.contains("'Atoms # style'"), "{e}");
    // A style this reader does not know.
    let e = one("hybrid", "1 1 0 0 0").unwrap_err().to_string();
    assert!(e.contains("line 3") && e.contains("'hybrid'"), "{e}");
}

/// Rows in any order: atoms sorted by id, velocities and bonds following them; image flags kept
/// as properties; type labels, masses keyed by label, and elements from comments, labels and
/// masses; a blank title line.
#[test]
fn ids_out_of_order_labels_and_elements() {
    let text = "\n3 atoms\n3 atom types\n2 bonds\n1 bond types\n\
        -1 9 xlo xhi\n0 10 ylo yhi\n0 10 zlo zhi # box\n\n\
        Atom Type Labels\n\n1 CA\n2 Ca\n3 X1\n\n\
        Masses\n\nCA 12.011 # aromatic carbon\nCa 40.078\nX1 1.0 # C\n\n\
        Atoms # full\n\n\
        3 1 X1 0.1 3 0 0 0 0 1\n1 1 CA -0.2 1 0 0 0 0 0\n2 2 2 0.1 2 0 0 -1 0 0\n\n\
        Velocities\n\n2 0.2 0 0\n3 0.3 0 0\n1 0.1 0 0\n\n\
        Bonds\n\n1 1 3 1\n2 1 2 1\n";
    let f = read(text).unwrap();
    assert_eq!(f.comment, "");
    assert_eq!(f.ids, [1, 2, 3]);
    assert_eq!(
        f.positions,
        [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]]
    );
    assert_eq!(labels(&f), ["CA", "2", "X1"]);
    assert_eq!(f.res_ids, [1, 2, 1]);
    // CA: no symbol, mass → C; Ca: its label; X1: the comment's symbol over its mass.
    assert_eq!(symbols(&f), ["C", "Ca", "C"]);
    assert_eq!(f.property("mass"), Some(&[12.011, 40.078, 1.0][..]));
    assert_eq!(f.property("charge"), Some(&[-0.2, 0.1, 0.1][..]));
    assert_eq!(f.property("ix"), Some(&[0.0, -1.0, 0.0][..]));
    assert_eq!(f.property("iz"), Some(&[0.0, 0.0, 1.0][..]));
    assert_eq!(f.property("vx"), Some(&[0.1, 0.2, 0.3][..]));
    assert_eq!(f.bonds, [[0, 1], [0, 2]]);
    let c = f.cell.unwrap();
    assert_eq!(c.origin(), [-1.0, 0.0, 0.0]);
    assert_eq!(c.lengths(), [10.0, 10.0, 10.0]);
    // The topology of the same text.
    let t = Topology::from_reader(Cursor::new(text), TopologyFormat::LammpsData, "t.data").unwrap();
    assert_eq!(t.ids, f.ids);
    assert_eq!(t.elements, f.elements);
    assert_eq!(t.res_ids, f.res_ids);
    assert_eq!(t.bonds, f.bonds);
}

#[test]
fn restricted_triclinic_box_as_lammps_documents_it() {
    let f = read("t\n0 atoms\n1 5 xlo xhi\n-2 2 ylo yhi\n0 3 zlo zhi\n0.5 -0.25 0.75 xy xz yz\n")
        .unwrap();
    let c = f.cell.unwrap();
    assert_eq!(
        c.matrix(),
        [[4.0, 0.0, 0.0], [0.5, 4.0, 0.0], [-0.25, 0.75, 3.0]]
    );
    assert_eq!(c.origin(), [1.0, -2.0, 0.0]);
    assert_eq!(f.n_atoms(), 0);
    // No box lines: no cell.
    assert!(
        read("t\n1 atoms\nAtoms\n\n1 1 0 0 0\n")
            .unwrap()
            .cell
            .is_none()
    );
}

#[test]
fn names_and_first_bytes_tell_a_data_file() {
    for name in ["system.data", "a/b.LMP", "data.peptide", "data.lj.gz"] {
        assert_eq!(
            Format::from_path(Path::new(name)),
            Some(Format::LammpsData),
            "{name}"
        );
    }
    assert_eq!(Format::from_path(Path::new("in.lammps")), None);
    assert_eq!(
        Format::from_extension("lammps-data"),
        Some(Format::LammpsData)
    );
    assert_eq!(Format::LammpsData.name(), "lammps-data");
    let head = std::fs::read(path("topo_mda.data")).unwrap();
    assert_eq!(Format::from_magic(&head[..256]), Some(Format::LammpsData));
    let head = std::fs::read(path("replicate/water.data")).unwrap();
    assert_eq!(Format::from_magic(&head[..256]), Some(Format::LammpsData));
    // An XYZ whose comment says "5 atoms" stays XYZ; an input script is no data file.
    assert_eq!(
        Format::from_magic(b"2\n2 atoms\nH 0 0 0\nH 1 0 0\n"),
        Some(Format::Xyz)
    );
    assert_eq!(
        Format::from_magic(b"units real\natom_style full\nread_data x.data\n"),
        None
    );
}

/// Each damage names its line (and byte: `error` checks there is one).
#[test]
fn damage_names_the_line_and_what_was_expected() {
    let full =
        |atoms: &str| format!("t\n2 atoms\n1 bonds\n\nAtoms # full\n\n{atoms}\nBonds\n\n1 1 1 2\n");
    // A row with too few columns.
    let e = error(&full("1 1 1 0 0 0 0\n2 1 1 0 0 0"), 8);
    assert!(e.contains("as many columns as the first Atoms line"), "{e}");
    // An id repeated: the second line, naming the first.
    let e = error(&full("1 1 1 0 0 0 0\n1 1 1 0 0 0 1"), 8);
    assert!(
        e.contains("each atom id once") && e.contains("first on line 7"),
        "{e}"
    );
    // An id that is not positive: the byte of the token.
    let text = full("1 1 1 0 0 0 0\n0 1 1 0 0 0 1");
    let e = read(&text).unwrap_err();
    assert_eq!(
        e.location().unwrap().byte,
        Some(text.find("\n0 1 1").unwrap() as u64 + 1)
    );
    assert!(e.to_string().contains("a positive atom id"), "{e}");
    // A bond to a missing atom: the byte of its id.
    let text = "t\n2 atoms\n1 bonds\nAtoms # atomic\n\n1 1 0 0 0\n2 1 0 0 1\n\nBonds\n\n1 1 1 9\n";
    let e = read(text).unwrap_err();
    let at = e.location().unwrap();
    assert_eq!(
        (at.line, at.byte),
        (Some(11), Some(text.rfind('9').unwrap() as u64))
    );
    assert!(e.to_string().contains("found '9'"), "{e}");
    // A bond from an atom to itself.
    let e = error(&text.replace("1 1 1 9", "1 1 2 2"), 11);
    assert!(e.contains("two different atoms"), "{e}");
    // A velocity for a missing atom.
    let v = "t\n1 atoms\nAtoms # atomic\n\n1 1 0 0 0\n\nVelocities\n\n5 0 0 0\n";
    let e = error(v, 9);
    assert!(e.contains("a velocity for an atom id"), "{e}");
    // A section longer than its count: the line after its last.
    let e = error("t\n1 atoms\nAtoms # atomic\n\n1 1 0 0 0\n2 1 0 0 0\n", 6);
    assert!(e.contains("section keyword"), "{e}");
    // Shorter: the next section's keyword comes first.
    let e = error(
        "t\n2 atoms\nAtoms # atomic\n\n1 1 0 0 0\n\nMasses\n\n1 1.0\n",
        7,
    );
    assert!(
        e.contains("Masses after 1 of the 2 lines of the Atoms section"),
        "{e}"
    );
    // A box with hi <= lo: the byte of hi.
    let text = "t\n1 atoms\n0 10 xlo xhi\n5 5 ylo yhi\n0 1 zlo zhi\n";
    let e = read(text).unwrap_err();
    assert_eq!(
        e.location().unwrap().byte,
        Some(text.find("5 ylo").unwrap() as u64)
    );
    assert!(e.to_string().contains("hi > lo"), "{e}");
    // A left-handed general box.
    let e = error(
        "t\n0 atoms\n1 0 0 avec\n0 0 1 bvec\n0 1 0 cvec\n0 0 0 abc origin\n",
        3,
    );
    assert!(e.contains("right-handed"), "{e}");
    // Both kinds of box.
    let e = error(
        "t\n0 atoms\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n1 0 0 avec\n",
        3,
    );
    assert!(e.contains("not both"), "{e}");
    // Not a header line, not a section.
    let e = error("t\n1 atoms\n1 atomz\n", 3);
    assert!(e.contains("a header line"), "{e}");
    // An atom type out of the header's range, on its atom's line.
    let e = error("t\n1 atoms\n1 atom types\nAtoms # atomic\n\n1 2 0 0 0\n", 6);
    assert!(e.contains("atom type"), "{e}");
    // A section twice.
    let e = error("t\n0 atoms\n0 atom types\nMasses\n\nMasses\n", 6);
    assert!(e.contains("each section once"), "{e}");
    // A coordinate that is not a number.
    let e = error("t\n1 atoms\nAtoms # atomic\n\n1 1 0 x 0\n", 5);
    assert!(e.contains("a coordinate") && e.contains("'x'"), "{e}");
}

/// A cut file is a cut (Error::Truncated), whatever its counts claim: a missing section, and a
/// count far beyond what the file holds, which allocates nothing for it.
#[test]
fn cut_files_and_counts_beyond_the_file() {
    let cut = "t\n2 atoms\n1 bonds\nAtoms # atomic\n\n1 1 0 0 0\n2 1 0 0 1\n";
    let e = read(cut).unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("the Bonds section (the header's 1 bonds)"),
        "{e}"
    );
    let huge = "t\n1000000000000 atoms\nAtoms # atomic\n\n1 1 0 0 0\n";
    let e = read(huge).unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("999999999999 more lines of the Atoms section"),
        "{e}"
    );
    let e = read("just a title\n").unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    // Counted structure agrees with streaming.
    let mut t = Trajectory::from_reader(Cursor::new(cut), Format::LammpsData, "cut").unwrap();
    assert!(matches!(t.n_frames(), Err(Error::Truncated { .. })));
}
