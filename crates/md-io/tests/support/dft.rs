//! What the tests of DFT codes' outputs (pw.x, VASP) share: rows of a reference JSON, every
//! frame of a trajectory, the energies and stress the readers put in a frame's comment, and
//! the largest deviation between two lists of vectors.

use serde_json::Value;
use texmap_md_io::{Frame, Trajectory};

/// A JSON array of 3-vectors.
pub fn rows(v: &Value) -> Vec<[f64; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| std::array::from_fn(|c| r[c].as_f64().unwrap()))
        .collect()
}

/// Every frame of `t`, in order.
pub fn read_all(t: &mut Trajectory<impl std::io::Read + std::io::Seek>) -> Vec<Frame> {
    super::fixtures::stream(t)
}

/// The comment's `key=value` number.
pub fn comment_number(f: &Frame, key: &str) -> Option<f64> {
    f.comment
        .split(' ')
        .find_map(|kv| kv.strip_prefix(&format!("{key}=")))
        .map(|v| v.parse().unwrap())
}

/// The comment's `stress="…"` as ASE's Voigt order (xx yy zz yz xz xy), from the upper
/// triangle; with `symmetric`, the matrix must equal its transpose (pw.x prints a symmetric
/// tensor; VASP's vasprun.xml may differ in the last digits, and ASE keeps its upper triangle).
pub fn comment_stress(f: &Frame, symmetric: bool) -> Option<[f64; 6]> {
    let s = f.comment.split("stress=\"").nth(1)?.split('"').next()?;
    let v: Vec<f64> = s.split(' ').map(|x| x.parse().unwrap()).collect();
    assert_eq!(v.len(), 9, "{}", f.comment);
    if symmetric {
        assert_eq!(
            [v[1], v[2], v[5]],
            [v[3], v[6], v[7]],
            "symmetric: {}",
            f.comment
        );
    }
    Some([v[0], v[4], v[8], v[5], v[2], v[1]])
}

/// Largest |a - b| over matching components, asserting the shapes agree.
pub fn max_dev(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |c| (x[c] - y[c]).abs()))
        .fold(0.0, f64::max)
}

/// A frame's positions in f64.
pub fn positions(f: &Frame) -> Vec<[f64; 3]> {
    f.positions.iter().map(|p| p.map(f64::from)).collect()
}

/// A frame's cell vectors (rows); the frame must have a cell.
pub fn cell(f: &Frame) -> Vec<[f64; 3]> {
    f.cell.unwrap().matrix().to_vec()
}
