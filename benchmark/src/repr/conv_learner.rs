//! The follow-up's convolutional VAE and β-VAE as representation learners (`conv-vae`,
//! `conv-bvae`; Laversanne-Finot, Péré & Oudeyer, CoRL 2018): their configuration tables, the
//! training loop (resumable from checkpoints, bit-identical whatever the threads), and the
//! fitted encoder (the mean of the encoder's Gaussian; a model file for the model cache).
//!
//! - **Pictures**: RGB, stored rows first with the channels last (`HWC`, as `armballs-corl`
//!   renders them), square, of a side that is a multiple of 16 (64 x 64 for the follow-up). Each
//!   batch is turned channel-major for the networks ([`channels_first`]).
//! - **Training**, as the dense networks': the initial weights from the learner stream
//!   (PyTorch's default initialisation, [`ConvNet::init`]), then per iteration the first `batch`
//!   entries of a fresh partial Fisher-Yates shuffle ([`draw_batch`]), the reparameterisation
//!   noise (one `eps` per picture and latent), one step of the host engine ([`ConvTrainer`]),
//!   the loss checked finite and recorded every `log_every` iterations; after training, 32
//!   bytes of the stream are drawn (as every neural learner does), so the stream's use does
//!   not depend on the kind of network.
//! - `conv-vae` is the β = 1 VAE without capacity; `conv-bvae` the capacity-annealed β-VAE
//!   ([`ConvConfig`]).

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::checkpoint::{self, CheckpointSpec, Inspected, Restored, Snapshot};
use super::conv_net::{ConvArch, ConvInit, ConvNet, channels_first};
use super::conv_train::{ConvConfig, ConvTrainer};
use super::evidence::{EVIDENCE_IMAGES, TrainingEvidence, bce_of_logit, mean_image_loss};
use super::host_train::HostOptimizer;
use super::model_file::{ModelFileError, seal, unseal};
use super::nets::TfAdam;
use super::neural_model::Variant;
use super::params::{LearnerParams, ParamError, ParamGuard};
use super::trainer::{ProgressFn, draw_batch};
use super::training_loop::{Iterations, run_until};
use super::{
    Encoder, FitContext, GaussianPrior, ImageSet, Latents, ReprError, RepresentationLearner,
    Subnormals, TrainingOutcome, check_fit_input,
};
use crate::seed::Stream;

/// Colour channels of the pictures the convolutional learners take.
pub const CHANNELS: usize = 3;

/// The optimiser state's file in a checkpoint.
const OPTIM_FILE: &str = "optim.bin";

/// Pictures encoded at a time (bounds the activations' memory; the codes do not depend on it).
const ENCODE_CHUNK: usize = 100;

/// Which of the follow-up's two networks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ConvModel {
    /// `conv-vae`: β = 1, no capacity.
    ConvVae,
    /// `conv-bvae`: the capacity-annealed β-VAE.
    ConvBvae,
}

impl ConvModel {
    /// Name in campaign files and results.
    pub fn name(self) -> &'static str {
        match self {
            ConvModel::ConvVae => "conv-vae",
            ConvModel::ConvBvae => "conv-bvae",
        }
    }

    /// The training when the configuration sets nothing.
    pub fn default_config(self) -> ConvConfig {
        match self {
            ConvModel::ConvVae => ConvConfig::followup_vae(),
            ConvModel::ConvBvae => ConvConfig::followup_bvae(),
        }
    }
}

/// The partial form of [`ConvConfig`] for configuration files (`[learners.conv-vae]`,
/// `[learners.conv-bvae]`): missing keys take the model's default.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ConvSection {
    pub filters: Option<usize>,
    pub hidden: Option<usize>,
    pub iterations: Option<usize>,
    pub batch: Option<usize>,
    pub lr: Option<f64>,
    pub log_every: Option<usize>,
    /// `conv-bvae` only.
    pub beta: Option<f64>,
    /// `conv-bvae` only.
    pub capacity: Option<f64>,
    /// `conv-bvae` only.
    pub capacity_iterations: Option<usize>,
    /// `conv-bvae` only.
    pub warmup: Option<usize>,
    /// `conv-bvae` only.
    pub kl_delay: Option<usize>,
    /// `conv-bvae` only.
    pub delay_factor: Option<f64>,
    /// `conv-bvae` only.
    pub beta_final: Option<f64>,
    /// `conv-bvae` only.
    pub beta_from: Option<usize>,
    /// `conv-bvae` only.
    pub beta_until: Option<usize>,
    /// `conv-bvae` only.
    pub tc: Option<f64>,
    pub blur: Option<f64>,
    pub blur_until: Option<usize>,
    pub flush_subnormals: Option<bool>,
    pub init: Option<ConvInit>,
}

impl ConvSection {
    /// The complete configuration for `model`.
    pub fn resolve(&self, model: ConvModel) -> ConvConfig {
        let d = model.default_config();
        ConvConfig {
            filters: self.filters.unwrap_or(d.filters),
            hidden: self.hidden.unwrap_or(d.hidden),
            iterations: self.iterations.unwrap_or(d.iterations),
            batch: self.batch.unwrap_or(d.batch),
            lr: self.lr.unwrap_or(d.lr),
            log_every: self.log_every.unwrap_or(d.log_every),
            beta: self.beta.unwrap_or(d.beta),
            capacity: self.capacity.or(d.capacity),
            capacity_iterations: self.capacity_iterations.or(d.capacity_iterations),
            warmup: self.warmup.unwrap_or(d.warmup),
            kl_delay: self.kl_delay.unwrap_or(d.kl_delay),
            delay_factor: self.delay_factor.or(d.delay_factor),
            beta_final: self.beta_final.or(d.beta_final),
            beta_from: self.beta_from.or(d.beta_from),
            beta_until: self.beta_until.or(d.beta_until),
            tc: self.tc.or(d.tc),
            blur: self.blur.or(d.blur),
            blur_until: self.blur_until.or(d.blur_until),
            flush_subnormals: self.flush_subnormals.unwrap_or(d.flush_subnormals),
            init: self.init.unwrap_or(d.init),
        }
    }
}

impl ParamGuard for (ConvModel, ConvSection) {
    type Checked = ConvParams;
    fn check(self) -> Result<ConvParams, ParamError> {
        let (model, section) = self;
        if model == ConvModel::ConvVae {
            for (key, set) in [
                ("beta", section.beta.is_some()),
                ("capacity", section.capacity.is_some()),
                ("capacity_iterations", section.capacity_iterations.is_some()),
                ("warmup", section.warmup.is_some()),
                ("kl_delay", section.kl_delay.is_some()),
                ("delay_factor", section.delay_factor.is_some()),
                ("beta_final", section.beta_final.is_some()),
                ("beta_from", section.beta_from.is_some()),
                ("beta_until", section.beta_until.is_some()),
                ("tc", section.tc.is_some()),
            ] {
                if set {
                    return Err(ParamError::at(
                        key,
                        "the conv-vae is the β = 1 VAE; the β-VAE's settings go in \
                         [learners.conv-bvae]",
                    ));
                }
            }
        }
        let config = section.resolve(model);
        config.check()?;
        Ok(ConvParams { model, config })
    }
}

/// The checked `[learners.conv-vae|conv-bvae]` table.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvParams {
    pub model: ConvModel,
    pub config: ConvConfig,
}

impl LearnerParams for ConvParams {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn identity(&self, _variant: Option<Variant>) -> serde_json::Value {
        serde_json::to_value(&self.config).expect("serialisable")
    }
    fn deviations(&self, _variant: Option<Variant>) -> Vec<String> {
        vec![
            format!(
                "{}: training settings of ours (the authors' are not public): {} iterations, batch {}, \
             lr {}{}{}{}{}",
                self.model.name(),
                self.config.iterations,
                self.config.batch,
                self.config.lr,
                match self.config.capacity {
                    Some(c) => format!(", β {} and capacity {c} nats", self.config.beta),
                    None => String::new(),
                },
                match (self.config.beta_final, self.config.beta_from) {
                    (Some(last), Some(from)) => format!(
                        ", β moving to {last} from iteration {from} to {}",
                        self.config.beta_until.unwrap_or(from)
                    ),
                    _ => String::new(),
                },
                match self.config.tc {
                    Some(w) => format!(", a total-correlation term weighted {w} (β-TCVAE's)"),
                    None => String::new(),
                },
                match (self.config.blur, self.config.blur_until) {
                    (Some(s), Some(until)) => format!(
                        ", the reconstruction target blurred by a Gaussian of {s} pixels falling \
                         to none at iteration {until}"
                    ),
                    _ => String::new(),
                },
            ),
            if self.config.flush_subnormals {
                format!(
                    "{}: trained with subnormal numbers flushed to zero (x86-64 FTZ and DAZ; \
                 PyTorch's CPU default keeps them): the same bits on every x86-64 CPU, without \
                 Intel's slow subnormal assists",
                    self.model.name()
                )
            } else {
                format!(
                    "{}: trained with IEEE subnormals (flush_subnormals = false)",
                    self.model.name()
                )
            },
        ]
        .into_iter()
        .chain((self.config.init == ConvInit::Torch).then(|| {
            format!(
                "{}: today's PyTorch initialisation (init = \"{}\"): the last transposed \
                 convolution drawn 3.3 times wider than by the authors' PyTorch 0.4.0",
                self.model.name(),
                ConvInit::Torch.name()
            )
        }))
        .collect()
    }
    fn build(&self, _variant: Option<Variant>) -> Box<dyn RepresentationLearner> {
        Box::new(ConvLearner::new(self.model, self.config.clone()))
    }
}

/// A convolutional representation learner: the network, its training and an optional progress
/// callback.
#[derive(Clone)]
pub struct ConvLearner {
    pub model: ConvModel,
    pub config: ConvConfig,
    progress: Option<ProgressFn>,
}

impl std::fmt::Debug for ConvLearner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ConvLearner")
            .field("model", &self.model)
            .field("config", &self.config)
            .finish()
    }
}

impl ConvLearner {
    pub fn new(model: ConvModel, config: ConvConfig) -> Self {
        ConvLearner {
            model,
            config,
            progress: None,
        }
    }

    /// Report every training iteration to `f`.
    pub fn with_progress(mut self, f: ProgressFn) -> Self {
        self.progress = Some(f);
        self
    }
}

impl RepresentationLearner for ConvLearner {
    fn name(&self) -> &str {
        self.model.name()
    }

    fn fit(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        self.fit_in(images, latents, rng, &FitContext::default())
    }

    /// The training with the context's progress (else this learner's own), checkpoints and
    /// thread count: bit-identical whatever the context.
    fn fit_in(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
        ctx: &FitContext,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        let progress = ctx.progress.as_ref().or(self.progress.as_ref());
        let train = || {
            train(
                self.model,
                &self.config,
                images,
                latents,
                rng,
                progress,
                ctx.checkpoint.as_ref(),
            )
        };
        let subnormals = if self.config.flush_subnormals {
            Subnormals::Flushed
        } else {
            Subnormals::Kept
        };
        let mut enc = ctx.in_pool_with(subnormals, train)?;
        let z = enc.encode(images)?;
        Ok((Box::new(enc), z))
    }

    fn persists(&self) -> bool {
        true
    }

    fn load(&self, key: &str, bytes: &[u8]) -> Result<Box<dyn Encoder>, ModelFileError> {
        let enc = ConvEncoder::from_bytes(key, bytes)?;
        if enc.model != self.model {
            return Err(ModelFileError::Content(format!(
                "the file holds a {}, not a {}",
                enc.model.name(),
                self.model.name()
            )));
        }
        Ok(Box::new(enc))
    }

    fn saves_checkpoints(&self) -> bool {
        true
    }

    fn load_checkpoint(
        &self,
        _key: &str,
        checkpoint: &Inspected,
    ) -> Result<Box<dyn Encoder>, ModelFileError> {
        Ok(Box::new(ConvEncoder {
            model: self.model,
            net: ConvNet::from_model_bytes(&checkpoint.net)?,
            losses: checkpoint.losses.clone(),
            iterations: checkpoint.step,
        }))
    }
}

/// The network for `latents` dimensions of the pictures of `images` (RGB, square, `HWC`), with
/// the configuration's sizes; `Err` says why the pictures do not fit.
pub fn arch_for(
    cfg: &ConvConfig,
    images: &ImageSet,
    latents: usize,
) -> Result<ConvArch, ReprError> {
    let pixels = images.dim / CHANNELS;
    let side = (pixels as f64).sqrt().round() as usize;
    let arch = ConvArch {
        channels: CHANNELS,
        side,
        filters: cfg.filters,
        hidden: cfg.hidden,
        latents,
    };
    let square = images.dim.is_multiple_of(CHANNELS) && side * side == pixels;
    match arch.check() {
        Ok(()) if square => Ok(arch),
        why => Err(ReprError::InvalidInput(format!(
            "the convolutional networks take square RGB pictures whose side is a multiple of 16 \
             (the follow-up's armballs-corl: 64 x 64 x 3 = 12288 values); these have {} values{}",
            images.dim,
            why.err().map(|w| format!(" ({w})")).unwrap_or_default()
        ))),
    }
}

/// A training of a convolutional network in progress: the trainer, the batch sampler and the
/// iterations done.
struct ConvTraining<'a> {
    trainer: ConvTrainer,
    cfg: &'a ConvConfig,
    images: &'a ImageSet,
    perm: Vec<usize>,
    /// The batch, channel-major.
    x: Vec<f32>,
    step: usize,
}

impl<'a> ConvTraining<'a> {
    fn new(
        trainer: ConvTrainer,
        cfg: &'a ConvConfig,
        images: &'a ImageSet,
        perm: Vec<usize>,
        step: usize,
    ) -> Self {
        let k = cfg.batch.min(images.n);
        ConvTraining {
            trainer,
            cfg,
            images,
            perm,
            x: vec![0.0; k * images.dim],
            step,
        }
    }

    /// The training continuing from a trusted checkpoint.
    fn resume(
        cfg: &'a ConvConfig,
        images: &'a ImageSet,
        arch: ConvArch,
        r: &Restored<'_>,
    ) -> Result<Self, String> {
        let net = ConvNet::from_model_bytes(r.net).map_err(|e| e.to_string())?;
        if net.arch != arch || r.perm.len() != images.n {
            return Err("checkpoint does not match the training".into());
        }
        let bytes = std::fs::read(r.optim).map_err(|e| e.to_string())?;
        let mut trainer = ConvTrainer::new(net);
        trainer.opt = fresh_optimizer(&trainer.net)
            .read(&bytes)
            .map_err(|e| e.to_string())?;
        Ok(ConvTraining::new(
            trainer,
            cfg,
            images,
            r.perm.to_vec(),
            r.step,
        ))
    }
}

fn fresh_optimizer(net: &ConvNet) -> HostOptimizer {
    let sizes: Vec<usize> = net.params().iter().map(|p| p.len()).collect();
    HostOptimizer::adam(TfAdam::torch(), &sizes)
}

impl Iterations for ConvTraining<'_> {
    fn done(&self) -> usize {
        self.step
    }

    fn iterate(&mut self, rng: &mut Stream) -> Result<f64, ReprError> {
        let dim = self.images.dim;
        let k = self.x.len() / dim;
        draw_batch(&mut self.perm, k, rng);
        for (picture, &i) in self.x.chunks_exact_mut(dim).zip(&self.perm[..k]) {
            channels_first(self.images.row(i), CHANNELS, picture);
        }
        let value = self.trainer.step(self.cfg, &self.x, k, self.step, rng)?;
        if !value.is_finite() {
            return Err(ReprError::Numerical(format!(
                "convolutional VAE training diverged at iteration {}: loss = {value}",
                self.step
            )));
        }
        self.step += 1;
        Ok(value)
    }

    fn checkpoint(
        &self,
        c: &CheckpointSpec,
        rng: &Stream,
        losses: &[(usize, f64)],
    ) -> Result<(), ReprError> {
        let snapshot = Snapshot {
            step: self.step,
            losses,
            perm: &self.perm,
            param_ids: [0; 12],
            net: self.trainer.net.to_model_bytes(),
            optim_file: OPTIM_FILE,
        };
        checkpoint::save_snapshot(c, snapshot, rng, |path| {
            crate::fsio::write_atomic(path, &self.trainer.opt.to_bytes()).map_err(|e| {
                ReprError::Cache(format!("checkpoint: cannot write {}: {e}", path.display()))
            })
        })
    }
}

/// Train `model` with `cfg` on `images` and return the encoder. The stream gives the initial
/// weights, then per iteration the batch and the noise, then 32 bytes after training. With
/// `ckpt`, a checkpoint every `ckpt.every` iterations, and the latest valid one resumed
/// (bit-identical to an uninterrupted training); they are removed at the end.
pub fn train(
    model: ConvModel,
    cfg: &ConvConfig,
    images: &ImageSet,
    latents: usize,
    rng: &mut Stream,
    progress: Option<&ProgressFn>,
    ckpt: Option<&CheckpointSpec>,
) -> Result<ConvEncoder, ReprError> {
    cfg.check()
        .map_err(|e| ReprError::InvalidInput(format!("{}: {e}", model.name())))?;
    check_fit_input(images, latents)?;
    let arch = arch_for(cfg, images, latents)?;
    let start = rng.clone();
    let resumed = match ckpt {
        Some(c) => {
            checkpoint::load_latest_with(c, cfg.iterations, images.n, OPTIM_FILE, rng, |r| {
                ConvTraining::resume(cfg, images, arch, r)
            })?
        }
        None => None,
    };
    let (mut training, mut losses) = match resumed {
        Some(r) => r,
        None => {
            *rng = start;
            let net = ConvNet::init(rng, arch, cfg.init);
            let training = ConvTraining::new(
                ConvTrainer::new(net),
                cfg,
                images,
                (0..images.n).collect(),
                0,
            );
            (training, Vec::new())
        }
    };
    run_until(
        &mut training,
        cfg.iterations,
        cfg.log_every,
        rng,
        &mut losses,
        ckpt,
        progress,
    )?;
    if let Some(c) = ckpt {
        checkpoint::remove_all(c);
    }
    let mut seed = [0u8; 32];
    rng.fill_bytes(&mut seed);
    Ok(ConvEncoder {
        model,
        net: training.trainer.net,
        losses,
        iterations: cfg.iterations,
    })
}

/// A trained convolutional network as an encoder: the mean of its Gaussian posterior, image by
/// image group (the codes do not depend on the grouping or the threads).
#[derive(Clone, Debug, PartialEq)]
pub struct ConvEncoder {
    pub model: ConvModel,
    pub net: ConvNet,
    /// The recorded loss curve, `(iteration, mini-batch loss)`.
    pub losses: Vec<(usize, f64)>,
    /// The iterations trained.
    pub iterations: usize,
}

/// The header of a convolutional encoder's model file.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct EncoderHeader {
    key: String,
    model: ConvModel,
    arch: ConvArch,
    iterations: usize,
    losses: Vec<(usize, f64)>,
}

impl ConvEncoder {
    /// The encoder's head outputs (`[n, 2d]`: mean | log-variance) of the `HWC` pictures of
    /// `images`.
    pub fn heads(&self, images: &ImageSet) -> Result<Vec<f32>, ReprError> {
        let arch = self.net.arch;
        if images.dim != arch.image_len() {
            return Err(ReprError::InvalidInput(format!(
                "the network takes pictures of {} values ({} x {} x {}), got {}",
                arch.image_len(),
                arch.side,
                arch.side,
                arch.channels,
                images.dim
            )));
        }
        let mut heads = Vec::with_capacity(images.n * 2 * arch.latents);
        let mut x = Vec::new();
        for first in (0..images.n).step_by(ENCODE_CHUNK) {
            let m = ENCODE_CHUNK.min(images.n - first);
            x.resize(m * images.dim, 0.0);
            for (j, picture) in x.chunks_exact_mut(images.dim).enumerate() {
                channels_first(images.row(first + j), arch.channels, picture);
            }
            heads.extend(self.net.encode_heads(&x, m));
        }
        Ok(heads)
    }

    /// The mean KL divergence of each latent's posterior from the prior N(0, 1) over `images`,
    /// in nats: `mean_i 0.5 (mu^2 + exp(logvar) - logvar - 1)`. The follow-up's criterion of an
    /// active latent, and how it orders the modules.
    pub fn per_latent_kl(&self, images: &ImageSet) -> Result<Vec<f64>, ReprError> {
        let d = self.net.arch.latents;
        let heads = self.heads(images)?;
        let mut kl = vec![0.0f64; d];
        for h in heads.chunks_exact(2 * d) {
            for (j, k) in kl.iter_mut().enumerate() {
                let (mu, lv) = (f64::from(h[j]), f64::from(h[d + j]));
                *k += 0.5 * (mu * mu + libm::exp(lv) - lv - 1.0);
            }
        }
        let n = images.n.max(1) as f64;
        Ok(kl.into_iter().map(|k| k / n).collect())
    }

    /// The reconstruction loss on (at most `max`) `images`: the Bernoulli loss summed over the
    /// values and averaged over the pictures, of the decoder applied to each picture's mean
    /// code, comparable with the mean-picture loss ([`mean_image_loss`]).
    pub fn reconstruction_loss(&self, images: &ImageSet, max: usize) -> Result<f64, ReprError> {
        let set = images.head(max);
        let d = self.net.arch.latents;
        let heads = self.heads(&set)?;
        let mut total = 0.0f64;
        let mut chw = vec![0.0f32; set.dim];
        for (c, group) in heads.chunks(ENCODE_CHUNK * 2 * d).enumerate() {
            let m = group.len() / (2 * d);
            let z: Vec<f32> = group
                .chunks_exact(2 * d)
                .flat_map(|h| h[..d].iter().copied())
                .collect();
            let logits = self.net.decode_logits(&z, m);
            for (j, picture) in logits.chunks_exact(set.dim).enumerate() {
                channels_first(
                    set.row(c * ENCODE_CHUNK + j),
                    self.net.arch.channels,
                    &mut chw,
                );
                total += picture
                    .iter()
                    .zip(&chw)
                    .map(|(&l, &t)| bce_of_logit(l, t))
                    .sum::<f64>();
            }
        }
        Ok(total / set.n.max(1) as f64)
    }

    /// Read back [`Encoder::save`]'s bytes; `Err` says why they cannot be trusted.
    pub fn from_bytes(key: &str, bytes: &[u8]) -> Result<ConvEncoder, ModelFileError> {
        let (header, payload) = unseal(bytes)?;
        let h: EncoderHeader =
            serde_json::from_slice(header).map_err(|e| ModelFileError::Header(e.to_string()))?;
        if h.key != key {
            return Err(ModelFileError::Key { found: h.key });
        }
        Ok(ConvEncoder {
            model: h.model,
            net: ConvNet::from_payload(h.arch, payload)?,
            losses: h.losses,
            iterations: h.iterations,
        })
    }
}

impl Encoder for ConvEncoder {
    fn latents(&self) -> usize {
        self.net.arch.latents
    }

    fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        let d = self.net.arch.latents;
        let heads = self.heads(images)?;
        let data = heads
            .chunks_exact(2 * d)
            .flat_map(|h| h[..d].iter().map(|&v| f64::from(v)))
            .collect();
        let z = Latents {
            n: images.n,
            latents: d,
            data,
        };
        super::check_latents(&z, self.model.name())?;
        Ok(z)
    }

    fn reconstruct(&mut self, image: &[f32]) -> Option<Result<Vec<f32>, ReprError>> {
        let one = match ImageSet::new(1, image.len(), image.to_vec()) {
            Ok(s) => s,
            Err(e) => return Some(Err(e)),
        };
        let d = self.net.arch.latents;
        Some(self.heads(&one).map(|h| {
            let logits = self.net.decode_logits(&h[..d], 1);
            // Back to the pictures' layout (channels last).
            let c = self.net.arch.channels;
            let pixels = logits.len() / c;
            (0..logits.len())
                .map(|k| {
                    let (p, ch) = (k / c, k % c);
                    1.0 / (1.0 + libm::expf(-logits[ch * pixels + p]))
                })
                .collect()
        }))
    }

    fn per_latent_kl(&mut self, images: &ImageSet) -> Option<Result<Vec<f64>, ReprError>> {
        Some(ConvEncoder::per_latent_kl(self, images))
    }

    fn prior(&self) -> Option<GaussianPrior> {
        let d = self.net.arch.latents;
        Some(GaussianPrior {
            mean: vec![0.0; d],
            std: vec![1.0; d],
        })
    }

    fn save(&self, key: &str) -> Option<Vec<u8>> {
        let header = serde_json::to_vec(&EncoderHeader {
            key: key.to_string(),
            model: self.model,
            arch: self.net.arch,
            iterations: self.iterations,
            losses: self.losses.clone(),
        })
        .expect("a header serialises");
        Some(seal(&header, &self.net.payload()))
    }

    fn training_outcome(&self, images: &ImageSet) -> Option<TrainingOutcome> {
        let evidence = images.head(EVIDENCE_IMAGES);
        let rec = self.reconstruction_loss(&evidence, evidence.n).ok()?;
        Some(TrainingOutcome {
            losses: self.losses.clone(),
            iterations: self.iterations,
            evidence: TrainingEvidence::new(mean_image_loss(&evidence), rec, evidence.n),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    /// `n` RGB pictures of 16 x 16 (`HWC`), one lit square each, its colour by picture.
    fn pictures(n: usize) -> ImageSet {
        let side = 16;
        let dim = side * side * CHANNELS;
        let mut data = vec![0.0f32; n * dim];
        for (i, p) in data.chunks_exact_mut(dim).enumerate() {
            let (y0, x0) = ((i * 5) % (side - 4), (i * 3) % (side - 4));
            for y in y0..y0 + 4 {
                for x in x0..x0 + 4 {
                    for c in 0..CHANNELS {
                        p[(y * side + x) * CHANNELS + c] = if (i + c) % 2 == 0 { 1.0 } else { 0.5 };
                    }
                }
            }
        }
        ImageSet::new(n, dim, data).unwrap()
    }

    /// The small β-VAE of [`small`], 2 latents, trained on `images` from learner seed 1.
    fn small_bvae(images: &ImageSet) -> ConvEncoder {
        train(
            ConvModel::ConvBvae,
            &small(),
            images,
            2,
            &mut stream_named(1, "learner"),
            None,
            None,
        )
        .unwrap()
    }

    fn small() -> ConvConfig {
        ConvConfig {
            filters: 3,
            hidden: 8,
            iterations: 12,
            batch: 4,
            log_every: 5,
            warmup: 4,
            ..ConvConfig::followup_bvae()
        }
    }

    #[test]
    fn pictures_that_do_not_fit_are_refused_with_the_reason() {
        let gray = ImageSet::new(3, 4900, vec![0.0; 3 * 4900]).unwrap();
        let e = arch_for(&small(), &gray, 2).unwrap_err().to_string();
        assert!(e.contains("4900 values") && e.contains("12288"), "{e}");
        let odd = ImageSet::new(3, 3 * 20 * 20, vec![0.0; 3 * 1200]).unwrap();
        let e = arch_for(&small(), &odd, 2).unwrap_err().to_string();
        assert!(e.contains("multiple of 16"), "{e}");
        assert_eq!(arch_for(&small(), &pictures(3), 2).unwrap().side, 16);
    }

    /// The flush is on by default, can be turned off for both networks, and is part of the
    /// run's identity and its listed deviations.
    #[test]
    fn the_flush_of_subnormals_is_a_recorded_choice() {
        for model in [ConvModel::ConvVae, ConvModel::ConvBvae] {
            let on = (model, ConvSection::default()).check().unwrap();
            let off = (
                model,
                ConvSection {
                    flush_subnormals: Some(false),
                    ..ConvSection::default()
                },
            )
                .check()
                .unwrap();
            assert!(on.config.flush_subnormals && !off.config.flush_subnormals);
            assert_ne!(on.identity(None), off.identity(None));
            assert!(
                on.deviations(None)
                    .iter()
                    .any(|d| d.contains("flushed to zero"))
            );
            assert!(
                off.deviations(None)
                    .iter()
                    .any(|d| d.contains("IEEE subnormals"))
            );
        }
    }

    #[test]
    fn the_vae_refuses_the_beta_vaes_settings() {
        let section = ConvSection {
            capacity: Some(3.0),
            ..ConvSection::default()
        };
        let e = (ConvModel::ConvVae, section.clone()).check().unwrap_err();
        assert_eq!(e.key.as_deref(), Some("capacity"));
        assert!((ConvModel::ConvBvae, section).check().is_ok());
        let e = (
            ConvModel::ConvBvae,
            ConvSection {
                capacity_iterations: Some(0),
                ..ConvSection::default()
            },
        )
            .check()
            .unwrap_err();
        assert_eq!(e.key.as_deref(), Some("capacity_iterations"));
        let delayed = ConvSection {
            kl_delay: Some(100),
            ..ConvSection::default()
        };
        let e = (ConvModel::ConvVae, delayed.clone()).check().unwrap_err();
        assert_eq!(e.key.as_deref(), Some("kl_delay"));
        let p = (ConvModel::ConvBvae, delayed).check().unwrap();
        assert_eq!(p.config.kl_delay, 100);
        // A later β: the β-VAE's, said among its deviations.
        let later = ConvSection {
            beta_final: Some(40.0),
            beta_from: Some(1000),
            beta_until: Some(2000),
            ..ConvSection::default()
        };
        let e = (ConvModel::ConvVae, later.clone()).check().unwrap_err();
        assert_eq!(e.key.as_deref(), Some("beta_final"));
        let p = (ConvModel::ConvBvae, later).check().unwrap();
        assert_eq!(p.config.beta_at(1500), 22.0);
        assert!(
            p.deviations(None)
                .iter()
                .any(|d| d.contains(", β moving to 40 from iteration 1000 to 2000")),
            "{:?}",
            p.deviations(None)
        );
        // A total-correlation weight: the β-VAE's, checked, said among its deviations, and
        // out of the identity when unset.
        let weighted = ConvSection {
            tc: Some(10.0),
            ..ConvSection::default()
        };
        let e = (ConvModel::ConvVae, weighted.clone()).check().unwrap_err();
        assert_eq!(e.key.as_deref(), Some("tc"));
        let p = (ConvModel::ConvBvae, weighted).check().unwrap();
        assert!(
            p.deviations(None)
                .iter()
                .any(|d| d.contains(", a total-correlation term weighted 10")),
            "{:?}",
            p.deviations(None)
        );
        assert_eq!(p.identity(None)["tc"], 10.0);
        let plain = (ConvModel::ConvBvae, ConvSection::default())
            .check()
            .unwrap();
        assert!(plain.identity(None).get("tc").is_none());
        for bad in [0.0, -1.0, f64::NAN, 2e6] {
            let section = ConvSection {
                tc: Some(bad),
                ..ConvSection::default()
            };
            let e = (ConvModel::ConvBvae, section).check().unwrap_err();
            assert_eq!(e.key.as_deref(), Some("tc"), "{bad}: {e}");
        }
        // A blurred target: either network's, checked, said among the deviations, out of the
        // identity when unset.
        let blurred = ConvSection {
            blur: Some(16.0),
            blur_until: Some(3000),
            ..ConvSection::default()
        };
        for model in [ConvModel::ConvVae, ConvModel::ConvBvae] {
            let p = (model, blurred.clone()).check().unwrap();
            assert!(
                p.deviations(None).iter().any(|d| d.contains(
                    ", the reconstruction target blurred by a Gaussian of 16 pixels falling to \
                     none at iteration 3000"
                )),
                "{:?}",
                p.deviations(None)
            );
            assert_eq!(p.identity(None)["blur_until"], 3000);
        }
        assert!(plain.identity(None).get("blur").is_none());
        for (blur, until, key) in [
            (Some(16.0), None, "blur_until"),
            (None, Some(3000), "blur_until"),
            (Some(0.0), Some(3000), "blur"),
            (Some(65.0), Some(3000), "blur"),
            (Some(f64::NAN), Some(3000), "blur"),
            (Some(16.0), Some(0), "blur_until"),
            (Some(16.0), Some(5001), "blur_until"),
        ] {
            let section = ConvSection {
                blur,
                blur_until: until,
                ..ConvSection::default()
            };
            let e = (ConvModel::ConvBvae, section).check().unwrap_err();
            assert_eq!(e.key.as_deref(), Some(key), "{blur:?} {until:?}: {e}");
        }
    }

    /// A training killed after a checkpoint and started again gives the same network, bit for
    /// bit, as one that ran through; a damaged checkpoint is skipped (an older one or a fresh
    /// start), never trusted.
    #[test]
    fn a_resumed_training_is_the_uninterrupted_one() {
        let images = pictures(10);
        let cfg = small();
        let fit = |progress: Option<&ProgressFn>, ckpt: Option<&CheckpointSpec>| {
            let mut rng = stream_named(5, "learner");
            train(
                ConvModel::ConvBvae,
                &cfg,
                &images,
                2,
                &mut rng,
                progress,
                ckpt,
            )
            .unwrap()
        };
        let through = fit(None, None);
        let dir = tempfile::tempdir().unwrap();
        let spec = CheckpointSpec {
            dir: dir.path().to_path_buf(),
            key: "k".into(),
            every: 5,
            keep: false,
        };
        // The "killed" run: stopped after 7 iterations, with the checkpoint of iteration 5.
        let short = ConvConfig {
            iterations: 7,
            ..cfg.clone()
        };
        let mut rng = stream_named(5, "learner");
        let arch = arch_for(&cfg, &images, 2).unwrap();
        let mut t = ConvTraining::new(
            ConvTrainer::new(ConvNet::init(&mut rng, arch, cfg.init)),
            &short,
            &images,
            (0..images.n).collect(),
            0,
        );
        let mut losses = vec![];
        run_until(
            &mut t,
            7,
            cfg.log_every,
            &mut rng,
            &mut losses,
            Some(&spec),
            None,
        )
        .unwrap();
        assert!(dir.path().join("k.ckpt.5").join("state.json").exists());
        // Counts the iterations a training does.
        let counter = || {
            let n = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
            let m = n.clone();
            let f: ProgressFn = std::sync::Arc::new(move |_| {
                m.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            });
            (n, f)
        };
        let (done, progress) = counter();
        let resumed = fit(Some(&progress), Some(&spec));
        assert_eq!(resumed, through);
        assert_eq!(
            done.load(std::sync::atomic::Ordering::Relaxed),
            12 - 5,
            "resumed at 5"
        );
        assert!(
            std::fs::read_dir(dir.path()).unwrap().next().is_none(),
            "checkpoints are removed at the end"
        );
        // A damaged checkpoint: the optimiser file changed after its hash was taken.
        let mut rng = stream_named(5, "learner");
        let mut t = ConvTraining::new(
            ConvTrainer::new(ConvNet::init(&mut rng, arch, cfg.init)),
            &short,
            &images,
            (0..images.n).collect(),
            0,
        );
        run_until(
            &mut t,
            7,
            cfg.log_every,
            &mut rng,
            &mut vec![],
            Some(&spec),
            None,
        )
        .unwrap();
        std::fs::write(dir.path().join("k.ckpt.5").join(OPTIM_FILE), b"junk").unwrap();
        let (done, progress) = counter();
        let fresh = fit(Some(&progress), Some(&spec));
        assert_eq!(fresh, through);
        assert_eq!(
            done.load(std::sync::atomic::Ordering::Relaxed),
            12,
            "started over"
        );
    }

    /// Kept checkpoints outlive the training, and a checkpoint read back as an encoder
    /// (`ugl embed --checkpoint`) is the network of a training stopped there: the weights and
    /// loss curve of a 4-iteration training, part-way through a 12-iteration one whose schedule
    /// does not depend on its length. A checkpoint not kept is refused with the ones there are.
    #[test]
    fn a_kept_checkpoint_is_the_network_part_way() {
        let images = pictures(10);
        let cfg = ConvConfig {
            capacity_iterations: Some(6),
            ..small()
        };
        let fit = |cfg: &ConvConfig, ckpt: Option<&CheckpointSpec>| {
            let mut rng = stream_named(5, "learner");
            train(ConvModel::ConvBvae, cfg, &images, 2, &mut rng, None, ckpt).unwrap()
        };
        let dir = tempfile::tempdir().unwrap();
        let spec = CheckpointSpec {
            dir: dir.path().to_path_buf(),
            key: "k".into(),
            every: 4,
            keep: true,
        };
        fit(&cfg, Some(&spec));
        for step in [4, 8] {
            assert!(
                dir.path()
                    .join(format!("k.ckpt.{step}/state.json"))
                    .exists()
            );
        }
        let four = fit(
            &ConvConfig {
                iterations: 4,
                ..cfg.clone()
            },
            None,
        );
        let learner = ConvLearner::new(ConvModel::ConvBvae, cfg.clone());
        let seen = checkpoint::inspect(dir.path(), "k", 4, images.n).unwrap();
        let mut enc = learner.load_checkpoint("k", &seen).unwrap();
        assert_eq!(
            enc.encode(&images).unwrap(),
            four.clone().encode(&images).unwrap()
        );
        // Its loss curve so far: the 4-iteration training's without the last iteration, which
        // a finished training always logs.
        let outcome = enc.training_outcome(&images).unwrap();
        assert_eq!(outcome.iterations, 4);
        assert_eq!(outcome.losses[..], four.losses[..four.losses.len() - 1]);
        // Part-way is not the end: the 8-iteration network encodes otherwise.
        let seen = checkpoint::inspect(dir.path(), "k", 8, images.n).unwrap();
        let mut eight = learner.load_checkpoint("k", &seen).unwrap();
        assert_ne!(
            eight.encode(&images).unwrap(),
            four.clone().encode(&images).unwrap()
        );
        let e = checkpoint::inspect(dir.path(), "k", 6, images.n)
            .unwrap_err()
            .to_string();
        assert!(e.contains("after 4, 8 iterations"), "{e}");
        let e = checkpoint::inspect(dir.path(), "other", 4, images.n)
            .unwrap_err()
            .to_string();
        assert!(e.contains("none of this network"), "{e}");
    }

    /// The per-latent KL is the closed form of the heads, and a latent the network ignores
    /// (mean 0, variance 1) has none.
    #[test]
    fn the_per_latent_kl() {
        let images = pictures(6);
        let mut enc = small_bvae(&images);
        let heads = enc.heads(&images).unwrap();
        let kl = enc.per_latent_kl(&images).unwrap();
        let want: f64 = heads
            .chunks_exact(4)
            .map(|h| {
                let (mu, lv) = (f64::from(h[1]), f64::from(h[3]));
                0.5 * (mu * mu + lv.exp() - lv - 1.0)
            })
            .sum::<f64>()
            / 6.0;
        assert!((kl[1] - want).abs() < 1e-12, "{} vs {want}", kl[1]);
        // Silence latent 0: its head weights and biases (mean, log-variance) set to 0.
        let h = enc.net.arch.hidden;
        let d = 2;
        for r in 0..h {
            enc.net.head.w[r * 2 * d] = 0.0;
            enc.net.head.w[r * 2 * d + d] = 0.0;
        }
        enc.net.head.b[0] = 0.0;
        enc.net.head.b[d] = 0.0;
        let kl = enc.per_latent_kl(&images).unwrap();
        assert_eq!(kl[0], 0.0);
        assert!(kl[1] > 0.0);
    }

    /// The reconstruction loss of a set decoded in groups is the mean of each picture's own
    /// (150 pictures: two groups).
    #[test]
    fn the_reconstruction_loss_is_the_mean_over_pictures() {
        let images = pictures(150);
        let enc = small_bvae(&images);
        let all = enc.reconstruction_loss(&images, 150).unwrap();
        let each: f64 = (0..150)
            .map(|i| {
                let one = ImageSet::new(1, images.dim, images.row(i).to_vec()).unwrap();
                enc.reconstruction_loss(&one, 1).unwrap()
            })
            .sum::<f64>()
            / 150.0;
        assert!((all - each).abs() < 1e-9 * each, "{all} vs {each}");
        assert!(
            enc.reconstruction_loss(&images, 10).unwrap() != all,
            "max is honoured"
        );
    }

    #[test]
    fn a_model_file_of_the_other_network_is_refused() {
        let images = pictures(6);
        let enc = small_bvae(&images);
        let bytes = enc.save("k").unwrap();
        let vae = ConvLearner::new(ConvModel::ConvVae, ConvConfig::followup_vae());
        assert!(vae.load("k", &bytes).is_err());
        let bvae = ConvLearner::new(ConvModel::ConvBvae, small());
        assert!(bvae.load("k", &bytes).is_ok());
    }
}
