//! BinaryCIF (`.bcif`, `.bcif.gz`): the binary encoding of PDBx/mmCIF that the RCSB PDB and
//! PDBe serve and Mol* reads, read into the frames the text reader ([`crate::mmcif`]) makes.
//!
//! # What is read
//! What the text reader reads, from the first data block: the `_atom_site` columns it uses
//! (matched by name, case-insensitive, others not decoded), `_cell.length_a/b/c` and
//! `angle_alpha/beta/gamma` and `_struct.title` (the first row of each, wherever the category
//! stands in the block). The rows become frames through the text reader's own code
//! (`mmcif::AtomSites`): models as frames, auth over label fields, elements, chains, occupancy
//! and B-factor properties, the first alternate location of each atom with one warning per
//! frame that lost rows, the atom count of every model checked against model 1's, the 1 Å
//! placeholder cell dropped. A `.bcif` and the `.cif` it was made from give the same frames.
//!
//! A value is taken as the text reader takes its text: a masked value (mask 1 is CIF's `.`,
//! 2 its `?`) is missing, and so is an unmasked string `.` or `?` (a writer that stores them
//! without a mask means the same); an integer column gives labels and the alternate-location
//! keys by its decimal text, a string column's numbers are parsed as text is.
//!
//! # Format
//! A MessagePack map `{version, encoder, dataBlocks: [{header, categories: [{name, rowCount,
//! columns: [{name, data, mask}]}]}]}`. A column's `data` (and its optional `mask`) is bytes
//! and the list of encodings that made them, undone from the last to the first:
//! - `ByteArray {type}`: little-endian Int8/16/32 (1, 2, 3), Uint8/16/32 (4, 5, 6), Float32/64
//!   (32, 33);
//! - `FixedPoint {factor}`: integers k to k / factor;
//! - `IntervalQuantization {min, max, numSteps}`: integers k to min + k (max − min) /
//!   (numSteps − 1);
//! - `RunLength {srcSize}`: (value, count) pairs to srcSize integers;
//! - `Delta {origin, srcType}`: differences to values, the first plus origin, wrapped to
//!   srcType as a typed array would;
//! - `IntegerPacking {byteCount, isUnsigned, srcSize}`: 1- or 2-byte values, a value at the
//!   type's limit (127/−128, 255, 32767/−32768, 65535) continued by the next, summed; left as
//!   they are when there are already srcSize of them;
//! - `StringArray {stringData, offsets, offsetEncoding, dataEncoding}`: the unique strings
//!   concatenated, their boundaries (UTF-16 code units, as Mol*'s `substring`) and one index a
//!   row, −1 for the empty string.
//!
//! # Numbers
//! A FixedPoint value is computed as k / factor, a division, so correctly rounded: the double
//! nearest the decimal k / 10^d the writer scaled. Rounded to `f32` it is the `f32` nearest the
//! decimal, the one the text reader parses from the same digits, whenever d ≤ 8 (Mol* writes
//! 3 for coordinates): a double rounding differs from one rounding only when the double is
//! an `f32` tie, half-way between two floats, while the decimal is not; near a value of
//! magnitude 2^e (e ≤ 24) the ties are odd multiples of 2^(e−24), so the decimal's distance
//! to one is a non-zero multiple of 1 / (10^d 2^(24−e)), which exceeds the double's half
//! ulp 2^(e−53) unless 10^d > 2^29, d ≥ 9. Float32 and Float64 ByteArray values are the
//! numbers stored (the same argument holds for a Float64 its writer parsed from ≤ 8
//! decimals). IntervalQuantization is lossy by design: a value is within a step, (max − min) /
//! (numSteps − 1), of what was quantised (half a step from a writer that rounds, as Mol*'s;
//! biotite 1.6 takes the step at or above the value).
//!
//! # Damage
//! No count in the file is trusted: a MessagePack string, array or map longer than the bytes
//! left is refused before anything is allocated; nesting deeper than 32 is refused; a
//! category's `rowCount` may not exceed the file's byte count (a real file spends at least a
//! byte per atom on each coordinate); a RunLength output is checked against its srcSize and
//! against the rows (or strings) the column can have before it is allocated, IntegerPacking
//! and Delta outputs are no longer than their inputs, and every column must decode to exactly
//! `rowCount` values; a used `_atom_site` column named twice is refused before any is decoded.
//! Memory so stays within a fixed multiple of the file's size. Errors name the file and the
//! byte offset of the value at fault, the column (`_atom_site.Cartn_x`) and row where one is
//! at fault, and the frame when a frame was being read. A cut file is an error, also under
//! `allow_truncated` (the document is one MessagePack value: nothing before the cut is known
//! to be whole).
//!
//! # Design
//! The whole file is read and parsed into a tree of MessagePack values that borrow its bytes
//! (about 40 bytes a value: a few thousand for a real file, the columns being byte strings);
//! the `_atom_site` columns used are then decoded once, 4 bytes a row each (Int32, the `f32`
//! of a coordinate, a string's index into its column's table), and kept for random access:
//! frame k is model k's row range, its rows turned into atoms as the text reader turns its
//! rows. Measured on a synthetic file of two 500,000-atom models (77.5 MB as text, 11.4 MB
//! from Mol*'s cif2bcif 5.6.1): `/usr/bin/time -v texmap info big.bcif` takes 1.0 s with a
//! 138 MB peak, the `.cif` 1.1 s with 71 MB; streaming both frames takes 0.54 s (0.08 s of it
//! the decoding) against the text reader's 0.60 s. Rejected: decoding a frame's rows on
//! demand, since RunLength and Delta decode only from a column's start (every frame would
//! decode whole columns again); and a MessagePack crate, as the subset used here is 200
//! lines that bound every count by the bytes present.
//!
//! # References
//! - D. Sehnal, S. Bittrich, S. Velankar, J. Koča, R. Svobodová, S. K. Burley, A. S. Rose,
//!   "BinaryCIF and CIFTools — Lightweight, efficient and extensible macromolecular data
//!   management", PLoS Comput. Biol. 16 (2020) e1008247; the format's `encoding.md`
//!   (github.com/molstar/BinaryCIF, version 0.3.0, the one every writer uses).
//! - MessagePack specification (msgpack.org, `spec.md`).

use std::io::Read;
use std::ops::Range;
use std::sync::Arc;

use crate::cif::strip_esd;
use crate::cursor::{IN_BOUNDS, first_out_of_bounds};
use crate::error::{Error, Location};
use crate::frame::{Frame, Label, UnitCell};
use crate::mmcif::{
    ALTLOC_EXPECTED, AtomSites, CELL_EXPECTED, CELL_ITEMS, COLUMNS_EXPECTED, MODEL_EXPECTED,
    NOT_A_COORDINATE, Role, RolesProblem, SCALAR_NAMES, Site, altloc_warning, cell_values,
    check_roles, fnv, role,
};
use crate::parse::{parse_f32, parse_f64, parse_i64};
use crate::text::ModelCheck;

/// Deepest MessagePack nesting read: BinaryCIF needs 13 levels (a StringArray's encodings).
const MAX_DEPTH: usize = 32;

/// Whether `head`, a file's first bytes, starts as a BinaryCIF file: a MessagePack map whose
/// first key is `encoder`, `version` or `dataBlocks` (the order writers use varies).
pub(crate) fn is_bcif(head: &[u8]) -> bool {
    let key = match head {
        [0x81..=0x8f, k @ 0xa0..=0xbf, rest @ ..] => rest.get(..(k & 0x1f) as usize),
        [0xde, _, _, 0xa0..=0xbf, rest @ ..] => rest.get(..(head[3] & 0x1f) as usize),
        _ => None,
    };
    matches!(key, Some(b"encoder" | b"version" | b"dataBlocks"))
}

/// A location in the file: no line, no frame unless given.
fn at(file: &Arc<str>, frame: Option<usize>, byte: u64) -> Location {
    Location {
        file: file.clone(),
        frame,
        line: None,
        byte: Some(byte),
    }
}

// ---------------------------------------------------------------------------------------------
// MessagePack

/// A MessagePack value, its strings and bytes borrowed from the file.
#[derive(Debug)]
enum Value<'a> {
    Nil,
    Bool(bool),
    Int(i64),
    UInt(u64),
    Float(f64),
    Str(&'a [u8]),
    Bin(&'a [u8]),
    Array(Vec<Node<'a>>),
    Map(Vec<(Node<'a>, Node<'a>)>),
}

/// A value and the byte offset of its first byte.
#[derive(Debug)]
struct Node<'a> {
    at: u64,
    v: Value<'a>,
}

impl<'a> Node<'a> {
    /// The value of `key` in a map (`None` for a missing key or a value that is not a map).
    fn get(&self, key: &str) -> Option<&Node<'a>> {
        let Value::Map(m) = &self.v else {
            return None;
        };
        m.iter()
            .find(|(k, _)| matches!(k.v, Value::Str(s) if s == key.as_bytes()))
            .map(|(_, v)| v)
    }

    /// An integer, or a float with an integral value.
    fn int(&self) -> Option<i64> {
        match self.v {
            Value::Int(v) => Some(v),
            Value::UInt(v) => i64::try_from(v).ok(),
            Value::Float(v) if v.fract() == 0.0 && v.abs() < 9.0e15 => Some(v as i64),
            _ => None,
        }
    }

    /// A number.
    fn number(&self) -> Option<f64> {
        match self.v {
            Value::Int(v) => Some(v as f64),
            Value::UInt(v) => Some(v as f64),
            Value::Float(v) => Some(v),
            _ => None,
        }
    }

    fn str(&self) -> Option<&'a [u8]> {
        match self.v {
            Value::Str(s) => Some(s),
            _ => None,
        }
    }

    /// Bytes (a `bin`; a `str` too, as a lax writer may give raw bytes).
    fn bytes(&self) -> Option<&'a [u8]> {
        match self.v {
            Value::Bin(b) | Value::Str(b) => Some(b),
            _ => None,
        }
    }

    fn array(&self) -> Option<&[Node<'a>]> {
        match &self.v {
            Value::Array(a) => Some(a),
            _ => None,
        }
    }

    /// What the value is, for an error.
    fn kind(&self) -> String {
        match &self.v {
            Value::Nil => "nil".into(),
            Value::Bool(b) => format!("{b}"),
            Value::Int(v) => format!("the integer {v}"),
            Value::UInt(v) => format!("the integer {v}"),
            Value::Float(v) => format!("the number {v}"),
            Value::Str(s) => format!("the string \"{}\"", Error::found(s)),
            Value::Bin(b) => format!("{} bytes", b.len()),
            Value::Array(a) => format!("an array of {}", a.len()),
            Value::Map(m) => format!("a map of {} keys", m.len()),
        }
    }
}

/// Parses MessagePack from a byte slice; every length is checked against the bytes left.
struct Unpacker<'a, 'f> {
    b: &'a [u8],
    pos: usize,
    file: &'f Arc<str>,
}

impl<'a> Unpacker<'a, '_> {
    /// The next `n` bytes of the value that starts at `start`.
    fn take(&mut self, n: usize, start: usize, what: &str) -> Result<&'a [u8], Error> {
        let left = self.b.len() - self.pos;
        if n > left {
            return Err(Error::Truncated {
                at: at(self.file, None, self.b.len() as u64),
                expected: format!(
                    "{} more bytes of the MessagePack {what} that starts at byte {start}",
                    n - left
                ),
            });
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// A big-endian unsigned integer of `n` bytes.
    fn uint(&mut self, n: usize, start: usize, what: &str) -> Result<u64, Error> {
        let b = self.take(n, start, what)?;
        Ok(b.iter().fold(0u64, |v, &x| (v << 8) | x as u64))
    }

    /// A length of `n` bytes, as a count of bytes or elements of the value at `start`,
    /// checked by [`Unpacker::fits`].
    fn len(&mut self, n: usize, start: usize, what: &str) -> Result<usize, Error> {
        let len = self.uint(n, start, what)?;
        self.fits(len, start, what)
    }

    /// The value that starts here, `depth` levels down.
    fn value(&mut self, depth: usize) -> Result<Node<'a>, Error> {
        let start = self.pos;
        let node = |v| Node {
            at: start as u64,
            v,
        };
        if depth > MAX_DEPTH {
            return Err(Error::Parse {
                at: at(self.file, None, start as u64),
                expected: "MessagePack nested at most 32 deep (BinaryCIF needs 13)",
                found: "a deeper array or map".into(),
            });
        }
        let tag = self.take(1, start, "value")?[0];
        let v = match tag {
            0x00..=0x7f => Value::Int(tag as i64),
            0xe0..=0xff => Value::Int(tag as i8 as i64),
            0xc0 => Value::Nil,
            0xc2 => Value::Bool(false),
            0xc3 => Value::Bool(true),
            0xcc..=0xcf => Value::UInt(self.uint(1 << (tag - 0xcc), start, "integer")?),
            0xd0..=0xd3 => {
                let n = 1 << (tag - 0xd0);
                let u = self.uint(n, start, "integer")?;
                // Sign-extend from n bytes.
                let shift = 64 - 8 * n as u32;
                Value::Int(((u << shift) as i64) >> shift)
            }
            0xca => Value::Float(f32::from_bits(self.uint(4, start, "float")? as u32) as f64),
            0xcb => Value::Float(f64::from_bits(self.uint(8, start, "float")?)),
            0xa0..=0xbf | 0xd9..=0xdb | 0xc4..=0xc6 => {
                let (n, str) = match tag {
                    0xa0..=0xbf => ((tag & 0x1f) as usize, true),
                    0xd9..=0xdb => (self.len(1 << (tag - 0xd9), start, "string")?, true),
                    _ => (self.len(1 << (tag - 0xc4), start, "bytes")?, false),
                };
                let b = self.take(n, start, if str { "string" } else { "bytes" })?;
                if str { Value::Str(b) } else { Value::Bin(b) }
            }
            0x90..=0x9f | 0xdc | 0xdd => {
                let n = match tag {
                    0x90..=0x9f => self.fits((tag & 0x0f) as u64, start, "array")?,
                    _ => self.len(2 << (tag - 0xdc), start, "array")?,
                };
                // Grown as elements arrive: a count is not an allocation.
                let mut a = Vec::with_capacity(n.min(16));
                for _ in 0..n {
                    a.push(self.value(depth + 1)?);
                }
                Value::Array(a)
            }
            0x80..=0x8f | 0xde | 0xdf => {
                let n = match tag {
                    0x80..=0x8f => self.fits((tag & 0x0f) as u64, start, "map")?,
                    _ => self.len(2 << (tag - 0xde), start, "map")?,
                };
                let mut m = Vec::with_capacity(n.min(16));
                for _ in 0..n {
                    let k = self.value(depth + 1)?;
                    let v = self.value(depth + 1)?;
                    m.push((k, v));
                }
                Value::Map(m)
            }
            _ => {
                return Err(Error::Parse {
                    at: at(self.file, None, start as u64),
                    expected: "a MessagePack value of a kind BinaryCIF uses (no extension types)",
                    found: format!("the type byte {tag:#04x}"),
                });
            }
        };
        Ok(node(v))
    }

    /// A count `n` of bytes or elements (each takes a byte at least) of the value at `start`:
    /// more than the bytes left is a cut, found before anything is allocated.
    fn fits(&self, n: u64, start: usize, what: &str) -> Result<usize, Error> {
        let left = (self.b.len() - self.pos) as u64;
        if n > left {
            return Err(Error::Truncated {
                at: at(self.file, None, self.b.len() as u64),
                expected: format!(
                    "{} more bytes for the MessagePack {what} of {n} that starts at byte {start}",
                    n - left
                ),
            });
        }
        Ok(n as usize)
    }
}

/// Parses the whole of `bytes` as one MessagePack value.
fn unpack<'a>(bytes: &'a [u8], file: &Arc<str>) -> Result<Node<'a>, Error> {
    let mut u = Unpacker {
        b: bytes,
        pos: 0,
        file,
    };
    let root = u.value(0)?;
    if u.pos != bytes.len() {
        return Err(Error::Parse {
            at: at(file, None, u.pos as u64),
            expected: "the end of the file after the BinaryCIF document",
            found: format!("{} more bytes", bytes.len() - u.pos),
        });
    }
    Ok(root)
}

// ---------------------------------------------------------------------------------------------
// Columns

/// A column's values once decoded, kept for the frames: 4 bytes a row but for other
/// columns of floating-point numbers.
#[derive(Debug)]
enum Values {
    /// BinaryCIF's integer type, Int32 (what its RunLength, Delta and IntegerPacking give).
    Int(Vec<i32>),
    Float(Vec<f64>),
    /// A coordinate, occupancy or B-factor column of floating-point numbers: the `f32` the
    /// frame takes, rounded once at the open (the module doc's # Numbers).
    Real(Vec<f32>),
    Str(Strings),
}

/// A StringArray: the unique strings and one per row.
#[derive(Debug)]
struct Strings {
    text: Vec<u8>,
    /// Byte ranges into `text`; entry 0 is the empty string (index −1 in the file).
    spans: Vec<(u32, u32)>,
    /// Per row, an entry of `spans`.
    rows: Vec<u32>,
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::Int(v) => v.len(),
            Values::Float(v) => v.len(),
            Values::Real(v) => v.len(),
            Values::Str(s) => s.rows.len(),
        }
    }
}

/// One value of a column, as the text reader would have met it.
#[derive(Clone, Copy)]
enum Cell<'c> {
    /// Masked, or the string `.` or `?` (the byte: `.` or `?`).
    Missing(u8),
    Int(i64),
    Float(f64),
    Real(f32),
    Str(&'c [u8]),
}

/// A decoded column: its values, its mask (0 present, 1 `.`, 2 `?`), its name and where its
/// data are in the file, for errors.
#[derive(Debug)]
struct Column {
    name: String,
    at: u64,
    values: Values,
    mask: Option<Vec<u8>>,
}

impl Column {
    fn cell(&self, r: usize) -> Cell<'_> {
        if let Some(m) = &self.mask
            && m[r] != 0
        {
            return Cell::Missing(if m[r] == 1 { b'.' } else { b'?' });
        }
        match &self.values {
            Values::Int(v) => Cell::Int(v[r] as i64),
            Values::Float(v) => Cell::Float(v[r]),
            Values::Real(v) => Cell::Real(v[r]),
            Values::Str(s) => {
                let (a, b) = s.spans[s.rows[r] as usize];
                match &s.text[a as usize..b as usize] {
                    b"." => Cell::Missing(b'.'),
                    b"?" => Cell::Missing(b'?'),
                    t => Cell::Str(t),
                }
            }
        }
    }
}

/// The text of a present value (a number written into `buf`), as in a text CIF.
fn text<'c>(cell: Cell<'c>, buf: &'c mut [u8; 32]) -> &'c [u8] {
    use std::io::Write;
    let mut w = std::io::Cursor::new(&mut buf[..]);
    // 32 bytes hold any i64 and any f64 in `{:?}` (shortest, with an exponent when long).
    let _ = match cell {
        Cell::Str(s) => return s,
        Cell::Missing(c) => write!(w, "{}", c as char),
        Cell::Int(v) => write!(w, "{v}"),
        Cell::Float(v) => write!(w, "{v:?}"),
        Cell::Real(v) => write!(w, "{v:?}"),
    };
    let n = w.position() as usize;
    &buf[..n]
}

/// The alternate-location key of a value: [`fnv`] of its text, 0 when missing.
fn key(cell: Cell) -> u64 {
    match cell {
        Cell::Missing(_) => 0,
        c => fnv(text(c, &mut [0; 32])),
    }
}

/// A value as an `f32`, as the text reader parses a coordinate; `None` when missing or not a
/// finite number.
fn real(cell: Cell) -> Option<f32> {
    let v = match cell {
        Cell::Missing(_) => return None,
        Cell::Str(s) => return parse_f32(strip_esd(s)),
        Cell::Int(v) => v as f32,
        // The module doc's # Numbers: one rounding of the decimal, for FixedPoint too.
        Cell::Float(v) => v as f32,
        Cell::Real(v) => v,
    };
    v.is_finite().then_some(v)
}

/// A value as an integer, as the text reader parses one; `None` when missing or not integral.
fn integer(cell: Cell) -> Option<i64> {
    match cell {
        Cell::Missing(_) => None,
        Cell::Str(s) => parse_i64(s),
        Cell::Int(v) => Some(v),
        Cell::Float(v) => (v.fract() == 0.0 && v.abs() < 9.0e15).then_some(v as i64),
        Cell::Real(v) => (v.fract() == 0.0 && v.abs() < 9.0e15).then_some(v as i64),
    }
}

/// Where decoding is, for its errors: the file and the column.
struct ColumnAt<'f> {
    file: &'f Arc<str>,
    /// `_category.column`, or `_category.column mask`.
    column: &'f str,
}

impl ColumnAt<'_> {
    fn error(&self, byte: u64, expected: &'static str, found: String) -> Error {
        Error::Parse {
            at: at(self.file, None, byte),
            expected,
            found: format!("column {}: {found}", self.column),
        }
    }
}

/// A column as it is decoded, one encoding at a time.
#[derive(Debug)]
enum Stage<'a> {
    Bytes(&'a [u8]),
    Ints(Vec<i64>),
    Floats(Vec<f64>),
    Strings(Strings),
}

/// What an encoding map must hold.
const ENCODING: &str = "a BinaryCIF encoding: a map with its kind and parameters";

/// Decodes a `{data, encoding}` map (at most `limit` values at any step that expands).
fn decode<'a>(data: &Node<'a>, limit: usize, cx: &ColumnAt) -> Result<Stage<'a>, Error> {
    const DATA: &str = "BinaryCIF data: a map with data (bytes) and encoding (a list)";
    let bytes = data.get("data");
    let encodings = data.get("encoding").and_then(Node::array);
    let (Some((at, bytes)), Some(encodings)) =
        (bytes.and_then(|b| Some((b.at, b.bytes()?))), encodings)
    else {
        return Err(cx.error(data.at, DATA, data.kind()));
    };
    decode_steps(Stage::Bytes(bytes), at, encodings, limit, cx)
}

/// Where the bytes of a `{data, encoding}` map start (the map's start if it has none).
fn data_at(data: &Node) -> u64 {
    data.get("data").map_or(data.at, |d| d.at)
}

/// Undoes `encodings` on `stage`, last first.
fn decode_steps<'a>(
    mut stage: Stage<'a>,
    at: u64,
    encodings: &[Node<'a>],
    limit: usize,
    cx: &ColumnAt,
) -> Result<Stage<'a>, Error> {
    for e in encodings.iter().rev() {
        stage = step(stage, at, e, limit, cx)?;
    }
    Ok(stage)
}

/// An integer parameter of encoding `e`.
fn param_int(e: &Node, key: &'static str, cx: &ColumnAt) -> Result<i64, Error> {
    e.get(key)
        .and_then(Node::int)
        .ok_or_else(|| cx.error(e.at, ENCODING, format!("no integer {key}")))
}

/// A finite number parameter of encoding `e`.
fn param_number(e: &Node, key: &'static str, cx: &ColumnAt) -> Result<f64, Error> {
    e.get(key)
        .and_then(Node::number)
        .filter(|v| v.is_finite())
        .ok_or_else(|| cx.error(e.at, ENCODING, format!("no finite number {key}")))
}

/// An element type code of encoding `e` (1-6 integers, 32-33 floats).
fn param_type(e: &Node, key: &'static str, floats: bool, cx: &ColumnAt) -> Result<i64, Error> {
    let t = param_int(e, key, cx)?;
    let ok = matches!(t, 1..=6) || (floats && matches!(t, 32 | 33));
    if !ok {
        return Err(cx.error(
            e.at,
            "a BinaryCIF type code: 1-6 (Int8, Int16, Int32, Uint8, Uint16, Uint32), 32, 33 (Float32, Float64)",
            format!("{key} {t}"),
        ));
    }
    Ok(t)
}

/// `v` stored in an array of integer type `t`, as a typed array stores it (wrapping).
fn wrap(v: i64, t: i64) -> i64 {
    match t {
        1 => v as i8 as i64,
        2 => v as i16 as i64,
        3 => v as i32 as i64,
        4 => v as u8 as i64,
        5 => v as u16 as i64,
        _ => v as u32 as i64,
    }
}

/// Undoes one encoding.
fn step<'a>(
    stage: Stage<'a>,
    at: u64,
    e: &Node<'a>,
    limit: usize,
    cx: &ColumnAt,
) -> Result<Stage<'a>, Error> {
    let kind = e.get("kind").and_then(Node::str).unwrap_or_default();
    let wrong_input = |what: &str| {
        cx.error(
            e.at,
            "encodings that each get the kind of array they decode",
            format!("{} over {what}", String::from_utf8_lossy(kind)),
        )
    };
    let ints = |stage: Stage<'a>| match stage {
        Stage::Ints(v) => Ok(v),
        // Bytes with no ByteArray step are Uint8 values, as Mol* takes them.
        Stage::Bytes(b) => Ok(b.iter().map(|&x| x as i64).collect()),
        Stage::Floats(..) => Err(wrong_input("floating-point values")),
        Stage::Strings(_) => Err(wrong_input("strings")),
    };
    Ok(match kind {
        b"ByteArray" => {
            let Stage::Bytes(b) = stage else {
                return Err(wrong_input("decoded values, not bytes"));
            };
            let t = param_type(e, "type", true, cx)?;
            let size = match t {
                1 | 4 => 1,
                2 | 5 => 2,
                3 | 6 | 32 => 4,
                _ => 8,
            };
            if b.len() % size != 0 {
                return Err(cx.error(
                    at,
                    "data bytes a whole number of the ByteArray's elements",
                    format!("{} bytes of {size}-byte elements", b.len()),
                ));
            }
            let c = b.chunks_exact(size);
            match t {
                1 => Stage::Ints(b.iter().map(|&x| x as i8 as i64).collect()),
                2 => Stage::Ints(c.map(|x| i16::from_le_bytes([x[0], x[1]]) as i64).collect()),
                3 => Stage::Ints(
                    c.map(|x| i32::from_le_bytes([x[0], x[1], x[2], x[3]]) as i64)
                        .collect(),
                ),
                4 => Stage::Ints(b.iter().map(|&x| x as i64).collect()),
                5 => Stage::Ints(c.map(|x| u16::from_le_bytes([x[0], x[1]]) as i64).collect()),
                6 => Stage::Ints(
                    c.map(|x| u32::from_le_bytes([x[0], x[1], x[2], x[3]]) as i64)
                        .collect(),
                ),
                32 => Stage::Floats(
                    c.map(|x| f32::from_le_bytes([x[0], x[1], x[2], x[3]]) as f64)
                        .collect(),
                ),
                _ => Stage::Floats(
                    c.map(|x| f64::from_le_bytes(x.try_into().unwrap_or_default()))
                        .collect(),
                ),
            }
        }
        b"FixedPoint" => {
            let factor = param_number(e, "factor", cx)?;
            param_type(e, "srcType", true, cx)?;
            if factor == 0.0 {
                return Err(cx.error(e.at, ENCODING, "FixedPoint factor 0".into()));
            }
            let v = ints(stage)?;
            // A division, correctly rounded (the module doc's # Numbers).
            Stage::Floats(v.into_iter().map(|k| k as f64 / factor).collect())
        }
        b"IntervalQuantization" => {
            let (min, max) = (param_number(e, "min", cx)?, param_number(e, "max", cx)?);
            let steps = param_int(e, "numSteps", cx)?;
            let single = param_type(e, "srcType", true, cx)? == 32;
            if steps < 2 {
                return Err(cx.error(
                    e.at,
                    "an IntervalQuantization of 2 steps or more",
                    format!("numSteps {steps}"),
                ));
            }
            let delta = (max - min) / (steps - 1) as f64;
            let v = ints(stage)?;
            let q = |k: i64| {
                let x = min + delta * k as f64;
                if single { x as f32 as f64 } else { x }
            };
            Stage::Floats(v.into_iter().map(q).collect())
        }
        b"RunLength" => {
            let size = param_int(e, "srcSize", cx)?;
            let t = param_type(e, "srcType", false, cx)?;
            if size < 0 || size as u64 > limit as u64 {
                return Err(cx.error(
                    e.at,
                    "a RunLength output no longer than the column (rowCount)",
                    format!("RunLength output {size} values, at most {limit}"),
                ));
            }
            let v = ints(stage)?;
            if v.len() % 2 != 0 {
                return Err(cx.error(
                    at,
                    "RunLength (value, count) pairs",
                    format!("{} values", v.len()),
                ));
            }
            let size = size as usize;
            let mut out = Vec::with_capacity(size);
            for p in v.chunks_exact(2) {
                let (value, count) = (wrap(p[0], t), p[1]);
                if count < 0 || count as u64 > (size - out.len()) as u64 {
                    return Err(cx.error(
                        at,
                        "RunLength counts that add up to its srcSize",
                        format!(
                            "a run of {count} after {} of srcSize {size} values",
                            out.len()
                        ),
                    ));
                }
                out.resize(out.len() + count as usize, value);
            }
            if out.len() != size {
                return Err(cx.error(
                    at,
                    "RunLength counts that add up to its srcSize",
                    format!("runs of {} values, srcSize {size}", out.len()),
                ));
            }
            Stage::Ints(out)
        }
        b"Delta" => {
            let origin = param_int(e, "origin", cx)?;
            let t = param_type(e, "srcType", false, cx)?;
            let mut v = ints(stage)?;
            let mut acc = origin;
            for x in v.iter_mut() {
                acc = wrap(acc.wrapping_add(*x), t);
                *x = acc;
            }
            Stage::Ints(v)
        }
        b"IntegerPacking" => {
            let bytes = param_int(e, "byteCount", cx)?;
            let size = param_int(e, "srcSize", cx)?;
            let unsigned = match e.get("isUnsigned").map(|n| &n.v) {
                Some(Value::Bool(b)) => *b,
                _ => return Err(cx.error(e.at, ENCODING, "no boolean isUnsigned".into())),
            };
            let v = ints(stage)?;
            // Each value takes one packed value at least.
            if size < 0 || size as u64 > v.len() as u64 {
                return Err(cx.error(
                    e.at,
                    "an IntegerPacking srcSize no larger than its packed values",
                    format!("srcSize {size} of {} values", v.len()),
                ));
            }
            let size = size as usize;
            if v.len() == size {
                // Nothing was packed (Mol* writes such columns so).
                Stage::Ints(v)
            } else {
                let (upper, lower) = match (bytes, unsigned) {
                    (1, false) => (0x7f, -0x80),
                    (2, false) => (0x7fff, -0x8000),
                    (1, true) => (0xff, i64::MIN),
                    (2, true) => (0xffff, i64::MIN),
                    _ => {
                        return Err(cx.error(
                            e.at,
                            "an IntegerPacking byteCount of 1 or 2",
                            format!("byteCount {bytes}"),
                        ));
                    }
                };
                let mut out = Vec::with_capacity(size);
                let (mut sum, mut more) = (0i64, false);
                for &x in &v {
                    sum = sum.wrapping_add(x);
                    if x == upper || x == lower {
                        continue;
                    }
                    if out.len() == size {
                        more = true;
                        break;
                    }
                    out.push(sum);
                    sum = 0;
                }
                let cut = v.last().is_some_and(|&x| x == upper || x == lower);
                if out.len() != size || cut || more {
                    return Err(cx.error(
                        at,
                        "packed values that unpack to the IntegerPacking srcSize",
                        format!(
                            "{}{} values{} from {} packed, srcSize {size}",
                            if more { "more than " } else { "" },
                            out.len(),
                            if cut { " and a cut one" } else { "" },
                            v.len()
                        ),
                    ));
                }
                if out.iter().any(|&x| x != x as i32 as i64) {
                    return Err(cx.error(
                        at,
                        "unpacked values within Int32",
                        "a value past 2^31".into(),
                    ));
                }
                Stage::Ints(out)
            }
        }
        b"StringArray" => {
            let Stage::Bytes(b) = stage else {
                return Err(wrong_input("decoded values, not bytes"));
            };
            Stage::Strings(strings(b, at, e, limit, cx)?)
        }
        _ => {
            return Err(cx.error(
                e.at,
                "an encoding kind of BinaryCIF 0.3: ByteArray, FixedPoint, IntervalQuantization, RunLength, Delta, IntegerPacking, StringArray",
                format!("kind {}", Error::found(kind)),
            ));
        }
    })
}

/// Undoes a StringArray encoding over the index bytes `b` (at `at`).
fn strings(b: &[u8], at: u64, e: &Node, limit: usize, cx: &ColumnAt) -> Result<Strings, Error> {
    let text = e.get("stringData").and_then(Node::str);
    let offsets = e.get("offsets").and_then(Node::bytes);
    let data_enc = e.get("dataEncoding").and_then(Node::array);
    let offset_enc = e.get("offsetEncoding").and_then(Node::array);
    let (Some(text), Some(offsets), Some(data_enc), Some(offset_enc)) =
        (text, offsets, data_enc, offset_enc)
    else {
        return Err(cx.error(
            e.at,
            "a StringArray with stringData, offsets, dataEncoding and offsetEncoding",
            e.kind(),
        ));
    };
    let offsets_at = e.get("offsets").map_or(e.at, |n| n.at);
    // Offsets count UTF-16 code units (Mol*'s substring): the byte where each unit starts.
    let units: Option<Vec<u32>> = if text.is_ascii() {
        None
    } else {
        let s = std::str::from_utf8(text)
            .map_err(|_| cx.error(e.at, "stringData in UTF-8", "invalid UTF-8".into()))?;
        let mut u = Vec::with_capacity(s.len() + 1);
        for (i, c) in s.char_indices() {
            u.push(i as u32);
            if c.len_utf16() == 2 {
                // The middle of a surrogate pair is no boundary.
                u.push(u32::MAX);
            }
        }
        u.push(s.len() as u32);
        Some(u)
    };
    let n_units = units.as_ref().map_or(text.len(), |u| u.len() - 1);
    // One offset more than strings, strings distinct (one empty at most): a bound before
    // a RunLength expands them.
    let offsets = match decode_steps(
        Stage::Bytes(offsets),
        offsets_at,
        offset_enc,
        n_units + 2,
        cx,
    )? {
        Stage::Ints(v) => v,
        Stage::Bytes(b) => b.iter().map(|&x| x as i64).collect(),
        _ => {
            return Err(cx.error(
                offsets_at,
                "integer StringArray offsets",
                "other values".into(),
            ));
        }
    };
    let mut spans = Vec::with_capacity(offsets.len().max(1));
    spans.push((0, 0));
    let byte_of = |o: i64| -> Option<u32> {
        let o = usize::try_from(o).ok().filter(|&o| o <= n_units)?;
        match &units {
            None => Some(o as u32),
            Some(u) => Some(u[o]).filter(|&b| b != u32::MAX),
        }
    };
    for w in offsets.windows(2) {
        match (byte_of(w[0]), byte_of(w[1])) {
            (Some(a), Some(b)) if a <= b => spans.push((a, b)),
            _ => {
                return Err(cx.error(
                    offsets_at,
                    "StringArray offsets that rise within stringData",
                    format!("offsets {} then {} in {n_units} characters", w[0], w[1]),
                ));
            }
        }
    }
    let index = match decode_steps(Stage::Bytes(b), at, data_enc, limit, cx)? {
        Stage::Ints(v) => v,
        Stage::Bytes(b) => b.iter().map(|&x| x as i64).collect(),
        _ => return Err(cx.error(at, "integer StringArray indices", "other values".into())),
    };
    let n = spans.len() as i64 - 1;
    let mut rows = Vec::with_capacity(index.len());
    for (r, &i) in index.iter().enumerate() {
        if !(-1..n).contains(&i) {
            return Err(cx.error(
                at,
                "StringArray indices of its strings (or -1)",
                format!("row {}: index {i} of {n} strings", r + 1),
            ));
        }
        rows.push((i + 1) as u32);
    }
    Ok(Strings {
        text: text.to_vec(),
        spans,
        rows,
    })
}

/// Decodes column node `c` of a category of `rows` rows named `category`.
fn column(c: &Node, category: &str, rows: usize, file: &Arc<str>) -> Result<Column, Error> {
    const COLUMN: &str = "a BinaryCIF column: a map with name, data and mask (or none)";
    let name = c.get("name").and_then(Node::str);
    let data = c.get("data");
    let (Some(name), Some(data)) = (name, data) else {
        return Err(Error::Parse {
            at: at(file, None, c.at),
            expected: COLUMN,
            found: c.kind(),
        });
    };
    let name = format!("{category}.{}", String::from_utf8_lossy(name));
    let cx = ColumnAt {
        file,
        column: &name,
    };
    let count = |len: usize, what: &str| {
        if len == rows {
            return Ok(());
        }
        Err(cx.error(
            data_at(data),
            "a column of its category's rowCount values",
            format!("{what} {len} values, rowCount {rows}"),
        ))
    };
    let values = match decode(data, rows, &cx)? {
        Stage::Bytes(b) => Values::Int(b.iter().map(|&x| x as i32).collect()),
        Stage::Ints(v) => {
            if let Some(r) = v.iter().position(|&x| x != x as i32 as i64) {
                return Err(cx.error(
                    data_at(data),
                    "integers within Int32, BinaryCIF's integer type",
                    format!("row {}: {}", r + 1, v[r]),
                ));
            }
            Values::Int(v.into_iter().map(|x| x as i32).collect())
        }
        Stage::Floats(v) => Values::Float(v),
        Stage::Strings(s) => Values::Str(s),
    };
    let last = data
        .get("encoding")
        .and_then(Node::array)
        .and_then(|e| e.first())
        .and_then(|e| e.get("kind"))
        .and_then(Node::str)
        .map_or("data of".into(), |k| {
            format!("{} output", String::from_utf8_lossy(k))
        });
    count(values.len(), &last)?;
    let mask = match c.get("mask") {
        None => None,
        Some(Node { v: Value::Nil, .. }) => None,
        Some(m) => {
            let mask_name = format!("{name} mask");
            let mcx = ColumnAt {
                file,
                column: &mask_name,
            };
            let v = match decode(m, rows, &mcx)? {
                Stage::Ints(v) => v,
                Stage::Bytes(b) => b.iter().map(|&x| x as i64).collect(),
                _ => return Err(mcx.error(data_at(m), "an integer mask", "other values".into())),
            };
            if v.len() != rows {
                return Err(mcx.error(
                    data_at(m),
                    "a mask of its category's rowCount values",
                    format!("{} values, rowCount {rows}", v.len()),
                ));
            }
            if let Some(r) = v.iter().position(|x| !(0..=2).contains(x)) {
                return Err(mcx.error(
                    data_at(m),
                    "mask values 0 (present), 1 ('.') or 2 ('?')",
                    format!("row {}: {}", r + 1, v[r]),
                ));
            }
            Some(v.into_iter().map(|x| x as u8).collect())
        }
    };
    Ok(Column {
        name,
        at: data_at(data),
        values,
        mask,
    })
}

// ---------------------------------------------------------------------------------------------
// The document

/// A category of the first block: its name (`_atom_site`), rows and column nodes.
struct Category<'n, 'a> {
    name: String,
    at: u64,
    rows: usize,
    columns: &'n [Node<'a>],
}

/// The categories of the first data block, with their names (any case, `_` or not).
fn categories<'n, 'a>(
    root: &'n Node<'a>,
    file: &Arc<str>,
    size: usize,
) -> Result<Vec<Category<'n, 'a>>, Error> {
    let bad = |n: &Node, expected: &'static str| Error::Parse {
        at: at(file, None, n.at),
        expected,
        found: n.kind(),
    };
    let Some(blocks) = root.get("dataBlocks").and_then(Node::array) else {
        return Err(bad(
            root,
            "a BinaryCIF file: a MessagePack map with dataBlocks (a list)",
        ));
    };
    let Some(block) = blocks.first() else {
        return Err(Error::Parse {
            at: at(file, None, root.at),
            expected: "a data block in a BinaryCIF file",
            found: "no data block".into(),
        });
    };
    let Some(cats) = block.get("categories").and_then(Node::array) else {
        return Err(bad(
            block,
            "a BinaryCIF data block: a map with header and categories (a list)",
        ));
    };
    let mut out = Vec::with_capacity(cats.len());
    for c in cats {
        const CATEGORY: &str = "a BinaryCIF category: a map with name, rowCount and columns";
        let name = c.get("name").and_then(Node::str);
        let rows = c.get("rowCount").and_then(Node::int);
        let columns = c.get("columns").and_then(Node::array);
        let (Some(name), Some(rows), Some(columns)) = (name, rows, columns) else {
            return Err(bad(c, CATEGORY));
        };
        let name = String::from_utf8_lossy(name).to_ascii_lowercase();
        let name = match name.strip_prefix('_') {
            Some(n) => format!("_{n}"),
            None => format!("_{name}"),
        };
        if rows < 0 || rows as u64 > size as u64 {
            return Err(Error::Parse {
                at: at(file, None, c.at),
                expected: "a rowCount of at most the file's byte count",
                found: format!("category {name}: rowCount {rows} in a file of {size} bytes"),
            });
        }
        out.push(Category {
            name,
            at: c.at,
            rows: rows as usize,
            columns,
        });
    }
    Ok(out)
}

/// The first row of column `item` of `cat`, if it has one, decoded.
fn first_value<T>(
    cat: &Category,
    item: &str,
    file: &Arc<str>,
    f: impl FnOnce(Cell, &Column) -> Result<Option<T>, Error>,
) -> Result<Option<T>, Error> {
    if cat.rows == 0 {
        return Ok(None);
    }
    let node = cat.columns.iter().find(|c| {
        c.get("name")
            .and_then(Node::str)
            .is_some_and(|n| n.eq_ignore_ascii_case(item.as_bytes()))
    });
    let Some(node) = node else {
        return Ok(None);
    };
    let col = column(node, &cat.name, cat.rows, file)?;
    f(col.cell(0), &col)
}

/// The `_atom_site` columns used, decoded, and the model ranges.
struct Table {
    /// The columns with their roles (`Role::Other` ones are not decoded).
    columns: Vec<(Role, Column)>,
    /// Each frame's rows.
    models: Vec<Range<usize>>,
    /// A damaged model order: the frame it breaks (the one after `models`) and its error.
    broken: Option<(usize, Location, &'static str, String)>,
}

/// A column's value error while frame `frame` is read.
fn value_error(
    file: &Arc<str>,
    frame: usize,
    col: &Column,
    r: usize,
    cell: Cell,
    expected: &'static str,
) -> Error {
    Error::Parse {
        at: at(file, Some(frame), col.at),
        expected,
        found: format!(
            "{} row {}: {}",
            col.name,
            r + 1,
            Error::found(text(cell, &mut [0; 32]))
        ),
    }
}

impl Table {
    /// Decodes the `_atom_site` category and splits its rows into models.
    fn new(cat: &Category, file: &Arc<str>) -> Result<Table, Error> {
        // The roles first: a column repeated (a thousand times) is refused before any is
        // decoded, so at most one column a role is.
        let roles: Vec<Role> = (cat.columns.iter())
            .map(|c| {
                let name = c.get("name").and_then(Node::str).unwrap_or_default();
                role(&name.to_ascii_lowercase())
            })
            .collect();
        let problem = |expected, found| Error::Parse {
            at: at(file, None, cat.at),
            expected,
            found,
        };
        match check_roles(&roles) {
            Ok(()) => {}
            Err(RolesProblem::Repeated(k)) => {
                let name = cat.columns[k].get("name").and_then(Node::str);
                return Err(problem(
                    "each _atom_site column once",
                    format!(
                        "column {} again",
                        String::from_utf8_lossy(name.unwrap_or_default())
                    ),
                ));
            }
            Err(RolesProblem::Missing(axis)) => {
                return Err(problem(
                    COLUMNS_EXPECTED,
                    format!("no _atom_site.{axis} among the category's columns"),
                ));
            }
        }
        let mut columns = Vec::new();
        for (c, &r) in cat.columns.iter().zip(&roles) {
            if r == Role::Other {
                continue;
            }
            let mut col = column(c, &cat.name, cat.rows, file)?;
            if let (Role::X | Role::Y | Role::Z | Role::Scalar(_), Values::Float(v)) =
                (r, &col.values)
            {
                col.values = Values::Real(v.iter().map(|&x| x as f32).collect());
            }
            columns.push((r, col));
        }
        let mut table = Table {
            columns,
            models: Vec::new(),
            broken: None,
        };
        table.split(cat.rows, file);
        Ok(table)
    }

    /// The model ranges: each change of `pdbx_PDB_model_num` starts one; numbers must rise.
    fn split(&mut self, rows: usize, file: &Arc<str>) {
        let Some((_, col)) = self.columns.iter().find(|(r, _)| *r == Role::Model) else {
            if rows > 0 {
                self.models.push(0..rows);
            }
            return;
        };
        let (mut start, mut cur) = (0, None);
        for r in 0..rows {
            let cell = col.cell(r);
            let frame = self.models.len();
            let Some(m) = integer(cell) else {
                let found = format!(
                    "{} row {}: {}",
                    col.name,
                    r + 1,
                    Error::found(text(cell, &mut [0; 32]))
                );
                self.broken = Some((
                    frame,
                    at(file, Some(frame), col.at),
                    "an integer pdbx_PDB_model_num",
                    found,
                ));
                return;
            };
            match cur {
                None => cur = Some(m),
                Some(c) if m == c => {}
                Some(c) if m > c => {
                    self.models.push(start..r);
                    start = r;
                    cur = Some(m);
                }
                Some(c) => {
                    let found = format!("row {}: model {m} after model {c}", r + 1);
                    self.broken = Some((
                        frame,
                        at(file, Some(frame), col.at),
                        "increasing pdbx_PDB_model_num, each model's rows together",
                        found,
                    ));
                    return;
                }
            }
        }
        if rows > start {
            self.models.push(start..rows);
        }
    }

    /// Row `r`'s values (labels and numbers only when `read`), for frame `frame`.
    fn site(&self, r: usize, read: bool, frame: usize, file: &Arc<str>) -> Result<Site, Error> {
        let mut s = Site::default();
        for (role, col) in &self.columns {
            let cell = col.cell(r);
            let bad = |expected| value_error(file, frame, col, r, cell, expected);
            let label = |expected| -> Result<Option<Label>, Error> {
                if !read || matches!(cell, Cell::Missing(_)) {
                    return Ok(None);
                }
                Label::from_utf8(text(cell, &mut [0; 32]))
                    .map(Some)
                    .ok_or_else(|| bad(expected))
            };
            let missing = matches!(cell, Cell::Missing(_));
            match *role {
                r @ (Role::X | Role::Y | Role::Z) if read => {
                    let axis = match r {
                        Role::X => 0,
                        Role::Y => 1,
                        _ => 2,
                    };
                    s.xyz[axis] = real(cell).ok_or_else(|| bad(NOT_A_COORDINATE[axis]))?;
                }
                Role::Id if read && !missing => {
                    s.id = Some(integer(cell).ok_or_else(|| bad("an integer _atom_site.id"))?);
                }
                Role::Symbol => s.symbol = label("an element symbol in type_symbol")?,
                Role::AltId => s.alt = !missing,
                Role::InsCode => s.ins_key = key(cell),
                Role::Asym(k) => {
                    s.asym_key[k] = key(cell);
                    s.asym[k] = label("a chain name of at most 15 bytes")?;
                }
                Role::Atom(k) => {
                    s.atom_key[k] = key(cell);
                    s.atom[k] = label("an atom name of at most 15 bytes")?;
                }
                Role::Comp(k) => {
                    s.comp_key[k] = key(cell);
                    s.comp[k] = label("a residue name of at most 15 bytes")?;
                }
                Role::Seq(k) => {
                    s.seq_key[k] = key(cell);
                    if read && !missing {
                        let expected = "an integer residue number (seq_id)";
                        s.seq[k] = Some(integer(cell).ok_or_else(|| bad(expected))?);
                    }
                }
                Role::Scalar(k) if read && !missing => {
                    s.scalar[k] = Some(real(cell).ok_or_else(|| bad(SCALAR_NAMES[k].1))?);
                }
                _ => {}
            }
        }
        Ok(s)
    }
}

/// A BinaryCIF file read as a trajectory ([`crate::Format::Bcif`]): models as frames.
pub(crate) struct BcifReader {
    file: Arc<str>,
    table: Table,
    cell: Option<UnitCell>,
    title: Option<String>,
    /// Frames ahead of the next read.
    next: usize,
    /// Model 1's atom count has been taken (frame 0 walked).
    first_counted: bool,
    /// Every frame has been walked once (the count is known good).
    scanned: bool,
    sites: AtomSites<usize>,
    models: ModelCheck,
}

impl BcifReader {
    /// Reads and decodes the whole file; `lenient` turns a model's atom count that differs
    /// from model 1's into a warning.
    pub fn new<R: Read>(mut src: R, file: Arc<str>, lenient: bool) -> Result<BcifReader, Error> {
        let mut bytes = Vec::new();
        src.read_to_end(&mut bytes).map_err(|source| Error::Io {
            at: Location::file(&file),
            source,
        })?;
        // A map first (a text CIF named .bcif is told here, not as a number and garbage).
        if !matches!(bytes.first(), Some(0x80..=0x8f | 0xde | 0xdf)) {
            return Err(Error::Parse {
                at: at(&file, None, 0),
                expected: "a BinaryCIF file: a MessagePack map with dataBlocks",
                found: Error::found(&bytes[..bytes.len().min(16)]),
            });
        }
        let root = unpack(&bytes, &file)?;
        let cats = categories(&root, &file, bytes.len())?;
        let find = |name: &str| cats.iter().find(|c| c.name == name);
        let Some(atoms) = find("_atom_site") else {
            let names: Vec<&str> = cats.iter().map(|c| c.name.as_str()).collect();
            return Err(Error::Parse {
                at: at(&file, None, root.at),
                expected: "an _atom_site category in the first data block",
                found: Error::found(names.join(" ").as_bytes()),
            });
        };
        let table = Table::new(atoms, &file)?;
        let mut cell = None;
        if let Some(c) = find("_cell") {
            let mut values = [None; 6];
            // Where the first value is, for an error of the cell they make.
            let mut first_at = None;
            for (k, item) in CELL_ITEMS.iter().enumerate() {
                values[k] = first_value(c, item, &file, |cell, col| {
                    first_at.get_or_insert(col.at);
                    match cell {
                        Cell::Missing(_) => Ok(None),
                        Cell::Str(s) => parse_f64(strip_esd(s)).map(Some).ok_or_else(|| {
                            value_error_open(
                                &file,
                                col,
                                cell,
                                "a number for a _cell length or angle",
                            )
                        }),
                        Cell::Int(v) => Ok(Some(v as f64)),
                        Cell::Float(v) => Ok(Some(v)),
                        Cell::Real(v) => Ok(Some(v as f64)),
                    }
                })?;
            }
            if let Some((lengths, angles)) = cell_values(values) {
                let c =
                    UnitCell::from_lengths_angles(lengths, angles).map_err(|e| Error::Parse {
                        at: at(&file, None, first_at.unwrap_or(c.at)),
                        expected: CELL_EXPECTED,
                        found: e.to_string(),
                    })?;
                cell = Some(c);
            }
        }
        let mut title = None;
        if let Some(s) = find("_struct") {
            title = first_value(s, "title", &file, |cell, _| {
                Ok(match cell {
                    Cell::Missing(_) => None,
                    c => {
                        let t = String::from_utf8_lossy(text(c, &mut [0; 32])).into_owned();
                        // Lines joined by spaces, as the text reader joins a text field's.
                        let lines: Vec<&str> =
                            t.split('\n').map(|l| l.trim_end_matches('\r')).collect();
                        Some(lines.join(" ").trim().to_string())
                    }
                })
            })?;
        }
        let mut sites = AtomSites::default();
        let roles: Vec<Role> = table.columns.iter().map(|(role, _)| *role).collect();
        sites.set_columns(&roles);
        Ok(BcifReader {
            file,
            table,
            cell,
            title,
            next: 0,
            first_counted: false,
            scanned: false,
            sites,
            models: ModelCheck::new(lenient),
        })
    }

    /// The warnings gathered so far (emptied).
    pub fn take_warnings(&mut self) -> Vec<Error> {
        self.models.take_warnings()
    }

    /// The error of a damaged model order, for frame `k` and past it.
    fn broken(&self, k: usize) -> Option<Error> {
        let (frame, at, expected, found) = self.table.broken.as_ref()?;
        (k >= *frame).then(|| Error::Parse {
            at: at.clone(),
            expected,
            found: found.clone(),
        })
    }

    /// Reads (with a frame) or checks (without) frame `k`; `Ok(false)` past the last.
    fn walk(&mut self, k: usize, mut frame: Option<&mut Frame>) -> Result<bool, Error> {
        let Some(rows) = self.table.models.get(k).cloned() else {
            return match self.broken(k) {
                Some(e) => Err(e),
                None => Ok(false),
            };
        };
        if k > 0 && !self.first_counted {
            self.walk(0, None)?;
        }
        self.sites.start_frame();
        let read = frame.is_some();
        for r in rows {
            let site = self.table.site(r, read, k, &self.file)?;
            self.sites.push(&site, r, frame.as_deref_mut());
        }
        let file = &self.file;
        let n = self.sites.n_atoms;
        // At the model numbers' column.
        let model_at = (self.table.columns.iter())
            .find(|(r, _)| *r == Role::Model)
            .map_or(0, |(_, c)| c.at);
        self.models
            .check_at(k, || at(file, Some(k), model_at), n, MODEL_EXPECTED)?;
        if k == 0 {
            self.first_counted = true;
        }
        if let Some((dropped, row)) = self.sites.dropped() {
            let place = Location {
                byte: None,
                ..at(file, Some(k), 0)
            };
            let first = format!("the first: _atom_site row {}", row + 1);
            let w = altloc_warning(place, dropped, &first);
            self.models.warn(k, ALTLOC_EXPECTED, w);
        }
        if let Some(f) = frame {
            if let Some(bad) = first_out_of_bounds(&f.positions) {
                let x = self.table.columns.iter().find(|(r, _)| *r == Role::X);
                return Err(Error::Parse {
                    at: at(file, Some(k), x.map_or(0, |(_, c)| c.at)),
                    expected: IN_BOUNDS,
                    found: format!("atom {bad}: {:?}", f.positions[bad]),
                });
            }
            f.cell = self.cell;
            if k == 0
                && let Some(t) = &self.title
            {
                f.comment.clone_from(t);
            }
        }
        Ok(true)
    }

    /// Reads the next frame into `frame` (cleared first); `Ok(false)` after the last.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        match self.walk(self.next, Some(frame)) {
            Ok(true) => {
                self.next += 1;
                Ok(true)
            }
            Ok(false) => Ok(false),
            Err(e) => {
                frame.clear();
                Err(e)
            }
        }
    }

    /// Makes `read_next` read frame `n`; `Ok(false)` when there is none.
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        let good = self.table.models.len();
        let exists = match self.broken(good) {
            // A damaged model order: its frame starts (reading it gives the error), a frame
            // past it cannot be reached.
            Some(e) if n > good => return Err(e),
            Some(_) => n <= good,
            None => n < good,
        };
        if exists {
            self.next = n;
        }
        Ok(exists)
    }

    /// The number of frames: every frame walked once (counts checked); a damaged one's error.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        if !self.scanned {
            for k in 0..self.table.models.len() {
                self.walk(k, None)?;
            }
            if let Some(e) = self.broken(self.table.models.len()) {
                return Err(e);
            }
            self.scanned = true;
        }
        Ok(self.table.models.len())
    }
}

/// A value error met while the file is opened (a `_cell` value): no frame.
fn value_error_open(file: &Arc<str>, col: &Column, cell: Cell, expected: &'static str) -> Error {
    Error::Parse {
        at: at(file, None, col.at),
        expected,
        found: format!(
            "{} row 1: {}",
            col.name,
            Error::found(text(cell, &mut [0; 32]))
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tiny MessagePack writer for hand-built files.
    enum M {
        Bool(bool),
        Int(i64),
        F(f64),
        S(&'static str),
        T(String),
        B(Vec<u8>),
        A(Vec<M>),
        O(Vec<(&'static str, M)>),
    }

    fn pack(m: &M, out: &mut Vec<u8>) {
        match m {
            M::Bool(b) => out.push(if *b { 0xc3 } else { 0xc2 }),
            M::Int(v) => {
                out.push(0xd3);
                out.extend(v.to_be_bytes());
            }
            M::F(v) => {
                out.push(0xcb);
                out.extend(v.to_bits().to_be_bytes());
            }
            M::S(s) => pack(&M::T(s.to_string()), out),
            M::T(s) => {
                out.push(0xda);
                out.extend((s.len() as u16).to_be_bytes());
                out.extend(s.as_bytes());
            }
            M::B(b) => {
                out.push(0xc6);
                out.extend((b.len() as u32).to_be_bytes());
                out.extend(b);
            }
            M::A(a) => {
                out.push(0xdc);
                out.extend((a.len() as u16).to_be_bytes());
                for x in a {
                    pack(x, out);
                }
            }
            M::O(o) => {
                out.push(0xde);
                out.extend((o.len() as u16).to_be_bytes());
                for (k, v) in o {
                    pack(&M::S(k), out);
                    pack(v, out);
                }
            }
        }
    }

    fn enc(kind: &'static str, params: Vec<(&'static str, M)>) -> M {
        let mut o = vec![("kind", M::S(kind))];
        o.extend(params);
        M::O(o)
    }

    fn byte_array(t: i64) -> M {
        enc("ByteArray", vec![("type", M::Int(t))])
    }

    /// Decodes `bytes` under `encodings` (at most `limit` values).
    fn run(bytes: Vec<u8>, encodings: Vec<M>, limit: usize) -> Result<Stage<'static>, Error> {
        let data = M::O(vec![("data", M::B(bytes)), ("encoding", M::A(encodings))]);
        let mut b = Vec::new();
        pack(&data, &mut b);
        let b: &'static [u8] = Box::leak(b.into_boxed_slice());
        let file: Arc<str> = "t.bcif".into();
        let node = unpack(b, &file)?;
        let node: &'static Node<'static> = Box::leak(Box::new(node));
        decode(
            node,
            limit,
            &ColumnAt {
                file: &file,
                column: "_t.c",
            },
        )
    }

    fn ints(s: Stage) -> Vec<i64> {
        match s {
            Stage::Ints(v) => v,
            _ => panic!("not integers"),
        }
    }

    fn floats(s: Stage) -> Vec<f64> {
        match s {
            Stage::Floats(v) => v,
            _ => panic!("not floats"),
        }
    }

    #[test]
    fn byte_arrays_of_every_type_are_little_endian() {
        let b = vec![0xff, 0x80, 0x01, 0x00];
        assert_eq!(
            ints(run(b.clone(), vec![byte_array(1)], 9).unwrap()),
            [-1, -128, 1, 0]
        );
        assert_eq!(
            ints(run(b.clone(), vec![byte_array(4)], 9).unwrap()),
            [255, 128, 1, 0]
        );
        assert_eq!(
            ints(run(b.clone(), vec![byte_array(2)], 9).unwrap()),
            [-32513, 1]
        );
        assert_eq!(
            ints(run(b.clone(), vec![byte_array(5)], 9).unwrap()),
            [33023, 1]
        );
        assert_eq!(
            ints(run(b.clone(), vec![byte_array(3)], 9).unwrap()),
            [98559]
        );
        let m = vec![0xff; 4];
        assert_eq!(ints(run(m.clone(), vec![byte_array(3)], 9).unwrap()), [-1]);
        assert_eq!(ints(run(m, vec![byte_array(6)], 9).unwrap()), [4294967295]);
        let f = 1.5f32.to_le_bytes().to_vec();
        assert_eq!(floats(run(f, vec![byte_array(32)], 9).unwrap()), [1.5]);
        let d = (-2.25f64).to_le_bytes().to_vec();
        assert_eq!(floats(run(d, vec![byte_array(33)], 9).unwrap()), [-2.25]);
        let e = run(vec![1, 2, 3], vec![byte_array(2)], 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("column _t.c: 3 bytes of 2-byte elements"), "{e}");
        let e = run(vec![1], vec![byte_array(7)], 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("type 7"), "{e}");
    }

    #[test]
    fn fixed_point_and_interval_quantization() {
        let k: Vec<u8> = [35999i32, -200, 7]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let fp = enc(
            "FixedPoint",
            vec![("factor", M::Int(1000)), ("srcType", M::Int(33))],
        );
        let v = floats(run(k.clone(), vec![fp, byte_array(3)], 9).unwrap());
        assert_eq!(v, [35.999, -0.2, 0.007]);
        let iq = enc(
            "IntervalQuantization",
            vec![
                ("min", M::F(1.0)),
                ("max", M::F(2.0)),
                ("numSteps", M::Int(3)),
                ("srcType", M::Int(33)),
            ],
        );
        let v = floats(run(vec![0, 1, 2], vec![iq, byte_array(4)], 9).unwrap());
        assert_eq!(v, [1.0, 1.5, 2.0]);
        let one = enc(
            "IntervalQuantization",
            vec![
                ("min", M::F(1.0)),
                ("max", M::F(2.0)),
                ("numSteps", M::Int(1)),
                ("srcType", M::Int(33)),
            ],
        );
        assert!(run(vec![0], vec![one, byte_array(4)], 9).is_err());
    }

    /// The module doc's # Numbers: k / 1000 rounded twice (to the double, then to `f32`) is
    /// the `f32` a parse of the decimal gives, over a million values of every magnitude.
    #[test]
    fn fixed_point_coordinates_are_the_parsed_decimals() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..1_000_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let k = (x % 20_000_000_000) as i64 - 10_000_000_000;
            let decimal = format!(
                "{}{}.{:03}",
                if k < 0 { "-" } else { "" },
                k.abs() / 1000,
                k.abs() % 1000
            );
            let parsed = parse_f32(decimal.as_bytes()).unwrap();
            assert_eq!((k as f64 / 1000.0) as f32, parsed, "{decimal}");
        }
    }

    #[test]
    fn run_length_delta_and_packing() {
        let rl = |size| {
            enc(
                "RunLength",
                vec![("srcSize", M::Int(size)), ("srcType", M::Int(3))],
            )
        };
        // [1, 3, 2, 1, 3, 2] -> 1 1 1 2 3 3 (the spec's example).
        let b = vec![1, 3, 2, 1, 3, 2];
        assert_eq!(
            ints(run(b.clone(), vec![rl(6), byte_array(4)], 6).unwrap()),
            [1, 1, 1, 2, 3, 3]
        );
        let e = run(b.clone(), vec![rl(7), byte_array(4)], 6)
            .unwrap_err()
            .to_string();
        assert!(e.contains("RunLength output 7 values, at most 6"), "{e}");
        let e = run(b.clone(), vec![rl(5), byte_array(4)], 6)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a run of 2 after 4 of srcSize 5"), "{e}");
        let e = run(vec![1, 2], vec![rl(3), byte_array(4)], 6)
            .unwrap_err()
            .to_string();
        assert!(e.contains("runs of 2 values, srcSize 3"), "{e}");
        // A huge count is refused before anything is allocated.
        let big: Vec<u8> = [1i32, i32::MAX]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert!(run(big, vec![rl(6), byte_array(3)], 6).is_err());
        // Delta: [1000, 1003, 1005, 1006] from origin 1000, and Int8 wrapping.
        let delta = |origin, t| {
            enc(
                "Delta",
                vec![("origin", M::Int(origin)), ("srcType", M::Int(t))],
            )
        };
        assert_eq!(
            ints(run(vec![0, 3, 2, 1], vec![delta(1000, 3), byte_array(1)], 9).unwrap()),
            [1000, 1003, 1005, 1006]
        );
        assert_eq!(
            ints(run(vec![100, 100], vec![delta(0, 1), byte_array(4)], 9).unwrap()),
            [100, -56]
        );
        // IntegerPacking: [1, 2, -3, 128] as signed bytes [1, 2, -3, 127, 1] (the spec's).
        let pack = |n, unsigned, size| {
            enc(
                "IntegerPacking",
                vec![
                    ("byteCount", M::Int(n)),
                    ("isUnsigned", M::Bool(unsigned)),
                    ("srcSize", M::Int(size)),
                ],
            )
        };
        let b = vec![1, 2, 0xfd, 0x7f, 1];
        assert_eq!(
            ints(run(b, vec![pack(1, false, 4), byte_array(1)], 9).unwrap()),
            [1, 2, -3, 128]
        );
        let b = vec![0x80, 0x80, 0x00];
        assert_eq!(
            ints(run(b, vec![pack(1, false, 1), byte_array(1)], 9).unwrap()),
            [-256]
        );
        let b = vec![0xff, 0xff, 4, 9];
        assert_eq!(
            ints(run(b, vec![pack(1, true, 2), byte_array(4)], 9).unwrap()),
            [514, 9]
        );
        let b: Vec<u8> = [0x7fff_i16, 1, -0x8000, -1]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            ints(run(b, vec![pack(2, false, 2), byte_array(2)], 9).unwrap()),
            [32768, -32769]
        );
        let b: Vec<u8> = [0xffff_u16, 0xffff, 2]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            ints(run(b, vec![pack(2, true, 1), byte_array(5)], 9).unwrap()),
            [131072]
        );
        // Already srcSize values: left as they are.
        assert_eq!(
            ints(run(vec![255, 1], vec![pack(1, true, 2), byte_array(4)], 9).unwrap()),
            [255, 1]
        );
        // A value cut by the end, too many values, srcSize past the packed values, a
        // byteCount of 3.
        let e = run(vec![1, 255], vec![pack(1, true, 1), byte_array(4)], 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a cut one"), "{e}");
        let e = run(vec![1, 2], vec![pack(1, true, 1), byte_array(4)], 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than 1 values from 2 packed"), "{e}");
        assert!(run(vec![1], vec![pack(1, true, 2), byte_array(4)], 9).is_err());
        let e = run(vec![1, 2, 3], vec![pack(3, true, 2), byte_array(4)], 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("byteCount 3"), "{e}");
    }

    #[test]
    fn string_arrays_and_wrong_orders() {
        // ['a', 'AB', 'a', missing]: stringData "aAB", offsets [0, 1, 3], indices [0, 1, 0, -1].
        let sa = enc(
            "StringArray",
            vec![
                ("stringData", M::S("aAB")),
                ("offsets", M::B(vec![0, 1, 3])),
                ("offsetEncoding", M::A(vec![byte_array(4)])),
                ("dataEncoding", M::A(vec![byte_array(1)])),
            ],
        );
        let Stage::Strings(s) = run(vec![0, 1, 0, 0xff], vec![sa], 9).unwrap() else {
            panic!("strings");
        };
        let got: Vec<&[u8]> = s
            .rows
            .iter()
            .map(|&r| &s.text[s.spans[r as usize].0 as usize..s.spans[r as usize].1 as usize])
            .collect();
        assert_eq!(got, [&b"a"[..], b"AB", b"a", b""]);
        // Offsets count UTF-16 units: "Å" is one unit of two bytes.
        let sa = enc(
            "StringArray",
            vec![
                ("stringData", M::S("ÅB")),
                ("offsets", M::B(vec![0, 1, 2])),
                ("offsetEncoding", M::A(vec![byte_array(4)])),
                ("dataEncoding", M::A(vec![byte_array(4)])),
            ],
        );
        let Stage::Strings(s) = run(vec![0, 1], vec![sa], 9).unwrap() else {
            panic!("strings");
        };
        assert_eq!(s.spans, [(0, 0), (0, 2), (2, 3)]);
        // An index past the strings.
        let sa = enc(
            "StringArray",
            vec![
                ("stringData", M::S("a")),
                ("offsets", M::B(vec![0, 1])),
                ("offsetEncoding", M::A(vec![byte_array(4)])),
                ("dataEncoding", M::A(vec![byte_array(4)])),
            ],
        );
        let e = run(vec![0, 1], vec![sa], 9).unwrap_err().to_string();
        assert!(e.contains("row 2: index 1 of 1 strings"), "{e}");
        // A ByteArray over decoded values, FixedPoint over floats, an unknown kind.
        assert!(run(vec![0], vec![byte_array(4), byte_array(4)], 9).is_err());
        let fp = enc(
            "FixedPoint",
            vec![("factor", M::Int(10)), ("srcType", M::Int(33))],
        );
        assert!(run(vec![0; 8], vec![fp, byte_array(33)], 9).is_err());
        let e = run(vec![0], vec![enc("Zip", vec![])], 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("kind Zip"), "{e}");
    }

    #[test]
    fn msgpack_counts_and_depth_are_bounded() {
        let file: Arc<str> = "t.bcif".into();
        // An array claiming 2^32 - 1 values in 6 bytes: refused, nothing allocated.
        let e = unpack(&[0xdd, 0xff, 0xff, 0xff, 0xff, 0x00], &file).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
        let e = unpack(&[0xc6, 0, 0, 1, 0, 1, 2], &file).unwrap_err();
        assert!(e.to_string().starts_with("t.bcif: byte 7"), "{e}");
        let deep = vec![0x91; 100];
        let e = unpack(&deep, &file).unwrap_err().to_string();
        assert!(e.contains("nested at most 32"), "{e}");
        let e = unpack(&[0xc1], &file).unwrap_err().to_string();
        assert!(e.contains("0xc1"), "{e}");
        let e = unpack(&[0xc0, 0xc0], &file).unwrap_err().to_string();
        assert!(e.contains("t.bcif: byte 1"), "{e}");
        // Every kind of integer and float.
        let n = unpack(
            &[0x93, 0xd0, 0x80, 0xcd, 0x01, 0x00, 0xca, 0x3f, 0xc0, 0, 0],
            &file,
        )
        .unwrap();
        let a = n.array().unwrap();
        assert_eq!(
            (a[0].int(), a[1].int(), a[2].number()),
            (Some(-128), Some(256), Some(1.5))
        );
        assert!(is_bcif(&[
            0x83, 0xa7, b'e', b'n', b'c', b'o', b'd', b'e', b'r'
        ]));
        assert!(is_bcif(b"\x83\xaadataBlocks"));
        assert!(!is_bcif(b"data_1abc"));
    }

    /// A column of Int32 values, Float64 values or strings (a StringArray), with a mask.
    fn col(name: &'static str, values: Col, mask: Option<&[u8]>) -> M {
        let (bytes, encoding) = match values {
            Col::I(v) => (
                v.iter().flat_map(|x| x.to_le_bytes()).collect(),
                byte_array(3),
            ),
            Col::F(v) => (
                v.iter().flat_map(|x| x.to_le_bytes()).collect(),
                byte_array(33),
            ),
            Col::S(v) => {
                let mut unique: Vec<&str> = Vec::new();
                let mut index = Vec::new();
                for x in v {
                    let k = unique.iter().position(|u| *u == x).unwrap_or_else(|| {
                        unique.push(x);
                        unique.len() - 1
                    });
                    index.extend((k as i32).to_le_bytes());
                }
                let mut offsets = vec![0i32];
                for u in &unique {
                    offsets.push(offsets.last().unwrap() + u.len() as i32);
                }
                let sa = enc(
                    "StringArray",
                    vec![
                        ("stringData", M::T(unique.concat())),
                        (
                            "offsets",
                            M::B(offsets.iter().flat_map(|x| x.to_le_bytes()).collect()),
                        ),
                        ("offsetEncoding", M::A(vec![byte_array(3)])),
                        ("dataEncoding", M::A(vec![byte_array(3)])),
                    ],
                );
                (index, sa)
            }
        };
        let data = M::O(vec![
            ("data", M::B(bytes)),
            ("encoding", M::A(vec![encoding])),
        ]);
        let mut o = vec![("name", M::S(name)), ("data", data)];
        if let Some(m) = mask {
            let m = M::O(vec![
                ("data", M::B(m.to_vec())),
                ("encoding", M::A(vec![byte_array(4)])),
            ]);
            o.push(("mask", m));
        }
        M::O(o)
    }

    enum Col {
        I(Vec<i32>),
        F(Vec<f64>),
        S(Vec<&'static str>),
    }

    /// A file of one block holding `_atom_site` with `columns` and `rows` rows.
    fn file(rows: i64, columns: Vec<M>) -> Vec<u8> {
        let cat = M::O(vec![
            ("name", M::S("_atom_site")),
            ("rowCount", M::Int(rows)),
            ("columns", M::A(columns)),
        ]);
        let block = M::O(vec![
            ("header", M::S("hand")),
            ("categories", M::A(vec![cat])),
        ]);
        let root = M::O(vec![
            ("encoder", M::S("hand")),
            ("version", M::S("0.3.0")),
            ("dataBlocks", M::A(vec![block])),
        ]);
        let mut b = Vec::new();
        pack(&root, &mut b);
        b
    }

    /// Frames and warnings of `bytes`, or the first error.
    fn frames(bytes: &[u8], lenient: bool) -> Result<(Vec<Frame>, Vec<String>), Error> {
        let opts = crate::ReadOptions::new().allow_truncated(lenient);
        let src = std::io::Cursor::new(bytes);
        let mut t = crate::Trajectory::from_reader_with(src, crate::Format::Bcif, "h.bcif", opts)?;
        let n = t.n_frames()?;
        let mut out = Vec::new();
        let mut f = Frame::new();
        while t.read_next(&mut f)? {
            out.push(f.clone());
        }
        assert_eq!(out.len(), n);
        Ok((out, t.warnings().iter().map(|w| w.to_string()).collect()))
    }

    fn xyz(n: usize) -> Vec<M> {
        let v = |a: f64| Col::F((0..n).map(|i| a + i as f64).collect());
        vec![
            col("Cartn_x", v(0.0), None),
            col("Cartn_y", v(10.0), None),
            col("Cartn_z", v(20.0), None),
        ]
    }

    #[test]
    fn hand_built_files_follow_the_text_readers_rules() {
        // Models of 2 and 1 atoms: an error at frame 1, a warning under allow_truncated.
        let mut c = xyz(3);
        c.push(col("pdbx_PDB_model_num", Col::I(vec![1, 1, 2]), None));
        c.push(col("label_atom_id", Col::S(vec!["N", "CA", "N"]), None));
        let b = file(3, c);
        let e = frames(&b, false).unwrap_err().to_string();
        assert!(e.starts_with("h.bcif: frame 1, byte "), "{e}");
        assert!(e.contains("'1 atoms, model 1 has 2'"), "{e}");
        let (f, w) = frames(&b, true).unwrap();
        assert_eq!((f.len(), w.len()), (2, 1), "{w:?}");
        assert_eq!(f[1].positions, [[2.0, 12.0, 22.0]]);
        assert_eq!(f[0].names[1], "CA");
        // Model numbers that fall: frame 0 (the one being read) fails.
        let mut c = xyz(2);
        c.push(col("pdbx_PDB_model_num", Col::I(vec![2, 1]), None));
        let e = frames(&file(2, c), false).unwrap_err().to_string();
        assert!(
            e.contains("frame 0") && e.contains("row 2: model 1 after model 2"),
            "{e}"
        );
        // Model 1, model 2, then model 1 again: frame 0 reads, frame 1 is the damage, by
        // streaming, by index and by count alike.
        let mut c = xyz(3);
        c.push(col("pdbx_PDB_model_num", Col::I(vec![1, 2, 1]), None));
        let b = file(3, c);
        let src = std::io::Cursor::new(&b);
        let mut t = crate::Trajectory::from_reader(src, crate::Format::Bcif, "h.bcif").unwrap();
        let mut f = Frame::new();
        t.read_frame(0, &mut f).unwrap();
        for k in [1, 2] {
            let e = t.read_frame(k, &mut f).unwrap_err().to_string();
            assert!(
                e.contains("frame 1") && e.contains("model 1 after model 2"),
                "{e}"
            );
        }
        assert!(t.n_frames().is_err());
        t.read_frame(0, &mut f).unwrap();
        assert!(t.read_next(&mut f).is_err());
        // A coordinate that is not a number; a masked one ('?').
        let mut c = xyz(2);
        c[1] = col("Cartn_y", Col::S(vec!["1.5", "x"]), None);
        let e = frames(&file(2, c), false).unwrap_err().to_string();
        assert!(e.starts_with("h.bcif: frame 0, byte "), "{e}");
        assert!(
            e.ends_with(
                "expected a number for _atom_site.Cartn_y, found '_atom_site.Cartn_y row 2: x'"
            ),
            "{e}"
        );
        let mut c = xyz(2);
        c[2] = col("Cartn_z", Col::F(vec![0.0, 1.0]), Some(&[0, 2]));
        let e = frames(&file(2, c), false).unwrap_err().to_string();
        assert!(e.contains("Cartn_z row 2: ?"), "{e}");
        // Masked (and unmasked '.') alternate locations are none; a chain as an integer.
        let mut c = xyz(2);
        c.push(col("label_alt_id", Col::S(vec!["A", "."]), Some(&[1, 0])));
        c.push(col("auth_asym_id", Col::I(vec![7, 7]), None));
        c.push(col("label_atom_id", Col::S(vec!["O", "O"]), None));
        let (f, w) = frames(&file(2, c), false).unwrap();
        assert_eq!((f[0].n_atoms(), w.len()), (2, 0));
        assert_eq!(f[0].chains[0], "7");
        // An alternate location of an atom already kept: dropped, with the row in the warning.
        let mut c = xyz(2);
        c.push(col("label_alt_id", Col::S(vec!["A", "B"]), None));
        c.push(col("label_atom_id", Col::S(vec!["O", "O"]), None));
        let (f, w) = frames(&file(2, c), false).unwrap();
        assert_eq!(f[0].n_atoms(), 1);
        assert!(
            w[0].starts_with("h.bcif: frame 0: expected one conformation"),
            "{w:?}"
        );
        assert!(
            w[0].contains(
                "'1 rows of other alternate locations, dropped (the first: _atom_site row 2)'"
            ),
            "{w:?}"
        );
        // A used column twice; no Cartn_y; a column of the wrong length; a rowCount past the
        // file; no rows.
        let mut c = xyz(2);
        c.push(col("Cartn_x", Col::F(vec![0.0; 2]), None));
        let e = frames(&file(2, c), false).unwrap_err().to_string();
        assert!(e.contains("found 'column Cartn_x again'"), "{e}");
        let mut c = xyz(2);
        c.remove(1);
        let e = frames(&file(2, c), false).unwrap_err().to_string();
        assert!(
            e.contains("no _atom_site.Cartn_y among the category's columns"),
            "{e}"
        );
        let mut c = xyz(2);
        c[0] = col("Cartn_x", Col::F(vec![0.0; 3]), None);
        let e = frames(&file(2, c), false).unwrap_err().to_string();
        assert!(
            e.contains("found 'column _atom_site.Cartn_x: ByteArray output 3 values, rowCount 2'"),
            "{e}"
        );
        let e = frames(&file(1 << 40, xyz(2)), false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("rowCount 1099511627776 in a file of"), "{e}");
        assert!(frames(&file(0, xyz(0)), false).unwrap().0.is_empty());
        // A coordinate past 1e7 Å.
        let mut c = xyz(1);
        c[0] = col("Cartn_x", Col::F(vec![2e7]), None);
        let e = frames(&file(1, c), false).unwrap_err().to_string();
        assert!(e.contains("finite coordinates within"), "{e}");
    }
}
