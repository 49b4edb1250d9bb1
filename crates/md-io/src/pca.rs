//! Principal component analysis of atomic motion, as MDAnalysis's `analysis.pca.PCA`,
//! `gmx covar` + `gmx anaeig` and ProDy compute it: the covariance of the atoms' positions
//! over the frames, its eigenvectors (the collective motions, largest variance first) and each
//! frame projected onto them. The frames should be superposed first (`--align`), or the
//! molecule's rotation dominates the first components.
//!
//! With `x_f` a frame's 3N coordinates (Å) and `μ` their mean over the F frames, the
//! covariance is `C = Σ_f (x_f − μ)(x_f − μ)ᵀ / (F − 1)` (MDAnalysis's normalisation, unweighted);
//! `variance[k]` is its k-th largest eigenvalue (Å²), `vectors[k]` the unit eigenvector and
//! `projections[f][k] = (x_f − μ) · vectors[k]` (Å). When there are fewer frames than
//! coordinates the rank is below F and the same eigenpairs come from the F x F matrix of the
//! frames' products (`Y Yᵀ`, whose eigenvector `u` gives `Yᵀ u / √(λ (F − 1))`): a 10,000-atom
//! selection over 500 frames costs a 500² eigenproblem, not a 30,000² one.
//!
//! [`cosine_content`] is Hess's test (2002) of whether the sampling converged: a projection
//! that is half a cosine over the run (content near 1) is what random diffusion gives, not a
//! motion of the molecule.
//!
//! ```
//! use texmap_md_io::pca::Pca;
//! // Two atoms moving together along x: one component carries all the variance.
//! let mut pca = Pca::new(1 << 20);
//! for t in [-1.0f32, 0.0, 1.0, 0.5] {
//!     pca.add(&[[t, 0.0, 0.0], [5.0 + t, 2.0, 0.0]]).unwrap();
//! }
//! let c = pca.solve(2).unwrap();
//! assert!((c.variance[0] - c.total_variance).abs() < 1e-12);
//! let s = 0.5f64.sqrt();
//! for (got, want) in c.vectors[0][0].iter().zip([s, 0.0, 0.0]) {
//!     assert!((got - want).abs() < 1e-12);
//! }
//! assert!((c.projections[0][0] + 2.0f64.sqrt() * 1.125).abs() < 1e-12); // x₀ − μ = −1.125
//! ```

use std::fmt;

use rayon::prelude::*;

use crate::msd::MsdError;

/// The largest eigenproblem [`Pca::solve`] takes: min(frames, 3 x atoms). Its three n² f64
/// matrices take 384 MB at 4,000 and the decomposition about a minute.
pub const MAX_ORDER: usize = 4000;

/// What a principal component analysis could not do.
#[derive(Clone, Debug, PartialEq)]
pub enum PcaError {
    /// A frame that cannot be added (atom count, a coordinate not finite).
    Frame(MsdError),
    /// Keeping the frames would take more than the memory limit.
    Memory {
        /// Atoms per frame.
        atoms: usize,
        /// Frames kept so far, this one included.
        frames: usize,
        /// The limit in bytes.
        limit: usize,
    },
    /// Fewer than two frames: no covariance.
    TooFewFrames(usize),
    /// The eigenproblem would be larger than [`MAX_ORDER`].
    TooLarge {
        /// Frames added.
        frames: usize,
        /// Atoms per frame.
        atoms: usize,
    },
    /// The eigenvalue iteration did not converge (not expected for finite positions).
    NoConvergence,
}

impl fmt::Display for PcaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PcaError::Frame(e) => e.fmt(f),
            PcaError::Memory {
                atoms,
                frames,
                limit,
            } => write!(
                f,
                "{frames} frames of {atoms} atoms need {} MB kept for the covariance, over the limit of {} MB: select fewer atoms (name CA), take fewer frames (a --frames step) or raise the limit",
                (frames * atoms * 12).div_ceil(1 << 20),
                limit >> 20
            ),
            PcaError::TooFewFrames(n) => {
                write!(f, "{n} frame(s): a covariance needs at least two frames")
            }
            PcaError::TooLarge { frames, atoms } => write!(
                f,
                "{frames} frames of {atoms} atoms make a {}² eigenproblem, over the {MAX_ORDER}² this analysis takes: select fewer atoms (name CA) or take fewer frames (a --frames step)",
                frames.min(&(3 * atoms))
            ),
            PcaError::NoConvergence => {
                write!(f, "the eigenvalue iteration did not converge")
            }
        }
    }
}

impl std::error::Error for PcaError {}

/// The frames of a principal component analysis, kept until [`Pca::solve`].
#[derive(Clone, Debug)]
pub struct Pca {
    /// Every frame's 3N coordinates, frame after frame.
    data: Vec<f32>,
    /// Atoms per frame (set by the first).
    atoms: usize,
    frames: usize,
    /// The most bytes `data` may take.
    limit: usize,
}

/// The result of [`Pca::solve`]; see the module docs for the definitions.
#[derive(Clone, Debug)]
pub struct Components {
    /// Each atom's mean position (Å).
    pub mean: Vec<[f64; 3]>,
    /// The eigenvalues of the covariance, largest first (Å²): min(frames, 3N) of them, the
    /// others zero.
    pub variance: Vec<f64>,
    /// The trace of the covariance: the sum of all the variances (Å²).
    pub total_variance: f64,
    /// The first components asked for, each a unit vector of one displacement per atom, its
    /// largest-magnitude coordinate positive.
    pub vectors: Vec<Vec<[f64; 3]>>,
    /// Per frame, its projection on each of `vectors` (Å).
    pub projections: Vec<Vec<f64>>,
}

impl Components {
    /// The fraction of the total variance that components `0..=k` carry (MDAnalysis's
    /// `cumulated_variance[k]`).
    pub fn cumulated(&self, k: usize) -> f64 {
        let sum: f64 = self.variance[..=k.min(self.variance.len() - 1)]
            .iter()
            .sum();
        if self.total_variance > 0.0 {
            sum / self.total_variance
        } else {
            0.0
        }
    }

    /// `frames` structures along component `k` (`mean + t · vectors[k]`), `t` evenly from the
    /// smallest projection of any frame to the largest: the motion `gmx anaeig -extr` shows.
    pub fn along(&self, k: usize, frames: usize) -> Vec<Vec<[f32; 3]>> {
        let (lo, hi) = self
            .projections
            .iter()
            .map(|p| p[k])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
                (a.min(t), b.max(t))
            });
        (0..frames)
            .map(|i| {
                let t = if frames > 1 {
                    lo + (hi - lo) * i as f64 / (frames - 1) as f64
                } else {
                    0.5 * (lo + hi)
                };
                self.mean
                    .iter()
                    .zip(&self.vectors[k])
                    .map(|(m, v)| std::array::from_fn(|a| (m[a] + t * v[a]) as f32))
                    .collect()
            })
            .collect()
    }
}

impl Pca {
    /// No frame yet; `limit` bounds the bytes the frames are kept in (12 per atom and frame).
    pub fn new(limit: usize) -> Pca {
        Pca {
            data: Vec::new(),
            atoms: 0,
            frames: 0,
            limit,
        }
    }

    /// Frames added.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Adds a frame's positions (Å) of the analysed atoms, the same atoms in the same order
    /// every frame.
    pub fn add(&mut self, positions: &[[f32; 3]]) -> Result<(), PcaError> {
        crate::msd::check_frame(positions, (self.frames > 0).then_some(self.atoms))
            .map_err(PcaError::Frame)?;
        let bytes = (self.frames + 1)
            .saturating_mul(positions.len())
            .saturating_mul(12);
        if bytes > self.limit {
            return Err(PcaError::Memory {
                atoms: positions.len(),
                frames: self.frames + 1,
                limit: self.limit,
            });
        }
        self.atoms = positions.len();
        self.frames += 1;
        self.data.extend(positions.iter().flatten());
        Ok(())
    }

    /// The variances of every component and the first `components` vectors with every
    /// frame's projections on them.
    pub fn solve(&self, components: usize) -> Result<Components, PcaError> {
        let (f, d) = (self.frames, 3 * self.atoms);
        if f < 2 || d == 0 {
            return Err(PcaError::TooFewFrames(f));
        }
        let order = f.min(d);
        if order > MAX_ORDER {
            return Err(PcaError::TooLarge {
                frames: f,
                atoms: self.atoms,
            });
        }
        let k = components.min(order);
        // The mean, then the centred frames Y (f x d, f64).
        let mut mean = vec![0.0f64; d];
        for row in self.data.chunks_exact(d) {
            for (m, x) in mean.iter_mut().zip(row) {
                *m += f64::from(*x);
            }
        }
        mean.iter_mut().for_each(|m| *m /= f as f64);
        let y: Vec<f64> = self
            .data
            .chunks_exact(d)
            .flat_map(|row| row.iter().zip(&mean).map(|(x, m)| f64::from(*x) - m))
            .collect();
        let norm = 1.0 / (f - 1) as f64;
        let total_variance = y.iter().map(|v| v * v).sum::<f64>() * norm;
        let (values, vectors): (Vec<f64>, Vec<Vec<f64>>) = if d <= f {
            // C = Yᵀ Y / (f − 1) from the columns of Y (its transpose's rows).
            let yt = transpose(&y, f, d);
            let c = gram(&yt, d, f, norm);
            let eig = crate::eigen::symmetric(c, d).map_err(|_| PcaError::NoConvergence)?;
            let vectors = (0..k).map(|i| eig.vector(i).to_vec()).collect();
            (eig.values, vectors)
        } else {
            // G = Y Yᵀ / (f − 1); its eigenvector u of λ gives Yᵀ u / √(λ (f − 1)).
            let g = gram(&y, f, d, norm);
            let eig = crate::eigen::symmetric(g, f).map_err(|_| PcaError::NoConvergence)?;
            let scale = eig.values[0].abs().max(f64::MIN_POSITIVE);
            let vectors = (0..k)
                .map(|i| {
                    let lambda = eig.values[i];
                    let mut v = vec![0.0f64; d];
                    if lambda > scale * 1e-13 {
                        for (row, u) in y.chunks_exact(d).zip(eig.vector(i)) {
                            for (a, b) in v.iter_mut().zip(row) {
                                *a += u * b;
                            }
                        }
                        let s = 1.0 / (lambda * (f - 1) as f64).sqrt();
                        v.iter_mut().for_each(|a| *a *= s);
                        let big = v
                            .iter()
                            .fold(0.0f64, |m, a| if a.abs() > m.abs() { *a } else { m });
                        if big < 0.0 {
                            v.iter_mut().for_each(|a| *a = -*a);
                        }
                    }
                    v
                })
                .collect();
            (eig.values, vectors)
        };
        let projections = y
            .chunks_exact(d)
            .map(|row| {
                vectors
                    .iter()
                    .map(|v| row.iter().zip(v).map(|(a, b)| a * b).sum())
                    .collect()
            })
            .collect();
        let triples = |v: &[f64]| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        Ok(Components {
            mean: triples(&mean),
            variance: values.into_iter().map(|v| v.max(0.0)).collect(),
            total_variance,
            vectors: vectors.iter().map(|v| triples(v)).collect(),
            projections,
        })
    }
}

/// `rows` (r x len, row-major) transposed.
fn transpose(rows: &[f64], r: usize, len: usize) -> Vec<f64> {
    let mut t = vec![0.0; r * len];
    for (i, row) in rows.chunks_exact(len).enumerate() {
        for (j, v) in row.iter().enumerate() {
            t[j * r + i] = *v;
        }
    }
    t
}

/// The lower triangle of `scale · A Aᵀ` for `a` (r x len, row-major): one dot product of two
/// rows per entry, rows shared between the threads (each entry is summed in the same order
/// whatever their number).
fn gram(a: &[f64], r: usize, len: usize, scale: f64) -> Vec<f64> {
    let mut g = vec![0.0; r * r];
    g.par_chunks_mut(r).enumerate().for_each(|(i, out)| {
        let ri = &a[i * len..(i + 1) * len];
        for (j, o) in out.iter_mut().enumerate().take(i + 1) {
            let rj = &a[j * len..(j + 1) * len];
            *o = scale * dot(ri, rj);
        }
    });
    g
}

/// A dot product on four independent partial sums (a fixed order: the same bits on every
/// machine and thread count).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut s = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            s[l] += x[l] * y[l];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// Hess's cosine content of a projection `p` (one value per frame, evenly spaced) on the
/// cosine of `k + 1` half periods: `(2/T) (∫ cos(π (k+1) t / T) p dt)² / ∫ p² dt`, the
/// integrals by Simpson's rule as SciPy's `integrate.simpson` takes them (Cartwright's
/// correction for the last interval of an even count), so that it equals MDAnalysis's
/// `pca.cosine_content(space, k)`. Near 1: the projection is the cosine that random
/// diffusion gives (the run has not sampled the motion); 0 for an empty or constant-zero `p`.
pub fn cosine_content(p: &[f64], k: usize) -> f64 {
    let t = p.len();
    if t == 0 {
        return 0.0;
    }
    let cos: Vec<f64> = (0..t)
        .map(|i| (std::f64::consts::PI * i as f64 * (k + 1) as f64 / t as f64).cos() * p[i])
        .collect();
    let squares: Vec<f64> = p.iter().map(|v| v * v).collect();
    let den = simpson(&squares);
    if den == 0.0 {
        return 0.0;
    }
    2.0 / t as f64 * simpson(&cos).powi(2) / den
}

/// The molar gas constant in kJ/(mol K): `kT` of [`Landscape::new`] is `R T`.
pub const GAS_CONSTANT: f64 = 8.314_462_618e-3;

/// A free-energy landscape over two projections (gmx sham's Gibbs landscape of the PC1–PC2
/// plane): the frames binned on a `bins x bins` grid spanning the projections' range (equal
/// widths, the last bin closed on the right, as NumPy's `histogram2d` with that range), and
/// `ΔG = −kT ln(n / n_max)` per bin, 0 at the most visited and `None` where no frame fell.
#[derive(Clone, Debug, PartialEq)]
pub struct Landscape {
    /// The first projection's range (lowest, highest).
    pub x: (f64, f64),
    /// The second's.
    pub y: (f64, f64),
    /// Bins along each axis.
    pub bins: usize,
    /// Frames per bin, row-major with `x` along a row: `counts[j * bins + i]` holds bin `i`
    /// along x and `j` along y.
    pub counts: Vec<u32>,
    /// `ΔG` per bin in the unit of `kT`, `None` for an empty bin.
    pub free_energy: Vec<Option<f64>>,
}

impl Landscape {
    /// The landscape of the points `(x, y)` (one per frame) on `bins x bins` bins, at `kt`
    /// (`R T` in kJ/mol gives kJ/mol). `None` when there are no points, a point is not finite,
    /// `bins` is 0 or `kt` is not positive and finite. A range of zero width is widened by
    /// ±0.5 about its value, as NumPy widens it.
    pub fn new(points: &[(f64, f64)], bins: usize, kt: f64) -> Option<Landscape> {
        if points.is_empty()
            || bins == 0
            || !(kt.is_finite() && kt > 0.0)
            || points.iter().any(|p| !(p.0.is_finite() && p.1.is_finite()))
        {
            return None;
        }
        let range = |v: &mut dyn Iterator<Item = f64>| {
            let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
                (lo.min(a), hi.max(a))
            });
            if lo == hi {
                (lo - 0.5, hi + 0.5)
            } else {
                (lo, hi)
            }
        };
        let x = range(&mut points.iter().map(|p| p.0));
        let y = range(&mut points.iter().map(|p| p.1));
        let bin = |v: f64, (lo, hi): (f64, f64)| {
            (((v - lo) / (hi - lo) * bins as f64) as usize).min(bins - 1)
        };
        let mut counts = vec![0u32; bins * bins];
        for p in points {
            counts[bin(p.1, y) * bins + bin(p.0, x)] += 1;
        }
        let most = f64::from(counts.iter().copied().max().unwrap_or(1));
        let free_energy = counts
            .iter()
            .map(|&n| (n > 0).then(|| -kt * (f64::from(n) / most).ln()))
            .collect();
        Some(Landscape {
            x,
            y,
            bins,
            counts,
            free_energy,
        })
    }

    /// The centre of bin `i` along x and `j` along y.
    pub fn centre(&self, i: usize, j: usize) -> (f64, f64) {
        let at =
            |(lo, hi): (f64, f64), k: usize| lo + (hi - lo) * (k as f64 + 0.5) / self.bins as f64;
        (at(self.x, i), at(self.y, j))
    }
}

/// Simpson's rule over unit-spaced samples, as SciPy's `integrate.simpson` (1.11 and later).
fn simpson(y: &[f64]) -> f64 {
    let n = y.len();
    let basic = |y: &[f64]| {
        // Pairs of intervals: (y0 + 4 y1 + y2) / 3.
        y.windows(3)
            .step_by(2)
            .map(|w| (w[0] + 4.0 * w[1] + w[2]) / 3.0)
            .sum::<f64>()
    };
    match n {
        0 | 1 => 0.0,
        2 => 0.5 * (y[0] + y[1]),
        _ if n % 2 == 1 => basic(y),
        _ => {
            basic(&y[..n - 1]) + 5.0 / 12.0 * y[n - 1] + 2.0 / 3.0 * y[n - 2]
                - 1.0 / 12.0 * y[n - 3]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames of `atoms` atoms moving along two known orthogonal modes with uncorrelated
    /// amplitudes (standard deviations about 2.1 and 0.7 Å).
    fn two_modes(atoms: usize, frames: usize) -> (Pca, Vec<f64>, Vec<f64>) {
        let d = 3 * atoms;
        let mut m1: Vec<f64> = (0..d).map(|i| (i * 7 % 11) as f64 - 5.0).collect();
        let n1 = m1.iter().map(|v| v * v).sum::<f64>().sqrt();
        m1.iter_mut().for_each(|v| *v /= n1);
        let mut m2: Vec<f64> = (0..d).map(|i| (i * 3 % 5) as f64 - 2.0).collect();
        let dot: f64 = m1.iter().zip(&m2).map(|(a, b)| a * b).sum();
        m2.iter_mut().zip(&m1).for_each(|(b, a)| *b -= dot * a);
        let n2 = m2.iter().map(|v| v * v).sum::<f64>().sqrt();
        m2.iter_mut().for_each(|v| *v /= n2);
        let mut pca = Pca::new(1 << 30);
        for t in 0..frames {
            // One and two periods over the run: uncorrelated, mean zero.
            let phase = 2.0 * std::f64::consts::PI * t as f64 / frames as f64;
            let a = 3.0 * phase.cos();
            let b = (2.0 * phase).cos();
            let frame: Vec<[f32; 3]> = (0..atoms)
                .map(|i| {
                    std::array::from_fn(|c| {
                        let j = 3 * i + c;
                        (10.0 + j as f64 + a * m1[j] + b * m2[j]) as f32
                    })
                })
                .collect();
            pca.add(&frame).unwrap();
        }
        (pca, m1, m2)
    }

    fn flat(v: &[[f64; 3]]) -> Vec<f64> {
        v.iter().flatten().copied().collect()
    }

    #[test]
    fn finds_the_modes_by_either_matrix() {
        // 4 atoms over 200 frames: the 12² covariance; 40 atoms over 30 frames: the 30² Gram
        // matrix. Both see two modes and nothing else (f32 rounding aside).
        for (atoms, frames) in [(4, 200), (40, 30)] {
            let (pca, m1, m2) = two_modes(atoms, frames);
            let c = pca.solve(3).unwrap();
            assert_eq!(c.variance.len(), (3 * atoms).min(frames));
            let sum: f64 = c.variance.iter().sum();
            assert!((sum - c.total_variance).abs() < 1e-9 * c.total_variance);
            assert!(c.cumulated(1) > 1.0 - 1e-9, "{}", c.cumulated(1));
            for (v, m) in [(&c.vectors[0], &m1), (&c.vectors[1], &m2)] {
                let dot: f64 = flat(v).iter().zip(m).map(|(a, b)| a * b).sum();
                assert!((dot.abs() - 1.0).abs() < 1e-6, "{atoms} atoms: {dot}");
            }
            // The projections are the frames' coordinates in the basis, centred.
            for p in &c.projections {
                assert!(p[2].abs() < 1e-4);
            }
            let var0: f64 =
                c.projections.iter().map(|p| p[0] * p[0]).sum::<f64>() / (frames - 1) as f64;
            assert!((var0 - c.variance[0]).abs() < 1e-9 * c.variance[0]);
        }
    }

    #[test]
    fn gram_and_covariance_agree() {
        // The same 10 atoms over 30 frames (30 coordinates: the covariance) and over 29
        // frames (the Gram matrix) share their leading components closely.
        let (a, _, _) = two_modes(10, 31);
        let (b, _, _) = two_modes(10, 29);
        let (ca, cb) = (a.solve(2).unwrap(), b.solve(2).unwrap());
        assert_eq!(ca.variance.len(), 30);
        assert_eq!(cb.variance.len(), 29);
        for k in 0..2 {
            let dot: f64 = flat(&ca.vectors[k])
                .iter()
                .zip(flat(&cb.vectors[k]))
                .map(|(x, y)| x * y)
                .sum();
            assert!(dot.abs() > 1.0 - 1e-6, "component {k}: {dot}");
        }
    }

    #[test]
    fn along_spans_the_projections() {
        let (pca, _, _) = two_modes(5, 40);
        let c = pca.solve(1).unwrap();
        let path = c.along(0, 5);
        assert_eq!(path.len(), 5);
        let (lo, hi) = c
            .projections
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[0]), b.max(p[0])));
        for (structure, t) in [(&path[0], lo), (&path[4], hi)] {
            let y: Vec<f64> = structure
                .iter()
                .zip(&c.mean)
                .flat_map(|(p, m)| (0..3).map(move |a| f64::from(p[a]) - m[a]))
                .collect();
            let proj: f64 = y.iter().zip(flat(&c.vectors[0])).map(|(a, b)| a * b).sum();
            assert!((proj - t).abs() < 1e-4, "{proj} vs {t}");
        }
    }

    #[test]
    fn cosine_content_of_a_cosine_and_of_noise() {
        // MDAnalysis 2.11's pca.cosine_content of the same half cosines (odd and even counts).
        for (t, mdanalysis) in [(99usize, 0.9798047586650777), (100, 0.9800065646181819)] {
            let cos: Vec<f64> = (0..t)
                .map(|i| (std::f64::consts::PI * i as f64 / t as f64).cos())
                .collect();
            assert!((cosine_content(&cos, 0) - mdanalysis).abs() < 1e-14);
            assert!(cosine_content(&cos, 1) < 0.01);
        }
        let mut x = 12345u64;
        let noise: Vec<f64> = (0..1000)
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        assert!(cosine_content(&noise, 0) < 0.05);
        assert_eq!(cosine_content(&[0.0; 5], 0), 0.0);
    }

    #[test]
    fn simpson_matches_exact_polynomials() {
        // Simpson's rule is exact for cubics on an odd count; Cartwright's correction keeps
        // quadratics exact on an even count.
        for n in [3usize, 5, 9] {
            let y: Vec<f64> = (0..n).map(|i| (i as f64).powi(3)).collect();
            let exact = ((n - 1) as f64).powi(4) / 4.0;
            assert!((simpson(&y) - exact).abs() < 1e-9);
        }
        for n in [4usize, 6, 10] {
            let y: Vec<f64> = (0..n).map(|i| (i as f64).powi(2)).collect();
            let exact = ((n - 1) as f64).powi(3) / 3.0;
            assert!((simpson(&y) - exact).abs() < 1e-9, "{n}: {}", simpson(&y));
        }
    }

    #[test]
    fn bad_input_is_refused() {
        let mut pca = Pca::new(1 << 20);
        assert_eq!(pca.solve(1).unwrap_err(), PcaError::TooFewFrames(0));
        pca.add(&[[0.0; 3]; 2]).unwrap();
        assert!(matches!(
            pca.add(&[[0.0; 3]; 3]),
            Err(PcaError::Frame(MsdError::AtomCount { first: 2, frame: 3 }))
        ));
        assert!(matches!(
            pca.add(&[[0.0, f32::NAN, 0.0]; 2]),
            Err(PcaError::Frame(MsdError::NotFinite(0)))
        ));
        assert_eq!(pca.solve(1).unwrap_err(), PcaError::TooFewFrames(1));
        // The memory limit counts 12 bytes per atom and frame.
        let mut small = Pca::new(12 * 10 * 2);
        small.add(&[[0.0; 3]; 10]).unwrap();
        small.add(&[[1.0; 3]; 10]).unwrap();
        let e = small.add(&[[2.0; 3]; 10]).unwrap_err();
        assert!(
            matches!(
                e,
                PcaError::Memory {
                    atoms: 10,
                    frames: 3,
                    ..
                }
            ),
            "{e}"
        );
        // A problem over MAX_ORDER in both directions is refused before any matrix.
        let mut big = Pca::new(usize::MAX);
        let frame = vec![[0.0f32; 3]; MAX_ORDER];
        for i in 0..=MAX_ORDER {
            let mut f = frame.clone();
            f[0][0] = i as f32;
            big.add(&f[..MAX_ORDER / 3 + 1]).unwrap();
        }
        assert!(matches!(big.solve(1), Err(PcaError::TooLarge { .. })));
    }
}
