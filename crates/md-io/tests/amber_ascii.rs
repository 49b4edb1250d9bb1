//! AMBER ASCII trajectories (mdcrd) and restarts (rst7 / inpcrd) written by ParmEd 4.3.1,
//! compared with what MDAnalysis 2.11 and ParmEd read back (tests/data/amber_ascii/
//! gen_amber_ascii.py, reference.json); and what a damaged or ambiguous file gives.

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Error, Format, Frame, ReadOptions, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/amber_ascii")
        .join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(path("reference.json")).unwrap()).unwrap()
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn from_text(
    text: &str,
    format: Format,
    opts: ReadOptions,
) -> Result<Trajectory<Cursor<Vec<u8>>>, Error> {
    Trajectory::from_reader_with(
        Cursor::new(text.as_bytes().to_vec()),
        format,
        "t.mdcrd",
        opts,
    )
}

/// Every frame of the three ParmEd trajectories, streamed and then read backwards by number:
/// positions equal to MDAnalysis's (both round the same decimal text to f32), boxes to its
/// lengths with right angles, and within 1e-4 Å of ParmEd's f64 reading. The fifth frame of
/// box.mdcrd has fields that run together (-150.123 fills its 8 columns, 1234.567 too).
#[test]
fn trajectories_as_mdanalysis_and_parmed_read_them() {
    let r = reference();
    for name in ["box.mdcrd", "nobox.mdcrd", "ten.mdcrd"] {
        let mda = &r[name]["mdanalysis"];
        let n = mda["n_atoms"].as_u64().unwrap() as usize;
        let frames = mda["positions"].as_array().unwrap();
        let opts = ReadOptions::new().atoms(n);
        let mut traj = Trajectory::open_with(path(name), opts.clone()).unwrap();
        assert_eq!(traj.format(), Format::AmberTrj);
        assert_eq!(traj.n_frames().unwrap(), frames.len(), "{name}");
        let mut f = Frame::new();
        let mut order: Vec<usize> = (0..frames.len()).collect();
        order.extend((0..frames.len()).rev());
        for (pass, &k) in order.iter().enumerate() {
            if pass < frames.len() {
                assert!(traj.read_next(&mut f).unwrap());
            } else {
                traj.read_frame(k, &mut f).unwrap();
            }
            assert_eq!(f.n_atoms(), n);
            for (i, p) in frames[k].as_array().unwrap().iter().enumerate() {
                let p: Vec<f32> = f64s(p).iter().map(|v| *v as f32).collect();
                assert_eq!(&f.positions[i][..], &p[..], "{name} frame {k} atom {i}");
            }
            if let Some(pm) = r[name].get("parmed") {
                let flat: Vec<f64> = pm["positions"][k]
                    .as_array()
                    .unwrap()
                    .iter()
                    .flat_map(f64s)
                    .collect();
                for (i, p) in f.positions.iter().enumerate() {
                    for c in 0..3 {
                        let d = (p[c] as f64 - flat[3 * i + c]).abs();
                        assert!(d <= 1e-4, "{name} frame {k} atom {i}: ParmEd {d}");
                    }
                }
            }
            let want_box = &mda["boxes"][k];
            match f.cell {
                None => assert!(want_box.is_null(), "{name} frame {k}: no box read"),
                Some(cell) => {
                    let b = f64s(want_box);
                    for c in 0..3 {
                        assert!((cell.lengths()[c] - b[c]).abs() < 1e-9, "{name} {k}");
                        assert!((cell.angles()[c] - b[3 + c]).abs() < 1e-9, "{name} {k}");
                    }
                }
            }
            assert_eq!(f.comment, "written by ParmEd for texmap's tests");
        }
        traj.read_frame(frames.len() - 1, &mut f).unwrap();
        assert!(!traj.read_next(&mut f).unwrap());
    }
}

/// A truncated octahedron's angles, which the trajectory's three-number box line leaves out,
/// come from the caller (the prmtop's BOX_DIMENSIONS): the cell's lengths and angles.
#[test]
fn three_number_box_takes_the_runs_angles() {
    let beta = 109.471_220_634_490_7;
    let opts = ReadOptions::new().atoms(66).box_angles([beta; 3]);
    let mut traj = Trajectory::open_with(path("box.mdcrd"), opts.clone()).unwrap();
    let mut f = Frame::new();
    traj.read_frame(2, &mut f).unwrap();
    let cell = f.cell.unwrap();
    let (l, a) = (cell.lengths(), cell.angles());
    for (c, want) in [18.5, 19.0, 19.25].iter().enumerate() {
        assert!((l[c] - want).abs() < 1e-9, "{l:?}");
        assert!((a[c] - beta).abs() < 1e-9, "{a:?}");
    }
    // The cell's volume: a b c sqrt(1 - 3 cos²β + 2 cos³β), from the lengths and angles alone.
    let cb = beta.to_radians().cos();
    let v = 18.5 * 19.0 * 19.25 * (1.0 - 3.0 * cb * cb + 2.0 * cb * cb * cb).sqrt();
    assert!((cell.volume() - v).abs() < 1e-9 * v);
}

/// Restarts: positions, velocities (Å/ps: the file's ×20.455), the box with its angles and
/// the time as ParmEd reads them back; positions as MDAnalysis's INPCRD reader. A 7-atom
/// inpcrd ends in a half line and holds neither velocities nor box.
#[test]
fn restarts_as_parmed_and_mdanalysis_read_them() {
    let r = reference();
    for name in ["vel_box.rst7", "odd.inpcrd"] {
        let pm = &r[name]["parmed"];
        let mut traj = Trajectory::open(path(name)).unwrap();
        assert_eq!(traj.format(), Format::AmberRestart);
        assert_eq!(traj.n_frames().unwrap(), 1);
        let mut f = Frame::new();
        traj.read_frame(0, &mut f).unwrap();
        let n = pm["natom"].as_u64().unwrap() as usize;
        assert_eq!(f.n_atoms(), n);
        let mda = r[name]["mdanalysis"]["positions"].as_array().unwrap();
        for (i, p) in pm["positions"].as_array().unwrap().iter().enumerate() {
            let (p, m) = (f64s(p), f64s(&mda[i]));
            for c in 0..3 {
                assert_eq!(f.positions[i][c], p[c] as f32, "{name} atom {i}");
                assert_eq!(f.positions[i][c], m[c] as f32, "{name} atom {i}");
            }
        }
        match pm["velocities"].as_array() {
            None => assert!(f.velocities.is_empty()),
            Some(v) => {
                assert_eq!(f.velocities.len(), n);
                for (i, want) in v.iter().enumerate() {
                    for (got, want) in f.velocities[i].iter().zip(f64s(want)) {
                        let got = *got as f64;
                        assert!(
                            (got - want).abs() <= 1e-6 * want.abs().max(1.0),
                            "{name} atom {i}: {got} vs {want}"
                        );
                    }
                }
            }
        }
        match pm["box"].as_array() {
            None => assert!(f.cell.is_none()),
            Some(_) => {
                let b = f64s(&pm["box"]);
                let cell = f.cell.unwrap();
                for c in 0..3 {
                    assert!((cell.lengths()[c] - b[c]).abs() < 1e-9);
                    assert!((cell.angles()[c] - b[3 + c]).abs() < 1e-9);
                }
            }
        }
        let time = r[name]["mdanalysis"]["time"].as_f64().unwrap();
        assert_eq!(f.time, Some(time), "{name}");
        assert!(!traj.read_next(&mut f).unwrap());
    }
}

/// How a file is recognised: by extension, by AMBER's default names, a `.crd` by its second
/// line, and a file with no telling name by its first bytes.
#[test]
fn formats_by_name_and_content() {
    let dir = tempfile::tempdir().unwrap();
    let copy = |from: &str, to: &str| {
        let p = dir.path().join(to);
        std::fs::copy(path(from), &p).unwrap();
        p
    };
    let opts = ReadOptions::new().atoms(66);
    for (from, to, want) in [
        ("box.mdcrd", "prod.crd", Format::AmberTrj),
        ("vel_box.rst7", "start.crd", Format::AmberRestart),
        ("box.mdcrd", "mdcrd", Format::AmberTrj),
        ("vel_box.rst7", "inpcrd", Format::AmberRestart),
        ("vel_box.rst7", "restrt", Format::AmberRestart),
        ("box.mdcrd", "run.trj", Format::AmberTrj),
        ("box.mdcrd", "noname", Format::AmberTrj),
        ("odd.inpcrd", "noname2", Format::AmberRestart),
    ] {
        let p = copy(from, to);
        let mut t = Trajectory::open_with(&p, opts.clone()).unwrap();
        assert_eq!(t.format(), want, "{to}");
        assert!(t.n_frames().unwrap() >= 1, "{to}");
    }
    // A .crd that is neither.
    let p = dir.path().join("other.crd");
    std::fs::write(&p, "title\nnot numbers at all\n").unwrap();
    let e = Trajectory::open_with(&p, opts.clone())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("other.crd") && e.contains("--format"), "{e}");
}

/// Without the atom count the trajectory cannot be read, and the error says where it comes
/// from; a wrong count misreads the line layout and is refused at the first line that shows it.
#[test]
fn atom_count_is_required_and_checked() {
    let e = Trajectory::open(path("box.mdcrd"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("box.mdcrd") && e.contains("--topology"), "{e}");
    // 65 atoms: 195 numbers, so the frame's 20th line should hold 5 and holds 8.
    let mut t = Trajectory::open_with(path("box.mdcrd"), ReadOptions::new().atoms(65)).unwrap();
    let e = t
        .n_frames()
        .and_then(|_| t.read_frame(0, &mut Frame::new()));
    let e = e.unwrap_err().to_string();
    assert!(e.contains("frame 0, line 21"), "{e}");
    assert!(e.contains("last coordinates"), "{e}");
}

/// A cut trajectory: the error names the frame, the line and what was missing; with
/// allow_truncated the complete frames are kept, with a warning. A field that is not a number
/// (Fortran's overflow stars) is named by its line and byte.
#[test]
fn damage_is_reported_where_it_is() {
    let text = std::fs::read_to_string(path("box.mdcrd")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    // Title + 5 frames of 20 coordinate lines and a box line; cut frame 3 after 4 lines.
    let cut = lines[..1 + 3 * 21 + 4].join("\n") + "\n";
    let opts = ReadOptions::new().atoms(66);
    let mut t = from_text(&cut, Format::AmberTrj, opts.clone()).unwrap();
    let e = t.n_frames().unwrap_err().to_string();
    assert!(e.starts_with("t.mdcrd: frame 3, line 69"), "{e}");
    assert!(e.contains("16 more coordinate lines"), "{e}");
    let mut t = from_text(&cut, Format::AmberTrj, opts.clone().allow_truncated(true)).unwrap();
    assert_eq!(t.n_frames().unwrap(), 3);
    assert_eq!(t.warnings().len(), 1);

    let mut bad: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    bad[30].replace_range(16..24, "********");
    let bad = bad.join("\n") + "\n";
    let mut t = from_text(&bad, Format::AmberTrj, opts.clone()).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    let e = t.read_next(&mut f).unwrap_err().to_string();
    let byte = lines[..30].iter().map(|l| l.len() + 1).sum::<usize>() + 16;
    assert_eq!(
        e,
        format!(
            "t.mdcrd: frame 1, line 31, byte {byte}: expected 10 coordinates of 8 columns each (10F8.3), found '********'"
        )
    );
}

/// The one-frame layouts a restart allows, and what it refuses: three atoms (two coordinate
/// lines) followed by one line (a box), two (velocities), three (both) or four (an error).
#[test]
fn restart_tails() {
    let head = "t\n    3  5.0000000E+00\n   1.0000000   2.0000000   3.0000000   4.0000000   5.0000000   6.0000000\n   7.0000000   8.0000000   9.0000000\n";
    let vel = "   0.1000000   0.2000000   0.3000000   0.4000000   0.5000000   0.6000000\n   0.7000000   0.8000000   0.9000000\n";
    let box3 = "  10.0000000  11.0000000  12.0000000\n";
    let read = |text: String| {
        let mut t = Trajectory::from_reader(
            Cursor::new(text.into_bytes()),
            Format::AmberRestart,
            "t.rst7",
        )?;
        let mut f = Frame::new();
        t.read_frame(0, &mut f).map(|_| f)
    };
    let f = read(head.to_string()).unwrap();
    assert_eq!(
        f.positions,
        vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]]
    );
    assert_eq!((f.time, f.cell, f.velocities.len()), (Some(5.0), None, 0));
    let f = read(format!("{head}{box3}")).unwrap();
    assert_eq!(f.cell.unwrap().lengths(), [10.0, 11.0, 12.0]);
    assert_eq!(f.cell.unwrap().angles(), [90.0; 3]);
    let f = read(format!("{head}{vel}")).unwrap();
    assert!(f.cell.is_none());
    assert!((f.velocities[2][2] as f64 - 0.9 * 20.455).abs() < 1e-5);
    let f = read(format!("{head}{vel}{box3}\n\n")).unwrap();
    assert!(f.cell.is_some() && f.velocities.len() == 3);
    let e = read(format!("{head}{vel}{box3}{box3}"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.rst7: frame 0, line 8"), "{e}");
    assert!(e.contains("at most the velocities"), "{e}");
    // A number missing from the coordinates' last line.
    let short = head.replace("   9.0000000\n", "\n");
    let e = read(short).unwrap_err().to_string();
    assert!(e.starts_with("t.rst7: frame 0, line 4"), "{e}");
    // A count of 0, and a count with nothing after it.
    let e = read("t\n    0\n".into()).unwrap_err().to_string();
    assert!(e.contains("the number of atoms"), "{e}");
    let e = read("t\n 4000000\n".into()).unwrap_err().to_string();
    assert!(
        e.contains("file ends inside the frame") && e.contains("coordinate lines"),
        "{e}"
    );
}

/// With one atom a frame is one line of three fields: a box line cannot be told from the next
/// frame, so the file is read as frames without boxes (as MDAnalysis does).
#[test]
fn one_atom_trajectory_has_no_box() {
    let text = "title\n   1.000   2.000   3.000\n   4.000   5.000   6.000\n";
    let mut t = from_text(text, Format::AmberTrj, ReadOptions::new().atoms(1)).unwrap();
    assert_eq!(t.n_frames().unwrap(), 2);
    let mut f = Frame::new();
    t.read_frame(1, &mut f).unwrap();
    assert_eq!(f.positions, vec![[4.0, 5.0, 6.0]]);
    assert!(f.cell.is_none());
    // Four atoms: a frame's first line has 10 fields, so a 3-field line after it is a box.
    let four = "title\n   1.000   2.000   3.000   4.000   5.000   6.000   7.000   8.000   9.000  10.000\n  11.000  12.000\n  20.000  21.000  22.000\n";
    let mut t = from_text(four, Format::AmberTrj, ReadOptions::new().atoms(4)).unwrap();
    t.read_frame(0, &mut f).unwrap();
    assert_eq!(f.positions[3], [10.0, 11.0, 12.0]);
    assert_eq!(f.cell.unwrap().lengths(), [20.0, 21.0, 22.0]);
    // A replica-exchange header line before each frame is skipped.
    let remd = four.replace(
        "title\n",
        "title\nREMD         1         0         1    300.00\n",
    );
    let mut t = from_text(&remd, Format::AmberTrj, ReadOptions::new().atoms(4)).unwrap();
    assert_eq!(t.n_frames().unwrap(), 1);
    t.read_frame(0, &mut f).unwrap();
    assert_eq!(f.positions[0], [1.0, 2.0, 3.0]);
}

/// A prmtop in a truncated octahedron (ParmEd's `box` + `save`: IFBOX 2, BOX_DIMENSIONS):
/// the topology's box angles are ParmEd's reading of them, and a trajectory read with them
/// gets the octahedron's cell.
#[test]
fn prmtop_box_angles_as_parmed_reads_them() {
    let r = reference();
    let want = f64s(&r["truncoct.parm7"]["parmed_box"]);
    let topo = texmap_md_io::Topology::open(path("truncoct.parm7")).unwrap();
    let angles = topo.box_angles.unwrap();
    for c in 0..3 {
        assert!(
            (angles[c] - want[3 + c]).abs() < 1e-5,
            "{angles:?} vs {want:?}"
        );
    }
    let plain = texmap_md_io::Topology::open(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/prmtop_parmed.prmtop"),
    )
    .unwrap();
    // IFBOX 1 with beta 90: a rectangular box.
    assert_eq!(plain.box_angles, Some([90.0; 3]));
    let opts = ReadOptions::new().atoms(topo.n_atoms()).box_angles(angles);
    let mut traj = Trajectory::open_with(path("box.mdcrd"), opts.clone()).unwrap();
    let mut f = Frame::new();
    traj.read_frame(0, &mut f).unwrap();
    assert_eq!(f.cell.unwrap().angles(), angles);
}

/// A blank title (AMBER writes 80 spaces when none is set) is still the title: the frames and
/// the restart read as with a named one.
#[test]
fn blank_titles_are_titles() {
    let opts = ReadOptions::new().atoms(66);
    for (name, format) in [
        ("box.mdcrd", Format::AmberTrj),
        ("vel_box.rst7", Format::AmberRestart),
    ] {
        let text = std::fs::read_to_string(path(name)).unwrap();
        let (_, rest) = text.split_once('\n').unwrap();
        let blank = format!("{}\n{rest}", " ".repeat(80));
        let read_all = |t: &str| {
            let mut traj = from_text(t, format, opts.clone()).unwrap();
            let mut f = Frame::new();
            let mut out = Vec::new();
            while traj.read_next(&mut f).unwrap() {
                out.push((f.positions.clone(), f.cell, f.velocities.clone()));
            }
            out
        };
        let (a, b) = (read_all(&text), read_all(&blank));
        assert!(!a.is_empty());
        assert_eq!(a, b, "{name}");
    }
}

/// AMBER's older `.top` name for a prmtop is read as one when it starts as one does; a
/// GROMACS `.top` is read as GROMACS's, not misread as a prmtop.
#[test]
fn top_files_are_prmtops_only_when_they_look_like_one() {
    let dir = tempfile::tempdir().unwrap();
    let amber = dir.path().join("system.top");
    std::fs::copy(path("truncoct.parm7"), &amber).unwrap();
    let t = texmap_md_io::Topology::open(&amber).unwrap();
    assert_eq!(t.n_atoms(), 66);
    let named = dir.path().join("prmtop");
    std::fs::copy(path("truncoct.parm7"), &named).unwrap();
    assert_eq!(texmap_md_io::Topology::open(&named).unwrap().n_atoms(), 66);
    let gromacs = dir.path().join("topol.top");
    std::fs::write(
        &gromacs,
        "; GROMACS\n[ atomtypes ]\nNA 11 22.99 0.0 A 0.33 0.01\n\
         [ moleculetype ]\nNA 1\n[ atoms ]\n1 NA 1 NA NA 1 1.0\n\
         [ system ]\nions\n[ molecules ]\nNA 3\n",
    )
    .unwrap();
    let t = texmap_md_io::Topology::open(&gromacs).unwrap();
    assert_eq!(t.n_atoms(), 3);
    assert_eq!(t.charges, [1.0; 3]);
    // Damaged, it is a GROMACS topology's error, naming the file.
    std::fs::write(&gromacs, "; GROMACS\n[ system ]\nnothing\n").unwrap();
    let e = texmap_md_io::Topology::open(&gromacs)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("topol.top") && e.contains("[ molecules ]"),
        "{e}"
    );
}

/// A NetCDF restart (the AMBERRESTART convention: one frame, doubles, ParmEd's NetCDFRestart
/// over scipy) holds what the ASCII restart of the same frame holds, as ParmEd reads that;
/// named `.rst7`, as pmemd may name it, it is still read as NetCDF.
#[test]
fn netcdf_restart_holds_the_same_frame() {
    let r = reference();
    let pm = &r["vel_box.rst7"]["parmed"];
    let dir = tempfile::tempdir().unwrap();
    let renamed = dir.path().join("md.rst7");
    std::fs::copy(path("vel_box.ncrst"), &renamed).unwrap();
    for p in [path("vel_box.ncrst"), renamed] {
        let mut traj = Trajectory::open(&p).unwrap();
        assert_eq!(traj.format(), Format::Netcdf);
        assert_eq!(traj.n_frames().unwrap(), 1);
        let mut f = Frame::new();
        assert!(traj.read_next(&mut f).unwrap());
        assert!(!traj.read_next(&mut Frame::new()).unwrap());
        let close = |got: &[[f32; 3]], want: &Value, tol: f64| {
            let want = want.as_array().unwrap();
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(want) {
                for (a, b) in g.iter().zip(f64s(w)) {
                    assert!(
                        (*a as f64 - b).abs() <= tol * b.abs().max(1.0),
                        "{a} vs {b}"
                    );
                }
            }
        };
        close(&f.positions, &pm["positions"], 1e-6);
        close(&f.velocities, &pm["velocities"], 1e-5);
        let cell = f.cell.unwrap();
        let b = f64s(&pm["box"]);
        for c in 0..3 {
            assert!((cell.lengths()[c] - b[c]).abs() < 1e-9);
            assert!((cell.angles()[c] - b[3 + c]).abs() < 1e-9);
        }
        assert_eq!(f.time, Some(1234.5));
    }
}
