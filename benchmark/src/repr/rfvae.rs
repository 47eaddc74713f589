//! The paper's dense VAE with radial flows (`DenseRadialVAE`; docs/original-code.md section 5,
//! "RFVAE"): the VAE's trunk with linear heads mu, logvar and the amortised parameters of
//! `K` = 10 radial flows (Rezende & Mohamed 2015): centres `c` (K x d), `a` (K), `b` (K).
//!
//! Per flow, from `z_{k-1}` (all per sample): `a <- |a|`, `beta <- -a + softplus(b)`,
//! `r = ||z - c||`, `h = 1 / (a + r)`, `z_k = z + beta h (z - c)`, and the log-determinant term
//! `log(clip((1 + beta h)^(d-1) (1 + beta h - beta r / (a + r)^2), 1e-4, 1e6))`.
//! Loss = `mean(ann * (KL(q0 || N(0, I)) + sum BCE) - sum_k logdet_k)` (faithful) with the warm-up
//! `ann = min(1, 0.01 + step / warmup)` (step 0-based; the paper's warm-up is 1e4 iterations) on both the KL and the reconstruction, not
//! on the log-det; the KL is the analytic Gaussian KL of z0. TF Adam, lr 1e-3, 50,000
//! iterations. Prior = N(0, I).
//!
//! Head layout (columns of the one head layer, drawn in this order like the original's
//! variables): `mu (d) | logvar (d) | c (K d, flow-major) | b (K) | a (K)`.
//!
//! Variants — everything else (initial weights, batch draws, the flow, the warm-up) is shared:
//! - **faithful**, as the original code:
//!   1. the reparameterisation noise `eps` has shape `[d]` and is shared by the whole batch
//!      (`tf.random_normal([emb_size])`, the same quirk as the VAE's);
//!   2. **log-det broadcast.** The original multiplies the per-sample `-1/(a+r)^2` (`[B]`) by
//!      `expand_dims(beta, 1)` (`[B, 1]`), which broadcasts the term to `[B, B]`:
//!      `T[i, j] = (1 + beta_j h_j)^(d-1) (1 + beta_j h_j - beta_i r_j / (a_j + r_j)^2)`, i.e.
//!      sample `j`'s geometry with sample `i`'s `beta` in the last product. The summed
//!      log-det `L[i, j] = sum_k log clip(T_k[i, j])` stays `[B, B]`, and adding the `[B]`
//!      reconstruction term broadcasts the loss to `[B, B]` before `reduce_mean`. Its exact
//!      effect, which we reproduce: `loss = ann * mean_j(KL_j + BCE_j) - mean_{i,j} L[i, j]`
//!      (only the diagonal `i = j` is the true log-det);
//!   3. **encoding mismatch.** Outcomes are encoded as `z_K` of a *freshly sampled*
//!      `z0 = mu + eps sigma` (the original's `transform(sampling=False)`; stochastic: each
//!      image draws its own `eps` of `d` normals from the encoder's stream, which is seeded from
//!      the learner stream at fit time), while the training latents returned by `fit` (what the
//!      KDE is fitted on) are `z0` samples `mu + eps sigma`, no flow
//!      (`transform(X, sampling=True)`). Goals and outcomes live in different spaces.
//! - **corrected**: per-sample `eps` (`[B, d]`); per-sample log-det (`[B]`, the diagonal);
//!   encoding and training latents are both the deterministic `z_K` of `z0 = mu` (the flows
//!   applied to the mean); and the prior N(0, I) is on `z_K`, where the outcomes are encoded
//!   (the free energy of Rezende & Mohamed 2015: `E[log q0(z0) - sum_k logdet_k - log p(z_K)]`),
//!   not on `z0` as in the original, whose Gaussian goals are drawn from a prior of another
//!   space than the encodings. (Results version 4.)

use crate::seed::standard_normal;
use burn::tensor::{Device, Tensor};

use super::host_ops::{exp, log, powf, softplus};
use super::nets::{DenseNet, bce_with_logits_sum, kl_std_normal};
use super::neural_model::{
    CodeSettings, Knobs, Latent, LatentInput, NeuralModel, Optimiser, StepInput, Variant,
    knob_count, tensor2,
};
use super::vae::eps;
use crate::seed::Stream;

/// Number of radial flows (the original's `nb_trans`).
pub const FLOWS: usize = 10;
/// The log-det clip range.
pub const LOGDET_CLIP: (f64, f64) = (1e-4, 1e6);
/// Warm-up length of the paper (the original's `ann_duration`); configurable as
/// `[learners.rfvae] warmup` (reduced budgets scale it down with the iterations).
pub const ANNEAL_STEPS: usize = 10_000;

/// Head block widths: mu, logvar, c, b, a.
pub fn head_blocks(d: usize) -> Vec<usize> {
    vec![d, d, FLOWS * d, FLOWS, FLOWS]
}

/// The KL warm-up factor at 0-based iteration `step` of a `warmup`-iteration warm-up:
/// `min(1, 0.01 + step / warmup)`.
pub fn annealing(step: usize, warmup: usize) -> f64 {
    (0.01 + step as f64 / warmup.max(1) as f64).min(1.0)
}

/// The flow parameters of a batch, sliced from the head outputs `[B, P]`.
pub struct FlowParams {
    /// `[B, K d]`.
    pub c: Tensor<2>,
    /// `[B, K]`, before `|.|`.
    pub a: Tensor<2>,
    /// `[B, K]`, before the softplus.
    pub b: Tensor<2>,
}

impl FlowParams {
    /// Slice the flow parameters out of the head outputs.
    pub fn from_heads(heads: &Tensor<2>, d: usize) -> FlowParams {
        let c = heads.clone().narrow(1, 2 * d, FLOWS * d);
        let b = heads.clone().narrow(1, 2 * d + FLOWS * d, FLOWS);
        let a = heads.clone().narrow(1, 2 * d + FLOWS * d + FLOWS, FLOWS);
        FlowParams { c, a, b }
    }
}

/// One radial flow `k` on a batch `z` (`[B, d]`). Returns `z_k` and the log-det term: `[B, 1]`
/// (corrected) or the original's broadcast `[B, B]` (faithful; see the module doc).
pub fn flow_step(
    z: Tensor<2>,
    p: &FlowParams,
    k: usize,
    d: usize,
    variant: Variant,
) -> (Tensor<2>, Tensor<2>) {
    let c = p.c.clone().narrow(1, k * d, d);
    let a = p.a.clone().narrow(1, k, 1).abs();
    let beta = softplus(p.b.clone().narrow(1, k, 1)) - a.clone();
    let diff = z.clone() - c;
    let r = diff.clone().square().sum_dim(1).sqrt();
    let a_plus_r = a + r.clone();
    let h = a_plus_r.clone().recip();
    let bh = beta.clone() * h;
    let z_next = z + bh.clone() * diff;
    // r / (a + r)^2, [B, 1]
    let q = r / a_plus_r.square();
    let (bh, q) = match variant {
        Variant::Corrected => (bh, q),
        // The broadcast: sample j's (bh, q) along the columns, sample i's beta down the rows.
        Variant::Faithful => (bh.transpose(), q.transpose()),
    };
    let one_bh = bh.add_scalar(1.0);
    let t = powf(one_bh.clone(), (d - 1) as f32) * (one_bh - beta * q);
    let logdet = log(t.clamp(LOGDET_CLIP.0, LOGDET_CLIP.1));
    (z_next, logdet)
}

/// All `K` flows from `z0`: `(z_K, sum_k logdet_k)`.
pub fn flows(z0: Tensor<2>, p: &FlowParams, d: usize, variant: Variant) -> (Tensor<2>, Tensor<2>) {
    let mut z = z0;
    let mut total: Option<Tensor<2>> = None;
    for k in 0..FLOWS {
        let (zn, ld) = flow_step(z, p, k, d, variant);
        z = zn;
        total = Some(match total {
            Some(t) => t + ld,
            None => ld,
        });
    }
    (z, total.expect("at least one flow"))
}

/// The code of the heads `[B, P]` through the flows (draws the noise): `(z_K, KL of z0 [B, 1],
/// summed log-det, warm-up factor)`.
fn code(
    heads: Tensor<2>,
    input: &LatentInput<'_>,
    rng: &mut Stream,
) -> (Tensor<2>, Tensor<2>, Tensor<2>, f64) {
    let d = input.latents;
    let mu = heads.clone().narrow(1, 0, d);
    let logvar = heads.clone().narrow(1, d, d);
    let p = FlowParams::from_heads(&heads, d);
    let e = eps(input.code.variant, input.batch, d, rng, input.device);
    let z0 = mu.clone() + e.mul(exp(logvar.clone().mul_scalar(0.5)));
    let (zk, logdet) = flows(z0.clone(), &p, d, input.code.variant);
    let ann = annealing(input.step, input.code.warmup);
    let kl = kl_std_normal(mu, logvar);
    let kl = match input.code.variant {
        Variant::Faithful => kl,
        // The prior is on z_K (Rezende & Mohamed 2015, Section 4.2): the free energy's
        // `E[log q0(z0) - log p(z_K)]` is the analytic KL of z0 plus the one-sample
        // `log p(z0) - log p(z_K) = (|z_K|^2 - |z0|^2) / 2`, so that N(0, I) is the prior of
        // the space the outcomes are encoded in (z_K) and Gaussian goals are drawn there.
        Variant::Corrected => {
            kl + (zk.clone().square() - z0.square())
                .sum_dim(1)
                .mul_scalar(0.5)
        }
    };
    (zk, kl, logdet, ann)
}

/// The training loss of one mini-batch (see the module doc for the two variants).
pub fn loss(net: &DenseNet, input: StepInput<'_>, rng: &mut Stream) -> Tensor<1> {
    let (zk, kl, logdet, ann) = code(net.heads(input.x.clone()), &input.latent, rng);
    let rec = bce_with_logits_sum(net.decode(zk), input.x) + kl;
    match input.latent.code.variant {
        Variant::Corrected => (rec.mul_scalar(ann) - logdet).mean(),
        Variant::Faithful => rec.mul_scalar(ann).mean() - logdet.mean(),
    }
}

/// The host engine's middle (same noise draws as [`loss`]): `z_K` of the flows, loss =
/// `ann` x (batch-mean reconstruction + batch-mean KL) - the mean log-det (the diagonal `[B]`
/// corrected, the original's broadcast `[B, B]` faithful; see the module doc).
pub fn latent(heads: Tensor<2>, input: &LatentInput<'_>, rng: &mut Stream) -> Latent {
    let (zk, kl, logdet, ann) = code(heads, input, rng);
    Latent {
        z: zk,
        extra: Some(kl.mean().mul_scalar(ann) - logdet.mean()),
        rec_scale: ann,
    }
}

/// Softplus in f64 (`ln(1 + e^x)`, linear above 20 like burn's).
fn softplus_f64(x: f64) -> f64 {
    if x > 20.0 {
        x
    } else {
        libm::log1p(libm::exp(x))
    }
}

/// One radial flow on the host (f64): updates `z` in place and returns the corrected
/// (per-sample, unclipped) log-det term `log((1 + beta h)^(d-1) (1 + beta h - beta r/(a+r)^2))`.
pub fn flow_step_host(z: &mut [f64], c: &[f64], a_raw: f64, b_raw: f64) -> f64 {
    let d = z.len();
    let a = a_raw.abs();
    let beta = -a + softplus_f64(b_raw);
    let r = z
        .iter()
        .zip(c)
        .map(|(zi, ci)| (zi - ci) * (zi - ci))
        .sum::<f64>()
        .sqrt();
    let h = 1.0 / (a + r);
    let bh = beta * h;
    for (zi, ci) in z.iter_mut().zip(c) {
        *zi += bh * (*zi - ci);
    }
    libm::log((1.0 + bh).powi(d as i32 - 1) * (1.0 + bh - beta * r / ((a + r) * (a + r))))
}

/// All flows of one image on the host, from the head outputs; `z` holds `z0` on entry.
pub fn flows_host(head: &[f32], d: usize, z: &mut [f64]) {
    let c0 = 2 * d;
    let b0 = c0 + FLOWS * d;
    let a0 = b0 + FLOWS;
    for k in 0..FLOWS {
        let c: Vec<f64> = head[c0 + k * d..c0 + (k + 1) * d]
            .iter()
            .map(|&v| f64::from(v))
            .collect();
        flow_step_host(z, &c, f64::from(head[a0 + k]), f64::from(head[b0 + k]));
    }
}

/// `z0 = mu + eps sigma` with a fresh `eps` (`d` normals from `rng`).
pub fn z0_sample(head: &[f32], d: usize, rng: &mut Stream, out: &mut [f64]) {
    for j in 0..d {
        let e = standard_normal(rng);
        out[j] = f64::from(head[j]) + e * libm::exp(0.5 * f64::from(head[d + j]));
    }
}

/// The encoding: faithful = `z_K` of a fresh `z0` sample (draws from `rng`); corrected =
/// `z_K` of `z0 = mu`.
pub fn encoding(head: &[f32], d: usize, variant: Variant, rng: &mut Stream, out: &mut [f64]) {
    match variant {
        Variant::Faithful => {
            z0_sample(head, d, rng, out);
            flows_host(head, d, out);
        }
        Variant::Corrected => mean_code(head, d, out),
    }
}

/// The noise-free code: `z_K` of `z0 = mu` (both variants; the corrected variant's encoding).
pub fn mean_code(head: &[f32], d: usize, out: &mut [f64]) {
    for (o, &m) in out.iter_mut().zip(&head[..d]) {
        *o = f64::from(m);
    }
    flows_host(head, d, out);
}

/// Test helper: the tensor flow's log-det terms of one flow for host points, on the plain
/// (non-autodiff) flex device. `z`, `c`: row-major `[n, d]`; returns `n` values (corrected) or
/// `n * n` (faithful, row-major `[i, j]`).
pub fn flow_logdet_tensor(
    z: &[f64],
    c: &[f64],
    a: &[f64],
    b: &[f64],
    d: usize,
    variant: Variant,
) -> (Vec<f64>, Vec<f64>) {
    let n = a.len();
    let device = Device::flex();
    let f = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let zt = tensor2(f(z), n, d, &device);
    // Build a head-shaped parameter set with only flow 0 used.
    let mut cfull = vec![0.0f32; n * FLOWS * d];
    let mut afull = vec![0.0f32; n * FLOWS];
    let mut bfull = vec![0.0f32; n * FLOWS];
    for i in 0..n {
        for j in 0..d {
            cfull[i * FLOWS * d + j] = c[i * d + j] as f32;
        }
        afull[i * FLOWS] = a[i] as f32;
        bfull[i * FLOWS] = b[i] as f32;
    }
    let p = FlowParams {
        c: tensor2(cfull, n, FLOWS * d, &device),
        a: tensor2(afull, n, FLOWS, &device),
        b: tensor2(bfull, n, FLOWS, &device),
    };
    let (zn, ld) = flow_step(zt, &p, 0, d, variant);
    let read = |t: Tensor<2>| -> Vec<f64> {
        t.into_data()
            .try_into_vec::<f32>()
            .expect("f32 tensor")
            .into_iter()
            .map(f64::from)
            .collect()
    };
    (read(zn), read(ld))
}
/// The RFVAE as a [`NeuralModel`]: TF Adam, KL warm-up, prior N(0, I), 50,000 iterations in
/// the paper; the faithful variant encodes stochastically.
pub struct Rfvae;

impl NeuralModel for Rfvae {
    fn name(&self) -> &'static str {
        "rfvae"
    }
    fn head_blocks(&self, latents: usize) -> Vec<usize> {
        head_blocks(latents)
    }
    fn paper_iterations(&self) -> usize {
        50_000
    }
    fn paper_warmup(&self) -> usize {
        ANNEAL_STEPS
    }
    fn own_knobs(&self) -> &'static [&'static str] {
        &["warmup"]
    }
    /// The paper's warm-up, [`ANNEAL_STEPS`].
    fn default_knobs(&self) -> Knobs {
        Knobs::from_iter([("warmup".into(), ANNEAL_STEPS.into())])
    }
    /// `warmup`: iterations of the KL warm-up `min(1, 0.01 + step / warmup)` (paper: 10,000 of
    /// 50,000), at least 1.
    fn knob_value(
        &self,
        key: &str,
        value: &serde_json::Value,
    ) -> Result<serde_json::Value, String> {
        match key {
            "warmup" => match knob_count(value)? {
                0 => Err("must be at least 1".into()),
                n => Ok(n.into()),
            },
            _ => Err(format!("rfvae has no knob '{key}'")),
        }
    }
    fn code_settings(
        &self,
        knobs: &Knobs,
        step: usize,
        iterations: usize,
        variant: Variant,
    ) -> CodeSettings {
        let _ = (step, iterations);
        CodeSettings {
            warmup: knobs
                .get("warmup")
                .and_then(serde_json::Value::as_u64)
                .map_or(ANNEAL_STEPS, |w| w as usize),
            kl_delay: 0,
            delay_factor: super::neural_model::INITIAL_WARMUP_FACTOR,
            beta: 1.0,
            capacity: None,
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
        loss(net, input, rng)
    }
    fn latent(&self, heads: Tensor<2>, input: &LatentInput<'_>, rng: &mut Stream) -> Latent {
        latent(heads, input, rng)
    }
    fn is_stochastic(&self, variant: Variant) -> bool {
        variant == Variant::Faithful
    }
    fn encoding(&self, head: &[f32], d: usize, v: Variant, rng: &mut Stream, out: &mut [f64]) {
        encoding(head, d, v, rng, out)
    }
    fn mean_code(&self, head: &[f32], d: usize, out: &mut [f64]) {
        mean_code(head, d, out)
    }
    fn training_sample(&self, head: &[f32], d: usize, rng: &mut Stream, out: &mut [f64]) {
        z0_sample(head, d, rng, out)
    }
}
