//! AVX-512 builds of the bulk lane kernels on power-of-two pyramids: the span sampler with 3x3
//! banks sixteen spans per step (`span_quads_k3_x16`, its set-up in 512-bit lanes) and eight
//! spans per step (`span_quads_k3`, the AVX2 set-up; it takes the groups of eight left over),
//! its four pixels read as the paper's mspan (chosen at run time by [`super::lanes`]'s
//! `span_quads4_best` where the CPU has AVX-512F/VL/BW/DQ; the AVX2 and SSE2 builds stay the
//! fallbacks), and per-pixel trilinear sixteen pixels per step, its set-up in 512-bit lanes
//! (`trilinear_pixels_x16`, chosen by `trilinear_pixels_best`: see `lanes::TRILINEAR_AVX512`;
//! the AVX2 build takes the group of eight left over).
//!
//! The arithmetic is the AVX2 / SSE2 / scalar kernels' operation for operation (`a + (b − a)·t`,
//! no FMA: Rust never contracts a multiply and an add), so the results are the same bits (tested
//! in `super::tests` against the SSE2 baseline and the bank emulator). The set-up of each step
//! (footprint or span extent, level pair, level sizes, texel coordinates, floors, weights,
//! window corners) is the AVX2 build's eight-lane code, here compiled with the AVX-512 features
//! (EVEX encoding, 32 vector registers) — except in `span_quads_k3_x16` and
//! `trilinear_pixels_x16`, where the same operations run on sixteen spans or pixels per zmm (`span_step16`, `mspan_level16`: the 32 images
//! transposed by three rounds of `vpermt2ps`, compares into mask registers, the level offset by
//! one `vpermd` over the 16-entry table), so that the loop issues no 256-bit µops (with 512-bit
//! µops in flight, Intel cores fuse vector ports 0 and 1, and 256-bit work loses a port); on
//! the Sapphire Rapids-class Xeon it measured faster than the eight-span kernel (interleaved
//! best-frame runs and criterion), and trilinear's sixteen-pixel build faster than its AVX2
//! build (where its eight-pixel AVX-512 build, the AVX2 set-up, had been slower). What changes
//! is the per-pixel part:
//!
//! - **span sampler (Seed 000 Eq. 8–10, K = 3), the mspan read:** one span = four pixels x RGBA
//!   = sixteen floats = one zmm. Its interior 3x3 window is read as three rows of three texels,
//!   each row as two overlapping 256-bit loads (texels 0–1 and 1–2: no mask, nothing past the
//!   window is read) — the one parallel read of the nine banks, per level per span. Each pixel
//!   then picks its own 2x2 out of it with one index: `t00` of all four pixels is one
//!   `vpermt2ps` over rows (0, 1) at texel 0, `t10` the same index over the rows' texel-1 loads,
//!   `t01`/`t11` likewise over rows (1, 2); four permutes per level per span instead of sixteen
//!   texel loads. The spans whose window is not interior take the edge path after the step's
//!   interior spans.
//!   The lanes are channel-major (`c·4 + p`: channel c of pixel p), so a span's four per-pixel
//!   weights `[w0 w1 w2 w3]` and the offset part of the permute index are 128-bit broadcasts
//!   from memory (load ports, no shuffle), and one `vpermps` turns the result back into pixel
//!   order before the one 512-bit store per span. The three Eq. (4) bilinear lerps and the level
//!   blend (one weight per span, a broadcast load) run on the four pixels at once.
//! - **per-pixel trilinear (Seed 000 Eq. 2–4), for fairness:** the set-up of sixteen pixels
//!   (footprint, λ split, level pair, per-level texel coordinates, floors, weights, wrapped
//!   indices, edge bits) in lanes = pixels (`tri_step16`, `tri_level16`: the inputs
//!   deinterleaved by two `vpermt2ps` per array, compares into mask registers, the level offset
//!   by one `vpermd`); then the same four pixels per zmm for the taps, lerps and blend: each tap
//!   of four pixels is one 128-bit load and three `vinsertf32x4` from memory, the weights one
//!   `vpermps` each, one 512-bit store per four pixels; where none of the four sits on a level
//!   edge it takes two indices per pixel and level, as the AVX2 build does per eight.
//!
//! Spans whose window is not interior (a level edge, or a level narrower than three texels)
//! take the AVX2 build's out-of-line edge path — except, with Repeat, in `span_quads_k3_x16`,
//! which reads a window crossing the level's right or bottom edge (wrapped) from the level's
//! seam strips (see [`MipTexture`]), with the strip's row stride, as an interior window; there
//! only spans whose pixels lie more than one texel apart take the edge path. K = 4 keeps the
//! AVX2 kernel (its window's rows need a row pair per pixel out of four rows: two permutes and
//! a blend per tap).

use core::arch::x86_64::*;

use glam::{Vec2, Vec4};

use super::Addr;
use super::avx2::{
    Offsets, SpanSetup, SpanStep, SpanWindow, edge_span, span_step, span_window, to_u32x8,
};
use crate::mip::MipTexture;

/// `a + (b − a)·t` lane-wise: the 128-bit `lerp4` on four pixels at once (same operations).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn lerp16(a: __m512, b: __m512, t: __m512) -> __m512 {
    _mm512_add_ps(a, _mm512_mul_ps(_mm512_sub_ps(b, a), t))
}

/// Sixteen `i32` lanes from an array (a constant vector).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn lanes16(v: [i32; 16]) -> __m512i {
    // SAFETY: same size, no invalid bit patterns.
    unsafe { core::mem::transmute::<[i32; 16], __m512i>(v) }
}

// ---------------------------------------------------------------------------------------------
// Span sampler, K = 3: eight spans per step, each span's four pixels from its mspan.

/// One level of `N` spans (eight or sixteen), span-major for the per-span zmm vectors (span `s`
/// at `[s]`).
struct MspanLevel<const N: usize> {
    /// `[row][span]`: doubled texel index of the window's rows 0, 1, 2 (the corner, plus one
    /// and two doubled row strides; `base + 8·index` addresses each).
    rows: [[u32; N]; 3],
    /// `[span][pixel]`: `oy·16 + ox·4`, the lane of the pixel's `t00` in two rows of four
    /// texels (`ox, oy ∈ {0, 1}` from the window corner).
    o: [[i32; 4]; N],
    /// `[span][pixel]`: the Eq. (4) bilinear weights.
    ax: [[f32; 4]; N],
    ay: [[f32; 4]; N],
    /// Lane bits of the spans whose window is interior (in the level, or in one of its Repeat
    /// seam strips: see `seam`).
    ok: i32,
    /// Lane bits of the spans whose window is read from one of the level's Repeat seam strips
    /// ([`MipTexture`]'s seam strips; `corner` and `w2` then address the strip). Always 0 in
    /// the eight-span build. Read by the tests' count only.
    #[cfg_attr(not(test), allow(dead_code))]
    seam: i32,
}

/// Four per-pixel vectors (lanes = spans) as span-major rows `[span][pixel]`: spans 0–3 in the
/// first register, 4–7 in the second.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn span_major(v: &[__m256; 4]) -> [[f32; 4]; 8] {
    let a = _mm512_insertf32x8::<1>(_mm512_castps256_ps512(v[0]), v[1]);
    let b = _mm512_insertf32x8::<1>(_mm512_castps256_ps512(v[2]), v[3]);
    // Lane s·4 + p = pixel p of span s = lane 8p + s of [v0 | v1 | v2 | v3].
    let lo = lanes16([0, 8, 16, 24, 1, 9, 17, 25, 2, 10, 18, 26, 3, 11, 19, 27]);
    let hi = _mm512_add_epi32(lo, _mm512_set1_epi32(4));
    let r = [
        _mm512_permutex2var_ps(a, lo, b),
        _mm512_permutex2var_ps(a, hi, b),
    ];
    // SAFETY: same size, no invalid bit patterns.
    unsafe { core::mem::transmute::<[__m512; 2], [[f32; 4]; 8]>(r) }
}

/// Seed 000 Eq. (10) for eight spans at levels `lvl` ([`span_window`], the AVX2 build's
/// arithmetic), arranged for the mspan read.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn mspan_level<A: Addr>(
    tex: &MipTexture,
    lvl: __m256i,
    sx: &[__m256; 4],
    sy: &[__m256; 4],
    offs: Offsets,
) -> MspanLevel<8> {
    // oy·16 + ox·4: small non-negative integers in interior windows, exact in f32 (other spans
    // take the edge path and ignore theirs).
    let (s16, s4) = (_mm256_set1_ps(16.0), _mm256_set1_ps(4.0));
    let mut o = [_mm256_setzero_ps(); 4];
    let SpanWindow {
        ax,
        ay,
        corner,
        wi,
        ok,
        ..
    } = span_window::<A, 3>(tex, lvl, sx, sy, offs, |j, ox, oy, _, _| {
        let v = _mm256_add_ps(_mm256_mul_ps(oy, s16), _mm256_mul_ps(ox, s4));
        o[j] = _mm256_castsi256_ps(_mm256_cvttps_epi32(v));
    });
    let o = span_major(&o);
    let (c2, w2) = (_mm256_slli_epi32::<1>(corner), _mm256_slli_epi32::<1>(wi));
    let c2w = _mm256_add_epi32(c2, w2);
    MspanLevel {
        rows: [
            to_u32x8(c2),
            to_u32x8(c2w),
            to_u32x8(_mm256_add_epi32(c2w, w2)),
        ],
        // SAFETY: same size, no invalid bit patterns (the i32 bits moved as f32 lanes).
        o: unsafe { core::mem::transmute::<[[f32; 4]; 8], [[i32; 4]; 8]>(o) },
        ax: span_major(&ax),
        ay: span_major(&ay),
        ok,
        seam: 0,
    }
}

/// The constant vectors of the mspan kernel.
#[derive(Clone, Copy)]
struct MspanConsts {
    /// Lane `c·4 + p` = `c` (the channel).
    c0: __m512i,
    /// Channel-major `c·4 + p` -> pixel-major `p·4 + c`.
    to_pixels: __m512i,
}

impl MspanConsts {
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
    fn new() -> MspanConsts {
        let cpat = lanes16([0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3]);
        MspanConsts {
            c0: cpat,
            to_pixels: lanes16([0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15]),
        }
    }
}

/// The bilinear of span `S`'s four pixels (channel-major) from its mspan at one level.
///
/// # Safety
/// `d` must come from [`mspan_level`] or [`mspan_level16`] on the texture whose texel buffer
/// ([`MipTexture::texel_buffer`]) starts at `base`, with span `S` interior (`d.ok` bit set): its
/// three rows of three texels lie inside the level, or inside one of its Repeat seam strips.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
unsafe fn mspan_bilinear<const N: usize, const S: usize>(
    base: *const u8,
    d: &MspanLevel<N>,
    k: &MspanConsts,
) -> __m512 {
    // SAFETY: the caller's contract: rows corner + r·w, r < 3, texels 0..3 inside the level
    // (the interior window, x0 + 3 ≤ w, y0 + 3 ≤ h) or in a seam strip (wrapped x0 < w,
    // y0 < h: columns up to w + 1 of rows up to h + 1 in the column strip, stride 4, or
    // columns x0 + 3 ≤ w of rows up to h + 1 in the row strip, stride w); each 256-bit load
    // reads two of a row's three texels. The 128-bit broadcasts read 4 values of `d`'s arrays.
    unsafe {
        // The mspan: one read of the 3x3 banks (Seed 000 Eq. 10), each row as its texels
        // (0, 1) and (1, 2) (the permutes read lanes 0–7 of each: texels 0 and 1 from the
        // index).
        let row = |r: usize, t: usize| {
            let p = base.add((d.rows[r][S] as usize + 2 * t) * 8) as *const f32;
            _mm512_zextps256_ps512(_mm256_loadu_ps(p))
        };
        let (r0, r1, r2) = (row(0, 0), row(1, 0), row(2, 0));
        let (s0, s1, s2) = (row(0, 1), row(1, 1), row(2, 1));
        // Each pixel's 2x2 out of it: lane c·4 + p takes channel c of texel (ox_p, oy_p) of
        // rows (0, 1) or (1, 2); the texel to its right is the same lane of the rows one texel
        // on.
        let o = _mm512_broadcast_i32x4(_mm_loadu_si128(d.o[S].as_ptr() as *const __m128i));
        let i = _mm512_add_epi32(o, k.c0);
        let t00 = _mm512_permutex2var_ps(r0, i, r1);
        let t10 = _mm512_permutex2var_ps(s0, i, s1);
        let t01 = _mm512_permutex2var_ps(r1, i, r2);
        let t11 = _mm512_permutex2var_ps(s1, i, s2);
        let wx = _mm512_broadcast_f32x4(_mm_loadu_ps(d.ax[S].as_ptr()));
        let wy = _mm512_broadcast_f32x4(_mm_loadu_ps(d.ay[S].as_ptr()));
        lerp16(lerp16(t00, t10, wx), lerp16(t01, t11, wx), wy)
    }
}

/// Span `S` of a step: its four pixels from the levels `a` (and `b`, blended by `frac[S]`, per
/// Eq. 4) when its window is interior (`fast` bit set); else nothing (the caller runs the edge
/// path afterwards: [`edge_spans`]).
///
/// # Safety
/// As [`mspan_bilinear`] for spans whose `fast` bit is set (`b` too unless `single`).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
#[allow(clippy::too_many_arguments)]
unsafe fn mspan_out<const N: usize, const S: usize>(
    base: *const u8,
    a: &MspanLevel<N>,
    b: &MspanLevel<N>,
    frac: &[f32; N],
    fast: i32,
    single: i32,
    k: &MspanConsts,
    o: &mut [Vec4; 4],
) {
    if fast & (1 << S) == 0 {
        return;
    }
    // SAFETY: the caller's contract; `o` holds 16 floats.
    unsafe {
        let ca = mspan_bilinear::<N, S>(base, a, k);
        let r = if single & (1 << S) != 0 {
            ca
        } else {
            // Seed 000 Eq. (4): one blend weight per span.
            let cb = mspan_bilinear::<N, S>(base, b, k);
            let t: __m512;
            // `_mm512_set1_ps(frac[S])` as one `vbroadcastss` from memory (LLVM otherwise
            // loads the scalar first and broadcasts the register, a port-5 µop). S < N: the
            // load is inside `frac`.
            const { assert!(S < N) };
            core::arch::asm!(
                "vbroadcastss {t}, dword ptr [{p} + {o}]",
                p = in(reg) frac.as_ptr(),
                o = const 4 * S,
                t = out(zmm_reg) t,
                options(pure, readonly, nostack, preserves_flags),
            );
            lerp16(ca, cb, t)
        };
        _mm512_storeu_ps(
            o.as_mut_ptr() as *mut f32,
            _mm512_permutexvar_ps(k.to_pixels, r),
        );
    }
}

/// The AVX2 build's edge path for the spans of a step whose bit is clear in `fast` (windows
/// crossing a level edge, or a conflict), after the interior spans (their code then has no
/// call between them, and no span's images are copied for one).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn edge_spans<A: Addr>(tex: &MipTexture, q: &[[Vec2; 4]], o: &mut [[Vec4; 4]], fast: i32) {
    let mut slow = !fast as u32 & ((1u32 << q.len()) - 1);
    while slow != 0 {
        let s = slow.trailing_zeros() as usize;
        slow &= slow - 1;
        // SAFETY: AVX2 is implied by AVX-512F; the texture is a power of two (the caller's
        // contract).
        o[s] = unsafe { edge_span::<A, 3>(tex, q[s]) };
    }
}

/// [`super::lanes::span_quads4`] with 3x3 banks for AVX-512, eight spans per step, each span's
/// pixels from its mspan: bit-identical, whole groups of eight spans (the caller does the tail).
///
/// # Safety
/// The CPU must support AVX-512F/VL/BW/DQ; the texture must be a power of two.
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
pub(super) unsafe fn span_quads_k3<A: Addr>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) -> usize {
    debug_assert!(tex.is_pow2());
    let c = SpanSetup::new(tex);
    let base = tex.texels().as_ptr() as *const u8;
    let n = quads.len().min(out.len()) / 8 * 8;
    let k = MspanConsts::new();
    for (o, q) in out[..n].chunks_exact_mut(8).zip(quads[..n].chunks_exact(8)) {
        let SpanStep {
            sx,
            sy,
            i0,
            i1,
            frac,
            single,
        } = span_step::<A, 3>(&c, q.try_into().expect("eight spans"));
        let mut a = mspan_level::<A>(tex, i0, &sx, &sy, c.offs);
        let mut b = mspan_level::<A>(tex, i1, &sx, &sy, c.offs);
        let mut fr: [f32; 8] = core::array::from_fn(|s| frac_lane(frac, s));
        // Keep the per-span values in memory: each is then one load or one broadcast load
        // (else LLVM keeps the vectors and extracts lanes with shuffles).
        core::hint::black_box((&mut a, &mut b, &mut fr));
        let fast = a.ok & (b.ok | single);
        // SAFETY: `mspan_out`'s contract: levels from `mspan_level` on this texture.
        unsafe {
            mspan_out::<8, 0>(base, &a, &b, &fr, fast, single, &k, &mut o[0]);
            mspan_out::<8, 1>(base, &a, &b, &fr, fast, single, &k, &mut o[1]);
            mspan_out::<8, 2>(base, &a, &b, &fr, fast, single, &k, &mut o[2]);
            mspan_out::<8, 3>(base, &a, &b, &fr, fast, single, &k, &mut o[3]);
            mspan_out::<8, 4>(base, &a, &b, &fr, fast, single, &k, &mut o[4]);
            mspan_out::<8, 5>(base, &a, &b, &fr, fast, single, &k, &mut o[5]);
            mspan_out::<8, 6>(base, &a, &b, &fr, fast, single, &k, &mut o[6]);
            mspan_out::<8, 7>(base, &a, &b, &fr, fast, single, &k, &mut o[7]);
        }
        edge_spans::<A>(tex, q, o, fast);
    }
    n
}

/// Lane `s` of eight floats.
#[inline(always)]
fn frac_lane(v: __m256, s: usize) -> f32 {
    // SAFETY: same size, no invalid bit patterns.
    unsafe { core::mem::transmute::<__m256, [f32; 8]>(v)[s] }
}

// ---------------------------------------------------------------------------------------------
// Span sampler, K = 3: sixteen spans per step, the set-up in 512-bit lanes (lanes = spans).

/// `i32` lanes from a lane -> source function (the index vectors of the transposes, built at
/// compile time).
macro_rules! perm16 {
    (|$l:ident| $e:expr) => {{
        const P: [i32; 16] = {
            let mut r = [0i32; 16];
            let mut $l = 0usize;
            while $l < 16 {
                r[$l] = ($e) as i32;
                $l += 1;
            }
            r
        };
        lanes16(P)
    }};
}

/// `vpermt2ps` over `(a | b)` (source lanes 0–15 of `a`, 16–31 of `b`).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn p2(a: __m512, i: __m512i, b: __m512) -> __m512 {
    _mm512_permutex2var_ps(a, i, b)
}

/// [`super::lanes::log2_split4`] on sixteen lanes (the AVX2 `log2_split8`'s operations).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn log2_split16(x: __m512) -> (__m512i, __m512) {
    let bits = _mm512_castps_si512(x);
    let e = _mm512_sub_epi32(
        _mm512_and_si512(_mm512_srli_epi32::<23>(bits), _mm512_set1_epi32(0xff)),
        _mm512_set1_epi32(127),
    );
    let t = _mm512_sub_ps(
        _mm512_castsi512_ps(_mm512_or_si512(
            _mm512_and_si512(bits, _mm512_set1_epi32(0x007f_ffff)),
            _mm512_set1_epi32(0x3f80_0000),
        )),
        _mm512_set1_ps(1.0),
    );
    let c = |k: f32| _mm512_set1_ps(k);
    let poly = _mm512_add_ps(c(super::LOG2_C3), _mm512_mul_ps(t, c(super::LOG2_C4)));
    let poly = _mm512_add_ps(c(super::LOG2_C2), _mm512_mul_ps(t, poly));
    let poly = _mm512_add_ps(c(super::LOG2_C1), _mm512_mul_ps(t, poly));
    (e, _mm512_mul_ps(t, poly))
}

/// [`super::clamp4`] on sixteen lanes: clamp to ±2^30, then NaN -> +0 (the AVX2
/// `clamp_nan0_8`'s order; a zero-masked move instead of the `and` with the compare).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn clamp_nan0_16(v: __m512) -> __m512 {
    let c = _mm512_min_ps(
        _mm512_max_ps(v, _mm512_set1_ps(-super::COORD_LIMIT)),
        _mm512_set1_ps(super::COORD_LIMIT),
    );
    _mm512_maskz_mov_ps(_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(v, v), c)
}

/// `roundps` floor on sixteen lanes (exact).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn floor16(x: __m512) -> __m512 {
    _mm512_roundscale_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(x)
}

/// Level size per lane, `max(2^(b − 127 − lvl), 1)` built from the float exponent (exact).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn pow2_16(b: i32, lvl: __m512i) -> __m512 {
    _mm512_castsi512_ps(_mm512_slli_epi32::<23>(_mm512_sub_epi32(
        _mm512_set1_epi32(b),
        lvl,
    )))
}

/// `min(min(v0, v1), min(v2, v3))` and the `max` likewise (the AVX2 build's order: `minps`
/// is not commutative on signed zeros).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn min4_16(v: &[__m512; 4]) -> __m512 {
    _mm512_min_ps(_mm512_min_ps(v[0], v[1]), _mm512_min_ps(v[2], v[3]))
}

#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn max4_16(v: &[__m512; 4]) -> __m512 {
    _mm512_max_ps(_mm512_max_ps(v[0], v[1]), _mm512_max_ps(v[2], v[3]))
}

/// A texture's constants for [`span_step16`] and [`mspan_level16`] (and trilinear's
/// [`tri_step16`] and [`tri_level16`]).
struct Setup16 {
    /// The 16-entry level-offset table (one `vpermd` per lookup).
    offs: __m512i,
    sw: __m512,
    sh: __m512,
    inv_w: __m512,
    inv_h: __m512,
    last: i32,
    nw: i32,
    nh: i32,
}

impl Setup16 {
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
    fn new(tex: &MipTexture) -> Setup16 {
        let l0 = &tex.levels()[0];
        let t = tex.level_offsets16();
        Setup16 {
            // SAFETY: `t` holds 16 i32 (one unaligned 512-bit load).
            offs: unsafe { _mm512_loadu_si512(t.as_ptr() as *const __m512i) },
            sw: _mm512_set1_ps(l0.width_f),
            sh: _mm512_set1_ps(l0.height_f),
            inv_w: _mm512_set1_ps(l0.inv_width_f),
            inv_h: _mm512_set1_ps(l0.inv_height_f),
            last: tex.level_count() as i32 - 1,
            nw: tex.width().trailing_zeros() as i32,
            nh: tex.height().trailing_zeros() as i32,
        }
    }
}

/// Sixteen lanes' coordinates, their level pair, Eq. (4) weight and the bits of single-level
/// lanes: for the span sampler (`C = [__m512; 4]`) the spans' level-0 texel coordinates (`sx[j]`,
/// `sy[j]`: pixel `j`, lane = span), for trilinear (`C = __m512`) the pixels' map coordinates
/// (lane = pixel).
struct Step16<C = [__m512; 4]> {
    sx: C,
    sy: C,
    i0: __m512i,
    i1: __m512i,
    frac: __m512,
    single: i32,
}

/// [`super::avx2::span_step`] (K = 3) on sixteen spans: the images transposed into lanes,
/// clamped, the repeat shift, Seed 000 Eq. (9)'s extent and the level pair, lane for lane the
/// same operations.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn span_step16<A: Addr>(c: &Setup16, q: &[[Vec2; 4]; 16]) -> Step16 {
    // Eight loads of two quads each: z[k] lane l = component l mod 8 (x0 y0 x1 y1 x2 y2 x3
    // y3) of span 2k + l / 8.
    // (Plain loops here: closures passed to `array::map` / `from_fn` are not inlined into a
    // `target_feature` function.)
    let mut z = [_mm512_setzero_ps(); 8];
    for (k, zk) in z.iter_mut().enumerate() {
        // SAFETY: sixteen quads = 128 contiguous floats, read unaligned.
        *zk = unsafe { _mm512_loadu_ps(q[2 * k].as_ptr() as *const f32) };
    }
    // Transpose in three rounds of two-source permutes. Round 1: spans 4m..4m+4, components
    // 4h..4h+4, lane c·4 + s.
    let r1 = [
        perm16!(|l| (l % 4 / 2) * 16 + (l % 4 % 2) * 8 + l / 4),
        perm16!(|l| (l % 4 / 2) * 16 + (l % 4 % 2) * 8 + 4 + l / 4),
    ];
    let mut a = [[z[0]; 2]; 4];
    for m in 0..4 {
        for h in 0..2 {
            a[m][h] = p2(z[2 * m], r1[h], z[2 * m + 1]);
        }
    }
    // Round 2: spans 8g..8g+8, components 4h + 2e + (0, 1), lane c·8 + s.
    let r2 = [
        perm16!(|l| (l % 8 / 4) * 16 + (l / 8) * 4 + l % 4),
        perm16!(|l| (l % 8 / 4) * 16 + (2 + l / 8) * 4 + l % 4),
    ];
    let mut b = [[[z[0]; 2]; 2]; 2];
    for g in 0..2 {
        for h in 0..2 {
            for e in 0..2 {
                b[g][h][e] = p2(a[2 * g][h], r2[e], a[2 * g + 1][h]);
            }
        }
    }
    // Round 3: all sixteen spans, component 4h + 2e + c: x (c = 0) or y (c = 1) of pixel
    // j = 2h + e.
    let r3 = [
        perm16!(|l| (l / 8) * 16 + l % 8),
        perm16!(|l| (l / 8) * 16 + 8 + l % 8),
    ];
    let (mut sx, mut sy) = ([z[0]; 4], [z[0]; 4]);
    for j in 0..4 {
        let (lo, hi) = (b[0][j / 2][j % 2], b[1][j / 2][j % 2]);
        sx[j] = clamp_nan0_16(_mm512_mul_ps(p2(lo, r3[0], hi), c.sw));
        sy[j] = clamp_nan0_16(_mm512_mul_ps(p2(lo, r3[1], hi), c.sh));
    }
    if A::REPEAT {
        // Shift each span by whole periods so its corner lies in the first period.
        let px = _mm512_mul_ps(floor16(_mm512_mul_ps(min4_16(&sx), c.inv_w)), c.sw);
        let py = _mm512_mul_ps(floor16(_mm512_mul_ps(min4_16(&sy), c.inv_h)), c.sh);
        for j in 0..4 {
            sx[j] = _mm512_sub_ps(sx[j], px);
            sy[j] = _mm512_sub_ps(sy[j], py);
        }
    }
    // Seed 000 Eq. (9): span level from the extent of the four images.
    let ext = _mm512_max_ps(
        _mm512_sub_ps(max4_16(&sx), min4_16(&sx)),
        _mm512_sub_ps(max4_16(&sy), min4_16(&sy)),
    );
    let (e, frac) = log2_split16(ext);
    // K = 3 takes the pair one level coarser (see the module doc's level policy).
    let fine = _mm512_add_epi32(e, _mm512_set1_epi32(1));
    let below = _mm512_cmpgt_epi32_mask(_mm512_setzero_si512(), fine);
    let above = _mm512_cmpgt_epi32_mask(fine, _mm512_set1_epi32(c.last - 1));
    // below ? 0 : above ? last : fine.
    let i0 = _mm512_maskz_mov_epi32(
        !below,
        _mm512_mask_mov_epi32(fine, above, _mm512_set1_epi32(c.last)),
    );
    // Blend two levels unless clamped to the pyramid or frac(λ) = 0.
    let clamped = below | above;
    let zero_t = _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(frac, _mm512_setzero_ps());
    let i1 = _mm512_mask_add_epi32(i0, !clamped, i0, _mm512_set1_epi32(1));
    Step16 {
        sx,
        sy,
        i0,
        i1,
        frac,
        single: (clamped | zero_t) as i32,
    }
}

/// Four per-pixel vectors (lanes = spans) as span-major rows `[span][pixel]` (sixteen spans,
/// four per register).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn span_major16(v: &[__m512; 4]) -> [[f32; 4]; 16] {
    // Pixels (0, 1) and (2, 3) of spans 8g..8g+8: lane s·2 + p.
    let h = [
        perm16!(|l| (l % 2) * 16 + l / 2),
        perm16!(|l| (l % 2) * 16 + 8 + l / 2),
    ];
    let p01 = [p2(v[0], h[0], v[1]), p2(v[0], h[1], v[1])];
    let p23 = [p2(v[2], h[0], v[3]), p2(v[2], h[1], v[3])];
    // Spans 4k..4k+4: lane s·4 + p, from span 4(k mod 2) + s of the pair vectors.
    let r = [
        perm16!(|l| (l % 4 / 2) * 16 + (l / 4) * 2 + l % 2),
        perm16!(|l| (l % 4 / 2) * 16 + (4 + l / 4) * 2 + l % 2),
    ];
    let mut out = [v[0]; 4];
    for k in 0..4 {
        out[k] = p2(p01[k / 2], r[k % 2], p23[k / 2]);
    }
    // SAFETY: same size, no invalid bit patterns.
    unsafe { core::mem::transmute::<[__m512; 4], [[f32; 4]; 16]>(out) }
}

/// [`super::avx2::span_window`] (K = 3) for sixteen spans at levels `lvl`, lane for lane the
/// same operations (Seed 000 Eq. 10), arranged for the mspan read as [`mspan_level`] does.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn mspan_level16<A: Addr>(
    c: &Setup16,
    r: &Seams16,
    lvl: __m512i,
    sx: &[__m512; 4],
    sy: &[__m512; 4],
) -> MspanLevel<16> {
    // Level scale (exactly w_i / w_0 = max(2^−i, 1/w_0)) and size per lane.
    let scx = _mm512_max_ps(pow2_16(127, lvl), c.inv_w);
    let scy = _mm512_max_ps(pow2_16(127, lvl), c.inv_h);
    let one = _mm512_set1_ps(1.0);
    let wf = _mm512_max_ps(pow2_16(127 + c.nw, lvl), one);
    let hf = _mm512_max_ps(pow2_16(127 + c.nh, lvl), one);
    let half = _mm512_set1_ps(0.5);
    let z = _mm512_setzero_ps();
    let mut flx = [z; 4];
    let mut fly = [z; 4];
    let mut ax = [z; 4];
    let mut ay = [z; 4];
    for j in 0..4 {
        // This level's texel coordinates (Eq. 3 on 2^L r_m − ½), floors and weights.
        let mut x = _mm512_sub_ps(_mm512_mul_ps(sx[j], scx), half);
        let mut y = _mm512_sub_ps(_mm512_mul_ps(sy[j], scy), half);
        if !A::REPEAT {
            // Clamp-to-edge bilinear equals bilinear at the clamped coordinate.
            x = _mm512_min_ps(_mm512_max_ps(x, z), _mm512_sub_ps(wf, one));
            y = _mm512_min_ps(_mm512_max_ps(y, z), _mm512_sub_ps(hf, one));
        }
        flx[j] = floor16(x);
        fly[j] = floor16(y);
        ax[j] = _mm512_sub_ps(x, flx[j]);
        ay[j] = _mm512_sub_ps(y, fly[j]);
    }
    // The window corner: the span's lowest texel.
    let (mx, my) = (min4_16(&flx), min4_16(&fly));
    let (x0, y0) = (_mm512_cvttps_epi32(mx), _mm512_cvttps_epi32(my));
    let (wi, hi) = (_mm512_cvttps_epi32(wf), _mm512_cvttps_epi32(hf));
    // Level offset (0 ≤ lvl < 16: one table permute), + y0·w + x0.
    let corner = _mm512_add_epi32(
        _mm512_add_epi32(
            _mm512_permutexvar_epi32(lvl, c.offs),
            _mm512_mullo_epi32(y0, wi),
        ),
        x0,
    );
    // Each pixel's offset from the corner: oy·16 + ox·4 (small non-negative integers in
    // interior windows, exact in f32), and the spans with an offset past the window.
    let lim = _mm512_set1_ps(1.0);
    let (s16, s4) = (_mm512_set1_ps(16.0), _mm512_set1_ps(4.0));
    let mut over: __mmask16 = 0;
    let mut o = [z; 4];
    for j in 0..4 {
        let ox = _mm512_sub_ps(flx[j], mx);
        let oy = _mm512_sub_ps(fly[j], my);
        over |=
            _mm512_cmp_ps_mask::<_CMP_GT_OQ>(ox, lim) | _mm512_cmp_ps_mask::<_CMP_GT_OQ>(oy, lim);
        let v = _mm512_add_ps(_mm512_mul_ps(oy, s16), _mm512_mul_ps(ox, s4));
        o[j] = _mm512_castsi512_ps(_mm512_cvttps_epi32(v));
    }
    // Interior: x0 ≥ 0, y0 ≥ 0, x0 + 3 ≤ w, y0 + 3 ≤ h.
    let k = _mm512_set1_epi32(3);
    let zi = _mm512_setzero_si512();
    let outside = _mm512_cmpgt_epi32_mask(zi, x0)
        | _mm512_cmpgt_epi32_mask(zi, y0)
        | _mm512_cmpgt_epi32_mask(_mm512_add_epi32(x0, k), wi)
        | _mm512_cmpgt_epi32_mask(_mm512_add_epi32(y0, k), hi);
    // Repeat: every window, its corner wrapped into the level (power of two: a mask), is
    // contiguous in the level or in one of its seam strips (origins from the tables, level
    // coordinates): crossing the right edge in the column strip (stride 4), else crossing the
    // bottom edge in the row strip (stride w).
    let (corner, stride, outside, seam) = if A::REPEAT {
        let one_i = _mm512_set1_epi32(1);
        let xw = _mm512_and_si512(x0, _mm512_sub_epi32(wi, one_i));
        let yw = _mm512_and_si512(y0, _mm512_sub_epi32(hi, one_i));
        let xs = _mm512_cmpgt_epi32_mask(_mm512_add_epi32(xw, k), wi);
        let ys = _mm512_cmpgt_epi32_mask(_mm512_add_epi32(yw, k), hi) & !xs;
        // Level or row strip: origin + yw·w + xw.
        let org = _mm512_mask_mov_epi32(
            _mm512_permutexvar_epi32(lvl, c.offs),
            ys,
            _mm512_permutexvar_epi32(lvl, r.row),
        );
        let lr = _mm512_add_epi32(_mm512_add_epi32(org, _mm512_mullo_epi32(yw, wi)), xw);
        // Column strip: origin + 4·yw + xw.
        let cs = _mm512_add_epi32(
            _mm512_add_epi32(
                _mm512_permutexvar_epi32(lvl, r.col),
                _mm512_slli_epi32::<2>(yw),
            ),
            xw,
        );
        (
            _mm512_mask_mov_epi32(lr, xs, cs),
            _mm512_mask_mov_epi32(wi, xs, _mm512_set1_epi32(4)),
            0,
            xs | ys,
        )
    } else {
        (corner, wi, outside, 0)
    };
    let o = span_major16(&o);
    let (c2, w2) = (
        _mm512_slli_epi32::<1>(corner),
        _mm512_slli_epi32::<1>(stride),
    );
    let c2w = _mm512_add_epi32(c2, w2);
    MspanLevel {
        rows: [
            to_u32x16(c2),
            to_u32x16(c2w),
            to_u32x16(_mm512_add_epi32(c2w, w2)),
        ],
        // SAFETY: same size, no invalid bit patterns (the i32 bits moved as f32 lanes).
        o: unsafe { core::mem::transmute::<[[f32; 4]; 16], [[i32; 4]; 16]>(o) },
        ax: span_major16(&ax),
        ay: span_major16(&ay),
        ok: !(over | outside) as i32 & 0xffff,
        seam: seam as i32 & !(over as i32) & 0xffff,
    }
}

/// A texture's Repeat seam strips for [`mspan_level16`] ([`MipTexture::seam_offsets16`]).
struct Seams16 {
    /// The column and row strips' origins per level (one `vpermd` per lookup).
    col: __m512i,
    row: __m512i,
}

impl Seams16 {
    /// `None` without strips (then the kernel must not be run with Repeat).
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
    fn new(tex: &MipTexture) -> Option<Seams16> {
        let (col, row) = tex.seam_offsets16()?;
        // SAFETY: each table holds 16 i32 (one unaligned 512-bit load).
        unsafe {
            Some(Seams16 {
                col: _mm512_loadu_si512(col.as_ptr() as *const __m512i),
                row: _mm512_loadu_si512(row.as_ptr() as *const __m512i),
            })
        }
    }
}

#[cfg(test)]
thread_local! {
    /// Windows (span-levels) the sixteen-span kernel read from a Repeat seam strip on this
    /// thread (for the tests: the seam path must be exercised).
    pub(super) static SEAM_WINDOWS: core::cell::Cell<u64> = const { core::cell::Cell::new(0) };
}

/// Sixteen `i32` lanes as an array (stored once, read per span).
#[inline(always)]
fn to_u32x16(v: __m512i) -> [u32; 16] {
    // SAFETY: same size, no invalid bit patterns.
    unsafe { core::mem::transmute::<__m512i, [u32; 16]>(v) }
}

/// [`span_quads_k3`] sixteen spans per step, the whole set-up in 512-bit lanes (no 256-bit
/// µops in the loop but the edge path's): bit-identical, whole groups of sixteen spans (the
/// caller does the tail, e.g. [`span_quads_k3`] then the scalar remainder). With Repeat,
/// windows crossing a level edge are read from the level's seam strips ([`MipTexture`]'s
/// seam strips) as interior windows, so only spans whose pixels are more than one texel apart
/// (Clamp: also windows at a level edge) take the edge path.
///
/// # Safety
/// The CPU must support AVX-512F/VL/BW/DQ; the texture must be a power of two.
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
pub(super) unsafe fn span_quads_k3_x16<A: Addr>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) -> usize {
    debug_assert!(tex.is_pow2());
    let c = Setup16::new(tex);
    // Power-of-two pyramids always have their strips (Clamp does not read them).
    let r = Seams16::new(tex).expect("power-of-two pyramid");
    let base = tex.texel_buffer().as_ptr() as *const u8;
    let n = quads.len().min(out.len()) / 16 * 16;
    let k = MspanConsts::new();
    for (o, q) in out[..n]
        .chunks_exact_mut(16)
        .zip(quads[..n].chunks_exact(16))
    {
        let s = span_step16::<A>(&c, q.try_into().expect("sixteen spans"));
        let mut a = mspan_level16::<A>(&c, &r, s.i0, &s.sx, &s.sy);
        let mut b = mspan_level16::<A>(&c, &r, s.i1, &s.sx, &s.sy);
        // SAFETY: same size, no invalid bit patterns.
        let mut fr = unsafe { core::mem::transmute::<__m512, [f32; 16]>(s.frac) };
        // Keep the per-span values in memory: each is then one load or one broadcast load.
        core::hint::black_box((&mut a, &mut b, &mut fr));
        let (fast, single) = (a.ok & (b.ok | s.single), s.single);
        #[cfg(test)]
        SEAM_WINDOWS.with(|n| {
            let used = (fast & a.seam).count_ones() + (fast & !single & b.seam).count_ones();
            n.set(n.get() + used as u64);
        });
        macro_rules! spans {
            ($($i:literal)*) => {$(
                mspan_out::<16, $i>(base, &a, &b, &fr, fast, single, &k, &mut o[$i]);
            )*};
        }
        // SAFETY: `mspan_out`'s contract: levels from `mspan_level16` on this texture.
        unsafe {
            spans!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15);
        }
        edge_spans::<A>(tex, q, o, fast);
    }
    n
}

// ---------------------------------------------------------------------------------------------
// Per-pixel trilinear: sixteen pixels per step, the set-up in 512-bit lanes (lane = pixel).

/// Sixteen `Vec2` as `(x lanes, y lanes)`, pixel `p` in lane `p`.
///
/// # Safety
/// `p` must point to at least 32 readable floats.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
unsafe fn deinterleave16(p: *const f32) -> (__m512, __m512) {
    // SAFETY: the caller's contract.
    let (a, b) = unsafe { (_mm512_loadu_ps(p), _mm512_loadu_ps(p.add(16))) };
    (
        p2(a, perm16!(|l| 2 * l), b),
        p2(a, perm16!(|l| 2 * l + 1), b),
    )
}

/// [`super::avx2::tri_step`] on sixteen pixels `i..i + 16`: Seed 000 Eq. (2)'s footprint (NaN
/// terms as 0) and the level split, lane for lane the same operations (compares into mask
/// registers).
///
/// # Safety
/// `i + 16` must not exceed the length of `uv`, `dx` and `dy`.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
unsafe fn tri_step16(
    c: &Setup16,
    i: usize,
    uv: &[Vec2],
    dx: &[Vec2],
    dy: &[Vec2],
) -> Step16<__m512> {
    let abs = _mm512_castsi512_ps(_mm512_set1_epi32(0x7fff_ffff));
    // SAFETY: the caller's contract (16 Vec2 = 32 floats from `i` in each slice).
    let ((u, v), (dxu, dxv), (dyu, dyv)) = unsafe {
        (
            deinterleave16(uv.as_ptr().add(i) as *const f32),
            deinterleave16(dx.as_ptr().add(i) as *const f32),
            deinterleave16(dy.as_ptr().add(i) as *const f32),
        )
    };
    // Seed 000 Eq. (2): the footprint, NaN terms as 0 (`maxps` returns its second operand, +0,
    // when the first is NaN).
    let z = _mm512_setzero_ps();
    let (sw, sh) = (c.sw, c.sh);
    let fu = _mm512_max_ps(
        _mm512_max_ps(_mm512_and_ps(_mm512_mul_ps(dxu, sw), abs), z),
        _mm512_max_ps(_mm512_and_ps(_mm512_mul_ps(dyu, sw), abs), z),
    );
    let fv = _mm512_max_ps(
        _mm512_max_ps(_mm512_and_ps(_mm512_mul_ps(dxv, sh), abs), z),
        _mm512_max_ps(_mm512_and_ps(_mm512_mul_ps(dyv, sh), abs), z),
    );
    let m = _mm512_max_ps(fu, fv);
    // λ = log2 m split into ⌊λ⌋ and frac(λ); level pair as `trilinear4`.
    let (e, frac) = log2_split16(m);
    let minified = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(m, _mm512_set1_ps(1.0));
    let past_top = _mm512_cmpgt_epi32_mask(e, _mm512_set1_epi32(c.last - 1));
    // minified ? (past_top ? last : e) : 0.
    let i0 = _mm512_maskz_mov_epi32(
        minified,
        _mm512_mask_mov_epi32(e, past_top, _mm512_set1_epi32(c.last)),
    );
    let single = !minified | past_top;
    let i1 = _mm512_mask_add_epi32(i0, !single, i0, _mm512_set1_epi32(1));
    Step16 {
        sx: u,
        sy: v,
        i0,
        i1,
        frac,
        single: single as i32,
    }
}

/// One level of sixteen pixels (lane = pixel): the doubled texel indices of their 2x2 taps and
/// their weights.
struct TriLevel16 {
    /// `[t00, t10, t01, t11][pixel]`.
    idx: [[u32; 16]; 4],
    ax: __m512,
    ay: __m512,
    /// Bits of the pixels whose 2x2 is split by the level edge (`x1 ≠ x0 + 1` or
    /// `y1 ≠ y0 + 1`); where clear, `t10 = t00 + 1` and `t11 = t01 + 1`.
    edge: i32,
}

/// `Addr::wrap` on sixteen lanes (`n`: the level size per lane; Repeat on power-of-two levels).
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn wrap16<A: Addr>(i: __m512i, n: __m512i) -> __m512i {
    let nm1 = _mm512_sub_epi32(n, _mm512_set1_epi32(1));
    if A::REPEAT {
        _mm512_and_si512(i, nm1)
    } else {
        _mm512_min_epi32(_mm512_max_epi32(i, _mm512_setzero_si512()), nm1)
    }
}

/// [`super::avx2::tri_level`] on sixteen pixels at levels `lvl`: Seed 000 Eq. (3) on
/// `2^L r_m − ½`, lane for lane the same operations, then the texel indices in lanes.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
fn tri_level16<A: Addr>(c: &Setup16, u: __m512, v: __m512, lvl: __m512i) -> TriLevel16 {
    let one = _mm512_set1_ps(1.0);
    let wf = _mm512_max_ps(pow2_16(127 + c.nw, lvl), one);
    let hf = _mm512_max_ps(pow2_16(127 + c.nh, lvl), one);
    let half = _mm512_set1_ps(0.5);
    // [`super::clampc`]: NaN -> −2^30 (`maxps` returns its second operand), then ±2^30.
    let (lo, hi) = (
        _mm512_set1_ps(-super::COORD_LIMIT),
        _mm512_set1_ps(super::COORD_LIMIT),
    );
    // Texel coordinates with texel centres at integers, floors and Eq. (4) weights.
    let x = _mm512_min_ps(
        _mm512_max_ps(_mm512_sub_ps(_mm512_mul_ps(u, wf), half), lo),
        hi,
    );
    let y = _mm512_min_ps(
        _mm512_max_ps(_mm512_sub_ps(_mm512_mul_ps(v, hf), half), lo),
        hi,
    );
    let (flx, fly) = (floor16(x), floor16(y));
    let (ax, ay) = (_mm512_sub_ps(x, flx), _mm512_sub_ps(y, fly));
    let (fx, fy) = (_mm512_cvttps_epi32(flx), _mm512_cvttps_epi32(fly));
    let (wi, hi) = (_mm512_cvttps_epi32(wf), _mm512_cvttps_epi32(hf));
    let one_i = _mm512_set1_epi32(1);
    // Wrapped columns and rows (Addr), then texel indices offset + y·w + x, doubled.
    let x0 = wrap16::<A>(fx, wi);
    let x1 = wrap16::<A>(_mm512_add_epi32(fx, one_i), wi);
    let y0 = wrap16::<A>(fy, hi);
    let y1 = wrap16::<A>(_mm512_add_epi32(fy, one_i), hi);
    // Level offset (0 ≤ lvl < 16: one table permute).
    let off = _mm512_permutexvar_epi32(lvl, c.offs);
    let r0 = _mm512_add_epi32(off, _mm512_mullo_epi32(y0, wi));
    let r1 = _mm512_add_epi32(off, _mm512_mullo_epi32(y1, wi));
    let d = |r: __m512i, c: __m512i| to_u32x16(_mm512_slli_epi32::<1>(_mm512_add_epi32(r, c)));
    // Pixels whose 2x2 is not split by wrap-around or clamping at the level edge.
    let inside = _mm512_cmpeq_epi32_mask(x1, _mm512_add_epi32(x0, one_i))
        & _mm512_cmpeq_epi32_mask(y1, _mm512_add_epi32(y0, one_i));
    TriLevel16 {
        idx: [d(r0, x0), d(r0, x1), d(r1, x0), d(r1, x1)],
        ax,
        ay,
        edge: !inside as i32 & 0xffff,
    }
}

/// Bilinear of pixels `4G..4G + 4` of a sixteen-pixel step, pixel-major (`widx` spreads lane
/// `4G + k`'s weights over pixel `k`'s four channels).
///
/// # Safety
/// `p` must come from [`tri_level16`] on the texture whose texels start at `base`.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
unsafe fn tri_quad16<const G: usize, const INSIDE: bool>(
    base: *const u8,
    p: &TriLevel16,
    widx: __m512i,
) -> __m512 {
    // Four pixels' texel `c` (plus `d` doubled units): one 128-bit load and three inserts.
    macro_rules! ld {
        ($c:expr, $d:expr) => {{
            let ix = &p.idx[$c];
            // SAFETY: the caller's contract (indices inside the texel buffer).
            unsafe {
                let at = |k: usize| base.add((ix[4 * G + k] as usize + $d) * 8) as *const f32;
                let v = _mm512_castps128_ps512(_mm_loadu_ps(at(0)));
                let v = _mm512_insertf32x4::<1>(v, _mm_loadu_ps(at(1)));
                let v = _mm512_insertf32x4::<2>(v, _mm_loadu_ps(at(2)));
                _mm512_insertf32x4::<3>(v, _mm_loadu_ps(at(3)))
            }
        }};
    }
    // No pixel's 2x2 split by the level edge: two indices per pixel (t10 = t00 + 1 texel, two
    // doubled units); else the four wrapped ones.
    let (t00, t01) = (ld!(0, 0), ld!(2, 0));
    let (t10, t11) = if INSIDE {
        (ld!(0, 2), ld!(2, 2))
    } else {
        (ld!(1, 0), ld!(3, 0))
    };
    let wx = _mm512_permutexvar_ps(widx, p.ax);
    let wy = _mm512_permutexvar_ps(widx, p.ay);
    lerp16(lerp16(t00, t10, wx), lerp16(t01, t11, wx), wy)
}

/// Each of four bits spread over four mask bits (a group's pixels over their channels).
const SPREAD4: [u16; 16] = {
    let mut r = [0u16; 16];
    let mut b = 0;
    while b < 16 {
        let mut k = 0;
        while k < 4 {
            if b & (1 << k) != 0 {
                r[b] |= 0xf << (4 * k);
            }
            k += 1;
        }
        b += 1;
    }
    r
};

/// Pixels `4G..4G + 4` of a sixteen-pixel step: level `a`, or Eq. (4)'s blend with level `b`
/// by `frac` where a pixel blends two levels; four taps per pixel and level where one of the
/// four sits on a level edge, else two.
///
/// # Safety
/// As [`tri_quad16`]; `o` must hold sixteen `Vec4`.
#[inline]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
unsafe fn tri_out16<const G: usize>(
    base: *const u8,
    pa: &TriLevel16,
    pb: &TriLevel16,
    s: &Step16<__m512>,
    widx: __m512i,
    o: *mut f32,
) {
    let single = (s.single >> (4 * G)) & 0xf;
    let edge = ((pa.edge | pb.edge) >> (4 * G)) & 0xf;
    // SAFETY: the caller's contract.
    unsafe {
        macro_rules! quad {
            ($p:expr) => {
                if edge == 0 {
                    tri_quad16::<G, true>(base, $p, widx)
                } else {
                    tri_quad16::<G, false>(base, $p, widx)
                }
            };
        }
        let ca = quad!(pa);
        let r = if single == 0xf {
            ca
        } else {
            // Seed 000 Eq. (4): blend the two levels by frac(λ); single pixels keep `ca`.
            let cb = quad!(pb);
            let r = lerp16(ca, cb, _mm512_permutexvar_ps(widx, s.frac));
            if single == 0 {
                r
            } else {
                _mm512_mask_blend_ps(SPREAD4[single as usize], r, ca)
            }
        };
        _mm512_storeu_ps(o.add(16 * G), r);
    }
}

/// [`super::lanes::trilinear_pixels`] for AVX-512 sixteen pixels per step, the whole set-up in
/// 512-bit lanes (no 256-bit µops in the loop), four pixels per zmm for the taps, lerps and
/// blend: bit-identical, whole chunks of sixteen (the caller does the tail).
///
/// # Safety
/// The CPU must support AVX-512F/VL/BW/DQ; the texture must be a power of two.
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
pub(super) unsafe fn trilinear_pixels_x16<A: Addr>(
    tex: &MipTexture,
    uv: &[Vec2],
    dx: &[Vec2],
    dy: &[Vec2],
    out: &mut [Vec4],
) -> usize {
    debug_assert!(tex.is_pow2());
    let c = Setup16::new(tex);
    let base = tex.texels().as_ptr() as *const u8;
    let n = uv.len().min(dx.len()).min(dy.len()).min(out.len()) / 16 * 16;
    // Pixel k of group G takes lane 4G + k's weights in its four channels.
    let w = perm16!(|l| l / 4);
    let four = _mm512_set1_epi32(4);
    let w1 = _mm512_add_epi32(w, four);
    let w2 = _mm512_add_epi32(w1, four);
    let w3 = _mm512_add_epi32(w2, four);
    for i in (0..n).step_by(16) {
        // SAFETY: i + 16 ≤ n ≤ every slice's length (16 Vec2 = 32 floats, 16 Vec4 = 64
        // floats); the indices come from `tri_level16` on this texture.
        unsafe {
            let s = tri_step16(&c, i, uv, dx, dy);
            let mut pa = tri_level16::<A>(&c, s.sx, s.sy, s.i0);
            let mut pb = tri_level16::<A>(&c, s.sx, s.sy, s.i1);
            // Keep the indices in memory: one load per index.
            core::hint::black_box((&mut pa.idx, &mut pb.idx));
            let o = out.as_mut_ptr().add(i) as *mut f32;
            tri_out16::<0>(base, &pa, &pb, &s, w, o);
            tri_out16::<1>(base, &pa, &pb, &s, w1, o);
            tri_out16::<2>(base, &pa, &pb, &s, w2, o);
            tri_out16::<3>(base, &pa, &pb, &s, w3, o);
        }
    }
    n
}
