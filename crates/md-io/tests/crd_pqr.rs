//! CHARMM coordinate files and PQR files written by other programs (MDAnalysis's CRDWriter and
//! PQRWriter, PDB2PQR, ParmEd), read against what those programs read back from them
//! (tests/data/crd_pqr_reference.json.gz, written by tests/data/gen_crd_pqr.py), every atom;
//! then damaged copies: a cut file, a coordinate that is no number, an atom count larger than
//! the atoms, an empty file, and a `.crd` that is not CHARMM's.

use serde_json::Value;
use std::io::Cursor;
use std::path::PathBuf;
use texmap_md_io::{Error, Format, Frame, Trajectory};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn reference() -> Value {
    let gz = std::fs::File::open(data("crd_pqr_reference.json.gz")).unwrap();
    serde_json::from_reader(flate2::read::GzDecoder::new(gz)).unwrap()
}

fn frames(t: &mut Trajectory) -> Vec<Frame> {
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

fn open(name: &str) -> Vec<Frame> {
    frames(&mut Trajectory::open(data(name)).unwrap())
}

fn strings(v: &Value) -> Vec<String> {
    let a = v.as_array().unwrap();
    a.iter().map(|s| s.as_str().unwrap().to_string()).collect()
}

fn ints(v: &Value) -> Vec<i64> {
    let a = v.as_array().unwrap();
    a.iter().map(|x| x.as_i64().unwrap()).collect()
}

fn f32s(v: &Value) -> Vec<f32> {
    let a = v.as_array().unwrap();
    a.iter().map(|x| x.as_f64().unwrap() as f32).collect()
}

fn labels(l: &[texmap_md_io::Label]) -> Vec<String> {
    l.iter().map(|s| s.to_string()).collect()
}

/// Values parsed from the same decimals: equal within one f32 rounding (the programs parse to
/// f64 and round to f32; so does the CRD reader, the PQR reader rounds once).
fn same_f32(what: &str, expected: &[f32], actual: &[f32]) {
    assert_eq!(expected.len(), actual.len(), "{what}: count");
    for (i, (e, a)) in expected.iter().zip(actual).enumerate() {
        assert!(
            (e - a).abs() <= e.abs() * f32::EPSILON,
            "{what} {i}: expected {e}, actual {a}"
        );
    }
}

fn positions(what: &str, expected: &Value, f: &Frame) {
    let e: Vec<f32> = expected.as_array().unwrap().iter().flat_map(f32s).collect();
    let a: Vec<f32> = f.positions.iter().flatten().copied().collect();
    same_f32(what, &e, &a);
}

/// A CHARMM CRD frame against MDAnalysis's reading: RESID is the residue number
/// (`resids`), SEGID the segment, WMAIN the `tempfactors`.
fn check_crd(what: &str, e: &Value, f: &Frame) {
    positions(what, &e["positions"], f);
    assert_eq!(f.ids, ints(&e["ids"]), "{what}");
    assert_eq!(labels(&f.names), strings(&e["names"]), "{what}");
    assert_eq!(labels(&f.res_names), strings(&e["resnames"]), "{what}");
    assert_eq!(f.res_ids, ints(&e["resids"]), "{what}");
    assert_eq!(labels(&f.segments), strings(&e["segids"]), "{what}");
    same_f32(what, &f32s(&e["tempfactors"]), f.property("wmain").unwrap());
    assert!(f.chains.is_empty(), "{what}");
    assert_eq!(f.check(), Ok(()));
}

/// A PQR frame against MDAnalysis's reading: the chain is its segment id (SYSTEM without
/// chains, where the frame has no chain column).
fn check_pqr(what: &str, e: &Value, f: &Frame) {
    positions(what, &e["positions"], f);
    assert_eq!(f.ids, ints(&e["ids"]), "{what}");
    assert_eq!(labels(&f.names), strings(&e["names"]), "{what}");
    assert_eq!(labels(&f.res_names), strings(&e["resnames"]), "{what}");
    assert_eq!(f.res_ids, ints(&e["resids"]), "{what}");
    let segids = strings(&e["segids"]);
    if segids.iter().all(|s| s == "SYSTEM") {
        assert!(f.chains.is_empty(), "{what}");
    } else {
        assert_eq!(labels(&f.chains), segids, "{what}");
    }
    same_f32(what, &f32s(&e["charges"]), f.property("charge").unwrap());
    same_f32(what, &f32s(&e["radii"]), f.property("radius").unwrap());
    assert!(
        f.radii.is_empty(),
        "{what}: PQR radii are not drawing radii"
    );
    assert_eq!(f.check(), Ok(()));
}

#[test]
fn mdanalysis_standard_crd() {
    let r = reference();
    let got = open("mda_chains.crd");
    assert_eq!(got.len(), 1);
    let f = &got[0];
    check_crd("mda_chains.crd", &r["mda_chains.crd"][0], f);
    assert_eq!(f.n_atoms(), 362);
    assert_eq!(f.comment, "FRAME 0 FROM chains_mda.pdb");
    // The residue ids restart in every segment; the residue numbers would not.
    assert_eq!(f.res_ids[80], 1);
    assert_eq!(ints(&r["mda_chains.crd"][0]["resnums"])[80], 9);
    // Elements from the names: the ions' NA is sodium, a DNA C4' carbon.
    let ion = f.names.iter().position(|n| *n == "NA").unwrap();
    assert_eq!(f.elements[ion].symbol(), "Na");
    assert_eq!(f.elements[0].symbol(), "N");
}

#[test]
fn mdanalysis_extended_crd_gzipped() {
    let r = reference();
    let mut t = Trajectory::open(data("mda_chains_ext.crd.gz")).unwrap();
    assert_eq!(t.format(), Format::CharmmCrd);
    let got = frames(&mut t);
    assert_eq!(got.len(), 1);
    check_crd(
        "mda_chains_ext.crd.gz",
        &r["mda_chains_ext.crd.gz"][0],
        &got[0],
    );
    // The same atoms as the standard file, at the standard file's 5 decimals.
    let std = &open("mda_chains.crd")[0];
    for (a, b) in got[0].positions.iter().zip(&std.positions) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() <= 5e-6 + b[k].abs() * f32::EPSILON);
        }
    }
}

#[test]
fn concatenated_crd_files_are_frames_and_each_has_its_layout() {
    let r = reference();
    let exp = r["mda_two.crd"].as_array().unwrap();
    let mut t = Trajectory::open(data("mda_two.crd")).unwrap();
    assert_eq!(t.n_frames().unwrap(), 2);
    let got = frames(&mut t);
    assert_eq!(got.len(), 2);
    for (k, (e, f)) in exp.iter().zip(&got).enumerate() {
        check_crd(&format!("mda_two.crd frame {k}"), e, f);
    }
    // Random access to the second (EXT) frame.
    let mut f = Frame::new();
    t.read_frame(1, &mut f).unwrap();
    assert_eq!(f, got[1]);
    assert_eq!(f.comment, "FRAME 3 FROM topo_mda.xtc");
}

#[test]
fn pdb2pqr_fixed_columns_without_chains() {
    let r = reference();
    let mut t = Trajectory::open(data("pdb2pqr_amber.pqr")).unwrap();
    assert_eq!(t.format(), Format::Pqr);
    let got = frames(&mut t);
    assert_eq!(got.len(), 1);
    check_pqr("pdb2pqr_amber.pqr", &r["pdb2pqr_amber.pqr"][0], &got[0]);
    // AMBER's water hydrogens have radius 0.
    assert_eq!(got[0].property("radius").unwrap().last(), Some(&0.0));
}

#[test]
fn pdb2pqr_whitespace_chains_and_insertion_code() {
    let r = reference();
    let got = open("pdb2pqr_chains.pqr");
    assert_eq!(got.len(), 1);
    let f = &got[0];
    check_pqr("pdb2pqr_chains.pqr", &r["pdb2pqr_chains.pqr"][0], f);
    // Residue 5A of chain B is residue 5, as MDAnalysis reads it.
    let text = std::fs::read_to_string(data("pdb2pqr_chains.pqr")).unwrap();
    let k = text.lines().position(|l| l.contains(" 5A ")).unwrap();
    assert_eq!((f.chains[k].as_str(), f.res_ids[k]), ("B", 5));
}

#[test]
fn mdanalysis_pqr_writer() {
    let r = reference();
    let got = open("mda_chains.pqr");
    assert_eq!(got.len(), 1);
    check_pqr("mda_chains.pqr", &r["mda_chains.pqr"][0], &got[0]);
}

#[test]
fn parmed_models_cell_and_chains() {
    let r = reference();
    let e = &r["parmed_models.pqr"];
    let got = open("parmed_models.pqr");
    let models = e["models"].as_array().unwrap();
    assert_eq!(got.len(), models.len());
    assert_eq!(got.len(), 3);
    let box_ = f32s(&e["box"]);
    for (k, (m, f)) in models.iter().zip(&got).enumerate() {
        let what = format!("parmed_models.pqr model {k}");
        positions(&what, m, f);
        assert_eq!(labels(&f.names), strings(&e["names"]), "{what}");
        assert_eq!(labels(&f.res_names), strings(&e["resnames"]), "{what}");
        assert_eq!(f.res_ids, ints(&e["resids"]), "{what}");
        assert_eq!(labels(&f.chains), strings(&e["chains"]), "{what}");
        same_f32(&what, &f32s(&e["charges"]), f.property("charge").unwrap());
        same_f32(&what, &f32s(&e["radii"]), f.property("radius").unwrap());
        let cell = f.cell.unwrap();
        for i in 0..3 {
            assert!((cell.lengths()[i] - box_[i] as f64).abs() < 1e-9, "{what}");
            assert!(
                (cell.angles()[i] - box_[3 + i] as f64).abs() < 1e-9,
                "{what}"
            );
        }
    }
}

/// Reads `bytes` as `format` to the end, returning the first error.
fn read_err(bytes: &[u8], format: Format, name: &str) -> Error {
    let mut t = Trajectory::from_reader(Cursor::new(bytes.to_vec()), format, name).unwrap();
    let mut f = Frame::new();
    loop {
        match t.read_next(&mut f) {
            Ok(true) => continue,
            Ok(false) => panic!("{name}: no error"),
            Err(e) => return e,
        }
    }
}

/// The byte offset where 1-based line `line` of `text` starts.
fn line_start(text: &[u8], line: usize) -> usize {
    if line == 1 {
        return 0;
    }
    text.iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(line - 2)
        .unwrap()
        .0
        + 1
}

#[test]
fn cut_files_name_the_line_and_what_was_missing() {
    // A CRD cut after atom line 100 of 362 (file line 103).
    let good = std::fs::read(data("mda_chains.crd")).unwrap();
    let cut = &good[..line_start(&good, 104)];
    let e = read_err(cut, Format::CharmmCrd, "cut.crd");
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert_eq!(e.location().unwrap().line, Some(104), "{e}");
    assert!(e.to_string().contains("262 more atom lines of 362"), "{e}");
    // Cut inside an atom line: the cut, not a bad number, is what is reported, where the
    // frame scan finds it (the partial line counts as a line, as for every text format).
    let cut = &good[..line_start(&good, 104) + 30];
    let e = read_err(cut, Format::CharmmCrd, "cut.crd");
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert_eq!(e.location().unwrap().line, Some(105), "{e}");
    assert!(e.to_string().contains("261 more atom lines of 362"), "{e}");
    // A PQR model cut before its ENDMDL.
    let good = std::fs::read(data("parmed_models.pqr")).unwrap();
    let text = std::str::from_utf8(&good).unwrap();
    let second = text.match_indices("MODEL").nth(1).unwrap().0;
    let cut = &good[..second + 200];
    let e = read_err(cut, Format::Pqr, "cut.pqr");
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert_eq!(e.location().unwrap().frame, Some(1), "{e}");
    assert!(e.to_string().contains("ENDMDL closing the MODEL"), "{e}");
}

#[test]
fn a_coordinate_that_is_no_number_names_line_and_column() {
    // CRD: the y field (columns 31-40) of atom 10, file line 13.
    let mut bad = std::fs::read(data("mda_chains.crd")).unwrap();
    let at = line_start(&bad, 13) + 33;
    bad[at] = b'x';
    let e = read_err(&bad, Format::CharmmCrd, "bad.crd");
    let loc = e.location().unwrap();
    assert_eq!(loc.line, Some(13), "{e}");
    // The byte names the field's first character.
    let field_start = line_start(&bad, 13)
        + 30
        + bad[line_start(&bad, 13) + 30..]
            .iter()
            .position(|b| *b != b' ')
            .unwrap();
    assert_eq!(loc.byte, Some(field_start as u64), "{e}");
    assert!(e.to_string().contains("columns 21-50"), "{e}");
    // PQR (whitespace fields): the z of the third atom.
    let mut bad = std::fs::read(data("pdb2pqr_chains.pqr")).unwrap();
    let line = line_start(&bad, 3);
    let text = std::str::from_utf8(&bad[line..])
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    let z = text.split_whitespace().nth(8).unwrap();
    let col = text.find(&format!(" {z} ")).unwrap() + 1;
    bad[line + col + 1] = b'#';
    let e = read_err(&bad, Format::Pqr, "bad.pqr");
    let loc = e.location().unwrap();
    assert_eq!(
        (loc.line, loc.byte),
        (Some(3), Some((line + col) as u64)),
        "{e}"
    );
}

#[test]
fn an_atom_count_larger_than_the_atoms() {
    // The last frame: the file ends first.
    let text = std::fs::read_to_string(data("mda_chains.crd")).unwrap();
    let bad = text.replacen("\n  362\n", "\n  400\n", 1);
    let e = read_err(bad.as_bytes(), Format::CharmmCrd, "big.crd");
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().contains("38 more atom lines of 400"), "{e}");
    // Not the last frame: the next title is where an atom line should be.
    let text = std::fs::read_to_string(data("mda_two.crd")).unwrap();
    let bad = text.replacen("\n   66\n", "\n   70\n", 1);
    let e = read_err(bad.as_bytes(), Format::CharmmCrd, "big.crd");
    assert!(matches!(e, Error::Parse { .. }), "{e}");
    assert_eq!(e.location().unwrap().line, Some(3 + 66 + 1), "{e}");
    assert!(
        e.to_string().contains("more atoms than the frame has"),
        "{e}"
    );
    // n_frames says so too.
    let mut t = Trajectory::from_reader(Cursor::new(bad), Format::CharmmCrd, "big.crd").unwrap();
    assert!(t.n_frames().is_err());
}

#[test]
fn empty_files_have_no_frames() {
    for format in [Format::CharmmCrd, Format::Pqr] {
        for bytes in [&b""[..], b"\n\n"] {
            let mut t = Trajectory::from_reader(Cursor::new(bytes), format, "empty").unwrap();
            assert_eq!(t.n_frames().unwrap(), 0, "{format}");
            assert!(!t.read_next(&mut Frame::new()).unwrap(), "{format}");
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty.crd");
    std::fs::write(&path, "").unwrap();
    let mut t = Trajectory::open(&path).unwrap();
    assert_eq!(t.format(), Format::CharmmCrd);
    assert_eq!(t.n_frames().unwrap(), 0);
}

#[test]
fn a_crd_without_a_star_title_is_refused_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    // Neither CHARMM (no '*' title) nor AMBER (the second line is text, not coordinates or an
    // atom count).
    let amber = "\ntrajectory from cpptraj\n   1.000   2.000   3.000   4.000   5.000   6.000\n";
    let path = dir.path().join("run.crd");
    std::fs::write(&path, amber).unwrap();
    let e = match Trajectory::open(&path) {
        Err(e) => e,
        Ok(_) => panic!("opened an AMBER trajectory as CHARMM"),
    };
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!("{}: line 2, byte 1", path.display())),
        "{msg}"
    );
    assert!(
        msg.contains("CHARMM") && msg.contains("AMBER") && msg.contains("--format"),
        "{msg}"
    );
    // Opened as CHARMM by request, it is read as CHARMM and fails at the title.
    let e = Trajectory::open_as(&path, Format::CharmmCrd)
        .unwrap()
        .read_next(&mut Frame::new())
        .unwrap_err();
    assert!(
        e.to_string().contains("a title line starting with '*'"),
        "{e}"
    );
    // A `.cor` and a name without an extension are CHARMM by name and by content.
    let good = std::fs::read(data("mda_two.crd")).unwrap();
    for name in ["two.cor", "two_crd"] {
        let path = dir.path().join(name);
        std::fs::write(&path, &good).unwrap();
        let mut t = Trajectory::open(&path).unwrap();
        assert_eq!(t.format(), Format::CharmmCrd, "{name}");
        assert_eq!(t.n_frames().unwrap(), 2, "{name}");
    }
}
