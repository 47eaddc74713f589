//! The two traits of a learner's parameters (linfa's `ParamGuard` pattern; the registry,
//! [`super::registry`], parses each `[learners.NAME]` table with them).

use std::any::Any;
use std::fmt::Debug;

use super::RepresentationLearner;
use super::neural_model::Variant;

/// A value of a learner's `[learners.NAME]` table that is not valid: its key, as data (None:
/// the table as a whole), and why. Shown as `KEY: why`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}{message}", key.as_deref().map(|k| format!("{k}: ")).unwrap_or_default())]
pub struct ParamError {
    /// The key inside the table (`warmup`, `hidden[1]`), without the `learners.NAME.` prefix.
    pub key: Option<String>,
    /// Why the value is refused.
    pub message: String,
}

impl ParamError {
    /// The value of `key` is refused.
    pub fn at(key: impl Into<String>, message: impl Into<String>) -> ParamError {
        ParamError {
            key: Some(key.into()),
            message: message.into(),
        }
    }

    /// The table as a whole is refused.
    pub fn table(message: impl Into<String>) -> ParamError {
        ParamError {
            key: None,
            message: message.into(),
        }
    }
}

/// A learner's table refused: which learner, and the [`ParamError`]. Shown as
/// `learners.NAME.KEY: why` (or `learners.NAME: why`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("learners.{learner}{}: {}", error.key.as_deref().map(|k| format!(".{k}")).unwrap_or_default(), error.message)]
pub struct LearnerParamError {
    /// The learner's name (the table's).
    pub learner: String,
    pub error: ParamError,
}

/// Unchecked parameters that can be validated (linfa's `ParamGuard`).
pub trait ParamGuard {
    /// The parameters after validation.
    type Checked;
    /// Validate every value; the error names the key.
    fn check(self) -> Result<Self::Checked, ParamError>;
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
