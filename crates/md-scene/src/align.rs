//! Least-squares superposition: the rotation and translation that bring one set of points
//! closest (in RMSD) to another, so that a trajectory's frames can be drawn with the protein
//! held still while it tumbles and diffuses (what MDAnalysis's `AlignTraj`, VMD's `measure fit`
//! and PyMOL's `intra_fit` do before a movie).
//!
//! The rotation is Horn's (1987) closed form ([`texmap_md_io::rotation`]): the unit quaternion
//! that is the eigenvector of the largest eigenvalue of a symmetric 4x4 matrix built from the two
//! sets' cross-covariance, found by Jacobi rotations in f64. It is always a proper rotation (never a reflection). The fit is
//! unweighted, as MDAnalysis's and VMD's defaults are, or weighted ([`superpose_weighted`],
//! e.g. by mass).
//!
//! ```
//! use texmap_md_scene::align::superpose;
//! let reference = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
//! // The same points turned 90 degrees about z and moved.
//! let mobile: Vec<[f64; 3]> =
//!     reference.iter().map(|p| [-p[1] + 5.0, p[0] - 1.0, p[2] + 2.0]).collect();
//! let fit = superpose(&mobile, &reference).unwrap();
//! assert!(fit.rmsd < 1e-9);
//! let back = fit.apply(mobile[2]);
//! assert!((0..3).all(|k| (back[k] - reference[2][k]).abs() < 1e-9));
//! ```

/// The fit of [`superpose`]: `apply(p) = rotation · (p − mobile_centre) + reference_centre`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Superposition {
    /// Row-major proper rotation matrix.
    pub rotation: [[f64; 3]; 3],
    /// Centroid of the mobile points.
    pub mobile_centre: [f64; 3],
    /// Centroid of the reference points.
    pub reference_centre: [f64; 3],
    /// RMSD (same unit as the points) between the fitted mobile points and the reference.
    pub rmsd: f64,
}

impl Superposition {
    /// The rotation applied to a direction (a velocity, a cell edge).
    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        [0, 1, 2].map(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
    }

    /// A point of the mobile set's frame moved onto the reference.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [0, 1, 2].map(|k| p[k] - self.mobile_centre[k]);
        let r = self.rotate(d);
        [0, 1, 2].map(|k| r[k] + self.reference_centre[k])
    }
}

/// The weighted centroid (`w(i)` the weight of point `i`; `total` their sum).
fn centroid(p: &[[f64; 3]], w: impl Fn(usize) -> f64, total: f64) -> [f64; 3] {
    let mut c = [0.0; 3];
    for (i, q) in p.iter().enumerate() {
        for k in 0..3 {
            c[k] += w(i) * q[k];
        }
    }
    c.map(|v| v / total)
}

/// The superposition of `mobile` onto `reference` (same length, point `i` to point `i`) that
/// minimises the RMSD; `None` when the lengths differ, fewer than three points are given, or a
/// coordinate is not finite. With fewer than three non-collinear points the rotation about
/// their line is arbitrary (but still a proper rotation).
pub fn superpose(mobile: &[[f64; 3]], reference: &[[f64; 3]]) -> Option<Superposition> {
    superpose_weighted(mobile, reference, None)
}

/// [`superpose`] with a weight per point (MDAnalysis's `weights="mass"` gives the masses):
/// weighted centroids, the rotation minimising the weighted sum of squared distances, and the
/// weighted RMSD `sqrt(sum w d² / sum w)`. `None` also when `weights` has another length, a
/// weight is negative or not finite, or they sum to 0.
pub fn superpose_weighted(
    mobile: &[[f64; 3]],
    reference: &[[f64; 3]],
    weights: Option<&[f64]>,
) -> Option<Superposition> {
    if mobile.len() != reference.len() || mobile.len() < 3 {
        return None;
    }
    let w = |i: usize| weights.map_or(1.0, |w| w[i]);
    let total = match weights {
        None => mobile.len() as f64,
        Some(ws) => {
            if ws.len() != mobile.len() || ws.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
                return None;
            }
            ws.iter().sum()
        }
    };
    if total <= 0.0 {
        return None;
    }
    if mobile
        .iter()
        .chain(reference)
        .flatten()
        .any(|v| !v.is_finite())
    {
        return None;
    }
    let (cm, cr) = (centroid(mobile, w, total), centroid(reference, w, total));
    // s[a][b] = sum over points of w x_a y_b (x mobile, y reference, both centred).
    let mut s = [[0.0f64; 3]; 3];
    for (i, (m, r)) in mobile.iter().zip(reference).enumerate() {
        let x = [0, 1, 2].map(|k| w(i) * (m[k] - cm[k]));
        let y = [0, 1, 2].map(|k| r[k] - cr[k]);
        for a in 0..3 {
            for b in 0..3 {
                s[a][b] += x[a] * y[b];
            }
        }
    }
    let (_, [q0, q1, q2, q3]) = texmap_md_io::rotation::best_rotation(s);
    let rotation = [
        [
            q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3,
            2.0 * (q1 * q2 - q0 * q3),
            2.0 * (q1 * q3 + q0 * q2),
        ],
        [
            2.0 * (q1 * q2 + q0 * q3),
            q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3,
            2.0 * (q2 * q3 - q0 * q1),
        ],
        [
            2.0 * (q1 * q3 - q0 * q2),
            2.0 * (q2 * q3 + q0 * q1),
            q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3,
        ],
    ];
    let mut fit = Superposition {
        rotation,
        mobile_centre: cm,
        reference_centre: cr,
        rmsd: 0.0,
    };
    // Measured on the moved points rather than from the eigenvalue (e0 - 2 lambda), which
    // cancels to noise for a near-perfect fit.
    let sum: f64 = mobile
        .iter()
        .zip(reference)
        .enumerate()
        .map(|(i, (m, r))| {
            let q = fit.apply(*m);
            w(i) * (0..3).map(|k| (q[k] - r[k]).powi(2)).sum::<f64>()
        })
        .sum();
    fit.rmsd = (sum / total).sqrt();
    Some(fit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotation from an axis and angle (Rodrigues).
    fn rotation(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
        let l = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let [x, y, z] = axis.map(|v| v / l);
        let (s, c) = angle.sin_cos();
        let t = 1.0 - c;
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    }

    fn points(n: usize) -> Vec<[f64; 3]> {
        // A deterministic irregular cloud.
        (0..n)
            .map(|i| {
                let f = i as f64;
                [
                    (f * 0.7).sin() * 9.0,
                    (f * 1.3).cos() * 5.0 + f * 0.1,
                    (f * 0.37).sin() * 7.0,
                ]
            })
            .collect()
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // matrix indices read as the maths writes them
    fn recovers_known_rotations_exactly_including_half_turns() {
        let reference = points(50);
        for (axis, angle) in [
            ([0.0, 0.0, 1.0], 0.3),
            ([1.0, 2.0, -0.5], 2.0),
            ([0.3, -1.0, 0.2], std::f64::consts::PI),
            ([1.0, 0.0, 0.0], 0.0),
        ] {
            let r = rotation(axis, angle);
            let shift = [3.0, -40.0, 12.5];
            let mobile: Vec<[f64; 3]> = reference
                .iter()
                .map(|p| {
                    [0, 1, 2].map(|i| r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + shift[i])
                })
                .collect();
            let fit = superpose(&mobile, &reference).unwrap();
            assert!(fit.rmsd < 1e-9, "{axis:?} {angle}: rmsd {}", fit.rmsd);
            for (m, p) in mobile.iter().zip(&reference) {
                let q = fit.apply(*m);
                for k in 0..3 {
                    assert!((q[k] - p[k]).abs() < 1e-9, "{axis:?} {angle}");
                }
            }
            // The fitted rotation is the inverse of the one applied: R_fit R = I.
            for i in 0..3 {
                for j in 0..3 {
                    let v: f64 = (0..3).map(|k| fit.rotation[i][k] * r[k][j]).sum();
                    assert!((v - (i == j) as u8 as f64).abs() < 1e-9);
                }
            }
        }
    }

    /// The RMSD of `mobile` moved by `fit` followed by the turn `t` about the reference centre.
    fn superpose_with(
        fit: &Superposition,
        t: [[f64; 3]; 3],
        mobile: &[[f64; 3]],
        reference: &[[f64; 3]],
    ) -> f64 {
        let c = fit.reference_centre;
        let sum: f64 = mobile
            .iter()
            .zip(reference)
            .map(|(m, r)| {
                let q = fit.apply(*m);
                let d = [0, 1, 2].map(|k| q[k] - c[k]);
                let q = [0, 1, 2].map(|i| t[i][0] * d[0] + t[i][1] * d[1] + t[i][2] * d[2] + c[i]);
                (0..3).map(|k| (q[k] - r[k]).powi(2)).sum::<f64>()
            })
            .sum();
        (sum / mobile.len() as f64).sqrt()
    }

    #[test]
    fn a_mirror_image_is_fitted_by_a_rotation_not_a_reflection() {
        let reference = points(30);
        let mirrored: Vec<[f64; 3]> = reference.iter().map(|p| [-p[0], p[1], p[2]]).collect();
        let fit = superpose(&mirrored, &reference).unwrap();
        let r = fit.rotation;
        let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        assert!((det - 1.0).abs() < 1e-9, "det {det}");
        assert!(fit.rmsd > 1.0);
        // No rotation does better: small turns about each axis only raise the RMSD.
        for axis in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] {
            for angle in [-0.01, 0.01] {
                let t = rotation(axis, angle);
                let worse = superpose_with(&fit, t, &mirrored, &reference);
                assert!(
                    worse > fit.rmsd,
                    "{axis:?} {angle}: {worse} <= {}",
                    fit.rmsd
                );
            }
        }
    }

    #[test]
    fn too_few_or_unequal_or_non_finite_points_are_refused() {
        let p = points(5);
        assert!(superpose(&p[..2], &p[..2]).is_none());
        assert!(superpose(&p[..4], &p[..3]).is_none());
        let mut q = p.clone();
        q[1][2] = f64::NAN;
        assert!(superpose(&q, &p).is_none());
    }
}
