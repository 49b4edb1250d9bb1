//! The impostor integration tests as one test binary (`cargo test -p texmap-impostor --test suite`;
//! one file's tests: `--test suite bonds::`). One binary links texmap-impostor and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

mod common;

#[path = "bonds.rs"]
mod bonds;
#[path = "polygon.rs"]
mod polygon;
#[path = "raycast.rs"]
mod raycast;
#[path = "sprites.rs"]
mod sprites;
#[path = "vs_reftrace.rs"]
mod vs_reftrace;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}
