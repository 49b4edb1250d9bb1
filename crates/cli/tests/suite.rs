//! The cli integration tests as one test binary (`cargo test -p texmap-cli --test suite`;
//! one file's tests: `--test suite camera_paths::`). One binary links texmap-cli and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

mod common;

#[path = "camera_paths.rs"]
mod camera_paths;
#[path = "cli.rs"]
mod cli;
#[path = "convert.rs"]
mod convert;
#[path = "damaged.rs"]
mod damaged;
#[path = "envmap.rs"]
mod envmap;
#[path = "md_inputs.rs"]
mod md_inputs;
#[path = "movies.rs"]
mod movies;
#[path = "plot_energy.rs"]
mod plot_energy;
#[path = "quality_flags.rs"]
mod quality_flags;
#[path = "shards.rs"]
mod shards;
#[path = "slurm.rs"]
mod slurm;
#[path = "terrain.rs"]
mod terrain;
#[path = "terrain_formats.rs"]
mod terrain_formats;
#[path = "volumes.rs"]
mod volumes;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}
