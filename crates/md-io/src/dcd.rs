//! DCD trajectories (CHARMM, NAMD, LAMMPS, X-PLOR): a reader over `Read + Seek` and a
//! CHARMM-flavour writer.
//!
//! # Layout
//! A DCD file is a sequence of Fortran "unformatted" records: a length marker, the payload, and
//! the same marker again. Markers are 32-bit in every current writer; some old 64-bit Fortran
//! runtimes wrote 64-bit markers, which are detected and read. Byte order is the writing
//! machine's: it is told from the first marker, which must be 84.
//!
//! ```text
//! header record (84 bytes): "CORD", then 20 i32 control words ICNTRL
//!     [0] NSET frames   [1] ISTART first step   [2] NSAVC steps per frame   [3] NSTEP
//!     [8] NAMNF fixed atoms   [9] DELTA time step (f32, AKMA units; X-PLOR: f64 over [9..11])
//!     [10] 1 if every frame starts with a unit-cell record   [11] 1 if a 4th coordinate follows
//!     [19] CHARMM version (0 = X-PLOR layout: no unit cell, no 4th dimension)
//! title record: i32 NTITLE, then NTITLE lines of 80 bytes
//! atom record: i32 NATOM
//! free-atom record (only if NAMNF > 0): NATOM - NAMNF 1-based i32 indices of the free atoms
//! every frame: [unit cell: 6 f64] X: N f32, Y: N f32, Z: N f32 [W: N f32]
//! ```
//! With fixed atoms (NAMNF > 0) the first frame holds every atom and later frames hold only the
//! free atoms; the fixed ones keep their first-frame positions.
//!
//! Every frame after the first has the same size, so the frame index is offset arithmetic: no
//! scan. The number of frames is taken from the file length (NSET is often stale: writers that
//! crash never patch it); a partial frame at the end, or fewer complete frames than NSET
//! promises, is reported as [`Error::Truncated`] for that frame while every complete frame
//! before it stays readable.
//!
//! # Unit cell
//! The cell record holds `[A, gamma, B, beta, alpha, C]`. CHARMM and NAMD ≥ 2.5 (and LAMMPS and
//! MDAnalysis) store the angles as cosines, NAMD 2.5 as degrees; when all three values lie in
//! [-1, 1] they are cosines. Newer CHARMM stores the symmetric shape matrix
//! `[h11, h21, h22, h31, h32, h33]` instead, recognised (as VMD and MDAnalysis do) by a negative
//! entry or an "angle" above 180.
//!
//! # References
//! - CHARMM `dynio.src` (the writer of the format); VMD `dcdplugin.c` and MDAnalysis
//!   `DCD.py` for the conventions of the unit cell and of fixed atoms (read, not copied).

use std::io::{self, Read, Seek, SeekFrom, Write};
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, all_finite, all_in_bounds, first_out_of_bounds};
use crate::error::{Error, Location};
use crate::frame::{Frame, UnitCell};

/// Size of the DCD header record payload: "CORD" + 20 control words.
const HEADER_LEN: u64 = 84;
/// Length of one title line.
const TITLE_LEN: usize = 80;
/// One AKMA time unit in picoseconds (CHARMM's internal time unit).
pub const AKMA_PS: f64 = 0.048_888_21;

/// Byte order of a binary file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Endian {
    /// Least significant byte first (x86, ARM).
    Little,
    /// Most significant byte first (old SGI, SPARC, POWER).
    Big,
}

/// Which program family wrote the file, as told by ICNTRL[19].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DcdFlavour {
    /// CHARMM layout (also NAMD, LAMMPS, MDAnalysis): f32 time step, optional unit cell and 4D.
    Charmm,
    /// X-PLOR layout: f64 time step, never a unit cell.
    Xplor,
}

/// A unit cell as three lengths (Å) and three angles (degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcdCell {
    /// Edge lengths a, b, c in Å.
    pub lengths: [f64; 3],
    /// Angles alpha (b^c), beta (a^c), gamma (a^b) in degrees.
    pub angles: [f64; 3],
}

/// What the header of a DCD file says.
#[derive(Clone, Debug, PartialEq)]
pub struct DcdInfo {
    /// Byte order of the file.
    pub endian: Endian,
    /// True if the record markers are 64-bit.
    pub wide_markers: bool,
    /// CHARMM or X-PLOR layout.
    pub flavour: DcdFlavour,
    /// Atoms in every frame (after merging the fixed atoms back in).
    pub n_atoms: usize,
    /// Fixed atoms (NAMNF): stored only in the first frame.
    pub n_fixed: usize,
    /// Every frame carries a unit-cell record.
    pub has_cell: bool,
    /// Every frame carries a 4th coordinate (skipped).
    pub has_4d: bool,
    /// Frames the header declares (NSET); may be stale.
    pub declared_frames: usize,
    /// First step (ISTART).
    pub first_step: i64,
    /// Steps between saved frames (NSAVC).
    pub steps_per_frame: i64,
    /// Integration time step in ps (DELTA converted from AKMA units).
    pub timestep_ps: f64,
    /// Title lines, trailing blanks and NULs removed.
    pub titles: Vec<String>,
}

/// Where the frames are: offsets and sizes fixed at open time.
#[derive(Clone, Copy, Debug)]
struct Layout {
    marker: u64,
    first_offset: u64,
    first_size: u64,
    frame_size: u64,
    n_complete: usize,
    file_len: u64,
}

impl Layout {
    /// Byte offset and size of frame `index`.
    fn span(&self, index: usize) -> (u64, u64) {
        if index == 0 {
            (self.first_offset, self.first_size)
        } else {
            let off = self.first_offset + self.first_size + (index as u64 - 1) * self.frame_size;
            (off, self.frame_size)
        }
    }
}

/// Reads a DCD file frame by frame, in any order.
#[derive(Debug)]
pub struct DcdReader<R> {
    src: R,
    file: Arc<str>,
    info: DcdInfo,
    layout: Layout,
    /// 0-based indices of the free atoms (empty without fixed atoms).
    free: Vec<u32>,
    /// Frame 0 positions when there are fixed atoms (the fixed ones are taken from here).
    fixed: Vec<[f32; 3]>,
    /// Raw bytes of the current frame.
    buf: Vec<u8>,
    /// Where `src` is now, to skip needless seeks when reading in order.
    pos: u64,
    /// The frame `read_next` reads.
    next: usize,
}

/// Location of a header problem (no frame yet).
fn header_at(file: &Arc<str>, byte: u64) -> Location {
    Location {
        byte: Some(byte),
        ..Location::file(file)
    }
}

fn io_error(file: &Arc<str>, frame: Option<usize>, byte: u64, source: io::Error) -> Error {
    Error::Io {
        at: Location {
            frame,
            byte: Some(byte),
            ..Location::file(file)
        },
        source,
    }
}

/// Reads exactly `buf.len()` bytes at `byte`; a short file is `Truncated`.
fn read_exact_at<R: Read>(
    src: &mut R,
    buf: &mut [u8],
    file: &Arc<str>,
    frame: Option<usize>,
    byte: u64,
    what: &str,
) -> Result<(), Error> {
    match src.read_exact(buf) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Err(Error::Truncated {
            at: Location {
                frame,
                byte: Some(byte),
                ..Location::file(file)
            },
            expected: format!("{} bytes of {what}", buf.len()),
        }),
        Err(e) => Err(io_error(file, frame, byte, e)),
    }
}

#[inline(always)]
pub(crate) fn u32_at(b: &[u8], endian: Endian) -> u32 {
    let a = [b[0], b[1], b[2], b[3]];
    match endian {
        Endian::Little => u32::from_le_bytes(a),
        Endian::Big => u32::from_be_bytes(a),
    }
}

#[inline(always)]
pub(crate) fn u64_at(b: &[u8], endian: Endian) -> u64 {
    let a = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
    match endian {
        Endian::Little => u64::from_le_bytes(a),
        Endian::Big => u64::from_be_bytes(a),
    }
}

#[inline(always)]
fn f32_at<const BIG: bool>(b: &[u8]) -> f32 {
    let a = [b[0], b[1], b[2], b[3]];
    if BIG {
        f32::from_be_bytes(a)
    } else {
        f32::from_le_bytes(a)
    }
}

/// Sequential reader of the header records, tracking the byte offset.
struct HeaderSrc<'a, R> {
    src: &'a mut R,
    file: &'a Arc<str>,
    off: u64,
    file_len: u64,
    endian: Endian,
    marker: u64,
}

impl<R: Read> HeaderSrc<'_, R> {
    fn bytes(&mut self, n: u64, what: &str) -> Result<Vec<u8>, Error> {
        // Check the length against the file before allocating: a corrupt marker must not
        // make us allocate gigabytes.
        if n > self.file_len.saturating_sub(self.off) {
            return Err(Error::Truncated {
                at: header_at(self.file, self.file_len),
                expected: format!("{n} bytes of {what} from byte {}", self.off),
            });
        }
        let mut v = vec![0; n as usize];
        read_exact_at(self.src, &mut v, self.file, None, self.off, what)?;
        self.off += n;
        Ok(v)
    }

    fn marker(&mut self, what: &str) -> Result<u64, Error> {
        let b = self.bytes(self.marker, what)?;
        Ok(if self.marker == 8 {
            u64_at(&b, self.endian)
        } else {
            u64::from(u32_at(&b, self.endian))
        })
    }

    /// One record whose length must be `expected` (or anything, if `None`).
    fn record(&mut self, expected: Option<u64>, what: &'static str) -> Result<Vec<u8>, Error> {
        let start = self.off;
        let len = self.marker(what)?;
        if let Some(want) = expected
            && len != want
        {
            return Err(Error::Parse {
                at: header_at(self.file, start),
                expected: what,
                found: format!("record marker {len}, expected {want}"),
            });
        }
        let payload = self.bytes(len, what)?;
        let end_at = self.off;
        let end = self.marker(what)?;
        if end != len {
            return Err(Error::Parse {
                at: header_at(self.file, end_at),
                expected: what,
                found: format!("closing record marker {end}, opening marker was {len}"),
            });
        }
        Ok(payload)
    }
}

impl<R: Read + Seek> DcdReader<R> {
    /// Opens a DCD stream: reads and checks the header, and measures the frames.
    ///
    /// `file` names the stream in errors.
    pub fn new(mut src: R, file: Arc<str>) -> Result<Self, Error> {
        // Measure the file.
        let file_len = src
            .seek(SeekFrom::End(0))
            .and_then(|n| src.seek(SeekFrom::Start(0)).map(|_| n))
            .map_err(|e| io_error(&file, None, 0, e))?;

        // Detect byte order and marker width from the first record marker (84) and "CORD".
        let mut head = [0u8; 12];
        let n_head = (file_len.min(12)) as usize;
        read_exact_at(&mut src, &mut head[..n_head], &file, None, 0, "DCD header")?;
        let (endian, marker) = detect(&head[..n_head]).ok_or_else(|| Error::Parse {
            at: header_at(&file, 0),
            expected: "DCD header record (marker 84, then \"CORD\")",
            found: Error::found(&head[..n_head]),
        })?;
        src.seek(SeekFrom::Start(0))
            .map_err(|e| io_error(&file, None, 0, e))?;

        let mut h = HeaderSrc {
            src: &mut src,
            file: &file,
            off: 0,
            file_len,
            endian,
            marker,
        };

        // Header record: "CORD" + ICNTRL[20].
        let rec = h.record(Some(HEADER_LEN), "84-byte DCD header record")?;
        let icntrl = |i: usize| u32_at(&rec[4 + 4 * i..], endian) as i32;
        let flavour = if icntrl(19) != 0 {
            DcdFlavour::Charmm
        } else {
            DcdFlavour::Xplor
        };
        let delta_akma = match flavour {
            DcdFlavour::Charmm => {
                let b = &rec[4 + 4 * 9..];
                f64::from(match endian {
                    Endian::Little => f32_at::<false>(b),
                    Endian::Big => f32_at::<true>(b),
                })
            }
            DcdFlavour::Xplor => f64::from_bits(u64_at(&rec[4 + 4 * 9..], endian)),
        };
        let has_cell = flavour == DcdFlavour::Charmm && icntrl(10) != 0;
        let has_4d = flavour == DcdFlavour::Charmm && icntrl(11) != 0;
        let declared = icntrl(0).max(0) as usize;
        let namnf = icntrl(8);

        // Title record: NTITLE then NTITLE x 80 bytes.
        let title_at = h.off;
        let rec = h.record(None, "title record (NTITLE, then 80-byte lines)")?;
        let ntitle = if rec.len() >= 4 {
            u32_at(&rec, endian) as usize
        } else {
            usize::MAX
        };
        if rec.len() < 4 || (rec.len() - 4) % TITLE_LEN != 0 || (rec.len() - 4) / TITLE_LEN < ntitle
        {
            return Err(Error::Parse {
                at: header_at(&file, title_at),
                expected: "title record of 4 + 80 x NTITLE bytes",
                found: format!("{} bytes", rec.len()),
            });
        }
        let titles = rec[4..]
            .chunks_exact(TITLE_LEN)
            .take(ntitle)
            .map(|t| {
                String::from_utf8_lossy(t)
                    .trim_end_matches([' ', '\0'])
                    .to_string()
            })
            .collect();

        // Atom record.
        let natom_at = h.off;
        let rec = h.record(Some(4), "4-byte atom-count record")?;
        let n_atoms = u32_at(&rec, endian) as i32;
        if n_atoms <= 0 || namnf < 0 || namnf >= n_atoms {
            return Err(Error::Parse {
                at: header_at(&file, natom_at),
                expected: "NATOM > 0 and 0 <= NAMNF < NATOM",
                found: format!("NATOM {n_atoms}, NAMNF {namnf}"),
            });
        }
        let n_atoms = n_atoms as usize;
        let n_fixed = namnf as usize;

        // Free-atom record (fixed atoms only): 1-based indices, checked and made 0-based.
        let mut free = Vec::new();
        if n_fixed > 0 {
            let n_free = n_atoms - n_fixed;
            let at = h.off;
            let rec = h.record(Some(4 * n_free as u64), "free-atom index record")?;
            free.reserve_exact(n_free);
            for (k, b) in rec.chunks_exact(4).enumerate() {
                let i = u32_at(b, endian);
                if i == 0 || i as usize > n_atoms {
                    return Err(Error::Parse {
                        at: header_at(&file, at + marker + 4 * k as u64),
                        expected: "free-atom index in 1..=NATOM",
                        found: i.to_string(),
                    });
                }
                free.push(i - 1);
            }
        }

        // Measure the frames: the first holds every atom, the others only the free ones.
        let record = |n: u64| 2 * marker + n;
        let frame_bytes = |n: u64| {
            let cell = if has_cell { record(48) } else { 0 };
            let dims = if has_4d { 4 } else { 3 };
            cell + dims * record(4 * n)
        };
        let first_offset = h.off;
        let first_size = frame_bytes(n_atoms as u64);
        let frame_size = frame_bytes((n_atoms - n_fixed) as u64);
        let body = file_len - first_offset;
        let n_complete = if body < first_size {
            0
        } else {
            1 + ((body - first_size) / frame_size) as usize
        };
        let info = DcdInfo {
            endian,
            wide_markers: marker == 8,
            flavour,
            n_atoms,
            n_fixed,
            has_cell,
            has_4d,
            declared_frames: declared,
            first_step: i64::from(icntrl(1)),
            steps_per_frame: i64::from(icntrl(2)),
            timestep_ps: delta_akma * AKMA_PS,
            titles,
        };
        let mut reader = DcdReader {
            src,
            file,
            info,
            layout: Layout {
                marker,
                first_offset,
                first_size,
                frame_size,
                n_complete,
                file_len,
            },
            free,
            fixed: Vec::new(),
            buf: Vec::new(),
            pos: first_offset,
            next: 0,
        };
        // Keep frame 0: later frames take their fixed atoms from it.
        if n_fixed > 0 && n_complete > 0 {
            let mut first = Vec::new();
            reader.read_frame(0, &mut first)?;
            reader.fixed = first;
        }
        Ok(reader)
    }

    /// What the header says.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn info(&self) -> &DcdInfo {
        &self.info
    }

    /// The number of complete frames in the file.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn frame_count(&self) -> usize {
        self.layout.n_complete
    }

    /// The error for the first frame that cannot be read because the file ends early, if any:
    /// a partial frame at the end, or fewer frames than the header declares.
    pub fn truncation(&self) -> Option<Error> {
        let l = &self.layout;
        let (off, size) = l.span(l.n_complete);
        if off < l.file_len {
            Some(Error::Truncated {
                at: Location::binary(&self.file, l.n_complete, l.file_len),
                expected: format!(
                    "{} more bytes (frame of {size} bytes starting at byte {off})",
                    off + size - l.file_len
                ),
            })
        } else if self.info.declared_frames > l.n_complete {
            Some(Error::Truncated {
                at: Location::binary(&self.file, l.n_complete, l.file_len),
                expected: format!(
                    "{} frames declared by the header (NSET), found {}",
                    self.info.declared_frames, l.n_complete
                ),
            })
        } else {
            None
        }
    }

    /// Reads frame `index` into `positions` (Å, one entry per atom) and returns its unit cell
    /// (`None` if the file has none or it is all zero).
    pub fn read_frame(
        &mut self,
        index: usize,
        positions: &mut Vec<[f32; 3]>,
    ) -> Result<Option<DcdCell>, Error> {
        if index >= self.layout.n_complete {
            if index == self.layout.n_complete
                && let Some(e) = self.truncation()
            {
                return Err(e);
            }
            return Err(Error::FrameOutOfRange {
                file: self.file.clone(),
                requested: index,
                n_frames: self.layout.n_complete,
            });
        }
        // Read the whole frame in one call.
        let (off, size) = self.layout.span(index);
        if self.pos != off {
            self.src
                .seek(SeekFrom::Start(off))
                .map_err(|e| io_error(&self.file, Some(index), off, e))?;
        }
        self.buf.resize(size as usize, 0);
        self.pos = u64::MAX;
        read_exact_at(
            &mut self.src,
            &mut self.buf,
            &self.file,
            Some(index),
            off,
            "DCD frame",
        )?;
        self.pos = off + size;

        // Decode it.
        let full = index == 0 || self.info.n_fixed == 0;
        let n = if full {
            self.info.n_atoms
        } else {
            self.info.n_atoms - self.info.n_fixed
        };
        let frame = FrameBytes {
            buf: &self.buf,
            file: &self.file,
            index,
            offset: off,
            endian: self.info.endian,
            marker: self.layout.marker,
        };
        let mut p = 0;
        let cell = if self.info.has_cell {
            let at = p;
            let b = frame.record(&mut p, 48, "unit-cell record (6 f64)")?;
            let mut u = [0.0; 6];
            for (k, v) in u.iter_mut().enumerate() {
                *v = f64::from_bits(u64_at(&b[8 * k..], self.info.endian));
            }
            cell_from_charmm(u).map_err(|found| Error::Parse {
                at: Location::binary(&self.file, index, off + at as u64),
                expected: "finite unit cell [A, gamma, B, beta, alpha, C]",
                found,
            })?
        } else {
            None
        };
        let x_at = p;
        let xs = frame.record(&mut p, 4 * n as u64, "X coordinate record")?;
        let ys = frame.record(&mut p, 4 * n as u64, "Y coordinate record")?;
        let zs = frame.record(&mut p, 4 * n as u64, "Z coordinate record")?;
        if self.info.has_4d {
            frame.record(&mut p, 4 * n as u64, "4th coordinate record")?;
        }

        // Interleave X, Y, Z into positions (kernel chosen by byte order outside the loop).
        if full {
            positions.clear();
            positions.resize(n, [0.0; 3]);
            match self.info.endian {
                Endian::Little => interleave::<false>(positions, xs, ys, zs),
                Endian::Big => interleave::<true>(positions, xs, ys, zs),
            }
        } else {
            // Fixed atoms: start from frame 0, then scatter the free atoms.
            positions.clear();
            positions.extend_from_slice(&self.fixed);
            match self.info.endian {
                Endian::Little => scatter::<false>(positions, &self.free, xs, ys, zs),
                Endian::Big => scatter::<true>(positions, &self.free, xs, ys, zs),
            }
        }

        // Check that no NaN, infinity or absurd value leaves the reader.
        if !all_in_bounds(positions) {
            let bad = first_out_of_bounds(positions).unwrap_or(0);
            let slot = if full {
                bad
            } else {
                self.free
                    .iter()
                    .position(|&f| f as usize == bad)
                    .unwrap_or(0)
            };
            return Err(Error::Parse {
                at: Location::binary(
                    &self.file,
                    index,
                    off + (x_at as u64) + self.layout.marker + 4 * slot as u64,
                ),
                expected: IN_BOUNDS,
                found: format!("atom {bad}: {:?}", positions[bad]),
            });
        }
        Ok(cell)
    }

    /// Reads the next frame into `frame` (the `Trajectory` contract): positions, cell, step and
    /// time (ISTART + k NSAVC steps of DELTA). `Ok(false)` after the last frame; on error the
    /// frame is left empty and the reader stays at the damaged frame.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        let index = self.next;
        if index >= self.layout.n_complete && self.truncation().is_none() {
            return Ok(false);
        }
        let r = self
            .read_frame(index, &mut frame.positions)
            .and_then(|cell| {
                cell.map(|c| {
                    UnitCell::from_lengths_angles(c.lengths, c.angles).map_err(|e| Error::Parse {
                        at: Location::binary(
                            &self.file,
                            index,
                            self.layout.span(index).0 + self.layout.marker,
                        ),
                        expected: "a unit cell with volume > 0",
                        found: e.to_string(),
                    })
                })
                .transpose()
            });
        crate::cursor::settle(r, frame, &mut self.next)?;
        let step = self.info.first_step + index as i64 * self.info.steps_per_frame;
        frame.step = Some(step);
        frame.time = Some(step as f64 * self.info.timestep_ps);
        Ok(true)
    }

    /// Makes `read_next` read frame `n`; `Ok(false)` if there is no frame `n` (a truncated frame
    /// counts as present, so that reading it reports the damage).
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        let damaged = self.truncation().is_some();
        Ok(crate::cursor::seek(
            &mut self.next,
            n,
            self.layout.n_complete,
            damaged,
        ))
    }

    /// Number of frames (the `Trajectory` contract; offset arithmetic, no scan). A partial frame
    /// at the end, or fewer frames than NSET declares, is that frame's [`Error::Truncated`], not
    /// a shorter count: nothing is dropped silently.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        match self.truncation() {
            Some(e) => Err(e),
            None => Ok(self.layout.n_complete),
        }
    }
}

/// Detects byte order and record-marker width from the first bytes.
fn detect(head: &[u8]) -> Option<(Endian, u64)> {
    if head.len() >= 8 && &head[4..8] == b"CORD" {
        for endian in [Endian::Little, Endian::Big] {
            if u32_at(head, endian) == HEADER_LEN as u32 {
                return Some((endian, 4));
            }
        }
    }
    if head.len() >= 12 && &head[8..12] == b"CORD" {
        for endian in [Endian::Little, Endian::Big] {
            if u64_at(head, endian) == HEADER_LEN {
                return Some((endian, 8));
            }
        }
    }
    None
}

/// The bytes of one frame, with what is needed to name a place in it.
struct FrameBytes<'a> {
    buf: &'a [u8],
    file: &'a Arc<str>,
    index: usize,
    offset: u64,
    endian: Endian,
    marker: u64,
}

impl<'a> FrameBytes<'a> {
    fn marker_at(&self, p: usize) -> u64 {
        if self.marker == 8 {
            u64_at(&self.buf[p..], self.endian)
        } else {
            u64::from(u32_at(&self.buf[p..], self.endian))
        }
    }

    /// Checks the two markers of a record of `len` bytes at `*p` and returns its payload.
    fn record(&self, p: &mut usize, len: u64, what: &'static str) -> Result<&'a [u8], Error> {
        let m = self.marker as usize;
        let start = *p;
        let end = start + m + len as usize;
        // The frame size was computed from these lengths, so the slices are in bounds.
        debug_assert!(end + m <= self.buf.len());
        for at in [start, end] {
            let found = self.marker_at(at);
            if found != len {
                return Err(Error::Parse {
                    at: Location::binary(self.file, self.index, self.offset + at as u64),
                    expected: what,
                    found: format!("record marker {found}, expected {len}"),
                });
            }
        }
        *p = end + m;
        Ok(&self.buf[start + m..end])
    }
}

/// Writes X, Y, Z blocks into interleaved positions.
fn interleave<const BIG: bool>(out: &mut [[f32; 3]], xs: &[u8], ys: &[u8], zs: &[u8]) {
    let it = xs
        .chunks_exact(4)
        .zip(ys.chunks_exact(4))
        .zip(zs.chunks_exact(4));
    for (o, ((x, y), z)) in out.iter_mut().zip(it) {
        *o = [f32_at::<BIG>(x), f32_at::<BIG>(y), f32_at::<BIG>(z)];
    }
}

/// Writes the free atoms' X, Y, Z into their slots.
fn scatter<const BIG: bool>(out: &mut [[f32; 3]], free: &[u32], xs: &[u8], ys: &[u8], zs: &[u8]) {
    let it = xs
        .chunks_exact(4)
        .zip(ys.chunks_exact(4))
        .zip(zs.chunks_exact(4));
    for (&i, ((x, y), z)) in free.iter().zip(it) {
        // Indices were checked at open time.
        out[i as usize] = [f32_at::<BIG>(x), f32_at::<BIG>(y), f32_at::<BIG>(z)];
    }
}

/// Converts the cell record `[A, gamma, B, beta, alpha, C]` to lengths and angles.
///
/// Returns `Ok(None)` for an all-zero record (no cell), `Err` for non-finite values.
fn cell_from_charmm(u: [f64; 6]) -> Result<Option<DcdCell>, String> {
    if !u.iter().all(|v| v.is_finite()) {
        return Err(format!("{u:?}"));
    }
    let lengths = [u[0], u[2], u[5]];
    if lengths == [0.0; 3] {
        return Ok(None);
    }
    let angles = [u[4], u[3], u[1]];
    if angles.iter().all(|a| (-1.0..=1.0).contains(a)) {
        // Cosines (CHARMM, NAMD >= 2.5, LAMMPS, MDAnalysis): 90 - asin gives exactly 90 for 0.
        let deg = |c: f64| 90.0 - c.asin().to_degrees();
        return Ok(Some(DcdCell {
            lengths,
            angles: angles.map(deg),
        }));
    }
    if u.iter().any(|&v| v < 0.0) || angles.iter().any(|&a| a > 180.0) {
        // Newer CHARMM: symmetric shape matrix [h11, h21, h22, h31, h32, h33].
        let e1 = [u[0], u[1], u[3]];
        let e2 = [u[1], u[2], u[4]];
        let e3 = [u[3], u[4], u[5]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let len = |a: [f64; 3]| dot(a, a).sqrt();
        let angle = |a: [f64; 3], b: [f64; 3]| {
            let c = (dot(a, b) / (len(a) * len(b))).clamp(-1.0, 1.0);
            c.acos().to_degrees()
        };
        let cell = DcdCell {
            lengths: [len(e1), len(e2), len(e3)],
            angles: [angle(e2, e3), angle(e1, e3), angle(e1, e2)],
        };
        if cell.angles.iter().all(|a| a.is_finite()) {
            return Ok(Some(cell));
        }
        return Err(format!("{u:?}"));
    }
    // NAMD 2.5: degrees.
    Ok(Some(DcdCell { lengths, angles }))
}

/// Writes CHARMM-flavour, little-endian DCD files with a unit cell in every frame.
///
/// The header is written with the first frame (which fixes the atom count) and kept current
/// after every frame (NSET, NSTEP; ISTART from the first frame's step, NSAVC and DELTA from the
/// first two frames' steps and times), so the file is complete whenever a frame has been
/// written. The cell is written as lengths and angle cosines (`sin(90° - angle)`, exact for
/// 90°), the NAMD/VMD/MDAnalysis convention; a frame without a cell gets an all-zero record,
/// which readers take as "no cell".
#[derive(Debug)]
pub struct DcdWriter<W> {
    pub(crate) out: W,
    file: Arc<str>,
    n_atoms: usize,
    n_written: usize,
    first: (Option<i64>, Option<f64>),
    nsavc: i64,
    /// The header's DELTA (AKMA units) as last written.
    delta: f32,
    buf: Vec<u8>,
}

fn put_u32(buf: &mut Vec<u8>, v: u32) {
    buf.extend_from_slice(&v.to_le_bytes());
}

/// Byte offset of ICNTRL[k] in a file with 32-bit markers.
fn icntrl_at(k: u64) -> u64 {
    8 + 4 * k
}

impl<W: Write + Seek> DcdWriter<W> {
    /// A DCD writer on `out`; `file` names it in errors.
    pub fn new(out: W, file: Arc<str>) -> Self {
        DcdWriter {
            out,
            file,
            n_atoms: 0,
            n_written: 0,
            first: (None, None),
            nsavc: 1,
            delta: (1.0 / AKMA_PS) as f32,
            buf: Vec::new(),
        }
    }

    /// Writes the header records for `n_atoms` atoms (NSET and friends patched later).
    fn header(&mut self, n_atoms: usize, first_step: i64) -> io::Result<()> {
        let buf = &mut self.buf;
        buf.clear();
        // Header record: "CORD" + ICNTRL.
        put_u32(buf, HEADER_LEN as u32);
        buf.extend_from_slice(b"CORD");
        let mut icntrl = [0u32; 20];
        icntrl[1] = first_step.clamp(0, i32::MAX as i64) as u32; // ISTART
        icntrl[2] = 1; // NSAVC
        icntrl[9] = self.delta.to_bits(); // DELTA: 1 ps until known
        icntrl[10] = 1; // unit cell in every frame
        icntrl[19] = 24; // CHARMM version
        for v in icntrl {
            put_u32(buf, v);
        }
        put_u32(buf, HEADER_LEN as u32);
        // Title record: two 80-byte lines.
        let mut line = [b' '; TITLE_LEN];
        let who = b"REMARKS written by texmap-md-io (CHARMM DCD, cell as cosines)";
        line[..who.len()].copy_from_slice(who);
        put_u32(buf, 4 + TITLE_LEN as u32);
        put_u32(buf, 1);
        buf.extend_from_slice(&line);
        put_u32(buf, 4 + TITLE_LEN as u32);
        // Atom record.
        put_u32(buf, 4);
        put_u32(buf, n_atoms as u32);
        put_u32(buf, 4);
        self.out.write_all(buf)
    }

    /// Appends one frame: positions in Å and an optional cell.
    pub fn write_positions(
        &mut self,
        positions: &[[f32; 3]],
        cell: Option<&DcdCell>,
        step: Option<i64>,
        time: Option<f64>,
    ) -> Result<(), Error> {
        let frame = self.n_written;
        let new_delta = self.delta_after(step, time);
        let invalid = |what: String| Error::InvalidFrame {
            file: self.file.clone(),
            frame,
            what,
        };
        let file = self.file.clone();
        let io = |e| io_error(&file, Some(frame), 0, e);
        if frame == 0 {
            if positions.is_empty() || positions.len() > i32::MAX as usize / 4 {
                return Err(invalid(format!(
                    "{} atoms (DCD needs 1..=2^29)",
                    positions.len()
                )));
            }
        } else if positions.len() != self.n_atoms {
            return Err(invalid(format!(
                "{} atoms, the file has {}",
                positions.len(),
                self.n_atoms
            )));
        }
        if !all_finite(positions) {
            return Err(invalid("a coordinate is NaN or infinite".into()));
        }
        let u = match cell {
            None => [0.0; 6],
            Some(c) => {
                let ok = c.lengths.iter().all(|l| l.is_finite() && *l > 0.0)
                    && c.angles
                        .iter()
                        .all(|a| a.is_finite() && *a > 0.0 && *a < 180.0);
                if !ok {
                    return Err(invalid(format!("unit cell {c:?}")));
                }
                // Cosine as sin(90° - angle): exactly 0 for 90°.
                let cos = |a: f64| (90.0 - a).to_radians().sin();
                let [a, b, c_] = c.lengths;
                let [alpha, beta, gamma] = c.angles;
                [a, cos(gamma), b, cos(beta), cos(alpha), c_]
            }
        };
        if frame == 0 {
            self.header(positions.len(), step.unwrap_or(0))
                .map_err(io)?;
            self.n_atoms = positions.len();
            self.first = (step, time);
        }
        // Assemble the frame: cell record, then X, Y, Z records.
        let buf = &mut self.buf;
        buf.clear();
        put_u32(buf, 48);
        for v in u {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        put_u32(buf, 48);
        let len = 4 * self.n_atoms as u32;
        for axis in 0..3 {
            put_u32(buf, len);
            buf.extend(positions.iter().flat_map(|p| p[axis].to_le_bytes()));
            put_u32(buf, len);
        }
        self.out.write_all(buf).map_err(io)?;
        self.n_written += 1;
        // Keep the header current.
        let mut patch: Vec<(u64, u32)> = Vec::with_capacity(4);
        if frame == 0 {
            // The time step a lone frame implies (time / step), until a second frame tells.
            if let Some(delta) = new_delta {
                self.delta = delta;
                patch.push((icntrl_at(9), delta.to_bits()));
            }
        } else if frame == 1 {
            // Steps per frame and time step from the first two frames.
            if let (Some(s0), Some(s1)) = (self.first.0, step)
                && s1 > s0
                && s1 - s0 <= i64::from(i32::MAX)
            {
                self.nsavc = s1 - s0;
                patch.push((icntrl_at(2), self.nsavc as u32));
            }
            if let Some(delta) = new_delta {
                self.delta = delta;
                patch.push((icntrl_at(9), delta.to_bits()));
            }
        }
        let nstep = (self.n_written as i64 * self.nsavc).min(i64::from(i32::MAX));
        patch.push((icntrl_at(0), self.n_written as u32));
        patch.push((icntrl_at(3), nstep as u32));
        let out = &mut self.out;
        let r: io::Result<()> = (|| {
            let end = out.stream_position()?;
            for (at, v) in patch {
                out.seek(SeekFrom::Start(at))?;
                out.write_all(&v.to_le_bytes())?;
            }
            out.seek(SeekFrom::Start(end))?;
            Ok(())
        })();
        r.map_err(|e| io_error(&self.file, Some(frame), 8, e))
    }

    /// Whether a frame of step `step`, written next, reads back with that step: a DCD stores
    /// the first step (ISTART, at least 0) and the steps between frames (NSAVC, from the first
    /// two frames), so later frames keep theirs only when evenly spaced.
    pub(crate) fn keeps_step(&self, step: i64) -> bool {
        let istart = self.first.0.unwrap_or(0).clamp(0, i64::from(i32::MAX));
        match self.n_written {
            0 => (0..=i64::from(i32::MAX)).contains(&step),
            1 => match self.first.0 {
                Some(s0) if s0 == istart && step > s0 && step - s0 <= i64::from(i32::MAX) => true,
                _ => step == istart + 1,
            },
            k => step == istart + k as i64 * self.nsavc,
        }
    }

    /// The header's DELTA (AKMA units) after writing a frame of `step` and `time` next, if that
    /// frame changes it: the first frame sets time / step (a step above 0), the second
    /// (time₁ − time₀) / (step₁ − step₀); later frames and frames without both leave it.
    fn delta_after(&self, step: Option<i64>, time: Option<f64>) -> Option<f32> {
        let (s, t) = (step?, time?);
        let per_step = match (self.n_written, self.first) {
            (0, _) if s > 0 && s <= i64::from(i32::MAX) => t / s as f64,
            (1, (Some(s0), Some(t0))) if s > s0 && s - s0 <= i64::from(i32::MAX) => {
                (t - t0) / (s - s0) as f64
            }
            _ => return None,
        };
        let delta = (per_step / AKMA_PS) as f32;
        (delta.is_finite() && delta > 0.0).then_some(delta)
    }

    /// Whether a frame of `step` and `time`, written next, reads back with that time: readers
    /// compute step × DELTA, so a DCD keeps times proportional to the steps. The second frame
    /// sets DELTA for the first as well, so its time counts as kept only when the first frame's
    /// still reads back. Times within 10⁻⁶ relative (DELTA is an f32) count as kept.
    pub(crate) fn keeps_time(&self, step: Option<i64>, time: f64) -> bool {
        let k = self.n_written as i64;
        let istart = match self.n_written {
            0 => step.unwrap_or(0),
            _ => self.first.0.unwrap_or(0),
        }
        .clamp(0, i64::from(i32::MAX));
        let read_step = match step {
            Some(s) if !self.keeps_step(s) => return false,
            Some(s) => s,
            None => istart + k * self.nsavc,
        };
        let delta = self.delta_after(step, Some(time)).unwrap_or(self.delta);
        let reads_back = |s: i64, t: f64| {
            let back = s as f64 * (f64::from(delta) * AKMA_PS);
            (back - t).abs() <= 1e-6 * t.abs().max(back.abs())
        };
        reads_back(read_step, time)
            && match (self.n_written, self.first) {
                (1, (s0, Some(t0))) => reads_back(s0.unwrap_or(0).max(0), t0),
                _ => true,
            }
    }

    /// Appends a [`Frame`] (the `Writer` contract): positions, cell lengths and angles, step
    /// and time. Everything else in the frame has no place in DCD.
    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        let cell = frame.cell.map(|c| DcdCell {
            lengths: c.lengths(),
            angles: c.angles(),
        });
        self.write_positions(&frame.positions, cell.as_ref(), frame.step, frame.time)
            .map_err(|e| match e {
                Error::Io { source, .. } => source,
                other => io::Error::new(io::ErrorKind::InvalidInput, other.to_string()),
            })
    }

    /// Ends the file (the `Writer` contract): nothing to add, the stream is flushed.
    pub fn finish(&mut self) -> io::Result<()> {
        self.out.flush()
    }

    /// Frames written so far.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn frame_count(&self) -> usize {
        self.n_written
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
        "test.dcd".into()
    }

    /// A hand-built DCD file: every byte is laid out here, independently of the writer.
    pub(crate) struct Build {
        pub big: bool,
        pub wide: bool,
        pub charmm: bool,
        pub cell: bool,
        pub four_d: bool,
        pub nset: i32,
        pub natom: usize,
        pub free: Vec<i32>,
        pub bytes: Vec<u8>,
    }

    impl Build {
        pub fn new(natom: usize) -> Build {
            Build {
                big: false,
                wide: false,
                charmm: true,
                cell: true,
                four_d: false,
                nset: 0,
                natom,
                free: Vec::new(),
                bytes: Vec::new(),
            }
        }
        fn i32(&mut self, v: i32) {
            let b = if self.big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            };
            self.bytes.extend_from_slice(&b);
        }
        fn marker(&mut self, v: usize) {
            if self.wide {
                let b = if self.big {
                    (v as u64).to_be_bytes()
                } else {
                    (v as u64).to_le_bytes()
                };
                self.bytes.extend_from_slice(&b);
            } else {
                self.i32(v as i32);
            }
        }
        fn record(&mut self, payload: Vec<u8>) {
            self.marker(payload.len());
            self.bytes.extend_from_slice(&payload);
            self.marker(payload.len());
        }
        fn enc_f32(&self, v: f32) -> [u8; 4] {
            if self.big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        }
        fn enc_i32(&self, v: i32) -> [u8; 4] {
            if self.big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        }
        pub fn header(mut self) -> Build {
            let mut p = b"CORD".to_vec();
            let mut ic = [0i32; 20];
            ic[0] = self.nset;
            ic[2] = 10;
            ic[8] = (self.natom
                - if self.free.is_empty() {
                    self.natom
                } else {
                    self.free.len()
                }) as i32;
            if self.charmm {
                ic[9] = 2.0f32.to_bits() as i32;
                ic[10] = self.cell as i32;
                ic[11] = self.four_d as i32;
                ic[19] = 24;
            }
            for v in ic {
                p.extend_from_slice(&self.enc_i32(v));
            }
            self.record(p);
            let mut t = self.enc_i32(1).to_vec();
            let mut line = [b' '; 80];
            line[..5].copy_from_slice(b"hello");
            t.extend_from_slice(&line);
            self.record(t);
            let n = self.enc_i32(self.natom as i32).to_vec();
            self.record(n);
            if !self.free.is_empty() {
                let f: Vec<u8> = self.free.iter().flat_map(|&i| self.enc_i32(i)).collect();
                self.record(f);
            }
            self
        }
        pub fn frame(&mut self, cell: [f64; 6], xyz: &[[f32; 3]]) {
            if self.cell && self.charmm {
                let c: Vec<u8> = cell
                    .iter()
                    .flat_map(|v| {
                        if self.big {
                            v.to_be_bytes()
                        } else {
                            v.to_le_bytes()
                        }
                    })
                    .collect();
                self.record(c);
            }
            let dims = if self.four_d { 4 } else { 3 };
            for k in 0..dims {
                let r: Vec<u8> = xyz
                    .iter()
                    .flat_map(|p| self.enc_f32(if k < 3 { p[k] } else { -1.0 }))
                    .collect();
                self.record(r);
            }
        }
    }

    fn atoms(n: usize, frame: usize) -> Vec<[f32; 3]> {
        (0..n)
            .map(|i| {
                let f = (frame * 100 + i) as f32;
                [f + 0.25, -f * 0.5, f * 2.0 + 1.0]
            })
            .collect()
    }

    fn close(a: f64, b: f64, tol: f64) {
        assert!(
            (a - b).abs() <= tol,
            "expected {b}, actual {a}, tolerance {tol}"
        );
    }

    #[test]
    fn every_flavour_reads_back_the_hand_built_values() {
        for big in [false, true] {
            for wide in [false, true] {
                for four_d in [false, true] {
                    let mut b = Build::new(5);
                    b.big = big;
                    b.wide = wide;
                    b.four_d = four_d;
                    b.nset = 3;
                    let mut b = b.header();
                    for f in 0..3 {
                        b.frame([10.0, 0.0, 20.0, 0.0, 0.0, 30.0], &atoms(5, f));
                    }
                    let mut r = DcdReader::new(Cursor::new(b.bytes), name()).unwrap();
                    assert_eq!(
                        r.info().endian,
                        if big { Endian::Big } else { Endian::Little }
                    );
                    assert_eq!(r.info().wide_markers, wide);
                    assert_eq!(r.info().titles, vec!["hello".to_string()]);
                    close(r.info().timestep_ps, 2.0 * AKMA_PS, 1e-12);
                    assert_eq!(r.frame_count(), 3);
                    assert!(r.truncation().is_none());
                    let mut p = Vec::new();
                    // Out of order on purpose: the index is offset arithmetic.
                    for f in [2, 0, 1] {
                        let c = r.read_frame(f, &mut p).unwrap().unwrap();
                        assert_eq!(p, atoms(5, f));
                        assert_eq!(c.lengths, [10.0, 20.0, 30.0]);
                        assert_eq!(c.angles, [90.0; 3]);
                    }
                }
            }
        }
    }

    #[test]
    fn xplor_layout_has_no_cell() {
        let mut b = Build::new(4);
        b.charmm = false;
        let mut b = b.header();
        b.frame([0.0; 6], &atoms(4, 0));
        let mut r = DcdReader::new(Cursor::new(b.bytes), name()).unwrap();
        assert_eq!(r.info().flavour, DcdFlavour::Xplor);
        let mut p = Vec::new();
        assert_eq!(r.read_frame(0, &mut p).unwrap(), None);
        assert_eq!(p, atoms(4, 0));
    }

    #[test]
    fn fixed_atoms_are_merged_from_the_first_frame() {
        // Atoms 2 and 4 (1-based) are free; 1, 3, 5 fixed.
        let mut b = Build::new(5);
        b.free = vec![2, 4];
        b.big = true;
        let mut b = b.header();
        let f0 = atoms(5, 0);
        b.frame([10.0, 0.0, 10.0, 0.0, 0.0, 10.0], &f0);
        let free1 = [[7.0, 8.0, 9.0], [-1.0, -2.0, -3.0]];
        b.frame([10.0, 0.0, 10.0, 0.0, 0.0, 10.0], &free1);
        let mut r = DcdReader::new(Cursor::new(b.bytes), name()).unwrap();
        assert_eq!(r.info().n_fixed, 3);
        assert_eq!(r.frame_count(), 2);
        let mut p = Vec::new();
        r.read_frame(1, &mut p).unwrap();
        let mut want = f0.clone();
        want[1] = free1[0];
        want[3] = free1[1];
        assert_eq!(p, want);
        r.read_frame(0, &mut p).unwrap();
        assert_eq!(p, f0);
    }

    #[test]
    fn cell_conventions_agree_with_f64_recomputation() {
        // Cosines: alpha 60, beta 70, gamma 80 degrees.
        let (al, be, ga) = (60f64, 70f64, 80f64);
        let u = [
            11.0,
            ga.to_radians().cos(),
            12.0,
            be.to_radians().cos(),
            al.to_radians().cos(),
            13.0,
        ];
        let c = cell_from_charmm(u).unwrap().unwrap();
        assert_eq!(c.lengths, [11.0, 12.0, 13.0]);
        for (a, w) in c.angles.iter().zip([al, be, ga]) {
            close(*a, w, 1e-10);
        }
        // Degrees (NAMD 2.5).
        let c = cell_from_charmm([11.0, ga, 12.0, be, al, 13.0])
            .unwrap()
            .unwrap();
        assert_eq!(c.angles, [al, be, ga]);
        // Shape matrix of a triclinic box: e1 = (a,0,0), e2, e3 symmetric form built by hand:
        // an orthorhombic box with a negative tilt is enough to trigger the matrix branch.
        // (The tilt must be outside [-1, 1], or the values read as cosines.)
        let h = [10.0, -2.0, 10.0, 0.0, 0.0, 10.0];
        let c = cell_from_charmm(h).unwrap().unwrap();
        let l = (104f64).sqrt();
        close(c.lengths[0], l, 1e-12);
        close(c.lengths[1], l, 1e-12);
        close(c.lengths[2], 10.0, 1e-12);
        close(c.angles[2], (-40.0 / 104.0f64).acos().to_degrees(), 1e-10);
        close(c.angles[0], 90.0, 1e-12);
        // All zero: no cell; NaN: error.
        assert_eq!(cell_from_charmm([0.0; 6]).unwrap(), None);
        assert!(cell_from_charmm([f64::NAN, 0.0, 1.0, 0.0, 0.0, 1.0]).is_err());
    }

    #[test]
    fn writer_output_reads_back_exactly() {
        let mut w = DcdWriter::new(Cursor::new(Vec::new()), name());
        let cell = DcdCell {
            lengths: [20.0, 21.0, 22.0],
            angles: [90.0, 100.0, 75.0],
        };
        for f in 0..4 {
            let (step, time) = (Some(100 + 5 * f as i64), Some(0.01 * f as f64));
            w.write_positions(&atoms(7, f), Some(&cell), step, time)
                .unwrap();
        }
        w.write_positions(&atoms(7, 4), None, None, None).unwrap();
        let bytes = w.into_inner().into_inner();
        let mut r = DcdReader::new(Cursor::new(bytes), name()).unwrap();
        assert_eq!(r.info().declared_frames, 5);
        assert_eq!(r.info().steps_per_frame, 5);
        assert_eq!(r.info().first_step, 100);
        close(r.info().timestep_ps, 0.002, 1e-9);
        assert_eq!(r.frame_count(), 5);
        let mut p = Vec::new();
        for f in 0..4 {
            let c = r.read_frame(f, &mut p).unwrap().unwrap();
            assert_eq!(p, atoms(7, f));
            assert_eq!(c.lengths, cell.lengths);
            for (a, w) in c.angles.iter().zip(cell.angles) {
                close(*a, w, 1e-9);
            }
            assert_eq!(c.angles[0], 90.0, "90 degrees must survive exactly");
        }
        assert_eq!(r.read_frame(4, &mut p).unwrap(), None);
    }

    #[test]
    fn writer_rejects_bad_frames() {
        let mut w = DcdWriter::new(Cursor::new(Vec::new()), name());
        assert!(w.write_positions(&[], None, None, None).is_err());
        w.write_positions(&atoms(2, 0), None, None, None).unwrap();
        assert!(matches!(
            w.write_positions(&atoms(3, 0), None, None, None),
            Err(Error::InvalidFrame { .. })
        ));
        assert!(
            w.write_positions(&[[f32::NAN, 0.0, 0.0]; 2], None, None, None)
                .is_err()
        );
        let bad = DcdCell {
            lengths: [1.0, 1.0, 1.0],
            angles: [90.0, 190.0, 90.0],
        };
        assert!(
            w.write_positions(&atoms(2, 0), Some(&bad), None, None)
                .is_err()
        );
        assert_eq!(w.frame_count(), 1);
    }

    #[test]
    fn truncation_keeps_complete_frames_and_names_the_offset() {
        let mut b = Build::new(3);
        b.nset = 4;
        let mut b = b.header();
        for f in 0..4 {
            b.frame([5.0, 0.0, 5.0, 0.0, 0.0, 5.0], &atoms(3, f));
        }
        let full = b.bytes.clone();
        // Cut inside frame 3.
        let cut = full.len() - 7;
        let mut r = DcdReader::new(Cursor::new(full[..cut].to_vec()), name()).unwrap();
        assert_eq!(r.frame_count(), 3);
        let mut p = Vec::new();
        r.read_frame(2, &mut p).unwrap();
        assert_eq!(p, atoms(3, 2));
        let e = r.read_frame(3, &mut p).unwrap_err();
        let at = e.location().unwrap();
        assert_eq!((at.frame, at.byte), (Some(3), Some(cut as u64)));
        // Cut exactly at a frame boundary: NSET tells.
        let (off, _) = r.layout.span(3);
        let r = DcdReader::new(Cursor::new(full[..off as usize].to_vec()), name()).unwrap();
        assert_eq!(r.frame_count(), 3);
        assert!(matches!(r.truncation(), Some(Error::Truncated { .. })));
    }

    #[test]
    fn corrupt_marker_names_frame_and_byte() {
        let mut b = Build::new(3).header();
        for f in 0..2 {
            b.frame([5.0, 0.0, 5.0, 0.0, 0.0, 5.0], &atoms(3, f));
        }
        let mut r = DcdReader::new(Cursor::new(b.bytes.clone()), name()).unwrap();
        let (off, _) = r.layout.span(1);
        // The X record's opening marker sits after the 56-byte cell record.
        let x_marker = off as usize + 56;
        let mut bytes = b.bytes;
        bytes[x_marker] ^= 0x40;
        r = DcdReader::new(Cursor::new(bytes), name()).unwrap();
        let mut p = Vec::new();
        r.read_frame(0, &mut p).unwrap();
        let e = r.read_frame(1, &mut p).unwrap_err();
        let at = e.location().unwrap();
        assert_eq!((at.frame, at.byte), (Some(1), Some(x_marker as u64)));
        assert!(e.to_string().contains("test.dcd"), "{e}");
    }

    #[test]
    fn nan_coordinates_are_an_error() {
        let mut b = Build::new(3).header();
        let mut a = atoms(3, 0);
        a[1][1] = f32::NAN;
        b.frame([5.0, 0.0, 5.0, 0.0, 0.0, 5.0], &a);
        let mut r = DcdReader::new(Cursor::new(b.bytes), name()).unwrap();
        let mut p = Vec::new();
        assert!(matches!(r.read_frame(0, &mut p), Err(Error::Parse { .. })));
    }

    #[test]
    fn not_a_dcd_is_a_parse_error() {
        for bytes in [
            &b""[..],
            b"CORD",
            b"\x54\0\0\0XXXX0000",
            b"hello world, not dcd",
        ] {
            let e = DcdReader::new(Cursor::new(bytes.to_vec()), name()).unwrap_err();
            assert!(
                matches!(e, Error::Parse { .. } | Error::Truncated { .. }),
                "{e}"
            );
        }
    }
}
