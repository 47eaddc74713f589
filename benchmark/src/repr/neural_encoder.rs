//! A trained dense network as an encoder of images into latents, and its file format (the
//! model cache's and the checkpoints' payload).

use rand::SeedableRng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::model_file::{ModelFileError, seal, unseal};
use super::nets::{HostLayer, HostNet, Scratch};
use super::neural_config::Model;
use super::neural_model::Variant;
use super::{Encoder, GaussianPrior, ImageSet, Latents, ReprError, check_latents};
use crate::seed::Stream;

/// A fitted neural encoder. `losses` is the recorded loss curve: `(iteration, loss)` pairs,
/// iteration 0-based, every `log_every` iterations plus the last.
pub struct NeuralEncoder {
    pub model: Model,
    pub variant: Variant,
    pub net: HostNet,
    pub losses: Vec<(usize, f64)>,
    /// The seed of the encoder's own stream (drawn from the learner stream after training):
    /// it draws the faithful RFVAE's training latents (z0 samples the KDE is fitted on).
    pub encode_seed: [u8; 32],
    /// The stream of the faithful RFVAE's stochastic encoding (unused by the others): seeded
    /// from `encode_seed`, then replaced by each run's own stream
    /// ([`Encoder::begin_run`]).
    rng: Stream,
    scratch: Scratch,
}

impl std::fmt::Debug for NeuralEncoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NeuralEncoder")
            .field("model", &self.model)
            .field("variant", &self.variant)
            .field("dim", &self.net.dim)
            .field("hidden", &self.net.hidden)
            .field("latents", &self.net.latents)
            .field("losses", &self.losses.len())
            .finish()
    }
}

impl NeuralEncoder {
    /// An encoder from trained weights; `encode_seed` seeds the stream of the stochastic
    /// (faithful RFVAE) encoding.
    pub fn new(
        model: Model,
        variant: Variant,
        net: HostNet,
        losses: Vec<(usize, f64)>,
        encode_seed: [u8; 32],
    ) -> Self {
        NeuralEncoder {
            model,
            variant,
            net,
            losses,
            encode_seed,
            rng: Stream::from_seed(encode_seed),
            scratch: Scratch::default(),
        }
    }

    /// Whether encoding draws random numbers (the faithful RFVAE).
    pub fn is_stochastic(&self) -> bool {
        self.model.spec().is_stochastic(self.variant)
    }

    fn encode_row(&mut self, image: &[f32], out: &mut [f64]) {
        let head = self.net.encode_head(image, &mut self.scratch);
        let d = self.net.latents;
        self.model
            .spec()
            .encoding(&head, d, self.variant, &mut self.rng, out);
    }

    fn check_dim(&self, dim: usize) -> Result<(), ReprError> {
        if dim != self.net.dim {
            return Err(ReprError::InvalidInput(format!(
                "images have {dim} pixels, the model {}",
                self.net.dim
            )));
        }
        Ok(())
    }

    /// The training latents (what the KDE is fitted on). Faithful RFVAE: z0 samples
    /// `mu + eps sigma` (the original's `transform(X, sampling=True)`), with noise from a fresh
    /// stream seeded by `encode_seed` (a function of the model alone); otherwise the encoding.
    pub fn training_latents(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        if !self.is_stochastic() {
            return self.encode(images);
        }
        self.check_dim(images.dim)?;
        let d = self.net.latents;
        let mut data = vec![0.0; images.n * d];
        // A fresh stream from the model's own seed: the same training latents whenever this is
        // called, whatever was encoded before.
        let mut rng = Stream::from_seed(self.encode_seed);
        for (i, out) in data.chunks_exact_mut(d).enumerate() {
            let head = self.net.encode_head(images.row(i), &mut self.scratch);
            self.model.spec().training_sample(&head, d, &mut rng, out);
        }
        let z = Latents {
            n: images.n,
            latents: d,
            data,
        };
        check_latents(&z, self.model.name())?;
        Ok(z)
    }
}

impl Encoder for NeuralEncoder {
    fn latents(&self) -> usize {
        self.net.latents
    }

    fn reconstruct(&mut self, image: &[f32]) -> Option<Result<Vec<f32>, ReprError>> {
        Some(
            self.check_dim(image.len())
                .map(|_| reconstruct(self.model, &self.net, image)),
        )
    }

    fn begin_run(&mut self, rng: Stream) {
        self.rng = rng;
    }

    fn training_latents(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        NeuralEncoder::training_latents(self, images)
    }

    fn save(&self, key: &str) -> Option<Vec<u8>> {
        Some(to_bytes(key, self))
    }

    fn training_outcome(&self, images: &ImageSet) -> Option<super::TrainingOutcome> {
        let head = images.head(super::evidence::EVIDENCE_IMAGES);
        let rec = reconstruction_loss(self.model, &self.net, &head, head.n);
        Some(super::TrainingOutcome {
            losses: self.losses.clone(),
            // The last iteration is always logged.
            iterations: self.losses.last().map_or(0, |&(step, _)| step + 1),
            evidence: super::evidence::TrainingEvidence::new(
                super::evidence::mean_image_loss(&head),
                rec,
                head.n,
            ),
        })
    }

    fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        self.check_dim(images.dim)?;
        let d = self.net.latents;
        let mut data = vec![0.0; images.n * d];
        if self.is_stochastic() {
            // Sequential: the noise is drawn image by image from the encoder's stream.
            for (i, out) in data.chunks_exact_mut(d).enumerate() {
                self.encode_row(images.row(i), out);
            }
        } else {
            let (net, model) = (&self.net, self.model);
            data.par_chunks_mut(d).enumerate().for_each_init(
                Scratch::default,
                |scratch, (i, out)| {
                    let head = net.encode_head(images.row(i), scratch);
                    // Not stochastic: the encoding is the noise-free code.
                    model.spec().mean_code(&head, d, out);
                },
            );
        }
        let z = Latents {
            n: images.n,
            latents: d,
            data,
        };
        check_latents(&z, self.model.name())?;
        Ok(z)
    }

    fn encode_one(&mut self, image: &[f32], out: &mut [f64]) -> Result<(), ReprError> {
        if image.len() != self.net.dim || out.len() != self.net.latents {
            return Err(ReprError::InvalidInput(format!(
                "encode_one: image of {} pixels / output of {} values, the model takes {} / {}",
                image.len(),
                out.len(),
                self.net.dim,
                self.net.latents
            )));
        }
        self.encode_row(image, out);
        if let Some(j) = out.iter().position(|v| !v.is_finite()) {
            return Err(ReprError::Numerical(format!(
                "{}: non-finite latent (dimension {j})",
                self.model.name()
            )));
        }
        Ok(())
    }

    fn prior(&self) -> Option<GaussianPrior> {
        self.model.spec().has_prior().then(|| GaussianPrior {
            mean: vec![0.0; self.net.latents],
            std: vec![1.0; self.net.latents],
        })
    }
}

#[derive(Serialize, Deserialize)]
pub(crate) struct Header {
    key: String,
    model: Model,
    variant: Variant,
    dim: usize,
    hidden: [usize; 2],
    latents: usize,
    /// `(inp, out)` of enc1, enc2, head, dec1, dec2, dec_out.
    layers: Vec<(usize, usize)>,
    losses: Vec<(usize, f64)>,
    encode_seed: String,
}

/// Serialise a neural encoder under `key`.
pub fn to_bytes(key: &str, enc: &NeuralEncoder) -> Vec<u8> {
    let net = &enc.net;
    let header = Header {
        key: key.into(),
        model: enc.model,
        variant: enc.variant,
        dim: net.dim,
        hidden: net.hidden,
        latents: net.latents,
        layers: net.layers().iter().map(|l| (l.inp, l.out)).collect(),
        losses: enc.losses.clone(),
        encode_seed: hex(&enc.encode_seed),
    };
    let header = serde_json::to_vec(&header).expect("header serialises");
    let mut payload = Vec::with_capacity(4 * net.num_params());
    for l in net.layers() {
        for v in l.w.iter().chain(&l.b) {
            payload.extend_from_slice(&v.to_le_bytes());
        }
    }
    seal(&header, &payload)
}

/// Parse and check a neural encoder's bytes; `Err` says why they cannot be trusted.
pub fn from_bytes(key: &str, bytes: &[u8]) -> Result<NeuralEncoder, ModelFileError> {
    let (header, payload) = unseal(bytes)?;
    let h: Header =
        serde_json::from_slice(header).map_err(|e| ModelFileError::Header(e.to_string()))?;
    if h.key != key {
        return Err(ModelFileError::Key { found: h.key });
    }
    let [h1, h2] = h.hidden;
    let p: usize = h.model.head_blocks(h.latents).iter().sum();
    let expect = vec![
        (h.dim, h1),
        (h1, h2),
        (h2, p),
        (h.latents, h2),
        (h2, h1),
        (h1, h.dim),
    ];
    if h.layers != expect {
        return Err(ModelFileError::Content(
            "layer shapes do not match the model".into(),
        ));
    }
    let values: usize = expect.iter().map(|(i, o)| i * o + o).sum();
    if payload.len() != 4 * values {
        return Err(ModelFileError::Content(format!(
            "weights have {} bytes, the shapes need {}",
            payload.len(),
            4 * values
        )));
    }
    let mut floats = payload
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")));
    let mut take = |k: usize| -> Vec<f32> { floats.by_ref().take(k).collect() };
    let mut layer = |(inp, out): (usize, usize)| HostLayer {
        inp,
        out,
        w: take(inp * out),
        b: take(out),
    };
    let net = HostNet {
        dim: h.dim,
        hidden: h.hidden,
        latents: h.latents,
        enc1: layer(expect[0]),
        enc2: layer(expect[1]),
        head: layer(expect[2]),
        dec1: layer(expect[3]),
        dec2: layer(expect[4]),
        dec_out: layer(expect[5]),
    };
    let seed =
        unhex(&h.encode_seed).ok_or_else(|| ModelFileError::Header("bad encoder seed".into()))?;
    Ok(NeuralEncoder::new(h.model, h.variant, net, h.losses, seed))
}

pub(crate) fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

pub(crate) fn unhex(s: &str) -> Option<[u8; 32]> {
    if s.len() != 64 {
        return None;
    }
    let mut out = [0u8; 32];
    for (i, o) in out.iter_mut().enumerate() {
        *o = u8::from_str_radix(s.get(2 * i..2 * i + 2)?, 16).ok()?;
    }
    Some(out)
}

/// The reconstruction loss of a trained network on (at most `max`) `images`: the Bernoulli
/// loss summed over pixels and averaged over images, of the decoder applied to each image's
/// noise-free code (AE: its sigmoid latents; VAE: mu; RFVAE: the flows applied to mu). No KL
/// term and no flow log-determinant, so it is comparable with the mean-image loss
/// ([`super::evidence::mean_image_loss`]) for every model.
pub fn reconstruction_loss(model: Model, net: &HostNet, images: &ImageSet, max: usize) -> f64 {
    let n = images.n.min(max);
    let per_image: Vec<f64> = (0..n)
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            let x = images.row(i);
            let logits = noise_free_logits(model, net, x, scratch);
            logits
                .iter()
                .zip(x)
                .map(|(&l, &t)| super::evidence::bce_of_logit(l, t))
                .sum::<f64>()
        })
        .collect();
    per_image.iter().sum::<f64>() / n as f64
}

/// The decoder's logits for an image's noise-free code (AE: its sigmoid latents; VAE: mu;
/// RFVAE: the flows applied to mu).
fn noise_free_logits(model: Model, net: &HostNet, x: &[f32], scratch: &mut Scratch) -> Vec<f32> {
    let d = net.latents;
    let head = net.encode_head(x, scratch);
    let mut code = vec![0.0f64; d];
    model.spec().mean_code(&head, d, &mut code);
    let z: Vec<f32> = code.iter().map(|&v| v as f32).collect();
    net.decode_logits(&z, scratch)
}

/// The reconstruction of an image (pixel probabilities, the sigmoid of the decoder's logits for
/// its noise-free code), as in [`reconstruction_loss`]: for figures.
pub fn reconstruct(model: Model, net: &HostNet, x: &[f32]) -> Vec<f32> {
    noise_free_logits(model, net, x, &mut Scratch::default())
        .into_iter()
        .map(|l| 1.0 / (1.0 + libm::expf(-l)))
        .collect()
}
