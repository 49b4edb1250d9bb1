//! HOOMD-blue GSD trajectories (`.gsd`): our own reader of the GSD file layer (file format
//! versions 1.0 and 2.x: what gsd 1.x to 5.x and HOOMD-blue write) and of the `hoomd` schema
//! inside it.
//!
//! # The file layer (GSD documentation, "File layer")
//! Little-endian, as every writer's machine stores it. A 256-byte header: the magic number
//! `0x65DF65DF65DF65DF`, the index's location and allocated entries, the namelist's location
//! and allocated 64-byte segments, the schema version, the file format version
//! (`0xaaaabbbb` is `aaaa.bbbb`), the application and schema names (64 bytes each, NUL-padded).
//! The **index** is an array of 32-byte entries, one per data chunk: frame (u64), rows N (u64),
//! location (i64), columns M (u32), name id (u16), type (u8: uint8, uint16, uint32, uint64,
//! int8, int16, int32, int64, float, double, char = 1..11), flags (u8). An entry at location 0
//! is an unused slot. Entries come in frame order (2.x: sorted by frame, then name id); the
//! frame count is the last entry's frame + 1, so a frame may have no chunk at all. The
//! **namelist** holds the chunk names: in 2.x NUL-terminated strings one after the other, in 1.0
//! one per 64-byte segment; an empty name ends the list, and the block's last byte is NUL. A
//! chunk's data is its N × M values (M the fast index) at its location.
//!
//! # The hoomd schema (GSD documentation, "HOOMD Schema")
//! A chunk present in frame *i* gives that frame's values. A chunk missing from frame *i* takes
//! frame 0's chunk of the same name (for per-particle and per-bond chunks only when frame 0 has
//! as many particles or bonds), else the schema's default: what `gsd.hoomd` does, and what
//! writers rely on, since they write types, bonds, diameters... in frame 0 only. Read here:
//!
//! | chunk | into | default |
//! |---|---|---|
//! | `configuration/step` | [`Frame::step`] | 0 |
//! | `configuration/dimensions` | checked (2 or 3) | 3 |
//! | `configuration/box` `Lx Ly Lz xy xz yz` | [`Frame::cell`] (below) | 1 1 1 0 0 0 |
//! | `particles/N` | the particle count | 0 |
//! | `particles/types`, `particles/typeid` | [`Frame::types`] and [`Frame::names`]: the type name; [`Frame::elements`] when some type name is an element symbol written as one (`Na`, not `A` or `Colloid`) | `A`, 0 |
//! | `particles/position` | [`Frame::positions`], as written | 0 0 0 |
//! | `particles/diameter` | [`Frame::radii`], halved | 1 |
//! | `particles/velocity` | [`Frame::velocities`] | 0 0 0 |
//! | `particles/mass`, `particles/charge`, `particles/body` | properties `mass`, `charge`, `body` | 1, 0, −1 |
//! | `particles/orientation` (r, a<sub>x</sub>, a<sub>y</sub>, a<sub>z</sub>) | properties `quatw quati quatj quatk` | 1 0 0 0 |
//! | `particles/image` | properties `ix iy iz` | 0 0 0 |
//! | `bonds/N`, `bonds/group` | [`Frame::bonds`] (pairs ordered, sorted, each once) | 0, 0 0 |
//! | `particles/type_shapes` (JSON per type) | properties `shapex shapey shapez` when some type is an `Ellipsoid`: its diameters `2a 2b 2c`, 0 0 0 for other types (LAMMPS's shape columns, for ellipsoids) | none |
//!
//! Elements follow the LAMMPS data reader's rule for type labels, so HOOMD's customary type
//! `B` is boron (drawn in boron's colour unless styled by type) while `A` has no element.
//!
//! A property (and the velocities) is in every frame when some frame of the file has its chunk
//! (its values in the other frames by the rule above), and in none otherwise: a file without
//! orientations gets no column of unit quaternions. The property names are those the LAMMPS
//! readers give the same quantities (`charge`, `ix`; a dump's `quatw …`), so colour by property
//! and the ellipsoids reach them alike. Type, angle, dihedral, improper, constraint, pair and `log/` chunks,
//! shapes other than ellipsoids (polyhedra, spheropolygons), `moment_inertia` and `angmom`
//! are not read.
//!
//! **The cell.** HOOMD's box is centred on the origin, with tilt factors: edges
//! a1 = (Lx, 0, 0), a2 = (xy·Ly, Ly, 0), a3 = (xz·Lz, yz·Lz, Lz), corner −(a1 + a2 + a3)/2. A
//! 2-D box has Lz = 0 (`gsd.hoomd` then writes `dimensions` 2), which no cell of volume > 0
//! has: it gets a3 = (0, 0, 1), a slab one length unit thick around the particles' z = 0
//! (LAMMPS's 2-D boxes are −0.5 ≤ z < 0.5 too), open along z ([`UnitCell::periodic`]: no atom
//! has an image across the slab, so neighbour searches stay in the plane, and our GSD writer
//! writes the box back as 2-D), and z stays as written. The slab is made for
//! Lz = 0 whatever `dimensions` says: gsd.hoomd reads such a box without complaint, and
//! refusing a file over that inconsistency would help no one.
//!
//! **Units.** HOOMD has no fixed units (reduced units, or whatever the user chose): positions
//! and box lengths are read as Å unchanged, so a box of 10 σ is drawn as 10 Å, with diameters
//! of 1 σ as radii of 0.5 Å; velocities likewise as Å/ps unchanged (length per time unit, as a
//! LAMMPS dump in `lj` units is read), so `--arrows velocity` and colour by speed work.
//!
//! # Why our own reader
//! No Rust crate reads GSD, and binding the reference C library (gsd.c) would add a C build
//! for a file layer of three small structures. The schema's default rule needs only frame 0
//! beside the frame read, so this module keeps the index entries of the chunks it reads and
//! reads a frame's chunks at their locations: random access costs one seek per chunk, memory is
//! one frame. Frame 0's chunks that a frame inherits (types, diameters, bonds) are read again
//! for each frame rather than cached: a second copy of the largest chunks for a few more reads.
//!
//! # Trust
//! The header's index and namelist blocks must lie inside the file before either is read or
//! sized; every index entry's type, name id and frame are checked (frames in order and below
//! the index's allocated entries, as gsd.c checks them), its N × M × size must not overflow, and
//! its data must lie inside the file. A chunk whose data runs past the end is a cut file: its
//! frame is [`Error::Truncated`] (every earlier frame readable), unless a later frame's chunk
//! lies inside the file, which no cut gives: damage, refused at open. A particle count N is
//! refused when N positions (12 bytes each) could not fit in the file, a bond count when its
//! pairs (8 bytes) could not: nothing is sized from a count the file's bytes do not back. A
//! chunk of the wrong type class (a float where integers belong) or shape (M ≠ 3 for
//! positions, N ≠ `particles/N`) is an [`Error::Parse`] naming the file, the frame read, the
//! chunk and the byte of its index entry; a bad value (a non-finite coordinate, a typeid past the
//! types, a bond to a missing particle) names the byte of the value.
//!
//! # Example
//! ```
//! use texmap_md_io::{Format, Frame, Trajectory};
//! # fn gsd_file() -> Vec<u8> {
//! #     let mut b = vec![0u8; 256];
//! #     let entry = |frame: u64, rows: u64, loc: u64, cols: u32, id: u16, ty: u8| {
//! #         let mut e = Vec::new();
//! #         e.extend(frame.to_le_bytes());
//! #         e.extend(rows.to_le_bytes());
//! #         e.extend(loc.to_le_bytes());
//! #         e.extend(cols.to_le_bytes());
//! #         e.extend(id.to_le_bytes());
//! #         e.extend([ty, 0]);
//! #         e
//! #     };
//! #     let names = b"particles/N\0particles/position\0\0\0";
//! #     let (index, namelist, data) = (256u64, 256 + 2 * 32, 256 + 2 * 32 + 64);
//! #     b[..8].copy_from_slice(&0x65DF_65DF_65DF_65DFu64.to_le_bytes());
//! #     for (k, v) in [index, 2, namelist, 1].into_iter().enumerate() {
//! #         b[8 + 8 * k..16 + 8 * k].copy_from_slice(&v.to_le_bytes());
//! #     }
//! #     b[40..44].copy_from_slice(&(1u32 << 16).to_le_bytes());
//! #     b[44..48].copy_from_slice(&(2u32 << 16).to_le_bytes());
//! #     b[112..117].copy_from_slice(b"hoomd");
//! #     b.extend(entry(0, 1, data, 1, 0, 3));
//! #     b.extend(entry(0, 2, data + 4, 3, 1, 9));
//! #     b.extend(names);
//! #     b.resize(namelist as usize + 64, 0);
//! #     b.extend(2u32.to_le_bytes());
//! #     for x in [-0.25f32, 0.0, 0.0, 0.25, 0.0, 0.0] {
//! #         b.extend(x.to_le_bytes());
//! #     }
//! #     b
//! # }
//! // Two particles in HOOMD's default box (1 × 1 × 1, centred on the origin).
//! let bytes = gsd_file();
//! let mut traj = Trajectory::from_reader(std::io::Cursor::new(bytes), Format::Gsd, "two.gsd")?;
//! let mut frame = Frame::new();
//! assert!(traj.read_next(&mut frame)?);
//! assert_eq!(frame.positions, [[-0.25, 0.0, 0.0], [0.25, 0.0, 0.0]]);
//! assert_eq!(frame.types[0], "A"); // the schema's default type
//! assert_eq!(frame.radii, [0.5, 0.5]); // and diameter
//! assert_eq!(frame.cell.unwrap().origin(), [-0.5, -0.5, -0.5]);
//! # Ok::<(), texmap_md_io::Error>(())
//! ```
//!
//! # References
//! - GSD documentation (gsd.readthedocs.io), "File layer" (header, index, namelist, data
//!   chunks, versions 1.0 and 2.x) and "HOOMD Schema" (chunk names, types, shapes, defaults,
//!   the box), as of gsd 3.4 / 5.0; gsd.c for the checks a reader makes on open.

use std::io::{self, Read, Seek, SeekFrom};
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, all_in_bounds, first_out_of_bounds};
use crate::elements::{Element, element_of_symbol};
use crate::error::{Error, Location};
use crate::frame::{Frame, Label, MAX_COORDINATE, Property, UnitCell};

/// The first 8 bytes of every GSD file (little-endian u64).
pub(crate) const MAGIC: u64 = 0x65DF_65DF_65DF_65DF;
/// The header's size.
const HEADER: u64 = 256;
/// One index entry's size.
const ENTRY: u64 = 32;
/// The namelist is allocated in segments of this many bytes (1.0: one name per segment).
const NAME_SEGMENT: u64 = 64;
/// Bytes of one particle's position (float32 × 3) and of one bond (uint32 × 2): what a count
/// must be backed by in the file.
const POSITION_BYTES: u64 = 12;
const BOND_BYTES: u64 = 8;

/// The GSD data types (`gsd_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Type {
    U8,
    U16,
    U32,
    U64,
    I8,
    I16,
    I32,
    I64,
    F32,
    F64,
    Char,
}

impl Type {
    fn from_code(c: u8) -> Option<Type> {
        use Type::*;
        Some(match c {
            1 => U8,
            2 => U16,
            3 => U32,
            4 => U64,
            5 => I8,
            6 => I16,
            7 => I32,
            8 => I64,
            9 => F32,
            10 => F64,
            11 => Char,
            _ => return None,
        })
    }

    fn size(self) -> u64 {
        use Type::*;
        match self {
            U8 | I8 | Char => 1,
            U16 | I16 => 2,
            U32 | I32 | F32 => 4,
            U64 | I64 | F64 => 8,
        }
    }

    fn name(self) -> &'static str {
        use Type::*;
        match self {
            U8 => "uint8",
            U16 => "uint16",
            U32 => "uint32",
            U64 => "uint64",
            I8 => "int8",
            I16 => "int16",
            I32 => "int32",
            I64 => "int64",
            F32 => "float",
            F64 => "double",
            Char => "char",
        }
    }

    /// True when values of this type are what `class` asks for.
    fn is(self, class: Class) -> bool {
        match class {
            Class::Int => !matches!(self, Type::F32 | Type::F64 | Type::Char),
            Class::Real => matches!(self, Type::F32 | Type::F64),
            Class::Text => matches!(self, Type::I8 | Type::U8 | Type::Char),
        }
    }
}

/// What a chunk's values must be: integers of any width, float or double, or bytes of text
/// (the schema's `int8` type names, or `char`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    Int,
    Real,
    Text,
}

/// The chunks this reader reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Chunk {
    Step,
    Dimensions,
    Box,
    ParticlesN,
    Types,
    TypeId,
    Position,
    Velocity,
    Diameter,
    Mass,
    Charge,
    Orientation,
    Image,
    Body,
    BondsN,
    BondsGroup,
    TypeShapes,
}

impl Chunk {
    const ALL: [Chunk; 17] = [
        Chunk::Step,
        Chunk::Dimensions,
        Chunk::Box,
        Chunk::ParticlesN,
        Chunk::Types,
        Chunk::TypeId,
        Chunk::Position,
        Chunk::Velocity,
        Chunk::Diameter,
        Chunk::Mass,
        Chunk::Charge,
        Chunk::Orientation,
        Chunk::Image,
        Chunk::Body,
        Chunk::BondsN,
        Chunk::BondsGroup,
        Chunk::TypeShapes,
    ];

    fn name(self) -> &'static str {
        match self {
            Chunk::Step => "configuration/step",
            Chunk::Dimensions => "configuration/dimensions",
            Chunk::Box => "configuration/box",
            Chunk::ParticlesN => "particles/N",
            Chunk::Types => "particles/types",
            Chunk::TypeId => "particles/typeid",
            Chunk::Position => "particles/position",
            Chunk::Velocity => "particles/velocity",
            Chunk::Diameter => "particles/diameter",
            Chunk::Mass => "particles/mass",
            Chunk::Charge => "particles/charge",
            Chunk::Orientation => "particles/orientation",
            Chunk::Image => "particles/image",
            Chunk::Body => "particles/body",
            Chunk::BondsN => "bonds/N",
            Chunk::BondsGroup => "bonds/group",
            Chunk::TypeShapes => "particles/type_shapes",
        }
    }
}

/// One index entry of a chunk this reader reads.
#[derive(Clone, Copy, Debug)]
struct Entry {
    frame: usize,
    rows: u64,
    cols: u32,
    location: u64,
    ty: Type,
    chunk: Chunk,
    /// Byte offset of the index entry itself (where a wrong shape or type is reported).
    at: u64,
}

impl Entry {
    /// Bytes of data (checked at open: no overflow, inside the file).
    fn bytes(&self) -> u64 {
        self.rows * self.cols as u64 * self.ty.size()
    }
}

/// The first chunk whose data runs past the end of the file.
#[derive(Clone, Debug)]
struct Cut {
    frame: usize,
    name: String,
    location: u64,
    bytes: u64,
}

/// Streaming reader of a HOOMD-blue GSD file (the `Trajectory` contract in lib.rs).
pub(crate) struct GsdReader<R> {
    src: R,
    file: Arc<str>,
    file_len: u64,
    /// The index entries of the chunks read here, in frame order.
    entries: Vec<Entry>,
    /// Frames whose every chunk lies inside the file.
    complete: usize,
    cut: Option<Cut>,
    /// Which of [`Chunk::ALL`] some frame of the file has.
    in_file: [bool; Chunk::ALL.len()],
    next: usize,
    buf: Vec<u8>,
    reals: Vec<f32>,
    ints: Vec<i64>,
    type_names: Vec<Label>,
}

/// The header fields this reader uses.
struct Header {
    index_location: u64,
    index_entries: u64,
    names_location: u64,
    names_segments: u64,
    /// File format 1.0 (names in 64-byte segments) rather than 2.x.
    v1: bool,
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap_or([0; 8]))
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap_or([0; 4]))
}

/// A NUL-padded string field: the bytes before the first NUL.
fn until_nul(b: &[u8]) -> &[u8] {
    &b[..b.iter().position(|c| *c == 0).unwrap_or(b.len())]
}

/// The semi-axes of a HOOMD shape description that is an ellipsoid
/// (`{"type": "Ellipsoid", "a": 1.0, "b": 0.5, "c": 0.5}`, keys in any order), or `None` for
/// another shape or a description that is not one: the three finite values > 0 of `a`, `b`,
/// `c` in a JSON object whose `type` is `Ellipsoid`.
fn ellipsoid_axes(json: &[u8]) -> Option<[f32; 3]> {
    let text = std::str::from_utf8(json).ok()?;
    // The value after `"key"` and its colon: a string's contents or a number's text.
    let value = |key: &str| -> Option<&str> {
        let quoted = format!("\"{key}\"");
        let at = text.find(&quoted)? + quoted.len();
        let rest = text[at..].trim_start().strip_prefix(':')?.trim_start();
        match rest.strip_prefix('"') {
            Some(s) => s.split('"').next(),
            None => rest.split([',', '}', ' ']).next(),
        }
    };
    if value("type")? != "Ellipsoid" {
        return None;
    }
    let axis = |k: &str| {
        value(k)?
            .trim()
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
    };
    Some([axis("a")?, axis("b")?, axis("c")?])
}

fn version(v: u32) -> String {
    format!("{}.{}", v >> 16, v & 0xFFFF)
}

impl<R: Read + Seek> GsdReader<R> {
    /// Reads and checks the header, the namelist and the index.
    pub fn new(mut src: R, file: Arc<str>) -> Result<Self, Error> {
        let at = |byte: u64| Location {
            byte: Some(byte),
            ..Location::file(&file)
        };
        let io = |byte: u64| {
            let at = at(byte);
            move |source: io::Error| Error::Io { at, source }
        };
        let file_len = src.seek(SeekFrom::End(0)).map_err(io(0))?;
        src.seek(SeekFrom::Start(0)).map_err(io(0))?;
        let mut head = Vec::with_capacity(HEADER as usize);
        (&mut src)
            .take(HEADER)
            .read_to_end(&mut head)
            .map_err(io(0))?;
        let header = read_header(&head, file_len, &at)?;
        // The namelist: its block inside the file, ending in NUL.
        let names_bytes = header.names_segments * NAME_SEGMENT;
        src.seek(SeekFrom::Start(header.names_location))
            .map_err(io(header.names_location))?;
        let mut block = vec![0u8; names_bytes as usize];
        src.read_exact(&mut block)
            .map_err(io(header.names_location))?;
        if block.last().is_some_and(|b| *b != 0) {
            return Err(Error::Parse {
                at: at(header.names_location + names_bytes - 1),
                expected: "a namelist block ending in a NUL byte",
                found: Error::found(&block[block.len().saturating_sub(24)..]),
            });
        }
        let names = names(&block, header.v1);
        let index = read_index(&mut src, &header, file_len, &names, &at)?;
        Ok(GsdReader {
            src,
            file,
            file_len,
            entries: index.entries,
            complete: index.complete,
            cut: index.cut,
            in_file: index.in_file,
            next: 0,
            buf: Vec::new(),
            reals: Vec::new(),
            ints: Vec::new(),
            type_names: Vec::new(),
        })
    }

    /// The error of the first frame the file's end cuts, if any.
    fn truncation(&self) -> Option<Error> {
        self.cut.as_ref().map(|c| {
            let end = c.location.saturating_add(c.bytes);
            Error::Truncated {
                at: Location::binary(&self.file, c.frame, self.file_len),
                expected: format!(
                    "{} more bytes: the index puts chunk {} at bytes {}..{end}",
                    end - self.file_len,
                    c.name,
                    c.location
                ),
            }
        })
    }

    /// The entries of frame `k`.
    fn frame_entries(&self, k: usize) -> &[Entry] {
        let lo = self.entries.partition_point(|e| e.frame < k);
        let hi = self.entries.partition_point(|e| e.frame <= k);
        &self.entries[lo..hi]
    }

    fn find(&self, k: usize, c: Chunk) -> Option<Entry> {
        self.frame_entries(k).iter().find(|e| e.chunk == c).copied()
    }

    /// The chunk that gives `c` in frame `k`: its own, else frame 0's (the schema's rule for
    /// configuration chunks, counts and type names).
    fn own_or_first(&self, k: usize, c: Chunk) -> Option<Entry> {
        self.find(k, c).or_else(|| self.find(0, c))
    }

    /// The chunk that gives per-item `c` in frame `k` of `n` items: its own, else frame 0's when
    /// frame 0 has as many items (`n0`).
    fn per_item(&self, k: usize, c: Chunk, n: u64, n0: u64) -> Option<Entry> {
        self.find(k, c)
            .or_else(|| (n == n0).then(|| self.find(0, c)).flatten())
    }

    /// An error for `e`'s index entry (its type or shape), read for frame `k`.
    fn shape_error(&self, k: usize, e: &Entry, expected: &'static str, n: Option<u64>) -> Error {
        let count = n.map(|n| format!(", for N = {n}")).unwrap_or_default();
        Error::Parse {
            at: Location::binary(&self.file, k, e.at),
            expected,
            found: format!(
                "{}: {} × {} {} at byte {}{count}",
                e.chunk.name(),
                e.rows,
                e.cols,
                e.ty.name(),
                e.location
            ),
        }
    }

    /// An error for a value of chunk `c` at byte `byte`, read for frame `k`.
    fn value_error(
        &self,
        k: usize,
        c: Chunk,
        byte: u64,
        expected: &'static str,
        what: String,
    ) -> Error {
        Error::Parse {
            at: Location::binary(&self.file, k, byte),
            expected,
            found: format!("{}: {what}", c.name()),
        }
    }

    /// Checks `e`'s class and shape (`rows` × `cols`, or `values` in all) for frame `k`, then
    /// reads its data into `self.buf`.
    fn load(
        &mut self,
        k: usize,
        e: &Entry,
        class: Class,
        shape: Shape,
        expected: &'static str,
    ) -> Result<(), Error> {
        let ok = e.ty.is(class)
            && match shape {
                Shape::Values(v) => e.rows * e.cols as u64 == v,
                Shape::Rows(n, m) => e.rows == n && e.cols == m,
                Shape::Table => e.cols > 0 || e.rows == 0,
            };
        if !ok {
            let n = match shape {
                Shape::Rows(n, _) => Some(n),
                _ => None,
            };
            return Err(self.shape_error(k, e, expected, n));
        }
        let at = Location::binary(&self.file, k, e.location);
        self.buf.resize(e.bytes() as usize, 0);
        self.src
            .seek(SeekFrom::Start(e.location))
            .map_err(|source| Error::Io {
                at: at.clone(),
                source,
            })?;
        match self.src.read_exact(&mut self.buf) {
            Ok(()) => Ok(()),
            Err(x) if x.kind() == io::ErrorKind::UnexpectedEof => Err(Error::Truncated {
                at,
                expected: format!("{} bytes of chunk {}", e.bytes(), e.chunk.name()),
            }),
            Err(source) => Err(Error::Io { at, source }),
        }
    }

    /// The one integer of chunk `e` (`configuration/step`, a count), read for frame `k`.
    fn scalar(
        &mut self,
        k: usize,
        e: Option<Entry>,
        expected: &'static str,
    ) -> Result<Option<(i128, Entry)>, Error> {
        let Some(e) = e else {
            return Ok(None);
        };
        self.load(k, &e, Class::Int, Shape::Values(1), expected)?;
        Ok(Some((int_at(e.ty, &self.buf, 0), e)))
    }

    /// The count (`particles/N`, `bonds/N`) chunk `e` gives, read for frame `k` (0 without a
    /// chunk): at most `file_len / backing`.
    fn count(
        &mut self,
        k: usize,
        e: Option<Entry>,
        backing: u64,
        expected: &'static str,
    ) -> Result<(u64, Option<Entry>), Error> {
        let Some((n, e)) = self.scalar(k, e, "a count: one integer")? else {
            return Ok((0, None));
        };
        if n < 0 || n as u128 * backing as u128 > self.file_len as u128 {
            return Err(self.value_error(k, e.chunk, e.location, expected, n.to_string()));
        }
        Ok((n as u64, Some(e)))
    }

    /// Reads `e`'s `n` × `cols` reals into `self.reals` (float, or double rounded to float),
    /// each finite.
    fn reals(
        &mut self,
        k: usize,
        e: &Entry,
        n: u64,
        cols: u32,
        expected: &'static str,
    ) -> Result<(), Error> {
        self.load(k, e, Class::Real, Shape::Rows(n, cols), expected)?;
        self.reals.clear();
        match e.ty {
            Type::F64 => self.reals.extend(
                self.buf
                    .chunks_exact(8)
                    .map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8])) as f32),
            ),
            _ => self.reals.extend(
                self.buf
                    .chunks_exact(4)
                    .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            ),
        }
        if let Some(i) = self.reals.iter().position(|v| !v.is_finite()) {
            let (row, col) = (i / cols as usize, i % cols as usize);
            let what = format!("particle {row}, column {col}: {}", self.reals[i]);
            let byte = e.location + i as u64 * e.ty.size();
            return Err(self.value_error(k, e.chunk, byte, "finite values (as f32)", what));
        }
        Ok(())
    }

    /// Reads `e`'s `n` × `cols` integers into `self.ints` (saturated to i64).
    fn ints(
        &mut self,
        k: usize,
        e: &Entry,
        n: u64,
        cols: u32,
        expected: &'static str,
    ) -> Result<(), Error> {
        self.load(k, e, Class::Int, Shape::Rows(n, cols), expected)?;
        self.ints.clear();
        let size = e.ty.size() as usize;
        let count = self.buf.len() / size;
        self.ints.extend(
            (0..count).map(|i| {
                int_at(e.ty, &self.buf, i).clamp(i64::MIN as i128, i64::MAX as i128) as i64
            }),
        );
        Ok(())
    }

    /// Adds the property columns of `p` for frame `k` of `counts` = (N, frame 0's N)
    /// particles, when the file has its chunk in some frame: the chunk by the schema's rule,
    /// else the default.
    fn property(
        &mut self,
        frame: &mut Frame,
        k: usize,
        p: &PropertyChunk,
        counts: (u64, u64),
    ) -> Result<(), Error> {
        if !self.columns(k, p, counts)? {
            return Ok(());
        }
        let cols = p.names.len();
        for (j, name) in p.names.iter().enumerate() {
            let values = self.reals.iter().skip(j).step_by(cols).copied().collect();
            frame.properties.push(Property {
                name: (*name).to_string(),
                values,
            });
        }
        Ok(())
    }

    /// The values of `p`'s chunk for frame `k` of `counts` = (N, frame 0's N) particles into
    /// `self.reals`, row by row (the chunk by the schema's rule, else the default); false, and
    /// nothing read, when no frame of the file has the chunk.
    fn columns(&mut self, k: usize, p: &PropertyChunk, counts: (u64, u64)) -> Result<bool, Error> {
        if !self.in_file[p.chunk as usize] {
            return Ok(false);
        }
        let (n, n0) = counts;
        let cols = p.names.len();
        match self.per_item(k, p.chunk, n, n0) {
            Some(e) if p.class == Class::Int => {
                self.ints(k, &e, n, cols as u32, p.expected)?;
                self.reals.clear();
                let ints = &self.ints;
                self.reals.extend(ints.iter().map(|v| *v as f32));
            }
            Some(e) => self.reals(k, &e, n, cols as u32, p.expected)?,
            None => {
                self.reals.clear();
                for _ in 0..n {
                    self.reals.extend_from_slice(p.default);
                }
            }
        }
        Ok(true)
    }

    /// Reads frame `k` into `frame`; gives its cell.
    fn read_frame(&mut self, k: usize, frame: &mut Frame) -> Result<Option<UnitCell>, Error> {
        // Configuration.
        let step = self.own_or_first(k, Chunk::Step);
        let step = self.scalar(k, step, "configuration/step: one integer")?;
        frame.step = Some(match step {
            Some((s, e)) => i64::try_from(s).map_err(|_| {
                self.value_error(k, e.chunk, e.location, "a step below 2^63", s.to_string())
            })?,
            None => 0,
        });
        let dims = self.own_or_first(k, Chunk::Dimensions);
        if let Some((d, e)) = self.scalar(k, dims, "configuration/dimensions: one integer")?
            && d != 2
            && d != 3
        {
            let what = d.to_string();
            return Err(self.value_error(k, e.chunk, e.location, "dimensions 2 or 3", what));
        }
        let cell = self.cell(k)?;
        // Particles.
        let expected = "a particle count whose positions (12 bytes each) fit in the file";
        let (n, n_entry) = self.count(
            k,
            self.own_or_first(k, Chunk::ParticlesN),
            POSITION_BYTES,
            expected,
        )?;
        let (n0, _) = self.count(k, self.find(0, Chunk::ParticlesN), POSITION_BYTES, expected)?;
        let counts = (n, n0);
        let nu = n as usize;
        match self.per_item(k, Chunk::Position, n, n0) {
            Some(e) => {
                self.reals(
                    k,
                    &e,
                    n,
                    3,
                    "particles/position: N × 3 float or double, N = particles/N",
                )?;
                frame
                    .positions
                    .extend(self.reals.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
                if !all_in_bounds(&frame.positions) {
                    let bad = first_out_of_bounds(&frame.positions).unwrap_or(0);
                    let c = frame.positions[bad]
                        .iter()
                        .position(|v| v.is_nan() || v.abs() > MAX_COORDINATE as f32)
                        .unwrap_or(0);
                    let byte = e.location + (3 * bad + c) as u64 * e.ty.size();
                    let what = format!("particle {bad}: {:?}", frame.positions[bad]);
                    return Err(self.value_error(k, e.chunk, byte, IN_BOUNDS, what));
                }
            }
            None => frame.positions.resize(nu, [0.0; 3]),
        }
        self.types(k, frame, counts, n_entry)?;
        match self.per_item(k, Chunk::Diameter, n, n0) {
            Some(e) => {
                self.reals(
                    k,
                    &e,
                    n,
                    1,
                    "particles/diameter: N × 1 float or double, N = particles/N",
                )?;
                if let Some(i) = self.reals.iter().position(|d| *d < 0.0) {
                    let what = format!("particle {i}: {}", self.reals[i]);
                    let byte = e.location + i as u64 * e.ty.size();
                    return Err(self.value_error(k, e.chunk, byte, "diameters >= 0", what));
                }
                frame.radii.extend(self.reals.iter().map(|d| d * 0.5));
            }
            None => frame.radii.resize(nu, 0.5),
        }
        for p in &PROPERTIES {
            self.property(frame, k, p, counts)?;
        }
        // The frame's velocities (read as Å/ps, as positions as Å).
        if self.columns(k, &VELOCITY, counts)? {
            let v = self.reals.chunks_exact(3).map(|c| [c[0], c[1], c[2]]);
            frame.velocities.extend(v);
        }
        self.bonds(k, frame, n)?;
        Ok(Some(cell))
    }

    /// The cell of frame `k` (see the module doc).
    fn cell(&mut self, k: usize) -> Result<UnitCell, Error> {
        let expected_box = "configuration/box: 6 float or double values (Lx Ly Lz xy xz yz)";
        let (b, e) = match self.own_or_first(k, Chunk::Box) {
            Some(e) => {
                self.load(k, &e, Class::Real, Shape::Values(6), expected_box)?;
                let b: [f64; 6] = std::array::from_fn(|i| real_at(e.ty, &self.buf, i));
                (b, Some(e))
            }
            None => ([1.0, 1.0, 1.0, 0.0, 0.0, 0.0], None),
        };
        let [lx, ly, lz, xy, xz, yz] = b;
        let cell = if b.iter().all(|v| v.is_finite()) && lx > 0.0 && ly > 0.0 && lz >= 0.0 {
            let c = if lz == 0.0 { 1.0 } else { lz };
            let m = [[lx, 0.0, 0.0], [xy * ly, ly, 0.0], [xz * c, yz * c, c]];
            UnitCell::from_matrix(m).map(|cell| {
                let o = std::array::from_fn(|i| -0.5 * (m[0][i] + m[1][i] + m[2][i]));
                // A 2-D box's slab has no images along z.
                cell.with_origin(o).with_periodic([true, true, lz != 0.0])
            })
        } else {
            Err(Error::InvalidValue {
                what: format!("box {b:?}"),
            })
        };
        cell.map_err(|x| {
            // (The default box is a valid cell: an error comes from a chunk.)
            let byte = e.map_or(0, |e| e.location);
            let expected = "a box with Lx, Ly > 0, Lz >= 0, finite tilts, edges at most 1e7";
            self.value_error(k, Chunk::Box, byte, expected, x.to_string())
        })
    }

    /// Types, names and elements of frame `k`'s particles.
    fn types(
        &mut self,
        k: usize,
        frame: &mut Frame,
        counts: (u64, u64),
        n_entry: Option<Entry>,
    ) -> Result<(), Error> {
        let (n, n0) = counts;
        self.type_names.clear();
        match self.own_or_first(k, Chunk::Types) {
            Some(e) => {
                self.load(
                    k,
                    &e,
                    Class::Text,
                    Shape::Table,
                    "particles/types: NT × M type names (int8 or char)",
                )?;
                let cols = e.cols as usize;
                for (r, row) in self.buf.chunks_exact(cols.max(1)).enumerate() {
                    let name = until_nul(row);
                    let Some(l) = Label::from_utf8(name) else {
                        let byte = e.location + (r * cols) as u64;
                        let what = format!("type {r}: {}", Error::found(name));
                        return Err(self.value_error(
                            k,
                            e.chunk,
                            byte,
                            "a type name of at most 15 bytes of UTF-8",
                            what,
                        ));
                    };
                    self.type_names.push(l);
                }
            }
            None => self.type_names.push(Label::new("A").unwrap_or_default()),
        }
        let nt = self.type_names.len() as i64;
        match self.per_item(k, Chunk::TypeId, n, n0) {
            Some(e) => {
                self.ints(
                    k,
                    &e,
                    n,
                    1,
                    "particles/typeid: N × 1 integers, N = particles/N",
                )?;
                if let Some(i) = self.ints.iter().position(|t| !(0..nt).contains(t)) {
                    let byte = e.location + i as u64 * e.ty.size();
                    let what = format!("particle {i}: {} of {nt} types", self.ints[i]);
                    return Err(self.value_error(
                        k,
                        e.chunk,
                        byte,
                        "a typeid below the count of particles/types",
                        what,
                    ));
                }
            }
            None => {
                if nt == 0 && n > 0 {
                    let byte = n_entry.map_or(0, |e| e.location);
                    return Err(self.value_error(
                        k,
                        Chunk::ParticlesN,
                        byte,
                        "a type for the default typeid 0 (particles/types is empty)",
                        format!("{n} particles"),
                    ));
                }
                self.ints.clear();
                self.ints.resize(n as usize, 0);
            }
        }
        self.type_shapes(k, frame)?;
        let names = &self.type_names;
        frame
            .types
            .extend(self.ints.iter().map(|t| names[*t as usize]));
        frame.names.extend_from_slice(&frame.types);
        let elements: Vec<Option<Element>> = names
            .iter()
            .map(|l| element_of_symbol(l.as_bytes()))
            .collect();
        if elements.iter().any(|e| e.is_some()) {
            frame.elements.extend(
                self.ints
                    .iter()
                    .map(|t| elements[*t as usize].unwrap_or(Element::UNKNOWN)),
            );
        }
        Ok(())
    }

    /// The ellipsoids among frame `k`'s type shapes (`particles/type_shapes`, one JSON object
    /// per type): when some type is `{"type": "Ellipsoid", "a": .., "b": .., "c": ..}`, every
    /// particle gets the properties `shapex shapey shapez`, its type's diameters `2a 2b 2c`
    /// (as LAMMPS gives an ellipsoid's shape), 0 0 0 for a type of another shape or none (a
    /// sphere of its diameter, as LAMMPS's spheres). Called with `self.ints` holding the
    /// particles' typeids.
    fn type_shapes(&mut self, k: usize, frame: &mut Frame) -> Result<(), Error> {
        let Some(e) = self.own_or_first(k, Chunk::TypeShapes) else {
            return Ok(());
        };
        self.load(
            k,
            &e,
            Class::Text,
            Shape::Table,
            "particles/type_shapes: NT × M JSON shape descriptions (int8 or char)",
        )?;
        let cols = (e.cols as usize).max(1);
        let axes: Vec<Option<[f32; 3]>> = self
            .buf
            .chunks_exact(cols)
            .map(|row| ellipsoid_axes(until_nul(row)))
            .collect();
        if axes.iter().all(Option::is_none) {
            return Ok(());
        }
        for (c, name) in ["shapex", "shapey", "shapez"].into_iter().enumerate() {
            let values = self
                .ints
                .iter()
                .map(|t| {
                    axes.get(*t as usize)
                        .copied()
                        .flatten()
                        .map_or(0.0, |a| 2.0 * a[c])
                })
                .collect();
            frame.properties.push(Property {
                name: name.to_string(),
                values,
            });
        }
        Ok(())
    }

    /// Bonds of frame `k` between its `n` particles.
    fn bonds(&mut self, k: usize, frame: &mut Frame, n: u64) -> Result<(), Error> {
        let expected = "a bond count whose pairs (8 bytes each) fit in the file";
        let (bn, bn_entry) =
            self.count(k, self.own_or_first(k, Chunk::BondsN), BOND_BYTES, expected)?;
        if bn == 0 {
            return Ok(());
        }
        let (bn0, _) = self.count(k, self.find(0, Chunk::BondsN), BOND_BYTES, expected)?;
        let Some(e) = self.per_item(k, Chunk::BondsGroup, bn, bn0) else {
            // The schema's default pair (0, 0) is no bond.
            let byte = bn_entry.map_or(0, |e| e.location);
            return Err(self.value_error(
                k,
                Chunk::BondsN,
                byte,
                "a bonds/group chunk for the bonds bonds/N counts",
                format!("{bn} bonds without pairs"),
            ));
        };
        self.ints(k, &e, bn, 2, "bonds/group: N × 2 integers, N = bonds/N")?;
        let pairs = self.ints.chunks_exact(2);
        let bad = pairs.clone().position(|p| {
            p[0] == p[1] || !(0..n as i64).contains(&p[0]) || !(0..n as i64).contains(&p[1])
        });
        if let Some(i) = bad {
            let byte = e.location + 2 * i as u64 * e.ty.size();
            let what = format!(
                "bond {i}: {} {} of {n} particles",
                self.ints[2 * i],
                self.ints[2 * i + 1]
            );
            return Err(self.value_error(
                k,
                e.chunk,
                byte,
                "a bond between two different particles below particles/N",
                what,
            ));
        }
        frame.bonds.extend(pairs.map(|p| {
            let (a, b) = (p[0] as u32, p[1] as u32);
            [a.min(b), a.max(b)]
        }));
        frame.bonds.sort_unstable();
        frame.bonds.dedup();
        Ok(())
    }

    /// Reads the next frame (the `Trajectory` contract).
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        let k = self.next;
        if let Some(end) = crate::cursor::past_complete(k, self.complete, || self.truncation()) {
            return end;
        }
        let read = self.read_frame(k, frame);
        crate::cursor::settle(read, frame, &mut self.next)
    }

    /// Makes `read_next` read frame `n` (a cut frame counts as present).
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        let cut = self.cut.is_some();
        Ok(crate::cursor::seek(&mut self.next, n, self.complete, cut))
    }

    /// Number of frames; a chunk past the end of the file is its frame's error.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        match self.truncation() {
            Some(e) => Err(e),
            None => Ok(self.complete),
        }
    }
}

/// How many values a chunk must hold.
#[derive(Clone, Copy, Debug)]
enum Shape {
    /// This many in all, in any N × M (the box: 6 × 1 or 1 × 6).
    Values(u64),
    /// N rows of M.
    Rows(u64, u32),
    /// Any rows of M > 0 (type names).
    Table,
}

/// A per-particle chunk read into properties.
struct PropertyChunk {
    chunk: Chunk,
    class: Class,
    /// One property per column.
    names: &'static [&'static str],
    /// The schema's default row.
    default: &'static [f32],
    expected: &'static str,
}

/// The velocities: the frame's [`Frame::velocities`], read like a property's columns.
const VELOCITY: PropertyChunk = PropertyChunk {
    chunk: Chunk::Velocity,
    class: Class::Real,
    names: &["vx", "vy", "vz"],
    default: &[0.0; 3],
    expected: "particles/velocity: N × 3 float or double, N = particles/N",
};

/// The per-particle chunks that become properties, in the schema's order; names as the LAMMPS
/// readers give the same quantities.
const PROPERTIES: [PropertyChunk; 5] = [
    PropertyChunk {
        chunk: Chunk::Mass,
        class: Class::Real,
        names: &["mass"],
        default: &[1.0],
        expected: "particles/mass: N × 1 float or double, N = particles/N",
    },
    PropertyChunk {
        chunk: Chunk::Charge,
        class: Class::Real,
        names: &["charge"],
        default: &[0.0],
        expected: "particles/charge: N × 1 float or double, N = particles/N",
    },
    PropertyChunk {
        chunk: Chunk::Body,
        class: Class::Int,
        names: &["body"],
        default: &[-1.0],
        expected: "particles/body: N × 1 integers, N = particles/N",
    },
    PropertyChunk {
        chunk: Chunk::Orientation,
        class: Class::Real,
        names: &["quatw", "quati", "quatj", "quatk"],
        default: &[1.0, 0.0, 0.0, 0.0],
        expected: "particles/orientation: N × 4 float or double, N = particles/N",
    },
    PropertyChunk {
        chunk: Chunk::Image,
        class: Class::Int,
        names: &["ix", "iy", "iz"],
        default: &[0.0; 3],
        expected: "particles/image: N × 3 integers, N = particles/N",
    },
];

/// Value `i` of integer data `b` of type `ty` (little-endian).
fn int_at(ty: Type, b: &[u8], i: usize) -> i128 {
    let s = ty.size() as usize;
    let Some(v) = b.get(i * s..(i + 1) * s) else {
        return 0;
    };
    let mut w = [0u8; 8];
    w[..s].copy_from_slice(v);
    let u = u64::from_le_bytes(w);
    match ty {
        Type::I8 => u as u8 as i8 as i128,
        Type::I16 => u as u16 as i16 as i128,
        Type::I32 => u as u32 as i32 as i128,
        Type::I64 => u as i64 as i128,
        _ => u as i128,
    }
}

/// Value `i` of real data `b` of type `ty` (little-endian), as f64.
fn real_at(ty: Type, b: &[u8], i: usize) -> f64 {
    let s = ty.size() as usize;
    let Some(v) = b.get(i * s..(i + 1) * s) else {
        return f64::NAN;
    };
    match ty {
        Type::F32 => f32::from_le_bytes([v[0], v[1], v[2], v[3]]) as f64,
        Type::F64 => f64::from_le_bytes(v.try_into().unwrap_or([0; 8])),
        _ => f64::NAN,
    }
}

/// Checks the 256-byte header (`head`, shorter when the file is) against the file's length.
fn read_header(head: &[u8], file_len: u64, at: &dyn Fn(u64) -> Location) -> Result<Header, Error> {
    let parse = |byte, expected, found| Error::Parse {
        at: at(byte),
        expected,
        found,
    };
    if head.len() >= 8 && u64_at(head, 0) != MAGIC {
        return Err(parse(
            0,
            "the GSD magic number 0x65DF65DF65DF65DF (little-endian)",
            format!("{:#018x}", u64_at(head, 0)),
        ));
    }
    if (head.len() as u64) < HEADER {
        return Err(Error::Truncated {
            at: at(file_len),
            expected: format!("the 256-byte GSD header (the file has {file_len} bytes)"),
        });
    }
    let (schema_version, gsd_version) = (u32_at(head, 40), u32_at(head, 44));
    if gsd_version != 1 << 16 && gsd_version >> 16 != 2 {
        return Err(parse(
            44,
            "GSD file format version 1.0 or 2.x",
            version(gsd_version),
        ));
    }
    let schema = until_nul(&head[112..176]);
    if schema != b"hoomd" {
        return Err(parse(
            112,
            "the hoomd schema (a HOOMD-blue trajectory)",
            Error::found(schema),
        ));
    }
    if !(1 << 16..3 << 16).contains(&schema_version) {
        return Err(parse(
            40,
            "hoomd schema version 1.x or 2.x",
            version(schema_version),
        ));
    }
    // The index and namelist blocks, each inside the file.
    let block = |loc_at: usize, count_at: usize, unit: u64, what| {
        let (loc, count) = (u64_at(head, loc_at), u64_at(head, count_at));
        let fits = count
            .checked_mul(unit)
            .and_then(|b| b.checked_add(loc))
            .is_some_and(|end| end <= file_len && loc >= HEADER);
        if fits {
            Ok((loc, count))
        } else {
            Err(parse(
                count_at as u64,
                what,
                format!("{count} × {unit} bytes at byte {loc}, file of {file_len} bytes"),
            ))
        }
    };
    let (index_location, index_entries) = block(
        8,
        16,
        ENTRY,
        "an index block (index_location, index_allocated_entries) after the header, inside the file",
    )?;
    let (names_location, names_segments) = block(
        24,
        32,
        NAME_SEGMENT,
        "a namelist block (namelist_location, namelist_allocated_entries) after the header, inside the file",
    )?;
    Ok(Header {
        index_location,
        index_entries,
        names_location,
        names_segments,
        v1: gsd_version >> 16 == 1,
    })
}

/// The names of the namelist block, in id order.
fn names(block: &[u8], v1: bool) -> Vec<&[u8]> {
    let mut out = Vec::new();
    let mut rest = block;
    while !rest.is_empty() {
        let name = until_nul(rest);
        if name.is_empty() {
            break;
        }
        out.push(name);
        let step = if v1 {
            NAME_SEGMENT as usize
        } else {
            name.len() + 1
        };
        rest = &rest[step.min(rest.len())..];
    }
    out
}

/// What the index gives.
struct Index {
    entries: Vec<Entry>,
    complete: usize,
    cut: Option<Cut>,
    in_file: [bool; Chunk::ALL.len()],
}

/// Reads and checks the index: every used entry's type, name id, frame and size, and where the
/// file's data ends.
fn read_index<R: Read + Seek>(
    src: &mut R,
    h: &Header,
    file_len: u64,
    names: &[&[u8]],
    at: &dyn Fn(u64) -> Location,
) -> Result<Index, Error> {
    // The chunk each name id names (`None`: one this reader does not read).
    let chunk_of: Vec<Option<Chunk>> = names
        .iter()
        .map(|n| Chunk::ALL.into_iter().find(|c| c.name().as_bytes() == *n))
        .collect();
    let parse = |byte, expected, found| Error::Parse {
        at: at(byte),
        expected,
        found,
    };
    src.seek(SeekFrom::Start(h.index_location))
        .map_err(|source| Error::Io {
            at: at(h.index_location),
            source,
        })?;
    let mut entries = Vec::new();
    let mut in_file = [false; Chunk::ALL.len()];
    let mut cut: Option<(Cut, u64)> = None;
    let mut last_frame = None;
    // Read in blocks of 4096 entries (128 KiB).
    let mut block = vec![0u8; (ENTRY * 4096).min(h.index_entries * ENTRY) as usize];
    let mut slot = 0u64;
    while slot < h.index_entries {
        let n = (h.index_entries - slot).min(4096);
        let bytes = &mut block[..(n * ENTRY) as usize];
        let start = h.index_location + slot * ENTRY;
        src.read_exact(bytes).map_err(|source| Error::Io {
            at: at(start),
            source,
        })?;
        for (j, b) in bytes.chunks_exact(ENTRY as usize).enumerate() {
            let e_at = start + j as u64 * ENTRY;
            let location = u64_at(b, 16);
            if location == 0 {
                continue; // an unused slot
            }
            let (frame, rows, cols) = (u64_at(b, 0), u64_at(b, 8), u32_at(b, 24));
            let id = u16::from_le_bytes([b[28], b[29]]) as usize;
            let ty = Type::from_code(b[30])
                .ok_or_else(|| parse(e_at + 30, "a GSD data type code 1-11", b[30].to_string()))?;
            if id >= chunk_of.len() {
                return Err(parse(
                    e_at + 28,
                    "a chunk name id of the namelist",
                    format!("{id} of {} names", chunk_of.len()),
                ));
            }
            if frame >= h.index_entries {
                return Err(parse(
                    e_at,
                    "a frame number below the index's allocated entries",
                    format!("{frame} of {}", h.index_entries),
                ));
            }
            if last_frame.is_some_and(|f| frame < f) {
                return Err(parse(
                    e_at,
                    "index entries in frame order",
                    format!("frame {frame} after frame {}", last_frame.unwrap_or(0)),
                ));
            }
            last_frame = Some(frame);
            if location > i64::MAX as u64 {
                return Err(parse(
                    e_at + 16,
                    "a chunk location >= 0",
                    format!("{}", location as i64),
                ));
            }
            let size = rows
                .checked_mul(cols as u64)
                .and_then(|v| v.checked_mul(ty.size()));
            let Some(size) = size else {
                return Err(parse(
                    e_at + 8,
                    "a chunk size N × M × type size within 64 bits",
                    format!("{rows} × {cols} {}", ty.name()),
                ));
            };
            let frame = frame as usize;
            let inside = location
                .checked_add(size)
                .is_some_and(|end| end <= file_len);
            match &cut {
                None if !inside => {
                    cut = Some((
                        Cut {
                            frame,
                            name: String::from_utf8_lossy(names[id]).into_owned(),
                            location,
                            bytes: size,
                        },
                        e_at,
                    ));
                }
                // Data is written frame after frame: past a cut, no later frame's chunk lies
                // inside the file.
                Some((c, c_at)) if inside && size > 0 && frame > c.frame => {
                    return Err(parse(
                        c_at + 16,
                        "a chunk inside the file (a later frame's chunk is)",
                        format!(
                            "{} bytes at byte {}, file of {file_len} bytes",
                            c.bytes, c.location
                        ),
                    ));
                }
                _ => {}
            }
            if let Some(chunk) = chunk_of[id] {
                in_file[chunk as usize] = true;
                entries.push(Entry {
                    frame,
                    rows,
                    cols,
                    location,
                    ty,
                    chunk,
                    at: e_at,
                });
            }
        }
        slot += n;
    }
    let declared = last_frame.map_or(0, |f| f as usize + 1);
    let complete = cut.as_ref().map_or(declared, |(c, _)| c.frame);
    Ok(Index {
        entries,
        complete,
        cut: cut.map(|(c, _)| c),
        in_file,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn ellipsoid_shapes_are_read_from_their_json() {
        let axes = |j: &str| ellipsoid_axes(j.as_bytes());
        assert_eq!(
            axes(r#"{"type": "Ellipsoid", "a": 1.5, "b": 0.6, "c": 0.4}"#),
            Some([1.5, 0.6, 0.4])
        );
        assert_eq!(
            axes(r#"{"c":3,"a":1,"type":"Ellipsoid","b":2}"#),
            Some([1.0, 2.0, 3.0])
        );
        assert_eq!(axes(r#"{"type": "Sphere", "diameter": 1.0}"#), None);
        assert_eq!(
            axes(r#"{"type": "Ellipsoid", "a": 1.0, "b": 0.0, "c": 1.0}"#),
            None
        );
        assert_eq!(axes(r#"{"type": "Ellipsoid", "a": 1.0, "b": 2.0}"#), None);
        assert_eq!(axes("not json"), None);
        assert_eq!(ellipsoid_axes(&[0xff, 0xfe, b'{']), None);
    }

    #[test]
    fn refuses_other_files_with_a_located_error() {
        let e = GsdReader::new(Cursor::new(b"CDF\x01\0\0\0\0\0\0".to_vec()), "x.gsd".into())
            .err()
            .unwrap();
        assert!(
            e.to_string()
                .starts_with("x.gsd: byte 0: expected the GSD magic"),
            "{e}"
        );
        let e = GsdReader::new(Cursor::new(MAGIC.to_le_bytes().to_vec()), "x.gsd".into())
            .err()
            .unwrap();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
    }

    #[test]
    fn integers_of_every_width_and_sign() {
        let b = [0xFFu8; 8];
        assert_eq!(int_at(Type::U8, &b, 0), 255);
        assert_eq!(int_at(Type::I8, &b, 0), -1);
        assert_eq!(int_at(Type::I16, &b, 1), -1);
        assert_eq!(int_at(Type::U32, &b, 1), u32::MAX as i128);
        assert_eq!(int_at(Type::U64, &b, 0), u64::MAX as i128);
        assert_eq!(int_at(Type::I64, &b, 0), -1);
        assert_eq!(int_at(Type::I32, &b, 2), 0, "past the data");
    }

    #[test]
    fn names_in_both_layouts() {
        let v2 = b"particles/N\0log/x\0particles/position\0\0\0";
        let want: [&[u8]; 3] = [b"particles/N", b"log/x", b"particles/position"];
        assert_eq!(names(v2, false), want);
        let mut v1 = vec![0u8; 192];
        v1[..11].copy_from_slice(b"particles/N");
        v1[64..69].copy_from_slice(b"log/x");
        assert_eq!(names(&v1, true), want[..2]);
    }
}
