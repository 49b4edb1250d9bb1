//! Small-molecule formats against the programs that wrote them (tests/data/molecules/, by
//! gen_molecules.py): MDL SD files and a V3000 molfile written by RDKit, read atom for atom
//! and bond for bond as RDKit holds them; Tripos MOL2 written by Open Babel, read as MDAnalysis
//! reads it (names, SYBYL types, residues, partial charges, bonds, every pose's positions) and
//! as Open Babel reads it back (a library whose molecules differ in size).

use std::path::{Path, PathBuf};

use serde_json::Value;
use texmap_md_io::{BOND_AROMATIC, Error, Format, Frame, Trajectory};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/molecules")
        .join(name)
}

fn reference() -> Value {
    let text = std::fs::read_to_string(data("molecules_reference.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn frames(name: &str) -> Vec<Frame> {
    let mut t = Trajectory::open(data(name)).unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    assert_eq!(t.n_frames().unwrap(), out.len());
    out
}

fn pairs(v: &Value) -> Vec<[u32; 2]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|b| [b[0].as_u64().unwrap() as u32, b[1].as_u64().unwrap() as u32])
        .collect()
}

fn assert_positions(got: &[[f32; 3]], want: &Value, what: &str) {
    let want = want.as_array().unwrap();
    assert_eq!(got.len(), want.len(), "{what}");
    for (i, (p, w)) in got.iter().zip(want).enumerate() {
        for k in 0..3 {
            let w = w[k].as_f64().unwrap();
            assert!(
                (p[k] as f64 - w).abs() < 1e-3,
                "{what} atom {i}: {p:?} vs {w}"
            );
        }
    }
}

#[test]
fn sd_files_read_as_rdkit_wrote_them() {
    let r = reference();
    for (name, records) in r["sdf"].as_object().unwrap() {
        let got = frames(name);
        let records = records.as_array().unwrap();
        assert_eq!(got.len(), records.len(), "{name}");
        for (k, (f, want)) in got.iter().zip(records).enumerate() {
            let what = format!("{name} record {k}");
            // The title line (data items follow as pairs on the next line).
            assert_eq!(
                f.comment.lines().next().unwrap_or(""),
                want["name"].as_str().unwrap(),
                "{what}"
            );
            if name == "library.sdf" {
                // gen_molecules.py's SetProp("score", ...), an RDKit data item.
                let score = format!("{:.2}", -7.5 + 0.8 * k as f64);
                assert_eq!(f.comment_value("score"), Some(score.as_str()), "{what}");
            }
            let symbols: Vec<&str> = f.elements.iter().map(|e| e.symbol()).collect();
            let want_symbols: Vec<&str> = want["elements"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_str().unwrap())
                .collect();
            assert_eq!(symbols, want_symbols, "{what}");
            assert_positions(&f.positions, &want["positions"], &what);
            assert_eq!(f.bonds, pairs(&want["bonds"]), "{what}");
            assert_eq!(f.check(), Ok(()), "{what}");
        }
    }
    // The library's molecules differ in size: each frame has its own atoms.
    let sizes: Vec<usize> = frames("library.sdf").iter().map(Frame::n_atoms).collect();
    assert_eq!(sizes, [21, 24, 33, 7, 17]);
}

/// Formal charges as RDKit 2026.09.1 reads them (`Chem.MolFromMolFile(path, sanitize=False)`,
/// `GetFormalCharge()` per atom): the atom lines' charge codes, `M  CHG` lines replacing
/// every code of their record, V3000's `CHG=`, and the library's acetate and
/// tetramethylammonium. They become the `charge` property, absent from uncharged records.
#[test]
fn formal_charges_read_as_rdkit_reads_them() {
    let atoms = "    0.0000    0.0000    0.0000 N   0  3  0  0  0  0  0  0  0  0  0  0\n    1.4000    0.0000    0.0000 C   0  0  0  0  0  0  0  0  0  0  0  0\n    2.1000    1.2000    0.0000 O   0  ";
    let v2000 = |o_code: &str, props: &str| {
        format!(
            "q\n\n  made by hand\n  3  2  0  0  0  0  0  0  0  0999 V2000\n{atoms}{o_code}  0  0  0  0  0  0  0  0  0  0\n  1  2  1  0\n  2  3  1  0\n{props}M  END\n$$$$\n"
        )
    };
    let v3000 = "q\n\n  made by hand\n  0  0  0     0  0            999 V3000\nM  V30 BEGIN CTAB\nM  V30 COUNTS 3 2 0 0 0\nM  V30 BEGIN ATOM\nM  V30 1 N 0 0 0 0 CHG=1\nM  V30 2 C 1.4 0 0 0\nM  V30 3 O 2.1 1.2 0 0 CHG=-1\nM  V30 END ATOM\nM  V30 BEGIN BOND\nM  V30 1 1 1 2\nM  V30 2 1 2 3\nM  V30 END BOND\nM  V30 END CTAB\nM  END\n$$$$\n";
    for (what, text, rdkit) in [
        ("codes", v2000("5", ""), [1.0, 0.0, -1.0]),
        (
            "M  CHG over codes",
            v2000("0", "M  CHG  1   3  -2\n"),
            [0.0, 0.0, -2.0],
        ),
        ("V3000", v3000.to_string(), [1.0, 0.0, -1.0]),
    ] {
        let src = std::io::Cursor::new(text.into_bytes());
        let mut t = Trajectory::from_reader(src, Format::Sdf, "q.sdf").unwrap();
        let mut f = Frame::new();
        assert!(t.read_next(&mut f).unwrap(), "{what}");
        assert_eq!(f.property("charge"), Some(&rdkit[..]), "{what}");
    }
    let library = frames("library.sdf");
    let charged: Vec<(usize, Vec<(usize, f32)>)> = library
        .iter()
        .enumerate()
        .filter_map(|(k, f)| {
            let q = f.property("charge")?;
            Some((
                k,
                q.iter()
                    .copied()
                    .enumerate()
                    .filter(|q| q.1 != 0.0)
                    .collect(),
            ))
        })
        .collect();
    assert_eq!(charged, [(3, vec![(3, -1.0)]), (4, vec![(1, 1.0)])]);
    // A damaged M  CHG line is an error at its line, not a charge dropped.
    let sdf = std::fs::read_to_string(data("library.sdf")).unwrap();
    let (n, e) = read(
        &sdf.replacen("M  CHG  1   4  -1", "M  CHG  2   4  -1", 1),
        Format::Sdf,
    );
    assert_eq!(n, 3);
    let e = e.unwrap().to_string();
    assert!(e.contains("frame 3") && e.contains("M  CHG"), "{e}");
}

#[test]
fn mol2_reads_as_mdanalysis_reads_it() {
    let r = reference();
    let want = &r["mol2_mdanalysis"];
    let got = frames("imatinib_poses.mol2");
    let poses = want["frames"].as_array().unwrap();
    assert_eq!(got.len(), poses.len());
    let strings = |key: &str| -> Vec<String> {
        want[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_string())
            .collect()
    };
    for (k, (f, pose)) in got.iter().zip(poses).enumerate() {
        let what = format!("pose {k}");
        assert_positions(&f.positions, pose, &what);
        let labels = |v: &[texmap_md_io::Label]| -> Vec<String> {
            v.iter().map(|l| l.as_str().to_string()).collect()
        };
        assert_eq!(labels(&f.names), strings("names"), "{what}");
        assert_eq!(labels(&f.types), strings("types"), "{what}");
        assert_eq!(labels(&f.res_names), strings("resnames"), "{what}");
        let resids: Vec<i64> = want["resids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_i64().unwrap())
            .collect();
        assert_eq!(f.res_ids, resids, "{what}");
        let charges = f.property("charge").unwrap();
        for (q, w) in charges.iter().zip(want["charges"].as_array().unwrap()) {
            assert!((*q as f64 - w.as_f64().unwrap()).abs() < 1e-6, "{what}");
        }
        assert_eq!(f.bonds, pairs(&want["bonds"]), "{what}");
    }
    // Elements from the SYBYL types: imatinib's heavy atoms are C, N and O, with H.
    let e: std::collections::BTreeSet<&str> = got[0].elements.iter().map(|e| e.symbol()).collect();
    assert_eq!(e, ["C", "H", "N", "O"].into());
}

#[test]
fn a_mol2_library_reads_as_open_babel_reads_it_back() {
    let r = reference();
    let want = r["mol2_openbabel"].as_array().unwrap();
    let got = frames("library.mol2");
    assert_eq!(got.len(), want.len());
    for (k, (f, w)) in got.iter().zip(want).enumerate() {
        let what = format!("molecule {k}");
        let z: Vec<u64> = f.elements.iter().map(|e| e.z() as u64).collect();
        let want_z: Vec<u64> = w["atomic_numbers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap())
            .collect();
        assert_eq!(z, want_z, "{what}");
        assert_positions(&f.positions, &w["positions"], &what);
        assert_eq!(f.bonds, pairs(&w["bonds"]), "{what}");
    }
}

#[test]
fn formats_are_told_by_their_first_lines() {
    for (name, format) in [
        ("library.sdf", Format::Sdf),
        ("caffeine_v3000.mol", Format::Sdf),
        ("library.mol2", Format::Mol2),
    ] {
        let head = std::fs::read(data(name)).unwrap();
        assert_eq!(Format::from_magic(&head[..256]), Some(format), "{name}");
        assert_eq!(Format::from_path(&data(name)), Some(format), "{name}");
    }
}

/// Reads `text` as `format`; the frames before the first error, and the error.
fn read(text: &str, format: Format) -> (usize, Option<Error>) {
    let src = std::io::Cursor::new(text.as_bytes().to_vec());
    let mut t = Trajectory::from_reader(src, format, "bad").unwrap();
    let mut f = Frame::new();
    let mut n = 0;
    loop {
        match t.read_next(&mut f) {
            Ok(true) => n += 1,
            Ok(false) => return (n, None),
            Err(e) => return (n, Some(e)),
        }
    }
}

#[test]
fn damaged_records_are_errors_naming_the_line() {
    let sdf = std::fs::read_to_string(data("library.sdf")).unwrap();
    // A bond to atom 99 of aspirin's 21.
    let bad = sdf.replacen("  1  2  1  0\n", " 99  2  1  0\n", 1);
    let (n, e) = read(&bad, Format::Sdf);
    let e = e.unwrap().to_string();
    assert_eq!(n, 0);
    assert!(
        e.contains("frame 0, line 26") && e.contains("two atom numbers"),
        "{e}"
    );
    // A damaged record end: the next record's counts line comes before '$$$$'.
    let bad = sdf.replacen("$$$$", "$$x$", 1);
    let (n, e) = read(&bad, Format::Sdf);
    assert_eq!(n, 0);
    assert!(
        e.unwrap()
            .to_string()
            .contains("'$$$$' ending the record first")
    );

    let mol2 = std::fs::read_to_string(data("library.mol2")).unwrap();
    // The second molecule's header damaged: its atoms must not join the first molecule's.
    let second = mol2.match_indices("@<TRIPOS>MOLECULE").nth(1).unwrap().0;
    let mut bad = mol2.clone();
    bad.replace_range(second..second + 1, "x");
    let (n, e) = read(&bad, Format::Mol2);
    assert_eq!(n, 0);
    assert!(
        e.unwrap()
            .to_string()
            .contains("'@<TRIPOS>MOLECULE' before more atoms")
    );
    // A bond to an atom id the molecule does not have.
    let bond = mol2.find("@<TRIPOS>BOND\n").unwrap() + "@<TRIPOS>BOND\n".len();
    let line_end = bond + mol2[bond..].find('\n').unwrap();
    let mut bad = mol2.clone();
    bad.replace_range(bond..line_end, "     1   500     2    1");
    let (_, e) = read(&bad, Format::Mol2);
    assert!(
        e.unwrap()
            .to_string()
            .contains("two atom ids of this molecule")
    );
}

/// Bond orders: every record's bonds with their orders as RDKit reads the SD files and the
/// V3000 molfile (the file's Kekulé single and double bonds) and as MDAnalysis reads the MOL2
/// files (aromatic `ar` bonds as [`BOND_AROMATIC`]) (molecules/gen_bond_orders.py).
#[test]
fn bond_orders_read_as_rdkit_and_mdanalysis_read_them() {
    let text = std::fs::read_to_string(data("bond_orders_reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let mut aromatic = 0;
    for (name, records) in reference.as_object().unwrap() {
        let got = frames(name);
        let records = records.as_array().unwrap();
        assert_eq!(got.len(), records.len(), "{name}");
        for (k, (f, want)) in got.iter().zip(records).enumerate() {
            assert_eq!(f.bond_orders.len(), f.bonds.len(), "{name} record {k}");
            let ours: Vec<[u64; 3]> = f
                .bonds
                .iter()
                .zip(&f.bond_orders)
                .map(|(b, o)| [b[0] as u64, b[1] as u64, *o as u64])
                .collect();
            let theirs: Vec<[u64; 3]> = want
                .as_array()
                .unwrap()
                .iter()
                .map(|b| [0, 1, 2].map(|c| b[c].as_u64().unwrap()))
                .collect();
            assert_eq!(ours, theirs, "{name} record {k}");
            aromatic += f
                .bond_orders
                .iter()
                .filter(|o| **o == BOND_AROMATIC)
                .count();
        }
    }
    assert!(aromatic > 100, "{aromatic} aromatic bonds");
}
