//! LAMMPS data files (what `read_data` reads and `write_data`, MDAnalysis, ASE, OVITO and
//! moltemplate write) as one-frame trajectories ([`crate::Format::LammpsData`]); the LAMMPS data
//! topology ([`crate::TopologyFormat::LammpsData`]) is this same parse, its frame's labels kept.
//!
//! # What is read
//! The layout of the LAMMPS `read_data` documentation: the first line is a title (the frame's
//! comment; LAMMPS skips it whatever it holds), then header lines, then sections. `#` starts a
//! comment anywhere; blank lines are skipped.
//!
//! - **Header:** the counts (`N atoms`, `N bonds`, `N angles`, `N dihedrals`, `N impropers`,
//!   `N atom types` … `N improper types`, `N ellipsoids`, `N lines`, `N triangles`,
//!   `N crossterms`; `N extra … per atom` is read past) and the box. An `N atoms` line is
//!   required. The box is `xlo xhi`, `ylo yhi`, `zlo zhi` (all three, each `hi > lo`) with the
//!   optional `xy xz yz` tilt of LAMMPS's restricted triclinic box: edges a = (xhi−xlo, 0, 0),
//!   b = (xy, yhi−ylo, 0), c = (xz, yz, zhi−zlo), origin (xlo, ylo, zlo), as the LAMMPS dump reader
//!   builds it; or the general triclinic `avec`, `bvec`, `cvec`, `abc origin` (LAMMPS 2024 and
//!   later, OVITO 3.17's writer), whose vectors must form a right-handed cell. Without box lines
//!   the frame has no cell (LAMMPS would take −0.5 0.5 on each axis).
//! - **Sections**, in any order, each once; each holds exactly the line count its header gives
//!   (`Atoms` and `Velocities` the atoms, `Masses` and `Pair Coeffs` the atom types, `PairIJ
//!   Coeffs` N(N+1)/2 of them, `Bonds` the bonds, `Bond Coeffs` the bond types, …, `Atom Type
//!   Labels` … `Improper Type Labels` the types, `CMAP` the crossterms). A section shorter than
//!   its count (another section's keyword comes first), longer (a line that is not a section
//!   keyword follows its last line) or missing (`Atoms` and the `Bonds` … `Impropers`,
//!   `Ellipsoids`, `Lines`, `Triangles`, `CMAP` sections of a non-zero count; a cut file) is an
//!   error. Coefficients, angles, dihedrals, impropers, ellipsoids, lines, triangles and CMAP
//!   are skipped by their counts. `Bodies` (entries of several lines) is not read.
//! - **`Atoms`:** the style comes from the section's comment (`Atoms # full`, which `write_data`,
//!   MDAnalysis, ASE and OVITO write): `atomic` (id type x y z), `charge` (id type q x y z),
//!   `molecular`, `bond`, `angle` (id mol type x y z), `full` (id mol type q x y z), `sphere`
//!   (id type diameter density x y z), `ellipsoid` (id type ellipsoidflag density x y z), `dipole`
//!   (id type q x y z mux muy muz), `peri` (id type volume density x y z), `dpd` (id type theta
//!   x y z). Without a comment the style is told by the column count, as ASE and MDAnalysis do:
//!   5 (8 with image flags) is `atomic`, 7 (10) is `full`; any other count is ambiguous (6 is
//!   `charge` or `molecular`) and an error asking for the comment. Every line has as many columns
//!   as the first (LAMMPS's rule): the style's, or three more for the image flags.
//! - Atoms are **ordered by id** (rows may come in any order), as the LAMMPS dump reader orders
//!   them, so index `i` is the same atom in a data file and the dumps of its run. Ids are
//!   positive and each appears once. Molecule ids are [`Frame::res_ids`], types
//!   [`Frame::types`] as written (a number, or a label of the `Atom Type Labels` section; a
//!   number must lie in 1..=`atom types` when the header gives that count).
//! - **Properties** ([`Frame::properties`]): `charge` (e), the style's other columns under the
//!   names above (`density`, `mux`, `theta`, …), `mass` (from `Masses`, when every type has
//!   one), the image flags `ix iy iz` when the lines have them, and the velocities `vx vy vz`.
//!   A `sphere` style's diameters become [`Frame::radii`] (halved) when all are positive, else
//!   they stay the `diameter` property (LAMMPS's point particles have diameter 0).
//! - **Positions are kept as written** (wrapped into the box, as `write_data` writes them) and
//!   the image flags are kept as the properties `ix iy iz`, not applied: what OVITO does
//!   (its `Periodic Image` property); ASE adds the image-flag translations to the positions.
//! - **Velocities are the properties `vx vy vz`, as written, not [`Frame::velocities`]:** a data
//!   file does not state its units, and LAMMPS velocities are in the run's distance/time units
//!   (Å/fs for `units real`, Å/ps for `metal`, reduced for `lj`), so no conversion to the frame's
//!   Å/ps can be justified. Arrows and colours by property reach them (the stem `v`). Extra
//!   columns of a `Velocities` line (a sphere's angular velocity) are read past.
//! - **Elements**, per type: the first word of a `Masses` line's comment (`1 12.011 # C`, what
//!   ASE, OVITO and moltemplate write) or the type's label (`Atom Type Labels`) when it is an
//!   element symbol written as one (`C`, `Ca`; not `CA`, an aromatic carbon's type name);
//!   else the mass, when it lies within 0.1 % of exactly one element's standard atomic weight
//!   (12.011 and 12.0 are carbon, 15.9994 oxygen). Masses of isotopes (deuterium 2.014),
//!   united atoms (CH2 14.027), coarse-grained beads (72) and reduced units (1.0) match none:
//!   those types stay of unknown element and are drawn one colour per type, as OVITO does.
//!   (ASE takes the nearest element whatever the distance, so a bead of mass 72 is germanium.)
//!   When no type gets an element, [`Frame::elements`] is left empty.
//! - **`Bonds`** become [`Frame::bonds`] (index pairs, sorted, each once), so they are drawn as
//!   listed; a bond to an atom id the `Atoms` section lacks, or from an atom to itself, is an
//!   error.
//!
//! # Damage
//! Errors name the file, frame 0, the line and the byte (of the offending token where there is
//! one) and what was expected: a header line that is no header keyword nor section keyword, a
//! box with `hi <= lo` or a left-handed general box, a line with too few or too many columns,
//! a value that is not a number, an atom id repeated or not positive, a velocity or bond naming
//! a missing atom, a section shorter or longer than its count, a missing section. Nothing is
//! sized from a count before the lines are read: the frame reserves at most what the file's size
//! can hold (`Ctx::reserve`), and a count larger than the file is a cut file
//! ([`Error::Truncated`]) when its lines run out.
//!
//! # References
//! - LAMMPS documentation, `read_data` (header keywords, sections and their line counts, the
//!   Atoms line of each style, image flags, type labels), "Triclinic (non-orthogonal)
//!   simulation boxes" (restricted and general triclinic).
//! - OVITO 3.17 user manual, "LAMMPS data file reader" (the `Atoms # style` hint, image flags
//!   kept as a property).
//! - ASE `ase.io.lammpsdata` and MDAnalysis `DATAParser` (style by column count, mass → element).

use std::collections::HashMap;
use std::io::Read;

use crate::elements::{Element, element_of_symbol};
use crate::error::Error;
use crate::frame::{Frame, Label, Property, UnitCell};
use crate::parse::{fields, parse_f32, parse_f64, parse_i64, trim};
use crate::text::{Ctx, FrameWalk, LineReader, Pos};

/// What a column of the `Atoms` section holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Col {
    Id,
    Mol,
    Type,
    /// Charge: the `charge` property.
    Q,
    /// Coordinate 0, 1, 2.
    X(usize),
    /// Sphere diameter: radii, or the `diameter` property.
    Diameter,
    /// Another number: a property of this name.
    Named(&'static str),
    /// Image flag 0, 1, 2: the properties `ix iy iz`.
    Image(usize),
}

use Col::{Diameter, Id, Mol, Named, Q, Type, X};

/// The atom styles read: their names and the columns of their `Atoms` lines (LAMMPS `read_data`).
const STYLES: &[(&[&str], &[Col])] = &[
    (&["atomic"], &[Id, Type, X(0), X(1), X(2)]),
    (&["charge"], &[Id, Type, Q, X(0), X(1), X(2)]),
    (
        &["molecular", "bond", "angle"],
        &[Id, Mol, Type, X(0), X(1), X(2)],
    ),
    (&["full"], &[Id, Mol, Type, Q, X(0), X(1), X(2)]),
    (
        &["sphere"],
        &[Id, Type, Diameter, Named("density"), X(0), X(1), X(2)],
    ),
    (
        &["ellipsoid"],
        &[
            Id,
            Type,
            Named("ellipsoidflag"),
            Named("density"),
            X(0),
            X(1),
            X(2),
        ],
    ),
    (
        &["dipole"],
        &[
            Id,
            Type,
            Q,
            X(0),
            X(1),
            X(2),
            Named("mux"),
            Named("muy"),
            Named("muz"),
        ],
    ),
    (
        &["peri"],
        &[
            Id,
            Type,
            Named("volume"),
            Named("density"),
            X(0),
            X(1),
            X(2),
        ],
    ),
    (&["dpd"], &[Id, Type, Named("theta"), X(0), X(1), X(2)]),
];

/// Header counts, by index.
const COUNTS: [&str; 15] = [
    "atoms",
    "bonds",
    "angles",
    "dihedrals",
    "impropers",
    "atom types",
    "bond types",
    "angle types",
    "dihedral types",
    "improper types",
    "ellipsoids",
    "lines",
    "triangles",
    "bodies",
    "crossterms",
];
const ATOMS: usize = 0;
const BONDS: usize = 1;
const ANGLES: usize = 2;
const DIHEDRALS: usize = 3;
const IMPROPERS: usize = 4;
const ATOM_TYPES: usize = 5;
const BOND_TYPES: usize = 6;
const ANGLE_TYPES: usize = 7;
const DIHEDRAL_TYPES: usize = 8;
const IMPROPER_TYPES: usize = 9;
const ELLIPSOIDS: usize = 10;
const LINES: usize = 11;
const TRIANGLES: usize = 12;
const CROSSTERMS: usize = 14;

/// A section's line count: a header count, or N(N+1)/2 of the atom types (`PairIJ Coeffs`).
#[derive(Clone, Copy)]
enum Rows {
    Count(usize),
    PairIj,
}

/// The sections read or skipped: name, line count, required when the count is not zero.
const SECTIONS: &[(&str, Rows, bool)] = &[
    ("Atoms", Rows::Count(ATOMS), true),
    ("Velocities", Rows::Count(ATOMS), false),
    ("Masses", Rows::Count(ATOM_TYPES), false),
    ("Bonds", Rows::Count(BONDS), true),
    ("Angles", Rows::Count(ANGLES), true),
    ("Dihedrals", Rows::Count(DIHEDRALS), true),
    ("Impropers", Rows::Count(IMPROPERS), true),
    ("Ellipsoids", Rows::Count(ELLIPSOIDS), true),
    ("Lines", Rows::Count(LINES), true),
    ("Triangles", Rows::Count(TRIANGLES), true),
    ("CMAP", Rows::Count(CROSSTERMS), true),
    ("Atom Type Labels", Rows::Count(ATOM_TYPES), false),
    ("Bond Type Labels", Rows::Count(BOND_TYPES), false),
    ("Angle Type Labels", Rows::Count(ANGLE_TYPES), false),
    ("Dihedral Type Labels", Rows::Count(DIHEDRAL_TYPES), false),
    ("Improper Type Labels", Rows::Count(IMPROPER_TYPES), false),
    ("Pair Coeffs", Rows::Count(ATOM_TYPES), false),
    ("PairIJ Coeffs", Rows::PairIj, false),
    ("Bond Coeffs", Rows::Count(BOND_TYPES), false),
    ("Angle Coeffs", Rows::Count(ANGLE_TYPES), false),
    ("Dihedral Coeffs", Rows::Count(DIHEDRAL_TYPES), false),
    ("Improper Coeffs", Rows::Count(IMPROPER_TYPES), false),
    ("BondBond Coeffs", Rows::Count(ANGLE_TYPES), false),
    ("BondAngle Coeffs", Rows::Count(ANGLE_TYPES), false),
    (
        "MiddleBondTorsion Coeffs",
        Rows::Count(DIHEDRAL_TYPES),
        false,
    ),
    ("EndBondTorsion Coeffs", Rows::Count(DIHEDRAL_TYPES), false),
    ("AngleTorsion Coeffs", Rows::Count(DIHEDRAL_TYPES), false),
    (
        "AngleAngleTorsion Coeffs",
        Rows::Count(DIHEDRAL_TYPES),
        false,
    ),
    ("BondBond13 Coeffs", Rows::Count(DIHEDRAL_TYPES), false),
    ("AngleAngle Coeffs", Rows::Count(IMPROPER_TYPES), false),
];
const S_ATOMS: usize = 0;
const S_VELOCITIES: usize = 1;
const S_MASSES: usize = 2;
const S_BONDS: usize = 3;
const S_ATOM_TYPE_LABELS: usize = 11;

/// Relative distance within which a mass names an element (see the module doc).
const MASS_TOLERANCE: f64 = 1e-3;

/// The line without its `#` comment.
fn strip_comment(line: &[u8]) -> &[u8] {
    match memchr::memchr(b'#', line) {
        Some(k) => &line[..k],
        None => line,
    }
}

/// The comment of a line (after `#`), trimmed; empty without one.
fn comment(line: &[u8]) -> &[u8] {
    match memchr::memchr(b'#', line) {
        Some(k) => trim(&line[k + 1..]),
        None => &[],
    }
}

/// The section a keyword line (comment stripped) names, its words separated by any blanks.
fn section_of(line: &[u8]) -> Option<usize> {
    let first = *line.first()?;
    if !first.is_ascii_alphabetic() {
        return None;
    }
    SECTIONS.iter().position(|(name, ..)| {
        let mut want = name.split(' ').map(str::as_bytes);
        let mut got = fields(line);
        loop {
            match (want.next(), got.next()) {
                (None, None) => return true,
                (Some(a), Some(b)) if a == b => {}
                _ => return false,
            }
        }
    })
}

/// The element a mass names: the one element whose standard atomic weight lies within
/// [`MASS_TOLERANCE`] (relative) of it, if exactly one does.
pub(crate) fn element_of_mass(mass: f64) -> Option<Element> {
    let mut found = None;
    for z in 1..=103u8 {
        let e = Element::from_z(z)?;
        let m = e.mass();
        if (mass - m).abs() <= MASS_TOLERANCE * m {
            if found.is_some() {
                return None;
            }
            found = Some(e);
        }
    }
    found
}

/// The columns of the style an `Atoms # style` comment names: `Some(None)` without a comment,
/// `None` for a style this reader does not know.
fn style_named(hint: &[u8]) -> Option<Option<&'static [Col]>> {
    let Some(word) = fields(hint).next() else {
        return Some(None);
    };
    STYLES
        .iter()
        .find(|(names, _)| names.iter().any(|n| n.as_bytes() == word))
        .map(|s| Some(s.1))
}

/// A parse error at `pos` (a token's own position) with what was found.
fn err(ctx: &Ctx, pos: Pos, expected: &'static str, found: impl Into<String>) -> Error {
    Error::Parse {
        at: ctx.at(pos),
        expected,
        found: found.into(),
    }
}

/// Where `token`, a sub-slice of `line` starting at `pos`, starts.
fn pos_of(pos: Pos, line: &[u8], token: &[u8]) -> Pos {
    let col = (token.as_ptr() as usize).wrapping_sub(line.as_ptr() as usize);
    let col = if col <= line.len() { col } else { 0 };
    Pos {
        line: pos.line,
        byte: pos.byte + col as u64,
    }
}

/// The header: counts and box.
#[derive(Default)]
struct Header {
    counts: [u64; COUNTS.len()],
    has_atoms: bool,
    has_atom_types: bool,
    bounds: [Option<[f64; 2]>; 3],
    tilt: Option<[f64; 3]>,
    /// `avec`, `bvec`, `cvec`, `abc origin`.
    general: [Option<[f64; 3]>; 4],
    /// The first box line, for errors about the box as a whole.
    box_at: Option<(Pos, String)>,
}

impl Header {
    /// Reads a header line (comment stripped, trimmed, not blank); `false` when it is not one.
    fn line(&mut self, ctx: &Ctx, pos: Pos, raw: &[u8], line: &[u8]) -> Result<bool, Error> {
        let all: Vec<&[u8]> = fields(line).collect();
        let k = all
            .iter()
            .position(|f| f[0].is_ascii_alphabetic())
            .unwrap_or(all.len());
        let (values, words) = all.split_at(k);
        let key = words.join(&b' ');
        let number = |f: &[u8]| {
            parse_f64(f).ok_or_else(|| ctx.parse(pos, raw, f, "a finite number in the header"))
        };
        let three = |values: &[&[u8]]| -> Result<[f64; 3], Error> {
            if values.len() != 3 {
                return Err(ctx.parse(pos, raw, line, "three numbers before the keyword"));
            }
            Ok([number(values[0])?, number(values[1])?, number(values[2])?])
        };
        if let Some(c) = COUNTS.iter().position(|c| c.as_bytes() == key) {
            let [v] = values else {
                return Err(ctx.parse(pos, raw, line, "one count before the keyword"));
            };
            let n = parse_i64(v)
                .and_then(|n| u64::try_from(n).ok())
                .ok_or_else(|| ctx.parse(pos, raw, v, "a count (a whole number >= 0)"))?;
            self.counts[c] = n;
            self.has_atoms |= c == ATOMS;
            self.has_atom_types |= c == ATOM_TYPES;
            return Ok(true);
        }
        if key.starts_with(b"extra ") && key.ends_with(b" per atom") {
            let [v] = values else {
                return Err(ctx.parse(pos, raw, line, "one count before the keyword"));
            };
            parse_i64(v)
                .filter(|n| *n >= 0)
                .ok_or_else(|| ctx.parse(pos, raw, v, "a count (a whole number >= 0)"))?;
            return Ok(true);
        }
        let bound = [&b"xlo xhi"[..], b"ylo yhi", b"zlo zhi"]
            .iter()
            .position(|b| *b == key);
        let general = [&b"avec"[..], b"bvec", b"cvec", b"abc origin"]
            .iter()
            .position(|b| *b == key);
        if bound.is_some() || general.is_some() || key == b"xy xz yz" {
            self.box_at
                .get_or_insert_with(|| (pos, String::from_utf8_lossy(line).into_owned()));
        }
        if let Some(axis) = bound {
            let [lo, hi] = values else {
                return Err(ctx.parse(pos, raw, line, "two bounds (lo hi) before the keyword"));
            };
            let (l, h) = (number(lo)?, number(hi)?);
            if h <= l {
                return Err(ctx.parse(pos, raw, hi, "a box bound hi > lo"));
            }
            self.bounds[axis] = Some([l, h]);
            return Ok(true);
        }
        if let Some(k) = general {
            self.general[k] = Some(three(values)?);
            return Ok(true);
        }
        if key == b"xy xz yz" {
            self.tilt = Some(three(values)?);
            return Ok(true);
        }
        Ok(false)
    }

    /// The cell the box lines give, checked; `None` without box lines.
    fn cell(&self, ctx: &Ctx, end: Pos) -> Result<Option<UnitCell>, Error> {
        let Some((at, line)) = &self.box_at else {
            return Ok(None);
        };
        let bad = |expected| err(ctx, *at, expected, line.clone());
        let any_bound = self.bounds.iter().any(Option::is_some) || self.tilt.is_some();
        let cell = if self.general.iter().any(Option::is_some) {
            if any_bound {
                return Err(bad(
                    "either xlo xhi, ylo yhi, zlo zhi (and xy xz yz) or avec, bvec, cvec, abc origin, not both",
                ));
            }
            let [Some(a), Some(b), Some(c), Some(o)] = self.general else {
                return Err(err(
                    ctx,
                    end,
                    "all four of avec, bvec, cvec and abc origin in the header",
                    "some",
                ));
            };
            UnitCell::from_matrix([a, b, c])
                .map(|cell| cell.with_origin(o))
                .map_err(|_| {
                    bad("avec, bvec, cvec of a right-handed box at most 1e7 Å long (LAMMPS refuses others)")
                })?
        } else {
            let [Some(x), Some(y), Some(z)] = self.bounds else {
                return Err(err(
                    ctx,
                    end,
                    "all three of xlo xhi, ylo yhi, zlo zhi in the header",
                    "some",
                ));
            };
            let [xy, xz, yz] = self.tilt.unwrap_or([0.0; 3]);
            let m = [
                [x[1] - x[0], 0.0, 0.0],
                [xy, y[1] - y[0], 0.0],
                [xz, yz, z[1] - z[0]],
            ];
            UnitCell::from_matrix(m)
                .map(|cell| cell.with_origin([x[0], y[0], z[0]]))
                .map_err(|_| bad("a box at most 1e7 Å long"))?
        };
        Ok(Some(cell))
    }

    /// The line count of section `k`.
    fn rows(&self, k: usize) -> u64 {
        match SECTIONS[k].1 {
            Rows::Count(c) => self.counts[c],
            Rows::PairIj => {
                let n = self.counts[ATOM_TYPES];
                n.saturating_mul(n.saturating_add(1)) / 2
            }
        }
    }

    /// What a section's count is called in the header.
    fn count_name(k: usize) -> &'static str {
        match SECTIONS[k].1 {
            Rows::Count(c) => COUNTS[c],
            Rows::PairIj => "atom types (N(N+1)/2 lines)",
        }
    }
}

/// How the `Atoms` lines of this file are read, fixed by the first line.
struct Layout {
    cols: Vec<Col>,
    /// Per column, the frame property it fills.
    props: Vec<Option<usize>>,
}

/// The LAMMPS data file parser; its vectors are scratch kept between reads.
#[derive(Default)]
pub(crate) struct LammpsData {
    layout: Option<Layout>,
    /// Where each atom's line starts, in file order, then in id order.
    atom_at: Vec<Pos>,
    /// `Masses`: type, mass, the comment's first word, where.
    masses: Vec<(Label, f64, Option<Label>, Pos)>,
    /// `Atom Type Labels`: number, label.
    labels: Vec<(Label, Label)>,
    /// `Velocities`: id, velocity, where.
    velocities: Vec<(i64, [f32; 3], Pos)>,
    /// `Bonds`: the two atom ids and where each is written.
    bonds: Vec<([i64; 2], [Pos; 2])>,
    perm: Vec<(i64, u32)>,
}

impl LammpsData {
    fn reset(&mut self) {
        self.layout = None;
        self.atom_at.clear();
        self.masses.clear();
        self.labels.clear();
        self.velocities.clear();
        self.bonds.clear();
    }

    /// The `Atoms` layout from the section's style comment (`hint`) or the first line's column
    /// count; creates the frame's properties.
    fn layout(
        ctx: &Ctx,
        pos: Pos,
        raw: &[u8],
        hint: &[u8],
        n_fields: usize,
        n_atoms: usize,
        frame: &mut Frame,
    ) -> Result<Layout, Error> {
        let style = match style_named(hint) {
            Some(Some(cols)) => cols,
            // (An unknown style was refused at the section's keyword.)
            Some(None) | None => match n_fields {
                5 | 8 => STYLES[0].1,
                7 | 10 => STYLES[3].1,
                _ => {
                    return Err(ctx.parse(
                        pos,
                        raw,
                        trim(raw),
                        "an Atoms line of 5 (atomic) or 7 (full) columns, or an 'Atoms # style' comment naming the style",
                    ));
                }
            },
        };
        let mut cols = style.to_vec();
        if n_fields == cols.len() + 3 {
            cols.extend([Col::Image(0), Col::Image(1), Col::Image(2)]);
        } else if n_fields != cols.len() {
            return Err(ctx.parse(
                pos,
                raw,
                trim(raw),
                "as many columns as the atom style has (plus 3 optional image flags)",
            ));
        }
        let reserve = n_atoms.min(ctx.reserve);
        let props = cols
            .iter()
            .map(|c| {
                let name = match c {
                    Col::Q => "charge",
                    Col::Diameter => "diameter",
                    Col::Named(n) => *n,
                    Col::Image(k) => ["ix", "iy", "iz"][*k],
                    _ => return None,
                };
                frame.properties.push(Property {
                    name: name.to_string(),
                    values: Vec::with_capacity(reserve),
                });
                Some(frame.properties.len() - 1)
            })
            .collect();
        Ok(Layout { cols, props })
    }

    /// One `Atoms` line.
    #[allow(clippy::too_many_arguments)] // the line, where it is, and what it goes into
    fn atom(
        &mut self,
        ctx: &Ctx,
        pos: Pos,
        raw: &[u8],
        line: &[u8],
        hint: &[u8],
        n_atoms: usize,
        frame: &mut Frame,
    ) -> Result<(), Error> {
        let n_fields = fields(line).count();
        if self.layout.is_none() {
            frame.positions.reserve(n_atoms.min(ctx.reserve));
            self.layout = Some(Self::layout(ctx, pos, raw, hint, n_fields, n_atoms, frame)?);
        }
        let layout = self.layout.as_ref().expect("set above");
        if n_fields != layout.cols.len() {
            return Err(ctx.parse(
                pos,
                raw,
                trim(raw),
                "as many columns as the first Atoms line (the atom style's, plus 3 optional image flags)",
            ));
        }
        let mut xyz = [0f32; 3];
        for ((f, col), prop) in fields(line).zip(&layout.cols).zip(&layout.props) {
            match *col {
                Col::Id => {
                    let id = parse_i64(f)
                        .filter(|id| *id > 0)
                        .ok_or_else(|| ctx.parse(pos, raw, f, "a positive atom id"))?;
                    frame.ids.push(id);
                }
                Col::Mol => {
                    let m = parse_i64(f)
                        .ok_or_else(|| ctx.parse(pos, raw, f, "an integer molecule id"))?;
                    frame.res_ids.push(m);
                }
                Col::Type => {
                    let t = Label::from_utf8(f).ok_or_else(|| {
                        ctx.parse(pos, raw, f, "an atom type of at most 15 bytes")
                    })?;
                    frame.types.push(t);
                }
                Col::X(k) => {
                    xyz[k] = parse_f32(f).ok_or_else(|| ctx.parse(pos, raw, f, "a coordinate"))?;
                }
                Col::Image(_) => {
                    let v = parse_i64(f)
                        .and_then(|v| i32::try_from(v).ok())
                        .ok_or_else(|| ctx.parse(pos, raw, f, "an integer image flag"))?;
                    let k = prop.expect("image flags are properties");
                    frame.properties[k].values.push(v as f32);
                }
                Col::Q | Col::Diameter | Col::Named(_) => {
                    let v = parse_f32(f).ok_or_else(|| {
                        ctx.parse(pos, raw, f, "a finite number (the atom style's column)")
                    })?;
                    if *col == Col::Diameter && v < 0.0 {
                        return Err(ctx.parse(pos, raw, f, "a diameter >= 0"));
                    }
                    let k = prop.expect("numbers are properties");
                    frame.properties[k].values.push(v);
                }
            }
        }
        frame.positions.push(xyz);
        self.atom_at.push(pos);
        Ok(())
    }

    /// One line of a section other than `Atoms`, into the parser's lists.
    fn row(&mut self, k: usize, ctx: &Ctx, pos: Pos, raw: &[u8], line: &[u8]) -> Result<(), Error> {
        let f: Vec<&[u8]> = fields(line).collect();
        match k {
            S_MASSES => {
                let [t, m] = f[..] else {
                    return Err(ctx.parse(pos, raw, line, "a Masses line 'type mass'"));
                };
                let t = Label::from_utf8(t)
                    .ok_or_else(|| ctx.parse(pos, raw, t, "an atom type of at most 15 bytes"))?;
                let m = parse_f64(m)
                    .filter(|m| *m > 0.0)
                    .ok_or_else(|| ctx.parse(pos, raw, m, "a mass > 0"))?;
                let word = fields(comment(raw)).next().and_then(Label::from_utf8);
                self.masses.push((t, m, word, pos));
            }
            S_ATOM_TYPE_LABELS => {
                let [n, l] = f[..] else {
                    return Err(ctx.parse(pos, raw, line, "a type label line 'type label'"));
                };
                let n = parse_i64(n)
                    .filter(|n| *n > 0)
                    .and_then(|_| Label::from_utf8(n))
                    .ok_or_else(|| ctx.parse(pos, raw, n, "a positive atom type number"))?;
                let l = Label::from_utf8(l)
                    .ok_or_else(|| ctx.parse(pos, raw, l, "a type label of at most 15 bytes"))?;
                self.labels.push((n, l));
            }
            S_VELOCITIES => {
                if f.len() < 4 {
                    return Err(ctx.parse(pos, raw, line, "a Velocities line 'id vx vy vz'"));
                }
                let id = parse_i64(f[0]).ok_or_else(|| ctx.parse(pos, raw, f[0], "an atom id"))?;
                let mut v = [0f32; 3];
                for (x, s) in v.iter_mut().zip(&f[1..4]) {
                    *x = parse_f32(s).ok_or_else(|| ctx.parse(pos, raw, s, "a velocity"))?;
                }
                self.velocities.push((id, v, pos));
            }
            S_BONDS => {
                let [_, _, a, b] = f[..] else {
                    return Err(ctx.parse(pos, raw, line, "a Bonds line 'id type atom1 atom2'"));
                };
                let id =
                    |s: &[u8]| parse_i64(s).ok_or_else(|| ctx.parse(pos, raw, s, "an atom id"));
                self.bonds
                    .push(([id(a)?, id(b)?], [pos_of(pos, raw, a), pos_of(pos, raw, b)]));
            }
            _ => {}
        }
        Ok(())
    }

    /// After the last section: ids ordered and checked, types, elements, masses, velocities and
    /// bonds resolved.
    fn finish(&mut self, ctx: &Ctx, h: &Header, frame: &mut Frame) -> Result<(), Error> {
        let n = frame.n_atoms();
        // Order by id (file order → id order).
        if !frame.ids.is_sorted() {
            self.perm.clear();
            self.perm
                .extend(frame.ids.iter().enumerate().map(|(k, id)| (*id, k as u32)));
            self.perm.sort_unstable();
            let perm = &self.perm;
            fn permute<T: Copy>(v: &mut Vec<T>, perm: &[(i64, u32)]) {
                if !v.is_empty() {
                    *v = perm.iter().map(|&(_, i)| v[i as usize]).collect();
                }
            }
            permute(&mut frame.positions, perm);
            permute(&mut frame.ids, perm);
            permute(&mut frame.types, perm);
            permute(&mut frame.res_ids, perm);
            permute(&mut self.atom_at, perm);
            for p in &mut frame.properties {
                permute(&mut p.values, perm);
            }
        }
        if let Some(k) = frame.ids.windows(2).position(|w| w[0] == w[1]) {
            let (a, b) = (self.atom_at[k], self.atom_at[k + 1]);
            let (first, second) = if a.byte < b.byte { (a, b) } else { (b, a) };
            return Err(err(
                ctx,
                second,
                "each atom id once in the Atoms section",
                format!("id {} again (first on line {})", frame.ids[k], first.line),
            ));
        }
        // Types: numbers in range, labels from the Atom Type Labels section; the key of each
        // type is its number.
        let to_number: HashMap<Label, Label> = self.labels.iter().map(|(n, l)| (*l, *n)).collect();
        let key = |t: &Label| -> Option<Label> {
            match parse_i64(t.as_bytes()) {
                Some(v) => (v >= 1 && (!h.has_atom_types || v as u64 <= h.counts[ATOM_TYPES]))
                    .then_some(*t),
                None => to_number.get(t).copied(),
            }
        };
        let mut keys = Vec::with_capacity(n);
        for (t, at) in frame.types.iter().zip(&self.atom_at) {
            keys.push(key(t).ok_or_else(|| {
                err(
                    ctx,
                    *at,
                    "an atom type in 1..=the header's 'atom types', or a label of the Atom Type Labels section",
                    t.as_str(),
                )
            })?);
        }
        // Per type: mass and element.
        let mut per_type: HashMap<Label, (Option<f64>, Option<Element>)> = HashMap::new();
        for (num, label) in &self.labels {
            per_type.entry(*num).or_default().1 = element_of_symbol(label.as_bytes());
        }
        for (t, m, word, at) in &self.masses {
            let k = key(t).ok_or_else(|| {
                err(
                    ctx,
                    *at,
                    "a Masses type in 1..=the header's 'atom types', or a label of the Atom Type Labels section",
                    t.as_str(),
                )
            })?;
            let entry = per_type.entry(k).or_default();
            entry.0 = Some(*m);
            let named = word.and_then(|w| element_of_symbol(w.as_bytes()));
            entry.1 = named.or(entry.1).or_else(|| element_of_mass(*m));
        }
        let info = |k: &Label| per_type.get(k).copied().unwrap_or_default();
        if keys.iter().any(|k| info(k).1.is_some()) {
            frame
                .elements
                .extend(keys.iter().map(|k| info(k).1.unwrap_or(Element::UNKNOWN)));
        }
        if !self.masses.is_empty() && keys.iter().all(|k| info(k).0.is_some()) {
            let values = keys
                .iter()
                .map(|k| info(k).0.unwrap_or(0.0) as f32)
                .collect();
            frame.properties.push(Property {
                name: "mass".into(),
                values,
            });
        }
        // Sphere diameters as radii when every particle has one.
        if let Some(k) = frame.properties.iter().position(|p| p.name == "diameter")
            && frame.properties[k].values.iter().all(|d| *d > 0.0)
        {
            let p = frame.properties.remove(k);
            frame.radii = p.values.iter().map(|d| d * 0.5).collect();
        }
        let index = |id: i64| frame.ids.binary_search(&id).ok();
        // Velocities, each atom once (the section has one line per atom).
        if !self.velocities.is_empty() {
            let mut v = vec![[f32::NAN; 3]; n];
            for (id, vel, at) in &self.velocities {
                let Some(i) = index(*id) else {
                    return Err(err(
                        ctx,
                        *at,
                        "a velocity for an atom id of the Atoms section",
                        id.to_string(),
                    ));
                };
                if !v[i][0].is_nan() {
                    return Err(err(
                        ctx,
                        *at,
                        "each atom id once in the Velocities section",
                        id.to_string(),
                    ));
                }
                v[i] = *vel;
            }
            for (c, name) in ["vx", "vy", "vz"].iter().enumerate() {
                frame.properties.push(Property {
                    name: (*name).into(),
                    values: v.iter().map(|x| x[c]).collect(),
                });
            }
        }
        // Bonds as index pairs.
        frame.bonds.reserve(self.bonds.len());
        for (ids, at) in &self.bonds {
            let mut ij = [0u32; 2];
            for k in 0..2 {
                ij[k] = index(ids[k]).ok_or_else(|| {
                    err(
                        ctx,
                        at[k],
                        "a bond between atom ids of the Atoms section",
                        ids[k].to_string(),
                    )
                })? as u32;
            }
            if ij[0] == ij[1] {
                return Err(err(
                    ctx,
                    at[1],
                    "a bond between two different atoms",
                    ids[1].to_string(),
                ));
            }
            frame.bonds.push([ij[0].min(ij[1]), ij[0].max(ij[1])]);
        }
        frame.bonds.sort_unstable();
        frame.bonds.dedup();
        Ok(())
    }
}

impl FrameWalk for LammpsData {
    /// The whole file is one frame: the title, the header, every section. Without a frame the
    /// structure alone is checked (header, section keywords and line counts).
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        mut frame: Option<&mut Frame>,
    ) -> Result<bool, Error> {
        self.reset();
        // Title: line 1, whatever it holds. When line 1 was blank the reader skipped it, and
        // this line is the header's first.
        let p = lines.pos();
        let Some((pos, title)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Ok(false);
        };
        if pos.line == 1 {
            if let Some(f) = frame.as_deref_mut() {
                f.comment = String::from_utf8_lossy(trim(title)).into_owned();
            }
        } else {
            lines.unread(pos);
        }
        // Header lines, up to the first section keyword.
        let mut h = Header::default();
        let mut next: Option<(Pos, usize, Vec<u8>)> = None;
        loop {
            let p = lines.pos();
            let Some((pos, raw)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                break;
            };
            let line = trim(strip_comment(raw));
            if line.is_empty() || h.line(ctx, pos, raw, line)? {
                continue;
            }
            let Some(k) = section_of(line) else {
                return Err(ctx.parse(
                    pos,
                    raw,
                    line,
                    "a header line ('N atoms', 'xlo xhi', ...) or a section keyword this reader knows (Atoms, Masses, Bonds, Pair Coeffs, ...)",
                ));
            };
            next = Some((pos, k, comment(raw).to_vec()));
            break;
        }
        let end = lines.pos();
        if !h.has_atoms {
            return Err(match &next {
                Some((at, k, _)) => err(
                    ctx,
                    *at,
                    "an 'N atoms' header line before the sections",
                    SECTIONS[*k].0,
                ),
                None => ctx.truncated(
                    end,
                    "the header's 'N atoms' line and the Atoms section".into(),
                ),
            });
        }
        // A box cut short by the end of the file is a cut, not a damaged box.
        let partial = h.box_at.is_some()
            && h.bounds.iter().any(Option::is_none)
            && h.general.iter().any(Option::is_none);
        if next.is_none() && partial {
            return Err(ctx.truncated(
                end,
                "the rest of the header's box lines and the sections".into(),
            ));
        }
        let cell = h.cell(ctx, next.as_ref().map_or(end, |n| n.0))?;
        let n_atoms = usize::try_from(h.counts[ATOMS]).unwrap_or(usize::MAX);
        if let Some(f) = frame.as_deref_mut() {
            f.cell = cell;
        }
        // Sections.
        let mut seen = [false; SECTIONS.len()];
        while let Some((pos, k, hint)) = next.take() {
            let name = SECTIONS[k].0;
            if seen[k] {
                return Err(err(ctx, pos, "each section once", name));
            }
            seen[k] = true;
            if k == S_ATOMS && style_named(&hint).is_none() {
                let word = fields(&hint).next().unwrap_or_default();
                return Err(err(
                    ctx,
                    pos,
                    "an atom style this reader knows after 'Atoms #' (atomic, charge, molecular, bond, angle, full, sphere, ellipsoid, dipole, peri, dpd)",
                    String::from_utf8_lossy(word),
                ));
            }
            let n = h.rows(k);
            let mut got = 0u64;
            while got < n {
                let p = lines.pos();
                let Some((rpos, raw)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                    return Err(ctx.truncated(
                        p,
                        format!(
                            "{} more lines of the {name} section (the header's {n} {})",
                            n - got,
                            Header::count_name(k)
                        ),
                    ));
                };
                let line = trim(strip_comment(raw));
                if line.is_empty() {
                    continue;
                }
                if let Some(other) = section_of(line) {
                    return Err(err(
                        ctx,
                        rpos,
                        "as many lines in a section as the header counts",
                        format!(
                            "{} after {got} of the {n} lines of the {name} section (the header's {})",
                            SECTIONS[other].0,
                            Header::count_name(k)
                        ),
                    ));
                }
                got += 1;
                if let Some(f) = frame.as_deref_mut() {
                    if k == S_ATOMS {
                        self.atom(ctx, rpos, raw, line, &hint, n_atoms, f)?;
                    } else {
                        self.row(k, ctx, rpos, raw, line)?;
                    }
                }
            }
            // The next line that is not blank starts another section, or the file ends.
            loop {
                let p = lines.pos();
                let Some((rpos, raw)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                    break;
                };
                let line = trim(strip_comment(raw));
                if line.is_empty() {
                    continue;
                }
                let Some(k2) = section_of(line) else {
                    return Err(ctx.parse(
                        rpos,
                        raw,
                        line,
                        "a section keyword this reader knows, after as many lines as the header counts",
                    ));
                };
                next = Some((rpos, k2, comment(raw).to_vec()));
                break;
            }
        }
        // Sections a non-zero count needs.
        let end = lines.pos();
        for (k, (name, _, required)) in SECTIONS.iter().enumerate() {
            let n = h.rows(k);
            if *required && n > 0 && !seen[k] {
                return Err(ctx.truncated(
                    end,
                    format!(
                        "the {name} section (the header's {n} {})",
                        Header::count_name(k)
                    ),
                ));
            }
        }
        if let Some(f) = frame {
            self.finish(ctx, &h, f)?;
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masses_name_one_element_or_none() {
        let sym = |m: f64| element_of_mass(m).map(|e| e.symbol());
        assert_eq!(sym(12.011), Some("C"));
        assert_eq!(sym(12.0), Some("C"));
        assert_eq!(sym(12.01), Some("C"));
        assert_eq!(sym(15.9994), Some("O"));
        assert_eq!(sym(16.0), Some("O"));
        assert_eq!(sym(1.008), Some("H"));
        assert_eq!(sym(1.00794), Some("H"));
        assert_eq!(sym(55.845), Some("Fe"));
        // Reduced units, deuterium, united-atom CH2 and CH3, a Martini bead: none.
        for m in [1.0, 2.014, 14.027, 15.035, 72.0] {
            assert_eq!(sym(m), None, "{m}");
        }
        // Every element's own weight names it, except the two pairs whose weights lie within
        // 0.1 % of each other (Bi 208.980 and Po 208.982, Cm and Bk at 247.070): ambiguous.
        for z in 1..=103u8 {
            let e = Element::from_z(z).unwrap();
            let want = (!["Bi", "Po", "Cm", "Bk"].contains(&e.symbol())).then_some(e);
            assert_eq!(element_of_mass(e.mass()), want, "{}", e.symbol());
        }
    }

    #[test]
    fn section_keywords_with_any_blanks() {
        assert_eq!(section_of(b"Pair  Coeffs"), Some(16));
        assert_eq!(section_of(b"Atoms"), Some(S_ATOMS));
        assert_eq!(section_of(b"Atom Type Labels"), Some(S_ATOM_TYPE_LABELS));
        assert_eq!(section_of(b"Atomsx"), None);
        assert_eq!(section_of(b"1 2 3"), None);
    }
}
