//! NAMD binary coordinates written by MDAnalysis 2.11's NAMDBINWriter (tests/data/namd/
//! gen_namd.py), in both byte orders, compared with MDAnalysis's reading; and what a damaged
//! file gives.

use std::io::Cursor;
use std::path::PathBuf;

use texmap_md_io::{Error, Format, Frame, Trajectory};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/namd")
        .join(name)
}

/// Both byte orders give MDAnalysis's positions (the same f64 values rounded to f32), one frame.
#[test]
fn both_byte_orders_read_as_mdanalysis_reads_them() {
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path("reference.json")).unwrap()).unwrap();
    let want: Vec<[f32; 3]> = r["positions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| std::array::from_fn(|c| p[c].as_f64().unwrap() as f32))
        .collect();
    assert_eq!(want.len(), 66);
    for name in ["topo_mda.coor", "topo_mda_be.coor"] {
        let mut t = Trajectory::open(path(name)).unwrap();
        assert_eq!(t.format(), Format::NamdBin);
        assert_eq!(t.n_frames().unwrap(), 1);
        let mut f = Frame::new();
        assert!(t.read_next(&mut f).unwrap());
        assert_eq!(f.positions, want, "{name}");
        assert!(!t.read_next(&mut Frame::new()).unwrap());
        t.read_frame(0, &mut f).unwrap();
        assert_eq!(f.positions, want, "{name}");
    }
}

/// A file cut or padded by any number of bytes no longer fits its count in either byte order:
/// an error naming both readings and the length, never a misread frame; a NaN coordinate is
/// named by its atom and byte.
#[test]
fn a_length_that_does_not_fit_the_count_is_an_error() {
    let good = std::fs::read(path("topo_mda.coor")).unwrap();
    let open = |b: Vec<u8>| Trajectory::from_reader(Cursor::new(b), Format::NamdBin, "x.coor");
    for cut in (0..good.len()).step_by(7) {
        let e = open(good[..cut].to_vec()).err().unwrap();
        assert!(
            e.to_string().starts_with("x.coor: frame 0, byte 0"),
            "{cut}: {e}"
        );
    }
    let mut padded = good.clone();
    padded.push(0);
    let e = open(padded).err().unwrap().to_string();
    assert!(
        e.contains("66 (little-endian)") && e.contains("1589 bytes"),
        "{e}"
    );
    let mut nan = good.clone();
    nan[4 + 24 * 5 + 8..4 + 24 * 5 + 16].copy_from_slice(&f64::NAN.to_le_bytes());
    let mut t = open(nan).unwrap();
    let e = t.read_next(&mut Frame::new()).unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e}");
    assert!(e.to_string().contains("atom 5"), "{e}");
    assert!(
        e.to_string().contains(&format!("byte {}", 4 + 24 * 5)),
        "{e}"
    );
}
