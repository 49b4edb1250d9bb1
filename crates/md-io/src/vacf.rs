//! The velocity autocorrelation function over every time origin, the diffusion coefficient it
//! integrates to (Green–Kubo), and the vibrational density of states, its spectrum: what
//! `gmx velacc`, `gmx dos` and LAMMPS's `compute vacf` give.
//!
//! [`Velocities`] keeps every frame's velocities (`f32`, [`crate::msd::STORED_BYTES`] per atom
//! per frame, up to a memory limit) and transforms each atom's three velocity series by FFT,
//! zero-padded to at least twice the frames (the correlation of the shared module
//! `correlate`, as the MSD over every origin uses it):
//!
//! - [`Velocities::autocorrelation`]: for a lag of m frames, the mean over the atoms and the
//!   T − m origins k of `v(k) · v(k + m)` (Å²/ps² from velocities in Å/ps), per kind of atom
//!   and over all;
//! - [`green_kubo`]: D = ⅓ ∫₀^τ C(t) dt by the trapezoid rule (Å²/ps, which is 10⁻⁴ cm²/s);
//! - [`Velocities::density_of_states`]: the power spectrum of the velocities,
//!   `g(ν) ∝ Σ_i m_i |ṽ_i(ν)|²` at ν = k / (n Δt) for k = 0 … n/2, mass-weighted as `gmx dos`
//!   weighs it (each mode of a harmonic system then counts once, whatever its atoms' masses),
//!   every column normalised to ∫ g dν = 3 over ν ≥ 0 (three degrees of freedom per atom).
//!   The squared transform of a zero-padded series is the transform of its autocorrelation
//!   summed over origins (not divided by T − m): the correlation under a triangular (Bartlett)
//!   window, which keeps the spectrum non-negative. The frequency step is 1 / (n Δt) with n the
//!   power of two at or above 2T; the resolution is that of the run, 1 / (T Δt).
//!
//! ```
//! use texmap_md_io::vacf::{Velocities, green_kubo};
//! // One atom whose velocity along x is cos(2π t / 8) (Å/ps), sampled every 0.5 ps.
//! let mut v = Velocities::new(1 << 20);
//! for f in 0..256 {
//!     let t = f as f64 * 0.5;
//!     v.push(&[[(std::f64::consts::TAU * t / 8.0).cos() as f32, 0.0, 0.0]]).unwrap();
//! }
//! let c = v.autocorrelation(&[0], 1).unwrap();
//! assert!((c.total[0] - 0.5).abs() < 1e-2); // ⟨cos²⟩
//! assert!((c.total[8] + 0.5).abs() < 2e-2); // half a period later: −⟨cos²⟩
//! // The spectrum peaks at 1/8 THz.
//! let g = v.density_of_states(&[0], 1, &[1.0], 0.5).unwrap();
//! let peak = (0..g.frequency.len()).max_by(|&a, &b| g.total[a].total_cmp(&g.total[b])).unwrap();
//! assert!((g.frequency[peak] - 0.125).abs() < 0.005);
//! // An oscillation integrates to no diffusion.
//! let time: Vec<f64> = (0..c.total.len()).map(|m| m as f64 * 0.5).collect();
//! assert!(green_kubo(&time, &c.total, 64.0).unwrap().abs() < 0.02);
//! ```

use crate::correlate::Store;
use crate::msd::{MsdError, per_origin};

/// Every frame's velocities, for correlations over every time origin.
#[derive(Clone, Debug)]
pub struct Velocities {
    store: Store,
}

/// A quantity per lag 0, 1, … T − 1 frames, over every atom and per kind.
#[derive(Clone, Debug, PartialEq)]
pub struct Lagged {
    /// Over every atom.
    pub total: Vec<f64>,
    /// Over the atoms of each kind (NaN for a kind without atoms).
    pub kinds: Vec<Vec<f64>>,
}

/// [`Velocities::density_of_states`]'s spectrum.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    /// Frequency of each bin, in cycles per unit of the frame interval's time (THz for ps).
    pub frequency: Vec<f64>,
    /// Over every atom, mass-weighted; ∫ g dν = 3.
    pub total: Vec<f64>,
    /// Over the atoms of each kind; ∫ g dν = 3 each (NaN for a kind without atoms).
    pub kinds: Vec<Vec<f64>>,
}

impl Velocities {
    /// Keeps no frame yet; [`Velocities::push`] refuses a frame that would take the kept
    /// velocities over `limit` bytes.
    pub fn new(limit: usize) -> Velocities {
        Velocities {
            store: Store::new(limit),
        }
    }

    /// Frames kept.
    pub fn frames(&self) -> usize {
        self.store.frames
    }

    /// Keeps a frame's velocities: every frame has the first's atoms in the same order.
    pub fn push(&mut self, velocities: &[[f32; 3]]) -> Result<(), MsdError> {
        self.store.push(velocities, |_, v| v)
    }

    /// The velocity autocorrelation per lag, `⟨v(k) · v(k + m)⟩` over the origins k and the
    /// atoms, over every atom and over each of `kinds` kinds (`kind[i]` below `kinds` naming
    /// atom i's).
    pub fn autocorrelation(&self, kind: &[usize], kinds: usize) -> Result<Lagged, MsdError> {
        self.store.check_kinds(kind, kinds)?;
        let t = self.store.frames;
        if t == 0 {
            return Ok(Lagged {
                total: Vec::new(),
                kinds: vec![Vec::new(); kinds],
            });
        }
        let sums = self.store.spectra(kind, kinds, false, None).correlations();
        let mut counts = vec![0usize; kinds];
        for &k in kind {
            counts[k] += 1;
        }
        Ok(Lagged {
            total: per_origin(&|m| sums.iter().map(|g| g[m]).sum(), t, kind.len()),
            kinds: (0..kinds)
                .map(|g| per_origin(&|m| sums[g][m], t, counts[g]))
                .collect(),
        })
    }

    /// The vibrational density of states of frames `dt` apart (see the module docs): atom i
    /// weighted by `mass[i]` (positive and finite), every column normalised to ∫ g dν = 3. An
    /// all-zero column (atoms at rest) stays zero.
    pub fn density_of_states(
        &self,
        kind: &[usize],
        kinds: usize,
        mass: &[f64],
        dt: f64,
    ) -> Result<Spectrum, MsdError> {
        self.store.check_kinds(kind, kinds)?;
        if let Some(i) = mass.iter().position(|m| !(m.is_finite() && *m > 0.0)) {
            return Err(MsdError::Weight(i));
        }
        if mass.len() != kind.len() {
            return Err(MsdError::KindCount {
                atoms: self.store.atoms,
                kinds: mass.len(),
            });
        }
        let t = self.store.frames;
        if t == 0 {
            return Ok(Spectrum {
                frequency: Vec::new(),
                total: Vec::new(),
                kinds: vec![Vec::new(); kinds],
            });
        }
        let spectra = self.store.spectra(kind, kinds, false, Some(mass));
        let n = spectra.n;
        let step = 1.0 / (n as f64 * dt);
        let bins = n / 2 + 1;
        let normalised = |power: Vec<f64>| -> Vec<f64> {
            // Trapezoid over ν ≥ 0: the ends count half.
            let area = step * (power.iter().sum::<f64>() - 0.5 * (power[0] + power[bins - 1]));
            let scale = if area > 0.0 { 3.0 / area } else { 0.0 };
            power.into_iter().map(|p| p * scale).collect()
        };
        let mut counts = vec![0usize; kinds];
        for &k in kind {
            counts[k] += 1;
        }
        let total = normalised(
            (0..bins)
                .map(|k| (0..kinds).map(|g| spectra.power_of(g, k)).sum())
                .collect(),
        );
        let per_kind = (0..kinds)
            .map(|g| {
                if counts[g] == 0 {
                    vec![f64::NAN; bins]
                } else {
                    normalised((0..bins).map(|k| spectra.power_of(g, k)).collect())
                }
            })
            .collect();
        Ok(Spectrum {
            frequency: (0..bins).map(|k| k as f64 * step).collect(),
            total,
            kinds: per_kind,
        })
    }
}

/// The Green–Kubo diffusion coefficient, D = ⅓ ∫ C(t) dt over the lags with `time ≤ to`, by
/// the trapezoid rule (Å²/ps from C in Å²/ps²); `None` with fewer than two such lags. The
/// integral of a finite run's tail is noise: `to` is where C(t) has decayed.
pub fn green_kubo(time: &[f64], vacf: &[f64], to: f64) -> Option<f64> {
    let slack = 1e-6 * to.abs();
    let points: Vec<(f64, f64)> = time
        .iter()
        .zip(vacf)
        .take_while(|(t, _)| **t <= to + slack)
        .map(|(t, c)| (*t, *c))
        .collect();
    if points.len() < 2 {
        return None;
    }
    let integral: f64 = points
        .windows(2)
        .map(|w| 0.5 * (w[1].0 - w[0].0) * (w[0].1 + w[1].1))
        .sum();
    Some(integral / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Velocities of three kinds: an Ornstein–Uhlenbeck process per kind (relaxation time and
    /// spread differing) plus, for kind 2, an oscillation.
    fn frames(atoms: usize, t: usize) -> (Vec<Vec<[f32; 3]>>, Vec<usize>) {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let kind: Vec<usize> = (0..atoms).map(|i| (i * 5) % 3).collect();
        let mut v = vec![[0.0f64; 3]; atoms];
        let mut out = Vec::new();
        for f in 0..t {
            for (w, k) in v.iter_mut().zip(&kind) {
                let keep = [0.9, 0.6, 0.95][*k];
                for x in w.iter_mut() {
                    *x = keep * *x + next();
                }
            }
            out.push(
                v.iter()
                    .zip(&kind)
                    .map(|(w, k)| {
                        let wave = if *k == 2 { (0.7 * f as f64).sin() } else { 0.0 };
                        std::array::from_fn(|a| (w[a] + wave) as f32)
                    })
                    .collect(),
            );
        }
        (out, kind)
    }

    #[test]
    fn the_autocorrelation_as_the_definition_sums_it() {
        let (frames, kind) = frames(1500, 41);
        let mut v = Velocities::new(usize::MAX);
        for f in &frames {
            v.push(f).unwrap();
        }
        let fast = v.autocorrelation(&kind, 3).unwrap();
        let t = frames.len();
        for m in [0, 1, 5, 20, 40] {
            let mut sums = [0.0f64; 3];
            for k in 0..t - m {
                for (i, g) in kind.iter().enumerate() {
                    sums[*g] += (0..3)
                        .map(|a| f64::from(frames[k][i][a]) * f64::from(frames[k + m][i][a]))
                        .sum::<f64>();
                }
            }
            let count = |g: usize| kind.iter().filter(|&&k| k == g).count() as f64;
            let origins = (t - m) as f64;
            let total = sums.iter().sum::<f64>() / (origins * kind.len() as f64);
            let scale = fast.total[0];
            assert!((fast.total[m] - total).abs() < 1e-9 * scale, "lag {m}");
            for (g, sum) in sums.iter().enumerate() {
                let want = sum / (origins * count(g));
                assert!(
                    (fast.kinds[g][m] - want).abs() < 1e-9 * scale,
                    "kind {g} lag {m}"
                );
            }
        }
        // The same bits on one thread.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| v.autocorrelation(&kind, 3).unwrap());
        assert_eq!(one, fast);
    }

    #[test]
    fn the_spectrum_is_the_squared_transform_and_integrates_to_three() {
        let (frames, kind) = frames(200, 64);
        let mut v = Velocities::new(usize::MAX);
        for f in &frames {
            v.push(f).unwrap();
        }
        let mass: Vec<f64> = kind.iter().map(|k| [16.0, 1.0, 12.0][*k]).collect();
        let dt = 0.01;
        let g = v.density_of_states(&kind, 3, &mass, dt).unwrap();
        let n = 128;
        assert_eq!(g.frequency.len(), n / 2 + 1);
        assert!((g.frequency[1] - 1.0 / (n as f64 * dt)).abs() < 1e-9);
        // The direct discrete transform of the padded series, mass-weighted.
        let direct = |pick: &dyn Fn(usize) -> bool, k: usize| -> f64 {
            let mut p = 0.0;
            for (i, m) in mass.iter().enumerate().filter(|(i, _)| pick(*i)) {
                for a in 0..3 {
                    let (mut re, mut im) = (0.0f64, 0.0f64);
                    for (f, frame) in frames.iter().enumerate() {
                        let phase = -std::f64::consts::TAU * (k * f) as f64 / n as f64;
                        re += f64::from(frame[i][a]) * phase.cos();
                        im += f64::from(frame[i][a]) * phase.sin();
                    }
                    p += m * (re * re + im * im);
                }
            }
            p
        };
        type Pick<'a> = &'a dyn Fn(usize) -> bool;
        let columns: [(&[f64], Pick); 2] =
            [(&g.total, &|_| true), (&g.kinds[1], &|i| kind[i] == 1)];
        for (column, pick) in columns {
            let raw: Vec<f64> = (0..=n / 2).map(|k| direct(pick, k)).collect();
            let step = g.frequency[1];
            let area = step * (raw.iter().sum::<f64>() - 0.5 * (raw[0] + raw[n / 2]));
            for (k, (got, want)) in column.iter().zip(&raw).enumerate() {
                let want = 3.0 * want / area;
                assert!(
                    (got - want).abs() < 1e-9 * (1.0 + want),
                    "bin {k}: {got} {want}"
                );
            }
        }
        // Kind 2's oscillation, 0.7 rad per frame: its peak.
        let omega = 0.7 / (std::f64::consts::TAU * dt);
        let peak = (1..g.frequency.len())
            .max_by(|&a, &b| g.kinds[2][a].total_cmp(&g.kinds[2][b]))
            .unwrap();
        assert!(
            (g.frequency[peak] - omega).abs() <= g.frequency[1],
            "{peak}"
        );
    }

    #[test]
    fn green_kubo_of_an_exponential_and_the_refusals() {
        // C(t) = 3 e^{−t/2}: D = ⅓ · 3 · 2 (1 − e^{−10}) over 20 ps.
        let time: Vec<f64> = (0..=4000).map(|k| k as f64 * 0.005).collect();
        let c: Vec<f64> = time.iter().map(|t| 3.0 * (-t / 2.0).exp()).collect();
        let d = green_kubo(&time, &c, 20.0).unwrap();
        assert!((d - 2.0 * (1.0 - (-10.0f64).exp())).abs() < 1e-5, "{d}");
        assert!(green_kubo(&time, &c, 0.001).is_none());
        let mut v = Velocities::new(usize::MAX);
        v.push(&[[1.0; 3]; 2]).unwrap();
        assert_eq!(
            v.push(&[[1.0; 3]; 3]),
            Err(MsdError::AtomCount { first: 2, frame: 3 })
        );
        assert!(v.density_of_states(&[0, 0], 1, &[1.0, 0.0], 1.0).is_err());
        assert!(v.density_of_states(&[0, 0], 1, &[1.0], 1.0).is_err());
        assert!(v.autocorrelation(&[0, 1], 1).is_err());
        let still = Velocities::new(usize::MAX);
        assert!(still.autocorrelation(&[], 0).unwrap().total.is_empty());
    }
}
