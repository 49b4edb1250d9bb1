//! Coordination polyhedra, as VESTA and CrystalMaker draw them: around each centre atom, the
//! convex hull of the atoms bonded to it ([`crate::DrawStyle::Polyhedra`]).
//!
//! A centre's ligands are its bond partners (the plan's bonds: listed, or by distance), seen
//! from the centre through the periodic images: the nearest image, and every other image
//! within the bond-by-distance cutoff (the two covalent radii + 0.45 Å,
//! [`texmap_md_io::bonds`]). A polyhedron whose centre sits by a face of the box is whole and
//! pokes out of it, as VESTA draws it, and in a unit cell shorter than two bonds (rutile's c,
//! 2.96 Å) one atom is the ligand twice, once through each face, as in the crystal. The hull
//! ([`convex_hull`]) is exact for the few points a coordination shell has: every plane through
//! three ligands with all ligands on one side of it is a face, coplanar ligands make one face
//! (a square of an octahedron's equator is two triangles, not four), and faces are wound
//! counter-clockwise seen from outside with their own flat normal, so the polyhedra are lit
//! flat, edges sharp. Three ligands, or more in one plane (square-planar coordination), make a
//! flat polygon drawn from both sides; fewer than three make nothing. A centre with more than
//! [`MAX_LIGANDS`] bonds (a metal counted bonded to a whole cluster) is left out.
//!
//! Each polyhedron takes its centre's material, so it is coloured as the centre atom would be.

use glam::{DVec3, Vec3};
use texmap_md_io::UnitCell;

use crate::surface::MolMesh;

/// Most ligands a centre may have for its polyhedron to be drawn.
pub const MAX_LIGANDS: usize = 32;

/// The bond-by-distance tolerance over the two covalent radii, and the shortest bond, Å
/// ([`texmap_md_io::bonds`]).
const BOND_TOLERANCE: f64 = texmap_md_io::bonds::BOND_TOLERANCE as f64;
const MIN_BOND: f64 = texmap_md_io::bonds::MIN_BOND_LENGTH as f64;

/// Calls `found` with every periodic image of the displacement `nearest` (a nearest image)
/// other than itself that is shorter than `cutoff` and longer than 0.4 Å.
fn images_within(cell: &UnitCell, nearest: DVec3, cutoff: f64, mut found: impl FnMut(DVec3)) {
    if cutoff.is_nan() || cutoff <= 0.0 {
        return;
    }
    let m = cell.matrix().map(DVec3::from_array);
    let k = (cutoff / cell.min_periodic_width()).ceil().clamp(1.0, 3.0) as i32;
    // No images across an edge that is not periodic.
    let [ka, kb, ke] = cell.periodic().map(|p| if p { k } else { 0 });
    for a in -ka..=ka {
        for b in -kb..=kb {
            for e in -ke..=ke {
                if (a, b, e) == (0, 0, 0) {
                    continue;
                }
                let v = nearest + m[0] * a as f64 + m[1] * b as f64 + m[2] * e as f64;
                let l = v.length();
                if l < cutoff && l > MIN_BOND {
                    found(v);
                }
            }
        }
    }
}

/// The pairs of atoms of `frame` bonded by distance through its cell's nearest images, for a
/// cell too narrow for [`texmap_md_io::bonds::bonds_by_distance`]'s periodic grid (under three
/// cutoffs wide: a crystal's unit cell, a film one cell thick), which then gives plain
/// distances. The same rule, `0.4 Å < d < r_i + r_j + 0.45 Å` to the nearest image: the frame
/// is replicated ([`texmap_md_io::replicate`]) until the grid takes it, its bonds found there and
/// folded back onto the original atoms, so the cost stays linear in the atoms; only if that
/// copy would be too large is every pair tested.
pub fn pairs_in_narrow_cell(frame: &texmap_md_io::Frame, cell: &UnitCell) -> Vec<[u32; 2]> {
    let n = frame.n_atoms();
    let elements: Vec<texmap_md_io::Element> = (0..n)
        .map(|i| texmap_md_io::atom_element(frame, i))
        .collect();
    let widest = elements
        .iter()
        .map(|e| e.covalent_radius() as f64)
        .fold(0.0, f64::max);
    let cutoff = 2.0 * widest + BOND_TOLERANCE;
    let m = cell.matrix().map(DVec3::from_array);
    let volume = cell.volume();
    let widths = [(1, 2), (2, 0), (0, 1)].map(|(a, b)| volume / m[a].cross(m[b]).length());
    let periodic = cell.periodic();
    let copies: [usize; 3] = std::array::from_fn(|k| {
        if periodic[k] {
            ((3.0 * cutoff / widths[k]).ceil() as usize + 1).max(1)
        } else {
            1
        }
    });
    let mut copy = texmap_md_io::Frame::new();
    copy.positions = frame.positions.clone();
    copy.elements = elements;
    copy.cell = Some(*cell);
    if texmap_md_io::replicate::replicate(&mut copy, &mut Vec::new(), copies).is_ok() {
        let found = texmap_md_io::bonds::bonds_by_distance(&copy, true);
        if found.periodic {
            // Atom `a` of image `m` is copy atom `m·n + a`.
            let n = n as u32;
            let mut pairs: Vec<[u32; 2]> = found
                .pairs
                .iter()
                .map(|&[i, j]| (i % n, j % n))
                .filter(|(a, b)| a != b)
                .map(|(a, b)| [a.min(b), a.max(b)])
                .collect();
            pairs.sort_unstable();
            pairs.dedup();
            return pairs;
        }
    }
    every_pair(frame, cell)
}

/// [`pairs_in_narrow_cell`] by testing every pair of atoms at its nearest image.
fn every_pair(frame: &texmap_md_io::Frame, cell: &UnitCell) -> Vec<[u32; 2]> {
    let n = frame.n_atoms();
    let radii: Vec<f64> = (0..n)
        .map(|i| texmap_md_io::atom_element(frame, i).covalent_radius() as f64)
        .collect();
    let mut pairs = Vec::new();
    for i in 0..n {
        if radii[i] <= 0.0 {
            continue;
        }
        let p = frame.positions[i];
        for j in i + 1..n {
            if radii[j] <= 0.0 {
                continue;
            }
            let q = frame.positions[j];
            let d: [f64; 3] = std::array::from_fn(|k| q[k] as f64 - p[k] as f64);
            let l = DVec3::from_array(texmap_md_io::pbc::minimum_image(cell, d)).length();
            if l > MIN_BOND && l < radii[i] + radii[j] + BOND_TOLERANCE {
                pairs.push([i as u32, j as u32]);
            }
        }
    }
    pairs
}

/// The faces of the convex hull of `points` as triangles of indices into them, wound
/// counter-clockwise seen from outside. Points within `1e-6` of the hull's size of a face's
/// plane belong to it; a face of more than three points is fanned from its first point in
/// angular order. Points all in one plane give that polygon twice, once per side; fewer than
/// three points, or all on one line, give nothing.
pub fn convex_hull(points: &[DVec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    let mut faces = Vec::new();
    if n < 3 {
        return faces;
    }
    let centroid = points.iter().sum::<DVec3>() / n as f64;
    let size = points
        .iter()
        .map(|p| (*p - centroid).length())
        .fold(0.0, f64::max);
    if !(size > 0.0 && size.is_finite()) {
        return faces;
    }
    let eps = 1e-6 * size;
    // Unit outward normals and offsets of the faces found so far.
    let mut planes: Vec<(DVec3, f64)> = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let normal = (points[j] - points[i]).cross(points[k] - points[i]);
                let len = normal.length();
                if len <= eps * size {
                    continue;
                }
                let normal = normal / len;
                let d = normal.dot(points[i]);
                let (lo, hi) = points.iter().fold((0.0f64, 0.0f64), |(lo, hi), p| {
                    let s = normal.dot(*p) - d;
                    (lo.min(s), hi.max(s))
                });
                // Every point behind the plane (or in it): a face, seen from +normal or -normal.
                for (out, offset, behind) in [(normal, d, hi <= eps), (-normal, -d, lo >= -eps)] {
                    let same = |(m, o): &(DVec3, f64)| {
                        m.dot(out) > 1.0 - 1e-9 && (o - offset).abs() <= eps
                    };
                    if behind && !planes.iter().any(same) {
                        planes.push((out, offset));
                    }
                }
            }
        }
    }
    for (normal, offset) in planes {
        let on: Vec<usize> = (0..n)
            .filter(|&m| (normal.dot(points[m]) - offset).abs() <= eps)
            .collect();
        let c = on.iter().map(|&m| points[m]).sum::<DVec3>() / on.len() as f64;
        let u = (points[on[0]] - c).normalize_or_zero();
        let v = normal.cross(u);
        let mut ordered: Vec<(f64, usize)> = on
            .iter()
            .map(|&m| {
                let r = points[m] - c;
                (r.dot(v).atan2(r.dot(u)), m)
            })
            .collect();
        ordered.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for w in 1..ordered.len() - 1 {
            faces.push([ordered[0].1, ordered[w].1, ordered[w + 1].1]);
        }
    }
    faces
}

/// Appends to `mesh` the polyhedron of every atom `centre` picks (`centre[i]`), from the
/// ligands `bonds` give it (pairs of atom indices, each once, either order), at `positions`
/// (Å), through `cell`'s images when there is a cell (see the module docs; `radii` are the
/// atoms' covalent radii, 0 where unknown); each polyhedron's triangles take `kinds[i]`.
/// Returns the number of polyhedra appended.
pub fn append_polyhedra(
    positions: &[Vec3],
    radii: &[f32],
    kinds: &[u16],
    centre: &[bool],
    bonds: &[[u32; 2]],
    cell: Option<&UnitCell>,
    mesh: &mut MolMesh,
) -> usize {
    let n = positions.len();
    // Each centre's ligands, in bond order.
    let mut count = vec![0u32; n + 1];
    for b in bonds {
        for (a, _) in [(b[0], b[1]), (b[1], b[0])] {
            if centre.get(a as usize).copied().unwrap_or(false) {
                count[a as usize + 1] += 1;
            }
        }
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let mut fill = count.clone();
    let mut ligands = vec![0u32; count[n] as usize];
    for b in bonds {
        for (a, l) in [(b[0], b[1]), (b[1], b[0])] {
            if centre.get(a as usize).copied().unwrap_or(false) {
                ligands[fill[a as usize] as usize] = l;
                fill[a as usize] += 1;
            }
        }
    }
    let mut made = 0;
    let mut points = Vec::new();
    for i in 0..n {
        let own = &ligands[count[i] as usize..count[i + 1] as usize];
        if own.is_empty() || own.len() > MAX_LIGANDS {
            continue;
        }
        let c = positions[i].as_dvec3();
        points.clear();
        for &l in own {
            let d = (positions[l as usize].as_dvec3() - c).to_array();
            match cell {
                None => points.push(c + DVec3::from_array(d)),
                Some(cell) => {
                    let nearest = DVec3::from_array(texmap_md_io::pbc::minimum_image(cell, d));
                    points.push(c + nearest);
                    let cutoff = (radii[i] + radii[l as usize]) as f64 + BOND_TOLERANCE;
                    images_within(cell, nearest, cutoff, |v| points.push(c + v));
                }
            }
        }
        if points.len() < 3 || points.len() > MAX_LIGANDS {
            continue;
        }
        let faces = convex_hull(&points);
        if faces.is_empty() {
            continue;
        }
        made += 1;
        for f in faces {
            let [a, b, e] = f.map(|m| points[m]);
            let normal = (b - a).cross(e - a).normalize_or_zero().as_vec3();
            let base = mesh.positions.len() as u32;
            for p in [a, b, e] {
                mesh.positions.push(p.as_vec3());
                mesh.normals.push(normal);
            }
            mesh.triangles.push([base, base + 1, base + 2]);
            mesh.kinds.push(kinds[i]);
        }
    }
    made
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every edge of a closed, consistently wound mesh is used once in each direction.
    fn closed(faces: &[[usize; 3]]) -> bool {
        let mut edges = std::collections::HashMap::new();
        for f in faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        edges
            .iter()
            .all(|(&(a, b), &c)| c == 1 && edges.get(&(b, a)) == Some(&1))
    }

    fn volume(points: &[DVec3], faces: &[[usize; 3]]) -> f64 {
        faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| points[i]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn platonic_hulls_have_their_faces_and_volumes() {
        let r = 2.1;
        let octahedron: Vec<DVec3> = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ]
        .map(|v| v * r + DVec3::new(0.3, -1.0, 5.0))
        .to_vec();
        let f = convex_hull(&octahedron);
        assert_eq!(f.len(), 8);
        assert!(closed(&f));
        let v = volume(&octahedron, &f);
        assert!((v - 4.0 / 3.0 * r * r * r).abs() < 1e-9, "{v}");
        // A cube's square faces are two triangles each, not four overlapping ones.
        let cube: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64) * 1.5)
            .collect();
        let f = convex_hull(&cube);
        assert_eq!(f.len(), 12);
        assert!(closed(&f));
        assert!((volume(&cube, &f) - 3.375).abs() < 1e-9);
        // A regular tetrahedron.
        let tet = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        let f = convex_hull(&tet);
        assert_eq!(f.len(), 4);
        assert!((volume(&tet, &f) - 8.0 / 3.0).abs() < 1e-9);
    }

    #[test]
    fn random_clouds_are_wrapped_and_flat_shells_are_two_sided() {
        let mut s = 11u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for n in 4..20 {
            let pts: Vec<DVec3> = (0..n).map(|_| DVec3::new(r(), r(), r())).collect();
            let f = convex_hull(&pts);
            assert!(closed(&f), "{n} points");
            assert!(volume(&pts, &f) > 0.0);
            // Every point lies behind every face.
            for t in &f {
                let [a, b, c] = t.map(|i| pts[i]);
                let nrm = (b - a).cross(c - a);
                assert!(pts.iter().all(|p| nrm.dot(*p - a) <= 1e-9), "{n} points");
            }
        }
        // Square-planar coordination: one square, from both sides.
        let square = [DVec3::X, DVec3::Y, DVec3::NEG_X, DVec3::NEG_Y];
        let f = convex_hull(&square);
        assert_eq!(f.len(), 4);
        assert_eq!(volume(&square, &f), 0.0);
        // On one line: nothing.
        let line = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(convex_hull(&line).is_empty());
    }

    #[test]
    fn a_centre_by_the_box_face_takes_its_ligands_nearest_images() {
        // A cubic cell of 4 Å, the centre at a corner, six ligands 1.9 Å away along the axes:
        // the three on the negative side are written through the box, at 4 - 1.9 = 2.1.
        let cell = UnitCell::orthorhombic(4.0, 4.0, 4.0).unwrap();
        let mut positions = vec![Vec3::ZERO];
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            positions.push(axis * 1.9);
            positions.push(axis * 2.1);
        }
        let bonds: Vec<[u32; 2]> = (1..7).map(|l| [0, l]).collect();
        let mut centre = vec![false; 7];
        centre[0] = true;
        let kinds = vec![3u16; 7];
        let radii = vec![0.0f32; 7];
        let mut mesh = MolMesh::default();
        let made = append_polyhedra(
            &positions,
            &radii,
            &kinds,
            &centre,
            &bonds,
            Some(&cell),
            &mut mesh,
        );
        assert_eq!(made, 1);
        assert_eq!(mesh.triangles.len(), 8);
        assert!(mesh.kinds.iter().all(|k| *k == 3));
        let v = mesh.volume();
        assert!((v - 4.0 / 3.0 * 1.9f64.powi(3)).abs() < 1e-4, "{v}");
        // Without the cell the ligands are all on the positive side: another polyhedron.
        let mut open = MolMesh::default();
        append_polyhedra(&positions, &radii, &kinds, &centre, &bonds, None, &mut open);
        assert!((open.volume() - v).abs() > 0.5);
    }

    #[test]
    fn a_ligand_bonded_through_both_faces_of_a_short_cell_counts_twice() {
        // c = 3 Å: the atom at z = 1.5 is 1.5 Å above the centre and 1.5 Å below it, both
        // within the 0.8 + 0.8 + 0.45 Å cutoff; two more ligands at ±1.9 Å along x make a
        // square in the xz plane, drawn from both sides.
        let cell = UnitCell::orthorhombic(4.0, 10.0, 3.0).unwrap();
        let positions = [
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, 1.5),
            Vec3::X * 1.9,
            Vec3::X * 2.1,
        ];
        let radii = [0.8f32; 4];
        let bonds = [[0u32, 1], [0, 2], [0, 3]];
        let mut mesh = MolMesh::default();
        let made = append_polyhedra(
            &positions,
            &radii,
            &[0; 4],
            &[true, false, false, false],
            &bonds,
            Some(&cell),
            &mut mesh,
        );
        assert_eq!(made, 1);
        assert_eq!(mesh.triangles.len(), 4);
        let zs: Vec<f32> = mesh.positions.iter().map(|p| p.z).collect();
        assert!(
            zs.iter().any(|z| (*z - 1.5).abs() < 1e-6)
                && zs.iter().any(|z| (*z + 1.5).abs() < 1e-6)
        );
        assert!(
            mesh.area() > 2.0 * 1.5 * 1.9 * 2.0 - 1e-3,
            "{}",
            mesh.area()
        );
    }

    #[test]
    fn a_narrow_cells_pairs_by_the_grid_equal_every_pair_tested() {
        // Rutile's unit cell (c = 2.959 Å, under three cutoffs) and a film of 6 x 5 x 1 cells.
        let (a, c, u) = (4.594f64, 2.959f64, 0.3048f64);
        let sites = [
            ("Ti", [0.0, 0.0, 0.0]),
            ("Ti", [0.5, 0.5, 0.5]),
            ("O", [u, u, 0.0]),
            ("O", [1.0 - u, 1.0 - u, 0.0]),
            ("O", [0.5 + u, 0.5 - u, 0.5]),
            ("O", [0.5 - u, 0.5 + u, 0.5]),
        ];
        for (nx, ny) in [(1usize, 1usize), (6, 5)] {
            let cell = UnitCell::orthorhombic(a * nx as f64, a * ny as f64, c).unwrap();
            let mut f = texmap_md_io::Frame::new();
            for x in 0..nx {
                for y in 0..ny {
                    for (el, p) in sites {
                        let frac = [
                            (p[0] + x as f64) / nx as f64,
                            (p[1] + y as f64) / ny as f64,
                            p[2],
                        ];
                        f.positions.push(cell.to_cartesian(frac).map(|v| v as f32));
                        f.elements
                            .push(texmap_md_io::Element::from_symbol(el).unwrap());
                    }
                }
            }
            f.cell = Some(cell);
            let mut want = every_pair(&f, &cell);
            want.sort_unstable();
            let got = pairs_in_narrow_cell(&f, &cell);
            assert!(!got.is_empty());
            assert_eq!(got, want, "{nx} x {ny} cells");
        }
    }
}
