//! Many series autocorrelated over every time origin by FFT (Wiener–Khinchin), shared by the
//! mean squared displacement ([`crate::msd::AllOrigins`]) and the velocity autocorrelation
//! ([`crate::vacf::Velocities`]).
//!
//! [`Store`] keeps one `[f32; 3]` per atom per frame, frame-major, up to a memory limit.
//! [`Store::spectra`] transforms every atom's three coordinate series, zero-padded to `n ≥ 2T`
//! so the circular correlation does not wrap, two real series packed in one complex transform;
//! it sums the power spectra per kind of atom (one inverse transform per kind then gives the sum
//! of the kind's correlations) and the squared values per frame (the MSD's prefix sums). Atoms
//! are cut into fixed tasks summed in order, so the result is the same bit for bit on any
//! number of threads.

use rustfft::num_complex::Complex;

use crate::msd::{MsdError, STORED_BYTES, check_frame};

/// Atoms per block whose series one task transforms in turn (their frames stay in cache).
const BLOCK: usize = 32;
/// Atoms per parallel task: fixed, so the sums' order does not depend on the threads.
const TASK: usize = 1024;

/// Every frame's values of the same atoms, frame-major: frame f's atom i at `f * atoms + i`.
#[derive(Clone, Debug)]
pub(crate) struct Store {
    pub atoms: usize,
    pub frames: usize,
    pub values: Vec<[f32; 3]>,
    limit: usize,
}

/// Per kind: the summed squared transforms of its packed pairs of series (`n` bins; see
/// [`Spectra::power_of`]) and the summed squared values per frame.
pub(crate) struct Spectra {
    /// Transform length.
    pub n: usize,
    /// Frames.
    pub t: usize,
    pub power: Vec<Vec<f64>>,
    pub squares: Vec<Vec<f64>>,
}

impl Store {
    pub fn new(limit: usize) -> Store {
        Store {
            atoms: 0,
            frames: 0,
            values: Vec::new(),
            limit,
        }
    }

    /// Keeps a frame: `values` (finite, the first frame's number of atoms) mapped by `map`.
    pub fn push<T: Copy + Into<f64>>(
        &mut self,
        values: &[[T; 3]],
        map: impl Fn(usize, [T; 3]) -> [f32; 3],
    ) -> Result<(), MsdError> {
        check_frame(values, (self.frames > 0).then_some(self.atoms))?;
        if self.frames == 0 {
            self.atoms = values.len();
        }
        let bytes = (self.frames + 1).saturating_mul(self.atoms.saturating_mul(STORED_BYTES));
        if bytes > self.limit {
            return Err(MsdError::Memory {
                atoms: self.atoms,
                frames: self.frames + 1,
                limit: self.limit,
            });
        }
        self.values
            .extend(values.iter().enumerate().map(|(i, v)| map(i, *v)));
        self.frames += 1;
        Ok(())
    }

    /// Checks `kind` names one of `kinds` for every atom.
    pub fn check_kinds(&self, kind: &[usize], kinds: usize) -> Result<(), MsdError> {
        if kind.len() != self.atoms || kind.iter().any(|&k| k >= kinds) {
            return Err(MsdError::KindCount {
                atoms: self.atoms,
                kinds: kind.len(),
            });
        }
        Ok(())
    }

    /// The power spectra and squares of every series, summed per kind (`kind[i]` below
    /// `kinds`, checked by the caller). `centre` subtracts each series' mean first; `weight`
    /// scales atom i's series by `sqrt(weight[i])`, so its power counts `weight[i]` times.
    pub fn spectra(
        &self,
        kind: &[usize],
        kinds: usize,
        centre: bool,
        weight: Option<&[f64]>,
    ) -> Spectra {
        use rayon::prelude::*;
        let t = self.frames;
        let n = (2 * t).next_power_of_two();
        let forward = rustfft::FftPlanner::<f64>::new().plan_fft_forward(n);
        let parts: Vec<Spectra> = (0..self.atoms.div_ceil(TASK))
            .into_par_iter()
            .map(|task| {
                let atoms = task * TASK..((task + 1) * TASK).min(self.atoms);
                self.part(atoms, kind, kinds, n, centre, weight, forward.as_ref())
            })
            .collect();
        let mut total = Spectra::new(kinds, n, t);
        for part in &parts {
            total.add(part);
        }
        total
    }

    #[allow(clippy::too_many_arguments)]
    fn part(
        &self,
        atoms: std::ops::Range<usize>,
        kind: &[usize],
        kinds: usize,
        n: usize,
        centre: bool,
        weight: Option<&[f64]>,
        forward: &dyn rustfft::Fft<f64>,
    ) -> Spectra {
        let t = self.frames;
        let mut sums = Spectra::new(kinds, n, t);
        let mut buffer = vec![Complex::new(0.0, 0.0); n];
        let mut scratch = vec![Complex::new(0.0, 0.0); forward.get_inplace_scratch_len()];
        let mut series = [vec![0.0f64; t], vec![0.0f64; t]];
        let mut block = atoms.start;
        while block < atoms.end {
            let end = (block + BLOCK).min(atoms.end);
            for g in 0..kinds {
                let mut pending = (block..end)
                    .filter(|&i| kind[i] == g)
                    .flat_map(|i| (0..3).map(move |axis| (i, axis)))
                    .peekable();
                while let Some(a) = pending.next() {
                    let b = pending.next();
                    for (slot, which) in [Some(a), b].into_iter().enumerate() {
                        let out = &mut series[slot];
                        match which {
                            Some((i, axis)) => {
                                let scale = weight.map_or(1.0, |w| w[i].sqrt());
                                for (f, x) in out.iter_mut().enumerate() {
                                    *x = scale * f64::from(self.values[f * self.atoms + i][axis]);
                                }
                                if centre {
                                    let mean = out.iter().sum::<f64>() / t as f64;
                                    out.iter_mut().for_each(|x| *x -= mean);
                                }
                            }
                            None => out.fill(0.0),
                        }
                    }
                    for (f, z) in buffer.iter_mut().enumerate() {
                        *z = if f < t {
                            Complex::new(series[0][f], series[1][f])
                        } else {
                            Complex::new(0.0, 0.0)
                        };
                    }
                    forward.process_with_scratch(&mut buffer, &mut scratch);
                    for (p, z) in sums.power[g].iter_mut().zip(&buffer) {
                        *p += z.norm_sqr();
                    }
                    for (s, (x, y)) in sums.squares[g]
                        .iter_mut()
                        .zip(series[0].iter().zip(&series[1]))
                    {
                        *s += x * x + y * y;
                    }
                }
            }
            block = end;
        }
        sums
    }
}

impl Spectra {
    fn new(kinds: usize, n: usize, t: usize) -> Spectra {
        Spectra {
            n,
            t,
            power: vec![vec![0.0; n]; kinds],
            squares: vec![vec![0.0; t]; kinds],
        }
    }

    fn add(&mut self, other: &Spectra) {
        for (a, b) in self.power.iter_mut().zip(&other.power) {
            a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
        }
        for (a, b) in self.squares.iter_mut().zip(&other.squares) {
            a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
        }
    }

    /// Kind g's summed power spectrum of its series, bin k of `n`: two real series packed in
    /// one transform Z, (|Z_k|² + |Z_{n−k}|²) / 2 is the sum of their power spectra.
    pub fn power_of(&self, g: usize, k: usize) -> f64 {
        let p = &self.power[g];
        0.5 * (p[k] + p[(self.n - k) % self.n])
    }

    /// Per kind and lag m < T: the sum over the kind's series and origins k of
    /// `x(k) · x(k + m)`.
    pub fn correlations(&self) -> Vec<Vec<f64>> {
        let inverse = rustfft::FftPlanner::<f64>::new().plan_fft_inverse(self.n);
        (0..self.power.len())
            .map(|g| {
                let mut buffer: Vec<Complex<f64>> = (0..self.n)
                    .map(|k| Complex::new(self.power_of(g, k), 0.0))
                    .collect();
                inverse.process(&mut buffer);
                buffer[..self.t]
                    .iter()
                    .map(|z| z.re / self.n as f64)
                    .collect()
            })
            .collect()
    }
}
