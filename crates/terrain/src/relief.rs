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

use crate::dem::Grid;

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
        let de = ((c + 2.0 * f + i) - (a + 2.0 * d + g)) / (8.0 * self.east[row as usize]);
        let ds = ((g + 2.0 * hh + i) - (a + 2.0 * b + c)) / (8.0 * self.south);
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

/// The shaded-relief sRGB colour of sample `(col, row)`: its height colour times
/// `0.35 + 0.9 · shade`; no-data is opaque grey.
pub fn relief_colour(grid: &Grid, shade: &Hillshade, col: u32, row: u32) -> [u8; 4] {
    let Some(s) = shade.at(col, row) else {
        return [128, 128, 128, 255];
    };
    let (lo, hi) = grid.height_range();
    let span = (hi - lo).max(f32::MIN_POSITIVE);
    let base = height_colour((grid.at(col, row) - lo) / span);
    let k = (0.35 + 0.9 * s) as f32;
    let c = |v: f32| (v * k).round().clamp(0.0, 255.0) as u8;
    [c(base[0]), c(base[1]), c(base[2]), 255]
}

/// The texel `(x, y)` of the grid's shaded relief at `side` texels a side: the colour of the
/// nearest sample ([`relief_image`] and the tiles of a 3D Tiles export share it).
pub fn relief_texel(grid: &Grid, shade: &Hillshade, side: u32, x: u32, y: u32) -> [u8; 4] {
    let nearest = |t: u32, n: u32| {
        let i = ((t as f64 + 0.5) / side as f64 * (n - 1) as f64).round() as u32;
        i.min(n - 1)
    };
    relief_colour(
        grid,
        shade,
        nearest(x, grid.width()),
        nearest(y, grid.height()),
    )
}

/// The shaded relief of the whole grid as an sRGB image, nearest sample per texel: the side is at
/// most `max_side` and at most the grid's larger side (at least 1). Rows are coloured in parallel
/// (each texel on its own: the same bytes for any thread count).
pub fn relief_image(grid: &Grid, max_side: u32) -> image::RgbaImage {
    use rayon::prelude::*;
    let side = max_side.min(grid.width().max(grid.height())).max(1);
    let shade = Hillshade::new(grid, Light::default());
    let mut raw = vec![0u8; side as usize * side as usize * 4];
    raw.par_chunks_mut(side as usize * 4)
        .enumerate()
        .for_each(|(y, line)| {
            for (x, px) in line.chunks_exact_mut(4).enumerate() {
                px.copy_from_slice(&relief_texel(grid, &shade, side, x as u32, y as u32));
            }
        });
    image::RgbaImage::from_raw(side, side, raw).expect("side² RGBA texels")
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
