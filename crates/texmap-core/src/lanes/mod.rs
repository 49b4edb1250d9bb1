//! Lane types, CPU-feature dispatch and the maths written over lanes, shared by the
//! rasteriser, the sphere/bond ray caster and the samplers.
//!
//! # Files
//! - `cpu.rs`: the one place that detects x86 features: [`Isa`] and [`isa()`] (detected once,
//!   cached; `TEXMAP_ISA=baseline|avx2|avx512` lowers the level, e.g. to test a fallback).
//! - `f32x4.rs`: four lanes, [`F32x4`] / [`I32x4`] (SSE2 on x86-64, arrays elsewhere), with
//!   the array form [`f32x4::portable`] always compiled as their scalar twin.
//! - `f32x8.rs`: eight lanes: the traits [`Lanes8`] / [`LaneMask`] kernels are written over,
//!   the baseline backend [`F32x8`] / [`Mask8`] (two SSE2 registers, arrays elsewhere), and
//!   its array form [`f32x8::portable`], always compiled, as the scalar twin.
//! - `f32x8_avx2.rs`: the AVX2 backend [`F32x8Avx2`] / [`Mask8Avx2`] (x86-64 only; usable
//!   where [`Isa::Avx2`] is enabled).
//! - `math.rs`: `log2`/`exp2`/`pow` polynomials (scalar and over lanes), integer specular
//!   powers ([`SpecPow`]), the samplers' [`log2_split`], the sRGB encode over lanes.
//! - `shade.rs`: the shading model ([`crate::shade::Lighting`]) with the polynomial power, one
//!   pixel or 8 lanes at a time.
//!
//! # Rules every backend follows
//! Each operation is one IEEE single-precision operation per lane, never a fused multiply-add,
//! with SSE semantics for `min`/`max` (`a.min(b) = if a < b { a } else { b }`) and all-ones /
//! all-zero masks; so a kernel written over these types gives the same bits on every backend
//! and on every thread count. Tests compare each SIMD form against its portable twin bit for
//! bit. SIMD wrappers are `#[inline(always)]` so that they inline into the
//! `#[target_feature]` kernels that use them.
//!
//! ```
//! use texmap_core::lanes::{F32x8, Isa, Lanes8, isa, pow01, pow01_lanes};
//! // The baseline backend runs everywhere; the level in use never exceeds what the CPU has.
//! assert!(F32x8::available() && isa() <= Isa::detected());
//! let x = F32x8::load(&[0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 1.0]);
//! let y = pow01_lanes(x, F32x8::splat(8.0)).store();
//! // The lane form equals the scalar form lane by lane.
//! for (l, xl) in x.store().into_iter().enumerate() {
//!     let want = if xl > 0.0 { pow01(xl, 8.0) } else { 0.0 };
//!     assert_eq!(y[l].to_bits(), want.to_bits());
//! }
//! ```

pub mod cpu;
pub mod f32x4;
pub mod f32x8;
#[cfg(target_arch = "x86_64")]
pub mod f32x8_avx2;
pub mod math;
pub mod shade;

pub use cpu::{Isa, isa};
pub use f32x4::{F32x4, I32x4};
pub use f32x8::{F32x8, LANES8, LaneMask, Lanes8, Mask8};
#[cfg(target_arch = "x86_64")]
pub use f32x8_avx2::{F32x8Avx2, Mask8Avx2};
pub use math::{
    LOG2_C1, LOG2_C2, LOG2_C3, LOG2_C4, MAX_INT_EXPONENT, SRGB_N, SpecPow, exp2_neg, exp2_neg_x8,
    log2_fast, log2_fast_x8, log2_split, pow_floors, pow_int_lanes, pow01, pow01_lanes, pow01_x4,
    spec_pow, spec_pow_of, srgb_pack_scalar, srgb_rgba_lanes, srgb_table32,
};

#[cfg(test)]
mod tests;
