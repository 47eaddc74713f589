//! Gaussian kernel density estimate of the training latents, as `scipy.stats.gaussian_kde`
//! with its defaults (docs/original-code.md section 3, "Goal sampling for REP"): full data covariance
//! (unbiased, n - 1), bandwidth factor by Scott's rule `n^(-1/(d+4))`, kernel covariance =
//! factor^2 x data covariance. Sampling = a training latent chosen uniformly + the kernel's
//! Gaussian noise (`gaussian_kde.resample`).

use crate::seed::standard_normal;
use rand::RngExt;
use ugl_kernels::SymmetricEigen;

use super::GoalSampler;
use crate::repr::{Latents, ReprError};
use crate::seed::Stream;

/// A fitted KDE goal sampler.
#[derive(Clone, Debug)]
pub struct KdeGoals {
    data: Latents,
    /// Scott's factor.
    pub factor: f64,
    /// Kernel covariance (d x d, row-major).
    pub covariance: Vec<f64>,
    /// A square root S of the kernel covariance (S S^T = covariance), from its eigen-decomposition
    /// so that a singular covariance (a constant latent) is handled.
    sqrt: Vec<f64>,
}

impl KdeGoals {
    /// Fit on the encodings of the training images.
    pub fn fit(data: &Latents) -> Result<Self, ReprError> {
        let (n, d) = (data.n, data.latents);
        if n < 2 || d == 0 {
            return Err(ReprError::InvalidInput(format!(
                "KDE needs at least 2 points of dimension >= 1, got {n} x {d}"
            )));
        }
        if d >= n {
            return Err(ReprError::InvalidInput(format!(
                "KDE: {d} latents need more than {d} training points to estimate a covariance, \
                 got {n}; use fewer latents or more UGL images"
            )));
        }
        if data.data.iter().any(|v| !v.is_finite()) {
            return Err(ReprError::Numerical(
                "KDE: non-finite training latent".into(),
            ));
        }
        let mut mean = vec![0.0; d];
        for i in 0..n {
            for (m, v) in mean.iter_mut().zip(data.row(i)) {
                *m += v;
            }
        }
        mean.iter_mut().for_each(|m| *m /= n as f64);
        let mut cov = vec![0.0; d * d];
        for i in 0..n {
            let r = data.row(i);
            for a in 0..d {
                for b in 0..d {
                    cov[a * d + b] += (r[a] - mean[a]) * (r[b] - mean[b]);
                }
            }
        }
        let factor = libm::pow(n as f64, -1.0 / (d as f64 + 4.0));
        let covariance: Vec<f64> = cov
            .iter()
            .map(|c| c / (n as f64 - 1.0) * factor * factor)
            .collect();
        // The symmetric eigen-decomposition of the covariance (deterministic, plain arithmetic):
        // S = V sqrt(max(L, 0)).
        let eig = SymmetricEigen::new(&covariance, d)
            .map_err(|e| ReprError::Numerical(format!("KDE: eigen-decomposition failed: {e}")))?;
        let mut sqrt = vec![0.0; d * d];
        for c in 0..d {
            let s = eig.values[c].max(0.0).sqrt();
            for r in 0..d {
                // Column c of the eigenvectors scaled by sqrt(lambda).
                sqrt[r * d + c] = eig.vector(r, c) * s;
            }
        }
        Ok(KdeGoals {
            data: data.clone(),
            factor,
            covariance,
            sqrt,
        })
    }
}

/// Its registry entry's builder: the KDE of the training latents.
pub(crate) fn for_learned(
    space: &super::TrainingLatents<'_>,
) -> Result<Box<dyn GoalSampler>, ReprError> {
    Ok(Box::new(KdeGoals::fit(space.latents)?))
}

impl GoalSampler for KdeGoals {
    fn dim(&self) -> usize {
        self.data.latents
    }
    fn sample(&mut self, rng: &mut Stream, out: &mut [f64]) {
        let d = self.data.latents;
        let i = rng.random_range(0..self.data.n);
        let eps: Vec<f64> = (0..d).map(|_| standard_normal(rng)).collect();
        let base = self.data.row(i);
        for r in 0..d {
            out[r] = base[r] + (0..d).map(|c| self.sqrt[r * d + c] * eps[c]).sum::<f64>();
        }
    }
    fn name(&self) -> &'static str {
        ugl_types::samplers::KDE.name
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    fn sample_data() -> Latents {
        let mut rng = stream_named(9, "kde");
        let n = 500;
        let mut data = Vec::new();
        for _ in 0..n {
            let a = standard_normal(&mut rng);
            let b = standard_normal(&mut rng);
            data.extend_from_slice(&[2.0 * a + 1.0, 0.5 * a + 0.3 * b - 2.0]);
        }
        Latents {
            n,
            latents: 2,
            data,
        }
    }

    #[test]
    fn bandwidth_is_scotts_factor_squared_times_covariance() {
        let z = sample_data();
        let k = KdeGoals::fit(&z).unwrap();
        let f = 500f64.powf(-1.0 / 6.0);
        assert!((k.factor - f).abs() < 1e-15);
        // Unbiased data covariance, computed independently.
        let n = z.n as f64;
        let m: Vec<f64> = (0..2)
            .map(|a| (0..z.n).map(|i| z.row(i)[a]).sum::<f64>() / n)
            .collect();
        for a in 0..2 {
            for b in 0..2 {
                let c = (0..z.n)
                    .map(|i| (z.row(i)[a] - m[a]) * (z.row(i)[b] - m[b]))
                    .sum::<f64>()
                    / (n - 1.0);
                assert!((k.covariance[a * 2 + b] - c * f * f).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn samples_have_the_mixture_mean_and_covariance() {
        let z = sample_data();
        let mut k = KdeGoals::fit(&z).unwrap();
        let mut rng = stream_named(1, "draws");
        let m = 200_000;
        let (mut s, mut ss) = ([0.0; 2], [0.0; 4]);
        let mut out = [0.0; 2];
        for _ in 0..m {
            k.sample(&mut rng, &mut out);
            for a in 0..2 {
                s[a] += out[a];
                for b in 0..2 {
                    ss[a * 2 + b] += out[a] * out[b];
                }
            }
        }
        let n = z.n as f64;
        let mean: Vec<f64> = (0..2)
            .map(|a| (0..z.n).map(|i| z.row(i)[a]).sum::<f64>() / n)
            .collect();
        for a in 0..2 {
            let sm = s[a] / m as f64;
            assert!((sm - mean[a]).abs() < 0.02, "mean {a}: {sm} vs {}", mean[a]);
            for b in 0..2 {
                // Mixture covariance = biased data covariance + kernel covariance.
                let data_cov = (0..z.n)
                    .map(|i| (z.row(i)[a] - mean[a]) * (z.row(i)[b] - mean[b]))
                    .sum::<f64>()
                    / n;
                let want = data_cov + k.covariance[a * 2 + b];
                let got = ss[a * 2 + b] / m as f64 - (s[a] / m as f64) * (s[b] / m as f64);
                assert!(
                    (got - want).abs() < 0.03 * want.abs().max(0.3),
                    "cov {a}{b}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn constant_latent_is_handled() {
        let z = Latents {
            n: 3,
            latents: 2,
            data: vec![0.0, 1.0, 1.0, 1.0, 2.0, 1.0],
        };
        let mut k = KdeGoals::fit(&z).unwrap();
        let mut out = [0.0; 2];
        k.sample(&mut stream_named(1, "c"), &mut out);
        assert_eq!(out[1], 1.0);
        assert!(
            KdeGoals::fit(&Latents {
                n: 1,
                latents: 2,
                data: vec![0.0, 0.0]
            })
            .is_err()
        );
    }
}
