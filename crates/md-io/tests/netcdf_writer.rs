//! Our AMBER NetCDF writer (src/netcdf_writer.rs) against independent readers.
//!
//! - tests/data/netcdf_write/*.nc are files this writer wrote from the repository's fixtures
//!   (a triclinic GSD run with velocities, a GROMACS TRR with times and velocities, a POSCAR whose
//!   cell is not in AMBER's orientation); the test writes them again and requires the same bytes.
//! - tests/data/netcdf_write/reference.json.gz is what MDAnalysis 2.11's `NCDFReader` and the
//!   netCDF4 Python module (Unidata's netCDF-C library) read from those files
//!   (gen_netcdf_write.py); it must be the frames we wrote: positions bit for bit, cells, times,
//!   velocities in Å/ps, the header's dimensions, types, units and attributes.
//! - Our reader reads every written file back (and a rewritten MDAnalysis file as the original).
//! - Live checks on a file written now, where the programs are installed: `ncdump` (netcdf-bin)
//!   and python3 with netCDF4 and MDAnalysis; without them they print SKIPPED.
//! - Refused frames: the error names the file, the frame and what was expected, nothing of the
//!   frame is written, and an unfinished file reads as no frames.
//! - 100,000 atoms: the header patch, the 64-bit `begin`s and the record offsets.

use std::io::{Cursor, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;
use support::fixtures::{data, stream};
use texmap_md_io::{Error, Format, Frame, Trajectory, UnitCell, Writer};

use crate::support;

/// A file of tests/data/netcdf_write.
fn here(name: &str) -> PathBuf {
    data("netcdf_write").join(name)
}

fn frames_of(path: &Path) -> Vec<Frame> {
    let mut t = Trajectory::open(path).unwrap_or_else(|e| panic!("{e}"));
    stream(&mut t)
}

/// The inputs of the committed files (the generator script's `CASES` names them).
fn cases() -> Vec<(&'static str, Vec<Frame>)> {
    // HOOMD-blue: 200 particles, a triclinic box changing in frame 3, velocities, no times.
    let mut gsd = frames_of(&data("gsd/hoomd_tri.gsd"));
    gsd.truncate(4);
    // GROMACS: 36 atoms, a cubic box, times and velocities.
    let mut trr = frames_of(&data("dynamics/vel.trr"));
    trr.truncate(5);
    // ASE's NaCl POSCAR: lattice vectors not in AMBER's orientation; made-up velocities.
    let mut nacl = frames_of(&data("lammps_write/nacl_primitive.vasp"));
    for f in &mut nacl {
        f.velocities = (0..f.n_atoms())
            .map(|i| [0.5 - 0.25 * i as f32, 0.125 * i as f32, -1.5])
            .collect();
    }
    vec![("gsd_tri", gsd), ("vel_trr", trr), ("nacl_rotated", nacl)]
}

fn write(frames: &[Frame], name: &str) -> Result<Vec<u8>, Error> {
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Netcdf, name)?;
    for f in frames {
        w.write_frame(f)?;
    }
    Ok(w.finish()?.into_inner())
}

fn read_back(bytes: Vec<u8>) -> Vec<Frame> {
    let mut t = Trajectory::from_reader(Cursor::new(bytes), Format::Netcdf, "back.nc").unwrap();
    stream(&mut t)
}

fn ulp(x: f32) -> f32 {
    f32::from_bits(x.abs().to_bits() + 1) - x.abs()
}

/// `x` is `want` to one unit in the last place.
fn within_ulp(x: f32, want: f32, what: &str) {
    assert!(
        (x - want).abs() <= ulp(want),
        "{what}: {x} read, {want} written"
    );
}

fn is_upright(cell: &UnitCell) -> bool {
    let m = cell.matrix();
    m[0][1] == 0.0 && m[0][2] == 0.0 && m[1][2] == 0.0
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[test]
fn committed_files_are_what_the_writer_writes() {
    let regenerate = std::env::var_os("NETCDF_WRITE_REGENERATE").is_some();
    for (name, frames) in cases() {
        let path = here(&format!("{name}.nc"));
        let bytes = write(&frames, &path.display().to_string()).unwrap();
        if regenerate {
            std::fs::write(&path, &bytes).unwrap();
            continue;
        }
        let committed = std::fs::read(&path).unwrap();
        let version = env!("CARGO_PKG_VERSION");
        assert!(
            committed
                .windows(version.len())
                .any(|w| w == version.as_bytes()),
            "{name}.nc was written by another version than {version}: rerun gen_netcdf_write.py"
        );
        assert_eq!(bytes.len(), committed.len(), "{name}.nc: length");
        if let Some(i) = (0..bytes.len()).find(|&i| bytes[i] != committed[i]) {
            panic!("{name}.nc: byte {i} differs from the committed file");
        }
    }
}

fn reference() -> Value {
    let gz = std::fs::File::open(here("reference.json.gz")).unwrap();
    serde_json::from_reader(flate2::read::GzDecoder::new(gz)).unwrap()
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Numbers that are f32 values (positions, float32 dimensions, times). serde_json's parse of a
/// decimal may be one f64 ulp off (its exact mode is a feature not enabled here), which the
/// rounding to f32 removes.
fn f32s(v: &Value) -> Vec<f32> {
    f64s(v).into_iter().map(|x| x as f32).collect()
}

fn vec3s_f32(v: &Value) -> Vec<[f32; 3]> {
    vec3s(v).into_iter().map(|p| p.map(|x| x as f32)).collect()
}

/// Doubles read back, to the f64 ulp the JSON parse may lose.
fn same_f64(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 4.0 * f64::EPSILON * b.abs(),
        "{what}: {a} vs {b}"
    );
}

fn vec3s(v: &Value) -> Vec<[f64; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let p = f64s(p);
            [p[0], p[1], p[2]]
        })
        .collect()
}

/// The header as netCDF-C (through netCDF4) reads it.
fn check_header(name: &str, frames: &[Frame], nc: &Value) {
    let f0 = &frames[0];
    assert_eq!(nc["file_format"], "NETCDF3_64BIT_OFFSET", "{name}");
    let dims = &nc["dimensions"];
    assert_eq!(
        dims["frame"],
        serde_json::json!([frames.len(), true]),
        "{name}"
    );
    assert_eq!(dims["atom"], serde_json::json!([f0.n_atoms(), false]));
    for (d, n) in [
        ("spatial", 3),
        ("cell_spatial", 3),
        ("cell_angular", 3),
        ("label", 5),
    ] {
        assert_eq!(dims[d], serde_json::json!([n, false]), "{name}: {d}");
    }
    let g = &nc["attributes"];
    assert_eq!(g["Conventions"], "AMBER");
    assert_eq!(g["ConventionVersion"], "1.0");
    assert_eq!(g["program"], "texmap");
    assert_eq!(g["programVersion"], env!("CARGO_PKG_VERSION"));
    assert_eq!(g["title"], f0.comment.as_str(), "{name}");
    let vars = &nc["variables"];
    let var = |v: &str, dtype: &str, dims: &[&str], units: Option<&str>| {
        let x = &vars[v];
        assert_eq!(x["dtype"], dtype, "{name}: {v}");
        assert_eq!(x["dimensions"], serde_json::json!(dims), "{name}: {v}");
        assert_eq!(
            x["attributes"]["units"].as_str(),
            units,
            "{name}: {v} units"
        );
    };
    var("spatial", "S1", &["spatial"], None);
    var("time", "float32", &["frame"], Some("picosecond"));
    let xyz = ["frame", "atom", "spatial"];
    var("coordinates", "float32", &xyz, Some("angstrom"));
    assert_eq!(nc["spatial"], "xyz");
    assert_eq!(f0.cell.is_some(), vars.get("cell_lengths").is_some());
    if f0.cell.is_some() {
        var("cell_spatial", "S1", &["cell_spatial"], None);
        var("cell_angular", "S1", &["cell_angular", "label"], None);
        var(
            "cell_lengths",
            "float64",
            &["frame", "cell_spatial"],
            Some("angstrom"),
        );
        var(
            "cell_angles",
            "float64",
            &["frame", "cell_angular"],
            Some("degree"),
        );
        assert_eq!(nc["cell_spatial"], "abc");
        assert_eq!(
            nc["cell_angular"],
            serde_json::json!(["alpha", "beta ", "gamma"])
        );
    }
    assert_eq!(!f0.velocities.is_empty(), vars.get("velocities").is_some());
    if !f0.velocities.is_empty() {
        var("velocities", "float32", &xyz, Some("angstrom/picosecond"));
        assert_eq!(vars["velocities"]["attributes"]["scale_factor"], 20.455);
    }
    assert!(vars.get("forces").is_none());
}

#[test]
fn mdanalysis_and_netcdf4_read_the_committed_files_as_our_frames() {
    let r = reference();
    for (name, frames) in cases() {
        let case = &r["cases"][name];
        let (mda, nc) = (&case["mdanalysis"], &case["netcdf4"]);
        check_header(name, &frames, nc);
        assert_eq!(case["ncdump_k"], "64-bit offset", "{name}");
        assert_eq!(mda["n_atoms"], frames[0].n_atoms(), "{name}");
        assert_eq!(mda["n_frames"], frames.len(), "{name}");
        let times = f32s(&nc["time"]);
        for (k, f) in frames.iter().enumerate() {
            let at = format!("{name} frame {k}");
            let m = &mda["frames"][k];
            // Time: the frame's (as float), else its index.
            let t = f.time.unwrap_or(k as f64) as f32;
            assert_eq!(
                m["time"].as_f64().unwrap() as f32,
                t,
                "{at}: MDAnalysis time"
            );
            assert_eq!(times[k], t, "{at}: netCDF4 time");
            let pos_mda = vec3s_f32(&m["positions"]);
            let pos_nc = vec3s_f32(&nc["coordinates"][k]);
            assert_eq!(pos_mda, pos_nc, "{at}: the two readers");
            let cell = f.cell.unwrap();
            // Cell: doubles as written (netCDF4); MDAnalysis's dimensions are float32.
            let lengths = f64s(&nc["cell_lengths"][k]);
            let angles = f64s(&nc["cell_angles"][k]);
            for e in 0..3 {
                same_f64(
                    lengths[e],
                    cell.lengths()[e],
                    &format!("{at}: cell_lengths"),
                );
                same_f64(angles[e], cell.angles()[e], &format!("{at}: cell_angles"));
            }
            let dims = f32s(&m["dimensions"]);
            let want: Vec<f64> = cell.lengths().into_iter().chain(cell.angles()).collect();
            for (d, w) in dims.iter().zip(&want) {
                assert_eq!(*d, *w as f32, "{at}: MDAnalysis dimensions");
            }
            let vel_mda = vec3s_f32(&m["velocities"]);
            let vel_nc = vec3s(&nc["velocities"][k]);
            let stored = vec3s_f32(&nc["velocities_stored"][k]);
            if is_upright(&cell) {
                // Positions bit for bit.
                for (i, p) in f.positions.iter().enumerate() {
                    assert_eq!(pos_mda[i], *p, "{at} atom {i}");
                }
                for (i, v) in f.velocities.iter().enumerate() {
                    for c in 0..3 {
                        let what = format!("{at} atom {i} velocity");
                        // Stored in AMBER units: the f32 of v / 20.455.
                        let s = (v[c] as f64 / 20.455) as f32;
                        assert_eq!(stored[i][c], s, "{what}: stored");
                        // netCDF4 scales in double: s · 20.455.
                        same_f64(vel_nc[i][c], s as f64 * 20.455, &what);
                        within_ulp(vel_mda[i][c], v[c], &what);
                        within_ulp(vel_nc[i][c] as f32, v[c], &what);
                    }
                }
            } else {
                // Rotated into AMBER's orientation: the same fractional coordinates in the cell
                // MDAnalysis builds from its dimensions, and the same velocity components along
                // the cell's edges.
                let theirs = UnitCell::from_lengths_angles(
                    [lengths[0], lengths[1], lengths[2]],
                    [angles[0], angles[1], angles[2]],
                )
                .unwrap();
                let (mo, mt) = (cell.matrix(), theirs.matrix());
                assert!(mt[0][1] == 0.0 && mt[0][2] == 0.0 && mt[1][2] == 0.0);
                for (i, p) in f.positions.iter().enumerate() {
                    let p = p.map(f64::from);
                    for e in 0..3 {
                        let ours = dot(p, mo[e]) / dot(mo[e], mo[e]);
                        let back = dot(pos_mda[i].map(f64::from), mt[e]) / dot(mt[e], mt[e]);
                        assert!((ours - back).abs() < 1e-6, "{at} atom {i} edge {e}");
                    }
                }
                for (i, v) in f.velocities.iter().enumerate() {
                    let v = v.map(f64::from);
                    for e in 0..3 {
                        let ours = dot(v, mo[e]) / cell.lengths()[e];
                        let back = dot(vel_mda[i].map(f64::from), mt[e]) / theirs.lengths()[e];
                        assert!(
                            (ours - back).abs() < 1e-5,
                            "{at} atom {i}: v along edge {e}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn our_reader_reads_back_what_was_written() {
    for (name, frames) in cases() {
        let back = read_back(write(&frames, "t.nc").unwrap());
        assert_eq!(back.len(), frames.len(), "{name}");
        for (k, (f, g)) in frames.iter().zip(&back).enumerate() {
            let at = format!("{name} frame {k}");
            assert_eq!(
                g.time,
                Some(f.time.unwrap_or(k as f64) as f32 as f64),
                "{at}"
            );
            let (c, d) = (f.cell.unwrap(), g.cell.unwrap());
            assert_eq!(c.lengths(), d.lengths(), "{at}");
            assert_eq!(c.angles(), d.angles(), "{at}");
            if is_upright(&c) {
                assert_eq!(g.positions, f.positions, "{at}");
                for (v, w) in g.velocities.iter().zip(&f.velocities) {
                    for k in 0..3 {
                        within_ulp(v[k], w[k], &at);
                    }
                }
            }
        }
    }
    // MDAnalysis's own file: positions, times and cells as read from it.
    let mda = frames_of(&data("amber_mda.ncdf"));
    let back = read_back(write(&mda, "t.nc").unwrap());
    assert_eq!(back.len(), 4);
    for (f, g) in mda.iter().zip(&back) {
        assert_eq!(g.positions, f.positions);
        assert_eq!(g.time, f.time);
        assert_eq!(g.cell.map(|c| c.lengths()), f.cell.map(|c| c.lengths()));
        assert_eq!(g.cell.map(|c| c.angles()), f.cell.map(|c| c.angles()));
    }
    // A frame without a cell: no cell variables, read back without a cell.
    let mut bare = mda[0].clone();
    bare.cell = None;
    let bytes = write(std::slice::from_ref(&bare), "t.nc").unwrap();
    assert!(!bytes.windows(12).any(|w| w == b"cell_lengths"));
    let back = read_back(bytes);
    assert_eq!(back[0].cell, None);
    assert_eq!(back[0].positions, bare.positions);
}

/// Writes `frames` through `Writer::create` to `path`: the first error, with the writer
/// finished (or dropped unfinished) after it.
fn create(path: &Path, frames: &[Frame], finish: bool) -> Option<String> {
    let mut w = Writer::create(path, Format::Netcdf).unwrap();
    let mut err = None;
    for f in frames {
        if let Err(e) = w.write_frame(f) {
            assert!(matches!(e, Error::InvalidFrame { .. }), "{e:?}");
            err.get_or_insert(e.to_string());
        }
    }
    if finish {
        w.finish().unwrap();
    }
    err
}

#[test]
fn refused_frames_name_the_file_frame_and_what_was_expected() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.nc");
    let shown = path.display().to_string();
    let gsd = frames_of(&data("gsd/hoomd_tri.gsd"));
    assert_eq!((gsd[3].n_atoms(), gsd[4].n_atoms()), (200, 180));
    let trr = frames_of(&data("trr_mda.trr"));
    assert!(!trr[0].velocities.is_empty() && trr[1].velocities.is_empty());
    let base = &trr[0];
    let tweak = |f: fn(&mut Frame)| {
        let mut g = base.clone();
        f(&mut g);
        g
    };
    let cases: Vec<(&str, Vec<Frame>, &[&str])> = vec![
        (
            "atom count",
            gsd[3..5].to_vec(),
            &["frame 1", "180 atoms", "first frame 200"],
        ),
        (
            "velocities lacking",
            trr[..2].to_vec(),
            &["frame 1", "no velocities", "first frame had velocities"],
        ),
        (
            "velocities appearing",
            vec![tweak(|g| g.velocities.clear()), base.clone()],
            &["frame 1", "has velocities, and the first frame had none"],
        ),
        (
            "cell lacking",
            vec![base.clone(), tweak(|g| g.cell = None)],
            &["frame 1", "no cell", "first frame had a cell"],
        ),
        (
            "cell appearing",
            vec![tweak(|g| g.cell = None), base.clone()],
            &["frame 1", "has a cell, and the first frame had none"],
        ),
        (
            "time lacking",
            vec![base.clone(), base.clone(), tweak(|g| g.time = None)],
            &["frame 2", "no time", "first frame had a time"],
        ),
        (
            "no atoms",
            vec![Frame::new()],
            &["frame 0", "no atoms", "length 1 or more"],
        ),
        (
            "far atom",
            vec![tweak(|g| g.positions[3][1] = 2e7)],
            &["frame 0", "atom 3", "beyond"],
        ),
        (
            "huge time",
            vec![base.clone(), tweak(|g| g.time = Some(1e300))],
            &["frame 1", "time 1e300 ps", "float"],
        ),
    ];
    for (what, frames, words) in cases {
        let e = create(&path, &frames, true).unwrap_or_else(|| panic!("{what}: not refused"));
        assert!(e.starts_with(&format!("{shown}: ")), "{what}: {e}");
        for w in words {
            assert!(e.contains(w), "{what}: {w:?} not in {e}");
        }
        // Nothing of the refused frame was written: the finished file holds the frames before
        // it (those that were not refused), and reads back as them.
        let good: Vec<&Frame> = {
            let mut g = Vec::new();
            let mut first: Option<&Frame> = None;
            for f in &frames {
                let ok = f.n_atoms() > 0
                    && f.positions.iter().flatten().all(|x| x.abs() < 1e7)
                    && f.time.is_none_or(|t| t < 1e30)
                    && first.is_none_or(|p| {
                        p.n_atoms() == f.n_atoms()
                            && p.cell.is_some() == f.cell.is_some()
                            && p.velocities.is_empty() == f.velocities.is_empty()
                            && p.time.is_some() == f.time.is_some()
                    });
                if ok {
                    first.get_or_insert(f);
                    g.push(f);
                }
            }
            g
        };
        let len = std::fs::metadata(&path).unwrap().len();
        if good.is_empty() {
            assert_eq!(len, 0, "{what}: a file without frames is empty");
            continue;
        }
        let owned: Vec<Frame> = good.iter().map(|f| (*f).clone()).collect();
        let expected = write(&owned, "x.nc").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), expected, "{what}");
        assert_eq!(frames_of(&path).len(), good.len(), "{what}");
    }
    // A writer dropped without finish (a crash, an error the caller gave up on): numrecs is
    // still 0, so readers see no frame, never one of unknown length.
    let e = create(&path, &trr[..2], false).unwrap();
    assert!(e.contains("frame 1"), "{e}");
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"CDF\x02\0\0\0\0");
    let mut t = Trajectory::open(&path).unwrap();
    assert_eq!(t.n_frames().unwrap(), 0);
    assert!(!t.read_next(&mut Frame::new()).unwrap());
}

/// Reads a big-endian u32 / u64 at `at`.
fn be32(b: &[u8], at: usize) -> u32 {
    u32::from_be_bytes(b[at..at + 4].try_into().unwrap())
}
fn be64(b: &[u8], at: usize) -> u64 {
    u64::from_be_bytes(b[at..at + 8].try_into().unwrap())
}

/// The `begin` of variable `name` in a header: the 8 bytes that end its entry (found after its
/// name by walking its dimension ids, attributes, type and vsize).
fn begin_of(b: &[u8], name: &str) -> (u32, u64) {
    let mut key = (name.len() as u32).to_be_bytes().to_vec();
    key.extend_from_slice(name.as_bytes());
    key.resize(4 + name.len().div_ceil(4) * 4, 0);
    // The variable list starts at tag 0x0B: search after it.
    let vars = (0..b.len() - 4)
        .find(|&i| be32(b, i) == 0x0B && b[i + 8..].starts_with(&[0, 0, 0, 7]))
        .unwrap();
    let mut at = (vars..b.len()).find(|&i| b[i..].starts_with(&key)).unwrap();
    at += key.len();
    let rank = be32(b, at) as usize;
    at += 4 + 4 * rank;
    let tag = be32(b, at);
    let n_attrs = be32(b, at + 4) as usize;
    at += 8;
    assert!(tag == 0x0C || (tag == 0 && n_attrs == 0));
    for _ in 0..n_attrs {
        let len = be32(b, at) as usize;
        at += 4 + len.div_ceil(4) * 4;
        let ty = be32(b, at);
        let count = be32(b, at + 4) as usize;
        let size = if ty == 6 { 8 } else { 1 };
        at += 8 + (count * size).div_ceil(4) * 4;
    }
    let vsize = be32(b, at + 4);
    (vsize, be64(b, at + 8))
}

#[test]
fn a_hundred_thousand_atoms() {
    let n = 100_000;
    let cell = UnitCell::from_lengths_angles([300.0, 310.0, 320.0], [70.0, 80.0, 100.0]).unwrap();
    let frames: Vec<Frame> = (0..3)
        .map(|k| {
            let mut f = Frame::new();
            f.positions = (0..n)
                .map(|i| {
                    let x = (i * 7919 + k * 13) % 300_000;
                    [x as f32 * 1e-3, (i % 310) as f32, (i / 1000) as f32 + 0.5]
                })
                .collect();
            f.velocities = (0..n)
                .map(|i| [(i % 17) as f32 - 8.0, k as f32, 0.25])
                .collect();
            f.cell = Some(cell);
            f.time = Some(1000.0 + 2.0 * k as f64);
            f
        })
        .collect();
    let bytes = write(&frames, "big.nc").unwrap();
    assert_eq!(&bytes[..4], b"CDF\x02");
    assert_eq!(be32(&bytes, 4), 3, "numrecs patched by finish");
    let records = [
        ("time", 4),
        ("coordinates", 12 * n as u64),
        ("cell_lengths", 24),
        ("cell_angles", 24),
        ("velocities", 12 * n as u64),
    ];
    let (_, first) = begin_of(&bytes, "time");
    let mut at = first;
    for (name, size) in records {
        let (vsize, begin) = begin_of(&bytes, name);
        assert_eq!(begin, at, "{name}'s 64-bit begin");
        assert_eq!(vsize as u64, size, "{name}'s vsize");
        at += size;
    }
    let recsize = at - first;
    assert_eq!(bytes.len() as u64, first + 3 * recsize);
    // Fixed variables sit between the header and the records, "xyz", "abc", the angle labels.
    let (_, spatial) = begin_of(&bytes, "spatial");
    assert_eq!(&bytes[spatial as usize..spatial as usize + 3], b"xyz");
    let (_, angular) = begin_of(&bytes, "cell_angular");
    assert_eq!(
        &bytes[angular as usize..angular as usize + 15],
        b"alphabeta gamma"
    );
    // Record 2's coordinates of atom 99,999, found at begin + 2·recsize.
    let (_, coords) = begin_of(&bytes, "coordinates");
    let off = (coords + 2 * recsize) as usize + 12 * (n - 1);
    let x = f32::from_be_bytes(bytes[off..off + 4].try_into().unwrap());
    assert_eq!(x, frames[2].positions[n - 1][0]);
    // Our reader, by index, backwards.
    let mut t =
        Trajectory::from_reader(Cursor::new(bytes.clone()), Format::Netcdf, "big.nc").unwrap();
    assert_eq!(t.n_frames().unwrap(), 3);
    let mut g = Frame::new();
    for k in (0..3).rev() {
        t.read_frame(k, &mut g).unwrap();
        assert_eq!(g.positions, frames[k].positions);
        assert_eq!(g.time, frames[k].time);
    }
    // ncdump, where installed.
    if let Some(header) = ncdump(&bytes, "-h") {
        assert!(header.contains("atom = 100000 ;"), "{header}");
        assert!(
            header.contains("frame = UNLIMITED ; // (3 currently)"),
            "{header}"
        );
    }
}

/// Runs `ncdump ARG` on `bytes` written to a temporary file: its output, or `None` (and a
/// SKIPPED line) without ncdump.
fn ncdump(bytes: &[u8], arg: &str) -> Option<String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.nc");
    std::fs::write(&path, bytes).unwrap();
    let out = match Command::new("ncdump").arg(arg).arg(&path).output() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("SKIPPED: ncdump {arg} (apt install netcdf-bin): {e}");
            return None;
        }
    };
    assert!(
        out.status.success(),
        "ncdump {arg}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(String::from_utf8(out.stdout).unwrap())
}

/// Reads a file with netCDF4 and MDAnalysis and prints, per frame, the time, the coordinates
/// (netCDF4), MDAnalysis's positions, velocities and dimensions.
const PYTHON: &str = r#"
import json, sys
import netCDF4
import MDAnalysis.coordinates.TRJ as trj
path = sys.argv[1]
with netCDF4.Dataset(path) as d:
    nc = {"format": d.file_format,
          "time": d["time"][:].tolist(),
          "coordinates": d["coordinates"][:].tolist(),
          "velocities": d["velocities"][:].tolist(),
          "conventions": d.Conventions}
r = trj.NCDFReader(path)
mda = [{"time": float(ts.time), "positions": ts.positions.tolist(),
        "velocities": ts.velocities.tolist(), "dimensions": ts.dimensions.tolist()} for ts in r]
print(json.dumps({"netcdf4": nc, "mdanalysis": mda}))
"#;

#[test]
fn ncdump_netcdf4_and_mdanalysis_read_a_file_written_now() {
    let (_, frames) = cases().swap_remove(0);
    let bytes = write(&frames, "now.nc").unwrap();
    if let Some(kind) = ncdump(&bytes, "-k") {
        assert_eq!(kind.trim(), "64-bit offset");
    }
    if let Some(h) = ncdump(&bytes, "-h") {
        for line in [
            "frame = UNLIMITED ; // (4 currently)",
            "atom = 200 ;",
            "label = 5 ;",
            "float coordinates(frame, atom, spatial) ;",
            "coordinates:units = \"angstrom\" ;",
            "double cell_lengths(frame, cell_spatial) ;",
            "char cell_angular(cell_angular, label) ;",
            "velocities:units = \"angstrom/picosecond\" ;",
            "velocities:scale_factor = 20.455 ;",
            ":Conventions = \"AMBER\" ;",
            ":ConventionVersion = \"1.0\" ;",
            ":program = \"texmap\" ;",
        ] {
            assert!(h.contains(line), "{line} not in\n{h}");
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("now.nc");
    std::fs::write(&path, &bytes).unwrap();
    let out = match Command::new("python3")
        .arg("-c")
        .arg(PYTHON)
        .arg(&path)
        .output()
    {
        Ok(o) => o,
        Err(e) => {
            eprintln!("SKIPPED: reading by netCDF4 and MDAnalysis (python3: {e})");
            return;
        }
    };
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        if err.contains("No module named") {
            eprintln!(
                "SKIPPED: reading by netCDF4 and MDAnalysis (pip install netCDF4 MDAnalysis)"
            );
            return;
        }
        panic!("python3 failed: {err}");
    }
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let nc = &v["netcdf4"];
    assert_eq!(nc["format"], "NETCDF3_64BIT_OFFSET");
    assert_eq!(nc["conventions"], "AMBER");
    for (k, f) in frames.iter().enumerate() {
        let m = &v["mdanalysis"][k];
        assert_eq!(f32s(&nc["time"])[k], k as f32);
        assert_eq!(m["time"].as_f64().unwrap() as f32, k as f32);
        let pos = vec3s_f32(&nc["coordinates"][k]);
        assert_eq!(pos, vec3s_f32(&m["positions"]));
        assert_eq!(pos, f.positions, "frame {k}");
        let (vn, vm) = (vec3s_f32(&nc["velocities"][k]), vec3s_f32(&m["velocities"]));
        for (i, w) in f.velocities.iter().enumerate() {
            for c in 0..3 {
                within_ulp(vn[i][c], w[c], "netCDF4 velocity");
                within_ulp(vm[i][c], w[c], "MDAnalysis velocity");
            }
        }
        let c = f.cell.unwrap();
        let dims = f32s(&m["dimensions"]);
        for (d, w) in dims.iter().zip(c.lengths().into_iter().chain(c.angles())) {
            assert_eq!(*d, w as f32, "frame {k} dimensions");
        }
    }
}

#[test]
fn a_stream_not_at_its_start_and_seek_back_to_the_end() {
    // The file starts where the stream is when the first frame comes; finish leaves the stream
    // at the file's end (so that a caller may go on writing after it).
    let (_, frames) = cases().swap_remove(1);
    let mut c = Cursor::new(Vec::new());
    c.get_mut().extend_from_slice(b"prefix!!");
    c.seek(SeekFrom::End(0)).unwrap();
    let mut w = Writer::new(c, Format::Netcdf, "t.nc").unwrap();
    for f in &frames {
        w.write_frame(f).unwrap();
    }
    let mut c = w.finish().unwrap();
    let end = c.stream_position().unwrap();
    assert_eq!(end, c.get_ref().len() as u64);
    let mut all = Vec::new();
    c.seek(SeekFrom::Start(0)).unwrap();
    c.read_to_end(&mut all).unwrap();
    assert_eq!(&all[..8], b"prefix!!");
    assert_eq!(all[8..].to_vec(), write(&frames, "t.nc").unwrap());
}
