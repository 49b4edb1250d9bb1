//! Solid angles of spherical caps and of their intersection: the exact visible fraction of a disc
//! light behind a spherical occluder, against which the soft shadows of texmap-quality and of the
//! reference ray tracer are tested.
//!
//! A cap of angular radius `a` is the set of unit directions within `a` of its centre; its solid
//! angle is `2π (1 − cos a)`. Two caps whose centres are `g` apart intersect in a lens whose solid
//! angle is given in closed form by Tovchigrechko and Vakser (2001, Eq. 3). A disc light of
//! angular radius `ρ` seen past a sphere of angular radius `σ` whose centre is `g` from the
//! light's is `1 − cap_intersection(ρ, σ, g) / cap(ρ)` visible.
//!
//! # References
//! - A. Tovchigrechko, I. A. Vakser, "How common is the funnel-like energy landscape in
//!   protein-protein interactions?", *Protein Science* 10 (2001), Eq. 3.

use std::f64::consts::PI;

/// Solid angle (steradians) of a cap of angular radius `a` (radians, `0 ≤ a ≤ π`).
pub fn cap(a: f64) -> f64 {
    2.0 * PI * (1.0 - a.cos())
}

/// Solid angle (steradians) of the intersection of two caps of angular radii `a` and `b` whose
/// centres are `g` apart (radians, all in `[0, π]`).
pub fn cap_intersection(a: f64, b: f64, g: f64) -> f64 {
    if g >= a + b {
        return 0.0;
    }
    if g <= (a - b).abs() {
        return cap(a.min(b));
    }
    let (ca, cb, cg) = (a.cos(), b.cos(), g.cos());
    let (sa, sb, sg) = (a.sin(), b.sin(), g.sin());
    let clamp = |x: f64| x.clamp(-1.0, 1.0);
    2.0 * (PI
        - clamp((cg - ca * cb) / (sa * sb)).acos()
        - clamp((cb - cg * ca) / (sg * sa)).acos() * ca
        - clamp((ca - cg * cb) / (sg * sb)).acos() * cb)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The intersection by counting a deterministic, area-uniform grid of directions over the
    /// first cap (Fibonacci points on its sphere zone).
    fn counted(a: f64, b: f64, g: f64, n: usize) -> f64 {
        let golden = PI * (3.0 - 5f64.sqrt());
        let (zmin, centre_b) = (a.cos(), [g.sin(), 0.0, g.cos()]);
        let mut inside = 0usize;
        for i in 0..n {
            // z uniform in [cos a, 1] is uniform in solid angle over the cap around +z.
            let z = 1.0 - (1.0 - zmin) * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            let d = [r * phi.cos(), r * phi.sin(), z];
            let dot = d[0] * centre_b[0] + d[1] * centre_b[1] + d[2] * centre_b[2];
            inside += (dot >= b.cos()) as usize;
        }
        cap(a) * inside as f64 / n as f64
    }

    #[test]
    fn the_closed_form_matches_counting_directions() {
        for (a, b, g) in [
            (0.2, 0.3, 0.25),
            (0.5, 0.5, 0.9),
            (0.1, 0.8, 0.75),
            (1.2, 0.4, 1.0),
            (0.3, 0.3, 0.05),
        ] {
            let want = counted(a, b, g, 400_000);
            let got = cap_intersection(a, b, g);
            assert!(
                (got - want).abs() <= 2e-3 * cap(a.min(b)),
                "a {a} b {b} g {g}: {got} vs counted {want}"
            );
            // Symmetric in the two caps.
            assert!((cap_intersection(b, a, g) - got).abs() < 1e-12);
        }
    }

    #[test]
    fn disjoint_and_nested_caps() {
        assert_eq!(cap_intersection(0.2, 0.3, 0.6), 0.0);
        assert_eq!(cap_intersection(0.2, 0.9, 0.1), cap(0.2));
        assert!((cap(PI) - 4.0 * PI).abs() < 1e-12);
        assert!((cap(PI / 2.0) - 2.0 * PI).abs() < 1e-12);
    }
}
