//! GROMACS TRR files written by our writer, against the file GROMACS 2022.5's `mdrun` wrote for
//! the same frames and what GROMACS (`gmx check`) and MDAnalysis 2.11 read from ours
//! (tests/data/trr_write/gen_trr_write.sh: 213 SPC waters, 20 steps, positions every 10 steps,
//! velocities every 20, forces every 5).

use std::io::{Cursor, Read};
use std::path::PathBuf;

use texmap_md_io::{Format, Frame, Trajectory, Writer};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/trr_write")
        .join(name)
}

/// Every frame of `path` that has positions (the others hold only forces).
fn frames(path: &std::path::Path) -> Vec<Frame> {
    let mut t = Trajectory::open(path).unwrap_or_else(|e| panic!("{e}"));
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap_or_else(|e| panic!("{e}")) {
        if f.n_atoms() > 0 {
            out.push(f.clone());
        }
    }
    out
}

fn written(frames: &[Frame]) -> Vec<u8> {
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Trr, "written.trr").unwrap();
    for f in frames {
        w.write_frame(f).unwrap_or_else(|e| panic!("{e}"));
    }
    w.finish().unwrap().into_inner()
}

/// One TRR record as the bytes give it, parsed here independently of the crate's reader:
/// the thirteen header integers, time and λ, and every f32 of the blocks.
struct Record {
    ints: [i32; 13],
    time: u32,
    lambda: u32,
    reals: Vec<u32>,
}

fn records(b: &[u8]) -> Vec<Record> {
    let word = |at: usize| u32::from_be_bytes(b[at..at + 4].try_into().unwrap());
    let mut out = Vec::new();
    let mut p = 0;
    while p < b.len() {
        assert_eq!(word(p), 1993, "magic at byte {p}");
        assert_eq!(&b[p + 12..p + 24], b"GMX_trn_file");
        let ints: [i32; 13] = std::array::from_fn(|k| word(p + 24 + 4 * k) as i32);
        let size: usize = ints[..10].iter().map(|&s| s as usize).sum();
        assert_eq!(ints[2] % 36, 0, "single precision");
        let (time, lambda) = (word(p + 76), word(p + 80));
        let reals = (0..size / 4).map(|k| word(p + 84 + 4 * k)).collect();
        out.push(Record {
            ints,
            time,
            lambda,
            reals,
        });
        p += 84 + size;
    }
    out
}

#[test]
fn rewriting_the_gromacs_file_gives_the_committed_file() {
    let frames = frames(&data("md.trr"));
    assert_eq!(frames.len(), 3, "steps 0, 10 and 20 have positions");
    let bytes = written(&frames);
    if std::env::var_os("TEXMAP_BLESS").is_some() {
        std::fs::write(data("written.trr"), &bytes).unwrap();
    }
    let committed = std::fs::read(data("written.trr")).unwrap();
    assert!(
        bytes == committed,
        "written.trr differs from what is written now"
    );
}

#[test]
fn our_records_are_gromacs_records_to_the_last_place() {
    let gromacs = std::fs::read(data("md.trr")).unwrap();
    let ours = written(&frames(&data("md.trr")));
    let (g, o) = (records(&gromacs), records(&ours));
    assert_eq!(g.len(), 5);
    assert_eq!(o.len(), 3);
    let (mut same, mut total) = (0usize, 0usize);
    for r in &o {
        // The GROMACS record of the same step (ints[11]).
        let src = g.iter().find(|s| s.ints[11] == r.ints[11]).unwrap();
        // Block sizes, atoms, step, nre; time and λ bit for bit.
        assert_eq!(r.ints, src.ints, "step {}", r.ints[11]);
        assert_eq!((r.time, r.lambda), (src.time, src.lambda));
        assert_eq!(r.reals.len(), src.reals.len());
        for (k, (a, b)) in r.reals.iter().zip(&src.reals).enumerate() {
            // nm → Å → nm in f32 (and forces the other way) can move a value by one unit in
            // the last place, never more.
            assert!(
                a.abs_diff(*b) <= 1,
                "step {} real {k}: {} against GROMACS's {}",
                r.ints[11],
                f32::from_bits(*a),
                f32::from_bits(*b)
            );
            same += usize::from(a == b);
            total += 1;
        }
    }
    eprintln!("{same} of {total} reals bit for bit the same as GROMACS's, the rest one ulp away");
    assert!(same * 10 > total * 8, "{same} of {total}");
}

/// What MDAnalysis 2.11's TRRReader read from written.trr (gen_trr_write.py).
#[test]
fn mdanalysis_reads_our_file_as_we_wrote_it() {
    let mut gz = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(data("mdanalysis.json.gz")).unwrap())
        .read_to_string(&mut gz)
        .unwrap();
    let reference: serde_json::Value = serde_json::from_str(&gz).unwrap();
    let ours = frames(&data("written.trr"));
    let mda = reference["frames"].as_array().unwrap();
    assert_eq!(mda.len(), ours.len());
    let floats = |v: &serde_json::Value| -> Vec<f32> {
        v.as_array()
            .unwrap()
            .iter()
            .flat_map(|r| r.as_array().unwrap().iter())
            .map(|x| x.as_f64().unwrap() as f32)
            .collect()
    };
    for (f, m) in ours.iter().zip(mda) {
        assert_eq!(f.step, m["step"].as_i64());
        assert_eq!(
            f.time.map(|t| t as f32),
            m["time"].as_f64().map(|t| t as f32)
        );
        let dims: Vec<f64> = m["dimensions"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let cell = f.cell.unwrap();
        for k in 0..3 {
            assert!((cell.lengths()[k] - dims[k]).abs() < 1e-5);
            assert!((cell.angles()[k] - dims[k + 3]).abs() < 1e-4);
        }
        // MDAnalysis multiplies nm by 10 in f32, as our reader does: the same bits.
        assert_eq!(f.positions.as_flattened(), floats(&m["positions"]));
        match m["velocities"].is_null() {
            true => assert!(f.velocities.is_empty()),
            false => assert_eq!(f.velocities.as_flattened(), floats(&m["velocities"])),
        }
        // Forces: MDAnalysis multiplies by 0.1 in f32 where we divide by 10: one ulp apart at
        // most.
        let mf = floats(&m["forces"]);
        let [fx, fy, fz] = ["fx", "fy", "fz"].map(|n| f.property(n).unwrap());
        for (i, w) in mf.chunks(3).enumerate() {
            for (d, col) in [fx, fy, fz].iter().enumerate() {
                let (a, b) = (col[i], w[d]);
                assert!(
                    a.to_bits().abs_diff(b.to_bits()) <= 1,
                    "atom {i}: {a} vs {b}"
                );
            }
        }
    }
}

/// The counts `gmx check` printed for written.trr (gen_trr_write.sh): GROMACS finds every
/// block where we wrote it.
#[test]
fn gmx_check_counts_our_blocks() {
    let text = std::fs::read_to_string(data("gmx_check.txt")).unwrap();
    let count = |item: &str| -> usize {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(item))
            .unwrap_or_else(|| panic!("no {item} line in gmx_check.txt"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let ours = frames(&data("written.trr"));
    let forces = ours.iter().filter(|f| f.property("fx").is_some()).count();
    let velocities = ours.iter().filter(|f| !f.velocities.is_empty()).count();
    assert_eq!(count("Coords"), ours.len());
    assert_eq!(count("Velocities"), velocities);
    assert_eq!(count("Forces"), forces);
    assert_eq!(count("Box"), ours.len());
    assert_eq!((velocities, forces), (2, 3));
}

/// GROMACS itself on a file written now, where `gmx` is installed (Debian: apt install gromacs).
#[test]
fn gmx_reads_a_file_written_now() {
    if std::process::Command::new("gmx")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("SKIPPED: no gmx on PATH (apt install gromacs); the committed files cover it");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut frames = frames(&data("md.trr"));
    // A frame without velocities or forces between two with them.
    frames[1].velocities.clear();
    frames[1].properties.clear();
    let path = dir.path().join("now.trr");
    std::fs::write(&path, written(&frames)).unwrap();
    let o = std::process::Command::new("gmx")
        .args(["-quiet", "check", "-f"])
        .arg(&path)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}");
    let line = |item: &str| {
        text.lines()
            .find(|l| l.split_whitespace().next() == Some(item))
            .map(|l| l.split_whitespace().nth(1).unwrap().to_string())
    };
    assert_eq!(line("Coords").as_deref(), Some("3"), "{text}");
    assert_eq!(line("Velocities").as_deref(), Some("2"), "{text}");
    assert_eq!(line("Forces").as_deref(), Some("2"), "{text}");
    // gmx dump prints the first position of the first frame in nm.
    let o = std::process::Command::new("gmx")
        .args(["-quiet", "dump", "-f"])
        .arg(&path)
        .output()
        .unwrap();
    let dump = String::from_utf8_lossy(&o.stdout);
    let x0 = dump
        .lines()
        .find(|l| l.trim_start().starts_with("x[    0]="))
        .unwrap_or_else(|| panic!("no x[    0] in gmx dump:\n{dump}"));
    let nums: Vec<f64> = x0
        .split(['{', '}', ','])
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    assert_eq!(nums.len(), 3, "{x0}");
    for (got, p) in nums.iter().zip(frames[0].positions[0]) {
        let want = f64::from(p) / 10.0;
        assert!((got - want).abs() < 1e-5, "{x0} against {want}");
    }
}

#[test]
fn frames_the_format_cannot_hold_are_refused_naming_the_frame() {
    let frames = frames(&data("md.trr"));
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Trr, "out.trr").unwrap();
    w.write_frame(&frames[0]).unwrap();
    let mut fewer = frames[1].clone();
    fewer.retain_atoms(&(0..fewer.n_atoms()).map(|i| i % 3 == 0).collect::<Vec<_>>());
    let e = w.write_frame(&fewer).unwrap_err().to_string();
    assert!(e.contains("out.trr") && e.contains("frame 1"), "{e}");
    assert!(
        e.contains("213 atoms, where the first frame had 639"),
        "{e}"
    );
    let mut late = frames[1].clone();
    late.step = Some(3_000_000_000);
    let e = w.write_frame(&late).unwrap_err().to_string();
    assert!(e.contains("step 3000000000") && e.contains("32-bit"), "{e}");
    // Nothing of the refused frames was written: the next frame is frame 1.
    w.write_frame(&frames[1]).unwrap();
    let bytes = w.finish().unwrap().into_inner();
    assert_eq!(records(&bytes).len(), 2);
}

/// The blocks of every frame of `trr_mixed/argon.trr` as `gmx dump` lists them
/// (gmx_dump_blocks.txt, written by gen.sh there): atoms, and whether x, v and f are present.
fn gmx_dump_blocks() -> Vec<(usize, [bool; 3])> {
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/trr_mixed/gmx_dump_blocks.txt"),
    )
    .unwrap();
    let mut out: Vec<(usize, [bool; 3])> = Vec::new();
    for line in text.lines() {
        let t = line.trim();
        if let Some(n) = t.strip_prefix("natoms=") {
            let n = n.split_whitespace().next().unwrap().parse().unwrap();
            out.push((n, [false; 3]));
        } else if let Some(k) = ["x (", "v (", "f ("].iter().position(|p| t.starts_with(p)) {
            out.last_mut().unwrap().1[k] = true;
        }
    }
    out
}

/// mdrun's frames of only velocities or only forces (nstxout 10, nstvout 5, nstfout 2): a
/// frame without positions has no atoms, and `without_positions` says what it held, as
/// `gmx dump` lists it, so that a converter can name what it cannot write.
#[test]
fn frames_without_positions_say_what_they_held() {
    let blocks = gmx_dump_blocks();
    assert_eq!(blocks.len(), 13);
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/trr_mixed/argon.trr");
    let mut t = Trajectory::open(&path).unwrap();
    let mut f = Frame::new();
    for (k, &(n, [x, v, force])) in blocks.iter().enumerate() {
        assert!(t.read_next(&mut f).unwrap(), "frame {k}");
        if x {
            assert_eq!(f.n_atoms(), n, "frame {k}");
            assert_eq!(f.velocities.len(), if v { n } else { 0 }, "frame {k}");
            assert_eq!(f.property("fx").is_some(), force, "frame {k}");
            assert_eq!(t.without_positions(), None, "frame {k}");
        } else {
            assert_eq!(f.n_atoms(), 0, "frame {k}");
            let want = texmap_md_io::WithoutPositions {
                atoms: n,
                velocities: v,
                forces: force,
            };
            assert_eq!(t.without_positions(), Some(want), "frame {k}");
        }
    }
    assert!(!t.read_next(&mut f).unwrap());
}
