//! Goals from an isotropic standard Gaussian, N(0, I): the paper's Gaussian-prior ("GP") goal
//! sampling for VAE-type latent spaces (PAPER-NOTES.md section 3, `--sampling=normal`).

use rand_distr::{Distribution, StandardNormal};

use super::GoalSampler;
use crate::seed::Stream;

/// N(0, I) goals in dimension `dim`.
#[derive(Clone, Debug)]
pub struct GaussianGoals {
    dim: usize,
}

impl GaussianGoals {
    /// Standard normal goals.
    pub fn new(dim: usize) -> Self {
        GaussianGoals { dim }
    }
}

impl GoalSampler for GaussianGoals {
    fn dim(&self) -> usize {
        self.dim
    }
    fn sample(&mut self, rng: &mut Stream, out: &mut [f64]) {
        for v in out.iter_mut() {
            *v = StandardNormal.sample(rng);
        }
    }
    fn name(&self) -> &'static str {
        "gaussian"
    }
}
