//! Geoid undulation grids: the height N of the geoid above the WGS 84 ellipsoid, so that a DEM's
//! heights above sea level (orthometric, H — what SRTM, most national DEMs and GDAL's EGM96 /
//! EGM2008 vertical datums hold) become the ellipsoidal heights h = H + N that earth-centred
//! placement needs. Without it a tileset sits N too high or too low against Cesium World Terrain
//! or photogrammetry in ellipsoidal heights: −27.5 m at Mount Washington, +41 m at Fuji.
//!
//! Read from the files users have:
//! - PROJ's `.gtx` (NOAA VDatum) grids, e.g. proj-data's `egm96_15.gtx`: a 40-byte big-endian
//!   header (latitude and longitude of the south-west sample, the latitude and longitude steps as
//!   f64; rows and columns as i32), then rows × columns f32 from south to north, west to east;
//!   −88.8888 is no-data;
//! - any grid [`crate::dem::read_dem`] reads in degrees, e.g. PROJ's current
//!   `us_nga_egm96_15.tif` or a `gdal_translate` cut of a geoid grid.
//!
//! Undulations are interpolated bilinearly between the four samples around a point, as PROJ
//! does; a grid spanning 360° of longitude wraps around the antimeridian. A point outside the
//! grid, or next to a no-data sample, has no undulation (an error for the caller to name).

use std::path::Path;

use crate::dem::{CrsKind, ReadOptions, read_dem};
use crate::error::{TerrainError, io};

/// Largest grid accepted, in samples: EGM2008 at 1' is 21,601 × 10,801 (233 M samples).
const MAX_SAMPLES: u64 = 250_000_000;

/// The GTX value meaning "no data".
const GTX_NODATA: f32 = -88.8888;

/// A geoid undulation grid in degrees: sample `(col, row)` is at longitude
/// `lon0 + col·dlon`, latitude `lat0 + row·dlat`.
#[derive(Clone, Debug)]
pub struct Geoid {
    name: String,
    lon0: f64,
    lat0: f64,
    dlon: f64,
    dlat: f64,
    cols: usize,
    rows: usize,
    /// Row-major undulations in metres, `NaN` = no data.
    values: Vec<f32>,
    /// Columns after which longitude wraps (the grid spans 360°), if it does.
    wrap: Option<usize>,
}

impl Geoid {
    /// Reads `path`: a `.gtx` grid by its extension, anything else through [`read_dem`] (which
    /// must find a geographic grid).
    pub fn open(path: impl AsRef<Path>) -> Result<Geoid, TerrainError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let gtx = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("gtx"));
        if gtx {
            let bytes = std::fs::read(path).map_err(io(path))?;
            return Geoid::from_gtx(&bytes, &name);
        }
        let grid = read_dem(path, &ReadOptions::default())?;
        let g = grid.georef();
        if g.crs != CrsKind::Geographic {
            return Err(TerrainError::Unsupported {
                source: name,
                what: format!(
                    "a geoid grid must be in degrees of longitude and latitude; this one is {:?} \
                     (PROJ's .gtx and us_nga_egm96_15.tif grids are)",
                    g.crs
                ),
            });
        }
        Geoid::new(
            name,
            [g.origin_x, g.origin_y, g.dx, g.dy],
            grid.width() as usize,
            grid.height() as usize,
            grid.heights().to_vec(),
        )
    }

    /// Parses the bytes of a `.gtx` file named `name` in errors.
    pub fn from_gtx(bytes: &[u8], name: &str) -> Result<Geoid, TerrainError> {
        let bad = |at: String, expected: String| TerrainError::Format {
            source: name.to_string(),
            at,
            expected,
        };
        if bytes.len() < 40 {
            return Err(bad(
                format!("byte {}", bytes.len()),
                "a 40-byte GTX header (lat, lon, dlat, dlon as f64; rows, columns as i32)".into(),
            ));
        }
        let f = |k: usize| f64::from_be_bytes(bytes[8 * k..8 * k + 8].try_into().unwrap());
        let i = |at: usize| i32::from_be_bytes(bytes[at..at + 4].try_into().unwrap());
        let (lat0, lon0, dlat, dlon) = (f(0), f(1), f(2), f(3));
        let (rows, cols) = (i(32), i(36));
        if rows < 2 || cols < 2 {
            return Err(bad(
                "bytes 32-39".into(),
                format!("at least 2 rows and 2 columns, found {rows} x {cols}"),
            ));
        }
        let n = rows as u64 * cols as u64;
        if n > MAX_SAMPLES {
            return Err(bad(
                "bytes 32-39".into(),
                format!("at most {MAX_SAMPLES} samples, found {rows} x {cols}"),
            ));
        }
        let want = 40 + 4 * n;
        if bytes.len() as u64 != want {
            return Err(bad(
                format!("byte {}", bytes.len().min(want as usize)),
                format!(
                    "{want} bytes for {rows} x {cols} f32 samples after the header, the file has {}",
                    bytes.len()
                ),
            ));
        }
        let values: Vec<f32> = bytes[40..]
            .chunks_exact(4)
            .map(|b| f32::from_be_bytes([b[0], b[1], b[2], b[3]]))
            .map(|v| if v == GTX_NODATA { f32::NAN } else { v })
            .collect();
        Geoid::new(
            name.to_string(),
            [lon0, lat0, dlon, dlat],
            cols as usize,
            rows as usize,
            values,
        )
    }

    /// A grid of `cols` × `rows` undulations with sample (0, 0) at `[lon0, lat0]` and steps
    /// `[dlon, dlat]` (the last may be negative: north-up rows).
    fn new(
        name: String,
        [lon0, lat0, dlon, dlat]: [f64; 4],
        cols: usize,
        rows: usize,
        values: Vec<f32>,
    ) -> Result<Geoid, TerrainError> {
        let lat_end = lat0 + (rows - 1) as f64 * dlat;
        let sane = [lon0, lat0, dlon, dlat].iter().all(|v| v.is_finite())
            && dlon > 0.0
            && dlat != 0.0
            && (-90.0 - 1e-9..=90.0 + 1e-9).contains(&lat0)
            && (-90.0 - 1e-9..=90.0 + 1e-9).contains(&lat_end)
            && cols as f64 * dlon <= 360.0 + dlon;
        if !sane {
            return Err(TerrainError::Format {
                source: name,
                at: "the grid's georeference".into(),
                expected: format!(
                    "longitude and latitude steps > 0 within the globe, found origin ({lon0}, \
                     {lat0}), steps ({dlon}, {dlat}), {cols} x {rows} samples"
                ),
            });
        }
        if let Some(k) = values.iter().position(|v| v.is_infinite()) {
            return Err(TerrainError::NonFinite {
                source: name,
                col: (k % cols) as u32,
                row: (k / cols) as u32,
            });
        }
        // 360° of longitude in `cols` steps, or in `cols − 1` with the first column repeated.
        let close = |n: usize| (n as f64 * dlon - 360.0).abs() < 1e-6 * dlon.max(1.0);
        let wrap = if close(cols) {
            Some(cols)
        } else if close(cols - 1) {
            Some(cols - 1)
        } else {
            None
        };
        Ok(Geoid {
            name,
            lon0,
            lat0,
            dlon,
            dlat,
            cols,
            rows,
            values,
            wrap,
        })
    }

    /// The file the grid was read from.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The undulation N in metres at `(lon, lat)` degrees (bilinear), or `None` outside the grid
    /// or next to a no-data sample.
    pub fn undulation(&self, lon: f64, lat: f64) -> Option<f64> {
        let row = (lat - self.lat0) / self.dlat;
        let max_row = (self.rows - 1) as f64;
        if !(row > -1e-9 && row < max_row + 1e-9) {
            return None;
        }
        let row = row.clamp(0.0, max_row);
        let mut col = (lon - self.lon0) / self.dlon;
        let (c0, c1, fc) = match self.wrap {
            Some(period) => {
                col = col.rem_euclid(period as f64);
                let c0 = (col.floor() as usize).min(period - 1);
                (c0, (c0 + 1) % period, col - c0 as f64)
            }
            None => {
                let max_col = (self.cols - 1) as f64;
                if !(col > -1e-9 && col < max_col + 1e-9) {
                    return None;
                }
                let col = col.clamp(0.0, max_col);
                let c0 = (col.floor() as usize).min(self.cols - 2);
                (c0, c0 + 1, col - c0 as f64)
            }
        };
        let r0 = (row.floor() as usize).min(self.rows - 2);
        let fr = row - r0 as f64;
        let v = |c: usize, r: usize| self.values[r * self.cols + c] as f64;
        let (a, b) = (v(c0, r0), v(c1, r0));
        let (c, d) = (v(c0, r0 + 1), v(c1, r0 + 1));
        let n = (a * (1.0 - fc) + b * fc) * (1.0 - fr) + (c * (1.0 - fc) + d * fc) * fr;
        n.is_finite().then_some(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gtx(
        lat0: f64,
        lon0: f64,
        d: f64,
        rows: i32,
        cols: i32,
        f: impl Fn(f64, f64) -> f32,
    ) -> Vec<u8> {
        let mut b = Vec::new();
        for v in [lat0, lon0, d, d] {
            b.extend_from_slice(&v.to_be_bytes());
        }
        b.extend_from_slice(&rows.to_be_bytes());
        b.extend_from_slice(&cols.to_be_bytes());
        for r in 0..rows {
            for c in 0..cols {
                let v = f(lon0 + c as f64 * d, lat0 + r as f64 * d);
                b.extend_from_slice(&v.to_be_bytes());
            }
        }
        b
    }

    #[test]
    fn bilinear_is_exact_on_bilinear_fields_and_wraps_the_antimeridian() {
        // A global 1° grid (lon −180..179) holding N = lat/10 + cos(lon): at the antimeridian the
        // wrap interpolates between columns 179°E and 180°W.
        let b = gtx(-90.0, -180.0, 1.0, 181, 360, |lon, lat| {
            (lat / 10.0 + lon.to_radians().cos()) as f32
        });
        let g = Geoid::from_gtx(&b, "g.gtx").unwrap();
        assert_eq!(g.wrap, Some(360));
        let lin = |lon: f64, lat: f64| {
            // The field is linear in lat; in lon the grid interpolates cos between samples.
            let (l0, l1) = (lon.floor(), lon.floor() + 1.0);
            let t = lon - l0;
            lat / 10.0 + (1.0 - t) * l0.to_radians().cos() + t * l1.to_radians().cos()
        };
        for (lon, lat) in [(10.25, 44.5), (179.5, -30.0), (-179.5, 60.75), (539.5, 0.0)] {
            let want = lin(if lon > 180.0 { lon - 360.0 } else { lon }, lat);
            let got = g.undulation(lon, lat).unwrap();
            assert!((got - want).abs() < 1e-6, "{lon} {lat}: {got} vs {want}");
        }
        assert!(g.undulation(0.0, 90.0).is_some());
        assert!(g.undulation(0.0, 90.5).is_none());
    }

    #[test]
    fn regional_grids_end_and_no_data_is_none() {
        let b = gtx(40.0, -75.0, 0.5, 5, 5, |lon, _| {
            if lon > -73.1 { -88.8888 } else { 1.0 }
        });
        let g = Geoid::from_gtx(&b, "r.gtx").unwrap();
        assert_eq!(g.wrap, None);
        assert_eq!(g.undulation(-74.0, 41.0), Some(1.0));
        assert_eq!(g.undulation(-75.5, 41.0), None, "west of the grid");
        assert_eq!(g.undulation(-73.25, 41.0), None, "next to no-data");
    }

    #[test]
    fn damaged_headers_are_named() {
        let b = gtx(40.0, -75.0, 0.5, 5, 5, |_, _| 0.0);
        let e = Geoid::from_gtx(&b[..30], "x.gtx").unwrap_err().to_string();
        assert!(e.starts_with("x.gtx: byte 30"), "{e}");
        let e = Geoid::from_gtx(&b[..b.len() - 4], "x.gtx")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bytes for 5 x 5"), "{e}");
        let mut huge = b.clone();
        huge[32..36].copy_from_slice(&1_000_000i32.to_be_bytes());
        huge[36..40].copy_from_slice(&1_000_000i32.to_be_bytes());
        let e = Geoid::from_gtx(&huge, "x.gtx").unwrap_err().to_string();
        assert!(e.contains("at most"), "{e}");
        let mut neg = b.clone();
        neg[16..24].copy_from_slice(&(-0.5f64).to_be_bytes());
        neg[24..32].copy_from_slice(&(-0.5f64).to_be_bytes());
        assert!(Geoid::from_gtx(&neg, "x.gtx").is_err());
    }
}
