//! Uniform goals in the unit box [0,1)^d: RGE-EFR's goal policy (docs/original-code.md section 3).

use rand::RngExt;

use super::GoalSampler;
use crate::seed::Stream;

/// Goals uniform in `[lo, hi)^d`.
#[derive(Clone, Debug)]
pub struct UniformGoals {
    dim: usize,
    lo: f64,
    hi: f64,
}

impl UniformGoals {
    /// Uniform in [0,1)^dim, the engineered goal space of RGE-EFR.
    pub fn unit(dim: usize) -> Self {
        UniformGoals {
            dim,
            lo: 0.0,
            hi: 1.0,
        }
    }
}

impl GoalSampler for UniformGoals {
    fn dim(&self) -> usize {
        self.dim
    }
    fn sample(&mut self, rng: &mut Stream, out: &mut [f64]) {
        for v in out.iter_mut() {
            *v = rng.random_range(self.lo..self.hi);
        }
    }
    fn name(&self) -> &'static str {
        ugl_types::samplers::UNIFORM.name
    }
}
