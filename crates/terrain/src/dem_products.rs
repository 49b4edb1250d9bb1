//! `gdaldem`'s products from an elevation grid: hillshade, slope, aspect, colour relief, TRI, TPI
//! and roughness, each equal to GDAL 3.6.2's (tests/dem_products.rs compares every mode with
//! the output of `gdaldem` committed by tests/data/gdaldem.sh).
//!
//! Every product except the colour relief is a function of a sample's 3 x 3 window
//! `a b c / d e f / g h i` (row − 1 on top, `e` the sample). As in gdaldem:
//! - A no-data sample gives no-data (0 for byte products, −9999 for float ones).
//! - Without `compute_edges`, a sample whose window leaves the grid or holds a no-data sample
//!   gives no-data. With it, a row beyond the grid's top or bottom is extrapolated through the
//!   edge row (`2·edge − next`), a column beyond the left or right edge through the edge column
//!   (`2·edge − next`), except that on the grid's first and last rows every missing column
//!   repeats the edge column (so the extrapolated row above a corner is `2·edge − next` of the
//!   edge column); every neighbour still missing (no-data, or extrapolated from no-data) takes
//!   the centre's height. (Measured against gdaldem with unit impulses: a corner's window sum is
//!   `5·corner + 3·beside`, not the `2·edge − next` plane extrapolation a corner would need.)
//! - The gradient is Horn's (1981) 3 x 3 (the one [`crate::relief`] shades with,
//!   [`horn_differences`]) or Zevenbergen & Thorne's (1987) central differences.
//!
//! # Spacing
//! gdaldem divides by the georeference's pixel size times `-s` (its `scale`), so a geographic
//! grid needs `-s 111120` (metres per degree at the equator) and is still stretched east–west
//! by `1/cos φ`. With [`DemOptions::scale`] given we do exactly that. Without it a projected or
//! local grid takes scale 1 (gdaldem's default) and a geographic one takes the true metres per
//! degree at each row's latitude (the spacing [`crate::relief`] uses: the WGS 84 parallel and
//! meridian arcs of [`crate::dem::Georef::local_metres`]), so its slopes are right without a
//! scale. Aspect, TRI, TPI and roughness use no spacing, as in gdaldem.
//!
//! # Products
//! | product | what | type, no-data |
//! |---|---|---|
//! | hillshade | `1 + 254·cos` of the angle between the normal (heights × `z`) and the light, 1 when the cosine ≤ 0; combined (× slope), multidirectional (Mark 1992: 225°, 270°, 315°, 360° weighted by aspect) and Igor's (no light altitude, darker by slope facing away) variants | byte, 0 |
//! | slope | `atan |∇z|` in degrees, or `100·|∇z|` percent | float32, −9999 |
//! | aspect | the downhill direction, degrees clockwise from north (or counter-clockwise from east); flat is −9999 (or 0) | float32, −9999 |
//! | colour relief | heights coloured by a colour file ([`ColorTable`]) | RGB(A) bytes, none |
//! | TRI | Riley's `√Σ(n − e)²` or Wilson's `Σ|n − e|/8` over the 8 neighbours | float32, −9999 |
//! | TPI | `e − Σn/8` | float32, −9999 |
//! | roughness | the largest minus the smallest height of the window | float32, −9999 |
//!
//! The colour relief departs from GDAL 3.6.2 in two places, both where GDAL contradicts its own
//! documentation: with `-exact_color_entry` GDAL colours only heights equal to the lowest entry
//! (its search compares a height with the entry below the first one not below it; measured,
//! tests/dem_products.rs), where we colour every height equal to an entry; and GDAL places an
//! `nv` entry at the band's no-data value among the heights, so a height below the lowest entry
//! is interpolated from the no-data colour, where we give it the lowest entry's colour (no-data
//! is `NaN` in a [`Grid`]: the file's no-data value is gone). No-data without an `nv` entry takes
//! the lowest entry's colour (transparent black with exact matching), as in GDAL. Percentages
//! are of the grid's lowest to highest valid height. Named colours are GDAL's (not X11's).
//!
//! Byte values are rounded as GDAL converts a float to a byte (`⌊v + 0.5⌋` in `f32`). Rows are
//! computed in parallel (rayon), each sample on its own: the same bytes for any thread count.
//!
//! # References
//! - Horn, B. K. P. (1981). Hill shading and the reflectance map. Proc. IEEE 69(1), 14–47.
//! - Zevenbergen, L. W., Thorne, C. R. (1987). Quantitative analysis of land surface topography.
//!   Earth Surface Processes and Landforms 12, 47–56.
//! - Mark, R. K. (1992). Multidirectional, oblique-weighted, shaded-relief image of the Island of
//!   Hawaii. USGS Open-File Report 92-422.
//! - Riley, S. J., DeGloria, S. D., Elliot, R. (1999). A terrain ruggedness index that quantifies
//!   topographic heterogeneity. Intermountain Journal of Sciences 5, 23–27.
//! - Wilson, M. F. J. et al. (2007). Multiscale terrain analysis of multibeam bathymetry data for
//!   habitat mapping on the continental slope. Marine Geodesy 30, 3–35.
//! - Weiss, A. (2001). Topographic position and landforms analysis (TPI).
//! - GDAL 3.6 `gdaldem` documentation (the options, the colour file's syntax).

use crate::dem::{CrsKind, Grid};
use crate::error::{TerrainError, format_err};
use rayon::prelude::*;
use std::path::Path;

/// gdaldem's no-data value of its float products.
pub const FLOAT_NODATA: f32 = -9999.0;

/// The 3 x 3 gradient.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Gradient {
    /// Horn (1981): weighted differences over the whole window; smooth, gdaldem's default.
    #[default]
    Horn,
    /// Zevenbergen & Thorne (1987): central differences of the 4 side neighbours; sharper.
    ZevenbergenThorne,
}

/// How a hillshade turns a normal into a shade.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Shading {
    /// The cosine to one light (gdaldem's default).
    #[default]
    Standard,
    /// The cosine's angle times the slope (gdaldem `-combined`).
    Combined,
    /// Four lights (225°, 270°, 315°, 360°) weighted by the aspect (`-multidirectional`).
    Multidirectional,
    /// Igor Ruiz's shading: darker by slope facing away from the light (`-igor`).
    Igor,
}

/// `gdaldem hillshade`'s parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HillshadeOptions {
    /// Vertical exaggeration (`-z`).
    pub z: f64,
    /// Light azimuth, degrees clockwise from north (`-az`, 315).
    pub azimuth: f64,
    /// Light altitude above the horizon, degrees (`-alt`, 45).
    pub altitude: f64,
    pub shading: Shading,
}

impl Default for HillshadeOptions {
    fn default() -> Self {
        HillshadeOptions {
            z: 1.0,
            azimuth: 315.0,
            altitude: 45.0,
            shading: Shading::Standard,
        }
    }
}

/// TRI's formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TriAlg {
    /// Riley et al. (1999): the root of the summed squared differences (terrestrial; default).
    #[default]
    Riley,
    /// Wilson et al. (2007): the mean absolute difference (bathymetry).
    Wilson,
}

/// One 3 x 3 product.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Product {
    Hillshade(HillshadeOptions),
    /// Slope in degrees, or percent.
    Slope {
        percent: bool,
    },
    /// Aspect clockwise from north, or counter-clockwise from east (`trigonometric`); flat
    /// ground is no-data, or 0 with `zero_for_flat`.
    Aspect {
        trigonometric: bool,
        zero_for_flat: bool,
    },
    Tri(TriAlg),
    Tpi,
    Roughness,
}

/// Options every 3 x 3 product shares.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DemOptions {
    pub gradient: Gradient,
    /// gdaldem's `-compute_edges`: values at the grid's edges and beside no-data too.
    pub compute_edges: bool,
    /// gdaldem's `-s`: ratio of vertical units to the georeference's horizontal units. `None`:
    /// 1, except for a geographic grid, which takes true metres per degree (module docs).
    pub scale: Option<f64>,
}

/// A product's samples, row-major.
#[derive(Clone, Debug, PartialEq)]
pub enum ProductSamples {
    /// One byte a sample (hillshade; no-data 0).
    Gray8(Vec<u8>),
    /// RGB bytes, interleaved (colour relief).
    Rgb8(Vec<u8>),
    /// RGBA bytes, interleaved (colour relief with alpha).
    Rgba8(Vec<u8>),
    /// Float32 (no-data [`FLOAT_NODATA`]).
    F32(Vec<f32>),
}

/// A computed product on the grid's lattice.
#[derive(Clone, Debug, PartialEq)]
pub struct DemProduct {
    pub width: u32,
    pub height: u32,
    pub samples: ProductSamples,
    /// The no-data value gdaldem writes for the product (none for a colour relief).
    pub nodata: Option<f64>,
}

impl DemProduct {
    /// Write the product as a GeoTIFF placed by `grid`'s georeference (strips or a COG).
    pub fn write_geotiff(
        &self,
        path: &Path,
        grid: &Grid,
        options: &crate::dem::geotiff_writer::GeoTiffOptions,
    ) -> Result<(), TerrainError> {
        use crate::dem::geotiff_writer::{Samples, write_geotiff_with};
        let samples = match &self.samples {
            ProductSamples::Gray8(v) => Samples::U8(v),
            ProductSamples::Rgb8(v) => Samples::Rgb8(v),
            ProductSamples::Rgba8(v) => Samples::Rgba8(v),
            ProductSamples::F32(v) => Samples::F32(v),
        };
        write_geotiff_with(
            path,
            self.width,
            self.height,
            samples,
            grid.georef(),
            self.nodata,
            options,
        )
    }

    /// The product as a picture: grey for one band (float products stretched from their lowest
    /// to highest value, no-data black), the colours as they are.
    pub fn image(&self) -> image::RgbaImage {
        let n = self.width as usize * self.height as usize;
        let mut raw = Vec::with_capacity(n * 4);
        match &self.samples {
            ProductSamples::Gray8(v) => v.iter().for_each(|&g| raw.extend([g, g, g, 255])),
            ProductSamples::Rgb8(v) => v
                .chunks_exact(3)
                .for_each(|p| raw.extend([p[0], p[1], p[2], 255])),
            ProductSamples::Rgba8(v) => raw.extend_from_slice(v),
            ProductSamples::F32(v) => {
                let valid = || v.iter().copied().filter(|&x| x != FLOAT_NODATA);
                let lo = valid().fold(f32::INFINITY, f32::min);
                let hi = valid().fold(f32::NEG_INFINITY, f32::max);
                let span = (hi - lo).max(f32::MIN_POSITIVE);
                for &x in v {
                    let g = if x == FLOAT_NODATA {
                        0
                    } else {
                        (1.0 + 254.0 * (x - lo) / span).round() as u8
                    };
                    raw.extend([g, g, g, 255]);
                }
            }
        }
        image::RgbaImage::from_raw(self.width, self.height, raw).expect("w·h RGBA pixels")
    }
}

/// Horn's weighted differences of a 3 x 3 window `[a b c d e f g h i]` (row − 1 first):
/// `((c + f + f + i) − (a + d + d + g), (g + h + h + i) − (a + b + b + c))`, i.e. 8 times the
/// height change per column step and per row step; divide by 8 spacings for the gradient.
/// Summed left to right in `T`: gdaldem sums its `f32` window in `f32` in this order, and
/// [`crate::relief`] in `f64`.
pub fn horn_differences<T>(w: &[T; 9]) -> (T, T)
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T>,
{
    (
        (w[2] + w[5] + w[5] + w[8]) - (w[0] + w[3] + w[3] + w[6]),
        (w[6] + w[7] + w[7] + w[8]) - (w[0] + w[1] + w[1] + w[2]),
    )
}

/// The 3 x 3 window of `(col, row)` as the module docs say, or `None` where the product is
/// no-data.
/// In `f32`, the grid's type, as gdaldem's window.
fn window(grid: &Grid, col: u32, row: u32, edges: bool) -> Option<[f32; 9]> {
    let (w, h) = (grid.width() as i64, grid.height() as i64);
    let v = |c: i64, r: i64| grid.at(c as u32, r as u32);
    let centre = v(col as i64, row as i64);
    if centre.is_nan() {
        return None;
    }
    let (c0, r0) = (col as i64, row as i64);
    let mut win = [0f32; 9];
    for (k, out) in win.iter_mut().enumerate() {
        let (dc, dr) = (k as i64 % 3 - 1, k as i64 / 3 - 1);
        let (c, r) = (c0 + dc, r0 + dr);
        let inside_r = (0..h).contains(&r);
        let outside = !(inside_r && (0..w).contains(&c));
        if outside && !edges {
            return None;
        }
        // On the first and last rows a missing column repeats the edge column, on every row
        // of the window.
        let c = if r0 == 0 || r0 == h - 1 {
            c.clamp(0, w - 1)
        } else {
            c
        };
        let value = if !inside_r {
            // The missing row, through the edge row.
            2.0 * v(c, r0) - v(c, r0 - dr)
        } else if !(0..w).contains(&c) {
            // A missing column on an inner row, through the edge column.
            2.0 * v(c0, r) - v(c0 - dc, r)
        } else {
            v(c, r)
        };
        *out = if value.is_nan() {
            if edges {
                centre
            } else {
                return None;
            }
        } else {
            value
        };
    }
    Some(win)
}

/// Spacing of one column and one row step (`(x, y)` in the georeference's directions, times
/// the scale), for each row.
fn spacings(grid: &Grid, scale: Option<f64>) -> Vec<(f64, f64)> {
    let g = grid.georef();
    match (scale, g.crs) {
        (None, CrsKind::Geographic) => {
            let rows = grid.height().max(2) as f64 - 1.0;
            let south = (g.local_metres(0.0, rows).1 - g.local_metres(0.0, 0.0).1) / rows;
            (0..grid.height())
                .map(|r| {
                    let r = r as f64;
                    let east = g.local_metres(1.0, r).0 - g.local_metres(0.0, r).0;
                    (east, -south)
                })
                .collect()
        }
        (s, _) => {
            let s = s.unwrap_or(1.0);
            vec![(g.dx * s, g.dy * s); grid.height() as usize]
        }
    }
}

/// The gradient of a window as gdaldem writes it: `x` = west minus east, `y` = next row minus
/// previous, each divided by its spacing (8 spacings for Horn, 2 for Zevenbergen–Thorne are
/// left in `zfactor`); returns `(x, y, divisor)`.
fn gradient(win: &[f32; 9], alg: Gradient, ew: f64, ns: f64) -> (f64, f64, f64) {
    let (e, s) = raw_differences(win, alg);
    let div = match alg {
        Gradient::Horn => 8.0,
        Gradient::ZevenbergenThorne => 2.0,
    };
    (-e / ew, s / ns, div)
}

/// The raw differences aspect uses (no spacing): `(east − west, next row − previous)`.
/// Summed in `f32`, as gdaldem sums its window.
fn raw_differences(win: &[f32; 9], alg: Gradient) -> (f64, f64) {
    let (e, s) = match alg {
        Gradient::Horn => horn_differences(win),
        Gradient::ZevenbergenThorne => (win[5] - win[3], win[7] - win[1]),
    };
    (e as f64, s as f64)
}

/// A float converted to a byte as GDAL does: `⌊v + 0.5⌋` in `f32`, clamped to 0..=255.
fn to_byte(v: f64) -> u8 {
    let v = v as f32;
    (v + 0.5).floor().clamp(0.0, 255.0) as u8
}

/// The light's constants, computed once.
struct Light {
    sin_alt: f64,
    cos_alt: f64,
    sin_az: f64,
    cos_az: f64,
    az: f64,
}

/// One hillshade value (1..=255, before the byte conversion) of a gradient `(x, y)` already
/// scaled by `z / divisor`, and the aspect angle `aspect` (radians, Igor's shading only).
fn shade(s: Shading, l: &Light, x: f64, y: f64, aspect: f64) -> f64 {
    let xx_yy = x * x + y * y;
    // Cosine between the normal (x, −y, 1)/|·| and the light: x points west, y north.
    let cosine = |sin_az: f64, cos_az: f64| l.sin_alt - l.cos_alt * (y * cos_az - x * sin_az);
    match s {
        Shading::Standard => {
            let c = cosine(l.sin_az, l.cos_az) / (1.0 + xx_yy).sqrt();
            if c <= 0.0 { 1.0 } else { 1.0 + 254.0 * c }
        }
        Shading::Combined => {
            let c = cosine(l.sin_az, l.cos_az) / (1.0 + xx_yy).sqrt();
            // The cosine's angle times the slope angle, over (π/2)².
            let c = 1.0
                - c.clamp(-1.0, 1.0).acos() * xx_yy.sqrt().atan()
                    / (std::f64::consts::FRAC_PI_2 * std::f64::consts::FRAC_PI_2);
            if c <= 0.0 { 1.0 } else { 1.0 + 254.0 * c }
        }
        Shading::Multidirectional => {
            if xx_yy == 0.0 {
                return 1.0 + 254.0 * l.sin_alt;
            }
            let h = std::f64::consts::FRAC_1_SQRT_2;
            // Mark (1992): lights from 225°, 270°, 315° and 360°, each weighted by
            // sin²(aspect − azimuth); the weights sum to 2·|∇|².
            let v225 = cosine(-h, -h).max(0.0);
            let v270 = cosine(-1.0, 0.0).max(0.0);
            let v315 = cosine(-h, h).max(0.0);
            let v360 = cosine(0.0, 1.0).max(0.0);
            let w225 = 0.5 * xx_yy - x * y;
            let w270 = x * x;
            let w315 = xx_yy - w225;
            let w360 = y * y;
            let c = (w225 * v225 + w270 * v270 + w315 * v315 + w360 * v360)
                / xx_yy
                / (1.0 + xx_yy).sqrt();
            1.0 + 127.0 * c
        }
        Shading::Igor => {
            let slope = xx_yy.sqrt().atan().to_degrees();
            let mut diff =
                (1.5 * std::f64::consts::PI - l.az - aspect).abs() % (2.0 * std::f64::consts::PI);
            if diff > std::f64::consts::PI {
                diff = 2.0 * std::f64::consts::PI - diff;
            }
            255.0 * (1.0 - slope / 90.0 * (1.0 - diff / std::f64::consts::PI))
        }
    }
}

/// A float product of a window and its row's `(column, row)` spacing.
type Kernel<'k> = dyn Fn(&[f32; 9], (f64, f64)) -> f32 + Sync + 'k;

/// A colour file's entry at a height.
pub(crate) type Level = (f64, [u8; 4]);

/// Compute `product` over `grid`.
///
/// # Errors
/// [`TerrainError::BadParameter`] for a scale, z factor, azimuth or altitude that is not finite
/// (or a scale or z not > 0).
pub fn compute(
    grid: &Grid,
    product: &Product,
    options: &DemOptions,
) -> Result<DemProduct, TerrainError> {
    let bad = |name: &'static str, v: f64, expected: &'static str| TerrainError::BadParameter {
        name,
        value: v.to_string(),
        expected,
    };
    if let Some(s) = options.scale
        && !(s.is_finite() && s > 0.0)
    {
        return Err(bad("scale", s, "a finite ratio > 0"));
    }
    if let Product::Hillshade(h) = product {
        if !(h.z.is_finite() && h.z > 0.0) {
            return Err(bad("z", h.z, "a finite factor > 0"));
        }
        for (name, v) in [("azimuth", h.azimuth), ("altitude", h.altitude)] {
            if !v.is_finite() {
                return Err(bad(name, v, "finite degrees"));
            }
        }
    }
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let space = spacings(grid, options.scale);
    let edges = options.compute_edges;
    let alg = options.gradient;
    let floats = |f: &Kernel| {
        let mut v = vec![0f32; w * h];
        v.par_chunks_mut(w).enumerate().for_each(|(row, out)| {
            for (col, o) in out.iter_mut().enumerate() {
                *o = match window(grid, col as u32, row as u32, edges) {
                    Some(win) => f(&win, space[row]),
                    None => FLOAT_NODATA,
                };
            }
        });
        DemProduct {
            width: w as u32,
            height: h as u32,
            samples: ProductSamples::F32(v),
            nodata: Some(FLOAT_NODATA as f64),
        }
    };
    let neighbours = |win: &[f32; 9]| {
        let mut n = [0f64; 8];
        for (k, o) in n.iter_mut().enumerate() {
            *o = win[if k < 4 { k } else { k + 1 }] as f64;
        }
        n
    };
    Ok(match *product {
        Product::Hillshade(hs) => {
            let (az, alt) = (hs.azimuth.to_radians(), hs.altitude.to_radians());
            let light = Light {
                sin_alt: alt.sin(),
                cos_alt: alt.cos(),
                sin_az: az.sin(),
                cos_az: az.cos(),
                az,
            };
            let mut v = vec![0u8; w * h];
            v.par_chunks_mut(w).enumerate().for_each(|(row, out)| {
                let (ew, ns) = space[row];
                for (col, o) in out.iter_mut().enumerate() {
                    let Some(win) = window(grid, col as u32, row as u32, edges) else {
                        *o = 0;
                        continue;
                    };
                    let (x, y, div) = gradient(&win, alg, ew, ns);
                    let k = hs.z / div;
                    let (dx, dy) = raw_differences(&win, alg);
                    let aspect = dy.atan2(-dx);
                    *o = to_byte(shade(hs.shading, &light, x * k, y * k, aspect));
                }
            });
            DemProduct {
                width: w as u32,
                height: h as u32,
                samples: ProductSamples::Gray8(v),
                nodata: Some(0.0),
            }
        }
        Product::Slope { percent } => floats(&|win, (ew, ns)| {
            let (x, y, div) = gradient(win, alg, ew, ns);
            let g = (x * x + y * y).sqrt() / div;
            if percent {
                (100.0 * g) as f32
            } else {
                g.atan().to_degrees() as f32
            }
        }),
        Product::Aspect {
            trigonometric,
            zero_for_flat,
        } => floats(&|win, _| {
            let (dx, dy) = raw_differences(win, alg);
            if dx == 0.0 && dy == 0.0 {
                return if zero_for_flat { 0.0 } else { FLOAT_NODATA };
            }
            // Degrees counter-clockwise from east of the downhill direction, in f32 as gdaldem.
            let mut a = dy.atan2(-dx).to_degrees() as f32;
            if trigonometric {
                if a < 0.0 {
                    a += 360.0;
                }
            } else if a > 90.0 {
                a = 450.0 - a;
            } else {
                a = 90.0 - a;
            }
            if a == 360.0 { 0.0 } else { a }
        }),
        Product::Tri(TriAlg::Riley) => floats(&|win, _| {
            let e = win[4] as f64;
            let s: f64 = neighbours(win).iter().map(|n| (n - e).powi(2)).sum();
            s.sqrt() as f32
        }),
        Product::Tri(TriAlg::Wilson) => floats(&|win, _| {
            let e = win[4] as f64;
            let s: f64 = neighbours(win).iter().map(|n| (n - e).abs()).sum();
            (s / 8.0) as f32
        }),
        Product::Tpi => floats(&|win, _| {
            // Summed in f32, left to right, as gdaldem.
            let s = win[0] + win[1] + win[2] + win[3] + win[5] + win[6] + win[7] + win[8];
            win[4] - s / 8.0
        }),
        Product::Roughness => floats(&|win, _| {
            let hi = win.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            let lo = win.iter().copied().fold(f32::INFINITY, f32::min);
            hi - lo
        }),
    })
}

// ---------------------------------------------------------------------------------------------
// Colour relief
// ---------------------------------------------------------------------------------------------

/// How a height between two entries of a colour file is coloured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ColorMatch {
    /// Linear between the entries below and above (gdaldem's default); beyond the first or
    /// last entry, its colour.
    #[default]
    Linear,
    /// Only heights equal to an entry; others transparent black (`-exact_color_entry`).
    Exact,
    /// The nearest entry's colour (`-nearest_color_entry`).
    Nearest,
}

/// Where a colour file's entry sits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorLevel {
    /// A height.
    Height(f64),
    /// A percentage of the way from the grid's lowest to highest height.
    Percent(f64),
    /// No-data (`nv`).
    NoData,
}

/// gdaldem's named colours, as GDAL 3.6.2 colours them (measured: `gdaldem color-relief` of a
/// file naming each; its table holds fractions of 255, truncated, so brown is 191, 127, 63 and
/// not X11's 165, 42, 42).
const NAMED: [(&str, [u8; 3]); 16] = [
    ("white", [255, 255, 255]),
    ("black", [0, 0, 0]),
    ("red", [255, 0, 0]),
    ("green", [0, 255, 0]),
    ("blue", [0, 0, 255]),
    ("yellow", [255, 255, 0]),
    ("magenta", [255, 0, 255]),
    ("cyan", [0, 255, 255]),
    ("aqua", [0, 191, 191]),
    ("grey", [191, 191, 191]),
    ("gray", [191, 191, 191]),
    ("orange", [255, 127, 0]),
    ("brown", [191, 127, 63]),
    ("purple", [127, 0, 255]),
    ("violet", [127, 0, 255]),
    ("indigo", [0, 127, 255]),
];

/// A colour file of `gdaldem color-relief`: one entry a line, `level R G B [A]` or
/// `level name`, the level a height, a percentage (`50%`) or `nv` (no-data); fields separated by
/// spaces, tabs, commas or colons. Blank lines and lines starting with `#` are skipped.
///
/// # Guarantees
/// At least one entry; every channel in 0..=255; every level finite.
#[derive(Clone, Debug, PartialEq)]
pub struct ColorTable {
    pub entries: Vec<(ColorLevel, [u8; 4])>,
}

impl ColorTable {
    /// Read a colour file.
    pub fn read(path: &Path) -> Result<ColorTable, TerrainError> {
        let text = std::fs::read_to_string(path).map_err(crate::error::io(path))?;
        ColorTable::parse(&text, &path.display().to_string())
    }

    /// Parse a colour file's text; `source` names it in errors (with the line).
    pub fn parse(text: &str, source: &str) -> Result<ColorTable, TerrainError> {
        let mut entries = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let at = || format!("line {}", i + 1);
            let fields: Vec<&str> = line
                .split([' ', '\t', ',', ':'])
                .filter(|f| !f.is_empty())
                .collect();
            let level = match fields[0] {
                f if f.eq_ignore_ascii_case("nv") => ColorLevel::NoData,
                f => {
                    let (num, pct) = match f.strip_suffix('%') {
                        Some(n) => (n, true),
                        None => (f, false),
                    };
                    match num.parse::<f64>() {
                        Ok(v) if v.is_finite() && pct => ColorLevel::Percent(v),
                        Ok(v) if v.is_finite() => ColorLevel::Height(v),
                        _ => {
                            return Err(format_err(
                                source,
                                at(),
                                format!("a height, a percentage or nv, got {f:?}"),
                            ));
                        }
                    }
                }
            };
            let channel = |s: &str| s.parse::<u8>().ok();
            let colour = match fields.len() {
                2 => NAMED
                    .iter()
                    .find(|(n, _)| n.eq_ignore_ascii_case(fields[1]))
                    .map(|(_, c)| [c[0], c[1], c[2], 255]),
                4 | 5 => {
                    let c: Vec<Option<u8>> = fields[1..].iter().map(|s| channel(s)).collect();
                    match c[..] {
                        [Some(r), Some(g), Some(b)] => Some([r, g, b, 255]),
                        [Some(r), Some(g), Some(b), Some(a)] => Some([r, g, b, a]),
                        _ => None,
                    }
                }
                _ => None,
            };
            let Some(colour) = colour else {
                return Err(format_err(
                    source,
                    at(),
                    format!(
                        "`level R G B [A]` with channels 0..=255, or `level name` with a colour \
                         name ({}), got {line:?}",
                        NAMED.map(|n| n.0).join(", ")
                    ),
                ));
            };
            entries.push((level, colour));
        }
        if entries.is_empty() {
            return Err(format_err(
                source,
                "end of file",
                "at least one colour entry",
            ));
        }
        Ok(ColorTable { entries })
    }

    /// The entries with levels as heights of `grid` (percentages of its range), sorted by
    /// height (stably: equal heights keep the file's order), and the no-data colour.
    pub(crate) fn resolve(&self, grid: &Grid) -> (Vec<Level>, Option<[u8; 4]>) {
        let (lo, hi) = grid.height_range();
        let (lo, hi) = (lo as f64, hi as f64);
        let mut nodata = None;
        let mut levels = Vec::new();
        for &(level, c) in &self.entries {
            match level {
                ColorLevel::NoData => {
                    nodata.get_or_insert(c);
                }
                ColorLevel::Height(v) => levels.push((v, c)),
                ColorLevel::Percent(p) => levels.push((lo + p / 100.0 * (hi - lo), c)),
            }
        }
        levels.sort_by(|a, b| a.0.total_cmp(&b.0));
        (levels, nodata)
    }
}

/// The colour of height `v` (`NaN`: no-data) among sorted `levels`.
pub(crate) fn colour_of(
    levels: &[Level],
    nodata: Option<[u8; 4]>,
    m: ColorMatch,
    v: f64,
) -> [u8; 4] {
    if v.is_nan() {
        // No-data without an `nv` entry is coloured as a height below every entry.
        return match (nodata, m) {
            (Some(c), _) => c,
            (None, ColorMatch::Exact) => [0; 4],
            (None, _) => levels.first().map_or([0; 4], |e| e.1),
        };
    }
    // The first entry at or above v.
    let i = levels.partition_point(|e| e.0 < v);
    match m {
        ColorMatch::Exact => levels.get(i).filter(|e| e.0 == v).map_or([0; 4], |e| e.1),
        ColorMatch::Nearest => {
            // The entry below when it is strictly nearer (or there is none above).
            let below = i == levels.len() || (i > 0 && v - levels[i - 1].0 < levels[i].0 - v);
            levels[if below { i - 1 } else { i }].1
        }
        ColorMatch::Linear => {
            if i == 0 {
                levels[0].1
            } else if i == levels.len() {
                levels[i - 1].1
            } else if levels[i].0 == v {
                levels[i].1
            } else {
                let (a, b) = (levels[i - 1], levels[i]);
                let t = (v - a.0) / (b.0 - a.0);
                // gdaldem rounds the interpolated channel as ⌊0.45 + c⌋.
                [0, 1, 2, 3]
                    .map(|k| (0.45 + a.1[k] as f64 + t * (b.1[k] as f64 - a.1[k] as f64)) as u8)
            }
        }
    }
}

/// `grid` coloured by `table` as `gdaldem color-relief` colours it: RGB, or RGBA with `alpha`.
pub fn color_relief(grid: &Grid, table: &ColorTable, m: ColorMatch, alpha: bool) -> DemProduct {
    let (levels, nodata) = table.resolve(grid);
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let bands = if alpha { 4 } else { 3 };
    let mut v = vec![0u8; w * h * bands];
    v.par_chunks_mut(w * bands)
        .enumerate()
        .for_each(|(row, out)| {
            for (col, px) in out.chunks_exact_mut(bands).enumerate() {
                let c = if levels.is_empty() {
                    nodata
                        .filter(|_| grid.at(col as u32, row as u32).is_nan())
                        .unwrap_or([0; 4])
                } else {
                    colour_of(&levels, nodata, m, grid.at(col as u32, row as u32) as f64)
                };
                px.copy_from_slice(&c[..bands]);
            }
        });
    DemProduct {
        width: w as u32,
        height: h as u32,
        samples: if alpha {
            ProductSamples::Rgba8(v)
        } else {
            ProductSamples::Rgb8(v)
        },
        nodata: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::Georef;

    fn plane(gx: f32, gy: f32) -> Grid {
        let n = 7u32;
        let h = (0..n * n)
            .map(|i| 500.0 + gx * (i % n) as f32 + gy * (i / n) as f32)
            .collect();
        Grid::new("plane", n, n, h, Georef::local(10.0)).unwrap()
    }

    /// On a plane the slope is the analytic one at every sample, edges included with
    /// compute_edges (extrapolation keeps a plane) except the four corners, where gdaldem's
    /// repeated edge column halves the east–west difference; no-data on the edges without.
    #[test]
    fn plane_slope_and_edges() {
        let g = plane(3.0, 4.0); // ∇ = (0.3, 0.4): |∇| = 0.5
        let want = 0.5f64.atan().to_degrees() as f32;
        let corner = 0.15f64.hypot(0.4).atan().to_degrees() as f32;
        for edges in [false, true] {
            let p = compute(
                &g,
                &Product::Slope { percent: false },
                &DemOptions {
                    compute_edges: edges,
                    ..Default::default()
                },
            )
            .unwrap();
            let ProductSamples::F32(v) = p.samples else {
                panic!()
            };
            for (i, &s) in v.iter().enumerate() {
                let edge = i % 7 == 0 || i % 7 == 6 || i / 7 == 0 || i / 7 == 6;
                let is_corner = [0, 6, 42, 48].contains(&i);
                if edge && !edges {
                    assert_eq!(s, FLOAT_NODATA);
                } else if is_corner {
                    assert!((s - corner).abs() < 1e-4, "{i}: {s} vs {corner}");
                } else {
                    assert!((s - want).abs() < 1e-4, "{i}: {s} vs {want}");
                }
            }
        }
    }

    /// Exact, nearest and linear colours between two entries, below and above them, and on
    /// no-data with and without an `nv` entry.
    #[test]
    fn colour_matching() {
        let t = ColorTable::parse("10 100 0 0\n20 200 0 0 100\n", "c").unwrap();
        let grid = Grid::new(
            "g",
            3,
            2,
            vec![10.0, 14.0, 16.0, 20.0, 25.0, f32::NAN],
            Georef::local(1.0),
        )
        .unwrap();
        let red = |m: ColorMatch| {
            let ProductSamples::Rgba8(v) = color_relief(&grid, &t, m, true).samples else {
                panic!()
            };
            v.chunks_exact(4).map(|p| [p[0], p[3]]).collect::<Vec<_>>()
        };
        let (o, a) = ([100, 255], [200, 100]);
        assert_eq!(
            red(ColorMatch::Exact),
            [o, [0, 0], [0, 0], a, [0, 0], [0, 0]]
        );
        assert_eq!(red(ColorMatch::Nearest), [o, o, a, a, a, o]);
        // 14: 100 + 0.4·100 + 0.45 → 140; alpha 255 − 0.4·155 + 0.45 → 193.
        assert_eq!(red(ColorMatch::Linear)[1], [140, 193]);
        assert_eq!(red(ColorMatch::Linear)[4], a);
        let t = ColorTable::parse("nv 1 2 3 4\n10 100 0 0\n", "c").unwrap();
        let ProductSamples::Rgb8(v) = color_relief(&grid, &t, ColorMatch::Linear, false).samples
        else {
            panic!()
        };
        assert_eq!(&v[15..], [1, 2, 3]);
    }

    #[test]
    fn colour_file_errors_name_the_line() {
        let e = ColorTable::parse("0 1 2 3\n\n100 1 2\n", "c.txt").unwrap_err();
        assert!(e.to_string().contains("c.txt: line 3"), "{e}");
        let e = ColorTable::parse("x 1 2 3\n", "c.txt").unwrap_err();
        assert!(e.to_string().contains("line 1"), "{e}");
        let e = ColorTable::parse("5 teal\n", "c.txt").unwrap_err();
        assert!(e.to_string().contains("line 1"), "{e}");
        let t = ColorTable::parse("nv 0 0 0 0\n10%,white\n5:1:2:3:4", "c").unwrap();
        assert_eq!(t.entries.len(), 3);
        assert_eq!(t.entries[2], (ColorLevel::Height(5.0), [1, 2, 3, 4]));
    }
}
