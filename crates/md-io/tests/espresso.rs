//! Quantum ESPRESSO pw.x outputs and inputs written and run by pw.x 6.7 (tests/data/espresso/
//! gen.sh), compared with ASE 3.29's reading of the same files (gen_reference.py) and, for the
//! inputs ASE does not read (ibrav ≠ 0, alat positions with a cell in angstrom), with the
//! geometry pw.x itself printed for them and, for the lattices of the scf runs that left their
//! data file, the geometry in that file with all its digits. Magnetic moments, which ASE reads
//! wrongly from pw.x 6.7's lines, are compared with the file's numbers read by plain text
//! matching.
//!
//! Tolerances. Positions are f32 in a [`Frame`]: below 16 Å an f32 rounds to within 4.8e-7 Å,
//! and ASE's espresso units differ from the CODATA 2006 constants used here (the module doc's
//! Units) by 4.6e-10 relative, so 1e-6 Å bounds both. Cells are f64: 1e-8 Å (the units'
//! difference times 10 Å, with margin). Forces are f32: 1e-6 eV/Å plus 1e-7 relative.
//! Energies: 1e-9 relative (the Rydbergs differ by 1.9e-10); stresses 3e-9 relative
//! (Ry/bohr³: the bohrs' difference three times over). An input against pw.x's header is
//! bounded by the header's printed digits: crystal axes with 6 decimals of alat, positions with
//! 7 (so 5e-7 alat and 5e-8 alat, plus f32), alat at most twice the longest cell vector for the
//! lattices read here.

use crate::support;

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use support::alloc::measure;
use support::dft::{cell, comment_number, comment_stress, max_dev, positions, read_all, rows};
use texmap_md_io::{Error, Format, Frame, ReadOptions, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/espresso")
        .join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(path("reference.json")).unwrap()).unwrap()
}

const OUTPUTS: [&str; 25] = [
    "si_relax",
    "si_md",
    "si_vcrelax",
    "si_vcmd",
    "ibrav0_alat",
    "ibrav1_bohr",
    "ibrav3_bcc",
    "ibrav4_hex",
    "ibrav6_tet",
    "ibrav8_ortho",
    "ibrav5_trig",
    "ibravm5_trig111",
    "ibravm3_bcc",
    "ibrav7_bct",
    "ibrav9_baseco",
    "ibravm9_baseco",
    "ibrav91_aco",
    "ibrav10_fco",
    "ibrav11_bco",
    "ibrav12_mono",
    "ibravm12_mono",
    "ibrav13_cmono",
    "ibravm13_cmono",
    "ibrav14_tri",
    "fe_relax_mag",
];

/// Compares our frame with ASE's, within the module's tolerances; returns the largest
/// deviations: positions and cell (Å), forces (eV/Å), energy (relative).
fn compare(name: &str, k: usize, f: &Frame, w: &Value) -> [f64; 4] {
    let mut worst = [0.0f64; 4];
    let symbols: Vec<&str> = f.elements.iter().map(|e| e.symbol()).collect();
    let want: Vec<&str> = w["symbols"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert_eq!(symbols, want, "{name} frame {k}");
    let dp = max_dev(&positions(f), &rows(&w["positions"]));
    assert!(
        dp <= 1e-6,
        "{name} frame {k}: positions off by {dp} Å (tolerance 1e-6)"
    );
    let dc = max_dev(&cell(f), &rows(&w["cell"]));
    assert!(
        dc <= 1e-8,
        "{name} frame {k}: cell off by {dc} Å (tolerance 1e-8)"
    );
    worst[0] = dp;
    worst[1] = dc;
    match w["forces"].as_array() {
        None => assert!(f.property("fx").is_none(), "{name} frame {k}: no forces"),
        Some(_) => {
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
        }
    }
    match w["energy"].as_f64() {
        None => assert_eq!(comment_number(f, "energy"), None, "{name} frame {k}"),
        Some(e) => {
            let got = comment_number(f, "energy").unwrap();
            worst[3] = (got - e).abs() / e.abs();
            assert!(
                (got - e).abs() <= 1e-9 * e.abs(),
                "{name} frame {k}: energy {got} eV vs ASE {e} (tolerance 1e-9 relative)"
            );
        }
    }
    match w["stress"].as_array() {
        None => assert_eq!(comment_stress(f, true), None, "{name} frame {k}"),
        Some(s) => {
            let got = comment_stress(f, true).unwrap();
            for (c, x) in s.iter().enumerate() {
                let x = x.as_f64().unwrap();
                assert!(
                    (got[c] - x).abs() <= 3e-9 * x.abs() + 1e-15,
                    "{name} frame {k}: stress {got:?} vs ASE {s:?}"
                );
            }
        }
    }
    worst
}

/// Every frame of every output as ASE reads it: the same count (ASE's rule: a relax's final
/// coordinates are no frame, a vc-relax's final scf is one, md's positions after the last step
/// are none), positions, cells, elements, forces, energies and stress.
#[test]
fn outputs_as_ase_reads_them() {
    let r = reference();
    let mut worst = [0.0f64; 4];
    let mut total = 0;
    for name in OUTPUTS {
        let want = &r["outputs"][name]["frames"];
        let file = path(&format!("{name}.pwo"));
        let mut t = Trajectory::open(&file).unwrap();
        assert_eq!(t.format(), Format::EspressoOut, "{name}");
        let frames = want.as_array().unwrap();
        assert_eq!(t.n_frames().unwrap(), frames.len(), "{name}: frame count");
        let got = read_all(&mut t);
        assert_eq!(got.len(), frames.len(), "{name}: frames streamed");
        assert!(t.warnings().is_empty(), "{name}: {:?}", t.warnings());
        for (k, (f, w)) in got.iter().zip(frames).enumerate() {
            let d = compare(name, k, f, w);
            for (w, d) in worst.iter_mut().zip(d) {
                *w = w.max(d);
            }
            total += 1;
            assert_eq!(f.check(), Ok(()), "{name} frame {k}");
            assert_eq!(f.step, Some(k as i64), "{name} frame {k}: step");
            // Random access gives the streamed frame.
            let mut g = Frame::new();
            t.read_frame(k, &mut g).unwrap();
            assert_eq!(&g, f, "{name} frame {k} by index");
        }
    }
    println!(
        "{total} frames as ASE reads them; largest deviations: positions {:.1e} Å, cells \
         {:.1e} Å, forces {:.1e} eV/Å, energies {:.1e} relative",
        worst[0], worst[1], worst[2], worst[3]
    );
    let count = |name: &str| r["outputs"][name]["frames"].as_array().unwrap().len();
    assert_eq!(
        ["si_relax", "si_md", "si_vcrelax", "si_vcmd"].map(count),
        [4, 4, 8, 3],
        "ASE's counts the module doc describes"
    );
}

/// What ASE does not keep: the species labels as names, the md's times and steps, the
/// vc-relax's changing cell and its final scf repeating the last step's geometry.
#[test]
fn labels_times_and_the_final_scf() {
    let mut t = Trajectory::open(path("si_md.pwo")).unwrap();
    let md = read_all(&mut t);
    for f in &md {
        let names: Vec<&str> = f.names.iter().map(|l| l.as_str()).collect();
        assert_eq!(names, ["Si1", "Si2"]);
    }
    let times: Vec<Option<f64>> = md.iter().map(|f| f.time).collect();
    assert_eq!(times, [Some(0.0), Some(0.001), Some(0.0019), Some(0.0029)]);
    let mut t = Trajectory::open(path("si_vcrelax.pwo")).unwrap();
    let vc = read_all(&mut t);
    assert_eq!(vc.len(), 8);
    assert_ne!(vc[0].cell, vc[1].cell, "the cell changes");
    assert_eq!(vc[6].positions, vc[7].positions, "the final scf's geometry");
    assert_eq!(vc[6].cell, vc[7].cell);
    assert_ne!(
        comment_number(&vc[6], "energy"),
        comment_number(&vc[7], "energy")
    );
    // vc-md: the times as pw.x prints them with each step (before the step's move, unlike md).
    let mut t = Trajectory::open(path("si_vcmd.pwo")).unwrap();
    let vcmd = read_all(&mut t);
    let times: Vec<Option<f64>> = vcmd.iter().map(|f| f.time).collect();
    assert_eq!(times, [None, Some(0.0), Some(0.00097)]);
    let volumes: Vec<f64> = vcmd.iter().map(|f| f.cell.unwrap().volume()).collect();
    assert!(
        volumes.is_sorted() && volumes[0] < volumes[2],
        "{volumes:?}"
    );
    // The relax: frame 0 is the input geometry, never an md time.
    let mut t = Trajectory::open(path("si_relax.pwo")).unwrap();
    assert!(read_all(&mut t).iter().all(|f| f.time.is_none()));
}

/// Two runs in one file (outputs concatenated): each banner starts a run, as ASE reads it.
#[test]
fn concatenated_runs() {
    let r = reference();
    let mut bytes = std::fs::read(path("si_md.pwo")).unwrap();
    bytes.extend(std::fs::read(path("si_relax.pwo")).unwrap());
    let mut t =
        Trajectory::from_reader(Cursor::new(bytes), Format::EspressoOut, "two.pwo").unwrap();
    let want = r["concatenated"].as_array().unwrap();
    assert_eq!(t.n_frames().unwrap(), want.len());
    let got = read_all(&mut t);
    for (k, (f, w)) in got.iter().zip(want).enumerate() {
        compare("concatenated", k, f, w);
    }
    let steps: Vec<i64> = got.iter().map(|f| f.step.unwrap()).collect();
    assert_eq!(steps, [0, 1, 2, 3, 0, 1, 2, 3]);
}

/// Each input as pw.x read it: the geometry the run's header printed (ASE's frame 0 of the
/// output), within the printed digits; and as ASE reads the input where it does.
#[test]
fn inputs_as_pwx_and_ase_read_them() {
    let r = reference();
    let mut read_by_ase = 0;
    let mut worst = [0.0f64; 4];
    for name in OUTPUTS.into_iter().chain(["si_vcmd_stopped"]) {
        let mut t = Trajectory::open(path(&format!("{name}.pwi"))).unwrap();
        assert_eq!(t.format(), Format::EspressoIn, "{name}");
        assert_eq!(t.n_frames().unwrap(), 1, "{name}");
        let f = read_all(&mut t).remove(0);
        assert_eq!(f.check(), Ok(()), "{name}");
        // pw.x's header: axes with 6 decimals of alat, positions with 7.
        let header = &r["outputs"][name]["frames"][0];
        let want_cell = rows(&header["cell"]);
        let longest = want_cell
            .iter()
            .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        let alat_bound = 2.0 * longest;
        let dc = max_dev(&cell(&f), &want_cell);
        assert!(dc <= 5e-7 * alat_bound, "{name}: cell off pw.x's by {dc} Å");
        worst[0] = worst[0].max(dc);
        let dp = max_dev(&positions(&f), &rows(&header["positions"]));
        assert!(
            dp <= 5e-8 * alat_bound + 1e-6,
            "{name}: positions off pw.x's by {dp} Å"
        );
        worst[1] = worst[1].max(dp);
        let symbols: Vec<&str> = f.elements.iter().map(|e| e.symbol()).collect();
        let want: Vec<&str> = header["symbols"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap())
            .collect();
        assert_eq!(symbols, want, "{name}");
        // starting_magnetization is no moment.
        assert!(f.property("magmom").is_none(), "{name}");
        // ASE's reading, where it reads the file.
        if let Some(w) = r["inputs"][name]["frame"].as_object() {
            read_by_ase += 1;
            let dp = max_dev(&positions(&f), &rows(&w["positions"]));
            assert!(dp <= 1e-6, "{name}: positions off ASE's by {dp} Å");
            let dc = max_dev(&cell(&f), &rows(&w["cell"]));
            assert!(dc <= 1e-8, "{name}: cell off ASE's by {dc} Å");
            worst[2] = worst[2].max(dc);
            worst[3] = worst[3].max(dp);
        }
    }
    assert_eq!(read_by_ase, 2, "ASE reads ibrav0_alat and si_vcrelax");
    println!(
        "inputs against pw.x's header: cells {:.1e} Å, positions {:.1e} Å; against ASE: cells \
         {:.1e} Å, positions {:.1e} Å",
        worst[0], worst[1], worst[2], worst[3]
    );
    // Labels of one element.
    let mut t = Trajectory::open(path("ibrav6_tet.pwi")).unwrap();
    let f = read_all(&mut t).remove(0);
    let names: Vec<&str> = f.names.iter().map(|l| l.as_str()).collect();
    assert_eq!(names, ["Si1", "Si2"]);
}

/// Every lattice pw.x 6.7 builds from ibrav (from celldm(1..6) or from A, B, C and the cosines)
/// as pw.x built it: the cell and Cartesian positions of its data file
/// (data-file-schema.xml, all digits, converted to Å with pw.x's own bohr). Tolerances: cells
/// are f64; a lattice given by A, B, C (Å) is pw.x's to rounding and latgen's 13-digit √2 and
/// √3 (1e-13 relative), one given by celldm (bohr) differs by the ratio of pw.x 6.7's bohr
/// (CODATA 2018) to the one read here (ASE's, CODATA 2006), 4.4e-9: 5e-9 of the longest vector
/// plus 1e-12 Å; positions are f32: 1e-6 Å.
#[test]
fn every_lattice_as_pwx_built_it() {
    let r = reference();
    let mut worst = [0.0f64; 2];
    let mut worst_abc = 0.0f64;
    let mut lattices = Vec::new();
    for (name, input) in r["inputs"].as_object().unwrap() {
        let Some(xml) = input.get("xml") else {
            continue;
        };
        let mut t = Trajectory::open(path(&format!("{name}.pwi"))).unwrap();
        let f = read_all(&mut t).remove(0);
        let want = rows(&xml["cell"]);
        let longest = want
            .iter()
            .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        let tol = 5e-9 * longest + 1e-12;
        let dc = max_dev(&cell(&f), &want);
        assert!(
            dc <= tol,
            "{name}: cell off pw.x's by {dc} Å (tolerance {tol})"
        );
        // By A, B, C (Å): no bohr between the input and the cell.
        let by_abc = std::fs::read_to_string(path(&format!("{name}.pwi")))
            .unwrap()
            .contains(" A = ");
        if by_abc {
            assert!(dc <= 1e-12 * longest, "{name}: {dc} Å");
            worst_abc = worst_abc.max(dc);
        }
        let dp = max_dev(&positions(&f), &rows(&xml["positions"]));
        assert!(
            dp <= 1e-6,
            "{name}: positions off pw.x's by {dp} Å (tolerance 1e-6)"
        );
        worst = [worst[0].max(dc), worst[1].max(dp)];
        let ibrav = std::fs::read_to_string(path(&format!("{name}.pwi")))
            .unwrap()
            .split("ibrav = ")
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .to_string();
        lattices.push(ibrav.parse::<i64>().unwrap());
    }
    lattices.sort();
    assert_eq!(
        lattices,
        [-13, -12, -9, -5, -3, 5, 7, 9, 10, 11, 12, 13, 14, 91],
        "every ibrav the older fixtures leave out"
    );
    println!(
        "{} lattices as pw.x built them; largest deviations: cells {:.1e} Å ({:.1e} Å by A, B, \
         C), positions {:.1e} Å",
        lattices.len(),
        worst[0],
        worst_abc,
        worst[1]
    );
}

/// pw.x's abc2celldm: with A, the cosines go to the celldm slot each lattice reads (cos α, cos β,
/// cos γ as celldm(4..6) for ibrav 14; cosAC as celldm(5) for -12 and -13; cosAB as celldm(4)
/// for ±5, 12, 13), and a cosine the lattice does not read is ignored as pw.x ignores it.
#[test]
fn cosines_as_celldm() {
    let read = |text: String| {
        let mut t =
            Trajectory::from_reader(Cursor::new(text), Format::EspressoIn, "x.pwi").unwrap();
        read_all(&mut t).remove(0)
    };
    const BOHR: f64 = 0.529_177_208_59;
    let cases = [
        (
            "ibrav14_tri",
            "A = 4.1, B = 4.6, C = 5.2, cosAB = 0.1, cosAC = 0.2, cosBC = 0.3",
            format!(
                "celldm(1) = {}, celldm(2) = {}, celldm(3) = {}, celldm(4) = 0.3, celldm(5) = 0.2, celldm(6) = 0.1",
                4.1 / BOHR,
                4.6 / 4.1,
                5.2 / 4.1
            ),
        ),
        (
            "ibravm13_cmono",
            "A = 4.2, B = 4.0, C = 5.0, cosAC = 0.3",
            format!(
                "celldm(1) = {}, celldm(2) = {}, celldm(3) = {}, celldm(5) = 0.3, cosAB = 0.7",
                4.2 / BOHR,
                4.0 / 4.2,
                5.0 / 4.2
            ),
        ),
        (
            "ibrav12_mono",
            "A = 4.0, B = 4.5, C = 5.0, cosAB = 0.2",
            format!(
                "celldm(1) = {}, celldm(2) = {}, celldm(3) = {}, celldm(4) = 0.2, celldm(5) = 0.9",
                4.0 / BOHR,
                4.5 / 4.0,
                5.0 / 4.0
            ),
        ),
    ];
    for (name, abc, celldm) in cases {
        let text = std::fs::read_to_string(path(&format!("{name}.pwi"))).unwrap();
        assert!(text.contains(abc), "{name}");
        let by_abc = read(text.clone());
        let by_celldm = read(text.replace(abc, &celldm));
        let d = max_dev(&cell(&by_abc), &cell(&by_celldm));
        assert!(d <= 1e-12, "{name}: {d} Å");
    }
}

/// Cell parameters out of pw.x's bounds are errors at their token (or at ibrav when missing).
#[test]
fn lattice_parameters_out_of_bounds() {
    let err = |name: &str, from: &str, to: &str| -> String {
        let text = std::fs::read_to_string(path(&format!("{name}.pwi"))).unwrap();
        assert!(text.contains(from), "{name}: {from}");
        let mut t = Trajectory::from_reader(
            Cursor::new(text.replace(from, to)),
            Format::EspressoIn,
            "bad",
        )
        .unwrap();
        t.n_frames().unwrap_err().to_string()
    };
    let e = err("ibrav12_mono", "cosAB = 0.2", "cosAB = 1.0");
    assert!(e.starts_with("bad: frame 0, line 6, byte"), "{e}");
    assert!(
        e.contains("cosAB with A) in (-1, 1) for ibrav = 12 or 13, found '1.0'"),
        "{e}"
    );
    let e = err("ibrav5_trig", "celldm(4) = 0.3", "celldm(4) = -0.6");
    assert!(
        e.contains("in (-1/2, 1) for ibrav = 5 or -5, found '-0.6'"),
        "{e}"
    );
    let e = err("ibravm12_mono", "celldm(5) = -0.25", "celldm(5) = 1d0");
    assert!(e.contains("for ibrav = -12 or -13, found '1d0'"), "{e}");
    let e = err(
        "ibrav14_tri",
        "cosAB = 0.1, cosAC = 0.2, cosBC = 0.3",
        "cosAB = -0.9, cosAC = -0.9, cosBC = -0.9",
    );
    assert!(e.contains("cell with volume > 0"), "{e}");
    assert!(
        e.contains("found 'cos α -0.9, cos β -0.9, cos γ -0.9'"),
        "{e}"
    );
    let e = err("ibrav7_bct", "celldm(3) = 1.4", "celldm(2) = 1.4");
    assert!(
        e.contains("found 'ibrav = 7 (body-centred tetragonal) without it'"),
        "{e}"
    );
    let e = err("ibravm9_baseco", "B = 4.4", "B = -4.4");
    assert!(e.contains("celldm(2) (b/a) or B > 0"), "{e}");
    assert!(e.contains("found '-4.4'"), "{e}");
    let e = err("ibrav10_fco", "C = 6.0", "C = x");
    assert!(e.contains("expected a real number, found 'x'"), "{e}");
}

/// A spin-polarised run's moments (`Magnetic moment per site`, the last block of each step) as
/// the property `magmom` (μB), against the numbers read from the file by plain text matching
/// (gen_reference.py). ASE 3.29 takes the last field of pw.x 6.7's lines, the constraint
/// column (`constr:    0.0000`), so its moments are all 0 and are not the reference here.
#[test]
fn magnetic_moments() {
    let r = reference();
    let out = &r["outputs"]["fe_relax_mag"];
    let want = out["magn"].as_array().unwrap();
    let mut t = Trajectory::open(path("fe_relax_mag.pwo")).unwrap();
    let frames = read_all(&mut t);
    assert_eq!(
        frames.len(),
        3,
        "relax stopped at nstep = 3: its last positions have no results"
    );
    for (k, f) in frames.iter().enumerate() {
        let got = f.property("magmom").unwrap();
        let w: Vec<f64> = want[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(got.len(), w.len());
        for (g, w) in got.iter().zip(&w) {
            // f32 of a 4-decimal number below 8: within 4.8e-7.
            assert!(
                (f64::from(*g) - w).abs() <= 5e-7,
                "frame {k}: {got:?} vs {w:?}"
            );
        }
        let ase: Vec<f64> = out["frames"][k]["magmoms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert!(ase.iter().all(|m| *m == 0.0), "ASE's reading: {ase:?}");
    }
    assert_ne!(frames[0].property("magmom"), frames[2].property("magmom"));
    // The input's starting_magnetization(1) is no moment.
    let mut t = Trajectory::open(path("fe_relax_mag.pwi")).unwrap();
    assert!(read_all(&mut t)[0].property("magmom").is_none());
    // A run without spin: no moments.
    let mut t = Trajectory::open(path("si_relax.pwo")).unwrap();
    assert!(
        read_all(&mut t)
            .iter()
            .all(|f| f.property("magmom").is_none())
    );
    // pw.x 6.8's format of the same lines reads alike.
    let text = std::fs::read_to_string(path("fe_relax_mag.pwo")).unwrap();
    let newer: String = text
        .split_inclusive('\n')
        .map(|l| match l.trim_start().strip_prefix("atom:") {
            Some(rest) if l.contains("magn:") => {
                let f: Vec<&str> = rest.split_whitespace().collect();
                format!(
                    "     atom {:>6} (R=0.190)  charge={:>8}  magn={:>8}\n",
                    f[0], f[2], f[4]
                )
            }
            _ => l.to_string(),
        })
        .collect();
    assert!(newer.contains("(R=0.190)  charge=  6.2918  magn=  3.3015"));
    let mut t =
        Trajectory::from_reader(Cursor::new(newer), Format::EspressoOut, "newer.pwo").unwrap();
    let again = read_all(&mut t);
    for (f, g) in frames.iter().zip(&again) {
        assert_eq!(f.property("magmom"), g.property("magmom"));
    }
    // Damage in a moment line, and a block cut short.
    let bad = text.replacen("magn:    3.3081", "magn:    3.3x81", 1);
    let mut t = Trajectory::from_reader(Cursor::new(bad), Format::EspressoOut, "bad").unwrap();
    let e = t.n_frames().unwrap_err().to_string();
    assert!(e.starts_with("bad: frame 1, line 468, byte"), "{e}");
    assert!(e.contains("a moment line"), "{e}");
    assert!(e.contains("found '3.3x81'"), "{e}");
    let cut_at = text.find("     atom:    2    charge:    6.2892").unwrap();
    let opts = ReadOptions::new().allow_truncated(true);
    let mut t = Trajectory::from_reader_with(
        Cursor::new(text[..cut_at].to_string()),
        Format::EspressoOut,
        "cut",
        opts,
    )
    .unwrap();
    assert_eq!(t.n_frames().unwrap(), 1);
    assert!(
        t.warnings()[0]
            .to_string()
            .contains("more lines of the magnetic moments"),
        "{:?}",
        t.warnings()
    );
}

/// An output cut anywhere keeps the frames before the cut under `allow_truncated`, with a
/// warning; strictly the cut is an error naming the frame. A run that ends without `JOB DONE.`
/// is cut even when its last step's results are whole.
#[test]
fn cut_outputs() {
    let text = std::fs::read_to_string(path("si_relax.pwo")).unwrap();
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let find = |from: usize, needle: &str| {
        from + lines[from..]
            .iter()
            .position(|l| l.contains(needle))
            .unwrap()
    };
    let cut_at = |n: usize| lines[..n].concat();
    let step1 = find(0, "ATOMIC_POSITIONS") + 1;
    let scf2 = find(step1, "End of self-consistent calculation");
    let energy2 = find(step1, "!    total energy");
    let final_coords = find(0, "Begin final coordinates");
    let job_done = find(0, "JOB DONE.");
    // (lines kept, frames kept, the frame the strict error names, what it says)
    let cases = [
        (scf2 - 2, 1, 1, "the step's results"),
        (energy2, 1, 1, "the step's '!    total energy' line"),
        (energy2 + 3, 1, 1, "the step's forces"),
        (final_coords, 4, 4, "JOB DONE"),
        (job_done, 4, 4, "JOB DONE"),
    ];
    for (n, frames, bad, what) in cases {
        let cut = cut_at(n);
        let mut t =
            Trajectory::from_reader(Cursor::new(cut.clone()), Format::EspressoOut, "cut.pwo")
                .unwrap();
        let e = t.n_frames().unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, Error::Truncated { .. }), "{n}: {msg}");
        assert!(
            msg.starts_with(&format!("cut.pwo: frame {bad}, line")),
            "{n}: {msg}"
        );
        assert!(msg.contains(what), "{n}: {msg}");
        let opts = ReadOptions::new().allow_truncated(true);
        let mut t =
            Trajectory::from_reader_with(Cursor::new(cut), Format::EspressoOut, "cut.pwo", opts)
                .unwrap();
        assert_eq!(t.n_frames().unwrap(), frames, "{n}");
        assert_eq!(read_all(&mut t).len(), frames, "{n}");
        assert_eq!(t.warnings().len(), 1, "{n}: {:?}", t.warnings());
    }
    // pw.x's own error ends the run: the cut names it.
    let failed = cut_at(scf2 - 2)
        + "\n %%%%%%%%%%%%%%\n     Error in routine c_bands (1):\n     too many bands are not converged\n";
    let mut t =
        Trajectory::from_reader(Cursor::new(failed), Format::EspressoOut, "failed.pwo").unwrap();
    let e = t.n_frames().unwrap_err().to_string();
    assert!(e.contains("pw.x stopped with an error at line"), "{e}");
    assert!(e.contains("Error in routine c_bands"), "{e}");
}

/// A real run that pw.x stopped with an error in step 2's scf (si_vcmd_stopped.pwo: the cell
/// blew up): strictly a cut at frame 2 that names pw.x's error; under `allow_truncated` the two
/// complete frames, as ASE reads the file.
#[test]
fn a_run_pwx_stopped() {
    let r = reference();
    let file = path("si_vcmd_stopped.pwo");
    let mut t = Trajectory::open(&file).unwrap();
    let e = t.n_frames().unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::Truncated { .. }), "{msg}");
    assert!(
        msg.contains("si_vcmd_stopped.pwo: frame 2, line 494"),
        "{msg}"
    );
    assert!(
        msg.contains("pw.x stopped with an error at line 489: Error in routine electrons (1):"),
        "{msg}"
    );
    let opts = ReadOptions::new().allow_truncated(true);
    let mut t = Trajectory::open_with(&file, opts).unwrap();
    let want = r["outputs"]["si_vcmd_stopped"]["frames"]
        .as_array()
        .unwrap();
    assert_eq!(t.n_frames().unwrap(), want.len());
    let got = read_all(&mut t);
    assert_eq!(got.len(), 2);
    for (k, (f, w)) in got.iter().zip(want).enumerate() {
        compare("si_vcmd_stopped", k, f, w);
    }
    assert_eq!(t.warnings().len(), 1);
}

/// Damage is an error naming the file, frame, line and what was expected; counts in the file
/// are not trusted to size anything.
#[test]
fn damage_is_located() {
    let out = std::fs::read_to_string(path("si_relax.pwo")).unwrap();
    let input = std::fs::read_to_string(path("ibrav4_hex.pwi")).unwrap();
    let err = |text: String, format: Format| -> String {
        let mut t = Trajectory::from_reader(Cursor::new(text), format, "bad").unwrap();
        t.n_frames().unwrap_err().to_string()
    };
    // An ibrav pw.x does not know is named.
    for bad in ["15", "-7", "92"] {
        let e = err(
            input.replace("ibrav = 4", &format!("ibrav = {bad}")),
            Format::EspressoIn,
        );
        assert!(e.starts_with("bad: frame 0, line 6, byte"), "{e}");
        assert!(e.contains(&format!("found 'ibrav = {bad}'")), "{e}");
    }
    let e = err(input.replace("{crystal}", "crystal_sg"), Format::EspressoIn);
    assert!(e.contains("crystal_sg"), "{e}");
    let e = err(input.replace("1/3  2/3", "1/3  2/x"), Format::EspressoIn);
    assert!(e.starts_with("bad: frame 0, line 15"), "{e}");
    assert!(e.contains("found '2/x'"), "{e}");
    let e = err(input.replace("celldm(3) = 1.6,", ""), Format::EspressoIn);
    assert!(e.starts_with("bad: frame 0, line 6, byte"), "{e}");
    assert!(
        e.contains("expected celldm(3) (c/a) or C > 0 in &SYSTEM, which this ibrav needs, found 'ibrav = 4 (hexagonal) without it'"),
        "{e}"
    );
    let e = err(input.replace("  Si  2/3", "  Ge  2/3"), Format::EspressoIn);
    assert!(
        e.contains("a species label of the ATOMIC_SPECIES card, found 'Ge'"),
        "{e}"
    );
    let e = err(
        input.replace("celldm(1) = 7.3D0", "celldm(1) = 7.3D0, A = 3.9"),
        Format::EspressoIn,
    );
    assert!(e.contains("not both"), "{e}");
    // A damaged output line is named.
    let e = err(
        out.replacen(
            "     atom    2 type  1   force =",
            "     atom    2 type  1   force = x",
            1,
        ),
        Format::EspressoOut,
    );
    assert!(e.starts_with("bad: frame 0, line"), "{e}");
    assert!(e.contains("a force line"), "{e}");
    let e = err(
        out.replacen("celldm(1)=  10.200000", "celldm(1)= -10.200000", 1),
        Format::EspressoOut,
    );
    assert!(e.contains("celldm(1) > 0"), "{e}");
    // A step without the energy its run's first step printed (the line damaged) is named at the
    // next step's first line.
    let second = out.match_indices("!    total energy").nth(1).unwrap().0;
    let mut damaged = out.clone();
    damaged.replace_range(second..second + 1, "?");
    let e = err(damaged, Format::EspressoOut);
    assert!(e.starts_with("bad: frame 1, line"), "{e}");
    assert!(
        e.contains("'!    total energy' line before the next step"),
        "{e}"
    );
    assert!(e.contains("found 'ATOMIC_POSITIONS (alat)'"), "{e}");
    // Not a pw.x output at all.
    let e = err("hello\nworld\n".into(), Format::EspressoOut);
    assert!(e.starts_with("bad: frame 0, line 1, byte 0"), "{e}");
    assert!(e.contains("Program PWSCF"), "{e}");
    // Hostile counts: a billion atoms in the header and in the input, read from a small file.
    let hostile_out = out.replace(
        "number of atoms/cell      =            2",
        "number of atoms/cell      =   1000000000",
    );
    let hostile_in = input.replace("nat = 2", "nat = 1000000000");
    for (text, format) in [
        (hostile_out, Format::EspressoOut),
        (hostile_in, Format::EspressoIn),
    ] {
        let len = text.len();
        let (e, peak) = measure(|| err(text, format));
        assert!(e.starts_with("bad: frame 0, line"), "{e}");
        assert!(
            peak < 64 * len + (1 << 20),
            "heap peak {peak} for a {len}-byte file"
        );
    }
}

/// A file is told by its content where its name does not say: pw.x's banner in an `.out`, a
/// first namelist in an `.in`; an `.in` or `.out` of another program is not taken.
#[test]
fn told_by_content() {
    let dir = tempfile::tempdir().unwrap();
    let copy = |from: &str, to: &str| {
        let p = dir.path().join(to);
        std::fs::copy(path(from), &p).unwrap();
        p
    };
    let t = Trajectory::open(copy("si_md.pwo", "run.out")).unwrap();
    assert_eq!(t.format(), Format::EspressoOut);
    let t = Trajectory::open(copy("si_md.pwi", "run.in")).unwrap();
    assert_eq!(t.format(), Format::EspressoIn);
    for (name, text) in [
        ("in.lammps.in", "units real\natom_style full\n"),
        ("g09.out", " Entering Gaussian System, Link 0=g09\n"),
        ("ph.in", "&inputph\n  tr2_ph = 1.0d-14\n/\n"),
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let e = Trajectory::open(&p).err().unwrap();
        assert!(matches!(e, Error::UnknownFormat { .. }), "{name}: {e}");
    }
    assert_eq!(Format::from_extension("pwo"), Some(Format::EspressoOut));
    assert_eq!(
        Format::from_extension("espresso-in"),
        Some(Format::EspressoIn)
    );
    assert_eq!(Format::from_extension("in"), None);
    assert_eq!(Format::from_extension("out"), None);
}
