//! ESRI ASCII grid (`.asc`): a header of `key value` lines — `ncols`, `nrows`, `xllcorner` or
//! `xllcenter`, `yllcorner` or `yllcenter`, `cellsize` or `dx`/`dy` (GDAL writes the pair for
//! non-square cells), optional `NODATA_value` — then `nrows` rows of `ncols` numbers, north row
//! first. Keys are case-insensitive. `*llcorner` is the outer corner of the lower-left cell, so the
//! lower-left sample centre is half a cell inside it; `*llcenter` is that centre itself.
//! The coordinate system is not in the file (it is in a `.prj` beside it when at all), so the
//! grid's [`CrsKind`] is `Local` (metres assumed).

use super::{CrsKind, Georef, Grid, check_size};
use crate::error::{TerrainError, format_err, io};
use std::path::Path;

/// Read an ESRI ASCII grid from a file.
pub fn read_asc(path: &Path) -> Result<Grid, TerrainError> {
    let text = std::fs::read_to_string(path).map_err(io(path))?;
    read_asc_str(&text, &path.display().to_string())
}

/// Read an ESRI ASCII grid from text; `source` names it in errors.
pub fn read_asc_str(text: &str, source: &str) -> Result<Grid, TerrainError> {
    let mut ncols = None;
    let mut nrows = None;
    let mut xll = None; // (value, is_center)
    let mut yll = None;
    let mut cell = None;
    let mut dx = None;
    let mut dy = None;
    let mut nodata = None;
    let mut lines = text.lines().enumerate().peekable();
    // Header: lines whose first token starts with a letter.
    while let Some(&(n, line)) = lines.peek() {
        let mut it = line.split_whitespace();
        let Some(key) = it.next() else {
            lines.next();
            continue;
        };
        if !key.starts_with(|c: char| c.is_ascii_alphabetic()) {
            break;
        }
        let value = it.next().ok_or_else(|| {
            format_err(
                source,
                format!("line {}", n + 1),
                format!("a value after {key}"),
            )
        })?;
        let num = |v: &str| -> Result<f64, TerrainError> {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    format_err(
                        source,
                        format!("line {}", n + 1),
                        format!("a finite number for {key}, got {v:?}"),
                    )
                })
        };
        match key.to_ascii_lowercase().as_str() {
            "ncols" => ncols = Some(num(value)?),
            "nrows" => nrows = Some(num(value)?),
            "xllcorner" => xll = Some((num(value)?, false)),
            "xllcenter" => xll = Some((num(value)?, true)),
            "yllcorner" => yll = Some((num(value)?, false)),
            "yllcenter" => yll = Some((num(value)?, true)),
            "cellsize" => cell = Some(num(value)?),
            "dx" => dx = Some(num(value)?),
            "dy" => dy = Some(num(value)?),
            "nodata_value" => nodata = Some(num(value)?),
            other => {
                return Err(format_err(
                    source,
                    format!("line {}", n + 1),
                    format!(
                        "a header key (ncols, nrows, xllcorner, yllcorner, cellsize, dx, dy, NODATA_value), got {other:?}"
                    ),
                ));
            }
        }
        lines.next();
    }
    let need = |v: Option<f64>, k: &str| {
        v.ok_or_else(|| format_err(source, "header", format!("the {k} key")))
    };
    let ncols = need(ncols, "ncols")?;
    let nrows = need(nrows, "nrows")?;
    if ncols.fract() != 0.0 || nrows.fract() != 0.0 || ncols < 0.0 || nrows < 0.0 {
        return Err(format_err(
            source,
            "header",
            format!("whole ncols and nrows, got {ncols} and {nrows}"),
        ));
    }
    let (w, h) = (ncols as u64, nrows as u64);
    check_size(source, w, h)?;
    let (cx, cy) = match (cell, dx, dy) {
        (Some(c), _, _) => (c, c),
        (None, Some(a), Some(b)) => (a, b),
        _ => return Err(format_err(source, "header", "cellsize, or dx and dy")),
    };
    if cx <= 0.0 || cy <= 0.0 {
        return Err(format_err(
            source,
            "header",
            format!("positive cell sizes, got {cx} and {cy}"),
        ));
    }
    let (xv, xc) = xll.ok_or_else(|| format_err(source, "header", "xllcorner or xllcenter"))?;
    let (yv, yc) = yll.ok_or_else(|| format_err(source, "header", "yllcorner or yllcenter"))?;
    let x0 = if xc { xv } else { xv + 0.5 * cx };
    let y_ll = if yc { yv } else { yv + 0.5 * cy };
    let georef = Georef {
        crs: CrsKind::Local,
        epsg: None,
        origin_x: x0,
        origin_y: y_ll + (h - 1) as f64 * cy,
        dx: cx,
        dy: -cy,
    };
    // Every value takes at least two characters: reserve no more than the text can hold.
    let mut heights = Vec::with_capacity((w * h).min(text.len() as u64 / 2 + 1) as usize);
    for (n, line) in lines {
        for tok in line.split_whitespace() {
            if heights.len() as u64 == w * h {
                return Err(format_err(
                    source,
                    format!("line {}", n + 1),
                    format!("{} values in all, found more", w * h),
                ));
            }
            let v: f64 = tok.parse().map_err(|_| {
                format_err(
                    source,
                    format!("line {}", n + 1),
                    format!("a number, got {tok:?}"),
                )
            })?;
            if !v.is_finite() {
                let i = heights.len() as u64;
                return Err(TerrainError::NonFinite {
                    source: source.into(),
                    col: (i % w) as u32,
                    row: (i / w) as u32,
                });
            }
            heights.push(v as f32);
        }
    }
    if (heights.len() as u64) < w * h {
        return Err(format_err(
            source,
            "end of file",
            format!("{} values, found {}", w * h, heights.len()),
        ));
    }
    Grid::from_samples(source, w as u32, h as u32, heights, nodata, false, georef)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corner_vs_center_and_nodata() {
        let t = "ncols 3\nnrows 2\nxllcorner 100\nyllcorner 200\ncellsize 10\nNODATA_value -9999\n1 2 3\n4 -9999 6\n";
        let g = read_asc_str(t, "t.asc").unwrap();
        assert_eq!((g.georef().origin_x, g.georef().origin_y), (105.0, 215.0));
        assert!(g.at(1, 1).is_nan());
        assert_eq!(g.at(2, 1), 6.0);
        let t2 = t
            .replace("xllcorner 100", "xllcenter 105")
            .replace("yllcorner 200", "yllcenter 205");
        assert_eq!(read_asc_str(&t2, "t").unwrap().georef(), g.georef());
    }

    #[test]
    fn errors_name_the_line() {
        let e = read_asc_str(
            "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 x\n",
            "a.asc",
        )
        .unwrap_err();
        assert_eq!(e.to_string(), "a.asc: line 7: expected a number, got \"x\"");
        let e = read_asc_str(
            "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3\n",
            "a.asc",
        )
        .unwrap_err();
        assert!(e.to_string().contains("4 values, found 3"), "{e}");
        let e = read_asc_str(
            "ncols 99999999\nnrows 99999999\nxllcorner 0\nyllcorner 0\ncellsize 1\n",
            "a.asc",
        )
        .unwrap_err();
        assert!(matches!(e, TerrainError::BadSize { .. }), "{e}");
    }
}
