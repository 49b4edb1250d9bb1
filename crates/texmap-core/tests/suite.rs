//! The texmap-core integration tests as one test binary (`cargo test -p texmap-core --test suite`;
//! one file's tests: `--test suite accuracy::`). One binary links texmap-core and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

#[path = "accuracy.rs"]
mod accuracy;
#[path = "coverage.rs"]
mod coverage;
#[path = "mip.rs"]
mod mip;
#[path = "sample.rs"]
mod sample;
#[path = "span_banks.rs"]
mod span_banks;
#[path = "transform.rs"]
mod transform;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}
