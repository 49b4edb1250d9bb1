//! Bonds by distance: atoms `i` and `j` are bonded when
//! `0.4 Å < d(i, j) < r_i + r_j + 0.45 Å`, `r` being the covalent radius of Cordero et al.
//! (2008, [`crate::Element::covalent_radius`]) — the rule of Open Babel and Jmol (the 0.45 Å
//! tolerance; the 0.4 Å floor keeps overlapping atoms of a damaged frame from bonding), and the
//! one ASE's `natural_cutoffs` + `neighbor_list` gives with a skin of 0.225 Å per atom. Atoms of
//! unknown element (radius 0, negative or NaN) bond to nothing.
//!
//! The test is made in f32 on squared lengths: with `v` the displacement of the pair (see below
//! for periodic boxes), `d² = v.x·v.x + v.y·v.y + v.z·v.z` (in that order, no fused multiply-add),
//! bonded when `d² < (r_i + r_j + 0.45)²` and `d² > 0.4²`, both strict.
//!
//! # Cost: a cell grid, linear in atoms
//! Atoms are binned into cells at least as wide as the largest cutoff and large enough to hold
//! about three atoms on average, so each atom needs only the 27 cells around its own, and the
//! work is proportional to the atoms times the (bounded) density. Four phases, each parallel
//! (rayon) and each giving the same bytes for any thread count:
//!
//! 1. **Cells.** Each atom's cell, its position wrapped into the box (periodic only), and its
//!    *reach*: which faces of its cell are closer than its largest cutoff (its radius + the
//!    largest radius + 0.45 Å, plus a margin for the f32 rounding of positions), i.e. on which
//!    sides neighbour cells can hold a partner.
//! 2. **Counting sort by cell**, in two stable levels so that every task writes only its own
//!    part of the output: atoms are first partitioned into blocks of consecutive cells (per-chunk
//!    histograms, prefix sums in block-then-chunk order, each chunk scattering into its own
//!    disjoint pieces), then each block is sorted by cell on its own. The result is the unique
//!    stable order by cell, kept as a structure of arrays (x, y, z, radius, original index,
//!    reach) so that the pair loop reads contiguous f32 slices.
//! 3. **Pairs** over a half-shell stencil: a cell is paired with itself (`j` after `i` in the
//!    sorted order) and with 13 of its 26 neighbours; the other 13 reach the same cell pairs from
//!    the other side, so each pair of atoms is tested once. Cells are numbered x fastest, so for
//!    a cell whose neighbourhood neither wraps nor leaves the grid the 13 neighbours plus the rest
//!    of its own cell are 5 contiguous runs of sorted atoms: the rest of the own cell with the
//!    next cell in x, and 4 rows of three cells. Each atom tests only the runs its reach allows,
//!    trimmed to the cells in x it reaches, 4 atoms at a time with no branch
//!    (`lanes::hits`, SSE2, a bit mask of hits, the tail masked off); the hits are collected
//!    after. Cells at the faces of a periodic grid take each of their 13 neighbours separately
//!    with its periodic shift; at the faces of an open grid, neighbours outside it are skipped.
//!    Which atom of a pair is tested against which only changes the rounding of a periodic
//!    shift, so the pairing of cells is fixed (cell `c` against `c + offset`, offset from the
//!    half shell) and the reach only ever skips pairs that the test would reject.
//! 4. **Canonical order.** The pairs of each z-slab of cells are found independently, then
//!    partitioned by blocks of first atoms in the same two-level way, counting-sorted by first
//!    atom within each block and by second atom within each first: sorted, each pair once,
//!    `i < j`, whatever the thread count.
//!
//! On the 1,000,000-atom system of the `md_bonds` bench (`cargo bench --bench md_bonds`), the pair
//! tests take about 40% of the time, the cells and the sort together about as much, and the
//! canonical order the rest; a sizeable part of the cells and sort phases is the first touch
//! of freshly allocated pages.
//!
//! # Periodic boxes: minimum image, never across the box
//! With a cell ([`UnitCell`]) the grid is laid out in fractional coordinates over the box and
//! wraps around; positions are wrapped into the box (fractional coordinates in [0, 1), computed
//! in f64 and rounded once to f32), and the displacement of a pair is that to the nearest
//! periodic image: for a pair reached through the face of the grid, one atom is moved by
//! the box edges the face crosses: with `a` the atom of the cell whose stencil reaches across
//! the face and `b` its partner, `v = p_b − (p_a − shift)` (`shift` summed in f32); otherwise
//! `v = p_b − p_a`. So a bond between an atom at one face and its partner just across the
//! opposite face (the same molecule, split by wrapping) is found and has its true short length,
//! while two atoms at opposite faces are never bonded through the box. This is the exact
//! minimum image for orthorhombic boxes and for triclinic boxes whose perpendicular widths exceed
//! twice the cutoff by the skew (all MD boxes in practice); the grid refuses to wrap a box
//! narrower than 3 cutoffs in any direction (it falls back to plain distances, noted in
//! [`Bonds::periodic`]).
//!
//! Rejected: a k-d tree (n log n and not simpler); all pairs (quadratic); cells of the cutoff's
//! width whatever the density (for dilute atoms, most of the time goes to visiting empty cells);
//! a full 27-cell stencil with `i < j` filtering (twice the tests). Measured on the bench system
//! (process CPU time, one thread, periodic box): testing every neighbour run without the reach
//! (pair phase 56 ms instead of 36); recomputing the wrapped positions while sorting instead of
//! storing them (+8 ms); a global comparison sort of the pairs (+3 ms here, where they arrive
//! nearly sorted, and far slower when they do not).

use rayon::prelude::*;

use crate::frame::{Frame, UnitCell};
use crate::style::atom_element;

mod lanes;
use lanes::LANES;

/// The Open Babel / Jmol tolerance added to the sum of covalent radii (Å).
pub const BOND_TOLERANCE: f32 = 0.45;
/// Shorter than this (Å) is an overlap, not a bond.
pub const MIN_BOND_LENGTH: f32 = 0.4;

/// Bonds found by distance.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bonds {
    /// Pairs `[i, j]`, `i < j`, sorted, each once.
    pub pairs: Vec<[u32; 2]>,
    /// True when the minimum image was used (the frame had a cell wide enough).
    pub periodic: bool,
}

/// Per-atom cutoff radii (covalent radius of each atom's element; 0 for unknown).
fn radii(frame: &Frame) -> Vec<f32> {
    (0..frame.n_atoms())
        .map(|i| atom_element(frame, i).covalent_radius())
        .collect()
}

/// Bonds of `frame` by distance (see the module doc); `periodic` asks for the minimum image when
/// the frame has a cell.
pub fn bonds_by_distance(frame: &Frame, periodic: bool) -> Bonds {
    let r = radii(frame);
    bonds_with_radii(
        &frame.positions,
        &r,
        if periodic { frame.cell } else { None },
    )
}

/// Half of the 26 neighbour offsets `[dx, dy, dz]` (the other half reaches the same cell pairs
/// from the other side), so each pair of neighbouring cells is visited once. After `[1, 0, 0]`
/// come four rows of three cells `dx = -1, 0, 1`, each contiguous in the sorted atoms.
const HALF_SHELL: [[i64; 3]; 13] = [
    [1, 0, 0],
    [-1, 1, 0],
    [0, 1, 0],
    [1, 1, 0],
    [-1, -1, 1],
    [0, -1, 1],
    [1, -1, 1],
    [-1, 0, 1],
    [0, 0, 1],
    [1, 0, 1],
    [-1, 1, 1],
    [0, 1, 1],
    [1, 1, 1],
];

/// Reach bits of an atom: its cutoff sphere may cross the lower (`LO_*`) or upper (`HI_*`) face
/// of its cell along a grid axis, so the neighbours on that side need testing.
const LO_X: u8 = 1;
const HI_X: u8 = 2;
const LO_Y: u8 = 4;
const HI_Y: u8 = 8;
const LO_Z: u8 = 16;
const HI_Z: u8 = 32;

/// The reach bits a neighbour at cell offset `off` needs.
const fn needs(off: [i64; 3]) -> u8 {
    let mut bits = 0;
    let lo = [LO_X, LO_Y, LO_Z];
    let hi = [HI_X, HI_Y, HI_Z];
    let mut k = 0;
    while k < 3 {
        if off[k] < 0 {
            bits |= lo[k];
        } else if off[k] > 0 {
            bits |= hi[k];
        }
        k += 1;
    }
    bits
}

/// The cell `min(u as usize, dims - 1)` of grid coordinate `u` (NaN and negative give 0),
/// through an i64 conversion, which is cheaper than the usize one.
#[inline(always)]
fn cell_of(u: f64, dims: usize) -> usize {
    (u as i64).clamp(0, dims as i64 - 1) as usize
}

/// Reach bits of an atom at fraction `t[k]` (in [0, 1]) across its cell, whose faces are
/// `width[k]` apart, with cutoff `cut`: a face closer than `cut` is reachable. Conservative: a
/// NaN distance reaches everything.
fn reach_bits(t: [f64; 3], width: [f64; 3], cut: f64) -> u8 {
    let mut bits = 0;
    for k in 0..3 {
        let lo_far = t[k] * width[k] >= cut;
        let hi_far = (1.0 - t[k]) * width[k] >= cut;
        bits |= (!lo_far as u8 * [LO_X, LO_Y, LO_Z][k]) | (!hi_far as u8 * [HI_X, HI_Y, HI_Z][k]);
    }
    bits
}

/// Atoms per chunk of the first sorting level (fixed, so the work split is the same for any
/// thread count; the result does not depend on it anyway).
const SORT_CHUNK: usize = 1 << 15;

/// Atoms sorted by cell: positions (wrapped into the box when periodic), radii and original
/// indices as a structure of arrays, contiguous per cell.
struct Grid {
    dims: [usize; 3],
    /// Cell `c` holds sorted atoms `start[c]..start[c + 1]`.
    start: Vec<u32>,
    /// Coordinates and radii of the sorted atoms, followed by `LANES` padding entries so that
    /// the kernel can always load whole lanes. A radius that bonds nothing (zero, negative, NaN)
    /// is stored as NaN, which fails both comparisons of the test.
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    r: Vec<f32>,
    /// Original index of each sorted atom.
    idx: Vec<u32>,
    /// Reach bits of each sorted atom.
    reach: Vec<u8>,
    /// The box edges (rows) for periodic images, `None` for an open grid.
    edges: Option<[[f32; 3]; 3]>,
    /// The axes the grid wraps around (none for an open grid).
    periodic: [bool; 3],
}

/// The sorted-atom arrays of one block of cells, filled by one task.
struct BlockOut<'a> {
    start: &'a mut [u32],
    x: &'a mut [f32],
    y: &'a mut [f32],
    z: &'a mut [f32],
    r: &'a mut [f32],
    /// The block's atom indices in original order, replaced by them in sorted order.
    idx: &'a mut [u32],
    reach: &'a mut [u8],
}

/// Splits `a` into consecutive pieces of the given lengths.
fn split_lengths<'a, T>(mut a: &'a mut [T], lengths: &[usize]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(lengths.len());
    for &l in lengths {
        let (head, tail) = a.split_at_mut(l);
        out.push(head);
        a = tail;
    }
    out
}

/// A stable partition of the items of `chunks` (in chunk order) by `bucket` (< `n_buckets`)
/// into `out` (as long as all chunks together), writing `emit(chunk, position, item)`; returns
/// the bucket lengths. Each chunk is counted and scattered by one task, into its own disjoint
/// pieces of `out` (bucket-major, chunk-minor), so the result does not depend on threads.
fn partition<T: Sync, U: Send>(
    chunks: &[&[T]],
    n_buckets: usize,
    bucket: impl Fn(&T) -> usize + Sync,
    emit: impl Fn(usize, usize, &T) -> U + Sync,
    out: &mut [U],
) -> Vec<usize> {
    let counts: Vec<Vec<usize>> = chunks
        .par_iter()
        .map(|items| {
            let mut h = vec![0usize; n_buckets];
            for item in items.iter() {
                h[bucket(item)] += 1;
            }
            h
        })
        .collect();
    let lengths: Vec<usize> = (0..n_buckets)
        .flat_map(|b| counts.iter().map(move |h| h[b]))
        .collect();
    let mut per_chunk: Vec<Vec<&mut [U]>> = (0..chunks.len())
        .map(|_| Vec::with_capacity(n_buckets))
        .collect();
    for (k, piece) in split_lengths(out, &lengths).into_iter().enumerate() {
        per_chunk[k % chunks.len()].push(piece);
    }
    chunks
        .par_iter()
        .zip(per_chunk)
        .enumerate()
        .for_each(|(k, (items, mut pieces))| {
            let mut fill = vec![0usize; n_buckets];
            for (t, item) in items.iter().enumerate() {
                let b = bucket(item);
                pieces[b][fill[b]] = emit(k, t, item);
                fill[b] += 1;
            }
        });
    (0..n_buckets)
        .map(|b| counts.iter().map(|h| h[b]).sum())
        .collect()
}

/// The pairs of `parts` sorted, each once; `n` bounds the atom indices.
fn sort_pairs(parts: Vec<Vec<[u32; 2]>>, n: usize) -> Vec<[u32; 2]> {
    // Buckets of 2^shift consecutive first atoms, at most 1024 of them, each sorted alone.
    let shift = (usize::BITS - n.leading_zeros()).saturating_sub(10);
    let n_buckets = (n >> shift) + 1;
    let chunks: Vec<&[[u32; 2]]> = parts.iter().map(|p| p.as_slice()).collect();
    let total = chunks.iter().map(|c| c.len()).sum();
    let mut pairs = vec![[0u32; 2]; total];
    let lengths = partition(
        &chunks,
        n_buckets,
        |p| p[0] as usize >> shift,
        |_, _, p| *p,
        &mut pairs,
    );
    drop(parts);
    // Each bucket: a counting sort by first atom, then each atom's few partners sorted.
    split_lengths(&mut pairs, &lengths)
        .into_par_iter()
        .enumerate()
        .for_each(|(b, bucket)| {
            let first = b << shift;
            let mut start = vec![0u32; (1 << shift) + 1];
            for p in bucket.iter() {
                start[p[0] as usize - first + 1] += 1;
            }
            for k in 0..1 << shift {
                start[k + 1] += start[k];
            }
            let mut sorted = vec![[0u32; 2]; bucket.len()];
            let mut fill = start.clone();
            for p in bucket.iter() {
                let slot = &mut fill[p[0] as usize - first];
                sorted[*slot as usize] = *p;
                *slot += 1;
            }
            for w in start.windows(2) {
                // The partners of one atom: a handful, sorted by insertion.
                let run = &mut sorted[w[0] as usize..w[1] as usize];
                if run.len() > 16 {
                    run.sort_unstable();
                    continue;
                }
                for i in 1..run.len() {
                    let mut j = i;
                    while j > 0 && run[j - 1][1] > run[j][1] {
                        run.swap(j - 1, j);
                        j -= 1;
                    }
                }
            }
            bucket.copy_from_slice(&sorted);
        });
    pairs.dedup();
    pairs
}

impl Grid {
    /// Sorts the atoms by cell (`cells[i]` < `dims[0]·dims[1]·dims[2]`), a stable counting sort
    /// in two levels (module doc, phase 2).
    fn build(
        cells: &[u32],
        reach: &[u8],
        pos: &[[f32; 3]],
        radii: &[f32],
        dims: [usize; 3],
        edges: Option<[[f32; 3]; 3]>,
    ) -> Grid {
        let n = cells.len();
        let n_cells = dims[0] * dims[1] * dims[2];
        // Blocks of 2^shift consecutive cells, at most 1024 of them.
        let shift = (usize::BITS - n_cells.leading_zeros()).saturating_sub(10);
        let per_block = 1usize << shift;
        let n_blocks = n_cells.div_ceil(per_block);
        // Level 1: a stable partition of the atom indices by block.
        let chunks: Vec<&[u32]> = cells.chunks(SORT_CHUNK).collect();
        let mut order = vec![0u32; n];
        let block_len = partition(
            &chunks,
            n_blocks,
            |&c| c as usize >> shift,
            |k, t, _| (k * SORT_CHUNK + t) as u32,
            &mut order,
        );
        // Level 2: each block sorted by cell into its own part of the arrays.
        let padded = n + LANES;
        let (mut x, mut y, mut z) = (vec![0f32; padded], vec![0f32; padded], vec![0f32; padded]);
        let mut r = vec![f32::NAN; padded];
        let mut sreach = vec![0u8; n];
        let mut start = vec![0u32; n_cells + 1];
        let block_first: Vec<usize> = block_len
            .iter()
            .scan(0usize, |acc, &l| {
                let f = *acc;
                *acc += l;
                Some(f)
            })
            .collect();
        let outs: Vec<BlockOut> = split_lengths(&mut x[..n], &block_len)
            .into_iter()
            .zip(split_lengths(&mut y[..n], &block_len))
            .zip(split_lengths(&mut z[..n], &block_len))
            .zip(split_lengths(&mut r[..n], &block_len))
            .zip(split_lengths(&mut order, &block_len))
            .zip(split_lengths(&mut sreach, &block_len))
            .zip(start[..n_cells].chunks_mut(per_block))
            .map(|((((((x, y), z), r), idx), reach), start)| BlockOut {
                start,
                x,
                y,
                z,
                r,
                idx,
                reach,
            })
            .collect();
        outs.into_par_iter().enumerate().for_each(|(b, out)| {
            let ord = out.idx.to_vec();
            let local = per_block - 1;
            let mut fill = vec![0u32; out.start.len()];
            for &i in ord.iter() {
                fill[cells[i as usize] as usize & local] += 1;
            }
            let mut acc = block_first[b] as u32;
            for (f, st) in fill.iter_mut().zip(out.start.iter_mut()) {
                *st = acc;
                let c = *f;
                *f = acc - block_first[b] as u32;
                acc += c;
            }
            for &i in ord.iter() {
                let i = i as usize;
                let slot = &mut fill[cells[i] as usize & local];
                let k = *slot as usize;
                *slot += 1;
                let p = pos[i];
                out.x[k] = p[0];
                out.y[k] = p[1];
                out.z[k] = p[2];
                let ri = radii[i];
                out.r[k] = if ri > 0.0 { ri } else { f32::NAN };
                out.idx[k] = i as u32;
                out.reach[k] = reach[i];
            }
        });
        start[n_cells] = n as u32;
        Grid {
            dims,
            start,
            x,
            y,
            z,
            r,
            idx: order,
            reach: sreach,
            periodic: [edges.is_some(); 3],
            edges,
        }
    }

    /// Tests sorted atom `a` (at `p`, already moved by the periodic shift of the run, radius
    /// `ra`) against sorted atoms `lo..hi`, pushing each bond as `[i, j]` (original indices,
    /// `i < j`).
    #[inline(always)]
    fn scan(&self, a: usize, p: [f32; 3], ra: f32, lo: usize, hi: usize, out: &mut Vec<[u32; 2]>) {
        let ia = self.idx[a];
        let mut k = lo;
        while k < hi {
            // The padding after the last atom keeps `k..k + LANES` in bounds.
            let lane = |v: &[f32]| -> [f32; LANES] { v[k..k + LANES].try_into().unwrap() };
            let mut mask = lanes::hits(
                p,
                ra,
                &lane(&self.x),
                &lane(&self.y),
                &lane(&self.z),
                &lane(&self.r),
            );
            let left = hi - k;
            if left < LANES {
                mask &= (1u32 << left) - 1;
            }
            while mask != 0 {
                let l = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let ib = self.idx[k + l];
                let (i, j) = if ia < ib { (ia, ib) } else { (ib, ia) };
                out.push([i, j]);
            }
            k += LANES;
        }
    }

    /// The bonds found from the cells of the z-slab `cz` (module doc, phase 3).
    fn slab(&self, cz: usize, out: &mut Vec<[u32; 2]>) {
        let d = self.dims;
        let (d0, d01) = (d[0], d[0] * d[1]);
        let st = |c: usize| self.start[c] as usize;
        // The rows of the inner stencil: (dy, dz) = (1, 0), (-1, 1), (0, 1), (1, 1).
        let row_needs = [
            needs([0, 1, 0]),
            needs([0, -1, 1]),
            needs([0, 0, 1]),
            needs([0, 1, 1]),
        ];
        // (first, end, shift, reach bits needed) of the neighbours of a face cell.
        let mut runs: Vec<(usize, usize, [f32; 3], u8)> = Vec::with_capacity(HALF_SHELL.len());
        for cy in 0..d[1] {
            for cx in 0..d[0] {
                let c = cz * d01 + cy * d0 + cx;
                let (s, e) = (st(c), st(c + 1));
                if s == e {
                    continue;
                }
                let inner = cx >= 1 && cx + 1 < d[0] && cy >= 1 && cy + 1 < d[1] && cz + 1 < d[2];
                if inner {
                    // Rest of the own cell, then [1, 0, 0] up to `c + 2`; each row from its
                    // cell dx = -1 or 0 to its cell dx = 0 or 1 after the end, by reach.
                    let next_end = st(c + 2);
                    let rows = [c + d0, c + d01 - d0, c + d01, c + d01 + d0]
                        .map(|r| [st(r - 1), st(r), st(r + 1), st(r + 2)]);
                    for a in s..e {
                        let ra = self.r[a];
                        if ra.is_nan() {
                            continue;
                        }
                        let m = self.reach[a];
                        let (lo_x, hi_x) = (m & LO_X != 0, m & HI_X != 0);
                        let p = [self.x[a], self.y[a], self.z[a]];
                        self.scan(a, p, ra, a + 1, if hi_x { next_end } else { e }, out);
                        for (row, need) in rows.iter().zip(row_needs) {
                            if m & need == need {
                                let lo = if lo_x { row[0] } else { row[1] };
                                let hi = if hi_x { row[3] } else { row[2] };
                                self.scan(a, p, ra, lo, hi, out);
                            }
                        }
                    }
                    continue;
                }
                runs.clear();
                for off in HALF_SHELL {
                    let q = [cx as i64 + off[0], cy as i64 + off[1], cz as i64 + off[2]];
                    let mut nb = [0usize; 3];
                    let mut shift = [0f32; 3];
                    let mut inside = true;
                    for k in 0..3 {
                        let dk = d[k] as i64;
                        let wrapped = q[k].rem_euclid(dk);
                        if wrapped != q[k] {
                            match &self.edges {
                                Some(m) if self.periodic[k] => {
                                    let w = ((q[k] - wrapped) / dk) as f32;
                                    for (t, sh) in shift.iter_mut().enumerate() {
                                        *sh += w * m[k][t];
                                    }
                                }
                                _ => inside = false,
                            }
                        }
                        nb[k] = wrapped as usize;
                    }
                    if inside {
                        let cn = nb[2] * d01 + nb[1] * d0 + nb[0];
                        runs.push((st(cn), st(cn + 1), shift, needs(off)));
                    }
                }
                for a in s..e {
                    let ra = self.r[a];
                    if ra.is_nan() {
                        continue;
                    }
                    let m = self.reach[a];
                    let p = [self.x[a], self.y[a], self.z[a]];
                    self.scan(a, p, ra, a + 1, e, out);
                    for &(lo, hi, sh, need) in &runs {
                        if m & need == need {
                            let ps = [p[0] - sh[0], p[1] - sh[1], p[2] - sh[2]];
                            self.scan(a, ps, ra, lo, hi, out);
                        }
                    }
                }
            }
        }
    }
}

/// Bonds for positions with per-atom covalent radii (0 = bonds to nothing), under the minimum
/// image of `cell` when given.
///
/// ```
/// use texmap_md_io::{Element, UnitCell, bonds::bonds_with_radii};
/// let (o, h) = (Element::from_symbol("O").unwrap(), Element::from_symbol("H").unwrap());
/// let r = [o.covalent_radius(), h.covalent_radius(), h.covalent_radius()];
/// // A water split by the face x = 0 of a 10 Å box: bonded through the face only.
/// let pos = [[0.2, 5.0, 5.0], [9.44, 5.0, 5.0], [0.44, 5.93, 5.0]];
/// let cell = UnitCell::orthorhombic(10.0, 10.0, 10.0)?;
/// assert_eq!(bonds_with_radii(&pos, &r, Some(cell)).pairs, [[0, 1], [0, 2]]);
/// assert_eq!(bonds_with_radii(&pos, &r, None).pairs, [[0, 2]]);
/// # Ok::<(), texmap_md_io::Error>(())
/// ```
pub fn bonds_with_radii(positions: &[[f32; 3]], radii: &[f32], cell: Option<UnitCell>) -> Bonds {
    let n = positions.len().min(radii.len());
    let (positions, radii) = (&positions[..n], &radii[..n]);
    // The largest radius, NaN ignored (exact, so any split gives the same value).
    let max_r = radii
        .par_chunks(SORT_CHUNK)
        .map(|rs| {
            let mut m = [0f32; 8];
            for c in rs.chunks(8) {
                for (m, &r) in m.iter_mut().zip(c) {
                    *m = if r > *m { r } else { *m };
                }
            }
            m.into_iter().fold(0.0f32, f32::max)
        })
        .reduce(|| 0.0, f32::max);
    if n < 2 || max_r <= 0.0 {
        return Bonds::default();
    }
    let cutoff = (2.0 * max_r + BOND_TOLERANCE) as f64;
    // Cells at least `cutoff` wide, and large enough to hold ~3 atoms on average (fewer, and
    // visiting empty cells costs more than the pairs).
    let edge = |volume: f64| cutoff.max((3.0 * volume / n as f64).cbrt());
    let periodic = cell.and_then(|c| {
        let m = c.matrix();
        let inv = invert(m)?;
        let vol = c.volume();
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let widths = [
            vol / norm(cross(m[1], m[2])),
            vol / norm(cross(m[2], m[0])),
            vol / norm(cross(m[0], m[1])),
        ];
        let e = edge(vol);
        // The density's edge, but never fewer than 3 cells where the cutoff allows 3.
        let dims = widths.map(|w| {
            let by_cutoff = (w / cutoff).floor() as usize;
            ((w / e).floor() as usize)
                .max(by_cutoff.min(3))
                .clamp(1, 1024)
        });
        // At least 3 cells along each periodic axis, so that the neighbours of a cell are
        // distinct cells.
        if dims.iter().zip(c.periodic()).any(|(d, p)| p && *d < 3) {
            return None;
        }
        Some((c, inv, dims, widths))
    });
    // The reach of an atom of radius `ra`: the largest cutoff it has with any atom, plus a
    // margin that covers the f32 rounding of positions up to `size` Å from the origin (so that
    // reach bits only ever skip pairs that the f32 test rejects).
    let reach_cut = |ra: f32, size: f64| {
        let margin = 1e-3 + size * (1.0 / 65536.0);
        if size.is_finite() {
            ra as f64 + max_r as f64 + BOND_TOLERANCE as f64 + margin
        } else {
            f64::INFINITY
        }
    };
    let grid = match periodic {
        Some((c, inv, dims, widths)) => {
            let o = c.origin();
            let m = c.matrix();
            let periodic = c.periodic();
            let size = o.iter().map(|v| v.abs()).fold(0.0, f64::max)
                + m.iter().flatten().map(|v| v.abs()).sum::<f64>();
            let cell_width: [f64; 3] = std::array::from_fn(|k| widths[k] / dims[k] as f64);
            type CellsReach = (Vec<u32>, Vec<u8>);
            let (wrapped, (cells, reach)): (Vec<[f32; 3]>, CellsReach) = positions
                .par_iter()
                .zip(radii)
                .map(|(p, &ra)| {
                    let d = [p[0] as f64 - o[0], p[1] as f64 - o[1], p[2] as f64 - o[2]];
                    // Fractional f = d · M⁻¹ (rows of M are the edges), wrapped into [0, 1)
                    // along the periodic axes (along the others, outside the box is in the
                    // edge cells, at least as far as their atoms).
                    let f: [f64; 3] = std::array::from_fn(|k| {
                        let x = d[0] * inv[0][k] + d[1] * inv[1][k] + d[2] * inv[2][k];
                        if periodic[k] { x - x.floor() } else { x }
                    });
                    let ci: [usize; 3] =
                        std::array::from_fn(|k| cell_of(f[k] * dims[k] as f64, dims[k]));
                    let w: [f32; 3] = std::array::from_fn(|k| {
                        (o[k] + f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k]) as f32
                    });
                    let t = std::array::from_fn(|k| f[k] * dims[k] as f64 - ci[k] as u32 as f64);
                    let c = ((ci[2] * dims[1] + ci[1]) * dims[0] + ci[0]) as u32;
                    (w, (c, reach_bits(t, cell_width, reach_cut(ra, size))))
                })
                .unzip();
            let edges = m.map(|r| r.map(|v| v as f32));
            let mut grid = Grid::build(&cells, &reach, &wrapped, radii, dims, Some(edges));
            grid.periodic = periodic;
            grid
        }
        None => {
            // The bounding box (min and max are exact, so any split gives the same box).
            let (lo, hi) = positions
                .par_chunks(SORT_CHUNK)
                .map(|ps| {
                    // Four independent running boxes (NaN ignored), then merged.
                    let mut lo = [[f32::INFINITY; 3]; 4];
                    let mut hi = [[f32::NEG_INFINITY; 3]; 4];
                    for c in ps.chunks(4) {
                        for (l, p) in c.iter().enumerate() {
                            for k in 0..3 {
                                lo[l][k] = if p[k] < lo[l][k] { p[k] } else { lo[l][k] };
                                hi[l][k] = if p[k] > hi[l][k] { p[k] } else { hi[l][k] };
                            }
                        }
                    }
                    let lo = lo
                        .into_iter()
                        .reduce(|a, b| std::array::from_fn(|k| a[k].min(b[k])));
                    let hi = hi
                        .into_iter()
                        .reduce(|a, b| std::array::from_fn(|k| a[k].max(b[k])));
                    (lo.unwrap(), hi.unwrap())
                })
                .reduce(
                    || ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
                    |a, b| {
                        (
                            std::array::from_fn(|k| a.0[k].min(b.0[k])),
                            std::array::from_fn(|k| a.1[k].max(b.1[k])),
                        )
                    },
                );
            let ext: [f64; 3] = std::array::from_fn(|k| (hi[k] - lo[k]) as f64);
            let mut width = edge(ext.iter().map(|e| e.max(cutoff)).product());
            // Never more than 2^24 cells (a far outlier makes the box huge and mostly empty).
            while ext
                .iter()
                .map(|e| (e / width).floor() + 1.0)
                .product::<f64>()
                > 16_777_216.0
            {
                width *= 1.26;
            }
            let dims: [usize; 3] = std::array::from_fn(|k| (ext[k] / width).floor() as usize + 1);
            let size = (0..3)
                .map(|k| (lo[k] as f64).abs().max((hi[k] as f64).abs()))
                .fold(0.0, f64::max);
            let (cells, reach): (Vec<u32>, Vec<u8>) = positions
                .par_iter()
                .zip(radii)
                .map(|(p, &ra)| {
                    let u: [f64; 3] = std::array::from_fn(|k| ((p[k] - lo[k]) as f64) / width);
                    let ci: [usize; 3] = std::array::from_fn(|k| cell_of(u[k], dims[k]));
                    let t = std::array::from_fn(|k| u[k] - ci[k] as u32 as f64);
                    let c = ((ci[2] * dims[1] + ci[1]) * dims[0] + ci[0]) as u32;
                    (c, reach_bits(t, [width; 3], reach_cut(ra, size)))
                })
                .unzip();
            Grid::build(&cells, &reach, positions, radii, dims, None)
        }
    };
    let slabs: Vec<Vec<[u32; 2]>> = (0..grid.dims[2])
        .into_par_iter()
        .map(|cz| {
            let d01 = grid.dims[0] * grid.dims[1];
            let atoms = grid.start[(cz + 1) * d01] - grid.start[cz * d01];
            let mut out = Vec::with_capacity(atoms as usize);
            grid.slab(cz, &mut out);
            out
        })
        .collect();
    // The order of discovery depends on the grid, not on threads; sorting makes it canonical.
    let pairs = sort_pairs(slabs, n);
    Bonds {
        pairs,
        periodic: grid.edges.is_some(),
    }
}

/// The inverse of a 3×3 matrix, `None` when singular.
fn invert(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if det.abs() < 1e-300 || !det.is_finite() {
        return None;
    }
    let c =
        |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    Some([
        [
            c(1, 1, 2, 2) / det,
            -c(0, 1, 2, 2) / det,
            c(0, 1, 1, 2) / det,
        ],
        [
            -c(1, 0, 2, 2) / det,
            c(0, 0, 2, 2) / det,
            -c(0, 0, 1, 2) / det,
        ],
        [
            c(1, 0, 2, 1) / det,
            -c(0, 0, 2, 1) / det,
            c(0, 0, 1, 1) / det,
        ],
    ])
}

#[cfg(test)]
mod tests;
