//! Our VASP writer (src/vasp_writer.rs). POSCAR and XDATCAR files written from real inputs of
//! tests/data (crystal CIFs, ASE's POSCARs, a peptide in water and a triclinic GRO box with
//! velocities, a LAMMPS dump, ASE's variable-cell and pymatgen's fixed-cell XDATCARs) are
//! committed in tests/data/vasp_write and compared byte for byte with what the writer writes
//! now; what ASE 3.29, pymatgen 2026.10 and (POSCARs) phonopy 4.10 read from those files
//! (tests/data/vasp_write/gen_vasp_write.py) is compared with the frames they were written
//! from; the same files are read back by our reader; the header layout of an XDATCAR whose cell
//! is fixed, changes, or starts changing is checked, and so are the frames refused. A live check
//! hands files written now to ASE (and pymatgen and phonopy where installed) through python3,
//! printing SKIPPED without them.

use std::io::Cursor;
use std::path::Path;
use std::process::Command;

use serde_json::Value;
use support::fixtures::{data, stream};
use texmap_md_io::{
    Element, Error, Format, Frame, Label, Trajectory, UnitCell, Writer, atom_element,
};

use crate::support;

/// Output file name and input (a file of tests/data).
const CASES: [(&str, &str); 9] = [
    ("POSCAR_cod", "crystal/cod_9001665.cif"),
    ("POSCAR_nisb", "crystal/cod_1010930.cif"),
    ("POSCAR_triclinic", "vasp/POSCAR_ase_direct"),
    ("POSCAR_vel", "vasp/CONTCAR_ase_vel.vasp"),
    ("POSCAR_water", "topo_mda.gro"),
    ("POSCAR_gro_vel", "mda_vel.gro"),
    ("XDATCAR_lammps", "lmp_tri.lammpstrj"),
    ("XDATCAR_npt", "vasp/XDATCAR_ase"),
    ("XDATCAR_pmg", "vasp/XDATCAR_pmg"),
];

/// Every frame of `source`.
fn input(source: &str) -> Vec<Frame> {
    let mut t = Trajectory::open(data(source)).unwrap_or_else(|e| panic!("{e}"));
    stream(&mut t)
}

/// The frames case `name` writes: its input's first frame for a POSCAR, every frame for an
/// XDATCAR.
fn case_frames(name: &str, source: &str) -> Vec<Frame> {
    let mut frames = input(source);
    if name.starts_with("POSCAR") {
        frames.truncate(1);
    }
    frames
}

/// `frames` written by our writer to a file called `name`.
fn written(name: &str, frames: &[Frame]) -> Result<Vec<u8>, Error> {
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Vasp, name)?;
    for f in frames {
        w.write_frame(f)?;
    }
    Ok(w.finish()?.into_inner())
}

/// Our reader on `bytes` of a file called `name`.
fn read_back(name: &str, bytes: &[u8]) -> Vec<Frame> {
    let mut t = Trajectory::from_reader(Cursor::new(bytes.to_vec()), Format::Vasp, name)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    stream(&mut t)
}

fn symbol(f: &Frame, i: usize) -> &'static str {
    atom_element(f, i).symbol()
}

/// A position or velocity another program read, in f64, against ours (f32).
///
/// Tolerance 1e-9 (Å, or Å/ps relative above 1): the fractions we write are exact decimals of
/// the f64 fractions of the f32 positions, which ASE and pymatgen multiply by the lattice in
/// f64, so only f64 round-off separates them (below 1e-12 Å in these cells). A writer that
/// rounded fractions to the usual 6 to 8 decimals would be off by 1e-7 to 1e-5 Å and fail.
fn close(v: f64, x: f32, tol: f64, what: &str) {
    let d = (v - x as f64).abs();
    assert!(
        d <= tol * (x.abs() as f64).max(1.0),
        "{what}: read {v}, the frame has {x} (|Δ| = {d:e})"
    );
}

/// What `reader` read (frames of symbols, cell, positions, and velocities when the reader
/// reads them) is `frames`, the frames written to `file`.
fn same_as_written(reader: &str, file: &str, got: &Value, frames: &[Frame]) {
    let got = got
        .as_array()
        .unwrap_or_else(|| panic!("{reader} on {file}: no frames"));
    assert_eq!(got.len(), frames.len(), "{reader} on {file}: frames");
    let velocities = file.starts_with("POSCAR") && reader != "phonopy";
    for (k, (g, f)) in got.iter().zip(frames).enumerate() {
        let at = |what: &str| format!("{reader} on {file}, frame {k}: {what}");
        let symbols: Vec<&str> = g["symbols"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap())
            .collect();
        let ours: Vec<&str> = (0..f.n_atoms()).map(|i| symbol(f, i)).collect();
        assert_eq!(symbols, ours, "{}", at("symbols, in order"));
        let m = f.cell.unwrap().matrix();
        for r in 0..3 {
            for c in 0..3 {
                let v = g["cell"][r][c].as_f64().unwrap();
                assert!(
                    (v - m[r][c]).abs() <= 1e-12 * m[r][c].abs().max(1.0),
                    "{}",
                    at(&format!("cell[{r}][{c}] {v} vs {}", m[r][c]))
                );
            }
        }
        for (i, p) in f.positions.iter().enumerate() {
            for c in 0..3 {
                let v = g["positions"][i][c].as_f64().unwrap();
                close(v, p[c], 1e-9, &at(&format!("atom {i} axis {c}")));
            }
        }
        // Velocities: a POSCAR of a frame that has them, nothing else.
        let v = &g["velocities"];
        if velocities && !f.velocities.is_empty() {
            for (i, u) in f.velocities.iter().enumerate() {
                for c in 0..3 {
                    let x = v[i][c].as_f64().unwrap();
                    close(
                        x,
                        u[c],
                        1e-9,
                        &at(&format!("velocity of atom {i} axis {c}")),
                    );
                }
            }
        } else {
            assert!(v.is_null(), "{}", at("velocities where none were written"));
        }
    }
}

#[test]
fn the_committed_files_are_what_the_writer_writes() {
    let regenerate = std::env::var_os("VASP_WRITE_REGENERATE").is_some();
    for (name, source) in CASES {
        let frames = case_frames(name, source);
        let bytes = written(name, &frames).unwrap_or_else(|e| panic!("{name}: {e}"));
        let path = data(&format!("vasp_write/{name}"));
        if regenerate {
            std::fs::write(&path, &bytes).unwrap();
            continue;
        }
        let committed = std::fs::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            committed == bytes,
            "{name}: the writer no longer writes the committed file (if the change is meant, \
             regenerate: see tests/data/vasp_write/gen_vasp_write.py)"
        );
    }
}

#[test]
fn ase_pymatgen_and_phonopy_read_our_files_as_the_frames_written() {
    let text = std::fs::read_to_string(data("vasp_write/reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    for (name, source) in CASES {
        let frames = case_frames(name, source);
        let r = &reference[name];
        assert!(!r.is_null(), "{name}: not in reference.json");
        same_as_written("ASE", name, &r["ase"], &frames);
        same_as_written("pymatgen", name, &r["pymatgen"], &frames);
        // phonopy reads POSCARs (its unit cells), not trajectories.
        if name.starts_with("POSCAR") {
            same_as_written("phonopy", name, &r["phonopy"], &frames);
        } else {
            assert!(r["phonopy"].is_null(), "{name}");
        }
    }
    // The cases cover what they are meant to: velocities read by both, interleaved species.
    assert!(reference["POSCAR_gro_vel"]["ase"][0]["velocities"].is_array());
    assert!(reference["POSCAR_vel"]["pymatgen"][0]["velocities"].is_array());
}

#[test]
fn our_reader_gives_back_the_frames() {
    for (name, source) in CASES {
        let frames = case_frames(name, source);
        let bytes = written(name, &frames).unwrap();
        let back = read_back(name, &bytes);
        assert_eq!(back.len(), frames.len(), "{name}: frames");
        for (k, (a, b)) in frames.iter().zip(&back).enumerate() {
            let at = format!("{name}, frame {k}");
            let n = a.n_atoms();
            assert_eq!(b.n_atoms(), n, "{at}");
            // The cell: the same f64 numbers.
            assert_eq!(b.cell.unwrap().matrix(), a.cell.unwrap().matrix(), "{at}");
            for i in 0..n {
                // Same element and order; the type is the element symbol.
                let e = atom_element(a, i);
                assert_eq!(b.elements[i], e, "{at}, atom {i}");
                assert_eq!(b.types[i], e.symbol(), "{at}, atom {i}");
                // Positions: the same f32, but where f64 round-off of the fraction shows in a
                // coordinate that is (nearly) zero: 1e-12 Å.
                for c in 0..3 {
                    let (p, q) = (a.positions[i][c], b.positions[i][c]);
                    assert!(
                        p == q || (p - q).abs() <= 1e-12,
                        "{at}, atom {i} axis {c}: wrote {p}, read {q}"
                    );
                }
            }
            // Velocities: POSCAR only, the same f32 (Å/ps → Å/fs → Å/ps in f64).
            if name.starts_with("POSCAR") {
                assert_eq!(b.velocities, a.velocities, "{at}: velocities");
            } else {
                assert!(b.velocities.is_empty(), "{at}");
            }
            // The comment line: the frame's, else the formula.
            let c = a.comment.lines().next().unwrap_or("").trim();
            if !c.is_empty() {
                assert_eq!(b.comment, c, "{at}: comment");
            }
        }
        // Frames of an XDATCAR are numbered from 1, as VASP numbers them.
        if name.starts_with("XDATCAR") {
            let steps: Vec<Option<i64>> = back.iter().map(|f| f.step).collect();
            let want: Vec<Option<i64>> = (1..=back.len() as i64).map(Some).collect();
            assert_eq!(steps, want, "{name}");
        }
    }
}

/// The species names and counts lines of a written file, and its lines.
fn species(text: &str) -> (Vec<&str>, Vec<usize>, Vec<&str>) {
    let lines: Vec<&str> = text.lines().collect();
    let names = lines[5].split_whitespace().collect();
    let counts = lines[6]
        .split_whitespace()
        .map(|c| c.parse().unwrap())
        .collect();
    (names, counts, lines)
}

#[test]
fn runs_of_one_species_are_groups_in_the_frames_order() {
    // A peptide in water (N H C H C H ... then O H H per water), written in the GRO's order.
    let text = std::fs::read_to_string(data("vasp_write/POSCAR_water")).unwrap();
    let (names, counts, lines) = species(&text);
    assert_eq!(names.len(), counts.len());
    let expanded: Vec<&str> = names
        .iter()
        .zip(&counts)
        .flat_map(|(s, c)| std::iter::repeat_n(*s, *c))
        .collect();
    let f = &input("topo_mda.gro")[0];
    let ours: Vec<&str> = (0..f.n_atoms()).map(|i| symbol(f, i)).collect();
    assert_eq!(expanded, ours);
    // No two neighbouring groups are of one species. The peptide's last O and the first
    // water's O are one run (`O 2`, then `H 2`); the 11 waters after it are O H O H ... /
    // 1 2 1 2.
    assert!(names.windows(2).all(|w| w[0] != w[1]));
    let k = names.len() - 22;
    assert_eq!((names[k - 2], counts[k - 2]), ("O", 2));
    assert_eq!((names[k - 1], counts[k - 1]), ("H", 2));
    for w in 0..11 {
        let (o, h) = (k + 2 * w, k + 2 * w + 1);
        assert_eq!(
            (names[o], counts[o], names[h], counts[h]),
            ("O", 1, "H", 2),
            "water {w}"
        );
    }
    // The layout: comment, scale 1.0, lattice, species, counts, Direct, the atoms; no
    // velocities in the frame, none in the file.
    assert_eq!(lines[1], "1.0");
    assert_eq!(lines[7], "Direct");
    assert_eq!(lines.len(), 8 + f.n_atoms());
    // With velocities: a blank line after the coordinates, then one line per atom.
    let text = std::fs::read_to_string(data("vasp_write/POSCAR_gro_vel")).unwrap();
    let (_, counts, lines) = species(&text);
    let n: usize = counts.iter().sum();
    assert_eq!(lines[8 + n], "");
    assert_eq!(lines.len(), 8 + n + 1 + n);
}

/// The number of headers (scaling-factor lines) and configuration lines of an XDATCAR.
fn xdatcar_layout(text: &str) -> (usize, Vec<String>) {
    let lines: Vec<&str> = text.lines().collect();
    let headers = lines.iter().filter(|l| **l == "1.0").count();
    let configurations = lines
        .iter()
        .filter(|l| l.starts_with("Direct configuration="))
        .map(|l| l.to_string())
        .collect();
    (headers, configurations)
}

#[test]
fn an_xdatcar_repeats_its_header_only_when_the_cell_changes() {
    // A fixed box: one header.
    let text = std::fs::read_to_string(data("vasp_write/XDATCAR_lammps")).unwrap();
    let (headers, conf) = xdatcar_layout(&text);
    assert_eq!(headers, 1);
    assert_eq!(
        conf,
        [
            "Direct configuration=     1",
            "Direct configuration=     2",
            "Direct configuration=     3"
        ]
    );
    // An NPT run (every frame another cell): a header per frame, each with the first comment.
    let text = std::fs::read_to_string(data("vasp_write/XDATCAR_npt")).unwrap();
    let (headers, conf) = xdatcar_layout(&text);
    assert_eq!((headers, conf.len()), (5, 5));
    let first = text.lines().next().unwrap();
    assert_eq!(text.lines().filter(|l| *l == first).count(), 5);
    // A box that starts changing at frame 2: frames 0 and 1 under one header, then a header
    // before every frame, as VASP writes a run whose cell changes.
    let mut frames = input("vasp/XDATCAR_pmg");
    frames.truncate(5);
    let cell = frames[0].cell.unwrap();
    for (k, f) in frames.iter_mut().enumerate().skip(2) {
        let l = cell.lengths().map(|x| x * (1.0 + 0.01 * k as f64));
        f.cell = Some(UnitCell::from_lengths_angles(l, cell.angles()).unwrap());
    }
    frames[4].cell = frames[3].cell;
    let bytes = written("XDATCAR", &frames).unwrap();
    let text = String::from_utf8(bytes.clone()).unwrap();
    let (headers, conf) = xdatcar_layout(&text);
    assert_eq!((headers, conf.len()), (4, 5), "{text}");
    let back = read_back("XDATCAR", &bytes);
    for (a, b) in frames.iter().zip(&back) {
        assert_eq!(a.cell.unwrap().matrix(), b.cell.unwrap().matrix());
    }
}

fn label(s: &str) -> Label {
    Label::new(s).unwrap()
}

fn crystal() -> Frame {
    input("vasp/POSCAR_ase_direct").remove(0)
}

/// The message of `frames` refused, checking that nothing of the refused frame was written:
/// the frames before it give the same bytes alone.
fn refused(name: &str, frames: &[Frame]) -> String {
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Vasp, name).unwrap();
    for (k, f) in frames.iter().enumerate() {
        if let Err(e) = w.write_frame(f) {
            assert!(matches!(e, Error::InvalidFrame { frame, .. } if frame == k));
            let bytes = w.finish().unwrap().into_inner();
            assert_eq!(bytes, written(name, &frames[..k]).unwrap(), "{name}: bytes");
            return e.to_string();
        }
    }
    panic!("{name}: nothing refused");
}

#[test]
fn frames_a_vasp_file_cannot_hold_are_refused_naming_file_frame_and_reason() {
    // No cell.
    let mut f = crystal();
    f.cell = None;
    let e = refused("POSCAR", std::slice::from_ref(&f));
    assert!(
        e.contains("POSCAR: frame 0") && e.contains("no cell"),
        "{e}"
    );
    // No atoms.
    let mut f = crystal();
    f.clear();
    f.cell = crystal().cell;
    let e = refused("POSCAR", &[f]);
    assert!(e.contains("no atoms"), "{e}");
    // A second frame in a POSCAR (any name that is not an XDATCAR's).
    let e = refused("out/si.vasp", &[crystal(), crystal()]);
    assert!(
        e.contains("out/si.vasp: frame 1") && e.contains("one structure") && e.contains("XDATCAR"),
        "{e}"
    );
    // An atom without an element, named.
    let mut f = crystal();
    f.elements[4] = Element::UNKNOWN;
    f.names[4] = label("Q7");
    f.types[4] = label("Q7");
    let e = refused("POSCAR", &[f]);
    assert!(
        e.contains("atom 4 (name 'Q7', type 'Q7') has no element"),
        "{e}"
    );
    // XDATCAR: another atom count in frame 2.
    let frames = input("vasp/XDATCAR_pmg");
    let mut more = frames[..3].to_vec();
    let keep: Vec<bool> = (0..more[2].n_atoms()).map(|i| i != 3).collect();
    more[2].retain_atoms(&keep);
    let e = refused("XDATCAR", &more);
    assert!(
        e.contains("XDATCAR: frame 2") && e.contains("has 8 atoms, the XDATCAR's first frame 9"),
        "{e}"
    );
    // XDATCAR: the same atoms in another order.
    let mut swapped = frames[..2].to_vec();
    swapped[1].elements.swap(0, 8);
    let e = refused("XDATCAR_run", &swapped);
    assert!(
        e.contains("XDATCAR_run: frame 1")
            && e.contains("atom 0")
            && e.contains("is Li")
            && e.contains("first frame is Fe"),
        "{e}"
    );
    // XDATCAR: a later frame without a cell.
    let mut lost = frames[..2].to_vec();
    lost[1].cell = None;
    let e = refused("XDATCAR", &lost);
    assert!(e.contains("frame 1") && e.contains("no cell"), "{e}");
    // A left-handed lattice never reaches the writer: a cell cannot be made of one.
    assert!(UnitCell::from_matrix([[0.0, 5.0, 0.0], [5.0, 0.0, 0.0], [0.0, 0.0, 5.0]]).is_err());
}

#[test]
fn create_tells_an_xdatcar_from_a_poscar_by_the_file_name() {
    let dir = tempfile::tempdir().unwrap();
    let frames = input("vasp/XDATCAR_pmg");
    for name in ["XDATCAR", "xdatcar.2", "run.XDATCAR"] {
        let path = dir.path().join(name);
        let mut w = Writer::create(&path, Format::Vasp).unwrap();
        for f in &frames {
            w.write_frame(f).unwrap();
        }
        w.finish().unwrap();
        let back = stream(&mut Trajectory::open_as(&path, Format::Vasp).unwrap());
        assert_eq!(back.len(), frames.len(), "{name}");
    }
    for name in ["POSCAR", "CONTCAR_relaxed", "si.vasp", "si.poscar"] {
        let path = dir.path().join(name);
        let mut w = Writer::create(&path, Format::Vasp).unwrap();
        w.write_frame(&frames[0]).unwrap();
        let e = w.write_frame(&frames[1]).unwrap_err().to_string();
        assert!(e.contains("one structure"), "{name}: {e}");
        w.finish().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().nth(7), Some("Direct"), "{name}");
    }
}

/// ASE (and pymatgen and phonopy where installed) on files written now, through python3 and the
/// generator's reading code; SKIPPED without python3 or ASE.
#[test]
fn ase_reads_files_written_now() {
    let ase = Command::new("python3").args(["-c", "import ase"]).output();
    match ase {
        Ok(o) if o.status.success() => {}
        Ok(_) => {
            eprintln!("SKIPPED: ASE on files written now (pip install ase)");
            return;
        }
        Err(e) => {
            eprintln!("SKIPPED: ASE on files written now (python3: {e})");
            return;
        }
    }
    let dir = tempfile::tempdir().unwrap();
    // Every case, and a crystal whose atoms lie outside the cell (not wrapped) with velocities.
    let mut cases: Vec<(String, Vec<Frame>)> = CASES
        .iter()
        .map(|(name, source)| (name.to_string(), case_frames(name, source)))
        .collect();
    let mut outside = crystal();
    for (i, p) in outside.positions.iter_mut().enumerate() {
        p[i % 3] += if i % 2 == 0 { 9.5 } else { -13.25 };
    }
    outside.velocities = (0..outside.n_atoms())
        .map(|i| [i as f32 * 0.5 - 2.0, 1e-3, -7.25])
        .collect();
    cases.push(("POSCAR_outside".into(), vec![outside]));
    for (name, frames) in &cases {
        std::fs::write(dir.path().join(name), written(name, frames).unwrap()).unwrap();
    }
    let script = data("vasp_write/gen_vasp_write.py");
    let o = Command::new("python3")
        .arg(&script)
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let got: Value = serde_json::from_slice(&o.stdout).unwrap();
    let pymatgen = !got[&cases[0].0]["pymatgen"].is_null();
    if !pymatgen {
        eprintln!("SKIPPED: pymatgen on files written now (pip install pymatgen); ASE checked");
    }
    let phonopy = !got[&cases[0].0]["phonopy"].is_null();
    if !phonopy {
        eprintln!("SKIPPED: phonopy on files written now (pip install phonopy); ASE checked");
    }
    for (name, frames) in &cases {
        same_as_written("ASE", name, &got[name]["ase"], frames);
        if pymatgen {
            same_as_written("pymatgen", name, &got[name]["pymatgen"], frames);
        }
        if phonopy && name.starts_with("POSCAR") {
            same_as_written("phonopy", name, &got[name]["phonopy"], frames);
        }
    }
}

#[test]
fn the_reference_covers_every_case() {
    let text = std::fs::read_to_string(data("vasp_write/reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let files: Vec<&String> = reference.as_object().unwrap().keys().collect();
    let mut cases: Vec<&str> = CASES.iter().map(|(n, _)| *n).collect();
    cases.sort_unstable();
    assert_eq!(files, cases);
    assert!(Path::new(&data("vasp_write/gen_vasp_write.py")).exists());
}
