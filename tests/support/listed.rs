//! The check every crate's `tests/suite.rs` runs as its `listed` test: each crate builds its
//! integration tests as one binary with `autotests = false`, so Cargo would leave a new file in
//! `tests/` unbuilt and its tests silently unrun. Included by path from each suite.

use std::path::Path;

/// Every `.rs` file in `<manifest_dir>/tests` but `suite.rs` is a module of the suite, whose text
/// is `suite`, declared as `#[path = "<file>"]` then `mod <name>;`.
pub fn every_file_is_a_module(manifest_dir: &str, suite: &str) {
    let dir = Path::new(manifest_dir).join("tests");
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
