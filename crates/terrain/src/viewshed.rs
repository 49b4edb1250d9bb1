//! Viewsheds: which cells of an elevation grid an observer standing on it can see — the radar,
//! tower-siting and line-of-sight query of flight simulators and GIS, answered as `gdal_viewshed`
//! answers it and by explicit sight lines.
//!
//! The observer stands at the centre of one sample, its eye `observer_height` metres above that
//! sample's ground; a cell is *visible* when a target `target_height` metres above its ground can
//! be seen from the eye. Earth curvature and refraction lower every height by `c·d²/D` at distance
//! `d` (`D` = the WGS 84 equatorial diameter, `c` = [`DEFAULT_CURVATURE`] = 0.85714 = 1 − 1/7, the
//! standard refraction coefficient, as gdal_viewshed's `-cc`; 0 takes the earth flat), so over
//! flat ground an eye `h` up sees to the horizon at `√(h·D/c)`, 5.46 km for 2 m. Cells farther
//! than `max_distance` get their own class.
//!
//! # Methods
//!
//! | [`Method`] | what is computed | cost |
//! |---|---|---|
//! | `Wang` | Wang, Robinson & White's reference planes: one sweep outwards from the observer's row, each cell's *horizon height* the plane through the eye and the two horizon heights of the cells it is seen past (`gdal_viewshed`'s default "edge" interpolation) | `O(cells)`, one pass: 0.09 s |
//! | `Gdal` | the same sweep bit for bit as GDAL 3.6's `gdal_viewshed` (the version that wrote the test fixtures), including its rule for the cells around the observer | the same |
//! | `Exact` | Franklin & Ray's R3: one sight line per cell, heights interpolated linearly at every crossing of a grid line, the exact reference of the viewshed literature | `O(cells × distance)`, rows in parallel: 37 s (1.1 s within 20 km) |
//!
//! Times: a 3601² grid (the SRTM tile N44W072 resampled to SRTM 1″'s size), observer on Mount
//! Washington, release build, 2 threads on a shared machine, the viewshed alone as
//! `texmap terrain viewshed srtm1.tif --observer-lonlat=-71.3033,44.2706 --method M` reports it
//! (whole commands, reading and writing included: `gdal_viewshed` 0.33 s, texmap's 0.4 s with
//! `wang`). The sweep is fast enough that a wavefront-
//! parallel sweep (anti-diagonals of the quadrants) was not worth its bookkeeping. A sight line
//! walks every grid line between the cell and the observer (stopping at the first that hides a
//! cell asked only whether it is seen), in integer steps: no division in the loop.
//!
//! The sweep (Wang 2000, §"Reference planes"): a cell `(i, j)` columns and rows from the observer
//! with `i ≥ j` is seen past column `i − 1`, which its sight line crosses between rows `j − 1`
//! and `j`; the plane through the eye and the horizon heights `Za` of `(i − 1, j − 1)` and `Zb` of
//! `(i − 1, j)` has height `Zo + ((Za − Zo)·j + (Zb − Zo)·(i − j))/(i − 1)` at the cell (the
//! interpolation at the crossing, `Za·j/i + Zb·(i − j)/i`, extrapolated from distance `i − 1` to
//! `i`); rows mirror columns when `j > i`, and cells on the observer's row, column or a diagonal
//! extend the line through the one cell before them. A cell is invisible when its height plus the
//! target height is below that plane, and its horizon height is the higher of the two. The sweep
//! is sequential along each row and from row to row; the rows above and below the observer are
//! swept in parallel (`rayon::join`), every cell by the same arithmetic in the same order, so the
//! result is the same bytes for any thread count.
//!
//! `Gdal` differs from `Wang` only next to the observer: for the three cells on each of the rows
//! above and below it, GDAL 3.6 takes the observer's *ground* (not a line from the eye, not the
//! cell's own height) as the plane, so such a cell lower than the observer's ground is invisible
//! (even on flat ground, once curvature lowers it) and its horizon is raised to the observer's
//! ground, which then shadows the terrain that falls away beyond it — from a summit most of the
//! slopes around (on the SRTM fixture from Mount Washington's summit: 7.0 % of the cells visible,
//! against 24.2 % by `Wang` and by `Exact`). GDAL's later rewrite (the `Viewshed` class) gives
//! those cells their own height, as `Wang` does. `Gdal` is kept to check the sweep against
//! `gdal_viewshed` cell for cell (tests/srtm.rs: 100 % of the cells of every fixture agree, and
//! of a 3601² run).
//!
//! Distances are ground metres: a projected or local grid's own units, as GDAL takes them; a
//! geographic or Web Mercator grid's through [`crate::dem::Georef::local_metres`] row by row
//! (GDAL takes degrees, or Mercator metres, there, so its `-md` is in degrees and its curvature
//! vanishes on a geographic grid: with curvature 0 and no maximum distance the methods agree with
//! it there too). GDAL applies curvature only when the grid has a coordinate system; here every
//! grid gets it (curvature 0 turns it off).
//!
//! No-data samples never block a sight line: a sweep lets the plane through them (their horizon
//! height is the plane's), a sight line skips them; their class is [`Seen::NoData`]. GDAL has no
//! such rule (it takes the no-data value as a height).
//!
//! # References
//! - Wang, J., Robinson, G. J., White, K., "Generating viewsheds without using sightlines",
//!   *Photogrammetric Engineering & Remote Sensing* 66(1), 87–90, 2000.
//! - Franklin, W. R., Ray, C. K., "Higher isn't necessarily better: visibility algorithms and
//!   experiments", *6th Int. Symposium on Spatial Data Handling*, 1994 (R3, the exact method).
//! - GDAL's `gdal_viewshed` and `GDALViewshedGenerate` (alg/viewshed.cpp as of GDAL 3.6): the
//!   curvature formula, the defaults (`-oz 2 -tz 0 -cc 0.85714`, visible 255, invisible 0,
//!   out of range 0), the `-om DEM/GROUND` heights and the "edge" interpolation `Wang` and
//!   `Gdal` follow.

use crate::dem::{CrsKind, Grid};
use crate::error::TerrainError;
use std::sync::atomic::{AtomicU64, Ordering};

/// gdal_viewshed's default curvature coefficient `-cc`: `1 − 1/7`, the earth's curvature less the
/// standard atmospheric refraction (light bends with a radius seven times the earth's).
pub const DEFAULT_CURVATURE: f64 = 0.85714;

/// The sphere diameter of the curvature term `c·d²/D`: twice the WGS 84 semi-major axis, as GDAL
/// takes it from the grid's ellipsoid (GRS 80 has the same axis).
pub const EARTH_DIAMETER: f64 = 2.0 * crate::geodesy::A;

/// Where the observer stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Observer {
    /// At the centre of sample `(col, row)`.
    Cell { col: u32, row: u32 },
    /// At the sample whose cell holds map point `(x, y)` in the grid's coordinates.
    Map { x: f64, y: f64 },
}

/// How visibility is computed (the module docs compare them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Reference-plane sweep (Wang, Robinson & White 2000), the eight cells around the observer
    /// seen as they are.
    Wang,
    /// The reference-plane sweep bit for bit as GDAL 3.6's `gdal_viewshed`.
    Gdal,
    /// One sight line per cell, heights interpolated at every grid-line crossing (R3).
    Exact,
}

impl Method {
    /// The names [`Method::by_name`] accepts.
    pub const NAMES: [&'static str; 3] = ["wang", "gdal", "exact"];

    pub fn by_name(name: &str) -> Option<Method> {
        match name {
            "wang" => Some(Method::Wang),
            "gdal" => Some(Method::Gdal),
            "exact" => Some(Method::Exact),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Method::Wang => "wang",
            Method::Gdal => "gdal",
            Method::Exact => "exact",
        }
    }
}

/// What a viewshed holds besides each cell's class (gdal_viewshed's `-om`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// Visibility only (`-om NORMAL`): a mask.
    Visibility,
    /// Also the lowest elevation (above sea level, before curvature lowers it) a target at each
    /// cell is seen at (`-om DEM`): below the cell's ground where the ground itself is seen, never
    /// below 0, as GDAL computes it.
    Elevation,
    /// Also the lowest height above the cell's ground a target must have to be seen, 0 where
    /// the ground is seen (`-om GROUND`).
    Height,
}

/// Options of [`viewshed`]; the defaults are gdal_viewshed's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewshedOptions {
    /// The eye above the observer's ground, metres (default 2).
    pub observer_height: f64,
    /// The target above each cell's ground, metres (default 0).
    pub target_height: f64,
    /// Cells farther than this many metres are [`Seen::OutOfRange`] (default: none).
    pub max_distance: Option<f64>,
    /// Curvature coefficient `c` of the drop `c·d²/D` (default [`DEFAULT_CURVATURE`]; 0: flat).
    pub curvature: f64,
    pub method: Method,
    pub output: Output,
}

impl Default for ViewshedOptions {
    fn default() -> Self {
        ViewshedOptions {
            observer_height: 2.0,
            target_height: 0.0,
            max_distance: None,
            curvature: DEFAULT_CURVATURE,
            method: Method::Wang,
            output: Output::Visibility,
        }
    }
}

/// A cell's class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Seen {
    Invisible,
    Visible,
    /// Farther than the maximum distance.
    OutOfRange,
    /// A no-data sample.
    NoData,
}

/// The byte values of a mask (gdal_viewshed's `-vv`, `-iv`, `-ov`); no-data cells take the
/// out-of-range value (neither has an answer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaskValues {
    pub visible: u8,
    pub invisible: u8,
    pub out_of_range: u8,
}

impl Default for MaskValues {
    fn default() -> Self {
        MaskValues {
            visible: 255,
            invisible: 0,
            out_of_range: 0,
        }
    }
}

/// How many cells of each class.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub visible: u64,
    pub invisible: u64,
    pub out_of_range: u64,
    pub nodata: u64,
}

/// A computed viewshed over the grid's own lattice (same size and georeference).
#[derive(Clone, Debug)]
pub struct Viewshed {
    pub width: u32,
    pub height: u32,
    pub georef: crate::dem::Georef,
    /// The observer's sample `(col, row)`.
    pub observer: (u32, u32),
    /// The eye's height: the observer's ground plus the observer height, metres.
    pub eye: f64,
    /// Each cell's class, row-major.
    pub seen: Vec<Seen>,
    /// [`Output::Elevation`] or [`Output::Height`]: each cell's needed elevation or height,
    /// `NaN` beyond the maximum distance and on no-data.
    pub heights: Option<Vec<f32>>,
}

impl Viewshed {
    /// The class of sample `(col, row)`. Panics if out of range.
    pub fn at(&self, col: u32, row: u32) -> Seen {
        self.seen[row as usize * self.width as usize + col as usize]
    }

    pub fn counts(&self) -> Counts {
        let mut n = Counts::default();
        for s in &self.seen {
            match s {
                Seen::Visible => n.visible += 1,
                Seen::Invisible => n.invisible += 1,
                Seen::OutOfRange => n.out_of_range += 1,
                Seen::NoData => n.nodata += 1,
            }
        }
        n
    }

    /// The mask bytes, row-major.
    pub fn mask(&self, values: &MaskValues) -> Vec<u8> {
        self.seen
            .iter()
            .map(|s| match s {
                Seen::Visible => values.visible,
                Seen::Invisible => values.invisible,
                Seen::OutOfRange | Seen::NoData => values.out_of_range,
            })
            .collect()
    }

    /// Write the viewshed as a GeoTIFF on the grid's georeference: the needed heights (float32,
    /// no-data `nan`) when it has them, the mask (bytes) otherwise; in strips.
    pub fn write_geotiff(
        &self,
        path: &std::path::Path,
        values: &MaskValues,
    ) -> Result<(), TerrainError> {
        self.write_geotiff_with(path, values, &Default::default())
    }

    /// [`Viewshed::write_geotiff`] laid out by `options` (strips, or a Cloud-Optimized GeoTIFF).
    pub fn write_geotiff_with(
        &self,
        path: &std::path::Path,
        values: &MaskValues,
        options: &crate::dem::geotiff_writer::GeoTiffOptions,
    ) -> Result<(), TerrainError> {
        use crate::dem::geotiff_writer::{Samples, write_geotiff_with};
        let (w, h, g) = (self.width, self.height, &self.georef);
        match &self.heights {
            Some(z) => {
                let nodata = z.iter().any(|v| v.is_nan()).then_some(f64::NAN);
                write_geotiff_with(path, w, h, Samples::F32(z), g, nodata, options)
            }
            None => write_geotiff_with(
                path,
                w,
                h,
                Samples::U8(&self.mask(values)),
                g,
                None,
                options,
            ),
        }
    }

    /// The grid's shaded relief ([`crate::relief`]) with the viewshed over it, nearest cell per
    /// pixel, at most `max_side` pixels a side (a small grid is enlarged by a whole factor to about
    /// 1024): visible cells tinted yellow, invisible ones darkened, cells beyond the range greyed,
    /// the observer a red dot. `grid` must be the grid the
    /// viewshed was computed on.
    ///
    /// # Panics
    /// If `grid` is not the viewshed's size.
    pub fn image(&self, grid: &Grid, max_side: u32) -> image::RgbaImage {
        self.image_tinted(grid, &crate::relief::Tint::Ramp, max_side)
    }

    /// As [`Viewshed::image`], the relief coloured by `tint` (a database's
    /// [`crate::db::Database::tint`]).
    ///
    /// # Panics
    /// If `grid` is not the viewshed's size.
    pub fn image_tinted(
        &self,
        grid: &Grid,
        tint: &crate::relief::Tint,
        max_side: u32,
    ) -> image::RgbaImage {
        use crate::relief::{Hillshade, Light};
        use rayon::prelude::*;
        assert_eq!((grid.width(), grid.height()), (self.width, self.height));
        let (w, h) = (self.width as f64, self.height as f64);
        // Larger grids shrink to `max_side`; small ones grow by a whole factor to about 1024.
        let scale = if w.max(h) > max_side.max(1) as f64 {
            max_side.max(1) as f64 / w.max(h)
        } else {
            (max_side.clamp(1, 1024) as f64 / w.max(h)).floor().max(1.0)
        };
        let (iw, ih) = (
            ((w * scale).round() as u32).max(1),
            ((h * scale).round() as u32).max(1),
        );
        let shade = Hillshade::new(grid, Light::default());
        let (ocx, ocy) = (
            (self.observer.0 as f64 + 0.5) * scale,
            (self.observer.1 as f64 + 0.5) * scale,
        );
        let dot = (iw.max(ih) as f64 / 150.0).max(2.5);
        let mut raw = vec![0u8; iw as usize * ih as usize * 4];
        raw.par_chunks_mut(iw as usize * 4)
            .enumerate()
            .for_each(|(y, line)| {
                let row = (((y as f64 + 0.5) / scale) as u32).min(self.height - 1);
                for (x, px) in line.chunks_exact_mut(4).enumerate() {
                    let col = (((x as f64 + 0.5) / scale) as u32).min(self.width - 1);
                    let base = tint.colour(grid, &shade, col, row);
                    let mix = |a: [u8; 4], b: [f32; 3], t: f32| -> [u8; 4] {
                        let m = |i: usize| (a[i] as f32 * (1.0 - t) + b[i] * t).round() as u8;
                        [m(0), m(1), m(2), 255]
                    };
                    let (dx, dy) = (x as f64 + 0.5 - ocx, y as f64 + 0.5 - ocy);
                    let c = if dx * dx + dy * dy <= dot * dot {
                        [220, 20, 20, 255]
                    } else {
                        match self.at(col, row) {
                            Seen::Visible => mix(base, [255.0, 215.0, 0.0], 0.55),
                            Seen::Invisible => mix(base, [10.0, 20.0, 60.0], 0.55),
                            Seen::OutOfRange | Seen::NoData => {
                                mix(base, [150.0, 150.0, 150.0], 0.7)
                            }
                        }
                    };
                    px.copy_from_slice(&c);
                }
            });
        image::RgbaImage::from_raw(iw, ih, raw).expect("iw x ih RGBA pixels")
    }
}

/// The viewshed of `observer` over `grid`.
pub fn viewshed(
    grid: &Grid,
    observer: Observer,
    opts: &ViewshedOptions,
) -> Result<Viewshed, TerrainError> {
    viewshed_with_progress(grid, observer, opts, |_, _| {})
}

/// As [`viewshed`], calling `progress(rows done, rows)` as rows are finished (from any thread).
pub fn viewshed_with_progress(
    grid: &Grid,
    observer: Observer,
    opts: &ViewshedOptions,
    progress: impl Fn(u64, u64) + Sync,
) -> Result<Viewshed, TerrainError> {
    let finite = |name: &'static str, v: f64| {
        if v.is_finite() {
            Ok(())
        } else {
            Err(TerrainError::BadParameter {
                name,
                value: v.to_string(),
                expected: "a finite number",
            })
        }
    };
    finite("observer height", opts.observer_height)?;
    finite("target height", opts.target_height)?;
    finite("curvature", opts.curvature)?;
    if let Some(d) = opts.max_distance
        && !(d.is_finite() && d > 0.0)
    {
        return Err(TerrainError::BadParameter {
            name: "max distance",
            value: d.to_string(),
            expected: "metres > 0",
        });
    }
    let (width, height) = (grid.width(), grid.height());
    let (oc, or) = observer_cell(grid, observer)?;
    let ground = grid.at(oc, or);
    if ground.is_nan() {
        return Err(TerrainError::ObserverNoData { col: oc, row: or });
    }
    let scene = Scene::new(grid, (oc, or), opts);
    let cells = width as usize * height as usize;
    let mut seen = vec![Seen::Invisible; cells];
    let mut heights = (opts.output != Output::Visibility).then(|| vec![0.0f32; cells]);
    let done = AtomicU64::new(0);
    let tick = || {
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        progress(d, height as u64);
    };
    match opts.method {
        Method::Wang => scene.sweep(Near::Own, &mut seen, heights.as_deref_mut(), &tick),
        Method::Gdal => scene.sweep(Near::Ground, &mut seen, heights.as_deref_mut(), &tick),
        Method::Exact => scene.sight_lines(&mut seen, heights.as_deref_mut(), &tick),
    }
    Ok(Viewshed {
        width,
        height,
        georef: *grid.georef(),
        observer: (oc, or),
        eye: scene.eye,
        seen,
        heights,
    })
}

/// The sample an observer stands on, or where it falls outside.
fn observer_cell(grid: &Grid, observer: Observer) -> Result<(u32, u32), TerrainError> {
    let (w, h) = (grid.width(), grid.height());
    let (x, y, col, row) = match observer {
        Observer::Cell { col, row } => (col as f64, row as f64, col as f64, row as f64),
        Observer::Map { x, y } => {
            let (c, r) = grid.georef().xy_to_sample(x, y);
            // The cell of a sample reaches half a sample either side of its centre.
            (x, y, (c + 0.5).floor(), (r + 0.5).floor())
        }
    };
    if !(col >= 0.0 && row >= 0.0 && col < w as f64 && row < h as f64) {
        return Err(TerrainError::ObserverOutside {
            x,
            y,
            col,
            row,
            width: w,
            height: h,
        });
    }
    Ok((col as u32, row as u32))
}

/// The horizon of the cells next to the observer on the rows above and below it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Near {
    /// Their own height (they are always visible).
    Own,
    /// The observer's ground (GDAL 3.6).
    Ground,
}

/// The sweep's extrapolation of the horizon height `za` one cell further along a line through the
/// eye: `za` lies `i − 1` cells from the observer, the result `i` (`za` itself next to it).
#[inline]
/// Store a cell's class, horizon height and (when heights are kept) the height it would need.
fn put(c: usize, cell: (Seen, f64, f32), seen: &mut [Seen], horizon: &mut [f64], need: &mut [f32]) {
    (seen[c], horizon[c]) = (cell.0, cell.1);
    if !need.is_empty() {
        need[c] = cell.2;
    }
}

fn line(i: usize, za: f64, eye: f64) -> f64 {
    if i == 1 {
        za
    } else {
        (za - eye) / (i - 1) as f64 + za
    }
}

/// The plane through the eye, `za` (`i − 1, j − 1` from the observer along the two axes, `i ≤ j`)
/// and `zb` (`i, j − 1`), at `(i, j)`: Wang 2000's interpolation of the two horizon heights at the
/// sight line's crossing of row `j − 1`, extrapolated to row `j` (the module docs).
#[inline]
fn edge(i: usize, j: usize, za: f64, zb: f64, eye: f64) -> f64 {
    if i == j {
        line(i, za, eye)
    } else {
        ((za - eye) * i as f64 + (zb - eye) * (j - i) as f64) / (j - 1) as f64 + eye
    }
}

/// Everything a viewshed's cells share, worked out once.
struct Scene<'a> {
    h: &'a [f32],
    w: usize,
    rows: usize,
    oc: usize,
    or: usize,
    /// Ground metres per column step, at each row.
    ew: Vec<f64>,
    /// Ground metres from the observer's row to each row (signed).
    ns: Vec<f64>,
    curvature: f64,
    /// The maximum distance squared (infinite: none).
    md2: f64,
    eye: f64,
    /// The observer's ground.
    ground: f64,
    target: f64,
    /// Add each cell's ground to its needed height ([`Output::Elevation`]).
    elevation: bool,
}

impl<'a> Scene<'a> {
    fn new(grid: &'a Grid, (oc, or): (u32, u32), opts: &ViewshedOptions) -> Scene<'a> {
        let g = grid.georef();
        let rows = grid.height() as usize;
        let planar = match g.crs {
            CrsKind::Projected => !g.is_web_mercator(),
            CrsKind::Local => true,
            CrsKind::Geographic => false,
        };
        let (ew, ns): (Vec<f64>, Vec<f64>) = if planar {
            // The grid's own units, as GDAL's geotransform gives them: `dx·i`, `dy·j`.
            (0..rows)
                .map(|r| (g.dx, g.dy * (r as f64 - or as f64)))
                .unzip()
        } else {
            let south0 = g.local_metres(0.0, or as f64).1;
            (0..rows)
                .map(|r| {
                    let r = r as f64;
                    let (e0, s) = g.local_metres(0.0, r);
                    (g.local_metres(1.0, r).0 - e0, s - south0)
                })
                .unzip()
        };
        let ground = grid.at(oc, or) as f64;
        Scene {
            h: grid.heights(),
            w: grid.width() as usize,
            rows,
            oc: oc as usize,
            or: or as usize,
            ew,
            ns,
            curvature: opts.curvature,
            md2: opts.max_distance.map_or(f64::INFINITY, |d| d * d),
            eye: opts.observer_height + ground,
            ground,
            target: opts.target_height,
            elevation: opts.output == Output::Elevation,
        }
    }

    /// Squared ground distance from the observer to sample `(c, r)`.
    #[inline]
    fn r2(&self, c: usize, r: usize) -> f64 {
        let x = self.ew[r] * (c as f64 - self.oc as f64);
        let y = self.ns[r];
        x * x + y * y
    }

    /// The raw height of `(c, r)`.
    #[inline]
    fn raw(&self, c: usize, r: usize) -> f64 {
        self.h[r * self.w + c] as f64
    }

    /// The height of `(c, r)` lowered by curvature and refraction (`NaN`: no-data).
    #[inline]
    fn adjusted(&self, c: usize, r: usize, r2: f64) -> f64 {
        let v = self.raw(c, r);
        if self.curvature != 0.0 {
            v - self.curvature * r2 / EARTH_DIAMETER
        } else {
            v
        }
    }

    /// What a needed height is measured from at `(c, r)`.
    #[inline]
    fn base(&self, c: usize, r: usize) -> f64 {
        if self.elevation { self.raw(c, r) } else { 0.0 }
    }

    /// A cell at squared distance `r2` with adjusted height `a` under the plane `z`: its class, its
    /// horizon height and its needed height.
    #[inline]
    fn settle(&self, c: usize, r: usize, r2: f64, a: f64, z: f64) -> (Seen, f64, f32) {
        if a.is_nan() {
            // Transparent: the plane passes over a hole unchanged.
            return (Seen::NoData, z, f32::NAN);
        }
        let seen = if r2 > self.md2 {
            Seen::OutOfRange
        } else if a + self.target < z {
            Seen::Invisible
        } else {
            Seen::Visible
        };
        let horizon = if a < z { z } else { a };
        let need = if seen == Seen::OutOfRange {
            f32::NAN
        } else {
            (z - a + self.base(c, r)).max(0.0) as f32
        };
        (seen, horizon, need)
    }

    /// The plane at a cell next to the observer on the rows above or below (`a` its own adjusted
    /// height, `ground` the observer's ground as the previous row holds it).
    #[inline]
    fn near(&self, rule: Near, ground: f64, a: f64) -> f64 {
        match rule {
            Near::Ground => ground,
            Near::Own if a.is_nan() => self.ground,
            Near::Own => a,
        }
    }

    /// The reference-plane sweep: the observer's row, then the rows above and below it in
    /// parallel, each outwards from the observer's column.
    fn sweep(
        &self,
        rule: Near,
        seen: &mut [Seen],
        heights: Option<&mut [f32]>,
        tick: &(impl Fn() + Sync),
    ) {
        let w = self.w;
        let (seen_above, rest) = seen.split_at_mut(self.or * w);
        let (seen_row, seen_below) = rest.split_at_mut(w);
        // Without heights every row's slice of them is empty (the kernels test for that).
        let (need_above, need_row, need_below): (&mut [f32], &mut [f32], &mut [f32]) = match heights
        {
            Some(h) => {
                let (a, rest) = h.split_at_mut(self.or * w);
                let (r, b) = rest.split_at_mut(w);
                (a, r, b)
            }
            None => (&mut [], &mut [], &mut []),
        };
        let mut first = vec![0.0f64; w];
        self.first_row(&mut first, seen_row, need_row);
        tick();
        rayon::join(
            || {
                let mut last = first.clone();
                let mut this = vec![0.0f64; w];
                for r in (0..self.or).rev() {
                    let span = r * w..(r + 1) * w;
                    let need = if need_above.is_empty() {
                        &mut []
                    } else {
                        &mut need_above[span.clone()]
                    };
                    self.sweep_row(rule, r, &last, &mut this, &mut seen_above[span], need);
                    std::mem::swap(&mut last, &mut this);
                    tick();
                }
            },
            || {
                let mut last = first.clone();
                let mut this = vec![0.0f64; w];
                for r in self.or + 1..self.rows {
                    let k = r - self.or - 1;
                    let span = k * w..(k + 1) * w;
                    let need = if need_below.is_empty() {
                        &mut []
                    } else {
                        &mut need_below[span.clone()]
                    };
                    self.sweep_row(rule, r, &last, &mut this, &mut seen_below[span], need);
                    std::mem::swap(&mut last, &mut this);
                    tick();
                }
            },
        );
    }

    /// The observer's row: the observer and the samples beside it visible, the rest along the two
    /// half-lines.
    fn first_row(&self, first: &mut [f64], seen: &mut [Seen], need: &mut [f32]) {
        let (oc, r) = (self.oc, self.or);
        let cell = (Seen::Visible, self.ground, self.base(oc, r) as f32);
        put(oc, cell, seen, first, need);
        for (i, c, prev) in self.outward() {
            let r2 = self.r2(c, r);
            let a = self.adjusted(c, r, r2);
            let cell = if i == 1 {
                // Beside the observer: seen, whatever the range (as GDAL).
                if a.is_nan() {
                    (Seen::NoData, self.ground, f32::NAN)
                } else {
                    (Seen::Visible, a, self.base(c, r) as f32)
                }
            } else {
                self.settle(c, r, r2, a, line(i, first[prev], self.eye))
            };
            put(c, cell, seen, first, need);
        }
    }

    /// The columns of a row outward from the observer's, the left half-line then the right:
    /// `(i, c, prev)`, column `c` being `i` columns from the observer's and `prev` the column
    /// before it on its half-line.
    fn outward(&self) -> impl Iterator<Item = (usize, usize, usize)> {
        let (oc, w) = (self.oc, self.w);
        let left = (1..=oc).map(move |i| (i, oc - i, oc - i + 1));
        let right = (1..w - oc).map(move |i| (i, oc + i, oc + i - 1));
        left.chain(right)
    }

    /// Row `r` (not the observer's) from the horizon heights `last` of the row before it (one row
    /// nearer the observer) into `this`.
    fn sweep_row(
        &self,
        rule: Near,
        r: usize,
        last: &[f64],
        this: &mut [f64],
        seen: &mut [Seen],
        need: &mut [f32],
    ) {
        let (oc, eye) = (self.oc, self.eye);
        let j = r.abs_diff(self.or);
        // The observer's column: the line through the cell before it.
        let r2 = self.r2(oc, r);
        let a = self.adjusted(oc, r, r2);
        let z = if j == 1 {
            self.near(rule, last[oc], a)
        } else {
            line(j, last[oc], eye)
        };
        put(oc, self.settle(oc, r, r2, a, z), seen, this, need);
        for (i, c, prev) in self.outward() {
            let r2 = self.r2(c, r);
            let a = self.adjusted(c, r, r2);
            let z = if i == 1 && j == 1 {
                self.near(rule, last[oc], a)
            } else if i >= j {
                // Seen past column i − 1, between rows j − 1 and j.
                edge(j, i, last[prev], this[prev], eye)
            } else {
                // Seen past row j − 1, between columns i − 1 and i.
                edge(i, j, last[prev], last[c], eye)
            };
            put(c, self.settle(c, r, r2, a, z), seen, this, need);
        }
    }

    /// R3: a sight line to every cell, rows in parallel.
    fn sight_lines(
        &self,
        seen: &mut [Seen],
        heights: Option<&mut [f32]>,
        tick: &(impl Fn() + Sync),
    ) {
        use rayon::prelude::*;
        let w = self.w;
        match heights {
            Some(h) => seen
                .par_chunks_mut(w)
                .zip(h.par_chunks_mut(w))
                .enumerate()
                .for_each(|(r, (s, n))| {
                    self.sight_row(r, s, n);
                    tick();
                }),
            None => seen.par_chunks_mut(w).enumerate().for_each(|(r, s)| {
                self.sight_row(r, s, &mut []);
                tick();
            }),
        }
    }

    fn sight_row(&self, r: usize, seen: &mut [Seen], need: &mut [f32]) {
        let heights = !need.is_empty();
        for c in 0..self.w {
            let r2 = self.r2(c, r);
            let a = self.adjusted(c, r, r2);
            let (class, n) = if (c, r) == (self.oc, self.or) {
                (Seen::Visible, self.base(c, r) as f32)
            } else if a.is_nan() {
                (Seen::NoData, f32::NAN)
            } else if r2 > self.md2 {
                (Seen::OutOfRange, f32::NAN)
            } else if heights {
                // Nothing between (the observer's neighbours): the cell's own height, as the
                // sweeps take it.
                let (e, t) = self.steepest(c, r, r2, None);
                let z = if e == f64::NEG_INFINITY {
                    a
                } else {
                    self.eye + e / t
                };
                let class = if a + self.target < z {
                    Seen::Invisible
                } else {
                    Seen::Visible
                };
                (class, (z - a + self.base(c, r)).max(0.0) as f32)
            } else {
                let rise = a + self.target - self.eye;
                let (e, t) = self.steepest(c, r, r2, Some(rise));
                let blocked = e > rise * t;
                (
                    if blocked {
                        Seen::Invisible
                    } else {
                        Seen::Visible
                    },
                    0.0,
                )
            };
            seen[c] = class;
            if heights {
                need[c] = n;
            }
        }
    }

    /// The steepest rise of the terrain along the sight line from the eye to `(c, r)`, as `(e, t)`:
    /// the crossing `t` of the way along whose height above the eye `e` makes `e/t` largest.
    /// Crossings are those of every column and row line strictly between the two, the terrain there
    /// the linear interpolation of the two samples on the line (R3), lowered by curvature by
    /// `c·(t·d)²/D`. With `stop`, returns as soon as a crossing has `e > stop·t` (the target is
    /// hidden). `e = −∞` when nothing lies between.
    fn steepest(&self, c: usize, r: usize, r2: f64, stop: Option<f64>) -> (f64, f64) {
        let drop = if self.curvature != 0.0 {
            self.curvature * r2 / EARTH_DIAMETER
        } else {
            0.0
        };
        let (dc, dr) = (c as i64 - self.oc as i64, r as i64 - self.or as i64);
        let w = self.w as i64;
        // The steepest crossing so far as (height above the eye, t): rises are compared by cross
        // multiplication (t > 0), so the loop divides nothing.
        let (mut best_e, mut best_t) = (f64::NEG_INFINITY, 1.0);
        // Column lines (steps = |dc|, across = dr, the sample pairs one above the other), then row
        // lines (the pairs side by side).
        for (steps, across, column) in [(dc, dr, true), (dr, dc, false)] {
            let n = steps.abs();
            if n < 2 {
                continue;
            }
            let inv = 1.0 / n as f64;
            // The crossing k steps along lies k·across/n across: q whole samples and rem/n of
            // one, kept exactly by adding across/n's quotient and remainder at each step.
            let (qa, ra) = (across.div_euclid(n), across.rem_euclid(n));
            let (mut q, mut rem) = (0i64, 0i64);
            // Index steps along the line and across it; the second sample of a pair is the
            // next one across.
            let (along, across_step) = if column {
                (steps.signum(), w)
            } else {
                (steps.signum() * w, 1)
            };
            let origin = self.or as i64 * w + self.oc as i64;
            for k in 1..n {
                q += qa;
                rem += ra;
                if rem >= n {
                    rem -= n;
                    q += 1;
                }
                let at = (origin + k * along + q * across_step) as usize;
                let h0 = self.h[at] as f64;
                let z = if rem == 0 {
                    h0
                } else {
                    let h1 = self.h[at + across_step as usize] as f64;
                    h0 + (h1 - h0) * (rem as f64 * inv)
                };
                if z.is_nan() {
                    continue; // no-data never blocks
                }
                let t = k as f64 * inv;
                let e = z - drop * t * t - self.eye;
                if e * best_t > best_e * t {
                    (best_e, best_t) = (e, t);
                    if stop.is_some_and(|s| e > s * t) {
                        break;
                    }
                }
            }
            if stop.is_some_and(|s| best_e > s * best_t) {
                break;
            }
        }
        (best_e, best_t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::Georef;

    fn flat(n: u32, cell: f64) -> Grid {
        Grid::new(
            "flat",
            n,
            n,
            vec![100.0; (n * n) as usize],
            Georef::local(cell),
        )
        .unwrap()
    }

    #[test]
    fn line_and_edge_extend_planes_through_the_eye() {
        // A horizon falling 1 m per cell from an eye at 10 m keeps falling 1 m per cell.
        assert_eq!(line(3, 8.0, 10.0), 7.0);
        assert_eq!(line(1, 8.0, 10.0), 8.0);
        // The plane z = 10 − x − 2y through the eye: (1, 2) and (2, 2) give (2, 3), whose
        // sight line crosses row 2 at x = 4/3.
        let z = |x: f64, y: f64| 10.0 - x - 2.0 * y;
        let got = edge(2, 3, z(1.0, 2.0), z(2.0, 2.0), 10.0);
        assert!((got - z(2.0, 3.0)).abs() < 1e-12, "{got}");
    }

    #[test]
    fn refuses_an_observer_outside_or_on_no_data() {
        let g = flat(5, 1.0);
        let o = ViewshedOptions::default();
        let e = viewshed(&g, Observer::Map { x: 7.0, y: -1.0 }, &o).unwrap_err();
        assert!(matches!(e, TerrainError::ObserverOutside { .. }), "{e}");
        assert!(e.to_string().contains("outside the 5 x 5 grid"), "{e}");
        let e = viewshed(&g, Observer::Cell { col: 5, row: 0 }, &o).unwrap_err();
        assert!(matches!(e, TerrainError::ObserverOutside { .. }), "{e}");
        let mut h = vec![1.0; 25];
        h[12] = f32::NAN;
        let g = Grid::new("hole", 5, 5, h, Georef::local(1.0)).unwrap();
        let e = viewshed(&g, Observer::Cell { col: 2, row: 2 }, &o).unwrap_err();
        assert!(
            matches!(e, TerrainError::ObserverNoData { col: 2, row: 2 }),
            "{e}"
        );
        // Map points within half a cell of a sample stand on it.
        let v = viewshed(&flat(5, 1.0), Observer::Map { x: 4.49, y: -0.3 }, &o).unwrap();
        assert_eq!(v.observer, (4, 0));
    }

    const ALL: [Method; 3] = [Method::Wang, Method::Gdal, Method::Exact];

    #[test]
    fn a_flat_plane_is_seen_whole() {
        let g = flat(33, 30.0);
        for method in ALL {
            for observer in [
                Observer::Cell { col: 16, row: 16 },
                Observer::Cell { col: 0, row: 32 },
            ] {
                let o = ViewshedOptions {
                    method,
                    curvature: 0.0,
                    output: Output::Height,
                    ..Default::default()
                };
                let v = viewshed(&g, observer, &o).unwrap();
                assert_eq!(v.counts().visible, 33 * 33, "{method:?} {observer:?}");
                assert!(v.heights.unwrap().iter().all(|&h| h == 0.0), "{method:?}");
            }
        }
    }

    /// A wall 1 m high along column 10 of flat ground, the eye 2 m up at column 0: the sight line
    /// to ground at column c passes the wall at 2·(1 − 10/c) m, so columns 11..=19 are hidden and
    /// 20 on (where it grazes the top) are seen, on every row; a target needs 2 − c/10 m there.
    #[test]
    fn a_wall_casts_the_shadow_geometry_says() {
        let (w, h) = (41u32, 61u32);
        let heights = (0..w * h)
            .map(|i| if i % w == 10 { 1.0 } else { 0.0 })
            .collect();
        let g = Grid::new("wall", w, h, heights, Georef::local(10.0)).unwrap();
        for method in ALL {
            let o = ViewshedOptions {
                method,
                curvature: 0.0,
                output: Output::Height,
                ..Default::default()
            };
            let v = viewshed(&g, Observer::Cell { col: 0, row: 30 }, &o).unwrap();
            let need = v.heights.as_ref().unwrap();
            for row in 0..h {
                for col in 0..w {
                    let want = if (11..20).contains(&col) {
                        Seen::Invisible
                    } else {
                        Seen::Visible
                    };
                    // Column 20 is a tie (the sight line grazes the wall's top): the sweeps' plane
                    // there is 2 − 20/10 = 0 up to rounding, either side of the ground.
                    if col != 20 || method == Method::Exact {
                        assert_eq!(v.at(col, row), want, "{method:?} at ({col}, {row})");
                    }
                    let n = need[(row * w + col) as usize] as f64;
                    let expect = if col > 10 {
                        (2.0 - col as f64 / 10.0).max(0.0)
                    } else {
                        0.0
                    };
                    assert!(
                        (n - expect).abs() < 1e-5,
                        "{method:?} ({col}, {row}): {n} vs {expect}"
                    );
                }
            }
        }
    }

    /// Over flat ground the earth's curvature less refraction hides everything beyond the horizon
    /// `√(h·D/c)` (the sight line from an eye `h` up grazes ground lowered by `c·d²/D`): 5456 m
    /// for a 2 m eye with the standard coefficient. Sampling puts the edge within a cell or two.
    #[test]
    fn the_curved_earth_has_a_horizon_where_textbooks_put_it() {
        let g = flat(121, 100.0);
        let horizon = (2.0 * EARTH_DIAMETER / DEFAULT_CURVATURE).sqrt();
        assert!((horizon - 5455.8).abs() < 0.5, "{horizon}");
        for method in ALL {
            let o = ViewshedOptions {
                method,
                ..Default::default()
            };
            let v = viewshed(&g, Observer::Cell { col: 60, row: 60 }, &o).unwrap();
            for row in 0..121u32 {
                for col in 0..121u32 {
                    let d = 100.0 * ((col as f64 - 60.0).hypot(row as f64 - 60.0));
                    let seen = v.at(col, row);
                    let beside = col.abs_diff(60) <= 1 && row.abs_diff(60) == 1;
                    if method == Method::Gdal && beside {
                        // GDAL 3.6 compares the six cells beside the observer on the rows above
                        // and below with the observer's ground, which curvature has not lowered.
                        assert_eq!(seen, Seen::Invisible, "{method:?} at {d} m");
                    } else if d < horizon - 200.0 {
                        assert_eq!(seen, Seen::Visible, "{method:?} at {d} m");
                    } else if d > horizon + 200.0 {
                        assert_eq!(seen, Seen::Invisible, "{method:?} at {d} m");
                    }
                }
            }
        }
    }

    #[test]
    fn max_distance_is_its_own_class_and_heights_are_nan_there() {
        let g = flat(41, 100.0);
        for method in ALL {
            let o = ViewshedOptions {
                method,
                max_distance: Some(1000.0),
                curvature: 0.0,
                output: Output::Elevation,
                ..Default::default()
            };
            let v = viewshed(&g, Observer::Cell { col: 20, row: 20 }, &o).unwrap();
            let need = v.heights.as_ref().unwrap();
            for row in 0..41u32 {
                for col in 0..41u32 {
                    let d2 = 1e4 * ((col as f64 - 20.0).powi(2) + (row as f64 - 20.0).powi(2));
                    let n = need[(row * 41 + col) as usize];
                    if d2 > 1e6 {
                        assert_eq!(v.at(col, row), Seen::OutOfRange, "{method:?}");
                        assert!(n.is_nan());
                    } else {
                        // -om DEM: flat ground within 1 km is seen, so a target is seen down
                        // to the sight line's height, below the ground (the eye is 2 m up and
                        // the line falls 2 m per 100 m at most).
                        assert_eq!(v.at(col, row), Seen::Visible, "{method:?}");
                        assert!((98.0..=100.0).contains(&n), "{method:?}: {n}");
                    }
                }
            }
        }
    }

    #[test]
    fn holes_never_block_and_are_their_own_class() {
        // A 60 m wall of no-data across a flat plane: every real cell stays visible.
        let n = 21u32;
        let mut h = vec![0.0f32; (n * n) as usize];
        for r in 0..n {
            h[(r * n + 12) as usize] = f32::NAN;
        }
        let g = Grid::new("holes", n, n, h, Georef::local(10.0)).unwrap();
        for method in [Method::Wang, Method::Gdal, Method::Exact] {
            let o = ViewshedOptions {
                method,
                curvature: 0.0,
                ..Default::default()
            };
            let v = viewshed(&g, Observer::Cell { col: 3, row: 10 }, &o).unwrap();
            let c = v.counts();
            assert_eq!((c.nodata, c.invisible), (n as u64, 0), "{method:?}");
        }
    }
}
