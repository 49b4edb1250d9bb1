//! VASP structures written from frames ([`crate::Format::Vasp`]): a POSCAR (one structure, the
//! input VASP, phonopy and the structure tools start from) or, for a file named `XDATCAR*` (or
//! `*.xdatcar`), a VASP 5 XDATCAR trajectory. The reader in src/vasp.rs reads every file
//! written here back to the same atoms, in the same order; so do ASE (`ase.io.read`, formats
//! `vasp` and `vasp-xdatcar`) and pymatgen (`Poscar`, `Xdatcar`), which tests/vasp_writer.rs
//! checks. The layout is the one VASP itself writes, which phonopy and OVITO read.
//!
//! # What is written
//! VASP 5 layout, one header per structure:
//! 1. the comment: the frame's comment (its first line, trimmed), else the formula in Hill
//!    order (`C2 H6 O`). A comment that is blank or holds the word `configuration` (which
//!    XDATCAR readers, ours and ASE's, take for a configuration line) is replaced by the
//!    formula;
//! 2. the scaling factor `1.0`;
//! 3. the lattice vectors, one per line: the frame's cell (the rows of
//!    [`crate::UnitCell::matrix`], Å);
//! 4. the species names (element symbols) and the number of atoms of each, in two lines;
//! 5. `Direct` (in an XDATCAR `Direct configuration=     N`, N counting frames from 1 as VASP
//!    does), then one line per atom: its fractional coordinates.
//!
//! Numbers are Rust's shortest round-trip decimals of f64 values: the cell as it is, the
//! fractions of the f32 positions, so a reader gets back the cell exactly and every position
//! to f64 round-off: our reader the same f32 (a coordinate at or next to zero may come back
//! within 1e-12 Å of it), ASE and pymatgen within 1e-9 Å.
//!
//! - **Positions are not wrapped** into the cell (ASE's `write_vasp` does not either): an atom
//!   outside the cell gets a fraction below 0 or from 1 on, which VASP accepts, and reading
//!   the file back gives the frame's positions, not images of them. Fractions are of the
//!   positions as they are: the cell's origin ([`crate::UnitCell::origin`], a LAMMPS box's
//!   `lo`) has no place in a POSCAR and is not written. Wrapping ([`crate::pbc::wrap`]) is the
//!   user's choice.
//! - **Atom order is the frame's.** VASP lists atoms by species, one count per species name;
//!   each run of consecutive atoms of one element becomes a group of its own, as ASE's
//!   `write_vasp` does without `sort=True`: a water box `O H H O H H` is written `O H O H` /
//!   `1 2 1 2`. So an XDATCAR's atoms stay aligned with the trajectory it came from and a
//!   round trip keeps every index. A VASP run wants few groups (one POTCAR entry each):
//!   selecting and ordering the atoms by species before writing is the user's choice.
//! - **Species names are element symbols**: the frame's elements, else those the names tell
//!   ([`crate::atom_element`]). A POTCAR label read from a POSCAR (`Fe_pv`) is written as its
//!   element (`Fe`); the POTCAR chooses the potential.
//! - **Velocities** (POSCAR only, when the frame has them): after the coordinates, a blank line
//!   and one line per atom in Cartesian Å/fs, as VASP writes a CONTCAR; ASE, pymatgen and our
//!   reader read them back (Å/ps in a [`Frame`]). An XDATCAR has no velocities.
//! - **XDATCAR**: one header, then each frame's configuration. When a frame's cell differs from
//!   the cell of the last header (an NPT run), the header is written again before it and before
//!   every later frame, as VASP writes a run whose cell changes, always with the first frame's
//!   comment (pymatgen finds a new header by that line).
//! - **Not written**: ids, names, types other than the element, residues, bonds, properties,
//!   time and step, selective-dynamics flags, the cell's open edges (VASP is periodic along all
//!   three: a slab or a molecule is modelled with vacuum in its cell).
//!
//! # Refused
//! An [`crate::Error::InvalidFrame`] naming the file and the frame, before any byte of that
//! frame is written:
//! - a frame without a cell (VASP needs the three lattice vectors) or without atoms;
//! - an atom whose element is not known (the species line names elements: ASE and pymatgen
//!   refuse any other label, and VASP matches them with the POTCAR), naming the atom;
//! - a second frame in a POSCAR (a POSCAR holds one structure: a trajectory goes to a file
//!   named `XDATCAR`);
//! - in an XDATCAR, a frame with another atom count, or other elements in another order, than
//!   the first (the species are listed once, for every frame).
//!
//! A left-handed lattice, which VASP refuses, cannot reach the writer: a [`crate::UnitCell`]
//! is right-handed by construction (and our reader refuses a left-handed POSCAR).
//!
//! # References
//! - VASP wiki, "POSCAR" and "XDATCAR" (layout, Direct coordinates, velocities in Å/fs).
//! - ASE `ase.io.vasp` (`write_vasp`, `write_vasp_xdatcar`: runs of one species as groups),
//!   pymatgen `pymatgen.io.vasp` (`Poscar`, `Xdatcar`): how the readers users trust read them.

use std::io::{self, Write};

use crate::elements::Element;
use crate::frame::Frame;
use crate::pbc::to_frac;
use crate::style::atom_element;

/// Å/ps (a frame's velocities) → Å/fs (VASP's).
const PS_PER_FS: f64 = 1000.0;

/// A number as written: `-0` becomes `0` (every other value is unchanged).
fn z(x: f64) -> f64 {
    x + 0.0
}

/// What a frame's atoms are, as the header lists them.
struct Plan {
    lattice: [[f64; 3]; 3],
    /// Each atom's element.
    elements: Vec<Element>,
}

/// The atom as an error names it: index, then its name and type where it has them.
fn describe(frame: &Frame, i: usize) -> String {
    let mut s = format!("atom {i}");
    let name = frame.names.get(i).filter(|l| !l.is_empty());
    let ty = frame.types.get(i).filter(|l| !l.is_empty());
    match (name, ty) {
        (Some(n), Some(t)) => s.push_str(&format!(" (name '{n}', type '{t}')")),
        (Some(n), None) => s.push_str(&format!(" (name '{n}')")),
        (None, Some(t)) => s.push_str(&format!(" (type '{t}')")),
        (None, None) => s.push_str(" (no name or type)"),
    }
    s
}

fn plan(frame: &Frame) -> Result<Plan, String> {
    let n = frame.n_atoms();
    let cell = frame.cell.as_ref().ok_or_else(|| {
        "the frame has no cell: a VASP file needs three lattice vectors (read the atoms from a \
         file that has a box or lattice)"
            .to_string()
    })?;
    if n == 0 {
        return Err("the frame has no atoms: a VASP file lists at least one".into());
    }
    let mut elements = Vec::with_capacity(n);
    for i in 0..n {
        let e = atom_element(frame, i);
        if e.is_unknown() {
            return Err(format!(
                "{} has no element: a VASP species line names elements (VASP matches them with \
                 the POTCAR; ASE and pymatgen read nothing else); give the atoms elements (an \
                 element column, element names, or a topology)",
                describe(frame, i)
            ));
        }
        elements.push(e);
    }
    Ok(Plan {
        lattice: cell.matrix(),
        elements,
    })
}

/// The species groups: each run of consecutive atoms of one element, with its length.
fn runs(elements: &[Element]) -> Vec<(Element, usize)> {
    let mut out: Vec<(Element, usize)> = Vec::new();
    for &e in elements {
        match out.last_mut() {
            Some((last, count)) if *last == e => *count += 1,
            _ => out.push((e, 1)),
        }
    }
    out
}

/// The formula in Hill order (carbon, hydrogen, then alphabetical; alphabetical without
/// carbon), a count after each symbol but 1: `C2 H6 O`.
fn formula(elements: &[Element]) -> String {
    let mut counts: Vec<(Element, usize)> = Vec::new();
    for &e in elements {
        match counts.iter_mut().find(|(x, _)| *x == e) {
            Some((_, c)) => *c += 1,
            None => counts.push((e, 1)),
        }
    }
    let carbon = counts.iter().any(|(e, _)| e.symbol() == "C");
    let rank = |e: &Element| match e.symbol() {
        "C" if carbon => 0,
        "H" if carbon => 1,
        _ => 2,
    };
    counts.sort_by(|a, b| {
        rank(&a.0)
            .cmp(&rank(&b.0))
            .then_with(|| a.0.symbol().cmp(b.0.symbol()))
    });
    let parts: Vec<String> = counts
        .iter()
        .map(|(e, c)| {
            if *c == 1 {
                e.symbol().to_string()
            } else {
                format!("{}{c}", e.symbol())
            }
        })
        .collect();
    parts.join(" ")
}

/// The comment line: the frame's (first line, trimmed) unless it is blank or would be read as
/// a configuration line, else the formula.
fn comment(frame: &Frame, elements: &[Element]) -> String {
    let line = frame.comment.lines().next().unwrap_or("").trim();
    let configuration = line.to_ascii_lowercase().contains("configuration");
    if line.is_empty() || configuration {
        formula(elements)
    } else {
        line.to_string()
    }
}

/// Writes a header: comment, scale, lattice, species names and counts (each column as wide as
/// its longer entry, right-aligned).
fn write_header(
    w: &mut impl Write,
    comment: &str,
    lattice: &[[f64; 3]; 3],
    groups: &[(Element, usize)],
) -> io::Result<()> {
    writeln!(w, "{comment}")?;
    writeln!(w, "1.0")?;
    for row in lattice {
        writeln!(w, "  {} {} {}", z(row[0]), z(row[1]), z(row[2]))?;
    }
    let counts: Vec<String> = groups.iter().map(|(_, c)| c.to_string()).collect();
    let width = |k: usize| groups[k].0.symbol().len().max(counts[k].len());
    write!(w, " ")?;
    for (k, (e, _)) in groups.iter().enumerate() {
        write!(w, " {:>1$}", e.symbol(), width(k))?;
    }
    write!(w, "\n ")?;
    for (k, c) in counts.iter().enumerate() {
        write!(w, " {:>1$}", c, width(k))?;
    }
    writeln!(w)
}

/// Writes each atom's fractional coordinates.
fn write_coordinates(
    w: &mut impl Write,
    lattice: &[[f64; 3]; 3],
    positions: &[[f32; 3]],
) -> io::Result<()> {
    for p in positions {
        let f = to_frac(lattice, p.map(f64::from));
        writeln!(w, "  {} {} {}", z(f[0]), z(f[1]), z(f[2]))?;
    }
    Ok(())
}

/// What an XDATCAR keeps of its first frame.
struct First {
    elements: Vec<Element>,
    groups: Vec<(Element, usize)>,
    comment: String,
    /// The cell of the last header written.
    header_cell: [[f64; 3]; 3],
    /// True once the cell has changed: every later frame gets a header.
    variable: bool,
}

/// Writes frames as a POSCAR or an XDATCAR (see the module docs).
pub(crate) struct VaspWriter<W> {
    pub out: W,
    xdatcar: bool,
    frames: usize,
    first: Option<First>,
}

impl<W> VaspWriter<W> {
    /// Whether `frame`'s comment line reads back from this file when written next: each POSCAR
    /// and an XDATCAR's first frame write their own; an XDATCAR's later frames repeat the
    /// first's.
    pub(crate) fn keeps_comment(&self, frame: &Frame) -> bool {
        match &self.first {
            Some(first) if self.xdatcar => comment(frame, &first.elements) == first.comment,
            _ => true,
        }
    }
}

/// True when a file named `name` (a path) is an XDATCAR: its file name starts with `XDATCAR`
/// or ends with `.xdatcar`, in any case.
pub(crate) fn is_xdatcar(name: &str) -> bool {
    let file = std::path::Path::new(name)
        .file_name()
        .map(|f| f.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    file.starts_with("xdatcar") || file.ends_with(".xdatcar")
}

impl<W: Write> VaspWriter<W> {
    /// A POSCAR writer, or an XDATCAR writer when `xdatcar`.
    pub fn new(out: W, xdatcar: bool) -> Self {
        VaspWriter {
            out,
            xdatcar,
            frames: 0,
            first: None,
        }
    }

    /// Why `frame` cannot be written, if it cannot.
    pub fn check(&self, frame: &Frame) -> Result<(), String> {
        self.plan(frame).map(|_| ())
    }

    /// The frame's plan, or why it cannot be written (see the module docs).
    fn plan(&self, frame: &Frame) -> Result<Plan, String> {
        if !self.xdatcar && self.frames > 0 {
            return Err(
                "a POSCAR holds one structure: write a trajectory to a file named XDATCAR (VASP's \
                 MD trajectory), or choose one frame"
                    .into(),
            );
        }
        let plan = plan(frame)?;
        let Some(first) = &self.first else {
            return Ok(plan);
        };
        let (n0, n) = (first.elements.len(), plan.elements.len());
        if n != n0 {
            return Err(format!(
                "the frame has {n} atoms, the XDATCAR's first frame {n0}: an XDATCAR lists its \
                 species and counts once, for every frame (write .xyz or .lammpstrj, whose \
                 frames may differ)"
            ));
        }
        if let Some(i) = (0..n).find(|&i| plan.elements[i] != first.elements[i]) {
            return Err(format!(
                "{} is {}, but atom {i} of the XDATCAR's first frame is {}: an XDATCAR lists \
                 its species once, so every frame holds the same elements in the same order",
                describe(frame, i),
                plan.elements[i].symbol(),
                first.elements[i].symbol()
            ));
        }
        Ok(plan)
    }

    pub fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }

    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        let plan = self.plan(frame).map_err(io::Error::other)?;
        self.frames += 1;
        let w = &mut self.out;
        if !self.xdatcar {
            let groups = runs(&plan.elements);
            write_header(w, &comment(frame, &plan.elements), &plan.lattice, &groups)?;
            writeln!(w, "Direct")?;
            write_coordinates(w, &plan.lattice, &frame.positions)?;
            if !frame.velocities.is_empty() {
                writeln!(w)?;
                for v in &frame.velocities {
                    let v = v.map(|x| z(f64::from(x) / PS_PER_FS));
                    writeln!(w, "  {} {} {}", v[0], v[1], v[2])?;
                }
            }
            return Ok(());
        }
        match &mut self.first {
            None => {
                let first = First {
                    groups: runs(&plan.elements),
                    comment: comment(frame, &plan.elements),
                    header_cell: plan.lattice,
                    variable: false,
                    elements: plan.elements,
                };
                write_header(w, &first.comment, &first.header_cell, &first.groups)?;
                self.first = Some(first);
            }
            Some(first) => {
                if first.variable || plan.lattice != first.header_cell {
                    first.variable = true;
                    first.header_cell = plan.lattice;
                    write_header(w, &first.comment, &plan.lattice, &first.groups)?;
                }
            }
        }
        writeln!(w, "Direct configuration= {:5}", self.frames)?;
        write_coordinates(w, &plan.lattice, &frame.positions)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Label, UnitCell};

    fn el(s: &str) -> Element {
        Element::from_symbol(s).unwrap()
    }

    #[test]
    fn runs_keep_the_atom_order() {
        let e: Vec<Element> = ["O", "H", "H", "O", "H", "H", "Na"]
            .iter()
            .map(|s| el(s))
            .collect();
        let r = runs(&e);
        let names: Vec<(&str, usize)> = r.iter().map(|(e, c)| (e.symbol(), *c)).collect();
        assert_eq!(names, [("O", 1), ("H", 2), ("O", 1), ("H", 2), ("Na", 1)]);
    }

    #[test]
    fn formula_is_in_hill_order() {
        let e: Vec<Element> = ["O", "H", "C", "H", "C", "H", "H", "H", "H"]
            .iter()
            .map(|s| el(s))
            .collect();
        assert_eq!(formula(&e), "C2 H6 O");
        let e: Vec<Element> = ["O", "Fe", "Li", "O"].iter().map(|s| el(s)).collect();
        assert_eq!(formula(&e), "Fe Li O2");
    }

    #[test]
    fn a_comment_that_reads_as_a_configuration_line_becomes_the_formula() {
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]];
        f.elements = vec![el("Si")];
        f.comment = "Direct configuration=     3\nsecond line".into();
        assert_eq!(comment(&f, &f.elements), "Si");
        f.comment = "  relaxed Si  \nmore".into();
        assert_eq!(comment(&f, &f.elements), "relaxed Si");
        f.comment = "   ".into();
        assert_eq!(comment(&f, &f.elements), "Si");
    }

    #[test]
    fn xdatcar_names() {
        assert!(is_xdatcar("XDATCAR"));
        assert!(is_xdatcar("out/xdatcar_npt"));
        assert!(is_xdatcar("run.XDATCAR"));
        assert!(!is_xdatcar("POSCAR"));
        assert!(!is_xdatcar("XDATCAR/POSCAR"));
        assert!(!is_xdatcar("si.vasp"));
    }

    #[test]
    fn header_columns_line_up() {
        let mut out = Vec::new();
        let groups = [(el("O"), 1), (el("H"), 12), (el("Na"), 1)];
        let m = [[3.0, 0.0, -0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 3.0]];
        write_header(&mut out, "x", &m, &groups).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(
            text,
            "x\n1.0\n  3 0 0\n  0 3 0\n  0 0 3\n  O  H Na\n  1 12  1\n"
        );
    }

    #[test]
    fn an_unknown_element_is_named() {
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 2];
        f.cell = Some(UnitCell::orthorhombic(5.0, 5.0, 5.0).unwrap());
        f.names = vec![Label::new("Si").unwrap(), Label::new("Q9").unwrap()];
        let e = plan(&f).err().unwrap();
        assert!(e.starts_with("atom 1 (name 'Q9') has no element"), "{e}");
    }
}
