//! Goals from an isotropic standard Gaussian, N(0, I): the paper's Gaussian-prior ("GP") goal
//! sampling for VAE-type latent spaces (docs/original-code.md section 3, `--sampling=normal`).

use crate::seed::standard_normal;

use super::GoalSampler;
use crate::seed::Stream;

/// Goals `mean + std * N(0, I)`; N(0, I) in dimension `dim` by default.
#[derive(Clone, Debug)]
pub struct GaussianGoals {
    dim: usize,
    mean: Vec<f64>,
    std: Vec<f64>,
}

impl GaussianGoals {
    /// Standard normal goals.
    pub fn new(dim: usize) -> Self {
        GaussianGoals {
            dim,
            mean: vec![0.0; dim],
            std: vec![1.0; dim],
        }
    }

    /// Goals from an encoder's diagonal Gaussian prior (N(0, I) for the VAE and RFVAE, what an
    /// external program's `prior.npy` says otherwise).
    pub fn from_prior(prior: &crate::repr::GaussianPrior) -> Self {
        GaussianGoals {
            dim: prior.mean.len(),
            mean: prior.mean.clone(),
            std: prior.std.clone(),
        }
    }
}

/// Its registry entry's builder: the goal space's prior, which the learner must declare.
pub(crate) fn for_learned(
    space: &super::TrainingLatents<'_>,
) -> Result<Box<dyn GoalSampler>, crate::repr::ReprError> {
    match space.prior {
        Some(prior) => Ok(Box::new(GaussianGoals::from_prior(prior))),
        None => Err(crate::repr::ReprError::InvalidInput(format!(
            "the gaussian sampler needs a goal-space prior, and {} has none (use kde)",
            space.algo
        ))),
    }
}

impl GoalSampler for GaussianGoals {
    fn dim(&self) -> usize {
        self.dim
    }
    fn sample(&mut self, rng: &mut Stream, out: &mut [f64]) {
        for ((v, m), s) in out.iter_mut().zip(&self.mean).zip(&self.std) {
            let z = standard_normal(rng);
            *v = m + s * z;
        }
    }
    fn name(&self) -> &'static str {
        ugl_types::samplers::GAUSSIAN.name
    }
}
