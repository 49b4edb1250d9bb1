//! VASP run outputs written by VASP itself, from pymatgen's test files (tests/data/vasp_out:
//! the vasprun.xml and the OUTCAR of one VASP 5.2.12 relaxation of bcc Li, three ionic steps
//! with a changing primitive cell; a single-step vasprun.xml of SiO2, VASP 5.4.1; a
//! single-step OUTCAR of GaAs, VASP 5.4.1; provenance in tests/data/README.md), compared with
//! ASE 3.29's reading of the same files (`gen_reference.py` wrote `reference.json`;
//! [`ase_reads_the_files_as_the_reference_says`] re-runs it where ASE is installed). None has
//! selective dynamics or bytes after `</modeling>`.
//!
//! Tolerances. Positions are f32 in a [`Frame`]: every coordinate here is below 8 Å, where an
//! f32 rounds to within 2.4e-7 Å, and the fractional-to-Cartesian product is summed in another
//! order than numpy's (1e-14 Å), so 1e-6 Å. Cells are f64 read from the same decimal text as
//! ASE reads: 1e-12 Å. Forces are f32: 1e-6 eV/Å plus 1e-7 relative (f32's rounding is 6e-8
//! relative). Energies are the same decimal numbers combined as ASE combines them (e_fr less
//! PSTRESS·V plus the last electronic step's e_0 − e_fr): 1e-12 relative. Stresses are VASP's
//! kB times 0.1 GPa, a product whose last bit may differ from ASE's: 1e-12 relative plus
//! 1e-18 eV/Å³.

use crate::support;

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use support::alloc::measure;
use support::dft::{comment_number, comment_stress, max_dev, read_all, rows};
use texmap_md_io::{Error, Format, Frame, ReadOptions, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/vasp_out")
        .join(name)
}

fn data(name: &str) -> Vec<u8> {
    std::fs::read(path(name)).unwrap()
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(path("reference.json")).unwrap()).unwrap()
}

/// The fixtures, their formats and ASE's frame counts.
const FILES: [(&str, Format, usize); 4] = [
    ("vasprun_li_relax.xml", Format::VaspXml, 3),
    ("vasprun_sio2.xml", Format::VaspXml, 1),
    ("OUTCAR_li_relax", Format::Outcar, 3),
    ("OUTCAR_gaas", Format::Outcar, 1),
];

/// Compares our frame with ASE's within the module's tolerances; returns the largest
/// deviations: positions and cell (Å), forces (eV/Å), energies and stress (relative).
fn compare(name: &str, k: usize, f: &Frame, w: &Value) -> [f64; 5] {
    let mut worst = [0.0f64; 5];
    let symbols: Vec<&str> = f.elements.iter().map(|e| e.symbol()).collect();
    let want: Vec<&str> = w["symbols"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert_eq!(symbols, want, "{name} frame {k}");
    let names: Vec<&str> = f.names.iter().map(|l| l.as_str()).collect();
    assert_eq!(names, want, "{name} frame {k}: names");
    let pos: Vec<[f64; 3]> = f.positions.iter().map(|p| p.map(f64::from)).collect();
    let dp = max_dev(&pos, &rows(&w["positions"]));
    assert!(
        dp <= 1e-6,
        "{name} frame {k}: positions off by {dp} Å (tolerance 1e-6)"
    );
    let dc = max_dev(&f.cell.unwrap().matrix(), &rows(&w["cell"]));
    assert!(
        dc <= 1e-12,
        "{name} frame {k}: cell off by {dc} Å (tolerance 1e-12)"
    );
    worst[0] = dp;
    worst[1] = dc;
    for (i, fw) in rows(&w["forces"]).iter().enumerate() {
        for (c, key) in ["fx", "fy", "fz"].iter().enumerate() {
            let got = f64::from(f.property(key).unwrap()[i]);
            let tol = 1e-6 + 1e-7 * fw[c].abs();
            worst[2] = worst[2].max((got - fw[c]).abs());
            assert!(
                (got - fw[c]).abs() <= tol,
                "{name} frame {k} atom {i} {key}: {got} vs ASE {} (tolerance {tol})",
                fw[c]
            );
        }
    }
    for key in ["energy", "free_energy"] {
        let e = w[key].as_f64().unwrap();
        let got = comment_number(f, key).unwrap();
        let d = (got - e).abs() / e.abs();
        worst[3] = worst[3].max(d);
        assert!(
            d <= 1e-12,
            "{name} frame {k}: {key} {got} eV vs ASE {e} (tolerance 1e-12 relative)"
        );
    }
    let got = comment_stress(f, false).unwrap();
    for (c, x) in w["stress"].as_array().unwrap().iter().enumerate() {
        let x = x.as_f64().unwrap();
        let d = (got[c] - x).abs();
        worst[4] = worst[4].max(d / x.abs());
        assert!(
            d <= 1e-12 * x.abs() + 1e-18,
            "{name} frame {k}: stress {got:?} vs ASE {:?} (tolerance 1e-12 relative)",
            w["stress"]
        );
    }
    worst
}

/// Every frame of every fixture as ASE reads it: the count (one per `<calculation>`, one per
/// OUTCAR step), elements,
/// positions, cells, forces, energies and stress; streamed and by index alike.
#[test]
fn frames_as_ase_reads_them() {
    let r = reference();
    let mut worst = [0.0f64; 5];
    let mut total = 0;
    for (name, format, count) in FILES {
        let want = r["files"][name]["frames"].as_array().unwrap();
        assert_eq!(want.len(), count, "{name}: ASE's count");
        let mut t = Trajectory::open(path(name)).unwrap();
        assert_eq!(t.format(), format, "{name}");
        assert_eq!(t.n_frames().unwrap(), count, "{name}: frame count");
        let got = read_all(&mut t);
        assert_eq!(got.len(), count, "{name}: frames streamed");
        assert!(t.warnings().is_empty(), "{name}: {:?}", t.warnings());
        for (k, (f, w)) in got.iter().zip(want).enumerate() {
            let d = compare(name, k, f, w);
            for (w, d) in worst.iter_mut().zip(d) {
                *w = w.max(d);
            }
            total += 1;
            assert_eq!(f.check(), Ok(()), "{name} frame {k}");
            assert_eq!(f.step, Some(k as i64), "{name} frame {k}: step");
            assert_eq!(f.time, None, "{name} frame {k}: no md, no time");
            let mut g = Frame::new();
            t.read_frame(k, &mut g).unwrap();
            assert_eq!(&g, f, "{name} frame {k} by index");
        }
    }
    println!(
        "{total} frames as ASE reads them; largest deviations: positions {:.1e} Å, cells \
         {:.1e} Å, forces {:.1e} eV/Å, energies {:.1e} relative, stress {:.1e} relative",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
}

/// ASE itself, where python3 has it, reads the fixtures as `reference.json` says (the
/// committed JSON is what the other tests use), and reads files cut mid-run to the frames we
/// keep under `allow_truncated`.
#[test]
fn ase_reads_the_files_as_the_reference_says() {
    let probe = std::process::Command::new("python3")
        .args(["-c", "import ase.io"])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!("SKIPPED: no python3 with ASE (pip install ase); reference.json covers it");
        return;
    }
    let o = std::process::Command::new("python3")
        .arg("gen_reference.py")
        .arg("-")
        .current_dir(path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let live: Value = serde_json::from_slice(&o.stdout).unwrap();
    let committed = reference();
    for (name, _, _) in FILES {
        let (a, b) = (
            &live["files"][name]["frames"],
            &committed["files"][name]["frames"],
        );
        assert_eq!(a, b, "{name}: ASE {} now reads otherwise", live["ase"]);
    }
    // Cut files: ASE's frames are the steps we keep.
    let dir = tempfile::tempdir().unwrap();
    for (name, format, _) in FILES {
        let good = data(name);
        for k in 1..8 {
            let cut = &good[..good.len() * k / 8];
            let file = dir.path().join(format!("cut{k}_{name}"));
            std::fs::write(&file, cut).unwrap();
            let fmt = if format == Format::VaspXml {
                "vasp-xml"
            } else {
                "vasp-out"
            };
            let script = format!(
                "import sys, ase.io\ntry:\n    print(len(ase.io.read(sys.argv[1], ':', \
                 format='{fmt}')))\nexcept Exception as e:\n    print(-1)\n"
            );
            let o = std::process::Command::new("python3")
                .args(["-c", &script])
                .arg(&file)
                .output()
                .unwrap();
            let ase: i64 = String::from_utf8_lossy(&o.stdout).trim().parse().unwrap();
            let opts = ReadOptions::new().allow_truncated(true);
            let ours = Trajectory::open_as_with(&file, format, opts).and_then(|mut t| t.n_frames());
            match ours {
                // ASE returns the initial structure of a vasprun.xml cut before its first
                // step's energy; we have no frame there (the module doc says so). ASE fails
                // (-1) on a file cut inside the last step's eigenvalues, which we read past.
                Ok(n) => assert!(
                    ase == n as i64 || (n == 0 && ase <= 1) || ase == -1,
                    "{name} cut at {}/8: ours {n}, ASE {ase}",
                    k
                ),
                // No step whole: ASE returns the initial structure or fails.
                Err(e) => assert!(ase <= 1, "{name} cut at {k}/8: {e}, ASE {ase}"),
            }
        }
    }
}

/// The names, the molecular-dynamics times and the species of several kinds.
#[test]
fn species_steps_and_times() {
    let mut t = Trajectory::open(path("vasprun_sio2.xml")).unwrap();
    let f = read_all(&mut t).remove(0);
    let names: Vec<&str> = f.names.iter().map(|l| l.as_str()).collect();
    assert_eq!(names, ["Si", "Si", "Si", "O", "O", "O", "O", "O", "O"]);
    let mut t = Trajectory::open(path("OUTCAR_gaas")).unwrap();
    let f = read_all(&mut t).remove(0);
    let names: Vec<&str> = f.names.iter().map(|l| l.as_str()).collect();
    assert_eq!(names, ["Ga", "Ga", "Ga", "Ga", "As", "As", "As", "As"]);
    // The Li relaxation as an md run (IBRION set to 0 in `<incar>` and `<parameters>`, in
    // memory: a test of the time only): step · POTIM (0.5 fs), in ps.
    let text = String::from_utf8(data("vasprun_li_relax.xml")).unwrap();
    let md = text.replace(
        "<i type=\"int\" name=\"IBRION\">     2</i>",
        "<i type=\"int\" name=\"IBRION\">     0</i>",
    );
    assert_eq!(md.matches("name=\"IBRION\">     0<").count(), 2);
    let mut t = Trajectory::from_reader(Cursor::new(md), Format::VaspXml, "md.xml").unwrap();
    let times: Vec<f64> = read_all(&mut t).iter().map(|f| f.time.unwrap()).collect();
    let want = [0.0, 0.0005, 0.001];
    assert_eq!(times.len(), want.len());
    for (g, w) in times.iter().zip(want) {
        assert!((g - w).abs() < 1e-15, "{times:?} vs {want:?}");
    }
    let text = String::from_utf8(data("OUTCAR_li_relax")).unwrap();
    let md = text.replace("   IBRION =      2", "   IBRION =      0");
    assert_ne!(md, text);
    let mut t = Trajectory::from_reader(Cursor::new(md), Format::Outcar, "OUTCAR").unwrap();
    let times: Vec<f64> = read_all(&mut t).iter().map(|f| f.time.unwrap()).collect();
    assert_eq!(times, [0.0, 0.0005, 0.001]);
}

/// Told by name and content: `vasprun.xml`, `vasprun_relax.xml`, an `.xml` rooted at
/// `<modeling>`, `OUTCAR`, `OUTCAR.relax`, a file starting with VASP's banner; another XML is
/// not taken.
#[test]
fn told_by_name_and_content() {
    let dir = tempfile::tempdir().unwrap();
    let copy = |from: &str, to: &str| {
        let p = dir.path().join(to);
        std::fs::copy(path(from), &p).unwrap();
        p
    };
    for (from, to, format) in [
        ("vasprun_sio2.xml", "vasprun.xml", Format::VaspXml),
        ("vasprun_li_relax.xml", "vasprun_relax.xml", Format::VaspXml),
        ("vasprun_sio2.xml", "run1.xml", Format::VaspXml),
        ("vasprun_li_relax.xml", "run1.xml.gz", Format::VaspXml),
        ("OUTCAR_gaas", "OUTCAR", Format::Outcar),
        ("OUTCAR_li_relax", "OUTCAR.relax", Format::Outcar),
        ("OUTCAR_gaas", "gaas.log", Format::Outcar),
        ("OUTCAR_li_relax", "li.log", Format::Outcar),
    ] {
        let p = copy(from, to);
        if to.ends_with(".gz") {
            // A gzip file named .gz: its inner name and content.
            let bytes = std::fs::read(path(from)).unwrap();
            let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
            std::io::Write::write_all(&mut enc, &bytes).unwrap();
            std::fs::write(&p, enc.finish().unwrap()).unwrap();
        }
        let t = Trajectory::open(&p).unwrap();
        assert_eq!(t.format(), format, "{to}");
    }
    let p = dir.path().join("other.xml");
    std::fs::write(&p, "<?xml version=\"1.0\"?>\n<svg>\n</svg>\n").unwrap();
    let e = Trajectory::open(&p).err().unwrap();
    assert!(matches!(e, Error::UnknownFormat { .. }), "{e}");
    assert_eq!(Format::from_extension("vasp-xml"), Some(Format::VaspXml));
    assert_eq!(Format::from_extension("vasp-out"), Some(Format::Outcar));
    assert_eq!(Format::from_extension("xml"), None);
}

/// Reads `bytes` as `format` until the end or the first error.
fn read_until_error(
    bytes: &[u8],
    format: Format,
    opts: ReadOptions,
) -> (Vec<Frame>, Option<Error>) {
    let mut t =
        Trajectory::from_reader_with(Cursor::new(bytes.to_vec()), format, "cut", opts).unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    loop {
        match t.read_next(&mut f) {
            Ok(true) => out.push(f.clone()),
            Ok(false) => return (out, None),
            Err(e) => return (out, Some(e)),
        }
        assert!(out.len() < 100, "reader does not stop");
    }
}

/// Byte offsets where each frame is kept (`kept`: after its calculation-level `</energy>` line
/// in vasprun.xml, after the 4th line after `FREE ENERGIE` in an OUTCAR) and where it is whole
/// (`whole`: after `</calculation>`; an OUTCAR's are the kept ones). Between the two a frame is
/// kept with what the file holds: a DFPT step's linear-response electronic steps, which come
/// after its energy, may still change its `energy` (ASE reads it so).
fn frame_ends(bytes: &[u8], format: Format) -> (Vec<usize>, Vec<usize>) {
    let text = std::str::from_utf8(bytes).unwrap();
    let mut starts = vec![0];
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    for l in &lines {
        starts.push(starts.last().unwrap() + l.len());
    }
    let (mut kept, mut whole) = (Vec::new(), Vec::new());
    for (k, l) in lines.iter().enumerate() {
        match format {
            Format::VaspXml if *l == "  </energy>\n" => kept.push(starts[k + 1]),
            Format::VaspXml if *l == " </calculation>\n" => whole.push(starts[k + 1]),
            Format::Outcar if l.contains("FREE ENERGIE OF THE ION-ELECTRON") => {
                kept.push(starts[k + 5]);
                whole.push(starts[k + 5]);
            }
            _ => {}
        }
    }
    (kept, whole)
}

/// A file cut every 97th byte (about 6 000 cuts over the four files) never panics. Strictly:
/// the frames before the cut read back unchanged, then an [`Error::Truncated`] naming the file,
/// the frame, the line and the byte. Under `allow_truncated`: the complete frames, the count
/// agreeing with streaming, and a warning (one frame more where the cut leaves a closing tag
/// whole but for its last `>`, which nothing tells from a whole one).
#[test]
fn cut_files_keep_their_complete_steps() {
    for (name, format, count) in FILES {
        let good = data(name);
        let all = read_until_error(&good, format, ReadOptions::new()).0;
        assert_eq!(all.len(), count);
        let last = good.len();
        let closing = if format == Format::Outcar {
            "General timing and accounting"
        } else {
            "</modeling"
        };
        let text = std::str::from_utf8(&good).unwrap();
        let done = text.find(closing).unwrap() + closing.len();
        let (kept, whole) = frame_ends(&good[..last], format);
        assert_eq!(kept.len(), count, "{name}");
        assert_eq!(whole.len(), count, "{name}");
        for cut in (1..last).step_by(97) {
            let bytes = &good[..cut];
            let complete = kept.iter().filter(|e| **e <= cut).count();
            let unchanged = whole.iter().filter(|e| **e <= cut).count();
            let (got, err) = read_until_error(bytes, format, ReadOptions::new());
            assert!(
                got.len() >= complete && got.len() <= complete + 1,
                "{name} cut at {cut}: {} frames, {complete} complete",
                got.len()
            );
            for k in 0..unchanged {
                assert_eq!(got[k], all[k], "{name} cut at {cut}: frame {k}");
            }
            // A run is whole once VASP's closing line is read: `</modeling` (its `>` and
            // what follows are not needed), OUTCAR's `General timing and accounting` (the
            // timing figures after it are not read).
            let Some(e) = err else {
                assert!(cut >= done, "{name} cut at {cut}: no error");
                assert_eq!(got, all, "{name} cut at {cut}");
                continue;
            };
            let msg = e.to_string();
            assert!(
                matches!(e, Error::Truncated { .. }),
                "{name} cut at {cut}: {msg}"
            );
            let loc = e.location().unwrap();
            assert_eq!(loc.frame, Some(got.len()), "{msg}");
            assert!(loc.line.is_some() && loc.byte.is_some(), "{msg}");
            assert!(msg.starts_with("cut: frame "), "{msg}");
            assert!(msg.contains("expected"), "{msg}");
            let lenient = ReadOptions::new().allow_truncated(true);
            let mut t =
                Trajectory::from_reader_with(Cursor::new(bytes.to_vec()), format, "cut", lenient)
                    .unwrap();
            let n = t.n_frames().unwrap();
            assert_eq!(n, got.len(), "{name} cut at {cut}");
            assert_eq!(read_all(&mut t).len(), n, "{name} cut at {cut}");
            assert_eq!(
                t.warnings().len(),
                1,
                "{name} cut at {cut}: {:?}",
                t.warnings()
            );
        }
    }
}

/// A damaged number names its line; a count far beyond the file allocates nothing by it.
#[test]
fn damage_names_the_line_and_counts_allocate_nothing() {
    let err = |text: String, format: Format| {
        let mut t = Trajectory::from_reader(Cursor::new(text), format, "bad").unwrap();
        let e = t.n_frames().err().or_else(|| {
            let mut f = Frame::new();
            std::iter::from_fn(|| Some(t.read_next(&mut f)))
                .find_map(|r| match r {
                    Ok(true) => None,
                    Ok(false) => Some(None),
                    Err(e) => Some(Some(e)),
                })
                .flatten()
        });
        e.expect("an error").to_string()
    };
    let xml = String::from_utf8(data("vasprun_li_relax.xml")).unwrap();
    // The force of the second step, garbled (its only atom's, the row after the second
    // `<varray name="forces" >`).
    let line = 1 + xml
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains("<varray name=\"forces\""))
        .nth(1)
        .unwrap()
        .0;
    let mut lines: Vec<String> = xml.lines().map(String::from).collect();
    assert_eq!(
        lines[line],
        "   <v>      -0.00000000       0.00000000       0.00000000 </v>"
    );
    lines[line] = "   <v>      -0.00000000       0.0000x000       0.00000000 </v>".into();
    let e = err(lines.join("\n"), Format::VaspXml);
    assert!(
        e.starts_with(&format!("bad: frame 1, line {}", line + 1)),
        "{e}"
    );
    assert!(e.contains("0.0000x000"), "{e}");
    // A position row missing (SiO2, 9 atoms): the count is the atominfo's.
    let xml = String::from_utf8(data("vasprun_sio2.xml")).unwrap();
    let calc = xml.lines().position(|l| l == " <calculation>").unwrap();
    let first_pos = calc
        + xml
            .lines()
            .skip(calc)
            .position(|l| l.contains("<varray name=\"positions\""))
            .unwrap();
    let mut lines: Vec<&str> = xml.lines().collect();
    lines.remove(first_pos + 1);
    let e = err(lines.join("\n"), Format::VaspXml);
    assert!(e.contains("one <v>x y z</v> row per atom"), "{e}");
    let outcar = String::from_utf8(data("OUTCAR_li_relax")).unwrap();
    let at = outcar
        .find("free  energy   TOTEN  =        -1.922180 eV")
        .unwrap();
    let line = outcar[..at].matches('\n').count() + 1;
    let bad = outcar.replace("-1.922180 eV", "-1.92x180 eV");
    let e = err(bad, Format::Outcar);
    assert!(e.starts_with(&format!("bad: frame 1, line {line}")), "{e}");
    // Hostile counts over small files.
    for (text, format) in [
        (
            xml.replace("<atoms>       9 </atoms>", "<atoms>  1000000000 </atoms>"),
            Format::VaspXml,
        ),
        (
            outcar.replace(
                "ions per type =               1\n",
                "ions per type =      1000000000\n",
            ),
            Format::Outcar,
        ),
    ] {
        let len = text.len();
        let (e, peak) = measure(|| err(text, format));
        assert!(e.starts_with("bad: frame 0, line"), "{e}");
        assert!(
            peak < 64 * len + (1 << 20),
            "heap peak {peak} for a {len}-byte file"
        );
    }
    // Not a VASP file at all.
    let e = err("hello\nworld\n".into(), Format::VaspXml);
    assert!(e.starts_with("bad: frame 0, line 1, byte 0"), "{e}");
    let e = err("hello\nworld\n".into(), Format::Outcar);
    assert!(e.starts_with("bad: frame 0, line 1, byte 0"), "{e}");
}
