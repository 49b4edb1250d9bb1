//! Bonds by distance: atoms `i` and `j` are bonded when
//! `0.4 Å < d(i, j) < r_i + r_j + 0.45 Å`, `r` being the covalent radius of Cordero et al.
//! (2008, [`crate::Element::covalent_radius`]) — the rule of Open Babel and Jmol (the 0.45 Å
//! tolerance; the 0.4 Å floor keeps overlapping atoms of a damaged frame from bonding), and the
//! one ASE's `natural_cutoffs` + `neighbor_list` gives with a skin of 0.225 Å per atom. Atoms of
//! unknown element bond to nothing.
//!
//! # Cost: a cell grid, linear in atoms
//! Atoms are binned (counting sort) into cells at least as wide as the largest cutoff, and each
//! atom looks only at the 27 cells around its own, so the work is proportional to the atoms
//! times the (bounded) density. Atoms are processed in index order in parallel chunks (rayon)
//! and each atom's bonds are sorted, so the output is the same for any thread count.
//!
//! # Periodic boxes: minimum image, never across the box
//! With a cell ([`UnitCell`]) the grid is laid out in fractional coordinates over the box and
//! wraps around; the distance of a pair is that of the nearest periodic image (fractional
//! differences rounded to the nearest integer). So a bond between an atom at one face and its
//! partner just across the opposite face (the same molecule, split by wrapping) is found and has
//! its true short length, while two atoms at opposite faces are never bonded through the box.
//! The rounding is the exact minimum image for orthorhombic boxes and for triclinic boxes whose
//! perpendicular widths exceed twice the cutoff by the skew (all MD boxes in practice); the grid
//! refuses to wrap a box narrower than that (it falls back to plain distances, noted in
//! [`Bonds::periodic`]).
//!
//! Rejected: a k-d tree (n log n and not simpler); all pairs (quadratic).

use rayon::prelude::*;

use crate::frame::{Frame, UnitCell};
use crate::style::atom_element;

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

/// Half of the 26 neighbour offsets (the other half reaches the same cell pairs from the other
/// side), so each pair of neighbouring cells is visited once.
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

/// Atoms sorted by cell (counting sort): positions (wrapped into the box when periodic), radii
/// and original indices contiguous per cell.
struct Grid {
    dims: [usize; 3],
    /// Cell `c` holds sorted atoms `start[c]..start[c + 1]`.
    start: Vec<u32>,
    pos: Vec<[f32; 3]>,
    rad: Vec<f32>,
    idx: Vec<u32>,
    /// The box edges (rows) for periodic images, `None` for an open grid.
    edges: Option<[[f32; 3]; 3]>,
}

impl Grid {
    fn build(
        cells: &[u32],
        pos: &[[f32; 3]],
        radii: &[f32],
        dims: [usize; 3],
        edges: Option<[[f32; 3]; 3]>,
    ) -> Grid {
        let n_cells = dims[0] * dims[1] * dims[2];
        let mut start = vec![0u32; n_cells + 1];
        for c in cells {
            start[*c as usize + 1] += 1;
        }
        for k in 0..n_cells {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let n = cells.len();
        let mut spos = vec![[0f32; 3]; n];
        let mut srad = vec![0f32; n];
        let mut sidx = vec![0u32; n];
        for (i, c) in cells.iter().enumerate() {
            let slot = &mut fill[*c as usize];
            let k = *slot as usize;
            spos[k] = pos[i];
            srad[k] = radii[i];
            sidx[k] = i as u32;
            *slot += 1;
        }
        Grid {
            dims,
            start,
            pos: spos,
            rad: srad,
            idx: sidx,
            edges,
        }
    }

    /// The bonds found from the cells of the z-slab `cz`, as original index pairs `[i < j]`.
    fn slab(&self, cz: usize, out: &mut Vec<[u32; 2]>) {
        let d = self.dims;
        let min2 = MIN_BOND_LENGTH * MIN_BOND_LENGTH;
        // Atoms `a` of `s..e` against atoms `b` of `s2..e2` (only `b > a` when `same`), the
        // second cell's atoms moved by `shift` (a periodic image).
        let mut pairs = |s: usize, e: usize, s2: usize, e2: usize, shift: [f32; 3], same: bool| {
            for a in s..e {
                let ra = self.rad[a];
                if ra <= 0.0 {
                    continue;
                }
                let p = self.pos[a];
                let p = [p[0] - shift[0], p[1] - shift[1], p[2] - shift[2]];
                let from = if same { a + 1 } else { s2 };
                let (qs, rs) = (&self.pos[from..e2], &self.rad[from..e2]);
                for (k, (q, &rb)) in qs.iter().zip(rs).enumerate() {
                    let v = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                    let d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                    let lim = ra + rb + BOND_TOLERANCE;
                    if d2 < lim * lim && d2 > min2 && rb > 0.0 {
                        let (i, j) = (self.idx[a], self.idx[from + k]);
                        out.push(if i < j { [i, j] } else { [j, i] });
                    }
                }
            }
        };
        let lin_offsets = HALF_SHELL.map(|o| (o[2] * d[1] as i64 + o[1]) * d[0] as i64 + o[0]);
        for cy in 0..d[1] {
            for cx in 0..d[0] {
                let c = (cz * d[1] + cy) * d[0] + cx;
                let (s, e) = (self.start[c] as usize, self.start[c + 1] as usize);
                if s == e {
                    continue;
                }
                pairs(s, e, s, e, [0.0; 3], true);
                // Interior cells: neighbours by linear offset, no wrapping.
                let interior = (1..d[0] - 1).contains(&cx)
                    && (1..d[1] - 1).contains(&cy)
                    && (1..d[2] - 1).contains(&cz);
                if interior {
                    for lin in &lin_offsets {
                        let cn = (c as i64 + lin) as usize;
                        let (s2, e2) = (self.start[cn] as usize, self.start[cn + 1] as usize);
                        pairs(s, e, s2, e2, [0.0; 3], false);
                    }
                    continue;
                }
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
                                Some(m) => {
                                    let w = ((q[k] - wrapped) / dk) as f32;
                                    for (t, sh) in shift.iter_mut().enumerate() {
                                        *sh += w * m[k][t];
                                    }
                                }
                                None => inside = false,
                            }
                        }
                        nb[k] = wrapped as usize;
                    }
                    if !inside {
                        continue;
                    }
                    let cn = (nb[2] * d[1] + nb[1]) * d[0] + nb[0];
                    let (s2, e2) = (self.start[cn] as usize, self.start[cn + 1] as usize);
                    pairs(s, e, s2, e2, shift, false);
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
    let max_r = radii.iter().copied().fold(0.0f32, f32::max);
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
            ((w / e).floor() as usize).max(by_cutoff.min(3)).min(1024)
        });
        // At least 3 cells per axis, so that the neighbours of a cell are distinct cells.
        if dims.iter().any(|d| *d < 3) {
            return None;
        }
        Some((c, inv, dims))
    });
    let grid = match periodic {
        Some((c, inv, dims)) => {
            let o = c.origin();
            let m = c.matrix();
            let (wrapped, cells): (Vec<[f32; 3]>, Vec<u32>) = positions
                .par_iter()
                .map(|p| {
                    let d = [p[0] as f64 - o[0], p[1] as f64 - o[1], p[2] as f64 - o[2]];
                    // Fractional f = d · M⁻¹ (rows of M are the edges), wrapped into [0, 1).
                    let f: [f64; 3] = std::array::from_fn(|k| {
                        let x = d[0] * inv[0][k] + d[1] * inv[1][k] + d[2] * inv[2][k];
                        x - x.floor()
                    });
                    let ci: [usize; 3] = std::array::from_fn(|k| {
                        ((f[k] * dims[k] as f64) as usize).min(dims[k] - 1)
                    });
                    let w: [f32; 3] = std::array::from_fn(|k| {
                        (o[k] + f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k]) as f32
                    });
                    (w, ((ci[2] * dims[1] + ci[1]) * dims[0] + ci[0]) as u32)
                })
                .unzip();
            let edges = m.map(|r| r.map(|v| v as f32));
            Grid::build(&cells, &wrapped, radii, dims, Some(edges))
        }
        None => {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in positions {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
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
            let cells: Vec<u32> = positions
                .par_iter()
                .map(|p| {
                    let ci: [usize; 3] = std::array::from_fn(|k| {
                        ((((p[k] - lo[k]) as f64) / width) as usize).min(dims[k] - 1)
                    });
                    ((ci[2] * dims[1] + ci[1]) * dims[0] + ci[0]) as u32
                })
                .collect();
            Grid::build(&cells, positions, radii, dims, None)
        }
    };
    let slabs: Vec<Vec<[u32; 2]>> = (0..grid.dims[2])
        .into_par_iter()
        .map(|cz| {
            let mut out = Vec::new();
            grid.slab(cz, &mut out);
            out
        })
        .collect();
    let mut pairs = slabs.concat();
    // The order of discovery depends on the grid, not on threads; sorting makes it canonical.
    pairs.par_sort_unstable();
    pairs.dedup();
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
mod tests {
    use super::*;

    #[test]
    fn inverse_times_matrix_is_identity() {
        let m = UnitCell::from_lengths_angles([10.0, 12.0, 15.0], [70.0, 80.0, 100.0])
            .unwrap()
            .matrix();
        let inv = invert(m).unwrap();
        for (r, row) in m.iter().enumerate() {
            for c in 0..3 {
                let v: f64 = row.iter().zip(&inv).map(|(a, b)| a * b[c]).sum();
                assert!((v - if r == c { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn water_across_the_box_bonds_by_minimum_image_only() {
        // O at x = 0.2, H at x = 9.4 in a 10 Å box: 0.8 Å apart through the face, 9.2 Å
        // directly; a second H in the middle, 4.8 Å from the O.
        let pos = [[0.2, 5.0, 5.0], [9.4, 5.0, 5.0], [5.0, 5.0, 5.0]];
        let r = [0.66, 0.31, 0.31];
        let cell = UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap();
        assert_eq!(bonds_with_radii(&pos, &r, Some(cell)).pairs, vec![[0, 1]]);
        assert!(bonds_with_radii(&pos, &r, None).pairs.is_empty());
    }
}
