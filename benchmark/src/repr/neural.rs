//! The neural representation learners of the paper (AE, VAE, RFVAE; docs/original-code.md section 5):
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

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::model_file::ModelFileError;
pub use super::nets::Init;
pub use super::neural_encoder::{reconstruct, reconstruction_loss};
pub use super::neural_model::{
    Knobs, Latent, LatentInput, NeuralModel, Optimiser, StepInput, Variant, knob_count,
    knob_number, normals, tensor2,
};
use super::params::{LearnerParams, ParamError, ParamGuard};
use super::{Encoder, ImageSet, Latents, ReprError, RepresentationLearner};
use crate::seed::Stream;

pub use super::checkpoint::CheckpointSpec;
pub use super::neural_config::{
    BACKEND, Engine, LEGACY_WARMUP, Model, NeuralConfig, PlateauRule, training_device, unknown_knob,
};
pub use super::neural_encoder::NeuralEncoder;
pub use super::trainer::{ProgressFn, ResumeState, TrainProgress, Trainer, draw_batch, init_net};

/// The partial form of [`NeuralConfig`] for configuration files (`[learners.vae]` etc.):
/// missing keys take the paper's value for the model ([`NeuralSection::resolve`]). The variant
/// is not here: it is a dimension of the run matrix (`matrix.variants`, `ugl run --variant`).
/// Keys beyond the shared ones are the model's own knobs (the RFVAE's `warmup`, the β-VAE's
/// `beta` and `capacity`: [`NeuralModel::own_knobs`]); the model checks them, and a key no model
/// has is refused with its name.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NeuralSection {
    pub iterations: Option<usize>,
    pub hidden: Option<[usize; 2]>,
    pub batch: Option<usize>,
    pub lr: Option<f64>,
    pub log_every: Option<usize>,
    /// Weight initialisation: `paper`, `he` or `glorot` ([`Init`]).
    pub init: Option<Init>,
    /// Training engine: `host` (default) or `burn` ([`Engine`]).
    pub engine: Option<Engine>,
    /// The plateau rule: `{ chunk = N, cap = M }` ([`PlateauRule`]).
    pub plateau: Option<PlateauRule>,
    /// The model's own knobs, as written in the table.
    #[serde(flatten)]
    pub knobs: Knobs,
}

impl NeuralSection {
    /// The complete configuration for `model` and `variant` (the knobs as the model records
    /// them; [`ParamGuard::check`] has refused any it does not accept).
    pub fn resolve(&self, model: Model, variant: Variant) -> NeuralConfig {
        let p = NeuralConfig::paper(model);
        let spec = model.spec();
        let mut knobs = p.knobs;
        for (key, value) in &self.knobs {
            let value = spec
                .knob_value(key, value)
                .unwrap_or_else(|_| value.clone());
            knobs.insert(key.clone(), value);
        }
        NeuralConfig {
            iterations: self.iterations.unwrap_or(p.iterations),
            hidden: self.hidden.unwrap_or(p.hidden),
            batch: self.batch.unwrap_or(p.batch),
            lr: self.lr.unwrap_or(p.lr),
            variant,
            log_every: self.log_every.unwrap_or(p.log_every),
            init: self.init.unwrap_or(p.init),
            engine: self.engine.unwrap_or(p.engine),
            plateau: self.plateau,
            knobs,
        }
    }
}

impl ParamGuard for (Model, NeuralSection) {
    type Checked = NeuralParams;
    fn check(self) -> Result<NeuralParams, ParamError> {
        let (model, section) = self;
        let spec = model.spec();
        for (key, value) in &section.knobs {
            if !spec.own_knobs().contains(&key.as_str()) {
                return Err(unknown_knob(model, key));
            }
            spec.knob_value(key, value)
                .map_err(|e| ParamError::at(key, e))?;
        }
        section.resolve(model, Variant::Faithful).check(model)?;
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
        let train = || {
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
        let mut enc = ctx.in_pool(train)?;
        let z = enc.training_latents(images)?;
        Ok((Box::new(enc), z))
    }

    fn persists(&self) -> bool {
        true
    }

    fn load(&self, key: &str, bytes: &[u8]) -> Result<Box<dyn Encoder>, ModelFileError> {
        let enc = super::cache::from_bytes(key, bytes)?;
        if (enc.model, enc.variant) != (self.model, self.config.variant) {
            return Err(ModelFileError::Content(format!(
                "the file holds a {} ({}), not a {} ({})",
                enc.model.name(),
                enc.variant,
                self.model.name(),
                self.config.variant
            )));
        }
        Ok(Box::new(enc))
    }

    fn saves_checkpoints(&self) -> bool {
        true
    }

    /// A dense checkpoint's weights are an encoder's model file, with the loss curve so far.
    fn load_checkpoint(
        &self,
        key: &str,
        checkpoint: &super::checkpoint::Inspected,
    ) -> Result<Box<dyn Encoder>, ModelFileError> {
        self.load(key, &checkpoint.net)
    }
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
    // Where the training may stop: `iterations`, and with the plateau rule every `chunk` more
    // up to the cap. A resumed training passed every boundary before its step (each found the
    // network on the plateau: the check is a function of the weights), and a checkpoint is
    // never written at a boundary, so its target is the first boundary after it.
    let boundaries: Vec<usize> = match cfg.plateau {
        Some(rule) => rule.boundaries(cfg.iterations).collect(),
        None => vec![cfg.iterations],
    };
    let mut at = boundaries
        .iter()
        .position(|&b| b > trainer.step)
        .unwrap_or(boundaries.len() - 1);
    let evidence = images.head(super::evidence::EVIDENCE_IMAGES);
    let plateau_loss = super::evidence::mean_image_loss(&evidence);
    loop {
        let target = boundaries[at];
        super::training_loop::run_until(
            &mut trainer,
            target,
            cfg.log_every,
            rng,
            &mut losses,
            ckpt,
            progress,
        )?;
        if at + 1 >= boundaries.len() {
            break;
        }
        let net = trainer.host_net()?;
        let rec = super::neural_encoder::reconstruction_loss(model, &net, &evidence, evidence.n);
        if rec / plateau_loss < super::evidence::UNTRAINED_FRACTION {
            break;
        }
        at += 1;
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
                *b = libm::log(m / (1.0 - m)) as f32;
            }
            let mean = reconstruction_loss(model, &net, &images, n);
            assert!(
                (mean - plateau).abs() < 1e-3 * plateau,
                "{model:?}: {mean} vs {plateau}"
            );
        }
    }
}
