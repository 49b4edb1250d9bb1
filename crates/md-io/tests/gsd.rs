//! HOOMD-blue GSD files written by gsd 5.0.1's `gsd.hoomd` (tests/data/gsd/gen_gsd.py), every
//! frame compared with what `gsd.hoomd.open` reads back (gsd/reference.json.gz): positions,
//! types, diameters, masses, charges, bodies, orientations, velocities, images, bonds, steps,
//! including the frames whose values come from frame 0 or the schema's defaults; the cell
//! against the box edges computed in Python from gsd's box; streaming against random access;
//! the extension, content sniffing and gzip paths of `Trajectory::open`; and damage: a cut file,
//! a chunk of the wrong shape, a non-finite position, a header that lies.
//!
//! Values are compared with `==`: gsd.hoomd and this reader hand over the same float32 numbers
//! (double-precision chunks rounded to float32 by both sides' casts), and the reference stores
//! each as the shortest decimal that parses back to it. Cells are f64 products of those numbers
//! on both sides: within 1e-12 Å.

use std::collections::BTreeSet;
use std::io::{Cursor, Write};
use std::path::PathBuf;

use serde_json::Value;
use support::gsd_index::chunk;
use texmap_md_io::{Element, Error, Format, Frame, ReadOptions, Trajectory};

use crate::support;

const FILES: [&str; 4] = [
    "hoomd_tri.gsd",
    "hoomd_2d.gsd",
    "hoomd_one.gsd",
    "hoomd_v1.gsd",
];

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/gsd")
        .join(name)
}

fn reference() -> Value {
    let gz = std::fs::File::open(path("reference.json.gz")).unwrap();
    serde_json::from_reader(flate2::read::GzDecoder::new(gz)).unwrap()
}

fn f32s(v: &Value) -> Vec<f32> {
    let mut out = Vec::new();
    match v {
        Value::Array(a) => a.iter().for_each(|x| out.extend(f32s(x))),
        x => out.push(x.as_f64().unwrap() as f32),
    }
    out
}

fn ints(v: &Value) -> Vec<i64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect()
}

fn close(expected: f64, actual: f64, tol: f64, what: &str) {
    assert!(
        (expected - actual).abs() <= tol,
        "{what}: expected {expected}, actual {actual}, tolerance {tol}"
    );
}

/// Every frame of `traj`, streamed.
fn stream<R: std::io::Read + std::io::Seek>(traj: &mut Trajectory<R>) -> Vec<Frame> {
    let mut out = Vec::new();
    let mut f = Frame::new();
    while traj.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

/// Compares frame `k` of `file` with gsd.hoomd's reading; `in_file` are the chunks some frame
/// of the file has (a property exists for those only).
fn compare(file: &str, k: usize, f: &Frame, want: &Value, in_file: &BTreeSet<String>) {
    let at = format!("{file} frame {k}");
    assert_eq!(f.check(), Ok(()), "{at}");
    assert_eq!(f.step, Some(want["step"].as_i64().unwrap()), "{at}");
    let n = want["N"].as_u64().unwrap() as usize;
    assert_eq!(f.n_atoms(), n, "{at}");
    assert_eq!(f.positions.as_flattened(), f32s(&want["position"]), "{at}");
    // Types and names: the typeid's name; elements only for a type named by its symbol.
    let types: Vec<String> = want["types"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap().to_string())
        .collect();
    let typeid = ints(&want["typeid"]);
    for i in 0..n {
        let t = &types[typeid[i] as usize];
        assert_eq!(f.types[i].as_str(), t, "{at} particle {i}");
        assert_eq!(f.names[i].as_str(), t, "{at} particle {i}");
    }
    // An element symbol written as one ("Na", "B"), not "A" or "Colloid".
    let element = |t: &str| Element::from_symbol(t).filter(|e| e.symbol() == t);
    if types.iter().any(|t| element(t).is_some()) {
        for i in 0..n {
            let t = &types[typeid[i] as usize];
            let e = element(t).unwrap_or(Element::UNKNOWN);
            assert_eq!(f.elements[i], e, "{at} particle {i} of type {t}");
        }
    } else {
        assert!(f.elements.is_empty(), "{at}: no type names an element");
    }
    let radii: Vec<f32> = f32s(&want["diameter"]).iter().map(|d| d / 2.0).collect();
    assert_eq!(f.radii, radii, "{at}");
    // Properties, column by column, where the file has the chunk.
    let columns: [(&str, &[&str]); 5] = [
        ("mass", &["mass"]),
        ("charge", &["charge"]),
        ("body", &["body"]),
        ("orientation", &["quatw", "quati", "quatj", "quatk"]),
        ("image", &["ix", "iy", "iz"]),
    ];
    let mut names = Vec::new();
    for (chunk, props) in columns {
        if !in_file.contains(&format!("particles/{chunk}")) {
            continue;
        }
        let values = f32s(&want[chunk]);
        for (j, p) in props.iter().enumerate() {
            let col: Vec<f32> = values
                .iter()
                .skip(j)
                .step_by(props.len())
                .copied()
                .collect();
            assert_eq!(f.property(p), Some(&col[..]), "{at} property {p}");
            names.push(p.to_string());
        }
    }
    let have: Vec<String> = f.properties.iter().map(|p| p.name.clone()).collect();
    assert_eq!(have, names, "{at}: the properties");
    // Velocities, where the file has them.
    if in_file.contains("particles/velocity") {
        let v = f32s(&want["velocity"]);
        let want: Vec<[f32; 3]> = v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        assert_eq!(f.velocities, want, "{at}: velocities");
    } else {
        assert!(f.velocities.is_empty(), "{at}: no velocities");
    }
    // Bonds: the pairs ordered, sorted, each once.
    let group = want["bonds_group"].as_array().unwrap();
    let bonds: BTreeSet<[u32; 2]> = group
        .iter()
        .map(|p| {
            let (a, b) = (p[0].as_u64().unwrap() as u32, p[1].as_u64().unwrap() as u32);
            [a.min(b), a.max(b)]
        })
        .collect();
    assert_eq!(group.len(), want["bonds_N"].as_u64().unwrap() as usize);
    assert_eq!(f.bonds, bonds.into_iter().collect::<Vec<_>>(), "{at}");
    // The cell: the box edges and corner computed in Python.
    let cell = f.cell.unwrap();
    let m = cell.matrix();
    for r in 0..3 {
        for c in 0..3 {
            let w = want["cell"][r][c].as_f64().unwrap();
            close(w, m[r][c], 1e-12, &format!("{at} cell[{r}][{c}]"));
        }
        let o = want["origin"][r].as_f64().unwrap();
        close(o, cell.origin()[r], 1e-12, &format!("{at} origin[{r}]"));
    }
    // Every particle inside the cell: fractional coordinates in [0, 1).
    // With the edges as columns, r - origin = A s: s = A⁻¹ (r - origin).
    let inv = glam::DMat3::from_cols_array_2d(&m).inverse();
    for (i, p) in f.positions.iter().enumerate() {
        let d = glam::DVec3::from_array(p.map(f64::from)) - glam::DVec3::from_array(cell.origin());
        let s = inv * d;
        for c in 0..3 {
            assert!(
                (-1e-6..1.0 + 1e-6).contains(&s[c]),
                "{at} particle {i} at {p:?}: fractional {s:?}"
            );
        }
    }
}

#[test]
fn every_frame_matches_gsd_hoomd_streamed_and_at_random() {
    let r = reference();
    for file in FILES {
        let want = r[file]["frames"].as_array().unwrap();
        let in_file: BTreeSet<String> = want
            .iter()
            .flat_map(|f| f["chunks"].as_array().unwrap().iter())
            .map(|c| c.as_str().unwrap().to_string())
            .collect();
        let mut traj = Trajectory::open(path(file)).unwrap();
        assert_eq!(traj.format(), Format::Gsd);
        assert_eq!(traj.n_frames().unwrap(), want.len(), "{file}");
        let frames = stream(&mut traj);
        assert_eq!(frames.len(), want.len(), "{file}");
        for (k, f) in frames.iter().enumerate() {
            compare(file, k, f, &want[k], &in_file);
        }
        // Random access, out of order: the frames streaming gave.
        let n = frames.len();
        let mut f = Frame::new();
        for k in (0..n).rev().chain((0..n).step_by(2)).chain([n / 2, 0]) {
            traj.read_frame(k, &mut f).unwrap();
            assert_eq!(f, frames[k], "{file}: frame {k} by index");
        }
        // A fresh reader whose first read is the last frame (frame 0 not read before).
        let mut fresh = Trajectory::open(path(file)).unwrap();
        fresh.read_frame(n - 1, &mut f).unwrap();
        assert_eq!(f, frames[n - 1], "{file}: the last frame first");
        assert!(!fresh.read_next(&mut f).unwrap());
        assert!(matches!(
            fresh.read_frame(n, &mut f),
            Err(Error::FrameOutOfRange { .. })
        ));
    }
}

#[test]
fn the_fixtures_exercise_the_default_rule() {
    let r = reference();
    let tri = &r["hoomd_tri.gsd"]["frames"];
    let has = |k: usize, c: &str| tri[k]["chunks"].as_array().unwrap().iter().any(|x| x == c);
    // Frame 3 takes frame 0's diameters (not frame 2's) and types, bonds and charges.
    assert!(!has(3, "particles/diameter") && has(2, "particles/diameter"));
    assert!(!has(3, "particles/types") && !has(3, "bonds/group"));
    // Frame 0 has no mass chunk: frames 1 and 3 are the default 1.0, frame 2 has its own.
    assert!(!has(0, "particles/mass") && has(2, "particles/mass"));
    // Frame 4 has fewer particles: charges, typeids, bodies are the defaults, not frame 0's.
    assert_eq!(tri[4]["N"], 180);
    assert!(!has(4, "particles/charge") && !has(4, "particles/typeid"));
    // Frame 0's step 0 is the default and not written; the 2-D file says dimensions 2.
    assert!(!has(0, "configuration/step"));
    assert_eq!(r["hoomd_2d.gsd"]["frames"][0]["dimensions"], 2);
    assert_eq!(r["hoomd_v1.gsd"]["gsd_version"][0], 1);

    let mut t = Trajectory::open(path("hoomd_tri.gsd")).unwrap();
    let mut f = Frame::new();
    t.read_frame(4, &mut f).unwrap();
    assert!(f.property("charge").unwrap().iter().all(|q| *q == 0.0));
    assert!(f.property("body").unwrap().iter().all(|b| *b == -1.0));
    assert!(f.property("quatw").unwrap().iter().all(|w| *w == 1.0));
    assert!(f.types.iter().all(|t| t == "A"));
    assert!(f.bonds.is_empty());
}

#[test]
fn a_box_of_lz_0_is_a_slab_whatever_the_dimensions_and_a_negative_one_is_refused() {
    let good = std::fs::read(path("hoomd_2d.gsd")).unwrap();
    let dims = chunk(&good, 0, "configuration/dimensions").location;
    let mut b = good.clone();
    b[dims] = 3;
    let mut t = Trajectory::from_reader(Cursor::new(b.clone()), Format::Gsd, "z.gsd").unwrap();
    let mut f = Frame::new();
    t.read_frame(0, &mut f).unwrap();
    assert_eq!(f.cell.unwrap().matrix()[2], [0.0, 0.0, 1.0]);
    b[dims] = 4;
    let mut t = Trajectory::from_reader(Cursor::new(b), Format::Gsd, "z.gsd").unwrap();
    let e = t.read_frame(0, &mut f).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "z.gsd: frame 0, byte {dims}: expected dimensions 2 or 3"
        )),
        "{e}"
    );
    // Lz = -1 in frame 1's box.
    let boxes = chunk(&good, 1, "configuration/box").location;
    let mut b = good.clone();
    b[boxes + 8..boxes + 12].copy_from_slice(&(-1.0f32).to_le_bytes());
    let mut t = Trajectory::from_reader(Cursor::new(b), Format::Gsd, "z.gsd").unwrap();
    t.read_frame(0, &mut f).unwrap();
    let e = t.read_frame(1, &mut f).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "z.gsd: frame 1, byte {boxes}: expected a box with"
        )),
        "{e}"
    );
}

#[test]
fn the_2d_box_is_a_slab_one_unit_thick() {
    let mut t = Trajectory::open(path("hoomd_2d.gsd")).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    let c = f.cell.unwrap();
    assert_eq!(c.matrix()[2], [0.0, 0.0, 1.0]);
    assert_eq!(c.origin()[2], -0.5);
    assert!(f.positions.iter().all(|p| p[2] == 0.0));
}

#[test]
fn a_cut_file_names_the_cut_frame_and_keeps_the_others() {
    let bytes = std::fs::read(path("hoomd_tri.gsd")).unwrap();
    // Cut inside frame 3's positions: frames 0-2 complete.
    let pos3 = chunk(&bytes, 3, "particles/position").location;
    let cut = bytes[..pos3 + 100].to_vec();
    let mut strict =
        Trajectory::from_reader(Cursor::new(cut.clone()), Format::Gsd, "cut.gsd").unwrap();
    let e = strict.n_frames().unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    let head = format!(
        "cut.gsd: frame 3, byte {}: file ends inside the frame",
        pos3 + 100
    );
    assert!(e.to_string().starts_with(&head), "{e}");
    assert!(e.to_string().contains("particles/position"), "{e}");
    let good = stream(&mut Trajectory::open(path("hoomd_tri.gsd")).unwrap());
    let mut f = Frame::new();
    for (k, want) in good.iter().enumerate().take(3) {
        strict.read_frame(k, &mut f).unwrap();
        assert_eq!(&f, want);
    }
    assert!(matches!(
        strict.read_next(&mut f),
        Err(Error::Truncated { .. })
    ));

    let opts = ReadOptions::new().allow_truncated(true);
    let mut lenient =
        Trajectory::from_reader_with(Cursor::new(cut), Format::Gsd, "cut.gsd", opts).unwrap();
    assert_eq!(lenient.n_frames().unwrap(), 3);
    assert_eq!(stream(&mut lenient), good[..3]);
    assert_eq!(lenient.warnings().len(), 1);
    assert_eq!(lenient.warnings()[0].to_string(), e.to_string());
}

#[test]
fn a_chunk_of_the_wrong_shape_or_type_is_located() {
    let good = std::fs::read(path("hoomd_tri.gsd")).unwrap();
    let at = chunk(&good, 2, "particles/position").entry;
    // M = 2 instead of 3.
    let mut b = good.clone();
    b[at + 24..at + 28].copy_from_slice(&2u32.to_le_bytes());
    let mut t = Trajectory::from_reader(Cursor::new(b), Format::Gsd, "m2.gsd").unwrap();
    let mut f = Frame::new();
    t.read_frame(1, &mut f).unwrap();
    let e = t.read_frame(2, &mut f).unwrap_err().to_string();
    let head = format!("m2.gsd: frame 2, byte {at}: expected particles/position: N × 3");
    assert!(e.starts_with(&head), "{e}");
    assert!(
        e.contains("found 'particles/position: 200 × 2 float"),
        "{e}"
    );
    // An integer type where floats belong.
    let mut b = good.clone();
    b[at + 30] = 3;
    let mut t = Trajectory::from_reader(Cursor::new(b), Format::Gsd, "int.gsd").unwrap();
    let e = t.read_frame(2, &mut f).unwrap_err().to_string();
    assert!(e.contains("200 × 3 uint32"), "{e}");
    // Frame 0's typeid (which frames 1-3 take) past the three types: reading frame 3 names
    // frame 3 and the byte of the value in frame 0's chunk.
    let typeid = chunk(&good, 0, "particles/typeid").location;
    let mut b = good.clone();
    b[typeid + 4 * 7..typeid + 4 * 8].copy_from_slice(&3u32.to_le_bytes());
    let mut t = Trajectory::from_reader(Cursor::new(b), Format::Gsd, "tid.gsd").unwrap();
    let e = t.read_frame(3, &mut f).unwrap_err().to_string();
    let head = format!(
        "tid.gsd: frame 3, byte {}: expected a typeid below",
        typeid + 28
    );
    assert!(e.starts_with(&head) && e.contains("particle 7"), "{e}");
}

#[test]
fn a_non_finite_or_absurd_position_names_the_particle() {
    let good = std::fs::read(path("hoomd_tri.gsd")).unwrap();
    let pos = chunk(&good, 1, "particles/position").location;
    for bad in [f32::NAN, f32::INFINITY, 1e30] {
        let mut b = good.clone();
        let at = pos + 12 * 5 + 4;
        b[at..at + 4].copy_from_slice(&bad.to_le_bytes());
        let mut t = Trajectory::from_reader(Cursor::new(b), Format::Gsd, "nan.gsd").unwrap();
        let mut f = Frame::new();
        let e = t.read_frame(1, &mut f).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("nan.gsd: frame 1, byte {at}")),
            "{e}"
        );
        assert!(e.contains("particles/position: particle 5"), "{e}");
        assert!(
            f.positions.is_empty(),
            "a failed read leaves the frame empty"
        );
    }
}

#[test]
fn open_by_extension_by_content_and_through_gzip() {
    let good = stream(&mut Trajectory::open(path("hoomd_tri.gsd")).unwrap());
    let bytes = std::fs::read(path("hoomd_tri.gsd")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    // No extension, and an extension that names no format: told by the magic number.
    for name in ["hoomd_run", "hoomd.traj"] {
        let p = dir.path().join(name);
        std::fs::write(&p, &bytes).unwrap();
        let mut t = Trajectory::open(&p).unwrap();
        assert_eq!(t.format(), Format::Gsd, "{name}");
        assert_eq!(stream(&mut t), good, "{name}");
    }
    // gzip: named .gsd.gz, and without a name that tells.
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(&bytes).unwrap();
    let gz = gz.finish().unwrap();
    for name in ["run.gsd.gz", "run.gz"] {
        let p = dir.path().join(name);
        std::fs::write(&p, &gz).unwrap();
        let mut t = Trajectory::open(&p).unwrap();
        assert_eq!(t.format(), Format::Gsd, "{name}");
        assert_eq!(t.n_frames().unwrap(), good.len());
        assert_eq!(stream(&mut t), good, "{name}");
        let mut f = Frame::new();
        t.read_frame(2, &mut f).unwrap();
        assert_eq!(f, good[2]);
    }
}

#[test]
fn other_files_and_lying_headers_are_refused() {
    let good = std::fs::read(path("hoomd_2d.gsd")).unwrap();
    let open = |b: Vec<u8>| {
        Trajectory::from_reader(Cursor::new(b), Format::Gsd, "h.gsd")
            .err()
            .unwrap()
            .to_string()
    };
    let mut b = good.clone();
    b[0] ^= 1;
    assert!(open(b).starts_with("h.gsd: byte 0: expected the GSD magic number"));
    // Another schema.
    let mut b = good.clone();
    b[112..117].copy_from_slice(b"mdtrj");
    assert!(open(b).contains("expected the hoomd schema"));
    // A file format version 3.0.
    let mut b = good.clone();
    b[44..48].copy_from_slice(&(3u32 << 16).to_le_bytes());
    assert!(open(b).contains("version 1.0 or 2.x, found '3.0'"));
    // An index of 2^40 entries, a namelist of 2^50 segments.
    for (field, what) in [(16, "an index block"), (32, "a namelist block")] {
        let mut b = good.clone();
        b[field..field + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
        let e = open(b);
        assert!(
            e.starts_with(&format!("h.gsd: byte {field}: expected {what}")),
            "{e}"
        );
    }
    // A namelist whose block does not end in NUL.
    let names_at = u64::from_le_bytes(good[24..32].try_into().unwrap()) as usize;
    let segments = u64::from_le_bytes(good[32..40].try_into().unwrap()) as usize;
    let mut b = good.clone();
    b[names_at..names_at + 64 * segments].fill(b'x');
    let e = open(b);
    let end = names_at + 64 * segments - 1;
    assert!(
        e.starts_with(&format!(
            "h.gsd: byte {end}: expected a namelist block ending in a NUL"
        )),
        "{e}"
    );
}
