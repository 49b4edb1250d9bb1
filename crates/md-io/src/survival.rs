//! Survival probabilities: how long the members of a set that changes from frame to frame
//! stay in it (water in a protein's first shell, ions at a site, hydrogen bonds), as
//! MDAnalysis computes them (`lib.correlations.autocorrelation` after
//! `correct_intermittency`; the waterdynamics MDAKit's `SurvivalProbability`,
//! `HydrogenBondAnalysis.lifetime`).
//!
//! S(τ) is the mean, over every time origin t whose set is not empty and with t + τ a frame,
//! of the share of t's members present at every frame from t to t + τ; S(0) = 1. With an
//! intermittency k, a member absent for up to k consecutive frames between two frames that
//! have it counts as present in them (MDAnalysis's `correct_intermittency`).
//!
//! ```
//! use texmap_md_io::survival::survival_probability;
//! // Atom 7 stays for 3 frames, atom 8 for 1.
//! let frames = vec![vec![7, 8], vec![7], vec![7], vec![]];
//! let s = survival_probability(&frames, 3, 0);
//! // Lag 1: origin 0 keeps 1 of 2, origins 1 and 2 keep 1 of 1 and 0 of 1: (0.5 + 1 + 0) / 3.
//! assert_eq!(s[1], 0.5);
//! assert_eq!(s[2], (0.5 + 0.0) / 2.0);
//! ```

/// S(0) … S(min(`tau_max`, frames − 1)) of the members (any keys: atom indices, pairs packed
/// into a u64) listed per frame; NaN at a lag no origin reaches (every set empty). Linear in
/// the members over the frames plus frames × lags.
pub fn survival_probability(frames: &[Vec<u64>], tau_max: usize, intermittency: usize) -> Vec<f64> {
    let n = frames.len();
    if n == 0 {
        return Vec::new();
    }
    let tau_max = tau_max.min(n - 1);
    // Each member's frames, in order.
    let mut ids = std::collections::HashMap::new();
    let mut present: Vec<Vec<usize>> = Vec::new();
    for (f, members) in frames.iter().enumerate() {
        for &key in members {
            let id = *ids.entry(key).or_insert_with(|| {
                present.push(Vec::new());
                present.len() - 1
            });
            if present[id].last() != Some(&f) {
                present[id].push(f);
            }
        }
    }
    // Per origin: its members, and how many survive each lag (a histogram of the continuous
    // run each member has from it, then summed from the top).
    let lags = tau_max + 1;
    let mut count = vec![0u32; n];
    let mut runs = vec![0u32; n * lags];
    for frames_of in &present {
        let mut k = 0;
        while k < frames_of.len() {
            // A run of consecutive frames, gaps of up to `intermittency` bridged.
            let start = frames_of[k];
            let mut end = start;
            k += 1;
            while k < frames_of.len() && frames_of[k] - end <= intermittency + 1 {
                end = frames_of[k];
                k += 1;
            }
            for t in start..=end {
                count[t] += 1;
                runs[t * lags + (end - t).min(tau_max)] += 1;
            }
        }
    }
    let mut sum = vec![0.0f64; lags];
    let mut origins = vec![0usize; lags];
    for t in 0..n {
        if count[t] == 0 {
            continue;
        }
        let mut surviving = 0u32;
        for tau in (0..lags).rev() {
            surviving += runs[t * lags + tau];
            if t + tau < n {
                sum[tau] += surviving as f64 / count[t] as f64;
                origins[tau] += 1;
            }
        }
    }
    let mut c: Vec<f64> = sum
        .iter()
        .zip(&origins)
        .map(|(s, &o)| if o == 0 { f64::NAN } else { s / o as f64 })
        .collect();
    c[0] = 1.0;
    c
}
