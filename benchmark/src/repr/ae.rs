//! The paper's dense auto-encoder (`DenseAE`; docs/original-code.md section 5, "AE"):
//! `dim -> H1 ReLU -> H2 ReLU -> d sigmoid` (latents in (0, 1)), decoder
//! `d -> H2 ReLU -> H1 ReLU -> dim` logits, loss = batch mean of the pixel-summed Bernoulli
//! cross-entropy, TF Adagrad (lr 1e-3, initial accumulator 0.1), 200,000 iterations.
//! Encoding = the sigmoid latent.
//!
//! The original AE has no documented defect: [`Variant::Faithful`](super::neural_model::Variant) and
//! `Corrected` train and encode identically (same stream, same weights, same latents).

use burn::tensor::Tensor;

use super::host_ops::sigmoid;
use super::nets::{DenseNet, bce_with_logits_sum};
use super::neural_model::{Latent, LatentInput, NeuralModel, Optimiser, StepInput};
use crate::seed::Stream;

/// The training loss of one mini-batch: `mean_b sum_pixels BCE(decode(sigmoid(head(x))), x)`.
pub fn loss(net: &DenseNet, input: StepInput<'_>) -> Tensor<1> {
    let z = sigmoid(net.heads(input.x.clone()));
    bce_with_logits_sum(net.decode(z), input.x).mean()
}

/// The host engine's middle: `z = sigmoid(heads)`, loss = the batch-mean reconstruction.
pub fn latent(heads: Tensor<2>, input: &LatentInput<'_>) -> Latent {
    Latent {
        z: sigmoid(heads.narrow(1, 0, input.latents)),
        extra: None,
        rec_scale: 1.0,
    }
}

/// Encoding from the head outputs: the sigmoid latent.
pub fn encoding(head: &[f32], d: usize, out: &mut [f64]) {
    for (o, &h) in out.iter_mut().zip(&head[..d]) {
        *o = 1.0 / (1.0 + libm::exp(-f64::from(h)));
    }
}

/// The AE as a [`NeuralModel`]: TF Adagrad, no prior, 200,000 iterations in the paper.
pub struct Ae;

impl NeuralModel for Ae {
    fn name(&self) -> &'static str {
        "ae"
    }
    fn head_blocks(&self, latents: usize) -> Vec<usize> {
        vec![latents]
    }
    fn paper_iterations(&self) -> usize {
        200_000
    }
    fn optimiser(&self) -> Optimiser {
        Optimiser::Adagrad
    }
    fn has_prior(&self) -> bool {
        false
    }
    fn loss(&self, net: &DenseNet, input: StepInput<'_>, _rng: &mut Stream) -> Tensor<1> {
        loss(net, input)
    }
    fn latent(&self, heads: Tensor<2>, input: &LatentInput<'_>, _rng: &mut Stream) -> Latent {
        latent(heads, input)
    }
    fn mean_code(&self, head: &[f32], d: usize, out: &mut [f64]) {
        encoding(head, d, out)
    }
}
