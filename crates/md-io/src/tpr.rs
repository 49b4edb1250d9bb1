//! GROMACS run input files (`.tpr`): the topology grompp compiled — atoms with their names,
//! types, masses and charges, residues, molecule types and the force field's bonds — and the
//! starting positions, velocities and box.
//!
//! GROMACS users keep the `.tpr` beside every `.xtc`/`.trr`; it is the one file that says
//! which atoms are bonded (a `.gro` does not), so MDAnalysis, gorder and every `gmx` analysis
//! tool take it as the topology. Read here, as GROMACS's own `tpxio.cpp` reads it:
//!
//! - **Versions**: file versions 58 (GROMACS 4.0) to 139 and generations up to 29
//!   (GROMACS 2026), single and double precision. Files from before 4.0 are refused, as
//!   GROMACS refuses them. A file newer than version 139 of a known generation is read as the
//!   newest known layout, since GROMACS keeps the topology part readable within a generation.
//! - **Layout**: an XDR header (version string, precision, version, generation, atom count,
//!   which parts follow); from version 119 (GROMACS 2020) the body is GROMACS's in-memory
//!   serialisation, big-endian but with 1-byte booleans and characters, 2-byte shorts and
//!   strings as a 64-bit length and unpadded bytes; before it, the body is XDR as the header.
//!   The body is the box, the topology, the positions and velocities, then the run
//!   parameters, which are not read.
//! - **Topology**: the symbol table, the force-field parameters (skipped by each interaction
//!   type's size, the type numbers of old files renumbered as GROMACS renumbers them), the
//!   molecule types and the molecule blocks, expanded into per-atom columns.
//! - **Bonds** are GROMACS's chemical bonds (the interaction types it flags `IF_CHEMBOND`:
//!   bonds of every functional form, connection bonds, polarization springs, constraints,
//!   and SETTLE as two O–H bonds), the bonds `gmx trjconv -pbc mol` makes molecules whole
//!   by. Harmonic potentials (type 6, the elastic networks of Martini proteins), distance
//!   restraints and constraints or tabulated bonds "without connection" are not bonds and are
//!   not drawn; MDAnalysis counts them as bonds.
//! - **Residue numbers** follow GROMACS's tools (`gmx editconf -f md.tpr -o md.gro` writes
//!   the same): molecules of one residue (water, ions) are numbered on after the highest
//!   number of the others, which keep the numbers of the structure grompp read; a system of a
//!   single molecule keeps its numbers throughout.
//! - **Elements** come from the atom types' atomic numbers; where a type has none (−1, as in
//!   coarse-grained and united-atom force fields) from the name and mass, as for PSF files,
//!   and a massless site (a TIP4P virtual site) is no element.
//! - **Molecule types** are the atoms' segments (`segid SOL`); a molecule type named as
//!   `pdb2gmx` names chains (`Protein_chain_A`) gives its chain.
//!
//! Every count in the file is checked against the bytes left before anything is allocated,
//! every index against what it indexes; an error names the byte offset.

use std::io::Read;
use std::sync::Arc;

use crate::cursor::{IN_BOUNDS, first_out_of_bounds};
use crate::elements::Element;
use crate::error::{Error, Location};
use crate::frame::{Frame, Label, UnitCell};
use crate::topology::{Topology, tidy};

/// The oldest file version read (GROMACS 4.0), as GROMACS itself.
const OLDEST: i32 = 58;
/// The newest file generation known here: 28 in GROMACS 2025 and 2026, 29 written by
/// development builds of 2026 with the same topology layout.
const NEWEST_GENERATION: i32 = 29;
/// The file version from which the body is GROMACS's in-memory serialisation (2020).
const SIZE_FIELD: i32 = 119;

/// GROMACS's interaction function types, in the order of `ifunc.cpp` (the numbering of the
/// newest files; older files are renumbered by [`RENUMBER`]).
mod f {
    pub const BONDS: usize = 0;
    pub const G96BONDS: usize = 1;
    pub const MORSE: usize = 2;
    pub const CUBICBONDS: usize = 3;
    pub const CONNBONDS: usize = 4;
    pub const HARMONIC: usize = 5;
    pub const FENEBONDS: usize = 6;
    pub const TABBONDS: usize = 7;
    pub const TABBONDSNC: usize = 8;
    pub const RESTRAINTPOT: usize = 9;
    pub const ANGLES: usize = 10;
    pub const G96ANGLES: usize = 11;
    pub const RESTRANGLES: usize = 12;
    pub const LINEAR_ANGLES: usize = 13;
    pub const CROSS_BOND_BONDS: usize = 14;
    pub const CROSS_BOND_ANGLES: usize = 15;
    pub const UREY_BRADLEY: usize = 16;
    pub const QUARTIC_ANGLES: usize = 17;
    pub const TABANGLES: usize = 18;
    pub const PDIHS: usize = 19;
    pub const RBDIHS: usize = 20;
    pub const RESTRDIHS: usize = 21;
    pub const CBTDIHS: usize = 22;
    pub const FOURDIHS: usize = 23;
    pub const IDIHS: usize = 24;
    pub const PIDIHS: usize = 25;
    pub const TABDIHS: usize = 26;
    pub const CMAP: usize = 27;
    pub const GB12: usize = 28;
    pub const GB13: usize = 29;
    pub const GB14: usize = 30;
    pub const GBPOL: usize = 31;
    pub const NPSOLVATION: usize = 32;
    pub const LJ14: usize = 33;
    pub const LJC14_Q: usize = 35;
    pub const LJC_PAIRS_NB: usize = 36;
    pub const LJ: usize = 37;
    pub const BHAM: usize = 38;
    pub const LJ_RECIP: usize = 46;
    pub const POLARIZATION: usize = 48;
    pub const WATER_POL: usize = 49;
    pub const THOLE_POL: usize = 50;
    pub const ANHARM_POL: usize = 51;
    pub const POSRES: usize = 52;
    pub const FBPOSRES: usize = 53;
    pub const DISRES: usize = 54;
    pub const ORIRES: usize = 56;
    pub const ANGRES: usize = 58;
    pub const ANGRESZ: usize = 59;
    pub const DIHRES: usize = 60;
    pub const CONSTR: usize = 62;
    pub const CONSTRNC: usize = 63;
    pub const SETTLE: usize = 64;
    pub const VSITE1: usize = 65;
    pub const VSITE2: usize = 66;
    pub const VSITE2FD: usize = 67;
    pub const VSITE3: usize = 68;
    pub const VSITE3FD: usize = 69;
    pub const VSITE3FAD: usize = 70;
    pub const VSITE3OUT: usize = 71;
    pub const VSITE4FD: usize = 72;
    pub const VSITE4FDN: usize = 73;
    pub const VSITEN: usize = 74;
    pub const DENSITYFIT: usize = 76;
    pub const ENNPOT: usize = 78;
    pub const VTEMP: usize = 84;
    pub const PDISPCORR: usize = 85;
    pub const DVDL_COUL: usize = 90;
    pub const DVDL_VDW: usize = 91;
    pub const DVDL_BONDED: usize = 92;
    pub const DVDL_RESTRAINT: usize = 93;
    pub const DVDL_TEMPERATURE: usize = 94;
    /// The number of types.
    pub const COUNT: usize = 95;
}

/// Interaction types added after file version 57: (the first version that has it, the
/// type), ascending by type, as GROMACS's `ftupd` table. A file older than the version has
/// no list for the type, and its type numbers from that one up are one lower.
const RENUMBER: [(i32, usize); 25] = [
    (70, f::RESTRAINTPOT),
    (98, f::RESTRANGLES),
    (76, f::LINEAR_ANGLES),
    (98, f::RESTRDIHS),
    (98, f::CBTDIHS),
    (65, f::CMAP),
    (60, f::GB12),
    (61, f::GB13),
    (61, f::GB14),
    (72, f::GBPOL),
    (72, f::NPSOLVATION),
    (93, f::LJ_RECIP),
    (76, f::ANHARM_POL),
    (90, f::FBPOSRES),
    (121, f::VSITE1),
    (118, f::VSITE2FD),
    (117, f::DENSITYFIT),
    (137, f::ENNPOT),
    (69, f::VTEMP),
    (66, f::PDISPCORR),
    (79, f::DVDL_COUL),
    (79, f::DVDL_VDW),
    (79, f::DVDL_BONDED),
    (79, f::DVDL_RESTRAINT),
    (79, f::DVDL_TEMPERATURE),
];

/// The chemical-bond types of two atoms (GROMACS's `IF_CHEMBOND`), SETTLE aside.
const CHEMICAL_BONDS: [usize; 10] = [
    f::BONDS,
    f::G96BONDS,
    f::MORSE,
    f::CUBICBONDS,
    f::CONNBONDS,
    f::FENEBONDS,
    f::TABBONDS,
    f::POLARIZATION,
    f::ANHARM_POL,
    f::CONSTR,
];

/// What a `.tpr` file holds: its topology, the starting frame and what the header says.
#[derive(Clone, Debug)]
pub struct Tpr {
    /// The atoms, residues, molecule types and bonds.
    pub topology: Topology,
    /// The starting positions in Å (empty when the file has none).
    pub positions: Vec<[f64; 3]>,
    /// The starting velocities in Å/ps (empty when the file has none).
    pub velocities: Vec<[f64; 3]>,
    /// The box vectors in Å, rows a, b, c (`None` when the file has no box).
    pub cell: Option<[[f64; 3]; 3]>,
    /// The GROMACS version that wrote the file (`VERSION 2022.5`).
    pub writer: String,
    /// The file version (127 for GROMACS 2022).
    pub version: i32,
    /// Whether reals are 8 bytes (a double-precision GROMACS wrote it).
    pub double: bool,
    /// Per atom, the molecule (0-based, over the whole system).
    pub molecules: Vec<u32>,
}

/// Reads a `.tpr` file's bytes (`file` names it in errors).
pub fn read_tpr(bytes: &[u8], file: &Arc<str>) -> Result<Tpr, Error> {
    let mut r = Reader {
        b: bytes,
        pos: 0,
        file: file.clone(),
        double: false,
        compact: false,
    };
    let h = header(&mut r)?;
    if h.version >= SIZE_FIELD && h.generation >= 27 {
        let body = usize::try_from(h.body_size).unwrap_or(usize::MAX);
        let left = r.b.len() - r.pos;
        if body > left {
            return Err(r.truncated(format!(
                "the {body}-byte body the header announces ({left} bytes left)"
            )));
        }
        if left as u64 == 4 * h.body_size as u64 && h.body_size > 0 {
            return Err(Error::Unsupported {
                file: file.clone(),
                what: "a .tpr written by a GROMACS 2020 beta (its body is laid out as no release writes it); regenerate it with grompp",
            });
        }
        r.compact = true;
    }
    // The box and, for old Berendsen coupling, one real per coupling group.
    let mut cell = None;
    if h.has_box {
        let m = r.rvecs(3, "the box")?;
        cell = Some([m[0], m[1], m[2]].map(|v| v.map(|x| x * 10.0)));
        if h.version >= 51 {
            r.rvecs(3, "the box's relative shape")?;
        }
        r.rvecs(3, "the box's velocity")?;
        if h.version < 56 {
            r.rvecs(3, "an obsolete box matrix")?;
        }
    }
    if h.ngtc > 0 {
        let n = r.count(h.ngtc, r.real_size(), "temperature-coupling groups")?;
        if h.version < 69 {
            r.skip(n * r.real_size(), "temperature-coupling lambdas")?;
        }
        r.skip(n * r.real_size(), "temperature-coupling lambdas")?;
    }
    if !h.has_topology {
        return Err(Error::Parse {
            at: r.at(),
            expected: "a .tpr with a topology (the header says it has none)",
            found: "no topology".into(),
        });
    }
    let top = mtop(&mut r, h.version, h.natoms, h.has_x)?;
    let n = top.names.len();
    let mut positions = Vec::new();
    let mut velocities = Vec::new();
    // Positions and velocities, nm and nm/ps to Å and Å/ps; a value that is not finite (or
    // a position past 10^7 Å) is an error at its bytes.
    let mut vectors = |what: &'static str, limit: f64| -> Result<Vec<[f64; 3]>, Error> {
        let start = r.pos;
        let mut v = r.rvecs(n, what)?;
        for (k, p) in v.iter_mut().enumerate() {
            *p = p.map(|x| x * 10.0);
            if p.iter().any(|x| x.is_nan() || x.abs() > limit) {
                return Err(Error::Parse {
                    at: Location {
                        file: r.file.clone(),
                        byte: Some((start + 3 * r.real_size() * k) as u64),
                        ..Location::default()
                    },
                    expected: what,
                    found: format!("atom {k}: {p:?}"),
                });
            }
        }
        Ok(v)
    };
    if h.has_x {
        positions = vectors("positions within 10^7 Å", crate::MAX_COORDINATE)?;
    }
    if h.has_v {
        velocities = vectors("finite velocities", f64::MAX)?;
    }
    Ok(Tpr {
        molecules: top.molecules.clone(),
        topology: top.into_topology(file.clone()),
        positions,
        velocities,
        cell,
        writer: h.writer,
        version: h.version,
        double: r.double,
    })
}

/// The header's fields this reader uses.
struct Header {
    writer: String,
    version: i32,
    generation: i32,
    natoms: usize,
    ngtc: i32,
    has_topology: bool,
    has_x: bool,
    has_v: bool,
    has_box: bool,
    body_size: i64,
}

fn header(r: &mut Reader) -> Result<Header, Error> {
    let start = r.at();
    let not_tpr = Error::Parse {
        at: start,
        expected: "a GROMACS run input file (.tpr): a 'VERSION ...' string first",
        found: Error::found(&r.b[..r.b.len().min(40)]),
    };
    let writer = match r.string("the version string") {
        Ok(writer) if writer.starts_with("VERSION") => writer,
        _ => return Err(not_tpr),
    };
    let at = r.at();
    match r.int("the precision")? {
        4 => r.double = false,
        8 => r.double = true,
        p => {
            return Err(Error::Parse {
                at,
                expected: "the precision: 4 (single) or 8 (double) bytes a real",
                found: p.to_string(),
            });
        }
    }
    let version = r.int("the file version")?;
    if version < OLDEST {
        return Err(Error::Unsupported {
            file: r.file.clone(),
            what: "a .tpr from before GROMACS 4.0 (file version below 58), which GROMACS itself no longer reads; regenerate it with grompp",
        });
    }
    if (77..=79).contains(&version) {
        r.string("the file tag")?;
    }
    let at = r.at();
    let generation = r.int("the file generation")?;
    if generation > NEWEST_GENERATION {
        return Err(Error::Parse {
            at,
            expected: "a file generation up to 29 (GROMACS 2026); a newer GROMACS changed the topology's layout",
            found: generation.to_string(),
        });
    }
    if version >= 81 {
        r.string("the file tag")?;
    }
    let at = r.at();
    let natoms = r.int("the number of atoms")?;
    let natoms = usize::try_from(natoms).map_err(|_| Error::Parse {
        at,
        expected: "a number of atoms of 0 or more",
        found: natoms.to_string(),
    })?;
    let ngtc = r.int("the number of temperature-coupling groups")?;
    if version < 62 {
        r.int("an obsolete integer")?;
        r.real("an obsolete real")?;
    }
    if version >= 79 {
        r.int("the free-energy state")?;
    }
    r.real("lambda")?;
    r.boolean("whether run parameters follow")?;
    let has_topology = r.boolean("whether a topology follows")?;
    let has_x = r.boolean("whether positions follow")?;
    let has_v = r.boolean("whether velocities follow")?;
    r.boolean("whether forces follow")?;
    let has_box = r.boolean("whether a box follows")?;
    let mut body_size = 0;
    if version >= SIZE_FIELD && generation >= 27 {
        let at = r.at();
        body_size = r.int64("the body's size")?;
        if body_size < 0 {
            return Err(Error::Parse {
                at,
                expected: "the body's size in bytes, 0 or more",
                found: body_size.to_string(),
            });
        }
    }
    Ok(Header {
        writer,
        version,
        generation,
        natoms,
        ngtc,
        has_topology,
        has_x,
        has_v,
        has_box,
        body_size,
    })
}

/// One molecule type: its atoms and the chemical bonds among them.
struct MolType {
    name: String,
    /// Per atom: mass, charge, residue index within the molecule, atomic number.
    atoms: Vec<(f64, f64, usize, i32)>,
    names: Vec<String>,
    types: Vec<String>,
    /// Per residue: name, number.
    residues: Vec<(String, i64)>,
    bonds: Vec<[u32; 2]>,
}

/// The whole system, expanded to atoms.
struct System {
    names: Vec<Label>,
    types: Vec<Label>,
    res_names: Vec<Label>,
    res_ids: Vec<i64>,
    segments: Vec<Label>,
    chains: Vec<Label>,
    elements: Vec<Element>,
    masses: Vec<f32>,
    charges: Vec<f32>,
    bonds: Vec<[u32; 2]>,
    molecules: Vec<u32>,
}

impl System {
    fn into_topology(self, file: Arc<str>) -> Topology {
        let n = self.names.len();
        let mut t = Topology::from_parts(
            file,
            self.names,
            self.elements,
            self.types,
            (1..=n as i64).collect(),
            self.res_names,
            self.res_ids,
            self.bonds,
        );
        t.segments = self.segments;
        t.chains = self.chains;
        t.charges = self.charges;
        t.masses = self.masses;
        t
    }
}

/// A label from a name of the file, cut to [`Label::CAPACITY`] bytes at a character boundary.
fn label(s: &str) -> Label {
    let mut end = s.len().min(Label::CAPACITY);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    Label::new(&s[..end]).unwrap_or_default()
}

fn mtop(r: &mut Reader, version: i32, natoms: usize, has_x: bool) -> Result<System, Error> {
    // The symbol table: every name of the file, referred to by index.
    let at = r.at();
    let nsym = r.int("the number of symbols")?;
    let nsym = r.count_at(at, nsym, 8, "symbols")?;
    let mut symbols = Vec::with_capacity(nsym);
    for _ in 0..nsym {
        symbols.push(r.string("a symbol")?);
    }
    let sym = |r: &mut Reader, what: &'static str| -> Result<String, Error> {
        let at = r.at();
        let k = r.int(what)?;
        usize::try_from(k)
            .ok()
            .and_then(|k| symbols.get(k))
            .cloned()
            .ok_or_else(|| Error::Parse {
                at,
                expected: "an index into the symbol table",
                found: format!("{k} (the table holds {})", symbols.len()),
            })
    };
    sym(r, "the system's name")?;
    ffparams(r, version)?;

    let at = r.at();
    let nmoltype = r.int("the number of molecule types")?;
    let nmoltype = r.count_at(at, nmoltype, 8, "molecule types")?;
    let mut moltypes = Vec::with_capacity(nmoltype);
    for _ in 0..nmoltype {
        moltypes.push(moltype(r, version, &sym)?);
    }

    let at = r.at();
    let nblock = r.int("the number of molecule blocks")?;
    let nblock = r.count_at(at, nblock, 20, "molecule blocks")?;
    let mut blocks = Vec::with_capacity(nblock);
    let mut total: u64 = 0;
    for _ in 0..nblock {
        let at = r.at();
        let ty = r.int("a molecule block's type")?;
        let Some(ty) = usize::try_from(ty).ok().filter(|&t| t < nmoltype) else {
            return Err(Error::Parse {
                at,
                expected: "a molecule type index",
                found: format!("{ty} ({nmoltype} types)"),
            });
        };
        let at = r.at();
        let nmol = r.int("a molecule block's molecule count")?;
        let nmol = u64::try_from(nmol).map_err(|_| Error::Parse {
            at: at.clone(),
            expected: "a molecule count of 0 or more",
            found: nmol.to_string(),
        })?;
        let per = r.int("a molecule block's atoms per molecule")?;
        if per != moltypes[ty].atoms.len() as i32 {
            return Err(Error::Parse {
                at,
                expected: "as many atoms per molecule as its type has",
                found: format!("{per} (the type has {})", moltypes[ty].atoms.len()),
            });
        }
        for what in [
            "position-restraint references",
            "B-state restraint references",
        ] {
            let at = r.at();
            let n = r.int(what)?;
            let n = r.count_at(at, n, 3 * r.real_size(), what)?;
            r.skip(n * 3 * r.real_size(), what)?;
        }
        total += nmol * moltypes[ty].atoms.len() as u64;
        blocks.push((ty, nmol));
    }
    let at = r.at();
    let n = r.int("the number of atoms")?;
    if total != natoms as u64 || n as i64 != natoms as i64 {
        return Err(Error::Parse {
            at,
            expected: "as many atoms in the molecule blocks as the header says",
            found: format!("{total} in the blocks, {n} here, {natoms} in the header"),
        });
    }

    let mut bonds = Vec::new();
    if version >= 103 && r.boolean("whether inter-molecular interactions follow")? {
        let lists = ilists(r, version)?;
        bonds = chemical_bonds(&lists, natoms, r, "an inter-molecular bond")?;
    }
    if version < 128 {
        // The atom types' table (atomic numbers, and implicit-solvent radii before 113).
        let at = r.at();
        let nr = r.int("the number of atom types")?;
        let reals = match version {
            ..60 => 3,
            60..113 => 5,
            _ => 0,
        };
        let per = reals * r.real_size() + 4;
        let nr = r.count_at(at, nr, per, "atom types")?;
        r.skip(nr * per, "the atom types")?;
    }
    if version >= 65 {
        let at = r.at();
        let ngrid = r.int("the number of CMAP grids")?;
        let ngrid = r.count_at(at, ngrid, 0, "CMAP grids")?;
        let at = r.at();
        let extent = r.int("the CMAP grid size")?;
        let extent = r.count_at(at, extent, 0, "CMAP grid points")?;
        let reals = (ngrid as u64)
            .saturating_mul(extent as u64)
            .saturating_mul(extent as u64)
            .saturating_mul(4 * r.real_size() as u64);
        r.skip(
            usize::try_from(reals).unwrap_or(usize::MAX),
            "the CMAP grids",
        )?;
    }
    // Atom groups (temperature coupling, energy output, freezing, ...): 10 kinds.
    for _ in 0..10 {
        let at = r.at();
        let n = r.int("an atom group's size")?;
        let n = r.count_at(at, n, 4, "group entries")?;
        r.skip(4 * n, "an atom group")?;
    }
    let at = r.at();
    let n = r.int("the number of group names")?;
    let n = r.count_at(at, n, 4, "group names")?;
    r.skip(4 * n, "the group names")?;
    for _ in 0..10 {
        let at = r.at();
        let n = r.int("a group numbering's size")?;
        let one = if r.compact { 1 } else { 4 };
        let n = r.count_at(at, n, one, "group numbers")?;
        r.skip(one * n, "a group numbering")?;
    }
    if version >= 120 {
        let at = r.at();
        let n = r.int64("the size of the non-bonded exclusion group")?;
        let n = r.count_at(at, i32::try_from(n).unwrap_or(-1), 4, "excluded atoms")?;
        r.skip(4 * n, "the non-bonded exclusion group")?;
    }

    // Expand the blocks into atoms: as many as the positions that follow hold (a file of
    // water stores one molecule and a count), or, with no positions, at most 2^26.
    let left = r.b.len() - r.pos;
    if (has_x && natoms.saturating_mul(3 * r.real_size()) > left) || (!has_x && natoms > 1 << 26) {
        return Err(r.truncated(format!("the {natoms} atoms' positions ({left} bytes left)")));
    }
    let single = blocks.len() == 1 && blocks[0].1 == 1;
    let renumber_max = if single { 0 } else { 1 };
    let mut highest = 0;
    for m in &moltypes {
        if m.residues.len() > renumber_max {
            highest = m.residues.iter().map(|r| r.1).fold(highest, i64::max);
        }
    }
    let chain_of = |name: &str| name.rsplit_once("_chain_").map(|(_, c)| label(c));
    let has_chains = moltypes.iter().any(|m| chain_of(&m.name).is_some());
    let mut s = System {
        names: Vec::with_capacity(natoms),
        types: Vec::with_capacity(natoms),
        res_names: Vec::with_capacity(natoms),
        res_ids: Vec::with_capacity(natoms),
        segments: Vec::with_capacity(natoms),
        chains: Vec::new(),
        elements: Vec::with_capacity(natoms),
        masses: Vec::with_capacity(natoms),
        charges: Vec::with_capacity(natoms),
        bonds: Vec::new(),
        molecules: Vec::with_capacity(natoms),
    };
    let mut molecule = 0u32;
    for &(ty, nmol) in &blocks {
        let m = &moltypes[ty];
        let names: Vec<Label> = m.names.iter().map(|n| label(n)).collect();
        let types: Vec<Label> = m.types.iter().map(|n| label(n)).collect();
        let res_names: Vec<Label> = m.residues.iter().map(|r| label(&r.0)).collect();
        let elements: Vec<Element> = m
            .atoms
            .iter()
            .enumerate()
            .map(|(i, a)| element(a.3, &m.names[i], &m.residues[a.2].0, a.0))
            .collect();
        let segment = label(&m.name);
        let chain = chain_of(&m.name).unwrap_or_default();
        for _ in 0..nmol {
            let first = s.names.len() as u32;
            for (i, a) in m.atoms.iter().enumerate() {
                s.names.push(names[i]);
                s.types.push(types[i]);
                s.res_names.push(res_names[a.2]);
                s.res_ids.push(if m.residues.len() > renumber_max {
                    m.residues[a.2].1
                } else {
                    highest + 1 + a.2 as i64
                });
                s.segments.push(segment);
                if has_chains {
                    s.chains.push(chain);
                }
                s.elements.push(elements[i]);
                s.masses.push(a.0 as f32);
                s.charges.push(a.1 as f32);
                s.molecules.push(molecule);
            }
            if m.residues.len() <= renumber_max {
                highest += m.residues.len() as i64;
            }
            s.bonds
                .extend(m.bonds.iter().map(|b| [b[0] + first, b[1] + first]));
            molecule += 1;
        }
    }
    s.bonds.extend(bonds);
    tidy(&mut s.bonds);
    Ok(s)
}

/// The element of atomic number `z`, or else guessed from the name and mass.
fn element(z: i32, name: &str, residue: &str, mass: f64) -> Element {
    match u8::try_from(z).ok().and_then(Element::from_z) {
        Some(e) => e,
        None if mass < 0.5 => Element::UNKNOWN,
        None => crate::psf::element_of(name, residue, mass),
    }
}

fn moltype(
    r: &mut Reader,
    version: i32,
    sym: &dyn Fn(&mut Reader, &'static str) -> Result<String, Error>,
) -> Result<MolType, Error> {
    let name = sym(r, "a molecule type's name")?;
    let at = r.at();
    let nr = r.int("a molecule type's atom count")?;
    let per_atom = 4 * r.real_size() + 2 * r.short_size() + 12 + 12;
    let nr = r.count_at(at, nr, per_atom, "atoms")?;
    let at = r.at();
    let nres = r.int("a molecule type's residue count")?;
    let nres = r.count_at(at, nres, 4, "residues")?;
    let mut atoms = Vec::with_capacity(nr);
    for _ in 0..nr {
        let m = r.real("an atom's mass")?;
        let q = r.real("an atom's charge")?;
        r.real("an atom's B-state mass")?;
        r.real("an atom's B-state charge")?;
        r.short("an atom's type")?;
        r.short("an atom's B-state type")?;
        r.int("an atom's particle type")?;
        let at = r.at();
        let res = r.int("an atom's residue index")?;
        let Some(res) = usize::try_from(res).ok().filter(|&k| k < nres) else {
            return Err(Error::Parse {
                at,
                expected: "a residue index of the molecule type",
                found: format!("{res} ({nres} residues)"),
            });
        };
        let z = r.int("an atom's atomic number")?;
        atoms.push((m, q, res, z));
    }
    let mut names = Vec::with_capacity(nr);
    for _ in 0..nr {
        names.push(sym(r, "an atom's name")?);
    }
    let mut types = Vec::with_capacity(nr);
    for _ in 0..nr {
        types.push(sym(r, "an atom's type name")?);
    }
    for _ in 0..nr {
        sym(r, "an atom's B-state type name")?;
    }
    let mut residues = Vec::with_capacity(nres);
    for k in 0..nres {
        let name = sym(r, "a residue's name")?;
        let nr = if version >= 63 {
            let nr = r.int("a residue's number")?;
            r.uchar("a residue's insertion code")?;
            nr as i64
        } else {
            k as i64 + 1
        };
        residues.push((name, nr));
    }
    let lists = ilists(r, version)?;
    let bonds = chemical_bonds(&lists, nr, r, "a bond")?;
    // The obsolete charge groups, then the exclusions.
    let at = r.at();
    let n = r.int("the number of charge groups")?;
    let n = r.count_at(at, n.saturating_add(1), 4, "charge-group bounds")?;
    r.skip(4 * n, "the charge groups")?;
    let at = r.at();
    let lists = r.int("the number of exclusion lists")?;
    let at2 = r.at();
    let elements = r.int("the number of exclusions")?;
    let lists = r.count_at(at, lists.saturating_add(1), 4, "exclusion bounds")?;
    r.skip(4 * lists, "the exclusion bounds")?;
    let elements = r.count_at(at2, elements, 4, "exclusions")?;
    r.skip(4 * elements, "the exclusions")?;
    Ok(MolType {
        name,
        atoms,
        names,
        types,
        residues,
        bonds,
    })
}

/// Each interaction type's atom list (type index then atoms, flat), empty where the file has
/// none.
fn ilists(r: &mut Reader, version: i32) -> Result<Vec<Vec<i32>>, Error> {
    let mut lists = vec![Vec::new(); f::COUNT];
    for (t, list) in lists.iter_mut().enumerate() {
        if RENUMBER.iter().any(|&(v, ty)| version < v && ty == t) {
            continue;
        }
        let at = r.at();
        let n = r.int("an interaction list's length")?;
        let n = r.count_at(at, n, 4, "interaction entries")?;
        *list = r.ints(n, "an interaction list")?;
        if version < 78 && t == f::SETTLE {
            // Old files list SETTLE's oxygen only; its hydrogens are the next two atoms.
            *list = list
                .chunks(2)
                .flat_map(|c| {
                    let o = c.get(1).copied().unwrap_or(0);
                    [c[0], o, o + 1, o + 2]
                })
                .collect();
        }
    }
    Ok(lists)
}

/// The chemical bonds of a molecule type's (or the system's) interaction lists, each atom
/// checked to be one of the `n` atoms.
fn chemical_bonds(
    lists: &[Vec<i32>],
    n: usize,
    r: &Reader,
    what: &'static str,
) -> Result<Vec<[u32; 2]>, Error> {
    let mut bonds = Vec::new();
    let atom = |k: i32| -> Result<u32, Error> {
        usize::try_from(k)
            .ok()
            .filter(|&k| k < n)
            .map(|k| k as u32)
            .ok_or_else(|| Error::Parse {
                at: r.at(),
                expected: what,
                found: format!("atom {k} of {n}"),
            })
    };
    for &t in &CHEMICAL_BONDS {
        for e in lists[t].chunks(3) {
            if let [_, i, j] = *e {
                bonds.push([atom(i)?, atom(j)?]);
            }
        }
    }
    for e in lists[f::SETTLE].chunks(4) {
        if let [_, o, h1, h2] = *e {
            bonds.push([atom(o)?, atom(h1)?]);
            bonds.push([atom(o)?, atom(h2)?]);
        }
    }
    if let Some(b) = bonds.iter().find(|b| b[0] == b[1]) {
        return Err(Error::Parse {
            at: r.at(),
            expected: "bonds between two different atoms",
            found: format!("atom {} bonded to itself", b[0]),
        });
    }
    Ok(bonds)
}

/// The force-field parameters, skipped: the interaction types, and each type's parameters by
/// its size.
fn ffparams(r: &mut Reader, version: i32) -> Result<(), Error> {
    r.int("the number of atom types")?;
    let at = r.at();
    let ntypes = r.int("the number of interaction types")?;
    let ntypes = r.count_at(at, ntypes, 4, "interaction types")?;
    let at = r.at();
    let mut types = r.ints(ntypes, "the interaction types")?;
    if version >= 66 {
        r.skip(8, "the repulsion power")?;
    }
    r.real("fudgeQQ")?;
    for t in &mut types {
        for &(v, ty) in &RENUMBER {
            if version < v && *t >= ty as i32 {
                *t += 1;
            }
        }
    }
    for t in types {
        let Some((reals, ints)) = usize::try_from(t).ok().and_then(|t| params(t, version)) else {
            return Err(Error::Parse {
                at,
                expected: "interaction types GROMACS has parameters for",
                found: t.to_string(),
            });
        };
        r.skip(reals * r.real_size() + ints * 4, "interaction parameters")?;
    }
    Ok(())
}

/// The number of reals and of integers an interaction type's parameters take in a file of
/// `version` (`tpxio.cpp`'s `do_iparams`); `None` for a type that has none stored.
fn params(t: usize, v: i32) -> Option<(usize, usize)> {
    use f::*;
    Some(match t {
        ANGLES | G96ANGLES | BONDS | G96BONDS | HARMONIC | IDIHS => (4, 0),
        RESTRANGLES | RESTRDIHS => (if v < 134 { 2 } else { 4 }, 0),
        LINEAR_ANGLES => (4, 0),
        FENEBONDS => (2, 0),
        RESTRAINTPOT => (8, 0),
        TABBONDS | TABBONDSNC | TABANGLES | TABDIHS => (2, 1),
        CROSS_BOND_BONDS => (3, 0),
        CROSS_BOND_ANGLES => (4, 0),
        UREY_BRADLEY => (if v >= 79 { 8 } else { 4 }, 0),
        QUARTIC_ANGLES => (6, 0),
        BHAM => (3, 0),
        MORSE => (if v >= 79 { 6 } else { 3 }, 0),
        CUBICBONDS => (3, 0),
        CONNBONDS | VSITE1 => (0, 0),
        POLARIZATION => (1, 0),
        ANHARM_POL => (3, 0),
        WATER_POL => (6, 0),
        THOLE_POL => (if v < 127 { 4 } else { 3 }, 0),
        LJ => (2, 0),
        LJ14 => (4, 0),
        LJC14_Q => (5, 0),
        LJC_PAIRS_NB => (4, 0),
        PDIHS | PIDIHS | ANGRES | ANGRESZ => (4, 1),
        DISRES => (4, 2),
        ORIRES => (3, 3),
        DIHRES if v < 82 => (3, 2),
        DIHRES => (6, 0),
        POSRES => (12, 0),
        FBPOSRES => (5, 1),
        CBTDIHS => (if v < 134 { 6 } else { 12 }, 0),
        RBDIHS | FOURDIHS => (12, 0),
        CONSTR | CONSTRNC | SETTLE => (2, 0),
        VSITE2 | VSITE2FD => (1, 0),
        VSITE3 | VSITE3FD | VSITE3FAD => (2, 0),
        VSITE3OUT | VSITE4FD | VSITE4FDN => (3, 0),
        VSITEN => (1, 1),
        GB12 | GB13 | GB14 => (if v < 68 { 4 } else { 0 } + if v < 113 { 5 } else { 0 }, 0),
        CMAP => (0, 2),
        _ => return None,
    })
}

/// A cursor over the file's bytes, in XDR or (the body from version 119) GROMACS's in-memory
/// serialisation.
struct Reader<'a> {
    b: &'a [u8],
    pos: usize,
    file: Arc<str>,
    double: bool,
    compact: bool,
}

impl Reader<'_> {
    fn at(&self) -> Location {
        Location {
            file: self.file.clone(),
            byte: Some(self.pos as u64),
            ..Location::default()
        }
    }

    fn truncated(&self, expected: String) -> Error {
        Error::Truncated {
            at: self.at(),
            expected,
        }
    }

    fn real_size(&self) -> usize {
        if self.double { 8 } else { 4 }
    }

    fn short_size(&self) -> usize {
        if self.compact { 2 } else { 4 }
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&[u8], Error> {
        if self.b.len() - self.pos < n {
            return Err(self.truncated(format!(
                "{what}: {n} bytes, {} left",
                self.b.len() - self.pos
            )));
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn skip(&mut self, n: usize, what: &str) -> Result<(), Error> {
        self.take(n, what).map(|_| ())
    }

    fn int(&mut self, what: &str) -> Result<i32, Error> {
        let b = self.take(4, what)?;
        Ok(i32::from_be_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn int64(&mut self, what: &str) -> Result<i64, Error> {
        let b = self.take(8, what)?;
        Ok(i64::from_be_bytes(b.try_into().unwrap_or_default()))
    }

    fn real(&mut self, what: &str) -> Result<f64, Error> {
        if self.double {
            let b = self.take(8, what)?;
            Ok(f64::from_be_bytes(b.try_into().unwrap_or_default()))
        } else {
            let b = self.take(4, what)?;
            Ok(f32::from_be_bytes([b[0], b[1], b[2], b[3]]) as f64)
        }
    }

    fn short(&mut self, what: &str) -> Result<(), Error> {
        self.skip(self.short_size(), what)
    }

    fn uchar(&mut self, what: &str) -> Result<(), Error> {
        self.skip(if self.compact { 1 } else { 4 }, what)
    }

    fn boolean(&mut self, what: &str) -> Result<bool, Error> {
        if self.compact {
            Ok(self.take(1, what)?[0] != 0)
        } else {
            Ok(self.int(what)? != 0)
        }
    }

    fn string(&mut self, what: &'static str) -> Result<String, Error> {
        let at = self.at();
        let n = if self.compact {
            let n = self.int64(what)?;
            usize::try_from(n).ok()
        } else {
            // GROMACS's XDR string: its size with the terminating zero, then an XDR string
            // (length, bytes, padding to 4).
            self.int(what)?;
            let n = self.int(what)?;
            usize::try_from(n).ok()
        };
        let Some(n) = n.filter(|&n| n <= self.b.len() - self.pos) else {
            return Err(Error::Parse {
                at,
                expected: what,
                found: "a string longer than the file".into(),
            });
        };
        let pad = if self.compact { 0 } else { (4 - n % 4) % 4 };
        let s = self.take(n, what)?;
        let s = String::from_utf8_lossy(s)
            .trim_end_matches('\0')
            .to_string();
        self.skip(pad.min(self.b.len() - self.pos), what)?;
        Ok(s)
    }

    fn ints(&mut self, n: usize, what: &str) -> Result<Vec<i32>, Error> {
        let b = self.take(4 * n, what)?;
        Ok(b.chunks_exact(4)
            .map(|c| i32::from_be_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    }

    fn rvecs(&mut self, n: usize, what: &str) -> Result<Vec<[f64; 3]>, Error> {
        let size = self.real_size();
        let b = self.take(3 * size * n, what)?;
        Ok(b.chunks_exact(3 * size)
            .map(|c| {
                let v = |k: usize| -> f64 {
                    let c = &c[k * size..(k + 1) * size];
                    if size == 8 {
                        f64::from_be_bytes(c.try_into().unwrap_or_default())
                    } else {
                        f32::from_be_bytes([c[0], c[1], c[2], c[3]]) as f64
                    }
                };
                [v(0), v(1), v(2)]
            })
            .collect())
    }

    /// `n` entries of at least `size` bytes each, checked against the bytes left (and
    /// against being negative) before anything is allocated for them.
    fn count_at(&self, at: Location, n: i32, size: usize, what: &str) -> Result<usize, Error> {
        let Ok(k) = usize::try_from(n) else {
            return Err(Error::Parse {
                at,
                expected: "a count of 0 or more",
                found: format!("{n} {what}"),
            });
        };
        if k.saturating_mul(size) > self.b.len() - self.pos {
            return Err(Error::Truncated {
                at,
                expected: format!(
                    "{k} {what} of {size} bytes or more ({} bytes left)",
                    self.b.len() - self.pos
                ),
            });
        }
        Ok(k)
    }

    fn count(&self, n: i32, size: usize, what: &str) -> Result<usize, Error> {
        self.count_at(self.at(), n, size, what)
    }
}

/// A `.tpr` read as a trajectory ([`crate::Format::Tpr`]): one frame, the starting positions
/// with the topology's labels, masses, charges and bonds.
pub(crate) struct TprReader {
    frame: Frame,
    next: usize,
}

impl TprReader {
    /// Reads and parses the whole file.
    pub fn new<R: Read>(mut src: R, file: Arc<str>) -> Result<TprReader, Error> {
        let mut bytes = Vec::new();
        src.read_to_end(&mut bytes).map_err(|source| Error::Io {
            at: Location::file(&file),
            source,
        })?;
        let t = read_tpr(&bytes, &file)?;
        if t.positions.len() != t.topology.n_atoms() {
            return Err(Error::Parse {
                at: Location::binary(&file, 0, 0),
                expected: "a .tpr with positions (the header says it has none)",
                found: "a topology only".into(),
            });
        }
        let mut frame = Frame::new();
        frame.positions = t.positions.iter().map(|p| p.map(|x| x as f32)).collect();
        if let Some(bad) = first_out_of_bounds(&frame.positions) {
            return Err(Error::Parse {
                at: Location::binary(&file, 0, 0),
                expected: IN_BOUNDS,
                found: format!("atom {bad}: {:?}", frame.positions[bad]),
            });
        }
        frame.velocities = t.velocities.iter().map(|p| p.map(|x| x as f32)).collect();
        if let Some(bad) = frame
            .velocities
            .iter()
            .position(|v| v.iter().any(|x| !x.is_finite()))
        {
            return Err(Error::Parse {
                at: Location::binary(&file, 0, 0),
                expected: "finite velocities",
                found: format!("atom {bad}: {:?}", frame.velocities[bad]),
            });
        }
        // A zero box is a system without periodic boundaries (pbc = no).
        frame.cell = match t.cell {
            Some(m) if m.iter().flatten().any(|&x| x != 0.0) => {
                Some(UnitCell::from_matrix(m).map_err(|e| Error::Parse {
                    at: Location::binary(&file, 0, 0),
                    expected: "a box of three independent vectors",
                    found: e.to_string(),
                })?)
            }
            _ => None,
        };
        t.topology.apply(&mut frame, &file, 0)?;
        frame.bonds.clone_from(&t.topology.bonds);
        frame.comment = t.writer;
        Ok(TprReader { frame, next: 0 })
    }

    /// The one frame, then the end.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        if self.next > 0 {
            return Ok(false);
        }
        frame.clone_from(&self.frame);
        self.next = 1;
        Ok(true)
    }

    /// Makes `read_next` read frame `n`: only frame 0 exists.
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        self.next = n;
        Ok(n == 0)
    }

    /// One frame.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        Ok(1)
    }
}
