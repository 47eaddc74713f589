//! The run matrix: which runs a campaign consists of, and their identities.

use serde::Serialize;

use super::config::{CampaignConfig, LatentSize};
use crate::env::EnvKind;
use crate::explore::{Algo, SamplerKind};

/// One run of the matrix.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct RunSpec {
    pub env: EnvKind,
    pub algo: Algo,
    /// Goal sampler (`none` for RPE, `uniform` for EFR).
    pub sampler: SamplerKind,
    /// Latent size of a learned goal space; 0 for RPE and EFR.
    pub latents: usize,
    /// Repetition index (`--seed` of `ugl run`).
    pub seed: u64,
}

impl RunSpec {
    /// A baseline run (RPE or RGE-EFR).
    pub fn baseline(env: EnvKind, algo: Algo, seed: u64) -> Self {
        let sampler = if algo == Algo::Rpe { SamplerKind::None } else { SamplerKind::Uniform };
        RunSpec { env, algo, sampler, latents: 0, seed }
    }

    /// Canonical identity (DESIGN.md "Seeding"): `env=armball/algo=rge-efr/seed=3`, or for a
    /// learned goal space `env=armball/algo=rge-pca/sampler=kde/latents=10/seed=3`. It enters
    /// the run-seed hash, so it is part of the results' specification.
    pub fn identity(&self) -> String {
        match self.algo.learner() {
            None => format!("env={}/algo={}/seed={}", self.env, self.algo, self.seed),
            Some(_) => format!(
                "env={}/algo={}/sampler={}/latents={}/seed={}",
                self.env, self.algo, self.sampler, self.latents, self.seed
            ),
        }
    }

    /// File-name-safe identity: `armball.rge-efr.s3`, `armball.rge-pca.kde.l10.s3`.
    pub fn run_id(&self) -> String {
        match self.algo.learner() {
            None => format!("{}.{}.s{}", self.env, self.algo, self.seed),
            Some(_) => format!("{}.{}.{}.l{}.s{}", self.env, self.algo, self.sampler, self.latents, self.seed),
        }
    }

    /// The identity of the trained representation this run uses (shared by every sampler of
    /// the same env, learner, latent size, data-set size and repetition); None for baselines.
    pub fn representation_identity(&self, images: usize) -> Option<String> {
        self.algo.learner().map(|l| {
            format!("repr/env={}/learner={}/latents={}/images={images}/seed={}", self.env, l.name(), self.latents, self.seed)
        })
    }
}

/// All runs of a campaign, in a fixed order (env, algo, sampler, latents, seed).
pub fn plan(cfg: &CampaignConfig) -> Vec<RunSpec> {
    let mut runs = Vec::new();
    for &env in &cfg.matrix.envs {
        for &algo in &cfg.matrix.algos {
            if algo.learner().is_none() {
                for seed in 0..cfg.campaign.reps as u64 {
                    runs.push(RunSpec::baseline(env, algo, seed));
                }
                continue;
            }
            for &sampler in &cfg.matrix.samplers {
                for l in &cfg.matrix.latents {
                    let latents = match l {
                        LatentSize::N(n) => *n,
                        LatentSize::TrueDim => env.state_dim(),
                    };
                    for seed in 0..cfg.campaign.reps as u64 {
                        runs.push(RunSpec { env, algo, sampler, latents, seed });
                    }
                }
            }
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::Learner;

    #[test]
    fn identities() {
        let r = RunSpec::baseline(EnvKind::ArmArrow, Algo::RgeEfr, 3);
        assert_eq!(r.identity(), "env=armarrow/algo=rge-efr/seed=3");
        assert_eq!(r.run_id(), "armarrow.rge-efr.s3");
        assert_eq!(r.representation_identity(10), None);
        let r = RunSpec { env: EnvKind::ArmBall, algo: Algo::Rge(Learner::Pca), sampler: SamplerKind::Kde, latents: 10, seed: 2 };
        assert_eq!(r.identity(), "env=armball/algo=rge-pca/sampler=kde/latents=10/seed=2");
        assert_eq!(r.run_id(), "armball.rge-pca.kde.l10.s2");
        let g = RunSpec { sampler: SamplerKind::Gaussian, ..r.clone() };
        assert_eq!(r.representation_identity(100), g.representation_identity(100));
    }
}
