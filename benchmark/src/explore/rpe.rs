//! Random parameter exploration (RPE; docs/original-code.md section 3): `epochs` uniformly random
//! parameter vectors, no warm-up.

use super::history::{ExplorationLog, Metrics, Recorder};
use super::meta_policy::random_params;
use super::{ExploreConfig, ExploreError, Explorer};
use crate::env::Environment;
use crate::seed::{Component, stream};

/// Run RPE. Outcome i is produced at epoch i + 1.
pub fn run_rpe(env: &dyn Environment, cfg: &ExploreConfig, run_seed: u64) -> ExplorationLog {
    let metrics = Metrics::for_env(env);
    let mut rec = Recorder::new(&metrics, env.initial_state(), cfg.eval_epochs(), cfg.epochs);
    let mut params = stream(run_seed, Component::Params);
    let mut env_rng = stream(run_seed, Component::Distractor);
    for epoch in 1..=cfg.epochs {
        let theta = random_params(&mut params, env.param_dim());
        let r = env.rollout(&theta, &mut env_rng);
        rec.push(epoch, &r, true);
        rec.end_epoch(epoch);
    }
    rec.finish()
}

/// RPE as an [`Explorer`].
pub struct Rpe;

impl Explorer for Rpe {
    fn explore(
        &mut self,
        env: &dyn Environment,
        cfg: &ExploreConfig,
        run_seed: u64,
    ) -> Result<ExplorationLog, ExploreError> {
        Ok(run_rpe(env, cfg, run_seed))
    }
}
