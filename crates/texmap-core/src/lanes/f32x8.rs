//! Eight `f32` lanes: the [`Lanes8`] and [`LaneMask`] traits every 8-lane kernel is written
//! over, and the baseline backend [`F32x8`] / [`Mask8`] (two SSE2 registers on x86-64, a plain
//! array elsewhere). The AVX2 backend is [`F32x8Avx2`](super::F32x8Avx2) (x86-64 only).
//!
//! Every operation is one IEEE single-precision operation per lane, no fused multiply-add, with
//! the same `min`/`max`/`select` semantics on every backend, so a kernel gives the same bits on
//! each (tests compare the backends, and the array form, lane by lane).

// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use super::math::{SRGB_N, srgb_pack_scalar};

/// Lanes of an 8-lane vector.
pub const LANES8: usize = 8;

#[cfg(not(target_arch = "x86_64"))]
use array_repr as repr;
#[cfg(target_arch = "x86_64")]
use sse2_repr as repr;

/// Eight `f32` lanes: two SSE registers on x86-64 (SSE2 is part of the x86-64 baseline, so no
/// run-time detection is needed), a plain array elsewhere. Every operation is an IEEE single
/// operation per lane (no fused multiply-add), so both forms give bit-identical results.
/// `min`/`max`/`select` follow SSE semantics: `a.min(b) = if a < b { a } else { b }`. The
/// array form is compiled on every target as [`portable::F32x8`].
#[derive(Clone, Copy, Debug)]
pub struct F32x8(repr::Repr);

/// A lane mask from a comparison of [`F32x8`]s (all bits set where true).
#[derive(Clone, Copy, Debug)]
pub struct Mask8(repr::Repr);

/// The inherent methods, [`Lanes8`] and [`LaneMask`] of a baseline lane pair `F32x8` / `Mask8`
/// (the names in scope where it is invoked) over the lane representation module `$r`.
macro_rules! baseline_lanes {
    ($r:ident) => {
        impl F32x8 {
            #[inline(always)]
            pub fn splat(x: f32) -> F32x8 {
                F32x8($r::splat(x))
            }
            #[inline(always)]
            pub fn load(a: &[f32; 8]) -> F32x8 {
                F32x8($r::load(a))
            }
            #[inline(always)]
            pub fn store(self) -> [f32; 8] {
                $r::store(self.0)
            }
            #[inline(always)]
            pub fn sqrt(self) -> F32x8 {
                F32x8($r::sqrt(self.0))
            }
            #[inline(always)]
            pub fn min(self, o: F32x8) -> F32x8 {
                F32x8($r::min(self.0, o.0))
            }
            #[inline(always)]
            pub fn max(self, o: F32x8) -> F32x8 {
                F32x8($r::max(self.0, o.0))
            }
            #[inline(always)]
            pub fn lt(self, o: F32x8) -> Mask8 {
                Mask8($r::lt(self.0, o.0))
            }
            #[inline(always)]
            pub fn gt(self, o: F32x8) -> Mask8 {
                Mask8($r::gt(self.0, o.0))
            }
            /// `m ? a : b` per lane.
            #[inline(always)]
            pub fn select(m: Mask8, a: F32x8, b: F32x8) -> F32x8 {
                F32x8($r::select(m.0, a.0, b.0))
            }
            #[inline(always)]
            pub fn le(self, o: F32x8) -> Mask8 {
                Mask8($r::le(self.0, o.0))
            }
            #[inline(always)]
            pub fn ge(self, o: F32x8) -> Mask8 {
                Mask8($r::ge(self.0, o.0))
            }
            /// The first 8 values of `a`.
            #[inline(always)]
            pub fn load_from(a: &[f32]) -> F32x8 {
                F32x8::load(a[..LANES8].try_into().expect("8 values"))
            }
            /// Store into the first 8 values of `a`.
            #[inline(always)]
            pub fn store_to(self, a: &mut [f32]) {
                $r::store_to(self.0, (&mut a[..LANES8]).try_into().expect("8 values"))
            }
            /// Lanes 0–3 from `a[..4]`, lanes 4–7 from `b[..4]` (two rows of a narrow box).
            #[inline(always)]
            pub fn load_halves(a: &[f32], b: &[f32]) -> F32x8 {
                F32x8($r::load_halves(
                    a[..4].try_into().expect("4 values"),
                    b[..4].try_into().expect("4 values"),
                ))
            }
            /// Store lanes 0–3 into `a[..4]`.
            #[inline(always)]
            pub fn store_lo(self, a: &mut [f32]) {
                $r::store_lo(self.0, (&mut a[..4]).try_into().expect("4 values"))
            }
            /// Store lanes 4–7 into `b[..4]`.
            #[inline(always)]
            pub fn store_hi(self, b: &mut [f32]) {
                $r::store_hi(self.0, (&mut b[..4]).try_into().expect("4 values"))
            }
            /// The `u32` bit patterns of `a[..8]` as lanes (for selecting winner indices bit-exactly).
            #[inline(always)]
            pub fn load_bits(a: &[u32]) -> F32x8 {
                let f: &[u32; LANES8] = a[..LANES8].try_into().expect("8 values");
                F32x8::load(&f.map(f32::from_bits))
            }
            /// A `u32` bit pattern in every lane.
            #[inline(always)]
            pub fn splat_bits(x: u32) -> F32x8 {
                F32x8::splat(f32::from_bits(x))
            }
            /// Store the lanes' bit patterns into `a[..8]`.
            #[inline(always)]
            pub fn store_bits(self, a: &mut [u32]) {
                let f = self.store();
                a[..LANES8].copy_from_slice(&f.map(f32::to_bits));
            }
            /// Truncation toward zero of lanes known to lie in `[0, 2^31)` (the caller clamps).
            #[inline(always)]
            pub fn trunc_u32(self) -> [u32; LANES8] {
                $r::trunc_u32(self.0)
            }
        }

        impl Mask8 {
            /// Lanes whose `e` has bit `b` set.
            #[inline(always)]
            pub fn bit_set(e: &[u32; LANES8], b: u32) -> Mask8 {
                Mask8($r::bit_set(e, b))
            }
            #[inline(always)]
            pub fn and(self, o: Mask8) -> Mask8 {
                Mask8($r::and(self.0, o.0))
            }
            /// The first `n` lanes of each half (lanes `l` with `l % 4 < n`).
            #[inline(always)]
            pub fn first_of_halves(n: usize) -> Mask8 {
                const IOTA: [f32; 8] = [0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0];
                F32x8::load(&IOTA).lt(F32x8::splat(n as f32))
            }
            /// The first `n` lanes (`n ≤ 8`).
            #[inline(always)]
            pub fn first(n: usize) -> Mask8 {
                const IOTA: [f32; 8] = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
                F32x8::load(&IOTA).lt(F32x8::splat(n as f32))
            }
            /// One bit per lane (lane 0 in bit 0).
            #[inline(always)]
            pub fn bits(self) -> u32 {
                $r::bits(self.0)
            }
        }

        // SAFETY: the baseline uses SSE2 (part of x86-64) or plain arrays: available everywhere.
        unsafe impl Lanes8 for F32x8 {
            type Mask = Mask8;
            #[inline(always)]
            fn available() -> bool {
                true
            }
            #[inline(always)]
            fn splat(x: f32) -> F32x8 {
                F32x8::splat(x)
            }
            #[inline(always)]
            fn load_from(a: &[f32]) -> F32x8 {
                F32x8::load_from(a)
            }
            #[inline(always)]
            fn store_to(self, a: &mut [f32]) {
                F32x8::store_to(self, a)
            }
            #[inline(always)]
            fn load_halves(a: &[f32], b: &[f32]) -> F32x8 {
                F32x8::load_halves(a, b)
            }
            #[inline(always)]
            fn store_lo(self, a: &mut [f32]) {
                F32x8::store_lo(self, a)
            }
            #[inline(always)]
            fn store_hi(self, b: &mut [f32]) {
                F32x8::store_hi(self, b)
            }
            #[inline(always)]
            fn sqrt(self) -> F32x8 {
                F32x8::sqrt(self)
            }
            #[inline(always)]
            fn min(self, o: F32x8) -> F32x8 {
                F32x8::min(self, o)
            }
            #[inline(always)]
            fn max(self, o: F32x8) -> F32x8 {
                F32x8::max(self, o)
            }
            #[inline(always)]
            fn lt(self, o: F32x8) -> Mask8 {
                F32x8::lt(self, o)
            }
            #[inline(always)]
            fn gt(self, o: F32x8) -> Mask8 {
                F32x8::gt(self, o)
            }
            #[inline(always)]
            fn le(self, o: F32x8) -> Mask8 {
                F32x8::le(self, o)
            }
            #[inline(always)]
            fn ge(self, o: F32x8) -> Mask8 {
                F32x8::ge(self, o)
            }
            #[inline(always)]
            fn eq_bits(self, o: F32x8) -> Mask8 {
                Mask8($r::eq_bits(self.0, o.0))
            }
            #[inline(always)]
            fn select(m: Mask8, a: F32x8, b: F32x8) -> F32x8 {
                F32x8::select(m, a, b)
            }
            #[inline(always)]
            fn and_bits(self, o: F32x8) -> F32x8 {
                F32x8($r::and(self.0, o.0))
            }
            #[inline(always)]
            fn xor_bits(self, o: F32x8) -> F32x8 {
                F32x8($r::xor(self.0, o.0))
            }
            #[inline(always)]
            fn splat_bits(x: u32) -> F32x8 {
                F32x8::splat_bits(x)
            }
            #[inline(always)]
            fn load_bits(a: &[u32]) -> F32x8 {
                F32x8::load_bits(a)
            }
            #[inline(always)]
            fn store_bits(self, a: &mut [u32]) {
                F32x8::store_bits(self, a)
            }
            #[inline(always)]
            fn bit_set(e: &[u32; LANES8], b: u32) -> Mask8 {
                Mask8::bit_set(e, b)
            }
            #[inline(always)]
            fn transpose(rows: [&[f32; 8]; 8]) -> [F32x8; 8] {
                $r::transpose(rows).map(F32x8)
            }
            #[inline(always)]
            fn srgb_pack(r: F32x8, g: F32x8, b: F32x8, table: &[u32; SRGB_N]) -> F32x8 {
                let px = srgb_pack_scalar(r.trunc_u32(), g.trunc_u32(), b.trunc_u32(), table);
                F32x8::load_bits(&px)
            }
            #[inline(always)]
            fn store_rgba(self, out: &mut [[u8; 4]]) {
                let mut px = [0u32; LANES8];
                self.store_bits(&mut px);
                for (o, p) in out[..LANES8].iter_mut().zip(px) {
                    *o = p.to_le_bytes();
                }
            }
        }

        impl LaneMask for Mask8 {
            #[inline(always)]
            fn and(self, o: Mask8) -> Mask8 {
                Mask8::and(self, o)
            }
            #[inline(always)]
            fn bits(self) -> u32 {
                Mask8::bits(self)
            }
            #[inline(always)]
            fn first(n: usize) -> Mask8 {
                Mask8::first(n)
            }
            #[inline(always)]
            fn first_of_halves(n: usize) -> Mask8 {
                Mask8::first_of_halves(n)
            }
        }

        impl std::ops::Add for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn add(self, o: F32x8) -> F32x8 {
                F32x8($r::add(self.0, o.0))
            }
        }
        impl std::ops::Sub for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn sub(self, o: F32x8) -> F32x8 {
                F32x8($r::sub(self.0, o.0))
            }
        }
        impl std::ops::Mul for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn mul(self, o: F32x8) -> F32x8 {
                F32x8($r::mul(self.0, o.0))
            }
        }
        impl std::ops::Div for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn div(self, o: F32x8) -> F32x8 {
                F32x8($r::div(self.0, o.0))
            }
        }
    };
}

baseline_lanes!(repr);

/// The array form of [`F32x8`] / [`Mask8`], compiled on every target: the scalar twin the SSE2
/// form is tested against lane by lane (off x86-64 it is the baseline itself). Kernels written
/// over [`Lanes8`] run on it unchanged.
pub mod portable {
    use super::*;

    /// Eight `f32` lanes as a plain array (the same semantics as [`super::F32x8`]).
    #[derive(Clone, Copy, Debug)]
    pub struct F32x8(array_repr::Repr);

    /// A lane mask of [`F32x8`] (all bits set where true).
    #[derive(Clone, Copy, Debug)]
    pub struct Mask8(array_repr::Repr);

    baseline_lanes!(array_repr);
}

/// Eight `f32` lanes, whatever the backend: the baseline [`F32x8`] (SSE2 or arrays), its array
/// twin [`portable::F32x8`] or, on x86-64 CPUs that have it, the AVX2
/// [`F32x8Avx2`](super::F32x8Avx2). The hot kernels are written once, generic over this trait,
/// and compiled once per backend; every operation is one IEEE single-precision operation per lane
/// (no fused multiply-add, the same `min`/`max`/`select` semantics), so every backend gives the
/// same bits.
///
/// # Safety
/// An implementation may execute instructions beyond the x86-64 baseline; [`Lanes8::available`]
/// says whether this CPU has them, and code may use the implementation's operations only after
/// it returned `true` (the kernels check it once per frame, when they are chosen).
pub unsafe trait Lanes8:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
{
    /// A lane mask (all bits set where true).
    type Mask: LaneMask;
    /// Whether this CPU can run the backend.
    fn available() -> bool;
    fn splat(x: f32) -> Self;
    /// The first 8 values of `a`.
    fn load_from(a: &[f32]) -> Self;
    /// Store into the first 8 values of `a`.
    fn store_to(self, a: &mut [f32]);
    /// Lanes 0–3 from `a[..4]`, lanes 4–7 from `b[..4]`.
    fn load_halves(a: &[f32], b: &[f32]) -> Self;
    /// Store lanes 0–3 into `a[..4]`.
    fn store_lo(self, a: &mut [f32]);
    /// Store lanes 4–7 into `b[..4]`.
    fn store_hi(self, b: &mut [f32]);
    fn sqrt(self) -> Self;
    /// `if self < o { self } else { o }` per lane (SSE semantics).
    fn min(self, o: Self) -> Self;
    /// `if self > o { self } else { o }` per lane (SSE semantics).
    fn max(self, o: Self) -> Self;
    fn lt(self, o: Self) -> Self::Mask;
    fn gt(self, o: Self) -> Self::Mask;
    fn le(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    /// Lanes whose bit patterns are equal.
    fn eq_bits(self, o: Self) -> Self::Mask;
    /// `m ? a : b` per lane.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Bitwise and / exclusive or of the lanes' bit patterns.
    fn and_bits(self, o: Self) -> Self;
    fn xor_bits(self, o: Self) -> Self;
    /// A `u32` bit pattern in every lane.
    fn splat_bits(x: u32) -> Self;
    /// The `u32` bit patterns of `a[..8]` as lanes.
    fn load_bits(a: &[u32]) -> Self;
    /// Store the lanes' bit patterns into `a[..8]`.
    fn store_bits(self, a: &mut [u32]);
    /// Lanes whose `e` has bit `b` set.
    fn bit_set(e: &[u32; LANES8], b: u32) -> Self::Mask;
    /// The columns of 8 rows of 8 values as lanes: `out[k]` holds `rows[l][k]` in lane `l`
    /// (an array-of-structures to structure-of-arrays transpose).
    fn transpose(rows: [&[f32; 8]; 8]) -> [Self; 8];
    /// `table[r] | table[g] << 8 | table[b] << 16 | 255 << 24` per lane, the indices being the
    /// lanes truncated toward zero (the caller clamps them to `[0, SRGB_N − 1]`; other values
    /// are wrapped into the table, never read outside it).
    fn srgb_pack(r: Self, g: Self, b: Self, table: &[u32; SRGB_N]) -> Self;
    /// Store the lanes' bit patterns as 8 little-endian RGBA pixels into `out[..8]`.
    fn store_rgba(self, out: &mut [[u8; 4]]);
}

/// A lane mask of a [`Lanes8`] backend.
pub trait LaneMask: Copy {
    fn and(self, o: Self) -> Self;
    /// One bit per lane (lane 0 in bit 0).
    fn bits(self) -> u32;
    /// The first `n` lanes (`n ≤ 8`).
    fn first(n: usize) -> Self;
    /// The first `n` lanes of each half (lanes `l` with `l % 4 < n`).
    fn first_of_halves(n: usize) -> Self;
}

#[cfg(target_arch = "x86_64")]
mod sse2_repr {
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
    bin!(xor, _mm_xor_ps);
    /// Lanes whose bit patterns are equal.
    #[inline(always)]
    pub fn eq_bits(a: Repr, b: Repr) -> Repr {
        unsafe {
            [
                _mm_castsi128_ps(_mm_cmpeq_epi32(
                    _mm_castps_si128(a[0]),
                    _mm_castps_si128(b[0]),
                )),
                _mm_castsi128_ps(_mm_cmpeq_epi32(
                    _mm_castps_si128(a[1]),
                    _mm_castps_si128(b[1]),
                )),
            ]
        }
    }
    /// Columns of the 4x4 block `[a, b, c, d]` (rows).
    #[inline(always)]
    fn transpose4(a: __m128, b: __m128, c: __m128, d: __m128) -> [__m128; 4] {
        unsafe {
            let t0 = _mm_unpacklo_ps(a, b);
            let t1 = _mm_unpacklo_ps(c, d);
            let t2 = _mm_unpackhi_ps(a, b);
            let t3 = _mm_unpackhi_ps(c, d);
            [
                _mm_movelh_ps(t0, t1),
                _mm_movehl_ps(t1, t0),
                _mm_movelh_ps(t2, t3),
                _mm_movehl_ps(t3, t2),
            ]
        }
    }
    /// Lane vectors of the columns of 8 rows: `out[k][l] = rows[l][k]`.
    #[inline(always)]
    pub fn transpose(rows: [&[f32; 8]; 8]) -> [Repr; 8] {
        let lo = |r: &[f32; 8]| unsafe { _mm_loadu_ps(r.as_ptr()) };
        let hi = |r: &[f32; 8]| unsafe { _mm_loadu_ps(r.as_ptr().add(4)) };
        let a = transpose4(lo(rows[0]), lo(rows[1]), lo(rows[2]), lo(rows[3]));
        let b = transpose4(hi(rows[0]), hi(rows[1]), hi(rows[2]), hi(rows[3]));
        let c = transpose4(lo(rows[4]), lo(rows[5]), lo(rows[6]), lo(rows[7]));
        let d = transpose4(hi(rows[4]), hi(rows[5]), hi(rows[6]), hi(rows[7]));
        [
            [a[0], c[0]],
            [a[1], c[1]],
            [a[2], c[2]],
            [a[3], c[3]],
            [b[0], d[0]],
            [b[1], d[1]],
            [b[2], d[2]],
            [b[3], d[3]],
        ]
    }
}

/// The plain-array lanes behind [`portable`] (and behind [`F32x8`] off x86-64).
mod array_repr {
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
        map2(a, b, |x, y| f32::from_bits(x.to_bits() & y.to_bits()))
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
    #[inline(always)]
    pub fn xor(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| f32::from_bits(x.to_bits() ^ y.to_bits()))
    }
    #[inline(always)]
    pub fn eq_bits(a: Repr, b: Repr) -> Repr {
        map2(a, b, |x, y| mask(x.to_bits() == y.to_bits()))
    }
    #[inline(always)]
    pub fn transpose(rows: [&[f32; 8]; 8]) -> [Repr; 8] {
        std::array::from_fn(|k| std::array::from_fn(|l| rows[l][k]))
    }
}
