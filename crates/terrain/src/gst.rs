//! Geospecific texture (GST, Seed 000): an orthophoto placed over the elevation grid, cut into a
//! pyramid of square maps, and the residency of those maps decided by Seed 000 Eq. (5)–(7).
//!
//! **Placement.** The texture spans the DEM's extent from the centre of sample (0, 0) (`u, v = 0`)
//! to that of the last sample (`u, v = 1`), the same `[0, 1]²` the chunk vertices' texture
//! coordinates use. A photo with a georeference (a GeoTIFF, a VRT, a mosaic of tiles) is sampled
//! where it lies; texels outside it are transparent (alpha 0) and no overlap at all is an error.
//! A photo without one (PNG, JPEG, a plain TIFF) is stretched over the extent. Colours are
//! interpolated weighted by their alpha (premultiplied), so that the transparent pixels of a
//! photo's no-data, alpha band or mosaic gaps lend no colour to the texels beside them; a
//! database draws the grid's shaded relief under the texels the photo does not fully cover
//! ([`Drawn::relief_under`]), the texture a database without a photo has.
//!
//! **Reprojection.** A photo in another coordinate system than the grid's is reprojected on the
//! fly: each texel's grid coordinates go through longitude and latitude into the photo's system
//! ([`crate::geodesy::Placement`]: WGS 84 longitude/latitude, UTM of WGS 84, ETRS89 or NAD83, Web
//! Mercator), so a Sentinel-2 scene in UTM drapes an SRTM tile in degrees, and a photo in a
//! neighbouring UTM zone lands where it belongs instead of where its numbers would put it in the
//! grid's zone. As in GDAL's warper, the exact transform is evaluated on a lattice over the grid
//! (64 cells a side, doubled until the bilinear interpolation between nodes is within 0.02 photo
//! pixels of it at every cell's centre and edge midpoints) and interpolated between nodes. Two codes with no
//! conversion here are an error that names both and the `gdalwarp` command to use; a side with no
//! code is taken to be in the other's system.
//! Multispectral GeoTIFFs choose three bands (`--bands 3,2,1`); samples wider than 8 bits are
//! stretched linearly from each band's minimum to its maximum, or between percentiles or given
//! values with a gamma ([`crate::photo::PhotoOptions`]).
//!
//! **Pyramid.** Level `L` is `T·2^L` texels a side (`T` texels per map, 256 by default) and holds
//! `2^L x 2^L` maps of `T x T`; the finest level is resampled bilinearly from the photo and each
//! coarser one is the 2x2 box average of the next (in 8-bit sRGB, as the tiles are stored).
//!
//! **Residency** ([`needed_maps`], [`GstCache`]). Seed 000 Eq. (7) bounds the level a ground point
//! at distance `x_a` can need; level `L` is needed within `radius_in_own_maps` of its own maps
//! around the eye ([`texmap_core::coverage::ActiveArea`]), i.e. a block of `2⌈r⌉ x 2⌈r⌉` maps per
//! level — 36 per level and 324 for levels 0..=8 in the paper's worked example (ψ = 45°, 1024
//! pixels, 256² maps). The cache keeps those maps resident under a byte budget, evicting the least
//! recently used ones first, and counts hits, loads and evictions for the flight view to report.

use crate::dem::{Georef, Grid};
use crate::error::{TerrainError, format_err, io};
use crate::photo::PhotoOptions;
use image::{Rgba, RgbaImage};
use std::collections::HashMap;
use std::path::Path;
use texmap_core::coverage::ActiveArea;

/// An orthophoto in 8-bit RGBA with its georeference, if it has one.
#[derive(Clone, Debug)]
pub struct Orthophoto {
    pub image: RgbaImage,
    pub georef: Option<Georef>,
    pub source: String,
    /// The stretch its colours were made with, when they were mapped from other samples.
    pub stretch: Option<crate::photo::Applied>,
}

/// Read an orthophoto whole: PNG or JPEG through `image`; a TIFF or a GDAL VRT through
/// [`crate::photo::TiffPhoto`] and [`crate::photo::VrtPhoto`] (the same pixels as their rows),
/// its bands and colours by `opts` ([`crate::photo::PhotoOptions`]).
pub fn read_photo(path: &Path, opts: &PhotoOptions) -> Result<Orthophoto, TerrainError> {
    let source = path.display().to_string();
    let rows: Option<Box<dyn PhotoSource>> = if crate::photo::is_tiff(path) {
        Some(Box::new(crate::photo::TiffPhoto::open(path, opts)?))
    } else if crate::dem::vrt::is_vrt(path) {
        Some(Box::new(crate::photo::VrtPhoto::open(path, opts)?))
    } else {
        None
    };
    if let Some(p) = rows {
        return Ok(Orthophoto {
            image: p.rows(0, p.size().1)?,
            georef: p.georef(),
            stretch: p.stretch(),
            source,
        });
    }
    let img = image::ImageReader::open(path)
        .map_err(io(path))?
        .with_guessed_format()
        .map_err(io(path))?
        .decode()
        .map_err(|e| format_err(&source, "image data", format!("a PNG or JPEG ({e})")))?;
    let (image, stretch) = crate::photo::decoded_to_rgba(img, opts, &source)?;
    Ok(Orthophoto {
        image,
        georef: None,
        source,
        stretch,
    })
}

/// A map of the pyramid: level, column, row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MapKey {
    pub level: u32,
    pub x: u32,
    pub y: u32,
}

/// A GST pyramid: `levels[L]` is `T·2^L` texels a side.
#[derive(Clone, Debug)]
pub struct Pyramid {
    pub map_texels: u32,
    pub levels: Vec<RgbaImage>,
}

/// Bilinear sample at continuous pixel position `(x, y)` (pixel corners at integers) of a
/// `w x h` image whose pixel `(i, j)` is `px(i, j)`, clamped at the image's edges.
fn bilinear(w: i64, h: i64, px: impl Fn(u32, u32) -> [f64; 4], x: f64, y: f64) -> [f64; 4] {
    let (fx, fy) = (x - 0.5, y - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (ax, ay) = (fx - x0, fy - y0);
    let px = |i: i64, j: i64| px(i.clamp(0, w - 1) as u32, j.clamp(0, h - 1) as u32);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let (a, b, c, d) = (
        px(x0, y0),
        px(x0 + 1, y0),
        px(x0, y0 + 1),
        px(x0 + 1, y0 + 1),
    );
    std::array::from_fn(|k| {
        (a[k] * (1.0 - ax) + b[k] * ax) * (1.0 - ay) + (c[k] * (1.0 - ax) + d[k] * ax) * ay
    })
}

/// Where a photo lies over a lattice (a grid's samples, or a photo mosaic's pixels): texture
/// coordinates `(u, v)` over the lattice's extent, from the centre of its first sample to that of
/// its last, to photo pixel positions (see the module docs).
#[derive(Debug)]
pub(crate) struct Placement {
    grid: Georef,
    gw: f64,
    gh: f64,
    photo: Option<Georef>,
    pw: f64,
    ph: f64,
    /// Photo positions on a `(k + 1)²` lattice over `[0, 1]²`, row-major, when the photo is in
    /// another coordinate system than the grid: positions between the nodes are bilinear.
    lattice: Option<(usize, Vec<(f64, f64)>)>,
}

/// The largest distance in photo pixels between a reprojected position and the lattice's
/// bilinear interpolation of it, at the lattice cells' centres and edge midpoints (GDAL's
/// approximate transformer allows 0.125 by default).
const LATTICE_TOLERANCE_PX: f64 = 0.02;
/// The finest lattice: 1024 x 1024 cells.
const LATTICE_MAX_CELLS: usize = 1024;

fn crs_name(g: &Georef) -> String {
    match g.epsg {
        Some(e) => format!("EPSG:{e}"),
        None => format!("{:?}", g.crs).to_lowercase(),
    }
}

impl Placement {
    /// The photo of `size` pixels at `georef` over the `lattice.1 x lattice.2` samples of
    /// `lattice.0`; an error when none of it lies there.
    pub(crate) fn new(
        lattice: (&Georef, u32, u32),
        size: (u32, u32),
        georef: Option<Georef>,
        source: &str,
    ) -> Result<Placement, TerrainError> {
        let mut p = Placement {
            grid: *lattice.0,
            gw: lattice.1.saturating_sub(1) as f64,
            gh: lattice.2.saturating_sub(1) as f64,
            photo: georef,
            pw: size.0 as f64,
            ph: size.1 as f64,
            lattice: None,
        };
        let Some(pg) = p.photo else {
            return Ok(p);
        };
        let (from, to) = (
            crate::geodesy::Placement::of(&p.grid),
            crate::geodesy::Placement::of(&pg),
        );
        match (from, to) {
            (Some(from), Some(to)) if from != to => p.lattice = Some(p.reprojection(from, to)),
            (Some(_), Some(_)) => {}
            _ if p.grid.epsg.is_some() && pg.epsg.is_some() && p.grid.epsg != pg.epsg => {
                return Err(TerrainError::Unsupported {
                    source: source.to_string(),
                    what: format!(
                        "placing a photo in {} on an elevation grid in {}: texmap reprojects \
                         between WGS 84 longitude/latitude, UTM (WGS 84, ETRS89, NAD83) and Web \
                         Mercator only; reproject the photo first, e.g. gdalwarp -t_srs {} \
                         -r bilinear",
                        crs_name(&pg),
                        crs_name(&p.grid),
                        crs_name(&p.grid),
                    ),
                });
            }
            // A side without a code: the photo is taken to be in the grid's system.
            _ => {}
        }
        if !p.overlaps(from, to) {
            let (cmin, cmax, rmin, rmax) = p.grid_in_photo();
            return Err(TerrainError::NoOverlap {
                photo: source.to_string(),
                dem: format!(
                    "({}): the grid falls at photo pixels {cmin:.0}..{cmax:.0} x \
                     {rmin:.0}..{rmax:.0}, outside its {} x {} pixels{}",
                    crs_name(&p.grid),
                    p.pw,
                    p.ph,
                    if p.lattice.is_some() {
                        format!(" (the photo in {}, reprojected)", crs_name(&pg))
                    } else {
                        String::new()
                    }
                ),
            });
        }
        Ok(p)
    }

    /// Whether any of the photo lies over the grid's extent: the extents' rectangles in photo
    /// pixels, or, reprojected, a lattice node on the photo or a photo corner on the grid.
    fn overlaps(
        &self,
        from: Option<crate::geodesy::Placement>,
        to: Option<crate::geodesy::Placement>,
    ) -> bool {
        let on_photo = |(c, r): (f64, f64)| c >= 0.0 && r >= 0.0 && c <= self.pw && r <= self.ph;
        match (&self.lattice, from, to, &self.photo) {
            (Some((_, nodes)), Some(from), Some(to), Some(pg)) => {
                nodes.iter().any(|&q| on_photo(q))
                    || [
                        (0.0, 0.0),
                        (self.pw, 0.0),
                        (0.0, self.ph),
                        (self.pw, self.ph),
                    ]
                    .into_iter()
                    .any(|(c, r)| {
                        let (x, y) = pg.sample_xy(c - 0.5, r - 0.5);
                        let (lon, lat) = to.lonlat(x, y);
                        let (gx, gy) = from.xy(lon, lat);
                        let (col, row) = self.grid.xy_to_sample(gx, gy);
                        (0.0..=self.gw).contains(&col) && (0.0..=self.gh).contains(&row)
                    })
            }
            _ => {
                let (cmin, cmax, rmin, rmax) = self.grid_in_photo();
                !(cmax <= 0.0 || rmax <= 0.0 || cmin >= self.pw || rmin >= self.ph)
            }
        }
    }

    /// The photo pixel ranges (columns, then rows) between the grid's first and last sample.
    fn grid_in_photo(&self) -> (f64, f64, f64, f64) {
        let (a, b) = (self.to_photo(0.0, 0.0), self.to_photo(1.0, 1.0));
        (a.0.min(b.0), a.0.max(b.0), a.1.min(b.1), a.1.max(b.1))
    }

    /// The exact photo position of `(u, v)` through longitude and latitude.
    fn reprojected(
        &self,
        from: crate::geodesy::Placement,
        to: crate::geodesy::Placement,
        pg: &Georef,
        u: f64,
        v: f64,
    ) -> (f64, f64) {
        let (x, y) = self.grid.sample_xy(u * self.gw, v * self.gh);
        let (lon, lat) = from.lonlat(x, y);
        let (px, py) = to.xy(lon, lat);
        let (c, r) = pg.xy_to_sample(px, py);
        (c + 0.5, r + 0.5)
    }

    /// The coarsest lattice (from 64 cells a side, doubling) whose bilinear interpolation is
    /// within [`LATTICE_TOLERANCE_PX`] of the exact reprojection at every cell's centre and the
    /// midpoints of its top and left edges.
    fn reprojection(
        &self,
        from: crate::geodesy::Placement,
        to: crate::geodesy::Placement,
    ) -> (usize, Vec<(f64, f64)>) {
        let pg = self.photo.expect("a photo georeference");
        let mut k = 64;
        loop {
            let inv = 1.0 / k as f64;
            let nodes: Vec<(f64, f64)> = (0..(k + 1) * (k + 1))
                .map(|i| {
                    let (a, b) = (i % (k + 1), i / (k + 1));
                    self.reprojected(from, to, &pg, a as f64 * inv, b as f64 * inv)
                })
                .collect();
            if k >= LATTICE_MAX_CELLS {
                return (k, nodes);
            }
            // At the centre a conformal map's two curvatures cancel (its components are
            // harmonic), so the edges' midpoints are checked too.
            let mut worst = 0.0f64;
            for b in 0..k {
                for a in 0..k {
                    let q = |da: usize, db: usize| nodes[(b + db) * (k + 1) + a + da];
                    let (n00, n10, n01, n11) = (q(0, 0), q(1, 0), q(0, 1), q(1, 1));
                    let mid = |p: (f64, f64), q: (f64, f64)| ((p.0 + q.0) / 2.0, (p.1 + q.1) / 2.0);
                    for (s, t, est) in [
                        (0.5, 0.5, mid(mid(n00, n10), mid(n01, n11))),
                        (0.5, 0.0, mid(n00, n10)),
                        (0.0, 0.5, mid(n00, n01)),
                    ] {
                        let exact = self.reprojected(
                            from,
                            to,
                            &pg,
                            (a as f64 + s) * inv,
                            (b as f64 + t) * inv,
                        );
                        let e = (est.0 - exact.0).hypot(est.1 - exact.1);
                        // NaN (a position off the projection's domain) counts as a miss.
                        worst = if e.is_nan() {
                            f64::INFINITY
                        } else {
                            worst.max(e)
                        };
                    }
                }
            }
            if worst <= LATTICE_TOLERANCE_PX {
                return (k, nodes);
            }
            k *= 2;
        }
    }

    /// Photo pixel position (continuous, pixel corners at integers) of texture coordinates.
    pub(crate) fn to_photo(&self, u: f64, v: f64) -> (f64, f64) {
        match (&self.photo, &self.lattice) {
            (Some(_), Some((k, nodes))) => {
                let k = *k;
                let (fu, fv) = (u.clamp(0.0, 1.0) * k as f64, v.clamp(0.0, 1.0) * k as f64);
                let (a, b) = ((fu as usize).min(k - 1), (fv as usize).min(k - 1));
                let (s, t) = (fu - a as f64, fv - b as f64);
                let q = |da: usize, db: usize| nodes[(b + db) * (k + 1) + a + da];
                let (n00, n10, n01, n11) = (q(0, 0), q(1, 0), q(0, 1), q(1, 1));
                let lerp = |p: f64, q: f64, w: f64| p + (q - p) * w;
                (
                    lerp(lerp(n00.0, n10.0, s), lerp(n01.0, n11.0, s), t),
                    lerp(lerp(n00.1, n10.1, s), lerp(n01.1, n11.1, s), t),
                )
            }
            (Some(pg), None) => {
                let (x, y) = self.grid.sample_xy(u * self.gw, v * self.gh);
                let (c, r) = pg.xy_to_sample(x, y);
                (c + 0.5, r + 0.5)
            }
            (None, _) => (u * self.pw, v * self.ph),
        }
    }

    /// The texel of a `size`-sided texture at `(tx, ty)`: the photo sampled bilinearly through
    /// `px` with its colours weighted by their alpha (premultiplied, so that a transparent pixel
    /// lends a texel none of its colour), transparent outside the photo; not rounded.
    fn texel(&self, size: u32, tx: u32, ty: u32, px: impl Fn(u32, u32) -> [u8; 4]) -> [f64; 4] {
        let inv = 1.0 / (size - 1).max(1) as f64;
        let (x, y) = self.to_photo(tx as f64 * inv, ty as f64 * inv);
        let inside = x >= 0.0 && y >= 0.0 && x <= self.pw && y <= self.ph;
        if !inside {
            return [0.0; 4];
        }
        let premultiplied = |i, j| {
            let [r, g, b, a] = px(i, j);
            // An opaque pixel is its colour exactly (a / 255 = 1).
            let k = a as f64 / 255.0;
            [r as f64 * k, g as f64 * k, b as f64 * k, a as f64]
        };
        bilinear(self.pw as i64, self.ph as i64, premultiplied, x, y)
    }

    /// The photo rows bilinear reads for texture rows `ty0..ty1` of a `size`-sided texture
    /// (`None` when none of them lies on the photo).
    fn rows_for(&self, size: u32, ty0: u32, ty1: u32) -> Option<(u32, u32)> {
        let inv = 1.0 / (size - 1).max(1) as f64;
        self.rows_between(ty0 as f64 * inv, (ty1 - 1) as f64 * inv)
    }

    /// The photo rows bilinear reads for texture coordinates `v0..=v1` (`None` when none of them
    /// lies on the photo).
    pub(crate) fn rows_between(&self, v0: f64, v1: f64) -> Option<(u32, u32)> {
        let (lo, hi) = match &self.lattice {
            // Bilinear positions lie between their cell's nodes: bound by the nodes of the
            // lattice rows the texture rows fall in.
            Some((k, nodes)) => {
                let row = |v: f64| ((v.clamp(0.0, 1.0) * *k as f64) as usize).min(k - 1);
                nodes[row(v0) * (k + 1)..(row(v1) + 2) * (k + 1)]
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                        (lo.min(q.1), hi.max(q.1))
                    })
            }
            None => {
                let ys = [
                    self.to_photo(0.0, v0).1,
                    self.to_photo(1.0, v0).1,
                    self.to_photo(0.0, v1).1,
                    self.to_photo(1.0, v1).1,
                ];
                (
                    ys.iter().copied().fold(f64::INFINITY, f64::min),
                    ys.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                )
            }
        };
        if hi < 0.0 || lo > self.ph {
            return None;
        }
        let last = self.ph as i64 - 1;
        let r0 = ((lo - 0.5).floor() as i64).clamp(0, last);
        let r1 = ((hi - 0.5).floor() as i64 + 1).clamp(0, last);
        Some((r0 as u32, r1 as u32 + 1))
    }
}

/// A grid's samples as the lattice a photo is placed over.
fn lattice(grid: &Grid) -> (&Georef, u32, u32) {
    (grid.georef(), grid.width(), grid.height())
}

/// Resample `photo` over the grid's extent into a `size x size` texture (see the module docs).
/// Where the photo is transparent its texels are too, their colours premultiplied by alpha.
pub fn place(photo: &Orthophoto, grid: &Grid, size: u32) -> Result<RgbaImage, TerrainError> {
    let img = &photo.image;
    let p = Placement::new(lattice(grid), img.dimensions(), photo.georef, &photo.source)?;
    Ok(RgbaImage::from_fn(size, size, |tx, ty| {
        Rgba(round(p.texel(size, tx, ty, |i, j| img.get_pixel(i, j).0)))
    }))
}

fn round(c: [f64; 4]) -> [u8; 4] {
    c.map(|v| v.round() as u8)
}

/// What a pyramid's finest level draws besides the photo ([`write_pyramid_with`]).
#[derive(Clone, Copy, Default)]
pub struct Drawn<'a> {
    /// The grid's shaded relief in this tint ([`crate::relief::Tint::texel`], one sample per
    /// texel) under the photo, where the photo does not cover: beyond it, and at its no-data and
    /// transparent pixels (composited under the premultiplied texel: `C + relief·(1 − A/255)`,
    /// opaque).
    pub relief_under: Option<&'a crate::relief::Tint>,
    /// Contour lines ([`crate::relief::Contours`]), over the photo.
    pub contours: Option<&'a crate::relief::Contours>,
    /// Vector overlays ([`crate::vector::Overlay`], placed on this pyramid's finest level), last.
    pub overlay: Option<&'a crate::vector::Overlay>,
}

/// Box-average four `T x T` child maps (north-west, north-east, south-west, south-east) into
/// their parent map, in 8-bit sRGB as the tiles are stored (the same rule as [`pyramid`]).
fn parent_map(children: &[RgbaImage; 4], t: u32) -> RgbaImage {
    let h = t / 2;
    RgbaImage::from_fn(t, t, |x, y| {
        let child = &children[(y / h * 2 + x / h) as usize];
        let (cx, cy) = (2 * (x % h), 2 * (y % h));
        let mut s = [0u32; 4];
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let p = child.get_pixel(cx + dx, cy + dy).0;
            for k in 0..4 {
                s[k] += p[k] as u32;
            }
        }
        Rgba(s.map(|v| ((v + 2) / 4) as u8))
    })
}

/// Make the GST pyramid of `photo` over `grid` map by map, never holding a level: the finest
/// level (`levels − 1`) one row of maps at a time from the photo rows it needs
/// ([`PhotoSource::rows`], read once per row of maps), each coarser map from its four children
/// read back through `read`. Every map goes to `write` as it is made (maps of one row, or of one
/// level, in parallel); `progress(level)` after each level, finest first. The maps equal those of
/// `pyramid(place(photo, grid, T·2^(levels−1)), T)` byte for byte.
pub fn write_pyramid(
    photo: &dyn PhotoSource,
    grid: &Grid,
    map_texels: u32,
    levels: u32,
    write: &(dyn Fn(MapKey, &RgbaImage) -> Result<(), TerrainError> + Sync),
    read: &(dyn Fn(MapKey) -> Result<RgbaImage, TerrainError> + Sync),
    progress: &mut dyn FnMut(u32),
) -> Result<(), TerrainError> {
    let drawn = Drawn::default();
    write_pyramid_with(
        photo, grid, map_texels, levels, &drawn, write, read, progress,
    )
}

/// [`write_pyramid`] with the shaded relief under the photo, contour lines and then vector
/// overlays drawn into the finest level's texels ([`Drawn`]); the coarser levels average them
/// down like the photo.
#[allow(clippy::too_many_arguments)]
pub fn write_pyramid_with(
    photo: &dyn PhotoSource,
    grid: &Grid,
    map_texels: u32,
    levels: u32,
    drawn: &Drawn,
    write: &(dyn Fn(MapKey, &RgbaImage) -> Result<(), TerrainError> + Sync),
    read: &(dyn Fn(MapKey) -> Result<RgbaImage, TerrainError> + Sync),
    progress: &mut dyn FnMut(u32),
) -> Result<(), TerrainError> {
    use rayon::prelude::*;
    let t = map_texels;
    if levels == 0 || t < 2 || !t.is_power_of_two() {
        return Err(TerrainError::BadParameter {
            name: "map texels",
            value: format!("{t} texels, {levels} levels"),
            expected: "a power of two ≥ 2 and at least one level",
        });
    }
    let finest = levels - 1;
    let n = 1u32 << finest;
    let size = t << finest;
    let (pw, ph) = photo.size();
    let p = Placement::new(lattice(grid), (pw, ph), photo.georef(), photo.source())?;
    let Drawn {
        relief_under,
        contours,
        overlay,
    } = *drawn;
    let shade = relief_under.map(|tint| {
        (
            tint,
            crate::relief::Hillshade::new(grid, crate::relief::Light::default()),
        )
    });
    if let Some(o) = overlay.filter(|o| o.size() != size) {
        return Err(TerrainError::BadParameter {
            name: "overlay size",
            value: format!("{} texels for a finest level of {size}", o.size()),
            expected: "an overlay placed on this pyramid's finest level",
        });
    }
    for y in 0..n {
        let rows = p.rows_for(size, y * t, (y + 1) * t);
        let band = match rows {
            Some((r0, r1)) => photo.rows(r0, r1)?,
            None => RgbaImage::new(pw, 0),
        };
        let r0 = rows.map_or(0, |r| r.0);
        (0..n).into_par_iter().try_for_each(|x| {
            // Grid samples per texel (the texture spans sample 0 to the last).
            let per_texel = [
                (grid.width() - 1) as f64 / (size - 1).max(1) as f64,
                (grid.height() - 1) as f64 / (size - 1).max(1) as f64,
            ];
            let mut map = RgbaImage::from_fn(t, t, |i, j| {
                let (gx, gy) = (x * t + i, y * t + j);
                // `rows_for` covers every row a texel on the photo reads.
                let c = p.texel(size, gx, gy, |a, b| {
                    band.get_pixel_checked(a, b.wrapping_sub(r0))
                        .map_or([0; 4], |px| px.0)
                });
                let px = match &shade {
                    Some((tint, shade)) if c[3] < 255.0 => {
                        let under = tint.texel(grid, shade, size, gx, gy);
                        let k = 1.0 - c[3] / 255.0;
                        let c = [0, 1, 2].map(|i| c[i] + under[i] as f64 * k);
                        Rgba([
                            c[0].round() as u8,
                            c[1].round() as u8,
                            c[2].round() as u8,
                            255,
                        ])
                    }
                    _ => Rgba(round(c)),
                };
                match contours {
                    None => px,
                    Some(c) => {
                        let (col, row) = (gx as f64 * per_texel[0], gy as f64 * per_texel[1]);
                        let cover = c.coverage(grid, col, row, per_texel);
                        Rgba(crate::relief::Contours::blend(px.0, cover))
                    }
                }
            });
            if let Some(o) = overlay {
                o.draw(x, y, &mut map);
            }
            write(
                MapKey {
                    level: finest,
                    x,
                    y,
                },
                &map,
            )
        })?;
    }
    progress(finest);
    for level in (0..finest).rev() {
        let m = 1u32 << level;
        (0..m * m).into_par_iter().try_for_each(|i| {
            let (x, y) = (i % m, i / m);
            let child = |dx: u32, dy: u32| {
                read(MapKey {
                    level: level + 1,
                    x: 2 * x + dx,
                    y: 2 * y + dy,
                })
            };
            let children = [child(0, 0)?, child(1, 0)?, child(0, 1)?, child(1, 1)?];
            write(MapKey { level, x, y }, &parent_map(&children, t))
        })?;
        progress(level);
    }
    Ok(())
}

/// An orthophoto read by rows: its size, georeference and any band of full-width rows. The
/// pyramid writer ([`write_pyramid`]) asks for the rows one row of maps needs, top to bottom, so
/// a source may read them on demand ([`crate::photo::TiffPhoto`]) instead of holding the image.
pub trait PhotoSource: Sync {
    /// Width and height in pixels.
    fn size(&self) -> (u32, u32);
    fn georef(&self) -> Option<Georef>;
    /// The file or name, for errors.
    fn source(&self) -> &str;
    /// Rows `y0..y1` (`y0 < y1 ≤ height`) at full width, 8-bit RGBA.
    fn rows(&self, y0: u32, y1: u32) -> Result<RgbaImage, TerrainError>;
    /// The stretch its colours were made with, when they were mapped from other samples
    /// (wider than 8 bits, or by a `--stretch`).
    fn stretch(&self) -> Option<crate::photo::Applied> {
        None
    }
}

impl PhotoSource for Orthophoto {
    fn size(&self) -> (u32, u32) {
        self.image.dimensions()
    }
    fn georef(&self) -> Option<Georef> {
        self.georef
    }
    fn source(&self) -> &str {
        &self.source
    }
    fn stretch(&self) -> Option<crate::photo::Applied> {
        self.stretch.clone()
    }
    fn rows(&self, y0: u32, y1: u32) -> Result<RgbaImage, TerrainError> {
        Ok(image::imageops::crop_imm(&self.image, 0, y0, self.image.width(), y1 - y0).to_image())
    }
}

/// Build the pyramid from the finest level's texture (`T·2^L` a side) by 2x2 box averages.
pub fn pyramid(finest: RgbaImage, map_texels: u32) -> Pyramid {
    let mut levels = vec![finest];
    while levels.last().is_some_and(|l| l.width() > map_texels) {
        let src = levels.last().expect("non-empty");
        let n = src.width() / 2;
        let down = RgbaImage::from_fn(n, n, |x, y| {
            let mut s = [0u32; 4];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let p = src.get_pixel(2 * x + dx, 2 * y + dy).0;
                for k in 0..4 {
                    s[k] += p[k] as u32;
                }
            }
            Rgba(s.map(|v| ((v + 2) / 4) as u8))
        });
        levels.push(down);
    }
    levels.reverse();
    Pyramid { map_texels, levels }
}

/// The level count for a grid: the finest level has at least one texel per grid sample, capped
/// at `max_levels`.
pub fn level_count(grid: &Grid, map_texels: u32, max_levels: u32) -> u32 {
    texture_levels(grid.width().max(grid.height()), map_texels, max_levels)
}

/// The level count for a photo over a grid: the finest level has at least one texel per grid
/// sample and per photo pixel over the grid's extent, capped at `max_levels`.
pub fn photo_level_count(
    photo: &dyn PhotoSource,
    grid: &Grid,
    map_texels: u32,
    max_levels: u32,
) -> Result<u32, TerrainError> {
    let p = Placement::new(lattice(grid), photo.size(), photo.georef(), photo.source())?;
    let (a, b) = (p.to_photo(0.0, 0.0), p.to_photo(1.0, 1.0));
    let across = (b.0 - a.0).abs().max((b.1 - a.1).abs()).min(1e9) as u32;
    let side = grid.width().max(grid.height()).max(across);
    Ok(texture_levels(side, map_texels, max_levels))
}

fn texture_levels(side: u32, map_texels: u32, max_levels: u32) -> u32 {
    let need = side as f64 / map_texels as f64;
    let l = need.log2().ceil().max(0.0) as u32;
    (l + 1).min(max_levels.max(1))
}

impl Pyramid {
    /// The map `key` (a `T x T` crop), if it exists.
    pub fn map(&self, key: MapKey) -> Option<RgbaImage> {
        let img = self.levels.get(key.level as usize)?;
        let t = self.map_texels;
        let n = 1u32 << key.level;
        (key.x < n && key.y < n)
            .then(|| image::imageops::crop_imm(img, key.x * t, key.y * t, t, t).to_image())
    }
}

/// Per-level map counts of Seed 000's active area (Eq. 5–7) for levels `0..levels`.
pub fn map_budget(
    hfov_deg: f64,
    pixels: u32,
    map_texels: u32,
    levels: u32,
) -> Result<Vec<(u32, u64)>, TerrainError> {
    let area =
        ActiveArea::new(hfov_deg, pixels, map_texels).map_err(|e| TerrainError::BadParameter {
            name: "active area",
            value: e.to_string(),
            expected: "0° < fov < 180°, pixels > 0, map texels > 0",
        })?;
    Ok((0..levels).map(|l| (l, area.maps_per_level())).collect())
}

/// The maps Seed 000's active area needs around the eye at texture position `(eye_u, eye_v)`
/// (level-0 map widths, i.e. `[0, 1]²` over the DEM) for levels `0..levels`: per level the
/// `2⌈r⌉ x 2⌈r⌉` block of maps centred on the map corner nearest the eye, clipped to the pyramid.
pub fn needed_maps(area: &ActiveArea, eye_u: f64, eye_v: f64, levels: u32) -> Vec<MapKey> {
    let r = area.radius_in_own_maps().ceil() as i64;
    let mut out = Vec::new();
    for level in 0..levels {
        let n = 1i64 << level;
        let (cx, cy) = (
            (eye_u * n as f64).round() as i64,
            (eye_v * n as f64).round() as i64,
        );
        for y in (cy - r).max(0)..(cy + r).min(n) {
            for x in (cx - r).max(0)..(cx + r).min(n) {
                out.push(MapKey {
                    level,
                    x: x as u32,
                    y: y as u32,
                });
            }
        }
    }
    out
}

/// Counters of a [`GstCache`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct CacheStats {
    pub hits: u64,
    pub loads: u64,
    pub evictions: u64,
    pub resident: u64,
    pub resident_bytes: u64,
}

/// A residency cache of GST maps under a byte budget, least-recently-used eviction.
pub struct GstCache {
    budget: u64,
    tick: u64,
    maps: HashMap<MapKey, (RgbaImage, u64)>,
    stats: CacheStats,
}

impl GstCache {
    /// A cache holding at most `budget_bytes` of map texels (4 bytes per texel).
    pub fn new(budget_bytes: u64) -> GstCache {
        GstCache {
            budget: budget_bytes,
            tick: 0,
            maps: HashMap::new(),
            stats: CacheStats::default(),
        }
    }

    pub fn stats(&self) -> CacheStats {
        self.stats
    }

    pub fn contains(&self, key: MapKey) -> bool {
        self.maps.contains_key(&key)
    }

    /// The map `key`, loading it with `load` on a miss and evicting least-recently-used maps to
    /// stay within the budget. A map larger than the whole budget is returned but not kept.
    pub fn get(
        &mut self,
        key: MapKey,
        load: impl FnOnce(MapKey) -> Result<RgbaImage, TerrainError>,
    ) -> Result<&RgbaImage, TerrainError> {
        self.tick += 1;
        let tick = self.tick;
        if self.maps.contains_key(&key) {
            self.stats.hits += 1;
            let e = self.maps.get_mut(&key).expect("checked");
            e.1 = tick;
            return Ok(&e.0);
        }
        let img = load(key)?;
        self.stats.loads += 1;
        let bytes = img.as_raw().len() as u64;
        while self.stats.resident_bytes + bytes > self.budget && !self.maps.is_empty() {
            // Least recently used; ties broken by key so the order is deterministic.
            let victim = *self
                .maps
                .iter()
                .min_by_key(|(k, v)| (v.1, **k))
                .expect("non-empty")
                .0;
            let (old, _) = self.maps.remove(&victim).expect("present");
            self.stats.resident_bytes -= old.as_raw().len() as u64;
            self.stats.evictions += 1;
        }
        self.stats.resident_bytes += bytes;
        self.maps.insert(key, (img, tick));
        self.stats.resident = self.maps.len() as u64;
        Ok(&self.maps[&key].0)
    }

    /// Make every map of `keys` resident (in order), returning how many had to be loaded.
    pub fn make_resident(
        &mut self,
        keys: &[MapKey],
        mut load: impl FnMut(MapKey) -> Result<RgbaImage, TerrainError>,
    ) -> Result<u64, TerrainError> {
        let before = self.stats.loads;
        for &k in keys {
            self.get(k, &mut load)?;
        }
        self.stats.resident = self.maps.len() as u64;
        Ok(self.stats.loads - before)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reprojection_lattice_holds_its_tolerance_over_large_grids() {
        use crate::dem::CrsKind;
        // A 6° x 6° geographic grid under a UTM photo of 100 m pixels, and a 300 km UTM grid under a Web Mercator photo of 10 m pixels: between the nodes the interpolated position stays
        // within the tolerance of the exact one (checked off the cell centres too).
        let geo = Georef {
            crs: CrsKind::Geographic,
            epsg: Some(4326),
            origin_x: -75.0,
            origin_y: 48.0,
            dx: 6.0 / 600.0,
            dy: -6.0 / 600.0,
        };
        let utm = Georef {
            crs: CrsKind::Projected,
            epsg: Some(32618),
            origin_x: 200_000.0,
            origin_y: 5_400_000.0,
            dx: 100.0,
            dy: -100.0,
        };
        let merc = Georef {
            crs: CrsKind::Projected,
            epsg: Some(3857),
            origin_x: -8_230_000.0,
            origin_y: 5_660_000.0,
            dx: 10.0,
            dy: -10.0,
        };
        let utm_grid = Georef {
            origin_x: 600_000.0,
            origin_y: 5_000_000.0,
            dx: 300.0,
            dy: -300.0,
            ..utm
        };
        for (g, photo, size) in [(geo, utm, (6000, 8000)), (utm_grid, merc, (40_000, 40_000))] {
            let grid = Grid::new("g", 1001, 1001, vec![0.0; 1001 * 1001], g).unwrap();
            let p = Placement::new(lattice(&grid), size, Some(photo), "photo").unwrap();
            let (k, _) = p.lattice.as_ref().expect("reprojected");
            let from = crate::geodesy::Placement::of(&g).unwrap();
            let to = crate::geodesy::Placement::of(&photo).unwrap();
            let mut worst = 0.0f64;
            for i in 0..=97 {
                for j in 0..=89 {
                    let (u, v) = (i as f64 / 97.0, j as f64 / 89.0);
                    let a = p.to_photo(u, v);
                    let b = p.reprojected(from, to, &photo, u, v);
                    worst = worst.max((a.0 - b.0).hypot(a.1 - b.1));
                }
            }
            assert!(worst <= 1.5 * LATTICE_TOLERANCE_PX, "{k} cells: {worst} px");
            assert!(*k > 64, "the lattice refined ({k} cells)");
        }
    }

    #[test]
    fn seed000_worked_example_324_maps() {
        let b = map_budget(45.0, 1024, 256, 9).unwrap();
        assert!(b.iter().all(|&(_, n)| n == 36));
        assert_eq!(b.iter().map(|x| x.1).sum::<u64>(), 324);
        // Away from the pyramid's edges the active area is the full 6x6 block per level.
        let area = ActiveArea::new(45.0, 1024, 256).unwrap();
        let keys = needed_maps(&area, 0.5, 0.5, 9);
        let per: Vec<usize> = (0..9)
            .map(|l| keys.iter().filter(|k| k.level == l).count())
            .collect();
        assert_eq!(per[3..], [36; 6]);
        assert_eq!(per[0], 1); // level 0 has one map
    }

    #[test]
    fn cache_budget_and_counters() {
        let mut c = GstCache::new(3 * 4 * 16); // three 4x4 maps
        let load = |_k: MapKey| Ok(RgbaImage::new(4, 4));
        let k = |x| MapKey { level: 2, x, y: 0 };
        for x in [0, 1, 2, 0, 3, 1] {
            c.get(k(x), load).unwrap();
        }
        // loads 0,1,2 ; hit 0 ; load 3 evicts 1 (LRU) ; load 1 evicts 2.
        let s = c.stats();
        assert_eq!((s.hits, s.loads, s.evictions, s.resident), (1, 5, 2, 3));
        assert!(c.contains(k(0)) && c.contains(k(3)) && c.contains(k(1)) && !c.contains(k(2)));
    }

    #[test]
    fn pyramid_levels_are_box_averages() {
        let fine = RgbaImage::from_fn(8, 8, |x, _| {
            Rgba([if x % 2 == 0 { 100 } else { 200 }, 0, 0, 255])
        });
        let p = pyramid(fine, 2);
        assert_eq!(
            p.levels.iter().map(|l| l.width()).collect::<Vec<_>>(),
            vec![2, 4, 8]
        );
        assert_eq!(p.levels[1].get_pixel(0, 0).0, [150, 0, 0, 255]);
        assert_eq!(
            p.map(MapKey {
                level: 2,
                x: 3,
                y: 3
            })
            .unwrap()
            .dimensions(),
            (2, 2)
        );
        assert!(
            p.map(MapKey {
                level: 1,
                x: 2,
                y: 0
            })
            .is_none()
        );
    }
}
