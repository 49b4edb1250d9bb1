//! AVX2 builds of the two bulk lane kernels (chosen at run time by [`super::lanes`]'s `*_best`
//! entry points; the SSE2 kernels of `lanes.rs` stay the baseline): per-pixel trilinear, four
//! pixels per step, and the span sampler, four spans per step, on power-of-two pyramids.
//!
//! The arithmetic is the SSE2 kernels' operation for operation (no FMA), so the results are the
//! same bits (tested in `super::tests`). What changes is the bookkeeping around it, the same way
//! in both kernels so that their comparison stays fair:
//! - **texel indices in lanes, stored once:** the level's base index comes from a 16-entry table
//!   with two register permutes (`vpermd`), rows from `vpmulld`, and each pixel's texel indices
//!   (`offset + y·w + x`, doubled so that the load addresses `base + 8·index` need no shift) are
//!   stored to a small array once per four lanes: a pixel then costs one load per index, where
//!   the SSE2 kernels extract lanes, sign-extend, look the level up and multiply per pixel;
//! - **two pixels per 256-bit register:** the bilinear taps of two pixels are loaded into the two
//!   halves of one register and lerped together (each lane does exactly the 128-bit lerp), the
//!   weights of the pair come from one `vpermps`, and the pair is stored with one 256-bit store;
//! - **`roundps` floors** (SSE4.1, implied by AVX2) instead of the truncate-and-correct sequence
//!   (the same values: both are exact).
//!
//! The span kernel also takes what the paper's structure gives it and trilinear cannot: one level
//! pair, one blend weight, one window corner and one row stride per span, shared by its four
//! pixels (trilinear needs four texel indices per pixel and level because wrap-around may split
//! its 2x2; the span's interior window cannot split, so a pixel needs one index per level).

use core::arch::x86_64::*;

use glam::{Vec2, Vec4};

use super::Addr;
use super::lanes::{
    clamp_coord, clamp_nan0, deinterleave, footprint4, log2_split4, transpose, wrap4,
};
use crate::mip::MipTexture;

/// The level-offset table of a texture in two registers (levels 0–7 and 8–15).
#[derive(Clone, Copy)]
struct Offsets {
    lo: __m256i,
    hi: __m256i,
}

#[inline]
#[target_feature(enable = "avx2")]
fn offsets(tex: &MipTexture) -> Offsets {
    let t = tex.level_offsets16();
    // SAFETY: `t` holds 16 i32 (two unaligned 256-bit loads).
    unsafe {
        Offsets {
            lo: _mm256_loadu_si256(t.as_ptr() as *const __m256i),
            hi: _mm256_loadu_si256(t.as_ptr().add(8) as *const __m256i),
        }
    }
}

/// Texel index of level `lvl`'s texel (0, 0) per lane (`0 ≤ lvl < 16`).
#[inline]
#[target_feature(enable = "avx2")]
fn level_offset(t: Offsets, lvl: __m128i) -> __m128i {
    let l = _mm256_castsi128_si256(lvl);
    let a = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(t.lo, l));
    let b = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(t.hi, l));
    _mm_blendv_epi8(a, b, _mm_cmpgt_epi32(lvl, _mm_set1_epi32(7)))
}

/// Four `i32` lanes as an array (stored once, read per pixel).
#[inline(always)]
fn to_u32(v: __m128i) -> [u32; 4] {
    // SAFETY: same size, no invalid bit patterns.
    unsafe { core::mem::transmute::<__m128i, [u32; 4]>(v) }
}

/// The permute indices that spread lanes `a` and `b` of a 128-bit vector over the two halves.
#[inline]
#[target_feature(enable = "avx2")]
fn pair_idx(a: i32, b: i32) -> __m256i {
    _mm256_setr_epi32(a, a, a, a, b, b, b, b)
}

/// Lanes `a` and `b` of `v` spread over the two halves of a 256-bit register.
#[inline]
#[target_feature(enable = "avx2")]
fn pair_of(v: __m128, idx: __m256i) -> __m256 {
    _mm256_permutevar8x32_ps(_mm256_castps128_ps256(v), idx)
}

/// `a + (b − a)·t` lane-wise: the 128-bit `lerp4` on two pixels at once (same operations).
#[inline]
#[target_feature(enable = "avx2")]
fn lerp8(a: __m256, b: __m256, t: __m256) -> __m256 {
    _mm256_add_ps(a, _mm256_mul_ps(_mm256_sub_ps(b, a), t))
}

/// Texels `i0` (low half) and `i1` (high half): doubled texel indices, `base + 8·index`.
///
/// # Safety
/// Both indices must be inside the texel buffer (`index / 2 < len`).
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn load_pair(base: *const u8, i0: usize, i1: usize) -> __m256 {
    // SAFETY: the caller's contract; texels are 16-byte `Vec4`s, read unaligned-tolerant.
    unsafe {
        _mm256_loadu2_m128(
            base.add(i1 * 8) as *const f32,
            base.add(i0 * 8) as *const f32,
        )
    }
}

// ---------------------------------------------------------------------------------------------
// Per-pixel trilinear (Seed 000 Eq. 2 + 4), four pixels per step.

/// One level of four pixels: the doubled texel indices of their 2x2 taps and their weights.
struct TriLevel {
    /// `[t00, t10, t01, t11][lane]`.
    idx: [[u32; 4]; 4],
    ax: __m128,
    ay: __m128,
}

/// Seed 000 Eq. (3) on `2^L r_m − ½` for four pixels at levels `lvl`: the SSE2 `level_lanes`
/// arithmetic, then the texel indices in lanes.
#[inline]
#[target_feature(enable = "avx2")]
fn tri_level<A: Addr>(
    u: __m128,
    v: __m128,
    lvl: __m128i,
    nw: i32,
    nh: i32,
    offs: Offsets,
) -> TriLevel {
    // Level size per lane: max(2^(n − i), 1) from the float exponent (exact).
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
    // Texel coordinates with texel centres at integers, floors and Eq. (4) weights.
    let x = clamp_coord(_mm_sub_ps(_mm_mul_ps(u, wf), half));
    let y = clamp_coord(_mm_sub_ps(_mm_mul_ps(v, hf), half));
    let (flx, fly) = (_mm_floor_ps(x), _mm_floor_ps(y));
    let (ax, ay) = (_mm_sub_ps(x, flx), _mm_sub_ps(y, fly));
    let (fx, fy) = (_mm_cvttps_epi32(flx), _mm_cvttps_epi32(fly));
    let (wi, hi) = (_mm_cvttps_epi32(wf), _mm_cvttps_epi32(hf));
    let one_i = _mm_set1_epi32(1);
    // Wrapped columns and rows (Addr), then texel indices offset + y·w + x, doubled.
    let x0 = wrap4::<A>(fx, wi);
    let x1 = wrap4::<A>(_mm_add_epi32(fx, one_i), wi);
    let y0 = wrap4::<A>(fy, hi);
    let y1 = wrap4::<A>(_mm_add_epi32(fy, one_i), hi);
    let off = level_offset(offs, lvl);
    let r0 = _mm_add_epi32(off, _mm_mullo_epi32(y0, wi));
    let r1 = _mm_add_epi32(off, _mm_mullo_epi32(y1, wi));
    let d = |r: __m128i, c: __m128i| to_u32(_mm_slli_epi32::<1>(_mm_add_epi32(r, c)));
    TriLevel {
        idx: [d(r0, x0), d(r0, x1), d(r1, x0), d(r1, x1)],
        ax,
        ay,
    }
}

/// Bilinear of lanes `j`, `j + 1` of a prepared level (`ix`, `iy`: their weight permutes).
///
/// # Safety
/// `p` must come from [`tri_level`] on `tex` (indices inside the texel buffer).
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn tri_pair(base: *const u8, p: &TriLevel, j: usize, ix: __m256i) -> __m256 {
    // SAFETY: the caller's contract.
    unsafe {
        let t00 = load_pair(base, p.idx[0][j] as usize, p.idx[0][j + 1] as usize);
        let t10 = load_pair(base, p.idx[1][j] as usize, p.idx[1][j + 1] as usize);
        let t01 = load_pair(base, p.idx[2][j] as usize, p.idx[2][j + 1] as usize);
        let t11 = load_pair(base, p.idx[3][j] as usize, p.idx[3][j + 1] as usize);
        let (wx, wy) = (pair_of(p.ax, ix), pair_of(p.ay, ix));
        lerp8(lerp8(t00, t10, wx), lerp8(t01, t11, wx), wy)
    }
}

/// [`super::lanes::trilinear_pixels`] for AVX2: bit-identical, whole chunks of four pixels.
///
/// # Safety
/// The CPU must support AVX2; the texture must be a power of two (`tex.is_pow2()`).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn trilinear_pixels<A: Addr>(
    tex: &MipTexture,
    uv: &[Vec2],
    dx: &[Vec2],
    dy: &[Vec2],
    out: &mut [Vec4],
) -> usize {
    debug_assert!(tex.is_pow2());
    let l0 = &tex.levels()[0];
    let (w0, h0) = (l0.width_f, l0.height_f);
    let last = tex.level_count() as i32 - 1;
    let nw = tex.width().trailing_zeros() as i32;
    let nh = tex.height().trailing_zeros() as i32;
    let offs = offsets(tex);
    let base = tex.texels().as_ptr() as *const u8;
    let n = uv.len().min(dx.len()).min(dy.len()).min(out.len()) / 4 * 4;
    let ix = [pair_idx(0, 1), pair_idx(2, 3)];
    for ((o, p), (a, b)) in out[..n]
        .chunks_exact_mut(4)
        .zip(uv[..n].chunks_exact(4))
        .zip(dx[..n].chunks_exact(4).zip(dy[..n].chunks_exact(4)))
    {
        let (u, v) = deinterleave(p);
        let m: __m128 = footprint4(w0, h0, a, b).into();
        // Seed 000 Eq. (2): λ = log2 m split into ⌊λ⌋ and frac(λ); level pair as `trilinear4`.
        let (e, frac) = log2_split4(m);
        let minified = _mm_castps_si128(_mm_cmpgt_ps(m, _mm_set1_ps(1.0)));
        let past_top = _mm_cmpgt_epi32(e, _mm_set1_epi32(last - 1));
        let top = _mm_set1_epi32(last);
        let i0 = _mm_and_si128(
            minified,
            _mm_or_si128(_mm_and_si128(past_top, top), _mm_andnot_si128(past_top, e)),
        );
        let single_v = _mm_or_si128(_mm_andnot_si128(minified, _mm_set1_epi32(-1)), past_top);
        let i1 = _mm_sub_epi32(i0, _mm_andnot_si128(single_v, _mm_set1_epi32(-1)));
        let pa = tri_level::<A>(u, v, i0, nw, nh, offs);
        let pb = tri_level::<A>(u, v, i1, nw, nh, offs);
        let single = _mm_movemask_ps(_mm_castsi128_ps(single_v));
        for (k, ixk) in ix.iter().enumerate() {
            let j = 2 * k;
            let pair = (single >> j) & 3;
            // SAFETY: indices from `tri_level` on this texture; `o` holds four Vec4 (16 floats).
            unsafe {
                let ca = tri_pair(base, &pa, j, *ixk);
                let r = if pair == 3 {
                    ca
                } else {
                    // Seed 000 Eq. (4): blend the two levels by frac(λ); single lanes keep `ca`.
                    let cb = tri_pair(base, &pb, j, *ixk);
                    let r = lerp8(ca, cb, pair_of(frac, *ixk));
                    if pair == 0 {
                        r
                    } else {
                        _mm256_blendv_ps(r, ca, pair_of(_mm_castsi128_ps(single_v), *ixk))
                    }
                };
                _mm256_storeu_ps(o.as_mut_ptr().add(j) as *mut f32, r);
            }
        }
    }
    n
}

// ---------------------------------------------------------------------------------------------
// Span sampler (Seed 000 Eq. 8–10), four spans per step (lanes = spans).

/// One level of four spans: per pixel `j` and span `s` the doubled index of its 2x2's corner
/// texel (window corner + `oy·w + ox`), per span the doubled row stride and the weights of its
/// four pixels `[ax0 ax1 ax2 ax3 | ay0 ay1 ay2 ay3]`; `ok` as in the SSE2 `SpanLevel4`.
struct SpanLevel {
    idx: [[u32; 4]; 4],
    w2: [u32; 4],
    wts: [__m256; 4],
    ok: i32,
}

/// Seed 000 Eq. (10) for four spans at levels `lvl`: the SSE2 `span_level4` arithmetic, then
/// the indices in lanes and the weights transposed to one register per span.
#[inline]
#[target_feature(enable = "avx2")]
fn span_level<A: Addr, const K: usize>(
    tex: &MipTexture,
    lvl: __m128i,
    sx: &[__m128; 4],
    sy: &[__m128; 4],
    offs: Offsets,
) -> SpanLevel {
    let l0 = &tex.levels()[0];
    let nw = tex.width().trailing_zeros() as i32;
    let nh = tex.height().trailing_zeros() as i32;
    // Level scale (exactly w_i / w_0 = max(2^−i, 1/w_0)) and size per lane.
    let pow =
        |b: i32| _mm_castsi128_ps(_mm_slli_epi32::<23>(_mm_sub_epi32(_mm_set1_epi32(b), lvl)));
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
        // This level's texel coordinates (Eq. 3 on 2^L r_m − ½), floors and weights.
        let mut x = _mm_sub_ps(_mm_mul_ps(sx[j], scx), half);
        let mut y = _mm_sub_ps(_mm_mul_ps(sy[j], scy), half);
        if !A::REPEAT {
            // Clamp-to-edge bilinear equals bilinear at the clamped coordinate.
            x = _mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), _mm_sub_ps(wf, one));
            y = _mm_min_ps(_mm_max_ps(y, _mm_setzero_ps()), _mm_sub_ps(hf, one));
        }
        flx[j] = _mm_floor_ps(x);
        fly[j] = _mm_floor_ps(y);
        ax[j] = _mm_sub_ps(x, flx[j]);
        ay[j] = _mm_sub_ps(y, fly[j]);
    }
    // The window corner: the span's lowest texel.
    let mx = _mm_min_ps(_mm_min_ps(flx[0], flx[1]), _mm_min_ps(flx[2], flx[3]));
    let my = _mm_min_ps(_mm_min_ps(fly[0], fly[1]), _mm_min_ps(fly[2], fly[3]));
    let (x0, y0) = (_mm_cvttps_epi32(mx), _mm_cvttps_epi32(my));
    let (wi, hi) = (_mm_cvttps_epi32(wf), _mm_cvttps_epi32(hf));
    let corner = _mm_add_epi32(
        _mm_add_epi32(level_offset(offs, lvl), _mm_mullo_epi32(y0, wi)),
        x0,
    );
    let lim = _mm_set1_ps((K - 2) as f32);
    let mut over = _mm_setzero_ps();
    let mut idx = [[0u32; 4]; 4];
    for j in 0..4 {
        let ox = _mm_sub_ps(flx[j], mx);
        let oy = _mm_sub_ps(fly[j], my);
        over = _mm_or_ps(
            over,
            _mm_or_ps(_mm_cmpgt_ps(ox, lim), _mm_cmpgt_ps(oy, lim)),
        );
        // corner + oy·w + ox (oy·w + ox: small non-negative integers, exact in f32), doubled.
        let o = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(oy, wf), ox));
        idx[j] = to_u32(_mm_slli_epi32::<1>(_mm_add_epi32(corner, o)));
    }
    // Interior: x0 ≥ 0, y0 ≥ 0, x0 + K ≤ w, y0 + K ≤ h.
    let k = _mm_set1_epi32(K as i32);
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
    let ok = !_mm_movemask_ps(_mm_or_ps(over, _mm_castsi128_ps(outside))) & 0xf;
    // Weights per span: rows [ax_j | ay_j] (lanes = spans), transposed within each half.
    let r: [__m256; 4] = core::array::from_fn(|j| _mm256_set_m128(ay[j], ax[j]));
    let t0 = _mm256_unpacklo_ps(r[0], r[1]);
    let t1 = _mm256_unpacklo_ps(r[2], r[3]);
    let t2 = _mm256_unpackhi_ps(r[0], r[1]);
    let t3 = _mm256_unpackhi_ps(r[2], r[3]);
    let wts = [
        _mm256_castpd_ps(_mm256_unpacklo_pd(
            _mm256_castps_pd(t0),
            _mm256_castps_pd(t1),
        )),
        _mm256_castpd_ps(_mm256_unpackhi_pd(
            _mm256_castps_pd(t0),
            _mm256_castps_pd(t1),
        )),
        _mm256_castpd_ps(_mm256_unpacklo_pd(
            _mm256_castps_pd(t2),
            _mm256_castps_pd(t3),
        )),
        _mm256_castpd_ps(_mm256_unpackhi_pd(
            _mm256_castps_pd(t2),
            _mm256_castps_pd(t3),
        )),
    ];
    SpanLevel {
        idx,
        w2: to_u32(_mm_slli_epi32::<1>(wi)),
        wts,
        ok,
    }
}

/// Bilinear of pixels `j`, `j + 1` of span `s` from its interior window (`ix`, `iy`: the weight
/// permutes of the pair).
///
/// # Safety
/// `d` must come from [`span_level`] on this texture with span `s` interior (`d.ok` bit set).
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn span_pair(
    base: *const u8,
    d: &SpanLevel,
    s: usize,
    j: usize,
    ix: __m256i,
    iy: __m256i,
) -> __m256 {
    let (i0, i1, w) = (
        d.idx[j][s] as usize,
        d.idx[j + 1][s] as usize,
        d.w2[s] as usize,
    );
    // SAFETY: the caller's contract: the 2x2 of every pixel lies in the window inside the level.
    unsafe {
        let t00 = load_pair(base, i0, i1);
        let t10 = load_pair(base, i0 + 2, i1 + 2);
        let t01 = load_pair(base, i0 + w, i1 + w);
        let t11 = load_pair(base, i0 + w + 2, i1 + w + 2);
        let wx = _mm256_permutevar8x32_ps(d.wts[s], ix);
        let wy = _mm256_permutevar8x32_ps(d.wts[s], iy);
        lerp8(lerp8(t00, t10, wx), lerp8(t01, t11, wx), wy)
    }
}

/// [`super::lanes::span_quads4`] for AVX2: bit-identical, whole groups of four spans.
///
/// # Safety
/// The CPU must support AVX2; the texture must be a power of two (`tex.is_pow2()`).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn span_quads4<A: Addr, const K: usize>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) -> usize {
    debug_assert!(tex.is_pow2());
    let l0 = &tex.levels()[0];
    let last = tex.level_count() as i32 - 1;
    let offs = offsets(tex);
    let base = tex.texels().as_ptr() as *const u8;
    let n = quads.len().min(out.len()) / 4 * 4;
    // Weight permutes of the pixel pairs (0, 1) and (2, 3): ax in the low four lanes of a span's
    // weights, ay in the high four.
    let ix = [pair_idx(0, 1), pair_idx(2, 3)];
    let iy = [pair_idx(4, 5), pair_idx(6, 7)];
    let (sw, sh) = (_mm_set1_ps(l0.width_f), _mm_set1_ps(l0.height_f));
    for (o, q) in out[..n].chunks_exact_mut(4).zip(quads[..n].chunks_exact(4)) {
        // Load the 16 images and transpose: x[j], y[j] hold pixel j of the four spans.
        // SAFETY: each quad is 4 Vec2 = 8 floats, read unaligned.
        let ld =
            |s: usize, h: usize| unsafe { _mm_loadu_ps((q[s].as_ptr() as *const f32).add(4 * h)) };
        let xy01 = transpose(ld(0, 0), ld(1, 0), ld(2, 0), ld(3, 0)); // x0 y0 x1 y1
        let xy23 = transpose(ld(0, 1), ld(1, 1), ld(2, 1), ld(3, 1)); // x2 y2 x3 y3
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
        let min4 = |v: &[__m128; 4]| _mm_min_ps(_mm_min_ps(v[0], v[1]), _mm_min_ps(v[2], v[3]));
        let max4 = |v: &[__m128; 4]| _mm_max_ps(_mm_max_ps(v[0], v[1]), _mm_max_ps(v[2], v[3]));
        if A::REPEAT {
            // Shift each span by whole periods so its corner lies in the first period.
            let px = _mm_mul_ps(
                _mm_floor_ps(_mm_mul_ps(min4(&sx), _mm_set1_ps(l0.inv_width_f))),
                sw,
            );
            let py = _mm_mul_ps(
                _mm_floor_ps(_mm_mul_ps(min4(&sy), _mm_set1_ps(l0.inv_height_f))),
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
        let a = span_level::<A, K>(tex, i0, &sx, &sy, offs);
        let b = span_level::<A, K>(tex, i1, &sx, &sy, offs);
        let fast = a.ok & (b.ok | single);
        for s in 0..4 {
            if fast & (1 << s) == 0 {
                // A window crossing a level edge (or a conflict): the generic path.
                o[s] = super::span_quad::<A, super::Direct, K>(tex, q[s], 0, &mut super::Direct);
                continue;
            }
            let dst = o[s].as_mut_ptr() as *mut f32;
            // SAFETY: span `s` is interior on the levels read (`fast`); `dst` holds 16 floats.
            unsafe {
                if single & (1 << s) != 0 {
                    for k in 0..2 {
                        let ca = span_pair(base, &a, s, 2 * k, ix[k], iy[k]);
                        _mm256_storeu_ps(dst.add(8 * k), ca);
                    }
                } else {
                    // Seed 000 Eq. (4): one blend weight per span.
                    let tt = pair_of(frac, pair_idx(s as i32, s as i32));
                    for k in 0..2 {
                        let ca = span_pair(base, &a, s, 2 * k, ix[k], iy[k]);
                        let cb = span_pair(base, &b, s, 2 * k, ix[k], iy[k]);
                        _mm256_storeu_ps(dst.add(8 * k), lerp8(ca, cb, tt));
                    }
                }
            }
        }
    }
    n
}
