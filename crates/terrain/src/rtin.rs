//! Right-triangulated irregular network (RTIN) on a `(2^k + 1)²` grid: an error map computed
//! bottom-up once, then meshes extracted at any maximum vertical error by walking the implicit
//! binary triangle tree.
//!
//! # The hierarchy
//! The square of side `S = 2^k` is cut by its diagonal into two right isosceles triangles; a
//! triangle `(a, b, c)` (hypotenuse `a–b`, right angle at `c`) splits at the hypotenuse midpoint
//! `m` into `(c, a, m)` and `(b, c, m)`. Two kinds of midpoint alternate, finest first:
//! - *diamond* vertices of step `s`: midpoints of the edges of the `s`-cell lattice, shared by the
//!   two triangles whose hypotenuse is that edge (the rhombus `|dx| + |dy| ≤ s/2` around it);
//! - *square* vertices of step `s`: centres of `s`-cells, shared by the two triangles cut by the
//!   cell's diagonal (the diagonal passes through the centre of the parent `2s`-cell).
//!
//! # The error map (a strict bound, unlike martini's)
//! `errors[m]` is the largest vertical distance, over every grid sample inside either triangle
//! of `m`'s diamond, between the sample and the plane of the triangle it lies in — computed
//! exactly by visiting the samples — maxed with `errors` of the four children midpoints. A
//! triangle left unsplit because `errors[m] ≤ ε` therefore has every grid sample within `ε` of it,
//! and because a vertex's value dominates its descendants', splitting a triangle always splits its
//! ancestors and the neighbours sharing their hypotenuses: the mesh is conforming (no T-junction).
//! Mapbox martini stores only the midpoint's distance to its hypotenuse's linear interpolation
//! (maxed over descendants), which is cheaper but not a bound on the triangle's error; the cost
//! of the exact bound is visiting every sample once per level (`2 log2 S` passes over the grid),
//! done in parallel over map rows with rayon — first every midpoint's own error (they are
//! independent), then the max with the children, level by level — and vectorised over the
//! samples of each row segment. Every entry is computed by one fixed sequence of operations and
//! the max is exact, so the map is the same for any thread count.
//!
//! # No-data
//! A diamond holding both valid and no-data (`NaN`) samples gets an infinite error, so it is split
//! down to single cells around every hole; a diamond of no-data only gets 0 (nothing to refine),
//! and triangles with a no-data vertex are dropped at extraction: holes stay holes, with
//! cell-exact rims, and padding a grid with `NaN` to `2^k + 1` costs only its border.

use rayon::prelude::*;
use texmap_core::lanes::F32x4;

/// A triangle of grid sample coordinates `(x, y)`: hypotenuse `a–b`, right angle at `c`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tri {
    pub a: [u32; 2],
    pub b: [u32; 2],
    pub c: [u32; 2],
}

/// The error map of a `(2^k + 1)²` grid.
#[derive(Clone, Debug)]
pub struct ErrorMap {
    n: u32,
    errors: Vec<f32>,
    /// Whether the grid it was built from has no-data samples.
    nodata: bool,
}

/// Lanes of the sample fold: 8 independent running maxima, so the per-sample loop is a vector
/// loop instead of one chain of dependent comparisons.
const LANES: usize = 8;

/// Fold of a diamond's or cell's samples: the max error (per lane), samples visited and no-data
/// samples seen (per lane; counted only when the grid has no-data, `NODATA`).
///
/// Branch-free per sample: a NaN difference never wins the `>` comparison, and no-data is counted
/// separately. The max does not depend on the order samples are folded in (every error is
/// `≥ +0`), so the lanes change nothing in the result.
#[derive(Clone, Copy)]
struct Acc<const NODATA: bool> {
    err: [f32; LANES],
    nodata: [u32; LANES],
    seen: u32,
}

impl<const NODATA: bool> Acc<NODATA> {
    #[inline(always)]
    fn new() -> Self {
        Acc {
            err: [0.0; LANES],
            nodata: [0; LANES],
            seen: 0,
        }
    }

    /// Samples `heights[start + i]`, `i < len`, against the plane values `base + slope·i`.
    #[inline(always)]
    fn scan(&mut self, heights: &[f32], start: usize, len: usize, base: f32, slope: f32) {
        self.seen += len as u32;
        let mut i = 0;
        while i + LANES <= len {
            let chunk = heights[start + i..start + i + LANES].try_into().unwrap();
            self.fold::<LANES>(chunk, base, slope, i, LANES);
            i += LANES;
        }
        // The partial chunk at the end, on 8 or (short segments of the fine levels) 4 lanes.
        let rest = len - i;
        if rest > 4 {
            self.fold_part::<LANES>(heights, start + i, base, slope, i, rest);
        } else if rest > 0 {
            self.fold_part::<4>(heights, start + i, base, slope, i, rest);
        }
    }

    /// Folds the `valid < W` samples from `heights[at]` (segment index `i0` on): reads a whole
    /// chunk when the grid has the samples past them, and masks the lanes beyond the segment
    /// (their samples belong to other triangles).
    #[inline(always)]
    fn fold_part<const W: usize>(
        &mut self,
        heights: &[f32],
        at: usize,
        base: f32,
        slope: f32,
        i0: usize,
        valid: usize,
    ) {
        if at + W <= heights.len() {
            self.fold::<W>(
                heights[at..at + W].try_into().unwrap(),
                base,
                slope,
                i0,
                valid,
            );
        } else {
            let mut chunk = [0.0f32; W];
            chunk[..valid].copy_from_slice(&heights[at..at + valid]);
            self.fold::<W>(&chunk, base, slope, i0, valid);
        }
    }

    /// Folds `chunk[j]` (segment index `i0 + j`) for the lanes `j < valid` into the first `W`
    /// lanes (`W` = 4 or 8).
    #[inline(always)]
    fn fold<const W: usize>(
        &mut self,
        chunk: &[f32; W],
        base: f32,
        slope: f32,
        i0: usize,
        valid: usize,
    ) {
        // `i0 + j` as f32 is exact (grid sides are far below 2^24). The lane mask comes from a
        // table (all ones for the live lanes), so the loop is all vector operations.
        const J: [f32; LANES] = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
        const MASKS: [[u32; LANES]; LANES + 1] = {
            let mut m = [[0u32; LANES]; LANES + 1];
            let mut v = 0;
            while v <= LANES {
                let mut j = 0;
                while j < v {
                    m[v][j] = u32::MAX;
                    j += 1;
                }
                v += 1;
            }
            m
        };
        let mask = &MASKS[valid];
        let f0 = i0 as f32;
        let mut e = [0.0f32; W];
        for j in 0..W {
            let h = chunk[j];
            let d = (h - (base + slope * (f0 + J[j]))).abs();
            e[j] = f32::from_bits(d.to_bits() & mask[j]);
            if NODATA {
                self.nodata[j] += h.is_nan() as u32 & mask[j];
            }
        }
        for q in 0..W / 4 {
            let (acc, new) = (&mut self.err[4 * q..4 * q + 4], &e[4 * q..4 * q + 4]);
            let m = max4(new.try_into().unwrap(), acc[..].try_into().unwrap());
            acc.copy_from_slice(&m);
        }
    }

    #[inline(always)]
    fn value(self) -> f32 {
        let mut err = 0.0f32;
        let mut nodata = 0;
        for j in 0..LANES {
            err = if self.err[j] > err { self.err[j] } else { err };
            nodata += self.nodata[j];
        }
        fold_value(err, self.seen, nodata)
    }
}

/// `if e > acc { e } else { acc }` lane by lane (a NaN `e` never wins): one `maxps` through the
/// workspace's lane type, which the plain comparison does not compile to (signed zeros).
#[inline(always)]
fn max4(e: [f32; 4], acc: [f32; 4]) -> [f32; 4] {
    F32x4::new(e).max(F32x4::new(acc)).to_array()
}

/// The value of a fold of `seen` samples of which `nodata` are no-data, `err` being the max error
/// over the valid ones.
#[inline(always)]
fn fold_value(err: f32, seen: u32, nodata: u32) -> f32 {
    if nodata == 0 {
        err
    } else if nodata == seen {
        0.0
    } else {
        f32::INFINITY
    }
}

impl ErrorMap {
    /// Side length `n = 2^k + 1` the map works on (with `k ≥ 1`).
    pub fn is_valid_size(n: u32) -> bool {
        n >= 3 && (n - 1).is_power_of_two()
    }

    /// Build the error map of `heights` (`n x n`, row-major, `NaN` = no-data).
    ///
    /// Two passes, both parallel over map rows and writing in place: every midpoint's own error
    /// (its diamond or cell against the triangles' planes; independent of the other entries),
    /// then, level by level from the finest, the max with the four children.
    ///
    /// # Panics
    /// If `n` is not `2^k + 1` with `k ≥ 1` or `heights.len() != n²` (callers pad first).
    pub fn new(heights: &[f32], n: u32) -> ErrorMap {
        assert!(
            Self::is_valid_size(n),
            "RTIN needs 2^k + 1 samples a side, got {n}"
        );
        assert_eq!(heights.len(), n as usize * n as usize);
        let size = n - 1;
        let nu = n as usize;
        let mut errors = vec![0.0f32; nu * nu];
        // Without no-data anywhere (the common case) no sample needs counting.
        let nodata = heights.iter().any(|h| h.is_nan());
        errors.par_chunks_mut(nu).enumerate().for_each(|(y, row)| {
            if nodata {
                own_row::<true>(heights, nu, size, y as u32, row)
            } else {
                own_row::<false>(heights, nu, size, y as u32, row)
            }
        });
        let mut s = 2;
        while s <= size {
            let h = s / 2;
            if h >= 2 {
                // Diamond vertices of step s (rows at multiples of h) take their children, the
                // square vertices of step h (rows at odd multiples of h / 2).
                let k = h / 2;
                for_rows(
                    &mut errors,
                    nu,
                    |y| y % h == 0,
                    |y, row, rows| {
                        let (first, step) = if y % s == 0 { (h, s) } else { (0, s) };
                        let mut x = first;
                        while x <= size {
                            let mut e = row[x as usize];
                            for (dx, dy) in [(-1i64, -1i64), (1, -1), (-1, 1), (1, 1)] {
                                let cx = x as i64 + dx * k as i64;
                                let cy = y as i64 + dy * k as i64;
                                if cx >= 0 && cy >= 0 && cx <= size as i64 && cy <= size as i64 {
                                    e = e.max(rows[cy as usize][cx as usize]);
                                }
                            }
                            row[x as usize] = e;
                            x += step;
                        }
                    },
                );
            }
            // Square vertices of step s (rows at odd multiples of h) take the four diamond
            // vertices of step s on their cell's edges: two on their own row, two on the rows of
            // the cell's top and bottom (multiples of s).
            for_rows(
                &mut errors,
                nu,
                |y| y % s == h,
                |y, row, rows| {
                    let y0 = y - h;
                    for x0 in (0..size).step_by(s as usize) {
                        let mut e = row[(x0 + h) as usize];
                        e = e.max(rows[y0 as usize][(x0 + h) as usize]);
                        e = e.max(rows[(y0 + s) as usize][(x0 + h) as usize]);
                        e = e.max(row[x0 as usize]);
                        e = e.max(row[(x0 + s) as usize]);
                        row[(x0 + h) as usize] = e;
                    }
                },
            );
            s *= 2;
        }
        ErrorMap { n, errors, nodata }
    }

    /// Side length in samples.
    pub fn n(&self) -> u32 {
        self.n
    }

    /// The error bound stored at sample `(x, y)` (0 at the corners and for leaf cells).
    pub fn error_at(&self, x: u32, y: u32) -> f32 {
        self.errors[y as usize * self.n as usize + x as usize]
    }

    /// The two triangles of the `s`-cell at `(x0, y0)` (aligned: multiples of `s`, a power of two),
    /// wound the same way as every triangle of the hierarchy.
    pub fn cell_triangles(&self, x0: u32, y0: u32, s: u32) -> [Tri; 2] {
        let size = self.n - 1;
        let (x1, y1) = (x0 + s, y0 + s);
        if is_main_diagonal(x0 / s, y0 / s, s, size) {
            [
                Tri {
                    a: [x0, y0],
                    b: [x1, y1],
                    c: [x1, y0],
                },
                Tri {
                    a: [x1, y1],
                    b: [x0, y0],
                    c: [x0, y1],
                },
            ]
        } else {
            [
                Tri {
                    a: [x0, y1],
                    b: [x1, y0],
                    c: [x0, y0],
                },
                Tri {
                    a: [x1, y0],
                    b: [x0, y1],
                    c: [x1, y1],
                },
            ]
        }
    }
}

/// A vertex of the walk: its grid sample index `y·n + x` (low 32 bits) and its slot `j·side + i`
/// on the extracted cell's lattice (high 32 bits). Both are linear in the coordinates and the two
/// ends of a hypotenuse have coordinates of the same parity, so `(p + q) >> 1` is the midpoint in
/// both halves at once when it lies on the lattice (neither half's sum reaches 2^32 for
/// `n ≤ 2^15 + 1`).
type Vert = u64;

/// The midpoint of the hypotenuse `p–q`, a lattice point.
#[inline(always)]
fn mid(p: Vert, q: Vert) -> Vert {
    (p + q) >> 1
}

/// The lattice slot of a vertex.
#[inline(always)]
fn slot(p: Vert) -> u32 {
    (p >> 32) as u32
}

/// A level of the walk: triangles with legs `D = 2^K` long, as a type so that every level
/// compiles apart (no branch on the level in the walk).
struct Legs<const K: u32>;

trait Level {
    /// The legs' length.
    const D: u32;
    /// The level of half the legs (itself for `D = 1`, which is not split).
    type Half: Level;
}

macro_rules! levels {
    ($($k:literal => $half:literal),*) => {
        $(impl Level for Legs<$k> {
            const D: u32 = 1 << $k;
            type Half = Legs<$half>;
        })*
    };
}

levels!(0 => 0, 1 => 0, 2 => 1, 3 => 2, 4 => 3, 5 => 4, 6 => 5, 7 => 6, 8 => 7, 9 => 8,
    10 => 9, 11 => 10, 12 => 11, 13 => 12, 14 => 13, 15 => 14);

/// The walk of [`extract`], depth first, first child first: split a triangle while its
/// hypotenuse midpoint's bound exceeds `max_error`, never below cells of `min_step`. Kept
/// triangles go to `tris` as lattice slots, in walk order; with `NODATA` (the grid has no-data),
/// those with a no-data vertex are dropped.
struct Walker<'a, const NODATA: bool> {
    errors: &'a [f32],
    heights: &'a [f32],
    max_error: f32,
    min_step: u32,
    /// Kept triangles in `tris[..len]`; the rest is room written ahead of `len`.
    tris: Vec<[u32; 3]>,
    len: usize,
    /// Largest finite bound among the kept triangles.
    max_bound: f32,
    /// Kept triangles with an infinite bound.
    bridging: u32,
}

impl<const NODATA: bool> Walker<'_, NODATA> {
    /// The error map entry at the hypotenuse midpoint of `p–q` (a grid sample, on the lattice
    /// or not: only the sample halves are added).
    #[inline(always)]
    fn stored(&self, p: Vert, q: Vert) -> f32 {
        self.errors[((p + q) as u32 >> 1) as usize]
    }

    /// Makes room for `k` more triangles past `len`.
    #[inline(always)]
    fn room(&mut self, k: usize) {
        if self.len + k > self.tris.len() {
            let grown = (self.len + k).max(2 * self.tris.len()).max(1024);
            self.tris.resize(grown, [0; 3]);
        }
    }

    /// Keeps the triangle `(a, b, c)` of error bound `bound`.
    #[inline(always)]
    fn emit(&mut self, a: Vert, b: Vert, c: Vert, bound: f32) {
        if NODATA {
            if [a, b, c]
                .iter()
                .any(|&p| self.heights[p as u32 as usize].is_nan())
            {
                return;
            }
            if bound.is_finite() {
                self.max_bound = self.max_bound.max(bound);
            } else {
                self.bridging += 1;
            }
        } else {
            self.max_bound = self.max_bound.max(bound);
        }
        self.room(1);
        self.tris[self.len] = [slot(a), slot(b), slot(c)];
        self.len += 1;
    }

    /// [`Walker::square`], as a call of its own for the coarse levels and inlined into the
    /// caller for the last two (legs of 4 and 2).
    #[inline(always)]
    fn child<L: Level>(&mut self, a: Vert, b: Vert, c: Vert, e: f32) {
        if L::D > 4 {
            self.square_call::<L>(a, b, c, e)
        } else {
            self.square::<L>(a, b, c, e)
        }
    }

    /// [`Walker::square`] as a function of its own (the recursion).
    #[inline(never)]
    fn square_call<L: Level>(&mut self, a: Vert, b: Vert, c: Vert, e: f32) {
        self.square::<L>(a, b, c, e)
    }

    /// The triangle `(a, b, c)` (hypotenuse `a–b`, right angle at `c`) with legs along the axes,
    /// `L::D` long, and `e` the map at its hypotenuse midpoint (unused for `L::D = 1`).
    #[inline(always)]
    fn square<L: Level>(&mut self, a: Vert, b: Vert, c: Vert, e: f32) {
        if L::D == 1 {
            return self.emit(a, b, c, 0.0);
        }
        if !NODATA && L::D == 2 && self.min_step == 1 {
            return self.fine(a, b, c, e);
        }
        if L::D > self.min_step && e > self.max_error {
            let m = mid(a, b);
            let (first, second) = (self.stored(c, a), self.stored(b, c));
            self.diagonal::<L>(c, a, m, first);
            self.diagonal::<L>(b, c, m, second);
        } else {
            self.emit(a, b, c, e);
        }
    }

    /// The triangle `(a, b, c)` with diagonal legs, `L::D ≥ 2` steps `|dx| + |dy|` long.
    #[inline(always)]
    fn diagonal<L: Level>(&mut self, a: Vert, b: Vert, c: Vert, e: f32) {
        if e > self.max_error {
            let m = mid(a, b);
            let (first, second) = if L::D > 2 {
                (self.stored(c, a), self.stored(b, c))
            } else {
                (0.0, 0.0)
            };
            self.child::<L::Half>(c, a, m, first);
            self.child::<L::Half>(b, c, m, second);
        } else {
            self.emit(a, b, c, e);
        }
    }

    /// [`Walker::square`] for legs of 2 (and `min_step = 1`) on a grid without no-data, without a
    /// branch on the terrain: the subtree's candidates (the triangle, its two children, their
    /// four children) are all written in walk order, `len` advancing past the kept ones only.
    #[inline(always)]
    fn fine(&mut self, a: Vert, b: Vert, c: Vert, e: f32) {
        let (m, ca, bc) = (mid(a, b), mid(c, a), mid(b, c));
        let (e1, e2) = (self.stored(c, a), self.stored(b, c));
        let max = self.max_error;
        let (s0, s1, s2) = (e > max, e1 > max, e2 > max);
        let keep0 = !s0;
        let (keep1, keep1s) = (s0 & !s1, s0 & s1);
        let (keep2, keep2s) = (s0 & !s2, s0 & s2);
        let at = |p: Vert| slot(p);
        let cands = [
            ([at(a), at(b), at(c)], keep0),
            ([at(c), at(a), at(m)], keep1),
            ([at(m), at(c), at(ca)], keep1s),
            ([at(a), at(m), at(ca)], keep1s),
            ([at(b), at(c), at(m)], keep2),
            ([at(m), at(b), at(bc)], keep2s),
            ([at(c), at(m), at(bc)], keep2s),
        ];
        self.room(cands.len());
        let out = &mut self.tris[self.len..self.len + cands.len()];
        let mut k = 0;
        for (t, keep) in cands {
            out[k] = t;
            k += keep as usize;
        }
        self.len += k;
        // The kept triangles' bounds, the others' times 0 (finite without no-data): a product,
        // which does not compile to a branch as a select would.
        let pick = |keep: bool, e: f32| e * keep as u8 as f32;
        self.max_bound = self
            .max_bound
            .max(pick(keep0, e))
            .max(pick(keep1, e1))
            .max(pick(keep2, e2));
    }
}

/// Whether the `s`-cell with index `(i, j)` is cut by its main diagonal `(x0, y0)–(x0+s, y0+s)`:
/// the diagonal passes through the parent cell's centre, i.e. the main one when `i` and `j` have
/// the same parity; the whole square (`s = size`) uses the main diagonal.
fn is_main_diagonal(i: u32, j: u32, s: u32, size: u32) -> bool {
    s == size || (i & 1) == (j & 1)
}

/// [`cell_error_in`] with the small steps compiled apart (constant segment lengths: the scans
/// unroll to straight-line vector code).
fn cell_error<const NODATA: bool>(
    heights: &[f32],
    nu: usize,
    x0: u32,
    y0: u32,
    s: u32,
    main: bool,
) -> f32 {
    match s {
        4 => cell_error_in::<NODATA>(heights, nu, x0, y0, 4, main),
        8 => cell_error_in::<NODATA>(heights, nu, x0, y0, 8, main),
        16 => cell_error_in::<NODATA>(heights, nu, x0, y0, 16, main),
        _ => cell_error_in::<NODATA>(heights, nu, x0, y0, s, main),
    }
}

/// Exact error of the two triangles of an `s`-cell (`s ≥ 4`) against their planes, row by row.
#[inline(always)]
fn cell_error_in<const NODATA: bool>(
    heights: &[f32],
    nu: usize,
    x0: u32,
    y0: u32,
    s: u32,
    main: bool,
) -> f32 {
    let at = |x: u32, y: u32| heights[y as usize * nu + x as usize];
    let h00 = at(x0, y0);
    let h10 = at(x0 + s, y0);
    let h01 = at(x0, y0 + s);
    let h11 = at(x0 + s, y0 + s);
    let inv = 1.0 / s as f32;
    let mut acc = Acc::<NODATA>::new();
    for v in 0..=s {
        let fv = v as f32 * inv;
        let start = (y0 + v) as usize * nu + x0 as usize;
        let len = s as usize + 1;
        if main {
            // u < v: the lower-left triangle (h00, h01, h11); u ≥ v: the upper-right (h00, h10, h11).
            let split = v as usize;
            acc.scan(
                heights,
                start,
                split,
                h00 + (h01 - h00) * fv,
                (h11 - h01) * inv,
            );
            let (b1, d1) = (h00 + (h11 - h10) * fv, (h10 - h00) * inv);
            acc.scan(
                heights,
                start + split,
                len - split,
                b1 + d1 * split as f32,
                d1,
            );
        } else {
            // u + v ≤ s: the upper-left triangle (h00, h10, h01); beyond: the lower-right (h10, h01, h11).
            let split = (s - v) as usize + 1;
            acc.scan(
                heights,
                start,
                split,
                h00 + (h01 - h00) * fv,
                (h10 - h00) * inv,
            );
            let d2 = -(h01 - h11) * inv;
            let b2 = h11 + (h01 - h11) + (h10 - h11) * (1.0 - fv);
            acc.scan(
                heights,
                start + split,
                len - split,
                b2 + d2 * split as f32,
                d2,
            );
        }
    }
    acc.value()
}

/// [`diamond_error_in`] with the small steps compiled apart (constant segment lengths).
fn diamond_error<const NODATA: bool>(
    heights: &[f32],
    nu: usize,
    mx: u32,
    my: u32,
    h: u32,
    horizontal: bool,
    size: u32,
) -> f32 {
    match h {
        2 => diamond_error_in::<NODATA>(heights, nu, mx, my, 2, horizontal, size),
        4 => diamond_error_in::<NODATA>(heights, nu, mx, my, 4, horizontal, size),
        8 => diamond_error_in::<NODATA>(heights, nu, mx, my, 8, horizontal, size),
        _ => diamond_error_in::<NODATA>(heights, nu, mx, my, h, horizontal, size),
    }
}

/// Exact error of the (one or two) triangles whose hypotenuse is the lattice edge of length `2h`
/// (`h ≥ 2`) centred at `(mx, my)`: horizontal edge -> apexes above and below, vertical -> left
/// and right. Samples on the edge are visited once per side (harmless for a max).
#[inline(always)]
fn diamond_error_in<const NODATA: bool>(
    heights: &[f32],
    nu: usize,
    mx: u32,
    my: u32,
    h: u32,
    horizontal: bool,
    size: u32,
) -> f32 {
    let at = |x: u32, y: u32| heights[y as usize * nu + x as usize];
    let mut acc = Acc::<NODATA>::new();
    let inv = 1.0 / h as f32;
    let half = 0.5 * inv;
    if horizontal {
        let (ha, hb) = (at(mx - h, my), at(mx + h, my));
        let mid = 0.5 * (ha + hb);
        let slope = (hb - ha) * half;
        for side in [-1i64, 1] {
            let ay = my as i64 + side * h as i64;
            if ay < 0 || ay > size as i64 {
                continue;
            }
            let lift = at(mx, ay as u32) - mid;
            for wa in 0..=h {
                let y = (my as i64 + side * wa as i64) as usize;
                let r = h - wa;
                let x_start = mx - r;
                let start = y * nu + x_start as usize;
                let base = ha + slope * (x_start - (mx - h)) as f32 + lift * wa as f32 * inv;
                acc.scan(heights, start, 2 * r as usize + 1, base, slope);
            }
        }
    } else {
        let (ha, hb) = (at(mx, my - h), at(mx, my + h));
        let mid = 0.5 * (ha + hb);
        let left = (mx >= h).then(|| at(mx - h, my) - mid);
        let right = (mx + h <= size).then(|| at(mx + h, my) - mid);
        for t in -(h as i64)..=h as i64 {
            let y = (my as i64 + t) as usize;
            let r = h - t.unsigned_abs() as u32;
            let along = ha + (hb - ha) * (t + h as i64) as f32 * half;
            if let Some(l) = left {
                let start = y * nu + (mx - r) as usize;
                acc.scan(
                    heights,
                    start,
                    r as usize + 1,
                    along + l * r as f32 * inv,
                    -l * inv,
                );
            }
            if let Some(rl) = right {
                let start = y * nu + mx as usize;
                acc.scan(heights, start, r as usize + 1, along, rl * inv);
            }
        }
    }
    acc.value()
}

/// Runs `f(y, row, rows)` in parallel over the map rows `y` with `dest(y)`, `row` writable and
/// `rows[y']` the other rows, readable (empty for the rows being written).
fn for_rows(
    errors: &mut [f32],
    nu: usize,
    dest: impl Fn(u32) -> bool,
    f: impl Fn(u32, &mut [f32], &[&[f32]]) + Sync,
) {
    let mut written = Vec::new();
    let mut rows: Vec<&[f32]> = Vec::with_capacity(nu);
    for (y, row) in errors.chunks_mut(nu).enumerate() {
        if dest(y as u32) {
            written.push((y as u32, row));
            rows.push(&[]);
        } else {
            rows.push(row);
        }
    }
    written
        .into_par_iter()
        .for_each(|(y, row)| f(y, row, &rows));
}

/// The own error of every midpoint on map row `y` (before the max with its children).
///
/// With `2^t` the largest power of two dividing `y` (`y = 0` and `y = size` count as the top
/// level), the row holds the horizontal-edge diamond vertices of every step `2h ≤ 2^t` at odd
/// multiples of `h`, and, for `y` an odd multiple of `h = 2^t`, the square vertices of step
/// `2h` (odd multiples of `h`) and vertical-edge diamond vertices of step `2h` (multiples of
/// `2h`). The corners of the grid are no midpoint and stay 0.
fn own_row<const NODATA: bool>(heights: &[f32], nu: usize, size: u32, y: u32, row: &mut [f32]) {
    let top = size.trailing_zeros();
    let ty = if y == 0 { top } else { y.trailing_zeros() };
    let line = |y: u32| &heights[y as usize * nu..(y as usize + 1) * nu];
    let cur = line(y);
    let up = (y > 0).then(|| line(y - 1));
    let down = (y < size).then(|| line(y + 1));
    if ty > 0 {
        if NODATA {
            fine_horizontal(cur, up, down, row);
        } else {
            // Every interior x; the even ones are other midpoints, overwritten below.
            fine_horizontal_all(cur, row);
        }
    }
    for t in 1..ty.min(top) {
        let h = 1u32 << t;
        for x in (h..size).step_by(2 * h as usize) {
            row[x as usize] = diamond_error::<NODATA>(heights, nu, x, y, h, true, size);
        }
    }
    if ty < top {
        let h = 1u32 << ty;
        let s = 2 * h;
        let (up, down) = (up.unwrap(), down.unwrap());
        if h == 1 {
            if NODATA {
                fine_vertical(cur, up, down, row, size);
            } else {
                // Every x; the odd ones are cell centres, overwritten next.
                fine_vertical_all(cur, up, down, row);
            }
            fine_cells::<NODATA>(cur, up, down, row, y, size);
        } else {
            let y0 = y - h;
            for x0 in (0..size).step_by(s as usize) {
                let main = is_main_diagonal(x0 / s, y0 / s, s, size);
                row[(x0 + h) as usize] = cell_error::<NODATA>(heights, nu, x0, y0, s, main);
            }
            for x in (0..=size).step_by(s as usize) {
                row[x as usize] = diamond_error::<NODATA>(heights, nu, x, y, h, false, size);
            }
        }
    }
}

/// [`fine_horizontal`] on a grid without no-data, written at every interior `x` (one vector
/// loop): `|h[x] − (h[x − 1] + h[x + 1]) / 2|`.
fn fine_horizontal_all(cur: &[f32], row: &mut [f32]) {
    let n = cur.len();
    for (((o, &a), &m), &b) in row[1..n - 1]
        .iter_mut()
        .zip(&cur[..n - 2])
        .zip(&cur[1..n - 1])
        .zip(&cur[2..])
    {
        *o = (m - 0.5 * (a + b)).abs();
    }
}

/// [`fine_vertical`] on a grid without no-data, written at every `x` (one vector loop).
fn fine_vertical_all(cur: &[f32], up: &[f32], down: &[f32], row: &mut [f32]) {
    for (((o, &m), &a), &b) in row.iter_mut().zip(cur).zip(up).zip(down) {
        *o = (m - 0.5 * (a + b)).abs();
    }
}

/// Diamonds of one sample step on an edge along an even row (odd `x`): the only sample of their
/// triangles not a vertex is the midpoint, measured against the edge; the apexes above and below
/// (where the grid has them) only count for no-data.
fn fine_horizontal(cur: &[f32], up: Option<&[f32]>, down: Option<&[f32]>, row: &mut [f32]) {
    let size = cur.len() - 1;
    for x in (1..size).step_by(2) {
        let (a, b, m) = (cur[x - 1], cur[x + 1], cur[x]);
        let mut seen = 3;
        let mut nodata = a.is_nan() as u32 + b.is_nan() as u32 + m.is_nan() as u32;
        for apex in [up, down].into_iter().flatten() {
            seen += 1;
            nodata += apex[x].is_nan() as u32;
        }
        row[x] = fold_value((m - 0.5 * (a + b)).abs(), seen, nodata);
    }
}

/// Diamonds of one sample step on an edge across an odd row (even `x`): the midpoint against
/// the samples above and below; the apexes left and right only count for no-data.
fn fine_vertical(cur: &[f32], up: &[f32], down: &[f32], row: &mut [f32], size: u32) {
    let size = size as usize;
    for x in (0..=size).step_by(2) {
        let (a, b, m) = (up[x], down[x], cur[x]);
        let mut seen = 3;
        let mut nodata = a.is_nan() as u32 + b.is_nan() as u32 + m.is_nan() as u32;
        if x >= 1 {
            seen += 1;
            nodata += cur[x - 1].is_nan() as u32;
        }
        if x < size {
            seen += 1;
            nodata += cur[x + 1].is_nan() as u32;
        }
        row[x] = fold_value((m - 0.5 * (a + b)).abs(), seen, nodata);
    }
}

/// Cells of two sample steps centred on an odd row (odd `x`): besides the corners, the centre
/// (on the diagonal) and the four edge midpoints (on the legs), each measured against the line
/// it lies on.
fn fine_cells<const NODATA: bool>(
    cur: &[f32],
    up: &[f32],
    down: &[f32],
    row: &mut [f32],
    y: u32,
    size: u32,
) {
    let j = (y - 1) / 2;
    for x in (1..size as usize).step_by(2) {
        let (h00, h10, h01, h11) = (up[x - 1], up[x + 1], down[x - 1], down[x + 1]);
        let (hc, ht, hb, hl, hr) = (cur[x], up[x], down[x], cur[x - 1], cur[x + 1]);
        let diag = if is_main_diagonal((x as u32 - 1) / 2, j, 2, size) {
            0.5 * (h00 + h11)
        } else {
            0.5 * (h10 + h01)
        };
        let err = (hc - diag)
            .abs()
            .max((ht - 0.5 * (h00 + h10)).abs())
            .max((hb - 0.5 * (h01 + h11)).abs())
            .max((hl - 0.5 * (h00 + h01)).abs())
            .max((hr - 0.5 * (h10 + h11)).abs());
        row[x] = if NODATA {
            let nodata = [h00, h10, h01, h11, hc, ht, hb, hl, hr]
                .iter()
                .map(|v| v.is_nan() as u32)
                .sum();
            fold_value(err, 9, nodata)
        } else {
            err
        };
    }
}

/// A mesh extracted from an error map: grid sample indices per vertex, triangles over them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GridMesh {
    /// `(x, y)` grid sample of each vertex, in the order the walk first meets them.
    pub vertices: Vec<[u32; 2]>,
    /// Counter-clockwise seen from above (x east, y down the rows, heights up).
    pub triangles: Vec<[u32; 3]>,
    /// Largest error bound among the kept triangles (finite ones).
    pub max_bound: f32,
    /// Kept triangles whose bound is infinite: they span no-data they were not allowed to split away.
    pub bridging: u32,
}

/// Extract the mesh under the `s`-cell at `(x0, y0)` (the whole grid: `(0, 0, n − 1)`): the
/// tree walked from the cell's two triangles, splitting a triangle while its hypotenuse
/// midpoint's bound exceeds `max_error`, never below cells of `min_step` (a power of two ≥ 1).
/// Triangles with a no-data vertex are dropped.
///
/// Vertices are numbered in first-use order over the kept triangles (deterministic) through a
/// dense slot table over the cell's lattice of `min_step` samples (every kept vertex lies on it:
/// the walk stops only at triangles whose legs are axis-aligned and at least `min_step` long),
/// so a coarse chunk of a large grid needs `(s / min_step + 1)²` slots, not one per grid sample.
///
/// # Panics
/// If `s` is not a power of two or the map is larger than `(2^15 + 1)²` (the walk's packed
/// vertex indices).
pub fn extract(
    map: &ErrorMap,
    heights: &[f32],
    x0: u32,
    y0: u32,
    s: u32,
    max_error: f32,
    min_step: u32,
) -> GridMesh {
    assert!(s.is_power_of_two(), "cells are 2^k samples a side, got {s}");
    assert!(map.n <= (1 << 15) + 1, "extract needs n ≤ 2^15 + 1");
    let g = if min_step > 1
        && min_step.is_power_of_two()
        && x0.is_multiple_of(min_step)
        && y0.is_multiple_of(min_step)
        && s.is_multiple_of(min_step)
    {
        min_step
    } else {
        1
    };
    let shift = g.trailing_zeros();
    let side = s / g + 1;
    let n = map.n;
    let vert = |[x, y]: [u32; 2]| -> Vert {
        let sample = y as u64 * n as u64 + x as u64;
        let lattice = ((y - y0) >> shift) as u64 * side as u64 + ((x - x0) >> shift) as u64;
        sample | lattice << 32
    };
    let roots = map
        .cell_triangles(x0, y0, s)
        .map(|t| [t.a, t.b, t.c].map(vert));
    let (mut tris, max_bound, bridging) = if map.nodata {
        walk::<true>(map, heights, roots, s, max_error, min_step)
    } else {
        walk::<false>(map, heights, roots, s, max_error, min_step)
    };
    // At most 1 + (T + B) / 2 vertices for T triangles tiling the cell (Euler for a disk:
    // V − E + T = 1 with 3T = 2E − B), B ≤ 4 (side − 1) of them on its border; no-data can leave
    // separate islands, up to 3 vertices a triangle. The numbering table takes 16-bit entries
    // when the numbers fit (half the memory: the 513² cell's table then stays in L2).
    let slots = side as usize * side as usize;
    let most = if map.nodata {
        3 * tris.len()
    } else {
        1 + (tris.len() + 4 * (side as usize - 1)) / 2
    };
    let order = if most < u16::MAX as usize {
        number::<u16>(&mut tris, slots, most)
    } else {
        number::<u32>(&mut tris, slots, most)
    };
    // Slot -> lattice row by a multiply: `⌊(M·v) / 2^64⌋` with `M = ⌊(2^64 − 1) / side⌋ + 1` is
    // `⌊v / side⌋` for every 32-bit `v` (Lemire, Kaser & Kurz 2019), without a division a vertex.
    let m = (u64::MAX / side as u64 + 1) as u128;
    let vertices = order
        .iter()
        .map(|&v| {
            let row = ((m * v as u128) >> 64) as u32;
            let col = v - row * side;
            [x0 + (col << shift), y0 + (row << shift)]
        })
        .collect();
    GridMesh {
        vertices,
        triangles: tris,
        max_bound,
        bridging,
    }
}

/// An entry of the numbering table: a vertex number + 1, 0 for a slot not met yet.
trait Entry: Copy + Default {
    fn get(self) -> u32;
    /// `v` fits (the caller sized the type to the most vertices).
    fn of(v: u32) -> Self;
}

impl Entry for u16 {
    #[inline(always)]
    fn get(self) -> u32 {
        self as u32
    }
    #[inline(always)]
    fn of(v: u32) -> u16 {
        v as u16
    }
}

impl Entry for u32 {
    #[inline(always)]
    fn get(self) -> u32 {
        self
    }
    #[inline(always)]
    fn of(v: u32) -> u32 {
        v
    }
}

/// Vertex numbers in first-use order for `tris` (lattice slots in, numbers out) over `slots`
/// lattice slots and at most `most` vertices; returns each number's slot. Branch-free per
/// vertex (whether a vertex is new depends on the terrain: a branch on it is mispredicted about
/// once a triangle): `index[slot]` is the vertex number + 1, 0 (a zeroed table, no fill) for a
/// slot not met yet, so `index[slot] − 1` wrapped and capped at the count is the vertex's number
/// either way; every corner's slot is written at the count, which advances only for a new one.
fn number<E: Entry>(tris: &mut [[u32; 3]], slots: usize, most: usize) -> Vec<u32> {
    let mut index = vec![E::default(); slots];
    let mut order = vec![0u32; slots.min(most) + 1];
    let mut count = 0u32;
    for t in tris.iter_mut() {
        for v in t.iter_mut() {
            let at = *v as usize;
            let id = index[at].get().wrapping_sub(1).min(count);
            index[at] = E::of(id + 1);
            order[count as usize] = *v;
            count += (id == count) as u32;
            *v = id;
        }
    }
    order.truncate(count as usize);
    order
}

/// The kept triangles (lattice slots, walk order) of the tree under the two `roots` (`s` their
/// legs), their largest finite bound and how many have an infinite one.
fn walk<const NODATA: bool>(
    map: &ErrorMap,
    heights: &[f32],
    roots: [[Vert; 3]; 2],
    s: u32,
    max_error: f32,
    min_step: u32,
) -> (Vec<[u32; 3]>, f32, u32) {
    let mut w = Walker::<NODATA> {
        errors: &map.errors,
        heights,
        max_error,
        min_step,
        tris: Vec::new(),
        len: 0,
        max_bound: 0.0,
        bridging: 0,
    };
    for [a, b, c] in roots {
        let e = if s > 1 { w.stored(a, b) } else { 0.0 };
        macro_rules! root {
            ($($k:literal)*) => {
                match s.trailing_zeros() {
                    $($k => w.square_call::<Legs<$k>>(a, b, c, e),)*
                    _ => unreachable!("cells are at most 2^15 samples"),
                }
            };
        }
        root!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15);
    }
    w.tris.truncate(w.len);
    (w.tris, w.max_bound, w.bridging)
}

/// Pad a `w x h` grid with no-data to the smallest `(2^k + 1)²` square holding it (borrowed
/// as is when it already is one: no copy of a large grid).
pub fn pad_to_rtin(heights: &[f32], w: u32, h: u32) -> (std::borrow::Cow<'_, [f32]>, u32) {
    let need = w.max(h).max(3) - 1;
    let n = need.next_power_of_two() + 1;
    if n == w && n == h {
        return (std::borrow::Cow::Borrowed(heights), n);
    }
    let mut out = vec![f32::NAN; n as usize * n as usize];
    for r in 0..h as usize {
        out[r * n as usize..r * n as usize + w as usize]
            .copy_from_slice(&heights[r * w as usize..(r + 1) * w as usize]);
    }
    (std::borrow::Cow::Owned(out), n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: u32, f: impl Fn(f64, f64) -> f64) -> Vec<f32> {
        (0..n * n)
            .map(|i| f((i % n) as f64, (i / n) as f64) as f32)
            .collect()
    }

    #[test]
    fn plane_is_two_triangles_and_exact() {
        let n = 65;
        let h = grid(n, |x, y| 3.0 * x - 2.0 * y + 10.0);
        let m = ErrorMap::new(&h, n);
        let mesh = extract(&m, &h, 0, 0, n - 1, 0.0, 1);
        assert_eq!(mesh.triangles.len(), 2);
        assert_eq!(mesh.vertices.len(), 4);
    }

    #[test]
    fn zero_error_keeps_every_cell_of_a_paraboloid() {
        // A paraboloid has no plane over more than one cell: at error 0 every cell is 2 triangles.
        let n = 17;
        let h = grid(n, |x, y| (x - 7.3).powi(2) + (y - 4.1).powi(2));
        let m = ErrorMap::new(&h, n);
        let mesh = extract(&m, &h, 0, 0, n - 1, 0.0, 1);
        assert_eq!(mesh.triangles.len(), 2 * 16 * 16);
        assert_eq!(mesh.vertices.len(), 17 * 17);
    }

    #[test]
    fn branch_free_mesher_matches_the_checking_one() {
        // Without no-data, the walk keeps the cells of two sample steps branch-free; forcing the
        // no-data path (the plain recursion down to single cells, a height check per kept
        // triangle, which never fires here) must give the same mesh, in the same order, for
        // whole grids and for chunks on a coarser lattice.
        let n = 129;
        let h = grid(n, |x, y| {
            (x * 0.21).sin() * 30.0 + (y * 0.17).cos() * 20.0 + ((x * 3.0 + y) % 5.0)
        });
        let dense = ErrorMap::new(&h, n);
        assert!(!dense.nodata);
        let mut checking = dense.clone();
        checking.nodata = true;
        for (x0, y0, s, step) in [
            (0, 0, 128, 1),
            (64, 0, 64, 1),
            (0, 64, 64, 4),
            (32, 32, 32, 2),
        ] {
            for e in [0.0f32, 0.5, 3.0, 20.0] {
                let a = extract(&dense, &h, x0, y0, s, e, step);
                let b = extract(&checking, &h, x0, y0, s, e, step);
                assert!(!a.triangles.is_empty());
                assert_eq!(a, b, "cell ({x0}, {y0}) side {s} step {step}, {e} m");
            }
        }
    }

    #[test]
    fn no_data_free_paths_match_the_counting_ones() {
        // On a grid without no-data the map skips all counting (vector loops over whole rows at
        // the finest level): every own error must equal the counting path's, bit for bit.
        let n = 65;
        let h = grid(n, |x, y| {
            (x * 0.37).sin() * 40.0 + (y * 0.23).cos() * 25.0 + ((x * y) % 7.0)
        });
        let nu = n as usize;
        for y in 0..n {
            let mut plain = vec![0.0f32; nu];
            let mut counted = vec![0.0f32; nu];
            own_row::<false>(&h, nu, n - 1, y, &mut plain);
            own_row::<true>(&h, nu, n - 1, y, &mut counted);
            let bits = |r: &[f32]| r.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&plain), bits(&counted), "row {y}");
        }
    }

    #[test]
    fn map_is_the_same_for_any_thread_count() {
        let n = 129;
        let mut h = grid(n, |x, y| (x * 0.11).sin() * 90.0 + (y * 0.07).cos() * 60.0);
        for i in (0..h.len()).step_by(97) {
            h[i] = f32::NAN;
        }
        let bits = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let m = pool.install(|| ErrorMap::new(&h, n));
            m.errors.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        };
        let one = bits(1);
        assert_eq!(one, bits(2));
        assert_eq!(one, bits(5));
    }

    #[test]
    fn bound_is_exact_on_a_single_bump() {
        // One raised centre sample on a 3x3 grid: the two top triangles err by exactly 5; the four
        // triangles around the centre represent it exactly.
        let mut h = vec![0.0f32; 9];
        h[4] = 5.0;
        let m = ErrorMap::new(&h, 3);
        assert_eq!(m.error_at(1, 1), 5.0);
        assert_eq!(extract(&m, &h, 0, 0, 2, 5.0, 1).triangles.len(), 2);
        assert_eq!(extract(&m, &h, 0, 0, 2, 4.99, 1).triangles.len(), 4);
    }
}
