//! The errors of a run or a campaign.

use crate::explore::ExploreError;
use thiserror::Error;

use super::store::StoreError;
use crate::repr::ReprError;

/// Errors of a run or campaign.
#[derive(Debug, Error)]
pub enum RunError {
    #[error(transparent)]
    Store(#[from] StoreError),
    #[error("cannot start the worker pool: {0}")]
    Pool(String),
    #[error("run {run}: {source}")]
    Repr { run: String, source: ReprError },
    #[error("run {run}: {source}")]
    Explore { run: String, source: ExploreError },
    /// A run whose representation was not fitted because the same fit failed before: in its
    /// group (the runs sharing the representation), or, for an external learner, in another
    /// seed of the same cell (a failing program is started once, not once per run).
    #[error("run {run}: not run: the fit of its goal space failed for run {first} (error above)")]
    FitFailedBefore { run: String, first: String },
    #[error(
        "interrupted: {done} of {total} runs finished and stored; rerun the same command to resume"
    )]
    Interrupted { done: usize, total: usize },
    /// Several runs failed (each reported as it failed, `Progress::Failed`); the others
    /// finished and are stored.
    #[error(
        "{failed} runs failed ({not_run} more not run: the fit they share failed; {stored} \
         finished and stored); the first failure: {first}"
    )]
    Failed {
        failed: usize,
        not_run: usize,
        stored: usize,
        first: Box<RunError>,
    },
}
