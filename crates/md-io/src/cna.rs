//! Crystal structure per atom by adaptive common neighbour analysis (a-CNA; A. Stukowski,
//! "Structure identification methods for atomistic simulations of crystalline materials",
//! Modelling Simul. Mater. Sci. Eng. 20 (2012) 045021), as OVITO's Common Neighbor Analysis
//! modifier assigns it in its default adaptive mode: FCC, HCP, BCC, icosahedral or other.
//! Materials simulations colour by it and hide the perfect crystal to show dislocations,
//! stacking faults, grain boundaries and surfaces.
//!
//! Per atom:
//! 1. The 12 nearest neighbours (FCC, HCP, icosahedral test): the local cutoff is
//!    `(1 + √2) / 2` times their mean distance, and two neighbours are bonded when they are at
//!    most that far apart. For each neighbour, its CNA signature is (common neighbours: the
//!    other neighbours bonded to it; bonds among those; bonds in the largest connected set of
//!    those bonds). Twelve (4,2,1) is FCC; six (4,2,1) and six (4,2,2) HCP; twelve (5,5,5)
//!    icosahedral.
//! 2. Otherwise the 14 nearest (BCC test): the cutoff is `(1 + √2) / 2` times
//!    `(2/√3 · Σ₁⁸ rⱼ + Σ₉¹⁴ rⱼ) / 14`; eight (6,6,6) and six (4,4,4) is BCC.
//! 3. Otherwise other (surfaces, cores of defects, liquids, too few atoms).
//!
//! Neighbours are found in a cell grid; in a periodic cell by the nearest image (rounded
//! fractional differences, as [`crate::pbc::minimum_image`]), so the box must be wider than
//! twice the 14th neighbour distance (any box of a few unit cells). Frames without a cell are
//! open. Atoms are classified in parallel (rayon); the result does not depend on the thread
//! count.
//!
//! ```
//! use texmap_md_io::cna::{StructureType, classify};
//! use texmap_md_io::{Frame, UnitCell};
//! // A 3x3x3 block of FCC unit cells (a = 3.6 Å), periodic.
//! let a = 3.6f32;
//! let mut frame = Frame::new();
//! for (i, j, k) in (0..27).map(|n| (n % 3, n / 3 % 3, n / 9)) {
//!     for b in [[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]] {
//!         frame.positions.push([(i as f32 + b[0]) * a, (j as f32 + b[1]) * a, (k as f32 + b[2]) * a]);
//!     }
//! }
//! frame.cell = Some(UnitCell::orthorhombic(3.0 * a as f64, 3.0 * a as f64, 3.0 * a as f64).unwrap());
//! assert!(classify(&frame).iter().all(|t| *t == StructureType::Fcc));
//! ```

use glam::{DMat3, DVec3};

use crate::frame::{Frame, UnitCell};

/// A crystal structure type; the numbers are OVITO's structure type codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum StructureType {
    Other = 0,
    Fcc = 1,
    Hcp = 2,
    Bcc = 3,
    Ico = 4,
}

impl StructureType {
    /// All types, in code order.
    pub const ALL: [StructureType; 5] = [
        StructureType::Other,
        StructureType::Fcc,
        StructureType::Hcp,
        StructureType::Bcc,
        StructureType::Ico,
    ];

    /// The lower-case name (`other`, `fcc`, `hcp`, `bcc`, `ico`).
    pub fn name(self) -> &'static str {
        match self {
            StructureType::Other => "other",
            StructureType::Fcc => "fcc",
            StructureType::Hcp => "hcp",
            StructureType::Bcc => "bcc",
            StructureType::Ico => "ico",
        }
    }

    /// The type named `name` (any case).
    pub fn from_name(name: &str) -> Option<StructureType> {
        StructureType::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(name))
    }
}

/// Neighbours examined per atom: the BCC test's 14.
const MAX_NEIGHBOURS: usize = 14;

/// Atoms per grid cell on average: cells about as wide as the 14th neighbour distance of FCC
/// (1.04 a) and BCC (1.31 a), so one ring of cells usually holds the neighbours.
const ATOMS_PER_CELL: f64 = 4.5;

/// The structure type of every atom of `frame` (see the module docs). Atoms with non-finite
/// coordinates are other, and are nobody's neighbour.
pub fn classify(frame: &Frame) -> Vec<StructureType> {
    use rayon::prelude::*;
    let grid = Grid::new(&frame.positions, frame.cell.as_ref());
    // Atoms are independent: in parallel, each with its own scratch, in atom order.
    (0..frame.positions.len())
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            grid.nearest(i, scratch);
            signature_type(&scratch.near)
        })
        .collect()
}

/// One worker's buffers for [`Grid::nearest`].
#[derive(Default)]
struct Scratch {
    cells: Vec<usize>,
    found: Vec<([f64; 3], f64)>,
    /// The nearest neighbours found: vector from the atom, distance.
    near: Vec<([f64; 3], f64)>,
}

/// The count of each type in `types`, indexed by the type's code.
pub fn counts(types: &[StructureType]) -> [usize; 5] {
    let mut c = [0; 5];
    for t in types {
        c[*t as usize] += 1;
    }
    c
}

/// The type from the neighbour vectors sorted by length (at most [`MAX_NEIGHBOURS`] used).
fn signature_type(near: &[([f64; 3], f64)]) -> StructureType {
    if near.len() >= 12 {
        let mean = near[..12].iter().map(|n| n.1).sum::<f64>() / 12.0;
        let cutoff = 0.5 * (1.0 + std::f64::consts::SQRT_2) * mean;
        let sigs = signatures(&near[..12], cutoff);
        let count = |s: [u8; 3]| sigs.iter().filter(|x| **x == s).count();
        let (s421, s422, s555) = (count([4, 2, 1]), count([4, 2, 2]), count([5, 5, 5]));
        if s421 == 12 {
            return StructureType::Fcc;
        }
        if s421 == 6 && s422 == 6 {
            return StructureType::Hcp;
        }
        if s555 == 12 {
            return StructureType::Ico;
        }
    }
    if near.len() >= 14 {
        let first: f64 = near[..8].iter().map(|n| n.1).sum();
        let second: f64 = near[8..14].iter().map(|n| n.1).sum();
        let mean = (2.0 / 3f64.sqrt() * first + second) / 14.0;
        let cutoff = 0.5 * (1.0 + std::f64::consts::SQRT_2) * mean;
        let sigs = signatures(&near[..14], cutoff);
        let count = |s: [u8; 3]| sigs.iter().filter(|x| **x == s).count();
        if count([6, 6, 6]) == 8 && count([4, 4, 4]) == 6 {
            return StructureType::Bcc;
        }
    }
    StructureType::Other
}

/// Each neighbour's CNA signature among `near` (vectors from the central atom) with bonds
/// shorter than `cutoff`.
fn signatures(near: &[([f64; 3], f64)], cutoff: f64) -> Vec<[u8; 3]> {
    let n = near.len();
    let c2 = cutoff * cutoff;
    // bonded[j] has bit k when neighbours j and k are bonded.
    let mut bonded = [0u16; MAX_NEIGHBOURS];
    for j in 0..n {
        for k in j + 1..n {
            let d: f64 = (0..3).map(|a| (near[j].0[a] - near[k].0[a]).powi(2)).sum();
            if d <= c2 {
                bonded[j] |= 1 << k;
                bonded[k] |= 1 << j;
            }
        }
    }
    // Bonds among the atoms of `set`.
    let bonds_in = |set: u16| -> u32 {
        let mut twice = 0;
        let mut rest = set;
        while rest != 0 {
            let k = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            twice += (bonded[k] & set).count_ones();
        }
        twice / 2
    };
    (0..n)
        .map(|j| {
            let common = bonded[j];
            // The largest set of bonds connected through shared atoms: the connected
            // components of the common neighbours' bond graph, each grown from an atom.
            let mut left = common;
            let mut largest = 0;
            while left != 0 {
                let mut component = 1u16 << left.trailing_zeros();
                loop {
                    let mut grown = component;
                    let mut rest = component;
                    while rest != 0 {
                        let k = rest.trailing_zeros() as usize;
                        rest &= rest - 1;
                        grown |= bonded[k] & common;
                    }
                    if grown == component {
                        break;
                    }
                    component = grown;
                }
                largest = largest.max(bonds_in(component));
                left &= !component;
            }
            [
                common.count_ones() as u8,
                bonds_in(common).min(255) as u8,
                largest.min(255) as u8,
            ]
        })
        .collect()
}

/// A cell grid over the atoms (fractional cells in a periodic cell, the bounding box
/// otherwise) for nearest-neighbour queries.
struct Grid<'a> {
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
    frac: Vec<DVec3>,
}

impl<'a> Grid<'a> {
    fn new(positions: &'a [[f32; 3]], cell: Option<&'a UnitCell>) -> Grid<'a> {
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
            frac: Vec::new(),
        };
        match cell {
            Some(c) => {
                // UnitCell::matrix has the edges as rows.
                let edges = DMat3::from_cols_array_2d(&c.matrix());
                let inverse = edges.inverse();
                grid.edges = edges;
                grid.frac = positions
                    .iter()
                    .map(|p| {
                        let f = inverse * DVec3::from(p.map(f64::from));
                        f - f.floor()
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
        let p = self.positions[i].map(f64::from);
        match self.cell {
            Some(_) => {
                let f = self.frac[i].to_array();
                [0, 1, 2].map(|a| ((f[a] * self.dims[a] as f64) as usize).min(self.dims[a] - 1))
            }
            None => [0, 1, 2].map(|a| {
                (((p[a] - self.lo[a]) * self.inv[a]).max(0.0) as usize).min(self.dims[a] - 1)
            }),
        }
    }

    fn cell_of(&self, i: usize) -> usize {
        let [x, y, z] = self.coords(i);
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// The vector from atom `i` to atom `j` (nearest image in a periodic cell).
    fn vector(&self, i: usize, j: usize) -> [f64; 3] {
        match self.cell {
            Some(_) => {
                // The fractional difference rounded to the nearest image, as
                // `pbc::minimum_image` does, from the fractional coordinates kept.
                let d = self.frac[j] - self.frac[i];
                (self.edges * (d - d.round())).to_array()
            }
            None => [0, 1, 2].map(|a| self.positions[j][a] as f64 - self.positions[i][a] as f64),
        }
    }

    /// Atom `i`'s nearest neighbours (vector, distance), closest first, at most
    /// [`MAX_NEIGHBOURS`], into `scratch.near`.
    fn nearest(&self, i: usize, scratch: &mut Scratch) {
        let Scratch { cells, found, near } = scratch;
        near.clear();
        if self.of[i] == usize::MAX {
            return;
        }
        let centre = self.coords(i);
        let max_ring = self.dims.iter().max().copied().unwrap_or(1);
        for ring in 1..=max_ring.max(1) {
            // Every cell within `ring` of the centre (wrapped in a periodic cell), once.
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
            found.clear();
            for &c in cells.iter() {
                for &j in &self.order[self.starts[c] as usize..self.starts[c + 1] as usize] {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    let v = self.vector(i, j);
                    found.push((v, norm(v)));
                }
            }
            // The nearest MAX_NEIGHBOURS, in order (ties by atom order of the scan).
            if found.len() > MAX_NEIGHBOURS {
                found.select_nth_unstable_by(MAX_NEIGHBOURS - 1, |a, b| a.1.total_cmp(&b.1));
                found.truncate(MAX_NEIGHBOURS);
            }
            found.sort_by(|a, b| a.1.total_cmp(&b.1));
            // The ring holds every atom within `ring` cell widths: enough when the
            // neighbours needed are that close, or when the ring covers the whole grid.
            let whole = (0..3).all(|a| 2 * ring + 1 >= self.dims[a]);
            let enough = found.len() >= MAX_NEIGHBOURS
                && found[MAX_NEIGHBOURS - 1].1 <= ring as f64 * self.width;
            if enough || whole {
                break;
            }
        }
        near.extend_from_slice(found);
    }

    /// The offsets along axis `a` from grid coordinate `at` within `ring` cells: inside an open
    /// grid, and at most once around a periodic one.
    fn offsets(&self, at: usize, a: usize, ring: usize) -> std::ops::RangeInclusive<isize> {
        let (n, at, r) = (self.dims[a] as isize, at as isize, ring as isize);
        match self.cell {
            Some(_) if 2 * r + 1 >= n => 0..=n - 1,
            Some(_) => -r..=r,
            None => (-r).max(-at)..=r.min(n - 1 - at),
        }
    }

    /// The cell at `offset` from `centre`: wrapped in a periodic cell, `None` outside an open
    /// grid.
    fn offset_cell(&self, centre: [usize; 3], offset: [isize; 3]) -> Option<usize> {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let n = self.dims[a] as isize;
            let v = centre[a] as isize + offset[a];
            c[a] = match self.cell {
                Some(_) => v.rem_euclid(n) as usize,
                None if (0..n).contains(&v) => v as usize,
                None => return None,
            };
        }
        Some((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0])
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}
