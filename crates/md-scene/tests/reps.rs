//! Several representations in one scene (`MolOptions::reps`): the scene of a protein's tube, a
//! DNA strand's balls and sticks and the waters as licorice is exactly the three scenes each
//! representation makes alone, concatenated, each bond with its own style's radius (per-bond
//! radii are checked against the reference ray tracer in the impostor crate's tests/bonds.rs).

use std::path::Path;

use texmap_md_io::{Frame, Selection, Trajectory};
use texmap_md_scene::{
    BALL_AND_STICK_BOND_RADIUS, DrawStyle, LICORICE_RADIUS, MolOptions, MolPlan, Representation,
    SceneBuilder, SphereScene, StyleOptions,
};

fn frame() -> Frame {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-io/tests/data/chains_mda.pdb");
    let mut t = Trajectory::open(p).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    f
}

fn build(reps: Vec<Representation>) -> SphereScene {
    let mut plan = MolPlan::new(MolOptions {
        reps,
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut scene = SphereScene::default();
    plan.build(&mut builder, &mut frame(), &mut scene).unwrap();
    scene
}

fn rep(sel: &str, draw: DrawStyle) -> Representation {
    Representation {
        select: Some(Selection::parse(sel).unwrap()),
        draw,
    }
}

#[test]
fn several_representations_are_each_ones_scene_concatenated() {
    let reps = vec![
        rep("protein", DrawStyle::Tube),
        rep("nucleic", DrawStyle::BallStick),
        rep("resname SOL HOH WAT TIP3", DrawStyle::Licorice),
        rep(
            "not (protein or nucleic or resname SOL HOH WAT TIP3)",
            DrawStyle::Spacefill,
        ),
    ];
    let all = build(reps.clone());
    let mut offset = 0;
    let mut bonds = 0;
    let mut radii_seen = Vec::new();
    for r in &reps {
        let alone = build(vec![r.clone()]);
        assert!(!alone.is_empty());
        let n = alone.len();
        assert_eq!(all.centers[offset..offset + n], alone.centers[..]);
        assert_eq!(all.radii[offset..offset + n], alone.radii[..]);
        assert_eq!(all.kinds[offset..offset + n], alone.kinds[..]);
        for (k, pair) in alone.bonds.iter().enumerate() {
            assert_eq!(all.bonds[bonds + k], pair.map(|i| i + offset as u32));
            assert_eq!(all.bond_radius_of(bonds + k), alone.bond_radius);
        }
        if !alone.bonds.is_empty() {
            radii_seen.push(alone.bond_radius);
        }
        offset += n;
        bonds += alone.bonds.len();
    }
    assert_eq!(all.len(), offset);
    assert_eq!(all.bonds.len(), bonds);
    assert_eq!(all.bond_radii.len(), bonds);
    // Tube and licorice sticks of 0.3 Å and ball-and-stick bonds of 0.2 Å in one scene.
    assert!(radii_seen.contains(&LICORICE_RADIUS));
    assert!(radii_seen.contains(&BALL_AND_STICK_BOND_RADIUS));
}

#[test]
fn one_representation_is_the_plain_select_and_style() {
    let a = build(vec![rep("protein or nucleic", DrawStyle::BallStick)]);
    let mut plan = MolPlan::new(MolOptions {
        select: Some(Selection::parse("protein or nucleic").unwrap()),
        draw: DrawStyle::BallStick,
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut b = SphereScene::default();
    plan.build(&mut builder, &mut frame(), &mut b).unwrap();
    assert_eq!(a, b);
    assert!(a.bond_radii.is_empty());
}
