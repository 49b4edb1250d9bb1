//! Airborne lidar point clouds (LAS and LAZ, [`super::las`]) gridded into an elevation grid, as
//! terrain engineers do with PDAL's `writers.gdal` or `gdal_grid`.
//!
//! **Points chosen** ([`Selection`]): by default the ground (ASPRS class 2) when the clouds hold
//! any ground point, otherwise every point but the noise classes 7 (low point) and 18 (high
//! noise), so that an unclassified survey still grids; or the classes asked for
//! ([`LidarOptions::classes`], e.g. 2 and 9: ground and water). Withheld points (the flag that
//! marks a point deleted) are never used; [`LidarOptions::last_returns`] keeps only the last
//! return of each pulse (the one that reached furthest down). Several files are one cloud: a
//! survey's tiles grid together, so the cells along a tile's edge see the points across it.
//!
//! **Lattice**: square cells of side `c` ([`LidarOptions::cell`], in the cloud's metres) aligned
//! to multiples of `c`: column `k` spans `[k·c, (k+1)·c)` in x, and the grid runs from the cell
//! holding the westernmost (southernmost) chosen point to the one holding the easternmost
//! (northernmost), at least 2 x 2. This is PDAL's grid (`writers.gdal`: width `⌊(max − min)/c⌋ + 1`
//! from `origin_x`, cell centres at `origin + (i + ½)·c`) with its origin snapped down to a
//! multiple of the cell, so that grids of neighbouring surveys at one cell size share a lattice
//! and join in a [`super::mosaic`] without resampling. Without a cell size, [`auto_cell`] picks
//! the side holding about two points per cell, rounded to 1, 2 or 5 times a power of ten.
//!
//! **Cell values** ([`LidarMethod`], PDAL's `output_type` rule): every chosen point counts in
//! every cell whose centre lies *strictly* within the radius `R` of it (`d < R`, `d` the
//! Euclidean distance in x and y; `R` = `c·√2` by default, PDAL's `radius`), and the cell takes
//! their mean, lowest or highest height, or their inverse-distance weighted mean `Σ(z/dᵖ) /
//! Σ(1/dᵖ)` (power `p` = 1, PDAL's default; a point exactly on the centre gives the cell its
//! height, the first such point in file order). Two statistics are grids for quality control,
//! not terrains: the number of points (`count`, the survey's density; 0 where none reaches) and
//! the population standard deviation of their heights (`stdev`: roughness, or objects left
//! among the ground points). A cell no point reaches is no-data, unless
//! [`LidarOptions::fill`] = `N` > 0 fills it as PDAL's `window_size` does: the mean of the
//! non-empty cells within `N` cells of it (a square window), weighted by one over their
//! Chebyshev distance in cells (filled cells are not sources). `terrain build --fill` fills the
//! rest afterwards ([`super::Grid::fill_nodata`]).
//!
//! `gdal_grid -a average:radius1=R:radius2=R` (and `minimum`, `maximum`, `invdist:power=1`)
//! gives the same values on the same lattice except where a point lies exactly `R` from a cell
//! centre: GDAL's search ellipse keeps it (`≤`), PDAL's rule does not (`<`). Its `invdist`
//! weighs by `1/(d²)^{p/2}` and takes a point within `√1e-13` of the centre as exact, which
//! differs from PDAL's `1/dᵖ` only in the last bits.
//!
//! **Parallel and deterministic**: the points are sorted into their home cells by a stable
//! counting sort (each cell's points in file order), then every row of cells is computed on its
//! own (rayon), each cell gathering the points of the home cells within `⌈R/c − ½⌉` of it in
//! raster order. Each cell's sum is taken in that one order whatever the thread count, so the
//! grid is the same to the bit for any number of threads. Scattering each point into the cells
//! around it (PDAL's loop) would need one writer per cell, or atomics whose floating-point sums
//! depend on the schedule.
//!
//! **Cost** (`texmap terrain grid cloud.las -o dem.tif --lidar-cell 1`, release build, two
//! cores; a synthetic cloud of 10 M points written by laspy over 2 x 2.5 km, 7 M of them ground,
//! 5 M cells): reading takes 0.4–0.6 s from LAS (18–24 M points/s) and 2.6–2.9 s from LAZ
//! (3.5–3.9 M points/s, the `laz` crate decoding on one thread), gridding 1.0–1.4 s (5–7 M
//! points/s, the sort a little under half of it): the faster figures with the points in
//! flight-line order, the slower with them shuffled, whose sort misses the cache at every point.
//!
//! **Coordinate system**: the files' (all the same one), from their GeoKey or WKT records; none
//! gives a local grid. A cloud in longitude and latitude degrees is refused: a cell in degrees is
//! not square, and lidar is delivered projected (reproject with PDAL's `filters.reprojection`).
//!
//! # References
//! - PDAL, `writers.gdal` (pdal.io/stages/writers.gdal.html; `io/private/GDALGrid.cpp`): the
//!   radius rule, `output_type`, `power`, `window_size`.
//! - GDAL, `gdal_grid` (gdal.org/programs/gdal_grid.html): `average`, `minimum`, `maximum`,
//!   `invdist` with `radius1`/`radius2`.
//! - ASPRS, *LAS Specification 1.4 — R15*, table 17: the standard classes.

use super::las::{CrsRecord, LasPoint, LasReader};
use super::{CrsKind, Georef, Grid, MAX_SAMPLES, MAX_SIDE};
use crate::error::{TerrainError, format_err};
use rayon::prelude::*;
use std::path::PathBuf;

/// How a cell's height comes from the points within the radius of its centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LidarMethod {
    /// Their mean height (PDAL `mean`, `gdal_grid -a average`).
    Mean,
    /// The lowest (`min`, `minimum`): the ground under low vegetation.
    Min,
    /// The highest (`max`, `maximum`): a surface model of canopy and roofs.
    Max,
    /// Inverse-distance weighted (`idw`, `invdist`).
    Idw,
    /// How many points (PDAL `count`, `gdal_grid -a count`): the survey's density, 0 where no
    /// point reaches. Not a height: a grid for quality control, not a terrain.
    Count,
    /// The population standard deviation of their heights (PDAL `stdev`): roughness, and
    /// vegetation or buildings left among the ground points. Not a height either.
    Stdev,
}

impl LidarMethod {
    pub const NAMES: [&'static str; 6] = ["mean", "min", "max", "idw", "count", "stdev"];

    /// Whether the cells hold heights (a terrain), not a statistic of the points.
    pub fn is_height(self) -> bool {
        !matches!(self, LidarMethod::Count | LidarMethod::Stdev)
    }

    pub fn by_name(name: &str) -> Option<LidarMethod> {
        match name.to_ascii_lowercase().as_str() {
            "mean" | "average" => Some(LidarMethod::Mean),
            "min" | "minimum" => Some(LidarMethod::Min),
            "max" | "maximum" => Some(LidarMethod::Max),
            "idw" | "invdist" => Some(LidarMethod::Idw),
            "count" => Some(LidarMethod::Count),
            "stdev" | "std" => Some(LidarMethod::Stdev),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            LidarMethod::Mean => "mean",
            LidarMethod::Min => "min",
            LidarMethod::Max => "max",
            LidarMethod::Idw => "idw",
            LidarMethod::Count => "count",
            LidarMethod::Stdev => "stdev",
        }
    }
}

/// A set of ASPRS classes (0–255).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClassSet([u64; 4]);

impl ClassSet {
    pub fn of(classes: &[u8]) -> ClassSet {
        let mut s = ClassSet::default();
        for &c in classes {
            s.0[c as usize / 64] |= 1 << (c % 64);
        }
        s
    }

    pub fn contains(&self, class: u8) -> bool {
        self.0[class as usize / 64] & (1 << (class % 64)) != 0
    }

    pub fn is_empty(&self) -> bool {
        self.0 == [0; 4]
    }

    /// The classes in increasing order.
    pub fn iter(&self) -> impl Iterator<Item = u8> + '_ {
        (0..=255u8).filter(|&c| self.contains(c))
    }

    /// A comma-separated list such as `2,9`.
    pub fn parse(text: &str) -> Result<ClassSet, String> {
        let mut v = Vec::new();
        for t in text.split(',') {
            let t = t.trim();
            match t.parse::<u8>() {
                Ok(c) => v.push(c),
                Err(_) => {
                    return Err(format!(
                        "{t:?} is not a class: expected numbers 0 to 255 separated by commas, \
                         e.g. 2,9 (ground and water)"
                    ));
                }
            }
        }
        Ok(ClassSet::of(&v))
    }
}

impl std::fmt::Display for ClassSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v: Vec<String> = self.iter().map(|c| c.to_string()).collect();
        write!(f, "{}", v.join(","))
    }
}

/// How a cloud is gridded (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LidarOptions {
    /// Cell side in the cloud's units (metres); `None`: [`auto_cell`].
    pub cell: Option<f64>,
    pub method: LidarMethod,
    /// Search radius around a cell's centre; `None`: `cell·√2` (PDAL's default).
    pub radius: Option<f64>,
    /// Inverse-distance power of [`LidarMethod::Idw`] (PDAL's default 1).
    pub power: f64,
    /// The classes to grid; `None`: ground, or all but noise when there is no ground.
    pub classes: Option<ClassSet>,
    /// Only the last return of each pulse.
    pub last_returns: bool,
    /// Fill empty cells from the non-empty ones within this many cells (PDAL's `window_size`;
    /// 0: leave them no-data).
    pub fill: u32,
}

impl Default for LidarOptions {
    fn default() -> Self {
        LidarOptions {
            cell: None,
            method: LidarMethod::Mean,
            radius: None,
            power: 1.0,
            classes: None,
            last_returns: false,
            fill: 0,
        }
    }
}

/// The largest radius and fill window accepted, in cells: beyond them a cell's value would be
/// a smoothing of a wide area (grid at a larger cell instead), and the gather's cost grows with
/// their square.
pub const MAX_REACH: u32 = 100;

/// Which points were gridded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Selection {
    /// The ground class (2), the default when the clouds have ground points.
    Ground,
    /// Every class but the noise classes 7 and 18: the default for a cloud without ground.
    AllButNoise,
    /// The classes asked for.
    Classes(ClassSet),
}

impl std::fmt::Display for Selection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Selection::Ground => write!(f, "ground (class 2)"),
            Selection::AllButNoise => {
                write!(
                    f,
                    "all classes but noise (7, 18): the cloud has no ground class"
                )
            }
            Selection::Classes(s) => write!(f, "classes {s}"),
        }
    }
}

/// The chosen points' coordinates, in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Cloud {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
}

impl Cloud {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    pub fn push(&mut self, x: f64, y: f64, z: f64) {
        self.x.push(x);
        self.y.push(y);
        self.z.push(z);
    }

    fn clear(&mut self) {
        *self = Cloud::default();
    }
}

/// One file of a cloud.
#[derive(Clone, Debug, PartialEq)]
pub struct FileReport {
    pub source: String,
    pub version: (u8, u8),
    pub point_format: u8,
    pub compressed: bool,
    pub points: u64,
    pub crs_record: CrsRecord,
}

/// What [`read_cloud`] read and chose.
#[derive(Clone, Debug, PartialEq)]
pub struct CloudReport {
    pub files: Vec<FileReport>,
    /// The files' names joined by ` + `, as errors and the grid name them.
    pub source: String,
    pub points_read: u64,
    pub withheld: u64,
    /// Points per class (classes present only), withheld points included.
    pub classes: Vec<(u8, u64)>,
    pub selection: Selection,
    pub points_used: u64,
    pub crs: CrsKind,
    pub epsg: Option<u16>,
}

/// What [`grid_cloud`] made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridReport {
    pub cell: f64,
    /// The cell was chosen by [`auto_cell`].
    pub cell_auto: bool,
    pub radius: f64,
    pub width: u32,
    pub height: u32,
    /// Cells no point reached.
    pub empty_cells: u64,
    /// Of those, the cells the window fill gave a value.
    pub filled_cells: u64,
}

/// Read and choose the points of `paths` (one cloud; see the module docs).
pub fn read_cloud(
    paths: &[PathBuf],
    opts: &LidarOptions,
) -> Result<(Cloud, CloudReport), TerrainError> {
    let source = paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(" + ");
    if paths.is_empty() {
        return Err(TerrainError::BadParameter {
            name: "point clouds",
            value: "none".into(),
            expected: "at least one LAS or LAZ file",
        });
    }
    let mut files = Vec::with_capacity(paths.len());
    let mut counts = vec![0u64; 256];
    let (mut read, mut withheld) = (0u64, 0u64);
    // The default rule keeps ground and, until the first ground point, the other non-noise
    // points in case there is none.
    let (mut chosen, mut others) = (Cloud::default(), Cloud::default());
    let mut any_ground = false;
    let mut system: Option<(CrsKind, Option<u16>, String)> = None;
    let mut batch: Vec<LasPoint> = Vec::with_capacity(super::las::BATCH);
    for path in paths {
        let mut r = LasReader::open(path)?;
        let h = r.header().clone();
        match &system {
            None => system = Some((h.crs, h.epsg, r.source().to_string())),
            Some((crs, epsg, first)) if (*crs, *epsg) != (h.crs, h.epsg) => {
                let name = |c: CrsKind, e: Option<u16>| match e {
                    Some(e) => format!("EPSG:{e}"),
                    None => format!("{c:?}").to_lowercase(),
                };
                return Err(TerrainError::Unsupported {
                    source: r.source().to_string(),
                    what: format!(
                        "joining a cloud in {} to {first} in {}: the tiles of one grid need one \
                         coordinate system; reproject it first",
                        name(h.crs, h.epsg),
                        name(*crs, *epsg)
                    ),
                });
            }
            Some(_) => {}
        }
        if h.crs == CrsKind::Geographic {
            return Err(TerrainError::Unsupported {
                source: r.source().to_string(),
                what: format!(
                    "a cloud in longitude and latitude degrees ({}): grid cells must be square \
                     metres; reproject it to a projected system first (e.g. pdal translate \
                     in.laz out.laz reprojection --filters.reprojection.out_srs=EPSG:326NN)",
                    h.epsg.map(|e| format!("EPSG:{e}")).unwrap_or_default()
                ),
            });
        }
        while r.read_batch(&mut batch)? > 0 {
            for p in &batch {
                counts[p.class as usize] += 1;
                if p.withheld {
                    withheld += 1;
                    continue;
                }
                if opts.last_returns && !p.is_last_return() {
                    continue;
                }
                match opts.classes {
                    Some(set) if set.contains(p.class) => chosen.push(p.x, p.y, p.z),
                    Some(_) => {}
                    None if p.class == 2 => {
                        if !any_ground {
                            any_ground = true;
                            others.clear();
                        }
                        chosen.push(p.x, p.y, p.z);
                    }
                    None if !any_ground && p.class != 7 && p.class != 18 => {
                        others.push(p.x, p.y, p.z)
                    }
                    None => {}
                }
            }
            read += batch.len() as u64;
            if chosen.len() + others.len() >= u32::MAX as usize {
                return Err(TerrainError::Unsupported {
                    source: r.source().to_string(),
                    what: "more than 2^32 - 1 points in one grid: grid the tiles in groups".into(),
                });
            }
        }
        files.push(FileReport {
            source: r.source().to_string(),
            version: h.version,
            point_format: h.point_format,
            compressed: h.compressed,
            points: r.points_read(),
            crs_record: h.crs_record,
        });
    }
    let selection = match opts.classes {
        Some(set) => Selection::Classes(set),
        None if any_ground => Selection::Ground,
        None => {
            chosen = std::mem::take(&mut others);
            Selection::AllButNoise
        }
    };
    let classes: Vec<(u8, u64)> = counts
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(c, &n)| (c as u8, n))
        .collect();
    if chosen.is_empty() {
        let found = classes
            .iter()
            .map(|(c, n)| format!("class {c}: {n}"))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(format_err(
            &source,
            "points",
            format!(
                "at least one point of {selection}{}{} (found {read} points: {})",
                if opts.last_returns {
                    ", last returns"
                } else {
                    ""
                },
                if withheld > 0 {
                    format!(", not withheld ({withheld} are)")
                } else {
                    String::new()
                },
                if found.is_empty() {
                    "none".into()
                } else {
                    found
                }
            ),
        ));
    }
    let (crs, epsg, _) = system.expect("one file was read");
    let points_used = chosen.len() as u64;
    Ok((
        chosen,
        CloudReport {
            files,
            source,
            points_read: read,
            withheld,
            classes,
            selection,
            points_used,
            crs,
            epsg,
        },
    ))
}

/// A cell side for `cloud`: about two points per cell over the area the points cover, rounded
/// to the nearest (in ratio) of 1, 2 or 5 times a power of ten. The covered area is that of the
/// occupied cells of a probe grid of about sixteen points per cell, so gaps between flight
/// strips or a cloud clipped to a polygon do not thin the estimate. `None` for fewer than 2
/// points or points on a line.
pub fn auto_cell(cloud: &Cloud) -> Option<f64> {
    let n = cloud.len();
    if n < 2 {
        return None;
    }
    let (x0, x1, y0, y1) = bounds(cloud);
    let area = (x1 - x0) * (y1 - y0);
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    // Probe cells of ~16 points if the points were spread evenly.
    let s = (area / n as f64).sqrt() * 4.0;
    let pw = ((x1 - x0) / s).floor() as usize + 1;
    let ph = ((y1 - y0) / s).floor() as usize + 1;
    let mut occupied = vec![false; pw * ph];
    for (&x, &y) in cloud.x.iter().zip(&cloud.y) {
        let (c, r) = (
            (((x - x0) / s) as usize).min(pw - 1),
            (((y - y0) / s) as usize).min(ph - 1),
        );
        occupied[r * pw + c] = true;
    }
    let covered = occupied.iter().filter(|&&o| o).count() as f64 * s * s;
    let side = (2.0 * covered / n as f64).sqrt();
    Some(nice(side))
}

/// The value of the 1–2–5 series nearest to `v` in ratio.
fn nice(v: f64) -> f64 {
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .min_by(|a, b| (a / v).ln().abs().total_cmp(&(b / v).ln().abs()))
        .expect("four candidates")
}

fn bounds(cloud: &Cloud) -> (f64, f64, f64, f64) {
    let fold = |v: &[f64]| {
        v.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &a| {
                (lo.min(a), hi.max(a))
            })
    };
    let (x0, x1) = fold(&cloud.x);
    let (y0, y1) = fold(&cloud.y);
    (x0, x1, y0, y1)
}

/// Read `paths` as one cloud and grid it (see the module docs).
pub fn read_lidar(
    paths: &[PathBuf],
    opts: &LidarOptions,
) -> Result<(Grid, CloudReport, GridReport), TerrainError> {
    let (cloud, report) = read_cloud(paths, opts)?;
    let (grid, g) = grid_cloud(&cloud, &report.source, report.crs, report.epsg, opts)?;
    Ok((grid, report, g))
}

/// Grid `cloud` (coordinates in a system of kind `crs`, EPSG code `epsg`; `source` names it in
/// errors) by `opts` (see the module docs).
pub fn grid_cloud(
    cloud: &Cloud,
    source: &str,
    crs: CrsKind,
    epsg: Option<u16>,
    opts: &LidarOptions,
) -> Result<(Grid, GridReport), TerrainError> {
    let (cell, cell_auto) = match opts.cell {
        Some(c) => (c, false),
        None => (
            auto_cell(cloud).ok_or_else(|| {
                format_err(
                    source,
                    "points",
                    format!(
                        "points spread over an area to choose a cell size from ({} chosen); \
                         give the cell size",
                        cloud.len()
                    ),
                )
            })?,
            true,
        ),
    };
    if !(cell.is_finite() && cell > 0.0) {
        return Err(TerrainError::BadParameter {
            name: "lidar cell",
            value: cell.to_string(),
            expected: "a cell side > 0 in the cloud's units (metres)",
        });
    }
    let radius = opts.radius.unwrap_or(cell * std::f64::consts::SQRT_2);
    if !(radius.is_finite() && radius > 0.0 && radius <= MAX_REACH as f64 * cell) {
        return Err(TerrainError::BadParameter {
            name: "lidar radius",
            value: radius.to_string(),
            expected: "a radius > 0 of at most 100 cells",
        });
    }
    if !(opts.power.is_finite() && opts.power > 0.0) {
        return Err(TerrainError::BadParameter {
            name: "lidar power",
            value: opts.power.to_string(),
            expected: "an inverse-distance power > 0 (PDAL's default 1, gdal_grid's 2)",
        });
    }
    if opts.fill > MAX_REACH {
        return Err(TerrainError::BadParameter {
            name: "lidar fill",
            value: opts.fill.to_string(),
            expected: "a window of 0 to 100 cells",
        });
    }
    if cloud.is_empty() || cloud.y.len() != cloud.len() || cloud.z.len() != cloud.len() {
        return Err(format_err(
            source,
            "points",
            "at least one point, with x, y and z each",
        ));
    }
    if let Some(i) = (0..cloud.len())
        .find(|&i| !(cloud.x[i].is_finite() && cloud.y[i].is_finite() && cloud.z[i].is_finite()))
    {
        return Err(format_err(
            source,
            format!("point {i}"),
            "finite coordinates",
        ));
    }

    // Lattice: columns k·c .. (k+1)·c from the cell of the westernmost point.
    let (x0, x1, y0, y1) = bounds(cloud);
    let (kx0, ky0) = ((x0 / cell).floor(), (y0 / cell).floor());
    let w = ((x1 / cell).floor() - kx0 + 1.0).max(2.0);
    let h = ((y1 / cell).floor() - ky0 + 1.0).max(2.0);
    if w * h > MAX_SAMPLES as f64 || w.max(h) > MAX_SIDE as f64 {
        return Err(TerrainError::BadSize {
            source: source.to_string(),
            width: w.min(u64::MAX as f64) as u64,
            height: h.min(u64::MAX as f64) as u64,
            reason: "more than 2^30 cells or a side longer than 32768 at this cell size: choose \
                     a larger cell, or grid the tiles in groups",
        });
    }
    let (w, h) = (w as usize, h as usize);
    let cells = w * h;

    // Sort the points into their home cells (stable: file order within a cell).
    let home: Vec<u32> = cloud
        .x
        .par_iter()
        .zip(&cloud.y)
        .map(|(&x, &y)| {
            let col = ((x / cell).floor() - kx0) as usize;
            let row = (ky0 + (h - 1) as f64 - (y / cell).floor()) as usize;
            debug_assert!(col < w && row < h);
            (row.min(h - 1) * w + col.min(w - 1)) as u32
        })
        .collect();
    let mut start = vec![0u32; cells + 1];
    for &c in &home {
        start[c as usize + 1] += 1;
    }
    for i in 0..cells {
        start[i + 1] += start[i];
    }
    // Scatter the point indices (4 bytes a point, the one sequential pass), then gather the
    // coordinates in that order in parallel.
    let mut order = vec![0u32; cloud.len()];
    {
        let mut next: Vec<u32> = start[..cells].to_vec();
        for (i, &c) in home.iter().enumerate() {
            let at = &mut next[c as usize];
            order[*at as usize] = i as u32;
            *at += 1;
        }
    }
    drop(home);
    let take = |v: &[f64]| -> Vec<f64> { order.par_iter().map(|&i| v[i as usize]).collect() };
    let (px, py, pz) = (take(&cloud.x), take(&cloud.y), take(&cloud.z));
    drop(order);

    // Home cells within `reach` of a cell can hold points within the radius of its centre: a
    // point `k` cells away is at least `(k − ½)·c` from it.
    let reach = ((radius / cell - 0.5 + 1e-6).ceil().max(0.0) as usize).min(MAX_REACH as usize);
    let pts = Points {
        x: &px,
        y: &py,
        z: &pz,
        start: &start,
        w,
        h,
        west: kx0 * cell,
        south: ky0 * cell,
        cell,
        reach,
        radius,
    };
    let (origin_x, origin_y) = (pts.centre_x(0), pts.centre_y(0));
    let mut values = vec![f64::NAN; cells];
    let mut counts = vec![0u32; cells];
    match opts.method {
        LidarMethod::Mean => gather::<Mean>(&pts, opts.power, &mut values, &mut counts),
        LidarMethod::Min => gather::<Min>(&pts, opts.power, &mut values, &mut counts),
        LidarMethod::Max => gather::<Max>(&pts, opts.power, &mut values, &mut counts),
        LidarMethod::Idw => gather::<Idw>(&pts, opts.power, &mut values, &mut counts),
        LidarMethod::Count => gather::<Count>(&pts, opts.power, &mut values, &mut counts),
        LidarMethod::Stdev => gather::<Stdev>(&pts, opts.power, &mut values, &mut counts),
    }
    if opts.method == LidarMethod::Count {
        // A count is a value everywhere: no point is 0 points.
        values.iter_mut().for_each(|v| *v = v.max(0.0));
    }
    drop((px, py, pz, start));
    let empty_cells = counts.iter().filter(|&&c| c == 0).count() as u64;
    let mut filled_cells = 0;
    if opts.fill > 0 && empty_cells > 0 {
        let filled = window_fill(&values, &counts, w, h, opts.fill as usize);
        filled_cells = filled
            .iter()
            .zip(&counts)
            .filter(|(v, c)| **c == 0 && !v.is_nan())
            .count() as u64;
        values = filled;
    }
    let heights: Vec<f32> = values.par_iter().map(|&v| v as f32).collect();
    let georef = Georef {
        crs,
        epsg,
        origin_x,
        origin_y,
        dx: cell,
        dy: -cell,
    };
    let grid = Grid::new(source, w as u32, h as u32, heights, georef)?;
    Ok((
        grid,
        GridReport {
            cell,
            cell_auto,
            radius,
            width: w as u32,
            height: h as u32,
            empty_cells,
            filled_cells,
        },
    ))
}

/// The points sorted by home cell (row-major, row 0 the north), and the gather's reach.
struct Points<'a> {
    x: &'a [f64],
    y: &'a [f64],
    z: &'a [f64],
    /// Cell `i`'s points are `start[i]..start[i + 1]`.
    start: &'a [u32],
    w: usize,
    h: usize,
    /// The grid's west and south edges, and the cell side.
    west: f64,
    south: f64,
    cell: f64,
    reach: usize,
    radius: f64,
}

impl Points<'_> {
    /// PDAL's cell centres, `origin + (i + ½)·c` from the south-west corner.
    fn centre_x(&self, col: usize) -> f64 {
        self.west + (col as f64 + 0.5) * self.cell
    }

    fn centre_y(&self, row: usize) -> f64 {
        self.south + ((self.h - 1 - row) as f64 + 0.5) * self.cell
    }
}

/// One cell's running statistic over the points within the radius of its centre.
trait Accumulate: Default {
    /// Add the height `z` of a point at distance `d` (< radius) from the centre.
    fn add(&mut self, z: f64, d: f64, power: f64);
    /// The cell's value (called only when a point was added).
    fn value(&self) -> f64;
}

#[derive(Default)]
struct Mean(f64, u32);
impl Accumulate for Mean {
    fn add(&mut self, z: f64, _: f64, _: f64) {
        self.0 += z;
        self.1 += 1;
    }
    fn value(&self) -> f64 {
        self.0 / self.1 as f64
    }
}

struct Min(f64);
impl Default for Min {
    fn default() -> Self {
        Min(f64::INFINITY)
    }
}
impl Accumulate for Min {
    fn add(&mut self, z: f64, _: f64, _: f64) {
        self.0 = self.0.min(z);
    }
    fn value(&self) -> f64 {
        self.0
    }
}

struct Max(f64);
impl Default for Max {
    fn default() -> Self {
        Max(f64::NEG_INFINITY)
    }
}
impl Accumulate for Max {
    fn add(&mut self, z: f64, _: f64, _: f64) {
        self.0 = self.0.max(z);
    }
    fn value(&self) -> f64 {
        self.0
    }
}

/// PDAL's `GDALGrid::update` for `idw`: `Σ z/dᵖ` and `Σ 1/dᵖ`, or the height of the first point
/// exactly on the centre.
#[derive(Default)]
struct Idw {
    num: f64,
    den: f64,
    exact: Option<f64>,
}
impl Accumulate for Idw {
    fn add(&mut self, z: f64, d: f64, power: f64) {
        if self.exact.is_some() {
            return;
        }
        if d == 0.0 {
            self.exact = Some(z);
            return;
        }
        let dp = if power == 1.0 { d } else { d.powf(power) };
        self.num += z / dp;
        self.den += 1.0 / dp;
    }
    fn value(&self) -> f64 {
        self.exact.unwrap_or(self.num / self.den)
    }
}

/// How many points.
#[derive(Default)]
struct Count(u32);
impl Accumulate for Count {
    fn add(&mut self, _: f64, _: f64, _: f64) {
        self.0 += 1;
    }
    fn value(&self) -> f64 {
        self.0 as f64
    }
}

/// The population standard deviation, by Welford's update (mean and sum of squared deviations),
/// which loses no digits to heights far from zero.
#[derive(Default)]
struct Stdev {
    n: u32,
    mean: f64,
    m2: f64,
}
impl Accumulate for Stdev {
    fn add(&mut self, z: f64, _: f64, _: f64) {
        self.n += 1;
        let d = z - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (z - self.mean);
    }
    fn value(&self) -> f64 {
        (self.m2 / self.n as f64).sqrt()
    }
}

/// Every cell's value and point count, a row of cells per task.
fn gather<A: Accumulate>(p: &Points, power: f64, values: &mut [f64], counts: &mut [u32]) {
    let (w, h, k) = (p.w, p.h, p.reach);
    values
        .par_chunks_mut(w)
        .zip(counts.par_chunks_mut(w))
        .enumerate()
        .for_each(|(row, (vals, cnts))| {
            let cy = p.centre_y(row);
            let (r0, r1) = (row.saturating_sub(k), (row + k).min(h - 1));
            for col in 0..w {
                let cx = p.centre_x(col);
                let (c0, c1) = (col.saturating_sub(k), (col + k).min(w - 1));
                let mut acc = A::default();
                let mut n = 0u32;
                for rr in r0..=r1 {
                    // The home cells c0..=c1 of a row are one run of the sorted points.
                    let (a, b) = (
                        p.start[rr * w + c0] as usize,
                        p.start[rr * w + c1 + 1] as usize,
                    );
                    for i in a..b {
                        // PDAL's GDALGrid::distance: √((x₁ − x)² + (y₁ − y)²) < radius.
                        let (dx, dy) = (cx - p.x[i], cy - p.y[i]);
                        let d = (dx * dx + dy * dy).sqrt();
                        if d < p.radius {
                            acc.add(p.z[i], d, power);
                            n += 1;
                        }
                    }
                }
                if n > 0 {
                    vals[col] = acc.value();
                }
                cnts[col] = n;
            }
        });
}

/// PDAL's `GDALGrid::windowFill`: each empty cell the `1/d`-weighted mean of the non-empty cells
/// within `n` cells (Chebyshev distance `d`), summed in PDAL's order (columns west to east, each
/// from south to north); no-data when there is none.
fn window_fill(values: &[f64], counts: &[u32], w: usize, h: usize, n: usize) -> Vec<f64> {
    let mut out = values.to_vec();
    out.par_chunks_mut(w).enumerate().for_each(|(row, dst)| {
        for col in 0..w {
            if counts[row * w + col] != 0 {
                continue;
            }
            let (c0, c1) = (col.saturating_sub(n), (col + n).min(w - 1));
            let (r0, r1) = (row.saturating_sub(n), (row + n).min(h - 1));
            let (mut sum, mut weights) = (0.0f64, 0.0f64);
            for c in c0..=c1 {
                for r in (r0..=r1).rev() {
                    let i = r * w + c;
                    if counts[i] == 0 {
                        continue;
                    }
                    let d = c.abs_diff(col).max(r.abs_diff(row)) as f64;
                    sum += values[i] / d;
                    weights += 1.0 / d;
                }
            }
            dst[col] = if weights > 0.0 {
                sum / weights
            } else {
                f64::NAN
            };
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(cell: f64, method: LidarMethod) -> LidarOptions {
        LidarOptions {
            cell: Some(cell),
            method,
            ..LidarOptions::default()
        }
    }

    #[test]
    fn the_lattice_is_aligned_and_points_count_within_the_radius() {
        let mut c = Cloud::default();
        // Cells of 10: the points span columns 31..=33 and rows 40..=41 of the lattice.
        c.push(315.0, 405.0, 1.0); // on the centre of (31, 40)
        c.push(325.0, 405.0, 3.0); // on the centre of (32, 40)
        c.push(333.0, 419.0, 5.0);
        let (g, r) = grid_cloud(
            &c,
            "t",
            CrsKind::Local,
            None,
            &opts(10.0, LidarMethod::Mean),
        )
        .unwrap();
        assert_eq!((r.width, r.height), (3, 2));
        let geo = g.georef();
        assert_eq!(
            (geo.origin_x, geo.origin_y, geo.dx, geo.dy),
            (315.0, 415.0, 10.0, -10.0)
        );
        // (31, 40) is row 1, column 0: the first two points (0 and 10 away; the third is
        // 23 away, beyond 10·√2).
        assert_eq!(g.at(0, 1), 2.0);
        // (32, 41), row 0 column 1: centre (325, 415): 10 from the second point, √200 = R from
        // the first (not counted: d < R), 8.9 from the third.
        assert_eq!(g.at(1, 0), 4.0);
        let (g, _) =
            grid_cloud(&c, "t", CrsKind::Local, None, &opts(10.0, LidarMethod::Idw)).unwrap();
        assert_eq!(g.at(0, 1), 1.0, "a point on the centre gives its height");
        let (g, _) =
            grid_cloud(&c, "t", CrsKind::Local, None, &opts(10.0, LidarMethod::Max)).unwrap();
        assert_eq!(g.at(2, 0), 5.0);
    }

    #[test]
    fn empty_cells_are_no_data_or_window_filled() {
        let mut c = Cloud::default();
        for (x, z) in [(5.0, 10.0), (95.0, 20.0)] {
            c.push(x, 5.0, z);
            c.push(x, 45.0, z);
        }
        let o = opts(10.0, LidarMethod::Mean);
        let (g, r) = grid_cloud(&c, "t", CrsKind::Local, None, &o).unwrap();
        assert_eq!((r.width, r.height), (10, 5));
        assert!(g.at(5, 2).is_nan());
        assert!(r.empty_cells > 0 && r.filled_cells == 0);
        let (g, r) = grid_cloud(
            &c,
            "t",
            CrsKind::Local,
            None,
            &LidarOptions { fill: 4, ..o },
        )
        .unwrap();
        // Column 4, row 2: the cells of column 1 (3 away) hold 10; column 8 (4 away) holds 20.
        let v = g.at(4, 2);
        assert!(v > 10.0 && v < 20.0, "{v}");
        assert!(r.filled_cells > 0);
    }

    #[test]
    fn auto_cell_gives_about_two_points_per_cell() {
        let mut c = Cloud::default();
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        // 20 000 points over 100 x 100 m: 2 per m², so 1 m cells.
        for _ in 0..20_000 {
            c.push(rnd() * 100.0, rnd() * 100.0, 0.0);
        }
        assert_eq!(auto_cell(&c), Some(1.0));
        assert_eq!(nice(3.3), 5.0);
        assert_eq!(nice(3.1), 2.0);
        assert_eq!(nice(0.7), 0.5);
    }

    #[test]
    fn class_sets_parse() {
        let s = ClassSet::parse("2, 9").unwrap();
        assert!(s.contains(2) && s.contains(9) && !s.contains(3));
        assert_eq!(s.to_string(), "2,9");
        assert!(ClassSet::parse("2,x").is_err());
        assert!(ClassSet::parse("256").is_err());
    }
}
