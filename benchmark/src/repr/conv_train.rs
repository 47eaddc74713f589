//! One training iteration of the follow-up's convolutional VAE / β-VAE ([`super::conv_net`]) on
//! the host engine: forward, loss, backward and the optimiser step, on the deterministic kernels.
//!
//! - **Loss**, as the authors' `loss_function`: the Bernoulli cross-entropy of the pixel logits,
//!   summed over the pixels and channels and averaged over the batch, plus the model's KL term.
//!   For the β-VAE with capacity annealing that is `c β |mean_b KL_b − C(t)|`, with `C(t)` rising
//!   linearly to `capacity` and the warm-up factor `c = min(1, 0.01 + t / warmup)` (`bvae.rs`),
//!   both after an optional VAE phase of `kl_delay` iterations (the follow-up's own form has
//!   none; [`ConvConfig::kl_delay`]).
//! - **The middle** (heads -> code, KL) is the model's own ([`super::neural_model::NeuralModel::latent`]),
//!   on burn's autodiff, as in the dense host engine: one implementation of each model's code.
//! - **Optimiser**: `torch.optim.Adam` as the authors ran it (no clipping, PyTorch's placement of
//!   ε; [`TfAdam::torch`]), in place on the host weights.
//!
//! Determinism: the convolutions and products are one FMA chain per output in a fixed order
//! ([`ugl_kernels::Conv2d`]); the bias sums and the optimiser run element by element or in a fixed
//! order. The weights after `n` iterations depend on the stream alone, not on the thread count
//! or the SIMD path (tested).

use burn::tensor::Device;
use serde::{Deserialize, Serialize};

use super::ReprError;
use super::conv_net::{CONV_LAYERS, ConvInit, ConvNet, DecoderActivations, EncoderActivations};
use super::host_train::{
    HostOptimizer, Middle, bce_and_grad, dense_backward, relu_backward, sized,
};
use super::nets::TfAdam;
use super::neural_config::Model;
use super::neural_model::{CodeSettings, Variant};
use super::params::ParamError;
use super::target_blur;
use crate::seed::Stream;

/// The training recipe of a convolutional network (`[learners.conv-vae]`,
/// `[learners.conv-bvae]`). The authors' values of β, C, T_C, T_a, the learning rate, the
/// iterations and the batch are not in their code (`docs/armballs.md`); the defaults
/// ([`ConvConfig::followup_vae`], [`ConvConfig::followup_bvae`]) are ours.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvConfig {
    /// Channels of every hidden convolution (the authors': 32).
    pub filters: usize,
    /// Width of the dense layers (the authors': 256).
    pub hidden: usize,
    /// Optimiser steps.
    pub iterations: usize,
    /// Pictures per mini-batch.
    pub batch: usize,
    /// Adam's learning rate.
    pub lr: f64,
    /// Record the mini-batch loss every this many iterations.
    pub log_every: usize,
    /// The weight β of the KL term (1: the VAE).
    pub beta: f64,
    /// Capacity annealing: the KL target's final value C, in nats (None: the plain KL term).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capacity: Option<f64>,
    /// The iterations over which the target rises linearly from 0 to C (T_C; None: the whole
    /// training after the KL delay).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capacity_iterations: Option<usize>,
    /// The warm-up factor's length T_a: the KL term is multiplied by
    /// `min(1, 0.01 + max(0, t − T_v) / T_a)` (0: no warm-up).
    pub warmup: usize,
    /// The KL delay T_v: a VAE phase of T_v iterations before the authors' schedule, which then
    /// runs shifted by T_v. During it the warm-up factor stays at 0.01
    /// ([`super::bvae::warmup_factor`]) and the KL target at 0 ([`ConvConfig::capacity_at`]), so
    /// the loss is a VAE's with the KL weighted by 0.01 β (β = 100: the VAE's loss). 0 (the
    /// default, left out of the configuration's identity): the follow-up's own form.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub kl_delay: usize,
    /// The warm-up factor during the KL delay, so that the phase's KL weight is `delay_factor β`
    /// whatever β presses after it (None: the authors' initial 0.01,
    /// [`super::neural_model::INITIAL_WARMUP_FACTOR`]; left out of the configuration's
    /// identity). Ours: the phase's weight set apart from β (`docs/neural.md`, "Fifth round").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay_factor: Option<f64>,
    /// A later KL weight: β moves linearly to `beta_final` between the iterations `beta_from`
    /// and `beta_until` (a jump at `beta_from` when they are equal), and stays there
    /// ([`ConvConfig::beta_at`]).
    /// Ours: a β that lets the network leave the plateau and learn both objects, then one that
    /// holds the KL at the target (`docs/neural.md`, "Eighth round"). None (the default, left
    /// out of the configuration's identity): β throughout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta_final: Option<f64>,
    /// The iteration at which β starts moving to `beta_final` (with `beta_final` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta_from: Option<usize>,
    /// The iteration at which β reaches `beta_final` (default: `beta_from`, a jump).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta_until: Option<usize>,
    /// A total-correlation weight λ: the loss gains `λ TC`, the batch's total correlation
    /// (β-TCVAE, Chen et al. 2018; [`super::total_correlation`]), under the KL term's warm-up
    /// factor. Ours: it presses the dependence between latents alone, which the β-VAE's KL term
    /// leaves free inside its capacity (`docs/neural.md`, "Tenth round"). None (the default,
    /// left out of the configuration's identity): no such term.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tc: Option<f64>,
    /// A blurred reconstruction target: the loss compares the decoder's picture with the
    /// picture blurred by a Gaussian of σ pixels, σ falling linearly from `blur` at iteration
    /// 0 to 0 at `blur_until` ([`super::target_blur`]); the encoder sees the picture itself.
    /// Ours: the reconstruction then orders places farther apart than an object's diameter,
    /// which sharp pictures leave equal (`docs/neural.md`, "Eleventh round"). None (the
    /// default, left out of the configuration's identity): the picture itself throughout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blur: Option<f64>,
    /// The iteration at which the blur's σ reaches 0 (with `blur` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blur_until: Option<usize>,
    /// Train with subnormal numbers flushed to zero (x86-64's FTZ and DAZ,
    /// [`ugl_kernels::flushing_pool`]): the same bits on every x86-64 CPU and path, and no
    /// microcode assists on Intel CPUs, where a trained VAE's tiny gradients made each iteration
    /// 6 times slower. `false`: IEEE subnormals, as PyTorch's CPU default (other bits).
    pub flush_subnormals: bool,
    /// Which PyTorch's default initialisation draws the weights ([`ConvInit`]; the authors'
    /// 0.4.0 by default). A configuration recorded before the key existed was today's PyTorch.
    #[serde(default = "init_before_the_key")]
    pub init: ConvInit,
}

/// The initialisation of a configuration recorded before `init` existed.
fn init_before_the_key() -> ConvInit {
    ConvInit::BEFORE_THE_KEY
}

impl ConvConfig {
    /// The VAE of the follow-up (β = 1, no capacity), at our default budget.
    pub fn followup_vae() -> ConvConfig {
        ConvConfig {
            filters: 32,
            hidden: 256,
            iterations: 5_000,
            batch: 64,
            lr: 1e-3,
            log_every: 50,
            beta: 1.0,
            capacity: None,
            capacity_iterations: None,
            warmup: 0,
            kl_delay: 0,
            delay_factor: None,
            beta_final: None,
            beta_from: None,
            beta_until: None,
            tc: None,
            blur: None,
            blur_until: None,
            flush_subnormals: true,
            init: ConvInit::Torch04,
        }
    }

    /// The β-VAE of the follow-up: the capacity-annealed objective (Burgess et al. 2018) with
    /// the warm-up factor, at our default budget and settings.
    pub fn followup_bvae() -> ConvConfig {
        ConvConfig {
            beta: 4.0,
            capacity: Some(12.0),
            warmup: 500,
            ..ConvConfig::followup_vae()
        }
    }

    /// The KL target at iteration `step`: `C min(1, max(0, step − T_v) / T_C)`, T_C defaulting
    /// to the iterations after the delay. With no delay (the authors' form) `C min(1, step /
    /// T_C)`.
    pub fn capacity_at(&self, step: usize) -> Option<f64> {
        let ramp = self
            .capacity_iterations
            .unwrap_or(self.iterations.saturating_sub(self.kl_delay))
            .max(1);
        let after = step.saturating_sub(self.kl_delay);
        self.capacity
            .map(|c| c * (after as f64 / ramp as f64).min(1.0))
    }

    /// The KL weight at iteration `step`: β, moving linearly to `beta_final` between
    /// `beta_from` and `beta_until` where the configuration sets them.
    pub fn beta_at(&self, step: usize) -> f64 {
        let (Some(last), Some(from)) = (self.beta_final, self.beta_from) else {
            return self.beta;
        };
        let until = self.beta_until.unwrap_or(from);
        if step < from {
            self.beta
        } else if step >= until {
            last
        } else {
            let t = (step - from) as f64 / (until - from) as f64;
            self.beta + (last - self.beta) * t
        }
    }

    /// The settings of the KL term at iteration `step` (the β-VAE's code; one `eps` per
    /// picture).
    pub fn code_at(&self, step: usize) -> CodeSettings {
        CodeSettings {
            warmup: self.warmup,
            kl_delay: self.kl_delay,
            delay_factor: self
                .delay_factor
                .unwrap_or(super::neural_model::INITIAL_WARMUP_FACTOR),
            beta: self.beta_at(step),
            capacity: self.capacity_at(step),
            tc: self.tc,
            variant: Variant::Corrected,
        }
    }

    /// The σ, in pixels, of the blur of the reconstruction target at iteration `step` (None:
    /// the picture itself).
    pub fn blur_at(&self, step: usize) -> Option<f64> {
        match (self.blur, self.blur_until) {
            (Some(s), Some(until)) => target_blur::sigma_at(s, until, step),
            _ => None,
        }
    }

    /// Validate every value; the error names the key.
    pub fn check(&self) -> Result<(), ParamError> {
        for (key, v, most) in [
            ("filters", self.filters, 512),
            ("hidden", self.hidden, 16_384),
        ] {
            if v == 0 || v > most {
                return Err(ParamError::at(
                    key,
                    format!("must be between 1 and {most}, got {v}"),
                ));
            }
        }
        if self.batch == 0 {
            return Err(ParamError::at("batch", "must be at least 1"));
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
        if self.flush_subnormals && !cfg!(target_arch = "x86_64") {
            return Err(ParamError::at(
                "flush_subnormals",
                ugl_kernels::FlushError::Unsupported(std::env::consts::ARCH).to_string(),
            ));
        }
        check_beta("beta", self.beta)?;
        if let Some(w) = self.tc {
            check_beta("tc", w)?;
        }
        match (self.blur, self.blur_until) {
            (None, None) => {}
            (None, Some(_)) => {
                return Err(ParamError::at(
                    "blur_until",
                    "ends the blur of the reconstruction target: set blur too",
                ));
            }
            (Some(_), None) => {
                return Err(ParamError::at(
                    "blur_until",
                    "must be set with blur: the iteration at which the blur reaches 0",
                ));
            }
            (Some(s), Some(until)) => {
                if !(s.is_finite() && s > 0.0 && s <= 64.0) {
                    return Err(ParamError::at(
                        "blur",
                        format!("must be a σ in pixels above 0 and at most 64, got {s}"),
                    ));
                }
                if until == 0 || until > self.iterations {
                    return Err(ParamError::at(
                        "blur_until",
                        format!(
                            "must be between 1 and the iterations ({}), got {until}",
                            self.iterations
                        ),
                    ));
                }
            }
        }
        if let Some(c) = self.capacity
            && !(c.is_finite() && (0.0..=1e4).contains(&c))
        {
            return Err(ParamError::at(
                "capacity",
                format!("must be between 0 and 1e4 nats, got {c}"),
            ));
        }
        if self.capacity.is_none() && self.capacity_iterations.is_some() {
            return Err(ParamError::at(
                "capacity_iterations",
                "sets the ramp of a capacity: set capacity too",
            ));
        }
        if self.capacity_iterations == Some(0) {
            return Err(ParamError::at("capacity_iterations", "must be at least 1"));
        }
        if self.kl_delay >= self.iterations.max(1) {
            return Err(ParamError::at(
                "kl_delay",
                format!(
                    "must be below the iterations ({}), got {}: the KL term would never get its \
                     weight",
                    self.iterations, self.kl_delay
                ),
            ));
        }
        if let Some(f) = self.delay_factor {
            if self.kl_delay == 0 {
                return Err(ParamError::at(
                    "delay_factor",
                    "sets the KL term's factor during a KL delay: set kl_delay too",
                ));
            }
            if !(f.is_finite() && (0.0..=1.0).contains(&f)) {
                return Err(ParamError::at(
                    "delay_factor",
                    format!("must be between 0 and 1, got {f}"),
                ));
            }
        }
        match (self.beta_final, self.beta_from) {
            (None, None) if self.beta_until.is_some() => {
                return Err(ParamError::at(
                    "beta_until",
                    "ends the move to beta_final: set beta_final and beta_from too",
                ));
            }
            (None, None) => {}
            (Some(_), None) => {
                return Err(ParamError::at(
                    "beta_from",
                    "must be set with beta_final: the iteration at which β starts moving to it",
                ));
            }
            (None, Some(_)) => {
                return Err(ParamError::at(
                    "beta_final",
                    "must be set with beta_from: the KL weight β moves to",
                ));
            }
            (Some(last), Some(from)) => {
                check_beta("beta_final", last)?;
                let until = self.beta_until.unwrap_or(from);
                if until < from {
                    return Err(ParamError::at(
                        "beta_until",
                        format!("must not be below beta_from ({from}), got {until}"),
                    ));
                }
                if until >= self.iterations.max(1) {
                    return Err(ParamError::at(
                        if self.beta_until.is_some() {
                            "beta_until"
                        } else {
                            "beta_from"
                        },
                        format!(
                            "must be below the iterations ({}), got {until}: β would never reach \
                             beta_final",
                            self.iterations
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// A KL weight (`beta`, `beta_final`, `tc`): positive, finite and at most 1e6.
fn check_beta(key: &str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v > 0.0 && v <= 1e6 {
        Ok(())
    } else {
        Err(ParamError::at(
            key,
            format!("must be positive and at most 1e6, got {v}"),
        ))
    }
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

/// Index of the first gradient buffer of each layer group in [`ConvNet::params`] order.
const ENC_FC: usize = 2 * CONV_LAYERS;
const HEAD: usize = ENC_FC + 4;
const DEC_FC: usize = HEAD + 2;
const DEC_CONV: usize = DEC_FC + 4;

/// Buffers of one iteration, allocated once.
#[derive(Default)]
struct Workspace {
    enc: EncoderActivations,
    dec: DecoderActivations,
    z: Vec<f32>,
    /// The gradient flowing back, and the next one (swapped layer by layer).
    grad: Vec<f32>,
    grad_next: Vec<f32>,
    dz: Vec<f32>,
    /// The blurred reconstruction target, when the recipe blurs it.
    target: Vec<f32>,
    /// Gradients of the parameters, [`ConvNet::params`] order.
    grads: Vec<Vec<f32>>,
}

/// A training of the convolutional VAE in progress: weights, optimiser state, workspace.
pub struct ConvTrainer {
    pub net: ConvNet,
    pub opt: HostOptimizer,
    ws: Workspace,
    device: Device,
}

impl ConvTrainer {
    /// A fresh training of `net` with the authors' optimiser.
    pub fn new(net: ConvNet) -> ConvTrainer {
        let sizes: Vec<usize> = net.params().iter().map(|p| p.len()).collect();
        let opt = HostOptimizer::adam(TfAdam::torch(), &sizes);
        ConvTrainer {
            net,
            opt,
            ws: Workspace {
                grads: sizes.iter().map(|&n| vec![0.0; n]).collect(),
                ..Workspace::default()
            },
            device: Device::flex().autodiff(),
        }
    }

    /// One iteration on the batch `x` (`rows` pictures, `NCHW`): forward, loss, backward and the
    /// optimiser step. `rng` gives the model's noise. Returns the mini-batch loss (not yet
    /// checked for finiteness).
    pub fn step(
        &mut self,
        cfg: &ConvConfig,
        x: &[f32],
        rows: usize,
        step: usize,
        rng: &mut Stream,
    ) -> Result<f64, ReprError> {
        let loss = self.forward_backward(cfg, x, rows, step, rng)?;
        self.opt
            .step_all(cfg.lr, self.net.params_mut(), &self.ws.grads);
        Ok(loss)
    }

    /// The gradients of the last [`ConvTrainer::forward_backward`], [`ConvNet::params`] order.
    pub fn gradients(&self) -> &[Vec<f32>] {
        &self.ws.grads
    }

    /// Forward pass, loss and gradients of one batch (kept in the workspace), without the
    /// optimiser step. Returns the mini-batch loss.
    pub fn forward_backward(
        &mut self,
        cfg: &ConvConfig,
        x: &[f32],
        rows: usize,
        step: usize,
        rng: &mut Stream,
    ) -> Result<f64, ReprError> {
        let net = &self.net;
        let arch = net.arch;
        if x.len() != rows * arch.image_len() {
            return Err(ReprError::InvalidInput(format!(
                "a batch of {rows} pictures of {} values needs {} values, got {}",
                arch.image_len(),
                rows * arch.image_len(),
                x.len()
            )));
        }
        let (d, n) = (arch.latents, rows);
        let ws = &mut self.ws;
        let mut grads = std::mem::take(&mut ws.grads);

        net.encoder_forward(x, n, &mut ws.enc);

        // The model's middle on burn's autodiff.
        let middle = Middle::forward(
            Model::Bvae,
            &cfg.code_at(step),
            &ws.enc.heads,
            n,
            d,
            step,
            &self.device,
            rng,
        )?;
        ws.z.clone_from(&middle.z);

        net.decoder_forward(&ws.z, n, &mut ws.dec);
        let target: &[f32] = match cfg.blur_at(step) {
            Some(sigma) => {
                target_blur::blur(x, n, arch.channels, arch.side, sigma, &mut ws.target);
                &ws.target
            }
            None => x,
        };
        let scale = middle.rec_scale() / n as f64;
        let per_image = bce_and_grad(
            &ws.dec.logits,
            target,
            arch.image_len(),
            scale as f32,
            sized(&mut ws.grad, ws.dec.logits.len()),
        );
        let rec: f64 = per_image.iter().sum();

        // Decoder backward: the transposed convolutions, last first; `ws.grad` holds the
        // gradient of the current layer's output.
        for (i, l) in net.dec_conv.iter().enumerate().rev() {
            let input: &[f32] = if i == 0 {
                &ws.dec.g2
            } else {
                &ws.dec.deconv[i - 1]
            };
            let [gw, gb] = &mut grads[DEC_CONV + 2 * i..DEC_CONV + 2 * i + 2] else {
                unreachable!("weight and bias")
            };
            l.shape.backward_weight(n, input, &ws.grad, gw, Some(gb));
            let dx = sized(&mut ws.grad_next, input.len());
            l.shape.backward_input(n, &ws.grad, &l.w, dx);
            relu_backward(dx, input);
            std::mem::swap(&mut ws.grad, &mut ws.grad_next);
        }
        // The dense decoder layers: `ws.grad` is the gradient of g2.
        {
            let [gw, gb, gw2, gb2] = &mut grads[DEC_FC..DEC_FC + 4] else {
                unreachable!("two layers")
            };
            let dg1 = sized(&mut ws.grad_next, n * arch.hidden);
            dense_backward(&net.dec_fc[1], &ws.dec.g1, &ws.grad, n, gw2, gb2, Some(dg1));
            relu_backward(dg1, &ws.dec.g1);
            let dz = sized(&mut ws.dz, n * d);
            dense_backward(&net.dec_fc[0], &ws.z, dg1, n, gw, gb, Some(dz));
        }

        let (dheads, extra_value) = middle.backward(&ws.dz, &self.device)?;

        // Encoder backward: the dense layers, then the convolutions, last first.
        {
            let [gw1, gb1, gw2, gb2, gwh, gbh] = &mut grads[ENC_FC..ENC_FC + 6] else {
                unreachable!("three layers")
            };
            let dh2 = sized(&mut ws.grad, n * arch.hidden);
            dense_backward(&net.head, &ws.enc.h2, &dheads, n, gwh, gbh, Some(dh2));
            relu_backward(dh2, &ws.enc.h2);
            let dh1 = sized(&mut ws.grad_next, n * arch.hidden);
            dense_backward(&net.enc_fc[1], &ws.enc.h1, dh2, n, gw2, gb2, Some(dh1));
            relu_backward(dh1, &ws.enc.h1);
            let top = &ws.enc.conv[CONV_LAYERS - 1];
            let dtop = sized(&mut ws.grad, top.len());
            dense_backward(&net.enc_fc[0], top, dh1, n, gw1, gb1, Some(dtop));
            relu_backward(dtop, top);
        }
        for (i, l) in net.enc_conv.iter().enumerate().rev() {
            let input: &[f32] = if i == 0 { x } else { &ws.enc.conv[i - 1] };
            let [gw, gb] = &mut grads[2 * i..2 * i + 2] else {
                unreachable!("weight and bias")
            };
            l.shape.backward_weight(n, input, &ws.grad, gw, Some(gb));
            if i > 0 {
                let dx = sized(&mut ws.grad_next, input.len());
                l.shape.backward_input(n, &ws.grad, &l.w, dx);
                relu_backward(dx, input);
                std::mem::swap(&mut ws.grad, &mut ws.grad_next);
            }
        }
        ws.grads = grads;
        Ok(scale * rec + extra_value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repr::conv_net::ConvArch;
    use crate::repr::nets::bce_with_logits_sum;
    use crate::repr::neural_model::LatentInput;
    use crate::seed::stream_named;
    use burn::tensor::activation::relu;
    use burn::tensor::module::{conv_transpose2d, conv2d};
    use burn::tensor::ops::{ConvOptions, ConvTransposeOptions};
    use burn::tensor::{Tensor, TensorData};
    use rand::RngExt;

    /// A network small enough for a test: 2 channels of 16x16, 3 filters, 5 hidden, 2 latents.
    fn small() -> ConvArch {
        ConvArch {
            channels: 2,
            side: 16,
            filters: 3,
            hidden: 5,
            latents: 2,
        }
    }

    /// Pictures with values in [0, 1], a third of them 0.
    fn pictures(arch: ConvArch, n: usize, seed: u64) -> Vec<f32> {
        let mut rng = stream_named(seed, "pictures");
        (0..n * arch.image_len())
            .map(|_| {
                let u: f32 = rng.random();
                if u < 0.33 { 0.0 } else { u }
            })
            .collect()
    }

    /// The β-VAE with capacity annealing and the warm-up, as the follow-up trains it.
    fn followup_config() -> ConvConfig {
        ConvConfig {
            iterations: 100,
            warmup: 10,
            beta: 4.0,
            capacity: Some(5.0),
            batch: 3,
            ..ConvConfig::followup_bvae()
        }
    }

    /// The same loss, written independently on burn's autodiff (its own convolutions, products
    /// and gradients): the loss and every gradient of the host engine must agree with it.
    fn burn_loss_and_grads(
        net: &ConvNet,
        cfg: &ConvConfig,
        x: &[f32],
        n: usize,
        step: usize,
        rng: &mut Stream,
    ) -> (f64, Vec<Vec<f32>>) {
        let device = Device::flex().autodiff();
        let arch = net.arch;
        let params: Vec<Tensor<1>> = net
            .params()
            .iter()
            .map(|p| {
                Tensor::<1>::from_data(TensorData::new(p.to_vec(), [p.len()]), &device)
                    .require_grad()
            })
            .collect();
        let w4 = |i: usize, dims: [usize; 4]| params[i].clone().reshape(dims);
        let w2 = |i: usize, inp: usize, out: usize| params[i].clone().reshape([inp, out]);
        let dense = |h: Tensor<2>, i: usize, inp: usize, out: usize| {
            h.matmul(w2(i, inp, out)) + params[i + 1].clone().unsqueeze_dim::<2>(0)
        };
        let k = super::super::conv_net::KERNEL;
        let mut a: Tensor<4> = Tensor::from_data(
            TensorData::new(x.to_vec(), [n, arch.channels, arch.side, arch.side]),
            &device,
        );
        for (i, l) in net.enc_conv.iter().enumerate() {
            let s = l.shape;
            let w = w4(2 * i, [s.channels_out, s.channels_in, k, k]);
            let opts = ConvOptions::new([2, 2], [1, 1], [1, 1], 1);
            a = relu(conv2d(a, w, Some(params[2 * i + 1].clone()), opts));
        }
        let (h, d, flat) = (arch.hidden, arch.latents, arch.flat());
        let h1 = relu(dense(a.reshape([n, flat]), ENC_FC, flat, h));
        let h2 = relu(dense(h1, ENC_FC + 2, h, h));
        let heads = dense(h2, HEAD, h, 2 * d);
        let input = LatentInput {
            batch: n,
            latents: d,
            step,
            code: cfg.code_at(step),
            device: &device,
        };
        let latent = Model::Bvae.spec().latent(heads, &input, rng);
        let g1 = relu(dense(latent.z, DEC_FC, d, h));
        let g2 = relu(dense(g1, DEC_FC + 2, h, flat));
        let b = arch.bottom_side();
        let mut a = g2.reshape([n, arch.filters, b, b]);
        for (i, l) in net.dec_conv.iter().enumerate() {
            let s = l.shape;
            let w = w4(DEC_CONV + 2 * i, [s.channels_in, s.channels_out, k, k]);
            let opts = ConvTransposeOptions::new([2, 2], [1, 1], [0, 0], [1, 1], 1);
            let bias = params[DEC_CONV + 2 * i + 1].clone();
            a = conv_transpose2d(a, w, Some(bias), opts);
            if i + 1 < CONV_LAYERS {
                a = relu(a);
            }
        }
        let targets =
            Tensor::<2>::from_data(TensorData::new(x.to_vec(), [n, arch.image_len()]), &device);
        let rec = bce_with_logits_sum(a.reshape([n, arch.image_len()]), targets).mean();
        let loss = rec.mul_scalar(latent.rec_scale) + latent.extra.expect("a KL term");
        let value = f64::from(loss.clone().into_scalar::<f32>());
        let graph = loss.backward();
        let grads = params
            .iter()
            .map(|p| {
                p.grad(&graph)
                    .expect("every parameter has a gradient")
                    .into_data()
                    .try_into_vec::<f32>()
                    .unwrap()
            })
            .collect();
        (value, grads)
    }

    #[test]
    fn the_host_gradients_are_burns() {
        let arch = small();
        let n = 3;
        let net = ConvNet::init(&mut stream_named(1, "conv"), arch, ConvInit::Torch04);
        let x = pictures(arch, n, 2);
        let delayed = ConvConfig {
            kl_delay: 20,
            ..followup_config()
        };
        let own_factor = ConvConfig {
            delay_factor: Some(0.3),
            ..delayed.clone()
        };
        let with_tc = ConvConfig {
            tc: Some(7.0),
            ..followup_config()
        };
        for (cfg, step) in [0, 3, 60]
            .map(|s| (followup_config(), s))
            .into_iter()
            .chain([5, 25].map(|s| (delayed.clone(), s)))
            .chain([(own_factor, 5)])
            .chain([3, 60].map(|s| (with_tc.clone(), s)))
        {
            let cfg = &cfg;
            let mut trainer = ConvTrainer::new(net.clone());
            let loss = trainer
                .forward_backward(cfg, &x, n, step, &mut stream_named(3, "noise"))
                .unwrap();
            let (want, want_grads) =
                burn_loss_and_grads(&net, cfg, &x, n, step, &mut stream_named(3, "noise"));
            assert!(
                (loss - want).abs() <= 1e-5 * (1.0 + want.abs()),
                "step {step}: loss {loss} vs burn's {want}"
            );
            for (i, (got, want)) in trainer.gradients().iter().zip(&want_grads).enumerate() {
                let scale = want.iter().fold(0.0f32, |m, v| m.max(v.abs()));
                assert!(
                    scale > 0.0,
                    "step {step}: parameter {i} has a zero gradient"
                );
                let worst = got
                    .iter()
                    .zip(want)
                    .fold(0.0f32, |m, (a, b)| m.max((a - b).abs()));
                assert!(
                    worst <= 1e-4 * scale,
                    "step {step}: parameter {i}: gradients differ by {worst} (largest {scale})"
                );
            }
        }
    }

    /// A known-bad case must fail the comparison above: the same loss without the warm-up
    /// factor has other gradients of the encoder heads.
    #[test]
    fn the_warm_up_changes_the_gradients() {
        let arch = small();
        let net = ConvNet::init(&mut stream_named(1, "conv"), arch, ConvInit::Torch04);
        let x = pictures(arch, 3, 2);
        let run = |cfg: &ConvConfig| {
            let mut t = ConvTrainer::new(net.clone());
            t.forward_backward(cfg, &x, 3, 2, &mut stream_named(3, "noise"))
                .unwrap();
            t.gradients()[HEAD].clone()
        };
        let with = run(&followup_config());
        let without = run(&ConvConfig {
            warmup: 0,
            ..followup_config()
        });
        assert_ne!(with, without);
        // And a total-correlation weight changes them too (its own gradients are checked
        // against its definition in `total_correlation.rs`).
        let with_tc = run(&ConvConfig {
            tc: Some(7.0),
            ..followup_config()
        });
        assert_ne!(with, with_tc);
    }

    /// A blurred reconstruction target changes the loss and the gradients until `blur_until`,
    /// and nothing from it on (the blur itself is tested in `target_blur.rs`).
    #[test]
    fn the_blur_changes_the_target_until_its_end() {
        let arch = small();
        let net = ConvNet::init(&mut stream_named(1, "conv"), arch, ConvInit::Torch04);
        let x = pictures(arch, 3, 2);
        let run = |cfg: &ConvConfig, step: usize| {
            let mut t = ConvTrainer::new(net.clone());
            let loss = t
                .forward_backward(cfg, &x, 3, step, &mut stream_named(3, "noise"))
                .unwrap();
            (loss, t.gradients().to_vec())
        };
        let blurred = ConvConfig {
            blur: Some(3.0),
            blur_until: Some(5),
            ..followup_config()
        };
        assert_eq!(blurred.check(), Ok(()));
        let (sharp_loss, sharp_grads) = run(&followup_config(), 2);
        let (loss, grads) = run(&blurred, 2);
        assert_ne!(loss, sharp_loss);
        assert_ne!(grads[DEC_CONV + 6], sharp_grads[DEC_CONV + 6]);
        assert_eq!(run(&blurred, 5), run(&followup_config(), 5));
    }

    /// β moves linearly to `beta_final` between `beta_from` and `beta_until` (a jump when they
    /// are equal) and the KL term's weight follows it; the keys stay out of the identity when
    /// unset, and a schedule that never reaches its value, or half of one, is refused by key.
    #[test]
    fn beta_moves_to_its_final_value_on_its_schedule() {
        let ramp = ConvConfig {
            beta_final: Some(24.0),
            beta_from: Some(40),
            beta_until: Some(60),
            ..followup_config()
        };
        assert!(ramp.check().is_ok());
        let betas: Vec<f64> = [0, 39, 40, 50, 59, 60, 99]
            .iter()
            .map(|s| ramp.beta_at(*s))
            .collect();
        assert_eq!(betas, [4.0, 4.0, 4.0, 14.0, 23.0, 24.0, 24.0]);
        assert_eq!(ramp.code_at(50).beta, 14.0);
        let jump = ConvConfig {
            beta_until: None,
            ..ramp.clone()
        };
        assert_eq!((jump.beta_at(39), jump.beta_at(40)), (4.0, 24.0));
        assert_eq!(followup_config().beta_at(99), 4.0);

        let plain = serde_json::to_value(followup_config()).unwrap();
        assert!(plain.get("beta_final").is_none() && plain.get("beta_from").is_none());
        assert_eq!(serde_json::to_value(&ramp).unwrap()["beta_final"], 24.0);

        let key = |cfg: ConvConfig| cfg.check().unwrap_err().key;
        let only = |final_: Option<f64>, from: Option<usize>, until: Option<usize>| ConvConfig {
            beta_final: final_,
            beta_from: from,
            beta_until: until,
            ..followup_config()
        };
        assert_eq!(
            key(only(Some(24.0), None, None)).as_deref(),
            Some("beta_from")
        );
        assert_eq!(
            key(only(None, Some(40), None)).as_deref(),
            Some("beta_final")
        );
        assert_eq!(
            key(only(None, None, Some(60))).as_deref(),
            Some("beta_until")
        );
        assert_eq!(
            key(only(Some(24.0), Some(40), Some(30))).as_deref(),
            Some("beta_until")
        );
        assert_eq!(
            key(only(Some(24.0), Some(100), None)).as_deref(),
            Some("beta_from")
        );
        assert_eq!(
            key(only(Some(24.0), Some(40), Some(100))).as_deref(),
            Some("beta_until")
        );
        assert_eq!(
            key(only(Some(0.0), Some(40), None)).as_deref(),
            Some("beta_final")
        );
    }

    /// The KL delay T_v holds the warm-up factor at 0.01, then the ramp starts; no delay is the
    /// follow-up's own form, and it stays out of the configuration's identity (the hashes of the
    /// networks trained before it existed hold).
    #[test]
    fn the_kl_delay_holds_the_factor_then_ramps() {
        use crate::repr::bvae::warmup_factor;
        let factor = |step: usize, kl_delay: usize, warmup: usize| {
            let cfg = ConvConfig {
                kl_delay,
                warmup,
                ..followup_config()
            };
            warmup_factor(step, &cfg.code_at(step))
        };
        assert_eq!(factor(7, 0, 0), None);
        assert_eq!(factor(0, 0, 100), Some(0.01));
        assert_eq!(factor(50, 0, 100), Some(0.51));
        assert_eq!(factor(50, 300, 100), Some(0.01));
        assert_eq!(factor(300, 300, 100), Some(0.01));
        assert_eq!(factor(350, 300, 100), Some(0.51));
        assert_eq!(factor(10_000, 300, 100), Some(1.0));
        assert_eq!(factor(299, 300, 0), Some(0.01));
        assert_eq!(factor(300, 300, 0), Some(1.0));
        // A factor of its own during the delay only; the authors' ramp from 0.01 after it.
        let own = ConvConfig {
            kl_delay: 300,
            warmup: 100,
            delay_factor: Some(0.0004),
            iterations: 1000,
            ..followup_config()
        };
        assert_eq!(warmup_factor(0, &own.code_at(0)), Some(0.0004));
        assert_eq!(warmup_factor(299, &own.code_at(299)), Some(0.0004));
        assert_eq!(warmup_factor(300, &own.code_at(300)), Some(0.01));
        assert_eq!(warmup_factor(350, &own.code_at(350)), Some(0.51));
        assert!(
            serde_json::to_value(followup_config())
                .unwrap()
                .get("delay_factor")
                .is_none()
        );
        assert_eq!(serde_json::to_value(&own).unwrap()["delay_factor"], 0.0004);
        for (bad, key) in [
            (
                ConvConfig {
                    delay_factor: Some(0.5),
                    ..followup_config()
                },
                "delay_factor",
            ),
            (
                ConvConfig {
                    delay_factor: Some(1.5),
                    ..own.clone()
                },
                "delay_factor",
            ),
        ] {
            let e = bad.check().unwrap_err();
            assert_eq!(e.key.as_deref(), Some(key), "{e}");
        }
        own.check().unwrap();

        let shifted = ConvConfig {
            kl_delay: 40,
            capacity_iterations: Some(20),
            ..followup_config()
        };
        assert_eq!(shifted.capacity_at(39), Some(0.0));
        assert_eq!(shifted.capacity_at(50), Some(2.5));
        assert_eq!(shifted.capacity_at(60), Some(5.0));
        let whole = ConvConfig {
            kl_delay: 40,
            ..followup_config()
        };
        assert_eq!(
            whole.capacity_at(70),
            Some(2.5),
            "ramped over the 60 iterations left"
        );
        assert_eq!(followup_config().capacity_at(50), Some(2.5));

        let plain = serde_json::to_value(followup_config()).unwrap();
        assert!(plain.get("kl_delay").is_none(), "{plain}");
        let delayed = ConvConfig {
            kl_delay: 40,
            ..followup_config()
        };
        assert_eq!(serde_json::to_value(&delayed).unwrap()["kl_delay"], 40);
        let back: ConvConfig = serde_json::from_value(plain).unwrap();
        assert_eq!(back, followup_config());

        // Before the delay ends the factor is 0.01: the heads' gradients differ from the
        // undelayed form's at the same step (factor 0.31 at step 3 of a 10-iteration ramp).
        let arch = small();
        let net = ConvNet::init(&mut stream_named(1, "conv"), arch, ConvInit::Torch04);
        let x = pictures(arch, 3, 2);
        let run = |cfg: &ConvConfig| {
            let mut t = ConvTrainer::new(net.clone());
            t.forward_backward(cfg, &x, 3, 3, &mut stream_named(3, "noise"))
                .unwrap();
            t.gradients()[HEAD].clone()
        };
        assert_ne!(run(&delayed), run(&followup_config()));

        let e = ConvConfig {
            kl_delay: 100,
            ..followup_config()
        }
        .check()
        .unwrap_err();
        assert_eq!(e.key.as_deref(), Some("kl_delay"), "{e}");
    }

    /// The weights after a few steps, as bits, in a pool of `threads` that flushes subnormals
    /// or not.
    fn trained_bits(threads: usize, flush: bool) -> Vec<u32> {
        let arch = small();
        let pool = if flush {
            ugl_kernels::flushing_pool(threads).unwrap()
        } else {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
        };
        pool.install(|| {
            let mut t = ConvTrainer::new(ConvNet::init(
                &mut stream_named(1, "conv"),
                arch,
                ConvInit::Torch04,
            ));
            let cfg = followup_config();
            let mut rng = stream_named(4, "noise");
            for step in 0..3 {
                let x = pictures(arch, 3, 10 + step as u64);
                t.step(&cfg, &x, 3, step, &mut rng).unwrap();
            }
            t.net
                .params()
                .iter()
                .flat_map(|p| p.iter().map(|v| v.to_bits()))
                .collect()
        })
    }

    #[test]
    fn the_weights_after_training_do_not_depend_on_the_threads() {
        for flush in [true, false] {
            assert_eq!(trained_bits(1, flush), trained_bits(2, flush));
            assert_eq!(trained_bits(1, flush), trained_bits(3, flush));
        }
    }

    /// `n` pictures of one lit 4x4 square each, at different places, in every channel.
    fn squares(arch: ConvArch, n: usize) -> Vec<f32> {
        let side = arch.side;
        let mut out = vec![0.0f32; n * arch.image_len()];
        for (i, img) in out.chunks_exact_mut(arch.image_len()).enumerate() {
            let (y0, x0) = ((i * 5) % (side - 4), (i * 3) % (side - 4));
            for c in 0..arch.channels {
                for y in y0..y0 + 4 {
                    for x in x0..x0 + 4 {
                        img[(c * side + y) * side + x] = 1.0;
                    }
                }
            }
        }
        out
    }

    /// Training must beat the known-bad answer, the mean picture: its loss (the pixel-summed
    /// cross-entropy of every picture against the mean) bounds what a network that encodes
    /// nothing can reach. The loss of a VAE is its reconstruction plus a KL >= 0, so a loss
    /// below that bound means the codes carry what tells the pictures apart.
    ///
    /// At this tiny size (8 filters, 32 hidden units, 2 latents, 8 pictures) some fits stay on
    /// the mean-picture plateau: in a sweep by hand, 1 of 6 initial weights at the authors' learning
    /// rate (1e-3) and 1 of 3 at 3e-3. So 4 fits are trained and 3 must leave it.
    #[test]
    fn training_beats_the_mean_picture() {
        let arch = ConvArch {
            filters: 8,
            hidden: 32,
            ..small()
        };
        let n = 8;
        let x = squares(arch, n);
        let len = arch.image_len();
        let entropy = |m: f64| {
            if m <= 0.0 || m >= 1.0 {
                0.0
            } else {
                -(m * m.ln() + (1.0 - m) * (1.0 - m).ln())
            }
        };
        let mean_picture_loss: f64 = (0..len)
            .map(|p| entropy((0..n).map(|i| f64::from(x[i * len + p])).sum::<f64>() / n as f64))
            .sum();
        let cfg = ConvConfig {
            iterations: 1500,
            warmup: 0,
            beta: 1.0,
            capacity: None,
            lr: 1e-3,
            batch: n,
            ..followup_config()
        };
        let mut finals = vec![];
        // Today's PyTorch initialisation: with the authors' (the last layer drawn smaller)
        // only 1 of these 4 seeds leaves the plateau in 1500 iterations (`docs/neural.md`).
        for seed in 1..=4 {
            let mut t = ConvTrainer::new(ConvNet::init(
                &mut stream_named(seed, "conv"),
                arch,
                ConvInit::Torch,
            ));
            let mut rng = stream_named(seed, "noise");
            let mut losses = vec![];
            for step in 0..cfg.iterations {
                losses.push(t.step(&cfg, &x, n, step, &mut rng).unwrap());
            }
            assert!(
                losses[0] > mean_picture_loss,
                "an untrained network cannot beat the mean picture ({} vs {mean_picture_loss})",
                losses[0]
            );
            finals.push(losses[losses.len() - 20..].iter().sum::<f64>() / 20.0);
        }
        let left = finals
            .iter()
            .filter(|&&l| l < 0.8 * mean_picture_loss)
            .count();
        assert!(
            left >= 3,
            "final losses {finals:?}; the mean picture's is {mean_picture_loss}"
        );
    }

    #[test]
    fn a_batch_of_the_wrong_size_is_an_error() {
        let arch = small();
        let mut t = ConvTrainer::new(ConvNet::init(
            &mut stream_named(1, "conv"),
            arch,
            ConvInit::Torch04,
        ));
        let x = pictures(arch, 2, 1);
        let err = t
            .forward_backward(&followup_config(), &x, 3, 0, &mut stream_named(3, "n"))
            .unwrap_err();
        assert!(err.to_string().contains("a batch of 3 pictures"), "{err}");
    }
}
