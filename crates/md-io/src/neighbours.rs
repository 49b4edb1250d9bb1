//! The k nearest neighbours of each atom, from a cell grid: what [`crate::cna`] and
//! [`crate::centrosymmetry`] examine around every atom; and the atom nearest to any point, the
//! site [`crate::wigner_seitz`] assigns an atom to.
//!
//! The grid has fractional cells in a periodic cell (about [`ATOMS_PER_CELL`] atoms each) and
//! cells over the bounding box otherwise. A query grows rings of cells around the atom until the
//! k nearest found are closer than the ring's inner width, or the ring covers the grid. In a
//! periodic cell each neighbour is taken at its nearest image by rounding fractional
//! differences, which finds it whenever it is closer than half the cell's width (farther, in a
//! skewed cell, only [`crate::pbc::minimum_image`]'s search does), so the cell must be wider
//! than twice the k-th neighbour distance for the answer to be the true k nearest.

use glam::{DMat3, DVec3};

use crate::frame::UnitCell;

/// Atoms per grid cell on average: cells about as wide as the 14th neighbour distance of FCC
/// (1.04 a) and BCC (1.31 a), so one ring of cells usually holds the neighbours.
pub(crate) const ATOMS_PER_CELL: f64 = 4.5;

/// One worker's buffers for [`Grid::nearest`].
#[derive(Default)]
pub(crate) struct Scratch {
    cells: Vec<usize>,
    found: Vec<([f64; 3], f64, u32)>,
    /// The nearest neighbours found: vector from the atom, distance; closest first.
    pub(crate) near: Vec<([f64; 3], f64)>,
    /// Their atom indices, in the same order.
    pub(crate) index: Vec<u32>,
}

/// A cell grid over the atoms (fractional cells in a periodic cell, the bounding box
/// otherwise) for nearest-neighbour queries.
pub(crate) struct Grid<'a> {
    positions: &'a [[f32; 3]],
    cell: Option<&'a UnitCell>,
    /// Grid size per axis, and each atom's cell (`usize::MAX`: non-finite atom).
    dims: [usize; 3],
    /// Atoms sorted by cell, and where each cell's atoms start (`starts[c]..starts[c + 1]`).
    order: Vec<u32>,
    starts: Vec<u32>,
    /// Cell index per atom.
    of: Vec<usize>,
    /// The smallest width of a grid cell (Å) along an axis of more than one cell: a ring of k
    /// cells around an atom holds every atom within k times this (an axis of one cell is
    /// covered whole by every ring).
    width: f64,
    /// Bounding-box origin and inverse cell size per axis (open frames).
    lo: [f64; 3],
    inv: [f64; 3],
    /// The cell's edges as columns (periodic frames: Cartesian = edges · fractional), and each
    /// atom's wrapped fractional coordinates.
    edges: DMat3,
    /// Fractional = inverse · Cartesian (periodic frames).
    inverse: DMat3,
    frac: Vec<DVec3>,
    /// Per axis: the cell repeats along it (none without a cell).
    periodic: [bool; 3],
    /// 1 along the periodic axes, 0 along the others: what whole edges are taken off.
    wrap: DVec3,
}

impl<'a> Grid<'a> {
    pub(crate) fn new(positions: &'a [[f32; 3]], cell: Option<&'a UnitCell>) -> Grid<'a> {
        let finite: Vec<usize> = (0..positions.len())
            .filter(|&i| positions[i].iter().all(|v| v.is_finite()))
            .collect();
        let n = finite.len().max(1) as f64;
        let mut grid = Grid {
            positions,
            cell,
            dims: [1; 3],
            order: Vec::new(),
            starts: Vec::new(),
            of: vec![usize::MAX; positions.len()],
            width: f64::INFINITY,
            lo: [0.0; 3],
            inv: [0.0; 3],
            edges: DMat3::IDENTITY,
            inverse: DMat3::IDENTITY,
            frac: Vec::new(),
            periodic: [false; 3],
            wrap: DVec3::ZERO,
        };
        match cell {
            Some(c) => {
                // UnitCell::matrix has the edges as rows.
                let edges = DMat3::from_cols_array_2d(&c.matrix());
                let inverse = edges.inverse();
                grid.edges = edges;
                grid.inverse = inverse;
                grid.periodic = c.periodic();
                grid.wrap = DVec3::from(c.periodic().map(|p| if p { 1.0 } else { 0.0 }));
                // Wrapped along the periodic axes; along the others an atom outside the cell
                // falls in the edge cells (at least as far as those cells' atoms).
                let wrap = grid.wrap;
                grid.frac = positions
                    .iter()
                    .map(|p| {
                        let f = inverse * DVec3::from(p.map(f64::from));
                        f - f.floor() * wrap
                    })
                    .collect();
                let volume = edges.determinant().abs();
                // Perpendicular widths of the cell; about 4.5 atoms per grid cell, so that the
                // first ring of cells holds the 14 nearest neighbours of a crystal atom.
                let target = (ATOMS_PER_CELL * volume / n).cbrt();
                for a in 0..3 {
                    let (b, d) = ((a + 1) % 3, (a + 2) % 3);
                    let area = edges.col(b).cross(edges.col(d)).length();
                    let w = volume / area.max(f64::MIN_POSITIVE);
                    grid.dims[a] = ((w / target).floor() as usize).clamp(1, 1024);
                    if grid.dims[a] > 1 {
                        grid.width = grid.width.min(w / grid.dims[a] as f64);
                    }
                }
            }
            None => {
                // The box of the 0.5th to 99.5th percentile per axis: a few atoms far away (an
                // evaporated atom) do not stretch the grid; they are kept in the edge cells,
                // which leaves every ring's guarantee intact (they are at least as far as
                // those cells).
                let mut lo = [0.0; 3];
                let mut hi = [0.0; 3];
                let mut values: Vec<f64> = Vec::with_capacity(finite.len());
                for a in 0..3 {
                    values.clear();
                    values.extend(finite.iter().map(|&i| positions[i][a] as f64));
                    if values.is_empty() {
                        continue;
                    }
                    let last = values.len() - 1;
                    let (k_lo, k_hi) = (last / 200, last - last / 200);
                    lo[a] = *values.select_nth_unstable_by(k_lo, f64::total_cmp).1;
                    hi[a] = *values.select_nth_unstable_by(k_hi, f64::total_cmp).1;
                }
                let extent = [0, 1, 2].map(|a| (hi[a] - lo[a]).max(1e-3));
                // ATOMS_PER_CELL per cell: the cell size s solves s³ = A Π max(extent, s) / n,
                // so that a flat or thin system gets few cells across its thin side rather
                // than cells far smaller than its atoms' spacing.
                let mut target = (ATOMS_PER_CELL * extent.iter().product::<f64>() / n)
                    .cbrt()
                    .max(1e-3);
                for _ in 0..60 {
                    let v: f64 = extent.iter().map(|e| e.max(target)).product();
                    target = (ATOMS_PER_CELL * v / n).cbrt().max(1e-3);
                }
                for (a, e) in extent.into_iter().enumerate() {
                    grid.dims[a] = ((e / target).ceil() as usize).clamp(1, 1024);
                    let size = e / grid.dims[a] as f64;
                    grid.inv[a] = 1.0 / size;
                    if grid.dims[a] > 1 {
                        grid.width = grid.width.min(size);
                    }
                }
                grid.lo = lo;
            }
        }
        let total = grid.dims.iter().product::<usize>();
        let mut count = vec![0u32; total + 1];
        for &i in &finite {
            let c = grid.cell_of(i);
            grid.of[i] = c;
            count[c + 1] += 1;
        }
        for c in 0..total {
            count[c + 1] += count[c];
        }
        let mut next = count.clone();
        grid.order = vec![0; finite.len()];
        for &i in &finite {
            let c = grid.of[i];
            grid.order[next[c] as usize] = i as u32;
            next[c] += 1;
        }
        grid.starts = count;
        grid
    }

    /// The grid coordinates of atom `i`.
    fn coords(&self, i: usize) -> [usize; 3] {
        match self.cell {
            Some(_) => self.coords_of(self.frac[i].to_array()),
            None => self.coords_of(self.positions[i].map(f64::from)),
        }
    }

    /// The grid coordinates of a point: wrapped fractional coordinates in a periodic cell,
    /// Cartesian ones otherwise (outside the grid: its edge cells).
    fn coords_of(&self, q: [f64; 3]) -> [usize; 3] {
        match self.cell {
            Some(_) => [0, 1, 2]
                .map(|a| ((q[a] * self.dims[a] as f64).max(0.0) as usize).min(self.dims[a] - 1)),
            None => [0, 1, 2].map(|a| {
                (((q[a] - self.lo[a]) * self.inv[a]).max(0.0) as usize).min(self.dims[a] - 1)
            }),
        }
    }

    /// Every cell within `ring` of `centre` (wrapped in a periodic cell), once, into `cells`.
    fn ring_cells(&self, centre: [usize; 3], ring: usize, cells: &mut Vec<usize>) {
        cells.clear();
        let span = [0, 1, 2].map(|a| self.offsets(centre[a], a, ring));
        for dz in span[2].clone() {
            for dy in span[1].clone() {
                for dx in span[0].clone() {
                    if let Some(c) = self.offset_cell(centre, [dx, dy, dz]) {
                        cells.push(c);
                    }
                }
            }
        }
        cells.sort_unstable();
        cells.dedup();
    }

    /// The atom nearest to the point `p` (Å; at its nearest image in a periodic cell) and its
    /// distance; equal distances go to the lower index. `None` for a non-finite point or an
    /// empty grid.
    pub(crate) fn nearest_to(&self, p: [f64; 3], cells: &mut Vec<usize>) -> Option<(usize, f64)> {
        if !p.iter().all(|v| v.is_finite()) || self.order.is_empty() {
            return None;
        }
        let q = match self.cell {
            Some(_) => {
                let f = self.inverse * DVec3::from(p);
                (f - f.floor() * self.wrap).to_array()
            }
            None => p,
        };
        let centre = self.coords_of(q);
        let max_ring = self.dims.iter().max().copied().unwrap_or(1);
        let mut best: Option<(usize, f64)> = None;
        for ring in 1..=max_ring.max(1) {
            self.ring_cells(centre, ring, cells);
            for &c in cells.iter() {
                for &j in &self.order[self.starts[c] as usize..self.starts[c + 1] as usize] {
                    let j = j as usize;
                    let v = match self.cell {
                        Some(_) => {
                            let d = self.frac[j] - DVec3::from(q);
                            (self.edges * (d - round(d) * self.wrap)).to_array()
                        }
                        None => [0, 1, 2].map(|a| self.positions[j][a] as f64 - p[a]),
                    };
                    let d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
                    if best.is_none_or(|(b, bd)| d2 < bd || (d2 == bd && j < b)) {
                        best = Some((j, d2));
                    }
                }
            }
            let whole = self.covers(centre, ring);
            let reach = ring as f64 * self.width;
            if whole || best.is_some_and(|(_, d2)| d2 <= reach * reach) {
                break;
            }
        }
        best.map(|(j, d2)| (j, d2.sqrt()))
    }

    fn cell_of(&self, i: usize) -> usize {
        let [x, y, z] = self.coords(i);
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// The vector from atom `i` to atom `j` (nearest image in a periodic cell).
    fn vector(&self, i: usize, j: usize) -> [f64; 3] {
        match self.cell {
            Some(_) => {
                // The fractional difference rounded to the nearest image (exact within half
                // the cell's width), from the fractional coordinates kept.
                let d = self.frac[j] - self.frac[i];
                (self.edges * (d - round(d) * self.wrap)).to_array()
            }
            None => [0, 1, 2].map(|a| self.positions[j][a] as f64 - self.positions[i][a] as f64),
        }
    }

    /// Atom `i`'s `k` nearest neighbours (vector, distance), closest first, into
    /// `scratch.near` (fewer when the frame has fewer other atoms; none for a non-finite atom).
    pub(crate) fn nearest(&self, i: usize, k: usize, scratch: &mut Scratch) {
        let Scratch {
            cells,
            found,
            near,
            index,
        } = scratch;
        near.clear();
        index.clear();
        if k == 0 || self.of[i] == usize::MAX {
            return;
        }
        let centre = self.coords(i);
        let max_ring = self.dims.iter().max().copied().unwrap_or(1);
        for ring in 1..=max_ring.max(1) {
            self.ring_cells(centre, ring, cells);
            found.clear();
            for &c in cells.iter() {
                for &j in &self.order[self.starts[c] as usize..self.starts[c + 1] as usize] {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    let v = self.vector(i, j);
                    // Squared for now; the distances kept are rooted at the end.
                    found.push((v, v[0] * v[0] + v[1] * v[1] + v[2] * v[2], j as u32));
                }
            }
            // The nearest k, in order (ties by atom order of the scan).
            if found.len() > k {
                found.select_nth_unstable_by(k - 1, |a, b| a.1.total_cmp(&b.1));
                found.truncate(k);
            }
            found.sort_by(|a, b| a.1.total_cmp(&b.1));
            // The ring holds every atom within `ring` cell widths: enough when the
            // neighbours needed are that close, or when the ring covers the whole grid.
            let whole = self.covers(centre, ring);
            let reach = ring as f64 * self.width;
            let enough = found.len() >= k && found[k - 1].1 <= reach * reach;
            if enough || whole {
                break;
            }
        }
        near.extend(found.iter().map(|&(v, d2, _)| (v, d2.sqrt())));
        index.extend(found.iter().map(|f| f.2));
    }

    /// True when the cells within `ring` of `centre` are the whole grid: around a periodic
    /// axis, 2·ring + 1 cells; along an open one, every cell on both sides.
    fn covers(&self, centre: [usize; 3], ring: usize) -> bool {
        (0..3).all(|a| {
            let n = self.dims[a];
            if self.periodic[a] {
                2 * ring + 1 >= n
            } else {
                ring >= centre[a].max(n - 1 - centre[a])
            }
        })
    }

    /// The offsets along axis `a` from grid coordinate `at` within `ring` cells: inside the grid
    /// along an open axis, and at most once around a periodic one.
    fn offsets(&self, at: usize, a: usize, ring: usize) -> std::ops::RangeInclusive<isize> {
        let (n, at, r) = (self.dims[a] as isize, at as isize, ring as isize);
        match self.periodic[a] {
            true if 2 * r + 1 >= n => 0..=n - 1,
            true => -r..=r,
            false => (-r).max(-at)..=r.min(n - 1 - at),
        }
    }

    /// The cell at `offset` from `centre`: wrapped around the periodic axes, `None` outside the
    /// grid along an open one.
    fn offset_cell(&self, centre: [usize; 3], offset: [isize; 3]) -> Option<usize> {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let n = self.dims[a] as isize;
            let v = centre[a] as isize + offset[a];
            c[a] = match self.periodic[a] {
                true => v.rem_euclid(n) as usize,
                false if (0..n).contains(&v) => v as usize,
                false => return None,
            };
        }
        Some((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0])
    }
}

/// Each component rounded to the nearest integer (ties to even) without a libm call: adding and
/// subtracting 1.5 · 2⁵² leaves no fractional bits (fractional coordinate differences are far
/// below 2⁵¹).
fn round(d: DVec3) -> DVec3 {
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    (d + MAGIC) - MAGIC
}
