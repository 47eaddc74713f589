//! Executing one run: environment + explorer (+ goal sampler in a learned space), then the
//! results store.

use std::path::Path;
use std::time::Instant;

use super::config::UglConfig;
use super::machine::{cpu_info, host_name};
use super::plan::RunSpec;
use super::store::{self, Manifest, Summary};
use crate::env::{Environment, make_env};
use crate::explore::{
    Algo, EngineeredGoals, EngineeredSpace, ExplorationLog, ExploreConfig, Explorer, GoalModule,
    GoalSource, GoalSpaceKind, LearnedSpace, Learner, Modules, OutcomeSpace, Rpe, SamplerKind,
    goal_modules,
};
use crate::goals::{GoalSampler, TrainingLatents};
use crate::repr::{GaussianPrior, Latents, ReprError};
use crate::seed::{Component, run_seed, stream};
use ugl_types::RunDiscovery;

use super::context::RunContext;
use super::error::RunError;
use super::fit::{Representation, fit_representation};
use super::provenance::{crate_versions, git_revision_for};
use crate::explore::mixed::{MixedGoals, MixedSpace};

/// What an exploration produced, with its timings.
pub struct Explored {
    pub log: ExplorationLog,
    /// Seconds spent rendering and encoding outcomes (learned goal spaces).
    pub encode_s: Option<f64>,
}

/// Run the exploration of one spec (no I/O). Learned goal spaces need their representation.
pub fn explore(
    spec: &RunSpec,
    ctx: &RunContext,
    repr: Option<&mut Representation>,
) -> Result<Explored, RunError> {
    let seed = run_seed(ctx.campaign_seed, &spec.exploration_identity());
    let env = make_env(spec.env, ctx.env);
    let env: &dyn Environment = env.as_ref();
    let d = env.state_dim();
    let run_err = |source| RunError::Repr {
        run: spec.run_id(),
        source,
    };
    let explore_err = |source| RunError::Explore {
        run: spec.run_id(),
        source,
    };
    let strategy = spec.algo.strategy();
    match spec.algo.space() {
        GoalSpaceKind::None => Ok(Explored {
            log: Rpe.explore(env, ctx.explore, seed).map_err(explore_err)?,
            encode_s: None,
        }),
        GoalSpaceKind::Engineered
        | GoalSpaceKind::EngineeredPosition
        | GoalSpaceKind::EngineeredMixed => {
            let (mut space, goals): (Box<dyn OutcomeSpace>, Box<dyn GoalSource>) =
                match spec.algo.space() {
                    GoalSpaceKind::Engineered => (
                        Box::new(EngineeredSpace::new(d)),
                        Box::new(EngineeredGoals::new(d, spec.env.objects())),
                    ),
                    GoalSpaceKind::EngineeredMixed => {
                        let objects: Vec<_> =
                            spec.env.objects().into_iter().map(|(_, r)| r).collect();
                        (
                            Box::new(MixedSpace::new(d, &objects)),
                            Box::new(MixedGoals::new(d, &objects)),
                        )
                    }
                    _ => {
                        let dims = spec.env.spec().position_dims();
                        let n = dims.len();
                        (
                            Box::new(EngineeredSpace::of(dims)),
                            Box::new(EngineeredGoals::new(n, Vec::new())),
                        )
                    }
                };
            let explore = ctx.mge.engineered_explore(ctx.explore);
            let log = strategy
                .explorer(space.as_mut(), goals.as_ref(), ctx.mge)
                .map_err(run_err)?
                .explore(env, &explore, seed)
                .map_err(explore_err)?;
            Ok(Explored {
                log,
                encode_s: None,
            })
        }
        GoalSpaceKind::Learned(_) => {
            let repr = repr.ok_or_else(|| {
                run_err(ReprError::InvalidInput(
                    "no representation was fitted".into(),
                ))
            })?;
            let goals = LearnedGoals {
                dim: repr.encoder.latents(),
                spread: module_order(repr),
                train: &repr.train,
                prior: repr.encoder.prior(),
                sampler: spec.sampler,
                algo: spec.algo,
            };
            repr.encoder.begin_run(stream(seed, Component::Encoding));
            let mut space = LearnedSpace::new(env, repr.encoder.as_mut());
            let log = strategy
                .explorer(&mut space, &goals, ctx.mge)
                .map_err(run_err)?
                .explore(env, ctx.explore, seed)
                .map_err(explore_err)?;
            if let Some(e) = space.error.take() {
                return Err(run_err(e));
            }
            Ok(Explored {
                log,
                encode_s: Some(space.encode_s),
            })
        }
    }
}

/// The goals of a learned goal space: the KDE of the training encodings or the model's prior
/// (`sampler`), and modules of latents ordered by their spread.
struct LearnedGoals<'r> {
    dim: usize,
    /// What orders the latents into modules ([`module_order`]).
    spread: Vec<f64>,
    train: &'r Latents,
    prior: Option<GaussianPrior>,
    sampler: SamplerKind,
    algo: Algo,
}

impl GoalSource for LearnedGoals<'_> {
    fn modules(&self, choice: Modules, module_size: usize) -> Result<Vec<GoalModule>, ReprError> {
        goal_modules(choice, self.dim, None, &self.spread, module_size)
            .map_err(|e| ReprError::InvalidInput(e.to_string()))
    }

    /// Over every latent (`dims` None) or over one module's latents (the KDE of those latents
    /// of the training encodings; the prior's marginal).
    fn sampler(&self, dims: Option<&[usize]>) -> Result<Box<dyn GoalSampler>, ReprError> {
        let train = self.train;
        let algo = self.algo.to_string();
        let Some(dims) = dims else {
            return self.sampler.build(&TrainingLatents {
                latents: train,
                prior: self.prior.as_ref(),
                algo: &algo,
            });
        };
        let module = Latents {
            n: train.n,
            latents: dims.len(),
            data: (0..train.n)
                .flat_map(|i| dims.iter().map(move |&k| train.row(i)[k]))
                .collect(),
        };
        let prior = self.prior.as_ref().map(|p| GaussianPrior {
            mean: dims.iter().map(|&k| p.mean[k]).collect(),
            std: dims.iter().map(|&k| p.std[k]).collect(),
        });
        self.sampler.build(&TrainingLatents {
            latents: &module,
            prior: prior.as_ref(),
            algo: &algo,
        })
    }
}

/// What orders a representation's latents into modules ([`goal_modules`], largest first): the
/// follow-up's criterion, each latent's mean KL divergence from the prior on the 1000 held-out
/// images, where the encoder has a posterior and the latent-quality measure recorded it
/// (`latent_quality.kl_per_latent`: the convolutional networks, on scenes with several
/// objects); else the variance of its training encodings, which every learner has (a collapsed
/// latent has none).
fn module_order(repr: &Representation) -> Vec<f64> {
    match repr.quality.as_ref().map(|q| &q.kl_per_latent) {
        Some(kl) if !kl.is_empty() && kl.len() == repr.train.latents => kl.clone(),
        _ => latent_spread(&repr.train),
    }
}

/// The spread of each latent over the training encodings (its variance).
fn latent_spread(train: &Latents) -> Vec<f64> {
    let (n, d) = (train.n as f64, train.latents);
    (0..d)
        .map(|k| {
            let mean = (0..train.n).map(|i| train.row(i)[k]).sum::<f64>() / n;
            (0..train.n)
                .map(|i| (train.row(i)[k] - mean).powi(2))
                .sum::<f64>()
                / n
        })
        .collect()
}

/// The summary of a finished log.
pub fn summarize(spec: &RunSpec, log: &ExplorationLog) -> Summary {
    let last = log.checkpoints.last().expect("at least one checkpoint");
    Summary {
        run: spec.run_id(),
        final_klc: last.klc,
        n_moved: last.n_moved,
        coverage: last.coverage,
    }
}

/// Execute one run and store it in `out`; returns its summary. A learned goal space is fitted
/// first unless `repr` is given (campaigns share one fit between samplers).
pub fn execute(
    spec: &RunSpec,
    ctx: &RunContext,
    out: &Path,
    repr: Option<&mut Representation>,
) -> Result<Summary, RunError> {
    let mut own: Option<Representation> = None;
    let repr = match (spec.algo.learner(), repr) {
        (None, _) => None,
        (Some(_), Some(r)) => Some(r),
        (Some(_), None) => {
            let fitted = fit_representation(spec, ctx).map_err(|source| RunError::Repr {
                run: spec.run_id(),
                source,
            })?;
            Some(own.insert(fitted))
        }
    };
    let fit_s = repr.as_ref().map(|r| r.fit_s);
    let learner_fit_s = repr.as_ref().and_then(|r| r.encoder.reported_fit_s());
    let learner_name = repr.as_ref().map(|r| r.learner_name.clone());
    let train = repr.as_ref().and_then(|r| r.training.clone());
    let latent_quality = repr.as_ref().and_then(|r| r.quality.clone());
    let t0 = Instant::now();
    let explored = explore(spec, ctx, repr)?;
    let wall_s = t0.elapsed().as_secs_f64();
    let log = explored.log;
    let summary = summarize(spec, &log);
    // What the run discovered, recorded in its manifest so that the outcomes file need not be
    // kept (`ugl_types::discovery`).
    let discovery = match RunDiscovery::measure(spec.env.spec(), &store::outcomes_of(&log)) {
        Ok(d) => d,
        Err(e) => {
            tracing::warn!(
                "run {}: its discovery measures cannot be computed ({e}); the report will read \
                 its outcomes file",
                spec.run_id()
            );
            None
        }
    };
    let paper = ExploreConfig::default();
    let mut notes = Vec::new();
    if ctx.explore.epochs < paper.epochs {
        notes.push(format!(
            "{} exploration epochs instead of the paper's {}",
            ctx.explore.epochs, paper.epochs
        ));
    }
    if spec.algo.learner().is_some() && ctx.ugl.images < UglConfig::default().images {
        notes.push(format!(
            "{} UGL images instead of the paper's {}",
            ctx.ugl.images,
            UglConfig::default().images
        ));
    }
    if let Some(l) = spec.algo.learner()
        && let Ok(params) = ctx.learners.params(l)
    {
        notes.extend(params.deviations(spec.variant));
    }
    let manifest = Manifest {
        run_id: spec.run_id(),
        identity: spec.identity(),
        env: spec.env.name().into(),
        algo: spec.algo.name().into(),
        sampler: spec.sampler.name().into(),
        latents: spec.latents,
        variant: spec.variant.map(|v| v.name()).unwrap_or("none").into(),
        learner: learner_name,
        seed: spec.seed,
        exploration: spec.exploration,
        run_seed: run_seed(ctx.campaign_seed, &spec.exploration_identity()),
        campaign: ctx.campaign.into(),
        role: ctx.role.clone(),
        campaign_seed: ctx.campaign_seed,
        profile: ctx.harness.profile.into(),
        config_hash: ctx.config_hash(spec),
        explore: serde_json::to_value(ctx.explore).expect("serialisable"),
        env_config: serde_json::to_value(ctx.env).expect("serialisable"),
        ugl: spec
            .algo
            .learner()
            .map(|_| serde_json::to_value(ctx.ugl).expect("serialisable")),
        reduced_budget: !notes.is_empty(),
        budget_note: notes.join("; "),
        git_revision: git_revision_for(out),
        crate_versions: crate_versions(),
        toolchain: env!("UGL_RUSTC_VERSION").into(),
        threads: ctx.threads,
        wall_s,
        fit_s,
        learner_fit_s,
        encode_s: explored.encode_s,
        train,
        external: spec
            .algo
            .learner()
            .is_some_and(Learner::is_external)
            .then(|| serde_json::to_value(ctx.learners.external()).expect("serialisable")),
        host: host_name().into(),
        cpu: Some(cpu_info().clone()),
        latent_quality,
        summary: summary.clone(),
        discovery,
        // Filled in by `write_run` from the bytes it writes.
        discovery_blake3: None,
        files: None,
    };
    store::write_run(out, spec, &log, &manifest)?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repr::{Encoder, ImageSet};

    struct NoEncoder;
    impl Encoder for NoEncoder {
        fn latents(&self) -> usize {
            3
        }
        fn encode(&mut self, _: &ImageSet) -> Result<Latents, ReprError> {
            Err(ReprError::InvalidInput("not used".into()))
        }
    }

    /// The latents are ordered by their KL from the prior where the measure recorded it, else
    /// by the variance of their training encodings.
    #[test]
    fn modules_follow_the_per_latent_kl_where_there_is_one() {
        let quality = |kl: &[f64]| -> ugl_types::LatentQuality {
            serde_json::from_value(serde_json::json!({
                "targets": [], "linear_r2": [], "knn_r2": [], "linear_r2_mean": 0.0,
                "knn_r2_mean": 0.0, "n_train": 4, "n_heldout": 4, "k": 1, "kl_per_latent": kl,
            }))
            .unwrap()
        };
        // Variances 0, 1.25, 5 (latent 2 spreads most); KL puts latent 0 first.
        let train = Latents {
            n: 4,
            latents: 3,
            data: vec![1.0, 0.0, 0.0, 1.0, 1.0, 2.0, 1.0, 2.0, 4.0, 1.0, 3.0, 6.0],
        };
        let mut repr = Representation {
            encoder: Box::new(NoEncoder),
            train,
            fit_s: 0.0,
            learner_name: "x".into(),
            training: None,
            quality: Some(quality(&[3.1, 0.0, 2.9])),
        };
        assert_eq!(module_order(&repr), [3.1, 0.0, 2.9]);
        repr.quality = Some(quality(&[]));
        assert_eq!(module_order(&repr), [0.0, 1.25, 5.0]);
        repr.quality = None;
        assert_eq!(module_order(&repr), [0.0, 1.25, 5.0]);
    }
}
