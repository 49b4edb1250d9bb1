//! gzip (and bzip2) input: `.gz` copies of fixtures made by GNU gzip (tests/data/gzip.sh) read through
//! `Trajectory::open*` and `Topology::open*` exactly as the plain files, and damaged copies
//! (cut, a flipped byte, a misnamed plain file) are errors naming the file and "gzip".
//!
//! Plain and `.gz` are compared with `==`: the same decompressed bytes go through the same parser,
//! so every coordinate must be equal bit for bit; a tolerance would hide a lost or shifted byte.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use texmap_md_io::{Error, Format, Frame, ReadOptions, Topology, TopologyFormat, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The name errors give a file opened by path.
fn name_of(p: &Path) -> String {
    p.display().to_string()
}

/// Every frame of `traj`, streamed, then the frame count.
fn frames(traj: &mut Trajectory) -> (Vec<Frame>, usize) {
    let mut all = Vec::new();
    let mut f = Frame::new();
    while traj.read_next(&mut f).unwrap() {
        all.push(f.clone());
    }
    let n = traj.n_frames().unwrap();
    (all, n)
}

/// `traj`'s warnings as they print.
fn warnings(traj: &Trajectory) -> Vec<String> {
    traj.warnings().iter().map(|w| w.to_string()).collect()
}

/// The trajectory fixtures: (gzip copy, format, frames in the plain file).
const TRAJECTORIES: [(&str, Format, usize); 3] = [
    ("topo_mda.pdb.gz", Format::Pdb, 1),
    ("3jqh.cif.gz", Format::Mmcif, 1),
    ("lmp_tri.lammpstrj.gz", Format::LammpsDump, 3),
];

#[test]
fn every_frame_of_a_gz_equals_the_plain_files() {
    for (gz, format, n_frames) in TRAJECTORIES {
        let gz = path(gz);
        let plain = gz.with_extension("");
        let name = name_of(&gz);
        // The plain file read under the .gz file's name: errors and warnings must then agree too.
        let mut want = Trajectory::from_reader(File::open(&plain).unwrap(), format, &name).unwrap();
        let (want_frames, want_n) = frames(&mut want);
        assert_eq!(want_n, n_frames, "{name}");
        assert_eq!(want_frames.len(), n_frames, "{name}");

        let mut opened = [
            Trajectory::open(&gz).unwrap(),
            Trajectory::open_with(&gz, ReadOptions::new().allow_truncated(true)).unwrap(),
            Trajectory::open_as(&gz, format).unwrap(),
            Trajectory::open_as_with(&gz, format, ReadOptions::new()).unwrap(),
        ];
        for traj in &mut opened {
            assert_eq!(traj.format(), format, "{name}");
            assert_eq!(traj.name(), name);
            assert_eq!(traj.n_atoms().unwrap(), want_frames[0].n_atoms(), "{name}");
            let (got_frames, got_n) = frames(traj);
            assert_eq!(got_n, want_n, "{name}");
            assert_eq!(got_frames.len(), want_frames.len(), "{name}");
            for (i, (got, want)) in got_frames.iter().zip(&want_frames).enumerate() {
                assert!(
                    got == want,
                    "{name}: frame {i} differs from the plain file's"
                );
            }
            // Random access, last frame first.
            let mut f = Frame::new();
            for i in (0..want_n).rev() {
                traj.read_frame(i, &mut f).unwrap();
                assert!(f == want_frames[i], "{name}: read_frame({i})");
            }
            assert_eq!(warnings(traj), warnings(&want), "{name}");
        }
        // What each fixture is meant to exercise is there.
        assert!(want_frames.iter().all(|f| f.n_atoms() > 0), "{name}");
        if format == Format::LammpsDump {
            assert!(want_frames.iter().all(|f| f.cell.is_some()), "{name}");
        }
        if format == Format::Mmcif {
            assert!(!want.warnings().is_empty(), "3JQH has alternate locations");
        }
    }
}

#[test]
fn the_two_member_fixture_has_two_members() {
    // A gzip member header: magic 1f 8b and method 8 (deflate), RFC 1952 §2.3.1.
    let bytes = std::fs::read(path("lmp_tri.lammpstrj.gz")).unwrap();
    let headers = bytes
        .windows(3)
        .enumerate()
        .filter(|(_, w)| *w == [0x1f, 0x8b, 8])
        .map(|(i, _)| i)
        .collect::<Vec<_>>();
    assert!(headers.len() >= 2 && headers[0] == 0, "{headers:?}");
}

#[test]
fn every_topology_of_a_gz_equals_the_plain_files() {
    for (gz, format) in [
        ("topo_mda.pdb.gz", TopologyFormat::Pdb),
        ("psf_parmed.psf.gz", TopologyFormat::Psf),
        ("3jqh.cif.gz", TopologyFormat::Mmcif),
    ] {
        let gz = path(gz);
        let plain = gz.with_extension("");
        let name = name_of(&gz);
        assert_eq!(TopologyFormat::from_path(&gz), Some(format));
        let want = Topology::from_reader(File::open(&plain).unwrap(), format, &name).unwrap();
        assert!(want.n_atoms() > 0, "{name}");
        if format != TopologyFormat::Mmcif {
            assert!(!want.bonds.is_empty(), "{name}: CONECT / !NBOND bonds");
        }
        let got = Topology::open(&gz).unwrap();
        assert!(
            got == want,
            "{name}: differs from the plain file's topology"
        );
        assert!(Topology::open_as(&gz, format).unwrap() == want, "{name}");
        assert_eq!(got.name(), name);
    }
}

/// A scratch directory, removed when dropped.
fn scratch() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// Writes `bytes` to `dir/name` and gives the path.
fn put(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn the_magic_decides_and_a_bare_gz_name_is_sniffed_after_decompression() {
    let dir = scratch();
    let gz = std::fs::read(path("3jqh.cif.gz")).unwrap();
    let mut want = Trajectory::open(path("3jqh.cif")).unwrap();
    let (want_frames, _) = frames(&mut want);
    // No format in the name: the decompressed bytes' `data_` line tells mmCIF.
    // gzip bytes under a plain name: read decompressed all the same.
    for name in ["entry.gz", "entry.cif", "entry"] {
        let p = put(&dir, name, &gz);
        let mut traj = Trajectory::open(&p).unwrap();
        assert_eq!(traj.format(), Format::Mmcif, "{name}");
        assert!(frames(&mut traj).0 == want_frames, "{name}");
    }
    // A bare .gz whose content no format claims is the usual unknown-format error.
    let p = put(&dir, "noise.gz", &gzip(b"hello\nworld\n"));
    let e = Trajectory::open(&p).map(|_| ()).unwrap_err();
    assert!(matches!(e, Error::UnknownFormat { .. }), "{e}");
}

/// gzip of `bytes` by flate2 (for synthetic content; the fixtures are GNU gzip's).
fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// Checks that `e` names `p`, says "gzip" and gives a compressed byte offset at most `len`.
fn assert_gzip_error(e: &Error, p: &Path, len: usize) {
    let msg = e.to_string();
    assert!(msg.starts_with(&name_of(p)), "{msg}");
    assert!(msg.contains("gzip"), "{msg}");
    let byte = e.location().and_then(|l| l.byte);
    assert!(byte.is_some_and(|b| b <= len as u64), "{msg}");
}

#[test]
fn a_cut_gz_is_an_error_not_a_shorter_trajectory() {
    let dir = scratch();
    for fixture in [
        "lmp_tri.lammpstrj.gz",
        "topo_mda.pdb.gz",
        "psf_parmed.psf.gz",
    ] {
        let gz = std::fs::read(path(fixture)).unwrap();
        // In the middle of the deflate data, and just before the 8-byte trailer (CRC-32, size):
        // all the data inflates, only the check is missing.
        for cut in [gz.len() / 2, gz.len() - 8, gz.len() - 1] {
            let p = put(&dir, fixture, &gz[..cut]);
            let e = match fixture {
                "psf_parmed.psf.gz" => Topology::open(&p).unwrap_err(),
                _ => Trajectory::open(&p).map(|_| ()).unwrap_err(),
            };
            assert_gzip_error(&e, &p, cut);
            assert!(e.to_string().contains("found 'end of file'"), "{e}");
        }
    }
}

/// Under `allow_truncated`, a gzip stream that ends early is read up to the cut, with a
/// warning naming the compressed offset, and the frame the cut falls in is dropped as in a
/// cut plain file: at every cut, the frames read are the plain file's first frames, bit for
/// bit, and as many as the inflated prefix holds whole. Topologies stay strict.
#[test]
fn allow_truncated_keeps_the_complete_frames_of_a_cut_gz() {
    let dir = scratch();
    let lenient = ReadOptions::new().allow_truncated(true);
    // GNU gzip's two-member copy, and MDAnalysis's multi-model PDB gzipped here.
    let multi = gzip(&std::fs::read(path("mda_multi.pdb")).unwrap());
    for (fixture, plain) in [
        ("lmp_tri.lammpstrj.gz", "lmp_tri.lammpstrj"),
        ("mda_multi.pdb.gz", "mda_multi.pdb"),
    ] {
        let gz = match fixture {
            "mda_multi.pdb.gz" => multi.clone(),
            _ => std::fs::read(path(fixture)).unwrap(),
        };
        let plain = path(plain);
        let (want, n) = frames(&mut Trajectory::open(&plain).unwrap());
        assert!(n >= 2, "{fixture}");
        let mut seen = std::collections::BTreeSet::new();
        for cut in (20..gz.len()).step_by(gz.len() / 40) {
            let p = put(&dir, fixture, &gz[..cut]);
            let mut t = Trajectory::open_with(&p, lenient.clone()).unwrap();
            let (got, k) = frames(&mut t);
            assert!(k <= n, "{fixture} cut at {cut}");
            assert!(
                got[..] == want[..k],
                "{fixture} cut at {cut}: frames differ"
            );
            // A cut exactly at a member boundary leaves a whole gzip file: no gzip warning.
            let whole = gz[cut..].starts_with(&[0x1f, 0x8b, 8]);
            let w = warnings(&t);
            assert!(
                whole || (w[0].starts_with(&name_of(&p)) && w[0].contains("gzip")),
                "{fixture} cut at {cut}: {w:?}"
            );
            seen.insert(k);
        }
        // Cuts early and late: some keep no frame or a few, some all but the last.
        assert!(
            seen.len() >= 2 && seen.contains(&(n - 1)),
            "{fixture}: {seen:?}"
        );
        // Only the trailer missing: every frame inflated, the cut still reported.
        let p = put(&dir, fixture, &gz[..gz.len() - 4]);
        let mut t = Trajectory::open_with(&p, lenient.clone()).unwrap();
        assert_eq!(frames(&mut t).1, n);
        assert!(warnings(&t)[0].contains("gzip"));
    }
    let gz = std::fs::read(path("psf_parmed.psf.gz")).unwrap();
    let p = put(&dir, "psf_parmed.psf.gz", &gz[..gz.len() / 2]);
    assert_gzip_error(&Topology::open(&p).unwrap_err(), &p, gz.len() / 2);
}

#[test]
fn a_flipped_byte_anywhere_in_the_deflate_data_is_an_error() {
    let dir = scratch();
    for fixture in ["topo_mda.pdb.gz", "psf_parmed.psf.gz"] {
        let gz = std::fs::read(path(fixture)).unwrap();
        // gzip -n writes the 10-byte header with no optional fields (FLG = 0).
        assert_eq!(gz[3], 0, "{fixture}: header flags");
        for k in 10..gz.len() - 8 {
            let mut bad = gz.clone();
            bad[k] ^= 0xff;
            let p = put(&dir, fixture, &bad);
            let e = match fixture {
                "psf_parmed.psf.gz" => Topology::open(&p).unwrap_err(),
                _ => Trajectory::open(&p).map(|_| ()).unwrap_err(),
            };
            assert_gzip_error(&e, &p, bad.len());
        }
    }
}

#[test]
fn a_gz_name_over_plain_text_is_a_clear_error() {
    let dir = scratch();
    let p = put(
        &dir,
        "plain.pdb.gz",
        &std::fs::read(path("topo_mda.pdb")).unwrap(),
    );
    for e in [
        Trajectory::open(&p).map(|_| ()).unwrap_err(),
        Trajectory::open_as(&p, Format::Pdb)
            .map(|_| ())
            .unwrap_err(),
        Topology::open(&p).map(|_| ()).unwrap_err(),
    ] {
        let msg = e.to_string();
        assert!(msg.starts_with(&name_of(&p)), "{msg}");
        assert!(msg.contains("not gzip"), "{msg}");
    }
    // An empty .gz file too.
    let p = put(&dir, "empty.xyz.gz", b"");
    let e = Trajectory::open(&p).map(|_| ()).unwrap_err();
    assert!(e.to_string().contains("not gzip"), "{e}");
}

#[test]
fn errors_inside_a_gz_give_decompressed_offsets_under_the_gz_name() {
    // Frame 1's second atom has a bad coordinate.
    let text = b"2\nfirst\nO 0 0 0\nH 1 0 0\n2\nsecond\nO 0 0 0\nH 1 x 0\n";
    let dir = scratch();
    let p = put(&dir, "bad.xyz.gz", &gzip(text));
    let mut want =
        Trajectory::from_reader(std::io::Cursor::new(text), Format::Xyz, &name_of(&p)).unwrap();
    let want = want.read_frame(1, &mut Frame::new()).unwrap_err();
    let mut got = Trajectory::open(&p).unwrap();
    let got = got.read_frame(1, &mut Frame::new()).unwrap_err();
    assert_eq!(got.to_string(), want.to_string());
    assert!(got.location().unwrap().byte.is_some(), "{got}");
}

/// Writes `bytes` into a new FIFO `dir/name` from another thread; `None` without `mkfifo`.
#[cfg(unix)]
fn fifo(
    dir: &tempfile::TempDir,
    name: &str,
    bytes: Vec<u8>,
) -> Option<(PathBuf, std::thread::JoinHandle<()>)> {
    let p = dir.path().join(name);
    let made = std::process::Command::new("mkfifo").arg(&p).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("SKIPPED: no mkfifo");
        return None;
    }
    let q = p.clone();
    Some((
        p,
        std::thread::spawn(move || std::fs::write(q, bytes).unwrap()),
    ))
}

#[cfg(unix)]
#[test]
fn pipes_stream_without_a_seek_plain_or_named_gz() {
    let dir = scratch();
    let plain = std::fs::read(path("lmp_tri.lammpstrj")).unwrap();
    let gz = std::fs::read(path("lmp_tri.lammpstrj.gz")).unwrap();
    let mut want = Trajectory::open(path("lmp_tri.lammpstrj")).unwrap();
    let want = frames(&mut want).0;
    for (name, bytes) in [("plain.lammpstrj", plain), ("packed.lammpstrj.gz", gz)] {
        let Some((p, writer)) = fifo(&dir, name, bytes) else {
            return;
        };
        // Streaming only: a pipe has no frame index to come back to.
        let mut traj = Trajectory::open(&p).unwrap();
        let mut got = Vec::new();
        let mut f = Frame::new();
        while traj.read_next(&mut f).unwrap() {
            got.push(f.clone());
        }
        writer.join().unwrap();
        assert!(got == want, "{name}");
    }
}

/// bzip2 (the real bzip2 1.0.8, tests/data/gzip.sh): a two-stream `.mdcrd.bz2` reads as the plain
/// file frame for frame and a `.parm7.bz2` as the plain topology; every cut of the stream is an
/// error naming "bzip2" at or before its offset, or with `allow_truncated` the plain file's
/// first frames and a warning; a `.bz2` name over other bytes is an error.
#[test]
fn bzip2_reads_as_the_plain_file_and_cuts_are_located() {
    let opts = ReadOptions::new().atoms(66);
    let bz = path("amber_ascii/box.mdcrd.bz2");
    let (want, n) =
        frames(&mut Trajectory::open_with(path("amber_ascii/box.mdcrd"), opts.clone()).unwrap());
    let mut t = Trajectory::open_with(&bz, opts.clone()).unwrap();
    assert_eq!(t.format(), Format::AmberTrj);
    let (got, k) = frames(&mut t);
    assert_eq!((k, &got), (n, &want));
    let topo_bz = path("amber_ascii/truncoct.parm7.bz2");
    let plain = File::open(path("amber_ascii/truncoct.parm7")).unwrap();
    let want_topo =
        Topology::from_reader(plain, TopologyFormat::Prmtop, &name_of(&topo_bz)).unwrap();
    assert!(want_topo.box_angles.is_some() && !want_topo.bonds.is_empty());
    assert!(Topology::open(&topo_bz).unwrap() == want_topo);

    let dir = scratch();
    let bytes = std::fs::read(&bz).unwrap();
    let second = (4..bytes.len())
        .find(|&i| bytes[i..].starts_with(b"BZh9"))
        .unwrap();
    let mut kept = std::collections::BTreeSet::new();
    for cut in (10..bytes.len()).step_by(97).filter(|&c| c != second) {
        let p = put(&dir, "cut.mdcrd.bz2", &bytes[..cut]);
        let e = Trajectory::open_with(&p, opts.clone())
            .map(|_| ())
            .unwrap_err();
        let Error::Parse { at, .. } = &e else {
            panic!("cut at {cut}: {e:?}");
        };
        assert!(e.to_string().contains("bzip2"), "{e}");
        assert!(at.byte.unwrap() <= cut as u64, "cut at {cut}: {e}");
        let mut t = Trajectory::open_with(&p, opts.clone().allow_truncated(true)).unwrap();
        let (got, k) = frames(&mut t);
        assert!(got[..] == want[..k], "cut at {cut}: frames differ");
        assert!(warnings(&t)[0].contains("bzip2"), "cut at {cut}");
        kept.insert(k);
    }
    // bzip2 decodes whole blocks (each stream here is one): a cut inside the first stream
    // keeps nothing, one inside the second keeps the first stream's complete frames.
    assert_eq!(kept.into_iter().collect::<Vec<_>>(), [0, 2]);
    let p = put(
        &dir,
        "plain.mdcrd.bz2",
        &std::fs::read(path("amber_ascii/box.mdcrd")).unwrap(),
    );
    let e = Trajectory::open_with(&p, opts.clone())
        .map(|_| ())
        .unwrap_err();
    assert!(e.to_string().contains("bzip2 magic"), "{e}");
}
