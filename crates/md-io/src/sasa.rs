//! Solvent-accessible surface area per atom by the Shrake–Rupley method (J. Mol. Biol. 79
//! (1973) 351), as MDTraj's `shrake_rupley`, VMD's `measure sasa` and PyMOL's `get_area` with
//! `dot_solvent` compute it.
//!
//! Each atom is a sphere of its van der Waals radius plus the probe's (1.4 Å, a water
//! molecule), carrying [`POINTS`] points spread over it by the golden-section spiral (point k
//! of n at height y = (k + ½)·2/n − 1, turned k·π(3 − √5) about the axis). A point inside
//! another atom's sphere is buried; the atom's area is its sphere's, 4π(r + p)², times the
//! fraction of its points left. Only the atoms asked about count, as blockers too (a protein
//! measured alone, without its water). Radii ([`radius`]) are MDTraj's: Bondi's (J. Phys.
//! Chem. 68 (1964) 441) for the atoms of biomolecules (H 1.20, C 1.70, N 1.55, O 1.52, P 1.80,
//! S 1.80 Å, as VMD and FreeSASA's classic set also take them), Shannon's ionic radii for the
//! ions of a simulation's solvent (Na⁺ 1.02, K⁺ 1.38, Mg²⁺ 0.86, Ca²⁺ 1.14, Cl⁻ 1.81 Å), else
//! the element's van der Waals radius ([`crate::Element::vdw_radius`]).
//!
//! Neighbours come from the bond grid ([`crate::bonds`]) at the sum of the two spheres' radii,
//! at their nearest periodic image in a cell (a cell narrower than three such sums along a
//! periodic edge is an error, as for [`crate::coordination`]), and atoms closer than that
//! grid's 0.4 Å floor (overlapping copies) from the nearest-neighbour grid. Every atom's area
//! is computed on its own, in parallel: the same result on any number of threads.
//!
//! ```
//! use texmap_md_io::{Element, Frame};
//! use texmap_md_io::sasa::{PROBE, radius, sasa};
//! // Two carbon atoms 3 Å apart: each loses the cap of its sphere inside the other's.
//! let mut frame = Frame::new();
//! frame.positions = vec![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]];
//! frame.elements = vec![Element::from_symbol("C").unwrap(); 2];
//! let area = sasa(&frame, None, PROBE).unwrap();
//! let r = f64::from(radius(frame.elements[0]) + PROBE);
//! // A cap of height h = r − d/2 has area 2π r h.
//! let exact = 4.0 * std::f64::consts::PI * r * r - 2.0 * std::f64::consts::PI * r * (r - 1.5);
//! assert!((f64::from(area[0]) - exact).abs() < 0.01 * exact);
//! ```

use std::fmt;

use rayon::prelude::*;

use crate::bonds::{BOND_TOLERANCE, MIN_BOND_LENGTH, bonds_with_radii};
use crate::elements::Element;
use crate::frame::Frame;
use crate::pbc::NearestImage;

/// The probe's radius, Å: a water molecule.
pub const PROBE: f32 = 1.4;
/// Points per atom's sphere (MDTraj's default).
pub const POINTS: usize = 960;

/// Why the areas cannot be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum SasaError {
    /// The probe radius is negative, not finite or absurd.
    BadProbe(f32),
    /// The selection mask has another length than the frame's atoms.
    MaskLength {
        /// The frame's atoms.
        atoms: usize,
        /// The mask's entries.
        mask: usize,
    },
    /// An atom counted has a position that is not finite.
    NotFinite(usize),
    /// The periodic cell is narrower than three neighbour distances along a periodic edge.
    CellTooSmall {
        /// The cell's narrowest periodic width, Å.
        width: f64,
        /// The largest distance at which two spheres touch, Å.
        reach: f32,
    },
}

impl fmt::Display for SasaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SasaError::BadProbe(p) => {
                write!(f, "the probe radius {p} is not a number from 0 to 10 Å")
            }
            SasaError::MaskLength { atoms, mask } => {
                write!(f, "a selection of {mask} atoms for a frame of {atoms}")
            }
            SasaError::NotFinite(i) => write!(f, "atom {i} has no finite position"),
            SasaError::CellTooSmall { width, reach } => write!(
                f,
                "the periodic cell is {width:.2} Å wide, less than three times the {reach:.2} Å \
                 at which two atoms' spheres touch: replicate it first (--replicate)"
            ),
        }
    }
}

impl std::error::Error for SasaError {}

/// The van der Waals radius (Å) an atom of `element` has for its accessible surface (see the
/// module docs).
pub fn radius(element: Element) -> f32 {
    match element.symbol() {
        "H" => 1.20,
        "C" => 1.70,
        "N" => 1.55,
        "O" => 1.52,
        "F" => 1.47,
        "P" => 1.80,
        "S" => 1.80,
        "Cl" => 1.81,
        "Br" => 1.85,
        "I" => 1.98,
        "Se" => 1.90,
        "Si" => 2.10,
        "Li" => 0.76,
        "Na" => 1.02,
        "K" => 1.38,
        "Mg" => 0.86,
        "Ca" => 1.14,
        "Zn" => 1.39,
        _ => element.vdw_radius(),
    }
}

/// The `n` points of the golden-section spiral on the unit sphere (see the module docs).
pub fn sphere_points(n: usize) -> Vec<[f64; 3]> {
    let turn = std::f64::consts::PI * (3.0 - 5.0f64.sqrt());
    let step = 2.0 / n as f64;
    (0..n)
        .map(|k| {
            let y = k as f64 * step - 1.0 + step / 2.0;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = k as f64 * turn;
            [phi.cos() * r, y, phi.sin() * r]
        })
        .collect()
}

/// Every atom's solvent-accessible surface area (Å²) with a probe of radius `probe` (Å), over
/// the atoms `mask` keeps (all without one) that have an element; the others (virtual sites,
/// dummies) get NaN and bury nothing.
pub fn sasa(frame: &Frame, mask: Option<&[bool]>, probe: f32) -> Result<Vec<f32>, SasaError> {
    if !(probe.is_finite() && (0.0..=10.0).contains(&probe)) {
        return Err(SasaError::BadProbe(probe));
    }
    let n = frame.n_atoms();
    if let Some(m) = mask
        && m.len() != n
    {
        return Err(SasaError::MaskLength {
            atoms: n,
            mask: m.len(),
        });
    }
    // Atoms without an element (virtual sites such as TIP4P's MW, dummies) have no surface.
    let counted: Vec<usize> = (0..n)
        .filter(|&i| mask.is_none_or(|m| m[i]) && !crate::atom_element(frame, i).is_unknown())
        .collect();
    if let Some(&i) = counted
        .iter()
        .find(|&&i| !frame.positions[i].iter().all(|v| v.is_finite()))
    {
        return Err(SasaError::NotFinite(i));
    }
    let positions: Vec<[f32; 3]> = counted.iter().map(|&i| frame.positions[i]).collect();
    // Each sphere's radius; the bond grid pairs two atoms closer than r_a + r_b + tolerance.
    let spheres: Vec<f32> = counted
        .iter()
        .map(|&i| radius(crate::atom_element(frame, i)) + probe)
        .collect();
    let half = BOND_TOLERANCE / 2.0;
    let reach: Vec<f32> = spheres.iter().map(|r| r - half).collect();
    let pairs = bonds_with_radii(&positions, &reach, frame.cell);
    if let Some(cell) = frame.cell
        && !pairs.periodic
        && positions.len() >= 2
        && cell.periodic().contains(&true)
    {
        let widest = spheres.iter().copied().fold(0.0, f32::max);
        return Err(SasaError::CellTooSmall {
            width: cell.min_periodic_width(),
            reach: 2.0 * widest,
        });
    }
    // The bond grid leaves out pairs under its 0.4 Å floor; overlapping atoms (a damaged or
    // generated frame) bury each other all the same, so they are found as nearest neighbours.
    let grid = crate::neighbours::Grid::new(&positions, frame.cell.as_ref());
    let close: Vec<[u32; 2]> = (0..positions.len())
        .into_par_iter()
        .with_min_len(256)
        .map_init(crate::neighbours::Scratch::default, |scratch, a| {
            grid.nearest(a, 4, scratch);
            scratch
                .near
                .iter()
                .zip(&scratch.index)
                .filter(|((_, d), b)| *d < f64::from(MIN_BOND_LENGTH) && (**b as usize) > a)
                .map(|(_, &b)| [a as u32, b])
                .collect::<Vec<_>>()
        })
        .flatten()
        .collect();
    let m = positions.len();
    let (start, list) = crate::pbc::adjacency(m, pairs.pairs.iter().chain(&close));
    let points = sphere_points(POINTS);
    let image = if pairs.periodic {
        frame.cell.as_ref().and_then(NearestImage::new)
    } else {
        None
    };
    let areas: Vec<f32> = (0..m)
        .into_par_iter()
        .with_min_len(64)
        .map_init(Vec::new, |near: &mut Vec<([f64; 3], f64)>, a| {
            let ra = f64::from(spheres[a]);
            let pa = positions[a];
            near.clear();
            for &b in &list[start[a] as usize..start[a + 1] as usize] {
                let pb = positions[b as usize];
                let d: [f64; 3] = std::array::from_fn(|k| f64::from(pb[k]) - f64::from(pa[k]));
                let d = match &image {
                    Some(image) => image.apply(d),
                    None => d,
                };
                let rb = f64::from(spheres[b as usize]);
                let dist2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                // Only spheres that overlap this one bury any of its points.
                if dist2 < (ra + rb) * (ra + rb) {
                    near.push((d, rb * rb));
                }
            }
            // Nearest first: they bury the most points.
            near.sort_by(|x, y| {
                let l = |v: &[f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                l(&x.0).total_cmp(&l(&y.0))
            });
            let mut last = 0usize;
            let mut open = 0usize;
            for u in &points {
                let p = [u[0] * ra, u[1] * ra, u[2] * ra];
                let buried = |&(d, r2): &([f64; 3], f64)| {
                    let v = [p[0] - d[0], p[1] - d[1], p[2] - d[2]];
                    v[0] * v[0] + v[1] * v[1] + v[2] * v[2] < r2
                };
                // The neighbour that buried the previous point usually buries this one too.
                if near.get(last).is_some_and(buried) {
                    continue;
                }
                match near.iter().position(buried) {
                    Some(j) => last = j,
                    None => open += 1,
                }
            }
            (4.0 * std::f64::consts::PI * ra * ra * open as f64 / POINTS as f64) as f32
        })
        .collect();
    let mut out = vec![f32::NAN; n];
    for (&i, a) in counted.iter().zip(areas) {
        out[i] = a;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::UnitCell;

    fn atoms(symbol: &str, positions: Vec<[f32; 3]>) -> Frame {
        let mut frame = Frame::new();
        frame.elements = vec![Element::from_symbol(symbol).unwrap(); positions.len()];
        frame.positions = positions;
        frame
    }

    #[test]
    fn a_lone_atom_has_its_whole_sphere_and_a_buried_one_none() {
        let frame = atoms("O", vec![[1.0, 2.0, 3.0]]);
        let a = sasa(&frame, None, PROBE).unwrap()[0] as f64;
        let r = 1.52 + 1.4;
        assert!((a - 4.0 * std::f64::consts::PI * r * r).abs() < 1e-3, "{a}");
        // A carbon at the centre of an octahedron of carbons 1.5 Å away is buried whole.
        let mut p = vec![[0.0f32; 3]];
        for axis in 0..3 {
            for s in [-1.5, 1.5] {
                let mut q = [0.0; 3];
                q[axis] = s;
                p.push(q);
            }
        }
        let area = sasa(&atoms("C", p), None, PROBE).unwrap();
        assert_eq!(area[0], 0.0);
        assert!(area[1] > 20.0);
    }

    #[test]
    fn the_mask_chooses_the_blockers_and_the_cell_its_images() {
        // Two atoms 3 Å apart across a periodic face are neighbours; without the cell or
        // with the face open they are not.
        let mut frame = atoms("C", vec![[0.5, 5.0, 5.0], [17.5, 5.0, 5.0]]);
        let lone = sasa(&frame, None, PROBE).unwrap();
        frame.cell = Some(UnitCell::orthorhombic(20.0, 20.0, 20.0).unwrap());
        let periodic = sasa(&frame, None, PROBE).unwrap();
        assert!(periodic[0] < lone[0] - 10.0, "{periodic:?} {lone:?}");
        frame.cell = frame.cell.map(|c| c.with_periodic([false, true, true]));
        assert_eq!(sasa(&frame, None, PROBE).unwrap(), lone);
        frame.cell = None;
        // Masked out, the second atom neither counts nor blocks.
        let close = atoms("C", vec![[0.0; 3], [3.0, 0.0, 0.0]]);
        let one = sasa(&close, Some(&[true, false]), PROBE).unwrap();
        assert_eq!(
            one[0],
            sasa(&atoms("C", vec![[0.0; 3]]), None, PROBE).unwrap()[0]
        );
        assert!(one[1].is_nan());
        assert!(sasa(&close, Some(&[true]), PROBE).is_err());
        assert!(sasa(&close, None, -1.0).is_err());
        // A periodic cell too small for one image per neighbour.
        let mut small = close.clone();
        small.cell = Some(UnitCell::orthorhombic(12.0, 12.0, 12.0).unwrap());
        let e = sasa(&small, None, PROBE).unwrap_err();
        assert!(matches!(e, SasaError::CellTooSmall { .. }), "{e}");
    }

    #[test]
    fn the_spiral_spreads_its_points_evenly() {
        let p = sphere_points(POINTS);
        // Every octant holds an eighth of the points, within a few.
        let mut octants = [0usize; 8];
        for q in &p {
            let k =
                (q[0] > 0.0) as usize | ((q[1] > 0.0) as usize) << 1 | ((q[2] > 0.0) as usize) << 2;
            octants[k] += 1;
        }
        assert!(
            octants.iter().all(|&c| c.abs_diff(POINTS / 8) <= 4),
            "{octants:?}"
        );
        assert!(
            p.iter()
                .all(|q| (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - 1.0).abs() < 1e-12)
        );
    }
}
