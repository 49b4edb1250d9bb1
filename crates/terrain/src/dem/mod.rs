//! Elevation grids: samples, georeference and no-data, and the readers that make them.
//!
//! A [`Grid`] is a row-major array of `f32` heights in metres, row 0 at the north (top) edge, with
//! no-data as `NaN` (never as −32768 or −9999: a reader turns its format's marker into `NaN`, so
//! no marker can reach a mesh as a spike). Its [`Georef`] places the *centre* of sample
//! `(col, row)` at `origin + (col·dx, row·dy)` in the grid's coordinate system, whose kind
//! ([`CrsKind`]) says whether the units are metres (projected) or degrees (geographic). Centres,
//! not corners, because every mesh vertex is a sample: the GeoTIFF reader resolves
//! `PixelIsArea` vs `PixelIsPoint` (the half-pixel shift) once, here, and nothing downstream
//! needs to know which one the file used.
//!
//! Geographic grids are turned into local metres with the latitude-dependent spacing
//! ([`Georef::local_metres`]): east-west metres per degree shrink with `cos φ` row by row, so a
//! 1° tile at 60° N is half as wide as at the equator. Web Mercator grids (EPSG:3857) too: their
//! metres are ground metres only at the equator. The grid itself keeps its own coordinates; the
//! conversion happens when vertices are made, so the georeference survives to the export.
//!
//! Readers ([`DemFormat`], [`read_dem`]): GeoTIFF ([`geotiff`]), ESRI ASCII grid ([`asc`]),
//! SRTM `.hgt` ([`hgt`]), DTED levels 0–2 ([`dted`]), ESRI GridFloat `.flt` and BIL `.bil` with
//! their `.hdr` and `.prj` ([`ehdr`]), 16-bit PNG with a scale and offset, and Mapbox Terrain-RGB
//! and Terrarium PNG ([`png`]), the last two placed in Web Mercator when they are web-map tiles
//! addressed `Z/X/Y.png` ([`png::TileAddress`]), gridded XYZ text ([`xyz`]), and GDAL VRTs as
//! `gdalbuildvrt` and `gdal_translate -of VRT` write them ([`vrt`], which also reads photo VRTs
//! and lays out photo mosaics for [`crate::photo`]); grids that tile an area join into one
//! ([`mosaic`], [`read_dems`]: web-map tiles of one zoom only). Airborne lidar point clouds, LAS
//! 1.0–1.4 and LAZ ([`las`]), are gridded into a grid as PDAL's `writers.gdal` grids them
//! ([`lidar`]; several files are one cloud). Each validates at the file
//! boundary ([`Grid::new`]): at least 2 x 2 samples, at most [`MAX_SAMPLES`], every value finite
//! or no-data, not all no-data. [`geotiff_writer`] writes a grid (or a mask computed from one, such
//! as a [`crate::viewshed`]) back as a GeoTIFF that GDAL and [`geotiff`] read with the same
//! georeference.

pub mod asc;
pub mod dted;
pub mod ehdr;
pub mod geotiff;
pub mod geotiff_writer;
pub mod hgt;
pub mod las;
pub mod lidar;
pub mod mosaic;
pub mod png;
pub mod vrt;
pub mod xyz;

use crate::error::TerrainError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The largest grid accepted: 2^30 samples (4 GiB of `f32`), far above any DEM tile a terrain
/// database is built from in one piece, and low enough that a header claiming more is refused
/// before anything is allocated.
pub const MAX_SAMPLES: u64 = 1 << 30;

/// The longest side accepted, 2^15 samples: the mesher pads a grid to the smallest
/// `(2^k + 1)²` square holding it, and walks squares of at most `(2^15 + 1)²` (a longer strip would
/// also pad to a square far beyond [`MAX_SAMPLES`]).
pub const MAX_SIDE: u32 = 1 << 15;

/// What the grid's coordinates measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CrsKind {
    /// A projected system: coordinates in metres (e.g. UTM).
    Projected,
    /// Longitude and latitude in degrees.
    Geographic,
    /// No georeference: coordinates are in the units the caller gave (metres are assumed).
    Local,
}

/// Where the samples are: the centre of sample `(col, row)` is `origin + (col·dx, row·dy)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Georef {
    pub crs: CrsKind,
    /// EPSG code, when the file names one.
    pub epsg: Option<u16>,
    /// Centre of sample (0, 0): easting or longitude.
    pub origin_x: f64,
    /// Centre of sample (0, 0): northing or latitude.
    pub origin_y: f64,
    /// Step between columns (positive: east).
    pub dx: f64,
    /// Step between rows (negative for the usual north-up grid).
    pub dy: f64,
}

impl Georef {
    /// A local frame with `cell` metres between samples, north up.
    pub fn local(cell: f64) -> Georef {
        Georef {
            crs: CrsKind::Local,
            epsg: None,
            origin_x: 0.0,
            origin_y: 0.0,
            dx: cell,
            dy: -cell,
        }
    }

    /// The grid coordinates of the centre of sample `(col, row)`.
    pub fn sample_xy(&self, col: f64, row: f64) -> (f64, f64) {
        (self.origin_x + col * self.dx, self.origin_y + row * self.dy)
    }

    /// The fractional sample position of grid coordinates `(x, y)` (inverse of [`Self::sample_xy`]).
    pub fn xy_to_sample(&self, x: f64, y: f64) -> (f64, f64) {
        ((x - self.origin_x) / self.dx, (y - self.origin_y) / self.dy)
    }

    /// Local metres `(east, south)` of sample `(col, row)` from sample (0, 0).
    ///
    /// Projected and local grids: `(col·dx, −row·dy)`. Geographic grids: the WGS 84 meridian arc
    /// `M(φ) ≈ 111 132.92 − 559.82 cos 2φ + 1.175 cos 4φ` metres per degree of latitude (taken at
    /// the mean latitude of the two rows) and the parallel `P(φ) ≈ 111 412.84 cos φ − 93.5 cos 3φ`
    /// metres per degree of longitude at the sample's own latitude (the standard series, good to
    /// about a centimetre per degree). Web Mercator grids (EPSG:3857), whose metres are ground
    /// metres only at the equator (√2 of them at 45°), the same way after turning rows into
    /// latitudes and columns into degrees of longitude.
    pub fn local_metres(&self, col: f64, row: f64) -> (f64, f64) {
        let arcs = |lat0: f64, lat: f64, dlon: f64| {
            let mid = (0.5 * (lat0 + lat)).to_radians();
            let m_lat = 111_132.92 - 559.82 * (2.0 * mid).cos() + 1.175 * (4.0 * mid).cos();
            let phi = lat.to_radians();
            let m_lon = 111_412.84 * phi.cos() - 93.5 * (3.0 * phi).cos();
            (dlon * m_lon, -(lat - lat0) * m_lat)
        };
        match self.crs {
            CrsKind::Projected if self.is_web_mercator() => {
                let (_, lat0) = crate::geodesy::web_mercator_to_lonlat(0.0, self.origin_y);
                let (dlon, lat) = crate::geodesy::web_mercator_to_lonlat(
                    col * self.dx,
                    self.origin_y + row * self.dy,
                );
                arcs(lat0, lat, dlon)
            }
            CrsKind::Projected | CrsKind::Local => (col * self.dx, -row * self.dy),
            CrsKind::Geographic => {
                arcs(self.origin_y, self.origin_y + row * self.dy, col * self.dx)
            }
        }
    }

    /// Whether the grid coordinates are Web Mercator metres (EPSG:3857, or its old code 3785).
    pub fn is_web_mercator(&self) -> bool {
        self.crs == CrsKind::Projected && matches!(self.epsg, Some(3857 | 3785))
    }

    /// Approximate sample spacing in metres `(east, north)` at the grid's centre row.
    pub fn spacing_metres(&self, rows: u32) -> (f64, f64) {
        let r = 0.5 * rows.saturating_sub(1) as f64;
        let (e0, s0) = self.local_metres(0.0, r);
        let (e1, s1) = self.local_metres(1.0, r + 1.0);
        ((e1 - e0).abs(), (s1 - s0).abs())
    }
}

/// A validated elevation grid.
///
/// # Guarantees
/// `2 ≤ width, height ≤ MAX_SIDE`, `width·height ≤ MAX_SAMPLES`, every sample finite or `NaN`
/// (no-data), at least one finite sample.
#[derive(Clone, Debug)]
pub struct Grid {
    width: u32,
    height: u32,
    heights: Heights,
    georef: Georef,
    /// Lowest and highest valid height (`height_range`), found once.
    range: (f32, f32),
}

impl PartialEq for Grid {
    fn eq(&self, o: &Grid) -> bool {
        self.width == o.width
            && self.height == o.height
            && self.georef == o.georef
            && self.heights() == o.heights()
    }
}

/// Where a grid's samples live: in memory, or in a database's `grid.f32` mapped into the address
/// space ([`Grid::map_file`]), so that a flight over a grid larger than memory touches only the
/// pages under the eye, the models and the path.
#[derive(Clone, Debug)]
enum Heights {
    Owned(Vec<f32>),
    Mapped(std::sync::Arc<memmap2::Mmap>),
}

impl Heights {
    fn as_slice(&self) -> &[f32] {
        match self {
            Heights::Owned(v) => v,
            Heights::Mapped(m) => {
                let bytes: &[u8] = m;
                // SAFETY: `map_file` maps only on little-endian targets, checked the length is a
                // multiple of 4 and the start 4-aligned (a mapping starts on a page), and every
                // bit pattern is a valid f32.
                unsafe { std::slice::from_raw_parts(bytes.as_ptr().cast::<f32>(), bytes.len() / 4) }
            }
        }
    }

    fn to_mut(&mut self) -> &mut Vec<f32> {
        if let Heights::Mapped(m) = self {
            let owned = Heights::Mapped(m.clone()).as_slice().to_vec();
            *self = Heights::Owned(owned);
        }
        match self {
            Heights::Owned(v) => v,
            Heights::Mapped(_) => unreachable!("converted to owned above"),
        }
    }
}

/// Lowest and highest non-NaN value (`(inf, -inf)` when there is none).
fn range_of(heights: &[f32]) -> (f32, f32) {
    let mut lo = f32::INFINITY;
    let mut hi = f32::NEG_INFINITY;
    for &h in heights {
        if !h.is_nan() {
            lo = lo.min(h);
            hi = hi.max(h);
        }
    }
    (lo, hi)
}

/// Check a size claimed by a header before allocating for it.
pub(crate) fn check_size(source: &str, width: u64, height: u64) -> Result<(), TerrainError> {
    let bad = |reason| {
        Err(TerrainError::BadSize {
            source: source.to_string(),
            width,
            height,
            reason,
        })
    };
    if width < 2 || height < 2 {
        return bad("need at least 2 x 2 samples to make a triangle");
    }
    if width > u32::MAX as u64 / 2
        || height > u32::MAX as u64 / 2
        || width.saturating_mul(height) > MAX_SAMPLES
    {
        return bad("more than 2^30 samples: split the grid into tiles first");
    }
    if width.max(height) > MAX_SIDE as u64 {
        return bad(
            "a side longer than 32768 samples (meshes are cut from the grid padded to a \
             (2^k + 1)² square): split the grid into tiles first",
        );
    }
    Ok(())
}

impl Grid {
    /// Validate `heights` (row-major, `NaN` = no-data). `source` names the data in errors.
    ///
    /// Infinite values are refused (a reader maps its no-data marker to `NaN` before this).
    pub fn new(
        source: &str,
        width: u32,
        height: u32,
        heights: Vec<f32>,
        georef: Georef,
    ) -> Result<Grid, TerrainError> {
        check_size(source, width as u64, height as u64)?;
        if heights.len() as u64 != width as u64 * height as u64 {
            return Err(crate::error::format_err(
                source,
                "sample count",
                format!(
                    "{} samples for {width} x {height}, got {}",
                    width as u64 * height as u64,
                    heights.len()
                ),
            ));
        }
        if let Some(i) = heights.iter().position(|h| h.is_infinite()) {
            return Err(TerrainError::NonFinite {
                source: source.to_string(),
                col: (i % width as usize) as u32,
                row: (i / width as usize) as u32,
            });
        }
        if heights.iter().all(|h| h.is_nan()) {
            return Err(TerrainError::AllNoData {
                source: source.to_string(),
            });
        }
        let ok = |v: f64| v.is_finite();
        if !(ok(georef.origin_x) && ok(georef.origin_y) && ok(georef.dx) && ok(georef.dy))
            || georef.dx == 0.0
            || georef.dy == 0.0
        {
            return Err(crate::error::format_err(
                source,
                "georeference",
                format!("finite origin and non-zero finite spacing, got {georef:?}"),
            ));
        }
        let range = range_of(&heights);
        Ok(Grid {
            width,
            height,
            heights: Heights::Owned(heights),
            georef,
            range,
        })
    }

    /// A grid over the little-endian `f32` samples of `path` (a database's `grid.f32`), mapped
    /// rather than read: only the pages a caller touches are loaded, so opening a 16k² grid costs
    /// no memory until heights are asked for. `range` is the file's lowest and highest valid
    /// height, as recorded when it was written; the samples are not scanned again (a database
    /// build validated them). On big-endian targets the file is read into memory instead.
    ///
    /// The file must not be changed while the grid is alive (a truncated mapping faults).
    pub fn map_file(
        path: &Path,
        width: u32,
        height: u32,
        georef: Georef,
        range: (f32, f32),
    ) -> Result<Grid, TerrainError> {
        let source = path.display().to_string();
        check_size(&source, width as u64, height as u64)?;
        if !(range.0.is_finite() && range.1.is_finite() && range.0 <= range.1) {
            return Err(crate::error::format_err(
                &source,
                "height range",
                format!("finite lowest ≤ highest height, got {range:?}"),
            ));
        }
        let want = width as u64 * height as u64 * 4;
        let file = std::fs::File::open(path).map_err(crate::error::io(path))?;
        let len = file.metadata().map_err(crate::error::io(path))?.len();
        if len != want {
            return Err(crate::error::format_err(
                &source,
                "file size",
                format!("{want} bytes for {width} x {height} f32, got {len}"),
            ));
        }
        let heights = if cfg!(target_endian = "little") {
            // SAFETY: the mapping is read-only and the database directory is not written while a
            // terrain is open (documented above).
            let map = unsafe { memmap2::Mmap::map(&file) }.map_err(crate::error::io(path))?;
            if map.as_ptr().align_offset(4) != 0 {
                return Err(crate::error::format_err(
                    &source,
                    "mapping",
                    "a 4-byte aligned mapping",
                ));
            }
            Heights::Mapped(std::sync::Arc::new(map))
        } else {
            let bytes = std::fs::read(path).map_err(crate::error::io(path))?;
            Heights::Owned(
                bytes
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect(),
            )
        };
        Ok(Grid {
            width,
            height,
            heights,
            georef,
            range,
        })
    }

    /// Like [`Grid::new`], but samples equal to `nodata` (when given) become `NaN` first, and a
    /// NaN is an error (`NonFinite`) rather than no-data unless the format itself uses NaN for it.
    pub fn from_samples(
        source: &str,
        width: u32,
        height: u32,
        mut heights: Vec<f32>,
        nodata: Option<f64>,
        nan_is_nodata: bool,
        georef: Georef,
    ) -> Result<Grid, TerrainError> {
        if !nan_is_nodata && let Some(i) = heights.iter().position(|h| h.is_nan()) {
            return Err(TerrainError::NonFinite {
                source: source.to_string(),
                col: (i % width.max(1) as usize) as u32,
                row: (i / width.max(1) as usize) as u32,
            });
        }
        if let Some(nd) = nodata {
            let nd32 = nd as f32;
            for h in &mut heights {
                if *h == nd32 {
                    *h = f32::NAN;
                }
            }
        }
        Grid::new(source, width, height, heights, georef)
    }

    pub fn width(&self) -> u32 {
        self.width
    }
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Row-major heights, `NaN` = no-data.
    pub fn heights(&self) -> &[f32] {
        self.heights.as_slice()
    }
    pub fn georef(&self) -> &Georef {
        &self.georef
    }
    /// Height of sample `(col, row)` (`NaN` = no-data). Panics if out of range.
    pub fn at(&self, col: u32, row: u32) -> f32 {
        self.heights()[row as usize * self.width as usize + col as usize]
    }
    /// Number of no-data samples.
    pub fn nodata_count(&self) -> u64 {
        self.heights().iter().filter(|h| h.is_nan()).count() as u64
    }
    /// Lowest and highest valid height.
    pub fn height_range(&self) -> (f32, f32) {
        self.range
    }

    /// Fill no-data samples from their neighbours: repeated passes in which every no-data sample
    /// with at least one valid 8-neighbour takes their mean, until none is left (a flood from the
    /// hole's rim inwards; deterministic, since each pass reads only the previous pass's values).
    pub fn fill_nodata(&mut self) {
        let (w, h) = (self.width as usize, self.height as usize);
        let heights = self.heights.to_mut();
        let mut todo: Vec<usize> = (0..w * h).filter(|&i| heights[i].is_nan()).collect();
        while !todo.is_empty() {
            let mut updates = Vec::with_capacity(todo.len());
            for &i in &todo {
                let (x, y) = ((i % w) as isize, (i / w) as isize);
                let (mut sum, mut n) = (0.0f64, 0u32);
                for dy in -1..=1isize {
                    for dx in -1..=1isize {
                        let (nx, ny) = (x + dx, y + dy);
                        if (dx, dy) != (0, 0)
                            && nx >= 0
                            && ny >= 0
                            && (nx as usize) < w
                            && (ny as usize) < h
                        {
                            let v = heights[ny as usize * w + nx as usize];
                            if !v.is_nan() {
                                sum += v as f64;
                                n += 1;
                            }
                        }
                    }
                }
                if n > 0 {
                    updates.push((i, (sum / n as f64) as f32));
                }
            }
            // The grid has a valid sample (guaranteed), so every pass fills at least one.
            for &(i, v) in &updates {
                heights[i] = v;
            }
            todo.retain(|&i| heights[i].is_nan());
        }
    }
}

/// The elevation file formats read by [`read_dem`] (chosen by extension, or by content when the
/// extension is not one of theirs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DemFormat {
    GeoTiff,
    EsriAscii,
    Hgt,
    /// DTED levels 0, 1, 2 (`.dt0`, `.dt1`, `.dt2`).
    Dted,
    /// ESRI `.hdr` labelled rasters: GridFloat `.flt` and BIL `.bil` (or their `.hdr`).
    EsriHdr,
    /// 16-bit greyscale PNG: `height = scale · value + offset`.
    Png16,
    /// Mapbox Terrain-RGB: `height = −10000 + 0.1 · (R·65536 + G·256 + B)`.
    TerrainRgb,
    /// Terrarium (AWS Terrain Tiles, Mapzen): `height = R·256 + G + B/256 − 32768`.
    Terrarium,
    /// A lidar point cloud, LAS or LAZ (`.las`, `.laz`), gridded by [`lidar`].
    Las,
    /// Gridded XYZ text (`.xyz`): an `x y z` line per sample ([`xyz`]).
    Xyz,
    /// A GDAL virtual raster (`.vrt`): band 1 composited from its sources ([`vrt`]).
    Vrt,
}

/// Options for the readers that need outside information.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadOptions {
    /// Force a format instead of the extension's.
    pub format: Option<DemFormat>,
    /// PNG heightmaps: metres per PNG unit (16-bit PNG), default 1.
    pub scale: f64,
    /// PNG heightmaps: height of PNG value 0, default 0.
    pub offset: f64,
    /// PNG heightmaps (no georeference): metres between samples, default 1. Not used for a
    /// Terrain-RGB or Terrarium tile with an address.
    pub cell: f64,
    /// Terrain-RGB and Terrarium: the file's tile address, instead of the one its path spells
    /// (`.../Z/X/Y.png`).
    pub tile: Option<png::TileAddress>,
    /// Terrain-RGB and Terrarium: tile addresses count rows from the south (TMS), not the north.
    pub tms: bool,
    /// DTED: a record whose checksum does not match its bytes is an error (default `true`);
    /// `false` reads a file whose producer wrote wrong checksums.
    pub verify_checksums: bool,
    /// LAS and LAZ point clouds: how they are gridded.
    pub lidar: lidar::LidarOptions,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            format: None,
            scale: 1.0,
            offset: 0.0,
            cell: 1.0,
            tile: None,
            tms: false,
            verify_checksums: true,
            lidar: lidar::LidarOptions::default(),
        }
    }
}

impl DemFormat {
    /// The format a file name's extension says, if known.
    pub fn from_path(path: &Path) -> Option<DemFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "tif" | "tiff" => Some(DemFormat::GeoTiff),
            "asc" => Some(DemFormat::EsriAscii),
            "hgt" => Some(DemFormat::Hgt),
            "dt0" | "dt1" | "dt2" => Some(DemFormat::Dted),
            "flt" | "bil" | "hdr" => Some(DemFormat::EsriHdr),
            "png" => Some(DemFormat::Png16),
            "las" | "laz" => Some(DemFormat::Las),
            "xyz" => Some(DemFormat::Xyz),
            "vrt" => Some(DemFormat::Vrt),
            _ => None,
        }
    }

    /// The format a file's content says, for a name whose extension is none of the above: a
    /// DTED cell begins with its user header label `UHL1`, a LAS or LAZ file with `LASF`; an
    /// ESRI `.hdr` raster has its `.hdr` beside it.
    pub fn sniff(path: &Path) -> Option<DemFormat> {
        use std::io::Read;
        let mut head = [0u8; 4];
        let read = std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut head))
            .is_ok();
        match &head {
            b"UHL1" if read => return Some(DemFormat::Dted),
            b"LASF" if read => return Some(DemFormat::Las),
            b"<VRT" if read => return Some(DemFormat::Vrt),
            _ => {}
        }
        ["hdr", "HDR"]
            .iter()
            .any(|e| path.with_extension(e).is_file())
            .then_some(DemFormat::EsriHdr)
    }
}

/// Read an elevation grid, choosing the reader by `opts.format`, the extension or the content.
pub fn read_dem(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<Grid, TerrainError> {
    let path = path.as_ref();
    let format = opts
        .format
        .or_else(|| DemFormat::from_path(path))
        .or_else(|| DemFormat::sniff(path))
        .ok_or_else(|| TerrainError::Unsupported {
            source: path.display().to_string(),
            what: "unknown extension (expected .tif, .tiff, .asc, .hgt, .dt0, .dt1, .dt2, .flt, \
                   .bil, .png, .las, .laz, .xyz or .vrt)"
                .into(),
        })?;
    match format {
        DemFormat::GeoTiff => geotiff::read_geotiff(path),
        DemFormat::EsriAscii => asc::read_asc(path),
        DemFormat::Hgt => hgt::read_hgt(path),
        DemFormat::Dted => dted::read_dted_with(
            path,
            if opts.verify_checksums {
                dted::Checksums::Verify
            } else {
                dted::Checksums::Ignore
            },
        ),
        DemFormat::EsriHdr => ehdr::read_ehdr(path),
        DemFormat::Png16 => png::read_png16(path, opts.scale, opts.offset, opts.cell),
        DemFormat::TerrainRgb => read_rgb(path, png::RgbEncoding::TerrainRgb, opts),
        DemFormat::Terrarium => read_rgb(path, png::RgbEncoding::Terrarium, opts),
        DemFormat::Las => lidar::read_lidar(&[path.to_path_buf()], &opts.lidar).map(|r| r.0),
        DemFormat::Xyz => xyz::read_xyz(path),
        DemFormat::Vrt => vrt::read_vrt(path),
    }
}

/// Whether `path` is a lidar point cloud under `opts` (by the forced format, the extension or
/// the content).
fn is_lidar(path: &Path, opts: &ReadOptions) -> bool {
    opts.format
        .or_else(|| DemFormat::from_path(path))
        .or_else(|| DemFormat::sniff(path))
        == Some(DemFormat::Las)
}

/// The tile address of `path` under `opts` (given, or spelled by the path; TMS rows flipped), for
/// the RGB-encoded formats.
fn tile_address(path: &Path, opts: &ReadOptions) -> Result<Option<png::TileAddress>, TerrainError> {
    let t = match opts.tile {
        Some(t) => Some(t),
        None => png::TileAddress::from_path(path).transpose()?,
    };
    Ok(t.map(|t| if opts.tms { t.flip_y() } else { t }))
}

fn read_rgb(
    path: &Path,
    encoding: png::RgbEncoding,
    opts: &ReadOptions,
) -> Result<Grid, TerrainError> {
    png::read_rgb_tile(path, encoding, tile_address(path, opts)?, opts.cell)
}

/// Read several elevation files for [`mosaic::mosaic`], each named by its path. A directory
/// stands for the web-map tiles under it ([`png::tiles_in_dir`]). Terrain-RGB and Terrarium
/// tiles must all be of one zoom: a tile of another zoom than the first is an error naming both
/// files, before any is read (a mosaic never resamples). Lidar point clouds are one cloud,
/// gridded together ([`lidar::read_lidar`]) in the place of the first of them, named
/// `a.laz + b.laz`.
pub fn read_dems(
    paths: &[std::path::PathBuf],
    opts: &ReadOptions,
) -> Result<Vec<(String, Grid)>, TerrainError> {
    let mut files = Vec::with_capacity(paths.len());
    for p in paths {
        if p.is_dir() {
            files.extend(png::tiles_in_dir(p)?);
        } else {
            files.push(p.clone());
        }
    }
    if opts.tile.is_some() && files.len() > 1 {
        return Err(TerrainError::BadParameter {
            name: "tile",
            value: format!("{} files", files.len()),
            expected: "one file: several tiles are placed by their Z/X/Y paths",
        });
    }
    if matches!(
        opts.format,
        Some(DemFormat::TerrainRgb | DemFormat::Terrarium)
    ) {
        let mut first: Option<(&Path, u8)> = None;
        for f in &files {
            let Some(t) = tile_address(f, opts)? else {
                continue;
            };
            match first {
                None => first = Some((f, t.z)),
                Some((p0, z0)) if z0 != t.z => {
                    return Err(TerrainError::Unsupported {
                        source: f.display().to_string(),
                        what: format!(
                            "a zoom {} tile joined to {} of zoom {z0}: a mosaic joins tiles of \
                             one zoom (it never resamples)",
                            t.z,
                            p0.display()
                        ),
                    });
                }
                Some(_) => {}
            }
        }
    }
    let lidar: Vec<std::path::PathBuf> = files
        .iter()
        .filter(|f| is_lidar(f, opts))
        .cloned()
        .collect();
    let mut out = Vec::with_capacity(files.len());
    for f in &files {
        if !lidar.contains(f) {
            out.push((f.display().to_string(), read_dem(f, opts)?));
        } else if lidar.first() == Some(f) {
            let (grid, cloud, _) = lidar::read_lidar(&lidar, &opts.lidar)?;
            out.push((cloud.source, grid));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_degenerate_grids() {
        let g = Georef::local(1.0);
        assert!(matches!(
            Grid::new("t", 1, 1, vec![0.0], g),
            Err(TerrainError::BadSize { .. })
        ));
        assert!(matches!(
            Grid::new("t", 2, 2, vec![f32::NAN; 4], g),
            Err(TerrainError::AllNoData { .. })
        ));
        assert!(matches!(
            Grid::from_samples("t", 2, 2, vec![0.0, f32::NAN, 1.0, 2.0], None, false, g),
            Err(TerrainError::NonFinite { col: 1, row: 0, .. })
        ));
        assert!(matches!(
            Grid::new("t", 2, 2, vec![0.0, f32::INFINITY, 1.0, 2.0], g),
            Err(TerrainError::NonFinite { .. })
        ));
        assert!(matches!(
            check_size("t", 1 << 20, 1 << 20),
            Err(TerrainError::BadSize { .. })
        ));
        // Few samples, but a strip too long to pad to a meshable square.
        assert!(check_size("t", MAX_SIDE as u64, 2).is_ok());
        let e = check_size("t", MAX_SIDE as u64 + 1, 2).unwrap_err();
        assert!(e.to_string().contains("32768"), "{e}");
    }

    #[test]
    fn fill_takes_neighbour_means() {
        let mut g = Grid::from_samples(
            "t",
            3,
            3,
            vec![1.0, 1.0, 1.0, 1.0, -9999.0, 1.0, 1.0, 1.0, 1.0],
            Some(-9999.0),
            false,
            Georef::local(1.0),
        )
        .unwrap();
        assert_eq!(g.nodata_count(), 1);
        g.fill_nodata();
        assert_eq!(g.at(1, 1), 1.0);
    }

    #[test]
    fn geographic_spacing_shrinks_with_latitude() {
        // One arc-second: ~30.87 m north-south; east-west 30.92·cos φ.
        let g = |lat: f64| Georef {
            crs: CrsKind::Geographic,
            epsg: Some(4326),
            origin_x: 138.0,
            origin_y: lat,
            dx: 1.0 / 3600.0,
            dy: -1.0 / 3600.0,
        };
        let (e0, n0) = g(0.0).spacing_metres(1);
        let (e60, _) = g(60.0).spacing_metres(1);
        assert!((n0 - 30.715).abs() < 0.05, "{n0}");
        assert!((e0 - 30.92).abs() < 0.05, "{e0}");
        assert!((e60 / e0 - 0.5).abs() < 0.003, "{}", e60 / e0);
    }
}
