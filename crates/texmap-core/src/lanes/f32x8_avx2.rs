//! The AVX2 backend of [`Lanes8`]: 8 lanes in one `__m256`, available where
//! [`Isa::Avx2`] is enabled ([`super::isa`]). The kernels that use it are
//! compiled inside `#[target_feature(enable = "avx2")]` functions so that these
//! `#[inline(always)]` wrappers and their intrinsics inline into them. No FMA: the same IEEE
//! operations as [`F32x8`](super::F32x8), so the same bits.

use super::math::SRGB_N;
use super::{Isa, LANES8, LaneMask, Lanes8};
use std::arch::x86_64::*;

/// Eight `f32` lanes in one AVX2 register.
#[derive(Clone, Copy, Debug)]
pub struct F32x8Avx2(__m256);
/// A lane mask of [`F32x8Avx2`] (all bits set where true).
#[derive(Clone, Copy, Debug)]
pub struct Mask8Avx2(__m256);

// SAFETY (every `unsafe` block of this module): values of these types are only created and
// used by code that runs after `F32x8Avx2::available()` returned true (the `Lanes8` contract), so
// the AVX/AVX2 instructions exist; the loads and stores go through slices of checked length.

// SAFETY: see the module note; `available` checks the CPU (through `Isa`, which never reports
// more than the CPU has).
unsafe impl Lanes8 for F32x8Avx2 {
    type Mask = Mask8Avx2;
    #[inline(always)]
    fn available() -> bool {
        Isa::Avx2.enabled()
    }
    #[inline(always)]
    fn splat(x: f32) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_set1_ps(x) })
    }
    #[inline(always)]
    fn load_from(a: &[f32]) -> F32x8Avx2 {
        let a = &a[..LANES8];
        F32x8Avx2(unsafe { _mm256_loadu_ps(a.as_ptr()) })
    }
    #[inline(always)]
    fn store_to(self, a: &mut [f32]) {
        let a = &mut a[..LANES8];
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn load_halves(a: &[f32], b: &[f32]) -> F32x8Avx2 {
        let (a, b) = (&a[..4], &b[..4]);
        F32x8Avx2(unsafe { _mm256_loadu2_m128(b.as_ptr(), a.as_ptr()) })
    }
    #[inline(always)]
    fn store_lo(self, a: &mut [f32]) {
        let a = &mut a[..4];
        unsafe { _mm_storeu_ps(a.as_mut_ptr(), _mm256_castps256_ps128(self.0)) }
    }
    #[inline(always)]
    fn store_hi(self, b: &mut [f32]) {
        let b = &mut b[..4];
        unsafe { _mm_storeu_ps(b.as_mut_ptr(), _mm256_extractf128_ps::<1>(self.0)) }
    }
    #[inline(always)]
    fn sqrt(self) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn min(self, o: F32x8Avx2) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_min_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: F32x8Avx2) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_max_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn lt(self, o: F32x8Avx2) -> Mask8Avx2 {
        Mask8Avx2(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn gt(self, o: F32x8Avx2) -> Mask8Avx2 {
        Mask8Avx2(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn le(self, o: F32x8Avx2) -> Mask8Avx2 {
        Mask8Avx2(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn ge(self, o: F32x8Avx2) -> Mask8Avx2 {
        Mask8Avx2(unsafe { _mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn eq_bits(self, o: F32x8Avx2) -> Mask8Avx2 {
        Mask8Avx2(unsafe {
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(
                _mm256_castps_si256(self.0),
                _mm256_castps_si256(o.0),
            ))
        })
    }
    #[inline(always)]
    fn select(m: Mask8Avx2, a: F32x8Avx2, b: F32x8Avx2) -> F32x8Avx2 {
        // Masks are all ones or all zeros per lane, so the sign-bit blend equals and/andnot.
        F32x8Avx2(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
    }
    #[inline(always)]
    fn and_bits(self, o: F32x8Avx2) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_and_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn xor_bits(self, o: F32x8Avx2) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_xor_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn splat_bits(x: u32) -> F32x8Avx2 {
        F32x8Avx2(unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(x as i32)) })
    }
    #[inline(always)]
    fn load_bits(a: &[u32]) -> F32x8Avx2 {
        let a = &a[..LANES8];
        F32x8Avx2(unsafe { _mm256_castsi256_ps(_mm256_loadu_si256(a.as_ptr() as *const __m256i)) })
    }
    #[inline(always)]
    fn store_bits(self, a: &mut [u32]) {
        let a = &mut a[..LANES8];
        unsafe { _mm256_storeu_si256(a.as_mut_ptr() as *mut __m256i, _mm256_castps_si256(self.0)) }
    }
    #[inline(always)]
    fn bit_set(e: &[u32; LANES8], b: u32) -> Mask8Avx2 {
        Mask8Avx2(unsafe {
            let one = _mm256_set1_epi32(1);
            let v = _mm256_loadu_si256(e.as_ptr() as *const __m256i);
            let t = _mm256_and_si256(_mm256_srl_epi32(v, _mm_cvtsi32_si128(b as i32)), one);
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(t, one))
        })
    }
    #[inline(always)]
    fn transpose(rows: [&[f32; 8]; 8]) -> [F32x8Avx2; 8] {
        unsafe {
            let r = rows.map(|r| _mm256_loadu_ps(r.as_ptr()));
            // Interleave pairs of rows, then pairs of pairs, then swap 128-bit halves.
            let t0 = _mm256_unpacklo_ps(r[0], r[1]);
            let t1 = _mm256_unpackhi_ps(r[0], r[1]);
            let t2 = _mm256_unpacklo_ps(r[2], r[3]);
            let t3 = _mm256_unpackhi_ps(r[2], r[3]);
            let t4 = _mm256_unpacklo_ps(r[4], r[5]);
            let t5 = _mm256_unpackhi_ps(r[4], r[5]);
            let t6 = _mm256_unpacklo_ps(r[6], r[7]);
            let t7 = _mm256_unpackhi_ps(r[6], r[7]);
            let u0 = _mm256_shuffle_ps::<0x44>(t0, t2);
            let u1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
            let u2 = _mm256_shuffle_ps::<0x44>(t1, t3);
            let u3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
            let u4 = _mm256_shuffle_ps::<0x44>(t4, t6);
            let u5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
            let u6 = _mm256_shuffle_ps::<0x44>(t5, t7);
            let u7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
            [
                F32x8Avx2(_mm256_permute2f128_ps::<0x20>(u0, u4)),
                F32x8Avx2(_mm256_permute2f128_ps::<0x20>(u1, u5)),
                F32x8Avx2(_mm256_permute2f128_ps::<0x20>(u2, u6)),
                F32x8Avx2(_mm256_permute2f128_ps::<0x20>(u3, u7)),
                F32x8Avx2(_mm256_permute2f128_ps::<0x31>(u0, u4)),
                F32x8Avx2(_mm256_permute2f128_ps::<0x31>(u1, u5)),
                F32x8Avx2(_mm256_permute2f128_ps::<0x31>(u2, u6)),
                F32x8Avx2(_mm256_permute2f128_ps::<0x31>(u3, u7)),
            ]
        }
    }
    #[inline(always)]
    fn srgb_pack(r: F32x8Avx2, g: F32x8Avx2, b: F32x8Avx2, table: &[u32; SRGB_N]) -> F32x8Avx2 {
        unsafe {
            let m = _mm256_set1_epi32(SRGB_N as i32 - 1);
            let t = table.as_ptr() as *const i32;
            // The indices are masked into [0, SRGB_N), so every gather reads inside `table`.
            let look = |c: F32x8Avx2| {
                let i = _mm256_and_si256(_mm256_cvttps_epi32(c.0), m);
                _mm256_i32gather_epi32::<4>(t, i)
            };
            let px = _mm256_or_si256(
                _mm256_or_si256(look(r), _mm256_slli_epi32::<8>(look(g))),
                _mm256_or_si256(
                    _mm256_slli_epi32::<16>(look(b)),
                    _mm256_set1_epi32(0xff00_0000_u32 as i32),
                ),
            );
            F32x8Avx2(_mm256_castsi256_ps(px))
        }
    }
    #[inline(always)]
    fn store_rgba(self, out: &mut [[u8; 4]]) {
        let out = &mut out[..LANES8];
        unsafe {
            _mm256_storeu_si256(
                out.as_mut_ptr() as *mut __m256i,
                _mm256_castps_si256(self.0),
            )
        }
    }
}

impl LaneMask for Mask8Avx2 {
    #[inline(always)]
    fn and(self, o: Mask8Avx2) -> Mask8Avx2 {
        Mask8Avx2(unsafe { _mm256_and_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }
    #[inline(always)]
    fn first(n: usize) -> Mask8Avx2 {
        const IOTA: [f32; 8] = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
        F32x8Avx2::load_from(&IOTA).lt(F32x8Avx2::splat(n as f32))
    }
    #[inline(always)]
    fn first_of_halves(n: usize) -> Mask8Avx2 {
        const IOTA: [f32; 8] = [0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0];
        F32x8Avx2::load_from(&IOTA).lt(F32x8Avx2::splat(n as f32))
    }
}

macro_rules! op {
    ($tr:ident, $f:ident, $i:ident) => {
        impl std::ops::$tr for F32x8Avx2 {
            type Output = F32x8Avx2;
            #[inline(always)]
            fn $f(self, o: F32x8Avx2) -> F32x8Avx2 {
                F32x8Avx2(unsafe { $i(self.0, o.0) })
            }
        }
    };
}
op!(Add, add, _mm256_add_ps);
op!(Sub, sub, _mm256_sub_ps);
op!(Mul, mul, _mm256_mul_ps);
op!(Div, div, _mm256_div_ps);
