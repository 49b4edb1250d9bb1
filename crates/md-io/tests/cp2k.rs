//! CP2K's MD and optimisation outputs (tests/data/cp2k, written by CP2K 2023.1 with `gen.sh`):
//! the `-pos-1.xyz` comment lines read as step, time and energy, and the `.cell` file's cells
//! given to the frames by step ([`CellTable`], [`Sequence::set_cells`]).
//!
//! Against: ASE 3.29's reading of the same `.xyz` files (`gen_reference.py`: its `info` dict of
//! `i`, `time`, `E`, and the positions), and CP2K's own restart file of the run's last step,
//! which holds the cell and positions with all their digits. Tolerances: positions are f32 in
//! a [`Frame`] (below 32 Å an f32 is within 2e-6 Å of the printed value); the `.cell` file
//! prints 10 decimals, so its vectors are within 5e-11 Å of the restart's (plus the f64 parse).

use crate::support::dft::rows;
use crate::support::fixtures;

use std::io::Cursor;
use std::path::PathBuf;
use std::sync::Arc;

use serde_json::Value;
use texmap_md_io::cells::{CellOverride, CellTable};
use texmap_md_io::{Error, Frame, ReadOptions, Sequence, Trajectory, UnitCell};

fn path(name: &str) -> PathBuf {
    fixtures::data(&format!("cp2k/{name}"))
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(path("reference.json")).unwrap()).unwrap()
}

fn frames(name: &str) -> Vec<Frame> {
    fixtures::stream(&mut Trajectory::open(path(name)).unwrap())
}

/// Every frame of the NPT run and of the optimisation: step = ASE's `i`, time (ps) = ASE's
/// `time` (fs) / 1000 where CP2K writes one, `E` the same number as ASE's, positions equal.
#[test]
fn comment_lines_give_step_time_and_energy_as_ase_reads_them() {
    let r = reference();
    for (key, file, has_time) in [
        ("npt_frames", "ar_npt-pos-1.xyz", true),
        ("opt_frames", "ar_opt-pos-1.xyz", false),
    ] {
        let ours = frames(file);
        let theirs = r[key].as_array().unwrap();
        assert_eq!(ours.len(), theirs.len(), "{file}");
        for (k, (f, t)) in ours.iter().zip(theirs).enumerate() {
            let info = &t["info"];
            assert_eq!(
                f.step,
                Some(info["i"].as_i64().unwrap()),
                "{file} frame {k}"
            );
            match (f.time, has_time) {
                (Some(ps), true) => {
                    let fs = info["time"].as_f64().unwrap();
                    assert!((ps * 1000.0 - fs).abs() < 1e-9, "{file} frame {k}: {ps} ps");
                }
                (None, false) => {}
                (time, _) => panic!("{file} frame {k}: time {time:?}"),
            }
            let e: f64 = f.comment_value("E").unwrap().parse().unwrap();
            assert_eq!(e, info["E"].as_f64().unwrap(), "{file} frame {k}");
            assert!(f.cell.is_none(), "{file}: CP2K's .xyz holds no cell");
            let want = rows(&t["positions"]);
            assert_eq!(f.positions.len(), want.len());
            for (p, q) in f.positions.iter().zip(&want) {
                for d in 0..3 {
                    assert!((p[d] as f64 - q[d]).abs() < 2e-6, "{file} frame {k}");
                }
            }
            assert!(f.elements.iter().all(|e| e.symbol() == "Ar"));
        }
    }
}

/// The `.cell` file's step 40 equals the restart file's cell (all digits) to the 10 printed
/// decimals, and the run's last frame equals the restart's positions.
#[test]
fn cell_file_agrees_with_the_restart_file() {
    let r = reference();
    let table = CellTable::read(path("ar_npt-1.cell")).unwrap();
    assert_eq!(table.len(), 41);
    assert_eq!(table.steps(), (0, 40));
    let (time, cell) = table.at_step(40).unwrap();
    assert_eq!(time, 200.0);
    let want = rows(&r["restart"]["cell"]);
    for (row, w) in cell.matrix().iter().zip(&want) {
        for d in 0..3 {
            assert!((row[d] - w[d]).abs() < 6e-11, "{row:?} against {w:?}");
        }
    }
    let last = frames("ar_npt-pos-1.xyz").pop().unwrap();
    assert_eq!(last.step, Some(40));
    for (p, q) in last.positions.iter().zip(rows(&r["restart"]["positions"])) {
        for d in 0..3 {
            assert!((p[d] as f64 - q[d]).abs() < 2e-6);
        }
    }
}

/// Through a [`Sequence`]: read in order and out of order, every frame gets the cell of its
/// step, and ASE's wrap with that cell (done in gen_reference.py from numpy's reading of the
/// `.cell` file) agrees with wrapping our frame into the cell we gave it.
#[test]
fn frames_get_the_cell_of_their_step() {
    let r = reference();
    let table = Arc::new(CellTable::read(path("ar_npt-1.cell")).unwrap());
    let mut seq = Sequence::open(&[path("ar_npt-pos-1.xyz")], None, ReadOptions::new()).unwrap();
    seq.set_cells(Some(CellOverride::Steps(table.clone())));
    let mut f = Frame::new();
    let mut k = 0;
    while seq.read_next(&mut f).unwrap() {
        let step = f.step.unwrap();
        assert_eq!(step, 4 * k as i64);
        assert_eq!(f.cell.as_ref(), Some(table.at_step(step).unwrap().1));
        let cell = f.cell.unwrap();
        let wrapped = rows(&r["npt_wrapped"][k]);
        for (p, q) in f.positions.iter().zip(&wrapped) {
            let w = wrap(&cell, [p[0] as f64, p[1] as f64, p[2] as f64]);
            // A coordinate at a face can wrap to either side: compare modulo the cell.
            let d = [w[0] - q[0], w[1] - q[1], w[2] - q[2]];
            let frac = fractional(&cell, d);
            for c in frac {
                let off = c - c.round();
                assert!(off.abs() < 1e-6, "frame {k}: {w:?} against ASE's {q:?}");
            }
            let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!(dist < 1e-5, "frame {k}: {w:?} against ASE's {q:?}");
        }
        k += 1;
    }
    assert_eq!(k, 11);
    // Out of order: frame 7 is step 28.
    seq.read_frame(7, &mut f).unwrap();
    assert_eq!(f.cell.as_ref(), Some(table.at_step(28).unwrap().1));
    // A fixed cell for every frame.
    let fixed = UnitCell::from_lengths_angles([15.78; 3], [90.0; 3]).unwrap();
    seq.set_cells(Some(CellOverride::Fixed(fixed)));
    seq.read_frame(3, &mut f).unwrap();
    assert_eq!(f.cell, Some(fixed));
}

/// `p` in fractional coordinates of `cell` (p = s·M, the cell vectors M's rows).
fn fractional(cell: &UnitCell, p: [f64; 3]) -> [f64; 3] {
    let m = cell.matrix().map(glam::DVec3::from_array);
    (glam::DMat3::from_cols(m[0], m[1], m[2]).inverse() * glam::DVec3::from_array(p)).to_array()
}

/// `p` moved into the cell by whole cell vectors (fractional coordinates in [0, 1)).
fn wrap(cell: &UnitCell, p: [f64; 3]) -> [f64; 3] {
    let m = cell.matrix();
    let s = fractional(cell, p).map(|c| c - c.floor());
    [0, 1, 2].map(|d| s[0] * m[0][d] + s[1] * m[1][d] + s[2] * m[2][d])
}

/// Bad cell files and frames the table cannot place: errors naming the file and line, or the
/// frame and step.
#[test]
fn bad_cell_files_and_unplaceable_frames_are_named() {
    let header = "#   Step   Time [fs]       Ax [Angstrom] ... Volume [Angstrom^3]\n";
    let good = "       0       0.000  10 0 0  0 11 0  0 0 12  1320\n";
    let cases = [
        // A volume that is not the vectors' determinant: columns of another file.
        (
            "       0       0.000  10 0 0  0 11 0  0 0 12  1000\n",
            2,
            "volume 1000",
        ),
        (
            "       0       0.000  10 0 0  0 11 0  0 0 12\n",
            2,
            "11 fields",
        ),
        (
            "       x       0.000  10 0 0  0 11 0  0 0 12  1320\n",
            2,
            "step x",
        ),
        (
            "       0       0.000  10 0 0  0 11 0  0 0 nan  1320\n",
            2,
            "nan",
        ),
        // Left-handed vectors (volume < 0).
        (
            "       0       0.000  10 0 0  0 11 0  0 0 -12  -1320\n",
            2,
            "step 0",
        ),
    ];
    for (line, at, found) in cases {
        let text = format!("{header}{line}");
        match CellTable::parse(Cursor::new(text), "bad.cell") {
            Err(Error::Parse {
                at: loc, found: f, ..
            }) => {
                assert_eq!(loc.line, Some(at), "{line}");
                assert!(f.contains(found), "{line}: {f}");
            }
            other => panic!("{line}: {other:?}"),
        }
    }
    let e = CellTable::parse(Cursor::new(header), "empty.cell").unwrap_err();
    assert!(e.to_string().contains("empty.cell"), "{e}");
    // A later line of the same step (a restarted run) replaces the earlier one.
    let text = format!("{header}{good}       0       0.000  10 0 0  0 11 0  0 0 13  1430\n");
    let t = CellTable::parse(Cursor::new(text), "twice.cell").unwrap();
    assert_eq!(t.len(), 1);
    assert_eq!(t.at_step(0).unwrap().1.matrix()[2], [0.0, 0.0, 13.0]);

    // Frames: the table holds step 0 only.
    let table =
        Arc::new(CellTable::parse(Cursor::new(format!("{header}{good}")), "t.cell").unwrap());
    let over = CellOverride::Steps(table);
    let mut f = Frame::new();
    let e = over.apply(&mut f, 3, "run.xyz").unwrap_err().to_string();
    assert!(
        e.contains("run.xyz: frame 3") && e.contains("no step number"),
        "{e}"
    );
    f.step = Some(8);
    let e = over.apply(&mut f, 3, "run.xyz").unwrap_err().to_string();
    assert!(
        e.contains("step 8 is not in t.cell (1 steps, 0 to 0)"),
        "{e}"
    );
    f.step = Some(0);
    f.time = Some(0.5);
    let e = over.apply(&mut f, 3, "run.xyz").unwrap_err().to_string();
    assert!(e.contains("500.000 fs, but at 0.000 fs in t.cell"), "{e}");
    f.time = Some(0.0);
    over.apply(&mut f, 3, "run.xyz").unwrap();
    assert_eq!(f.cell.unwrap().volume(), 1320.0);
}

/// The spaced `key = value,` pairs do not change extended XYZ: ASE's `key=value` comment
/// reads as before, and a CP2K-like line whose first key is not `i` keeps `Time` in ps.
#[test]
fn spaced_pairs_leave_extended_xyz_alone() {
    let text = "1\nLattice=\"5 0 0 0 5 0 0 0 5\" Properties=species:S:1:pos:R:3 energy=-1.5 Time=2.5 step=7\nAr 1 2 3\n\
                1\nstep = 9, Time = 0.25, energy = -2\nAr 1 2 3\n";
    let mut t =
        Trajectory::from_reader(Cursor::new(text), texmap_md_io::Format::Xyz, "x.xyz").unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    assert_eq!((f.step, f.time), (Some(7), Some(2.5)));
    assert_eq!(f.comment_value("energy"), Some("-1.5"));
    assert!(f.cell.is_some());
    assert!(t.read_next(&mut f).unwrap());
    assert_eq!((f.step, f.time), (Some(9), Some(0.25)));
    assert_eq!(f.comment_value("energy"), Some("-2"));
}

/// The `.cell` file cut at every byte: never a panic; the whole lines before the cut are the
/// table, and a cut inside a line is an error naming that line, unless only the volume's last
/// digits were cut (the cell vectors whole, the volume still within its check).
#[test]
fn cell_file_cut_at_every_byte() {
    let bytes = std::fs::read(path("ar_npt-1.cell")).unwrap();
    let full = CellTable::parse(Cursor::new(&bytes), "c.cell").unwrap();
    let mut errors = 0;
    for cut in 0..bytes.len() {
        let head = &bytes[..cut];
        let whole_lines = head.iter().filter(|&&b| b == b'\n').count();
        match CellTable::parse(Cursor::new(head), "c.cell") {
            Ok(t) => {
                // Rows: whole data lines (the header is line 1), plus a last line cut only in
                // its volume.
                let rows = t.len();
                assert!(
                    rows == whole_lines.saturating_sub(1) || rows == whole_lines,
                    "cut {cut}: {rows} rows after {whole_lines} lines"
                );
                for step in 0..rows as i64 {
                    assert_eq!(t.at_step(step).unwrap().1, full.at_step(step).unwrap().1);
                }
            }
            Err(Error::Parse { at, .. }) => {
                errors += 1;
                let line = at.line.unwrap_or(0);
                assert!(
                    line == whole_lines as u64 + 1 || (whole_lines <= 1 && at.line.is_none()),
                    "cut {cut}: error at line {line} after {whole_lines} whole lines"
                );
            }
            Err(e) => panic!("cut {cut}: {e}"),
        }
    }
    assert!(errors > bytes.len() / 2, "{errors} errors");
}
