//! Writing LAMMPS text dumps as `dump custom` writes them, for LAMMPS (`read_dump`), OVITO, ASE
//! and our reader (src/lammps.rs).
//!
//! Each frame is
//! ```text
//! ITEM: TIMESTEP
//! <step>
//! ITEM: NUMBER OF ATOMS
//! <n>
//! ITEM: BOX BOUNDS xy xz yz pp pp pp
//! xlo_bound xhi_bound xy
//! ylo_bound yhi_bound xz
//! zlo_bound zhi_bound yz
//! ITEM: ATOMS id type x y z [element] [vx vy vz] [radius] [ColorR ColorG ColorB] [properties]
//! <one line per atom>
//! ```
//!
//! - **Step**: [`Frame::step`], else the number of frames this writer wrote before.
//! - **Box**: LAMMPS boxes are restricted triclinic: edge a = (xhi − xlo, 0, 0) along +x,
//!   b = (xy, yhi − ylo, 0) in the xy plane, c = (xz, yz, zhi − zlo), corner (xlo, ylo, zlo)
//!   ([`UnitCell::origin`]). A cell whose a has a y or z component, or whose b has a z
//!   component (beyond 1e-10 of its longest edge), or whose diagonal is not positive, is an
//!   error ([`LammpsDumpWriter::check`]): it is not rotated into that form, which would move the
//!   atoms. Tilted cells write the bounding box of the cell as the LAMMPS manual ("Triclinic
//!   (non-orthogonal) simulation boxes") gives it: `xlo_bound = xlo + min(0, xy, xz, xy+xz)`,
//!   `xhi_bound = xhi + max(0, xy, xz, xy+xz)`, `ylo_bound = ylo + min(0, yz)`,
//!   `yhi_bound = yhi + max(0, yz)`, `zlo_bound = zlo`, `zhi_bound = zhi`, each line followed by
//!   its tilt factor (the boundary flags `pp` for a periodic edge, `ff` for another); a cell
//!   with all three tilts zero writes `ITEM: BOX BOUNDS pp pp pp` and
//!   `lo hi` lines. A frame without a cell writes the atoms' extent as a shrink-wrapped,
//!   non-periodic box, `ITEM: BOX BOUNDS ss ss ss` (as LAMMPS writes one; `0 0` for no atoms).
//! - **id**: [`Frame::ids`] as given, else 1..=n.
//! - **type**: LAMMPS types are positive integers. When every one of [`Frame::types`] is one,
//!   it is written as is. Otherwise the atoms' labels (their types, or when the frame has no
//!   types the symbols of their elements, [`crate::atom_element`], `X` when unknown) are
//!   numbered 1, 2, ... in order of first appearance, and the numbers stay the same for the
//!   whole file: a label first seen in a later frame gets the next number.
//! - **element**: the label of each atom when types were numbered from labels, the element
//!   symbols when the types are numbers; written only when it names something (a frame with
//!   named types, or whose every atom has a known element), as OVITO and LAMMPS's
//!   `dump_modify element` write it.
//! - **vx vy vz** ([`Frame::velocities`], written in the frame's Å/ps: LAMMPS `metal` units),
//!   **radius** ([`Frame::radii`]), **ColorR ColorG ColorB** ([`Frame::colors`], as OVITO writes
//!   and reads colours) when the frame has them, then every [`Frame::properties`] column under
//!   its name.
//! - **Numbers**: shortest round-trip decimal (the same f32 bits when read back; box numbers
//!   the same f64), integer-valued property columns (every value an integer below 2^24) without
//!   a decimal point, NaN as `nan`, infinities `inf` / `-inf`, as LAMMPS writes them.
//!
//! Not written: [`Frame::time`] (`ITEM: TIME` needs `ITEM: UNITS`, which `dump custom` writes
//! only on request), atom names, residues, chains, bonds.
//!
//! [`LammpsDumpWriter::check`] refuses what would not read back as written: a non-restricted
//! cell, a type label that is empty or has white space (it goes in the `element` column), a
//! property whose name is empty, has white space, is written twice, or is one of the columns
//! above or one our reader and OVITO read as another field (`diameter`, colour names such as
//! `Color.R`).

use crate::elements::Element;
use crate::frame::{Frame, Label, UnitCell};
use crate::parse::parse_i64;
use crate::style::atom_element;
use crate::writer::write_atom_tail;
use crate::xyz::check_labels;
use std::collections::HashMap;
use std::io::Write;

/// Property names the dump's own columns or the readers' column mapping take.
const RESERVED: [&str; 11] = [
    "id", "type", "element", "x", "y", "z", "vx", "vy", "vz", "radius", "diameter",
];

/// A column name OVITO and our reader take for a colour component: `Color.R`, `ColorR`, ... in
/// any letter case.
fn is_color_name(name: &str) -> bool {
    let b = name.as_bytes();
    if b.len() < 6 || !b[..5].eq_ignore_ascii_case(b"color") {
        return false;
    }
    let rest = b[5..].strip_prefix(b".").unwrap_or(&b[5..]);
    matches!(rest, [c] if b"rgb".contains(&c.to_ascii_lowercase()))
}

/// How far from zero (relative to the longest edge) the entries above the diagonal of a
/// "restricted triclinic" cell matrix may be: rounding in a cell built by rotation, not a tilt.
const FLAT: f64 = 1e-10;

/// The LAMMPS box of `cell`: `[lo_bound, hi_bound, tilt]` per line (x: xy, y: xz, z: yz), or why
/// it has none.
pub(crate) fn box_bounds(cell: &UnitCell) -> Result<[[f64; 3]; 3], String> {
    let m = cell.matrix();
    let tol = FLAT * cell.lengths().iter().fold(0.0f64, |a, b| a.max(*b));
    let restricted = m[0][1].abs() <= tol
        && m[0][2].abs() <= tol
        && m[1][2].abs() <= tol
        && m[0][0] > 0.0
        && m[1][1] > 0.0
        && m[2][2] > 0.0;
    if !restricted {
        return Err(format!(
            "the cell is not in LAMMPS's restricted triclinic form (a along x, b in the xy \
             plane): a = {:?}, b = {:?}, c = {:?}",
            m[0], m[1], m[2]
        ));
    }
    let o = cell.origin();
    let (xy, xz, yz) = (m[1][0], m[2][0], m[2][1]);
    let (xlo, ylo, zlo) = (o[0], o[1], o[2]);
    let (xhi, yhi, zhi) = (xlo + m[0][0], ylo + m[1][1], zlo + m[2][2]);
    let x_min = 0f64.min(xy).min(xz).min(xy + xz);
    let x_max = 0f64.max(xy).max(xz).max(xy + xz);
    Ok([
        [xlo + x_min, xhi + x_max, xy],
        [ylo + 0f64.min(yz), yhi + 0f64.max(yz), xz],
        [zlo, zhi, yz],
    ])
}

/// Whether a type label is a LAMMPS type number (a positive integer).
pub(crate) fn is_type_number(l: &Label) -> bool {
    parse_i64(l.as_bytes()).is_some_and(|t| t > 0)
}

/// Writes frames as a LAMMPS text dump (see the module doc).
pub(crate) struct LammpsDumpWriter<W> {
    pub out: W,
    /// Frames written so far: the timestep of a frame without one.
    frames: u64,
    /// The type number of each label numbered so far (1, 2, ... by first appearance).
    numbers: HashMap<Label, usize>,
}

impl<W: Write> LammpsDumpWriter<W> {
    pub fn new(out: W) -> Self {
        LammpsDumpWriter {
            out,
            frames: 0,
            numbers: HashMap::new(),
        }
    }

    /// Why `frame` cannot be written as a LAMMPS dump, if it cannot (see the module doc).
    pub fn check(frame: &Frame) -> Result<(), String> {
        if let Some(cell) = &frame.cell {
            box_bounds(cell)?;
        }
        check_labels(&frame.types, "type", false)?;
        for (k, p) in frame.properties.iter().enumerate() {
            let name = p.name.as_str();
            if name.is_empty() || name.chars().any(char::is_whitespace) {
                return Err(format!(
                    "property '{name}' is not a LAMMPS dump column name: it must be one word \
                     without white space"
                ));
            }
            if RESERVED.contains(&name) || is_color_name(name) {
                return Err(format!(
                    "property '{name}' has the name of a column LAMMPS dump readers give \
                     another meaning ({}, ColorR/Color.R ...)",
                    RESERVED.join(", ")
                ));
            }
            if frame.properties[..k].iter().any(|q| q.name == name) {
                return Err(format!("property '{name}' appears twice"));
            }
        }
        Ok(())
    }

    /// A LAMMPS dump has no trailer.
    pub fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }

    /// The type number of `label`, numbering it if it is new.
    fn number(&mut self, label: Label) -> usize {
        let next = self.numbers.len() + 1;
        *self.numbers.entry(label).or_insert(next)
    }

    pub fn write_frame(&mut self, frame: &Frame) -> std::io::Result<()> {
        let n = frame.n_atoms();
        let step = frame.step.unwrap_or(self.frames as i64);
        self.frames += 1;
        // Types and the element column.
        let numeric = !frame.types.is_empty() && frame.types.iter().all(is_type_number);
        let elements: Vec<Element> = if frame.types.is_empty() || numeric {
            (0..n).map(|i| atom_element(frame, i)).collect()
        } else {
            Vec::new()
        };
        let known = n > 0 && elements.len() == n && elements.iter().all(|e| !e.is_unknown());
        // Per atom: the type number when types are numbered from labels.
        let numbers: Vec<usize> = if numeric {
            Vec::new()
        } else if frame.types.is_empty() {
            let symbol = |e: &Element| Label::new(e.symbol()).unwrap_or_default();
            elements.iter().map(|e| self.number(symbol(e))).collect()
        } else {
            frame.types.iter().map(|t| self.number(*t)).collect()
        };
        let named = !frame.types.is_empty() && !numeric;
        let element_column = named || known;

        let w = &mut self.out;
        writeln!(w, "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{n}")?;
        match &frame.cell {
            Some(cell) => {
                let b = box_bounds(cell).map_err(std::io::Error::other)?;
                // Periodic edges `pp`, the others fixed `ff`.
                let [x, y, z] = cell.periodic().map(|p| if p { "pp" } else { "ff" });
                if b.iter().all(|l| l[2] == 0.0) {
                    writeln!(w, "ITEM: BOX BOUNDS {x} {y} {z}")?;
                    for l in b {
                        writeln!(w, "{} {}", l[0], l[1])?;
                    }
                } else {
                    writeln!(w, "ITEM: BOX BOUNDS xy xz yz {x} {y} {z}")?;
                    for l in b {
                        writeln!(w, "{} {} {}", l[0], l[1], l[2])?;
                    }
                }
            }
            None => {
                writeln!(w, "ITEM: BOX BOUNDS ss ss ss")?;
                for k in 0..3 {
                    let (lo, hi) = frame
                        .positions
                        .iter()
                        .map(|p| p[k])
                        .fold(None, |acc: Option<(f32, f32)>, x| match acc {
                            None => Some((x, x)),
                            Some((lo, hi)) => Some((lo.min(x), hi.max(x))),
                        })
                        .unwrap_or((0.0, 0.0));
                    writeln!(w, "{lo} {hi}")?;
                }
            }
        }
        write!(w, "ITEM: ATOMS id type x y z")?;
        if element_column {
            write!(w, " element")?;
        }
        if !frame.velocities.is_empty() {
            write!(w, " vx vy vz")?;
        }
        if !frame.radii.is_empty() {
            write!(w, " radius")?;
        }
        if !frame.colors.is_empty() {
            write!(w, " ColorR ColorG ColorB")?;
        }
        for p in &frame.properties {
            write!(w, " {}", p.name)?;
        }
        writeln!(w)?;
        for i in 0..n {
            match frame.ids.get(i) {
                Some(id) => write!(w, "{id}")?,
                None => write!(w, "{}", i + 1)?,
            }
            if numeric {
                write!(w, " {}", frame.types[i])?;
            } else {
                write!(w, " {}", numbers[i])?;
            }
            let p = frame.positions[i];
            write!(w, " {} {} {}", p[0], p[1], p[2])?;
            if element_column {
                if named {
                    write!(w, " {}", frame.types[i])?;
                } else {
                    write!(w, " {}", elements[i].symbol())?;
                }
            }
            write_atom_tail(w, frame, i)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writer_box_bounds_follow_the_lammps_manual() {
        // lx = 10, ly = 8, lz = 6, xy = 3, xz = 1, yz = -2, origin (0, 0, 0):
        // min(0, 3, 1, 4) = 0, max = 4; min(0, -2) = -2, max = 0.
        let m = [[10.0, 0.0, 0.0], [3.0, 8.0, 0.0], [1.0, -2.0, 6.0]];
        let cell = UnitCell::from_matrix(m).unwrap();
        assert_eq!(
            box_bounds(&cell).unwrap(),
            [[0.0, 14.0, 3.0], [-2.0, 8.0, 1.0], [0.0, 6.0, -2.0]]
        );
        // The same kind of box turned by 90° about z: a along y.
        let r = UnitCell::from_matrix([[0.0, 10.0, 0.0], [-8.0, 0.0, 0.0], [0.0, 0.0, 6.0]]);
        let e = box_bounds(&r.unwrap()).unwrap_err();
        assert!(e.contains("restricted triclinic"), "{e}");
    }

    #[test]
    fn writer_colour_names_are_reserved() {
        for c in ["ColorR", "color.g", "COLOR.B"] {
            assert!(is_color_name(c), "{c}");
        }
        for c in ["Color", "ColorX", "c_color[1]", "colors"] {
            assert!(!is_color_name(c), "{c}");
        }
    }
}
