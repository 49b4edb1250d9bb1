//! Texture samplers behind one enum: nearest, bilinear, trilinear (Seed 000 Eq. 4), the
//! span-parallel sampler of Seed 000 §3 (Eq. 8–10) with K x K memory banks, and an anisotropic
//! many-tap reference.
//!
//! # Coordinates and API
//! Map coordinates `uv` are in map widths (Seed 000's `r_m`): `u = 1` is one map width; texel
//! centres sit at `(x + ½)/w` (see [`crate::mip`]). Derivatives `duv_dx`, `duv_dy` are the change of
//! `uv` per pixel step to the right and per pixel step DOWN (screen y grows downward).
//!
//! - [`Sampler::sample`] — one pixel with its derivatives.
//! - [`Sampler::sample_quad`] — a 2x2 quad, pixels in the order `[(x,y), (x+1,y), (x,y+1),
//!   (x+1,y+1)]`; per-pixel samplers take the quad's coarse derivatives (`uv[1]−uv[0]`,
//!   `uv[2]−uv[0]`), the span sampler uses the four images directly (Eq. 9). All four `uv` must be
//!   given, also for pixels outside the triangle (extrapolate them from the plane, as GPUs do).
//! - [`Sampler::sample_quad_with_derivatives`] — the same with analytic per-pixel derivatives.
//! - [`Sampler::sample_pixels`], [`Sampler::sample_quads`] — many at once, the kernel chosen once
//!   outside the loop.
//!
//! Nothing here panics on bad input: NaN coordinates are treated as 0, infinite or huge ones are
//! clamped to ±2^30 texels, NaN/zero derivatives select level 0, and no NaN reaches the output
//! (the texels are finite by [`crate::mip::MipTexture`]'s guarantees).
//!
//! # Levels
//! Seed 000 Eq. (2) gives the level `l = −log2(max |∂r_m/∂(x_s, y_s)|)` with LARGER l = FINER. The
//! samplers use the usual `λ = log2(max |∂(u·w0, v·h0)/∂(x_s, y_s)|)` in level-0 texels (larger =
//! coarser, level index `i`, level 0 finest). For a square `2^n` map the two are related by
//! `λ = n − l`, pyramid index `i = n − L`, and Eq. (4)'s finer weight `γ = frac(l)` is the
//! coarser weight `1 − frac(λ)` seen from the other side: both blend the same two levels with the
//! same weights.
//!
//! # The span sampler and its bank emulator (Seed 000 §3)
//! A span is a 2x2 quad. Eq. (9) takes the span level from the extent of its four map images,
//! `λ_span = log2(max(u_max − u_min, v_max − v_min))` in level-0 texels. Each level is stored as
//! K x K banks: texel `(X, Y)` lives in bank `(X mod K, Y mod K)` at address `(X div K, Y div K)`;
//! ONE parallel read of all K² banks, at the Eq. (10) addresses
//! `a_i = ⌊X0/K⌋ + δ(i, X0)`, `δ(i, X0) = 1 if i < X0 mod K`, fetches the K x K window whose corner
//! `X0 = ⌊min_j x_j⌋` is the span's lowest texel. Each pixel then takes its own 2x2 from the window
//! and blends two levels with Eq. (4).
//!
//! **Level policy (verified):** the bilinear neighbourhood of pixel `j` is texels `⌊x_j⌋, ⌊x_j⌋+1`,
//! so a window with corner `⌊x_min⌋` holds all four neighbourhoods iff
//! `⌊x_max⌋ + 1 − ⌊x_min⌋ ≤ K − 1`. With the span extent `e = x_max − x_min` at that level,
//! `⌊x_max⌋ − ⌊x_min⌋ ≤ ⌊frac(x_min) + e⌋`, so `e < K − 2` suffices: `e < 1` for K = 3, `e < 2`
//! for K = 4 (with `K − 2 ≤ e < K − 1` the neighbourhoods can need `K + 1` columns). At level
//! `i = ⌊λ_span⌋` the extent is `2^(λ−i) ∈ [1, 2)` texels, at `i + 1` it is `< 1`. Hence:
//! - **K = 3** forces the pair `(⌊λ⌋ + 1, ⌊λ⌋ + 2)` — in the paper's convention
//!   `(⌊l⌋ − 1, ⌊l⌋)` — one level coarser than conventional trilinear: the blur the paper reports;
//! - **K = 4** allows the conventional pair `(⌊λ⌋, ⌊λ⌋ + 1)` = `(⌊l⌋, ⌊l⌋ + 1)`.
//!
//! The bound is tight: one level finer than this policy (for K = 3, the conventional pair) DOES
//! conflict, as `tests/span_banks.rs` shows with [`BankedTexture::with_level_bias`].
//! The reading of /work/shared/SEEDS.md is therefore confirmed, with details the paper does not
//! mention:
//! (1) `⌊λ⌋` is taken EXACTLY from the float exponent of the extent (no `log2` rounding), and the
//! extent is measured on the very coordinates used for addressing (after the repeat shift), so
//! rounding cannot push a span over the bound; (2) the span extent of Eq. (9) measures the
//! diagonal, `|∂u/∂x| + |∂u/∂y|`, so even K = 4 can be up to one level blurrier than per-pixel
//! trilinear with Eq. (2)'s `max`.
//!
//! Measured blur (`tests/accuracy.rs`, tilted plane, PSNR against 8x8 supersampling): trilinear
//! 29.8 dB, span K = 4 29.8 dB, span K = 3 22.9 dB with the map axes along the screen; with the
//! map turned 45°, 29.3 / 28.2 / 21.5 dB.
//!
//! **Wrap-around:** `2^n` is never a multiple of 3, so with [`Wrap::Repeat`] the window
//! `w−1, 0, 1` would put texels `w−1` and `0` in the same bank. The emulator stores each level
//! PADDED with an apron of `K − 1` texels past the right and bottom edges (wrapped texels for
//! Repeat, edge texels for Clamp); the window corner is reduced into `[0, w)` so windows never
//! wrap in bank space. With Clamp the pixel coordinates are first clamped to `[0, w − 1]` texel
//! centres (bilinear clamp-to-edge is unchanged by that). On levels narrower than `K` texels a
//! repeat-wrapped offset is folded back into the window (`offset mod w`), which is the same texel.
//! A property test (`tests/span_banks.rs`) runs the emulator over random planes, eyes and spans
//! and asserts zero conflicts.
//!
//! The fast path ([`Sampler::Span`]) reads the same K x K window from the row-major pyramid
//! instead of the banks; a test asserts it is bit-identical to the emulator ([`BankedTexture`]).
//!
//! # Performance notes (what was measured and rejected)
//! Texels are linear RGBA `f32` (`Vec4`, one SSE register): filtering is gamma-correct for free
//! and a lerp is three SIMD instructions. The level's `log2` uses the float exponent plus a
//! degree-4 mantissa polynomial (`log2_split`, |error| ≤ 1.2e-4 in λ) instead of libm's `log2f`;
//! Repeat on power-of-two levels is a mask; texel reads skip bounds checks (indices are folded by
//! construction).
//!
//! **Lane kernels** (x86_64, power-of-two pyramids; the tail of a call, NPOT pyramids and other
//! targets take the scalar path): the bulk calls run per-pixel trilinear several PIXELS per step
//! and the span sampler several SPANS per step, the footprint, level split, level sizes (from the
//! float exponent), texel coordinates, floors and fractions computed once per group of lanes.
//! - `sample/lanes.rs`: the SSE2 baseline, four lanes per step.
//! - `sample/avx2.rs`: the build chosen at run time (`is_x86_feature_detected!("avx2")`), eight
//!   lanes per step; each pixel's texel indices computed in lanes (level base from a 16-entry
//!   table with two `vpermd`, rows by `vpmulld`, doubled so that `base + 8·index` addresses a
//!   texel) and stored once, one load per index; two pixels per 256-bit register for the taps,
//!   lerps and blend, their weights by one in-lane `vpermilps` (lanes ordered so that a pixel
//!   pair shares a lane of the two halves), one 256-bit store per pair; `roundps` floors.
//! - `sample/avx512.rs`: where the CPU has AVX-512F/VL/BW/DQ, the span sampler with K = 3 reads
//!   each span's interior 3x3 window as Seed 000's mspan (each row two overlapping 256-bit
//!   loads, one zmm = four pixels x RGBA; each pixel's 2x2 picked by four `vpermt2ps` per
//!   level; the three Eq. 4 lerps and the level blend on the four pixels at once), sixteen spans per step with
//!   the set-up in 512-bit lanes (the AVX2 eight-span set-up on a group of eight left over).
//!   Per-pixel trilinear likewise, for fairness: sixteen pixels per step, the set-up in 512-bit
//!   lanes, four pixels per zmm for the taps (`lanes::TRILINEAR_AVX512`: measured faster than
//!   its AVX2 build on the Sapphire Rapids-class Xeon); K = 4 keeps the AVX2 kernel.
//!
//! Both builds are bit-identical to the scalar kernels and to the bank emulator (no FMA anywhere;
//! tests below, which fail under mutations of the weights, blend masks and indices).
//! `sample_quad` runs trilinear's four pixels in one SSE2 lane kernel, and the span through an
//! AVX2 one-span kernel (same pixel-pair taps) or, without AVX2, a fused scalar path. One call is
//! one dependency chain, so the power-of-two one-span kernel (`avx2::span_quad_pow2`) is built
//! for its length and not for lane width (see "One span per call" below).
//!
//! The comparison is kept fair: every general technique is in both kernels. The span kernel only
//! adds what Seed 000's structure gives it: one level pair, one blend weight, one window corner
//! and one row stride per span, and ONE index per pixel and level (its 2x2 lies in an interior
//! K x K window, `corner + oy·w + ox + {0, 1, w, w+1}`); trilinear needs four (wrap-around may
//! split its 2x2) except where no pixel of the eight sits on a level edge (98% of groups here),
//! where it takes two.
//!
//! Measured with callgrind (instructions per sample, `examples/sampling_prof.rs`: the bench's
//! tilted plane 1024x768 on a 4096² pyramid, one frame):
//!
//! | kernel | instructions per sample (AVX2 build) |
//! |---|---|
//! | trilinear, `sample_pixels` | 58.6 |
//! | span K3, `sample_quads` | 46.75 |
//! | span K4, `sample_quads` | 46.0 |
//! | trilinear, one `sample_quad` per quad | 155.8 |
//! | span K3, one `sample_quad` per quad | 84.0 |
//! | span K4, one `sample_quad` per quad | 83.5 |
//!
//! **One span per call.** A naive one-span path is SLOWER than trilinear's per quad (measured
//! 23–26 against ~16–17 ns per sample of thread CPU on the Intel Xeon) with fewer instructions.
//! The causes, and what the code does about them (all bit-identical): (1) a
//! store-forwarding stall: LLVM read the quad's images with a 16-byte load at bytes 4..20,
//! straddling the caller's two 16-byte stores of the quad (`perf`: ~15 % of the kernel's samples
//! on the two instructions after it); now two loads, one per half. (2) The call is one chain
//! (images -> repeat shift -> extent -> level -> coordinates -> floors -> indices -> texels -> 3
//! lerps), and nearly every instruction hangs on it, so the scheduler fills with one call and
//! the next cannot start: what counts is the chain's length and the instruction count. The
//! power-of-two kernel keeps x and y of the four pixels in one 256-bit register
//! (`[x0 y0 x2 y2 | x1 y1 x3 y3]`: extremes, coordinates, floors and fractions of both axes at
//! once, a pixel pair's weights by in-lane broadcasts), builds the level scales from the level's
//! bits in lanes (no round trip through integer registers), reduces the shifted extremes instead
//! of the shifted lanes, takes each texel index straight from the truncated coordinate (equal to
//! the floor in an interior window; no window corner on the index path) and checks the ±2^30
//! clamp beside the chain (lanes out of range take the edge path). llvm-mca (icelake-server) on
//! the hot path: old kernel 230 cycles per call alone, 180 back to back; new 163 / 119. (3) The
//! generic `sample_quad` frame (six saved registers, 0x338 bytes of stack) cost ~35
//! instructions per call: `sample_quad` is now an inlined dispatch, the span on power-of-two
//! pyramids with AVX2 tail-calls its kernel and trilinear has its own out-of-line entry (the same
//! saving for trilinear: 161.7 -> 155.8). Tried and dropped: taking the extent before the repeat
//! shift (it differs in the last bit on two spans in three on the bench's plane: lanes small next
//! to the texture width lose bits in the shift).
//!
//! Of span K3's 46.8: set-up per eight spans 18.1, per pixel 26.7 (8 texel loads, 10.5 in lerps
//! and the Eq. 4 blend, 2.9 weight permutes, 5.3 index loads, stores and branches) and 2.0 for
//! spans whose window crosses a level edge (out of line; each pixel takes four wrapped indices
//! there, as trilinear does); trilinear's 58.6: set-up 28.6, per pixel 30 (8.8 of it index
//! loads, stores and branches). So the span sampler runs 1.25x fewer instructions; its other gain is the memory organisation the paper designed it for (callgrind
//! cache simulation, per sample): 0.30 L1 read misses and 0.04 last-level misses for K3 against
//! trilinear's 0.93 and 0.27 (K4: 0.56 and 0.26, its level pair is trilinear's), which is worth
//! more as the instruction counts fall: in thread CPU time (best frame) K3 ran ~1.4x and K4
//! ~1.3x trilinear on the shared AMD machine; on the Intel Xeon ~1.4x (best
//! frame; K4 too) and 1.4–1.8x in criterion's thread CPU (load ~3, ±35 % between runs): a 1.5x
//! shows up in time only where the memory advantage weighs; in instructions it is 1.25x.
//!
//! Measured and rejected or left: LLVM turns a constant-index `vpermps` into `vshufps` +
//! `vpermpd` (two instructions per weight): the lane order `[0 2 4 6 | 1 3 5 7]` (trilinear) and
//! the `[w_2p | w_2p+1]` weight registers (span) make it one `vpermilps`. With the indices in a
//! plain array LLVM kept the vectors and extracted lanes (three instructions per index); a
//! `black_box` on the arrays keeps them in memory (span 55 -> 51, trilinear 64 -> 59). Inlining
//! the edge-window fallback into the eight unrolled spans made the kernel miss the instruction
//! cache (0.25 I1 misses per sample): it is out of line now, with its own four-index path (the
//! generic scalar path it replaced cost 4.4 instructions per sample, now 2.0). Left: a padded
//! (apron) pyramid, as the emulator has, would make every window interior; the 3x3 window's
//! shared texels (9 distinct of 16 loads per level) are not exploited: loads are the cheapest
//! part of the per-pixel work.
//!
//! Rejected by operation count (not built): keeping the K x K window in registers (the 2x2 of each
//! pixel is then picked with blends, ~9 SSE2 operations per texel against one L1 load); a weighted
//! sum over the whole 3x3 window per pixel (17 operations per level against 13). Not done, by
//! measurement: RGBA16/RGBA8 texel storage for the samplers — the same scene on a 256² pyramid
//! (L2-resident) runs only ~30% faster than on 4096² (a bound on what halving the bytes could give)
//! while the decode adds ~3 instructions per texel to an instruction-bound loop; not done.
//! Earlier: `<[_; 4]>::map` in the span loop did not inline and cost ~1.6x; copying the window
//! into a stack array gained nothing; pipelining the scalar span loop took ~17 to ~14 ns/sample.
//!
//! # References
//! Seed 000 (Kajihara), Eq. (2)–(4), (8)–(10); /work/shared/SEEDS.md.

use glam::{Vec2, Vec4, Vec4Swizzles};

use crate::mip::{LevelInfo, MipTexture, Wrap};

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
#[cfg(target_arch = "x86_64")]
mod lanes;

/// Memory banks per side for the span sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Banks {
    /// 3x3 banks (the paper's design): one level blurrier than trilinear.
    K3,
    /// 4x4 banks: the conventional trilinear level pair.
    K4,
}

impl Banks {
    /// K, the banks per side.
    #[inline]
    pub const fn k(self) -> usize {
        match self {
            Banks::K3 => 3,
            Banks::K4 => 4,
        }
    }
}

/// The samplers. A closed set: `enum` + `match`, the kernel chosen outside pixel loops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sampler {
    /// Nearest texel of level 0 (no mip mapping; aliases under minification).
    Nearest,
    /// Bilinear on level 0 (no mip mapping).
    Bilinear,
    /// Seed 000 Eq. (4): bilinear on two adjacent levels blended by the fractional level (Eq. 2).
    Trilinear,
    /// Seed 000 Eq. (8)–(10): 2x2 span, level from the span extent, K x K bank window per level.
    Span(Banks),
    /// Reference: a box filter over the pixel's parallelogram footprint (`uv ± ½duv_dx ± ½duv_dy`),
    /// `n_x x n_y` trilinear taps with `n = ⌈footprint side in texels⌉`, at most `max_taps` per
    /// side (clamped to 1..=64).
    Anisotropic { max_taps: u32 },
}

/// Largest texel coordinate magnitude: keeps `f32 -> i32` conversions and `+1` in range.
const COORD_LIMIT: f32 = (1u32 << 30) as f32;

// ---------------------------------------------------------------------------------------------
// Addressing kernels (wrap modes), chosen once per call.

trait Addr {
    const REPEAT: bool;
    /// Fold an integer texel address into `0..n`.
    fn wrap(i: i32, n: i32) -> i32;
}

/// Repeat on a power-of-two level: a mask.
struct RepeatPow2;
/// Repeat on any size: Euclidean remainder.
struct RepeatAny;
/// Clamp to edge.
struct ClampEdge;

impl Addr for RepeatPow2 {
    const REPEAT: bool = true;
    #[inline(always)]
    fn wrap(i: i32, n: i32) -> i32 {
        i & (n - 1)
    }
}
impl Addr for RepeatAny {
    const REPEAT: bool = true;
    #[inline(always)]
    fn wrap(i: i32, n: i32) -> i32 {
        i.rem_euclid(n)
    }
}
impl Addr for ClampEdge {
    const REPEAT: bool = false;
    #[inline(always)]
    fn wrap(i: i32, n: i32) -> i32 {
        i.max(0).min(n - 1)
    }
}

/// Clamp a texel coordinate to ±2^30; NaN becomes −2^30 (then the weights stay finite).
#[inline(always)]
fn clampc(x: f32) -> f32 {
    // Plain comparisons (a NaN fails the first and becomes −2^30): cheaper than f32::max/min.
    let x = if x >= -COORD_LIMIT { x } else { -COORD_LIMIT };
    if x <= COORD_LIMIT { x } else { COORD_LIMIT }
}

/// `log2 x` split into its integer part `⌊log2 x⌋` (exact, from the exponent) and an approximate
/// fraction in `[0, 1]`: a degree-4 polynomial in the mantissa `t = x/2^e − 1` with `p(0) = 0`,
/// `p(1) = 1` (continuous across octaves), fitted to `log2(1 + t)` with max error 1.2e-4 (tested).
/// For positive normal `x` only; the callers route 0, NaN and subnormals elsewhere.
#[inline(always)]
fn log2_split(x: f32) -> (i32, f32) {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    let t = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000) - 1.0;
    (
        e,
        t * (LOG2_C1 + t * (LOG2_C2 + t * (LOG2_C3 + t * LOG2_C4))),
    )
}

/// [`log2_split`]'s mantissa polynomial (shared with the lane kernels).
const LOG2_C1: f32 = 1.438_725_7;
const LOG2_C2: f32 = -0.677_783_9;
const LOG2_C3: f32 = 0.321_188_76;
const LOG2_C4: f32 = 1.0 - LOG2_C1 - LOG2_C2 - LOG2_C3;

/// ⌊x⌋ for |x| ≤ 2^30 (finite): truncate, then step down for negative fractions.
#[inline(always)]
fn floor_i32(x: f32) -> i32 {
    debug_assert!(x.is_finite() && x.abs() <= COORD_LIMIT);
    // SAFETY: callers pass finite values clamped to ±2^30, which fit in i32.
    let t: i32 = unsafe { x.to_int_unchecked() };
    t - ((t as f32 > x) as i32)
}

#[inline(always)]
fn lerp(a: Vec4, b: Vec4, t: f32) -> Vec4 {
    a + (b - a) * t
}

#[inline(always)]
fn texel(texels: &[Vec4], i: usize) -> Vec4 {
    debug_assert!(i < texels.len());
    // SAFETY: every index is `offset + y*w + x` with x, y folded into the level by `Addr::wrap`
    // and the level inside the buffer (MipTexture guarantees).
    unsafe { *texels.get_unchecked(i) }
}

/// Nearest texel of level 0.
#[inline(always)]
fn nearest<A: Addr>(texels: &[Vec4], l: &LevelInfo, uv: Vec2) -> Vec4 {
    let (w, h) = (l.width as i32, l.height as i32);
    let x = A::wrap(floor_i32(clampc(uv.x * l.width_f)), w);
    let y = A::wrap(floor_i32(clampc(uv.y * l.height_f)), h);
    texel(texels, l.offset + (y * w + x) as usize)
}

/// Seed 000 Eq. (4), one level: bilinear of the four texels around `2^L r_m − ½` with weights
/// `(α, β) = frac(2^L r_m − ½)`, texel addresses per Eq. (3).
#[inline(always)]
fn bilinear<A: Addr>(texels: &[Vec4], l: &LevelInfo, uv: Vec2) -> Vec4 {
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
fn footprint(l0: &LevelInfo, duv_dx: Vec2, duv_dy: Vec2) -> f32 {
    let s = Vec2::new(l0.width_f, l0.height_f);
    (duv_dx * s).abs().max((duv_dy * s).abs()).max_element()
}

/// λ (larger = coarser) of a footprint; NaN or zero give −∞ (level 0). Exact `log2`, for the
/// reference sampler.
#[inline(always)]
fn lambda(l0: &LevelInfo, duv_dx: Vec2, duv_dy: Vec2) -> f32 {
    let m = footprint(l0, duv_dx, duv_dy);
    if m > 0.0 { m.log2() } else { f32::NEG_INFINITY }
}

/// Seed 000 Eq. (4): blend the bilinear samples of levels ⌊λ⌋ and ⌊λ⌋+1 by frac(λ), clamped to the
/// pyramid; `m` is the footprint in level-0 texels (λ = log2 m, split by [`log2_split`]).
#[inline(always)]
// `!(a > b)` on purpose: NaN must take the fallback branch.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn trilinear_fp<A: Addr>(tex: &MipTexture, uv: Vec2, m: f32) -> Vec4 {
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
fn trilinear<A: Addr>(tex: &MipTexture, uv: Vec2, lam: f32) -> Vec4 {
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
fn anisotropic<A: Addr>(
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

// ---------------------------------------------------------------------------------------------
// Span sampler (Seed 000 §3).

/// Where a span's K x K windows come from: the row-major pyramid (fast path) or the bank
/// emulator (counts reads and conflicts). The per-pixel arithmetic is shared, so both give the
/// same bits.
trait WindowSource {
    /// A fetched window.
    type Win;
    /// The window whose corner is texel `(x0, y0)` of `level` (any integers; wrapped).
    fn window<A: Addr, const K: usize>(
        &mut self,
        tex: &MipTexture,
        level: usize,
        x0: i32,
        y0: i32,
    ) -> Self::Win;
    /// Texels `(ox, oy), (ox+1, oy), (ox, oy+1), (ox+1, oy+1)` of a fetched window
    /// (offsets from its corner, `ox, oy ≤ K − 2`).
    fn quad(tex: &MipTexture, win: &Self::Win, ox: usize, oy: usize) -> [Vec4; 4];
    /// A texel access fell outside the window.
    fn conflict(&mut self);
}

/// Fast path: a window inside the level is just its corner index in the row-major level (pixels
/// read `corner + oy·w + ox`, no wrap); a window crossing an edge keeps K wrapped column indices
/// and K wrapped row starts. Either way no texel is copied.
struct Direct;

/// A window of the fast path.
struct DirectWin {
    /// Index of the corner texel when the window lies inside the level, else `usize::MAX`.
    corner: usize,
    width: usize,
    cols: [usize; 4],
    rows: [usize; 4],
}

impl WindowSource for Direct {
    type Win = DirectWin;
    #[inline(always)]
    fn window<A: Addr, const K: usize>(
        &mut self,
        tex: &MipTexture,
        level: usize,
        x0: i32,
        y0: i32,
    ) -> DirectWin {
        let l = &tex.levels()[level];
        let (w, h) = (l.width as i32, l.height as i32);
        let k = K as i32;
        if x0 >= 0 && y0 >= 0 && x0 + k <= w && y0 + k <= h {
            return DirectWin {
                corner: l.offset + (y0 * w + x0) as usize,
                width: w as usize,
                cols: [0; 4],
                rows: [0; 4],
            };
        }
        let mut cols = [0usize; 4];
        let mut rows = [l.offset; 4];
        for o in 0..K {
            cols[o] = A::wrap(x0 + o as i32, w) as usize;
            rows[o] = l.offset + (A::wrap(y0 + o as i32, h) * w) as usize;
        }
        DirectWin {
            corner: usize::MAX,
            width: w as usize,
            cols,
            rows,
        }
    }
    #[inline(always)]
    fn quad(tex: &MipTexture, win: &DirectWin, ox: usize, oy: usize) -> [Vec4; 4] {
        let t = tex.texels();
        if win.corner != usize::MAX {
            let i = win.corner + oy * win.width + ox;
            [
                texel(t, i),
                texel(t, i + 1),
                texel(t, i + win.width),
                texel(t, i + win.width + 1),
            ]
        } else {
            let (c0, c1) = (win.cols[ox & 3], win.cols[(ox + 1) & 3]);
            let (r0, r1) = (win.rows[oy & 3], win.rows[(oy + 1) & 3]);
            [
                texel(t, r0 + c0),
                texel(t, r0 + c1),
                texel(t, r1 + c0),
                texel(t, r1 + c1),
            ]
        }
    }
    #[inline(always)]
    fn conflict(&mut self) {}
}

/// `⌊v⌋` per lane for finite lanes with `|v| ≤ 2^30`: truncate, then step down where truncation
/// rounded up. SSE2 (baseline on x86_64) converts four lanes at once; other targets use the
/// scalar [`floor_i32`]. Both give the same values.
#[inline(always)]
fn floor4(v: Vec4) -> Vec4 {
    let tf = trunc_lanes(v);
    Vec4::select(tf.cmpgt(v), tf - Vec4::ONE, tf)
}

/// Lanes truncated toward zero (finite, `|v| ≤ 2^30`), as floats.
#[inline(always)]
fn trunc_lanes(v: Vec4) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{__m128, _mm_cvtepi32_ps, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            let m: __m128 = v.into();
            Vec4::from(_mm_cvtepi32_ps(_mm_cvttps_epi32(m)))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec4::from(v.to_array().map(|x| floor_i32(x.abs()) as f32 * x.signum()))
    }
}

/// Integer-valued lanes (`|v| ≤ 2^30`) as `i32`.
#[inline(always)]
fn lanes_i32(v: Vec4) -> [i32; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{__m128, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of the x86_64 baseline; __m128i and [i32; 4] have the same size
        // and no invalid bit patterns.
        unsafe {
            let m: __m128 = v.into();
            core::mem::transmute::<_, [i32; 4]>(_mm_cvttps_epi32(m))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        v.to_array().map(floor_i32)
    }
}

#[inline(always)]
fn lerp4(a: Vec4, b: Vec4, t: Vec4) -> Vec4 {
    a + (b - a) * t
}

/// Replace NaN lanes by 0 and clamp to ±2^30.
#[inline(always)]
fn clamp4(v: Vec4) -> Vec4 {
    Vec4::select(v.cmpeq(v), v, Vec4::ZERO)
        .max(Vec4::splat(-COORD_LIMIT))
        .min(Vec4::splat(COORD_LIMIT))
}

/// A span's level decision (Seed 000 Eq. 9) and its lane coordinates.
#[derive(Clone, Copy)]
struct SpanPlan {
    sx: Vec4,
    sy: Vec4,
    i0: usize,
    i1: usize,
    t: f32,
}

/// First half of a span: Eq. (8)'s four pixel images `uv` as lanes, Eq. (9)'s level pair.
#[inline(always)]
fn span_plan<A: Addr, const K: usize>(tex: &MipTexture, uv: [Vec2; 4], bias: i32) -> SpanPlan {
    let u = Vec4::new(uv[0].x, uv[1].x, uv[2].x, uv[3].x);
    let v = Vec4::new(uv[0].y, uv[1].y, uv[2].y, uv[3].y);
    span_plan_lanes::<A, K>(tex, u, v, bias)
}

/// [`span_plan`] on the images already in lanes (`u`, `v`: pixel `j` in lane `j`).
#[inline(always)]
fn span_plan_lanes<A: Addr, const K: usize>(
    tex: &MipTexture,
    u: Vec4,
    v: Vec4,
    bias: i32,
) -> SpanPlan {
    let levels = tex.levels();
    let l0 = &levels[0];
    let last = levels.len() - 1;
    // Level-0 texel coordinates (no half-texel offset yet), one lane per pixel; NaN -> 0.
    let mut sx = clamp4(u * l0.width_f);
    let mut sy = clamp4(v * l0.height_f);
    // Repeat: shift the whole span by whole periods so its corner lies in the first period.
    if A::REPEAT {
        let px = floor_i32(sx.min_element() * l0.inv_width_f) as f32 * l0.width_f;
        let py = floor_i32(sy.min_element() * l0.inv_height_f) as f32 * l0.height_f;
        sx -= Vec4::splat(px);
        sy -= Vec4::splat(py);
    }
    // Seed 000 Eq. (9): span level from the extent of the four images (level-0 texels).
    let ext = (sx.max_element() - sx.min_element()).max(sy.max_element() - sy.min_element());
    let (i0, i1, t) = span_levels::<K>(ext, last, bias);
    SpanPlan { sx, sy, i0, i1, t }
}

/// Eq. (9)'s level pair `(i0, i1)` and blend weight of a span whose images span `ext` level-0
/// texels, clamped to the pyramid (`last`: its top level); K = 3 takes the pair one level
/// coarser (the module doc's level policy).
#[inline(always)]
fn span_levels<const K: usize>(ext: f32, last: usize, bias: i32) -> (usize, usize, f32) {
    let shift = if K == 3 { 1 } else { 0 };
    // Exact ⌊λ⌋ from the exponent (0 and subnormals give −127), frac(λ) from the mantissa.
    let (e, frac) = log2_split(ext);
    let fine = e + shift + bias;
    if fine < 0 {
        (0, 0, 0.0)
    } else if fine as usize >= last {
        (last, last, 0.0)
    } else {
        (fine as usize, fine as usize + 1, frac)
    }
}

/// Second half of a span: Eq. (10)'s window per level and Eq. (4)'s per-pixel blend.
#[inline(always)]
fn span_finish<A: Addr, S: WindowSource, const K: usize>(
    tex: &MipTexture,
    p: SpanPlan,
    src: &mut S,
) -> [Vec4; 4] {
    let a = span_level::<A, S, K>(tex, p.i0, p.sx, p.sy, src);
    if p.i1 == p.i0 || p.t == 0.0 {
        return a;
    }
    let b = span_level::<A, S, K>(tex, p.i1, p.sx, p.sy, src);
    let mut out = a;
    for j in 0..4 {
        out[j] = lerp(a[j], b[j], p.t);
    }
    out
}

/// One span (Seed 000 §3): [`span_plan`] then [`span_finish`].
#[inline(always)]
fn span_quad<A: Addr, S: WindowSource, const K: usize>(
    tex: &MipTexture,
    uv: [Vec2; 4],
    bias: i32,
    src: &mut S,
) -> [Vec4; 4] {
    span_finish::<A, S, K>(tex, span_plan::<A, K>(tex, uv, bias), src)
}

/// Many spans, software-pipelined: the level decision of span `n + 1` is issued before the texel
/// work of span `n`, so the two dependency chains overlap (one span alone is latency-bound).
#[inline(always)]
fn span_quads<A: Addr, const K: usize>(
    tex: &MipTexture,
    quads: &[[Vec2; 4]],
    out: &mut [[Vec4; 4]],
) {
    let n = quads.len().min(out.len());
    if n == 0 {
        return;
    }
    let mut next = span_plan::<A, K>(tex, quads[0], 0);
    for i in 0..n {
        let cur = next;
        if i + 1 < n {
            next = span_plan::<A, K>(tex, quads[i + 1], 0);
        }
        out[i] = span_finish_direct::<A, K>(tex, cur);
    }
}

/// One level of a span on the fast path, set up for [`span_finish_direct`]: when every pixel's
/// bilinear neighbourhood lies in a K x K window inside the level (the common case), the window
/// corner's index and each pixel's offset from it (`oy·w + ox`), else `None`.
struct DirectLevel {
    corner: usize,
    width: usize,
    idx: [i32; 4],
    ax: Vec4,
    ay: Vec4,
}

/// Seed 000 Eq. (10) for the fast path: the level's texel coordinates, floors and weights
/// exactly as [`span_level`] computes them, and the interior window if there is one.
#[inline(always)]
fn direct_level<A: Addr, const K: usize>(
    tex: &MipTexture,
    level: usize,
    sx: Vec4,
    sy: Vec4,
) -> Option<DirectLevel> {
    let l = &tex.levels()[level];
    let mut x = sx * l.scale_x - Vec4::splat(0.5);
    let mut y = sy * l.scale_y - Vec4::splat(0.5);
    if !A::REPEAT {
        x = x.max(Vec4::ZERO).min(Vec4::splat(l.width_f - 1.0));
        y = y.max(Vec4::ZERO).min(Vec4::splat(l.height_f - 1.0));
    }
    let (flx, fly) = (floor4(x), floor4(y));
    let (mx, my) = (flx.min_element(), fly.min_element());
    let (ox, oy) = (flx - Vec4::splat(mx), fly - Vec4::splat(my));
    let lim = Vec4::splat((K - 2) as f32);
    // SAFETY: mx, my are floors of lanes clamped to ±2^30: integer-valued and within i32.
    let (x0, y0): (i32, i32) = unsafe { (mx.to_int_unchecked(), my.to_int_unchecked()) };
    let (w, h) = (l.width as i32, l.height as i32);
    let k = K as i32;
    if (ox.cmpgt(lim) | oy.cmpgt(lim)).any() || x0 < 0 || y0 < 0 || x0 + k > w || y0 + k > h {
        return None;
    }
    Some(DirectLevel {
        corner: l.offset + (y0 * w + x0) as usize,
        width: w as usize,
        // oy·w + ox: small non-negative integers, exact in f32 (w ≤ 2^14, oy ≤ 2).
        idx: lanes_i32(oy * Vec4::splat(l.width_f) + ox),
        ax: x - flx,
        ay: y - fly,
    })
}

/// Bilinear of pixel `j` from an interior window (Eq. 4 weights, the arithmetic of
/// [`span_level`]).
#[inline(always)]
fn direct_pixel(t: &[Vec4], d: &DirectLevel, ax: Vec4, ay: Vec4, j: usize) -> Vec4 {
    let i = d.corner + d.idx[j] as usize;
    let t00 = texel(t, i);
    let t10 = texel(t, i + 1);
    let t01 = texel(t, i + d.width);
    let t11 = texel(t, i + d.width + 1);
    lerp4(lerp4(t00, t10, ax), lerp4(t01, t11, ax), ay)
}

/// [`span_finish`] for the fast path with both levels fused per pixel: when both windows are
/// interior, each pixel reads its 2x2 on each level and blends, results staying in registers.
/// Bit-identical to [`span_finish`] (same operations in the same order); other spans take it.
#[inline(always)]
fn span_finish_direct<A: Addr, const K: usize>(tex: &MipTexture, p: SpanPlan) -> [Vec4; 4] {
    let t = tex.texels();
    let Some(a) = direct_level::<A, K>(tex, p.i0, p.sx, p.sy) else {
        return span_finish::<A, Direct, K>(tex, p, &mut Direct);
    };
    let axs = [a.ax.xxxx(), a.ax.yyyy(), a.ax.zzzz(), a.ax.wwww()];
    let ays = [a.ay.xxxx(), a.ay.yyyy(), a.ay.zzzz(), a.ay.wwww()];
    let mut out = [Vec4::ZERO; 4];
    if p.i1 == p.i0 || p.t == 0.0 {
        for j in 0..4 {
            out[j] = direct_pixel(t, &a, axs[j], ays[j], j);
        }
        return out;
    }
    let Some(b) = direct_level::<A, K>(tex, p.i1, p.sx, p.sy) else {
        return span_finish::<A, Direct, K>(tex, p, &mut Direct);
    };
    let bxs = [b.ax.xxxx(), b.ax.yyyy(), b.ax.zzzz(), b.ax.wwww()];
    let bys = [b.ay.xxxx(), b.ay.yyyy(), b.ay.zzzz(), b.ay.wwww()];
    let tt = Vec4::splat(p.t);
    for j in 0..4 {
        let ca = direct_pixel(t, &a, axs[j], ays[j], j);
        let cb = direct_pixel(t, &b, bxs[j], bys[j], j);
        out[j] = lerp4(ca, cb, tt);
    }
    out
}

/// The four bilinear samples of one level from ONE window read.
#[inline(always)]
fn span_level<A: Addr, S: WindowSource, const K: usize>(
    tex: &MipTexture,
    level: usize,
    sx: Vec4,
    sy: Vec4,
    src: &mut S,
) -> [Vec4; 4] {
    let l = &tex.levels()[level];
    // This level's texel coordinates, texel centres at integers (Eq. 3 applied to 2^L r_m − ½).
    let mut x = sx * l.scale_x - Vec4::splat(0.5);
    let mut y = sy * l.scale_y - Vec4::splat(0.5);
    if !A::REPEAT {
        // Clamp-to-edge bilinear equals bilinear at the clamped coordinate.
        x = x.max(Vec4::ZERO).min(Vec4::splat(l.width_f - 1.0));
        y = y.max(Vec4::ZERO).min(Vec4::splat(l.height_f - 1.0));
    }
    let (flx, fly) = (floor4(x), floor4(y));
    let (ax, ay) = (x - flx, y - fly);
    let (mx, my) = (flx.min_element(), fly.min_element());
    // SAFETY: mx, my are floors of lanes clamped to ±2^30: integer-valued and within i32, so
    // truncation is exact.
    let (x0, y0): (i32, i32) = unsafe { (mx.to_int_unchecked(), my.to_int_unchecked()) };
    // Offsets of each pixel's texel from the window corner (small integers, exact in f32).
    let (ox, oy) = (flx - Vec4::splat(mx), fly - Vec4::splat(my));
    // Seed 000 Eq. (10): one parallel read of the K x K window at corner (x0, y0).
    let win = src.window::<A, K>(tex, level, x0, y0);
    let lim = (K - 2) as f32;
    let (oxi, oyi) = (lanes_i32(ox), lanes_i32(oy));
    if ox.max_element() <= lim && oy.max_element() <= lim {
        // Every bilinear neighbourhood lies in the window (the level policy's guarantee).
        let axs = [ax.xxxx(), ax.yyyy(), ax.zzzz(), ax.wwww()];
        let ays = [ay.xxxx(), ay.yyyy(), ay.zzzz(), ay.wwww()];
        // (A plain loop: `<[_; 4]>::map` does not inline here and cost 2x.)
        let mut out = [Vec4::ZERO; 4];
        for j in 0..4 {
            let [t00, t10, t01, t11] = S::quad(tex, &win, oxi[j] as usize, oyi[j] as usize);
            out[j] = lerp4(lerp4(t00, t10, axs[j]), lerp4(t01, t11, axs[j]), ays[j]);
        }
        return out;
    }
    let lim = K as i32 - 2;
    let mut out = [Vec4::ZERO; 4];
    for j in 0..4 {
        let (mut ox, mut oy) = (oxi[j], oyi[j]);
        if ox > lim || oy > lim {
            // Fold repeat-wrapped offsets on narrow levels back into the window (same texel).
            if A::REPEAT {
                if ox > lim {
                    ox = ox.rem_euclid(l.width as i32);
                }
                if oy > lim {
                    oy = oy.rem_euclid(l.height as i32);
                }
            }
            if ox > lim || oy > lim {
                // A bank conflict: the policy makes this unreachable; serve it from memory.
                src.conflict();
                out[j] = bilinear::<A>(
                    tex.texels(),
                    l,
                    Vec2::new((x[j] + 0.5) / l.width_f, (y[j] + 0.5) / l.height_f),
                );
                continue;
            }
        }
        let [t00, t10, t01, t11] = S::quad(tex, &win, ox as usize, oy as usize);
        let (axj, ayj) = (Vec4::splat(ax[j]), Vec4::splat(ay[j]));
        out[j] = lerp4(lerp4(t00, t10, axj), lerp4(t01, t11, axj), ayj);
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Public API.

/// Call `$body` with `$A` bound to the texture's addressing kernel.
macro_rules! with_addr {
    ($tex:expr, $A:ident, $body:expr) => {
        match ($tex.wrap(), $tex.is_pow2()) {
            (Wrap::Repeat, true) => {
                type $A = RepeatPow2;
                $body
            }
            (Wrap::Repeat, false) => {
                type $A = RepeatAny;
                $body
            }
            (Wrap::Clamp, _) => {
                type $A = ClampEdge;
                $body
            }
        }
    };
}

/// Why a bulk sampling call was refused.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SampleError {
    /// Input and output slices differ in length.
    LengthMismatch { expected: usize, actual: usize },
}

impl std::fmt::Display for SampleError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SampleError::LengthMismatch { expected, actual } => {
                write!(f, "slice holds {actual} elements, expected {expected}")
            }
        }
    }
}

impl std::error::Error for SampleError {}

/// `Sampler::Span(banks).sample_quad` on a power-of-two pyramid when the CPU has AVX2 (checked
/// by the caller): the addressing kernel and K chosen, then the one-span kernel, out of line.
#[cfg(target_arch = "x86_64")]
#[inline(never)]
fn span_quad_pow2_avx2(tex: &MipTexture, banks: Banks, uv: [Vec2; 4]) -> [Vec4; 4] {
    debug_assert!(tex.is_pow2() && lanes::has_avx2());
    // SAFETY: AVX2 and a power-of-two pyramid, as the caller checked.
    unsafe {
        match (tex.wrap(), banks) {
            (Wrap::Repeat, Banks::K3) => avx2::span_quad_pow2::<RepeatPow2, 3>(tex, uv),
            (Wrap::Repeat, Banks::K4) => avx2::span_quad_pow2::<RepeatPow2, 4>(tex, uv),
            (Wrap::Clamp, Banks::K3) => avx2::span_quad_pow2::<ClampEdge, 3>(tex, uv),
            (Wrap::Clamp, Banks::K4) => avx2::span_quad_pow2::<ClampEdge, 4>(tex, uv),
        }
    }
}

/// `Sampler::Trilinear.sample_quad` out of line (the sampler already tested by the caller).
#[inline(never)]
fn trilinear_quad_entry(tex: &MipTexture, uv: [Vec2; 4]) -> [Vec4; 4] {
    with_addr!(tex, A, Sampler::Trilinear.quad_one::<A>(tex, uv))
}

/// The quad's span images for a single pixel: the pixel is the top-left of its own span (Eq. 8
/// with the span centre at `uv + ½duv_dx + ½duv_dy`).
#[inline(always)]
fn quad_from_pixel(uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> [Vec2; 4] {
    [uv, uv + duv_dx, uv + duv_dy, uv + duv_dx + duv_dy]
}

impl Sampler {
    /// One pixel: `uv` in map widths and its screen derivatives. The span sampler treats the pixel
    /// as the top-left of a span whose other pixels follow the derivatives (Eq. 8).
    pub fn sample(&self, tex: &MipTexture, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Vec4 {
        with_addr!(tex, A, self.sample_one::<A>(tex, uv, duv_dx, duv_dy))
    }

    #[inline(always)]
    fn sample_one<A: Addr>(&self, tex: &MipTexture, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Vec4 {
        let l0 = &tex.levels()[0];
        match *self {
            Sampler::Nearest => nearest::<A>(tex.texels(), l0, uv),
            Sampler::Bilinear => bilinear::<A>(tex.texels(), l0, uv),
            Sampler::Trilinear => trilinear_fp::<A>(tex, uv, footprint(l0, duv_dx, duv_dy)),
            Sampler::Span(Banks::K3) => {
                span_quad::<A, Direct, 3>(tex, quad_from_pixel(uv, duv_dx, duv_dy), 0, &mut Direct)
                    [0]
            }
            Sampler::Span(Banks::K4) => {
                span_quad::<A, Direct, 4>(tex, quad_from_pixel(uv, duv_dx, duv_dy), 0, &mut Direct)
                    [0]
            }
            Sampler::Anisotropic { max_taps } => {
                anisotropic::<A>(tex, uv, duv_dx, duv_dy, max_taps)
            }
        }
    }

    /// A 2x2 quad `[(x,y), (x+1,y), (x,y+1), (x+1,y+1)]`. Per-pixel samplers use the quad's coarse
    /// derivatives `uv[1] − uv[0]` and `uv[2] − uv[0]`; the span sampler uses Eq. (9).
    #[inline]
    pub fn sample_quad(&self, tex: &MipTexture, uv: [Vec2; 4]) -> [Vec4; 4] {
        // Inlined into the caller, where the sampler is usually loop-invariant: the span on a
        // power-of-two pyramid with AVX2 goes straight to its kernel, without the frame of
        // `sample_quad_any` (six saved registers and 0x338 bytes of stack for the inlined
        // trilinear lanes: ~35 instructions of a one-span call).
        // Trilinear has its own out-of-line entry so that it tests the sampler once, as before.
        match *self {
            #[cfg(target_arch = "x86_64")]
            Sampler::Span(banks) if tex.is_pow2() && lanes::has_avx2() => {
                span_quad_pow2_avx2(tex, banks, uv)
            }
            Sampler::Trilinear => trilinear_quad_entry(tex, uv),
            s => s.sample_quad_any(tex, uv),
        }
    }

    /// [`Sampler::sample_quad`] for every sampler (out of line).
    #[inline(never)]
    fn sample_quad_any(self, tex: &MipTexture, uv: [Vec2; 4]) -> [Vec4; 4] {
        with_addr!(tex, A, self.quad_one::<A>(tex, uv))
    }

    #[inline(always)]
    fn quad_one<A: Addr>(&self, tex: &MipTexture, uv: [Vec2; 4]) -> [Vec4; 4] {
        match *self {
            // One span per call: the AVX2 kernel where the CPU has it (same bits).
            #[cfg(target_arch = "x86_64")]
            Sampler::Span(banks) if lanes::has_avx2() => match (tex.is_pow2(), banks) {
                // SAFETY: AVX2 was detected just above; the pow2 kernels check nothing else.
                (true, Banks::K3) => unsafe { avx2::span_quad_pow2::<A, 3>(tex, uv) },
                (true, Banks::K4) => unsafe { avx2::span_quad_pow2::<A, 4>(tex, uv) },
                (false, Banks::K3) => unsafe { avx2::span_quad::<A, 3>(tex, uv) },
                (false, Banks::K4) => unsafe { avx2::span_quad::<A, 4>(tex, uv) },
            },
            Sampler::Span(Banks::K3) => {
                span_finish_direct::<A, 3>(tex, span_plan::<A, 3>(tex, uv, 0))
            }
            Sampler::Span(Banks::K4) => {
                span_finish_direct::<A, 4>(tex, span_plan::<A, 4>(tex, uv, 0))
            }
            #[cfg(target_arch = "x86_64")]
            Sampler::Trilinear if tex.is_pow2() => {
                // The quad's four pixels in the lanes of one trilinear kernel (same bits).
                let m = footprint(&tex.levels()[0], uv[1] - uv[0], uv[2] - uv[0]);
                let u = Vec4::new(uv[0].x, uv[1].x, uv[2].x, uv[3].x);
                let v = Vec4::new(uv[0].y, uv[1].y, uv[2].y, uv[3].y);
                // NaN footprint -> 0, as the lane kernel expects (both mean level 0).
                let m = if m > 0.0 { m } else { 0.0 };
                lanes::trilinear4::<A>(tex, u, v, Vec4::splat(m))
            }
            _ => {
                let dx = uv[1] - uv[0];
                let dy = uv[2] - uv[0];
                let mut out = [Vec4::ZERO; 4];
                for j in 0..4 {
                    out[j] = self.sample_one::<A>(tex, uv[j], dx, dy);
                }
                out
            }
        }
    }

    /// A 2x2 quad with analytic per-pixel derivatives (e.g. from [`crate::transform`]). The span
    /// sampler ignores the derivatives (its level is Eq. 9's).
    pub fn sample_quad_with_derivatives(
        &self,
        tex: &MipTexture,
        uv: [Vec2; 4],
        duv_dx: [Vec2; 4],
        duv_dy: [Vec2; 4],
    ) -> [Vec4; 4] {
        with_addr!(tex, A, {
            match *self {
                Sampler::Span(_) => self.quad_one::<A>(tex, uv),
                _ => {
                    let mut out = [Vec4::ZERO; 4];
                    for j in 0..4 {
                        out[j] = self.sample_one::<A>(tex, uv[j], duv_dx[j], duv_dy[j]);
                    }
                    out
                }
            }
        })
    }

    /// Many pixels: `out[i] = sample(uv[i], duv_dx[i], duv_dy[i])`, the kernel chosen once.
    pub fn sample_pixels(
        &self,
        tex: &MipTexture,
        uv: &[Vec2],
        duv_dx: &[Vec2],
        duv_dy: &[Vec2],
        out: &mut [Vec4],
    ) -> Result<(), SampleError> {
        let n = uv.len();
        for len in [duv_dx.len(), duv_dy.len(), out.len()] {
            if len != n {
                return Err(SampleError::LengthMismatch {
                    expected: n,
                    actual: len,
                });
            }
        }
        macro_rules! run {
            ($A:ty, $f:expr) => {
                for i in 0..n {
                    out[i] = $f(uv[i], duv_dx[i], duv_dy[i]);
                }
            };
        }
        with_addr!(tex, A, {
            let texels = tex.texels();
            let l0 = &tex.levels()[0];
            match *self {
                Sampler::Nearest => run!(A, |p, _, _| nearest::<A>(texels, l0, p)),
                Sampler::Bilinear => run!(A, |p, _, _| bilinear::<A>(texels, l0, p)),
                Sampler::Trilinear => {
                    // Four pixels per step in lanes (power-of-two pyramids), then the tail.
                    #[cfg(target_arch = "x86_64")]
                    let done = if tex.is_pow2() {
                        lanes::trilinear_pixels_best::<A>(tex, uv, duv_dx, duv_dy, out)
                    } else {
                        0
                    };
                    #[cfg(not(target_arch = "x86_64"))]
                    let done = 0;
                    for i in done..n {
                        out[i] = trilinear_fp::<A>(tex, uv[i], footprint(l0, duv_dx[i], duv_dy[i]));
                    }
                }
                s => run!(A, |p, dx, dy| s.sample_one::<A>(tex, p, dx, dy)),
            }
        });
        Ok(())
    }

    /// Many quads: `out[i] = sample_quad(quads[i])`, the kernel chosen once.
    pub fn sample_quads(
        &self,
        tex: &MipTexture,
        quads: &[[Vec2; 4]],
        out: &mut [[Vec4; 4]],
    ) -> Result<(), SampleError> {
        if quads.len() != out.len() {
            return Err(SampleError::LengthMismatch {
                expected: quads.len(),
                actual: out.len(),
            });
        }
        with_addr!(tex, A, {
            match *self {
                Sampler::Span(banks) => {
                    // Four spans per step in lanes (power-of-two pyramids), then the tail.
                    #[cfg(target_arch = "x86_64")]
                    let done = match (tex.is_pow2(), banks) {
                        (true, Banks::K3) => lanes::span_quads4_best::<A, 3>(tex, quads, out),
                        (true, Banks::K4) => lanes::span_quads4_best::<A, 4>(tex, quads, out),
                        (false, _) => 0,
                    };
                    #[cfg(not(target_arch = "x86_64"))]
                    let done = 0;
                    let (q, o) = (&quads[done..], &mut out[done..]);
                    match banks {
                        Banks::K3 => span_quads::<A, 3>(tex, q, o),
                        Banks::K4 => span_quads::<A, 4>(tex, q, o),
                    }
                }
                s => {
                    for (o, q) in out.iter_mut().zip(quads) {
                        *o = s.quad_one::<A>(tex, *q);
                    }
                }
            }
        });
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// Bank emulator.

/// Counters of the bank emulator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BankStats {
    /// Spans sampled.
    pub spans: u64,
    /// Parallel window reads (one per level per span).
    pub window_reads: u64,
    /// Individual bank reads (K² per window read; each bank read once per window).
    pub bank_reads: u64,
    /// Texel accesses that fell outside the fetched window (would need another memory cycle).
    pub conflicts: u64,
    /// Window reads that crossed the right or bottom edge of their level (served by the apron).
    pub edge_windows: u64,
}

/// One level stored as K x K banks of the padded level (apron of K − 1 texels, see module doc).
#[derive(Clone, Debug)]
struct BankedLevel {
    /// Addresses per bank row (bank width).
    bank_w: usize,
    /// `banks[j * K + i]` holds texels with `X mod K = i`, `Y mod K = j`.
    banks: Vec<Vec<Vec4>>,
}

/// A [`MipTexture`] re-laid out as K x K memory banks per level (Seed 000 Eq. 10), for emulating
/// the span sampler's parallel reads and counting bank conflicts. Slow by design: it is the
/// model the fast path is checked against, not a renderer.
#[derive(Clone, Debug)]
pub struct BankedTexture {
    banks: Banks,
    levels: Vec<BankedLevel>,
    bias: i32,
}

impl BankedTexture {
    /// Split every level of `tex` into `banks.k()`² banks (with the wrap apron).
    pub fn new(tex: &MipTexture, banks: Banks) -> BankedTexture {
        let k = banks.k();
        let levels = (0..tex.level_count())
            .map(|li| {
                let l = tex.levels()[li];
                let (pw, ph) = (l.width as usize + k - 1, l.height as usize + k - 1);
                let (bw, bh) = (pw.div_ceil(k), ph.div_ceil(k));
                let mut bk = vec![vec![Vec4::ZERO; bw * bh]; k * k];
                for py in 0..ph {
                    for px in 0..pw {
                        // Padded texel (px, py) holds the wrapped (Repeat) or edge (Clamp) texel.
                        let t = tex.texel(li, px as i64, py as i64).unwrap_or(Vec4::ZERO);
                        bk[(py % k) * k + px % k][(py / k) * bw + px / k] = t;
                    }
                }
                BankedLevel {
                    bank_w: bw,
                    banks: bk,
                }
            })
            .collect();
        BankedTexture {
            banks,
            levels,
            bias: 0,
        }
    }

    /// For experiments: add `bias` to the policy's finer level index (negative = finer). Any
    /// negative bias breaks the no-conflict guarantee — e.g. K = 3 with bias −1 is the
    /// conventional trilinear pair — and the conflicts show up in [`BankStats::conflicts`].
    pub fn with_level_bias(mut self, bias: i32) -> BankedTexture {
        self.bias = bias.clamp(-64, 64);
        self
    }

    /// K, banks per side.
    pub fn banks(&self) -> Banks {
        self.banks
    }

    /// The span sampler through the banks: same output as [`Sampler::Span`] (bit-identical),
    /// counting reads and conflicts in `stats`. `tex` must be the texture this was built from.
    pub fn sample_quad(&self, tex: &MipTexture, uv: [Vec2; 4], stats: &mut BankStats) -> [Vec4; 4] {
        stats.spans += 1;
        let mut src = BankSource { bt: self, stats };
        with_addr!(tex, A, {
            match self.banks {
                Banks::K3 => span_quad::<A, _, 3>(tex, uv, self.bias, &mut src),
                Banks::K4 => span_quad::<A, _, 4>(tex, uv, self.bias, &mut src),
            }
        })
    }
}

struct BankSource<'a> {
    bt: &'a BankedTexture,
    stats: &'a mut BankStats,
}

impl WindowSource for BankSource<'_> {
    type Win = [[Vec4; 4]; 4];
    fn window<A: Addr, const K: usize>(
        &mut self,
        tex: &MipTexture,
        level: usize,
        x0: i32,
        y0: i32,
    ) -> Self::Win {
        let l = &tex.levels()[level];
        let bl = &self.bt.levels[level];
        // Reduce the corner into the level (the window never wraps in the padded bank space).
        let (x0, y0) = if A::REPEAT {
            (
                x0.rem_euclid(l.width as i32) as usize,
                y0.rem_euclid(l.height as i32) as usize,
            )
        } else {
            (
                x0.clamp(0, l.width as i32 - 1) as usize,
                y0.clamp(0, l.height as i32 - 1) as usize,
            )
        };
        self.stats.window_reads += 1;
        if x0 + K > l.width as usize || y0 + K > l.height as usize {
            self.stats.edge_windows += 1;
        }
        let mut win = [[Vec4::ZERO; 4]; 4];
        for j in 0..K {
            // Seed 000 Eq. (10): a_j = ⌊Y0/K⌋ + δ(j, Y0), δ = 1 if j < Y0 mod K.
            let ay = y0 / K + usize::from(j < y0 % K);
            let oy = ay * K + j - y0;
            for i in 0..K {
                let ax = x0 / K + usize::from(i < x0 % K);
                let ox = ax * K + i - x0;
                debug_assert!(ox < K && oy < K);
                win[oy][ox] = bl.banks[j * K + i][ay * bl.bank_w + ax];
                self.stats.bank_reads += 1;
            }
        }
        win
    }
    fn quad(_tex: &MipTexture, win: &Self::Win, ox: usize, oy: usize) -> [Vec4; 4] {
        [
            win[oy][ox],
            win[oy][ox + 1],
            win[oy + 1][ox],
            win[oy + 1][ox + 1],
        ]
    }
    fn conflict(&mut self) {
        self.stats.conflicts += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mip::Reduction;

    fn ramp(w: u32, h: u32, wrap: Wrap) -> MipTexture {
        let data: Vec<Vec4> = (0..w * h)
            .map(|i| Vec4::new((i % w) as f32, (i / w) as f32, 1.0, 1.0))
            .collect();
        MipTexture::from_linear(w, h, &data, Reduction::GammaCorrect, wrap).unwrap()
    }

    #[test]
    fn log2_split_is_exact_in_its_integer_part_and_close_in_its_fraction() {
        let mut worst = 0f64;
        let mut prev = f64::NEG_INFINITY;
        for i in 0..200_000 {
            let x = 2f32.powf(-20.0 + 40.0 * i as f32 / 200_000.0);
            let (e, f) = log2_split(x);
            let exact = (x as f64).log2();
            assert_eq!(e, exact.floor() as i32, "x = {x}");
            assert!((0.0..=1.0).contains(&f), "x = {x}: fraction {f}");
            let got = e as f64 + f as f64;
            worst = worst.max((got - exact).abs());
            assert!(got >= prev, "not monotone at {x}");
            prev = got;
        }
        assert!(worst < 1.3e-4, "expected |error| < 1.3e-4, worst {worst}");
    }

    #[test]
    fn bilinear_at_texel_centres_and_midpoints_is_exact() {
        let t = ramp(8, 8, Wrap::Clamp);
        // Centre of texel (3, 5) is ((3.5)/8, (5.5)/8).
        let c =
            Sampler::Bilinear.sample(&t, Vec2::new(3.5 / 8.0, 5.5 / 8.0), Vec2::ZERO, Vec2::ZERO);
        assert!(
            (c - Vec4::new(3.0, 5.0, 1.0, 1.0)).abs().max_element() < 1e-6,
            "{c}"
        );
        let m =
            Sampler::Bilinear.sample(&t, Vec2::new(4.0 / 8.0, 2.25 / 8.0), Vec2::ZERO, Vec2::ZERO);
        let expect = Vec4::new(3.5, 1.75, 1.0, 1.0);
        assert!(
            (m - expect).abs().max_element() < 1e-6,
            "expected {expect}, got {m}, tol 1e-6"
        );
    }

    #[test]
    fn nan_and_huge_inputs_give_finite_output() {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let t = ramp(6, 10, wrap);
            for s in [
                Sampler::Nearest,
                Sampler::Bilinear,
                Sampler::Trilinear,
                Sampler::Span(Banks::K3),
                Sampler::Span(Banks::K4),
                Sampler::Anisotropic { max_taps: 8 },
            ] {
                for uv in [
                    Vec2::NAN,
                    Vec2::splat(1e30),
                    Vec2::splat(-f32::INFINITY),
                    Vec2::new(0.3, 0.7),
                ] {
                    for d in [
                        Vec2::NAN,
                        Vec2::ZERO,
                        Vec2::splat(1e30),
                        Vec2::new(0.01, 0.0),
                    ] {
                        let c = s.sample(&t, uv, d, d.perp());
                        assert!(c.is_finite(), "{s:?} {wrap:?} {uv} {d} -> {c}");
                    }
                }
            }
        }
    }

    /// Random pixels from every regime: magnified, minified, past the top level, NaN and huge
    /// coordinates and derivatives, zero derivatives.
    fn random_pixels(n: usize, seed: u32) -> (Vec<Vec2>, Vec<Vec2>, Vec<Vec2>) {
        let mut rng = seed;
        let mut r = move || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            (rng >> 8) as f32 / (1u32 << 24) as f32
        };
        let (mut uv, mut dx, mut dy) = (vec![], vec![], vec![]);
        for i in 0..n {
            let mut p = Vec2::new(r() * 6.0 - 3.0, r() * 6.0 - 3.0);
            let s = 10f32.powf(r() * 7.0 - 5.0);
            let mut a = Vec2::new(r() - 0.5, r() - 0.5) * s;
            let mut b = Vec2::new(r() - 0.5, r() - 0.5) * s;
            match i % 23 {
                0 => p = Vec2::NAN,
                1 => a = Vec2::NAN,
                2 => (a, b) = (Vec2::NAN, Vec2::NAN),
                3 => p = Vec2::splat(1e30),
                4 => (a, b) = (Vec2::ZERO, Vec2::ZERO),
                5 => a = Vec2::splat(f32::INFINITY),
                6 => p.x = -f32::INFINITY,
                _ => {}
            }
            uv.push(p);
            dx.push(a);
            dy.push(b);
        }
        (uv, dx, dy)
    }

    #[test]
    fn bulk_trilinear_lanes_match_the_per_pixel_sampler_bit_for_bit() {
        // The lane kernel (power-of-two pyramids) against `sample`, which always takes the scalar
        // per-pixel path; odd lengths exercise the scalar tail; NPOT takes the scalar path.
        let mut reached_pair = false;
        for (w, h) in [(64, 64), (64, 16), (1, 8), (1, 1), (256, 128), (48, 20)] {
            for wrap in [Wrap::Repeat, Wrap::Clamp] {
                let t = ramp(w, h, wrap);
                let (uv, dx, dy) = random_pixels(4003, w * 31 + h);
                let mut out = vec![Vec4::ZERO; uv.len()];
                Sampler::Trilinear
                    .sample_pixels(&t, &uv, &dx, &dy, &mut out)
                    .unwrap();
                for i in 0..uv.len() {
                    let e = Sampler::Trilinear.sample(&t, uv[i], dx[i], dy[i]);
                    assert_eq!(
                        out[i].to_array().map(f32::to_bits),
                        e.to_array().map(f32::to_bits),
                        "{w}x{h} {wrap:?} pixel {i}: uv {} dx {} dy {}: expected {e}, got {}",
                        uv[i],
                        dx[i],
                        dy[i],
                        out[i]
                    );
                    let m = footprint(&t.levels()[0], dx[i], dy[i]);
                    reached_pair |= m > 1.0 && m.log2() < (t.level_count() - 1) as f32;
                }
            }
        }
        assert!(reached_pair, "no pixel blended two levels");
    }

    /// Spans from [`random_pixels`]' regimes, every third one small (mostly interior windows).
    fn random_quads(n: usize, seed: u32) -> Vec<[Vec2; 4]> {
        let (uv, dx, dy) = random_pixels(n, seed);
        (0..n)
            .map(|i| {
                let s = if i % 3 == 0 { 0.02 } else { 1.0 };
                quad_from_pixel(uv[i], dx[i] * s, dy[i] * s)
            })
            .collect()
    }

    #[test]
    fn one_span_calls_match_the_bank_emulator_bit_for_bit() {
        // `sample_quad(Span)` (the AVX2 power-of-two one-span kernel where the CPU has it) on
        // square, wide, tall and tiny pyramids, every input regime, against the emulator.
        let mut interior = 0u64;
        for (w, h) in [(64, 64), (64, 16), (16, 128), (1, 8), (2, 2), (256, 128)] {
            for wrap in [Wrap::Repeat, Wrap::Clamp] {
                let t = ramp(w, h, wrap);
                let quads = random_quads(3001, w * 13 + h);
                for banks in [Banks::K3, Banks::K4] {
                    let bt = BankedTexture::new(&t, banks);
                    let mut st = BankStats::default();
                    for (i, q) in quads.iter().enumerate() {
                        let bits = |c: [Vec4; 4]| c.map(|p| p.to_array().map(f32::to_bits));
                        let (got, e) = (
                            Sampler::Span(banks).sample_quad(&t, *q),
                            bt.sample_quad(&t, *q, &mut st),
                        );
                        assert_eq!(
                            bits(got),
                            bits(e),
                            "{w}x{h} {wrap:?} {banks:?} quad {i} {q:?}: expected {e:?}, got {got:?}"
                        );
                    }
                    assert_eq!(st.conflicts, 0, "{w}x{h} {wrap:?} {banks:?}: {st:?}");
                    interior += st.window_reads - st.edge_windows;
                }
            }
        }
        assert!(interior > 20_000, "too few interior windows: {interior}");
    }

    #[test]
    fn bulk_span_lanes_match_the_bank_emulator_bit_for_bit() {
        // `sample_quads` (four spans per step in lanes on power-of-two pyramids, generic path for
        // edge windows, the tail and NPOT) against the bank emulator, quad by quad.
        let mut lane_spans = 0usize;
        for (w, h) in [(64, 64), (64, 16), (1, 8), (2, 2), (256, 128), (48, 20)] {
            for wrap in [Wrap::Repeat, Wrap::Clamp] {
                let t = ramp(w, h, wrap);
                let quads = random_quads(2001, w * 17 + h);
                for banks in [Banks::K3, Banks::K4] {
                    let bt = BankedTexture::new(&t, banks);
                    let mut st = BankStats::default();
                    let mut out = vec![[Vec4::ZERO; 4]; quads.len()];
                    Sampler::Span(banks)
                        .sample_quads(&t, &quads, &mut out)
                        .unwrap();
                    for (i, q) in quads.iter().enumerate() {
                        let e = bt.sample_quad(&t, *q, &mut st);
                        for j in 0..4 {
                            assert_eq!(
                                out[i][j].to_array().map(f32::to_bits),
                                e[j].to_array().map(f32::to_bits),
                                "{w}x{h} {wrap:?} {banks:?} quad {i} pixel {j}: {q:?}: expected {}, got {}",
                                e[j],
                                out[i][j]
                            );
                        }
                    }
                    assert_eq!(st.conflicts, 0, "{w}x{h} {wrap:?} {banks:?}: {st:?}");
                    if t.is_pow2() {
                        lane_spans += st.window_reads as usize - st.edge_windows as usize;
                    }
                }
            }
        }
        assert!(
            lane_spans > 10_000,
            "too few interior windows: {lane_spans}"
        );
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn sse2_and_runtime_chosen_lane_builds_agree_bit_for_bit() {
        // The bulk calls above test the build chosen for this CPU (AVX2 or AVX-512); the SSE2
        // baseline build must give the same bits.
        let t = ramp(128, 64, Wrap::Repeat);
        let (uv, dx, dy) = random_pixels(4000, 99);
        let mut a = vec![Vec4::ZERO; uv.len()];
        let mut b = vec![Vec4::ZERO; uv.len()];
        let na = lanes::trilinear_pixels::<RepeatPow2>(&t, &uv, &dx, &dy, &mut a);
        let nb = lanes::trilinear_pixels_best::<RepeatPow2>(&t, &uv, &dx, &dy, &mut b);
        assert_eq!((na, nb), (4000, 4000));
        let bits = |v: &[Vec4]| {
            v.iter()
                .map(|c| c.to_array().map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&a), bits(&b));
        let quads: Vec<[Vec2; 4]> = (0..uv.len())
            .map(|i| quad_from_pixel(uv[i], dx[i] * 0.05, dy[i] * 0.05))
            .collect();
        let mut qa = vec![[Vec4::ZERO; 4]; quads.len()];
        let mut qb = vec![[Vec4::ZERO; 4]; quads.len()];
        lanes::span_quads4::<RepeatPow2, 3>(&t, &quads, &mut qa);
        lanes::span_quads4_best::<RepeatPow2, 3>(&t, &quads, &mut qb);
        assert_eq!(bits(qa.as_flattened()), bits(qb.as_flattened()));
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx512_lane_builds_match_the_sse2_baseline_bit_for_bit() {
        // The AVX-512 kernels (per-pixel trilinear sixteen pixels per step, four per zmm; the
        // span sampler's mspan read, K = 3) against the SSE2 baseline over every input regime of `random_pixels` /
        // `random_quads` on square, wide, tall and tiny power-of-two pyramids, both wraps (edge
        // windows included: with Repeat they are read from the level's seam strips, and the
        // count of such windows must be positive on every pyramid; with Clamp they take the
        // AVX2 edge path). Skipped where the CPU lacks AVX-512.
        if !lanes::has_avx512() {
            eprintln!("no AVX-512 on this CPU: the AVX-512 builds are not tested here");
            return;
        }
        let bits = |v: &[Vec4]| {
            v.iter()
                .map(|c| c.to_array().map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        let (mut interior, mut edge) = (0u64, 0u64);
        for (w, h) in [
            (64, 64),
            (256, 64),
            (16, 128),
            (1, 8),
            (2, 2),
            (4, 4),
            (128, 128),
        ] {
            for wrap in [Wrap::Repeat, Wrap::Clamp] {
                avx512::SEAM_WINDOWS.with(|n| n.set(0));
                let t = ramp(w, h, wrap);
                let (uv, dx, dy) = random_pixels(4000, w * 7 + h);
                let quads = random_quads(4000, w * 11 + h);
                let (mut a, mut b) = (vec![Vec4::ZERO; uv.len()], vec![Vec4::ZERO; uv.len()]);
                let (mut qa, mut qb) = (
                    vec![[Vec4::ZERO; 4]; quads.len()],
                    vec![[Vec4::ZERO; 4]; quads.len()],
                );
                macro_rules! run {
                    ($A:ty) => {{
                        let na = lanes::trilinear_pixels::<$A>(&t, &uv, &dx, &dy, &mut a);
                        // SAFETY: AVX-512F/VL/BW/DQ detected above; `t` is a power of two.
                        let nb = unsafe {
                            avx512::trilinear_pixels_x16::<$A>(&t, &uv, &dx, &dy, &mut b)
                        };
                        assert_eq!((na, nb), (4000, 4000));
                        lanes::span_quads4::<$A, 3>(&t, &quads, &mut qa);
                        // SAFETY: as above.
                        let nq = unsafe { avx512::span_quads_k3::<$A>(&t, &quads, &mut qb) };
                        assert_eq!(nq, 4000);
                        // Trilinear sixteen pixels per step likewise: the kernel alone, the
                        // chosen build (16, then the AVX2 build on the rest) and the public call
                        // (then the scalar remainder).
                        for len in [4000, 3992, 3987, 24, 17, 13, 7, 0] {
                            let same = |what: &str, n: usize, c: &[Vec4]| {
                                assert_eq!(
                                    bits(&a[..n]),
                                    bits(&c[..n]),
                                    "trilinear {what} {w}x{h} {wrap:?} len {len}"
                                );
                            };
                            let (u, x, y) = (&uv[..len], &dx[..len], &dy[..len]);
                            let mut c = vec![Vec4::ZERO; len];
                            // SAFETY: as above.
                            let n16 =
                                unsafe { avx512::trilinear_pixels_x16::<$A>(&t, u, x, y, &mut c) };
                            assert_eq!(n16, len / 16 * 16);
                            same("x16", n16, &c);
                            let mut c = vec![Vec4::ZERO; len];
                            let nb = lanes::trilinear_pixels_best::<$A>(&t, u, x, y, &mut c);
                            assert_eq!(nb, len / 8 * 8);
                            same("best", nb, &c);
                            let mut c = vec![Vec4::ZERO; len];
                            Sampler::Trilinear
                                .sample_pixels(&t, u, x, y, &mut c)
                                .expect("same lengths");
                            same("sample_pixels", len, &c);
                        }
                        // Sixteen spans per step on scenes that are not whole groups of 16
                        // (or of 8): the kernel alone, the chosen build (16, then the
                        // 8-span kernel on the rest) and the public call (then the scalar
                        // remainder).
                        for len in [4000, 3992, 3987, 24, 17, 13, 7, 0] {
                            // The first `n` spans of `qc` against the SSE2 baseline's.
                            let same = |what: &str, n: usize, qc: &[[Vec4; 4]]| {
                                assert_eq!(
                                    bits(qa[..n].as_flattened()),
                                    bits(qc[..n].as_flattened()),
                                    "span K3 {what} {w}x{h} {wrap:?} len {len}"
                                );
                            };
                            let mut qc = vec![[Vec4::ZERO; 4]; len];
                            // SAFETY: as above.
                            let n16 = unsafe {
                                avx512::span_quads_k3_x16::<$A>(&t, &quads[..len], &mut qc)
                            };
                            assert_eq!(n16, len / 16 * 16);
                            same("x16", n16, &qc);
                            let mut qc = vec![[Vec4::ZERO; 4]; len];
                            let nb = lanes::span_quads4_best::<$A, 3>(&t, &quads[..len], &mut qc);
                            assert_eq!(nb, len / 8 * 8);
                            same("best", nb, &qc);
                            let mut qc = vec![[Vec4::ZERO; 4]; len];
                            Sampler::Span(Banks::K3)
                                .sample_quads(&t, &quads[..len], &mut qc)
                                .expect("same lengths");
                            same("sample_quads", len, &qc);
                        }
                    }};
                }
                match wrap {
                    Wrap::Repeat => run!(RepeatPow2),
                    Wrap::Clamp => run!(ClampEdge),
                }
                // With Repeat the sixteen-span kernel must have read edge windows from the seam
                // strips (Clamp never does).
                let seam = avx512::SEAM_WINDOWS.with(|n| n.get());
                match wrap {
                    Wrap::Repeat => assert!(seam > 1_000, "{w}x{h}: {seam} seam-strip windows"),
                    Wrap::Clamp => assert_eq!(seam, 0, "{w}x{h}: Clamp read a seam strip"),
                }
                assert_eq!(bits(&a), bits(&b), "trilinear {w}x{h} {wrap:?}");
                for (i, (x, y)) in qa.iter().zip(&qb).enumerate() {
                    assert_eq!(
                        bits(x),
                        bits(y),
                        "span K3 {w}x{h} {wrap:?} quad {i} {:?}",
                        quads[i]
                    );
                }
                let bt = BankedTexture::new(&t, Banks::K3);
                let mut st = BankStats::default();
                for q in &quads {
                    bt.sample_quad(&t, *q, &mut st);
                }
                assert_eq!(st.conflicts, 0);
                interior += st.window_reads - st.edge_windows;
                edge += st.edge_windows;
            }
        }
        assert!(interior > 10_000, "too few interior windows: {interior}");
        assert!(edge > 1_000, "too few edge windows: {edge}");
    }

    #[test]
    fn trilinear_quad_lanes_match_per_pixel_sampling_bit_for_bit() {
        // `sample_quad` (trilinear in lanes on pow2) against four `sample` calls with the quad's
        // coarse derivatives.
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let t = ramp(64, 32, wrap);
            let (uv, dx, dy) = random_pixels(3000, 5);
            for i in 0..uv.len() {
                let q = quad_from_pixel(uv[i], dx[i], dy[i]);
                let got = Sampler::Trilinear.sample_quad(&t, q);
                for j in 0..4 {
                    let e = Sampler::Trilinear.sample(&t, q[j], q[1] - q[0], q[2] - q[0]);
                    assert_eq!(
                        got[j].to_array().map(f32::to_bits),
                        e.to_array().map(f32::to_bits),
                        "{wrap:?} quad {i} pixel {j}: expected {e}, got {}",
                        got[j]
                    );
                }
            }
        }
    }

    #[test]
    fn span_fast_path_matches_bank_emulator_bit_for_bit() {
        // `sample_quad` (one span per call: the AVX2 kernel on CPUs that have it, else the fused
        // scalar path) against the emulator, on power-of-two and NPOT sizes, both wrap modes.
        let mut interior = 0u64;
        for (w, h, wrap) in [
            (64, 32, Wrap::Repeat),
            (64, 32, Wrap::Clamp),
            (48, 20, Wrap::Repeat),
            (48, 20, Wrap::Clamp),
        ] {
            let t = ramp(w, h, wrap);
            interior += span_fast_path_case(&t);
        }
        assert!(interior > 10_000, "too few interior windows: {interior}");
    }

    /// One texture of [`span_fast_path_matches_bank_emulator_bit_for_bit`]; returns the number
    /// of interior window reads.
    fn span_fast_path_case(t: &MipTexture) -> u64 {
        let t = t.clone();
        let mut interior = 0;
        for banks in [Banks::K3, Banks::K4] {
            let bt = BankedTexture::new(&t, banks);
            let mut st = BankStats::default();
            let mut rng = 0x1234_5678u32;
            let mut r = || {
                rng ^= rng << 13;
                rng ^= rng >> 17;
                rng ^= rng << 5;
                rng as f32 / u32::MAX as f32
            };
            for _ in 0..2000 {
                let p = Vec2::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0);
                let dx = Vec2::new(r() - 0.5, r() - 0.5) * 0.2 * r();
                let dy = Vec2::new(r() - 0.5, r() - 0.5) * 0.2 * r();
                let q = [p, p + dx, p + dy, p + dx + dy];
                let a = Sampler::Span(banks).sample_quad(&t, q);
                let b = bt.sample_quad(&t, q, &mut st);
                for j in 0..4 {
                    assert_eq!(
                        a[j].to_array().map(f32::to_bits),
                        b[j].to_array().map(f32::to_bits),
                        "{banks:?} {:?} quad {q:?} pixel {j}: expected {}, got {}",
                        t.wrap(),
                        b[j],
                        a[j]
                    );
                }
            }
            assert_eq!(st.conflicts, 0, "{banks:?}: {st:?}");
            interior += st.window_reads - st.edge_windows;
        }
        interior
    }
}
