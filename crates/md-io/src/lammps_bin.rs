//! LAMMPS binary dumps: `dump atom` and `dump custom` written to a file whose name ends in
//! `.bin`, read into the same [`Frame`] as the text dump of the same data (src/lammps.rs).
//!
//! # Layout
//! The writing machine's byte order, frame after frame (`bigint` is 8 bytes, LAMMPS's default
//! build):
//!
//! ```text
//! [i64 −len, len bytes "DUMPCUSTOM" or "DUMPATOM", i32 endian = 1, i32 revision]  magic header
//! i64 timestep   i64 natoms   i32 triclinic   i32 boundary[3][2] (0 p, 1 f, 2 s, 3 m)
//! triclinic 0: f64 xlo xhi ylo yhi zlo zhi          (the box)
//! triclinic 1: f64 xlo xhi ylo yhi zlo zhi xy xz yz (its bounding box and tilts)
//! triclinic 2: f64 avec[3] bvec[3] cvec[3] boxlo[3] (general triclinic, LAMMPS 2024+)
//! i32 size_one                                      (values per atom)
//! [revision >= 2: i32 n, n bytes unit style (n = 0 after the first frame that named it),
//!                 u8 time flag [f64 time], i32 n, n bytes column names]
//! i32 nchunk, then nchunk times: i32 n, n f64 (n / size_one atoms, size_one values each)
//! ```
//! A chunk is what one MPI rank (or, with `dump_modify nfile`, one cluster of ranks) holds; every
//! value is a double, integers (`id`, `type`, `ix`) included.
//!
//! # Versions
//! - **Revision 2** (LAMMPS 29 Sep 2021 writes it: tests/data/lammps_bin/): magic header, units,
//!   time and column names. The names map to the frame as the text dump's `ITEM: ATOMS` line does
//!   ([`crate::lammps::plan_columns`]); the unit style, written once, holds for the frames
//!   after it.
//! - **Revision 1** and **no magic header** (older LAMMPS; the first i64 is then the timestep,
//!   so it is never negative): no names. The names come from
//!   [`crate::ReadOptions::lammps_columns`], OVITO's approach (its binary dump importer asks for
//!   the column mapping). Without them, a file whose `size_one` is 5 or 8 is read as `dump
//!   atom`'s default columns, `id type xs ys zs` and `ix iy iz` (`dump_modify scale yes`, the
//!   default): a frame with a scaled coordinate outside [−0.5, 1.5], which no atom in its box
//!   has, is an error naming the atom and asking for the names (`scale no` and a 5-column `dump
//!   custom` write box coordinates there); any other `size_one` is an error asking for them.
//!   Files without a magic header are told little- from big-endian by their flags (triclinic 0
//!   or 1, boundaries 0 to 3).
//!
//! Not read: a `-DLAMMPS_SMALLSMALL` build's 4-byte timestep and atom count (an error naming
//! the header). In a binary dump an `element` column holds the type number (LAMMPS writes no
//! strings there): it becomes the property `element`. A value beyond f32's range becomes ±inf
//! in a property (drawn grey, as NaN), and is an error in a position, velocity, radius or colour.
//!
//! # Checks
//! Nothing is sized from the header before the file is seen to hold it: string lengths are
//! checked against the bytes left, every chunk against what the header's `natoms × size_one`
//! leaves (and the chunks' sum against it), the data against the file's end. The frame index
//! (16 bytes per frame: its start and the units in force) is built at open time from the headers
//! and chunk counts alone, skipping the data; a frame is parsed again when read. A frame cut by
//! the end of the file is [`Error::Truncated`] for that frame (kept out, with a warning, under
//! `allow_truncated`); any other inconsistency is [`Error::Parse`] naming the byte.
//!
//! # References
//! - LAMMPS `src/dump_custom.cpp` and `src/dump_atom.cpp` (`header_binary*`,
//!   `format_magic_string_binary`, `write_binary`) and `tools/binary2txt.cpp` (read, not copied).

use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, first_out_of_bounds};
use crate::dcd::{Endian, u32_at, u64_at};
use crate::error::{Error, Location};
use crate::frame::{Frame, Label, Property, UnitCell};
use crate::lammps::{Act, BoxKind, IdSort, PosKind, Units, cell_from_bounds, plan_columns};

/// Longest magic string read (LAMMPS writes 8 or 10 bytes).
const MAX_MAGIC: i64 = 64;
/// Bytes of atom rows decoded at a time (at least one row): small enough to stay in cache.
const BLOCK: usize = 256 * 1024;
/// The magic strings LAMMPS writes.
const MAGICS: [&[u8]; 2] = [b"DUMPCUSTOM", b"DUMPATOM"];
/// `dump atom`'s default columns, by `size_one`, for files that do not name them.
const DUMP_ATOM_5: &[u8] = b"id type xs ys zs";
const DUMP_ATOM_8: &[u8] = b"id type xs ys zs ix iy iz";
/// Type numbers below this have their labels kept from atom to atom.
const TYPE_LABELS: usize = 4096;
/// Scaled coordinates of atoms in their box stay within this distance of 0.5: [−0.5, 1.5] (an
/// atom leaves its box by at most what it moved since the last reneighbouring).
const SCALED_SLACK: f64 = 1.0;

/// One frame header, checked.
#[derive(Debug)]
struct Header {
    endian: Endian,
    step: i64,
    natoms: u64,
    periodic: [bool; 3],
    kind: BoxKind,
    /// Per axis `[lo, hi, tilt, _]`, or `[a_k, b_k, c_k, origin_k]` (general triclinic).
    rows: [[f64; 4]; 3],
    /// Byte of the box values.
    box_at: u64,
    size_one: usize,
    /// Byte of `size_one`.
    size_at: u64,
    /// The unit style the header names (the first frame's, in a revision-2 file).
    units: Option<Units>,
    time: Option<f64>,
    /// The column names (revision 2), and their byte.
    names: Option<(Vec<u8>, u64)>,
    nchunk: usize,
    /// Byte of the first chunk's count.
    data: u64,
}

/// Where a frame starts, and the unit style in force there.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    start: u64,
    units: Units,
}

/// A buffered, position-tracking view of the source.
struct Src<R> {
    r: BufReader<R>,
    pos: u64,
    /// A read or seek failed: where the source stands is unknown until the next seek.
    lost: bool,
    len: u64,
}

impl<R: Read + Seek> Src<R> {
    fn seek(&mut self, to: u64) -> io::Result<()> {
        if to == self.pos && !self.lost {
            return Ok(());
        }
        // Within the buffer when close: `seek_relative` keeps it.
        let delta = i64::try_from(i128::from(to) - i128::from(self.pos)).unwrap_or(i64::MAX);
        let relative = !self.lost && delta.unsigned_abs() < 1 << 20;
        // Lost until the seek succeeds.
        self.lost = true;
        if relative {
            self.r.seek_relative(delta)?;
        } else {
            self.r.seek(SeekFrom::Start(to))?;
        }
        self.pos = to;
        self.lost = false;
        Ok(())
    }

    fn left(&self) -> u64 {
        self.len.saturating_sub(self.pos)
    }

    fn read(&mut self, out: &mut [u8]) -> io::Result<()> {
        if let Err(e) = self.r.read_exact(out) {
            self.lost = true;
            return Err(e);
        }
        self.pos += out.len() as u64;
        Ok(())
    }
}

/// What a header or chunk read needs: the source, and where errors point.
struct Cur<'a, R> {
    src: &'a mut Src<R>,
    file: &'a Arc<str>,
    frame: usize,
    endian: Endian,
}

impl<R: Read + Seek> Cur<'_, R> {
    fn parse(&self, at: u64, expected: &'static str, found: String) -> Error {
        Error::Parse {
            at: Location::binary(self.file, self.frame, at),
            expected,
            found,
        }
    }

    /// The data ends: `Truncated` at the end of the file, saying what was still needed.
    fn cut(&self, what: &str) -> Error {
        Error::Truncated {
            at: Location::binary(self.file, self.frame, self.src.len),
            expected: format!("{what} (byte {})", self.src.pos),
        }
    }

    fn io(&self, e: io::Error, what: &str) -> Error {
        if e.kind() == io::ErrorKind::UnexpectedEof {
            return self.cut(what);
        }
        Error::Io {
            at: Location::binary(self.file, self.frame, self.src.pos),
            source: e,
        }
    }

    /// `N` bytes, or the cut that stops them.
    fn bytes<const N: usize>(&mut self, what: &str) -> Result<[u8; N], Error> {
        if self.src.left() < N as u64 {
            return Err(self.cut(what));
        }
        let mut b = [0u8; N];
        self.src.read(&mut b).map_err(|e| self.io(e, what))?;
        Ok(b)
    }

    fn i32(&mut self, what: &str) -> Result<i32, Error> {
        Ok(u32_at(&self.bytes::<4>(what)?, self.endian) as i32)
    }

    fn i64(&mut self, what: &str) -> Result<i64, Error> {
        Ok(u64_at(&self.bytes::<8>(what)?, self.endian) as i64)
    }

    fn f64(&mut self, what: &str) -> Result<f64, Error> {
        Ok(f64::from_bits(u64_at(&self.bytes::<8>(what)?, self.endian)))
    }

    /// A length-prefixed string of at most the bytes left.
    fn string(&mut self, what: &str) -> Result<(Vec<u8>, u64), Error> {
        let at = self.src.pos;
        let n = self.i32(what)?;
        let Ok(n) = u64::try_from(n) else {
            return Err(self.parse(at, "a string length >= 0", n.to_string()));
        };
        if n > self.src.left() {
            return Err(self.cut(what));
        }
        let mut s = vec![0u8; n as usize];
        let start = self.src.pos;
        self.src.read(&mut s).map_err(|e| self.io(e, what))?;
        Ok((s, start))
    }
}

/// True when the first bytes of an old file (no magic header) read as a plausible frame
/// header in byte order `e`: triclinic 0 or 1, boundaries 0 to 3 with a periodic side only
/// opposite a periodic one.
fn bare_header_fits(h: &[u8], e: Endian) -> bool {
    if h.len() < 44 {
        return false;
    }
    let int = |k: usize| u32_at(&h[k..], e) as i32;
    let b: [i32; 6] = std::array::from_fn(|k| int(20 + 4 * k));
    matches!(int(16), 0 | 1)
        && b.iter().all(|v| (0..=3).contains(v))
        && (0..3).all(|k| (b[2 * k] == 0) == (b[2 * k + 1] == 0))
        && (u64_at(&h[8..], e) as i64) >= 0
}

/// Whether the first bytes of a file show a LAMMPS binary dump: the magic header (either byte
/// order), or a header without it whose fields are all plausible (timestep and atom count >= 0,
/// triclinic 0 or 1, boundaries 0 to 3, a finite box with lo <= hi, 1 to 4096 values per atom,
/// a first chunk of whole atoms within the count).
pub(crate) fn sniff(head: &[u8]) -> bool {
    for e in [Endian::Little, Endian::Big] {
        let Some(first) = head.get(..8).map(|b| u64_at(b, e) as i64) else {
            return false;
        };
        if (-MAX_MAGIC..0).contains(&first) {
            let len = first.unsigned_abs() as usize;
            if head.get(8..8 + len).is_some_and(|m| MAGICS.contains(&m)) {
                return true;
            }
        }
    }
    // No magic: the whole header's shape.
    [Endian::Little, Endian::Big].into_iter().any(|e| {
        if !bare_header_fits(head, e) {
            return false;
        }
        let int = |k: usize| head.get(k..k + 4).map(|b| u32_at(b, e) as i32);
        let real = |k: usize| head.get(k..k + 8).map(|b| f64::from_bits(u64_at(b, e)));
        let natoms = u64_at(&head[8..], e) as i64;
        let tri = int(16) == Some(1);
        let mut at = 44;
        let mut ok = true;
        for _ in 0..3 {
            match (real(at), real(at + 8)) {
                (Some(lo), Some(hi)) => ok &= lo.is_finite() && hi.is_finite() && lo <= hi,
                _ => return false,
            }
            at += 16;
        }
        if tri {
            for _ in 0..3 {
                ok &= real(at).is_some_and(f64::is_finite);
                at += 8;
            }
        }
        let (Some(size_one), Some(nchunk), Some(n)) = (int(at), int(at + 4), int(at + 8)) else {
            return false;
        };
        ok && (1..=4096).contains(&size_one)
            && nchunk >= 1
            && n >= 0
            && n % size_one == 0
            && i64::from(n) <= natoms.saturating_mul(i64::from(size_one))
    })
}

/// Reads a LAMMPS binary dump frame by frame, in any order.
pub struct LammpsBinReader<R> {
    src: Src<R>,
    file: Arc<str>,
    /// Column names for files that do not hold them ([`crate::ReadOptions::lammps_columns`]).
    columns: Option<Arc<str>>,
    frames: Vec<Entry>,
    /// The error of the frame after the last complete one (damaged or cut), if any.
    tail: Option<Error>,
    /// The byte order of frames without a magic header, told by the first of them.
    bare: Option<Endian>,
    /// The frame `read_next` reads.
    next: usize,
    // Per-frame scratch, reused: the column plan (and the names it was made from), a block
    // of raw rows, scaled positions, the sort by id.
    acts: Vec<Act>,
    properties: Vec<String>,
    pos_kind: PosKind,
    planned: Vec<u8>,
    block: Vec<u8>,
    xyz: Vec<[f64; 3]>,
    type_labels: Vec<Option<Label>>,
    sort: IdSort,
}

impl<R: Read + Seek> LammpsBinReader<R> {
    /// Opens a binary dump and indexes its frames from their headers and chunk counts; the
    /// column names for files without them are `columns` (see the module doc).
    ///
    /// A damaged or cut frame stops the index: the frames before it stay readable, and reading
    /// it (or counting) gives its error.
    pub fn new(mut src: R, file: Arc<str>, columns: Option<Arc<str>>) -> Result<Self, Error> {
        let io = |e| Error::Io {
            at: Location::binary(&file, 0, 0),
            source: e,
        };
        let len = src.seek(SeekFrom::End(0)).map_err(io)?;
        src.seek(SeekFrom::Start(0)).map_err(io)?;
        let mut r = LammpsBinReader {
            src: Src {
                r: BufReader::with_capacity(64 * 1024, src),
                pos: 0,
                lost: false,
                len,
            },
            file,
            columns,
            frames: Vec::new(),
            tail: None,
            bare: None,
            next: 0,
            acts: Vec::new(),
            properties: Vec::new(),
            pos_kind: PosKind::Cartesian,
            planned: Vec::new(),
            block: Vec::new(),
            xyz: Vec::new(),
            type_labels: Vec::new(),
            sort: IdSort::default(),
        };
        r.index();
        if r.frames.is_empty()
            && let Some(e) = r.tail.take()
        {
            return Err(e);
        }
        Ok(r)
    }

    /// Scans every frame's header and chunk counts, skipping the data.
    fn index(&mut self) {
        let mut start = 0u64;
        let mut units = Units::Unknown;
        while start < self.src.len {
            let k = self.frames.len();
            let scanned = self.header(k, start).and_then(|h| {
                chunks(&mut self.src, &self.file, &mut self.block, k, &h, None)?;
                Ok(h)
            });
            match scanned {
                Ok(h) => {
                    units = h.units.unwrap_or(units);
                    self.frames.push(Entry { start, units });
                    start = self.src.pos;
                }
                Err(e) => {
                    self.tail = Some(e);
                    return;
                }
            }
        }
    }

    /// Parses and checks the header of frame `k` at byte `start`; leaves the source at its first
    /// chunk.
    fn header(&mut self, k: usize, start: u64) -> Result<Header, Error> {
        let file = &self.file;
        let io = |e| Error::Io {
            at: Location::binary(file, k, start),
            source: e,
        };
        self.src.seek(start).map_err(io)?;
        let mut c = Cur {
            src: &mut self.src,
            file: &self.file,
            frame: k,
            endian: Endian::Little,
        };
        // A magic header (its negative length first, in either byte order), or the timestep
        // of a file without one.
        let first: [u8; 8] = c.bytes("the timestep or the magic header")?;
        let marker = |e| u64_at(&first, e) as i64;
        let magic = [Endian::Little, Endian::Big]
            .into_iter()
            .find(|&e| (-MAX_MAGIC..0).contains(&marker(e)));
        let named = match magic {
            Some(e) => {
                c.endian = e;
                let len = marker(e).unsigned_abs() as usize;
                let at = c.src.pos;
                if c.src.left() < len as u64 {
                    return Err(c.cut("the magic string"));
                }
                let mut m = vec![0u8; len];
                c.src
                    .read(&mut m)
                    .map_err(|e| c.io(e, "the magic string"))?;
                if !MAGICS.contains(&&m[..]) {
                    return Err(c.parse(
                        at,
                        "the magic string DUMPCUSTOM or DUMPATOM",
                        Error::found(&m),
                    ));
                }
                let at = c.src.pos;
                let endian = c.i32("the endian flag")?;
                if endian != 1 {
                    return Err(c.parse(
                        at,
                        "the endian flag 1 in the byte order of the magic header",
                        format!("{endian:#x}"),
                    ));
                }
                let at = c.src.pos;
                let revision = c.i32("the format revision")?;
                if !(1..=2).contains(&revision) {
                    return Err(c.parse(
                        at,
                        "format revision 1 or 2 (a newer LAMMPS may write fields this reader does not know)",
                        revision.to_string(),
                    ));
                }
                // Revision 1 is laid out as a file without a magic header.
                revision == 2
            }
            None => {
                // The first frame without a magic header tells the byte order by the flags
                // that follow its timestep; the file's later ones follow it.
                c.endian = match self.bare {
                    Some(e) => e,
                    None => {
                        let mut look = [0u8; 44];
                        look[..8].copy_from_slice(&first);
                        let have = (c.src.left() as usize).min(36);
                        c.src
                            .read(&mut look[8..8 + have])
                            .map_err(|e| c.io(e, "the frame header"))?;
                        if bare_header_fits(&look, Endian::Big)
                            && !bare_header_fits(&look, Endian::Little)
                        {
                            Endian::Big
                        } else {
                            Endian::Little
                        }
                    }
                };
                c.src.seek(start).map_err(|e| c.io(e, "the frame header"))?;
                false
            }
        };
        let at = c.src.pos;
        let step = c.i64("the timestep")?;
        if step < 0 {
            return Err(c.parse(
                at,
                "a timestep >= 0 (or a magic header: a negative length, then DUMPCUSTOM or DUMPATOM)",
                step.to_string(),
            ));
        }
        let at = c.src.pos;
        let natoms = c.i64("the atom count")?;
        let Ok(natoms) = u64::try_from(natoms) else {
            return Err(c.parse(at, "an atom count >= 0", natoms.to_string()));
        };
        let at = c.src.pos;
        let tri = c.i32("the triclinic flag")?;
        let kind = match tri {
            0 => BoxKind::Orthogonal,
            1 => BoxKind::Restricted,
            2 => BoxKind::General,
            _ => return Err(c.parse(at, "a triclinic flag of 0, 1 or 2", tri.to_string())),
        };
        let at = c.src.pos;
        let mut b = [0i32; 6];
        for v in &mut b {
            *v = c.i32("the boundary flags")?;
        }
        if b.iter().any(|v| !(0..=3).contains(v)) {
            return Err(c.parse(at, "boundary flags 0 to 3 (p, f, s, m)", format!("{b:?}")));
        }
        // An axis is periodic when both its sides are `p` (the text dump's `pp`).
        let periodic = [0, 1, 2].map(|k| b[2 * k] == 0 && b[2 * k + 1] == 0);
        let box_at = c.src.pos;
        let mut rows = [[0f64; 4]; 3];
        if kind == BoxKind::General {
            // avec, bvec, cvec (row k: edge k, as the text dump's `abc origin` lines), then
            // boxlo (each line's fourth value).
            for row in &mut rows {
                for v in &mut row[..3] {
                    *v = c.f64("the box")?;
                }
            }
            for row in &mut rows {
                row[3] = c.f64("the box")?;
            }
        } else {
            for row in &mut rows {
                row[0] = c.f64("the box")?;
                row[1] = c.f64("the box")?;
            }
            if kind == BoxKind::Restricted {
                for row in &mut rows {
                    row[2] = c.f64("the box")?;
                }
            }
        }
        if rows.as_flattened().iter().any(|v| !v.is_finite()) {
            return Err(c.parse(box_at, "a finite box", format!("{rows:?}")));
        }
        let size_at = c.src.pos;
        let size_one = c.i32("the values per atom (size_one)")?;
        if size_one < 1 {
            return Err(c.parse(
                size_at,
                "values per atom (size_one) >= 1",
                size_one.to_string(),
            ));
        }
        let size_one = size_one as usize;
        // Units, time and column names (revision 2).
        let (mut units, mut time, mut names) = (None, None, None);
        if named {
            let (u, _) = c.string("the unit style")?;
            if !u.is_empty() {
                units = Some(Units::from_name(&u));
            }
            let at = c.src.pos;
            let flag = c.bytes::<1>("the time flag")?[0];
            match flag {
                0 => {}
                1 => time = Some(c.f64("the time")?),
                _ => return Err(c.parse(at, "a time flag of 0 or 1", flag.to_string())),
            }
            let (n, at) = c.string("the column names")?;
            let count = crate::parse::fields(&n).count();
            if count != size_one {
                return Err(c.parse(
                    at,
                    "as many column names as values per atom (size_one)",
                    format!(
                        "{count} names for size_one {size_one}: {}",
                        Error::found(&n)
                    ),
                ));
            }
            names = Some((n, at));
        }
        let at = c.src.pos;
        let nchunk = c.i32("the chunk count")?;
        let Ok(nchunk) = usize::try_from(nchunk) else {
            return Err(c.parse(at, "a chunk count >= 0", nchunk.to_string()));
        };
        let endian = c.endian;
        if !named && self.bare.is_none() {
            self.bare = Some(endian);
        }
        Ok(Header {
            endian,
            step,
            natoms,
            periodic,
            kind,
            rows,
            box_at,
            size_one,
            size_at,
            units,
            time,
            names,
            nchunk,
            data: self.src.pos,
        })
    }

    /// The number of complete frames before the end of the file or the first damaged frame.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Plans the columns of frame `k` (header `h`): the file's names, the caller's, or `dump
    /// atom`'s default by `size_one`. Returns whether the default was assumed.
    fn plan(&mut self, k: usize, h: &Header) -> Result<bool, Error> {
        let parse = |at: u64, expected: &'static str, found: String| Error::Parse {
            at: Location::binary(&self.file, k, at),
            expected,
            found,
        };
        let (names, at, assumed): (&[u8], u64, bool) = match (&h.names, &self.columns) {
            (Some((n, at)), _) => (n, *at, false),
            (None, Some(c)) => (c.as_bytes(), h.size_at, false),
            (None, None) => match h.size_one {
                5 => (DUMP_ATOM_5, h.size_at, true),
                8 => (DUMP_ATOM_8, h.size_at, true),
                _ => {
                    return Err(parse(
                        h.size_at,
                        "a file that names its columns (a LAMMPS binary dump from an older LAMMPS does not): give them (texmap: --lammps-columns 'id type x y z ...'; the library: ReadOptions::lammps_columns)",
                        format!("size_one {} and no column names", h.size_one),
                    ));
                }
            },
        };
        let count = crate::parse::fields(names).count();
        if count != h.size_one {
            return Err(parse(
                at,
                "as many column names as values per atom (size_one)",
                format!(
                    "{count} names for size_one {}: {}",
                    h.size_one,
                    Error::found(names)
                ),
            ));
        }
        if self.planned != names || self.acts.is_empty() {
            self.planned.clear();
            let Some(kind) = plan_columns(names, &mut self.acts, &mut self.properties) else {
                self.acts.clear();
                return Err(parse(
                    at,
                    "position columns x y z, xs ys zs, xu yu zu or xsu ysu zsu",
                    Error::found(names),
                ));
            };
            // A binary dump's `element` column holds the type number: a property (once).
            for a in &mut self.acts {
                if *a == Act::Element {
                    *a = match self.properties.iter().position(|p| p == "element") {
                        Some(_) => Act::Skip,
                        None => {
                            self.properties.push("element".into());
                            Act::Property(self.properties.len() - 1)
                        }
                    };
                }
            }
            self.planned.extend_from_slice(names);
            self.pos_kind = kind;
        }
        Ok(assumed)
    }

    /// Reads frame `k` into `frame` (cleared), but for the cell, which is returned.
    fn read_frame(&mut self, k: usize, frame: &mut Frame) -> Result<Option<UnitCell>, Error> {
        let entry = self.frames[k];
        let h = self.header(k, entry.start)?;
        let assumed = self.plan(k, &h)?;
        let cell = cell_from_bounds(h.rows, h.kind).map(|c| c.with_periodic(h.periodic));
        if self.pos_kind == PosKind::Scaled && cell.is_none() {
            return Err(Error::Parse {
                at: Location::binary(&self.file, k, h.box_at),
                expected: "a box with volume > 0 for scaled coordinates",
                found: format!("{:?}", h.rows),
            });
        }
        frame.step = Some(h.step);
        frame.time = entry.units.time_ps(h.time);
        // Reserve no more atoms than the rest of the file holds.
        let room = self.src.left() / (8 * h.size_one as u64);
        let n = h.natoms.min(room) as usize;
        frame.positions.reserve(n);
        for name in &self.properties {
            frame.properties.push(Property {
                name: name.clone(),
                values: Vec::with_capacity(n),
            });
        }
        let mut decode = Decode {
            acts: &self.acts,
            scaled: if self.pos_kind == PosKind::Scaled {
                cell.as_ref()
            } else {
                None
            },
            assumed,
            vel_scale: entry.units.velocity_scale(),
            row: h.size_one * 8,
            file: &self.file,
            frame: k,
            xyz: std::mem::take(&mut self.xyz),
            type_labels: &mut self.type_labels,
        };
        let big = h.endian == Endian::Big;
        let mut sink = |rows: usize, b: &[u8], at: u64| {
            if big {
                decode.rows::<true>(rows, b, at, frame)
            } else {
                decode.rows::<false>(rows, b, at, frame)
            }
        };
        let read = chunks(
            &mut self.src,
            &self.file,
            &mut self.block,
            k,
            &h,
            Some(&mut sink),
        );
        self.xyz = decode.xyz;
        read?;
        if self.acts.contains(&Act::Id) {
            self.sort.sort(frame);
        }
        Ok(cell)
    }

    /// Reads the next frame into `frame` (the `Trajectory` contract). `Ok(false)` after the
    /// last frame; on error the frame is left empty and the reader stays at the damaged frame.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        let k = self.next;
        let tail = &self.tail;
        if let Some(r) = crate::cursor::past_complete(k, self.frames.len(), || {
            tail.as_ref().map(crate::xtc::clone_error)
        }) {
            return r;
        }
        let read = self.read_frame(k, frame);
        crate::cursor::settle(read, frame, &mut self.next)
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

    /// Number of frames (the index is built at open time). A damaged or cut frame after the
    /// good ones is that frame's error, not a shorter count: nothing is dropped silently.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        match &self.tail {
            Some(e) => Err(crate::xtc::clone_error(e)),
            None => Ok(self.frames.len()),
        }
    }
}

/// What takes a chunk's rows: `(rows, their bytes, the byte they start at)`.
type RowSink<'a> = dyn FnMut(usize, &[u8], u64) -> Result<(), Error> + 'a;

/// Walks frame `k`'s chunks from its first count (`h.data`): each holds whole atoms within what
/// the header's `natoms × size_one` leaves, and together exactly that. Without `sink` the data
/// is skipped; with it each chunk's rows go to `sink(rows, bytes, byte of the rows)` in blocks
/// of whole rows read into `block`.
fn chunks<R: Read + Seek>(
    src: &mut Src<R>,
    file: &Arc<str>,
    block: &mut Vec<u8>,
    k: usize,
    h: &Header,
    mut sink: Option<&mut RowSink>,
) -> Result<(), Error> {
    let mut c = Cur {
        src,
        file,
        frame: k,
        endian: h.endian,
    };
    let Some(total) = h
        .natoms
        .checked_mul(h.size_one as u64)
        .filter(|t| *t <= u64::MAX / 8)
    else {
        return Err(c.parse(
            h.data,
            "natoms x size_one values that a file can hold",
            format!("natoms {} x size_one {}", h.natoms, h.size_one),
        ));
    };
    let row = h.size_one * 8;
    let mut sum = 0u64;
    for _ in 0..h.nchunk {
        let at = c.src.pos;
        let n = c.i32("a chunk's value count")?;
        let left = total - sum;
        let Some(n) = u64::try_from(n)
            .ok()
            .filter(|n| *n <= left && *n % h.size_one as u64 == 0)
        else {
            return Err(c.parse(
                at,
                "a chunk of at most natoms x size_one values left, in whole atoms",
                format!(
                    "{n} values (natoms {} x size_one {}: {left} left)",
                    h.natoms, h.size_one
                ),
            ));
        };
        sum += n;
        let bytes = n * 8;
        if bytes > c.src.left() {
            return Err(c.cut(&format!("a chunk of {n} values, {bytes} bytes")));
        }
        match sink.as_deref_mut() {
            None => {
                let to = c.src.pos + bytes;
                c.src.seek(to).map_err(|e| c.io(e, "a chunk"))?;
            }
            Some(sink) => {
                // Whole rows at a time, at most BLOCK bytes (at least one row).
                let per = (BLOCK / row).max(1) * row;
                let mut rest = bytes as usize;
                while rest > 0 {
                    let take = rest.min(per);
                    block.resize(take, 0);
                    let at = c.src.pos;
                    c.src.read(block).map_err(|e| c.io(e, "a chunk"))?;
                    sink(take / row, block, at)?;
                    rest -= take;
                }
            }
        }
    }
    if sum != total {
        return Err(c.parse(
            c.src.pos,
            "chunks holding natoms x size_one values in all",
            format!(
                "{sum} values in {} chunks; natoms {} x size_one {} = {total}",
                h.nchunk, h.natoms, h.size_one
            ),
        ));
    }
    Ok(())
}

/// One frame's column plan applied to blocks of rows: each column is one pass over the block
/// (the action chosen outside the loop over atoms).
struct Decode<'a> {
    acts: &'a [Act],
    /// The cell scaled positions are relative to (`None`: Cartesian positions).
    scaled: Option<&'a UnitCell>,
    /// The columns are `dump atom`'s default, assumed: scaled values are checked to be.
    assumed: bool,
    vel_scale: f32,
    /// Bytes per atom.
    row: usize,
    file: &'a Arc<str>,
    frame: usize,
    xyz: Vec<[f64; 3]>,
    /// The labels of the types met, by type number (below [`TYPE_LABELS`]).
    type_labels: &'a mut Vec<Option<Label>>,
}

/// The double at byte `o` of `b`, in the file's byte order.
#[inline(always)]
fn value<const BIG: bool>(b: &[u8], o: usize) -> f64 {
    // One bounds check and one 8-byte load (an array built byte by byte is not one).
    let a: [u8; 8] = b[o..o + 8].try_into().expect("8 bytes");
    f64::from_bits(if BIG {
        u64::from_be_bytes(a)
    } else {
        u64::from_le_bytes(a)
    })
}

/// `x` as an integer when it is one of magnitude below `limit` (at most 2^63): ids and types
/// are integers written as doubles.
#[inline(always)]
fn whole(x: f64, limit: f64) -> Option<i64> {
    // NaN fails the comparison; `as` truncates, and the round trip tells a fraction.
    (x.abs() < limit && (x as i64) as f64 == x).then_some(x as i64)
}

/// The label of an integer of at most 14 digits, as the text dump prints it; no allocation.
fn int_label(v: i64) -> Label {
    let mut buf = [0u8; 16];
    let mut i = buf.len();
    let mut u = v.unsigned_abs();
    loop {
        i -= 1;
        buf[i] = b'0' + (u % 10) as u8;
        u /= 10;
        if u == 0 {
            break;
        }
    }
    if v < 0 {
        i -= 1;
        buf[i] = b'-';
    }
    Label::from_utf8(&buf[i..]).expect("at most 15 bytes")
}

impl Decode<'_> {
    fn bad(&self, at: u64, expected: &'static str, found: String) -> Error {
        Error::Parse {
            at: Location::binary(self.file, self.frame, at),
            expected,
            found,
        }
    }

    /// Appends `rows` atoms of block `b` (which starts at byte `at`) to `f`.
    fn rows<const BIG: bool>(
        &mut self,
        rows: usize,
        b: &[u8],
        at: u64,
        f: &mut Frame,
    ) -> Result<(), Error> {
        let row = self.row;
        let base = f.positions.len();
        let byte = |r: usize, c: usize| at + (r * row + c * 8) as u64;
        self.xyz.clear();
        self.xyz.resize(rows, [0.0; 3]);
        let has_vel = self.acts.iter().any(|a| matches!(a, Act::Vel(_)));
        let has_color = self.acts.iter().any(|a| matches!(a, Act::Color(_)));
        if has_vel {
            f.velocities.resize(base + rows, [0.0; 3]);
        }
        if has_color {
            f.colors.resize(base + rows, [0.0; 3]);
        }
        for (c, &act) in self.acts.iter().enumerate() {
            let v = |r: usize| value::<BIG>(b, r * row + c * 8);
            match act {
                Act::Pos(k) => {
                    for (r, p) in self.xyz.iter_mut().enumerate() {
                        p[k] = v(r);
                    }
                }
                Act::Vel(k) => {
                    let scale = self.vel_scale;
                    for (r, o) in f.velocities[base..].iter_mut().enumerate() {
                        o[k] = v(r) as f32 * scale;
                    }
                }
                Act::Color(k) => {
                    for (r, o) in f.colors[base..].iter_mut().enumerate() {
                        o[k] = v(r) as f32;
                    }
                }
                Act::Id => {
                    for r in 0..rows {
                        let x = v(r);
                        let Some(id) = whole(x, 9.2e18) else {
                            return Err(self.bad(byte(r, c), "an integer atom id", x.to_string()));
                        };
                        f.ids.push(id);
                    }
                }
                Act::Type => {
                    for r in 0..rows {
                        let x = v(r);
                        let Some(t) = whole(x, 1e14) else {
                            return Err(self.bad(
                                byte(r, c),
                                "an integer atom type",
                                x.to_string(),
                            ));
                        };
                        let label = match usize::try_from(t) {
                            Ok(k) if k < TYPE_LABELS => {
                                if self.type_labels.len() <= k {
                                    self.type_labels.resize(k + 1, None);
                                }
                                *self.type_labels[k].get_or_insert_with(|| int_label(t))
                            }
                            _ => int_label(t),
                        };
                        f.types.push(label);
                    }
                }
                Act::Radius | Act::Diameter => {
                    let half = if act == Act::Diameter { 0.5 } else { 1.0 };
                    for r in 0..rows {
                        let x = v(r) as f32;
                        if !(x >= 0.0 && x.is_finite()) {
                            return Err(self.bad(byte(r, c), "a radius >= 0", x.to_string()));
                        }
                        f.radii.push(x * half);
                    }
                }
                Act::Property(k) => {
                    f.properties[k]
                        .values
                        .extend((0..rows).map(|r| v(r) as f32));
                }
                Act::Element | Act::Skip => {}
            }
        }
        // Velocities and colours: finite.
        for (vals, what) in [
            (&f.velocities, "finite velocities"),
            (&f.colors, "finite colour components"),
        ] {
            if let Some(r) = vals
                .get(base..)
                .and_then(|v| v.iter().position(|x| !x.iter().all(|c| c.is_finite())))
            {
                return Err(self.bad(
                    byte(r, 0),
                    what,
                    format!("atom {}: {:?}", base + r, vals[base + r]),
                ));
            }
        }
        // Positions: scaled ones to Cartesian with the frame's box (f64), then to f32.
        match self.scaled {
            Some(cell) => {
                if self.assumed
                    && let Some(r) = self
                        .xyz
                        .iter()
                        .position(|s| !s.iter().all(|x| (x - 0.5).abs() <= SCALED_SLACK))
                {
                    return Err(self.bad(
                        byte(r, 2),
                        "scaled coordinates xs ys zs in [-0.5, 1.5]: the file names no columns, and dump atom's default (id type xs ys zs) was assumed; give the columns (texmap: --lammps-columns 'id type x y z'; the library: ReadOptions::lammps_columns)",
                        format!("atom {}: {:?}", base + r, self.xyz[r]),
                    ));
                }
                f.positions.extend(self.xyz.iter().map(|s| {
                    let p = cell.to_cartesian(*s);
                    [p[0] as f32, p[1] as f32, p[2] as f32]
                }));
            }
            None => f.positions.extend(
                self.xyz
                    .iter()
                    .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]),
            ),
        }
        if let Some(r) = first_out_of_bounds(&f.positions[base..]) {
            return Err(self.bad(
                byte(r, 0),
                IN_BOUNDS,
                format!("atom {}: {:?}", base + r, f.positions[base + r]),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Format, ReadOptions, Trajectory};
    use std::io::Cursor;

    /// One frame laid out byte by byte: the magic header and revision-2 fields when `names`
    /// is given, else the older layout.
    struct Spec<'a> {
        big: bool,
        names: Option<&'a str>,
        units: &'a str,
        time: Option<f64>,
        step: i64,
        natoms: i64,
        triclinic: i32,
        boundary: [i32; 6],
        /// 6, 9 or 12 values, as the triclinic flag asks.
        bounds: &'a [f64],
        size_one: i32,
        chunks: &'a [&'a [f64]],
    }

    fn frame(s: &Spec) -> Vec<u8> {
        let mut b = Vec::new();
        let big = s.big;
        let i32b = |b: &mut Vec<u8>, v: i32| {
            b.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let i64b = |b: &mut Vec<u8>, v: i64| {
            b.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let f64b = |b: &mut Vec<u8>, v: f64| {
            b.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        if s.names.is_some() {
            i64b(&mut b, -10);
            b.extend(b"DUMPCUSTOM");
            i32b(&mut b, 1);
            i32b(&mut b, 2);
        }
        i64b(&mut b, s.step);
        i64b(&mut b, s.natoms);
        i32b(&mut b, s.triclinic);
        for v in s.boundary {
            i32b(&mut b, v);
        }
        for &v in s.bounds {
            f64b(&mut b, v);
        }
        i32b(&mut b, s.size_one);
        if let Some(names) = s.names {
            i32b(&mut b, s.units.len() as i32);
            b.extend(s.units.as_bytes());
            b.push(s.time.is_some() as u8);
            if let Some(t) = s.time {
                f64b(&mut b, t);
            }
            i32b(&mut b, names.len() as i32);
            b.extend(names.as_bytes());
        }
        i32b(&mut b, s.chunks.len() as i32);
        for c in s.chunks {
            i32b(&mut b, c.len() as i32);
            for &v in *c {
                f64b(&mut b, v);
            }
        }
        b
    }

    fn spec<'a>(names: Option<&'a str>, chunks: &'a [&'a [f64]]) -> Spec<'a> {
        Spec {
            big: false,
            names,
            units: "metal",
            time: Some(0.5),
            step: 100,
            natoms: chunks.iter().map(|c| c.len() as i64).sum::<i64>() / 5,
            triclinic: 0,
            boundary: [0, 0, 1, 1, 2, 2],
            bounds: &[0.0, 10.0, -1.0, 9.0, 0.0, 12.0],
            size_one: 5,
            chunks,
        }
    }

    fn read(bytes: Vec<u8>, options: ReadOptions) -> Result<Vec<Frame>, Error> {
        let mut t =
            Trajectory::from_reader_with(Cursor::new(bytes), Format::LammpsBin, "t.bin", options)?;
        let mut out = Vec::new();
        let mut f = Frame::new();
        while t.read_next(&mut f)? {
            out.push(f.clone());
        }
        Ok(out)
    }

    fn text(dump: &str) -> Vec<Frame> {
        let mut t = Trajectory::from_reader(Cursor::new(dump.to_string()), Format::LammpsDump, "t")
            .unwrap();
        let mut out = Vec::new();
        let mut f = Frame::new();
        while t.read_next(&mut f).unwrap() {
            out.push(f.clone());
        }
        out
    }

    const ATOMS: [&[f64]; 2] = [
        &[2.0, 1.0, 1.5, 2.5, 3.5, 1.0, 2.0, 0.25, 0.5, 0.75],
        &[3.0, 1.0, 4.0, 5.0, 6.0],
    ];

    #[test]
    fn sniffs_the_magic_header_and_older_headers_in_either_byte_order() {
        for big in [false, true] {
            for names in [Some("id type x y z"), None] {
                let s = Spec {
                    big,
                    ..spec(names, &ATOMS)
                };
                let b = frame(&s);
                assert!(sniff(&b), "big {big}, names {names:?}");
                assert_eq!(Format::from_magic(&b), Some(Format::LammpsBin));
            }
        }
        assert!(!sniff(b"ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n"));
        assert!(!sniff(&[0u8; 7]));
        // An older header whose values do not fit (a triclinic flag of 7).
        let mut b = frame(&spec(None, &ATOMS));
        b[16] = 7;
        assert!(!sniff(&b));
    }

    #[test]
    fn text_and_binary_of_the_same_frame_agree() {
        // Scaled columns in an orthogonal box with p f s boundaries, chunks out of id order.
        let names = "id type xs ys zs";
        let bin = read(frame(&spec(Some(names), &ATOMS)), ReadOptions::new()).unwrap();
        let dump = "ITEM: UNITS\nmetal\nITEM: TIME\n0.5\nITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n3\n\
                    ITEM: BOX BOUNDS pp ff ss\n0 10\n-1 9\n0 12\nITEM: ATOMS id type xs ys zs\n\
                    2 1 1.5 2.5 3.5\n1 2 0.25 0.5 0.75\n3 1 4 5 6\n";
        assert_eq!(bin, text(dump));
        assert_eq!(bin[0].ids, [1, 2, 3]);
        assert_eq!(bin[0].cell.unwrap().periodic(), [true, false, false]);
        // General triclinic (LAMMPS 2024+): edge vectors and origin.
        let general = [
            1.0, 2.0, 3.0, 0.5, 4.0, 0.0, 0.2, 0.3, 5.0, -1.0, -2.0, -3.0,
        ];
        let s = Spec {
            triclinic: 2,
            bounds: &general,
            boundary: [0; 6],
            ..spec(Some("id type x y z"), &ATOMS)
        };
        let bin = read(frame(&s), ReadOptions::new()).unwrap();
        let dump = "ITEM: UNITS\nmetal\nITEM: TIME\n0.5\nITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n3\n\
                    ITEM: BOX BOUNDS abc origin pp pp pp\n1 2 3 -1\n0.5 4 0 -2\n0.2 0.3 5 -3\n\
                    ITEM: ATOMS id type x y z\n2 1 1.5 2.5 3.5\n1 2 0.25 0.5 0.75\n3 1 4 5 6\n";
        assert_eq!(bin, text(dump));
        // Restricted triclinic, big-endian, real units: Å/fs velocities become Å/ps.
        let tri = [0.0, 11.0, -1.0, 9.5, 0.0, 12.0, 1.0, 0.0, 0.5];
        let atoms: [&[f64]; 1] = [&[7.0, 3.0, 1.0, 2.0, 3.0, 0.01, -0.02, 0.03, -4.5]];
        let s = Spec {
            big: true,
            units: "real",
            triclinic: 1,
            bounds: &tri,
            size_one: 9,
            natoms: 1,
            ..spec(Some("id type x y z vx vy vz element"), &atoms)
        };
        let bin = read(frame(&s), ReadOptions::new()).unwrap();
        let dump = "ITEM: UNITS\nreal\nITEM: TIME\n0.5\nITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n1\n\
                    ITEM: BOX BOUNDS xy xz yz pp ff ss\n0 11 1\n-1 9.5 0\n0 12 0.5\n\
                    ITEM: ATOMS id type x y z vx vy vz c_element\n7 3 1 2 3 0.01 -0.02 0.03 -4.5\n";
        let mut want = text(dump);
        // A binary dump's element column holds the type number: the property "element".
        want[0].properties[0].name = "element".into();
        assert_eq!(bin, want);
        assert_eq!(bin[0].time, Some(0.5e-3));
        assert_eq!(bin[0].velocities[0], [10.0, -20.0, 30.0]);
    }

    #[test]
    fn hostile_headers_are_refused_before_anything_is_sized_from_them() {
        let good = frame(&spec(Some("id type x y z"), &ATOMS));
        // (byte, value) of the header's natoms, size_one, the unit string's length, the column
        // names' length and nchunk: each set to extremes over a file of ~200 bytes.
        let natoms = 8 + 10 + 8 + 8;
        let size_one = natoms + 8 + 4 + 24 + 48;
        let units = size_one + 4;
        let columns = units + 4 + 5 + 1 + 8;
        let nchunk = columns + 4 + 13;
        for (at, wide) in [
            (natoms, true),
            (size_one, false),
            (units, false),
            (columns, false),
            (nchunk, false),
        ] {
            for v in [i64::MAX, i64::from(i32::MAX), -1, 1 << 40] {
                let mut b = good.clone();
                if wide {
                    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
                } else {
                    b[at..at + 4].copy_from_slice(&(v as i32).to_le_bytes());
                }
                let e = read(b, ReadOptions::new()).unwrap_err();
                let loc = e.location().unwrap_or_else(|| panic!("{e}"));
                assert_eq!((loc.frame, &*loc.file), (Some(0), "t.bin"), "{e}");
                assert!(loc.byte.is_some(), "{e}");
            }
        }
        // A chunk that would overrun natoms x size_one: named with the numbers.
        let mut b = good.clone();
        let chunk0 = nchunk + 4;
        b[chunk0..chunk0 + 4].copy_from_slice(&20i32.to_le_bytes());
        let e = read(b, ReadOptions::new()).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "t.bin: frame 0, byte {chunk0}: expected a chunk of at most natoms x size_one values left, in whole atoms, found '20 values (natoms 3 x size_one 5: 15 left)'"
            )
        );
    }

    #[test]
    fn every_cut_keeps_the_frames_before_it() {
        let names = Some("id type x y z");
        let mut bytes = Vec::new();
        let mut ends = vec![0];
        for step in 0..3 {
            let s = Spec {
                step,
                ..spec(names, &ATOMS)
            };
            bytes.extend(frame(&s));
            ends.push(bytes.len());
        }
        for cut in 0..bytes.len() {
            let complete = ends.iter().filter(|&&e| e > 0 && e <= cut).count();
            let lenient = ReadOptions::new().allow_truncated(true);
            match LammpsBinReader::new(Cursor::new(bytes[..cut].to_vec()), "t.bin".into(), None) {
                Ok(mut r) => {
                    assert_eq!(r.frame_count(), complete, "cut at {cut}");
                    if !ends.contains(&cut) {
                        let e = r.n_frames().unwrap_err();
                        let at = e.location().unwrap();
                        assert_eq!(
                            (at.frame, at.byte),
                            (Some(complete), Some(cut as u64)),
                            "{e}"
                        );
                        assert!(matches!(e, Error::Truncated { .. }), "{e}");
                    }
                    let kept = read(bytes[..cut].to_vec(), lenient).unwrap();
                    assert_eq!(kept.len(), complete, "cut at {cut}");
                }
                Err(e) => {
                    assert_eq!(complete, 0, "{e}");
                    assert_eq!(e.location().unwrap().byte, Some(cut as u64), "{e}");
                }
            }
        }
    }

    #[test]
    fn integer_labels() {
        for v in [0, 7, -3, 12345678901234, -99999999999999] {
            assert_eq!(int_label(v).as_str(), v.to_string());
        }
    }
}
