//! End-to-end tests of `texmap render --isosurface` on volumetric data written by another
//! program: formaldehyde's HOMO as PySCF 2.14 writes a Gaussian cube file
//! (tests/data/orbital/gen_orbital.py), against scikit-image's marching cubes of the same data
//! and the reference ray tracer.

use std::path::Path;
use std::process::Output;

use crate::common;
use common::texmap;

fn cube() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/orbital/h2co_homo.cube.gz")
        .to_str()
        .unwrap()
        .to_string()
}

fn reference() -> serde_json::Value {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/orbital/reference.json");
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Enclosed volume and area of the triangles of an OBJ file (1-based `v/vt/vn` faces).
fn obj_volume_area(path: &Path) -> (f64, f64, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut v: Vec<[f64; 3]> = Vec::new();
    let (mut vol, mut area, mut n) = (0.0, 0.0, 0);
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => v.push(std::array::from_fn(|_| it.next().unwrap().parse().unwrap())),
            Some("f") => {
                let [a, b, c]: [[f64; 3]; 3] = std::array::from_fn(|_| {
                    let t = it.next().unwrap();
                    v[t.split('/').next().unwrap().parse::<usize>().unwrap() - 1]
                });
                let cross = |p: [f64; 3], q: [f64; 3]| {
                    [
                        p[1] * q[2] - p[2] * q[1],
                        p[2] * q[0] - p[0] * q[2],
                        p[0] * q[1] - p[1] * q[0],
                    ]
                };
                let bc = cross(b, c);
                vol += (a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2]) / 6.0;
                let (ab, ac) = (
                    [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                    [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
                );
                let x = cross(ab, ac);
                area += (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() / 2.0;
                n += 1;
            }
            _ => {}
        }
    }
    (vol, area, n)
}

/// Checks that every face of an exported OBJ mesh lies in one colour band of `value` (64
/// bands over `range`, corners on a boundary in both) and that its palette texel is that band's
/// (one offset for all: the scene's atom materials come first); returns the face count.
fn assert_banded(
    text: &str,
    obj: &Path,
    value: impl Fn([f64; 3]) -> f64,
    (lo, hi): (f64, f64),
) -> usize {
    let (mut v, mut vt) = (Vec::<[f64; 3]>::new(), Vec::<f64>::new());
    let mut bases = std::collections::BTreeSet::new();
    let mut faces = 0;
    // The palette is one row of materials + 1 texels (the scene's atom materials, the 64
    // bands, the grey): kinds from the uv's texel.
    let texels = image::open(obj.with_extension("png"))
        .map(|i| i.width())
        .unwrap_or(0);
    assert!(texels > 64, "palette of {texels} texels");
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => v.push(std::array::from_fn(|_| it.next().unwrap().parse().unwrap())),
            Some("vt") => vt.push(it.next().unwrap().parse().unwrap()),
            Some("f") => {
                let corners: Vec<(usize, usize)> = it
                    .map(|t| {
                        let mut p = t.split('/');
                        let vi = p.next().unwrap().parse::<usize>().unwrap() - 1;
                        let ti = p.next().unwrap().parse::<usize>().unwrap() - 1;
                        (vi, ti)
                    })
                    .collect();
                let kind = (vt[corners[0].1] * texels as f64).floor() as i64;
                let us: Vec<f64> = corners
                    .iter()
                    .map(|&(vi, _)| ((value(v[vi]) - lo) / (hi - lo) * 64.0).clamp(0.0, 64.0))
                    .collect();
                let top = us.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                let bottom = us.iter().cloned().fold(f64::INFINITY, f64::min);
                assert!(top - bottom <= 1.0 + 1e-3, "a piece spans {bottom}..{top}");
                let band = ((bottom + top) / 2.0).floor().min(63.0) as i64;
                bases.insert(kind - band);
                faces += 1;
            }
            _ => {}
        }
    }
    assert_eq!(bases.len(), 1, "kind - band: {bases:?}");
    faces
}

fn mean_abs_diff(a: &Path, b: &Path) -> f64 {
    let (a, b) = (
        image::open(a).unwrap().to_rgb8(),
        image::open(b).unwrap().to_rgb8(),
    );
    let sum: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| (*x as i64 - *y as i64).unsigned_abs())
        .sum();
    sum as f64 / a.as_raw().len() as f64
}

/// The two lobes of PySCF's orbital at ±0.05: the exported meshes enclose the volumes and
/// have the areas scikit-image's marching cubes gives the same grid (both close the lobes at
/// the grid's border; the two extractions differ by their O(h²) cut corners), one lobe alone
/// with --isosurface-sign; the rasterised picture matches the reference ray tracer's, opaque
/// and translucent.
#[test]
fn an_orbitals_lobes_match_marching_cubes_and_the_ray_tracer() {
    let want = reference();
    let level = want["level"].as_f64().unwrap().to_string();
    let dir = tempfile::tempdir().unwrap();
    let cube = cube();
    let base = [
        cube.as_str(),
        "--style",
        "ball-stick",
        "--isosurface",
        level.as_str(),
        "--size",
        "320x240",
    ];
    let export = |name: &str, extra: &[&str]| {
        let obj = dir.path().join(name);
        let png = dir.path().join(format!("{name}.png"));
        let mut args = vec!["render", "--quiet"];
        args.extend(base);
        args.extend(extra);
        args.extend(["--export-mesh", obj.to_str().unwrap()]);
        args.extend(["-o", png.to_str().unwrap()]);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        obj_volume_area(&obj)
    };
    let (pos, neg) = (&want["positive"], &want["negative"]);
    let (mc_vol, mc_area) = (
        pos["volume"].as_f64().unwrap() + neg["volume"].as_f64().unwrap(),
        pos["area"].as_f64().unwrap() + neg["area"].as_f64().unwrap(),
    );
    let (vol, area, tris) = export("both.obj", &[]);
    assert!(tris > 2000, "{tris} triangles");
    assert!((vol / mc_vol - 1.0).abs() < 0.03, "{vol} Å³ vs {mc_vol}");
    assert!(
        (area / mc_area - 1.0).abs() < 0.03,
        "{area} Å² vs {mc_area}"
    );
    let (one, _, one_tris) = export("pos.obj", &["--isosurface-sign", "positive"]);
    let mc_one = pos["volume"].as_f64().unwrap();
    assert!((one / mc_one - 1.0).abs() < 0.03, "{one} Å³ vs {mc_one}");
    assert!(one_tris * 2 > tris - 50 && one_tris * 2 < tris + 50);

    // Drawn by the rasteriser over the ray-cast atoms, and traced by the reference.
    for opacity in ["1", "0.6"] {
        let raycast = dir.path().join(format!("r{opacity}.png"));
        let traced = dir.path().join(format!("t{opacity}.png"));
        for (method, out) in [("raycast", &raycast), ("reference", &traced)] {
            let mut args = vec!["render", "--quiet", "--method", method];
            args.extend(base);
            args.extend(["--isosurface-opacity", opacity, "-o", out.to_str().unwrap()]);
            let o = texmap(&args);
            assert!(o.status.success(), "{}", stderr(&o));
        }
        let d = mean_abs_diff(&raycast, &traced);
        assert!(
            d < 1.5,
            "opacity {opacity}: mean |raycast - reference| = {d}"
        );
    }
    // Both lobes in their colours: blue-ish and red-ish pixels.
    let img = image::open(dir.path().join("r1.png")).unwrap().to_rgb8();
    let blue = img
        .pixels()
        .filter(|p| p.0[2] as i32 > p.0[0] as i32 + 40)
        .count();
    let red = img
        .pixels()
        .filter(|p| p.0[0] as i32 > p.0[2] as i32 + 40)
        .count();
    assert!(blue > 2000 && red > 2000, "{blue} blue, {red} red pixels");
}

/// What the data cannot give is a usage error (exit 2) saying what it holds; a file with no
/// volumetric data is an error naming it (exit 1).
#[test]
fn isosurface_errors_say_what_the_data_holds() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let out = out.to_str().unwrap();
    let cube = cube();
    let run = |extra: &[&str]| {
        let mut args = vec!["render", "--quiet", cube.as_str(), "-o", out];
        args.extend(extra);
        texmap(&args)
    };
    let o = run(&["--isosurface", "5"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("runs from -0.558"), "{}", stderr(&o));
    let o = run(&["--isosurface", "0.05", "--volume-set", "2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("holds 1 data set"), "{}", stderr(&o));
    let o = run(&["--isosurface", "0.05", "--isosurface-opacity", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = run(&["--volume", cube.as_str()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--isosurface"), "{}", stderr(&o));
    // A structure without a grid.
    let xyz = dir.path().join("w.xyz");
    std::fs::write(&xyz, "3\nwater\nO 0 0 0\nH 0.96 0 0\nH -0.24 0.93 0\n").unwrap();
    let o = texmap(&[
        "render",
        "--quiet",
        xyz.to_str().unwrap(),
        "--isosurface",
        "0.05",
        "-o",
        out,
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("w.xyz"), "{}", stderr(&o));
    assert!(!Path::new(out).exists());
}

/// `texmap info` on a cube file: its atoms, and each data set's grid and range.
#[test]
fn info_gives_the_grid_and_the_range() {
    let o = texmap(&["info", cube().as_str()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["atoms"], 4);
    let want = reference();
    let set = &v["volumes"][0];
    assert_eq!(set["points"], want["shape"]);
    let (lo, hi) = (want["min"].as_f64().unwrap(), want["max"].as_f64().unwrap());
    assert!((set["min"].as_f64().unwrap() - lo).abs() < 1e-6);
    assert!((set["max"].as_f64().unwrap() - hi).abs() < 1e-6);
    // A CCP4/MRC map (written by mrcfile) has a grid and no atoms; drawn beside a structure.
    let map =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-io/tests/data/volume/emd_float.mrc");
    let o = texmap(&["info", map.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "CCP4/MRC");
    assert_eq!(v["volumes"][0]["points"], serde_json::json!([20, 24, 28]));
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("map.png");
    let o = texmap(&[
        "render",
        "--quiet",
        cube().as_str(),
        "--volume",
        map.to_str().unwrap(),
        "--isosurface",
        "1.5",
        "--size",
        "96x72",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A CHGCAR (pymatgen's, md-io's tests/data/volume/gen_volume.py) is periodic: its
/// isosurface follows the atoms' periodic images, each image the same surface moved by a cell
/// vector; `--volume-set 2` draws the magnetisation, both signs.
#[test]
fn a_chgcar_surface_follows_the_periodic_images() {
    let chgcar = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data/volume/CHGCAR_pmg_spin")
        .to_str()
        .unwrap()
        .to_string();
    let dir = tempfile::tempdir().unwrap();
    let export = |name: &str, extra: &[&str]| {
        let obj = dir.path().join(name);
        let png = dir.path().join(format!("{name}.png"));
        let mut args = vec![
            "render",
            "--quiet",
            chgcar.as_str(),
            "--size",
            "160x120",
            "--export-mesh",
            obj.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        obj_volume_area(&obj)
    };
    let (v1, a1, n1) = export("one.obj", &["--isosurface", "0.2"]);
    let (v4, a4, n4) = export("four.obj", &["--isosurface", "0.2", "--replicate", "2,2,1"]);
    assert!(n1 > 100, "{n1} triangles");
    assert_eq!(n4, 4 * n1);
    assert!((v4 / v1 - 4.0).abs() < 1e-3, "{v4} vs 4 x {v1}");
    assert!((a4 / a1 - 4.0).abs() < 1e-3, "{a4} vs 4 x {a1}");
    let (_, _, both) = export("m.obj", &["--isosurface", "0.03", "--volume-set", "2"]);
    let (_, _, pos) = export(
        "mp.obj",
        &[
            "--isosurface",
            "0.03",
            "--volume-set",
            "2",
            "--isosurface-sign",
            "positive",
        ],
    );
    assert!(pos > 0 && both > pos, "{both} and {pos} triangles");
}

/// A cube file's text: atoms (Z, position in Å) and `f` on `n`³ points `step` Å apart from
/// `origin` (axes in Å: negative counts; x outermost, z fastest).
fn cube_text(
    atoms: &[(u32, [f64; 3])],
    origin: f64,
    step: f64,
    n: usize,
    f: impl Fn([f64; 3]) -> f64,
) -> String {
    let mut s = format!(
        "synthetic\nfield\n{} {origin} {origin} {origin}\n",
        atoms.len()
    );
    for a in 0..3 {
        let mut v = [0.0; 3];
        v[a] = step;
        s += &format!("-{n} {} {} {}\n", v[0], v[1], v[2]);
    }
    for (z, p) in atoms {
        s += &format!("{z} 0.0 {} {} {}\n", p[0], p[1], p[2]);
    }
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = [i, j, k].map(|c| origin + step * c as f64);
                s += &format!("{:.8e}\n", f(p));
            }
        }
    }
    s
}

/// --isosurface-color-by: a Gaussian density's sphere coloured by a linear field z (on a
/// coarser grid of its own, where interpolation is exact): every exported piece lies in the
/// colour band of its z, in 64 bands over --volume-range (reversed too); the picture
/// matches the reference ray tracer's; a range that is not two numbers is a usage error.
#[test]
fn a_surface_coloured_by_another_volume_is_banded_by_its_values() {
    let dir = tempfile::tempdir().unwrap();
    let atoms = [(8u32, [0.0, 0.0, 0.0])];
    let rho = dir.path().join("rho.cube");
    let pot = dir.path().join("pot.cube");
    std::fs::write(
        &rho,
        cube_text(&atoms, -2.0, 0.1, 41, |p| {
            (-(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])).exp()
        }),
    )
    .unwrap();
    std::fs::write(&pot, cube_text(&atoms, -2.5, 0.5, 11, |p| p[2])).unwrap();
    let (rho, pot) = (rho.to_str().unwrap(), pot.to_str().unwrap());
    for (range, lo, hi) in [("-1:1", -1.0, 1.0), ("1:-1", 1.0, -1.0)] {
        let obj = dir.path().join("m.obj");
        let png = dir.path().join("picture.png");
        let o = texmap(&[
            "render",
            "--quiet",
            rho,
            "--isosurface",
            "0.3",
            "--isosurface-color-by",
            pot,
            "--volume-range",
            range,
            "--size",
            "240x180",
            "--export-mesh",
            obj.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        // Faces and the palette texel (kind) their uvs pick.
        let text = std::fs::read_to_string(&obj).unwrap();
        let faces = assert_banded(&text, &obj, |p| p[2], (lo, hi));
        assert!(faces > 1000, "{faces} faces");
    }
    // Against the reference ray tracer.
    let mut images = Vec::new();
    for method in ["raycast", "reference"] {
        let png = dir.path().join(format!("{method}.png"));
        let o = texmap(&[
            "render",
            "--quiet",
            "--method",
            method,
            rho,
            "--isosurface",
            "0.3",
            "--isosurface-color-by",
            pot,
            "--size",
            "240x180",
            "-o",
            png.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        images.push(png);
    }
    let d = mean_abs_diff(&images[0], &images[1]);
    assert!(d < 1.5, "mean |raycast - reference| = {d}");
    let o = texmap(&[
        "render",
        "--quiet",
        rho,
        "--isosurface",
        "0.3",
        "--isosurface-color-by",
        pot,
        "--volume-range",
        "1:1",
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// --volume-slice: a plane through a cube file's grid at the fraction asked, both sides, cut
/// into the colour bands of its values (a linear field: every piece in its band, in its colour);
/// what it cannot draw is a usage error.
#[test]
fn a_volume_slice_is_the_grids_plane_in_its_values_colours() {
    let dir = tempfile::tempdir().unwrap();
    let field = dir.path().join("field.cube");
    let atoms = [(6u32, [0.0, 0.0, 0.0])];
    std::fs::write(
        &field,
        cube_text(&atoms, -2.5, 0.5, 11, |p| p[0] + 2.0 * p[1]),
    )
    .unwrap();
    let field = field.to_str().unwrap();
    let obj = dir.path().join("slice.obj");
    let png = dir.path().join("picture.png");
    let o = texmap(&[
        "render",
        "--quiet",
        field,
        "--volume-slice",
        "c:0.5",
        "--volume-range",
        "-7.5:7.5",
        "--size",
        "240x180",
        "--export-mesh",
        obj.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&obj).unwrap();
    let v = common::obj_vertices(&obj);
    // The plane z = 0 (the grid's middle along c), spanning the grid's 5 x 5 Å.
    assert!(v.iter().all(|p| p[2].abs() < 1e-5), "off the plane");
    let span = |k: usize| {
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[k]), b.max(p[k])));
        hi - lo
    };
    assert!((span(0) - 5.0).abs() < 1e-4 && (span(1) - 5.0).abs() < 1e-4);
    assert_banded(&text, &obj, |p| p[0] + 2.0 * p[1], (-7.5, 7.5));
    let (vol, area, faces) = obj_volume_area(&obj);
    // Two sides of 25 Å²; a plane seen both ways encloses nothing.
    assert!((area - 50.0).abs() < 1e-3, "{area}");
    assert!(vol.abs() < 1e-6, "{vol}");
    assert!(
        faces > 400,
        "{faces} faces: the bands cut the 400 triangles"
    );
    let bad = |extra: &[&str]| {
        let mut args = vec!["render", "--quiet", field, "-o", png.to_str().unwrap()];
        args.extend(extra);
        let o = texmap(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        stderr(&o)
    };
    assert!(bad(&["--volume-slice", "d:0.5"]).contains("a, b or c"));
    assert!(bad(&["--volume-slice", "a:1.5"]).contains("from 0 to 1"));
    bad(&[
        "--volume-slice",
        "a:0.5",
        "--isosurface",
        "1",
        "--isosurface-color-by",
        field,
    ]);
}

/// An XSF file (ASE's, md-io's tests/data/xsf/gen_xsf.py): a periodic function on the general
/// grid over a triclinic crystal's cell, read as a periodic volume (the repeated end planes
/// dropped), so its isosurface follows the periodic images as a CHGCAR's does; `texmap info`
/// gives the grid.
#[test]
fn an_xsf_grid_is_drawn_as_a_periodic_isosurface() {
    let xsf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data/xsf/ase_grid_crystal.xsf")
        .to_str()
        .unwrap()
        .to_string();
    let o = texmap(&["info", xsf.as_str()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "xsf");
    assert_eq!(v["atoms"], 2);
    let set = &v["volumes"][0];
    assert_eq!(set["name"], "data: grid#1");
    assert_eq!(set["points"], serde_json::json!([8, 9, 10]));
    assert_eq!(set["periodic"], true);
    let dir = tempfile::tempdir().unwrap();
    let export = |name: &str, extra: &[&str]| {
        let obj = dir.path().join(name);
        let png = dir.path().join(format!("{name}.png"));
        let mut args = vec![
            "render",
            "--quiet",
            xsf.as_str(),
            "--style",
            "ball-stick",
            "--size",
            "160x120",
            "--isosurface",
            "0.8",
            "--export-mesh",
            obj.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = texmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(png.exists());
        obj_volume_area(&obj)
    };
    let (v1, a1, n1) = export("one.obj", &[]);
    let (v4, a4, n4) = export("four.obj", &["--replicate", "2,2,1"]);
    assert!(n1 > 50, "{n1} triangles");
    assert_eq!(n4, 4 * n1);
    assert!((v4 / v1 - 4.0).abs() < 1e-3, "{v4} vs 4 x {v1}");
    assert!((a4 / a1 - 4.0).abs() < 1e-3, "{a4} vs 4 x {a1}");
}

/// --surface-color-by: a molecular surface coloured by an OpenDX potential, as PyMOL colours
/// one by APBS's map. The potential is linear (trilinear interpolation is exact for it), so
/// every exported face lies in the colour band of the field at its corners; reversed with
/// --volume-range HI:LO; without a surface to colour, a usage error.
#[test]
fn a_molecular_surface_is_coloured_by_a_dx_potential() {
    use texmap_md_io::volume::{Volume, write_dx};
    let dir = tempfile::tempdir().unwrap();
    let pqr = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data/pdb2pqr_amber.pqr")
        .to_str()
        .unwrap()
        .to_string();
    // The atoms span 0.5..57 Å; the grid 1.6 Å apart from -10 to 70 Å along each axis.
    let field = |p: [f64; 3]| 0.2 * (p[0] - 20.0) - 0.1 * (p[1] - 20.0);
    let (n, step, start) = (51usize, 1.6, -10.0);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = [i, j, k].map(|c| start + c as f64 * step);
                data.push(field(p) as f32);
            }
        }
    }
    let steps = [[step, 0.0, 0.0], [0.0, step, 0.0], [0.0, 0.0, step]];
    let v = Volume::new([start; 3], steps, [n; 3], data, false, "potential").unwrap();
    let dx = dir.path().join("pot.dx");
    let mut text = Vec::new();
    write_dx(&v, &["a linear potential"], &mut text).unwrap();
    std::fs::write(&dx, text).unwrap();
    for (range, lo, hi) in [("-3:3", -3.0, 3.0), ("3:-3", 3.0, -3.0)] {
        let obj = dir.path().join("s.obj");
        let png = dir.path().join("picture.png");
        let o = texmap(&[
            "render",
            "--quiet",
            &pqr,
            "--style",
            "surface",
            "--surface-color-by",
            dx.to_str().unwrap(),
            "--volume-range",
            range,
            "--size",
            "160x120",
            "--export-mesh",
            obj.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(!stderr(&o).contains("outside"), "{}", stderr(&o));
        let text = std::fs::read_to_string(&obj).unwrap();
        let faces = assert_banded(&text, &obj, field, (lo, hi));
        assert!(faces > 5000, "{faces} faces");
    }
    let o = texmap(&[
        "render",
        "--quiet",
        &pqr,
        "--surface-color-by",
        dx.to_str().unwrap(),
        "-o",
        dir.path().join("x.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--style surface"), "{}", stderr(&o));
}
