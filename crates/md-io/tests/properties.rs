//! Per-atom properties (`Frame::properties`) against the programs that wrote or read the files:
//! gemmi's occupancies and B-factors of two wwPDB mmCIF entries and of its own PDB, MDAnalysis
//! reading that PDB, ASE's extended-XYZ arrays, and the unwrapped-coordinate columns of a LAMMPS
//! dump against LAMMPS's own relation xu = x + ix·a + iy·b + iz·c (tests/data/gen_properties.py).

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{Format, Frame, Trajectory, Writer};

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn first_frame(name: &str) -> Frame {
    let mut t = Trajectory::open(path(name)).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap(), "{name}");
    f
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn same(what: &str, expected: &[f64], actual: Option<&[f32]>, tol: f64) {
    let actual = actual.unwrap_or_else(|| panic!("{what}: no such property"));
    assert_eq!(expected.len(), actual.len(), "{what}");
    for (i, (e, a)) in expected.iter().zip(actual).enumerate() {
        assert!((e - *a as f64).abs() <= tol, "{what} atom {i}: {e} vs {a}");
    }
}

#[test]
fn occupancies_and_b_factors_as_gemmi_and_mdanalysis_read_them() {
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(path("properties_reference.json")).unwrap())
            .unwrap();
    for name in ["3jqh.cif", "1uqc.cif", "3jqh_gemmi.pdb"] {
        let f = first_frame(name);
        for p in ["occupancy", "bfactor"] {
            same(
                &format!("{name} {p}"),
                &numbers(&r[name][p]),
                f.property(p),
                1e-4,
            );
        }
        // The X-ray entry has real B-factors (the NMR entry's are 0).
        let b = f.property("bfactor").unwrap();
        assert_eq!(
            b.iter().any(|v| *v > 10.0),
            name.starts_with("3jqh"),
            "{name}"
        );
    }
    // A PDB whose occupancy and B-factor fields are all blank has neither property.
    let blank = "ATOM      1  CA  ALA A   1       1.000   2.000   3.000\n";
    let mut t = Trajectory::from_reader(Cursor::new(blank), Format::Pdb, "blank.pdb").unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    assert!(f.properties.is_empty());
}

#[test]
fn ase_extended_xyz_arrays_are_properties() {
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(path("properties_reference.json")).unwrap())
            .unwrap();
    let f = first_frame("ase_props.xyz");
    let names: Vec<&str> = f.properties.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["initial_charges", "tags", "masses", "von_mises"]);
    for p in ["initial_charges", "tags", "masses", "von_mises"] {
        let want = numbers(&r["ase_props.xyz"][p]);
        same(
            p,
            &want,
            f.property(p),
            1e-6 * want.iter().fold(1.0, |m, v| v.abs().max(m)),
        );
    }
}

/// lmp_tri.lammpstrj (LAMMPS 22 Jul 2025) dumps x y z, xs ys zs, xu yu zu and ix iy iz: the
/// columns not read as positions are properties, in column order, and hold LAMMPS's relation
/// between wrapped and unwrapped coordinates (sorted by id with the positions).
#[test]
fn lammps_dump_columns_are_properties_in_lammps_relation() {
    let mut t = Trajectory::open(path("lmp_tri.lammpstrj")).unwrap();
    let mut f = Frame::new();
    let mut frames = 0;
    while t.read_next(&mut f).unwrap() {
        let names: Vec<&str> = f.properties.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(
            names,
            ["xs", "ys", "zs", "xu", "yu", "zu", "ix", "iy", "iz"]
        );
        let m = f.cell.unwrap().matrix();
        let col = |n: &str| f.property(n).unwrap();
        let (ix, iy, iz) = (col("ix"), col("iy"), col("iz"));
        let mut crossed = 0;
        for i in 0..f.n_atoms() {
            let img = [ix[i] as f64, iy[i] as f64, iz[i] as f64];
            crossed += (img != [0.0; 3]) as usize;
            for (k, u) in ["xu", "yu", "zu"].iter().enumerate() {
                let want = f.positions[i][k] as f64
                    + img[0] * m[0][k]
                    + img[1] * m[1][k]
                    + img[2] * m[2][k];
                let got = col(u)[i] as f64;
                assert!((want - got).abs() < 2e-3, "atom {i} {u}: {want} vs {got}");
            }
        }
        assert!(crossed > 0, "some atoms carry image flags");
        frames += 1;
    }
    assert!(frames > 0);
}

#[test]
fn pdb_writer_keeps_b_factors_and_refuses_what_does_not_fit() {
    let f = first_frame("3jqh.cif");
    let mut out = Cursor::new(Vec::new());
    let mut w = Writer::new(&mut out, Format::Pdb, "out.pdb").unwrap();
    w.write_frame(&f).unwrap();
    w.finish().unwrap();
    let bytes = out.into_inner();
    let mut t = Trajectory::from_reader(Cursor::new(bytes), Format::Pdb, "out.pdb").unwrap();
    let mut back = Frame::new();
    assert!(t.read_next(&mut back).unwrap());
    for p in ["occupancy", "bfactor"] {
        let want: Vec<f64> = f.property(p).unwrap().iter().map(|v| *v as f64).collect();
        same(p, &want, back.property(p), 0.005);
    }
    let mut big = f.clone();
    let k = big
        .properties
        .iter()
        .position(|p| p.name == "bfactor")
        .unwrap();
    big.properties[k].values[3] = 1000.0;
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Pdb, "out.pdb").unwrap();
    let e = w.write_frame(&big).unwrap_err().to_string();
    assert!(e.contains("atom 3") && e.contains("bfactor"), "{e}");
}

/// MDAnalysis's `prop` selections on gemmi's PDB of 3JQH select the atoms ours select.
#[test]
fn prop_selections_select_what_mdanalysis_selects() {
    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(path("properties_reference.json")).unwrap())
            .unwrap();
    let f = first_frame("3jqh_gemmi.pdb");
    let cases = r["prop_selections"].as_object().unwrap();
    assert!(cases.len() >= 9);
    for (text, want) in cases {
        let want: Vec<usize> = want
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        let got = texmap_md_io::Selection::parse(text)
            .unwrap()
            .indices(&f)
            .unwrap();
        assert_eq!(got, want, "{text}");
    }
    // VMD's spelling selects what MDAnalysis's does.
    for (vmd, mda) in [
        ("beta > 60", "prop tempfactor > 60"),
        ("occupancy < 1", "prop occupancy < 1"),
        (
            "beta>=57.5 and name CA",
            "prop tempfactor>=57.5 and name CA",
        ),
    ] {
        let want: Vec<usize> = cases[mda]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        let got = texmap_md_io::Selection::parse(vmd)
            .unwrap()
            .indices(&f)
            .unwrap();
        assert_eq!(got, want, "{vmd}");
    }
    // A property the frame lacks is an error listing those it has.
    let e = texmap_md_io::Selection::parse("prop c_pe > 1")
        .unwrap()
        .indices(&f)
        .unwrap_err()
        .to_string();
    assert!(e.contains("c_pe") && e.contains("bfactor"), "{e}");
    // Malformed comparisons point at `prop`.
    for bad in [
        "prop bfactor",
        "prop bfactor > ",
        "prop 5 > 6",
        "prop x => 5",
    ] {
        let e = texmap_md_io::Selection::parse(bad).unwrap_err().to_string();
        assert!(e.contains("prop [abs] NAME OP VALUE"), "{bad}: {e}");
    }
}
