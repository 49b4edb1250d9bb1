//! AMBER NetCDF trajectories written by MDAnalysis 2.11.0 (`NCDFWriter`, CDF-2 64-bit offset)
//! and by scipy 1.17 (`netcdf_file`, CDF-1 classic, velocities with AMBER's scale_factor),
//! compared with the values those programs read back (tests/data/gen_topology.py,
//! topology_reference.json).

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Error, Format, Frame, ReadOptions, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(path("topology_reference.json")).unwrap())
        .unwrap()
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b}");
}

#[test]
fn mdanalysis_ncdf_positions_cells_and_times() {
    let r = reference();
    let frames = r["ncdf"].as_array().unwrap();
    let mut traj = Trajectory::open(path("amber_mda.ncdf")).unwrap();
    assert_eq!(traj.format(), Format::Netcdf);
    assert_eq!(traj.n_frames().unwrap(), frames.len());
    assert_eq!(traj.n_atoms().unwrap(), 66);
    let mut f = Frame::new();
    // Streaming, then random access backwards: the same values.
    let mut order: Vec<usize> = (0..frames.len()).collect();
    order.extend((0..frames.len()).rev());
    for (pass, &k) in order.iter().enumerate() {
        if pass < frames.len() {
            assert!(traj.read_next(&mut f).unwrap());
        } else {
            traj.read_frame(k, &mut f).unwrap();
        }
        let want = &frames[k];
        close(
            f.time.unwrap(),
            want["time"].as_f64().unwrap(),
            1e-6,
            "time",
        );
        let pos = want["positions"].as_array().unwrap();
        assert_eq!(f.n_atoms(), pos.len());
        for (i, p) in pos.iter().enumerate() {
            for c in 0..3 {
                // Both are the same f32 values (JSON keeps them as the shortest f64 repr).
                assert_eq!(
                    f.positions[i][c],
                    p[c].as_f64().unwrap() as f32,
                    "frame {k} atom {i}"
                );
            }
        }
        let dims = want["dimensions"].as_array().unwrap();
        let cell = f.cell.unwrap();
        for c in 0..3 {
            close(
                cell.lengths()[c],
                dims[c].as_f64().unwrap(),
                1e-9,
                "cell length",
            );
            close(
                cell.angles()[c],
                dims[3 + c].as_f64().unwrap(),
                1e-9,
                "cell angle",
            );
        }
    }
    traj.read_frame(frames.len() - 1, &mut f).unwrap();
    assert!(!traj.read_next(&mut f).unwrap());
    assert!(traj.read_frame(frames.len(), &mut f).is_err());
}

#[test]
fn scipy_classic_file_with_scaled_velocities() {
    let r = &reference()["scipy_cdf1"];
    let mut traj = Trajectory::open(path("amber_scipy_cdf1.nc")).unwrap();
    assert_eq!(traj.n_frames().unwrap(), 3);
    let mut f = Frame::new();
    for k in 0..3 {
        traj.read_frame(k, &mut f).unwrap();
        close(f.time.unwrap(), r["time"][k].as_f64().unwrap(), 0.0, "time");
        close(
            f.cell.unwrap().lengths()[2],
            r["cell_lengths"][k][2].as_f64().unwrap(),
            0.0,
            "c",
        );
        for i in 0..5 {
            for c in 0..3 {
                assert_eq!(
                    f.positions[i][c],
                    r["positions"][k][i][c].as_f64().unwrap() as f32
                );
                // f32 times the scale factor, against scipy's f64 product.
                close(
                    f.velocities[i][c] as f64,
                    r["velocities"][k][i][c].as_f64().unwrap(),
                    1e-5,
                    "velocity",
                );
            }
        }
    }
}

#[test]
fn a_cut_file_names_the_first_incomplete_frame_and_keeps_the_others() {
    let bytes = std::fs::read(path("amber_mda.ncdf")).unwrap();
    let cut = bytes[..bytes.len() - 10].to_vec();
    let mut strict =
        Trajectory::from_reader(Cursor::new(cut.clone()), Format::Netcdf, "cut.nc").unwrap();
    let e = strict.n_frames().unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().starts_with("cut.nc: frame 3"), "{e}");
    let opts = ReadOptions::new().allow_truncated(true);
    let mut lenient =
        Trajectory::from_reader_with(Cursor::new(cut), Format::Netcdf, "cut.nc", opts).unwrap();
    assert_eq!(lenient.n_frames().unwrap(), 3);
    assert_eq!(lenient.warnings().len(), 1);
}

#[test]
fn an_atom_at_1e30_is_a_reader_error_naming_the_atom() {
    let mut bytes = std::fs::read(path("amber_mda.ncdf")).unwrap();
    // Find frame 0's coordinates of atom 7, x, by the value MDAnalysis read back.
    let x = reference()["ncdf"][0]["positions"][7][0].as_f64().unwrap() as f32;
    let pat = x.to_be_bytes();
    let at = bytes.windows(4).position(|w| w == pat).unwrap();
    bytes[at..at + 4].copy_from_slice(&1e30f32.to_be_bytes());
    let mut t = Trajectory::from_reader(Cursor::new(bytes), Format::Netcdf, "far.nc").unwrap();
    let e = t.read_frame(0, &mut Frame::new()).unwrap_err().to_string();
    assert!(
        e.starts_with("far.nc: frame 0, byte") && e.contains("atom 7"),
        "{e}"
    );
}
