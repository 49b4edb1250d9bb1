//! `draw_surface`: what a caller's surface shader receives (world position, normal, view ray)
//! against independent f64 geometry, and the same coverage and depth as the built-in programs.

use glam::{DVec3, Vec3};
use texmap_core::camera::Camera;
use texmap_raster::{Cull, DrawState, Framebuffer, Mesh, Shading, SurfaceQuad};

fn camera() -> Camera {
    Camera::perspective_look_at(
        Vec3::new(0.3, 2.0, 5.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        60.0,
        160,
        120,
    )
    .unwrap()
}

fn no_cull() -> DrawState {
    DrawState {
        cull: Cull::None,
        ..DrawState::default()
    }
}

#[test]
fn world_position_and_face_normal_match_the_exact_plane() {
    let cam = camera();
    // The tilted plane 0.2x − y − 0.1z = 0, no vertex normals: the face normal is used.
    let plane_y = |x: f32, z: f32| 0.2 * x - 0.1 * z;
    let corners = [(-4.0, -6.0), (4.0, -6.0), (4.0, 3.0), (-4.0, 3.0)];
    let pos: Vec<Vec3> = corners
        .iter()
        .map(|&(x, z)| Vec3::new(x, plane_y(x, z), z))
        .collect();
    let idx = [[0, 3, 2], [0, 2, 1]];
    let mesh = Mesh::new(&pos, &idx).unwrap();
    let n = DVec3::new(-0.2, 1.0, 0.1).normalize(); // the side facing the camera (above)
    // Pass 1: world position as colour. Pass 2: the unit normal as colour.
    let mut fb = Framebuffer::new(160, 120).unwrap();
    fb.clear([0, 0, 0, 255]);
    let at = |q: &SurfaceQuad| std::array::from_fn(|l| q.world_position(&cam, l));
    fb.draw_surface(&cam, &mesh, &at, &no_cull()).unwrap();
    let mut fb_n = Framebuffer::new(160, 120).unwrap();
    fb_n.clear([0, 0, 0, 255]);
    let normal = |q: &SurfaceQuad| std::array::from_fn(|l| q.normal(l));
    fb_n.draw_surface(&cam, &mesh, &normal, &no_cull()).unwrap();
    let (mut checked, mut worst) = (0, 0.0f64);
    for y in 0..120u32 {
        for x in 0..160u32 {
            let Some(depth) = fb.depth_at(x, y).filter(|d| d.is_finite()) else {
                continue;
            };
            // The exact point of the plane under the pixel centre, in f64.
            let ray = cam.ray(x as f32 + 0.5, y as f32 + 0.5);
            let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
            let t = -n.dot(o) / n.dot(d);
            let p = o + d * t;
            if p.x.abs() > 3.9 || p.z < -5.9 || p.z > 2.9 {
                continue; // near the border, where snapping decides coverage
            }
            let got = fb.color_at(x, y).unwrap().as_dvec3();
            let err = (got - p).length();
            // f32 depth (~1e-6 relative) times a distance of up to ~12 units, plus the
            // 1/256-pixel vertex snap on a plane seen at up to ~4 units per 10 pixels.
            let tol = 2e-3;
            assert!(
                err <= tol,
                "pixel ({x},{y}) depth {depth}: expected {p}, got {got}, error {err:e}, tol {tol:e}"
            );
            let gn = fb_n.color_at(x, y).unwrap().as_dvec3();
            assert!(
                (gn - n).length() < 1e-6,
                "pixel ({x},{y}): normal {gn}, expected {n}, tol 1e-6"
            );
            worst = f64::max(worst, err);
            checked += 1;
        }
    }
    assert!(checked > 5000, "only {checked} pixels checked");
    eprintln!("{checked} pixels, worst position error {worst:e}");
}

/// A UV sphere of radius `r` at `c` with exact vertex normals.
fn sphere(c: Vec3, r: f32, rings: u32, segs: u32) -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>) {
    let mut pos = Vec::new();
    let mut nrm = Vec::new();
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segs {
            let ph = std::f32::consts::TAU * j as f32 / segs as f32;
            let n = Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
            nrm.push(n);
            pos.push(c + n * r);
        }
    }
    let mut idx = Vec::new();
    let w = segs + 1;
    for i in 0..rings {
        for j in 0..segs {
            let (a, b) = (i * w + j, i * w + j + 1);
            let (cc, d) = ((i + 1) * w + j, (i + 1) * w + j + 1);
            idx.push([a, b, d]);
            idx.push([a, d, cc]);
        }
    }
    (pos, nrm, idx)
}

#[test]
fn interpolated_vertex_normals_follow_the_sphere_and_face_the_viewer() {
    let cam = camera();
    let c = Vec3::new(0.0, 0.0, -1.0);
    let (pos, nrm, idx) = sphere(c, 1.5, 48, 96);
    let mesh = Mesh::new(&pos, &idx).unwrap().with_normals(&nrm).unwrap();
    let mut fb = Framebuffer::new(160, 120).unwrap();
    fb.clear([0, 0, 0, 255]);
    // Colour = 0.5 + 0.5·(angle between the shaded normal and the true sphere normal at the
    // pixel's world point, in radians), and the sign of n · view as a separate channel.
    let probe = |q: &SurfaceQuad| {
        std::array::from_fn(|l| {
            let n = q.normal(l);
            let truth = (q.world_position(&cam, l) - c).normalize();
            let facing = n.dot(q.view_ray(&cam, l));
            Vec3::new(n.angle_between(truth), facing, 0.0)
        })
    };
    fb.draw_surface(&cam, &mesh, &probe, &DrawState::default())
        .unwrap();
    let mut covered = 0;
    for y in 0..120u32 {
        for x in 0..160u32 {
            if !fb.depth_at(x, y).unwrap().is_finite() {
                continue;
            }
            covered += 1;
            let v = fb.color_at(x, y).unwrap();
            // A 48x96 tessellation: the facet's sagitta moves the world point off the sphere by
            // < r(1 − cos(π/96)) ≈ 8e-4, which tilts the true normal by < ~0.03 rad at the rim.
            assert!(v.x < 0.05, "pixel ({x},{y}): normal off by {} rad", v.x);
            assert!(
                v.y < 0.0,
                "pixel ({x},{y}): normal does not face the viewer"
            );
        }
    }
    assert!(covered > 3000, "only {covered} pixels covered");
}

#[test]
fn coverage_and_depth_are_those_of_the_flat_program() {
    let cam = camera();
    let (pos, nrm, idx) = sphere(Vec3::new(0.4, 0.2, -1.0), 1.2, 12, 24);
    let mesh = Mesh::new(&pos, &idx).unwrap().with_normals(&nrm).unwrap();
    let mut a = Framebuffer::new(160, 120).unwrap();
    a.clear([0, 0, 0, 255]);
    a.draw_mesh(
        &cam,
        &mesh,
        &Shading::Flat(Vec3::ONE),
        &DrawState::default(),
    )
    .unwrap();
    let mut b = Framebuffer::new(160, 120).unwrap();
    b.clear([0, 0, 0, 255]);
    let white = |_: &SurfaceQuad| [Vec3::ONE; 4];
    b.draw_surface(&cam, &mesh, &white, &DrawState::default())
        .unwrap();
    let (fa, fbb) = (a.to_frame(), b.to_frame());
    assert_eq!(fa.color, fbb.color);
    assert_eq!(
        fa.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
        fbb.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>()
    );
}
