//! Secondary structure (`secondary::assign`) against MDAnalysis 2.11's `DSSP` (its pydssp C3
//! reduction of Kabsch & Sander) on twelve wwPDB chains from MDAnalysis's own DSSP test set
//! (tests/data/dssp/, the reference written by tests/data/gen_dssp.py).

use std::path::{Path, PathBuf};

use serde_json::Value;
use texmap_md_io::secondary::{self, Structure};
use texmap_md_io::{Frame, Trajectory};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/dssp")
}

fn first_frame(p: &Path) -> Frame {
    let mut t = Trajectory::open(p).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap(), "{}", p.display());
    f
}

fn reference() -> serde_json::Map<String, Value> {
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("reference.json")).unwrap())
            .unwrap();
    r.as_object().unwrap().clone()
}

#[test]
fn every_chain_is_assigned_as_mdanalysis_assigns_it() {
    let r = reference();
    assert_eq!(r.len(), 12);
    let mut counts = [0usize; 3];
    for (name, e) in &r {
        let f = first_frame(&dir().join(name));
        let ss = secondary::assign(&f);
        let ids: Vec<i64> = ss.residues().iter().map(|x| x.res_id).collect();
        let want: Vec<i64> = e["resids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_i64().unwrap())
            .collect();
        assert_eq!(ids, want, "{name}: residues");
        assert_eq!(ss.codes(), e["dssp"].as_str().unwrap(), "{name}");
        // Whole chains: nothing breaks them.
        assert_eq!(
            ss.residues().iter().filter(|x| x.starts_piece).count(),
            1,
            "{name}"
        );
        for (k, c) in counts.iter_mut().enumerate() {
            *c += ss.counts()[k];
        }
        // Every atom of a residue takes its class; no other atom has one.
        let per_atom = ss.per_atom(f.n_atoms());
        for (res, c) in ss.residues().iter().zip(ss.classes()) {
            assert!(per_atom[res.atoms.clone()].iter().all(|a| *a == Some(*c)));
        }
        let in_residues: usize = ss.residues().iter().map(|x| x.atoms.len()).sum();
        assert_eq!(per_atom.iter().filter(|a| a.is_some()).count(), in_residues);
    }
    // The set holds all three classes in numbers.
    assert!(counts.iter().all(|&c| c > 300), "{counts:?}");
}

#[test]
fn the_assignment_does_not_depend_on_where_the_protein_lies() {
    let r = reference();
    for name in ["1h4aX.pdb.gz", "4gcnA.pdb.gz"] {
        let mut f = first_frame(&dir().join(name));
        // A rotation about z by 90 degrees and a shift across cell boundaries of the grid.
        for p in &mut f.positions {
            *p = [-p[1] + 1234.5, p[0] - 987.25, p[2] + 2.5];
        }
        assert_eq!(
            secondary::assign(&f).codes(),
            r[name]["dssp"].as_str().unwrap(),
            "{name}"
        );
    }
}

#[test]
fn a_chain_broken_in_two_is_its_two_halves() {
    // The second half moved 100 A away: the peptide bond between the halves is broken, no
    // hydrogen bond reaches across, and no turn or bridge may span the break. Each half is
    // then what MDAnalysis assigns to that half on its own.
    let r = reference();
    let mut n = 0;
    for (name, e) in &r {
        let Some(split) = e.get("split") else {
            continue;
        };
        n += 1;
        let at = split["at"].as_i64().unwrap();
        let mut f = first_frame(&dir().join(name));
        for (p, &id) in f.positions.iter_mut().zip(&f.res_ids) {
            if id >= at {
                p[0] += 100.0;
            }
        }
        let ss = secondary::assign(&f);
        let want = format!(
            "{}{}",
            split["first"].as_str().unwrap(),
            split["second"].as_str().unwrap()
        );
        assert_eq!(ss.codes(), want, "{name}");
        let starts: Vec<i64> = ss
            .residues()
            .iter()
            .filter(|x| x.starts_piece)
            .map(|x| x.res_id)
            .collect();
        assert_eq!(starts[1..], [at], "{name}");
    }
    assert_eq!(n, 3);
}

#[test]
fn a_residue_without_its_backbone_is_left_out_and_breaks_the_chain() {
    // MDAnalysis refuses this file (unequal numbers of N, CA, C and O); here residue 219,
    // which has no C and O, is skipped and the chain breaks after 218.
    let whole = secondary::assign(&first_frame(&dir().join("1mr1D.pdb.gz")));
    let f = first_frame(&dir().join("1mr1D_failing.pdb.gz"));
    let ss = secondary::assign(&f);
    let ids: Vec<i64> = ss.residues().iter().map(|x| x.res_id).collect();
    let want: Vec<i64> = whole
        .residues()
        .iter()
        .map(|x| x.res_id)
        .filter(|&id| id != 219)
        .collect();
    assert_eq!(ids, want);
    let k = ids.iter().position(|&id| id == 220).unwrap();
    assert!(ss.residues()[k].starts_piece);
    // The atoms of 219 have no class.
    let per_atom = ss.per_atom(f.n_atoms());
    for (i, a) in per_atom.iter().enumerate() {
        if f.res_ids[i] == 219 {
            assert_eq!(*a, None);
        }
    }
}

#[test]
fn frames_without_residues_or_backbones_have_no_structure() {
    let mut f = Frame::new();
    f.positions = vec![[0.0; 3]; 4];
    assert!(secondary::assign(&f).residues().is_empty());
    // Names and residues, but no residue has all of N, CA, C and O.
    for (k, name) in ["N", "CA", "C", "CB"].iter().enumerate() {
        f.names.push(texmap_md_io::Label::new(name).unwrap());
        f.res_names.push(texmap_md_io::Label::new("ALA").unwrap());
        f.res_ids.push(k as i64 / 2);
    }
    let ss = secondary::assign(&f);
    assert!(ss.residues().is_empty());
    assert_eq!(ss.per_atom(4), vec![None::<Structure>; 4]);
}

#[test]
fn vmd_structure_keywords_select_the_residues_mdanalysis_assigns() {
    let r = reference();
    for name in ["3gwiA.pdb.gz", "3e8mA.pdb.gz"] {
        let f = first_frame(&dir().join(name));
        let codes: Vec<char> = r[name]["dssp"].as_str().unwrap().chars().collect();
        let ca = texmap_md_io::Selection::parse("name CA")
            .unwrap()
            .indices(&f)
            .unwrap();
        let ca_sel = |text: &str| -> Vec<usize> {
            let on = texmap_md_io::Selection::parse(text)
                .unwrap()
                .evaluate(&f)
                .unwrap();
            ca.iter().filter(|&&i| on[i]).copied().collect()
        };
        for (text, code) in [
            ("helix", 'H'),
            ("sheet", 'E'),
            ("betasheet", 'E'),
            ("beta_sheet", 'E'),
            ("coil", '-'),
        ] {
            // The CA atoms of protein residues, in order, are the reference's residues.
            let want: Vec<usize> = ca
                .iter()
                .zip(&codes)
                .filter(|(_, c)| **c == code)
                .map(|(i, _)| *i)
                .collect();
            assert!(!want.is_empty(), "{name} {text}");
            assert_eq!(
                ca_sel(&format!("protein and {text}")),
                want,
                "{name} {text}"
            );
        }
        // Every protein atom is in exactly one class; waters and ligands in none.
        let any = texmap_md_io::Selection::parse("helix or sheet or coil")
            .unwrap()
            .evaluate(&f)
            .unwrap();
        let protein = texmap_md_io::Selection::parse("protein")
            .unwrap()
            .evaluate(&f)
            .unwrap();
        assert_eq!(any, protein, "{name}");
    }
    // A frame without residue names cannot answer.
    let mut f = Frame::new();
    f.positions = vec![[0.0; 3]; 2];
    f.names = vec![texmap_md_io::Label::new("CA").unwrap(); 2];
    let e = texmap_md_io::Selection::parse("name CA or helix")
        .unwrap()
        .evaluate(&f)
        .unwrap_err();
    assert_eq!(e.column, 12, "{e}");
    assert!(e.to_string().contains("residue names"), "{e}");
}

#[test]
fn residues_stacked_on_one_point_are_coil_at_once() {
    // 20,000 alanines with every atom within 1 Å of the origin (a placeholder file): the search
    // would evaluate 4e8 pairs and find hydrogen bonds among most of them; the density guard
    // makes it all coil, with no bond searched.
    let mut f = Frame::new();
    let mut seed = 12345u64;
    let mut jitter = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 1.0
    };
    for r in 0..20_000 {
        for name in ["N", "CA", "C", "O"] {
            f.names.push(texmap_md_io::Label::new(name).unwrap());
            f.res_names.push(texmap_md_io::Label::new("ALA").unwrap());
            f.res_ids.push(r);
            f.positions.push([jitter(), jitter(), jitter()]);
        }
    }
    let ss = secondary::assign(&f);
    assert_eq!(ss.residues().len(), 20_000);
    assert_eq!(ss.hbonds(), 0);
    assert!(ss.classes().iter().all(|c| *c == Structure::Coil));
}
