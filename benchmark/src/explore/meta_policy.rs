//! The meta-policy of RGE (docs/original-code.md section 3): nearest stored outcome to the goal, its
//! parameters plus independent Gaussian noise, clipped to [-1,1].

use rand::RngExt;

use crate::seed::Stream;

/// `n` uniform random motor parameters in [-1, 1) (explauto `rand_bounds`), drawn in order.
pub fn random_params(rng: &mut Stream, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
}

/// `theta + N(0, sigma^2)` per dimension, clipped to [-1, 1].
pub fn perturb(theta: &[f64], sigma: f64, rng: &mut Stream) -> Vec<f64> {
    theta
        .iter()
        .map(|t| {
            let n = crate::seed::standard_normal(rng);
            (t + sigma * n).clamp(-1.0, 1.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::PARAMS;
    use crate::seed::{Component, stream};

    #[test]
    fn random_params_in_range_and_noise_statistics() {
        let mut rng = stream(1, Component::Params);
        let mut sum = 0.0;
        for _ in 0..1000 {
            let t = random_params(&mut rng, PARAMS);
            assert!(t.iter().all(|v| (-1.0..1.0).contains(v)));
            sum += t.iter().sum::<f64>();
        }
        assert!((sum / 21_000.0).abs() < 0.02);
        let mut rng = stream(1, Component::Noise);
        let zero = [0.0; PARAMS];
        let (mut s1, mut s2) = (0.0, 0.0);
        let n = 4000;
        for _ in 0..n {
            for v in perturb(&zero, 0.1, &mut rng) {
                s1 += v;
                s2 += v * v;
            }
        }
        let m = s1 / (n * PARAMS) as f64;
        let sd = (s2 / (n * PARAMS) as f64 - m * m).sqrt();
        assert!(m.abs() < 0.003, "{m}");
        assert!((sd - 0.1).abs() < 0.003, "{sd}");
        // Clipping.
        let ones = [1.0; PARAMS];
        assert!(perturb(&ones, 0.5, &mut rng).iter().all(|v| *v <= 1.0));
    }
}
