//! Disentanglement of a goal space against the scene's factors (the follow-up's premise: one
//! latent per degree of freedom of one object).
//!
//! * **MIG**, the mutual information gap (Chen et al., NeurIPS 2018, as `disentanglement_lib`
//!   computes it): latents and factors are discretised into equal-width bins over their range;
//!   for each factor, the gap between the two latents that share the most information with it,
//!   divided by the factor's entropy; averaged over the factors. 1: each factor is captured by
//!   one latent alone; 0: by none, or by two equally.
//! * **SAP**, the separated attribute predictability (Kumar et al., ICLR 2018): for each factor,
//!   the R² of a linear regression on each latent alone; the gap between the two best latents,
//!   averaged over the factors.
//!
//! Every sum runs in a fixed order and the logarithms come from `libm`, so a score is a function
//! of its inputs alone.

/// Why a score cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DisentanglementError {
    /// The arrays do not hold `n` rows of their width.
    #[error("{what}: {len} values are not {n} rows of {width}")]
    Shape {
        /// Latents or factors.
        what: &'static str,
        /// Values given.
        len: usize,
        /// Rows expected.
        n: usize,
        /// Columns.
        width: usize,
    },
    /// Fewer than two latents (no gap), no factor, or fewer than two rows.
    #[error(
        "disentanglement needs at least 2 latents, 1 factor and 2 samples (got {latents}, {factors}, {n})"
    )]
    TooSmall {
        /// Latents.
        latents: usize,
        /// Factors.
        factors: usize,
        /// Samples.
        n: usize,
    },
    /// A value is NaN or infinite.
    #[error("{0} holds a value that is not finite")]
    NotFinite(&'static str),
}

/// A score and what it is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Score {
    /// The mean over the factors.
    pub score: f64,
    /// Per factor: the gap.
    pub per_factor: Vec<f64>,
    /// Per factor: the latent that explains it best.
    pub best_latent: Vec<usize>,
    /// `[factor][latent]`: mutual information in nats (MIG) or R² (SAP).
    pub matrix: Vec<Vec<f64>>,
}

/// Bins per variable (`disentanglement_lib`'s default for MIG).
pub const BINS: usize = 20;

/// Column `j` of a row-major `n x width` array.
fn column(data: &[f64], width: usize, j: usize) -> impl Iterator<Item = f64> + Clone + '_ {
    data.iter().skip(j).step_by(width).copied()
}

fn check(
    latents: &[f64],
    d: usize,
    factors: &[f64],
    k: usize,
    n: usize,
) -> Result<(), DisentanglementError> {
    if d < 2 || k < 1 || n < 2 {
        return Err(DisentanglementError::TooSmall {
            latents: d,
            factors: k,
            n,
        });
    }
    for (what, v, width) in [("latents", latents, d), ("factors", factors, k)] {
        if v.len() != n * width {
            return Err(DisentanglementError::Shape {
                what,
                len: v.len(),
                n,
                width,
            });
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(DisentanglementError::NotFinite(what));
        }
    }
    Ok(())
}

/// Equal-width bins over the column's range (`np.histogram`'s edges: the maximum falls in the
/// last bin); a constant column is one bin.
fn discretise(values: impl Iterator<Item = f64> + Clone, bins: usize) -> Vec<usize> {
    let lo = values.clone().fold(f64::INFINITY, f64::min);
    let hi = values.clone().fold(f64::NEG_INFINITY, f64::max);
    let width = (hi - lo) / bins as f64;
    values
        .map(|v| {
            if width > 0.0 {
                (((v - lo) / width) as usize).min(bins - 1)
            } else {
                0
            }
        })
        .collect()
}

/// Entropy (nats) of a discrete variable.
fn entropy(a: &[usize], bins: usize) -> f64 {
    let mut count = vec![0usize; bins];
    for &x in a {
        count[x] += 1;
    }
    let n = a.len() as f64;
    let mut h = 0.0;
    for &c in &count {
        if c > 0 {
            let p = c as f64 / n;
            h -= p * libm::log(p);
        }
    }
    h
}

/// Mutual information (nats) of two discrete variables (scikit-learn's `mutual_info_score`).
fn mutual_information(a: &[usize], b: &[usize], bins: usize) -> f64 {
    let mut joint = vec![0usize; bins * bins];
    let (mut ca, mut cb) = (vec![0usize; bins], vec![0usize; bins]);
    for (&x, &y) in a.iter().zip(b) {
        joint[x * bins + y] += 1;
        ca[x] += 1;
        cb[y] += 1;
    }
    let n = a.len() as f64;
    let mut mi = 0.0;
    for x in 0..bins {
        for y in 0..bins {
            let c = joint[x * bins + y];
            if c > 0 {
                let pxy = c as f64 / n;
                mi += pxy * libm::log(c as f64 * n / (ca[x] as f64 * cb[y] as f64));
            }
        }
    }
    mi.max(0.0)
}

/// The gap between the largest and the second largest value of a row, and the best index.
fn gap(row: &[f64]) -> (f64, usize) {
    let mut order: Vec<usize> = (0..row.len()).collect();
    order.sort_by(|&a, &b| row[b].total_cmp(&row[a]).then(a.cmp(&b)));
    (row[order[0]] - row[order[1]], order[0])
}

/// MIG of `n` rows of `d` latents against `k` factors (both row-major).
pub fn mig(
    latents: &[f64],
    d: usize,
    factors: &[f64],
    k: usize,
) -> Result<Score, DisentanglementError> {
    let n = latents.len().checked_div(d).unwrap_or(0);
    check(latents, d, factors, k, n)?;
    let z: Vec<Vec<usize>> = (0..d)
        .map(|j| discretise(column(latents, d, j), BINS))
        .collect();
    Ok(score_by_factor(k, |f| {
        let v = discretise(column(factors, k, f), BINS);
        let row = z
            .iter()
            .map(|zj| mutual_information(zj, &v, BINS))
            .collect();
        (row, entropy(&v, BINS))
    }))
}

/// The score of `k` factors from each factor's row of latent scores and the number its gap is
/// divided by (0: the gap counts as 0): the gap, the best latent, and the mean gap.
fn score_by_factor(k: usize, mut row_of: impl FnMut(usize) -> (Vec<f64>, f64)) -> Score {
    let mut matrix = Vec::with_capacity(k);
    let mut per_factor = Vec::with_capacity(k);
    let mut best_latent = Vec::with_capacity(k);
    for f in 0..k {
        let (row, norm) = row_of(f);
        let (g, best) = gap(&row);
        per_factor.push(if norm > 0.0 { g / norm } else { 0.0 });
        best_latent.push(best);
        matrix.push(row);
    }
    let score = per_factor.iter().sum::<f64>() / k as f64;
    Score {
        score,
        per_factor,
        best_latent,
        matrix,
    }
}

/// R² of the least-squares line of `y` on `x` (0 when either is constant).
fn r2_linear(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    if sxx > 0.0 && syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        0.0
    }
}

/// SAP of `n` rows of `d` latents against `k` factors (both row-major), with linear R² scores.
pub fn sap(
    latents: &[f64],
    d: usize,
    factors: &[f64],
    k: usize,
) -> Result<Score, DisentanglementError> {
    let n = latents.len().checked_div(d).unwrap_or(0);
    check(latents, d, factors, k, n)?;
    let z: Vec<Vec<f64>> = (0..d).map(|j| column(latents, d, j).collect()).collect();
    Ok(score_by_factor(k, |f| {
        let v: Vec<f64> = column(factors, k, f).collect();
        (z.iter().map(|zj| r2_linear(zj, &v)).collect(), 1.0)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::{standard_normal, stream_named};
    use rand::RngExt;

    /// `n` samples of the four factors of a two-ball scene, uniform in [-1, 1].
    fn factors(n: usize) -> Vec<f64> {
        let mut rng = stream_named(1, "disentanglement-test");
        (0..4 * n).map(|_| rng.random_range(-1.0..1.0)).collect()
    }

    /// Latents `z = M f + noise`, with `d` rows of `m`.
    fn latents(f: &[f64], m: &[[f64; 4]], noise: f64) -> Vec<f64> {
        let mut rng = stream_named(2, "disentanglement-test");
        f.chunks(4)
            .flat_map(|row| {
                m.iter()
                    .map(|w| (0..4).map(|j| w[j] * row[j]).sum::<f64>())
                    .collect::<Vec<_>>()
            })
            .map(|v| v + noise * standard_normal(&mut rng))
            .collect()
    }

    #[test]
    fn a_disentangled_space_scores_high_and_a_rotated_one_low() {
        let n = 5000;
        let f = factors(n);
        // One latent per factor (permuted), plus two collapsed latents.
        let one_each = [
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 2.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, -1.0, 0.0],
            [0.0; 4],
            [0.0; 4],
        ];
        // The same information, every latent mixing all four factors.
        let h = 0.5;
        let mixed = [[h, h, h, h], [h, -h, h, -h], [h, h, -h, -h], [h, -h, -h, h]];
        for noise in [0.0, 0.05] {
            let good_m = mig(&latents(&f, &one_each, noise), 6, &f, 4).unwrap();
            let bad_m = mig(&latents(&f, &mixed, noise), 4, &f, 4).unwrap();
            assert!(good_m.score > 0.5, "{good_m:?}");
            assert!(bad_m.score < 0.1, "{bad_m:?}");
            assert_eq!(good_m.best_latent, [2, 0, 3, 1]);
            let good_s = sap(&latents(&f, &one_each, noise), 6, &f, 4).unwrap();
            let bad_s = sap(&latents(&f, &mixed, noise), 4, &f, 4).unwrap();
            assert!(good_s.score > 0.9, "{good_s:?}");
            assert!(bad_s.score < 0.1, "{bad_s:?}");
        }
        // Entangled within an object only (a rotation of the ball's x and y): in between.
        let c = std::f64::consts::FRAC_1_SQRT_2;
        let per_object = [
            [c, c, 0.0, 0.0],
            [c, -c, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let mid = mig(&latents(&f, &per_object, 0.0), 4, &f, 4).unwrap();
        let good = mig(&latents(&f, &one_each, 0.0), 6, &f, 4).unwrap();
        let bad = mig(&latents(&f, &mixed, 0.0), 4, &f, 4).unwrap();
        eprintln!(
            "MIG: one latent per factor {:.3}, rotated within the ball {:.3}, all mixed {:.3}",
            good.score, mid.score, bad.score
        );
        // scikit-learn's mutual_info_score on numpy's bins gives 0.985, 0.496 and 0.003 on the
        // same design (other draws).
        assert!((good.score - 0.985).abs() < 0.02 && (mid.score - 0.496).abs() < 0.03);
        assert!(
            bad.score < mid.score && mid.score < good.score,
            "{bad:?} {mid:?} {good:?}"
        );
    }

    #[test]
    fn mutual_information_and_entropy_are_exact_on_small_cases() {
        // Two independent fair bits: H = ln 2 each, I = 0; identical bits: I = ln 2.
        let a = [0, 0, 1, 1];
        let b = [0, 1, 0, 1];
        assert!((entropy(&a, 2) - 2f64.ln()).abs() < 1e-15);
        assert_eq!(mutual_information(&a, &b, 2), 0.0);
        assert!((mutual_information(&a, &a, 2) - 2f64.ln()).abs() < 1e-15);
        // A constant latent carries nothing; the maximum falls in the last bin.
        assert_eq!(discretise([3.0, 3.0].into_iter(), 20), [0, 0]);
        assert_eq!(discretise([0.0, 0.5, 1.0].into_iter(), 2), [0, 1, 1]);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let f = factors(10);
        assert!(matches!(
            mig(&[0.0; 10], 1, &f, 4),
            Err(DisentanglementError::TooSmall { .. })
        ));
        assert!(matches!(
            mig(&[0.0; 21], 2, &f, 4),
            Err(DisentanglementError::Shape { .. })
        ));
        let mut z = vec![0.0; 20];
        z[3] = f64::NAN;
        assert_eq!(
            sap(&z, 2, &f, 4),
            Err(DisentanglementError::NotFinite("latents"))
        );
    }
}
