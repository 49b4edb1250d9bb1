//! The RMSD between every pair of frames after their optimal superposition: the matrix that
//! MDAnalysis's `diffusionmap.DistanceMatrix`, `gmx rms -m` and cpptraj's `2drms` compute, whose
//! blocks show a trajectory's conformational states and the transitions between them.
//!
//! Each frame's atoms are centred on their centroid once; a pair's RMSD is then
//! `√((|A|² + |B|² − 2 λ) / N)` with `λ` the largest eigenvalue of Horn's quaternion matrix of
//! the pair's correlation ([`crate::rotation::best_rotation`]): unweighted, no rotation
//! applied, as MDAnalysis's `rms.rmsd(a, b, center=True, superposition=True)`. The pairs above
//! the diagonal are shared between the threads by rows, each computed alone (the matrix is the
//! same for any thread count), and mirrored below it.
//!
//! ```
//! use texmap_md_io::rmsd::rmsd_matrix;
//! // A triangle, the same triangle turned and moved, and one stretched along x.
//! let a = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
//! let b: Vec<[f32; 3]> = a.iter().map(|p| [5.0 - p[1], p[0], 1.0]).collect();
//! let c: Vec<[f32; 3]> = a.iter().map(|p| [2.0 * p[0], p[1], p[2]]).collect();
//! let m = rmsd_matrix(&[a, b, c], usize::MAX).unwrap();
//! assert!(m[1].abs() < 1e-6); // a and b superpose exactly
//! assert!(m[2] > 0.1 && m[2] == m[6]); // a and c do not; the matrix is symmetric
//! ```

use rayon::prelude::*;

use crate::msd::MsdError;

/// The pairwise RMSD (Å) of `frames` (each the same atoms in the same order), row-major
/// `F x F` with a zero diagonal. `limit` bounds the bytes of the matrix and the centred
/// frames (`8 F² + 24 F N`): past it, [`MsdError::Matrix`].
pub fn rmsd_matrix(frames: &[Vec<[f32; 3]>], limit: usize) -> Result<Vec<f64>, MsdError> {
    let f = frames.len();
    let n = frames.first().map_or(0, Vec::len);
    for p in frames {
        crate::msd::check_frame(p, Some(n))?;
    }
    let bytes = matrix_bytes(f, n);
    if bytes > limit {
        return Err(MsdError::Matrix {
            frames: f,
            bytes,
            limit,
        });
    }
    let centred: Vec<Vec<[f64; 3]>> = frames.iter().map(|p| centre(p)).collect();
    let norms: Vec<f64> = centred
        .iter()
        .map(|p| {
            p.iter()
                .map(|q| q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
                .sum()
        })
        .collect();
    // The pairs above the diagonal, then their mirror images.
    let mut m = vec![0.0; f * f];
    m.par_chunks_mut(f.max(1)).enumerate().for_each(|(i, row)| {
        for (j, out) in row.iter_mut().enumerate().skip(i + 1) {
            *out = pair(&centred[i], &centred[j], norms[i] + norms[j]);
        }
    });
    for i in 0..f {
        for j in 0..i {
            m[i * f + j] = m[j * f + i];
        }
    }
    Ok(m)
}

/// The bytes [`rmsd_matrix`] takes for `frames` frames of `atoms` atoms: the matrix and the
/// centred frames (`8 F² + 24 F N`), so that a caller keeping the frames can stop at its limit
/// before it has read them all.
pub fn matrix_bytes(frames: usize, atoms: usize) -> usize {
    frames
        .saturating_mul(frames)
        .saturating_mul(8)
        .saturating_add(frames.saturating_mul(atoms).saturating_mul(24))
}

/// The positions moved so that their centroid is the origin.
fn centre(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    let n = p.len().max(1) as f64;
    let mut c = [0.0f64; 3];
    for q in p {
        for a in 0..3 {
            c[a] += f64::from(q[a]);
        }
    }
    let c = c.map(|v| v / n);
    p.iter()
        .map(|q| std::array::from_fn(|a| f64::from(q[a]) - c[a]))
        .collect()
}

/// The superposed RMSD of two centred sets whose squared norms sum to `norms`.
fn pair(a: &[[f64; 3]], b: &[[f64; 3]], norms: f64) -> f64 {
    if a.is_empty() {
        return 0.0;
    }
    let mut s = [[0.0f64; 3]; 3];
    for (p, q) in a.iter().zip(b) {
        for (r, row) in s.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v += p[r] * q[c];
            }
        }
    }
    let (lambda, _) = crate::rotation::best_rotation(s);
    ((norms - 2.0 * lambda).max(0.0) / a.len() as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rigid_motions_cost_nothing_and_a_stretch_its_exact_rmsd() {
        // A helix-like chain of 30 atoms.
        let base: Vec<[f32; 3]> = (0..30)
            .map(|i| {
                let t = i as f32 * 1.745;
                [2.3 * t.cos(), 2.3 * t.sin(), 1.5 * i as f32]
            })
            .collect();
        // Turned 70° about a tilted axis and moved.
        let (s, c) = 70f32.to_radians().sin_cos();
        let turned: Vec<[f32; 3]> = base
            .iter()
            .map(|p| {
                [
                    c * p[0] - s * p[2] + 4.0,
                    p[1] - 2.0,
                    s * p[0] + c * p[2] + 9.0,
                ]
            })
            .collect();
        // Every atom displaced by ±0.5 Å along a fixed direction, alternately, about the
        // centroid: an RMSD of at most 0.5 Å (the superposition can only lower it).
        let wobbled: Vec<[f32; 3]> = base
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let d = if i % 2 == 0 { 0.5 } else { -0.5 };
                [p[0] + d * 0.6, p[1] + d * 0.8, p[2]]
            })
            .collect();
        let m = rmsd_matrix(&[base, turned, wobbled], usize::MAX).unwrap();
        assert!(m[1] < 1e-5, "{}", m[1]);
        assert!(m[2] > 0.45 && m[2] <= 0.5 + 1e-6, "{}", m[2]);
        assert!(
            (m[2] - m[5]).abs() < 1e-5,
            "the same after the rigid motion"
        );
        for i in 0..3 {
            assert_eq!(m[4 * i], 0.0);
            for j in 0..3 {
                assert_eq!(m[3 * i + j], m[3 * j + i]);
            }
        }
    }

    #[test]
    fn bad_input_is_refused() {
        let a = vec![[0.0f32; 3]; 4];
        let b = vec![[0.0f32; 3]; 5];
        assert!(matches!(
            rmsd_matrix(&[a.clone(), b], usize::MAX),
            Err(MsdError::AtomCount { first: 4, frame: 5 })
        ));
        let mut c = a.clone();
        c[2][1] = f32::INFINITY;
        assert!(matches!(
            rmsd_matrix(&[a.clone(), c], usize::MAX),
            Err(MsdError::NotFinite(2))
        ));
        let frames = vec![a; 100];
        assert!(matches!(
            rmsd_matrix(&frames, 80_000),
            Err(MsdError::Matrix { frames: 100, .. })
        ));
        assert!(rmsd_matrix(&[], usize::MAX).unwrap().is_empty());
    }
}
