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
//! [`AllOrigins`] keeps the unwrapped frames and gives the displacement averaged over every
//! time origin against lag time (MDAnalysis's `EinsteinMSD`), and [`fit_diffusion`] the
//! diffusion coefficient from its slope.
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
use crate::pbc::NearestImage;

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
    /// [`AllOrigins`] would keep more than its memory limit.
    Memory {
        /// Atoms per frame.
        atoms: usize,
        /// Frames kept so far, this one included.
        frames: usize,
        /// The limit in bytes.
        limit: usize,
    },
    /// An atom's weight (a mass for [`crate::vacf::Velocities::density_of_states`]) is not
    /// positive and finite.
    Weight(usize),
    /// A frame-by-frame matrix ([`crate::rmsd::rmsd_matrix`]) would take more than its
    /// memory limit.
    Matrix {
        /// Frames.
        frames: usize,
        /// The bytes it would take.
        bytes: usize,
        /// The limit in bytes.
        limit: usize,
    },
    /// [`AllOrigins::mean`] was given a kind for another number of atoms than the frames'.
    KindCount {
        /// The frames' atoms.
        atoms: usize,
        /// The kinds given.
        kinds: usize,
    },
}

impl fmt::Display for MsdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MsdError::AtomCount { first, frame } => write!(
                f,
                "this frame has {frame} atoms and the first {first}: every frame must hold the same atoms"
            ),
            MsdError::NotFinite(i) => write!(f, "atom {i} has a coordinate that is not finite"),
            MsdError::Memory {
                atoms,
                frames,
                limit,
            } => write!(
                f,
                "{frames} frames of {atoms} atoms need {} MB kept for the average over every time origin, over the limit of {} MB: take fewer frames (a --frames step) or raise the limit",
                (frames * atoms * STORED_BYTES).div_ceil(1 << 20),
                limit >> 20
            ),
            MsdError::Matrix {
                frames,
                bytes,
                limit,
            } => write!(
                f,
                "a {frames} x {frames} matrix of the frames needs {} MB, over the limit of {} MB: take fewer frames (a --frames step) or raise the limit",
                bytes.div_ceil(1 << 20),
                limit >> 20
            ),
            MsdError::Weight(i) => write!(f, "atom {i}'s mass is not positive and finite"),
            MsdError::KindCount { atoms, kinds } => write!(
                f,
                "{kinds} kinds given for frames of {atoms} atoms: one kind per atom"
            ),
        }
    }
}

impl std::error::Error for MsdError {}

/// The checks a frame passes before it is followed: every position finite and, after a first
/// frame of `first` atoms, as many atoms.
pub(crate) fn check_frame<T: Copy + Into<f64>>(
    positions: &[[T; 3]],
    first: Option<usize>,
) -> Result<(), MsdError> {
    if let Some(i) = positions
        .iter()
        .position(|p| p.iter().any(|x| !(*x).into().is_finite()))
    {
        return Err(MsdError::NotFinite(i));
    }
    match first {
        Some(first) if first != positions.len() => Err(MsdError::AtomCount {
            first,
            frame: positions.len(),
        }),
        _ => Ok(()),
    }
}

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

    /// Each atom's position unwrapped by continuity, as of the last frame given (empty before
    /// the first).
    pub fn unwrapped(&self) -> &[[f64; 3]] {
        &self.unwrapped
    }

    /// Follows the atoms to `frame` and returns each atom's squared displacement (Å²) from
    /// the first frame given.
    pub fn add(&mut self, frame: &Frame) -> Result<Vec<f64>, MsdError> {
        let n = frame.n_atoms();
        check_frame(
            &frame.positions,
            (self.frames > 0).then_some(self.origin.len()),
        )?;
        let now: Vec<[f64; 3]> = frame.positions.iter().map(|p| p.map(f64::from)).collect();
        self.frames += 1;
        if self.frames == 1 {
            self.origin = now.clone();
            self.unwrapped = now.clone();
            self.last = now;
            return Ok(vec![0.0; n]);
        }
        let image = frame.cell.as_ref().and_then(NearestImage::new);
        for ((u, last), p) in self.unwrapped.iter_mut().zip(&mut self.last).zip(&now) {
            let step: [f64; 3] = std::array::from_fn(|k| p[k] - last[k]);
            let step = image.as_ref().map_or(step, |m| m.apply(step));
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

/// Bytes [`AllOrigins`] keeps per atom per frame: the displacement from the atom's first
/// position as three `f32`.
pub const STORED_BYTES: usize = 12;

/// The mean squared displacement against lag time, averaged over every time origin: for a lag
/// of m frames, the mean over all atoms and all origins k of |r(k + m) − r(k)|², as
/// MDAnalysis's `EinsteinMSD` gives it (the windowed MSD; GROMACS's `gmx msd` takes an origin
/// every `-trestart` instead). Averaging over origins is what makes a diffusion coefficient
/// from one trajectory usable: the single-origin curve of [`Tracker`] is one noisy sample.
///
/// Frames are given as unwrapped positions ([`Tracker::unwrapped`]) and kept as `f32`
/// displacements from each atom's first position ([`STORED_BYTES`] per atom per frame, up to
/// the limit given to [`AllOrigins::new`]); [`AllOrigins::mean`] then needs O(T log T) per atom
/// for T frames: each coordinate's autocorrelation by FFT (two series to one complex
/// transform, the power spectra of a kind summed before one inverse transform), the squared
/// terms by prefix sums (the algorithm of Kneller et al., nMoldyn). The atoms are split into
/// fixed blocks summed in order, so the result does not depend on the thread count.
///
/// ```
/// use texmap_md_io::msd::AllOrigins;
/// // One atom moving 1 Å per frame along x: every lag m has squared displacement m².
/// let mut all = AllOrigins::new(1 << 20);
/// for f in 0..5 {
///     all.push(&[[f as f64, 0.0, 0.0]]).unwrap();
/// }
/// let lags = all.mean(&[0], 1).unwrap();
/// for (m, v) in lags.total.iter().enumerate() {
///     assert!((v - (m * m) as f64).abs() < 1e-9);
/// }
/// ```
#[derive(Clone, Debug)]
pub struct AllOrigins {
    first: Vec<[f64; 3]>,
    /// Each frame's displacements from the first.
    store: crate::correlate::Store,
}

/// [`AllOrigins::mean`]'s result: per lag 0, 1, … T − 1 frames.
#[derive(Clone, Debug, PartialEq)]
pub struct LagMsd {
    /// Over every atom (Å²).
    pub total: Vec<f64>,
    /// Over the atoms of each kind (NaN for a kind without atoms).
    pub kinds: Vec<Vec<f64>>,
}

impl AllOrigins {
    /// Keeps no frame yet; [`AllOrigins::push`] refuses a frame that would take the kept
    /// displacements over `limit` bytes.
    pub fn new(limit: usize) -> AllOrigins {
        AllOrigins {
            first: Vec::new(),
            store: crate::correlate::Store::new(limit),
        }
    }

    /// Frames kept.
    pub fn frames(&self) -> usize {
        self.store.frames
    }

    /// Keeps a frame's unwrapped positions (Å): every frame has the first's atoms in the
    /// same order.
    pub fn push(&mut self, unwrapped: &[[f64; 3]]) -> Result<(), MsdError> {
        if self.store.frames == 0 {
            check_frame(unwrapped, None)?;
            self.first = unwrapped.to_vec();
        }
        let first = &self.first;
        self.store.push(unwrapped, |i, p| {
            std::array::from_fn(|k| (p[k] - first[i][k]) as f32)
        })
    }

    /// The mean squared displacement per lag over every atom and over each of `kinds` kinds,
    /// `kind[i]` (below `kinds`) naming atom i's.
    pub fn mean(&self, kind: &[usize], kinds: usize) -> Result<LagMsd, MsdError> {
        self.store.check_kinds(kind, kinds)?;
        let t = self.store.frames;
        if t == 0 {
            return Ok(LagMsd {
                total: Vec::new(),
                kinds: vec![Vec::new(); kinds],
            });
        }
        // Centred: the displacements do not change, the FFT's rounding shrinks with the values.
        let spectra = self.store.spectra(kind, kinds, true, None);
        let mut counts = vec![0usize; kinds];
        for &k in kind {
            counts[k] += 1;
        }
        // Per kind and lag: Σ over the kind's series and origins of the squared displacement,
        // Σ (x(k + m) − x(k))² = Σ x(k + m)² + Σ x(k)² − 2 Σ x(k) x(k + m).
        let numerators: Vec<Vec<f64>> = spectra
            .correlations()
            .iter()
            .zip(&spectra.squares)
            .map(|(correlation, squares)| {
                let mut prefix = vec![0.0f64; t + 1];
                for (f, s) in squares.iter().enumerate() {
                    prefix[f + 1] = prefix[f] + s;
                }
                (0..t)
                    .map(|m| {
                        let value = prefix[t - m] + (prefix[t] - prefix[m]) - 2.0 * correlation[m];
                        value.max(0.0)
                    })
                    .collect()
            })
            .collect();
        Ok(LagMsd {
            total: per_origin(&|m| numerators.iter().map(|g| g[m]).sum(), t, kind.len()),
            kinds: (0..kinds)
                .map(|g| per_origin(&|m| numerators[g][m], t, counts[g]))
                .collect(),
        })
    }
}

/// Per lag m < t: `sum(m)` averaged over the `t − m` origins and `atoms` atoms (NaN without
/// atoms).
pub(crate) fn per_origin(sum: &dyn Fn(usize) -> f64, t: usize, atoms: usize) -> Vec<f64> {
    (0..t)
        .map(|m| {
            if atoms == 0 {
                f64::NAN
            } else {
                sum(m) / ((t - m) * atoms) as f64
            }
        })
        .collect()
}

/// A diffusion coefficient from the slope of the mean squared displacement against time
/// (Einstein: MSD = 6 D t in three dimensions), fitted by least squares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffusion {
    /// D in the units of the MSD per unit of time over 6 (Å²/ps gives 10⁻⁴ cm²/s).
    pub d: f64,
    /// The fitted line's slope and intercept.
    pub slope: f64,
    /// The line's value at time 0.
    pub intercept: f64,
    /// Points fitted.
    pub points: usize,
}

/// Fits MSD = slope · t + intercept to the points with `from ≤ t ≤ to` and a finite MSD, as
/// `gmx msd` does between `-beginfit` and `-endfit`; `None` with fewer than two distinct times.
/// A time within a millionth of the range of either end counts as inside: times read from
/// single-precision files land a rounding away from the whole values users name.
pub fn fit_diffusion(time: &[f64], msd: &[f64], from: f64, to: f64) -> Option<Diffusion> {
    let slack = 1e-6 * from.abs().max(to.abs());
    let points: Vec<(f64, f64)> = time
        .iter()
        .zip(msd)
        .filter(|(t, m)| **t >= from - slack && **t <= to + slack && m.is_finite())
        .map(|(t, m)| (*t, *m))
        .collect();
    let count = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mean_t = points.iter().map(|p| p.0).sum::<f64>() / count;
    let mean_m = points.iter().map(|p| p.1).sum::<f64>() / count;
    let stt: f64 = points.iter().map(|p| (p.0 - mean_t).powi(2)).sum();
    if stt <= 0.0 {
        return None;
    }
    let stm: f64 = points.iter().map(|p| (p.0 - mean_t) * (p.1 - mean_m)).sum();
    let slope = stm / stt;
    Some(Diffusion {
        d: slope / 6.0,
        slope,
        intercept: mean_m - slope * mean_t,
        points: points.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition, every origin and lag summed directly: O(T² N).
    fn direct(frames: &[Vec<[f64; 3]>], kind: &[usize], kinds: usize) -> LagMsd {
        let t = frames.len();
        let atoms = kind.len();
        let mut sums = vec![vec![0.0f64; t]; kinds];
        for m in 0..t {
            for k in 0..t - m {
                for i in 0..atoms {
                    let d: f64 = (0..3)
                        .map(|a| (frames[k + m][i][a] - frames[k][i][a]).powi(2))
                        .sum();
                    sums[kind[i]][m] += d;
                }
            }
        }
        let count = |g: usize| kind.iter().filter(|&&k| k == g).count();
        LagMsd {
            total: (0..t)
                .map(|m| sums.iter().map(|s| s[m]).sum::<f64>() / ((t - m) * atoms) as f64)
                .collect(),
            kinds: (0..kinds)
                .map(|g| {
                    (0..t)
                        .map(|m| sums[g][m] / ((t - m) * count(g)) as f64)
                        .collect()
                })
                .collect(),
        }
    }

    /// A deterministic walk: atoms of three kinds with different step sizes, drifting away
    /// from positions hundreds of Å from the origin (the stored f32 displacements and the
    /// centring must keep the precision).
    fn walk(atoms: usize, t: usize) -> (Vec<Vec<[f64; 3]>>, Vec<usize>) {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let kind: Vec<usize> = (0..atoms).map(|i| (i * 7) % 3).collect();
        let mut p: Vec<[f64; 3]> = (0..atoms)
            .map(|_| std::array::from_fn(|_| 500.0 + 100.0 * next()))
            .collect();
        let mut frames = Vec::new();
        for _ in 0..t {
            frames.push(p.clone());
            for (q, k) in p.iter_mut().zip(&kind) {
                let step = [0.3, 1.0, 2.5][*k];
                for x in q.iter_mut() {
                    *x += step * next() + 0.05;
                }
            }
        }
        (frames, kind)
    }

    #[test]
    fn every_origin_as_the_definition_sums_it() {
        // 2,100 atoms: three parallel tasks, the last one partial; 37 frames: a padded FFT.
        let (frames, kind) = walk(2100, 37);
        let mut all = AllOrigins::new(usize::MAX);
        for f in &frames {
            all.push(f).unwrap();
        }
        let fast = all.mean(&kind, 3).unwrap();
        let slow = direct(&frames, &kind, 3);
        for (series, (a, b)) in std::iter::once((&fast.total, &slow.total))
            .chain(fast.kinds.iter().zip(&slow.kinds))
            .enumerate()
        {
            for (m, (x, y)) in a.iter().zip(b).enumerate() {
                assert!(
                    (x - y).abs() <= 1e-5 * y.max(1e-3),
                    "series {series} lag {m}: {x} against {y}"
                );
            }
        }
        assert_eq!(fast.total[0], 0.0);
        // Fixed tasks summed in order: the same bits on one thread as on the pool.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| all.mean(&kind, 3).unwrap());
        assert_eq!(one, fast);
        // The kinds' steps differ, so do their curves.
        assert!(fast.kinds[2][10] > 10.0 * fast.kinds[0][10]);
    }

    #[test]
    fn the_same_for_one_frame_two_frames_and_an_empty_kind() {
        for t in [1, 2] {
            let (frames, kind) = walk(5, t);
            let mut all = AllOrigins::new(usize::MAX);
            for f in &frames {
                all.push(f).unwrap();
            }
            // A fourth kind has no atoms: its column is NaN, not a division by zero.
            let fast = all.mean(&kind, 4).unwrap();
            let slow = direct(&frames, &kind, 3);
            assert_eq!(fast.total.len(), t);
            for (x, y) in fast.total.iter().zip(&slow.total) {
                assert!((x - y).abs() <= 1e-6 * y.max(1e-3), "{x} {y}");
            }
            assert!(fast.kinds[3].iter().all(|v| v.is_nan()));
        }
    }

    #[test]
    fn refuses_what_it_cannot_keep_or_average() {
        let mut all = AllOrigins::new(2 * 3 * STORED_BYTES);
        all.push(&[[0.0; 3]; 3]).unwrap();
        assert_eq!(
            all.push(&[[0.0; 3]; 2]),
            Err(MsdError::AtomCount { first: 3, frame: 2 })
        );
        assert_eq!(
            all.push(&[[0.0, f64::NAN, 0.0]; 3]),
            Err(MsdError::NotFinite(0))
        );
        all.push(&[[1.0; 3]; 3]).unwrap();
        let e = all.push(&[[2.0; 3]; 3]).unwrap_err();
        assert!(matches!(e, MsdError::Memory { frames: 3, .. }), "{e}");
        assert_eq!(all.frames(), 2);
        assert!(all.mean(&[0, 0], 1).is_err());
        assert!(all.mean(&[0, 0, 1], 1).is_err());
        assert_eq!(all.mean(&[0, 0, 0], 1).unwrap().total, vec![0.0, 3.0]);
    }

    #[test]
    fn a_line_fitted_gives_its_slope_over_six() {
        let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.5).collect();
        let msd: Vec<f64> = t.iter().map(|t| 1.2 * t + 3.0).collect();
        let fit = fit_diffusion(&t, &msd, 2.0, 20.0).unwrap();
        assert!((fit.slope - 1.2).abs() < 1e-12 && (fit.intercept - 3.0).abs() < 1e-10);
        assert!((fit.d - 0.2).abs() < 1e-12);
        assert_eq!(fit.points, 37);
        assert!(fit_diffusion(&t, &msd, 2.0, 2.2).is_none());
        // Ends a rounding away from the times given still count.
        let near: Vec<f64> = t.iter().map(|t| t * (1.0 + 3e-8)).collect();
        assert_eq!(fit_diffusion(&near, &msd, 2.0, 20.0).unwrap().points, 37);
    }
}
