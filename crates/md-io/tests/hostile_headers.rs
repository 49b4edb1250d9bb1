//! Regression tests made from the mutants of real files that broke a reader: a header that
//! claims 2^31 atoms, a last frame cut short, a damaged PDB atom line, finite but absurd values.
//! Every mutant starts from a file written by another program (MDAnalysis, gsd.hoomd, see
//! tests/data/README-binary.md and README.md) and is changed here byte by byte.
//!
//! Memory is measured with a counting global allocator (tests/support/alloc.rs): what a reader
//! allocates for a file must be bounded by what the file can hold, whatever its header says.

use crate::support;

use std::io::Cursor;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use support::alloc::measure;
use support::gsd_index::{chunk, chunks};
use texmap_md_io::{Error, Format, Frame, ReadOptions, Trajectory};

fn data(name: &str) -> Vec<u8> {
    std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

fn lenient() -> ReadOptions {
    ReadOptions::new().allow_truncated(true)
}

/// Opens, counts and streams every frame; the first error, else the frame count.
fn read_all(bytes: &[u8], format: Format, name: &str, opts: ReadOptions) -> Result<usize, Error> {
    let mut t = Trajectory::from_reader_with(Cursor::new(bytes.to_vec()), format, name, opts)?;
    let n = t.n_frames()?;
    let mut f = Frame::new();
    let mut k = 0;
    while t.read_next(&mut f)? {
        k += 1;
    }
    assert_eq!(k, n, "{name}: streamed frames and n_frames disagree");
    Ok(n)
}

/// Frame starts of an XTC (magic 1995, compressed frames), walked from the byte counts.
fn xtc_frames(b: &[u8]) -> Vec<usize> {
    let be = |at: usize| u32::from_be_bytes(b[at..at + 4].try_into().unwrap()) as usize;
    let mut out = Vec::new();
    let mut off = 0;
    while off < b.len() {
        assert_eq!(be(off), 1995);
        assert!(be(off + 4) > 9, "compressed frames only");
        out.push(off);
        off += 92 + be(off + 88).div_ceil(4) * 4;
    }
    assert_eq!(off, b.len());
    out
}

fn parse_error(e: &Error) -> (&'static str, &str) {
    match e {
        Error::Parse {
            expected, found, ..
        } => (expected, found),
        other => panic!("expected a parse error, got {other}"),
    }
}

#[test]
fn xtc_header_claiming_2_pow_31_atoms_is_refused_without_allocating_it() {
    let good = data("xtc_mda.xtc");
    let starts = xtc_frames(&good);
    let cap = 64 * good.len() + (1 << 20);
    // i32::MAX (2^31 - 1), 2^31 (negative as i32), 2^29; in every frame, or in frame 0 only.
    for claim in [i32::MAX as u32, 1 << 31, 1 << 29] {
        for frames in [&starts[..], &starts[..1]] {
            let mut b = good.clone();
            for &s in frames {
                b[s + 4..s + 8].copy_from_slice(&claim.to_be_bytes());
                b[s + 52..s + 56].copy_from_slice(&claim.to_be_bytes());
            }
            let t0 = Instant::now();
            let (r, peak) = measure(|| read_all(&b, Format::Xtc, "huge.xtc", ReadOptions::new()));
            let took = t0.elapsed();
            let e = r.unwrap_err();
            assert!(
                peak <= cap,
                "claim {claim}: {peak} bytes at peak for a {}-byte file (cap {cap})",
                good.len()
            );
            // A hang guard, not a speed figure: the refusal reads one header.
            assert!(took < Duration::from_secs(5), "claim {claim}: {took:?}");
            // 2^31 is negative as an i32: refused by the sign check at the second count.
            let byte = if claim == 1 << 31 { 52 } else { 4 };
            let at = e.location().unwrap();
            assert_eq!((at.frame, at.byte), (Some(0), Some(byte)), "{e}");
            let head = format!("huge.xtc: frame 0, byte {byte}: expected ");
            assert!(e.to_string().starts_with(&head), "{e}");
        }
    }
}

#[test]
fn xtc_precision_of_1e_minus_30_is_a_located_error() {
    let good = data("xtc_mda.xtc");
    let starts = xtc_frames(&good);
    let mut b = good.clone();
    // Frame 2's precision (the f32 right after the 56-byte header).
    let at = starts[2] + 56;
    b[at..at + 4].copy_from_slice(&1e-30f32.to_be_bytes());
    let mut t = Trajectory::from_reader(Cursor::new(b), Format::Xtc, "prec.xtc").unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap() && t.read_next(&mut f).unwrap());
    let e = t.read_next(&mut f).unwrap_err();
    let loc = e.location().unwrap();
    assert_eq!((loc.frame, loc.byte), (Some(2), Some(at as u64)), "{e}");
    assert!(parse_error(&e).0.contains("precision"), "{e}");
}

/// A frame cut short is never dropped silently: strict, the count is the error; lenient, the
/// complete frames are kept and the same error is a warning.
fn cut_frame_is_reported(name: &str, format: Format, cut: usize, complete: usize) {
    let good = data(name);
    let b = &good[..cut];
    let e = read_all(b, format, name, ReadOptions::new()).unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    let at = e.location().unwrap();
    assert_eq!(
        (at.frame, at.byte),
        (Some(complete), Some(cut as u64)),
        "{e}"
    );
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!(
            "{name}: frame {complete}, byte {cut}: file ends inside"
        )),
        "{msg}"
    );
    assert!(msg.contains("more bytes"), "{msg}");

    let opened = Trajectory::from_reader_with(Cursor::new(b.to_vec()), format, name, lenient());
    let mut t = match opened {
        Ok(t) => t,
        Err(e) => {
            // XTC and TRR index at open time: without one complete frame there is no file.
            assert_eq!(complete, 0, "{e}");
            assert_eq!(e.to_string(), msg);
            return;
        }
    };
    assert_eq!(t.n_frames().unwrap(), complete);
    let mut f = Frame::new();
    let mut k = 0;
    while t.read_next(&mut f).unwrap() {
        k += 1;
    }
    assert_eq!(k, complete);
    assert_eq!(t.warnings().len(), 1);
    assert_eq!(t.warnings()[0].to_string(), msg);
}

#[test]
fn truncated_last_frame_is_an_error_or_a_warning() {
    // DCD (MDAnalysis, 12 atoms, cell records): 4 frames of 4 + 48 + 4 + 3 (4 + 48 + 4) bytes
    // after a 276-byte header: cut in the middle of frame 2, and inside frame 0.
    let dcd = data("dcd_mda.dcd");
    let frame = 56 + 3 * 56;
    let header = dcd.len() - 4 * frame;
    cut_frame_is_reported("dcd_mda.dcd", Format::Dcd, header + 2 * frame + 100, 2);
    cut_frame_is_reported("dcd_mda.dcd", Format::Dcd, header + 30, 0);
    // XTC: inside frame 3 (the last), and inside frame 0's compressed bytes.
    let xtc = data("xtc_mda.xtc");
    let starts = xtc_frames(&xtc);
    cut_frame_is_reported("xtc_mda.xtc", Format::Xtc, starts[3] + 100, 3);
    cut_frame_is_reported("xtc_mda.xtc", Format::Xtc, 100, 0);
    // TRR: one byte short of the end.
    let trr = data("trr_mda.trr");
    cut_frame_is_reported("trr_mda.trr", Format::Trr, trr.len() - 1, 3);
    // GSD (gsd.hoomd, 5 frames): inside frame 3's positions, and inside frame 0's first chunk.
    let gsd = data("gsd/hoomd_tri.gsd");
    let first = chunks(&gsd).iter().map(|c| c.location).min().unwrap();
    let pos3 = chunk(&gsd, 3, "particles/position").location;
    cut_frame_is_reported("gsd/hoomd_tri.gsd", Format::Gsd, pos3 + 100, 3);
    cut_frame_is_reported("gsd/hoomd_tri.gsd", Format::Gsd, first + 2, 0);
}

#[test]
fn gsd_counts_claiming_more_than_the_file_holds_are_refused_without_allocating() {
    let good = data("gsd/hoomd_tri.gsd");
    let cap = 64 * good.len() + (1 << 20);
    // (what is changed, byte, value, frame of the error (None: at open), byte of the error)
    let n_at = chunk(&good, 0, "particles/N").location;
    let bonds_at = chunk(&good, 0, "bonds/N").location;
    let position = chunk(&good, 0, "particles/position").entry;
    let cases: [(&str, usize, u64, Option<usize>, usize); 6] = [
        ("index entries", 16, 1 << 40, None, 16),
        ("index entries", 16, u64::MAX, None, 16),
        ("namelist segments", 32, 1 << 50, None, 32),
        ("particles/N", n_at, u32::MAX as u64, Some(0), n_at),
        ("bonds/N", bonds_at, u32::MAX as u64, Some(0), bonds_at),
        // Frame 0's positions as 2^40 rows: data past the end before later frames' data.
        ("position rows", position + 8, 1 << 40, None, position + 16),
    ];
    for (what, at, value, frame, byte) in cases {
        let mut b = good.clone();
        if what.ends_with("/N") {
            b[at..at + 4].copy_from_slice(&(value as u32).to_le_bytes());
        } else {
            b[at..at + 8].copy_from_slice(&value.to_le_bytes());
        }
        let t0 = Instant::now();
        let (r, peak) = measure(|| read_all(&b, Format::Gsd, "huge.gsd", ReadOptions::new()));
        let e = r.unwrap_err();
        assert!(peak <= cap, "{what}: {peak} bytes at peak (cap {cap})");
        assert!(t0.elapsed() < Duration::from_secs(5), "{what}");
        let loc = e.location().unwrap();
        assert_eq!(
            (loc.frame, loc.byte),
            (frame, Some(byte as u64)),
            "{what}: {e}"
        );
        assert!(matches!(e, Error::Parse { .. }), "{what}: {e}");
    }
    // Frame 4 (180 particles, not frame 0's 200) without its position chunk (renamed to
    // bonds/types, which is not read) takes the default (0, 0, 0) per particle: its count of
    // 2^31 - 1 must be refused before anything is sized from it.
    let mut b = good.clone();
    let pos4 = chunk(&good, 4, "particles/position").entry;
    let other = chunk(&good, 0, "bonds/types").entry;
    b.copy_within(other + 28..other + 30, pos4 + 28);
    let mut t = Trajectory::from_reader(Cursor::new(b.clone()), Format::Gsd, "d.gsd").unwrap();
    let mut f = Frame::new();
    t.read_frame(4, &mut f).unwrap();
    assert!(f.n_atoms() == 180 && f.positions.iter().all(|p| *p == [0.0; 3]));
    let n4 = chunk(&good, 4, "particles/N").location;
    b[n4..n4 + 4].copy_from_slice(&(i32::MAX as u32).to_le_bytes());
    let (r, peak) = measure(|| read_all(&b, Format::Gsd, "d.gsd", ReadOptions::new()));
    let e = r.unwrap_err();
    assert!(peak <= cap, "{peak} bytes at peak (cap {cap})");
    let loc = e.location().unwrap();
    assert_eq!((loc.frame, loc.byte), (Some(4), Some(n4 as u64)), "{e}");
    assert!(
        e.to_string().contains("a particle count whose positions"),
        "{e}"
    );
}

#[test]
fn dcd_cut_at_a_frame_boundary_is_short_of_what_the_header_declares() {
    let dcd = data("dcd_mda.dcd");
    let frame = 56 + 3 * 56;
    let cut = dcd.len() - frame;
    let e = read_all(&dcd[..cut], Format::Dcd, "d.dcd", ReadOptions::new()).unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().contains("4 frames declared"), "{e}");
    assert_eq!(
        read_all(&dcd[..cut], Format::Dcd, "d.dcd", lenient()).unwrap(),
        3
    );
}

/// Byte offset of line `k` (0-based) of a text.
fn line_start(text: &[u8], k: usize) -> usize {
    let mut n = 0;
    for (i, b) in text.iter().enumerate() {
        if n == k {
            return i;
        }
        if *b == b'\n' {
            n += 1;
        }
    }
    panic!("no line {k}");
}

#[test]
fn pdb_damaged_atom_keyword_is_a_located_error_not_a_dropped_atom() {
    let good = data("mda_multi.pdb");
    // Line 5 (1-based) is model 1's second ATOM record: "ATOM" -> "AT0M".
    let at = line_start(&good, 4);
    assert_eq!(&good[at..at + 4], b"ATOM");
    let mut b = good.clone();
    b[at + 2] = b'0';
    let e = read_all(&b, Format::Pdb, "m.pdb", ReadOptions::new()).unwrap_err();
    let loc = e.location().unwrap();
    assert_eq!(
        (loc.frame, loc.line, loc.byte),
        (Some(0), Some(5), Some(at as u64)),
        "{e}"
    );
    assert_eq!(parse_error(&e).0, "ATOM or HETATM in columns 1-6");
    // Lenient or not: a damaged line is damage, not a cut end.
    assert!(read_all(&b, Format::Pdb, "m.pdb", lenient()).is_err());
}

#[test]
fn pdb_model_with_another_atom_count_is_an_error_or_a_warning() {
    let good = data("mda_multi.pdb");
    // Remove model 2's third ATOM line (line 20, 1-based): model 2 has 10 atoms, model 1 11.
    let (a, z) = (line_start(&good, 19), line_start(&good, 20));
    assert!(good[a..].starts_with(b"ATOM"));
    let b = [&good[..a], &good[z..]].concat();
    let e = read_all(&b, Format::Pdb, "m.pdb", ReadOptions::new()).unwrap_err();
    let loc = e.location().unwrap();
    assert_eq!(loc.frame, Some(1), "{e}");
    assert!(e.to_string().contains("10 atoms, model 1 has 11"), "{e}");

    let mut t =
        Trajectory::from_reader_with(Cursor::new(b), Format::Pdb, "m.pdb", lenient()).unwrap();
    let mut f = Frame::new();
    let mut counts = Vec::new();
    while t.read_next(&mut f).unwrap() {
        counts.push(f.n_atoms());
    }
    assert_eq!(counts, [11, 10, 11]);
    assert_eq!(t.warnings().len(), 1, "{:?}", t.warnings());
    assert_eq!(t.warnings()[0].location().unwrap().frame, Some(1));
}

#[test]
fn pdb_cut_atom_line_is_a_located_error() {
    let good = data("mda_multi.pdb");
    // Model 1's fourth ATOM line cut after column 40 (inside y), the rest of the file kept.
    let a = line_start(&good, 6);
    let z = line_start(&good, 7);
    let b = [&good[..a + 40], b"\n", &good[z..]].concat();
    let e = read_all(&b, Format::Pdb, "m.pdb", ReadOptions::new()).unwrap_err();
    let loc = e.location().unwrap();
    assert_eq!((loc.frame, loc.line), (Some(0), Some(7)), "{e}");
}

#[test]
fn finite_but_absurd_values_are_located_errors() {
    // DCD: atom 5's x of frame 1 set to 1e38.
    let dcd = data("dcd_mda.dcd");
    let frame = 56 + 3 * 56;
    let header = dcd.len() - 4 * frame;
    let mut b = dcd.clone();
    let x5 = header + frame + 56 + 4 + 4 * 5;
    b[x5..x5 + 4].copy_from_slice(&1e38f32.to_le_bytes());
    let e = read_all(&b, Format::Dcd, "x.dcd", ReadOptions::new()).unwrap_err();
    let loc = e.location().unwrap();
    assert_eq!((loc.frame, loc.byte), (Some(1), Some(x5 as u64)), "{e}");
    assert!(parse_error(&e).1.starts_with("atom 5:"), "{e}");

    // DCD: frame 2's cell length A set to 1e300 (finite f64).
    let mut b = dcd.clone();
    let a = header + 2 * frame + 4;
    b[a..a + 8].copy_from_slice(&1e300f64.to_le_bytes());
    let e = read_all(&b, Format::Dcd, "c.dcd", ReadOptions::new()).unwrap_err();
    assert_eq!(e.location().unwrap().frame, Some(2), "{e}");

    // XYZ (ASE): an exponent that makes a finite 1e38.
    let xyz = String::from_utf8(data("ase_plain.xyz")).unwrap();
    let line = xyz.lines().nth(4).unwrap();
    let x = line.split_whitespace().nth(1).unwrap();
    let bad = xyz.replacen(line, &line.replacen(x, "1e38", 1), 1);
    let e = read_all(bad.as_bytes(), Format::Xyz, "a.xyz", ReadOptions::new()).unwrap_err();
    let loc = e.location().unwrap();
    assert_eq!((loc.frame, loc.line), (Some(0), Some(1)), "{e}");
    assert!(parse_error(&e).1.starts_with("atom 2:"), "{e}");

    // PDB: a CRYST1 of 1e300 Å.
    let pdb = String::from_utf8(data("mda_multi.pdb")).unwrap();
    let bad = pdb.replacen("CRYST1   30.000", "CRYST1    1e300", 1);
    let e = read_all(bad.as_bytes(), Format::Pdb, "c.pdb", ReadOptions::new()).unwrap_err();
    let loc = e.location().unwrap();
    assert_eq!((loc.frame, loc.line), (Some(0), Some(2)), "{e}");
}
