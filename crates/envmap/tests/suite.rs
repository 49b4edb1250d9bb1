//! The envmap integration tests as one test binary (`cargo test -p texmap-envmap --test suite`;
//! one file's tests: `--test suite behaviour::`). One binary links texmap-envmap and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

#[path = "behaviour.rs"]
mod behaviour;
#[path = "time_slicing.rs"]
mod time_slicing;

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
