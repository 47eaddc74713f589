//! The paper's dense VAE (`DenseVAE`; docs/original-code.md section 5, "VAE"): the AE's trunk with
//! linear heads mu and logvar, `z = mu + eps * exp(logvar / 2)`, loss = batch mean of
//! (pixel-summed Bernoulli cross-entropy + analytic KL(N(mu, sigma^2) || N(0, I))), beta = 1,
//! no warm-up, TF Adam (lr 1e-3), 100,000 iterations. Encoding = mu; prior = N(0, I).
//!
//! Variants (the only difference; initial weights, batches and everything else are the same
//! for the same stream):
//! - **faithful**: `eps` has shape `[d]` and is **shared by the whole batch**, as the
//!   original's `tf.random_normal([emb_size])`: one draw of `d` normals per iteration.
//! - **corrected**: one `eps` per sample, `[batch, d]`: `batch * d` normals per iteration
//!   (row-major), the standard reparameterisation.

use burn::tensor::Tensor;

use super::host_ops::exp;
use super::nets::{DenseNet, bce_with_logits_sum, kl_std_normal};
use super::neural_model::{
    Latent, LatentInput, NeuralModel, Optimiser, StepInput, Variant, normals, tensor2,
};
use crate::seed::Stream;

/// The reparameterisation noise of one iteration: `[1, d]` (faithful: shared by the batch,
/// broadcast) or `[batch, d]` (corrected).
pub fn eps(
    variant: Variant,
    batch: usize,
    d: usize,
    rng: &mut Stream,
    device: &burn::tensor::Device,
) -> Tensor<2> {
    let rows = match variant {
        Variant::Faithful => 1,
        Variant::Corrected => batch,
    };
    tensor2(normals(rng, rows * d), rows, d, device)
}

/// The reparameterised code of the heads `[B, P]`: `(z, mu, logvar)` (draws the noise of
/// `variant`).
pub fn code(
    heads: Tensor<2>,
    input: &LatentInput<'_>,
    variant: Variant,
    rng: &mut Stream,
) -> (Tensor<2>, Tensor<2>, Tensor<2>) {
    let d = input.latents;
    let mu = heads.clone().narrow(1, 0, d);
    let logvar = heads.narrow(1, d, d);
    let e = eps(variant, input.batch, d, rng, input.device);
    let z = mu.clone() + e.mul(exp(logvar.clone().mul_scalar(0.5)));
    (z, mu, logvar)
}

/// The training loss of one mini-batch: `mean_b (sum_pixels BCE + KL)`.
pub fn loss(net: &DenseNet, input: StepInput<'_>, rng: &mut Stream) -> Tensor<1> {
    let variant = input.latent.code.variant;
    let (z, mu, logvar) = code(net.heads(input.x.clone()), &input.latent, variant, rng);
    let rec = bce_with_logits_sum(net.decode(z), input.x);
    (rec + kl_std_normal(mu, logvar)).mean()
}

/// The host engine's middle (same noise draws as [`loss`]): `z = mu + eps exp(logvar / 2)`,
/// loss = the batch-mean reconstruction + the batch-mean KL.
pub fn latent(heads: Tensor<2>, input: &LatentInput<'_>, rng: &mut Stream) -> Latent {
    let (z, mu, logvar) = code(heads, input, input.code.variant, rng);
    Latent {
        z,
        extra: Some(kl_std_normal(mu, logvar).mean()),
        rec_scale: 1.0,
    }
}

/// Encoding from the head outputs: mu.
pub fn encoding(head: &[f32], d: usize, out: &mut [f64]) {
    for (o, &h) in out.iter_mut().zip(&head[..d]) {
        *o = f64::from(h);
    }
}

/// The VAE as a [`NeuralModel`]: TF Adam, prior N(0, I), 100,000 iterations in the paper.
pub struct Vae;

impl NeuralModel for Vae {
    fn name(&self) -> &'static str {
        "vae"
    }
    fn head_blocks(&self, latents: usize) -> Vec<usize> {
        vec![latents, latents]
    }
    fn paper_iterations(&self) -> usize {
        100_000
    }
    fn optimiser(&self) -> Optimiser {
        Optimiser::Adam
    }
    fn has_prior(&self) -> bool {
        true
    }
    fn loss(&self, net: &DenseNet, input: StepInput<'_>, rng: &mut Stream) -> Tensor<1> {
        loss(net, input, rng)
    }
    fn latent(&self, heads: Tensor<2>, input: &LatentInput<'_>, rng: &mut Stream) -> Latent {
        latent(heads, input, rng)
    }
    fn mean_code(&self, head: &[f32], d: usize, out: &mut [f64]) {
        encoding(head, d, out)
    }
}
