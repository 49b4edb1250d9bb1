//! Robust ray–primitive intersection: analytic spheres, capped cylinders and a watertight
//! triangle test.
//!
//! These functions are the leaf tests of the BVH traversal in [`crate::Scene`]; they are pure, take
//! the ray as origin + direction (any non-zero length) and an open parameter interval
//! `(tmin, tmax)`, and return `None` rather than a non-finite `t`.
//!
//! # References
//! - M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th ed., §6.2 (sphere) and
//!   §6.8.1: the discriminant `b² − 4ac` is computed as `4a (r + |v|)(r − |v|)` with `v` the vector
//!   from the sphere centre to the point of the ray line closest to it, which avoids the
//!   catastrophic cancellation of the textbook formula for small, distant spheres.
//! - S. Woop, C. Benthin, I. Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013: shear
//!   the triangle into a ray-aligned frame, evaluate the three 2D edge functions, and fall back to
//!   f64 when an edge function is exactly zero, so that a ray through a shared edge or vertex hits
//!   at least one of the triangles sharing it.
//!
//! Departure from the paper: the triangle test divides `T / det` once instead of using the
//! sign-bit trick, since the reference values clarity over the last few percent.

use glam::{DVec2, Vec3};

/// Per-ray constants of the watertight triangle test (Woop et al. 2013, §3): the axis permutation
/// that makes the ray's dominant axis `z`, and the shear that maps the ray to `+z`.
#[derive(Clone, Copy, Debug)]
pub struct RayPre {
    pub origin: Vec3,
    pub dir: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl RayPre {
    /// Precompute the shear for a ray. `dir` must be finite and non-zero (checked by the callers).
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> RayPre {
        debug_assert!(dir.is_finite() && dir != Vec3::ZERO);
        // Choose the dominant axis as kz, keep the winding with kx, ky.
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        // Compute the shear constants.
        let sz = 1.0 / dir[kz];
        RayPre {
            origin,
            dir,
            kx,
            ky,
            kz,
            sx: dir[kx] * sz,
            sy: dir[ky] * sz,
            sz,
        }
    }
}

/// A triangle hit: parameter and barycentric weights of vertices 1 and 2
/// (`p = (1 − b1 − b2)·v0 + b1·v1 + b2·v2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Watertight ray/triangle test (Woop, Benthin, Wald 2013). Two-sided. Returns the hit with
/// `tmin < t < tmax`, or `None`. Degenerate triangles (`det == 0`) never hit.
#[inline]
pub fn intersect_triangle(
    r: &RayPre,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
    tmin: f32,
    tmax: f32,
) -> Option<TriHit> {
    // Translate the vertices to the ray origin.
    let a = v0 - r.origin;
    let b = v1 - r.origin;
    let c = v2 - r.origin;
    // Shear and scale the vertices (Woop et al. Eq. 4–6).
    let ax = a[r.kx] - r.sx * a[r.kz];
    let ay = a[r.ky] - r.sy * a[r.kz];
    let bx = b[r.kx] - r.sx * b[r.kz];
    let by = b[r.ky] - r.sy * b[r.kz];
    let cx = c[r.kx] - r.sx * c[r.kz];
    let cy = c[r.ky] - r.sy * c[r.kz];
    // Compute the scaled barycentric coordinates (2D edge functions).
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    // Fall back to double precision at exactly zero, where f32 rounding decides the edge.
    if u == 0.0 || v == 0.0 || w == 0.0 {
        let (a2, b2, c2) = (
            DVec2::new(ax as f64, ay as f64),
            DVec2::new(bx as f64, by as f64),
            DVec2::new(cx as f64, cy as f64),
        );
        u = (c2.x * b2.y - c2.y * b2.x) as f32;
        v = (a2.x * c2.y - a2.y * c2.x) as f32;
        w = (b2.x * a2.y - b2.y * a2.x) as f32;
    }
    // Edge test: all three of the same sign (zero counts as either).
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    // Determinant; zero means the ray is in the triangle's plane or the triangle is degenerate.
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // Scaled hit distance and the interval test.
    let az = r.sz * a[r.kz];
    let bz = r.sz * b[r.kz];
    let cz = r.sz * c[r.kz];
    let t_scaled = u * az + v * bz + w * cz;
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    if !(t > tmin && t < tmax) {
        return None;
    }
    Some(TriHit {
        t,
        b1: v * inv,
        b2: w * inv,
    })
}

/// Nearest ray/sphere intersection with `tmin < t < tmax`, pbrt-style (see module docs).
/// `dir` need not be unit length. Returns `None` for a miss (never a non-finite `t`).
#[inline]
pub fn intersect_sphere(
    origin: Vec3,
    dir: Vec3,
    center: Vec3,
    radius: f32,
    tmin: f32,
    tmax: f32,
) -> Option<f32> {
    // Quadratic coefficients of |o + t d − c|² = r².
    let f = origin - center;
    let a = dir.length_squared();
    let b = 2.0 * dir.dot(f);
    let c = f.length_squared() - radius * radius;
    // Compute sphere discriminant b² − 4ac = 4a (r + |v|)(r − |v|), v = f − (b / 2a) d.
    let v = f - dir * (b / (2.0 * a));
    // Reject before the square root when the line passes outside the sphere (a NaN `vv`
    // passes here and is caught by the discriminant test below).
    let vv = v.length_squared();
    if vv > radius * radius {
        return None;
    }
    let len = vv.sqrt();
    let disc = 4.0 * a * (radius + len) * (radius - len);
    // A negative (or NaN) discriminant misses.
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    // Compute the roots with the cancellation-free form q = −(b + sign(b)√disc)/2.
    let root = disc.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let (mut t0, mut t1) = (q / a, c / q);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    // Keep the nearest root inside the interval (NaN fails both tests).
    if t0 > tmin && t0 < tmax {
        Some(t0)
    } else if t1 > tmin && t1 < tmax {
        Some(t1)
    } else {
        None
    }
}

/// Which part of a capped cylinder was hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CylinderPart {
    /// The curved side.
    Side,
    /// The disc at the first end point `a` (outward normal `−axis`).
    CapA,
    /// The disc at the second end point `b` (outward normal `+axis`).
    CapB,
}

/// A capped cylinder hit: parameter, part and outward unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylHit {
    pub t: f32,
    pub part: CylinderPart,
    pub normal: Vec3,
}

/// Nearest intersection of a ray with the solid capped cylinder from `a` to `b` of radius `r`,
/// with `tmin < t < tmax`. The caller guarantees `a != b`, `r > 0`, all finite.
///
/// The side uses the sphere's robust discriminant in the plane perpendicular to the axis
/// (`v` is the perpendicular offset of the ray line's closest approach to the axis); the caps are
/// ray/plane tests followed by a disc test.
#[inline]
pub fn intersect_cylinder(
    origin: Vec3,
    dir: Vec3,
    a: Vec3,
    b: Vec3,
    r: f32,
    tmin: f32,
    tmax: f32,
) -> Option<CylHit> {
    let axis = b - a;
    let len = axis.length();
    let u = axis / len;
    // Split origin offset and direction into axial and perpendicular parts.
    let f = origin - a;
    let fu = f.dot(u);
    let du = dir.dot(u);
    let fp = f - u * fu;
    let dp = dir - u * du;
    let mut best: Option<CylHit> = None;
    let mut best_t = tmax;
    // Side: |fp + t dp|² = r², robust discriminant as for the sphere.
    let qa = dp.length_squared();
    if qa > 0.0 {
        let qb = 2.0 * dp.dot(fp);
        let qc = fp.length_squared() - r * r;
        let v = fp - dp * (qb / (2.0 * qa));
        let vl = v.length();
        let disc = 4.0 * qa * (r + vl) * (r - vl);
        if disc >= 0.0 {
            let root = disc.sqrt();
            let q = if qb < 0.0 {
                -0.5 * (qb - root)
            } else {
                -0.5 * (qb + root)
            };
            let (mut t0, mut t1) = (q / qa, qc / q);
            if t0 > t1 {
                std::mem::swap(&mut t0, &mut t1);
            }
            for t in [t0, t1] {
                if t > tmin && t < best_t {
                    let h = fu + t * du;
                    if (0.0..=len).contains(&h) {
                        let radial = fp + dp * t;
                        let n = radial.normalize_or_zero();
                        if n != Vec3::ZERO {
                            best_t = t;
                            best = Some(CylHit {
                                t,
                                part: CylinderPart::Side,
                                normal: n,
                            });
                            break;
                        }
                    }
                }
            }
        }
    }
    // Caps: planes h = 0 and h = len, disc |radial| <= r.
    if du != 0.0 {
        for (h, part, n) in [(0.0, CylinderPart::CapA, -u), (len, CylinderPart::CapB, u)] {
            let t = (h - fu) / du;
            if t > tmin && t < best_t {
                let radial = fp + dp * t;
                if radial.length_squared() <= r * r {
                    best_t = t;
                    best = Some(CylHit { t, part, normal: n });
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Tiny deterministic RNG (PCG-like LCG) for property tests.
    struct Lcg(u64);
    impl Lcg {
        fn next_f32(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32) / (1u64 << 24) as f32
        }
        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next_f32()
        }
        fn vec(&mut self, lo: f32, hi: f32) -> Vec3 {
            Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
        }
    }

    /// f64 reference: nearest sphere root in (tmin, inf) by the textbook formula in f64.
    fn sphere_f64(o: Vec3, d: Vec3, c: Vec3, r: f32) -> Option<f64> {
        let (o, d, c, r) = (o.as_dvec3(), d.as_dvec3(), c.as_dvec3(), r as f64);
        let f = o - c;
        let a = d.dot(d);
        let b = 2.0 * d.dot(f);
        let cc = f.dot(f) - r * r;
        let disc = b * b - 4.0 * a * cc;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        let t0 = (-b - s) / (2.0 * a);
        let t1 = (-b + s) / (2.0 * a);
        if t0 > 0.0 {
            Some(t0)
        } else if t1 > 0.0 {
            Some(t1)
        } else {
            None
        }
    }

    #[test]
    fn sphere_matches_f64_for_small_distant_spheres() {
        // Spheres of radius 0.3 up to 1000 units away: the naive f32 discriminant loses all its
        // bits here; the robust one must agree with f64 to a few ulp of t.
        let mut rng = Lcg(7);
        let mut hits = 0;
        for _ in 0..20_000 {
            let c = rng.vec(-1000.0, 1000.0);
            let r = rng.range(0.05, 0.5);
            let o = Vec3::ZERO;
            // Aim near the sphere: within ~1.2 r of its centre.
            let target = c + rng.vec(-1.2, 1.2) * r;
            let d = (target - o).normalize();
            let got = intersect_sphere(o, d, c, r, 0.0, f32::INFINITY);
            let want = sphere_f64(o, d, c, r);
            match (got, want) {
                (Some(t), Some(tw)) => {
                    hits += 1;
                    let tol = 1e-5 * tw.max(1.0);
                    assert!(
                        ((t as f64) - tw).abs() <= tol,
                        "c={c} r={r}: expected t={tw}, got {t}, tolerance {tol}"
                    );
                }
                (None, None) => {}
                (g, w) => {
                    // Disagreement is allowed only for grazing rays (closest approach ≈ r).
                    let cd = c.as_dvec3();
                    let dd = d.as_dvec3();
                    let dist = (cd - dd * cd.dot(dd)).length();
                    // f32 resolves the closest approach to a few ulp of the distance.
                    let off = (dist - r as f64).abs();
                    let tol = 1e-6 * (cd.length() + 1.0);
                    assert!(
                        off < tol,
                        "non-grazing disagreement: got {g:?}, expected {w:?}, |dist-r| = {off}, tolerance {tol}"
                    );
                }
            }
        }
        assert!(
            hits > 10_000,
            "only {hits} hits: test does not exercise hits"
        );
    }

    #[test]
    fn sphere_from_inside_returns_far_root_and_never_nan() {
        let t = intersect_sphere(Vec3::ZERO, Vec3::X, Vec3::ZERO, 2.0, 0.0, f32::INFINITY);
        assert_eq!(t, Some(2.0));
        // Tangent ray, zero radius: no NaN, just a miss or a boundary hit.
        let t = intersect_sphere(
            Vec3::new(0.0, 1.0, -5.0),
            Vec3::Z,
            Vec3::ZERO,
            1.0,
            0.0,
            f32::INFINITY,
        );
        assert!(t.is_none_or(|t| t.is_finite()), "{t:?}");
        let t = intersect_sphere(Vec3::ZERO, Vec3::Z, Vec3::ZERO, 0.0, 0.0, f32::INFINITY);
        assert!(t.is_none_or(|t| t.is_finite()), "{t:?}");
    }

    /// Brute-force f64 reference for the capped cylinder: sample the nearest hit by testing the
    /// side quadratic and both caps in f64.
    fn cylinder_f64(o: Vec3, d: Vec3, a: Vec3, b: Vec3, r: f32) -> Option<(f64, CylinderPart)> {
        let (o, d, a, b, r) = (
            o.as_dvec3(),
            d.as_dvec3(),
            a.as_dvec3(),
            b.as_dvec3(),
            r as f64,
        );
        let len = (b - a).length();
        let u = (b - a) / len;
        let mut best: Option<(f64, CylinderPart)> = None;
        let mut consider = |t: f64, p: CylinderPart| {
            if t > 0.0 && best.is_none_or(|(bt, _)| t < bt) {
                best = Some((t, p));
            }
        };
        let perp = |v: DVec3| v - u * v.dot(u);
        let (fp, dp) = (perp(o - a), perp(d));
        let qa = dp.dot(dp);
        let qb = 2.0 * dp.dot(fp);
        let qc = fp.dot(fp) - r * r;
        let disc = qb * qb - 4.0 * qa * qc;
        if qa > 0.0 && disc >= 0.0 {
            for t in [
                (-qb - disc.sqrt()) / (2.0 * qa),
                (-qb + disc.sqrt()) / (2.0 * qa),
            ] {
                let h = (o + d * t - a).dot(u);
                if (0.0..=len).contains(&h) {
                    consider(t, CylinderPart::Side);
                }
            }
        }
        for (h, p) in [(0.0, CylinderPart::CapA), (len, CylinderPart::CapB)] {
            let du = d.dot(u);
            if du != 0.0 {
                let t = (h - (o - a).dot(u)) / du;
                if perp(o + d * t - a).length() <= r {
                    consider(t, p);
                }
            }
        }
        best
    }

    #[test]
    fn capped_cylinder_matches_f64_reference() {
        let mut rng = Lcg(11);
        let mut parts = [0usize; 3];
        for _ in 0..20_000 {
            let a = rng.vec(-2.0, 2.0);
            let b = rng.vec(-2.0, 2.0);
            if (b - a).length() < 0.2 {
                continue;
            }
            let r = rng.range(0.1, 0.8);
            let o = rng.vec(-10.0, 10.0);
            let target = (a + b) * 0.5 + rng.vec(-1.5, 1.5);
            let d = (target - o).normalize();
            if (o - (a + b) * 0.5).length() < 3.0 {
                continue;
            }
            let got = intersect_cylinder(o, d, a, b, r, 0.0, f32::INFINITY);
            let want = cylinder_f64(o, d, a, b, r);
            match (got, want) {
                (Some(h), Some((tw, pw))) => {
                    let tol = 1e-4 * tw.max(1.0);
                    assert!(
                        ((h.t as f64) - tw).abs() <= tol,
                        "expected t={tw} ({pw:?}), got {} ({:?}), tolerance {tol}",
                        h.t,
                        h.part
                    );
                    if (h.t as f64 - tw).abs() < 1e-6 * tw {
                        // Same parameter: the part must agree unless on a rim.
                        let p = o + d * h.t;
                        let hh = (p - a).dot((b - a).normalize());
                        let on_rim = hh.abs() < 1e-3 || (hh - (b - a).length()).abs() < 1e-3;
                        assert!(on_rim || h.part == pw, "part {:?} vs {pw:?}", h.part);
                    }
                    parts[h.part as usize] += 1;
                    // The normal is unit and points out of the solid.
                    assert!((h.normal.length() - 1.0).abs() < 1e-5);
                    assert!(h.normal.dot(d) <= 1e-4, "normal faces the incoming ray");
                }
                (None, None) => {}
                (g, w) => {
                    // Only grazing rays may disagree: the f64 nearest is on a silhouette.
                    let t = w.map(|x| x.0).unwrap_or_else(|| g.unwrap().t as f64);
                    let p = o.as_dvec3() + d.as_dvec3() * t;
                    let u = (b - a).normalize().as_dvec3();
                    let v = p - a.as_dvec3();
                    let radial = (v - u * v.dot(u)).length();
                    let h = v.dot(u);
                    let len = (b - a).length() as f64;
                    let near_edge = (radial - r as f64).abs() < 1e-3
                        || h.abs() < 1e-3
                        || (h - len).abs() < 1e-3;
                    assert!(near_edge, "got {g:?}, expected {w:?}");
                }
            }
        }
        assert!(
            parts.iter().all(|&n| n > 100),
            "every part must be reached: side/capA/capB = {parts:?}"
        );
    }

    #[test]
    fn triangle_hit_matches_barycentric_f64() {
        let mut rng = Lcg(3);
        let mut hits = 0;
        for _ in 0..10_000 {
            let v0 = rng.vec(-1.0, 1.0);
            let v1 = rng.vec(-1.0, 1.0);
            let v2 = rng.vec(-1.0, 1.0);
            let o = rng.vec(-5.0, 5.0) + Vec3::new(0.0, 0.0, 6.0);
            // Aim at a random barycentric point (some outside the triangle).
            let (p, q) = (rng.range(-0.2, 1.0), rng.range(-0.2, 1.0));
            let target = v0 + (v1 - v0) * p + (v2 - v0) * q;
            let d = (target - o).normalize();
            let pre = RayPre::new(o, d);
            let got = intersect_triangle(&pre, v0, v1, v2, 0.0, f32::INFINITY);
            let inside = p >= 0.0 && q >= 0.0 && p + q <= 1.0;
            let margin = p.min(q).min(1.0 - p - q).abs();
            if margin < 1e-3 {
                continue;
            }
            // f64 reference: the f32 ray (o, d) against the triangle's plane.
            let (od, dd) = (o.as_dvec3(), d.as_dvec3());
            let (a, e1, e2) = (v0.as_dvec3(), (v1 - v0).as_dvec3(), (v2 - v0).as_dvec3());
            let n = e1.cross(e2);
            let cos = n.normalize().dot(dd).abs();
            if cos < 0.05 {
                continue; // grazing: t is ill-conditioned in any precision
            }
            let tw = n.dot(a - od) / n.dot(dd);
            let pp = od + dd * tw - a;
            let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let den = d00 * d11 - d01 * d01;
            let bw1 = (d11 * pp.dot(e1) - d01 * pp.dot(e2)) / den;
            let bw2 = (d00 * pp.dot(e2) - d01 * pp.dot(e1)) / den;
            assert_eq!(got.is_some(), inside, "p={p} q={q}");
            if let Some(h) = got {
                hits += 1;
                let tol = 1e-5 * tw.max(1.0) / cos;
                assert!(
                    ((h.t as f64) - tw).abs() < tol,
                    "expected t={tw}, got {}, tolerance {tol}",
                    h.t
                );
                let btol = 1e-4 / cos;
                assert!(
                    (h.b1 as f64 - bw1).abs() < btol && (h.b2 as f64 - bw2).abs() < btol,
                    "expected bary ({bw1}, {bw2}), got {h:?}, tolerance {btol}"
                );
            }
        }
        assert!(hits > 1000);
    }

    #[test]
    fn ray_through_shared_edge_and_vertex_hits_at_least_one_triangle() {
        // A fan of triangles around the origin in the z = 0 plane; rays straight down through the
        // exact shared vertex and along shared edges must hit.
        let ring: Vec<Vec3> = (0..7)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / 7.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let dirs = [
            Vec3::NEG_Z,
            Vec3::new(0.3, 0.1, -1.0).normalize(),
            Vec3::new(-0.7, 0.2, -0.1).normalize(),
        ];
        for d in dirs {
            for s in [0.0f32, 0.25, 0.5, 0.9] {
                for k in 0..7 {
                    let target = ring[k] * s;
                    let o = target - d * 3.0;
                    let pre = RayPre::new(o, d);
                    let n = (0..7)
                        .filter(|&j| {
                            intersect_triangle(
                                &pre,
                                Vec3::ZERO,
                                ring[j],
                                ring[(j + 1) % 7],
                                0.0,
                                f32::INFINITY,
                            )
                            .is_some()
                        })
                        .count();
                    assert!(n >= 1, "pinhole at {target} dir {d}");
                }
            }
        }
    }

    /// Textbook Möller–Trumbore in f32, NOT watertight: only here to show that the pinhole test
    /// below can fail.
    fn moller_trumbore(o: Vec3, d: Vec3, v0: Vec3, v1: Vec3, v2: Vec3) -> bool {
        let (e1, e2) = (v1 - v0, v2 - v0);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 {
            return false;
        }
        let inv = 1.0 / det;
        let s = o - v0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return false;
        }
        let q = s.cross(e1);
        let v = d.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return false;
        }
        e2.dot(q) * inv > 0.0
    }

    #[test]
    fn shared_edges_leak_with_moller_trumbore_but_not_with_the_watertight_test() {
        // A 24x24-vertex heightfield with irregular heights and irregular x/z spacing; rays aimed
        // exactly at vertices and edge midpoints from several directions, tested against every
        // triangle (brute force). Surface slopes (< 0.4) are below every ray's slope (> 1.2), so
        // the surface projects one-to-one along each ray: no tangent rays, every ray must hit.
        let n = 24usize;
        let mut rng = Lcg(99);
        let xs: Vec<f32> = (0..n)
            .map(|i| i as f32 * 0.37 + rng.range(0.0, 0.2))
            .collect();
        let zs: Vec<f32> = (0..n)
            .map(|j| j as f32 * 0.41 + rng.range(0.0, 0.2))
            .collect();
        let mut pos = Vec::new();
        for &z in &zs {
            for &x in &xs {
                pos.push(Vec3::new(x, rng.range(-0.05, 0.05), z));
            }
        }
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                tris.push([pos[a], pos[a + n], pos[a + 1]]);
                tris.push([pos[a + 1], pos[a + n], pos[a + n + 1]]);
            }
        }
        let (mut ours, mut mt, mut rays) = (0, 0, 0);
        for dir in [
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.31, -0.9, 0.17).normalize(),
            Vec3::new(-0.2, -0.7, 0.55).normalize(),
        ] {
            for j in 1..n - 1 {
                for i in 1..n - 1 {
                    let k = j * n + i;
                    for target in [
                        pos[k],
                        (pos[k] + pos[k + 1]) * 0.5,
                        (pos[k] + pos[k + n]) * 0.5,
                        (pos[k] + pos[k + n + 1]) * 0.5,
                    ] {
                        let o = target - dir * 2.0;
                        let pre = RayPre::new(o, dir);
                        rays += 1;
                        if !tris.iter().any(|t| {
                            intersect_triangle(&pre, t[0], t[1], t[2], 0.0, f32::INFINITY).is_some()
                        }) {
                            ours += 1;
                        }
                        if !tris
                            .iter()
                            .any(|t| moller_trumbore(o, dir, t[0], t[1], t[2]))
                        {
                            mt += 1;
                        }
                    }
                }
            }
        }
        assert_eq!(ours, 0, "watertight test leaked {ours} of {rays} rays");
        assert!(
            mt > 0,
            "Möller–Trumbore leaked none of {rays}: the test does not discriminate"
        );
    }
}
