//! Random parameter exploration (RPE; PAPER-NOTES.md section 3): `epochs` uniformly random
//! parameter vectors, no warm-up.

use super::ExploreConfig;
use super::history::{ExplorationLog, Recorder};
use super::meta_policy::random_params;
use crate::env::Environment;
use crate::metrics::KlCoverage;
use crate::seed::{Component, stream};

/// Run RPE. Outcome i is produced at epoch i + 1.
pub fn run_rpe(env: &dyn Environment, cfg: &ExploreConfig, run_seed: u64) -> ExplorationLog {
    let klc = KlCoverage::new(env.state_dim()).expect("environment dimension is 2 or 3");
    let mut rec = Recorder::new(&klc, env.initial_state(), cfg.eval_epochs(), cfg.epochs);
    let mut params = stream(run_seed, Component::Params);
    for epoch in 1..=cfg.epochs {
        let theta = random_params(&mut params);
        let r = env.rollout(&theta);
        rec.push(epoch, &r, true);
        rec.end_epoch(epoch);
    }
    rec.finish()
}
