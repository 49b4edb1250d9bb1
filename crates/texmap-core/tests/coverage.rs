//! Seed 000 Eq. (5)–(7): the paper's worked example, Eq. (7) against a brute-force maximum of
//! Eq. (6), and Eq. (6) against the transform's analytic derivative (Eq. 2) on a real camera.

use texmap_core::camera::Camera;
use texmap_core::coverage::{ActiveArea, level_at, level_max};
use texmap_core::glam::Vec3;
use texmap_core::transform::TexturedFace;

#[test]
fn worked_example_psi45_1024px_256texels() {
    let a = ActiveArea::new(45.0, 1024, 256).unwrap();
    // Level L covers |x_a| ≤ 2.83·2^−L map widths.
    let r = a.radius_in_own_maps();
    assert!(
        (r - 2.83).abs() < 0.005,
        "expected 2.83, got {r}, tol 0.005"
    );
    for l in 0..=8 {
        let expect = 2.83 * (-(l as f64)).exp2();
        let got = a.radius(l);
        assert!(
            (got - expect).abs() <= 0.005 * expect,
            "level {l}: expected {expect}, got {got}"
        );
        // At that radius Eq. (7) asks for exactly level L's density, 256·2^L texels per map width.
        let need = a.level_max(got);
        let have = (256.0 * (l as f64).exp2()).log2();
        assert!(
            (need - have).abs() < 1e-9,
            "level {l}: Eq. 7 gives {need}, level has {have}"
        );
    }
    // (2·3)² maps per level, 9 levels: 324.
    assert_eq!(a.maps_per_level(), 36);
    assert_eq!(a.map_count(0..=8), 324);
}

#[test]
fn eq7_is_the_maximum_of_eq6_over_altitude_and_pitch() {
    for (fov_deg, n_pxl) in [(45.0f64, 1024u32), (60.0, 1920), (90.0, 640), (20.0, 800)] {
        let psi = fov_deg.to_radians();
        let k = n_pxl as f64 / (2.0 * (psi * 0.5).tan());
        for x_a in [0.01, 0.3, 1.0, 7.5] {
            // Brute force: h log-spaced over 6 decades around x_a, θ over ε ± ψ/2.
            let mut best = f64::NEG_INFINITY;
            let mut best_at = (0.0, 0.0);
            for ih in 0..=600 {
                let h = x_a * 10f64.powf(-3.0 + 6.0 * ih as f64 / 600.0);
                let eps = (x_a / h).atan();
                for it in 0..=200 {
                    let theta = eps - psi * 0.5 + psi * it as f64 / 200.0;
                    let l = level_at(x_a, h, theta, k);
                    if l > best {
                        best = l;
                        best_at = (h, theta - eps);
                    }
                }
            }
            let eq7 = level_max(x_a, n_pxl, psi);
            // The grid reaches the maximiser h = x_a, |θ − ε| = ψ/2 exactly, so they agree to
            // rounding; nothing on the grid may exceed Eq. (7).
            assert!(
                (best - eq7).abs() < 1e-9,
                "ψ={fov_deg} n={n_pxl} x_a={x_a}: expected {eq7}, brute force {best} at {best_at:?}, tol 1e-9"
            );
            assert!(
                (best_at.0 / x_a - 1.0).abs() < 1e-9 && (best_at.1.abs() - psi / 2.0).abs() < 1e-9
            );
            // And off the grid: random (h, θ) never beat it.
            let mut s = 0x1234_5678_9abc_def0u64;
            for _ in 0..20_000 {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                let u = (s >> 11) as f64 / (1u64 << 53) as f64;
                let v = ((s >> 3) & 0xffff) as f64 / 65535.0;
                let h = x_a * 10f64.powf(-3.0 + 6.0 * u);
                let theta = (x_a / h).atan() + psi * (v - 0.5);
                let l = level_at(x_a, h, theta, k);
                assert!(
                    l <= eq7 + 1e-9,
                    "Eq. 6 {l} exceeds Eq. 7 {eq7} at h={h} θ={theta}"
                );
            }
        }
    }
}

#[test]
fn eq6_matches_the_transforms_derivative_on_a_pitched_camera() {
    // Eye at altitude h over the origin, pitched θ from the nadir toward +x; ground y = 0 with map
    // x along world x and one world unit per map width. A = (x_a, 0, 0) is on the centre column.
    let mut checked = 0;
    for &(h, theta_deg, x_a) in &[
        (1.0f32, 30.0f32, 0.8f32),
        (2.0, 50.0, 3.0),
        (0.5, 70.0, 1.5),
        (3.0, 10.0, 0.2),
        (1.0, 45.0, 1.0),
    ] {
        let theta = theta_deg.to_radians();
        let eye = Vec3::new(0.0, h, 0.0);
        let fwd = Vec3::new(theta.sin(), -theta.cos(), 0.0);
        let cam = Camera::perspective_look_at(eye, eye + fwd, Vec3::Y, 60.0, 1000, 1000).unwrap();
        let face = TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, 1.0, &cam).unwrap();
        let (p, _) = cam
            .project(Vec3::new(x_a, 0.0, 0.0))
            .expect("A in front of the eye");
        if !(p.y >= 0.0 && p.y <= 1000.0) {
            continue;
        }
        let s = face.map(p.x, p.y).unwrap();
        assert!(
            (s.uv.x - x_a).abs() < 1e-4 && s.uv.y.abs() < 1e-4,
            "A maps to {}",
            s.uv
        );
        // The paper's x_s is the screen direction in the pitch plane: our y (down).
        let got = -(s.duv_dy.x.abs() as f64).log2();
        let expect = level_at(x_a as f64, h as f64, theta as f64, cam.scale() as f64);
        assert!(
            (got - expect).abs() < 1e-4,
            "h={h} θ={theta_deg} x_a={x_a}: Eq. 6 {expect}, transform {got}, tol 1e-4"
        );
        checked += 1;
    }
    assert_eq!(checked, 5);
}
