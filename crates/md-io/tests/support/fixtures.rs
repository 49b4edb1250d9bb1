//! The test data directory and every frame of a trajectory, for test binaries that declare
//! `mod support { pub mod fixtures; }`.

use std::io::{Read, Seek};
use std::path::PathBuf;

use texmap_md_io::{Frame, Trajectory};

/// A file of tests/data.
pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Every frame of `traj`, read in order.
pub fn stream<R: Read + Seek>(traj: &mut Trajectory<R>) -> Vec<Frame> {
    let mut out = Vec::new();
    let mut f = Frame::new();
    while traj.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}
