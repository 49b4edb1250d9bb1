//! AMBER NetCDF trajectories written ([`NetcdfWriter`], `.nc` / `.ncdf`): the AMBER convention
//! 1.0 (ambermd.org/netcdf/nctraj.xhtml) in the NetCDF-3 64-bit offset container (`CDF\x02`),
//! which AMBER (pmemd, sander) and cpptraj write by default, with the variables and attributes
//! they write, so that the programs reading AMBER's files (cpptraj, MDAnalysis, MDTraj, VMD,
//! OVITO, ParmEd) read these. Tested against MDAnalysis's `NCDFReader`, Unidata's netCDF-C
//! library (`ncdump`, the netCDF4 Python module) and our reader (src/netcdf.rs):
//! tests/netcdf_writer.rs.
//!
//! # What is written
//! - **Global attributes**: `title` (the first frame's comment, or empty), `program` `texmap`,
//!   `programVersion` (this crate's version), `Conventions` `AMBER`, `ConventionVersion` `1.0`.
//! - **Dimensions**: `frame` (unlimited: the record dimension), `spatial` 3, `atom` N,
//!   `cell_spatial` 3, `cell_angular` 3, `label` 5.
//! - **Variables**, in this order (the order of their data in the file):
//!
//! | variable | type | units | when |
//! |---|---|---|---|
//! | `spatial(spatial)` | char | `"xyz"` | always |
//! | `time(frame)` | float | `picosecond` | always |
//! | `coordinates(frame, atom, spatial)` | float | `angstrom` | always |
//! | `cell_spatial(cell_spatial)` | char | `"abc"` | the first frame has a cell |
//! | `cell_angular(cell_angular, label)` | char | `"alpha"`, `"beta "`, `"gamma"` | the first frame has a cell |
//! | `cell_lengths(frame, cell_spatial)` | double | `angstrom` | the first frame has a cell |
//! | `cell_angles(frame, cell_angular)` | double | `degree` | the first frame has a cell |
//! | `velocities(frame, atom, spatial)` | float | `angstrom/picosecond`, `scale_factor` 20.455 | the first frame has velocities |
//!
//! **Time** is the frame's time in ps, else (a frame from a file without times: GSD, PDB, a plain
//! XYZ) the frame's index in this file, 0, 1, 2, ..., so that readers that require `time`
//! (MDAnalysis warns without it) get increasing values. Stored as float, as AMBER stores it.
//!
//! **Coordinates** are the frame's f32 positions, bit for bit, when the frame has no cell or its
//! cell is in AMBER's orientation (a along +x, b in the xy plane with +y: every cell from GROMACS,
//! LAMMPS, DCD, AMBER, GSD, PDB or GRO). The convention keeps a cell as lengths and angles only,
//! which readers rebuild in that orientation; a cell in another orientation (a POSCAR's, an
//! XSF's or an extended XYZ's lattice vectors) is therefore rotated into it with its atoms and
//! velocities (p ↦ p·M⁻¹·M′, the fractional coordinates kept, as the LAMMPS data writer and
//! ASE's `Prism` do), so that every atom keeps its place in the cell and its distances. The
//! cell's origin and non-periodic edges have no place in the convention: the cell is written as
//! a fully periodic one at the origin (the atoms are not moved; readers that wrap see the same
//! periodic system).
//!
//! **Velocities** are stored in AMBER's own unit, Å per AMBER time unit (1/20.455 ps), with the
//! attribute `scale_factor` 20.455 (a double) that turns them into Å/ps, exactly as pmemd, sander,
//! cpptraj and MDAnalysis's `NCDFWriter` store them: cpptraj reads the stored values as AMBER
//! units and ignores `scale_factor`, while MDAnalysis, the netCDF4 library (auto-scaling) and
//! our reader multiply by it and get Å/ps. The quotient v / 20.455 is rounded to f32 (correctly,
//! from double precision), so a velocity read back is the frame's to one unit in the last place:
//! the same f32 for about 87 % of values where the reader multiplies in double precision
//! (MDAnalysis, netCDF4), within one unit for the rest and for our reader (which multiplies in
//! single precision).
//!
//! **Forces are not written.** The convention's `forces` are in kcal/(mol·Å), but a frame's
//! `fx fy fz` carry the units of the file they came from, which the frame does not record: eV/Å
//! from an ASE trajectory, Hartree/Å from XSF, 10 J/(mol·Å) from DL_POLY, the run's units from a
//! LAMMPS dump (kcal/(mol·Å) for `units real`, eV/Å for `metal`). No conversion to kcal/(mol·Å)
//! can be honest for all of them, and a wrong unit in a force file is worse than no forces.
//!
//! Not written either: names, elements, residues, bonds (an AMBER trajectory has no topology:
//! that is the prmtop's job), step numbers, per-atom properties, REMD variables.
//!
//! # Layout and streaming
//! The header is written with the first frame (which fixes the atom count and the variables),
//! the fixed variables' data after it, then one record per frame: the `time`, `coordinates`,
//! `cell_lengths`, `cell_angles` and `velocities` of that frame, each padded to 4 bytes (they
//! all are multiples of 4 already) as the classic format's record layout says. Every `begin` is
//! 64 bits (CDF-2), so a file is not limited to 2 GiB; `numrecs` is written 0 and set to the
//! number of frames by [`NetcdfWriter::finish`] (seek back to byte 4, then to the end): a file
//! whose writing was not finished reads as no frames rather than as frames of unknown length. The
//! writer keeps one frame's record in memory. A file finished without any frame is empty (the
//! atom count, a dimension of the header, is never known), as the DCD writer leaves it.
//!
//! # Refused, before any byte of the frame is written
//! As [`crate::Error::InvalidFrame`], naming the frame:
//! - a frame whose atom count differs from the first frame's (`atom` is one dimension for the
//!   whole file);
//! - a frame lacking velocities, a cell or a time that the first frame had, or having one the
//!   first frame lacked (the variables are fixed by the header; zeros or made-up values would be
//!   read back as data);
//! - no atoms (in NetCDF-3 a dimension of length 0 is the unlimited one), or more than
//!   357,913,941 (one record of `coordinates`, 12 bytes per atom, must stay below 4 GiB in the
//!   64-bit offset format: the netCDF-C library refuses larger ones);
//! - a coordinate beyond ±10^7 Å, which our reader and the others' sanity checks treat as damage
//!   ([`crate::MAX_COORDINATE`]), and a time that float cannot hold;
//! - a frame past 2^31 − 1 (`numrecs` is a non-negative 32-bit integer).
//!
//! # Why our own writer
//! Neither NetCDF crate is a dependency: `netcdf` binds the netCDF-C library (with HDF5, a C
//! toolchain to build them), and `netcdf3` is not needed for a header that is a few fixed lists.
//! Our reader of the format is our own too (src/netcdf.rs), so this module writes the header byte
//! by byte from the format specification, then streams one record per frame.
//!
//! # References
//! - Unidata, "The NetCDF Classic Format Specification" (NetCDF Users Guide, file format
//!   appendix): header grammar, 64-bit offset variant, record layout and padding, `vsize`.
//! - J. Mongan, D. R. Roe et al., "AMBER NetCDF Trajectory/Restart Convention", version 1.0
//!   (ambermd.org/netcdf/nctraj.xhtml).

use std::io::{self, Seek, SeekFrom, Write};

use crate::frame::{Frame, MAX_COORDINATE, UnitCell};
use crate::pbc::{to_cart, to_frac};

/// AMBER's time unit in ps⁻¹ (1 ps = 20.455 AMBER time units): the `scale_factor` of velocities.
pub(crate) const AMBER_VELOCITY_SCALE: f64 = 20.455;

/// Most atoms a file can hold: 12 bytes each in one record of `coordinates`, at most
/// 2^32 − 4 bytes (the 64-bit offset format's limit on one record of a variable).
pub(crate) const MAX_ATOMS: usize = ((u32::MAX as u64 - 3) / 12) as usize;

/// Most frames: `numrecs` is a non-negative 32-bit integer.
const MAX_FRAMES: u64 = i32::MAX as u64;

// NetCDF-3 header tags and type codes.
const NC_DIMENSION: u32 = 0x0A;
const NC_VARIABLE: u32 = 0x0B;
const NC_ATTRIBUTE: u32 = 0x0C;
const NC_CHAR: u32 = 2;
const NC_FLOAT: u32 = 5;
const NC_DOUBLE: u32 = 6;

// Dimension ids, in the order of the dimension list.
const FRAME: u32 = 0;
const SPATIAL: u32 = 1;
const ATOM: u32 = 2;
const CELL_SPATIAL: u32 = 3;
const CELL_ANGULAR: u32 = 4;
const LABEL: u32 = 5;

/// What the first frame fixed: the header's dimensions and variables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Shape {
    atoms: usize,
    cell: bool,
    velocities: bool,
    time: bool,
}

impl Shape {
    fn of(frame: &Frame) -> Shape {
        Shape {
            atoms: frame.n_atoms(),
            cell: frame.cell.is_some(),
            velocities: !frame.velocities.is_empty(),
            time: frame.time.is_some(),
        }
    }
}

/// One variable of the header.
struct Var {
    name: &'static str,
    dims: &'static [u32],
    ty: u32,
    /// Bytes of one record (record variables) or of all the data (fixed ones), unpadded.
    size: u64,
    units: Option<&'static str>,
    scale: Option<f64>,
    record: bool,
}

fn pad4(n: u64) -> u64 {
    n.div_ceil(4) * 4
}

/// The header's variables, in file order, for `shape`.
fn variables(shape: Shape) -> Vec<Var> {
    let n = shape.atoms as u64;
    let var = |name, dims, ty, size, units, record| Var {
        name,
        dims,
        ty,
        size,
        units,
        scale: None,
        record,
    };
    let mut v = vec![
        var("spatial", &[SPATIAL], NC_CHAR, 3, None, false),
        var("time", &[FRAME], NC_FLOAT, 4, Some("picosecond"), true),
        var(
            "coordinates",
            &[FRAME, ATOM, SPATIAL],
            NC_FLOAT,
            12 * n,
            Some("angstrom"),
            true,
        ),
    ];
    if shape.cell {
        v.push(var(
            "cell_spatial",
            &[CELL_SPATIAL],
            NC_CHAR,
            3,
            None,
            false,
        ));
        v.push(var(
            "cell_angular",
            &[CELL_ANGULAR, LABEL],
            NC_CHAR,
            15,
            None,
            false,
        ));
        v.push(var(
            "cell_lengths",
            &[FRAME, CELL_SPATIAL],
            NC_DOUBLE,
            24,
            Some("angstrom"),
            true,
        ));
        v.push(var(
            "cell_angles",
            &[FRAME, CELL_ANGULAR],
            NC_DOUBLE,
            24,
            Some("degree"),
            true,
        ));
    }
    if shape.velocities {
        let mut vel = var(
            "velocities",
            &[FRAME, ATOM, SPATIAL],
            NC_FLOAT,
            12 * n,
            Some("angstrom/picosecond"),
            true,
        );
        vel.scale = Some(AMBER_VELOCITY_SCALE);
        v.push(vel);
    }
    v
}

/// The fixed variables' data, in file order (each padded to 4 bytes with zeros).
fn fixed_data(name: &str) -> &'static [u8] {
    match name {
        "spatial" => b"xyz\0",
        "cell_spatial" => b"abc\0",
        "cell_angular" => b"alphabeta gamma\0",
        _ => b"",
    }
}

/// Header bytes.
struct Header(Vec<u8>);

impl Header {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_be_bytes());
    }

    fn padded(&mut self, b: &[u8]) {
        self.0.extend_from_slice(b);
        let pad = pad4(b.len() as u64) - b.len() as u64;
        self.0.extend(std::iter::repeat_n(0u8, pad as usize));
    }

    fn name(&mut self, s: &str) {
        self.u32(s.len() as u32);
        self.padded(s.as_bytes());
    }

    fn text_attribute(&mut self, name: &str, value: &[u8]) {
        self.name(name);
        self.u32(NC_CHAR);
        self.u32(value.len() as u32);
        self.padded(value);
    }

    fn attribute_list(&mut self, n: usize) {
        if n == 0 {
            self.u32(0);
            self.u32(0);
        } else {
            self.u32(NC_ATTRIBUTE);
            self.u32(n as u32);
        }
    }
}

/// The file's layout: the header bytes, where the records start and how long one is.
struct Layout {
    header: Vec<u8>,
    /// Offset of the first record from the start of the file.
    records: u64,
    recsize: u64,
}

/// The header for `shape` and `title`, with every `begin` set.
fn layout(shape: Shape, title: &[u8]) -> Layout {
    let vars = variables(shape);
    let build = |begins: &[u64]| {
        let mut h = Header(Vec::with_capacity(1024));
        h.0.extend_from_slice(b"CDF\x02");
        h.u32(0); // numrecs, set by finish
        let dims: [(&str, u32); 6] = [
            ("frame", 0),
            ("spatial", 3),
            ("atom", shape.atoms as u32),
            ("cell_spatial", 3),
            ("cell_angular", 3),
            ("label", 5),
        ];
        h.u32(NC_DIMENSION);
        h.u32(dims.len() as u32);
        for (name, len) in dims {
            h.name(name);
            h.u32(len);
        }
        h.attribute_list(5);
        h.text_attribute("title", title);
        h.text_attribute("program", b"texmap");
        h.text_attribute("programVersion", env!("CARGO_PKG_VERSION").as_bytes());
        h.text_attribute("Conventions", b"AMBER");
        h.text_attribute("ConventionVersion", b"1.0");
        h.u32(NC_VARIABLE);
        h.u32(vars.len() as u32);
        for (v, begin) in vars.iter().zip(begins) {
            h.name(v.name);
            h.u32(v.dims.len() as u32);
            for d in v.dims {
                h.u32(*d);
            }
            let n_attrs = usize::from(v.units.is_some()) + usize::from(v.scale.is_some());
            h.attribute_list(n_attrs);
            if let Some(u) = v.units {
                h.text_attribute("units", u.as_bytes());
            }
            if let Some(s) = v.scale {
                h.name("scale_factor");
                h.u32(NC_DOUBLE);
                h.u32(1);
                h.0.extend_from_slice(&s.to_be_bytes());
            }
            h.u32(v.ty);
            // vsize: the padded size (of one record); at most 2^32 - 4 by MAX_ATOMS.
            h.u32(pad4(v.size).min(u32::MAX as u64) as u32);
            h.0.extend_from_slice(&begin.to_be_bytes());
        }
        h.0
    };
    // The header's length does not depend on the begins (8 bytes each in CDF-2).
    let header_len = build(&vec![0; vars.len()]).len() as u64;
    let mut begins = Vec::with_capacity(vars.len());
    let mut at = header_len;
    for v in vars.iter().filter(|v| !v.record) {
        begins.push((v.name, at));
        at += pad4(v.size);
    }
    let records = at;
    for v in vars.iter().filter(|v| v.record) {
        begins.push((v.name, at));
        at += pad4(v.size);
    }
    let recsize = at - records;
    let ordered: Vec<u64> = vars
        .iter()
        .map(|v| {
            begins
                .iter()
                .find(|(n, _)| *n == v.name)
                .map_or(0, |(_, b)| *b)
        })
        .collect();
    let mut header = build(&ordered);
    for v in vars.iter().filter(|v| !v.record) {
        header.extend_from_slice(fixed_data(v.name));
    }
    Layout {
        header,
        records,
        recsize,
    }
}

/// A cell matrix (rows a, b, c).
type Matrix = [[f64; 3]; 3];

/// The linear map taking `cell` into AMBER's orientation (a along +x, b in the xy plane), as the
/// cell's matrix and the upright one with its lengths and angles, or `None` when it is already
/// there.
fn reorientation(cell: &UnitCell) -> Option<(Matrix, Matrix)> {
    let m = cell.matrix();
    let longest = cell.lengths().iter().fold(0.0f64, |a, b| a.max(*b));
    let tol = 1e-10 * longest;
    let upright = m[0][1].abs() <= tol
        && m[0][2].abs() <= tol
        && m[1][2].abs() <= tol
        && m[0][0] > 0.0
        && m[1][1] > 0.0;
    if upright {
        return None;
    }
    let standard = UnitCell::from_lengths_angles(cell.lengths(), cell.angles()).ok()?;
    Some((m, standard.matrix()))
}

/// The stored (AMBER unit) value of a velocity component `v` in Å/ps: the correctly rounded
/// f32 of v / 20.455 (see the module doc).
fn amber_velocity(v: f32) -> f32 {
    (v as f64 / AMBER_VELOCITY_SCALE) as f32
}

/// Writes frames as an AMBER NetCDF trajectory (see the module doc).
pub(crate) struct NetcdfWriter<W> {
    pub out: W,
    /// The first frame's shape, once the header is written.
    shape: Option<Shape>,
    /// Where the file starts in `out`, where its records start, and one record's size.
    start: u64,
    records: u64,
    recsize: u64,
    frames: u64,
    /// An earlier write failed: the file's end is not where the next record belongs.
    failed: bool,
    buf: Vec<u8>,
    /// Positions and velocities of a frame rotated into AMBER's orientation.
    rotated: Vec<[f32; 3]>,
}

impl<W: Write + Seek> NetcdfWriter<W> {
    pub fn new(out: W) -> NetcdfWriter<W> {
        NetcdfWriter {
            out,
            shape: None,
            start: 0,
            records: 0,
            recsize: 0,
            frames: 0,
            failed: false,
            buf: Vec::new(),
            rotated: Vec::new(),
        }
    }

    /// Why `frame` cannot be the next record, if it cannot.
    pub fn check(&self, frame: &Frame) -> Result<(), String> {
        let n = frame.n_atoms();
        let here = Shape::of(frame);
        match self.shape {
            None => {
                if n == 0 {
                    return Err(
                        "it has no atoms: an AMBER NetCDF trajectory needs an `atom` \
                                dimension of length 1 or more (length 0 is NetCDF-3's \
                                unlimited dimension)"
                            .into(),
                    );
                }
                if n > MAX_ATOMS {
                    return Err(format!(
                        "it has {n} atoms, more than the {MAX_ATOMS} an AMBER NetCDF file can \
                         hold (one frame of `coordinates`, 12 bytes per atom, must stay below \
                         4 GiB in the 64-bit offset format)"
                    ));
                }
            }
            Some(first) => {
                if n != first.atoms {
                    return Err(format!(
                        "it has {n} atoms and the first frame {}: every frame of an AMBER \
                         NetCDF trajectory holds the atoms of its `atom` dimension (write .xyz \
                         or .lammpstrj, whose frames may differ)",
                        first.atoms
                    ));
                }
                // (lacking, having) in the words of the message.
                let fields = [
                    (
                        "no velocities",
                        "velocities",
                        first.velocities,
                        here.velocities,
                    ),
                    ("no cell", "a cell", first.cell, here.cell),
                    ("no time", "a time", first.time, here.time),
                ];
                for (lacking, having, had, has) in fields {
                    if had && !has {
                        return Err(format!(
                            "it has {lacking}, and the first frame had {having}: the file's \
                             header, written with the first frame, holds them for every frame"
                        ));
                    }
                    if has && !had {
                        return Err(format!(
                            "it has {having}, and the first frame had none: the file's header, \
                             written with the first frame, has no place for them"
                        ));
                    }
                }
                if self.frames >= MAX_FRAMES {
                    return Err(format!(
                        "a NetCDF-3 file holds at most {MAX_FRAMES} frames (numrecs is a \
                         32-bit integer)"
                    ));
                }
            }
        }
        let far = |v: &[[f32; 3]]| {
            v.iter()
                .position(|p| p.iter().any(|x| (*x as f64).abs() > MAX_COORDINATE))
        };
        if let Some(i) = far(&frame.positions) {
            return Err(format!(
                "atom {i} is at {:?}, beyond ±{MAX_COORDINATE:e} Å, which readers take for a \
                 damaged file",
                frame.positions[i]
            ));
        }
        if let Some(t) = frame.time
            && !(t.is_finite() && (t as f32).is_finite())
        {
            return Err(format!(
                "its time {t:e} ps is not a number the float variable `time` can hold"
            ));
        }
        Ok(())
    }

    /// Writes the header and the fixed variables for `frame`, the first.
    fn header(&mut self, frame: &Frame) -> io::Result<()> {
        let shape = Shape::of(frame);
        let l = layout(shape, frame.comment.as_bytes());
        self.start = self.out.stream_position()?;
        self.out.write_all(&l.header)?;
        self.records = l.records;
        self.recsize = l.recsize;
        self.shape = Some(shape);
        Ok(())
    }

    /// Appends one frame as a record (the `Writer` contract).
    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        if self.failed {
            return Err(io::Error::other(
                "an earlier write to this NetCDF file failed",
            ));
        }
        self.check(frame)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        let r = self.write_record(frame);
        if r.is_err() {
            self.failed = true;
        }
        r
    }

    fn write_record(&mut self, frame: &Frame) -> io::Result<()> {
        if self.shape.is_none() {
            self.header(frame)?;
        }
        let Some(shape) = self.shape else {
            return Ok(());
        };
        let time = frame.time.unwrap_or(self.frames as f64) as f32;
        let turn = frame.cell.as_ref().and_then(reorientation);
        let buf = &mut self.buf;
        buf.clear();
        buf.extend_from_slice(&time.to_be_bytes());
        // Coordinates (rotated into AMBER's orientation when the cell is not in it).
        let rotated = &mut self.rotated;
        let rotate = |v: &[[f32; 3]], out: &mut Vec<[f32; 3]>| {
            if let Some((m, r)) = &turn {
                out.clear();
                out.extend(v.iter().map(|p| {
                    let q = to_cart(r, to_frac(m, p.map(f64::from)));
                    q.map(|x| x as f32)
                }));
            }
        };
        rotate(&frame.positions, rotated);
        let positions = if turn.is_some() {
            rotated.as_slice()
        } else {
            frame.positions.as_slice()
        };
        buf.extend(positions.iter().flatten().flat_map(|x| x.to_be_bytes()));
        if shape.cell
            && let Some(c) = &frame.cell
        {
            buf.extend(c.lengths().iter().flat_map(|x| x.to_be_bytes()));
            buf.extend(c.angles().iter().flat_map(|x| x.to_be_bytes()));
        }
        if shape.velocities {
            rotate(&frame.velocities, rotated);
            let v = if turn.is_some() {
                rotated.as_slice()
            } else {
                frame.velocities.as_slice()
            };
            buf.extend(
                v.iter()
                    .flatten()
                    .flat_map(|x| amber_velocity(*x).to_be_bytes()),
            );
        }
        debug_assert_eq!(buf.len() as u64, self.recsize);
        self.out.write_all(buf)?;
        self.frames += 1;
        Ok(())
    }

    /// Sets `numrecs` to the frames written and leaves the stream at the file's end.
    pub fn finish(&mut self) -> io::Result<()> {
        if self.failed {
            return Err(io::Error::other(
                "an earlier write to this NetCDF file failed: it is incomplete",
            ));
        }
        if self.shape.is_none() {
            return Ok(());
        }
        let end = self.start + self.records + self.frames * self.recsize;
        self.out.seek(SeekFrom::Start(self.start + 4))?;
        self.out.write_all(&(self.frames as u32).to_be_bytes())?;
        self.out.seek(SeekFrom::Start(end))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::netcdf::NetcdfReader;
    use std::io::Cursor;

    fn frame(n: usize) -> Frame {
        let mut f = Frame::new();
        f.positions = (0..n).map(|i| [i as f32, 0.5 * i as f32, -0.25]).collect();
        f
    }

    fn write(frames: &[Frame]) -> Vec<u8> {
        let mut w = NetcdfWriter::new(Cursor::new(Vec::new()));
        for f in frames {
            w.check(f).unwrap();
            w.write_frame(f).unwrap();
        }
        w.finish().unwrap();
        w.out.into_inner()
    }

    fn be32(b: &[u8], at: usize) -> u32 {
        u32::from_be_bytes(b[at..at + 4].try_into().unwrap())
    }

    #[test]
    fn a_minimal_file_is_laid_out_as_the_specification_says() {
        let mut f = frame(2);
        f.comment = "ab".into();
        let b = write(&[f.clone(), f]);
        assert_eq!(&b[..4], b"CDF\x02");
        assert_eq!(be32(&b, 4), 2, "numrecs");
        // Dimension list: tag, count, then "frame" of length 0 (the record dimension).
        assert_eq!(be32(&b, 8), NC_DIMENSION);
        assert_eq!(be32(&b, 12), 6);
        assert_eq!(be32(&b, 16), 5);
        assert_eq!(&b[20..28], b"frame\0\0\0");
        assert_eq!(be32(&b, 28), 0);
        // Header, "xyz\0", then two records of time (4) + coordinates (24).
        let l = layout(Shape::of(&frame(2)), b"ab");
        assert_eq!(l.recsize, 28);
        assert_eq!(b.len() as u64, l.records + 2 * 28);
        assert_eq!(&b[l.records as usize - 4..l.records as usize], b"xyz\0");
        let rec1 = l.records as usize + 28;
        assert_eq!(
            f32::from_be_bytes(b[rec1..rec1 + 4].try_into().unwrap()),
            1.0
        );
        assert_eq!(
            f32::from_be_bytes(b[rec1 + 4 + 12..rec1 + 20].try_into().unwrap()),
            1.0,
            "atom 1's x"
        );
    }

    #[test]
    fn our_reader_reads_back_positions_cells_times_and_velocities() {
        let mut frames = Vec::new();
        for k in 0..3 {
            let mut f = frame(5);
            f.time = Some(0.5 * k as f64);
            f.cell = Some(
                UnitCell::from_lengths_angles([10.0, 11.0 + k as f64, 12.0], [80.0, 95.0, 105.0])
                    .unwrap(),
            );
            f.velocities = (0..5)
                .map(|i| [0.1 * i as f32, -3.7 + k as f32, 1e-3])
                .collect();
            frames.push(f);
        }
        let b = write(&frames);
        let mut r = NetcdfReader::new(Cursor::new(b), "t.nc".into()).unwrap();
        assert_eq!(r.n_frames().unwrap(), 3);
        let mut g = Frame::new();
        for f in &frames {
            assert!(r.read_next(&mut g).unwrap());
            assert_eq!(g.positions, f.positions);
            assert_eq!(g.time, f.time);
            for (a, b) in g.velocities.iter().zip(&f.velocities) {
                for k in 0..3 {
                    let ulp = (f32::from_bits(b[k].abs().to_bits() + 1) - b[k].abs()).max(1e-45);
                    assert!((a[k] - b[k]).abs() <= ulp, "{a:?} {b:?}");
                }
            }
        }
    }

    #[test]
    fn velocities_come_back_within_one_unit_in_the_last_place() {
        let mut exact = 0;
        let n = 10_000;
        for i in 0..n {
            let v = (i as f32 - 5000.0) * 0.0137 + 1e-4;
            let s = amber_velocity(v);
            let ulp = f32::from_bits(v.abs().to_bits() + 1) - v.abs();
            let wide = (s as f64 * AMBER_VELOCITY_SCALE) as f32;
            let narrow = s * AMBER_VELOCITY_SCALE as f32;
            assert!((wide - v).abs() <= ulp && (narrow - v).abs() <= ulp, "{v}");
            exact += usize::from(wide == v);
        }
        assert!(exact > n * 8 / 10, "{exact} of {n}");
        assert_eq!(amber_velocity(0.0), 0.0);
    }

    #[test]
    fn the_atom_limit_is_the_64_bit_offset_formats() {
        assert_eq!(MAX_ATOMS, 357_913_941);
        assert!(12 * MAX_ATOMS as u64 <= u32::MAX as u64 - 3);
        assert!(12 * (MAX_ATOMS as u64 + 1) > u32::MAX as u64 - 3);
        let w = NetcdfWriter::new(Cursor::new(Vec::new()));
        assert!(w.check(&frame(0)).unwrap_err().contains("no atoms"));
    }

    #[test]
    fn a_rotated_cell_keeps_fractional_coordinates() {
        // A cell whose a vector is along y: not AMBER's orientation.
        let cell =
            UnitCell::from_matrix([[0.0, 5.0, 0.0], [-6.0, 0.0, 0.0], [0.0, 0.0, 7.0]]).unwrap();
        let mut f = frame(3);
        f.cell = Some(cell);
        f.velocities = vec![[0.0, 1.0, 0.0]; 3];
        let b = write(std::slice::from_ref(&f));
        let mut r = NetcdfReader::new(Cursor::new(b), "t.nc".into()).unwrap();
        let mut g = Frame::new();
        assert!(r.read_next(&mut g).unwrap());
        let m = g.cell.unwrap().matrix();
        assert!((m[0][0] - 5.0).abs() < 1e-12 && m[0][1] == 0.0);
        for (p, q) in f.positions.iter().zip(&g.positions) {
            let a = to_frac(&cell.matrix(), p.map(f64::from));
            let b = to_frac(&m, q.map(f64::from));
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 1e-6, "{a:?} {b:?}");
            }
        }
        // Along a, which is now +x.
        for v in &g.velocities {
            assert!((v[0] - 1.0).abs() < 1e-6 && v[1].abs() < 1e-6, "{v:?}");
        }
    }
}
