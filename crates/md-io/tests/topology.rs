//! Topologies read from files MDAnalysis 2.11.0 wrote (tests/data/gen_topology.py), compared with
//! what MDAnalysis itself reads back from each (topology_reference.json), and applied to the XTC
//! and DCD of the same atoms that MDAnalysis wrote.

use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Error, Frame, Topology, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(path("topology_reference.json")).unwrap())
        .unwrap()
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| match x {
            Value::String(s) => s.clone(),
            other => other.to_string(),
        })
        .collect()
}

fn bonds(v: &Value) -> Vec<[u32; 2]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|b| [b[0].as_u64().unwrap() as u32, b[1].as_u64().unwrap() as u32])
        .collect()
}

fn ints(v: &Value) -> Vec<i64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect()
}

fn labels(l: &[texmap_md_io::Label]) -> Vec<String> {
    l.iter().map(|x| x.to_string()).collect()
}

#[test]
fn pdb_topology_matches_mdanalysis_names_residues_and_conect_bonds() {
    let r = &reference()["pdb"];
    let t = Topology::open(path("topo_mda.pdb")).unwrap();
    assert_eq!(t.n_atoms() as u64, r["n_atoms"].as_u64().unwrap());
    assert_eq!(labels(&t.names), strings(&r["names"]));
    assert_eq!(labels(&t.res_names), strings(&r["resnames"]));
    assert_eq!(t.res_ids, ints(&r["resids"]));
    let elements: Vec<String> = t
        .elements
        .iter()
        .map(|e| e.symbol().to_uppercase())
        .collect();
    let expected: Vec<String> = strings(&r["elements"])
        .iter()
        .map(|e| e.to_uppercase())
        .collect();
    assert_eq!(elements, expected);
    assert_eq!(t.bonds, bonds(&r["bonds"]));
    assert_eq!(t.bonds.len(), 53);
    assert_eq!(t.n_residues(), 15);
}

#[test]
fn gro_topology_matches_mdanalysis() {
    let r = &reference()["gro"];
    let t = Topology::open(path("topo_mda.gro")).unwrap();
    assert_eq!(labels(&t.names), strings(&r["names"]));
    assert_eq!(labels(&t.res_names), strings(&r["resnames"]));
    assert!(t.bonds.is_empty());
}

#[test]
fn lammps_data_topology_matches_mdanalysis() {
    let r = &reference()["data"];
    let t = Topology::open(path("topo_mda.data")).unwrap();
    assert_eq!(t.n_atoms() as u64, r["n_atoms"].as_u64().unwrap());
    assert_eq!(labels(&t.types), strings(&r["types"]));
    let ids: Vec<i64> = r["ids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_i64().unwrap())
        .collect();
    assert_eq!(t.ids, ids);
    assert_eq!(t.bonds, bonds(&r["bonds"]));
    // The same bonds as the PDB's CONECT records, through another file format and program path.
    assert_eq!(t.bonds, bonds(&reference()["pdb"]["bonds"]));
    // The charges gen_topology.py gave MDAnalysis (atom i: 0.1 * ((i % 5) - 2) e), which the
    // frames it labels carry as their `charge` property.
    let want: Vec<f32> = (0..t.n_atoms())
        .map(|i| (0.1 * ((i % 5) as f64 - 2.0)) as f32)
        .collect();
    assert!(
        t.charges
            .iter()
            .zip(&want)
            .all(|(q, w)| (q - w).abs() < 1e-6),
        "{:?}",
        t.charges
    );
    let mut traj = Trajectory::open(path("amber_mda.ncdf")).unwrap();
    let mut f = Frame::new();
    assert!(traj.read_next(&mut f).unwrap());
    t.apply(&mut f, "amber_mda.ncdf", 0).unwrap();
    assert_eq!(f.property("charge"), Some(&t.charges[..]));
}

#[test]
fn topology_gives_names_to_every_frame_of_an_xtc_and_a_dcd() {
    let r = reference();
    let t = Topology::open(path("topo_mda.gro")).unwrap();
    for traj_name in ["topo_mda.xtc", "topo_mda.dcd"] {
        let mut traj = Trajectory::open(path(traj_name)).unwrap();
        assert_eq!(
            traj.n_frames().unwrap() as u64,
            r["xtc_frames"].as_u64().unwrap()
        );
        let mut f = Frame::new();
        let mut k = 0;
        while traj.read_next(&mut f).unwrap() {
            assert!(f.names.is_empty(), "{traj_name} carries no names itself");
            t.apply(&mut f, traj.name(), k).unwrap();
            assert_eq!(labels(&f.names), strings(&r["gro"]["names"]));
            assert_eq!(f.elements[2].symbol(), "C");
            k += 1;
        }
        assert_eq!(k, 4);
    }
}

#[test]
fn count_mismatch_names_both_files() {
    // The select fixture has 30·10 + 200·3 + 5 = 905 atoms; the XTC 66.
    let t = Topology::open(path("select_mda.pdb")).unwrap();
    let mut traj = Trajectory::open(path("topo_mda.xtc")).unwrap();
    let mut f = Frame::new();
    traj.read_next(&mut f).unwrap();
    let e = t.apply(&mut f, traj.name(), 0).unwrap_err();
    assert!(matches!(e, Error::TopologyMismatch { .. }));
    let s = e.to_string();
    assert!(
        s.contains("select_mda.pdb") && s.contains("topo_mda.xtc"),
        "{s}"
    );
    assert!(s.contains("905") && s.contains("66"), "{s}");
}

#[test]
fn unknown_topology_extension_is_refused_with_the_name() {
    let e = Topology::open(path("topo_mda.xtc"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("topo_mda.xtc") && e.contains("topology"), "{e}");
}

/// A PSF written by ParmEd 4.3 from the same PDB (tests/data/gen_psf.py), against what
/// MDAnalysis reads from that PSF; the elements (which a PSF does not store) against the PDB's.
#[test]
fn psf_written_by_parmed_matches_mdanalysis_and_gives_the_pdb_elements() {
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(path("psf_reference.json")).unwrap())
            .unwrap();
    let t = Topology::open(path("psf_parmed.psf")).unwrap();
    assert_eq!(t.n_atoms() as u64, r["n_atoms"].as_u64().unwrap());
    assert_eq!(labels(&t.names), strings(&r["names"]));
    assert_eq!(labels(&t.res_names), strings(&r["resnames"]));
    assert_eq!(labels(&t.types), strings(&r["types"]));
    assert_eq!(t.res_ids, ints(&r["resids"]));
    assert_eq!(t.bonds, bonds(&r["bonds"]));
    // Segments as MDAnalysis reads them (tests/data/gen_chains.py).
    let chains: Value =
        serde_json::from_str(&std::fs::read_to_string(path("chains_reference.json")).unwrap())
            .unwrap();
    assert_eq!(labels(&t.segments), strings(&chains["psf_segments"]));
    let pdb = Topology::open(path("topo_mda.pdb")).unwrap();
    assert_eq!(t.elements, pdb.elements);
    // And it labels the XTC of the same atoms.
    let mut traj = Trajectory::open(path("topo_mda.xtc")).unwrap();
    let mut f = Frame::new();
    assert!(traj.read_next(&mut f).unwrap());
    t.apply(&mut f, "topo_mda.xtc", 0).unwrap();
    assert_eq!(labels(&f.names), strings(&r["names"]));
    assert_eq!(f.segments, t.segments);
}

/// A GROMACS OPLS-AA topology names its residues as GROMOS did (LYSH, HISB, CYSH): MDAnalysis
/// 2.11 selects the 3,341 atoms of adenylate kinase as `protein` and guesses their elements as
/// H 1,685, C 1,040, O 320, N 289, S 7 (`u.select_atoms('protein')`, `DefaultGuesser
/// .guess_types(p.names)` on hbonds/adk_top.gro.gz). "CA" in LYSH is its α carbon, not calcium.
#[test]
fn gromos_residue_names_are_protein_with_organic_elements() {
    let top = Topology::open(path("hbonds/adk_top.gro.gz")).unwrap();
    let mut frame = Frame::new();
    let mut t = Trajectory::open(path("hbonds/adk_0_9.xtc")).unwrap();
    assert!(t.read_next(&mut frame).unwrap());
    top.apply(&mut frame, "adk_0_9.xtc", 0).unwrap();
    let protein = texmap_md_io::select::Selection::parse("protein")
        .unwrap()
        .evaluate(&frame)
        .unwrap();
    let mut counts = std::collections::BTreeMap::new();
    for i in (0..frame.n_atoms()).filter(|&i| protein[i]) {
        *counts
            .entry(texmap_md_io::atom_element(&frame, i).symbol())
            .or_insert(0) += 1;
    }
    let want = [("C", 1040), ("H", 1685), ("N", 289), ("O", 320), ("S", 7)];
    assert_eq!(counts.into_iter().collect::<Vec<_>>(), want);
}
