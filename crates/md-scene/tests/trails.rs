//! Trails (`DrawStyle::Trails`): the path of each atom picked at the first frame, one point per
//! frame built, unwrapped through the box, as many frames long as asked, drawn as spheres joined
//! by sticks; the other atoms leave no trail.

use glam::Vec3;
use texmap_md_io::{Element, Frame, Label, Selection, UnitCell};
use texmap_md_scene::{
    DrawStyle, MolError, MolOptions, MolPlan, Representation, SceneBuilder, SphereScene,
    StyleOptions, TRAIL_RADIUS,
};

/// Two argon atoms in a 10 Å box: atom 0 walks +1.5 Å in x per frame from x = 7 (wrapped into
/// the box as a trajectory writer wraps it), atom 1 stays at the centre.
fn frame(k: usize, cell: bool) -> Frame {
    let mut f = Frame::new();
    let x = (7.0 + 1.5 * k as f32) % 10.0;
    f.positions = vec![[x, 2.0, 3.0], [5.0, 5.0, 5.0]];
    f.elements = vec![Element::from_symbol("Ar").unwrap(); 2];
    f.names = vec![Label::new("AR").unwrap(); 2];
    if cell {
        f.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
    }
    f
}

fn plan(length: Option<usize>) -> MolPlan {
    MolPlan::new(MolOptions {
        reps: vec![Representation {
            select: Some(Selection::parse("index 0").unwrap()),
            draw: DrawStyle::Trails,
            color: None,
        }],
        trail_length: length,
        ..MolOptions::default()
    })
    .unwrap()
}

fn build(plan: &mut MolPlan, mut f: Frame) -> Result<SphereScene, MolError> {
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut scene = SphereScene::default();
    plan.build(&mut builder, &mut f, &mut scene)?;
    Ok(scene)
}

#[test]
fn a_trail_follows_its_atom_across_the_box_face() {
    let mut p = plan(None);
    let mut scene = SphereScene::default();
    for k in 0..5 {
        scene = build(&mut p, frame(k, true)).unwrap();
    }
    // Unwrapped, 7, 8.5, 10, 11.5, 13 (the file says 7, 8.5, 0, 1.5, 3), drawn ending at the
    // atom's 3: out of the box through the face it came in by.
    let xs: Vec<f32> = scene.centers.iter().map(|c| c.x).collect();
    assert_eq!(xs, [-3.0, -1.5, 0.0, 1.5, 3.0]);
    assert!(scene.centers.iter().all(|c| c.y == 2.0 && c.z == 3.0));
    assert!(scene.radii.iter().all(|r| *r == TRAIL_RADIUS));
    assert_eq!(scene.bonds, [[0, 1], [1, 2], [2, 3], [3, 4]]);
    assert!(p.draws_bonds());
    // Atom 1 leaves none; the trail's record names atom 0.
    let trails: Vec<(u32, Vec<Vec3>)> = p
        .trails()
        .map(|(i, t)| (i, t.iter().copied().collect()))
        .collect();
    assert_eq!(trails.len(), 1);
    assert_eq!(trails[0].0, 0);
    assert_eq!(trails[0].1.last(), Some(&Vec3::new(13.0, 2.0, 3.0)));
}

#[test]
fn a_trail_is_as_long_as_asked_and_without_a_box_it_jumps() {
    let mut p = plan(Some(3));
    let mut scene = SphereScene::default();
    for k in 0..5 {
        scene = build(&mut p, frame(k, true)).unwrap();
    }
    let xs: Vec<f32> = scene.centers.iter().map(|c| c.x).collect();
    assert_eq!(xs, [0.0, 1.5, 3.0]);
    assert_eq!(scene.bonds, [[0, 1], [1, 2]]);
    // No cell: the positions as written, back across.
    let mut p = plan(None);
    for k in 0..4 {
        scene = build(&mut p, frame(k, false)).unwrap();
    }
    let xs: Vec<f32> = scene.centers.iter().map(|c| c.x).collect();
    assert_eq!(xs, [7.0, 8.5, 0.0, 1.5]);
}

#[test]
fn a_frame_without_the_followed_atom_is_an_error() {
    let mut p = plan(None);
    build(&mut p, frame(0, true)).unwrap();
    let mut small = frame(1, true);
    small.positions.truncate(0);
    small.elements.truncate(0);
    small.names.truncate(0);
    let e = build(&mut p, small).unwrap_err();
    assert!(
        matches!(e, MolError::TrailAtoms { atom: 0, frame: 0 }),
        "{e}"
    );
}

/// `MolOptions::displacement`: each frame's `displacement` property is every atom's distance
/// from the first frame built, the short way through the box, and selections can use it.
#[test]
fn displacements_are_a_property_selections_see() {
    let mut p = MolPlan::new(MolOptions {
        displacement: true,
        select: Some(Selection::parse("prop displacement > 2").unwrap()),
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    for k in 0..4 {
        let mut f = frame(k, true);
        let mut scene = SphereScene::default();
        p.build(&mut builder, &mut f, &mut scene).unwrap();
        let d = f.property(texmap_md_scene::DISPLACEMENT).unwrap();
        // Atom 0 has walked 1.5 Å a frame (through the face at k = 2); atom 1 stays.
        assert!((d[0] - 1.5 * k as f32).abs() < 1e-5, "frame {k}: {d:?}");
        assert_eq!(d[1], 0.0);
        assert_eq!(scene.centers.len(), usize::from(k >= 2), "frame {k}");
    }
}

/// `MolPlan::set_displacement_reference`: displacements from a frame given beforehand (here
/// frame 3, walked through the box face), not from the first frame built; the reference is
/// replicated with the frames, and one of another atom count is an error of the build.
#[test]
fn displacements_measure_from_a_given_reference() {
    let mut p = MolPlan::new(MolOptions {
        displacement: true,
        ..MolOptions::default()
    })
    .unwrap();
    let mut reference = frame(3, true);
    p.set_displacement_reference(&mut reference).unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    for k in [0usize, 3, 5] {
        let mut f = frame(k, true);
        let mut scene = SphereScene::default();
        p.build(&mut builder, &mut f, &mut scene).unwrap();
        let d = f.property(texmap_md_scene::DISPLACEMENT).unwrap();
        let want = 1.5 * (k as f32 - 3.0).abs();
        assert!((d[0] - want).abs() < 1e-5, "frame {k}: {d:?}");
        assert_eq!(d[1], 0.0);
    }
    // Replicated 2x1x1: the reference is too, image by image.
    let mut p = MolPlan::new(MolOptions {
        displacement: true,
        replicate: Some([2, 1, 1]),
        ..MolOptions::default()
    })
    .unwrap();
    p.set_displacement_reference(&mut frame(3, true)).unwrap();
    let mut f = frame(4, true);
    p.build(&mut builder, &mut f, &mut SphereScene::default())
        .unwrap();
    let d = f.property(texmap_md_scene::DISPLACEMENT).unwrap();
    assert_eq!(d.len(), 4);
    for (i, v) in d.iter().enumerate() {
        let want = if i % 2 == 0 { 1.5 } else { 0.0 };
        assert!((v - want).abs() < 1e-5, "atom {i}: {d:?}");
    }
    // A reference of another atom count.
    let mut p = MolPlan::new(MolOptions {
        displacement: true,
        ..MolOptions::default()
    })
    .unwrap();
    let mut one = frame(0, true);
    one.positions.truncate(1);
    one.elements.truncate(1);
    one.names.truncate(1);
    p.set_displacement_reference(&mut one).unwrap();
    let e = p
        .build(
            &mut builder,
            &mut frame(1, true),
            &mut SphereScene::default(),
        )
        .unwrap_err();
    assert!(
        e.to_string().contains('1') && e.to_string().contains('2'),
        "{e}"
    );
}
