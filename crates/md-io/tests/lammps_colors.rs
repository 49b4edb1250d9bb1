//! Per-atom colour columns in LAMMPS dumps: files written by LAMMPS and by OVITO against what
//! those programs hold (tests/data/color_reference.json, made by gen_colors.py), OVITO's own
//! column-name mapping, and hand-written column orders, partial colours and damaged values.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use serde_json::Value;
use texmap_md_io::{AtomStyle, Error, Format, Frame, Trajectory};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(data("color_reference.json")).unwrap()).unwrap()
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

fn read(text: &str) -> Result<Vec<Frame>, Error> {
    let mut t = Trajectory::from_reader(
        Cursor::new(text.as_bytes().to_vec()),
        Format::LammpsDump,
        "case",
    )?;
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f)? {
        out.push(f.clone());
    }
    Ok(out)
}

fn close(what: &str, expected: f64, actual: f64, tol: f64) {
    assert!(
        (expected - actual).abs() <= tol,
        "{what}: expected {expected}, actual {actual}, tolerance {tol}"
    );
}

fn rows(v: &Value) -> Vec<[f64; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let r = r.as_array().unwrap();
            [0, 1, 2].map(|k| r[k].as_f64().unwrap())
        })
        .collect()
}

fn ids(v: &Value) -> Vec<i64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect()
}

/// Tolerance of a value printed with `%g` (6 significant digits: half a unit of the 6th digit)
/// then parsed to f32 (half an ulp, at most 6e-8 relative).
fn g6(v: f64) -> f64 {
    let unit = 10f64.powf(v.abs().max(1e-30).log10().floor() - 5.0);
    0.5 * unit + 6e-8 * v.abs()
}

/// Checks a frame's ids, colours and (when given) radii against reference rows sorted by id;
/// `tol` gives the tolerance of an expected value.
fn check(what: &str, e: &Value, f: &Frame, tol: impl Fn(f64) -> f64) {
    assert_eq!(f.ids, ids(&e["ids"]), "{what}: ids, sorted");
    let colors = rows(&e["colors"]);
    assert_eq!(f.colors.len(), colors.len(), "{what}: one colour per atom");
    for (i, (c, got)) in colors.iter().zip(&f.colors).enumerate() {
        for k in 0..3 {
            let t = tol(c[k]);
            close(
                &format!("{what} atom {i} channel {k}"),
                c[k],
                got[k] as f64,
                t,
            );
        }
    }
    if let Some(r) = e.get("radii").and_then(|r| r.as_array()) {
        assert_eq!(f.radii.len(), r.len(), "{what}: radii");
        for (i, (r, got)) in r.iter().zip(&f.radii).enumerate() {
            close(
                &format!("{what} radius {i}"),
                r.as_f64().unwrap(),
                *got as f64,
                1e-6,
            );
        }
    }
}

#[test]
fn lammps_written_colour_columns_against_lammps_state() {
    let r = reference();
    for file in ["lmp_color.lammpstrj", "lmp_color_dot.lammpstrj"] {
        let got = frames(file);
        let exp = r[file].as_array().unwrap();
        assert_eq!(got.len(), exp.len(), "{file}: frames");
        for (k, (e, f)) in exp.iter().zip(&got).enumerate() {
            // The file is in LAMMPS's spatial order, not id order: the sort must carry colours.
            assert_ne!(
                ids(&e["file_order_ids"]),
                ids(&e["ids"]),
                "{file}: the test needs unsorted ids"
            );
            assert_eq!(f.step, e["step"].as_i64(), "{file} frame {k}");
            check(&format!("{file} frame {k}"), e, f, g6);
        }
        // Some values are outside [0, 1] on purpose; they are kept as written.
        let all: Vec<f32> = got
            .iter()
            .flat_map(|f| f.colors.iter().flatten())
            .copied()
            .collect();
        assert!(
            all.iter().any(|v| *v > 1.0) && all.iter().any(|v| *v < 0.0),
            "{file}"
        );
    }
}

#[test]
fn ovito_reads_the_same_colours_and_its_export_reads_back() {
    let r = reference();
    // OVITO 3.17.2 read both LAMMPS files: its colours (f32) equal ours.
    for file in [
        "lmp_color.lammpstrj",
        "lmp_color_dot.lammpstrj",
        "ovito_color.lammpstrj",
    ] {
        let got = frames(file);
        let exp = r["ovito_import"][file].as_array().unwrap();
        for (k, e) in exp.iter().enumerate() {
            assert!(
                e["properties"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|p| p == "Color"),
                "{file}: OVITO found a Color property"
            );
            // OVITO parses the same decimal text to f32 (its colour type): equal to 1 ulp.
            check(&format!("{file} (OVITO) frame {k}"), e, &got[k], |v| {
                f64::from(f32::EPSILON) * v.abs()
            });
        }
    }
    // OVITO's exporter writes ColorR ColorG ColorB: the spelling we must read.
    let text = std::fs::read_to_string(data("ovito_color.lammpstrj")).unwrap();
    assert!(
        text.contains("ColorR ColorG ColorB"),
        "OVITO's column names"
    );
}

#[test]
fn colour_column_names_map_as_ovito_maps_them() {
    let r = reference();
    for probe in r["ovito_mapping"].as_array().unwrap() {
        let cols: Vec<&str> = probe["columns"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap())
            .collect();
        // The probe file gen_colors.py gave OVITO.
        let text = format!(
            "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\n\
             ITEM: ATOMS id type x y z {}\n1 1 1.0 2.0 3.0 0.25 0.5 0.75\n",
            cols.join(" ")
        );
        let f = read(&text).unwrap();
        let ovito_has = probe["color_property"].as_bool().unwrap();
        assert_eq!(
            !f[0].colors.is_empty(),
            ovito_has,
            "{cols:?}: colour as in OVITO"
        );
        if ovito_has {
            let c = rows(&Value::Array(vec![probe["color"].clone()]))[0];
            assert_eq!(f[0].colors[0].map(f64::from), c, "{cols:?}");
        }
        assert_eq!(
            f[0].positions[0],
            [1.0, 2.0, 3.0],
            "{cols:?}: positions untouched"
        );
    }
}

/// All 6 orders of the three colour columns, each placed around the other columns.
#[test]
fn colour_columns_in_any_order_and_place() {
    let names = ["ColorR", "colorg", "Color.B"];
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    // Atom 1 has colour (0.1, 0.2, 0.3), atom 2 (0.9, 0.8, 0.7); other columns: id x y z type.
    let rgb = [[0.1f32, 0.2, 0.3], [0.9, 0.8, 0.7]];
    for p in perms {
        for slot in 0..3 {
            // Layout: colour p[0], then `slot` of the other columns, colour p[1], the rest, p[2].
            let others = ["id", "x", "y", "z", "type"];
            let mut cols: Vec<String> = vec![names[p[0]].into()];
            cols.extend(others[..slot].iter().map(|s| s.to_string()));
            cols.push(names[p[1]].into());
            cols.extend(others[slot..].iter().map(|s| s.to_string()));
            cols.push(names[p[2]].into());
            let line = |id: usize| -> String {
                cols.iter()
                    .map(|c| match c.as_str() {
                        "id" => (id + 1).to_string(),
                        "x" => format!("{}", id as f32 + 0.5),
                        "y" | "z" => "0".into(),
                        "type" => "1".into(),
                        name => rgb[id][names.iter().position(|n| *n == name).unwrap()].to_string(),
                    })
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            // Atoms written in reverse id order: the sort must carry the colours.
            let text = format!(
                "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\n\
                 ITEM: ATOMS {}\n{}\n{}\n",
                cols.join(" "),
                line(1),
                line(0)
            );
            let f = read(&text).unwrap();
            assert_eq!(f[0].ids, [1, 2], "{cols:?}");
            assert_eq!(f[0].colors, rgb, "{cols:?}");
            assert_eq!(f[0].positions[1], [1.5, 0.0, 0.0], "{cols:?}");
        }
    }
}

#[test]
fn partial_colours_are_skipped_and_bad_values_are_errors() {
    let head = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\n";
    // Two of three channels: not a colour (the columns are skipped, the frame still reads).
    let f = read(&format!(
        "{head}ITEM: ATOMS id x y z ColorR ColorG\n1 1 2 3 0.5 0.5\n"
    ))
    .unwrap();
    assert!(f[0].colors.is_empty());
    assert_eq!(f[0].positions[0], [1.0, 2.0, 3.0]);
    // A repeated channel counts once (the first column of a kind), so R R B is partial too.
    let f = read(&format!(
        "{head}ITEM: ATOMS id x y z ColorR ColorR ColorB\n1 1 2 3 0.5 0.5 0.5\n"
    ))
    .unwrap();
    assert!(f[0].colors.is_empty());
    // A colour that is not a finite number is an error naming the line and the token.
    for bad in ["nan", "inf", "red", "1e40"] {
        let e = read(&format!(
            "{head}ITEM: ATOMS id x y z ColorR ColorG ColorB\n1 1 2 3 0.5 {bad} 0.5\n"
        ))
        .unwrap_err();
        let s = e.to_string();
        assert!(
            s.starts_with("case: frame 0, line 10, byte ")
                && s.ends_with(&format!(
                    "expected a finite colour component, found '{bad}'"
                )),
            "{bad}: {s}"
        );
    }
    // A missing colour value is reported like any missing column.
    let e = read(&format!(
        "{head}ITEM: ATOMS id x y z ColorR ColorG ColorB\n1 1 2 3 0.5 0.5\n"
    ))
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("as many values as ITEM: ATOMS columns"),
        "{e}"
    );
}

#[test]
fn out_of_range_file_colours_are_kept_and_clamped_only_for_drawing() {
    let f = &frames("lmp_color.lammpstrj")[0];
    let style = AtomStyle::new();
    let (mut radii, mut colors) = (Vec::new(), Vec::new());
    style.apply(f, &mut radii, &mut colors);
    for (i, (file, drawn)) in f.colors.iter().zip(&colors).enumerate() {
        for k in 0..3 {
            // Expected: the file value clamped to [0, 1] (computed here in f64).
            let e = (file[k] as f64).clamp(0.0, 1.0);
            close(&format!("atom {i} channel {k}"), e, drawn[k] as f64, 0.0);
        }
    }
    // The diameter column gives the radius (diameter / 2), and it wins over the table.
    assert!(radii.iter().all(|r| *r == 1.2 || *r == 1.5), "{radii:?}");
}
