//! The per-frame analyses a plan runs before styling (`MolOptions::coordination` after
//! `MolOptions::replicate`), against OVITO 3.17: the atoms `prop coordination < 12` keeps of a
//! jiggled FCC crystal with a vacancy cluster are exactly those OVITO's Coordination analysis
//! counts fewer than 12 neighbours for (md-io's cna fixture and reference), and replicating the
//! periodic crystal first changes no atom's count: every copy of an atom has its count.

use std::path::Path;

use texmap_md_io::{Frame, Selection, Trajectory};
use texmap_md_scene::{COORDINATION, MolOptions, MolPlan, SceneBuilder, SphereScene, StyleOptions};

fn cna(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data/cna")
        .join(name)
}

fn fcc() -> Frame {
    let mut t = Trajectory::open(cna("crystals.xyz.gz")).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    f
}

/// The frame after the plan's steps, and the scene drawn from it.
fn build(options: MolOptions) -> (Frame, SphereScene) {
    let mut plan = MolPlan::new(options).unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let (mut frame, mut scene) = (fcc(), SphereScene::default());
    plan.build(&mut builder, &mut frame, &mut scene).unwrap();
    (frame, scene)
}

#[test]
fn the_under_coordinated_atoms_are_ovitos() {
    let text = std::fs::read_to_string(cna("coordination_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let ovito: Vec<u64> = v["frames"][0]["2.9"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    let (frame, scene) = build(MolOptions {
        coordination: Some(2.9),
        select: Some(Selection::parse("prop coordination < 12").unwrap()),
        ..MolOptions::default()
    });
    let want: Vec<[f32; 3]> = (0..ovito.len())
        .filter(|&i| ovito[i] < 12)
        .map(|i| frame.positions[i])
        .collect();
    assert_eq!(want.len(), 24);
    let got: Vec<[f32; 3]> = scene.centers.iter().map(|c| c.to_array()).collect();
    assert_eq!(got, want);
}

#[test]
fn replicating_first_keeps_every_count() {
    let (one, _) = build(MolOptions {
        coordination: Some(4.0),
        ..MolOptions::default()
    });
    let (many, _) = build(MolOptions {
        coordination: Some(4.0),
        replicate: Some([2, 1, 2]),
        ..MolOptions::default()
    });
    let counts = |f: &Frame| f.property(COORDINATION).unwrap().to_vec();
    assert_eq!(counts(&many), counts(&one).repeat(4));
}
