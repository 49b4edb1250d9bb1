//! Number densities on a grid, averaged over frames: where water, ions or a ligand spend
//! their time around an aligned protein, as MDAnalysis's `DensityAnalysis` and VMD's
//! `volmap density` compute them. The result is a [`Volume`] in atoms per Å³, written as an
//! OpenDX file ([`crate::volume::write_dx`]) and drawn as an isosurface.
//!
//! The grid is MDAnalysis's (2.x, `DensityAnalysis` without a user grid): it spans the first
//! frame's selected atoms, `padding` Å beyond them on every side, and is widened evenly on both
//! sides to a whole number of cells `delta` Å wide (`lib.util.fixedwidth_bins`), at least two
//! along each axis. Each frame,
//! every position falls into the cell whose edges `e[b] ≤ x < e[b + 1]` hold it (the last cell
//! also takes `x` on its upper edge), the edges being `lo + b·(hi − lo)/n` as numpy's
//! `linspace` and `histogramdd` compute them, so that the counts equal MDAnalysis's. Positions
//! outside the grid are counted as [`DensityMap::outside`] (MDAnalysis drops them silently).
//! The density of a cell is its count over the frames and the cell's volume. Grid points are
//! the cells' centres, as GridDataFormats writes them.
//!
//! ```
//! use texmap_md_io::density::DensityMap;
//! // Two atoms that stay put over 4 frames, 1 Å cells, no padding: 2 x 2 x 2 cells from
//! // (0, 0, 0) to (2, 2, 2); each atom's cell holds 1 atom per Å³.
//! let atoms = [[0.25f32, 0.5, 0.5], [1.75, 1.5, 1.5]];
//! let mut map = DensityMap::around(&atoms, 1.0, 0.0).unwrap();
//! for _ in 0..4 {
//!     assert_eq!(map.add(atoms.iter().copied()), 0);
//! }
//! let v = map.to_volume("density");
//! assert_eq!(v.dims, [2, 2, 2]);
//! assert_eq!(v.origin, [0.5, 0.5, 0.5]); // the first cell's centre
//! assert_eq!(v.data, vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
//! ```

use crate::volume::Volume;

/// Avogadro's number (CODATA 2018, exact).
const AVOGADRO: f64 = 6.022_140_76e23;

/// The units a density map may be written in, with the number of those units in one atom per
/// Å³: per Å³, per nm³, molar (mol/L), and relative to bulk water's molecules — `water` at
/// 0.997 g/cm³, the water models `SPC` at 0.985, `TIP3P` at 1.002 and `TIP4P` at 1.001, with
/// 18.016 g/mol (the densities MDAnalysis's `units` module converts with, so a map in `water`
/// reads 1 where an oxygen's density is bulk water's and 2 where it is twice that).
pub const UNITS: [(&str, f64); 7] = [
    ("A^-3", 1.0),
    ("nm^-3", 1000.0),
    ("molar", 1e27 / AVOGADRO),
    ("water", WATER_MOLAR_MASS / (0.997 * AVOGADRO * 1e-24)),
    ("SPC", WATER_MOLAR_MASS / (0.985 * AVOGADRO * 1e-24)),
    ("TIP3P", WATER_MOLAR_MASS / (1.002 * AVOGADRO * 1e-24)),
    ("TIP4P", WATER_MOLAR_MASS / (1.001 * AVOGADRO * 1e-24)),
];

/// g/mol of water in [`UNITS`].
const WATER_MOLAR_MASS: f64 = 18.016;

/// Why a [`DensityMap`] cannot be set up.
#[derive(Clone, Debug, PartialEq)]
pub enum DensityError {
    /// No atoms to span the grid.
    NoAtoms,
    /// A cell width or padding that is not a finite number (width > 0, padding ≥ 0).
    BadSize(&'static str, f64),
    /// A position that is not a finite number.
    NotFinite(usize),
    /// The grid would have more than [`DensityMap::MAX_POINTS`] cells.
    TooLarge([usize; 3]),
}

impl std::fmt::Display for DensityError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DensityError::NoAtoms => write!(f, "no atoms to set the grid around"),
            DensityError::BadSize(what, v) => write!(f, "a {what} of {v}"),
            DensityError::NotFinite(i) => write!(f, "atom {i}'s position is not finite"),
            DensityError::TooLarge([a, b, c]) => write!(
                f,
                "a grid of {a}x{b}x{c} cells, more than {} (widen the cells or select fewer atoms)",
                DensityMap::MAX_POINTS
            ),
        }
    }
}

impl std::error::Error for DensityError {}

/// Counts of positions per grid cell over frames (see the module docs).
#[derive(Clone, Debug)]
pub struct DensityMap {
    /// Cell edges along each axis: `n + 1` of them, the last exactly the grid's upper bound.
    edges: [Vec<f64>; 3],
    /// Positions per cell, x fastest (saturating at `u32::MAX`).
    counts: Vec<u32>,
    frames: usize,
    outside: u64,
}

impl DensityMap {
    /// Most cells a map may have: 2^27 (512 MiB of counts).
    pub const MAX_POINTS: usize = 1 << 27;

    /// An empty map over `positions` (Å): their bounds `padding` Å wider on every side, cut
    /// into cells `delta` Å wide (the bounds widened evenly to a whole number of cells).
    pub fn around(
        positions: &[[f32; 3]],
        delta: f64,
        padding: f64,
    ) -> Result<DensityMap, DensityError> {
        if !(delta.is_finite() && delta > 0.0) {
            return Err(DensityError::BadSize("cell width", delta));
        }
        if !(padding.is_finite() && padding >= 0.0) {
            return Err(DensityError::BadSize("padding", padding));
        }
        if positions.is_empty() {
            return Err(DensityError::NoAtoms);
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (i, p) in positions.iter().enumerate() {
            for a in 0..3 {
                let x = p[a] as f64;
                if !x.is_finite() {
                    return Err(DensityError::NotFinite(i));
                }
                lo[a] = lo[a].min(x);
                hi[a] = hi[a].max(x);
            }
        }
        // At least two cells along each axis (a grid of points needs two to span it).
        let cells = [0, 1, 2].map(|a| ((hi[a] - lo[a] + 2.0 * padding) / delta).ceil().max(2.0));
        let n = cells.map(|c| c as usize);
        if cells.iter().product::<f64>() > Self::MAX_POINTS as f64 {
            return Err(DensityError::TooLarge(n));
        }
        let mut edges: [Vec<f64>; 3] = Default::default();
        for a in 0..3 {
            let (min, max) = (lo[a] - padding, hi[a] + padding);
            let length = max - min;
            let cells = cells[a];
            let excess = 0.5 * (cells * delta - length);
            let (start, stop) = (min - excess, max + excess);
            let step = (stop - start) / cells;
            let mut e: Vec<f64> = (0..n[a]).map(|b| b as f64 * step + start).collect();
            e.push(stop);
            edges[a] = e;
        }
        Ok(DensityMap {
            edges,
            counts: vec![0; n[0] * n[1] * n[2]],
            frames: 0,
            outside: 0,
        })
    }

    /// Cells along each axis.
    pub fn dims(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| self.edges[a].len() - 1)
    }

    /// The grid's lower and upper corners (Å).
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (
            [0, 1, 2].map(|a| self.edges[a][0]),
            [0, 1, 2].map(|a| *self.edges[a].last().unwrap_or(&0.0)),
        )
    }

    /// Frames added.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Positions that fell outside the grid (or were not finite), over every frame.
    pub fn outside(&self) -> u64 {
        self.outside
    }

    /// The cell holding coordinate `x` along axis `a`, if any.
    #[inline]
    fn cell(&self, a: usize, x: f64) -> Option<usize> {
        let e = &self.edges[a];
        let n = e.len() - 1;
        let (first, last) = (e[0], e[n]);
        if !(x >= first && x <= last) {
            return None;
        }
        let step = (last - first) / n as f64;
        let mut b = (((x - first) / step) as usize).min(n - 1);
        while b > 0 && x < e[b] {
            b -= 1;
        }
        while b + 1 < n && x >= e[b + 1] {
            b += 1;
        }
        Some(b)
    }

    /// Adds one frame's positions (Å); returns how many fell outside the grid.
    pub fn add(&mut self, positions: impl IntoIterator<Item = [f32; 3]>) -> u64 {
        let [nx, ny, _] = self.dims();
        let mut outside = 0;
        for p in positions {
            let cell = (|| {
                Some(
                    (self.cell(2, p[2] as f64)? * ny + self.cell(1, p[1] as f64)?) * nx
                        + self.cell(0, p[0] as f64)?,
                )
            })();
            match cell {
                Some(c) => self.counts[c] = self.counts[c].saturating_add(1),
                None => outside += 1,
            }
        }
        self.frames += 1;
        self.outside += outside;
        outside
    }

    /// The mean number density (atoms per Å³) of every cell over the frames added, as a
    /// volume whose points are the cells' centres (zero before any frame).
    pub fn to_volume(&self, name: &str) -> Volume {
        let dims = self.dims();
        let step: [f64; 3] =
            [0, 1, 2].map(|a| (self.edges[a][dims[a]] - self.edges[a][0]) / dims[a] as f64);
        let origin = [0, 1, 2].map(|a| self.edges[a][0] + 0.5 * step[a]);
        let per = 1.0 / (self.frames.max(1) as f64 * step[0] * step[1] * step[2]);
        let data = self
            .counts
            .iter()
            .map(|&c| (c as f64 * per) as f32)
            .collect();
        let steps = [
            [step[0], 0.0, 0.0],
            [0.0, step[1], 0.0],
            [0.0, 0.0, step[2]],
        ];
        Volume {
            origin,
            steps,
            dims,
            data,
            periodic: false,
            name: name.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_is_widened_evenly_to_whole_cells() {
        // x spans 0..3.5 with 1 Å padding: 5.5 Å → 6 cells, 0.25 Å more on each side.
        let atoms = [[0.0f32, 0.0, 0.0], [3.5, 1.0, 2.0]];
        let map = DensityMap::around(&atoms, 1.0, 1.0).unwrap();
        assert_eq!(map.dims(), [6, 3, 4]);
        let (lo, hi) = map.bounds();
        assert_eq!(lo, [-1.25, -1.0, -1.0]);
        assert_eq!(hi, [4.75, 2.0, 3.0]);
    }

    #[test]
    fn edges_follow_numpy_searchsorted_and_the_last_edge_is_inside() {
        let atoms = [[0.0f32, 0.0, 0.0], [2.0, 2.0, 2.0]];
        let mut map = DensityMap::around(&atoms, 1.0, 0.0).unwrap();
        assert_eq!(map.dims(), [2, 2, 2]);
        // On an inner edge: the upper cell; on the grid's upper edge: the last cell.
        assert_eq!(map.cell(0, 1.0), Some(1));
        assert_eq!(map.cell(0, 2.0), Some(1));
        assert_eq!(map.cell(0, 0.0), Some(0));
        assert_eq!(map.cell(0, -1e-9), None);
        assert_eq!(map.cell(0, 2.0 + 1e-9), None);
        assert_eq!(map.cell(0, f64::NAN), None);
        let out = map.add([[2.0, 2.0, 2.0], [5.0, 1.0, 1.0], [0.5, 0.5, f32::NAN]]);
        assert_eq!((out, map.outside(), map.frames()), (2, 2, 1));
        assert_eq!(map.counts[7], 1);
    }

    #[test]
    fn bad_sizes_and_huge_grids_are_refused() {
        let atoms = [[0.0f32; 3], [1000.0, 1000.0, 1000.0]];
        assert!(matches!(
            DensityMap::around(&atoms, 0.0, 2.0),
            Err(DensityError::BadSize(..))
        ));
        assert!(matches!(
            DensityMap::around(&atoms, 1.0, -1.0),
            Err(DensityError::BadSize(..))
        ));
        assert_eq!(
            DensityMap::around(&[], 1.0, 2.0).unwrap_err(),
            DensityError::NoAtoms
        );
        assert!(matches!(
            DensityMap::around(&atoms, 0.01, 2.0),
            Err(DensityError::TooLarge(_))
        ));
        assert_eq!(
            DensityMap::around(&[[0.0, f32::INFINITY, 0.0]], 1.0, 2.0).unwrap_err(),
            DensityError::NotFinite(0)
        );
    }
}
