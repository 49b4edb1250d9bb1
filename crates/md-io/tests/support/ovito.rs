//! Fixtures OVITO wrote (`tests/data/<dir>/gen_*.py`) and its reference values, for the tests
//! of the analyses that compare with OVITO (clusters, strain, Wigner–Seitz, Voronoi, formulas).
#![allow(dead_code)] // Each test binary uses its own part.

use std::path::PathBuf;

use texmap_md_io::{Frame, Trajectory};

/// A fixture directory under `tests/data`.
pub struct Fixtures(pub &'static str);

impl Fixtures {
    /// The path of file `name` in the directory.
    pub fn path(&self, name: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(self.0)
            .join(name)
    }

    /// The first frame of file `name`.
    pub fn frame(&self, name: &str) -> Frame {
        let mut frame = Frame::new();
        let read = Trajectory::open(self.path(name))
            .unwrap()
            .read_next(&mut frame)
            .unwrap();
        assert!(read, "{name}: no frame");
        frame
    }

    /// The JSON file `name` (OVITO's values).
    pub fn json(&self, name: &str) -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(self.path(name)).unwrap()).unwrap()
    }
}

/// A JSON array of numbers.
pub fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// A JSON array of integers.
pub fn integers(v: &serde_json::Value) -> Vec<i64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect()
}
