//! Several representations in one scene (`MolOptions::reps`): the scene of a protein's tube, a
//! DNA strand's balls and sticks and the waters as licorice is exactly the three scenes each
//! representation makes alone, concatenated, each bond with its own style's radius (per-bond
//! radii are checked against the reference ray tracer in the impostor crate's tests/bonds.rs).
//! A representation with its own colouring colours its atoms exactly as a builder with that
//! colouring does, and the colour rules win over it.

use std::path::Path;

use texmap_md_io::{Frame, Selection, Trajectory};
use texmap_md_scene::{
    BALL_AND_STICK_BOND_RADIUS, ColorBy, DrawStyle, LICORICE_RADIUS, MolOptions, MolPlan, RepColor,
    Representation, SceneBuilder, SphereScene, StyleOptions,
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
        color: None,
    }
}

/// Each sphere's material colour as 8-bit sRGB.
fn colours(scene: &SphereScene) -> Vec<[u8; 3]> {
    scene
        .kinds
        .iter()
        .map(|&k| {
            let m = scene.materials[k as usize].base_color;
            [m.x, m.y, m.z].map(texmap_core::color::linear_to_srgb8_exact)
        })
        .collect()
}

/// The scene of `options` with a builder colouring by `color_by`.
fn build_with(options: MolOptions, color_by: ColorBy, frame: &mut Frame) -> SphereScene {
    let mut plan = MolPlan::new(options).unwrap();
    let style = StyleOptions {
        color_by,
        ..StyleOptions::default()
    };
    let mut builder = SceneBuilder::new(&style).unwrap();
    let mut scene = SphereScene::default();
    plan.build(&mut builder, frame, &mut scene).unwrap();
    scene
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

#[test]
fn a_representations_own_colouring_is_that_colourings_scene() {
    let red = [1.0, 0.0, 0.0];
    let green = [0.0, 1.0, 0.0];
    let own = |sel: &str, draw, color| Representation {
        color: Some(color),
        ..rep(sel, draw)
    };
    let reps = vec![
        own("protein", DrawStyle::Tube, RepColor::By(ColorBy::Structure)),
        own(
            "nucleic",
            DrawStyle::BallStick,
            RepColor::By(ColorBy::Chain),
        ),
        own("resname SOL", DrawStyle::Licorice, RepColor::Fixed(red)),
        rep("resname NA", DrawStyle::Spacefill),
    ];
    // A colour rule on the nucleic phosphorus atoms wins over the chain colours.
    let rule = || vec![(Selection::parse("name P").unwrap(), green)];
    let options = MolOptions {
        reps: reps.clone(),
        colors: rule(),
        ..MolOptions::default()
    };
    let all = build_with(options, ColorBy::Type, &mut frame());
    let all_colours = colours(&all);
    let mut offset = 0;
    let mut ruled = 0;
    for r in &reps {
        // The representation alone, drawn by a builder whose own colouring is the
        // representation's (the sodium ions: the outer builder's, by type).
        let color_by = match r.color {
            Some(RepColor::By(c)) => c,
            _ => ColorBy::Type,
        };
        let alone_options = MolOptions {
            reps: vec![Representation {
                color: None,
                ..r.clone()
            }],
            colors: rule(),
            ..MolOptions::default()
        };
        let mut f = frame();
        let alone = build_with(alone_options, color_by, &mut f);
        let n = alone.len();
        assert!(n > 0);
        let part = &all_colours[offset..offset + n];
        match r.color {
            Some(RepColor::Fixed(_)) => assert!(part.iter().all(|c| *c == [255, 0, 0])),
            _ => assert_eq!(part, &colours(&alone)[..], "{:?}", r.color),
        }
        ruled += part.iter().filter(|c| **c == [0, 255, 0]).count();
        offset += n;
    }
    assert_eq!(offset, all.len());
    // The rule reached the ball-and-stick phosphorus atoms (P only; the tube has none).
    let phosphorus = frame().names.iter().filter(|n| n.as_str() == "P").count();
    assert!(phosphorus > 0);
    assert_eq!(ruled, phosphorus);
    // The protein really is in structure colours and the nucleic acid in more than one colour
    // per chain: the colourings are not all the default.
    let structure: Vec<[u8; 3]> = texmap_md_scene::STRUCTURE_COLORS
        .iter()
        .map(|c| c.map(|v| (v * 255.0).round() as u8))
        .collect();
    let tube = build_with(
        MolOptions {
            reps: vec![reps[0].clone()],
            ..MolOptions::default()
        },
        ColorBy::Element,
        &mut frame(),
    );
    assert!(colours(&tube).iter().all(|c| structure.contains(c)));
}

#[test]
fn a_representation_coloured_by_the_file_keeps_the_colour_column() {
    // Three carbons with a colour column, drawn by an element-colouring builder (which drops
    // the column) in one representation coloured by the file's colours.
    let mut f = Frame::new();
    f.positions = vec![[0.0, 0.0, 0.0], [5.0, 0.0, 0.0], [10.0, 0.0, 0.0]];
    f.elements = vec![texmap_md_io::Element::from_symbol("C").unwrap(); 3];
    f.colors = vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]];
    let options = || MolOptions {
        reps: vec![
            Representation {
                select: None,
                draw: DrawStyle::Spacefill,
                color: Some(RepColor::By(ColorBy::Property)),
            },
            Representation {
                select: None,
                draw: DrawStyle::Spacefill,
                color: None,
            },
        ],
        ..MolOptions::default()
    };
    let scene = build_with(options(), ColorBy::Element, &mut f.clone());
    let carbon = texmap_md_io::Element::from_symbol("C")
        .unwrap()
        .color()
        .map(|v| (v * 255.0).round() as u8);
    assert_eq!(
        colours(&scene),
        vec![
            [255, 0, 0],
            [0, 0, 255],
            [255, 255, 0],
            carbon,
            carbon,
            carbon
        ]
    );
}
