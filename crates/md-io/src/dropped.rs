//! What a written file does not keep of a frame: [`Writer::dropped`](crate::Writer::dropped)
//! names each kind of data a frame carries that its output has no place for, so that a
//! converter can say so instead of losing it in silence.
//!
//! # What each output keeps
//! One table, [`keeps`], read from the writers' code (src/xyz.rs, src/lammps_dump_writer.rs,
//! src/lammps_data_writer.rs, src/gro.rs, src/pdb.rs, src/mmcif_writer.rs, src/dcd.rs,
//! src/xtc.rs, src/trr_writer.rs, src/netcdf_writer.rs, src/gsd_writer.rs, src/vasp_writer.rs,
//! src/sdf_writer.rs), with the cases that depend on the values in [`dropped`]:
//!
//! | kind | kept by |
//! |---|---|
//! | velocities ([`Frame::velocities`]) | .xyz, .lammpstrj, .gro, .trr, .nc, .gsd, POSCAR (a LAMMPS data file writes the properties `vx vy vz` as its `Velocities`, never Å/ps) |
//! | forces (the properties `fx fy fz`, all three) | .xyz, .lammpstrj, .trr |
//! | image flags (the properties `ix iy iz`, all three) | .xyz, .lammpstrj, .gsd; .data when they are whole numbers and the frame has a cell |
//! | any other property | .xyz, .lammpstrj; `occupancy`, `bfactor` also .pdb, .cif; `charge` also .data, .gsd and, when every value is an integer in -15..=15 (formal charges), .sdf; `mass` also .gsd and .data (when every value is positive: its `Masses`); `vx vy vz` also .data; `body` and `quatw quati quatj quatk` also .gsd |
//! | partial charges (`charge` values an SD file cannot hold as formal charges) | as `charge` above, but not .sdf |
//! | bonds | .data, .pdb (CONECT), .gsd, .sdf |
//! | bond orders | .sdf; .pdb when every order is 1, 2 or 3 (CONECT repeats a double or triple bond, as Open Babel reads it; our PDB reader reads the bonds only) |
//! | the cell | every output but .sdf; a .cif holds the first frame's only |
//! | atom names | .xyz, .gro, .pdb, .cif |
//! | atom types | .xyz, .gsd; .lammpstrj and .data when every type is a number (labels are numbered 1, 2, …, the dump's element column or the data file's `Masses` comments keeping the label) |
//! | residues (names and numbers) | .gro, .pdb, .cif |
//! | chains | .pdb, .cif |
//! | segments | .pdb when each has at most 4 characters |
//! | radii | .xyz, .lammpstrj, .gsd (diameters) |
//! | colours | .xyz, .lammpstrj |
//! | time | .xyz, .gro, .xtc, .trr, .nc, .sdf (a data item); .dcd when the times are proportional to the steps (readers compute step × the header's time step) |
//! | step | .xyz, .lammpstrj, .gro, .xtc, .trr, .gsd, .sdf (a data item); .dcd when the steps are evenly spaced from a first step of at least 0 |
//! | the comment's `KEY=value` pairs that are no field (ASE's `energy=`, `stress=`, `info`; what our pw.x and ASE trajectory readers put there) | .xyz (after its own keys); as the title line: .gro, .sdf (the name line), .data, POSCAR, and XDATCAR while the frames' lines equal the first's |
//!
//! Bond orders are named only when the bonds themselves are kept (without bonds there is
//! nothing to order). tests/writers.rs checks the table against the files: a frame carrying
//! every kind is written to each output and read back, and what did not come back must be
//! exactly what [`dropped`] names.
//!
//! # Not reported
//! Precision (PDB's 3 decimals, XTC's 0.001 nm, GRO's fixed columns), atom ids (renumbered
//! 1, 2, ... by .data, .sdf and the outputs without ids), elements (written by most outputs as
//! symbols, in .xyz and .gro as the names, from which readers guess them), the title line (but
//! for its `KEY=value` pairs), and
//! the cell's origin and open edges.

use crate::format::Format;
use crate::frame::Frame;

/// One kind of data a frame carries that an output does not keep
/// ([`crate::Writer::dropped`]).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum Dropped {
    /// [`Frame::velocities`].
    Velocities,
    /// The properties `fx fy fz` (all three).
    Forces,
    /// The properties `ix iy iz` (all three): periodic image flags.
    ImageFlags,
    /// A named per-atom property ([`crate::Property`]) other than the above.
    Property(String),
    /// The `charge` property when its values are not the integer formal charges an SD file
    /// holds (MOL2, PQR, PDBQT or a force field's partial charges).
    PartialCharges,
    /// [`Frame::bonds`].
    Bonds,
    /// [`Frame::bond_orders`] of bonds that are written.
    BondOrders,
    /// [`Frame::cell`].
    Cell,
    /// [`Frame::names`].
    Names,
    /// [`Frame::types`].
    Types,
    /// [`Frame::res_names`] and [`Frame::res_ids`].
    Residues,
    /// [`Frame::chains`].
    Chains,
    /// [`Frame::segments`].
    Segments,
    /// [`Frame::radii`].
    Radii,
    /// [`Frame::colors`].
    Colors,
    /// [`Frame::time`].
    Time,
    /// [`Frame::step`].
    Step,
    /// The `KEY=value` pairs of [`Frame::comment`] that are no field of the frame (an energy, a
    /// stress, ASE's `info`: [`Frame::comment_pairs`] but for the cell, columns, time and step).
    CommentValues,
}

/// What a [`Dropped`] kind is counted in: atoms, bonds or frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Per {
    /// Per-atom data: counted in the atoms of a frame.
    Atom,
    /// Bonds and their orders: counted in bonds.
    Bond,
    /// Per-frame data (the cell, time, step): counted in frames.
    Frame,
}

/// The outputs as they differ in what they keep: the writable formats, with VASP's POSCAR and
/// XDATCAR apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Output {
    Xyz,
    LammpsDump,
    LammpsData,
    Gro,
    Pdb,
    Mmcif,
    Dcd,
    Xtc,
    Trr,
    Netcdf,
    Gsd,
    Poscar,
    Xdatcar,
    Sdf,
}

impl Output {
    const ALL: [Output; 14] = [
        Output::Xyz,
        Output::LammpsDump,
        Output::LammpsData,
        Output::Gro,
        Output::Pdb,
        Output::Mmcif,
        Output::Dcd,
        Output::Xtc,
        Output::Trr,
        Output::Netcdf,
        Output::Gsd,
        Output::Poscar,
        Output::Xdatcar,
        Output::Sdf,
    ];

    /// The output of `format` (`xdatcar`: a VASP file named as an XDATCAR), if it has a writer.
    pub fn of(format: Format, xdatcar: bool) -> Option<Output> {
        Some(match format {
            Format::Xyz => Output::Xyz,
            Format::LammpsDump => Output::LammpsDump,
            Format::LammpsData => Output::LammpsData,
            Format::Gro => Output::Gro,
            Format::Pdb => Output::Pdb,
            Format::Mmcif => Output::Mmcif,
            Format::Dcd => Output::Dcd,
            Format::Xtc => Output::Xtc,
            Format::Trr => Output::Trr,
            Format::Netcdf => Output::Netcdf,
            Format::Gsd => Output::Gsd,
            Format::Vasp if xdatcar => Output::Xdatcar,
            Format::Vasp => Output::Poscar,
            Format::Sdf => Output::Sdf,
            _ => return None,
        })
    }

    /// The file name users know the output by.
    pub fn name(self) -> &'static str {
        match self {
            Output::Xyz => ".xyz",
            Output::LammpsDump => ".lammpstrj",
            Output::LammpsData => ".data",
            Output::Gro => ".gro",
            Output::Pdb => ".pdb",
            Output::Mmcif => ".cif",
            Output::Dcd => ".dcd",
            Output::Xtc => ".xtc",
            Output::Trr => ".trr",
            Output::Netcdf => ".nc",
            Output::Gsd => ".gsd",
            Output::Poscar => "POSCAR",
            Output::Xdatcar => "XDATCAR",
            Output::Sdf => ".sdf",
        }
    }

    /// The output as the subject of a sentence: "a .gro file", "a LAMMPS data file".
    fn subject(self) -> &'static str {
        match self {
            Output::Xyz => "an extended XYZ file",
            Output::LammpsDump => "a LAMMPS dump",
            Output::LammpsData => "a LAMMPS data file",
            Output::Gro => "a .gro file",
            Output::Pdb => "a PDB file",
            Output::Mmcif => "a PDBx/mmCIF file",
            Output::Dcd => "a DCD file",
            Output::Xtc => "an XTC file",
            Output::Trr => "a TRR file",
            Output::Netcdf => "an AMBER NetCDF file",
            Output::Gsd => "a GSD file",
            Output::Poscar => "a POSCAR",
            Output::Xdatcar => "an XDATCAR",
            Output::Sdf => "an SD file",
        }
    }
}

/// Whether `output` keeps `kind` as far as the kind alone tells it (the cases that depend on
/// the frame's values are [`dropped`]'s).
pub(crate) fn keeps(output: Output, kind: &Dropped) -> bool {
    use Output::*;
    match kind {
        Dropped::Velocities => {
            matches!(output, Xyz | LammpsDump | Gro | Trr | Netcdf | Gsd | Poscar)
        }
        Dropped::Forces => matches!(output, Xyz | LammpsDump | Trr),
        Dropped::ImageFlags => matches!(output, Xyz | LammpsDump | LammpsData | Gsd),
        Dropped::Property(name) => keeps_property(output, name),
        Dropped::PartialCharges => matches!(output, Xyz | LammpsDump | LammpsData | Gsd),
        Dropped::Bonds => matches!(output, LammpsData | Pdb | Gsd | Sdf),
        Dropped::BondOrders => matches!(output, Sdf),
        Dropped::Cell => !matches!(output, Sdf),
        Dropped::Names => matches!(output, Xyz | Gro | Pdb | Mmcif),
        Dropped::Types => matches!(output, Xyz | LammpsDump | LammpsData | Gsd),
        Dropped::Residues => matches!(output, Gro | Pdb | Mmcif),
        Dropped::Chains => matches!(output, Pdb | Mmcif),
        Dropped::Segments => matches!(output, Pdb),
        Dropped::Radii => matches!(output, Xyz | LammpsDump | Gsd),
        Dropped::Colors => matches!(output, Xyz | LammpsDump),
        Dropped::Time => matches!(output, Xyz | Gro | Dcd | Xtc | Trr | Netcdf | Sdf),
        Dropped::Step => matches!(output, Xyz | LammpsDump | Gro | Dcd | Xtc | Trr | Gsd | Sdf),
        // The title lines: .gro's and .sdf's per frame, a data file's and a POSCAR's one frame,
        // an XDATCAR's first.
        Dropped::CommentValues => matches!(output, Xyz | LammpsData | Gro | Poscar | Xdatcar | Sdf),
    }
}

/// Whether `output` writes the property `name` (one not taken as forces or image flags).
fn keeps_property(output: Output, name: &str) -> bool {
    use Output::*;
    match output {
        Xyz | LammpsDump => true,
        Pdb | Mmcif => matches!(name, "occupancy" | "bfactor"),
        LammpsData => matches!(name, "charge" | "mass" | "vx" | "vy" | "vz"),
        Gsd => matches!(
            name,
            "charge" | "mass" | "body" | "quatw" | "quati" | "quatj" | "quatk"
        ),
        Sdf => name == "charge",
        _ => false,
    }
}

/// The properties an output takes as one vector, only when all of them are there: a LAMMPS
/// data file's `Velocities`, a GSD file's orientations.
const GROUPS: [(Output, &[&str]); 2] = [
    (Output::LammpsData, &["vx", "vy", "vz"]),
    (Output::Gsd, &["quatw", "quati", "quatj", "quatk"]),
];

/// The group of properties `output` takes `name` in, if it takes it only in one.
fn group(output: Output, name: &str) -> Option<&'static [&'static str]> {
    GROUPS
        .iter()
        .find(|(o, g)| *o == output && g.contains(&name))
        .map(|(_, g)| *g)
}

/// What the writer's state adds to the table: for a .cif after its first frame, that frame's
/// cell (the only one the file holds); for a DCD, whether it gives the frame's step and time
/// back; for an XDATCAR, whether the frame's comment is the first's.
#[derive(Default)]
pub(crate) struct State<'a> {
    pub first_cell: Option<Option<&'a crate::UnitCell>>,
    pub step_kept: Option<bool>,
    pub time_kept: Option<bool>,
    pub comment_kept: Option<bool>,
}

/// What of `frame` writing it to `output` loses, with the writer's `state`: the kinds the
/// frame carries and the output does not keep, in the order of [`Dropped`]'s variants except
/// that the properties (partial charges among them) come in the frame's order.
pub(crate) fn dropped(output: Output, frame: &Frame, state: State) -> Vec<Dropped> {
    let table = |kind: &Dropped| keeps(output, kind);
    let all = |names: &[&str]| names.iter().all(|n| frame.property(n).is_some());
    let some = |labels: &[crate::Label]| labels.iter().any(|l| !l.is_empty());
    let forces = all(&["fx", "fy", "fz"]);
    let images = all(&["ix", "iy", "iz"]);
    // Each kind: whether the frame carries it, and whether the output keeps it (for these
    // values, after the frames written before).
    let mut kinds: Vec<(Dropped, bool, bool)> = vec![
        (
            Dropped::Velocities,
            !frame.velocities.is_empty(),
            table(&Dropped::Velocities),
        ),
        (Dropped::Forces, forces, table(&Dropped::Forces)),
        (
            Dropped::ImageFlags,
            images,
            table(&Dropped::ImageFlags)
                && (output != Output::LammpsData
                    || crate::lammps_data_writer::data_images(frame).is_some()),
        ),
    ];
    for p in &frame.properties {
        let name = p.name.as_str();
        if (forces && matches!(name, "fx" | "fy" | "fz"))
            || (images && matches!(name, "ix" | "iy" | "iz"))
        {
            continue;
        }
        let kept = keeps_property(output, name)
            // A vector the output takes only whole: a part without the rest is not written.
            && group(output, name).is_none_or(&all)
            && match (output, name) {
                (Output::Sdf, "charge") => formal_charges(&p.values),
                (Output::LammpsData, "mass") => p.values.iter().all(|m| m.is_finite() && *m > 0.0),
                _ => true,
            };
        let kind = if output == Output::Sdf && name == "charge" {
            Dropped::PartialCharges
        } else {
            Dropped::Property(name.to_string())
        };
        kinds.push((kind, true, kept));
    }
    let bonded = !frame.bonds.is_empty();
    let pdb_orders = output == Output::Pdb && frame.bond_orders.iter().all(|o| matches!(o, 1..=3));
    let long_segment = frame
        .segments
        .iter()
        .any(|s| s.as_str().chars().count() > 4);
    kinds.extend([
        (Dropped::Bonds, bonded, table(&Dropped::Bonds)),
        // Orders only of bonds that are written: without bonds there is nothing to order.
        (
            Dropped::BondOrders,
            bonded && !frame.bond_orders.is_empty() && table(&Dropped::Bonds),
            table(&Dropped::BondOrders) || pdb_orders,
        ),
        (
            Dropped::Cell,
            frame.cell.is_some(),
            table(&Dropped::Cell) && state.first_cell.is_none_or(|c| c == frame.cell.as_ref()),
        ),
        (Dropped::Names, some(&frame.names), table(&Dropped::Names)),
        (
            Dropped::Types,
            some(&frame.types),
            table(&Dropped::Types)
                && match output {
                    Output::LammpsDump => frame
                        .types
                        .iter()
                        .all(crate::lammps_dump_writer::is_type_number),
                    Output::LammpsData => crate::lammps_data_writer::types_are_numbers(frame),
                    _ => true,
                },
        ),
        (
            Dropped::Residues,
            some(&frame.res_names) || !frame.res_ids.is_empty(),
            table(&Dropped::Residues),
        ),
        (
            Dropped::Chains,
            some(&frame.chains),
            table(&Dropped::Chains),
        ),
        (
            Dropped::Segments,
            some(&frame.segments),
            table(&Dropped::Segments) && !long_segment,
        ),
        (
            Dropped::Radii,
            !frame.radii.is_empty(),
            table(&Dropped::Radii),
        ),
        (
            Dropped::Colors,
            !frame.colors.is_empty(),
            table(&Dropped::Colors),
        ),
        (
            Dropped::Time,
            frame.time.is_some(),
            table(&Dropped::Time) && state.time_kept != Some(false),
        ),
        (
            Dropped::Step,
            frame.step.is_some(),
            table(&Dropped::Step) && state.step_kept != Some(false),
        ),
        (
            Dropped::CommentValues,
            crate::xyz::carried_pairs(frame).next().is_some(),
            table(&Dropped::CommentValues) && state.comment_kept != Some(false),
        ),
    ]);
    kinds
        .into_iter()
        .filter(|(_, carried, kept)| *carried && !*kept)
        .map(|(kind, _, _)| kind)
        .collect()
}

/// Whether `charge` values are formal charges an SD file writes: integers in -15..=15.
fn formal_charges(values: &[f32]) -> bool {
    values
        .iter()
        .all(|v| v.fract() == 0.0 && (-15.0..=15.0).contains(v))
}

impl Dropped {
    /// The kind as a noun phrase: "the velocities", "the per-atom property 'grain'".
    pub fn what(&self) -> String {
        match self {
            Dropped::Velocities => "the velocities".into(),
            Dropped::Forces => "the forces (fx fy fz)".into(),
            Dropped::ImageFlags => "the image flags (ix iy iz)".into(),
            Dropped::Property(name) => format!("the per-atom property '{name}'"),
            Dropped::PartialCharges => "the partial charges ('charge')".into(),
            Dropped::Bonds => "the bonds".into(),
            Dropped::BondOrders => "the bond orders".into(),
            Dropped::Cell => "the periodic cell".into(),
            Dropped::Names => "the atom names".into(),
            Dropped::Types => "the atom types".into(),
            Dropped::Residues => "the residues (names and numbers)".into(),
            Dropped::Chains => "the chains".into(),
            Dropped::Segments => "the segment names".into(),
            Dropped::Radii => "the radii".into(),
            Dropped::Colors => "the colours".into(),
            Dropped::Time => "the time".into(),
            Dropped::Step => "the step numbers".into(),
            Dropped::CommentValues => {
                "the comment line's KEY=value pairs (an energy, a stress)".into()
            }
        }
    }

    /// Whether [`Dropped::what`] is grammatically singular ("was not written").
    pub fn singular(&self) -> bool {
        matches!(self, Dropped::Property(_) | Dropped::Cell | Dropped::Time)
    }

    /// What the kind is counted in.
    pub fn per(&self) -> Per {
        match self {
            Dropped::Bonds | Dropped::BondOrders => Per::Bond,
            Dropped::Cell | Dropped::Time | Dropped::Step | Dropped::CommentValues => Per::Frame,
            _ => Per::Atom,
        }
    }

    /// The outputs that would keep this kind of `frame`'s data, as users know them (`.xyz`,
    /// `.lammpstrj`, `POSCAR`, ...): those whose [`crate::Writer::dropped`] would not name it
    /// for `frame` as a first frame (partial charges and a lost `charge` property count as
    /// the same data).
    pub fn kept_by(&self, frame: &Frame) -> Vec<&'static str> {
        let same = |d: &Dropped| match (d, self) {
            (Dropped::PartialCharges, Dropped::Property(n))
            | (Dropped::Property(n), Dropped::PartialCharges) => n == "charge",
            _ => d == self,
        };
        Output::ALL
            .into_iter()
            .filter(|o| !dropped(*o, frame, State::default()).iter().any(same))
            .map(Output::name)
            .collect()
    }
}

/// Why `output` does not keep `kind`, as the end of a sentence "... was not written: ".
pub(crate) fn reason(output: Output, kind: &Dropped) -> String {
    let subject = output.subject();
    match (output, kind) {
        (Output::LammpsData, Dropped::Velocities) => "a LAMMPS data file's velocities are in its run's units, which it does not state; a data file's own velocities, the properties vx vy vz, are written".into(),
        (Output::Sdf, Dropped::PartialCharges) => "an SD file holds integer formal charges only".into(),
        (Output::LammpsData, Dropped::ImageFlags) => "a LAMMPS data file's image flags are whole numbers of periodic cells, and these are not, or the frame has no cell".into(),
        (Output::Mmcif, Dropped::Cell) => "a PDBx/mmCIF file holds the first frame's cell only".into(),
        (Output::Pdb, Dropped::BondOrders) => "a PDB file's CONECT records repeat double and triple bonds only (aromatic and unknown orders are written as single bonds)".into(),
        (Output::Dcd, Dropped::Time) => "a DCD file has no time per frame: readers compute step × one time step, so only times proportional to the steps come back".into(),
        (Output::Dcd, Dropped::Step) => "a DCD file holds evenly spaced steps only (the first step and the spacing of the first two frames)".into(),
        (Output::LammpsDump, Dropped::Types) => "LAMMPS types are numbers: the labels were numbered 1, 2, … and written as the element column, which readers take as names".into(),
        (Output::LammpsData, Dropped::Types) => "LAMMPS types are numbers: the labels were numbered 1, 2, … and written as the Masses lines' comments (the Type Labels section of LAMMPS 2022 and later is not written: earlier versions reject it)".into(),
        (Output::Pdb, Dropped::Segments) => "a PDB file's segment column holds 4 characters".into(),
        (Output::LammpsData, Dropped::Property(name)) if name == "mass" => "a LAMMPS data file's Masses are positive, one per type (the section is left out)".into(),
        (_, Dropped::Property(name)) if group(output, name).is_some() => {
            let g = group(output, name).unwrap_or_default();
            format!("{subject} takes {} only together", g.join(" "))
        }
        (_, k) if k.singular() => format!("{subject} has no place for it"),
        _ => format!("{subject} has no place for them"),
    }
}
