//! The configuration of a dense neural learner: which model, which engine, and the training
//! recipe (`[learners.ae|vae|rfvae|bvae]`), with the paper's values.

use burn::tensor::Device;
use serde::{Deserialize, Serialize};

use super::ReprError;
use super::nets::Init;
use super::neural_model::{CodeSettings, Knobs, NeuralModel, Variant};
use super::params::ParamError;
use crate::repr::{ae, bvae, rfvae, vae};

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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
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

impl<'de> Deserialize<'de> for Engine {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        super::nets::named_choice(d, &Engine::ALL, Engine::name)
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

/// Training configuration of a dense neural learner: what every dense network shares, and the
/// model's own knobs ([`Knobs`]: the RFVAE's warm-up, the β-VAE's weight and capacity), which the
/// model declares, checks and reads ([`NeuralModel::own_knobs`]). Every field is required in
/// serde form (it is the complete, hashable description of a training run); `NeuralSection`
/// (`neural.rs`) is the partial form for configuration files, with the paper's values per model
/// as defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NeuralConfig {
    /// Optimiser steps. 0 keeps the initial weights: the *untrained twin* of a trained network
    /// (same architecture, init, data set and exploration streams), the control of
    /// `data/campaigns/paper-untrained.toml`.
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
    /// How the weights are drawn (paper: truncated normal, std 0.001). Absent in manifests
    /// written before it was configurable, which all used the paper's.
    #[serde(default)]
    pub init: Init,
    /// What runs the iterations. Absent in manifests written before it was configurable, which
    /// all trained on burn.
    #[serde(default = "Engine::before_v3")]
    pub engine: Engine,
    /// The plateau rule ([`PlateauRule`]): train on past `iterations`, in fixed chunks, while the
    /// network is still on the mean-image plateau. Absent: train exactly `iterations` (and the
    /// configurations and hashes of profiles without it are what they were).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plateau: Option<PlateauRule>,
    /// The model's own knobs, resolved (the table's values, the model's defaults for the rest),
    /// and `warmup` = 0 for the models without one ([`LEGACY_WARMUP`]).
    #[serde(flatten)]
    pub knobs: Knobs,
}

/// Every dense network recorded a `warmup` (0 where the model has none) before the knobs moved
/// to their models; a configuration still records it, so that its hash, and with it every
/// committed store's, holds. It is not a key of those models' tables.
pub const LEGACY_WARMUP: &str = "warmup";

/// Train on while on the plateau: after `iterations`, and after every further `chunk`
/// iterations, the reconstruction loss of the first [`super::evidence::EVIDENCE_IMAGES`]
/// training images is compared with their mean-image loss; while it is not below
/// [`super::evidence::UNTRAINED_FRACTION`] of it and fewer than `cap` iterations have run, the
/// training goes on for `chunk` more (the same stream, optimiser and schedule: the RFVAE's
/// warm-up and the β-VAE's capacity have saturated by then). The check draws nothing, so a run
/// is still a function of its identity; a resumed training finds its place from the iteration
/// count alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlateauRule {
    /// Iterations per extension.
    pub chunk: usize,
    /// Most iterations in all, `iterations` included.
    pub cap: usize,
}

impl PlateauRule {
    /// Where the training may stop: `iterations`, then every `chunk` more, up to `cap`.
    pub fn boundaries(&self, iterations: usize) -> impl Iterator<Item = usize> + '_ {
        (0..)
            .map(move |k| iterations + k * self.chunk)
            .take_while(move |&b| b <= self.cap.max(iterations))
    }
}

impl NeuralConfig {
    /// The most iterations this training can run: `iterations`, or the plateau rule's cap.
    pub fn max_iterations(&self) -> usize {
        self.plateau
            .map_or(self.iterations, |r| r.cap.max(self.iterations))
    }

    /// The settings of the model's KL term at iteration `step`.
    pub fn code_at(&self, model: Model, step: usize) -> CodeSettings {
        model
            .spec()
            .code_settings(&self.knobs, step, self.iterations, self.variant)
    }

    /// The capacity C of the annealed β-VAE objective at 0-based iteration `step` (None: a plain
    /// KL term).
    pub fn capacity_at(&self, model: Model, step: usize) -> Option<f64> {
        self.code_at(model, step).capacity
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
            init: Init::Paper,
            engine: Engine::Host,
            plateau: None,
            knobs: with_legacy_warmup(model.spec().default_knobs()),
        }
    }

    /// This configuration with the model's knob `key` set to `value` (checked by
    /// [`NeuralConfig::check`]).
    pub fn with_knob(mut self, key: &str, value: impl Into<serde_json::Value>) -> Self {
        self.knobs.insert(key.to_string(), value.into());
        self
    }

    /// Check every value for `model`, as a learner's `who` at fit time.
    pub fn validate(&self, model: Model, who: &str) -> Result<(), ReprError> {
        self.check(model)
            .map_err(|e| ReprError::InvalidInput(format!("{who}: {e}")))
    }

    /// Check every value for `model`; the error names the key.
    pub fn check(&self, model: Model) -> Result<(), ParamError> {
        if self.batch == 0 {
            return Err(ParamError::at("batch", "must be at least 1"));
        }
        if self.hidden.contains(&0) {
            return Err(ParamError::at(
                "hidden",
                format!("sizes must be at least 1, got {:?}", self.hidden),
            ));
        }
        if let Err(e) = crate::limits::check_hidden(self.hidden) {
            return Err(ParamError::at(
                "hidden",
                format!("{:?} {}", self.hidden, e.needs()),
            ));
        }
        if !(self.lr.is_finite() && self.lr > 0.0) {
            return Err(ParamError::at(
                "lr",
                format!("must be positive and finite, got {}", self.lr),
            ));
        }
        if self.log_every == 0 {
            return Err(ParamError::at("log_every", "must be at least 1"));
        }
        if let Some(rule) = self.plateau {
            if rule.chunk == 0 {
                return Err(ParamError::at("plateau.chunk", "must be at least 1"));
            }
            if rule.cap < self.iterations {
                return Err(ParamError::at(
                    "plateau.cap",
                    format!(
                        "must be at least the iterations ({}), got {}",
                        self.iterations, rule.cap
                    ),
                ));
            }
            if self.iterations == 0 {
                return Err(ParamError::at(
                    "plateau",
                    "an untrained twin (iterations = 0) has no plateau rule",
                ));
            }
        }
        let spec = model.spec();
        for (key, value) in &self.knobs {
            if spec.own_knobs().contains(&key.as_str()) {
                spec.knob_value(key, value)
                    .map_err(|e| ParamError::at(key, e))?;
            } else if !(key == LEGACY_WARMUP && value.as_u64() == Some(0)) {
                return Err(unknown_knob(model, key));
            }
        }
        Ok(())
    }
}

/// The error of a key that is neither shared by the dense networks nor one of `model`'s knobs:
/// it names the models that have it, if any.
pub fn unknown_knob(model: Model, key: &str) -> ParamError {
    let owners: Vec<&str> = Model::ALL
        .iter()
        .filter(|m| m.spec().own_knobs().contains(&key))
        .map(|m| m.name())
        .collect();
    let why = if owners.is_empty() {
        let own = model.spec().own_knobs();
        format!(
            "not a key of [learners.{}] (its own keys besides the shared ones: {})",
            model.name(),
            if own.is_empty() {
                "none".to_string()
            } else {
                own.join(", ")
            }
        )
    } else {
        format!("only the {} has this key", owners.join(" and the "))
    };
    ParamError::at(key, why)
}

/// `knobs` with `warmup` = 0 added where the model has none ([`LEGACY_WARMUP`]).
pub fn with_legacy_warmup(mut knobs: Knobs) -> Knobs {
    knobs
        .entry(LEGACY_WARMUP)
        .or_insert(serde_json::Value::from(0u64));
    knobs
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
