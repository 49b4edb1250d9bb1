//! The reftrace integration tests as one test binary (`cargo test -p texmap-reftrace --test suite`;
//! one file's tests: `--test suite effects::`). One binary links texmap-reftrace and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

#[path = "effects.rs"]
mod effects;
#[path = "reference.rs"]
mod reference;
#[path = "smooth.rs"]
mod smooth;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}
