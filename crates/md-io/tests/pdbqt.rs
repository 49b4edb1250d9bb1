//! AutoDock PDBQT written by Meeko 0.8.0 (a receptor and a ligand) and by AutoDock Vina 1.2.7
//! (five docked poses, one MODEL each), compared with MDAnalysis 2.11's PDBQT reader and with
//! what Vina itself reported (tests/data/pdbqt/gen_pdbqt.py, reference.json).

use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Element, Format, Frame, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/pdbqt")
        .join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(path("reference.json")).unwrap()).unwrap()
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect()
}

/// Every frame of `name`, appended: MDAnalysis reads a file's MODELs as one frame of all atoms.
fn all_frames(name: &str) -> (Vec<Frame>, Frame) {
    let mut t = Trajectory::open(path(name)).unwrap();
    assert_eq!(t.format(), Format::Pdbqt);
    let mut frames = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        frames.push(f.clone());
    }
    let mut all = Frame::new();
    for f in &frames {
        all.append(f);
    }
    (frames, all)
}

/// Names, residues, chains, charges, AutoDock types and positions of every atom as MDAnalysis
/// reads them.
#[test]
fn atoms_as_mdanalysis_reads_them() {
    let r = reference();
    for name in ["receptor.pdbqt", "ligand.pdbqt", "poses.pdbqt"] {
        let want = &r[name];
        let (frames, all) = all_frames(name);
        let n = want["names"].as_array().unwrap().len();
        assert_eq!(all.n_atoms(), n, "{name}");
        let labels = |v: &[texmap_md_io::Label]| -> Vec<String> {
            v.iter().map(|l| l.as_str().to_string()).collect()
        };
        assert_eq!(labels(&all.names), strings(&want["names"]), "{name}");
        assert_eq!(labels(&all.res_names), strings(&want["resnames"]), "{name}");
        assert_eq!(labels(&all.types), strings(&want["types"]), "{name}");
        let chains = strings(&want["chains"]);
        if chains.iter().all(|c| c.is_empty()) {
            assert!(frames.iter().all(|f| f.chains.is_empty()), "{name}");
        } else {
            assert_eq!(labels(&all.chains), chains, "{name}");
        }
        let resids: Vec<i64> = want["resids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_i64().unwrap())
            .collect();
        assert_eq!(all.res_ids, resids, "{name}");
        let charges = all.property("charge").unwrap();
        for (i, q) in want["charges"].as_array().unwrap().iter().enumerate() {
            assert!(
                (charges[i] as f64 - q.as_f64().unwrap()).abs() < 1e-6,
                "{name} {i}"
            );
        }
        let pos = want["positions"][0].as_array().unwrap();
        for (i, p) in pos.iter().enumerate() {
            let p: Vec<f32> = p
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() as f32)
                .collect();
            assert_eq!(&all.positions[i][..], &p[..], "{name} atom {i}");
        }
        assert!(frames.iter().all(|f| f.segments.is_empty()), "{name}");
    }
}

/// Elements from the AutoDock types: the ligand is 2-bromo-4-chlorobenzamide, C7H5BrClNO,
/// whose three aromatic hydrogens Meeko merges into their carbons (AutoDock's united atoms), so
/// its PDBQT holds C7 H2 Br Cl N O, the carbons typed `A` (aromatic) and `C`, the amide's
/// hydrogens `HD`, its oxygen `OA`.
#[test]
fn elements_follow_the_autodock_types() {
    let (frames, _) = all_frames("ligand.pdbqt");
    let f = &frames[0];
    let count = |e: Element| f.elements.iter().filter(|x| **x == e).count();
    let sym = |s: &str| Element::from_symbol(s).unwrap();
    let got: Vec<usize> = ["C", "H", "Br", "Cl", "N", "O"]
        .iter()
        .map(|s| count(sym(s)))
        .collect();
    assert_eq!(got, [7, 2, 1, 1, 1, 1]);
    for (e, t) in f.elements.iter().zip(&f.types) {
        let want = match t.as_str() {
            "A" | "C" => "C",
            "HD" => "H",
            "OA" => "O",
            "N" | "NA" => "N",
            other => other,
        };
        assert_eq!(*e, sym(want), "type {t:?}");
    }
}

/// Vina's poses are frames, each titled by its `REMARK VINA RESULT` line: the score is the
/// one Vina's Python API reported for that pose.
#[test]
fn poses_are_frames_titled_by_their_vina_score() {
    let r = reference();
    let energies = r["poses.pdbqt"]["vina_energies"].as_array().unwrap();
    let (frames, _) = all_frames("poses.pdbqt");
    assert_eq!(frames.len(), energies.len());
    for (f, e) in frames.iter().zip(energies) {
        assert_eq!(f.n_atoms(), 13);
        let title = f.comment.strip_prefix("VINA RESULT: ").unwrap();
        assert_eq!(title.split(' ').count(), 3, "{title}");
        let score: f64 = title.split_whitespace().next().unwrap().parse().unwrap();
        assert!(
            (score - e[0].as_f64().unwrap()).abs() < 5e-4,
            "{title} vs {e}"
        );
    }
}

/// A damaged charge or type column is an error at its line and column, not a silent default.
#[test]
fn damaged_columns_are_located() {
    let text = std::fs::read_to_string(path("ligand.pdbqt")).unwrap();
    let k = text.lines().position(|l| l.starts_with("ATOM")).unwrap();
    for (at, junk, want) in [
        (70, "x", "a partial charge in columns 67-76"),
        (77, " ", "an AutoDock atom type in columns 78-79"),
    ] {
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        lines[k].replace_range(at..at + 1, junk);
        if junk == " " {
            lines[k].truncate(77);
        }
        let bad = lines.join("\n") + "\n";
        let mut t = Trajectory::from_reader(
            std::io::Cursor::new(bad.into_bytes()),
            Format::Pdbqt,
            "bad.pdbqt",
        )
        .unwrap();
        let e = t.read_next(&mut Frame::new()).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("bad.pdbqt: frame 0, line {}", k + 1)),
            "{e}"
        );
        assert!(e.contains(want), "{e}");
    }
}
