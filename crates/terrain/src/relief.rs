//! Shaded relief for a terrain without an orthophoto: heights coloured low to high, lit by a
//! hillshade.
//!
//! The hillshade is the one GIS users know from `gdaldem hillshade` (equal to GDAL's bytes to
//! their rounding inside a GDAL-written grid; tests/srtm.rs): Horn's (1981) 3x3 gradient at each sample, with the spacing in metres of the grid's
//! georeference (a geographic grid's east spacing shrinks with latitude), and the cosine between
//! the surface normal and a light from an azimuth (degrees clockwise from north) and an altitude
//! above the horizon, clamped at 0. GDAL's default light, from the north-west at 45°, is
//! [`Light::default`]. At the grid's edges and around no-data the missing neighbours are
//! extrapolated so that a plane keeps its exact shade (GDAL's `-compute_edges` differs there).
//!
//! The colour of a texel is its height's colour on a green–brown–white ramp times
//! `0.35 + 0.9 · shade` (a flat sample, shade `sin 45°`, keeps 99 % of its colour; a slope facing
//! away from the light falls to 35 %), each channel clipped to 255.
//!
//! # Tints
//! The height colour comes from a [`Tint`]: the built-in ramp, or a table of `(height, colour)`
//! entries resolved from a `gdaldem color-relief` colour file ([`TintTable::resolve`]:
//! percentages taken of the grid's height range once, at build time) and interpolated linearly
//! between them, as `gdaldem color-relief` does by default (the interpolation is
//! [`crate::dem_products`]'s, one mechanism). The table is saved in the database manifest, so a
//! reopened database, its streamed textures and its exports colour every texel alike without the
//! file. The shade factor is the same for both tints. A no-data sample has no shade: it takes
//! the file's `nv` colour where the file has one, and the ramp's opaque grey otherwise. The relief
//! is opaque: an entry's alpha is ignored (a translucent texel would show the relief through
//! itself where it is composited under a photo).

use crate::dem::Grid;

/// Contour lines drawn into a terrain's texture, as topographic maps draw them: a line at every
/// multiple of `interval` metres of height, every `index_every`-th (an index contour) twice as
/// wide, in [`CONTOUR_COLOUR`].
///
/// Each texel is covered by how near its centre lies to a contour level: the height and its
/// gradient come from the grid bilinearly at the texel's place, the distance to the nearest
/// level is the height difference over the gradient per texel (the first-order distance in
/// texels, as for an isoline drawn by its signed distance), and the coverage falls linearly from
/// 1 to 0 across the line's edge, one texel wide, so lines are anti-aliased at any zoom. A texel
/// by no-data draws no line; flat ground (gradient under 10⁻⁹ m a texel) draws none unless it
/// lies exactly on a level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contours {
    /// Height between two lines, metres (> 0).
    pub interval: f64,
    /// Line width in texels of the finest texture level.
    pub width: f32,
    /// Every how many lines an index contour (0: none).
    pub index_every: u32,
}

/// The contour lines' colour (sRGB): the brown of topographic maps.
pub const CONTOUR_COLOUR: [u8; 3] = [130, 75, 35];

impl Contours {
    /// Lines every `interval` metres, 1.5 texels wide, every fifth an index contour.
    pub fn every(interval: f64) -> Contours {
        Contours {
            interval,
            width: 1.5,
            index_every: 5,
        }
    }

    /// The coverage (0..=1) of the texel centred at grid coordinates `(col, row)` (fractional
    /// sample indices), the texture holding `per_texel` samples per texel along x and y.
    pub fn coverage(&self, grid: &Grid, col: f64, row: f64, per_texel: [f64; 2]) -> f32 {
        let (w, h) = (grid.width(), grid.height());
        if w < 2 || h < 2 || self.interval.is_nan() || self.interval <= 0.0 {
            return 0.0;
        }
        let c0 = (col.floor().max(0.0) as u32).min(w - 2);
        let r0 = (row.floor().max(0.0) as u32).min(h - 2);
        let (fx, fy) = (col - c0 as f64, row - r0 as f64);
        let z = |c: u32, r: u32| grid.at(c, r) as f64;
        let (z00, z10, z01, z11) = (z(c0, r0), z(c0 + 1, r0), z(c0, r0 + 1), z(c0 + 1, r0 + 1));
        if [z00, z10, z01, z11].iter().any(|v| v.is_nan()) {
            return 0.0;
        }
        let height = z00 * (1.0 - fx) * (1.0 - fy)
            + z10 * fx * (1.0 - fy)
            + z01 * (1.0 - fx) * fy
            + z11 * fx * fy;
        let dcol = (z10 - z00) * (1.0 - fy) + (z11 - z01) * fy;
        let drow = (z01 - z00) * (1.0 - fx) + (z11 - z10) * fx;
        let (gx, gy) = (dcol * per_texel[0], drow * per_texel[1]);
        let level = (height / self.interval).round();
        let off = (height - level * self.interval).abs();
        let slope = (gx * gx + gy * gy).sqrt();
        let distance = if slope < 1e-9 {
            if off == 0.0 { 0.0 } else { f64::INFINITY }
        } else {
            off / slope
        };
        let index = self.index_every > 0 && (level as i64).rem_euclid(self.index_every as i64) == 0;
        let width = self.width as f64 * if index { 2.0 } else { 1.0 };
        (width / 2.0 + 0.5 - distance).clamp(0.0, 1.0) as f32
    }

    /// `px` with the line laid over it at `coverage` (in sRGB, as maps are drawn); a transparent
    /// texel becomes as opaque as the line covers it.
    pub fn blend(px: [u8; 4], coverage: f32) -> [u8; 4] {
        if coverage <= 0.0 {
            return px;
        }
        let mix = |a: u8, b: u8| (a as f32 + (b as f32 - a as f32) * coverage).round() as u8;
        [
            mix(px[0], CONTOUR_COLOUR[0]),
            mix(px[1], CONTOUR_COLOUR[1]),
            mix(px[2], CONTOUR_COLOUR[2]),
            px[3].max((coverage * 255.0).round() as u8),
        ]
    }
}

/// A distant light: `azimuth_deg` clockwise from north, `altitude_deg` above the horizon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub azimuth_deg: f64,
    pub altitude_deg: f64,
}

impl Default for Light {
    /// `gdaldem hillshade`'s default: azimuth 315° (north-west), altitude 45°.
    fn default() -> Self {
        Light {
            azimuth_deg: 315.0,
            altitude_deg: 45.0,
        }
    }
}

/// A grid's hillshade under one light: per-row spacings in metres, computed once.
pub struct Hillshade<'a> {
    grid: &'a Grid,
    /// Unit vector toward the light, `(east, north, up)`.
    light: [f64; 3],
    /// East metres per column, at each row (latitude-dependent for a geographic grid).
    east: Vec<f64>,
    /// South metres per row (negative where rows run north).
    south: f64,
}

impl<'a> Hillshade<'a> {
    pub fn new(grid: &'a Grid, light: Light) -> Hillshade<'a> {
        let (az, alt) = (
            light.azimuth_deg.to_radians(),
            light.altitude_deg.to_radians(),
        );
        let g = grid.georef();
        let east = (0..grid.height())
            .map(|r| {
                let r = r as f64;
                g.local_metres(1.0, r).0 - g.local_metres(0.0, r).0
            })
            .collect();
        let rows = grid.height().max(2) as f64 - 1.0;
        let south = (g.local_metres(0.0, rows).1 - g.local_metres(0.0, 0.0).1) / rows;
        Hillshade {
            grid,
            light: [az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin()],
            east,
            south,
        }
    }

    /// The shade of sample `(col, row)` in `[0, 1]`, or `None` where the sample is no-data.
    /// A neighbour beyond the grid's edge or without data is extrapolated, exactly on a plane:
    /// an edge neighbour through the sample from the opposite one (`2·centre − opposite`, or the
    /// sample's own height when that is missing too), a corner from the two edge neighbours
    /// beside it (`left/right + above/below − centre`).
    pub fn at(&self, col: u32, row: u32) -> Option<f64> {
        let (w, h) = (self.grid.width() as i64, self.grid.height() as i64);
        let centre = self.grid.at(col, row) as f64;
        if centre.is_nan() {
            return None;
        }
        let raw = |dc: i64, dr: i64| -> Option<f64> {
            let (c, r) = (col as i64 + dc, row as i64 + dr);
            if c < 0 || r < 0 || c >= w || r >= h {
                return None;
            }
            let v = self.grid.at(c as u32, r as u32) as f64;
            (!v.is_nan()).then_some(v)
        };
        let edge = |dc: i64, dr: i64| -> f64 {
            raw(dc, dr)
                .or_else(|| raw(-dc, -dr).map(|o| 2.0 * centre - o))
                .unwrap_or(centre)
        };
        let (b, d, f, hh) = (edge(0, -1), edge(-1, 0), edge(1, 0), edge(0, 1));
        let corner =
            |dc: i64, dr: i64, side: f64, vert: f64| raw(dc, dr).unwrap_or(side + vert - centre);
        // a b c / d e f / g h i, row − 1 on top.
        let (a, c) = (corner(-1, -1, d, b), corner(1, -1, f, b));
        let (g, i) = (corner(-1, 1, d, hh), corner(1, 1, f, hh));
        let (dcol, drow) =
            crate::dem_products::horn_differences(&[a, b, c, d, centre, f, g, hh, i]);
        let de = dcol / (8.0 * self.east[row as usize]);
        let ds = drow / (8.0 * self.south);
        // Normal (east, north, up) = (−dz/de, dz/ds, 1), normalised.
        let n = [-de, ds, 1.0];
        let len = (n[0] * n[0] + n[1] * n[1] + 1.0).sqrt();
        let l = self.light;
        Some(((n[0] * l[0] + n[1] * l[1] + n[2] * l[2]) / len).max(0.0))
    }
}

/// The height colour of `t` in `[0, 1]` (lowest to highest valid height): green, brown, white.
pub fn height_colour(t: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 3] = [
        [60.0, 110.0, 50.0],
        [140.0, 110.0, 70.0],
        [240.0, 240.0, 240.0],
    ];
    let t = t.clamp(0.0, 1.0);
    let (a, b, f) = if t < 0.5 {
        (STOPS[0], STOPS[1], t / 0.5)
    } else {
        (STOPS[1], STOPS[2], (t - 0.5) / 0.5)
    };
    [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * f)
}

/// The colour of a no-data sample in the built-in ramp's relief (and in a table's without `nv`).
const NODATA_GREY: [u8; 4] = [128, 128, 128, 255];

/// How a shaded relief colours heights (module doc, *Tints*).
#[derive(Clone, Debug, PartialEq, Default)]
pub enum Tint {
    /// The built-in green–brown–white ramp over the grid's height range ([`height_colour`]).
    #[default]
    Ramp,
    /// A resolved colour file, interpolated linearly.
    Table(TintTable),
}

/// A colour file's entries resolved against one grid: heights in metres, sorted, and the
/// no-data colour. Stored in the database manifest as `relief_tint`.
///
/// # Guarantees
/// Made by [`TintTable::resolve`]: `entries` sorted by height (stably), every height finite.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TintTable {
    /// `(height, [r, g, b, a])`, ascending heights.
    pub entries: Vec<(f64, [u8; 4])>,
    /// The `nv` entry's colour.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nodata: Option<[u8; 4]>,
}

impl TintTable {
    /// `table`'s entries with percentages resolved against `grid`'s valid height range.
    pub fn resolve(table: &crate::dem_products::ColorTable, grid: &Grid) -> TintTable {
        let (entries, nodata) = table.resolve(grid);
        TintTable { entries, nodata }
    }

    /// The table's colour of height `v` (linear between entries, the end entries' beyond them;
    /// no entries at all: transparent black, as gdaldem).
    pub fn colour(&self, v: f64) -> [u8; 4] {
        if self.entries.is_empty() {
            return [0; 4];
        }
        crate::dem_products::colour_of(
            &self.entries,
            self.nodata,
            crate::dem_products::ColorMatch::Linear,
            v,
        )
    }
}

impl Tint {
    /// The shaded-relief sRGB colour of sample `(col, row)`: its height colour times
    /// `0.35 + 0.9 · shade`, opaque; no-data is the table's `nv` colour or opaque grey.
    pub fn colour(&self, grid: &Grid, shade: &Hillshade, col: u32, row: u32) -> [u8; 4] {
        let Some(s) = shade.at(col, row) else {
            return match self {
                Tint::Table(TintTable {
                    nodata: Some(c), ..
                }) => [c[0], c[1], c[2], 255],
                _ => NODATA_GREY,
            };
        };
        let base = match self {
            Tint::Ramp => {
                let (lo, hi) = grid.height_range();
                let span = (hi - lo).max(f32::MIN_POSITIVE);
                height_colour((grid.at(col, row) - lo) / span)
            }
            Tint::Table(t) => {
                let c = t.colour(grid.at(col, row) as f64);
                [c[0] as f32, c[1] as f32, c[2] as f32]
            }
        };
        let k = (0.35 + 0.9 * s) as f32;
        let c = |v: f32| (v * k).round().clamp(0.0, 255.0) as u8;
        [c(base[0]), c(base[1]), c(base[2]), 255]
    }

    /// The texel `(x, y)` of the grid's shaded relief at `side` texels a side: the colour of the
    /// nearest sample ([`Tint::image`], the relief under a photo and the tiles of a 3D Tiles
    /// export share it).
    pub fn texel(&self, grid: &Grid, shade: &Hillshade, side: u32, x: u32, y: u32) -> [u8; 4] {
        let nearest = |t: u32, n: u32| {
            let i = ((t as f64 + 0.5) / side as f64 * (n - 1) as f64).round() as u32;
            i.min(n - 1)
        };
        self.colour(
            grid,
            shade,
            nearest(x, grid.width()),
            nearest(y, grid.height()),
        )
    }

    /// The shaded relief of the whole grid as an sRGB image, nearest sample per texel: the side
    /// is at most `max_side` and at most the grid's larger side (at least 1). Rows are coloured
    /// in parallel (each texel on its own: the same bytes for any thread count).
    pub fn image(&self, grid: &Grid, max_side: u32) -> image::RgbaImage {
        use rayon::prelude::*;
        let side = max_side.min(grid.width().max(grid.height())).max(1);
        let shade = Hillshade::new(grid, Light::default());
        let mut raw = vec![0u8; side as usize * side as usize * 4];
        raw.par_chunks_mut(side as usize * 4)
            .enumerate()
            .for_each(|(y, line)| {
                for (x, px) in line.chunks_exact_mut(4).enumerate() {
                    px.copy_from_slice(&self.texel(grid, &shade, side, x as u32, y as u32));
                }
            });
        image::RgbaImage::from_raw(side, side, raw).expect("side² RGBA texels")
    }
}

/// [`Tint::colour`] with the built-in ramp.
pub fn relief_colour(grid: &Grid, shade: &Hillshade, col: u32, row: u32) -> [u8; 4] {
    Tint::Ramp.colour(grid, shade, col, row)
}

/// [`Tint::texel`] with the built-in ramp.
pub fn relief_texel(grid: &Grid, shade: &Hillshade, side: u32, x: u32, y: u32) -> [u8; 4] {
    Tint::Ramp.texel(grid, shade, side, x, y)
}

/// [`Tint::image`] with the built-in ramp.
pub fn relief_image(grid: &Grid, max_side: u32) -> image::RgbaImage {
    Tint::Ramp.image(grid, max_side)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::Georef;

    fn plane(gx: f32, gy: f32, cell: f64) -> Grid {
        let n = 9u32;
        let h = (0..n * n)
            .map(|i| 500.0 + gx * (i % n) as f32 + gy * (i / n) as f32)
            .collect();
        Grid::new("plane", n, n, h, Georef::local(cell)).unwrap()
    }

    /// On a plane the shade is the analytic cosine, at every sample (edges included: the
    /// one-sided gradient of a plane is its gradient).
    /// A plane rising 1 m per sample east: the lines every 10 m lie on the columns of height
    /// 10k, fully covered there, half covered 0.75 texels off (1.5 texels wide), twice as wide
    /// every fifth line; none through no-data.
    #[test]
    fn contour_coverage_on_a_plane_is_its_distance_to_the_level() {
        let grid = plane(1.0, 0.0, 10.0); // 500 + col
        let c = Contours::every(10.0);
        let at = |col: f64| c.coverage(&grid, col, 4.0, [1.0, 1.0]);
        // 500 is level 50, an index line 3 texels wide: covered 1 texel off, not 2 off.
        assert_eq!(at(0.0), 1.0);
        assert_eq!(at(1.0), 1.0);
        assert_eq!(at(2.0), 0.0);
        let c = Contours {
            interval: 7.0,
            width: 1.5,
            index_every: 0,
        };
        // 504 is 7 · 72: column 4; 0.75 texels off, half covered; 2 off, none.
        let at = |col: f64, per: f64| c.coverage(&grid, col, 4.0, [per, per]);
        assert_eq!(at(4.0, 1.0), 1.0);
        assert!((at(4.75, 1.0) - 0.5).abs() < 1e-6, "{}", at(4.75, 1.0));
        assert_eq!(at(6.0, 1.0), 0.0);
        // Four texels a sample: 0.75 samples off is 3 texels off.
        assert_eq!(at(4.75, 0.25), 0.0);
        assert!((at(4.1875, 0.25) - 0.5).abs() < 1e-6);
        // Index lines are twice as wide: 1.5 texels off, half covered.
        let c = Contours {
            interval: 7.0,
            width: 1.5,
            index_every: 72,
        };
        assert!((c.coverage(&grid, 5.5, 4.0, [1.0, 1.0]) - 0.5).abs() < 1e-6);
        // No line through a no-data sample; blending keeps a texel the line misses.
        let mut h: Vec<f32> = grid.heights().to_vec();
        h[4 * 9 + 4] = f32::NAN;
        let holed = Grid::new("holed", 9, 9, h, Georef::local(10.0)).unwrap();
        assert_eq!(c.coverage(&holed, 4.0, 4.0, [1.0, 1.0]), 0.0);
        assert_eq!(Contours::blend([9, 8, 7, 255], 0.0), [9, 8, 7, 255]);
        let full = Contours::blend([9, 8, 7, 0], 1.0);
        assert_eq!(
            full,
            [CONTOUR_COLOUR[0], CONTOUR_COLOUR[1], CONTOUR_COLOUR[2], 255]
        );
    }

    #[test]
    fn plane_shade_is_the_analytic_cosine() {
        // Heights rise 3 m per column east and 4 m per row south, 10 m cells: slope
        // (dz/deast, dz/dnorth) = (0.3, −0.4), normal ∝ (−0.3, 0.4, 1).
        let grid = plane(3.0, 4.0, 10.0);
        let light = Light::default();
        let hs = Hillshade::new(&grid, light);
        let (az, alt) = (315f64.to_radians(), 45f64.to_radians());
        let l = [az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin()];
        let want = (-0.3 * l[0] + 0.4 * l[1] + l[2]) / (0.09f64 + 0.16 + 1.0).sqrt();
        for (c, r) in [(4, 4), (0, 0), (8, 3), (2, 8)] {
            let got = hs.at(c, r).unwrap();
            assert!((got - want).abs() < 1e-9, "({c}, {r}): {got} vs {want}");
        }
        // Flat ground under the default light: sin 45°.
        let level = plane(0.0, 0.0, 30.0);
        let flat = Hillshade::new(&level, light).at(4, 4).unwrap();
        assert!((flat - 0.5f64.sqrt()).abs() < 1e-12);
    }

    /// A slope facing the light is brighter than flat ground, one facing away darker, and a
    /// steep one facing away is black (clamped, never negative).
    #[test]
    fn slopes_toward_and_away_from_the_light() {
        let light = Light::default();
        let flat = Hillshade::new(&plane(0.0, 0.0, 10.0), light)
            .at(4, 4)
            .unwrap();
        // Rising to the south-east: faces north-west, toward the light.
        let toward = Hillshade::new(&plane(5.0, 5.0, 10.0), light)
            .at(4, 4)
            .unwrap();
        let away = Hillshade::new(&plane(-5.0, -5.0, 10.0), light)
            .at(4, 4)
            .unwrap();
        let cliff = Hillshade::new(&plane(-80.0, -80.0, 10.0), light)
            .at(4, 4)
            .unwrap();
        assert!(toward > flat && flat > away, "{toward} {flat} {away}");
        assert_eq!(cliff, 0.0);
    }

    #[test]
    fn nodata_is_grey_and_its_neighbours_stay_finite() {
        let mut h = vec![100.0f32; 25];
        h[12] = f32::NAN;
        h[0] = 130.0;
        let grid = Grid::new("hole", 5, 5, h, Georef::local(10.0)).unwrap();
        let hs = Hillshade::new(&grid, Light::default());
        assert_eq!(relief_colour(&grid, &hs, 2, 2), [128, 128, 128, 255]);
        for (c, r) in [(1, 1), (2, 1), (3, 3)] {
            assert!(hs.at(c, r).unwrap().is_finite());
        }
    }
}
