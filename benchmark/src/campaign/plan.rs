//! The run matrix: which runs a campaign consists of, and their identities.

use serde::Serialize;

use super::config::CampaignConfig;
use crate::env::EnvKind;
use crate::explore::Algo;

/// One run of the matrix.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct RunSpec {
    pub env: EnvKind,
    pub algo: Algo,
    /// Repetition index (`--seed` of `ugl run`).
    pub seed: u64,
}

impl RunSpec {
    /// Canonical identity (DESIGN.md "Seeding"): `env=armball/algo=rge-efr/seed=3`. It enters
    /// the run-seed hash, so it is part of the results' specification.
    pub fn identity(&self) -> String {
        format!("env={}/algo={}/seed={}", self.env, self.algo, self.seed)
    }

    /// File-name-safe identity: `armball.rge-efr.s3`.
    pub fn run_id(&self) -> String {
        format!("{}.{}.s{}", self.env, self.algo, self.seed)
    }

    /// The goal sampler name recorded in results.
    pub fn sampler(&self) -> &'static str {
        self.algo.sampler()
    }
}

/// All runs of a campaign, in a fixed order (env, algo, seed).
pub fn plan(cfg: &CampaignConfig) -> Vec<RunSpec> {
    let mut runs = Vec::new();
    for &env in &cfg.matrix.envs {
        for &algo in &cfg.matrix.algos {
            for seed in 0..cfg.campaign.reps as u64 {
                runs.push(RunSpec { env, algo, seed });
            }
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identities() {
        let r = RunSpec { env: EnvKind::ArmArrow, algo: Algo::RgeEfr, seed: 3 };
        assert_eq!(r.identity(), "env=armarrow/algo=rge-efr/seed=3");
        assert_eq!(r.run_id(), "armarrow.rge-efr.s3");
    }
}
