//! The run matrix: which runs a campaign consists of, and their identities.

use crate::invalid::InvalidValue;
use serde::Serialize;

use super::config::CampaignConfig;
use crate::env::EnvKind;
use crate::explore::{Algo, GoalSpaceKind, SamplerKind};
use crate::repr::neural::Variant;

/// One run of the matrix.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct RunSpec {
    pub env: EnvKind,
    pub algo: Algo,
    /// Goal sampler (`none` for RPE, `uniform` for EFR).
    pub sampler: SamplerKind,
    /// Latent size of a learned goal space; 0 for RPE and EFR.
    pub latents: usize,
    /// Faithful or corrected, for the learners that have both (VAE, RFVAE); None otherwise.
    pub variant: Option<Variant>,
    /// Repetition index (`--seed` of `ugl run`): the data set, the fitted goal space and the
    /// exploration streams.
    pub seed: u64,
    /// Exploration replicate of the repetition (`--exploration`; `[campaign] explorations`):
    /// replicate `j > 0` explores the same fitted goal space with its own streams. Replicate 0
    /// is the run of a campaign without replicates (same identity, id and bytes).
    pub exploration: u32,
}

impl RunSpec {
    /// A baseline run (RPE or RGE-EFR).
    pub fn baseline(env: EnvKind, algo: Algo, seed: u64) -> Self {
        let sampler = if algo == Algo::RPE {
            SamplerKind::NONE
        } else {
            SamplerKind::UNIFORM
        };
        RunSpec {
            env,
            algo,
            sampler,
            latents: 0,
            variant: None,
            seed,
            exploration: 0,
        }
    }

    /// A run in a learned goal space; `variant` is kept only for the learners that have
    /// variants ([`crate::explore::Learner::has_variants`]).
    pub fn learned(
        env: EnvKind,
        algo: Algo,
        sampler: SamplerKind,
        latents: usize,
        variant: Variant,
        seed: u64,
    ) -> Self {
        let variant = algo.learner().filter(|l| l.has_variants()).map(|_| variant);
        RunSpec {
            env,
            algo,
            sampler,
            latents,
            variant,
            seed,
            exploration: 0,
        }
    }

    /// The same run as exploration replicate `j` of its repetition.
    pub fn with_exploration(mut self, j: u32) -> Self {
        self.exploration = j;
        self
    }

    /// `/exploration=J` (or `.eJ` with `sep` `.`, key `e`) for a replicate above 0, else nothing.
    fn exploration_part(&self, sep: &str, key: &str) -> String {
        if self.exploration == 0 {
            String::new()
        } else {
            format!("{sep}{key}{}", self.exploration)
        }
    }

    /// `/variant=NAME` or nothing.
    fn variant_part(&self, sep: &str, key: &str) -> String {
        self.variant
            .map(|v| format!("{sep}{key}{v}"))
            .unwrap_or_default()
    }

    /// Canonical identity (docs/reproducibility.md): `env=armball/algo=rge-efr/seed=3`, for a
    /// learned goal space `env=armball/algo=rge-pca/sampler=kde/latents=10/seed=3`, and with a
    /// variant `env=armball/algo=rge-vae/variant=corrected/sampler=kde/latents=10/seed=3`. It
    /// enters the run-seed hash, so it is part of the results' specification.
    pub fn identity(&self) -> String {
        match self.algo.learner() {
            None => format!(
                "env={}/algo={}/seed={}{}",
                self.env,
                self.algo,
                self.seed,
                self.exploration_part("/", "exploration=")
            ),
            Some(_) => format!(
                "env={}/algo={}{}/sampler={}/latents={}/seed={}{}",
                self.env,
                self.algo,
                self.variant_part("/", "variant="),
                self.sampler,
                self.latents,
                self.seed,
                self.exploration_part("/", "exploration=")
            ),
        }
    }

    /// The identity the run's exploration streams derive from (random/goal choice, motor
    /// parameters, goals, meta-policy noise, encoding noise): for a learned goal space
    /// `explore/env=armball/sampler=kde/latents=10/seed=3`, without the learner and the
    /// variant, so that every learner of a cell draws the same streams and runs pair across
    /// learners (`ugl compare`, probability of improvement). Baselines use [`Self::identity`],
    /// of the algorithm whose streams they draw ([`Algo::stream_algo`]: the position-only EFR
    /// draws RGE-EFR's).
    pub fn exploration_identity(&self) -> String {
        match self.algo.learner() {
            None if self.algo.stream_algo() != self.algo => RunSpec {
                algo: self.algo.stream_algo(),
                ..self.clone()
            }
            .identity(),
            None => self.identity(),
            Some(_) => format!(
                "explore/env={}/sampler={}/latents={}/seed={}{}",
                self.env,
                self.sampler,
                self.latents,
                self.seed,
                self.exploration_part("/", "exploration=")
            ),
        }
    }

    /// File-name-safe identity: `armball.rge-efr.s3`, `armball.rge-pca.kde.l10.s3`,
    /// `armball.rge-vae.corrected.kde.l10.s3`; exploration replicate 2 of the last
    /// `armball.rge-vae.corrected.kde.l10.s3.e2`.
    pub fn run_id(&self) -> String {
        match self.algo.learner() {
            None => format!(
                "{}.{}.s{}{}",
                self.env,
                self.algo,
                self.seed,
                self.exploration_part(".", "e")
            ),
            Some(_) => format!(
                "{}.{}{}.{}.l{}.s{}{}",
                self.env,
                self.algo,
                self.variant_part(".", ""),
                self.sampler,
                self.latents,
                self.seed,
                self.exploration_part(".", "e")
            ),
        }
    }

    /// The identity of the trained representation this run uses (shared by every sampler of
    /// the same env, learner, variant, latent size, data-set size and repetition); None for
    /// baselines. It groups runs, shards and names the model cache entry.
    pub fn representation_identity(&self, images: usize) -> Option<String> {
        self.algo.learner().map(|l| {
            let id = self.learner_identity(l.name(), images);
            match self.variant {
                Some(v) => format!("{id}/variant={v}"),
                None => id,
            }
        })
    }

    /// The identity the learner's random stream derives from: the representation identity
    /// without the variant, so the faithful and corrected variants of a cell start from the
    /// same weights and draw the same batches (a paired comparison), and under the name of the
    /// learner whose stream it shares (`LearnerInfo::shares_stream_with`: the follow-up's VAE
    /// draws its β-VAE's, so a repetition's two start from the same weights too).
    pub fn learner_seed_identity(&self, images: usize) -> Option<String> {
        self.algo
            .learner()
            .map(|l| self.learner_identity(l.entry().info.stream_name(), images))
    }

    fn learner_identity(&self, learner: &str, images: usize) -> String {
        format!(
            "repr/env={}/learner={learner}/latents={}/images={images}/seed={}",
            self.env, self.latents, self.seed
        )
    }
}

/// All runs of a campaign, in a fixed order (env, algo, variant, sampler, latents, seed,
/// exploration replicate).
/// Learned goal spaces are crossed with `matrix.samplers` and `matrix.latents`; the VAE and
/// RFVAE also with `matrix.variants`. `gaussian` goals need a prior, so they are planned only
/// for the learners that may have one (VAE, RFVAE, external), as in the paper. The position-only
/// engineered goal space is planned only where the outcome has more than the positions.
pub fn plan(cfg: &CampaignConfig) -> Vec<RunSpec> {
    let mut runs = Vec::new();
    for &env in &cfg.matrix.envs {
        for &algo in &cfg.matrix.algos {
            let Some(learner) = algo.learner() else {
                if algo.space() == GoalSpaceKind::EngineeredPosition
                    && !env.spec().has_orientation()
                {
                    // The position is the whole engineered outcome (ArmBall): the run would be
                    // RGE-EFR's, byte for byte.
                    continue;
                }
                for seed in 0..cfg.campaign.reps as u64 {
                    for j in 0..cfg.campaign.explorations as u32 {
                        runs.push(RunSpec::baseline(env, algo, seed).with_exploration(j));
                    }
                }
                continue;
            };
            let variants: &[Variant] = if learner.has_variants() {
                &cfg.matrix.variants
            } else {
                &[Variant::Faithful]
            };
            for &variant in variants {
                for &sampler in &cfg.matrix.samplers {
                    if sampler.needs_prior() && !learner.may_have_prior() {
                        continue;
                    }
                    for l in &cfg.matrix.latents {
                        let latents = l.size(env);
                        for seed in 0..cfg.campaign.reps as u64 {
                            for j in 0..cfg.campaign.explorations as u32 {
                                runs.push(
                                    RunSpec::learned(env, algo, sampler, latents, variant, seed)
                                        .with_exploration(j),
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    runs
}

/// Runs that share a trained representation, in one group each: `items` (each with its run,
/// `spec_of`) grouped by [`RunSpec::representation_identity`], groups in order of first
/// appearance and items in their order. A run without a representation (RPE, RGE-EFR) is a
/// group of its own, with key None. The one grouping of the runner (a representation is fitted
/// once, then its runs run one after the other), the shards ([`shard_groups`]) and
/// `--refresh-diagnostics`.
pub fn representation_groups<'s, T>(
    items: impl IntoIterator<Item = T>,
    spec_of: impl Fn(&T) -> &'s RunSpec,
    images: usize,
) -> Vec<(Option<String>, Vec<T>)> {
    let mut index: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    let mut groups: Vec<(Option<String>, Vec<T>)> = Vec::new();
    for item in items {
        match spec_of(&item).representation_identity(images) {
            Some(key) => match index.get(&key) {
                Some(&g) => groups[g].1.push(item),
                None => {
                    index.insert(key.clone(), groups.len());
                    groups.push((Some(key), vec![item]));
                }
            },
            None => groups.push((None, vec![item])),
        }
    }
    groups
}

/// The representation group of every run of `runs`, numbered in plan order of first
/// appearance ([`representation_groups`]): runs that share a trained representation share a
/// group; every other run is a group of its own. Shards deal these groups round-robin
/// ([`shard`]), so a campaign has at most `groups` non-empty shards.
pub fn shard_groups(runs: &[RunSpec], images: usize) -> Vec<usize> {
    let mut of = vec![0; runs.len()];
    for (g, (_, members)) in representation_groups(0..runs.len(), |&i| &runs[i], images)
        .into_iter()
        .enumerate()
    {
        for i in members {
            of[i] = g;
        }
    }
    of
}

/// A deterministic slice `index` of `count` (0-based) of the plan, for spreading a campaign over
/// machines (`ugl campaign --shard i/n`). Runs that share a trained representation stay in one
/// shard, so no representation is fitted twice; groups are dealt round-robin in plan order
/// ([`shard_groups`]). The shards are disjoint and their union is the whole plan.
pub fn shard(runs: &[RunSpec], images: usize, index: usize, count: usize) -> Vec<RunSpec> {
    assert!(
        index < count,
        "shard index {index} must be below the shard count {count}"
    );
    runs.iter()
        .zip(shard_groups(runs, images))
        .filter(|(_, g)| g % count == index)
        .map(|(spec, _)| spec.clone())
        .collect()
}

/// Parse `i/n` (0 <= i < n).
pub fn parse_shard(s: &str) -> Result<(usize, usize), InvalidValue> {
    let err = || {
        InvalidValue::new(
            "--shard",
            format!("--shard must be i/n with 0 <= i < n (0-based, e.g. 0/4 .. 3/4), got '{s}'"),
        )
    };
    let (i, n) = s.split_once('/').ok_or_else(err)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| err())?,
        n.trim().parse().map_err(|_| err())?,
    );
    if n == 0 || i >= n {
        return Err(err());
    }
    Ok((i, n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::Learner;

    #[test]
    fn identities() {
        let r = RunSpec::baseline(EnvKind::ARMARROW, Algo::RGE_EFR, 3);
        assert_eq!(r.identity(), "env=armarrow/algo=rge-efr/seed=3");
        assert_eq!(r.run_id(), "armarrow.rge-efr.s3");
        assert_eq!(r.representation_identity(10), None);
        let r = RunSpec::learned(
            EnvKind::ARMBALL,
            Algo::rge(Learner::by_name("pca").unwrap()),
            SamplerKind::KDE,
            10,
            Variant::Corrected,
            2,
        );
        assert_eq!(r.variant, None, "PCA has no variants");
        assert_eq!(
            r.identity(),
            "env=armball/algo=rge-pca/sampler=kde/latents=10/seed=2"
        );
        assert_eq!(r.run_id(), "armball.rge-pca.kde.l10.s2");
        let g = RunSpec {
            sampler: SamplerKind::GAUSSIAN,
            ..r.clone()
        };
        assert_eq!(
            r.representation_identity(100),
            g.representation_identity(100)
        );
        let v = RunSpec::learned(
            EnvKind::ARMBALL,
            Algo::rge(Learner::by_name("vae").unwrap()),
            SamplerKind::GAUSSIAN,
            2,
            Variant::Corrected,
            0,
        );
        assert_eq!(
            v.identity(),
            "env=armball/algo=rge-vae/variant=corrected/sampler=gaussian/latents=2/seed=0"
        );
        assert_eq!(v.run_id(), "armball.rge-vae.corrected.gaussian.l2.s0");
        let f = RunSpec {
            variant: Some(Variant::Faithful),
            ..v.clone()
        };
        assert_ne!(v.representation_identity(10), f.representation_identity(10));
        assert_eq!(
            v.learner_seed_identity(10),
            f.learner_seed_identity(10),
            "the variants of a cell are paired"
        );
        assert_eq!(
            RunSpec::learned(
                EnvKind::ARMBALL,
                Algo::rge(Learner::by_name("ae").unwrap()),
                SamplerKind::KDE,
                2,
                Variant::Corrected,
                0
            )
            .run_id(),
            "armball.rge-ae.kde.l2.s0"
        );
    }

    /// The follow-up's VAE draws its β-VAE's stream (a repetition's two networks start from the
    /// same weights and batches) but keeps its own model; every other learner draws its own,
    /// under the identity its committed runs were drawn with.
    #[test]
    fn the_convolutional_vae_draws_the_beta_vaes_stream() {
        let spec = |learner: &str, env| {
            RunSpec::learned(
                env,
                Algo::rge(Learner::by_name(learner).unwrap()),
                SamplerKind::GAUSSIAN,
                10,
                Variant::Faithful,
                3,
            )
        };
        // (learner, its β twin, environment, the learner's stream and model identities).
        for (learner, twin, env, stream, model) in [
            (
                "conv-vae",
                "conv-bvae",
                EnvKind::ARMBALLS_CORL,
                "repr/env=armballs-corl/learner=conv-bvae/latents=10/images=100/seed=3",
                "repr/env=armballs-corl/learner=conv-vae/latents=10/images=100/seed=3",
            ),
            (
                "vae",
                "bvae",
                EnvKind::ARMBALL,
                "repr/env=armball/learner=vae/latents=10/images=100/seed=3",
                "repr/env=armball/learner=vae/latents=10/images=100/seed=3/variant=faithful",
            ),
        ] {
            let (a, b) = (spec(learner, env), spec(twin, env));
            assert_eq!(a.learner_seed_identity(100).as_deref(), Some(stream));
            assert_eq!(a.representation_identity(100).as_deref(), Some(model));
            assert_ne!(
                a.representation_identity(100),
                b.representation_identity(100)
            );
            let shared = learner.starts_with("conv");
            assert_eq!(
                a.learner_seed_identity(100) == b.learner_seed_identity(100),
                shared,
                "{learner} and {twin}"
            );
        }
    }

    /// The position-only engineered goal space is a condition only where the outcome has an
    /// orientation (ArmArrow); on ArmBall it would repeat RGE-EFR's runs.
    #[test]
    fn the_position_only_goal_space_is_planned_where_there_is_an_angle() {
        let text = "[campaign]\nname = \"t\"\nreps = 1\n[matrix]\n\
                    envs = [\"armball\", \"armarrow\", \"armballs\"]\n\
                    algos = [\"rge-efr\", \"rge-efr-position\"]\n";
        let cfg = CampaignConfig::from_toml(text, std::path::Path::new("t.toml")).unwrap();
        let ids: Vec<String> = plan(&cfg).iter().map(|r| r.run_id()).collect();
        assert_eq!(
            ids,
            [
                "armball.rge-efr.s0",
                "armarrow.rge-efr.s0",
                "armarrow.rge-efr-position.s0",
                "armballs.rge-efr.s0",
            ]
        );
    }

    /// Exploration replicates explore one fitted goal space with their own streams: replicate
    /// 0 is the run without replicates; the others differ in identity, id and exploration
    /// streams, never in the fitted representation.
    #[test]
    fn exploration_replicates_share_the_fit_and_not_the_streams() {
        let text = "[campaign]\nname = \"t\"\nreps = 2\nexplorations = 3\n[matrix]\n\
                    envs = [\"armball\"]\nalgos = [\"rpe\", \"rge-pca\"]\nlatents = [2]\n";
        let cfg = CampaignConfig::from_toml(text, std::path::Path::new("t.toml")).unwrap();
        let ids: Vec<String> = plan(&cfg).iter().map(|r| r.run_id()).collect();
        assert_eq!(
            ids,
            [
                "armball.rpe.s0",
                "armball.rpe.s0.e1",
                "armball.rpe.s0.e2",
                "armball.rpe.s1",
                "armball.rpe.s1.e1",
                "armball.rpe.s1.e2",
                "armball.rge-pca.kde.l2.s0",
                "armball.rge-pca.kde.l2.s0.e1",
                "armball.rge-pca.kde.l2.s0.e2",
                "armball.rge-pca.kde.l2.s1",
                "armball.rge-pca.kde.l2.s1.e1",
                "armball.rge-pca.kde.l2.s1.e2",
            ]
        );
        let runs = plan(&cfg);
        let (a, b) = (&runs[6], &runs[7]);
        assert_eq!(
            a.identity(),
            "env=armball/algo=rge-pca/sampler=kde/latents=2/seed=0"
        );
        assert_eq!(
            b.identity(),
            "env=armball/algo=rge-pca/sampler=kde/latents=2/seed=0/exploration=1"
        );
        assert_ne!(a.exploration_identity(), b.exploration_identity());
        assert_eq!(a.representation_identity(10), b.representation_identity(10));
        assert_eq!(a.learner_seed_identity(10), b.learner_seed_identity(10));
        assert_eq!(
            runs[1].identity(),
            "env=armball/algo=rpe/seed=0/exploration=1"
        );
        // Shards keep the replicates of a fit together.
        for i in 0..2 {
            let s = shard(&runs, 10, i, 2);
            let fits: Vec<_> = s
                .iter()
                .filter_map(|r| r.representation_identity(10))
                .collect();
            for f in &fits {
                assert_eq!(fits.iter().filter(|g| *g == f).count(), 3);
            }
        }
    }

    #[test]
    fn gaussian_goals_and_variants_only_where_they_apply() {
        let text = "[campaign]\nname = \"t\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
                    algos = [\"rge-pca\", \"rge-ae\", \"rge-vae\"]\nsamplers = [\"kde\", \"gaussian\"]\n\
                    latents = [10]\nvariants = [\"faithful\", \"corrected\"]\n";
        let cfg = CampaignConfig::from_toml(text, std::path::Path::new("t.toml")).unwrap();
        let ids: Vec<String> = plan(&cfg).iter().map(|r| r.run_id()).collect();
        assert_eq!(
            ids,
            [
                "armball.rge-pca.kde.l10.s0",
                "armball.rge-ae.kde.l10.s0",
                "armball.rge-vae.faithful.kde.l10.s0",
                "armball.rge-vae.faithful.gaussian.l10.s0",
                "armball.rge-vae.corrected.kde.l10.s0",
                "armball.rge-vae.corrected.gaussian.l10.s0",
            ]
        );
    }

    #[test]
    fn shards_partition_the_plan_and_keep_groups_together() {
        let text = "[campaign]\nname = \"t\"\nreps = 3\n[matrix]\nenvs = [\"armball\", \"armarrow\"]\n\
                    algos = [\"rpe\", \"rge-pca\", \"rge-isomap\"]\nsamplers = [\"kde\", \"gaussian\"]\nlatents = [10, \"true\"]\n";
        let cfg = CampaignConfig::from_toml(text, std::path::Path::new("t.toml")).unwrap();
        let all = plan(&cfg);
        for n in [1, 2, 3, 7, 100] {
            let mut union: Vec<RunSpec> = (0..n).flat_map(|i| shard(&all, 10, i, n)).collect();
            assert_eq!(
                union.len(),
                all.len(),
                "n = {n}: shards are disjoint and cover the plan"
            );
            union.sort();
            let mut sorted = all.clone();
            sorted.sort();
            assert_eq!(union, sorted);
            for i in 0..n {
                // The samplers of a cell are in the same shard.
                for r in shard(&all, 10, i, n) {
                    let mates = all.iter().filter(|o| {
                        o.algo.learner().is_some()
                            && o.representation_identity(10) == r.representation_identity(10)
                    });
                    for m in mates {
                        assert!(shard(&all, 10, i, n).contains(m));
                    }
                }
            }
        }
        assert_eq!(parse_shard("1/4"), Ok((1, 4)));
        assert!(
            parse_shard("4/4").is_err()
                && parse_shard("1").is_err()
                && parse_shard("a/b").is_err()
                && parse_shard("0/0").is_err()
        );
    }
}
