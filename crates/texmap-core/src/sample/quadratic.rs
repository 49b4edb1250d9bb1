//! The quadratic 3x3 sampler ([`Sampler::Quadratic3`]): per level, separable 3-point Lagrange
//! (quadratic) interpolation on the 3x3 texels around the pixel's nearest texel, clamped to
//! [0, 1]; the levels and their blend are trilinear's (Seed 000 Eq. 2 and 4).
//!
//! On one level, with texel centres at integers, the pixel's texel coordinate `x = u·w − ½` is
//! split into its nearest texel `c = round(x)` (half away from zero) and `d = x − c ∈ [−½, ½]`;
//! the texels `c − 1, c, c + 1` get the Lagrange weights
//! `(½d(d − 1), 1 − d², ½d(d + 1))` (they sum to 1 and reproduce any quadratic exactly), each row
//! of three is weighted along x, the three rows along y, and the sum is clamped to [0, 1] (the
//! negative lobes can overshoot an edge). Texel addresses are wrapped by the texture's [`Wrap`]
//! (the `Addr` kernels), exactly as bilinear's.
//!
//! Two forms with the same arithmetic, tested bit for bit against each other:
//! - [`quadratic_fp`]: one pixel (the scalar reference, used by [`Sampler::sample`]);
//! - [`quadratic_quad`]: a 2x2 quad, whose four pixels share the footprint of the quad's coarse
//!   derivatives and so one level pair: the level decision once, the coordinates, nearest
//!   texels, fractions and the six weights of the four pixels in the lanes of one `Vec4` each,
//!   then per pixel its nine texel loads and the weighted sums (RGBA in the lanes). Where the
//!   wrapped nearest texels of the quad's four pixels all lie at least one texel inside the
//!   level (almost always), each pixel takes one index and reads `index + {0, 1, 2} +
//!   w·{0, 1, 2}`; otherwise three wrapped columns and three wrapped rows per pixel.

use super::*;

/// `(c, d)`: `c = round(x)` (half away from zero, as `f32::round`) and `d = x − c`, for finite
/// `|x| ≤ 2^30`; `c` as a float (integer-valued).
#[inline(always)]
fn round_split(x: f32) -> (f32, f32) {
    let a = x.abs();
    // a ≥ 0: truncation is the floor; a − ⌊a⌋ is exact.
    let fl = floor_i32(a) as f32;
    let ca = fl + if a - fl >= 0.5 { 1.0 } else { 0.0 };
    let c = ca.copysign(x);
    (c, x - c)
}

/// [`round_split`] on four lanes (the same operations lane by lane).
#[inline(always)]
fn round_split4(x: Vec4) -> (Vec4, Vec4) {
    let a = x.abs();
    let fl = trunc_lanes(a);
    let ca = fl + Vec4::select((a - fl).cmpge(Vec4::splat(0.5)), Vec4::ONE, Vec4::ZERO);
    let c = ca.copysign(x);
    (c, x - c)
}

/// The three Lagrange weights of the texels at offsets −1, 0, +1 from the nearest texel, for a
/// fraction `d` from it.
#[inline(always)]
fn weights(d: f32) -> [f32; 3] {
    [0.5 * d * (d - 1.0), 1.0 - d * d, 0.5 * d * (d + 1.0)]
}

/// [`weights`] on four lanes.
#[inline(always)]
fn weights4(d: Vec4) -> [Vec4; 3] {
    let h = Vec4::splat(0.5) * d;
    [h * (d - Vec4::ONE), Vec4::ONE - d * d, h * (d + Vec4::ONE)]
}

/// The 3x3 sum of one pixel: its texels are `t[rows[j] + cols[i]]`, `wx`, `wy` its weights
/// splatted to RGBA; clamped to [0, 1].
#[inline(always)]
fn sum3x3(t: &[Vec4], rows: [usize; 3], cols: [usize; 3], wx: [Vec4; 3], wy: [Vec4; 3]) -> Vec4 {
    let row = |r: usize| {
        texel(t, r + cols[0]) * wx[0]
            + texel(t, r + cols[1]) * wx[1]
            + texel(t, r + cols[2]) * wx[2]
    };
    let s = row(rows[0]) * wy[0] + row(rows[1]) * wy[1] + row(rows[2]) * wy[2];
    s.max(Vec4::ZERO).min(Vec4::ONE)
}

/// One level, one pixel at `uv` (map widths).
#[inline(always)]
pub(super) fn quadratic_level<A: Addr>(texels: &[Vec4], l: &LevelInfo, uv: Vec2) -> Vec4 {
    let (cx, dx) = round_split(clampc(uv.x * l.width_f - 0.5));
    let (cy, dy) = round_split(clampc(uv.y * l.height_f - 0.5));
    // Integer-valued and within ±2^30 (clampc): exact.
    let (cx, cy) = (cx as i32, cy as i32);
    let (w, h) = (l.width as i32, l.height as i32);
    let col = |x: i32| A::wrap(x, w) as usize;
    let row = |y: i32| l.offset + (A::wrap(y, h) * w) as usize;
    let ([wx0, wx1, wx2], [wy0, wy1, wy2]) = (weights(dx), weights(dy));
    sum3x3(
        texels,
        [row(cy - 1), row(cy), row(cy + 1)],
        [col(cx - 1), col(cx), col(cx + 1)],
        [Vec4::splat(wx0), Vec4::splat(wx1), Vec4::splat(wx2)],
        [Vec4::splat(wy0), Vec4::splat(wy1), Vec4::splat(wy2)],
    )
}

/// The level pair of a footprint `m` (level-0 texels): trilinear's decision
/// ([`trilinear_fp`]): magnification, zero or NaN -> level 0 alone; past the top -> the top
/// level alone (`None` as the blend); else `(⌊λ⌋, Some(frac λ))` with λ = log2 m split by
/// [`log2_split`].
#[inline(always)]
// `!(a > b)` on purpose: NaN must take the fallback branch.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn levels_of(last: usize, m: f32) -> (usize, Option<f32>) {
    if !(m > 1.0) {
        return (0, None);
    }
    let (i, f) = log2_split(m);
    let i = i as usize;
    if i >= last {
        (last, None)
    } else {
        (i, Some(f))
    }
}

/// One pixel: the quadratic 3x3 of levels ⌊λ⌋ and ⌊λ⌋ + 1 blended by frac(λ), clamped to the
/// pyramid, `m` the footprint in level-0 texels (as [`trilinear_fp`]).
#[inline(always)]
pub(super) fn quadratic_fp<A: Addr>(tex: &MipTexture, uv: Vec2, m: f32) -> Vec4 {
    let levels = tex.levels();
    let texels = tex.texels();
    match levels_of(levels.len() - 1, m) {
        (i, None) => quadratic_level::<A>(texels, &levels[i], uv),
        (i, Some(f)) => {
            let a = quadratic_level::<A>(texels, &levels[i], uv);
            let b = quadratic_level::<A>(texels, &levels[i + 1], uv);
            lerp(a, b, f)
        }
    }
}

/// Levels of at most this many texels take each pixel's index within the level in f32 lanes
/// (exact below 2^24); larger ones in integers. Lowered in tests so that both paths run on
/// small pyramids.
const FLOAT_INDEX_TEXELS: usize = if cfg!(test) { 1 << 8 } else { 1 << 24 };

/// One level of a quad: every pixel's nearest texel and weights, from the pixels' `u`, `v` in
/// lanes, and (when every pixel's 3x3 lies inside the level) the index of each pixel's first
/// texel of its 3x3.
struct QuadLevel {
    /// `offset + (y − 1)·w + x − 1` of each pixel's wrapped nearest texel `(x, y)`, when
    /// `interior`.
    corner: [usize; 4],
    width: usize,
    wx: [Vec4; 3],
    wy: [Vec4; 3],
    /// Whether every pixel's wrapped nearest texel lies at least one texel inside the level, so
    /// that its 3x3 is `corner + {0, 1, 2} + w·{0, 1, 2}` (no wrapping needed).
    interior: bool,
}

#[inline(always)]
fn quad_level<A: Addr>(l: &LevelInfo, u: Vec4, v: Vec4) -> QuadLevel {
    // clampc lane-wise (NaN -> −2^30: `max` returns its second operand on NaN, as `maxps`).
    let lim = Vec4::splat(COORD_LIMIT);
    let x = (u * Vec4::splat(l.width_f) - Vec4::splat(0.5))
        .max(-lim)
        .min(lim);
    let y = (v * Vec4::splat(l.height_f) - Vec4::splat(0.5))
        .max(-lim)
        .min(lim);
    let (cxf, dx) = round_split4(x);
    let (cyf, dy) = round_split4(y);
    // Wrapping the centre wraps its neighbours with it while 1 ≤ centre ≤ size − 2 (Repeat is
    // periodic, Clamp leaves that range alone).
    let xw = A::wrap_lanes(cxf, l.width_f, l.inv_width_f);
    let yw = A::wrap_lanes(cyf, l.height_f, l.inv_height_f);
    let one = Vec4::ONE;
    let interior = (xw.cmpge(one)
        & xw.cmple(Vec4::splat(l.width_f - 2.0))
        & yw.cmpge(one)
        & yw.cmple(Vec4::splat(l.height_f - 2.0)))
    .all();
    let mut corner = [0usize; 4];
    let width = l.width as usize;
    if interior {
        if width * l.height as usize <= FLOAT_INDEX_TEXELS {
            // (y − 1)·w + x − 1 < 2^24: exact in f32.
            let i = lanes_i32((yw - one) * Vec4::splat(l.width_f) + (xw - one));
            for j in 0..4 {
                corner[j] = l.offset + i[j] as usize;
            }
        } else {
            let (xi, yi) = (lanes_i32(xw - one), lanes_i32(yw - one));
            for j in 0..4 {
                corner[j] = l.offset + yi[j] as usize * width + xi[j] as usize;
            }
        }
    }
    QuadLevel {
        corner,
        width,
        wx: weights4(dx),
        wy: weights4(dy),
        interior,
    }
}

/// Lane `j` of `v` in all four lanes (`j` a constant after inlining).
#[inline(always)]
fn lane(v: Vec4, j: usize) -> Vec4 {
    match j {
        0 => v.xxxx(),
        1 => v.yyyy(),
        2 => v.zzzz(),
        _ => v.wwww(),
    }
}

/// Pixel `j` of an interior quad level.
#[inline(always)]
fn interior_pixel(t: &[Vec4], p: &QuadLevel, j: usize) -> Vec4 {
    // The 3x3 from its first texel (one slice per pixel: each texel then sits at a constant
    // offset from the slice's start, which the loads take as their displacement).
    let w = p.width;
    sum3x3(
        &t[p.corner[j]..],
        [0, w, 2 * w],
        [0, 1, 2],
        [lane(p.wx[0], j), lane(p.wx[1], j), lane(p.wx[2], j)],
        [lane(p.wy[0], j), lane(p.wy[1], j), lane(p.wy[2], j)],
    )
}

/// The four pixels of a quad on one level, any position: [`quadratic_level`] per pixel (out of
/// line: rare).
#[inline(never)]
fn wrapped_pixels<A: Addr>(tex: &MipTexture, level: usize, uv: [Vec2; 4]) -> [Vec4; 4] {
    let (t, l) = (tex.texels(), &tex.levels()[level]);
    [
        quadratic_level::<A>(t, l, uv[0]),
        quadratic_level::<A>(t, l, uv[1]),
        quadratic_level::<A>(t, l, uv[2]),
        quadratic_level::<A>(t, l, uv[3]),
    ]
}

/// The four pixels of a quad on one level.
#[inline(always)]
fn quad_pixels<A: Addr>(tex: &MipTexture, level: usize, uv: [Vec2; 4], p: &QuadLevel) -> [Vec4; 4] {
    if !p.interior {
        return wrapped_pixels::<A>(tex, level, uv);
    }
    let t = tex.texels();
    [
        interior_pixel(t, p, 0),
        interior_pixel(t, p, 1),
        interior_pixel(t, p, 2),
        interior_pixel(t, p, 3),
    ]
}

/// A 2x2 quad `uv` whose pixels share the footprint `m` (level-0 texels, from the quad's coarse
/// derivatives): [`quadratic_fp`] for each pixel, the same bits, with the per-level set-up of
/// the four pixels in lanes.
#[inline(always)]
pub(super) fn quadratic_quad<A: Addr>(tex: &MipTexture, uv: [Vec2; 4], m: f32) -> [Vec4; 4] {
    let levels = tex.levels();
    let u = Vec4::new(uv[0].x, uv[1].x, uv[2].x, uv[3].x);
    let v = Vec4::new(uv[0].y, uv[1].y, uv[2].y, uv[3].y);
    let (i, f) = levels_of(levels.len() - 1, m);
    let pa = quad_level::<A>(&levels[i], u, v);
    let Some(f) = f else {
        return quad_pixels::<A>(tex, i, uv, &pa);
    };
    let pb = quad_level::<A>(&levels[i + 1], u, v);
    let f = Vec4::splat(f);
    let a = quad_pixels::<A>(tex, i, uv, &pa);
    let b = quad_pixels::<A>(tex, i + 1, uv, &pb);
    [
        lerp4(a[0], b[0], f),
        lerp4(a[1], b[1], f),
        lerp4(a[2], b[2], f),
        lerp4(a[3], b[3], f),
    ]
}
