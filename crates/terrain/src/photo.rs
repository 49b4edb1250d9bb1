//! Orthophotos as [`PhotoSource`]s: PNG and JPEG decoded whole ([`Orthophoto`], within the
//! `image` crate's decode limits), GeoTIFFs of any size read a band of rows at a time
//! ([`TiffPhoto`]), so that a 32k² satellite scene becomes a GST pyramid without ever being held
//! in memory, and GDAL VRTs and mosaics of several photos read the same way ([`VrtPhoto`],
//! over [`crate::dem::vrt`]).
//!
//! [`TiffPhoto`] decodes the stored chunks (strips or tiles) under the rows asked for and keeps
//! the last row of chunks, because the pyramid writer asks for overlapping bands top to bottom.
//! Bands are chosen as [`crate::gst::read_photo`] chooses them (`--bands 3,2,1`; by default 1, 2, 3, or
//! band 1 as grey) — the same 8-bit values `read_photo` makes from the whole image.
//!
//! **Colours** ([`PhotoOptions`], `--stretch`, `--gamma`). 8-bit bands are taken as they are;
//! samples wider than 8 bits are mapped linearly from each band's lowest to its highest sample
//! over the photo's covered pixels ([`Stretch::Auto`]), found in one pass over the file when it
//! is opened. A 16-bit satellite scene (Sentinel-2 and Landsat reflectance) has clouds, glints
//! and snow far brighter than its land, which that leaves dark, so a [`Stretch::Percent`] maps
//! each band's low and high percentiles instead (QGIS's "cumulative count cut", 2–98 % there),
//! from a histogram per band: one bin per value, counted in the same pass as the ranges, while
//! every sample is a whole number from −32768 to 65535 (8- and 16-bit integer bands); else a
//! second pass counts them, exact for whole-number samples spanning fewer than 65,536 values,
//! else in 65,536 bins over the band's range with each percentile taken at its bin's centre
//! (within half a bin). The percentiles are
//! ranks in the sorted covered samples, rounded down at the low end and up at the high one —
//! numpy's `percentile(method="lower")` and `"higher"`. [`Stretch::Range`] gives the ranges
//! (`gdal_translate -scale`), and a gamma follows the stretch (`t^(1/γ)`, `gdal_translate
//! -exponent 1/γ`). The ranges used are reported ([`Applied`], kept in a database's manifest),
//! so that a neighbouring database built with them as a `Range` gets the same colours; a
//! percentile stretch of each alone would not. A mosaic is stretched as one photo.
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

/// How a photo's samples become 8-bit colours (`--stretch`; see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stretch {
    /// 8-bit bands as they are, wider samples from each band's lowest to its highest.
    Auto,
    /// Every band, 8-bit ones too, from its lowest to its highest sample.
    MinMax,
    /// Each band from its `lo`-th to its `hi`-th percentile (QGIS's "cumulative count cut", 2
    /// and 98 by default there): numpy's `percentile(method="lower")` and `"higher"` of the
    /// covered samples.
    Percent(f64, f64),
    /// Each band from a given sample value to another (`gdal_translate -scale_N`).
    Range([(f64, f64); 3]),
}

impl std::str::FromStr for Stretch {
    type Err = String;

    /// `auto`, `minmax`, `percent:LO,HI` (e.g. `percent:2,98`), `range:MIN,MAX` for every band
    /// or `range:R0,R1,G0,G1,B0,B1`.
    fn from_str(s: &str) -> Result<Stretch, String> {
        let (kind, args) = s.split_once(':').unwrap_or((s, ""));
        let numbers = || -> Result<Vec<f64>, String> {
            args.split(',')
                .map(|t| {
                    t.trim()
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| format!("'{}' is not a number", t.trim()))
                })
                .collect()
        };
        let expected = "auto, minmax, percent:LO,HI (e.g. percent:2,98) or range:MIN,MAX \
                        (or range:R0,R1,G0,G1,B0,B1)";
        match (kind.trim(), args.is_empty()) {
            ("auto", true) => Ok(Stretch::Auto),
            ("minmax", true) => Ok(Stretch::MinMax),
            ("percent", false) => match numbers()?[..] {
                [lo, hi] if (0.0..hi).contains(&lo) && hi <= 100.0 => Ok(Stretch::Percent(lo, hi)),
                _ => Err(format!(
                    "{s}: expected two percentiles 0 ≤ LO < HI ≤ 100, e.g. percent:2,98"
                )),
            },
            ("range", false) => {
                let v = numbers()?;
                let pairs: [(f64, f64); 3] = match v[..] {
                    [a, b] => [(a, b); 3],
                    [a, b, c, d, e, f] => [(a, b), (c, d), (e, f)],
                    _ => {
                        return Err(format!(
                            "{s}: expected MIN,MAX or six numbers, one pair per band"
                        ));
                    }
                };
                if pairs.iter().any(|(a, b)| a >= b) {
                    return Err(format!("{s}: each MIN must be below its MAX"));
                }
                Ok(Stretch::Range(pairs))
            }
            _ => Err(format!("{s}: expected {expected}")),
        }
    }
}

/// How to read a photo: the bands for red, green and blue, and how their samples become 8-bit
/// colours (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotoOptions {
    /// 1-based band numbers for red, green and blue; by default 1, 2, 3, or band 1 as grey.
    pub bands: Option<[u16; 3]>,
    pub stretch: Stretch,
    /// After the stretch, `t ↦ t^(1/gamma)` on `t ∈ [0, 1]` (`gdal_translate -exponent
    /// 1/gamma`): above 1 brightens the shadows, as QGIS's gamma does.
    pub gamma: f64,
}

impl Default for PhotoOptions {
    fn default() -> PhotoOptions {
        PhotoOptions {
            bands: None,
            stretch: Stretch::Auto,
            gamma: 1.0,
        }
    }
}

impl PhotoOptions {
    /// The default colours with `bands` chosen.
    pub fn bands(bands: Option<[u16; 3]>) -> PhotoOptions {
        PhotoOptions {
            bands,
            ..PhotoOptions::default()
        }
    }

    /// Whether samples of `bits` bits are mapped (else taken as they are, 8-bit).
    fn maps(&self, bits: u32) -> bool {
        bits > 8 || self.stretch != Stretch::Auto || self.gamma != 1.0
    }

    fn check(&self, source: &str) -> Result<(), TerrainError> {
        if !(self.gamma.is_finite() && self.gamma > 0.0) {
            return Err(TerrainError::Unsupported {
                source: source.into(),
                what: format!("photo gamma {}: expected a number above 0", self.gamma),
            });
        }
        Ok(())
    }
}

/// The stretch a photo's colours were made with: each channel's sample values mapped to 0 and
/// 255, the rule that chose them, and the gamma.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Applied {
    /// `minmax`, `percent:LO,HI` or `range`.
    pub rule: String,
    /// Per channel (red, green, blue), the samples mapped to 0 and to 255.
    pub ranges: [[f64; 2]; 3],
    pub gamma: f64,
}

/// How raw samples of three chosen bands (and an alpha band) become 8-bit RGBA (see the module
/// docs).
#[derive(Clone, Copy, Debug)]
struct Rgba8 {
    /// Per channel: `(lowest, 255 / (highest − lowest))`, or `(0, 1)` for 8-bit bands.
    scale: [(f32, f32); 3],
    /// Per channel, its band's no-data value.
    nodata: [Option<f32>; 3],
    /// `1 / gamma`, when the gamma is not 1.
    exponent: Option<f32>,
}

impl Rgba8 {
    fn new(nodata: [Option<f64>; 3]) -> Rgba8 {
        Rgba8 {
            scale: [(0.0, 1.0); 3],
            nodata: nodata.map(|v| v.map(|v| v as f32)),
            exponent: None,
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
            let v = match self.exponent {
                None => (v - lo) * s,
                Some(e) => ((v - lo) * s / 255.0).clamp(0.0, 1.0).powf(e) * 255.0,
            };
            v.round().clamp(0.0, 255.0) as u8
        };
        Rgba([c(0), c(1), c(2), 255])
    }

    /// Map each channel's `ranges` (lowest, highest) to 0 and 255, then apply `gamma`.
    fn stretch(&mut self, ranges: [(f64, f64); 3], gamma: f64) {
        for (k, (lo, hi)) in ranges.into_iter().enumerate() {
            self.scale[k] = if hi > lo {
                (lo as f32, (255.0 / (hi - lo)) as f32)
            } else {
                (if lo.is_finite() { lo as f32 } else { 0.0 }, 0.0)
            };
        }
        self.exponent = (gamma != 1.0).then_some((1.0 / gamma) as f32);
    }
}

/// Each channel's lowest and highest sample over the covered pixels seen, and whether they
/// were all whole numbers.
struct Ranges {
    bounds: [(f32, f32); 3],
    integral: [bool; 3],
    /// Per channel, a count of each whole value seen, kept while every sample is one from
    /// [`DIRECT_LOW`] to [`DIRECT_HIGH`] (8- and 16-bit integer bands always are): the
    /// percentiles' histogram made in the same pass, so that they need no second one.
    direct: Option<[Direct; 3]>,
}

/// The lowest and highest sample [`Ranges::direct`] counts: Int16's and UInt16's.
const DIRECT_LOW: i32 = -32768;
const DIRECT_HIGH: i32 = 65535;

/// Counts of whole values from `lo`, grown as values outside arrive (by at least its length, so
/// that growing costs O(1) a sample on average; at most 98,304 bins).
#[derive(Default)]
struct Direct {
    lo: i32,
    counts: Vec<u64>,
}

impl Direct {
    fn add(&mut self, v: i32) {
        let len = self.counts.len() as i32;
        if len == 0 {
            self.lo = v;
            self.counts.push(0);
        } else if v < self.lo || v >= self.lo + len {
            let lo = if v < self.lo {
                (v - len).max(DIRECT_LOW)
            } else {
                self.lo
            };
            let hi = if v >= self.lo + len {
                (v + len).min(DIRECT_HIGH)
            } else {
                self.lo + len - 1
            };
            let mut grown = vec![0; (hi - lo + 1) as usize];
            grown[(self.lo - lo) as usize..][..len as usize].copy_from_slice(&self.counts);
            (self.lo, self.counts) = (lo, grown);
        }
        self.counts[(v - self.lo) as usize] += 1;
    }
}

impl Ranges {
    /// Ranges, counting whole values too when `direct` (for percentiles).
    fn new(direct: bool) -> Ranges {
        Ranges {
            bounds: [(f32::INFINITY, f32::NEG_INFINITY); 3],
            integral: [true; 3],
            direct: direct.then(Default::default),
        }
    }

    /// The pixels of `planes` (three colour planes, then an alpha plane if `alpha`) that
    /// `convert` does not hide.
    fn add(&mut self, planes: &[Vec<f32>], alpha: bool, convert: &Rgba8) {
        covered(planes, alpha, convert, |k, v| {
            let r = &mut self.bounds[k];
            *r = (r.0.min(v), r.1.max(v));
            let whole = v.fract() == 0.0;
            self.integral[k] &= whole;
            if let Some(d) = &mut self.direct {
                if whole && (DIRECT_LOW as f32..=DIRECT_HIGH as f32).contains(&v) {
                    d[k].add(v as i32);
                } else {
                    self.direct = None;
                }
            }
        });
    }

    fn f64(&self) -> [(f64, f64); 3] {
        self.bounds.map(|(lo, hi)| (lo as f64, hi as f64))
    }
}

/// Each sample (channel `k`, value) of the pixels of `planes` (three colour planes, then an
/// alpha plane if `alpha`) that `convert` does not hide, NaN samples left out.
fn covered(planes: &[Vec<f32>], alpha: bool, convert: &Rgba8, mut f: impl FnMut(usize, f32)) {
    for i in 0..planes[0].len() {
        let (rgb, a) = sample(planes, alpha, i);
        if convert.hidden(rgb, a) {
            continue;
        }
        for (k, v) in rgb.into_iter().enumerate() {
            if !v.is_nan() {
                f(k, v);
            }
        }
    }
}

/// Bins of a histogram over one channel's range: exact (one per value) for whole-number samples
/// spanning fewer than this many values, else this many over the range.
const HISTOGRAM_BINS: usize = 1 << 16;

/// Per-channel histograms of the covered samples, for percentiles (see [`Stretch::Percent`]).
struct Histograms {
    lo: [f64; 3],
    /// Per channel, whether each bin is one sample value.
    exact: [bool; 3],
    /// Bin width per channel: 1 when exact.
    width: [f64; 3],
    counts: [Vec<u64>; 3],
}

impl Histograms {
    /// The exact histograms [`Ranges::direct`] counted.
    fn direct(d: [Direct; 3]) -> Histograms {
        Histograms {
            lo: std::array::from_fn(|k| d[k].lo as f64),
            exact: [true; 3],
            width: [1.0; 3],
            counts: d.map(|d| d.counts),
        }
    }

    fn new(r: &Ranges) -> Histograms {
        let mut lo = [0.0; 3];
        let mut width = [1.0; 3];
        let mut exact = [true; 3];
        let counts = std::array::from_fn(|k| {
            let (a, b) = r.bounds[k];
            if b.partial_cmp(&a).is_none_or(|o| o.is_lt()) {
                return Vec::new();
            }
            lo[k] = a as f64;
            let span = b as f64 - a as f64;
            if r.integral[k] && span < HISTOGRAM_BINS as f64 {
                vec![0; span as usize + 1]
            } else {
                width[k] = span / HISTOGRAM_BINS as f64;
                exact[k] = false;
                vec![0; HISTOGRAM_BINS]
            }
        });
        Histograms {
            lo,
            exact,
            width,
            counts,
        }
    }

    fn add(&mut self, planes: &[Vec<f32>], alpha: bool, convert: &Rgba8) {
        covered(planes, alpha, convert, |k, v| {
            let n = self.counts[k].len();
            if n > 0 {
                let b = ((v as f64 - self.lo[k]) / self.width[k]).floor();
                self.counts[k][(b.max(0.0) as usize).min(n - 1)] += 1;
            }
        });
    }

    /// Channel `k`'s `p`-th percentile, rounded down (`higher`: up) to a sample's rank as
    /// numpy's `method="lower"` (`"higher"`) does; an inexact bin stands for its centre.
    fn percentile(&self, k: usize, p: f64, higher: bool) -> f64 {
        let counts = &self.counts[k];
        let n: u64 = counts.iter().sum();
        if n == 0 {
            return 0.0;
        }
        let at = (p / 100.0) * (n - 1) as f64;
        let rank = if higher { at.ceil() } else { at.floor() } as u64;
        let mut seen = 0;
        for (b, &c) in counts.iter().enumerate() {
            seen += c;
            if seen > rank {
                let centre = if self.exact[k] { 0.0 } else { 0.5 };
                return self.lo[k] + self.width[k] * (b as f64 + centre);
            }
        }
        self.lo[k] + self.width[k] * counts.len() as f64
    }
}

/// The conversion of a photo's samples to 8-bit RGBA by `opts`, for samples of `bits` bits with
/// the bands' `nodata` and an alpha plane if `alpha`: `pass` hands every chunk of the photo's
/// planes to its argument, once per call (never for 8-bit photos with the default colours; once
/// for a min-max stretch, twice for percentiles, whose histograms need the ranges).
fn fit(
    opts: &PhotoOptions,
    nodata: [Option<f64>; 3],
    bits: u32,
    alpha: bool,
    mut pass: impl FnMut(&mut dyn FnMut(&[Vec<f32>])) -> Result<(), TerrainError>,
) -> Result<(Rgba8, Option<Applied>), TerrainError> {
    let mut convert = Rgba8::new(nodata);
    if !opts.maps(bits) {
        return Ok((convert, None));
    }
    let (fixed, percent) = match opts.stretch {
        Stretch::Range(r) => (Some(r), None),
        Stretch::Auto if bits <= 8 => (Some([(0.0, 255.0); 3]), None),
        Stretch::Auto | Stretch::MinMax => (None, None),
        Stretch::Percent(lo, hi) => (None, Some((lo, hi))),
    };
    let (rule, bounds) = match fixed {
        Some(r) => ("range".to_string(), r),
        None => {
            let mut r = Ranges::new(percent.is_some());
            pass(&mut |p| r.add(p, alpha, &convert))?;
            match percent {
                None => ("minmax".to_string(), r.f64()),
                Some((lo, hi)) => {
                    let h = match r.direct.take() {
                        Some(counts) => Histograms::direct(counts),
                        None => {
                            let mut h = Histograms::new(&r);
                            pass(&mut |p| h.add(p, alpha, &convert))?;
                            h
                        }
                    };
                    let at = |k| (h.percentile(k, lo, false), h.percentile(k, hi, true));
                    (format!("percent:{lo},{hi}"), std::array::from_fn(at))
                }
            }
        }
    };
    convert.stretch(bounds, opts.gamma);
    let applied = Applied {
        rule,
        ranges: bounds.map(|(a, b)| if b >= a { [a, b] } else { [0.0, 0.0] }),
        gamma: opts.gamma,
    };
    Ok((convert, Some(applied)))
}

/// The pixel `i` of `planes` (three colour planes, then an alpha plane if `alpha`).
fn sample(planes: &[Vec<f32>], alpha: bool, i: usize) -> ([f32; 3], Option<f32>) {
    (
        [planes[0][i], planes[1][i], planes[2][i]],
        alpha.then(|| planes[3][i]),
    )
}

/// The [`PhotoSource`] methods a photo answers from its [`Head`] (`self.head`).
macro_rules! head_getters {
    () => {
        fn size(&self) -> (u32, u32) {
            (self.head.width, self.head.height)
        }
        fn georef(&self) -> Option<Georef> {
            self.head.georef
        }
        fn source(&self) -> &str {
            &self.head.source
        }
        fn stretch(&self) -> Option<Applied> {
            self.head.applied.clone()
        }
    };
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
    /// The stretch its colours were made with, when they were mapped.
    applied: Option<Applied>,
}

/// A GeoTIFF orthophoto read by rows (see the module docs).
pub struct TiffPhoto {
    head: Head,
    rows: Mutex<ChunkRows<RgbaImage>>,
}

impl TiffPhoto {
    /// Open a TIFF photo: header, georeference, band choice, and (for samples wider than
    /// 8 bits, or another stretch than `auto`) one pass for each band's range, and another for
    /// percentiles.
    pub fn open(path: &Path, opts: &PhotoOptions) -> Result<TiffPhoto, TerrainError> {
        opts.check(&path.display().to_string())?;
        let band_count = crate::dem::geotiff::band_count(path)?;
        let pick = pick_bands(opts.bands, band_count)?;
        let head = RasterReader::open(path, Some(&pick), CHUNK_LIMIT)?;
        let alpha = head.alpha.filter(|a| !pick.contains(a));
        let mut reader = match alpha {
            Some(a) => {
                RasterReader::open(path, Some(&[pick[0], pick[1], pick[2], a]), CHUNK_LIMIT)?
            }
            None => head,
        };
        let (convert, applied) = fit(
            opts,
            [reader.nodata; 3],
            reader.bits as u32,
            alpha.is_some(),
            |f| {
                for c in 0..reader.chunk_count() {
                    f(&reader.read_chunk(c)?.planes);
                }
                Ok(())
            },
        )?;
        Ok(TiffPhoto {
            head: Head {
                source: path.display().to_string(),
                width: reader.width,
                height: reader.height,
                georef: reader.georef,
                convert,
                alpha: alpha.is_some(),
                applied,
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
    head_getters!();

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
    pub fn open(path: &Path, opts: &PhotoOptions) -> Result<VrtPhoto, TerrainError> {
        opts.check(&path.display().to_string())?;
        VrtPhoto::new(Vrt::open(path, crate::dem::vrt::Use::Photo)?, opts)
    }

    /// The mosaic of several photos, as `gdalbuildvrt` would make it ([`Vrt::mosaic`]): each
    /// photo's `opts.bands`, the mosaic's colours stretched as one photo's.
    pub fn mosaic(paths: &[PathBuf], opts: &PhotoOptions) -> Result<VrtPhoto, TerrainError> {
        opts.check(&format!("{} photos", paths.len()))?;
        let vrt = Vrt::mosaic(paths, opts.bands)?;
        VrtPhoto::new(
            vrt,
            &PhotoOptions {
                bands: None,
                ..*opts
            },
        )
    }

    fn new(vrt: Vrt, opts: &PhotoOptions) -> Result<VrtPhoto, TerrainError> {
        let n = vrt.bands.len();
        let pick = pick_bands(opts.bands, n.min(u16::MAX as usize) as u16)?.map(|b| b as usize);
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
        let nodata = pick.map(|b| vrt.bands[b].nodata);
        let wide = pick
            .iter()
            .any(|&b| vrt.bands[b].data_type != DataType::Byte);
        let (source, width, height, georef) =
            (vrt.source.clone(), vrt.width, vrt.height, vrt.georef);
        let mut reader = VrtReader::new(vrt, want);
        let bits = if wide { 16 } else { 8 };
        let (convert, applied) = fit(opts, nodata, bits, alpha.is_some(), |f| {
            for y in (0..height).step_by(PASS_ROWS as usize) {
                f(&reader.rows(y, (y + PASS_ROWS).min(height))?);
            }
            Ok(())
        })?;
        Ok(VrtPhoto {
            head: Head {
                source,
                width,
                height,
                georef,
                convert,
                alpha: alpha.is_some(),
                applied,
            },
            reader: Mutex::new(reader),
        })
    }
}

impl PhotoSource for VrtPhoto {
    head_getters!();

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
pub fn open_photo(path: &Path, opts: &PhotoOptions) -> Result<Box<dyn PhotoSource>, TerrainError> {
    if is_tiff(path) {
        Ok(Box::new(TiffPhoto::open(path, opts)?))
    } else if crate::dem::vrt::is_vrt(path) {
        Ok(Box::new(VrtPhoto::open(path, opts)?))
    } else {
        let p: Orthophoto = read_photo(path, opts)?;
        Ok(Box::new(p))
    }
}

/// Open one photo ([`open_photo`]) or the mosaic of several ([`VrtPhoto::mosaic`], later files
/// winning); a directory stands for the GeoTIFFs and VRTs in it, in the order of their names.
pub fn open_photos(
    paths: &[PathBuf],
    opts: &PhotoOptions,
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
        [one] => open_photo(one, opts),
        _ => Ok(Box::new(VrtPhoto::mosaic(&files, opts)?)),
    }
}

/// A PNG's or JPEG's decoded pixels as 8-bit RGBA by `opts` (bands are not chosen: red, green
/// and blue are the image's, or its grey), and the stretch applied, if its colours were mapped.
pub(crate) fn decoded_to_rgba(
    img: image::DynamicImage,
    opts: &PhotoOptions,
    source: &str,
) -> Result<(RgbaImage, Option<Applied>), TerrainError> {
    opts.check(source)?;
    let bits = match img.color() {
        image::ColorType::Rgb32F | image::ColorType::Rgba32F => 32,
        c if c.bytes_per_pixel() / c.channel_count() >= 2 => 16,
        _ => 8,
    };
    if !opts.maps(bits) {
        return Ok((img.to_rgba8(), None));
    }
    let (w, h) = (img.width(), img.height());
    let has_alpha = img.color().has_alpha();
    let values: Vec<f32> = match bits {
        32 => img.to_rgba32f().into_raw(),
        16 => img
            .to_rgba16()
            .into_raw()
            .into_iter()
            .map(f32::from)
            .collect(),
        _ => img
            .to_rgba8()
            .into_raw()
            .into_iter()
            .map(f32::from)
            .collect(),
    };
    drop(img);
    let mut planes: Vec<Vec<f32>> = (0..4)
        .map(|_| Vec::with_capacity(values.len() / 4))
        .collect();
    for px in values.chunks_exact(4) {
        for (plane, &v) in planes.iter_mut().zip(px) {
            plane.push(v);
        }
    }
    let (convert, applied) = fit(opts, [None; 3], bits, has_alpha, |f| {
        f(&planes);
        Ok(())
    })?;
    let out = RgbaImage::from_fn(w, h, |x, y| {
        let (rgb, a) = sample(&planes, has_alpha, (y as usize) * w as usize + x as usize);
        convert.pixel(rgb, a)
    });
    Ok((out, applied))
}
