//! The pair test on four atoms at once: [`hits`] gives a bit mask of the lanes that pass
//! `d² < (ra + rb + 0.45)²` and `d² > 0.4²`, with `d²` summed x, y, z in that order.
//!
//! On x86-64 it uses SSE2 (part of the x86-64 baseline, so no runtime detection is needed);
//! elsewhere [`hits_scalar`], which is also the reference the SSE2 path is tested against bit for
//! bit. Every operation is IEEE-exact lane by lane (no FMA), so both give the same mask.
//!
//! Why not leave it to the auto-vectoriser: the lane loop (`(hit as u32) << l`) was vectorised
//! with shuffles between partial vectors of 1, 2 and 4 lanes instead of one load per array.

use super::{BOND_TOLERANCE, MIN_BOND_LENGTH};

/// Atoms per test.
pub(super) const LANES: usize = 4;

/// The hit mask (bit `l` for lane `l`) of the atom at `p` with radius `ra` against the four
/// atoms `xs[l], ys[l], zs[l]` with radii `rs[l]`.
#[cfg(any(test, not(target_arch = "x86_64")))]
#[inline(always)]
pub(super) fn hits_scalar(
    p: [f32; 3],
    ra: f32,
    xs: &[f32; LANES],
    ys: &[f32; LANES],
    zs: &[f32; LANES],
    rs: &[f32; LANES],
) -> u32 {
    let min2 = MIN_BOND_LENGTH * MIN_BOND_LENGTH;
    let mut mask = 0u32;
    for l in 0..LANES {
        let v = [xs[l] - p[0], ys[l] - p[1], zs[l] - p[2]];
        let d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let lim = ra + rs[l] + BOND_TOLERANCE;
        mask |= (((d2 < lim * lim) & (d2 > min2)) as u32) << l;
    }
    mask
}

#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) fn hits(
    p: [f32; 3],
    ra: f32,
    xs: &[f32; LANES],
    ys: &[f32; LANES],
    zs: &[f32; LANES],
    rs: &[f32; LANES],
) -> u32 {
    use core::arch::x86_64::*;
    // SAFETY: SSE2 is part of the x86-64 baseline, always enabled on this target; the loads
    // read exactly the four f32 of each array reference.
    unsafe {
        let load = |a: &[f32; LANES]| _mm_loadu_ps(a.as_ptr());
        let vx = _mm_sub_ps(load(xs), _mm_set1_ps(p[0]));
        let vy = _mm_sub_ps(load(ys), _mm_set1_ps(p[1]));
        let vz = _mm_sub_ps(load(zs), _mm_set1_ps(p[2]));
        let d2 = _mm_add_ps(
            _mm_add_ps(_mm_mul_ps(vx, vx), _mm_mul_ps(vy, vy)),
            _mm_mul_ps(vz, vz),
        );
        let lim = _mm_add_ps(
            _mm_add_ps(_mm_set1_ps(ra), load(rs)),
            _mm_set1_ps(BOND_TOLERANCE),
        );
        let ok = _mm_and_ps(
            _mm_cmplt_ps(d2, _mm_mul_ps(lim, lim)),
            _mm_cmpgt_ps(d2, _mm_set1_ps(MIN_BOND_LENGTH * MIN_BOND_LENGTH)),
        );
        _mm_movemask_ps(ok) as u32
    }
}

#[cfg(not(target_arch = "x86_64"))]
pub(super) use hits_scalar as hits;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_match_the_scalar_test_bit_for_bit() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let special = [f32::NAN, 0.4, 1.07, f32::INFINITY, -0.0, 0.0];
        let mut seen = [0usize; 1 << LANES];
        for it in 0..200_000 {
            let p = [3.0 * next(), 3.0 * next(), 3.0 * next()];
            let ra = if it % 97 == 0 { f32::NAN } else { 1.2 * next() };
            let mut arr = || -> [f32; LANES] { std::array::from_fn(|_| 3.0 * next()) };
            let (mut xs, ys, zs, mut rs) = (arr(), arr(), arr(), arr());
            if it % 5 == 0 {
                rs[it % LANES] = special[it % special.len()];
                xs[(it / 7) % LANES] = p[0] + special[(it / 3) % special.len()];
            }
            let want = hits_scalar(p, ra, &xs, &ys, &zs, &rs);
            assert_eq!(
                hits(p, ra, &xs, &ys, &zs, &rs),
                want,
                "{p:?} {ra} {xs:?} {rs:?}"
            );
            seen[want as usize] += 1;
        }
        // Every mask occurs, so both outcomes of every lane were compared.
        assert!(seen.iter().all(|&c| c > 0), "{seen:?}");
    }
}
