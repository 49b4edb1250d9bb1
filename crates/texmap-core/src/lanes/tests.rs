//! The lane maths against independent references (libm `powf`, f64 `powi`, [`Lighting::shade`],
//! [`linear_to_srgb8_fast`]) and the SIMD backends against their portable forms.

// Lane loops index several fixed-width arrays with one lane counter.
#![allow(clippy::needless_range_loop)]

use glam::Vec3;

use super::shade::{Surf8, shade, shade8};
use super::*;
use crate::color::linear_to_srgb8_fast;
use crate::shade::{Lighting, Material};

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
        let same = spec_pow(&[e as f32; LANES8]);
        // Lane 3 carries `e`; the others other exponents (so `Ints`, with more bits).
        let mixed: [f32; 8] = std::array::from_fn(|l| exps[(ei + l + 7) % exps.len()] as f32);
        let ints = spec_pow(&mixed);
        assert!(matches!(same, SpecPow::Same { .. }), "{same:?}");
        assert!(matches!(ints, SpecPow::Ints { .. }), "{ints:?}");
        let SpecPow::Same { floor, .. } = same else {
            unreachable!()
        };
        for &x in &xs {
            let a = pow_int_lanes([F32x8::splat(x)], &same)[0].store()[0];
            let b = pow_int_lanes([F32x8::splat(x)], &ints)[0].store()[3];
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
        let mut want = [Vec3::ZERO; LANES8];
        for i in 0..LANES8 {
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
        for i in 0..LANES8 {
            let g = Vec3::new(got[0][i], got[1][i], got[2][i]);
            worst = worst.max((g - want[i]).abs().max_element());
        }
    }
    assert!(worst <= 2e-5, "expected ≤ 2e-5, got {worst}");
}

#[test]
fn pow01_x4_matches_powf_within_1e_5() {
    let mut worst = 0.0f64;
    for p in [1.0f32, 2.5, 5.0, 40.0, 128.0, 1000.0, 65536.0] {
        for k in 0..=4096u32 {
            // Uniform in [0, 1] plus a dense set just below 1 and a few tiny values.
            let xs = [
                k as f32 / 4096.0,
                1.0 - k as f32 * 1e-7,
                f32::MIN_POSITIVE * k as f32,
                1e-20 * k as f32,
            ];
            let got = pow01_x4(F32x4::new(xs), p).to_array();
            for (x, g) in xs.into_iter().zip(got) {
                let want = (x as f64).powf(p as f64);
                let err = (g as f64 - want).abs();
                let tol = 1e-5 * want + 1e-37;
                assert!(err <= tol, "{x}^{p}: expected {want} got {g} tol {tol}");
                if want > 1e-30 {
                    worst = worst.max(err / want);
                }
            }
        }
    }
    assert!(worst > 0.0 && worst < 1e-5, "worst relative error {worst}");
}

#[test]
fn log2_split_is_exact_in_its_integer_part_and_close_in_its_fraction() {
    let mut worst = 0f64;
    let mut prev = f64::NEG_INFINITY;
    for i in 0..200_000 {
        let x = 2f32.powf(-20.0 + 40.0 * i as f32 / 200_000.0);
        let (e, f) = log2_split(x);
        let exact = (x as f64).log2();
        assert_eq!(e, exact.floor() as i32, "x = {x}");
        assert!((0.0..=1.0).contains(&f), "x = {x}: fraction {f}");
        let got = e as f64 + f as f64;
        worst = worst.max((got - exact).abs());
        assert!(got >= prev, "not monotone at {x}");
        prev = got;
    }
    assert!(worst < 1.3e-4, "expected |error| < 1.3e-4, worst {worst}");
}

/// Deterministic test values: specials, small and large magnitudes, raw bit patterns.
fn values(seed: u64, n: usize) -> Vec<f32> {
    let specials = [
        0.0f32,
        -0.0,
        1.0,
        -1.5,
        0.5,
        1e30,
        -3e9,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        2.5e-40,
        4096.0,
    ];
    let mut st = seed;
    (0..n)
        .map(|k| {
            st = st
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let v = (st >> 32) as u32;
            match k % 4 {
                0 => specials[v as usize % specials.len()],
                1 => (v as i32 as f32) * 1e-6,
                2 => (v >> 8) as f32 / (1u32 << 24) as f32 * 1.25 - 0.1,
                _ => f32::from_bits(v),
            }
        })
        .collect()
}

/// The sRGB lane encode gives `linear_to_srgb8_fast`'s bytes, NaN and out-of-range included.
#[test]
fn srgb_lanes_equal_the_scalar_encoder() {
    let table = srgb_table32();
    let v = values(11, 24 * 500);
    for c in v.chunks_exact(24) {
        let (r, g, b) = (&c[..8], &c[8..16], &c[16..]);
        let px = srgb_rgba_lanes(
            F32x8::load_from(r),
            F32x8::load_from(g),
            F32x8::load_from(b),
            table,
        );
        let mut out = [[0u8; 4]; 8];
        px.store_rgba(&mut out);
        for l in 0..8 {
            let want = [
                linear_to_srgb8_fast(r[l]),
                linear_to_srgb8_fast(g[l]),
                linear_to_srgb8_fast(b[l]),
                255,
            ];
            assert_eq!(out[l], want, "lane {l}: {} {} {}", r[l], g[l], b[l]);
        }
    }
}

/// One sequence of [`Lanes8`] operations on `a`, `b`; every result as bits.
fn trace8<V: Lanes8>(a: &[f32], b: &[f32], e: &[u32; 8], n: usize) -> Vec<u32> {
    let (va, vb) = (V::load_from(a), V::load_from(b));
    let vs = [
        va + vb,
        va - vb,
        va * vb,
        va / vb,
        va.sqrt(),
        va.min(vb),
        va.max(vb),
        V::select(va.lt(vb), va, vb),
        V::select(va.le(vb), vb, va),
        V::select(va.gt(vb).and(vb.ge(va)), va, vb),
        V::select(va.eq_bits(vb), va, vb),
        V::select(V::bit_set(e, (n % 20) as u32), va, vb),
        V::select(<V::Mask as LaneMask>::first(n % 9), va, vb),
        V::select(<V::Mask as LaneMask>::first_of_halves(n % 5), va, vb),
        va.and_bits(vb),
        va.xor_bits(vb),
        V::splat_bits(e[0]),
        V::load_bits(e),
        V::load_halves(a, &b[4..]),
    ];
    let mut out = Vec::new();
    for v in vs {
        let mut bits = [0u32; 8];
        v.store_bits(&mut bits);
        out.extend(bits);
    }
    let masks = [va.lt(vb), va.le(vb), va.gt(vb), va.ge(vb), va.eq_bits(vb)];
    out.extend(masks.map(|m| m.bits()));
    let mut halves = [0f32; 8];
    va.store_lo(&mut halves[..4]);
    vb.store_hi(&mut halves[4..]);
    out.extend(halves.map(f32::to_bits));
    let rows: [[f32; 8]; 8] =
        std::array::from_fn(|r| std::array::from_fn(|k| a[(r + k) % 8] * b[r]));
    let cols = V::transpose(std::array::from_fn(|r| &rows[r]));
    for c in cols {
        let mut bits = [0u32; 8];
        c.store_bits(&mut bits);
        out.extend(bits);
    }
    // The sRGB pack on indices in range (the callers clamp them).
    let q = |x: V| x.max(V::splat(0.0)).min(V::splat((SRGB_N - 1) as f32));
    let px = V::srgb_pack(
        q(va * V::splat(4096.0)),
        q(vb * V::splat(4096.0)),
        q((va + vb) * V::splat(2048.0)),
        srgb_table32(),
    );
    let mut rgba = [[0u8; 4]; 8];
    px.store_rgba(&mut rgba);
    out.extend(rgba.map(u32::from_le_bytes));
    out
}

/// The same [`Lanes8`] operations on plain `f32` per lane (the scalar twin of every backend).
fn trace8_scalar(a: &[f32], b: &[f32], e: &[u32; 8], n: usize) -> Vec<u32> {
    let sel = |c: bool, x: f32, y: f32| if c { x } else { y };
    let mut out = Vec::new();
    let per_lane: [&dyn Fn(usize) -> u32; 19] = [
        &|l| (a[l] + b[l]).to_bits(),
        &|l| (a[l] - b[l]).to_bits(),
        &|l| (a[l] * b[l]).to_bits(),
        &|l| (a[l] / b[l]).to_bits(),
        &|l| a[l].sqrt().to_bits(),
        &|l| sel(a[l] < b[l], a[l], b[l]).to_bits(),
        &|l| sel(a[l] > b[l], a[l], b[l]).to_bits(),
        &|l| sel(a[l] < b[l], a[l], b[l]).to_bits(),
        &|l| sel(a[l] <= b[l], b[l], a[l]).to_bits(),
        &|l| sel(a[l] > b[l] && b[l] >= a[l], a[l], b[l]).to_bits(),
        &|l| sel(a[l].to_bits() == b[l].to_bits(), a[l], b[l]).to_bits(),
        &|l| sel((e[l] >> (n % 20)) & 1 != 0, a[l], b[l]).to_bits(),
        &|l| sel(l < n % 9, a[l], b[l]).to_bits(),
        &|l| sel(l % 4 < n % 5, a[l], b[l]).to_bits(),
        &|l| a[l].to_bits() & b[l].to_bits(),
        &|l| a[l].to_bits() ^ b[l].to_bits(),
        &|_| e[0],
        &|l| e[l],
        &|l| if l < 4 { a[l] } else { b[l] }.to_bits(),
    ];
    for f in per_lane {
        out.extend((0..8).map(f));
    }
    let bits = |f: &dyn Fn(usize) -> bool| (0..8).fold(0u32, |m, l| m | ((f(l) as u32) << l));
    out.push(bits(&|l| a[l] < b[l]));
    out.push(bits(&|l| a[l] <= b[l]));
    out.push(bits(&|l| a[l] > b[l]));
    out.push(bits(&|l| a[l] >= b[l]));
    out.push(bits(&|l| a[l].to_bits() == b[l].to_bits()));
    out.extend((0..8).map(|l| if l < 4 { a[l] } else { b[l] }.to_bits()));
    let rows: [[f32; 8]; 8] =
        std::array::from_fn(|r| std::array::from_fn(|k| a[(r + k) % 8] * b[r]));
    for k in 0..8 {
        out.extend((0..8).map(|l| rows[l][k].to_bits()));
    }
    let q = |x: f32| {
        let x = if x > 0.0 { x } else { 0.0 };
        let x = if x < (SRGB_N - 1) as f32 {
            x
        } else {
            (SRGB_N - 1) as f32
        };
        x as u32
    };
    let idx = |f: &dyn Fn(usize) -> f32| -> [u32; 8] { std::array::from_fn(|l| q(f(l))) };
    let px = srgb_pack_scalar(
        idx(&|l| a[l] * 4096.0),
        idx(&|l| b[l] * 4096.0),
        idx(&|l| (a[l] + b[l]) * 2048.0),
        srgb_table32(),
    );
    out.extend(px);
    out
}

/// Compare two traces; NaN payloads may differ between implementations, NaN-ness may not.
fn assert_same_trace(got: &[u32], want: &[u32], what: &str, round: usize) {
    assert_eq!(got.len(), want.len(), "{what}: trace lengths");
    for (k, (x, y)) in got.iter().zip(want).enumerate() {
        let nan = |v: u32| f32::from_bits(v).is_nan();
        assert!(
            x == y || (nan(*x) && nan(*y)),
            "{what}, round {round}, value {k}: {x:#x} against {y:#x}"
        );
    }
}

#[test]
fn baseline_8_lanes_equal_the_scalar_twin() {
    let v = values(3, 16 * 3000);
    for (round, c) in v.chunks_exact(16).enumerate() {
        let (a, b) = (&c[..8], &c[8..]);
        let e: [u32; 8] =
            std::array::from_fn(|l| a[l].to_bits() ^ (round as u32).rotate_left(l as u32));
        let want = trace8_scalar(a, b, &e, round);
        let array = trace8::<f32x8::portable::F32x8>(a, b, &e, round);
        assert_same_trace(&array, &want, "portable F32x8", round);
        let got = trace8::<F32x8>(a, b, &e, round);
        assert_same_trace(&got, &want, "F32x8", round);
    }
}

/// A shading run on the SSE2 lanes and on their array twin gives the same bits.
#[test]
fn baseline_shading_equals_the_portable_shading() {
    use super::shade::{LaneSurf, LanesLighting, shade_chunks};
    let l = Lighting::new(
        Vec3::splat(0.1),
        &[
            (Vec3::new(-0.4, 0.5, 1.0), Vec3::splat(0.9)),
            (Vec3::new(0.6, -0.2, 0.8), Vec3::splat(0.3)),
            (Vec3::new(0.1, 0.9, 0.3), Vec3::splat(0.5)),
        ],
    )
    .unwrap();
    fn run<V: Lanes8>(l: &Lighting, v: &[f32], shin: [f32; 8]) -> Vec<u32> {
        let lights = LanesLighting::<V, 3>::new(l);
        let mut out = Vec::new();
        for c in v.chunks_exact(8 * 10) {
            let ld = |k: usize| V::load_from(&c[8 * k..]);
            let s = LaneSurf {
                n: [ld(0), ld(1), ld(2)],
                v: [ld(3), ld(4), ld(5)],
                base: [ld(6), ld(7), ld(8)],
                spec: ld(9),
                shin: V::load_from(&shin),
            };
            let pw = spec_pow(&shin);
            for ch in shade_chunks(&lights, [s], pw)[0] {
                let mut bits = [0u32; 8];
                ch.store_bits(&mut bits);
                out.extend(bits);
            }
        }
        out
    }
    let v: Vec<f32> = values(21, 8 * 10 * 400)
        .into_iter()
        .map(|x| {
            if x.is_finite() && x.abs() <= 1.5 {
                x
            } else {
                0.3
            }
        })
        .collect();
    for shin in [
        [40.0; 8],
        [1.0, 2.0, 3.0, 7.0, 40.0, 41.0, 128.0, 1000.0],
        [7.5, 40.0, 0.5, 12.25, 1.0, 2.0, 3.0, 4.0],
    ] {
        let a = run::<F32x8>(&l, &v, shin);
        let b = run::<f32x8::portable::F32x8>(&l, &v, shin);
        assert_same_trace(&a, &b, "shading", 0);
    }
}

#[cfg(target_arch = "x86_64")]
#[test]
fn avx2_8_lanes_equal_the_baseline() {
    if !F32x8Avx2::available() {
        eprintln!("AVX2 not enabled (CPU or TEXMAP_ISA): skipped");
        return;
    }
    /// The trace compiled for AVX2.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn trace_avx2(a: &[f32], b: &[f32], e: &[u32; 8], n: usize) -> Vec<u32> {
        trace8::<F32x8Avx2>(a, b, e, n)
    }
    let v = values(5, 16 * 3000);
    for (round, c) in v.chunks_exact(16).enumerate() {
        let (a, b) = (&c[..8], &c[8..]);
        let e: [u32; 8] =
            std::array::from_fn(|l| a[l].to_bits() ^ (round as u32).rotate_left(l as u32));
        // SAFETY: AVX2 was checked above.
        let got = unsafe { trace_avx2(a, b, &e, round) };
        let want = trace8::<F32x8>(a, b, &e, round);
        assert_same_trace(&got, &want, "F32x8Avx2", round);
    }
}

/// The lane powers equal the scalar forms lane by lane (the shading relies on it to match
/// [`shade`] up to the squaring path).
#[test]
fn pow01_lanes_equal_pow01() {
    let xs = values(9, 8 * 2000);
    for (k, c) in xs.chunks_exact(8).enumerate() {
        // x in (0, 1], exponents as the shading passes them.
        let x: [f32; 8] = std::array::from_fn(|l| {
            let v = c[l].abs();
            if v > 0.0 && v <= 1.0 && v.is_normal() {
                v
            } else {
                0.5
            }
        });
        let e = [1.0, 2.5, 7.5, 40.0, 128.0, 1000.0, 0.25, k as f32][k % 8];
        let got = pow01_lanes(F32x8::load(&x), F32x8::splat(e)).store();
        for l in 0..8 {
            assert_eq!(got[l].to_bits(), pow01(x[l], e).to_bits(), "{}^{e}", x[l]);
        }
    }
}
