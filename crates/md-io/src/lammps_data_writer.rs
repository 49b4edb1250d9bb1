//! LAMMPS data files written from a frame ([`crate::Format::LammpsData`]), for `read_data`: a
//! crystal from a CIF or POSCAR, a solvated protein from a PDB or `.tpr`, set up for a LAMMPS
//! run (what OVITO's "LAMMPS data" export, ASE's `write_lammps_data` and VMD's TopoTools do).
//!
//! # What is written
//! One frame (a data file is one configuration: a second frame is an error), as `write_data`
//! lays it out: a title line (the frame's comment, or "LAMMPS data file written by texmap"),
//! the counts, the box, `Masses`, `Atoms # STYLE`, `Velocities` and `Bonds`.
//!
//! - **Atom style**, from what the frame has: `full` (id mol type q x y z) with bonds and
//!   charges, `molecular` (id mol type x y z) with bonds only, `charge` (id type q x y z) with
//!   charges only, else `atomic` (id type x y z). Charges are the `charge` property (a PSF,
//!   prmtop, `.tpr`, PQR or data file's); the molecule id is the residue number where the frame
//!   has them, else the bonded fragment's number from 1.
//! - **Atoms** are numbered 1, 2, … in frame order; positions are written as they are (the
//!   shortest decimal that reads back as the same f32), so atoms outside a periodic box are
//!   remapped by `read_data` itself, which sets their image flags.
//! - **Atom types**: when every atom's type is a positive integer (a LAMMPS dump's), those
//!   numbers; otherwise the type labels (else element symbols, else names) numbered 1, 2, … in
//!   order of first appearance, each label written as the comment of its `Masses` line
//!   (`1 12.011 # C`, as ASE and OVITO write it, and as our reader and OVITO's take the element
//!   from it).
//! - **Masses** per type: [`crate::atom_mass`] (the file's masses, else the element's). Atoms of
//!   one type with different masses are an error (a LAMMPS type has one mass). When some type
//!   has no positive mass (an element we cannot tell, a massless virtual site) the section is
//!   left out: `read_data` accepts that, and the input script sets the masses.
//! - **Bonds** ([`Frame::bonds`]): one bond type per unordered pair of atom type labels,
//!   numbered in order of first appearance, as TopoTools assigns them; `N bond types` counts
//!   them. Angles, dihedrals and coefficients are not written (a force field's job).
//! - **Box**: LAMMPS's restricted triclinic form (a along +x, b in the xy plane): a cell in
//!   another orientation (a POSCAR's or XSF's lattice vectors) is rotated into it with its
//!   atoms, as ASE's `Prism` does; tilt factors beyond half an edge along a periodic edge are
//!   reduced to an equivalent lattice (b − k a, c − k b − l a), which LAMMPS releases before
//!   2023 require; a tilted box writes `xy xz yz`. (Cells are right-handed by construction, so
//!   the rotation never mirrors the structure.) A frame without a cell gets the atoms' bounding box grown by
//!   1 Å on each side (for `boundary f` or `s`).
//! - **Velocities**: the properties `vx vy vz` (a data file's `Velocities` as our reader gives
//!   them, in the run's units, unconverted), turned with the box when it is rotated, so a data
//!   file read and written back keeps its velocities. [`Frame::velocities`] (Å/ps, from a
//!   trajectory) are not written: a data file does not state its units, and LAMMPS's are the
//!   run's (Å/fs for `units real`, Å/ps for `metal`), so no conversion can be chosen here
//!   (`texmap convert` warns when it drops them).
//! - **Image flags**: the properties `ix iy iz` (a data file's or a dump's), when the frame has
//!   all three as whole numbers and a cell, as the Atoms lines' three last columns, so that
//!   molecules stay whole across the box's faces for `read_data`; a reduced tilt changes the
//!   lattice they count in, and they are recomputed for it (the same periodic image).
//! - **Not written**: angles, dihedrals, impropers, coefficients.
//!
//! # References
//! - LAMMPS documentation, `read_data` (header, sections, the Atoms line of each style) and
//!   "Triclinic (non-orthogonal) simulation boxes" (restricted form, tilt factors, limits).

use std::collections::HashMap;
use std::io::Write;

use crate::frame::{Frame, Label, UnitCell};
use crate::writer::Num;

/// What an atom line holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Style {
    Atomic,
    Charge,
    Molecular,
    Full,
}

impl Style {
    fn name(self) -> &'static str {
        match self {
            Style::Atomic => "atomic",
            Style::Charge => "charge",
            Style::Molecular => "molecular",
            Style::Full => "full",
        }
    }
}

/// The box `read_data` reads: `[lo, hi]` per axis and the tilts `xy xz yz`, plus the map of a
/// position into it (the rotation into the restricted form, `None` when the cell is already in
/// it).
pub(crate) struct DataBox {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub tilt: [f64; 3],
    pub rotate: Option<Rotation>,
    /// The multiples taken off by the tilt reduction: `c −= k₁·b`, then `b −= k_b·a` and
    /// `c −= k_c·a` ([`DataBox::image`]).
    reduced: [f64; 3],
}

impl DataBox {
    /// Image flags `n` in the cell's lattice as flags in the written (reduced) lattice: the same
    /// periodic image, `n_a·a + n_b·b + n_c·c`, with `b = b′ + k_b·a` and `c = c′ + k₁·b′ +
    /// (k_c + k₁·k_b)·a`. A rotation keeps fractional coordinates, and with them the flags.
    pub fn image(&self, n: [f64; 3]) -> [f64; 3] {
        let [k1, kb, kc] = self.reduced;
        [
            n[0] + kb * n[1] + (kc + k1 * kb) * n[2],
            n[1] + k1 * n[2],
            n[2],
        ]
    }
}

/// p ↦ origin + ((p − origin) · M⁻¹) · M′: the fractional coordinates in the old cell M are
/// the same in the restricted cell M′.
pub(crate) struct Rotation {
    origin: [f64; 3],
    cell: [[f64; 3]; 3],
    restricted: [[f64; 3]; 3],
}

impl Rotation {
    pub fn apply(&self, p: [f32; 3]) -> [f32; 3] {
        let d: [f64; 3] = std::array::from_fn(|k| p[k] as f64 - self.origin[k]);
        let q = self.apply_vector(d);
        std::array::from_fn(|j| (self.origin[j] + q[j]) as f32)
    }

    /// The rotation of a vector (a velocity, a displacement): `apply` without the origin.
    pub fn apply_vector(&self, v: [f64; 3]) -> [f64; 3] {
        let f = crate::pbc::to_frac(&self.cell, v);
        crate::pbc::to_cart(&self.restricted, f)
    }
}

/// The image flags `ix iy iz`, if the frame has all three as whole numbers and a cell for them
/// to count (see the module docs).
/// A type label of a frame of `n` atoms as the data file's type number, when it is one: a
/// positive integer up to 16 n (a larger one would make `read_data` reserve that many types).
fn type_number(l: &Label, n: usize) -> Option<usize> {
    l.as_str()
        .parse::<usize>()
        .ok()
        .filter(|&t| t > 0 && t <= n.max(1) * 16)
}

/// Whether the frame's types are written as they are (each a type number); otherwise they are
/// numbered 1, 2, … and a label survives only as its `Masses` line's comment.
pub(crate) fn types_are_numbers(frame: &Frame) -> bool {
    let n = frame.n_atoms();
    frame.types.iter().all(|t| type_number(t, n).is_some())
}

pub(crate) fn data_images(frame: &Frame) -> Option<[&[f32]; 3]> {
    frame.cell?;
    let flags = [
        frame.property("ix")?,
        frame.property("iy")?,
        frame.property("iz")?,
    ];
    let whole = |v: &f32| v.fract() == 0.0 && v.abs() <= 1e9;
    flags.iter().all(|f| f.iter().all(whole)).then_some(flags)
}

/// The properties `vx vy vz` (a data file's velocities, in the run's units), if the frame has
/// all three.
fn data_velocities(frame: &Frame) -> Option<[&[f32]; 3]> {
    Some([
        frame.property("vx")?,
        frame.property("vy")?,
        frame.property("vz")?,
    ])
}

/// The restricted triclinic form of `cell` with its tilts reduced along periodic edges. A
/// [`UnitCell`] is right-handed with volume by construction, so the rotation never mirrors.
pub(crate) fn data_box(cell: &UnitCell) -> DataBox {
    let m = cell.matrix();
    let longest = cell.lengths().iter().fold(0.0f64, |a, b| a.max(*b));
    let tol = 1e-10 * longest;
    let restricted = m[0][1].abs() <= tol && m[0][2].abs() <= tol && m[1][2].abs() <= tol;
    let (mut r, rotate) = if restricted {
        (m, None)
    } else {
        // a = (|a|, 0, 0); b in the xy plane with +y; c with +z.
        let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let la = dot(m[0], m[0]).sqrt();
        let bx = dot(m[1], m[0]) / la;
        let by = (dot(m[1], m[1]) - bx * bx).max(0.0).sqrt();
        let cx = dot(m[2], m[0]) / la;
        let cy = (dot(m[2], m[1]) - bx * cx) / by;
        let cz = (dot(m[2], m[2]) - cx * cx - cy * cy).max(0.0).sqrt();
        let r = [[la, 0.0, 0.0], [bx, by, 0.0], [cx, cy, cz]];
        let rotation = Rotation {
            origin: cell.origin(),
            cell: m,
            restricted: r,
        };
        (r, Some(rotation))
    };
    // Tilts beyond half an edge, along a periodic edge, become an equivalent lattice's.
    let periodic = cell.periodic();
    let reduce = |tilt: f64, edge: f64| (tilt / edge).round();
    let mut reduced = [0.0; 3];
    if periodic[1] {
        let k = reduce(r[2][1], r[1][1]);
        if r[2][1].abs() > 0.5 * r[1][1] + tol && k != 0.0 {
            r[2][0] -= k * r[1][0];
            r[2][1] -= k * r[1][1];
            reduced[0] = k;
        }
    }
    if periodic[0] {
        for row in [1, 2] {
            let k = reduce(r[row][0], r[0][0]);
            if r[row][0].abs() > 0.5 * r[0][0] + tol && k != 0.0 {
                r[row][0] -= k * r[0][0];
                reduced[row] = k;
            }
        }
    }
    let o = cell.origin();
    let (xy, xz, yz) = (r[1][0], r[2][0], r[2][1]);
    DataBox {
        lo: o,
        hi: [o[0] + r[0][0], o[1] + r[1][1], o[2] + r[2][2]],
        tilt: [xy, xz, yz],
        rotate,
        reduced,
    }
}

/// The bounding box of `positions` grown by 1 Å on each side (a frame without a cell).
pub(crate) fn bounding_box(positions: &[[f32; 3]]) -> DataBox {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] as f64);
            hi[k] = hi[k].max(p[k] as f64);
        }
    }
    if positions.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    DataBox {
        lo: lo.map(|v| v - 1.0),
        hi: hi.map(|v| v + 1.0),
        tilt: [0.0; 3],
        reduced: [0.0; 3],
        rotate: None,
    }
}

/// Writes one frame as a LAMMPS data file (see the module docs).
pub(crate) struct LammpsDataWriter<W> {
    pub out: W,
    frames: usize,
}

/// Everything a frame's data file needs, worked out before a byte is written.
struct Plan {
    style: Style,
    data_box: DataBox,
    /// Type number of each atom (1-based) and the label of each type (by number − 1; `None`
    /// for a number no atom has).
    types: Vec<usize>,
    labels: Vec<Option<Label>>,
    /// Mass of each type, when every type has a positive one.
    masses: Option<Vec<f64>>,
    charges: Option<Vec<f32>>,
    molecules: Vec<i64>,
    /// Bond type (1-based) of each bond, and the number of bond types.
    bond_types: Vec<usize>,
    n_bond_types: usize,
}

fn plan(frame: &Frame) -> Result<Plan, String> {
    let n = frame.n_atoms();
    let data_box = match &frame.cell {
        Some(cell) => data_box(cell),
        None => bounding_box(&frame.positions),
    };
    let charges = frame
        .property("charge")
        .filter(|c| c.len() == n)
        .map(|c| c.to_vec());
    if let Some(i) = charges
        .as_ref()
        .and_then(|c| c.iter().position(|q| !q.is_finite()))
    {
        return Err(format!("atom {i}'s charge is not a number"));
    }
    if let Some(v) = data_velocities(frame)
        && let Some((d, i)) =
            (0..3).find_map(|d| v[d].iter().position(|x| !x.is_finite()).map(|i| (d, i)))
    {
        return Err(format!(
            "atom {i}'s velocity {} is {}: read_data takes finite numbers",
            ["vx", "vy", "vz"][d],
            v[d][i]
        ));
    }
    let bonded = !frame.bonds.is_empty();
    let style = match (bonded, charges.is_some()) {
        (true, true) => Style::Full,
        (true, false) => Style::Molecular,
        (false, true) => Style::Charge,
        (false, false) => Style::Atomic,
    };
    // Type labels: the types, else the elements, else the names.
    let label = |i: usize| -> Label {
        if let Some(t) = frame.types.get(i) {
            *t
        } else if let Some(e) = frame.elements.get(i).filter(|e| !e.is_unknown()) {
            Label::new(e.symbol()).unwrap_or_default()
        } else if let Some(nm) = frame.names.get(i) {
            *nm
        } else {
            Label::new("1").unwrap_or_default()
        }
    };
    let numeric: Option<Vec<usize>> = (0..n).map(|i| type_number(&label(i), n)).collect();
    let (types, mut labels) = match numeric {
        Some(types) if n > 0 => {
            let count = types.iter().copied().max().unwrap_or(1);
            let mut labels = vec![None; count];
            for (i, &t) in types.iter().enumerate() {
                labels[t - 1].get_or_insert(label(i));
            }
            (types, labels)
        }
        _ => {
            let mut number: HashMap<Label, usize> = HashMap::new();
            let mut labels = Vec::new();
            let types = (0..n)
                .map(|i| {
                    let l = label(i);
                    *number.entry(l).or_insert_with(|| {
                        labels.push(Some(l));
                        labels.len()
                    })
                })
                .collect();
            (types, labels)
        }
    };
    if labels.is_empty() {
        labels.push(None);
    }
    // One mass per type.
    let mut mass: Vec<Option<(f64, usize)>> = vec![None; labels.len()];
    for (i, &t) in types.iter().enumerate() {
        let m = crate::style::atom_mass(frame, i);
        match mass[t - 1] {
            None => mass[t - 1] = Some((m, i)),
            Some((m0, i0)) => {
                if (m - m0).abs() > 1e-6 * m0.abs().max(1e-6) {
                    return Err(format!(
                        "atoms {i0} and {i} are both of type '{}' but weigh {m0} and {m} u: a LAMMPS atom type has one mass (give them different types)",
                        labels[t - 1].map_or(String::new(), |l| l.to_string())
                    ));
                }
            }
        }
    }
    let masses = mass
        .iter()
        .map(|m| m.map(|(m, _)| m).filter(|m| m.is_finite() && *m > 0.0))
        .collect::<Option<Vec<f64>>>();
    // Molecule ids: residue numbers, else bonded fragments from 1.
    let molecules = if !bonded {
        Vec::new()
    } else if frame.res_ids.len() == n {
        frame.res_ids.clone()
    } else {
        crate::select::fragments(frame)
            .into_iter()
            .map(|f| f as i64 + 1)
            .collect()
    };
    // Bond types by the unordered pair of their atoms' labels.
    let mut pair_number: HashMap<(Label, Label), usize> = HashMap::new();
    let bond_types = frame
        .bonds
        .iter()
        .map(|&[a, b]| {
            let (la, lb) = (label(a as usize), label(b as usize));
            let key = if la.as_str() <= lb.as_str() {
                (la, lb)
            } else {
                (lb, la)
            };
            let next = pair_number.len() + 1;
            *pair_number.entry(key).or_insert(next)
        })
        .collect();
    Ok(Plan {
        style,
        data_box,
        types,
        labels,
        masses,
        charges,
        molecules,
        bond_types,
        n_bond_types: pair_number.len(),
    })
}

impl<W: Write> LammpsDataWriter<W> {
    pub fn new(out: W) -> Self {
        LammpsDataWriter { out, frames: 0 }
    }

    /// Why `frame` cannot be written, if it cannot.
    pub fn check(&self, frame: &Frame) -> Result<(), String> {
        if self.frames > 0 {
            return Err(
                "a LAMMPS data file holds one configuration: choose one frame (--frames N)".into(),
            );
        }
        plan(frame).map(|_| ())
    }

    pub fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }

    pub fn write_frame(&mut self, frame: &Frame) -> std::io::Result<()> {
        let plan = plan(frame).map_err(std::io::Error::other)?;
        self.frames += 1;
        let w = &mut self.out;
        let title = frame.comment.lines().next().unwrap_or("").trim();
        if title.is_empty() {
            writeln!(w, "LAMMPS data file written by texmap")?;
        } else {
            writeln!(w, "{title}")?;
        }
        writeln!(w)?;
        writeln!(w, "{} atoms", frame.n_atoms())?;
        if !frame.bonds.is_empty() {
            writeln!(w, "{} bonds", frame.bonds.len())?;
        }
        writeln!(w, "{} atom types", plan.labels.len())?;
        if !frame.bonds.is_empty() {
            writeln!(w, "{} bond types", plan.n_bond_types)?;
        }
        writeln!(w)?;
        let b = &plan.data_box;
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            writeln!(w, "{} {} {axis}lo {axis}hi", b.lo[k], b.hi[k])?;
        }
        if b.tilt.iter().any(|&t| t != 0.0) {
            writeln!(w, "{} {} {} xy xz yz", b.tilt[0], b.tilt[1], b.tilt[2])?;
        }
        if let Some(masses) = &plan.masses {
            writeln!(w, "\nMasses\n")?;
            for (t, &m) in masses.iter().enumerate() {
                // A mass the file gave in single precision is written as that f32 (16, not
                // 15.999999046325684); an element's standard weight as its f64.
                let m = if m as f32 as f64 == m {
                    (m as f32).to_string()
                } else {
                    m.to_string()
                };
                match plan.labels[t] {
                    Some(l) => writeln!(w, "{} {m} # {l}", t + 1)?,
                    None => writeln!(w, "{} {m}", t + 1)?,
                }
            }
        }
        writeln!(w, "\nAtoms # {}\n", plan.style.name())?;
        let images = data_images(frame);
        for (i, &p) in frame.positions.iter().enumerate() {
            let p = b.rotate.as_ref().map_or(p, |r| r.apply(p));
            write!(w, "{}", i + 1)?;
            if matches!(plan.style, Style::Molecular | Style::Full) {
                write!(w, " {}", plan.molecules[i])?;
            }
            write!(w, " {}", plan.types[i])?;
            if let Some(q) = &plan.charges {
                write!(w, " {}", Num(q[i]))?;
            }
            write!(w, " {} {} {}", p[0], p[1], p[2])?;
            if let Some([ix, iy, iz]) = images {
                let n = b.image([ix[i], iy[i], iz[i]].map(f64::from));
                write!(w, " {} {} {}", n[0] as i64, n[1] as i64, n[2] as i64)?;
            }
            writeln!(w)?;
        }
        if let Some([vx, vy, vz]) = data_velocities(frame) {
            writeln!(w, "\nVelocities\n")?;
            for i in 0..frame.n_atoms() {
                let v = [vx[i], vy[i], vz[i]];
                // Turned with the box, as the positions are (an f64 rotation, rounded once).
                let v = b
                    .rotate
                    .as_ref()
                    .map_or(v, |r| r.apply_vector(v.map(f64::from)).map(|x| x as f32));
                writeln!(w, "{} {} {} {}", i + 1, v[0], v[1], v[2])?;
            }
        }
        if !frame.bonds.is_empty() {
            writeln!(w, "\nBonds\n")?;
            for (k, (&[a, b], t)) in frame.bonds.iter().zip(&plan.bond_types).enumerate() {
                writeln!(w, "{} {t} {} {}", k + 1, a + 1, b + 1)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rotated_cell_becomes_the_restricted_form_with_its_atoms() {
        // An FCC primitive cell as a POSCAR gives it, and an atom at fractional (0.25, 0.5, 0.75).
        let m = [[0.0, 1.8, 1.8], [1.8, 0.0, 1.8], [1.8, 1.8, 0.0]];
        let cell = UnitCell::from_matrix(m).unwrap();
        let b = data_box(&cell);
        let r = b.rotate.as_ref().unwrap();
        let f = [0.25, 0.5, 0.75];
        let p: [f32; 3] =
            std::array::from_fn(|j| (0..3).map(|k| f[k] * m[k][j]).sum::<f64>() as f32);
        let q = r.apply(p);
        // Lengths and angles are kept; the atom keeps its fractional coordinates.
        let lr = r.restricted;
        let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        for k in 0..3 {
            assert!((len(lr[k]) - len(m[k])).abs() < 1e-12);
        }
        let want: [f64; 3] = std::array::from_fn(|j| (0..3).map(|k| f[k] * lr[k][j]).sum());
        for j in 0..3 {
            assert!((q[j] as f64 - want[j]).abs() < 1e-5, "{q:?} {want:?}");
        }
        assert_eq!(lr[0][1], 0.0);
        assert_eq!(lr[0][2], 0.0);
        assert_eq!(lr[1][2], 0.0);
    }

    #[test]
    fn large_tilts_are_reduced_to_an_equivalent_lattice() {
        // b = (3, 2, 0) over a = (2, 0, 0): the tilt 3 > 1 becomes 3 - 2 * 2 = -1.
        let cell =
            UnitCell::from_matrix([[2.0, 0.0, 0.0], [3.0, 2.0, 0.0], [0.0, 0.0, 2.0]]).unwrap();
        let b = data_box(&cell);
        assert_eq!(b.tilt, [-1.0, 0.0, 0.0]);
    }
}
