//! Trajectory smoothing: every frame's positions replaced by their mean over a window of
//! consecutive frames centred on it, as VMD's trajectory smoothing does, so that a movie shows
//! the molecule's motion rather than its thermal jitter.
//!
//! - The window of frame `f` with half-width `h` is `f - k ..= f + k`, with `k = min(h, f,
//!   n - 1 - f)`: shrunk symmetrically at the trajectory's ends ([`window`]), so that steady
//!   motion is not pulled back at the first and last frames (a one-sided window would lag).
//!   The first and last frames are drawn as read.
//! - With a periodic cell, each neighbour's position enters as the centre frame's position
//!   plus the nearest image of the displacement ([`crate::pbc::minimum_image`] in the centre
//!   frame's cell), so an atom the trajectory wrapped across the box between two frames is
//!   averaged where it is, not through the middle of the box. This holds while no atom moves
//!   more than half a box length within one window.
//! - Only positions are averaged; velocities, the cell and every other column are the centre
//!   frame's. Frames must have the same atoms in the same order (LAMMPS dumps are sorted by id
//!   when read); a window that meets another atom count is an error naming both frames.
//!
//! [`Smoother`] reads the window's frames by number from a [`crate::Trajectory`] or a
//! [`crate::Sequence`] and keeps the positions of the last window, so that consecutive frames
//! read each frame once.
//!
//! ```
//! use texmap_md_io::smooth::{mean_positions, window};
//! use texmap_md_io::Frame;
//! assert_eq!(window(0, 10, 2), 0..=0);
//! assert_eq!(window(1, 10, 2), 0..=2);
//! assert_eq!(window(5, 10, 2), 3..=7);
//! // An atom moving 1 Å per frame: the mean over a centred window is where it is.
//! let mut centre = Frame::new();
//! centre.positions = vec![[2.0, 0.0, 0.0]];
//! let (before, after) = ([[1.0, 0.0, 0.0]], [[3.0, 0.0, 0.0]]);
//! mean_positions(&mut centre, &[&before[..], &after[..]]);
//! assert_eq!(centre.positions[0], [2.0, 0.0, 0.0]);
//! ```

use std::collections::VecDeque;
use std::ops::RangeInclusive;

use crate::error::{Error, Location};
use crate::frame::Frame;
use crate::pbc::NearestImage;
use crate::trajectory::FrameSource;

/// The frames averaged into frame `f` of `n_frames` with half-width `half` (see the module
/// docs); `f..=f` when `half` is 0 or `f` is an end frame.
pub fn window(f: usize, n_frames: usize, half: usize) -> RangeInclusive<usize> {
    let k = half.min(f).min(n_frames.saturating_sub(f + 1));
    f - k..=f + k
}

/// `frame`'s positions replaced by their mean with `others` (each as many atoms as `frame`),
/// neighbours taken at their nearest image of the frame's position when the frame has a cell.
/// Sums in f64, so the mean of equal positions is that position exactly.
///
/// # Panics
/// When an entry of `others` has another length than `frame.positions` (check first).
pub fn mean_positions(frame: &mut Frame, others: &[&[[f32; 3]]]) {
    let n = frame.positions.len();
    assert!(
        others.iter().all(|o| o.len() == n),
        "frames of unequal atom counts"
    );
    let count = (others.len() + 1) as f64;
    let image = frame.cell.as_ref().and_then(NearestImage::new);
    for (i, p) in frame.positions.iter_mut().enumerate() {
        let centre = p.map(f64::from);
        let mut sum = [0.0f64; 3];
        for o in others {
            let d = [0, 1, 2].map(|k| f64::from(o[i][k]) - centre[k]);
            let d = image.as_ref().map_or(d, |m| m.apply(d));
            for k in 0..3 {
                sum[k] += d[k];
            }
        }
        *p = [0, 1, 2].map(|k| (centre[k] + sum[k] / count) as f32);
    }
}

/// Smooths frames read from a trajectory with a window of half-width `half` (see the module
/// docs), reading each neighbour once while frames are asked for in order.
#[derive(Debug)]
pub struct Smoother {
    half: usize,
    /// Positions of the frames read for recent windows, by frame index, in increasing order.
    cache: VecDeque<(usize, Vec<[f32; 3]>)>,
    scratch: Frame,
}

impl Smoother {
    /// A smoother averaging `2 * half + 1` frames (0: frames as read).
    pub fn new(half: usize) -> Smoother {
        Smoother {
            half,
            cache: VecDeque::new(),
            scratch: Frame::new(),
        }
    }

    /// The half-width of the window.
    pub fn half(&self) -> usize {
        self.half
    }

    /// `frame`, which holds frame `f` of `traj` as read, smoothed over its window of `n_frames`
    /// frames; the neighbours are read from `traj` (which is left at an arbitrary frame). A
    /// neighbour with another atom count is an error naming the trajectory and both frames.
    pub fn smooth(
        &mut self,
        traj: &mut impl FrameSource,
        n_frames: usize,
        f: usize,
        frame: &mut Frame,
    ) -> Result<(), Error> {
        let range = window(f, n_frames, self.half);
        if range.start() == range.end() {
            return Ok(());
        }
        while self.cache.front().is_some_and(|(g, _)| g < range.start()) {
            self.cache.pop_front();
        }
        self.cache.retain(|(g, _)| g <= range.end());
        for g in range.clone().filter(|&g| g != f) {
            if self.cache.iter().any(|(h, _)| *h == g) {
                continue;
            }
            traj.read_frame(g, &mut self.scratch)?;
            let at = self.cache.partition_point(|(h, _)| *h < g);
            self.cache
                .insert(at, (g, std::mem::take(&mut self.scratch.positions)));
        }
        // The centre frame as read, for its neighbours' windows.
        if !self.cache.iter().any(|(h, _)| *h == f) {
            let at = self.cache.partition_point(|(h, _)| *h < f);
            self.cache.insert(at, (f, frame.positions.clone()));
        }
        let window: Vec<&(usize, Vec<[f32; 3]>)> = self
            .cache
            .iter()
            .filter(|(g, _)| *g != f && range.contains(g))
            .collect();
        if let Some((g, p)) = window.iter().find(|(_, p)| p.len() != frame.n_atoms()) {
            return Err(Error::Parse {
                at: Location {
                    frame: Some(*g),
                    ..Location::file(&traj.name().into())
                },
                expected: "the same atoms in every frame of the smoothing window",
                found: format!("{} atoms, but frame {f} has {}", p.len(), frame.n_atoms()),
            });
        }
        let others: Vec<&[[f32; 3]]> = window.iter().map(|(_, p)| p.as_slice()).collect();
        mean_positions(frame, &others);
        Ok(())
    }
}
