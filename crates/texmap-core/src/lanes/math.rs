//! The shared lane maths: `log2`/`exp2`/`pow` polynomials (one scalar form, the reference, and
//! the lane forms beside it), the integer specular powers, and the sRGB encode over lanes.
//!
//! # Three polynomial families, and why they stay three
//! They compute different things, and each renderer's images are fixed by its own (golden-image
//! and bit-for-bit tests), so they are kept side by side here rather than merged:
//!
//! - [`log2_fast`] / [`exp2_neg`] / [`pow01`] (and their lane forms [`log2_fast_x8`],
//!   [`exp2_neg_x8`], [`pow01_lanes`]): `x^e` for the shading model ([`super::shade`]), an atanh
//!   series to `u⁷` for `log2` and a Taylor series to `g⁶` for `exp2`; relative error ≤ 2e-5.
//! - [`pow01_x4`]: the rasteriser's per-pixel Phong power over [`F32x4`] lanes, one term more in
//!   each series (atanh to `t⁹`, Taylor to degree 7): relative error below 1e-5.
//! - [`log2_split`]: the samplers' level of detail, `⌊log2 x⌋` exact from the exponent plus a
//!   degree-4 fraction polynomial in `[0, 1]` (error 1.2e-4, monotone, continuous across
//!   octaves): cheaper, and the split is what the level selection needs. The lane forms in
//!   `sample/{lanes,avx2,avx512}.rs` use its coefficients [`LOG2_C1`]..[`LOG2_C4`].
//!
//! # sRGB
//! The lane encoder reads [`srgb_table32`], the `u32` widening of the table behind
//! [`crate::color::linear_to_srgb8_fast`], with the same indices (`floor(c·4096)` clamped, NaN
//! to 0), so it gives that function's bytes lane by lane (tested).

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

use super::{F32x4, I32x4, LANES8, Lanes8};

// ---------------------------------------------------------------------------------------------
// The shading power: x^e = exp2(e·log2 x).

/// `log2(x)` for finite `x > 0` (absolute error ≲ 1e-7 on normal numbers).
#[inline(always)]
pub fn log2_fast(x: f32) -> f32 {
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
pub fn exp2_neg(z: f32) -> f32 {
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

/// `x^e` for `x ∈ [0, 1]`, `e > 0` (relative error ≤ 2e-5 against `powf`, tested).
#[inline(always)]
pub fn pow01(x: f32, e: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    exp2_neg((e * log2_fast(x)).min(0.0))
}

/// Branch-free [`log2_fast`] over 8 lanes (inputs > 0; the caller masks the rest).
#[inline(always)]
pub fn log2_fast_x8(x: &[f32; LANES8]) -> [f32; LANES8] {
    let mut out = [0.0; LANES8];
    for l in 0..LANES8 {
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
pub fn exp2_neg_x8(z: &[f32; LANES8]) -> [f32; LANES8] {
    let mut out = [0.0; LANES8];
    for l in 0..LANES8 {
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

/// `x^e = exp2(e·log2 x)` over 8 lanes with the polynomials (`x ∈ (0, 1]`, any `e ≥ 0`).
#[inline(always)]
pub fn pow01_lanes<V: Lanes8>(x: V, e: V) -> V {
    let mut a = [0f32; LANES8];
    x.store_to(&mut a);
    let lg = V::load_from(&log2_fast_x8(&a));
    let z = (e * lg).min(V::splat(0.0));
    z.store_to(&mut a);
    V::load_from(&exp2_neg_x8(&a))
}

// ---------------------------------------------------------------------------------------------
// Integer specular powers by squaring.

/// Largest exponent [`pow_int_lanes`] takes (16 squarings).
pub const MAX_INT_EXPONENT: f32 = 65_535.0;

/// How the shading over lanes takes the specular power `x^e` of 8 lanes, chosen once per chunk
/// (or once per frame when every material has the same shininess).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpecPow {
    /// All 8 exponents are the same integer `k < 2^bits`: squarings, bit tests on a scalar.
    /// Bases below `floor` ([`pow_floors`] of `bits`) give 0.
    Same {
        /// The exponent.
        k: u32,
        /// Its bit length.
        bits: u32,
        /// The smallest base that is not flushed to 0.
        floor: f32,
    },
    /// Every exponent is an integer below `2^bits`: squarings, bit tests over lanes. Bases
    /// below their lane's `floor` ([`pow_floors`] of the lane's bit length) give 0.
    Ints {
        /// The exponent of each lane.
        e: [u32; LANES8],
        /// The bit length of the largest.
        bits: u32,
        /// The smallest base of each lane that is not flushed to 0.
        floor: [f32; LANES8],
    },
    /// Otherwise: `exp2(e·log2 x)` with the polynomials ([`pow01_lanes`]).
    Poly,
}

/// The [`SpecPow`] of 8 exponents: integers in `[0, MAX_INT_EXPONENT]` are taken by squaring.
#[inline(always)]
pub fn spec_pow(e: &[f32; LANES8]) -> SpecPow {
    let mut ei = [0u32; LANES8];
    let mut ok = true;
    let mut any = 0u32;
    for i in 0..LANES8 {
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

/// The [`SpecPow`] of the exponents in the lanes of `shin`.
#[inline(always)]
pub fn spec_pow_of<V: Lanes8>(shin: V) -> SpecPow {
    let mut e = [0f32; LANES8];
    shin.store_to(&mut e);
    spec_pow(&e)
}

/// `pow_floors()[b]`: the smallest base [`pow_int_lanes`] raises to an exponent `e` of bit
/// length `b` (`2^(b−1) ≤ e < 2^b`); smaller bases give 0. It is `2^(−120/2^b)` (0 for
/// `b = 0`), so every product of the squarings of a base at or above it stays at or above
/// `floor^(2^b) = 2^−120`: a normal number. Without it, a base below ~0.2 raised to 40
/// underflows into subnormal numbers, and every multiply producing one takes a microcode
/// assist of ~100+ cycles (measured: a quarter of an S1 ray-cast frame). What it drops is a
/// power below `floor^(2^(b−1)) = 2^−60`, invisible in any colour. The values are `2^−120`
/// square-rooted `b` times in `f32` (correctly rounded everywhere: the same on every backend).
pub fn pow_floors() -> &'static [f32; 17] {
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

/// `x^e` by repeated squaring over 8 lanes (`x ∈ [0, 1]`, integer exponents below `2^bits`):
/// at most `2·bits` rounded products; each squaring doubles the relative error it is given, so
/// the power is within ~`e·2^−24` of exact (tested). Bases below the floor of [`pow_floors`]
/// give 0. `Same` and `Ints` perform the same products, so they give the same bits. `pw` must
/// not be [`SpecPow::Poly`] (then every power is 1).
///
/// `N` powers (one per light) are taken in one loop: the loop control is shared and the `N`
/// dependency chains of squarings overlap. Every power sees the same products as alone.
#[inline(always)]
pub fn pow_int_lanes<V: Lanes8, const N: usize>(x: [V; N], pw: &SpecPow) -> [V; N] {
    let mut acc = [V::splat(1.0); N];
    let zero = V::splat(0.0);
    // Bases below the floor become 0 (no subnormal products; see `pow_floors`).
    let floor = match pw {
        SpecPow::Same { floor, .. } => V::splat(*floor),
        SpecPow::Ints { floor, .. } => V::load_from(floor),
        SpecPow::Poly => return acc,
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
        SpecPow::Poly => {}
    }
    acc
}

// ---------------------------------------------------------------------------------------------
// The rasteriser's power over four lanes.

/// `x^p` for four lanes with `x` in `[0, 1]` and `0 < p <= 65536`, as `exp2(p · log2 x)`:
/// relative error below 1e-5 against `f32::powf` (tested); lanes with `x` below the smallest
/// normal f32 give 0, as `powf` does up to its own rounding.
///
/// `log2 x = e + log2 m` with `m ∈ [√½, √2)`, `log2 m = 2/ln2 · atanh(t)`, `t = (m − 1)/(m + 1)`,
/// odd series to `t⁹` (|t| < 0.172: truncation < 1e-9); `2^y = 2^n · 2^f` with
/// `n = trunc(y − ½)`, `f ∈ (−½, ½]`, Taylor series of `e^(f·ln2)` to degree 7 (< 1e-8).
#[inline(always)]
pub fn pow01_x4(x: F32x4, p: f32) -> F32x4 {
    let s = F32x4::splat;
    let i = I32x4::splat;
    // Split x = 2^e · m, m in [1, 2), then fold m into [√½, √2).
    let bits = x.cast_i32();
    let e = bits.shr::<23>().sub(i(127));
    let m = bits.and(i(0x007f_ffff)).or(i(0x3f80_0000)).cast_f32();
    let big = s(std::f32::consts::SQRT_2).lt(m);
    let m = F32x4::select(big, m.mul(s(0.5)), m);
    let e = F32x4::select(big, e.to_f32().add(s(1.0)), e.to_f32());
    // log2 m by the atanh series.
    let t = m.sub(s(1.0)).div(m.add(s(1.0)));
    let t2 = t.mul(t);
    let c = |k: f32| s((2.0 / std::f64::consts::LN_2 / k as f64) as f32);
    let poly = c(9.0)
        .mul(t2)
        .add(c(7.0))
        .mul(t2)
        .add(c(5.0))
        .mul(t2)
        .add(c(3.0))
        .mul(t2)
        .add(c(1.0));
    let log2x = e.add(t.mul(poly));
    // y = p · log2 x <= 0, clamped where 2^y is below the normal range anyway.
    let y = s(p).mul(log2x).max(s(-126.0));
    // 2^y = 2^n · 2^f.
    let n = y.sub(s(0.5)).trunc_i32();
    let f = y.sub(n.to_f32()).mul(s(std::f32::consts::LN_2));
    let mut ef = s(1.0 / 5040.0);
    for k in [720.0f32, 120.0, 24.0, 6.0, 2.0, 1.0, 1.0] {
        ef = ef.mul(f).add(s(1.0 / k));
    }
    let two_n = n.add(i(127)).shl::<23>().cast_f32();
    let r = ef.mul(two_n);
    F32x4::select(s(f32::MIN_POSITIVE).le(x), r, s(0.0))
}

// ---------------------------------------------------------------------------------------------
// The samplers' level of detail.

/// `log2 x` split into its integer part `⌊log2 x⌋` (exact, from the exponent) and an approximate
/// fraction in `[0, 1]`: a degree-4 polynomial in the mantissa `t = x/2^e − 1` with `p(0) = 0`,
/// `p(1) = 1` (continuous across octaves), fitted to `log2(1 + t)` with max error 1.2e-4 (tested).
/// For positive normal `x` only; the callers route 0, NaN and subnormals elsewhere.
#[inline(always)]
pub fn log2_split(x: f32) -> (i32, f32) {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    let t = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000) - 1.0;
    (
        e,
        t * (LOG2_C1 + t * (LOG2_C2 + t * (LOG2_C3 + t * LOG2_C4))),
    )
}

/// [`log2_split`]'s mantissa polynomial, `t·(C1 + t·(C2 + t·(C3 + t·C4)))` (shared with the
/// samplers' lane kernels).
pub const LOG2_C1: f32 = 1.438_725_7;
/// See [`LOG2_C1`].
pub const LOG2_C2: f32 = -0.677_783_9;
/// See [`LOG2_C1`].
pub const LOG2_C3: f32 = 0.321_188_76;
/// See [`LOG2_C1`] (chosen so that the polynomial is 1 at `t = 1`).
pub const LOG2_C4: f32 = 1.0 - LOG2_C1 - LOG2_C2 - LOG2_C3;

// ---------------------------------------------------------------------------------------------
// sRGB encode over lanes.

/// Entries of the sRGB encode table (the bins of [`crate::color::linear_to_srgb8_fast`]).
pub const SRGB_N: usize = crate::color::SRGB_ENCODE_BINS;

/// [`crate::color::srgb_encode_table`] widened to `u32` entries, for gathers over lanes.
pub fn srgb_table32() -> &'static [u32; SRGB_N] {
    static T: OnceLock<[u32; SRGB_N]> = OnceLock::new();
    T.get_or_init(|| crate::color::srgb_encode_table().map(u32::from))
}

/// sRGB8 RGBA of 8 linear colours, as little-endian `u32` lanes (alpha 255): table indices
/// `floor(c·4096)` clamped to `[0, 4095]`, NaN → 0, exactly as
/// [`crate::color::linear_to_srgb8_fast`] computes them, then `table` ([`srgb_table32`])
/// lookups.
#[inline(always)]
pub fn srgb_rgba_lanes<V: Lanes8>(r: V, g: V, b: V, table: &[u32; SRGB_N]) -> V {
    let q = |c: V| {
        let x = c * V::splat(SRGB_N as f32);
        // `max` first: NaN lanes become 0 (SSE `max(NaN, 0)` returns the second operand).
        x.max(V::splat(0.0)).min(V::splat((SRGB_N - 1) as f32))
    };
    V::srgb_pack(q(r), q(g), q(b), table)
}

/// [`Lanes8::srgb_pack`] one lane at a time.
#[inline(always)]
pub fn srgb_pack_scalar(
    r: [u32; LANES8],
    g: [u32; LANES8],
    b: [u32; LANES8],
    table: &[u32; SRGB_N],
) -> [u32; LANES8] {
    let m = SRGB_N - 1;
    std::array::from_fn(|l| {
        table[r[l] as usize & m]
            | table[g[l] as usize & m] << 8
            | table[b[l] as usize & m] << 16
            | 0xff00_0000
    })
}
