//! Atomic-level strain between a reference configuration and the current one, as OVITO's
//! Atomic strain modifier computes it (F. Shimizu, S. Ogata, J. Li, Mater. Trans. 48 (2007)
//! 2923; M. L. Falk, J. S. Langer, Phys. Rev. E 57 (1998) 7192): the local deformation
//! gradient of each atom from the motion of its neighbours, and from it the von Mises shear
//! strain that shows shear bands, slip and plastic zones in deformed solids and glasses, the
//! volumetric strain, and the non-affine squared displacement D²min.
//!
//! For atom `i` with neighbours `j` within the cutoff in the reference (vectors `d₀ⱼ`) and the
//! same atoms' vectors now (`dⱼ`):
//! - `V = Σ d₀ⱼ d₀ⱼᵀ`, `W = Σ dⱼ d₀ⱼᵀ`, and the deformation gradient `F = W V⁻¹` (the affine
//!   map that best carries the reference vectors onto the current ones, in least squares);
//! - the Green–Lagrangian strain `E = (FᵀF − I) / 2`;
//! - the shear strain `√(E₀₁² + E₀₂² + E₁₂² + ((E₀₀−E₁₁)² + (E₀₀−E₂₂)² + (E₁₁−E₂₂)²) / 6)`
//!   and the volumetric strain `(E₀₀ + E₁₁ + E₂₂) / 3`;
//! - `D²min = Σ |dⱼ − F d₀ⱼ|²`, in Å².
//!
//! Neighbours are found once, in the reference, within the cutoff at their nearest image (the
//! pairs of [`crate::coordination`]: the same cutoff range, and a periodic cell narrower than
//! three cutoffs is refused). A neighbour's current vector is taken at the periodic image nearest
//! its reference vector in fractional coordinates of each cell, so atoms that were wrapped
//! back into the box between the two frames, and cells that changed shape, give the vectors the
//! atoms really moved by (OVITO's default: minimum image, no affine mapping). Atoms are matched
//! by index. An atom with fewer than three neighbours, or whose neighbours lie in a plane or on a
//! line, has no deformation gradient: it is invalid ([`Strain::invalid`]), with every value 0,
//! as OVITO marks it.
//!
//! ```
//! use texmap_md_io::strain::atomic_strain;
//! use texmap_md_io::{Frame, UnitCell};
//! // A simple cubic lattice (a = 2.5 Å), then the same atoms sheared by γ = 0.1 in x along y.
//! let mut reference = Frame::new();
//! for n in 0..216 {
//!     let (i, j, k) = (n % 6, n / 6 % 6, n / 36);
//!     reference.positions.push([i as f32 * 2.5, j as f32 * 2.5, k as f32 * 2.5]);
//! }
//! reference.cell = Some(UnitCell::orthorhombic(15.0, 15.0, 15.0).unwrap());
//! let mut sheared = reference.clone();
//! for p in &mut sheared.positions {
//!     p[0] += 0.1 * p[1];
//! }
//! sheared.cell = Some(UnitCell::from_matrix([[15.0, 0.0, 0.0], [1.5, 15.0, 0.0], [0.0, 0.0, 15.0]]).unwrap());
//! let s = atomic_strain(&reference, &sheared, 3.0).unwrap();
//! // E = (FᵀF − I)/2 with F = [[1, 0.1, 0], [0, 1, 0], [0, 0, 1]]: E₀₁ = 0.05, E₁₁ = 0.005.
//! let expected = (0.05f32.powi(2) + 2.0 * 0.005f32.powi(2) / 6.0).sqrt();
//! assert!(s.shear.iter().all(|v| (v - expected).abs() < 1e-5));
//! assert!(s.d2min.iter().all(|v| v.abs() < 1e-6));
//! ```

use std::fmt;

use glam::{DMat3, DVec3};

use crate::coordination::{CoordinationError, pairs_within};
use crate::frame::Frame;

/// What [`atomic_strain`] finds, per atom.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Strain {
    /// The von Mises shear strain.
    pub shear: Vec<f32>,
    /// The volumetric (hydrostatic) strain.
    pub volumetric: Vec<f32>,
    /// The non-affine squared displacement D²min, Å².
    pub d2min: Vec<f32>,
    /// Whether the atom had too few neighbours, or neighbours in a plane, for a deformation
    /// gradient (its values are 0).
    pub invalid: Vec<bool>,
}

/// Why the strain cannot be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum StrainError {
    /// The two configurations hold different numbers of atoms.
    AtomCount {
        /// Atoms in the reference.
        reference: usize,
        /// Atoms in the current frame.
        current: usize,
    },
    /// The neighbours in the reference cannot be found (cutoff out of range, cell too small).
    Neighbours(CoordinationError),
}

impl fmt::Display for StrainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StrainError::AtomCount { reference, current } => write!(
                f,
                "the reference configuration has {reference} atoms and this frame {current}: \
                 strain needs the same atoms in the same order"
            ),
            StrainError::Neighbours(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for StrainError {}

/// The atomic strain of every atom of `current` against `reference`, from the neighbours
/// within `cutoff` Å in the reference (see the module docs).
pub fn atomic_strain(
    reference: &Frame,
    current: &Frame,
    cutoff: f32,
) -> Result<Strain, StrainError> {
    use rayon::prelude::*;
    let n = reference.n_atoms();
    if current.n_atoms() != n {
        return Err(StrainError::AtomCount {
            reference: n,
            current: current.n_atoms(),
        });
    }
    let pairs = pairs_within(reference, cutoff).map_err(StrainError::Neighbours)?;
    // Each atom's neighbours, in pair order (a CSR list).
    let mut start = vec![0u32; n + 1];
    for [i, j] in &pairs {
        start[*i as usize + 1] += 1;
        start[*j as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut next = start.clone();
    let mut neighbours = vec![0u32; start[n] as usize];
    for [i, j] in &pairs {
        neighbours[next[*i as usize] as usize] = *j;
        next[*i as usize] += 1;
        neighbours[next[*j as usize] as usize] = *i;
        next[*j as usize] += 1;
    }
    // Cells with the edges as columns; a frame without one takes the other's (an open frame
    // against an open reference has none).
    let edges = |f: &Frame| f.cell.map(|c| DMat3::from_cols_array_2d(&c.matrix()));
    let cells = match (edges(reference), edges(current)) {
        (Some(a), Some(b)) => Some((a, b)),
        (Some(a), None) => Some((a, a)),
        (None, Some(b)) => Some((b, b)),
        (None, None) => None,
    };
    let cells = cells.map(|(h0, h)| (h0, h0.inverse(), h, h.inverse()));
    // Whole edges come off along the periodic edges only (the reference's, else the current
    // frame's).
    let periodic = reference
        .cell
        .or(current.cell)
        .map_or([false; 3], |c| c.periodic());
    let wrap = DVec3::from(periodic.map(|p| if p { 1.0 } else { 0.0 }));
    let at = |f: &Frame, i: u32| DVec3::from(f.positions[i as usize].map(f64::from));
    let per_atom: Vec<(f32, f32, f32, bool)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let list = &neighbours[start[i] as usize..start[i + 1] as usize];
            let (r0, r) = (at(reference, i as u32), at(current, i as u32));
            let vectors = list.iter().map(|&j| {
                let (d0, d) = (at(reference, j) - r0, at(current, j) - r);
                match &cells {
                    None => (d0, d),
                    Some((h0, h0_inv, h, h_inv)) => {
                        let f0 = *h0_inv * d0;
                        let f0 = f0 - f0.round() * wrap;
                        let f = *h_inv * d;
                        (*h0 * f0, *h * (f - (f - f0).round() * wrap))
                    }
                }
            });
            let mut v = DMat3::ZERO;
            let mut w = DMat3::ZERO;
            for (d0, d) in vectors.clone() {
                v += outer(d0, d0);
                w += outer(d, d0);
            }
            // A plane or a line of neighbours: V is singular (relative to its own scale).
            let scale = v.col(0).x + v.col(1).y + v.col(2).z;
            let det = v.determinant();
            let singular = det.abs().partial_cmp(&(1e-10 * scale * scale * scale))
                != Some(std::cmp::Ordering::Greater);
            if list.len() < 3 || singular {
                return (0.0, 0.0, 0.0, true);
            }
            let f = w * v.inverse();
            let e = (f.transpose() * f - DMat3::IDENTITY) * 0.5;
            let c = |row: usize, col: usize| e.col(col)[row];
            let shear = (c(0, 1).powi(2)
                + c(0, 2).powi(2)
                + c(1, 2).powi(2)
                + ((c(0, 0) - c(1, 1)).powi(2)
                    + (c(0, 0) - c(2, 2)).powi(2)
                    + (c(1, 1) - c(2, 2)).powi(2))
                    / 6.0)
                .sqrt();
            let volumetric = (c(0, 0) + c(1, 1) + c(2, 2)) / 3.0;
            let d2min: f64 = vectors.map(|(d0, d)| (d - f * d0).length_squared()).sum();
            (shear as f32, volumetric as f32, d2min as f32, false)
        })
        .collect();
    let mut strain = Strain::default();
    for (shear, volumetric, d2min, invalid) in per_atom {
        strain.shear.push(shear);
        strain.volumetric.push(volumetric);
        strain.d2min.push(d2min);
        strain.invalid.push(invalid);
    }
    Ok(strain)
}

/// `a bᵀ`.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}
