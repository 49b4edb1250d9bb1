//! Seed 000 Eq. (1)–(3) checked against an independent f64 ray–plane intersection through the
//! camera's ray (Eq. 1) and f64 central finite differences of that intersection (Eq. 2).

use texmap_core::camera::Camera;
use texmap_core::glam::{DVec3, Vec3};
use texmap_core::transform::{TexturedFace, TransformError};

/// xorshift64*: a small seeded generator (no dependency).
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.f()
    }
    fn vec(&mut self, s: f64) -> DVec3 {
        DVec3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
}

struct Scene {
    cam: Camera,
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    map_width: f64,
}

/// The map coordinates (map widths) of the face point seen through screen point (x, y), by
/// intersecting the camera ray with the plane in f64.
fn reference(s: &Scene, x: f64, y: f64) -> Option<(f64, f64)> {
    let c = &s.cam;
    let k = c.scale() as f64;
    let dir = c.right().as_dvec3() * (x - c.width() as f64 * 0.5)
        - c.up().as_dvec3() * (y - c.height() as f64 * 0.5)
        + c.forward().as_dvec3() * k;
    let eye = c.eye().as_dvec3();
    let n = s.u.cross(s.v);
    let t = n.dot(s.origin - eye) / n.dot(dir);
    if !(t > 0.0 && t.is_finite()) {
        return None;
    }
    let p = eye + dir * t - s.origin;
    // Solve p = w (x_m u + y_m v) by the normal equations.
    let (uu, uv, vv) = (s.u.dot(s.u), s.u.dot(s.v), s.v.dot(s.v));
    let (pu, pv) = (p.dot(s.u), p.dot(s.v));
    let det = uu * vv - uv * uv;
    Some((
        (pu * vv - pv * uv) / det / s.map_width,
        (pv * uu - pu * uv) / det / s.map_width,
    ))
}

/// The cosine between the pixel ray and the face normal (small = grazing, ill-conditioned).
fn ray_cos(s: &Scene, x: f64, y: f64) -> f64 {
    let c = &s.cam;
    let dir = (c.right().as_dvec3() * (x - c.width() as f64 * 0.5)
        - c.up().as_dvec3() * (y - c.height() as f64 * 0.5)
        + c.forward().as_dvec3() * c.scale() as f64)
        .normalize();
    dir.dot(s.u.cross(s.v).normalize()).abs()
}

fn random_scene(r: &mut Rng) -> Scene {
    loop {
        let eye = r.vec(20.0);
        let target = r.vec(3.0);
        let fov = r.range(10.0, 120.0) as f32;
        let (w, h) = (r.range(16.0, 1200.0) as u32, r.range(16.0, 900.0) as u32);
        let Ok(cam) =
            Camera::perspective_look_at(eye.as_vec3(), target.as_vec3(), Vec3::Y, fov, w, h)
        else {
            continue;
        };
        let origin = r.vec(5.0);
        let u = r.vec(1.0);
        let v = r.vec(1.0);
        if u.cross(v).length() < 0.2 * u.length() * v.length()
            || u.length() < 0.1
            || v.length() < 0.1
        {
            continue;
        }
        return Scene {
            cam,
            origin,
            u,
            v,
            map_width: r.range(0.1, 10.0),
        };
    }
}

#[test]
fn eq1_matches_f64_ray_plane_intersection_and_eq2_matches_finite_differences() {
    let mut r = Rng(0x9E37_79B9_7F4A_7C15);
    let (mut checked, mut missed) = (0, 0);
    let mut worst_uv = 0.0f64;
    let mut worst_d = 0.0f64;
    for _ in 0..300 {
        let s = random_scene(&mut r);
        let face = match TexturedFace::new(
            s.origin.as_vec3(),
            s.u.as_vec3(),
            s.v.as_vec3(),
            s.map_width as f32,
            &s.cam,
        ) {
            Ok(f) => f,
            Err(e) => panic!("random scene refused: {e}"),
        };
        let eye_map = face.eye_in_map().as_dvec3().length();
        for _ in 0..40 {
            let x = r.range(0.0, s.cam.width() as f64);
            let y = r.range(0.0, s.cam.height() as f64);
            let got = face.map(x as f32, y as f32);
            let Some(expect) = reference(&s, x, y) else {
                assert!(got.is_none(), "ray misses in f64 but f32 gave {got:?}");
                missed += 1;
                continue;
            };
            // Skip grazing rays, where f32 input rounding alone moves the answer a lot.
            if ray_cos(&s, x, y) < 0.05 {
                continue;
            }
            let got = got.unwrap_or_else(|| panic!("f64 hits at ({x},{y}) but f32 missed"));
            // Eq. (1): tolerance relative to the magnitudes the f32 sum goes through.
            let mag = 1.0 + expect.0.abs().max(expect.1.abs()) + eye_map;
            let tol = 2e-4 * mag;
            let err = (got.uv.x as f64 - expect.0)
                .abs()
                .max((got.uv.y as f64 - expect.1).abs());
            assert!(
                err <= tol,
                "uv at ({x},{y}): expected {expect:?}, got {}, tol {tol}",
                got.uv
            );
            worst_uv = worst_uv.max(err / mag);
            // Eq. (2): central differences of the f64 reference, h = 1e-3 px.
            let h = 1e-3;
            let (px, mx) = (
                reference(&s, x + h, y).unwrap(),
                reference(&s, x - h, y).unwrap(),
            );
            let (py, my) = (
                reference(&s, x, y + h).unwrap(),
                reference(&s, x, y - h).unwrap(),
            );
            let fd_dx = ((px.0 - mx.0) / (2.0 * h), (px.1 - mx.1) / (2.0 * h));
            let fd_dy = ((py.0 - my.0) / (2.0 * h), (py.1 - my.1) / (2.0 * h));
            let scale = fd_dx
                .0
                .abs()
                .max(fd_dx.1.abs())
                .max(fd_dy.0.abs())
                .max(fd_dy.1.abs());
            // f32 rounding of the analytic form (worst seen ~3e-5 relative) plus O(h²) of the
            // differences.
            let dtol = 5e-4 * scale;
            for (a, e) in [
                (got.duv_dx.x, fd_dx.0),
                (got.duv_dx.y, fd_dx.1),
                (got.duv_dy.x, fd_dy.0),
                (got.duv_dy.y, fd_dy.1),
            ] {
                let d = (a as f64 - e).abs();
                assert!(
                    d <= dtol,
                    "derivative at ({x},{y}): expected {e}, got {a}, tol {dtol}"
                );
                worst_d = worst_d.max(d / scale);
            }
            checked += 1;
        }
    }
    assert!(
        checked > 3000,
        "only {checked} pixels checked ({missed} missed)"
    );
    assert!(
        missed > 100,
        "random scenes never missed the plane: the miss branch is untested"
    );
    eprintln!(
        "checked {checked}, missed {missed}, worst uv rel {worst_uv:e}, worst d rel {worst_d:e}"
    );
}

#[test]
fn level_and_lambda_relation_for_a_2n_map() {
    // Straight down from height 10 with 90° FOV over 256 px: 20 world units per 256 px.
    let cam = Camera::perspective_look_at(
        Vec3::new(0.0, 10.0, 0.0),
        Vec3::ZERO,
        Vec3::NEG_Z,
        90.0,
        256,
        256,
    )
    .unwrap();
    let face = TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, 5.0, &cam).unwrap();
    let s = face.map(128.0, 128.0).unwrap();
    // ∂x_m/∂x_s = 20/256 world units per px / 5 world units per map = 1/64 map widths per px.
    let expect = 1.0 / 64.0;
    assert!(
        (s.duv_dx.x - expect).abs() < 1e-7,
        "expected {expect}, got {}, tol 1e-7",
        s.duv_dx.x
    );
    // l = −log2(1/64) = 6: level 6 (64 texels per map width) is one texel per pixel.
    assert!((s.level() - 6.0).abs() < 1e-4, "l = {}", s.level());
    // A 1024-texel map (n = 10): λ = n − l = 4, i.e. 16 texels of level 0 per pixel.
    assert!(
        (s.lambda(10.0) - 4.0).abs() < 1e-4,
        "λ = {}",
        s.lambda(10.0)
    );
    let texels_per_px = s.duv_dx.x.abs().max(s.duv_dy.y.abs()) * 1024.0;
    assert!((texels_per_px.log2() - s.lambda(10.0)).abs() < 1e-4);
    // Eq. (3) at l = 6: a_c = ⌊64 r_m⌋, a_f = ⌊128 r_m⌋; γ = frac(l).
    let s2 = face.map(140.3, 100.7).unwrap();
    let a = s2.texel_address();
    assert_eq!(a.level, s2.level().floor() as i32);
    let c = (a.level as f64).exp2();
    assert_eq!(a.a_c.x, (s2.uv.x as f64 * c).floor() as i64);
    assert_eq!(a.a_f.y, (s2.uv.y as f64 * 2.0 * c).floor() as i64);
    assert!((a.gamma - (s2.level() - s2.level().floor())).abs() < 1e-6);
    assert!(a.w_c.x >= 0.0 && a.w_c.x < 1.0 && a.w_f.y >= 0.0 && a.w_f.y < 1.0);
}

#[test]
fn span_images_follow_eq8() {
    let cam = Camera::perspective_look_at(
        Vec3::new(1.0, 3.0, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        60.0,
        320,
        240,
    )
    .unwrap();
    let face = TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::NEG_Z, 2.0, &cam).unwrap();
    let q = face.map_span(160.0, 120.0).unwrap();
    let direct = [
        (159.5, 119.5),
        (160.5, 119.5),
        (159.5, 120.5),
        (160.5, 120.5),
    ]
    .map(|(x, y)| face.map(x, y).unwrap().uv);
    assert_eq!(q, direct);
    // z⁻¹ is affine in the screen (Eq. 8): the centre's value is the mean of the four.
    let zc = face.inv_depth(160.0, 120.0);
    let zm = [
        (159.5, 119.5),
        (160.5, 119.5),
        (159.5, 120.5),
        (160.5, 120.5),
    ]
    .map(|(x, y)| face.inv_depth(x, y))
    .iter()
    .sum::<f32>()
        / 4.0;
    assert!(
        (zc - zm).abs() <= 1e-6 * zc,
        "expected {zc}, got {zm}, tol {}",
        1e-6 * zc
    );
}

#[test]
fn degenerate_faces_are_errors_and_horizon_pixels_are_none() {
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 60.0, 64, 64)
            .unwrap();
    // The eye lies in the plane y = 1: edge-on.
    assert!(matches!(
        TexturedFace::new(Vec3::new(0.0, 1.0, 0.0), Vec3::X, Vec3::Z, 1.0, &cam),
        Err(TransformError::EdgeOn { .. })
    ));
    assert_eq!(
        TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0, 1.0, &cam),
        Err(TransformError::DegenerateAxes)
    );
    assert_eq!(
        TexturedFace::new(Vec3::ZERO, Vec3::ZERO, Vec3::Z, 1.0, &cam),
        Err(TransformError::DegenerateAxes)
    );
    assert_eq!(
        TexturedFace::new(Vec3::NAN, Vec3::X, Vec3::Z, 1.0, &cam),
        Err(TransformError::NonFinite)
    );
    for w in [0.0, -1.0] {
        assert!(matches!(
            TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, w, &cam),
            Err(TransformError::BadMapWidth { .. })
        ));
    }
    let ortho =
        Camera::orthographic_look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 4.0, 64, 64)
            .unwrap();
    assert_eq!(
        TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, 1.0, &ortho),
        Err(TransformError::Orthographic)
    );
    // FOV 0° / 180° and a NaN eye never become a camera, so never reach a face.
    for fov in [0.0, 180.0] {
        assert!(Camera::perspective_look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, fov, 8, 8).is_err());
    }
    assert!(Camera::perspective_look_at(Vec3::NAN, Vec3::ZERO, Vec3::Y, 60.0, 8, 8).is_err());
    // Ground plane y = 0 seen from above at a shallow angle: the top rows see the sky.
    let face = TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, 1.0, &cam).unwrap();
    let mut sky = 0;
    for j in 0..64 {
        for i in 0..64 {
            match face.map(i as f32 + 0.5, j as f32 + 0.5) {
                None => sky += 1,
                Some(s) => {
                    assert!(s.uv.is_finite() && s.level().is_finite() && s.inv_depth > 0.0);
                }
            }
        }
    }
    assert!(sky > 0 && sky < 64 * 64, "sky pixels {sky}");
    let s = face.map(32.0, 63.5).unwrap();
    assert!(s.level().is_finite() && s.lambda(8.0).is_finite());
}
