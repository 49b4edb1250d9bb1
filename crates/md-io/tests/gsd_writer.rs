//! HOOMD-blue GSD files written by our writer, read back by `gsd.hoomd` (the reader HOOMD users
//! trust: gsd 5.0.1) and by our reader (tests/data/gsd_write/gen_gsd_write.py).
//!
//! - `tri`: gsd.hoomd's own 5-frame file (../gsd/hoomd_tri.gsd: a triclinic box that changes,
//!   a frame of fewer particles, bonds, orientations, images) rewritten: gsd.hoomd reads from
//!   our file, frame by frame, what it reads from the original (../gsd/reference.json.gz).
//! - `vel`: MDAnalysis's triclinic GRO with velocities (atoms outside the box, wrapped in with
//!   their images).
//! - `nacl`: ASE's primitive NaCl POSCAR, a cell in general orientation (rotated into HOOMD's).
//! - `twod`: gsd.hoomd's 2-D file (../gsd/hoomd_2d.gsd: `dimensions` 2, Lz 0, a tilted box)
//!   rewritten: still 2-D, as gsd.hoomd reads it, with the original's box and positions.

use std::io::{Cursor, Read};
use std::path::PathBuf;

use texmap_md_io::{Format, Frame, Trajectory, Writer};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

const CASES: [(&str, &str); 4] = [
    ("tri", "gsd/hoomd_tri.gsd"),
    ("vel", "mda_vel.gro"),
    ("nacl", "lammps_write/nacl_primitive.vasp"),
    ("twod", "gsd/hoomd_2d.gsd"),
];

fn frames(path: &std::path::Path) -> Vec<Frame> {
    let mut t = Trajectory::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap_or_else(|e| panic!("{e}")) {
        out.push(f.clone());
    }
    out
}

fn written(frames: &[Frame]) -> Vec<u8> {
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Gsd, "out.gsd").unwrap();
    for f in frames {
        w.write_frame(f).unwrap_or_else(|e| panic!("{e}"));
    }
    w.finish().unwrap().into_inner()
}

fn json_gz(path: &std::path::Path) -> serde_json::Value {
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(path).unwrap())
        .read_to_string(&mut text)
        .unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn rewriting_the_inputs_gives_the_committed_files() {
    for (case, src) in CASES {
        let bytes = written(&frames(&data(src)));
        let path = data(&format!("gsd_write/{case}.gsd"));
        if std::env::var_os("TEXMAP_BLESS").is_some() {
            std::fs::write(&path, &bytes).unwrap();
        }
        assert!(
            bytes == std::fs::read(&path).unwrap(),
            "{case}: {} differs from what is written now",
            path.display()
        );
    }
}

/// gsd.hoomd reads from our rewrites of hoomd_tri.gsd and of the 2-D hoomd_2d.gsd exactly what
/// it reads from the originals, the dimensionality included.
#[test]
fn gsd_hoomd_reads_our_rewrite_as_the_original() {
    for (case, original, n) in [("tri", "hoomd_tri.gsd", 5), ("twod", "hoomd_2d.gsd", 3)] {
        rewrite_reads_as_original(case, original, n);
    }
}

fn rewrite_reads_as_original(case: &str, original: &str, n: usize) {
    let ours = json_gz(&data("gsd_write/gsd_hoomd.json.gz"));
    let all = json_gz(&data("gsd/reference.json.gz"));
    let original = &all[original]["frames"];
    let ours = &ours[case]["frames"];
    assert_eq!(ours.as_array().unwrap().len(), n, "{case}");
    for (k, (o, g)) in ours
        .as_array()
        .unwrap()
        .iter()
        .zip(original.as_array().unwrap())
        .enumerate()
    {
        for key in [
            "step",
            "dimensions",
            "box",
            "N",
            "position",
            "velocity",
            "diameter",
            "mass",
            "charge",
            "orientation",
            "image",
            "body",
        ] {
            assert_eq!(o[key], g[key], "{case} frame {k}: {key}");
        }
        // Bonds: the original lists one bond twice (both orders), which a frame holds once.
        let bonds = |v: &serde_json::Value| -> Vec<[u64; 2]> {
            let mut b: Vec<[u64; 2]> = v["bonds_group"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| {
                    let (a, c) = (p[0].as_u64().unwrap(), p[1].as_u64().unwrap());
                    [a.min(c), a.max(c)]
                })
                .collect();
            b.sort_unstable();
            b.dedup();
            b
        };
        assert_eq!(bonds(o), bonds(g), "{case} frame {k}: bonds");
        assert_eq!(o["bonds_N"].as_u64().unwrap() as usize, bonds(o).len());
        // Types are numbered in order of first appearance: compare each particle's name.
        let names = |v: &serde_json::Value| -> Vec<String> {
            let types: Vec<&str> = v["types"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| t.as_str().unwrap())
                .collect();
            v["typeid"]
                .as_array()
                .unwrap()
                .iter()
                .map(|i| types[i.as_u64().unwrap() as usize].to_string())
                .collect()
        };
        assert_eq!(names(o), names(g), "{case} frame {k}: particle types");
    }
}

/// All-atom inputs: gsd.hoomd finds every particle inside HOOMD's box, and the positions plus
/// their images are the input's, moved by the same rigid motion (the rotation into HOOMD's form
/// and the shift to its centred box): every distance between atoms is kept.
#[test]
fn all_atom_inputs_are_placed_in_hoomds_box_with_their_images() {
    let ours = json_gz(&data("gsd_write/gsd_hoomd.json.gz"));
    for case in ["vel", "nacl"] {
        let src = &frames(&data(CASES.iter().find(|c| c.0 == case).unwrap().1))[0];
        let f = &ours[case]["frames"][0];
        let b: Vec<f64> = f["box"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let m = [
            [b[0], 0.0, 0.0],
            [b[3] * b[1], b[1], 0.0],
            [b[4] * b[2], b[5] * b[2], b[2]],
        ];
        let rows = |key: &str| -> Vec<[f64; 3]> {
            f[key]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| std::array::from_fn(|d| r[d].as_f64().unwrap()))
                .collect()
        };
        let (pos, img) = (rows("position"), rows("image"));
        assert_eq!(pos.len(), src.n_atoms(), "{case}");
        // Inside: fractions in [-1/2, 1/2] (Lx etc. along the restricted form's axes).
        for p in &pos {
            let fz = p[2] / m[2][2];
            let fy = (p[1] - fz * m[2][1]) / m[1][1];
            let fx = (p[0] - fz * m[2][0] - fy * m[1][0]) / m[0][0];
            for v in [fx, fy, fz] {
                assert!((-0.5 - 1e-6..=0.5 + 1e-6).contains(&v), "{case}: {p:?}");
            }
        }
        let unwrapped: Vec<[f64; 3]> = pos
            .iter()
            .zip(&img)
            .map(|(p, n)| {
                std::array::from_fn(|k| p[k] + n[0] * m[0][k] + n[1] * m[1][k] + n[2] * m[2][k])
            })
            .collect();
        let dist = |a: [f64; 3], c: [f64; 3]| {
            ((a[0] - c[0]).powi(2) + (a[1] - c[1]).powi(2) + (a[2] - c[2]).powi(2)).sqrt()
        };
        let src_p: Vec<[f64; 3]> = src.positions.iter().map(|p| p.map(f64::from)).collect();
        for i in 0..pos.len() {
            for j in 0..i {
                let (d0, d1) = (dist(src_p[i], src_p[j]), dist(unwrapped[i], unwrapped[j]));
                assert!(
                    (d0 - d1).abs() < 2e-5 * (1.0 + d0),
                    "{case} atoms {i} {j}: {d0} vs {d1}"
                );
            }
        }
        // Velocities as written; types the elements.
        if case == "vel" {
            let v = rows("velocity");
            for (a, w) in v.iter().zip(&src.velocities) {
                for k in 0..3 {
                    assert_eq!(a[k] as f32, w[k], "{case}");
                }
            }
        }
    }
}

/// Our reader on our files: frames as written, through HOOMD's box.
#[test]
fn our_reader_reads_our_files_back() {
    for (case, src) in CASES {
        let a = frames(&data(src));
        let b = frames(&data(&format!("gsd_write/{case}.gsd")));
        assert_eq!(a.len(), b.len(), "{case}");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.n_atoms(), y.n_atoms(), "{case}");
            assert_eq!(x.velocities, y.velocities, "{case}");
            assert_eq!(x.bonds, y.bonds, "{case}");
            let vol = |f: &Frame| f.cell.unwrap().volume();
            assert!((vol(x) - vol(y)).abs() < 1e-6 * vol(x), "{case}");
            if case == "tri" {
                // Already in HOOMD's form and inside its box: nothing moves.
                assert_eq!(x.positions, y.positions);
                assert_eq!(x.types, y.types);
                assert_eq!(x.radii, y.radii);
            } else {
                let sym = |f: &Frame| f.elements.iter().map(|e| e.symbol()).collect::<Vec<_>>();
                assert_eq!(sym(x), sym(y), "{case}");
            }
        }
    }
}

/// gsd.hoomd itself on files written now, where python3 has the gsd package.
#[test]
fn gsd_hoomd_reads_files_written_now() {
    let probe = std::process::Command::new("python3")
        .args(["-c", "import gsd.hoomd"])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!("SKIPPED: no python3 with gsd (pip install gsd); the committed files cover it");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut frames = frames(&data("gsd/hoomd_tri.gsd"));
    // Different steps, and one frame without bonds after frames with them.
    for (k, f) in frames.iter_mut().enumerate() {
        f.step = Some(1000 * k as i64 + 7);
    }
    frames[1].bonds.clear();
    let path = dir.path().join("now.gsd");
    std::fs::write(&path, written(&frames)).unwrap();
    let script = "import sys, gsd.hoomd\n\
        t = gsd.hoomd.open(sys.argv[1], 'r')\n\
        for f in t:\n\
        \x20   print(f.configuration.step, f.particles.N, f.bonds.N, f.particles.types, \
        float(f.particles.position[3][1]), float(f.configuration.box[3]))\n";
    let o = std::process::Command::new("python3")
        .args(["-c", script])
        .arg(&path)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 5, "{text}");
    for (k, (line, f)) in lines.iter().zip(&frames).enumerate() {
        let w: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(w[0], (1000 * k + 7).to_string(), "{line}");
        assert_eq!(w[1], f.n_atoms().to_string(), "{line}");
        assert_eq!(w[2], f.bonds.len().to_string(), "{line}");
        let y: f32 = w[w.len() - 2].parse().unwrap();
        assert_eq!(y, f.positions[3][1], "{line}");
    }
}

#[test]
fn what_the_schema_cannot_hold_is_refused_naming_the_frame() {
    let mut f = frames(&data("mda_vel.gro")).remove(0);
    f.step = Some(-5);
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Gsd, "bad.gsd").unwrap();
    let e = w.write_frame(&f).unwrap_err().to_string();
    assert!(
        e.contains("bad.gsd") && e.contains("frame 0") && e.contains("step -5"),
        "{e}"
    );
}

/// A cell rotated into HOOMD's form turns the velocities with the positions: a velocity along
/// the cell's first edge is along HOOMD's a1 = (Lx, 0, 0) in the file.
#[test]
fn velocities_turn_with_a_rotated_box() {
    let mut f = frames(&data("lammps_write/nacl_primitive.vasp")).remove(0);
    let a = f.cell.unwrap().matrix()[0];
    assert!(
        a[1] != 0.0 || a[2] != 0.0,
        "the cell is not in HOOMD's form"
    );
    f.velocities = vec![a.map(|x| x as f32); f.n_atoms()];
    let back = Trajectory::from_reader(Cursor::new(written(&[f])), Format::Gsd, "r.gsd")
        .and_then(|mut t| {
            let mut g = Frame::new();
            t.read_next(&mut g).map(|_| g)
        })
        .unwrap();
    let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    for v in &back.velocities {
        let want = [len, 0.0, 0.0];
        for k in 0..3 {
            // An f64 rotation of f32 values of ~8, rounded to f32: within 2e-6.
            assert!(
                (v[k] as f64 - want[k]).abs() <= 2e-6,
                "{v:?} vs {want:?}, tolerance 2e-6"
            );
        }
    }
}
