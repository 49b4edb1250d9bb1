//! LAMMPS data files written by our writer, against what LAMMPS itself made of them and what
//! ASE writes for the same crystal (tests/data/lammps_write/gen_lammps_write.py: LAMMPS 29 Sep
//! 2021 read each file with `read_data` and wrote it back with `write_data`).

use std::io::Read;
use texmap_md_io::{Format, Frame, UnitCell, Writer};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/lammps_write")
        .join(name)
}

fn read(path: &std::path::Path) -> Frame {
    let mut t = texmap_md_io::Trajectory::open(path).unwrap_or_else(|e| panic!("{e}"));
    let mut f = Frame::new();
    t.read_frame(0, &mut f).unwrap_or_else(|e| panic!("{e}"));
    f
}

const CASES: [&str; 5] = ["nacl", "cod", "nisb", "peptide", "caffeine"];

fn file(dir: &str, case: &str) -> std::path::PathBuf {
    let gz = data(&format!("{dir}/{case}.data.gz"));
    if gz.exists() {
        gz
    } else {
        data(&format!("{dir}/{case}.data"))
    }
}

/// `frame`'s positions with its image flags (`ix iy iz`) undone.
fn unwrapped(frame: &Frame) -> Vec<[f64; 3]> {
    let m = frame.cell.unwrap().matrix();
    let flag = |name: &str| frame.property(name).map(|v| v.to_vec());
    let (ix, iy, iz) = (flag("ix"), flag("iy"), flag("iz"));
    frame
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let n = [&ix, &iy, &iz].map(|f| f.as_ref().map_or(0.0, |v| v[i] as f64));
            std::array::from_fn(|k| p[k] as f64 + n[0] * m[0][k] + n[1] * m[1][k] + n[2] * m[2][k])
        })
        .collect()
}

fn sorted_bonds(f: &Frame) -> Vec<[u32; 2]> {
    let mut b = f.bonds.clone();
    b.sort_unstable();
    b
}

#[test]
fn lammps_reads_our_files_as_we_wrote_them() {
    for case in CASES {
        let ours = read(&file("written", case));
        let lammps = read(&file("lammps", case));
        let n = ours.n_atoms();
        assert_eq!(lammps.n_atoms(), n, "{case}");
        assert_eq!(lammps.types, ours.types, "{case}: types");
        assert_eq!(lammps.res_ids, ours.res_ids, "{case}: molecule ids");
        assert_eq!(sorted_bonds(&lammps), sorted_bonds(&ours), "{case}: bonds");
        for p in ["charge", "mass"] {
            assert_eq!(lammps.property(p), ours.property(p), "{case}: {p}");
        }
        // The box LAMMPS set up is the one we wrote.
        let (a, b) = (ours.cell.unwrap(), lammps.cell.unwrap());
        let (ma, mb) = (a.matrix(), b.matrix());
        for r in 0..3 {
            for c in 0..3 {
                assert!(
                    (ma[r][c] - mb[r][c]).abs() <= 1e-9 * 50.0,
                    "{case}: {ma:?} {mb:?}"
                );
            }
            assert!((a.origin()[r] - b.origin()[r]).abs() <= 1e-9, "{case}");
        }
        // Every atom where we put it, once LAMMPS's remapping into the box is undone.
        let (pa, pb) = (unwrapped(&ours), unwrapped(&lammps));
        for i in 0..n {
            for k in 0..3 {
                assert!(
                    (pa[i][k] - pb[i][k]).abs() <= 2e-5,
                    "{case}: atom {i}: ours {:?}, LAMMPS {:?}",
                    pa[i],
                    pb[i]
                );
            }
        }
    }
}

#[test]
fn every_case_has_the_style_its_frame_calls_for() {
    // Masses are written with their elements as comments, which LAMMPS drops and our reader
    // takes the elements from.
    for (case, style) in [
        ("nacl", "atomic"),
        ("cod", "atomic"),
        ("peptide", "full"),
        ("caffeine", "molecular"),
    ] {
        let mut text = String::new();
        let path = file("written", case);
        if path.extension().is_some_and(|e| e == "gz") {
            flate2::read::GzDecoder::new(std::fs::File::open(&path).unwrap())
                .read_to_string(&mut text)
                .unwrap();
        } else {
            text = std::fs::read_to_string(&path).unwrap();
        }
        assert!(text.contains(&format!("\nAtoms # {style}\n")), "{case}");
        let f = read(&path);
        assert!(!f.elements.is_empty(), "{case}");
    }
}

#[test]
fn a_rotated_cell_is_placed_as_ase_places_it() {
    // The POSCAR's lattice is not LAMMPS's restricted form: ASE's Prism and our writer rotate
    // it the same way (a along x, b in the xy plane).
    let ours = read(&file("written", "nacl"));
    let ase = read(&data("nacl_ase.data"));
    let (ma, mb) = (ours.cell.unwrap().matrix(), ase.cell.unwrap().matrix());
    for r in 0..3 {
        for c in 0..3 {
            assert!((ma[r][c] - mb[r][c]).abs() <= 1e-6, "{ma:?} {mb:?}");
        }
    }
    assert_eq!(ours.n_atoms(), ase.n_atoms());
    for (p, q) in ours.positions.iter().zip(&ase.positions) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() <= 2e-5, "{p:?} {q:?}");
        }
    }
    assert_eq!(ours.elements, ase.elements);
    // And the rotation kept the crystal: every distance of the POSCAR is in the data file.
    let poscar = read(&data("nacl_primitive.vasp"));
    let d = |f: &Frame, i: usize, j: usize| {
        (0..3)
            .map(|k| (f.positions[i][k] - f.positions[j][k]).powi(2))
            .sum::<f32>()
            .sqrt()
    };
    for i in 0..poscar.n_atoms() {
        for j in 0..i {
            assert!((d(&poscar, i, j) - d(&ours, i, j)).abs() < 1e-4);
        }
    }
}

fn written(frames: &[Frame]) -> Result<String, texmap_md_io::Error> {
    let mut w = Writer::new(
        std::io::Cursor::new(Vec::new()),
        Format::LammpsData,
        "t.data",
    )?;
    for f in frames {
        w.write_frame(f)?;
    }
    Ok(String::from_utf8(w.finish()?.into_inner()).unwrap())
}

fn two_atoms() -> Frame {
    let mut f = Frame::new();
    f.positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    f.elements = vec![texmap_md_io::Element::from_symbol("C").unwrap(); 2];
    f.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
    f
}

#[test]
fn what_a_data_file_cannot_hold_is_refused() {
    let f = two_atoms();
    assert!(written(std::slice::from_ref(&f)).is_ok());
    let e = written(&[f.clone(), f.clone()]).unwrap_err().to_string();
    assert!(e.contains("one configuration"), "{e}");
    // One type, two masses.
    let mut g = f.clone();
    g.properties.push(texmap_md_io::Property {
        name: "mass".into(),
        values: vec![12.0, 13.0],
    });
    let e = written(&[g]).unwrap_err().to_string();
    assert!(e.contains("one mass"), "{e}");
    // An unknown element and no mass: no Masses section, the rest written.
    let mut u = f.clone();
    u.elements.clear();
    u.names = vec![texmap_md_io::Label::new("X1").unwrap(); 2];
    let text = written(&[u]).unwrap();
    assert!(
        !text.contains("Masses") && text.contains("Atoms # atomic"),
        "{text}"
    );
}

/// LAMMPS's `read_data in.data` then `write_data out.data` in `dir` with `atom_style`: the
/// file LAMMPS wrote, or `None` without `lmp` on PATH (Debian: apt install lammps).
fn lammps_rewrite(dir: &std::path::Path, atom_style: &str) -> Option<Frame> {
    if std::process::Command::new("lmp")
        .arg("-h")
        .output()
        .is_err()
    {
        eprintln!("SKIPPED: no lmp on PATH (apt install lammps); the committed files cover it");
        return None;
    }
    std::fs::write(
        dir.join("in.lmp"),
        format!(
            "units metal\natom_style {atom_style}\nboundary p p p\nread_data in.data\nwrite_data out.data nocoeff\n"
        ),
    )
    .unwrap();
    let o = std::process::Command::new("lmp")
        .args(["-in", "in.lmp", "-log", "none"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    Some(read(&dir.join("out.data")))
}

/// LAMMPS itself on a file written now, where `lmp` is installed.
#[test]
fn lammps_reads_a_file_written_now() {
    let dir = tempfile::tempdir().unwrap();
    // The P-1 crystal with charges: atom style charge.
    let mut f = read(&data("../crystal/cod_9001665.cif"));
    let q: Vec<f32> = (0..f.n_atoms()).map(|i| i as f32 * 0.25 - 1.0).collect();
    f.properties.push(texmap_md_io::Property {
        name: "charge".into(),
        values: q,
    });
    let text = written(std::slice::from_ref(&f)).unwrap();
    assert!(text.contains("Atoms # charge"));
    let ours = dir.path().join("in.data");
    std::fs::write(&ours, &text).unwrap();
    let Some(back) = lammps_rewrite(dir.path(), "charge") else {
        return;
    };
    let mine = read(&ours);
    assert_eq!(back.property("charge"), mine.property("charge"));
    let (pa, pb) = (unwrapped(&mine), unwrapped(&back));
    for i in 0..pa.len() {
        for k in 0..3 {
            assert!((pa[i][k] - pb[i][k]).abs() <= 2e-5, "atom {i}");
        }
    }
}

/// The velocities of a data file (ASE's, with a `Velocities` section) read and written back:
/// the same numbers, bit for bit, and LAMMPS (where `lmp` is installed) reads our file and its
/// `write_data` gives them back.
#[test]
fn a_data_files_velocities_are_written_back() {
    let src = data("../lammps_data/ase_atomic_tri.data");
    let f = read(&src);
    let v = |f: &Frame| ["vx", "vy", "vz"].map(|k| f.property(k).map(<[f32]>::to_vec));
    assert!(v(&f)[0].is_some(), "the input has velocities");
    let text = written(std::slice::from_ref(&f)).unwrap();
    assert!(text.contains("\nVelocities\n\n1 "), "{text}");
    let dir = tempfile::tempdir().unwrap();
    let ours = dir.path().join("in.data");
    std::fs::write(&ours, &text).unwrap();
    assert_eq!(v(&read(&ours)), v(&f));
    if let Some(back) = lammps_rewrite(dir.path(), "atomic") {
        assert_eq!(v(&back), v(&f));
    }
}

/// A cell rotated into LAMMPS's form turns the velocities with the positions: a velocity set
/// to the vector from atom 0 to atom 1 is still that vector in the file.
#[test]
fn velocities_turn_with_a_rotated_box() {
    let mut f = read(&data("nacl_primitive.vasp"));
    let d: Vec<f32> = (0..3)
        .map(|k| f.positions[1][k] - f.positions[0][k])
        .collect();
    for (k, name) in ["vx", "vy", "vz"].into_iter().enumerate() {
        f.properties.push(texmap_md_io::Property {
            name: name.into(),
            values: vec![d[k]; f.n_atoms()],
        });
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.data");
    std::fs::write(&path, written(std::slice::from_ref(&f)).unwrap()).unwrap();
    let g = read(&path);
    let vx = g.property("vx").unwrap();
    let (vy, vz) = (g.property("vy").unwrap(), g.property("vz").unwrap());
    let moved = [vx[0], vy[0], vz[0]];
    let want: [f32; 3] = std::array::from_fn(|k| g.positions[1][k] - g.positions[0][k]);
    // f32 positions of a few Å, rotated in f64 and rounded: a few ulp of 5 Å.
    for k in 0..3 {
        assert!(
            (moved[k] - want[k]).abs() <= 4e-6,
            "velocity {moved:?}, atom 0 to 1 {want:?}, tolerance 4e-6"
        );
    }
    assert!(moved[1] != d[1] || moved[2] != d[2], "the box was rotated");
}

/// Image flags are written in the Atoms lines, and recomputed for the lattice a large tilt is
/// reduced to: every atom's unwrapped position (position + flags · cell) is the same in our
/// file as read back and in the file LAMMPS's `read_data`/`write_data` makes of it.
#[test]
fn image_flags_survive_a_reduced_tilt_and_lammps() {
    // xy = 7 > 10/2, yz = -6 < -9/2 and then xz = 10 > 5: all three tilts reduced.
    let cell = UnitCell::from_matrix([[10.0, 0.0, 0.0], [7.0, 9.0, 0.0], [3.0, -6.0, 8.0]])
        .unwrap()
        .with_origin([-1.0, 2.0, 0.5]);
    let m = cell.matrix();
    let mut f = Frame::new();
    let mut flags = [Vec::new(), Vec::new(), Vec::new()];
    for i in 0..24u32 {
        // Fractional positions inside the cell, flags from -2 to 2.
        let s = [
            0.05 + 0.037 * i as f64,
            0.9 - 0.031 * i as f64,
            (0.13 * i as f64).fract(),
        ];
        let p: [f32; 3] = std::array::from_fn(|k| {
            (cell.origin()[k] + s[0] * m[0][k] + s[1] * m[1][k] + s[2] * m[2][k]) as f32
        });
        f.positions.push(p);
        f.types
            .push(texmap_md_io::Label::new(if i % 2 == 0 { "1" } else { "2" }).unwrap());
        for (k, fl) in flags.iter_mut().enumerate() {
            fl.push(((i as i32 * (k as i32 + 2)) % 5 - 2) as f32);
        }
    }
    f.cell = Some(cell);
    f.properties.push(texmap_md_io::Property {
        name: "mass".into(),
        values: vec![39.95; f.positions.len()],
    });
    for (name, values) in ["ix", "iy", "iz"].into_iter().zip(flags) {
        f.properties.push(texmap_md_io::Property {
            name: name.into(),
            values,
        });
    }
    let want = unwrapped(&f);
    let text = written(std::slice::from_ref(&f)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let ours = dir.path().join("in.data");
    std::fs::write(&ours, &text).unwrap();
    let mine = read(&ours);
    let tilts = mine.cell.unwrap().matrix();
    assert!(tilts[1][0].abs() <= 5.0 && tilts[2][0].abs() <= 5.0 && tilts[2][1].abs() <= 4.5);
    let close = |got: &[[f64; 3]], who: &str| {
        for (i, (a, b)) in want.iter().zip(got).enumerate() {
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-4,
                    "{who}: atom {i} {a:?} against {b:?}"
                );
            }
        }
    };
    close(&unwrapped(&mine), "ours");
    if let Some(back) = lammps_rewrite(dir.path(), "atomic") {
        close(&unwrapped(&back), "LAMMPS");
    }
}
