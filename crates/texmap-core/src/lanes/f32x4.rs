//! Four lanes: [`I32x4`] (wrapping integer arithmetic, shifts) and [`F32x4`] (IEEE single
//! arithmetic, comparisons that return all-ones / all-zero lane masks as `F32x4`, selects).
//!
//! On x86-64 they are SSE2 registers (SSE2 is part of the x86-64 baseline, so no run-time
//! detection is needed); elsewhere they are the [`portable`] arrays, which are compiled on every
//! target as the scalar twin the SSE2 form is tested against bit for bit. Every operation is
//! IEEE-exact lane by lane (no FMA, no approximate reciprocal), so both forms, and the scalar
//! formulas they replace, give bit-identical results.
//!
//! The rasteriser's quad loop is written with them: lane loops such as `(d < s) as u8 << l` or
//! `if on { a } else { b }` stay scalar under the auto-vectoriser, and written with these types
//! the depth test of a quad is about ten instructions.

// The arithmetic is written as method chains (`a.mul(b).add(c)`), in the evaluation order the
// bit-for-bit tests fix; the methods are named after the operations they perform.
#![allow(clippy::should_implement_trait)]

#[cfg(target_arch = "x86_64")]
mod sse2 {
    use core::arch::x86_64::*;

    /// Four i32 lanes (wrapping arithmetic).
    #[derive(Clone, Copy, Debug)]
    pub struct I32x4(__m128i);

    /// Four f32 lanes; comparisons return all-ones / all-zero lane masks as `F32x4`.
    #[derive(Clone, Copy, Debug)]
    pub struct F32x4(__m128);

    impl I32x4 {
        #[inline(always)]
        pub fn new(a: [i32; 4]) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_set_epi32(a[3], a[2], a[1], a[0])) }
        }
        #[inline(always)]
        pub fn splat(v: i32) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_set1_epi32(v)) }
        }
        #[inline(always)]
        pub fn add(self, o: I32x4) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_add_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn or(self, o: I32x4) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_or_si128(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn sub(self, o: I32x4) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_sub_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn and(self, o: I32x4) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_and_si128(self.0, o.0)) }
        }
        /// Arithmetic shift right by `N`.
        #[inline(always)]
        pub fn shr<const N: i32>(self) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_srai_epi32::<N>(self.0)) }
        }
        /// Shift left by `N`.
        #[inline(always)]
        pub fn shl<const N: i32>(self) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_slli_epi32::<N>(self.0)) }
        }
        /// Exact conversion of each lane to f32 (rounded to nearest above 2^24).
        #[inline(always)]
        pub fn to_f32(self) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_cvtepi32_ps(self.0)) }
        }
        /// The lanes' bits as f32 lanes.
        #[inline(always)]
        pub fn cast_f32(self) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_castsi128_ps(self.0)) }
        }
        /// Bit l set when lane l is negative.
        #[inline(always)]
        pub fn neg_bits(self) -> u32 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { _mm_movemask_ps(_mm_castsi128_ps(self.0)) as u32 }
        }
    }

    impl F32x4 {
        #[inline(always)]
        pub fn new(a: [f32; 4]) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_set_ps(a[3], a[2], a[1], a[0])) }
        }
        #[inline(always)]
        pub fn splat(v: f32) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_set1_ps(v)) }
        }
        /// Store into the first four values of `s`.
        #[inline(always)]
        pub fn store(self, s: &mut [f32]) {
            let s = &mut s[..4];
            // SAFETY: `s` holds four f32 (checked above); unaligned store.
            unsafe { _mm_storeu_ps(s.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        pub fn to_array(self) -> [f32; 4] {
            let mut a = [0.0; 4];
            self.store(&mut a);
            a
        }
        #[inline(always)]
        pub fn add(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn mul(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn div(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn lt(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_cmplt_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn le(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_cmple_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn eq(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_cmpeq_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn and(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_and_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn or(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_or_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn sub(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_sub_ps(self.0, o.0)) }
        }
        /// IEEE square root.
        #[inline(always)]
        pub fn sqrt(self) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_sqrt_ps(self.0)) }
        }
        /// `if self > o { self } else { o }` lane by lane (so NaN in `self` gives `o`).
        #[inline(always)]
        pub fn max(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_max_ps(self.0, o.0)) }
        }
        /// `self & !o` bit by bit.
        #[inline(always)]
        pub fn and_not(self, o: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_andnot_ps(o.0, self.0)) }
        }
        /// The lanes' bits as i32 lanes.
        #[inline(always)]
        pub fn cast_i32(self) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_castps_si128(self.0)) }
        }
        /// Truncation toward zero (lanes outside the i32 range give `i32::MIN`).
        #[inline(always)]
        pub fn trunc_i32(self) -> I32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { I32x4(_mm_cvttps_epi32(self.0)) }
        }
        /// Four rows of four lanes transposed: lane l of output i = lane i of input l.
        #[inline(always)]
        pub fn transpose(r: [F32x4; 4]) -> [F32x4; 4] {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe {
                let t0 = _mm_unpacklo_ps(r[0].0, r[1].0);
                let t1 = _mm_unpacklo_ps(r[2].0, r[3].0);
                let t2 = _mm_unpackhi_ps(r[0].0, r[1].0);
                let t3 = _mm_unpackhi_ps(r[2].0, r[3].0);
                [
                    F32x4(_mm_movelh_ps(t0, t1)),
                    F32x4(_mm_movehl_ps(t1, t0)),
                    F32x4(_mm_movelh_ps(t2, t3)),
                    F32x4(_mm_movehl_ps(t3, t2)),
                ]
            }
        }
        /// Bit l set when the sign bit of lane l is set (for masks: lane l true).
        #[inline(always)]
        pub fn bits(self) -> u32 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { _mm_movemask_ps(self.0) as u32 }
        }
        /// The lane mask of the low four bits of `m` (bit l -> lane l all ones).
        #[inline(always)]
        pub fn from_bits(m: u8) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            let b = unsafe { _mm_set_epi32(8, 4, 2, 1) };
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            let v = unsafe { _mm_and_si128(_mm_set1_epi32(m as i32), b) };
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe { F32x4(_mm_castsi128_ps(_mm_cmpeq_epi32(v, b))) }
        }
        /// Lane by lane: `a` where `mask` is true, else `b`.
        #[inline(always)]
        pub fn select(mask: F32x4, a: F32x4, b: F32x4) -> F32x4 {
            // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target.
            unsafe {
                F32x4(_mm_or_ps(
                    _mm_and_ps(mask.0, a.0),
                    _mm_andnot_ps(mask.0, b.0),
                ))
            }
        }
    }
}

/// The portable lanes: the implementation off x86-64, and the scalar twin the SSE2 lanes are
/// tested against on x86-64.
pub mod portable {
    /// Four i32 lanes (wrapping arithmetic).
    #[derive(Clone, Copy, Debug)]
    pub struct I32x4([i32; 4]);

    /// Four f32 lanes; comparisons return all-ones / all-zero lane masks as `F32x4`.
    #[derive(Clone, Copy, Debug)]
    pub struct F32x4([f32; 4]);

    #[inline(always)]
    fn mask(b: bool) -> f32 {
        f32::from_bits(if b { u32::MAX } else { 0 })
    }

    impl I32x4 {
        #[inline(always)]
        pub fn new(a: [i32; 4]) -> I32x4 {
            I32x4(a)
        }
        #[inline(always)]
        pub fn splat(v: i32) -> I32x4 {
            I32x4([v; 4])
        }
        #[inline(always)]
        pub fn add(self, o: I32x4) -> I32x4 {
            I32x4(std::array::from_fn(|l| self.0[l].wrapping_add(o.0[l])))
        }
        #[inline(always)]
        pub fn or(self, o: I32x4) -> I32x4 {
            I32x4(std::array::from_fn(|l| self.0[l] | o.0[l]))
        }
        #[inline(always)]
        pub fn sub(self, o: I32x4) -> I32x4 {
            I32x4(std::array::from_fn(|l| self.0[l].wrapping_sub(o.0[l])))
        }
        #[inline(always)]
        pub fn and(self, o: I32x4) -> I32x4 {
            I32x4(std::array::from_fn(|l| self.0[l] & o.0[l]))
        }
        #[inline(always)]
        pub fn shr<const N: i32>(self) -> I32x4 {
            I32x4(self.0.map(|v| v >> N))
        }
        #[inline(always)]
        pub fn shl<const N: i32>(self) -> I32x4 {
            I32x4(self.0.map(|v| v << N))
        }
        #[inline(always)]
        pub fn to_f32(self) -> F32x4 {
            F32x4(self.0.map(|v| v as f32))
        }
        #[inline(always)]
        pub fn cast_f32(self) -> F32x4 {
            F32x4(self.0.map(|v| f32::from_bits(v as u32)))
        }
        #[inline(always)]
        pub fn neg_bits(self) -> u32 {
            (0..4).fold(0, |m, l| m | (((self.0[l] < 0) as u32) << l))
        }
    }

    impl F32x4 {
        #[inline(always)]
        pub fn new(a: [f32; 4]) -> F32x4 {
            F32x4(a)
        }
        #[inline(always)]
        pub fn splat(v: f32) -> F32x4 {
            F32x4([v; 4])
        }
        #[inline(always)]
        pub fn store(self, s: &mut [f32]) {
            s[..4].copy_from_slice(&self.0);
        }
        #[inline(always)]
        pub fn to_array(self) -> [f32; 4] {
            self.0
        }
        #[inline(always)]
        pub fn add(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| self.0[l] + o.0[l]))
        }
        #[inline(always)]
        pub fn mul(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| self.0[l] * o.0[l]))
        }
        #[inline(always)]
        pub fn div(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| self.0[l] / o.0[l]))
        }
        #[inline(always)]
        pub fn lt(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| mask(self.0[l] < o.0[l])))
        }
        #[inline(always)]
        pub fn le(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| mask(self.0[l] <= o.0[l])))
        }
        #[inline(always)]
        pub fn eq(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| mask(self.0[l] == o.0[l])))
        }
        #[inline(always)]
        pub fn and(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| {
                f32::from_bits(self.0[l].to_bits() & o.0[l].to_bits())
            }))
        }
        #[inline(always)]
        pub fn or(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| {
                f32::from_bits(self.0[l].to_bits() | o.0[l].to_bits())
            }))
        }
        #[inline(always)]
        pub fn sub(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| self.0[l] - o.0[l]))
        }
        #[inline(always)]
        pub fn sqrt(self) -> F32x4 {
            F32x4(self.0.map(f32::sqrt))
        }
        #[inline(always)]
        pub fn max(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| {
                if self.0[l] > o.0[l] {
                    self.0[l]
                } else {
                    o.0[l]
                }
            }))
        }
        #[inline(always)]
        pub fn and_not(self, o: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| {
                f32::from_bits(self.0[l].to_bits() & !o.0[l].to_bits())
            }))
        }
        #[inline(always)]
        pub fn cast_i32(self) -> I32x4 {
            I32x4(self.0.map(|v| v.to_bits() as i32))
        }
        #[inline(always)]
        pub fn trunc_i32(self) -> I32x4 {
            I32x4(std::array::from_fn(|l| {
                let v = self.0[l];
                if v > -2147483904.0 && v < 2147483648.0 {
                    v as i32
                } else {
                    i32::MIN
                }
            }))
        }
        #[inline(always)]
        pub fn transpose(r: [F32x4; 4]) -> [F32x4; 4] {
            std::array::from_fn(|i| F32x4(std::array::from_fn(|l| r[l].0[i])))
        }
        #[inline(always)]
        pub fn bits(self) -> u32 {
            (0..4).fold(0, |m, l| m | ((self.0[l].to_bits() >> 31) << l))
        }
        #[inline(always)]
        pub fn from_bits(m: u8) -> F32x4 {
            F32x4(std::array::from_fn(|l| mask(m & (1 << l) != 0)))
        }
        #[inline(always)]
        pub fn select(m: F32x4, a: F32x4, b: F32x4) -> F32x4 {
            F32x4(std::array::from_fn(|l| {
                if m.0[l].to_bits() != 0 {
                    a.0[l]
                } else {
                    b.0[l]
                }
            }))
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
pub use portable::{F32x4, I32x4};
#[cfg(target_arch = "x86_64")]
pub use sse2::{F32x4, I32x4};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_match_scalar_operations() {
        let a = [1.5f32, -0.0, f32::NAN, f32::INFINITY];
        let b = [1.5f32, 0.0, 3.0, 2.0];
        let (va, vb) = (F32x4::new(a), F32x4::new(b));
        let bits =
            |f: fn(f32, f32) -> bool| (0..4).fold(0u32, |m, l| m | ((f(a[l], b[l]) as u32) << l));
        assert_eq!(va.lt(vb).bits(), bits(|x, y| x < y));
        assert_eq!(va.le(vb).bits(), bits(|x, y| x <= y));
        assert_eq!(va.eq(vb).bits(), bits(|x, y| x == y));
        let sum = va.add(vb).mul(vb).div(vb).sqrt().max(vb).to_array();
        for l in 0..4 {
            let e = ((a[l] + b[l]) * b[l] / b[l]).sqrt();
            let e = if e > b[l] { e } else { b[l] };
            assert_eq!(
                sum[l].to_bits(),
                e.to_bits(),
                "lane {l}: expected {e} got {}",
                sum[l]
            );
        }
        for m in 0..16u8 {
            assert_eq!(F32x4::from_bits(m).bits(), m as u32);
            let s = F32x4::select(F32x4::from_bits(m), va, vb).to_array();
            for l in 0..4 {
                let e = if m & (1 << l) != 0 { a[l] } else { b[l] };
                assert_eq!(s[l].to_bits(), e.to_bits());
            }
        }
        let i = I32x4::new([-1, 0, i32::MAX, i32::MIN]).add(I32x4::splat(1));
        // Wrapping: MAX + 1 = MIN.
        assert_eq!(i.neg_bits(), 0b1100);
        assert_eq!(
            I32x4::new([-1, 2, -3, 4]).or(I32x4::splat(0)).neg_bits(),
            0b0101
        );
    }

    /// Run one sequence of lane operations with a lane implementation; every result as bits.
    macro_rules! op_trace {
        ($f:ty, $i:ty, $a:expr, $b:expr, $ia:expr, $ib:expr, $m:expr) => {{
            let (a, b) = (<$f>::new($a), <$f>::new($b));
            let (ia, ib) = (<$i>::new($ia), <$i>::new($ib));
            let fs = [
                a.add(b),
                a.sub(b),
                a.mul(b),
                a.div(b),
                a.sqrt(),
                a.max(b),
                a.lt(b),
                a.le(b),
                a.eq(b),
                a.and(b),
                a.or(b),
                a.and_not(b),
                <$f>::select(<$f>::from_bits($m), a, b),
                ia.add(ib).cast_f32(),
                ia.sub(ib).cast_f32(),
                ia.and(ib).or(ib).cast_f32(),
                ia.shr::<7>().cast_f32(),
                ia.shl::<9>().cast_f32(),
                ia.to_f32(),
                a.trunc_i32().cast_f32(),
                a.cast_i32().cast_f32(),
                a.add(<$f>::splat(0.25)),
                ia.add(<$i>::splat(3)).cast_f32(),
            ];
            let mut out: Vec<u32> = fs
                .iter()
                .flat_map(|v| v.to_array().map(f32::to_bits))
                .collect();
            out.extend([
                a.bits(),
                a.lt(b).bits(),
                ia.neg_bits(),
                <$f>::from_bits($m).bits(),
            ]);
            let mut stored = [0.0f32; 5];
            b.store(&mut stored[1..]);
            out.extend(stored.map(f32::to_bits));
            let t = <$f>::transpose([a, b, a.add(b), a.mul(b)]);
            out.extend(t.iter().flat_map(|v| v.to_array().map(f32::to_bits)));
            out
        }};
    }

    #[test]
    fn sse2_lanes_equal_the_portable_lanes() {
        let mut st = 5u64;
        let mut bits = || {
            st = st
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (st >> 32) as u32
        };
        let specials = [
            0.0f32,
            -0.0,
            1.0,
            -1.5,
            1e30,
            -3e9,
            f32::INFINITY,
            f32::NAN,
            2.5e-40,
        ];
        for round in 0..5000 {
            let mut f = |k: usize| {
                let v = bits();
                match (round + k) % 3 {
                    0 => specials[v as usize % specials.len()],
                    1 => (v as i32 as f32) * 1e-6,
                    _ => f32::from_bits(v),
                }
            };
            let a = [f(0), f(1), f(2), f(3)];
            let b = [f(4), f(5), f(6), f(7)];
            let ia = [bits() as i32, bits() as i32, -(round as i32), round as i32];
            let ib = [bits() as i32, 7, i32::MIN, i32::MAX];
            let m = (round % 16) as u8;
            let fast = op_trace!(F32x4, I32x4, a, b, ia, ib, m);
            let portable = op_trace!(portable::F32x4, portable::I32x4, a, b, ia, ib, m);
            // NaN payloads may differ between implementations; NaN-ness may not.
            for (k, (x, y)) in fast.iter().zip(&portable).enumerate() {
                let nan = |v: u32| f32::from_bits(v).is_nan();
                assert!(
                    x == y || (nan(*x) && nan(*y)),
                    "round {round} value {k}: sse2 {x:#x} portable {y:#x} ({a:?} {b:?} {ia:?} {ib:?})"
                );
            }
        }
    }
}
