//! Root-mean-square fluctuation: each atom's RMS distance from its mean position over the
//! frames, as MDAnalysis's `rms.RMSF` and `gmx rmsf` give it, the number a protein's
//! flexibility is coloured by. The frames should be superposed first (`--align`), or the
//! molecule's tumbling counts as fluctuation; positions are taken as given, so an atom that
//! jumps across a periodic boundary fluctuates by the jump (make molecules whole first).
//!
//! [`Fluctuation`] keeps a running mean and sum of squared deviations per atom (Welford's
//! update, in `f64`): one pass, memory of the atoms only, the population RMSF (divided by the
//! frame count, as MDAnalysis does).
//!
//! ```
//! use texmap_md_io::rmsf::Fluctuation;
//! let mut f = Fluctuation::new();
//! // The first atom moves between x = 0 and x = 2, the second stays.
//! for x in [0.0, 2.0, 0.0, 2.0] {
//!     f.add(&[[x, 0.0, 0.0], [5.0, 5.0, 5.0]]).unwrap();
//! }
//! assert_eq!(f.rmsf(), vec![1.0, 0.0]);
//! assert_eq!(f.mean()[0], [1.0, 0.0, 0.0]);
//! ```

use crate::msd::MsdError;

/// Each atom's running mean position and squared deviation; see the module docs.
#[derive(Clone, Debug, Default)]
pub struct Fluctuation {
    mean: Vec<[f64; 3]>,
    /// Per atom: the sum over frames of the squared distance from the running mean (Welford).
    squares: Vec<f64>,
    frames: usize,
}

impl Fluctuation {
    /// No frame seen.
    pub fn new() -> Fluctuation {
        Fluctuation::default()
    }

    /// Frames added.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Adds a frame's positions (Å): every frame has the first's atoms in the same order.
    pub fn add(&mut self, positions: &[[f32; 3]]) -> Result<(), MsdError> {
        crate::msd::check_frame(positions, (self.frames > 0).then_some(self.mean.len()))?;
        if self.frames == 0 {
            self.mean = vec![[0.0; 3]; positions.len()];
            self.squares = vec![0.0; positions.len()];
        }
        self.frames += 1;
        let n = self.frames as f64;
        for ((m, s), p) in self.mean.iter_mut().zip(&mut self.squares).zip(positions) {
            for k in 0..3 {
                let x = f64::from(p[k]);
                let before = x - m[k];
                m[k] += before / n;
                *s += before * (x - m[k]);
            }
        }
        Ok(())
    }

    /// Each atom's mean position over the frames added.
    pub fn mean(&self) -> &[[f64; 3]] {
        &self.mean
    }

    /// Each atom's RMS fluctuation (Å) about its mean position.
    pub fn rmsf(&self) -> Vec<f64> {
        let n = self.frames.max(1) as f64;
        self.squares
            .iter()
            .map(|s| (s.max(0.0) / n).sqrt())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the two-pass definition on positions far from the origin (where a naive sum of
    /// squares would cancel).
    #[test]
    fn welford_equals_the_two_pass_definition() {
        let frames: Vec<Vec<[f32; 3]>> = (0..50)
            .map(|f| {
                (0..7)
                    .map(|i| {
                        let w = (f * 7 + i) as f32;
                        [
                            1000.0 + (w * 0.37).sin() * i as f32,
                            -500.0 + (w * 0.11).cos(),
                            250.0 + 0.01 * w,
                        ]
                    })
                    .collect()
            })
            .collect();
        let mut f = Fluctuation::new();
        for p in &frames {
            f.add(p).unwrap();
        }
        for i in 0..7 {
            let mean: [f64; 3] = std::array::from_fn(|k| {
                frames.iter().map(|p| f64::from(p[i][k])).sum::<f64>() / 50.0
            });
            let want = (frames
                .iter()
                .map(|p| {
                    (0..3)
                        .map(|k| (f64::from(p[i][k]) - mean[k]).powi(2))
                        .sum::<f64>()
                })
                .sum::<f64>()
                / 50.0)
                .sqrt();
            assert!((f.rmsf()[i] - want).abs() < 1e-9, "atom {i}");
            assert!((f.mean()[i][0] - mean[0]).abs() < 1e-9);
        }
        assert_eq!(
            f.add(&[[0.0; 3]; 6]),
            Err(MsdError::AtomCount { first: 7, frame: 6 })
        );
        assert_eq!(f.add(&[[f32::NAN; 3]; 7]), Err(MsdError::NotFinite(0)));
        assert_eq!(f.frames(), 50);
    }
}
