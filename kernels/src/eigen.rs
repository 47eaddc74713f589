//! The eigen-decomposition of a dense symmetric matrix, in plain `f64` arithmetic with no
//! run-time dispatch: Householder reduction to tridiagonal form, then the implicit QL
//! iteration (`tred2` and `tql2` of EISPACK, as in JAMA's public-domain port). Every operation
//! runs in a fixed order, so the bits depend only on the input. For the small problems of the
//! project (the KDE's covariance, Rayleigh-Ritz steps and dense problems up to a few hundred
//! rows).

/// Eigenvalues, increasing, and orthonormal eigenvectors (column `j` of the row-major `n x n`
/// `vectors` belongs to `values[j]`).
#[derive(Clone, Debug)]
pub struct SymmetricEigen {
    pub values: Vec<f64>,
    pub vectors: Vec<f64>,
    pub n: usize,
}

/// The QL iteration did not converge, or the input is not finite.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EigenError {
    #[error("the symmetric eigen-solver got a non-finite entry")]
    NotFinite,
    #[error("the symmetric eigen-solver did not converge for eigenvalue {0} of {1}")]
    NoConvergence(usize, usize),
    #[error("a symmetric matrix of {n} rows needs {} entries, got {len}", n * n)]
    Shape { n: usize, len: usize },
}

impl SymmetricEigen {
    /// The decomposition of the symmetric `n x n` matrix `a` (row-major; only the lower
    /// triangle is read).
    pub fn new(a: &[f64], n: usize) -> Result<SymmetricEigen, EigenError> {
        if a.len() != n * n {
            return Err(EigenError::Shape { n, len: a.len() });
        }
        if a.iter().any(|x| !x.is_finite()) {
            return Err(EigenError::NotFinite);
        }
        let mut v = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                v[i * n + j] = a[i * n + j];
                v[j * n + i] = a[i * n + j];
            }
        }
        let mut d = vec![0.0; n];
        let mut e = vec![0.0; n];
        if n > 0 {
            tred2(&mut v, &mut d, &mut e, n);
            tql2(&mut v, &mut d, &mut e, n)?;
        }
        Ok(SymmetricEigen {
            values: d,
            vectors: v,
            n,
        })
    }

    /// Entry `i` of eigenvector `j`.
    pub fn vector(&self, i: usize, j: usize) -> f64 {
        self.vectors[i * self.n + j]
    }
}

/// Householder tridiagonalisation (JAMA `tred2`): `v` becomes the accumulated transformation,
/// `d` the diagonal and `e` the sub-diagonal (in `e[1..]`).
fn tred2(v: &mut [f64], d: &mut [f64], e: &mut [f64], n: usize) {
    let at = |i: usize, j: usize| i * n + j;
    for j in 0..n {
        d[j] = v[at(n - 1, j)];
    }
    for i in (1..n).rev() {
        let mut scale = 0.0;
        let mut h = 0.0;
        for k in 0..i {
            scale += d[k].abs();
        }
        if scale == 0.0 {
            e[i] = d[i - 1];
            for j in 0..i {
                d[j] = v[at(i - 1, j)];
                v[at(i, j)] = 0.0;
                v[at(j, i)] = 0.0;
            }
        } else {
            for k in 0..i {
                d[k] /= scale;
                h += d[k] * d[k];
            }
            let mut f = d[i - 1];
            let mut g = h.sqrt();
            if f > 0.0 {
                g = -g;
            }
            e[i] = scale * g;
            h -= f * g;
            d[i - 1] = f - g;
            for j in 0..i {
                e[j] = 0.0;
            }
            for j in 0..i {
                f = d[j];
                v[at(j, i)] = f;
                g = e[j] + v[at(j, j)] * f;
                for k in j + 1..i {
                    g += v[at(k, j)] * d[k];
                    e[k] += v[at(k, j)] * f;
                }
                e[j] = g;
            }
            f = 0.0;
            for j in 0..i {
                e[j] /= h;
                f += e[j] * d[j];
            }
            let hh = f / (h + h);
            for j in 0..i {
                e[j] -= hh * d[j];
            }
            for j in 0..i {
                f = d[j];
                g = e[j];
                for k in j..i {
                    v[at(k, j)] -= f * e[k] + g * d[k];
                }
                d[j] = v[at(i - 1, j)];
                v[at(i, j)] = 0.0;
            }
        }
        d[i] = h;
    }
    // Accumulate the transformations.
    for i in 0..n - 1 {
        v[at(n - 1, i)] = v[at(i, i)];
        v[at(i, i)] = 1.0;
        let h = d[i + 1];
        if h != 0.0 {
            for k in 0..=i {
                d[k] = v[at(k, i + 1)] / h;
            }
            for j in 0..=i {
                let mut g = 0.0;
                for k in 0..=i {
                    g += v[at(k, i + 1)] * v[at(k, j)];
                }
                for k in 0..=i {
                    v[at(k, j)] -= g * d[k];
                }
            }
        }
        for k in 0..=i {
            v[at(k, i + 1)] = 0.0;
        }
    }
    for j in 0..n {
        d[j] = v[at(n - 1, j)];
        v[at(n - 1, j)] = 0.0;
    }
    v[at(n - 1, n - 1)] = 1.0;
    e[0] = 0.0;
}

/// Implicit QL on the tridiagonal form (JAMA `tql2`), eigenvalues sorted increasing with
/// their vectors.
fn tql2(v: &mut [f64], d: &mut [f64], e: &mut [f64], n: usize) -> Result<(), EigenError> {
    let at = |i: usize, j: usize| i * n + j;
    for i in 1..n {
        e[i - 1] = e[i];
    }
    e[n - 1] = 0.0;
    let mut f = 0.0;
    let mut tst1: f64 = 0.0;
    let eps = f64::EPSILON;
    for l in 0..n {
        tst1 = tst1.max(d[l].abs() + e[l].abs());
        let mut m = l;
        while m < n {
            if e[m].abs() <= eps * tst1 {
                break;
            }
            m += 1;
        }
        let m = m.min(n - 1);
        if m > l {
            let mut iter = 0;
            loop {
                iter += 1;
                if iter > 60 {
                    return Err(EigenError::NoConvergence(l, n));
                }
                let mut g = d[l];
                let mut p = (d[l + 1] - g) / (2.0 * e[l]);
                let mut r = libm::hypot(p, 1.0);
                if p < 0.0 {
                    r = -r;
                }
                d[l] = e[l] / (p + r);
                d[l + 1] = e[l] * (p + r);
                let dl1 = d[l + 1];
                let mut h = g - d[l];
                for i in l + 2..n {
                    d[i] -= h;
                }
                f += h;
                p = d[m];
                let mut c = 1.0;
                let mut c2 = c;
                let mut c3 = c;
                let el1 = e[l + 1];
                let mut s = 0.0;
                let mut s2 = 0.0;
                for i in (l..m).rev() {
                    c3 = c2;
                    c2 = c;
                    s2 = s;
                    g = c * e[i];
                    h = c * p;
                    r = libm::hypot(p, e[i]);
                    e[i + 1] = s * r;
                    s = e[i] / r;
                    c = p / r;
                    p = c * d[i] - s * g;
                    d[i + 1] = h + s * (c * g + s * d[i]);
                    for k in 0..n {
                        h = v[at(k, i + 1)];
                        v[at(k, i + 1)] = s * v[at(k, i)] + c * h;
                        v[at(k, i)] = c * v[at(k, i)] - s * h;
                    }
                }
                p = -s * s2 * c3 * el1 * e[l] / dl1;
                e[l] = s * p;
                d[l] = c * p;
                if e[l].abs() <= eps * tst1 {
                    break;
                }
            }
        }
        d[l] += f;
        e[l] = 0.0;
    }
    // Sort increasing (selection sort: stable in the sense of a fixed order).
    for i in 0..n.saturating_sub(1) {
        let mut k = i;
        let mut p = d[i];
        for j in i + 1..n {
            if d[j] < p {
                k = j;
                p = d[j];
            }
        }
        if k != i {
            d[k] = d[i];
            d[i] = p;
            for j in 0..n {
                v.swap(at(j, i), at(j, k));
            }
        }
    }
    Ok(())
}

/// Solve `A x = b` for a symmetric positive-definite `n x n` `A` (row-major, lower triangle
/// read) by Cholesky, for `cols` right-hand sides (`b` row-major `n x cols`, overwritten by
/// `x`). `None` if `A` is not positive definite.
pub fn cholesky_solve(a: &[f64], n: usize, b: &mut [f64], cols: usize) -> Option<()> {
    assert_eq!(a.len(), n * n, "cholesky_solve: A is not {n}x{n}");
    assert_eq!(b.len(), n * cols, "cholesky_solve: B is not {n}x{cols}");
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            if i == j {
                if s.is_nan() || s <= 0.0 {
                    return None;
                }
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    for c in 0..cols {
        // L y = b, then L^T x = y.
        for i in 0..n {
            let mut s = b[i * cols + c];
            for k in 0..i {
                s -= l[i * n + k] * b[k * cols + c];
            }
            b[i * cols + c] = s / l[i * n + i];
        }
        for i in (0..n).rev() {
            let mut s = b[i * cols + c];
            for k in i + 1..n {
                s -= l[k * n + i] * b[k * cols + c];
            }
            b[i * cols + c] = s / l[i * n + i];
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_symmetric(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let x = next();
                a[i * n + j] = x;
                a[j * n + i] = x;
            }
        }
        a
    }

    #[test]
    fn decomposition_reconstructs_and_is_orthonormal() {
        for n in [1, 2, 3, 10, 57, 130] {
            let a = random_symmetric(n, n as u64);
            let e = SymmetricEigen::new(&a, n).unwrap();
            assert!(e.values.windows(2).all(|w| w[0] <= w[1]), "increasing");
            let scale = e.values.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1.0);
            for i in 0..n {
                for j in 0..n {
                    let r: f64 = (0..n)
                        .map(|k| e.vector(i, k) * e.values[k] * e.vector(j, k))
                        .sum();
                    assert!((r - a[i * n + j]).abs() < 1e-11 * scale, "n={n} A[{i},{j}]");
                    let g: f64 = (0..n).map(|k| e.vector(k, i) * e.vector(k, j)).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((g - want).abs() < 1e-11, "n={n} V^T V [{i},{j}]");
                }
            }
        }
    }

    #[test]
    fn known_spectrum_and_repeated_eigenvalues() {
        // [[2, 1], [1, 2]] has eigenvalues 1 and 3 (the upper triangle, 99, is not read); the
        // identity's repeated 1s need no iteration.
        let a = [2.0, 99.0, 1.0, 2.0];
        let e = SymmetricEigen::new(&a, 2).unwrap();
        assert!((e.values[0] - 1.0).abs() < 1e-15 && (e.values[1] - 3.0).abs() < 1e-15);
        let id = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let e = SymmetricEigen::new(&id, 3).unwrap();
        assert!(
            e.values.iter().all(|v| (v - 1.0).abs() < 1e-15),
            "{:?}",
            e.values
        );
        assert_eq!(
            SymmetricEigen::new(&[f64::NAN], 1).unwrap_err(),
            EigenError::NotFinite
        );
    }

    #[test]
    fn cholesky_solves_and_refuses_indefinite_matrices() {
        let a = [4.0, 2.0, 2.0, 3.0];
        let mut b = [2.0, 1.0, 1.0, 2.0]; // two right-hand sides, row-major 2 x 2
        cholesky_solve(&a, 2, &mut b, 2).unwrap();
        // A x = b column by column.
        for c in 0..2 {
            let (x0, x1) = (b[c], b[2 + c]);
            let want = [[2.0, 1.0], [1.0, 2.0]];
            assert!((4.0 * x0 + 2.0 * x1 - want[0][c]).abs() < 1e-14);
            assert!((2.0 * x0 + 3.0 * x1 - want[1][c]).abs() < 1e-14);
        }
        assert!(cholesky_solve(&[1.0, 2.0, 2.0, 1.0], 2, &mut [0.0; 2], 1).is_none());
    }
}
