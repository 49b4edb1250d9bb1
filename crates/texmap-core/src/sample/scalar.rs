//! The scalar kernels: wrap modes (addressing kernels chosen once per call, also on four lanes),
//! the log2 split, nearest, bilinear, trilinear (Seed 000 Eq. 4) and the anisotropic reference.
//! They are also the reference the lane kernels are tested against bit for bit.

use super::*;
// The level-of-detail logarithm and its coefficients (used by the lane kernels too).
pub(super) use crate::lanes::math::{LOG2_C1, LOG2_C2, LOG2_C3, LOG2_C4, log2_split};

pub(super) trait Addr {
    const REPEAT: bool;
    /// Fold an integer texel address into `0..n`.
    fn wrap(i: i32, n: i32) -> i32;
    /// [`Addr::wrap`] on four integer-valued lanes (`|i| ≤ 2^30 + 1`) of a level `n` texels
    /// wide (`inv_n = 1/n`), as floats: the same values.
    fn wrap_lanes(i: Vec4, n: f32, inv_n: f32) -> Vec4;
}

/// Repeat on a power-of-two level: a mask.
pub(super) struct RepeatPow2;
/// Repeat on any size: Euclidean remainder.
pub(super) struct RepeatAny;
/// Clamp to edge.
pub(super) struct ClampEdge;

impl Addr for RepeatPow2 {
    const REPEAT: bool = true;
    #[inline(always)]
    fn wrap(i: i32, n: i32) -> i32 {
        i & (n - 1)
    }
    #[inline(always)]
    fn wrap_lanes(i: Vec4, n: f32, _: f32) -> Vec4 {
        // The mask on each lane (LLVM keeps the four in one register).
        let (m, i) = (n as i32 - 1, lanes_i32(i));
        Vec4::new(
            (i[0] & m) as f32,
            (i[1] & m) as f32,
            (i[2] & m) as f32,
            (i[3] & m) as f32,
        )
    }
}
impl Addr for RepeatAny {
    const REPEAT: bool = true;
    #[inline(always)]
    fn wrap(i: i32, n: i32) -> i32 {
        i.rem_euclid(n)
    }
    #[inline(always)]
    fn wrap_lanes(i: Vec4, n: f32, _: f32) -> Vec4 {
        // A float quotient is not exact for any n: one lane at a time in integers.
        let (n, i) = (n as i32, lanes_i32(i));
        let r = |j: usize| i[j].rem_euclid(n) as f32;
        Vec4::new(r(0), r(1), r(2), r(3))
    }
}
impl Addr for ClampEdge {
    const REPEAT: bool = false;
    #[inline(always)]
    fn wrap(i: i32, n: i32) -> i32 {
        i.max(0).min(n - 1)
    }
    #[inline(always)]
    fn wrap_lanes(i: Vec4, n: f32, _: f32) -> Vec4 {
        i.max(Vec4::ZERO).min(Vec4::splat(n - 1.0))
    }
}

/// Clamp a texel coordinate to ±2^30; NaN becomes −2^30 (then the weights stay finite).
#[inline(always)]
pub(super) fn clampc(x: f32) -> f32 {
    // Plain comparisons (a NaN fails the first and becomes −2^30): cheaper than f32::max/min.
    let x = if x >= -COORD_LIMIT { x } else { -COORD_LIMIT };
    if x <= COORD_LIMIT { x } else { COORD_LIMIT }
}

/// ⌊x⌋ for |x| ≤ 2^30 (finite): truncate, then step down for negative fractions.
#[inline(always)]
pub(super) fn floor_i32(x: f32) -> i32 {
    debug_assert!(x.is_finite() && x.abs() <= COORD_LIMIT);
    // SAFETY: callers pass finite values clamped to ±2^30, which fit in i32.
    let t: i32 = unsafe { x.to_int_unchecked() };
    t - ((t as f32 > x) as i32)
}

#[inline(always)]
pub(super) fn lerp(a: Vec4, b: Vec4, t: f32) -> Vec4 {
    a + (b - a) * t
}

#[inline(always)]
pub(super) fn texel(texels: &[Vec4], i: usize) -> Vec4 {
    debug_assert!(i < texels.len());
    // SAFETY: every index is `offset + y*w + x` with x, y folded into the level by `Addr::wrap`
    // and the level inside the buffer (MipTexture guarantees).
    unsafe { *texels.get_unchecked(i) }
}

/// Nearest texel of level 0.
#[inline(always)]
pub(super) fn nearest<A: Addr>(texels: &[Vec4], l: &LevelInfo, uv: Vec2) -> Vec4 {
    let (w, h) = (l.width as i32, l.height as i32);
    let x = A::wrap(floor_i32(clampc(uv.x * l.width_f)), w);
    let y = A::wrap(floor_i32(clampc(uv.y * l.height_f)), h);
    texel(texels, l.offset + (y * w + x) as usize)
}

/// Seed 000 Eq. (4), one level: bilinear of the four texels around `2^L r_m − ½` with weights
/// `(α, β) = frac(2^L r_m − ½)`, texel addresses per Eq. (3).
#[inline(always)]
pub(super) fn bilinear<A: Addr>(texels: &[Vec4], l: &LevelInfo, uv: Vec2) -> Vec4 {
    let x = clampc(uv.x * l.width_f - 0.5);
    let y = clampc(uv.y * l.height_f - 0.5);
    let (fx, fy) = (floor_i32(x), floor_i32(y));
    let (ax, ay) = (x - fx as f32, y - fy as f32);
    let (w, h) = (l.width as i32, l.height as i32);
    let x0 = A::wrap(fx, w);
    let x1 = A::wrap(fx + 1, w);
    let r0 = l.offset + (A::wrap(fy, h) * w) as usize;
    let r1 = l.offset + (A::wrap(fy + 1, h) * w) as usize;
    let t00 = texel(texels, r0 + x0 as usize);
    let t10 = texel(texels, r0 + x1 as usize);
    let t01 = texel(texels, r1 + x0 as usize);
    let t11 = texel(texels, r1 + x1 as usize);
    lerp(lerp(t00, t10, ax), lerp(t01, t11, ax), ay)
}

/// Eq. (2)'s max of the four partial derivatives, in level-0 texels per pixel: `λ = log2` of it.
#[inline(always)]
pub(super) fn footprint(l0: &LevelInfo, duv_dx: Vec2, duv_dy: Vec2) -> f32 {
    let s = Vec2::new(l0.width_f, l0.height_f);
    (duv_dx * s).abs().max((duv_dy * s).abs()).max_element()
}

/// λ (larger = coarser) of a footprint; NaN or zero give −∞ (level 0). Exact `log2`, for the
/// reference sampler.
#[inline(always)]
pub(super) fn lambda(l0: &LevelInfo, duv_dx: Vec2, duv_dy: Vec2) -> f32 {
    let m = footprint(l0, duv_dx, duv_dy);
    if m > 0.0 { m.log2() } else { f32::NEG_INFINITY }
}

/// Seed 000 Eq. (4): blend the bilinear samples of levels ⌊λ⌋ and ⌊λ⌋+1 by frac(λ), clamped to the
/// pyramid; `m` is the footprint in level-0 texels (λ = log2 m, split by [`log2_split`]).
#[inline(always)]
// `!(a > b)` on purpose: NaN must take the fallback branch.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub(super) fn trilinear_fp<A: Addr>(tex: &MipTexture, uv: Vec2, m: f32) -> Vec4 {
    let levels = tex.levels();
    let texels = tex.texels();
    let last = levels.len() - 1;
    // Magnification (λ ≤ 0), zero or NaN footprint: level 0 alone.
    if !(m > 1.0) {
        return bilinear::<A>(texels, &levels[0], uv);
    }
    let (i, f) = log2_split(m);
    let i = i as usize;
    if i >= last {
        return bilinear::<A>(texels, &levels[last], uv);
    }
    let a = bilinear::<A>(texels, &levels[i], uv);
    let b = bilinear::<A>(texels, &levels[i + 1], uv);
    lerp(a, b, f)
}

/// [`trilinear_fp`] at an explicit λ (used by the anisotropic reference's taps).
#[inline(always)]
// `!(a > b)` on purpose: NaN must take the fallback branch.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub(super) fn trilinear<A: Addr>(tex: &MipTexture, uv: Vec2, lam: f32) -> Vec4 {
    let levels = tex.levels();
    let texels = tex.texels();
    let last = levels.len() - 1;
    if !(lam > 0.0) {
        return bilinear::<A>(texels, &levels[0], uv);
    }
    if lam >= last as f32 {
        return bilinear::<A>(texels, &levels[last], uv);
    }
    let i = lam as usize;
    let f = lam - i as f32;
    let a = bilinear::<A>(texels, &levels[i], uv);
    let b = bilinear::<A>(texels, &levels[i + 1], uv);
    lerp(a, b, f)
}

/// The box-filtered footprint reference (see [`Sampler::Anisotropic`]).
pub(super) fn anisotropic<A: Addr>(
    tex: &MipTexture,
    uv: Vec2,
    duv_dx: Vec2,
    duv_dy: Vec2,
    max_taps: u32,
) -> Vec4 {
    let l0 = &tex.levels()[0];
    let s = Vec2::new(l0.width_f, l0.height_f);
    let cap = max_taps.clamp(1, 64) as f32;
    // Taps per side: one per texel of the footprint side (NaN -> 1).
    let nx = (duv_dx * s).length().ceil().max(1.0).min(cap) as u32;
    let ny = (duv_dy * s).length().ceil().max(1.0).min(cap) as u32;
    let (ddx, ddy) = (duv_dx / nx as f32, duv_dy / ny as f32);
    let lam = lambda(l0, ddx, ddy);
    let mut sum = Vec4::ZERO;
    for j in 0..ny {
        let fy = (j as f32 + 0.5) / ny as f32 - 0.5;
        for i in 0..nx {
            let fx = (i as f32 + 0.5) / nx as f32 - 0.5;
            sum += trilinear::<A>(tex, uv + duv_dx * fx + duv_dy * fy, lam);
        }
    }
    sum / (nx * ny) as f32
}
