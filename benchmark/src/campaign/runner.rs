//! Executes runs: environment + explorer, then the results store.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use serde::Serialize;
use thiserror::Error;

use super::config::{CampaignConfig, LearnersConfig, UglConfig};
use super::goal_space;
use super::machine::{cpu_info, host_name};
use super::plan::{RunSpec, plan};
use super::store::{self, Manifest, StoreError, Summary};
use crate::env::{EnvConfig, Environment, make_env};
use crate::explore::{
    Algo, EngineeredSpace, ExplorationLog, ExploreConfig, LearnedSpace, Learner, MgeConfig,
    SamplerKind, goal_modules, run_mge, run_rge, run_rpe,
};
use crate::goals::{GaussianGoals, GoalSampler, KdeGoals, UniformGoals};
use crate::repr::cache::{CacheEntry, ModelCache};
use crate::repr::dataset::{dataset_identity, generate};
use crate::repr::evidence::TrainingEvidence;
use crate::repr::external::LineSink;
use crate::repr::neural::{self, TrainProgress, Variant};
use crate::repr::quality::{self, LatentQuality};
use crate::repr::{Encoder, FitContext, ImageSet, Latents, ReprError, RepresentationLearner};
use crate::seed::{Component, run_seed, stream};

/// Bumped whenever a change alters results for the same configuration.
/// 2: exploration streams of learned goal spaces derive from
/// [`RunSpec::exploration_identity`] (paired across learners), and a stochastic encoder draws
/// its noise from the run's own stream (order-independent results); the KDE's square root of
/// its covariance comes from faer's symmetric eigen-solver (was: cyclic Jacobi).
/// 3: the neural learners train on the host engine by default (`engine = "host"`: other
/// summation orders than burn's), and gemm/faer use their AVX-512 kernels where the CPU has them.
pub const RESULTS_VERSION: u32 = 3;

/// Errors of a run or campaign.
#[derive(Debug, Error)]
pub enum RunError {
    #[error(transparent)]
    Store(#[from] StoreError),
    #[error("cannot start the worker pool: {0}")]
    Pool(String),
    #[error("run {run}: {source}")]
    Repr { run: String, source: ReprError },
    /// A run whose representation was not fitted because the same fit failed before: in its
    /// group (the runs sharing the representation), or, for an external learner, in another
    /// seed of the same cell (a failing program is started once, not once per run).
    #[error("run {run}: not run: the fit of its goal space failed for run {first} (error above)")]
    FitFailedBefore { run: String, first: String },
    #[error(
        "interrupted: {done} of {total} runs finished and stored; rerun the same command to resume"
    )]
    Interrupted { done: usize, total: usize },
}

/// What a run depends on, hashed into its config hash.
#[derive(Serialize)]
struct HashInput<'a> {
    results_version: u32,
    identity: &'a str,
    campaign_seed: u64,
    explore: &'a ExploreConfig,
    env: &'a EnvConfig,
    #[serde(skip_serializing_if = "Option::is_none")]
    ugl: Option<&'a UglConfig>,
    #[serde(skip_serializing_if = "Option::is_none")]
    learner: Option<serde_json::Value>,
    /// Modular explorations only.
    #[serde(skip_serializing_if = "Option::is_none")]
    mge: Option<&'a MgeConfig>,
}

/// Receives the training progress of neural representations: the representation's label
/// (`armball.rge-vae.faithful.l10.s0`) and the progress.
pub type TrainSink = dyn Fn(&str, TrainProgress) + Send + Sync;

/// Receives the stderr lines of external learners while they fit: the representation's label,
/// then `Some(line)` for each line and `None` when the fit is over.
pub type MessageSink = dyn Fn(&str, Option<&str>) + Send + Sync;

/// Everything needed to execute one run.
#[derive(Clone)]
pub struct RunContext<'a> {
    pub campaign: &'a str,
    pub campaign_seed: u64,
    pub profile: &'a str,
    pub explore: &'a ExploreConfig,
    pub env: &'a EnvConfig,
    pub ugl: &'a UglConfig,
    pub learners: &'a LearnersConfig,
    /// Modular goal exploration's constants (`mge-*` algorithms).
    pub mge: &'a MgeConfig,
    pub threads: usize,
    /// Where trained neural models are kept (None: always train).
    pub cache: Option<&'a ModelCache>,
    /// Training progress of neural representations.
    pub train_progress: Option<Arc<TrainSink>>,
    /// Threads of a neural training: 0 = the calling pool's (a campaign's workers each have a
    /// pool of `cores / jobs` threads: two 1-thread trainings side by side beat one 2-thread
    /// training on 2 cores; STACK-NOTES.md).
    pub train_threads: usize,
    /// Where an external learner's stderr is kept: `<log_dir>/<representation label>.learner.log`
    /// (the results directory; None: not kept).
    pub log_dir: Option<&'a Path>,
    /// External learners' stderr lines, as they come.
    pub learner_messages: Option<Arc<MessageSink>>,
    /// Neural trainings save a checkpoint in the model cache every this many iterations
    /// (0: never); a killed training resumes from its latest one, bit-identically.
    pub checkpoint_every: usize,
}

impl RunContext<'_> {
    /// The config hash of a run: BLAKE3 of its identity, campaign seed and every constant.
    pub fn config_hash(&self, spec: &RunSpec) -> String {
        let identity = spec.identity();
        let input = HashInput {
            results_version: RESULTS_VERSION,
            identity: &identity,
            campaign_seed: self.campaign_seed,
            explore: self.explore,
            env: self.env,
            // Learned goal spaces also depend on the UGL stage; baseline hashes do not.
            ugl: spec.algo.learner().map(|_| self.ugl),
            learner: spec
                .algo
                .learner()
                .map(|l| self.learners.hash_value(l, spec.variant)),
            mge: spec.algo.modules().map(|_| self.mge),
        };
        let json = serde_json::to_vec(&input).expect("config serialises");
        blake3::hash(&json).to_hex().to_string()
    }
}

/// A fitted representation, shared by the runs that use it (every sampler of a cell).
pub struct Representation {
    pub encoder: Box<dyn Encoder>,
    /// Encodings of the training images (the KDE is fitted on them).
    pub train: Latents,
    /// Seconds to generate the data set and fit.
    pub fit_s: f64,
    /// Name of the learner (the external program's configured name for `external`).
    pub learner_name: String,
    /// Training details of a neural representation.
    pub training: Option<TrainInfo>,
    /// How well the true object state can be read off the latents (None if it could not be
    /// measured; the reason is logged).
    pub quality: Option<LatentQuality>,
}

/// Held-out images of the latent-quality measure.
pub const QUALITY_HELDOUT: usize = 1000;

/// Measure the latent quality of a fitted encoder (measure version
/// [`quality::MEASURE_VERSION`]): regressions fitted on the encodings of every training image,
/// scored on [`QUALITY_HELDOUT`] fresh images from the data set's held-out stream. A stochastic
/// encoder draws its noise from that stream too, and every run resets it
/// ([`Encoder::begin_run`]), so this changes no run's results.
pub fn measure_quality(
    encoder: &mut dyn Encoder,
    env: &dyn Environment,
    data: &crate::repr::dataset::UglDataset,
    ds_seed: u64,
) -> Result<LatentQuality, ReprError> {
    let d = env.state_dim();
    let mut rng = stream(ds_seed, Component::HeldOut);
    let heldout = generate(env, QUALITY_HELDOUT, &mut rng)?;
    encoder.begin_run(rng);
    let z_train = encoder.encode(&data.images)?;
    let z_heldout = encoder.encode(&heldout.images)?;
    let (y_train, names) = quality::targets(&data.states, d);
    let (y_heldout, _) = quality::targets(&heldout.states, d);
    let mut q = quality::latent_quality(&z_train, &y_train, &z_heldout, &y_heldout, names)?;
    let objects = env.kind().objects();
    if objects.len() > 1 {
        q.per_latent = quality::per_latent_r2(
            &data.states,
            &z_train,
            &heldout.states,
            &z_heldout,
            d,
            &objects,
        );
    }
    Ok(q)
}

/// How a trained network was obtained, recorded in the manifests of its runs.
#[derive(Clone, Debug, Serialize)]
pub struct TrainInfo {
    /// The complete training configuration (the learner's parameters, resolved).
    pub config: serde_json::Value,
    /// The recorded loss curve, `(iteration, mini-batch loss)`.
    pub losses: Vec<(usize, f64)>,
    /// `hit` (loaded from the model cache), `miss` (trained and stored), `rebuilt` (a cache
    /// file was invalid: trained again and overwritten) or `off` (no cache).
    pub cache: &'static str,
    /// The cache key (BLAKE3 of everything the model depends on).
    pub key: String,
    /// The reconstruction loss against the mean-image loss (the plateau) of the first training
    /// images, and whether the network left it ([`TrainingEvidence`]).
    pub evidence: TrainingEvidence,
}

/// Build the learner of an algorithm from its checked `[learners.NAME]` parameters (the
/// registry's entry parses them); `variant` is used by the learners that have variants.
pub fn make_learner(
    learner: Learner,
    cfg: &LearnersConfig,
    variant: Option<Variant>,
) -> Result<Box<dyn RepresentationLearner>, ReprError> {
    Ok(cfg
        .params(learner)
        .map_err(ReprError::InvalidInput)?
        .build(variant))
}

/// The model-cache key of a representation: BLAKE3 of everything it depends on (the
/// environment and its constants, learner, variant, latents, data-set size and seed, learner
/// seed, the learner's parameters (`identity`, [`crate::repr::registry::LearnerParams`]),
/// backend, and the cache and results versions).
pub fn model_key(spec: &RunSpec, ctx: &RunContext, identity: &serde_json::Value) -> String {
    let images = ctx.ugl.images;
    let input = serde_json::json!({
        "cache_format": crate::repr::cache::FORMAT_VERSION,
        "results_version": RESULTS_VERSION,
        "env": spec.env.name(),
        "env_config": ctx.env,
        "learner": spec.algo.learner().map(|l| l.name()),
        "variant": spec.variant.map(|v| v.name()),
        "latents": spec.latents,
        "images": images,
        "dataset_seed": run_seed(ctx.campaign_seed, &dataset_identity(spec.env, images, spec.seed)),
        "learner_seed": spec.learner_seed_identity(images).map(|id| run_seed(ctx.campaign_seed, &id)),
        "config": identity,
        "backend": neural::BACKEND,
    });
    let json = serde_json::to_vec(&input).expect("key serialises");
    blake3::hash(&json).to_hex().to_string()
}

/// What the harness offers the fit of `spec`'s representation: progress bars and messages
/// under its label, checkpoints in the model cache under `key`, the training's threads.
fn fit_context(
    spec: &RunSpec,
    ctx: &RunContext,
    key: &str,
    cache: Option<&ModelCache>,
) -> FitContext {
    let label = representation_label(spec);
    FitContext {
        progress: ctx.train_progress.as_ref().map(|sink| {
            let (sink, label) = (sink.clone(), label.clone());
            Arc::new(move |p: TrainProgress| sink(&label, p)) as neural::ProgressFn
        }),
        checkpoint: cache
            .filter(|_| ctx.checkpoint_every > 0)
            .map(|c| neural::CheckpointSpec {
                dir: c.dir.clone(),
                key: key.to_string(),
                every: ctx.checkpoint_every,
            }),
        threads: ctx.train_threads,
        // An external program's stderr: a log file beside the runs, and its lines to the caller.
        log_file: ctx.log_dir.map(|d| d.join(format!("{label}.learner.log"))),
        messages: ctx.learner_messages.as_ref().map(|sink| {
            let (sink, label) = (sink.clone(), label.clone());
            LineSink(Arc::new(move |line| sink(&label, Some(line))))
        }),
    }
}

/// Fit `spec`'s representation on `images`, or load it from the model cache (learners whose
/// encoders persist): the one fit path of every learner. Returns the encoder, the training
/// latents, for a trained network how it was obtained, and the learner's name in results (an
/// external program's configured name).
fn fit_or_load(
    spec: &RunSpec,
    ctx: &RunContext,
    learner: Learner,
    images: &ImageSet,
    rng: &mut crate::seed::Stream,
) -> Result<(Box<dyn Encoder>, Latents, Option<TrainInfo>, String), ReprError> {
    let params = ctx
        .learners
        .params(learner)
        .map_err(ReprError::InvalidInput)?;
    let identity = params.identity(spec.variant);
    let fitter = params.build(spec.variant);
    let key = model_key(spec, ctx, &identity);
    let cache = ctx.cache.filter(|_| fitter.persists());
    let mut status = "off";
    let cached = match cache.map(|c| c.load(&key, |bytes| fitter.load(&key, bytes))) {
        Some(CacheEntry::Hit(enc)) => {
            status = "hit";
            Some(enc)
        }
        Some(CacheEntry::Invalid(why)) => {
            tracing::warn!("model cache: ignoring an invalid file ({why}); fitting again");
            status = "rebuilt";
            None
        }
        Some(CacheEntry::Miss) => {
            status = "miss";
            None
        }
        None => None,
    };
    let (encoder, z) = match cached {
        Some(mut enc) => {
            let z = enc.training_latents(images)?;
            (enc, z)
        }
        None => {
            if let Some(c) = cache {
                c.check_writable()?;
            }
            let fit_ctx = fit_context(spec, ctx, &key, cache);
            let fitted = fitter.fit_in(images, spec.latents, rng, &fit_ctx);
            if let Some(sink) = &ctx.learner_messages {
                sink(&representation_label(spec), None);
            }
            let (enc, z) = fitted?;
            if let Some(c) = cache
                && let Some(bytes) = enc.save(&key)
            {
                c.store(&key, &bytes)?;
            }
            (enc, z)
        }
    };
    let info = encoder.training_record(images).map(|r| TrainInfo {
        config: identity,
        losses: r.losses,
        cache: status,
        key,
        evidence: r.evidence,
    });
    Ok((encoder, z, info, fitter.name().to_string()))
}

/// A short label of a run's representation, for progress bars and messages:
/// `armball.rge-vae.faithful.l10.s0`.
pub fn representation_label(spec: &RunSpec) -> String {
    let v = spec.variant.map(|v| format!(".{v}")).unwrap_or_default();
    format!(
        "{}.{}{v}.l{}.s{}",
        spec.env, spec.algo, spec.latents, spec.seed
    )
}

/// Generate the UGL data set of the spec's repetition and fit its learner.
pub fn fit_representation(spec: &RunSpec, ctx: &RunContext) -> Result<Representation, ReprError> {
    fit_with_data(spec, ctx).map(|(r, _, _)| r)
}

/// [`fit_representation`], also returning the UGL data set it was fitted on and its seed.
pub fn fit_with_data(
    spec: &RunSpec,
    ctx: &RunContext,
) -> Result<(Representation, crate::repr::dataset::UglDataset, u64), ReprError> {
    let learner = spec.algo.learner().ok_or_else(|| {
        ReprError::InvalidInput(format!("{} learns no representation", spec.algo))
    })?;
    let t0 = Instant::now();
    let env = make_env(spec.env, ctx.env);
    let ds_seed = run_seed(
        ctx.campaign_seed,
        &dataset_identity(spec.env, ctx.ugl.images, spec.seed),
    );
    let data = generate(
        env.as_ref(),
        ctx.ugl.images,
        &mut stream(ds_seed, Component::Dataset),
    )?;
    let seed_id = spec
        .learner_seed_identity(ctx.ugl.images)
        .expect("learned algorithm");
    let mut rng = stream(run_seed(ctx.campaign_seed, &seed_id), Component::Learner);
    let (mut encoder, train, info, learner_name) =
        fit_or_load(spec, ctx, learner, &data.images, &mut rng)?;
    let quality = match measure_quality(encoder.as_mut(), env.as_ref(), &data, ds_seed) {
        Ok(q) => Some(q),
        Err(e) => {
            tracing::warn!("{}: latent quality not measured: {e}", spec.run_id());
            None
        }
    };
    let repr = Representation {
        encoder,
        train,
        fit_s: t0.elapsed().as_secs_f64(),
        learner_name,
        training: info,
        quality,
    };
    Ok((repr, data, ds_seed))
}

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
    let mge_err = |m: String| run_err(ReprError::InvalidInput(m));
    let log = match spec.algo {
        Algo::Rpe => run_rpe(env, ctx.explore, seed),
        Algo::RgeEfr => run_rge(
            env,
            &mut EngineeredSpace::new(d),
            &mut UniformGoals::unit(d),
            ctx.explore,
            seed,
        ),
        Algo::MgeEfr(m) => {
            let objects = spec.env.objects();
            let modules =
                goal_modules(m, d, Some(&objects), &[], ctx.mge.module_size).map_err(mge_err)?;
            let mut samplers: Vec<Box<dyn GoalSampler>> = modules
                .iter()
                .map(|g| Box::new(UniformGoals::unit(g.dims.len())) as Box<dyn GoalSampler>)
                .collect();
            run_mge(
                env,
                &mut EngineeredSpace::new(d),
                &modules,
                &mut samplers,
                m,
                ctx.explore,
                ctx.mge,
                seed,
            )
            .map_err(mge_err)?
        }
        Algo::Rge(_) | Algo::Mge(..) => {
            let repr = repr.ok_or_else(|| {
                run_err(ReprError::InvalidInput(
                    "no representation was fitted".into(),
                ))
            })?;
            let dim = repr.encoder.latents();
            let modules = match spec.algo.modules() {
                None => None,
                Some(m) => Some(
                    goal_modules(
                        m,
                        dim,
                        None,
                        &latent_spread(&repr.train),
                        ctx.mge.module_size,
                    )
                    .map_err(mge_err)?,
                ),
            };
            let mut samplers: Vec<Box<dyn GoalSampler>> = match &modules {
                None => vec![goal_sampler(spec, repr, None).map_err(run_err)?],
                Some(ms) => ms
                    .iter()
                    .map(|g| goal_sampler(spec, repr, Some(&g.dims)))
                    .collect::<Result<_, _>>()
                    .map_err(run_err)?,
            };
            repr.encoder.begin_run(stream(seed, Component::Encoding));
            let mut space = LearnedSpace::new(env, repr.encoder.as_mut());
            let log = match (&modules, spec.algo.modules()) {
                (Some(ms), Some(m)) => run_mge(
                    env,
                    &mut space,
                    ms,
                    &mut samplers,
                    m,
                    ctx.explore,
                    ctx.mge,
                    seed,
                )
                .map_err(mge_err)?,
                _ => run_rge(env, &mut space, samplers[0].as_mut(), ctx.explore, seed),
            };
            if let Some(e) = space.error.take() {
                return Err(run_err(e));
            }
            return Ok(Explored {
                log,
                encode_s: Some(space.encode_s),
            });
        }
    };
    Ok(Explored {
        log,
        encode_s: None,
    })
}

/// The spread of each latent over the training encodings (its variance), which orders the
/// latents into modules ([`goal_modules`]).
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

/// The goal sampler of a learned goal space, over every latent (`dims` None) or over one
/// module's latents (the KDE of those latents of the training encodings; the prior's marginal).
fn goal_sampler(
    spec: &RunSpec,
    repr: &Representation,
    dims: Option<&[usize]>,
) -> Result<Box<dyn GoalSampler>, ReprError> {
    Ok(match spec.sampler {
        SamplerKind::Kde => Box::new(match dims {
            None => KdeGoals::fit(&repr.train)?,
            Some(dims) => KdeGoals::fit(&Latents {
                n: repr.train.n,
                latents: dims.len(),
                data: (0..repr.train.n)
                    .flat_map(|i| dims.iter().map(move |&k| repr.train.row(i)[k]))
                    .collect(),
            })?,
        }),
        SamplerKind::Gaussian => match repr.encoder.prior() {
            Some(prior) => Box::new(GaussianGoals::from_prior(&match dims {
                None => prior,
                Some(dims) => crate::repr::GaussianPrior {
                    mean: dims.iter().map(|&k| prior.mean[k]).collect(),
                    std: dims.iter().map(|&k| prior.std[k]).collect(),
                },
            })),
            None => {
                return Err(ReprError::InvalidInput(format!(
                    "the gaussian sampler needs a goal-space prior, and {} has none (use kde)",
                    spec.algo
                )));
            }
        },
        other => {
            return Err(ReprError::InvalidInput(format!(
                "sampler {other} is not for learned goal spaces"
            )));
        }
    })
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
        run_seed: run_seed(ctx.campaign_seed, &spec.exploration_identity()),
        campaign: ctx.campaign.into(),
        campaign_seed: ctx.campaign_seed,
        profile: ctx.profile.into(),
        config_hash: ctx.config_hash(spec),
        explore: serde_json::to_value(ctx.explore).expect("serialisable"),
        env_config: serde_json::to_value(ctx.env).expect("serialisable"),
        ugl: spec
            .algo
            .learner()
            .map(|_| serde_json::to_value(ctx.ugl).expect("serialisable")),
        reduced_budget: !notes.is_empty(),
        budget_note: notes.join("; "),
        git_revision: git_revision().into(),
        crate_versions: serde_json::json!({
            "ugl-bench": env!("CARGO_PKG_VERSION"),
            "results_version": RESULTS_VERSION,
        }),
        toolchain: env!("UGL_RUSTC_VERSION").into(),
        threads: ctx.threads,
        wall_s,
        fit_s,
        learner_fit_s,
        encode_s: explored.encode_s,
        train: train.map(|t| serde_json::to_value(t).expect("serialisable")),
        external: spec
            .algo
            .learner()
            .is_some_and(Learner::is_external)
            .then(|| serde_json::to_value(ctx.learners.external()).expect("serialisable")),
        host: host_name().into(),
        cpu: Some(cpu_info().clone()),
        latent_quality: latent_quality.map(|q| serde_json::to_value(q).expect("serialisable")),
        summary: summary.clone(),
        // Filled in by `write_run` from the bytes it writes.
        files: None,
    };
    store::write_run(out, spec, &log, &manifest)?;
    Ok(summary)
}

/// Progress events of a campaign.
#[derive(Clone, Debug)]
pub enum Progress {
    /// The plan: total runs and how many are already complete (skipped).
    Planned { total: usize, skipped: usize },
    /// A run finished.
    Finished(Summary),
}

/// The outcome of each run of a group (None: skipped after a stop request).
type GroupResult = Vec<Option<Result<Summary, RunError>>>;

/// Options of a campaign execution.
pub struct CampaignOptions<'a> {
    /// Worker threads (runs in parallel; each run is single-threaded).
    pub jobs: usize,
    /// Profile name recorded in manifests.
    pub profile: &'a str,
    /// Set to stop after the runs in flight (Ctrl-C).
    pub stop: &'a AtomicBool,
    /// Run only this slice `(index, count)` of the plan (`--shard i/n`).
    pub shard: Option<(usize, usize)>,
    /// The model cache of neural representations.
    pub cache: Option<&'a ModelCache>,
    /// Training progress of neural representations.
    pub train_progress: Option<Arc<TrainSink>>,
    /// External learners' stderr lines.
    pub learner_messages: Option<Arc<MessageSink>>,
    /// [`RunContext::checkpoint_every`].
    pub checkpoint_every: usize,
}

/// The run context of a campaign's runs.
pub(crate) fn campaign_context<'a>(
    cfg: &'a CampaignConfig,
    out: &'a Path,
    opts: &CampaignOptions<'a>,
) -> RunContext<'a> {
    RunContext {
        campaign: &cfg.campaign.name,
        campaign_seed: cfg.campaign.seed,
        profile: opts.profile,
        explore: &cfg.explore,
        env: &cfg.env,
        ugl: &cfg.ugl,
        learners: &cfg.learners,
        mge: &cfg.mge,
        threads: opts.jobs,
        cache: opts.cache,
        train_progress: opts.train_progress.clone(),
        // Each worker's own pool is the training's ([`for_each_group`]).
        train_threads: 0,
        log_dir: Some(out),
        learner_messages: opts.learner_messages.clone(),
        checkpoint_every: opts.checkpoint_every,
    }
}

/// Run `work(g)` for every group index `g < n`: `jobs` plain worker threads pull indexes from a
/// shared counter, and each worker owns a rayon pool of `cores / jobs` threads for the parallel
/// parts of a fit (Isomap's searches, the training kernels). Not a rayon `par_iter` over
/// groups: a rayon worker waiting inside a fit steals other groups and starts their fits too,
/// so dozens of fits (and their memory) pile up. Returns the results in index order.
pub(crate) fn for_each_group<T: Send>(
    jobs: usize,
    n: usize,
    work: &(dyn Fn(usize) -> T + Sync),
) -> Result<Vec<T>, RunError> {
    let jobs = jobs.max(1);
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let inner = (cores / jobs).max(1);
    let next = AtomicUsize::new(0);
    let slots: Vec<Mutex<Option<T>>> = (0..n).map(|_| Mutex::new(None)).collect();
    let pools = (0..jobs.min(n))
        .map(|_| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(inner)
                .build()
                .map_err(|e| RunError::Pool(e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    std::thread::scope(|scope| {
        let handles: Vec<_> = pools
            .iter()
            .map(|pool| {
                scope.spawn(|| {
                    loop {
                        let g = next.fetch_add(1, Ordering::SeqCst);
                        if g >= n {
                            break;
                        }
                        let r = pool.install(|| work(g));
                        *slots[g].lock().expect("result slot") = Some(r);
                    }
                })
            })
            .collect();
        for h in handles {
            if let Err(panic) = h.join() {
                std::panic::resume_unwind(panic);
            }
        }
    });
    Ok(slots
        .into_iter()
        .map(|m| {
            m.into_inner()
                .expect("result slot")
                .expect("every group ran")
        })
        .collect())
}

/// Run every run of the campaign that is not complete in `out` (resumable: complete runs with a
/// matching config hash are skipped). Returns the summaries of the runs executed now.
pub fn run_campaign(
    cfg: &CampaignConfig,
    out: &Path,
    opts: &CampaignOptions,
    on_progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Summary>, RunError> {
    let ctx = campaign_context(cfg, out, opts);
    let all = match opts.shard {
        None => plan(cfg),
        Some((i, n)) => super::plan::shard(&plan(cfg), cfg.ugl.images, i, n),
    };
    let todo: Vec<&RunSpec> = all
        .iter()
        .filter(|s| !store::is_complete(out, &s.run_id(), &ctx.config_hash(s)))
        .collect();
    on_progress(Progress::Planned {
        total: all.len(),
        skipped: all.len() - todo.len(),
    });
    // Runs sharing a representation form one group: fitted once, then run one after the other.
    let mut groups: Vec<(Option<String>, Vec<&RunSpec>)> = Vec::new();
    let n_todo = todo.len();
    for spec in todo {
        let key = spec.representation_identity(cfg.ugl.images);
        match groups.iter_mut().find(|(k, _)| key.is_some() && *k == key) {
            Some((_, g)) => g.push(spec),
            None => groups.push((key, vec![spec])),
        }
    }
    // Expensive groups (learned representations) first, for a better load balance.
    groups.sort_by_key(|(k, _)| k.is_none());
    // External-learner cells whose fit failed: (env, learner, latents) -> the failed run.
    let failed_external: Mutex<HashMap<String, String>> = Mutex::new(HashMap::new());
    let external_cell = |spec: &RunSpec| {
        spec.algo
            .learner()
            .is_some_and(Learner::is_external)
            .then(|| format!("{}/{}", spec.env.name(), spec.latents))
    };
    let run_group = |key: &Option<String>, specs: &[&RunSpec]| -> GroupResult {
        let mut out_v = Vec::with_capacity(specs.len());
        let mut repr = None;
        let mut failed: Option<String> = None;
        for spec in specs {
            if opts.stop.load(Ordering::SeqCst) {
                out_v.push(None);
                continue;
            }
            if key.is_some() && repr.is_none() {
                let cell = external_cell(spec);
                let before = failed.clone().or_else(|| {
                    let seen = failed_external.lock().unwrap_or_else(|e| e.into_inner());
                    cell.as_ref().and_then(|c| seen.get(c).cloned())
                });
                if let Some(first) = before {
                    out_v.push(Some(Err(RunError::FitFailedBefore {
                        run: spec.run_id(),
                        first,
                    })));
                    continue;
                }
                match fit_representation(spec, &ctx) {
                    Ok(mut r) => {
                        if goal_space::wanted(spec)
                            && let Err(e) = goal_space::write(out, spec, &ctx, &mut r)
                        {
                            tracing::warn!(
                                "{}: goal-space figure data not written: {e}",
                                spec.run_id()
                            );
                        }
                        repr = Some(r)
                    }
                    Err(source) => {
                        failed = Some(spec.run_id());
                        if let Some(c) = cell {
                            failed_external
                                .lock()
                                .unwrap_or_else(|e| e.into_inner())
                                .entry(c)
                                .or_insert_with(|| spec.run_id());
                        }
                        out_v.push(Some(Err(RunError::Repr {
                            run: spec.run_id(),
                            source,
                        })));
                        continue;
                    }
                }
            }
            let r = execute(spec, &ctx, out, repr.as_mut());
            if let Ok(s) = &r {
                on_progress(Progress::Finished(s.clone()));
            }
            out_v.push(Some(r));
        }
        out_v
    };
    let results: Vec<GroupResult> = for_each_group(opts.jobs, groups.len(), &|g| {
        let (key, specs) = &groups[g];
        run_group(key, specs)
    })?;
    let mut done = Vec::new();
    let mut skipped_now = 0;
    let mut first_err: Option<RunError> = None;
    for r in results.into_iter().flatten() {
        match r {
            Some(Ok(r)) => done.push(r),
            // The error to report: the first real one (a run skipped because of an earlier
            // failed fit only points to it).
            Some(Err(e)) => match (&first_err, &e) {
                (None, _) | (Some(RunError::FitFailedBefore { .. }), RunError::Repr { .. }) => {
                    first_err = Some(e)
                }
                _ => {}
            },
            None => skipped_now += 1,
        }
    }
    if let Some(e) = first_err {
        return Err(e);
    }
    if skipped_now > 0 {
        return Err(RunError::Interrupted {
            done: all.len() - n_todo + done.len(),
            total: all.len(),
        });
    }
    Ok(done)
}

/// `git rev-parse HEAD` of the working directory, with `-dirty` if there are uncommitted
/// changes; `unknown` outside a repository.
pub fn git_revision() -> &'static str {
    static REV: OnceLock<String> = OnceLock::new();
    REV.get_or_init(|| {
        let run = |args: &[&str]| {
            std::process::Command::new("git")
                .args(args)
                .output()
                .ok()
                .filter(|o| o.status.success())
                .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        };
        match run(&["rev-parse", "HEAD"]) {
            Some(rev) => {
                let dirty = run(&["status", "--porcelain", "--untracked-files=no"])
                    .is_some_and(|s| !s.is_empty());
                if dirty { format!("{rev}-dirty") } else { rev }
            }
            None => "unknown".into(),
        }
    })
}
