//! Point defects by Wigner–Seitz cell analysis, as OVITO's Wigner-Seitz defect analysis
//! modifier finds them in radiation-damage and diffusion simulations: every site of a reference
//! configuration (the perfect crystal) owns the space closer to it than to any other site (its
//! Wigner–Seitz cell), each atom of the current frame is counted on the site whose cell holds
//! it, and a site's occupancy tells what happened there: 0 a vacancy, 1 a regular site, 2 or
//! more an interstitial (a split dumbbell puts two atoms on one site). The vacancy count is the
//! number of empty sites; the interstitial count the atoms beyond one per site, so that a
//! Frenkel pair is one of each and a replacement sequence none.
//!
//! The nearest site is found in a cell grid over the sites (at the nearest periodic image in a
//! periodic reference). A current frame with a cell of its own is first mapped onto the
//! reference cell (each atom's fractional coordinates in its cell, placed in the reference's):
//! OVITO's "affine mapping to the reference", which equals no mapping while the cell does not
//! change, and keeps a box that an NPT run has strained from moving atoms across sites. The
//! current frame may hold another number of atoms than the reference (sputtered or implanted
//! atoms). Atoms are assigned in parallel; the result does not depend on the thread count.
//!
//! ```
//! use texmap_md_io::wigner_seitz::wigner_seitz;
//! use texmap_md_io::{Frame, UnitCell};
//! // A simple cubic crystal of 4³ sites (a = 2.5 Å); atom 0 pushed next to site 1 (a Frenkel pair).
//! let mut reference = Frame::new();
//! for n in 0..64 {
//!     reference.positions.push([(n % 4) as f32 * 2.5, (n / 4 % 4) as f32 * 2.5, (n / 16) as f32 * 2.5]);
//! }
//! reference.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
//! let mut current = reference.clone();
//! current.positions[0] = [2.9, 0.3, 0.0];
//! let ws = wigner_seitz(&reference, &current).unwrap();
//! assert_eq!((ws.vacancies, ws.interstitials), (1, 1));
//! assert_eq!((ws.occupancy[0], ws.occupancy[1]), (0, 2));
//! assert_eq!(ws.site[0], Some(1));
//! ```

use std::fmt;

use glam::{DMat3, DVec3};

use crate::frame::Frame;
use crate::neighbours::Grid;

/// What [`wigner_seitz`] finds.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct WignerSeitz {
    /// Per site (atom of the reference): the atoms of the current frame in its cell.
    pub occupancy: Vec<u32>,
    /// Per atom of the current frame: its site (`None` for an atom with non-finite
    /// coordinates, which is counted nowhere).
    pub site: Vec<Option<u32>>,
    /// Sites with no atom.
    pub vacancies: usize,
    /// Atoms beyond one per site.
    pub interstitials: usize,
}

/// Why the analysis cannot be made.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WignerSeitzError {
    /// The reference has no site with finite coordinates.
    NoSites,
}

impl fmt::Display for WignerSeitzError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WignerSeitzError::NoSites => {
                write!(
                    f,
                    "the reference configuration has no atoms to serve as sites"
                )
            }
        }
    }
}

impl std::error::Error for WignerSeitzError {}

/// Each atom of `current` on its nearest site of `reference` (see the module docs).
pub fn wigner_seitz(reference: &Frame, current: &Frame) -> Result<WignerSeitz, WignerSeitzError> {
    use rayon::prelude::*;
    if !reference
        .positions
        .iter()
        .any(|p| p.iter().all(|v| v.is_finite()))
    {
        return Err(WignerSeitzError::NoSites);
    }
    let grid = Grid::new(&reference.positions, reference.cell.as_ref());
    let edges = |f: &Frame| f.cell.map(|c| DMat3::from_cols_array_2d(&c.matrix()));
    // Current Cartesian -> reference Cartesian, through fractional coordinates.
    let (map, shift) = match (edges(reference), edges(current)) {
        (Some(h0), Some(h)) => {
            let (o0, o) = (
                DVec3::from(reference.cell.expect("has a cell").origin()),
                DVec3::from(current.cell.expect("has a cell").origin()),
            );
            let map = h0 * h.inverse();
            (map, o0 - map * o)
        }
        _ => (DMat3::IDENTITY, DVec3::ZERO),
    };
    let site: Vec<Option<u32>> = current
        .positions
        .par_iter()
        .map_init(Vec::new, |cells, p| {
            let q = map * DVec3::from(p.map(f64::from)) + shift;
            grid.nearest_to(q.to_array(), cells).map(|(j, _)| j as u32)
        })
        .collect();
    let mut occupancy = vec![0u32; reference.n_atoms()];
    for s in site.iter().flatten() {
        occupancy[*s as usize] += 1;
    }
    let finite = |p: &[f32; 3]| p.iter().all(|v| v.is_finite());
    let vacancies = occupancy
        .iter()
        .zip(&reference.positions)
        .filter(|(o, p)| **o == 0 && finite(p))
        .count();
    let interstitials = occupancy
        .iter()
        .map(|&o| o.saturating_sub(1) as usize)
        .sum();
    Ok(WignerSeitz {
        occupancy,
        site,
        vacancies,
        interstitials,
    })
}
