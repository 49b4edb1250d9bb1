//! The rotation that best superposes two point sets, by Horn's closed form (B. K. P. Horn,
//! "Closed-form solution of absolute orientation using unit quaternions", J. Opt. Soc. Am. A 4
//! (1987) 629): the unit quaternion that is the eigenvector of the largest eigenvalue of a
//! symmetric 4x4 matrix built from the sets' correlation matrix, found by Jacobi rotations in
//! f64. It is always a proper rotation, never a reflection. [`crate::orientation`] fits lattice
//! templates with it; trajectory alignment (md-scene) superposes frames with it.
//!
//! ```
//! use texmap_md_io::rotation::best_rotation;
//! // Points x and their images y = R x, R a quarter turn about z.
//! let x = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
//! let y: Vec<[f64; 3]> = x.iter().map(|p| [-p[1], p[0], p[2]]).collect();
//! let mut s = [[0.0; 3]; 3];
//! for (p, q) in x.iter().zip(&y) {
//!     for a in 0..3 {
//!         for b in 0..3 {
//!             s[a][b] += p[a] * q[b];
//!         }
//!     }
//! }
//! let (sum, [w, qx, qy, qz]) = best_rotation(s);
//! assert!((sum - 14.0).abs() < 1e-12); // Σ y·(R x) = Σ |x|²
//! let half = std::f64::consts::FRAC_PI_4;
//! assert!((w.abs() - half.cos()).abs() < 1e-12 && (qz.abs() - half.sin()).abs() < 1e-12);
//! assert!(qx.abs() < 1e-12 && qy.abs() < 1e-12 && w * qz > 0.0);
//! ```

/// For the correlation matrix `s[a][b] = Σ x_a y_b` of point pairs (x, y), the rotation R
/// maximising Σ y·(R x) as a unit quaternion `[w, x, y, z]`, and that maximum (the largest
/// eigenvalue of Horn's matrix).
pub fn best_rotation(s: [[f64; 3]; 3]) -> (f64, [f64; 4]) {
    let [[sxx, sxy, sxz], [syx, syy, syz], [szx, szy, szz]] = s;
    let n = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let (values, vectors) = jacobi4(n);
    let best = (0..4)
        .max_by(|&a, &b| values[a].total_cmp(&values[b]))
        .unwrap_or(0);
    let q = [0, 1, 2, 3].map(|k| vectors[k][best]);
    let len = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    (values[best], q.map(|v| v / len))
}

/// Eigenvalues and eigenvectors (columns of the returned matrix) of a symmetric 4x4 matrix by
/// cyclic Jacobi rotations.
fn jacobi4(mut a: [[f64; 4]; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let scale: f64 = a
        .iter()
        .flatten()
        .map(|x| x.abs())
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    for _sweep in 0..64 {
        let off: f64 = (0..4)
            .flat_map(|i| (0..4).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off.sqrt() <= 1e-15 * scale {
            break;
        }
        for p in 0..3 {
            for q in p + 1..4 {
                if a[p][q].abs() <= f64::MIN_POSITIVE {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (rp, rq) = (a[p], a[q]);
                for k in 0..4 {
                    a[p][k] = c * rp[k] - s * rq[k];
                    a[q][k] = s * rp[k] + c * rq[k];
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2], a[3][3]], v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_diagonalises() {
        let m = [
            [4.0, 1.0, 0.5, 0.0],
            [1.0, 3.0, 0.2, 0.1],
            [0.5, 0.2, -1.0, 0.7],
            [0.0, 0.1, 0.7, 2.0],
        ];
        let (values, vectors) = jacobi4(m);
        for j in 0..4 {
            for r in 0..4 {
                let mv: f64 = (0..4).map(|c| m[r][c] * vectors[c][j]).sum();
                assert!((mv - values[j] * vectors[r][j]).abs() < 1e-12);
            }
        }
    }
}
