//! Eigenvalues and eigenvectors of a real symmetric matrix, for the principal component
//! analysis (`pca`): Householder reduction to a tridiagonal matrix, then the implicit QL
//! iteration with Wilkinson's shift (Golub & Van Loan, §8.3), the method of LAPACK's `dsteqr`.
//!
//! The matrix is a dense `n x n` row-major `f64` slice. The reduction applies each reflector
//! `H = I − β v vᵀ` to the trailing block as one rank-2 update (`A − v wᵀ − w vᵀ`, rows
//! contiguous); the eigenvectors are kept as rows (`Qᵀ`, then rotated two rows at a time by
//! the QL sweeps), so every inner loop runs along memory. Cost ~ (4/3 + 1 + 3) n³ flops:
//! about 1 s for n = 900 (300 atoms), one thread.

/// The eigenpairs of a symmetric matrix: values in decreasing order, `vectors[k]` (a row of
/// `n`) the unit eigenvector of `values[k]`, its largest-magnitude entry positive (the sign
/// of an eigenvector is otherwise arbitrary).
#[derive(Clone, Debug)]
pub(crate) struct Eigen {
    pub values: Vec<f64>,
    pub vectors: Vec<f64>,
    pub n: usize,
}

impl Eigen {
    /// Eigenvector `k` (of the `k`-th largest value).
    pub fn vector(&self, k: usize) -> &[f64] {
        &self.vectors[k * self.n..(k + 1) * self.n]
    }
}

/// The QL iteration did not converge (it does in a few sweeps per eigenvalue for any finite
/// symmetric matrix; this guards against NaN input).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct NoConvergence;

/// The eigenpairs of the symmetric `n x n` matrix `a` (row-major; only its lower triangle is
/// read). `a` is overwritten.
pub(crate) fn symmetric(mut a: Vec<f64>, n: usize) -> Result<Eigen, NoConvergence> {
    assert_eq!(a.len(), n * n);
    if n == 0 {
        return Ok(Eigen {
            values: Vec::new(),
            vectors: Vec::new(),
            n,
        });
    }
    // Mirror the lower triangle so that rows can be read whole.
    for i in 0..n {
        for j in 0..i {
            a[j * n + i] = a[i * n + j];
        }
    }
    let (mut d, mut e, mut z) = tridiagonalise(&mut a, n);
    drop(a);
    ql(&mut d, &mut e, &mut z, n)?;
    // Decreasing order, vectors with them.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| d[j].total_cmp(&d[i]).then(i.cmp(&j)));
    let mut vectors = Vec::with_capacity(n * n);
    for &k in &order {
        let row = &mut z[k * n..(k + 1) * n];
        let big = row
            .iter()
            .enumerate()
            .fold((0usize, 0.0f64), |(bi, bv), (i, v)| {
                if v.abs() > bv { (i, v.abs()) } else { (bi, bv) }
            })
            .0;
        let sign = if row[big] < 0.0 { -1.0 } else { 1.0 };
        vectors.extend(row.iter().map(|v| v * sign));
    }
    Ok(Eigen {
        values: order.iter().map(|&k| d[k]).collect(),
        vectors,
        n,
    })
}

/// Householder reduction of the full symmetric `a` to tridiagonal form `T = Qᵀ A Q`: the
/// diagonal, the off-diagonal (`e[i]` between `i` and `i + 1`, `e[n − 1] = 0`) and `Qᵀ`
/// (row-major).
fn tridiagonalise(a: &mut [f64], n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut d = vec![0.0; n];
    let mut e = vec![0.0; n];
    // The reflectors: v_k (entries k+1..n) in row k of `refl`, and β_k.
    let mut refl = vec![0.0; n * n];
    let mut beta = vec![0.0; n];
    let mut p = vec![0.0; n];
    for k in 0..n.saturating_sub(2) {
        d[k] = a[k * n + k];
        let m = k + 1;
        let x = &a[k * n + m..k * n + n];
        let scale = x.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        if scale == 0.0 {
            e[k] = 0.0;
            continue;
        }
        let norm = scale * x.iter().map(|v| (v / scale).powi(2)).sum::<f64>().sqrt();
        let alpha = if x[0] > 0.0 { -norm } else { norm };
        let v = &mut refl[k * n + m..k * n + n];
        v.copy_from_slice(x);
        v[0] -= alpha;
        let vv: f64 = v.iter().map(|t| t * t).sum();
        e[k] = alpha;
        if vv == 0.0 {
            continue;
        }
        let b = 2.0 / vv;
        beta[k] = b;
        // p = β B v over the trailing block B = a[m.., m..]; K = β/2 pᵀv; w = p − K v.
        let v = &refl[k * n + m..k * n + n];
        let w = &mut p[m..n];
        for (i, wi) in w.iter_mut().enumerate() {
            let row = &a[(m + i) * n + m..(m + i) * n + n];
            *wi = b * row.iter().zip(v).map(|(r, t)| r * t).sum::<f64>();
        }
        let kk = 0.5 * b * w.iter().zip(v).map(|(s, t)| s * t).sum::<f64>();
        for (wi, t) in w.iter_mut().zip(v) {
            *wi -= kk * t;
        }
        // B ← B − v wᵀ − w vᵀ.
        for i in 0..n - m {
            let (vi, wi) = (v[i], w[i]);
            let row = &mut a[(m + i) * n + m..(m + i) * n + n];
            for ((r, vj), wj) in row.iter_mut().zip(v).zip(w.iter()) {
                *r -= vi * wj + wi * vj;
            }
        }
    }
    if n >= 2 {
        d[n - 2] = a[(n - 2) * n + n - 2];
        e[n - 2] = a[(n - 2) * n + n - 1];
    }
    d[n - 1] = a[(n - 1) * n + n - 1];
    // Qᵀ = H_{n−3} ⋯ H_1 H_0, built from the left end: M = I, then M ← M H_k for k from
    // n − 3 down to 0. Before H_k is applied M = H_{n−3} ⋯ H_{k+1} is the identity outside
    // its trailing block of rows and columns k+1.., where v_k lives, so the update
    // M ← M − β (M v) vᵀ touches that block only.
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        q[i * n + i] = 1.0;
    }
    for k in (0..n.saturating_sub(2)).rev() {
        if beta[k] == 0.0 {
            continue;
        }
        let m = k + 1;
        let v = &refl[k * n + m..k * n + n];
        for r in m..n {
            let row = &mut q[r * n + m..r * n + n];
            let t = beta[k] * row.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
            for (x, y) in row.iter_mut().zip(v) {
                *x -= t * y;
            }
        }
    }
    (d, e, q)
}

/// Implicit QL with Wilkinson's shift on the tridiagonal (`d`, `e`), rotating the rows of `z`.
fn ql(d: &mut [f64], e: &mut [f64], z: &mut [f64], n: usize) -> Result<(), NoConvergence> {
    for l in 0..n {
        let mut sweeps = 0;
        loop {
            // The first negligible off-diagonal at or after l splits the matrix.
            let mut m = l;
            while m + 1 < n {
                let dd = d[m].abs() + d[m + 1].abs();
                if e[m].abs() <= f64::EPSILON * dd {
                    break;
                }
                m += 1;
            }
            if m == l {
                break;
            }
            sweeps += 1;
            if sweeps > 60 || !e[l].is_finite() {
                return Err(NoConvergence);
            }
            // Wilkinson's shift from the leading 2x2 block.
            let g = (d[l + 1] - d[l]) / (2.0 * e[l]);
            let r = g.hypot(1.0);
            let mut g = d[m] - d[l] + e[l] / (g + r.copysign(g));
            let (mut s, mut c, mut p) = (1.0f64, 1.0f64, 0.0f64);
            let mut deflated = false;
            let mut i = m;
            while i > l {
                i -= 1;
                let f = s * e[i];
                let b = c * e[i];
                let r = f.hypot(g);
                e[i + 1] = r;
                if r == 0.0 {
                    // Underflow: the block splits here; restart from l.
                    d[i + 1] -= p;
                    e[m] = 0.0;
                    deflated = true;
                    break;
                }
                s = f / r;
                c = g / r;
                let gg = d[i + 1] - p;
                let rr = (d[i] - gg) * s + 2.0 * c * b;
                p = s * rr;
                d[i + 1] = gg + p;
                g = c * rr - b;
                rotate(z, n, i, c, s);
            }
            if deflated {
                continue;
            }
            d[l] -= p;
            e[l] = g;
            e[m] = 0.0;
        }
    }
    Ok(())
}

/// Rows `i` and `i + 1` of `z` ← (c·zᵢ − s·zᵢ₊₁, s·zᵢ + c·zᵢ₊₁).
#[inline]
fn rotate(z: &mut [f64], n: usize, i: usize, c: f64, s: f64) {
    let (lo, hi) = z.split_at_mut((i + 1) * n);
    let a = &mut lo[i * n..];
    let b = &mut hi[..n];
    for (x, y) in a.iter_mut().zip(b.iter_mut()) {
        let (u, w) = (*x, *y);
        *x = c * u - s * w;
        *y = s * u + c * w;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic generator of numbers in [−1, 1).
    fn numbers(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// An orthogonal matrix (rows) by Gram–Schmidt on random rows.
    fn orthogonal(n: usize, seed: u64) -> Vec<f64> {
        let mut r = numbers(seed);
        let mut q: Vec<f64> = (0..n * n).map(|_| r()).collect();
        for i in 0..n {
            for j in 0..i {
                let dot: f64 = (0..n).map(|k| q[i * n + k] * q[j * n + k]).sum();
                for k in 0..n {
                    q[i * n + k] -= dot * q[j * n + k];
                }
            }
            let norm = (0..n).map(|k| q[i * n + k].powi(2)).sum::<f64>().sqrt();
            for k in 0..n {
                q[i * n + k] /= norm;
            }
        }
        q
    }

    /// A = Σ λ_k q_k q_kᵀ with the given λ: the eigenpairs are known exactly.
    fn built(q: &[f64], lambda: &[f64]) -> Vec<f64> {
        let n = lambda.len();
        let mut a = vec![0.0; n * n];
        for (k, l) in lambda.iter().enumerate() {
            for i in 0..n {
                for j in 0..n {
                    a[i * n + j] += l * q[k * n + i] * q[k * n + j];
                }
            }
        }
        a
    }

    #[test]
    fn recovers_known_eigenpairs() {
        for (n, seed) in [(1, 1), (2, 2), (3, 3), (7, 4), (40, 5), (150, 6)] {
            let q = orthogonal(n, seed);
            // Distinct values, some negative, in scrambled order.
            let lambda: Vec<f64> = (0..n)
                .map(|k| ((k * 37 % n) as f64 - n as f64 / 3.0) * 0.75 + 0.1)
                .collect();
            let eig = symmetric(built(&q, &lambda), n).unwrap();
            let mut want = lambda.clone();
            want.sort_by(|a, b| b.total_cmp(a));
            let scale = want.iter().fold(1.0f64, |s, v| s.max(v.abs()));
            for (got, want) in eig.values.iter().zip(&want) {
                assert!(
                    (got - want).abs() < 1e-12 * scale * n as f64,
                    "n {n}: {got} vs {want}"
                );
            }
            for (k, want_value) in want.iter().enumerate() {
                let src = lambda.iter().position(|l| l == want_value).unwrap();
                let dot: f64 = eig
                    .vector(k)
                    .iter()
                    .zip(&q[src * n..(src + 1) * n])
                    .map(|(a, b)| a * b)
                    .sum();
                assert!(
                    (dot.abs() - 1.0).abs() < 1e-10,
                    "n {n} vector {k}: |dot| {dot}"
                );
            }
        }
    }

    #[test]
    fn degenerate_and_diagonal_matrices() {
        // A diagonal matrix is its own decomposition; a repeated value gets an orthonormal
        // basis of its space.
        let n = 5;
        let mut a = vec![0.0; n * n];
        for (i, v) in [3.0, -1.0, 3.0, 0.0, 2.0].iter().enumerate() {
            a[i * n + i] = *v;
        }
        let eig = symmetric(a.clone(), n).unwrap();
        assert_eq!(eig.values, vec![3.0, 3.0, 2.0, 0.0, -1.0]);
        for i in 0..n {
            for j in 0..n {
                let dot: f64 = eig
                    .vector(i)
                    .iter()
                    .zip(eig.vector(j))
                    .map(|(x, y)| x * y)
                    .sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((dot - want).abs() < 1e-14);
            }
            // A v = λ v.
            for r in 0..n {
                let av: f64 = (0..n).map(|c| a[r * n + c] * eig.vector(i)[c]).sum();
                assert!((av - eig.values[i] * eig.vector(i)[r]).abs() < 1e-14);
            }
        }
        // The zero matrix and a rank-one matrix.
        let zero = symmetric(vec![0.0; 16], 4).unwrap();
        assert!(zero.values.iter().all(|v| *v == 0.0));
        let u = [1.0, 2.0, 2.0];
        let rank1: Vec<f64> = (0..9).map(|k| u[k / 3] * u[k % 3]).collect();
        let eig = symmetric(rank1, 3).unwrap();
        assert!((eig.values[0] - 9.0).abs() < 1e-13);
        assert!(eig.values[1].abs() < 1e-13 && eig.values[2].abs() < 1e-13);
        for (got, want) in eig.vector(0).iter().zip([1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0]) {
            assert!((got - want).abs() < 1e-14);
        }
    }

    #[test]
    fn not_finite_input_is_an_error_not_a_hang() {
        let mut a = vec![1.0, 0.5, 0.5, 2.0];
        a[2] = f64::NAN;
        assert_eq!(symmetric(a, 2).unwrap_err(), NoConvergence);
    }
}
