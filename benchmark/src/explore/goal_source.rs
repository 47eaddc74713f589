//! Where an explorer's goals come from: a goal space's modules and goal samplers.

use super::mge::{GoalModule, Modules, goal_modules};
use crate::goals::{GoalSampler, UniformGoals};
use crate::repr::ReprError;

/// The goals of a goal space: its modules and its goal samplers.
pub trait GoalSource {
    /// The modules of `choice` ([`goal_modules`]).
    fn modules(&self, choice: Modules, module_size: usize) -> Result<Vec<GoalModule>, ReprError>;
    /// A goal sampler over every coordinate (`dims` None) or over the coordinates `dims`.
    fn sampler(&self, dims: Option<&[usize]>) -> Result<Box<dyn GoalSampler>, ReprError>;
}

/// The goals of an engineered goal space (EFR): uniform in [0,1]^d, one module per object.
#[derive(Clone, Debug)]
pub struct EngineeredGoals {
    dim: usize,
    objects: Vec<(&'static str, std::ops::Range<usize>)>,
}

impl EngineeredGoals {
    /// For outcomes of dimension `dim` holding `objects` (`EnvKind::objects`).
    pub fn new(dim: usize, objects: Vec<(&'static str, std::ops::Range<usize>)>) -> Self {
        EngineeredGoals { dim, objects }
    }
}

impl GoalSource for EngineeredGoals {
    fn modules(&self, choice: Modules, module_size: usize) -> Result<Vec<GoalModule>, ReprError> {
        goal_modules(choice, self.dim, Some(&self.objects), &[], module_size)
            .map_err(|e| ReprError::InvalidInput(e.to_string()))
    }
    fn sampler(&self, dims: Option<&[usize]>) -> Result<Box<dyn GoalSampler>, ReprError> {
        Ok(Box::new(UniformGoals::unit(
            dims.map_or(self.dim, <[usize]>::len),
        )))
    }
}
