//! [`Lighting::shade`] without library calls: the same formula with a polynomial `pow`.
//!
//! Shading is a third of the ray-cast time with `powf` from libm (measured on S2, one thread:
//! `Lighting::shade` 17% + `powf` 14%). [`shade`] evaluates the identical ambient + Lambert +
//! Blinn-Phong sum, only `x^e` becomes `exp2(e·log2 x)` with the two polynomials below; a unit
//! test bounds the difference from [`Lighting::shade`] (≤ 2e-5 absolute on random inputs, far
//! under half an 8-bit sRGB step).

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use glam::Vec3;
use texmap_core::shade::{Lighting, Material};

/// `log2(x)` for finite `x > 0` (absolute error ≲ 1e-7 on normal numbers).
#[inline(always)]
fn log2_fast(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    // Mantissa in [1, 2), then moved to [1/√2, √2) so that u = (m − 1)/(m + 1) stays ≤ 0.172.
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    if m > std::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let u = (m - 1.0) / (m + 1.0);
    let u2 = u * u;
    // ln m = 2 (u + u³/3 + u⁵/5 + u⁷/7 + …); the next term is below 1e-7.
    let p = u * (2.0 + u2 * (2.0 / 3.0 + u2 * (2.0 / 5.0 + u2 * (2.0 / 7.0))));
    e as f32 + p * std::f32::consts::LOG2_E
}

/// `2^z` for `z ≤ 0` (relative error ≲ 3e-7; 0 below 2^−126).
#[inline(always)]
fn exp2_neg(z: f32) -> f32 {
    if !(z > -126.0) {
        return 0.0;
    }
    // floor without a libm call (no SSE4.1 `roundps` in the portable baseline).
    let mut i = z as i32;
    if (i as f32) > z {
        i -= 1;
    }
    let i = i as f32;
    // 2^f = √2 · e^{g}, g = (f − 1/2)·ln 2 ∈ [−0.347, 0.347]: Taylor to g⁶.
    let g = (z - i - 0.5) * std::f32::consts::LN_2;
    let p = 1.0
        + g * (1.0
            + g * (0.5
                + g * (1.0 / 6.0 + g * (1.0 / 24.0 + g * (1.0 / 120.0 + g * (1.0 / 720.0))))));
    let scale = f32::from_bits(((i as i32 + 127) as u32) << 23);
    p * std::f32::consts::SQRT_2 * scale
}

/// `x^e` for `x ∈ [0, 1]`, `e > 0`.
#[inline(always)]
pub(crate) fn pow01(x: f32, e: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    exp2_neg((e * log2_fast(x)).min(0.0))
}

/// [`Lighting::shade`] with [`pow01`]: same inputs, same formula.
#[inline]
pub(crate) fn shade(l: &Lighting, m: &Material, n: Vec3, v: Vec3) -> Vec3 {
    let mut c = l.ambient * m.base_color;
    for light in l.lights() {
        let ndl = n.dot(light.to_light);
        if ndl > 0.0 {
            let mut term = m.base_color * ndl;
            if m.specular > 0.0 {
                let h = light.to_light + v;
                let hh = h.length_squared();
                if hh > 0.0 {
                    let ndh = (n.dot(h) / hh.sqrt()).clamp(0.0, 1.0);
                    term += Vec3::splat(m.specular * pow01(ndh, m.shininess));
                }
            }
            c += light.color * term;
        }
    }
    c
}

/// Lane width of [`shade8`].
pub(crate) const W: usize = 8;
pub(crate) type F8 = [f32; W];

/// Branch-free [`log2_fast`] over 8 lanes (inputs > 0; the caller masks the rest).
#[inline(always)]
fn log2_8(x: &F8) -> F8 {
    let mut out = [0.0; W];
    for l in 0..W {
        let bits = x[l].to_bits();
        let e = ((bits >> 23) & 0xff) as i32 - 127;
        let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
        let big = m > std::f32::consts::SQRT_2;
        let m = if big { m * 0.5 } else { m };
        let e = (e + big as i32) as f32;
        let u = (m - 1.0) / (m + 1.0);
        let u2 = u * u;
        let p = u * (2.0 + u2 * (2.0 / 3.0 + u2 * (2.0 / 5.0 + u2 * (2.0 / 7.0))));
        out[l] = e + p * std::f32::consts::LOG2_E;
    }
    out
}

/// Branch-free [`exp2_neg`] over 8 lanes (`z ≤ 0`; 0 below 2^−126).
#[inline(always)]
fn exp2_neg8(z: &F8) -> F8 {
    let mut out = [0.0; W];
    for l in 0..W {
        let zl = if z[l] > -126.0 { z[l] } else { -126.0 };
        let ti = zl as i32;
        let i = ti - ((ti as f32) > zl) as i32;
        let g = (zl - i as f32 - 0.5) * std::f32::consts::LN_2;
        let p = 1.0
            + g * (1.0
                + g * (0.5
                    + g * (1.0 / 6.0 + g * (1.0 / 24.0 + g * (1.0 / 120.0 + g * (1.0 / 720.0))))));
        let scale = f32::from_bits(((i + 127) as u32) << 23);
        let v = p * std::f32::consts::SQRT_2 * scale;
        out[l] = if z[l] > -126.0 { v } else { 0.0 };
    }
    out
}

/// Surface and material of 8 pixels, structure-of-arrays.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Surf8 {
    pub n: [F8; 3],
    pub v: [F8; 3],
    pub base: [F8; 3],
    pub spec: F8,
    pub shin: F8,
}

/// [`shade`] over 8 lanes: the same formula, masks instead of branches.
#[inline(always)]
pub(crate) fn shade8(l: &Lighting, s: &Surf8) -> [F8; 3] {
    let mut c = [[0.0; W]; 3];
    for k in 0..3 {
        for i in 0..W {
            c[k][i] = l.ambient[k] * s.base[k][i];
        }
    }
    for light in l.lights() {
        let a = light.to_light;
        let mut ndl = [0.0; W];
        let mut ndh = [0.0; W];
        for i in 0..W {
            ndl[i] = s.n[0][i] * a.x + s.n[1][i] * a.y + s.n[2][i] * a.z;
            let hx = a.x + s.v[0][i];
            let hy = a.y + s.v[1][i];
            let hz = a.z + s.v[2][i];
            let hh = hx * hx + hy * hy + hz * hz;
            let nh = s.n[0][i] * hx + s.n[1][i] * hy + s.n[2][i] * hz;
            let q = nh / hh.sqrt();
            // Clamp to (0, 1]; lanes at 0 (or NaN from hh = 0) are masked after the pow.
            ndh[i] = if q > 1e-30 {
                if q < 1.0 { q } else { 1.0 }
            } else {
                1e-30
            };
        }
        let lg = log2_8(&ndh);
        let mut z = [0.0; W];
        for i in 0..W {
            let e = s.shin[i] * lg[i];
            z[i] = if e < 0.0 { e } else { 0.0 };
        }
        let pw = exp2_neg8(&z);
        for i in 0..W {
            let lit = ndl[i] > 0.0;
            let spec = if ndh[i] > 1e-30 {
                s.spec[i] * pw[i]
            } else {
                0.0
            };
            for k in 0..3 {
                let term = s.base[k][i] * ndl[i] + spec;
                c[k][i] += if lit { light.color[k] * term } else { 0.0 };
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow_matches_libm() {
        let mut worst = 0f32;
        for i in 0..=20_000 {
            let x = i as f32 / 20_000.0;
            for e in [1.0f32, 2.0, 7.5, 40.0, 128.0] {
                let a = x.powf(e);
                let b = pow01(x, e);
                worst = worst.max((a - b).abs() / a.max(1e-30).max(1e-6));
            }
        }
        assert!(worst < 2e-5, "relative error expected < 2e-5, got {worst}");
    }

    #[test]
    fn shade_matches_lighting_shade() {
        let l = Lighting::new(
            Vec3::splat(0.1),
            &[
                (Vec3::new(-0.4, 0.5, 1.0), Vec3::splat(0.9)),
                (Vec3::new(0.6, -0.2, 0.8), Vec3::splat(0.3)),
            ],
        )
        .unwrap();
        let m = Material::plastic(Vec3::new(0.7, 0.3, 0.2));
        let mut s = 1u32;
        let mut r = || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        let mut worst = 0f32;
        for _ in 0..100_000 {
            let n = Vec3::new(r(), r(), r()).normalize_or(Vec3::Z);
            let v = Vec3::new(r() * 0.3, r() * 0.3, 1.0).normalize();
            let a = l.shade(&m, n, v);
            let b = shade(&l, &m, n, v);
            worst = worst.max((a - b).abs().max_element());
        }
        assert!(worst <= 2e-5, "expected ≤ 2e-5, got {worst}");
    }

    #[test]
    fn shade8_matches_lighting_shade() {
        let l = Lighting::new(
            Vec3::splat(0.1),
            &[
                (Vec3::new(-0.4, 0.5, 1.0), Vec3::splat(0.9)),
                (Vec3::new(0.6, -0.2, 0.8), Vec3::splat(0.3)),
            ],
        )
        .unwrap();
        let mats = [
            Material::plastic(Vec3::new(0.7, 0.3, 0.2)),
            Material::matte(Vec3::new(0.1, 0.9, 0.4)),
        ];
        let mut st = 7u32;
        let mut r = || {
            st = st.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (st >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        let mut worst = 0f32;
        for _ in 0..20_000 {
            let mut s = Surf8::default();
            let mut want = [Vec3::ZERO; W];
            for i in 0..W {
                let n = Vec3::new(r(), r(), r()).normalize_or(Vec3::Z);
                let v = Vec3::new(r() * 0.3, r() * 0.3, 1.0).normalize();
                let m = &mats[i % 2];
                want[i] = l.shade(m, n, v);
                for k in 0..3 {
                    s.n[k][i] = n[k];
                    s.v[k][i] = v[k];
                    s.base[k][i] = m.base_color[k];
                }
                s.spec[i] = m.specular;
                s.shin[i] = m.shininess;
            }
            let got = shade8(&l, &s);
            for i in 0..W {
                let g = Vec3::new(got[0][i], got[1][i], got[2][i]);
                worst = worst.max((g - want[i]).abs().max_element());
            }
        }
        assert!(worst <= 2e-5, "expected ≤ 2e-5, got {worst}");
    }
}
