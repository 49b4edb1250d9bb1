//! [`Writer`]: one writer for every format that has one.
//!
//! - [`Format::Xyz`]: extended XYZ with the species, positions, ids, types, velocities, radii,
//!   colours and every named property ([`crate::Property`]) as `Properties=` columns, the cell
//!   as `Lattice=` (read back by ASE, OVITO and our reader).
//! - [`Format::LammpsDump`]: a LAMMPS text dump as `dump custom` writes it, `ITEM: ATOMS id
//!   type x y z` then `element`, `vx vy vz`, `radius`, `ColorR ColorG ColorB` and the
//!   properties when the frame has them (read back by LAMMPS `read_dump`, OVITO, ASE and our
//!   reader).
//! - [`Format::LammpsData`]: one frame as a LAMMPS data file for `read_data` (atom style by
//!   what the frame has, types with their masses, a data file's `Velocities` (the properties
//!   `vx vy vz`), bonds typed by their atoms' types, the box in LAMMPS's restricted form:
//!   src/lammps_data_writer.rs).
//! - [`Format::Gro`]: GROMACS .gro as `gmx trjconv` writes it (residues, names, numbers,
//!   positions to 0.001 nm, velocities, the box; time and step in the title).
//! - [`Format::Pdb`], [`Format::Dcd`], [`Format::Xtc`]: positions and cell, with PDB's atom
//!   records.
//! - [`Format::Trr`]: GROMACS TRR in single precision, per frame the box, positions,
//!   velocities and the forces `fx fy fz` the frame has (src/trr_writer.rs).
//! - [`Format::Gsd`]: HOOMD-blue GSD (file format 2.0, hoomd schema 1.4): the box in HOOMD's
//!   centred form with the positions wrapped into it and their images (2-D, `dimensions` 2,
//!   for a planar frame in a cell open along its third edge, as a 2-D GSD reads), types,
//!   velocities, diameters, masses, charges, orientations and bonds (src/gsd_writer.rs).
//! - [`Format::Mmcif`]: PDBx/mmCIF, frames as the models of one `_atom_site` loop (names,
//!   residues, chains and elements in the label and auth items, the `occupancy` and `bfactor`
//!   properties, the first frame's cell), with no limit on atom count, residue numbers or chain
//!   names (read back by gemmi, ChimeraX, PyMOL, VMD and our reader).
//! - [`Format::Vasp`]: a VASP 5 POSCAR (one frame: cell, element species as runs in atom
//!   order, Direct coordinates, velocities) or, for a file named `XDATCAR*`, an XDATCAR with
//!   the header repeated when the cell changes (read back by ASE, pymatgen, phonopy, OVITO and
//!   our reader: src/vasp_writer.rs).
//! - [`Format::Netcdf`]: an AMBER NetCDF trajectory (64-bit offset NetCDF-3, the AMBER
//!   convention 1.0): time, f32 coordinates, the cell as lengths and angles, velocities with
//!   AMBER's `scale_factor` 20.455; no forces (src/netcdf_writer.rs; read back by MDAnalysis,
//!   the netCDF-C library and our reader).
//! - [`Format::Sdf`]: MDL SD file, one molfile record per frame (V2000, V3000 past 999 atoms
//!   or bonds): elements, positions to 4 decimals, bonds with their orders, formal charges,
//!   step, time (src/sdf_writer.rs; read back by RDKit, Open Babel and our reader).
//!
//! Rules the text writers share:
//! - numbers are written in Rust's shortest round-trip form, so reading them back gives the
//!   same f32 bits (cell and box numbers are f64, written the same way);
//! - a property whose every value is an integer below 2^24 in magnitude (where f32 holds
//!   every integer) is an integer column, written without a decimal point: `I` in extended
//!   XYZ's `Properties=`, `5` not `5.0` in both formats;
//! - a NaN property value is written `nan` (and makes its column real), as ASE and LAMMPS write
//!   it and ASE, OVITO and our readers read it; infinities `inf` and `-inf`;
//! - what would not read back as written is an [`Error::InvalidFrame`] before anything of the
//!   frame is written, never a silently changed file: a label with white space, a property name
//!   the format cannot hold, and for LAMMPS a cell that is not restricted triclinic.
//!
//! What a format has no place for is not an error: [`Writer::dropped`] names it before the frame
//! is written (src/dropped.rs has the table of what each output keeps), so that a caller can
//! say what the file will lack.
//!
//! The per-format details are on the writer types (src/xyz.rs `XyzWriter`,
//! src/lammps_dump_writer.rs, src/gro.rs `GroWriter`, src/mmcif_writer.rs).

use crate::dcd::DcdWriter;
use crate::dropped::{Dropped, Output};
use crate::error::{Error, Location};
use crate::format::Format;
use crate::frame::Frame;
use crate::gro::GroWriter;
use crate::gsd_writer::GsdWriter;
use crate::lammps_data_writer::LammpsDataWriter;
use crate::lammps_dump_writer::LammpsDumpWriter;
use crate::mmcif_writer::MmcifWriter;
use crate::netcdf_writer::NetcdfWriter;
use crate::pdb::PdbWriter;
use crate::sdf_writer::SdfWriter;
use crate::trr_writer::TrrWriter;
use crate::vasp_writer::{VaspWriter, is_xdatcar};
use crate::xtc::XtcWriter;
use crate::xyz::XyzWriter;
use std::fmt;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;
use std::sync::Arc;

/// A number as the text writers write it: shortest round-trip decimal, `nan` for NaN, `inf` /
/// `-inf` for infinities, integers without a decimal point.
pub(crate) struct Num(pub f32);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_nan() {
            f.write_str("nan")
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// True when every value is an integer that f32 holds exactly with its neighbours (|v| < 2^24):
/// a column written as integers.
pub(crate) fn integer_valued(values: &[f32]) -> bool {
    values
        .iter()
        .all(|v| v.is_finite() && v.fract() == 0.0 && v.abs() < 16_777_216.0)
}

/// The columns both text writers end an atom's line with, in this order, for the fields the
/// frame has: velocity (3), radius, colour (3), then every property ([`Num`]).
pub(crate) fn write_atom_tail(
    w: &mut impl std::io::Write,
    frame: &Frame,
    i: usize,
) -> std::io::Result<()> {
    if let Some(v) = frame.velocities.get(i) {
        write!(w, " {} {} {}", v[0], v[1], v[2])?;
    }
    if let Some(r) = frame.radii.get(i) {
        write!(w, " {r}")?;
    }
    if let Some(c) = frame.colors.get(i) {
        write!(w, " {} {} {}", c[0], c[1], c[2])?;
    }
    for p in &frame.properties {
        write!(w, " {}", Num(p.values[i]))?;
    }
    writeln!(w)
}

/// The per-format writers: a closed set, dispatched by `match`.
enum WriterKind<W> {
    Xyz(XyzWriter<W>),
    LammpsDump(LammpsDumpWriter<W>),
    LammpsData(LammpsDataWriter<W>),
    Gro(GroWriter<W>),
    Dcd(DcdWriter<W>),
    Xtc(XtcWriter<W>),
    Pdb(PdbWriter<W>),
    Mmcif(MmcifWriter<W>),
    Netcdf(NetcdfWriter<W>),
    Vasp(VaspWriter<W>),
    Trr(TrrWriter<W>),
    Gsd(GsdWriter<W>),
    Sdf(SdfWriter<W>),
}

/// Runs `$body` with `$w` bound to the format's writer, whatever the format.
macro_rules! each_writer {
    ($writer:expr, $w:ident => $body:expr) => {
        match $writer {
            WriterKind::Xyz($w) => $body,
            WriterKind::LammpsDump($w) => $body,
            WriterKind::LammpsData($w) => $body,
            WriterKind::Gro($w) => $body,
            WriterKind::Dcd($w) => $body,
            WriterKind::Xtc($w) => $body,
            WriterKind::Pdb($w) => $body,
            WriterKind::Mmcif($w) => $body,
            WriterKind::Netcdf($w) => $body,
            WriterKind::Vasp($w) => $body,
            WriterKind::Trr($w) => $body,
            WriterKind::Gsd($w) => $body,
            WriterKind::Sdf($w) => $body,
        }
    };
}

/// A trajectory file being written, frame by frame. Call [`Writer::finish`] at the end (it
/// writes the format's trailer, e.g. PDB's END, and flushes); without it a trailer may be missing.
pub struct Writer<W: Write + Seek = BufWriter<File>> {
    kind: WriterKind<W>,
    file: Arc<str>,
    format: Format,
    output: Output,
    written: usize,
}

impl Writer<BufWriter<File>> {
    /// Creates (or truncates) `path` and writes `format` to it.
    pub fn create(path: impl AsRef<Path>, format: Format) -> Result<Self, Error> {
        Writer::create_as(path.as_ref(), format, path.as_ref())
    }

    /// Creates (or truncates) `path`, a temporary file to be renamed `name` once whole, and
    /// writes `format` to it: errors name `name`, and so does the file's content where the
    /// format keeps a name (the data block of PDBx/mmCIF).
    pub fn create_as(
        path: impl AsRef<Path>,
        format: Format,
        name: impl AsRef<Path>,
    ) -> Result<Self, Error> {
        let path = path.as_ref();
        let name: Arc<str> = name.as_ref().display().to_string().into();
        let f = File::create(path).map_err(|source| Error::Io {
            at: Location::file(&name),
            source,
        })?;
        Writer::new(BufWriter::with_capacity(1 << 20, f), format, &name)
    }
}

impl<W: Write + Seek> Writer<W> {
    /// Writes `format` to `out`; `name` is what errors call the file (for [`Format::Vasp`] its
    /// file name also chooses an XDATCAR, `XDATCAR*` or `*.xdatcar`, over a POSCAR).
    pub fn new(out: W, format: Format, name: &str) -> Result<Self, Error> {
        let file: Arc<str> = name.into();
        let unsupported = || Error::Unsupported {
            file: file.clone(),
            what: "writing this format",
        };
        let output = Output::of(format, is_xdatcar(&file)).ok_or_else(unsupported)?;
        let kind = match format {
            Format::Xyz => WriterKind::Xyz(XyzWriter { out }),
            Format::LammpsDump => WriterKind::LammpsDump(LammpsDumpWriter::new(out)),
            Format::LammpsData => WriterKind::LammpsData(LammpsDataWriter::new(out)),
            Format::Gro => WriterKind::Gro(GroWriter { out }),
            Format::Dcd => WriterKind::Dcd(DcdWriter::new(out, file.clone())),
            Format::Xtc => WriterKind::Xtc(XtcWriter::new(out, file.clone(), 1000.0)?),
            Format::Pdb => WriterKind::Pdb(PdbWriter::new(out)),
            Format::Mmcif => WriterKind::Mmcif(MmcifWriter::new(out, &file)),
            Format::Netcdf => WriterKind::Netcdf(NetcdfWriter::new(out)),
            Format::Vasp => WriterKind::Vasp(VaspWriter::new(out, is_xdatcar(&file))),
            Format::Trr => WriterKind::Trr(TrrWriter::new(out)),
            Format::Gsd => WriterKind::Gsd(GsdWriter::new(out)),
            Format::Sdf => WriterKind::Sdf(SdfWriter::new(out, &file)),
            _ => return Err(unsupported()),
        };
        Ok(Writer {
            kind,
            file,
            format,
            output,
            written: 0,
        })
    }

    /// The format being written.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Frames written so far.
    pub fn frames_written(&self) -> usize {
        self.written
    }

    /// What of `frame` this file will not hold when `frame` is the next one written: each kind
    /// of data the frame carries that the format has no place for (velocities in a .dcd, a
    /// property other than `occupancy` and `bfactor` in a .pdb, partial charges in an .sdf, a
    /// cell that differs from the first frame's in a .cif, ...), in a fixed order, each once;
    /// empty when the file keeps everything. Call it before [`Writer::write_frame`]. The table
    /// of what each format keeps is in src/dropped.rs. Counts and precision are not reported
    /// (see there).
    ///
    /// ```
    /// use std::io::Cursor;
    /// use texmap_md_io::{Dropped, Format, Frame, Writer};
    /// let mut f = Frame::new();
    /// f.positions = vec![[0.0; 3]];
    /// f.velocities = vec![[1.0, 0.0, 0.0]];
    /// let dcd = Writer::new(Cursor::new(Vec::new()), Format::Dcd, "out.dcd").unwrap();
    /// assert_eq!(dcd.dropped(&f), [Dropped::Velocities]);
    /// let xyz = Writer::new(Cursor::new(Vec::new()), Format::Xyz, "out.xyz").unwrap();
    /// assert!(xyz.dropped(&f).is_empty());
    /// ```
    pub fn dropped(&self, frame: &Frame) -> Vec<Dropped> {
        let mut state = crate::dropped::State::default();
        match &self.kind {
            WriterKind::Mmcif(w) if self.written > 0 => {
                state.first_cell = Some(w.first_cell.as_ref());
            }
            WriterKind::Vasp(w) => state.comment_kept = Some(w.keeps_comment(frame)),
            WriterKind::Dcd(w) => {
                state.step_kept = frame.step.map(|s| w.keeps_step(s));
                state.time_kept = frame.time.map(|t| w.keeps_time(frame.step, t));
            }
            _ => {}
        }
        crate::dropped::dropped(self.output, frame, state)
    }

    /// Why this file does not hold `kind` (one of [`Writer::dropped`]'s), as the end of a
    /// sentence: "a .gro file has no place for them".
    pub fn why_dropped(&self, kind: &Dropped) -> String {
        crate::dropped::reason(self.output, kind)
    }

    /// The file name users know this output by: `.xyz`, `.gro`, `POSCAR`, `XDATCAR`, ...
    pub fn output_name(&self) -> &'static str {
        self.output.name()
    }

    /// Appends one frame, after checking it ([`Frame::check`]).
    pub fn write_frame(&mut self, frame: &Frame) -> Result<(), Error> {
        frame.check().map_err(|what| Error::InvalidFrame {
            file: self.file.clone(),
            frame: self.written,
            what,
        })?;
        // Format limits (e.g. PDB's fixed columns, LAMMPS's restricted triclinic box).
        let limits = match &self.kind {
            WriterKind::Pdb(w) => w.check(frame),
            WriterKind::Xyz(_) => XyzWriter::<W>::check(frame),
            WriterKind::LammpsDump(_) => LammpsDumpWriter::<W>::check(frame),
            WriterKind::LammpsData(w) => w.check(frame),
            WriterKind::Gro(_) => GroWriter::<W>::check(frame),
            WriterKind::Mmcif(w) => w.check(frame),
            WriterKind::Netcdf(w) => w.check(frame),
            WriterKind::Vasp(w) => w.check(frame),
            WriterKind::Trr(w) => w.check(frame),
            WriterKind::Gsd(w) => w.check(frame),
            _ => Ok(()),
        };
        limits.map_err(|what| Error::InvalidFrame {
            file: self.file.clone(),
            frame: self.written,
            what,
        })?;
        let r = each_writer!(&mut self.kind, w => w.write_frame(frame));
        r.map_err(|source| self.io(source))?;
        self.written += 1;
        Ok(())
    }

    fn io(&self, source: std::io::Error) -> Error {
        Error::Io {
            at: Location {
                file: self.file.clone(),
                frame: Some(self.written),
                line: None,
                byte: None,
            },
            source,
        }
    }

    /// Writes the trailer, flushes, and returns the output.
    pub fn finish(mut self) -> Result<W, Error> {
        let r = each_writer!(&mut self.kind, w => w.finish().and_then(|()| w.out.flush()));
        r.map_err(|source| self.io(source))?;
        Ok(each_writer!(self.kind, w => w.out))
    }
}
