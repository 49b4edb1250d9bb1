//! Mean squared displacement from the first frame, with the atoms followed across the periodic
//! boundaries: what a diffusion coefficient is read from (D = MSD / 6t at long times), as
//! MDAnalysis's `NoJump` transformation followed by the displacement from frame 0 gives it.
//!
//! [`Tracker`] keeps each atom's unwrapped position: every frame after the first moves it by the
//! minimum image of its step since the frame before (GROMACS's `trjconv -pbc nojump`), so an
//! atom that leaves through one face and comes back through the other is seen to have gone
//! on. That holds while no atom moves half a cell (the narrowest width) between two frames
//! given: frames far apart in a fast system (a large `--frames` step) undercount.
//! Unwrapped trajectories (LAMMPS `xu yu zu`) and frames without a cell are followed as they
//! are.
//!
//! ```
//! use texmap_md_io::msd::Tracker;
//! use texmap_md_io::{Frame, UnitCell};
//! let mut frame = Frame::new();
//! frame.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
//! frame.positions = vec![[9.5, 5.0, 5.0], [1.0, 1.0, 1.0]];
//! let mut t = Tracker::new();
//! assert_eq!(t.add(&frame).unwrap(), [0.0, 0.0]);
//! // The first atom crosses the face at x = 10 and comes in at x = 0.5: 1 Å gone, not 9 back.
//! frame.positions[0] = [0.5, 5.0, 5.0];
//! frame.positions[1] = [1.0, 3.0, 1.0];
//! let d2 = t.add(&frame).unwrap();
//! assert!((d2[0] - 1.0).abs() < 1e-9 && (d2[1] - 4.0).abs() < 1e-9);
//! ```

use std::fmt;

use crate::frame::Frame;
use crate::pbc::minimum_image;

/// Why a frame cannot be followed from the ones before.
#[derive(Clone, Debug, PartialEq)]
pub enum MsdError {
    /// The frame has another number of atoms than the first.
    AtomCount {
        /// The first frame's atoms.
        first: usize,
        /// This frame's.
        frame: usize,
    },
    /// An atom's position is not finite.
    NotFinite(usize),
}

impl fmt::Display for MsdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MsdError::AtomCount { first, frame } => write!(
                f,
                "this frame has {frame} atoms and the first {first}: displacements follow the same atoms"
            ),
            MsdError::NotFinite(i) => write!(f, "atom {i} has no finite position"),
        }
    }
}

impl std::error::Error for MsdError {}

/// Each atom's position unwrapped by continuity since the first frame (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Tracker {
    /// The first frame's positions.
    origin: Vec<[f64; 3]>,
    /// The last frame's positions as the file gave them.
    last: Vec<[f64; 3]>,
    /// The unwrapped positions.
    unwrapped: Vec<[f64; 3]>,
    /// Frames followed.
    frames: usize,
}

impl Tracker {
    /// A tracker that has seen no frame.
    pub fn new() -> Tracker {
        Tracker::default()
    }

    /// Follows the atoms to `frame` and returns each atom's squared displacement (Å²) from
    /// the first frame given.
    pub fn add(&mut self, frame: &Frame) -> Result<Vec<f64>, MsdError> {
        let n = frame.n_atoms();
        if let Some(i) = frame
            .positions
            .iter()
            .position(|p| p.iter().any(|x| !x.is_finite()))
        {
            return Err(MsdError::NotFinite(i));
        }
        let now: Vec<[f64; 3]> = frame.positions.iter().map(|p| p.map(f64::from)).collect();
        self.frames += 1;
        if self.frames == 1 {
            self.origin = now.clone();
            self.unwrapped = now.clone();
            self.last = now;
            return Ok(vec![0.0; n]);
        }
        if n != self.origin.len() {
            self.frames -= 1;
            return Err(MsdError::AtomCount {
                first: self.origin.len(),
                frame: n,
            });
        }
        for ((u, last), p) in self.unwrapped.iter_mut().zip(&mut self.last).zip(&now) {
            let step: [f64; 3] = std::array::from_fn(|k| p[k] - last[k]);
            let step = match &frame.cell {
                Some(cell) => minimum_image(cell, step),
                None => step,
            };
            for k in 0..3 {
                u[k] += step[k];
            }
            *last = *p;
        }
        Ok(self
            .unwrapped
            .iter()
            .zip(&self.origin)
            .map(|(u, o)| (0..3).map(|k| (u[k] - o[k]).powi(2)).sum())
            .collect())
    }
}
