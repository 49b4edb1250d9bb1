//! Coordination numbers: how many atoms lie within a cutoff distance of each atom, as OVITO's
//! Coordination analysis modifier counts them, so that under- and over-coordinated atoms
//! (surfaces, vacancies, amorphous regions, dangling bonds) can be coloured and selected.
//!
//! The pairs come from the cell grid of [`crate::bonds`] ([`bonds_with_radii`] with every atom's
//! radius set so that its bond cutoff is the coordination cutoff): linear in the atoms,
//! parallel, the same counts for any thread count, under the minimum image in a periodic cell.
//! A pair counts when its distance is below the cutoff and above 0.4 Å (the bond finder's floor:
//! atoms on top of each other are damage, not neighbours).
//!
//! The minimum image is only the nearest image: a periodic cell narrower than three cutoffs
//! (perpendicular width) along some axis would need several images of one neighbour, and is an
//! error ([`CoordinationError::CellTooSmall`]) rather than a silent undercount; replicate the
//! frame first ([`crate::replicate`]).
//!
//! ```
//! use texmap_md_io::coordination::coordination;
//! use texmap_md_io::Frame;
//! let mut frame = Frame::new();
//! // A square of side 2 Å: each corner has two neighbours at 2 Å, the diagonal is 2.83 Å.
//! frame.positions = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 2.0, 0.0]];
//! assert_eq!(coordination(&frame, 2.5).unwrap(), [2, 2, 2, 2]);
//! assert_eq!(coordination(&frame, 3.0).unwrap(), [3, 3, 3, 3]);
//! ```

use std::fmt;

use crate::bonds::{BOND_TOLERANCE, bonds_with_radii};
use crate::frame::Frame;

/// The largest cutoff taken, in Å (a typo such as 300 would otherwise make every atom a
/// neighbour of every other, quadratic in memory).
pub const MAX_CUTOFF: f32 = 20.0;

/// Why coordination numbers cannot be counted.
#[derive(Clone, Debug, PartialEq)]
pub enum CoordinationError {
    /// The cutoff is not a distance in (0.45, [`MAX_CUTOFF`]] Å.
    BadCutoff(f32),
    /// The periodic cell is narrower than three cutoffs along an axis.
    CellTooSmall {
        /// The cell's narrowest perpendicular width, Å.
        width: f64,
        /// The cutoff, Å.
        cutoff: f32,
    },
}

impl fmt::Display for CoordinationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoordinationError::BadCutoff(c) => write!(
                f,
                "the cutoff {c} is not a distance between 0.45 and {MAX_CUTOFF} Å"
            ),
            CoordinationError::CellTooSmall { width, cutoff } => write!(
                f,
                "the periodic cell is {width:.2} Å wide, less than three cutoffs of {cutoff} Å: \
                 replicate it first (--replicate) so each neighbour has one nearest image"
            ),
        }
    }
}

impl std::error::Error for CoordinationError {}

/// The number of atoms within `cutoff` Å of each atom of `frame` (see the module docs).
pub fn coordination(frame: &Frame, cutoff: f32) -> Result<Vec<u32>, CoordinationError> {
    if !(cutoff > BOND_TOLERANCE && cutoff <= MAX_CUTOFF) {
        return Err(CoordinationError::BadCutoff(cutoff));
    }
    let n = frame.n_atoms();
    // Every pair's bond cutoff is r + r + tolerance = `cutoff`.
    let radius = (cutoff - BOND_TOLERANCE) / 2.0;
    let bonds = bonds_with_radii(&frame.positions, &vec![radius; n], frame.cell);
    if let Some(cell) = frame.cell
        && !bonds.periodic
        && n >= 2
    {
        let width = cell.min_width();
        return Err(CoordinationError::CellTooSmall { width, cutoff });
    }
    let mut counts = vec![0u32; n];
    for [i, j] in bonds.pairs {
        counts[i as usize] += 1;
        counts[j as usize] += 1;
    }
    Ok(counts)
}
