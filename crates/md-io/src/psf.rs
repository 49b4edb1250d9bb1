//! CHARMM/NAMD/X-PLOR protein structure files (`.psf`): atoms and bonds, as a [`Topology`].
//!
//! A PSF starts with a `PSF` line (flags such as `EXT`, `CHEQ`, `XPLOR`, `CMAP` follow it on the
//! same line), a title block (`N !NTITLE` and N remark lines), then `N !NATOM` and one line per
//! atom: `id segment resid resname name type charge mass [imove ...]` (all kept but the mass, which decides elements), then `N !NBOND` and the
//! bonded pairs of atom ids, four pairs (eight ids) a line. Later sections (angles, dihedrals,
//! ...) are not needed to draw molecules and are not read.
//!
//! Atom lines are split on whitespace, as VMD and MDAnalysis do; the `EXT` and standard fixed
//! column layouts both read this way unless two fields touch, which the writers avoid. The
//! residue number may carry an insertion code (`12A`): its digits are kept. The type is kept as
//! written (a name in X-PLOR files, a number in CHARMM files).
//!
//! **Elements.** A PSF names no element. Each atom's element is guessed from its name as for
//! PDB files ([`guess_element`]), and the mass column decides where the name misleads: when the
//! guess's standard atomic weight is more than 1.5 u away from the atom's mass and one element's
//! weight is within 0.2 u of it, that element is taken (CHARMM's `CAL` is calcium, 40.08 u, not
//! carbon). Hydrogens with repartitioned masses (about 3 u) have no element within 0.2 u and keep
//! their name's element.
//!
//! Counts in the file are never trusted for allocation: atoms and bonds are pushed as read, and
//! a file that ends early is an [`Error::Truncated`] naming how many were announced and found.

use std::io::Read;
use std::sync::Arc;

use crate::elements::{Element, guess_element};
use crate::error::{Error, Location};
use crate::frame::Label;
use crate::parse::{fields, parse_f64, parse_i64};
use crate::topology::{LineAt, Lines, Topology, at, parse_err, tidy};

/// Standard atomic weights (u) of the elements met in biomolecular and materials MD
/// (IUPAC 2021 conventional values, rounded to 0.01 u).
const WEIGHTS: [(&str, f64); 30] = [
    ("H", 1.008),
    ("He", 4.003),
    ("Li", 6.94),
    ("B", 10.81),
    ("C", 12.011),
    ("N", 14.007),
    ("O", 15.999),
    ("F", 18.998),
    ("Ne", 20.18),
    ("Na", 22.99),
    ("Mg", 24.305),
    ("Al", 26.982),
    ("Si", 28.085),
    ("P", 30.974),
    ("S", 32.06),
    ("Cl", 35.45),
    ("Ar", 39.95),
    ("K", 39.098),
    ("Ca", 40.078),
    ("Mn", 54.938),
    ("Fe", 55.845),
    ("Co", 58.933),
    ("Ni", 58.693),
    ("Cu", 63.546),
    ("Zn", 65.38),
    ("Se", 78.971),
    ("Br", 79.904),
    ("Cd", 112.41),
    ("I", 126.9),
    ("Cs", 132.91),
];

fn weight(e: Element) -> Option<f64> {
    WEIGHTS
        .iter()
        .find(|(s, _)| Element::from_symbol(s) == Some(e))
        .map(|w| w.1)
}

/// The element of an atom named `name` in residue `res` with mass `mass` (see the module docs).
pub(crate) fn element_of(name: &str, res: &str, mass: f64) -> Element {
    let guess = guess_element(name, Some(res), None);
    let fits = weight(guess).is_some_and(|w| (w - mass).abs() <= 1.5);
    if fits || !(mass.is_finite() && mass > 0.5) {
        return guess;
    }
    WEIGHTS
        .iter()
        .filter(|(_, w)| (w - mass).abs() <= 0.2)
        .min_by(|a, b| (a.1 - mass).abs().total_cmp(&(b.1 - mass).abs()))
        .and_then(|(s, _)| Element::from_symbol(s))
        .unwrap_or(guess)
}

/// The count before `!TAG` on a section header line (`  66 !NATOM`), if this line is that header.
fn section_count(line: &[u8], tag: &[u8]) -> Option<Option<u64>> {
    let bang = line.iter().position(|&b| b == b'!')?;
    let label = &line[bang + 1..];
    if !label.starts_with(tag) {
        return None;
    }
    let first = fields(&line[..bang]).next()?;
    Some(parse_i64(first).and_then(|n| u64::try_from(n).ok()))
}

/// The digits of a residue number, dropping an insertion code (`12A` -> 12).
fn res_number(s: &[u8]) -> Option<i64> {
    let end = s
        .iter()
        .enumerate()
        .position(|(k, b)| !(b.is_ascii_digit() || (k == 0 && *b == b'-')))
        .unwrap_or(s.len());
    parse_i64(&s[..end])
}

/// Reads a PSF (see the module docs) from `src`, named `file` in errors.
pub(crate) fn read_psf<R: Read>(src: R, file: &Arc<str>) -> Result<Topology, Error> {
    let mut lines = Lines::new(src, file.clone());
    // The PSF header line.
    match lines.next_line()? {
        Some((l, pos)) => {
            if fields(l).next().is_none_or(|f| f != b"PSF") {
                return Err(parse_err(file, &pos, "a first line starting with PSF", l));
            }
        }
        None => {
            return Err(Error::Parse {
                at: Location::file(file),
                expected: "a first line starting with PSF",
                found: "an empty file".into(),
            });
        }
    }
    // Up to !NATOM (the title block is skipped).
    let n_atoms = loop {
        let Some((l, pos)) = lines.next_line()? else {
            return Err(Error::Truncated {
                at: at(file, &end_of(&lines)),
                expected: "an 'N !NATOM' section".into(),
            });
        };
        if let Some(n) = section_count(l, b"NATOM") {
            break n.ok_or_else(|| parse_err(file, &pos, "an atom count before !NATOM", l))?;
        }
    };
    let mut ids: Vec<i64> = Vec::new();
    let mut names: Vec<Label> = Vec::new();
    let mut types: Vec<Label> = Vec::new();
    let mut res_names: Vec<Label> = Vec::new();
    let mut res_ids: Vec<i64> = Vec::new();
    let mut segments: Vec<Label> = Vec::new();
    let mut charges: Vec<f32> = Vec::new();
    let mut elements: Vec<Element> = Vec::new();
    while (ids.len() as u64) < n_atoms {
        let Some((l, pos)) = lines.next_line()? else {
            return Err(Error::Truncated {
                at: at(file, &end_of(&lines)),
                expected: format!(
                    "{n_atoms} atom lines (the !NATOM count), found {}",
                    ids.len()
                ),
            });
        };
        let f: Vec<&[u8]> = fields(l).collect();
        if f.is_empty() {
            continue;
        }
        if f.len() < 8 {
            return Err(parse_err(
                file,
                &pos,
                "an atom line 'id segment resid resname name type charge mass'",
                l,
            ));
        }
        let id = parse_i64(f[0]).ok_or_else(|| parse_err(file, &pos, "an atom id", f[0]))?;
        let resid =
            res_number(f[2]).ok_or_else(|| parse_err(file, &pos, "a residue number", f[2]))?;
        let label = |s: &[u8], what: &'static str| {
            Label::from_utf8(s).ok_or_else(|| parse_err(file, &pos, what, s))
        };
        let segment = label(f[1], "a segment name of at most 15 bytes")?;
        let res = label(f[3], "a residue name of at most 15 bytes")?;
        let name = label(f[4], "an atom name of at most 15 bytes")?;
        let ty = label(f[5], "an atom type of at most 15 bytes")?;
        let charge = parse_f64(f[6])
            .filter(|q| q.is_finite())
            .ok_or_else(|| parse_err(file, &pos, "a finite charge", f[6]))?;
        let mass = parse_f64(f[7])
            .filter(|m| m.is_finite())
            .ok_or_else(|| parse_err(file, &pos, "a finite mass", f[7]))?;
        ids.push(id);
        elements.push(element_of(name.as_str(), res.as_str(), mass));
        names.push(name);
        types.push(ty);
        res_names.push(res);
        res_ids.push(resid);
        segments.push(segment);
        charges.push(charge as f32);
    }
    // Atom ids to indices (PSF ids are 1..N in order, but do not rely on it).
    let mut order: Vec<(i64, u32)> = ids
        .iter()
        .enumerate()
        .map(|(k, &i)| (i, k as u32))
        .collect();
    order.sort_unstable();
    if let Some(w) = order.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(Error::InvalidValue {
            what: format!(
                "{file}: atom id {} appears twice in the !NATOM section",
                w[0].0
            ),
        });
    }
    // Bonds, if the file has the section.
    let mut bonds: Vec<[u32; 2]> = Vec::new();
    let mut header = None;
    while let Some((l, pos)) = lines.next_line()? {
        if let Some(n) = section_count(l, b"NBOND") {
            header = Some(n.ok_or_else(|| parse_err(file, &pos, "a bond count before !NBOND", l))?);
            break;
        }
        if l.contains(&b'!') {
            break; // a later section without bonds before it
        }
    }
    if let Some(n_bonds) = header {
        let mut pending: Option<u32> = None;
        let mut read = 0u64;
        while read < n_bonds {
            let Some((l, pos)) = lines.next_line()? else {
                return Err(Error::Truncated {
                    at: at(file, &end_of(&lines)),
                    expected: format!("{n_bonds} bonds (the !NBOND count), found {read}"),
                });
            };
            for t in fields(l) {
                let id = parse_i64(t).ok_or_else(|| parse_err(file, &pos, "an atom id", t))?;
                let k = order
                    .binary_search_by_key(&id, |o| o.0)
                    .map(|k| order[k].1)
                    .map_err(|_| parse_err(file, &pos, "a bond between atoms of !NATOM", t))?;
                match pending.take() {
                    None => pending = Some(k),
                    Some(a) => {
                        if a != k {
                            bonds.push([a, k]);
                        }
                        read += 1;
                        if read == n_bonds {
                            break;
                        }
                    }
                }
            }
        }
    }
    tidy(&mut bonds);
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
    topology.segments = segments;
    topology.charges = charges;
    Ok(topology)
}

fn end_of<R: Read>(lines: &Lines<R>) -> LineAt {
    lines.end()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn psf(text: &str) -> Result<Topology, Error> {
        read_psf(Cursor::new(text), &"t.psf".into())
    }

    const SMALL: &str = "PSF EXT\n\n         1 !NTITLE\n REMARKS water and an ion\n\n         4 !NATOM\n\
         1 W        1        TIP3     OH2      OT      -0.834000       15.9994           0\n\
         2 W        1        TIP3     H1       HT       0.417000        1.0080           0\n\
         3 W        1        TIP3     H2       HT       0.417000        1.0080           0\n\
         4 I        2A       CAL      CAL      CAL      2.000000       40.0800           0\n\n\
         2 !NBOND: bonds\n         1         2         1         3\n\n         0 !NTHETA\n";

    #[test]
    fn atoms_bonds_and_mass_checked_elements() {
        let t = psf(SMALL).unwrap();
        assert_eq!(t.n_atoms(), 4);
        let n: Vec<&str> = t.names.iter().map(|l| l.as_str()).collect();
        assert_eq!(n, ["OH2", "H1", "H2", "CAL"]);
        assert_eq!(t.res_ids, [1, 1, 1, 2]);
        assert_eq!(t.bonds, [[0, 1], [0, 2]]);
        let e: Vec<&str> = t.elements.iter().map(|e| e.symbol()).collect();
        // CAL: the name reads as carbon, the mass says calcium.
        assert_eq!(e, ["O", "H", "H", "Ca"]);
    }

    #[test]
    fn damaged_files_are_located_errors() {
        let e = psf("PDB\n").unwrap_err().to_string();
        assert!(e.contains("line 1") && e.contains("PSF"), "{e}");
        // An atom line cut short.
        let e = psf(&SMALL.replace("40.0800           0", ""))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 10"), "{e}");
        // More atoms announced than listed: the next section is not an atom line.
        let e = psf(&SMALL.replace("4 !NATOM", "9 !NATOM"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 12") && e.contains("NBOND"), "{e}");
        // A file cut inside the atoms.
        let cut: String = SMALL.lines().take(8).map(|l| format!("{l}\n")).collect();
        let e = psf(&cut).unwrap_err().to_string();
        assert!(e.contains("4 atom lines") && e.contains("found 2"), "{e}");
        // A bond to an atom that does not exist.
        let e = psf(&SMALL.replace("1         3\n", "1         7\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 13") && e.contains("'7'"), "{e}");
        // More bonds announced than given: truncated, not a huge allocation.
        let huge = SMALL
            .replace("2 !NBOND", "4000000000 !NBOND")
            .replace("\n         0 !NTHETA\n", "");
        let e = psf(&huge).unwrap_err().to_string();
        assert!(e.contains("4000000000 bonds"), "{e}");
    }
}
