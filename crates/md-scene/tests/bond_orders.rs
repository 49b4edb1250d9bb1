//! Bond orders drawn as PyMOL's valence mode (`MolOptions::bond_orders`): a double bond as two
//! sticks in the plane of its neighbours, a triple as three, an aromatic bond as a stick with a
//! dashed line inside its ring; single bonds and bonds without orders as before.

use glam::Vec3;
use texmap_md_io::{BOND_AROMATIC, Element, Frame, Label};
use texmap_md_scene::{
    DrawStyle, MolOptions, MolPlan, SceneBuilder, SphereScene, StyleOptions, VALENCE_OFFSET,
};

fn molecule(atoms: &[(&str, [f32; 3])], bonds: &[([u32; 2], u8)]) -> Frame {
    let mut f = Frame::new();
    for (el, p) in atoms {
        f.positions.push(*p);
        f.elements.push(Element::from_symbol(el).unwrap());
        f.names.push(Label::new(el).unwrap());
    }
    let mut b = bonds.to_vec();
    b.sort_unstable();
    f.bonds = b.iter().map(|x| x.0).collect();
    f.bond_orders = b.iter().map(|x| x.1).collect();
    f
}

fn draw(mut f: Frame, orders: bool) -> SphereScene {
    let mut plan = MolPlan::new(MolOptions {
        draw: DrawStyle::BallStick,
        bond_orders: orders,
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut scene = SphereScene::default();
    plan.build(&mut builder, &mut f, &mut scene).unwrap();
    scene
}

/// Ethylene in the xy plane: C=C along x, hydrogens at ±y.
fn ethylene() -> Frame {
    molecule(
        &[
            ("C", [0.0, 0.0, 0.0]),
            ("C", [1.34, 0.0, 0.0]),
            ("H", [-0.55, 0.93, 0.0]),
            ("H", [-0.55, -0.93, 0.0]),
            ("H", [1.89, 0.93, 0.0]),
            ("H", [1.89, -0.93, 0.0]),
        ],
        &[
            ([0, 1], 2),
            ([0, 2], 1),
            ([0, 3], 1),
            ([1, 4], 1),
            ([1, 5], 1),
        ],
    )
}

#[test]
fn a_double_bond_is_two_sticks_in_the_molecules_plane() {
    let plain = draw(ethylene(), false);
    assert_eq!(plain.bonds.len(), 5);
    let s = draw(ethylene(), true);
    // Four single bonds, and the double bond's two sticks between four new end spheres.
    assert_eq!(s.bonds.len(), 6);
    assert_eq!(s.bond_radii.len(), s.bonds.len());
    let r = plain.bond_radius;
    let sticks: Vec<[u32; 2]> = s.bonds.iter().copied().filter(|b| b[0] >= 6).collect();
    assert_eq!(sticks.len(), 2);
    for b in &sticks {
        let (a, c) = (s.centers[b[0] as usize], s.centers[b[1] as usize]);
        // Parallel to the bond, in the plane (z = 0), VALENCE_OFFSET bond radii off its axis.
        assert!((c - a - Vec3::new(1.34, 0.0, 0.0)).length() < 1e-5);
        assert!(a.z.abs() < 1e-6);
        assert!((a.y.abs() - VALENCE_OFFSET * r).abs() < 1e-5, "{a}");
        assert!(s.bond_radius_of(s.bonds.iter().position(|x| x == b).unwrap()) < r);
    }
}

#[test]
fn triple_and_aromatic_bonds() {
    // Acetylene along x: three sticks.
    let hcch = molecule(
        &[
            ("H", [-1.06, 0.0, 0.0]),
            ("C", [0.0, 0.0, 0.0]),
            ("C", [1.2, 0.0, 0.0]),
            ("H", [2.26, 0.0, 0.0]),
        ],
        &[([0, 1], 1), ([1, 2], 3), ([2, 3], 1)],
    );
    let s = draw(hcch, true);
    assert_eq!(s.bonds.len(), 2 + 3);
    // Benzene, aromatic bonds: each drawn as a stick and three dashes on the ring's side.
    let ring: Vec<(&str, [f32; 3])> = (0..6)
        .map(|k| {
            let t = std::f32::consts::TAU * k as f32 / 6.0;
            ("C", [1.39 * t.cos(), 1.39 * t.sin(), 0.0])
        })
        .collect();
    let bonds: Vec<([u32; 2], u8)> = (0..6u32)
        .map(|k| ([k.min((k + 1) % 6), k.max((k + 1) % 6)], BOND_AROMATIC))
        .collect();
    let s = draw(molecule(&ring, &bonds), true);
    assert_eq!(s.bonds.len(), 6 * (1 + 3));
    // Every dash lies inside the ring, nearer its centre than the bonds' midpoints (1.20 Å).
    let dashes: Vec<usize> = (0..s.bonds.len())
        .filter(|&b| s.bond_radius_of(b) < 0.5 * s.bond_radius)
        .collect();
    assert_eq!(dashes.len(), 18);
    for b in dashes {
        let mid = (s.centers[s.bonds[b][0] as usize] + s.centers[s.bonds[b][1] as usize]) / 2.0;
        assert!(mid.length() < 1.15, "{mid}");
    }
}
