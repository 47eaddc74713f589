//! The model-specific part of the dense neural learners (docs/original-code.md section 5): one
//! [`NeuralModel`] trait that the AE (`ae.rs`), the VAE (`vae.rs`), the RFVAE (`rfvae.rs`) and
//! the β-VAE (`bvae.rs`) implement, with the types their code shares. `neural.rs` is the generic part (training loop,
//! encoder, cache keys) and reaches a model only through [`super::neural::Model::spec`]; the
//! model files depend on this module and on `nets.rs`, never on `neural.rs`.

use crate::seed::standard_normal;
use burn::tensor::{Device, Tensor, TensorData};
use serde::{Deserialize, Serialize};

use super::nets::DenseNet;
use crate::seed::Stream;

/// The original optimiser of a model (both engines).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Optimiser {
    /// TF Adagrad (the AE).
    Adagrad,
    /// TF Adam (the VAE and RFVAE).
    Adam,
}

/// What distinguishes one dense neural learner from another: its encoder's head, its latent
/// code and loss, its encoding of an image, its optimiser and the paper's budget.
pub trait NeuralModel: Sync {
    /// `ae`, `vae`, `rfvae`.
    fn name(&self) -> &'static str;
    /// The widths of the encoder's head blocks for `latents` dimensions.
    fn head_blocks(&self, latents: usize) -> Vec<usize>;
    /// The paper's training length (the original's `fit`).
    fn paper_iterations(&self) -> usize;
    /// The paper's KL warm-up (0: the model has none).
    fn paper_warmup(&self) -> usize {
        0
    }
    /// The model's own knobs: the keys of `[learners.NAME]` beyond those every dense network
    /// shares ([`super::neural_config::NeuralConfig`]), e.g. the RFVAE's `warmup`, the β-VAE's
    /// `beta` and `capacity`. None by default.
    fn own_knobs(&self) -> &'static [&'static str] {
        &[]
    }
    /// The values of the knobs that a table does not set (the paper's): every own knob with a
    /// default, none of the others.
    fn default_knobs(&self) -> Knobs {
        Knobs::new()
    }
    /// Check the value of one of [`NeuralModel::own_knobs`] and return it as recorded (e.g. an
    /// integer `beta = 4` as the float 4.0); the message says what is wrong.
    fn knob_value(
        &self,
        key: &str,
        value: &serde_json::Value,
    ) -> Result<serde_json::Value, String> {
        let _ = value;
        Err(format!("{} has no knob '{key}'", self.name()))
    }
    /// The settings of the KL term at 0-based iteration `step` of a training of `iterations`,
    /// from the resolved knobs: a KL weighed by 1, no warm-up and no capacity unless the model
    /// says otherwise.
    fn code_settings(
        &self,
        knobs: &Knobs,
        step: usize,
        iterations: usize,
        variant: Variant,
    ) -> CodeSettings {
        let _ = (knobs, step, iterations);
        CodeSettings {
            warmup: 0,
            kl_delay: 0,
            delay_factor: INITIAL_WARMUP_FACTOR,
            beta: 1.0,
            capacity: None,
            tc: None,
            variant,
        }
    }
    /// The original's optimiser.
    fn optimiser(&self) -> Optimiser;
    /// Whether goals may be drawn from the prior N(0, I) (a VAE's).
    fn has_prior(&self) -> bool;
    /// The loss of one training iteration (burn engine).
    fn loss(&self, net: &DenseNet, input: StepInput<'_>, rng: &mut Stream) -> Tensor<1>;
    /// The middle of one iteration from the head outputs (host engine).
    fn latent(&self, heads: Tensor<2>, input: &LatentInput<'_>, rng: &mut Stream) -> Latent;
    /// Whether encoding an image draws random numbers (`rng` of [`NeuralModel::encoding`]).
    fn is_stochastic(&self, _variant: Variant) -> bool {
        false
    }
    /// The noise-free code of one image from its head outputs (AE: the sigmoid latent; VAE: mu;
    /// RFVAE: the flows applied to mu): the encoding of every model that is not stochastic, and
    /// what the decoder reconstructs from (the evidence of training).
    fn mean_code(&self, head: &[f32], d: usize, out: &mut [f64]);
    /// The goal-space latents of one image from its head outputs; [`NeuralModel::mean_code`]
    /// unless the model is stochastic in `variant`.
    fn encoding(
        &self,
        head: &[f32],
        d: usize,
        _variant: Variant,
        _rng: &mut Stream,
        out: &mut [f64],
    ) {
        self.mean_code(head, d, out);
    }
    /// The training latent of one image of a model that is stochastic in its variant (the
    /// faithful RFVAE's z0 sample, what the original fitted its KDE on); the others' training
    /// latents are their encodings, and this is not called for them.
    fn training_sample(&self, head: &[f32], d: usize, _rng: &mut Stream, out: &mut [f64]) {
        self.mean_code(head, d, out);
    }
}

/// A dense network's own training knobs by name ([`NeuralModel::own_knobs`]), as recorded in its
/// configuration (a sorted JSON map). The model declares, checks and reads them, so a knob of
/// one model is an edit of that model's file.
pub type Knobs = serde_json::Map<String, serde_json::Value>;

/// A knob's value as a count: a non-negative integer (or a float with no fractional part).
pub fn knob_count(value: &serde_json::Value) -> Result<usize, String> {
    value
        .as_u64()
        .or_else(|| {
            value
                .as_f64()
                .filter(|f| f.fract() == 0.0 && *f >= 0.0 && *f < 1e15)
                .map(|f| f as u64)
        })
        .map(|v| v as usize)
        .ok_or_else(|| format!("must be a non-negative integer, got {value}"))
}

/// A knob's value as a number.
pub fn knob_number(value: &serde_json::Value) -> Result<f64, String> {
    value
        .as_f64()
        .ok_or_else(|| format!("must be a number, got {value}"))
}

/// Paper-faithful or corrected behaviour where the original code has a defect.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Variant {
    /// What the original code did, defects included (see `vae.rs`, `rfvae.rs`).
    #[default]
    Faithful,
    /// The defects fixed. The AE has none: both variants are identical.
    Corrected,
}

impl Variant {
    /// Both.
    pub const ALL: [Variant; 2] = [Variant::Faithful, Variant::Corrected];

    /// `faithful` / `corrected`.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Faithful => "faithful",
            Variant::Corrected => "corrected",
        }
    }
}

/// What one training iteration's loss needs besides the network (burn engine): the batch and
/// what the model's code needs.
pub struct StepInput<'a> {
    pub x: Tensor<2>,
    pub latent: LatentInput<'a>,
}

/// The follow-up code's initial warm-up factor, the 0.01 of `c = min(1, 0.01 + t / T_a)`
/// (the β-VAE's `warmup_factor`).
pub const INITIAL_WARMUP_FACTOR: f64 = 0.01;

/// The settings of a model's KL term at one iteration, from its training configuration (the
/// dense networks' [`super::neural_config::NeuralConfig::code_at`], the convolutional ones'
/// [`super::conv_train::ConvConfig::code_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CodeSettings {
    /// The warm-up length (RFVAE; the follow-up's `c` ramp of the β-VAE); 0: none.
    pub warmup: usize,
    /// The iterations before the β-VAE's warm-up ramp starts (its factor stays at 0.01 until
    /// then); 0 for every other model and for the follow-up's own form.
    pub kl_delay: usize,
    /// The factor of the KL term during the delay (the follow-up's initial warm-up factor,
    /// [`INITIAL_WARMUP_FACTOR`], unless the configuration sets another).
    pub delay_factor: f64,
    /// The weight of the KL term (1 for every model but the β-VAE).
    pub beta: f64,
    /// The KL target C at this iteration (None: plain KL term).
    pub capacity: Option<f64>,
    /// The weight of an added total-correlation term (the convolutional β-VAE's `tc`,
    /// [`super::total_correlation`]; None: none, every other model).
    pub tc: Option<f64>,
    pub variant: Variant,
}

/// What a model's latent code needs besides the head outputs (both engines).
pub struct LatentInput<'a> {
    pub batch: usize,
    pub latents: usize,
    /// 0-based iteration.
    pub step: usize,
    /// The settings of the KL term at this iteration, from the training configuration.
    pub code: CodeSettings,
    pub device: &'a Device,
}

/// A model's middle, from the head outputs (host engine): the latent code fed to the decoder,
/// and the loss as `rec_scale * mean_b(sum_pixels BCE_b) + extra` (`extra`: the KL and flow
/// terms, None for the AE).
pub struct Latent {
    /// `[B, d]`.
    pub z: Tensor<2>,
    pub extra: Option<Tensor<1>>,
    pub rec_scale: f64,
}

/// `n` standard normals from `rng`.
pub fn normals(rng: &mut Stream, n: usize) -> Vec<f32> {
    (0..n).map(|_| standard_normal(rng) as f32).collect()
}

/// Helper for the model files: a `[rows, cols]` tensor from host values.
pub fn tensor2(values: Vec<f32>, rows: usize, cols: usize, device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(values, [rows, cols]), device)
}
