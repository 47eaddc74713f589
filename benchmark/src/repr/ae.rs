//! The paper's dense auto-encoder (`DenseAE`; PAPER-NOTES.md section 5, "AE"):
//! `dim -> H1 ReLU -> H2 ReLU -> d sigmoid` (latents in (0, 1)), decoder
//! `d -> H2 ReLU -> H1 ReLU -> dim` logits, loss = batch mean of the pixel-summed Bernoulli
//! cross-entropy, TF Adagrad (lr 1e-3, initial accumulator 0.1), 200,000 iterations.
//! Encoding = the sigmoid latent.
//!
//! The original AE has no documented defect: [`Variant::Faithful`](super::neural::Variant) and
//! `Corrected` train and encode identically (same stream, same weights, same latents).

use std::sync::Arc;

use burn::tensor::Tensor;
use burn::tensor::activation::sigmoid;

use super::nets::{DenseNet, bce_with_logits_sum};
use super::neural::{
    self, Model, NeuralConfig, NeuralEncoder, ProgressFn, StepInput, TrainProgress,
};
use super::{Encoder, ImageSet, Latents, ReprError, RepresentationLearner};
use crate::seed::Stream;

/// The AE learner (`ae`).
#[derive(Clone)]
pub struct Ae {
    pub config: NeuralConfig,
    progress: Option<ProgressFn>,
}

impl Ae {
    /// With a configuration.
    pub fn new(config: NeuralConfig) -> Self {
        Ae {
            config,
            progress: None,
        }
    }

    /// The paper's configuration.
    pub fn paper() -> Self {
        Ae::new(NeuralConfig::paper(Model::Ae))
    }

    /// Report every training iteration to `f`.
    pub fn with_progress(mut self, f: Arc<dyn Fn(TrainProgress) + Send + Sync>) -> Self {
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
        neural::fit(
            Model::Ae,
            &self.config,
            images,
            latents,
            rng,
            self.progress.as_ref(),
        )
    }
}

impl std::fmt::Debug for Ae {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ae").field("config", &self.config).finish()
    }
}

impl RepresentationLearner for Ae {
    fn name(&self) -> &str {
        "ae"
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
}

/// The training loss of one mini-batch: `mean_b sum_pixels BCE(decode(sigmoid(head(x))), x)`.
pub fn loss(net: &DenseNet, input: StepInput<'_>) -> Tensor<1> {
    let z = sigmoid(net.heads(input.x.clone()));
    bce_with_logits_sum(net.decode(z), input.x).mean()
}

/// Encoding from the head outputs: the sigmoid latent.
pub fn encoding(head: &[f32], d: usize, out: &mut [f64]) {
    for (o, &h) in out.iter_mut().zip(&head[..d]) {
        *o = 1.0 / (1.0 + (-f64::from(h)).exp());
    }
}
