//! AMBER NetCDF trajectories (`.nc`, `.ncdf`): our own reader of the NetCDF-3 container
//! (classic `CDF\x01` and 64-bit offset `CDF\x02`) and of the AMBER convention inside it.
//!
//! # The container (NetCDF classic format specification, Unidata)
//! A big-endian header: magic, `numrecs`, then three lists (dimensions, global attributes,
//! variables), each absent or a tag (`0x0A`, `0x0C`, `0x0B`) and a count. A name is a length and
//! bytes padded to 4. A variable gives its dimension ids, its attributes, its type, its size and
//! its `begin` offset (32-bit in CDF-1, 64-bit in CDF-2). Variables whose first dimension is the
//! unlimited (record) dimension are stored interleaved: record `k` of variable `v` is at
//! `v.begin + k · recsize`, `recsize` being the sum of one record of every record variable
//! (each padded to 4 bytes, unless there is only one record variable).
//!
//! # The AMBER convention (ambermd.org/netcdf/nctraj.xhtml)
//! Global `Conventions` contains `AMBER`; dimensions `frame` (unlimited), `atom`, `spatial` (3);
//! `coordinates(frame, atom, spatial)` float Å, optional `time(frame)` float ps,
//! `cell_lengths(frame, cell_spatial)` and `cell_angles(frame, cell_angular)` double Å and
//! degrees, optional `velocities(frame, atom, spatial)` float. A `scale_factor` attribute
//! multiplies a variable's values (AMBER velocities carry 20.455, which turns them into Å/ps).
//!
//! A restart (global `Conventions` `AMBERRESTART`, which pmemd writes with `ntxo = 2`, its
//! default) is one frame: the same variables without the `frame` dimension, coordinates and
//! velocities in double precision, `time` a scalar (or a one-element `time(time)`, as ParmEd
//! writes it).
//!
//! # Why our own reader
//! The `netcdf3` crate reads a whole variable at once (every frame of `coordinates`), which is
//! the opposite of streaming one frame with memory of one frame; the format is small (the header
//! is a few lists), so this module reads exactly the bytes of one record of the variables it
//! needs, at offsets computed from the header: random access costs one seek per variable.
//!
//! # Trust
//! Every count in the header is checked against the bytes the file has left before anything is
//! sized from it, every `begin` and the records must lie inside the file; a file shorter than
//! `numrecs` records is [`Error::Truncated`] for the first incomplete frame.

use std::io::{self, Read, Seek, SeekFrom};
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, all_in_bounds, first_out_of_bounds};
use crate::error::{Error, Location};
use crate::frame::{Frame, UnitCell};

/// NetCDF external types (`nc_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum NcType {
    Byte,
    Char,
    Short,
    Int,
    Float,
    Double,
}

impl NcType {
    fn from_code(c: u32) -> Option<NcType> {
        Some(match c {
            1 => NcType::Byte,
            2 => NcType::Char,
            3 => NcType::Short,
            4 => NcType::Int,
            5 => NcType::Float,
            6 => NcType::Double,
            _ => return None,
        })
    }

    fn size(self) -> u64 {
        match self {
            NcType::Byte | NcType::Char => 1,
            NcType::Short => 2,
            NcType::Int | NcType::Float => 4,
            NcType::Double => 8,
        }
    }
}

/// One variable of the header.
#[derive(Clone, Debug)]
struct Var {
    name: Vec<u8>,
    dims: Vec<usize>,
    ty: NcType,
    begin: u64,
    /// Bytes of one record (record variables) or of the whole variable.
    size: u64,
    record: bool,
    scale: Option<f64>,
}

/// An attribute: name, type and raw big-endian values.
type Attribute = (Vec<u8>, NcType, Vec<u8>);

/// Reads the header from a byte stream, never past `len`.
struct Header<'a, R> {
    src: &'a mut R,
    pos: u64,
    len: u64,
    file: &'a Arc<str>,
}

impl<R: Read> Header<'_, R> {
    fn err(&self, expected: &'static str, found: String) -> Error {
        Error::Parse {
            at: Location {
                byte: Some(self.pos),
                ..Location::file(self.file)
            },
            expected,
            found,
        }
    }

    fn bytes(&mut self, n: u64, what: &str) -> Result<Vec<u8>, Error> {
        if n > self.len.saturating_sub(self.pos) {
            return Err(Error::Truncated {
                at: Location {
                    byte: Some(self.pos),
                    ..Location::file(self.file)
                },
                expected: format!("{n} bytes of {what} in the NetCDF header"),
            });
        }
        let mut b = vec![0u8; n as usize];
        self.src.read_exact(&mut b).map_err(|source| Error::Io {
            at: Location {
                byte: Some(self.pos),
                ..Location::file(self.file)
            },
            source,
        })?;
        self.pos += n;
        Ok(b)
    }

    fn u32(&mut self, what: &str) -> Result<u32, Error> {
        let b = self.bytes(4, what)?;
        Ok(u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u64(&mut self, what: &str) -> Result<u64, Error> {
        let b = self.bytes(8, what)?;
        Ok(u64::from_be_bytes(b.try_into().unwrap_or([0; 8])))
    }

    /// A count of items each at least `min` bytes long, checked against the bytes left.
    fn count(&mut self, min: u64, what: &'static str) -> Result<usize, Error> {
        let at = self.pos;
        let n = self.u32(what)? as u64;
        if n.saturating_mul(min) > self.len.saturating_sub(self.pos) {
            self.pos = at;
            return Err(self.err(what, format!("{n}, more than the file's bytes can hold")));
        }
        Ok(n as usize)
    }

    fn padded(&mut self, n: u64, what: &str) -> Result<Vec<u8>, Error> {
        let b = self.bytes(n, what)?;
        let pad = (4 - n % 4) % 4;
        self.bytes(pad, what)?;
        Ok(b)
    }

    fn name(&mut self) -> Result<Vec<u8>, Error> {
        let n = self.count(1, "a name length")? as u64;
        self.padded(n, "a name")
    }

    /// A list's tag and count; `None` for an absent list (two zero words).
    fn list(&mut self, tag: u32, min: u64, what: &'static str) -> Result<usize, Error> {
        let at = self.pos;
        let t = self.u32(what)?;
        if t == 0 {
            let n = self.u32(what)?;
            if n != 0 {
                self.pos = at;
                return Err(self.err(what, format!("absent list with count {n}")));
            }
            return Ok(0);
        }
        if t != tag {
            self.pos = at;
            return Err(self.err(what, format!("tag {t:#x}")));
        }
        self.count(min, what)
    }

    /// An attribute list: (name, type, values) for each.
    fn attributes(&mut self) -> Result<Vec<Attribute>, Error> {
        let n = self.list(0x0C, 12, "an attribute list (tag 0x0C)")?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let name = self.name()?;
            let at = self.pos;
            let code = self.u32("an attribute type")?;
            let ty = NcType::from_code(code).ok_or_else(|| {
                self.pos = at;
                self.err("a NetCDF type code 1-6", code.to_string())
            })?;
            let count = self.count(ty.size(), "an attribute value count")? as u64;
            let values = self.padded(count * ty.size(), "attribute values")?;
            out.push((name, ty, values));
        }
        Ok(out)
    }
}

/// A number from an attribute's values (the first one), as f64.
fn attr_number(ty: NcType, v: &[u8]) -> Option<f64> {
    Some(match ty {
        NcType::Float => f32::from_be_bytes(v.get(..4)?.try_into().ok()?) as f64,
        NcType::Double => f64::from_be_bytes(v.get(..8)?.try_into().ok()?),
        NcType::Int => i32::from_be_bytes(v.get(..4)?.try_into().ok()?) as f64,
        NcType::Short => i16::from_be_bytes(v.get(..2)?.try_into().ok()?) as f64,
        _ => return None,
    })
}

/// Where the variables the reader needs are, and how the records are laid out.
#[derive(Clone, Debug)]
struct Layout {
    /// Records `numrecs` claims.
    declared: usize,
    /// Records wholly inside the file.
    complete: usize,
    recsize: u64,
    file_len: u64,
    coords: Var,
    velocities: Option<Var>,
    time: Option<Var>,
    lengths: Option<Var>,
    angles: Option<Var>,
}

/// Streaming reader of an AMBER NetCDF trajectory (the `Trajectory` contract in lib.rs).
pub(crate) struct NetcdfReader<R> {
    src: R,
    file: Arc<str>,
    layout: Layout,
    next: usize,
    buf: Vec<u8>,
}

impl<R: Read + Seek> NetcdfReader<R> {
    /// Reads and checks the header.
    pub fn new(mut src: R, file: Arc<str>) -> Result<Self, Error> {
        let io = |source: io::Error| Error::Io {
            at: Location::file(&file),
            source,
        };
        let file_len = src.seek(SeekFrom::End(0)).map_err(io)?;
        src.seek(SeekFrom::Start(0)).map_err(io)?;
        let layout = {
            let mut h = Header {
                src: &mut src,
                pos: 0,
                len: file_len,
                file: &file,
            };
            read_layout(&mut h)?
        };
        Ok(NetcdfReader {
            src,
            file,
            layout,
            next: 0,
            buf: Vec::new(),
        })
    }

    /// The first frame that cannot be read because the file ends early, if any.
    fn truncation(&self) -> Option<Error> {
        let l = &self.layout;
        if l.complete < l.declared {
            let start = l.coords.begin.min(l.file_len) + l.complete as u64 * l.recsize;
            Some(Error::Truncated {
                at: Location::binary(&self.file, l.complete, l.file_len),
                expected: format!(
                    "{} records declared by the header (numrecs), the file holds {} (record {} of {} bytes would start at byte {start})",
                    l.declared, l.complete, l.complete, l.recsize
                ),
            })
        } else {
            None
        }
    }

    /// Reads one record of `var` (frame `index`) into `self.buf`; returns its byte offset.
    fn read_record(&mut self, var: &Var, index: usize) -> Result<u64, Error> {
        let off = var.begin + index as u64 * self.layout.recsize;
        let n = var.size as usize;
        self.buf.resize(n, 0);
        let file = &self.file;
        let at = |byte| Location::binary(file, index, byte);
        self.src
            .seek(SeekFrom::Start(off))
            .map_err(|source| Error::Io {
                at: at(off),
                source,
            })?;
        match self.src.read_exact(&mut self.buf) {
            Ok(()) => Ok(off),
            Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Err(Error::Truncated {
                at: at(off),
                expected: format!(
                    "{n} bytes of variable {}",
                    String::from_utf8_lossy(&var.name)
                ),
            }),
            Err(source) => Err(Error::Io {
                at: at(off),
                source,
            }),
        }
    }

    /// Reads record `index` into `frame`; gives its cell.
    fn read_frame(&mut self, index: usize, frame: &mut Frame) -> Result<Option<UnitCell>, Error> {
        let l = self.layout.clone();
        // Coordinates.
        let off = self.read_record(&l.coords, index)?;
        frame.positions.clear();
        vectors(&l.coords, &self.buf, &mut frame.positions);
        if !all_in_bounds(&frame.positions) {
            let bad = first_out_of_bounds(&frame.positions).unwrap_or(0);
            return Err(Error::Parse {
                at: Location::binary(&self.file, index, off + 3 * l.coords.ty.size() * bad as u64),
                expected: IN_BOUNDS,
                found: format!("atom {bad}: {:?}", frame.positions[bad]),
            });
        }
        if let Some(v) = &l.velocities {
            let off = self.read_record(v, index)?;
            frame.velocities.clear();
            vectors(v, &self.buf, &mut frame.velocities);
            if let Some(bad) = frame
                .velocities
                .iter()
                .position(|p| !p.iter().all(|x| x.is_finite()))
            {
                return Err(Error::Parse {
                    at: Location::binary(&self.file, index, off + 3 * v.ty.size() * bad as u64),
                    expected: "finite velocities",
                    found: format!("atom {bad}: {:?}", frame.velocities[bad]),
                });
            }
        }
        if let Some(v) = &l.time {
            let off = self.read_record(v, index)?;
            let t = read_number(v.ty, &self.buf, 0).unwrap_or(f64::NAN) * v.scale.unwrap_or(1.0);
            if !t.is_finite() {
                return Err(Error::Parse {
                    at: Location::binary(&self.file, index, off),
                    expected: "a finite time",
                    found: t.to_string(),
                });
            }
            frame.time = Some(t);
        }
        if let (Some(lv), Some(av)) = (&l.lengths, &l.angles) {
            let off = self.read_record(lv, index)?;
            let lengths = three(lv.ty, &self.buf);
            self.read_record(av, index)?;
            let angles = three(av.ty, &self.buf);
            // An all-zero cell means none (as AMBER writes for non-periodic runs).
            if lengths.iter().any(|x| *x != 0.0) {
                let cell =
                    UnitCell::from_lengths_angles(lengths, angles).map_err(|e| Error::Parse {
                        at: Location::binary(&self.file, index, off),
                        expected: "cell_lengths and cell_angles of a cell with volume > 0",
                        found: e.to_string(),
                    })?;
                return Ok(Some(cell));
            }
        }
        Ok(None)
    }

    /// Reads the next frame (the `Trajectory` contract).
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        let index = self.next;
        let complete = self.layout.complete;
        if let Some(end) = crate::cursor::past_complete(index, complete, || self.truncation()) {
            return end;
        }
        let read = self.read_frame(index, frame);
        crate::cursor::settle(read, frame, &mut self.next)
    }

    /// Makes `read_next` read frame `n` (a cut frame counts as present).
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        let damaged = self.truncation().is_some();
        Ok(crate::cursor::seek(
            &mut self.next,
            n,
            self.layout.complete,
            damaged,
        ))
    }

    /// Number of frames; a file shorter than `numrecs` records is that frame's error.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        match self.truncation() {
            Some(e) => Err(e),
            None => Ok(self.layout.complete),
        }
    }
}

/// One record of a float or double `(atom, 3)` variable as f32 vectors, times its scale factor.
fn vectors(v: &Var, buf: &[u8], out: &mut Vec<[f32; 3]>) {
    let s = v.ty.size() as usize;
    match v.ty {
        NcType::Double => {
            let scale = v.scale.unwrap_or(1.0);
            out.extend(buf.chunks_exact(3 * s).map(|c| {
                std::array::from_fn(|k| {
                    let b: [u8; 8] = c[k * 8..k * 8 + 8].try_into().unwrap_or([0; 8]);
                    (f64::from_be_bytes(b) * scale) as f32
                })
            }));
        }
        _ => {
            let scale = v.scale.unwrap_or(1.0) as f32;
            out.extend(buf.chunks_exact(3 * s).map(|c| {
                std::array::from_fn(|k| {
                    let b: [u8; 4] = c[k * 4..k * 4 + 4].try_into().unwrap_or([0; 4]);
                    f32::from_be_bytes(b) * scale
                })
            }));
        }
    }
}

fn read_number(ty: NcType, b: &[u8], k: usize) -> Option<f64> {
    let s = ty.size() as usize;
    attr_number(ty, b.get(k * s..(k + 1) * s)?)
}

fn three(ty: NcType, b: &[u8]) -> [f64; 3] {
    std::array::from_fn(|k| read_number(ty, b, k).unwrap_or(f64::NAN))
}

/// Parses the header and finds the AMBER variables.
fn read_layout<R: Read>(h: &mut Header<'_, R>) -> Result<Layout, Error> {
    let magic = h.bytes(4, "the magic number")?;
    let offset64 = match magic.as_slice() {
        b"CDF\x01" => false,
        b"CDF\x02" => true,
        [b'C', b'D', b'F', 5] => {
            h.pos = 3;
            return Err(h.err(
                "NetCDF-3 version 1 or 2 (CDF-5, 64-bit data, is not used for AMBER trajectories)",
                "version 5".into(),
            ));
        }
        _ => {
            h.pos = 0;
            return Err(h.err(
                "the NetCDF-3 magic number 'CDF\\x01' or 'CDF\\x02' (NetCDF-4/HDF5 files are not read)",
                Error::found(&magic),
            ));
        }
    };
    let numrecs = h.u32("numrecs")?;
    // Dimensions.
    let n_dims = h.list(0x0A, 8, "a dimension list (tag 0x0A)")?;
    let mut dims: Vec<(Vec<u8>, u64)> = Vec::with_capacity(n_dims);
    let mut record_dim = None;
    for k in 0..n_dims {
        let name = h.name()?;
        let len = h.u32("a dimension length")? as u64;
        if len == 0 {
            record_dim = Some(k);
        }
        dims.push((name, len));
    }
    let globals = h.attributes()?;
    let amber = globals.iter().any(|(n, _, v)| {
        n == b"Conventions" && v.windows(5).any(|w| w.eq_ignore_ascii_case(b"AMBER"))
    });
    if !amber {
        return Err(h.err(
            "a global attribute Conventions naming AMBER (an AMBER trajectory)",
            "none".into(),
        ));
    }
    // Variables.
    let n_vars = h.list(0x0B, 24, "a variable list (tag 0x0B)")?;
    let mut vars = Vec::with_capacity(n_vars);
    for _ in 0..n_vars {
        let name = h.name()?;
        let rank = h.count(4, "a variable's dimension count")?;
        let mut ids = Vec::with_capacity(rank);
        for _ in 0..rank {
            let at = h.pos;
            let d = h.u32("a dimension id")? as usize;
            if d >= dims.len() {
                h.pos = at;
                return Err(h.err("a dimension id of the dimension list", d.to_string()));
            }
            ids.push(d);
        }
        let attrs = h.attributes()?;
        let at = h.pos;
        let code = h.u32("a variable type")?;
        let ty = NcType::from_code(code).ok_or_else(|| {
            h.pos = at;
            h.err("a NetCDF type code 1-6", code.to_string())
        })?;
        let _vsize = h.u32("a variable size")?;
        let begin = if offset64 {
            h.u64("a variable offset")?
        } else {
            h.u32("a variable offset")? as u64
        };
        let record = ids.first().is_some_and(|d| Some(*d) == record_dim);
        // The size from the dimensions (vsize saturates for large variables).
        let mut size = ty.size();
        for (k, d) in ids.iter().enumerate() {
            if k == 0 && record {
                continue;
            }
            size = size.saturating_mul(dims[*d].1);
        }
        let scale = attrs
            .iter()
            .find(|(n, _, _)| n == b"scale_factor")
            .and_then(|(_, t, v)| attr_number(*t, v));
        if begin > h.len || (!record && size > h.len - begin) {
            return Err(h.err(
                "a variable lying inside the file",
                format!(
                    "{} at byte {begin}, {size} bytes, file of {} bytes",
                    String::from_utf8_lossy(&name),
                    h.len
                ),
            ));
        }
        vars.push(Var {
            name,
            dims: ids,
            ty,
            begin,
            size,
            record,
            scale,
        });
    }
    let header_end = h.pos;
    let find = |n: &[u8]| vars.iter().find(|v| v.name == n).cloned();
    let Some(coords) = find(b"coordinates") else {
        return Err(h.err("a variable named coordinates", "none".into()));
    };
    let dim_name = |d: usize| dims[d].0.as_slice();
    // A restart (the AMBERRESTART convention) is one frame: no record dimension, so its
    // variables lack the leading `frame`.
    let restart = !coords.record;
    let lead = usize::from(!restart);
    let numeric = |v: &Var| matches!(v.ty, NcType::Float | NcType::Double);
    let shape_ok = |v: &Var, last: &[u8]| {
        v.record != restart
            && v.dims.len() == 2 + lead
            && dim_name(v.dims[lead]) == b"atom"
            && dim_name(v.dims[lead + 1]) == last
            && dims[v.dims[lead + 1]].1 == 3
            && numeric(v)
    };
    if !shape_ok(&coords, b"spatial") {
        return Err(h.err(
            "coordinates(frame, atom, spatial = 3), or (atom, spatial = 3) in a restart, of type float or double",
            format!("{} dimensions of type {:?}", coords.dims.len(), coords.ty),
        ));
    }
    let velocities = find(b"velocities").filter(|v| shape_ok(v, b"spatial"));
    // A restart's time is a scalar, or (as ParmEd writes it) `time(time = 1)`.
    let scalar =
        |v: &Var| v.dims.len() == lead || (restart && v.dims.len() == 1 && v.size == v.ty.size());
    let time = find(b"time").filter(|v| v.record != restart && scalar(v) && numeric(v));
    let cell = |n: &[u8]| {
        find(n).filter(|v| {
            v.record != restart
                && v.dims.len() == 1 + lead
                && dims[v.dims[lead]].1 == 3
                && numeric(v)
        })
    };
    let (lengths, angles) = (cell(b"cell_lengths"), cell(b"cell_angles"));
    // One record of every record variable (each padded to 4 bytes, unless it is the only one).
    let rec_vars: Vec<&Var> = vars.iter().filter(|v| v.record).collect();
    let recsize = if rec_vars.len() == 1 {
        rec_vars[0].size
    } else {
        rec_vars
            .iter()
            .fold(0u64, |s, v| s.saturating_add(v.size.div_ceil(4) * 4))
    };
    let declared = if numrecs == u32::MAX {
        // Streaming mode: as many records as the file holds.
        usize::MAX
    } else {
        numrecs as usize
    };
    // Records wholly inside the file: every record variable's slice of record k must fit.
    let fits = |k: u64| {
        rec_vars.iter().all(|v| {
            k.checked_mul(recsize)
                .and_then(|o| o.checked_add(v.begin))
                .and_then(|o| o.checked_add(v.size))
                .is_some_and(|end| end <= h.len)
        })
    };
    let first = rec_vars.iter().map(|v| v.begin).min().unwrap_or(header_end);
    let complete = match h.len.saturating_sub(first).checked_div(recsize) {
        None => 0,
        Some(q) => {
            let mut k = (q + 1).min(declared as u64);
            while k > 0 && !fits(k - 1) {
                k -= 1;
            }
            k as usize
        }
    };
    let declared = if declared == usize::MAX {
        complete
    } else {
        declared
    };
    // A restart's one frame lies inside the file (its variables were checked above).
    let (declared, complete, recsize) = if restart {
        (1, 1, 0)
    } else {
        (declared, complete, recsize)
    };
    Ok(Layout {
        declared,
        complete,
        recsize,
        file_len: h.len,
        coords,
        velocities,
        time,
        lengths,
        angles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn refuses_other_files_with_a_located_error() {
        let e = NetcdfReader::new(Cursor::new(b"CDF\x01\0\0".to_vec()), "x.nc".into())
            .err()
            .unwrap();
        assert!(e.to_string().starts_with("x.nc: byte 4"), "{e}");
        let e = NetcdfReader::new(Cursor::new(b"\x89HDF\r\n\x1a\n".to_vec()), "x.nc".into())
            .err()
            .unwrap();
        assert!(e.to_string().contains("NetCDF-4/HDF5"), "{e}");
    }

    #[test]
    fn a_huge_dimension_count_is_not_allocated() {
        let mut b = b"CDF\x02".to_vec();
        b.extend_from_slice(&0u32.to_be_bytes());
        b.extend_from_slice(&0x0Au32.to_be_bytes());
        b.extend_from_slice(&u32::MAX.to_be_bytes());
        let e = NetcdfReader::new(Cursor::new(b), "x.nc".into())
            .err()
            .unwrap();
        assert!(e.to_string().contains("more than the file"), "{e}");
    }
}
