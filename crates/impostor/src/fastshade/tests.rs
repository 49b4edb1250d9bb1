use super::*;

#[test]
fn pow_matches_libm() {
    let mut worst = 0f32;
    for i in 0..=20_000 {
        let x = i as f32 / 20_000.0;
        for e in [1.0f32, 2.0, 7.5, 40.0, 128.0] {
            let a = x.powf(e);
            let b = pow01(x, e);
            worst = worst.max((a - b).abs() / a.max(1e-30).max(1e-6));
        }
    }
    assert!(worst < 2e-5, "relative error expected < 2e-5, got {worst}");
}

/// The squaring powers against f64 `powi`: within `e` units of rounding where the base is at or
/// above its floor; 0 below it, where the exact power is below 2^−60; never a subnormal
/// result; and the per-lane form (`Ints`) gives the same bits as the shared one (`Same`).
#[test]
fn integer_powers_are_accurate_and_never_subnormal() {
    let exps = [0u32, 1, 2, 3, 7, 40, 41, 128, 1000, 65_535];
    let mut xs: Vec<f32> = (0..=2000).map(|i| i as f32 / 2000.0).collect();
    xs.extend((1..=140).map(|i| 2f32.powi(-i)));
    xs.extend([f32::MIN_POSITIVE, 1e-30, 0.1, 0.177, 0.2, 0.27, 0.99999]);
    let mut checked = 0;
    for (ei, &e) in exps.iter().enumerate() {
        let same = spec_pow(&[e as f32; W]);
        // Lane 3 carries `e`; the others other exponents (so `Ints`, with more bits).
        let mixed: F8 = std::array::from_fn(|l| exps[(ei + l + 7) % exps.len()] as f32);
        let ints = spec_pow(&mixed);
        assert!(matches!(same, SpecPow::Same { .. }), "{same:?}");
        assert!(matches!(ints, SpecPow::Ints { .. }), "{ints:?}");
        let SpecPow::Same { floor, .. } = same else {
            unreachable!()
        };
        for &x in &xs {
            let a = pow_int8([V8::splat(x)], &same)[0].store()[0];
            let b = pow_int8([V8::splat(x)], &ints)[0].store()[3];
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "x = {x}, e = {e}: Same {a}, Ints {b}"
            );
            assert!(
                a == 0.0 || a.is_normal(),
                "x = {x}, e = {e}: {a} is subnormal"
            );
            let exact = (x as f64).powi(e as i32);
            if x >= floor {
                // Each squaring doubles the relative error it is given and adds one
                // rounding: x^e ends within ~(e − 1)·2^−24 of exact (plus the products).
                let tol = 1.1 * e.max(1) as f64 * 2f64.powi(-24);
                let rel = (a as f64 - exact).abs() / exact.max(f64::MIN_POSITIVE);
                assert!(rel <= tol, "x = {x}, e = {e}: {a} vs {exact} ({rel:e})");
            } else {
                assert_eq!(a, 0.0, "x = {x} below the floor {floor}, e = {e}");
                assert!(
                    exact < 2f64.powi(-60),
                    "x = {x}, e = {e}: dropped {exact:e}"
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, exps.len() * xs.len());
}

#[test]
fn shade_matches_lighting_shade() {
    let l = Lighting::new(
        Vec3::splat(0.1),
        &[
            (Vec3::new(-0.4, 0.5, 1.0), Vec3::splat(0.9)),
            (Vec3::new(0.6, -0.2, 0.8), Vec3::splat(0.3)),
        ],
    )
    .unwrap();
    let m = Material::plastic(Vec3::new(0.7, 0.3, 0.2));
    let mut s = 1u32;
    let mut r = || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
    };
    let mut worst = 0f32;
    for _ in 0..100_000 {
        let n = Vec3::new(r(), r(), r()).normalize_or(Vec3::Z);
        let v = Vec3::new(r() * 0.3, r() * 0.3, 1.0).normalize();
        let a = l.shade(&m, n, v);
        let b = shade(&l, &m, n, v);
        worst = worst.max((a - b).abs().max_element());
    }
    assert!(worst <= 2e-5, "expected ≤ 2e-5, got {worst}");
}

#[test]
fn shade8_matches_lighting_shade() {
    let l = Lighting::new(
        Vec3::splat(0.1),
        &[
            (Vec3::new(-0.4, 0.5, 1.0), Vec3::splat(0.9)),
            (Vec3::new(0.6, -0.2, 0.8), Vec3::splat(0.3)),
        ],
    )
    .unwrap();
    let mats = [
        Material::plastic(Vec3::new(0.7, 0.3, 0.2)),
        Material::matte(Vec3::new(0.1, 0.9, 0.4)),
    ];
    let mut st = 7u32;
    let mut r = || {
        st = st.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (st >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
    };
    let mut worst = 0f32;
    for _ in 0..20_000 {
        let mut s = Surf8::default();
        let mut want = [Vec3::ZERO; W];
        for i in 0..W {
            let n = Vec3::new(r(), r(), r()).normalize_or(Vec3::Z);
            let v = Vec3::new(r() * 0.3, r() * 0.3, 1.0).normalize();
            let m = &mats[i % 2];
            want[i] = l.shade(m, n, v);
            for k in 0..3 {
                s.n[k][i] = n[k];
                s.v[k][i] = v[k];
                s.base[k][i] = m.base_color[k];
            }
            s.spec[i] = m.specular;
            s.shin[i] = m.shininess;
        }
        let got = shade8(&l, &s);
        for i in 0..W {
            let g = Vec3::new(got[0][i], got[1][i], got[2][i]);
            worst = worst.max((g - want[i]).abs().max_element());
        }
    }
    assert!(worst <= 2e-5, "expected ≤ 2e-5, got {worst}");
}
