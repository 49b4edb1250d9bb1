//! `texmap convert` against files other programs wrote: OVITO 3.17.2's exports of the same
//! analysed, cut-down systems (tests/data/convert/gen_convert.py) and MDAnalysis's XTC with
//! its GRO (md-io's fixtures), read back through md-io's readers.

use std::path::{Path, PathBuf};
use std::process::Output;

use texmap_md_io::{Frame, Sequence};

use crate::common;
use common::texmap;

fn md_data(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(name);
    p.to_str().unwrap().to_string()
}

fn convert_data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/convert")
        .join(name)
}

/// md-io's fixture `name`, a JSON file of reference values.
fn json(name: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(md_data(name)).unwrap()).unwrap()
}

/// A JSON array of numbers.
fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every frame of `path`.
fn frames(path: &Path) -> Vec<Frame> {
    let mut t = Sequence::open(&[path.to_path_buf()], None, Default::default()).unwrap();
    let n = t.n_frames().unwrap();
    (0..n)
        .map(|k| {
            let mut f = Frame::new();
            t.read_frame(k, &mut f).unwrap();
            f
        })
        .collect()
}

/// The values whose `keep` is true (a selection's atoms).
fn kept<T: Clone>(values: &[T], keep: &[bool]) -> Vec<T> {
    (values.iter().zip(keep))
        .filter(|(_, k)| **k)
        .map(|(v, _)| v.clone())
        .collect()
}

fn run_ok(args: &[&str]) {
    let o = texmap(args);
    assert!(o.status.success(), "texmap {args:?}: {}", stderr(&o));
}

/// The grain boundaries of a polycrystal (the atoms adaptive CNA does not call FCC) with their
/// structure types and coordination numbers: the same atoms, positions and values as OVITO's
/// export of CNA + Coordination analysis + Delete selected, in a LAMMPS dump and in extended XYZ.
#[test]
fn defects_with_their_columns_are_ovitos_export() {
    let dir = tempfile::tempdir().unwrap();
    let source = md_data("grains/fcc_poly.xyz");
    let ovito_dump = &frames(&convert_data("ovito_defects.lammpstrj"))[0];
    let ovito_xyz = &frames(&convert_data("ovito_defects.xyz"))[0];
    assert_eq!(ovito_dump.n_atoms(), 3756);
    for out in ["ours.lammpstrj", "ours.xyz"] {
        let path = dir.path().join(out);
        run_ok(&[
            "convert",
            &source,
            "--coordination",
            "3.2",
            "--select",
            "not cna fcc",
            "--columns",
            "cna,coordination",
            "-q",
            "-o",
            path.to_str().unwrap(),
        ]);
        let ours = frames(&path);
        assert_eq!(ours.len(), 1);
        let ours = &ours[0];
        assert_eq!(ours.n_atoms(), ovito_dump.n_atoms(), "{out}");
        assert_eq!(ours.positions, ovito_dump.positions, "{out}");
        assert_eq!(
            ours.cell.as_ref().unwrap().matrix(),
            ovito_dump.cell.as_ref().unwrap().matrix()
        );
        let names: Vec<&str> = ours.properties.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(
            names,
            ["cna", "coordination"],
            "{out}: the columns asked for, in order"
        );
        assert_eq!(
            ours.property("cna").unwrap(),
            ovito_dump.property("StructureType").unwrap(),
            "{out}"
        );
        assert_eq!(
            ours.property("coordination").unwrap(),
            ovito_dump.property("Coordination").unwrap(),
            "{out}"
        );
        assert_eq!(
            ours.property("coordination").unwrap(),
            ovito_xyz.property("n_neighb").unwrap(),
            "{out}"
        );
        assert!(
            ours.property("cna").unwrap().iter().all(|&t| t != 1.0),
            "no FCC atom is left"
        );
        // The kept atoms carry their numbers in the whole crystal (the file has no ids).
        let whole = &frames(Path::new(&source))[0];
        assert_eq!(ours.ids.len(), ours.n_atoms(), "{out}");
        for (id, p) in ours.ids.iter().zip(&ours.positions) {
            assert_eq!(whole.positions[*id as usize - 1], *p, "{out}: atom id {id}");
        }
    }
}

/// Wigner-Seitz point defects: the atoms on sites that hold other than one atom, with the
/// occupancy, equal OVITO's export of the same analysis after Delete selected.
#[test]
fn point_defects_are_ovitos_export() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("defects.xyz");
    run_ok(&[
        "convert",
        &md_data("wigner_seitz/cur.xyz"),
        "--wigner-seitz",
        "atoms",
        "--displacement-reference",
        &md_data("wigner_seitz/ref.xyz"),
        "--select",
        "prop site_occupancy != 1",
        "--columns",
        "site_occupancy",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let ours = &frames(&out)[0];
    let ovito = &frames(&convert_data("ovito_ws_defects.xyz"))[0];
    assert_eq!(ours.n_atoms(), 16);
    assert_eq!(ours.positions, ovito.positions);
    assert_eq!(
        ours.property("site_occupancy").unwrap(),
        ovito.property("Occupancy").unwrap()
    );
}

/// A smaller trajectory for another program: the C-alpha atoms of every second frame of
/// MDAnalysis's XTC, as XTC, DCD, PDB, PDBx/mmCIF, GRO and a LAMMPS dump; each equals the
/// source's frames cut down by the GRO's atom names, to the output's precision (mmCIF: bit for
/// bit, the atoms keeping their numbers in the whole frame).
#[test]
fn a_selection_of_every_second_frame_in_each_format() {
    let dir = tempfile::tempdir().unwrap();
    let xtc = md_data("topo_mda.xtc");
    let gro = md_data("topo_mda.gro");
    let source = frames(Path::new(&xtc));
    let names = &frames(Path::new(&gro))[0].names;
    let keep: Vec<bool> = names.iter().map(|n| n.as_str() == "CA").collect();
    let picked = keep.iter().filter(|&&k| k).count();
    assert!(picked > 0 && picked < keep.len());
    for (out, tolerance) in [
        ("ca.xtc", 1.01e-3),
        ("ca.dcd", 1e-6),
        ("ca.pdb", 5.01e-4),
        ("ca.cif", 0.0),
        ("ca.lammpstrj", 1e-6),
        ("ca.gro", 5.01e-3),
    ] {
        let path = dir.path().join(out);
        run_ok(&[
            "convert",
            &xtc,
            "--topology",
            &gro,
            "--select",
            "name CA",
            "--frames",
            "::2",
            "-q",
            "-o",
            path.to_str().unwrap(),
        ]);
        let got = frames(&path);
        let expected: Vec<usize> = (0..source.len()).step_by(2).collect();
        assert_eq!(got.len(), expected.len(), "{out}");
        for (g, &k) in got.iter().zip(&expected) {
            let want = kept(&source[k].positions, &keep);
            assert_eq!(g.n_atoms(), picked, "{out}");
            for (a, b) in g.positions.iter().zip(&want) {
                for c in 0..3 {
                    let scale = b[c].abs().max(1.0);
                    assert!(
                        (a[c] - b[c]).abs() <= tolerance * scale,
                        "{out} frame {k}: {a:?} vs {b:?}"
                    );
                }
            }
        }
        if out.ends_with(".pdb") || out.ends_with(".gro") || out.ends_with(".cif") {
            assert!(got[0].names.iter().all(|n| n.as_str() == "CA"));
        }
        if out.ends_with(".cif") {
            let ids = kept(&(1..=keep.len() as i64).collect::<Vec<_>>(), &keep);
            assert!(got.iter().all(|g| g.ids == ids), "{out}: ids");
        }
    }
}

/// The same input gives the same bytes on one thread and on two (the analyses run in parallel).
#[test]
fn output_does_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let source = md_data("grains/fcc_poly.xyz");
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let path = dir.path().join(format!("g{threads}.xyz"));
        run_ok(&[
            "--threads",
            threads,
            "convert",
            &source,
            "--grains",
            "--orientations",
            "--coordination",
            "3.2",
            "-q",
            "-o",
            path.to_str().unwrap(),
        ]);
        outputs.push(std::fs::read(&path).unwrap());
    }
    assert_eq!(outputs[0], outputs[1]);
    let text = String::from_utf8_lossy(&outputs[0]);
    let header = text.lines().nth(1).unwrap();
    for column in [
        "coordination:I:1",
        "orientation_w:R:1",
        "lattice_rmsd:R:1",
        "grain:I:1",
    ] {
        assert!(header.contains(column), "{column} in {header}");
    }
}

/// Bad requests: exit code 2 for usage, 1 for what a frame holds, and never a file left behind.
#[test]
fn bad_requests_are_refused_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let source = md_data("grains/fcc_poly.xyz");
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let cases: [(Vec<String>, i32, &str); 7] = [
        (
            vec![source.clone()],
            2,
            "nothing to write: give -o FILE, or a table",
        ),
        (
            vec![
                source.clone(),
                "--rdf".into(),
                "8".into(),
                "--rdf-table".into(),
                out("g.csv"),
                "--select".into(),
                "all".into(),
            ],
            2,
            "--select and --columns choose what -o FILE holds",
        ),
        (
            vec![
                md_data("ase_plain.xyz"),
                "--rdf".into(),
                "5".into(),
                "--rdf-table".into(),
                out("g.csv"),
            ],
            1,
            "--rdf: the frame has no periodic cell",
        ),
        (
            vec![source.clone(), "-o".into(), out("x.png")],
            2,
            "expected a .xyz/.extxyz, .lammpstrj/.dump, .data/.lmp, .gro, .pdb, .cif/.mmcif, .dcd, .xtc, .trr, .nc/.ncdf, .gsd, .sdf/.sd/.mol, POSCAR/.vasp or XDATCAR file name",
        ),
        (
            vec![
                source.clone(),
                "--columns".into(),
                "cna".into(),
                "-o".into(),
                out("x.dcd"),
            ],
            2,
            "--columns",
        ),
        (
            vec![
                source.clone(),
                "--columns".into(),
                "grain".into(),
                "-o".into(),
                out("x.xyz"),
            ],
            1,
            "no property 'grain' (it has: none); --grains computes it",
        ),
        (
            vec![
                md_data("wigner_seitz/cur.xyz"),
                "--select".into(),
                "prop coordination > 8".into(),
                "-o".into(),
                out("y.xyz"),
            ],
            2,
            "--coordination R computes it",
        ),
    ];
    for (args, code, message) in cases {
        let mut all = vec!["convert"];
        all.extend(args.iter().map(String::as_str));
        let o = texmap(&all);
        assert_eq!(o.status.code(), Some(code), "{all:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{all:?}: {}", stderr(&o));
    }
    // A selection whose atom count changes between frames cannot be one XTC: frame 1 fails
    // and nothing is written.
    let xtc = out("moving.xtc");
    let o = texmap(&[
        "convert",
        &md_data("topo_mda.xtc"),
        "--topology",
        &md_data("topo_mda.gro"),
        "--select",
        "prop x > 4",
        "-o",
        &xtc,
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("frame 1: nothing was written")
            && e.contains("--select picks 55 atoms here and 53 in the first frame written")
            && e.contains("holds the same atoms in every frame"),
        "{e}"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// `-o x.cif` writes PDBx/mmCIF: a multi-chain structure (protein, DNA, water, ions) reads
/// back with the same atoms, labels and positions (bit for bit: shortest round-trip decimals),
/// in a data block named after the output (`--select` and `--frames` into .cif:
/// `a_selection_of_every_second_frame_in_each_format`).
#[test]
fn mmcif_output_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let pdb = md_data("chains_mda.pdb");
    let out = dir.path().join("chains.cif");
    run_ok(&["convert", &pdb, "-q", "-o", out.to_str().unwrap()]);
    let source = &frames(Path::new(&pdb))[0];
    let back = frames(&out);
    assert_eq!(back.len(), 1);
    let atoms = |f: &Frame| {
        let labels = [&f.names, &f.res_names, &f.chains].map(|l| l.clone());
        (
            f.positions.clone(),
            labels,
            f.res_ids.clone(),
            f.ids.clone(),
            f.elements.clone(),
        )
    };
    assert!(
        atoms(&back[0]) == atoms(source),
        "every atom as the PDB has it"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("data_chains\n"),
        "named after -o, not the temporary file"
    );
}

/// A GROMACS TRR of mixed blocks (mdrun's positions every 10 steps, velocities every 20, forces
/// every 5) cut to its first 71 waters: the frames with positions keep their velocities and forces, the
/// force-only frames are skipped and said to be, and the rewrite is what our writer gives the
/// same frames (md-io's trr_writer tests hold it against GROMACS and MDAnalysis).
#[test]
fn trr_output_keeps_velocities_and_forces() {
    let dir = tempfile::tempdir().unwrap();
    let src = md_data("trr_write/md.trr");
    let out = dir.path().join("ow.trr");
    let o = texmap(&[
        "convert",
        &src,
        "--select",
        "index 0 to 212",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("2 frame(s) of") && stderr(&o).contains("wrote 3 frame(s)"),
        "{}",
        stderr(&o)
    );
    let source: Vec<Frame> = frames(Path::new(&src))
        .into_iter()
        .filter(|f| f.n_atoms() > 0)
        .collect();
    // Rendering a force-only frame with a topology says what the frame is and how to keep the
    // frames with positions.
    let top = dir.path().join("top.pdb");
    run_ok(&[
        "convert",
        &src,
        "-q",
        "--frames",
        "0",
        "-o",
        top.to_str().unwrap(),
    ]);
    let png = dir.path().join("f.png");
    let o = texmap(&[
        "render",
        &src,
        "--topology",
        top.to_str().unwrap(),
        "--frames",
        "1",
        "-q",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("frame 1 has no positions") && stderr(&o).contains("-o positions.trr"),
        "{}",
        stderr(&o)
    );
    let back = frames(&out);
    assert_eq!(back.len(), 3);
    for (b, s) in back.iter().zip(&source) {
        let keep: Vec<bool> = (0..s.n_atoms()).map(|i| i < 213).collect();
        assert_eq!(b.n_atoms(), 213);
        assert_eq!((b.step, b.time), (s.step, s.time));
        assert_eq!(b.velocities.len(), kept(&s.velocities, &keep).len());
        for name in ["fx", "fy", "fz"] {
            let (got, want) = (
                b.property(name).unwrap(),
                kept(s.property(name).unwrap(), &keep),
            );
            for (g, w) in got.iter().zip(&want) {
                assert!(g.to_bits().abs_diff(w.to_bits()) <= 1, "{name}: {g} vs {w}");
            }
        }
        for (g, w) in b.positions.iter().zip(kept(&s.positions, &keep)) {
            for d in 0..3 {
                assert!((g[d] - w[d]).abs() <= w[d].abs() * 2.5e-7, "{g:?} vs {w:?}");
            }
        }
    }
}

/// mdrun's argon run with positions every 10 steps, velocities every 5 and forces every 2
/// (md-io/tests/data/trr_mixed): TRR -> TRR keeps the three frames with positions whole, and
/// the velocities and forces of the ten without, which no frame can carry, are named in one
/// warning with the counts `gmx dump` gives (2 frames of velocities, 8 of forces, 8 atoms).
#[test]
fn trr_frames_without_positions_are_named_not_dropped_in_silence() {
    let dir = tempfile::tempdir().unwrap();
    let src = md_data("trr_mixed/argon.trr");
    let out = dir.path().join("b.trr");
    let o = texmap(&["convert", &src, "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.matches("warning:").count(), 1, "{err}");
    assert!(
        err.contains("10 frame(s) of")
            && err.contains(
                "velocities (2 frame(s)) and forces (8 frame(s)) of 8 atoms were not written"
            )
            && err.contains("wrote 3 frame(s)"),
        "{err}"
    );
    let back = frames(&out);
    let steps: Vec<Option<i64>> = back.iter().map(|f| f.step).collect();
    assert_eq!(steps, [Some(0), Some(10), Some(20)]);
    for f in &back {
        assert_eq!((f.n_atoms(), f.velocities.len()), (8, 8));
        assert!(f.property("fx").is_some());
    }
}

/// A LAMMPS data file's Velocities (ASE's) come back in the data file written from it; a
/// trajectory's velocities (Å/ps), which a data file cannot state the units of, are named in
/// a warning.
#[test]
fn lammps_data_output_keeps_a_data_files_velocities() {
    let dir = tempfile::tempdir().unwrap();
    let src = md_data("lammps_data/ase_atomic_tri.data");
    let out = dir.path().join("out.data");
    let o = texmap(&["convert", &src, "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let (a, b) = (&frames(Path::new(&src))[0], &frames(&out)[0]);
    for k in ["vx", "vy", "vz"] {
        assert_eq!(a.property(k), b.property(k), "{k}");
    }
    let gro = dir.path().join("v.data");
    let o = texmap(&[
        "convert",
        &md_data("mda_vel.gro"),
        "--frames",
        "0",
        "-o",
        gro.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: the velocities of 11 atoms (1 frame) were not written: a LAMMPS data file's velocities are in its run's units"),
        "{}",
        stderr(&o)
    );
}

/// A MOL2's partial charges (Gasteiger's, as Open Babel writes them) have no place in an SD
/// file, which holds integer formal charges: the conversion names them in one warning, with
/// the formats that keep them, and the SD file read back indeed has no charges.
#[test]
fn mol2_partial_charges_written_as_sdf_are_named_in_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let src = md_data("molecules/library.mol2");
    let input = frames(Path::new(&src));
    let n: usize = input.iter().map(|f| f.n_atoms()).max().unwrap();
    assert!(
        input.iter().all(|f| f
            .property("charge")
            .is_some_and(|q| q.iter().any(|v| v.fract() != 0.0))),
        "the fixture has partial charges in every molecule"
    );
    let out = dir.path().join("library.sdf");
    let o = texmap(&["convert", &src, "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let line = err
        .lines()
        .find(|l| l.contains("partial charges"))
        .unwrap_or_else(|| panic!("no warning names the charges: {err}"));
    assert_eq!(err.matches("partial charges").count(), 1, "{err}");
    assert_eq!(
        line,
        format!(
            "texmap: warning: the partial charges ('charge') of {n} atoms ({} frames) were not written: an SD file holds integer formal charges only (.xyz, .lammpstrj, .data, .gsd keep them)",
            input.len()
        )
    );
    let back = frames(&out);
    assert_eq!(back.len(), input.len());
    assert!(back.iter().all(|f| f.property("charge").is_none()));
    // The same charges written where they are kept: no warning about them, and they come back.
    let xyz = dir.path().join("library.xyz");
    let o = texmap(&[
        "convert",
        &src,
        "--frames",
        "0",
        "-o",
        xyz.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("charge"), "{}", stderr(&o));
    assert_eq!(
        frames(&xyz)[0].property("charge"),
        input[0].property("charge")
    );
}

/// Converting to a format that holds everything the input has prints no warning, and the
/// output reads back with the input's columns; converting the same input to a format without
/// them names each one.
#[test]
fn nothing_dropped_means_no_warning() {
    let dir = tempfile::tempdir().unwrap();
    for (src, name) in [
        ("ase_props.xyz", "same.xyz"),
        ("lmp_tri.lammpstrj", "same.lammpstrj"),
        ("mda_vel.gro", "same.gro"),
    ] {
        let src = md_data(src);
        let out = dir.path().join(name);
        let o = texmap(&["convert", &src, "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(!stderr(&o).contains("warning"), "{name}: {}", stderr(&o));
        let (a, b) = (frames(Path::new(&src)), frames(&out));
        assert_eq!(a.len(), b.len(), "{name}");
        for (a, b) in a.iter().zip(&b) {
            let names = |f: &Frame| {
                f.properties
                    .iter()
                    .map(|p| p.name.clone())
                    .collect::<Vec<_>>()
            };
            assert_eq!(names(a), names(b), "{name}");
            assert_eq!(a.velocities.len(), b.velocities.len(), "{name}");
        }
    }
    // The extended XYZ's properties in a .gro: one warning each, naming it.
    let src = md_data("ase_props.xyz");
    let input = &frames(Path::new(&src))[0];
    assert!(!input.properties.is_empty());
    let gro = dir.path().join("props.gro");
    let o = texmap(&["convert", &src, "-o", gro.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    for p in &input.properties {
        let named = format!(
            "warning: the per-atom property '{}' of {} atoms (1 frame) was not written: a .gro file has no place for it",
            p.name,
            input.n_atoms()
        );
        assert_eq!(err.matches(&named).count(), 1, "{}: {err}", p.name);
    }
    // Nothing else of the fixture (species, positions, cell) is lost in a .gro.
    assert_eq!(
        err.matches("warning:").count(),
        input.properties.len(),
        "{err}"
    );
    // A coordinate trajectory is read with its topology: the names and residues a .dcd has no
    // place for are one note, not a warning each; its lost times are still a warning.
    let dcd = dir.path().join("md.dcd");
    let o = texmap(&[
        "convert",
        &md_data("topo_mda.xtc"),
        "--topology",
        &md_data("topo_mda.gro"),
        "-o",
        dcd.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(
        err.matches("holds coordinates, not the atom names, the residues (names and numbers): read it with its topology").count(),
        1,
        "{err}"
    );
    assert!(!err.contains("warning: the atom names"), "{err}");
    // The DCD gives back the first frame's time (0 at step 0) and loses the other three, as
    // reading both files shows.
    assert!(
        err.contains("warning: the time of 3 frames was not written"),
        "{err}"
    );
    let times = |path: &str| -> Vec<Option<f64>> {
        let mut t = texmap_md_io::Trajectory::open(path).unwrap();
        let mut f = Frame::new();
        let mut out = Vec::new();
        while t.read_next(&mut f).unwrap() {
            out.push(f.time);
        }
        out
    };
    let (xtc, back) = (
        times(&md_data("topo_mda.xtc")),
        times(dcd.to_str().unwrap()),
    );
    let differ = |(a, b): (&Option<f64>, &Option<f64>)| match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() > 1e-4,
        _ => true,
    };
    assert_eq!(
        xtc.iter().zip(&back).filter(|p| differ(*p)).count(),
        3,
        "{xtc:?} {back:?}"
    );
}

/// The trajectory formats of AMBER, HOOMD-blue and VASP: every frame of a triclinic LAMMPS
/// dump comes back from each (md-io's netcdf_writer, gsd_writer and vasp_writer tests hold the
/// files against MDAnalysis, netCDF-C, gsd.hoomd, ASE and pymatgen); a POSCAR takes one frame,
/// and an AMBER restart name is refused rather than given a trajectory.
#[test]
fn amber_hoomd_and_vasp_trajectories_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let src = md_data("lmp_tri.lammpstrj");
    let source = frames(Path::new(&src));
    assert!(source.len() > 1);
    for name in ["run.nc", "run.gsd", "XDATCAR"] {
        let out = dir.path().join(name);
        run_ok(&["convert", &src, "-q", "-o", out.to_str().unwrap()]);
        let back = frames(&out);
        assert_eq!(back.len(), source.len(), "{name}");
        for (b, s) in back.iter().zip(&source) {
            assert_eq!(b.n_atoms(), s.n_atoms(), "{name}");
            let (vb, vs) = (b.cell.unwrap().volume(), s.cell.unwrap().volume());
            assert!((vb - vs).abs() < 1e-4 * vs, "{name}: volume {vb} vs {vs}");
            // Every format keeps the distances between atoms (GSD moves the box to HOOMD's
            // centred form and wraps atoms into it: compare through the minimum image).
            let cell = b.cell.unwrap();
            for (i, j) in [(0, 1), (2, 7), (5, s.n_atoms() - 1)] {
                let d = |f: &Frame, c: &texmap_md_io::UnitCell| {
                    let v: [f64; 3] = std::array::from_fn(|k| {
                        f64::from(f.positions[i][k]) - f64::from(f.positions[j][k])
                    });
                    let m = texmap_md_io::pbc::minimum_image(c, v);
                    (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt()
                };
                let (db, ds) = (d(b, &cell), d(s, &s.cell.unwrap()));
                assert!(
                    (db - ds).abs() < 1e-3,
                    "{name}: atoms {i} {j}: {db} vs {ds}"
                );
            }
        }
    }
    let poscar = dir.path().join("POSCAR");
    let o = texmap(&["convert", &src, "-o", poscar.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("XDATCAR"), "{}", stderr(&o));
    assert!(!poscar.exists(), "no partial POSCAR");
    run_ok(&[
        "convert",
        &src,
        "-q",
        "--frames",
        "1",
        "-o",
        poscar.to_str().unwrap(),
    ]);
    assert_eq!(frames(&poscar)[0].n_atoms(), source[1].n_atoms());
    let rst = dir.path().join("x.ncrst");
    let o = texmap(&["convert", &src, "-o", rst.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// A label no CIF value can hold (a control character in an atom name) fails the frame,
/// naming the atom, and leaves no file; a compressed output name is refused before reading.
#[test]
fn mmcif_output_refuses_what_would_not_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("in");
    std::fs::create_dir(&xyz).unwrap();
    let xyz = xyz.join("bell.xyz");
    std::fs::write(&xyz, "2\nbell\nC 0 0 0\nO\x07 1.2 0 0\n").unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let cases = [
        ("bell.cif", 1, "frame 0: nothing was written"),
        (
            "bell.cif",
            1,
            "atom 1's name \"O\\u{7}\" holds a control character",
        ),
        ("x.cif.gz", 2, "written uncompressed; write"),
    ];
    for (name, code, message) in cases {
        let path = out.join(name);
        let o = texmap(&[
            "convert",
            xyz.to_str().unwrap(),
            "-o",
            path.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(code), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{name}: {}", stderr(&o));
    }
    let leftovers: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// `--columns diamond` writes OVITO's Identify diamond structure type of every atom (silicon
/// with a vacancy, hexagonal diamond, a slab with free surfaces: md-io's fixtures, OVITO's
/// types in diamond_reference.json), and `--select` on it keeps the atoms OVITO would.
#[test]
fn diamond_column_is_ovitos_structure_type() {
    let dir = tempfile::tempdir().unwrap();
    let reference: serde_json::Value = json("diamond/diamond_reference.json");
    for entry in reference.as_array().unwrap() {
        let file = entry["file"].as_str().unwrap();
        let want: Vec<f32> = entry["structure"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect();
        let out = dir.path().join(format!("{file}.lammpstrj"));
        run_ok(&[
            "convert",
            &md_data(&format!("diamond/{file}")),
            "--columns",
            "diamond",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(frames(&out)[0].property("diamond").unwrap(), want, "{file}");
        // Not cubic diamond: the vacancy's neighbours, the surfaces, all of hexagonal.
        let out = dir.path().join(format!("{file}.defects.xyz"));
        run_ok(&[
            "convert",
            &md_data(&format!("diamond/{file}")),
            "--select",
            "not diamond cubic",
            "--columns",
            "diamond",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        let kept = frames(&out)[0].property("diamond").unwrap().to_vec();
        let expected: Vec<f32> = want.iter().copied().filter(|&t| t != 1.0).collect();
        assert_eq!(kept, expected, "{file}");
    }
}

/// `--rdf-table` without -o: the mean over the frames of g(r), total and partial, equals the
/// mean of OVITO's Coordination analysis tables of the same frames (md-io's rdf fixture: a
/// triclinic Si/O mixture, two frames), to a pair moved across a bin edge by f32 positions and
/// the table's 6 decimals.
#[test]
fn rdf_table_is_the_mean_of_ovitos() {
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("gr.csv");
    let file = md_data("rdf/mixture.xyz");
    run_ok(&[
        "convert",
        &file,
        "--rdf",
        "6",
        "--rdf-bins",
        "60",
        "--rdf-partial",
        "--rdf-table",
        table.to_str().unwrap(),
        "-q",
    ]);
    let text = std::fs::read_to_string(&table).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "r,g,g_O-O,g_O-Si,g_Si-Si");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 60);
    let reference: serde_json::Value = json("rdf/rdf_reference.json");
    let entries: Vec<&serde_json::Value> = reference
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["file"] == "mixture.xyz")
        .collect();
    assert_eq!(entries.len(), 2);
    let frame = &frames(Path::new(&file))[0];
    let volume = frame.cell.as_ref().unwrap().volume();
    let (n, n_si, n_o) = (1500.0, 1000.0, 500.0);
    let column = |e: &serde_json::Value, name: &str| -> Vec<f64> {
        if name == "total" {
            return numbers(&e["total"]);
        }
        let k = e["columns"]
            .as_array()
            .unwrap()
            .iter()
            .position(|c| c == name)
            .unwrap();
        numbers(&e["g"][k])
    };
    // Our column, OVITO's name, and the ordered pairs' density for counting.
    for (col, name, pairs) in [
        (1, "total", n * n),
        (2, "O-O", n_o * n_o),
        (3, "Si-O", 2.0 * n_si * n_o),
        (4, "Si-Si", n_si * n_si),
    ] {
        let mean: Vec<f64> = (0..60)
            .map(|k| entries.iter().map(|e| column(e, name)[k]).sum::<f64>() / 2.0)
            .collect();
        for (k, row) in rows.iter().enumerate() {
            assert!((row[0] - (k as f64 + 0.5) * 0.1).abs() < 1e-6);
            let (r0, r1) = (k as f64 * 0.1, (k + 1) as f64 * 0.1);
            let ideal =
                4.0 / 3.0 * std::f64::consts::PI * (r1.powi(3) - r0.powi(3)) * pairs / volume;
            // Pair ends summed over both frames: at most one pair per frame across an edge.
            let diff = (row[col] - mean[k]).abs() * ideal * 2.0;
            assert!(
                diff <= 4.0 + 1e-6 * ideal * 2.0 + 1e-9,
                "{name} bin {k}: {} vs OVITO {}",
                row[col],
                mean[k]
            );
        }
    }
}

/// A CSV table's rows after its header, as numbers (empty fields NaN), and the header.
fn table(path: &Path) -> (String, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (header, rows)
}

/// `--msd-table`: the mean squared displacement of random walks that cross the faces of an
/// 18 Å box many times (written by MDAnalysis, wrapped into the box) equals MDAnalysis's, after
/// its NoJump transformation, for all atoms and per kind; and `--rmsd-table` equals
/// MDAnalysis's rms.RMSD, plain and mass-weighted.
#[test]
fn msd_and_rmsd_tables_are_mdanalysis() {
    let dir = tempfile::tempdir().unwrap();
    let msd = dir.path().join("msd.csv");
    run_ok(&[
        "convert",
        &md_data("dynamics/walk.dcd"),
        "--topology",
        &md_data("dynamics/walk.gro"),
        "--msd-table",
        msd.to_str().unwrap(),
        "-q",
    ]);
    let (header, rows) = table(&msd);
    assert_eq!(header, "frame,time,msd,msd_Na,msd_O");
    let reference: serde_json::Value = json("dynamics/msd_reference.json");
    let reference = reference.as_array().unwrap();
    assert_eq!(rows.len(), reference.len());
    for (row, r) in rows.iter().zip(reference) {
        assert_eq!(row[0], r["frame"].as_f64().unwrap());
        for (col, name) in [(2, "msd"), (3, "msd_NA"), (4, "msd_OW")] {
            // The kinds are the elements (the GRO has no types): Na, O.
            let want = r[name].as_f64().unwrap();
            // f32 positions, 6 decimals in the table.
            assert!(
                (row[col] - want).abs() <= 1e-5 * want.max(1.0),
                "frame {} {name}: {} vs MDAnalysis {want}",
                row[0],
                row[col]
            );
        }
    }
    // By the last frame the walks have gone far beyond half the box (9 Å): the unwrapping
    // counts, a wrapped displacement would be capped.
    assert!(rows.last().unwrap()[2] > 50.0);

    let rmsd: serde_json::Value = json("dynamics/rmsd_reference.json");
    for (extra, name) in [(None, "rmsd"), (Some("--align-mass"), "rmsd_mass")] {
        let out = dir.path().join(format!("{name}.csv"));
        let mut args = vec![
            "convert".to_string(),
            md_data("topo_mda.xtc"),
            "--topology".into(),
            md_data("topo_mda.gro"),
            "--align".into(),
            "all".into(),
            "--rmsd-table".into(),
            out.to_str().unwrap().into(),
            "-q".into(),
        ];
        args.extend(extra.map(String::from));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        run_ok(&args);
        let (header, rows) = table(&out);
        assert_eq!(header, "frame,time,rmsd");
        let want = rmsd[name].as_array().unwrap();
        assert_eq!(rows.len(), want.len());
        for (row, w) in rows.iter().zip(want) {
            let w = w.as_f64().unwrap();
            assert!(
                (row[2] - w).abs() <= 2e-6,
                "{name} frame {}: {} vs MDAnalysis {w}",
                row[0],
                row[2]
            );
        }
    }
}

/// `--rmsf-table` after `--align all` equals MDAnalysis's rms.RMSF after align.AlignTraj on all
/// atoms, atom by atom; `--property rmsf=TABLE.csv` reads the column back, so a selection by
/// it keeps the atoms MDAnalysis's values pick.
#[test]
fn rmsf_table_is_mdanalysis_and_reads_back_as_a_property() {
    let dir = tempfile::tempdir().unwrap();
    let rmsf = dir.path().join("rmsf.csv");
    let traj = md_data("topo_mda.xtc");
    let gro = md_data("topo_mda.gro");
    run_ok(&[
        "convert",
        &traj,
        "--topology",
        &gro,
        "--align",
        "all",
        "--rmsf-table",
        rmsf.to_str().unwrap(),
        "-q",
    ]);
    let text = std::fs::read_to_string(&rmsf).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("atom,id,name,resname,resid,chain,rmsf"));
    let want = numbers(&json("dynamics/rmsf_reference.json")["rmsf"]);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), want.len());
    let first = &frames(Path::new(&gro))[0];
    for (i, (row, want)) in rows.iter().zip(&want).enumerate() {
        assert_eq!(row[0], i.to_string());
        assert_eq!(row[2], first.names[i].to_string());
        let got: f64 = row[6].parse().unwrap();
        assert!(
            // 6 decimals in the table; without --align the values differ by up to 0.09 Å.
            (got - want).abs() < 2e-6,
            "atom {i}: {got} vs MDAnalysis {want}"
        );
    }
    let cut = 0.5;
    let kept = want.iter().filter(|v| **v > cut).count();
    assert!(kept > 0 && kept < want.len(), "{kept} of {}", want.len());
    let out = dir.path().join("mobile.xyz");
    run_ok(&[
        "convert",
        &traj,
        "--topology",
        &gro,
        "--property",
        &format!("rmsf={}", rmsf.display()),
        "--select",
        &format!("prop rmsf > {cut}"),
        "--frames",
        "0",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(frames(&out)[0].n_atoms(), kept);
    // A header without the property's column is named in the error.
    let o = texmap(&[
        "convert",
        &traj,
        "--topology",
        &gro,
        "--property",
        &format!("bfactor={}", rmsf.display()),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("none named bfactor"), "{}", stderr(&o));
}

/// `--profile-table`: the mass density profile of the random walks across z in 72 slabs
/// equals MDAnalysis's LinearDensity (0.25 Å bins) averaged over the 40 frames, for all atoms
/// and per kind (its mass densities over the masses it guessed), at the same slab centres;
/// another axis, a file without a cell and --align are refused or handled as documented.
#[test]
fn density_profile_is_mdanalysis_linear_density() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("profile.csv");
    let walk = [
        "convert",
        &md_data("dynamics/walk.dcd"),
        "--topology",
        &md_data("dynamics/walk.gro"),
        "--profile-table",
        out.to_str().unwrap(),
        "--profile-bins",
        "72",
        "-q",
    ];
    run_ok(&walk);
    let (header, rows) = table(&out);
    assert_eq!(header, "z,number,mass,number_Na,number_O");
    let reference = json("dynamics/profile_reference.json");
    let edges = numbers(&reference["edges"]);
    let mass = numbers(&reference["mass"]);
    assert_eq!(rows.len(), 72);
    // MDAnalysis's guessed masses (O 15.999, Na 22.98977) and its unit conversion.
    let g_per_cm3 = 1.660_539_066_60;
    for (col, name, m) in [(3, "mass_NA", 22.98977), (4, "mass_OW", 15.999)] {
        let want = numbers(&reference[name]);
        for (b, (row, want)) in rows.iter().zip(&want).enumerate() {
            let got = row[col] * m * g_per_cm3;
            assert!(
                (got - want).abs() < 1e-6,
                "slab {b} {name}: {got} vs {want}"
            );
        }
    }
    for (b, row) in rows.iter().enumerate() {
        assert!((row[0] - 0.5 * (edges[b] + edges[b + 1])).abs() < 1e-4);
        assert!(
            (row[2] - mass[b]).abs() < 1e-6,
            "slab {b}: {} vs MDAnalysis {}",
            row[2],
            mass[b]
        );
    }
    // Along x the same atoms give the same mean: total mass over the box.
    let mut across = walk.to_vec();
    across.extend(["--profile-axis", "x"]);
    run_ok(&across);
    let (header, rows) = table(&out);
    assert!(header.starts_with("x,number,mass"));
    let mean = |rows: &[Vec<f64>]| rows.iter().map(|r| r[2]).sum::<f64>() / rows.len() as f64;
    let want = mass.iter().sum::<f64>() / mass.len() as f64;
    assert!((mean(&rows) - want).abs() < 1e-6);

    let mut aligned = walk.to_vec();
    aligned.extend(["--align", "all"]);
    assert_eq!(texmap(&aligned).status.code(), Some(2));
    std::fs::remove_file(&out).unwrap();
    let o = texmap(&[
        "convert",
        &md_data("ase_plain.xyz"),
        "--profile-table",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no cell"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// A per-kind table's columns are the first frame's kinds: a later frame with an atom of
/// another kind (a LAMMPS dump whose atom changed type) is refused, naming frame and atom,
/// rather than its atom left out of every column.
#[test]
fn a_kind_the_first_frame_lacked_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let dump = dir.path().join("types.lammpstrj");
    let frame = |step: u32, second: u32| {
        format!(
            "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\nITEM: ATOMS id type x y z\n1 1 1 1 1\n2 {second} 5 5 5\n"
        )
    };
    std::fs::write(&dump, frame(0, 1) + &frame(10, 2)).unwrap();
    for flag in ["--profile-table", "--msd-table"] {
        let out = dir.path().join("t.csv");
        let o = texmap(&[
            "convert",
            dump.to_str().unwrap(),
            flag,
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(1), "{flag}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains(&format!("{flag}: frame 1's atom 1 is of kind 2")) && e.contains("(1)"),
            "{e}"
        );
        assert!(!out.exists());
    }
}

/// `--dihedral-table`: the φ and ψ of a 23-residue protein (PDB 3JQH with noise, written by
/// MDAnalysis) in every one of 12 frames equal MDAnalysis's Ramachandran for residues 2–22,
/// and ω its Dihedral over each residue's omega_selection(); the termini leave the angle they
/// lack empty.
#[test]
fn dihedral_table_is_mdanalysis_ramachandran() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rama.csv");
    run_ok(&[
        "convert",
        &md_data("dihedrals/helix.dcd"),
        "--topology",
        &md_data("dihedrals/helix.pdb"),
        "--dihedral-table",
        out.to_str().unwrap(),
        "-q",
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("frame,time,chain,resid,resname,phi,psi,omega")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 12 * 23);
    let reference = json("dihedrals/ramachandran_reference.json");
    let resids = numbers(&reference["resids"]);
    let omega_resids = numbers(&reference["omega_resids"]);
    // Angles on the circle: -180 and 180 are the same.
    let near = |a: f64, b: f64| ((a - b + 540.0) % 360.0 - 180.0).abs() < 2e-3;
    for f in 0..12 {
        let frame: Vec<&Vec<&str>> = rows.iter().filter(|r| r[0] == f.to_string()).collect();
        assert_eq!(frame.len(), 23);
        let row = |resid: f64| {
            frame
                .iter()
                .find(|r| r[3].parse::<f64>().unwrap() == resid)
                .unwrap()
        };
        let angles = reference["angles"][f].as_array().unwrap();
        for (k, resid) in resids.iter().enumerate() {
            let want = numbers(&angles[k]);
            let r = row(*resid);
            for (col, w) in [(5, want[0]), (6, want[1])] {
                let got: f64 = r[col].parse().unwrap();
                assert!(
                    near(got, w),
                    "frame {f} residue {resid} col {col}: {got} vs {w}"
                );
            }
        }
        let omega = numbers(&reference["omega"][f]);
        for (resid, want) in omega_resids.iter().zip(&omega) {
            let got: f64 = row(*resid)[7].parse().unwrap();
            assert!(
                near(got, *want),
                "frame {f} residue {resid} omega: {got} vs {want}"
            );
        }
        assert_eq!(row(1.0)[5], "", "the first residue has no phi");
        assert_eq!(
            (row(23.0)[6], row(23.0)[7]),
            ("", ""),
            "the last has no psi, omega"
        );
    }
}

/// `--msd-lags`: the mean squared displacement over every time origin of the same random
/// walks equals MDAnalysis's EinsteinMSD (the direct sum, fft=False) per lag, for all atoms
/// and per kind, and the diffusion coefficients printed equal a least-squares line through
/// MDAnalysis's curve over the same window (and the walk's own: 0.7² Å² per axis per ps, so
/// 6 D = 1.47 Å²/ps). A narrower --msd-fit fits fewer lags; too little memory, or --shard,
/// is refused and leaves no file.
#[test]
fn msd_over_every_origin_is_mdanalysis_einstein_msd() {
    let dir = tempfile::tempdir().unwrap();
    let lags = dir.path().join("lags.csv");
    let walk = [
        "convert",
        &md_data("dynamics/walk.dcd"),
        "--topology",
        &md_data("dynamics/walk.gro"),
        "--msd-lags",
        lags.to_str().unwrap(),
    ];
    let o = texmap(&walk);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = table(&lags);
    assert_eq!(header, "lag,time,msd,msd_Na,msd_O");
    let reference = json("dynamics/msd_lags_reference.json");
    let time = numbers(&reference["time"]);
    assert_eq!(rows.len(), time.len());
    for (col, name) in [(2, "msd"), (3, "msd_NA"), (4, "msd_OW")] {
        let want = numbers(&reference[name]);
        for (m, (row, want)) in rows.iter().zip(&want).enumerate() {
            assert_eq!(row[0], m as f64);
            assert!((row[1] - time[m]).abs() < 1e-5, "lag {m}: time {}", row[1]);
            assert!(
                (row[col] - want).abs() <= 1e-5 * want.max(1.0),
                "lag {m} {name}: {} vs MDAnalysis {want}",
                row[col]
            );
        }
    }
    // Printed as "D = 2.4526 × 10⁻⁵ cm²/s for every atom (… 32 lags)", then per kind.
    let printed: Vec<(f64, String)> = stderr(&o)
        .lines()
        .filter_map(|l| {
            let rest = l.split_once("D = ")?.1;
            let (d, rest) = rest.split_once(' ')?;
            let lags = rest.rsplit_once(", ")?.1;
            Some((d.parse().ok()?, lags.to_string()))
        })
        .collect();
    assert_eq!(printed.len(), 3, "{}", stderr(&o));
    for ((d, lags), name) in printed.iter().zip(["D_msd", "D_msd_Na", "D_msd_OW"]) {
        let name = name.replace("Na", "NA");
        let want = reference[name.as_str()].as_f64().unwrap();
        assert!((d - want).abs() < 1e-3, "{name}: {d} vs {want}");
        assert_eq!(lags, "32 lags)");
    }
    assert!((printed[0].0 - 1.47 / 6.0 * 10.0).abs() < 0.1 * 2.45);

    let mut narrow = walk.to_vec();
    narrow.extend(["--msd-fit", "5:10"]);
    let o = texmap(&narrow);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("over 5–10 ps, 6 lags)"),
        "{}",
        stderr(&o)
    );

    // texmap render writes the same table beside its frames.
    let rendered = dir.path().join("rendered.csv");
    let frames = dir.path().join("f%04d.png");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", walk[1], walk[2], walk[3], "--size", "64x48"];
        args.extend(["--msd-lags", rendered.to_str().unwrap()]);
        args.extend(["-o", frames.to_str().unwrap(), "-q"]);
        args.extend(extra);
        texmap(&args)
    };
    let o = render(&[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&rendered).unwrap(),
        std::fs::read(&lags).unwrap()
    );
    std::fs::remove_file(&rendered).unwrap();
    let o = render(&["--shard", "1/2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!rendered.exists());

    std::fs::remove_file(&lags).unwrap();
    for (extra, code) in [
        (&["--msd-memory", "0"][..], 1),
        (&["--msd-fit", "10:5"][..], 2),
        (&["--msd-fit", "-1:5"][..], 2),
    ] {
        let mut args = walk.to_vec();
        args.extend(extra);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(code), "{extra:?}: {}", stderr(&o));
        assert!(!lags.exists(), "{extra:?} left {}", lags.display());
    }
}

/// `--vacf-table` and `--vdos-table` of Langevin dynamics written by MDAnalysis as a .trr with
/// velocities (md-io's dynamics/gen_vacf.py): the autocorrelation per lag equals tidynamics'
/// over every origin, the printed Green–Kubo coefficients numpy's trapezoid of it, the spectrum
/// numpy's transform of the padded series (mass-weighted over every atom), its peaks the
/// springs' 3 and 10 THz; render writes the same tables; a trajectory without velocities, an
/// aligned run and a split run are refused and leave no file.
#[test]
fn vacf_and_vdos_tables_are_tidynamics_and_numpys() {
    let dir = tempfile::tempdir().unwrap();
    let vacf = dir.path().join("vacf.csv");
    let vdos = dir.path().join("vdos.csv");
    let run = [
        "convert",
        &md_data("dynamics/vel.trr"),
        "--topology",
        &md_data("dynamics/vel.gro"),
        "--vacf-table",
        vacf.to_str().unwrap(),
        "--vdos-table",
        vdos.to_str().unwrap(),
    ];
    let o = texmap(&run);
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = json("dynamics/vacf_reference.json");
    let columns = [("all", 2), ("HW", 3), ("NA", 4), ("OW", 5)];

    let (header, rows) = table(&vacf);
    assert_eq!(header, "lag,time,vacf,vacf_H,vacf_Na,vacf_O");
    let time = numbers(&reference["lag_time"]);
    assert_eq!(rows.len(), time.len());
    for (name, col) in columns {
        let want = numbers(&reference["vacf"][name]);
        let scale = want[0];
        for (m, (row, want)) in rows.iter().zip(&want).enumerate() {
            assert_eq!(row[0], m as f64);
            assert!((row[1] - time[m]).abs() < 1e-5, "lag {m}: time {}", row[1]);
            assert!(
                (row[col] - want).abs() <= 1e-6 * scale,
                "lag {m} {name}: {} vs tidynamics {want}",
                row[col]
            );
        }
    }
    // "D = 4.5315 × 10⁻⁵ cm²/s for every atom (Green–Kubo, ⅓ ∫ C(t) dt over 0–1.6 ps)".
    let printed: Vec<f64> = stderr(&o)
        .lines()
        .filter(|l| l.contains("Green–Kubo"))
        .filter_map(|l| l.split_once("D = ")?.1.split_once(' ')?.0.parse().ok())
        .collect();
    assert_eq!(printed.len(), 4, "{}", stderr(&o));
    for ((name, _), d) in columns.iter().zip(&printed) {
        let want = reference["d_green_kubo"][name].as_f64().unwrap();
        assert!((d - want).abs() < 2e-4, "{name}: D {d} vs numpy {want}");
    }

    let (header, rows) = table(&vdos);
    assert_eq!(header, "frequency,wavenumber,vdos,vdos_H,vdos_Na,vdos_O");
    let frequency = numbers(&reference["frequency"]);
    assert_eq!(rows.len(), frequency.len());
    for (name, col) in columns {
        let want = numbers(&reference["vdos"][name]);
        let top = want.iter().cloned().fold(0.0, f64::max);
        for (k, (row, want)) in rows.iter().zip(&want).enumerate() {
            assert!((row[0] - frequency[k]).abs() < 1e-6 * frequency[k].max(1.0));
            assert!((row[1] / row[0].max(1e-30) - 33.356_41).abs() < 1e-4 || k == 0);
            assert!(
                (row[col] - want).abs() <= 1e-6 * top,
                "bin {k} {name}: {} vs numpy {want}",
                row[col]
            );
        }
    }
    for (name, col, thz) in [("HW", 3, 10.0), ("OW", 5, 3.0)] {
        let peak = (1..rows.len())
            .max_by(|&a, &b| rows[a][col].total_cmp(&rows[b][col]))
            .unwrap();
        let want = reference["peak_thz"][name].as_f64().unwrap();
        assert!((rows[peak][0] - want).abs() < 1e-6, "{name} peak");
        assert!(
            (rows[peak][0] - thz).abs() < 0.1,
            "{name}: {} THz",
            rows[peak][0]
        );
    }

    // texmap render writes the same tables beside its frames.
    let (rv, rd) = (dir.path().join("rv.csv"), dir.path().join("rd.csv"));
    let frames = dir.path().join("f%04d.png");
    let mut args = vec!["render", run[1], run[2], run[3], "--size", "48x32", "-q"];
    args.extend(["--frames", "::1", "-o", frames.to_str().unwrap()]);
    args.extend(["--vacf-table", rv.to_str().unwrap()]);
    args.extend(["--vdos-table", rd.to_str().unwrap()]);
    let o = texmap(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&rv).unwrap(), std::fs::read(&vacf).unwrap());
    assert_eq!(std::fs::read(&rd).unwrap(), std::fs::read(&vdos).unwrap());

    std::fs::remove_file(&vacf).unwrap();
    std::fs::remove_file(&vdos).unwrap();
    let walk = md_data("dynamics/walk.dcd");
    let walk_top = md_data("dynamics/walk.gro");
    for (swap, extra, code, says) in [
        (true, &[][..], 1, "frame 0 has no velocities"),
        (false, &["--align", "all"][..], 2, "--align"),
        (false, &["--shard", "1/2"][..], 2, "--shard"),
        (false, &["--vacf-integrate", "0"][..], 2, "above 0"),
    ] {
        let mut args = run.to_vec();
        if swap {
            args[1] = &walk;
            args[3] = &walk_top;
        }
        args.extend(extra);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(code), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{extra:?}: {}", stderr(&o));
        assert!(!vacf.exists() && !vdos.exists(), "{extra:?} left a table");
    }
}

/// `--sasa`: the solvent-accessible area per residue of a wwPDB chain equals MDTraj's
/// shrake_rupley(mode='residue') (md-io's sasa fixture), within a point of each atom's sphere;
/// `--sasa protein` measures MDAnalysis's solvated peptide without its water as MDTraj measures
/// the protein sliced out; the per-frame total is the residues' sum; the property colours a
/// render; a bad probe is a usage error and leaves no table.
#[test]
fn sasa_tables_are_mdtrajs() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("sasa/sasa_reference.json");
    let (total, residues) = (dir.path().join("t.csv"), dir.path().join("r.csv"));
    for (file, key, select) in [
        ("dssp/3gwiA.pdb.gz", "3gwiA.pdb.gz", "all"),
        ("select_mda.pdb", "select_mda.pdb protein", "protein"),
    ] {
        let o = texmap(&[
            "convert",
            &md_data(file),
            "--sasa",
            select,
            "--sasa-table",
            total.to_str().unwrap(),
            "--sasa-residue-table",
            residues.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let (header, rows) = table(&residues);
        assert_eq!(header, "frame,time,chain,resid,resname,sasa");
        let want = numbers(&reference[key]["residues"]);
        assert_eq!(rows.len(), want.len(), "{file}");
        for (k, (row, w)) in rows.iter().zip(&want).enumerate() {
            // One point of a 3.1 Å sphere is 0.126 Å²; a residue's atoms may each be one off.
            assert!(
                (row[5] - w).abs() < 0.6,
                "{file} residue {k}: {} vs MDTraj {w}",
                row[5]
            );
        }
        let (header, rows_total) = table(&total);
        assert_eq!(header, "frame,time,sasa");
        let want_total = reference[key]["total"].as_f64().unwrap();
        let sum: f64 = rows.iter().map(|r| r[5]).sum();
        assert!((rows_total[0][2] - sum).abs() < 0.01 * rows.len() as f64);
        assert!(
            (rows_total[0][2] - want_total).abs() < 1e-4 * want_total,
            "{file}"
        );
    }
    // The property colours a render and selects atoms.
    let png = dir.path().join("s.png");
    let o = texmap(&[
        "render",
        &md_data("dssp/3gwiA.pdb.gz"),
        "--color-by",
        "sasa",
        "--select",
        "prop sasa > 20",
        "--size",
        "64x48",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(&total).unwrap();
    let o = texmap(&[
        "convert",
        &md_data("dssp/3gwiA.pdb.gz"),
        "--sasa",
        "--sasa-probe",
        "-1",
        "--sasa-table",
        total.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!total.exists());
}

/// `--gyration-table`: the radius of gyration and the asphericity of a protein and its CA atoms
/// over 12 frames equal MDAnalysis's (radius_of_gyration, asphericity; md-io's
/// dihedrals/gen_gyration.py), mass-weighted and not, with gmx gyrate's radii about the axes;
/// a selection that picks nothing is refused and leaves no table.
#[test]
fn gyration_table_is_mdanalysis() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rg.csv");
    let reference = json("dihedrals/gyration_reference.json");
    for (select, weighted) in [("protein", true), ("name CA", true), ("protein", false)] {
        let mut args = vec![
            "convert".to_string(),
            md_data("dihedrals/helix.dcd"),
            "--topology".into(),
            md_data("dihedrals/helix.pdb"),
            "--gyration-table".into(),
            out.to_str().unwrap().into(),
            "--gyration-select".into(),
            select.into(),
        ];
        if !weighted {
            args.push("--gyration-unweighted".into());
        }
        let args: Vec<&str> = args.iter().map(|a| a.as_str()).collect();
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let (header, rows) = table(&out);
        assert_eq!(header, "frame,time,rg,rg_x,rg_y,rg_z,asphericity");
        let want = reference[select]["frames"].as_array().unwrap();
        assert_eq!(rows.len(), want.len());
        for (f, (row, w)) in rows.iter().zip(want).enumerate() {
            let rg = if weighted { &w["rg"] } else { &w["unweighted"] };
            assert!(
                (row[2] - rg.as_f64().unwrap()).abs() < 1e-4,
                "{select} frame {f}"
            );
            if weighted {
                for (k, about) in numbers(&w["about"]).iter().enumerate() {
                    assert!(
                        (row[3 + k] - about).abs() < 1e-4,
                        "{select} frame {f} axis {k}"
                    );
                }
                let kappa = w["asphericity"].as_f64().unwrap();
                assert!(
                    (row[6] - kappa).abs() < 1e-5,
                    "{select} frame {f}: {}",
                    row[6]
                );
            }
        }
    }
    std::fs::remove_file(&out).unwrap();
    let o = texmap(&[
        "convert",
        &md_data("dihedrals/helix.dcd"),
        "--topology",
        &md_data("dihedrals/helix.pdb"),
        "--gyration-table",
        out.to_str().unwrap(),
        "--gyration-select",
        "resname HOH",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("none of the atoms"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `--cluster-table`: the copper clusters in iron (md-io's cluster fixture, written by OVITO)
/// have OVITO's sizes, largest first, frame by frame; the precipitate (every site within 6 Å
/// of (12, 13, 14)) is centred there, with about a solid sphere's radius of gyration
/// (√(3/5) · 6 = 4.65 Å; the lattice's sites and the solutes touching it make it 4.78).
#[test]
fn cluster_table_has_ovitos_sizes_and_the_precipitates_shape() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.csv");
    run_ok(&[
        "convert",
        &md_data("clusters/fecu.xyz"),
        "--clusters",
        "2.9",
        "--cluster-atoms",
        "element Cu",
        "--cluster-table",
        out.to_str().unwrap(),
        "-q",
    ]);
    let (header, rows) = table(&out);
    assert_eq!(header, "frame,cluster,atoms,x,y,z,rg");
    let reference: serde_json::Value = json("clusters/clusters_reference.json");
    let fecu = reference
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["file"] == "fecu.xyz")
        .unwrap();
    let sizes: Vec<f64> = numbers(&fecu["sizes"]);
    assert_eq!(rows.iter().map(|r| r[2]).collect::<Vec<_>>(), sizes);
    assert!(
        rows.iter()
            .enumerate()
            .all(|(k, r)| r[0] == 0.0 && r[1] == k as f64)
    );
    let big = &rows[0];
    for (got, want) in big[3..6].iter().zip([12.0, 13.0, 14.0]) {
        assert!((got - want).abs() < 0.2, "{big:?}");
    }
    assert!((big[6] - (0.6f64).sqrt() * 6.0).abs() < 0.2, "{big:?}");
    // Single solutes: a radius of gyration of 0.
    assert!(rows.iter().filter(|r| r[2] == 1.0).all(|r| r[6] == 0.0));
}

/// `--density-map` is MDAnalysis's DensityAnalysis (md-io's tests/data/volume/gen_dx.py wrote
/// its OpenDX file): the same grid and every cell's density, and the NA positions that left
/// the grid of frame 0's atoms counted as MDAnalysis's numpy count gives them; `texmap info`
/// and `--volume ... --isosurface` read the map back; bad values are usage errors.
#[test]
fn density_map_is_mdanalysis_density_analysis() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("na.dx");
    let (dcd, gro) = (md_data("dynamics/walk.dcd"), md_data("dynamics/walk.gro"));
    let args = [
        "convert",
        &dcd,
        "--topology",
        &gro,
        "--density-map",
        map.to_str().unwrap(),
        "--density-select",
        "name NA",
        "--density-padding",
        "0",
    ];
    let o = texmap(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = json("volume/density_reference.json");
    let outside = reference["na"]["outside"].as_u64().unwrap();
    assert!(
        stderr(&o).contains(&format!("{outside} of 4000 positions fell outside")),
        "{}",
        stderr(&o)
    );
    let ours = &texmap_md_io::volume::read_volumes(&map).unwrap().1[0];
    let theirs = &texmap_md_io::volume::read_volumes(md_data("volume/density_na.dx.gz"))
        .unwrap()
        .1[0];
    assert_eq!(ours.dims, theirs.dims);
    for a in 0..3 {
        assert!((ours.origin[a] - theirs.origin[a]).abs() < 1e-5);
        assert_eq!(ours.steps[a], theirs.steps[a]);
    }
    // One position in another cell moves two values by 1 / (40 frames · 1 Å³).
    for (i, (a, b)) in ours.data.iter().zip(&theirs.data).enumerate() {
        assert!((a - b).abs() < 1e-5, "cell {i}: {a} vs MDAnalysis {b}");
    }
    // In other units: MDAnalysis's factors (MDAnalysis.units.densityUnit_factor, 2.11).
    for (unit, factor) in [
        ("water", 30.00628806551247f64),
        ("TIP4P", 29.886382818497438),
        ("molar", 1660.5389210321898),
        ("nm^-3", 1000.0),
    ] {
        let scaled = dir.path().join(format!("na_{}.dx", unit.replace('^', "")));
        let mut a = args.to_vec();
        a.extend(["--density-units", unit, "-q"]);
        a[5] = scaled.to_str().unwrap();
        run_ok(&a);
        let v = &texmap_md_io::volume::read_volumes(&scaled).unwrap().1[0];
        for (i, (x, y)) in v.data.iter().zip(&ours.data).enumerate() {
            let (x, want) = (f64::from(*x), f64::from(*y) * factor);
            assert!(
                (x - want).abs() <= 2e-6 * factor,
                "{unit} cell {i}: {x} vs {want}"
            );
        }
        assert!(
            std::fs::read_to_string(&scaled)
                .unwrap()
                .contains(&format!("({unit})"))
        );
    }
    let info = texmap(&["info", map.to_str().unwrap()]);
    assert!(info.status.success(), "{}", stderr(&info));
    let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(v["format"], "OpenDX");
    assert_eq!(numbers(&v["volumes"][0]["points"]), [18.0, 18.0, 18.0]);
    let png = dir.path().join("iso.png");
    run_ok(&[
        "render",
        &gro,
        "--volume",
        map.to_str().unwrap(),
        "--isosurface",
        "0.1",
        "--size",
        "96x72",
        "-o",
        png.to_str().unwrap(),
        "-q",
    ]);
    assert!(png.exists());
    // Usage: a negative margin, a cell width of 0 (exit 2); nothing selected (exit 1).
    for (flag, value, code) in [
        ("--density-padding", "-1", 2),
        ("--density-delta", "0", 2),
        ("--density-select", "name XX", 1),
    ] {
        let mut a = args.to_vec();
        let at = a.iter().position(|x| *x == flag).unwrap_or(a.len());
        if at < a.len() {
            a[at + 1] = value;
        } else {
            a.extend([flag, value]);
        }
        let o = texmap(&a);
        assert_eq!(
            o.status.code(),
            Some(code),
            "{flag} {value}: {}",
            stderr(&o)
        );
        assert!(stderr(&o).contains("density"), "{}", stderr(&o));
        assert!(!map.with_extension("dx.tmp").exists());
    }
}

/// `--contacts-table` is MDAnalysis's contacts.Contacts (md-io's
/// tests/data/dihedrals/gen_contacts.py): the backbone N–O contacts of frame 0 within 3.5 Å by
/// the hard cut (no longer than in frame 0) and by the radius, and the CA–CA contacts within
/// 4.5 Å by the soft cut (self pairs included, as MDAnalysis counts them), Q per frame of the
/// noisy helix; a --contacts without two
/// selections is a usage error.
#[test]
fn contacts_table_is_mdanalysis_native_contacts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("q.csv");
    let reference = json("dihedrals/contacts_reference.json");
    let (dcd, pdb) = (
        md_data("dihedrals/helix.dcd"),
        md_data("dihedrals/helix.pdb"),
    );
    let run = |extra: &[&str]| {
        let mut args = vec![
            "convert",
            &dcd,
            "--topology",
            &pdb,
            "--contacts-table",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        texmap(&args)
    };
    for (key, method) in [
        ("backbone_hbonds", "hard"),
        ("backbone_radius", "radius"),
        ("ca_soft", "soft"),
    ] {
        let r = &reference[key];
        let groups = format!(
            "{};{}",
            r["select_a"].as_str().unwrap(),
            r["select_b"].as_str().unwrap()
        );
        let radius = r["radius"].as_f64().unwrap().to_string();
        let o = run(&[
            "--contacts",
            &groups,
            "--contacts-radius",
            &radius,
            "--contacts-method",
            method,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let native = r["native"].as_u64().unwrap();
        assert!(
            stderr(&o).contains(&format!("{native} native contacts")),
            "{}",
            stderr(&o)
        );
        let (header, rows) = table(&out);
        assert_eq!(header, "frame,time,q");
        let want = numbers(&r["q"]);
        assert_eq!(rows.len(), want.len());
        for (f, (row, w)) in rows.iter().zip(&want).enumerate() {
            assert!(
                (row[2] - w).abs() < 2e-6,
                "{key} frame {f}: {} vs MDAnalysis {w}",
                row[2]
            );
        }
    }
    let o = run(&["--contacts", "name CA"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// `--survival-table` is the waterdynamics MDAKit's SurvivalProbability (md-io's
/// tests/data/dynamics/gen_survival.py): the OW atoms within 2 Å of an NA atom, selected every
/// frame through the periodic box, continuous and with gaps of 2 frames forgiven, at every lag
/// to 10.
#[test]
fn survival_table_is_the_waterdynamics_survival_probability() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sp.csv");
    let reference = json("dynamics/survival_reference.json");
    for inter in ["0", "2"] {
        let o = texmap(&[
            "convert",
            &md_data("dynamics/walk.dcd"),
            "--topology",
            &md_data("dynamics/walk.gro"),
            "--survival-table",
            out.to_str().unwrap(),
            "--survival-select",
            reference["select"].as_str().unwrap(),
            "--survival-max",
            "10",
            "--survival-intermittency",
            inter,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stderr(&o).contains("lifetime ∫S dτ"), "{}", stderr(&o));
        let (header, rows) = table(&out);
        assert_eq!(header, "lag,time,survival");
        let want = numbers(&reference[format!("intermittency_{inter}")]);
        assert_eq!(rows.len(), want.len());
        for (lag, (row, w)) in rows.iter().zip(&want).enumerate() {
            assert_eq!(row[0], lag as f64);
            assert!(
                (row[2] - w).abs() < 2e-6,
                "intermittency {inter}, lag {lag}: {} vs {w}",
                row[2]
            );
        }
    }
}

/// `--pca-table`, `--pca-projection`, `--pca-vectors` and `--pca-extremes` after `--align` on
/// the same atoms equal MDAnalysis's align.AlignTraj + analysis.pca.PCA (md-io's
/// data/pca/gen_pca.py: a bending, twisting helix, 80 frames, turned and moved at random),
/// on the CA atoms (the covariance matrix) and the backbone (the frames' products): every
/// variance, the cumulated fraction, the cosine content, every frame's projection, the
/// components (up to sign) and the mean; the extremes run from the smallest projection on PC1
/// to the largest, and the vectors read back as properties (a porcupine plot's input).
#[test]
fn pca_tables_are_mdanalysis_pca() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("pca/pca_reference.json");
    let (xtc, pdb) = (md_data("pca/helix_pca.xtc"), md_data("dihedrals/helix.pdb"));
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (t, p, v, x) = (
        path("pca.csv"),
        path("proj.csv"),
        path("vec.csv"),
        path("pc1.pdb"),
    );
    for sel in ["name CA", "backbone"] {
        let r = &reference[format!("aligned {sel}")];
        run_ok(&[
            "convert",
            &xtc,
            "--topology",
            &pdb,
            "--align",
            sel,
            "--pca-select",
            sel,
            "--pca-components",
            "3",
            "--pca-table",
            &t,
            "--pca-projection",
            &p,
            "--pca-vectors",
            &v,
            "--pca-extremes",
            &x,
            "-q",
        ]);
        let variance = numbers(&r["variance"]);
        let top = variance[0];
        let (header, rows) = table(Path::new(&t));
        assert_eq!(
            header,
            "component,variance,fraction,cumulated,cosine_content"
        );
        assert_eq!(rows.len(), variance.len().min(80), "{sel}");
        let cumulated = numbers(&r["cumulated_variance"]);
        let cosine = numbers(&r["cosine_content"]);
        for (k, row) in rows.iter().enumerate() {
            assert_eq!(row[0], (k + 1) as f64);
            // Six decimals in the table; the two XTC decoders may differ in a last f32 bit.
            assert!(
                (row[1] - variance[k]).abs() < 2e-6 + 1e-7 * top,
                "{sel} {k}"
            );
            assert!((row[3] - cumulated[k]).abs() < 2e-6, "{sel} {k}");
            if k < 3 {
                assert!((row[4] - cosine[k]).abs() < 2e-6, "{sel} {k}: {}", row[4]);
            } else {
                assert!(
                    row[4].is_nan(),
                    "{sel}: no cosine content past the components"
                );
            }
        }
        // The components, up to sign, and the mean, in the atoms' rows.
        let (header, rows) = table(Path::new(&v));
        assert!(
            header.ends_with(",mean_x,mean_y,mean_z,pc1x,pc1y,pc1z,pc2x,pc2y,pc2z,pc3x,pc3y,pc3z")
        );
        assert_eq!(rows.len(), 185);
        let picked: Vec<&Vec<f64>> = rows.iter().filter(|r| !r[6].is_nan()).collect();
        assert_eq!(picked.len() as u64, r["atoms"].as_u64().unwrap(), "{sel}");
        let mean = numbers(&r["mean"]);
        let mut signs = [0.0; 3];
        for (k, sign) in signs.iter_mut().enumerate() {
            let want = numbers(&r["components"][k]);
            let got: Vec<f64> = picked
                .iter()
                .flat_map(|row| row[9 + 3 * k..12 + 3 * k].to_vec())
                .collect();
            let dot: f64 = got.iter().zip(&want).map(|(a, b)| a * b).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-4, "{sel} pc{}: {dot}", k + 1);
            *sign = dot.signum();
        }
        let got_mean: Vec<f64> = picked.iter().flat_map(|row| row[6..9].to_vec()).collect();
        for (a, b) in got_mean.iter().zip(&mean) {
            assert!((a - b).abs() < 2e-4, "{sel}: mean {a} vs {b}");
        }
        // Every frame's projection.
        let (header, rows) = table(Path::new(&p));
        assert_eq!(header, "frame,time,pc1,pc2,pc3");
        let want = r["projections"].as_array().unwrap();
        assert_eq!(rows.len(), want.len());
        for (f, (row, w)) in rows.iter().zip(want).enumerate() {
            assert_eq!(row[0], f as f64);
            for k in 0..3 {
                let w = signs[k] * w[k].as_f64().unwrap();
                assert!(
                    (row[2 + k] - w).abs() < 1e-5 * top.sqrt(),
                    "{sel} frame {f} pc{}",
                    k + 1
                );
            }
        }
        // The extremes: 20 structures of the selected atoms from PC1's smallest projection to
        // its largest (coordinates to 0.001 Å in the PDB file).
        let (lo, hi) = rows
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), r| (a.min(r[2]), b.max(r[2])));
        let moved = frames(Path::new(&x));
        assert_eq!(moved.len(), 20);
        let pc1: Vec<f64> = picked.iter().flat_map(|row| row[9..12].to_vec()).collect();
        for (structure, t) in [(&moved[0], lo), (&moved[19], hi)] {
            assert_eq!(structure.n_atoms(), picked.len());
            let proj: f64 = structure
                .positions
                .iter()
                .flatten()
                .zip(&got_mean)
                .zip(&pc1)
                .map(|((p, m), v)| (f64::from(*p) - m) * v)
                .sum();
            assert!((proj - t).abs() < 0.01, "{sel}: {proj} vs {t}");
        }
    }
    // The vectors read back as properties: the CA atoms have them, the others none (NaN).
    let out = dir.path().join("ca.xyz");
    run_ok(&[
        "convert",
        &pdb,
        "--property",
        &format!("pc1x={v}"),
        "--select",
        "prop pc1x > -2",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(frames(&out)[0].n_atoms(), 92);
}

/// The principal component analysis refuses what it cannot do, before or after the frames,
/// and leaves none of its files.
#[test]
fn pca_bad_requests_are_refused_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let (xtc, pdb) = (md_data("pca/helix_pca.xtc"), md_data("dihedrals/helix.pdb"));
    let t = dir.path().join("pca.csv");
    let ts = t.to_str().unwrap();
    let bad_ext = dir.path().join("pc1.png");
    let cases: [(&[&str], i32, &str); 6] = [
        (
            &[
                "--pca-table",
                ts,
                "--pca-extremes",
                bad_ext.to_str().unwrap(),
            ],
            2,
            "--pca-extremes",
        ),
        (
            &[
                "--pca-table",
                ts,
                "--pca-extremes",
                "x.pdb",
                "--pca-components",
                "2",
                "--pca-mode",
                "3",
            ],
            2,
            "--pca-mode 3",
        ),
        (&["--pca-select", "name CA"], 2, "pca"),
        (
            &["--pca-table", ts, "--pca-select", "resname XYZ"],
            1,
            "none of the atoms",
        ),
        (
            &["--pca-table", ts, "--frames", "0"],
            1,
            "at least two frames",
        ),
        (
            &["--pca-table", ts, "--pca-select", "name CA and"],
            2,
            "--pca-select",
        ),
    ];
    for (extra, code, message) in cases {
        let mut args = vec!["convert", &xtc, "--topology", &pdb];
        args.extend(extra);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(code), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{extra:?}: {}", stderr(&o));
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{extra:?} left {left:?}");
    }
    // A render split over a Slurm array cannot hold every frame.
    let o = texmap(&[
        "render",
        &xtc,
        "--topology",
        &pdb,
        "--pca-table",
        ts,
        "--shard",
        "0/2",
        "-o",
        dir.path().join("f%02d.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--pca-table with --shard"),
        "{}",
        stderr(&o)
    );
}

/// `--dssp-table` equals MDAnalysis's DSSP frame by frame (md-io's
/// data/dssp/gen_trajectory.py) on the fraying helix (80 frames) and on adenylate kinase in
/// water made whole by `--pbc unwrap` (helices and a sheet); `--dssp-residue-table` holds the
/// same frames' shares per residue and `--dssp-timeline` draws them.
#[test]
fn dssp_tables_are_mdanalysis_dssp() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("dssp/trajectory_reference.json");
    for (key, traj, top, extra) in [
        ("helix", "pca/helix_pca.xtc", "dihedrals/helix.pdb", None),
        (
            "adk",
            "hbonds/adk_0_9.xtc",
            "hbonds/adk_top.gro.gz",
            Some("unwrap"),
        ),
    ] {
        let (ss, res, png) = (
            dir.path().join(format!("{key}.csv")),
            dir.path().join(format!("{key}_res.csv")),
            dir.path().join(format!("{key}.png")),
        );
        let (traj, top) = (md_data(traj), md_data(top));
        let mut args = vec![
            "convert",
            &traj,
            "--topology",
            &top,
            "--dssp-table",
            ss.to_str().unwrap(),
            "--dssp-residue-table",
            res.to_str().unwrap(),
            "--dssp-timeline",
            png.to_str().unwrap(),
            "-q",
        ];
        if let Some(pbc) = extra {
            args.extend(["--pbc", pbc]);
        }
        run_ok(&args);
        let r = &reference[key];
        let want: Vec<&str> = r["frames"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        let text = std::fs::read_to_string(&ss).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("frame,time,helix,strand,coil,ss"));
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len(), want.len(), "{key}");
        for (f, (row, want)) in rows.iter().zip(&want).enumerate() {
            assert_eq!(row[0], f.to_string());
            assert_eq!(row[5], *want, "{key} frame {f}");
            let count = |c: char| want.chars().filter(|x| *x == c).count().to_string();
            assert_eq!(
                row[2..5],
                [count('H'), count('E'), count('-')],
                "{key} frame {f}"
            );
        }
        // Each residue's shares over the frames, in MDAnalysis's residue order.
        let (header, shares) = table(&res);
        assert_eq!(header, "chain,resid,resname,helix,strand,coil");
        let resids = numbers(&r["resids"]);
        assert_eq!(shares.len(), resids.len());
        for (k, (row, resid)) in shares.iter().zip(&resids).enumerate() {
            assert_eq!(row[1], *resid);
            for (col, c) in [(3, 'H'), (4, 'E'), (5, '-')] {
                let n = want.iter().filter(|s| s.as_bytes()[k] as char == c).count();
                let share = n as f64 / want.len() as f64;
                assert!((row[col] - share).abs() < 6e-5, "{key} residue {resid} {c}");
            }
        }
        let img = image::open(&png).unwrap().to_rgb8();
        let purple = img.pixels().filter(|p| p.0 == [166, 0, 166]).count();
        assert!(purple > 10_000, "{key}: {purple} helix pixels");
        if key == "adk" {
            assert!(
                img.pixels().any(|p| p.0 == [255, 255, 0]),
                "adk's strands drawn"
            );
        }
    }
    // Without a protein backbone there is nothing to assign; a timeline needs an image name.
    let walk = md_data("dynamics/walk.gro");
    let o = texmap(&[
        "convert",
        &walk,
        "--dssp-table",
        dir.path().join("none.csv").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no residue with the backbone"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("none.csv").exists());
    let o = texmap(&[
        "convert",
        &walk,
        "--dssp-timeline",
        dir.path().join("ss.pdf").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("expected a .png or .svg"),
        "{}",
        stderr(&o)
    );
}

/// `--rmsd-matrix` over every second frame equals MDAnalysis's DistanceMatrix with a
/// superposing rms.rmsd (md-io's data/pca/gen_rmsd_matrix.py) to the table's four decimals;
/// `--rmsd-matrix-chart` draws it (PNG and SVG); a chart name of another kind is refused.
#[test]
fn rmsd_matrix_is_mdanalysis_distance_matrix() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("pca/rmsd_matrix_reference.json");
    let (xtc, pdb) = (md_data("pca/helix_pca.xtc"), md_data("dihedrals/helix.pdb"));
    let (csv, png, svg) = (
        dir.path().join("m.csv"),
        dir.path().join("m.png"),
        dir.path().join("m.svg"),
    );
    run_ok(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--frames",
        "::2",
        "--rmsd-matrix",
        csv.to_str().unwrap(),
        "--rmsd-matrix-chart",
        png.to_str().unwrap(),
        "-q",
    ]);
    let (header, rows) = table(&csv);
    let frames: Vec<String> = (0..80).step_by(2).map(|f| f.to_string()).collect();
    assert_eq!(header, format!("frame,{}", frames.join(",")));
    let want = numbers(&reference["matrix"]);
    assert_eq!(rows.len(), 40);
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row[0], (2 * i) as f64);
        for j in 0..40 {
            let w = want[40 * i + j];
            assert!(
                (row[1 + j] - w).abs() < 6e-5,
                "({i}, {j}): {} vs {w}",
                row[1 + j]
            );
        }
    }
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (900, 760));
    run_ok(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--frames",
        "::4",
        "--rmsd-matrix-chart",
        svg.to_str().unwrap(),
        "--rmsd-matrix-select",
        "backbone",
        "-q",
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.matches("<rect").count() >= 400);
    let bad = dir.path().join("m.pdf");
    let o = texmap(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--rmsd-matrix-chart",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--rmsd-matrix-chart"), "{}", stderr(&o));
    assert!(!bad.exists());
    // Past the memory limit the run stops at the frame that passes it, and writes nothing.
    std::fs::remove_file(&csv).unwrap();
    let o = texmap(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--rmsd-matrix",
        csv.to_str().unwrap(),
        "--msd-memory",
        "0",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("over the limit"), "{}", stderr(&o));
    assert!(!csv.exists());
}

/// `--rmsd-clusters`, `--rmsd-cluster-table` and `--rmsd-cluster-middles` agree with GROMACS
/// 2022.5's gmx cluster on the same file (md-io's data/conformations/gen_clusters.py), for the
/// gromos method and single linkage: every frame's cluster names the same frames as gmx's
/// -clid, the table's sizes, middle frames and mean RMSDs are gmx's cluster.log, and the
/// middles are those frames' atoms. A cutoff of 0 and a middles name of no format are refused
/// before anything is read, and a run that stops leaves no file.
#[test]
fn rmsd_clusters_are_gmx_cluster() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("conformations/clusters_reference.json");
    let (xtc, pdb) = (
        md_data("conformations/states.xtc"),
        md_data("dihedrals/helix.pdb"),
    );
    let input = frames(Path::new(&xtc));
    let (clid, table_csv, middles) = (
        dir.path().join("clid.csv"),
        dir.path().join("clusters.csv"),
        dir.path().join("middles.pdb"),
    );
    for run in reference["runs"].as_array().unwrap() {
        let method = run["method"].as_str().unwrap();
        let cutoff = format!("{}", 10.0 * run["cutoff_nm"].as_f64().unwrap());
        run_ok(&[
            "convert",
            &xtc,
            "--topology",
            &pdb,
            "--rmsd-clusters",
            clid.to_str().unwrap(),
            "--rmsd-cluster-table",
            table_csv.to_str().unwrap(),
            "--rmsd-cluster-middles",
            middles.to_str().unwrap(),
            "--rmsd-cluster-method",
            method,
            "--rmsd-cluster-cutoff",
            &cutoff,
            "-q",
        ]);
        let what = format!("{method} at {cutoff} Å");
        // Each frame's cluster, as sets of frames, is gmx's -clid.
        let (header, rows) = table(&clid);
        assert_eq!(header, "frame,time,cluster");
        assert_eq!(rows.len(), 200);
        let theirs = numbers(&run["cluster_of_frame"]);
        let sets = |ids: &[f64]| {
            let mut by: std::collections::BTreeMap<u64, Vec<usize>> = Default::default();
            for (f, &c) in ids.iter().enumerate() {
                by.entry(c as u64).or_default().push(f);
            }
            by.into_values().collect::<std::collections::BTreeSet<_>>()
        };
        let ours: Vec<f64> = rows.iter().map(|r| r[2]).collect();
        assert_eq!(sets(&ours), sets(&theirs), "{what}");
        for (k, r) in rows.iter().enumerate() {
            assert_eq!(
                (r[0], r[1]),
                (k as f64, 5.0 * k as f64),
                "{what}: frame, time"
            );
        }
        // The table: gmx's sizes (in its order), middles and mean RMSDs (nm, three decimals).
        let (_, clusters) = table(&table_csv);
        let gmx = run["clusters"].as_array().unwrap();
        assert_eq!(clusters.len(), gmx.len(), "{what}");
        for (k, g) in gmx.iter().enumerate() {
            let members = numbers(&g["members"]);
            let id = ours[members[0] as usize];
            let row = &clusters[id as usize - 1];
            assert_eq!(row[1], members.len() as f64, "{what}: cluster {}", k + 1);
            assert_eq!(clusters[k][1], members.len() as f64, "{what}: gmx's order");
            assert_eq!(row[3], g["middle"].as_f64().unwrap(), "{what}: middle");
            assert_eq!(row[4], 5.0 * row[3], "{what}: middle time");
            assert_eq!((row[8], row[9]), (members[0], *members.last().unwrap()));
            for (col, key) in [(6, "mean_rmsd_nm"), (5, "middle_rmsd_nm")] {
                let want = g[key].as_f64().map_or(0.0, |nm| 10.0 * nm);
                assert!((row[col] - want).abs() <= 0.0051, "{what}: {key}");
            }
        }
        let fractions: f64 = clusters.iter().map(|r| r[2]).sum();
        assert!((fractions - 1.0).abs() < 1e-5);
        // The middles: one model per cluster, the middle frame's every atom.
        let written = frames(&middles);
        assert_eq!(written.len(), gmx.len(), "{what}");
        for (row, model) in clusters.iter().zip(&written) {
            let source = &input[row[3] as usize];
            assert_eq!(model.n_atoms(), 185);
            for (a, b) in model.positions.iter().zip(&source.positions) {
                for d in 0..3 {
                    assert!((a[d] - b[d]).abs() < 6e-4, "{what}: PDB's 3 decimals");
                }
            }
        }
    }
    // Refused before reading: no cutoff, a middles name of no format, --shard.
    for (flag, value, said) in [
        ("--rmsd-cluster-cutoff", "0", "--rmsd-cluster-cutoff"),
        ("--rmsd-cluster-middles", "m.nope", "--rmsd-cluster-middles"),
        ("--shard", "1/2", "--shard"),
    ] {
        let bad = dir.path().join("bad.csv");
        let mut args = vec![
            "convert",
            &xtc,
            "--topology",
            &pdb,
            "--rmsd-clusters",
            bad.to_str().unwrap(),
            flag,
            value,
        ];
        if flag == "--shard" {
            args.extend(["-o", "shard.xyz"]);
        }
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{flag}: {}", stderr(&o));
        assert!(stderr(&o).contains(said), "{flag}: {}", stderr(&o));
        assert!(!bad.exists(), "{flag}");
    }
    // Past the memory limit the middles' frames stop the run: no file is left.
    for p in [&clid, &table_csv, &middles] {
        std::fs::remove_file(p).unwrap();
    }
    let o = texmap(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--rmsd-clusters",
        clid.to_str().unwrap(),
        "--rmsd-cluster-middles",
        middles.to_str().unwrap(),
        "--msd-memory",
        "0",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--rmsd-clusters: frame 0"),
        "{}",
        stderr(&o)
    );
    assert!(!clid.exists() && !middles.exists());
}

/// `--pca-landscape-table` bins the frames' PC1–PC2 projections as NumPy's histogram2d bins
/// MDAnalysis's (md-io's data/pca/gen_landscape.py: the same frames after the same alignment,
/// each component's sign as MDAnalysis chose it), with ΔG = −RT ln(n / n_max) at 300 K;
/// `--pca-landscape` draws it; axes past the components computed are refused.
#[test]
fn pca_landscape_is_numpys_histogram_of_the_projections() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("pca/landscape_reference.json");
    let mda = json("pca/pca_reference.json");
    let (xtc, pdb) = (md_data("pca/helix_pca.xtc"), md_data("dihedrals/helix.pdb"));
    let (proj, fel, png) = (
        dir.path().join("proj.csv"),
        dir.path().join("fel.csv"),
        dir.path().join("fel.png"),
    );
    run_ok(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--align",
        "name CA",
        "--pca-projection",
        proj.to_str().unwrap(),
        "--pca-landscape-table",
        fel.to_str().unwrap(),
        "--pca-landscape",
        png.to_str().unwrap(),
        "--pca-landscape-bins",
        "12",
        "-q",
    ]);
    // Each component's sign against MDAnalysis's (eigenvectors have none of their own).
    let (_, p) = table(&proj);
    let theirs = mda["aligned name CA"]["projections"].as_array().unwrap();
    let sign: Vec<bool> = (0..2)
        .map(|k| {
            let dot: f64 = p
                .iter()
                .zip(theirs)
                .map(|(r, t)| r[2 + k] * t[k].as_f64().unwrap())
                .sum();
            dot < 0.0
        })
        .collect();
    let want = &reference["landscapes"][0];
    assert_eq!(want["bins"], 12);
    let counts = want["counts"].as_array().unwrap();
    let energy = want["free_energy"].as_array().unwrap();
    let (header, rows) = table(&fel);
    assert_eq!(header, "pc1,pc2,frames,free_energy");
    assert_eq!(rows.len(), 144);
    for (k, row) in rows.iter().enumerate() {
        // Rows go along pc1 first; a flipped component mirrors its bins.
        let (a, b) = (k % 12, k / 12);
        let i = if sign[0] { 11 - a } else { a };
        let j = if sign[1] { 11 - b } else { b };
        assert_eq!(row[2], counts[i][j].as_f64().unwrap(), "bin ({a}, {b})");
        match energy[i][j].as_f64() {
            Some(g) => assert!((row[3] - g).abs() < 6e-5, "{} vs {g}", row[3]),
            None => assert!(row[3].is_nan(), "an empty bin has no ΔG"),
        }
    }
    // The bin centres span the projections' range.
    let lo = p.iter().map(|r| r[2]).fold(f64::INFINITY, f64::min);
    let hi = p.iter().map(|r| r[2]).fold(f64::NEG_INFINITY, f64::max);
    assert!((rows[0][0] - (lo + (hi - lo) / 24.0)).abs() < 1e-3);
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (900, 760));
    // Axes past the components computed: refused before reading, nothing written.
    std::fs::remove_file(&fel).unwrap();
    let o = texmap(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--pca-landscape-table",
        fel.to_str().unwrap(),
        "--pca-landscape-axes",
        "1,4",
        "--pca-components",
        "3",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--pca-landscape-axes 1,4"),
        "{}",
        stderr(&o)
    );
    assert!(!fel.exists());
}

/// `--ramachandran` draws a dot at every residue's (φ, ψ) of `--dihedral-table` (whose angles
/// equal MDAnalysis's: md_inputs.rs) on adenylate kinase in water, and nowhere else;
/// `--ramachandran-select 'resname GLY'` keeps the glycines' alone. Refused under --shard and
/// when no residue has both angles.
#[test]
fn ramachandran_plot_has_a_dot_at_every_residues_angles() {
    let dir = tempfile::tempdir().unwrap();
    let (xtc, gro) = (
        md_data("hbonds/adk_0_9.xtc"),
        md_data("hbonds/adk_top.gro.gz"),
    );
    let (png, csv) = (dir.path().join("rama.png"), dir.path().join("rama.csv"));
    for select in ["protein", "resname GLY"] {
        run_ok(&[
            "convert",
            &xtc,
            "--topology",
            &gro,
            "--ramachandran",
            png.to_str().unwrap(),
            "--ramachandran-select",
            select,
            "--dihedral-table",
            csv.to_str().unwrap(),
            "-q",
        ]);
        let text = std::fs::read_to_string(&csv).unwrap();
        let angles: Vec<(f64, f64, bool)> = text
            .lines()
            .skip(1)
            .filter_map(|l| {
                let c: Vec<&str> = l.split(',').collect();
                Some((c[5].parse().ok()?, c[6].parse().ok()?, c[4] == "GLY"))
            })
            .collect();
        assert!(angles.len() > 400, "{}", angles.len());
        let img = image::open(&png).unwrap().to_rgb8();
        let (w, h) = img.dimensions();
        assert_eq!((w, h), (900, 760));
        // The plot area of study::chart's heatmap layout: x 76..884, y 16..700.
        let (x0, x1, y0, y1) = (76.0, 884.0, 16.0, 700.0);
        let at = |phi: f64, psi: f64| {
            (
                x0 + (phi + 180.0) / 360.0 * (x1 - x0),
                y0 + (180.0 - psi) / 360.0 * (y1 - y0),
            )
        };
        let ink = |x: u32, y: u32| img.get_pixel(x, y).0 == [0x1f, 0x3a, 0x93];
        let kept: Vec<(f64, f64)> = angles
            .iter()
            .filter(|a| select == "protein" || a.2)
            .map(|a| at(a.0, a.1))
            .collect();
        for &(x, y) in &kept {
            assert!(
                ink(x.round() as u32, y.round() as u32),
                "{select}: ({x}, {y})"
            );
        }
        // Every inked pixel belongs to the dot (3 px and its edge) of a residue kept.
        for y in 0..h {
            for x in 0..w {
                if ink(x, y) {
                    let near = kept
                        .iter()
                        .any(|&(px, py)| (px - x as f64).hypot(py - y as f64) < 7.0);
                    assert!(near, "{select}: stray ink at ({x}, {y})");
                }
            }
        }
    }
    for args in [
        vec!["--shard", "1/2", "-o", "rama.xyz"],
        vec!["--ramachandran-select", "resname SOL"],
    ] {
        std::fs::remove_file(&png).ok();
        let mut all = vec![
            "convert",
            &xtc,
            "--topology",
            &gro,
            "--ramachandran",
            png.to_str().unwrap(),
        ];
        all.extend(args.iter().copied());
        let o = texmap(&all);
        assert!(!o.status.success(), "{args:?}");
        assert!(stderr(&o).contains("--ramachandran"), "{}", stderr(&o));
        assert!(!png.exists(), "{args:?}");
    }
}

/// `--distance-map` and `--contact-map` on adenylate kinase in water (a truncated
/// octahedron) equal MDAnalysis's minimum-image distances reduced per residue pair (md-io's
/// data/distance_map: the same reference gmx mdmat agrees with) to the tables' decimals; the
/// charts are drawn; a selection of one residue is refused with no file left.
#[test]
fn residue_maps_are_mdanalysis_and_gmx_mdmat() {
    use std::io::Read;
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::new();
    flate2::read::GzDecoder::new(
        std::fs::File::open(md_data("distance_map/reference.json.gz")).unwrap(),
    )
    .read_to_string(&mut text)
    .unwrap();
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    let (xtc, gro) = (
        md_data("hbonds/adk_0_9.xtc"),
        md_data("hbonds/adk_top.gro.gz"),
    );
    let (dm, cm, dpng, csvg) = (
        dir.path().join("dm.csv"),
        dir.path().join("cm.csv"),
        dir.path().join("dm.png"),
        dir.path().join("cm.svg"),
    );
    run_ok(&[
        "convert",
        &xtc,
        "--topology",
        &gro,
        "--distance-map",
        dm.to_str().unwrap(),
        "--distance-map-chart",
        dpng.to_str().unwrap(),
        "--contact-map",
        cm.to_str().unwrap(),
        "--contact-map-chart",
        csvg.to_str().unwrap(),
        "-q",
    ]);
    let n = reference["residues"].as_u64().unwrap() as usize;
    for (path, key, tolerance) in [(&dm, "mean", 6e-4), (&cm, "contact_fraction", 6e-5)] {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(header.len(), n + 1);
        assert_eq!(
            (header[0], header[1], header[n]),
            ("residue", "MET1", "GLY214")
        );
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').skip(1).map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), n);
        // The reference holds the upper triangle row by row.
        let want = numbers(&reference[key]);
        let upper = (0..n).flat_map(|i| (i + 1..n).map(move |j| (i, j)));
        for ((i, j), w) in upper.zip(&want) {
            assert_eq!(rows[i][j], rows[j][i], "{key}: symmetric");
            assert!(
                (rows[i][j] - w).abs() <= tolerance,
                "{key} ({i}, {j}): {} vs {w}",
                rows[i][j]
            );
        }
        assert_eq!(want.len(), n * (n - 1) / 2);
    }
    let img = image::open(&dpng).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (900, 760));
    let svg = std::fs::read_to_string(&csvg).unwrap();
    assert!(svg.matches("<rect").count() > n * n / 2);
    // One residue is no map.
    std::fs::remove_file(&dm).unwrap();
    let o = texmap(&[
        "convert",
        &xtc,
        "--topology",
        &gro,
        "--distance-map",
        dm.to_str().unwrap(),
        "--distance-map-select",
        "resid 5",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("1 residue(s)"), "{}", stderr(&o));
    assert!(!dm.exists());
}

/// `texmap plot` draws a table texmap convert wrote (`--rmsd-table`): the SVG's polyline has a
/// point per frame, left to right in frame order, each as high as its RMSD ranks (the largest
/// highest); it reads gmx cluster's own .xvg file (axis labels from its `@` lines); a column
/// that does not exist, a cell that is not a number (named by line and column) and an image
/// name of another kind are refused with nothing written.
#[test]
fn plot_draws_convert_tables_and_gmx_xvg_files() {
    let dir = tempfile::tempdir().unwrap();
    let (xtc, pdb) = (md_data("pca/helix_pca.xtc"), md_data("dihedrals/helix.pdb"));
    let csv = dir.path().join("rmsd.csv");
    run_ok(&[
        "convert",
        &xtc,
        "--topology",
        &pdb,
        "--align",
        "name CA",
        "--rmsd-table",
        csv.to_str().unwrap(),
        "-q",
    ]);
    let (_, rows) = table(&csv);
    let rmsd: Vec<f64> = rows.iter().map(|r| r[2]).collect();
    let svg = dir.path().join("rmsd.svg");
    run_ok(&[
        "plot",
        csv.to_str().unwrap(),
        "-o",
        svg.to_str().unwrap(),
        "-q",
    ]);
    // The data's polyline: the one with a point per row.
    let lines = common::svg_polylines(&std::fs::read_to_string(&svg).unwrap());
    let data = lines
        .iter()
        .find(|l| l.len() == rmsd.len())
        .expect("a point per frame");
    assert!(
        data.windows(2).all(|w| w[1].0 > w[0].0),
        "frames left to right"
    );
    for i in 0..rmsd.len() {
        for j in 0..rmsd.len() {
            if rmsd[i] > rmsd[j] + 0.01 {
                assert!(data[i].1 < data[j].1, "frame {i} above frame {j}");
            }
        }
    }
    // gmx cluster's -clid file, as GROMACS 2022.5 wrote it.
    let png = dir.path().join("clid.png");
    run_ok(&[
        "plot",
        &md_data("conformations/gmx_clid.xvg"),
        "-o",
        png.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(
        image::open(&png).unwrap().to_rgb8().dimensions(),
        (960, 640)
    );
    // Bad requests.
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "frame,rmsd\n0,0.5\n1,abc\n").unwrap();
    let out = dir.path().join("out.png");
    for (args, code, said) in [
        (
            vec![csv.to_str().unwrap(), "--y", "nope"],
            2,
            "no column 'nope'",
        ),
        (
            vec![bad.to_str().unwrap()],
            1,
            "line 3: column 'rmsd' holds 'abc'",
        ),
    ] {
        let mut all = vec!["plot"];
        all.extend(args);
        all.extend(["-o", out.to_str().unwrap()]);
        let o = texmap(&all);
        assert_eq!(o.status.code(), Some(code), "{}", stderr(&o));
        assert!(stderr(&o).contains(said), "{}", stderr(&o));
        assert!(!out.exists());
    }
    let pdf = dir.path().join("out.pdf");
    let o = texmap(&["plot", csv.to_str().unwrap(), "-o", pdf.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!pdf.exists());
}

/// `--order-table` on md-io's model bilayer (data/order: 32 lipids split across the box, GRO +
/// XTC by MDAnalysis, bonds found by distance): S_CH per carbon equals numpy's to the table's
/// decimals, the united-atom construction equals `gmx order`'s −S_CD, the Martini-style bond
/// rows numpy's; bad requests are refused with no file left.
#[test]
fn order_table_is_gmx_order_and_numpys() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("order/reference.json");
    let (xtc, gro) = (md_data("order/bilayer.xtc"), md_data("order/bilayer.gro"));
    let (csv, svg) = (dir.path().join("order.csv"), dir.path().join("order.svg"));
    let rows = |method: &str| -> Vec<(String, Vec<f64>)> {
        run_ok(&[
            "convert",
            &xtc,
            "--topology",
            &gro,
            "--order-table",
            csv.to_str().unwrap(),
            "--order-select",
            "resname DPPC and name C2* C3*",
            "--order-method",
            method,
            "--order-chart",
            svg.to_str().unwrap(),
            "-q",
        ]);
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next(),
            Some("resname,atom,chain,position,sites,vectors,s,minus_s,sem")
        );
        lines
            .map(|l| {
                let c: Vec<&str> = l.split(',').collect();
                assert_eq!((c[0], c[4]), ("DPPC", "32"), "{l}");
                // CHARMM's names: C2n is carbon n of the first chain, C3n of the second.
                let name = c[1].split('-').next().unwrap();
                let chain = name[1..2].parse::<usize>().unwrap() - 1;
                assert_eq!(
                    (chain.to_string().as_str(), &name[2..]),
                    (c[2], c[3]),
                    "{l}"
                );
                let v = c[6..]
                    .iter()
                    .map(|x| x.parse().unwrap_or(f64::NAN))
                    .collect();
                (c[1].to_string(), v)
            })
            .collect()
    };
    let near = |a: f64, b: f64, tolerance: f64| (a - b).abs() <= tolerance;
    let h = rows("hydrogens");
    assert_eq!(h.len(), 28);
    for (name, v) in &h {
        let want = reference["hydrogens"][name].as_f64().unwrap();
        let sem = reference["sem"][name].as_f64().unwrap();
        assert!(
            near(v[0], want, 6e-7) && v[1] == -v[0],
            "{name}: {v:?} vs {want}"
        );
        assert!(near(v[2], sem, 6e-7), "{name}: {v:?} vs {sem}");
    }
    // The chart: a line per chain, a point per carbon.
    let chart = std::fs::read_to_string(&svg).unwrap();
    let long = common::svg_polylines(&chart)
        .iter()
        .filter(|l| l.len() == 14)
        .count();
    assert_eq!(long, 2, "{chart}");
    assert!(chart.contains("DPPC chain 2"));
    let ua = rows("united-atom");
    assert_eq!(ua.len(), 24);
    for (name, v) in &ua {
        let want = reference["gmx_order"][name].as_f64().unwrap();
        assert!(near(v[1], want, 3e-5), "{name}: {v:?} vs gmx {want}");
    }
    let b = rows("bonds");
    assert_eq!(b.len(), 26);
    assert_eq!(b[0].0, "C21-C22");
    for (name, v) in &b {
        let want = reference["bonds"][name].as_f64().unwrap();
        assert!(near(v[0], want, 6e-7), "{name}: {v:?} vs {want}");
    }
    // No hydrogens among the carbons' bonds with the united-atom file's selection, no table
    // without --order-select, a selection of nothing: refused, nothing written.
    std::fs::remove_file(&csv).unwrap();
    for (extra, says) in [
        (&["--order-select", "name P"][..], "bonded hydrogen"),
        (&["--order-select", "name XYZ"][..], "bonded hydrogen"),
        (&[][..], "--order-select"),
    ] {
        let mut args = vec![
            "convert",
            &xtc,
            "--topology",
            &gro,
            "--order-table",
            csv.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = texmap(&args);
        assert!(!o.status.success(), "{args:?}");
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
        assert!(!csv.exists(), "{args:?}");
    }
}

/// `--membrane-table` on the same bilayer: 16 lipids a leaflet (MDAnalysis's LeafletFinder's
/// sets), the thickness through the tails across the box's bottom face equal to the mean P
/// heights' difference before the shift (to the XTC's rounding), the area per lipid the box's
/// over 16; at the default 15 Å cutoff the heads (20 Å apart) form no leaflet: refused, no file.
#[test]
fn membrane_table_is_leaflet_finders_thickness_and_area() {
    let dir = tempfile::tempdir().unwrap();
    let reference = json("order/reference.json");
    let m = &reference["membrane"];
    let (xtc, gro) = (md_data("order/bilayer.xtc"), md_data("order/bilayer.gro"));
    let csv = dir.path().join("membrane.csv");
    let args = |cutoff: &'static str| {
        vec![
            "convert".to_string(),
            xtc.clone(),
            "--topology".into(),
            gro.clone(),
            "--membrane-table".into(),
            csv.to_str().unwrap().into(),
            "--membrane-cutoff".into(),
            cutoff.into(),
            "-q".into(),
        ]
    };
    let a = args("25");
    run_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let (header, rows) = table(&csv);
    assert_eq!(
        header,
        "frame,time,upper,lower,thickness,area,apl_upper,apl_lower"
    );
    let want = numbers(&m["thickness"]);
    assert_eq!(rows.len(), want.len());
    for (r, w) in rows.iter().zip(&want) {
        assert_eq!((r[2], r[3]), (16.0, 16.0));
        assert!((r[4] - w).abs() < 0.005, "{r:?} vs {w}");
        assert_eq!((r[5], r[6], r[7]), (6400.0, 400.0, 400.0));
    }
    std::fs::remove_file(&csv).unwrap();
    let a = args("15");
    let o = texmap(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no bilayer"), "{}", stderr(&o));
    assert!(!csv.exists());
}

#[test]
fn lammps_data_output_is_the_file_lammps_read() {
    // md-io/tests/data/lammps_write: LAMMPS 29 Sep 2021 read these very bytes with read_data
    // (md-io/tests/lammps_write.rs compares what it made of them with what we wrote).
    let dir = tempfile::tempdir().unwrap();
    for (case, args) in [
        ("nacl", vec![md_data("lammps_write/nacl_primitive.vasp")]),
        ("cod", vec![md_data("crystal/cod_9001665.cif")]),
        ("nisb", vec![md_data("crystal/cod_1010930.cif")]),
        (
            "peptide",
            vec![
                md_data("tpr/peptide.tpr.gz"),
                "--select".into(),
                "not name MW and index 0:999".into(),
            ],
        ),
        ("caffeine", vec![md_data("molecules/caffeine_v3000.mol")]),
    ] {
        let out = dir.path().join(format!("{case}.data"));
        let mut all: Vec<&str> = vec!["convert", "-q"];
        all.extend(args.iter().map(String::as_str));
        all.extend(["-o", out.to_str().unwrap()]);
        let o = texmap(&all);
        assert!(o.status.success(), "{case}: {}", stderr(&o));
        let got = std::fs::read(&out).unwrap();
        let want = match std::fs::read(md_data(&format!("lammps_write/written/{case}.data"))) {
            Ok(w) => w,
            Err(_) => {
                let mut w = Vec::new();
                std::io::Read::read_to_end(
                    &mut flate2::read::GzDecoder::new(
                        std::fs::File::open(md_data(&format!(
                            "lammps_write/written/{case}.data.gz"
                        )))
                        .unwrap(),
                    ),
                    &mut w,
                )
                .unwrap();
                w
            }
        };
        assert!(
            got == want,
            "{case}: the bytes differ from the file LAMMPS read"
        );
    }
    // A data file is one configuration: two frames are refused, and nothing is left.
    let out = dir.path().join("two.data");
    let o = texmap(&[
        "convert",
        &md_data("topo_mda.xtc"),
        "--topology",
        &md_data("topo_mda.gro"),
        "--frames",
        "0:2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("one configuration"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `--saltbridge-table` and `--saltbridge-occupancy` on adenylate kinase in water (a
/// truncated octahedron, two frames) list the salt bridges of md-io's saltbridges reference
/// (VMD saltbr's criterion computed with MDAnalysis's distances: `gen_saltbridges.py`), at
/// 3.2 Å and at 4.0 Å with histidines, both distances to the tables' decimals; the occupancy
/// counts the frames. A cutoff out of range is refused with no file left.
#[test]
fn salt_bridge_tables_are_mdanalysis_distances() {
    use std::io::Read;
    let dir = tempfile::tempdir().unwrap();
    let (xtc, gro) = (
        md_data("hbonds/adk_0_9.xtc"),
        md_data("hbonds/adk_top.gro.gz"),
    );
    let mut top = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(&gro).unwrap())
        .read_to_string(&mut top)
        .unwrap();
    // RESNAME RESID of atom i, from the GRO's fixed columns.
    let lines: Vec<&str> = top.lines().collect();
    let residue = |i: u64| {
        let l = lines[i as usize + 2];
        format!("{}{}", l[5..10].trim(), l[0..5].trim())
    };
    let reference = json("saltbridges/reference.json");
    let (table, occ) = (dir.path().join("sb.csv"), dir.path().join("occ.csv"));
    for run in reference["runs"].as_array().unwrap() {
        let cutoff = run["cutoff"].as_f64().unwrap().to_string();
        let mut args = vec![
            "convert",
            &xtc,
            "--topology",
            &gro,
            "--saltbridge-table",
            table.to_str().unwrap(),
            "--saltbridge-occupancy",
            occ.to_str().unwrap(),
            "--saltbridge-cutoff",
            &cutoff,
            "-q",
        ];
        if run["histidine"].as_bool().unwrap() {
            args.push("--saltbridge-his");
        }
        run_ok(&args);
        let text = std::fs::read_to_string(&table).unwrap();
        let mut rows = text.lines();
        assert_eq!(
            rows.next(),
            Some("frame,time,acid,base,acid_chain,base_chain,distance,min_distance")
        );
        let got: Vec<Vec<&str>> = rows.map(|l| l.split(',').collect()).collect();
        let mut want = Vec::new();
        let mut present = std::collections::BTreeMap::new();
        for (f, frame) in run["frames"].as_array().unwrap().iter().enumerate() {
            for r in frame.as_array().unwrap() {
                let (a, b) = (
                    residue(r[0].as_u64().unwrap()),
                    residue(r[1].as_u64().unwrap()),
                );
                *present.entry((a.clone(), b.clone())).or_insert(0) += 1;
                want.push((f, a, b, r[2].as_f64().unwrap(), r[3].as_f64().unwrap()));
            }
        }
        assert_eq!(got.len(), want.len(), "cutoff {cutoff}:\n{text}");
        for (g, (f, a, b, d, m)) in got.iter().zip(&want) {
            assert_eq!(
                (g[0], g[2], g[3], g[4], g[5]),
                (f.to_string().as_str(), a.as_str(), b.as_str(), "", ""),
                "cutoff {cutoff}"
            );
            assert!(!g[1].is_empty(), "the XTC has times");
            let (gd, gm): (f64, f64) = (g[6].parse().unwrap(), g[7].parse().unwrap());
            assert!(
                (gd - d).abs() < 1e-4 && (gm - m).abs() < 1e-4,
                "{g:?} {d} {m}"
            );
        }
        if run["histidine"].as_bool().unwrap() {
            assert!(got.iter().any(|g| g[3].starts_with("HISB")), "{text}");
        } else {
            assert!(!got.iter().any(|g| g[3].starts_with("HIS")), "{text}");
        }
        let text = std::fs::read_to_string(&occ).unwrap();
        let mut rows = text.lines();
        assert_eq!(
            rows.next(),
            Some("acid,base,acid_chain,base_chain,frames,occupancy,distance,min_distance")
        );
        let got: Vec<Vec<&str>> = rows.map(|l| l.split(',').collect()).collect();
        assert_eq!(got.len(), present.len());
        let frames: Vec<u32> = got.iter().map(|g| g[4].parse().unwrap()).collect();
        assert!(frames.windows(2).all(|w| w[0] >= w[1]), "{text}");
        for g in &got {
            let n = present[&(g[0].to_string(), g[1].to_string())];
            assert_eq!(g[4], n.to_string(), "{g:?}");
            assert_eq!(g[5], format!("{:.6}", f64::from(n) / 2.0));
        }
    }
    std::fs::remove_file(&table).unwrap();
    let o = texmap(&[
        "convert",
        &xtc,
        "--topology",
        &gro,
        "--saltbridge-table",
        table.to_str().unwrap(),
        "--saltbridge-cutoff",
        "9",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--saltbridge-cutoff"), "{}", stderr(&o));
    assert!(!table.exists());
}

/// A PDB keeps the topology's bonds as CONECT records: md-io's committed file (whose CONECT
/// lines are MDAnalysis's, byte for byte), read back with the PSF's bonds; with --select, the
/// bonds among the atoms kept, numbered as written.
#[test]
fn pdb_output_keeps_the_topology_bonds_as_conect_records() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.pdb");
    let (gro, psf) = (md_data("topo_mda.gro"), md_data("psf_parmed.psf"));
    run_ok(&[
        "convert",
        &gro,
        "--topology",
        &psf,
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&out).unwrap();
    let committed = std::fs::read_to_string(md_data("pdb_conect/peptide_psf.pdb")).unwrap();
    assert_eq!(text, committed);
    let bonds = |p: &str| texmap_md_io::Topology::open(p).unwrap().bonds;
    let all = bonds(&psf);
    assert_eq!(all.len(), 53);
    assert_eq!(bonds(out.to_str().unwrap()), all);
    // The peptide alone (atoms 0-29): its bonds, none to the waters.
    let sel = dir.path().join("ala.pdb");
    let sel_s = sel.to_str().unwrap();
    run_ok(&[
        "convert",
        &gro,
        "--topology",
        &psf,
        "--select",
        "resname ALA",
        "-q",
        "-o",
        sel_s,
    ]);
    let kept: Vec<[u32; 2]> = all.iter().copied().filter(|b| b[1] < 30).collect();
    assert!(kept.len() > 20 && kept.len() < all.len(), "{kept:?}");
    assert_eq!(bonds(sel_s), kept);
    // Without a topology with bonds, no CONECT records (the files of before).
    let plain = dir.path().join("plain.pdb");
    run_ok(&["convert", &gro, "-q", "-o", plain.to_str().unwrap()]);
    assert!(!std::fs::read_to_string(&plain).unwrap().contains("CONECT"));
}

/// An SD file of docked poses and of a MOL2 library is md-io's committed file (checked there
/// against RDKit) byte for byte: the PDBQT poses with their bonds by distance, the MOL2's with
/// their orders. From a GRO with a PSF topology, --select keeps the topology's bonds among the
/// atoms it keeps.
#[test]
fn sdf_output_is_the_committed_file_with_bonds() {
    let dir = tempfile::tempdir().unwrap();
    for (src, committed) in [
        ("pdbqt/poses.pdbqt", "sdf_write/vina_poses.sdf"),
        ("molecules/library.mol2", "sdf_write/library_mol2.sdf"),
    ] {
        let out = dir.path().join("out.sdf");
        run_ok(&["convert", &md_data(src), "-q", "-o", out.to_str().unwrap()]);
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(
            text == std::fs::read_to_string(md_data(committed)).unwrap(),
            "{src}: {text}"
        );
    }
    let (gro, psf) = (md_data("topo_mda.gro"), md_data("psf_parmed.psf"));
    let out = dir.path().join("ala.sdf");
    run_ok(&[
        "convert",
        &gro,
        "--topology",
        &psf,
        "--select",
        "resname ALA",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let all = texmap_md_io::Topology::open(&psf).unwrap().bonds;
    let kept: Vec<[u32; 2]> = all.iter().copied().filter(|b| b[1] < 30).collect();
    let written = frames(&out);
    assert_eq!(written.len(), 1);
    assert_eq!(written[0].n_atoms(), 30);
    assert!(kept.len() > 20 && kept.len() < all.len(), "{kept:?}");
    assert_eq!(written[0].bonds, kept);
    assert_eq!(written[0].bond_orders, vec![1; kept.len()]);
}
