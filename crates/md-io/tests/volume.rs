//! Volumetric readers (`volume::read_volumes`): Gaussian cube and VASP CHGCAR-family files.
//!
//! - Files written by ASE and pymatgen (tests/data/volume, `gen_volume.py`) against what those
//!   programs' own readers give back (`expected.json`): atoms, grid origin and steps, dims, and
//!   per data set the sum, min, max and values at listed points.
//! - Synthetic files for each rule (Bohr and Å axes, DSET_IDS over two lines, NVAL, Fortran
//!   exponents, augmentation occupancies and per-atom moments between grids, gzip, file names),
//!   checked against the values the test wrote.
//! - Damage: every cut and replaced bytes of a small cube and CHGCAR, under a heap cap; hostile
//!   headers; error messages that name the file and the line.

use crate::support;

use std::io::Write;
use std::path::{Path, PathBuf};

use serde_json::Value;
use support::alloc::measure;
use texmap_md_io::volume::{VaspQuantity, Volume, VolumeFormat, read_volumes, read_volumes_from};
use texmap_md_io::{Error, Format, Frame, Trajectory};

const BOHR: f64 = 0.529177210903;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/volume")
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

/// Relative 1e-5 of the value (values are f32 here, f64 in the reference).
fn close_rel(a: f64, b: f64, what: &str) {
    close(a, b, 1e-5 * b.abs().max(1e-30), what);
}

#[test]
fn files_of_ase_and_pymatgen_read_as_their_readers_read_them() {
    let expected: Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("expected.json")).unwrap())
            .unwrap();
    let files = expected.as_object().unwrap();
    assert_eq!(files.len(), 5);
    for (name, want) in files {
        let path = dir().join(name);
        let (frame, sets) = read_volumes(&path).unwrap_or_else(|e| panic!("{e}"));
        // Atoms.
        let symbols: Vec<&str> = want["symbols"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap())
            .collect();
        let got: Vec<&str> = frame.elements.iter().map(|e| e.symbol()).collect();
        assert_eq!(got, symbols, "{name}");
        for (i, p) in want["positions"].as_array().unwrap().iter().enumerate() {
            for (a, x) in f64s(p).into_iter().enumerate() {
                close(
                    frame.positions[i][a] as f64,
                    x,
                    1e-4,
                    &format!("{name} atom {i}"),
                );
            }
        }
        let periodic = want["periodic"].as_bool().unwrap();
        assert_eq!(
            frame.cell.is_some(),
            periodic,
            "{name}: a cell for VASP only"
        );
        // Grid.
        let dims: Vec<usize> = f64s(&want["dims"]).iter().map(|d| *d as usize).collect();
        let origin = f64s(&want["origin"]);
        let sets_want = want["sets"].as_array().unwrap();
        assert_eq!(sets.len(), sets_want.len(), "{name}");
        for (s, (v, w)) in sets.iter().zip(sets_want).enumerate() {
            let what = format!("{name} set {s}");
            assert_eq!(v.dims.to_vec(), dims, "{what}");
            assert_eq!(v.periodic, periodic, "{what}");
            for a in 0..3 {
                close(v.origin[a], origin[a], 1e-6, &what);
                let step = f64s(&want["steps"][a]);
                for (got, want) in v.steps[a].iter().zip(step) {
                    close(*got, want, 1e-6, &format!("{what} step {a}"));
                }
            }
            if let Some(names) = want.get("names") {
                assert_eq!(v.name, names[s].as_str().unwrap(), "{what}");
            } else {
                assert_eq!(v.name, "analytic field, written by ASE", "{what}");
            }
            let sum: f64 = v.data.iter().map(|x| *x as f64).sum();
            let abs_sum = w["abs_sum"].as_f64().unwrap();
            close(
                sum,
                w["sum"].as_f64().unwrap(),
                1e-5 * abs_sum,
                &format!("{what} sum"),
            );
            let (lo, hi) = v.range().unwrap();
            close_rel(
                lo as f64,
                w["min"].as_f64().unwrap(),
                &format!("{what} min"),
            );
            close_rel(
                hi as f64,
                w["max"].as_f64().unwrap(),
                &format!("{what} max"),
            );
            for p in w["samples"].as_array().unwrap() {
                let p = f64s(p);
                let (i, j, k) = (p[0] as usize, p[1] as usize, p[2] as usize);
                close_rel(
                    v.at(i, j, k) as f64,
                    p[3],
                    &format!("{what} at {i} {j} {k}"),
                );
            }
        }
        // The same file as a trajectory: one frame, the same atoms.
        let mut t = Trajectory::open(&path).unwrap();
        let want_format = if name.ends_with(".cube") {
            Format::Cube
        } else {
            Format::Vasp
        };
        assert_eq!(t.format(), want_format, "{name}");
        assert_eq!(t.n_frames().unwrap(), 1, "{name}");
        let mut f = Frame::new();
        assert!(t.read_next(&mut f).unwrap());
        assert_eq!(f.positions, frame.positions, "{name}");
        assert_eq!(f.elements, frame.elements, "{name}");
        assert!(!t.read_next(&mut f).unwrap());
    }
}

/// A density CHGCAR integrates to ρ·V summed over the points / N: the electron count VASP
/// writes is the plain mean of the stored values.
#[test]
fn a_chgcar_density_integrates_to_the_mean_of_the_stored_values() {
    let (frame, sets) = read_volumes(dir().join("CHGCAR_small")).unwrap();
    let v = &sets[0];
    let volume = frame.cell.unwrap().volume();
    let n = v.data.len() as f64;
    let stored_mean = v.data.iter().map(|x| *x as f64 * volume).sum::<f64>() / n;
    close(
        v.integral(),
        stored_mean,
        1e-6 * stored_mean.abs().max(1.0),
        "integral",
    );
    close(
        v.cell_volume() * n,
        volume,
        1e-9,
        "grid cells tile the cell",
    );
}

fn read(text: &str, kind: VolumeFormat, name: &str) -> Result<(Frame, Vec<Volume>), Error> {
    read_volumes_from(text.as_bytes(), kind, name)
}

/// A cube file: two atoms, a 3 x 2 x 2 grid of `per_point` values per point, each `f(i, j, k,
/// s)`; `count` is the signed point count written on each axis line.
fn cube_text(natoms: &str, ids: &str, nval: &str, counts: [i64; 3], steps: [f64; 3]) -> String {
    let per_point = if ids.is_empty() {
        nval.trim().parse::<usize>().unwrap_or(1)
    } else {
        2
    };
    let mut s = format!("first title\nsecond\n{natoms} 0.1 0.2 0.3 {nval}\n");
    for a in 0..3 {
        let mut v = [0.0; 3];
        v[a] = steps[a];
        s += &format!("{} {} {} {}\n", counts[a], v[0], v[1], v[2]);
    }
    s += "8 8.0 1.0 2.0 3.0\n1 0.9 1.5 2.0 3.0\n";
    s += ids;
    let mut k = 0;
    for i in 0..3 {
        for j in 0..2 {
            for z in 0..2 {
                for p in 0..per_point {
                    s += &format!("{:.5E}", f(i, j, z, p));
                    k += 1;
                    s += if k % 6 == 0 { "\n" } else { " " };
                }
            }
        }
    }
    s + "\n"
}

fn f(i: usize, j: usize, k: usize, s: usize) -> f64 {
    (1 + i + 10 * j + 100 * k) as f64 * 1.5e-5 * if s == 0 { 1.0 } else { -2.0 }
}

fn check_values(v: &Volume, s: usize) {
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..3 {
                close_rel(v.at(i, j, k) as f64, f(i, j, k, s), &format!("{i} {j} {k}"));
            }
        }
    }
}

#[test]
fn cube_axes_in_bohr_and_in_angstrom() {
    let bohr = cube_text("2", "", "", [3, 2, 2], [0.5, 0.6, 0.7]);
    let (fb, vb) = read(&bohr, VolumeFormat::Cube, "b.cube").unwrap();
    let ang = cube_text("2", "", "", [-3, -2, -2], [0.5, 0.6, 0.7]);
    let (fa, va) = read(&ang, VolumeFormat::Cube, "a.cube").unwrap();
    for (f, v, unit) in [(&fb, &vb[0], BOHR), (&fa, &va[0], 1.0)] {
        assert_eq!(v.dims, [3, 2, 2]);
        assert!(!v.periodic && f.cell.is_none());
        assert_eq!(v.name, "first title");
        for a in 0..3 {
            close(v.origin[a], [0.1, 0.2, 0.3][a] * unit, 1e-12, "origin");
            close(v.steps[a][a], [0.5, 0.6, 0.7][a] * unit, 1e-12, "step");
        }
        close(f.positions[1][0] as f64, 1.5 * unit, 1e-6, "atom x");
        assert_eq!(f.elements[0].symbol(), "O");
        assert_eq!(f.elements[1].symbol(), "H");
        check_values(v, 0);
    }
    assert_eq!(fb.comment, "first title");
}

#[test]
fn cube_dset_ids_wrapping_onto_a_second_line_give_one_volume_per_orbital() {
    let text = cube_text("-2", "    2   11\n  12\n", "", [3, 2, 2], [0.5, 0.5, 0.5]);
    let (frame, sets) = read(&text, VolumeFormat::Cube, "mo.cube").unwrap();
    assert_eq!(frame.n_atoms(), 2);
    assert_eq!(sets.len(), 2);
    assert_eq!(sets[0].name, "orbital 11");
    assert_eq!(sets[1].name, "orbital 12");
    check_values(&sets[0], 0);
    check_values(&sets[1], 1);
    // NVAL 1 on line 3 is allowed beside DSET_IDS; NVAL 3 is not.
    let one = cube_text("-2", "2 11 12\n", "1", [3, 2, 2], [0.5, 0.5, 0.5]);
    assert_eq!(
        read(&one, VolumeFormat::Cube, "mo.cube").unwrap().1.len(),
        2
    );
    let three = one.replacen(" 1\n", " 3\n", 1);
    let e = read(&three, VolumeFormat::Cube, "mo.cube").unwrap_err();
    assert!(e.to_string().starts_with("mo.cube: frame 0, line 3"), "{e}");
}

#[test]
fn cube_nval_2_gives_two_volumes() {
    let text = cube_text("2", "", "2", [3, 2, 2], [0.5, 0.5, 0.5]);
    let (_, sets) = read(&text, VolumeFormat::Cube, "two.cube").unwrap();
    assert_eq!(sets.len(), 2);
    assert_eq!(
        (sets[0].name.as_str(), sets[1].name.as_str()),
        ("value 1", "value 2")
    );
    check_values(&sets[0], 0);
    check_values(&sets[1], 1);
}

#[test]
fn fortran_exponents_parse_and_a_dropped_e_is_an_error_naming_the_line() {
    let text = cube_text("2", "", "", [3, 2, 2], [0.5, 0.5, 0.5]);
    assert!(
        text.contains("1.50000E-5"),
        "the values are written with E exponents"
    );
    let (_, sets) = read(&text, VolumeFormat::Cube, "e.cube").unwrap();
    close_rel(sets[0].at(0, 0, 0) as f64, 1.5e-5, "E exponent");
    // Fortran drops the E of a three-digit exponent: 1.0-100. Line 9 holds the first values.
    let bad = text.replacen("1.50000E-5", "1.0-100", 1);
    let e = read(&bad, VolumeFormat::Cube, "e.cube").unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("e.cube: frame 0, line 9, byte "), "{msg}");
    assert!(
        msg.contains("Fortran") && msg.ends_with("found '1.0-100'"),
        "{msg}"
    );
    // A value beyond f32 is not finite there: an error too.
    let big = text.replacen("1.50000E-5", "1e39", 1);
    assert!(read(&big, VolumeFormat::Cube, "e.cube").is_err());
}

/// A CHGCAR of 2 atoms on a 2 x 3 x 2 grid: `total` then augmentation occupancies, a line of
/// per-atom moments, the magnetisation and its occupancies; values `g(n, s)` in file order.
fn chgcar_text() -> String {
    let mut s = String::from(
        "test cell\n1.0\n 3.0 0.0 0.0\n 1.0 4.0 0.0\n 0.0 0.5 5.0\nSi C\n1 1\nDirect\n\
         0.0 0.0 0.0\n0.5 0.5 0.5\n\n   2   3   2\n",
    );
    let grid = |s: &mut String, set: usize| {
        for n in 0..12 {
            *s += &format!(" {:.11E}", g(n, set));
            if n % 5 == 4 || n == 11 {
                *s += "\n";
            }
        }
    };
    grid(&mut s, 0);
    s += "augmentation occupancies   1   3\n 0.1 0.2 0.3\naugmentation occupancies   2   3\n\
          0.1 0.2 -0.3E-01\n";
    s += " 0.5000E+00 -0.2500E+00\n   2   3   2\n";
    grid(&mut s, 1);
    s += "augmentation occupancies   1   2\n 0.1 0.2\naugmentation occupancies   2   2\n 0.3 0.4\n";
    s
}

fn g(n: usize, set: usize) -> f64 {
    (n as f64 + 1.0) * if set == 0 { 10.0 } else { -1.0 }
}

#[test]
fn chgcar_grids_around_augmentation_occupancies_and_moments() {
    let text = chgcar_text();
    let (frame, sets) = read(&text, VolumeFormat::Vasp(VaspQuantity::Density), "CHGCAR").unwrap();
    let cell = frame.cell.unwrap();
    close(cell.volume(), 60.0, 1e-12, "cell volume");
    assert_eq!(frame.elements[1].symbol(), "C");
    assert_eq!(frame.positions[1], [2.0, 2.25, 2.5]);
    assert_eq!(sets.len(), 2);
    assert_eq!(sets[0].name, "total density (e/Å³)");
    assert_eq!(sets[1].name, "magnetisation density (e/Å³)");
    for (s, v) in sets.iter().enumerate() {
        assert!(v.periodic);
        assert_eq!(v.dims, [2, 3, 2]);
        assert_eq!(v.origin, [0.0; 3]);
        assert_eq!(v.steps[1], [1.0 / 3.0, 4.0 / 3.0, 0.0]);
        // x fastest, as VASP writes: data index n is the file's n-th value.
        for (n, x) in v.data.iter().enumerate() {
            close_rel(*x as f64, g(n, s) / 60.0, &format!("set {s} value {n}"));
        }
    }
    // The same layout as a LOCPOT and an ELFCAR: values as written.
    let (_, pot) = read(&text, VolumeFormat::Vasp(VaspQuantity::Potential), "LOCPOT").unwrap();
    assert_eq!(pot[1].name, "local potential, spin down (eV)");
    close_rel(pot[0].at(1, 2, 1) as f64, g(11, 0), "potential as written");
    let (_, elf) = read(&text, VolumeFormat::Vasp(VaspQuantity::Elf), "ELFCAR").unwrap();
    assert_eq!(
        (elf[0].name.as_str(), elf[1].name.as_str()),
        ("ELF, spin up", "ELF, spin down")
    );
    // Non-collinear: four grids, x y z magnetisations.
    let mut ncl = text.clone();
    let second = &text[text.rfind("   2   3   2\n").unwrap()..];
    ncl += second;
    ncl += second;
    let (_, four) = read(&ncl, VolumeFormat::Vasp(VaspQuantity::Density), "CHGCAR").unwrap();
    let names: Vec<&str> = four.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "total density (e/Å³)",
            "magnetisation x density (e/Å³)",
            "magnetisation y density (e/Å³)",
            "magnetisation z density (e/Å³)"
        ]
    );
}

#[test]
fn vasp_volumetric_names_and_cube_extensions() {
    use VaspQuantity::*;
    for (name, q) in [
        ("CHGCAR", Some(Density)),
        ("CHGCAR_spin", Some(Density)),
        ("PARCHG.0012.ALLK", Some(Density)),
        ("run1.CHGCAR", Some(Density)),
        ("CHGCAR.vasp", Some(Density)),
        ("CHG", Some(Density)),
        ("AECCAR0", Some(Density)),
        ("AECCAR2.gz", Some(Density)),
        ("LOCPOT", Some(Potential)),
        ("ELFCAR", Some(Elf)),
        ("POSCAR", None),
        ("CHGCARX", None),
        ("notes.txt", None),
    ] {
        let format = VolumeFormat::from_path(Path::new(name));
        assert_eq!(format, q.map(VolumeFormat::Vasp), "{name}");
        if q.is_some() {
            assert_eq!(
                Format::from_path(Path::new(name)),
                Some(Format::Vasp),
                "{name}"
            );
        }
    }
    for name in ["a.cube", "a.CUB", "b.cube.gz"] {
        assert_eq!(
            VolumeFormat::from_path(Path::new(name)),
            Some(VolumeFormat::Cube)
        );
        assert_eq!(
            Format::from_path(Path::new(name)),
            Some(Format::Cube),
            "{name}"
        );
    }
    let e = read_volumes("frame.xyz").unwrap_err();
    assert!(e.to_string().starts_with("frame.xyz: unsupported"), "{e}");
}

#[test]
fn gzip_files_are_read_through() {
    let tmp = std::env::temp_dir().join(format!("texmap-volume-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    for (name, text, n) in [
        (
            "x.cube.gz",
            cube_text("2", "", "", [3, 2, 2], [0.5, 0.5, 0.5]),
            1,
        ),
        ("CHGCAR.gz", chgcar_text(), 2),
        (
            "x.xsf.gz",
            std::fs::read_to_string(dir().join("../xsf/ase_grid_small.xsf")).unwrap(),
            1,
        ),
    ] {
        let path = tmp.join(name);
        let mut z = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(text.as_bytes()).unwrap();
        std::fs::write(&path, z.finish().unwrap()).unwrap();
        let (frame, sets) = read_volumes(&path).unwrap();
        assert_eq!((frame.n_atoms(), sets.len()), (2, n), "{name}");
        let plain = tmp.join(name.trim_end_matches(".gz"));
        std::fs::write(&plain, &text).unwrap();
        assert_eq!(read_volumes(&plain).unwrap().1, sets, "{name}");
    }
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// Reads `text` as a file named as `place` starts, and checks the error message: it starts
/// with `place` and holds each of `parts`.
fn error_names(text: &str, kind: VolumeFormat, place: &str, parts: &[&str]) {
    let name = place.split(':').next().unwrap();
    let msg = read(text, kind, name).unwrap_err().to_string();
    assert!(msg.starts_with(place), "{msg}");
    for p in parts {
        assert!(msg.contains(p), "{msg}");
    }
}

#[test]
fn errors_name_the_file_the_line_and_what_was_expected() {
    let cube = cube_text("2", "", "", [3, 2, 2], [0.5, 0.5, 0.5]);
    // Cut after 10 of the 12 values: the data set, the count expected and found, the end.
    let lines: Vec<&str> = cube.lines().collect();
    let cut = format!("{}\n{}\n", lines[..8].join("\n"), "1.5E-5 ".repeat(10));
    let e = read(&cut, VolumeFormat::Cube, "cut.cube").unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "cut.cube: frame 0, line 10, byte {}: file ends inside the frame: expected 12 \
             values of the grid (3x2x2 points, 1 per point), found 10",
            cut.len()
        )
    );
    // An axis line with a zero count.
    let bad = cube.replacen("2 0 0.5 0", "0 0 0.5 0", 1);
    let expected = ["expected a point count, > 0 (Bohr) or < 0 (Å)"];
    error_names(
        &bad,
        VolumeFormat::Cube,
        "axis.cube: frame 0, line 5, byte ",
        &expected,
    );
    // A CHGCAR whose second grid line differs from the first (line 21, after the moments).
    let text = chgcar_text();
    let k = text.rfind("   2   3   2\n").unwrap();
    let text = format!("{}   2   3   3\n{}", &text[..k], &text[k + 13..]);
    let expected = [
        "the grid dimensions of the next data set",
        "found '2   3   3'",
    ];
    let density = VolumeFormat::Vasp(VaspQuantity::Density);
    error_names(
        &text,
        density,
        "CHGCAR_x: frame 0, line 21, byte ",
        &expected,
    );
    // Junk between grids.
    let junk = chgcar_text().replacen(" 0.5000E+00 -0.2500E+00\n", "hello\n", 1);
    let e = read(&junk, VolumeFormat::Vasp(VaspQuantity::Density), "CHGCAR").unwrap_err();
    assert!(e.to_string().starts_with("CHGCAR: frame 0, line 20"), "{e}");
    // A truncated CHGCAR names the data set.
    let text = chgcar_text();
    let aug = text.rfind("augmentation occupancies   1   2").unwrap();
    let cut = &text[..text[..aug - 1].rfind('\n').unwrap() + 1];
    let e = read(cut, VolumeFormat::Vasp(VaspQuantity::Density), "CHGCAR").unwrap_err();
    assert!(
        e.to_string()
            .contains("12 values of data set 2 (2x3x2 points), found 10"),
        "{e}"
    );
}

#[test]
fn hostile_headers_are_refused_before_any_allocation() {
    let cube = cube_text("2", "", "", [3, 2, 2], [0.5, 0.5, 0.5]);
    let vasp = VolumeFormat::Vasp(VaspQuantity::Density);
    let cases = [
        (
            cube.replacen("2 0.1 0.2 0.3", "2000000000 0.1 0.2 0.3", 1),
            VolumeFormat::Cube,
        ),
        (
            cube.replacen("3 0.5 0 0", "1073741824 0.5 0 0", 1),
            VolumeFormat::Cube,
        ),
        (
            cube.replacen("3 0.5 0 0", "-9223372036854775808 0.5 0 0", 1),
            VolumeFormat::Cube,
        ),
        (
            cube.replacen("0.1 0.2 0.3 ", "0.1 0.2 0.3 1000000000", 1),
            VolumeFormat::Cube,
        ),
        (
            chgcar_text().replacen("   2   3   2\n", "   2000   3000   2000\n", 1),
            vasp,
        ),
        (
            chgcar_text().replacen("   2   3   2\n", "   20   30   20\n", 1),
            vasp,
        ),
        (chgcar_text().replacen("1 1\n", "1 1000000000\n", 1), vasp),
        (
            chgcar_text().replacen("occupancies   1   3", "occupancies   1 999999999", 1),
            vasp,
        ),
    ];
    for (text, kind) in cases {
        let (r, peak) = measure(|| read(&text, kind, "hostile"));
        assert!(r.is_err(), "{text:.200}");
        assert!(
            peak < 2 << 20,
            "{peak} bytes for a {} byte file",
            text.len()
        );
    }
    // With the file's size known, a grid it cannot hold is refused at its header line.
    let tmp = std::env::temp_dir().join(format!("texmap-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let path = tmp.join("CHGCAR");
    std::fs::write(
        &path,
        chgcar_text().replacen("   2   3   2\n", "   200 300 200\n", 1),
    )
    .unwrap();
    let e = read_volumes(&path).unwrap_err();
    assert!(
        e.to_string().contains("line 12") && e.to_string().contains("2^30"),
        "{e}"
    );
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// Start of the file's last number: a cut inside it that leaves a number cannot be told from
/// a file without a final newline.
fn last_token_start(b: &[u8]) -> usize {
    let end = b.iter().rposition(|c| !c.is_ascii_whitespace()).unwrap();
    b[..end]
        .iter()
        .rposition(|c| c.is_ascii_whitespace())
        .unwrap()
        + 1
}

/// Every cut is an error, or reads complete data sets of the whole file: all of a cube's
/// (only a cut inside its last number, which still parses, reads), the first grids of a
/// CHGCAR (a cut after a grid or its occupancies: the rest is optional), the last of them
/// differing only in its last value when the cut leaves that number partial. Replaced bytes
/// give a located error or a read. Neither holds more heap than 64 x the bytes + 1 MiB.
#[test]
fn every_cut_and_replaced_byte_of_a_small_cube_and_chgcar_is_an_error_or_complete_sets() {
    for (name, kind) in [
        ("ase_small.cube", VolumeFormat::Cube),
        ("CHGCAR_small", VolumeFormat::Vasp(VaspQuantity::Density)),
    ] {
        let good = std::fs::read(dir().join(name)).unwrap();
        let (_, all) = read_volumes_from(&good[..], kind, name).unwrap();
        let cap = 64 * good.len() + (1 << 20);
        let last = last_token_start(&good);
        let located = |e: &Error| {
            let at = e.location().unwrap_or_else(|| panic!("{e}"));
            assert!(e.to_string().starts_with(name), "{e}");
            assert!(at.line.is_some() && at.byte.is_some(), "{e}");
        };
        let mut reads = 0;
        for cut in 0..good.len() {
            let (r, peak) = measure(|| read_volumes_from(&good[..cut], kind, name));
            assert!(peak <= cap, "{name} cut at {cut}: {peak} bytes");
            let sets = match r {
                Err(e) => {
                    located(&e);
                    continue;
                }
                Ok((_, sets)) => sets,
            };
            reads += 1;
            let partial = cut > 0 && !good[cut - 1].is_ascii_whitespace();
            let n = sets.len();
            assert!(
                (1..=all.len()).contains(&n),
                "{name} cut at {cut}: {n} sets"
            );
            assert_eq!(sets[..n - 1], all[..n - 1], "{name} cut at {cut}");
            let (a, b) = (&sets[n - 1], &all[n - 1]);
            if a != b {
                let k = b.data.len() - 1;
                assert!(partial, "{name} cut at {cut}: set {n} differs");
                assert_eq!(a.data[..k], b.data[..k], "{name} cut at {cut}");
            }
            if kind == VolumeFormat::Cube {
                assert!(cut > last, "{name} cut at {cut} read");
            }
        }
        assert!(reads > 0, "{name}: the cut inside the last number reads");
        for at in 0..good.len() {
            for junk in [b'x', b'\n', b' ', 0xff] {
                let mut bad = good.clone();
                bad[at] = junk;
                let (r, peak) = measure(|| read_volumes_from(&bad[..], kind, name));
                assert!(peak <= cap, "{name} byte {at}: {peak} bytes");
                if let Err(e) = r {
                    located(&e);
                }
            }
        }
    }
}

/// As a trajectory a cube is one frame, the molecule, even with blank comment lines (which the
/// frame scan passes over); its values are walked, so a damaged one is an error for frame 0.
#[test]
fn a_cube_trajectory_is_one_frame_and_its_damaged_values_an_error() {
    use std::io::Cursor;
    let text = cube_text("2", "", "", [3, 2, 2], [0.5, 0.5, 0.5]);
    let blank = text.replacen("first title\nsecond\n", "\n\n", 1);
    for t in [&text, &blank] {
        let mut traj =
            Trajectory::from_reader(Cursor::new(t.clone()), Format::Cube, "m.cube").unwrap();
        assert_eq!(traj.n_frames().unwrap(), 1);
        let mut f = Frame::new();
        assert!(traj.read_next(&mut f).unwrap());
        assert_eq!(f.n_atoms(), 2);
        assert_eq!(f.positions[1], [1.5, 2.0, 3.0].map(|x| (x * BOHR) as f32));
        assert!(!traj.read_next(&mut f).unwrap());
    }
    let (_, sets) = read(&blank, VolumeFormat::Cube, "m.cube").unwrap();
    assert_eq!(sets[0].name, "values");
    let bad = text.replacen("1.50000E-5", "1.5x", 1);
    let mut traj = Trajectory::from_reader(Cursor::new(bad), Format::Cube, "m.cube").unwrap();
    let e = traj.read_next(&mut Frame::new()).unwrap_err();
    assert!(
        e.to_string().starts_with("m.cube: frame 0, line 9, byte "),
        "{e}"
    );
    // A CHGCAR's damaged grid too, through the VASP reader.
    let bad = chgcar_text().replacen("0.1 0.2 0.3", "0.1 0.x 0.3", 1);
    let mut traj = Trajectory::from_reader(Cursor::new(bad), Format::Vasp, "CHGCAR").unwrap();
    let e = traj.read_next(&mut Frame::new()).unwrap_err();
    assert!(
        e.to_string().starts_with("CHGCAR: frame 0, line 17, byte "),
        "{e}"
    );
}

/// PySCF's electrostatic potential cube of formaldehyde (`gen_esp.py`), interpolated between
/// its grid points, against the potential PySCF evaluates exactly at those points; its density
/// cube lies on the same grid.
#[test]
fn a_pyscf_potential_interpolates_to_pyscfs_exact_values() {
    let want: Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("esp_points.json")).unwrap())
            .unwrap();
    let (atoms, esp) = read_volumes(dir().join("h2co_esp.cube.gz")).unwrap();
    let (_, rho) = read_volumes(dir().join("h2co_density.cube.gz")).unwrap();
    assert_eq!(atoms.n_atoms(), 4);
    let (esp, rho) = (&esp[0], &rho[0]);
    assert_eq!(
        (esp.dims, esp.origin, esp.steps),
        (rho.dims, rho.origin, rho.steps)
    );
    let points = want["points_angstrom"].as_array().unwrap();
    let exact = want["esp_hartree_per_e"].as_array().unwrap();
    let (mut worst, mut far) = (0.0f64, 0);
    for (p, e) in points.iter().zip(exact) {
        let p: [f64; 3] = std::array::from_fn(|a| p[a].as_f64().unwrap());
        let e = e.as_f64().unwrap();
        let got = esp.interpolate(p).expect("inside the grid");
        let near = atoms
            .positions
            .iter()
            .map(|a| {
                (0..3)
                    .map(|k| (a[k] as f64 - p[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        // Where potential maps are drawn (a van der Waals surface, ≥ 1.2 Å from the nuclei)
        // the field is smooth; next to a nucleus its 1/r peak falls between grid points.
        if near >= 1.2 {
            worst = worst.max((got - e).abs());
            far += 1;
        }
    }
    assert!(far >= 15, "{far} points");
    assert!(
        worst < 1e-3,
        "largest interpolation error {worst} hartree/e"
    );
}

// OpenDX files and densities averaged over frames.

fn dynamics() -> PathBuf {
    dir().join("../dynamics")
}

/// The positions of the atoms named `name` in ../dynamics/walk.dcd (names from walk.gro),
/// frame by frame.
fn walk_positions(name: &str) -> Vec<Vec<[f32; 3]>> {
    let mut f = Frame::new();
    let mut gro = Trajectory::open(dynamics().join("walk.gro")).unwrap();
    gro.read_frame(0, &mut f).unwrap();
    let pick: Vec<usize> = (0..f.n_atoms()).filter(|&i| f.names[i] == name).collect();
    let mut dcd = Trajectory::open(dynamics().join("walk.dcd")).unwrap();
    let n = dcd.n_frames().unwrap();
    (0..n)
        .map(|k| {
            dcd.read_frame(k, &mut f).unwrap();
            pick.iter().map(|&i| f.positions[i]).collect()
        })
        .collect()
}

/// MDAnalysis's DensityAnalysis of the walk's OW and NA atoms, written by GridDataFormats
/// (gen_dx.py): our reader gives its grid, and our `DensityMap` of the same frames the same
/// grid and every cell's value (counts equal: a position in another cell would move two
/// values by 1/(frames · cell volume), 400x the tolerance), and counts the NA positions
/// that later frames put outside the grid, which MDAnalysis drops.
#[test]
fn mdanalysis_densities_read_from_its_dx_files_and_equal_ours() {
    use texmap_md_io::density::DensityMap;
    let text = std::fs::read_to_string(dir().join("density_reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    for (key, file, name) in [
        ("ow", "density_ow.dx", "OW"),
        ("na", "density_na.dx.gz", "NA"),
    ] {
        let r = &reference[key];
        let (atoms, sets) = read_volumes(dir().join(file)).unwrap();
        assert_eq!((atoms.n_atoms(), sets.len()), (0, 1), "{file}");
        let theirs = &sets[0];
        assert_eq!(theirs.name, "density");
        assert!(!theirs.periodic);
        let cells: Vec<usize> = f64s(&r["cells"]).iter().map(|&c| c as usize).collect();
        assert_eq!(theirs.dims.to_vec(), cells, "{file}");
        for a in 0..3 {
            // GridDataFormats writes the origin with 6 decimals.
            close(theirs.origin[a], f64s(&r["origin"])[a], 1e-6, "origin");
            close(theirs.steps[a][a], f64s(&r["grid_delta"])[a], 1e-9, "delta");
        }
        let sum: f64 = theirs.data.iter().map(|&v| v as f64).sum();
        close_rel(sum, r["sum"].as_f64().unwrap(), "sum");

        let frames = walk_positions(name);
        let delta = r["delta"].as_f64().unwrap();
        let mut map =
            DensityMap::around(&frames[0], delta, r["padding"].as_f64().unwrap()).unwrap();
        let outside: u64 = frames.iter().map(|p| map.add(p.iter().copied())).sum();
        assert_eq!(outside, r["outside"].as_u64().unwrap(), "{key}");
        assert_eq!(map.outside(), outside);
        assert_eq!(map.frames() as u64, r["frames"].as_u64().unwrap());
        let (lo, hi) = map.bounds();
        for a in 0..3 {
            close(lo[a], f64s(&r["lo"])[a], 1e-5, "lower edge");
            close(hi[a], f64s(&r["hi"])[a], 1e-5, "upper edge");
        }
        let ours = map.to_volume("density");
        assert_eq!(ours.dims, theirs.dims);
        for a in 0..3 {
            close(ours.origin[a], theirs.origin[a], 1e-5, "origin");
        }
        let unit = 1.0 / (frames.len() as f64 * delta.powi(3));
        for (i, (a, b)) in ours.data.iter().zip(&theirs.data).enumerate() {
            close(
                *a as f64,
                *b as f64,
                unit / 400.0,
                &format!("{key} cell {i}"),
            );
        }
        let counted = ours.data.iter().map(|&v| v as f64).sum::<f64>() / unit;
        close(
            counted,
            r["counted"].as_f64().unwrap(),
            1e-3,
            "positions counted",
        );
    }
}

/// Our OpenDX file reads back to the same volume (values to the bit), and GridDataFormats,
/// which MDAnalysis, APBS tools and PyMOL users read DX files with, reads it as we wrote it
/// (SKIPPED without python3 and gridData).
#[test]
fn written_dx_files_read_back_here_and_in_griddataformats() {
    use texmap_md_io::density::DensityMap;
    use texmap_md_io::volume::write_dx;
    let frames = walk_positions("OW");
    let mut map = DensityMap::around(&frames[0], 0.7, 1.0).unwrap();
    for p in &frames {
        map.add(p.iter().copied());
    }
    let mut v = map.to_volume("OW density");
    // Values that need an exponent, and a negative one, round-trip too.
    v.data[5] = 1.25e-9;
    v.data[6] = -3.5e8;
    let mut text = Vec::new();
    write_dx(&v, &["texmap test", "second comment"], &mut text).unwrap();
    let (_, back) = read_volumes_from(&text[..], VolumeFormat::Dx, "ours.dx").unwrap();
    assert_eq!(back[0].data, v.data);
    assert_eq!(back[0].dims, v.dims);
    for a in 0..3 {
        close(back[0].origin[a], v.origin[a], 5e-8, "origin");
        assert_eq!(back[0].steps[a], v.steps[a]);
    }
    let tmp = std::env::temp_dir().join(format!("texmap-dx-{}.dx", std::process::id()));
    std::fs::write(&tmp, &text).unwrap();
    let has_griddata = std::process::Command::new("python3")
        .args(["-c", "import gridData"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_griddata {
        std::fs::remove_file(&tmp).unwrap();
        eprintln!("SKIPPED: python3 with gridData (GridDataFormats) is not available");
        return;
    }
    let script = "import sys, gridData\n\
                  g = gridData.Grid(sys.argv[1])\n\
                  d = g.delta if g.delta.ndim == 1 else g.delta.diagonal()\n\
                  print(*g.grid.shape, *g.origin, *d, g.grid[1, 2, 3], g.grid.sum())";
    let out = std::process::Command::new("python3")
        .args(["-c", script])
        .arg(&tmp)
        .output()
        .unwrap();
    std::fs::remove_file(&tmp).unwrap();
    assert!(
        out.status.success(),
        "gridData could not read our file: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got: Vec<f64> = String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(got[..3], v.dims.map(|d| d as f64));
    for a in 0..3 {
        close(got[3 + a], v.origin[a], 5e-8, "gridData origin");
        close(got[6 + a], v.steps[a][a], 1e-12, "gridData delta");
    }
    // gridData reads the shortest decimal that gives our f32, in f64.
    let x = v.at(1, 2, 3) as f64;
    close(got[9], x, 1e-7 * x.abs(), "gridData value");
    let sum: f64 = v.data.iter().map(|&x| x as f64).sum();
    close_rel(got[10], sum, "gridData sum");
}

/// f(i, j, k) = i + 10 j + 100 k − 0.5 on a 3 x 2 x 2 grid, in the C order DX files use.
fn dx_values() -> Vec<f64> {
    let mut v = Vec::new();
    for i in 0..3 {
        for j in 0..2 {
            for k in 0..2 {
                v.push(i as f64 + 10.0 * j as f64 + 100.0 * k as f64 - 0.5);
            }
        }
    }
    v
}

/// The layout APBS writes (its comments, `%e` values, unquoted type, its field name).
fn apbs_text() -> String {
    let values: Vec<String> = dx_values().iter().map(|v| format!("{v:.6e}")).collect();
    let rows: Vec<String> = values.chunks(3).map(|c| c.join(" ")).collect();
    format!(
        "# Data from APBS 3.4.1\n#\n# POTENTIAL (kT/e)\n#\n\
         object 1 class gridpositions counts 3 2 2\n\
         origin -1.000000e+00 -5.000000e-01 2.500000e-01\n\
         delta 5.000000e-01 0.000000e+00 0.000000e+00\n\
         delta 0.000000e+00 5.000000e-01 0.000000e+00\n\
         delta 0.000000e+00 0.000000e+00 2.500000e-01\n\
         object 2 class gridconnections counts 3 2 2\n\
         object 3 class array type double rank 0 items 12 data follows\n\
         {}\n\
         attribute \"dep\" string \"positions\"\n\
         object \"regular positions regular connections\" class field\n\
         component \"positions\" value 1\ncomponent \"connections\" value 2\n\
         component \"data\" value 3\n",
        rows.join("\n")
    )
}

#[test]
fn dx_layouts_of_apbs_and_vmd_read_in_c_order_with_skewed_steps() {
    let (atoms, sets) = read(&apbs_text(), VolumeFormat::Dx, "pot.dx").unwrap();
    assert_eq!((atoms.n_atoms(), sets.len()), (0, 1));
    let v = &sets[0];
    assert_eq!(v.dims, [3, 2, 2]);
    assert_eq!(v.origin, [-1.0, -0.5, 0.25]);
    assert_eq!(v.name, "regular positions regular connections");
    for i in 0..3 {
        for j in 0..2 {
            for k in 0..2 {
                let want = i as f64 + 10.0 * j as f64 + 100.0 * k as f64 - 0.5;
                assert_eq!(v.at(i, j, k) as f64, want, "({i}, {j}, {k})");
            }
        }
    }
    assert_eq!(v.point(1, 1, 1), [-0.5, 0.0, 0.5]);
    // VMD's volmap: one value per line, skewed steps, no trailer at all.
    let values: Vec<String> = dx_values().iter().map(|v| v.to_string()).collect();
    let vmd = format!(
        "# Data calculated by the VMD volmap function\n\
         object 1 class gridpositions counts 3 2 2\norigin 0 0 0\n\
         delta 0.5 0 0\ndelta 0.25 0.5 0\ndelta 0 0.1 0.4\n\
         object 2 class gridconnections counts 3 2 2\n\
         object 3 class array type float rank 0 items 12 data follows\n{}\n",
        values.join("\n")
    );
    let w = &read(&vmd, VolumeFormat::Dx, "vmd.dx").unwrap().1[0];
    assert_eq!(w.name, "values");
    assert_eq!(w.data, v.data);
    assert_eq!(w.point(1, 1, 1), [0.75, 0.6, 0.4]);
    assert_eq!(
        VolumeFormat::from_path(Path::new("apbs.pqr.dx")),
        Some(VolumeFormat::Dx)
    );
    assert_eq!(
        VolumeFormat::from_path(Path::new("map.DX.gz")),
        Some(VolumeFormat::Dx)
    );
}

#[test]
fn dx_files_we_do_not_read_are_errors_naming_the_line() {
    let apbs = apbs_text();
    let array = "object 3 class array type double rank 0 items 12 data follows";
    let cases: Vec<(String, &str, &[&str])> = vec![
        (
            apbs.replace(
                array,
                "object 3 class array type float rank 0 items 12 ieee msb data follows",
            ),
            "x.dx: frame 0, line 11",
            &["binary"],
        ),
        (
            apbs.replace(
                array,
                "object 3 class array type float rank 1 shape 3 items 12 data follows",
            ),
            "x.dx: frame 0, line 11",
            &["rank 0"],
        ),
        (
            apbs.replace(
                array,
                "object 3 class array type double rank 0 items 13 data follows",
            ),
            "x.dx: frame 0, line 11",
            &["as many items"],
        ),
        (
            apbs.replace(
                array,
                "object 3 class array type double rank 0 items 12 data file pot.bin",
            ),
            "x.dx: frame 0, line 11",
            &["data follows"],
        ),
        (
            apbs.replace("gridpositions counts 3 2 2", "gridpositions counts 3 2"),
            "x.dx: frame 0, line 5",
            &["three point counts"],
        ),
        (
            apbs.replace(
                "gridconnections counts 3 2 2",
                "gridconnections counts 3 2 3",
            ),
            "x.dx: frame 0, line 10",
            &["gridconnections counts equal"],
        ),
        (
            apbs.replace("origin -1.000000e+00", "origin nan"),
            "x.dx: frame 0, line 6",
            &["origin"],
        ),
        (
            apbs.replace("attribute", "1.0\nattribute"),
            "x.dx: frame 0, line 16",
            &["after the data"],
        ),
        (
            apbs.replace("object 1 class", "object 1 klass"),
            "x.dx: frame 0, line 5",
            &["class"],
        ),
        (
            apbs.replace("delta 0.000000e+00 0.000000e+00 2.500000e-01\n", ""),
            "x.dx",
            &["three delta lines"],
        ),
    ];
    for (text, place, parts) in cases {
        error_names(&text, VolumeFormat::Dx, place, parts);
    }
    // A cut inside the values: the data set, the values expected and found.
    let cut: String = apbs.lines().take(13).collect::<Vec<_>>().join("\n");
    let e = read(&cut, VolumeFormat::Dx, "cut.dx").unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(
        e.to_string().contains("12 values") && e.to_string().contains("found 6"),
        "{e}"
    );
    // Every cut is an error or the whole grid (a cut in the trailer, or inside the last value,
    // which still parses).
    let bytes = apbs.as_bytes();
    let whole = read(&apbs, VolumeFormat::Dx, "x.dx").unwrap().1[0]
        .data
        .clone();
    for n in 0..bytes.len() {
        let text = String::from_utf8_lossy(&bytes[..n]).into_owned();
        if let Ok((_, sets)) = read(&text, VolumeFormat::Dx, "x.dx") {
            let got = &sets[0].data;
            let last = whole.len() - 1;
            assert_eq!(got[..last], whole[..last], "cut at {n}");
        }
    }
    // Hostile counts are refused before anything is reserved for them.
    for counts in ["100000 100000 100000", "1000 1000 1000"] {
        let text = apbs.replace(
            "gridpositions counts 3 2 2",
            &format!("gridpositions counts {counts}"),
        );
        let (r, peak) = measure(|| read(&text, VolumeFormat::Dx, "hostile.dx"));
        assert!(r.is_err(), "{counts}");
        assert!(peak < 2 << 20, "{peak} bytes for counts {counts}");
    }
}

// CCP4 / MRC maps.

/// Maps written by mrcfile (gen_mrc.py) read as GridDataFormats reads them: the same grid
/// shape, origin (ORIGIN plus NSTART along the axes MAPC/MAPR/MAPS name) and voxel size,
/// and every value, for float32, big-endian int16 with permuted axes and an extended header,
/// uint16 and float16.
#[test]
fn mrcfile_maps_read_as_griddataformats_reads_them() {
    let text = std::fs::read_to_string(dir().join("mrc_reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    for name in [
        "emd_float.mrc",
        "ccp4_int16_be.map",
        "uint16_half.mrc",
        "half_float.mrc",
    ] {
        let r = &reference[name];
        let (atoms, sets) = read_volumes(dir().join(name)).unwrap();
        assert_eq!((atoms.n_atoms(), sets.len()), (0, 1), "{name}");
        let v = &sets[0];
        let shape: Vec<usize> = f64s(&r["shape"]).iter().map(|&n| n as usize).collect();
        assert_eq!(v.dims.to_vec(), shape, "{name}");
        for a in 0..3 {
            close(v.origin[a], f64s(&r["origin"])[a], 1e-6, name);
            for b in 0..3 {
                let want = if a == b { f64s(&r["delta"])[a] } else { 0.0 };
                close(v.steps[a][b], want, 1e-9, name);
            }
        }
        let values = f64s(&r["values"]);
        let [nx, ny, nz] = v.dims;
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let want = values[(i * ny + j) * nz + k];
                    // serde_json parses the shortest decimal to within an ulp of f64.
                    let got = v.at(i, j, k) as f64;
                    close(
                        got,
                        want,
                        1e-12 * want.abs(),
                        &format!("{name} ({i}, {j}, {k})"),
                    );
                }
            }
        }
    }
    let (_, sets) = read_volumes(dir().join("emd_float.mrc")).unwrap();
    assert_eq!(
        sets[0].name,
        "texmap test map: f(x, y, z) at the grid points"
    );
    // f at a point between the grid's points, by trilinear interpolation.
    let f = |p: [f64; 3]| (0.3 * p[0]).sin() + 0.05 * p[1] * p[1] - 0.1 * p[2] + 0.02 * p[0] * p[2];
    let p = [20.0, 10.0, 15.0];
    close(
        sets[0].interpolate(p).unwrap(),
        f(p),
        0.05,
        "interpolated f",
    );
}

/// An oblique cell's axes (γ = 60°): b in the xy plane at 60° from a.
#[test]
fn an_oblique_mrc_cell_gives_skewed_steps() {
    let mut bytes = std::fs::read(dir().join("emd_float.mrc")).unwrap();
    bytes[60..64].copy_from_slice(&60.0f32.to_le_bytes());
    let (_, sets) = read_volumes_from(&bytes[..], VolumeFormat::Mrc, "oblique.mrc").unwrap();
    let s = sets[0].steps;
    close(s[1][0], 1.5 * 0.5, 1e-9, "b step x");
    close(s[1][1], 1.5 * 3f64.sqrt() / 2.0, 1e-9, "b step y");
    assert_eq!(s[0], [1.25, 0.0, 0.0]);
    close(s[2][2], 0.75, 1e-9, "c step z");
}

/// Every cut of a map is an error (with the file's length known, before any value is read;
/// streamed, at the cut); hostile and wrong header fields are errors naming their byte.
#[test]
fn damaged_mrc_maps_are_errors_naming_the_byte() {
    let whole = std::fs::read(dir().join("ccp4_int16_be.map")).unwrap();
    let tmp = std::env::temp_dir().join(format!("texmap-mrc-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let path = tmp.join("cut.map");
    for n in (0..whole.len()).step_by(7).chain([whole.len() - 1]) {
        std::fs::write(&path, &whole[..n]).unwrap();
        let e = read_volumes(&path).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "cut at {n}: {e}");
        let e = read_volumes_from(&whole[..n], VolumeFormat::Mrc, "cut.map").unwrap_err();
        assert!(
            matches!(e, Error::Truncated { .. }),
            "streamed cut at {n}: {e}"
        );
    }
    std::fs::remove_dir_all(&tmp).unwrap();
    let float = std::fs::read(dir().join("emd_float.mrc")).unwrap();
    let patched = |at: usize, bytes: [u8; 4]| {
        let mut b = float.clone();
        b[at..at + 4].copy_from_slice(&bytes);
        b
    };
    let cases = [
        (patched(12, 3i32.to_le_bytes()), "byte 12", "MODE"),
        (patched(64, 2i32.to_le_bytes()), "byte 64", "MAPC"),
        (patched(4, 0i32.to_le_bytes()), "byte 4", "counts"),
        (patched(40, (-1.0f32).to_le_bytes()), "byte 40", "lengths"),
        (patched(196, f32::NAN.to_le_bytes()), "byte 196", "ORIGIN"),
        (
            patched(1024 + 400, f32::INFINITY.to_le_bytes()),
            "byte 1424",
            "finite",
        ),
        (patched(92, (-8i32).to_le_bytes()), "byte 92", "NSYMBT"),
        (patched(92, 1_000_000i32.to_le_bytes()), "byte", "NSYMBT"),
    ];
    for (bytes, place, what) in cases {
        let e = read_volumes_from(&bytes[..], VolumeFormat::Mrc, "bad.mrc")
            .unwrap_err()
            .to_string();
        assert!(e.contains(place) && e.contains(what), "{e}");
    }
    // Counts of 2^20 along each axis: refused before anything is reserved for them.
    let mut huge = float.clone();
    for k in 0..3 {
        huge[4 * k..4 * k + 4].copy_from_slice(&(1i32 << 20).to_le_bytes());
    }
    let (r, peak) = measure(|| read_volumes_from(&huge[..], VolumeFormat::Mrc, "huge.mrc"));
    assert!(r.is_err());
    assert!(peak < 2 << 20, "{peak} bytes");
    // 2^9 each (2^27 points, allowed) on a short stream: read as far as it goes.
    for k in 0..3 {
        huge[4 * k..4 * k + 4].copy_from_slice(&(1i32 << 9).to_le_bytes());
    }
    let (r, peak) = measure(|| read_volumes_from(&huge[..], VolumeFormat::Mrc, "huge.mrc"));
    assert!(matches!(r, Err(Error::Truncated { .. })));
    assert!(peak < 4 << 20, "{peak} bytes");
    assert_eq!(
        VolumeFormat::from_path(Path::new("emd_1234.map.gz")),
        Some(VolumeFormat::Mrc)
    );
}

/// Every byte of a small MRC map and an APBS-layout DX file replaced by a few values: each
/// read is a located error or a grid, never a panic, and holds at most 64x the file's bytes
/// + 1 MiB of heap.
#[test]
fn replaced_bytes_of_mrc_and_dx_files_are_errors_or_grids() {
    let mrc = std::fs::read(dir().join("ccp4_int16_be.map")).unwrap();
    let dx = apbs_text().into_bytes();
    for (bytes, kind, name) in [
        (mrc, VolumeFormat::Mrc, "m.map"),
        (dx, VolumeFormat::Dx, "p.dx"),
    ] {
        let (mut read_ok, mut errors) = (0, 0);
        for i in 0..bytes.len() {
            for v in [0u8, 0x7f, 0xff, b'9', b' '] {
                if bytes[i] == v {
                    continue;
                }
                let mut b = bytes.clone();
                b[i] = v;
                let (r, peak) = measure(|| read_volumes_from(&b[..], kind, name));
                assert!(
                    peak < 64 * b.len() + (1 << 20),
                    "{name}: byte {i} = {v}: {peak} bytes of heap"
                );
                match r {
                    Ok((_, sets)) => {
                        assert_eq!(sets.len(), 1);
                        read_ok += 1;
                    }
                    Err(e) => {
                        assert!(e.to_string().starts_with(name), "{e}");
                        errors += 1;
                    }
                }
            }
        }
        eprintln!("{name}: {read_ok} mutants read, {errors} errors");
        assert!(
            read_ok > 0 && errors > 0,
            "{name}: {read_ok} read, {errors} errors"
        );
    }
}
