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
    /// Bases below `floor` ([`pow_floors`] of `bits`) give 0.
    Same { k: u32, bits: u32, floor: f32 },
    /// Every exponent is an integer below `2^bits`: squarings, bit tests over lanes. Bases
    /// below their lane's `floor` ([`pow_floors`] of the lane's bit length) give 0.
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

#[cfg(target_arch = "x86_64")]
mod avx;
mod shading;
mod vec8;

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::V8x;
pub(crate) use shading::*;
pub(crate) use vec8::*;

#[cfg(test)]
mod tests;
