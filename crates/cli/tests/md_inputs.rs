//! End-to-end tests of `texmap` on MD inputs written by other programs (MDAnalysis 2.11.0, scipy:
//! md-io's tests/data/gen_topology.py): a topology beside a coordinate-only trajectory, AMBER
//! NetCDF, bonds, selections, periodic boundaries, and the small defects of the issue.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use common::texmap;

fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

/// md-io's fixture directory `dir` (tests/data/<dir>: files OVITO wrote and its values).
fn ovito_data(dir: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data")
        .join(dir)
}

/// Runs `texmap render ARGS -q -o DIR/OUT`, which must succeed, and returns the PNG's bytes.
fn render_png(dir: &Path, args: &[&str], out: &str) -> Vec<u8> {
    let out = dir.join(out);
    let mut all = vec!["render", "-q"];
    all.extend_from_slice(args);
    all.extend(["-o", out.to_str().unwrap()]);
    let o = texmap(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::read(out).unwrap()
}

/// A JSON file of reference values.
fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn reference() -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(data("topology_reference.json")).unwrap())
        .unwrap()
}

#[test]
fn info_with_a_topology_counts_what_mdanalysis_counts() {
    let r = reference();
    for (traj, topo, key) in [
        ("topo_mda.xtc", "topo_mda.pdb", "pdb"),
        ("topo_mda.dcd", "topo_mda.gro", "gro"),
        ("amber_mda.ncdf", "topo_mda.data", "data"),
    ] {
        let o = texmap(&["info", &data(traj), "--topology", &data(topo)]);
        assert!(o.status.success(), "{traj}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["atoms"], r[key]["n_atoms"]);
        assert_eq!(v["frames"], 4);
        assert_eq!(v["topology"]["atoms"], r[key]["n_atoms"]);
        assert_eq!(
            v["topology"]["bonds"].as_u64().unwrap() as usize,
            r[key]["bonds"].as_array().unwrap().len()
        );
    }
}

#[test]
fn a_count_mismatch_names_both_files_and_exits_1() {
    let o = texmap(&[
        "info",
        &data("topo_mda.xtc"),
        "--topology",
        &data("select_mda.pdb"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("topo_mda.xtc") && e.contains("select_mda.pdb"),
        "{e}"
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.png");
    let o = texmap(&[
        "render",
        &data("topo_mda.xtc"),
        "--topology",
        &data("select_mda.pdb"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("select_mda.pdb"));
    assert!(!out.exists());
}

#[test]
fn small_defects_of_the_issue() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.png");
    let o = out.to_str().unwrap();
    // An empty frame range is an error (exit 2), not "wrote 0 frames".
    let r = texmap(&["render", &data("topo_mda.xtc"), "--frames", "3:1", "-o", o]);
    assert_eq!(r.status.code(), Some(2), "{}", stderr(&r));
    assert!(stderr(&r).contains("not after start"), "{}", stderr(&r));
    // A directory is said once.
    let r = texmap(&["info", dir.path().to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1));
    let e = stderr(&r);
    assert_eq!(e.matches("directory").count(), 1, "{e}");
    // A trajectory without names says so once; with a topology it does not.
    let r = texmap(&[
        "render",
        &data("topo_mda.xtc"),
        "--frames",
        "0:2",
        "--size",
        "64x48",
        "-o",
        o,
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert_eq!(
        stderr(&r).matches("--topology").count(),
        1,
        "{}",
        stderr(&r)
    );
    let r = texmap(&[
        "render",
        &data("topo_mda.xtc"),
        "--topology",
        &data("topo_mda.gro"),
        "--frames",
        "0",
        "--size",
        "64x48",
        "-o",
        o,
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(!stderr(&r).contains("no atom names"), "{}", stderr(&r));
    // A bad selection points at the column.
    let r = texmap(&[
        "render",
        &data("topo_mda.xtc"),
        "--topology",
        &data("topo_mda.pdb"),
        "--select",
        "resname SOL and (",
        "-o",
        o,
    ]);
    assert_eq!(r.status.code(), Some(2));
    assert!(stderr(&r).contains("column 18"), "{}", stderr(&r));
}

fn mean_abs_diff(a: &Path, b: &Path) -> f64 {
    let a = image::open(a).unwrap().to_rgb8();
    let b = image::open(b).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), b.dimensions());
    let s: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| (*x as i32 - *y as i32).unsigned_abs() as u64)
        .sum();
    s as f64 / a.as_raw().len() as f64
}

fn lit(p: &Path) -> usize {
    let a = image::open(p).unwrap().to_rgb8();
    a.pixels().filter(|p| p.0.iter().any(|c| *c > 0)).count()
}

#[test]
fn ball_and_stick_of_a_selection_matches_the_reference_ray_tracer() {
    let dir = tempfile::tempdir().unwrap();
    let run = |method: &str, extra: &[&str]| -> PathBuf {
        let out = dir
            .path()
            .join(format!("{method}-{}.png", extra.join("_").replace(' ', "")));
        let mut args = vec![
            "render",
            "--frames",
            "1",
            "--size",
            "160x120",
            "--method",
            method,
            "--topology",
        ];
        let (traj, topo) = (data("amber_mda.ncdf"), data("topo_mda.pdb"));
        args.push(&topo);
        args.push(&traj);
        args.extend_from_slice(extra);
        let o = out.to_str().unwrap().to_string();
        args.extend_from_slice(&["-o", &o]);
        let r = texmap(&args);
        assert!(r.status.success(), "{}", stderr(&r));
        out
    };
    let bs = [
        "--style",
        "ball-stick",
        "--select",
        "not resname SOL",
        "--pbc",
        "unwrap",
    ];
    let ours = run("raycast", &bs);
    let reference = run("reference", &bs);
    let d = mean_abs_diff(&ours, &reference);
    assert!(d < 2.0, "mean |raycast - reference| = {d} per channel");
    // Something is drawn (atoms at 0.3 of their radii and thin sticks: a few hundred pixels).
    assert!(lit(&ours) > 100, "{}", lit(&ours));
    // The same atoms at the same size without bonds (spacefill) light fewer pixels.
    let spacefill = run(
        "raycast",
        &[
            "--select",
            "not resname SOL",
            "--pbc",
            "unwrap",
            "--radius-scale",
            "0.3",
        ],
    );
    assert!(
        lit(&ours) > lit(&spacefill) + 20,
        "sticks add pixels: {} vs {}",
        lit(&ours),
        lit(&spacefill)
    );
}

#[test]
fn per_selection_colour_wins() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.png");
    let r = texmap(&[
        "render",
        &data("topo_mda.gro"),
        "--color",
        "all=#00ff00",
        "--color",
        "resname SOL=0,0,255",
        "--select",
        "resname SOL",
        "--size",
        "96x72",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
    let img = image::open(&out).unwrap().to_rgb8();
    // Only water drawn, all of it blue: no lit pixel is red- or green-dominant.
    let mut blue = 0;
    for p in img.pixels() {
        let [r, g, b] = p.0;
        if r.max(g).max(b) > 20 {
            assert!(b >= r && b >= g, "{:?}", p.0);
            blue += 1;
        }
    }
    assert!(blue > 50);
}

#[test]
fn mmcif_alternate_locations_are_a_plain_warning() {
    // 3JQH (wwPDB, from Biopython's tests): gemmi keeps 206 of its 238 atom rows, dropping the
    // second conformations (md-io's tests/data/mmcif_reference.json).
    let o = texmap(&["info", &data("3jqh.cif")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["atoms"], 206);
    let err = stderr(&o);
    assert!(
        err.contains("32 rows of other alternate locations") && !err.contains("--allow-truncated"),
        "{err}"
    );
}

#[test]
fn gzip_inputs_read_like_the_plain_files() {
    // GNU gzip copies (md-io's tests/data/gzip.sh): a PDB as trajectory, a PSF as topology.
    let o = texmap(&[
        "info",
        &data("topo_mda.pdb.gz"),
        "--topology",
        &data("psf_parmed.psf.gz"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let r = reference();
    assert_eq!(j["format"], "pdb");
    assert_eq!(j["atoms"], r["pdb"]["n_atoms"]);
    assert_eq!(j["topology"]["atoms"], r["pdb"]["n_atoms"]);
    // A cut copy is an error naming the file and gzip, exit status 1.
    let dir = tempfile::tempdir().unwrap();
    let gz = std::fs::read(data("topo_mda.pdb.gz")).unwrap();
    let cut = dir.path().join("cut.pdb.gz");
    std::fs::write(&cut, &gz[..gz.len() - 8]).unwrap();
    let o = texmap(&["info", cut.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("cut.pdb.gz") && e.contains("gzip"), "{e}");
}

#[test]
fn info_lists_chains_and_colour_by_chain_draws_the_palette_colour() {
    // chains_mda.pdb: MDAnalysis wrote chain and segment identifiers (gen_chains.py).
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("chains_reference.json")).unwrap())
            .unwrap();
    let o = texmap(&["info", &data("chains_mda.pdb")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for (key, column) in [("chains", "chains"), ("segments", "segments")] {
        let labels: Vec<&str> = r[column]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        let listed = j[key].as_array().unwrap();
        let total: u64 = listed.iter().map(|e| e[1].as_u64().unwrap()).sum();
        assert_eq!(total as usize, labels.len(), "{key}");
        for e in listed {
            let (name, n) = (e[0].as_str().unwrap(), e[1].as_u64().unwrap() as usize);
            assert_eq!(
                labels.iter().filter(|l| **l == name).count(),
                n,
                "{key} {name}"
            );
        }
    }
    assert_eq!(j["chains"][0][0], "A");
    // Chain A drawn by chain takes the palette's first colour: the same image as colouring it
    // with that colour by a rule.
    let dir = tempfile::tempdir().unwrap();
    let c = texmap_md_scene::type_color(0).map(|v| (v * 255.0).round() as u8);
    let rule = format!("all={},{},{}", c[0], c[1], c[2]);
    let draw = |name: &str, extra: &[&str]| -> PathBuf {
        let out = dir.path().join(name);
        let file = data("chains_mda.pdb");
        let mut args = vec!["render", &file, "--select", "chain A", "--size", "96x72"];
        args.extend_from_slice(extra);
        let o = out.to_str().unwrap().to_string();
        args.extend_from_slice(&["-o", &o]);
        let run = texmap(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        out
    };
    let by_chain = draw("chain.png", &["--color-by", "chain"]);
    let by_rule = draw("rule.png", &["--color", &rule]);
    let by_element = draw("element.png", &["--color-by", "element"]);
    assert!(lit(&by_chain) > 50);
    assert_eq!(mean_abs_diff(&by_chain, &by_rule), 0.0);
    assert!(mean_abs_diff(&by_chain, &by_element) > 1.0);
    // A file without chains or segments: element colours and a warning naming the flag.
    let out = dir.path().join("none.png");
    let o = texmap(&[
        "render",
        &data("topo_mda.gro"),
        "--color-by",
        "chain",
        "--size",
        "64x48",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("--color-by chain"), "{}", stderr(&o));
}

#[test]
fn tube_of_a_real_helix_matches_the_reference_ray_tracer() {
    // 3JQH (wwPDB): one helical chain; its CA trace as a tube, its waters as licorice.
    let dir = tempfile::tempdir().unwrap();
    let draw = |method: &str, style: &str| -> PathBuf {
        let out = dir.path().join(format!("{method}-{style}.png"));
        let file = data("3jqh.cif");
        let o = out.to_str().unwrap().to_string();
        let args = [
            "render", &file, "--style", style, "--select", "protein", "--size", "200x150",
            "--method", method, "-o", &o,
        ];
        let r = texmap(&args);
        assert!(r.status.success(), "{}", stderr(&r));
        out
    };
    let ours = draw("raycast", "tube");
    let reference = draw("reference", "tube");
    let d = mean_abs_diff(&ours, &reference);
    assert!(d < 2.0, "mean |raycast - reference| = {d} per channel");
    // A thin tube is drawn, lighting fewer pixels than the same atoms as licorice.
    let licorice = draw("raycast", "licorice");
    assert!(lit(&ours) > 300, "{}", lit(&ours));
    assert!(
        lit(&ours) < lit(&licorice),
        "{} vs {}",
        lit(&ours),
        lit(&licorice)
    );
}

/// The AMBER pair: a ParmEd prmtop labels the NetCDF trajectory of the same atoms; bonds and
/// chains as MDAnalysis reads them from the prmtop (tests/data/gen_prmtop.py).
#[test]
fn amber_prmtop_and_netcdf_render_together() {
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("prmtop_reference.json")).unwrap())
            .unwrap();
    let o = texmap(&[
        "info",
        &data("amber_mda.ncdf"),
        "--topology",
        &data("prmtop_parmed.prmtop"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let want = &r["prmtop_parmed.prmtop"];
    assert_eq!(v["topology"]["atoms"], want["n_atoms"]);
    assert_eq!(
        v["topology"]["bonds"].as_u64().unwrap() as usize,
        want["bonds"].as_array().unwrap().len()
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.png");
    let o = texmap(&[
        "render",
        &data("amber_mda.ncdf"),
        "--topology",
        &data("prmtop_parmed.prmtop"),
        "--select",
        "resname ALA",
        "--frames",
        "3",
        "--style",
        "licorice",
        "--color-by",
        "charge",
        "--colormap",
        "coolwarm",
        "--bonds",
        "topology",
        "--size",
        "96x72",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
    // A topology alone: info gives its counts (atoms, bonds and chains as MDAnalysis reads them).
    let o = texmap(&["info", &data("prmtop_chains.parm7")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let t: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let want = &r["prmtop_chains.parm7"];
    assert_eq!(t["format"], "prmtop");
    assert_eq!(t["atoms"], want["n_atoms"]);
    assert_eq!(
        t["bonds"].as_u64().unwrap() as usize,
        want["bonds"].as_array().unwrap().len()
    );
    assert_eq!(t["properties"], serde_json::json!(["charge"]));
    // RESIDUE_CHAINID's chains reach the frames: info counts them as MDAnalysis does.
    let o = texmap(&[
        "info",
        &data("chains_mda.pdb"),
        "--topology",
        &data("prmtop_chains.parm7"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let mut counts: Vec<(String, u64)> = Vec::new();
    for c in r["prmtop_chains.parm7"]["chains"].as_array().unwrap() {
        let c = c.as_str().unwrap();
        match counts.iter_mut().find(|(k, _)| k == c) {
            Some((_, n)) => *n += 1,
            None => counts.push((c.to_string(), 1)),
        }
    }
    assert_eq!(v["chains"], serde_json::json!(counts));
    assert_eq!(t["chains"], v["chains"]);
}

/// `--color-by bfactor` on the wwPDB's 3JQH: the gray map's colour bar runs from black at the
/// bottom (the smallest B-factor) to white at the top, beside an image otherwise equal to the
/// one without the bar; a property the file lacks is an error naming those it has; a reversed
/// range is a usage error.
#[test]
fn color_by_a_number_draws_its_colour_bar() {
    let dir = tempfile::tempdir().unwrap();
    let with = dir.path().join("with.png");
    let without = dir.path().join("without.png");
    let input = data_3jqh();
    for (out, extra) in [(&with, None), (&without, Some("--no-color-bar"))] {
        let mut args = vec![
            "render",
            "--quiet",
            &input,
            "--color-by",
            "bfactor",
            "--colormap",
            "gray",
            "--size",
            "320x240",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let a = image::open(&with).unwrap().to_rgba8();
    let b = image::open(&without).unwrap().to_rgba8();
    let (w, h) = a.dimensions();
    let mut differ_left = 0;
    let mut bar: Vec<(u32, u8)> = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
            if p != q && x < w * 2 / 3 {
                differ_left += 1;
            }
        }
    }
    assert_eq!(differ_left, 0, "the bar stays at the right edge");
    // The bar's gray ramp: find the column with the most distinct grays, read it top to bottom.
    let col = (w * 2 / 3..w)
        .max_by_key(|&x| {
            let mut g: Vec<u8> = (0..h)
                .map(|y| a.get_pixel(x, y).0)
                .filter(|p| p[0] == p[1] && p[1] == p[2])
                .map(|p| p[0])
                .collect();
            g.sort_unstable();
            g.dedup();
            g.len()
        })
        .unwrap();
    for y in 0..h {
        let p = a.get_pixel(col, y).0;
        if p[0] == p[1] && p[1] == p[2] {
            bar.push((y, p[0]));
        }
    }
    let top = bar.iter().filter(|(_, g)| *g > 240).map(|(y, _)| *y).min();
    let bottom = bar.iter().filter(|(_, g)| *g < 15).map(|(y, _)| *y).max();
    assert!(
        matches!((top, bottom), (Some(t), Some(b)) if t < b),
        "white above black in column {col}: {top:?} {bottom:?}"
    );
    // A property the file does not have.
    let o = texmap(&[
        "render",
        &data_3jqh(),
        "--color-by",
        "c_pe",
        "-o",
        with.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("occupancy, bfactor"), "{}", stderr(&o));
    // A reversed range.
    let o = texmap(&[
        "render",
        &data_3jqh(),
        "--color-by",
        "bfactor",
        "--color-range",
        "80:20",
        "-o",
        with.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // info lists what --color-by can name.
    let o = texmap(&["info", &data("lmp_tri.lammpstrj")]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["properties"][6], "ix", "{v}");
}

fn data_3jqh() -> String {
    data("3jqh.cif")
}

/// `helix`/`sheet` selections and `--color-by structure` end to end: each selection drawn alone
/// is VMD's colour for its class (helix purple, strand yellow) wherever an atom is lit, and
/// `info` reports MDAnalysis's assignment of the chain (md-io/tests/data/dssp/reference.json).
#[test]
fn secondary_structure_selects_and_colours() {
    let input = data("dssp/3gwiA.pdb.gz");
    let o = texmap(&["info", &input]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("dssp/reference.json")).unwrap())
            .unwrap();
    let codes = r["3gwiA.pdb.gz"]["dssp"].as_str().unwrap();
    let ss = &info["secondary_structure"];
    assert_eq!(ss["dssp"], codes);
    assert_eq!(ss["helix"], codes.matches('H').count());
    assert_eq!(ss["strand"], codes.matches('E').count());
    let dir = tempfile::tempdir().unwrap();
    // (selection, is this pixel of the class's hue? purple r = b > g, yellow r = g > b; the
    // white light's highlights desaturate but keep the hue)
    type Hue = fn([u8; 3]) -> bool;
    let cases: [(&str, Hue); 2] = [
        ("helix", |p| {
            p[0].abs_diff(p[2]) <= 10 && p[1] as u32 + 30 < p[0].min(p[2]) as u32
        }),
        ("sheet", |p| {
            p[0].abs_diff(p[1]) <= 10 && p[2] as u32 + 30 < p[0].min(p[1]) as u32
        }),
    ];
    for (sel, hue) in cases {
        let out = dir.path().join(format!("{sel}.png"));
        let o = texmap(&[
            "render",
            "--quiet",
            &input,
            "--select",
            sel,
            "--color-by",
            "structure",
            "--size",
            "320x240",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let img = image::open(&out).unwrap().to_rgb8();
        // Lit pixels: not background, not in deep shade, not a white highlight.
        let lit: Vec<[u8; 3]> = img
            .pixels()
            .map(|p| p.0)
            .filter(|p| {
                p.iter().copied().max().unwrap() > 100 && p.iter().copied().min().unwrap() < 200
            })
            .collect();
        assert!(lit.len() > 500, "{sel}: {} lit pixels", lit.len());
        let of_hue = lit.iter().filter(|p| hue(**p)).count();
        assert!(
            of_hue * 100 >= lit.len() * 95,
            "{sel}: {of_hue} of {} pixels",
            lit.len()
        );
    }
}

/// `--align backbone` holds a tumbling protein still: MDAnalysis-checked superposition
/// (md-scene/tests/align.rs) seen end to end. Without it the last frame's image shares little
/// with the first; with it the two differ only by the 0.4 Å jiggle the frames carry.
#[test]
fn align_holds_a_tumbling_protein_still() {
    let xtc = Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-scene/tests/data/align_3gwi.xtc");
    let top = data("dssp/3gwiA.pdb.gz");
    let dir = tempfile::tempdir().unwrap();
    let mut change = Vec::new();
    for align in [None, Some("backbone")] {
        let out = dir.path().join(format!("{}-%d.png", align.is_some()));
        let mut args = vec![
            "render",
            "--quiet",
            xtc.to_str().unwrap(),
            "--topology",
            &top,
            "--frames",
            "0:6:5",
            "--size",
            "200x150",
            "-o",
            out.to_str().unwrap(),
        ];
        if let Some(sel) = align {
            args.extend(["--align", sel]);
        }
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let img = |f: u32| {
            let p = dir.path().join(format!("{}-{f}.png", align.is_some()));
            image::open(p).unwrap().to_rgb8()
        };
        let (a, b) = (img(0), img(5));
        // Pixels whose coverage changed: background in one image and not in the other.
        let bg = |p: &image::Rgb<u8>| p.0 == [0, 0, 0];
        let covered = a.pixels().filter(|p| !bg(p)).count();
        let flipped = a
            .pixels()
            .zip(b.pixels())
            .filter(|(p, q)| bg(p) != bg(q))
            .count();
        change.push(flipped as f64 / covered as f64);
    }
    assert!(change[0] > 0.5, "unaligned: {change:?}");
    assert!(change[1] < 0.15, "aligned: {change:?}");
    // Fewer than three atoms is a usage error (exit 2) naming the flag.
    let o = texmap(&[
        "render",
        "--quiet",
        xtc.to_str().unwrap(),
        "--topology",
        &top,
        "--align",
        "index 0 1",
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--align"), "{}", stderr(&o));
}

/// `--label`: each frame's caption is the template with the time MDAnalysis reads from the
/// AMBER NetCDF (topology_reference.json), drawn by `draw_caption` over the image `render` makes
/// without it; nothing else changes. A bad placeholder is a usage error (exit 2); a time the file
/// lacks (PDB) a runtime error (exit 1).
#[test]
fn label_captions_each_frame_with_its_time() {
    let nc = data("amber_mda.ncdf");
    let top = data("topo_mda.pdb");
    let times: Vec<f64> = reference()["ncdf"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["time"].as_f64().unwrap())
        .collect();
    let dir = tempfile::tempdir().unwrap();
    for label in [None, Some("t = {time} ps, frame {frame}")] {
        let out = dir.path().join(format!("{}-%d.png", label.is_some()));
        let mut args = vec![
            "render",
            "--quiet",
            &nc,
            "--topology",
            &top,
            "--frames",
            "0:4",
            "--size",
            "320x240",
            "-o",
            out.to_str().unwrap(),
        ];
        if let Some(l) = label {
            args.extend(["--label", l]);
        }
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    for (f, t) in times.iter().enumerate() {
        let read = |labelled: bool| {
            image::open(dir.path().join(format!("{labelled}-{f}.png")))
                .unwrap()
                .to_rgba8()
        };
        let mut want = read(false);
        let text = format!("t = {t} ps, frame {f}");
        let (w, h) = want.dimensions();
        assert_eq!(
            texmap_md_scene::draw_caption(&mut want, w as usize, h as usize, &text),
            text.len()
        );
        assert!(read(true) == want, "frame {f}: {text}");
    }
    for (template, file, code) in [
        ("{bogus}", &nc, 2),
        ("t = {time", &nc, 2),
        ("t = {time} ps", &top, 1),
    ] {
        let out = dir.path().join("bad.png");
        let mut args = vec!["render", "--quiet", file.as_str()];
        if file == &nc {
            args.extend(["--topology", &top]);
        }
        args.extend(["--label", template, "-o", out.to_str().unwrap()]);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(code), "{template}: {}", stderr(&o));
        assert!(stderr(&o).contains("--label"), "{}", stderr(&o));
        assert!(!out.exists());
    }
}

/// `--label '{energy:.4}'`: a key of the frame's comment, here the energy our ASE trajectory
/// reader puts there, captions each frame with ASE's own `get_potential_energy()` (md-io's
/// asetraj/reference.json.gz) to 4 decimals; a key no frame has is a usage error listing the
/// keys it has, and a value that is no number with `:.N` a runtime error.
#[test]
fn label_takes_comment_keys_such_as_ase_energies() {
    let traj = data("asetraj/cu_md.traj");
    let mut gz = String::new();
    std::io::Read::read_to_string(
        &mut flate2::read::GzDecoder::new(
            std::fs::File::open(data("asetraj/reference.json.gz")).unwrap(),
        ),
        &mut gz,
    )
    .unwrap();
    let v: serde_json::Value = serde_json::from_str(&gz).unwrap();
    let energies: Vec<f64> = v["cu_md.traj"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["energy"].as_f64().unwrap())
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let render = |label: Option<&str>, name: &str| {
        let out = dir.path().join(name);
        let mut args = vec![
            "render",
            "--quiet",
            &traj,
            "--frames",
            "0:3",
            "--size",
            "240x180",
            "-o",
            out.to_str().unwrap(),
        ];
        if let Some(l) = label {
            args.extend(["--label", l]);
        }
        texmap(&args)
    };
    for (label, name) in [
        (None, "plain-%d.png"),
        (Some("E = {energy:.4} eV"), "e-%d.png"),
    ] {
        let o = render(label, name);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    for (f, e) in energies.iter().take(3).enumerate() {
        let read = |name: &str| {
            image::open(dir.path().join(format!("{name}-{f}.png")))
                .unwrap()
                .to_rgba8()
        };
        let mut want = read("plain");
        let text = format!("E = {e:.4} eV");
        let (w, h) = want.dimensions();
        texmap_md_scene::draw_caption(&mut want, w as usize, h as usize, &text);
        assert!(read("e") == want, "frame {f}: {text}");
    }
    let o = render(Some("{enrgy}"), "bad-%d.png");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("has no enrgy= in its comment (it has the keys energy"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("bad-0.png").exists());
    let o = render(Some("{stress:.2}"), "nan-%d.png");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("not a number"), "{}", stderr(&o));
}

/// `--rep SEL=STYLE`: one representation is `--select SEL --style STYLE` byte for byte; a second
/// adds its atoms (here residues 420-432 as balls and sticks over the tube); a style that does not exist, a missing '=', or --rep with --select are usage errors.
/// 3GWI chain A rendered at 320x240 down z with `extra` flags into `dir/name`.
fn render_3gwi(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let input = data("dssp/3gwiA.pdb.gz");
    let out = dir.join(name);
    let mut args = vec![
        "render", "--quiet", &input, "--size", "320x240", "--view", "z",
    ];
    args.extend(extra);
    args.extend(["-o", out.to_str().unwrap()]);
    let o = texmap(&args);
    assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    out
}

/// `texmap render --quiet ARGS -o dir/name`, which must succeed, and the image it wrote.
fn render_rgb(dir: &Path, name: &str, args: &[&str]) -> image::RgbImage {
    let out = dir.join(name);
    let mut all = vec!["render", "--quiet"];
    all.extend(args);
    all.extend(["-o", out.to_str().unwrap()]);
    let o = texmap(&all);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    image::open(&out).unwrap().to_rgb8()
}

#[test]
fn representations_combine_styles_in_one_image() {
    let input = data("dssp/3gwiA.pdb.gz");
    let dir = tempfile::tempdir().unwrap();
    let render =
        |name: &str, extra: &[&str]| std::fs::read(render_3gwi(dir.path(), name, extra)).unwrap();
    let plain = render("plain.png", &["--select", "protein", "--style", "tube"]);
    let one = render("one.png", &["--rep", "protein=tube"]);
    assert!(plain == one, "one --rep differs from --select/--style");
    let two = render(
        "two.png",
        &[
            "--rep",
            "protein=tube",
            "--rep",
            "resid 420 to 432 and not name H*=ball-stick",
        ],
    );
    assert!(two != one);
    for bad in [
        vec!["--rep", "protein=ribbons"],
        vec!["--rep", "protein"],
        vec!["--rep", "protein=tube", "--select", "protein"],
        vec!["--rep", "protein=tube", "--style", "licorice"],
    ] {
        let mut args = vec!["render", "--quiet", input.as_str()];
        args.extend(bad.iter().copied());
        let out = dir.path().join("bad.png");
        args.extend(["-o", out.to_str().unwrap()]);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
    }
}

#[test]
fn a_representation_takes_its_own_colouring() {
    let input = data("dssp/3gwiA.pdb.gz");
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, extra: &[&str]| render_3gwi(dir.path(), name, extra);
    let read = |p: &Path| std::fs::read(p).unwrap();
    // A representation's colouring is the same image as that --color-by for the whole scene.
    let own = render("own.png", &["--rep", "protein=tube:structure"]);
    let scene = render(
        "scene.png",
        &[
            "--select",
            "protein",
            "--style",
            "tube",
            "--color-by",
            "structure",
        ],
    );
    assert!(read(&own) == read(&scene));
    // A numeric --color-by that no representation uses draws no colour bar.
    let unused = render(
        "unused.png",
        &["--color-by", "bfactor", "--rep", "protein=tube:element"],
    );
    let element = render(
        "element.png",
        &[
            "--color-by",
            "element",
            "--select",
            "protein",
            "--style",
            "tube",
        ],
    );
    assert!(read(&unused) == read(&element));
    let used = render(
        "used.png",
        &[
            "--color-by",
            "bfactor",
            "--rep",
            "protein=tube:element",
            "--rep",
            "resid 420 to 432=spacefill",
        ],
    );
    assert!(read(&used) != read(&unused));
    // One colour: every lit pixel of the tube is a shade of it.
    let red = render("red.png", &["--rep", "protein=tube:#ff0000"]);
    let img = image::open(&red).unwrap().to_rgb8();
    let lit: Vec<_> = img.pixels().filter(|p| p.0 != [0, 0, 0]).collect();
    assert!(lit.len() > 1000);
    let reddish = lit
        .iter()
        .filter(|p| p.0[0] as u32 > 2 * p.0[1] as u32 + 10 && p.0[1].abs_diff(p.0[2]) < 8)
        .count();
    assert!(
        reddish * 100 >= lit.len() * 95,
        "{reddish} of {}",
        lit.len()
    );
    for bad in ["protein=tube:bfactor", "protein=tube:#12", "protein=tube:"] {
        let out = dir.path().join("bad.png");
        let o = texmap(&[
            "render",
            "--quiet",
            &input,
            "--rep",
            bad,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(!out.exists());
    }
}

/// `--align-to`: frame 5 of the tumbling trajectory fitted (by mass) onto a moved copy of the
/// structure is drawn where and as that structure is; a structure of other atoms is an input
/// error (exit 1) naming the flag; `--align-to` without `--align` a usage error (exit 2).
#[test]
fn align_to_a_reference_structure_draws_the_frames_as_it_sits() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-scene/tests/data");
    let xtc = here.join("align_3gwi.xtc");
    let target = here.join("align_target.pdb.gz");
    let top = data("dssp/3gwiA.pdb.gz");
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, input: &Path, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            "render",
            "--quiet",
            input.to_str().unwrap(),
            "--size",
            "200x150",
            "--view",
            "z",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = texmap(&args);
        (o, out)
    };
    let (o, reference) = render("target.png", &target, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let flipped = |p: &Path| {
        let (a, b) = (
            image::open(&reference).unwrap().to_rgb8(),
            image::open(p).unwrap().to_rgb8(),
        );
        let bg = |p: &image::Rgb<u8>| p.0 == [0, 0, 0];
        let covered = a.pixels().filter(|p| !bg(p)).count();
        let n = a
            .pixels()
            .zip(b.pixels())
            .filter(|(p, q)| bg(p) != bg(q))
            .count();
        n as f64 / covered as f64
    };
    let frame5 = ["--topology", &top, "--frames", "5:6"];
    let (o, as_read) = render("as_read.png", &xtc, &frame5);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut args = frame5.to_vec();
    let target_arg = target.to_str().unwrap();
    args.extend([
        "--align",
        "backbone",
        "--align-to",
        target_arg,
        "--align-mass",
    ]);
    let (o, fitted) = render("fitted.png", &xtc, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let (before, after) = (flipped(&as_read), flipped(&fitted));
    assert!(before > 0.2, "as read: {before} (fitted: {after})");
    assert!(after < 0.1, "fitted: {after}");
    // Another chain's structure: the picked atoms differ in number.
    let other = data("dssp/1eteA.pdb.gz");
    let mut args = frame5.to_vec();
    args.extend(["--align", "backbone", "--align-to", &other]);
    let (o, out) = render("other.png", &xtc, &args);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--align-to"), "{}", stderr(&o));
    assert!(!out.exists());
    let (o, _) = render("usage.png", &xtc, &["--align-to", target_arg]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// `--smooth`: a structure jiggled by seeded noise in every frame (an XYZ trajectory written by
/// md-io) flickers less from frame to frame when smoothed; the first frame, an end of the
/// window, is drawn as read, byte for byte.
#[test]
fn smoothing_takes_the_jitter_out_of_a_movie() {
    use texmap_md_io::{Format, Frame, Trajectory, Writer};
    let dir = tempfile::tempdir().unwrap();
    let mut t = Trajectory::open(data("dssp/3gwiA.pdb.gz")).unwrap();
    let mut base = Frame::new();
    assert!(t.read_next(&mut base).unwrap());
    let xyz = dir.path().join("jiggle.xyz");
    let mut w = Writer::create(&xyz, Format::Xyz).unwrap();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f32 / (1u64 << 53) as f32 - 0.5
    };
    let n = 12;
    for _ in 0..n {
        let mut f = base.clone();
        for p in &mut f.positions {
            *p = p.map(|x| x + 1.2 * noise());
        }
        w.write_frame(&f).unwrap();
    }
    w.finish().unwrap();
    let render = |tag: &str, smooth: &str| {
        let out = dir.path().join(format!("{tag}-%02d.png"));
        let o = texmap(&[
            "render",
            "--quiet",
            xyz.to_str().unwrap(),
            "--size",
            "200x150",
            "--smooth",
            smooth,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        (0..n)
            .map(|f| dir.path().join(format!("{tag}-{f:02}.png")))
            .collect::<Vec<_>>()
    };
    let raw = render("raw", "0");
    let smooth = render("smooth", "3");
    assert!(std::fs::read(&raw[0]).unwrap() == std::fs::read(&smooth[0]).unwrap());
    // Mean absolute change between consecutive interior frames.
    let flicker = |frames: &[PathBuf]| {
        (3..n - 4)
            .map(|f| mean_abs_diff(&frames[f], &frames[f + 1]))
            .sum::<f64>()
            / (n - 7) as f64
    };
    let (before, after) = (flicker(&raw), flicker(&smooth));
    assert!(after < 0.5 * before, "flicker {before} -> {after}");
    let o = texmap(&[
        "render",
        "--quiet",
        xyz.to_str().unwrap(),
        "--smooth",
        "-1",
        "-o",
        dir.path().join("bad.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// `--color-by cna` and the `cna` keyword on an FCC crystal with a stacking fault and free
/// surfaces (md-io's cna fixture, types checked against OVITO there): the whole crystal is
/// mostly OVITO's FCC green; with `--select 'not cna fcc'` no green is left, and both the
/// fault's HCP red and the surfaces' white are drawn.
#[test]
fn cna_colours_and_hides_the_perfect_crystal() {
    let input = data("cna/crystals.xyz.gz");
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, extra: &[&str]| {
        let mut args = vec![
            &input[..],
            "--frames",
            "3:4",
            "--size",
            "240x180",
            "--view",
            "x",
            "--color-by",
            "cna",
        ];
        args.extend(extra);
        render_rgb(dir.path(), name, &args)
    };
    // (green, red, white) shares of the lit pixels.
    let hues = |img: &image::RgbImage| {
        let lit: Vec<[i32; 3]> = img
            .pixels()
            .filter(|p| p.0 != [0, 0, 0])
            .map(|p| p.0.map(i32::from))
            .collect();
        let share = |f: &dyn Fn(&[i32; 3]) -> bool| {
            lit.iter().filter(|p| f(p)).count() as f64 / lit.len() as f64
        };
        (
            share(&|p| p[1] > p[0] + 30 && p[1] > p[2] + 30),
            share(&|p| p[0] > p[1] + 30 && p[0] > p[2] + 30),
            share(&|p| p[0].abs_diff(p[1]) < 12 && p[1].abs_diff(p[2]) < 12 && p[0] > 60),
        )
    };
    let all = hues(&render("all.png", &[]));
    assert!(all.0 > 0.4, "whole crystal (green, red, white): {all:?}");
    let defects = hues(&render("defects.png", &["--select", "not cna fcc"]));
    assert!(
        defects.0 < 0.01,
        "defects only (green, red, white): {defects:?}"
    );
    assert!(defects.1 > 0.1 && defects.2 > 0.1, "{defects:?}");
}

/// `--replicate` against OVITO's Replicate modifier end to end: 60 waters in a triclinic cell
/// with bonds across its faces (md-io's replicate fixture, written by OVITO 3.17.2), drawn
/// with `--replicate 2,2,1`, look like OVITO's own 2 x 2 x 1 copy of them drawn as read
/// (positions differ only in their last digit: no channel moves by more than 2); drawn alone
/// they do not. A frame without a cell is an error naming the flag and the frame, and a count
/// of 0 a usage error.
#[test]
fn replicate_draws_what_ovitos_replicate_modifier_makes() {
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, input: &str, topology: &str, extra: &[&str]| {
        let (input, topology) = (data(input), data(topology));
        let mut args = vec![
            &input[..],
            "--topology",
            &topology,
            "--style",
            "ball-stick",
            "--size",
            "320x240",
        ];
        args.extend(extra);
        render_rgb(dir.path(), name, &args)
    };
    let ours = render(
        "ours.png",
        "replicate/water.lammpstrj",
        "replicate/water.data",
        &["--replicate", "2,2,1"],
    );
    let ovito = render(
        "ovito.png",
        "replicate/water_2x2x1.lammpstrj.gz",
        "replicate/water_2x2x1.data.gz",
        &[],
    );
    let alone = render(
        "alone.png",
        "replicate/water.lammpstrj",
        "replicate/water.data",
        &[],
    );
    let worst = |a: &image::RgbImage, b: &image::RgbImage| {
        let (mut max, mut differ) = (0u8, 0usize);
        for (p, q) in a.pixels().zip(b.pixels()) {
            let d = (0..3).map(|k| p.0[k].abs_diff(q.0[k])).max().unwrap();
            max = max.max(d);
            differ += usize::from(d > 0);
        }
        (max, differ)
    };
    let (max, differ) = worst(&ours, &ovito);
    assert!(max <= 2 && differ < 320 * 240 / 100, "{max} {differ}");
    let (max, differ) = worst(&alone, &ovito);
    assert!(max > 100 && differ > 320 * 240 / 20, "{max} {differ}");

    let input = data("cna/crystals.xyz.gz");
    let out = dir.path().join("x.png");
    let o = texmap(&[
        "render",
        "--quiet",
        &input,
        "--frames",
        "4:5",
        "--replicate",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("--replicate") && e.contains("frame 4") && e.contains("no periodic cell"),
        "{e}"
    );
    assert!(!out.exists());
    let o = texmap(&[
        "render",
        &input,
        "--replicate",
        "2,0,1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// `--atom-label` puts each label where its atom projects: with the camera aimed at CA 420 of
/// 3GWI, the only pixels the label changes are its backdrop, centred on the image's centre
/// column and ending 2 px above its centre row, exactly as wide as six 6-px glyph cells (less
/// the last spacing column) plus a pixel of padding per side. The placeholders give the
/// residue's own name and number (byte-identical to the text typed out), a label needing a
/// column the file lacks is an error naming it, and a bad placeholder a usage error.
#[test]
fn atom_labels_sit_over_their_atoms() {
    use texmap_md_io::{Frame, Trajectory};
    let input = data("dssp/3gwiA.pdb.gz");
    let mut t = Trajectory::open(&input).unwrap();
    let mut frame = Frame::new();
    assert!(t.read_next(&mut frame).unwrap());
    let ca = (0..frame.n_atoms())
        .find(|&i| frame.res_ids[i] == 420 && frame.names[i].as_str() == "CA")
        .unwrap();
    assert_eq!(frame.res_names[ca].as_str(), "ALA");
    let p = frame.positions[ca];
    let target = format!("{},{},{}", p[0], p[1], p[2]);
    let eye = format!("{},{},{}", p[0], p[1], p[2] + 90.0);
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, extra: &[&str]| {
        let mut args = vec![
            &input[..],
            "--style",
            "tube",
            "--size",
            "400x300",
            "--eye",
            &eye,
            "--target",
            &target,
            "--up",
            "0,1,0",
        ];
        args.extend(extra);
        render_rgb(dir.path(), name, &args)
    };
    let plain = render("plain.png", &[]);
    let labelled = render(
        "labelled.png",
        &["--atom-label", "name CA and resid 420={resname}{resid}"],
    );
    let typed = render(
        "typed.png",
        &["--atom-label", "name CA and resid 420=ALA420"],
    );
    assert_eq!(labelled.as_raw(), typed.as_raw());
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (x, y, px) in labelled.enumerate_pixels() {
        if px != plain.get_pixel(x, y) {
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
        }
    }
    // 6 * 6 - 1 + 2 = 37 wide, 8 + 2 = 10 tall, centred on x = 200, ending at y = 150 - 2.
    assert_eq!((x1 - x0, y1 - y0), (37, 10), "{x0}..{x1} x {y0}..{y1}");
    assert!((181..=183).contains(&x0), "{x0}");
    assert!((147..=149).contains(&y1), "{y1}");

    let out = dir.path().join("x.png");
    let xyz = data("ase_plain.xyz");
    let o = texmap(&[
        "render",
        "-q",
        &xyz,
        "--atom-label",
        "index 0={resname}",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no resname column"), "{}", stderr(&o));
    assert!(!out.exists());
    let o = texmap(&[
        "render",
        "-q",
        &xyz,
        "--atom-label",
        "index 0={resnam}",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("{resnam} is not a placeholder"),
        "{}",
        stderr(&o)
    );
}

/// `--coordination R` (counts checked against OVITO in md-io and md-scene): a cell narrower than
/// three cutoffs is refused with a hint, and replicating it first makes it wide enough; a
/// cutoff out of range is a usage error; colouring by coordination without counting it names
/// the flag that would.
#[test]
fn coordination_needs_a_wide_enough_cell_and_says_how() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.png");
    let (input, topology) = (
        data("replicate/water.lammpstrj"),
        data("replicate/water.data"),
    );
    let run = |extra: &[&str]| {
        let mut args = vec!["render", "-q", &input, "--topology", &topology];
        args.extend(extra);
        args.extend(["-o", out.to_str().unwrap()]);
        texmap(&args)
    };
    let o = run(&["--coordination", "6", "--color-by", "coordination"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("--coordination") && e.contains("--replicate"),
        "{e}"
    );
    assert!(!out.exists());
    let o = run(&[
        "--coordination",
        "6",
        "--replicate",
        "2",
        "--color-by",
        "coordination",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
    std::fs::remove_file(&out).unwrap();
    let o = run(&["--coordination", "0.3"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = run(&["--color-by", "coordination"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--coordination R"), "{}", stderr(&o));
}

/// Small-molecule files with their bonds (md-io's molecules fixture: checked atom for atom
/// against RDKit, Open Babel and MDAnalysis there): imatinib's conformers as RDKit's SD file and
/// as Open Babel's MOL2 draw the same licorice image from the bonds each file lists, frame by
/// frame; `texmap info` counts those bonds; a MOL2's partial charges colour by `charge`.
#[test]
fn sdf_and_mol2_draw_the_bonds_they_list() {
    let dir = tempfile::tempdir().unwrap();
    let (sdf, mol2) = (
        data("molecules/imatinib_confs.sdf"),
        data("molecules/imatinib_poses.mol2"),
    );
    for frame in ["0:1", "3:4"] {
        let args = |f: &str| {
            vec![
                f.to_string(),
                "--frames".into(),
                frame.into(),
                "--style".into(),
                "licorice".into(),
                "--bonds".into(),
                "topology".into(),
                "--size".into(),
                "320x240".into(),
            ]
        };
        let a: Vec<String> = args(&sdf);
        let b: Vec<String> = args(&mol2);
        let a = render_rgb(
            dir.path(),
            "a.png",
            &a.iter().map(String::as_str).collect::<Vec<_>>(),
        );
        let b = render_rgb(
            dir.path(),
            "b.png",
            &b.iter().map(String::as_str).collect::<Vec<_>>(),
        );
        assert_eq!(a.as_raw(), b.as_raw(), "frame {frame}");
    }
    let o = texmap(&["info", &mol2]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["bonds"], 72);
    assert_eq!(v["frames"], 5);
    assert_eq!(v["format"], "mol2");
    let img = render_rgb(
        dir.path(),
        "q.png",
        &[&mol2, "--color-by", "charge", "--frames", "0:1"],
    );
    assert!(img.pixels().any(|p| p.0 != [0, 0, 0]));
}

/// `--add`: a receptor written by MDAnalysis with an RDKit SD file's ligand added draws, bonds
/// and all, byte for byte what ASE's single file of both molecules draws (md-io's
/// molecules/gen_scene.py): the receptor's bonds by distance and the ligand's as listed, each
/// part keeping its own. Poses as the frames, the receptor with every frame; an added file
/// with too few frames is an error naming it.
#[test]
fn added_files_share_the_scene_with_their_own_bonds() {
    let dir = tempfile::tempdir().unwrap();
    let (receptor, ligands) = (data("select_mda.pdb"), data("molecules/library.sdf"));
    let both = data("molecules/receptor_aspirin.xyz.gz");
    let size = ["--style", "ball-stick", "--size", "320x240"];
    let mut args = vec![&receptor[..], "--add", &ligands];
    args.extend(size);
    let added = render_rgb(dir.path(), "added.png", &args);
    let mut args = vec![&both[..]];
    args.extend(size);
    let single = render_rgb(dir.path(), "single.png", &args);
    assert_eq!(added.as_raw(), single.as_raw());
    // `prop file == 1` picks the added file's atoms: drawn alone, they are the ligand's image.
    let mut args = vec![
        &receptor[..],
        "--add",
        &ligands,
        "--select",
        "prop file == 1",
    ];
    args.extend(size);
    let picked = render_rgb(dir.path(), "picked.png", &args);
    let mut args = vec![&ligands[..], "--frames", "0:1"];
    args.extend(size);
    let alone = render_rgb(dir.path(), "alone.png", &args);
    assert_eq!(picked.as_raw(), alone.as_raw());

    let poses = data("molecules/imatinib_confs.sdf");
    let out = dir.path().join("pose_%02d.png");
    let o = texmap(&[
        "render",
        "-q",
        &poses,
        "--add",
        &receptor,
        "--size",
        "160x120",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for k in 0..5 {
        assert!(dir.path().join(format!("pose_{k:02}.png")).exists());
    }
    let three = data("mda_multi.pdb");
    let o = texmap(&[
        "render",
        "-q",
        &poses,
        "--add",
        &three,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("mda_multi.pdb: 3 frames"),
        "{}",
        stderr(&o)
    );
}

/// `--slice` (atoms checked against OVITO's Slice in md-scene's tests/analysis.rs): a (111)
/// slab through the FCC crystal's vacancy cluster, coloured by CNA, is mostly FCC green, with
/// the white of the cluster's atoms (their structure from the whole crystal, not the slab);
/// a zero normal is a usage error, and --slice-invert needs --slice.
#[test]
fn a_slab_keeps_the_whole_crystals_structure() {
    let dir = tempfile::tempdir().unwrap();
    let input = data("cna/crystals.xyz.gz");
    let img = render_rgb(
        dir.path(),
        "slab.png",
        &[
            &input,
            "--frames",
            "0:1",
            "--size",
            "240x180",
            "--slice",
            "1,1,1:20:6",
            "--color-by",
            "cna",
        ],
    );
    let lit: Vec<[i32; 3]> = img
        .pixels()
        .filter(|p| p.0 != [0, 0, 0])
        .map(|p| p.0.map(i32::from))
        .collect();
    let green = lit
        .iter()
        .filter(|p| p[1] > p[0] + 30 && p[1] > p[2] + 30)
        .count();
    let white = lit
        .iter()
        .filter(|p| p[0] > 150 && p[0].abs_diff(p[2]) < 12)
        .count();
    assert!(
        green * 10 > lit.len() * 7 && white > 0,
        "{green} {white} of {}",
        lit.len()
    );
    let out = dir.path().join("x.png");
    for bad in [
        &["--slice", "0,0,0:1"][..],
        &["--slice", "1,0,0:1:-2"],
        &["--slice-invert"],
    ] {
        let mut args = vec!["render", "-q", &input, "-o", out.to_str().unwrap()];
        args.extend(bad);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
    }
}

/// `--style surface` (md_scene::surface) on 3GWI chain A: drawn by every sphere method over the
/// same image the reference ray tracer makes of the same mesh; a ligand-in-pocket view mixes it
/// with balls and sticks; bad surface options and --quality are usage errors.
#[test]
fn a_molecular_surface_is_drawn_as_the_reference_traces_it() {
    let dir = tempfile::tempdir().unwrap();
    let surface = ["--style", "surface"];
    let reference = render_3gwi(
        dir.path(),
        "ref.png",
        &[&surface[..], &["--method", "reference"]].concat(),
    );
    for method in ["raycast", "template", "polygon"] {
        let name = format!("{method}.png");
        let ours = render_3gwi(
            dir.path(),
            &name,
            &[&surface[..], &["--method", method]].concat(),
        );
        let d = mean_abs_diff(&ours, &reference);
        eprintln!("{method}: mean |surface - reference| = {d:.3} per channel");
        assert!(
            d < 1.0,
            "{method}: mean |surface - reference| = {d} per channel"
        );
    }
    // The surface covers more of the image than the atoms' spheres (it fills the crevices) and
    // hides them: the density sum is at least each atom's own Gaussian, so a surface of scale
    // 1.1 encloses every atom's sphere and spacefill drawn with it adds nothing.
    let spheres = render_3gwi(dir.path(), "spheres.png", &[]);
    let wrapped = dir.path().join("raycast.png");
    assert!(
        lit(&wrapped) > lit(&spheres),
        "{} vs {}",
        lit(&wrapped),
        lit(&spheres)
    );
    let fuller = ["--surface-scale", "1.1"];
    let alone = render_3gwi(dir.path(), "alone.png", &[&surface[..], &fuller].concat());
    let both = render_3gwi(
        dir.path(),
        "both.png",
        &[
            &["--rep", "protein=surface", "--rep", "protein=spacefill"][..],
            &fuller,
        ]
        .concat(),
    );
    assert!(std::fs::read(&both).unwrap() == std::fs::read(&alone).unwrap());
    // A pocket view: the surface of all but residues 420-432, which show as balls and sticks.
    let pocket = render_3gwi(
        dir.path(),
        "pocket.png",
        &[
            "--rep",
            "not resid 420 to 432=surface",
            "--rep",
            "resid 420 to 432=ball-stick:#ff8000",
        ],
    );
    let img = image::open(&pocket).unwrap().to_rgb8();
    let orange = img
        .pixels()
        .filter(|p| p[0] > 180 && p[1] > 70 && p[1] < 150 && p[2] < 60)
        .count();
    assert!(orange > 200, "{orange} orange pixels");
    // Usage errors: exit 2, nothing written.
    let input = data("dssp/3gwiA.pdb.gz");
    for bad in [
        &["--style", "surface", "--surface-spacing", "0"][..],
        &["--style", "surface", "--surface-scale", "nan"],
        &["--rep", "protein=surfaces"],
    ] {
        let out = dir.path().join("bad.png");
        let mut args = vec!["render", input.as_str(), "-o", out.to_str().unwrap()];
        args.extend(bad);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
}

/// `--style cartoon` (md_scene::cartoon) on 3GWI chain A: helix ribbons, strand arrows and coil
/// in VMD's structure colours, drawn as the reference ray tracer traces the same mesh; with a
/// representation of balls and sticks beside it.
#[test]
fn a_cartoon_shows_dssps_structure_as_the_reference_traces_it() {
    let dir = tempfile::tempdir().unwrap();
    let cartoon = ["--style", "cartoon", "--color-by", "structure"];
    let reference = render_3gwi(
        dir.path(),
        "ref.png",
        &[&cartoon[..], &["--method", "reference"]].concat(),
    );
    let ours = render_3gwi(dir.path(), "ours.png", &cartoon);
    let d = mean_abs_diff(&ours, &reference);
    eprintln!("mean |cartoon - reference| = {d:.3} per channel");
    assert!(d < 1.0, "mean |cartoon - reference| = {d} per channel");
    let img = image::open(&ours).unwrap().to_rgb8();
    let count = |f: &dyn Fn(&image::Rgb<u8>) -> bool| img.pixels().filter(|p| f(p)).count();
    let purple = count(&|p| p[0] > 60 && p[1] < 30 && p[2] > 60 && p[0].abs_diff(p[2]) < 20);
    let yellow = count(&|p| p[0] > 90 && p[1] > 90 && p[2] < 30);
    let white = count(&|p| p[0] > 90 && p[0] == p[1] && p[1] == p[2]);
    eprintln!("purple {purple}, yellow {yellow}, white {white}");
    assert!(
        purple > 500 && yellow > 500 && white > 100,
        "{purple} {yellow} {white}"
    );
    // A cartoon drawn thinner than the atoms' spheres: fewer pixels than spacefill.
    let spheres = render_3gwi(dir.path(), "spheres.png", &[]);
    assert!(lit(&ours) < lit(&spheres));
    // Beside balls and sticks of residues 420-432 in orange.
    let both = render_3gwi(
        dir.path(),
        "both.png",
        &[
            "--rep",
            "protein=cartoon:structure",
            "--rep",
            "resid 420 to 432 and not name H*=ball-stick:#ff8000",
        ],
    );
    let img = image::open(&both).unwrap().to_rgb8();
    let orange = img
        .pixels()
        .filter(|p| p[0] > 180 && p[1] > 70 && p[1] < 150 && p[2] < 60)
        .count();
    assert!(orange > 100, "{orange} orange pixels");
}

/// `--surface-opacity`: a transparent surface (scale 1.3, so it encloses every atom's sphere)
/// over spacefill is, pixel by pixel, the opaque surface's colour mixed in linear light with
/// the spheres' at that opacity, and the spheres alone where it does not reach; the reference
/// lays its traced surface the same way. One camera for all (a keyframe on the molecule).
#[test]
fn a_transparent_surface_mixes_with_what_is_behind_it() {
    use texmap_core::color::{linear_to_srgb8, srgb8_to_linear_rgb};
    let dir = tempfile::tempdir().unwrap();
    let input = data("dssp/3gwiA.pdb.gz");
    let mut frame = texmap_md_io::Frame::new();
    texmap_md_io::Trajectory::open(&input)
        .unwrap()
        .read_frame(0, &mut frame)
        .unwrap();
    let n = frame.n_atoms() as f32;
    let c = frame.positions.iter().fold([0.0f32; 3], |s, p| {
        [s[0] + p[0] / n, s[1] + p[1] / n, s[2] + p[2] / n]
    });
    let keys = dir.path().join("camera.csv");
    std::fs::write(
        &keys,
        format!(
            "0 {} {} {} {} {} {}\n",
            c[0],
            c[1],
            c[2] + 90.0,
            c[0],
            c[1],
            c[2]
        ),
    )
    .unwrap();
    let keys = keys.to_str().unwrap().to_string();
    for method in ["raycast", "reference"] {
        let render = |name: &str, extra: &[&str]| {
            let mut args = vec![
                input.as_str(),
                "--size",
                "160x120",
                "--method",
                method,
                "--keyframes",
                &keys,
            ];
            args.extend(["--surface-scale", "1.3"]);
            args.extend(extra);
            render_rgb(dir.path(), &format!("{method}-{name}"), &args)
        };
        let both = ["--rep", "protein=surface", "--rep", "protein=spacefill"];
        let opaque = render("opaque.png", &both);
        let spheres = render("spheres.png", &["--style", "spacefill"]);
        let mixed = render(
            "mixed.png",
            &[&both[..], &["--surface-opacity", "0.4"]].concat(),
        );
        let (mut worst, mut covered) = (0u8, 0);
        for ((o, s), m) in opaque.pixels().zip(spheres.pixels()).zip(mixed.pixels()) {
            let expected = if o.0 == [0, 0, 0] {
                s.0
            } else {
                covered += 1;
                let lin = |p: &image::Rgb<u8>| srgb8_to_linear_rgb([p[0], p[1], p[2], 255]);
                let e = linear_to_srgb8(lin(o) * 0.4 + lin(s) * 0.6, 255);
                [e[0], e[1], e[2]]
            };
            for k in 0..3 {
                worst = worst.max(expected[k].abs_diff(m[k]));
            }
        }
        eprintln!("{method}: {covered} surface pixels, worst {worst} codes");
        assert!(
            covered > 2000 && worst <= 1,
            "{method}: {covered} pixels, worst {worst}"
        );
    }
}

/// `--export-mesh`: 3GWI's cartoon and a surface as binary glTF, read back by the gltf crate
/// (triangles, positions inside the molecule's reach, each vertex's uv on a palette texel of a
/// colour drawn) and checked by the Khronos glTF-Validator when installed; as OBJ with its MTL
/// and PNG; refused without a mesh style or with another extension.
#[test]
fn cartoon_and_surface_export_as_gltf_and_obj() {
    let dir = tempfile::tempdir().unwrap();
    let reps = [
        "--rep",
        "protein=cartoon:structure",
        "--rep",
        "resid 420 to 432=surface",
    ];
    let glb = dir.path().join("mol.glb");
    let args = [&reps[..], &["--export-mesh", glb.to_str().unwrap()]].concat();
    render_3gwi(dir.path(), "m.png", &args);
    let (doc, buffers, images) = gltf::import(&glb).unwrap();
    let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|b| Some(&buffers[b.index()]));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let uvs: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
    let triangles = reader.read_indices().unwrap().into_u32().count() / 3;
    assert!(triangles > 10_000, "{triangles} triangles");
    // In the molecule's own coordinates (Å): every vertex within 4 Å of some atom (an
    // arrowhead's corner is 1.5 Å from the CA spline, itself up to ~1.9 Å from the nearest
    // atom midway between CAs; the surface lies at the atoms' radii), where the molecule spans
    // some 50 Å.
    let mut frame = texmap_md_io::Frame::new();
    texmap_md_io::Trajectory::open(data("dssp/3gwiA.pdb.gz"))
        .unwrap()
        .read_frame(0, &mut frame)
        .unwrap();
    for p in positions.iter().step_by(97) {
        let near = frame
            .positions
            .iter()
            .map(|a| (0..3).map(|k| (a[k] - p[k]).powi(2)).sum::<f32>().sqrt());
        let d = near.fold(f32::MAX, f32::min);
        assert!(d < 4.0, "vertex {p:?} is {d} Å from every atom");
    }
    // The palette: each uv at a texel centre of one row; helix purple and strand yellow in it.
    let img = &images[0];
    assert_eq!(img.height, 1);
    for uv in &uvs {
        let x = uv[0] * img.width as f32 - 0.5;
        assert!(
            (x - x.round()).abs() < 1e-3 && (uv[1] - 0.5).abs() < 1e-6,
            "{uv:?}"
        );
    }
    let texels: Vec<&[u8]> = img.pixels.chunks(4).collect();
    assert!(
        texels.iter().any(|t| t[0] > 150 && t[1] < 30 && t[2] > 150),
        "no purple"
    );
    assert!(
        texels.iter().any(|t| t[0] > 240 && t[1] > 240 && t[2] < 30),
        "no yellow"
    );
    if let Some(reports) = common::gltf_validator_reports(std::slice::from_ref(&glb)) {
        assert_eq!(reports[0]["errors"], 0, "{}", reports[0]);
        assert_eq!(reports[0]["warnings"], 0, "{}", reports[0]);
        eprintln!("glTF-Validator: {}", reports[0]);
    }
    // OBJ: the same triangles, with the MTL and the palette PNG beside it.
    let obj = dir.path().join("mol.obj");
    let args = [&reps[..], &["--export-mesh", obj.to_str().unwrap()]].concat();
    render_3gwi(dir.path(), "o.png", &args);
    let meshes = texmap_mesh::read_obj(&obj).unwrap();
    assert_eq!(
        meshes.iter().map(|m| m.triangles.len()).sum::<usize>(),
        triangles
    );
    assert!(dir.path().join("mol.mtl").is_file() && dir.path().join("mol.png").is_file());
    // Refusals: exit 2, nothing written.
    let input = data("dssp/3gwiA.pdb.gz");
    let stl = dir.path().join("mol.stl");
    let spheres = dir.path().join("spheres.glb");
    for (bad, file) in [(&reps[..], &stl), (&["--style", "spacefill"][..], &spheres)] {
        let out = dir.path().join("bad.png");
        let mut args = vec!["render", input.as_str(), "-o", out.to_str().unwrap()];
        args.extend(bad);
        args.extend(["--export-mesh", file.to_str().unwrap()]);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(!out.exists() && !file.exists());
    }
}

/// `texmap render --quiet` of frame 0 of MDAnalysis's solvated adenylate kinase (md-io's
/// tests/data/hbonds: GRO topology + XTC) at `size`, with `extra`.
fn render_adk_frame0(size: &str, extra: &[&str]) -> Output {
    let (xtc, gro) = (data("hbonds/adk_0_9.xtc"), data("hbonds/adk_top.gro.gz"));
    let mut args = vec![
        "render",
        "--quiet",
        &xtc,
        "--topology",
        &gro,
        "--frames",
        "0",
        "--size",
        size,
    ];
    args.extend(extra);
    texmap(&args)
}

/// `--rep SEL=hbonds` on MDAnalysis's solvated adenylate kinase (GRO topology + XTC, triclinic
/// box): the dashes are drawn as the reference ray tracer traces them, in ChimeraX's blue
/// unless the representation names a colour; bad cutoffs are usage errors (exit 2).
#[test]
fn hydrogen_bonds_are_drawn_as_dashes_as_the_reference_traces_them() {
    let dir = tempfile::tempdir().unwrap();
    let near = "resid 1:25 or (resname SOL and same residue as within 3.5 of resid 1:25)";
    let hb = format!("{near}=hbonds");
    let sticks = format!("{near}=licorice");
    // The first frame at 320x240 down z, molecules whole, with `extra`.
    let run = |extra: &[&str]| {
        render_adk_frame0(
            "320x240",
            &[&["--view", "z", "--pbc", "unwrap"][..], extra].concat(),
        )
    };
    let ours = dir.path().join("ours.png");
    let reference = dir.path().join("ref.png");
    for (out, method) in [(&ours, "raycast"), (&reference, "reference")] {
        let out = out.to_str().unwrap();
        let o = run(&[
            "--rep", &sticks, "--rep", &hb, "--method", method, "-o", out,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let d = mean_abs_diff(&ours, &reference);
    eprintln!("mean |hbonds + licorice - reference| = {d:.3} per channel");
    assert!(d < 1.0, "mean |hbonds - reference| = {d} per channel");
    // The dashes alone: blue by default, red when the representation says so.
    let image = |name: &str, rep: &str| {
        let out = dir.path().join(name);
        let o = run(&["--rep", rep, "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        image::open(&out).unwrap().to_rgb8()
    };
    let blue = image("blue.png", &hb);
    // With --bonds none the dashes are the same (donors found by distance, dashes drawn).
    let out = dir.path().join("nobonds.png");
    let o = run(&["--rep", &hb, "--bonds", "none", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        image::open(&out).unwrap().to_rgb8() == blue,
        "--bonds none changed the dashes"
    );
    let red = image("red.png", &format!("{hb}:#ff0000"));
    let count = |img: &image::RgbImage, f: &dyn Fn(&image::Rgb<u8>) -> bool| {
        img.pixels().filter(|p| f(p)).count()
    };
    let bluish = |p: &image::Rgb<u8>| p[2] > 80 && p[2] as u16 > p[0] as u16 + 40;
    let reddish = |p: &image::Rgb<u8>| p[0] > 80 && p[0] as u16 > p[2] as u16 + 40;
    let lit = |p: &image::Rgb<u8>| p.0 != [0, 0, 0];
    eprintln!(
        "dash pixels: {} blue, {} red",
        count(&blue, &bluish),
        count(&red, &reddish)
    );
    assert!(count(&blue, &bluish) > 150 && count(&blue, &reddish) == 0);
    assert!(count(&red, &reddish) > 150 && count(&red, &bluish) == 0);
    let sticks_drawn = image::open(&ours).unwrap().to_rgb8();
    assert!(
        count(&sticks_drawn, &lit) > 3000,
        "{}",
        count(&sticks_drawn, &lit)
    );
    assert_eq!(count(&blue, &lit), count(&red, &lit));
    for bad in [
        ["--hbond-distance", "0.3"],
        ["--hbond-distance", "7"],
        ["--hbond-angle", "190"],
    ] {
        let out = dir.path().join("bad.png");
        let o = run(&["--rep", &hb, bad[0], bad[1], "-o", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(bad[0]), "{}", stderr(&o));
        assert!(!out.exists());
    }
    // A crystal structure without hydrogens: a warning that says why there are no dashes; with
    // nothing else to draw, an error that says so.
    let pdb = data("dssp/3gwiA.pdb.gz");
    let out = dir.path().join("noh.png");
    let noh = |reps: &[&str]| {
        let mut v = vec!["render", "--quiet", &pdb, "--size", "64x48"];
        for r in reps {
            v.extend(["--rep", r]);
        }
        v.extend(["-o", out.to_str().unwrap()]);
        texmap(&v)
    };
    let o = noh(&["protein=cartoon", "all=hbonds"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("no hydrogen atoms"), "{}", stderr(&o));
    std::fs::remove_file(&out).unwrap();
    let o = noh(&["all=hbonds"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no hydrogen bond"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `--hbond-table` lists, frame by frame, the hydrogen bonds the hbonds style draws: over the
/// whole solvated adenylate kinase (47,681 atoms, bonds by distance), exactly the bonds
/// MDAnalysis 2.11's HydrogenBondAnalysis finds in both frames (md-io's tests/data/hbonds),
/// and `texmap convert --hbonds all` writes the same tables without drawing. Without an
/// hbonds representation (or --hbonds) the flag is a usage error and no table is written.
#[test]
fn the_hydrogen_bond_table_is_mdanalysis_s_list() {
    let dir = tempfile::tempdir().unwrap();
    let (xtc, gro) = (data("hbonds/adk_0_9.xtc"), data("hbonds/adk_top.gro.gz"));
    let table = dir.path().join("hb.csv");
    let lifetime = dir.path().join("lifetime.csv");
    let frames = dir.path().join("f%02d.png");
    let run = |rep: &str| {
        texmap(&[
            "render",
            "--quiet",
            &xtc,
            "--topology",
            &gro,
            "--size",
            "160x120",
            "--rep",
            rep,
            "--hbond-table",
            table.to_str().unwrap(),
            "--hbond-lifetime",
            lifetime.to_str().unwrap(),
            "-o",
            frames.to_str().unwrap(),
        ])
    };
    let o = run("all=licorice");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--hbond-table"), "{}", stderr(&o));
    assert!(!table.exists() && !lifetime.exists());
    let o = run("all=hbonds");
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&table).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "frame,donor,hydrogen,acceptor,donor_atom,hydrogen_atom,acceptor_atom,distance,angle"
    );
    let mut got = vec![std::collections::BTreeSet::new(); 2];
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 9, "{line}");
        let n = |k: usize| f[k].parse::<u32>().unwrap();
        let (dist, angle): (f64, f64) = (f[7].parse().unwrap(), f[8].parse().unwrap());
        assert!(dist <= 3.0 && (150.0..=180.0).contains(&angle), "{line}");
        assert!(
            f[4].contains(':') && f[5].contains(":H") && f[6].contains(':'),
            "{line}"
        );
        got[n(0) as usize].insert((n(1), n(2), n(3)));
    }
    let mut gz = String::new();
    std::io::Read::read_to_string(
        &mut flate2::read::GzDecoder::new(
            std::fs::File::open(data("hbonds/reference.json.gz")).unwrap(),
        ),
        &mut gz,
    )
    .unwrap();
    let v: serde_json::Value = serde_json::from_str(&gz).unwrap();
    // MDAnalysis's (donor, hydrogen, acceptor) triples, per frame.
    let mda_triples: Vec<std::collections::BTreeSet<(u32, u32, u32)>> = v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|frame| {
            let flat: Vec<u32> = frame["dha"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_u64().unwrap() as u32)
                .collect();
            flat.chunks(3).map(|c| (c[0], c[1], c[2])).collect()
        })
        .collect();
    for (k, want) in mda_triples.iter().enumerate() {
        // A triple one side lists and the other does not must be a tie at a cutoff: a
        // donor-acceptor distance of 3.00 Å in the file (the XTC's 0.01 Å grid makes them),
        // which the f32 rounding of the positions decides (md-io's tests/hbonds.rs).
        let mut traj = texmap_md_io::Trajectory::open(&xtc).unwrap();
        let mut md = texmap_md_io::Frame::new();
        traj.read_frame(k, &mut md).unwrap();
        let cell = md.cell.unwrap();
        let differ: Vec<_> = got[k].symmetric_difference(want).collect();
        assert!(differ.len() <= 3, "frame {k}: {} differ", differ.len());
        for &(d, _, a) in differ {
            let (p, q) = (md.positions[d as usize], md.positions[a as usize]);
            let v = texmap_md_io::pbc::minimum_image(
                &cell,
                std::array::from_fn(|i| q[i] as f64 - p[i] as f64),
            );
            let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            assert!(
                (r - 3.0).abs() < 1e-5,
                "frame {k}: ({d}, {a}) at {r} Å is no tie"
            );
        }
        assert!(got[k].len() > 13_000);
    }
    // --hbond-lifetime over the two frames: C(1) is the share of frame 0's (hydrogen, acceptor)
    // pairs still bonded in frame 1, of the table's bonds exactly, and of MDAnalysis's within
    // the ties at the cutoff.
    let pairs = |s: &std::collections::BTreeSet<(u32, u32, u32)>| {
        s.iter()
            .map(|&(_, h, a)| (h, a))
            .collect::<std::collections::BTreeSet<_>>()
    };
    type Pairs = std::collections::BTreeSet<(u32, u32)>;
    fn kept(a: &Pairs, b: &Pairs) -> f64 {
        a.intersection(b).count() as f64 / a.len() as f64
    }
    let ours = kept(&pairs(&got[0]), &pairs(&got[1]));
    let text = std::fs::read_to_string(&lifetime).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert_eq!(rows[0], "lag,time,survival");
    assert!(
        rows[1].starts_with("0,") && rows[1].ends_with(",1.000000"),
        "{text}"
    );
    let c1: f64 = rows[2].rsplit(',').next().unwrap().parse().unwrap();
    assert!((c1 - ours).abs() < 1e-6, "C(1) {c1} vs the table's {ours}");
    let theirs: Vec<Pairs> = mda_triples.iter().map(pairs).collect();
    let mda = kept(&theirs[0], &theirs[1]);
    assert!(
        (c1 - mda).abs() < 4.0 / theirs[0].len() as f64,
        "C(1) {c1} vs MDAnalysis's {mda}"
    );
    // Frames 0 and 9 of the run: the water has moved on, a few dozen of the protein's bonds
    // hold.
    assert!(c1 > 0.0 && c1 < 0.05, "C(1) {c1}");
    // texmap convert finds the same bonds among --hbonds' atoms without drawing: the same
    // two files; without --hbonds the tables are a usage error.
    let (t2, l2, occ) = (
        dir.path().join("hb2.csv"),
        dir.path().join("lt2.csv"),
        dir.path().join("occ.csv"),
    );
    let convert = |extra: &[&str]| {
        let mut args = vec![
            "convert",
            "--quiet",
            &xtc,
            "--topology",
            &gro,
            "--hbond-table",
            t2.to_str().unwrap(),
            "--hbond-lifetime",
            l2.to_str().unwrap(),
            "--hbond-occupancy",
            occ.to_str().unwrap(),
        ];
        args.extend(extra);
        texmap(&args)
    };
    let o = convert(&["--hbonds", "all"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(&t2).unwrap(),
        std::fs::read_to_string(&table).unwrap()
    );
    assert_eq!(std::fs::read_to_string(&l2).unwrap(), text);
    // --hbond-occupancy: every bond of the table once, with the frames it is in (MDAnalysis's
    // count_by_ids over its own per-frame lists, the ties at the cutoff aside), the most
    // present first.
    let occupancy = std::fs::read_to_string(&occ).unwrap();
    let mut lines = occupancy.lines();
    assert_eq!(
        lines.next().unwrap(),
        "donor,hydrogen,acceptor,donor_atom,hydrogen_atom,acceptor_atom,frames,occupancy,distance,angle"
    );
    let ties: std::collections::BTreeSet<(u32, u32, u32)> = (0..2)
        .flat_map(|k| {
            got[k]
                .symmetric_difference(&mda_triples[k])
                .copied()
                .collect::<Vec<_>>()
        })
        .collect();
    let mut seen = std::collections::BTreeSet::new();
    let mut last = usize::MAX;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let n = |k: usize| f[k].parse::<u32>().unwrap();
        let t = (n(0), n(1), n(2));
        let frames = n(6) as usize;
        assert!(frames <= last, "sorted by frames: {line}");
        last = frames;
        let ours = got.iter().filter(|s| s.contains(&t)).count();
        assert_eq!(frames, ours, "{line}");
        let occupancy: f64 = f[7].parse().unwrap();
        assert!((occupancy - frames as f64 / 2.0).abs() < 1e-9);
        if !ties.contains(&t) {
            let theirs = mda_triples.iter().filter(|s| s.contains(&t)).count();
            assert_eq!(frames, theirs, "MDAnalysis's count for {line}");
        }
        let (dist, angle): (f64, f64) = (f[8].parse().unwrap(), f[9].parse().unwrap());
        assert!(dist <= 3.0 && (150.0..=180.0).contains(&angle), "{line}");
        seen.insert(t);
    }
    let all: std::collections::BTreeSet<_> = got.iter().flatten().copied().collect();
    assert_eq!(seen, all, "every bond once");
    assert!(all.len() > got[0].len(), "bonds that come and go");
    std::fs::remove_file(&t2).unwrap();
    std::fs::remove_file(&l2).unwrap();
    std::fs::remove_file(&occ).unwrap();
    let o = convert(&[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--hbonds"), "{}", stderr(&o));
    assert!(!t2.exists() && !l2.exists() && !occ.exists());
    // `--label {hbonds}` writes the count the table lists (the caption drawn byte for byte as
    // the literal number); without an hbonds representation it is a usage error.
    let caption = |label: &str, rep: &str, out: &str| {
        render_adk_frame0("160x120", &["--rep", rep, "--label", label, "-o", out])
    };
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let o = caption("{hbonds} H-bonds", "all=hbonds", a.to_str().unwrap());
    assert!(o.status.success(), "{}", stderr(&o));
    let literal = format!("{} H-bonds", got[0].len());
    let o = caption(&literal, "all=hbonds", b.to_str().unwrap());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap());
    let c = dir.path().join("c.png");
    let o = caption("{hbonds} H-bonds", "all=licorice", c.to_str().unwrap());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("{hbonds}") && !c.exists(),
        "{}",
        stderr(&o)
    );
}

/// VASP: pymatgen's fixed-cell XDATCAR (md-io's tests/data/gen_vasp.py) renders as the same
/// frames written by ASE as extended XYZ draw (elements, positions, cell, bonds by distance),
/// and `info` counts its frames and atoms.
#[test]
fn a_vasp_xdatcar_renders_as_its_frames_in_extended_xyz() {
    let xdatcar = data("vasp/XDATCAR_pmg");
    let o = texmap(&["info", &xdatcar]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "vasp");
    assert_eq!(v["frames"], 6);
    assert_eq!(v["atoms"], 9);
    let dir = tempfile::tempdir().unwrap();
    for frame in ["0", "5"] {
        let args = |f: &str| {
            vec![
                f.to_string(),
                "--frames".into(),
                frame.into(),
                "--style".into(),
                "ball-stick".into(),
                "--size".into(),
                "320x240".into(),
            ]
        };
        let a = args(&xdatcar);
        let extxyz = data("vasp/pmg_frames.extxyz");
        let b = args(&extxyz);
        let render = |name: &str, a: &[String]| {
            render_rgb(
                dir.path(),
                name,
                &a.iter().map(String::as_str).collect::<Vec<_>>(),
            )
        };
        let (a, b) = (render("a.png", &a), render("b.png", &b));
        let differ = a
            .pixels()
            .zip(b.pixels())
            .filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 2))
            .count();
        assert!(differ < 20, "frame {frame}: {differ} pixels differ");
        assert!(a.pixels().filter(|p| p.0 != [0, 0, 0]).count() > 2000);
    }
}

/// Coordination polyhedra: ASE's rutile (md-io's tests/data/gen_vasp.py) replicated 2x2x3 gives
/// one TiO6 octahedron per Ti, each of 8 faces and of the volume scipy's ConvexHull gives the
/// six O around a Ti (nearest images), Ti-Ti bonds by distance left out; the picture matches
/// the reference ray tracer's, opaque and translucent.
#[test]
fn rutile_polyhedra_are_its_tio6_octahedra() {
    let poscar = data("vasp/POSCAR_rutile");
    let want: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("vasp/rutile_polyhedra.json")).unwrap())
            .unwrap();
    let volume = want["octahedron_volumes"][0].as_f64().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("poly.obj");
    let base = [
        poscar.as_str(),
        "--rep",
        "element Ti=polyhedra",
        "--rep",
        "element O=ball-stick",
        "--replicate",
        "2,2,3",
        "--size",
        "320x240",
    ];
    let mut args = base.to_vec();
    args.extend(["--export-mesh", obj.to_str().unwrap()]);
    // Not poly.png: that is the OBJ's palette texture.
    let img = render_rgb(dir.path(), "picture.png", &args);
    assert!(img.pixels().filter(|p| p.0 != [0, 0, 0]).count() > 5000);
    // The exported mesh: vertices and triangles (1-based, `v/vt/vn` or plain).
    let text = std::fs::read_to_string(&obj).unwrap();
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<[usize; 3]> = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => v.push(std::array::from_fn(|_| it.next().unwrap().parse().unwrap())),
            Some("f") => faces.push(std::array::from_fn(|_| {
                let t = it.next().unwrap();
                t.split('/').next().unwrap().parse::<usize>().unwrap() - 1
            })),
            _ => {}
        }
    }
    let n_ti = 2 * 2 * 2 * 3;
    assert_eq!(faces.len(), n_ti * 8, "faces");
    let enclosed: f64 = faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| v[i]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum();
    let expected = n_ti as f64 * volume;
    assert!(
        (enclosed - expected).abs() < 1e-3 * expected,
        "{enclosed} Å³ enclosed, {expected} expected"
    );
    // Against the reference ray tracer, opaque and translucent.
    for opacity in ["1", "0.5"] {
        let mut args = base.to_vec();
        args.extend(["--polyhedra-opacity", opacity]);
        let raycast = dir.path().join(format!("r{opacity}.png"));
        let reference = dir.path().join(format!("t{opacity}.png"));
        for (method, out) in [("raycast", &raycast), ("reference", &reference)] {
            let mut all = vec!["render", "--quiet", "--method", method];
            all.extend(&args);
            all.extend(["-o", out.to_str().unwrap()]);
            let o = texmap(&all);
            assert!(o.status.success(), "{}", stderr(&o));
        }
        let d = mean_abs_diff(&raycast, &reference);
        assert!(
            d < 1.5,
            "opacity {opacity}: mean |raycast - reference| = {d}"
        );
    }
    let (opaque, clear) = (
        image::open(dir.path().join("r1.png")).unwrap().to_rgb8(),
        image::open(dir.path().join("r0.5.png")).unwrap().to_rgb8(),
    );
    assert_ne!(opaque.as_raw(), clear.as_raw());
}

/// Arrows: the velocities of ASE's CONTCAR (md-io's tests/data/gen_vasp.py) drawn at 0.3 Å per
/// Å/ps end, atom for atom, where ASE's positions plus 0.3 times ASE's velocities put them (the
/// exported mesh's farthest point along each arrow); displacements of ASE's XDATCAR drawn by
/// the rasteriser as the reference ray tracer draws them; a file without the vectors asked for
/// is an error naming what it lacks.
#[test]
fn arrows_end_where_the_vectors_point() {
    let dir = tempfile::tempdir().unwrap();
    let contcar = data("vasp/CONTCAR_ase_vel.vasp");
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("vasp/reference.json")).unwrap())
            .unwrap();
    let want = &reference["CONTCAR_ase_vel.vasp"][0];
    let obj = dir.path().join("arrows.obj");
    let args = [
        contcar.as_str(),
        "--rep",
        "all=arrows",
        "--arrow-scale",
        "0.3",
        "--size",
        "320x240",
        "--export-mesh",
        obj.to_str().unwrap(),
    ];
    render_rgb(dir.path(), "v.png", &args);
    let v = common::obj_vertices(&obj);
    let positions = want["positions"].as_array().unwrap();
    let velocities = want["velocities"].as_array().unwrap();
    assert_eq!(positions.len(), 9);
    for (p, u) in positions.iter().zip(velocities) {
        let p: [f64; 3] = std::array::from_fn(|k| p[k].as_f64().unwrap());
        let u: [f64; 3] = std::array::from_fn(|k| u[k].as_f64().unwrap() * 0.3);
        let len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        let tip: [f64; 3] = std::array::from_fn(|k| p[k] + u[k]);
        // Some vertex of the mesh is the tip, and no vertex of this arrow lies beyond it.
        let nearest = v
            .iter()
            .map(|q| (0..3).map(|k| (q[k] - tip[k]).powi(2)).sum::<f64>().sqrt())
            .fold(f64::MAX, f64::min);
        assert!(
            nearest < 1e-4 * len.max(1.0),
            "tip {tip:?}: nearest vertex {nearest} Å"
        );
    }
    // Displacements: rasteriser against the reference ray tracer, frame 0 (no arrows) and 4.
    let xdatcar = data("vasp/XDATCAR_ase");
    for method in ["raycast", "reference"] {
        let out = dir.path().join(format!("{method}%d.png"));
        let o = texmap(&[
            "render",
            "--quiet",
            &xdatcar,
            "--frames",
            "0:5:4",
            "--rep",
            "all=ball-stick",
            "--rep",
            "all=arrows",
            "--arrows",
            "displacement",
            "--arrow-scale",
            "5",
            "--size",
            "320x240",
            "--method",
            method,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let d = mean_abs_diff(
        &dir.path().join("raycast4.png"),
        &dir.path().join("reference4.png"),
    );
    assert!(d < 1.0, "mean |raycast - reference| = {d}");
    // Without the arrows (the same frames, so the same camera): frame 4 differs, and frame 0,
    // whose displacements are all zero, is the same picture.
    let o = texmap(&[
        "render",
        "--quiet",
        &xdatcar,
        "--frames",
        "0:5:4",
        "--rep",
        "all=ball-stick",
        "--size",
        "320x240",
        "-o",
        dir.path().join("plain%d.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (f0, f4) = (
        dir.path().join("raycast0.png"),
        dir.path().join("raycast4.png"),
    );
    assert!(
        mean_abs_diff(&dir.path().join("plain4.png"), &f4) > 0.2,
        "frame 4's arrows"
    );
    assert_eq!(
        mean_abs_diff(&dir.path().join("plain0.png"), &f0),
        0.0,
        "frame 0"
    );
    // What a file lacks.
    for (arrows, lacks) in [
        ("velocity", "no velocities"),
        ("f", "no per-atom properties fx"),
    ] {
        let o = texmap(&[
            "render",
            "--quiet",
            &xdatcar,
            "--rep",
            "all=arrows",
            "--arrows",
            arrows,
            "-o",
            dir.path().join("e.png").to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains(lacks), "{}", stderr(&o));
    }
}

/// Trails: two argon atoms in a 10 Å box, one walking 1.5 Å a frame through a face of the box
/// (an extended XYZ file written here): the rasteriser's picture matches the reference ray
/// tracer's, the trail grows frame by frame, and a render split into parts (`--shard`) draws
/// every frame byte for byte as the whole render does (each part builds the frames before its
/// own for their paths).
#[test]
fn trails_grow_over_the_frames_and_survive_sharding() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("walk.extxyz");
    let mut text = String::new();
    for k in 0..6 {
        let x = (7.0 + 1.5 * k as f64) % 10.0;
        text += &format!(
            "2\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3\nAr {x} 2 3\nAr 5 5 5\n"
        );
    }
    std::fs::write(&input, text).unwrap();
    let render = |sub: &str, extra: &[&str]| {
        let out = dir.path().join(sub);
        std::fs::create_dir_all(&out).unwrap();
        let pattern = out.join("f%d.png");
        let mut args = vec![
            "render",
            "--quiet",
            input.to_str().unwrap(),
            "--frames",
            "0:6",
            "--rep",
            "all=ball-stick",
            "--rep",
            "index 0=trails:#ffcc00",
            "--size",
            "320x240",
            "-o",
            pattern.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        out
    };
    let whole = render("whole", &[]);
    let reference = render("reference", &["--method", "reference"]);
    for k in 0..6 {
        let f = format!("f{k}.png");
        let d = mean_abs_diff(&whole.join(&f), &reference.join(&f));
        assert!(d < 1.0, "frame {k}: mean |raycast - reference| = {d}");
    }
    // The trail's colour covers more pixels as it grows.
    let yellow = |k: usize| {
        let img = image::open(whole.join(format!("f{k}.png")))
            .unwrap()
            .to_rgb8();
        img.pixels()
            .filter(|p| p.0[0] > 150 && p.0[1] > 120 && p.0[2] < 60)
            .count()
    };
    assert!(yellow(5) > yellow(2) + 50, "{} vs {}", yellow(5), yellow(2));
    let zero = texmap(&[
        "render",
        input.to_str().unwrap(),
        "--rep",
        "index 0=trails",
        "--trail-length",
        "0",
        "-o",
        dir.path().join("z.png").to_str().unwrap(),
    ]);
    assert_eq!(zero.status.code(), Some(2), "{}", stderr(&zero));
    for part in 0..2 {
        let shard = format!("{part}/2");
        let out = render(&format!("part{part}"), &["--shard", &shard]);
        for entry in std::fs::read_dir(&out).unwrap() {
            let name = entry.unwrap().file_name();
            let a = std::fs::read(out.join(&name)).unwrap();
            let b = std::fs::read(whole.join(&name)).unwrap();
            assert!(
                a == b,
                "part {part}: {name:?} differs from the whole render's"
            );
        }
    }
}

/// `--measure`: distances (one to a water far across the box: the nearest image), an angle and
/// a backbone dihedral on MDAnalysis's solvated adenylate kinase, frame by frame, written by
/// `--measure-table` as MDAnalysis's calc_bonds / calc_angles / calc_dihedrals give them with
/// the box (md-io's tests/data/gen_measure.py), and `texmap convert` writes the same table
/// without drawing; the dashes are drawn as the reference ray tracer traces them; a selection
/// that picks two atoms is an error naming it.
#[test]
fn measurements_are_mdanalysis_values_and_drawn_as_traced() {
    let dir = tempfile::tempdir().unwrap();
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(data("hbonds/measure_reference.json")).unwrap(),
    )
    .unwrap();
    let specs: Vec<&str> = reference
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["spec"].as_str().unwrap())
        .collect();
    let (xtc, gro) = (data("hbonds/adk_0_9.xtc"), data("hbonds/adk_top.gro.gz"));
    let table = dir.path().join("m.csv");
    let run = |method: &str, out: &str, table: Option<&Path>| {
        let mut args = vec![
            "render",
            "--quiet",
            xtc.as_str(),
            "--topology",
            gro.as_str(),
            "--frames",
            "0:2",
            "--select",
            "protein and resid 5:25",
            "--style",
            "licorice",
            "--size",
            "320x240",
            "--method",
            method,
        ];
        for s in &specs {
            args.extend(["--measure", s]);
        }
        let t = table.map(|t| t.to_str().unwrap().to_string());
        if let Some(t) = &t {
            args.extend(["--measure-table", t.as_str()]);
        }
        let out = dir.path().join(out);
        args.extend(["-o", out.to_str().unwrap()]);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    run("raycast", "r%d.png", Some(&table));
    let text = std::fs::read_to_string(&table).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert_eq!(rows[0], "frame,measure,kind,value,atoms,spec");
    assert_eq!(rows.len(), 1 + 2 * specs.len());
    for row in &rows[1..] {
        let f: Vec<&str> = row.splitn(6, ',').collect();
        let (frame, m) = (
            f[0].parse::<usize>().unwrap(),
            f[1].parse::<usize>().unwrap(),
        );
        let want = reference[m]["values"][frame].as_f64().unwrap();
        let got: f64 = f[3].parse().unwrap();
        assert!((got - want).abs() < 2e-3, "{row}: MDAnalysis {want}");
        let kind = ["distance", "angle", "dihedral"][specs[m].split(';').count() - 2];
        assert_eq!(f[2], kind);
        assert_eq!(f[5], format!("\"{}\"", specs[m]));
    }
    // texmap convert measures the same frames without drawing them: the same table.
    let converted = dir.path().join("c.csv");
    let mut args = vec![
        "convert",
        "-q",
        xtc.as_str(),
        "--topology",
        gro.as_str(),
        "--frames",
        "0:2",
        "--measure-table",
        converted.to_str().unwrap(),
    ];
    for s in &specs {
        args.extend(["--measure", s]);
    }
    let o = texmap(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&converted).unwrap(), text);
    // The picture: dashes and labels against the reference ray tracer's dashes (the labels
    // are drawn on both alike).
    run("reference", "t%d.png", None);
    for k in 0..2 {
        let d = mean_abs_diff(
            &dir.path().join(format!("r{k}.png")),
            &dir.path().join(format!("t{k}.png")),
        );
        assert!(d < 1.5, "frame {k}: mean |raycast - reference| = {d}");
    }
    // A selection that does not pick one atom.
    let o = render_adk_frame0(
        "160x120",
        &[
            "--select",
            "resid 10",
            "--measure",
            "resid 10 and name CA; resid 11",
            "-o",
            dir.path().join("e.png").to_str().unwrap(),
        ],
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("selection 2 picks"), "{}", stderr(&o));
}

/// A LAMMPS data file (MDAnalysis's topo_mda.data) is a structure to render and describe, not
/// only a topology: one frame, its listed bonds, elements from its masses.
#[test]
fn a_lammps_data_file_renders_and_is_described() {
    let file = data("topo_mda.data");
    let o = texmap(&["info", &file]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "lammps-data");
    assert_eq!(v["frames"], 1);
    assert_eq!(v["atoms"], 66);
    assert_eq!(v["bonds"], 53);
    let dir = tempfile::tempdir().unwrap();
    let img = render_rgb(dir.path(), "d.png", &[&file, "--style", "ball-stick"]);
    // The listed bonds drawn: more pixels lit than the same atoms without bonds.
    let none = render_rgb(
        dir.path(),
        "n.png",
        &[&file, "--style", "ball-stick", "--bonds", "none"],
    );
    let lit = |i: &image::RgbImage| i.pixels().filter(|p| p.0 != [0, 0, 0]).count();
    assert!(
        lit(&img) > lit(&none) + 100,
        "{} vs {}",
        lit(&img),
        lit(&none)
    );
}

/// `--bond-orders`: Open Babel's MOL2 of imatinib (aromatic rings, double bonds) drawn in
/// valence mode as the reference ray tracer traces it, and differently from single sticks.
#[test]
fn bond_orders_are_drawn_as_the_reference_traces_them() {
    let mol2 = data("molecules/imatinib_poses.mol2");
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            "render",
            "--quiet",
            mol2.as_str(),
            "--frames",
            "0",
            "--style",
            "licorice",
            "--size",
            "400x300",
        ];
        args.extend(extra);
        args.extend(["-o", out.to_str().unwrap()]);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        out
    };
    let valence = run("v.png", &["--bond-orders"]);
    let traced = run("t.png", &["--bond-orders", "--method", "reference"]);
    let single = run("s.png", &[]);
    let d = mean_abs_diff(&valence, &traced);
    assert!(d < 1.5, "mean |raycast - reference| = {d}");
    assert!(mean_abs_diff(&valence, &single) > 1.0);
}

/// `--displacements` / `--color-by displacement`: the property is there for colours (turned on
/// by the colouring itself) and for selections (with the flag), measured from the first frame
/// drawn: an atom walking 1.5 Å a frame through a box face is selected from frame 2 on.
#[test]
fn displacements_colour_and_select() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("walk.extxyz");
    let mut text = String::new();
    for k in 0..4 {
        let x = (7.0 + 1.5 * k as f64) % 10.0;
        text += &format!(
            "2\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3\nAr {x} 2 3\nAr 5 5 5\n"
        );
    }
    std::fs::write(&input, text).unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--quiet",
            input.to_str().unwrap(),
            "--size",
            "160x120",
        ];
        args.extend(extra);
        let out = dir.path().join("f%d.png");
        args.extend(["-o", out.to_str().unwrap()]);
        texmap(&args)
    };
    let o = run(&[
        "--frames",
        "0:4",
        "--color-by",
        "displacement",
        "--color-range",
        "0:5",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sel = ["--frames", "2:4", "--select", "prop displacement > 2"];
    let o = run(&sel);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("displacement"), "{}", stderr(&o));
    // Measured from frame 0 (the first drawn), a fixed camera over the whole box.
    let o = run(&[
        "--frames",
        "0:4",
        "--displacements",
        "--rep",
        "prop displacement > 2=ball-stick",
        "--rep",
        "index 1=ball-stick",
        "--eye",
        "5,5,40",
        "--target",
        "5,5,5",
        "--up",
        "0,1,0",
        "--fov",
        "20",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lit = |k: usize| {
        let img = image::open(dir.path().join(format!("f{k}.png")))
            .unwrap()
            .to_rgb8();
        img.pixels().filter(|p| p.0 != [0, 0, 0]).count()
    };
    // Frames 0 and 1 draw atom 1 only; frames 2 and 3 both atoms.
    assert!(lit(2) > lit(1) + 50, "{} vs {}", lit(2), lit(1));
    assert!(lit(3) > lit(0) + 50);
}

/// --displacement-reference: displacements of ASE's XDATCAR measured from a chosen frame (so
/// that frame itself has none: no atom is selected by `prop displacement > 0.001`) or from
/// a structure file (the same file's first frame draws the same image as frame 0); a reference
/// nothing uses, or past the last frame, is a usage error.
#[test]
fn displacements_measure_from_the_reference_given() {
    let xdatcar = data("vasp/XDATCAR_ase");
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["render", "--quiet", xdatcar.as_str(), "--size", "160x120"];
        args.extend(extra);
        args.extend(["-o", out.to_str().unwrap()]);
        (texmap(&args), out)
    };
    let moved = [
        "--frames",
        "2",
        "--displacements",
        "--select",
        "prop displacement > 0.001",
    ];
    let (o, _) = run(
        "self.png",
        &[&moved[..], &["--displacement-reference", "2"]].concat(),
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no atom to draw"), "{}", stderr(&o));
    let (o, _) = run(
        "first.png",
        &[&moved[..], &["--displacement-reference", "0"]].concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let colour = ["--frames", "2", "--color-by", "displacement"];
    let (o, a) = run(
        "a.png",
        &[&colour[..], &["--displacement-reference", "0"]].concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (o, b) = run(
        "b.png",
        &[&colour[..], &["--displacement-reference", &xdatcar]].concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let (o, c) = run(
        "c.png",
        &[&colour[..], &["--displacement-reference", "2"]].concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap());
    let (o, _) = run("x.png", &["--displacement-reference", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let (o, _) = run(
        "y.png",
        &[&colour[..], &["--displacement-reference", "999"]].concat(),
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("frames (0 to"), "{}", stderr(&o));
}

fn ellipsoid_data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-scene/tests/data/ellipsoids")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// `--style ellipsoids` (md_scene::ellipsoids) on a LAMMPS dump OVITO 3.17 exported: every
/// vertex of the exported mesh lies on one of the ellipsoids OVITO reads from the file; the
/// rasteriser draws what the reference ray tracer draws; LAMMPS's own columns (diameters, w
/// first) give the same picture; files without shapes and bad shapes are clear errors.
#[test]
fn ellipsoids_lie_where_ovito_reads_them() {
    let dir = tempfile::tempdir().unwrap();
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ellipsoid_data("ovito_read.json")).unwrap())
            .unwrap();
    let want = &reference["ovito_export.dump"];
    let obj = dir.path().join("e.obj");
    let dump = ellipsoid_data("ovito_export.dump");
    let base = [dump.as_str(), "--style", "ellipsoids", "--size", "320x240"];
    let with_obj = [&base[..], &["--export-mesh", obj.to_str().unwrap()]].concat();
    render_rgb(dir.path(), "picture.png", &with_obj);
    let vertices = common::obj_vertices(&obj);
    let f = |v: &serde_json::Value| -> Vec<[f64; 4]> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|r| {
                let r = r.as_array().unwrap();
                std::array::from_fn(|k| r.get(k).map_or(0.0, |x| x.as_f64().unwrap()))
            })
            .collect()
    };
    let (pos, semi, quat) = (
        f(&want["positions"]),
        f(&want["semi_axes"]),
        f(&want["orientation_xyzw"]),
    );
    // |u| of a point in the frame where particle i is the unit sphere (OVITO's x, y, z, w).
    let u = |p: &[f64; 3], i: usize| {
        let [x, y, z, w] = quat[i];
        let d = [p[0] - pos[i][0], p[1] - pos[i][1], p[2] - pos[i][2]];
        // The inverse rotation of d: conjugate quaternion.
        let (qx, qy, qz, qw) = (-x, -y, -z, w);
        let t = [
            2.0 * (qy * d[2] - qz * d[1]),
            2.0 * (qz * d[0] - qx * d[2]),
            2.0 * (qx * d[1] - qy * d[0]),
        ];
        let r = [
            d[0] + qw * t[0] + (qy * t[2] - qz * t[1]),
            d[1] + qw * t[1] + (qz * t[0] - qx * t[2]),
            d[2] + qw * t[2] + (qx * t[1] - qy * t[0]),
        ];
        ((0..3).map(|k| (r[k] / semi[i][k]).powi(2)).sum::<f64>()).sqrt()
    };
    let ellipsoids: Vec<usize> = (0..pos.len()).filter(|&i| semi[i][0] > 0.0).collect();
    assert_eq!(ellipsoids.len(), 59, "one sphere among 60");
    let mut hits = vec![0usize; pos.len()];
    for v in &vertices {
        let on = ellipsoids
            .iter()
            .copied()
            .find(|&i| (u(v, i) - 1.0).abs() < 1e-4);
        let i = on.unwrap_or_else(|| panic!("vertex {v:?} is on no ellipsoid"));
        hits[i] += 1;
    }
    assert!(
        ellipsoids.iter().all(|&i| hits[i] >= 12),
        "every ellipsoid exported"
    );
    // The rasteriser against the reference ray tracer, both drawing the view's mesh.
    let mut pngs = Vec::new();
    for method in ["raycast", "reference"] {
        let args = [&base[..], &["--method", method]].concat();
        render_rgb(dir.path(), &format!("{method}.png"), &args);
        pngs.push(dir.path().join(format!("{method}.png")));
    }
    let d = mean_abs_diff(&pngs[0], &pngs[1]);
    assert!(d < 1.0, "mean |raycast - reference| = {d}");
    assert!(lit(&pngs[0]) > 320 * 240 / 10);
    // LAMMPS's columns for the same particles: the same picture.
    let lammps = ellipsoid_data("lammps_columns.dump");
    let args = [
        "--style",
        "ellipsoids",
        "--size",
        "320x240",
        "--method",
        "raycast",
    ];
    render_rgb(
        dir.path(),
        "lammps.png",
        &[&[lammps.as_str()][..], &args].concat(),
    );
    let d = mean_abs_diff(&pngs[0], &dir.path().join("lammps.png"));
    assert!(d < 0.05, "mean |OVITO's columns - LAMMPS's| = {d}");
    // A file without shapes: exit 1 naming what it lacks; one shape for all draws it.
    let plain = data("ase_plain.xyz");
    let o = texmap(&[
        "render",
        "--quiet",
        &plain,
        "--style",
        "ellipsoids",
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("shapex"), "{}", stderr(&o));
    assert!(!dir.path().join("x.png").exists());
    let o = texmap(&[
        "render",
        "--quiet",
        &plain,
        "--style",
        "ellipsoids",
        "--ellipsoid-shape",
        "1.2,0.6,0.6",
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for bad in ["1,0,1", "1,2", "x"] {
        let o = texmap(&[
            "render",
            "--quiet",
            &plain,
            "--style",
            "ellipsoids",
            "--ellipsoid-shape",
            bad,
            "-o",
            dir.path().join("y.png").to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
    }
}

/// A trajectory in several files: OVITO's one-file-per-frame export of a LAMMPS run, as a quoted
/// pattern, draws the same bytes as the run's one file, smoothed across the files' boundaries
/// too; XTC parts count their frames together; unquoted (shell-sorted) parts are read as given
/// with a warning; a pattern matching nothing is an error.
#[test]
fn a_trajectory_in_several_files_is_one_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let seq = |name: &str| data(&format!("sequence/{name}"));
    let pattern = seq("ovito/dump.*.lammpstrj");
    let o = texmap(&["info", &pattern]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (info["frames"].as_u64(), info["files"].as_u64()),
        (Some(12), Some(12))
    );
    let o = texmap(&["info", &seq("part1.xtc"), &seq("part2.xtc")]);
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (info["frames"].as_u64(), info["files"].as_u64()),
        (Some(12), Some(2))
    );
    for (name, input) in [
        ("whole", seq("source.lammpstrj")),
        ("parts", pattern.clone()),
    ] {
        for smooth in ["0", "2"] {
            let out = dir.path().join(format!("{name}{smooth}_%02d.png"));
            let o = texmap(&[
                "render",
                "--quiet",
                &input,
                "--frames",
                "5:12:3",
                "--smooth",
                smooth,
                "--size",
                "200x150",
                "-o",
                out.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
        }
    }
    for smooth in ["0", "2"] {
        for f in [5, 8, 11] {
            let read = |name: &str| {
                std::fs::read(dir.path().join(format!("{name}{smooth}_{f:02}.png"))).unwrap()
            };
            assert!(
                read("whole") == read("parts"),
                "frame {f}, --smooth {smooth}"
            );
        }
    }
    // The shell's order: read as given, and said.
    let mut shell: Vec<String> = (0..12)
        .map(|k| seq(&format!("ovito/dump.{k}.lammpstrj")))
        .collect();
    shell.sort();
    let mut args = vec!["info"];
    args.extend(shell.iter().map(String::as_str));
    let o = texmap(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("quote the pattern"), "{}", stderr(&o));
    let o = texmap(&["info", dir.path().join("none.*.xtc").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no file matches"), "{}", stderr(&o));
}

/// `--axes-tripod`: seen down z the x axis points right and y up; seen down x, y points right
/// and z up (the automatic camera's up); `cell` labels the cell's vectors.
#[test]
fn the_axes_tripod_turns_with_the_view() {
    let dir = tempfile::tempdir().unwrap();
    let poscar = data("vasp/POSCAR_rutile");
    // The centroid of the pixels where channel k leads the others by 60, in the tripod's
    // corner (the panel at the bottom left, 4 px in, 60 px square at this size).
    let centroid = |img: &image::RgbImage, k: usize| {
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
        for (x, y, p) in img.enumerate_pixels() {
            let lead = (0..3)
                .filter(|&j| j != k)
                .all(|j| p[k] as i32 > p[j] as i32 + 60);
            if x < 64 && y >= img.height() - 64 && lead {
                sx += x as f64 - 34.0;
                sy += y as f64 - (img.height() - 34) as f64;
                n += 1.0;
            }
        }
        assert!(n > 10.0, "channel {k}: {n} pixels");
        (sx / n, sy / n)
    };
    let base = [poscar.as_str(), "--size", "320x240", "--axes-tripod", "xyz"];
    let img = render_rgb(dir.path(), "z.png", &[&base[..], &["--view", "z"]].concat());
    let (red, green) = (centroid(&img, 0), centroid(&img, 1));
    assert!(red.0 > 5.0 && red.1.abs() < 4.0, "x right: {red:?}");
    assert!(green.1 < -5.0 && green.0.abs() < 4.0, "y up: {green:?}");
    let img = render_rgb(dir.path(), "x.png", &[&base[..], &["--view", "x"]].concat());
    let (green, blue) = (centroid(&img, 1), centroid(&img, 2));
    assert!(green.0 > 5.0 && green.1.abs() < 4.0, "y right: {green:?}");
    assert!(blue.1 < -5.0 && blue.0.abs() < 4.0, "z up: {blue:?}");
    let plain = render_rgb(
        dir.path(),
        "plain.png",
        &[poscar.as_str(), "--size", "320x240", "--view", "z"],
    );
    assert!(img != plain, "the tripod is drawn");
    let img = render_rgb(
        dir.path(),
        "cell.png",
        &[
            poscar.as_str(),
            "--size",
            "320x240",
            "--axes-tripod",
            "cell",
            "--view",
            "z",
        ],
    );
    // Rutile's a and b are x and y: the same picture but for the labels.
    let (red_cell, green_cell) = (centroid(&img, 0), centroid(&img, 1));
    assert!(
        red_cell.0 > 5.0 && green_cell.1 < -5.0,
        "{red_cell:?} {green_cell:?}"
    );
}

/// `--dpi`: a size in print units becomes pixels at the resolution, and the PNG carries it in a
/// pHYs chunk as the PNG specification lays it out (read here from the bytes); without --dpi no
/// pHYs is written; units without --dpi, and --dpi with a movie, are usage errors.
#[test]
fn dpi_sizes_print_units_and_is_written_into_the_png() {
    let dir = tempfile::tempdir().unwrap();
    let input = data("topo_mda.gro");
    let out = dir.path().join("fig.png");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--quiet",
            input.as_str(),
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        texmap(&args)
    };
    // The pHYs chunk's (x, y, unit) from the PNG's chunks: length, type, data, CRC.
    let phys = |bytes: &[u8]| -> Option<(u32, u32, u8)> {
        let mut at = 8;
        while at + 8 <= bytes.len() {
            let len = u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
            let kind = &bytes[at + 4..at + 8];
            let data = &bytes[at + 8..at + 8 + len];
            if kind == b"pHYs" {
                let x = u32::from_be_bytes(data[0..4].try_into().unwrap());
                let y = u32::from_be_bytes(data[4..8].try_into().unwrap());
                return Some((x, y, data[8]));
            }
            at += 12 + len;
        }
        None
    };
    // 254 dpi is 100 pixels a centimetre, 10,000 a metre.
    let o = run(&["--size", "5cmx40mm", "--dpi", "254"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (500, 400));
    assert_eq!(
        phys(&std::fs::read(&out).unwrap()),
        Some((10_000, 10_000, 1))
    );
    // Pixels at 300 dpi: the same picture as without --dpi, and the chunk.
    let o = run(&["--size", "320x240", "--dpi", "300"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let with = image::open(&out).unwrap().to_rgba8();
    assert_eq!(
        phys(&std::fs::read(&out).unwrap()),
        Some((11_811, 11_811, 1))
    );
    let o = run(&["--size", "320x240"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(phys(&std::fs::read(&out).unwrap()), None);
    assert!(with == image::open(&out).unwrap().to_rgba8());
    for bad in [
        &["--size", "5cmx4cm"][..],
        &["--dpi", "0"],
        &["--dpi", "nan"],
        &["--size", "500inx500in", "--dpi", "300"],
    ] {
        let o = run(bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
    }
    let movie = dir.path().join("m.apng");
    let o = texmap(&[
        "render",
        "--quiet",
        input.as_str(),
        "--dpi",
        "300",
        "-o",
        movie.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// `--property NAME=FILE`: numbers numpy wrote (MDAnalysis's RMSF as a column, per-frame
/// distances as CSV rows) select exactly the atoms numpy selects with them: the picture of
/// `prop rmsf > m` is the picture of those atoms' indices, in frame 3 with the frame's row too;
/// a wrong count, a frame past the rows and a bad spec are errors.
#[test]
fn per_atom_values_from_files_colour_and_select() {
    let dir = tempfile::tempdir().unwrap();
    let values = |name: &str| {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/values")
            .join(name)
            .to_string_lossy()
            .into_owned()
    };
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(values("values_reference.json")).unwrap())
            .unwrap();
    let indices = |key: &str| -> String {
        let list: Vec<String> = reference[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.to_string())
            .collect();
        format!("index {}", list.join(" "))
    };
    let (xtc, gro) = (data("topo_mda.xtc"), data("topo_mda.gro"));
    let rmsf = format!("rmsf={}", values("rmsf.txt"));
    let dist = format!("dist={}", values("dist.csv"));
    let base = [
        xtc.as_str(),
        "--topology",
        gro.as_str(),
        "--size",
        "240x180",
        "--frames",
        "3",
    ];
    // The picture of the atoms a property selects against the picture of numpy's indices.
    let same = |property: &str, select: &str, key: &str| {
        let args = [&base[..], &["--property", property, "--select", select]].concat();
        let picked = render_rgb(dir.path(), &format!("{key}.png"), &args);
        let by_index = indices(key);
        let args = [&base[..], &["--select", &by_index]].concat();
        picked == render_rgb(dir.path(), &format!("{key}_listed.png"), &args)
    };
    let m = reference["rmsf_threshold"].as_f64().unwrap();
    let by_value = format!("prop rmsf > {m}");
    assert!(
        same(&rmsf, &by_value, "rmsf_above"),
        "{by_value} selects numpy's atoms"
    );
    assert!(
        same(&dist, "prop dist < 6", "dist_frame3_below_6"),
        "frame 3 takes row 3"
    );
    // Coloured by it: a colour bar titled with the name.
    let plain = render_rgb(dir.path(), "plain.png", &base);
    let coloured = render_rgb(
        dir.path(),
        "rmsf.png",
        &[&base[..], &["--property", &rmsf, "--color-by", "rmsf"]].concat(),
    );
    assert!(plain != coloured);
    // Errors: another atom count (exit 1, naming the file and line), too few rows, bad specs.
    let short = dir.path().join("short.txt");
    std::fs::write(&short, "1\n2\n3\n").unwrap();
    let out = dir.path().join("x.png");
    let run = |spec: &str, frames: &str| {
        texmap(&[
            "render",
            "--quiet",
            &xtc,
            "--topology",
            &gro,
            "--frames",
            frames,
            "--property",
            spec,
            "-o",
            out.to_str().unwrap(),
        ])
    };
    let o = run(&format!("short={}", short.display()), "0");
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("short.txt") && stderr(&o).contains("3 values for 66 atoms"),
        "{}",
        stderr(&o)
    );
    let rows = dir.path().join("rows.txt");
    std::fs::write(&rows, format!("{}\n", vec!["1"; 66].join(" "))).unwrap();
    let o = run(&format!("r={}", rows.display()), "0:2");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("1 rows"), "{}", stderr(&o));
    for bad in ["noequals", "bad name=x.txt", "=x.txt"] {
        assert_eq!(run(bad, "0").status.code(), Some(2), "{bad}");
    }
    assert!(!out.exists());
}

/// An AMBER ASCII trajectory (ParmEd's mdcrd of amber_mda.ncdf's frames, md-io's
/// tests/data/amber_ascii) read with its prmtop: the atom count and the truncated octahedron's
/// angles come from the topology, and a frame draws as the NetCDF's same frame does (the
/// positions differ by the mdcrd's 0.0005 Å rounding). Without a topology: exit 1, naming
/// --topology.
#[test]
fn amber_ascii_trajectory_reads_its_atom_count_from_the_prmtop() {
    let o = texmap(&[
        "info",
        &data("amber_ascii/box.mdcrd"),
        "--topology",
        &data("amber_ascii/truncoct.parm7"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "mdcrd");
    assert_eq!(
        (v["atoms"].as_u64(), v["frames"].as_u64()),
        (Some(66), Some(5))
    );
    let b: Vec<f64> = (0..6).map(|k| v["box"][k].as_f64().unwrap()).collect();
    assert_eq!(&b[..3], &[18.0, 18.5, 19.0]);
    assert!(
        b[3..].iter().all(|a| (a - 109.4712206).abs() < 1e-6),
        "{b:?}"
    );

    let o = texmap(&["info", &data("amber_ascii/box.mdcrd")]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--topology"), "{}", stderr(&o));

    let dir = tempfile::tempdir().unwrap();
    let draw = |traj: &str, name: &str| {
        let out = dir.path().join(name);
        let o = texmap(&[
            "render",
            &data(traj),
            "--topology",
            &data("prmtop_parmed.prmtop"),
            "--frames",
            "2",
            "--size",
            "160x120",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{traj}: {}", stderr(&o));
        out
    };
    let a = draw("amber_ascii/nobox.mdcrd", "mdcrd.png");
    let b = draw("amber_mda.ncdf", "ncdf.png");
    let d = mean_abs_diff(&a, &b);
    assert!(lit(&a) > 1000, "{}", lit(&a));
    assert!(d < 0.5, "mean |difference| {d}");
}

/// AutoDock Vina's docked poses (md-io's tests/data/pdbqt: Vina 1.2.7 on Meeko's receptor and
/// ligand) drawn in their receptor, one pose per frame, each captioned by its Vina score: the
/// caption differs between poses of different scores and the ligand moves.
#[test]
fn vina_poses_render_in_their_receptor_with_their_scores() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pose_%02d.png");
    let o = texmap(&[
        "render",
        &data("pdbqt/poses.pdbqt"),
        "--add",
        &data("pdbqt/receptor.pdbqt"),
        "--rep",
        "prop file == 0=ball-stick",
        "--rep",
        "prop file == 1=licorice",
        "--label",
        "{title}",
        "--frames",
        "0:2",
        "--size",
        "240x180",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let a = dir.path().join("pose_00.png");
    let b = dir.path().join("pose_01.png");
    assert!(lit(&a) > 1000);
    assert!(mean_abs_diff(&a, &b) > 0.1);
    // The caption strip at the top left differs (-4.268 against -4.517 kcal/mol).
    let top = |p: &Path| {
        let img = image::open(p).unwrap().to_rgb8();
        image::imageops::crop_imm(&img, 0, 0, 120, 14).to_image()
    };
    assert_ne!(top(&a), top(&b));
    let o = texmap(&["info", &data("pdbqt/poses.pdbqt")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (v["format"].as_str(), v["frames"].as_u64()),
        (Some("pdbqt"), Some(5))
    );
}

/// `--clusters`: the copper precipitate of md-io's clusters fixture (written by OVITO), drawn
/// alone by `--select 'prop cluster == 0'`, is the same picture, byte for byte, as the atoms of
/// OVITO's largest cluster selected by index; `--color-by cluster` without `--clusters`, or
/// `--cluster-atoms` alone, is a usage error.
#[test]
fn clusters_select_the_precipitate() {
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("clusters");
    let file = base.join("fecu.xyz").to_string_lossy().into_owned();
    let v = read_json(&base.join("clusters_reference.json"));
    let largest: Vec<String> = v[2]["ids"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .filter(|(_, id)| id.as_i64() == Some(0))
        .map(|(i, _)| i.to_string())
        .collect();
    assert_eq!(largest.len(), 81);
    let by_index = format!("index {}", largest.join(" "));
    let render = |select: &str, out: &str| {
        let out = dir.path().join(out);
        let o = texmap(&[
            "render",
            &file,
            "--clusters",
            "2.9",
            "--cluster-atoms",
            "element Cu",
            "--color-by",
            "cluster",
            "--select",
            select,
            "--size",
            "200x200",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(out).unwrap()
    };
    let ours = render("prop cluster == 0", "ours.png");
    assert_eq!(ours, render(&by_index, "ovito.png"));
    assert_ne!(ours, render("prop cluster == 1", "second.png"));
    let o = texmap(&["render", &file, "--color-by", "cluster", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--clusters R"));
    let o = texmap(&[
        "render",
        &file,
        "--cluster-atoms",
        "element Cu",
        "-o",
        "y.png",
    ]);
    assert_eq!(o.status.code(), Some(2));
}

/// `--strain` and `--centrosymmetry`: on md-io's strain fixture (a sheared, bulged copper slab
/// and its reference, written by OVITO), the atoms `--select 'prop shear_strain > 0.045'` draws
/// against `--displacement-reference` (a file, or frame 0 of a trajectory of both) are the
/// same picture, byte for byte, as OVITO's atoms above that strain selected by index; so are the
/// atoms above 2 Å² of OVITO's matching-mode centrosymmetry. Strain colours without `--strain`,
/// and a bad neighbour count, are usage errors.
#[test]
fn strain_and_centrosymmetry_select_ovitos_atoms() {
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("strain");
    let (reference, current) = (base.join("ref.xyz"), base.join("cur.xyz"));
    let json = |name: &str| read_json(&base.join(name));
    // OVITO's atoms above `threshold`, as an index selection (no value near the threshold).
    let above = |values: &serde_json::Value, threshold: f64| {
        let v: Vec<f64> = values
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert!(v.iter().all(|x| (x - threshold).abs() > 1e-4 * threshold));
        let picked: Vec<String> = (0..v.len())
            .filter(|&i| v[i] > threshold)
            .map(|i| i.to_string())
            .collect();
        assert!(
            picked.len() > 10 && picked.len() < v.len() / 2,
            "{}",
            picked.len()
        );
        format!("index {}", picked.join(" "))
    };
    let render = |file: &Path, extra: &[&str], select: &str, out: &str| {
        let head = [
            file.to_str().unwrap(),
            "--select",
            select,
            "--size",
            "200x200",
        ];
        render_png(dir.path(), &[&head[..], extra].concat(), out)
    };
    let strained = above(&json("strain_reference.json")["shear"], 0.045);
    let strain = [
        "--strain",
        "3",
        "--displacement-reference",
        reference.to_str().unwrap(),
    ];
    let ours = render(&current, &strain, "prop shear_strain > 0.045", "ours.png");
    assert_eq!(ours, render(&current, &[], &strained, "ovito.png"));
    // The same two configurations as frames 0 and 1 of one trajectory.
    let both = dir.path().join("both.xyz");
    let mut text = std::fs::read(&reference).unwrap();
    text.extend(std::fs::read(&current).unwrap());
    std::fs::write(&both, text).unwrap();
    let framed = [
        "--frames",
        "1",
        "--strain",
        "3",
        "--displacement-reference",
        "0",
    ];
    assert_eq!(
        ours,
        render(&both, &framed, "prop shear_strain > 0.045", "framed.png")
    );

    let matching = &json("centro_reference.json")[4];
    assert_eq!(
        (matching["file"].as_str(), matching["mode"].as_str()),
        (Some("cur.xyz"), Some("matching"))
    );
    let asymmetric = above(&matching["csp"], 2.0);
    let csp = ["--centrosymmetry", "12", "--centrosymmetry-matching"];
    assert_eq!(
        render(&current, &csp, "prop centrosymmetry > 2", "csp.png"),
        render(&current, &[], &asymmetric, "ovito_csp.png")
    );

    for (args, needs) in [
        (vec!["--color-by", "shear_strain"], "--strain R"),
        (vec!["--centrosymmetry", "7"], "not an even number"),
        (vec!["--centrosymmetry-matching"], "--centrosymmetry N"),
    ] {
        let mut all = vec!["render", current.to_str().unwrap()];
        all.extend(args);
        all.extend(["-o", "x.png"]);
        let o = texmap(&all);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(needs), "{}", stderr(&o));
    }
}

/// `--compute`: on md-io's expression fixture (a LAMMPS dump OVITO wrote, with OVITO's Compute
/// property values), the atoms `--compute 'speed=...' --select 'prop speed > 3'` draws are the
/// same picture, byte for byte, as OVITO's atoms above that speed selected by index, and a
/// second formula may use the first; a formula that does not parse is a usage error naming the
/// column, one naming what the file lacks a runtime error listing what it has.
#[test]
fn computed_properties_select_ovitos_atoms() {
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("expr");
    let file = base.join("atoms.lammpstrj").to_string_lossy().into_owned();
    let v = read_json(&base.join("expr_reference.json"));
    assert_eq!(v[0]["formula"], "sqrt(vx^2 + vy^2 + vz^2)");
    let speeds: Vec<f64> = v[0]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(speeds.iter().all(|s| (s - 3.0).abs() > 1e-4));
    let fast: Vec<String> = (0..speeds.len())
        .filter(|&i| speeds[i] > 3.0)
        .map(|i| i.to_string())
        .collect();
    assert!(fast.len() > 100 && fast.len() < 500, "{}", fast.len());
    let render = |extra: &[&str], out: &str| {
        render_png(
            dir.path(),
            &[&[file.as_str(), "--size", "200x200"], extra].concat(),
            out,
        )
    };
    let ours = render(
        &[
            "--compute",
            "speed=sqrt(vx^2 + vy^2 + vz^2)",
            "--compute",
            "fast=speed > 3",
            "--select",
            "prop fast == 1",
        ],
        "ours.png",
    );
    let by_index = format!("index {}", fast.join(" "));
    assert_eq!(ours, render(&["--select", &by_index], "ovito.png"));
    let o = texmap(&["render", &file, "--compute", "s=sqrt(vx^2+", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("column 11"), "{}", stderr(&o));
    let o = texmap(&["render", &file, "--compute", "s=sqrt(foo)", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no 'foo' (it has: x, y, z"),
        "{}",
        stderr(&o)
    );
}

/// `--wigner-seitz`: on md-io's Wigner–Seitz fixture (damaged iron and its perfect reference,
/// written by OVITO, with OVITO's analysis), the sites `--select 'prop site_occupancy != 1'`
/// draws (sites mode) are the same picture, byte for byte, as OVITO's vacancy and interstitial
/// sites selected by index in the reference; `--defect-table` and `--label` give OVITO's counts
/// per frame (none in the reference itself); the atoms mode keeps the frame's atoms; a
/// `{vacancies}` label without the analysis is a usage error.
#[test]
fn wigner_seitz_finds_ovitos_defects() {
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("wigner_seitz");
    let reference = base.join("ref.xyz").to_string_lossy().into_owned();
    let both = dir.path().join("both.xyz");
    let mut text = std::fs::read(base.join("ref.xyz")).unwrap();
    text.extend(std::fs::read(base.join("cur.xyz")).unwrap());
    std::fs::write(&both, text).unwrap();
    let both = both.to_string_lossy().into_owned();
    let v = read_json(&base.join("ws_reference.json"));
    let defective: Vec<String> = v["occupancy"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .filter(|(_, o)| o.as_i64() != Some(1))
        .map(|(i, _)| i.to_string())
        .collect();
    assert_eq!(
        defective.len(),
        10 + 8,
        "ten vacancies, eight sites holding two"
    );
    let render = |args: &[&str], out: &str| {
        render_png(dir.path(), &[&["--size", "200x200"], args].concat(), out)
    };
    let table = dir.path().join("defects.csv");
    let ours = render(
        &[
            &both,
            "--frames",
            "1",
            "--wigner-seitz",
            "--displacement-reference",
            "0",
            "--select",
            "prop site_occupancy != 1",
            "--defect-table",
            table.to_str().unwrap(),
        ],
        "ours.png",
    );
    let by_index = format!("index {}", defective.join(" "));
    assert_eq!(
        ours,
        render(&[&reference, "--select", &by_index], "ovito.png")
    );
    let want = format!(
        "frame,vacancies,interstitials\n1,{},{}\n",
        v["vacancies"], v["interstitials"]
    );
    assert_eq!(std::fs::read_to_string(&table).unwrap(), want);
    // Both frames, the first the reference: no defects there; the atoms drawn, with a caption.
    let captioned = [
        &both,
        "--wigner-seitz",
        "atoms",
        "--box-outline",
        "--select",
        "prop site_occupancy > 1",
        "--defect-table",
        table.to_str().unwrap(),
        "--label",
        "{vacancies} vacancies",
    ];
    let frames = dir.path().join("f%d.png");
    let mut all = vec!["render", "-q"];
    all.extend_from_slice(&captioned);
    all.extend(["-o", frames.to_str().unwrap()]);
    let o = texmap(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("f1.png").exists());
    assert_eq!(
        std::fs::read_to_string(&table).unwrap(),
        "frame,vacancies,interstitials\n0,0,0\n1,10,8\n"
    );
    let o = texmap(&["render", &both, "--label", "{vacancies}", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("add --wigner-seitz"), "{}", stderr(&o));
}

/// `--freeze`: over a trajectory of md-io's strain fixture (a copper slab, then the same atoms
/// sheared and wrapped), `--compute 'x0=x' --freeze x0 --select 'prop x0 < 11'` keeps, in both
/// frames, the atoms whose x was below 11 Å in the first, which the test reads from the file
/// itself: the pictures are those of the same atoms selected by index, byte for byte. Without
/// `--freeze` the second frame's selection follows the atoms' new x, and differs. A frozen name
/// the frame lacks is an error naming what it has.
#[test]
fn frozen_properties_follow_the_atoms() {
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("strain");
    let first = std::fs::read_to_string(base.join("ref.xyz")).unwrap();
    let both = dir.path().join("both.xyz");
    std::fs::write(
        &both,
        first.clone() + &std::fs::read_to_string(base.join("cur.xyz")).unwrap(),
    )
    .unwrap();
    let both = both.to_string_lossy().into_owned();
    let xs: Vec<f64> = first
        .lines()
        .skip(2)
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect();
    assert!(xs.iter().all(|x| (x - 11.0).abs() > 1e-3));
    let picked: Vec<String> = (0..xs.len())
        .filter(|&i| xs[i] < 11.0)
        .map(|i| i.to_string())
        .collect();
    assert!(picked.len() > 200 && picked.len() < xs.len() / 2);
    let render = |extra: &[&str], stem: &str| {
        let out = dir.path().join(format!("{stem}%d.png"));
        let mut args = vec!["render", both.as_str(), "--size", "160x120", "-q"];
        args.extend_from_slice(extra);
        args.extend(["-o", out.to_str().unwrap()]);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        [0, 1].map(|k| std::fs::read(dir.path().join(format!("{stem}{k}.png"))).unwrap())
    };
    let frozen = render(
        &[
            "--compute",
            "x0=x",
            "--freeze",
            "x0",
            "--select",
            "prop x0 < 11",
        ],
        "frozen",
    );
    let by_index = format!("index {}", picked.join(" "));
    assert_eq!(frozen, render(&["--select", &by_index], "index"));
    let moving = render(&["--compute", "x0=x", "--select", "prop x0 < 11"], "moving");
    assert_eq!(moving[0], frozen[0]);
    assert_ne!(moving[1], frozen[1]);
    let o = texmap(&["render", &both, "--freeze", "x0", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--freeze: freezing 'x0'"),
        "{}",
        stderr(&o)
    );
}

/// `--voronoi`: on md-io's Voronoi fixture (a dense disordered packing OVITO wrote, with OVITO's
/// Voronoi analysis), the atoms `--select 'prop voronoi_faces >= 15'` draws are OVITO's atoms
/// with 15 faces or more, byte for byte; a frame without a periodic cell is refused.
#[test]
fn voronoi_selects_ovitos_atoms() {
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("voronoi");
    let file = base.join("glass.xyz").to_string_lossy().into_owned();
    let v = read_json(&base.join("voronoi_reference.json"));
    assert_eq!(v[1]["file"], "glass.xyz");
    let many: Vec<String> = v[1]["faces"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .filter(|(_, f)| f.as_u64().unwrap() >= 15)
        .map(|(i, _)| i.to_string())
        .collect();
    assert!(many.len() > 100 && many.len() < 600, "{}", many.len());
    let render = |extra: &[&str], out: &str| {
        render_png(
            dir.path(),
            &[&[file.as_str(), "--size", "160x120"], extra].concat(),
            out,
        )
    };
    let ours = render(
        &["--voronoi", "--select", "prop voronoi_faces >= 15"],
        "ours.png",
    );
    let by_index = format!("index {}", many.join(" "));
    assert_eq!(ours, render(&["--select", &by_index], "ovito.png"));
    let open = dir.path().join("open.xyz");
    std::fs::write(&open, "2\nno cell\nAr 0 0 0\nAr 3 0 0\n").unwrap();
    let o = texmap(&["render", open.to_str().unwrap(), "--voronoi", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--voronoi: the frame has no cell periodic along all three edges"),
        "{}",
        stderr(&o)
    );
}

/// `--grains`, `--color-by ipf`, `--grain-table`: on md-io's grain fixtures (polycrystals OVITO
/// wrote, with OVITO's Polyhedral template matching and Grain segmentation). With the orphans
/// kept out, the atoms `--select 'prop grain == 1'` draws are OVITO's grain-1 atoms that
/// adaptive CNA calls crystalline, byte for byte; `--color-by ipf` colours every atom as the
/// inverse pole figure of OVITO's orientation colours it (drawn by `--color` rules); the table
/// lists OVITO's grain count.
#[test]
fn grains_and_orientation_colours_are_ovitos() {
    use texmap_md_io::orientation::{Symmetry, ipf_colour};
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("grains");
    let refs = read_json(&base.join("grains_reference.json"));
    let case = &refs["systems"][0];
    assert_eq!(case["file"], "fcc_poly.xyz");
    let path = base.join("fcc_poly.xyz");
    let file = path.to_string_lossy().into_owned();
    let mut frame = texmap_md_io::Frame::new();
    let mut traj = texmap_md_io::Trajectory::open(&path).unwrap();
    assert!(traj.read_next(&mut frame).unwrap());
    let cna = texmap_md_io::cna::classify(&frame);
    let column = |key: &str| case[key].as_array().unwrap().clone();
    let (ptm, grain, q) = (column("structure"), column("grain"), column("orientation"));
    let render = |extra: &[&str], out: &str| {
        render_png(
            dir.path(),
            &[&[file.as_str(), "--size", "200x160"], extra].concat(),
            out,
        )
    };

    let grain1: Vec<usize> = (0..cna.len())
        .filter(|&i| grain[i] == 1 && cna[i] != texmap_md_io::cna::StructureType::Other)
        .collect();
    assert!(grain1.len() > 500, "{}", grain1.len());
    let ours = render(
        &[
            "--grains",
            "--grain-keep-orphans",
            "--select",
            "prop grain == 1",
        ],
        "ours.png",
    );
    assert_eq!(
        ours,
        render(&["--select", &index_ranges(&grain1)], "ovito.png")
    );

    // The atoms crystalline to both, coloured from OVITO's quaternions (channels in eighths,
    // as the renderer rounds them).
    let both: Vec<usize> = (0..cna.len())
        .filter(|&i| cna[i] != texmap_md_io::cna::StructureType::Other)
        .filter(|&i| ptm[i].as_i64() == Some(cna[i] as i64))
        .collect();
    let mut groups: std::collections::BTreeMap<String, Vec<usize>> = Default::default();
    for &i in &both {
        let v: Vec<f64> = q[i]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let c = ipf_colour([v[0], v[1], v[2], v[3]], Symmetry::Cubic, [0.0, 0.0, 1.0]);
        let hex = c.map(|c| ((c * 7.0).round() / 7.0 * 255.0).round() as u8);
        let hex = format!("#{:02x}{:02x}{:02x}", hex[0], hex[1], hex[2]);
        groups.entry(hex).or_default().push(i);
    }
    let select = index_ranges(&both);
    let ours = render(&["--select", &select, "--color-by", "ipf"], "ipf.png");
    let mut rules = vec!["--select".to_string(), select.clone()];
    for (hex, atoms) in &groups {
        rules.push("--color".into());
        rules.push(format!("{}={hex}", index_ranges(atoms)));
    }
    let rules: Vec<&str> = rules.iter().map(|s| s.as_str()).collect();
    assert_eq!(ours, render(&rules, "ipf_ovito.png"));

    let table = dir.path().join("grains.csv");
    render(
        &["--grains", "--grain-table", table.to_str().unwrap()],
        "table.png",
    );
    let text = std::fs::read_to_string(&table).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(
        text.lines().next(),
        Some("frame,grain,atoms,crystalline,structure,qx,qy,qz,qw")
    );
    assert_eq!(rows.len(), case["grain_size"].as_array().unwrap().len());
    assert!(
        rows.iter()
            .all(|r| r.starts_with("0,") && r.contains(",fcc,"))
    );

    // The caption counts them; without --grains it is refused.
    let count = format!("{} grains", rows.len());
    assert_eq!(
        render(
            &["--color-by", "grain", "--label", "{grains} grains"],
            "label.png"
        ),
        render(
            &["--color-by", "grain", "--label", &count],
            "label_text.png"
        )
    );
    let o = texmap(&["render", &file, "--label", "{grains}", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("add --grains"), "{}", stderr(&o));
    // Bad usage: an angle out of range, grain options without --grains.
    for (args, says) in [
        (
            vec!["--grains", "45"],
            "is not an angle from 0 to 30 degrees",
        ),
        (
            vec!["--grains", "0"],
            "is not an angle from 0 to 30 degrees",
        ),
        (
            vec!["--grain-table", "g.csv"],
            "are about the grains: add --grains",
        ),
        (
            vec!["--grain-min-size", "10"],
            "are about the grains: add --grains",
        ),
    ] {
        let mut all = vec!["render", file.as_str(), "-o", "x.png"];
        all.extend(args.iter());
        let o = texmap(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
    }
}

/// A selection of the atoms `atoms` (ascending), runs as ranges: `index 3:7 9 12:40`.
fn index_ranges(atoms: &[usize]) -> String {
    let mut out = String::from("index");
    let mut k = 0;
    while k < atoms.len() {
        let mut end = k;
        while end + 1 < atoms.len() && atoms[end + 1] == atoms[end] + 1 {
            end += 1;
        }
        if end > k {
            out.push_str(&format!(" {}:{}", atoms[k], atoms[end]));
        } else {
            out.push_str(&format!(" {}", atoms[k]));
        }
        k = end + 1;
    }
    out
}

/// `--color-by diamond` and `--select 'not diamond cubic'`: on md-io's diamond fixture (a
/// silicon slab OVITO wrote, with OVITO's Identify diamond structure types), the colours are
/// OVITO's types in OVITO's colours drawn by `--color` rules, and the selection draws OVITO's
/// non-cubic atoms (the surfaces' first and second neighbours), byte for byte.
#[test]
fn diamond_types_colour_and_select_as_ovitos() {
    let dir = tempfile::tempdir().unwrap();
    let base = ovito_data("diamond");
    let refs = read_json(&base.join("diamond_reference.json"));
    let case = &refs[2];
    assert_eq!(case["file"], "slab.xyz");
    let file = base.join("slab.xyz").to_string_lossy().into_owned();
    let types: Vec<usize> = case["structure"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_u64().unwrap() as usize)
        .collect();
    let render = |extra: &[&str], out: &str| {
        render_png(
            dir.path(),
            &[&[file.as_str(), "--size", "200x160"], extra].concat(),
            out,
        )
    };
    let mut rules: Vec<String> = Vec::new();
    for (t, rgb) in texmap_md_scene::DIAMOND_COLORS.iter().enumerate() {
        let atoms: Vec<usize> = (0..types.len()).filter(|&i| types[i] == t).collect();
        if atoms.is_empty() {
            continue;
        }
        let hex = rgb.map(|c| (c * 255.0).round() as u8);
        rules.push("--color".into());
        rules.push(format!(
            "{}=#{:02x}{:02x}{:02x}",
            index_ranges(&atoms),
            hex[0],
            hex[1],
            hex[2]
        ));
    }
    assert!(rules.len() >= 6, "cubic, first and second neighbours");
    let rules: Vec<&str> = rules.iter().map(|s| s.as_str()).collect();
    assert_eq!(
        render(&["--color-by", "diamond"], "ours.png"),
        render(&rules, "ovito.png")
    );
    let defects: Vec<usize> = (0..types.len()).filter(|&i| types[i] != 1).collect();
    assert_eq!(
        render(&["--select", "not diamond cubic"], "sel.png"),
        render(&["--select", &index_ranges(&defects)], "sel_ovito.png")
    );
}

/// VMD's and PyMOL's style names are understood (NewCartoon, VDW, sticks); a --rep whose
/// selection picks no atom (the file's sodium residues are `NA+`, not `NA`) warns with the
/// residue names there are, and the same image is drawn once the name is right; a protein
/// chain cut by the periodic box is pointed to --pbc unwrap.
#[test]
fn style_aliases_and_a_rep_that_selects_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let o = render_adk_frame0(
        "96x72",
        &[
            "--rep",
            "protein=NewCartoon",
            "--rep",
            "resname NA=VDW",
            "-o",
            a.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("\"resname NA=VDW\" selects none of frame 0's atoms")
            && stderr(&o).contains(" NA+ "),
        "{}",
        stderr(&o)
    );
    let o = render_adk_frame0(
        "96x72",
        &[
            "--rep",
            "protein=cartoon",
            "--rep",
            "resname NA+=spacefill",
            "-o",
            b.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("selects none"), "{}", stderr(&o));
    assert!(std::fs::read(&a).unwrap() != std::fs::read(&b).unwrap());
    // The protein crosses the box's faces in this frame: a hint, gone with --pbc unwrap.
    assert!(
        stderr(&o).contains("crosses a face of the periodic box 4 time(s)"),
        "{}",
        stderr(&o)
    );
    let o = render_adk_frame0(
        "96x72",
        &[
            "--rep",
            "protein=newcartoon",
            "--pbc",
            "unwrap",
            "-o",
            b.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("periodic box"), "{}", stderr(&o));
}

/// A GROMACS run input as the whole input (its starting frame) and as the topology: GROMACS
/// 2022.5's file of two peptide chains in TIP4P water with ions (md-io's data/tpr/gen_tpr.py;
/// the reference is `gmx dump` and `gmx editconf` of the same file).
#[test]
fn gromacs_tpr_renders_and_converts_as_gromacs_reads_it() {
    let tpr = data("tpr/peptide.tpr.gz");
    let mut text = String::new();
    std::io::Read::read_to_string(
        &mut flate2::read::GzDecoder::new(
            std::fs::File::open(data("tpr/reference.json.gz")).unwrap(),
        ),
        &mut text,
    )
    .unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    let want = &r["peptide.tpr.gz"];
    let o = texmap(&["info", &tpr]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "tpr");
    assert_eq!(v["atoms"], want["n_atoms"]);
    assert_eq!(v["frames"], 1);
    // Molecule types are the segments, counted as MDAnalysis's moltypes.
    let mut counts: Vec<(String, u64)> = Vec::new();
    for m in want["moltypes"].as_array().unwrap() {
        let m = m.as_str().unwrap();
        match counts.iter_mut().find(|(k, _)| k == m) {
            Some((_, n)) => *n += 1,
            None => counts.push((m.to_string(), 1)),
        }
    }
    assert_eq!(v["segments"], serde_json::json!(counts));
    // The protein written as PDB: gmx dump's positions to the PDB's 0.001 Å, gmx editconf's
    // residue numbers.
    let dir = tempfile::tempdir().unwrap();
    let pdb = dir.path().join("protein.pdb");
    let o = texmap(&[
        "convert",
        &tpr,
        "--select",
        "segid Protein_chain_A Protein_chain_B",
        "-o",
        pdb.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&pdb).unwrap();
    let atoms: Vec<&str> = text.lines().filter(|l| l.starts_with("ATOM")).collect();
    let n = want["moltypes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m.as_str().unwrap().starts_with("Protein"))
        .count();
    assert_eq!(atoms.len(), n);
    for (k, line) in atoms.iter().enumerate() {
        let x: Vec<f64> = (0..3)
            .map(|d| line[30 + 8 * d..38 + 8 * d].trim().parse().unwrap())
            .collect();
        let p = &want["positions"][k];
        for d in 0..3 {
            assert!(
                (x[d] - p[d].as_f64().unwrap()).abs() <= 6e-4,
                "atom {k}: {line}"
            );
        }
        let resid: i64 = line[22..26].trim().parse().unwrap();
        assert_eq!(resid, want["resids"][k].as_i64().unwrap(), "{line}");
        // Chain A holds residues 1-8 of the PDB, chain B 20-27 (pdb2gmx -chainsep id).
        assert_eq!(&line[21..22], if resid <= 8 { "A" } else { "B" }, "{line}");
    }
    // Drawn with the .tpr's own bonds, molecules made whole across the box.
    let png = render_png(
        dir.path(),
        &[
            &tpr,
            "--select",
            "not segid SOL",
            "--bonds",
            "topology",
            "--pbc",
            "unwrap",
            "--style",
            "licorice",
            "--size",
            "96x72",
        ],
        "tpr.png",
    );
    assert!(png.starts_with(b"\x89PNG"));
    // Mass-weighted radii of gyration with the .tpr's masses (TIP4P's massless sites
    // included), as MDAnalysis computes them from the same file.
    let csv = dir.path().join("rg.csv");
    for (select, key) in [
        ("all", "rgyr_all"),
        ("segid Protein_chain_A Protein_chain_B", "rgyr_protein"),
    ] {
        let o = texmap(&[
            "convert",
            &tpr,
            "--gyration-table",
            csv.to_str().unwrap(),
            "--gyration-select",
            select,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&csv).unwrap();
        let row: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
        let rg: f64 = row[2].parse().unwrap();
        let want = want[key].as_f64().unwrap();
        assert!((rg - want).abs() < 2e-4, "{select}: rg {rg} against {want}");
    }
    // Beads of no element (type TA, 72 u): their masses come from the .tpr, where element
    // masses would have none.
    let o = texmap(&[
        "convert",
        &data("tpr/dummy_2022-rc1.tpr"),
        "--gyration-table",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn gromacs_index_groups_select_with_index() {
    // `gmx select -on`'s groups (tests/data/ndx/select.ndx) picked by `group`: the atoms
    // written are the group's, in its order, numbered as GROMACS numbered them.
    let tpr = data("tpr/peptide.tpr.gz");
    let ndx = data("ndx/select.ndx");
    let text = std::fs::read_to_string(&ndx).unwrap();
    let first: Vec<i64> = text
        .split('[')
        .nth(1)
        .unwrap()
        .lines()
        .skip(1)
        .flat_map(|l| l.split_whitespace().map(|w| w.parse::<i64>().unwrap()))
        .collect();
    assert_eq!(first.len(), 622);
    let dir = tempfile::tempdir().unwrap();
    let gro = dir.path().join("near.gro");
    let o = texmap(&[
        "convert",
        &tpr,
        "--index",
        &ndx,
        "--select",
        "group near_ions",
        "-o",
        gro.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = std::fs::read_to_string(&gro).unwrap();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[1].trim(), "622");
    let numbers: Vec<i64> = lines[2..2 + 622]
        .iter()
        .map(|l| l[15..20].trim().parse().unwrap())
        .collect();
    assert_eq!(numbers, first);
    // Groups in --rep, --measure and an analysis's selection too.
    let png = render_png(
        dir.path(),
        &[
            &tpr,
            "--index",
            &data("ndx/make_ndx.ndx"),
            "--rep",
            "group Protein=licorice",
            "--rep",
            "group C-alpha=ball-stick",
            "--measure",
            "group C-alpha and resid 1; group C-alpha and resid 3",
            "--size",
            "64x48",
        ],
        "groups.png",
    );
    assert!(png.starts_with(b"\x89PNG"));
    // A name no group has: a usage error listing the groups by number.
    let o = texmap(&[
        "convert",
        &tpr,
        "--index",
        &ndx,
        "--select",
        "group Protein",
        "-o",
        gro.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("has no group 'Protein'")
            && stderr(&o).contains("1 name_CA_and_molindex_2"),
        "{}",
        stderr(&o)
    );
    // A damaged index file: a runtime error naming its line.
    let bad = dir.path().join("bad.ndx");
    std::fs::write(&bad, "[ A ]\n1 2 3\n4 five 6\n").unwrap();
    let o = texmap(&[
        "convert",
        &tpr,
        "--index",
        bad.to_str().unwrap(),
        "--select",
        "group A",
        "-o",
        gro.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("bad.ndx: line 3, byte 14"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn ase_trajectories_render_and_convert() {
    // ASE's .traj (md-io/tests/data/asetraj, written by ASE 3.29): info, a picture with the
    // calculator's forces as arrows, and extended XYZ with the velocities ASE reads.
    let traj = data("asetraj/cu_md.traj");
    let o = texmap(&["info", &traj]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "ase-traj");
    assert_eq!(v["frames"], 4);
    assert_eq!(v["atoms"], 32);
    let dir = tempfile::tempdir().unwrap();
    let png = render_png(
        dir.path(),
        &[
            &traj,
            "--frames",
            "0",
            "--rep",
            "all=arrows",
            "--arrows",
            "f",
            "--size",
            "64x64",
        ],
        "forces.png",
    );
    assert!(png.starts_with(b"\x89PNG"));
    let xyz = dir.path().join("cu.xyz");
    let o = texmap(&[
        "convert",
        &traj,
        "--frames",
        "2",
        "-o",
        xyz.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut text = String::new();
    std::io::Read::read_to_string(
        &mut flate2::read::GzDecoder::new(
            std::fs::File::open(data("asetraj/reference.json.gz")).unwrap(),
        ),
        &mut text,
    )
    .unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    let want = &r["cu_md.traj"][2]["velocities"];
    let mut t = texmap_md_io::Trajectory::open(&xyz).unwrap();
    let mut f = texmap_md_io::Frame::new();
    t.read_next(&mut f).unwrap();
    for (i, v) in f.velocities.iter().enumerate() {
        for k in 0..3 {
            let w = want[i][k].as_f64().unwrap();
            assert!(
                (v[k] as f64 - w).abs() <= 1e-4 * w.abs().max(1.0),
                "atom {i}"
            );
        }
    }
}

#[test]
fn a_gromacs_topology_names_a_gro_as_its_tpr_does() {
    // md-io's tests/data/gromacs_top/amber (gen_top.py): grompp's preprocessed topology of two
    // chains in water and the .tpr grompp made of it give a .gro the same atoms and bonds.
    let gro = data("gromacs_top/amber/conf.gro.gz");
    let top = data("gromacs_top/amber/processed.top.gz");
    let tpr = data("gromacs_top/amber/topol.tpr.gz");
    let info = |topology: &str| -> serde_json::Value {
        let o = texmap(&["info", &gro, "--topology", topology]);
        assert!(o.status.success(), "{}", stderr(&o));
        let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["topology"]["file"] = serde_json::Value::Null;
        v
    };
    let (a, b) = (info(&top), info(&tpr));
    assert!(a["topology"]["bonds"].as_u64().unwrap() > 2000, "{a}");
    assert_eq!(a, b);
    // A selection by molecule type (segid) picks the same atoms, named the same.
    let dir = tempfile::tempdir().unwrap();
    let ca = |topology: &str, out: &str| -> Vec<String> {
        let out = dir.path().join(out);
        let o = texmap(&[
            "convert",
            &gro,
            "--topology",
            topology,
            "--select",
            "segid Protein_chain_A and name CA",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read_to_string(out)
            .unwrap()
            .lines()
            .filter(|l| l.starts_with("ATOM") || l.starts_with("HETATM"))
            .map(str::to_string)
            .collect()
    };
    let from_top = ca(&top, "top.pdb");
    assert_eq!(from_top.len(), 4, "{from_top:?}");
    assert_eq!(from_top, ca(&tpr, "tpr.pdb"));
    // The topology alone, gzipped: told from an AMBER prmtop by its content, with the charges
    // and masses it gives frames.
    let o = texmap(&["info", &top]);
    assert!(o.status.success(), "{}", stderr(&o));
    let t: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(t["format"], "gromacs-top", "{t}");
    assert_eq!(
        t["properties"],
        serde_json::json!(["charge", "mass"]),
        "{t}"
    );
    assert_eq!(t["bonds"], a["topology"]["bonds"], "{t}");
}

/// `--define` preprocesses a GROMACS topology as grompp's `define = -D...` does: md-io's
/// hand-written topology redefines the water hydrogens' type under HEAVY (4.032 u instead of
/// 1.008) and gives the ETH carbon C2 the charge CHARGE_C2; a define for a topology that is no
/// GROMACS one is a usage error.
#[test]
fn define_preprocesses_a_gromacs_topology() {
    let dir = tempfile::tempdir().unwrap();
    let top = data("gromacs_top/hand/system.top");
    // 16 atoms: two ETH (C1 C2 D), three waters, one ion.
    let xyz = dir.path().join("hand.xyz");
    let mut text = String::from("16\nhand-written\n");
    for i in 0..16 {
        text += &format!("X {} 0 0\n", 2.0 * i as f32);
    }
    std::fs::write(&xyz, text).unwrap();
    let masses = |defines: &[&str]| -> (Vec<f64>, Vec<f64>) {
        let out = dir.path().join("out.xyz");
        let mut args = vec![
            "convert",
            xyz.to_str().unwrap(),
            "--topology",
            &top,
            "-q",
            "--select",
            "name HW1 or name C2",
            "--columns",
            "mass,charge",
            "-o",
            out.to_str().unwrap(),
        ];
        for d in defines {
            args.extend(["--define", d]);
        }
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        let rows: Vec<Vec<f64>> = text
            .lines()
            .skip(2)
            .map(|l| {
                let w: Vec<&str> = l.split_whitespace().collect();
                w[w.len() - 2..]
                    .iter()
                    .map(|v| v.parse().unwrap())
                    .collect()
            })
            .collect();
        (
            rows.iter().map(|r| r[0]).collect(),
            rows.iter().map(|r| r[1]).collect(),
        )
    };
    // Two C2 then three HW1, in atom order.
    let (m, q) = masses(&[]);
    assert_eq!(m, [12.011, 12.011, 1.008, 1.008, 1.008]);
    assert_eq!(q[..2], [0.18, 0.18]);
    let (m, q) = masses(&["HEAVY", "CHARGE_C2=0.25"]);
    assert_eq!(m, [12.011, 12.011, 4.032, 4.032, 4.032]);
    assert_eq!(q[..2], [0.25, 0.25]);
    let gro = data("mda_vel.gro");
    let o = texmap(&["info", &gro]);
    assert!(o.status.success());
    let o = texmap(&[
        "convert",
        &gro,
        "--topology",
        &gro,
        "--define",
        "POSRES",
        "-o",
        dir.path().join("x.xyz").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--define POSRES"), "{}", stderr(&o));
}

#[test]
fn lammps_binary_dump_informs_renders_and_converts_as_its_text_dump() {
    // LAMMPS wrote both of the same frames (md-io's tests/data/lammps_bin/gen.sh; the text with
    // every float at %.17g): a triclinic box, 2 MPI ranks' chunks, a changing atom count.
    let (bin, text) = (
        data("lammps_bin/tri_np2.bin"),
        data("lammps_bin/tri_np2.lammpstrj"),
    );
    let info = |file: &str| {
        let o = texmap(&["info", file]);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let (mut b, t) = (info(&bin), info(&text));
    assert_eq!(
        b["format"], "lammps-bin",
        "told by its magic header, not its name"
    );
    b["format"] = t["format"].clone();
    assert_eq!(b, t);
    let dir = tempfile::tempdir().unwrap();
    let args = |f: &str| vec![f.to_string(), "--frames".into(), "0:1".into()];
    let png = |f: &str, out: &str| {
        let a = args(f);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        render_png(dir.path(), &a, out)
    };
    assert!(
        png(&bin, "bin.png") == png(&text, "text.png"),
        "the same image"
    );
    let convert = |f: &str, out: &str| {
        let out = dir.path().join(out);
        let o = texmap(&["convert", "-q", f, "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read_to_string(out).unwrap()
    };
    assert_eq!(convert(&bin, "bin.xyz"), convert(&text, "text.xyz"));
}

/// `--cell FILE.cell` on CP2K's NPT run (md-io's tests/data/cp2k): `convert --pbc wrap` puts
/// every atom where ASE's `wrap()` does with the cell of the frame's step, the written extended
/// XYZ carries that cell as its Lattice, and `info` reports the first step's box. A fixed
/// `--cell A,B,C` is the box of every frame; a bad `--cell` is a usage error (exit 2), a step
/// the cell file lacks a runtime error (exit 1) naming the frame and step, with no output.
#[test]
fn cp2k_positions_take_their_cells_from_the_cell_file() {
    let dir = tempfile::tempdir().unwrap();
    let pos = data("cp2k/ar_npt-pos-1.xyz");
    let cell = data("cp2k/ar_npt-1.cell");
    let out = dir.path().join("wrapped.xyz");
    let o = texmap(&[
        "convert",
        &pos,
        "--cell",
        &cell,
        "--pbc",
        "wrap",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = read_json(&ovito_data("cp2k/reference.json"));
    let table = texmap_md_io::cells::CellTable::read(&cell).unwrap();
    let mut t = texmap_md_io::Trajectory::open(&out).unwrap();
    let mut f = texmap_md_io::Frame::new();
    let mut k = 0;
    while t.read_next(&mut f).unwrap() {
        let step = f.step.expect("the step is written back");
        let want = table.at_step(step).unwrap().1;
        let got = f.cell.as_ref().expect("the Lattice is written");
        for (a, b) in got
            .matrix()
            .iter()
            .flatten()
            .zip(want.matrix().iter().flatten())
        {
            assert!((a - b).abs() < 1e-6, "frame {k}: {got:?} against {want:?}");
        }
        let ase = reference["npt_wrapped"][k].as_array().unwrap();
        for (p, q) in f.positions.iter().zip(ase) {
            for d in 0..3 {
                let q = q[d].as_f64().unwrap();
                // ASE and we wrap the same f64 positions: equal to the f32 of the output
                // (a coordinate exactly on a face could go either way; none is here).
                assert!(
                    (p[d] as f64 - q).abs() < 1e-5,
                    "frame {k}: {p:?} against ASE's"
                );
            }
        }
        k += 1;
    }
    assert_eq!(k, 11);

    let o = texmap(&["info", &pos, "--cell", "10,11,12,90,100,90"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let bx: Vec<f64> = info["box"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for (a, b) in bx.iter().zip([10.0, 11.0, 12.0, 90.0, 100.0, 90.0]) {
        assert!((a - b).abs() < 1e-9, "{bx:?}");
    }

    let bad = dir.path().join("bad.xyz");
    for spec in ["1,2", "10,10,10,90,90,200", "no-such.cell"] {
        let o = texmap(&["convert", &pos, "--cell", spec, "-o", bad.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{spec}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("--cell {spec}")),
            "{}",
            stderr(&o)
        );
    }
    // A cell file cut after step 4: frame 2 (step 8) has no cell.
    let short = dir.path().join("short.cell");
    let text = std::fs::read_to_string(&cell).unwrap();
    std::fs::write(&short, text.lines().take(6).collect::<Vec<_>>().join("\n")).unwrap();
    let o = texmap(&[
        "convert",
        &pos,
        "--cell",
        short.to_str().unwrap(),
        "-o",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("frame 2: step 8 is not in"),
        "{}",
        stderr(&o)
    );
    assert!(!bad.exists(), "no partial output");
}
