//! The top eigenpairs of a symmetric matrix (the MDS step of Isomap): a full dense
//! decomposition up to 256 rows, else a restarted block Krylov iteration with Rayleigh-Ritz
//! extraction (random start from the fit's stream).

use super::*;

/// Below this size the eigenpairs come from a full dense decomposition.
pub(super) const DENSE_EIGEN_MAX: usize = 256;
/// Residual tolerance of the Ritz pairs, relative to the spectral norm estimate.
pub(super) const EIGEN_TOL: f64 = 1e-10;
/// Most Krylov blocks per restart cycle (convergence is checked after every block).
pub(super) const KRYLOV_STEPS: usize = 16;
/// Maximum restart cycles.
pub(super) const MAX_CYCLES: usize = 200;
/// Rows per block of the parallel symmetric product.
pub(super) const MUL_ROWS: usize = 256;

/// The `d` largest (algebraic) eigenvalues of the symmetric n x n matrix `a` (column-major; by
/// symmetry also row-major), decreasing, with orthonormal eigenvectors (n x d column-major).
pub(super) fn top_eigenpairs(
    a: &[f64],
    n: usize,
    d: usize,
    rng: &mut Stream,
) -> Result<(Vec<f64>, Vec<f64>), ReprError> {
    if n <= DENSE_EIGEN_MAX {
        return dense_top_eigenpairs(a, n, d);
    }
    let b = (d + d.max(8)).min(n);
    let cap = (b * KRYLOV_STEPS).min(n);
    let mut q = vec![0.0f64; n * cap];
    let mut aq = vec![0.0f64; n * cap];
    let mut x: Vec<f64> = (0..n * b).map(|_| rng.random_range(-1.0..1.0)).collect();
    let mut xcols = b;
    for _cycle in 0..MAX_CYCLES {
        // Grow the block Krylov basis Q (orthonormal) and AQ = A Q one block at a time, with a
        // Rayleigh-Ritz convergence check after every block from the second on.
        let mut m = 0;
        let mut steps = 0;
        let rr = loop {
            let kept = orthonormalise_into(&mut q, n, m, &mut x, xcols, cap - m);
            if kept > 0 {
                sym_mul(
                    a,
                    n,
                    &q[m * n..(m + kept) * n],
                    kept,
                    &mut aq[m * n..(m + kept) * n],
                );
                x.clear();
                x.extend_from_slice(&aq[m * n..(m + kept) * n]);
                xcols = kept;
                m += kept;
                steps += 1;
            }
            let exhausted = kept == 0 || m >= cap;
            if m > 0 && (exhausted || steps >= 2) {
                let rr = rayleigh_ritz(&q[..n * m], &aq[..n * m], n, m, b.min(m), d)?;
                if rr.converged || exhausted {
                    break rr;
                }
            }
            if m == 0 {
                return Err(ReprError::Numerical(
                    "isomap: the eigen-solver's start block vanished".into(),
                ));
            }
        };
        if rr.converged {
            let (mut th, mut y) = (rr.theta, rr.y);
            y.truncate(n * d);
            th.truncate(d);
            return Ok((th, y));
        }
        // Restart from the top Ritz vectors.
        x = rr.y;
        xcols = rr.theta.len();
    }
    Err(ReprError::Numerical(format!(
        "isomap: the block Krylov eigen-solver did not converge in {MAX_CYCLES} cycles (n = {n}, d = {d})"
    )))
}

/// Ritz pairs of a Rayleigh-Ritz step.
pub(super) struct Ritz {
    /// Top Ritz values, decreasing.
    pub(super) theta: Vec<f64>,
    /// Their Ritz vectors, n x keep column-major.
    pub(super) y: Vec<f64>,
    /// Whether the top d pairs have residual `<= EIGEN_TOL * |A|` (or the basis is complete).
    pub(super) converged: bool,
}

/// Rayleigh-Ritz on the orthonormal basis `q` (n x m) with `aq = A q`: the top `keep` Ritz
/// pairs and whether the top `d` have converged.
pub(super) fn rayleigh_ritz(
    q: &[f64],
    aq: &[f64],
    n: usize,
    m: usize,
    keep: usize,
    d: usize,
) -> Result<Ritz, ReprError> {
    let qm = MatRef::col_major(q, n, m);
    let aqm = MatRef::col_major(aq, n, m);
    let mut t = vec![0.0f64; m * m];
    matmul_cm(&mut t, qm.t(), aqm, false);
    for i in 0..m {
        for j in 0..i {
            let s = 0.5 * (t[i + j * m] + t[j + i * m]);
            t[i + j * m] = s;
            t[j + i * m] = s;
        }
    }
    let eig = SymmetricEigen::new(&t, m).map_err(|e| {
        ReprError::Numerical(format!("isomap: Rayleigh-Ritz eigen-solver failed: {e}"))
    })?;
    let all = &eig.values;
    // Top `keep` Ritz vectors, decreasing eigenvalue.
    let mut s = vec![0.0f64; m * keep];
    let mut theta = vec![0.0f64; keep];
    for c in 0..keep {
        let src = m - 1 - c;
        theta[c] = all[src];
        for r in 0..m {
            s[r + c * m] = eig.vector(r, src);
        }
    }
    let smat = MatRef::col_major(&s, m, keep);
    let mut y = vec![0.0f64; n * keep];
    let mut ay = vec![0.0f64; n * keep];
    matmul_cm(&mut y, qm, smat, false);
    matmul_cm(&mut ay, aqm, smat, false);
    let norm_est = all.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
    let converged = keep >= d
        && (m == n
            || (0..d).all(|c| {
                let r: f64 = (0..n)
                    .map(|i| (ay[i + c * n] - theta[c] * y[i + c * n]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                r <= EIGEN_TOL * norm_est
            }));
    Ok(Ritz {
        theta,
        y,
        converged,
    })
}

/// Full dense eigendecomposition (small n).
pub(super) fn dense_top_eigenpairs(
    a: &[f64],
    n: usize,
    d: usize,
) -> Result<(Vec<f64>, Vec<f64>), ReprError> {
    // `a` is symmetric, so its column-major slice is also the row-major one.
    let eig = SymmetricEigen::new(&a[..n * n], n)
        .map_err(|e| ReprError::Numerical(format!("isomap: eigen-solver failed: {e}")))?;
    let (s, mut vals) = (&eig.values, Vec::with_capacity(d));
    let mut vecs = vec![0.0; n * d];
    for c in 0..d {
        let src = n - 1 - c;
        vals.push(s[src]);
        for r in 0..n {
            vecs[r + c * n] = eig.vector(r, src);
        }
    }
    Ok((vals, vecs))
}

/// Orthogonalise the `xcols` columns of `x` (n rows, column-major) against the first `m`
/// columns of `q` (two passes of block classical Gram-Schmidt), orthonormalise them among
/// themselves (modified Gram-Schmidt, twice), dropping numerically dependent columns, and
/// append at most `room` of them to `q`. Returns the number appended.
pub(super) fn orthonormalise_into(
    q: &mut [f64],
    n: usize,
    m: usize,
    x: &mut [f64],
    xcols: usize,
    room: usize,
) -> usize {
    let x = &mut x[..n * xcols];
    let orig: Vec<f64> = (0..xcols).map(|c| norm(&x[c * n..(c + 1) * n])).collect();
    if m > 0 {
        let (qb, _) = q.split_at(n * m);
        let qm = MatRef::col_major(qb, n, m);
        let mut coef = vec![0.0f64; m * xcols];
        for _ in 0..2 {
            matmul_cm(&mut coef, qm.t(), MatRef::col_major(x, n, xcols), false);
            // x -= Q coef, as x + Q (-coef) (negation is exact).
            coef.iter_mut().for_each(|c| *c = -*c);
            matmul_cm(x, qm, MatRef::col_major(&coef, m, xcols), true);
        }
    }
    let mut kept = 0;
    for c in 0..xcols {
        if kept == room {
            break;
        }
        let dst = m + kept;
        let (done, rest) = q.split_at_mut(dst * n);
        let col = &mut x[c * n..(c + 1) * n];
        for _ in 0..2 {
            for p in m..dst {
                let qp = &done[p * n..(p + 1) * n];
                let h = dot(qp, col);
                for (v, &qv) in col.iter_mut().zip(qp) {
                    *v -= h * qv;
                }
            }
        }
        let nv = norm(col);
        // Dependent (or NaN) column: drop it.
        if nv.is_nan() || nv <= 1e-10 * orig[c] || nv == 0.0 {
            continue;
        }
        for (d, &v) in rest[..n].iter_mut().zip(col.iter()) {
            *d = v / nv;
        }
        kept += 1;
    }
    kept
}

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(super) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `y = A x` for the symmetric n x n `a` and x with `cols` columns (column-major), in
/// fixed-size row blocks (`A[rows, :] = A[:, rows]^T` by symmetry), each a sequential product.
pub(super) fn sym_mul(a: &[f64], n: usize, x: &[f64], cols: usize, y: &mut [f64]) {
    let xmat = MatRef::col_major(x, n, cols);
    let blocks: Vec<Vec<f64>> = (0..n.div_ceil(MUL_ROWS))
        .into_par_iter()
        .map(|bi| {
            let r0 = bi * MUL_ROWS;
            let rn = MUL_ROWS.min(n - r0);
            let mut out = vec![0.0f64; rn * cols];
            let ablk = MatRef::col_major(&a[r0 * n..(r0 + rn) * n], n, rn);
            matmul_cm(&mut out, ablk.t(), xmat, false);
            out
        })
        .collect();
    for (bi, blk) in blocks.iter().enumerate() {
        let r0 = bi * MUL_ROWS;
        let rn = blk.len() / cols;
        for c in 0..cols {
            y[c * n + r0..c * n + r0 + rn].copy_from_slice(&blk[c * rn..(c + 1) * rn]);
        }
    }
}

/// sklearn `svd_flip` (u-based): make the largest-|.| entry of each column positive (the first
/// such entry on ties).
pub(super) fn flip_signs(v: &mut [f64], n: usize, d: usize) {
    for c in 0..d {
        let col = &mut v[c * n..(c + 1) * n];
        let mut best = 0;
        for i in 1..n {
            if col[i].abs() > col[best].abs() {
                best = i;
            }
        }
        if col[best] < 0.0 {
            for x in col.iter_mut() {
                *x = -*x;
            }
        }
    }
}
