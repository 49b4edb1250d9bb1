//! GROMACS TRR trajectories (single or double precision) over `Read + Seek`.
//!
//! # Layout
//! XDR (big-endian). Every frame starts with a header that gives the byte size of each block,
//! so any block can be absent in any frame and the file's precision is told by the sizes:
//!
//! ```text
//! i32 1993   i32 13   i32 12   "GMX_trn_file"
//! i32 ir_size e_size box_size vir_size pres_size top_size sym_size x_size v_size f_size
//! i32 natoms   i32 step   i32 nre   real t (ps)   real lambda
//! [box: 9 real, rows, nm] [virial: 9 real] [pressure: 9 real]
//! [x: natoms x 3 real, nm] [v: natoms x 3 real, nm/ps] [f: natoms x 3 real, kJ/(mol nm)]
//! ```
//! `real` is f32 or f64: 4 or 8 = box_size / 9 (or x_size, v_size, f_size / (3 natoms)).
//! The frame index is built at open time from the headers alone (one seek per frame). Lengths
//! are converted to Å (×10, in the file's precision, then rounded to f32), velocities to Å/ps;
//! forces become the per-atom properties `fx fy fz` in kJ/(mol·Å) (÷10, the unit MDAnalysis
//! gives them), the names ASE and LAMMPS dumps use, so `--arrows f` draws them.
//! A frame without positions (mdrun writes frames of only velocities or only forces when
//! `nstvout` or `nstfout` differ from `nstxout`) is read as a frame of no atoms, since a
//! [`Frame`]'s atoms are its positions; [`crate::Trajectory::without_positions`] then says
//! which blocks it held and for how many atoms, so that a converter names what it drops.
//!
//! # References
//! - GROMACS `trrio.cpp` (`do_trr_frame_header`, `do_trr_frame_data`) and xdrfile `trr_header`
//!   (read, not copied).

use std::io::{self, Read, Seek, SeekFrom};
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, all_finite, all_in_bounds, cell_of, first_out_of_bounds};
use crate::error::{Error, Location};
use crate::frame::{Frame, Property};

/// Magic number of every TRR frame.
pub const MAGIC: i32 = 1993;
/// Bytes of the header before t and lambda.
const FIXED: usize = 24 + 13 * 4;
/// Largest header: fixed part + two f64.
const MAX_HEADER: usize = FIXED + 16;

/// One TRR frame header, checked.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Header {
    /// 4 (single) or 8 (double).
    real: usize,
    natoms: usize,
    step: i64,
    time: f64,
    lambda: f64,
    box_size: usize,
    vir_size: usize,
    pres_size: usize,
    x_size: usize,
    v_size: usize,
    f_size: usize,
}

impl Header {
    fn len(&self) -> usize {
        FIXED + 2 * self.real
    }

    fn frame_size(&self) -> u64 {
        (self.len()
            + self.box_size
            + self.vir_size
            + self.pres_size
            + self.x_size
            + self.v_size
            + self.f_size) as u64
    }
}

/// What a TRR frame holds besides its arrays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrrFrameInfo {
    /// MD step.
    pub step: i64,
    /// Time in ps.
    pub time: f64,
    /// Free-energy coupling parameter λ.
    pub lambda: f64,
    /// Box vectors as rows in Å, if the frame has a box.
    pub box_vectors: Option<[[f64; 3]; 3]>,
    /// The frame has positions (else `positions` was left empty).
    pub has_positions: bool,
    /// The frame has velocities (else `velocities` was left empty).
    pub has_velocities: bool,
    /// The frame has forces (else `forces` was left empty).
    pub has_forces: bool,
    /// True for a double-precision frame.
    pub double: bool,
}

/// Reads a TRR file frame by frame, in any order.
#[derive(Debug)]
pub struct TrrReader<R> {
    src: R,
    file: Arc<str>,
    n_atoms: usize,
    frames: Vec<(u64, Header)>,
    tail: Option<Error>,
    buf: Vec<u8>,
    pos: u64,
    /// The frame `read_next` reads.
    next: usize,
    /// `read_next`'s buffer of forces, before they become properties.
    forces: Vec<[f32; 3]>,
    /// What the frame `read_next` read last held, when it had no positions.
    without_positions: Option<WithoutPositions>,
}

/// What a TRR frame without positions holds (mdrun writes such frames when `nstvout` or
/// `nstfout` differ from `nstxout`): [`crate::Trajectory::without_positions`] tells it for the
/// frame just read, which a [`Frame`] cannot carry (its atoms are its positions).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WithoutPositions {
    /// Atoms of the frame's blocks.
    pub atoms: usize,
    /// The frame has velocities.
    pub velocities: bool,
    /// The frame has forces.
    pub forces: bool,
}

fn be_u32(b: &[u8], at: usize) -> u32 {
    u32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn be_i32(b: &[u8], at: usize) -> i32 {
    be_u32(b, at) as i32
}

fn be_real(b: &[u8], at: usize, real: usize) -> f64 {
    if real == 8 {
        let hi = u64::from(be_u32(b, at));
        let lo = u64::from(be_u32(b, at + 4));
        f64::from_bits((hi << 32) | lo)
    } else {
        f64::from(f32::from_bits(be_u32(b, at)))
    }
}

fn io_error(file: &Arc<str>, frame: usize, byte: u64, source: io::Error) -> Error {
    Error::Io {
        at: Location::binary(file, frame, byte),
        source,
    }
}

/// Parses and checks a header from `h` (which holds at least `FIXED` bytes; `MAX_HEADER` if
/// available). `Ok(None)` means more bytes are needed for t and lambda.
fn parse_header(
    h: &[u8],
    file: &Arc<str>,
    frame: usize,
    offset: u64,
) -> Result<Option<Header>, Error> {
    let parse = |at: usize, expected: &'static str, found: String| Error::Parse {
        at: Location::binary(file, frame, offset + at as u64),
        expected,
        found,
    };
    if be_i32(h, 0) != MAGIC {
        return Err(parse(0, "TRR magic number 1993", be_i32(h, 0).to_string()));
    }
    if be_i32(h, 4) != 13 || be_i32(h, 8) != 12 || &h[12..24] != b"GMX_trn_file" {
        return Err(parse(
            4,
            "version string \"GMX_trn_file\"",
            Error::found(&h[4..24]),
        ));
    }
    // Block sizes, atoms, step.
    let int = |k: usize| be_i32(h, 24 + 4 * k);
    let [ir, e, bx, vir, pres, top, sym, x, v, f, natoms, step, _nre] = std::array::from_fn(int);
    for (k, (s, what)) in [(ir, "ir"), (e, "e"), (top, "top"), (sym, "sym")]
        .into_iter()
        .enumerate()
    {
        if s != 0 {
            let at = [0, 1, 5, 6][k];
            return Err(parse(
                24 + 4 * at,
                "zero size (block never written by GROMACS)",
                format!("{what}_size {s}"),
            ));
        }
    }
    if natoms < 0 || [bx, vir, pres, x, v, f].iter().any(|&s| s < 0) {
        return Err(parse(
            24,
            "non-negative block sizes and atom count",
            format!("{:?}", [bx, vir, pres, x, v, f, natoms]),
        ));
    }
    let natoms = natoms as usize;
    // Tell the precision from the first block that is present.
    let n3 = 3 * natoms;
    let real = if bx > 0 {
        bx as usize / 9
    } else if x > 0 && n3 > 0 {
        x as usize / n3
    } else if v > 0 && n3 > 0 {
        v as usize / n3
    } else if f > 0 && n3 > 0 {
        f as usize / n3
    } else {
        4
    };
    let ok = |s: i32, n: usize| s == 0 || s as usize == n * real;
    if !(real == 4 || real == 8)
        || !ok(bx, 9)
        || !ok(vir, 9)
        || !ok(pres, 9)
        || !ok(x, n3)
        || !ok(v, n3)
        || !ok(f, n3)
    {
        return Err(parse(
            32,
            "block sizes of 9 or 3 x natoms reals of 4 or 8 bytes",
            format!("box {bx}, vir {vir}, pres {pres}, x {x}, v {v}, f {f}, natoms {natoms}"),
        ));
    }
    if h.len() < FIXED + 2 * real {
        return Ok(None);
    }
    let time = be_real(h, FIXED, real);
    let lambda = be_real(h, FIXED + real, real);
    Ok(Some(Header {
        real,
        natoms,
        step: i64::from(step),
        time,
        lambda,
        box_size: bx as usize,
        vir_size: vir as usize,
        pres_size: pres as usize,
        x_size: x as usize,
        v_size: v as usize,
        f_size: f as usize,
    }))
}

impl<R: Read + Seek> TrrReader<R> {
    /// Opens a TRR stream and indexes its frames from their headers.
    ///
    /// A damaged or partial frame stops the index: the frames before it stay readable and
    /// [`TrrReader::truncation`] tells what went wrong where.
    pub fn new(mut src: R, file: Arc<str>) -> Result<Self, Error> {
        let file_len = src
            .seek(SeekFrom::End(0))
            .map_err(|e| io_error(&file, 0, 0, e))?;
        let mut frames: Vec<(u64, Header)> = Vec::new();
        let mut tail = None;
        let mut offset = 0u64;
        let mut head = [0u8; MAX_HEADER];
        while offset < file_len {
            let frame = frames.len();
            let want = ((file_len - offset) as usize).min(MAX_HEADER);
            src.seek(SeekFrom::Start(offset))
                .and_then(|_| src.read_exact(&mut head[..want]))
                .map_err(|e| io_error(&file, frame, offset, e))?;
            let short = || Error::Truncated {
                at: Location::binary(&file, frame, file_len),
                expected: format!("TRR frame header from byte {offset}"),
            };
            if want < FIXED {
                tail = Some(short());
                break;
            }
            let h = match parse_header(&head[..want], &file, frame, offset) {
                Ok(Some(h)) => h,
                Ok(None) => {
                    tail = Some(short());
                    break;
                }
                Err(e) => {
                    tail = Some(e);
                    break;
                }
            };
            let size = h.frame_size();
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
            frames.push((offset, h));
            offset += size;
        }
        if frames.is_empty()
            && let Some(e) = tail
        {
            return Err(e);
        }
        let n_atoms = frames.first().map_or(0, |(_, h)| h.natoms);
        Ok(TrrReader {
            src,
            file,
            n_atoms,
            frames,
            tail,
            buf: Vec::new(),
            pos: u64::MAX,
            next: 0,
            forces: Vec::new(),
            without_positions: None,
        })
    }

    /// Atoms in the first frame (0 for an empty file).
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn n_atoms(&self) -> usize {
        self.n_atoms
    }

    /// The number of complete frames before the end of the file or the first damaged frame.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Reads frame `index`: positions (Å), velocities (Å/ps) and forces (kJ/(mol·Å)) into the
    /// vectors (left empty when the frame lacks them), the rest returned.
    pub fn read_frame(
        &mut self,
        index: usize,
        positions: &mut Vec<[f32; 3]>,
        velocities: &mut Vec<[f32; 3]>,
        forces: &mut Vec<[f32; 3]>,
    ) -> Result<TrrFrameInfo, Error> {
        let Some(&(offset, h)) = self.frames.get(index) else {
            if index == self.frames.len()
                && let Some(e) = &self.tail
            {
                return Err(crate::xtc::clone_error(e));
            }
            return Err(Error::FrameOutOfRange {
                file: self.file.clone(),
                requested: index,
                n_frames: self.frames.len(),
            });
        };
        let size = h.frame_size() as usize;
        if self.pos != offset {
            self.src
                .seek(SeekFrom::Start(offset))
                .map_err(|e| io_error(&self.file, index, offset, e))?;
        }
        self.pos = u64::MAX;
        self.buf.resize(size, 0);
        self.src
            .read_exact(&mut self.buf)
            .map_err(|e| match e.kind() {
                io::ErrorKind::UnexpectedEof => Error::Truncated {
                    at: Location::binary(&self.file, index, offset),
                    expected: format!("{size} bytes of TRR frame"),
                },
                _ => io_error(&self.file, index, offset, e),
            })?;
        self.pos = offset + size as u64;
        // Check the header again: the file may have changed since indexing.
        let again = parse_header(&self.buf, &self.file, index, offset)?;
        if again != Some(h) {
            return Err(Error::Parse {
                at: Location::binary(&self.file, index, offset),
                expected: "the frame header seen when indexing",
                found: format!("{again:?}"),
            });
        }

        // Box, skipping virial and pressure.
        let r = h.real;
        let mut p = h.len();
        let box_vectors = if h.box_size > 0 {
            let mut m = [[0.0; 3]; 3];
            for (k, v) in m.as_flattened_mut().iter_mut().enumerate() {
                *v = be_real(&self.buf, p + r * k, r) * 10.0;
            }
            if !m.as_flattened().iter().all(|v| v.is_finite()) {
                return Err(Error::Parse {
                    at: Location::binary(&self.file, index, offset + p as u64),
                    expected: "finite box vectors",
                    found: format!("{m:?}"),
                });
            }
            Some(m)
        } else {
            None
        };
        p += h.box_size + h.vir_size + h.pres_size;
        // Positions and velocities, nm → Å; forces, per nm → per Å.
        for (size, out, what, per_nm) in [
            (h.x_size, &mut *positions, IN_BOUNDS, false),
            (h.v_size, &mut *velocities, "finite velocities", false),
            (h.f_size, &mut *forces, "finite forces", true),
        ] {
            out.clear();
            if size == 0 {
                continue;
            }
            let bytes = &self.buf[p..p + size];
            if r == 8 {
                convert::<8>(bytes, per_nm, out);
            } else {
                convert::<4>(bytes, per_nm, out);
            }
            let ok = if what == IN_BOUNDS {
                all_in_bounds(out)
            } else {
                all_finite(out)
            };
            if !ok {
                let bad = if what == IN_BOUNDS {
                    first_out_of_bounds(out)
                } else {
                    out.iter().position(|v| !v.iter().all(|c| c.is_finite()))
                }
                .unwrap_or(0);
                return Err(Error::Parse {
                    at: Location::binary(&self.file, index, offset + (p + 3 * r * bad) as u64),
                    expected: what,
                    found: format!("atom {bad}: {:?}", out[bad]),
                });
            }
            p += size;
        }
        Ok(TrrFrameInfo {
            step: h.step,
            time: h.time,
            lambda: h.lambda,
            box_vectors,
            has_positions: h.x_size > 0,
            has_velocities: h.v_size > 0,
            has_forces: h.f_size > 0,
            double: r == 8,
        })
    }

    /// Reads the next frame into `frame` (the `Trajectory` contract). `Ok(false)` after the
    /// last frame; on error the frame is left empty and the reader stays at the damaged frame.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        self.without_positions = None;
        let index = self.next;
        if index >= self.frames.len() && self.tail.is_none() {
            return Ok(false);
        }
        let mut forces = std::mem::take(&mut self.forces);
        let r = self
            .read_frame(
                index,
                &mut frame.positions,
                &mut frame.velocities,
                &mut forces,
            )
            .and_then(|info| {
                let offset = self.frames[index].0;
                frame.step = Some(info.step);
                frame.time = Some(info.time);
                if !info.has_positions {
                    // Velocities or forces without positions would break the frame's
                    // invariant: the frame has no atoms, and `without_positions` says what
                    // it held.
                    self.without_positions = Some(WithoutPositions {
                        atoms: frame.velocities.len().max(forces.len()),
                        velocities: info.has_velocities,
                        forces: info.has_forces,
                    });
                    frame.velocities.clear();
                } else if info.has_forces {
                    for (d, name) in ["fx", "fy", "fz"].into_iter().enumerate() {
                        frame.properties.push(Property {
                            name: name.into(),
                            values: forces.iter().map(|f| f[d]).collect(),
                        });
                    }
                }
                match info.box_vectors {
                    Some(m) => cell_of(
                        m,
                        &self.file,
                        index,
                        offset + (FIXED + 2 * if info.double { 8 } else { 4 }) as u64,
                    ),
                    None => Ok(None),
                }
            });
        self.forces = forces;
        crate::cursor::settle(r, frame, &mut self.next)
    }

    /// What the frame read last held when it had no positions (else `None`).
    pub fn without_positions(&self) -> Option<WithoutPositions> {
        self.without_positions
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
            Some(e) => Err(crate::xtc::clone_error(e)),
            None => Ok(self.frames.len()),
        }
    }
}

/// Big-endian reals (4 or 8 bytes) to f32 triples: lengths in nm to Å (×10), or, with
/// `per_nm`, quantities per nm to per Å (÷10, correctly rounded: 0.1 has no exact binary
/// form). Precision chosen outside the loop, output written in place: no per-atom push.
fn convert<const REAL: usize>(bytes: &[u8], per_nm: bool, out: &mut Vec<[f32; 3]>) {
    out.resize(bytes.len() / (3 * REAL), [0.0; 3]);
    for (o, c) in out.iter_mut().zip(bytes.chunks_exact(3 * REAL)) {
        *o = std::array::from_fn(|d| {
            let b = &c[d * REAL..];
            if REAL == 8 {
                let v = f64::from_be_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]);
                (if per_nm { v / 10.0 } else { v * 10.0 }) as f32
            } else {
                let v = f32::from_be_bytes([b[0], b[1], b[2], b[3]]);
                if per_nm { v / 10.0 } else { v * 10.0 }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn name() -> Arc<str> {
        "test.trr".into()
    }

    /// A hand-built TRR frame: every byte laid out here.
    fn frame(
        double: bool,
        natoms: usize,
        step: i32,
        bx: Option<[f64; 9]>,
        x: Option<&[f64]>,
        v: Option<&[f64]>,
        f: Option<&[f64]>,
    ) -> Vec<u8> {
        let r = if double { 8 } else { 4 };
        let mut b = Vec::new();
        let int = |b: &mut Vec<u8>, v: i32| b.extend_from_slice(&v.to_be_bytes());
        let real = |b: &mut Vec<u8>, v: f64| {
            if double {
                b.extend_from_slice(&v.to_be_bytes())
            } else {
                b.extend_from_slice(&(v as f32).to_be_bytes())
            }
        };
        int(&mut b, 1993);
        int(&mut b, 13);
        int(&mut b, 12);
        b.extend_from_slice(b"GMX_trn_file");
        let n3 = (3 * natoms * r) as i32;
        let sizes = [
            0,
            0,
            if bx.is_some() { 9 * r as i32 } else { 0 },
            0,
            0,
            0,
            0,
            if x.is_some() { n3 } else { 0 },
            if v.is_some() { n3 } else { 0 },
            if f.is_some() { n3 } else { 0 },
        ];
        for s in sizes {
            int(&mut b, s);
        }
        int(&mut b, natoms as i32);
        int(&mut b, step);
        int(&mut b, 0);
        real(&mut b, f64::from(step) * 0.002);
        real(&mut b, 0.5);
        for block in [bx.as_ref().map(|a| &a[..]), x, v, f].into_iter().flatten() {
            for &val in block {
                real(&mut b, val);
            }
        }
        b
    }

    fn values(n: usize, seed: f64) -> Vec<f64> {
        (0..3 * n).map(|i| seed + i as f64 * 0.125 - 1.0).collect()
    }

    #[test]
    fn single_and_double_with_missing_blocks() {
        for double in [false, true] {
            let n = 4;
            let bx = [3.0, 0.0, 0.0, 0.0, 3.5, 0.0, 0.5, 0.25, 4.0];
            let mut bytes = Vec::new();
            let (x0, v0, f0) = (values(n, 1.0), values(n, 2.0), values(n, 3.0));
            bytes.extend(frame(
                double,
                n,
                0,
                Some(bx),
                Some(&x0),
                Some(&v0),
                Some(&f0),
            ));
            bytes.extend(frame(double, n, 10, None, Some(&x0), None, None));
            bytes.extend(frame(double, n, 20, Some(bx), None, Some(&v0), None));
            bytes.extend(frame(double, n, 30, None, None, None, Some(&f0)));
            let mut r = TrrReader::new(Cursor::new(bytes), name()).unwrap();
            assert_eq!(r.frame_count(), 4);
            assert_eq!(r.n_atoms(), n);
            let (mut p, mut v, mut f) = (Vec::new(), Vec::new(), Vec::new());
            let want = |vals: &[f64]| -> Vec<[f32; 3]> {
                vals.chunks(3)
                    .map(|c| {
                        std::array::from_fn(|d| {
                            if double {
                                (c[d] * 10.0) as f32
                            } else {
                                (c[d] as f32) * 10.0
                            }
                        })
                    })
                    .collect()
            };
            let i = r.read_frame(2, &mut p, &mut v, &mut f).unwrap();
            assert_eq!(
                (i.step, i.double, i.has_positions, i.has_velocities),
                (20, double, false, true)
            );
            assert!(p.is_empty());
            assert_eq!(v, want(&v0));
            assert_eq!(i.box_vectors.unwrap()[2], [5.0, 2.5, 40.0]);
            assert!(f.is_empty());
            let i = r.read_frame(0, &mut p, &mut v, &mut f).unwrap();
            assert!(i.has_forces);
            assert_eq!(p, want(&x0));
            assert_eq!(v, want(&v0));
            // Forces per nm become per Å: divided by 10, correctly rounded.
            let per_a: Vec<[f32; 3]> = f0
                .chunks(3)
                .map(|c| {
                    std::array::from_fn(|d| {
                        if double {
                            (c[d] / 10.0) as f32
                        } else {
                            (c[d] as f32) / 10.0
                        }
                    })
                })
                .collect();
            assert_eq!(f, per_a);
            assert_eq!(f[0], [0.2, 0.2125, 0.225]);
            // The frame carries them as fx fy fz.
            let mut fr = Frame::new();
            assert!(r.seek_frame(0).unwrap());
            assert!(r.read_next(&mut fr).unwrap());
            assert_eq!(fr.property("fy").unwrap()[1], per_a[1][1]);
            assert_eq!(fr.properties.len(), 3);
            assert!(r.read_next(&mut fr).unwrap());
            assert!(fr.properties.is_empty(), "frame 1 has no forces");
            let i = r.read_frame(1, &mut p, &mut v, &mut Vec::new()).unwrap();
            assert_eq!(i.box_vectors, None);
            assert!(v.is_empty());
            assert_eq!(p, want(&x0));
            let i = r.read_frame(3, &mut p, &mut v, &mut Vec::new()).unwrap();
            assert!(p.is_empty() && v.is_empty() && i.has_forces);
            let tol = if double { 1e-12 } else { 1e-6 };
            assert!(
                (i.time - 0.06).abs() < tol,
                "expected 0.06, actual {}, tolerance {tol}",
                i.time
            );
        }
    }

    #[test]
    fn damage_never_panics_and_keeps_earlier_frames() {
        let n = 3;
        let x = values(n, 1.0);
        let bx = [3.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 3.0];
        let mut bytes = Vec::new();
        let mut ends = Vec::new();
        for k in 0..3 {
            bytes.extend(frame(k == 1, n, k, Some(bx), Some(&x), Some(&x), None));
            ends.push(bytes.len() as u64);
        }
        for cut in 0..bytes.len() {
            let complete = ends.iter().filter(|&&e| e <= cut as u64).count();
            match TrrReader::new(Cursor::new(bytes[..cut].to_vec()), name()) {
                Ok(mut r) => {
                    assert_eq!(r.frame_count(), complete, "cut at {cut}");
                    let (mut p, mut v) = (Vec::new(), Vec::new());
                    for f in 0..complete {
                        r.read_frame(f, &mut p, &mut v, &mut Vec::new()).unwrap();
                    }
                    if cut > 0 && !ends.contains(&(cut as u64)) {
                        let e = r
                            .read_frame(complete, &mut p, &mut v, &mut Vec::new())
                            .unwrap_err();
                        let at = e.location().unwrap();
                        assert_eq!(
                            (at.frame, at.byte),
                            (Some(complete), Some(cut as u64)),
                            "{e}"
                        );
                    }
                }
                Err(e) => {
                    assert_eq!(complete, 0, "{e}");
                    assert_eq!(e.location().unwrap().byte, Some(cut as u64), "{e}");
                }
            }
        }
        for at in 0..bytes.len() {
            for bit in [0x01u8, 0x80] {
                let mut b = bytes.clone();
                b[at] ^= bit;
                if let Ok(mut r) = TrrReader::new(Cursor::new(b), name()) {
                    let (mut p, mut v) = (Vec::new(), Vec::new());
                    for f in 0..r.frame_count() + 1 {
                        let _ = r.read_frame(f, &mut p, &mut v, &mut Vec::new());
                    }
                }
            }
        }
    }

    #[test]
    fn corrupt_size_names_the_byte() {
        let x = values(2, 0.0);
        let mut bytes = frame(false, 2, 0, None, Some(&x), None, None);
        bytes.extend(frame(false, 2, 1, None, Some(&x), None, None));
        let second = bytes.len() / 2;
        bytes[second + 24 + 4 * 7 + 3] ^= 0x04; // x_size of frame 1
        let mut r = TrrReader::new(Cursor::new(bytes), name()).unwrap();
        assert_eq!(r.frame_count(), 1);
        let e = r
            .read_frame(1, &mut Vec::new(), &mut Vec::new(), &mut Vec::new())
            .unwrap_err();
        let at = e.location().unwrap();
        assert_eq!(
            (at.frame, at.byte),
            (Some(1), Some(second as u64 + 32)),
            "{e}"
        );
    }
}
