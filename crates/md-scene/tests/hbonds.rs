//! The hydrogen-bond representation (`DrawStyle::HBonds`) on MDAnalysis's solvated adenylate
//! kinase (md-io's tests/data/hbonds: 47,681 atoms in a triclinic box, bonds by distance): it
//! draws exactly the bonds `texmap_md_io::hbonds` finds among its atoms (which md-io's tests
//! match with MDAnalysis's HydrogenBondAnalysis), each as `HBOND_DASHES` dashes along the
//! hydrogen → acceptor segment (to the acceptor's nearest image), in its colour.

use std::path::Path;

use glam::Vec3;
use texmap_md_io::hbonds::{Criteria, donor_hydrogens, hydrogen_bonds};
use texmap_md_io::{Frame, Selection, Topology, Trajectory};
use texmap_md_scene::{
    BondSource, DrawStyle, HBOND_COLOR, HBOND_DASHES, HBOND_RADIUS, MolError, MolOptions, MolPlan,
    RepColor, Representation, SceneBuilder, SphereScene, StyleOptions,
};

fn adk_frame() -> Frame {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-io/tests/data/hbonds");
    let top = Topology::open(dir.join("adk_top.gro.gz")).unwrap();
    let mut t = Trajectory::open(dir.join("adk_0_9.xtc")).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    top.apply(&mut f, "adk_0_9.xtc", 0).unwrap();
    f
}

fn rep(sel: &str, draw: DrawStyle, color: Option<RepColor>) -> Representation {
    Representation {
        select: Some(Selection::parse(sel).unwrap()),
        draw,
        color,
    }
}

fn build(options: MolOptions, frame: &mut Frame) -> Result<(SphereScene, MolPlan), MolError> {
    let mut plan = MolPlan::new(options)?;
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut scene = SphereScene::default();
    plan.build(&mut builder, frame, &mut scene)?;
    Ok((scene, plan))
}

fn colour(scene: &SphereScene, k: usize) -> [u8; 3] {
    let m = scene.materials[scene.kinds[k] as usize].base_color;
    [m.x, m.y, m.z].map(texmap_core::color::linear_to_srgb8_exact)
}

#[test]
fn draws_each_bond_md_io_finds_as_dashes_from_hydrogen_to_acceptor() {
    let sel = "protein or (resname SOL and same residue as within 4 of protein)";
    let mut frame = adk_frame();
    // The expected bonds, found on the frame as read (no periodic treatment is asked for).
    let mask = Selection::parse(sel).unwrap().evaluate(&frame).unwrap();
    let bonds = texmap_md_io::bonds::bonds_by_distance(&frame, true).pairs;
    let dh = donor_hydrogens(&frame, &bonds);
    let want = hydrogen_bonds(&frame, &dh, Some(&mask), Criteria::default()).unwrap();
    assert!(want.len() > 500, "{}", want.len());

    let options = MolOptions {
        reps: vec![rep(sel, DrawStyle::HBonds, None)],
        ..MolOptions::default()
    };
    let (scene, plan) = build(options, &mut frame).unwrap();
    assert_eq!(plan.last_hbonds(), &want[..]);
    assert_eq!(scene.bonds.len(), want.len() * HBOND_DASHES);
    assert_eq!(scene.len(), 2 * scene.bonds.len());
    assert!(scene.radii.iter().all(|&r| r == HBOND_RADIUS));
    assert_eq!(scene.bond_radius, HBOND_RADIUS);
    let cell = frame.cell.unwrap();
    let mut across = 0;
    for (b, hb) in want.iter().enumerate() {
        let h = Vec3::from(frame.positions[hb.hydrogen as usize]);
        let a = Vec3::from(frame.positions[hb.acceptor as usize]);
        let d = texmap_md_io::pbc::minimum_image(&cell, (a - h).as_dvec3().to_array());
        let seg = glam::DVec3::from(d).as_vec3();
        across += (((a - h) - seg).length() > 1.0) as usize;
        // Every dash's sphere centres on the segment, in order, inside it.
        let first = 2 * HBOND_DASHES * b;
        let mut last_t = -1.0;
        for k in first..first + 2 * HBOND_DASHES {
            let p = scene.centers[k] - h;
            let t = p.dot(seg) / seg.length_squared();
            assert!(t > last_t && (0.0..=1.0).contains(&t), "bond {b}: t {t}");
            assert!((p - seg * t).length() < 1e-4, "bond {b}: off the line");
            last_t = t;
            assert_eq!(
                colour(&scene, k),
                HBOND_COLOR.map(|x| (x * 255.0).round() as u8)
            );
        }
        // The first dash starts at the hydrogen, the last one ends at the acceptor.
        let ends =
            (scene.centers[first] - h).length() + (scene.centers[first + 7] - h - seg).length();
        assert!(
            (ends - 2.0 * HBOND_RADIUS).abs() < 1e-4,
            "bond {b}: ends {ends}"
        );
    }
    assert!(across > 0, "some bond of this frame crosses the box");
}

#[test]
fn a_colour_of_its_own_and_other_representations_beside_it() {
    let mut frame = adk_frame();
    let red = [1.0, 0.0, 0.0];
    let options = MolOptions {
        reps: vec![
            rep("protein", DrawStyle::Licorice, None),
            rep("protein", DrawStyle::HBonds, Some(RepColor::Fixed(red))),
        ],
        ..MolOptions::default()
    };
    let (scene, plan) = build(options, &mut frame).unwrap();
    let n = plan.last_hbonds().len();
    assert!(n > 30, "{n}");
    let dashes = 2 * HBOND_DASHES * n;
    let licorice = scene.len() - dashes;
    assert!((licorice..scene.len()).all(|k| colour(&scene, k) == [255, 0, 0]));
    assert!((0..licorice).all(|k| colour(&scene, k) != [255, 0, 0]));
    // Without a hydrogen in the selection there is nothing to draw.
    let options = MolOptions {
        reps: vec![rep("not element H", DrawStyle::HBonds, None)],
        ..MolOptions::default()
    };
    let (scene, plan) = build(options, &mut frame).unwrap();
    assert!(scene.is_empty() && plan.last_hbonds().is_empty());
}

#[test]
fn no_bonds_drawn_still_finds_donors_and_bad_cutoffs_are_refused() {
    let mut frame = adk_frame();
    let with = |bonds| MolOptions {
        reps: vec![rep("resid 1:40", DrawStyle::HBonds, None)],
        bonds,
        ..MolOptions::default()
    };
    let (_, auto) = build(with(BondSource::Auto), &mut frame).unwrap();
    let (_, none) = build(with(BondSource::None), &mut frame).unwrap();
    assert!(!auto.last_hbonds().is_empty());
    assert_eq!(auto.last_hbonds(), none.last_hbonds());
    // The dashes are cylinders: drawn whatever the bond source.
    assert!(auto.draws_bonds() && none.draws_bonds());
    for hbonds in [
        Criteria {
            distance: 0.2,
            angle: 150.0,
        },
        Criteria {
            distance: 3.0,
            angle: 200.0,
        },
    ] {
        let e = MolPlan::new(MolOptions {
            hbonds,
            ..with(BondSource::Auto)
        })
        .unwrap_err();
        assert!(matches!(e, MolError::HBonds(_)), "{e}");
    }
}
