//! Text formats read against files written by other programs (ASE, MDAnalysis, LAMMPS) and the
//! values those programs report for them (tests/data/text_reference.json, written by
//! tests/data/gen_text.py at generation time).

use serde_json::Value;
use std::path::PathBuf;
use texmap_md_io::{Element, Format, Frame, Trajectory};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn reference() -> Value {
    let text = std::fs::read_to_string(data("text_reference.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn frames(name: &str) -> Vec<Frame> {
    let mut t = Trajectory::open(data(name)).unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

fn close(what: &str, expected: f64, actual: f64, tol: f64) {
    assert!(
        (expected - actual).abs() <= tol,
        "{what}: expected {expected}, actual {actual}, tolerance {tol}"
    );
}

fn v3(v: &Value) -> [f64; 3] {
    [
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    ]
}

fn check_rows(what: &str, expected: &Value, actual: &[[f32; 3]], tol: f64) {
    let exp = expected.as_array().unwrap();
    assert_eq!(exp.len(), actual.len(), "{what}: atom count");
    for (i, (e, a)) in exp.iter().zip(actual).enumerate() {
        let e = v3(e);
        for k in 0..3 {
            close(&format!("{what} atom {i} axis {k}"), e[k], a[k] as f64, tol);
        }
    }
}

fn check_matrix(what: &str, expected: &Value, actual: [[f64; 3]; 3], tol: f64) {
    for r in 0..3 {
        let e = v3(&expected[r]);
        for k in 0..3 {
            close(&format!("{what} [{r}][{k}]"), e[k], actual[r][k], tol);
        }
    }
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn ase_extended_xyz() {
    let r = reference();
    let exp = r["ase_ext.xyz"].as_array().unwrap();
    let got = frames("ase_ext.xyz");
    assert_eq!(got.len(), exp.len());
    for (e, f) in exp.iter().zip(&got) {
        // ASE writes %16.8f: the f32 rounding dominates (|x| < 16: half an ulp < 1e-6).
        check_rows("position", &e["positions"], &f.positions, 1e-6);
        check_rows("color", &e["color"], &f.colors, 1e-7);
        let names: Vec<String> = f.names.iter().map(|l| l.to_string()).collect();
        assert_eq!(names, strings(&e["symbols"]));
        for (s, el) in strings(&e["symbols"]).iter().zip(&f.elements) {
            assert_eq!(Element::from_symbol(s), Some(*el));
        }
        for (i, rad) in e["radius"].as_array().unwrap().iter().enumerate() {
            close("radius", rad.as_f64().unwrap(), f.radii[i] as f64, 1e-7);
        }
        check_matrix("cell", &e["cell"], f.cell.unwrap().matrix(), 1e-12);
    }
}

#[test]
fn ase_plain_xyz() {
    let r = reference();
    let exp = r["ase_plain.xyz"].as_array().unwrap();
    let got = frames("ase_plain.xyz");
    assert_eq!(got.len(), exp.len());
    for (e, f) in exp.iter().zip(&got) {
        check_rows("position", &e["positions"], &f.positions, 1e-6);
        assert!(f.cell.is_none());
    }
}

#[test]
fn mdanalysis_multi_model_pdb() {
    let r = reference();
    let exp = r["mda_multi.pdb"].as_array().unwrap();
    // Three MODELs; the trailing CONECT/END records are not a fourth frame.
    let got = frames("mda_multi.pdb");
    assert_eq!(got.len(), exp.len());
    for (e, f) in exp.iter().zip(&got) {
        // Both parse the same 3-decimal text to f32.
        check_rows("position", &e["positions"], &f.positions, 1e-5);
        let names: Vec<String> = f.names.iter().map(|l| l.to_string()).collect();
        assert_eq!(names, strings(&e["names"]));
        let res: Vec<String> = f.res_names.iter().map(|l| l.to_string()).collect();
        assert_eq!(res, strings(&e["resnames"]));
        for (s, el) in strings(&e["elements"]).iter().zip(&f.elements) {
            assert_eq!(Element::from_symbol(s), Some(*el), "element {s}");
        }
        let ids: Vec<i64> = e["ids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_i64().unwrap())
            .collect();
        assert_eq!(f.ids, ids);
        let resids: Vec<i64> = e["resids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_i64().unwrap())
            .collect();
        assert_eq!(f.res_ids, resids);
        // CRYST1 has 3 decimals for lengths and 2 for angles; MDAnalysis' triclinic_vectors
        // uses the same orientation convention (a along x, b in xy).
        check_matrix("cell", &e["cell"], f.cell.unwrap().matrix(), 1e-4);
    }
}

#[test]
fn pdb_without_element_column_uses_the_name_rules() {
    let got = frames("mda_noelem.pdb");
    assert_eq!(got.len(), 1);
    let syms: Vec<&str> = got[0].elements.iter().map(|e| e.symbol()).collect();
    // ALA: N CA C O CB -> first letter; SOL: OW HW1 HW2; ions named after their residue.
    assert_eq!(
        syms,
        ["N", "C", "C", "O", "C", "O", "H", "H", "Ca", "Cl", "Fe"]
    );
    let r = reference();
    check_rows(
        "position",
        &r["mda_noelem.pdb"][0]["positions"],
        &got[0].positions,
        1e-5,
    );
}

#[test]
fn mdanalysis_gro_with_velocities_and_triclinic_box() {
    let r = reference();
    let exp = r["mda_vel.gro"].as_array().unwrap();
    let got = frames("mda_vel.gro");
    assert_eq!(got.len(), exp.len());
    for (e, f) in exp.iter().zip(&got) {
        // nm with 3 decimals -> Å: both sides computed from the same text, f32 results.
        check_rows("position", &e["positions"], &f.positions, 1e-4);
        check_rows("velocity", &e["velocities"], &f.velocities, 1e-4);
        let names: Vec<String> = f.names.iter().map(|l| l.to_string()).collect();
        assert_eq!(names, strings(&e["names"]));
        check_matrix("cell", &e["cell"], f.cell.unwrap().matrix(), 1e-3);
        let dims = e["dimensions"].as_array().unwrap();
        let c = f.cell.unwrap();
        for k in 0..3 {
            close("length", dims[k].as_f64().unwrap(), c.lengths()[k], 1e-3);
            close("angle", dims[k + 3].as_f64().unwrap(), c.angles()[k], 1e-2);
        }
    }
}

#[test]
fn gro_with_five_decimals() {
    let r = reference();
    let e = &r["py_prec5.gro"][0];
    let got = frames("py_prec5.gro");
    assert_eq!(got.len(), 1);
    let f = &got[0];
    check_rows("position", &e["positions"], &f.positions, 2e-6);
    check_rows("velocity", &e["velocities"], &f.velocities, 2e-6);
    assert_eq!(f.step, Some(250));
    close("time", 12.5, f.time.unwrap(), 0.0);
    let c = f.cell.unwrap();
    assert!(c.is_orthorhombic());
    close("box", 30.0, c.lengths()[0], 1e-12);
}

/// LAMMPS reference frame: box from extract_box, atoms gathered by id.
struct LmpRef {
    step: i64,
    ids: Vec<i64>,
    x: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    image: Vec<[i64; 3]>,
    lo: [f64; 3],
    m: [[f64; 3]; 3],
}

fn lammps_reference() -> Vec<LmpRef> {
    let r = reference();
    r["lmp_tri.lammpstrj"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            let lo = v3(&e["boxlo"]);
            let hi = v3(&e["boxhi"]);
            let (xy, xz, yz) = (
                e["xy"].as_f64().unwrap(),
                e["xz"].as_f64().unwrap(),
                e["yz"].as_f64().unwrap(),
            );
            let rows = |k: &str| -> Vec<[f64; 3]> {
                let flat: Vec<f64> = e[k].as_array().unwrap().iter().flat_map(v3).collect();
                flat.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
            };
            // LAMMPS packs image flags as 10-bit fields (IMGBITS = 10, IMGMAX = 512).
            let image = e["image"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| {
                    let i = v.as_i64().unwrap();
                    [(i & 1023) - 512, ((i >> 10) & 1023) - 512, (i >> 20) - 512]
                })
                .collect();
            LmpRef {
                step: e["step"].as_i64().unwrap(),
                ids: e["ids"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_i64().unwrap())
                    .collect(),
                x: rows("positions"),
                v: rows("velocities"),
                image,
                lo,
                m: [
                    [hi[0] - lo[0], 0.0, 0.0],
                    [xy, hi[1] - lo[1], 0.0],
                    [xz, yz, hi[2] - lo[2]],
                ],
            }
        })
        .collect()
}

fn check_lammps_frame(what: &str, e: &LmpRef, f: &Frame, positions: &[[f64; 3]], tol: f64) {
    assert_eq!(f.step, Some(e.step), "{what}: step");
    // Atoms sorted by id, as gather_atoms returns them.
    assert_eq!(f.ids, e.ids, "{what}: ids");
    let c = f.cell.unwrap();
    check_matrix(
        &format!("{what} cell"),
        &serde_json::json!(e.m),
        c.matrix(),
        1e-12,
    );
    for k in 0..3 {
        close(&format!("{what} origin"), e.lo[k], c.origin()[k], 1e-12);
    }
    for (i, (p, q)) in positions.iter().zip(&f.positions).enumerate() {
        for k in 0..3 {
            close(&format!("{what} atom {i} axis {k}"), p[k], q[k] as f64, tol);
        }
    }
}

#[test]
fn lammps_triclinic_dump_against_lammps_internal_state() {
    let exp = lammps_reference();
    let got = frames("lmp_tri.lammpstrj");
    assert_eq!(got.len(), exp.len());
    for (e, f) in exp.iter().zip(&got) {
        // The dump prints 6 significant digits: |x| < 20 Å gives < 1e-4 Å.
        check_lammps_frame("x", e, f, &e.x, 1e-4);
        let syms: Vec<&str> = f.elements.iter().map(|e| e.symbol()).collect();
        assert!(syms.iter().all(|s| *s == "Ar" || *s == "Kr"));
        for (i, (p, q)) in e.v.iter().zip(&f.velocities).enumerate() {
            for k in 0..3 {
                close(
                    &format!("velocity atom {i}"),
                    p[k],
                    q[k] as f64,
                    1e-4 * p[k].abs().max(1.0),
                );
            }
        }
    }
}

#[test]
fn lammps_scaled_and_unwrapped_columns() {
    let exp = lammps_reference();
    // Scaled only (dump atom): s -> origin + s·M with the triclinic box.
    let got = frames("lmp_scaled.lammpstrj");
    assert_eq!(got.len(), exp.len());
    for (e, f) in exp.iter().zip(&got) {
        // 6 significant digits of s in [0, 1): 1e-6 of an edge of ~20 Å, three edges summed.
        check_lammps_frame("xs", e, f, &e.x, 1e-4);
    }
    // Unwrapped: hide the x and xs columns of the custom dump so that xu is used, and
    // compare with x + image·M from LAMMPS.
    let text = std::fs::read_to_string(data("lmp_tri.lammpstrj")).unwrap();
    let text = text.replace(
        "ITEM: ATOMS id type element x y z xs ys zs",
        "ITEM: ATOMS id type element q1 q2 q3 s1 s2 s3",
    );
    let mut t =
        Trajectory::from_reader(std::io::Cursor::new(text), Format::LammpsDump, "xu").unwrap();
    let mut f = Frame::new();
    for e in &exp {
        assert!(t.read_next(&mut f).unwrap());
        let unwrapped: Vec<[f64; 3]> =
            e.x.iter()
                .zip(&e.image)
                .map(|(x, im)| {
                    let mut p = *x;
                    for (a, row) in im.iter().zip(&e.m) {
                        for k in 0..3 {
                            p[k] += *a as f64 * row[k];
                        }
                    }
                    p
                })
                .collect();
        check_lammps_frame("xu", e, &f, &unwrapped, 2e-4);
    }
}
