//! GeoTIFF rasters through the `tiff` crate, with the GeoTIFF tags interpreted here.
//!
//! Pixels are decoded one chunk (strip or tile) at a time with [`tiff::decoder::Decoder::read_chunk`]
//! and copied into the grid, so only one chunk's buffer is alive beside the result: a grid larger
//! than the crate's default 256 MiB whole-image decode limit loads, and the limit applies per chunk
//! ([`read_geotiff_limited`] lets a test shrink it). Sample types: 8/16/32/64-bit signed and
//! unsigned integers, 32- and 64-bit floats; compression (LZW, Deflate, PackBits, ZSTD, WebP,
//! JPEG, the last in YCbCr as GDAL writes photo COGs), predictors 2 and 3 and BigTIFF are the
//! `tiff` crate's (LERC is not). Interleaved (`PlanarConfiguration` 1) and planar (2) layouts.
//!
//! Georeference (GeoTIFF 1.1, OGC 19-008):
//! - `ModelPixelScale` (33550) `(Sx, Sy, Sz)` with `ModelTiepoint` (33922) `(I, J, K, X, Y, Z)`:
//!   raster point `(I, J)` is model point `(X, Y)`, so raster `(i, j)` is `(X + (i − I)·Sx, Y − (j − J)·Sy)`.
//! - or `ModelTransformation` (34264), a row-major 4x4 matrix; rotation or shear terms are refused.
//! - GeoKey directory (34735): `GTModelTypeGeoKey` (1024: 1 projected, 2 geographic),
//!   `GTRasterTypeGeoKey` (1025: 1 `RasterPixelIsArea`, the default; 2 `RasterPixelIsPoint`),
//!   `ProjectedCSTypeGeoKey` (3072) / `GeographicTypeGeoKey` (2048) for the EPSG code.
//! - The raster-space position of the centre of pixel `(c, r)` is `(c + ½, r + ½)` for
//!   `PixelIsArea` (raster space counts pixel corners) and `(c, r)` for `PixelIsPoint` — the
//!   half-pixel shift users trip on; [`Georef`] stores centres, so it is applied once here.
//! - GDAL's no-data tag (42113, ASCII) marks no-data samples.

use super::{CrsKind, Georef, Grid, check_size};
use crate::error::{TerrainError, format_err, io};
use std::path::Path;
use tiff::decoder::{ChunkType, Decoder, DecodingResult, Limits};
use tiff::tags::{PlanarConfiguration, Tag};

/// A decoded GeoTIFF raster: `bands` planes of `width·height` samples as `f32`.
#[derive(Clone, Debug)]
pub struct Raster {
    pub width: u32,
    pub height: u32,
    /// One plane per band requested, row-major.
    pub bands: Vec<Vec<f32>>,
    /// Bits per sample as stored (8 for a byte photo, 16 for a 16-bit scene...).
    pub bits: u8,
    /// The georeference, if the file has one.
    pub georef: Option<Georef>,
    /// GDAL's no-data value, if present.
    pub nodata: Option<f64>,
    /// Bands in the file.
    pub band_count: u16,
}

/// Read a GeoTIFF elevation grid (band 1).
pub fn read_geotiff(path: &Path) -> Result<Grid, TerrainError> {
    read_geotiff_limited(path, Limits::default().decoding_buffer_size)
}

/// As [`read_geotiff`], with the per-chunk decode buffer limited to `chunk_limit` bytes.
pub fn read_geotiff_limited(path: &Path, chunk_limit: usize) -> Result<Grid, TerrainError> {
    let source = path.display().to_string();
    let r = read_raster(path, Some(&[0]), chunk_limit)?;
    let georef = r.georef.unwrap_or(Georef::local(1.0));
    let Raster {
        width,
        height,
        mut bands,
        nodata,
        ..
    } = r;
    let plane = bands.pop().unwrap_or_default();
    // Float grids use NaN for no-data themselves (GDAL writes "nan"); an explicit NaN with no
    // nodata tag is still a hole, not an error, because it is how float rasters store voids.
    Grid::from_samples(
        &source,
        width,
        height,
        plane,
        nodata.filter(|v| !v.is_nan()),
        true,
        georef,
    )
}

fn tiff_err(source: &str, at: &str) -> impl FnOnce(tiff::TiffError) -> TerrainError {
    let source = source.to_string();
    let at = at.to_string();
    move |e| match e {
        tiff::TiffError::UnsupportedError(u) => TerrainError::Unsupported {
            source,
            what: format!("{at}: {u}"),
        },
        other => TerrainError::Format {
            source,
            at,
            expected: format!("valid TIFF data ({other})"),
        },
    }
}

/// Check the first image directory against the file before the `tiff` decoder reads it: every
/// entry's values (count x type size) must fit in the file. The decoder sizes a tag's value list
/// from its count (and keeps each value as a wide enum), so one flipped bit in a count would
/// otherwise allocate gigabytes for a kilobyte file.
fn check_directory(path: &Path, source: &str) -> Result<(), TerrainError> {
    use std::io::{Read, Seek, SeekFrom};
    let bad = |at: String, expected: String| TerrainError::Format {
        source: source.to_string(),
        at,
        expected,
    };
    let mut f = std::fs::File::open(path).map_err(io(path))?;
    let len = f.metadata().map_err(io(path))?.len();
    let mut head = [0u8; 16];
    let got = f.read(&mut head).map_err(io(path))?;
    if got < 8 {
        return Err(bad("header".into(), "a TIFF header of 8 bytes".into()));
    }
    let le = match &head[..2] {
        b"II" => true,
        b"MM" => false,
        _ => return Err(bad("header".into(), "byte order II or MM".into())),
    };
    let u16_at = |b: &[u8]| {
        if le {
            u16::from_le_bytes([b[0], b[1]])
        } else {
            u16::from_be_bytes([b[0], b[1]])
        }
    };
    let u32_at = |b: &[u8]| {
        let a = [b[0], b[1], b[2], b[3]];
        if le {
            u32::from_le_bytes(a)
        } else {
            u32::from_be_bytes(a)
        }
    };
    let u64_at = |b: &[u8]| {
        let a = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
        if le {
            u64::from_le_bytes(a)
        } else {
            u64::from_be_bytes(a)
        }
    };
    let big = match u16_at(&head[2..4]) {
        42 => false,
        43 => true,
        v => {
            return Err(bad(
                "header".into(),
                format!("version 42 or 43 (BigTIFF), found {v}"),
            ));
        }
    };
    if big && got < 16 {
        return Err(bad("header".into(), "a BigTIFF header of 16 bytes".into()));
    }
    let ifd = if big {
        u64_at(&head[8..16])
    } else {
        u32_at(&head[4..8]) as u64
    };
    let (count_size, entry_size, inline) = if big { (8u64, 20u64, 8u64) } else { (2, 12, 4) };
    if ifd.saturating_add(count_size) > len {
        return Err(bad(
            "first IFD offset".into(),
            format!("an offset inside the {len}-byte file, found {ifd}"),
        ));
    }
    f.seek(SeekFrom::Start(ifd)).map_err(io(path))?;
    let mut cbuf = [0u8; 8];
    f.read_exact(&mut cbuf[..count_size as usize])
        .map_err(io(path))?;
    let entries = if big {
        u64_at(&cbuf)
    } else {
        u16_at(&cbuf) as u64
    };
    if ifd
        .saturating_add(count_size)
        .saturating_add(entries.saturating_mul(entry_size))
        > len
    {
        return Err(bad(
            format!("IFD at byte {ifd}"),
            format!("{entries} entries inside the {len}-byte file"),
        ));
    }
    let mut table = vec![0u8; (entries * entry_size) as usize];
    f.read_exact(&mut table).map_err(io(path))?;
    for e in table.chunks_exact(entry_size as usize) {
        let tag = u16_at(&e[0..2]);
        let size: u64 = match u16_at(&e[2..4]) {
            1 | 2 | 6 | 7 => 1,
            3 | 8 => 2,
            4 | 9 | 11 | 13 => 4,
            5 | 10 | 12 | 16 | 17 | 18 => 8,
            _ => 1, // an unknown type: the decoder reports it
        };
        let count = if big {
            u64_at(&e[4..12])
        } else {
            u32_at(&e[4..8]) as u64
        };
        let bytes = count.saturating_mul(size);
        if bytes > inline && bytes > len {
            return Err(bad(
                format!("tag {tag}"),
                format!("values that fit in the {len}-byte file, found {count} of {size} bytes"),
            ));
        }
    }
    Ok(())
}

/// The number of bands (SamplesPerPixel) of a TIFF, read from its header only.
pub fn band_count(path: &Path) -> Result<u16, TerrainError> {
    let source = path.display().to_string();
    check_directory(path, &source)?;
    let file = std::fs::File::open(path).map_err(io(path))?;
    let mut dec =
        Decoder::new(std::io::BufReader::new(file)).map_err(tiff_err(&source, "header"))?;
    Ok(dec
        .find_tag_unsigned(Tag::SamplesPerPixel)
        .map_err(tiff_err(&source, "tag 277 SamplesPerPixel"))?
        .unwrap_or(1))
}

/// An open TIFF read one stored chunk (strip or tile) at a time: the header, georeference and
/// chunk layout checked once ([`RasterReader::open`]), then [`RasterReader::read_chunk`] decodes
/// one chunk's wanted bands. [`read_raster`] reads them all; an orthophoto larger than memory is
/// read a band of rows at a time ([`crate::photo::TiffPhoto`]).
pub struct RasterReader {
    source: String,
    dec: Decoder<std::io::BufReader<std::fs::File>>,
    pub width: u32,
    pub height: u32,
    /// Bands in the file, and bits per sample as stored.
    pub band_count: u16,
    pub bits: u8,
    planar: bool,
    want: Vec<u16>,
    pub georef: Option<Georef>,
    pub nodata: Option<f64>,
    /// The alpha band (0-based), when `ExtraSamples` (338) marks one: 2 unassociated (as
    /// `gdalwarp -dstalpha` writes it) or 1 associated.
    pub alpha: Option<u16>,
    chunk_type: ChunkType,
    cw: u32,
    ch: u32,
    across: u32,
    per_plane: u32,
    counts: Vec<u64>,
    compression: u16,
    expansion: u64,
    sample_bytes: u64,
    /// Photometric YCbCr (6), interleaved: the decoder hands out Y, Cb, Cr, converted to RGB here.
    ycbcr: bool,
    /// JPEG and WebP chunks: the file (opened again) and each chunk's offset, so that the frame
    /// size a chunk's own header claims is checked before its codec allocates for it.
    peek: Option<(std::fs::File, Vec<u64>)>,
}

/// Rows of a TIFF read by bands: each row of chunks is decoded once, by the caller's `decode`
/// into whatever it keeps (8-bit RGBA for a photo, `f32` planes for a VRT's source), and kept
/// until a request starts below it, since readers ask for overlapping bands top to bottom.
pub(crate) struct ChunkRows<T> {
    pub reader: RasterReader,
    cache: std::collections::BTreeMap<u32, T>,
}

impl<T> ChunkRows<T> {
    pub fn new(reader: RasterReader) -> ChunkRows<T> {
        ChunkRows {
            reader,
            cache: std::collections::BTreeMap::new(),
        }
    }

    /// Visit the decoded chunk rows under image rows `y0..y1` (`y0 < y1 ≤ height`) top to
    /// bottom: `visit(rows, top)` with `top` the image row of the chunk row's first row.
    pub fn visit(
        &mut self,
        y0: u32,
        y1: u32,
        decode: impl Fn(&mut RasterReader, u32) -> Result<T, TerrainError>,
        mut visit: impl FnMut(&T, u32),
    ) -> Result<(), TerrainError> {
        let ch = self.reader.chunk_rows();
        let (cr0, cr1) = (y0 / ch, y1.saturating_sub(1) / ch);
        // Rows above this band are not asked for again by a top-to-bottom reader.
        self.cache.retain(|&cr, _| cr >= cr0);
        for cr in cr0..=cr1 {
            if !self.cache.contains_key(&cr) {
                let rows = decode(&mut self.reader, cr)?;
                self.cache.insert(cr, rows);
            }
            visit(&self.cache[&cr], cr * ch);
        }
        Ok(())
    }
}

/// One decoded chunk: its rectangle in the image (clipped to it) and one plane per wanted band.
pub struct ChunkPlanes {
    pub x0: u32,
    pub y0: u32,
    pub width: u32,
    pub height: u32,
    pub planes: Vec<Vec<f32>>,
}

impl RasterReader {
    /// Open `path` for the bands `bands` (0-based; `None` = all), with the per-chunk decode
    /// buffer limited to `chunk_limit` bytes.
    pub fn open(
        path: &Path,
        bands: Option<&[u16]>,
        chunk_limit: usize,
    ) -> Result<RasterReader, TerrainError> {
        let source = path.display().to_string();
        check_directory(path, &source)?;
        let file = std::fs::File::open(path).map_err(io(path))?;
        let mut limits = Limits::default();
        limits.decoding_buffer_size = chunk_limit;
        let mut dec = Decoder::new(std::io::BufReader::new(file))
            .map_err(tiff_err(&source, "header"))?
            .with_limits(limits);
        let (width, height) = dec
            .dimensions()
            .map_err(tiff_err(&source, "ImageWidth/ImageLength"))?;
        check_size(&source, width as u64, height as u64)?;
        let spp: u16 = dec
            .find_tag_unsigned(Tag::SamplesPerPixel)
            .map_err(tiff_err(&source, "tag 277 SamplesPerPixel"))?
            .unwrap_or(1);
        let bits: u16 = dec
            .find_tag_unsigned_vec::<u16>(Tag::BitsPerSample)
            .map_err(tiff_err(&source, "tag 258 BitsPerSample"))?
            .and_then(|v| v.first().copied())
            .unwrap_or(1);
        let planar = dec
            .find_tag_unsigned::<u16>(Tag::PlanarConfiguration)
            .map_err(tiff_err(&source, "tag 284 PlanarConfiguration"))?
            .map(PlanarConfiguration::from_u16)
            .unwrap_or(Some(PlanarConfiguration::Chunky));
        let planar = match planar {
            Some(PlanarConfiguration::Chunky) => false,
            Some(PlanarConfiguration::Planar) => true,
            _ => {
                return Err(TerrainError::Unsupported {
                    source,
                    what: "tag 284 PlanarConfiguration other than 1 or 2".into(),
                });
            }
        };
        let want: Vec<u16> = match bands {
            Some(b) => b.to_vec(),
            None => (0..spp).collect(),
        };
        if let Some(&b) = want.iter().find(|&&b| b >= spp) {
            return Err(TerrainError::BadParameter {
                name: "band",
                value: (b + 1).to_string(),
                expected: "a band the file has (1-based, up to SamplesPerPixel)",
            });
        }
        let georef = read_georef(&mut dec, &source)?;
        let nodata = match dec
            .find_tag(Tag::GdalNodata)
            .map_err(tiff_err(&source, "tag 42113 GDAL_NODATA"))?
        {
            Some(v) => {
                let s = v
                    .into_string()
                    .map_err(tiff_err(&source, "tag 42113 GDAL_NODATA"))?;
                let t = s.trim_matches(|c: char| c == '\0' || c.is_whitespace());
                Some(t.parse::<f64>().map_err(|_| {
                    format_err(
                        &source,
                        "tag 42113 GDAL_NODATA",
                        format!("a number, got {t:?}"),
                    )
                })?)
            }
            None => None,
        };
        // ExtraSamples lists the last bands: the first alpha among them is the photo's.
        let extra = dec
            .find_tag_unsigned_vec::<u16>(Tag::ExtraSamples)
            .map_err(tiff_err(&source, "tag 338 ExtraSamples"))?
            .unwrap_or_default();
        let alpha = extra
            .iter()
            .position(|&e| e == 1 || e == 2)
            .and_then(|i| (spp as usize).checked_sub(extra.len() - i))
            .map(|b| b as u16);

        let (cw, ch) = dec.chunk_dimensions();
        let chunk_type = dec.get_chunk_type();
        // Both counts cover every plane of a planar image.
        let total = match chunk_type {
            ChunkType::Tile => dec
                .tile_count()
                .map_err(tiff_err(&source, "tile offsets"))?,
            ChunkType::Strip => dec
                .strip_count()
                .map_err(tiff_err(&source, "strip offsets"))?,
        };
        let per_plane = if planar {
            total / spp.max(1) as u32
        } else {
            total
        };
        let across = width.div_ceil(cw.max(1));
        let down = height.div_ceil(ch.max(1));
        // The offsets table is in the file: an image whose header claims more strips or tiles than
        // the table lists is refused before anything is sized from the claim.
        let needed = match chunk_type {
            ChunkType::Tile => across as u64 * down as u64,
            ChunkType::Strip => down as u64,
        };
        if (per_plane as u64) < needed {
            return Err(format_err(
                &source,
                "tags 273/324 StripOffsets/TileOffsets",
                format!(
                    "{needed} strips or tiles for a {width}x{height} image, the file lists {per_plane}"
                ),
            ));
        }
        // What each stored chunk can decode to: its byte count times the largest expansion of its
        // compression (none 1x; PackBits 64x: two bytes per 128-byte run; Deflate 1032x; LZW at
        // most 4096 bytes per 12-bit code; ZSTD 32768x: an RLE block of 128 KiB from 4 bytes; WebP
        // and JPEG are bounded alike). A chunk whose claimed size exceeds it is damage, found
        // before the decoder sizes a buffer for it.
        let counts = dec
            .get_tag_u64_vec(match chunk_type {
                ChunkType::Tile => Tag::TileByteCounts,
                ChunkType::Strip => Tag::StripByteCounts,
            })
            .map_err(tiff_err(
                &source,
                "tags 279/325 StripByteCounts/TileByteCounts",
            ))?;
        let compression: u16 = dec
            .find_tag_unsigned(Tag::Compression)
            .map_err(tiff_err(&source, "tag 259 Compression"))?
            .unwrap_or(1);
        let expansion: u64 = match compression {
            1 => 1,
            32773 => 64,
            8 | 32946 => 1032,
            50000 | 50001 => 32768,
            _ => 2731, // LZW: 4096 bytes from 12 bits; JPEG's least code per 8x8 block is larger
        };
        let sample_bytes = (bits as u64).div_ceil(8).max(1);
        let photometric: Option<u16> = dec
            .find_tag_unsigned(Tag::PhotometricInterpretation)
            .map_err(tiff_err(&source, "tag 262 PhotometricInterpretation"))?;
        let ycbcr = photometric == Some(6) && !planar && spp >= 3 && bits == 8;
        // JPEG (7) and WebP (50001) decoders size their output from the stream's own header, not
        // from the decode limit: those headers are read first (`check_codec_frame`).
        let peek = if matches!(compression, 7 | 50001) {
            let offsets = dec
                .get_tag_u64_vec(match chunk_type {
                    ChunkType::Tile => Tag::TileOffsets,
                    ChunkType::Strip => Tag::StripOffsets,
                })
                .map_err(tiff_err(&source, "tags 273/324 StripOffsets/TileOffsets"))?;
            Some((std::fs::File::open(path).map_err(io(path))?, offsets))
        } else {
            None
        };
        Ok(RasterReader {
            source,
            dec,
            width,
            height,
            band_count: spp,
            bits: bits.min(255) as u8,
            planar,
            want,
            georef,
            nodata,
            alpha,
            chunk_type,
            cw,
            ch,
            across,
            per_plane,
            counts,
            compression,
            expansion,
            sample_bytes,
            ycbcr,
            peek,
        })
    }

    /// Stored chunks per band, in file order (row-major tiles, or strips top to bottom).
    pub fn chunk_count(&self) -> u32 {
        self.per_plane
    }

    /// Height of a chunk row (strip or tile height) in image rows.
    pub fn chunk_rows(&self) -> u32 {
        self.ch.max(1)
    }

    /// The chunks holding image rows `y0..y1`, in file order.
    pub fn chunks_in_rows(&self, y0: u32, y1: u32) -> Vec<u32> {
        if y1 <= y0 {
            return Vec::new();
        }
        let (r0, r1) = (y0 / self.chunk_rows(), (y1 - 1) / self.chunk_rows());
        match self.chunk_type {
            ChunkType::Strip => (r0..=r1).collect(),
            ChunkType::Tile => (r0..=r1)
                .flat_map(|r| (0..self.across).map(move |c| r * self.across + c))
                .collect(),
        }
    }

    /// Decode the chunks of chunk row `cr` (image rows from `cr · chunk_rows()`, at full
    /// width), handing each to `put` in file order.
    pub fn read_chunk_row(
        &mut self,
        cr: u32,
        mut put: impl FnMut(&ChunkPlanes),
    ) -> Result<(), TerrainError> {
        let y0 = cr.saturating_mul(self.chunk_rows());
        let y1 = y0.saturating_add(self.chunk_rows()).min(self.height);
        for chunk in self.chunks_in_rows(y0, y1) {
            put(&self.read_chunk(chunk)?);
        }
        Ok(())
    }

    /// Decode stored chunk `chunk` (`0..chunk_count()`): its wanted bands, clipped to the image.
    pub fn read_chunk(&mut self, chunk: u32) -> Result<ChunkPlanes, TerrainError> {
        let source = self.source.clone();
        let (width, height) = (self.width, self.height);
        let (x0, y0) = match self.chunk_type {
            ChunkType::Tile => (
                (chunk % self.across).saturating_mul(self.cw),
                (chunk / self.across).saturating_mul(self.ch),
            ),
            ChunkType::Strip => (0, chunk.saturating_mul(self.ch)),
        };
        if y0 >= height || x0 >= width {
            return Err(format_err(
                &source,
                format!("chunk {chunk}"),
                "a chunk inside the image",
            ));
        }
        let spp = self.band_count;
        // Planar: band b of this chunk is chunk b·per_plane + chunk; interleaved: one chunk holds all.
        let reads: Vec<(u32, Option<usize>)> = if self.planar {
            self.want
                .iter()
                .enumerate()
                .map(|(k, &b)| {
                    (
                        (b as u32)
                            .saturating_mul(self.per_plane)
                            .saturating_add(chunk),
                        Some(k),
                    )
                })
                .collect()
        } else {
            vec![(chunk, None)]
        };
        let (mut out_w, mut out_h) = (0, 0);
        let mut planes: Vec<Vec<f32>> = self.want.iter().map(|_| Vec::new()).collect();
        for (index, only) in reads {
            let (dw, dh) = self.dec.chunk_data_dimensions(index);
            let at = format!("chunk {index}");
            let stored = self.counts.get(index as usize).copied().unwrap_or(0);
            let claimed = (dw as u64 * dh as u64)
                .saturating_mul(self.sample_bytes)
                .saturating_mul(if self.planar { 1 } else { spp as u64 });
            if claimed > stored.saturating_mul(self.expansion).saturating_add(64) {
                return Err(format_err(
                    &source,
                    &at,
                    format!(
                        "{claimed} decoded bytes cannot come from {stored} stored bytes (compression {})",
                        self.compression
                    ),
                ));
            }
            if let Some((file, offsets)) = &mut self.peek {
                let offset = offsets.get(index as usize).copied().unwrap_or(0);
                check_codec_frame(file, offset, stored, self.compression, (self.cw, self.ch))
                    .map_err(|what| format_err(&source, &at, what))?;
            }
            let data = self.dec.read_chunk(index).map_err(tiff_err(&source, &at))?;
            let mut vals = to_f32(data).ok_or_else(|| TerrainError::Unsupported {
                source: source.clone(),
                what: format!("{at}: sample type (need integer or 32/64-bit float samples)"),
            })?;
            let stride = if self.planar { 1 } else { spp as usize };
            if self.ycbcr {
                ycbcr_to_rgb(&mut vals, stride);
            }
            let need = dw as usize * dh as usize * stride;
            if vals.len() < need {
                return Err(format_err(
                    &source,
                    &at,
                    format!("{need} samples, decoded {}", vals.len()),
                ));
            }
            let dw_clip = dw.min(width - x0) as usize;
            let dh_clip = dh.min(height - y0) as usize;
            (out_w, out_h) = (dw_clip as u32, dh_clip as u32);
            for (k, &b) in self.want.iter().enumerate() {
                if only.is_some_and(|o| o != k) {
                    continue;
                }
                let sample = if self.planar { 0 } else { b as usize };
                let dst = &mut planes[k];
                dst.clear();
                dst.reserve(dw_clip * dh_clip);
                for row in 0..dh_clip {
                    let src_row = row * dw as usize * stride;
                    for col in 0..dw_clip {
                        dst.push(vals[src_row + col * stride + sample]);
                    }
                }
            }
        }
        Ok(ChunkPlanes {
            x0,
            y0,
            width: out_w,
            height: out_h,
            planes,
        })
    }
}

/// Read the bands `bands` (0-based; `None` = all) of a TIFF, chunk by chunk.
pub fn read_raster(
    path: &Path,
    bands: Option<&[u16]>,
    chunk_limit: usize,
) -> Result<Raster, TerrainError> {
    let mut r = RasterReader::open(path, bands, chunk_limit)?;
    let (width, height) = (r.width, r.height);
    let n = width as usize * height as usize;
    // The bands grow as their rows are decoded (each chunk's decoded size is bounded by the
    // decoder's limit), so a header's claim alone never sizes a buffer.
    let mut out: Vec<Vec<f32>> = r.want.iter().map(|_| Vec::new()).collect();
    for chunk in 0..r.chunk_count() {
        let c = r.read_chunk(chunk)?;
        let rows_end = (c.y0 + c.height) as usize;
        for (band, plane) in out.iter_mut().zip(&c.planes) {
            let len = (rows_end * width as usize).min(n);
            if band.len() < len {
                band.resize(len, 0.0);
            }
            for row in 0..c.height as usize {
                let dst = (c.y0 as usize + row) * width as usize + c.x0 as usize;
                let src = row * c.width as usize;
                band[dst..dst + c.width as usize]
                    .copy_from_slice(&plane[src..src + c.width as usize]);
            }
        }
    }
    for band in &mut out {
        band.resize(n, 0.0); // every chunk was read: already n long
    }
    Ok(Raster {
        width,
        height,
        bands: out,
        bits: r.bits,
        georef: r.georef,
        nodata: r.nodata,
        band_count: r.band_count,
    })
}

/// The frame size in a JPEG (7) or WebP (50001) chunk's own header, which its decoder allocates
/// for before the TIFF decode limit applies, must fit the chunk (`chunk`: tile or strip width and
/// height): a damaged header claiming 16384² pixels is refused here, not allocated.
fn check_codec_frame(
    file: &mut std::fs::File,
    offset: u64,
    stored: u64,
    compression: u16,
    chunk: (u32, u32),
) -> Result<(), String> {
    // Only the header bytes are read: the marker segments' heads up to the JPEG frame header
    // (within the chunk's first 64 KiB), or WebP's first 30 bytes.
    let limit = stored.min(1 << 16);
    let mut peek = |at: u64, n: u64| -> Result<Vec<u8>, String> {
        use std::io::{Read, Seek, SeekFrom};
        let mut b = Vec::new();
        file.seek(SeekFrom::Start(offset + at))
            .and_then(|_| {
                (&mut *file)
                    .take(n.min(limit.saturating_sub(at)))
                    .read_to_end(&mut b)
            })
            .map_err(|e| format!("the chunk's bytes at offset {}: {e}", offset + at))?;
        Ok(b)
    };
    let be16 = |b: &[u8], i: usize| {
        b.get(i..i + 2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]) as u32)
    };
    let le16 = |b: &[u8], i: usize| {
        b.get(i..i + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]) as u32)
    };
    let le24 = |b: &[u8], i: usize| {
        b.get(i..i + 3)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], 0]))
    };
    let frame = if compression == 7 {
        // Segments from SOI to the first start-of-frame marker (C0-CF but C4 DHT, C8, CC DAC),
        // each read as its marker, length and (for a frame header) precision, height, width.
        let mut found = None;
        if peek(0, 2)? == [0xFF, 0xD8] {
            let mut i = 2;
            while i + 4 <= limit {
                let m = peek(i, 9)?;
                if m[0] != 0xFF {
                    break;
                }
                let marker = m[1];
                if marker == 0xFF {
                    i += 1; // fill byte
                    continue;
                }
                if (0xC0..=0xCF).contains(&marker) && !matches!(marker, 0xC4 | 0xC8 | 0xCC) {
                    found = be16(&m, 7).zip(be16(&m, 5));
                    break;
                }
                let Some(len) = be16(&m, 2) else { break };
                i += 2 + len as u64;
            }
        }
        found.ok_or("a JPEG stream with a frame header (SOF) in its first 64 KiB")?
    } else {
        let head = peek(0, 30)?;
        if head.get(..4) != Some(b"RIFF") || head.get(8..12) != Some(b"WEBP") {
            return Err("a WebP stream (RIFF ... WEBP)".into());
        }
        match head.get(12..16) {
            Some(b"VP8 ") => le16(&head, 26)
                .zip(le16(&head, 28))
                .map(|(w, h)| (w & 0x3FFF, h & 0x3FFF)),
            Some(b"VP8L") => head.get(21..25).map(|b| {
                let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                ((v & 0x3FFF) + 1, ((v >> 14) & 0x3FFF) + 1)
            }),
            Some(b"VP8X") => le24(&head, 24)
                .zip(le24(&head, 27))
                .map(|(w, h)| (w + 1, h + 1)),
            _ => None,
        }
        .ok_or("a WebP VP8, VP8L or VP8X frame header")?
    };
    if frame.0 > chunk.0 || frame.1 > chunk.1 {
        return Err(format!(
            "a {} frame within the {}x{} chunk, its header claims {}x{}",
            if compression == 7 { "JPEG" } else { "WebP" },
            chunk.0,
            chunk.1,
            frame.0,
            frame.1
        ));
    }
    Ok(())
}

/// Y, Cb, Cr (the first three of every `stride` samples) to R, G, B in place, by the JFIF
/// equations (ITU-R BT.601 luma weights over the full 0–255 range), which are also TIFF's defaults
/// (`YCbCrCoefficients` 0.299/0.587/0.114, `ReferenceBlackWhite` 0/255, 128/255, 128/255) and the
/// conversion libjpeg makes when GDAL reads a YCbCr JPEG TIFF.
fn ycbcr_to_rgb(vals: &mut [f32], stride: usize) {
    for px in vals.chunks_exact_mut(stride) {
        let (y, cb, cr) = (px[0], px[1] - 128.0, px[2] - 128.0);
        let rgb = [
            y + 1.402 * cr,
            y - 0.344_136 * cb - 0.714_136 * cr,
            y + 1.772 * cb,
        ];
        for (dst, v) in px.iter_mut().zip(rgb) {
            *dst = v.round().clamp(0.0, 255.0);
        }
    }
}

fn to_f32(d: DecodingResult) -> Option<Vec<f32>> {
    Some(match d {
        DecodingResult::U8(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::U16(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::U32(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::U64(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::I8(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::I16(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::I32(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::I64(v) => v.into_iter().map(|x| x as f32).collect(),
        DecodingResult::F32(v) => v,
        DecodingResult::F64(v) => v.into_iter().map(|x| x as f32).collect(),
        _ => return None,
    })
}

fn f64_vec<R: std::io::Read + std::io::Seek>(
    dec: &mut Decoder<R>,
    tag: Tag,
    source: &str,
    name: &str,
) -> Result<Option<Vec<f64>>, TerrainError> {
    match dec.find_tag(tag).map_err(tiff_err(source, name))? {
        None => Ok(None),
        Some(v) => Ok(Some(v.into_f64_vec().map_err(tiff_err(source, name))?)),
    }
}

/// The keys of a GeoKey directory that place a grid or a point cloud: GeoTIFF's tag 34735, and the
/// same array of `u16` in a LAS file's `LASF_Projection` record 34735 ([`super::las`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct GeoKeys {
    /// `GTModelTypeGeoKey` (1024): 1 projected, 2 geographic, 3 geocentric.
    pub model: Option<u16>,
    /// `GTRasterTypeGeoKey` (1025): 1 `RasterPixelIsArea` (the default), 2 `RasterPixelIsPoint`.
    pub raster_type: u16,
    /// `ProjectedCSTypeGeoKey` (3072) or `GeographicTypeGeoKey` (2048), when an EPSG code.
    pub epsg: Option<u16>,
    /// The code came from `ProjectedCSTypeGeoKey` (3072).
    pub projected_key: bool,
}

impl Default for GeoKeys {
    fn default() -> Self {
        GeoKeys {
            model: None,
            raster_type: 1,
            epsg: None,
            projected_key: false,
        }
    }
}

impl GeoKeys {
    /// Read a key directory: a 4-value header (version, revision, minor revision, key count),
    /// then `(KeyID, TIFFTagLocation, Count, Value)` per key. Keys whose value lives in another
    /// tag (location ≠ 0) are passed over; user-defined (32767) and undefined (0) codes are none.
    pub fn parse(keys: &[u16], source: &str, at: &str) -> Result<GeoKeys, TerrainError> {
        if keys.len() < 4 {
            return Err(format_err(source, at, "a 4-value header"));
        }
        let count = keys[3] as usize;
        if keys.len() < 4 + 4 * count {
            return Err(format_err(
                source,
                at,
                format!("{count} keys of 4 values, got {} values", keys.len()),
            ));
        }
        let mut g = GeoKeys::default();
        for k in keys[4..4 + 4 * count].chunks_exact(4) {
            // (KeyID, TIFFTagLocation, Count, Value): location 0 = the value is inline.
            if k[1] != 0 {
                continue;
            }
            match k[0] {
                1024 => g.model = Some(k[3]),
                1025 => g.raster_type = k[3],
                2048 | 3072 if k[3] != 32767 && k[3] != 0 => {
                    g.epsg = Some(k[3]);
                    g.projected_key = k[0] == 3072;
                }
                _ => {}
            }
        }
        Ok(g)
    }

    /// The kind of system the model type names (no model type: `Local`, as GDAL reads it).
    pub fn crs(&self, source: &str) -> Result<CrsKind, TerrainError> {
        match self.model {
            Some(1) => Ok(CrsKind::Projected),
            Some(2) => Ok(CrsKind::Geographic),
            Some(3) => Err(TerrainError::Unsupported {
                source: source.into(),
                what: "GTModelTypeGeoKey 3 (geocentric)".into(),
            }),
            _ => Ok(CrsKind::Local),
        }
    }
}

/// Interpret the GeoTIFF tags; `None` when the file has no georeference at all.
fn read_georef<R: std::io::Read + std::io::Seek>(
    dec: &mut Decoder<R>,
    source: &str,
) -> Result<Option<Georef>, TerrainError> {
    let keys = match dec
        .find_tag_unsigned_vec::<u16>(Tag::GeoKeyDirectoryTag)
        .map_err(tiff_err(source, "tag 34735 GeoKeyDirectory"))?
    {
        Some(k) => GeoKeys::parse(&k, source, "tag 34735 GeoKeyDirectory")?,
        None => GeoKeys::default(),
    };
    let (crs, epsg, raster_type) = (keys.crs(source)?, keys.epsg, keys.raster_type);
    // Raster space of pixel centres: PixelIsArea counts corners, PixelIsPoint centres.
    let half = match raster_type {
        1 => 0.5,
        2 => 0.0,
        other => {
            return Err(format_err(
                source,
                "GeoKey 1025 GTRasterTypeGeoKey",
                format!("1 (PixelIsArea) or 2 (PixelIsPoint), got {other}"),
            ));
        }
    };
    let scale = f64_vec(
        dec,
        Tag::ModelPixelScaleTag,
        source,
        "tag 33550 ModelPixelScale",
    )?;
    let tie = f64_vec(
        dec,
        Tag::ModelTiepointTag,
        source,
        "tag 33922 ModelTiepoint",
    )?;
    let trans = f64_vec(
        dec,
        Tag::ModelTransformationTag,
        source,
        "tag 34264 ModelTransformation",
    )?;
    let (x_at, y_at, dx, dy) = match (scale, tie, trans) {
        (Some(s), Some(t), _) => {
            if s.len() < 2 || t.len() < 6 {
                return Err(format_err(
                    source,
                    "tags 33550/33922",
                    "3 pixel scales and 6 tie-point values",
                ));
            }
            // Raster (i, j) -> (X + (i − I)·Sx, Y − (j − J)·Sy).
            let (i, j, x, y) = (t[0], t[1], t[3], t[4]);
            (x - i * s[0], y + j * s[1], s[0], -s[1])
        }
        (_, _, Some(m)) => {
            if m.len() < 16 {
                return Err(format_err(
                    source,
                    "tag 34264 ModelTransformation",
                    "16 values",
                ));
            }
            if m[1] != 0.0 || m[4] != 0.0 {
                return Err(TerrainError::Unsupported {
                    source: source.into(),
                    what: "tag 34264 ModelTransformation with rotation or shear".into(),
                });
            }
            (m[3], m[7], m[0], m[5])
        }
        (None, _, None) | (Some(_), None, None) => return Ok(None),
    };
    Ok(Some(Georef {
        crs,
        epsg,
        origin_x: x_at + half * dx,
        origin_y: y_at + half * dy,
        dx,
        dy,
    }))
}
