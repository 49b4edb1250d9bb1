//! The md-scene integration tests as one test binary (`cargo test -p texmap-md-scene --test suite`;
//! one file's tests: `--test suite align::`). One binary links texmap-md-scene and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

mod common;

#[path = "align.rs"]
mod align;
#[path = "analysis.rs"]
mod analysis;
#[path = "bond_orders.rs"]
mod bond_orders;
#[path = "cartoon.rs"]
mod cartoon;
#[path = "colormap.rs"]
mod colormap;
#[path = "ellipsoids.rs"]
mod ellipsoids;
#[path = "hbonds.rs"]
mod hbonds;
#[path = "isosurface.rs"]
mod isosurface;
#[path = "reps.rs"]
mod reps;
#[path = "structure.rs"]
mod structure;
#[path = "surface.rs"]
mod surface;
#[path = "trails.rs"]
mod trails;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}
