//! `texmap plot` on a GROMACS 2022.5 energy file and a LAMMPS log (md-io's fixtures,
//! crates/md-io/tests/data/energy/gen_energy.py): terms picked by name are drawn, a point per
//! frame or thermo row, with their units in the labels; a name the file lacks, or none for an
//! .edr file, is refused with the file's terms listed and nothing written.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use common::texmap;

fn energy_data(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data/energy")
        .join(name);
    p.to_str().unwrap().to_string()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn run_ok(args: &[&str]) -> Output {
    let o = texmap(args);
    assert!(o.status.success(), "texmap {args:?}: {}", stderr(&o));
    o
}

/// The point lists of the SVG chart `svg`'s polylines.
fn polylines(svg: &Path) -> Vec<Vec<(f64, f64)>> {
    common::svg_polylines(&std::fs::read_to_string(svg).unwrap())
}

fn png_size(p: &PathBuf) -> (u32, u32) {
    image::open(p).unwrap().to_rgb8().dimensions()
}

#[test]
fn plot_draws_edr_terms_and_lammps_thermo() {
    let dir = tempfile::tempdir().unwrap();
    let (edr, log) = (energy_data("water.edr"), energy_data("melt.log.lammps"));
    // Two terms as PNG, the way the command is documented.
    let png = dir.path().join("t.png");
    run_ok(&[
        "plot",
        &edr,
        "--y",
        "Temperature,Pressure",
        "-o",
        png.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(png_size(&png), (960, 640));
    // One term as SVG: a point per energy frame (11), left to right; the labels carry the
    // units the file gives; gmx energy's menu spelling (spaces as '-') names a term too.
    let svg = dir.path().join("t.svg");
    for term in ["Temperature", "Kinetic-En."] {
        run_ok(&["plot", &edr, "--y", term, "-o", svg.to_str().unwrap(), "-q"]);
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("Time (ps)"), "{term}: no x label");
        let label = if term == "Temperature" {
            "Temperature (K)"
        } else {
            "Kinetic En. (kJ/mol)"
        };
        assert!(text.contains(label), "{term}: no '{label}'");
        let lines = polylines(&svg);
        let data = lines
            .iter()
            .find(|l| l.len() == 11)
            .expect("a point per frame");
        assert!(data.windows(2).all(|w| w[1].0 > w[0].0));
    }
    // The LAMMPS log, told by its first line: Temp over every run (6 + 4 + 6 + 4 rows) against
    // the step.
    let png = dir.path().join("l.png");
    run_ok(&[
        "plot",
        &log,
        "--y",
        "Temp,PotEng",
        "-o",
        png.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(png_size(&png), (960, 640));
    let svg = dir.path().join("l.svg");
    run_ok(&[
        "plot",
        &log,
        "--y",
        "Temp",
        "-o",
        svg.to_str().unwrap(),
        "-q",
    ]);
    assert!(polylines(&svg).iter().any(|l| l.len() == 20));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.lines().any(|l| l.trim() == "Step"),
        "no x label 'Step'"
    );
    // A log cut inside a row: the complete rows drawn, the cut one named in a warning.
    let cut = dir.path().join("cut.log");
    let bytes = std::fs::read(&log).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    let at = text.find("     120    1.6680662").unwrap() + 12;
    std::fs::write(&cut, &bytes[..at]).unwrap();
    let o = run_ok(&[
        "plot",
        cut.to_str().unwrap(),
        "--y",
        "Temp",
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(stderr(&o).contains("1 row(s) cut short"), "{}", stderr(&o));
    assert!(polylines(&svg).iter().any(|l| l.len() == 13));
}

#[test]
fn plot_refuses_unknown_terms_listing_the_files_terms() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let (edr, log) = (energy_data("water.edr"), energy_data("melt.log.lammps"));
    for (file, args, code, said) in [
        (
            &edr,
            vec!["--y", "Temprature"],
            2,
            vec![
                "no column 'Temprature'",
                "Temperature",
                "Pres-ZZ",
                "LJ (SR)",
            ],
        ),
        (&edr, vec![], 2, vec!["--y", "Temperature", "Lamb-System"]),
        (
            &log,
            vec!["--y", "PE"],
            2,
            vec!["no column 'PE'", "PotEng", "E_pair", "Step"],
        ),
    ] {
        let mut all = vec!["plot", file.as_str()];
        all.extend(args);
        all.extend(["-o", out.to_str().unwrap()]);
        let o = texmap(&all);
        assert_eq!(o.status.code(), Some(code), "{all:?}: {}", stderr(&o));
        for s in said {
            assert!(
                stderr(&o).contains(s),
                "{all:?}: no '{s}' in {}",
                stderr(&o)
            );
        }
        assert!(!out.exists());
    }
    // A damaged energy file: an error with its place, nothing written.
    let bad = dir.path().join("bad.edr");
    let mut bytes = std::fs::read(&edr).unwrap();
    let n = bytes.len();
    bytes.truncate(n - 30);
    std::fs::write(&bad, &bytes).unwrap();
    let o = texmap(&[
        "plot",
        bad.to_str().unwrap(),
        "--y",
        "Temperature",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("frame 10, byte"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `texmap info` lists an energy file's terms with their units (pyedr's) and each term's mean
/// over the frames, and a log's thermo keywords over its runs.
#[test]
fn info_lists_the_terms_and_their_means() {
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(energy_data("edr_reference.json")).unwrap())
            .unwrap();
    let want = &r["water"];
    let o = run_ok(&["info", &energy_data("water.edr")]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "edr");
    let names: Vec<&str> = want["names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .filter(|n| *n != "Time")
        .collect();
    let terms = v["terms"].as_array().unwrap();
    assert_eq!(terms.len(), names.len());
    let times = want["values"]["Time"].as_array().unwrap();
    assert_eq!(v["rows"].as_u64().unwrap() as usize, times.len());
    assert_eq!(v["time_ps"][0], times[0]);
    for (t, name) in terms.iter().zip(&names) {
        assert_eq!(t["name"], *name);
        assert_eq!(t["unit"], want["units"][name]);
        let values: Vec<f64> = want["values"][name]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let got = t["mean"].as_f64().unwrap();
        assert!(
            (got - mean).abs() <= 1e-9 * mean.abs().max(1.0),
            "{name}: {got} against {mean}"
        );
    }
    let o = run_ok(&["info", &energy_data("melt.log.lammps")]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "lammps-log");
    assert_eq!(v["runs"], 4);
    assert!(
        v["terms"]
            .as_array()
            .unwrap()
            .iter()
            .any(|t| t["name"] == "Temp")
    );
}
