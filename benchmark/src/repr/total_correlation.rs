//! The total correlation of a mini-batch's codes, `TC = KL(q(z) || prod_k q(z_k))`: the term of
//! the KL's decomposition (Chen et al., "Isolating Sources of Disentanglement in VAEs", NeurIPS
//! 2018; β-TCVAE) that a code spread over dependent latents pays and a factorised one does not.
//! The β-VAE's KL term presses the whole KL; a weight on this term presses the dependence alone
//! (`[learners.conv-bvae] tc`, ours: `docs/neural.md`, "Tenth round").
//!
//! **Estimator**: minibatch-weighted sampling over the batch's own mixture. With `M` codes
//! `z_i ~ q(z | x_i)`, `l_ijk = log N(z_ik; mu_jk, exp(logvar_jk))`,
//!
//! - `log q(z_i) ≈ logsumexp_j sum_k l_ijk − log M`,
//! - `log q(z_ik) ≈ logsumexp_j l_ijk − log M`,
//! - `TC ≈ mean_i (log q(z_i) − sum_k log q(z_ik))`.
//!
//! Chen et al. normalise by `log(N M)` (N: the data set's size), which adds the constant
//! `(d − 1) log N` to the value and nothing to the gradient; the batch's mixture (N = 1, as
//! `disentanglement_lib`'s `total_correlation` up to its constant) makes the value the TC of the
//! mixture of the batch's posteriors, 0 for codes whose latents are independent within it.
//!
//! Value and gradients (of `z`, `mu` and `logvar`) are computed on the host in f64, in a fixed
//! order, with `libm`: the same bits on every machine ([`super::host_ops`]). With `w_ijk = (p_ij
//! − r_ijk) / M`, `p_ij = softmax_j(sum_k l_ijk)`, `r_ijk = softmax_j(l_ijk)` and
//! `u = (z_ik − mu_jk) exp(−logvar_jk)`:
//! `dz_ik = −sum_j w_ijk u`, `dmu_jk = sum_i w_ijk u`,
//! `dlogvar_jk = sum_i w_ijk (u (z_ik − mu_jk) − 1) / 2`.

use burn::tensor::{Tensor, TensorData};

/// `ln(2π)`.
const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// The estimate and its gradients, each `[M, d]` row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct TcEstimate {
    pub value: f64,
    pub dz: Vec<f64>,
    pub dmu: Vec<f64>,
    pub dlogvar: Vec<f64>,
}

/// `log sum_j exp(a_j)` and the softmax weights `exp(a_j − lse)`, written into `weights`.
fn logsumexp(a: &[f64], weights: &mut [f64]) -> f64 {
    let top = a.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if top == f64::NEG_INFINITY {
        weights.iter_mut().for_each(|w| *w = 0.0);
        return top;
    }
    let mut sum = 0.0;
    for (w, &v) in weights.iter_mut().zip(a) {
        *w = libm::exp(v - top);
        sum += *w;
    }
    weights.iter_mut().for_each(|w| *w /= sum);
    top + libm::log(sum)
}

/// The minibatch-weighted estimate of the total correlation of the codes `z` (`[m, d]`,
/// sampled from `N(mu, exp(logvar))`, each `[m, d]`), with its gradients.
pub fn estimate(z: &[f32], mu: &[f32], logvar: &[f32], m: usize, d: usize) -> TcEstimate {
    assert!(
        z.len() == m * d && mu.len() == m * d && logvar.len() == m * d,
        "codes, means and log-variances of {m} x {d}"
    );
    let at = |v: &[f32], r: usize, k: usize| f64::from(v[r * d + k]);
    let precision: Vec<f64> = logvar.iter().map(|&v| libm::exp(-f64::from(v))).collect();
    // l[(j, k)] for one i at a time; the joint and each latent's softmax over j.
    let mut l = vec![0.0; m * d];
    let mut joint = vec![0.0; m];
    let mut p = vec![0.0; m];
    let mut column = vec![0.0; m];
    let mut weights = vec![0.0; m];
    let mut r = vec![0.0; m * d];
    let mut est = TcEstimate {
        value: 0.0,
        dz: vec![0.0; m * d],
        dmu: vec![0.0; m * d],
        dlogvar: vec![0.0; m * d],
    };
    let log_m = libm::log(m as f64);
    for i in 0..m {
        for j in 0..m {
            let mut sum = 0.0;
            for k in 0..d {
                let diff = at(z, i, k) - at(mu, j, k);
                let v = -0.5 * (LN_2PI + at(logvar, j, k) + diff * diff * precision[j * d + k]);
                l[j * d + k] = v;
                sum += v;
            }
            joint[j] = sum;
        }
        let mut term = logsumexp(&joint, &mut p) - log_m;
        for k in 0..d {
            for j in 0..m {
                column[j] = l[j * d + k];
            }
            term -= logsumexp(&column, &mut weights) - log_m;
            for j in 0..m {
                r[j * d + k] = weights[j];
            }
        }
        est.value += term / m as f64;
        for j in 0..m {
            for k in 0..d {
                let w = (p[j] - r[j * d + k]) / m as f64;
                let diff = at(z, i, k) - at(mu, j, k);
                let u = diff * precision[j * d + k];
                est.dz[i * d + k] -= w * u;
                est.dmu[j * d + k] += w * u;
                est.dlogvar[j * d + k] += 0.5 * w * (u * diff - 1.0);
            }
        }
    }
    est
}

/// The estimate as a burn scalar `[1]` whose value is the estimate and whose gradients are its
/// gradients (the constant plus `sum((x − detach(x)) g)` for `z`, `mu` and `logvar`, as
/// [`super::host_ops::host_map`] does).
pub fn total_correlation(z: Tensor<2>, mu: Tensor<2>, logvar: Tensor<2>) -> Tensor<1> {
    let [m, d] = z.dims();
    let device = z.device();
    let host = |t: &Tensor<2>| {
        t.clone()
            .into_data()
            .convert::<f32>()
            .try_into_vec::<f32>()
            .expect("converted to f32")
    };
    let est = estimate(&host(&z), &host(&mu), &host(&logvar), m, d);
    let linear = |x: Tensor<2>, g: &[f64]| {
        let g: Vec<f32> = g.iter().map(|&v| v as f32).collect();
        let g = Tensor::<2>::from_data(TensorData::new(g, [m, d]), &device);
        ((x.clone() - x.detach()) * g).sum()
    };
    let value = Tensor::<1>::from_data(TensorData::new(vec![est.value as f32], [1]), &device);
    value + linear(z, &est.dz) + linear(mu, &est.dmu) + linear(logvar, &est.dlogvar)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::{standard_normal, stream_named};
    use burn::tensor::Device;

    /// `m` codes of `d` latents, means spread by `spread`, log-variances near −2.
    fn codes(m: usize, d: usize, seed: u64) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let mut rng = stream_named(seed, "tc");
        let mut draw = |s: f64, c: f64| -> Vec<f32> {
            (0..m * d)
                .map(|_| (c + s * standard_normal(&mut rng)) as f32)
                .collect()
        };
        let mu = draw(1.0, 0.0);
        let logvar = draw(0.3, -2.0);
        let eps = draw(1.0, 0.0);
        let z = (0..m * d)
            .map(|i| mu[i] + eps[i] * (0.5 * logvar[i]).exp())
            .collect();
        (z, mu, logvar)
    }

    /// The estimate straight from its definition, in f64 (no softmax, no gradient).
    fn by_definition(z: &[f32], mu: &[f32], logvar: &[f32], m: usize, d: usize) -> f64 {
        let log_n = |x: f64, mean: f64, lv: f64| {
            -0.5 * ((2.0 * std::f64::consts::PI).ln() + lv + (x - mean).powi(2) / lv.exp())
        };
        let f = |v: &[f32], r: usize, k: usize| f64::from(v[r * d + k]);
        let mut tc = 0.0;
        for i in 0..m {
            let joint: f64 = (0..m)
                .map(|j| {
                    (0..d)
                        .map(|k| log_n(f(z, i, k), f(mu, j, k), f(logvar, j, k)))
                        .sum::<f64>()
                        .exp()
                })
                .sum::<f64>()
                / m as f64;
            let marginals: f64 = (0..d)
                .map(|k| {
                    ((0..m)
                        .map(|j| log_n(f(z, i, k), f(mu, j, k), f(logvar, j, k)).exp())
                        .sum::<f64>()
                        / m as f64)
                        .ln()
                })
                .sum();
            tc += (joint.ln() - marginals) / m as f64;
        }
        tc
    }

    #[test]
    fn the_estimate_is_its_definition() {
        for (m, d, seed) in [(5, 3, 1), (8, 2, 2), (1, 4, 3), (6, 1, 4)] {
            let (z, mu, lv) = codes(m, d, seed);
            let got = estimate(&z, &mu, &lv, m, d).value;
            let want = by_definition(&z, &mu, &lv, m, d);
            assert!((got - want).abs() < 1e-9, "{m}x{d}: {got} vs {want}");
        }
        // One code, or one latent: nothing to correlate.
        let (z, mu, lv) = codes(1, 4, 3);
        assert!(estimate(&z, &mu, &lv, 1, 4).value.abs() < 1e-12);
        let (z, mu, lv) = codes(6, 1, 4);
        assert!(estimate(&z, &mu, &lv, 6, 1).value.abs() < 1e-12);
    }

    /// Each gradient against central differences of the definition.
    #[test]
    fn the_gradients_are_the_estimates() {
        let (m, d) = (6, 3);
        let (z, mu, lv) = codes(m, d, 7);
        let est = estimate(&z, &mu, &lv, m, d);
        let h = 1e-3f32;
        for (which, grad) in [(0, &est.dz), (1, &est.dmu), (2, &est.dlogvar)] {
            for e in 0..m * d {
                let at = |value: f32| {
                    let (mut a, mut b, mut c) = (z.clone(), mu.clone(), lv.clone());
                    [&mut a, &mut b, &mut c][which][e] = value;
                    by_definition(&a, &b, &c, m, d)
                };
                let x = [&z, &mu, &lv][which][e];
                // The moved values as f32 holds them, so that the quotient's step is exact.
                let (up, down) = (x + h, x - h);
                let numeric = (at(up) - at(down)) / f64::from(up - down);
                assert!(
                    (numeric - grad[e]).abs() < 2e-3 * (1.0 + grad[e].abs()),
                    "input {which}, element {e}: {} vs the difference {numeric}",
                    grad[e]
                );
            }
        }
    }

    /// A known-good and a known-bad case: latents drawn independently have a small total
    /// correlation; the same draws with the second latent a copy of the first, a large one.
    #[test]
    fn dependent_latents_have_the_larger_total_correlation() {
        let (m, d) = (64, 2);
        let (z, mut mu, lv) = codes(m, d, 11);
        let independent = estimate(&z, &mu, &lv, m, d).value;
        let mut copied = z.clone();
        for i in 0..m {
            copied[i * d + 1] = copied[i * d];
            mu[i * d + 1] = mu[i * d];
        }
        let lv_copied: Vec<f32> = (0..m * d).map(|i| lv[i - i % d]).collect();
        let dependent = estimate(&copied, &mu, &lv_copied, m, d).value;
        assert!(
            dependent > independent + 1.0,
            "a copied latent {dependent} vs independent ones {independent}"
        );
    }

    /// The burn scalar carries the estimate and its gradients.
    #[test]
    fn the_tensor_has_the_estimate_and_its_gradients() {
        let (m, d) = (5, 3);
        let (z, mu, lv) = codes(m, d, 5);
        let est = estimate(&z, &mu, &lv, m, d);
        let device = Device::flex().autodiff();
        let t = |v: &[f32]| {
            Tensor::<2>::from_data(TensorData::new(v.to_vec(), [m, d]), &device).require_grad()
        };
        let (tz, tmu, tlv) = (t(&z), t(&mu), t(&lv));
        let tc = total_correlation(tz.clone(), tmu.clone(), tlv.clone());
        assert_eq!(tc.clone().into_scalar::<f32>(), est.value as f32);
        let grads = tc.backward();
        for (x, want) in [(tz, &est.dz), (tmu, &est.dmu), (tlv, &est.dlogvar)] {
            let got = x
                .grad(&grads)
                .unwrap()
                .into_data()
                .try_into_vec::<f32>()
                .unwrap();
            let want: Vec<f32> = want.iter().map(|&v| v as f32).collect();
            assert_eq!(got, want);
        }
    }
}
