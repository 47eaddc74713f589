//! The neural representation learners of the paper (AE, VAE, RFVAE; PAPER-NOTES.md section 5):
//! configuration, the training loop and the fitted encoder. The model-specific parts (loss,
//! encoding) live in `ae.rs`, `vae.rs` and `rfvae.rs`; the layers and optimisers in `nets.rs`.
//!
//! Training (all three models), as the original's `BaseNetwork.train`:
//! - weights drawn on the host from the learner stream ([`HostNet::init`]), loaded into a burn
//!   module on `Device::flex().autodiff()`;
//! - each iteration: the first `batch` indices of a fresh uniform permutation of the training
//!   set (a partial Fisher-Yates shuffle: `batch` draws `random_range(i..n)` from the learner
//!   stream), then the model's noise (VAE/RFVAE: standard normals from the same stream), a
//!   forward pass, the loss, backward, and one optimiser step with element-wise gradient
//!   clipping to [-1, 1];
//! - the loss of every iteration is checked (NaN/inf -> [`ReprError::Numerical`]) and recorded
//!   every `log_every` iterations.
//!
//! Nothing draws from burn's RNG, so the result is a function of the stream alone. Encoding
//! runs on the host ([`HostNet::encode_head`]), image by image, so a batch encode and
//! `encode_one` agree bit for bit and neither depends on the thread count.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use burn::module::Module as _;
use burn::optim::{GradientsParams, ModuleOptimizer};
use burn::tensor::Device;
use rand::{Rng, RngExt, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::host_train::{HostOptimizer, HostTrainer};
pub use super::nets::Init;
use super::nets::{DenseNet, HostNet, Scratch, TfAdagrad, TfAdam};
pub use super::neural_model::{
    Latent, LatentInput, NeuralModel, Optimiser, StepInput, Variant, normals, tensor2,
};
use super::params::{LearnerParams, ParamGuard};
use super::{
    Encoder, GaussianPrior, ImageSet, Latents, ReprError, RepresentationLearner, check_fit_input,
    check_latents,
};
use crate::repr::{ae, bvae, rfvae, vae};
use crate::seed::Stream;

/// The backend neural training runs on (part of the model-cache key, so models trained on
/// another backend are never mixed up).
#[cfg(not(feature = "cuda"))]
pub const BACKEND: &str = "burn-0.22.1/flex/f32";
/// The backend neural training runs on (part of the model-cache key).
#[cfg(feature = "cuda")]
pub const BACKEND: &str = "burn-0.22.1/cuda/f32";

/// The device of training: burn's `flex` CPU backend (bit-for-bit deterministic for a seed and
/// any thread count), or with the `cuda` cargo feature the first CUDA GPU (for the paper's
/// budgets; not deterministic across GPU models, not built or tested by CI).
pub fn training_device() -> Device {
    #[cfg(feature = "cuda")]
    {
        Device::cuda(0).autodiff()
    }
    #[cfg(not(feature = "cuda"))]
    {
        Device::flex().autodiff()
    }
}

/// What runs the training iterations (`engine` in `[learners.ae|vae|rfvae]`). Both train the
/// same networks with the same stream draws, loss and update rules; they differ in summation
/// order (so in the last bits) and in speed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// Hand-written forward and backward passes on the `gemm` crate, with the sparse first
    /// layer ([`super::host_train`]): the default, 2-3x faster than `burn` on CPU.
    #[default]
    Host,
    /// burn's autodiff on [`training_device`] (`flex`, or CUDA with the `cuda` feature).
    Burn,
}

impl Engine {
    /// Every engine.
    pub const ALL: [Engine; 2] = [Engine::Host, Engine::Burn];

    /// The name in TOML files and manifests.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Host => "host",
            Engine::Burn => "burn",
        }
    }

    /// The engine of manifests written before it was configurable (results versions 1 and 2).
    fn before_v3() -> Engine {
        Engine::Burn
    }
}

/// Which network.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    /// Dense auto-encoder, sigmoid latents, Adagrad.
    Ae,
    /// Dense VAE, Adam.
    Vae,
    /// Dense VAE with 10 amortised radial flows, KL warm-up, Adam.
    Rfvae,
    /// Dense β-VAE (the follow-up paper's learner), Adam.
    Bvae,
}

impl Model {
    /// All of them.
    pub const ALL: [Model; 4] = [Model::Ae, Model::Vae, Model::Rfvae, Model::Bvae];

    /// What the model is: the one place a model's identity maps to its code.
    pub fn spec(self) -> &'static dyn NeuralModel {
        match self {
            Model::Ae => &ae::Ae,
            Model::Vae => &vae::Vae,
            Model::Rfvae => &rfvae::Rfvae,
            Model::Bvae => &bvae::Bvae,
        }
    }

    /// `ae`, `vae`, `rfvae`, `bvae`.
    pub fn name(self) -> &'static str {
        self.spec().name()
    }

    /// The widths of the encoder's head blocks for `latents` dimensions.
    pub fn head_blocks(self, latents: usize) -> Vec<usize> {
        self.spec().head_blocks(latents)
    }

    /// The paper's training length (the original's `fit`: AE 2e5, VAE 1e5, RFVAE 5e4).
    pub fn paper_iterations(self) -> usize {
        self.spec().paper_iterations()
    }
}

/// Training configuration of a neural learner. Every field is required in serde form (it is the
/// complete, hashable description of a training run); [`NeuralSection`] is the partial form for
/// configuration files, with the paper's values per model as defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NeuralConfig {
    /// Optimiser steps.
    pub iterations: usize,
    /// Hidden sizes `[H1, H2]` (paper: 1200, 1200).
    pub hidden: [usize; 2],
    /// Mini-batch size (paper: 100; capped at the training set size).
    pub batch: usize,
    /// Learning rate (paper: 1e-3).
    pub lr: f64,
    /// Faithful or corrected.
    pub variant: Variant,
    /// Record the loss every this many iterations (the original logged every 100).
    pub log_every: usize,
    /// RFVAE only: iterations of the KL warm-up `min(1, 0.01 + step / warmup)` (paper: 10,000
    /// of 50,000); ignored by the AE and VAE.
    pub warmup: usize,
    /// How the weights are drawn (paper: truncated normal, std 0.001). Absent in manifests
    /// written before it was configurable, which all used the paper's.
    #[serde(default)]
    pub init: Init,
    /// What runs the iterations. Absent in manifests written before it was configurable, which
    /// all trained on burn.
    #[serde(default = "Engine::before_v3")]
    pub engine: Engine,
    /// β-VAE only: the weight of the KL term (absent for the other models, which weigh it by
    /// 1, so their configurations and hashes are what they were before the β-VAE existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    /// β-VAE only: Burgess et al.'s capacity annealing (the follow-up's objective): the KL term
    /// becomes `β |mean_b KL_b − C|`, C rising linearly from 0 to `capacity` nats over the
    /// training. Absent: the plain β-VAE (and every other model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capacity: Option<f64>,
}

impl NeuralConfig {
    /// The capacity C of the annealed β-VAE objective at 0-based iteration `step`.
    pub fn capacity_at(&self, step: usize) -> Option<f64> {
        self.capacity
            .map(|c| c * (step as f64 / self.iterations as f64).min(1.0))
    }

    /// The paper's configuration of `model`, faithful variant.
    pub fn paper(model: Model) -> NeuralConfig {
        NeuralConfig {
            iterations: model.paper_iterations(),
            hidden: [1200, 1200],
            batch: 100,
            lr: 1e-3,
            variant: Variant::Faithful,
            log_every: 100,
            warmup: model.spec().paper_warmup(),
            beta: model.spec().default_beta(),
            capacity: None,
            init: Init::Paper,
            engine: Engine::Host,
        }
    }

    /// Check every value for `model`; the message names the key.
    pub fn validate(&self, model: Model, who: &str) -> Result<(), ReprError> {
        let bad = |msg: String| {
            Err(ReprError::InvalidInput(if who.is_empty() {
                msg
            } else {
                format!("{who}: {msg}")
            }))
        };
        if self.iterations == 0 {
            return bad("iterations must be at least 1".into());
        }
        if self.batch == 0 {
            return bad("batch must be at least 1".into());
        }
        if self.hidden.contains(&0) {
            return bad(format!(
                "hidden sizes must be at least 1, got {:?}",
                self.hidden
            ));
        }
        if let Err(m) = crate::limits::check_hidden("hidden", self.hidden) {
            return bad(m);
        }
        if !(self.lr.is_finite() && self.lr > 0.0) {
            return bad(format!("lr must be positive and finite, got {}", self.lr));
        }
        if self.log_every == 0 {
            return bad("log_every must be at least 1".into());
        }
        if let Some(b) = self.beta
            && !(b.is_finite() && b > 0.0 && b <= 1e6)
        {
            return bad(format!("beta must be positive and at most 1e6, got {b}"));
        }
        if let Some(c) = self.capacity
            && !(c.is_finite() && (0.0..=1e4).contains(&c))
        {
            return bad(format!("capacity must be between 0 and 1e4 nats, got {c}"));
        }
        if model.spec().paper_warmup() > 0 && self.warmup == 0 {
            return bad("warmup must be at least 1".into());
        }
        Ok(())
    }
}

impl std::fmt::Display for Variant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Variant {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Variant::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| format!("unknown variant '{s}' (expected faithful or corrected)"))
    }
}

/// The partial form of [`NeuralConfig`] for configuration files (`[learners.vae]` etc.):
/// missing keys take the paper's value for the model ([`NeuralSection::resolve`]). The variant
/// is not here: it is a dimension of the run matrix (`matrix.variants`, `ugl run --variant`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NeuralSection {
    pub iterations: Option<usize>,
    pub hidden: Option<[usize; 2]>,
    pub batch: Option<usize>,
    pub lr: Option<f64>,
    pub log_every: Option<usize>,
    /// RFVAE warm-up iterations (only valid in `[learners.rfvae]`).
    pub warmup: Option<usize>,
    /// Weight initialisation: `paper`, `he` or `glorot` ([`Init`]).
    pub init: Option<Init>,
    /// Training engine: `host` (default) or `burn` ([`Engine`]).
    pub engine: Option<Engine>,
    /// β-VAE: the weight of the KL term (only valid in `[learners.bvae]`).
    pub beta: Option<f64>,
    /// β-VAE: capacity annealing, the KL target's final value in nats (only valid in
    /// `[learners.bvae]`).
    pub capacity: Option<f64>,
}

impl NeuralSection {
    /// The complete configuration for `model` and `variant`.
    pub fn resolve(&self, model: Model, variant: Variant) -> NeuralConfig {
        let p = NeuralConfig::paper(model);
        NeuralConfig {
            iterations: self.iterations.unwrap_or(p.iterations),
            hidden: self.hidden.unwrap_or(p.hidden),
            batch: self.batch.unwrap_or(p.batch),
            lr: self.lr.unwrap_or(p.lr),
            variant,
            log_every: self.log_every.unwrap_or(p.log_every),
            warmup: self.warmup.unwrap_or(p.warmup),
            init: self.init.unwrap_or(p.init),
            engine: self.engine.unwrap_or(p.engine),
            beta: p.beta.map(|b| self.beta.unwrap_or(b)),
            capacity: p.beta.and(self.capacity),
        }
    }
}

impl ParamGuard for (Model, NeuralSection) {
    type Checked = NeuralParams;
    fn check(self) -> Result<NeuralParams, String> {
        let (model, section) = self;
        if model.spec().paper_warmup() == 0 && section.warmup.is_some() {
            return Err("warmup: only the rfvae has a KL warm-up".into());
        }
        if model.spec().default_beta().is_none() && section.beta.is_some() {
            return Err("beta: only the bvae has a KL weight".into());
        }
        if model.spec().default_beta().is_none() && section.capacity.is_some() {
            return Err("capacity: only the bvae anneals a KL capacity".into());
        }
        section
            .resolve(model, Variant::Faithful)
            .validate(model, "")
            .map_err(|e| match e {
                ReprError::InvalidInput(m) => m,
                other => other.to_string(),
            })?;
        Ok(NeuralParams { model, section })
    }
}

/// The checked `[learners.ae|vae|rfvae]` table of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct NeuralParams {
    model: Model,
    section: NeuralSection,
}

impl NeuralParams {
    /// The complete training configuration for a run of `variant` (default: faithful).
    pub fn config(&self, variant: Option<Variant>) -> NeuralConfig {
        self.section
            .resolve(self.model, variant.unwrap_or_default())
    }
}

impl LearnerParams for NeuralParams {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn identity(&self, variant: Option<Variant>) -> serde_json::Value {
        serde_json::to_value(
            self.section
                .resolve(self.model, variant.unwrap_or_default()),
        )
        .expect("serialisable")
    }
    fn deviations(&self, variant: Option<Variant>) -> Vec<String> {
        let t = self.config(variant);
        let p = NeuralConfig::paper(self.model);
        let mut notes = Vec::new();
        if t.iterations < p.iterations {
            notes.push(format!(
                "{} training iterations instead of the paper's {}",
                t.iterations, p.iterations
            ));
        }
        if t.hidden != p.hidden {
            notes.push(format!(
                "hidden layers {:?} instead of the paper's {:?}",
                t.hidden, p.hidden
            ));
        }
        if t.init != p.init {
            notes.push(format!(
                "{} weight init instead of the paper's truncated normal (std 0.001)",
                t.init
            ));
        }
        if t.batch != p.batch || t.lr != p.lr {
            notes.push(format!(
                "batch {} / lr {} instead of the paper's {} / {}",
                t.batch, t.lr, p.batch, p.lr
            ));
        }
        notes
    }
    fn build(&self, variant: Option<Variant>) -> Box<dyn RepresentationLearner> {
        Box::new(NeuralLearner::new(
            self.model,
            self.section
                .resolve(self.model, variant.unwrap_or_default()),
        ))
    }
}

/// A neural representation learner (`ae`, `vae`, `rfvae`): the model, its training
/// configuration and an optional progress callback.
#[derive(Clone)]
pub struct NeuralLearner {
    pub model: Model,
    pub config: NeuralConfig,
    progress: Option<ProgressFn>,
}

impl NeuralLearner {
    /// `model` trained with `config`.
    pub fn new(model: Model, config: NeuralConfig) -> Self {
        NeuralLearner {
            model,
            config,
            progress: None,
        }
    }

    /// `model` at the paper's configuration (faithful).
    pub fn paper(model: Model) -> Self {
        NeuralLearner::new(model, NeuralConfig::paper(model))
    }

    /// Report every training iteration to `f`.
    pub fn with_progress(mut self, f: ProgressFn) -> Self {
        self.progress = Some(f);
        self
    }

    /// Fit and return the concrete encoder (with its loss curve) and the training latents.
    pub fn fit_neural(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(NeuralEncoder, Latents), ReprError> {
        fit(
            self.model,
            &self.config,
            images,
            latents,
            rng,
            self.progress.as_ref(),
        )
    }
}

impl std::fmt::Debug for NeuralLearner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NeuralLearner")
            .field("model", &self.model)
            .field("config", &self.config)
            .finish()
    }
}

impl super::RepresentationLearner for NeuralLearner {
    fn name(&self) -> &str {
        self.model.name()
    }
    fn fit(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        let (enc, z) = self.fit_neural(images, latents, rng)?;
        Ok((Box::new(enc), z))
    }

    /// The training with the context's progress (else this learner's own), checkpoints and
    /// thread count: bit-identical to [`NeuralLearner::fit_neural`] whatever the context.
    fn fit_in(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
        ctx: &super::FitContext,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        let progress = ctx.progress.as_ref().or(self.progress.as_ref());
        let mut train = || {
            train_with_checkpoints(
                self.model,
                &self.config,
                images,
                latents,
                rng,
                progress,
                ctx.checkpoint.as_ref(),
            )
        };
        let mut enc = if ctx.threads > 0 {
            rayon::ThreadPoolBuilder::new()
                .num_threads(ctx.threads)
                .build()
                .map_err(|e| ReprError::InvalidInput(format!("training pool: {e}")))?
                .install(train)?
        } else {
            train()?
        };
        let z = enc.training_latents(images)?;
        Ok((Box::new(enc), z))
    }

    fn persists(&self) -> bool {
        true
    }

    fn load(&self, key: &str, bytes: &[u8]) -> Result<Box<dyn Encoder>, String> {
        let enc = super::cache::from_bytes(key, bytes)?;
        if (enc.model, enc.variant) != (self.model, self.config.variant) {
            return Err(format!(
                "the file holds a {} ({}), not a {} ({})",
                enc.model.name(),
                enc.variant,
                self.model.name(),
                self.config.variant
            ));
        }
        Ok(Box::new(enc))
    }
}

/// Progress of a training run, reported after every iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrainProgress {
    /// Iterations done (1-based).
    pub iteration: usize,
    /// Iterations in all.
    pub total: usize,
    /// The loss of this iteration's mini-batch.
    pub loss: f64,
}

/// A progress callback (e.g. driving an indicatif bar).
pub type ProgressFn = Arc<dyn Fn(TrainProgress) + Send + Sync>;

/// A fitted neural encoder. `losses` is the recorded loss curve: `(iteration, loss)` pairs,
/// iteration 0-based, every `log_every` iterations plus the last.
pub struct NeuralEncoder {
    pub model: Model,
    pub variant: Variant,
    pub net: HostNet,
    pub losses: Vec<(usize, f64)>,
    /// The seed of the encoder's own stream (drawn from the learner stream after training):
    /// it draws the faithful RFVAE's training latents (z0 samples the KDE is fitted on).
    pub encode_seed: [u8; 32],
    /// The stream of the faithful RFVAE's stochastic encoding (unused by the others): seeded
    /// from `encode_seed`, then replaced by each run's own stream
    /// ([`Encoder::begin_run`]).
    rng: Stream,
    scratch: Scratch,
}

impl std::fmt::Debug for NeuralEncoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NeuralEncoder")
            .field("model", &self.model)
            .field("variant", &self.variant)
            .field("dim", &self.net.dim)
            .field("hidden", &self.net.hidden)
            .field("latents", &self.net.latents)
            .field("losses", &self.losses.len())
            .finish()
    }
}

impl NeuralEncoder {
    /// An encoder from trained weights; `encode_seed` seeds the stream of the stochastic
    /// (faithful RFVAE) encoding.
    pub fn new(
        model: Model,
        variant: Variant,
        net: HostNet,
        losses: Vec<(usize, f64)>,
        encode_seed: [u8; 32],
    ) -> Self {
        NeuralEncoder {
            model,
            variant,
            net,
            losses,
            encode_seed,
            rng: Stream::from_seed(encode_seed),
            scratch: Scratch::default(),
        }
    }

    /// Whether encoding draws random numbers (the faithful RFVAE).
    pub fn is_stochastic(&self) -> bool {
        self.model.spec().is_stochastic(self.variant)
    }

    fn encode_row(&mut self, image: &[f32], out: &mut [f64]) {
        let head = self.net.encode_head(image, &mut self.scratch);
        let d = self.net.latents;
        self.model
            .spec()
            .encoding(&head, d, self.variant, &mut self.rng, out);
    }

    fn check_dim(&self, dim: usize) -> Result<(), ReprError> {
        if dim != self.net.dim {
            return Err(ReprError::InvalidInput(format!(
                "images have {dim} pixels, the model {}",
                self.net.dim
            )));
        }
        Ok(())
    }

    /// The training latents (what the KDE is fitted on). Faithful RFVAE: z0 samples
    /// `mu + eps sigma` (the original's `transform(X, sampling=True)`), with noise from a fresh
    /// stream seeded by `encode_seed` (a function of the model alone); otherwise the encoding.
    pub fn training_latents(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        if !self.is_stochastic() {
            return self.encode(images);
        }
        self.check_dim(images.dim)?;
        let d = self.net.latents;
        let mut data = vec![0.0; images.n * d];
        // A fresh stream from the model's own seed: the same training latents whenever this is
        // called, whatever was encoded before.
        let mut rng = Stream::from_seed(self.encode_seed);
        for (i, out) in data.chunks_exact_mut(d).enumerate() {
            let head = self.net.encode_head(images.row(i), &mut self.scratch);
            self.model.spec().training_sample(&head, d, &mut rng, out);
        }
        let z = Latents {
            n: images.n,
            latents: d,
            data,
        };
        check_latents(&z, self.model.name())?;
        Ok(z)
    }
}

impl Encoder for NeuralEncoder {
    fn latents(&self) -> usize {
        self.net.latents
    }

    fn reconstruct(&mut self, image: &[f32]) -> Option<Result<Vec<f32>, ReprError>> {
        Some(
            self.check_dim(image.len())
                .map(|_| reconstruct(self.model, &self.net, image)),
        )
    }

    fn begin_run(&mut self, rng: Stream) {
        self.rng = rng;
    }

    fn training_latents(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        NeuralEncoder::training_latents(self, images)
    }

    fn save(&self, key: &str) -> Option<Vec<u8>> {
        Some(super::cache::to_bytes(key, self))
    }

    fn training_record(&self, images: &ImageSet) -> Option<super::TrainingRecord> {
        let head = images.head(super::evidence::EVIDENCE_IMAGES);
        let rec = reconstruction_loss(self.model, &self.net, &head, head.n);
        Some(super::TrainingRecord {
            losses: self.losses.clone(),
            evidence: super::evidence::TrainingEvidence::new(
                super::evidence::mean_image_loss(&head),
                rec,
                head.n,
            ),
        })
    }

    fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        self.check_dim(images.dim)?;
        let d = self.net.latents;
        let mut data = vec![0.0; images.n * d];
        if self.is_stochastic() {
            // Sequential: the noise is drawn image by image from the encoder's stream.
            for (i, out) in data.chunks_exact_mut(d).enumerate() {
                self.encode_row(images.row(i), out);
            }
        } else {
            let (net, model) = (&self.net, self.model);
            data.par_chunks_mut(d).enumerate().for_each_init(
                Scratch::default,
                |scratch, (i, out)| {
                    let head = net.encode_head(images.row(i), scratch);
                    // Not stochastic: the encoding is the noise-free code.
                    model.spec().mean_code(&head, d, out);
                },
            );
        }
        let z = Latents {
            n: images.n,
            latents: d,
            data,
        };
        check_latents(&z, self.model.name())?;
        Ok(z)
    }

    fn encode_one(&mut self, image: &[f32], out: &mut [f64]) -> Result<(), ReprError> {
        if image.len() != self.net.dim || out.len() != self.net.latents {
            return Err(ReprError::InvalidInput(format!(
                "encode_one: image of {} pixels / output of {} values, the model takes {} / {}",
                image.len(),
                out.len(),
                self.net.dim,
                self.net.latents
            )));
        }
        self.encode_row(image, out);
        if let Some(j) = out.iter().position(|v| !v.is_finite()) {
            return Err(ReprError::Numerical(format!(
                "{}: non-finite latent (dimension {j})",
                self.model.name()
            )));
        }
        Ok(())
    }

    fn prior(&self) -> Option<GaussianPrior> {
        self.model.spec().has_prior().then(|| GaussianPrior {
            mean: vec![0.0; self.net.latents],
            std: vec![1.0; self.net.latents],
        })
    }
}

/// The initial weights of `model` (a function of the stream only; the variant plays no part).
pub fn init_net(
    model: Model,
    cfg: &NeuralConfig,
    dim: usize,
    latents: usize,
    rng: &mut Stream,
) -> HostNet {
    HostNet::init(
        rng,
        cfg.init,
        dim,
        cfg.hidden,
        latents,
        &model.head_blocks(latents),
    )
}

/// Draw the mini-batch: the first `k` entries of a fresh uniform permutation of `perm`'s
/// contents (partial Fisher-Yates; `perm` keeps the shuffled order between calls, which does not
/// bias the next draw).
pub fn draw_batch(perm: &mut [usize], k: usize, rng: &mut Stream) {
    let n = perm.len();
    for i in 0..k.min(n) {
        let j = rng.random_range(i..n);
        perm.swap(i, j);
    }
}

/// The engine-specific part of a [`Trainer`]: the weights and the optimiser state.
enum EngineState {
    Burn {
        device: Device,
        net: Option<DenseNet>,
        opt: ModuleOptimizer,
    },
    Host(Box<HostTrainer>),
}

/// A training run in progress: the weights, their optimiser and the batch sampler. [`train`]
/// drives it; the `train_step` bench times [`Trainer::step`].
pub struct Trainer<'a> {
    pub model: Model,
    pub cfg: NeuralConfig,
    images: &'a ImageSet,
    latents: usize,
    state: EngineState,
    perm: Vec<usize>,
    xbuf: Vec<f32>,
    /// Iterations done.
    pub step: usize,
}

impl<'a> Trainer<'a> {
    /// Validate, draw the initial weights from `rng` and set up the engine.
    pub fn new(
        model: Model,
        cfg: &NeuralConfig,
        images: &'a ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<Self, ReprError> {
        cfg.validate(model, model.name())?;
        check_fit_input(images, latents)?;
        let host = init_net(model, cfg, images.dim, latents, rng);
        let state = match cfg.engine {
            Engine::Burn => {
                let device = training_device();
                EngineState::Burn {
                    net: Some(host.to_module(&device)),
                    device,
                    opt: optimizer(model),
                }
            }
            Engine::Host => {
                let opt = HostOptimizer::new(model, &host);
                EngineState::Host(Box::new(HostTrainer::new(host, opt)))
            }
        };
        Ok(Self::assemble(
            model,
            cfg,
            images,
            latents,
            state,
            (0..images.n).collect(),
            0,
        ))
    }

    fn assemble(
        model: Model,
        cfg: &NeuralConfig,
        images: &'a ImageSet,
        latents: usize,
        state: EngineState,
        perm: Vec<usize>,
        step: usize,
    ) -> Self {
        let k = cfg.batch.min(images.n);
        Trainer {
            model,
            cfg: cfg.clone(),
            images,
            latents,
            state,
            perm,
            xbuf: vec![0.0; k * images.dim],
            step,
        }
    }

    /// One iteration: batch, noise, forward, loss, backward, optimiser step. Returns the
    /// mini-batch loss (checked finite).
    pub fn step(&mut self, rng: &mut Stream) -> Result<f64, ReprError> {
        let dim = self.images.dim;
        let k = self.xbuf.len() / dim;
        draw_batch(&mut self.perm, k, rng);
        for (row, &i) in self.xbuf.chunks_exact_mut(dim).zip(&self.perm[..k]) {
            row.copy_from_slice(self.images.row(i));
        }
        let value = match &mut self.state {
            EngineState::Host(host) => {
                host.step(self.model, &self.cfg, &self.xbuf, k, self.step, rng)?
            }
            EngineState::Burn { device, net, opt } => {
                let x = tensor2(self.xbuf.clone(), k, dim, device);
                let module = net.take().expect("the module is present between steps");
                let input = StepInput {
                    x,
                    latent: LatentInput {
                        batch: k,
                        latents: self.latents,
                        step: self.step,
                        warmup: self.cfg.warmup,
                        beta: self.cfg.beta.unwrap_or(1.0),
                        capacity: self.cfg.capacity_at(self.step),
                        variant: self.cfg.variant,
                        device,
                    },
                };
                let loss = self.model.spec().loss(&module, input, rng);
                let value = f64::from(loss.clone().into_scalar::<f32>());
                if value.is_finite() {
                    let grads = GradientsParams::from_grads(loss.backward(), &module);
                    *net = Some(opt.step(self.cfg.lr, module, grads));
                } else {
                    *net = Some(module);
                }
                value
            }
        };
        if !value.is_finite() {
            return Err(ReprError::Numerical(format!(
                "{} training diverged at iteration {}: loss = {value}",
                self.model.name(),
                self.step
            )));
        }
        self.step += 1;
        Ok(value)
    }

    /// The state a checkpoint keeps besides the weights and the optimiser: parameter ids (the
    /// burn optimiser's state is keyed by them; zeros on the host engine) and the batch
    /// permutation.
    pub fn resume_state(&self) -> ([u64; 12], &[usize]) {
        let ids = match &self.state {
            EngineState::Burn { net, .. } => net
                .as_ref()
                .expect("the module is present between steps")
                .param_ids(),
            EngineState::Host(_) => [0; 12],
        };
        (ids, &self.perm)
    }

    /// Save the optimiser's state (burn's record format, or [`HostOptimizer::to_bytes`]).
    pub fn save_optimizer(&self, path: &Path) -> Result<(), ReprError> {
        let fail =
            |e: String| ReprError::Io(format!("saving optimiser state {}: {e}", path.display()));
        match &self.state {
            EngineState::Burn { opt, .. } => opt.save(path).map_err(|e| fail(format!("{e:?}"))),
            EngineState::Host(host) => crate::fsio::write_atomic(path, &host.opt.to_bytes())
                .map_err(|e| fail(e.to_string())),
        }
    }

    /// A trainer continuing from a checkpoint: weights `net` with parameter ids `ids`, the
    /// optimiser state in `optimizer`, the batch permutation and the iterations done. The
    /// caller restores the stream's position.
    pub fn resume(
        model: Model,
        cfg: &NeuralConfig,
        images: &'a ImageSet,
        latents: usize,
        state: ResumeState<'_>,
    ) -> Result<Self, ReprError> {
        cfg.validate(model, model.name())?;
        check_fit_input(images, latents)?;
        if state.perm.len() != images.n
            || state.net.dim != images.dim
            || state.net.latents != latents
            || state.net.hidden != cfg.hidden
        {
            return Err(ReprError::InvalidInput(
                "checkpoint does not match the training".into(),
            ));
        }
        let fail = |e: String| {
            ReprError::Io(format!(
                "loading optimiser state {}: {e}",
                state.optimizer.display()
            ))
        };
        let engine = match cfg.engine {
            Engine::Burn => {
                let device = training_device();
                let net = state.net.to_module_with_ids(&device, state.ids);
                let opt = optimizer(model)
                    .load(state.optimizer)
                    .map_err(|e| fail(format!("{e:?}")))?;
                EngineState::Burn {
                    device,
                    net: Some(net),
                    opt,
                }
            }
            Engine::Host => {
                let bytes = std::fs::read(state.optimizer).map_err(|e| fail(e.to_string()))?;
                let opt = HostOptimizer::from_bytes(model, state.net, &bytes).map_err(fail)?;
                EngineState::Host(Box::new(HostTrainer::new(state.net.clone(), opt)))
            }
        };
        Ok(Self::assemble(
            model,
            cfg,
            images,
            latents,
            engine,
            state.perm.to_vec(),
            state.step,
        ))
    }

    /// The current weights on the host.
    pub fn host_net(&self) -> Result<HostNet, ReprError> {
        match &self.state {
            EngineState::Burn { net, .. } => {
                let net = net
                    .as_ref()
                    .expect("the module is present between steps")
                    .valid();
                HostNet::from_module(&net, self.images.dim, self.cfg.hidden, self.latents)
            }
            EngineState::Host(host) => Ok(host.net.clone()),
        }
    }
}

/// The original's optimiser of `model`: Adagrad for the AE, Adam for the VAE and RFVAE.
fn optimizer(model: Model) -> ModuleOptimizer {
    match model.spec().optimiser() {
        Optimiser::Adagrad => TfAdagrad::default().into(),
        Optimiser::Adam => TfAdam::default().into(),
    }
}

/// What [`Trainer::resume`] continues from.
pub struct ResumeState<'s> {
    pub net: &'s HostNet,
    pub ids: &'s [u64; 12],
    pub optimizer: &'s Path,
    pub perm: &'s [usize],
    pub step: usize,
}

/// Mid-training checkpoints: where, under which key, and how often.
#[derive(Clone, Debug)]
pub struct CheckpointSpec {
    pub dir: PathBuf,
    pub key: String,
    /// Save every this many iterations (and never at the end: the model cache keeps that).
    pub every: usize,
}

/// Train `model` on `images` and return the encoder. The stream is used for: the initial
/// weights, then per iteration the batch indices and the model's noise, then (after training)
/// the 32-byte seed of the encoder's own stream.
pub fn train(
    model: Model,
    cfg: &NeuralConfig,
    images: &ImageSet,
    latents: usize,
    rng: &mut Stream,
    progress: Option<&ProgressFn>,
) -> Result<NeuralEncoder, ReprError> {
    train_with_checkpoints(model, cfg, images, latents, rng, progress, None)
}

/// [`train`], saving a checkpoint every `ckpt.every` iterations and starting from the latest
/// valid checkpoint of `ckpt.key` if there is one. The result is bit-identical to an
/// uninterrupted training (the weights, the optimiser state, the batch permutation and the
/// stream's position are all restored; tested). The checkpoints are removed at the end.
pub fn train_with_checkpoints(
    model: Model,
    cfg: &NeuralConfig,
    images: &ImageSet,
    latents: usize,
    rng: &mut Stream,
    progress: Option<&ProgressFn>,
    ckpt: Option<&CheckpointSpec>,
) -> Result<NeuralEncoder, ReprError> {
    let start = rng.clone();
    let resumed = match ckpt {
        Some(c) => super::checkpoint::load_latest(c, model, cfg, images, latents, rng)?,
        None => None,
    };
    let (mut trainer, mut losses) = match resumed {
        Some(r) => r,
        None => {
            *rng = start;
            (Trainer::new(model, cfg, images, latents, rng)?, Vec::new())
        }
    };
    for step in trainer.step..cfg.iterations {
        let value = trainer.step(rng)?;
        if step % cfg.log_every == 0 || step + 1 == cfg.iterations {
            losses.push((step, value));
        }
        if let Some(c) = ckpt
            && c.every > 0
            && (step + 1) % c.every == 0
            && step + 1 < cfg.iterations
        {
            super::checkpoint::save(c, &trainer, rng, &losses)?;
        }
        if let Some(p) = progress {
            p(TrainProgress {
                iteration: step + 1,
                total: cfg.iterations,
                loss: value,
            });
        }
    }
    let trained = trainer.host_net()?;
    if let Some(c) = ckpt {
        super::checkpoint::remove_all(c);
    }
    let mut seed = [0u8; 32];
    rng.fill_bytes(&mut seed);
    Ok(NeuralEncoder::new(
        model,
        cfg.variant,
        trained,
        losses,
        seed,
    ))
}

/// The reconstruction loss of a trained network on (at most `max`) `images`: the Bernoulli
/// loss summed over pixels and averaged over images, of the decoder applied to each image's
/// noise-free code (AE: its sigmoid latents; VAE: mu; RFVAE: the flows applied to mu). No KL
/// term and no flow log-determinant, so it is comparable with the mean-image loss
/// ([`super::evidence::mean_image_loss`]) for every model.
pub fn reconstruction_loss(model: Model, net: &HostNet, images: &ImageSet, max: usize) -> f64 {
    let n = images.n.min(max);
    let per_image: Vec<f64> = (0..n)
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            let x = images.row(i);
            let logits = noise_free_logits(model, net, x, scratch);
            // softplus(l) - x l, stably.
            logits
                .iter()
                .zip(x)
                .map(|(&l, &t)| {
                    let l = f64::from(l);
                    l.max(0.0) + (-l.abs()).exp().ln_1p() - f64::from(t) * l
                })
                .sum::<f64>()
        })
        .collect();
    per_image.iter().sum::<f64>() / n as f64
}

/// The decoder's logits for an image's noise-free code (AE: its sigmoid latents; VAE: mu;
/// RFVAE: the flows applied to mu).
fn noise_free_logits(model: Model, net: &HostNet, x: &[f32], scratch: &mut Scratch) -> Vec<f32> {
    let d = net.latents;
    let head = net.encode_head(x, scratch);
    let mut code = vec![0.0f64; d];
    model.spec().mean_code(&head, d, &mut code);
    let z: Vec<f32> = code.iter().map(|&v| v as f32).collect();
    net.decode_logits(&z, scratch)
}

/// The reconstruction of an image (pixel probabilities, the sigmoid of the decoder's logits for
/// its noise-free code), as in [`reconstruction_loss`]: for figures.
pub fn reconstruct(model: Model, net: &HostNet, x: &[f32]) -> Vec<f32> {
    noise_free_logits(model, net, x, &mut Scratch::default())
        .into_iter()
        .map(|l| 1.0 / (1.0 + (-l).exp()))
        .collect()
}

/// Floating-point operations of one training iteration, counted as `3 x` the forward pass's
/// `2 m n k` per dense layer (`m` = batch).
pub fn flops_per_iteration(
    model: Model,
    dim: usize,
    hidden: [usize; 2],
    latents: usize,
    batch: usize,
) -> f64 {
    let [h1, h2] = hidden;
    let p: usize = model.head_blocks(latents).iter().sum();
    let macs = dim * h1 + h1 * h2 + h2 * p + latents * h2 + h2 * h1 + h1 * dim;
    3.0 * 2.0 * (batch * macs) as f64
}

/// `train` plus the training latents, as [`super::RepresentationLearner::fit`] returns them.
pub fn fit(
    model: Model,
    cfg: &NeuralConfig,
    images: &ImageSet,
    latents: usize,
    rng: &mut Stream,
    progress: Option<&ProgressFn>,
) -> Result<(NeuralEncoder, Latents), ReprError> {
    let mut enc = train(model, cfg, images, latents, rng, progress)?;
    let z = enc.training_latents(images)?;
    Ok((enc, z))
}

#[cfg(test)]
mod evidence_tests {
    use super::*;
    use crate::repr::evidence::mean_image_loss;
    use crate::seed::stream_named;

    /// A decoder that outputs the mean image's logits whatever the code has exactly the
    /// plateau loss; one that outputs 0 logits has 4900 ln 2 per image (any model).
    #[test]
    fn reconstruction_loss_of_constant_decoders() {
        let (n, dim) = (40, 30);
        let data: Vec<f32> = (0..n * dim)
            .map(|k| if (k * 7 + k / dim) % 5 == 0 { 1.0 } else { 0.0 })
            .collect();
        let images = ImageSet::new(n, dim, data).unwrap();
        let plateau = mean_image_loss(&images);
        for model in Model::ALL {
            let cfg = NeuralConfig {
                hidden: [8, 6],
                ..NeuralConfig::paper(model)
            };
            let mut net = init_net(model, &cfg, dim, 3, &mut stream_named(2, "ev"));
            net.dec_out.w.iter_mut().for_each(|w| *w = 0.0);
            net.dec_out.b.iter_mut().for_each(|b| *b = 0.0);
            let zero = reconstruction_loss(model, &net, &images, n);
            assert!(
                (zero - dim as f64 * 2f64.ln()).abs() < 1e-4,
                "{model:?}: {zero}"
            );
            for (p, b) in net.dec_out.b.iter_mut().enumerate() {
                let m = (0..n).map(|i| images.row(i)[p] as f64).sum::<f64>() / n as f64;
                let m = m.clamp(1e-7, 1.0 - 1e-7);
                *b = (m / (1.0 - m)).ln() as f32;
            }
            let mean = reconstruction_loss(model, &net, &images, n);
            assert!(
                (mean - plateau).abs() < 1e-3 * plateau,
                "{model:?}: {mean} vs {plateau}"
            );
        }
    }
}
