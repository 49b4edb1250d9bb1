//! Radial distribution functions g(r), total and partial, of a periodic frame, as OVITO's
//! Coordination analysis modifier computes them (VMD's `measure gofr`, MDAnalysis's `InterRDF`
//! without exclusions).
//!
//! Every pair of atoms closer than the cutoff is counted under the minimum image in histogram
//! bins of width `cutoff / bins`, once from each end; the counts are divided by what an ideal
//! gas of the same density would give in each spherical shell:
//!
//! g(r_k) = h_k / (4π/3 · (r_{k+1}³ − r_k³) · N² / V)
//!
//! with N the atoms and V the cell's volume. A partial g_ab between the atoms of kinds a and b
//! (their type labels when the frame has types, else their element symbols) counts the pairs
//! of an a atom and a b atom once from each end as well, over 2 N_a N_b / V for a ≠ b and
//! N_a² / V for a = b, so that g_ab tends to 1 at long range in a random mixture and the total
//! is the sum of the partials weighted by their share of the ordered pairs, (2) N_a N_b / N².
//!
//! The pairs come from a list of fractional cells at least half a cutoff wide, the 125 around each
//! atom's, in parallel over the atoms (integer counts: the same for any thread count), when the
//! cell is at least three cutoffs wide; down to two cutoffs (the cutoff at most half the cell's
//! narrowest width, where the minimum image is still the only image within the cutoff) every
//! pair of atoms is tested, for frames of up to [`MAX_ALL_PAIRS_ATOMS`] atoms. A wider cutoff,
//! a frame without a cell (no density) or fewer than two atoms is an error.
//!
//! ```
//! use texmap_md_io::rdf::rdf;
//! use texmap_md_io::{Frame, UnitCell};
//! // A simple cubic crystal of spacing 2 Å, 6³ sites: the first peak holds 6 neighbours at 2 Å.
//! let mut frame = Frame::new();
//! for i in 0..6 { for j in 0..6 { for k in 0..6 {
//!     frame.positions.push([2.0 * i as f32, 2.0 * j as f32, 2.0 * k as f32]);
//! }}}
//! frame.cell = Some(UnitCell::orthorhombic(12.0, 12.0, 12.0).unwrap());
//! let g = rdf(&frame, 2.5, 4, false).unwrap();
//! // The 6 neighbours at 2 Å fall in bin 3 (1.875 to 2.5 Å):
//! // g = 6 / (ρ · 4π/3 · (2.5³ − 1.875³)).
//! let rho = 216.0 / 1728.0;
//! let shell = 4.0 / 3.0 * std::f64::consts::PI * (2.5f64.powi(3) - 1.875f64.powi(3));
//! assert!((g.total[3] - 6.0 / (rho * shell)).abs() < 1e-12);
//! assert_eq!(g.total[..3], [0.0; 3]);
//! assert_eq!(g.r[3], 2.1875);
//! ```

use std::collections::BTreeMap;
use std::fmt;

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::coordination::MAX_CUTOFF;
use crate::frame::{Frame, Label};

/// The most atoms whose pairs are all tested when the cell is too narrow for the cell grid
/// (about 1.1 × 10⁹ pairs).
pub const MAX_ALL_PAIRS_ATOMS: usize = 48_000;

/// The most histogram bins.
pub const MAX_BINS: usize = 100_000;

/// A frame's radial distribution functions.
#[derive(Clone, Debug, PartialEq)]
pub struct Rdf {
    /// The centre of each bin, Å.
    pub r: Vec<f64>,
    /// g(r) over every pair of atoms.
    pub total: Vec<f64>,
    /// g_ab(r) for each pair of kinds a ≤ b (in label order), when asked for.
    pub partial: Vec<PartialRdf>,
}

/// One partial radial distribution function.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialRdf {
    /// The two kinds (type labels or element symbols), `a <= b`.
    pub kinds: [Label; 2],
    /// The atoms of each kind.
    pub atoms: [usize; 2],
    /// g_ab at each bin.
    pub g: Vec<f64>,
}

/// Why a radial distribution function cannot be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum RdfError {
    /// The frame has no periodic cell: no volume, no density.
    NoCell,
    /// Fewer than two atoms.
    TooFewAtoms(usize),
    /// The cutoff is not a distance in (0.45, [`MAX_CUTOFF`]] Å.
    BadCutoff(f32),
    /// The bin count is 0 or above [`MAX_BINS`].
    BadBins(usize),
    /// The cutoff is more than half the cell's narrowest width.
    CutoffTooLong {
        /// The cell's narrowest perpendicular width, Å.
        width: f64,
        /// The cutoff, Å.
        cutoff: f32,
    },
    /// The cell is too narrow for the cell grid and the frame too large to test every pair.
    TooManyPairs {
        /// The atoms of the frame.
        atoms: usize,
        /// The cell's narrowest perpendicular width, Å.
        width: f64,
        /// The cutoff, Å.
        cutoff: f32,
    },
}

impl fmt::Display for RdfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RdfError::NoCell => write!(
                f,
                "the frame has no periodic cell, so no density to normalise g(r) by"
            ),
            RdfError::TooFewAtoms(n) => write!(f, "the frame has {n} atom(s): g(r) needs pairs"),
            RdfError::BadCutoff(c) => write!(
                f,
                "the cutoff {c} is not a distance between 0.45 and {MAX_CUTOFF} Å"
            ),
            RdfError::BadBins(b) => write!(f, "{b} bins: expected 1 to {MAX_BINS}"),
            RdfError::CutoffTooLong { width, cutoff } => write!(
                f,
                "the cutoff {cutoff} Å is more than half the periodic cell's narrowest width \
                 ({width:.2} Å), where an atom would see two images of a neighbour: use a \
                 cutoff up to {:.2} Å or replicate the cell",
                width / 2.0
            ),
            RdfError::TooManyPairs {
                atoms,
                width,
                cutoff,
            } => write!(
                f,
                "the periodic cell ({width:.2} Å wide) is narrower than three cutoffs of \
                 {cutoff} Å, and {atoms} atoms are too many to test every pair (at most \
                 {MAX_ALL_PAIRS_ATOMS}): use a cutoff up to {:.2} Å or replicate the cell",
                width / 3.0
            ),
        }
    }
}

impl std::error::Error for RdfError {}

/// The kind of atom `i` for partial RDFs (and per-kind tables): its type label, else its
/// element symbol.
pub fn atom_kind(frame: &Frame, i: usize) -> Label {
    match frame.types.get(i) {
        Some(t) => *t,
        None => Label::new(crate::atom_element(frame, i).symbol()).unwrap_or_default(),
    }
}

/// The partial histogram of the kinds `a` and `b` of `kinds`: the upper triangle a <= b, row
/// by row (after the total's, slot 0 of the histograms).
fn slot(kinds: usize, a: usize, b: usize) -> usize {
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    a * kinds - a * (a + 1) / 2 + b
}

/// The pair histograms of one frame: `slots` histograms of `bins` bins, the first over every
/// pair, then one per kind pair; each ordered pair (i, j ≠ i) within the cutoff counted once.
struct Histogram<'a> {
    /// Each atom's wrapped fractional coordinates.
    frac: Vec<DVec3>,
    /// The cell's edges as columns: Cartesian = edges · fractional.
    edges: DMat3,
    /// The axes the cell repeats along.
    periodic: [bool; 3],
    /// Each atom's kind (empty without partials), and the number of kinds.
    kind_of: &'a [usize],
    kinds: usize,
    cut2: f64,
    inv_dr: f64,
    bins: usize,
    slots: usize,
}

impl Histogram<'_> {
    /// Adds the pair (i, j) at Cartesian displacement `v` to `h`, if within the cutoff.
    #[inline]
    fn add(&self, h: &mut [u64], i: usize, j: usize, v: DVec3) {
        let r2 = v.length_squared();
        if r2 >= self.cut2 {
            return;
        }
        let bin = ((r2.sqrt() * self.inv_dr) as usize).min(self.bins - 1);
        h[bin] += 1;
        if self.slots > 1 {
            let s = 1 + slot(self.kinds, self.kind_of[i], self.kind_of[j]);
            h[s * self.bins + bin] += 1;
        }
    }

    /// Every ordered pair, by a cell list of `dims` fractional cells per axis, each at least
    /// half a cutoff wide and at least 5 per axis, so that the 125 cells within two of an atom's
    /// hold each neighbour once, at the image the cells' offset gives.
    fn by_cells(&self, dims: [usize; 3]) -> Vec<u64> {
        let n = self.frac.len();
        let cell_of = |f: DVec3| -> [usize; 3] {
            std::array::from_fn(|k| ((f[k] * dims[k] as f64) as usize).min(dims[k] - 1))
        };
        let index = |c: [usize; 3]| (c[0] * dims[1] + c[1]) * dims[2] + c[2];
        let n_cells = dims[0] * dims[1] * dims[2];
        let mut starts = vec![0u32; n_cells + 1];
        let cells: Vec<usize> = self.frac.iter().map(|f| index(cell_of(*f))).collect();
        for &c in &cells {
            starts[c + 1] += 1;
        }
        for c in 0..n_cells {
            starts[c + 1] += starts[c];
        }
        let mut fill = starts.clone();
        let mut order = vec![0u32; n];
        for (i, &c) in cells.iter().enumerate() {
            order[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        // Wrapped Cartesian positions: a neighbour's image is its position plus the shift of
        // the cell offset that reaches it.
        let cart: Vec<DVec3> = self.frac.iter().map(|f| self.edges * *f).collect();
        self.sum_over_atoms(|h, i| {
            let c = cell_of(self.frac[i]);
            let pi = cart[i];
            for o in 0..125 {
                let off = [o / 25, (o / 5) % 5, o % 5].map(|x| x as isize - 2);
                let mut shift = DVec3::ZERO;
                let mut nc = [0usize; 3];
                let mut inside = true;
                for k in 0..3 {
                    let x = c[k] as isize + off[k];
                    let d = dims[k] as isize;
                    if self.periodic[k] {
                        nc[k] = x.rem_euclid(d) as usize;
                        shift[k] = x.div_euclid(d) as f64;
                    } else if (0..d).contains(&x) {
                        nc[k] = x as usize;
                    } else {
                        inside = false;
                    }
                }
                if !inside {
                    continue;
                }
                let shift = self.edges * shift - pi;
                let cell = index(nc);
                for &j in &order[starts[cell] as usize..starts[cell + 1] as usize] {
                    let j = j as usize;
                    if j != i {
                        self.add(h, i, j, cart[j] + shift);
                    }
                }
            }
        })
    }

    /// Every ordered pair tested, at its nearest image (a cell under three cutoffs wide).
    fn all_pairs(&self) -> Vec<u64> {
        let n = self.frac.len();
        let wrap = DVec3::from(self.periodic.map(|p| if p { 1.0 } else { 0.0 }));
        let round = |d: DVec3| d - d.round() * wrap;
        self.sum_over_atoms(|h, i| {
            for j in (0..n).filter(|&j| j != i) {
                let d = round(self.frac[j] - self.frac[i]);
                self.add(h, i, j, self.edges * d);
            }
        })
    }

    /// The histograms of `count(h, i)` run for every atom `i`, in parallel: integer sums, the
    /// same for any split of the atoms.
    fn sum_over_atoms(&self, count: impl Fn(&mut [u64], usize) + Sync) -> Vec<u64> {
        let size = self.bins * self.slots;
        (0..self.frac.len())
            .into_par_iter()
            .fold(
                || vec![0u64; size],
                |mut h, i| {
                    count(&mut h, i);
                    h
                },
            )
            .reduce(
                || vec![0u64; size],
                |mut a, b| {
                    a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                    a
                },
            )
    }
}

/// The radial distribution function of `frame` to `cutoff` Å in `bins` bins, and with
/// `partial` the g_ab of every pair of kinds (see the module docs).
pub fn rdf(frame: &Frame, cutoff: f32, bins: usize, partial: bool) -> Result<Rdf, RdfError> {
    let Some(cell) = frame.cell else {
        return Err(RdfError::NoCell);
    };
    let n = frame.n_atoms();
    if n < 2 {
        return Err(RdfError::TooFewAtoms(n));
    }
    if bins == 0 || bins > MAX_BINS {
        return Err(RdfError::BadBins(bins));
    }
    if !(cutoff > 0.45 && cutoff <= MAX_CUTOFF) {
        return Err(RdfError::BadCutoff(cutoff));
    }
    let cut = cutoff as f64;
    let m = cell.matrix().map(DVec3::from_array);
    let volume = cell.volume();
    // Perpendicular width along each cell vector: the volume over the opposite face's area.
    let widths = [(1, 2), (2, 0), (0, 1)].map(|(a, b)| volume / m[a].cross(m[b]).length());
    // Only a periodic axis limits the cutoff: along the others no atom has an image.
    let periodic = cell.periodic();
    let width = (0..3)
        .filter(|&k| periodic[k])
        .map(|k| widths[k])
        .fold(f64::INFINITY, f64::min);
    if 2.0 * cut > width {
        return Err(RdfError::CutoffTooLong { width, cutoff });
    }
    let narrow = width < 3.0 * cut;
    // Cells at least half a cutoff wide (at least 6 per periodic axis when the cell is three
    // cutoffs wide), at most 512 per axis.
    let dims = widths.map(|w| ((2.0 * w / cut).floor() as usize).clamp(1, 512));
    if narrow && n > MAX_ALL_PAIRS_ATOMS {
        return Err(RdfError::TooManyPairs {
            atoms: n,
            width,
            cutoff,
        });
    }
    // Kinds in label order, and each atom's.
    let mut kinds: BTreeMap<&str, (Label, usize)> = BTreeMap::new();
    let of: Vec<Label> = if partial {
        (0..n).map(|i| atom_kind(frame, i)).collect()
    } else {
        Vec::new()
    };
    for k in &of {
        kinds.entry(k.as_str()).or_insert((*k, 0)).1 += 1;
    }
    let index: BTreeMap<&str, usize> = kinds.keys().enumerate().map(|(k, l)| (*l, k)).collect();
    let kind_of: Vec<usize> = of.iter().map(|l| index[l.as_str()]).collect();
    let n_kinds = kinds.len();
    let n_partial = n_kinds * (n_kinds + 1) / 2;
    let edges = DMat3::from_cols(m[0], m[1], m[2]);
    let inverse = edges.inverse();
    let frac: Vec<DVec3> = frame
        .positions
        .iter()
        .map(|p| {
            let f = inverse * DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            f - f.floor() * DVec3::from(periodic.map(|p| if p { 1.0 } else { 0.0 }))
        })
        .collect();
    let histogram = Histogram {
        frac,
        edges,
        periodic,
        kind_of: &kind_of,
        kinds: n_kinds,
        cut2: cut * cut,
        inv_dr: bins as f64 / cut,
        bins,
        slots: 1 + n_partial,
    };
    let hist = if narrow {
        histogram.all_pairs()
    } else {
        histogram.by_cells(dims)
    };
    let dr = cut / bins as f64;
    let shell = |k: usize| {
        let (r0, r1) = (k as f64 * dr, (k + 1) as f64 * dr);
        4.0 / 3.0 * std::f64::consts::PI * (r1 * r1 * r1 - r0 * r0 * r0)
    };
    let normalise = |h: &[u64], pairs_density: f64| -> Vec<f64> {
        h.iter()
            .enumerate()
            .map(|(k, &c)| c as f64 / (shell(k) * pairs_density))
            .collect()
    };
    let total = normalise(&hist[..bins], n as f64 * n as f64 / volume);
    let counts: Vec<(Label, usize)> = kinds.into_values().collect();
    let mut partials = Vec::with_capacity(n_partial);
    for a in 0..n_kinds {
        for b in a..n_kinds {
            let (na, nb) = (counts[a].1 as f64, counts[b].1 as f64);
            // An a-b pair (a ≠ b) is counted from each end, as the N_a N_b + N_b N_a ordered
            // pairs of the two kinds.
            let density = if a == b { na * na } else { 2.0 * na * nb } / volume;
            let s = 1 + slot(n_kinds, a, b);
            partials.push(PartialRdf {
                kinds: [counts[a].0, counts[b].0],
                atoms: [counts[a].1, counts[b].1],
                g: normalise(&hist[s * bins..(s + 1) * bins], density),
            });
        }
    }
    Ok(Rdf {
        r: (0..bins).map(|k| (k as f64 + 0.5) * dr).collect(),
        total,
        partial: partials,
    })
}
