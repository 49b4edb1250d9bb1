//! The centrosymmetry parameter (CSP; C. L. Kelchner, S. J. Plimpton, J. C. Hamilton, Phys.
//! Rev. B 58 (1998) 11085) of every atom, as LAMMPS's `compute centro/atom` and OVITO's
//! Centrosymmetry modifier compute it: how far an atom's `N` nearest neighbours are from
//! coming in opposite pairs. Zero in a perfect centrosymmetric crystal (FCC with `N` = 12, BCC
//! with 8), small under thermal noise and elastic strain, large at dislocation cores, stacking
//! faults and surfaces, so materials simulations colour by it or hide the atoms below a
//! threshold.
//!
//! With `r₁ … r_N` the vectors to the `N` nearest neighbours, each pair of neighbours `(i, j)`
//! weighs `|rᵢ + rⱼ|²`, and the CSP sums `N/2` of those weights:
//! - [`CspMode::Conventional`] (LAMMPS, OVITO's default): the `N/2` smallest of all
//!   `N(N−1)/2` pair weights, whether or not they share a neighbour;
//! - [`CspMode::Matching`] (OVITO's minimum-weight matching mode, after Stukowski 2012): the
//!   smallest sum over pairings that use every neighbour once, found exactly: in a crystal at
//!   once (every neighbour's lightest partner is mutual: no pairing can be lighter), else by
//!   branch and bound from the greedy pairing, or, where
//!   that search grows (disordered neighbourhoods), by dynamic programming over the sets of
//!   neighbours still unpaired (so `N` ≤ [`MAX_MATCHING`]).
//!
//! Neighbours come from the k-nearest cell grid that [`crate::cna`] uses too (nearest images in a periodic cell,
//! so the cell must be wider than twice the `N`-th neighbour distance); an atom with fewer than
//! `N` other atoms in the frame sums the pairs it has. Atoms are independent and computed in
//! parallel; the result does not depend on the thread count.
//!
//! ```
//! use texmap_md_io::centrosymmetry::{CspMode, centrosymmetry};
//! use texmap_md_io::{Frame, UnitCell};
//! // A periodic 3x3x3 block of FCC cells (a = 3.6 Å): every atom is a centre of symmetry.
//! let a = 3.6f32;
//! let mut frame = Frame::new();
//! for (i, j, k) in (0..27).map(|n| (n % 3, n / 3 % 3, n / 9)) {
//!     for b in [[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]] {
//!         frame.positions.push([(i as f32 + b[0]) * a, (j as f32 + b[1]) * a, (k as f32 + b[2]) * a]);
//!     }
//! }
//! frame.cell = Some(UnitCell::orthorhombic(3.0 * a as f64, 3.0 * a as f64, 3.0 * a as f64).unwrap());
//! let csp = centrosymmetry(&frame, 12, CspMode::Conventional).unwrap();
//! assert!(csp.iter().all(|p| p.abs() < 1e-4));
//! // Move one atom by 0.2 Å: it and its neighbours lose their symmetry.
//! frame.positions[0][0] += 0.2;
//! let csp = centrosymmetry(&frame, 12, CspMode::Matching).unwrap();
//! // Its six opposite pairs each weigh |−2 × 0.2 Å|² = 0.16 Å².
//! assert!((csp[0] - 0.96).abs() < 1e-3);
//! ```

use std::fmt;

use crate::frame::Frame;
use crate::neighbours::{Grid, Scratch};

/// The largest neighbour count taken (OVITO's limit).
pub const MAX_NEIGHBOURS: usize = 32;

/// The largest neighbour count of [`CspMode::Matching`]: the exact matching visits up to
/// `2^(N−1)` sets of unpaired neighbours per atom.
pub const MAX_MATCHING: usize = 16;

/// Which `N/2` pair weights the CSP sums (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum CspMode {
    /// The `N/2` smallest pair weights (LAMMPS, OVITO's default).
    #[default]
    Conventional,
    /// The pairing of all `N` neighbours with the smallest total weight.
    Matching,
}

/// Why the CSP cannot be computed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CentroError {
    /// The neighbour count is not an even number from 2 to [`MAX_NEIGHBOURS`].
    BadCount(usize),
    /// [`CspMode::Matching`] with more than [`MAX_MATCHING`] neighbours.
    MatchingTooMany(usize),
}

impl fmt::Display for CentroError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CentroError::BadCount(n) => write!(
                f,
                "the neighbour count {n} is not an even number from 2 to {MAX_NEIGHBOURS} \
                 (12 for FCC, 8 for BCC)"
            ),
            CentroError::MatchingTooMany(n) => write!(
                f,
                "the matching mode takes at most {MAX_MATCHING} neighbours, not {n} \
                 (the conventional mode takes up to {MAX_NEIGHBOURS})"
            ),
        }
    }
}

impl std::error::Error for CentroError {}

/// The CSP of every atom of `frame` from its `n` nearest neighbours, in Å² (see the module
/// docs). Atoms with non-finite coordinates get 0 and are nobody's neighbour.
pub fn centrosymmetry(frame: &Frame, n: usize, mode: CspMode) -> Result<Vec<f32>, CentroError> {
    use rayon::prelude::*;
    check(n, mode)?;
    let grid = Grid::new(&frame.positions, frame.cell.as_ref());
    Ok((0..frame.positions.len())
        .into_par_iter()
        .map_init(Work::default, |work, i| {
            grid.nearest(i, n, &mut work.scratch);
            let near = &work.scratch.near;
            let m = near.len();
            work.weights.clear();
            work.weights.resize(m * m, 0.0);
            for a in 0..m {
                for b in a + 1..m {
                    let s = [0, 1, 2].map(|k| near[a].0[k] + near[b].0[k]);
                    let w = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
                    work.weights[a * m + b] = w;
                    work.weights[b * m + a] = w;
                }
            }
            let p = match mode {
                CspMode::Conventional => work.conventional(m),
                CspMode::Matching => work.matching(m),
            };
            p as f32
        })
        .collect())
}

/// Whether [`centrosymmetry`] takes `n` neighbours in `mode` (what it refuses, before any
/// frame is read).
pub fn check(n: usize, mode: CspMode) -> Result<(), CentroError> {
    if !(2..=MAX_NEIGHBOURS).contains(&n) || !n.is_multiple_of(2) {
        return Err(CentroError::BadCount(n));
    }
    if mode == CspMode::Matching && n > MAX_MATCHING {
        return Err(CentroError::MatchingTooMany(n));
    }
    Ok(())
}

/// One worker's buffers.
#[derive(Default)]
struct Work {
    scratch: Scratch,
    /// `weights[a * m + b]`: |r_a + r_b|² for the `m` neighbours found.
    weights: Vec<f64>,
    pairs: Vec<f64>,
    /// The matching's memo: the best sum for each set of unpaired neighbours, valid where its
    /// stamp is the current atom's.
    memo: Vec<f64>,
    stamp: Vec<u32>,
    generation: u32,
    /// The branch and bound's pairs by weight, and each neighbour's partners (m − 1 each),
    /// lightest first.
    order: Vec<(f64, u8, u8)>,
    partners: Vec<u8>,
}

/// Sets of unpaired neighbours the branch and bound may visit per atom before the dynamic
/// programme takes over.
const SEARCH_BUDGET: u32 = 2048;

/// The branch and bound of [`Work::branch_and_bound`].
struct Search<'a> {
    weights: &'a [f64],
    partners: &'a [u8],
    m: usize,
    /// The lightest complete pairing found so far.
    best: f64,
    visited: u32,
}

impl Search<'_> {
    /// Searches the pairings of `set` after pairs costing `cost`; false when over budget.
    fn visit(&mut self, set: u32, cost: f64) -> bool {
        if set == 0 {
            self.best = self.best.min(cost);
            return true;
        }
        self.visited += 1;
        if self.visited > SEARCH_BUDGET {
            return false;
        }
        let m = self.m;
        let mut bound = 0.0;
        let mut rest = set;
        while rest != 0 {
            let x = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let lightest = self.partners[x * (m - 1)..(x + 1) * (m - 1)]
                .iter()
                .find(|&&y| set & (1 << y) != 0)
                .map_or(0.0, |&y| self.weights[x * m + y as usize]);
            bound += lightest;
        }
        // Within rounding of the best: the bound is tight in a crystal (every neighbour's
        // lightest pair is its opposite one), and summed in another order it can fall a few
        // ulps short of the same pairing's cost.
        if cost + 0.5 * bound >= self.best * (1.0 - 1e-12) {
            return true;
        }
        let a = set.trailing_zeros() as usize;
        for &b in &self.partners[a * (m - 1)..(a + 1) * (m - 1)] {
            if set & (1 << b) == 0 {
                continue;
            }
            let c = cost + self.weights[a * m + b as usize];
            // Partners come lightest first: no later one can do better.
            if c >= self.best {
                break;
            }
            if !self.visit(set & !(1 << a) & !(1 << b), c) {
                return false;
            }
        }
        true
    }
}

impl Work {
    /// The sum of the m/2 smallest weights over the pairs a < b.
    fn conventional(&mut self, m: usize) -> f64 {
        self.pairs.clear();
        for a in 0..m {
            for b in a + 1..m {
                self.pairs.push(self.weights[a * m + b]);
            }
        }
        let half = m / 2;
        if half == 0 {
            return 0.0;
        }
        if self.pairs.len() > half {
            self.pairs.select_nth_unstable_by(half - 1, f64::total_cmp);
        }
        let mut first = self.pairs[..half].to_vec();
        // Summed in ascending order, so the value does not depend on the selection's order.
        first.sort_by(f64::total_cmp);
        first.iter().sum()
    }

    /// The smallest total weight of a pairing of the m neighbours (m odd: one left unpaired,
    /// the pairing of the rest that costs least).
    fn matching(&mut self, m: usize) -> f64 {
        if m.is_multiple_of(2)
            && let Some(best) = self.matching_fast(m).or_else(|| self.branch_and_bound(m))
        {
            return best;
        }
        self.dynamic(m)
    }

    /// [`Self::matching`] by dynamic programming over the sets of unpaired neighbours.
    fn dynamic(&mut self, m: usize) -> f64 {
        let size = 1usize << m;
        if self.memo.len() < size {
            self.memo.resize(size, 0.0);
            self.stamp.resize(size, 0);
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.fill(0);
            self.generation = 1;
        }
        let full = (size - 1) as u32;
        self.best(full, m)
    }

    /// The lightest pairing when every neighbour's lightest partner has it as its own lightest
    /// partner (a crystal's opposite pairs): those pairs meet the lower bound of
    /// [`Self::branch_and_bound`], so no pairing is lighter. `None` otherwise.
    fn matching_fast(&self, m: usize) -> Option<f64> {
        let w = &self.weights;
        let lightest = |x: usize| {
            (0..m)
                .filter(|&y| y != x)
                .min_by(|&a, &b| w[x * m + a].total_cmp(&w[x * m + b]))
        };
        let mut total = 0.0;
        for x in 0..m {
            let y = lightest(x)?;
            if lightest(y) != Some(x) {
                return None;
            }
            if x < y {
                total += w[x * m + y];
            }
        }
        Some(total)
    }

    /// The smallest total weight of a pairing of the m neighbours (m even) by branch and bound:
    /// the greedy pairing (lightest pairs first) bounds it from above, each set of unpaired
    /// neighbours from below by every neighbour's lightest pair in the set, halved. In a crystal
    /// the greedy pairing is the opposite pairs and the search ends almost at once; `None` when
    /// it visits more than [`SEARCH_BUDGET`] sets (a disordered neighbourhood), for the exact
    /// dynamic programme to answer.
    fn branch_and_bound(&mut self, m: usize) -> Option<f64> {
        let w = &self.weights;
        self.order.clear();
        for a in 0..m {
            for b in a + 1..m {
                self.order.push((w[a * m + b], a as u8, b as u8));
            }
        }
        self.order.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut used = 0u32;
        let mut greedy = 0.0;
        for &(weight, a, b) in &self.order {
            let pair = (1 << a) | (1 << b);
            if used & pair == 0 {
                used |= pair;
                greedy += weight;
            }
        }
        // Each neighbour's partners, lightest first.
        self.partners.clear();
        for a in 0..m {
            let start = self.partners.len();
            self.partners
                .extend((0..m as u8).filter(|&b| b as usize != a));
            self.partners[start..]
                .sort_by(|&x, &y| w[a * m + x as usize].total_cmp(&w[a * m + y as usize]));
        }
        let mut search = Search {
            weights: w,
            partners: &self.partners,
            m,
            best: greedy,
            visited: 0,
        };
        search.visit((1u32 << m) - 1, 0.0).then_some(search.best)
    }

    /// The best pairing of the neighbours in `set`: its lowest neighbour paired with each of the
    /// others in turn (or, for an odd set, also left out).
    fn best(&mut self, set: u32, m: usize) -> f64 {
        if set.count_ones() < 2 {
            return 0.0;
        }
        if self.stamp[set as usize] == self.generation {
            return self.memo[set as usize];
        }
        let a = set.trailing_zeros() as usize;
        let rest = set & !(1 << a);
        let mut best = f64::INFINITY;
        if set.count_ones() % 2 == 1 {
            best = self.best(rest, m);
        }
        let mut others = rest;
        while others != 0 {
            let b = others.trailing_zeros() as usize;
            others &= others - 1;
            let w = self.weights[a * m + b] + self.best(rest & !(1 << b), m);
            if w < best {
                best = w;
            }
        }
        self.memo[set as usize] = best;
        self.stamp[set as usize] = self.generation;
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branch and bound finds the dynamic programme's optimum, on crystal-like and on
    /// random neighbourhoods (where it may give up, but never answers wrong).
    #[test]
    fn branch_and_bound_is_exact() {
        let mut seed = 7u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let fcc: Vec<[f64; 3]> = [
            [1., 1., 0.],
            [1., 0., 1.],
            [0., 1., 1.],
            [1., -1., 0.],
            [1., 0., -1.],
            [0., 1., -1.],
        ]
        .into_iter()
        .flat_map(|v: [f64; 3]| [v, v.map(|x| -x)])
        .collect();
        let (mut answered, mut gave_up) = (0, 0);
        for case in 0..600 {
            let m = [12, 8, 16, 6][case % 4];
            let noise = [0.05, 0.3, 1.0, 3.0][case / 4 % 4];
            let vectors: Vec<[f64; 3]> = (0..m)
                .map(|k| {
                    let base = if m == 12 { fcc[k] } else { [0.0; 3] };
                    base.map(|x| x * 1.8 + noise * next())
                })
                .collect();
            let mut work = Work {
                weights: vec![0.0; m * m],
                ..Work::default()
            };
            for a in 0..m {
                for b in 0..m {
                    let v = [0, 1, 2].map(|k| vectors[a][k] + vectors[b][k]);
                    work.weights[a * m + b] = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                }
            }
            let exact = work.dynamic(m);
            match work.matching_fast(m).or_else(|| work.branch_and_bound(m)) {
                Some(found) => {
                    answered += 1;
                    assert!(
                        (found - exact).abs() <= 1e-12 * exact.max(1.0),
                        "{found} {exact}"
                    );
                }
                None => gave_up += 1,
            }
        }
        assert!(answered > 500, "{answered} answered, {gave_up} gave up");
    }
}
