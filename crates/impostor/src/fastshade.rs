//! [`Lighting::shade`] without library calls: the same formula with a polynomial `pow`.
//!
//! Shading is a third of the ray-cast time with `powf` from libm (measured on S2, one thread:
//! `Lighting::shade` 17% + `powf` 14%). [`shade`] evaluates the identical ambient + Lambert +
//! Blinn-Phong sum, only `x^e` becomes `exp2(e·log2 x)` with the two polynomials below; a unit
//! test bounds the difference from [`Lighting::shade`] (≤ 2e-5 absolute on random inputs, far
//! under half an 8-bit sRGB step).

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

use glam::Vec3;
use texmap_core::color::linear_to_srgb8_fast;
use texmap_core::shade::{Lighting, Material};

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

/// The exponents as integers and the number of bits they need, when all 8 are integers in
/// `[0, MAX_INT_EXPONENT]`.
#[inline(always)]
fn int_exponents(e: &F8) -> Option<([u32; W], u32)> {
    let mut ei = [0u32; W];
    let mut ok = true;
    let mut any = 0u32;
    for i in 0..W {
        let x = e[i];
        let in_range = x >= 0.0 && x <= MAX_INT_EXPONENT;
        let xc = if in_range { x } else { 0.0 };
        // SAFETY: xc ∈ [0, 65535], so truncation is exact and in range.
        let n = unsafe { xc.to_int_unchecked::<i32>() } as u32;
        ok &= in_range && n as f32 == x;
        ei[i] = n;
        any |= n;
    }
    ok.then(|| (ei, u32::BITS - any.leading_zeros()))
}

/// `x^e` for integer `e < 2^bits` by repeated squaring over 8 lanes (`x ∈ [0, 1]`): at most
/// `2·bits` rounded products, so within ~`2·bits` ulp of the exact power. When the 8 exponents
/// are equal (one material, the common case) the bit tests are scalar.
#[inline(always)]
fn pow_int8(x: V8, e: &[u32; W], bits: u32) -> V8 {
    let mut acc = V8::splat(1.0);
    let mut p = x;
    if e.iter().all(|&k| k == e[0]) {
        let k = e[0];
        for b in 0..bits {
            if (k >> b) & 1 != 0 {
                acc = acc * p;
            }
            p = p * p;
        }
    } else {
        for b in 0..bits {
            acc = V8::select(M8::bit_set(e, b), acc * p, acc);
            p = p * p;
        }
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

/// Entries of [`srgb_table`] (texmap-core's encoder uses 2^12 bins).
pub(crate) const SRGB_N: usize = 4096;

/// Table indices of 8 linear values: `floor(c·4096)` clamped to `[0, 4095]`, NaN → 0, exactly
/// as [`linear_to_srgb8_fast`] computes them, in a form that vectorises.
#[inline(always)]
pub(crate) fn srgb_index8(c: &F8) -> [u32; W] {
    let x = V8::load(c) * V8::splat(SRGB_N as f32);
    // `max` first: NaN lanes become 0 (SSE `max(NaN, 0)` returns the second operand).
    let x = x.max(V8::splat(0.0)).min(V8::splat((SRGB_N - 1) as f32));
    x.trunc_u32()
}

/// Surface and material of 8 pixels, structure-of-arrays.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Surf8 {
    pub n: [F8; 3],
    pub v: [F8; 3],
    pub base: [F8; 3],
    pub spec: F8,
    pub shin: F8,
}

/// [`shade`] over 8 lanes: the same formula, masks instead of branches, on [`V8`] lanes.
#[inline(always)]
pub(crate) fn shade8(l: &Lighting, s: &Surf8) -> [F8; 3] {
    // Choose the specular power once for the 8 lanes: by squaring when every exponent is a
    // small integer (exact to a few ulp, and cheaper), else exp2(e·log2 x).
    let int_bits = int_exponents(&s.shin);
    let n = [V8::load(&s.n[0]), V8::load(&s.n[1]), V8::load(&s.n[2])];
    let v = [V8::load(&s.v[0]), V8::load(&s.v[1]), V8::load(&s.v[2])];
    let base = [
        V8::load(&s.base[0]),
        V8::load(&s.base[1]),
        V8::load(&s.base[2]),
    ];
    let spec_k = V8::load(&s.spec);
    let mut c = [
        base[0] * V8::splat(l.ambient.x),
        base[1] * V8::splat(l.ambient.y),
        base[2] * V8::splat(l.ambient.z),
    ];
    let zero = V8::splat(0.0);
    let tiny = V8::splat(1e-30);
    for light in l.lights() {
        let a = light.to_light;
        let (ax, ay, az) = (V8::splat(a.x), V8::splat(a.y), V8::splat(a.z));
        // Lambert term n·l.
        let ndl = n[0] * ax + n[1] * ay + n[2] * az;
        // Blinn half vector h = l + v and n·h/|h|.
        let hx = ax + v[0];
        let hy = ay + v[1];
        let hz = az + v[2];
        let hh = hx * hx + hy * hy + hz * hz;
        let nh = n[0] * hx + n[1] * hy + n[2] * hz;
        let q = nh / hh.sqrt();
        // Clamp to (0, 1]; lanes at 0 (or NaN from hh = 0) are masked after the pow.
        let pos = q.gt(tiny);
        let ndh = V8::select(pos, q.min(V8::splat(1.0)), tiny);
        let pw = match int_bits {
            Some((ei, bits)) => pow_int8(ndh, &ei, bits),
            None => {
                let lg = V8::load(&log2_8(&ndh.store()));
                let z = (V8::load(&s.shin) * lg).min(zero);
                V8::load(&exp2_neg8(&z.store()))
            }
        };
        let spec = V8::select(pos, spec_k * pw, zero);
        let lit = ndl.gt(zero);
        for k in 0..3 {
            let term = base[k] * ndl + spec;
            c[k] = c[k] + V8::select(lit, V8::splat(light.color[k]) * term, zero);
        }
    }
    [c[0].store(), c[1].store(), c[2].store()]
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
        map2(a, b, |x, y| mask(on(x) && on(y)))
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
