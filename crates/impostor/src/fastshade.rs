//! [`Lighting::shade`] without library calls: the same formula with a polynomial `pow`.
//!
//! Shading is a third of the ray-cast time with `powf` from libm (measured on S2, one thread:
//! `Lighting::shade` 17% + `powf` 14%). [`shade`] evaluates the identical ambient + Lambert +
//! Blinn-Phong sum, only `x^e` becomes `exp2(e·log2 x)` with the two polynomials below; a unit
//! test bounds the difference from [`Lighting::shade`] (≤ 2e-5 absolute on random inputs, far
//! under half an 8-bit sRGB step).
//!
//! **Lanes.** [`shade_lanes`] and the ray-cast kernels are written once over [`Simd8`], eight
//! `f32` lanes with two backends: [`V8`] (two SSE2 registers, the x86-64 baseline, or a plain
//! array elsewhere) and `V8x` (one AVX2 register, x86-64 only, chosen at run time with
//! `is_x86_feature_detected!` and compiled inside `#[target_feature(enable = "avx2")]`
//! functions). Both perform the same IEEE single operations in the same order — no FMA — so
//! they give the same bits; a test renders a busy scene with both and compares the bytes. The
//! trait also carries the two steps that make the resolve pass cheap: an 8x8 transpose (the
//! winners' 32-byte records and material rows loaded whole, then turned into lanes) and the
//! sRGB encode over lanes (AVX2 gathers from a `u32` copy of the table).

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

use glam::Vec3;
use texmap_core::color::linear_to_srgb8_fast;
use texmap_core::shade::{Lighting, MAX_LIGHTS, Material};

/// `log2(x)` for finite `x > 0` (absolute error ≲ 1e-7 on normal numbers).
#[inline(always)]
fn log2_fast(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    // Mantissa in [1, 2), then moved to [1/√2, √2) so that u = (m − 1)/(m + 1) stays ≤ 0.172.
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    if m > std::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let u = (m - 1.0) / (m + 1.0);
    let u2 = u * u;
    // ln m = 2 (u + u³/3 + u⁵/5 + u⁷/7 + …); the next term is below 1e-7.
    let p = u * (2.0 + u2 * (2.0 / 3.0 + u2 * (2.0 / 5.0 + u2 * (2.0 / 7.0))));
    e as f32 + p * std::f32::consts::LOG2_E
}

/// `2^z` for `z ≤ 0` (relative error ≲ 3e-7; 0 below 2^−126).
#[inline(always)]
fn exp2_neg(z: f32) -> f32 {
    if !(z > -126.0) {
        return 0.0;
    }
    // floor without a libm call (no SSE4.1 `roundps` in the portable baseline).
    let mut i = z as i32;
    if (i as f32) > z {
        i -= 1;
    }
    let i = i as f32;
    // 2^f = √2 · e^{g}, g = (f − 1/2)·ln 2 ∈ [−0.347, 0.347]: Taylor to g⁶.
    let g = (z - i - 0.5) * std::f32::consts::LN_2;
    let p = 1.0
        + g * (1.0
            + g * (0.5
                + g * (1.0 / 6.0 + g * (1.0 / 24.0 + g * (1.0 / 120.0 + g * (1.0 / 720.0))))));
    let scale = f32::from_bits(((i as i32 + 127) as u32) << 23);
    p * std::f32::consts::SQRT_2 * scale
}

/// `x^e` for `x ∈ [0, 1]`, `e > 0`.
#[inline(always)]
pub(crate) fn pow01(x: f32, e: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    exp2_neg((e * log2_fast(x)).min(0.0))
}

/// [`Lighting::shade`] with [`pow01`]: same inputs, same formula.
#[inline]
pub(crate) fn shade(l: &Lighting, m: &Material, n: Vec3, v: Vec3) -> Vec3 {
    let mut c = l.ambient * m.base_color;
    for light in l.lights() {
        let ndl = n.dot(light.to_light);
        if ndl > 0.0 {
            let mut term = m.base_color * ndl;
            if m.specular > 0.0 {
                let h = light.to_light + v;
                let hh = h.length_squared();
                if hh > 0.0 {
                    let ndh = (n.dot(h) / hh.sqrt()).clamp(0.0, 1.0);
                    term += Vec3::splat(m.specular * pow01(ndh, m.shininess));
                }
            }
            c += light.color * term;
        }
    }
    c
}

/// Lane width of [`shade8`].
pub(crate) const W: usize = 8;
pub(crate) type F8 = [f32; W];

/// Branch-free [`log2_fast`] over 8 lanes (inputs > 0; the caller masks the rest).
#[inline(always)]
fn log2_8(x: &F8) -> F8 {
    let mut out = [0.0; W];
    for l in 0..W {
        let bits = x[l].to_bits();
        let e = ((bits >> 23) & 0xff) as i32 - 127;
        let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
        let big = m > std::f32::consts::SQRT_2;
        let m = if big { m * 0.5 } else { m };
        let e = (e + big as i32) as f32;
        let u = (m - 1.0) / (m + 1.0);
        let u2 = u * u;
        let p = u * (2.0 + u2 * (2.0 / 3.0 + u2 * (2.0 / 5.0 + u2 * (2.0 / 7.0))));
        out[l] = e + p * std::f32::consts::LOG2_E;
    }
    out
}

/// Branch-free [`exp2_neg`] over 8 lanes (`z ≤ 0`; 0 below 2^−126).
#[inline(always)]
fn exp2_neg8(z: &F8) -> F8 {
    let mut out = [0.0; W];
    for l in 0..W {
        let zl = if z[l] > -126.0 { z[l] } else { -126.0 };
        let zl = if zl < 0.0 { zl } else { 0.0 };
        // SAFETY: zl ∈ [−126, 0] (NaN was replaced by −126 above), so the conversion is exact
        // truncation; unlike `as i32` it needs no saturation code and vectorises.
        let ti = unsafe { zl.to_int_unchecked::<i32>() };
        let i = ti - ((ti as f32) > zl) as i32;
        let g = (zl - i as f32 - 0.5) * std::f32::consts::LN_2;
        let p = 1.0
            + g * (1.0
                + g * (0.5
                    + g * (1.0 / 6.0 + g * (1.0 / 24.0 + g * (1.0 / 120.0 + g * (1.0 / 720.0))))));
        let scale = f32::from_bits(((i + 127) as u32) << 23);
        let v = p * std::f32::consts::SQRT_2 * scale;
        out[l] = if z[l] > -126.0 { v } else { 0.0 };
    }
    out
}

/// Largest exponent [`pow_int8`] takes (16 squarings).
const MAX_INT_EXPONENT: f32 = 65_535.0;

/// How [`shade_lanes`] takes the specular power `x^e` of 8 lanes, chosen once per chunk (or
/// once per frame when every material has the same shininess).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum SpecPow {
    /// All 8 exponents are the same integer `k < 2^bits`: squarings, bit tests on a scalar.
    /// Bases below `floor` ([`pow_floor`] of `bits`) give 0.
    Same { k: u32, bits: u32, floor: f32 },
    /// Every exponent is an integer below `2^bits`: squarings, bit tests over lanes. Bases
    /// below their lane's `floor` ([`pow_floor`] of the lane's bit length) give 0.
    Ints {
        e: [u32; W],
        bits: u32,
        floor: [f32; W],
    },
    /// Otherwise: `exp2(e·log2 x)` with the polynomials.
    Poly,
}

/// The [`SpecPow`] of 8 exponents: integers in `[0, MAX_INT_EXPONENT]` are taken by squaring.
#[inline(always)]
fn spec_pow(e: &F8) -> SpecPow {
    let mut ei = [0u32; W];
    let mut ok = true;
    let mut any = 0u32;
    for i in 0..W {
        let x = e[i];
        let in_range = (0.0..=MAX_INT_EXPONENT).contains(&x);
        let xc = if in_range { x } else { 0.0 };
        // SAFETY: xc ∈ [0, 65535], so truncation is exact and in range.
        let n = unsafe { xc.to_int_unchecked::<i32>() } as u32;
        ok &= in_range && n as f32 == x;
        ei[i] = n;
        any |= n;
    }
    let bit_len = |k: u32| u32::BITS - k.leading_zeros();
    let bits = bit_len(any);
    let floors = pow_floors();
    if !ok {
        SpecPow::Poly
    } else if ei.iter().all(|&k| k == ei[0]) {
        let floor = floors[bits as usize];
        SpecPow::Same {
            k: ei[0],
            bits,
            floor,
        }
    } else {
        let floor = ei.map(|k| floors[bit_len(k) as usize]);
        SpecPow::Ints { e: ei, bits, floor }
    }
}

/// `pow_floors()[b]`: the smallest base [`pow_int8`] raises to an exponent `e` of bit length
/// `b` (`2^(b−1) ≤ e < 2^b`); smaller bases give 0. It is `2^(−120/2^b)` (0 for `b = 0`), so
/// every product of the squarings of a base at or above it stays at or above
/// `floor^(2^b) = 2^−120`: a normal number. Without it, a base below ~0.2 raised to 40
/// underflows into subnormal numbers, and every multiply producing one takes a microcode
/// assist of ~100+ cycles (measured: a quarter of an S1 ray-cast frame). What it drops is a
/// power below `floor^(2^(b−1)) = 2^−60`, invisible in any colour. The values are `2^−120`
/// square-rooted `b` times in `f32` (correctly rounded everywhere: the same on every backend).
fn pow_floors() -> &'static [f32; 17] {
    static T: OnceLock<[f32; 17]> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = [0f32; 17];
        let mut f = f32::from_bits((127 - 120) << 23);
        for v in t.iter_mut().skip(1) {
            f = f.sqrt();
            *v = f;
        }
        t
    })
}

/// The [`SpecPow`] of the exponents in the lanes of `shin`.
#[inline(always)]
pub(crate) fn spec_pow_of<V: Simd8>(shin: V) -> SpecPow {
    let mut e = [0f32; W];
    shin.store_to(&mut e);
    spec_pow(&e)
}

/// `x^e` by repeated squaring over 8 lanes (`x ∈ [0, 1]`, integer exponents below `2^bits`):
/// at most `2·bits` rounded products; each squaring doubles the relative error it is given, so
/// the power is within ~`e·2^−24` of exact (tested). Bases below the floor of [`pow_floors`]
/// give 0. `Same` and `Ints` perform the same products, so they give the same bits.
///
/// `N` powers (one per light) are taken in one loop: the loop control is shared and the `N`
/// dependency chains of squarings overlap. Every power sees the same products as alone.
#[inline(always)]
fn pow_int8<V: Simd8, const N: usize>(x: [V; N], pw: &SpecPow) -> [V; N] {
    let mut acc = [V::splat(1.0); N];
    let zero = V::splat(0.0);
    // Bases below the floor become 0 (no subnormal products; see `pow_floors`).
    let floor = match pw {
        SpecPow::Same { floor, .. } => V::splat(*floor),
        SpecPow::Ints { floor, .. } => V::load_from(floor),
        SpecPow::Poly => unreachable!("pow_int8 takes integer exponents"),
    };
    // (A loop, not `map`: closures do not inherit the caller's `#[target_feature]`s.)
    let mut p = x;
    for p in &mut p {
        *p = V::select(p.ge(floor), *p, zero);
    }
    match *pw {
        SpecPow::Same { mut k, .. } => {
            // The same products as the `Ints` loop (its last squaring is never used).
            while k != 0 {
                if k & 1 != 0 {
                    for n in 0..N {
                        acc[n] = acc[n] * p[n];
                    }
                }
                k >>= 1;
                if k != 0 {
                    for p in &mut p {
                        *p = *p * *p;
                    }
                }
            }
        }
        SpecPow::Ints { ref e, bits, .. } => {
            for b in 0..bits {
                let m = V::bit_set(e, b);
                for n in 0..N {
                    acc[n] = V::select(m, acc[n] * p[n], acc[n]);
                    p[n] = p[n] * p[n];
                }
            }
        }
        SpecPow::Poly => unreachable!("pow_int8 takes integer exponents"),
    }
    acc
}

/// sRGB encode table: exactly [`linear_to_srgb8_fast`]'s (entry `i` is its
/// code at the centre of bin `i`, which lies in bin `i`), kept here so that the lane encoder
/// reads it without a lazy-initialisation check per channel.
pub(crate) fn srgb_table() -> &'static [u8; SRGB_N] {
    static T: OnceLock<[u8; SRGB_N]> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = [0u8; SRGB_N];
        for (i, v) in t.iter_mut().enumerate() {
            *v = linear_to_srgb8_fast((i as f32 + 0.5) / SRGB_N as f32);
        }
        t
    })
}

/// [`srgb_table`] widened to `u32` entries, for gathers over lanes.
pub(crate) fn srgb_table32() -> &'static [u32; SRGB_N] {
    static T: OnceLock<[u32; SRGB_N]> = OnceLock::new();
    T.get_or_init(|| srgb_table().map(u32::from))
}

/// Entries of [`srgb_table`] (texmap-core's encoder uses 2^12 bins).
pub(crate) const SRGB_N: usize = 4096;

/// sRGB8 RGBA of 8 linear colours, as little-endian `u32` lanes (alpha 255): table indices
/// `floor(c·4096)` clamped to `[0, 4095]`, NaN → 0, exactly as [`linear_to_srgb8_fast`]
/// computes them, then [`srgb_table32`] lookups.
#[inline(always)]
pub(crate) fn srgb_rgba_lanes<V: Simd8>(r: V, g: V, b: V, table: &[u32; SRGB_N]) -> V {
    let q = |c: V| {
        let x = c * V::splat(SRGB_N as f32);
        // `max` first: NaN lanes become 0 (SSE `max(NaN, 0)` returns the second operand).
        x.max(V::splat(0.0)).min(V::splat((SRGB_N - 1) as f32))
    };
    V::srgb_pack(q(r), q(g), q(b), table)
}

/// Surface and material of 8 pixels, structure-of-arrays.
#[derive(Clone, Copy, Debug, Default)]
#[cfg_attr(not(test), allow(dead_code))] // the SoA form of the tests (and of the bond pass)
pub(crate) struct Surf8 {
    pub n: [F8; 3],
    pub v: [F8; 3],
    pub base: [F8; 3],
    pub spec: F8,
    pub shin: F8,
}

/// [`shade`] over 8 lanes: the same formula, masks instead of branches, on [`V8`] lanes.
#[inline(always)]
#[cfg_attr(not(test), allow(dead_code))] // as `Surf8`
pub(crate) fn shade8(l: &Lighting, s: &Surf8) -> [F8; 3] {
    let ld = |a: &[F8; 3]| [V8::load(&a[0]), V8::load(&a[1]), V8::load(&a[2])];
    let c = shade_lanes(
        l,
        ld(&s.n),
        ld(&s.v),
        ld(&s.base),
        V8::load(&s.spec),
        V8::load(&s.shin),
        spec_pow(&s.shin),
    );
    [c[0].store(), c[1].store(), c[2].store()]
}

/// [`shade`] over 8 lanes of any [`Simd8`] backend: the same formula, masks instead of
/// branches. `pw` is [`spec_pow_of`]`(shin)` (the caller may know it for the whole frame):
/// integer exponents are taken by squaring (exact to a few ulp, and cheaper), others by
/// exp2(e·log2 x). Every backend performs the same IEEE operations in the same
/// order, so all give the same bits.
#[inline(always)]
pub(crate) fn shade_lanes<V: Simd8>(
    l: &Lighting,
    n: [V; 3],
    v: [V; 3],
    base: [V; 3],
    spec_k: V,
    shin: V,
    pw: SpecPow,
) -> [V; 3] {
    let a = (n, v, base, spec_k, shin, pw);
    // The build for this light count (the same operations as one generic loop).
    macro_rules! with {
        ($n:literal) => {
            shade_lanes_n(
                &LanesLighting::<V, $n>::new(l),
                a.0,
                a.1,
                a.2,
                a.3,
                a.4,
                a.5,
            )
        };
    }
    const { assert!(MAX_LIGHTS == 4) };
    match l.lights().len() {
        0 => with!(0),
        1 => with!(1),
        2 => with!(2),
        3 => with!(3),
        _ => with!(4),
    }
}

/// A [`Lighting`] with exactly `N` lights, its constants splat into lanes once (per tile) for
/// [`shade_lanes_n`].
#[derive(Clone, Copy)]
pub(crate) struct LanesLighting<V, const N: usize> {
    ambient: [V; 3],
    dir: [[V; 3]; N],
    color: [[V; 3]; N],
}

impl<V: Simd8, const N: usize> LanesLighting<V, N> {
    /// `l`'s constants as lanes (`l` must have `N` lights).
    #[inline(always)]
    pub(crate) fn new(l: &Lighting) -> Self {
        debug_assert_eq!(l.lights().len(), N);
        let v3 = |a: Vec3| [V::splat(a.x), V::splat(a.y), V::splat(a.z)];
        LanesLighting {
            ambient: v3(l.ambient),
            dir: std::array::from_fn(|i| v3(l.lights()[i].to_light)),
            color: std::array::from_fn(|i| v3(l.lights()[i].color)),
        }
    }
}

/// The body of [`shade_lanes`] for a lighting of `N` lights known at compile time: the light
/// loops unroll, and a caller that shades many chunks (the ray-cast resolve) makes `l` once per
/// tile, so the lights' constants stay in registers instead of being splat per chunk. Lights
/// are taken two at a time (their specular powers share one squaring loop, see `pow_int8`) and
/// their terms added in the lights' order.
#[inline(always)]
pub(crate) fn shade_lanes_n<V: Simd8, const N: usize>(
    l: &LanesLighting<V, N>,
    n: [V; 3],
    v: [V; 3],
    base: [V; 3],
    spec_k: V,
    shin: V,
    pw: SpecPow,
) -> [V; 3] {
    let s = LaneSurf {
        n,
        v,
        base,
        spec: spec_k,
        shin,
    };
    shade_chunks(l, [s], pw)[0]
}

/// The shading inputs of one 8-lane chunk for [`shade_chunks`].
#[derive(Clone, Copy)]
pub(crate) struct LaneSurf<V> {
    /// Unit normal.
    pub n: [V; 3],
    /// Unit vector toward the eye.
    pub v: [V; 3],
    /// Base colour.
    pub base: [V; 3],
    /// Specular coefficient.
    pub spec: V,
    /// Shininess (read only when `pw` is [`SpecPow::Poly`]).
    pub shin: V,
}

/// [`shade_lanes_n`] for `C` chunks at once (`C` ≤ 2) that share one [`SpecPow`]: every lane
/// sees exactly the operations it would alone, but the chunks' dependency chains (square
/// roots, divisions, the squarings of one shared loop) are interleaved in one straight-line
/// body, so the CPU overlaps them instead of waiting out one chunk's latency at a time.
#[inline(always)]
pub(crate) fn shade_chunks<V: Simd8, const N: usize, const C: usize>(
    l: &LanesLighting<V, N>,
    s: [LaneSurf<V>; C],
    pw: SpecPow,
) -> [[V; 3]; C] {
    const { assert!(C == 1 || C == 2) };
    // `Ints` holds exponents per lane: one chunk's.
    debug_assert!(C == 1 || !matches!(pw, SpecPow::Ints { .. }));
    let mut c: [[V; 3]; C] = std::array::from_fn(|j| {
        let b = s[j].base;
        [
            b[0] * l.ambient[0],
            b[1] * l.ambient[1],
            b[2] * l.ambient[2],
        ]
    });
    let zero = V::splat(0.0);
    let tiny = V::splat(1e-30);
    let mut p = 0;
    while p < N {
        let m = (N - p).min(2);
        let mut ndl = [[zero; 2]; C];
        let mut ndh = [[zero; 2]; C];
        let mut pos = [[zero.lt(zero); 2]; C];
        for i in 0..m {
            let [ax, ay, az] = l.dir[p + i];
            for j in 0..C {
                let (n, v) = (s[j].n, s[j].v);
                ndl[j][i] = n[0] * ax + n[1] * ay + n[2] * az;
                let hx = ax + v[0];
                let hy = ay + v[1];
                let hz = az + v[2];
                let hh = hx * hx + hy * hy + hz * hz;
                let nh = n[0] * hx + n[1] * hy + n[2] * hz;
                let q = nh / hh.sqrt();
                pos[j][i] = q.gt(tiny);
                ndh[j][i] = V::select(pos[j][i], q.min(V::splat(1.0)), tiny);
            }
        }
        // The powers of all chunks and lights in one squaring loop.
        let mut pw2 = [[zero; 2]; C];
        match pw {
            SpecPow::Poly => {
                for j in 0..C {
                    for i in 0..m {
                        pw2[j][i] = pow_poly8(ndh[j][i], s[j].shin);
                    }
                }
            }
            _ => match (C, m) {
                (1, 1) => pw2[0][0] = pow_int8([ndh[0][0]], &pw)[0],
                (1, _) => pw2[0] = pow_int8(ndh[0], &pw),
                (_, 1) => {
                    let r = pow_int8([ndh[0][0], ndh[C - 1][0]], &pw);
                    (pw2[0][0], pw2[C - 1][0]) = (r[0], r[1]);
                }
                _ => {
                    let r = pow_int8([ndh[0][0], ndh[0][1], ndh[C - 1][0], ndh[C - 1][1]], &pw);
                    (pw2[0], pw2[C - 1]) = ([r[0], r[1]], [r[2], r[3]]);
                }
            },
        }
        for i in 0..m {
            for j in 0..C {
                let spec = V::select(pos[j][i], s[j].spec * pw2[j][i], zero);
                let lit = ndl[j][i].gt(zero);
                for k in 0..3 {
                    let term = s[j].base[k] * ndl[j][i] + spec;
                    c[j][k] = c[j][k] + V::select(lit, l.color[p + i][k] * term, zero);
                }
            }
        }
        p += 2;
    }
    c
}

/// `x^e = exp2(e·log2 x)` over 8 lanes with the polynomials (`x ∈ (0, 1]`, any `e ≥ 0`).
#[inline(always)]
fn pow_poly8<V: Simd8>(x: V, shin: V) -> V {
    let mut a = [0f32; W];
    x.store_to(&mut a);
    let lg = V::load_from(&log2_8(&a));
    let z = (shin * lg).min(V::splat(0.0));
    z.store_to(&mut a);
    V::load_from(&exp2_neg8(&a))
}

/// Eight `f32` lanes: two SSE registers on x86-64 (SSE2 is part of the x86-64 baseline, so no
/// run-time detection is needed), a plain array elsewhere. Every operation is an IEEE single
/// operation per lane (no fused multiply-add), so both forms give bit-identical results.
/// `min`/`max`/`select` follow SSE semantics: `a.min(b) = if a < b { a } else { b }`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct V8(lanes::Repr);

/// A lane mask from a comparison of [`V8`]s (all bits set where true).
#[derive(Clone, Copy, Debug)]
pub(crate) struct M8(lanes::Repr);

#[cfg(target_arch = "x86_64")]
mod lanes {
    use std::arch::x86_64::*;
    pub type Repr = [__m128; 2];

    // SAFETY (whole module): SSE and SSE2 are enabled on every x86-64 target, so these
    // intrinsics are always available; the loads and stores take references to 8 floats.
    #[inline(always)]
    pub fn splat(x: f32) -> Repr {
        unsafe { [_mm_set1_ps(x), _mm_set1_ps(x)] }
    }
    #[inline(always)]
    pub fn load(a: &[f32; 8]) -> Repr {
        unsafe { [_mm_loadu_ps(a.as_ptr()), _mm_loadu_ps(a.as_ptr().add(4))] }
    }
    #[inline(always)]
    pub fn store(r: Repr) -> [f32; 8] {
        let mut out = [0f32; 8];
        unsafe {
            _mm_storeu_ps(out.as_mut_ptr(), r[0]);
            _mm_storeu_ps(out.as_mut_ptr().add(4), r[1]);
        }
        out
    }
    macro_rules! bin {
        ($name:ident, $op:ident) => {
            #[inline(always)]
            pub fn $name(a: Repr, b: Repr) -> Repr {
                unsafe { [$op(a[0], b[0]), $op(a[1], b[1])] }
            }
        };
    }
    bin!(add, _mm_add_ps);
    bin!(sub, _mm_sub_ps);
    bin!(mul, _mm_mul_ps);
    bin!(div, _mm_div_ps);
    bin!(min, _mm_min_ps);
    bin!(max, _mm_max_ps);
    bin!(lt, _mm_cmplt_ps);
    bin!(gt, _mm_cmpgt_ps);
    bin!(and, _mm_and_ps);
    #[inline(always)]
    pub fn sqrt(a: Repr) -> Repr {
        unsafe { [_mm_sqrt_ps(a[0]), _mm_sqrt_ps(a[1])] }
    }
    #[inline(always)]
    pub fn select(m: Repr, a: Repr, b: Repr) -> Repr {
        unsafe {
            [
                _mm_or_ps(_mm_and_ps(m[0], a[0]), _mm_andnot_ps(m[0], b[0])),
                _mm_or_ps(_mm_and_ps(m[1], a[1]), _mm_andnot_ps(m[1], b[1])),
            ]
        }
    }
    #[inline(always)]
    pub fn bits(m: Repr) -> u32 {
        unsafe { (_mm_movemask_ps(m[0]) | (_mm_movemask_ps(m[1]) << 4)) as u32 }
    }
    /// Lanes whose `u32` in `e` has bit `b` set.
    #[inline(always)]
    pub fn bit_set(e: &[u32; 8], b: u32) -> Repr {
        unsafe {
            let one = _mm_set1_epi32(1);
            let cnt = _mm_cvtsi32_si128(b as i32);
            let lo = _mm_loadu_si128(e.as_ptr() as *const __m128i);
            let hi = _mm_loadu_si128(e.as_ptr().add(4) as *const __m128i);
            let t0 = _mm_and_si128(_mm_srl_epi32(lo, cnt), one);
            let t1 = _mm_and_si128(_mm_srl_epi32(hi, cnt), one);
            [
                _mm_castsi128_ps(_mm_cmpeq_epi32(t0, one)),
                _mm_castsi128_ps(_mm_cmpeq_epi32(t1, one)),
            ]
        }
    }
    /// Truncate lanes known to lie in `[0, 2^31)` to integers.
    #[inline(always)]
    pub fn trunc_u32(a: Repr) -> [u32; 8] {
        let mut out = [0u32; 8];
        unsafe {
            _mm_storeu_si128(out.as_mut_ptr() as *mut __m128i, _mm_cvttps_epi32(a[0]));
            _mm_storeu_si128(
                out.as_mut_ptr().add(4) as *mut __m128i,
                _mm_cvttps_epi32(a[1]),
            );
        }
        out
    }
    bin!(le, _mm_cmple_ps);
    bin!(ge, _mm_cmpge_ps);
    /// Lanes 0–3 from `a[..4]`, lanes 4–7 from `b[..4]`.
    #[inline(always)]
    pub fn load_halves(a: &[f32; 4], b: &[f32; 4]) -> Repr {
        unsafe { [_mm_loadu_ps(a.as_ptr()), _mm_loadu_ps(b.as_ptr())] }
    }
    #[inline(always)]
    pub fn store_lo(r: Repr, a: &mut [f32; 4]) {
        unsafe { _mm_storeu_ps(a.as_mut_ptr(), r[0]) }
    }
    #[inline(always)]
    pub fn store_hi(r: Repr, b: &mut [f32; 4]) {
        unsafe { _mm_storeu_ps(b.as_mut_ptr(), r[1]) }
    }
    #[inline(always)]
    pub fn store_to(r: Repr, a: &mut [f32; 8]) {
        unsafe {
            _mm_storeu_ps(a.as_mut_ptr(), r[0]);
            _mm_storeu_ps(a.as_mut_ptr().add(4), r[1]);
        }
    }
    bin!(xor, _mm_xor_ps);
    /// Lanes whose bit patterns are equal.
    #[inline(always)]
    pub fn eq_bits(a: Repr, b: Repr) -> Repr {
        unsafe {
            [
                _mm_castsi128_ps(_mm_cmpeq_epi32(
                    _mm_castps_si128(a[0]),
                    _mm_castps_si128(b[0]),
                )),
                _mm_castsi128_ps(_mm_cmpeq_epi32(
                    _mm_castps_si128(a[1]),
                    _mm_castps_si128(b[1]),
                )),
            ]
        }
    }
    /// Columns of the 4x4 block `[a, b, c, d]` (rows).
    #[inline(always)]
    fn transpose4(a: __m128, b: __m128, c: __m128, d: __m128) -> [__m128; 4] {
        unsafe {
            let t0 = _mm_unpacklo_ps(a, b);
            let t1 = _mm_unpacklo_ps(c, d);
            let t2 = _mm_unpackhi_ps(a, b);
            let t3 = _mm_unpackhi_ps(c, d);
            [
                _mm_movelh_ps(t0, t1),
                _mm_movehl_ps(t1, t0),
                _mm_movelh_ps(t2, t3),
                _mm_movehl_ps(t3, t2),
            ]
        }
    }
    /// Lane vectors of the columns of 8 rows: `out[k][l] = rows[l][k]`.
    #[inline(always)]
    pub fn transpose(rows: [&[f32; 8]; 8]) -> [Repr; 8] {
        let lo = |r: &[f32; 8]| unsafe { _mm_loadu_ps(r.as_ptr()) };
        let hi = |r: &[f32; 8]| unsafe { _mm_loadu_ps(r.as_ptr().add(4)) };
        let a = transpose4(lo(rows[0]), lo(rows[1]), lo(rows[2]), lo(rows[3]));
        let b = transpose4(hi(rows[0]), hi(rows[1]), hi(rows[2]), hi(rows[3]));
        let c = transpose4(lo(rows[4]), lo(rows[5]), lo(rows[6]), lo(rows[7]));
        let d = transpose4(hi(rows[4]), hi(rows[5]), hi(rows[6]), hi(rows[7]));
        [
            [a[0], c[0]],
            [a[1], c[1]],
            [a[2], c[2]],
            [a[3], c[3]],
            [b[0], d[0]],
            [b[1], d[1]],
            [b[2], d[2]],
            [b[3], d[3]],
        ]
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod lanes {
    pub type Repr = [f32; 8];
    const T: f32 = f32::from_bits(u32::MAX);

    #[inline(always)]
    fn map2(a: Repr, b: Repr, f: impl Fn(f32, f32) -> f32) -> Repr {
        std::array::from_fn(|i| f(a[i], b[i]))
    }
    #[inline(always)]
    fn mask(x: bool) -> f32 {
        if x { T } else { 0.0 }
    }
    #[inline(always)]
    fn on(x: f32) -> bool {
        x.to_bits() != 0
    }
    #[inline(always)]
    pub fn splat(x: f32) -> Repr {
        [x; 8]
    }
    #[inline(always)]
    pub fn load(a: &[f32; 8]) -> Repr {
        *a
    }
    #[inline(always)]
    pub fn store(r: Repr) -> [f32; 8] {
        r
    }
    #[inline(always)]
    pub fn add(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| x + y)
    }
    #[inline(always)]
    pub fn sub(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| x - y)
    }
    #[inline(always)]
    pub fn mul(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| x * y)
    }
    #[inline(always)]
    pub fn div(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| x / y)
    }
    #[inline(always)]
    pub fn min(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| if x < y { x } else { y })
    }
    #[inline(always)]
    pub fn max(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| if x > y { x } else { y })
    }
    #[inline(always)]
    pub fn lt(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| mask(x < y))
    }
    #[inline(always)]
    pub fn gt(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| mask(x > y))
    }
    #[inline(always)]
    pub fn and(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| f32::from_bits(x.to_bits() & y.to_bits()))
    }
    #[inline(always)]
    pub fn sqrt(a: Repr) -> Repr {
        a.map(f32::sqrt)
    }
    #[inline(always)]
    pub fn select(m: Repr, a: Repr, b: Repr) -> Repr {
        std::array::from_fn(|i| if on(m[i]) { a[i] } else { b[i] })
    }
    #[inline(always)]
    pub fn bits(m: Repr) -> u32 {
        (0..8).fold(0, |acc, i| acc | ((on(m[i]) as u32) << i))
    }
    #[inline(always)]
    pub fn bit_set(e: &[u32; 8], b: u32) -> Repr {
        std::array::from_fn(|i| mask((e[i] >> b) & 1 != 0))
    }
    #[inline(always)]
    pub fn trunc_u32(a: Repr) -> [u32; 8] {
        a.map(|x| x as u32)
    }
    #[inline(always)]
    pub fn le(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| mask(x <= y))
    }
    #[inline(always)]
    pub fn ge(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| mask(x >= y))
    }
    #[inline(always)]
    pub fn load_halves(a: &[f32; 4], b: &[f32; 4]) -> Repr {
        std::array::from_fn(|i| if i < 4 { a[i] } else { b[i - 4] })
    }
    #[inline(always)]
    pub fn store_lo(r: Repr, a: &mut [f32; 4]) {
        a.copy_from_slice(&r[..4]);
    }
    #[inline(always)]
    pub fn store_hi(r: Repr, b: &mut [f32; 4]) {
        b.copy_from_slice(&r[4..]);
    }
    #[inline(always)]
    pub fn store_to(r: Repr, a: &mut [f32; 8]) {
        *a = r;
    }
    #[inline(always)]
    pub fn xor(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| f32::from_bits(x.to_bits() ^ y.to_bits()))
    }
    #[inline(always)]
    pub fn eq_bits(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| mask(x.to_bits() == y.to_bits()))
    }
    #[inline(always)]
    pub fn transpose(rows: [&[f32; 8]; 8]) -> [Repr; 8] {
        std::array::from_fn(|k| std::array::from_fn(|l| rows[l][k]))
    }
}

impl V8 {
    #[inline(always)]
    pub fn splat(x: f32) -> V8 {
        V8(lanes::splat(x))
    }
    #[inline(always)]
    pub fn load(a: &F8) -> V8 {
        V8(lanes::load(a))
    }
    #[inline(always)]
    pub fn store(self) -> F8 {
        lanes::store(self.0)
    }
    #[inline(always)]
    pub fn sqrt(self) -> V8 {
        V8(lanes::sqrt(self.0))
    }
    #[inline(always)]
    pub fn min(self, o: V8) -> V8 {
        V8(lanes::min(self.0, o.0))
    }
    #[inline(always)]
    pub fn max(self, o: V8) -> V8 {
        V8(lanes::max(self.0, o.0))
    }
    #[inline(always)]
    pub fn lt(self, o: V8) -> M8 {
        M8(lanes::lt(self.0, o.0))
    }
    #[inline(always)]
    pub fn gt(self, o: V8) -> M8 {
        M8(lanes::gt(self.0, o.0))
    }
    /// `m ? a : b` per lane.
    #[inline(always)]
    pub fn select(m: M8, a: V8, b: V8) -> V8 {
        V8(lanes::select(m.0, a.0, b.0))
    }
    #[inline(always)]
    pub fn le(self, o: V8) -> M8 {
        M8(lanes::le(self.0, o.0))
    }
    #[inline(always)]
    pub fn ge(self, o: V8) -> M8 {
        M8(lanes::ge(self.0, o.0))
    }
    /// The first 8 values of `a`.
    #[inline(always)]
    pub fn load_from(a: &[f32]) -> V8 {
        V8::load(a[..W].try_into().expect("8 values"))
    }
    /// Store into the first 8 values of `a`.
    #[inline(always)]
    pub fn store_to(self, a: &mut [f32]) {
        lanes::store_to(self.0, (&mut a[..W]).try_into().expect("8 values"))
    }
    /// Lanes 0–3 from `a[..4]`, lanes 4–7 from `b[..4]` (two rows of a narrow box).
    #[inline(always)]
    pub fn load_halves(a: &[f32], b: &[f32]) -> V8 {
        V8(lanes::load_halves(
            a[..4].try_into().expect("4 values"),
            b[..4].try_into().expect("4 values"),
        ))
    }
    /// Store lanes 0–3 into `a[..4]`.
    #[inline(always)]
    pub fn store_lo(self, a: &mut [f32]) {
        lanes::store_lo(self.0, (&mut a[..4]).try_into().expect("4 values"))
    }
    /// Store lanes 4–7 into `b[..4]`.
    #[inline(always)]
    pub fn store_hi(self, b: &mut [f32]) {
        lanes::store_hi(self.0, (&mut b[..4]).try_into().expect("4 values"))
    }
    /// The `u32` bit patterns of `a[..8]` as lanes (for selecting winner indices bit-exactly).
    #[inline(always)]
    pub fn load_bits(a: &[u32]) -> V8 {
        let f: &[u32; W] = a[..W].try_into().expect("8 values");
        V8::load(&f.map(f32::from_bits))
    }
    /// A `u32` bit pattern in every lane.
    #[inline(always)]
    pub fn splat_bits(x: u32) -> V8 {
        V8::splat(f32::from_bits(x))
    }
    /// Store the lanes' bit patterns into `a[..8]`.
    #[inline(always)]
    pub fn store_bits(self, a: &mut [u32]) {
        let f = self.store();
        a[..W].copy_from_slice(&f.map(f32::to_bits));
    }
    /// Truncation toward zero of lanes known to lie in `[0, 2^31)` (the caller clamps).
    #[inline(always)]
    pub fn trunc_u32(self) -> [u32; W] {
        lanes::trunc_u32(self.0)
    }
}

impl M8 {
    /// Lanes whose `e` has bit `b` set.
    #[inline(always)]
    pub fn bit_set(e: &[u32; W], b: u32) -> M8 {
        M8(lanes::bit_set(e, b))
    }
    #[inline(always)]
    pub fn and(self, o: M8) -> M8 {
        M8(lanes::and(self.0, o.0))
    }
    /// The first `n` lanes of each half (lanes `l` with `l % 4 < n`).
    #[inline(always)]
    pub fn first_of_halves(n: usize) -> M8 {
        const IOTA: F8 = [0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0];
        V8::load(&IOTA).lt(V8::splat(n as f32))
    }
    /// The first `n` lanes (`n ≤ 8`).
    #[inline(always)]
    pub fn first(n: usize) -> M8 {
        const IOTA: F8 = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
        V8::load(&IOTA).lt(V8::splat(n as f32))
    }
    /// One bit per lane (lane 0 in bit 0).
    #[inline(always)]
    pub fn bits(self) -> u32 {
        lanes::bits(self.0)
    }
}

/// Eight `f32` lanes, whatever the backend: the portable/SSE2 [`V8`] or, on x86-64 CPUs that
/// have it, the AVX2 [`V8x`]. The hot kernels are written once, generic over this trait, and
/// compiled once per backend; every operation is one IEEE single-precision operation per lane
/// (no fused multiply-add, the same `min`/`max`/`select` semantics), so every backend gives the
/// same bits.
///
/// # Safety
/// An implementation may execute instructions beyond the x86-64 baseline; [`Simd8::available`]
/// says whether this CPU has them, and code may use the implementation's operations only after
/// it returned `true` (the kernels check it once per frame, when they are chosen).
pub(crate) unsafe trait Simd8:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
{
    /// A lane mask (all bits set where true).
    type M: Mask8;
    /// Whether this CPU can run the backend.
    fn available() -> bool;
    fn splat(x: f32) -> Self;
    /// The first 8 values of `a`.
    fn load_from(a: &[f32]) -> Self;
    /// Store into the first 8 values of `a`.
    fn store_to(self, a: &mut [f32]);
    /// Lanes 0–3 from `a[..4]`, lanes 4–7 from `b[..4]`.
    fn load_halves(a: &[f32], b: &[f32]) -> Self;
    /// Store lanes 0–3 into `a[..4]`.
    fn store_lo(self, a: &mut [f32]);
    /// Store lanes 4–7 into `b[..4]`.
    fn store_hi(self, b: &mut [f32]);
    fn sqrt(self) -> Self;
    /// `if self < o { self } else { o }` per lane (SSE semantics).
    fn min(self, o: Self) -> Self;
    /// `if self > o { self } else { o }` per lane (SSE semantics).
    fn max(self, o: Self) -> Self;
    fn lt(self, o: Self) -> Self::M;
    fn gt(self, o: Self) -> Self::M;
    fn le(self, o: Self) -> Self::M;
    fn ge(self, o: Self) -> Self::M;
    /// Lanes whose bit patterns are equal.
    fn eq_bits(self, o: Self) -> Self::M;
    /// `m ? a : b` per lane.
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    /// Bitwise and / exclusive or of the lanes' bit patterns.
    fn and_bits(self, o: Self) -> Self;
    fn xor_bits(self, o: Self) -> Self;
    /// A `u32` bit pattern in every lane.
    fn splat_bits(x: u32) -> Self;
    /// The `u32` bit patterns of `a[..8]` as lanes.
    fn load_bits(a: &[u32]) -> Self;
    /// Store the lanes' bit patterns into `a[..8]`.
    fn store_bits(self, a: &mut [u32]);
    /// Lanes whose `e` has bit `b` set.
    fn bit_set(e: &[u32; W], b: u32) -> Self::M;
    /// The columns of 8 rows of 8 values as lanes: `out[k]` holds `rows[l][k]` in lane `l`
    /// (an array-of-structures to structure-of-arrays transpose).
    fn transpose(rows: [&[f32; 8]; 8]) -> [Self; 8];
    /// `table[r] | table[g] << 8 | table[b] << 16 | 255 << 24` per lane, the indices being the
    /// lanes truncated toward zero (the caller clamps them to `[0, SRGB_N − 1]`; other values
    /// are wrapped into the table, never read outside it).
    fn srgb_pack(r: Self, g: Self, b: Self, table: &[u32; SRGB_N]) -> Self;
    /// Store the lanes' bit patterns as 8 little-endian RGBA pixels into `out[..8]`.
    fn store_rgba(self, out: &mut [[u8; 4]]);
}

/// [`Simd8::srgb_pack`] one lane at a time.
#[inline(always)]
fn srgb_pack_scalar(r: [u32; W], g: [u32; W], b: [u32; W], table: &[u32; SRGB_N]) -> [u32; W] {
    let m = SRGB_N - 1;
    std::array::from_fn(|l| {
        table[r[l] as usize & m]
            | table[g[l] as usize & m] << 8
            | table[b[l] as usize & m] << 16
            | 0xff00_0000
    })
}

/// A lane mask of a [`Simd8`] backend.
pub(crate) trait Mask8: Copy {
    fn and(self, o: Self) -> Self;
    /// One bit per lane (lane 0 in bit 0).
    fn bits(self) -> u32;
    /// The first `n` lanes (`n ≤ 8`).
    fn first(n: usize) -> Self;
    /// The first `n` lanes of each half (lanes `l` with `l % 4 < n`).
    fn first_of_halves(n: usize) -> Self;
}

// SAFETY: V8 uses SSE2 (x86-64 baseline) or plain arrays: available everywhere.
unsafe impl Simd8 for V8 {
    type M = M8;
    #[inline(always)]
    fn available() -> bool {
        true
    }
    #[inline(always)]
    fn splat(x: f32) -> V8 {
        V8::splat(x)
    }
    #[inline(always)]
    fn load_from(a: &[f32]) -> V8 {
        V8::load_from(a)
    }
    #[inline(always)]
    fn store_to(self, a: &mut [f32]) {
        V8::store_to(self, a)
    }
    #[inline(always)]
    fn load_halves(a: &[f32], b: &[f32]) -> V8 {
        V8::load_halves(a, b)
    }
    #[inline(always)]
    fn store_lo(self, a: &mut [f32]) {
        V8::store_lo(self, a)
    }
    #[inline(always)]
    fn store_hi(self, b: &mut [f32]) {
        V8::store_hi(self, b)
    }
    #[inline(always)]
    fn sqrt(self) -> V8 {
        V8::sqrt(self)
    }
    #[inline(always)]
    fn min(self, o: V8) -> V8 {
        V8::min(self, o)
    }
    #[inline(always)]
    fn max(self, o: V8) -> V8 {
        V8::max(self, o)
    }
    #[inline(always)]
    fn lt(self, o: V8) -> M8 {
        V8::lt(self, o)
    }
    #[inline(always)]
    fn gt(self, o: V8) -> M8 {
        V8::gt(self, o)
    }
    #[inline(always)]
    fn le(self, o: V8) -> M8 {
        V8::le(self, o)
    }
    #[inline(always)]
    fn ge(self, o: V8) -> M8 {
        V8::ge(self, o)
    }
    #[inline(always)]
    fn eq_bits(self, o: V8) -> M8 {
        M8(lanes::eq_bits(self.0, o.0))
    }
    #[inline(always)]
    fn select(m: M8, a: V8, b: V8) -> V8 {
        V8::select(m, a, b)
    }
    #[inline(always)]
    fn and_bits(self, o: V8) -> V8 {
        V8(lanes::and(self.0, o.0))
    }
    #[inline(always)]
    fn xor_bits(self, o: V8) -> V8 {
        V8(lanes::xor(self.0, o.0))
    }
    #[inline(always)]
    fn splat_bits(x: u32) -> V8 {
        V8::splat_bits(x)
    }
    #[inline(always)]
    fn load_bits(a: &[u32]) -> V8 {
        V8::load_bits(a)
    }
    #[inline(always)]
    fn store_bits(self, a: &mut [u32]) {
        V8::store_bits(self, a)
    }
    #[inline(always)]
    fn bit_set(e: &[u32; W], b: u32) -> M8 {
        M8::bit_set(e, b)
    }
    #[inline(always)]
    fn transpose(rows: [&[f32; 8]; 8]) -> [V8; 8] {
        lanes::transpose(rows).map(V8)
    }
    #[inline(always)]
    fn srgb_pack(r: V8, g: V8, b: V8, table: &[u32; SRGB_N]) -> V8 {
        let px = srgb_pack_scalar(r.trunc_u32(), g.trunc_u32(), b.trunc_u32(), table);
        V8::load_bits(&px)
    }
    #[inline(always)]
    fn store_rgba(self, out: &mut [[u8; 4]]) {
        let mut px = [0u32; W];
        self.store_bits(&mut px);
        for (o, p) in out[..W].iter_mut().zip(px) {
            *o = p.to_le_bytes();
        }
    }
}

impl Mask8 for M8 {
    #[inline(always)]
    fn and(self, o: M8) -> M8 {
        M8::and(self, o)
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        M8::bits(self)
    }
    #[inline(always)]
    fn first(n: usize) -> M8 {
        M8::first(n)
    }
    #[inline(always)]
    fn first_of_halves(n: usize) -> M8 {
        M8::first_of_halves(n)
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::V8x;

/// The AVX2 backend: 8 lanes in one `__m256`. Chosen at run time (`is_x86_feature_detected!`);
/// the kernels that use it are compiled inside `#[target_feature(enable = "avx2")]` functions
/// so that these wrappers and the intrinsics inline into them. No FMA: the same IEEE operations
/// as [`V8`], so the same bits.
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{Mask8, SRGB_N, Simd8, W};
    use std::arch::x86_64::*;

    #[derive(Clone, Copy, Debug)]
    pub(crate) struct V8x(__m256);
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct M8x(__m256);

    // SAFETY (every `unsafe` block of this module): values of these types are only created and
    // used by code that runs after `V8x::available()` returned true (the `Simd8` contract), so
    // the AVX/AVX2 instructions exist; the loads and stores go through slices of checked length.

    // SAFETY: see the module note; `available` checks the CPU.
    unsafe impl Simd8 for V8x {
        type M = M8x;
        #[inline(always)]
        fn available() -> bool {
            std::arch::is_x86_feature_detected!("avx2")
        }
        #[inline(always)]
        fn splat(x: f32) -> V8x {
            V8x(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn load_from(a: &[f32]) -> V8x {
            let a = &a[..W];
            V8x(unsafe { _mm256_loadu_ps(a.as_ptr()) })
        }
        #[inline(always)]
        fn store_to(self, a: &mut [f32]) {
            let a = &mut a[..W];
            unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn load_halves(a: &[f32], b: &[f32]) -> V8x {
            let (a, b) = (&a[..4], &b[..4]);
            V8x(unsafe { _mm256_loadu2_m128(b.as_ptr(), a.as_ptr()) })
        }
        #[inline(always)]
        fn store_lo(self, a: &mut [f32]) {
            let a = &mut a[..4];
            unsafe { _mm_storeu_ps(a.as_mut_ptr(), _mm256_castps256_ps128(self.0)) }
        }
        #[inline(always)]
        fn store_hi(self, b: &mut [f32]) {
            let b = &mut b[..4];
            unsafe { _mm_storeu_ps(b.as_mut_ptr(), _mm256_extractf128_ps::<1>(self.0)) }
        }
        #[inline(always)]
        fn sqrt(self) -> V8x {
            V8x(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn min(self, o: V8x) -> V8x {
            V8x(unsafe { _mm256_min_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn max(self, o: V8x) -> V8x {
            V8x(unsafe { _mm256_max_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn lt(self, o: V8x) -> M8x {
            M8x(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn gt(self, o: V8x) -> M8x {
            M8x(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn le(self, o: V8x) -> M8x {
            M8x(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn ge(self, o: V8x) -> M8x {
            M8x(unsafe { _mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn eq_bits(self, o: V8x) -> M8x {
            M8x(unsafe {
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(
                    _mm256_castps_si256(self.0),
                    _mm256_castps_si256(o.0),
                ))
            })
        }
        #[inline(always)]
        fn select(m: M8x, a: V8x, b: V8x) -> V8x {
            // Masks are all ones or all zeros per lane, so the sign-bit blend equals and/andnot.
            V8x(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
        }
        #[inline(always)]
        fn and_bits(self, o: V8x) -> V8x {
            V8x(unsafe { _mm256_and_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn xor_bits(self, o: V8x) -> V8x {
            V8x(unsafe { _mm256_xor_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn splat_bits(x: u32) -> V8x {
            V8x(unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(x as i32)) })
        }
        #[inline(always)]
        fn load_bits(a: &[u32]) -> V8x {
            let a = &a[..W];
            V8x(unsafe { _mm256_castsi256_ps(_mm256_loadu_si256(a.as_ptr() as *const __m256i)) })
        }
        #[inline(always)]
        fn store_bits(self, a: &mut [u32]) {
            let a = &mut a[..W];
            unsafe {
                _mm256_storeu_si256(a.as_mut_ptr() as *mut __m256i, _mm256_castps_si256(self.0))
            }
        }
        #[inline(always)]
        fn bit_set(e: &[u32; W], b: u32) -> M8x {
            M8x(unsafe {
                let one = _mm256_set1_epi32(1);
                let v = _mm256_loadu_si256(e.as_ptr() as *const __m256i);
                let t = _mm256_and_si256(_mm256_srl_epi32(v, _mm_cvtsi32_si128(b as i32)), one);
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(t, one))
            })
        }
        #[inline(always)]
        fn transpose(rows: [&[f32; 8]; 8]) -> [V8x; 8] {
            unsafe {
                let r = rows.map(|r| _mm256_loadu_ps(r.as_ptr()));
                // Interleave pairs of rows, then pairs of pairs, then swap 128-bit halves.
                let t0 = _mm256_unpacklo_ps(r[0], r[1]);
                let t1 = _mm256_unpackhi_ps(r[0], r[1]);
                let t2 = _mm256_unpacklo_ps(r[2], r[3]);
                let t3 = _mm256_unpackhi_ps(r[2], r[3]);
                let t4 = _mm256_unpacklo_ps(r[4], r[5]);
                let t5 = _mm256_unpackhi_ps(r[4], r[5]);
                let t6 = _mm256_unpacklo_ps(r[6], r[7]);
                let t7 = _mm256_unpackhi_ps(r[6], r[7]);
                let u0 = _mm256_shuffle_ps::<0x44>(t0, t2);
                let u1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
                let u2 = _mm256_shuffle_ps::<0x44>(t1, t3);
                let u3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
                let u4 = _mm256_shuffle_ps::<0x44>(t4, t6);
                let u5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
                let u6 = _mm256_shuffle_ps::<0x44>(t5, t7);
                let u7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
                [
                    V8x(_mm256_permute2f128_ps::<0x20>(u0, u4)),
                    V8x(_mm256_permute2f128_ps::<0x20>(u1, u5)),
                    V8x(_mm256_permute2f128_ps::<0x20>(u2, u6)),
                    V8x(_mm256_permute2f128_ps::<0x20>(u3, u7)),
                    V8x(_mm256_permute2f128_ps::<0x31>(u0, u4)),
                    V8x(_mm256_permute2f128_ps::<0x31>(u1, u5)),
                    V8x(_mm256_permute2f128_ps::<0x31>(u2, u6)),
                    V8x(_mm256_permute2f128_ps::<0x31>(u3, u7)),
                ]
            }
        }
        #[inline(always)]
        fn srgb_pack(r: V8x, g: V8x, b: V8x, table: &[u32; SRGB_N]) -> V8x {
            unsafe {
                let m = _mm256_set1_epi32(SRGB_N as i32 - 1);
                let t = table.as_ptr() as *const i32;
                // The indices are masked into [0, SRGB_N), so every gather reads inside `table`.
                let look = |c: V8x| {
                    let i = _mm256_and_si256(_mm256_cvttps_epi32(c.0), m);
                    _mm256_i32gather_epi32::<4>(t, i)
                };
                let px = _mm256_or_si256(
                    _mm256_or_si256(look(r), _mm256_slli_epi32::<8>(look(g))),
                    _mm256_or_si256(
                        _mm256_slli_epi32::<16>(look(b)),
                        _mm256_set1_epi32(0xff00_0000_u32 as i32),
                    ),
                );
                V8x(_mm256_castsi256_ps(px))
            }
        }
        #[inline(always)]
        fn store_rgba(self, out: &mut [[u8; 4]]) {
            let out = &mut out[..W];
            unsafe {
                _mm256_storeu_si256(
                    out.as_mut_ptr() as *mut __m256i,
                    _mm256_castps_si256(self.0),
                )
            }
        }
    }

    impl Mask8 for M8x {
        #[inline(always)]
        fn and(self, o: M8x) -> M8x {
            M8x(unsafe { _mm256_and_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn bits(self) -> u32 {
            unsafe { _mm256_movemask_ps(self.0) as u32 }
        }
        #[inline(always)]
        fn first(n: usize) -> M8x {
            const IOTA: [f32; 8] = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
            V8x::load_from(&IOTA).lt(V8x::splat(n as f32))
        }
        #[inline(always)]
        fn first_of_halves(n: usize) -> M8x {
            const IOTA: [f32; 8] = [0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0];
            V8x::load_from(&IOTA).lt(V8x::splat(n as f32))
        }
    }

    macro_rules! op {
        ($tr:ident, $f:ident, $i:ident) => {
            impl std::ops::$tr for V8x {
                type Output = V8x;
                #[inline(always)]
                fn $f(self, o: V8x) -> V8x {
                    V8x(unsafe { $i(self.0, o.0) })
                }
            }
        };
    }
    op!(Add, add, _mm256_add_ps);
    op!(Sub, sub, _mm256_sub_ps);
    op!(Mul, mul, _mm256_mul_ps);
    op!(Div, div, _mm256_div_ps);
}

macro_rules! v8_op {
    ($tr:ident, $f:ident, $l:ident) => {
        impl std::ops::$tr for V8 {
            type Output = V8;
            #[inline(always)]
            fn $f(self, o: V8) -> V8 {
                V8(lanes::$l(self.0, o.0))
            }
        }
    };
}
v8_op!(Add, add, add);
v8_op!(Sub, sub, sub);
v8_op!(Mul, mul, mul);
v8_op!(Div, div, div);

#[cfg(test)]
mod tests {
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
}
