//! Goal samplers (paper Section 3, "goal policy"; docs/original-code.md section 3): where the explorer
//! draws its goals in the goal space.

pub mod kde;
pub mod prior;
pub mod registry;
pub mod uniform;

pub use kde::KdeGoals;
pub use prior::GaussianGoals;
pub use registry::{SamplerEntry, SamplerKind, TrainingLatents, register};
pub use uniform::UniformGoals;

use crate::seed::Stream;

/// Draws goals in a goal space of fixed dimension.
pub trait GoalSampler: Send {
    /// Goal-space dimension.
    fn dim(&self) -> usize;
    /// Draw one goal into `out` (length `dim`).
    fn sample(&mut self, rng: &mut Stream, out: &mut [f64]);
    /// Short name used in results (`uniform`, `kde`, `gaussian`).
    fn name(&self) -> &'static str;
}
