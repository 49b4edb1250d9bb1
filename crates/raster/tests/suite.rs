//! The raster integration tests as one test binary (`cargo test -p texmap-raster --test suite`;
//! one file's tests: `--test suite coverage::`). One binary links texmap-raster and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

#[path = "coverage.rs"]
mod coverage;
#[path = "shading.rs"]
mod shading;
#[path = "surface.rs"]
mod surface;

/// Every `.rs` file in tests/ is a module of this binary (with `autotests = false`, Cargo would
/// otherwise leave a new file unbuilt and its tests silently unrun).
#[test]
fn listed() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let suite = include_str!("suite.rs");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if let Some(module) = name.strip_suffix(".rs")
            && module != "suite"
        {
            assert!(
                suite.contains(&format!("#[path = \"{name}\"]\nmod {module};")),
                "tests/{name} is not a module of tests/suite.rs: add it there"
            );
        }
    }
}
