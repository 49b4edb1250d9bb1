//! The envmap integration tests as one test binary (`cargo test -p texmap-envmap --test suite`;
//! one file's tests: `--test suite behaviour::`). One binary links texmap-envmap and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

#[path = "bake.rs"]
mod bake;
#[path = "behaviour.rs"]
mod behaviour;
#[path = "time_slicing.rs"]
mod time_slicing;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}
