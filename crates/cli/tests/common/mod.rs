//! Shared by the command-line tests: running the `texmap` binary Cargo built for them.

use std::process::{Command, Output};

/// Run `texmap` with `args` and collect its exit status, stdout and stderr.
pub fn texmap(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_texmap"))
        .args(args)
        .output()
        .expect("the texmap binary runs")
}

/// The Khronos glTF-Validator's report on each of `files` (`tests/gltf_validate.cjs`: one JSON
/// object per file with its error and warning counts), or `None` (and a SKIPPED line) without
/// node or the validator (`.ci/run` installs it under target/gltf-validator;
/// `TEXMAP_GLTF_VALIDATOR` names another directory).
#[allow(dead_code)] // not every test binary validates glTF
pub fn gltf_validator_reports(files: &[std::path::PathBuf]) -> Option<Vec<serde_json::Value>> {
    use std::path::{Path, PathBuf};
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let validator = std::env::var_os("TEXMAP_GLTF_VALIDATOR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target/gltf-validator"));
    let node_ok = Command::new("node")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !node_ok || !validator.join("node_modules/gltf-validator").is_dir() {
        eprintln!(
            "SKIPPED the glTF-Validator check: node or {} is missing (npm install --prefix {} gltf-validator)",
            validator.join("node_modules/gltf-validator").display(),
            validator.display()
        );
        return None;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf_validate.cjs");
    let o = Command::new("node")
        .arg(&script)
        .arg(&validator)
        .args(files)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    Some(
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect(),
    )
}

/// The vertex positions (`v x y z` lines) of an OBJ file.
#[allow(dead_code)] // not every test binary reads OBJ files
pub fn obj_vertices(path: &std::path::Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let mut it = l.split_whitespace().map(|x| x.parse::<f64>().unwrap());
            std::array::from_fn(|_| it.next().unwrap())
        })
        .collect()
}

/// The point lists of an SVG chart's polylines (`texmap plot`'s series, axes and grid).
#[allow(dead_code)] // not every test binary draws charts
pub fn svg_polylines(svg: &str) -> Vec<Vec<(f64, f64)>> {
    svg.split("<polyline")
        .skip(1)
        .map(|p| {
            let points = p
                .split("points=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            points
                .split_whitespace()
                .map(|xy| {
                    let (x, y) = xy.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect()
}
