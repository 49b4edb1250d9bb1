//! GROMACS XTC trajectories: a panic-free decoder of the compressed coordinates over
//! `Read + Seek`, and a writer built on molly's compressor.
//!
//! # Layout
//! Every value is XDR (big-endian, 4-byte aligned). One frame:
//!
//! ```text
//! i32 magic (1995, or 2023 for the 64-bit byte count)   i32 natoms   i32 step   f32 time (ps)
//! 9 f32 box vectors (rows, nm)   i32 natoms again
//! natoms <= 9: 3 natoms f32 coordinates (nm), uncompressed
//! otherwise:   f32 precision   3 i32 minint   3 i32 maxint   i32 smallidx
//!              byte count (u32 for 1995, u64 for 2023)   the bytes, padded to 4
//! ```
//!
//! The compressed stream is a big-endian bit stream. Coordinates are integers
//! `round(x · precision)`; a "large" triple is an offset from `minint` packed as one mixed-radix
//! number (radices `maxint - minint + 1`), or three plain bit fields when a radix exceeds 2^24.
//! After it, one flag bit and a 5-bit run length announce a run of "small" triples: differences
//! from the previous atom, packed with radix `MAGICINTS[smallidx]`, where `smallidx` moves by
//! ±1 after each large triple. The first two atoms of a run are swapped back (the writer swaps
//! them so that water's O-H-H compresses better).
//!
//! # Design
//! molly (the pure-Rust XTC crate) decodes as fast, but it asserts and indexes on the file's
//! values, so a flipped byte can panic; this decoder validates every value that sizes or indexes
//! something (natoms, smallidx, the radices, the byte count) and reads bits from a buffer padded
//! by [`PAD`] bytes with one bound check per large triple, so a corrupt stream gives an
//! [`Error::Parse`] naming the frame and the byte, never a panic. Bits are read with one
//! unaligned big-endian u64 load per field; the bytes of a packed number come least significant
//! first, so a whole run of them is read at once and byte-swapped.
//!
//! Frames have no index: it is built at open time by reading each frame's header and byte count
//! and seeking over the data. Coordinates are converted nm → Å as `(i as f32 · (1/precision)) ·
//! 10`, the same f32 operations as xdrfile followed by MDAnalysis's unit conversion.
//!
//! # References
//! - GROMACS `xdrfile.c`, `xdr3dfcoord` (the format's reference implementation; read, not copied)
//! - molly 0.7 (used for writing, and in tests as an independent decoder)

use std::io::{self, Read, Seek, SeekFrom, Write};
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, all_in_bounds, cell_of, first_out_of_bounds};
use crate::error::{Error, Location};
use crate::frame::Frame;

/// Magic number of the classic format (32-bit byte count).
pub const MAGIC_1995: i32 = 1995;
/// Magic number of the GROMACS 2023 format (64-bit byte count).
pub const MAGIC_2023: i32 = 2023;
/// Bytes of the frame header (magic .. natoms again).
const HEADER: usize = 56;
/// Bytes of precision + minint + maxint + smallidx.
const PRELUDE: usize = 32;
/// Zero bytes after the compressed stream: one large triple plus a full run reads at most
/// 96 + 6 + 10 x 72 bits = 103 bytes, plus the 8-byte load.
const PAD: usize = 128;
/// Smallest valid `smallidx` (MAGICINTS[8] is 0).
const FIRSTIDX: usize = 9;
/// nm → Å.
const NM: f32 = 10.0;
/// Fewest bits one atom can take in a compressed stream. Each step of [`Decoder::decode`] reads
/// a large triple (at least 1 bit: a product of radices ≥ 1) and a run flag (1 bit) and gives one
/// atom, or reads k ≥ 1 more small triples of `smallidx` ≥ 9 bits and gives k + 1 atoms: never
/// fewer than 2 bits an atom, and the decoder rejects a stream that ends past its byte count.
/// So `natoms ≤ 8 · nbytes / 2` holds in every frame that decodes, and the atom count is checked
/// against it before the position buffer is sized (a header claiming 2^31 atoms over a few
/// bytes would otherwise ask for 24 GiB).
const MIN_BITS_PER_ATOM: u64 = 2;
/// Precisions (1/nm) the reader accepts: GROMACS writes 1000, users 10..=10^6; a value outside
/// this range is a damaged header, not a choice (1e-30 would turn every integer into ~1e31 Å).
const PRECISION_RANGE: std::ops::RangeInclusive<f32> = 1e-3..=1e9;

/// Radices of the small differences: MAGICINTS[i] ~ 2^(i/3), so three of them fit in i bits.
#[rustfmt::skip]
const MAGICINTS: [u32; 73] = [
    0, 0, 0, 0, 0, 0, 0, 0, 0, 8, 10, 12, 16, 20, 25, 32, 40, 50, 64,
    80, 101, 128, 161, 203, 256, 322, 406, 512, 645, 812, 1024, 1290,
    1625, 2048, 2580, 3250, 4096, 5060, 6501, 8192, 10321, 13003,
    16384, 20642, 26007, 32768, 41285, 52015, 65536, 82570, 104031,
    131072, 165140, 208063, 262144, 330280, 416127, 524287, 660561,
    832255, 1048576, 1321122, 1664510, 2097152, 2642245, 3329021,
    4194304, 5284491, 6658042, 8388607, 10568983, 13316085, 16777216,
];

/// Header values of one XTC frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct XtcFrameInfo {
    /// MD step.
    pub step: i64,
    /// Time in ps.
    pub time: f64,
    /// Box vectors as rows, in Å (all zero when the file has no box).
    pub box_vectors: [[f64; 3]; 3],
    /// Precision (1/nm) of the compressed coordinates; 0 for uncompressed frames (≤ 9 atoms).
    pub precision: f32,
}

/// One frame of the index.
#[derive(Clone, Copy, Debug)]
struct Entry {
    offset: u64,
    size: u64,
}

/// Reads an XTC file frame by frame, in any order.
#[derive(Debug)]
pub struct XtcReader<R> {
    src: R,
    file: Arc<str>,
    n_atoms: usize,
    frames: Vec<Entry>,
    /// Why the index stopped before the end of the file, if it did.
    tail: Option<Error>,
    buf: Vec<u8>,
    pos: u64,
    /// The frame `read_next` reads.
    next: usize,
}

fn be_u32(b: &[u8], at: usize) -> u32 {
    u32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn be_i32(b: &[u8], at: usize) -> i32 {
    be_u32(b, at) as i32
}

fn be_f32(b: &[u8], at: usize) -> f32 {
    f32::from_bits(be_u32(b, at))
}

fn io_error(file: &Arc<str>, frame: usize, byte: u64, source: io::Error) -> Error {
    Error::Io {
        at: Location::binary(file, frame, byte),
        source,
    }
}

/// Checks the magic number and the two atom counts of a header: (magic, natoms).
fn check_counts(
    head: &[u8],
    file: &Arc<str>,
    frame: usize,
    offset: u64,
) -> Result<(i32, usize), Error> {
    let parse = |at: usize, expected: &'static str, found: String| Error::Parse {
        at: Location::binary(file, frame, offset + at as u64),
        expected,
        found,
    };
    let magic = be_i32(head, 0);
    if magic != MAGIC_1995 && magic != MAGIC_2023 {
        return Err(parse(0, "XTC magic number 1995 or 2023", magic.to_string()));
    }
    let natoms = be_i32(head, 4);
    let again = be_i32(head, HEADER - 4);
    if natoms <= 0 || natoms != again {
        return Err(parse(
            HEADER - 4,
            "the atom count twice, equal and > 0",
            format!("{natoms} and {again}"),
        ));
    }
    Ok((magic, natoms as usize))
}

/// What a frame header says: (magic, natoms, size of the whole frame in bytes).
fn frame_size(
    head: &[u8],
    file: &Arc<str>,
    frame: usize,
    offset: u64,
) -> Result<(i32, usize, u64), Error> {
    let parse = |at: usize, expected: &'static str, found: String| Error::Parse {
        at: Location::binary(file, frame, offset + at as u64),
        expected,
        found,
    };
    let (magic, natoms) = check_counts(head, file, frame, offset)?;
    if natoms <= 9 {
        return Ok((magic, natoms, (HEADER + 12 * natoms) as u64));
    }
    let count_at = HEADER + PRELUDE;
    let (nbytes, count_len) = if magic == MAGIC_2023 {
        let hi = u64::from(be_u32(head, count_at));
        let lo = u64::from(be_u32(head, count_at + 4));
        ((hi << 32) | lo, 8)
    } else {
        (u64::from(be_u32(head, count_at)), 4)
    };
    // A byte count beyond any sane size is corruption, not a big file.
    if nbytes > (natoms as u64) * 64 + 1024 {
        return Err(parse(
            count_at,
            "a compressed byte count below 64 bytes per atom",
            nbytes.to_string(),
        ));
    }
    // And an atom count the stream cannot hold is corruption too, caught here, before anything
    // is sized from it: every atom costs the decoder at least `MIN_BITS_PER_ATOM` bits.
    if natoms as u64 > nbytes.saturating_mul(8) / MIN_BITS_PER_ATOM {
        return Err(parse(
            4,
            "an atom count the compressed stream can hold (at most 4 per byte)",
            format!("{natoms} atoms in {nbytes} bytes"),
        ));
    }
    let padded = nbytes.div_ceil(4) * 4;
    Ok((magic, natoms, (count_at + count_len) as u64 + padded))
}

impl<R: Read + Seek> XtcReader<R> {
    /// Opens an XTC stream and indexes its frames (reads every frame header, skips the data).
    ///
    /// A damaged or partial frame stops the index: the frames before it stay readable and
    /// [`XtcReader::truncation`] tells what went wrong where.
    pub fn new(mut src: R, file: Arc<str>) -> Result<Self, Error> {
        let file_len = src
            .seek(SeekFrom::End(0))
            .map_err(|e| io_error(&file, 0, 0, e))?;
        let mut frames = Vec::new();
        let mut n_atoms = 0;
        let mut tail = None;
        let mut offset = 0u64;
        let mut head = [0u8; HEADER + PRELUDE + 8];
        while offset < file_len {
            let frame = frames.len();
            // Read the header, prelude and byte count (as much as the file has).
            let want = ((file_len - offset) as usize).min(head.len());
            src.seek(SeekFrom::Start(offset))
                .and_then(|_| src.read_exact(&mut head[..want]))
                .map_err(|e| io_error(&file, frame, offset, e))?;
            if want < HEADER {
                tail = Some(Error::Truncated {
                    at: Location::binary(&file, frame, file_len),
                    expected: format!("{HEADER}-byte frame header from byte {offset}"),
                });
                break;
            }
            let natoms = be_i32(&head, 4);
            let compressed = natoms > 9;
            let min_needed = if compressed {
                if be_i32(&head, 0) == MAGIC_2023 {
                    HEADER + PRELUDE + 8
                } else {
                    HEADER + PRELUDE + 4
                }
            } else {
                HEADER
            };
            // A corrupt header is not blamed on the length.
            if let Err(e) = check_counts(&head, &file, frame, offset) {
                tail = Some(e);
                break;
            }
            if want < min_needed {
                tail = Some(Error::Truncated {
                    at: Location::binary(&file, frame, file_len),
                    expected: format!("{min_needed}-byte frame header from byte {offset}"),
                });
                break;
            }
            let (_, natoms, size) = match frame_size(&head, &file, frame, offset) {
                Ok(v) => v,
                Err(e) => {
                    tail = Some(e);
                    break;
                }
            };
            if frames.is_empty() {
                n_atoms = natoms;
            } else if natoms != n_atoms {
                tail = Some(Error::Parse {
                    at: Location::binary(&file, frame, offset + 4),
                    expected: "the same atom count in every frame",
                    found: format!("{natoms} atoms after {n_atoms}"),
                });
                break;
            }
            if offset + size > file_len {
                tail = Some(Error::Truncated {
                    at: Location::binary(&file, frame, file_len),
                    expected: format!(
                        "{} more bytes (frame of {size} bytes starting at byte {offset})",
                        offset + size - file_len
                    ),
                });
                break;
            }
            frames.push(Entry { offset, size });
            offset += size;
        }
        if frames.is_empty()
            && let Some(e) = tail
        {
            return Err(e);
        }
        Ok(XtcReader {
            src,
            file,
            n_atoms,
            frames,
            tail,
            buf: Vec::new(),
            pos: u64::MAX,
            next: 0,
        })
    }

    /// Atoms per frame (0 for an empty file).
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn n_atoms(&self) -> usize {
        self.n_atoms
    }

    /// The number of complete frames before the end of the file or the first damaged frame.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Why indexing stopped before the end of the file, if it did (the error of frame
    /// [`XtcReader::frame_count`]).
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn truncation(&self) -> Option<&Error> {
        self.tail.as_ref()
    }

    /// Byte offset of frame `index`.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn frame_offset(&self, index: usize) -> Option<u64> {
        self.frames.get(index).map(|e| e.offset)
    }

    /// Reads frame `index`: positions in Å into `positions`, header values returned.
    pub fn read_frame(
        &mut self,
        index: usize,
        positions: &mut Vec<[f32; 3]>,
    ) -> Result<XtcFrameInfo, Error> {
        let Some(&Entry { offset, size }) = self.frames.get(index) else {
            if index == self.frames.len()
                && let Some(e) = &self.tail
            {
                return Err(clone_error(e));
            }
            return Err(Error::FrameOutOfRange {
                file: self.file.clone(),
                requested: index,
                n_frames: self.frames.len(),
            });
        };
        // Read the frame, then pad it so the bit reader never leaves the buffer.
        if self.pos != offset {
            self.src
                .seek(SeekFrom::Start(offset))
                .map_err(|e| io_error(&self.file, index, offset, e))?;
        }
        self.pos = u64::MAX;
        self.buf.clear();
        self.buf.resize(size as usize + PAD, 0);
        self.src
            .read_exact(&mut self.buf[..size as usize])
            .map_err(|e| match e.kind() {
                io::ErrorKind::UnexpectedEof => Error::Truncated {
                    at: Location::binary(&self.file, index, offset),
                    expected: format!("{size} bytes of XTC frame"),
                },
                _ => io_error(&self.file, index, offset, e),
            })?;
        self.pos = offset + size;
        decode_frame(
            &self.buf,
            size as usize,
            &self.file,
            index,
            offset,
            positions,
        )
    }

    /// Reads the next frame into `frame` (the `Trajectory` contract). `Ok(false)` after the
    /// last frame; on error the frame is left empty and the reader stays at the damaged frame.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        let index = self.next;
        if index >= self.frames.len() && self.tail.is_none() {
            return Ok(false);
        }
        let r = self
            .read_frame(index, &mut frame.positions)
            .and_then(|info| {
                let offset = self.frames[index].offset;
                frame.step = Some(info.step);
                frame.time = Some(info.time);
                cell_of(info.box_vectors, &self.file, index, offset + 16)
            });
        crate::cursor::settle(r, frame, &mut self.next)
    }

    /// Makes `read_next` read frame `n`; `Ok(false)` if there is no frame `n` (a damaged frame
    /// right after the last good one counts as present, so that reading it reports the damage).
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        Ok(crate::cursor::seek(
            &mut self.next,
            n,
            self.frames.len(),
            self.tail.is_some(),
        ))
    }

    /// Number of frames (the `Trajectory` contract; the index is built at open time). A damaged
    /// or cut frame after the good ones is that frame's error, not a shorter count: nothing is
    /// dropped silently.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        match &self.tail {
            Some(e) => Err(clone_error(e)),
            None => Ok(self.frames.len()),
        }
    }
}

/// A copy of an error kept for re-reporting (io errors keep their kind and message).
pub(crate) fn clone_error(e: &Error) -> Error {
    match e {
        Error::Parse {
            at,
            expected,
            found,
        } => Error::Parse {
            at: at.clone(),
            expected,
            found: found.clone(),
        },
        Error::Truncated { at, expected } => Error::Truncated {
            at: at.clone(),
            expected: expected.clone(),
        },
        Error::Io { at, source } => Error::Io {
            at: at.clone(),
            source: io::Error::new(source.kind(), source.to_string()),
        },
        other => Error::InvalidValue {
            what: other.to_string(),
        },
    }
}

/// Decodes one frame held in `buf[..size]` (followed by `PAD` zero bytes).
fn decode_frame(
    buf: &[u8],
    size: usize,
    file: &Arc<str>,
    index: usize,
    offset: u64,
    positions: &mut Vec<[f32; 3]>,
) -> Result<XtcFrameInfo, Error> {
    let parse = |at: usize, expected: &'static str, found: String| Error::Parse {
        at: Location::binary(file, index, offset + at as u64),
        expected,
        found,
    };
    // Header: checked again, the file may have changed since indexing.
    let (magic, natoms, want) = frame_size(buf, file, index, offset)?;
    if want as usize != size {
        return Err(parse(
            4,
            "the frame size seen when indexing",
            want.to_string(),
        ));
    }
    let step = i64::from(be_i32(buf, 8));
    let time = f64::from(be_f32(buf, 12));
    let mut box_vectors = [[0.0; 3]; 3];
    for (k, v) in box_vectors.as_flattened_mut().iter_mut().enumerate() {
        *v = f64::from(be_f32(buf, 16 + 4 * k) * NM);
    }
    if !box_vectors.as_flattened().iter().all(|v| v.is_finite()) {
        return Err(parse(16, "finite box vectors", format!("{box_vectors:?}")));
    }
    positions.clear();
    positions.resize(natoms, [0.0; 3]);

    let precision = if natoms <= 9 {
        // Few atoms: plain floats.
        for (k, p) in positions.iter_mut().enumerate() {
            for (d, v) in p.iter_mut().enumerate() {
                *v = be_f32(buf, HEADER + 12 * k + 4 * d) * NM;
            }
        }
        0.0
    } else {
        let precision = be_f32(buf, HEADER);
        let inv = 1.0 / precision;
        if !(PRECISION_RANGE.contains(&precision) && inv.is_finite()) {
            return Err(parse(
                HEADER,
                "a precision in 1e-3..=1e9 per nm",
                precision.to_string(),
            ));
        }
        let minint = [0, 1, 2].map(|k| be_i32(buf, HEADER + 4 + 4 * k));
        let maxint = [0, 1, 2].map(|k| be_i32(buf, HEADER + 16 + 4 * k));
        let smallidx = be_i32(buf, HEADER + 28);
        if !(FIRSTIDX as i32..MAGICINTS.len() as i32).contains(&smallidx) {
            return Err(parse(
                HEADER + 28,
                "smallidx in 9..=72",
                smallidx.to_string(),
            ));
        }
        let mut sizes = [0u32; 3];
        for k in 0..3 {
            let s = i64::from(maxint[k]) - i64::from(minint[k]) + 1;
            if !(1..=i64::from(u32::MAX)).contains(&s) {
                return Err(parse(
                    HEADER + 4 + 4 * k,
                    "minint <= maxint",
                    format!("{} and {}", minint[k], maxint[k]),
                ));
            }
            sizes[k] = s as u32;
        }
        let count_len = if magic == MAGIC_2023 { 8 } else { 4 };
        let data_at = HEADER + PRELUDE + count_len;
        let nbytes = size - data_at - (size - data_at) % 4; // padded length
        let nbytes_exact = if magic == MAGIC_2023 {
            be_u32(buf, HEADER + PRELUDE + 4) as usize
        } else {
            be_u32(buf, HEADER + PRELUDE) as usize
        };
        debug_assert!(nbytes_exact <= nbytes);
        let mut ints = Decoder {
            bits: Bits {
                data: &buf[data_at..],
                pos: 0,
            },
            limit: 8 * nbytes_exact,
        };
        let scale = Scale { inv };
        ints.decode(positions, minint, sizes, smallidx as usize, scale)
            .map_err(|(atom, why)| {
                parse(
                    data_at + ints.bits.pos / 8,
                    "a valid compressed coordinate stream",
                    format!("atom {atom}: {why}"),
                )
            })?;
        precision
    };
    if !all_in_bounds(positions) {
        let bad = first_out_of_bounds(positions).unwrap_or(0);
        return Err(parse(
            HEADER,
            IN_BOUNDS,
            format!("atom {bad}: {:?}", positions[bad]),
        ));
    }
    Ok(XtcFrameInfo {
        step,
        time,
        box_vectors,
        precision,
    })
}

/// Big-endian bit reader over a buffer followed by `PAD` zero bytes.
struct Bits<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Bits<'_> {
    /// The next `n` bits (1 ≤ n ≤ 56), most significant first.
    #[inline(always)]
    fn read(&mut self, n: u32) -> u64 {
        debug_assert!((1..=56).contains(&n));
        let byte = self.pos >> 3;
        // In bounds by the check per large triple; `get` keeps a corrupt stream from panicking.
        let w = match self.data.get(byte..byte + 8) {
            Some(b) => u64::from_be_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
            None => 0,
        };
        let v = (w << (self.pos & 7)) >> (64 - n);
        self.pos += n as usize;
        v
    }

    /// A packed number of `nbits` bits whose bytes come least significant first
    /// (xdrfile `receiveints`), for nbits ≤ 63.
    #[inline(always)]
    fn read_le(&mut self, nbits: u32) -> u64 {
        let full = nbits / 8;
        let rem = nbits % 8;
        let mut v = 0u64;
        if full > 0 {
            // All full bytes in one load, then reversed into little-endian order.
            let x = self.read(8 * full);
            v = x.swap_bytes() >> (64 - 8 * full);
        }
        if rem > 0 {
            v |= self.read(rem) << (8 * full);
        }
        v
    }

    /// The same for nbits of 64..=96 (radices near 2^24).
    fn read_le_wide(&mut self, mut nbits: u32) -> u128 {
        let mut v = 0u128;
        let mut shift = 0;
        while nbits >= 8 {
            v |= u128::from(self.read(8)) << shift;
            shift += 8;
            nbits -= 8;
        }
        if nbits > 0 {
            v |= u128::from(self.read(nbits)) << shift;
        }
        v
    }
}

/// Unpacks a mixed-radix triple: v = (x · sy + y) · sz + z.
#[inline(always)]
fn unpack(bits: &mut Bits<'_>, nbits: u32, sizes: [u32; 3]) -> [i32; 3] {
    if nbits <= 32 {
        let v = bits.read_le(nbits) as u32;
        let (sy, sz) = (sizes[1], sizes[2]);
        let szy = sz.wrapping_mul(sy).max(1);
        let x = v / szy;
        let r = v - x * szy;
        let y = r / sz;
        let z = r - y * sz;
        [x as i32, y as i32, z as i32]
    } else if nbits <= 63 {
        let v = bits.read_le(nbits);
        let (sy, sz) = (u64::from(sizes[1]), u64::from(sizes[2]));
        let x = v / (sy * sz);
        let r = v - x * sy * sz;
        let y = r / sz;
        [x as i32, y as i32, (r - y * sz) as i32]
    } else {
        let v = bits.read_le_wide(nbits);
        let (sy, sz) = (u128::from(sizes[1]), u128::from(sizes[2]));
        let x = v / (sy * sz);
        let r = v - x * sy * sz;
        let y = r / sz;
        [x as i32, y as i32, (r - y * sz) as i32]
    }
}

/// Bit length of the product of three radices (xdrfile `sizeofints`).
fn bits_of_product(sizes: [u32; 3]) -> u32 {
    let p = u128::from(sizes[0]) * u128::from(sizes[1]) * u128::from(sizes[2]);
    128 - p.leading_zeros()
}

/// Integer → Å conversion.
#[derive(Clone, Copy)]
struct Scale {
    inv: f32,
}

impl Scale {
    #[inline(always)]
    fn apply(self, c: [i32; 3]) -> [f32; 3] {
        c.map(|v| (v as f32 * self.inv) * NM)
    }
}

struct Decoder<'a> {
    bits: Bits<'a>,
    /// Bits in the stream (without the padding).
    limit: usize,
}

impl Decoder<'_> {
    /// xdrfile `xdr3dfcoord`, decompression half, with every index and size checked.
    fn decode(
        &mut self,
        out: &mut [[f32; 3]],
        minint: [i32; 3],
        sizes: [u32; 3],
        mut smallidx: usize,
        scale: Scale,
    ) -> Result<(), (usize, &'static str)> {
        let natoms = out.len();
        // Choose the large-triple kernel: packed, or three bit fields for radices > 2^24.
        let large = sizes.iter().any(|&s| s > 0xff_ffff);
        let bitsize = bits_of_product(sizes);
        let field_bits = sizes.map(|s| 32 - s.leading_zeros());
        if !large && bitsize > 96 {
            return Err((0, "packed triple wider than 96 bits"));
        }
        let mut smaller = MAGICINTS[(smallidx - 1).max(FIRSTIDX)] / 2;
        let mut smallnum = MAGICINTS[smallidx] / 2;
        let mut sizesmall = MAGICINTS[smallidx];
        let mut run: u32 = 0;
        let mut i = 0;
        while i < natoms {
            // One bound check per large triple: everything up to the next one fits in PAD.
            if self.bits.pos > self.limit {
                return Err((i, "the stream ends before the last atom"));
            }
            // Read the large triple.
            let mut this = if large {
                [
                    self.bits.read(field_bits[0]) as i32,
                    self.bits.read(field_bits[1]) as i32,
                    self.bits.read(field_bits[2]) as i32,
                ]
            } else {
                unpack(&mut self.bits, bitsize, sizes)
            };
            for k in 0..3 {
                this[k] = this[k].wrapping_add(minint[k]);
            }
            let mut prev = this;
            // Read the run flag and length (a run length stays in force until the next flag).
            let mut is_smaller = 0i32;
            if self.bits.read(1) == 1 {
                let r = self.bits.read(5) as u32;
                is_smaller = (r % 3) as i32 - 1;
                run = r - r % 3;
            }
            if run > 0 {
                let n_small = (run / 3) as usize;
                if i + 1 + n_small > natoms {
                    return Err((i, "a run of small differences past the last atom"));
                }
                let small = [sizesmall; 3];
                for k in 0..n_small {
                    // Read a small difference from the previous atom.
                    let d = unpack(&mut self.bits, smallidx as u32, small);
                    let mut c = [0i32; 3];
                    for a in 0..3 {
                        c[a] = d[a].wrapping_add(prev[a]).wrapping_sub(smallnum as i32);
                    }
                    if k == 0 {
                        // Swap the first two atoms back (water: O-H-H stored as H-O-H).
                        std::mem::swap(&mut c, &mut prev);
                        out[i] = scale.apply(prev);
                        i += 1;
                    } else {
                        prev = c;
                    }
                    out[i] = scale.apply(c);
                    i += 1;
                }
            } else {
                out[i] = scale.apply(this);
                i += 1;
            }
            // Adapt the small radix.
            let next = smallidx as i32 + is_smaller;
            if !(FIRSTIDX as i32..MAGICINTS.len() as i32).contains(&next) {
                return Err((i, "smallidx leaves 9..=72"));
            }
            smallidx = next as usize;
            if is_smaller < 0 {
                smallnum = smaller;
                smaller = if smallidx > FIRSTIDX {
                    MAGICINTS[smallidx - 1] / 2
                } else {
                    0
                };
            } else if is_smaller > 0 {
                smaller = smallnum;
                smallnum = MAGICINTS[smallidx] / 2;
            }
            sizesmall = MAGICINTS[smallidx];
        }
        if self.bits.pos > self.limit {
            return Err((natoms, "the stream ends before the last atom"));
        }
        Ok(())
    }
}

/// Writes XTC files (magic 1995) with molly's compressor.
#[derive(Debug)]
pub struct XtcWriter<W> {
    pub(crate) out: W,
    file: Arc<str>,
    n_atoms: Option<usize>,
    n_written: usize,
    nm: Vec<f32>,
    /// Precision in 1/nm (1000 = GROMACS default: 0.001 nm = 0.01 Å).
    precision: f32,
}

impl<W: Write> XtcWriter<W> {
    /// An XTC writer with `precision` in 1/nm (GROMACS writes 1000).
    pub fn new(out: W, file: Arc<str>, precision: f32) -> Result<Self, Error> {
        if !(precision.is_finite() && (1.0..=1e6).contains(&precision)) {
            return Err(Error::InvalidValue {
                what: format!("XTC precision {precision} (must be in 1..=1e6 per nm)"),
            });
        }
        Ok(XtcWriter {
            out,
            file,
            n_atoms: None,
            n_written: 0,
            nm: Vec::new(),
            precision,
        })
    }

    /// Appends a frame: positions in Å, box rows in Å (`None`: zero box), step and time (ps).
    pub fn write_positions(
        &mut self,
        positions: &[[f32; 3]],
        box_vectors: Option<[[f64; 3]; 3]>,
        step: i64,
        time: f64,
    ) -> Result<(), Error> {
        let frame = self.n_written;
        let invalid = |what: String| Error::InvalidFrame {
            file: self.file.clone(),
            frame,
            what,
        };
        if positions.is_empty() || positions.len() > i32::MAX as usize / 3 {
            return Err(invalid(format!("{} atoms", positions.len())));
        }
        if let Some(n) = self.n_atoms
            && n != positions.len()
        {
            return Err(invalid(format!(
                "{} atoms, earlier frames had {n}",
                positions.len()
            )));
        }
        // Coordinates must fit i32 after scaling (with margin for molly's differences).
        let max = (i32::MAX / 4) as f32 / self.precision * NM;
        if !positions
            .as_flattened()
            .iter()
            .all(|v| v.is_finite() && v.abs() < max)
        {
            return Err(invalid(format!(
                "a coordinate is not finite or beyond ±{max} Å at precision {}",
                self.precision
            )));
        }
        let step = u32::try_from(step).map_err(|_| invalid(format!("step {step}")))?;
        let boxvec = box_vectors.unwrap_or([[0.0; 3]; 3]);
        if !boxvec.as_flattened().iter().all(|v| v.is_finite()) {
            return Err(invalid(format!("box {boxvec:?}")));
        }
        let mut bv = [0f32; 9];
        for (o, v) in bv.iter_mut().zip(boxvec.as_flattened()) {
            *o = (*v / f64::from(NM)) as f32;
        }
        // Convert Å → nm into the reused buffer, lend it to molly's frame, take it back.
        self.nm.clear();
        self.nm
            .extend(positions.as_flattened().iter().map(|v| v / NM));
        let mframe = molly::Frame {
            step,
            time: time as f32,
            boxvec: bv,
            precision: self.precision,
            positions: std::mem::take(&mut self.nm),
        };
        let r = molly::XTCWriter::new(&mut self.out).write_frame(&mframe);
        self.nm = mframe.positions;
        r.map_err(|e| Error::Io {
            at: Location {
                frame: Some(frame),
                ..Location::file(&self.file)
            },
            source: e,
        })?;
        self.n_atoms = Some(positions.len());
        self.n_written += 1;
        Ok(())
    }

    /// Appends a [`Frame`] (the `Writer` contract): positions, cell matrix, step and time.
    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        self.write_positions(
            &frame.positions,
            frame.cell.map(|c| c.matrix()),
            frame.step.unwrap_or(self.n_written as i64),
            frame.time.unwrap_or(0.0),
        )
        .map_err(|e| match e {
            Error::Io { source, .. } => source,
            other => io::Error::new(io::ErrorKind::InvalidInput, other.to_string()),
        })
    }

    /// Ends the file (the `Writer` contract): nothing to add, the stream is flushed.
    pub fn finish(&mut self) -> io::Result<()> {
        self.out.flush()
    }

    /// Gives back the stream.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn into_inner(self) -> W {
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn name() -> Arc<str> {
        "test.xtc".into()
    }

    /// A water-like system: triples of nearby atoms (exercises runs and the swap), spread over
    /// a box, plus some far jumps (large triples, smallidx changes).
    fn system(n: usize, frame: usize) -> Vec<[f32; 3]> {
        let mut s = 12345u64 + frame as u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) as f32) / (1u64 << 31) as f32
        };
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let c = [rnd() * 50.0, rnd() * 50.0, rnd() * 50.0];
            out.push(c);
            for _ in 0..2 {
                if out.len() < n {
                    out.push([c[0] + rnd() - 0.5, c[1] + rnd() - 0.5, c[2] + rnd() - 0.5]);
                }
            }
        }
        out
    }

    fn write_molly(frames: &[Vec<[f32; 3]>], magic: molly::Magic) -> Vec<u8> {
        let mut w = molly::XTCWriter::new_with_magic(Vec::new(), magic);
        for (k, f) in frames.iter().enumerate() {
            let fr = molly::Frame {
                step: k as u32 * 10,
                time: k as f32 * 0.5,
                boxvec: [5.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 5.0],
                precision: 1000.0,
                positions: f.iter().flatten().map(|v| v / 10.0).collect(),
            };
            w.write_frame(&fr).unwrap();
        }
        w.file
    }

    #[test]
    fn agrees_bit_for_bit_with_molly() {
        for magic in [molly::Magic::Xtc1995, molly::Magic::Xtc2023] {
            for n in [1, 9, 10, 11, 100, 3001] {
                let frames: Vec<_> = (0..3).map(|f| system(n, f)).collect();
                let bytes = write_molly(&frames, magic);
                // molly decodes...
                let mut m = molly::XTCReader::new(Cursor::new(bytes.clone()));
                let want = m.read_all_frames().unwrap();
                // ...and so do we, in reverse order.
                let mut r = XtcReader::new(Cursor::new(bytes), name()).unwrap();
                assert_eq!(r.frame_count(), 3);
                assert_eq!(r.n_atoms(), n);
                assert!(r.truncation().is_none());
                let mut p = Vec::new();
                for f in (0..3).rev() {
                    let info = r.read_frame(f, &mut p).unwrap();
                    assert_eq!(info.step, f as i64 * 10);
                    assert_eq!(info.box_vectors[1][1], 50.0);
                    for (k, (a, w)) in p.iter().zip(want[f].coords()).enumerate() {
                        let w = w.map(|v| v * NM);
                        assert_eq!(*a, w, "magic {magic:?} n {n} frame {f} atom {k}");
                    }
                    // And both are within half a precision step of what was written.
                    for (a, w) in p.iter().zip(&frames[f]) {
                        for d in 0..3 {
                            let tol = 0.005 + 1e-5 * w[d].abs();
                            assert!(
                                (a[d] - w[d]).abs() <= tol,
                                "expected {}, actual {}, tolerance {tol}",
                                w[d],
                                a[d]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn densest_streams_molly_writes_pass_the_atom_count_bound() {
        // Every atom at one point, or on a 0.001 nm grid: the fewest bits an atom molly's
        // compressor spends. The reader refuses natoms > 4 per byte before decoding; these
        // files must still read, and agree with molly.
        for n in [10, 11, 100, 1000, 4099] {
            let same = vec![[12.5f32, -3.0, 7.25]; n];
            let grid: Vec<[f32; 3]> = (0..n).map(|k| [k as f32 * 0.01, 0.0, 0.0]).collect();
            for frame in [same, grid] {
                let bytes = write_molly(std::slice::from_ref(&frame), molly::Magic::Xtc1995);
                let nbytes = be_u32(&bytes, HEADER + PRELUDE) as usize;
                let want = molly::XTCReader::new(Cursor::new(bytes.clone()))
                    .read_all_frames()
                    .unwrap();
                let mut r = XtcReader::new(Cursor::new(bytes), name())
                    .unwrap_or_else(|e| panic!("{n} atoms in {nbytes} bytes: {e}"));
                let mut p = Vec::new();
                r.read_frame(0, &mut p)
                    .unwrap_or_else(|e| panic!("{n} atoms in {nbytes} bytes: {e}"));
                for (a, w) in p.iter().zip(want[0].coords()) {
                    assert_eq!(*a, w.map(|v| v * NM), "{n} atoms in {nbytes} bytes");
                }
            }
        }
    }

    #[test]
    fn large_radix_branch_agrees_with_molly() {
        // Spread > 2^24 / 1000 nm = 16777 nm along x: three plain bit fields per triple.
        let mut frame = system(50, 0);
        frame[7][0] = 200_000.0;
        frame[20][0] = -10_000.0;
        let bytes = write_molly(&[frame.clone()], molly::Magic::Xtc1995);
        let want = molly::XTCReader::new(Cursor::new(bytes.clone()))
            .read_all_frames()
            .unwrap();
        let mut r = XtcReader::new(Cursor::new(bytes), name()).unwrap();
        let mut p = Vec::new();
        r.read_frame(0, &mut p).unwrap();
        for (a, w) in p.iter().zip(want[0].coords()) {
            assert_eq!(*a, w.map(|v| v * NM));
        }
    }

    #[test]
    fn our_writer_round_trips_within_precision() {
        let frames: Vec<_> = (0..2).map(|f| system(40, f)).collect();
        let mut w = XtcWriter::new(Vec::new(), name(), 1000.0).unwrap();
        let bx = [[30.0, 0.0, 0.0], [0.0, 31.0, 0.0], [1.0, 2.0, 32.0]];
        for f in &frames {
            w.write_positions(f, Some(bx), 7, 1.5).unwrap();
        }
        assert!(w.write_positions(&frames[0][..3], None, 0, 0.0).is_err());
        let bytes = w.into_inner();
        let mut r = XtcReader::new(Cursor::new(bytes), name()).unwrap();
        let mut p = Vec::new();
        let info = r.read_frame(1, &mut p).unwrap();
        assert_eq!((info.step, info.time), (7, 1.5));
        for (a, w) in info
            .box_vectors
            .as_flattened()
            .iter()
            .zip(bx.as_flattened())
        {
            assert!(
                (a - w).abs() < 1e-5,
                "expected {w}, actual {a}, tolerance 1e-5"
            );
        }
        for (a, w) in p.iter().zip(&frames[1]) {
            for d in 0..3 {
                assert!(
                    (a[d] - w[d]).abs() <= 0.0051,
                    "expected {}, actual {}",
                    w[d],
                    a[d]
                );
            }
        }
    }

    #[test]
    fn damage_never_panics_and_keeps_earlier_frames() {
        let frames: Vec<_> = (0..3).map(|f| system(30, f)).collect();
        let bytes = write_molly(&frames, molly::Magic::Xtc1995);
        let good = XtcReader::new(Cursor::new(bytes.clone()), name()).unwrap();
        let starts: Vec<u64> = (0..3).map(|f| good.frame_offset(f).unwrap()).collect();
        let ends = [starts[1], starts[2], bytes.len() as u64];
        // Cut everywhere: exactly the frames that end before the cut stay readable.
        for cut in 0..bytes.len() {
            let complete = ends.iter().filter(|&&e| e <= cut as u64).count();
            match XtcReader::new(Cursor::new(bytes[..cut].to_vec()), name()) {
                Ok(mut r) => {
                    assert_eq!(r.frame_count(), complete, "cut at {cut}");
                    let mut p = Vec::new();
                    for f in 0..complete {
                        r.read_frame(f, &mut p).unwrap();
                        assert_eq!(p.len(), 30);
                    }
                    let at_boundary = cut == 0 || ends.contains(&(cut as u64));
                    if !at_boundary {
                        let e = r.read_frame(complete, &mut p).unwrap_err();
                        let at = e.location().unwrap();
                        assert_eq!(at.frame, Some(complete), "{e}");
                        assert_eq!(at.byte, Some(cut as u64), "{e}");
                        assert!(matches!(e, Error::Truncated { .. }), "{e}");
                    }
                }
                Err(e) => {
                    assert_eq!(complete, 0, "cut at {cut}: {e}");
                    assert!(matches!(e, Error::Truncated { .. }), "{e}");
                }
            }
        }
        // Flip every byte, one at a time.
        for at in 0..bytes.len() {
            for bit in [0x01u8, 0x80] {
                let mut b = bytes.clone();
                b[at] ^= bit;
                if let Ok(mut r) = XtcReader::new(Cursor::new(b), name()) {
                    let mut p = Vec::new();
                    for f in 0..r.frame_count() + 1 {
                        let _ = r.read_frame(f, &mut p);
                    }
                }
            }
        }
    }
}
