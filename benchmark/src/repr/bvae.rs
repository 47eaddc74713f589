//! The β-VAE (Higgins et al., ICLR 2017), the goal-space learner of the follow-up paper
//! (Laversanne-Finot, Péré, Oudeyer, CoRL 2018; `docs/followup-paper-sources.md` section 2): the
//! dense VAE of `vae.rs` with the KL term weighted by β,
//! loss = batch mean of (pixel-summed Bernoulli cross-entropy + β KL(N(mu, sigma^2) || N(0, I))).
//! β > 1 presses the posterior towards the factorised prior, which is what makes the latents
//! disentangled; **β = 1 is the VAE** (bit-identical to the corrected VAE's training for the same
//! stream, tested in `neural.rs`). Encoding = mu; prior = N(0, I).
//!
//! Not a model of the ICLR paper, so it has no faithful variant: the reparameterisation noise is
//! always one `eps` per sample (the corrected VAE's). β comes from `[learners.bvae] beta`
//! (default [`DEFAULT_BETA`]). The follow-up's own weights were trained with Burgess et al.'s
//! capacity-annealed objective, whose hyper-parameters are not public (section 2 of the sources):
//! `[learners.bvae] capacity = C` selects it, the KL term becoming `β |mean_b KL_b − C_t|` with
//! `C_t` rising linearly from 0 to C nats over the training (the follow-up code's
//! `loss_function`, "Version 1", with γ = β; its warm-up ramp `c` when `warmup` is set). Without `capacity`, the
//! plain β-VAE objective. The budget, init and size follow the ICLR recipe of
//! `data/campaigns/paper.toml` (`docs/neural.md`).

use burn::tensor::Tensor;

use super::nets::{DenseNet, bce_with_logits_sum, kl_std_normal};
use super::neural_model::{
    CodeSettings, INITIAL_WARMUP_FACTOR, Knobs, Latent, LatentInput, NeuralModel, Optimiser,
    StepInput, Variant, knob_number,
};
use super::total_correlation::total_correlation;
use super::vae::{code, encoding};
use crate::seed::Stream;

/// β when `[learners.bvae]` does not set it: 4, the value Higgins et al. used on their 2-D
/// shapes data and a common default (the follow-up's is not public).
pub const DEFAULT_BETA: f64 = 4.0;

/// The batch's KL term: `β mean_b KL_b`, or with capacity annealing (Burgess et al. 2018, the
/// follow-up code's `loss_function`) `β |mean_b KL_b − C|`.
///
/// With a warm-up (`warmup` > 0, the follow-up code's `c` ramp) or a KL delay, the term is
/// multiplied by [`warmup_factor`]; without either (every dense β-VAE so far) it is left as it
/// was.
fn kl_term(mu: Tensor<2>, logvar: Tensor<2>, input: &LatentInput<'_>) -> Tensor<1> {
    let kl = kl_std_normal(mu, logvar);
    let term = match input.code.capacity {
        None => kl.mul_scalar(input.code.beta).mean(),
        Some(c) => kl.mean().sub_scalar(c).abs().mul_scalar(input.code.beta),
    };
    match warmup_factor(input.step, &input.code) {
        Some(f) => term.mul_scalar(f),
        None => term,
    }
}

/// The added total-correlation term (the convolutional β-VAE's `tc`, ours): `weight` times the
/// batch's total correlation ([`total_correlation`]), under the same warm-up factor as the KL
/// term, since it is a part of the KL that the term weighs again.
fn tc_term(
    z: Tensor<2>,
    mu: Tensor<2>,
    logvar: Tensor<2>,
    weight: f64,
    input: &LatentInput<'_>,
) -> Tensor<1> {
    let factor = warmup_factor(input.step, &input.code).unwrap_or(1.0);
    total_correlation(z, mu, logvar).mul_scalar(weight * factor)
}

/// The KL warm-up factor at 0-based iteration `step`: `min(1, 0.01 + max(0, step − T_v) / T_a)`
/// after a delay of T_v = `kl_delay` iterations, with T_a = `warmup`, and the `delay_factor`
/// (0.01 unless set) during the delay. With no delay that is the follow-up code's
/// `c = min(1, 0.01 + step / T_a)`; a delay holds c at its factor for T_v iterations first (a
/// VAE phase, with the KL target held at 0 by the configuration's `capacity_at`, before β
/// presses), which the follow-up's form cannot give with a large β (`docs/neural.md`, "Third
/// round"). With a delay and no ramp (T_a = 0) c jumps to 1 at T_v. None: neither (no factor).
pub fn warmup_factor(step: usize, code: &CodeSettings) -> Option<f64> {
    let (kl_delay, warmup) = (code.kl_delay, code.warmup);
    if warmup == 0 && kl_delay == 0 {
        return None;
    }
    if step < kl_delay {
        return Some(code.delay_factor);
    }
    let after = (step - kl_delay) as f64;
    Some(match warmup {
        0 => 1.0,
        t_a => (INITIAL_WARMUP_FACTOR + after / t_a as f64).min(1.0),
    })
}

/// The β-VAE as a [`NeuralModel`]: TF Adam, prior N(0, I).
pub struct Bvae;

impl NeuralModel for Bvae {
    fn name(&self) -> &'static str {
        "bvae"
    }
    fn head_blocks(&self, latents: usize) -> Vec<usize> {
        vec![latents, latents]
    }
    /// No paper budget of its own: the VAE's.
    fn paper_iterations(&self) -> usize {
        100_000
    }
    fn own_knobs(&self) -> &'static [&'static str] {
        &["beta", "capacity"]
    }
    /// β = [`DEFAULT_BETA`]; no capacity (the plain β-VAE).
    fn default_knobs(&self) -> Knobs {
        Knobs::from_iter([("beta".into(), DEFAULT_BETA.into())])
    }
    /// `beta`: the weight of the KL term, in (0, 1e6]. `capacity`: Burgess et al.'s capacity
    /// annealing (the follow-up's objective): the KL term becomes `β |mean_b KL_b − C|`, C rising
    /// linearly from 0 to `capacity` nats over the training, in [0, 1e4].
    fn knob_value(
        &self,
        key: &str,
        value: &serde_json::Value,
    ) -> Result<serde_json::Value, String> {
        let v = knob_number(value)?;
        match key {
            "beta" if v.is_finite() && v > 0.0 && v <= 1e6 => Ok(v.into()),
            "beta" => Err(format!("must be positive and at most 1e6, got {v}")),
            "capacity" if v.is_finite() && (0.0..=1e4).contains(&v) => Ok(v.into()),
            "capacity" => Err(format!("must be between 0 and 1e4 nats, got {v}")),
            _ => Err(format!("bvae has no knob '{key}'")),
        }
    }
    fn code_settings(
        &self,
        knobs: &Knobs,
        step: usize,
        iterations: usize,
        variant: Variant,
    ) -> CodeSettings {
        let number = |key: &str| knobs.get(key).and_then(serde_json::Value::as_f64);
        CodeSettings {
            warmup: 0,
            kl_delay: 0,
            delay_factor: INITIAL_WARMUP_FACTOR,
            beta: number("beta").unwrap_or(DEFAULT_BETA),
            capacity: number("capacity")
                .map(|c| c * (step as f64 / iterations.max(1) as f64).min(1.0)),
            tc: None,
            variant,
        }
    }
    fn optimiser(&self) -> Optimiser {
        Optimiser::Adam
    }
    fn has_prior(&self) -> bool {
        true
    }
    fn loss(&self, net: &DenseNet, input: StepInput<'_>, rng: &mut Stream) -> Tensor<1> {
        let heads = net.heads(input.x.clone());
        let (z, mu, logvar) = code(heads, &input.latent, Variant::Corrected, rng);
        let rec = bce_with_logits_sum(net.decode(z), input.x);
        match (
            input.latent.code.capacity,
            input.latent.code.warmup,
            input.latent.code.kl_delay,
        ) {
            (None, 0, 0) => {
                (rec + kl_std_normal(mu, logvar).mul_scalar(input.latent.code.beta)).mean()
            }
            _ => rec.mean() + kl_term(mu, logvar, &input.latent),
        }
    }
    fn latent(&self, heads: Tensor<2>, input: &LatentInput<'_>, rng: &mut Stream) -> Latent {
        let (z, mu, logvar) = code(heads, input, Variant::Corrected, rng);
        let extra = match input.code.tc {
            None => kl_term(mu, logvar, input),
            Some(weight) => {
                let tc = tc_term(z.clone(), mu.clone(), logvar.clone(), weight, input);
                kl_term(mu, logvar, input) + tc
            }
        };
        Latent {
            z,
            extra: Some(extra),
            rec_scale: 1.0,
        }
    }
    fn mean_code(&self, head: &[f32], d: usize, out: &mut [f64]) {
        encoding(head, d, out)
    }
}
