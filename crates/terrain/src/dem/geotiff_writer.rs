//! Writing a raster as a GeoTIFF that GDAL and our own reader ([`super::geotiff`]) read back with
//! the same georeference: 32-bit float samples (a [`Grid`], or heights computed from one) or bytes
//! (a visibility mask, a hillshade) or RGB(A) pixels of bytes (a colour relief; the alpha
//! unassociated, `ExtraSamples` 2, as `gdaldem color-relief -alpha` writes it),
//! Deflate-compressed, either in strips ([`write_grid`], [`write_geotiff`]) or as a
//! Cloud-Optimized GeoTIFF ([`write_grid_with`], [`write_geotiff_with`] with
//! [`GeoTiffOptions::cog`]).
//!
//! The georeference is written as the reader interprets it (GeoTIFF 1.1, OGC 19-008):
//! - `ModelPixelScale` (33550) `(|dx|, |dy|, 0)` and `ModelTiepoint` (33922) tying raster point
//!   `(0, 0)`, the *corner* of pixel `(0, 0)`, to `origin − (dx, dy)/2`: `GTRasterTypeGeoKey` is
//!   `RasterPixelIsArea` (GDAL's default), so a pixel's centre is half a pixel in from its corner
//!   and [`Georef`]'s sample centres come back unchanged (up to one rounding of the half-pixel
//!   shift). A grid whose rows run south (`dy > 0`) or whose columns run west gets a
//!   `ModelTransformation` (34264) instead, which the scale + tie point pair cannot express.
//! - GeoKeys (34735): `GTModelTypeGeoKey` 1 (projected) or 2 (geographic);
//!   `ProjectedCSTypeGeoKey` (3072) with the EPSG code and `ProjLinearUnitsGeoKey` (3076) metres,
//!   or `GeographicTypeGeoKey` (2048) with the EPSG code (4326 when the grid knows none:
//!   geographic grids are taken as WGS 84, see [`crate::geodesy`]). A local grid gets only the
//!   raster type: GDAL reports no system, as for the file it came from.
//! - GDAL's no-data tag (42113, ASCII) when the caller gives a no-data value (`nan` for a float
//!   grid with holes, as GDAL writes it).
//!
//! # Cloud-Optimized GeoTIFF
//! A COG lets a client that reads byte ranges over HTTP (QGIS, TiTiler, GDAL's `/vsicurl/`)
//! fetch only the tiles, at only the zoom level, it shows. We write the layout GDAL 3.6's COG
//! driver writes (`gdal_translate -of COG`, its documentation's "File format details"):
//! - Square tiles, 512 x 512 by default ([`GeoTiffOptions::block_size`], GDAL's `BLOCKSIZE`),
//!   edge tiles padded with the no-data value (0 without one); Deflate (zlib level 6) with a
//!   predictor: 3, the floating-point predictor, for float32 (libtiff's `fpDiff`: byte planes,
//!   most significant first, then byte differences along the row), 2 for bytes.
//! - Overviews halving (rounding down) until the image fits one tile, as the COG driver sizes
//!   them, each made from the level before it (GDAL cascades its overviews the same way). The
//!   resampling departs from GDAL's default, which is `CUBIC` for every raster without a colour
//!   table: cubic overshoots at cliffs and has no use for a mask's two values. Heights are
//!   averaged as GDAL's `AVERAGE` (`-co RESAMPLING=AVERAGE`): a pixel covers `src/dst` source
//!   pixels, the partly covered ones at odd sizes weighted by the part covered, no-data samples
//!   (`NaN` for `nan`) left out, `f64` sums rounded once to `f32`; masks and colours take
//!   GDAL's `NEAREST` (source index `⌊i·src/dst + 0.5⌋`). tests/dem_formats.rs compares every level with GDAL's:
//!   the same bits with no-data; at most 2 ulp apart without (GDAL's 2 x 2 shortcut then sums in
//!   `f32`).
//! - Overview IFDs carry `NewSubfileType` 1 and the no-data tag but, as GDAL writes them, no
//!   georeference (a reader scales the full resolution's).
//! - The layout: the TIFF header, GDAL's structural metadata ("ghost area":
//!   `LAYOUT=IFDS_BEFORE_DATA`, `BLOCK_ORDER=ROW_MAJOR`, `BLOCK_LEADER=SIZE_AS_UINT4`,
//!   `BLOCK_TRAILER=LAST_4_BYTES_REPEATED`, `KNOWN_INCOMPATIBLE_EDITION=NO`, which gdalinfo
//!   reports as `LAYOUT=COG`), every IFD with its values (full resolution first), then the tiles,
//!   the smallest overview's first and the full resolution's last, row-major within a level,
//!   each between its size as a `u32` and a repeat of its last 4 bytes.
//!
//! Tiles are compressed in parallel (rayon) and written in that fixed order, so the file's bytes
//! do not depend on the thread count. The whole compressed pyramid is held in memory before
//! writing, since the IFDs that come first hold every tile's offset: about the size of the file.
//!
//! The file is written under a temporary name beside the destination and renamed into place, so a
//! failure never leaves a partial file under the destination's name. Files over 4 GiB are BigTIFF.

use super::{CrsKind, Georef, Grid};
use crate::error::{TerrainError, io};
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};
use tiff::encoder::compression::DeflateLevel;
use tiff::encoder::{
    Compression, Predictor, TiffEncoder, TiffKind, TiffKindBig, TiffKindStandard, colortype,
};
use tiff::tags::Tag;

/// The samples of a raster to write, row-major.
#[derive(Clone, Copy, Debug)]
pub enum Samples<'a> {
    /// 32-bit floats (heights; `NaN` is no-data when the no-data value given is `NaN`).
    F32(&'a [f32]),
    /// Bytes (a mask).
    U8(&'a [u8]),
    /// RGB bytes, interleaved (a colour relief): 3 a pixel.
    Rgb8(&'a [u8]),
    /// RGBA bytes, interleaved, the alpha unassociated: 4 a pixel.
    Rgba8(&'a [u8]),
}

impl Samples<'_> {
    /// Pixels (whole ones: a trailing part of a pixel is not counted).
    fn len(&self) -> usize {
        match self {
            Samples::F32(v) => v.len(),
            Samples::U8(v) => v.len(),
            Samples::Rgb8(v) => v.len() / 3,
            Samples::Rgba8(v) => v.len() / 4,
        }
    }

    fn bytes_per_sample(&self) -> u64 {
        match self {
            Samples::F32(_) => 4,
            Samples::U8(_) => 1,
            Samples::Rgb8(_) => 3,
            Samples::Rgba8(_) => 4,
        }
    }

    /// Whether the slice holds exactly `len()` whole pixels.
    fn whole(&self) -> bool {
        match self {
            Samples::Rgb8(v) => v.len() % 3 == 0,
            Samples::Rgba8(v) => v.len() % 4 == 0,
            _ => true,
        }
    }
}

/// How [`write_geotiff_with`] lays a file out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeoTiffOptions {
    /// A Cloud-Optimized GeoTIFF (tiles, overviews, every directory before the data; see the
    /// module docs) instead of one image in strips.
    pub cog: bool,
    /// The side of a COG's square tiles in pixels, a multiple of 16 from 16 to 4096 (GDAL's
    /// `BLOCKSIZE`, 512 by default). Unused without `cog`.
    pub block_size: u32,
}

impl Default for GeoTiffOptions {
    /// Strips, as [`write_geotiff`] writes them.
    fn default() -> Self {
        GeoTiffOptions {
            cog: false,
            block_size: 512,
        }
    }
}

impl GeoTiffOptions {
    /// A Cloud-Optimized GeoTIFF with 512 x 512 tiles (GDAL's COG defaults).
    pub fn cog() -> Self {
        GeoTiffOptions {
            cog: true,
            ..GeoTiffOptions::default()
        }
    }
}

/// Write `grid` as a float32 GeoTIFF in strips, its holes as `NaN` with GDAL's no-data tag `nan`
/// (no tag when the grid has none).
pub fn write_grid(path: &Path, grid: &Grid) -> Result<(), TerrainError> {
    write_grid_with(path, grid, &GeoTiffOptions::default())
}

/// [`write_grid`] laid out as `options` say (strips, or a Cloud-Optimized GeoTIFF).
pub fn write_grid_with(
    path: &Path,
    grid: &Grid,
    options: &GeoTiffOptions,
) -> Result<(), TerrainError> {
    let nodata = (grid.nodata_count() > 0).then_some(f64::NAN);
    write_geotiff_with(
        path,
        grid.width(),
        grid.height(),
        Samples::F32(grid.heights()),
        grid.georef(),
        nodata,
        options,
    )
}

/// Write `width x height` samples placed by `georef` as a GeoTIFF in strips at `path` (through a
/// temporary file renamed into place), with GDAL's no-data tag when `nodata` is given.
pub fn write_geotiff(
    path: &Path,
    width: u32,
    height: u32,
    samples: Samples,
    georef: &Georef,
    nodata: Option<f64>,
) -> Result<(), TerrainError> {
    write_geotiff_with(
        path,
        width,
        height,
        samples,
        georef,
        nodata,
        &GeoTiffOptions::default(),
    )
}

/// [`write_geotiff`] laid out as `options` say (strips, or a Cloud-Optimized GeoTIFF).
pub fn write_geotiff_with(
    path: &Path,
    width: u32,
    height: u32,
    samples: Samples,
    georef: &Georef,
    nodata: Option<f64>,
    options: &GeoTiffOptions,
) -> Result<(), TerrainError> {
    let source = path.display().to_string();
    if width == 0
        || height == 0
        || !samples.whole()
        || samples.len() as u64 != width as u64 * height as u64
    {
        return Err(TerrainError::BadParameter {
            name: "samples",
            value: format!("{} for {width} x {height}", samples.len()),
            expected: "width x height samples, at least one",
        });
    }
    let block = options.block_size;
    if options.cog && (block == 0 || !block.is_multiple_of(16) || block > 4096) {
        return Err(TerrainError::BadParameter {
            name: "block_size",
            value: block.to_string(),
            expected: "a multiple of 16 from 16 to 4096",
        });
    }
    let tags = GeoTags::of(georef, &source)?;
    write_atomically(path, |out| {
        if options.cog {
            let written = match samples {
                Samples::F32(v) => {
                    let nd = nodata.map(|n| n as f32);
                    let levels = cog_levels_f32(v, width, height, block, nd);
                    write_cog(out, &levels, block, nd.unwrap_or(0.0), &tags, nodata, false)
                }
                Samples::U8(v) => {
                    let levels = cog_levels_u8(v, width, height, block);
                    let fill = nodata.map_or(0, |n| n as u8);
                    write_cog(out, &levels, block, fill, &tags, nodata, false)
                }
                Samples::Rgb8(v) => {
                    let px: Vec<[u8; 3]> = v.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
                    let levels = cog_levels(&px, width, height, block, nearest);
                    write_cog(out, &levels, block, [0; 3], &tags, nodata, false)
                }
                Samples::Rgba8(v) => {
                    let px: Vec<[u8; 4]> = v
                        .chunks_exact(4)
                        .map(|p| [p[0], p[1], p[2], p[3]])
                        .collect();
                    let levels = cog_levels(&px, width, height, block, nearest);
                    write_cog(out, &levels, block, [0; 4], &tags, nodata, false)
                }
            };
            return written.map_err(io(path));
        }
        // Classic TIFF offsets are 32-bit: leave a margin for the directory and the strip table
        // (Deflate never grows a strip by more than a few bytes per 64 KiB).
        let payload = samples.len() as u64 * samples.bytes_per_sample();
        if payload < (1u64 << 32) - (1 << 26) {
            let enc = TiffEncoder::<_, TiffKindStandard>::new_generic(out);
            encode(enc, width, height, samples, &tags, nodata, &source)
        } else {
            let enc = TiffEncoder::<_, TiffKindBig>::new_generic(out);
            encode(enc, width, height, samples, &tags, nodata, &source)
        }
    })
}

/// Run `write` on a buffered temporary file beside `path`, then sync it and rename it to `path`;
/// on any failure the temporary file is removed.
pub(crate) fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), TerrainError>,
) -> Result<(), TerrainError> {
    let tmp = temp_beside(path);
    let result = (|| {
        let file = std::fs::File::create(&tmp).map_err(io(path))?;
        let mut out = std::io::BufWriter::new(file);
        write(&mut out)?;
        let file = out.into_inner().map_err(|e| TerrainError::Io {
            path: path.to_path_buf(),
            source: e.into_error(),
        })?;
        file.sync_all().map_err(io(path))?;
        std::fs::rename(&tmp, path).map_err(io(path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// `.NAME.partial-PID` beside `path`.
fn temp_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out.tif".into());
    path.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

/// The georeference tags of one file, worked out before anything is written.
struct GeoTags {
    /// `ModelPixelScale` and `ModelTiepoint`, or a `ModelTransformation`.
    placement: Placement,
    keys: Vec<u16>,
}

enum Placement {
    ScaleTie([f64; 3], [f64; 6]),
    Transformation([f64; 16]),
}

impl GeoTags {
    fn of(g: &Georef, source: &str) -> Result<GeoTags, TerrainError> {
        let ok = [g.origin_x, g.origin_y, g.dx, g.dy]
            .iter()
            .all(|v| v.is_finite());
        if !ok || g.dx == 0.0 || g.dy == 0.0 {
            return Err(crate::error::format_err(
                source,
                "georeference",
                format!("finite origin and non-zero finite spacing, got {g:?}"),
            ));
        }
        // PixelIsArea: raster space counts pixel corners, so (0, 0) is half a pixel before the
        // centre of sample (0, 0).
        let (x0, y0) = (g.origin_x - 0.5 * g.dx, g.origin_y - 0.5 * g.dy);
        let placement = if g.dx > 0.0 && g.dy < 0.0 {
            Placement::ScaleTie([g.dx, -g.dy, 0.0], [0.0, 0.0, 0.0, x0, y0, 0.0])
        } else {
            Placement::Transformation([
                g.dx, 0.0, 0.0, x0, //
                0.0, g.dy, 0.0, y0, //
                0.0, 0.0, 0.0, 0.0, //
                0.0, 0.0, 0.0, 1.0,
            ])
        };
        // (KeyID, TIFFTagLocation 0 = inline, Count 1, Value), sorted by KeyID.
        let mut entries: Vec<[u16; 4]> = Vec::new();
        match g.crs {
            CrsKind::Projected => entries.push([1024, 0, 1, 1]),
            CrsKind::Geographic => entries.push([1024, 0, 1, 2]),
            CrsKind::Local => {}
        }
        entries.push([1025, 0, 1, 1]); // RasterPixelIsArea
        match g.crs {
            CrsKind::Geographic => entries.push([2048, 0, 1, g.epsg.unwrap_or(4326)]),
            CrsKind::Projected => {
                if let Some(code) = g.epsg {
                    entries.push([3072, 0, 1, code]);
                }
                entries.push([3076, 0, 1, 9001]); // metre
            }
            CrsKind::Local => {}
        }
        let mut keys = vec![1, 1, 0, entries.len() as u16];
        keys.extend(entries.iter().flatten());
        Ok(GeoTags { placement, keys })
    }
}

fn tiff_err(source: &str) -> impl Fn(tiff::TiffError) -> TerrainError + '_ {
    move |e| match e {
        tiff::TiffError::IoError(err) => TerrainError::Io {
            path: PathBuf::from(source),
            source: err,
        },
        other => TerrainError::Unsupported {
            source: source.to_string(),
            what: format!("writing the GeoTIFF: {other}"),
        },
    }
}

fn encode<W: Write + Seek, K: TiffKind>(
    enc: tiff::TiffResult<TiffEncoder<W, K>>,
    width: u32,
    height: u32,
    samples: Samples,
    tags: &GeoTags,
    nodata: Option<f64>,
    source: &str,
) -> Result<(), TerrainError> {
    let err = tiff_err(source);
    let enc = enc.map_err(&err)?;
    let mut enc = enc.with_compression(Compression::Deflate(DeflateLevel::Balanced));
    // Horizontal differencing makes long runs of one byte value (a mask) runs of zeros.
    let pred = Predictor::Horizontal;
    match samples {
        Samples::F32(v) => {
            image::<_, _, colortype::Gray32Float>(&mut enc, width, height, v, false, tags, nodata)
        }
        Samples::U8(v) => image::<_, _, colortype::Gray8>(
            &mut enc.with_predictor(pred),
            width,
            height,
            v,
            false,
            tags,
            nodata,
        ),
        Samples::Rgb8(v) => image::<_, _, colortype::RGB8>(
            &mut enc.with_predictor(pred),
            width,
            height,
            v,
            false,
            tags,
            nodata,
        ),
        Samples::Rgba8(v) => image::<_, _, colortype::RGBA8>(
            &mut enc.with_predictor(pred),
            width,
            height,
            v,
            true,
            tags,
            nodata,
        ),
    }
    .map_err(&err)
}

/// One strip image of colour type `C` with the geo tags; `alpha`: the last sample is
/// unassociated alpha (ExtraSamples 2, GDAL's -alpha output).
#[allow(clippy::too_many_arguments)] // the image's parts, each used once
fn image<W: Write + Seek, K: TiffKind, C: colortype::ColorType>(
    enc: &mut TiffEncoder<W, K>,
    width: u32,
    height: u32,
    data: &[C::Inner],
    alpha: bool,
    tags: &GeoTags,
    nodata: Option<f64>,
) -> tiff::TiffResult<()>
where
    [C::Inner]: tiff::encoder::TiffValue,
{
    let mut img = enc.new_image::<C>(width, height)?;
    if alpha {
        img.encoder().write_tag(Tag::ExtraSamples, &[2u16][..])?;
    }
    write_geo_tags(img.encoder(), tags, nodata)?;
    img.write_data(data)
}

fn write_geo_tags<W: Write + Seek, K: TiffKind>(
    dir: &mut tiff::encoder::DirectoryEncoder<'_, W, K>,
    tags: &GeoTags,
    nodata: Option<f64>,
) -> tiff::TiffResult<()> {
    match &tags.placement {
        Placement::ScaleTie(scale, tie) => {
            dir.write_tag(Tag::ModelPixelScaleTag, &scale[..])?;
            dir.write_tag(Tag::ModelTiepointTag, &tie[..])?;
        }
        Placement::Transformation(m) => dir.write_tag(Tag::ModelTransformationTag, &m[..])?,
    }
    dir.write_tag(Tag::GeoKeyDirectoryTag, &tags.keys[..])?;
    if let Some(v) = nodata {
        dir.write_tag(Tag::GdalNodata, nodata_text(v).as_str())?;
    }
    Ok(())
}

/// GDAL's no-data tag text: `nan`, or the value.
fn nodata_text(v: f64) -> String {
    if v.is_nan() {
        "nan".to_string()
    } else {
        format!("{v}")
    }
}

// ---------------------------------------------------------------------------------------------
// Cloud-Optimized GeoTIFF
// ---------------------------------------------------------------------------------------------

/// A sample type a COG holds: its bytes, TIFF `SampleFormat` and predictor.
trait CogSample: Copy + Send + Sync {
    /// Bytes per sample.
    const BYTES: usize;
    /// TIFF `SampleFormat` (339): 1 unsigned integer, 3 IEEE float.
    const FORMAT: u16;
    /// TIFF `Predictor` (317): 2 horizontal differencing, 3 floating point.
    const PREDICTOR: u16;
    /// Samples a pixel (`SamplesPerPixel`, 277): 1, or 3 (RGB) and 4 (RGBA) bytes.
    const SAMPLES: u16 = 1;
    /// The sample as little-endian bytes into `out` (`BYTES` long).
    fn put(self, out: &mut [u8]);
}

impl CogSample for f32 {
    const BYTES: usize = 4;
    const FORMAT: u16 = 3;
    const PREDICTOR: u16 = 3;
    fn put(self, out: &mut [u8]) {
        out.copy_from_slice(&self.to_le_bytes());
    }
}

impl CogSample for u8 {
    const BYTES: usize = 1;
    const FORMAT: u16 = 1;
    const PREDICTOR: u16 = 2;
    fn put(self, out: &mut [u8]) {
        out[0] = self;
    }
}

/// An RGB or RGBA byte pixel, its samples interleaved.
impl<const N: usize> CogSample for [u8; N] {
    const BYTES: usize = N;
    const FORMAT: u16 = 1;
    const PREDICTOR: u16 = 2;
    const SAMPLES: u16 = N as u16;
    fn put(self, out: &mut [u8]) {
        out.copy_from_slice(&self);
    }
}

/// One level of the pyramid, row-major.
struct Level<'a, T: Clone> {
    width: u32,
    height: u32,
    samples: std::borrow::Cow<'a, [T]>,
}

/// The overview sizes GDAL's COG driver makes: halving (rounding down, at least 1) until the
/// image fits one `block` x `block` tile.
fn overview_sizes(width: u32, height: u32, block: u32) -> Vec<(u32, u32)> {
    let mut sizes = Vec::new();
    let (mut w, mut h) = (width, height);
    while w > block || h > block {
        w = (w / 2).max(1);
        h = (h / 2).max(1);
        sizes.push((w, h));
    }
    sizes
}

/// GDAL's `AVERAGE` resampling from `src` (`sw x sh`) to `dw x dh` (GDAL 3.6
/// `GDALResampleChunk32R_Average`): destination pixel `i` covers source columns
/// `[i·r, (i+1)·r)`, `r = sw/dw`, the partly covered end columns (odd sizes) weighted by the part
/// covered; samples equal to `nodata` (or `NaN` when `nodata` is `NaN`) are left out, and a pixel
/// with none left is `nodata`. Sums are in `f64`, the mean rounded once to `f32`.
fn average_f32(src: &[f32], sw: u32, sh: u32, dw: u32, dh: u32, nodata: Option<f32>) -> Vec<f32> {
    use rayon::prelude::*;
    let is_nodata = |v: f32| match nodata {
        Some(n) if n.is_nan() => v.is_nan(),
        Some(n) => v == n,
        None => false,
    };
    // (first source index, end index, weight of the first, weight of the last) per destination
    // index along one axis; GDAL's epsilon of 1e-8 keeps exact multiples from rounding outward.
    let spans = |s: u32, d: u32| -> Vec<(usize, usize, f64, f64)> {
        let r = s as f64 / d as f64;
        (0..d)
            .map(|i| {
                let (x0, x1) = (i as f64 * r, (i + 1) as f64 * r);
                let a = (x0 + 1e-8) as usize;
                let mut b = (x1 - 1e-8).ceil() as usize;
                if b == a {
                    b += 1;
                }
                let b = b.min(s as usize);
                let first = if b == a + 1 {
                    1.0
                } else {
                    1.0 - (x0 - a as f64)
                };
                let last = 1.0 - (b as f64 - x1);
                (a, b, first, last)
            })
            .collect()
    };
    let (xs, ys) = (spans(sw, dw), spans(sh, dh));
    let fill = nodata.unwrap_or(f32::NAN);
    let mut out = vec![0f32; dw as usize * dh as usize];
    out.par_chunks_mut(dw as usize)
        .zip(ys.par_iter())
        .for_each(|(row, &(y0, y1, wy0, wy1))| {
            for (o, &(x0, x1, wx0, wx1)) in row.iter_mut().zip(&xs) {
                let (mut total, mut weight) = (0.0f64, 0.0f64);
                for y in y0..y1 {
                    let wy = if y == y0 {
                        wy0
                    } else if y + 1 == y1 {
                        wy1
                    } else {
                        1.0
                    };
                    let line = &src[y * sw as usize..][..sw as usize];
                    for (x, &v) in line.iter().enumerate().take(x1).skip(x0) {
                        if is_nodata(v) {
                            continue;
                        }
                        let wx = if x == x0 {
                            wx0
                        } else if x + 1 == x1 {
                            wx1
                        } else {
                            1.0
                        };
                        let w = wx * wy;
                        total += v as f64 * w;
                        weight += w;
                    }
                }
                *o = if weight > 0.0 {
                    (total / weight) as f32
                } else {
                    fill
                };
            }
        });
    out
}

/// GDAL 3.6's `NEAREST` resampling from `src` (`sw x sh`) to `dw x dh`: destination pixel `i`
/// takes source index `⌊i·sw/dw + 0.5⌋`.
fn nearest<T: Copy>(src: &[T], sw: u32, sh: u32, dw: u32, dh: u32) -> Vec<T> {
    let pick = |s: u32, d: u32| -> Vec<usize> {
        let r = s as f64 / d as f64;
        (0..d)
            .map(|i| ((i as f64 * r + 0.5) as usize).min(s as usize - 1))
            .collect()
    };
    let (xs, ys) = (pick(sw, dw), pick(sh, dh));
    let mut out = Vec::with_capacity(dw as usize * dh as usize);
    for &y in &ys {
        let line = &src[y * sw as usize..][..sw as usize];
        out.extend(xs.iter().map(|&x| line[x]));
    }
    out
}

/// Apply TIFF predictor `predictor` to one row of a tile, in place (`scratch` is reused).
/// - 2: each byte sample minus the same sample of the pixel before it (TIFF 6.0 §14): `stride`
///   bytes back (the samples a pixel).
/// - 3: the floating-point predictor (Adobe Photoshop TIFF Technical Note 3): the row's samples
///   split into byte planes, most significant first, then each byte minus the one before it
///   across the whole row, as libtiff's `fpDiff` does.
fn predict_row(predictor: u16, bytes: usize, stride: usize, row: &mut [u8], scratch: &mut Vec<u8>) {
    if predictor == 3 {
        let n = row.len() / bytes;
        scratch.clear();
        scratch.extend_from_slice(row);
        for (i, sample) in scratch.chunks_exact(bytes).enumerate() {
            for (b, &byte) in sample.iter().enumerate() {
                row[(bytes - 1 - b) * n + i] = byte;
            }
        }
    }
    for i in (stride..row.len()).rev() {
        row[i] = row[i].wrapping_sub(row[i - stride]);
    }
}

/// Every tile of `level`, row-major, predicted and Deflate-compressed (zlib stream, TIFF
/// compression 8). Tiles are compressed in parallel and gathered in order, so the bytes do not
/// depend on the thread count.
fn compress_tiles<T: CogSample>(level: &Level<T>, block: u32, fill: T) -> Vec<Vec<u8>> {
    use rayon::prelude::*;
    let (across, down) = (level.width.div_ceil(block), level.height.div_ceil(block));
    let b = block as usize;
    (0..across * down)
        .into_par_iter()
        .map(|t| {
            let (x0, y0) = ((t % across * block) as usize, (t / across * block) as usize);
            let mut raw = vec![0u8; b * b * T::BYTES];
            let mut scratch = Vec::new();
            for (r, row) in raw.chunks_exact_mut(b * T::BYTES).enumerate() {
                let y = y0 + r;
                for (c, out) in row.chunks_exact_mut(T::BYTES).enumerate() {
                    let x = x0 + c;
                    let v = if x < level.width as usize && y < level.height as usize {
                        level.samples[y * level.width as usize + x]
                    } else {
                        fill
                    };
                    v.put(out);
                }
                let stride = if T::SAMPLES > 1 {
                    T::SAMPLES as usize
                } else {
                    1
                };
                predict_row(T::PREDICTOR, T::BYTES, stride, row, &mut scratch);
            }
            let mut z = flate2::write::ZlibEncoder::new(
                Vec::with_capacity(raw.len() / 2),
                flate2::Compression::new(6),
            );
            // Writing into a Vec cannot fail.
            let _ = z.write_all(&raw);
            z.finish().unwrap_or_default()
        })
        .collect()
}

/// Classic TIFF (32-bit offsets) or BigTIFF (64-bit).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Classic,
    Big,
}

impl Kind {
    /// Bytes of an offset (and of an entry's value field).
    fn word(self) -> usize {
        match self {
            Kind::Classic => 4,
            Kind::Big => 8,
        }
    }
    fn header_len(self) -> usize {
        match self {
            Kind::Classic => 8,
            Kind::Big => 16,
        }
    }
    /// Bytes of an IFD without the values stored outside it.
    fn ifd_len(self, entries: usize) -> usize {
        match self {
            Kind::Classic => 2 + 12 * entries + 4,
            Kind::Big => 8 + 20 * entries + 8,
        }
    }
}

/// A tag's value.
enum Value {
    Short(Vec<u16>),
    Long(Vec<u32>),
    /// Offsets and byte counts: LONG in classic TIFF, LONG8 in BigTIFF.
    Offsets(Vec<u64>),
    Double(Vec<f64>),
    /// ASCII, NUL-terminated here.
    Ascii(Vec<u8>),
}

impl Value {
    /// (TIFF type, count, little-endian bytes).
    fn encode(&self, kind: Kind) -> (u16, u64, Vec<u8>) {
        match self {
            Value::Short(v) => (
                3,
                v.len() as u64,
                v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            ),
            Value::Long(v) => (
                4,
                v.len() as u64,
                v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            ),
            Value::Offsets(v) => match kind {
                Kind::Classic => (
                    4,
                    v.len() as u64,
                    v.iter().flat_map(|&x| (x as u32).to_le_bytes()).collect(),
                ),
                Kind::Big => (
                    16,
                    v.len() as u64,
                    v.iter().flat_map(|x| x.to_le_bytes()).collect(),
                ),
            },
            Value::Double(v) => (
                12,
                v.len() as u64,
                v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            ),
            Value::Ascii(v) => (2, v.len() as u64, v.clone()),
        }
    }
}

/// An IFD's bytes at `at`, its values that do not fit an entry placed right after it (each at
/// an even offset), chained to `next`.
fn ifd_bytes(kind: Kind, entries: &[(u16, Value)], at: u64, next: u64) -> Vec<u8> {
    let word = kind.word();
    let mut ifd = Vec::new();
    let mut extra = Vec::new();
    let extra_at = at + kind.ifd_len(entries.len()) as u64;
    match kind {
        Kind::Classic => ifd.extend((entries.len() as u16).to_le_bytes()),
        Kind::Big => ifd.extend((entries.len() as u64).to_le_bytes()),
    }
    for (tag, value) in entries {
        let (ty, count, bytes) = value.encode(kind);
        ifd.extend(tag.to_le_bytes());
        ifd.extend(ty.to_le_bytes());
        match kind {
            Kind::Classic => ifd.extend((count as u32).to_le_bytes()),
            Kind::Big => ifd.extend(count.to_le_bytes()),
        }
        if bytes.len() <= word {
            let mut field = bytes;
            field.resize(word, 0);
            ifd.extend(field);
        } else {
            let off = extra_at + extra.len() as u64;
            match kind {
                Kind::Classic => ifd.extend((off as u32).to_le_bytes()),
                Kind::Big => ifd.extend(off.to_le_bytes()),
            }
            extra.extend(bytes);
            if extra.len() % 2 == 1 {
                extra.push(0);
            }
        }
    }
    match kind {
        Kind::Classic => ifd.extend((next as u32).to_le_bytes()),
        Kind::Big => ifd.extend(next.to_le_bytes()),
    }
    ifd.extend(extra);
    ifd
}

/// GDAL's structural metadata ("ghost area") of a COG, written right after the TIFF header
/// (GDAL's COG driver documentation, "Header ghost area"): the IFDs come before the data, tiles
/// are in row-major order, each preceded by its size as a `u32` and followed by a repeat of its
/// last 4 bytes.
fn ghost_area() -> Vec<u8> {
    let body = "LAYOUT=IFDS_BEFORE_DATA\n\
                BLOCK_ORDER=ROW_MAJOR\n\
                BLOCK_LEADER=SIZE_AS_UINT4\n\
                BLOCK_TRAILER=LAST_4_BYTES_REPEATED\n\
                KNOWN_INCOMPATIBLE_EDITION=NO\n ";
    format!(
        "GDAL_STRUCTURAL_METADATA_SIZE={:06} bytes\n{body}",
        body.len()
    )
    .into_bytes()
}

/// Write `levels` (full resolution first) as a COG into `out`: BigTIFF when `big` or when an
/// offset would not fit 32 bits, classic TIFF otherwise. Partial edge tiles are padded with
/// `fill`.
fn write_cog<T: CogSample, W: Write>(
    out: &mut W,
    levels: &[Level<T>],
    block: u32,
    fill: T,
    tags: &GeoTags,
    nodata: Option<f64>,
    big: bool,
) -> std::io::Result<()> {
    let tiles: Vec<Vec<Vec<u8>>> = levels
        .iter()
        .map(|l| compress_tiles(l, block, fill))
        .collect();
    // The entries of every level's IFD, offsets left to fill in.
    let entries = |level: usize, offsets: Vec<u64>, counts: Vec<u64>| {
        let l = &levels[level];
        let mut e: Vec<(u16, Value)> = Vec::new();
        if level > 0 {
            e.push((254, Value::Long(vec![1]))); // NewSubfileType: reduced resolution
        }
        e.push((256, Value::Long(vec![l.width])));
        e.push((257, Value::Long(vec![l.height])));
        let spp = T::SAMPLES as usize;
        let bits = 8 * (T::BYTES / spp) as u16;
        e.push((258, Value::Short(vec![bits; spp])));
        e.push((259, Value::Short(vec![8]))); // Deflate
        // BlackIsZero, or RGB.
        e.push((262, Value::Short(vec![if spp >= 3 { 2 } else { 1 }])));
        e.push((277, Value::Short(vec![T::SAMPLES])));
        e.push((284, Value::Short(vec![1])));
        e.push((317, Value::Short(vec![T::PREDICTOR])));
        e.push((322, Value::Long(vec![block])));
        e.push((323, Value::Long(vec![block])));
        e.push((324, Value::Offsets(offsets)));
        e.push((325, Value::Offsets(counts)));
        if spp == 4 {
            e.push((338, Value::Short(vec![2]))); // ExtraSamples: unassociated alpha
        }
        e.push((339, Value::Short(vec![T::FORMAT; spp])));
        // GDAL writes the georeference on the full resolution only, the no-data value on all.
        if level == 0 {
            match &tags.placement {
                Placement::ScaleTie(scale, tie) => {
                    e.push((33550, Value::Double(scale.to_vec())));
                    e.push((33922, Value::Double(tie.to_vec())));
                }
                Placement::Transformation(m) => e.push((34264, Value::Double(m.to_vec()))),
            }
            e.push((34735, Value::Short(tags.keys.clone())));
        }
        if let Some(v) = nodata {
            let mut text = nodata_text(v).into_bytes();
            text.push(0);
            e.push((42113, Value::Ascii(text)));
        }
        e
    };
    let ghost = ghost_area();
    let layout = |kind: Kind| {
        // IFDs (with their values) one after the other, each at an even offset.
        let mut at = (kind.header_len() + ghost.len()).next_multiple_of(2) as u64;
        let mut ifd_at = Vec::new();
        for (i, t) in tiles.iter().enumerate() {
            ifd_at.push(at);
            let len = ifd_bytes(kind, &entries(i, vec![0; t.len()], vec![0; t.len()]), at, 0).len();
            at = (at + len as u64).next_multiple_of(2);
        }
        // Then the tiles, the smallest overview's first, each between its leader and trailer.
        let mut offsets: Vec<Vec<u64>> =
            tiles.iter().map(|t| Vec::with_capacity(t.len())).collect();
        for (i, t) in tiles.iter().enumerate().rev() {
            for tile in t {
                offsets[i].push(at + 4);
                at += tile.len() as u64 + 8;
            }
        }
        (ifd_at, offsets, at)
    };
    let (mut kind, mut plan) = (Kind::Classic, layout(Kind::Classic));
    if big || plan.2 > u32::MAX as u64 {
        kind = Kind::Big;
        plan = layout(kind);
    }
    let (ifd_at, offsets, _) = plan;
    // Header.
    match kind {
        Kind::Classic => {
            out.write_all(b"II\x2a\x00")?;
            out.write_all(&(ifd_at[0] as u32).to_le_bytes())?;
        }
        Kind::Big => {
            out.write_all(b"II\x2b\x00\x08\x00\x00\x00")?;
            out.write_all(&ifd_at[0].to_le_bytes())?;
        }
    }
    out.write_all(&ghost)?;
    let mut pos = (kind.header_len() + ghost.len()) as u64;
    for (i, t) in tiles.iter().enumerate() {
        let pad = ifd_at[i] - pos;
        out.write_all(&vec![0u8; pad as usize])?;
        let next = ifd_at.get(i + 1).copied().unwrap_or(0);
        let counts = t.iter().map(|x| x.len() as u64).collect();
        let bytes = ifd_bytes(
            kind,
            &entries(i, offsets[i].clone(), counts),
            ifd_at[i],
            next,
        );
        out.write_all(&bytes)?;
        pos = ifd_at[i] + bytes.len() as u64;
    }
    let first_tile = pos.next_multiple_of(2);
    out.write_all(&vec![0u8; (first_tile - pos) as usize])?;
    for t in tiles.iter().rev() {
        for tile in t {
            out.write_all(&(tile.len() as u32).to_le_bytes())?;
            out.write_all(tile)?;
            let mut trailer = [0u8; 4];
            let n = tile.len().min(4);
            trailer[4 - n..].copy_from_slice(&tile[tile.len() - n..]);
            out.write_all(&trailer)?;
        }
    }
    Ok(())
}

/// The pyramid of `samples` for a COG: full resolution, then overviews each made from the one
/// before by `down(previous, its width, its height, width, height)` (as GDAL's
/// `GDALRegenerateOverviews` cascades them).
fn cog_levels<'a, T: Clone>(
    samples: &'a [T],
    width: u32,
    height: u32,
    block: u32,
    down: impl Fn(&[T], u32, u32, u32, u32) -> Vec<T>,
) -> Vec<Level<'a, T>> {
    let mut levels = vec![Level {
        width,
        height,
        samples: std::borrow::Cow::Borrowed(samples),
    }];
    for (w, h) in overview_sizes(width, height, block) {
        let prev = &levels[levels.len() - 1];
        let s = down(&prev.samples, prev.width, prev.height, w, h);
        levels.push(Level {
            width: w,
            height: h,
            samples: std::borrow::Cow::Owned(s),
        });
    }
    levels
}

/// [`cog_levels`] of heights: `average` (no-data left out).
fn cog_levels_f32(
    samples: &[f32],
    width: u32,
    height: u32,
    block: u32,
    nodata: Option<f32>,
) -> Vec<Level<'_, f32>> {
    cog_levels(samples, width, height, block, |p, pw, ph, w, h| {
        average_f32(p, pw, ph, w, h, nodata)
    })
}

/// [`cog_levels`] of bytes: `nearest`.
fn cog_levels_u8(samples: &[u8], width: u32, height: u32, block: u32) -> Vec<Level<'_, u8>> {
    cog_levels(samples, width, height, block, nearest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::geotiff::read_geotiff;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
    }

    #[test]
    fn south_up_and_local_grids_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        for georef in [
            Georef::local(2.5),
            Georef {
                crs: CrsKind::Projected,
                epsg: Some(32619),
                origin_x: 500_000.0,
                origin_y: 4_900_000.0,
                dx: 30.0,
                dy: 30.0, // rows run north: a ModelTransformation
            },
        ] {
            let h: Vec<f32> = (0..12).map(|i| i as f32 * 1.5).collect();
            let g = Grid::new("t", 4, 3, h, georef).unwrap();
            let p = dir.path().join("g.tif");
            write_grid(&p, &g).unwrap();
            let back = read_geotiff(&p).unwrap();
            assert_eq!(back.heights(), g.heights());
            let c = dir.path().join("g_cog.tif");
            write_grid_with(&c, &g, &GeoTiffOptions::cog()).unwrap();
            let cog = read_geotiff(&c).unwrap();
            assert_eq!(cog.heights(), g.heights());
            assert_eq!(cog.georef(), back.georef());
            let (a, b) = (back.georef(), g.georef());
            assert_eq!((a.crs, a.epsg), (b.crs, b.epsg));
            assert!(close(a.origin_x, b.origin_x) && close(a.origin_y, b.origin_y));
            assert!(a.dx == b.dx && a.dy == b.dy, "{a:?} vs {b:?}");
        }
        // Nothing is left beside the output.
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 2);
    }

    /// A BigTIFF COG (what files over 4 GiB get) reads back through the tiff crate sample for
    /// sample, overviews included, with 16-pixel tiles so that a small grid has several levels.
    #[test]
    fn a_bigtiff_cog_reads_back_with_its_overviews() {
        use tiff::decoder::{Decoder, DecodingResult};
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (45u32, 37u32);
        let z: Vec<f32> = (0..w * h)
            .map(|i| if i % 7 == 0 { f32::NAN } else { i as f32 * 0.5 })
            .collect();
        let levels = cog_levels_f32(&z, w, h, 16, Some(f32::NAN));
        let sizes: Vec<_> = levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(45, 37), (22, 18), (11, 9)]);
        let georef = Georef::local(1.0);
        let tags = GeoTags::of(&georef, "t").unwrap();
        let p = dir.path().join("big.tif");
        let mut out = std::io::BufWriter::new(std::fs::File::create(&p).unwrap());
        write_cog(&mut out, &levels, 16, f32::NAN, &tags, Some(f64::NAN), true).unwrap();
        drop(out);
        let bytes = std::fs::read(&p).unwrap();
        assert_eq!(&bytes[..4], b"II\x2b\x00", "BigTIFF");
        let mut dec = Decoder::new(std::fs::File::open(&p).unwrap()).unwrap();
        for (i, level) in levels.iter().enumerate() {
            if i > 0 {
                dec.next_image().unwrap();
            }
            assert_eq!(dec.dimensions().unwrap(), (level.width, level.height));
            let DecodingResult::F32(v) = dec.read_image().unwrap() else {
                panic!("level {i} is not float32");
            };
            let same = v
                .iter()
                .zip(level.samples.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same && v.len() == level.samples.len(), "level {i}");
        }
        assert!(!dec.more_images());
        let back = read_geotiff(&p).unwrap();
        let same = back
            .heights()
            .iter()
            .zip(&z)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same);
    }

    #[test]
    fn a_failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("no/such/dir/g.tif");
        let g = Grid::new("t", 2, 2, vec![1.0; 4], Georef::local(1.0)).unwrap();
        let e = write_grid(&p, &g).unwrap_err();
        assert!(e.to_string().contains("g.tif"), "{e}");
        let bad = write_geotiff(
            &dir.path().join("m.tif"),
            3,
            3,
            Samples::U8(&[0; 8]),
            &Georef::local(1.0),
            None,
        );
        assert!(bad.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
