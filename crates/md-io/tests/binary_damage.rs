//! Damaged DCD / XTC / TRR / GSD / LAMMPS binary dump files, built from good ones written by
//! MDAnalysis, gsd.hoomd, LAMMPS and our own writers: cut at every byte (so at every record
//! boundary and inside every record) and with bits flipped at every byte. Nothing may panic;
//! every frame before the damage must read back unchanged; the error for the damaged frame must
//! name the file, the frame and the byte, and a cut frame is never dropped silently: `n_frames`
//! reports it, unless `allow_truncated` was asked for, which keeps the complete frames and gives
//! the same error as a warning.

use std::io::Cursor;
use std::path::PathBuf;

use texmap_md_io::{Error, Format, Frame, ReadOptions, Trajectory};

fn data(name: &str) -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    std::fs::read(p).unwrap()
}

fn frames_of(bytes: &[u8], format: Format) -> Vec<Frame> {
    let mut t = Trajectory::from_reader(Cursor::new(bytes.to_vec()), format, "good").unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

/// Our writers' output: a second source of good files (DCD with cells, XTC compressed).
fn ours(format: Format) -> Vec<u8> {
    let good = frames_of(&data("xtc_mda.xtc"), Format::Xtc);
    let mut w = texmap_md_io::Writer::new(Cursor::new(Vec::new()), format, "ours").unwrap();
    for f in &good {
        w.write_frame(f).unwrap();
    }
    w.finish().unwrap().into_inner()
}

fn cases() -> Vec<(&'static str, Format, Vec<u8>)> {
    vec![
        ("dcd_mda.dcd", Format::Dcd, data("dcd_mda.dcd")),
        ("xtc_mda.xtc", Format::Xtc, data("xtc_mda.xtc")),
        ("trr_mda.trr", Format::Trr, data("trr_mda.trr")),
        ("ours.dcd", Format::Dcd, ours(Format::Dcd)),
        ("ours.xtc", Format::Xtc, ours(Format::Xtc)),
        ("hoomd_2d.gsd", Format::Gsd, data("gsd/hoomd_2d.gsd")),
        ("hoomd_one.gsd", Format::Gsd, data("gsd/hoomd_one.gsd")),
        (
            "tri_np2.bin",
            Format::LammpsBin,
            data("lammps_bin/tri_np2.bin"),
        ),
        (
            "atom_np1.bin",
            Format::LammpsBin,
            data("lammps_bin/atom_np1.bin"),
        ),
    ]
}

#[test]
fn cut_at_every_byte_keeps_the_frames_before_the_cut() {
    for (name, format, bytes) in cases() {
        let good = frames_of(&bytes, format);
        let mut last_complete = 0;
        for cut in 0..=bytes.len() {
            let t = Trajectory::from_reader(Cursor::new(bytes[..cut].to_vec()), format, name);
            let mut t = match t {
                Ok(t) => t,
                Err(e) => {
                    // Only a damaged header may refuse the whole file.
                    assert_eq!(last_complete, 0, "{name} cut {cut}: {e}");
                    assert!(e.to_string().starts_with(name), "{e}");
                    continue;
                }
            };
            // Strict: a cut inside a frame (or short of the frames DCD's header declares) is
            // an error for that frame, naming the byte where the data ends.
            let strict = t.n_frames();
            let lenient = ReadOptions::new().allow_truncated(true);
            let mut t = Trajectory::from_reader_with(
                Cursor::new(bytes[..cut].to_vec()),
                format,
                name,
                lenient,
            )
            .unwrap();
            let complete = t.n_frames().unwrap();
            match strict {
                Ok(n) => {
                    assert_eq!(n, complete, "{name} cut {cut}");
                    assert!(t.warnings().is_empty(), "{name} cut {cut}");
                }
                Err(e) => {
                    assert!(
                        matches!(e, Error::Truncated { .. }),
                        "{name} cut {cut}: {e}"
                    );
                    let at = e.location().unwrap();
                    assert_eq!(
                        (at.frame, at.byte),
                        (Some(complete), Some(cut as u64)),
                        "{e}"
                    );
                    // Lenient: the same error, as a warning.
                    assert_eq!(t.warnings().len(), 1, "{name} cut {cut}");
                    assert_eq!(t.warnings()[0].to_string(), e.to_string());
                }
            }
            assert!(
                complete >= last_complete,
                "{name} cut {cut}: frames went down"
            );
            last_complete = complete;
            let mut f = Frame::new();
            for (k, want) in good.iter().enumerate().take(complete) {
                t.read_frame(k, &mut f).unwrap();
                assert_eq!(&f, want, "{name} cut {cut} frame {k}");
            }
            assert!(
                !t.read_next(&mut f).unwrap(),
                "{name} cut {cut}: past the end"
            );
            let mut t =
                Trajectory::from_reader(Cursor::new(bytes[..cut].to_vec()), format, name).unwrap();
            for k in 0..complete {
                t.read_frame(k, &mut f).unwrap();
            }
            match t.read_next(&mut f) {
                Ok(more) => assert!(!more, "{name} cut {cut}: a frame past the complete ones"),
                Err(e) => {
                    let at = e
                        .location()
                        .unwrap_or_else(|| panic!("{name} cut {cut}: {e}"));
                    assert!(
                        matches!(e, Error::Truncated { .. }),
                        "{name} cut {cut}: {e}"
                    );
                    assert_eq!(&*at.file, name);
                    assert_eq!(at.frame, Some(complete), "{e}");
                    assert_eq!(at.byte, Some(cut as u64), "{e}");
                    assert!(
                        f.positions.is_empty(),
                        "a failed read leaves the frame empty"
                    );
                }
            }
            if cut == bytes.len() {
                assert_eq!(complete, good.len(), "{name}: the whole file");
            }
        }
    }
}

#[test]
fn flipped_bytes_never_panic_and_errors_name_the_place() {
    for (name, format, bytes) in cases() {
        for at in 0..bytes.len() {
            for bit in [0x01u8, 0x10, 0x80] {
                let mut b = bytes.clone();
                b[at] ^= bit;
                let Ok(mut t) = Trajectory::from_reader(Cursor::new(b), format, name) else {
                    continue;
                };
                // A damaged frame after the good ones is the count's error, naming that frame.
                let n = match t.n_frames() {
                    Ok(n) => n,
                    Err(e) => {
                        let loc = e.location().unwrap_or_else(|| panic!("{e}"));
                        assert!(loc.byte.is_some(), "{e}");
                        loc.frame.unwrap_or_else(|| panic!("{name} byte {at}: {e}"))
                    }
                };
                let mut f = Frame::new();
                for k in 0..=n {
                    match t.read_frame(k, &mut f) {
                        Ok(()) => {
                            assert!(f.check().is_ok(), "{name} byte {at}: {:?}", f.check());
                        }
                        Err(Error::FrameOutOfRange { .. }) => assert_eq!(k, n),
                        Err(e) => {
                            let loc = e.location().unwrap_or_else(|| panic!("{e}"));
                            assert_eq!(loc.frame, Some(k), "{name} byte {at}: {e}");
                            assert!(loc.byte.is_some(), "{e}");
                        }
                    }
                }
            }
        }
    }
}
