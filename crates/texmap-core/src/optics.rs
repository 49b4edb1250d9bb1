//! Mirror reflection, Snell refraction and the Fresnel reflectance of a dielectric: the formulas
//! that the environment-mapping methods and the reference ray tracer's secondary rays share, so
//! that a difference between them is a method's error, never a formula's.
//!
//! Directions point *along* the light's travel: `d` is the incident direction (towards the
//! surface), `n` the unit normal on the side the ray comes from (`d · n ≤ 0`).
//!
//! # References
//! - Pharr, Jakob, Humphreys, *Physically Based Rendering* (4th ed.), §9.3 (specular reflection
//!   and transmission, the Fresnel equations for dielectrics).
//! - Seed 003 (dynamic environment mapping) reflects the eye vector about the normal to index the
//!   sphere map: [`reflect`].

use glam::Vec3;

/// The mirror direction of `d` about the unit normal `n`: `r = d − 2 (d · n) n`.
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// A refracted direction with the cosines the Fresnel term needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refraction {
    /// The transmitted direction (unit length when `d` and `n` are).
    pub dir: Vec3,
    /// `cos θ_i = −d · n`, clamped to [0, 1].
    pub cos_i: f32,
    /// `cos θ_t` of the transmitted direction.
    pub cos_t: f32,
}

/// Snell's law for the incident unit direction `d` at a surface with unit normal `n` facing the
/// incoming ray, and the relative index `eta = n_from / n_to` (entering glass of index 1.5 from
/// air: `eta = 1/1.5`). `None` is total internal reflection (`sin² θ_t ≥ 1`): the caller reflects.
#[inline]
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Refraction> {
    // Compute cos θ_i and sin² θ_t = η² (1 − cos² θ_i).
    let cos_i = (-d.dot(n)).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(Refraction {
        dir: d * eta + n * (eta * cos_i - cos_t),
        cos_i,
        cos_t,
    })
}

/// The exact unpolarised Fresnel reflectance of a dielectric interface, `(r_s² + r_p²) / 2`, from
/// the cosines of the incident and transmitted angles and the relative index `eta = n_from / n_to`.
/// Clamped to [0, 1]; a non-finite value (grazing incidence at a vanishing denominator) is 1.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    // r_s and r_p with n_from = eta, n_to = 1 (only the ratio matters).
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let f = 0.5 * (rs * rs + rp * rp);
    if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflection_keeps_the_tangent_and_flips_the_normal_part() {
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        let r = reflect(d, Vec3::Y);
        let want = Vec3::new(1.0, 1.0, 0.0).normalize();
        assert!(
            (r - want).length() < 1e-6,
            "expected {want}, got {r}, tol 1e-6"
        );
    }

    #[test]
    fn refraction_obeys_snell_and_total_internal_reflection() {
        // 30° incidence from air into glass (n = 1.5): sin θ_t = sin 30° / 1.5.
        let th = 30f32.to_radians();
        let d = Vec3::new(th.sin(), -th.cos(), 0.0);
        let t = refract(d, Vec3::Y, 1.0 / 1.5).expect("no TIR entering glass");
        let sin_t = t.dir.x / t.dir.length();
        assert!((sin_t - th.sin() / 1.5).abs() < 1e-6, "sin θ_t {sin_t}");
        assert!((t.dir.length() - 1.0).abs() < 1e-6);
        // Leaving glass beyond the critical angle asin(1/1.5) ≈ 41.8°: none.
        let th = 45f32.to_radians();
        let d = Vec3::new(th.sin(), -th.cos(), 0.0);
        assert!(refract(d, Vec3::Y, 1.5).is_none());
        // Just below the critical angle: a grazing transmitted ray.
        let th = 41.0f32.to_radians();
        let d = Vec3::new(th.sin(), -th.cos(), 0.0);
        assert!(refract(d, Vec3::Y, 1.5).is_some());
    }

    #[test]
    fn fresnel_matches_known_values() {
        // Normal incidence air -> glass (n = 1.5): ((1 - 1.5)/(1 + 1.5))² = 0.04.
        let f = fresnel_dielectric(1.0, 1.0, 1.0 / 1.5);
        assert!((f - 0.04).abs() < 1e-6, "expected 0.04, got {f}, tol 1e-6");
        // Brewster's angle: r_p = 0, so F = r_s²/2; at tan θ = 1.5.
        let th = 1.5f32.atan();
        let (ci, si) = (th.cos(), th.sin());
        let st = si / 1.5;
        let ct = (1.0 - st * st).sqrt();
        let rs = (ci - 1.5 * ct) / (ci + 1.5 * ct);
        let f = fresnel_dielectric(ci, ct, 1.0 / 1.5);
        assert!(
            (f - 0.5 * rs * rs).abs() < 1e-6,
            "expected {}, got {f}, tol 1e-6",
            0.5 * rs * rs
        );
    }
}
