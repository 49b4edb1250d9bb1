//! Text formats read against files written by other programs (ASE, MDAnalysis, LAMMPS) and the
//! values those programs report for them (tests/data/text_reference.json, written by
//! tests/data/gen_text.py at generation time); and LAMMPS binary dumps against the text dumps
//! LAMMPS wrote of the same frames (tests/data/lammps_bin/, written by its gen.sh).

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

// LAMMPS binary dumps (tests/data/lammps_bin/gen.sh): each run dumped every frame as binary and
// as text with every float at %.17g, so the text holds the binary's doubles exactly and the two
// readers must give the same frames, bit for bit.

use crate::support::lammps_bin::{Layout, column_names, rewrite, walk};
use texmap_md_io::{Error, ReadOptions};

/// The runs: binary and text dumps of the same frames.
const LAMMPS_BIN_PAIRS: [&str; 8] = [
    "custom_np1",
    "custom_np2",
    "scaled_np1",
    "atom_np1",
    "atom_image_np1",
    "tri_np1",
    "tri_np2",
    "tri_atom_np1",
];

fn lammps_bin(name: &str) -> Vec<u8> {
    std::fs::read(data(&format!("lammps_bin/{name}"))).unwrap()
}

/// Every frame of `bytes` read as `format` with `options`.
fn read_all(bytes: &[u8], format: Format, options: ReadOptions) -> Vec<Frame> {
    let src = std::io::Cursor::new(bytes.to_vec());
    let mut t = Trajectory::from_reader_with(src, format, "dump", options).unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

/// The same frame, every value bit for bit (the text printed the doubles with 17 significant
/// digits, which give them back exactly; each reader rounds them to f32 once), but the time: the
/// text's `ITEM: TIME` has 16 significant digits (LAMMPS prints it so), hence a relative 1e-15.
fn assert_same_frame(what: &str, bin: &Frame, text: &Frame) {
    let bits =
        |v: &[[f32; 3]]| -> Vec<[u32; 3]> { v.iter().map(|p| p.map(f32::to_bits)).collect() };
    assert_eq!(
        bits(&bin.positions),
        bits(&text.positions),
        "{what}: positions"
    );
    assert_eq!(
        bits(&bin.velocities),
        bits(&text.velocities),
        "{what}: velocities"
    );
    assert_eq!(bits(&bin.colors), bits(&text.colors), "{what}: colours");
    let names = |f: &Frame| {
        f.properties
            .iter()
            .map(|p| p.name.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(names(bin), names(text), "{what}: properties");
    for (a, b) in bin.properties.iter().zip(&text.properties) {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&a.values),
            bits(&b.values),
            "{what}: property {}",
            a.name
        );
    }
    match (bin.time, text.time) {
        (Some(a), Some(b)) => {
            let tol = 1e-15 * b.abs();
            assert!(
                (a - b).abs() <= tol,
                "{what}: time: expected {b}, actual {a}, tolerance {tol}"
            );
        }
        (a, b) => assert_eq!(a, b, "{what}: time"),
    }
    // The rest holds no float of the atoms: the cell's doubles are printed with 17 significant
    // digits too.
    let mut bin = bin.clone();
    let mut text = text.clone();
    for f in [&mut bin, &mut text] {
        f.positions.clear();
        f.velocities.clear();
        f.colors.clear();
        f.properties.clear();
        f.time = None;
    }
    assert_eq!(bin, text, "{what}");
}

#[test]
fn lammps_bin_frames_equal_the_text_dump_of_the_same_run() {
    for name in LAMMPS_BIN_PAIRS {
        let bin_path = data(&format!("lammps_bin/{name}.bin"));
        let mut b = Trajectory::open(&bin_path).unwrap();
        assert_eq!(
            b.format(),
            Format::LammpsBin,
            "{name}: told by its magic header"
        );
        let mut t = Trajectory::open(data(&format!("lammps_bin/{name}.lammpstrj"))).unwrap();
        let n = t.n_frames().unwrap();
        assert_eq!(b.n_frames().unwrap(), n, "{name}");
        assert_eq!(n, 4, "{name}: steps 0, 10, 20, 30");
        let (mut fb, mut ft) = (Frame::new(), Frame::new());
        let mut streamed = Vec::new();
        for k in 0..n {
            assert!(b.read_next(&mut fb).unwrap());
            assert!(t.read_next(&mut ft).unwrap());
            assert_same_frame(&format!("{name} frame {k}"), &fb, &ft);
            streamed.push(fb.clone());
        }
        assert!(!b.read_next(&mut fb).unwrap(), "{name}: the end");
        // Random access, backwards, gives the streamed frames.
        for k in (0..n).rev() {
            b.read_frame(k, &mut fb).unwrap();
            assert_eq!(fb, streamed[k], "{name} frame {k} by index");
        }
    }
}

#[test]
fn lammps_bin_runs_hold_what_the_inputs_asked_for() {
    let frames = read_all(
        &lammps_bin("custom_np2.bin"),
        Format::LammpsBin,
        ReadOptions::new(),
    );
    let f = &frames[3];
    assert_eq!((f.step, f.n_atoms()), (Some(30), 40));
    // Metal units: TIME in ps as written (30 steps of 0.002 ps).
    let t = f.time.unwrap();
    assert!(
        (t - 0.06).abs() <= 1e-15,
        "time: expected 0.06, actual {t}, tolerance 1e-15"
    );
    // boundary p f s.
    assert_eq!(f.cell.unwrap().periodic(), [true, false, false]);
    assert!(
        f.ids.is_sorted() && f.ids.len() == 40,
        "sorted by id across the 2 chunks"
    );
    let types: std::collections::BTreeSet<&str> = f.types.iter().map(|t| t.as_str()).collect();
    assert_eq!(types, ["1", "2"].into(), "two atom types");
    let props: Vec<&str> = f.properties.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        props,
        ["fx", "fy", "fz", "c_pe", "c_ke", "ix", "iy", "iz", "mass"]
    );
    assert!(f.property("mass").unwrap().iter().all(|m| *m == 63.5));
    // Triclinic, real units: a changing atom count (dump_modify thresh), one frame empty; time
    // in fs becomes ps, velocities Å/fs become Å/ps.
    let tri = read_all(
        &lammps_bin("tri_np2.bin"),
        Format::LammpsBin,
        ReadOptions::new(),
    );
    let counts: Vec<usize> = tri.iter().map(Frame::n_atoms).collect();
    assert_eq!(counts, [16, 0, 6, 8]);
    let t = tri[2].time.unwrap();
    assert!(
        (t - 0.04).abs() <= 1e-15,
        "time: expected 0.04, actual {t}, tolerance 1e-15"
    );
    // Tilts xy xz yz of 0.5, 0.3, -0.4 lattice spacings of 3.6 Å (LAMMPS's own products).
    let m = tri[0].cell.unwrap().matrix();
    for (got, want) in [m[1][0], m[2][0], m[2][1]]
        .into_iter()
        .zip([1.8, 1.08, -1.44])
    {
        assert!(
            (got - want).abs() <= 1e-12,
            "tilt: expected {want}, actual {got}, tolerance 1e-12"
        );
    }
}

#[test]
fn lammps_bin_older_layouts_and_big_endian_read_the_same_frames() {
    for name in [
        "custom_np2.bin",
        "tri_np1.bin",
        "atom_np1.bin",
        "atom_image_np1.bin",
    ] {
        let good = lammps_bin(name);
        let want = read_all(&good, Format::LammpsBin, ReadOptions::new());
        let columns = column_names(&good);
        for (layout, big) in [
            (Layout::Revision2, true),
            (Layout::Revision1, false),
            (Layout::Revision1, true),
            (Layout::Bare, false),
            (Layout::Bare, true),
        ] {
            let what = format!("{name} {layout:?} big-endian {big}");
            let bytes = rewrite(&good, layout, big);
            assert_eq!(
                Format::from_magic(&bytes[..512.min(bytes.len())]),
                Some(Format::LammpsBin),
                "{what}"
            );
            let opts = if layout == Layout::Revision2 {
                ReadOptions::new()
            } else {
                ReadOptions::new().lammps_columns(&columns)
            };
            let got = read_all(&bytes, Format::LammpsBin, opts);
            assert_eq!(got.len(), want.len(), "{what}");
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                let mut w = w.clone();
                if layout != Layout::Revision2 {
                    // No units: no time, and velocities as written: Å/fs in the real-unit run,
                    // which the revision-2 read scaled by 1000 (the same f32 product).
                    w.time = None;
                    if name.starts_with("tri_np") {
                        let scaled: Vec<[f32; 3]> =
                            g.velocities.iter().map(|v| v.map(|c| c * 1000.0)).collect();
                        assert_eq!(scaled, w.velocities, "{what} frame {k}: velocities");
                        w.velocities = g.velocities.clone();
                    }
                }
                assert_eq!(g, &w, "{what} frame {k}");
            }
        }
    }
}

#[test]
fn lammps_bin_without_column_names_assumes_dump_atom_or_asks_for_them() {
    // dump atom's default (id type xs ys zs) is read without names.
    let atom = lammps_bin("atom_np1.bin");
    let want = read_all(&atom, Format::LammpsBin, ReadOptions::new());
    let got = read_all(
        &rewrite(&atom, Layout::Bare, false),
        Format::LammpsBin,
        ReadOptions::new(),
    );
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g.positions, w.positions);
        assert_eq!(g.ids, w.ids);
    }
    // dump atom with scale no and image yes, 8 values per atom as the default with image
    // flags: its box coordinates are not scaled ones, and the error asks for the names.
    let image = rewrite(&lammps_bin("atom_image_np1.bin"), Layout::Bare, false);
    let mut t =
        Trajectory::from_reader(std::io::Cursor::new(image), Format::LammpsBin, "old.bin").unwrap();
    assert_eq!(
        t.n_frames().unwrap(),
        4,
        "the structure does not depend on the names"
    );
    let e = t.read_next(&mut Frame::new()).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("old.bin: frame 0, byte "), "{msg}");
    assert!(
        msg.contains("--lammps-columns") && msg.contains("ReadOptions::lammps_columns"),
        "{msg}"
    );
    // Any other count of values: the names are needed.
    let custom = rewrite(&lammps_bin("custom_np1.bin"), Layout::Revision1, false);
    let mut t = Trajectory::from_reader(
        std::io::Cursor::new(custom.clone()),
        Format::LammpsBin,
        "old.bin",
    )
    .unwrap();
    let e = t.read_next(&mut Frame::new()).unwrap_err();
    let f0 = &walk(&lammps_bin("custom_np1.bin"))[0];
    // Revision 1 drops nothing before size_one: it sits where it was.
    let want = format!(
        "old.bin: frame 0, byte {}: expected a file that names its columns",
        f0.size_one
    );
    assert!(e.to_string().starts_with(&want), "{e}");
    // Names that do not match the count are an error too, naming the count.
    let opts = ReadOptions::new().lammps_columns("id type x y z");
    let mut t = Trajectory::from_reader_with(
        std::io::Cursor::new(custom),
        Format::LammpsBin,
        "old.bin",
        opts,
    )
    .unwrap();
    let e = t.read_next(&mut Frame::new()).unwrap_err();
    assert!(e.to_string().contains("5 names for size_one 17"), "{e}");
}

#[test]
fn lammps_bin_errors_name_the_file_frame_and_byte() {
    let good = lammps_bin("custom_np2.bin");
    let frames = walk(&good);
    // Frame 2's second chunk claims more values than natoms x size_one leaves.
    let (count, _, _) = frames[2].chunks[1];
    let mut bad = good.clone();
    bad[count..count + 4].copy_from_slice(&99_999_999i32.to_le_bytes());
    let mut t =
        Trajectory::from_reader(std::io::Cursor::new(bad), Format::LammpsBin, "dump.bin").unwrap();
    let e = t.n_frames().unwrap_err();
    let left = 40 * 17 - frames[2].chunks[0].2;
    assert_eq!(
        e.to_string(),
        format!(
            "dump.bin: frame 2, byte {count}: expected a chunk of at most natoms x size_one values left, in whole atoms, found '99999999 values (natoms 40 x size_one 17: {left} left)'"
        )
    );
    let mut f = Frame::new();
    t.read_frame(1, &mut f).unwrap();
    assert_eq!(
        t.read_frame(2, &mut f).unwrap_err().to_string(),
        e.to_string()
    );
    // A cut inside the last frame: an error for it, or with allow_truncated a warning and the
    // frames before it.
    let cut = &good[..frames[3].chunks[1].1 + 100];
    let mut t = Trajectory::from_reader(
        std::io::Cursor::new(cut.to_vec()),
        Format::LammpsBin,
        "dump.bin",
    )
    .unwrap();
    let e = t.n_frames().unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(
        e.to_string().starts_with(&format!(
            "dump.bin: frame 3, byte {}: file ends inside the frame",
            cut.len()
        )),
        "{e}"
    );
    let opts = ReadOptions::new().allow_truncated(true);
    let mut t = Trajectory::from_reader_with(
        std::io::Cursor::new(cut.to_vec()),
        Format::LammpsBin,
        "dump.bin",
        opts,
    )
    .unwrap();
    assert_eq!(t.n_frames().unwrap(), 3);
    assert_eq!(t.warnings().len(), 1);
    // A header's string length beyond the file: refused before anything is allocated.
    let mut bad = good.clone();
    let c = frames[0].columns;
    bad[c..c + 4].copy_from_slice(&i32::MAX.to_le_bytes());
    let e = Trajectory::from_reader(std::io::Cursor::new(bad), Format::LammpsBin, "dump.bin")
        .err()
        .unwrap();
    assert!(e.to_string().starts_with("dump.bin: frame 0, byte "), "{e}");
}
