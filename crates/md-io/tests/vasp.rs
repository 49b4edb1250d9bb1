//! VASP POSCAR / CONTCAR / XDATCAR: files written by ASE and pymatgen (tests/data/vasp/, by
//! gen_vasp.py) read as ASE reads them back, and synthetic files whose answers follow from the
//! format's definition (the scaling factor's three forms, VASP 4 species, a changing cell,
//! velocities, damage).

use std::io::Cursor;
use std::path::{Path, PathBuf};

use serde_json::Value;
use texmap_md_io::{Element, Error, Format, Frame, Trajectory};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/vasp")
        .join(name)
}

fn read_text(text: &str) -> Result<Vec<Frame>, Error> {
    let mut t = Trajectory::from_reader(Cursor::new(text.to_string()), Format::Vasp, "POSCAR")?;
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f)? {
        out.push(f.clone());
    }
    assert_eq!(t.n_frames()?, out.len());
    Ok(out)
}

fn close(a: [f32; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] as f64 - b[k]).abs() < tol)
}

fn symbols(f: &Frame) -> Vec<&str> {
    f.elements.iter().map(|e| e.symbol()).collect()
}

#[test]
fn files_read_as_ase_reads_them() {
    let text = std::fs::read_to_string(data("reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let files = reference.as_object().unwrap();
    assert!(files.len() >= 5, "{} files", files.len());
    for (name, want) in files {
        let mut t = Trajectory::open(data(name)).unwrap();
        assert_eq!(t.format(), Format::Vasp, "{name}");
        let want = want.as_array().unwrap();
        assert_eq!(t.n_frames().unwrap(), want.len(), "{name}");
        let mut f = Frame::new();
        for (k, w) in want.iter().enumerate() {
            assert!(t.read_next(&mut f).unwrap(), "{name} frame {k}");
            let what = format!("{name} frame {k}");
            let els: Vec<&str> = w["symbols"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_str().unwrap())
                .collect();
            assert_eq!(symbols(&f), els, "{what}");
            let cell = f.cell.unwrap().matrix();
            for (r, row) in w["cell"].as_array().unwrap().iter().enumerate() {
                for c in 0..3 {
                    let x = row[c].as_f64().unwrap();
                    assert!((cell[r][c] - x).abs() < 1e-9 * x.abs().max(1.0), "{what}");
                }
            }
            let pos = w["positions"].as_array().unwrap();
            assert_eq!(f.positions.len(), pos.len(), "{what}");
            for (i, p) in pos.iter().enumerate() {
                let p = [0, 1, 2].map(|c| p[c].as_f64().unwrap());
                assert!(
                    close(f.positions[i], p, 2e-5),
                    "{what} atom {i}: {:?} vs {p:?}",
                    f.positions[i]
                );
            }
            match w.get("velocities") {
                Some(v) => {
                    let v = v.as_array().unwrap();
                    assert_eq!(f.velocities.len(), v.len(), "{what}");
                    for (i, p) in v.iter().enumerate() {
                        let p = [0, 1, 2].map(|c| p[c].as_f64().unwrap());
                        assert!(close(f.velocities[i], p, 1e-3), "{what} velocity {i}");
                    }
                }
                None => assert!(f.velocities.is_empty(), "{what}: velocities"),
            }
            if let Some(step) = w.get("step") {
                assert_eq!(f.step, step.as_i64(), "{what}");
            }
        }
        assert!(!t.read_next(&mut f).unwrap(), "{name}");
    }
}

const HEADER: &str = "Si O quartz-ish
   1.0
     4.0 0.0 0.0
     0.0 5.0 0.0
     0.0 0.0 6.0
   Si O
   1 2
";

#[test]
fn the_scaling_factor_scales_the_lattice_and_cartesian_coordinates() {
    // One factor.
    let one = "c\n 2.0\n 1 0 0\n 0 1 0\n 0 0 1\n H\n 2\nDirect\n 0.5 0.25 0\n 0 0 0.5\n";
    let f = &read_text(one).unwrap()[0];
    assert_eq!(f.cell.unwrap().lengths(), [2.0, 2.0, 2.0]);
    assert!(close(f.positions[0], [1.0, 0.5, 0.0], 1e-6));
    assert!(close(f.positions[1], [0.0, 0.0, 1.0], 1e-6));
    // A negative factor is the volume: 27 Å³ from a unit cube, so lengths 3.
    let vol = one.replace(" 2.0\n", " -27\n");
    let f = &read_text(&vol).unwrap()[0];
    let l = f.cell.unwrap().lengths();
    assert!(l.iter().all(|x| (x - 3.0).abs() < 1e-12), "{l:?}");
    assert!(close(f.positions[0], [1.5, 0.75, 0.0], 1e-6));
    // Three factors scale the Cartesian axes, of the lattice and of Cartesian coordinates.
    let three = "c\n 1 2 3\n 1 0 0\n 0 1 0\n 0 0 1\n H\n 1\nCartesian\n 1 1 1\n";
    let f = &read_text(three).unwrap()[0];
    assert_eq!(f.cell.unwrap().lengths(), [1.0, 2.0, 3.0]);
    assert!(close(f.positions[0], [1.0, 2.0, 3.0], 1e-6));
    // `K` is Cartesian too, scaled by the one factor.
    let k = one
        .replace("Direct", "K")
        .replace(" 0.5 0.25 0\n", " 0.5 0.25 0 T F T\n");
    let f = &read_text(&k).unwrap()[0];
    assert!(close(f.positions[0], [1.0, 0.5, 0.0], 1e-6));
}

#[test]
fn species_labels_vasp4_and_selective_dynamics() {
    let text = HEADER.replace("   Si O\n", "   Si_pv/6a2f546d O_s\n")
        + "Selective dynamics\nDirect\n 0 0 0 F F F\n 0.5 0.5 0.5 T T T O\n 0.25 0 0 T T F\n";
    let f = &read_text(&text).unwrap()[0];
    assert_eq!(symbols(f), ["Si", "O", "O"]);
    let types: Vec<&str> = f.types.iter().map(|t| t.as_str()).collect();
    assert_eq!(types, ["Si_pv", "O_s", "O_s"]);
    let names: Vec<&str> = f.names.iter().map(|t| t.as_str()).collect();
    assert_eq!(names, ["Si", "O", "O"]);
    assert_eq!(f.ids, [1, 2, 3]);
    assert_eq!(f.comment, "Si O quartz-ish");
    assert!(close(f.positions[1], [2.0, 2.5, 3.0], 1e-6));
    // VASP 4: no names line; the comment's first words name the species (ASE's convention).
    let v4 = HEADER.replace("   Si O\n", "") + "Direct\n 0 0 0\n 0.5 0.5 0.5\n 0.25 0 0\n";
    let f = &read_text(&v4).unwrap()[0];
    assert_eq!(symbols(f), ["Si", "O", "O"]);
    // ... else the species are unknown elements typed by their order.
    let anon = v4.replace("Si O quartz-ish", "quartz run 7");
    let f = &read_text(&anon).unwrap()[0];
    assert!(f.elements.iter().all(|e| *e == Element::UNKNOWN));
    let types: Vec<&str> = f.types.iter().map(|t| t.as_str()).collect();
    assert_eq!(types, ["1", "2", "2"]);
}

/// An XDATCAR whose cell changes at frame 3: frames 0-2 under the first header, 3-5 under the
/// second, each header written once.
fn two_cells() -> String {
    let mut s = String::new();
    for (h, a) in [(0, 4.0), (1, 8.0)] {
        s += &format!("run\n 1.0\n {a} 0 0\n 0 {a} 0\n 0 0 {a}\n Ar\n 2\n");
        for k in 0..3 {
            let step = 3 * h + k + 1;
            s += &format!("Direct configuration= {step:5}\n 0.{k} 0 0\n 0.5 0.5 0.5\n");
        }
    }
    s
}

#[test]
fn configurations_take_their_header_in_any_order_of_access() {
    let text = two_cells();
    let all = read_text(&text).unwrap();
    assert_eq!(all.len(), 6);
    for (k, f) in all.iter().enumerate() {
        let a = if k < 3 { 4.0 } else { 8.0 };
        assert_eq!(f.cell.unwrap().lengths(), [a; 3], "frame {k}");
        assert_eq!(f.step, Some(k as i64 + 1));
        let x = (k % 3) as f64 / 10.0 * a;
        assert!(close(f.positions[0], [x, 0.0, 0.0], 1e-6), "frame {k}");
    }
    // Random access: the last frame first, then back to the first cell's frames.
    let mut t = Trajectory::from_reader(Cursor::new(text), Format::Vasp, "XDATCAR").unwrap();
    let mut f = Frame::new();
    for k in [5, 1, 4, 2, 0, 3] {
        t.read_frame(k, &mut f).unwrap();
        assert_eq!(f, all[k], "frame {k}");
    }
}

#[test]
fn contcar_velocities_after_lattice_velocities_and_the_md_block() {
    let pos = "Direct\n 0 0 0\n 0.5 0.5 0.5\n 0.25 0 0\n";
    let lattice =
        "Lattice velocities and vectors\n  1\n 0 0 0\n 0 0 0\n 0 0 0\n 4 0 0\n 0 5 0\n 0 0 6\n";
    let vel = " 0.001 0.002 0.003\n -0.001 0 0\n 0 0 0.5\n";
    let md = " 1\n 0.5\n  3\n 0.1 0.2 0.3\n";
    for (extra, direct) in [
        (format!("\n{vel}\n{md}"), false),
        (format!("{lattice}\n{vel}"), false),
        (format!("Cartesian\n{vel}"), false),
        (format!("Direct\n{vel}"), true),
    ] {
        let f = &read_text(&(HEADER.to_string() + pos + &extra)).unwrap()[0];
        assert_eq!(f.velocities.len(), 3, "{extra}");
        // Å/fs to Å/ps; direct velocities are fractions of the lattice vectors per fs.
        let want = if direct {
            [4.0, 10.0, 18.0]
        } else {
            [1.0, 2.0, 3.0]
        };
        assert!(
            close(f.velocities[0], want, 1e-3),
            "{extra}: {:?}",
            f.velocities[0]
        );
    }
    // A POSCAR followed by the MD block alone has no velocities.
    let f = &read_text(&(HEADER.to_string() + pos + "\n" + md)).unwrap()[0];
    assert!(f.velocities.is_empty());
}

#[test]
fn damage_names_the_line_and_what_was_expected() {
    let good = HEADER.to_string() + "Direct\n 0 0 0\n 0.5 0.5 0.5\n 0.25 0 0\n";
    read_text(&good).unwrap();
    let cases = [
        // (replace, with, line, expected text)
        ("   1.0\n", "   0\n", 2, "non-zero scaling factor"),
        ("   1.0\n", "   1 2\n", 2, "one or three scaling factors"),
        (
            "     0.0 5.0 0.0\n",
            "     0.0 5.0\n",
            4,
            "3 lattice vector numbers",
        ),
        (
            "     0.0 0.0 6.0\n",
            "     0.0 0.0 -6.0\n",
            3,
            "right-handed",
        ),
        (
            "   1 2\n",
            "   1\n",
            7,
            "one positive atom count per species",
        ),
        ("   1 2\n", "   1 -2\n", 7, "a positive number of atoms"),
        (" 0.5 0.5 0.5\n", " 0.5 x 0.5\n", 10, "3 coordinates"),
    ];
    for (from, to, line, expected) in cases {
        let bad = good.replacen(from, to, 1);
        let e = read_text(&bad).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!("POSCAR: frame 0, line {line}, byte ")),
            "{to}: {msg}"
        );
        assert!(msg.contains(expected), "{to}: {msg}");
    }
    // A missing atom line is a cut file.
    let cut = good.trim_end_matches(" 0.25 0 0\n");
    let e = read_text(cut).unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().contains("1 more coordinate lines"), "{e}");
    // A configuration with no header before it.
    let e = read_text("Direct configuration=     1\n 0 0 0\n").unwrap_err();
    assert!(e.to_string().contains("a header"), "{e}");
}

#[test]
fn names_and_shapes_tell_the_format() {
    for name in [
        "POSCAR",
        "CONTCAR",
        "XDATCAR",
        "POSCAR_relaxed",
        "contcar.2",
        "x.vasp",
        "XDATCAR.gz",
    ] {
        assert_eq!(
            Format::from_path(Path::new(name)),
            Some(Format::Vasp),
            "{name}"
        );
    }
    assert_eq!(Format::from_path(Path::new("POS.xyz")), Some(Format::Xyz));
    // An extension names the format first.
    let named = Format::from_path(Path::new("XDATCAR_frames.extxyz"));
    assert_eq!(named, Some(Format::Xyz));
    let head = two_cells();
    assert_eq!(Format::from_magic(head.as_bytes()), Some(Format::Vasp));
    // The comment may be a number: still VASP, not XYZ.
    let numbered = head.replacen("run", "12", 1);
    assert_eq!(Format::from_magic(numbered.as_bytes()), Some(Format::Vasp));
    // An XYZ file whose species are atomic numbers is not taken for VASP.
    let xyz = "3\ncomment\n8 0.0 0.0 0.0\n1 0.9 0.0 0.0\n1 -0.2 0.9 0.0\n";
    assert_eq!(Format::from_magic(xyz.as_bytes()), Some(Format::Xyz));
}
