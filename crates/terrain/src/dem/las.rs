//! ASPRS LAS point clouds, versions 1.0 to 1.4, and their LASzip compression (LAZ): the header,
//! the records that carry the coordinate system, and the points, streamed in batches of
//! [`BATCH`] ([`LasReader`]). [`super::lidar`] grids them into an elevation grid.
//!
//! **Header** (LAS 1.4 R15 §2.4; 227 bytes in LAS 1.0–1.2, 235 in 1.3, 375 in 1.4): the
//! signature `LASF`, version, header size, offset to the point data, VLR count, point data
//! record format (bit 7 or bit 6 set: LAZ-compressed) and record length, point count (LAS 1.4's
//! 64-bit count when set; the legacy 32-bit one must then be 0 or the same), scale factors and
//! offsets (`x = X·scale + offset`, the stored integers turned into coordinates as laspy and PDAL
//! do), the bounding box, and in LAS 1.4 the first EVLR's offset and the EVLR count.
//!
//! **Points** (§2.6, formats 0–10): the integer `X`, `Y`, `Z` at bytes 0–12, then for formats 0–5
//! the return number (bits 0–2 of byte 14), number of returns (bits 3–5), classification (bits
//! 0–4 of byte 15) and the withheld flag (bit 7); for formats 6–10 the return number (bits 0–3 of
//! byte 14), number of returns (bits 4–7), the withheld flag (bit 2 of byte 15) and the
//! classification byte 16. A record may be longer than its format's minimum (extra bytes).
//!
//! **Coordinate system** (§2.5): the GeoKey directory (`LASF_Projection` record 34735, the
//! GeoTIFF keys, read by the GeoTIFF reader's code, `geotiff::GeoKeys`) or OGC WKT 1 or 2
//! (`LASF_Projection` record 2112, required for formats 6–10; read by the `.prj` reader's code,
//! `shapefile::crs_of_wkt`, a compound system by its horizontal part), in a VLR or an EVLR.
//! Bit 4 of the global encoding says which one the file means when it has both. A file with
//! neither is placed in a local frame.
//!
//! **LAZ** (LASzip 2 and 3, the `laszip encoded` record 22204): decompressed by the `laz` crate
//! (the pure-Rust port of LASzip that laspy's lazrs backend uses), after checks of ours that it
//! does not make: the LASzip record's items against the point record length, the chunk table
//! present and inside the file, its chunk sizes adding up to the compressed bytes and its chunks
//! to the header's point count, and for the layered chunks of formats 6–10 every chunk's layer
//! sizes inside the chunk. The crate sizes its buffers from those numbers, so one flipped bit
//! in them would otherwise allocate gigabytes or panic. A file of several chunks of at most
//! 262,144 points each (LASzip writes 50,000) is decoded a window of whole chunks at a time, two
//! chunks for each rayon thread, the chunks side by side (the crate's `ParLasZipDecompressor`);
//! the points come out in the file's order, so what is made from them does not depend on the
//! thread count. Other files are decoded serially, a batch at a time.
//!
//! **Nothing is sized from a claim**: the header's point count, VLR and EVLR counts and lengths
//! and the chunk table are checked against the file's length before anything is read or
//! allocated for them, and points are decoded [`BATCH`] at a time into a buffer of that size. An
//! uncompressed file too short for the points its header claims is refused at the point where it
//! ends. A point outside the header's bounding box by more than the box's own size (its larger
//! side) is refused as damage: it would otherwise stretch the grid made from the cloud to any
//! size (points just outside, from a header its writer did not quite update, are read). Every
//! error names the file and a byte offset, a record or a point index.
//!
//! **Departures**: the waveform packets of formats 4, 5, 9, 10 are not read (the points are);
//! LASzip's unchunked compressor (LASzip 1, before 2012) and files without a chunk table are
//! refused (the table is how a cut file is told from a whole one).
//!
//! # References
//! - ASPRS, *LAS Specification 1.4 — R15* (2019): §2.4 header, §2.5 VLRs and EVLRs, §2.6 point
//!   data record formats 0–10, §2.4 table 6 global encoding; *LAS 1.0* (2003), *1.2* (2008),
//!   *1.3 R11* (2010) for the shorter headers.
//! - M. Isenburg, *LASzip: lossless compression of LiDAR data*, PE&RS 79(2), 2013: chunks and the
//!   chunk table.

use super::CrsKind;
use super::geotiff::GeoKeys;
use crate::error::{TerrainError, format_err, io};
use crate::vector::LayerCrs;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// Points decoded per call of [`LasReader::read_batch`]: the record buffer is at most
/// `BATCH × 67` bytes (the longest standard record) plus extra bytes, whatever the header claims.
pub const BATCH: usize = 8192;

/// The shortest record of point data record formats 0–10 (LAS 1.4 R15 §2.6).
const RECORD_LEN: [u16; 11] = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67];
/// Header sizes of LAS 1.0–1.2, 1.3 and 1.4.
const HEADER_12: u64 = 227;
const HEADER_13: u64 = 235;
const HEADER_14: u64 = 375;
const VLR_HEADER: u64 = 54;
const EVLR_HEADER: u64 = 60;
/// The LASzip record's fixed part before its items.
const LASZIP_FIXED: usize = 34;

/// Which record placed the cloud.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CrsRecord {
    /// The GeoKey directory (`LASF_Projection` 34735).
    GeoKeys,
    /// OGC WKT (`LASF_Projection` 2112).
    Wkt,
    /// Neither: a local frame.
    None,
}

/// A LAS file's header, as checked against the file.
#[derive(Clone, Debug, PartialEq)]
pub struct LasHeader {
    /// Major and minor version (1, 0..=4).
    pub version: (u8, u8),
    /// Point data record format, 0–10.
    pub point_format: u8,
    /// Bytes per point record (at least the format's minimum).
    pub record_len: u16,
    /// The points are LASzip-compressed.
    pub compressed: bool,
    /// Points in the file (checked against the file's length or the LAZ chunk table).
    pub point_count: u64,
    /// Byte offset of the first point record.
    pub offset_to_points: u64,
    /// `x = X·scale[0] + offset[0]`, and so for y and z.
    pub scale: [f64; 3],
    pub offset: [f64; 3],
    /// The header's bounding box, `[x, y, z]`.
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// The coordinate system's kind and EPSG code, and the record that gave them.
    pub crs: CrsKind,
    pub epsg: Option<u16>,
    pub crs_record: CrsRecord,
}

/// One point's coordinates and the attributes gridding filters on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LasPoint {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    /// ASPRS class (2 ground, 7 low noise, 18 high noise, ...).
    pub class: u8,
    pub return_number: u8,
    pub number_of_returns: u8,
    /// Marked as deleted (the withheld flag).
    pub withheld: bool,
}

impl LasPoint {
    /// The last (or only) return of its pulse: its return number is the number of returns, or
    /// the pulse's count is unset (0).
    pub fn is_last_return(&self) -> bool {
        self.number_of_returns == 0 || self.return_number >= self.number_of_returns
    }
}

/// An open LAS or LAZ file, read [`BATCH`] points at a time.
pub struct LasReader {
    source: String,
    header: LasHeader,
    body: Body,
    /// Points read so far.
    next: u64,
    raw: Vec<u8>,
    /// The x, y box every point must lie in: the header's, widened by its larger side (and a
    /// scale step) each way; `None` when the header leaves its box unset (all zero).
    within: Option<([f64; 2], [f64; 2])>,
}

enum Body {
    Plain(BufReader<File>),
    Laz {
        dec: LazStream,
        /// `(first point, points, first byte)` of every chunk.
        chunks: Vec<(u64, u64, u64)>,
    },
}

/// A LASzip stream decoded one batch at a time, or (several chunks of at most [`PAR_CHUNK`]
/// points) a window of [`par_window`] whole chunks at a time, the chunks decoded side by side.
enum LazStream {
    Serial(Box<laz::LasZipDecompressor<'static, BufReader<File>>>),
    Parallel {
        dec: Box<laz::ParLasZipDecompressor<BufReader<File>>>,
        /// The decoded records of the current window, and how many of its bytes are served.
        window: Vec<u8>,
        served: usize,
    },
}

/// The most points a chunk may hold for the chunks to be decoded in parallel (LASzip writes
/// 50,000): a window's records are allocated whole, so a chunk table claiming more is decoded
/// serially, a batch at a time.
const PAR_CHUNK: u64 = 1 << 18;

/// Chunks decoded per parallel window: two for each worker thread.
fn par_window() -> usize {
    2 * rayon::current_num_threads()
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}
fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}
fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}
fn f64_at(b: &[u8], at: usize) -> f64 {
    f64::from_bits(u64_at(b, at))
}
/// A fixed-length text field without its NUL padding.
fn text(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).trim().to_string()
}

/// Read `n` bytes at `at` of `f`, a file of `len` bytes (the caller checked they are inside it).
fn read_at(f: &mut File, path: &Path, at: u64, n: usize) -> Result<Vec<u8>, TerrainError> {
    let mut buf = vec![0u8; n];
    f.seek(SeekFrom::Start(at)).map_err(io(path))?;
    f.read_exact(&mut buf).map_err(io(path))?;
    Ok(buf)
}

/// The records of interest found among the VLRs and EVLRs.
#[derive(Default)]
struct Records {
    geokeys: Option<(Vec<u16>, String)>,
    wkt: Option<(String, String)>,
    laszip: Option<(Vec<u8>, String)>,
}

impl Records {
    /// Keep the payload of record `(user, id)` if it is one we read; `at` names it in errors.
    fn wants(user: &str, id: u16) -> bool {
        matches!(
            (user, id),
            ("LASF_Projection", 34735 | 2112) | ("laszip encoded", 22204)
        )
    }

    fn keep(&mut self, user: &str, id: u16, data: Vec<u8>, at: String) {
        match (user, id) {
            ("LASF_Projection", 34735) => {
                let keys = data.chunks_exact(2).map(|c| u16_at(c, 0)).collect();
                self.geokeys.get_or_insert((keys, at));
            }
            ("LASF_Projection", 2112) => {
                let text = String::from_utf8_lossy(&data)
                    .trim_end_matches('\0')
                    .trim()
                    .to_string();
                self.wkt.get_or_insert((text, at));
            }
            ("laszip encoded", 22204) => {
                self.laszip.get_or_insert((data, at));
            }
            _ => {}
        }
    }
}

impl LasReader {
    /// Open `path`: the header, VLRs and EVLRs checked against the file's length, the coordinate
    /// system read, and for LAZ the LASzip record and the chunk table checked.
    pub fn open(path: impl AsRef<Path>) -> Result<LasReader, TerrainError> {
        let path = path.as_ref();
        let source = path.display().to_string();
        let bad = |at: &str, expected: String| format_err(&source, at, expected);
        let mut f = File::open(path).map_err(io(path))?;
        let len = f.metadata().map_err(io(path))?.len();

        // Public header block: the 227 bytes every version has, then the version's own size.
        if len < 4 {
            return Err(bad(
                "byte 0",
                format!("the signature LASF, the file has {len} bytes"),
            ));
        }
        let head = read_at(&mut f, path, 0, len.min(HEADER_14) as usize)?;
        if &head[..4] != b"LASF" {
            return Err(bad(
                "byte 0",
                format!(
                    "the signature LASF, found {:?}",
                    String::from_utf8_lossy(&head[..4])
                ),
            ));
        }
        if len < HEADER_12 {
            return Err(bad(
                "header",
                format!("a public header of at least {HEADER_12} bytes, the file has {len}"),
            ));
        }
        let version = (head[24], head[25]);
        if version.0 != 1 || version.1 > 4 {
            return Err(TerrainError::Unsupported {
                source: source.clone(),
                what: format!("LAS version {}.{} (read: 1.0 to 1.4)", version.0, version.1),
            });
        }
        let need = match version.1 {
            0..=2 => HEADER_12,
            3 => HEADER_13,
            _ => HEADER_14,
        };
        let header_size = u16_at(&head, 94) as u64;
        if header_size < need || header_size > len {
            return Err(bad(
                "byte 94 (header size)",
                format!(
                    "at least {need} bytes for LAS {}.{} inside the {len}-byte file, found \
                     {header_size}",
                    version.0, version.1
                ),
            ));
        }
        let offset_to_points = u32_at(&head, 96) as u64;
        if offset_to_points < header_size || offset_to_points > len {
            return Err(bad(
                "byte 96 (offset to point data)",
                format!(
                    "an offset from the header's end ({header_size}) to the file's end ({len}), \
                     found {offset_to_points}"
                ),
            ));
        }
        let vlr_count = u32_at(&head, 100);
        let format_byte = head[104];
        let compressed = format_byte & 0xC0 != 0;
        let point_format = format_byte & 0x3F;
        if point_format > 10 {
            return Err(TerrainError::Unsupported {
                source: source.clone(),
                what: format!("byte 104: point data record format {point_format} (read: 0 to 10)"),
            });
        }
        let record_len = u16_at(&head, 105);
        let min_len = RECORD_LEN[point_format as usize];
        if record_len < min_len {
            return Err(bad(
                "byte 105 (point data record length)",
                format!("at least {min_len} bytes for format {point_format}, found {record_len}"),
            ));
        }
        let legacy_count = u32_at(&head, 107) as u64;
        let triple = |at: usize| {
            [
                f64_at(&head, at),
                f64_at(&head, at + 8),
                f64_at(&head, at + 16),
            ]
        };
        let scale = triple(131);
        let offset = triple(155);
        // Bounds are stored max x, min x, max y, min y, max z, min z.
        let b = triple(179);
        let b2 = triple(203);
        let (max, min) = ([b[0], b[2], b2[1]], [b[1], b2[0], b2[2]]);
        if !scale.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(bad(
                "byte 131 (scale factors)",
                format!("three finite factors > 0, found {scale:?}"),
            ));
        }
        if !offset.iter().all(|o| o.is_finite()) {
            return Err(bad(
                "byte 155 (offsets)",
                format!("three finite offsets, found {offset:?}"),
            ));
        }
        if !min.iter().chain(&max).all(|v| v.is_finite()) {
            return Err(bad(
                "byte 179 (bounding box)",
                format!("finite bounds, found min {min:?} max {max:?}"),
            ));
        }
        let (mut point_count, mut evlrs) = (legacy_count, None);
        if version.1 >= 4 {
            let count = u64_at(&head, 247);
            if count != 0 {
                if legacy_count != 0 && legacy_count != count {
                    return Err(bad(
                        "bytes 107 and 247 (point counts)",
                        format!(
                            "the legacy count equal to the 64-bit count or 0, found {legacy_count} \
                             and {count}"
                        ),
                    ));
                }
                point_count = count;
            }
            let n = u32_at(&head, 243);
            if n > 0 {
                evlrs = Some((u64_at(&head, 235), n));
            }
        }

        // An uncompressed file holds its points whole.
        let points_end = if compressed {
            None
        } else {
            let end = point_count
                .checked_mul(record_len as u64)
                .and_then(|n| n.checked_add(offset_to_points));
            match end {
                Some(e) if e <= len => Some(e),
                _ => {
                    let whole = (len - offset_to_points) / record_len as u64;
                    return Err(bad(
                        &format!(
                            "point {whole} at byte {}",
                            offset_to_points + whole * record_len as u64
                        ),
                        format!(
                            "{point_count} points of {record_len} bytes from byte \
                             {offset_to_points} (the header's count), the file ends at byte {len}"
                        ),
                    ));
                }
            }
        };

        // VLRs lie between the header and the points.
        let mut records = Records::default();
        let mut pos = header_size;
        for i in 0..vlr_count {
            if pos + VLR_HEADER > offset_to_points {
                return Err(bad(
                    &format!("VLR {i} at byte {pos}"),
                    format!(
                        "a {VLR_HEADER}-byte record header before the points at byte \
                         {offset_to_points} (the header lists {vlr_count} VLRs)"
                    ),
                ));
            }
            let h = read_at(&mut f, path, pos, VLR_HEADER as usize)?;
            let (user, id, n) = (text(&h[2..18]), u16_at(&h, 18), u16_at(&h, 20) as u64);
            let at = format!("VLR {i} ({user} {id}) at byte {pos}");
            let end = pos + VLR_HEADER + n;
            if end > offset_to_points {
                return Err(bad(
                    &at,
                    format!("its {n} bytes before the points at byte {offset_to_points}"),
                ));
            }
            if Records::wants(&user, id) {
                let data = read_at(&mut f, path, pos + VLR_HEADER, n as usize)?;
                records.keep(&user, id, data, at);
            }
            pos = end;
        }
        // EVLRs (LAS 1.4) follow the points.
        if let Some((start, n)) = evlrs {
            let first = points_end.unwrap_or(offset_to_points);
            if start < first || start > len {
                return Err(bad(
                    "byte 235 (start of first EVLR)",
                    format!(
                        "an offset from the points' end ({first}) to the file's end ({len}), \
                         found {start}"
                    ),
                ));
            }
            let mut pos = start;
            for i in 0..n {
                if pos.saturating_add(EVLR_HEADER) > len {
                    return Err(bad(
                        &format!("EVLR {i} at byte {pos}"),
                        format!(
                            "a {EVLR_HEADER}-byte record header inside the {len}-byte file (the \
                             header lists {n} EVLRs)"
                        ),
                    ));
                }
                let h = read_at(&mut f, path, pos, EVLR_HEADER as usize)?;
                let (user, id, size) = (text(&h[2..18]), u16_at(&h, 18), u64_at(&h, 20));
                let at = format!("EVLR {i} ({user} {id}) at byte {pos}");
                let end = (pos + EVLR_HEADER).saturating_add(size);
                if end > len {
                    return Err(bad(
                        &at,
                        format!("its {size} bytes inside the {len}-byte file"),
                    ));
                }
                if Records::wants(&user, id) && user != "laszip encoded" {
                    let data = read_at(&mut f, path, pos + EVLR_HEADER, size as usize)?;
                    records.keep(&user, id, data, at);
                }
                pos = end;
            }
        }

        // The coordinate system: the record the global encoding's WKT bit names first.
        let wkt_bit = u16_at(&head, 6) & 0x10 != 0 && version.1 >= 4;
        let from_keys = |(keys, at): &(Vec<u16>, String)| -> Result<_, TerrainError> {
            let k = GeoKeys::parse(keys, &source, at)?;
            let crs = match (k.model, k.epsg) {
                (Some(_), _) => k.crs(&source)?,
                (None, Some(_)) if k.projected_key => CrsKind::Projected,
                (None, Some(_)) => CrsKind::Geographic,
                (None, None) => CrsKind::Local,
            };
            Ok((crs, k.epsg, CrsRecord::GeoKeys))
        };
        let from_wkt = |(w, at): &(String, String)| -> Result<_, TerrainError> {
            let (crs, epsg) = crs_of_wkt(w).map_err(|e| format_err(&source, at, e))?;
            Ok((crs, epsg, CrsRecord::Wkt))
        };
        let (crs, epsg, crs_record) = match (&records.wkt, &records.geokeys) {
            (Some(w), _) if wkt_bit => from_wkt(w)?,
            (_, Some(k)) => from_keys(k)?,
            (Some(w), None) => from_wkt(w)?,
            (None, None) => (CrsKind::Local, None, CrsRecord::None),
        };

        let header = LasHeader {
            version,
            point_format,
            record_len,
            compressed,
            point_count,
            offset_to_points,
            scale,
            offset,
            min,
            max,
            crs,
            epsg,
            crs_record,
        };
        let body = if compressed {
            let Some((vlr, at)) = records.laszip.take() else {
                return Err(bad(
                    "VLRs",
                    "the LASzip record (laszip encoded 22204) of a compressed file".into(),
                ));
            };
            open_laz(f, path, &source, &header, &vlr, &at, len)?
        } else {
            f.seek(SeekFrom::Start(offset_to_points))
                .map_err(io(path))?;
            Body::Plain(BufReader::with_capacity(1 << 16, f))
        };
        let unset = min.iter().chain(&max).all(|&v| v == 0.0);
        let within = (!unset).then(|| {
            let m = (max[0] - min[0]).max(max[1] - min[1]).max(0.0) + scale[0].max(scale[1]);
            ([min[0] - m, min[1] - m], [max[0] + m, max[1] + m])
        });
        Ok(LasReader {
            source,
            header,
            body,
            next: 0,
            raw: Vec::new(),
            within,
        })
    }

    pub fn header(&self) -> &LasHeader {
        &self.header
    }

    /// The file's name, as errors give it.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Points read so far.
    pub fn points_read(&self) -> u64 {
        self.next
    }

    /// Decode the next points (at most [`BATCH`]) into `out`, which is cleared first; returns how
    /// many, 0 at the end of the file.
    pub fn read_batch(&mut self, out: &mut Vec<LasPoint>) -> Result<usize, TerrainError> {
        out.clear();
        let left = self.header.point_count - self.next;
        if left == 0 {
            return Ok(0);
        }
        let rl = self.header.record_len as usize;
        let n = match &self.body {
            // A LAZ batch stays inside one chunk, so an error names it.
            Body::Laz { chunks, .. } => {
                let k = chunk_of(chunks, self.next);
                let (first, points, _) = chunks[k];
                (first + points - self.next).min(BATCH as u64) as usize
            }
            Body::Plain(_) => left.min(BATCH as u64) as usize,
        };
        if n == 0 {
            return Ok(0);
        }
        self.raw.resize(n * rl, 0);
        let raw = &mut self.raw[..n * rl];
        match &mut self.body {
            Body::Plain(r) => r.read_exact(raw).map_err(|e| TerrainError::Io {
                path: self.source.clone().into(),
                source: e,
            })?,
            Body::Laz {
                dec: LazStream::Serial(dec),
                chunks,
            } => {
                if let Err(e) = dec.decompress_many(raw) {
                    let k = chunk_of(chunks, self.next);
                    return Err(format_err(
                        &self.source,
                        format!(
                            "points {}..{} (LAZ chunk {k} at byte {})",
                            self.next,
                            self.next + n as u64,
                            chunks[k].2
                        ),
                        format!("LASzip-compressed points ({e})"),
                    ));
                }
            }
            Body::Laz {
                dec:
                    LazStream::Parallel {
                        dec,
                        window,
                        served,
                    },
                chunks,
            } => {
                if *served == window.len() {
                    // The next window: whole chunks from the one holding the next point (windows
                    // and batches both end at chunk ends, so it starts one).
                    let k = chunk_of(chunks, self.next);
                    let end = (k + par_window()).min(chunks.len());
                    let points: u64 = chunks[k..end].iter().map(|c| c.1).sum();
                    window.resize(points as usize * rl, 0);
                    *served = 0;
                    if let Err(e) = dec.decompress_many(window) {
                        window.clear();
                        return Err(format_err(
                            &self.source,
                            format!(
                                "points {}..{} (LAZ chunks {k}..{} from byte {})",
                                self.next,
                                self.next + points,
                                end - 1,
                                chunks[k].2
                            ),
                            format!("LASzip-compressed points ({e})"),
                        ));
                    }
                }
                raw.copy_from_slice(&window[*served..*served + n * rl]);
                *served += n * rl;
            }
        }
        let h = &self.header;
        let six = h.point_format >= 6;
        out.reserve(n);
        out.extend(raw.chunks_exact(rl).map(|r| {
            let int =
                |at: usize| i32::from_le_bytes([r[at], r[at + 1], r[at + 2], r[at + 3]]) as f64;
            let (return_number, number_of_returns, class, withheld) = if six {
                (r[14] & 0x0F, r[14] >> 4, r[16], r[15] & 0x04 != 0)
            } else {
                (
                    r[14] & 0x07,
                    (r[14] >> 3) & 0x07,
                    r[15] & 0x1F,
                    r[15] & 0x80 != 0,
                )
            };
            LasPoint {
                x: int(0) * h.scale[0] + h.offset[0],
                y: int(4) * h.scale[1] + h.offset[1],
                z: int(8) * h.scale[2] + h.offset[2],
                class,
                return_number,
                number_of_returns,
                withheld,
            }
        }));
        // Every point inside the header's box, give or take the box's own size.
        if let Some((lo, hi)) = self.within
            && let Some(k) = out
                .iter()
                .position(|p| !(p.x >= lo[0] && p.x <= hi[0] && p.y >= lo[1] && p.y <= hi[1]))
        {
            let i = self.next + k as u64;
            let p = out[k];
            let at = match &self.body {
                Body::Plain(_) => format!(
                    "point {i} at byte {}",
                    h.offset_to_points + i * h.record_len as u64
                ),
                Body::Laz { chunks, .. } => {
                    let c = chunk_of(chunks, i);
                    format!("point {i} (LAZ chunk {c} at byte {})", chunks[c].2)
                }
            };
            return Err(format_err(
                &self.source,
                at,
                format!(
                    "x, y within the header's bounding box x {}..{}, y {}..{} (give or take its \
                     size), found ({}, {}): a damaged point, or a header its writer did not update",
                    h.min[0], h.max[0], h.min[1], h.max[1], p.x, p.y
                ),
            ));
        }
        self.next += n as u64;
        Ok(n)
    }
}

/// The chunk holding point `p` (chunks are in point order).
fn chunk_of(chunks: &[(u64, u64, u64)], p: u64) -> usize {
    chunks
        .partition_point(|&(first, _, _)| first <= p)
        .saturating_sub(1)
}

/// The system an OGC WKT record names: a projected system by its EPSG code (any code, as the
/// GeoTIFF reader takes any), the degrees of WGS 84, ETRS89 or NAD83, a compound system by its
/// horizontal part; anything else is refused with the reprojection hint.
fn crs_of_wkt(wkt: &str) -> Result<(CrsKind, Option<u16>), String> {
    let wkt = horizontal(wkt.trim());
    let head = wkt
        .split('[')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_uppercase();
    let code = crate::shapefile::wkt_epsg(wkt).and_then(|c| u16::try_from(c).ok());
    match crate::shapefile::crs_of_wkt(wkt, "pdal translate --filters.reprojection.out_srs=") {
        Ok(LayerCrs::Lonlat) => Ok((CrsKind::Geographic, Some(code.unwrap_or(4326)))),
        Ok(LayerCrs::Epsg(code, _)) => Ok((CrsKind::Projected, Some(code))),
        Err(_) if matches!(head.as_str(), "PROJCS" | "PROJCRS") && code.is_some() => {
            Ok((CrsKind::Projected, code))
        }
        Err(e) => Err(e),
    }
}

/// The horizontal system of a compound one (`COMPD_CS[..., PROJCS[...], VERT_CS[...]]`, WKT 2's
/// `COMPOUNDCRS`); any other system as it is.
fn horizontal(wkt: &str) -> &str {
    let head = wkt
        .split('[')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_uppercase();
    if !matches!(head.as_str(), "COMPD_CS" | "COMPOUNDCRS") {
        return wkt;
    }
    let starts = ["PROJCS[", "PROJCRS[", "GEOGCS[", "GEOGCRS[", "GEODCRS["];
    let Some(i) = starts.iter().filter_map(|k| wkt.find(k)).min() else {
        return wkt;
    };
    // Up to the bracket that closes it (brackets inside quoted names do not count).
    let (mut depth, mut quoted) = (0i32, false);
    for (j, &b) in wkt.as_bytes()[i..].iter().enumerate() {
        match b {
            b'"' => quoted = !quoted,
            b'[' if !quoted => depth += 1,
            b']' if !quoted => {
                depth -= 1;
                if depth == 0 {
                    return &wkt[i..=i + j];
                }
            }
            _ => {}
        }
    }
    wkt
}

/// Open the LASzip stream of a compressed file after checking what the `laz` crate trusts.
fn open_laz(
    mut f: File,
    path: &Path,
    source: &str,
    h: &LasHeader,
    vlr: &[u8],
    at: &str,
    len: u64,
) -> Result<Body, TerrainError> {
    let bad = |at: &str, expected: String| format_err(source, at, expected);
    // The LASzip record: compressor, coder, version, options, chunk size, two EVLR fields, then
    // (type, size, version) per item.
    if vlr.len() < LASZIP_FIXED {
        return Err(bad(
            at,
            format!(
                "a LASzip record of at least {LASZIP_FIXED} bytes, found {}",
                vlr.len()
            ),
        ));
    }
    let compressor = u16_at(vlr, 0);
    let items = u16_at(vlr, 32) as usize;
    if vlr.len() != LASZIP_FIXED + 6 * items || items == 0 || items > 16 {
        return Err(bad(
            at,
            format!(
                "1 to 16 items of 6 bytes after {LASZIP_FIXED} bytes, found {items} items in {} \
                 bytes",
                vlr.len()
            ),
        ));
    }
    let layered = match compressor {
        2 => false,
        3 => true,
        1 => {
            return Err(TerrainError::Unsupported {
                source: source.into(),
                what: format!(
                    "{at}: LASzip's unchunked compressor (LASzip 1; rewrite it with laszip or \
                     pdal translate)"
                ),
            });
        }
        c => {
            return Err(bad(
                at,
                format!("compressor 2 (chunked) or 3 (layered), found {c}"),
            ));
        }
    };
    // Every item of its compressor's family, of its type's size; the first is the point.
    let mut sum = 0u32;
    let mut layers = 0u64;
    for k in 0..items {
        let e = &vlr[LASZIP_FIXED + 6 * k..];
        let (ty, size, ver) = (u16_at(e, 0), u16_at(e, 2), u16_at(e, 4));
        let fixed: Option<u16> = match ty {
            0 | 14 => None,
            6 => Some(20),
            7 => Some(8),
            8 | 11 => Some(6),
            9 | 13 => Some(29),
            10 => Some(30),
            12 => Some(8),
            _ => return Err(bad(at, format!("item {k}: a LASzip item type, found {ty}"))),
        };
        let family_ok = if layered {
            (10..=14).contains(&ty) && (3..=4).contains(&ver)
        } else {
            matches!(ty, 0 | 6..=9) && (1..=2).contains(&ver)
        };
        let first_ok = k != 0 || ty == if layered { 10 } else { 6 };
        if !family_ok || !first_ok || fixed.is_some_and(|s| s != size) || size == 0 {
            return Err(bad(
                at,
                format!(
                    "item {k}: a {} item (type, size, version) consistent with the point format, \
                     found ({ty}, {size}, {ver})",
                    if layered { "layered" } else { "chunked" }
                ),
            ));
        }
        sum += size as u32;
        // Layers of a layered chunk: the point 9, RGB 1, RGB + NIR 2, wave packet 1, a byte each.
        layers += match ty {
            10 => 9,
            11 | 13 => 1,
            12 => 2,
            _ => size as u64,
        };
    }
    if sum != h.record_len as u32 {
        return Err(bad(
            at,
            format!(
                "items of {} bytes in all (the point record length), found {sum}",
                h.record_len
            ),
        ));
    }
    let laz_vlr =
        laz::LazVlr::from_buffer(vlr).map_err(|e| bad(at, format!("a LASzip record ({e})")))?;
    let chunk_size = laz_vlr.chunk_size();
    let variable = laz_vlr.uses_variable_size_chunks();

    // The chunk table's offset: the 8 bytes before the chunks, or, where a writer could not
    // seek back, the file's last 8 bytes (as LASzip and the laz crate look for it).
    let start = h.offset_to_points;
    if start + 8 > len {
        return Err(bad(
            &format!("byte {start} (chunk table offset)"),
            format!("8 bytes inside the {len}-byte file"),
        ));
    }
    let mut table = u64_at(&read_at(&mut f, path, start, 8)?, 0) as i64;
    if table <= start as i64 {
        table = u64_at(&read_at(&mut f, path, len - 8, 8)?, 0) as i64;
    }
    let data = start + 8;
    if table < data as i64 || (table as u64).saturating_add(8) > len {
        return Err(bad(
            &format!("byte {start} (chunk table offset)"),
            format!(
                "the chunk table's offset, after the chunks at byte {data} and inside the \
                 {len}-byte file (a cut or unfinished LAZ file has none), found {table}"
            ),
        ));
    }
    let table = table as u64;
    let n_chunks = u32_at(&read_at(&mut f, path, table, 8)?, 4) as u64;
    // Each chunk begins with a whole raw point.
    let most = (table - data) / h.record_len as u64;
    if n_chunks > most {
        return Err(bad(
            &format!("chunk table at byte {table}"),
            format!(
                "at most {most} chunks in {} compressed bytes, found {n_chunks}",
                table - data
            ),
        ));
    }
    f.seek(SeekFrom::Start(start)).map_err(io(path))?;
    let mut reader = BufReader::new(f);
    let entries = laz::laszip::ChunkTable::read_from(&mut reader, &laz_vlr).map_err(|e| {
        bad(
            &format!("chunk table at byte {table}"),
            format!("a LASzip chunk table ({e})"),
        )
    })?;
    let entries: Vec<laz::laszip::ChunkTableEntry> = entries.as_ref().to_vec();
    if entries.len() as u64 != n_chunks {
        return Err(bad(
            &format!("chunk table at byte {table}"),
            format!("{n_chunks} entries, decoded {}", entries.len()),
        ));
    }
    // The chunks fill the compressed bytes and hold the header's points.
    let bytes = entries
        .iter()
        .fold(0u64, |s, e| s.saturating_add(e.byte_count));
    if bytes != table - data {
        return Err(bad(
            &format!("chunk table at byte {table}"),
            format!(
                "chunks of {} bytes in all (from byte {data} to the table), their sizes add \
                 up to {bytes}",
                table - data
            ),
        ));
    }
    let mut chunks = Vec::with_capacity(entries.len());
    let (mut first, mut byte) = (0u64, data);
    for (k, e) in entries.iter().enumerate() {
        let points = if variable {
            e.point_count
        } else {
            (h.point_count - first.min(h.point_count)).min(chunk_size as u64)
        };
        if points == 0 || e.byte_count < h.record_len as u64 {
            return Err(bad(
                &format!("chunk table at byte {table}"),
                format!(
                    "chunk {k} of at least one point and {} bytes (the header claims {} points), \
                     found {points} points in {} bytes",
                    h.record_len, h.point_count, e.byte_count
                ),
            ));
        }
        chunks.push((first, points, byte));
        first = first.saturating_add(points);
        byte += e.byte_count;
    }
    if first != h.point_count {
        return Err(bad(
            &format!("chunk table at byte {table}"),
            format!(
                "chunks holding the header's {} points, they hold {first}",
                h.point_count
            ),
        ));
    }
    // A layered chunk: its first point raw, a point count, then the byte size of every layer,
    // which the decompressor allocates before it reads them.
    if layered {
        let f = reader.get_mut();
        for (k, (e, &(_, _, at_byte))) in entries.iter().zip(&chunks).enumerate() {
            let head = h.record_len as u64 + 4;
            let sizes_end = head + 4 * layers;
            if sizes_end > e.byte_count {
                return Err(bad(
                    &format!("LAZ chunk {k} at byte {at_byte}"),
                    format!(
                        "{sizes_end} bytes of first point and layer sizes in its {} bytes",
                        e.byte_count
                    ),
                ));
            }
            let sizes = read_at(f, path, at_byte + head, 4 * layers as usize)?;
            let total = sizes
                .chunks_exact(4)
                .fold(0u64, |s, c| s + u32_at(c, 0) as u64);
            if sizes_end + total > e.byte_count {
                return Err(bad(
                    &format!("LAZ chunk {k} at byte {at_byte}"),
                    format!(
                        "layers inside its {} bytes, their sizes add up to {total} after \
                         {sizes_end}",
                        e.byte_count
                    ),
                ));
            }
        }
    }
    reader.seek(SeekFrom::Start(start)).map_err(io(path))?;
    let opened =
        |e: laz::LasZipError| bad(at, format!("a LASzip stream the decompressor opens ({e})"));
    let dec = if chunks.len() > 1 && chunks.iter().all(|c| c.1 <= PAR_CHUNK) {
        LazStream::Parallel {
            dec: Box::new(laz::ParLasZipDecompressor::new(reader, laz_vlr).map_err(opened)?),
            window: Vec::new(),
            served: 0,
        }
    } else {
        LazStream::Serial(Box::new(
            laz::LasZipDecompressor::new(reader, laz_vlr).map_err(opened)?,
        ))
    };
    Ok(Body::Laz { dec, chunks })
}
