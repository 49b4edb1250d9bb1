//! Vector contour lines of an elevation grid, equal to GDAL 3.6.2's `gdal_contour` (its
//! marching-squares generator, `alg/marching_squares`): the same lines, vertex for vertex, in the
//! same order and direction (tests/contour_lines.rs compares them with the GeoJSON that
//! tests/data/gdal_contour.sh had `gdal_contour` write).
//!
//! # The lattice
//! Sample `(col, row)` is a lattice point at pixel coordinates `(col + ½, row + ½)`, as GDAL
//! places pixel centres; the lattice's squares join four neighbouring samples. Outside the grid
//! and at no-data samples the lattice holds no value, and a square with one to three corners
//! without a value is cut into four quarter squares, one per valid corner, whose other corners
//! are the midpoints of its sides (the mean of the valid ends) and its centre (the mean of the
//! valid corners). So a line runs half a cell past the outermost samples to the raster's edge,
//! and half a cell towards a no-data sample, where it stops. A whole square is interpolated from
//! the midpoint of each side to the end the level lies towards, so the two squares sharing a side
//! (one of them cut, one whole) compute the same crossing bit for bit and their segments join.
//! The saddle cases (two opposite corners above the level) are always resolved the same way,
//! lower-left and upper-right corners cut off, as GDAL resolves them (never by the centre value).
//!
//! # Heights equal to a level
//! GDAL 3.6.2 perturbs a value within 10⁻⁶ of a level to the value plus 10⁻⁶ (`fudge`), both when
//! it decides which corners lie above a level and when it interpolates, and the values it
//! perturbs include the midpoints of whole squares' sides. A sample exactly on a level therefore
//! counts as above it, and the line passes beside the sample rather than through it (about
//! 10⁻⁶ of a cell divided by the height difference, towards the lower neighbour): on a grid of integer
//! heights with `-i 1` the lowest height's level has no line and the highest height's has one,
//! and a level exactly midway between two neighbours crosses 10⁻⁶ of a half cell off the
//! midpoint. Measured with tiny grids (tests/data/contour_onlevel.asc, gdal_contour/onlevel_*),
//! and matched bit for bit.
//!
//! # Levels
//! [`Levels`]: every `offset + k·interval` (`-i`, `-off`), a list (`-fl`), or `0, 1, b, b², …`
//! (`-e`: level `k ≥ 1` is `b^(k−1)`, level 0 is 0). The levels of a square are found by index
//! arithmetic from its lowest and highest corner, so a grid costs the same whatever the number of
//! levels; a square spanning more than [`MAX_LEVELS`] levels is refused, as GDAL refuses it.
//!
//! # Joining
//! Segments are joined into lines as GDAL's `SegmentMerger` joins them, row by row: a segment
//! extends the oldest open line of its level that ends at one of its ends (tried in GDAL's order:
//! that line's last point against the segment's end, its first point, then against the
//! segment's start), and the extended line then absorbs the oldest later line that ends where it
//! now ends. A line not extended during a row is finished at the row's end; a line closed by
//! joining two lines is finished at once (a ring: first point = last point). Lines are numbered
//! in the order they are finished (GDAL's `ID`), and the lines left open after the last row are
//! finished level by level. GDAL scans its open lines for each segment (quadratic in the number
//! of open lines); here an index of line ends gives the same choice in constant time.
//!
//! # Coordinates
//! Pixel coordinates `(px, py)` are placed by the grid's georeference as GDAL's geotransform
//! places them, `x = x₀ + dx·px`, `y = y₀ + dy·py` with `(x₀, y₀)` the grid's outer corner
//! (`Georef`'s origin is a sample centre: `x₀ = origin_x − dx/2`, exact for the grids read here
//! to a unit in the last place of the corner's coordinate).
//!
//! # Output
//! [`write_geojson`] lays the lines out as `gdal_contour -f GeoJSON` does: a FeatureCollection
//! named `contour`, one feature a line with properties `ID` (from 0, in the order above) and the
//! elevation attribute when one is named (`-a`), Z on every vertex with `-3d`, and the `crs`
//! member GDAL writes (OGC CRS84 for WGS 84 degrees, `urn:ogc:def:crs:EPSG::code` otherwise,
//! none for a grid without a system). Numbers are printed with the fewest digits that read back
//! to the same `f64` (GDAL prints 15 decimals). [`write_shapefile`] writes gdal_contour's
//! default format: `.shp`/`.shx` byte for byte GDAL's, `.dbf` equal but for the date it holds,
//! and GDAL's ESRI `.prj` for WGS 84 degrees and UTM zones (tests/contour_lines.rs compares them
//! with a live `gdal_contour` run).
//!
//! # Departures from GDAL 3.6.2
//! - A fixed level list is sorted (and repeated levels dropped) first: GDAL uses it as given and
//!   silently drops levels below an earlier larger one (`-fl 4.5 2.5` gives only 4.5).
//! - An extra no-data value ([`ContourOptions::nodata`], `-snodata`) is added to the file's
//!   no-data, which stays no-data; GDAL replaces the file's no-data value with it, so the file's
//!   no-data samples (−9999, −32768) would become heights.
//! - Polygons (`-p`) are not made, and a shapefile gets a `.prj` only for WGS 84 degrees and
//!   UTM zones of WGS 84 (GDAL writes any system's WKT from its database; none is at hand here).
//!
//! # References
//! - Lorensen, W. E., Cline, H. E. (1987). Marching cubes: a high resolution 3D surface
//!   construction algorithm. SIGGRAPH '87, 163–169 (the square case table is its 2D form).
//! - GDAL 3.6 `gdal_contour` documentation (the options and the output layout).

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::io::Write;
use std::path::Path;

use crate::dem::{CrsKind, Georef, Grid};
use crate::error::{TerrainError, io};

/// GDAL's perturbation of a value close to a level (`fudge` in GDAL's marching squares).
const FUDGE: f64 = 1e-6;

/// The most levels one square may span (GDAL's `knMAX_NUMBER_LEVELS`).
pub const MAX_LEVELS: i64 = 100_000;

/// Which heights get a line.
#[derive(Clone, Debug, PartialEq)]
pub enum Levels {
    /// `offset + k·interval` for every integer `k` (gdal_contour `-i`, `-off`).
    Interval { interval: f64, offset: f64 },
    /// These heights (gdal_contour `-fl`); sorted and deduplicated by [`Levels::check`].
    Fixed(Vec<f64>),
    /// `0, 1, base, base², …` (gdal_contour `-e`).
    Exponential { base: f64 },
}

impl Levels {
    /// The levels validated: a finite interval > 0 and finite offset, a non-empty list of finite
    /// heights (returned sorted, without repeats), or a finite base > 1.
    pub fn check(self) -> Result<Levels, TerrainError> {
        let bad = |name, value: String, expected| {
            Err(TerrainError::BadParameter {
                name,
                value,
                expected,
            })
        };
        match self {
            Levels::Interval { interval, offset } => {
                if !(interval.is_finite() && interval > 0.0) {
                    return bad("interval", interval.to_string(), "a finite interval > 0");
                }
                if !offset.is_finite() {
                    return bad("offset", offset.to_string(), "a finite offset");
                }
                Ok(Levels::Interval { interval, offset })
            }
            Levels::Fixed(mut v) => {
                if v.is_empty() {
                    return bad("levels", String::new(), "at least one level");
                }
                if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                    return bad("levels", x.to_string(), "finite heights");
                }
                v.sort_by(f64::total_cmp);
                v.dedup();
                Ok(Levels::Fixed(v))
            }
            Levels::Exponential { base } => {
                if !(base.is_finite() && base > 1.0) {
                    return bad("exponential base", base.to_string(), "a finite base > 1");
                }
                Ok(Levels::Exponential { base })
            }
        }
    }

    /// The height of level `idx`.
    fn level(&self, idx: i64) -> f64 {
        match self {
            Levels::Interval { interval, offset } => idx as f64 * interval + offset,
            Levels::Fixed(v) => v.get(idx as usize).copied().unwrap_or(f64::MAX),
            Levels::Exponential { base } => {
                if idx <= 0 {
                    0.0
                } else {
                    base.powf((idx - 1) as f64)
                }
            }
        }
    }

    /// The indices `[b, e)` of the levels a square whose corners span `[min, max]` crosses,
    /// with GDAL's perturbation: a level within 10⁻⁶ of `min` or `max` is compared with that
    /// value plus 10⁻⁶. Fails past [`MAX_LEVELS`] levels.
    fn range(&self, min: f64, max: f64) -> Result<(i64, i64), TooManyLevels> {
        let as_index = |v: f64| {
            if v >= i32::MIN as f64 && v < i32::MAX as f64 {
                Ok(v as i64)
            } else {
                Err(TooManyLevels)
            }
        };
        let (b, e) = match self {
            Levels::Interval { interval, offset } => {
                let mut i1 = as_index(((min - offset) / interval).ceil())?;
                let l1 = fudge(self.level(i1), min);
                if l1 > min {
                    i1 = as_index(((l1 - offset) / interval).ceil())?;
                }
                if min == max {
                    return Ok((i1, i1));
                }
                let mut i2 = as_index(((max - offset) / interval).floor() + 1.0)?;
                let l2 = fudge(self.level(i2), max);
                if l2 > max {
                    i2 = as_index(((l2 - offset) / interval).floor() + 1.0)?;
                }
                (i1, i2)
            }
            Levels::Fixed(v) => {
                let mut b = 0;
                while b < v.len() && v[b] < fudge(v[b], min) {
                    b += 1;
                }
                if min == max {
                    return Ok((b as i64, b as i64));
                }
                let mut e = b;
                while e < v.len() && v[e] <= fudge(v[e], max) {
                    e += 1;
                }
                (b as i64, e as i64)
            }
            Levels::Exponential { base } => {
                let ln = base.ln();
                let index1 = |p: f64| {
                    if p < 1.0 {
                        Ok(1)
                    } else {
                        as_index((p.ln() / ln).ceil() + 1.0)
                    }
                };
                let index2 = |p: f64| {
                    if p < 1.0 {
                        Ok(0)
                    } else {
                        as_index((p.ln() / ln).floor() + 2.0)
                    }
                };
                let mut i1 = index1(min)?;
                let l1 = fudge(self.level(i1), min);
                if l1 > min {
                    i1 = index1(l1)?;
                }
                if min == max {
                    return Ok((i1, i1));
                }
                let mut i2 = index2(max)?;
                let l2 = fudge(self.level(i2), max);
                if l2 > max {
                    i2 = index2(l2)?;
                }
                (i1, i2)
            }
        };
        if e > b + MAX_LEVELS {
            return Err(TooManyLevels);
        }
        Ok((b, e))
    }
}

/// A square spans more than [`MAX_LEVELS`] levels.
struct TooManyLevels;

/// GDAL 3.6.2's `fudge(level, value)`: a value within 10⁻⁶ of the level is moved 10⁻⁶ up.
#[inline]
fn fudge(level: f64, value: f64) -> f64 {
    if (level - value).abs() < FUDGE {
        value + FUDGE
    } else {
        value
    }
}

/// What [`contour_lines`] takes besides the levels.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ContourOptions {
    /// A height that is no-data besides the file's own no-data (gdal_contour `-snodata`).
    pub nodata: Option<f64>,
}

/// One contour line in the grid's coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct ContourLine {
    /// The level's height.
    pub level: f64,
    /// The vertices `(x, y)`, at least two; a ring's last equals its first.
    pub points: Vec<[f64; 2]>,
}

impl ContourLine {
    /// Whether the line is a ring (first vertex = last vertex).
    pub fn is_closed(&self) -> bool {
        self.points.len() > 2 && self.points.first() == self.points.last()
    }

    /// The length in the grid's units (degrees for a geographic grid).
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }
}

/// The contour lines of `grid` at `levels`, in GDAL's order (see the module docs).
pub fn contour_lines(
    grid: &Grid,
    levels: &Levels,
    options: &ContourOptions,
) -> Result<Vec<ContourLine>, TerrainError> {
    let levels = levels.clone().check()?;
    if let Some(nd) = options.nodata
        && nd.is_nan()
    {
        return Err(TerrainError::BadParameter {
            name: "nodata",
            value: nd.to_string(),
            expected: "a number",
        });
    }
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let heights = grid.heights();
    let value = |row: usize, col: usize| -> f64 {
        let v = heights[row * w + col] as f64;
        match options.nodata {
            Some(nd) if v == nd => f64::NAN,
            _ => v,
        }
    };
    let mut merger = Merger::default();
    let mut prev = vec![f64::NAN; w + 2];
    let mut cur = vec![f64::NAN; w + 2];
    // Rows 0..=h: lattice row r joins sample rows r − 1 and r (NaN beyond the grid); each row
    // is padded by a NaN column on both sides, so square c joins columns c − 1 and c.
    for r in 0..=h {
        std::mem::swap(&mut prev, &mut cur);
        for c in 0..w {
            cur[c + 1] = if r < h { value(r, c) } else { f64::NAN };
        }
        let (y0, y1) = (r as f64 - 0.5, r as f64 + 0.5);
        for c in 0..=w {
            let (ul, ur, ll, lr) = (prev[c], prev[c + 1], cur[c], cur[c + 1]);
            let nans =
                ul.is_nan() as u8 + ur.is_nan() as u8 + ll.is_nan() as u8 + lr.is_nan() as u8;
            if nans == 4 {
                continue;
            }
            let (x0, x1) = (c as f64 - 0.5, c as f64 + 0.5);
            let sq = Square {
                ul: Vp::new(x0, y0, ul),
                ur: Vp::new(x1, y0, ur),
                ll: Vp::new(x0, y1, ll),
                lr: Vp::new(x1, y1, lr),
                nans,
                split: false,
            };
            sq.process(&levels, &mut merger).map_err(|TooManyLevels| {
                TerrainError::BadParameter {
                    name: "levels",
                    value: format!("{levels:?}"),
                    expected: "at most 100000 levels between neighbouring samples",
                }
            })?;
        }
        merger.end_of_row();
    }
    merger.finish();
    // Pixel coordinates to the georeference: the outer corner plus the spacing times them.
    let g = grid.georef();
    let (gx, gy) = (g.origin_x - 0.5 * g.dx, g.origin_y - 0.5 * g.dy);
    Ok(merger
        .done
        .into_iter()
        .map(|(idx, pts)| ContourLine {
            level: levels.level(idx),
            points: pts
                .into_iter()
                .map(|p| [gx + g.dx * p.x, gy + g.dy * p.y])
                .collect(),
        })
        .collect())
}

/// A lattice point in pixel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
struct P {
    x: f64,
    y: f64,
}

impl P {
    /// The point's bits, `−0` taken as `+0`, for the index of line ends.
    fn key(self) -> (u64, u64) {
        ((self.x + 0.0).to_bits(), (self.y + 0.0).to_bits())
    }
}

/// A lattice point with its value (`NaN`: none).
#[derive(Clone, Copy, Debug)]
struct Vp {
    x: f64,
    y: f64,
    v: f64,
}

impl Vp {
    fn new(x: f64, y: f64, v: f64) -> Vp {
        Vp { x, y, v }
    }
}

/// The four sides of a square.
#[derive(Clone, Copy)]
enum Side {
    Left,
    Lower,
    Right,
    Upper,
}

/// One lattice square (or a quarter of one, `split`).
struct Square {
    ul: Vp,
    ur: Vp,
    ll: Vp,
    lr: Vp,
    /// How many corners have no value.
    nans: u8,
    /// A quarter of a square cut at no-data: interpolated over its whole sides.
    split: bool,
}

/// The mean of the valid values among `a` and `b` (one of them valid).
fn mean2(a: f64, b: f64) -> f64 {
    if a.is_nan() {
        b
    } else if b.is_nan() {
        a
    } else {
        0.5 * (a + b)
    }
}

impl Square {
    fn quarter(ul: Vp, ur: Vp, ll: Vp, lr: Vp) -> Square {
        Square {
            ul,
            ur,
            ll,
            lr,
            nans: 0,
            split: true,
        }
    }

    // The midpoints of the sides and the centre, with the means of the valid values.
    fn center(&self) -> Vp {
        let z = |v: f64| if v.is_nan() { 0.0 } else { v };
        Vp::new(
            0.5 * (self.ul.x + self.lr.x),
            0.5 * (self.ul.y + self.lr.y),
            (z(self.ll.v) + z(self.ul.v) + z(self.lr.v) + z(self.ur.v)) / (4 - self.nans) as f64,
        )
    }
    fn left_center(&self) -> Vp {
        let (u, l) = (self.ul, self.ll);
        Vp::new(u.x, 0.5 * (u.y + l.y), mean2(u.v, l.v))
    }
    fn lower_center(&self) -> Vp {
        let (l, r) = (self.ll, self.lr);
        Vp::new(0.5 * (l.x + r.x), l.y, mean2(r.v, l.v))
    }
    fn right_center(&self) -> Vp {
        let (u, l) = (self.ur, self.lr);
        Vp::new(u.x, 0.5 * (u.y + l.y), mean2(l.v, u.v))
    }
    fn upper_center(&self) -> Vp {
        let (l, r) = (self.ul, self.ur);
        Vp::new(0.5 * (l.x + r.x), l.y, mean2(l.v, r.v))
    }

    fn process(&self, levels: &Levels, merger: &mut Merger) -> Result<(), TooManyLevels> {
        if self.nans > 0 {
            // Cut at no-data: one quarter per valid corner, in GDAL's order.
            let (c, uc, lc, rc, dc) = (
                self.center(),
                self.upper_center(),
                self.left_center(),
                self.right_center(),
                self.lower_center(),
            );
            if !self.ul.v.is_nan() {
                Square::quarter(self.ul, uc, lc, c).process(levels, merger)?;
            }
            if !self.ur.v.is_nan() {
                Square::quarter(uc, self.ur, c, rc).process(levels, merger)?;
            }
            if !self.ll.v.is_nan() {
                Square::quarter(lc, c, self.ll, dc).process(levels, merger)?;
            }
            if !self.lr.v.is_nan() {
                Square::quarter(c, rc, dc, self.lr).process(levels, merger)?;
            }
            return Ok(());
        }
        let min = self.ul.v.min(self.ur.v).min(self.ll.v.min(self.lr.v));
        let max = self.ul.v.max(self.ur.v).max(self.ll.v.max(self.lr.v));
        let (b, e) = levels.range(min, max)?;
        for idx in b..e {
            let level = levels.level(idx);
            self.segments(idx, level, merger);
        }
        Ok(())
    }

    /// The segments of one level, oriented with higher values on their right.
    fn segments(&self, idx: i64, level: f64, merger: &mut Merger) {
        let above = |v: f64| level < fudge(level, v);
        let case = above(self.ul.v) as u8
            | (above(self.ll.v) as u8) << 1
            | (above(self.lr.v) as u8) << 2
            | (above(self.ur.v) as u8) << 3;
        use Side::*;
        let mut seg = |a: Side, b: Side| {
            let (p, q) = (self.interpolate(a, level), self.interpolate(b, level));
            merger.add_segment(idx, p, q);
        };
        // Corner bits: 1 upper left, 2 lower left, 4 lower right, 8 upper right.
        match case {
            0 | 15 => {}
            1 => seg(Upper, Left),
            2 => seg(Left, Lower),
            4 => seg(Lower, Right),
            8 => seg(Right, Upper),
            3 => seg(Upper, Lower),
            6 => seg(Left, Right),
            12 => seg(Lower, Upper),
            9 => seg(Right, Left),
            14 => seg(Left, Upper),
            13 => seg(Lower, Left),
            11 => seg(Right, Lower),
            7 => seg(Upper, Right),
            // The saddles, both resolved alike.
            5 | 10 => {
                seg(Left, Lower);
                seg(Right, Upper);
            }
            _ => unreachable!("four corner bits"),
        }
    }

    /// Where `level` crosses a side.
    fn interpolate(&self, side: Side, level: f64) -> P {
        let whole = !self.split;
        let (ul, ur, ll, lr) = (self.ul, self.ur, self.ll, self.lr);
        match side {
            Side::Left => P {
                x: ul.x,
                y: interpolate(level, ll.y, ul.y, ll.v, ul.v, whole),
            },
            Side::Lower => P {
                x: interpolate(level, ll.x, lr.x, ll.v, lr.v, whole),
                y: ll.y,
            },
            Side::Right => P {
                x: ur.x,
                y: interpolate(level, lr.y, ur.y, lr.v, ur.v, whole),
            },
            Side::Upper => P {
                x: interpolate(level, ul.x, ur.x, ul.v, ur.v, whole),
                y: ul.y,
            },
        }
    }
}

/// The position between `x1` (value `v1`) and `x2` (`v2`) where the values reach `level`. On a
/// whole square's side, from the side's midpoint to the end the level lies towards: a quarter
/// square beside it interpolates over that half, and both must give the same bits.
fn interpolate(level: f64, mut x1: f64, mut x2: f64, mut v1: f64, mut v2: f64, whole: bool) -> f64 {
    if whole {
        let (xm, vm) = (0.5 * (x1 + x2), 0.5 * (v1 + v2));
        let (f1, fm) = (fudge(level, v1), fudge(level, vm));
        if (f1 < level && level < fm) || (f1 > level && level > fm) {
            (x2, v2) = (xm, vm);
        } else {
            (x1, v1) = (xm, vm);
        }
    }
    let f1 = fudge(level, v1);
    let ratio = (level - f1) / (fudge(level, v2) - f1);
    x1 * (1.0 - ratio) + x2 * ratio
}

/// An open line: its points, and whether a segment extended it during this row.
struct Open {
    pts: VecDeque<P>,
    merged: bool,
}

/// A hasher for the bits of a point (two `u64`s): a multiply-rotate mix, several times faster
/// than the default SipHash here, where keys come from the grid, not from an adversary.
#[derive(Default)]
struct PointHasher(u64);

impl std::hash::Hasher for PointHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        bytes.iter().for_each(|&b| self.write_u64(b as u64));
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type PointMap<V> = HashMap<(u64, u64), V, std::hash::BuildHasherDefault<PointHasher>>;

/// No line (an empty slot of [`LevelLines::ends`]).
const NONE: u64 = u64::MAX;

/// The open lines of one level, in the order they were started (GDAL's list order).
#[derive(Default)]
struct LevelLines {
    lines: BTreeMap<u64, Open>,
    /// The lines ending at a point: at most two slots, since a lattice point of a level is on
    /// at most two segments (a ring's two ends are one point: two entries).
    ends: PointMap<[u64; 2]>,
}

impl LevelLines {
    fn register(&mut self, p: P, id: u64) {
        let e = self.ends.entry(p.key()).or_insert([NONE; 2]);
        let slot = if e[0] == NONE { 0 } else { 1 };
        debug_assert!(e[slot] == NONE, "a point ends at most two lines");
        e[slot] = id;
    }
    fn unregister(&mut self, p: P, id: u64) {
        let k = p.key();
        if let Some(e) = self.ends.get_mut(&k) {
            if e[0] == id {
                e[0] = e[1];
                e[1] = NONE;
            } else if e[1] == id {
                e[1] = NONE;
            }
            if e[0] == NONE {
                self.ends.remove(&k);
            }
        }
    }
    /// The oldest line ending at `p`, except `not`, started after `after`.
    fn oldest_at(&self, p: P, not: u64, after: Option<u64>) -> Option<u64> {
        self.ends.get(&p.key()).and_then(|e| {
            e.iter()
                .copied()
                .filter(|&id| id != NONE && id != not && after.is_none_or(|a| id > a))
                .min()
        })
    }
    fn ends_of(&self, id: u64) -> (P, P) {
        let l = &self.lines[&id].pts;
        (l[0], l[l.len() - 1])
    }
    fn remove(&mut self, id: u64) -> VecDeque<P> {
        let (a, b) = self.ends_of(id);
        self.unregister(a, id);
        self.unregister(b, id);
        self.lines.remove(&id).expect("an open line").pts
    }
    fn insert(&mut self, id: u64, pts: VecDeque<P>) {
        self.register(pts[0], id);
        self.register(pts[pts.len() - 1], id);
        self.lines.insert(id, Open { pts, merged: true });
    }
}

/// `a` followed by `b`, extending whichever is longer.
fn join(mut a: VecDeque<P>, mut b: VecDeque<P>) -> VecDeque<P> {
    if a.len() >= b.len() {
        a.extend(b);
        a
    } else {
        while let Some(p) = a.pop_back() {
            b.push_front(p);
        }
        b
    }
}

/// GDAL's `SegmentMerger` for lines (module docs, "Joining").
#[derive(Default)]
struct Merger {
    levels: BTreeMap<i64, LevelLines>,
    next_id: u64,
    /// Finished lines in pixel coordinates, with their level index.
    done: Vec<(i64, Vec<P>)>,
}

impl Merger {
    fn add_segment(&mut self, idx: i64, start: P, end: P) {
        if start == end {
            return;
        }
        let ll = self.levels.entry(idx).or_default();
        let found = match (
            ll.oldest_at(end, u64::MAX, None),
            ll.oldest_at(start, u64::MAX, None),
        ) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let Some(it) = found else {
            let id = self.next_id;
            self.next_id += 1;
            ll.insert(id, VecDeque::from([start, end]));
            return;
        };
        // Extend the line, trying its ends in GDAL's order.
        let line = ll.lines.get_mut(&it).expect("an open line");
        line.merged = true;
        let pts = &mut line.pts;
        let (front, back) = (pts[0], pts[pts.len() - 1]);
        let (matched, added) = if back == end {
            pts.push_back(start);
            (end, start)
        } else if front == end {
            pts.push_front(start);
            (end, start)
        } else if back == start {
            pts.push_back(end);
            (start, end)
        } else {
            debug_assert!(front == start);
            pts.push_front(end);
            (start, end)
        };
        ll.unregister(matched, it);
        ll.register(added, it);
        // Join the oldest later line that ends at one of its ends.
        let (front, back) = ll.ends_of(it);
        let other = match (
            ll.oldest_at(front, it, Some(it)),
            ll.oldest_at(back, it, Some(it)),
        ) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let Some(other) = other else {
            return;
        };
        let (ofront, oback) = ll.ends_of(other);
        let mut a = ll.remove(it);
        let mut b = ll.remove(other);
        let (id, pts) = if back == ofront {
            a.pop_back();
            (it, join(a, b))
        } else if oback == front {
            a.pop_front();
            (other, join(b, a))
        } else if back == oback {
            a.pop_back();
            b.make_contiguous().reverse();
            (it, join(a, b))
        } else {
            debug_assert!(front == ofront);
            a.pop_front();
            b.make_contiguous().reverse();
            (it, join(b, a))
        };
        if pts[0] == pts[pts.len() - 1] {
            self.done.push((idx, pts.into()));
        } else {
            ll.insert(id, pts);
        }
    }

    /// Finish the lines no segment extended during the row; the rest wait for the next row.
    fn end_of_row(&mut self) {
        for (&idx, ll) in &mut self.levels {
            let stale: Vec<u64> = ll
                .lines
                .iter()
                .filter(|(_, l)| !l.merged)
                .map(|(&id, _)| id)
                .collect();
            for id in stale {
                let pts = ll.remove(id);
                self.done.push((idx, pts.into()));
            }
            for l in ll.lines.values_mut() {
                l.merged = false;
            }
        }
    }

    /// Finish every line still open, level by level.
    fn finish(&mut self) {
        for (idx, ll) in std::mem::take(&mut self.levels) {
            for (_, l) in ll.lines {
                self.done.push((idx, l.pts.into()));
            }
        }
    }
}

/// How the lines are written.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct WriteOptions {
    /// The elevation attribute's name (gdal_contour `-a`); `None`: only `ID`.
    pub attr: Option<String>,
    /// Write the level as every vertex's Z (gdal_contour `-3d`).
    pub three_d: bool,
}

/// The GeoJSON `crs` member gdal_contour writes for `georef`: OGC CRS84 for WGS 84 degrees, the
/// EPSG URN for another coded system, none for a local grid.
fn geojson_crs(georef: &Georef) -> Option<String> {
    match (georef.crs, georef.epsg) {
        (CrsKind::Local, _) => None,
        (CrsKind::Geographic, Some(4326) | None) => Some("urn:ogc:def:crs:OGC:1.3:CRS84".into()),
        (_, Some(code)) => Some(format!("urn:ogc:def:crs:EPSG::{code}")),
        (CrsKind::Projected, None) => None,
    }
}

/// A JSON number for a finite `f64` (shortest round-trip digits, `.0` on integers).
fn num(v: f64) -> String {
    format!("{v:?}")
}

/// Write `lines` as a GeoJSON FeatureCollection laid out as gdal_contour's `-f GeoJSON` (layer
/// `contour`, properties `ID` and the elevation attribute, the `crs` member), under a temporary
/// name renamed into place, so a failure leaves no file.
pub fn write_geojson(
    path: &Path,
    lines: &[ContourLine],
    georef: &Georef,
    options: &WriteOptions,
) -> Result<(), TerrainError> {
    crate::dem::geotiff_writer::write_atomically(path, |out| {
        let mut s = String::with_capacity(1 << 16);
        s.push_str("{\n\"type\": \"FeatureCollection\",\n\"name\": \"contour\",\n");
        if let Some(crs) = geojson_crs(georef) {
            s.push_str(&format!(
                "\"crs\": {{ \"type\": \"name\", \"properties\": {{ \"name\": \"{crs}\" }} }},\n"
            ));
        }
        s.push_str("\"features\": [\n");
        let attr = options
            .attr
            .as_ref()
            .map(|a| serde_json::to_string(a).expect("a string serialises"));
        for (i, l) in lines.iter().enumerate() {
            s.push_str(&format!(
                "{{ \"type\": \"Feature\", \"properties\": {{ \"ID\": {i}"
            ));
            if let Some(a) = &attr {
                s.push_str(&format!(", {a}: {}", num(l.level)));
            }
            s.push_str(" }, \"geometry\": { \"type\": \"LineString\", \"coordinates\": [ ");
            for (j, p) in l.points.iter().enumerate() {
                if j > 0 {
                    s.push_str(", ");
                }
                if options.three_d {
                    s.push_str(&format!(
                        "[ {}, {}, {} ]",
                        num(p[0]),
                        num(p[1]),
                        num(l.level)
                    ));
                } else {
                    s.push_str(&format!("[ {}, {} ]", num(p[0]), num(p[1])));
                }
            }
            s.push_str(" ] } }");
            s.push_str(if i + 1 < lines.len() { ",\n" } else { "\n" });
            if s.len() > 1 << 20 {
                out.write_all(s.as_bytes()).map_err(io(path))?;
                s.clear();
            }
        }
        s.push_str("]\n}\n");
        out.write_all(s.as_bytes()).map_err(io(path))
    })
}

/// The `.prj` gdal_contour writes (ESRI's WKT 1) for WGS 84 degrees and the WGS 84 UTM zones,
/// the systems whose WKT needs no database; `None` for others.
fn esri_prj(georef: &Georef) -> Option<String> {
    const GCS: &str = "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",\
                       6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",\
                       0.0174532925199433]]";
    match (georef.crs, georef.epsg) {
        (CrsKind::Geographic, Some(4326) | None) => Some(GCS.to_string()),
        (CrsKind::Projected, Some(code @ (32601..=32660 | 32701..=32760))) => {
            let (zone, north) = (code % 100, code < 32700);
            let cm = -183 + 6 * zone as i32;
            Some(format!(
                "PROJCS[\"WGS_1984_UTM_Zone_{zone}{}\",{GCS},PROJECTION[\"Transverse_Mercator\"],\
                 PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",{}],\
                 PARAMETER[\"Central_Meridian\",{cm}.0],PARAMETER[\"Scale_Factor\",0.9996],\
                 PARAMETER[\"Latitude_Of_Origin\",0.0],UNIT[\"Meter\",1.0]]",
                if north { 'N' } else { 'S' },
                if north { "0.0" } else { "10000000.0" },
            ))
        }
        _ => None,
    }
}

/// Today's date (UTC) as dBASE stores it: years since 1900, month, day; the date of
/// `SOURCE_DATE_EPOCH` (seconds) when it is set, so that reproducible pipelines get the same
/// bytes every day (the reproducible-builds convention).
fn dbase_date() -> [u8; 3] {
    let secs = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0)
        });
    let days = (secs / 86_400) as i64;
    // Days since 1970-01-01 to a civil date (Hinnant's `civil_from_days`).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + (m <= 2) as i64;
    [(y - 1900).clamp(0, 255) as u8, m as u8, d as u8]
}

/// Write `lines` as an ESRI shapefile laid out as gdal_contour's default output: `x.shp` and
/// `x.shx` (PolyLine, or PolyLineZ with `three_d`, one part a line), `x.dbf` (`ID` as a number
/// of 8 digits, the elevation attribute as 24 with 15 decimals, its name cut to dBASE's 10
/// characters) and `x.prj` (ESRI's WKT, for WGS 84 degrees and UTM zones only). Each file is
/// written under a temporary name and renamed; on a failure the ones written are removed.
/// Returns whether a `.prj` was written.
pub fn write_shapefile(
    path: &Path,
    lines: &[ContourLine],
    georef: &Georef,
    options: &WriteOptions,
) -> Result<bool, TerrainError> {
    let (shp, shx) = shp_bytes(lines, options.three_d);
    let dbf = dbf_bytes(lines, options.attr.as_deref());
    let prj = esri_prj(georef);
    let mut files = vec![
        (path.with_extension("shp"), shp),
        (path.with_extension("shx"), shx),
        (path.with_extension("dbf"), dbf),
    ];
    if let Some(p) = &prj {
        files.push((path.with_extension("prj"), p.clone().into_bytes()));
    }
    let mut written = Vec::new();
    for (p, bytes) in &files {
        let r = crate::dem::geotiff_writer::write_atomically(p, |out| {
            out.write_all(bytes).map_err(io(p))
        });
        if let Err(e) = r {
            for w in &written {
                let _ = std::fs::remove_file(w);
            }
            return Err(e);
        }
        written.push(p.clone());
    }
    Ok(prj.is_some())
}

/// The `.shp` and `.shx` bytes.
fn shp_bytes(lines: &[ContourLine], three_d: bool) -> (Vec<u8>, Vec<u8>) {
    let shape_type: i32 = if three_d { 13 } else { 3 };
    let mut records = Vec::new();
    let mut index = Vec::new();
    let mut bbox = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, l) in lines.iter().enumerate() {
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in &l.points {
            b = [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ];
        }
        bbox = [
            bbox[0].min(b[0]),
            bbox[1].min(b[1]),
            bbox[2].max(b[2]),
            bbox[3].max(b[3]),
        ];
        zmin = zmin.min(l.level);
        zmax = zmax.max(l.level);
        let mut c = Vec::with_capacity(48 + 24 * l.points.len());
        c.extend(shape_type.to_le_bytes());
        b.iter().for_each(|v| c.extend(v.to_le_bytes()));
        c.extend(1i32.to_le_bytes());
        c.extend((l.points.len() as i32).to_le_bytes());
        c.extend(0i32.to_le_bytes());
        for p in &l.points {
            c.extend(p[0].to_le_bytes());
            c.extend(p[1].to_le_bytes());
        }
        if three_d {
            c.extend(l.level.to_le_bytes());
            c.extend(l.level.to_le_bytes());
            for _ in &l.points {
                c.extend(l.level.to_le_bytes());
            }
        }
        index.push((50 + records.len() / 2) as i32);
        index.push((c.len() / 2) as i32);
        records.extend(((i + 1) as i32).to_be_bytes());
        records.extend(((c.len() / 2) as i32).to_be_bytes());
        records.extend(c);
    }
    if lines.is_empty() {
        bbox = [0.0; 4];
        (zmin, zmax) = (0.0, 0.0);
    }
    if !three_d {
        (zmin, zmax) = (0.0, 0.0);
    }
    let header = |words: usize| {
        let mut h = Vec::with_capacity(100);
        h.extend(9994i32.to_be_bytes());
        h.extend([0u8; 20]);
        h.extend((words as i32).to_be_bytes());
        h.extend(1000i32.to_le_bytes());
        h.extend(shape_type.to_le_bytes());
        for v in bbox.iter().chain(&[zmin, zmax, 0.0, 0.0]) {
            h.extend(v.to_le_bytes());
        }
        h
    };
    let mut shp = header((100 + records.len()) / 2);
    shp.extend(records);
    let mut shx = header((100 + 4 * index.len()) / 2);
    index.iter().for_each(|v| shx.extend(v.to_be_bytes()));
    (shp, shx)
}

/// The `.dbf` bytes: dBASE III with `ID` (N 8.0) and the attribute (N 24.15).
fn dbf_bytes(lines: &[ContourLine], attr: Option<&str>) -> Vec<u8> {
    let mut fields: Vec<(String, u8, u8)> = vec![("ID".into(), 8, 0)];
    if let Some(a) = attr {
        let name: String = a.chars().filter(char::is_ascii).take(10).collect();
        fields.push((name, 24, 15));
    }
    let header_len = 32 + 32 * fields.len() + 1;
    let record_len = 1 + fields.iter().map(|f| f.1 as usize).sum::<usize>();
    let mut d = Vec::with_capacity(header_len + record_len * lines.len() + 1);
    d.push(3);
    d.extend(dbase_date());
    d.extend((lines.len() as u32).to_le_bytes());
    d.extend((header_len as u16).to_le_bytes());
    d.extend((record_len as u16).to_le_bytes());
    // Reserved bytes, but for byte 29: the language driver, 0x57 (ANSI), as GDAL sets it.
    let mut reserved = [0u8; 20];
    reserved[29 - 12] = 0x57;
    d.extend(reserved);
    for (name, len, dec) in &fields {
        let mut n = [0u8; 11];
        n[..name.len()].copy_from_slice(name.as_bytes());
        d.extend(n);
        d.push(b'N');
        d.extend([0u8; 4]);
        d.push(*len);
        d.push(*dec);
        d.extend([0u8; 14]);
    }
    d.push(0x0d);
    for (i, l) in lines.iter().enumerate() {
        d.push(b' ');
        d.extend(fit(format!("{i:>8}"), 8));
        if attr.is_some() {
            d.extend(fit(format!("{:>24.15}", l.level), 24));
        }
    }
    d.push(0x1a);
    d
}

/// `s` cut to `width` bytes (a value too wide for its dBASE field keeps its leading digits).
fn fit(s: String, width: usize) -> Vec<u8> {
    let mut b = s.into_bytes();
    b.truncate(width);
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::Georef;

    fn grid(w: u32, h: u32, v: Vec<f32>) -> Grid {
        Grid::new("t", w, h, v, Georef::local(1.0)).unwrap()
    }

    #[test]
    fn a_ramp_gives_one_straight_line_per_level_to_the_raster_edges() {
        // Heights rise by 1 a column: level 1.25 crosses a quarter of the way from column 1.
        let g = grid(4, 3, (0..12).map(|i| (i % 4) as f32).collect());
        let l = Levels::Fixed(vec![1.25]);
        let lines = contour_lines(&g, &l, &ContourOptions::default()).unwrap();
        assert_eq!(lines.len(), 1);
        let xs: Vec<f64> = lines[0].points.iter().map(|p| p[0]).collect();
        assert!(xs.iter().all(|&x| (x - 1.25).abs() < 1e-12), "{xs:?}");
        // From the bottom edge (y = −2.5, half a cell below the last row) to the top edge, the
        // higher heights on the right.
        let ys: Vec<f64> = lines[0].points.iter().map(|p| p[1]).collect();
        assert_eq!(ys.first().copied(), Some(-2.5));
        assert_eq!(ys.last().copied(), Some(0.5));
    }

    #[test]
    fn a_peak_gives_a_ring() {
        let mut v = vec![0.0; 25];
        v[12] = 10.0;
        let lines = contour_lines(
            &grid(5, 5, v),
            &Levels::Fixed(vec![4.0]),
            &ContourOptions::default(),
        )
        .unwrap();
        assert_eq!(lines.len(), 1);
        assert!(lines[0].is_closed());
        assert_eq!(lines[0].level, 4.0);
        // A diamond through the points 0.6 of a cell from the peak towards its four neighbours.
        assert_eq!(lines[0].points.len(), 5);
        let want = 4.0 * 0.6f64.hypot(0.6);
        let got = lines[0].length();
        assert!(
            (got - want).abs() < 1e-12,
            "{got}, expected {want}, tolerance 1e-12"
        );
    }

    #[test]
    fn a_height_on_a_level_counts_as_above_it() {
        // The lowest height's level has no line, the highest's has one.
        let g = grid(3, 3, vec![1., 2., 3., 1., 2., 3., 1., 2., 3.]);
        let l = Levels::Interval {
            interval: 1.0,
            offset: 0.0,
        };
        let lines = contour_lines(&g, &l, &ContourOptions::default()).unwrap();
        let levels: Vec<f64> = lines.iter().map(|l| l.level).collect();
        assert_eq!(levels, [2.0, 3.0]);
        // Level 2's line passes about 1e-6 of a cell beside the column of 2s, on the side of the
        // 1s: from the side's midpoint (1.5 at x = 0.5) to the 2 taken as 2 + 1e-6.
        let x = lines[0].points[0][0];
        let want = 0.5 + 0.5 * (0.5 / (0.5 + 1e-6));
        assert!(
            (x - want).abs() < 1e-12,
            "{x}, expected {want}, tolerance 1e-12"
        );
    }

    #[test]
    fn levels_are_checked() {
        let bad = [
            Levels::Interval {
                interval: 0.0,
                offset: 0.0,
            },
            Levels::Interval {
                interval: 1.0,
                offset: f64::NAN,
            },
            Levels::Fixed(vec![]),
            Levels::Fixed(vec![1.0, f64::INFINITY]),
            Levels::Exponential { base: 1.0 },
        ];
        for l in bad {
            assert!(l.clone().check().is_err(), "{l:?}");
        }
        assert_eq!(
            Levels::Fixed(vec![3.0, 1.0, 3.0]).check().unwrap(),
            Levels::Fixed(vec![1.0, 3.0])
        );
    }

    #[test]
    fn a_square_spanning_too_many_levels_is_refused() {
        let g = grid(2, 2, vec![0.0, 0.0, 0.0, 1e6]);
        let l = Levels::Interval {
            interval: 1.0,
            offset: 0.0,
        };
        assert!(contour_lines(&g, &l, &ContourOptions::default()).is_err());
    }
}
