//! Orthophotos as [`PhotoSource`]s: PNG and JPEG decoded whole ([`Orthophoto`], within the
//! `image` crate's decode limits), GeoTIFFs of any size read a band of rows at a time
//! ([`TiffPhoto`]), so that a 32k² satellite scene becomes a GST pyramid without ever being held
//! in memory, and GDAL VRTs and mosaics of several photos read the same way ([`VrtPhoto`],
//! over [`crate::dem::vrt`]).
//!
//! [`TiffPhoto`] decodes the stored chunks (strips or tiles) under the rows asked for and keeps
//! the last row of chunks, because the pyramid writer asks for overlapping bands top to bottom.
//! Bands are chosen as [`crate::gst::read_photo`] chooses them (`--bands 3,2,1`; by default 1, 2, 3, or
//! band 1 as grey), and samples wider than 8 bits are stretched linearly from each band's minimum
//! to its maximum over the photo's covered pixels, found in one pass over the file when it is
//! opened — the same 8-bit values `read_photo` makes from the whole image.
//!
//! **Coverage.** A pixel is transparent (alpha 0, colour 0) where the photo does not cover:
//! where its alpha band (TIFF `ExtraSamples` 1 or 2, as `gdalwarp -dstalpha` writes it; a VRT's
//! `ColorInterp` Alpha band) is 0, or where every chosen band equals its no-data value (GDAL's
//! `GDAL_NODATA` tag, or a VRT band's `NoDataValue`: "0" on an RGB photo marks black fill, not
//! every black pixel, as `gdalwarp` reads it), or where no source of a VRT or mosaic lies. Every
//! other pixel is opaque (an alpha between 1 and 255 counts as covered, as GDAL's VRTs count it).
//! The pyramid writer draws the shaded relief under transparent texels in a database
//! ([`crate::gst::Drawn`]).
//!
//! **Several photos** ([`open_photos`]): tiles are mosaicked as `gdalbuildvrt` mosaics them, the
//! later file winning where they overlap and a tile's no-data and transparent pixels letting the
//! one below show ([`crate::dem::vrt::Vrt::mosaic`]; a photo in another coordinate system is
//! reprojected into the mosaic). The mosaic reads each tile's rows only when the rows asked for
//! reach it and closes it when they have passed it.

use crate::dem::Georef;
use crate::dem::geotiff::{ChunkRows, RasterReader};
use crate::dem::vrt::{DataType, Vrt, VrtReader};
use crate::error::TerrainError;
use crate::gst::{Orthophoto, PhotoSource, read_photo};
use image::{Rgba, RgbaImage};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The per-chunk decode limit of photo reading (bytes).
const CHUNK_LIMIT: usize = 1 << 28;
/// Rows read at a time by the pass that finds a wide photo's ranges.
const PASS_ROWS: u32 = 256;

/// The bands to read for red, green and blue (0-based) from a 1-based choice.
pub(crate) fn pick_bands(
    bands: Option<[u16; 3]>,
    band_count: u16,
) -> Result<[u16; 3], TerrainError> {
    match bands {
        Some(b) => {
            if b.contains(&0) {
                return Err(TerrainError::BadParameter {
                    name: "bands",
                    value: format!("{b:?}"),
                    expected: "1-based band numbers",
                });
            }
            Ok(b.map(|x| x - 1))
        }
        None if band_count >= 3 => Ok([0, 1, 2]),
        None => Ok([0, 0, 0]),
    }
}

/// How raw samples of three chosen bands (and an alpha band) become 8-bit RGBA (see the module
/// docs).
#[derive(Clone, Copy, Debug)]
struct Rgba8 {
    /// Per channel: `(lowest, 255 / (highest − lowest))`, or `(0, 1)` for 8-bit bands.
    scale: [(f32, f32); 3],
    /// Per channel, its band's no-data value.
    nodata: [Option<f32>; 3],
}

impl Rgba8 {
    fn new(nodata: [Option<f64>; 3]) -> Rgba8 {
        Rgba8 {
            scale: [(0.0, 1.0); 3],
            nodata: nodata.map(|v| v.map(|v| v as f32)),
        }
    }

    /// Whether the pixel is not the photo's: no source (NaN), alpha 0, or all three channels
    /// no-data.
    fn hidden(&self, rgb: [f32; 3], alpha: Option<f32>) -> bool {
        rgb.iter().all(|v| v.is_nan())
            || alpha.is_some_and(|a| a.is_nan() || a == 0.0)
            || (0..3).all(|k| self.nodata[k].is_some_and(|nd| rgb[k] == nd))
    }

    fn pixel(&self, rgb: [f32; 3], alpha: Option<f32>) -> Rgba<u8> {
        if self.hidden(rgb, alpha) {
            return Rgba([0; 4]);
        }
        let c = |k: usize| {
            let (lo, s) = self.scale[k];
            let v = if rgb[k].is_nan() { lo } else { rgb[k] };
            ((v - lo) * s).round().clamp(0.0, 255.0) as u8
        };
        Rgba([c(0), c(1), c(2), 255])
    }

    /// Stretch each channel from the lowest to the highest of `ranges` (see [`Ranges`]).
    fn stretch(&mut self, ranges: &Ranges) {
        for k in 0..3 {
            let (lo, hi) = ranges.0[k];
            self.scale[k] = if hi > lo {
                (lo, 255.0 / (hi - lo))
            } else {
                (if lo.is_finite() { lo } else { 0.0 }, 0.0)
            };
        }
    }
}

/// Each channel's lowest and highest sample over the covered pixels seen.
struct Ranges([(f32, f32); 3]);

impl Ranges {
    fn new() -> Ranges {
        Ranges([(f32::INFINITY, f32::NEG_INFINITY); 3])
    }

    /// The pixels of `planes` (three colour planes, then an alpha plane if `alpha`) that
    /// `convert` does not hide.
    fn add(&mut self, planes: &[Vec<f32>], alpha: bool, convert: &Rgba8) {
        for i in 0..planes[0].len() {
            let (rgb, a) = sample(planes, alpha, i);
            if convert.hidden(rgb, a) {
                continue;
            }
            for (r, v) in self.0.iter_mut().zip(rgb) {
                if !v.is_nan() {
                    *r = (r.0.min(v), r.1.max(v));
                }
            }
        }
    }
}

/// The pixel `i` of `planes` (three colour planes, then an alpha plane if `alpha`).
fn sample(planes: &[Vec<f32>], alpha: bool, i: usize) -> ([f32; 3], Option<f32>) {
    (
        [planes[0][i], planes[1][i], planes[2][i]],
        alpha.then(|| planes[3][i]),
    )
}

/// What a photo read by rows knows of itself besides its rows.
struct Head {
    source: String,
    width: u32,
    height: u32,
    georef: Option<Georef>,
    convert: Rgba8,
    /// Its reader also reads an alpha band (the fourth plane).
    alpha: bool,
}

/// A GeoTIFF orthophoto read by rows (see the module docs).
pub struct TiffPhoto {
    head: Head,
    rows: Mutex<ChunkRows<RgbaImage>>,
}

impl TiffPhoto {
    /// Open a TIFF photo: header, georeference, band choice, and (for samples wider than
    /// 8 bits) one pass for each band's range.
    pub fn open(path: &Path, bands: Option<[u16; 3]>) -> Result<TiffPhoto, TerrainError> {
        let band_count = crate::dem::geotiff::band_count(path)?;
        let pick = pick_bands(bands, band_count)?;
        let head = RasterReader::open(path, Some(&pick), CHUNK_LIMIT)?;
        let alpha = head.alpha.filter(|a| !pick.contains(a));
        let mut reader = match alpha {
            Some(a) => {
                RasterReader::open(path, Some(&[pick[0], pick[1], pick[2], a]), CHUNK_LIMIT)?
            }
            None => head,
        };
        let mut convert = Rgba8::new([reader.nodata; 3]);
        if reader.bits > 8 {
            let mut ranges = Ranges::new();
            for c in 0..reader.chunk_count() {
                ranges.add(&reader.read_chunk(c)?.planes, alpha.is_some(), &convert);
            }
            convert.stretch(&ranges);
        }
        Ok(TiffPhoto {
            head: Head {
                source: path.display().to_string(),
                width: reader.width,
                height: reader.height,
                georef: reader.georef,
                convert,
                alpha: alpha.is_some(),
            },
            rows: Mutex::new(ChunkRows::new(reader)),
        })
    }

    /// Chunk row `cr` as full-width 8-bit RGBA rows.
    fn decode_row(&self, reader: &mut RasterReader, cr: u32) -> Result<RgbaImage, TerrainError> {
        let ch = reader.chunk_rows();
        let y0 = cr * ch;
        let h = &self.head;
        let y1 = (y0 + ch).min(h.height);
        let mut img = RgbaImage::new(h.width, y1 - y0);
        reader.read_chunk_row(cr, |c| {
            for row in 0..c.height {
                for col in 0..c.width {
                    let (rgb, a) = sample(&c.planes, h.alpha, (row * c.width + col) as usize);
                    img.put_pixel(c.x0 + col, c.y0 - y0 + row, h.convert.pixel(rgb, a));
                }
            }
        })?;
        Ok(img)
    }
}

impl PhotoSource for TiffPhoto {
    fn size(&self) -> (u32, u32) {
        (self.head.width, self.head.height)
    }
    fn georef(&self) -> Option<Georef> {
        self.head.georef
    }
    fn source(&self) -> &str {
        &self.head.source
    }

    fn rows(&self, y0: u32, y1: u32) -> Result<RgbaImage, TerrainError> {
        let width = self.head.width;
        let y1 = y1.min(self.head.height);
        let mut out = RgbaImage::new(width, y1.saturating_sub(y0));
        if y1 <= y0 {
            return Ok(out);
        }
        let mut rows = self.rows.lock().unwrap_or_else(|e| e.into_inner());
        rows.visit(
            y0,
            y1,
            |reader, cr| self.decode_row(reader, cr),
            |img, top| {
                let (a, b) = (y0.max(top), y1.min(top + img.height()));
                for y in a..b {
                    for x in 0..width {
                        out.put_pixel(x, y - y0, *img.get_pixel(x, y - top));
                    }
                }
            },
        )?;
        Ok(out)
    }
}

/// A GDAL VRT, or a mosaic of several photos, read by rows as an orthophoto (see the module
/// docs and [`crate::dem::vrt`]).
pub struct VrtPhoto {
    head: Head,
    reader: Mutex<VrtReader>,
}

impl VrtPhoto {
    /// Open a `.vrt` as a photo, its bands chosen as a TIFF's are (`bands`, 1-based; by default
    /// 1, 2, 3, or band 1 as grey); a band with `ColorInterp` Alpha is its alpha.
    pub fn open(path: &Path, bands: Option<[u16; 3]>) -> Result<VrtPhoto, TerrainError> {
        VrtPhoto::new(Vrt::open(path, crate::dem::vrt::Use::Photo)?, bands)
    }

    /// The mosaic of several photos, as `gdalbuildvrt` would make it ([`Vrt::mosaic`]): each
    /// photo's `bands`.
    pub fn mosaic(paths: &[PathBuf], bands: Option<[u16; 3]>) -> Result<VrtPhoto, TerrainError> {
        VrtPhoto::new(Vrt::mosaic(paths, bands)?, None)
    }

    fn new(vrt: Vrt, bands: Option<[u16; 3]>) -> Result<VrtPhoto, TerrainError> {
        let n = vrt.bands.len();
        let pick = pick_bands(bands, n.min(u16::MAX as usize) as u16)?.map(|b| b as usize);
        if let Some(&b) = pick.iter().find(|&&b| b >= n) {
            return Err(TerrainError::Unsupported {
                source: vrt.source.clone(),
                what: format!("band {}: the VRT has {n} band(s)", b + 1),
            });
        }
        let alpha = vrt
            .bands
            .iter()
            .position(|b| b.alpha)
            .filter(|a| !pick.contains(a));
        let mut want = pick.to_vec();
        want.extend(alpha);
        let mut convert = Rgba8::new(pick.map(|b| vrt.bands[b].nodata));
        let wide = pick
            .iter()
            .any(|&b| vrt.bands[b].data_type != DataType::Byte);
        let (source, width, height, georef) =
            (vrt.source.clone(), vrt.width, vrt.height, vrt.georef);
        let mut reader = VrtReader::new(vrt, want);
        if wide {
            let mut ranges = Ranges::new();
            for y in (0..height).step_by(PASS_ROWS as usize) {
                let planes = reader.rows(y, (y + PASS_ROWS).min(height))?;
                ranges.add(&planes, alpha.is_some(), &convert);
            }
            convert.stretch(&ranges);
        }
        Ok(VrtPhoto {
            head: Head {
                source,
                width,
                height,
                georef,
                convert,
                alpha: alpha.is_some(),
            },
            reader: Mutex::new(reader),
        })
    }
}

impl PhotoSource for VrtPhoto {
    fn size(&self) -> (u32, u32) {
        (self.head.width, self.head.height)
    }
    fn georef(&self) -> Option<Georef> {
        self.head.georef
    }
    fn source(&self) -> &str {
        &self.head.source
    }

    fn rows(&self, y0: u32, y1: u32) -> Result<RgbaImage, TerrainError> {
        let h = &self.head;
        let y1 = y1.min(h.height);
        let n = y1.saturating_sub(y0);
        let planes = self
            .reader
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .rows(y0, y1)?;
        Ok(RgbaImage::from_fn(h.width, n, |x, y| {
            let (rgb, a) = sample(&planes, h.alpha, (y * h.width + x) as usize);
            h.convert.pixel(rgb, a)
        }))
    }
}

/// Whether `path` names a TIFF (by its extension, `.tif` or `.tiff`, any case).
pub(crate) fn is_tiff(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tif") || e.eq_ignore_ascii_case("tiff"))
}

/// Open an orthophoto for a pyramid build: a TIFF or a VRT by rows ([`TiffPhoto`],
/// [`VrtPhoto`]), a PNG or JPEG whole.
pub fn open_photo(
    path: &Path,
    bands: Option<[u16; 3]>,
) -> Result<Box<dyn PhotoSource>, TerrainError> {
    if is_tiff(path) {
        Ok(Box::new(TiffPhoto::open(path, bands)?))
    } else if crate::dem::vrt::is_vrt(path) {
        Ok(Box::new(VrtPhoto::open(path, bands)?))
    } else {
        let p: Orthophoto = read_photo(path, bands)?;
        Ok(Box::new(p))
    }
}

/// Open one photo ([`open_photo`]) or the mosaic of several ([`VrtPhoto::mosaic`], later files
/// winning); a directory stands for the GeoTIFFs and VRTs in it, in the order of their names.
pub fn open_photos(
    paths: &[PathBuf],
    bands: Option<[u16; 3]>,
) -> Result<Box<dyn PhotoSource>, TerrainError> {
    let mut files = Vec::with_capacity(paths.len());
    for p in paths {
        if p.is_dir() {
            let mut inside: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(crate::error::io(p))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| {
                    f.is_file()
                        && (is_tiff(f)
                            || f.extension()
                                .and_then(|e| e.to_str())
                                .is_some_and(|e| e.eq_ignore_ascii_case("vrt")))
                })
                .collect();
            if inside.is_empty() {
                return Err(TerrainError::Unsupported {
                    source: p.display().to_string(),
                    what: "a directory of photos without a GeoTIFF (.tif, .tiff) or VRT in it"
                        .into(),
                });
            }
            inside.sort();
            files.extend(inside);
        } else {
            files.push(p.clone());
        }
    }
    match &files[..] {
        [] => Err(TerrainError::BadParameter {
            name: "photos",
            value: "none".into(),
            expected: "at least one photo",
        }),
        [one] => open_photo(one, bands),
        _ => Ok(Box::new(VrtPhoto::mosaic(&files, bands)?)),
    }
}
