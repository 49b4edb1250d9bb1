//! The terrain integration tests as one test binary (`cargo test -p texmap-terrain --test suite`;
//! one file's tests: `--test suite crack::`). One binary links texmap-terrain and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

mod common;
// The fuzz campaign's harness is md-io's, shared by path.
#[path = "../../md-io/tests/support/alloc.rs"]
mod alloc;
#[allow(dead_code)] // md-io's campaign uses the rest
#[path = "../../md-io/tests/support/campaign.rs"]
mod campaign;

// The counting allocator serves every module: its counters are per thread, so a test that
// measures sees only its own allocations.
#[global_allocator]
static ALLOC: alloc::CountingAlloc = alloc::CountingAlloc;

#[path = "contour_lines.rs"]
mod contour_lines;
#[path = "crack.rs"]
mod crack;
#[path = "db.rs"]
mod db;
#[path = "dem.rs"]
mod dem;
#[path = "dem_formats.rs"]
mod dem_formats;
#[path = "dem_products.rs"]
mod dem_products;
#[path = "fuji.rs"]
mod fuji;
#[path = "fuzz_campaign.rs"]
mod fuzz_campaign;
#[path = "geodesy.rs"]
mod geodesy;
#[path = "geoid.rs"]
mod geoid;
#[path = "models.rs"]
mod models;
#[path = "mosaic.rs"]
mod mosaic;
#[path = "paged.rs"]
mod paged;
#[path = "photo.rs"]
mod photo;
#[path = "qmesh.rs"]
mod qmesh;
#[path = "reproject.rs"]
mod reproject;
#[path = "rtin.rs"]
mod rtin;
#[path = "shapefile.rs"]
mod shapefile;
#[path = "srtm.rs"]
mod srtm;
#[path = "stream.rs"]
mod stream;
#[path = "tiles3d.rs"]
mod tiles3d;
#[path = "track.rs"]
mod track;
#[path = "vector.rs"]
mod vector;
#[path = "view.rs"]
mod view;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}
