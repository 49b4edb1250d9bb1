//! Our extended-XYZ and LAMMPS dump writers: round trips through our readers, the LAMMPS
//! manual's box bounds computed by hand, exact expected texts, refused frames, and files written
//! by LAMMPS, OVITO and ASE read, written again and read back; and for every output, what
//! `Writer::dropped` names against what a frame carrying everything does not give back when
//! the file is read.

use std::io::Cursor;
use std::path::PathBuf;
use texmap_md_io::{Element, Format, Frame, Label, Property, Trajectory, UnitCell, Writer};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn labels(s: &[&str]) -> Vec<Label> {
    s.iter().map(|l| Label::new(l).unwrap()).collect()
}

fn element(s: &str) -> Element {
    Element::from_symbol(s).unwrap()
}

fn property(name: &str, values: &[f32]) -> Property {
    Property {
        name: name.into(),
        values: values.to_vec(),
    }
}

/// Writes `frames` in `format` to memory.
fn write(format: Format, frames: &[Frame]) -> String {
    let mut w = Writer::new(Cursor::new(Vec::new()), format, "out").unwrap();
    for f in frames {
        w.write_frame(f).unwrap();
    }
    String::from_utf8(w.finish().unwrap().into_inner()).unwrap()
}

/// Reads every frame of `text` with our reader of `format`.
fn read(format: Format, text: &str) -> Vec<Frame> {
    let mut t =
        Trajectory::from_reader(Cursor::new(text.as_bytes().to_vec()), format, "out").unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

fn read_file(name: &str) -> Vec<Frame> {
    let mut t = Trajectory::open(data(name)).unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

/// The same f32 bits, NaN equal to NaN (a NaN's payload is not kept by `nan` in text).
fn same_bits(a: &[f32], b: &[f32], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
            "{what}[{i}]: wrote {x:?}, read back {y:?}"
        );
    }
}

fn same_bits3(a: &[[f32; 3]], b: &[[f32; 3]], what: &str) {
    same_bits(a.as_flattened(), b.as_flattened(), what);
}

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1.0),
        "{what}: {a} against {b}"
    );
}

/// The cell matrix (and origin when `origin`) within 1e-6 relative.
fn same_cell(a: &Frame, b: &Frame, origin: bool) {
    let (ca, cb) = (a.cell.unwrap(), b.cell.expect("a cell read back"));
    for r in 0..3 {
        for k in 0..3 {
            close(
                ca.matrix()[r][k],
                cb.matrix()[r][k],
                &format!("cell[{r}][{k}]"),
            );
        }
        if origin {
            close(ca.origin()[r], cb.origin()[r], &format!("origin[{r}]"));
        }
    }
}

fn same_properties(a: &Frame, b: &Frame) {
    let names = |f: &Frame| {
        f.properties
            .iter()
            .map(|p| p.name.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(names(a), names(b), "property names");
    for (p, q) in a.properties.iter().zip(&b.properties) {
        same_bits(&p.values, &q.values, &p.name);
    }
}

/// A user's analysis result: a triclinic cell with an origin (xy = 1, xz = -2, yz = 0.5), ids,
/// string types, velocities, radii, an integer property and a real one with a NaN.
fn analysis_frame() -> Frame {
    let mut f = Frame::new();
    f.positions = vec![
        [0.1, 1.0 / 3.0, -2.5e-3],
        [9.87654, 4.2, 5.999999],
        [-1.25, 7.0e-8, 3.3333333],
    ];
    f.velocities = vec![
        [0.5, -1.0e-3, 12.25],
        [0.0, -0.0, 1.0 / 7.0],
        [3.0, 2.0, 1.0],
    ];
    f.ids = vec![3, 7, 12];
    f.types = labels(&["Cu", "O", "Cu"]);
    f.elements = vec![element("Cu"), element("O"), element("Cu")];
    f.radii = vec![1.28, 0.66, 1.28];
    f.properties = vec![
        property("cluster", &[1.0, 2.0, -16_777_215.0]),
        property("c_pe", &[-3.54, f32::NAN, 1.0e-7]),
    ];
    f.cell = Some(
        UnitCell::from_matrix([[10.0, 0.0, 0.0], [1.0, 8.0, 0.0], [-2.0, 0.5, 6.0]])
            .unwrap()
            .with_origin([1.0, -2.0, 0.5]),
    );
    f.step = Some(100);
    f
}

#[test]
fn xyz_round_trip_of_ids_types_and_properties_is_bit_exact() {
    let f = analysis_frame();
    let text = write(Format::Xyz, std::slice::from_ref(&f));
    // The integer column is I, the one with a NaN R.
    assert!(
        text.contains(
            "Properties=species:S:1:pos:R:3:id:I:1:type:S:1:velo:R:3:radius:R:1:cluster:I:1:c_pe:R:1"
        ),
        "{text}"
    );
    assert!(text.contains(" -16777215 "), "{text}");
    let back = read(Format::Xyz, &text);
    assert_eq!(back.len(), 1);
    let b = &back[0];
    same_bits3(&f.positions, &b.positions, "positions");
    same_bits3(&f.velocities, &b.velocities, "velocities");
    same_bits(&f.radii, &b.radii, "radii");
    assert_eq!(f.ids, b.ids);
    assert_eq!(f.types, b.types);
    assert_eq!(f.elements, b.elements);
    // The species column is the element symbol when the frame has no names.
    assert_eq!(b.names, labels(&["Cu", "O", "Cu"]));
    same_properties(&f, b);
    assert_eq!(b.step, Some(100));
    // Extended XYZ has no cell origin: the edges only.
    same_cell(&f, b, false);
}

#[test]
fn lammps_round_trip_of_ids_types_and_properties_is_bit_exact() {
    let f = analysis_frame();
    let text = write(Format::LammpsDump, std::slice::from_ref(&f));
    let back = read(Format::LammpsDump, &text);
    assert_eq!(back.len(), 1);
    let b = &back[0];
    same_bits3(&f.positions, &b.positions, "positions");
    same_bits3(&f.velocities, &b.velocities, "velocities");
    same_bits(&f.radii, &b.radii, "radii");
    assert_eq!(f.ids, b.ids);
    // Named types are numbered by first appearance; the names come back as the element column.
    assert_eq!(b.types, labels(&["1", "2", "1"]));
    assert_eq!(f.elements, b.elements);
    same_properties(&f, b);
    assert_eq!(b.step, Some(100));
    same_cell(&f, b, true);
}

/// The bound lines of the first frame of a dump: `[lo_bound, hi_bound, tilt]` per line.
fn bounds(text: &str) -> (String, Vec<Vec<f64>>) {
    let mut lines = text
        .lines()
        .skip_while(|l| !l.starts_with("ITEM: BOX BOUNDS"));
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .take(3)
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

fn cell_frame(m: [[f64; 3]; 3], origin: [f64; 3]) -> Frame {
    let mut f = Frame::new();
    f.positions = vec![[1.0, 1.0, 1.0]];
    f.cell = Some(UnitCell::from_matrix(m).unwrap().with_origin(origin));
    f
}

#[test]
fn lammps_box_bounds_are_the_manuals_formulas() {
    // LAMMPS manual, Howto triclinic: xlo_bound = xlo + min(0, xy, xz, xy+xz),
    // xhi_bound = xhi + max(0, xy, xz, xy+xz), ylo_bound = ylo + min(0, yz),
    // yhi_bound = yhi + max(0, yz), z unchanged; each line ends with its tilt (xy, xz, yz).
    //
    // Box 1: lx = 10, ly = 8, lz = 6, xy = 1, xz = -2, yz = 0.5, origin (1, -2, 0.5):
    //   xlo = 1, xhi = 11; min(0, 1, -2, -1) = -2, max(0, 1, -2, -1) = 1 → -1, 12;
    //   ylo = -2, yhi = 6; min(0, 0.5) = 0, max = 0.5 → -2, 6.5;
    //   zlo = 0.5, zhi = 6.5.
    let f = cell_frame(
        [[10.0, 0.0, 0.0], [1.0, 8.0, 0.0], [-2.0, 0.5, 6.0]],
        [1.0, -2.0, 0.5],
    );
    let (header, rows) = bounds(&write(Format::LammpsDump, &[f]));
    assert_eq!(header, "ITEM: BOX BOUNDS xy xz yz pp pp pp");
    assert_eq!(
        rows,
        [[-1.0, 12.0, 1.0], [-2.0, 6.5, -2.0], [0.5, 6.5, 0.5]]
    );
    // Box 2: lx = 10, ly = 8, lz = 6, xy = -3, xz = 2, yz = -1, origin 0:
    //   min(0, -3, 2, -1) = -3, max(0, -3, 2, -1) = 2 → -3, 12;
    //   min(0, -1) = -1, max = 0 → -1, 8; z 0, 6.
    let f = cell_frame(
        [[10.0, 0.0, 0.0], [-3.0, 8.0, 0.0], [2.0, -1.0, 6.0]],
        [0.0; 3],
    );
    let (_, rows) = bounds(&write(Format::LammpsDump, &[f]));
    assert_eq!(
        rows,
        [[-3.0, 12.0, -3.0], [-1.0, 8.0, 2.0], [0.0, 6.0, -1.0]]
    );
    // An orthogonal box: lo hi per axis, no tilts.
    let f = cell_frame(
        [[10.0, 0.0, 0.0], [0.0, 8.0, 0.0], [0.0, 0.0, 6.0]],
        [-5.0, 0.0, 2.5],
    );
    let (header, rows) = bounds(&write(Format::LammpsDump, &[f]));
    assert_eq!(header, "ITEM: BOX BOUNDS pp pp pp");
    assert_eq!(rows, [[-5.0, 5.0], [0.0, 8.0], [2.5, 8.5]]);
    // Our reader recovers the box (lo = bound - min, hi = bound - max).
    let f = analysis_frame();
    let back = read(
        Format::LammpsDump,
        &write(Format::LammpsDump, std::slice::from_ref(&f)),
    );
    same_cell(&f, &back[0], true);
}

/// A 2-atom frame with every column both writers write.
fn two_atoms() -> Frame {
    let mut f = Frame::new();
    f.positions = vec![[0.5, 1.25, -2.0], [3.1, 0.2, 0.001]];
    f.velocities = vec![[0.1, 0.0, -0.1], [1.0, 2.0, 3.0]];
    f.elements = vec![element("Cu"), element("O")];
    f.ids = vec![5, 9];
    f.types = labels(&["Cu", "O"]);
    f.properties = vec![
        property("cluster", &[1.0, 2.0]),
        property("c_pe", &[-3.5, f32::NAN]),
    ];
    f.cell =
        Some(UnitCell::from_matrix([[4.0, 0.0, 0.0], [1.0, 5.0, 0.0], [-2.0, 0.5, 6.0]]).unwrap());
    f.step = Some(7);
    f
}

#[test]
fn xyz_text_of_a_two_atom_frame() {
    let expected = "\
2
Lattice=\"4 0 0 1 5 0 -2 0.5 6\" Properties=species:S:1:pos:R:3:id:I:1:type:S:1:velo:R:3:cluster:I:1:c_pe:R:1 step=7 pbc=\"T T T\"
Cu 0.5 1.25 -2 5 Cu 0.1 0 -0.1 1 -3.5
O 3.1 0.2 0.001 9 O 1 2 3 2 nan
";
    assert_eq!(write(Format::Xyz, &[two_atoms()]), expected);
}

#[test]
fn lammps_text_of_a_two_atom_frame() {
    // Bounds: xy = 1, xz = -2, yz = 0.5 over [0, 4] x [0, 5] x [0, 6]:
    // x: 0 + min(0, 1, -2, -1) = -2, 4 + max(0, 1, -2, -1) = 5; y: 0, 5 + 0.5 = 5.5.
    let expected = "\
ITEM: TIMESTEP
7
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS xy xz yz pp pp pp
-2 5 1
0 5.5 -2
0 6 0.5
ITEM: ATOMS id type x y z element vx vy vz cluster c_pe
5 1 0.5 1.25 -2 Cu 0.1 0 -0.1 1 -3.5
9 2 3.1 0.2 0.001 O 1 2 3 2 nan
";
    assert_eq!(write(Format::LammpsDump, &[two_atoms()]), expected);
}

#[test]
fn lammps_without_cell_types_or_step_shrink_wraps_and_numbers_elements_for_the_whole_file() {
    // No cell: the atoms' extent as a shrink-wrapped box. No types: the elements are numbered
    // in order of first appearance, and a later frame keeps the numbers (Fe stays 2, the new
    // H gets 3). No step: the frame's index in the file.
    let mut a = Frame::new();
    a.positions = vec![[1.0, -2.0, 3.0], [-4.0, 5.0, 0.5], [0.0, 0.0, 0.0]];
    a.elements = vec![element("O"), element("Fe"), element("O")];
    let mut b = Frame::new();
    b.positions = vec![[0.0; 3], [1.0; 3]];
    b.elements = vec![element("H"), element("Fe")];
    let expected = "\
ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
3
ITEM: BOX BOUNDS ss ss ss
-4 1
-2 5
0 3
ITEM: ATOMS id type x y z element
1 1 1 -2 3 O
2 2 -4 5 0.5 Fe
3 1 0 0 0 O
ITEM: TIMESTEP
1
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS ss ss ss
0 1
0 1
0 1
ITEM: ATOMS id type x y z element
1 3 0 0 0 H
2 2 1 1 1 Fe
";
    let text = write(Format::LammpsDump, &[a.clone(), b.clone()]);
    assert_eq!(text, expected);
    let back = read(Format::LammpsDump, &text);
    assert_eq!(back[0].elements, a.elements);
    assert_eq!(back[1].elements, b.elements);
    assert_eq!(back[1].types, labels(&["3", "2"]));
    assert_eq!((back[0].step, back[1].step), (Some(0), Some(1)));
}

#[test]
fn lammps_numeric_types_are_written_as_they_are() {
    let mut f = Frame::new();
    f.positions = vec![[0.0; 3], [1.0; 3]];
    f.types = labels(&["4", "2"]);
    let text = write(Format::LammpsDump, std::slice::from_ref(&f));
    assert!(
        text.contains("ITEM: ATOMS id type x y z\n1 4 0 0 0\n2 2 1 1 1\n"),
        "{text}"
    );
    assert_eq!(read(Format::LammpsDump, &text)[0].types, f.types);
}

/// The message of the error writing `f` in `format` gives; nothing of the frame is written.
fn refused(format: Format, f: &Frame) -> String {
    let mut w = Writer::new(Cursor::new(Vec::new()), format, "out").unwrap();
    let e = w.write_frame(f).unwrap_err().to_string();
    assert_eq!(w.frames_written(), 0);
    assert!(w.finish().unwrap().into_inner().is_empty(), "{format:?}");
    e
}

#[test]
fn frames_the_formats_cannot_hold_are_refused_with_the_reason() {
    // A cell turned 90° about z (a along y) is a valid cell but not a LAMMPS box.
    let mut f = two_atoms();
    f.cell =
        Some(UnitCell::from_matrix([[0.0, 10.0, 0.0], [-8.0, 0.0, 0.0], [0.0, 0.0, 6.0]]).unwrap());
    let e = refused(Format::LammpsDump, &f);
    assert!(
        e.contains(
            "the cell is not in LAMMPS's restricted triclinic form (a along x, b in the xy plane)"
        ),
        "{e}"
    );
    // Extended XYZ writes any cell.
    assert!(write(Format::Xyz, &[f]).contains("Lattice=\"0 10 0 -8 0 0 0 0 6\""));

    let mut f = two_atoms();
    f.properties[1].name = "a b".into();
    let e = refused(Format::Xyz, &f);
    assert!(
        e.contains("property 'a b' is not an extended-XYZ column name: letters, digits and _"),
        "{e}"
    );
    let e = refused(Format::LammpsDump, &f);
    assert!(
        e.contains("property 'a b'") && e.contains("white space"),
        "{e}"
    );

    // LAMMPS column names that are not extended-XYZ names.
    let mut f = two_atoms();
    f.properties[1].name = "v_stress[1]".into();
    let e = refused(Format::Xyz, &f);
    assert!(e.contains("property 'v_stress[1]'"), "{e}");
    assert!(write(Format::LammpsDump, &[f]).contains(" v_stress[1]\n"));

    let mut f = two_atoms();
    f.types[1] = Label::new("a b").unwrap();
    for format in [Format::Xyz, Format::LammpsDump] {
        let e = refused(format, &f);
        assert!(
            e.contains("atom 1's type 'a b' contains white space"),
            "{e}"
        );
    }

    // Names of the writers' own columns, and a name twice.
    for (format, name) in [
        (Format::Xyz, "pos"),
        (Format::Xyz, "type"),
        (Format::Xyz, "Z"),
        (Format::LammpsDump, "x"),
        (Format::LammpsDump, "element"),
        (Format::LammpsDump, "Color.R"),
    ] {
        let mut f = two_atoms();
        f.properties[0].name = name.into();
        let e = refused(format, &f);
        assert!(
            e.contains(&format!("property '{name}' has the name of a column")),
            "{e}"
        );
    }
    let mut f = two_atoms();
    f.properties[1].name = "cluster".into();
    for format in [Format::Xyz, Format::LammpsDump] {
        let e = refused(format, &f);
        assert!(e.contains("property 'cluster' appears twice"), "{e}");
    }
}

/// Every field the two frames hold is the same (properties by name and bits, cell within 1e-6).
fn same_frame(a: &Frame, b: &Frame, origin: bool) {
    same_bits3(&a.positions, &b.positions, "positions");
    same_bits3(&a.velocities, &b.velocities, "velocities");
    same_bits3(&a.colors, &b.colors, "colours");
    same_bits(&a.radii, &b.radii, "radii");
    assert_eq!(a.ids, b.ids, "ids");
    assert_eq!(a.types, b.types, "types");
    assert_eq!(a.names, b.names, "names");
    assert_eq!(a.elements, b.elements, "elements");
    assert_eq!(a.step, b.step, "step");
    assert_eq!(a.time, b.time, "time");
    same_properties(a, b);
    assert_eq!(a.cell.is_some(), b.cell.is_some(), "cell");
    if a.cell.is_some() {
        same_cell(a, b, origin);
    }
}

#[test]
fn lammps_dumps_of_lammps_and_ovito_read_written_and_read_back_unchanged() {
    // LAMMPS's own dump custom (triclinic, ids in processor order, numeric types with an element
    // column, velocities, scaled and unwrapped copies and image flags as properties) and
    // OVITO's export (a general-triclinic `abc origin` box, colours, radii).
    for name in ["lmp_tri.lammpstrj", "ovito_color.lammpstrj"] {
        let first = read_file(name);
        assert!(!first.is_empty());
        let text = write(Format::LammpsDump, &first);
        let back = read(Format::LammpsDump, &text);
        assert_eq!(back.len(), first.len(), "{name}");
        for (k, (a, b)) in first.iter().zip(&back).enumerate() {
            eprintln!("{name} frame {k}");
            same_frame(a, b, true);
        }
    }
    // What the LAMMPS file holds is all there.
    let f = &read_file("lmp_tri.lammpstrj")[0];
    assert_eq!(f.elements[0], element("Ar"));
    assert!(f.property("ix").is_some() && !f.velocities.is_empty());
}

#[test]
fn ase_extended_xyz_read_written_and_read_back_unchanged() {
    // ASE's extxyz with real and integer (`tags`) arrays, and one with radii and colours.
    for name in ["ase_props.xyz", "ase_ext.xyz"] {
        let first = read_file(name);
        let text = write(Format::Xyz, &first);
        let back = read(Format::Xyz, &text);
        assert_eq!(back.len(), first.len(), "{name}");
        for (a, b) in first.iter().zip(&back) {
            same_frame(a, b, false);
            // The comment line is ours, not the file's.
        }
        if name == "ase_props.xyz" {
            assert!(text.contains(":tags:I:1:"), "{}", &text[..300]);
        }
    }
}

/// Type names that are no element symbols (GROMACS's OW, HW) go to the `element` column, as
/// OVITO reads it; our reader takes them back as the atoms' names, the elements guessed from
/// them, whatever order the ids come in.
#[test]
fn lammps_type_names_that_are_no_elements_read_back_as_names() {
    let mut f = Frame::new();
    f.positions = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0]];
    f.types = labels(&["Na", "OW", "HW", "OW"]);
    f.ids = vec![4, 1, 2, 3];
    let text = write(Format::LammpsDump, &[f]);
    assert!(text.contains("ITEM: ATOMS id type x y z element\n4 1 0 0 0 Na\n1 2 1 0 0 OW\n"));
    let back = &read(Format::LammpsDump, &text)[0];
    // Sorted by id: 1 OW, 2 HW, 3 OW, 4 Na.
    assert_eq!(back.ids, [1, 2, 3, 4]);
    let names: Vec<&str> = back.names.iter().map(|l| l.as_str()).collect();
    assert_eq!(names, ["OW", "HW", "OW", "Na"]);
    let symbols: Vec<&str> = back.elements.iter().map(|e| e.symbol()).collect();
    assert_eq!(symbols, ["O", "H", "O", "Na"]);
    assert_eq!(back.positions[3], [0.0; 3]);
}

/// .gro files written by MDAnalysis (velocities, a triclinic box) and by a writer of five
/// decimals read, written as GROMACS writes them and read back: names, residues, numbers and the
/// box unchanged, positions to the written 0.001 nm (0.01 Å), velocities to 0.0001 nm/ps.
#[test]
fn gro_files_of_other_programs_read_written_and_read_back() {
    for name in ["mda_vel.gro", "py_prec5.gro"] {
        let first = read_file(name);
        let text = write(Format::Gro, &first);
        let back = read(Format::Gro, &text);
        assert_eq!(back.len(), first.len(), "{name}");
        for (a, b) in first.iter().zip(&back) {
            assert_eq!(a.names, b.names, "{name}");
            assert_eq!(a.res_names, b.res_names, "{name}");
            assert_eq!(a.res_ids, b.res_ids, "{name}");
            assert_eq!(a.ids, b.ids, "{name}");
            assert_eq!(a.elements, b.elements, "{name}");
            assert_eq!(a.velocities.len(), b.velocities.len(), "{name}");
            for (p, q) in a.positions.iter().zip(&b.positions) {
                for k in 0..3 {
                    assert!(
                        (p[k] - q[k]).abs() <= 0.005 + 1e-5 * p[k].abs(),
                        "{name}: {p:?} {q:?}"
                    );
                }
            }
            for (p, q) in a.velocities.iter().zip(&b.velocities) {
                for k in 0..3 {
                    assert!(
                        (p[k] - q[k]).abs() <= 0.0005 + 1e-5 * p[k].abs(),
                        "{name}: {p:?} {q:?}"
                    );
                }
            }
            let (ca, cb) = (a.cell.unwrap().matrix(), b.cell.unwrap().matrix());
            for r in 0..3 {
                for c in 0..3 {
                    assert!((ca[r][c] - cb[r][c]).abs() <= 5e-5, "{name}: {ca:?} {cb:?}");
                }
            }
        }
        // A three-decimal file is written back as it was, but for the title.
        if name == "mda_vel.gro" {
            let original = std::fs::read_to_string(data(name)).unwrap();
            let body = |t: &str| t.lines().skip(1).map(str::to_string).collect::<Vec<_>>();
            assert_eq!(body(&text), body(&original));
        }
    }
}

/// The exact text of a two-atom .gro frame (GROMACS's columns), and what .gro cannot hold.
#[test]
fn gro_text_and_refusals() {
    let mut f = Frame::new();
    // 12.345 as f32 is 12.3450003: 1.235 nm.
    f.positions = vec![[12.345, -0.5, 100.0], [0.0, 1.0, 2.0]];
    f.names = labels(&["OW", "HW1"]);
    f.res_names = labels(&["SOL", "SOL"]);
    f.res_ids = vec![7, 7];
    f.ids = vec![100_001, 2];
    f.time = Some(1.5);
    f.step = Some(30);
    f.cell = Some(UnitCell::orthorhombic(30.0, 31.0, 32.0).unwrap());
    let text = write(Format::Gro, std::slice::from_ref(&f));
    assert_eq!(
        text,
        "texmap t= 1.50000 step= 30\n    2\n    7SOL     OW    1   1.235  -0.050  10.000\n    7SOL    HW1    2   0.000   0.100   0.200\n   3.00000   3.10000   3.20000\n"
    );
    let back = &read(Format::Gro, &text)[0];
    assert_eq!(back.time, Some(1.5));
    assert_eq!(back.step, Some(30));
    let mut long = f.clone();
    long.names[1] = Label::new("HW123").unwrap();
    long.res_names[0] = Label::new("SOLVNT").unwrap();
    let e = refused(Format::Gro, &long);
    assert!(e.contains("residue name 'SOLVNT' does not fit"), "{e}");
    let mut tilted = f.clone();
    tilted.cell = Some(
        UnitCell::from_matrix([[30.0, 1.0, 0.0], [0.0, 31.0, 0.0], [0.0, 0.0, 32.0]]).unwrap(),
    );
    let e = refused(Format::Gro, &tilted);
    assert!(e.contains("not in GROMACS's form"), "{e}");
}

// SDF writer (src/sdf_writer.rs): the committed files of tests/data/sdf_write are what the
// writer writes now, our reader reads them back, and RDKit read them as rdkit_reference.json
// records (gen_rdkit_reference.py there).

/// Glycine as a zwitterion (NH3+, COO-) with step and time, then a Mg2+ ion, then an atom of
/// no element bonded to a carbon by a bond of unknown order.
fn sdf_charged_frames() -> Vec<Frame> {
    let mut gly = Frame::new();
    let atoms: [(&str, [f32; 3], f32); 10] = [
        ("N", [-1.4526, 0.3198, 0.0011], 1.0),
        ("C", [0.0, 0.4563, -0.0218], 0.0),
        ("C", [0.6116, -0.9304, 0.0121], 0.0),
        ("O", [1.8586, -0.9857, 0.0102], 0.0),
        ("O", [-0.1434, -1.9202, 0.0372], -1.0),
        ("H", [-1.8477, 1.2719, -0.0146], 0.0),
        ("H", [-1.7529, -0.1576, 0.8554], 0.0),
        ("H", [-1.7761, -0.1908, -0.8261], 0.0),
        ("H", [0.3179, 1.0063, -0.9084], 0.0),
        ("H", [0.3411, 1.0395, 0.8316], 0.0),
    ];
    for (e, p, _) in atoms {
        gly.positions.push(p);
        gly.elements.push(element(e));
    }
    gly.properties.push(property("charge", &atoms.map(|a| a.2)));
    gly.bonds = vec![
        [0, 1],
        [0, 5],
        [0, 6],
        [0, 7],
        [1, 2],
        [1, 8],
        [1, 9],
        [2, 3],
        [2, 4],
    ];
    gly.bond_orders = vec![1, 1, 1, 1, 1, 1, 1, 2, 1];
    gly.comment = "glycine zwitterion\nsecond comment line".into();
    gly.step = Some(42);
    gly.time = Some(0.5);
    let mut mg = Frame::new();
    mg.positions.push([0.0, 0.0, 0.0]);
    mg.elements.push(element("Mg"));
    mg.properties.push(property("charge", &[2.0]));
    mg.comment = "magnesium".into();
    let mut dummy = Frame::new();
    dummy.positions = vec![[0.0, 0.0, 0.0], [-1.5, 2.25, 99999.99]];
    dummy.elements = vec![element("C"), Element::UNKNOWN];
    dummy.names = labels(&["C1", "LP"]);
    dummy.bonds = vec![[0, 1]];
    dummy.bond_orders = vec![0];
    vec![gly, mg, dummy]
}

/// A chain of 1000 carbons (999 bonds, no orders): past V2000's 999 atoms, so V3000.
fn sdf_chain_frame() -> Frame {
    let mut f = Frame::new();
    for i in 0..1000 {
        let x = i as f32 * 1.2574;
        f.positions
            .push([x, if i % 2 == 0 { 0.0 } else { 0.8890 }, -0.25]);
        f.elements.push(element("C"));
    }
    f.bonds = (0..999).map(|i| [i, i + 1]).collect();
    f.comment = "C1000".into();
    f
}

/// Each committed SD file of tests/data/sdf_write and the frames it was written from.
fn sdf_sources() -> Vec<(&'static str, Vec<Frame>)> {
    let mut out = Vec::new();
    for (name, src) in [
        ("imatinib_confs.sdf", "molecules/imatinib_confs.sdf"),
        ("library_sdf.sdf", "molecules/library.sdf"),
        ("caffeine_v3000.sdf", "molecules/caffeine_v3000.mol"),
        ("imatinib_poses_mol2.sdf", "molecules/imatinib_poses.mol2"),
        ("library_mol2.sdf", "molecules/library.mol2"),
        ("vina_poses.sdf", "pdbqt/poses.pdbqt"),
    ] {
        let mut frames = read_file(src);
        if src.ends_with(".pdbqt") {
            // PDBQT lists no bonds: those by distance, as texmap convert gives an SD file.
            for f in &mut frames {
                f.bonds = texmap_md_io::bonds::bonds_by_distance(f, false).pairs;
            }
        }
        out.push((name, frames));
    }
    out.push(("charged.sdf", sdf_charged_frames()));
    out.push(("chain_v3000.sdf", vec![sdf_chain_frame()]));
    out
}

/// The element symbol the writer gives atom `i`.
fn sdf_symbol(f: &Frame, i: usize) -> String {
    match f.elements.get(i) {
        Some(e) if !e.is_unknown() => e.symbol().to_string(),
        _ => "*".to_string(),
    }
}

/// The bond types the file holds: the orders, 1 without them.
fn sdf_orders(f: &Frame) -> Vec<u8> {
    if f.bond_orders.is_empty() {
        vec![1; f.bonds.len()]
    } else {
        f.bond_orders.clone()
    }
}

/// The title line: the comment's first line, else the stem of the file name ("out").
fn sdf_title(f: &Frame) -> String {
    let t = f.comment.lines().next().unwrap_or("").trim_end();
    if t.is_empty() { "out" } else { t }.to_string()
}

/// Positions within the 4 written decimals plus the f32 rounding of the value read back.
fn sdf_close(a: [f32; 3], b: [f64; 3], what: &str) {
    for k in 0..3 {
        let tol = 5.1e-5 + 2.0 * f32::EPSILON as f64 * b[k].abs();
        assert!((a[k] as f64 - b[k]).abs() <= tol, "{what}: {a:?} vs {b:?}");
    }
}

#[test]
fn sdf_files_written_now_are_the_committed_ones_and_read_back() {
    for (name, frames) in sdf_sources() {
        let text = write(Format::Sdf, &frames);
        let path = data("sdf_write").join(name);
        if std::env::var_os("TEXMAP_REGENERATE_SDF").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap();
        assert!(committed == text, "{name}: the writer's bytes changed");
        let back = read(Format::Sdf, &text);
        assert_eq!(back.len(), frames.len(), "{name}");
        for (k, (a, b)) in frames.iter().zip(&back).enumerate() {
            let case = format!("{name} record {k}");
            assert!(!a.positions.is_empty() || b.positions.is_empty(), "{case}");
            assert_eq!(a.n_atoms(), b.n_atoms(), "{case}");
            for i in 0..a.n_atoms() {
                assert_eq!(sdf_symbol(a, i), sdf_symbol(b, i), "{case} atom {i}");
                let p = a.positions[i].map(|x| x as f64);
                sdf_close(b.positions[i], p, &case);
            }
            assert_eq!(a.bonds, b.bonds, "{case}");
            assert_eq!(sdf_orders(a), b.bond_orders, "{case}");
            assert_eq!(
                sdf_title(a),
                b.comment.lines().next().unwrap_or(""),
                "{case}"
            );
            assert_eq!((a.step, a.time), (b.step, b.time), "{case}: data items");
            // The data items read (pairs after the title line) come back.
            if a.comment.contains('\n') {
                for (key, value) in a.comment_pairs() {
                    assert_eq!(b.comment_value(key), Some(value), "{case}: item {key}");
                }
            }
        }
    }
    // The V2000/V3000 choice, charges and data items where they belong.
    let charged = std::fs::read_to_string(data("sdf_write/charged.sdf")).unwrap();
    assert!(charged.contains(" N   0  3  0") && charged.contains("M  CHG  2   1   1   5  -1\n"));
    assert!(charged.contains("> <step>\n42\n\n> <time>\n0.5\n\n$$$$\n"));
    let chain = std::fs::read_to_string(data("sdf_write/chain_v3000.sdf")).unwrap();
    assert!(chain.contains("999 V3000\n") && chain.contains("M  V30 COUNTS 1000 999 0 0 0\n"));
    let vina = std::fs::read_to_string(data("sdf_write/vina_poses.sdf")).unwrap();
    assert!(
        vina.contains("> <minimizedAffinity>\n-4.268\n\n$$$$\n"),
        "{vina}"
    );
}

/// RDKit's `SDWriter` (2026.09) writes data items as `>  <name>  (1) `: the step and time
/// of such a record are read, another item and a value that is no number are not.
#[test]
fn sdf_step_and_time_items_written_by_rdkit_are_read() {
    let record = |step: &str, time: &str| {
        format!(
            "ethanol\n     RDKit          2D\n\n  3  2  0  0  0  0  0  0  0  0999 V2000\n\
             \x20   0.0000    0.0000    0.0000 C   0  0  0  0  0  0  0  0  0  0  0  0\n\
             \x20   1.2990    0.7500    0.0000 C   0  0  0  0  0  0  0  0  0  0  0  0\n\
             \x20   2.5981   -0.0000    0.0000 O   0  0  0  0  0  0  0  0  0  0  0  0\n\
             \x20 1  2  1  0\n  2  3  1  0\nM  END\n>  <step>  (1) \n{step}\n\n\
             >  <time>  (1) \n{time}\n\n>  <note>  (1) \nx\n\n$$$$\n"
        )
    };
    let text = record("7", "0.25") + &record("n/a", "late");
    let back = read(Format::Sdf, &text);
    assert_eq!(back.len(), 2);
    assert_eq!((back[0].step, back[0].time), (Some(7), Some(0.25)));
    assert_eq!((back[1].step, back[1].time), (None, None));
    assert_eq!(back[0].positions[2], [2.5981, -0.0, 0.0]);
    // Another item is a pair on the comment's second line, after the title.
    assert_eq!(back[0].comment, "ethanol\nnote=x");
    assert_eq!(back[0].comment_value("note"), Some("x"));
    // A docked pose as GNINA writes its items: kept through our writer and reader; a value of
    // two lines and an item whose name is no key are left out.
    let gnina = "lig\n     RDKit          3D\n\n  1  0  0  0  0  0  0  0  0  0999 V2000\n\
                 \x20   1.0000    2.0000    3.0000 C   0  0  0  0  0  0  0  0  0  0  0  0\n\
                 M  END\n> <minimizedAffinity>\n-7.52\n\n> <CNNscore>\n0.81\n\n\
                 > <Molecular Formula>\nC\n\n> <remark>\nline one\nline two\n\n\
                 > <pose_name>\nbest pose\n\n$$$$\n";
    let f = &read(Format::Sdf, gnina)[0];
    assert_eq!(
        f.comment,
        "lig\nminimizedAffinity=-7.52 CNNscore=0.81 pose_name=\"best pose\""
    );
    let again = write(Format::Sdf, std::slice::from_ref(f));
    assert!(
        again.contains(
            "M  END\n> <minimizedAffinity>\n-7.52\n\n> <CNNscore>\n0.81\n\n> <pose_name>\nbest pose\n\n$$$$\n"
        ),
        "{again}"
    );
    assert_eq!(read(Format::Sdf, &again)[0].comment, f.comment);
}

/// The committed SD files as RDKit read them (rdkit_reference.json) against the frames they
/// were written from.
fn sdf_check_rdkit(reference: &serde_json::Value) {
    use serde_json::Value;
    let sources = sdf_sources();
    let files = reference.as_object().unwrap();
    assert_eq!(files.len(), sources.len());
    for (name, frames) in &sources {
        let records = files[*name].as_array().unwrap();
        assert_eq!(records.len(), frames.len(), "{name}");
        for (k, (r, f)) in records.iter().zip(frames).enumerate() {
            let case = format!("{name} record {k}");
            assert_eq!(r["name"], Value::from(sdf_title(f)), "{case}");
            let symbols: Vec<String> = (0..f.n_atoms()).map(|i| sdf_symbol(f, i)).collect();
            assert_eq!(r["symbols"], serde_json::json!(symbols), "{case}");
            let coords = r["coords"].as_array().unwrap();
            assert_eq!(coords.len(), f.n_atoms(), "{case}");
            for (c, p) in coords.iter().zip(&f.positions) {
                let c: Vec<f64> = c
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap())
                    .collect();
                // RDKit's f64 of the written text against our f32: 4 decimals.
                for k in 0..3 {
                    assert!((c[k] - p[k] as f64).abs() <= 5.1e-5, "{case}: {c:?} {p:?}");
                }
            }
            let bonds: Vec<[u32; 3]> = f
                .bonds
                .iter()
                .zip(sdf_orders(f))
                .map(|(b, o)| [b[0], b[1], o as u32])
                .collect();
            assert_eq!(r["bonds"], serde_json::json!(bonds), "{case}");
            let q: Vec<i64> = match f.property("charge") {
                Some(q) if q.iter().all(|v| v.fract() == 0.0) => {
                    q.iter().map(|&v| v as i64).collect()
                }
                _ => vec![0; f.n_atoms()],
            };
            assert_eq!(r["charges"], serde_json::json!(q), "{case}");
            // Every record passes RDKit's sanitizer with the charges written (an atom of no
            // element is a query atom there) but tetramethylammonium from MOL2: a MOL2 holds
            // partial charges, no formal charge for its N (+1), and a neutral N of four bonds
            // is refused. From the SD file its M  CHG line is read and written back.
            let sane = !(*name == "library_mol2.sdf" && sdf_title(f) == "tetramethylammonium");
            assert_eq!(r["sanitized"], Value::Bool(sane), "{case}");
            if sane {
                assert_eq!(r["sanitized_charges"], serde_json::json!(q), "{case}");
            }
            let props = r["props"].as_object().unwrap();
            assert_eq!(
                props.get("step").and_then(Value::as_str),
                f.step.map(|s| s.to_string()).as_deref(),
                "{case}"
            );
        }
    }
}

#[test]
fn sdf_files_read_by_rdkit_are_the_frames_written() {
    let text = std::fs::read_to_string(data("sdf_write/rdkit_reference.json")).unwrap();
    sdf_check_rdkit(&serde_json::from_str(&text).unwrap());
}

/// RDKit itself on the files written now, where python3 has rdkit.
#[test]
fn sdf_rdkit_reads_files_written_now() {
    let probe = std::process::Command::new("python3")
        .args(["-c", "import rdkit"])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!(
            "SKIPPED: no python3 with rdkit (pip install rdkit); the committed reference covers it"
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (name, frames) in sdf_sources() {
        std::fs::write(dir.path().join(name), write(Format::Sdf, &frames)).unwrap();
    }
    let out = dir.path().join("reference.json");
    let o = std::process::Command::new("python3")
        .arg(data("sdf_write/gen_rdkit_reference.py"))
        .arg(dir.path())
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let now: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    sdf_check_rdkit(&now);
}

#[test]
fn sdf_text_of_a_small_frame_and_refusals() {
    let mut f = Frame::new();
    f.positions = vec![[0.0, -0.0, 1.23456], [-1.5, 2.25, 100.0]];
    f.elements = vec![element("N"), Element::UNKNOWN];
    f.properties.push(property("charge", &[1.0, 0.0]));
    f.bonds = vec![[0, 1]];
    f.bond_orders = vec![2];
    f.comment = "ion\r\nsecond line".into();
    f.step = Some(7);
    let expected = "ion\n  texmap            3D\n\n\
        \x20 2  1  0  0  0  0  0  0  0  0999 V2000\n\
        \x20   0.0000    0.0000    1.2346 N   0  3  0  0  0  0  0  0  0  0  0  0\n\
        \x20  -1.5000    2.2500  100.0000 *   0  0  0  0  0  0  0  0  0  0  0  0\n\
        \x20 1  2  2  0\nM  CHG  1   1   1\nM  END\n> <step>\n7\n\n$$$$\n";
    assert_eq!(write(Format::Sdf, std::slice::from_ref(&f)), expected);
    // Partial charges are no formal charges: not written.
    f.properties[0].values = vec![0.5, -0.5];
    let text = write(Format::Sdf, std::slice::from_ref(&f));
    assert!(
        !text.contains("M  CHG") && text.contains(" N   0  0  0"),
        "{text}"
    );
    // Coordinates past V2000's columns (or touching fields, which RDKit misreads): V3000;
    // nothing is refused.
    for (k, x) in [(0, 100000.0), (1, -1000.0), (2, 10000.0), (0, -3.0e6)] {
        let mut g = f.clone();
        g.properties[0].values = vec![1.0, 0.0];
        g.positions[1][k] = x;
        let text = write(Format::Sdf, std::slice::from_ref(&g));
        assert!(
            text.contains(" V3000\n") && text.contains("M  V30 1 N 0.0000 0.0000 1.2346 0 CHG=1\n"),
            "{text}"
        );
        assert!(text.lines().all(|l| l.len() <= 80), "{text}");
        let back = read(Format::Sdf, &text).remove(0);
        assert_eq!(back.positions[1][k], x, "{text}");
        assert_eq!((back.bonds, back.bond_orders), (g.bonds.clone(), vec![2]));
    }
    let mut g = f.clone();
    g.positions[1] = [99999.99, 9999.99, -999.99];
    assert!(write(Format::Sdf, std::slice::from_ref(&g)).contains(" V2000\n"));
}

// ---- PDB CONECT records (fixtures and references in tests/data/pdb_conect) ----

fn conect_lines(text: &str) -> Vec<&str> {
    text.lines().filter(|l| l.starts_with("CONECT")).collect()
}

/// The bonds our PDB topology reader (CONECT) makes of `text`.
fn pdb_topology_bonds(text: &str) -> Vec<[u32; 2]> {
    texmap_md_io::Topology::from_reader(
        Cursor::new(text.as_bytes().to_vec()),
        texmap_md_io::TopologyFormat::Pdb,
        "out.pdb",
    )
    .unwrap()
    .bonds
}

/// Aspirin from an SDF (bonds with orders), and the solvated peptide of topo_mda.gro with the
/// PSF's bonds, as `texmap convert` gives them to the PDB writer.
fn conect_frames() -> (Frame, Frame) {
    let ligand = read_file("molecules/library.sdf").swap_remove(0);
    assert_eq!(ligand.bonds.len(), 21);
    let mut peptide = read_file("topo_mda.gro").swap_remove(0);
    let t = texmap_md_io::Topology::open(data("psf_parmed.psf")).unwrap();
    t.apply(&mut peptide, "topo_mda.gro", 0).unwrap();
    peptide.bonds = t.bonds.clone();
    assert_eq!(peptide.bonds.len(), 53);
    (ligand, peptide)
}

#[test]
fn pdb_conect_round_trip_through_our_reader_and_the_committed_files() {
    let (ligand, peptide) = conect_frames();
    for (f, file) in [(&ligand, "aspirin.pdb"), (&peptide, "peptide_psf.pdb")] {
        let text = write(Format::Pdb, std::slice::from_ref(f));
        // The references of gen_pdb_conect.py were read from these very bytes.
        let committed = std::fs::read_to_string(data("pdb_conect").join(file)).unwrap();
        assert_eq!(text, committed, "{file}");
        assert_eq!(pdb_topology_bonds(&text), f.bonds, "{file}");
        // The atoms read back as written: the CONECT lines make no frame and no atom.
        let back = read(Format::Pdb, &text);
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].n_atoms(), f.n_atoms());
    }
    // Double bonds repeat their partner: C2=O3 is listed twice from both atoms.
    let text = write(Format::Pdb, std::slice::from_ref(&ligand));
    assert!(text.contains("CONECT    2    1    3    3    4\n"), "{text}");
    assert!(text.contains("CONECT    3    2    2\n"), "{text}");
    // The same bonds with no orders list each partner once.
    let mut single = ligand.clone();
    single.bond_orders.clear();
    let text = write(Format::Pdb, &[single]);
    assert!(text.contains("CONECT    3    2\n"), "{text}");
    assert_eq!(pdb_topology_bonds(&text), ligand.bonds);
}

#[test]
fn pdb_conect_matches_rdkit_mdanalysis_and_gemmi_references() {
    let (ligand, peptide) = conect_frames();
    let text = std::fs::read_to_string(data("pdb_conect/reference.json")).unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    let pairs = |v: &serde_json::Value| -> Vec<[u32; 2]> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|b| [b[0].as_u64().unwrap() as u32, b[1].as_u64().unwrap() as u32])
            .collect()
    };
    let with_orders = |v: &serde_json::Value| -> Vec<(u32, u32, u8)> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|b| {
                let o = b[2].as_f64().unwrap() as u8;
                (
                    b[0].as_u64().unwrap() as u32,
                    b[1].as_u64().unwrap() as u32,
                    o,
                )
            })
            .collect()
    };
    let ours: Vec<(u32, u32, u8)> = ligand
        .bonds
        .iter()
        .zip(&ligand.bond_orders)
        .map(|(b, o)| (b[0], b[1], *o))
        .collect();
    let a = &r["aspirin"];
    // RDKit reads the SDF's bonds and orders from our CONECT records, and so does it the SDF.
    assert_eq!(with_orders(&a["rdkit"]["bonds"]), ours);
    assert_eq!(with_orders(&a["sdf_rdkit_bonds"]), ours);
    assert_eq!(a["rdkit"]["n_atoms"], 21);
    assert_eq!(pairs(&a["mdanalysis_bonds"]), ligand.bonds);
    // gemmi keeps the partners as listed: the double bond C2=O3 twice.
    assert_eq!(a["gemmi_conect"]["2"], serde_json::json!([1, 3, 3, 4]));
    assert_eq!(a["gemmi_conect"].as_object().unwrap().len(), 21);
    let p = &r["peptide"];
    assert_eq!(pairs(&p["psf_bonds"]), peptide.bonds);
    assert_eq!(pairs(&p["mdanalysis_bonds"]), peptide.bonds);
    let rd: Vec<[u32; 2]> = with_orders(&p["rdkit"]["bonds"])
        .into_iter()
        .map(|(i, j, _)| [i, j])
        .collect();
    assert_eq!(rd, peptide.bonds);
    // Byte for byte the CONECT lines MDAnalysis's PDBWriter writes for the same atoms and bonds.
    let mda: Vec<&str> = p["mdanalysis_conect_lines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    let text = write(Format::Pdb, &[peptide]);
    assert_eq!(conect_lines(&text), mda);
}

#[test]
fn pdb_conect_read_live_by_rdkit() {
    let probe = std::process::Command::new("python3")
        .args(["-c", "import rdkit"])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!("SKIPPED: no python3 with rdkit (pip install rdkit); reference.json covers it");
        return;
    }
    let (ligand, _) = conect_frames();
    // Two models: RDKit reads the first, whose block holds the CONECT records.
    let text = write(Format::Pdb, &[ligand.clone(), ligand.clone()]);
    let dir = std::env::temp_dir().join(format!("texmap_conect_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("ligand.pdb");
    std::fs::write(&path, &text).unwrap();
    let script = "import sys\nfrom rdkit import Chem\n\
        m = Chem.MolFromPDBFile(sys.argv[1], removeHs=False, proximityBonding=False, sanitize=False)\n\
        print(m.GetNumAtoms())\n\
        for b in sorted(sorted((b.GetBeginAtomIdx(), b.GetEndAtomIdx())) + [int(b.GetBondTypeAsDouble())] for b in m.GetBonds()):\n\
        \x20   print(*b)\n";
    let o = std::process::Command::new("python3")
        .args(["-c", script])
        .arg(&path)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8(o.stdout).unwrap();
    let mut expected = String::from("21\n");
    for (b, o) in ligand.bonds.iter().zip(&ligand.bond_orders) {
        expected.push_str(&format!("{} {} {o}\n", b[0], b[1]));
    }
    assert_eq!(out, expected);
}

#[test]
fn pdb_conect_layout_models_serials_and_refusals() {
    // Atom 0 bonded to six atoms (two lines), a triple bond 0-1, an aromatic bond 2-3 (once),
    // hybrid-36 serials past 99,999.
    let mut f = Frame::new();
    f.positions = vec![[0.0; 3]; 8];
    f.elements = vec![element("C"); 8];
    f.ids = vec![1, 2, 3, 99_999, 100_000, 100_001, 7, 8];
    f.bonds = vec![
        [0, 1],
        [0, 2],
        [0, 3],
        [0, 4],
        [0, 5],
        [0, 6],
        [2, 3],
        [6, 7],
    ];
    f.bond_orders = vec![3, 1, 1, 1, 1, 1, 4, 0];
    let text = write(Format::Pdb, &[f.clone(), f.clone()]);
    let expected_conect = [
        "CONECT    1    2    2    2    3",
        "CONECT    199999A0000A0001    7",
        "CONECT    2    1    1    1",
        "CONECT    3    199999",
        "CONECT99999    1    3",
        "CONECTA0000    1",
        "CONECTA0001    1",
        "CONECT    7    1    8",
        "CONECT    8    7",
    ];
    assert_eq!(conect_lines(&text), expected_conect);
    // One set, in the first model before its ENDMDL; the second model has none.
    let first_end = text.find("ENDMDL").unwrap();
    let model2 = text.find("MODEL        2").unwrap();
    assert!(text[..first_end].ends_with("CONECT    8    7\n"), "{text}");
    assert!(!text[model2..].contains("CONECT"), "{text}");
    assert!(text.ends_with("ENDMDL\nEND\n"), "{text}");
    assert_eq!(pdb_topology_bonds(&text), f.bonds);
    // Every CONECT line fits 31 columns: serial 7-11, partners 12-31.
    assert!(conect_lines(&text).iter().all(|l| l.len() <= 31));
    // No bonds: no CONECT records (the files of before).
    let mut none = f.clone();
    none.bonds.clear();
    none.bond_orders.clear();
    assert!(!write(Format::Pdb, &[none.clone()]).contains("CONECT"));

    // A later frame with other bonds (or orders) is refused, naming it.
    let refused_second = |a: &Frame, b: &Frame| -> String {
        let mut w = Writer::new(Cursor::new(Vec::new()), Format::Pdb, "out.pdb").unwrap();
        w.write_frame(a).unwrap();
        w.write_frame(b).unwrap_err().to_string()
    };
    let mut other = f.clone();
    other.bonds.pop();
    other.bond_orders.pop();
    let e = refused_second(&f, &other);
    assert!(e.contains("frame 1") && e.contains("bonds differ"), "{e}");
    let mut reordered = f.clone();
    reordered.bond_orders[0] = 2;
    let e = refused_second(&f, &reordered);
    assert!(e.contains("bonds differ"), "{e}");
    let e = refused_second(&none, &f);
    assert!(e.contains("bonds differ"), "{e}");
    // Orders written the same way (aromatic or none as single) are the same bonds.
    let mut same = f.clone();
    same.bond_orders[6] = 1;
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Pdb, "out.pdb").unwrap();
    w.write_frame(&f).unwrap();
    w.write_frame(&same).unwrap();
    // A bonded atom whose serial another atom shares (GRO numbers wrapping) is refused; an
    // unbonded one is not.
    let mut dup = f.clone();
    dup.ids[7] = 3;
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Pdb, "out.pdb").unwrap();
    let e = w.write_frame(&dup).unwrap_err().to_string();
    assert!(
        e.contains("atoms 2 and 7 share the serial number 3") && e.contains("CONECT"),
        "{e}"
    );
    dup.bonds.pop();
    dup.bond_orders.pop();
    dup.bonds.retain(|b| *b != [2, 3] && *b != [0, 2]);
    dup.bond_orders.truncate(dup.bonds.len());
    write(Format::Pdb, &[dup]);
}

// What each writer drops (`Writer::dropped`), checked against the files: a frame carrying every
// kind of data is written to each output and read back with our readers, and the kinds that
// did not come back must be exactly the ones `dropped` names.

/// Every output, as a file name that chooses it (a VASP name chooses POSCAR or XDATCAR).
const OUTPUTS: [(Format, &str); 14] = [
    (Format::Xyz, "out.xyz"),
    (Format::LammpsDump, "out.lammpstrj"),
    (Format::LammpsData, "out.data"),
    (Format::Gro, "out.gro"),
    (Format::Pdb, "out.pdb"),
    (Format::Mmcif, "out.cif"),
    (Format::Dcd, "out.dcd"),
    (Format::Xtc, "out.xtc"),
    (Format::Trr, "out.trr"),
    (Format::Netcdf, "out.nc"),
    (Format::Gsd, "out.gsd"),
    (Format::Vasp, "POSCAR"),
    (Format::Vasp, "XDATCAR"),
    (Format::Sdf, "out.sdf"),
];

/// A frame carrying everything a [`Frame`] holds: velocities, forces, image flags, charges
/// (partial when `partial`, else formal), masses, occupancies, B-factors, a custom property,
/// names, types, residues, chains, segments, radii, colours, bonds with orders (one aromatic
/// when `partial`), the cell, time, step and an energy and a string in the comment. Its atoms lie inside the cell (a GSD wraps atoms
/// into its box and adds the images it moved them by) and every value fits every format's
/// columns.
fn carrying_everything(partial: bool) -> Frame {
    let mut f = Frame::new();
    f.positions = vec![
        [1.5, 2.25, 3.0],
        [2.75, 2.5, 3.5],
        [8.0, 9.5, 10.25],
        [8.75, 10.0, 11.0],
    ];
    f.velocities = vec![
        [0.5, -1.25, 2.0],
        [-0.75, 0.25, 1.5],
        [1.0, 1.0, -1.0],
        [0.125, -0.5, 0.75],
    ];
    f.cell = Some(UnitCell::orthorhombic(20.0, 21.0, 22.0).unwrap());
    f.time = Some(1.5);
    f.step = Some(10);
    f.comment = "energy=-3.5 config_type=\"bulk md\"".into();
    f.names = labels(&["C1", "O1", "N1", "H1"]);
    f.elements = ["C", "O", "N", "H"].map(element).to_vec();
    f.types = labels(&["1", "2", "1", "3"]);
    f.ids = vec![1, 2, 3, 4];
    f.res_names = labels(&["ALA", "ALA", "LIG", "LIG"]);
    f.res_ids = vec![1, 1, 2, 2];
    f.chains = labels(&["A", "A", "B", "B"]);
    f.segments = labels(&["PROT", "PROT", "LIG", "LIG"]);
    f.radii = vec![0.75, 0.5, 0.625, 0.25];
    f.colors = vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.5, 0.5],
    ];
    let charge: [f32; 4] = if partial {
        [-0.375, 0.5, 0.25, -0.375]
    } else {
        [-1.0, 1.0, 0.0, 0.0]
    };
    f.properties = vec![
        property("charge", &charge),
        property("mass", &[12.0, 16.0, 12.0, 1.0]),
        property("fx", &[0.5, -0.25, 1.0, 2.0]),
        property("fy", &[1.5, 0.75, -1.0, 0.5]),
        property("fz", &[-0.5, 0.25, 0.125, 1.0]),
        property("ix", &[0.0, 1.0, -1.0, 0.0]),
        property("iy", &[0.0, 0.0, 2.0, 0.0]),
        property("iz", &[1.0, 0.0, 0.0, -1.0]),
        property("occupancy", &[1.0, 0.5, 0.25, 1.0]),
        property("bfactor", &[10.5, 20.25, 30.0, 40.75]),
        property("grain", &[0.0, 1.0, 1.0, 2.0]),
    ];
    f.bonds = vec![[0, 1], [2, 3]];
    f.bond_orders = if partial { vec![2, 4] } else { vec![2, 1] };
    f
}

/// Writes `frames` to memory as `name` chooses, with what `dropped` named before each frame.
fn write_noting_dropped(
    format: Format,
    name: &str,
    frames: &[Frame],
) -> (Vec<u8>, Vec<Vec<texmap_md_io::Dropped>>) {
    let mut w = Writer::new(Cursor::new(Vec::new()), format, name).unwrap();
    let mut dropped = Vec::new();
    for f in frames {
        dropped.push(w.dropped(f));
        w.write_frame(f).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    (w.finish().unwrap().into_inner(), dropped)
}

fn read_bytes(format: Format, name: &str, bytes: Vec<u8>) -> Vec<Frame> {
    let mut t = Trajectory::from_reader(Cursor::new(bytes), format, name)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t
        .read_next(&mut f)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
    {
        out.push(f.clone());
    }
    out
}

/// What a file holds that our frame readers leave out, read from its bytes into `back`: a
/// PDB's CONECT bonds (our PDB topology reader's), with the orders their repetition gives (a
/// double bond listed twice from each atom, as Open Babel reads them).
fn beyond_the_frame_reader(format: Format, bytes: &[u8], back: &mut Frame) {
    if format != Format::Pdb {
        return;
    }
    let text = String::from_utf8_lossy(bytes);
    let t = texmap_md_io::Topology::from_reader(
        Cursor::new(bytes.to_vec()),
        texmap_md_io::TopologyFormat::Pdb,
        "out.pdb",
    )
    .unwrap();
    back.bonds = t.bonds.clone();
    // Each CONECT partner of atom serial a, counted per bond (serial = index + 1 here).
    let mut count = std::collections::HashMap::<[u32; 2], u8>::new();
    for l in text.lines().filter(|l| l.starts_with("CONECT")) {
        let serial = |k: usize| {
            l.get(6 + 5 * k..11 + 5 * k)
                .map(|f| f.trim().parse::<u32>().unwrap())
        };
        let a = serial(0).unwrap() - 1;
        for k in 1..=4 {
            if let Some(b) = serial(k) {
                *count.entry([a, b - 1]).or_default() += 1;
            }
        }
    }
    back.bond_orders = t.bonds.iter().map(|b| count[b]).collect();
}

/// Whether `b` gives `a` back within `tol` (absolute, plus 1e-5 relative: the text writers'
/// fixed decimals, PDB's 2 for occupancy and B-factor, GRO's 0.001 Å/ps for velocities; TRR's
/// and NetCDF's unit conversions round within a few ulp).
fn within(a: &[f32], b: &[f32], tol: f32) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= tol + 1e-5 * x.abs().max(y.abs()))
}

/// The kinds of data `w` carries that `r`, the frame read back, does not give back, by our
/// own comparison of the two frames.
fn lost(w: &Frame, r: &Frame) -> Vec<texmap_md_io::Dropped> {
    use texmap_md_io::Dropped as D;
    let mut lost = Vec::new();
    let prop = |name: &str, tol: f32| match (w.property(name), r.property(name)) {
        (Some(a), Some(b)) => within(a, b, tol),
        _ => false,
    };
    if !within(
        w.velocities.as_flattened(),
        r.velocities.as_flattened(),
        1e-3,
    ) {
        lost.push(D::Velocities);
    }
    let group = |names: &[&str]| names.iter().all(|n| prop(n, 1e-5));
    if !group(&["fx", "fy", "fz"]) {
        lost.push(D::Forces);
    }
    if !group(&["ix", "iy", "iz"]) {
        lost.push(D::ImageFlags);
    }
    for p in &w.properties {
        if !matches!(p.name.as_str(), "fx" | "fy" | "fz" | "ix" | "iy" | "iz")
            && !prop(&p.name, 0.006)
        {
            lost.push(D::Property(p.name.clone()));
        }
    }
    if r.bonds != w.bonds {
        lost.push(D::Bonds);
    } else if r.bond_orders != w.bond_orders {
        lost.push(D::BondOrders);
    }
    let cell_back = match (w.cell, r.cell) {
        (Some(a), Some(b)) => (0..3).all(|k| {
            (a.lengths()[k] - b.lengths()[k]).abs() < 1e-3
                && (a.angles()[k] - b.angles()[k]).abs() < 1e-3
        }),
        _ => false,
    };
    if !cell_back {
        lost.push(D::Cell);
    }
    if r.names != w.names {
        lost.push(D::Names);
    }
    if r.types != w.types {
        lost.push(D::Types);
    }
    if r.res_names != w.res_names || r.res_ids != w.res_ids {
        lost.push(D::Residues);
    }
    if r.chains != w.chains {
        lost.push(D::Chains);
    }
    if r.segments != w.segments {
        lost.push(D::Segments);
    }
    if !within(&w.radii, &r.radii, 0.0) {
        lost.push(D::Radii);
    }
    if !within(w.colors.as_flattened(), r.colors.as_flattened(), 0.0) {
        lost.push(D::Colors);
    }
    if w.time.is_some() && !matches!((w.time, r.time), (Some(a), Some(b)) if (a - b).abs() < 1e-4) {
        lost.push(D::Time);
    }
    if w.step.is_some() && r.step != w.step {
        lost.push(D::Step);
    }
    if w.comment_pairs().count() > 0
        && w.comment_pairs()
            .any(|(k, v)| r.comment_value(k) != Some(v))
    {
        lost.push(D::CommentValues);
    }
    lost.sort();
    lost
}

/// What `dropped` named for each frame of `frames` written as `name`, and what did not come
/// back when the file was read; `dropped`'s partial charges are compared as the `charge`
/// property (which is what `lost` sees).
fn named_and_lost(
    format: Format,
    name: &str,
    frames: &[Frame],
) -> Vec<(Vec<texmap_md_io::Dropped>, Vec<texmap_md_io::Dropped>)> {
    use texmap_md_io::Dropped as D;
    let (bytes, dropped) = write_noting_dropped(format, name, frames);
    let mut back = read_bytes(format, name, bytes.clone());
    assert_eq!(back.len(), frames.len(), "{name}: frames read back");
    let mut out = Vec::new();
    for ((w, r), dropped) in frames.iter().zip(&mut back).zip(dropped) {
        beyond_the_frame_reader(format, &bytes, r);
        let mut named: Vec<D> = dropped
            .iter()
            .map(|d| match d {
                D::PartialCharges => D::Property("charge".into()),
                d => d.clone(),
            })
            .collect();
        named.sort();
        out.push((named, lost(w, r)));
    }
    out
}

#[test]
fn dropped_names_exactly_what_does_not_come_back_from_each_output() {
    use texmap_md_io::Dropped as D;
    let mut wrong = Vec::new();
    for partial in [true, false] {
        let frame = carrying_everything(partial);
        let mut lost_by = Vec::new();
        for (format, name) in OUTPUTS {
            let (named, lost) = named_and_lost(format, name, std::slice::from_ref(&frame))
                .pop()
                .unwrap();
            if named != lost {
                wrong.push(format!(
                    "{name} (partial charges: {partial}):\n  named by dropped: {named:?}\n  not read back:    {lost:?}"
                ));
            }
            lost_by.push((name, lost));
        }
        // Whatever some output drops, `kept_by` lists exactly the outputs that give it back.
        let mut kinds: Vec<&D> = lost_by.iter().flat_map(|(_, lost)| lost).collect();
        kinds.sort();
        kinds.dedup();
        for d in kinds {
            let kept_by = d.kept_by(&frame);
            assert!(!kept_by.is_empty(), "{d:?}: kept by no output");
            for (name, lost) in &lost_by {
                let known = if name.contains('.') { &name[3..] } else { name };
                if kept_by.contains(&known) == lost.contains(d) {
                    wrong.push(format!(
                        "{d:?}: kept_by {kept_by:?}, and {known} {} it",
                        if lost.contains(d) { "loses" } else { "keeps" }
                    ));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // The SD file names partial charges as such, and keeps formal ones.
    let sdf = Writer::new(Cursor::new(Vec::new()), Format::Sdf, "out.sdf").unwrap();
    assert!(
        sdf.dropped(&carrying_everything(true))
            .contains(&D::PartialCharges)
    );
    let formal = sdf.dropped(&carrying_everything(false));
    assert!(
        !formal
            .iter()
            .any(|d| matches!(d, D::PartialCharges) || *d == D::Property("charge".into()))
    );
    assert_eq!(
        D::PartialCharges.kept_by(&carrying_everything(true)),
        [".xyz", ".lammpstrj", ".data", ".gsd"]
    );
}

/// The cases where what is kept depends on the values or on earlier frames, each checked
/// against the file read back as above.
#[test]
fn dropped_follows_values_and_earlier_frames() {
    use texmap_md_io::Dropped as D;
    let base = carrying_everything(false);
    let with = |edit: &dyn Fn(&mut Frame)| {
        let mut f = base.clone();
        edit(&mut f);
        f
    };
    let cell_b = UnitCell::orthorhombic(25.0, 21.0, 22.0).unwrap();
    // An output, its frames, and per frame the kinds the case is about that it drops.
    type Case = (Format, &'static str, Vec<Frame>, Vec<Vec<D>>);
    let cases: Vec<Case> = vec![
        // A .cif holds the first frame's cell: a later, other cell is lost.
        (
            Format::Mmcif,
            "out.cif",
            vec![base.clone(), base.clone(), with(&|f| f.cell = Some(cell_b))],
            vec![vec![], vec![], vec![D::Cell]],
        ),
        // A DCD keeps evenly spaced steps.
        (
            Format::Dcd,
            "out.dcd",
            [0, 10, 20, 35]
                .map(|s| with(&|f| f.step = Some(s)))
                .to_vec(),
            vec![vec![], vec![], vec![], vec![D::Step]],
        ),
        // A DCD keeps times proportional to the steps (readers compute step × one time
        // step): from step 0, from a later step (a lone first frame sets the time step too),
        // and not a time off the line or one without a step to scale.
        (
            Format::Dcd,
            "out.dcd",
            [(0, 0.0), (10, 0.02), (20, 0.04), (30, 0.07)]
                .map(|(s, t)| with(&|f| (f.step, f.time) = (Some(s), Some(t))))
                .to_vec(),
            vec![vec![], vec![], vec![], vec![D::Time]],
        ),
        (
            Format::Dcd,
            "out.dcd",
            vec![with(&|f| (f.step, f.time) = (Some(500), Some(1.0)))],
            vec![vec![]],
        ),
        (
            Format::Dcd,
            "out.dcd",
            [(500, 1.0), (1000, 2.0), (1500, 3.0)]
                .map(|(s, t)| with(&|f| (f.step, f.time) = (Some(s), Some(t))))
                .to_vec(),
            vec![vec![], vec![], vec![]],
        ),
        (
            Format::Dcd,
            "out.dcd",
            vec![with(&|f| (f.step, f.time) = (None, Some(2.5)))],
            vec![vec![D::Time]],
        ),
        // A PDB segment column holds 4 characters; CONECT repeats no aromatic bond.
        (
            Format::Pdb,
            "out.pdb",
            vec![with(&|f| {
                f.segments = labels(&["PROTEIN", "PROTEIN", "LIG", "LIG"]);
                f.bond_orders = vec![4, 1];
            })],
            vec![vec![D::Segments, D::BondOrders]],
        ),
        // A data file's Masses are positive; its Velocities are the properties vx vy vz,
        // never Å/ps.
        (
            Format::LammpsData,
            "out.data",
            vec![with(&|f| {
                let mass = f.properties.iter_mut().find(|p| p.name == "mass").unwrap();
                mass.values[3] = 0.0;
                for v in ["vx", "vy", "vz"] {
                    f.properties.push(property(v, &[0.5, 1.0, -1.0, 2.0]));
                }
            })],
            vec![vec![D::Velocities, D::Property("mass".into())]],
        ),
        // An XDATCAR's title line is its first frame's: a later frame's energy is lost.
        (
            Format::Vasp,
            "XDATCAR",
            vec![
                base.clone(),
                base.clone(),
                with(&|f| f.comment = "energy=-4.25".into()),
            ],
            vec![vec![], vec![], vec![D::CommentValues]],
        ),
        // LAMMPS types are numbers: labels are numbered (a GSD and an .xyz keep them).
        (
            Format::LammpsDump,
            "out.lammpstrj",
            vec![with(&|f| f.types = labels(&["CT", "OW", "CT", "HW"]))],
            vec![vec![D::Types]],
        ),
        (
            Format::LammpsData,
            "out.data",
            vec![with(&|f| f.types = labels(&["CT", "OW", "CT", "HW"]))],
            vec![vec![D::Types]],
        ),
        (
            Format::Gsd,
            "out.gsd",
            vec![with(&|f| f.types = labels(&["CT", "OW", "CT", "HW"]))],
            vec![vec![]],
        ),
        // A GSD orientation needs all four quaternion components.
        (
            Format::Gsd,
            "out.gsd",
            vec![with(&|f| f.properties.push(property("quatw", &[1.0; 4])))],
            vec![vec![D::Property("quatw".into())]],
        ),
    ];
    for (format, name, frames, expected) in cases {
        let about: Vec<&D> = expected.iter().flatten().collect();
        let results = named_and_lost(format, name, &frames);
        for (k, ((named, lost), want)) in results.into_iter().zip(&expected).enumerate() {
            for d in &about {
                assert_eq!(
                    named.contains(d),
                    want.contains(d),
                    "{name} frame {k}: {d:?} in {named:?}"
                );
            }
            assert_eq!(
                named, lost,
                "{name} frame {k}: named by dropped (left), not read back (right)"
            );
        }
    }
    // Times not proportional to the steps (a run whose clock started before step 0): the
    // first frame's time reads back only until the second frame sets the time step, so the
    // loss is named with the second frame.
    let offset =
        [(100, 5.0), (110, 5.2)].map(|(s, t)| with(&|f| (f.step, f.time) = (Some(s), Some(t))));
    let results = named_and_lost(Format::Dcd, "out.dcd", &offset);
    let time = |v: &Vec<D>| v.contains(&D::Time);
    assert!(!time(&results[0].0) && time(&results[0].1), "{results:?}");
    assert!(time(&results[1].0) && time(&results[1].1), "{results:?}");
}
