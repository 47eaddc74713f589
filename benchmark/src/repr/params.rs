//! The two traits of a learner's parameters (linfa's `ParamGuard` pattern; the registry,
//! [`super::registry`], parses each `[learners.NAME]` table with them).

use std::any::Any;
use std::fmt::Debug;

use super::RepresentationLearner;
use super::neural_model::Variant;

/// Unchecked parameters that can be validated (linfa's `ParamGuard`).
pub trait ParamGuard {
    /// The parameters after validation.
    type Checked;
    /// Validate every value; the message names the key (without the `learners.NAME.` prefix).
    fn check(self) -> Result<Self::Checked, String>;
}

/// The checked parameters of one learner: what its runs depend on, and the learner itself.
pub trait LearnerParams: Debug + Send + Sync {
    /// What the runs depend on, hashed into their config hash (so changing the VAE budget
    /// reruns only the VAE's runs). `variant` is the run's, for learners with variants.
    fn identity(&self, variant: Option<Variant>) -> serde_json::Value;
    /// The learner for a run of `variant`.
    fn build(&self, variant: Option<Variant>) -> Box<dyn RepresentationLearner>;
    /// Where these parameters depart from the paper's (a smaller training budget, another
    /// init...), one phrase each, for the manifests' `budget_note` and the report's deviations.
    fn deviations(&self, variant: Option<Variant>) -> Vec<String> {
        let _ = variant;
        Vec::new()
    }
    /// The concrete type, for the harness's [`super::registry::Kind`]-specific paths (a neural
    /// learner's training configuration, an external learner's program).
    fn as_any(&self) -> &dyn Any;
}
