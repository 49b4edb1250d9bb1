//! Tests of the samplers: the scalar kernels against hand-computed values, every lane build
//! bit for bit against the scalar kernels and the bank emulator.

use super::*;
use crate::mip::Reduction;

fn ramp(w: u32, h: u32, wrap: Wrap) -> MipTexture {
    let data: Vec<Vec4> = (0..w * h)
        .map(|i| Vec4::new((i % w) as f32, (i / w) as f32, 1.0, 1.0))
        .collect();
    MipTexture::from_linear(w, h, &data, Reduction::GammaCorrect, wrap).unwrap()
}

#[test]
fn bilinear_at_texel_centres_and_midpoints_is_exact() {
    let t = ramp(8, 8, Wrap::Clamp);
    // Centre of texel (3, 5) is ((3.5)/8, (5.5)/8).
    let c = Sampler::Bilinear.sample(&t, Vec2::new(3.5 / 8.0, 5.5 / 8.0), Vec2::ZERO, Vec2::ZERO);
    assert!(
        (c - Vec4::new(3.0, 5.0, 1.0, 1.0)).abs().max_element() < 1e-6,
        "{c}"
    );
    let m = Sampler::Bilinear.sample(&t, Vec2::new(4.0 / 8.0, 2.25 / 8.0), Vec2::ZERO, Vec2::ZERO);
    let expect = Vec4::new(3.5, 1.75, 1.0, 1.0);
    assert!(
        (m - expect).abs().max_element() < 1e-6,
        "expected {expect}, got {m}, tol 1e-6"
    );
}

#[test]
fn nan_and_huge_inputs_give_finite_output() {
    for wrap in [Wrap::Repeat, Wrap::Clamp] {
        let t = ramp(6, 10, wrap);
        for s in [
            Sampler::Nearest,
            Sampler::Bilinear,
            Sampler::Trilinear,
            Sampler::Span(Banks::K3),
            Sampler::Span(Banks::K4),
            Sampler::Anisotropic { max_taps: 8 },
        ] {
            for uv in [
                Vec2::NAN,
                Vec2::splat(1e30),
                Vec2::splat(-f32::INFINITY),
                Vec2::new(0.3, 0.7),
            ] {
                for d in [
                    Vec2::NAN,
                    Vec2::ZERO,
                    Vec2::splat(1e30),
                    Vec2::new(0.01, 0.0),
                ] {
                    let c = s.sample(&t, uv, d, d.perp());
                    assert!(c.is_finite(), "{s:?} {wrap:?} {uv} {d} -> {c}");
                }
            }
        }
    }
}

/// Random pixels from every regime: magnified, minified, past the top level, NaN and huge
/// coordinates and derivatives, zero derivatives.
fn random_pixels(n: usize, seed: u32) -> (Vec<Vec2>, Vec<Vec2>, Vec<Vec2>) {
    let mut rng = seed;
    let mut r = move || {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        (rng >> 8) as f32 / (1u32 << 24) as f32
    };
    let (mut uv, mut dx, mut dy) = (vec![], vec![], vec![]);
    for i in 0..n {
        let mut p = Vec2::new(r() * 6.0 - 3.0, r() * 6.0 - 3.0);
        let s = 10f32.powf(r() * 7.0 - 5.0);
        let mut a = Vec2::new(r() - 0.5, r() - 0.5) * s;
        let mut b = Vec2::new(r() - 0.5, r() - 0.5) * s;
        match i % 23 {
            0 => p = Vec2::NAN,
            1 => a = Vec2::NAN,
            2 => (a, b) = (Vec2::NAN, Vec2::NAN),
            3 => p = Vec2::splat(1e30),
            4 => (a, b) = (Vec2::ZERO, Vec2::ZERO),
            5 => a = Vec2::splat(f32::INFINITY),
            6 => p.x = -f32::INFINITY,
            _ => {}
        }
        uv.push(p);
        dx.push(a);
        dy.push(b);
    }
    (uv, dx, dy)
}

#[test]
fn bulk_trilinear_lanes_match_the_per_pixel_sampler_bit_for_bit() {
    // The lane kernel (power-of-two pyramids) against `sample`, which always takes the scalar
    // per-pixel path; odd lengths exercise the scalar tail; NPOT takes the scalar path.
    let mut reached_pair = false;
    for (w, h) in [(64, 64), (64, 16), (1, 8), (1, 1), (256, 128), (48, 20)] {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let t = ramp(w, h, wrap);
            let (uv, dx, dy) = random_pixels(4003, w * 31 + h);
            let mut out = vec![Vec4::ZERO; uv.len()];
            Sampler::Trilinear
                .sample_pixels(&t, &uv, &dx, &dy, &mut out)
                .unwrap();
            for i in 0..uv.len() {
                let e = Sampler::Trilinear.sample(&t, uv[i], dx[i], dy[i]);
                assert_eq!(
                    out[i].to_array().map(f32::to_bits),
                    e.to_array().map(f32::to_bits),
                    "{w}x{h} {wrap:?} pixel {i}: uv {} dx {} dy {}: expected {e}, got {}",
                    uv[i],
                    dx[i],
                    dy[i],
                    out[i]
                );
                let m = footprint(&t.levels()[0], dx[i], dy[i]);
                reached_pair |= m > 1.0 && m.log2() < (t.level_count() - 1) as f32;
            }
        }
    }
    assert!(reached_pair, "no pixel blended two levels");
}

/// Spans from [`random_pixels`]' regimes, every third one small (mostly interior windows).
fn random_quads(n: usize, seed: u32) -> Vec<[Vec2; 4]> {
    let (uv, dx, dy) = random_pixels(n, seed);
    (0..n)
        .map(|i| {
            let s = if i % 3 == 0 { 0.02 } else { 1.0 };
            quad_from_pixel(uv[i], dx[i] * s, dy[i] * s)
        })
        .collect()
}

#[test]
fn one_span_calls_match_the_bank_emulator_bit_for_bit() {
    // `sample_quad(Span)` (the AVX2 power-of-two one-span kernel where the CPU has it) on
    // square, wide, tall and tiny pyramids, every input regime, against the emulator.
    let mut interior = 0u64;
    for (w, h) in [(64, 64), (64, 16), (16, 128), (1, 8), (2, 2), (256, 128)] {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let t = ramp(w, h, wrap);
            let quads = random_quads(3001, w * 13 + h);
            for banks in [Banks::K3, Banks::K4] {
                let bt = BankedTexture::new(&t, banks);
                let mut st = BankStats::default();
                for (i, q) in quads.iter().enumerate() {
                    let bits = |c: [Vec4; 4]| c.map(|p| p.to_array().map(f32::to_bits));
                    let (got, e) = (
                        Sampler::Span(banks).sample_quad(&t, *q),
                        bt.sample_quad(&t, *q, &mut st),
                    );
                    assert_eq!(
                        bits(got),
                        bits(e),
                        "{w}x{h} {wrap:?} {banks:?} quad {i} {q:?}: expected {e:?}, got {got:?}"
                    );
                }
                assert_eq!(st.conflicts, 0, "{w}x{h} {wrap:?} {banks:?}: {st:?}");
                interior += st.window_reads - st.edge_windows;
            }
        }
    }
    assert!(interior > 20_000, "too few interior windows: {interior}");
}

#[test]
fn bulk_span_lanes_match_the_bank_emulator_bit_for_bit() {
    // `sample_quads` (four spans per step in lanes on power-of-two pyramids, generic path for
    // edge windows, the tail and NPOT) against the bank emulator, quad by quad.
    let mut lane_spans = 0usize;
    for (w, h) in [(64, 64), (64, 16), (1, 8), (2, 2), (256, 128), (48, 20)] {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let t = ramp(w, h, wrap);
            let quads = random_quads(2001, w * 17 + h);
            for banks in [Banks::K3, Banks::K4] {
                let bt = BankedTexture::new(&t, banks);
                let mut st = BankStats::default();
                let mut out = vec![[Vec4::ZERO; 4]; quads.len()];
                Sampler::Span(banks)
                    .sample_quads(&t, &quads, &mut out)
                    .unwrap();
                for (i, q) in quads.iter().enumerate() {
                    let e = bt.sample_quad(&t, *q, &mut st);
                    for j in 0..4 {
                        assert_eq!(
                            out[i][j].to_array().map(f32::to_bits),
                            e[j].to_array().map(f32::to_bits),
                            "{w}x{h} {wrap:?} {banks:?} quad {i} pixel {j}: {q:?}: expected {}, got {}",
                            e[j],
                            out[i][j]
                        );
                    }
                }
                assert_eq!(st.conflicts, 0, "{w}x{h} {wrap:?} {banks:?}: {st:?}");
                if t.is_pow2() {
                    lane_spans += st.window_reads as usize - st.edge_windows as usize;
                }
            }
        }
    }
    assert!(
        lane_spans > 10_000,
        "too few interior windows: {lane_spans}"
    );
}

#[cfg(target_arch = "x86_64")]
#[test]
fn sse2_and_runtime_chosen_lane_builds_agree_bit_for_bit() {
    // The bulk calls above test the build chosen for this CPU (AVX2 or AVX-512); the SSE2
    // baseline build must give the same bits.
    let t = ramp(128, 64, Wrap::Repeat);
    let (uv, dx, dy) = random_pixels(4000, 99);
    let mut a = vec![Vec4::ZERO; uv.len()];
    let mut b = vec![Vec4::ZERO; uv.len()];
    let na = lanes::trilinear_pixels::<RepeatPow2>(&t, &uv, &dx, &dy, &mut a);
    let nb = lanes::trilinear_pixels_best::<RepeatPow2>(&t, &uv, &dx, &dy, &mut b);
    assert_eq!((na, nb), (4000, 4000));
    let bits = |v: &[Vec4]| {
        v.iter()
            .map(|c| c.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
    let quads: Vec<[Vec2; 4]> = (0..uv.len())
        .map(|i| quad_from_pixel(uv[i], dx[i] * 0.05, dy[i] * 0.05))
        .collect();
    let mut qa = vec![[Vec4::ZERO; 4]; quads.len()];
    let mut qb = vec![[Vec4::ZERO; 4]; quads.len()];
    lanes::span_quads4::<RepeatPow2, 3>(&t, &quads, &mut qa);
    lanes::span_quads4_best::<RepeatPow2, 3>(&t, &quads, &mut qb);
    assert_eq!(bits(qa.as_flattened()), bits(qb.as_flattened()));
}

#[cfg(target_arch = "x86_64")]
#[test]
fn avx512_lane_builds_match_the_sse2_baseline_bit_for_bit() {
    // The AVX-512 kernels (per-pixel trilinear sixteen pixels per step, four per zmm; the
    // span sampler's mspan read, K = 3) against the SSE2 baseline over every input regime of `random_pixels` /
    // `random_quads` on square, wide, tall and tiny power-of-two pyramids, both wraps (edge
    // windows included: with Repeat they are read from the level's seam strips, and the
    // count of such windows must be positive on every pyramid; with Clamp they take the
    // AVX2 edge path). Skipped where the CPU lacks AVX-512.
    if !lanes::has_avx512() {
        eprintln!("no AVX-512 on this CPU: the AVX-512 builds are not tested here");
        return;
    }
    let bits = |v: &[Vec4]| {
        v.iter()
            .map(|c| c.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    let (mut interior, mut edge) = (0u64, 0u64);
    for (w, h) in [
        (64, 64),
        (256, 64),
        (16, 128),
        (1, 8),
        (2, 2),
        (4, 4),
        (128, 128),
    ] {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            avx512::SEAM_WINDOWS.with(|n| n.set(0));
            let t = ramp(w, h, wrap);
            let (uv, dx, dy) = random_pixels(4000, w * 7 + h);
            let quads = random_quads(4000, w * 11 + h);
            let (mut a, mut b) = (vec![Vec4::ZERO; uv.len()], vec![Vec4::ZERO; uv.len()]);
            let (mut qa, mut qb) = (
                vec![[Vec4::ZERO; 4]; quads.len()],
                vec![[Vec4::ZERO; 4]; quads.len()],
            );
            macro_rules! run {
                ($A:ty) => {{
                    let na = lanes::trilinear_pixels::<$A>(&t, &uv, &dx, &dy, &mut a);
                    // SAFETY: AVX-512F/VL/BW/DQ detected above; `t` is a power of two.
                    let nb =
                        unsafe { avx512::trilinear_pixels_x16::<$A>(&t, &uv, &dx, &dy, &mut b) };
                    assert_eq!((na, nb), (4000, 4000));
                    lanes::span_quads4::<$A, 3>(&t, &quads, &mut qa);
                    // SAFETY: as above.
                    let nq = unsafe { avx512::span_quads_k3::<$A>(&t, &quads, &mut qb) };
                    assert_eq!(nq, 4000);
                    // Trilinear sixteen pixels per step likewise: the kernel alone, the
                    // chosen build (16, then the AVX2 build on the rest) and the public call
                    // (then the scalar remainder).
                    for len in [4000, 3992, 3987, 24, 17, 13, 7, 0] {
                        let same = |what: &str, n: usize, c: &[Vec4]| {
                            assert_eq!(
                                bits(&a[..n]),
                                bits(&c[..n]),
                                "trilinear {what} {w}x{h} {wrap:?} len {len}"
                            );
                        };
                        let (u, x, y) = (&uv[..len], &dx[..len], &dy[..len]);
                        let mut c = vec![Vec4::ZERO; len];
                        // SAFETY: as above.
                        let n16 =
                            unsafe { avx512::trilinear_pixels_x16::<$A>(&t, u, x, y, &mut c) };
                        assert_eq!(n16, len / 16 * 16);
                        same("x16", n16, &c);
                        let mut c = vec![Vec4::ZERO; len];
                        let nb = lanes::trilinear_pixels_best::<$A>(&t, u, x, y, &mut c);
                        assert_eq!(nb, len / 8 * 8);
                        same("best", nb, &c);
                        let mut c = vec![Vec4::ZERO; len];
                        Sampler::Trilinear
                            .sample_pixels(&t, u, x, y, &mut c)
                            .expect("same lengths");
                        same("sample_pixels", len, &c);
                    }
                    // Sixteen spans per step on scenes that are not whole groups of 16
                    // (or of 8): the kernel alone, the chosen build (16, then the
                    // 8-span kernel on the rest) and the public call (then the scalar
                    // remainder).
                    for len in [4000, 3992, 3987, 24, 17, 13, 7, 0] {
                        // The first `n` spans of `qc` against the SSE2 baseline's.
                        let same = |what: &str, n: usize, qc: &[[Vec4; 4]]| {
                            assert_eq!(
                                bits(qa[..n].as_flattened()),
                                bits(qc[..n].as_flattened()),
                                "span K3 {what} {w}x{h} {wrap:?} len {len}"
                            );
                        };
                        let mut qc = vec![[Vec4::ZERO; 4]; len];
                        // SAFETY: as above.
                        let n16 =
                            unsafe { avx512::span_quads_k3_x16::<$A>(&t, &quads[..len], &mut qc) };
                        assert_eq!(n16, len / 16 * 16);
                        same("x16", n16, &qc);
                        let mut qc = vec![[Vec4::ZERO; 4]; len];
                        let nb = lanes::span_quads4_best::<$A, 3>(&t, &quads[..len], &mut qc);
                        assert_eq!(nb, len / 8 * 8);
                        same("best", nb, &qc);
                        let mut qc = vec![[Vec4::ZERO; 4]; len];
                        Sampler::Span(Banks::K3)
                            .sample_quads(&t, &quads[..len], &mut qc)
                            .expect("same lengths");
                        same("sample_quads", len, &qc);
                    }
                }};
            }
            match wrap {
                Wrap::Repeat => run!(RepeatPow2),
                Wrap::Clamp => run!(ClampEdge),
            }
            // With Repeat the sixteen-span kernel must have read edge windows from the seam
            // strips (Clamp never does).
            let seam = avx512::SEAM_WINDOWS.with(|n| n.get());
            match wrap {
                Wrap::Repeat => assert!(seam > 1_000, "{w}x{h}: {seam} seam-strip windows"),
                Wrap::Clamp => assert_eq!(seam, 0, "{w}x{h}: Clamp read a seam strip"),
            }
            assert_eq!(bits(&a), bits(&b), "trilinear {w}x{h} {wrap:?}");
            for (i, (x, y)) in qa.iter().zip(&qb).enumerate() {
                assert_eq!(
                    bits(x),
                    bits(y),
                    "span K3 {w}x{h} {wrap:?} quad {i} {:?}",
                    quads[i]
                );
            }
            let bt = BankedTexture::new(&t, Banks::K3);
            let mut st = BankStats::default();
            for q in &quads {
                bt.sample_quad(&t, *q, &mut st);
            }
            assert_eq!(st.conflicts, 0);
            interior += st.window_reads - st.edge_windows;
            edge += st.edge_windows;
        }
    }
    assert!(interior > 10_000, "too few interior windows: {interior}");
    assert!(edge > 1_000, "too few edge windows: {edge}");
}

#[test]
fn trilinear_quad_lanes_match_per_pixel_sampling_bit_for_bit() {
    // `sample_quad` (trilinear in lanes on pow2) against four `sample` calls with the quad's
    // coarse derivatives.
    for wrap in [Wrap::Repeat, Wrap::Clamp] {
        let t = ramp(64, 32, wrap);
        let (uv, dx, dy) = random_pixels(3000, 5);
        for i in 0..uv.len() {
            let q = quad_from_pixel(uv[i], dx[i], dy[i]);
            let got = Sampler::Trilinear.sample_quad(&t, q);
            for j in 0..4 {
                let e = Sampler::Trilinear.sample(&t, q[j], q[1] - q[0], q[2] - q[0]);
                assert_eq!(
                    got[j].to_array().map(f32::to_bits),
                    e.to_array().map(f32::to_bits),
                    "{wrap:?} quad {i} pixel {j}: expected {e}, got {}",
                    got[j]
                );
            }
        }
    }
}

#[test]
fn span_fast_path_matches_bank_emulator_bit_for_bit() {
    // `sample_quad` (one span per call: the AVX2 kernel on CPUs that have it, else the fused
    // scalar path) against the emulator, on power-of-two and NPOT sizes, both wrap modes.
    let mut interior = 0u64;
    for (w, h, wrap) in [
        (64, 32, Wrap::Repeat),
        (64, 32, Wrap::Clamp),
        (48, 20, Wrap::Repeat),
        (48, 20, Wrap::Clamp),
    ] {
        let t = ramp(w, h, wrap);
        interior += span_fast_path_case(&t);
    }
    assert!(interior > 10_000, "too few interior windows: {interior}");
}

/// One texture of [`span_fast_path_matches_bank_emulator_bit_for_bit`]; returns the number
/// of interior window reads.
fn span_fast_path_case(t: &MipTexture) -> u64 {
    let t = t.clone();
    let mut interior = 0;
    for banks in [Banks::K3, Banks::K4] {
        let bt = BankedTexture::new(&t, banks);
        let mut st = BankStats::default();
        let mut rng = 0x1234_5678u32;
        let mut r = || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            rng as f32 / u32::MAX as f32
        };
        for _ in 0..2000 {
            let p = Vec2::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0);
            let dx = Vec2::new(r() - 0.5, r() - 0.5) * 0.2 * r();
            let dy = Vec2::new(r() - 0.5, r() - 0.5) * 0.2 * r();
            let q = [p, p + dx, p + dy, p + dx + dy];
            let a = Sampler::Span(banks).sample_quad(&t, q);
            let b = bt.sample_quad(&t, q, &mut st);
            for j in 0..4 {
                assert_eq!(
                    a[j].to_array().map(f32::to_bits),
                    b[j].to_array().map(f32::to_bits),
                    "{banks:?} {:?} quad {q:?} pixel {j}: expected {}, got {}",
                    t.wrap(),
                    b[j],
                    a[j]
                );
            }
        }
        assert_eq!(st.conflicts, 0, "{banks:?}: {st:?}");
        interior += st.window_reads - st.edge_windows;
    }
    interior
}
