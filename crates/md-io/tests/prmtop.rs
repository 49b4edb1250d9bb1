//! AMBER prmtop files written by ParmEd 4.3.1 (tests/data/gen_prmtop.py) against what MDAnalysis
//! 2.11 reads from them (prmtop_reference.json), the prmtop labelling the AMBER NetCDF trajectory
//! of the same atoms, and damaged copies giving located errors.

use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Frame, Topology, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect()
}

fn labels(v: &[texmap_md_io::Label]) -> Vec<String> {
    v.iter().map(|l| l.as_str().to_string()).collect()
}

#[test]
fn prmtops_written_by_parmed_read_as_mdanalysis_reads_them() {
    let all: Value =
        serde_json::from_str(&std::fs::read_to_string(path("prmtop_reference.json")).unwrap())
            .unwrap();
    for name in ["prmtop_parmed.prmtop", "prmtop_chains.parm7"] {
        let r = &all[name];
        let t = Topology::open(path(name)).unwrap();
        assert_eq!(t.n_atoms() as u64, r["n_atoms"].as_u64().unwrap(), "{name}");
        assert_eq!(labels(&t.names), strings(&r["names"]), "{name}");
        assert_eq!(labels(&t.types), strings(&r["types"]), "{name}");
        assert_eq!(labels(&t.res_names), strings(&r["resnames"]), "{name}");
        let resids: Vec<i64> = r["resids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_i64().unwrap())
            .collect();
        assert_eq!(t.res_ids, resids, "{name}");
        let elements: Vec<String> = t
            .elements
            .iter()
            .map(|e| e.symbol().to_ascii_uppercase())
            .collect();
        let want: Vec<String> = strings(&r["elements"])
            .iter()
            .map(|s| s.to_ascii_uppercase())
            .collect();
        assert_eq!(elements, want, "{name}");
        let bonds: Vec<[u32; 2]> = r["bonds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| [b[0].as_u64().unwrap() as u32, b[1].as_u64().unwrap() as u32])
            .collect();
        assert!(!bonds.is_empty());
        assert_eq!(t.bonds, bonds, "{name}");
        let charges: Vec<f64> = r["charges"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(t.charges.len(), charges.len(), "{name}");
        for (q, w) in t.charges.iter().zip(&charges) {
            assert!((*q as f64 - w).abs() < 1e-6, "{name}: charge {q} vs {w}");
        }
        match r.get("chains") {
            Some(c) => assert_eq!(labels(&t.chains), strings(c), "{name}"),
            None => assert!(t.chains.is_empty(), "{name}"),
        }
    }
}

/// The AMBER user's pair: the prmtop names the atoms of the NetCDF trajectory (written by
/// MDAnalysis from the same PDB) in every frame, and moves none.
#[test]
fn prmtop_labels_the_amber_netcdf_trajectory_of_the_same_atoms() {
    let t = Topology::open(path("prmtop_parmed.prmtop")).unwrap();
    let pdb = Topology::open(path("topo_mda.pdb")).unwrap();
    assert_eq!(t.names, pdb.names);
    assert_eq!(t.elements, pdb.elements);
    assert_eq!(t.bonds, pdb.bonds, "ParmEd kept the PDB's CONECT bonds");
    let mut traj = Trajectory::open(path("amber_mda.ncdf")).unwrap();
    let mut f = Frame::new();
    let mut frames = 0;
    while traj.read_next(&mut f).unwrap() {
        let positions = f.positions.clone();
        t.apply(&mut f, "amber_mda.ncdf", frames).unwrap();
        assert_eq!(f.positions, positions, "the topology never moves atoms");
        assert_eq!(f.names, t.names);
        frames += 1;
    }
    assert_eq!(frames, 4);
}

fn damaged(edit: impl Fn(&str) -> String) -> String {
    let text = std::fs::read_to_string(path("prmtop_parmed.prmtop")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.prmtop");
    std::fs::write(&p, edit(&text)).unwrap();
    Topology::open(&p).unwrap_err().to_string()
}

/// Line number (1-based) of the first line of `text` starting with `prefix`.
fn line_of(text: &str, prefix: &str) -> usize {
    text.lines().position(|l| l.starts_with(prefix)).unwrap() + 1
}

#[test]
fn damaged_prmtops_are_located_errors() {
    let text = std::fs::read_to_string(path("prmtop_parmed.prmtop")).unwrap();
    // Cut inside the atom names: the section holds fewer names than POINTERS announces.
    let e = damaged(|t| {
        let k = line_of(t, "%FLAG ATOM_NAME") + 2;
        t.lines().take(k).map(|l| format!("{l}\n")).collect()
    });
    let flag = line_of(&text, "%FLAG ATOM_NAME");
    assert!(
        e.contains(&format!("line {flag}")) && e.contains("holds 20 names") && e.contains("66"),
        "{e}"
    );
    // POINTERS claiming 10^8 atoms: a count error, not a huge allocation.
    let e = damaged(|t| t.replacen("      66      13", "99999999      13", 1));
    assert!(
        e.contains("holds 66 names") && e.contains("99999999"),
        "{e}"
    );
    // A bond entry that is not 3*(atom-1).
    let e = damaged(|t| {
        let k = line_of(t, "%FLAG BONDS_INC_HYDROGEN") + 1;
        let mut lines: Vec<String> = t.lines().map(String::from).collect();
        lines[k] = format!("{:>8}{}", 4, &lines[k][8..]);
        lines.join("\n") + "\n"
    });
    assert!(
        e.contains("BONDS_INC_HYDROGEN") && e.contains("3*(atom-1)"),
        "{e}"
    );
    // A mass that is not a number, located by its line.
    let mass_line = line_of(&text, "%FLAG MASS") + 2;
    let e = damaged(|t| {
        let mut lines: Vec<String> = t.lines().map(String::from).collect();
        lines[mass_line - 1].replace_range(4..8, "x.yz");
        lines.join("\n") + "\n"
    });
    assert!(
        e.contains(&format!("line {mass_line}")) && e.contains("number"),
        "{e}"
    );
    // A GROMACS topology under a prmtop name.
    let e = damaged(|_| "; topol.top\n[ defaults ]\n".into());
    assert!(e.contains("line 1") && e.contains("GROMACS"), "{e}");
    // A section missing altogether.
    let e = damaged(|t| t.replace("%FLAG RESIDUE_POINTER", "%FLAG RESIDUE_POINTERS"));
    assert!(e.contains("RESIDUE_POINTER"), "{e}");
}
