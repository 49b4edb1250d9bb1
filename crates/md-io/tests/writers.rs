//! Our extended-XYZ and LAMMPS dump writers: round trips through our readers, the LAMMPS
//! manual's box bounds computed by hand, exact expected texts, refused frames, and files written
//! by LAMMPS, OVITO and ASE read, written again and read back.

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
