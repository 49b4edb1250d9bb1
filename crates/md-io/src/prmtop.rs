//! AMBER parameter/topology files (`.prmtop`, `.parm7`): atoms, residues and bonds, as a
//! [`Topology`] for the AMBER NetCDF (`.nc`) trajectories they come with.
//!
//! A prmtop (the format of AMBER 7 and later, which tleap, ParmEd, cpptraj and CHARMM's
//! `chamber` write) is a `%VERSION` line and then sections, each a `%FLAG NAME` line, optional
//! `%COMMENT` lines, a Fortran `%FORMAT(20a4)`-style line and the data in fixed-width fields.
//! Sections come in any order; those not needed to draw molecules (force constants, angles,
//! dihedrals, ...) are skipped. Read here:
//!
//! - `POINTERS`: `NATOM` (1st), `NBONH` (3rd), `MBONA` (4th) and `NRES` (12th), against which
//!   the sections below are counted: a section holding fewer or more entries is an error naming
//!   its `%FLAG` line, never a silently shifted column;
//! - `ATOM_NAME`, `AMBER_ATOM_TYPE` (the types), `ATOMIC_NUMBER`, `MASS` and `CHARGE` (stored
//!   times 18.2223, divided back to e);
//! - `RESIDUE_LABEL` and `RESIDUE_POINTER` (the first atom of each residue, 1-based);
//! - `BONDS_INC_HYDROGEN` and `BONDS_WITHOUT_HYDROGEN`: triples `3*(i-1) 3*(j-1) type`;
//! - `RESIDUE_CHAINID` (cpptraj and ParmEd write it when the system has chains): the chains;
//! - `BOX_DIMENSIONS` (beta, a, b, c), for the box angles an AMBER ASCII trajectory leaves out:
//!   a truncated octahedron's beta (109.4712°) is all three angles, another beta a monoclinic
//!   box's (90°, beta, 90°).
//!
//! **Residue numbers** are 1..NRES in file order, as AMBER itself, VMD and MDAnalysis number
//! them (`resid 10` selects the tenth residue); a `RESIDUE_NUMBER` section with the numbers of
//! the PDB the system was built from is not read. Atom ids are 1..NATOM.
//!
//! **Elements** come from `ATOMIC_NUMBER`. An atom whose number is 0 or negative (extra points
//! and virtual sites, which tleap writes as −1) is unknown when its mass is below 0.5 u, and
//! otherwise guessed from its name and mass as for PSF files; files written before
//! `ATOMIC_NUMBER` existed are guessed that way throughout.
//!
//! Counts in `POINTERS` are never trusted for allocation: entries are pushed as read.

use std::collections::HashMap;
use std::io::Read;
use std::sync::Arc;

use crate::elements::Element;
use crate::error::Error;
use crate::frame::Label;
use crate::parse::{parse_f64, parse_i64};
use crate::topology::{LineAt, Lines, Topology, at, parse_err, tidy};

/// AMBER stores charges multiplied by 18.2223 (the square root of Coulomb's constant in
/// kcal·Å/(mol·e²)), so that products of two are energies.
const AMBER_CHARGE: f64 = 18.2223;

/// A `%FORMAT(...)` descriptor: `count` fields of `width` bytes a line.
#[derive(Clone, Copy, Debug, PartialEq)]
struct FieldFormat {
    count: usize,
    width: usize,
    kind: Kind,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Text,
    Int,
    Real,
}

/// Parses the inside of `%FORMAT(...)`: `20a4`, `10I8`, `5E16.8`, `1a80`, `(3I8)` (count 1 when
/// absent); `None` when it is not one of those.
fn field_format(line: &[u8]) -> Option<FieldFormat> {
    let rest = line.strip_prefix(b"%FORMAT")?;
    let open = rest.iter().position(|&b| b == b'(')?;
    let close = rest.iter().position(|&b| b == b')')?;
    let spec = rest.get(open + 1..close)?;
    let spec: Vec<u8> = spec
        .iter()
        .copied()
        .filter(|b| !b.is_ascii_whitespace())
        .collect();
    let letter = spec.iter().position(|b| b.is_ascii_alphabetic())?;
    let count = if letter == 0 {
        1
    } else {
        usize::try_from(parse_i64(&spec[..letter])?).ok()?
    };
    let kind = match spec[letter].to_ascii_uppercase() {
        b'A' => Kind::Text,
        b'I' => Kind::Int,
        b'E' | b'F' | b'G' | b'D' => Kind::Real,
        _ => return None,
    };
    let width_end = spec[letter + 1..]
        .iter()
        .position(|&b| b == b'.')
        .map_or(spec.len(), |p| letter + 1 + p);
    let width = usize::try_from(parse_i64(&spec[letter + 1..width_end])?).ok()?;
    ((1..=1000).contains(&count) && (1..=200).contains(&width)).then_some(FieldFormat {
        count,
        width,
        kind,
    })
}

/// One section's data as read.
enum Values {
    Text(Vec<Label>),
    Int(Vec<i64>),
    Real(Vec<f64>),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::Text(v) => v.len(),
            Values::Int(v) => v.len(),
            Values::Real(v) => v.len(),
        }
    }
}

/// A section kept for the topology: its name, its data and where its `%FLAG` line is.
struct Section {
    name: &'static str,
    flag: LineAt,
    values: Values,
}

impl Section {
    fn text(self, file: &Arc<str>) -> Result<Vec<Label>, Error> {
        match self.values {
            Values::Text(v) => Ok(v),
            _ => Err(wrong_kind(file, &self, "text (a4)")),
        }
    }

    fn ints(self, file: &Arc<str>) -> Result<Vec<i64>, Error> {
        match self.values {
            Values::Int(v) => Ok(v),
            _ => Err(wrong_kind(file, &self, "integers")),
        }
    }

    fn reals(self, file: &Arc<str>) -> Result<Vec<f64>, Error> {
        match self.values {
            Values::Real(v) => Ok(v),
            _ => Err(wrong_kind(file, &self, "numbers")),
        }
    }
}

/// The sections this reader uses; the others are skipped without parsing their fields.
const WANTED: [&str; 12] = [
    "POINTERS",
    "CHARGE",
    "ATOM_NAME",
    "AMBER_ATOM_TYPE",
    "ATOMIC_NUMBER",
    "MASS",
    "RESIDUE_LABEL",
    "RESIDUE_POINTER",
    "BONDS_INC_HYDROGEN",
    "BONDS_WITHOUT_HYDROGEN",
    "RESIDUE_CHAINID",
    "BOX_DIMENSIONS",
];

/// Splits a data line into `fmt`'s fixed-width fields and appends them to `values`. Blank
/// numeric fields at the end of a line (the last line of a section) are not values.
fn push_fields(
    line: &[u8],
    fmt: FieldFormat,
    values: &mut Values,
    file: &Arc<str>,
    pos: &LineAt,
) -> Result<(), Error> {
    if line.len() > fmt.count * fmt.width {
        return Err(parse_err(
            file,
            pos,
            "at most the %FORMAT's fields on a line",
            line,
        ));
    }
    for field in line.chunks(fmt.width) {
        match values {
            Values::Text(v) => {
                let text = field.trim_ascii();
                v.push(
                    Label::from_utf8(text)
                        .ok_or_else(|| parse_err(file, pos, "a name of at most 15 bytes", field))?,
                );
            }
            Values::Int(v) => {
                let t = field.trim_ascii();
                if t.is_empty() {
                    if line[line.len() - field.len()..].trim_ascii().is_empty() {
                        break;
                    }
                    return Err(parse_err(file, pos, "an integer field", field));
                }
                v.push(parse_i64(t).ok_or_else(|| parse_err(file, pos, "an integer", field))?);
            }
            Values::Real(v) => {
                let t = field.trim_ascii();
                if t.is_empty() {
                    if line[line.len() - field.len()..].trim_ascii().is_empty() {
                        break;
                    }
                    return Err(parse_err(file, pos, "a number field", field));
                }
                v.push(
                    parse_f64(t)
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| parse_err(file, pos, "a finite number", field))?,
                );
            }
        }
    }
    Ok(())
}

/// Reads a prmtop (see the module docs) from `src`, named `file` in errors.
pub(crate) fn read_prmtop<R: Read>(src: R, file: &Arc<str>) -> Result<Topology, Error> {
    let mut lines = Lines::new(src, file.clone());
    let mut sections: HashMap<&'static str, Section> = HashMap::new();
    // The section being read: its name if it is wanted, and its format once seen.
    let mut current: Option<(Option<&'static str>, Option<FieldFormat>)> = None;
    let mut first = true;
    while let Some((l, pos)) = lines.next_line()? {
        if first {
            first = false;
            if !(l.starts_with(b"%VERSION") || l.starts_with(b"%FLAG")) {
                return Err(parse_err(
                    file,
                    &pos,
                    "an AMBER prmtop starting with %VERSION or %FLAG (the format of AMBER 7 and later; a GROMACS .top is not a prmtop)",
                    l,
                ));
            }
        }
        if let Some(name) = l.strip_prefix(b"%FLAG") {
            let name = name.trim_ascii();
            let wanted = WANTED.iter().copied().find(|w| w.as_bytes() == name);
            if let Some(w) = wanted {
                if sections.contains_key(w) {
                    return Err(parse_err(file, &pos, "each %FLAG section once", l));
                }
                sections.insert(
                    w,
                    Section {
                        name: w,
                        flag: pos,
                        values: Values::Text(Vec::new()),
                    },
                );
            }
            current = Some((wanted, None));
            continue;
        }
        if l.starts_with(b"%FORMAT") {
            let Some((name, format)) = &mut current else {
                return Err(parse_err(file, &pos, "%FORMAT after a %FLAG line", l));
            };
            let fmt = field_format(l).ok_or_else(|| {
                parse_err(
                    file,
                    &pos,
                    "a Fortran format such as %FORMAT(20a4), (10I8) or (5E16.8)",
                    l,
                )
            })?;
            if let Some(name) = name {
                let section = sections.get_mut(name).expect("inserted at its %FLAG");
                section.values = match fmt.kind {
                    Kind::Text => Values::Text(Vec::new()),
                    Kind::Int => Values::Int(Vec::new()),
                    Kind::Real => Values::Real(Vec::new()),
                };
            }
            *format = Some(fmt);
            continue;
        }
        if l.starts_with(b"%") {
            continue; // %VERSION, %COMMENT and other directives
        }
        match current {
            Some((Some(name), Some(fmt))) => {
                let section = sections.get_mut(name).expect("inserted at its %FLAG");
                push_fields(l, fmt, &mut section.values, file, &pos)?;
            }
            Some((_, None)) => {
                return Err(parse_err(file, &pos, "a %FORMAT line after %FLAG", l));
            }
            None if !l.trim_ascii().is_empty() => {
                return Err(parse_err(file, &pos, "a %FLAG line before data", l));
            }
            _ => {} // a skipped section's data
        }
    }
    assemble(sections, file, &lines.end())
}

/// The topology from the sections read; counts are checked against `POINTERS`.
fn assemble(
    mut sections: HashMap<&'static str, Section>,
    file: &Arc<str>,
    end: &LineAt,
) -> Result<Topology, Error> {
    let missing = |what: &'static str| Error::Truncated {
        at: at(file, end),
        expected: format!("a %FLAG {what} section"),
    };
    let pointers = sections
        .remove("POINTERS")
        .ok_or_else(|| missing("POINTERS"))?;
    let pointers_at = at(file, &pointers.flag);
    let p = pointers.ints(file)?;
    if p.len() < 12 {
        return Err(Error::InvalidValue {
            what: format!(
                "{pointers_at}: %FLAG POINTERS holds {} values, at least 12 expected",
                p.len()
            ),
        });
    }
    let count = |k: usize, what: &str| {
        usize::try_from(p[k]).map_err(|_| Error::InvalidValue {
            what: format!("{pointers_at}: POINTERS {what} is {}", p[k]),
        })
    };
    let n_atoms = count(0, "NATOM")?;
    let n_bonds_h = count(2, "NBONH")?;
    let n_bonds_a = count(3, "MBONA")?;
    let n_res = count(11, "NRES")?;
    if n_atoms == 0 || n_atoms > u32::MAX as usize {
        return Err(Error::InvalidValue {
            what: format!("{pointers_at}: POINTERS NATOM is {n_atoms}, expected 1 to 2^32-1 atoms"),
        });
    }

    // A section, checked to hold `want` entries; `None` when the file lacks it.
    let mut take =
        |name: &'static str, want: usize, what: &str| -> Result<Option<Section>, Error> {
            let Some(s) = sections.remove(name) else {
                return Ok(None);
            };
            if s.values.len() != want {
                return Err(Error::InvalidValue {
                    what: format!(
                        "{}: %FLAG {name} holds {} {what}, POINTERS says {want}",
                        at(file, &s.flag),
                        s.values.len()
                    ),
                });
            }
            Ok(Some(s))
        };
    let names = take("ATOM_NAME", n_atoms, "names")?
        .ok_or_else(|| missing("ATOM_NAME"))?
        .text(file)?;
    let types = match take("AMBER_ATOM_TYPE", n_atoms, "types")? {
        Some(s) => s.text(file)?,
        None => Vec::new(),
    };
    let res_labels = take("RESIDUE_LABEL", n_res, "residue names")?
        .ok_or_else(|| missing("RESIDUE_LABEL"))?
        .text(file)?;
    let chain_ids = take("RESIDUE_CHAINID", n_res, "chain ids")?
        .map(|s| s.text(file))
        .transpose()?;
    let pointer_section = take("RESIDUE_POINTER", n_res, "residue pointers")?
        .ok_or_else(|| missing("RESIDUE_POINTER"))?;
    let pointer_at = at(file, &pointer_section.flag);
    let starts = pointer_section.ints(file)?;
    // Residue r covers atoms starts[r]-1 .. starts[r+1]-1: 1 first, strictly increasing.
    let bad_start = starts.first() != Some(&1)
        || starts.windows(2).any(|w| w[1] <= w[0])
        || starts
            .last()
            .is_some_and(|&s| s < 1 || s as usize > n_atoms);
    if bad_start {
        return Err(Error::InvalidValue {
            what: format!(
                "{pointer_at}: RESIDUE_POINTER must start at 1 and increase strictly up to NATOM = {n_atoms}"
            ),
        });
    }
    let mut res_names = Vec::with_capacity(n_atoms);
    let mut res_ids = Vec::with_capacity(n_atoms);
    let mut chains = Vec::new();
    for r in 0..n_res {
        let from = starts[r] as usize - 1;
        let to = starts.get(r + 1).map_or(n_atoms, |&s| s as usize - 1);
        for _ in from..to {
            res_names.push(res_labels[r]);
            res_ids.push(r as i64 + 1);
            if let Some(c) = &chain_ids {
                chains.push(c[r]);
            }
        }
    }
    let charges = match take("CHARGE", n_atoms, "charges")? {
        Some(s) => s
            .reals(file)?
            .iter()
            .map(|q| (q / AMBER_CHARGE) as f32)
            .collect(),
        None => Vec::new(),
    };
    let masses = take("MASS", n_atoms, "masses")?
        .map(|s| s.reals(file))
        .transpose()?;
    let numbers = take("ATOMIC_NUMBER", n_atoms, "atomic numbers")?
        .map(|s| s.ints(file))
        .transpose()?;
    let elements = (0..n_atoms)
        .map(|i| {
            let mass = masses.as_ref().map_or(f64::NAN, |m| m[i]);
            let z = numbers.as_ref().map_or(0, |z| z[i]);
            match u8::try_from(z).ok().and_then(Element::from_z) {
                Some(e) => e,
                None if numbers.is_some() && mass < 0.5 => Element::UNKNOWN,
                None => crate::psf::element_of(names[i].as_str(), res_names[i].as_str(), mass),
            }
        })
        .collect();

    let mut bonds = Vec::new();
    for (name, want, pointer) in [
        ("BONDS_INC_HYDROGEN", n_bonds_h, "NBONH"),
        ("BONDS_WITHOUT_HYDROGEN", n_bonds_a, "MBONA"),
    ] {
        let Some(s) = sections.remove(name) else {
            if want > 0 {
                return Err(missing(name));
            }
            continue;
        };
        let flag_at = at(file, &s.flag);
        let v = s.ints(file)?;
        if v.len() != 3 * want {
            return Err(Error::InvalidValue {
                what: format!(
                    "{flag_at}: %FLAG {name} holds {} values, POINTERS {pointer} = {want} bonds needs {}",
                    v.len(),
                    3 * want
                ),
            });
        }
        for t in v.chunks_exact(3) {
            let atom = |x: i64| {
                (x >= 0 && x % 3 == 0 && ((x / 3) as usize) < n_atoms).then_some((x / 3) as u32)
            };
            match (atom(t[0]), atom(t[1])) {
                (Some(a), Some(b)) if a != b => bonds.push([a, b]),
                _ => {
                    return Err(Error::InvalidValue {
                        what: format!(
                            "{flag_at}: %FLAG {name} has the bond {} {}: atom entries are 3*(atom-1), atoms 1..{n_atoms}",
                            t[0], t[1]
                        ),
                    });
                }
            }
        }
    }
    tidy(&mut bonds);

    let ids = (1..=n_atoms as i64).collect();
    let mut topology = Topology::from_parts(
        file.clone(),
        names,
        elements,
        types,
        ids,
        res_names,
        res_ids,
        bonds,
    );
    topology.chains = chains;
    topology.charges = charges;
    if let Some(s) = sections.remove("BOX_DIMENSIONS") {
        let flag_at = at(file, &s.flag);
        let v = s.reals(file)?;
        let beta = match v.first() {
            Some(&b) if v.len() == 4 && b > 0.0 && b < 180.0 => b,
            _ => {
                return Err(Error::InvalidValue {
                    what: format!(
                        "{flag_at}: %FLAG BOX_DIMENSIONS holds {v:?}, expected 4 numbers: the angle beta (0 to 180 degrees) and the box lengths"
                    ),
                });
            }
        };
        // A truncated octahedron has all three angles at arccos(-1/3); any other beta is
        // a monoclinic box's (alpha = gamma = 90), as cpptraj reads it.
        const TRUNCOCT: f64 = 109.471_220_634_490_7;
        topology.box_angles = Some(if (beta - TRUNCOCT).abs() < 0.001 {
            [TRUNCOCT; 3]
        } else {
            [90.0, beta, 90.0]
        });
    }
    Ok(topology)
}

fn wrong_kind(file: &Arc<str>, s: &Section, expected: &str) -> Error {
    Error::InvalidValue {
        what: format!(
            "{}: %FLAG {} has a %FORMAT of another kind, expected {expected}",
            at(file, &s.flag),
            s.name
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn prmtop(text: &str) -> Result<Topology, Error> {
        read_prmtop(Cursor::new(text), &"t.prmtop".into())
    }

    /// A TIP4P-style water (oxygen, two hydrogens, an extra point that tleap writes with atomic
    /// number -1 and mass 0) and a calcium ion with atomic number 0, in the
    /// chamber layout (%COMMENT lines between %FLAG and %FORMAT). Bonds: O-H1 and O-H2 with
    /// hydrogen, none without.
    const WATER: &str = "%VERSION  VERSION_STAMP = V0001.000  DATE = 01/01/26  00:00:00\n\
%FLAG CTITLE\n%FORMAT(a80)\nwater\n\
%FLAG POINTERS\n%COMMENT counts\n%FORMAT(10I8)\n\
       5       3       2       0       0       0       0       0       0       0\n\
      10       2       0       0       0       2       0       0       3       0\n\
       0       0       0       0       0       0       0       0       4       0\n\
       0\n\
%FLAG ATOM_NAME\n%FORMAT(20a4)\nO   H1  H2  EPW CAL \n\
%FLAG CHARGE\n%FORMAT(5E16.8)\n -1.51973982E+01  7.59869910E+00  7.59869910E+00  0.00000000E+00\n  3.64446000E+01\n\
%FLAG ATOMIC_NUMBER\n%FORMAT(10I8)\n       8       1       1      -1       0\n\
%FLAG MASS\n%FORMAT(5E16.8)\n  1.60000000E+01  1.00800000E+00  1.00800000E+00  0.00000000E+00\n  4.00800000E+01\n\
%FLAG RESIDUE_LABEL\n%FORMAT(20a4)\nWAT CAL \n\
%FLAG RESIDUE_POINTER\n%FORMAT(10I8)\n       1       5\n\
%FLAG BONDS_INC_HYDROGEN\n%FORMAT(10I8)\n       0       3       1       0       6       1\n\
%FLAG BONDS_WITHOUT_HYDROGEN\n%FORMAT(10I8)\n\n\
%FLAG AMBER_ATOM_TYPE\n%FORMAT(20a4)\nOW  HW  HW  EP  C0  \n";

    #[test]
    fn atoms_residues_bonds_and_elements_of_extra_points() {
        let t = prmtop(WATER).unwrap();
        assert_eq!(t.n_atoms(), 5);
        let names: Vec<&str> = t.names.iter().map(|l| l.as_str()).collect();
        assert_eq!(names, ["O", "H1", "H2", "EPW", "CAL"]);
        let types: Vec<&str> = t.types.iter().map(|l| l.as_str()).collect();
        assert_eq!(types, ["OW", "HW", "HW", "EP", "C0"]);
        let res: Vec<&str> = t.res_names.iter().map(|l| l.as_str()).collect();
        assert_eq!(res, ["WAT", "WAT", "WAT", "WAT", "CAL"]);
        assert_eq!(t.res_ids, [1, 1, 1, 1, 2]);
        assert_eq!(t.ids, [1, 2, 3, 4, 5]);
        assert_eq!(t.bonds, [[0, 1], [0, 2]]);
        assert!(t.chains.is_empty());
        // TIP3P's charges, stored times 18.2223.
        let want = [-0.834, 0.417, 0.417, 0.0, 2.0];
        assert!(
            t.charges
                .iter()
                .zip(want)
                .all(|(q, w)| (q - w).abs() < 1e-6),
            "{:?}",
            t.charges
        );
        // The extra point (mass 0) is no element; CAL's 40.08 u makes it calcium, not carbon.
        let e: Vec<&str> = t.elements.iter().map(|e| e.symbol()).collect();
        assert_eq!(e, ["O", "H", "H", "X", "Ca"]);
    }

    #[test]
    fn fortran_formats() {
        let f = |s: &str| field_format(s.as_bytes());
        let ff = |count, width, kind| Some(FieldFormat { count, width, kind });
        assert_eq!(f("%FORMAT(20a4)"), ff(20, 4, Kind::Text));
        assert_eq!(f("%FORMAT(10I8)"), ff(10, 8, Kind::Int));
        assert_eq!(f("%FORMAT(5E16.8)  "), ff(5, 16, Kind::Real));
        assert_eq!(f("%FORMAT(a80)"), ff(1, 80, Kind::Text));
        assert_eq!(f("%FORMAT(20I4)"), ff(20, 4, Kind::Int));
        assert_eq!(f("%FORMAT(20X4)"), None);
        assert_eq!(f("%FORMAT(0I8)"), None);
        assert_eq!(f("%FORMAT(10I)"), None);
    }

    #[test]
    fn damaged_files_are_located_errors() {
        let err = |t: String| prmtop(&t).unwrap_err().to_string();
        // Too many names on a line for its format.
        let e = err(WATER.replace(
            "CAL \n%FLAG CHARGE",
            &format!("CAL {}\n%FLAG CHARGE", "ABCD".repeat(20)),
        ));
        assert!(e.contains("line 14") && e.contains("%FORMAT"), "{e}");
        // A residue pointer past the atoms.
        let e = err(WATER.replace("       1       5\n", "       1       9\n"));
        assert!(
            e.contains("RESIDUE_POINTER") && e.contains("NATOM = 5"),
            "{e}"
        );
        // Fewer bond values than NBONH announces.
        let e = err(WATER.replace("       0       6       1\n", "\n"));
        assert!(
            e.contains("holds 3 values") && e.contains("NBONH = 2"),
            "{e}"
        );
        // A bond to atom 7 of 5.
        let e = err(WATER.replace("       0       6       1\n", "       0      18       1\n"));
        assert!(e.contains("0 18"), "{e}");
        // A section given twice.
        let e = err(format!("{WATER}%FLAG MASS\n"));
        assert!(e.contains("once"), "{e}");
        // No POINTERS at all.
        let e = err("%VERSION\n%FLAG TITLE\n%FORMAT(20a4)\nx\n".into());
        assert!(e.contains("POINTERS"), "{e}");
        // An empty file.
        let e = err(String::new());
        assert!(e.contains("POINTERS"), "{e}");
    }
}
