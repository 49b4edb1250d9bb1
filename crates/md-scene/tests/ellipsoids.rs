//! Ellipsoids (`md_scene::ellipsoids`) drawn through the rasteriser against the exact
//! ellipsoids: coverage and depth from this test's own ray–quadric intersection, and the
//! shading of a round "ellipsoid" against the reference ray tracer's exact sphere.

use glam::{Quat, Vec3};
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::metrics::psnr;
use texmap_core::shade::{Lighting, Material};
use texmap_md_scene::ellipsoids::{Ellipsoid, TOLERANCE_PX, draw, sag, tessellate};
use texmap_md_scene::surface::draw_mesh;
use texmap_reftrace::{RenderOptions, SceneBuilder, SurfaceMaterial};

/// A small deterministic generator (no dependency): uniform in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Gay–Berne-like particles: 3:1:1 and 2:1.5:0.5 ellipsoids at random orientations.
fn particles() -> Vec<Ellipsoid> {
    let mut rng = Lcg(7);
    (0..40)
        .map(|i| {
            let center = Vec3::new(rng.next(), rng.next(), rng.next()) * 16.0 - 8.0;
            let axis = Vec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5);
            let rotation =
                Quat::from_axis_angle(axis.normalize(), rng.next() * std::f32::consts::TAU);
            let semi_axes = if i % 2 == 0 {
                Vec3::new(1.5, 0.5, 0.5)
            } else {
                Vec3::new(1.0, 0.75, 0.25)
            };
            Ellipsoid {
                center,
                semi_axes,
                rotation,
                kind: (i % 2) as u16,
            }
        })
        .collect()
}

/// The nearest hit of a ray with `e`, as the ray parameter: the ray taken into the frame where
/// the ellipsoid is the unit sphere, and the quadratic solved there.
fn hit(e: &Ellipsoid, origin: Vec3, dir: Vec3) -> Option<f32> {
    let inv = e.rotation.inverse();
    let o = (inv * (origin - e.center)).as_dvec3() / e.semi_axes.as_dvec3();
    let d = (inv * dir).as_dvec3() / e.semi_axes.as_dvec3();
    let (a, b, c) = (d.dot(d), o.dot(d), o.dot(o) - 1.0);
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let t = (-b - disc.sqrt()) / a;
    (t > 0.0).then_some(t as f32)
}

fn camera() -> Camera {
    Camera::perspective_look_at(
        Vec3::new(14.0, 10.0, 30.0),
        Vec3::ZERO,
        Vec3::Y,
        45.0,
        480,
        360,
    )
    .unwrap()
}

fn materials() -> Vec<Material> {
    vec![
        Material::plastic(Vec3::new(0.8, 0.2, 0.2)),
        Material::plastic(Vec3::new(0.2, 0.4, 0.9)),
    ]
}

/// The exact picture of `particles`: per pixel centre the depth of the nearest ellipsoid
/// (infinite where none) and which it is.
fn exact_picture(cam: &Camera, particles: &[Ellipsoid]) -> (Vec<f32>, Vec<usize>) {
    let (w, h) = (cam.width() as usize, cam.height() as usize);
    let mut exact = vec![f32::INFINITY; w * h];
    let mut nearest = vec![usize::MAX; w * h];
    for y in 0..h {
        for x in 0..w {
            let ray = cam.ray(x as f32 + 0.5, y as f32 + 0.5);
            let along = ray.dir.dot(cam.forward());
            for (k, e) in particles.iter().enumerate() {
                if let Some(t) = hit(e, ray.origin, ray.dir)
                    && t * along < exact[y * w + x]
                {
                    exact[y * w + x] = t * along;
                    nearest[y * w + x] = k;
                }
            }
        }
    }
    (exact, nearest)
}

/// Coverage of `drawn` against the exact picture: (pixels that differ, those of them off a
/// silhouette), and the drawn points' |u| range in the frame where their exact ellipsoid is the
/// unit sphere, with the pixels where another ellipsoid's silhouette crosses.
fn against_exact(
    cam: &Camera,
    particles: &[Ellipsoid],
    drawn: &Frame,
    (exact, nearest): &(Vec<f32>, Vec<usize>),
) -> (usize, usize, f32, f32, usize) {
    let (w, h) = (cam.width() as usize, cam.height() as usize);
    let (mut wrong, mut off_edge) = (0, 0);
    let (mut inner, mut outer, mut crossings) = (1f32, 1f32, 0);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let drawn_here = drawn.depth[i].is_finite();
            if drawn_here != exact[i].is_finite() {
                wrong += 1;
                // Only at a silhouette: a neighbour of the exact picture is the other way.
                let edge = (y.saturating_sub(1)..(y + 2).min(h)).any(|v| {
                    (x.saturating_sub(1)..(x + 2).min(w))
                        .any(|u| exact[v * w + u].is_finite() == drawn_here)
                });
                off_edge += !edge as usize;
            } else if drawn_here {
                let e = &particles[nearest[i]];
                let ray = cam.ray(x as f32 + 0.5, y as f32 + 0.5);
                let p = ray.origin + ray.dir * (drawn.depth[i] / ray.dir.dot(cam.forward()));
                let u = (e.rotation.inverse() * (p - e.center) / e.semi_axes).length();
                if (u - 1.0).abs() > 0.2 {
                    crossings += 1;
                } else {
                    inner = inner.min(u);
                    outer = outer.max(u);
                }
            }
        }
    }
    (wrong, off_edge, inner, outer, crossings)
}

#[test]
fn coverage_and_depth_match_the_exact_ellipsoids() {
    let cam = camera();
    let particles = particles();
    let lighting = Lighting::default_for(&cam);
    let truth = exact_picture(&cam, &particles);
    let covered = truth.0.iter().filter(|d| d.is_finite()).count();
    assert!(covered > 10_000, "{covered} pixels");
    let bg = [0, 0, 0, 255];
    // The impostors: exact up to f32 at the silhouette.
    let mut impostors = Frame::new(cam.width(), cam.height(), bg);
    let n = draw(&particles, &materials(), &cam, &lighting, &mut impostors).unwrap();
    assert_eq!(n, particles.len());
    let (wrong, off_edge, inner, outer, crossings) =
        against_exact(&cam, &particles, &impostors, &truth);
    eprintln!(
        "impostors: {covered} pixels covered, {wrong} differ ({off_edge} off a silhouette), points at |u| {inner:.6}..{outer:.6}, {crossings} crossings"
    );
    assert_eq!(off_edge, 0);
    assert!(wrong <= 2, "{wrong} pixels");
    assert!(crossings <= 2, "{crossings}");
    assert!(inner > 1.0 - 1e-4 && outer < 1.0 + 1e-4, "{inner}..{outer}");
    // The view's mesh (what the reference traces): within its level's sag.
    let mesh = tessellate(&particles, Some(&cam), TOLERANCE_PX);
    let mut drawn = Frame::new(cam.width(), cam.height(), bg);
    draw_mesh(&mesh, &materials(), &cam, &lighting, 1.0, &mut drawn).unwrap();
    let (wrong, off_edge, inner, outer, crossings) =
        against_exact(&cam, &particles, &drawn, &truth);
    eprintln!(
        "mesh: {wrong} pixels differ ({off_edge} off a silhouette), points at |u| {inner:.4}..{outer:.4} ({crossings} at crossings), {} triangles",
        mesh.triangles.len()
    );
    assert_eq!(off_edge, 0);
    assert!(wrong * 100 < covered, "{wrong} of {covered}");
    assert!(crossings * 100 < covered, "{crossings} of {covered}");
    // On or just inside the ellipsoid: within the sag of the coarsest level used here.
    assert!(
        inner > 1.0 - sag(2) && outer < 1.0 + 1e-3,
        "{inner}..{outer}"
    );
    // No finer than needed: far fewer triangles than the finest level for every particle.
    assert!(mesh.triangles.len() < particles.len() * 20_480 / 8);
    // Both pictures alike where both cover.
    let db = psnr(&impostors, &drawn).unwrap();
    eprintln!("impostors against the mesh: {db:.2} dB");
    assert!(db > 35.0, "{db}");
    // An orthographic view, and a perspective one from among the particles (some behind the
    // eye, some through the near plane): the impostors still match.
    let views = [
        Camera::orthographic_look_at(
            Vec3::new(14.0, 10.0, 30.0),
            Vec3::ZERO,
            Vec3::Y,
            24.0,
            480,
            360,
        )
        .unwrap(),
        Camera::perspective_look_at(
            Vec3::new(1.0, 0.5, 2.0),
            Vec3::new(-3.0, 0.0, -6.0),
            Vec3::Y,
            90.0,
            480,
            360,
        )
        .unwrap()
        .with_clip(0.05, f32::INFINITY)
        .unwrap(),
    ];
    for (name, cam) in ["orthographic", "inside"].iter().zip(&views) {
        let truth = exact_picture(cam, &particles);
        let mut img = Frame::new(cam.width(), cam.height(), bg);
        draw(
            &particles,
            &materials(),
            cam,
            &Lighting::default_for(cam),
            &mut img,
        )
        .unwrap();
        let (wrong, off_edge, inner, outer, _) = against_exact(cam, &particles, &img, &truth);
        let covered = truth.0.iter().filter(|d| d.is_finite()).count();
        eprintln!(
            "{name}: {covered} covered, {wrong} differ ({off_edge} off a silhouette), |u| {inner:.6}..{outer:.6}"
        );
        assert!(covered > 5_000 && off_edge == 0 && wrong <= 2, "{name}");
        assert!(
            inner > 1.0 - 1e-4 && outer < 1.0 + 1e-4,
            "{name}: {inner}..{outer}"
        );
    }
}

#[test]
fn a_round_ellipsoid_is_shaded_as_the_reference_traces_its_sphere() {
    let cam = camera();
    let lighting = Lighting::default_for(&cam);
    let mats = materials();
    let spheres: Vec<Ellipsoid> = particles()
        .iter()
        .map(|e| Ellipsoid {
            semi_axes: Vec3::splat(0.9),
            ..*e
        })
        .collect();
    let mesh = tessellate(&spheres, Some(&cam), TOLERANCE_PX);
    let bg = [10, 20, 30, 255];
    let mut drawn = Frame::new(cam.width(), cam.height(), bg);
    draw_mesh(&mesh, &mats, &cam, &lighting, 1.0, &mut drawn).unwrap();
    let mut b = SceneBuilder::new();
    for e in &spheres {
        b.add_sphere(e.center, 0.9, e.kind as u32);
    }
    let surf: Vec<SurfaceMaterial> = mats.iter().map(|&m| SurfaceMaterial::opaque(m)).collect();
    let mut o = RenderOptions::new(lighting, &surf);
    o.background = texmap_core::color::srgb8_to_linear_rgb(bg);
    let reference = b.build().render(&cam, &o).unwrap();
    let db = psnr(&drawn, &reference).unwrap();
    let agree = (0..drawn.len())
        .filter(|&i| drawn.covered(i) == reference.covered(i))
        .count();
    eprintln!(
        "PSNR {db:.2} dB against reftrace's exact spheres; coverage differs at {} pixels",
        drawn.len() - agree
    );
    assert!(db > 38.0, "PSNR {db}");
    assert!(drawn.len() - agree < drawn.len() / 300);
    // The impostors: the reference's spheres up to its own f32.
    let mut impostors = Frame::new(cam.width(), cam.height(), bg);
    draw(&spheres, &mats, &cam, &lighting, &mut impostors).unwrap();
    let db = psnr(&impostors, &reference).unwrap();
    let agree = (0..drawn.len())
        .filter(|&i| impostors.covered(i) == reference.covered(i))
        .count();
    eprintln!(
        "impostors: PSNR {db:.2} dB against reftrace's exact spheres; coverage differs at {} pixels",
        drawn.len() - agree
    );
    assert!(db > 55.0, "PSNR {db}");
    assert!(drawn.len() - agree <= 2);
}

/// OVITO's reading of `file` (see `data/ellipsoids/gen_ellipsoids.py`): per particle its
/// semi-axes and orientation.
fn ovito_read(file: &str) -> Vec<(Vec3, Quat)> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/ellipsoids/ovito_read.json"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let f = &json[file];
    let v = |x: &serde_json::Value| -> Vec<f32> {
        x.as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap() as f32)
            .collect()
    };
    f["semi_axes"]
        .as_array()
        .unwrap()
        .iter()
        .zip(f["orientation_xyzw"].as_array().unwrap())
        .map(|(s, q)| {
            let (s, q) = (v(s), v(q));
            (
                Vec3::new(s[0], s[1], s[2]),
                Quat::from_xyzw(q[0], q[1], q[2], q[3]),
            )
        })
        .collect()
}

#[test]
fn shapes_and_orientations_are_read_as_ovito_reads_them() {
    use texmap_md_io::{Frame, Trajectory};
    use texmap_md_scene::ellipsoids::{EllipsoidOptions, shapes};
    // OVITO's own export (c_shape semi-axes, quati..quatw) and LAMMPS's columns (shapex..
    // diameters, quatw first), both read by OVITO 3.17.
    for file in ["ovito_export.dump", "lammps_columns.dump"] {
        let path = format!(
            "{}/tests/data/ellipsoids/{file}",
            env!("CARGO_MANIFEST_DIR")
        );
        let mut frame = Frame::new();
        Trajectory::open(&path)
            .unwrap()
            .read_frame(0, &mut frame)
            .unwrap();
        let ours = shapes(&frame, &EllipsoidOptions::default()).unwrap();
        let theirs = ovito_read(file);
        assert_eq!(ours.len(), theirs.len());
        for (i, ((a, q), (b, r))) in ours.iter().zip(&theirs).enumerate() {
            assert!(
                (*a - *b).abs().max_element() < 1e-5,
                "{file} atom {i}: {a} vs {b}"
            );
            // The same rotation (q and −q are one).
            let same = q.dot(r.normalize()).abs();
            assert!(same > 1.0 - 1e-5, "{file} atom {i}: {q} vs {r}");
        }
        assert_eq!(ours[7].0, Vec3::ZERO, "{file}: the sphere");
    }
}

/// Superposed on the first frame, a turned copy of the particles is drawn as the first: the
/// orientations turn with the positions (`MolOptions::align`).
#[test]
fn alignment_turns_the_orientations_with_the_positions() {
    use texmap_md_io::{Frame, Selection, Trajectory};
    use texmap_md_scene::{
        Alignment, DrawStyle, MolOptions, MolPlan, SceneBuilder, SphereScene, StyleOptions,
    };
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/ellipsoids/lammps_columns.dump"
    );
    let mut first = Frame::new();
    Trajectory::open(path)
        .unwrap()
        .read_frame(0, &mut first)
        .unwrap();
    // The same particles turned by 70° about (1, 2, 2) and moved: positions and quaternions.
    let turn = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 2.0).normalize(), 70f32.to_radians());
    let mut turned = first.clone();
    for p in &mut turned.positions {
        *p = (turn * Vec3::from(*p) + Vec3::new(5.0, -3.0, 1.0)).to_array();
    }
    let column = |f: &Frame, name: &str| f.properties.iter().position(|p| p.name == name).unwrap();
    let at = ["quatw", "quati", "quatj", "quatk"].map(|n| column(&turned, n));
    for i in 0..turned.n_atoms() {
        let v = |k: usize| turned.properties[at[k]].values[i];
        let q = turn * Quat::from_xyzw(v(1), v(2), v(3), v(0));
        for (k, x) in [q.w, q.x, q.y, q.z].into_iter().enumerate() {
            turned.properties[at[k]].values[i] = x;
        }
    }
    turned.cell = None;
    first.cell = None;
    let mut plan = MolPlan::new(MolOptions {
        draw: DrawStyle::Ellipsoids,
        align: Some(Alignment::on_first_frame(Selection::parse("all").unwrap())),
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut scene = SphereScene::default();
    plan.build(&mut builder, &mut first, &mut scene).unwrap();
    let want = plan.ellipsoids().to_vec();
    assert_eq!(want.len(), 59);
    plan.build(&mut builder, &mut turned, &mut scene).unwrap();
    let got = plan.ellipsoids();
    for (a, b) in want.iter().zip(got) {
        assert!(
            (a.center - b.center).length() < 1e-3,
            "{} vs {}",
            a.center,
            b.center
        );
        assert!(
            a.rotation.dot(b.rotation).abs() > 1.0 - 1e-5,
            "{} vs {}",
            a.rotation,
            b.rotation
        );
        assert_eq!(a.semi_axes, b.semi_axes);
    }
}

/// HOOMD-blue's shapes: a GSD file gsd.hoomd wrote, with an ellipsoid type and a sphere type in
/// `particles/type_shapes` (frame 0 only), read as OVITO 3.17.2 reads it, in both frames.
#[test]
fn hoomd_type_shapes_are_read_as_ovito_reads_them() {
    use texmap_md_io::{Frame, Trajectory};
    use texmap_md_scene::ellipsoids::{EllipsoidOptions, shapes};
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ellipsoids");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}/hoomd_read.json")).unwrap())
            .unwrap();
    let mut traj = Trajectory::open(format!("{dir}/hoomd_ellipsoids.gsd")).unwrap();
    let mut frame = Frame::new();
    for (k, want) in json.as_array().unwrap().iter().enumerate() {
        assert!(traj.read_next(&mut frame).unwrap());
        let ours = shapes(&frame, &EllipsoidOptions::default()).unwrap();
        let num = |v: &serde_json::Value| v.as_f64().unwrap() as f32;
        let semi = want["semi_axes"].as_array().unwrap();
        let quat = want["orientation_xyzw"].as_array().unwrap();
        assert_eq!(ours.len(), semi.len());
        for (i, (a, q)) in ours.iter().enumerate() {
            let s = Vec3::new(num(&semi[i][0]), num(&semi[i][1]), num(&semi[i][2]));
            let r = Quat::from_xyzw(
                num(&quat[i][0]),
                num(&quat[i][1]),
                num(&quat[i][2]),
                num(&quat[i][3]),
            );
            assert!(
                (*a - s).abs().max_element() < 1e-6,
                "frame {k} particle {i}: {a} vs {s}"
            );
            assert!(
                q.dot(r.normalize()).abs() > 1.0 - 1e-5,
                "frame {k} particle {i}"
            );
        }
        assert!(
            ours.iter().filter(|(a, _)| *a == Vec3::ZERO).count() == 20,
            "the spheres"
        );
    }
}
