//! XCrySDen XSF / AXSF: structures as frames (`Format::Xsf`) and data grids as volumes
//! (`volume::read_volumes`).
//!
//! - Files written by ASE 3.29 and pymatgen 2026.10 (tests/data/xsf, `gen_xsf.py`) against
//!   what those programs' own readers give back (`reference.json`): every frame's elements,
//!   positions (to f32 rounding), cell (to 1e-6 Å) and forces (eV/Å); every grid's counts,
//!   origin, spanning vectors and values.
//! - The analytic functions the script sampled, evaluated here at the grid points: the
//!   general grid over a crystal's cell read as a periodic volume (its repeated end planes
//!   dropped), ASE's default grid kept whole and not periodic.
//! - Synthetic files for each rule (pp.x's spelling, keywords in any case, comments, species
//!   labels, 2-D grids, sections read past) and damage: cuts, non-numbers, counts larger than
//!   the data, hostile counts under a heap cap, every cut and replaced byte of a grid file.

use crate::support;

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use support::alloc::measure;
use texmap_md_io::volume::{Volume, VolumeFormat, read_volumes, read_volumes_from};
use texmap_md_io::{Error, Format, Frame, Trajectory};

/// eV per Hartree (CODATA 2018), as the reader uses it.
const HARTREE: f64 = 27.211386245988;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/xsf")
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir().join("reference.json")).unwrap()).unwrap()
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

fn frames(path: &std::path::Path) -> Vec<Frame> {
    let mut t = Trajectory::open(path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(t.format(), Format::Xsf);
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f).unwrap_or_else(|e| panic!("{e}")) {
        out.push(f.clone());
    }
    assert_eq!(t.n_frames().unwrap(), out.len());
    out
}

/// Compares a frame with ASE's reading of it.
fn check_frame(got: &Frame, want: &Value, what: &str) {
    let numbers: Vec<u64> = want["numbers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|z| z.as_u64().unwrap())
        .collect();
    let z: Vec<u64> = got.elements.iter().map(|e| e.z() as u64).collect();
    assert_eq!(z, numbers, "{what}: elements");
    let positions = want["positions"].as_array().unwrap();
    assert_eq!(got.n_atoms(), positions.len(), "{what}");
    for (i, p) in positions.iter().enumerate() {
        let p = f64s(p);
        let w = [p[0] as f32, p[1] as f32, p[2] as f32];
        assert_eq!(got.positions[i], w, "{what}: atom {i}");
    }
    let pbc: Vec<bool> = want["pbc"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_bool().unwrap())
        .collect();
    let kind = match pbc[..] {
        [true, true, true] => "CRYSTAL",
        [true, true, false] => "SLAB",
        [true, false, false] => "POLYMER",
        _ => "",
    };
    assert_eq!(got.comment, kind, "{what}: the dimensionality keyword");
    match want["cell"].as_array() {
        Some(rows) => {
            let m = got
                .cell
                .unwrap_or_else(|| panic!("{what}: no cell"))
                .matrix();
            for (r, row) in rows.iter().enumerate() {
                for (c, x) in f64s(row).into_iter().enumerate() {
                    close(m[r][c], x, 1e-6, &format!("{what}: cell {r} {c}"));
                }
            }
        }
        None => assert!(got.cell.is_none(), "{what}: a molecule has no cell"),
    }
    match want["forces"].as_array() {
        Some(rows) => {
            let cols = ["fx", "fy", "fz"].map(|n| {
                got.property(n)
                    .unwrap_or_else(|| panic!("{what}: no {n}"))
                    .to_vec()
            });
            for (i, row) in rows.iter().enumerate() {
                for (a, x) in f64s(row).into_iter().enumerate() {
                    // ASE's Hartree (CODATA 2014) differs from ours by 8e-9, relative.
                    let tol = 2e-7 * x.abs().max(1e-3);
                    close(cols[a][i] as f64, x, tol, &format!("{what}: force {i} {a}"));
                }
            }
        }
        None => assert!(got.properties.is_empty(), "{what}: no forces"),
    }
}

#[test]
fn frames_read_as_ase_reads_them() {
    let want = reference();
    let files = want.as_object().unwrap();
    let mut n = 0;
    for (name, w) in files {
        let Some(frames_want) = w.get("frames") else {
            continue;
        };
        n += 1;
        let path = dir().join(name);
        let got = frames(&path);
        let frames_want = frames_want.as_array().unwrap();
        assert_eq!(got.len(), frames_want.len(), "{name}: frames");
        let animated = name.ends_with(".axsf");
        for (k, (g, w)) in got.iter().zip(frames_want).enumerate() {
            let what = format!("{name} frame {k}");
            check_frame(g, w, &what);
            assert_eq!(g.step, animated.then_some(k as i64 + 1), "{what}: step");
        }
        // Random access: the last frame, then the first, by index.
        let mut t = Trajectory::open(&path).unwrap();
        let mut f = Frame::new();
        let last = got.len() - 1;
        t.read_frame(last, &mut f).unwrap();
        assert_eq!(f, got[last], "{name}: frame {last} by index");
        t.read_frame(0, &mut f).unwrap();
        assert_eq!(f, got[0], "{name}: frame 0 by index");
        assert_eq!(t.n_atoms().unwrap(), got[0].n_atoms());
    }
    assert_eq!(n, 10);
}

/// pymatgen's own reading of its file: species, Cartesian coordinates, lattice and the
/// forces as written (Hartree/Å, read here times the Hartree).
#[test]
fn pymatgens_file_reads_as_pymatgen_reads_it() {
    let want = &reference()["pmg_grids.xsf"]["pymatgen"];
    let f = &frames(&dir().join("pmg_grids.xsf"))[0];
    let species: Vec<&str> = want["species"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    let got: Vec<&str> = f.elements.iter().map(|e| e.symbol()).collect();
    assert_eq!(got, species);
    let names: Vec<&str> = f.names.iter().map(|n| n.as_str()).collect();
    assert_eq!(names, species, "symbols as written are the names");
    for (i, p) in want["cart_coords"].as_array().unwrap().iter().enumerate() {
        let p = f64s(p);
        assert_eq!(f.positions[i], [p[0] as f32, p[1] as f32, p[2] as f32]);
    }
    let m = f.cell.unwrap().matrix();
    for (r, row) in want["lattice"].as_array().unwrap().iter().enumerate() {
        for (c, x) in f64s(row).into_iter().enumerate() {
            close(m[r][c], x, 1e-12, "lattice");
        }
    }
    let fx = f.property("fx").unwrap();
    let fz = f.property("fz").unwrap();
    for (i, row) in want["forces"].as_array().unwrap().iter().enumerate() {
        let row = f64s(row);
        assert_eq!(fx[i], (row[0] * HARTREE) as f32);
        assert_eq!(fz[i], (row[2] * HARTREE) as f32);
    }
}

/// The reference's grid `g` (values x fastest) at point (i, j, k).
fn ref_at(g: &Value, values: &[f64], i: usize, j: usize, k: usize) -> f64 {
    let s: Vec<usize> = f64s(&g["shape"]).iter().map(|x| *x as usize).collect();
    values[(k * s[1] + j) * s[0] + i]
}

/// Every grid of the grid files against ASE's (or pymatgen's) reading: counts, origin, spans
/// and values; a general grid over a crystal's cell as a periodic volume without its repeated
/// end planes, ASE's default grid (spans cell·(n+1)/n) whole and not periodic.
#[test]
fn grids_read_as_ase_and_pymatgen_read_them() {
    let want = reference();
    let mut n = 0;
    for (name, w) in want.as_object().unwrap() {
        let Some(grids) = w.get("grids").and_then(Value::as_array) else {
            continue;
        };
        n += 1;
        let (frame, sets) = read_volumes(dir().join(name)).unwrap_or_else(|e| panic!("{e}"));
        // The atoms are the file's last structure, as ASE's read_xsf(read_data=True) gives.
        let frames = w["frames"].as_array().unwrap();
        check_frame(&frame, frames.last().unwrap(), name);
        assert_eq!(sets.len(), grids.len(), "{name}");
        let periodic = w["frames"][0]["pbc"][0].as_bool().unwrap();
        for (s, (v, g)) in sets.iter().zip(grids).enumerate() {
            let what = format!("{name} grid {s}");
            let shape: Vec<usize> = f64s(&g["shape"]).iter().map(|x| *x as usize).collect();
            let values = f64s(&g["values"]);
            let origin = f64s(&g["origin"]);
            let span: Vec<Vec<f64>> = g["span"].as_array().unwrap().iter().map(f64s).collect();
            let label = g.get("label").map_or("grid#1", |l| {
                l.as_str().unwrap().trim_start_matches("grid/")
            });
            let block = g.get("block").map_or("data", |b| b.as_str().unwrap());
            assert_eq!(v.name, format!("{block}: {label}"), "{what}");
            assert_eq!(v.periodic, periodic, "{what}");
            let kept: Vec<usize> = shape.iter().map(|n| n - periodic as usize).collect();
            assert_eq!(v.dims.to_vec(), kept, "{what}: points");
            for a in 0..3 {
                close(v.origin[a], origin[a], 1e-12, &format!("{what}: origin"));
                for (c, x) in span[a].iter().enumerate() {
                    // A periodic grid's steps are the cell's vectors / N (the spans are
                    // written with fewer digits); a general grid's its spans / (n - 1).
                    let step = x / (kept[a] - !periodic as usize) as f64;
                    close(v.steps[a][c], step, 1e-6, &format!("{what}: step {a}"));
                }
            }
            // Every point, and the dropped planes: the first ones again.
            for k in 0..shape[2] {
                for j in 0..shape[1] {
                    for i in 0..shape[0] {
                        let x = ref_at(g, &values, i, j, k) as f32;
                        let (a, b, c) = if periodic {
                            (i % kept[0], j % kept[1], k % kept[2])
                        } else {
                            (i, j, k)
                        };
                        assert_eq!(v.at(a, b, c), x, "{what} at {i} {j} {k}");
                    }
                }
            }
        }
    }
    assert_eq!(n, 4);
}

/// The periodic functions of gen_xsf.py, of the fractional coordinates.
fn periodic_fn(which: &str, s: [f64; 3]) -> f64 {
    let tau = std::f64::consts::TAU;
    match which {
        "f" => {
            0.5 + 0.3 * (tau * s[0]).cos()
                + 0.2 * (tau * (s[1] + 2.0 * s[2])).sin()
                + 0.1 * (tau * (s[0] - s[1] + s[2])).cos()
        }
        "g" => (tau * s[0]).sin() * (tau * s[1]).cos() + 0.25 * (2.0 * tau * s[2]).cos(),
        _ => unreachable!(),
    }
}

/// The analytic functions the script sampled, at every grid point: the periodic ones on the
/// general grids over the cell (the volume tiling the cell, wrapping at N), the Gaussians on
/// ASE's default molecule grid.
#[test]
fn grid_values_are_the_sampled_functions() {
    let want = reference();
    let mut checked = 0;
    for (name, w) in want.as_object().unwrap() {
        let Some(analytic) = w.get("analytic") else {
            continue;
        };
        let (frame, sets) = read_volumes(dir().join(name)).unwrap();
        if let Some(fns) = analytic.get("periodic") {
            let cell = frame.cell.unwrap().matrix();
            // 6 decimals (ASE) or 14 (pymatgen), then f32.
            let tol = if name.starts_with("ase") { 6e-7 } else { 1e-7 };
            for (v, f) in sets.iter().zip(fns.as_array().unwrap()) {
                let f = f.as_str().unwrap();
                assert!(v.periodic, "{name}");
                let n = v.dims;
                for (a, row) in cell.iter().enumerate() {
                    for (c, x) in row.iter().enumerate() {
                        close(v.steps[a][c] * n[a] as f64, *x, 1e-12, "tiles the cell");
                    }
                }
                for k in 0..n[2] {
                    for j in 0..n[1] {
                        for i in 0..n[0] {
                            let s = [i, j, k].map(|x| x as f64);
                            let s = [s[0] / n[0] as f64, s[1] / n[1] as f64, s[2] / n[2] as f64];
                            let want = periodic_fn(f, s);
                            close(v.at(i, j, k) as f64, want, tol, &format!("{name} {f}"));
                        }
                    }
                }
                // A point and its image one cell vector over read the same.
                let p = v.point(0.3, 1.7, 2.2);
                let q: [f64; 3] = std::array::from_fn(|c| p[c] + cell[0][c] - cell[2][c]);
                close(
                    v.interpolate(p).unwrap(),
                    v.interpolate(q).unwrap(),
                    1e-5,
                    "periodic image",
                );
                checked += 1;
            }
        }
        if let Some(g) = analytic.get("gaussians") {
            let sigma = g["sigma"].as_f64().unwrap();
            let weights = f64s(&g["weights"]);
            let centres: Vec<Vec<f64>> =
                g["centres"].as_array().unwrap().iter().map(f64s).collect();
            let v = &sets[0];
            assert!(!v.periodic);
            for k in 0..v.dims[2] {
                for j in 0..v.dims[1] {
                    for i in 0..v.dims[0] {
                        let p = v.point(i as f64, j as f64, k as f64);
                        let want: f64 = weights
                            .iter()
                            .zip(&centres)
                            .map(|(w, c)| {
                                let r2: f64 = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum();
                                w * (-r2 / (2.0 * sigma * sigma)).exp()
                            })
                            .sum();
                        // The origin and spans are written with 6 decimals.
                        close(
                            v.at(i, j, k) as f64,
                            want,
                            1e-5,
                            &format!("{name} {i} {j} {k}"),
                        );
                    }
                }
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 5);
}

fn read(text: &str, name: &str) -> Result<(Frame, Vec<Volume>), Error> {
    read_volumes_from(text.as_bytes(), VolumeFormat::Xsf, name)
}

fn traj(text: &str, name: &str) -> Result<Vec<Frame>, Error> {
    let mut t = Trajectory::from_reader(Cursor::new(text.to_string()), Format::Xsf, name)?;
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f)? {
        out.push(f.clone());
    }
    Ok(out)
}

/// A pp.x-style file: keywords indented as Fortran's list-directed output writes them, species
/// labels, `DATAGRID_3D_UNKNOWN` without BEGIN_, N + 1 points over the cell, e13.5 values.
fn ppx(values: impl Fn(usize, usize, usize) -> f64) -> String {
    let mut s = String::from(
        " CRYSTAL\n PRIMVEC\n    2.000000000    0.000000000    0.000000000\n\
         \x20   0.000000000    3.000000000    0.000000000\n\
         \x20   0.500000000    0.000000000    4.000000000\n PRIMCOORD\n           2           1\n\
         Fe1      0.000000000    0.000000000    0.000000000\n\
         O_up     1.000000000    1.500000000    2.000000000\n\
         BEGIN_BLOCK_DATAGRID_3D\n3D_PWSCF\nDATAGRID_3D_UNKNOWN\n           3           4           3\n\
         \x20 0.000000  0.000000  0.000000\n    2.000000    0.000000    0.000000\n\
         \x20   0.000000    3.000000    0.000000\n    0.500000    0.000000    4.000000\n",
    );
    let mut n = 0;
    for k in 0..3 {
        for j in 0..4 {
            for i in 0..3 {
                s += &format!("{:13.5E}", values(i, j, k));
                n += 1;
                if n % 6 == 0 {
                    s += "\n";
                }
            }
        }
    }
    s + "\nEND_DATAGRID_3D\nEND_BLOCK_DATAGRID_3D\n"
}

/// Periodic over a 2 x 3 x 2 grid: the value of point (i mod 2, j mod 3, k mod 2).
fn wrapped(i: usize, j: usize, k: usize) -> f64 {
    let (i, j, k) = (i % 2, j % 3, k % 2);
    (1 + i + 10 * j + 100 * k) as f64 * 1e-3
}

#[test]
fn a_ppx_file_is_a_periodic_volume_over_its_cell() {
    let (frame, sets) = read(&ppx(wrapped), "rho.xsf").unwrap();
    assert_eq!(frame.comment, "CRYSTAL");
    let names: Vec<&str> = frame.names.iter().map(|n| n.as_str()).collect();
    assert_eq!(names, ["Fe1", "O_up"]);
    let symbols: Vec<&str> = frame.elements.iter().map(|e| e.symbol()).collect();
    assert_eq!(symbols, ["Fe", "O"]);
    let v = &sets[0];
    assert_eq!(v.name, "3D_PWSCF: UNKNOWN");
    assert!(v.periodic);
    assert_eq!(v.dims, [2, 3, 2]);
    assert_eq!(
        v.steps,
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.25, 0.0, 2.0]]
    );
    for k in 0..2 {
        for j in 0..3 {
            for i in 0..2 {
                let w = wrapped(i, j, k);
                close(v.at(i, j, k) as f64, w, 1e-6 * w, "value");
            }
        }
    }
    // The integral over the cell: the mean value times the cell volume.
    let mean = v.data.iter().map(|x| *x as f64).sum::<f64>() / 12.0;
    close(v.integral(), mean * 24.0, 1e-9, "integral");

    // End planes that do not repeat the first ones: not periodic, every point kept.
    let (_, sets) = read(&ppx(|i, j, k| (i + j + k) as f64), "ramp.xsf").unwrap();
    let v = &sets[0];
    assert!(!v.periodic);
    assert_eq!(v.dims, [3, 4, 3]);
    assert_eq!(v.steps[0], [1.0, 0.0, 0.0]);
    assert_eq!(v.at(2, 3, 2), 7.0);

    // The same grid in a slab: not periodic in 3-D, every point kept.
    let slab = ppx(wrapped).replacen(" CRYSTAL", "SLAB", 1);
    let (frame, sets) = read(&slab, "slab.xsf").unwrap();
    assert_eq!(frame.comment, "SLAB");
    assert!(frame.cell.is_some());
    assert!(!sets[0].periodic);
    assert_eq!(sets[0].dims, [3, 4, 3]);

    // Spans over part of the cell: not periodic.
    let part = ppx(wrapped).replacen("    2.000000    0.000000", "    1.000000    0.000000", 1);
    let (_, sets) = read(&part, "part.xsf").unwrap();
    assert!(!sets[0].periodic);
    assert_eq!(sets[0].steps[0], [0.5, 0.0, 0.0]);
}

#[test]
fn keywords_comments_and_blank_lines_anywhere() {
    let text = "# made by hand\n\nanimsteps 2\n# a comment\nMolecule\n\natoms 1\n\
                h 0 0 0\n# between atoms\nH 0.74 0 0\n\nAtoms 2\n1 0 0 0\nh 0.8 0 0\n\
                begin_info\n  anything\nend_info\n";
    let frames = traj(text, "h2.axsf").unwrap();
    assert_eq!(frames.len(), 2);
    assert_eq!(frames[0].positions[1], [0.74, 0.0, 0.0]);
    assert_eq!(frames[1].positions[1], [0.8, 0.0, 0.0]);
    assert_eq!(frames[1].comment, "MOLECULE");
    assert_eq!(frames[1].step, Some(2));
    assert!(frames.iter().all(|f| f.cell.is_none()));
    assert_eq!(Format::from_magic(text.as_bytes()), Some(Format::Xsf));
}

/// A block of two grids after an animation's last step (a variable cell: the grids are
/// compared with that step's), then a 2-D block: the trajectory reads past the 2-D grid,
/// read_volumes refuses it.
#[test]
fn grid_blocks_after_a_variable_cell_animation_and_a_2d_grid() {
    let mut text = String::from("ANIMSTEPS 2\nCRYSTAL\nPRIMVEC 1\n3 0 0\n0 3 0\n0 0 3\n");
    text += "PRIMCOORD 1\n1 1\nNa 0 0 0\nPRIMVEC 2\n2 0 0\n0 2 0\n0 0 2\nPRIMCOORD 2\n1 1\n";
    text += "Na 0.1 0 0\nBEGIN_BLOCK_DATAGRID_3D\nboth\n";
    for g in ["a", "b"] {
        text += &format!("BEGIN_DATAGRID_3D_{g}\n2 2 2\n0 0 0\n2 0 0\n0 2 0\n0 0 2\n");
        text += "1 1 1 1 1 1 1 1\nEND_DATAGRID_3D\n";
    }
    text += "END_BLOCK_DATAGRID_3D\n";
    let (frame, sets) = read(&text, "two.axsf").unwrap();
    assert_eq!(frame.positions[0], [0.1, 0.0, 0.0]);
    let names: Vec<&str> = sets.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names, ["both: a", "both: b"]);
    assert!(sets.iter().all(|v| v.periodic && v.dims == [1, 1, 1]));
    let frames = traj(&text, "two.axsf").unwrap();
    assert_eq!(frames.len(), 2);
    assert_eq!(frames[0].cell.unwrap().lengths(), [3.0; 3]);
    assert_eq!(frames[1].cell.unwrap().lengths(), [2.0; 3]);

    let two_d = format!(
        "{text}BEGIN_BLOCK_DATAGRID_2D\nplane\nBEGIN_DATAGRID_2D_x\n2 2\n0 0 0\n1 0 0\n0 1 0\n\
         1 2 3 4\nEND_DATAGRID_2D\nEND_BLOCK_DATAGRID_2D\n"
    );
    assert_eq!(traj(&two_d, "2d.axsf").unwrap().len(), 2);
    let e = read(&two_d, "2d.axsf").unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("2d.axsf: frame 1, line 36, byte "), "{msg}");
    assert!(msg.contains("2-D grids are not read"), "{msg}");
}

fn error_of(text: &str, name: &str) -> Error {
    traj(text, name).unwrap_err()
}

#[test]
fn damage_is_an_error_naming_the_file_line_and_what_was_expected() {
    let good = std::fs::read_to_string(dir().join("ase_anim_fixed.axsf")).unwrap();
    // Cut inside step 3's atoms: a truncated frame 2.
    let at = good.find("PRIMCOORD 3").unwrap() + 20;
    let cut = &good[..good[..at].rfind('\n').unwrap() + 1];
    let e = error_of(cut, "cut.axsf");
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().starts_with("cut.axsf: frame 2, line "), "{e}");
    // Cut between steps: ANIMSTEPS says 4.
    let cut = &good[..good.find("PRIMCOORD 4").unwrap()];
    let e = error_of(cut, "cut.axsf");
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().contains("structure 4 of ANIMSTEPS 4"), "{e}");
    // A non-number.
    let bad = good.replacen("0.89881000973497", "0.8988x000973497", 1);
    let e = error_of(&bad, "bad.axsf");
    let msg = e.to_string();
    assert!(msg.starts_with("bad.axsf: frame 0, line 9, byte "), "{msg}");
    assert!(msg.ends_with("found '0.8988x000973497'"), "{msg}");
    // A PRIMCOORD count larger than its atoms: the next keyword stands where an atom was due.
    let more = good.replacen(" 3 1\n", " 4 1\n", 1);
    let e = error_of(&more, "more.axsf");
    let msg = e.to_string();
    assert!(
        msg.starts_with("more.axsf: frame 0, line 12, byte "),
        "{msg}"
    );
    assert!(
        msg.contains("as many atom lines as the count after PRIMCOORD"),
        "{msg}"
    );
    // … and in the last step: the file ends.
    let k = good.rfind(" 3 1\n").unwrap();
    let last = format!("{} 5 1\n{}", &good[..k], &good[k + 5..]);
    let e = error_of(&last, "last.axsf");
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().contains("2 more atom lines"), "{e}");
    // More steps than ANIMSTEPS.
    let few = good.replacen("ANIMSTEPS 4", "ANIMSTEPS 3", 1);
    let e = error_of(&few, "few.axsf");
    assert!(e.to_string().starts_with("few.axsf: frame 3, line "), "{e}");
    assert!(
        e.to_string().contains("no more structures than ANIMSTEPS"),
        "{e}"
    );
    // Forces on some atom lines only.
    let mixed = std::fs::read_to_string(dir().join("ase_anim_molecule.axsf")).unwrap();
    let line = mixed.lines().nth(3).unwrap();
    let short: String = line
        .split_whitespace()
        .take(4)
        .collect::<Vec<_>>()
        .join(" ");
    let e = error_of(&mixed.replacen(line, &short, 1), "mixed.axsf");
    assert!(
        e.to_string()
            .contains("as many numbers as the frame's first"),
        "{e}"
    );
    // PRIMCOORD in a molecule, ATOMS in a crystal, PRIMVEC missing.
    let e = error_of("ATOMS\n1 0 0 0\nPRIMCOORD\n1 1\n1 0 0 0\n", "m.xsf");
    assert!(
        e.to_string().contains("CRYSTAL, SLAB, POLYMER or MOLECULE"),
        "{e}"
    );
    let e = error_of("CRYSTAL\nATOMS\n1 0 0 0\n", "c.xsf");
    assert!(e.to_string().contains("ATOMS is a molecule's"), "{e}");
    let e = error_of("CRYSTAL\nPRIMCOORD\n1 1\n1 0 0 0\n", "c.xsf");
    assert!(e.to_string().contains("PRIMVEC (the cell) before"), "{e}");
    // A left-handed crystal cell.
    let e = error_of(
        "CRYSTAL\nPRIMVEC\n0 1 0\n1 0 0\n0 0 1\nPRIMCOORD\n1 1\n1 0 0 0\n",
        "l.xsf",
    );
    assert!(e.to_string().starts_with("l.xsf: frame 0, line 5"), "{e}");
    // A slab whose vacuum vector is written as zeros has no cell.
    let f = traj(
        "SLAB\nPRIMVEC\n1 0 0\n0 1 0\n0 0 0\nPRIMCOORD\n1 1\n1 0 0 0\n",
        "s.xsf",
    )
    .unwrap();
    assert!(f[0].cell.is_none());
    // An unknown element symbol.
    let e = error_of("ATOMS\nQq 0 0 0\n", "q.xsf");
    assert!(
        e.to_string()
            .contains("an atomic number 0 to 255 or an element"),
        "{e}"
    );
}

#[test]
fn grid_damage_names_the_grid_and_the_place() {
    let good = std::fs::read_to_string(dir().join("ase_grid_small.xsf")).unwrap();
    // Cut inside the values.
    let k = good.find("END_DATAGRID_3D").unwrap() - 40;
    let cut = &good[..good[..k].rfind('\n').unwrap() + 1];
    let e = read(cut, "cut.xsf").unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("60 values of grid 'grid#1' (4x3x5 points)"),
        "{e}"
    );
    // The trajectory reader checks the values too: the error is frame 0's.
    let e = traj(cut, "cut.xsf").unwrap_err();
    assert!(e.to_string().starts_with("cut.xsf: frame 0, line "), "{e}");
    // A value that is not a number.
    let bad = good.replacen("0.263397", "0.26x397", 1);
    let e = read(&bad, "bad.xsf").unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("bad.xsf: frame 0, line 22, byte "), "{msg}");
    assert!(msg.ends_with("found '0.26x397'"), "{msg}");
    // Fewer values than the counts: END_DATAGRID_3D where a value was due.
    let fewer = good.replacen("  4 3 5\n", "  4 3 6\n", 1);
    let e = read(&fewer, "fewer.xsf").unwrap_err();
    assert!(e.to_string().contains("found 'END_DATAGRID_3D'"), "{e}");
    // One count of 1: a general grid has both ends.
    let one = good.replacen("  4 3 5\n", "  4 1 5\n", 1);
    let e = read(&one, "one.xsf").unwrap_err();
    assert!(e.to_string().contains("each ≥ 2"), "{e}");
    // No END_BLOCK_DATAGRID_3D.
    let open = good.replace("END_BLOCK_DATAGRID_3D\n", "");
    let e = read(&open, "open.xsf").unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(
        e.to_string().contains("END_BLOCK_DATAGRID_3D closing"),
        "{e}"
    );
}

#[test]
fn hostile_counts_are_refused_before_any_allocation() {
    let grid = std::fs::read_to_string(dir().join("ase_grid_small.xsf")).unwrap();
    let anim = std::fs::read_to_string(dir().join("ase_anim_fixed.axsf")).unwrap();
    let cases = [
        grid.replacen("  4 3 5\n", "  2000 3000 2000\n", 1),
        grid.replacen("  4 3 5\n", "  1024 1024 1024\n", 1),
        grid.replacen("  4 3 5\n", "  9223372036854775807 2 2\n", 1),
        grid.replacen(" 2 1\n", " 2000000000 1\n", 1),
        anim.replacen("ANIMSTEPS 4", "ANIMSTEPS 4000000000", 1),
        anim.replacen(" 3 1\n", " 999999999999 1\n", 1),
    ];
    for text in &cases {
        let (r, peak) = measure(|| read(text, "hostile.xsf"));
        assert!(r.is_err(), "{text:.120}");
        assert!(
            peak < 2 << 20,
            "{peak} bytes for a {} byte file",
            text.len()
        );
        let (r, peak) = measure(|| traj(text, "hostile.xsf"));
        assert!(
            peak < 2 << 20,
            "{peak} bytes for a {} byte file",
            text.len()
        );
        if let Err(e) = r {
            assert!(e.to_string().starts_with("hostile.xsf: frame "), "{e}");
        }
    }
    // With the file's size known, a grid it cannot hold is refused at its counts line.
    let tmp = std::env::temp_dir().join(format!("texmap-xsf-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let path = tmp.join("big.xsf");
    std::fs::write(&path, grid.replacen("  4 3 5\n", "  40 30 50\n", 1)).unwrap();
    let e = read_volumes(&path).unwrap_err();
    assert!(
        e.to_string().contains("line 13") && e.to_string().contains("2^30"),
        "{e}"
    );
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// Every cut of the small grid file is an error, or reads the structure and no grid (a cut
/// between the atoms and the grid block, where the rest is optional, cannot be told from a
/// whole file), or reads everything (only the cut of the final newline); replaced bytes give a
/// located error or a read; neither holds more heap than 64 x the bytes + 1 MiB.
#[test]
fn every_cut_and_replaced_byte_of_a_grid_file_is_an_error_or_a_read() {
    let name = "ase_grid_small.xsf";
    let good = std::fs::read(dir().join(name)).unwrap();
    let (_, all) = read_volumes_from(&good[..], VolumeFormat::Xsf, name).unwrap();
    let cap = 64 * good.len() + (1 << 20);
    let located = |e: &Error| {
        let at = e.location().unwrap_or_else(|| panic!("{e}"));
        assert!(e.to_string().starts_with(name), "{e}");
        assert!(at.line.is_some() && at.byte.is_some(), "{e}");
    };
    let end = good.len() - "END_BLOCK_DATAGRID_3D\n".len();
    for cut in 0..good.len() {
        let (r, peak) = measure(|| read_volumes_from(&good[..cut], VolumeFormat::Xsf, name));
        assert!(peak <= cap, "cut at {cut}: {peak} bytes");
        match r {
            Err(e) => located(&e),
            Ok((_, sets)) if sets.is_empty() => {
                assert!(cut < good.len() / 2, "cut at {cut} read no grid");
            }
            Ok((_, sets)) => {
                assert!(
                    cut >= end + "END_BLOCK_DATAGRID_3D".len(),
                    "cut at {cut} read"
                );
                assert_eq!(sets, all);
            }
        }
    }
    for at in 0..good.len() {
        for junk in [b'x', b'\n', b' ', 0xff] {
            let mut bad = good.clone();
            bad[at] = junk;
            let (r, peak) = measure(|| read_volumes_from(&bad[..], VolumeFormat::Xsf, name));
            assert!(peak <= cap, "byte {at}: {peak} bytes");
            if let Err(e) = r {
                located(&e);
            }
        }
    }
}

#[test]
fn names_and_extensions() {
    for name in ["a.xsf", "b.AXSF", "c.xsf.gz"] {
        let p = std::path::Path::new(name);
        assert_eq!(Format::from_path(p), Some(Format::Xsf), "{name}");
        assert_eq!(
            VolumeFormat::from_path(p),
            Some(VolumeFormat::Xsf),
            "{name}"
        );
    }
    assert_eq!(Format::from_extension("xsf"), Some(Format::Xsf));
    assert_eq!(Format::Xsf.name(), "xsf");
    // A file without a structure or a grid: no frames, no volumes.
    assert_eq!(traj("# nothing\n\n", "empty.xsf").unwrap().len(), 0);
    assert!(read("", "empty.xsf").unwrap().1.is_empty());
}
