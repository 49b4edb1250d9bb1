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
            Sampler::Quadratic3,
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

/// A pyramid of random texels in [0, 1] (the quadratic sampler's clamp then rarely bites).
fn noise(w: u32, h: u32, wrap: Wrap, seed: u32) -> MipTexture {
    let mut rng = seed | 1;
    let mut r = move || {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        (rng >> 8) as f32 / (1u32 << 24) as f32
    };
    let data: Vec<Vec4> = (0..w * h).map(|_| Vec4::new(r(), r(), r(), 1.0)).collect();
    MipTexture::from_linear(w, h, &data, Reduction::GammaCorrect, wrap).unwrap()
}

/// The quadratic 3x3 sampler as the flight study first wrote it (scalar, texels through
/// [`MipTexture::texel`], which wraps by the texture's mode, `f32::round` for the nearest
/// texel), with the level pair and blend weight taken from trilinear's `log2_split`.
fn quadratic_study(tex: &MipTexture, uv: Vec2, dx: Vec2, dy: Vec2) -> Vec4 {
    let level = |level: usize| {
        let l = &tex.levels()[level];
        let t = Vec2::new(uv.x * l.width_f - 0.5, uv.y * l.height_f - 0.5);
        let c = t.round().clamp(Vec2::splat(-1e9), Vec2::splat(1e9));
        let d = t - c;
        let w = |d: f32| [0.5 * d * (d - 1.0), 1.0 - d * d, 0.5 * d * (d + 1.0)];
        let (wx, wy) = (w(d.x), w(d.y));
        let (cx, cy) = (c.x as i64, c.y as i64);
        let mut sum = Vec4::ZERO;
        for (j, wyj) in wy.iter().enumerate() {
            let mut row = Vec4::ZERO;
            for (i, wxi) in wx.iter().enumerate() {
                let texel = tex
                    .texel(level, cx + i as i64 - 1, cy + j as i64 - 1)
                    .unwrap();
                row += texel * *wxi;
            }
            sum += row * *wyj;
        }
        sum.clamp(Vec4::ZERO, Vec4::ONE)
    };
    let l0 = &tex.levels()[0];
    let size = Vec2::new(l0.width_f, l0.height_f);
    let m = (dx * size).abs().max((dy * size).abs()).max_element();
    let last = tex.level_count() - 1;
    if m.is_nan() || m <= 1.0 {
        return level(0);
    }
    let (i, f) = log2_split(m);
    let i = i as usize;
    if i >= last {
        return level(last);
    }
    let (a, b) = (level(i), level(i + 1));
    a + (b - a) * f
}

#[test]
fn quadratic3_matches_the_study_formulation() {
    // Random uv and derivatives (finite), both wrap modes, power-of-two and NPOT pyramids: the
    // sampler against the study's scalar formulation with trilinear's log2; every regime
    // (magnified, blended pair, past the top) reached.
    let (mut blended, mut magnified, mut top) = (0, 0, 0);
    let mut same_bits = 0usize;
    let mut total = 0usize;
    for (w, h) in [(64, 64), (64, 16), (48, 20), (17, 9), (1, 8)] {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let t = noise(w, h, wrap, w * 7 + h);
            let (uv, dx, dy) = random_pixels(4000, w * 3 + h);
            for i in 0..uv.len() {
                // The study clamped its texel coordinate at ±1e9, the sampler at ±2^30: compare
                // where neither clamps (NaN and huge inputs are tested elsewhere).
                if !(uv[i].abs().max_element() < 1e4 && dx[i].is_finite() && dy[i].is_finite()) {
                    continue;
                }
                let got = Sampler::Quadratic3.sample(&t, uv[i], dx[i], dy[i]);
                let e = quadratic_study(&t, uv[i], dx[i], dy[i]);
                assert!(
                    (got - e).abs().max_element() <= 1e-6,
                    "{w}x{h} {wrap:?} pixel {i}: uv {} dx {} dy {}: expected {e}, got {got}",
                    uv[i],
                    dx[i],
                    dy[i],
                );
                same_bits +=
                    (got.to_array().map(f32::to_bits) == e.to_array().map(f32::to_bits)) as usize;
                total += 1;
                let m = footprint(&t.levels()[0], dx[i], dy[i]);
                if m <= 1.0 {
                    magnified += 1;
                } else if log2_split(m).0 as usize >= t.level_count() - 1 {
                    top += 1;
                } else {
                    blended += 1;
                }
            }
        }
    }
    assert!(
        blended > 1000 && magnified > 1000 && top > 1000,
        "{blended} {magnified} {top}"
    );
    assert_eq!(same_bits, total, "bit-identical on {same_bits} of {total}");
}

#[test]
fn quadratic3_reproduces_a_quadratic_and_clamps() {
    // Magnified (level 0 alone): a texture quadratic in x is reproduced exactly between its
    // edges, where bilinear is not; a texture with a spike overshoots and is clamped to [0, 1].
    let w = 16u32;
    let f = |x: f32| 0.002 * x * x + 0.01 * x + 0.1;
    let data: Vec<Vec4> = (0..w * w).map(|i| Vec4::splat(f((i % w) as f32))).collect();
    let t = MipTexture::from_linear(w, w, &data, Reduction::Box, Wrap::Clamp).unwrap();
    let tiny = Vec2::splat(1e-3);
    let (mut worst_q, mut worst_b) = (0f32, 0f32);
    for k in 0..100 {
        let x = 2.0 + 0.11 * k as f32;
        let uv = Vec2::new((x + 0.5) / w as f32, 0.5);
        let q = Sampler::Quadratic3.sample(&t, uv, tiny, tiny).x;
        worst_q = worst_q.max((q - f(x)).abs());
        let b = Sampler::Bilinear.sample(&t, uv, tiny, tiny).x;
        worst_b = worst_b.max((b - f(x)).abs());
    }
    assert!(worst_q < 1e-5, "quadratic {worst_q}");
    assert!(worst_b > 1e-4, "bilinear {worst_b}");
    // A single bright texel among zeros: the negative lobes next to it would go below 0.
    let mut data = vec![Vec4::ZERO; 64];
    data[3 * 8 + 3] = Vec4::ONE;
    let t = MipTexture::from_linear(8, 8, &data, Reduction::Box, Wrap::Repeat).unwrap();
    // Nearest texel (4, 3), 0.3 texels right of it: the x weight of texel 3 is ½d(d − 1) < 0.
    let uv = Vec2::new((4.3 + 0.5) / 8.0, 3.5 / 8.0);
    let got = Sampler::Quadratic3.sample(&t, uv, Vec2::ZERO, Vec2::ZERO);
    assert_eq!(got, Vec4::ZERO, "clamped at 0");
    // 0.3 texels left of the bright texel's centre: its weights are 1 − d² along x, 1 along y.
    let uv = Vec2::new((2.7 + 0.5) / 8.0, 3.5 / 8.0);
    let got = Sampler::Quadratic3.sample(&t, uv, Vec2::ZERO, Vec2::ZERO).x;
    let d: f32 = 2.7 - 3.0;
    assert!((got - (1.0 - d * d)).abs() < 1e-6, "{got}");
}

#[test]
fn quadratic3_quad_lanes_match_per_pixel_sampling_bit_for_bit() {
    // `sample_quad` and `sample_quads` (the quad kernel in lanes) against four `sample` calls
    // with the quad's coarse derivatives: every regime of `random_quads`, interior and wrapped
    // neighbourhoods, power-of-two and NPOT pyramids, both wrap modes.
    let mut blended = 0;
    for (w, h) in [(64, 64), (64, 16), (16, 128), (48, 20), (1, 8), (2, 2)] {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let t = noise(w, h, wrap, w + 5 * h);
            let quads = random_quads(3001, w * 11 + h);
            let mut bulk = vec![[Vec4::ZERO; 4]; quads.len()];
            Sampler::Quadratic3
                .sample_quads(&t, &quads, &mut bulk)
                .unwrap();
            for (i, q) in quads.iter().enumerate() {
                let got = Sampler::Quadratic3.sample_quad(&t, *q);
                let (dx, dy) = (q[1] - q[0], q[2] - q[0]);
                for j in 0..4 {
                    let e = Sampler::Quadratic3.sample(&t, q[j], dx, dy);
                    assert!(e.is_finite(), "{w}x{h} {wrap:?} quad {i}: {e}");
                    for (what, g) in [("sample_quad", got[j]), ("sample_quads", bulk[i][j])] {
                        assert_eq!(
                            g.to_array().map(f32::to_bits),
                            e.to_array().map(f32::to_bits),
                            "{what} {w}x{h} {wrap:?} quad {i} {q:?} pixel {j}: expected {e}, got {g}",
                        );
                    }
                }
                let m = footprint(&t.levels()[0], dx, dy);
                blended += (m > 1.0 && m.log2() < (t.level_count() - 1) as f32) as usize;
            }
        }
    }
    assert!(blended > 1000, "{blended} quads blended two levels");
}
