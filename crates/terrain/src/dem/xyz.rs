//! Gridded XYZ text (`.xyz`): one line per sample, `x y z` at the sample's centre, as GDAL's XYZ
//! driver writes (`gdal_translate -of XYZ`) and as many national mapping agencies ship their lidar
//! DEMs (the German states' DGM1 tiles, for one).
//!
//! - Columns are separated by spaces, tabs, commas or semicolons; with semicolons a decimal comma
//!   is read as a point (`350000,5;5650000,5;123,45`, spreadsheet exports).
//! - An optional header line names the columns: the first whose name starts with `x`, `lon` or
//!   `east` is X, `y`, `lat` or `north` Y, `z`, `alt`, `height` or `elev` Z (GDAL's rule); without
//!   one, X, Y, Z are the first three columns. Further columns are ignored.
//! - Lines may come in any order (GDAL wants rows of one Y with X increasing, or columns of one
//!   X). The spacing is the smallest step between distinct X (Y) values, evened over the whole
//!   extent so that coordinates printed with few digits still fit; every sample must lie within
//!   1 % of a step from its lattice point, and no two on one point.
//! - Samples the file does not list are no-data (GDAL reads them as 0), and so are `nan` and the
//!   usual markers −9999, −32767 and −32768, and anything below −11,000 m, a height no place on
//!   Earth has (GDAL keeps such values as heights: the format has no no-data field). A file
//!   listing fewer than one sample in 64 of its lattice is refused as scattered points
//!   (`gdal_grid` or a lidar cloud grids those).
//! - The coordinate system comes from a `.prj` beside the file (ESRI or OGC WKT 1, read as for
//!   GridFloat); without one the grid is `Local` (metres assumed).
//!
//! Memory is the file's text and 24 bytes a sample line, both bounded by the file's size: nothing is
//! sized from a claim.

use super::{CrsKind, Georef, Grid, check_size};
use crate::error::{TerrainError, format_err, io};
use std::borrow::Cow;
use std::path::Path;

/// Read a gridded XYZ file, with the `.prj` beside it when there is one.
pub fn read_xyz(path: &Path) -> Result<Grid, TerrainError> {
    let source = path.display().to_string();
    let text = std::fs::read(path).map_err(io(path))?;
    let text = String::from_utf8_lossy(&text);
    let prj_path = ["prj", "PRJ"]
        .iter()
        .map(|e| path.with_extension(e))
        .find(|p| p.is_file());
    let system = match &prj_path {
        Some(p) => {
            let wkt = std::fs::read(p).map_err(io(p))?;
            super::ehdr::crs_of_prj(&String::from_utf8_lossy(&wkt), &p.display().to_string())?
        }
        None => (CrsKind::Local, None),
    };
    read_xyz_str(&text, &source, system)
}

/// Read gridded XYZ text; `source` names it in errors, `system` is its coordinate system.
pub fn read_xyz_str(
    text: &str,
    source: &str,
    system: (CrsKind, Option<u16>),
) -> Result<Grid, TerrainError> {
    let at = |n: usize| format!("line {}", n + 1);
    let mut columns = [0usize, 1, 2];
    let mut points: Vec<(f64, f64, f32, u32)> = Vec::new(); // x, y, z, line
    let mut first = true;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let fields = split(line);
        if std::mem::take(&mut first) && fields.first().is_some_and(|f| number(f).is_none()) {
            columns = header_columns(&fields);
            continue;
        }
        let mut v = [0.0f64; 3];
        for (k, &c) in columns.iter().enumerate() {
            let f = fields.get(c).ok_or_else(|| {
                format_err(
                    source,
                    at(n),
                    format!("at least {} columns (x y z), got {}", c + 1, fields.len()),
                )
            })?;
            v[k] = number(f)
                .filter(|x| k == 2 || x.is_finite())
                .ok_or_else(|| {
                    format_err(
                        source,
                        at(n),
                        format!("a number for {}, got {f:?}", ["x", "y", "z"][k]),
                    )
                })?;
        }
        let z = v[2];
        let z = if z.is_nan() || z == -9999.0 || z == -32767.0 || z == -32768.0 || z < -11000.0 {
            f32::NAN
        } else if (z as f32).is_finite() {
            z as f32
        } else {
            return Err(format_err(source, at(n), format!("a height, got {z}")));
        };
        points.push((v[0], v[1], z, n as u32));
    }
    if points.len() < 4 {
        return Err(format_err(
            source,
            "the samples",
            format!(
                "at least 4 x y z lines (a 2 x 2 grid), got {}",
                points.len()
            ),
        ));
    }
    let (x0, dx, width) = lattice(points.iter().map(|p| p.0), source, "x")?;
    let (y0, dy, height) = lattice(points.iter().map(|p| p.1), source, "y")?;
    check_size(source, width, height)?;
    let cells = width * height;
    if cells > 64 * points.len() as u64 {
        return Err(format_err(
            source,
            "the samples",
            format!(
                "a grid: {} lines spread over {width} x {height} lattice points are scattered \
                 points (grid them first, e.g. with gdal_grid)",
                points.len()
            ),
        ));
    }
    let mut heights = vec![f32::NAN; cells as usize];
    let mut set = vec![false; cells as usize];
    // Rows run north to south: row 0 is the largest Y.
    let top = y0 + (height - 1) as f64 * dy;
    for &(x, y, z, line) in &points {
        let line = line as usize;
        let (c, r) = (
            ((x - x0) / dx).round() as u64,
            ((top - y) / dy).round() as u64,
        );
        let off = ((x - x0) / dx - c as f64)
            .abs()
            .max(((top - y) / dy - r as f64).abs());
        if off > 0.01 {
            return Err(format_err(
                source,
                at(line),
                format!(
                    "a sample on the lattice of {dx} x {dy} steps from ({x0}, {top}), \
                     ({x}, {y}) lies {:.0} % of a step off it",
                    off * 100.0
                ),
            ));
        }
        let k = (r * width + c) as usize;
        if std::mem::replace(&mut set[k], true) {
            return Err(format_err(
                source,
                at(line),
                format!("one line per sample, ({x}, {y}) is listed again"),
            ));
        }
        heights[k] = z;
    }
    let georef = Georef {
        crs: system.0,
        epsg: system.1,
        origin_x: x0,
        origin_y: top,
        dx,
        dy: -dy,
    };
    Grid::new(source, width as u32, height as u32, heights, georef)
}

/// The fields of a line: split at semicolons (with a decimal comma read as a point), else at
/// commas, else at spaces and tabs.
fn split(line: &str) -> Vec<Cow<'_, str>> {
    if line.contains(';') {
        line.split(';')
            .map(|f| match f.trim() {
                f if f.contains(',') => Cow::Owned(f.replace(',', ".")),
                f => Cow::Borrowed(f),
            })
            .collect()
    } else if line.contains(',') {
        line.split(',').map(|f| Cow::Borrowed(f.trim())).collect()
    } else {
        line.split_whitespace().map(Cow::Borrowed).collect()
    }
}

fn number(f: &str) -> Option<f64> {
    f.parse::<f64>().ok()
}

/// The X, Y and Z columns a header line names (GDAL's names; the first three otherwise).
fn header_columns(names: &[Cow<'_, str>]) -> [usize; 3] {
    let find = |prefixes: &[&str], default: usize| {
        names
            .iter()
            .position(|n| {
                let n = n.trim_matches('"').to_ascii_lowercase();
                prefixes.iter().any(|p| n.starts_with(p))
            })
            .unwrap_or(default)
    };
    [
        find(&["x", "lon", "east"], 0),
        find(&["y", "lat", "north"], 1),
        find(&["z", "alt", "height", "elev"], 2),
    ]
}

/// The lattice of one coordinate: `(lowest, step, count)`. The step is the smallest difference
/// between distinct values, evened over the extent (`extent / round(extent / smallest)`).
fn lattice(
    values: impl Iterator<Item = f64>,
    source: &str,
    axis: &str,
) -> Result<(f64, f64, u64), TerrainError> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    let (lo, hi) = (v[0], v[v.len() - 1]);
    let smallest = v
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    if !(smallest.is_finite() && smallest > 0.0) || v.len() < 2 {
        return Err(format_err(
            source,
            "the samples",
            format!("at least two distinct {axis} values (a grid 2 samples wide)"),
        ));
    }
    let steps = ((hi - lo) / smallest).round();
    if !steps.is_finite() || steps >= (1u64 << 32) as f64 {
        return Err(format_err(
            source,
            "the samples",
            format!("a regular {axis} spacing: {lo} to {hi} in steps of {smallest}"),
        ));
    }
    Ok((lo, (hi - lo) / steps, steps as u64 + 1))
}
