//! The size and shape of a group of atoms: the radius of gyration (MDAnalysis's
//! `radius_of_gyration`, `gmx gyrate`), the radii about the x, y and z axes through the centre
//! (`gmx gyrate`'s Rg(x), Rg(y), Rg(z)), and the relative shape anisotropy of the gyration
//! tensor (MDAnalysis's `asphericity`: 0 for a sphere, 1/4 for a disc, 1 for a rod), each
//! weighted by mass or not.
//!
//! With d the displacement from the (weighted) centre and w the weights summing to W: Rg² =
//! Σ w |d|² / W; about x, Σ w (d_y² + d_z²) / W; the gyration tensor S = Σ w d dᵀ / W, and the
//! anisotropy κ² = 3/2 · Σ (λ − λ̄)² / (Σ λ)² over its eigenvalues, which is 3/2 · tr(S²) /
//! tr(S)² − 1/2 without solving for them. The atoms are taken where they are: a molecule the
//! trajectory wrapped across the cell must be made whole first (`--pbc unwrap`).
//!
//! ```
//! use texmap_md_io::shape::gyration;
//! // Two equal masses 2 Å apart: Rg = 1 Å, a rod.
//! let g = gyration(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[1.0, 1.0]).unwrap();
//! assert!((g.rg - 1.0).abs() < 1e-12 && g.about[0].abs() < 1e-12);
//! assert!((g.about[1] - 1.0).abs() < 1e-12 && (g.asphericity - 1.0).abs() < 1e-12);
//! ```

/// [`gyration`]'s result (Å, except the anisotropy).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gyration {
    /// The radius of gyration.
    pub rg: f64,
    /// The radii of gyration about the x, y and z axes through the centre.
    pub about: [f64; 3],
    /// The relative shape anisotropy κ², from 0 (spherical) to 1 (a line).
    pub asphericity: f64,
}

/// The size and shape of `positions` weighted by `weights` (masses, or ones); `None` when there
/// are no atoms, a weight is not finite and ≥ 0, the weights sum to 0, or a position is not
/// finite.
pub fn gyration(positions: &[[f32; 3]], weights: &[f64]) -> Option<Gyration> {
    if positions.is_empty()
        || positions.len() != weights.len()
        || weights.iter().any(|w| !(w.is_finite() && *w >= 0.0))
        || positions.iter().flatten().any(|x| !x.is_finite())
    {
        return None;
    }
    let total: f64 = weights.iter().sum();
    if total <= 0.0 {
        return None;
    }
    let mut centre = [0.0f64; 3];
    for (p, w) in positions.iter().zip(weights) {
        for k in 0..3 {
            centre[k] += w * f64::from(p[k]);
        }
    }
    let centre = centre.map(|c| c / total);
    // The weighted second moments, S = Σ w d dᵀ / W.
    let mut s = [[0.0f64; 3]; 3];
    for (p, w) in positions.iter().zip(weights) {
        let d: [f64; 3] = std::array::from_fn(|k| f64::from(p[k]) - centre[k]);
        for a in 0..3 {
            for b in 0..3 {
                s[a][b] += w * d[a] * d[b];
            }
        }
    }
    let s = s.map(|row| row.map(|v| v / total));
    let trace = s[0][0] + s[1][1] + s[2][2];
    let square: f64 = (0..3)
        .flat_map(|a| (0..3).map(move |b| (a, b)))
        .map(|(a, b)| s[a][b] * s[b][a])
        .sum();
    Some(Gyration {
        rg: trace.sqrt(),
        about: std::array::from_fn(|a| (trace - s[a][a]).max(0.0).sqrt()),
        asphericity: if trace > 0.0 {
            1.5 * square / (trace * trace) - 0.5
        } else {
            0.0
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_of_points_is_isotropic_and_a_square_a_disc() {
        // The 8 corners of a cube of side 2: Rg² = 3, about any axis 2, no anisotropy.
        let cube: Vec<[f32; 3]> = (0..8)
            .map(|k| [0, 1, 2].map(|a| if k >> a & 1 == 1 { 1.0 } else { -1.0 }))
            .collect();
        let g = gyration(&cube, &[2.5; 8]).unwrap();
        assert!((g.rg - 3f64.sqrt()).abs() < 1e-12);
        assert!(g.about.iter().all(|r| (r - 2f64.sqrt()).abs() < 1e-12));
        assert!(g.asphericity.abs() < 1e-12);
        // A square's four corners: a disc, κ² = 1/4.
        let square = [
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [-1.0, -1.0, 0.0],
        ];
        let g = gyration(&square, &[1.0; 4]).unwrap();
        assert!((g.asphericity - 0.25).abs() < 1e-12, "{}", g.asphericity);
        // Weights move the centre: a heavy atom at the origin and a light one 4 Å away.
        let g = gyration(&[[0.0; 3], [4.0, 0.0, 0.0]], &[3.0, 1.0]).unwrap();
        // Centre at x = 1: Rg² = (3·1 + 1·9) / 4 = 3.
        assert!((g.rg - 3f64.sqrt()).abs() < 1e-12);
        assert!(gyration(&[], &[]).is_none());
        assert!(gyration(&[[0.0; 3]], &[0.0]).is_none());
        assert!(gyration(&[[f32::NAN; 3]], &[1.0]).is_none());
    }
}
