//! Fitting a run's representation: the UGL data set, the learner, the model cache and the
//! training evidence and latent quality recorded in the manifest.

use std::time::Instant;

use super::config::LearnersConfig;
use super::plan::RunSpec;
use crate::env::{Environment, make_env};
use crate::explore::Learner;
use crate::repr::cache::{CacheEntry, ModelFileError};
use crate::repr::dataset::{dataset_identity, generate};
use crate::repr::neural::{self, Variant};
use crate::repr::quality::{self, LatentQuality};
use crate::repr::{Encoder, ImageSet, Latents, ReprError, RepresentationLearner};
use crate::seed::{Component, run_seed, stream};

use super::context::RunContext;
use ugl_types::{CacheStatus, RESULTS_VERSION, TrainingRecord};

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
    pub training: Option<TrainingRecord>,
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
        match disentanglement(&z_heldout, &heldout.states, d, &objects) {
            Ok(dis) => q.disentanglement = Some(dis),
            Err(e) => tracing::warn!("disentanglement not measured: {e}"),
        }
        match encoder.per_latent_kl(&heldout.images) {
            Some(Ok(kl)) => q.kl_per_latent = kl,
            Some(Err(e)) => tracing::warn!("per-latent KL not measured: {e}"),
            None => {}
        }
    }
    Ok(q)
}

/// MIG and SAP of the latents `z` of the scenes `states` (`state_dim` values each) against the
/// coordinates of every object.
fn disentanglement(
    z: &Latents,
    states: &[f64],
    state_dim: usize,
    objects: &[(&str, std::ops::Range<usize>)],
) -> Result<ugl_types::Disentanglement, crate::repr::disentanglement::DisentanglementError> {
    use crate::repr::disentanglement::{mig, sap};
    let coordinate = |dims: &std::ops::Range<usize>, i: usize| match (dims.len(), i) {
        (2, 0) => "x".to_string(),
        (2, 1) => "y".to_string(),
        _ => i.to_string(),
    };
    let factors: Vec<String> = objects
        .iter()
        .flat_map(|(name, dims)| {
            (0..dims.len()).map(move |i| format!("{name} {}", coordinate(dims, i)))
        })
        .collect();
    let values: Vec<f64> = states
        .chunks_exact(state_dim)
        .flat_map(|s| {
            objects
                .iter()
                .flat_map(move |(_, dims)| s[dims.clone()].to_vec())
        })
        .collect();
    let k = factors.len();
    let m = mig(&z.data, z.latents, &values, k)?;
    let s = sap(&z.data, z.latents, &values, k)?;
    Ok(ugl_types::Disentanglement {
        factors,
        mig: m.score,
        mig_per_factor: m.per_factor,
        mig_best_latent: m.best_latent,
        sap: s.score,
        sap_per_factor: s.per_factor,
    })
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
        .map_err(|e| ReprError::InvalidInput(e.to_string()))?
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

/// Where a representation comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// Fitted, or loaded from the model cache: what a run uses.
    Fit,
    /// The weights of a neural training's checkpoint after this many iterations, in the model
    /// cache (`ugl embed --checkpoint`): the network part-way through its training.
    Checkpoint(usize),
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
    source: Source,
) -> Result<(Box<dyn Encoder>, Latents, Option<TrainingRecord>, String), ReprError> {
    let params = ctx
        .learners
        .params(learner)
        .map_err(|e| ReprError::InvalidInput(e.to_string()))?;
    let identity = params.identity(spec.variant);
    let fitter = params.build(spec.variant);
    let key = model_key(spec, ctx, &identity);
    let (encoder, z, status, iterations) = match source {
        Source::Fit => {
            let (encoder, z, status) =
                fit_or_cached(spec, ctx, fitter.as_ref(), &key, images, rng)?;
            (encoder, z, Some(status), None)
        }
        Source::Checkpoint(step) => {
            let (encoder, z) = read_checkpoint(ctx, fitter.as_ref(), &key, step, images)?;
            (encoder, z, None, Some(step))
        }
    };
    let info = encoder.training_outcome(images).map(|r| TrainingRecord {
        cache: status,
        config: identity,
        evidence: Some(r.evidence),
        iterations: Some(iterations.unwrap_or(r.iterations)),
        key,
        losses: r.losses,
    });
    Ok((encoder, z, info, fitter.name().to_string()))
}

/// The encoder of `key` from the model cache, or fitted (and stored there), with the training
/// latents and what the cache held.
fn fit_or_cached(
    spec: &RunSpec,
    ctx: &RunContext,
    fitter: &dyn RepresentationLearner,
    key: &str,
    images: &ImageSet,
    rng: &mut crate::seed::Stream,
) -> Result<(Box<dyn Encoder>, Latents, CacheStatus), ReprError> {
    let cache = ctx.harness.cache.filter(|_| fitter.persists());
    let mut status = CacheStatus::Off;
    let cached = match cache.map(|c| c.load(key, |bytes| fitter.load(key, bytes))) {
        Some(CacheEntry::Hit(enc)) => {
            status = CacheStatus::Hit;
            Some(enc)
        }
        Some(CacheEntry::Invalid(why)) => {
            tracing::warn!("model cache: ignoring an invalid file ({why}); fitting again");
            status = CacheStatus::Rebuilt;
            None
        }
        Some(CacheEntry::Miss) => {
            status = CacheStatus::Miss;
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
            let label = representation_label(spec);
            let fit_ctx =
                ctx.harness
                    .fit_context(&label, key, cache.is_some(), spec.env.spec().image);
            let fitted = fitter.fit_in(images, spec.latents, rng, &fit_ctx);
            if let Some(sink) = &ctx.harness.learner_messages {
                sink(&label, None);
            }
            let (enc, z) = fitted?;
            if let Some(c) = cache
                && let Some(bytes) = enc.save(key)
            {
                c.store(key, &bytes)?;
            }
            (enc, z)
        }
    };
    Ok((encoder, z, status))
}

/// The encoder of the checkpoint of `key` after `step` iterations, in the model cache
/// (`ugl embed --checkpoint`), with the training latents; nothing is trained.
fn read_checkpoint(
    ctx: &RunContext,
    fitter: &dyn RepresentationLearner,
    key: &str,
    step: usize,
    images: &ImageSet,
) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
    if !fitter.saves_checkpoints() {
        return Err(ReprError::InvalidInput(
            ModelFileError::NoCheckpoints {
                learner: fitter.name().to_string(),
            }
            .to_string(),
        ));
    }
    let cache = ctx.harness.cache.ok_or_else(|| {
        ReprError::InvalidInput(
            "a checkpoint is read from the model cache, and there is none".into(),
        )
    })?;
    let checkpoint = crate::repr::checkpoint::inspect(&cache.dir, key, step, images.n)?;
    let mut encoder = fitter
        .load_checkpoint(key, &checkpoint)
        .map_err(|e| ReprError::InvalidInput(format!("{}: {e}", fitter.name())))?;
    let z = encoder.training_latents(images)?;
    Ok((encoder, z))
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
    fit_with_data(spec, ctx, Source::Fit).map(|(r, _, _)| r)
}

/// [`fit_representation`] from `source`, also returning the UGL data set it was fitted on and
/// its seed.
pub fn fit_with_data(
    spec: &RunSpec,
    ctx: &RunContext,
    source: Source,
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
        fit_or_load(spec, ctx, learner, &data.images, &mut rng, source)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{EnvConfig, EnvKind};

    /// An encoder that reads the objects off an `armballs-corl` picture: the centroids of the
    /// red channel (the ball is yellow) and of the blue one (the distractor), optionally mixed by
    /// a fixed rotation of all four.
    struct Centroids {
        mixed: bool,
    }

    impl Encoder for Centroids {
        fn latents(&self) -> usize {
            4
        }
        fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
            let side = 64;
            let mut data = Vec::with_capacity(images.n * 4);
            for i in 0..images.n {
                let img = images.row(i);
                let mut c = [0.0f64; 4];
                for (channel, at) in [(0, 0), (2, 2)] {
                    let (mut w, mut x, mut y) = (0.0, 0.0, 0.0);
                    for p in 0..side * side {
                        let v = f64::from(img[p * 3 + channel]);
                        w += v;
                        x += v * (p % side) as f64;
                        y += v * (p / side) as f64;
                    }
                    c[at] = x / w.max(1e-9);
                    c[at + 1] = y / w.max(1e-9);
                }
                if self.mixed {
                    let [a, b, e, f] = c;
                    c = [a + b + e + f, a - b + e - f, a + b - e - f, a - b - e + f];
                }
                data.extend(c);
            }
            Ok(Latents {
                n: images.n,
                latents: 4,
                data,
            })
        }
    }

    /// The disentanglement recorded for a scene with two objects ranks a goal space with one
    /// latent per coordinate above the same information mixed across all four latents.
    #[test]
    fn disentanglement_ranks_the_separated_space_above_the_mixed_one() {
        let env = make_env(EnvKind::ARMBALLS_CORL, &EnvConfig::default());
        let data = generate(env.as_ref(), 400, &mut stream(3, Component::Dataset)).unwrap();
        let score = |mixed| {
            let q = measure_quality(&mut Centroids { mixed }, env.as_ref(), &data, 3).unwrap();
            let d = q.disentanglement.expect("two objects: measured");
            assert_eq!(
                d.factors,
                ["ball x", "ball y", "distractor x", "distractor y"]
            );
            assert!(q.kl_per_latent.is_empty(), "no posterior, no KL");
            (d.mig, d.sap)
        };
        let (good_mig, good_sap) = score(false);
        let (bad_mig, bad_sap) = score(true);
        assert!(good_mig > 0.5 && good_sap > 0.5, "{good_mig} {good_sap}");
        assert!(
            bad_mig < 0.5 * good_mig && bad_sap < 0.5 * good_sap,
            "mixed {bad_mig} {bad_sap} vs {good_mig} {good_sap}"
        );
    }
}
