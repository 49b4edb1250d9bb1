//! Hand-written inputs for the cases the program-written files do not cover, each checked
//! against values worked out by hand.

use std::io::Cursor;
use texmap_md_io::{Element, Error, Format, Frame, Trajectory};

fn read(text: &str, format: Format) -> Result<Vec<Frame>, Error> {
    let mut t = Trajectory::from_reader(Cursor::new(text.as_bytes().to_vec()), format, "case")?;
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f)? {
        out.push(f.clone());
    }
    Ok(out)
}

fn close(what: &str, expected: f64, actual: f64, tol: f64) {
    assert!(
        (expected - actual).abs() <= tol,
        "{what}: expected {expected}, actual {actual}, tolerance {tol}"
    );
}

#[test]
fn lammps_changing_atom_count_unsorted_ids_type_labels_and_diameter() {
    let text = "\
ITEM: UNITS
real
ITEM: TIME
2000.0
ITEM: TIMESTEP
10
ITEM: NUMBER OF ATOMS
3
ITEM: BOX BOUNDS pp pp pp
0 10
-5 5
0 20
ITEM: ATOMS type diameter vz vy vx xs ys zs id
O 2.0 0.003 0.002 0.001 0.5 0.5 0.5 7
H 1.0 0 0 0 0.1 0.2 0.3 2
Cl 3.0 0 0 0 1.0 0.0 0.25 5
ITEM: TIMESTEP
20
ITEM: NUMBER OF ATOMS
1
ITEM: BOX BOUNDS pp pp pp
0 10
-5 5
0 20
ITEM: ATOMS id type x y z
1 H 1 2 3
";
    let f = read(text, Format::LammpsDump).unwrap();
    assert_eq!(f.len(), 2);
    // Sorted by id: 2 (H), 5 (Cl), 7 (O).
    assert_eq!(f[0].ids, [2, 5, 7]);
    let syms: Vec<&str> = f[0].elements.iter().map(|e| e.symbol()).collect();
    assert_eq!(syms, ["H", "Cl", "O"]);
    // Scaled -> Cartesian with origin (0, -5, 0): H at (1, -3, 6).
    let expect = [[1.0, -3.0, 6.0], [10.0, -5.0, 5.0], [5.0, 0.0, 10.0]];
    for (e, p) in expect.iter().zip(&f[0].positions) {
        for k in 0..3 {
            close("position", e[k], p[k] as f64, 1e-6);
        }
    }
    assert_eq!(f[0].radii, [0.5, 1.5, 1.0]);
    // real units: Å/fs -> Å/ps (x1000), fs -> ps.
    assert_eq!(f[0].velocities[2], [1.0, 2.0, 3.0]);
    close("time", 2.0, f[0].time.unwrap(), 1e-12);
    assert_eq!((f[0].step, f[1].step), (Some(10), Some(20)));
    assert_eq!(f[1].n_atoms(), 1);
    assert_eq!(f[1].positions[0], [1.0, 2.0, 3.0]);
}

#[test]
fn lammps_restricted_triclinic_bounds_with_negative_tilts() {
    // Box: xlo 0 xhi 10, ylo 0 yhi 8, zlo 0 zhi 6, xy = -2, xz = 1, yz = -1.5.
    // Bounding box per the LAMMPS manual: xlo_bound = 0 + min(0, -2, 1, -1) = -2,
    // xhi_bound = 10 + max(0, -2, 1, -1) = 11, ylo_bound = 0 + min(0, -1.5) = -1.5, yhi_bound = 8.
    let text = "\
ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
1
ITEM: BOX BOUNDS xy xz yz pp pp pp
-2 11 -2
-1.5 8 1
0 6 -1.5
ITEM: ATOMS id xs ys zs
1 1 1 1
";
    let f = read(text, Format::LammpsDump).unwrap();
    let c = f[0].cell.unwrap();
    assert_eq!(
        c.matrix(),
        [[10.0, 0.0, 0.0], [-2.0, 8.0, 0.0], [1.0, -1.5, 6.0]]
    );
    assert_eq!(c.origin(), [0.0, 0.0, 0.0]);
    // The far corner a + b + c.
    assert_eq!(f[0].positions[0], [9.0, 6.5, 6.0]);
}

#[test]
fn lammps_errors_name_the_item() {
    let text = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: ATOMS id xs ys zs\n1 0 0 0\n";
    let e = read(text, Format::LammpsDump).unwrap_err();
    // Line 5 starts at byte 41; the column list 12 bytes into it.
    assert_eq!(
        e.to_string(),
        "case: frame 0, line 5, byte 53: expected a box before scaled coordinates, found 'id xs ys zs'"
    );
    let text = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\nITEM: ATOMS id x y z\n1 0 0 0\n2 0 zz 0\n";
    let e = read(text, Format::LammpsDump).unwrap_err();
    assert!(
        e.to_string().starts_with("case: frame 0, line 11, byte "),
        "{e}"
    );
    assert!(
        e.to_string().ends_with("expected a coordinate, found 'zz'"),
        "{e}"
    );
}

#[test]
fn gro_three_number_box_and_no_velocities() {
    let text = "\
Two atoms t= 1.5 step= 30
    2
    1SOL     OW    1   0.100   0.200   0.300
    1SOL    HW1    2  -0.050   1.000  10.000
   2.00000   3.00000   4.00000
";
    let f = read(text, Format::Gro).unwrap();
    assert_eq!(f.len(), 1);
    assert!(f[0].velocities.is_empty());
    assert_eq!(f[0].positions, [[1.0, 2.0, 3.0], [-0.5, 10.0, 100.0]]);
    assert_eq!(
        f[0].cell.unwrap().matrix(),
        [[20.0, 0.0, 0.0], [0.0, 30.0, 0.0], [0.0, 0.0, 40.0]]
    );
    assert_eq!((f[0].time, f[0].step), (Some(1.5), Some(30)));
    assert_eq!(
        f[0].elements,
        [
            Element::from_symbol("O").unwrap(),
            Element::from_symbol("H").unwrap()
        ]
    );
}

#[test]
fn pdb_without_models_is_one_frame_and_placeholder_cell_is_dropped() {
    let text = "\
CRYST1    1.000    1.000    1.000  90.00  90.00  90.00 P 1           1
HETATM    1 ZN    ZN A   1      11.104  13.207   2.100  1.00  0.00
HETATM    2  O   HOH A   2      -1.500   0.000   0.250  1.00  0.00           O
TER
CONECT    1    2
MASTER        0    0    0    0    0    0    0    0    2    0    0    0
END
";
    let f = read(text, Format::Pdb).unwrap();
    assert_eq!(f.len(), 1);
    assert!(f[0].cell.is_none());
    let syms: Vec<&str> = f[0].elements.iter().map(|e| e.symbol()).collect();
    assert_eq!(syms, ["Zn", "O"]);
    assert_eq!(f[0].positions[1], [-1.5, 0.0, 0.25]);
}

#[test]
fn xyz_errors_point_at_the_token() {
    let text = "2\ncomment\nC 0 0 0\nO 1.0 x 2\n";
    let e = read(text, Format::Xyz).unwrap_err();
    // Line 4 starts at byte 18; "x" is 6 bytes into it.
    assert_eq!(
        e.to_string(),
        "case: frame 0, line 4, byte 24: expected 3 coordinates after atom name, found 'x'"
    );
    let e = read("3\ncomment\nC 0 0 0\n", Format::Xyz).unwrap_err();
    assert_eq!(
        e.to_string(),
        "case: frame 0, line 4, byte 18: file ends inside the frame: expected 2 more atom lines"
    );
}
