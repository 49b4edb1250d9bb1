//! Molecular-dynamics trajectories for the sphere renderers: readers and writers of the usual
//! file formats, streaming frames, and element tables (radius, colour).
//!
//! - [`Trajectory`] reads XYZ / extended XYZ, PDB, PDBx/mmCIF (the first data block's
//!   `_atom_site`, models as frames; the text and its BinaryCIF encoding, `.bcif`), GRO and LAMMPS dumps (text, and binary `.bin` read to the same frames), MDL SDF/MOL and Tripos MOL2
//!   (records as frames, with the bonds they list: [`Frame::bonds`]), VASP POSCAR/CONTCAR
//!   and XDATCAR (the ionic steps as frames, a changing cell too), crystallographic CIF (COD,
//!   ICSD, Materials Project: each data block a frame, the asymmetric unit expanded by the
//!   file's symmetry operations; a `.cif` is told from PDBx/mmCIF by its tags), LAMMPS data files
//!   (one frame: the atom style's columns, the box, masses and their elements, velocities and
//!   image flags as properties, the `Bonds` as [`Frame::bonds`]), AMBER's ASCII trajectories
//!   (mdcrd: the atom count comes from the topology, [`ReadOptions::atoms`]) and restarts
//!   (rst7 / inpcrd, with velocities and box), CHARMM coordinate files
//!   (`.crd`/`.cor`, standard and `EXT`: segment ids, the WMAIN weighting as the `wmain`
//!   property; a `.crd` is CHARMM's when it starts with a `*` title, else AMBER's) and PQR
//!   (PDB2PQR/APBS: partial charges and radii as the `charge` and `radius` properties, chains,
//!   MODEL/ENDMDL frames), AutoDock PDBQT (Vina's poses as frames; charges, AutoDock types and
//!   the elements they name), Tinker `.xyz`/`.arc` with their bonds, DL_POLY CONFIG/HISTORY,
//!   XCrySDen XSF / AXSF (each structure a frame, with its cell and forces), Quantum ESPRESSO
//!   pw.x output (every ionic step of scf, relax, vc-relax, md, vc-md runs a frame, as ASE
//!   counts them: cell, forces, energy and stress) and input (its ibrav or CELL_PARAMETERS
//!   cell), VASP's vasprun.xml and OUTCAR (every ionic step a frame, as ASE counts them: cell,
//!   forces, energy, free energy and stress)
//!   (and the binary DCD, XTC,
//!   TRR, AMBER NetCDF, NAMD's binary `.coor` and HOOMD-blue GSD: particle types, diameters, per-particle properties
//!   and bonds, by the hoomd schema's rule for what a frame omits) one frame at a time into a
//!   reusable [`Frame`], or any frame by index.
//!   Any of them may be gzip- or bzip2-compressed (`1abc.cif.gz`, `prod.mdcrd.bz2`; topologies too): it is
//!   inflated once into a temporary file, so the byte offsets of a `.gz` file's errors count
//!   decompressed bytes, except for damage to the compressed stream itself (compressed offset).
//! - [`Sequence`] reads a trajectory in several files (a run continued in parts, a LAMMPS
//!   dump per step: [`sequence::expand`] for `dump.*.lammpstrj`) as one.
//! - [`Topology`] reads atom names, elements, residues and bonds (PDB, PDBx/mmCIF and BinaryCIF, GRO, PSF,
//!   AMBER prmtop, GROMACS .tpr and .top, LAMMPS data file) and gives them to the frames of a
//!   coordinate-only trajectory of the same atoms; [`read_tpr`] also gives a .tpr's starting
//!   positions, velocities and box.
//! - [`bonds`] finds bonds by distance (covalent radii, a cell grid, minimum image) and [`pbc`]
//!   wraps atoms into the box or makes bonded molecules whole across it; [`replicate`] copies a
//!   frame and its bonds along the cell vectors (periodic images, as OVITO's Replicate);
//!   [`coordination`] counts each atom's neighbours within a cutoff (and groups them into
//!   clusters), [`cna`] classifies its crystal structure, [`centrosymmetry`] measures how far
//!   its neighbours are from opposite pairs and [`strain`] its local deformation against a
//!   reference configuration, [`wigner_seitz`] its vacancies and interstitials, [`voronoi`] its Voronoi
//!   cell (volume, coordination, index), [`orientation`] its lattice orientation (PTM's) and
//!   [`grains`] the grains of a polycrystal, [`rdf`] the radial distribution functions of a frame, as OVITO's analyses do, [`msd`] each atom's squared displacement followed across the periodic boundaries and the mean over every time origin with its diffusion coefficient, [`vacf`] the velocity autocorrelation, its Green–Kubo diffusion coefficient and the vibrational density of states, [`conformations`] clusters the frames' shapes on their pairwise RMSD (gmx cluster's gromos and single linkage), [`rmsf`] each atom's fluctuation about its mean position, [`shape`] the radius of gyration and shape anisotropy of a group, [`contacts`] the fraction of a reference's native contacts a frame keeps, [`distance_map`] the residue–residue map of smallest distances and contacts over a run (gmx mdmat), [`survival`] how long members of a changing set stay (water residence, hydrogen-bond lifetimes), [`sasa`] solvent-accessible surface areas, [`dihedrals`] the backbone's φ, ψ and ω, [`profile`] density profiles along a cell axis, [`density`] number densities on a 3-D grid averaged over frames (MDAnalysis's DensityAnalysis, VMD's volmap), and [`expr`] computes a number per atom
//!   from a formula (OVITO's Compute property); [`hbonds`] finds hydrogen bonds by
//!   MDAnalysis's geometric criterion.
//! - [`energy`] reads energies over time: GROMACS energy files (`.edr`, every term with its
//!   unit) and the thermo tables of LAMMPS logs (the runs joined), as named columns.
//! - [`values`] reads per-atom numbers from a text file (an analysis result, a column or a row
//!   per frame) to give the frames as a property.
//! - [`volume`] reads volumetric data (Gaussian cube; VASP CHGCAR, CHG, PARCHG, LOCPOT, ELFCAR,
//!   AECCAR; XCrySDen XSF `DATAGRID_3D`; OpenDX from APBS, VMD and MDAnalysis; CCP4/MRC maps of cryo-EM and crystallography) into grids
//!   with their atoms ([`volume::read_volumes`]) and writes OpenDX ([`volume::write_dx`]); as
//!   trajectories these files are one frame, the atoms
//!   (`Format::Cube`, `Format::Vasp`), an XSF / AXSF file one per structure (`Format::Xsf`).
//! - [`Writer`] writes extended XYZ and LAMMPS text dumps (positions, ids, types, velocities,
//!   radii, colours and every named property, for OVITO, ASE and LAMMPS to read back), GRO,
//!   PDB, PDBx/mmCIF, DCD, XTC, TRR, AMBER NetCDF, HOOMD-blue GSD, VASP POSCAR / XDATCAR and
//!   MDL SD files; [`Writer::dropped`] names what of a frame the format has no place for
//!   ([`Dropped`]: velocities, forces, a property, bonds, the cell, ...).
//! - [`elements`] maps atom names to elements, gives van der Waals radii and CPK colours, and
//!   [`AtomStyle`] resolves each atom's radius and colour with user overrides.
//!
//! Positions are in Å whatever the file's units (lengths in units a file does not state, as in a
//! HOOMD-blue GSD file, are taken as Å); errors name the file, frame, line and byte.
//!
//! # What every reader promises
//! - **Located errors.** Damage is an [`Error`] naming the file and the place (frame, line, byte
//!   offset) and what was expected there; never a panic.
//! - **Bounded memory.** Nothing is sized from a count in a header before the bytes the file
//!   has left could hold it (an XTC header claiming 2^31 atoms over 1 KB is refused, not
//!   allocated); text readers reserve at most one atom per 8 bytes of the file.
//! - **No silent loss.** A last frame cut short is an [`Error::Truncated`] for that frame, from
//!   [`Trajectory::n_frames`] too, unless `allow_truncated` ([`ReadOptions`]) asks to keep the
//!   complete frames, and then it is a warning ([`Trajectory::warnings`]). A PDB or mmCIF model
//!   with another atom count than model 1, or a PDB atom record whose name is damaged, is an
//!   error. The one deliberate drop: of an mmCIF atom's alternate locations only the first is
//!   kept (as gemmi does), and each frame that lost rows says how many in a warning.
//! - **Sane values.** Coordinates and cell lengths are finite and within ±[`MAX_COORDINATE`]
//!   (10^7 Å); beyond it a value is damage, reported with the frame and the atom.
//!
//! docs/RELIABILITY.md gives the fuzz campaign that checks these promises on every build.
//!
//! **Architecture invariant:** md-io depends on no other crate of texmap; it is reusable alone.
//!
//! # Example
//! ```
//! use texmap_md_io::{Format, Frame, Trajectory};
//! let xyz = "2\nwater fragment\nO 0.0 0.0 0.0\nH 0.96 0.0 0.0\n";
//! let mut traj = Trajectory::from_reader(std::io::Cursor::new(xyz), Format::Xyz, "frag.xyz")?;
//! let mut frame = Frame::new();
//! while traj.read_next(&mut frame)? {
//!     assert_eq!(frame.n_atoms(), 2);
//!     assert_eq!(frame.elements[0].symbol(), "O");
//!     assert_eq!(frame.positions[1], [0.96, 0.0, 0.0]);
//! }
//! # Ok::<(), texmap_md_io::Error>(())
//! ```
//!
//! # How a format plugs in
//! Formats are a closed set: the [`Format`] enum plus one variant per format in the private
//! `Reader` enum (src/trajectory.rs) and `WriterKind` enum (src/writer.rs), dispatched by the
//! `each_reader!` / `each_writer!` macros there. To add a format:
//! 1. write `src/<fmt>.rs` with a reader type `XxxReader<R: Read + Seek>` having
//!    - `fn new(src: R, file: Arc<str>) -> Result<Self, Error>` (read and check the header),
//!    - `fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error>`: clear `frame`,
//!      fill it (Å, finite, per-atom vectors empty or n_atoms long), `Ok(false)` at the end; on
//!      a damaged frame return an error with a [`Location`] and stay at that frame,
//!    - `fn seek_frame(&mut self, n: usize) -> Result<bool, Error>`: make `read_next` read frame
//!      `n` next, `Ok(false)` when there is no frame `n` (build the frame index lazily),
//!    - `fn n_frames(&mut self) -> Result<usize, Error>` that keeps the read position and
//!      gives a damaged or cut frame's error rather than a shorter count (the `Trajectory`
//!      turns a cut end into a warning under `allow_truncated`);
//!    - and sizes nothing from a header before checking that the file can hold it;
//! 2. add the variant to `Reader`, an arm to `each_reader!` and to `Trajectory::from_reader`;
//! 3. for a writer, a type with `fn write_frame(&mut self, frame: &Frame) -> std::io::Result<()>`
//!    and `fn finish(&mut self) -> std::io::Result<()>`, a `WriterKind` variant and arms.
//!
//! Text formats instead implement the private `TextFormat` trait (src/text.rs) and get
//! streaming, the line-scan index and error positions from `TextReader`.

mod amber;
mod asetraj;
mod bcif;
pub mod bonds;
pub mod cells;
pub mod centrosymmetry;
mod chgcar;
mod cif;
pub mod cna;
mod components;
pub mod conformations;
pub mod contacts;
pub mod coordination;
mod correlate;
mod crd;
mod crystal_cif;
mod cube;
mod cursor;
mod dcd;
pub mod density;
pub mod dihedrals;
pub mod distance_map;
mod dlpoly;
mod dropped;
mod dx;
mod eigen;
pub mod elements;
pub mod energy;
mod error;
mod espresso;
pub mod expr;
mod format;
mod frame;
pub mod grains;
mod gro;
mod gromacs_top;
mod gsd;
mod gsd_writer;
mod gz;
pub mod hbonds;
mod lammps;
mod lammps_bin;
mod lammps_data;
mod lammps_data_writer;
mod lammps_dump_writer;
pub mod membrane;
mod mmcif;
mod mmcif_writer;
mod mol2;
mod mrc;
pub mod msd;
mod namdbin;
pub mod ndx;
mod neighbours;
mod netcdf;
mod netcdf_writer;
pub mod order;
pub mod orientation;
pub mod parse;
pub mod pbc;
pub mod pca;
mod pdb;
mod pqr;
mod prmtop;
pub mod profile;
mod psf;
pub mod rdf;
pub mod replicate;
pub mod rmsd;
pub mod rmsf;
pub mod rotation;
pub mod saltbridges;
pub mod sasa;
mod sdf;
mod sdf_writer;
pub mod secondary;
pub mod select;
pub mod sequence;
pub mod shape;
pub mod smooth;
pub mod strain;
pub mod style;
pub mod survival;
mod text;
mod tinker;
mod topology;
mod tpr;
mod trajectory;
mod trr;
mod trr_writer;
pub mod vacf;
pub mod values;
mod vasp;
mod vasp_out;
mod vasp_writer;
pub mod volume;
pub mod voronoi;
pub mod wigner_seitz;
mod writer;
mod xsf;
mod xtc;
mod xyz;

pub use dropped::{Dropped, Per};
pub use elements::Element;
pub use error::{Error, Location};
pub use format::Format;
pub use frame::{BOND_AROMATIC, Frame, Label, MAX_COORDINATE, Property, UnitCell};
pub use gromacs_top::{GromacsTopOptions, read_gromacs_top};
pub use mmcif::is_altloc_warning;
pub use select::{Selection, SelectionError};
pub use sequence::Sequence;
pub use style::{Appearance, AtomStyle, Selector, atom_element, atom_mass};
pub use topology::{Topology, TopologyFormat};
pub use tpr::{Tpr, read_tpr};
pub use trajectory::{FrameSource, ReadOptions, Trajectory};
pub use trr::WithoutPositions;
pub use writer::Writer;

/// molly, the XTC crate our decoder is measured against (benches/md_io.rs); not part of the API.
#[doc(hidden)]
pub use molly;
