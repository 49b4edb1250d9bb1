//! Four-pixel lane kernels (x86_64 SSE2, the baseline of the target: no runtime detection
//! needed) for the hot bulk paths of [`super`]: per-pixel trilinear (Seed 000 Eq. 2 + 4) on a
//! power-of-two pyramid, four pixels per call.
//!
//! The arithmetic is the scalar kernels' ([`super::trilinear_fp`], [`super::bilinear`],
//! [`super::log2_split`], [`super::floor_i32`], [`super::clampc`]) operation for operation, in
//! the same order and without fused multiply-adds, so every lane is BIT-IDENTICAL to the scalar
//! path (tested in `super::tests`). What the lanes buy is the shared work: the footprint, the
//! level split, the level sizes, the texel coordinates, floors, fractions and wrapped addresses
//! of four pixels take one instruction each instead of four; only the eight texel loads and
//! seven four-wide lerps per pixel stay per pixel.
//!
//! Other targets use the scalar kernels (same results).

use core::arch::x86_64::*;

use glam::{Vec2, Vec4};

use super::{Addr, COORD_LIMIT, lerp4, texel};
use crate::lanes::Isa;
use crate::mip::MipTexture;

/// Four `i32` lanes as an array (for the per-pixel scalar part).
#[inline(always)]
fn to_arr(v: __m128i) -> [i32; 4] {
    // SAFETY: __m128i and [i32; 4] have the same size and no invalid bit patterns.
    unsafe { core::mem::transmute::<__m128i, [i32; 4]>(v) }
}

/// Lane `j` of `v` in all four lanes (a register shuffle, no memory round trip).
#[inline(always)]
fn splat_lane(v: __m128, j: usize) -> Vec4 {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        Vec4::from(match j {
            0 => _mm_shuffle_ps::<0x00>(v, v),
            1 => _mm_shuffle_ps::<0x55>(v, v),
            2 => _mm_shuffle_ps::<0xAA>(v, v),
            _ => _mm_shuffle_ps::<0xFF>(v, v),
        })
    }
}

/// `⌊x⌋` per lane as `i32` and the fraction `x − ⌊x⌋`, for finite lanes with `|x| ≤ 2^30`:
/// [`super::floor_i32`] lane-wise (truncate, step down where truncation rounded up).
/// log2 of four positive floats split into ⌊log2 x⌋ (the exponent) and frac(log2 x) (the
/// mantissa polynomial), lane for lane the same operations as the scalar `log2_split`.
#[inline(always)]
pub(super) fn log2_split4(x: __m128) -> (__m128i, __m128) {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        let bits = _mm_castps_si128(x);
        let e = _mm_sub_epi32(
            _mm_and_si128(_mm_srli_epi32::<23>(bits), _mm_set1_epi32(0xff)),
            _mm_set1_epi32(127),
        );
        let t = _mm_sub_ps(
            _mm_castsi128_ps(_mm_or_si128(
                _mm_and_si128(bits, _mm_set1_epi32(0x007f_ffff)),
                _mm_set1_epi32(0x3f80_0000),
            )),
            _mm_set1_ps(1.0),
        );
        let c = |k: f32| _mm_set1_ps(k);
        let poly = _mm_add_ps(c(super::LOG2_C3), _mm_mul_ps(t, c(super::LOG2_C4)));
        let poly = _mm_add_ps(c(super::LOG2_C2), _mm_mul_ps(t, poly));
        let poly = _mm_add_ps(c(super::LOG2_C1), _mm_mul_ps(t, poly));
        (e, _mm_mul_ps(t, poly))
    }
}

#[inline(always)]
fn floor_frac(x: __m128) -> (__m128i, __m128) {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        let t = _mm_cvttps_epi32(x);
        let up = _mm_castps_si128(_mm_cmpgt_ps(_mm_cvtepi32_ps(t), x));
        let fl = _mm_add_epi32(t, up);
        (fl, _mm_sub_ps(x, _mm_cvtepi32_ps(fl)))
    }
}

/// [`super::clampc`] lane-wise: NaN -> −2^30, then clamp to ±2^30 (`maxps` returns its second
/// operand when the first is NaN).
#[inline(always)]
pub(super) fn clamp_coord(x: __m128) -> __m128 {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        _mm_min_ps(
            _mm_max_ps(x, _mm_set1_ps(-COORD_LIMIT)),
            _mm_set1_ps(COORD_LIMIT),
        )
    }
}

/// `Addr::wrap` on four lanes: `n` holds the level size per lane.
#[inline(always)]
pub(super) fn wrap4<A: Addr>(i: __m128i, n: __m128i) -> __m128i {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        let nm1 = _mm_sub_epi32(n, _mm_set1_epi32(1));
        if A::REPEAT {
            // Power-of-two levels only (the caller checks): a mask.
            _mm_and_si128(i, nm1)
        } else {
            // Clamp to 0..=n−1 with SSE2 compares (no pmaxsd/pminsd before SSE4.1).
            let pos = _mm_andnot_si128(_mm_cmplt_epi32(i, _mm_setzero_si128()), i);
            let over = _mm_cmpgt_epi32(pos, nm1);
            _mm_or_si128(_mm_and_si128(over, nm1), _mm_andnot_si128(over, pos))
        }
    }
}

/// One level's bilinear set-up for four lanes: wrapped columns/rows and weights
/// (Seed 000 Eq. 3 applied to `2^L r_m − ½`, Eq. 4's `(α, β)`).
struct LevelLanes {
    x0: [i32; 4],
    x1: [i32; 4],
    y0: [i32; 4],
    y1: [i32; 4],
    ax: __m128,
    ay: __m128,
}

/// Texel coordinates, floors, fractions and wrapped addresses of four lanes on the levels
/// `lvl` of a power-of-two pyramid whose level 0 is `2^nw x 2^nh`.
#[inline(always)]
fn level_lanes<A: Addr>(u: __m128, v: __m128, lvl: __m128i, nw: i32, nh: i32) -> LevelLanes {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        // Level size per lane: max(2^(n − i), 1), built from the float exponent (exact).
        let one = _mm_set1_ps(1.0);
        let wf = _mm_max_ps(
            _mm_castsi128_ps(_mm_slli_epi32::<23>(_mm_sub_epi32(
                _mm_set1_epi32(127 + nw),
                lvl,
            ))),
            one,
        );
        let hf = _mm_max_ps(
            _mm_castsi128_ps(_mm_slli_epi32::<23>(_mm_sub_epi32(
                _mm_set1_epi32(127 + nh),
                lvl,
            ))),
            one,
        );
        let half = _mm_set1_ps(0.5);
        // Texel coordinates with texel centres at integers: u·w − ½ (clamped like the scalar path).
        let x = clamp_coord(_mm_sub_ps(_mm_mul_ps(u, wf), half));
        let y = clamp_coord(_mm_sub_ps(_mm_mul_ps(v, hf), half));
        let (fx, ax) = floor_frac(x);
        let (fy, ay) = floor_frac(y);
        let (wi, hi) = (_mm_cvttps_epi32(wf), _mm_cvttps_epi32(hf));
        let one_i = _mm_set1_epi32(1);
        LevelLanes {
            x0: to_arr(wrap4::<A>(fx, wi)),
            x1: to_arr(wrap4::<A>(_mm_add_epi32(fx, one_i), wi)),
            y0: to_arr(wrap4::<A>(fy, hi)),
            y1: to_arr(wrap4::<A>(_mm_add_epi32(fy, one_i), hi)),
            ax,
            ay,
        }
    }
}

/// Bilinear of lane `j` on pyramid level `level` from the prepared lanes.
#[inline(always)]
fn bilinear_lane(tex: &MipTexture, level: usize, p: &LevelLanes, j: usize) -> Vec4 {
    let texels = tex.texels();
    // SAFETY (of the unchecked level access): levels come from `trilinear4`, clamped to `last`.
    debug_assert!(level < tex.level_count());
    let l = unsafe { tex.levels().get_unchecked(level) };
    let w = l.width as usize;
    let r0 = l.offset + p.y0[j] as usize * w;
    let r1 = l.offset + p.y1[j] as usize * w;
    let (x0, x1) = (p.x0[j] as usize, p.x1[j] as usize);
    let t00 = texel(texels, r0 + x0);
    let t10 = texel(texels, r0 + x1);
    let t01 = texel(texels, r1 + x0);
    let t11 = texel(texels, r1 + x1);
    let (ax, ay) = (splat_lane(p.ax, j), splat_lane(p.ay, j));
    lerp4(lerp4(t00, t10, ax), lerp4(t01, t11, ax), ay)
}

/// Seed 000 Eq. (4) for four pixels at once: `u`, `v` their map coordinates (map widths), `m`
/// their Eq. (2) footprints in level-0 texels (NaN lanes already 0). Bit-identical per lane to
/// [`super::trilinear_fp`]. The texture must be a power of two (`tex.is_pow2()`).
#[inline(always)]
pub(super) fn trilinear4<A: Addr>(tex: &MipTexture, u: Vec4, v: Vec4, m: Vec4) -> [Vec4; 4] {
    debug_assert!(tex.is_pow2());
    let last = tex.level_count() as i32 - 1;
    let nw = tex.width().trailing_zeros() as i32;
    let nh = tex.height().trailing_zeros() as i32;
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        let (u, v, m): (__m128, __m128, __m128) = (u.into(), v.into(), m.into());
        // λ = log2 m split into ⌊λ⌋ (exponent) and frac(λ) (mantissa polynomial), as log2_split.
        let (e, frac) = log2_split4(m);
        // Level pair per lane: magnification (λ ≤ 0, also NaN/0) -> level 0 alone; λ past the
        // top -> the top level alone; else (⌊λ⌋, ⌊λ⌋ + 1) blended by frac(λ).
        let minified = _mm_castps_si128(_mm_cmpgt_ps(m, _mm_set1_ps(1.0)));
        let past_top = _mm_cmpgt_epi32(e, _mm_set1_epi32(last - 1));
        let top = _mm_set1_epi32(last);
        let i0 = _mm_and_si128(
            minified,
            _mm_or_si128(_mm_and_si128(past_top, top), _mm_andnot_si128(past_top, e)),
        );
        let single = _mm_or_si128(_mm_andnot_si128(minified, _mm_set1_epi32(-1)), past_top);
        // i1 = i0 + 1 where a pair is blended (i0 where single: computed, never read).
        let i1 = _mm_sub_epi32(i0, _mm_andnot_si128(single, _mm_set1_epi32(-1)));
        let p0 = level_lanes::<A>(u, v, i0, nw, nh);
        let p1 = level_lanes::<A>(u, v, i1, nw, nh);
        let lv0 = to_arr(i0);
        let single = _mm_movemask_ps(_mm_castsi128_ps(single));
        let mut out = [Vec4::ZERO; 4];
        for j in 0..4 {
            let a = bilinear_lane(tex, lv0[j] as usize, &p0, j);
            out[j] = if single & (1 << j) != 0 {
                a
            } else {
                let b = bilinear_lane(tex, lv0[j] as usize + 1, &p1, j);
                lerp4(a, b, splat_lane(frac, j))
            };
        }
        out
    }
}

/// Eq. (2)'s footprint `max |∂(u·w0, v·h0)/∂(x_s, y_s)|` of four pixels, NaN terms as 0 (the
/// scalar `f32::max` chain ignores NaN the same way; an all-NaN footprint is level 0 in both).
#[inline(always)]
pub(super) fn footprint4(w0: f32, h0: f32, dx: &[Vec2], dy: &[Vec2]) -> Vec4 {
    let (dxu, dxv) = deinterleave(dx);
    let (dyu, dyv) = deinterleave(dy);
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        let abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff));
        let z = _mm_setzero_ps();
        let (sw, sh) = (_mm_set1_ps(w0), _mm_set1_ps(h0));
        let a = |d: __m128, s: __m128| _mm_max_ps(_mm_and_ps(_mm_mul_ps(d, s), abs), z);
        Vec4::from(_mm_max_ps(
            _mm_max_ps(a(dxu, sw), a(dyu, sw)),
            _mm_max_ps(a(dxv, sh), a(dyv, sh)),
        ))
    }
}

/// Four `Vec2` as `(x lanes, y lanes)`.
#[inline(always)]
pub(super) fn deinterleave(p: &[Vec2]) -> (__m128, __m128) {
    debug_assert!(p.len() >= 4);
    // SAFETY: SSE2 is part of the x86_64 baseline; `p` holds at least four Vec2 (8 bytes each,
    // `repr(C)` x, y), read unaligned.
    unsafe {
        let ptr = p.as_ptr() as *const f32;
        let a = _mm_loadu_ps(ptr);
        let b = _mm_loadu_ps(ptr.add(4));
        (
            _mm_shuffle_ps::<0b10_00_10_00>(a, b),
            _mm_shuffle_ps::<0b11_01_11_01>(a, b),
        )
    }
}

/// [`trilinear4`] over a run of pixels (whole chunks of four; the caller does the tail).
#[inline(always)]
pub(super) fn trilinear_pixels<A: Addr>(
    tex: &MipTexture,
    uv: &[Vec2],
    dx: &[Vec2],
    dy: &[Vec2],
    out: &mut [Vec4],
) -> usize {
    let l0 = &tex.levels()[0];
    let (w0, h0) = (l0.width_f, l0.height_f);
    let n = uv.len().min(dx.len()).min(dy.len()).min(out.len()) / 4 * 4;
    for ((o, p), (a, b)) in out[..n]
        .chunks_exact_mut(4)
        .zip(uv[..n].chunks_exact(4))
        .zip(dx[..n].chunks_exact(4).zip(dy[..n].chunks_exact(4)))
    {
        let (u, v) = deinterleave(p);
        let m = footprint4(w0, h0, a, b);
        let r = trilinear4::<A>(tex, Vec4::from(u), Vec4::from(v), m);
        o.copy_from_slice(&r);
    }
    n
}

// ---------------------------------------------------------------------------------------------
// Span sampler, four spans per step (Seed 000 Eq. 8–10).

/// Lane `s` of `v` as an `i32` (small lane-index helper for the per-span scalar part).
#[inline(always)]
fn lane_i32(v: &[i32; 4], s: usize) -> i32 {
    v[s]
}

/// `[a0 a1 a2 a3], [b..], [c..], [d..]` -> the four columns (a 4x4 transpose).
#[inline(always)]
pub(super) fn transpose(a: __m128, b: __m128, c: __m128, d: __m128) -> [__m128; 4] {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        let t0 = _mm_unpacklo_ps(a, b); // a0 b0 a1 b1
        let t1 = _mm_unpacklo_ps(c, d); // c0 d0 c1 d1
        let t2 = _mm_unpackhi_ps(a, b); // a2 b2 a3 b3
        let t3 = _mm_unpackhi_ps(c, d); // c2 d2 c3 d3
        [
            _mm_movelh_ps(t0, t1),
            _mm_movehl_ps(t1, t0),
            _mm_movelh_ps(t2, t3),
            _mm_movehl_ps(t3, t2),
        ]
    }
}

/// [`super::clamp4`] lane-wise: NaN -> 0, then clamp to ±2^30.
#[inline(always)]
pub(super) fn clamp_nan0(v: __m128) -> __m128 {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        let v = _mm_and_ps(_mm_cmpeq_ps(v, v), v);
        _mm_min_ps(
            _mm_max_ps(v, _mm_set1_ps(-COORD_LIMIT)),
            _mm_set1_ps(COORD_LIMIT),
        )
    }
}

#[inline(always)]
fn min4(v: &[__m128; 4]) -> __m128 {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe { _mm_min_ps(_mm_min_ps(v[0], v[1]), _mm_min_ps(v[2], v[3])) }
}

#[inline(always)]
fn max4(v: &[__m128; 4]) -> __m128 {
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe { _mm_max_ps(_mm_max_ps(v[0], v[1]), _mm_max_ps(v[2], v[3])) }
}

/// `⌊v⌋` lane-wise as floats ([`super::floor4`]: truncate, step down where truncation rounded up).
#[inline(always)]
fn floor_f(v: __m128) -> __m128 {
    let (fl, _) = floor_frac(v);
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe { _mm_cvtepi32_ps(fl) }
}

/// One level of four spans (lanes = spans), per pixel `j`: the offset `oy·w + ox` of its texel
/// from the window corner and its weights; per span the corner index; `ok` is the lane mask of
/// spans whose window is interior and holds every neighbourhood.
struct SpanLevel4 {
    idx: [[i32; 4]; 4],
    ax: [__m128; 4],
    ay: [__m128; 4],
    corner: [usize; 4],
    width: [usize; 4],
    ok: i32,
}

/// Seed 000 Eq. (10) for four spans at levels `lvl` (lanes = spans) of a power-of-two pyramid,
/// with [`super::span_level`]'s arithmetic per lane.
#[inline(always)]
fn span_level4<A: Addr, const K: usize>(
    tex: &MipTexture,
    lvl: __m128i,
    sx: &[__m128; 4],
    sy: &[__m128; 4],
) -> SpanLevel4 {
    let l0 = &tex.levels()[0];
    let nw = tex.width().trailing_zeros() as i32;
    let nh = tex.height().trailing_zeros() as i32;
    // SAFETY: SSE2 is part of the x86_64 baseline.
    unsafe {
        // Level scale (exactly w_i / w_0 = max(2^−i, 1/w_0)) and size per lane.
        let pow = |base: i32| {
            _mm_castsi128_ps(_mm_slli_epi32::<23>(_mm_sub_epi32(
                _mm_set1_epi32(base),
                lvl,
            )))
        };
        let scx = _mm_max_ps(pow(127), _mm_set1_ps(l0.inv_width_f));
        let scy = _mm_max_ps(pow(127), _mm_set1_ps(l0.inv_height_f));
        let one = _mm_set1_ps(1.0);
        let wf = _mm_max_ps(pow(127 + nw), one);
        let hf = _mm_max_ps(pow(127 + nh), one);
        let half = _mm_set1_ps(0.5);
        let mut flx = [_mm_setzero_ps(); 4];
        let mut fly = [_mm_setzero_ps(); 4];
        let mut ax = [_mm_setzero_ps(); 4];
        let mut ay = [_mm_setzero_ps(); 4];
        for j in 0..4 {
            let mut x = _mm_sub_ps(_mm_mul_ps(sx[j], scx), half);
            let mut y = _mm_sub_ps(_mm_mul_ps(sy[j], scy), half);
            if !A::REPEAT {
                // Clamp-to-edge bilinear equals bilinear at the clamped coordinate.
                x = _mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), _mm_sub_ps(wf, one));
                y = _mm_min_ps(_mm_max_ps(y, _mm_setzero_ps()), _mm_sub_ps(hf, one));
            }
            flx[j] = floor_f(x);
            fly[j] = floor_f(y);
            ax[j] = _mm_sub_ps(x, flx[j]);
            ay[j] = _mm_sub_ps(y, fly[j]);
        }
        // The window corner: the span's lowest texel.
        let (mx, my) = (min4(&flx), min4(&fly));
        let lim = _mm_set1_ps((K - 2) as f32);
        let mut over = _mm_setzero_ps();
        let mut idx = [[0i32; 4]; 4];
        for j in 0..4 {
            let ox = _mm_sub_ps(flx[j], mx);
            let oy = _mm_sub_ps(fly[j], my);
            over = _mm_or_ps(
                over,
                _mm_or_ps(_mm_cmpgt_ps(ox, lim), _mm_cmpgt_ps(oy, lim)),
            );
            // oy·w + ox: small non-negative integers, exact in f32.
            idx[j] = to_arr(_mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(oy, wf), ox)));
        }
        let (x0, y0) = (_mm_cvttps_epi32(mx), _mm_cvttps_epi32(my));
        let (wi, hi) = (_mm_cvttps_epi32(wf), _mm_cvttps_epi32(hf));
        let k = _mm_set1_epi32(K as i32);
        // Interior: x0 ≥ 0, y0 ≥ 0, x0 + K ≤ w, y0 + K ≤ h.
        let outside = _mm_or_si128(
            _mm_or_si128(
                _mm_cmplt_epi32(x0, _mm_setzero_si128()),
                _mm_cmplt_epi32(y0, _mm_setzero_si128()),
            ),
            _mm_or_si128(
                _mm_cmpgt_epi32(_mm_add_epi32(x0, k), wi),
                _mm_cmpgt_epi32(_mm_add_epi32(y0, k), hi),
            ),
        );
        let bad = _mm_or_ps(over, _mm_castsi128_ps(outside));
        let ok = !_mm_movemask_ps(bad) & 0xf;
        let (lv, x0, y0, wi) = (to_arr(lvl), to_arr(x0), to_arr(y0), to_arr(wi));
        let mut corner = [0usize; 4];
        let mut width = [0usize; 4];
        for s in 0..4 {
            if ok & (1 << s) != 0 {
                let l = &tex.levels()[lane_i32(&lv, s) as usize];
                let w = lane_i32(&wi, s) as usize;
                corner[s] = l.offset + lane_i32(&y0, s) as usize * w + lane_i32(&x0, s) as usize;
                width[s] = w;
            }
        }
        SpanLevel4 {
            idx,
            ax,
            ay,
            corner,
            width,
            ok,
        }
    }
}

/// Bilinear of pixel `j` of span `s` from an interior window.
#[inline(always)]
fn span_pixel(t: &[Vec4], d: &SpanLevel4, s: usize, j: usize) -> Vec4 {
    let i = d.corner[s] + d.idx[j][s] as usize;
    let w = d.width[s];
    let t00 = texel(t, i);
    let t10 = texel(t, i + 1);
    let t01 = texel(t, i + w);
    let t11 = texel(t, i + w + 1);
    let ax = splat_lane(d.ax[j], s);
    let ay = splat_lane(d.ay[j], s);
    lerp4(lerp4(t00, t10, ax), lerp4(t01, t11, ax), ay)
}

/// The span sampler over four spans per step on a power-of-two pyramid (lanes = spans): Eq. (8)'s
/// images, Eq. (9)'s level pair and Eq. (10)'s windows computed for four spans at once, then
/// each pixel's two bilinear samples and the Eq. (4) blend. Bit-identical to
/// [`super::span_quad`] (the bank emulator's arithmetic); spans whose window crosses a level
/// edge take that generic path. Returns how many quads were done (whole groups of four).
#[inline(always)]
pub(super) fn span_quads4<A: Addr, const K: usize>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) -> usize {
    debug_assert!(tex.is_pow2());
    let l0 = &tex.levels()[0];
    let last = tex.level_count() as i32 - 1;
    let texels = tex.texels();
    let n = quads.len().min(out.len()) / 4 * 4;
    for (o, q) in out[..n].chunks_exact_mut(4).zip(quads[..n].chunks_exact(4)) {
        // SAFETY: SSE2 is part of the x86_64 baseline; each quad is 4 Vec2 = 8 floats, read
        // unaligned.
        unsafe {
            // Load the 16 images and transpose: x[j], y[j] hold pixel j of the four spans.
            let ld = |s: usize, h: usize| _mm_loadu_ps((q[s].as_ptr() as *const f32).add(4 * h));
            let xy01 = transpose(ld(0, 0), ld(1, 0), ld(2, 0), ld(3, 0)); // x0 y0 x1 y1
            let xy23 = transpose(ld(0, 1), ld(1, 1), ld(2, 1), ld(3, 1)); // x2 y2 x3 y3
            let (sw, sh) = (_mm_set1_ps(l0.width_f), _mm_set1_ps(l0.height_f));
            let mut sx = [
                clamp_nan0(_mm_mul_ps(xy01[0], sw)),
                clamp_nan0(_mm_mul_ps(xy01[2], sw)),
                clamp_nan0(_mm_mul_ps(xy23[0], sw)),
                clamp_nan0(_mm_mul_ps(xy23[2], sw)),
            ];
            let mut sy = [
                clamp_nan0(_mm_mul_ps(xy01[1], sh)),
                clamp_nan0(_mm_mul_ps(xy01[3], sh)),
                clamp_nan0(_mm_mul_ps(xy23[1], sh)),
                clamp_nan0(_mm_mul_ps(xy23[3], sh)),
            ];
            if A::REPEAT {
                // Shift each span by whole periods so its corner lies in the first period.
                let px = _mm_mul_ps(
                    floor_f(_mm_mul_ps(min4(&sx), _mm_set1_ps(l0.inv_width_f))),
                    sw,
                );
                let py = _mm_mul_ps(
                    floor_f(_mm_mul_ps(min4(&sy), _mm_set1_ps(l0.inv_height_f))),
                    sh,
                );
                for j in 0..4 {
                    sx[j] = _mm_sub_ps(sx[j], px);
                    sy[j] = _mm_sub_ps(sy[j], py);
                }
            }
            // Seed 000 Eq. (9): span level from the extent of the four images.
            let ext = _mm_max_ps(
                _mm_sub_ps(max4(&sx), min4(&sx)),
                _mm_sub_ps(max4(&sy), min4(&sy)),
            );
            let (e, frac) = log2_split4(ext);
            // K = 3 takes the pair one level coarser (see the module doc's level policy).
            let fine = _mm_add_epi32(e, _mm_set1_epi32(if K == 3 { 1 } else { 0 }));
            let below = _mm_cmplt_epi32(fine, _mm_setzero_si128());
            let above = _mm_cmpgt_epi32(fine, _mm_set1_epi32(last - 1));
            let top = _mm_set1_epi32(last);
            let i0 = _mm_andnot_si128(
                below,
                _mm_or_si128(_mm_and_si128(above, top), _mm_andnot_si128(above, fine)),
            );
            // Blend two levels unless clamped to the pyramid or frac(λ) = 0.
            let clamped = _mm_or_si128(below, above);
            let zero_t = _mm_castps_si128(_mm_cmpeq_ps(frac, _mm_setzero_ps()));
            let single = _mm_movemask_ps(_mm_castsi128_ps(_mm_or_si128(clamped, zero_t)));
            let i1 = _mm_sub_epi32(i0, _mm_andnot_si128(clamped, _mm_set1_epi32(-1)));
            let a = span_level4::<A, K>(tex, i0, &sx, &sy);
            let b = span_level4::<A, K>(tex, i1, &sx, &sy);
            let fast = a.ok & (b.ok | single);
            for s in 0..4 {
                if fast & (1 << s) == 0 {
                    // A window crossing a level edge (or a conflict): the generic path.
                    o[s] =
                        super::span_quad::<A, super::Direct, K>(tex, q[s], 0, &mut super::Direct);
                    continue;
                }
                if single & (1 << s) != 0 {
                    for (j, oj) in o[s].iter_mut().enumerate() {
                        *oj = span_pixel(texels, &a, s, j);
                    }
                } else {
                    let tt = splat_lane(frac, s);
                    for (j, oj) in o[s].iter_mut().enumerate() {
                        let ca = span_pixel(texels, &a, s, j);
                        let cb = span_pixel(texels, &b, s, j);
                        *oj = lerp4(ca, cb, tt);
                    }
                }
            }
        }
    }
    n
}

// ---------------------------------------------------------------------------------------------
// Entry points: the same kernels compiled twice, for the SSE2 baseline and (chosen at run time)
// for AVX2, whose three-operand encoding drops the register copies SSE2's two-operand form needs
// (same instructions otherwise: no FMA, so the results are the same bits).

/// Whether the AVX2 build of the kernels can run here ([`crate::lanes::isa`]).
#[inline]
pub(super) fn has_avx2() -> bool {
    Isa::Avx2.enabled()
}

/// Whether the AVX-512 build of the kernels (F, VL, BW, DQ) can run here
/// ([`crate::lanes::isa`]).
#[inline]
pub(super) fn has_avx512() -> bool {
    Isa::Avx512.enabled()
}

/// Whether bulk per-pixel trilinear takes its AVX-512 build where the CPU has AVX-512: sixteen
/// pixels per step with the set-up in 512-bit lanes (`avx512::trilinear_pixels_x16`), then the
/// AVX2 build on a last group of eight. On: on the Sapphire Rapids-class Xeon it was built and
/// measured on (load ~1.5), interleaved best-frame thread CPU per sample (12 rounds each,
/// alternating) was median 8.35 / min 6.12 ns against the AVX2 build's 10.00 / 7.94, and
/// criterion `trilinear` (two runs, alternating) 124.6 / 115.7 M/s wall against 95.2 / 94.5
/// (thread CPU 134.1 / 113.9 against 92.9 / 119.4). The earlier AVX-512 build, eight pixels per
/// step with the AVX2 set-up compiled for AVX-512 (256-bit set-up beside 512-bit µops), had
/// been slower than the AVX2 build (~12.5–16 ns against ~8–9; docs/PERFORMANCE.md, "Designs
/// rejected") and was dropped. The kernel is tested bit for bit against the SSE2
/// baseline (`avx512_lane_builds_match_the_sse2_baseline_bit_for_bit`).
const TRILINEAR_AVX512: bool = true;

/// [`trilinear_pixels`] compiled for AVX2.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2")]
unsafe fn trilinear_pixels_avx2<A: Addr>(
    tex: &MipTexture,
    uv: &[Vec2],
    dx: &[Vec2],
    dy: &[Vec2],
    out: &mut [Vec4],
) -> usize {
    // SAFETY: this function's own contract (AVX2 present); the callers check `tex.is_pow2()`.
    unsafe { super::avx2::trilinear_pixels::<A>(tex, uv, dx, dy, out) }
}

/// [`span_quads4`] compiled for AVX2.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2")]
unsafe fn span_quads4_avx2<A: Addr, const K: usize>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) -> usize {
    // SAFETY: this function's own contract (AVX2 present); the callers check `tex.is_pow2()`.
    unsafe { super::avx2::span_quads::<A, K>(tex, quads, out) }
}

/// Bulk per-pixel trilinear in lanes, the build chosen for this CPU; returns the pixels done.
pub(super) fn trilinear_pixels_best<A: Addr>(
    tex: &MipTexture,
    uv: &[Vec2],
    dx: &[Vec2],
    dy: &[Vec2],
    out: &mut [Vec4],
) -> usize {
    if TRILINEAR_AVX512 && has_avx512() {
        // Sixteen pixels per step (the set-up in 512-bit lanes), then the AVX2 build on what is
        // left (the caller does the last < 8 pixels).
        // SAFETY: AVX-512F/VL/BW/DQ (so AVX2) were detected just above; the callers check
        // `tex.is_pow2()`.
        unsafe {
            let n = super::avx512::trilinear_pixels_x16::<A>(tex, uv, dx, dy, out);
            let rest = (&uv[n..], &dx[n..], &dy[n..], &mut out[n..]);
            n + trilinear_pixels_avx2::<A>(tex, rest.0, rest.1, rest.2, rest.3)
        }
    } else if has_avx2() {
        // SAFETY: AVX2 was detected just above.
        unsafe { trilinear_pixels_avx2::<A>(tex, uv, dx, dy, out) }
    } else {
        trilinear_pixels::<A>(tex, uv, dx, dy, out)
    }
}

/// Bulk span sampling in lanes, the build chosen for this CPU; returns the quads done.
pub(super) fn span_quads4_best<A: Addr, const K: usize>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) -> usize {
    if K == 3 && has_avx512() {
        // Sixteen spans per step (the set-up in 512-bit lanes), then the eight-span kernel on
        // what is left (the caller does the last < 8 spans).
        // SAFETY: AVX-512F/VL/BW/DQ were detected just above; the callers check `tex.is_pow2()`.
        unsafe {
            let n = super::avx512::span_quads_k3_x16::<A>(tex, quads, out);
            n + super::avx512::span_quads_k3::<A>(tex, &quads[n..], &mut out[n..])
        }
    } else if has_avx2() {
        // SAFETY: AVX2 was detected just above.
        unsafe { span_quads4_avx2::<A, K>(tex, quads, out) }
    } else {
        span_quads4::<A, K>(tex, quads, out)
    }
}
