//! Backbone dihedral angles of protein residues: φ (C(i−1)–N–CA–C), ψ (N–CA–C–N(i+1)) and ω
//! (CA–C–N(i+1)–CA(i+1)) in degrees from −180 to 180, IUPAC's sign, as MDAnalysis's
//! `Ramachandran` and `Dihedral` give them: the Ramachandran plot of a trajectory.
//!
//! A residue takes part when it has `N`, `CA` and `C` (the first atom of each name;
//! residues as [`crate::secondary::residue_ranges`] finds them). Consecutive such residues in
//! file order are bonded unless the chain or segment changes or `C(i−1)–N(i)` is longer than
//! [`crate::secondary::MAX_PEPTIDE_BOND`]; across a break, and at the ends, the angle that
//! needs the missing neighbour is `None` (MDAnalysis joins residues of one segment
//! regardless of a gap). Bond vectors are taken at their nearest periodic image when the frame
//! has a cell, so a protein split across the box has the angles of the whole one.
//!
//! ```
//! use texmap_md_io::{Frame, Label, dihedrals::backbone_dihedrals};
//! let mut f = Frame::new();
//! // Three residues of a fully extended chain (φ = ψ = ω = 180°), 1.45 Å bonds on a zigzag.
//! let zig = |k: usize| [k as f32 * 1.2, if k % 2 == 0 { 0.0 } else { 0.8 }, 0.0];
//! for k in 0..9 {
//!     f.names.push(Label::new(["N", "CA", "C"][k % 3]).unwrap());
//!     f.res_names.push(Label::new("GLY").unwrap());
//!     f.res_ids.push(1 + k as i64 / 3);
//!     f.positions.push(zig(k));
//! }
//! let angles = backbone_dihedrals(&f);
//! assert_eq!(angles.len(), 3);
//! assert!(angles[0].phi.is_none() && angles[2].psi.is_none());
//! assert!((angles[1].phi.unwrap().abs() - 180.0).abs() < 1e-4);
//! assert!((angles[1].psi.unwrap().abs() - 180.0).abs() < 1e-4);
//! ```

use std::ops::Range;

use glam::DVec3;

use crate::frame::{Frame, Label};
use crate::secondary::{MAX_PEPTIDE_BOND, backbone_of, residue_ranges};

/// One residue's backbone dihedrals (degrees).
#[derive(Clone, Debug, PartialEq)]
pub struct ResidueDihedrals {
    /// The residue's atoms (consecutive in the frame).
    pub atoms: Range<usize>,
    /// φ: C(i−1)–N–CA–C; `None` at a piece's start.
    pub phi: Option<f64>,
    /// ψ: N–CA–C–N(i+1); `None` at a piece's end.
    pub psi: Option<f64>,
    /// ω: CA–C–N(i+1)–CA(i+1), the peptide bond after the residue (near 180° trans, 0° cis);
    /// `None` at a piece's end.
    pub omega: Option<f64>,
}

/// The dihedral angle (degrees, −180..180, IUPAC sign) of the chain a–b–c–d given its bond
/// vectors b1 = b − a, b2 = c − b, b3 = d − c.
pub fn dihedral(b1: DVec3, b2: DVec3, b3: DVec3) -> f64 {
    let n1 = b1.cross(b2);
    let n2 = b2.cross(b3);
    let y = b2.length() * b1.dot(n2);
    let x = n1.dot(n2);
    y.atan2(x).to_degrees()
}

/// The label at `i` of a column that may be absent.
fn label(v: &[Label], i: usize) -> Option<&Label> {
    v.get(i)
}

/// Every residue of `frame` with `N`, `CA` and `C`, in file order, with its angles.
pub fn backbone_dihedrals(frame: &Frame) -> Vec<ResidueDihedrals> {
    if frame.names.len() != frame.n_atoms() {
        return Vec::new();
    }
    let at = |i: usize| {
        let p = frame.positions[i];
        DVec3::new(p[0].into(), p[1].into(), p[2].into())
    };
    let bond = |a: usize, b: usize| {
        let d = at(b) - at(a);
        match &frame.cell {
            Some(cell) => DVec3::from_array(crate::pbc::minimum_image(cell, d.to_array())),
            None => d,
        }
    };
    let residues: Vec<(Range<usize>, [usize; 3])> = residue_ranges(frame)
        .into_iter()
        .filter_map(|atoms| {
            let [n, ca, c, _] = backbone_of(frame, atoms.clone());
            let finite = |i: usize| at(i).is_finite();
            (n != usize::MAX && ca != usize::MAX && c != usize::MAX)
                .then_some([n, ca, c])
                .filter(|bb| bb.iter().all(|&i| finite(i)))
                .map(|bb| (atoms, bb))
        })
        .collect();
    // joined[k]: residue k is bonded to residue k + 1.
    let joined: Vec<bool> = residues
        .windows(2)
        .map(|w| {
            let ((a, prev), (b, next)) = (&w[0], &w[1]);
            label(&frame.chains, a.start) == label(&frame.chains, b.start)
                && label(&frame.segments, a.start) == label(&frame.segments, b.start)
                && bond(prev[2], next[0]).length() <= f64::from(MAX_PEPTIDE_BOND)
        })
        .collect();
    residues
        .iter()
        .enumerate()
        .map(|(k, (atoms, [n, ca, c]))| {
            let before = (k > 0 && joined[k - 1]).then(|| residues[k - 1].1);
            let after = joined
                .get(k)
                .copied()
                .unwrap_or(false)
                .then(|| residues[k + 1].1);
            ResidueDihedrals {
                atoms: atoms.clone(),
                phi: before.map(|p| dihedral(bond(p[2], *n), bond(*n, *ca), bond(*ca, *c))),
                psi: after.map(|q| dihedral(bond(*n, *ca), bond(*ca, *c), bond(*c, q[0]))),
                omega: after.map(|q| dihedral(bond(*ca, *c), bond(*c, q[0]), bond(q[0], q[1]))),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::UnitCell;

    /// The dihedral of four points placed at a chosen angle: a–b along x, b–c along z, c–d
    /// turned by θ about z from the a side.
    #[test]
    fn dihedral_of_points_placed_at_an_angle() {
        for theta in [-179.0f64, -120.0, -60.0, -1.0, 0.0, 30.0, 90.0, 150.0] {
            let t = theta.to_radians();
            let a = DVec3::new(1.0, 0.0, 0.0);
            let b = DVec3::ZERO;
            let c = DVec3::new(0.0, 0.0, 1.5);
            let d = c + DVec3::new(t.cos(), t.sin(), 0.0);
            let got = dihedral(b - a, c - b, d - c);
            assert!((got - theta).abs() < 1e-9, "{theta}: {got}");
        }
    }

    /// Two chains of three residues: the chain break and a long peptide bond leave the angles
    /// across them `None`; a residue without CA is skipped; moving a chain across a periodic
    /// face by a cell vector changes no angle.
    #[test]
    fn breaks_gaps_and_periodic_images() {
        let mut f = Frame::new();
        let mut push = |name: &str, res: i64, chain: &str, p: [f32; 3]| {
            f.names.push(Label::new(name).unwrap());
            f.res_names.push(Label::new("ALA").unwrap());
            f.res_ids.push(res);
            f.chains.push(Label::new(chain).unwrap());
            f.positions.push(p);
        };
        // A helix-like trace: each residue turned and raised.
        for (chain, shift) in [("A", 0.0f32), ("B", 20.0)] {
            for r in 0..4 {
                if chain == "B" && r == 2 {
                    push("N", r, chain, [0.0, 0.0, 0.0]);
                    push("C", r, chain, [0.0, 0.0, 0.0]);
                    continue; // no CA: not a backbone residue
                }
                for (k, name) in ["N", "CA", "C"].iter().enumerate() {
                    let s = (r * 3 + k as i64) as f32;
                    let a = s * 1.75;
                    // Chain B's last residue sits 3 Å further along: a missing loop.
                    let gap = if chain == "B" && r == 3 { 3.0 } else { 0.0 };
                    push(name, r, chain, [a.cos() + shift, a.sin(), 0.5 * s + gap]);
                }
            }
        }
        f.cell = Some(UnitCell::orthorhombic(50.0, 50.0, 50.0).unwrap());
        let angles = backbone_dihedrals(&f);
        assert_eq!(angles.len(), 7);
        let a = &angles[..4];
        assert!(a[0].phi.is_none() && a[3].psi.is_none() && a[3].omega.is_none());
        // Every inner angle of the regular trace is the same.
        let phi = a[1].phi.unwrap();
        assert!((a[2].phi.unwrap() - phi).abs() < 1e-3, "{:?}", a);
        assert!((a[1].psi.unwrap() - a[2].psi.unwrap()).abs() < 1e-3);
        // Chain B: residue 2 has no CA and 3 lies past a gap, so 1 and 3 are not joined.
        let b = &angles[4..];
        assert!(b[0].phi.is_none(), "a new chain starts a piece");
        assert!(b[1].psi.is_none() && b[2].phi.is_none());
        // Chain A moved by a whole cell edge along x: the same angles.
        let mut moved = f.clone();
        for p in &mut moved.positions[..12] {
            if p[2] > 2.0 {
                p[0] += 50.0;
            }
        }
        let again = backbone_dihedrals(&moved);
        for (x, y) in again.iter().zip(&angles) {
            for (u, v) in [(x.phi, y.phi), (x.psi, y.psi), (x.omega, y.omega)] {
                assert_eq!(u.is_some(), v.is_some());
                if let (Some(u), Some(v)) = (u, v) {
                    assert!((u - v).abs() < 1e-3, "{u} {v}");
                }
            }
        }
        // Without the cell the bond that crosses is 50 Å long and the angles are wrong.
        moved.cell = None;
        let wrong = backbone_dihedrals(&moved);
        assert!((wrong[1].psi.unwrap() - angles[1].psi.unwrap()).abs() > 1.0);
    }
}
