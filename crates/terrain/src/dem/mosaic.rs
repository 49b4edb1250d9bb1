//! Mosaics: elevation grids that tile an area (SRTM's 1° tiles, a survey delivered in sheets)
//! joined into one grid, as `gdalbuildvrt` joins them.
//!
//! Every grid must share the first one's coordinate system (kind and EPSG code), cell size
//! (within 1e-6 of it) and lattice (sample centres within 1e-3 cells of the first grid's
//! lattice): joining never resamples, so every height is a height of one of the files. The
//! mosaic spans the union of the extents; samples no grid covers are no-data. Where grids
//! overlap (adjacent SRTM tiles share their edge row or column), the later grid's valid samples
//! win, as in `gdalbuildvrt`, and its no-data samples leave the earlier heights; each overlap is
//! reported ([`Overlap`]: how many samples, the largest difference), so nothing is replaced
//! silently.

use super::{Georef, Grid, check_size};
use crate::error::TerrainError;

/// Two grids of a mosaic covering the same samples with valid heights.
#[derive(Clone, Debug, PartialEq)]
pub struct Overlap {
    /// The later grid (whose heights are kept).
    pub later: String,
    /// Samples where both held a valid height.
    pub samples: u64,
    /// The largest absolute difference between them, metres.
    pub max_difference: f32,
}

fn crs_name(g: &Georef) -> String {
    match g.epsg {
        Some(e) => format!("EPSG:{e}"),
        None => format!("{:?}", g.crs).to_lowercase(),
    }
}

/// Join `parts` (each a name for errors and reports, and its grid) into one grid named
/// `parts[0].0 + parts[1].0 + ...` (see the module docs). One part is returned as it is; the
/// parts are dropped as they are copied.
pub fn mosaic(parts: Vec<(String, Grid)>) -> Result<(Grid, Vec<Overlap>), TerrainError> {
    let Some((first_name, first)) = parts.first() else {
        return Err(TerrainError::BadParameter {
            name: "elevation grids",
            value: "none".into(),
            expected: "at least one grid",
        });
    };
    let r = *first.georef();
    let unsupported = |name: &str, what: String| TerrainError::Unsupported {
        source: name.to_string(),
        what,
    };
    // Each part's sample (0, 0) on the first grid's lattice.
    let mut at = Vec::with_capacity(parts.len());
    for (name, g) in &parts {
        let q = g.georef();
        if q.crs != r.crs || q.epsg != r.epsg {
            return Err(unsupported(
                name,
                format!(
                    "joining a grid in {} to {first_name} in {}: a mosaic needs one coordinate \
                     system; reproject it first, e.g. gdalwarp -t_srs {}",
                    crs_name(q),
                    crs_name(&r),
                    crs_name(&r)
                ),
            ));
        }
        let same = |a: f64, b: f64| (a - b).abs() <= 1e-6 * b.abs();
        if !same(q.dx, r.dx) || !same(q.dy, r.dy) {
            return Err(unsupported(
                name,
                format!(
                    "joining cells of {} x {} to {first_name}'s {} x {}: a mosaic needs one cell \
                     size; resample it first, e.g. gdalwarp -tr {} {}",
                    q.dx,
                    q.dy.abs(),
                    r.dx,
                    r.dy.abs(),
                    r.dx,
                    r.dy.abs()
                ),
            ));
        }
        let (c, w) = (
            (q.origin_x - r.origin_x) / r.dx,
            (q.origin_y - r.origin_y) / r.dy,
        );
        let off = (c - c.round()).abs().max((w - w.round()).abs());
        if off.is_nan() || off > 1e-3 || c.abs() > 1e9 || w.abs() > 1e9 {
            return Err(unsupported(
                name,
                format!(
                    "its samples fall {off:.3} cells off {first_name}'s lattice: a mosaic joins \
                     without resampling; align it first, e.g. gdalwarp -tap -tr {} {}",
                    r.dx,
                    r.dy.abs()
                ),
            ));
        }
        at.push((c.round() as i64, w.round() as i64));
    }
    if parts.len() == 1 {
        let (_, g) = parts.into_iter().next().expect("one part");
        return Ok((g, Vec::new()));
    }
    // The union's first and one-past-last column and row on the first grid's lattice.
    let (c0, r0, c1, r1) = at.iter().zip(&parts).fold(
        (i64::MAX, i64::MAX, i64::MIN, i64::MIN),
        |(c0, r0, c1, r1), (&(c, r), (_, g))| {
            (
                c0.min(c),
                r0.min(r),
                c1.max(c + g.width() as i64),
                r1.max(r + g.height() as i64),
            )
        },
    );
    let source = parts
        .iter()
        .map(|p| p.0.as_str())
        .collect::<Vec<_>>()
        .join(" + ");
    let (w, h) = ((c1 - c0) as u64, (r1 - r0) as u64);
    check_size(&source, w, h)?;
    let mut heights = vec![f32::NAN; (w * h) as usize];
    let mut overlaps = Vec::new();
    for ((name, g), &(ac, ar)) in parts.into_iter().zip(&at) {
        let (dc, dr) = ((ac - c0) as usize, (ar - r0) as usize);
        let gw = g.width() as usize;
        let (mut samples, mut max_difference) = (0u64, 0f32);
        for (row, src) in g.heights().chunks_exact(gw).enumerate() {
            let start = (dr + row) * w as usize + dc;
            for (dst, &v) in heights[start..start + gw].iter_mut().zip(src) {
                if v.is_nan() {
                    continue;
                }
                if !dst.is_nan() {
                    samples += 1;
                    max_difference = max_difference.max((*dst - v).abs());
                }
                *dst = v;
            }
        }
        if samples > 0 {
            overlaps.push(Overlap {
                later: name,
                samples,
                max_difference,
            });
        }
    }
    let georef = Georef {
        origin_x: r.origin_x + c0 as f64 * r.dx,
        origin_y: r.origin_y + r0 as f64 * r.dy,
        ..r
    };
    Ok((
        Grid::new(&source, w as u32, h as u32, heights, georef)?,
        overlaps,
    ))
}
