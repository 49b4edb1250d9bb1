//! AVX2 builds of the lane kernels (chosen at run time by [`super::lanes`]'s `*_best` entry
//! points and by `Sampler::sample_quad`; the SSE2 kernels of `lanes.rs` stay the baseline), on
//! power-of-two pyramids: per-pixel trilinear eight pixels per step, the span sampler eight spans
//! per step, and the span sampler one span per call.
//!
//! The arithmetic is the SSE2 / scalar kernels' operation for operation (no FMA), so the results
//! are the same bits (tested in `super::tests`). What changes is the bookkeeping around it, the
//! same way in both samplers so that their comparison stays fair:
//! - **eight lanes per step:** the set-up (footprint or span extent, level split, level sizes,
//!   texel coordinates, floors, weights) runs once per eight pixels or spans in 256-bit lanes;
//! - **texel indices in lanes, stored once:** the level's base index comes from a 16-entry table
//!   with two register permutes (`vpermd`), rows from `vpmulld`, and each pixel's texel indices
//!   (`offset + y·w + x`, doubled so that the load address `base + 8·index` needs no shift) are
//!   stored once per step and kept in memory (`black_box`: otherwise LLVM extracts lanes, three
//!   instructions per index): a pixel then costs one load per index;
//! - **two pixels per 256-bit register:** the bilinear taps of two pixels are loaded into the two
//!   halves of one register and lerped together (each lane does exactly the 128-bit lerp); the
//!   pair's weights come from one in-lane `vpermilps` (trilinear's lanes are ordered
//!   `[0 2 4 6 | 1 3 5 7]`, the span's weights are kept as `[w_2p | w_2p+1]` per four spans), and
//!   the pair is stored with one 256-bit store;
//! - **`roundps` floors** (SSE4.1, implied by AVX2) instead of the truncate-and-correct sequence
//!   (the same values: both are exact).
//!
//! The span kernel also takes what the paper's structure gives it: one level pair, one blend
//! weight, one window corner and one row stride per span, shared by its four pixels, and one
//! texel index per pixel and level (its 2x2 lies in the interior K x K window). Trilinear needs
//! four indices per pixel and level because wrap-around or clamping may split its 2x2; where no
//! pixel of the eight sits on a level edge it takes two (the same idea, applied for fairness).

use core::arch::x86_64::*;

use glam::{Vec2, Vec4};

use super::{Addr, COORD_LIMIT};
use crate::mip::{LevelInfo, MipTexture};

/// The level-offset table of a texture in two registers (levels 0–7 and 8–15).
#[derive(Clone, Copy)]
pub(super) struct Offsets {
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
// Eight-lane versions of the SSE2 lane helpers (same operations per lane).

/// [`super::lanes::log2_split4`] on eight lanes.
#[inline]
#[target_feature(enable = "avx2")]
fn log2_split8(x: __m256) -> (__m256i, __m256) {
    let bits = _mm256_castps_si256(x);
    let e = _mm256_sub_epi32(
        _mm256_and_si256(_mm256_srli_epi32::<23>(bits), _mm256_set1_epi32(0xff)),
        _mm256_set1_epi32(127),
    );
    let t = _mm256_sub_ps(
        _mm256_castsi256_ps(_mm256_or_si256(
            _mm256_and_si256(bits, _mm256_set1_epi32(0x007f_ffff)),
            _mm256_set1_epi32(0x3f80_0000),
        )),
        _mm256_set1_ps(1.0),
    );
    let c = |k: f32| _mm256_set1_ps(k);
    let poly = _mm256_add_ps(c(super::LOG2_C3), _mm256_mul_ps(t, c(super::LOG2_C4)));
    let poly = _mm256_add_ps(c(super::LOG2_C2), _mm256_mul_ps(t, poly));
    let poly = _mm256_add_ps(c(super::LOG2_C1), _mm256_mul_ps(t, poly));
    (e, _mm256_mul_ps(t, poly))
}

/// [`super::clampc`] on eight lanes: NaN -> −2^30 (`maxps` returns its second operand when the
/// first is NaN), then clamp to ±2^30.
#[inline]
#[target_feature(enable = "avx2")]
fn clamp_coord8(x: __m256) -> __m256 {
    _mm256_min_ps(
        _mm256_max_ps(x, _mm256_set1_ps(-COORD_LIMIT)),
        _mm256_set1_ps(COORD_LIMIT),
    )
}

/// [`super::clamp4`] on eight lanes: NaN -> 0, then clamp to ±2^30. The NaN mask is applied
/// last (a NaN lane clamps to −2^30, then masks to +0, as `clamp4`'s +0 clamps to +0), so the
/// compare runs beside the clamp instead of before it (the one-span kernel's chain).
#[inline]
#[target_feature(enable = "avx2")]
fn clamp_nan0_8(v: __m256) -> __m256 {
    let c = _mm256_min_ps(
        _mm256_max_ps(v, _mm256_set1_ps(-COORD_LIMIT)),
        _mm256_set1_ps(COORD_LIMIT),
    );
    _mm256_and_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(v, v), c)
}

/// `Addr::wrap` on eight lanes (`n`: the level size per lane; Repeat on power-of-two levels).
#[inline]
#[target_feature(enable = "avx2")]
fn wrap8<A: Addr>(i: __m256i, n: __m256i) -> __m256i {
    let nm1 = _mm256_sub_epi32(n, _mm256_set1_epi32(1));
    if A::REPEAT {
        _mm256_and_si256(i, nm1)
    } else {
        _mm256_min_epi32(_mm256_max_epi32(i, _mm256_setzero_si256()), nm1)
    }
}

/// Level size per lane, `max(2^(b − 127 − lvl), 1)` built from the float exponent (exact).
#[inline]
#[target_feature(enable = "avx2")]
fn pow2_lanes(b: i32, lvl: __m256i) -> __m256 {
    _mm256_castsi256_ps(_mm256_slli_epi32::<23>(_mm256_sub_epi32(
        _mm256_set1_epi32(b),
        lvl,
    )))
}

/// Texel index of level `lvl`'s texel (0, 0) per lane (`0 ≤ lvl < 16`): two table permutes.
#[inline]
#[target_feature(enable = "avx2")]
fn level_offset8(t: Offsets, lvl: __m256i) -> __m256i {
    let a = _mm256_permutevar8x32_epi32(t.lo, lvl);
    let b = _mm256_permutevar8x32_epi32(t.hi, lvl);
    _mm256_blendv_epi8(a, b, _mm256_cmpgt_epi32(lvl, _mm256_set1_epi32(7)))
}

/// Eight `i32` lanes as an array (stored once, read per pixel).
#[inline(always)]
pub(super) fn to_u32x8(v: __m256i) -> [u32; 8] {
    // SAFETY: same size, no invalid bit patterns.
    unsafe { core::mem::transmute::<__m256i, [u32; 8]>(v) }
}

/// In-lane 4x4 transposes of four rows: `[a b c d]` -> the four columns, in each 128-bit half.
#[inline]
#[target_feature(enable = "avx2")]
fn transpose8(a: __m256, b: __m256, c: __m256, d: __m256) -> [__m256; 4] {
    let pd = _mm256_castps_pd;
    let ps = _mm256_castpd_ps;
    let t0 = _mm256_unpacklo_ps(a, b);
    let t1 = _mm256_unpacklo_ps(c, d);
    let t2 = _mm256_unpackhi_ps(a, b);
    let t3 = _mm256_unpackhi_ps(c, d);
    [
        ps(_mm256_unpacklo_pd(pd(t0), pd(t1))),
        ps(_mm256_unpackhi_pd(pd(t0), pd(t1))),
        ps(_mm256_unpacklo_pd(pd(t2), pd(t3))),
        ps(_mm256_unpackhi_pd(pd(t2), pd(t3))),
    ]
}

/// Eight `Vec2` as `(x lanes, y lanes)` in the order `[0 2 4 6 | 1 3 5 7]`: pixels `2k` and
/// `2k + 1` share lane `k` of the two halves, so one in-lane permute gives a pair's weights.
///
/// # Safety
/// `p` must point to at least 16 readable floats.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn deinterleave8(p: *const f32) -> (__m256, __m256) {
    // SAFETY: the caller's contract.
    let (a, b) = unsafe { (_mm256_loadu_ps(p), _mm256_loadu_ps(p.add(8))) };
    // [x0 y0 x1 y1 | x2 y2 x3 y3] -> [x0 y0 x2 y2 | x1 y1 x3 y3] (64-bit lanes 0 2 1 3).
    let a = _mm256_castpd_ps(_mm256_permute4x64_pd::<0xD8>(_mm256_castps_pd(a)));
    let b = _mm256_castpd_ps(_mm256_permute4x64_pd::<0xD8>(_mm256_castps_pd(b)));
    (
        _mm256_shuffle_ps::<0b10_00_10_00>(a, b),
        _mm256_shuffle_ps::<0b11_01_11_01>(a, b),
    )
}

/// Lane `I / 0x55` of each half broadcast over that half.
#[inline]
#[target_feature(enable = "avx2")]
fn bc<const I: i32>(v: __m256) -> __m256 {
    _mm256_permute_ps::<I>(v)
}

// ---------------------------------------------------------------------------------------------
// Per-pixel trilinear (Seed 000 Eq. 2 + 4), eight pixels per step.

/// One level of eight pixels (lanes `[0 2 4 6 | 1 3 5 7]`): the doubled texel indices of their
/// 2x2 taps and their weights.
pub(super) struct TriLevel {
    /// `[t00, t10, t01, t11][lane]`.
    pub(super) idx: [[u32; 8]; 4],
    pub(super) ax: __m256,
    pub(super) ay: __m256,
    /// Lane mask of pixels whose 2x2 is split by the level edge (`x1 ≠ x0 + 1` or
    /// `y1 ≠ y0 + 1`); where it is 0, `t10 = t00 + 1` and `t11 = t01 + 1`.
    pub(super) edge: i32,
}

/// Seed 000 Eq. (3) on `2^L r_m − ½` for eight pixels at levels `lvl`: the SSE2 `level_lanes`
/// arithmetic lane for lane, then the texel indices in lanes.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn tri_level<A: Addr>(
    u: __m256,
    v: __m256,
    lvl: __m256i,
    nw: i32,
    nh: i32,
    offs: Offsets,
) -> TriLevel {
    let one = _mm256_set1_ps(1.0);
    let wf = _mm256_max_ps(pow2_lanes(127 + nw, lvl), one);
    let hf = _mm256_max_ps(pow2_lanes(127 + nh, lvl), one);
    let half = _mm256_set1_ps(0.5);
    // Texel coordinates with texel centres at integers, floors and Eq. (4) weights.
    let x = clamp_coord8(_mm256_sub_ps(_mm256_mul_ps(u, wf), half));
    let y = clamp_coord8(_mm256_sub_ps(_mm256_mul_ps(v, hf), half));
    let (flx, fly) = (_mm256_floor_ps(x), _mm256_floor_ps(y));
    let (ax, ay) = (_mm256_sub_ps(x, flx), _mm256_sub_ps(y, fly));
    let (fx, fy) = (_mm256_cvttps_epi32(flx), _mm256_cvttps_epi32(fly));
    let (wi, hi) = (_mm256_cvttps_epi32(wf), _mm256_cvttps_epi32(hf));
    let one_i = _mm256_set1_epi32(1);
    // Wrapped columns and rows (Addr), then texel indices offset + y·w + x, doubled.
    let x0 = wrap8::<A>(fx, wi);
    let x1 = wrap8::<A>(_mm256_add_epi32(fx, one_i), wi);
    let y0 = wrap8::<A>(fy, hi);
    let y1 = wrap8::<A>(_mm256_add_epi32(fy, one_i), hi);
    let off = level_offset8(offs, lvl);
    let r0 = _mm256_add_epi32(off, _mm256_mullo_epi32(y0, wi));
    let r1 = _mm256_add_epi32(off, _mm256_mullo_epi32(y1, wi));
    let d = |r: __m256i, c: __m256i| to_u32x8(_mm256_slli_epi32::<1>(_mm256_add_epi32(r, c)));
    // Pixels whose 2x2 is not split by wrap-around or clamping at the level edge.
    let inside = _mm256_and_si256(
        _mm256_cmpeq_epi32(x1, _mm256_add_epi32(x0, one_i)),
        _mm256_cmpeq_epi32(y1, _mm256_add_epi32(y0, one_i)),
    );
    TriLevel {
        idx: [d(r0, x0), d(r0, x1), d(r1, x0), d(r1, x1)],
        ax,
        ay,
        edge: !_mm256_movemask_ps(_mm256_castsi256_ps(inside)) & 0xff,
    }
}

/// Bilinear of pixels `2k`, `2k + 1` (lanes `k`, `4 + k`; `I = 0x55·k`) of a prepared level.
///
/// # Safety
/// `p` must come from [`tri_level`] on the texture whose texels start at `base`.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn tri_pair<const K: usize, const I: i32, const INSIDE: bool>(
    base: *const u8,
    p: &TriLevel,
) -> __m256 {
    let ld = |c: usize, d: usize| {
        // SAFETY: the caller's contract (indices inside the texel buffer).
        unsafe { load_pair(base, p.idx[c][K] as usize + d, p.idx[c][K + 4] as usize + d) }
    };
    // No pixel's 2x2 split by the level edge: two indices per pixel (t10 = t00 + 1 texel, two
    // doubled units); else the four wrapped ones.
    let (t00, t01) = (ld(0, 0), ld(2, 0));
    let (t10, t11) = if INSIDE {
        (ld(0, 2), ld(2, 2))
    } else {
        (ld(1, 0), ld(3, 0))
    };
    let (wx, wy) = (bc::<I>(p.ax), bc::<I>(p.ay));
    lerp8(lerp8(t00, t10, wx), lerp8(t01, t11, wx), wy)
}

/// A texture's constants for [`tri_step`].
#[derive(Clone, Copy)]
pub(super) struct TriSetup {
    sw: __m256,
    sh: __m256,
    last: i32,
    pub(super) nw: i32,
    pub(super) nh: i32,
    pub(super) offs: Offsets,
}

impl TriSetup {
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn new(tex: &MipTexture) -> TriSetup {
        let l0 = &tex.levels()[0];
        TriSetup {
            sw: _mm256_set1_ps(l0.width_f),
            sh: _mm256_set1_ps(l0.height_f),
            last: tex.level_count() as i32 - 1,
            nw: tex.width().trailing_zeros() as i32,
            nh: tex.height().trailing_zeros() as i32,
            offs: offsets(tex),
        }
    }
}

/// Eight pixels' map coordinates, two levels, Eq. (4) weight and single-level lanes (`sv` as a
/// lane mask, `single` as bits), lanes `[0 2 4 6 | 1 3 5 7]`.
pub(super) struct TriStep {
    pub(super) u: __m256,
    pub(super) v: __m256,
    pub(super) i0: __m256i,
    pub(super) i1: __m256i,
    pub(super) frac: __m256,
    pub(super) sv: __m256,
    pub(super) single: i32,
}

/// The set-up of pixels `i..i + 8`: Seed 000 Eq. (2)'s footprint and the level split as the
/// SSE2 `trilinear4` (the caller then runs [`tri_level`] on both levels, where the indices are
/// to stay: moving them costs copies).
///
/// # Safety
/// `i + 8` must not exceed the length of `uv`, `dx` and `dy`.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn tri_step<A: Addr>(
    c: &TriSetup,
    i: usize,
    uv: &[Vec2],
    dx: &[Vec2],
    dy: &[Vec2],
) -> TriStep {
    let TriSetup { sw, sh, last, .. } = *c;
    let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
    // SAFETY: the caller's contract (8 Vec2 = 16 floats from `i` in each slice).
    let ((u, v), (dxu, dxv), (dyu, dyv)) = unsafe {
        (
            deinterleave8(uv.as_ptr().add(i) as *const f32),
            deinterleave8(dx.as_ptr().add(i) as *const f32),
            deinterleave8(dy.as_ptr().add(i) as *const f32),
        )
    };
    // Seed 000 Eq. (2): the footprint, NaN terms as 0 (as `footprint4`).
    let z = _mm256_setzero_ps();
    let a = |d: __m256, s: __m256| _mm256_max_ps(_mm256_and_ps(_mm256_mul_ps(d, s), abs), z);
    let m = _mm256_max_ps(
        _mm256_max_ps(a(dxu, sw), a(dyu, sw)),
        _mm256_max_ps(a(dxv, sh), a(dyv, sh)),
    );
    // λ = log2 m split into ⌊λ⌋ and frac(λ); level pair as `trilinear4`.
    let (e, frac) = log2_split8(m);
    let minified = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GT_OQ>(m, _mm256_set1_ps(1.0)));
    let past_top = _mm256_cmpgt_epi32(e, _mm256_set1_epi32(last - 1));
    let top = _mm256_set1_epi32(last);
    let all = _mm256_set1_epi32(-1);
    let i0 = _mm256_and_si256(
        minified,
        _mm256_or_si256(
            _mm256_and_si256(past_top, top),
            _mm256_andnot_si256(past_top, e),
        ),
    );
    let single_v = _mm256_or_si256(_mm256_andnot_si256(minified, all), past_top);
    let i1 = _mm256_sub_epi32(i0, _mm256_andnot_si256(single_v, all));
    let sv = _mm256_castsi256_ps(single_v);
    let single = _mm256_movemask_ps(sv);
    TriStep {
        u,
        v,
        i0,
        i1,
        frac,
        sv,
        single,
    }
}

/// Pixels `2k`, `2k + 1` of a step: level `a`, or Eq. (4)'s blend with level `b` by `frac`
/// where the pixel blends two levels (`single`: lane mask of single-level pixels).
///
/// # Safety
/// As [`tri_pair`]; `o` must hold eight `Vec4`.
#[inline]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
unsafe fn tri_out<const K: usize, const I: i32, const INSIDE: bool>(
    base: *const u8,
    pa: &TriLevel,
    pb: &TriLevel,
    frac: __m256,
    single_v: __m256,
    single: i32,
    o: *mut f32,
) {
    let pair = ((single >> K) & 1) | (((single >> (K + 4)) & 1) << 1);
    // SAFETY: the caller's contract.
    unsafe {
        let ca = tri_pair::<K, I, INSIDE>(base, pa);
        let r = if pair == 3 {
            ca
        } else {
            // Seed 000 Eq. (4): blend the two levels by frac(λ); single pixels keep `ca`.
            let cb = tri_pair::<K, I, INSIDE>(base, pb);
            let r = lerp8(ca, cb, bc::<I>(frac));
            if pair == 0 {
                r
            } else {
                _mm256_blendv_ps(r, ca, bc::<I>(single_v))
            }
        };
        _mm256_storeu_ps(o.add(8 * K), r);
    }
}

/// [`super::lanes::trilinear_pixels`] for AVX2, eight pixels per step: bit-identical, whole
/// chunks of eight (the caller does the tail).
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
    let c = TriSetup::new(tex);
    let base = tex.texels().as_ptr() as *const u8;
    let n = uv.len().min(dx.len()).min(dy.len()).min(out.len()) / 8 * 8;
    for i in (0..n).step_by(8) {
        // SAFETY: i + 8 ≤ n ≤ every slice's length (8 Vec2 = 16 floats, 8 Vec4 = 32 floats);
        // the indices come from `tri_level` on this texture.
        unsafe {
            let TriStep {
                u,
                v,
                i0,
                i1,
                frac,
                sv,
                single,
            } = tri_step::<A>(&c, i, uv, dx, dy);
            let mut pa = tri_level::<A>(u, v, i0, c.nw, c.nh, c.offs);
            let mut pb = tri_level::<A>(u, v, i1, c.nw, c.nh, c.offs);
            // Keep the indices in memory: one load per index (else LLVM keeps the vectors and
            // extracts lanes, three instructions per index).
            core::hint::black_box((&mut pa.idx, &mut pb.idx));
            let o = out.as_mut_ptr().add(i) as *mut f32;
            if pa.edge | pb.edge == 0 {
                tri_out::<0, 0x00, true>(base, &pa, &pb, frac, sv, single, o);
                tri_out::<1, 0x55, true>(base, &pa, &pb, frac, sv, single, o);
                tri_out::<2, 0xAA, true>(base, &pa, &pb, frac, sv, single, o);
                tri_out::<3, 0xFF, true>(base, &pa, &pb, frac, sv, single, o);
            } else {
                tri_out::<0, 0x00, false>(base, &pa, &pb, frac, sv, single, o);
                tri_out::<1, 0x55, false>(base, &pa, &pb, frac, sv, single, o);
                tri_out::<2, 0xAA, false>(base, &pa, &pb, frac, sv, single, o);
                tri_out::<3, 0xFF, false>(base, &pa, &pb, frac, sv, single, o);
            }
        }
    }
    n
}

// ---------------------------------------------------------------------------------------------
// Span sampler (Seed 000 Eq. 8–10), eight spans per step (lanes = spans).

/// One level of eight spans: per pixel `j` and span `s` the doubled index of its 2x2's corner
/// texel (window corner + `oy·w + ox`), per span the doubled row stride; the weights as
/// `wx[h][p] = [ax_2p | ax_2p+1]` of spans `4h..4h+4` (`wy` likewise), so one in-lane permute
/// gives a pixel pair's weights; `ok` as in the SSE2 `SpanLevel4`.
struct SpanLevel {
    idx: [[u32; 8]; 4],
    w2: [u32; 8],
    wx: [[__m256; 2]; 2],
    wy: [[__m256; 2]; 2],
    ok: i32,
}

/// One level's K x K windows of eight spans (Seed 000 Eq. 10, lanes = spans): each pixel's
/// Eq. (4) weights (`[pixel]`, lanes = spans), the corner's texel index, the level width, and
/// the lane bits of interior windows (`ok`).
pub(super) struct SpanWindow {
    pub(super) ax: [__m256; 4],
    pub(super) ay: [__m256; 4],
    pub(super) corner: __m256i,
    pub(super) wi: __m256i,
    pub(super) ok: i32,
}

/// Seed 000 Eq. (10) for eight spans at levels `lvl`: the SSE2 `span_level4` arithmetic lane
/// for lane (shared by the AVX2 and AVX-512 builds). `offset(j, ox, oy, corner, wf)` receives
/// pixel `j`'s offset from the window corner (lanes = spans) as soon as it is known, with the
/// corner's texel index and the level width (inside the loop that makes the offsets: with all
/// eight live at once the AVX2 build spills registers).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn span_window<A: Addr, const K: usize>(
    tex: &MipTexture,
    lvl: __m256i,
    sx: &[__m256; 4],
    sy: &[__m256; 4],
    offs: Offsets,
    mut offset: impl FnMut(usize, __m256, __m256, __m256i, __m256),
) -> SpanWindow {
    let l0 = &tex.levels()[0];
    let nw = tex.width().trailing_zeros() as i32;
    let nh = tex.height().trailing_zeros() as i32;
    // Level scale (exactly w_i / w_0 = max(2^−i, 1/w_0)) and size per lane.
    let scx = _mm256_max_ps(pow2_lanes(127, lvl), _mm256_set1_ps(l0.inv_width_f));
    let scy = _mm256_max_ps(pow2_lanes(127, lvl), _mm256_set1_ps(l0.inv_height_f));
    let one = _mm256_set1_ps(1.0);
    let wf = _mm256_max_ps(pow2_lanes(127 + nw, lvl), one);
    let hf = _mm256_max_ps(pow2_lanes(127 + nh, lvl), one);
    let half = _mm256_set1_ps(0.5);
    let z = _mm256_setzero_ps();
    let mut flx = [z; 4];
    let mut fly = [z; 4];
    let mut ax = [z; 4];
    let mut ay = [z; 4];
    for j in 0..4 {
        // This level's texel coordinates (Eq. 3 on 2^L r_m − ½), floors and weights.
        let mut x = _mm256_sub_ps(_mm256_mul_ps(sx[j], scx), half);
        let mut y = _mm256_sub_ps(_mm256_mul_ps(sy[j], scy), half);
        if !A::REPEAT {
            // Clamp-to-edge bilinear equals bilinear at the clamped coordinate.
            x = _mm256_min_ps(_mm256_max_ps(x, z), _mm256_sub_ps(wf, one));
            y = _mm256_min_ps(_mm256_max_ps(y, z), _mm256_sub_ps(hf, one));
        }
        flx[j] = _mm256_floor_ps(x);
        fly[j] = _mm256_floor_ps(y);
        ax[j] = _mm256_sub_ps(x, flx[j]);
        ay[j] = _mm256_sub_ps(y, fly[j]);
    }
    // The window corner: the span's lowest texel.
    let mx = _mm256_min_ps(_mm256_min_ps(flx[0], flx[1]), _mm256_min_ps(flx[2], flx[3]));
    let my = _mm256_min_ps(_mm256_min_ps(fly[0], fly[1]), _mm256_min_ps(fly[2], fly[3]));
    let (x0, y0) = (_mm256_cvttps_epi32(mx), _mm256_cvttps_epi32(my));
    let (wi, hi) = (_mm256_cvttps_epi32(wf), _mm256_cvttps_epi32(hf));
    let corner = _mm256_add_epi32(
        _mm256_add_epi32(level_offset8(offs, lvl), _mm256_mullo_epi32(y0, wi)),
        x0,
    );
    let lim = _mm256_set1_ps((K - 2) as f32);
    let mut over = z;
    for j in 0..4 {
        let ox = _mm256_sub_ps(flx[j], mx);
        let oy = _mm256_sub_ps(fly[j], my);
        over = _mm256_or_ps(
            over,
            _mm256_or_ps(
                _mm256_cmp_ps::<_CMP_GT_OQ>(ox, lim),
                _mm256_cmp_ps::<_CMP_GT_OQ>(oy, lim),
            ),
        );
        offset(j, ox, oy, corner, wf);
    }
    // Interior: x0 ≥ 0, y0 ≥ 0, x0 + K ≤ w, y0 + K ≤ h.
    let k = _mm256_set1_epi32(K as i32);
    let zi = _mm256_setzero_si256();
    let outside = _mm256_or_si256(
        _mm256_or_si256(_mm256_cmpgt_epi32(zi, x0), _mm256_cmpgt_epi32(zi, y0)),
        _mm256_or_si256(
            _mm256_cmpgt_epi32(_mm256_add_epi32(x0, k), wi),
            _mm256_cmpgt_epi32(_mm256_add_epi32(y0, k), hi),
        ),
    );
    let ok = !_mm256_movemask_ps(_mm256_or_ps(over, _mm256_castsi256_ps(outside))) & 0xff;
    SpanWindow {
        ax,
        ay,
        corner,
        wi,
        ok,
    }
}

/// [`span_window`], then the indices in lanes and the weights arranged by pixel pair.
#[inline]
#[target_feature(enable = "avx2")]
fn span_level<A: Addr, const K: usize>(
    tex: &MipTexture,
    lvl: __m256i,
    sx: &[__m256; 4],
    sy: &[__m256; 4],
    offs: Offsets,
) -> SpanLevel {
    let mut idx = [[0u32; 8]; 4];
    let SpanWindow { ax, ay, wi, ok, .. } =
        span_window::<A, K>(tex, lvl, sx, sy, offs, |j, ox, oy, corner, wf| {
            // corner + oy·w + ox (oy·w + ox: small non-negative integers, exact in f32), doubled.
            let o = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(oy, wf), ox));
            idx[j] = to_u32x8(_mm256_slli_epi32::<1>(_mm256_add_epi32(corner, o)));
        });
    // Weights by pixel pair: [w_2p | w_2p+1] of spans 0-3 (h = 0) and 4-7 (h = 1).
    let pp = |w: &[__m256; 4]| {
        [
            [
                _mm256_permute2f128_ps::<0x20>(w[0], w[1]),
                _mm256_permute2f128_ps::<0x20>(w[2], w[3]),
            ],
            [
                _mm256_permute2f128_ps::<0x31>(w[0], w[1]),
                _mm256_permute2f128_ps::<0x31>(w[2], w[3]),
            ],
        ]
    };
    SpanLevel {
        idx,
        w2: to_u32x8(_mm256_slli_epi32::<1>(wi)),
        wx: pp(&ax),
        wy: pp(&ay),
        ok,
    }
}

/// Bilinear of pixels `2p`, `2p + 1` of span `S` from its interior window (`I = 0x55·(S mod 4)`).
///
/// # Safety
/// `d` must come from [`span_level`] on the texture whose texels start at `base`, with span `S`
/// interior (`d.ok` bit set).
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn span_pair<const S: usize, const I: i32>(
    base: *const u8,
    d: &SpanLevel,
    p: usize,
) -> __m256 {
    let (i0, i1, w) = (
        d.idx[2 * p][S] as usize,
        d.idx[2 * p + 1][S] as usize,
        d.w2[S] as usize,
    );
    // SAFETY: the caller's contract: the 2x2 of every pixel lies in the window inside the level.
    unsafe {
        let t00 = load_pair(base, i0, i1);
        let t10 = load_pair(base, i0 + 2, i1 + 2);
        let t01 = load_pair(base, i0 + w, i1 + w);
        let t11 = load_pair(base, i0 + w + 2, i1 + w + 2);
        let wx = bc::<I>(d.wx[S / 4][p]);
        let wy = bc::<I>(d.wy[S / 4][p]);
        lerp8(lerp8(t00, t10, wx), lerp8(t01, t11, wx), wy)
    }
}

/// Span `S` of a step: its four pixels from the levels `a` (and `b`, blended by `frac`, per
/// Eq. 4), or the generic path when its window is not interior.
///
/// # Safety
/// As [`span_pair`] for spans whose `fast` bit is set; `o` must hold four `Vec4`.
#[inline]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
unsafe fn span_out<A: Addr, const K: usize, const S: usize, const I: i32>(
    tex: &MipTexture,
    base: *const u8,
    a: &SpanLevel,
    b: &SpanLevel,
    frac: &[__m256; 2],
    fast: i32,
    single: i32,
    q: [Vec2; 4],
    o: &mut [Vec4; 4],
) {
    if fast & (1 << S) == 0 {
        // A window crossing a level edge (or a conflict).
        // SAFETY: `span_out`'s contract (AVX2, power-of-two texture).
        *o = unsafe { edge_span::<A, K>(tex, q) };
        return;
    }
    let dst = o.as_mut_ptr() as *mut f32;
    // SAFETY: the caller's contract; `dst` holds 16 floats.
    unsafe {
        if single & (1 << S) != 0 {
            _mm256_storeu_ps(dst, span_pair::<S, I>(base, a, 0));
            _mm256_storeu_ps(dst.add(8), span_pair::<S, I>(base, a, 1));
        } else {
            // Seed 000 Eq. (4): one blend weight per span.
            let tt = bc::<I>(frac[S / 4]);
            for p in 0..2 {
                let ca = span_pair::<S, I>(base, a, p);
                let cb = span_pair::<S, I>(base, b, p);
                _mm256_storeu_ps(dst.add(8 * p), lerp8(ca, cb, tt));
            }
        }
    }
}

/// A span whose window crosses a level edge (or does not hold every neighbourhood), kept out of
/// line: inlined into the eight unrolled spans of [`span_quads`] it made the kernel's code large
/// enough to miss the instruction cache (callgrind cache simulation: 0.25 I1 misses per sample).
/// Each pixel takes its own four wrapped texel indices per level (as trilinear does) instead of
/// one window index; spans with an offset past the window (narrow levels, or a conflict, which
/// the level policy excludes) take the generic path, which folds or counts them.
///
/// # Safety
/// The CPU must support AVX2; the texture must be a power of two.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn edge_span<A: Addr, const K: usize>(
    tex: &MipTexture,
    q: [Vec2; 4],
) -> [Vec4; 4] {
    let p = plan::<A, K>(tex, &q);
    let generic = || super::span_finish::<A, super::Direct, K>(tex, p, &mut super::Direct);
    let Some(a) = edge_level::<A, K>(tex, p.i0, p.sx, p.sy) else {
        return generic();
    };
    let base = tex.texels().as_ptr() as *const u8;
    let mut out = [Vec4::ZERO; 4];
    let dst = out.as_mut_ptr() as *mut f32;
    if p.i1 == p.i0 || p.t == 0.0 {
        // SAFETY: indices wrapped into the level (edge_level); `out` holds 16 floats.
        unsafe {
            _mm256_storeu_ps(dst, edge_pair(base, &a, 0));
            _mm256_storeu_ps(dst.add(8), edge_pair(base, &a, 1));
        }
        return out;
    }
    let Some(b) = edge_level::<A, K>(tex, p.i1, p.sx, p.sy) else {
        return generic();
    };
    // Seed 000 Eq. (4): one blend weight for the span.
    let tt = _mm256_set1_ps(p.t);
    for k in 0..2 {
        // SAFETY: as above.
        unsafe {
            let r = lerp8(edge_pair(base, &a, k), edge_pair(base, &b, k), tt);
            _mm256_storeu_ps(dst.add(8 * k), r);
        }
    }
    out
}

/// One level's texel coordinates of a span's four pixels (Seed 000 Eq. 3 on `2^L·r_m − ½`,
/// clamped to the edge texels for Clamp): their floors and fractions `(⌊x⌋, ⌊y⌋, αx, αy)`.
#[inline]
#[target_feature(enable = "avx2")]
fn span_texel_coords<A: Addr>(
    l: &LevelInfo,
    sx: Vec4,
    sy: Vec4,
) -> (__m128, __m128, __m128, __m128) {
    let mut x = sx * l.scale_x - Vec4::splat(0.5);
    let mut y = sy * l.scale_y - Vec4::splat(0.5);
    if !A::REPEAT {
        x = x.max(Vec4::ZERO).min(Vec4::splat(l.width_f - 1.0));
        y = y.max(Vec4::ZERO).min(Vec4::splat(l.height_f - 1.0));
    }
    let (x, y): (__m128, __m128) = (x.into(), y.into());
    let (flx, fly) = (_mm_floor_ps(x), _mm_floor_ps(y));
    (flx, fly, _mm_sub_ps(x, flx), _mm_sub_ps(y, fly))
}

/// The smallest of four lanes, in every lane.
#[inline]
#[target_feature(enable = "avx2")]
fn hmin(v: __m128) -> __m128 {
    let m = _mm_min_ps(v, _mm_shuffle_ps::<0b01_00_11_10>(v, v));
    _mm_min_ps(m, _mm_shuffle_ps::<0b10_11_00_01>(m, m))
}

/// A span's four per-pixel weights as the two pixel pairs' registers `[w0 ×4 | w1 ×4]`,
/// `[w2 ×4 | w3 ×4]`.
#[inline]
#[target_feature(enable = "avx2")]
fn pair_weights(v: __m128) -> [__m256; 2] {
    let pair = |a: i32, b: i32| {
        _mm256_permutevar8x32_ps(
            _mm256_castps128_ps256(v),
            _mm256_setr_epi32(a, a, a, a, b, b, b, b),
        )
    };
    [pair(0, 1), pair(2, 3)]
}

/// One level of an edge span: per pixel its four wrapped texel indices (doubled,
/// `[t00, t10, t01, t11][pixel]`) and the pixel pairs' weights.
struct EdgeLevel {
    idx: [[u32; 4]; 4],
    wx: [__m256; 2],
    wy: [__m256; 2],
}

/// [`super::span_level`]'s coordinates, floors and weights for one span; `None` if a pixel's
/// offset from the window corner exceeds `K − 2` (the generic path handles it).
#[inline]
#[target_feature(enable = "avx2")]
fn edge_level<A: Addr, const K: usize>(
    tex: &MipTexture,
    level: usize,
    sx: Vec4,
    sy: Vec4,
) -> Option<EdgeLevel> {
    debug_assert!(tex.is_pow2());
    let l = &tex.levels()[level];
    let (flx, fly, ax, ay) = span_texel_coords::<A>(l, sx, sy);
    let lim = _mm_set1_ps((K - 2) as f32);
    let over = _mm_or_ps(
        _mm_cmpgt_ps(_mm_sub_ps(flx, hmin(flx)), lim),
        _mm_cmpgt_ps(_mm_sub_ps(fly, hmin(fly)), lim),
    );
    if _mm_movemask_ps(over) != 0 {
        return None;
    }
    // Wrapped columns and rows (Repeat on a power-of-two level: a mask; Clamp: to the edge).
    let (fx, fy) = (_mm_cvttps_epi32(flx), _mm_cvttps_epi32(fly));
    let (w, h) = (
        _mm_set1_epi32(l.width as i32),
        _mm_set1_epi32(l.height as i32),
    );
    let one = _mm_set1_epi32(1);
    let wrap = |i: __m128i, n: __m128i| {
        let nm1 = _mm_sub_epi32(n, one);
        if A::REPEAT {
            _mm_and_si128(i, nm1)
        } else {
            _mm_min_epi32(_mm_max_epi32(i, _mm_setzero_si128()), nm1)
        }
    };
    let (c0, c1) = (wrap(fx, w), wrap(_mm_add_epi32(fx, one), w));
    let off = _mm_set1_epi32(l.offset as i32);
    let r0 = _mm_add_epi32(off, _mm_mullo_epi32(wrap(fy, h), w));
    let r1 = _mm_add_epi32(off, _mm_mullo_epi32(wrap(_mm_add_epi32(fy, one), h), w));
    let d = |r: __m128i, c: __m128i| {
        // SAFETY: same size, no invalid bit patterns.
        unsafe {
            core::mem::transmute::<__m128i, [u32; 4]>(_mm_slli_epi32::<1>(_mm_add_epi32(r, c)))
        }
    };
    Some(EdgeLevel {
        idx: [d(r0, c0), d(r0, c1), d(r1, c0), d(r1, c1)],
        wx: pair_weights(ax),
        wy: pair_weights(ay),
    })
}

/// Bilinear of pixels `2p`, `2p + 1` of an edge span.
///
/// # Safety
/// `d` must come from [`edge_level`] on the texture whose texels start at `base`.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn edge_pair(base: *const u8, d: &EdgeLevel, p: usize) -> __m256 {
    let (j, k) = (2 * p, 2 * p + 1);
    // SAFETY: the caller's contract: wrapped indices inside the level.
    unsafe {
        let t00 = load_pair(base, d.idx[0][j] as usize, d.idx[0][k] as usize);
        let t10 = load_pair(base, d.idx[1][j] as usize, d.idx[1][k] as usize);
        let t01 = load_pair(base, d.idx[2][j] as usize, d.idx[2][k] as usize);
        let t11 = load_pair(base, d.idx[3][j] as usize, d.idx[3][k] as usize);
        lerp8(lerp8(t00, t10, d.wx[p]), lerp8(t01, t11, d.wx[p]), d.wy[p])
    }
}

/// A texture's constants for [`span_step`].
#[derive(Clone, Copy)]
pub(super) struct SpanSetup<'a> {
    l0: &'a LevelInfo,
    last: i32,
    pub(super) offs: Offsets,
    sw: __m256,
    sh: __m256,
}

impl<'a> SpanSetup<'a> {
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn new(tex: &'a MipTexture) -> SpanSetup<'a> {
        let l0 = &tex.levels()[0];
        SpanSetup {
            l0,
            last: tex.level_count() as i32 - 1,
            offs: offsets(tex),
            sw: _mm256_set1_ps(l0.width_f),
            sh: _mm256_set1_ps(l0.height_f),
        }
    }
}

/// Eight spans' level-0 texel coordinates (`sx[j]`, `sy[j]`: pixel `j` of each span, shifted
/// by whole periods for Repeat), their level pair, Eq. (4) weight and single-level spans.
pub(super) struct SpanStep {
    pub(super) sx: [__m256; 4],
    pub(super) sy: [__m256; 4],
    pub(super) i0: __m256i,
    pub(super) i1: __m256i,
    pub(super) frac: __m256,
    pub(super) single: i32,
}

/// The set-up of eight spans (shared by the AVX2 and AVX-512 builds): the images transposed
/// into lanes, clamped as `span_plan` does, the repeat shift, Seed 000 Eq. (9)'s extent and the
/// level pair of the level policy.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn span_step<A: Addr, const K: usize>(c: &SpanSetup, q: &[[Vec2; 4]; 8]) -> SpanStep {
    let SpanSetup {
        l0, last, sw, sh, ..
    } = *c;
    // Load the 32 images, spans s and s + 4 in the two halves, and transpose: x[j], y[j]
    // hold pixel j of the eight spans.
    // SAFETY: each quad is 4 Vec2 = 8 floats, read unaligned.
    let ld = |s: usize, h: usize| unsafe {
        _mm256_loadu2_m128(
            (q[s + 4].as_ptr() as *const f32).add(4 * h),
            (q[s].as_ptr() as *const f32).add(4 * h),
        )
    };
    let xy01 = transpose8(ld(0, 0), ld(1, 0), ld(2, 0), ld(3, 0)); // x0 y0 x1 y1
    let xy23 = transpose8(ld(0, 1), ld(1, 1), ld(2, 1), ld(3, 1)); // x2 y2 x3 y3
    let mut sx = [
        clamp_nan0_8(_mm256_mul_ps(xy01[0], sw)),
        clamp_nan0_8(_mm256_mul_ps(xy01[2], sw)),
        clamp_nan0_8(_mm256_mul_ps(xy23[0], sw)),
        clamp_nan0_8(_mm256_mul_ps(xy23[2], sw)),
    ];
    let mut sy = [
        clamp_nan0_8(_mm256_mul_ps(xy01[1], sh)),
        clamp_nan0_8(_mm256_mul_ps(xy01[3], sh)),
        clamp_nan0_8(_mm256_mul_ps(xy23[1], sh)),
        clamp_nan0_8(_mm256_mul_ps(xy23[3], sh)),
    ];
    let min4 =
        |v: &[__m256; 4]| _mm256_min_ps(_mm256_min_ps(v[0], v[1]), _mm256_min_ps(v[2], v[3]));
    let max4 =
        |v: &[__m256; 4]| _mm256_max_ps(_mm256_max_ps(v[0], v[1]), _mm256_max_ps(v[2], v[3]));
    if A::REPEAT {
        // Shift each span by whole periods so its corner lies in the first period.
        let px = _mm256_mul_ps(
            _mm256_floor_ps(_mm256_mul_ps(min4(&sx), _mm256_set1_ps(l0.inv_width_f))),
            sw,
        );
        let py = _mm256_mul_ps(
            _mm256_floor_ps(_mm256_mul_ps(min4(&sy), _mm256_set1_ps(l0.inv_height_f))),
            sh,
        );
        for j in 0..4 {
            sx[j] = _mm256_sub_ps(sx[j], px);
            sy[j] = _mm256_sub_ps(sy[j], py);
        }
    }
    // Seed 000 Eq. (9): span level from the extent of the four images.
    let ext = _mm256_max_ps(
        _mm256_sub_ps(max4(&sx), min4(&sx)),
        _mm256_sub_ps(max4(&sy), min4(&sy)),
    );
    let (e, frac) = log2_split8(ext);
    // K = 3 takes the pair one level coarser (see the module doc's level policy).
    let fine = _mm256_add_epi32(e, _mm256_set1_epi32(if K == 3 { 1 } else { 0 }));
    let below = _mm256_cmpgt_epi32(_mm256_setzero_si256(), fine);
    let above = _mm256_cmpgt_epi32(fine, _mm256_set1_epi32(last - 1));
    let top = _mm256_set1_epi32(last);
    let i0 = _mm256_andnot_si256(
        below,
        _mm256_or_si256(
            _mm256_and_si256(above, top),
            _mm256_andnot_si256(above, fine),
        ),
    );
    // Blend two levels unless clamped to the pyramid or frac(λ) = 0.
    let clamped = _mm256_or_si256(below, above);
    let zero_t = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_EQ_OQ>(frac, _mm256_setzero_ps()));
    let single = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_or_si256(clamped, zero_t)));
    let i1 = _mm256_sub_epi32(i0, _mm256_andnot_si256(clamped, _mm256_set1_epi32(-1)));
    SpanStep {
        sx,
        sy,
        i0,
        i1,
        frac,
        single,
    }
}

/// [`super::lanes::span_quads4`] for AVX2, eight spans per step: bit-identical, whole groups
/// of eight spans (the caller does the tail).
///
/// # Safety
/// The CPU must support AVX2; the texture must be a power of two (`tex.is_pow2()`).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn span_quads<A: Addr, const K: usize>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) -> usize {
    debug_assert!(tex.is_pow2());
    let c = SpanSetup::new(tex);
    let base = tex.texels().as_ptr() as *const u8;
    let n = quads.len().min(out.len()) / 8 * 8;
    for (o, q) in out[..n].chunks_exact_mut(8).zip(quads[..n].chunks_exact(8)) {
        let SpanStep {
            sx,
            sy,
            i0,
            i1,
            frac,
            single,
        } = span_step::<A, K>(&c, q.try_into().expect("eight spans"));
        let offs = c.offs;
        let mut a = span_level::<A, K>(tex, i0, &sx, &sy, offs);
        let mut b = span_level::<A, K>(tex, i1, &sx, &sy, offs);
        // Keep the indices in memory: one load per index (else LLVM keeps the vectors and
        // extracts lanes, three instructions per index).
        core::hint::black_box((&mut a.idx, &mut a.w2, &mut b.idx, &mut b.w2));
        let fast = a.ok & (b.ok | single);
        let fr = [
            _mm256_permute2f128_ps::<0x00>(frac, frac),
            _mm256_permute2f128_ps::<0x11>(frac, frac),
        ];
        // SAFETY: `span_out`'s contract: levels from `span_level` on this texture.
        unsafe {
            span_out::<A, K, 0, 0x00>(tex, base, &a, &b, &fr, fast, single, q[0], &mut o[0]);
            span_out::<A, K, 1, 0x55>(tex, base, &a, &b, &fr, fast, single, q[1], &mut o[1]);
            span_out::<A, K, 2, 0xAA>(tex, base, &a, &b, &fr, fast, single, q[2], &mut o[2]);
            span_out::<A, K, 3, 0xFF>(tex, base, &a, &b, &fr, fast, single, q[3], &mut o[3]);
            span_out::<A, K, 4, 0x00>(tex, base, &a, &b, &fr, fast, single, q[4], &mut o[4]);
            span_out::<A, K, 5, 0x55>(tex, base, &a, &b, &fr, fast, single, q[5], &mut o[5]);
            span_out::<A, K, 6, 0xAA>(tex, base, &a, &b, &fr, fast, single, q[6], &mut o[6]);
            span_out::<A, K, 7, 0xFF>(tex, base, &a, &b, &fr, fast, single, q[7], &mut o[7]);
        }
    }
    n
}

// ---------------------------------------------------------------------------------------------
// One span per call (`Sampler::sample_quad`, the rasteriser's path): lanes = its four pixels.

/// One level of one span from an interior window: the doubled index of each pixel's 2x2 corner
/// texel, the doubled row stride and the weights of the pixel pairs `[w_2p | w_2p+1]`.
struct QuadLevel {
    idx: [u32; 4],
    w2: usize,
    wx: [__m256; 2],
    wy: [__m256; 2],
}

/// Seed 000 Eq. (10) for one span at `level` with [`super::direct_level`]'s arithmetic; `None`
/// when the window is not interior (the caller takes the generic path).
#[inline]
#[target_feature(enable = "avx2")]
fn quad_level<A: Addr, const K: usize>(
    tex: &MipTexture,
    level: usize,
    sx: Vec4,
    sy: Vec4,
) -> Option<QuadLevel> {
    let l = &tex.levels()[level];
    // This level's texel coordinates (Eq. 3 on 2^L r_m − ½), floors and weights.
    let (flx, fly, ax, ay) = span_texel_coords::<A>(l, sx, sy);
    // The window corner (the lowest texel) and each pixel's offset from it.
    let (mx, my) = (hmin(flx), hmin(fly));
    let (ox, oy) = (_mm_sub_ps(flx, mx), _mm_sub_ps(fly, my));
    let lim = _mm_set1_ps((K - 2) as f32);
    let over = _mm_movemask_ps(_mm_or_ps(_mm_cmpgt_ps(ox, lim), _mm_cmpgt_ps(oy, lim)));
    let (x0, y0) = (_mm_cvtss_si32(mx), _mm_cvtss_si32(my));
    let (w, h) = (l.width as i32, l.height as i32);
    let k = K as i32;
    if over != 0 || x0 < 0 || y0 < 0 || x0 + k > w || y0 + k > h {
        return None;
    }
    // corner + oy·w + ox (small non-negative integers, exact in f32), doubled.
    let corner = _mm_set1_epi32((l.offset + (y0 * w + x0) as usize) as i32);
    let o = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(oy, _mm_set1_ps(l.width_f)), ox));
    let idx = _mm_slli_epi32::<1>(_mm_add_epi32(corner, o));
    Some(QuadLevel {
        // SAFETY: same size, no invalid bit patterns.
        idx: unsafe { core::mem::transmute::<__m128i, [u32; 4]>(idx) },
        w2: 2 * w as usize,
        wx: pair_weights(ax),
        wy: pair_weights(ay),
    })
}

/// Bilinear of pixels `2p`, `2p + 1` from an interior window.
///
/// # Safety
/// `d` must come from [`quad_level`] on the texture whose texels start at `base`.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn quad_pair(base: *const u8, d: &QuadLevel, p: usize) -> __m256 {
    let (i0, i1, w) = (d.idx[2 * p] as usize, d.idx[2 * p + 1] as usize, d.w2);
    // SAFETY: the caller's contract: every pixel's 2x2 lies in the window inside the level.
    unsafe {
        let t00 = load_pair(base, i0, i1);
        let t10 = load_pair(base, i0 + 2, i1 + 2);
        let t01 = load_pair(base, i0 + w, i1 + w);
        let t11 = load_pair(base, i0 + w + 2, i1 + w + 2);
        lerp8(lerp8(t00, t10, d.wx[p]), lerp8(t01, t11, d.wx[p]), d.wy[p])
    }
}

/// [`super::span_plan`] with the images read as two 16-byte loads, each inside one half of the
/// quad: a load straddling the halves (what LLVM made of `Vec4::new(uv[0].x, ..)`, bytes
/// 4..20) cannot be forwarded from a caller's two 16-byte stores of the quad and waits for them
/// to retire (`perf` on the one-span calls: ~15 % of the samples there).
#[inline]
#[target_feature(enable = "avx2")]
fn plan<A: Addr, const K: usize>(tex: &MipTexture, uv: &[Vec2; 4]) -> super::SpanPlan {
    // SAFETY: `uv` is 8 floats.
    let (h0, h1) = unsafe {
        let f = uv.as_ptr() as *const f32;
        (_mm_loadu_ps(f), _mm_loadu_ps(f.add(4)))
    };
    let u = _mm_shuffle_ps::<0b10_00_10_00>(h0, h1);
    let v = _mm_shuffle_ps::<0b11_01_11_01>(h0, h1);
    super::span_plan_lanes::<A, K>(tex, u.into(), v.into(), 0)
}

/// The span sampler on one span (Seed 000 Eq. 8–10, Eq. 4 blend): bit-identical to
/// [`super::span_finish_direct`] after [`super::span_plan`], which it replaces on AVX2 CPUs.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn span_quad<A: Addr, const K: usize>(
    tex: &MipTexture,
    uv: [Vec2; 4],
) -> [Vec4; 4] {
    let p = plan::<A, K>(tex, &uv);
    let Some(a) = quad_level::<A, K>(tex, p.i0, p.sx, p.sy) else {
        return super::span_finish::<A, super::Direct, K>(tex, p, &mut super::Direct);
    };
    let base = tex.texels().as_ptr() as *const u8;
    let mut out = [Vec4::ZERO; 4];
    let dst = out.as_mut_ptr() as *mut f32;
    if p.i1 == p.i0 || p.t == 0.0 {
        // SAFETY: `a` is interior (quad_level); `out` holds 16 floats.
        unsafe {
            _mm256_storeu_ps(dst, quad_pair(base, &a, 0));
            _mm256_storeu_ps(dst.add(8), quad_pair(base, &a, 1));
        }
        return out;
    }
    let Some(b) = quad_level::<A, K>(tex, p.i1, p.sx, p.sy) else {
        return super::span_finish::<A, super::Direct, K>(tex, p, &mut super::Direct);
    };
    // Seed 000 Eq. (4): one blend weight for the span.
    let tt = _mm256_set1_ps(p.t);
    for k in 0..2 {
        // SAFETY: both levels interior; `out` holds 16 floats.
        unsafe {
            let r = lerp8(quad_pair(base, &a, k), quad_pair(base, &b, k), tt);
            _mm256_storeu_ps(dst.add(8 * k), r);
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// One span per call on a power-of-two pyramid: x and y of the four pixels in the two halves of
// one 256-bit register, the level sizes from the level index's bits, no window corner on the
// index path. One call is a dependency chain (images -> repeat shift -> extent -> level ->
// coordinates -> floors -> indices -> texels -> lerps), so what counts here is its length and
// the instruction count (how much of the next call the core can overlap), not lane width.

/// The smallest x (even lanes) and y (odd lanes) of `[x0 y0 x2 y2 | x1 y1 x3 y3]`, in every
/// even and odd lane respectively.
#[inline]
#[target_feature(enable = "avx2")]
fn min_xy(v: __m256) -> __m256 {
    let m = _mm256_min_ps(v, _mm256_permute_ps::<0b01_00_11_10>(v));
    _mm256_min_ps(m, _mm256_permute2f128_ps::<0x01>(m, m))
}

/// See [`min_xy`].
#[inline]
#[target_feature(enable = "avx2")]
fn max_xy(v: __m256) -> __m256 {
    let m = _mm256_max_ps(v, _mm256_permute_ps::<0b01_00_11_10>(v));
    _mm256_max_ps(m, _mm256_permute2f128_ps::<0x01>(m, m))
}

/// `[a b a b | a b a b]`.
#[inline]
#[target_feature(enable = "avx2")]
fn xy(a: f32, b: f32) -> __m256 {
    _mm256_setr_ps(a, b, a, b, a, b, a, b)
}

/// One level of a span on a power-of-two pyramid: the doubled index of each pixel's 2x2
/// corner texel, the doubled row stride, the pixel pairs' weights `[wx01, wx23, wy01, wy23]`
/// and whether the K x K window is NOT interior (then the caller takes the edge path).
struct Pow2Level {
    idx: [u32; 4],
    w2: usize,
    w: [__m256; 4],
    outside: bool,
}

/// [`quad_level`]'s arithmetic on `s = [x0 y0 x2 y2 | x1 y1 x3 y3]` at level `i` whose scale
/// (`w_i/w_0` in x lanes, `h_i/h_0` in y lanes; for power-of-two pyramids `max(2^−i, 1/w_0)`,
/// built from `i` by the caller, as
/// the eight-span kernel does), with each pixel's index `offset + ⌊y⌋·w + ⌊x⌋` straight from its
/// coordinates (for an interior window the same texel as `corner + oy·w + ox`).
#[inline]
#[target_feature(enable = "avx2")]
fn pow2_level<A: Addr, const K: usize>(
    tex: &MipTexture,
    s: __m256,
    scale: __m256,
    i: usize,
    size0: __m256,
) -> Pow2Level {
    debug_assert!(i < tex.level_count());
    // max(2^(n − i), 1) = scale · 2^n, exactly.
    let size = _mm256_mul_ps(scale, size0);
    // This level's texel coordinates (Eq. 3 on 2^L r_m − ½), clamped for Clamp; floors, weights.
    let mut x = _mm256_sub_ps(_mm256_mul_ps(s, scale), _mm256_set1_ps(0.5));
    if !A::REPEAT {
        x = _mm256_min_ps(
            _mm256_max_ps(x, _mm256_setzero_ps()),
            _mm256_sub_ps(size, _mm256_set1_ps(1.0)),
        );
    }
    let fl = _mm256_floor_ps(x);
    let a = _mm256_sub_ps(x, fl);
    // Interior: corner ≥ 0, corner + K ≤ size, every offset from the corner ≤ K − 2.
    let mn = min_xy(fl);
    let bad = _mm256_or_ps(
        _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_sub_ps(fl, mn), _mm256_set1_ps((K - 2) as f32)),
        _mm256_or_ps(
            _mm256_cmp_ps::<_CMP_LT_OQ>(mn, _mm256_setzero_ps()),
            _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_add_ps(mn, _mm256_set1_ps(K as f32)), size),
        ),
    );
    // In an interior window every x ≥ 0, so truncation is the floor: the indices need not wait
    // for `roundps` (other spans take the edge path and ignore them).
    let fi = _mm256_cvttps_epi32(x);
    // Row stride: the level width max(w_0 >> i, 1) as a shift; ⌊y⌋ moved under ⌊x⌋ (the even
    // lanes: pixels 0 and 2 in the low half, 1 and 3 in the high one).
    let lw = tex.width().trailing_zeros().saturating_sub(i as u32);
    let off = tex.level_offsets16()[i.min(15)];
    let rows = _mm256_sll_epi32(_mm256_srli_epi64::<32>(fi), _mm_cvtsi32_si128(lw as i32));
    let idx = _mm256_add_epi32(_mm256_add_epi32(fi, rows), _mm256_set1_epi32(off));
    let idx = to_u32x8(_mm256_slli_epi32::<1>(idx));
    Pow2Level {
        idx: [idx[0], idx[4], idx[2], idx[6]],
        w2: 2 << lw,
        // [ax0 ×4 | ax1 ×4], [ax2 | ax3], [ay0 | ay1], [ay2 | ay3]: in-lane broadcasts.
        w: [bc::<0x00>(a), bc::<0xAA>(a), bc::<0x55>(a), bc::<0xFF>(a)],
        outside: _mm256_movemask_ps(bad) != 0,
    }
}

/// Bilinear of pixels `2p`, `2p + 1` from an interior window of a [`Pow2Level`].
///
/// # Safety
/// `d` must come from [`pow2_level`] on the texture whose texels start at `base`, interior.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn pow2_pair(base: *const u8, d: &Pow2Level, p: usize) -> __m256 {
    let (i0, i1, w) = (d.idx[2 * p] as usize, d.idx[2 * p + 1] as usize, d.w2);
    let (wx, wy) = (d.w[p], d.w[2 + p]);
    // SAFETY: the caller's contract: every pixel's 2x2 lies in the window inside the level.
    unsafe {
        let t00 = load_pair(base, i0, i1);
        let t10 = load_pair(base, i0 + 2, i1 + 2);
        let t01 = load_pair(base, i0 + w, i1 + w);
        let t11 = load_pair(base, i0 + w + 2, i1 + w + 2);
        lerp8(lerp8(t00, t10, wx), lerp8(t01, t11, wx), wy)
    }
}

/// The span sampler on one span of a power-of-two pyramid (Seed 000 Eq. 8–10, Eq. 4 blend):
/// bit-identical to [`super::span_finish_direct`] after [`super::span_plan`]; spans whose
/// window is not interior take [`edge_span`].
///
/// # Safety
/// The CPU must support AVX2; the texture must be a power of two (`tex.is_pow2()`).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn span_quad_pow2<A: Addr, const K: usize>(
    tex: &MipTexture,
    uv: [Vec2; 4],
) -> [Vec4; 4] {
    debug_assert!(tex.is_pow2());
    let l0 = &tex.levels()[0];
    let last = tex.level_count() - 1;
    // The images as two 16-byte loads, each inside one half of the quad (a load straddling
    // the halves cannot be forwarded from the caller's stores of the quad), then [u | v].
    // SAFETY: `uv` is 8 floats.
    let q = unsafe {
        let f = uv.as_ptr() as *const f32;
        _mm256_loadu2_m128(f.add(4), f)
    };
    // [x0 y0 x2 y2 | x1 y1 x3 y3]: pixels 2p and 2p + 1 share lanes of the two halves, so a
    // pixel pair's weights are in-lane broadcasts.
    let uv8 = _mm256_castpd_ps(_mm256_permute4x64_pd::<0xD8>(_mm256_castps_pd(q)));
    let size0 = xy(l0.width_f, l0.height_f);
    let inv0 = xy(l0.inv_width_f, l0.inv_height_f);
    // Level-0 texel coordinates [sx | sy]. `span_plan` clamps them (NaN -> 0, ±2^30), which
    // changes nothing for finite lanes within the limit: those lanes skip the clamp, others
    // take the edge path (a check beside the chain instead of two steps in it).
    let mut s = _mm256_mul_ps(uv8, size0);
    let abs = _mm256_and_ps(s, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff)));
    let finite = _mm256_cmp_ps::<_CMP_LE_OQ>(abs, _mm256_set1_ps(COORD_LIMIT));
    let (mut lo, mut hi) = (min_xy(s), max_xy(s));
    if A::REPEAT {
        // Whole periods off so that the span's corner lies in the first period (span_plan).
        let p = _mm256_mul_ps(_mm256_floor_ps(_mm256_mul_ps(lo, inv0)), size0);
        s = _mm256_sub_ps(s, p);
        // The shifted lanes' extremes are the extremes shifted (rounding is monotone: the
        // same lanes stay smallest and largest), the same bits as reducing `s` again. (The
        // extent before the shift is NOT always the same: lanes small next to the width lose
        // bits in the shift; on the bench's plane two spans in three differ.)
        (lo, hi) = (_mm256_sub_ps(lo, p), _mm256_sub_ps(hi, p));
    }
    if _mm256_movemask_ps(finite) != 0xff {
        // SAFETY: the caller's contract.
        return unsafe { edge_span::<A, K>(tex, uv) };
    }
    // Seed 000 Eq. (9): the level pair from the extent of the four images.
    let d = _mm256_castps256_ps128(_mm256_sub_ps(hi, lo));
    let ext = _mm_max_ss(d, _mm_movehdup_ps(d));
    let (i0, i1, t) = super::span_levels::<K>(_mm_cvtss_f32(ext), last, 0);
    // The same level pair in lanes (no round trip through the integer registers on the way
    // to the coordinates): ⌊λ⌋ from the exponent (ext ≥ 0), clamped to the pyramid; the level
    // scales max(2^−i, 1/w_0) from the levels' bits.
    let fine = _mm_add_epi32(
        _mm_srli_epi32::<23>(_mm_castps_si128(ext)),
        _mm_set1_epi32(if K == 3 { 1 - 127 } else { -127 }),
    );
    let top = _mm_set1_epi32(last as i32);
    let lvl = |f: __m128i| _mm_min_epi32(_mm_max_epi32(f, _mm_setzero_si128()), top);
    let scale = |l: __m128i| {
        let b = _mm_slli_epi32::<23>(_mm_sub_epi32(_mm_set1_epi32(127), l));
        _mm256_max_ps(_mm256_castsi256_ps(_mm256_broadcastd_epi32(b)), inv0)
    };
    let sa = scale(lvl(fine));
    let sb = scale(lvl(_mm_add_epi32(fine, _mm_set1_epi32(1))));
    let a = pow2_level::<A, K>(tex, s, sa, i0, size0);
    let b = pow2_level::<A, K>(tex, s, sb, i1, size0);
    if a.outside | b.outside {
        // SAFETY: the caller's contract.
        return unsafe { edge_span::<A, K>(tex, uv) };
    }
    let base = tex.texels().as_ptr() as *const u8;
    let mut out = [Vec4::ZERO; 4];
    let dst = out.as_mut_ptr() as *mut f32;
    // SAFETY: both windows interior (pow2_level); `out` holds 16 floats.
    unsafe {
        if i1 == i0 || t == 0.0 {
            _mm256_storeu_ps(dst, pow2_pair(base, &a, 0));
            _mm256_storeu_ps(dst.add(8), pow2_pair(base, &a, 1));
        } else {
            // Seed 000 Eq. (4): one blend weight for the span.
            let tt = _mm256_set1_ps(t);
            for p in 0..2 {
                let r = lerp8(pow2_pair(base, &a, p), pow2_pair(base, &b, p), tt);
                _mm256_storeu_ps(dst.add(8 * p), r);
            }
        }
    }
    out
}
