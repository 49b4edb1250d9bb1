//! [`Topology`]: who the atoms are (names, elements, types, residues) and how they are bonded,
//! read from a structure file and given to every frame of a trajectory of the same atoms.
//!
//! Trajectory formats such as XTC, DCD, TRR and AMBER NetCDF carry coordinates only. MD users
//! always have a structure file beside them (the GROMACS `.gro`, the PDB, the LAMMPS data file
//! the run started from), and VMD, OVITO and MDAnalysis all take "topology + trajectory". This
//! module reads:
//!
//! - **PDB**: the first model's atoms through the PDB reader, plus `CONECT` records (serial
//!   numbers, hybrid-36 allowed, resolved to atom indices through the model's serials);
//! - **GRO**: the first frame's atoms (GRO has no bonds);
//! - **crystallographic CIF** (a `.cif` whose tags say so, as for trajectories): the first
//!   data block's atoms expanded by its symmetry operations, labels and elements, no bonds;
//! - **PDBx/mmCIF**: the first model's atoms through the mmCIF reader (the first alternate
//!   location of each atom, as there: the dropped rows are not reported here, read the file as a
//!   trajectory to see the warning). No bonds are taken from `_struct_conn`: as for GRO, bonds
//!   come from the distance-based finder ([`crate::bonds`]); its BinaryCIF encoding (`.bcif`)
//!   alike, through the BinaryCIF reader;
//! - **PSF** (CHARMM, NAMD, X-PLOR): atoms with segment-free residues, types and masses, and the
//!   `!NBOND` section (module `psf`: elements from names, checked against the masses);
//! - **AMBER prmtop** (`.prmtop`, `.parm7`): atoms, types, elements from `ATOMIC_NUMBER`,
//!   residues, chains (`RESIDUE_CHAINID`) and both bond sections (module `prmtop`);
//! - **GROMACS topology** (`.top` that is not an AMBER prmtop, `.itp`): the preprocessed
//!   topology with its `#include`s, filled as from the `.tpr` grompp makes of it (module
//!   `gromacs_top`; defines through [`crate::read_gromacs_top`]);
//! - **LAMMPS data file** (`.data`, `.lmp`, or a name starting `data.`): read by the trajectory
//!   reader of [`Format::LammpsData`] (module `lammps_data`: the atom styles, told by the
//!   `Atoms # style` comment or, without one, by the column count: 7 columns is `full`, 5
//!   `atomic`, 6 is ambiguous between `molecular` and `charge` and an error asking for the
//!   comment), and its frame's types, ids, molecule ids, elements, charges and `Bonds` kept.
//!   Atoms are ordered by id, as the LAMMPS dump reader orders them, so index `i` is the same
//!   atom in both. Errors name frame 0, as those of the other topologies read through a
//!   trajectory reader (PDB, GRO, mmCIF) do.
//!
//! Applying a topology ([`Topology::apply`]) replaces the frame's per-atom labels with the
//! topology's; an atom-count mismatch is an [`Error::TopologyMismatch`] naming both files.
//! Positions are never taken from the topology: the trajectory's frame is what is drawn.
//!
//! LAMMPS elements come from a `Masses` line's comment (`1 12.011 # C`) or a type label when it
//! is an element symbol, else from a mass within 0.1 % of exactly one element's standard weight.
//! Rejected: the nearest element whatever the distance (ASE's rule): masses of isotopes,
//! united atoms and coarse-grained beads would be wrong silently; those types stay of unknown
//! element and are drawn one colour per type, as OVITO does.

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::sync::Arc;

use crate::elements::Element;
use crate::error::{Error, Location};
use crate::format::Format;
use crate::frame::{Frame, Label};
use crate::parse::trim;
use crate::trajectory::Trajectory;

/// The kinds of file a topology is read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum TopologyFormat {
    /// PDB: atoms of the first model, bonds from `CONECT`.
    Pdb,
    /// GROMACS .gro: atoms of the first frame, no bonds.
    Gro,
    /// PDBx/mmCIF: atoms of the first model, no bonds.
    Mmcif,
    /// BinaryCIF (PDBx/mmCIF's binary encoding): as [`TopologyFormat::Mmcif`].
    Bcif,
    /// Crystallographic CIF (COD, ICSD, Materials Project): the first data block's atoms,
    /// expanded by its symmetry operations as the trajectory reader expands them, no bonds.
    CrystalCif,
    /// LAMMPS data file: `Atoms` and `Bonds` sections.
    LammpsData,
    /// CHARMM/NAMD/X-PLOR PSF: `!NATOM` and `!NBOND` sections (see the `psf` module).
    Psf,
    /// AMBER prmtop/parm7: atoms, residues, bonds and chains (see the `prmtop` module).
    Prmtop,
    /// GROMACS run input (.tpr): atoms with masses and charges, residues, molecule types and
    /// the force field's chemical bonds (see the `tpr` module).
    Tpr,
    /// GROMACS topology (.top with its #included .itp files): atoms with masses and charges,
    /// residues, molecule types and chemical bonds, as from the .tpr grompp makes of it (see
    /// the `gromacs_top` module).
    GromacsTop,
}

impl TopologyFormat {
    /// The format a path names: `.pdb`/`.ent`, `.gro`, `.cif`/`.mmcif`, `.bcif`, `.psf`,
    /// `.prmtop`/`.parm7`/`.top` or a file named `prmtop` (AMBER; [`Topology::open_as`] reads
    /// a `.top` that does not start as a prmtop does as a GROMACS topology, since GROMACS names
    /// its topologies so too), `.itp` (GROMACS), `.tpr`, `.data`/`.lmp` or `data.*` (LAMMPS).
    /// A final `.gz` is looked through (`top.psf.gz` is PSF, read decompressed by
    /// [`Topology::open`]).
    pub fn from_path(path: &Path) -> Option<TopologyFormat> {
        let path = crate::gz::inner_path(path);
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        if name.starts_with("data.") {
            return Some(TopologyFormat::LammpsData);
        }
        if name == "prmtop" {
            return Some(TopologyFormat::Prmtop);
        }
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "pdb" | "ent" => TopologyFormat::Pdb,
            "gro" => TopologyFormat::Gro,
            "cif" | "mmcif" => TopologyFormat::Mmcif,
            "bcif" => TopologyFormat::Bcif,
            "data" | "lmp" => TopologyFormat::LammpsData,
            "psf" => TopologyFormat::Psf,
            "tpr" => TopologyFormat::Tpr,
            "prmtop" | "parm7" | "top" => TopologyFormat::Prmtop,
            "itp" => TopologyFormat::GromacsTop,
            _ => return None,
        })
    }
}

/// Per-atom labels and bonds of a system; see the module doc.
///
/// Every per-atom vector is empty (the file has no such column) or [`Topology::n_atoms`] long.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Topology {
    file: Arc<str>,
    n_atoms: usize,
    /// Atom names (PDB/GRO).
    pub names: Vec<Label>,
    /// Elements (PDB element column, else guessed from names like the readers do).
    pub elements: Vec<Element>,
    /// Atom types (LAMMPS data).
    pub types: Vec<Label>,
    /// Atom serials / ids as written in the file.
    pub ids: Vec<i64>,
    /// Residue names.
    pub res_names: Vec<Label>,
    /// Residue numbers (LAMMPS: molecule ids).
    pub res_ids: Vec<i64>,
    /// Chain identifiers (PDB, mmCIF, AMBER `RESIDUE_CHAINID`).
    pub chains: Vec<Label>,
    /// Segment identifiers (PSF `segid`, PDB columns 73-76).
    pub segments: Vec<Label>,
    /// Partial charges in e (PSF, AMBER prmtop, GROMACS .tpr, LAMMPS data styles `full` and
    /// `charge`); given to frames as their `charge` property.
    pub charges: Vec<f32>,
    /// Masses in u as the force field gives them (GROMACS .tpr: united atoms, heavy hydrogens,
    /// coarse-grained beads); given to frames as their `mass` property.
    pub masses: Vec<f32>,
    /// Bonds as atom index pairs `[i, j]` with `i < j`, sorted, each once.
    pub bonds: Vec<[u32; 2]>,
    /// The periodic box's angles in degrees, when the topology gives them (AMBER prmtop
    /// `BOX_DIMENSIONS`: a truncated octahedron's 109.47°): for trajectories whose box lines
    /// hold lengths only ([`crate::ReadOptions::box_angles`]).
    pub box_angles: Option<[f64; 3]>,
}

/// A text line being parsed: its number and byte offset, for errors.
pub(crate) struct LineAt {
    pub(crate) line: u64,
    pub(crate) byte: u64,
}

pub(crate) fn at(file: &Arc<str>, l: &LineAt) -> Location {
    Location {
        file: file.clone(),
        frame: None,
        line: Some(l.line),
        byte: Some(l.byte),
    }
}

pub(crate) fn parse_err(
    file: &Arc<str>,
    l: &LineAt,
    expected: &'static str,
    found: &[u8],
) -> Error {
    Error::Parse {
        at: at(file, l),
        expected,
        found: Error::found(found),
    }
}

/// Streams the lines of a file with their numbers and byte offsets (one line buffered).
pub(crate) struct Lines<R> {
    src: BufReader<R>,
    buf: Vec<u8>,
    line: u64,
    byte: u64,
    next_byte: u64,
    file: Arc<str>,
}

impl<R: Read> Lines<R> {
    pub(crate) fn new(src: R, file: Arc<str>) -> Lines<R> {
        Lines {
            src: BufReader::new(src),
            buf: Vec::new(),
            line: 0,
            byte: 0,
            next_byte: 0,
            file,
        }
    }

    /// The next line (without its end), or `None` at the end of the file.
    /// Where the file ends (the line after the last one read), for truncation errors.
    pub(crate) fn end(&self) -> LineAt {
        LineAt {
            line: self.line + 1,
            byte: self.next_byte,
        }
    }

    pub(crate) fn next_line(&mut self) -> Result<Option<(&[u8], LineAt)>, Error> {
        self.buf.clear();
        let n = self
            .src
            .read_until(b'\n', &mut self.buf)
            .map_err(|source| Error::Io {
                at: Location {
                    file: self.file.clone(),
                    byte: Some(self.next_byte),
                    ..Location::default()
                },
                source,
            })?;
        if n == 0 {
            return Ok(None);
        }
        self.byte = self.next_byte;
        self.next_byte += n as u64;
        self.line += 1;
        let mut s: &[u8] = &self.buf;
        while let [rest @ .., b'\n' | b'\r'] = s {
            s = rest;
        }
        Ok(Some((
            s,
            LineAt {
                line: self.line,
                byte: self.byte,
            },
        )))
    }
}

/// What a `.top` file whose first bytes are `head` is: AMBER's prmtop when it starts as one
/// does (`%VERSION` or `%FLAG`), else GROMACS's topology.
fn top_format(head: &[u8]) -> TopologyFormat {
    if head.starts_with(b"%VERSION") || head.starts_with(b"%FLAG") {
        TopologyFormat::Prmtop
    } else {
        TopologyFormat::GromacsTop
    }
}

impl Topology {
    /// Reads the topology of `path`, its format told by the name (see [`TopologyFormat`]).
    ///
    /// A gzip file (`top.psf.gz`, `1abc.cif.gz`) is read decompressed, as by
    /// [`Trajectory::open`]: byte offsets in its errors count decompressed bytes.
    pub fn open(path: impl AsRef<Path>) -> Result<Topology, Error> {
        Topology::open_with(path, &crate::gromacs_top::GromacsTopOptions::default())
    }

    /// [`Topology::open`], with the defines and include directories a GROMACS topology is
    /// preprocessed with (grompp's `define = -DPOSRES`; unused by the other formats).
    pub fn open_with(
        path: impl AsRef<Path>,
        gromacs: &crate::gromacs_top::GromacsTopOptions,
    ) -> Result<Topology, Error> {
        let path = path.as_ref();
        let name: Arc<str> = path.display().to_string().into();
        let Some(format) = TopologyFormat::from_path(path) else {
            return Err(Error::Unsupported {
                file: name,
                what: "topology format (expected .pdb, .gro, .cif/.mmcif, .bcif, .psf, .prmtop/.parm7, .tpr, .top/.itp (GROMACS), or a LAMMPS data file: .data, .lmp, data.*)",
            });
        };
        Topology::open_as_with(path, format, gromacs)
    }

    /// The format [`Topology::open`] reads `path` as: [`TopologyFormat::from_path`], with a
    /// `.top` (gzipped too) told AMBER's or GROMACS's by its first line.
    pub fn format_of(path: impl AsRef<Path>) -> Result<Option<TopologyFormat>, Error> {
        let path = path.as_ref();
        let format = TopologyFormat::from_path(path);
        let is_top = crate::gz::inner_path(path)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("top"));
        if !is_top {
            return Ok(format);
        }
        let name: Arc<str> = path.display().to_string().into();
        let (mut file, _) = crate::gz::open(path, &name, false)?;
        let head = crate::trajectory::head(&mut file, &name, 64)?;
        Ok(Some(top_format(&head)))
    }

    /// Reads the topology of `path` as `format`; a gzip file is read decompressed, as by
    /// [`Topology::open`].
    ///
    /// A `.cif` named as PDBx/mmCIF is told from a crystallographic CIF by its tags, as
    /// [`Trajectory::open`] tells them ([`Format::cif_kind`]); `.mmcif` is always mmCIF.
    pub fn open_as(path: impl AsRef<Path>, format: TopologyFormat) -> Result<Topology, Error> {
        Topology::open_as_with(
            path,
            format,
            &crate::gromacs_top::GromacsTopOptions::default(),
        )
    }

    fn open_as_with(
        path: impl AsRef<Path>,
        format: TopologyFormat,
        gromacs: &crate::gromacs_top::GromacsTopOptions,
    ) -> Result<Topology, Error> {
        let path = path.as_ref();
        let name: Arc<str> = path.display().to_string().into();
        // A topology must be whole: a cut gzip stream is an error.
        let (mut file, _) = crate::gz::open(path, &name, false)?;
        let is_top = crate::gz::inner_path(path)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("top"));
        // A .top is AMBER's when it starts as a prmtop does, else GROMACS's.
        let mut format = format;
        if matches!(format, TopologyFormat::Prmtop | TopologyFormat::GromacsTop) && is_top {
            let head = crate::trajectory::head(&mut file, &name, 64)?;
            format = top_format(&head);
        }
        let format = if format == TopologyFormat::Mmcif {
            match crate::trajectory::cif_kind_of(&mut file, path, &name)? {
                Format::CrystalCif => TopologyFormat::CrystalCif,
                _ => TopologyFormat::Mmcif,
            }
        } else {
            format
        };
        if format == TopologyFormat::GromacsTop {
            return crate::gromacs_top::read_top(file, &name, gromacs);
        }
        Topology::from_reader(file, format, &name)
    }

    /// Reads `src` (named `name` in errors) as `format`. A GROMACS topology's `#include`s are
    /// looked for beside the path `name`, then in GROMACS's data directories.
    ///
    /// ```
    /// use texmap_md_io::{Topology, TopologyFormat};
    /// let data = "water\n\n3 atoms\n2 bonds\n\nAtoms # full\n\n\
    ///             1 1 1 -0.8 0.0 0.0 0.0\n3 1 2 0.4 -0.3 0.9 0.0\n2 1 2 0.4 0.96 0.0 0.0\n\n\
    ///             Bonds\n\n1 1 1 2\n2 1 1 3\n";
    /// let t = Topology::from_reader(std::io::Cursor::new(data), TopologyFormat::LammpsData, "w.data")?;
    /// assert_eq!(t.ids, [1, 2, 3]); // ordered by id, as LAMMPS dumps are read
    /// assert_eq!(t.types[1].as_str(), "2");
    /// assert_eq!(t.bonds, [[0, 1], [0, 2]]);
    /// # Ok::<(), texmap_md_io::Error>(())
    /// ```
    pub fn from_reader<R: Read + std::io::Seek>(
        mut src: R,
        format: TopologyFormat,
        name: &str,
    ) -> Result<Topology, Error> {
        let file: Arc<str> = name.into();
        match format {
            TopologyFormat::Pdb => {
                let start = src.stream_position().map_err(|source| Error::Io {
                    at: Location::file(&file),
                    source,
                })?;
                let mut t =
                    Topology::first_frame(Trajectory::from_reader(&mut src, Format::Pdb, name)?)?;
                src.seek(std::io::SeekFrom::Start(start))
                    .map_err(|source| Error::Io {
                        at: Location::file(&file),
                        source,
                    })?;
                t.bonds = pdb_conect(src, &file, &t.ids)?;
                Ok(t)
            }
            TopologyFormat::Gro => {
                Topology::first_frame(Trajectory::from_reader(src, Format::Gro, name)?)
            }
            TopologyFormat::Mmcif => {
                Topology::first_frame(Trajectory::from_reader(src, Format::Mmcif, name)?)
            }
            TopologyFormat::Bcif => {
                Topology::first_frame(Trajectory::from_reader(src, Format::Bcif, name)?)
            }
            TopologyFormat::CrystalCif => {
                Topology::first_frame(Trajectory::from_reader(src, Format::CrystalCif, name)?)
            }
            TopologyFormat::LammpsData => {
                // The trajectory reader's parse (module `lammps_data`), its frame's labels kept.
                let mut traj = Trajectory::from_reader(src, Format::LammpsData, name)?;
                let mut f = Frame::new();
                if !traj.read_next(&mut f)? {
                    return Err(Error::Truncated {
                        at: Location::file(&file),
                        expected:
                            "a LAMMPS data file: a title, an 'N atoms' line, the Atoms section"
                                .into(),
                    });
                }
                Ok(Topology::from_lammps_data(&f, &file))
            }
            TopologyFormat::Psf => crate::psf::read_psf(src, &file),
            TopologyFormat::Prmtop => crate::prmtop::read_prmtop(src, &file),
            TopologyFormat::GromacsTop => crate::gromacs_top::read_top(
                src,
                &file,
                &crate::gromacs_top::GromacsTopOptions::default(),
            ),
            TopologyFormat::Tpr => {
                let mut bytes = Vec::new();
                src.read_to_end(&mut bytes).map_err(|source| Error::Io {
                    at: Location::file(&file),
                    source,
                })?;
                Ok(crate::tpr::read_tpr(&bytes, &file)?.topology)
            }
        }
    }

    /// The labels of a trajectory's first frame (no bonds).
    fn first_frame<R: Read + std::io::Seek>(mut traj: Trajectory<R>) -> Result<Topology, Error> {
        let mut f = Frame::new();
        if !traj.read_next(&mut f)? {
            return Err(Error::Parse {
                at: Location::file(&traj.name().into()),
                expected: "at least one atom record",
                found: "end of file".into(),
            });
        }
        Ok(Topology::from_frame(&f, traj.name()))
    }

    /// A topology from its columns (empty vectors for what the file lacks).
    #[allow(clippy::too_many_arguments)] // one argument per column, named at the one call site
    pub(crate) fn from_parts(
        file: Arc<str>,
        names: Vec<Label>,
        elements: Vec<Element>,
        types: Vec<Label>,
        ids: Vec<i64>,
        res_names: Vec<Label>,
        res_ids: Vec<i64>,
        bonds: Vec<[u32; 2]>,
    ) -> Topology {
        Topology {
            file,
            n_atoms: ids.len(),
            names,
            elements,
            types,
            ids,
            res_names,
            res_ids,
            chains: Vec::new(),
            segments: Vec::new(),
            charges: Vec::new(),
            masses: Vec::new(),
            bonds,
            box_angles: None,
        }
    }

    /// The topology of a LAMMPS data file's frame: types, ids, molecule ids, elements (from
    /// the masses or their comments), charges and bonds.
    fn from_lammps_data(f: &Frame, file: &Arc<str>) -> Topology {
        Topology {
            file: file.clone(),
            n_atoms: f.n_atoms(),
            names: Vec::new(),
            elements: f.elements.clone(),
            types: f.types.clone(),
            ids: f.ids.clone(),
            res_names: Vec::new(),
            res_ids: f.res_ids.clone(),
            chains: Vec::new(),
            segments: Vec::new(),
            charges: f
                .property("charge")
                .map(<[f32]>::to_vec)
                .unwrap_or_default(),
            masses: Vec::new(),
            bonds: f.bonds.clone(),
            box_angles: None,
        }
    }

    /// The labels of `frame` as a topology named `name` (no bonds).
    pub fn from_frame(frame: &Frame, name: &str) -> Topology {
        let elements = if frame.elements.is_empty() && !frame.names.is_empty() {
            (0..frame.n_atoms())
                .map(|i| crate::style::atom_element(frame, i))
                .collect()
        } else {
            frame.elements.clone()
        };
        Topology {
            file: name.into(),
            n_atoms: frame.n_atoms(),
            names: frame.names.clone(),
            elements,
            types: frame.types.clone(),
            ids: frame.ids.clone(),
            res_names: frame.res_names.clone(),
            res_ids: frame.res_ids.clone(),
            chains: frame.chains.clone(),
            segments: frame.segments.clone(),
            charges: Vec::new(),
            masses: Vec::new(),
            bonds: Vec::new(),
            box_angles: None,
        }
    }

    /// The file the topology was read from (as errors name it).
    pub fn name(&self) -> &str {
        &self.file
    }

    /// Number of atoms.
    pub fn n_atoms(&self) -> usize {
        self.n_atoms
    }

    /// Number of distinct residues (consecutive atoms with the same residue number and name
    /// form one residue, as in PDB/GRO files); 0 without residue numbers.
    pub fn n_residues(&self) -> usize {
        let mut n = 0;
        for i in 0..self.res_ids.len() {
            let same = i > 0
                && self.res_ids[i] == self.res_ids[i - 1]
                && self.res_names.get(i) == self.res_names.get(i - 1);
            if !same {
                n += 1;
            }
        }
        n
    }

    /// Gives frame number `frame_index` of the trajectory `trajectory` (a name for errors) the
    /// topology's per-atom labels, replacing the frame's own. The frame's positions, cell,
    /// radii and colours stay. An atom-count mismatch is [`Error::TopologyMismatch`].
    pub fn apply(
        &self,
        frame: &mut Frame,
        trajectory: &str,
        frame_index: usize,
    ) -> Result<(), Error> {
        if frame.n_atoms() != self.n_atoms {
            return Err(Error::TopologyMismatch {
                topology: self.file.clone(),
                topology_atoms: self.n_atoms,
                trajectory: trajectory.into(),
                frame: frame_index,
                frame_atoms: frame.n_atoms(),
            });
        }
        // Labels the topology lacks but the frame has (a dump's types) are kept.
        let take = |dst: &mut Vec<Label>, src: &Vec<Label>| {
            if !src.is_empty() {
                dst.clone_from(src);
            }
        };
        take(&mut frame.names, &self.names);
        take(&mut frame.types, &self.types);
        take(&mut frame.res_names, &self.res_names);
        take(&mut frame.chains, &self.chains);
        take(&mut frame.segments, &self.segments);
        // An element the topology does not know (a LAMMPS type of no element) keeps the frame's
        // (a dump's `element` column).
        if self.elements.len() == frame.elements.len() {
            for (d, s) in frame.elements.iter_mut().zip(&self.elements) {
                if !s.is_unknown() {
                    *d = *s;
                }
            }
        } else if !self.elements.is_empty() {
            frame.elements.clone_from(&self.elements);
        }
        if !self.res_ids.is_empty() {
            frame.res_ids.clone_from(&self.res_ids);
        }
        if !self.ids.is_empty() {
            frame.ids.clone_from(&self.ids);
        }
        if !self.charges.is_empty() {
            frame.property_mut("charge").clone_from(&self.charges);
        }
        if !self.masses.is_empty() {
            frame.property_mut("mass").clone_from(&self.masses);
        }
        Ok(())
    }
}

/// Sorts, orders (`i < j`) and deduplicates bonds.
pub(crate) fn tidy(bonds: &mut Vec<[u32; 2]>) {
    for b in bonds.iter_mut() {
        if b[0] > b[1] {
            b.swap(0, 1);
        }
    }
    bonds.sort_unstable();
    bonds.dedup();
}

/// The bonds of a PDB file's `CONECT` records: columns 7-11 the atom, 12-16, 17-21, 22-26,
/// 27-31 the atoms bonded to it (serial numbers, hybrid-36 allowed). `ids` are the serials of
/// the first model's atoms.
fn pdb_conect<R: Read>(src: R, file: &Arc<str>, ids: &[i64]) -> Result<Vec<[u32; 2]>, Error> {
    let index: HashMap<i64, u32> = ids
        .iter()
        .enumerate()
        .map(|(k, id)| (*id, k as u32))
        .collect();
    let mut bonds = Vec::new();
    let mut lines = Lines::new(src, file.clone());
    while let Some((line, pos)) = lines.next_line()? {
        if !line.starts_with(b"CONECT") {
            continue;
        }
        let col = |a: usize, b: usize| -> &[u8] {
            let b = b.min(line.len());
            if a >= b { &[] } else { &line[a..b] }
        };
        let serial = |field: &[u8]| -> Result<Option<u32>, Error> {
            if trim(field).is_empty() {
                return Ok(None);
            }
            let Some(s) = crate::pdb::hy36_decode(field, 5) else {
                return Err(parse_err(file, &pos, "a CONECT atom serial number", field));
            };
            match index.get(&s) {
                Some(i) => Ok(Some(*i)),
                None => Err(parse_err(
                    file,
                    &pos,
                    "a CONECT serial number of an atom of the first model",
                    field,
                )),
            }
        };
        let Some(a) = serial(col(6, 11))? else {
            return Err(parse_err(file, &pos, "a CONECT atom serial number", line));
        };
        for k in 0..4 {
            if let Some(b) = serial(col(11 + 5 * k, 16 + 5 * k))?
                && a != b
            {
                bonds.push([a, b]);
            }
        }
    }
    tidy(&mut bonds);
    Ok(bonds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn lammps_styles_and_errors() {
        let data = "title\n\n3 atoms\n1 bonds\n\nAtoms # atomic\n\n3 2 0 0 0\n1 1 1 0 0\n2 1 2 0 0\n\nBonds\n\n1 1 3 1\n";
        let t = Topology::from_reader(Cursor::new(data), TopologyFormat::LammpsData, "d").unwrap();
        assert_eq!(t.ids, vec![1, 2, 3]);
        assert_eq!(
            t.types.iter().map(|l| l.as_str()).collect::<Vec<_>>(),
            ["1", "1", "2"]
        );
        assert_eq!(t.bonds, vec![[0, 2]]);
        assert!(t.res_ids.is_empty());
        // 6 columns without a style: ambiguous, an error on that line.
        let amb = "t\n2 atoms\nAtoms\n\n1 1 1 0 0 0\n2 1 1 0 0 0\n";
        let e = Topology::from_reader(Cursor::new(amb), TopologyFormat::LammpsData, "d")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("d: frame 0, line 5"), "{e}");
        // A bond naming a missing atom.
        let bad = "t\n1 atoms\n1 bonds\nAtoms # full\n\n1 1 1 0.0 0 0 0\nBonds\n\n1 1 1 7\n";
        let e = Topology::from_reader(Cursor::new(bad), TopologyFormat::LammpsData, "d")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("d: frame 0, line 9") && e.contains("'7'"),
            "{e}"
        );
        // Fewer atoms than announced.
        let cut = "t\n3 atoms\nAtoms # full\n\n1 1 1 0.0 0 0 0\n";
        let e = Topology::from_reader(Cursor::new(cut), TopologyFormat::LammpsData, "d")
            .unwrap_err()
            .to_string();
        assert!(e.contains("2 more lines of the Atoms section"), "{e}");
    }

    #[test]
    fn apply_checks_the_count() {
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 2];
        let mut t = Topology::from_frame(&f, "top.gro");
        t.names = vec![Label::new("OW").unwrap(); 2];
        t.apply(&mut f, "run.xtc", 0).unwrap();
        assert_eq!(f.names.len(), 2);
        f.positions.push([0.0; 3]);
        let e = t.apply(&mut f, "run.xtc", 4).unwrap_err().to_string();
        assert!(
            e.contains("top.gro") && e.contains("run.xtc") && e.contains("frame 4"),
            "{e}"
        );
    }
}
