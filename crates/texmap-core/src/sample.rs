//! Texture samplers behind one enum: nearest, bilinear, trilinear (Seed 000 Eq. 4), the
//! span-parallel sampler of Seed 000 §3 (Eq. 8–10) with K x K memory banks, a quadratic
//! (3x3 Lagrange) sampler on trilinear's levels, and an anisotropic many-tap reference.
//!
//! # Files
//! - `sample.rs` (this file): the API ([`Sampler`], [`Banks`], [`SampleError`]) and the dispatch
//!   to a kernel, chosen once per call (wrap mode, power-of-two pyramid, CPU features);
//! - `sample/scalar.rs`: the scalar kernels and wrap modes, the reference every build matches;
//! - `sample/span.rs`: the span sampler's planning and per-pixel work (Eq. 8–10);
//! - `sample/bank.rs`: the bank emulator ([`BankedTexture`], [`BankStats`]);
//! - `sample/quadratic.rs`: [`Sampler::Quadratic3`], one pixel and a quad in lanes;
//! - `sample/lanes.rs` (SSE2, the x86-64 baseline, and the run-time choice of build),
//!   `sample/avx2.rs`, `sample/avx512.rs`: one file per instruction set;
//! - `sample/tests.rs`: every build bit for bit against the scalar kernels and the emulator.
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
//! degree-4 mantissa polynomial ([`crate::lanes::log2_split`], |error| ≤ 1.2e-4 in λ) instead
//! of libm's `log2f`; Repeat on power-of-two levels is a mask; texel reads skip bounds checks (indices are folded by
//! construction).
//!
//! **Lane kernels** (x86_64, power-of-two pyramids; the tail of a call, NPOT pyramids and other
//! targets take the scalar path): the bulk calls run per-pixel trilinear several PIXELS per step
//! and the span sampler several SPANS per step, the footprint, level split, level sizes (from the
//! float exponent), texel coordinates, floors and fractions computed once per group of lanes.
//! - `sample/lanes.rs`: the SSE2 baseline, four lanes per step, and the choice of build
//!   ([`crate::lanes::isa`], the workspace's one CPU-feature detection).
//! - `sample/avx2.rs`: the build chosen at run time where [`crate::lanes::Isa::Avx2`] is
//!   enabled, eight lanes per step; each pixel's texel indices computed in lanes (level base
//!   from a 16-entry table with two `vpermd`, rows by `vpmulld`, doubled so that `base + 8·index` addresses a
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
//! [`Sampler::Quadratic3`]'s quad kernel (`sample/quadratic.rs`) is portable `Vec4` code: the
//! quad's one level pair, and per level the coordinates, nearest texels, weights and window
//! indices of its four pixels in lanes, then nine texel loads and the separable weighted sums
//! per pixel. One `sample_quad` per quad, it runs 212.7 instructions per sample against
//! trilinear's 158.8 in the same build (1.34x; table below) and ~1.45x trilinear's thread CPU
//! time (14.6 against 10.0 ns per sample, best of 10 frames of `examples/sampling_prof.rs`, AMD
//! EPYC with AVX-512, 2026-12-02). An AVX2 build of the same code runs 14 % fewer instructions
//! there and is no faster, so the quad kernel has none.
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
//! | quadratic3, one `sample_quad` per quad (SSE2 lanes only) | 212.7 |
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

mod bank;
mod quadratic;
mod scalar;
mod span;
#[cfg(test)]
mod tests;

pub use bank::{BankStats, BankedTexture};
use quadratic::*;
use scalar::*;
use span::*;

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
    /// Higher-order interpolation from the 3x3 neighbourhood (suggested by Seed 000, not tested
    /// there): per level, separable 3-point Lagrange (quadratic) interpolation on the 3x3 texels
    /// around the pixel's nearest texel, clamped to [0, 1]; the levels and their blend as
    /// [`Sampler::Trilinear`] (Eq. 2's footprint, Eq. 4's blend of ⌊λ⌋ and ⌊λ⌋ + 1). Nine texel
    /// reads per level where trilinear has four: one 3x3 window per pixel and level, which 3x3
    /// banks serve without conflict.
    Quadratic3,
    /// Reference: a box filter over the pixel's parallelogram footprint (`uv ± ½duv_dx ± ½duv_dy`),
    /// `n_x x n_y` trilinear taps with `n = ⌈footprint side in texels⌉`, at most `max_taps` per
    /// side (clamped to 1..=64).
    Anisotropic { max_taps: u32 },
}

/// Largest texel coordinate magnitude: keeps `f32 -> i32` conversions and `+1` in range.
const COORD_LIMIT: f32 = (1u32 << 30) as f32;

// ---------------------------------------------------------------------------------------------
// Public API.

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

/// `Sampler::Quadratic3.sample_quad` out of line (the sampler already tested by the caller).
#[inline(never)]
fn quadratic_quad_entry(tex: &MipTexture, uv: [Vec2; 4]) -> [Vec4; 4] {
    with_addr!(tex, A, Sampler::Quadratic3.quad_one::<A>(tex, uv))
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
            Sampler::Quadratic3 => quadratic_fp::<A>(tex, uv, footprint(l0, duv_dx, duv_dy)),
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
            Sampler::Quadratic3 => quadratic_quad_entry(tex, uv),
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
            // The quad's pixels share its footprint: one level decision, set-up in lanes.
            Sampler::Quadratic3 => {
                let m = footprint(&tex.levels()[0], uv[1] - uv[0], uv[2] - uv[0]);
                quadratic_quad::<A>(tex, uv, m)
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
