//! Representation learners: the UGL stage of IMGEP-UGL (paper Section 3, Algorithm 1;
//! docs/original-code.md section 5). A learner is fitted on passively observed images and returns an
//! encoder that maps images to latent vectors, the goal space of RGE-REP.
//!
//! Adding a learner = one file implementing [`RepresentationLearner`] + one entry in
//! [`registry`]. The conformance suite (`benchmark/tests/learner_conformance.rs`) runs against
//! every registered learner.

pub mod ae;
pub mod bvae;
pub mod cache;
pub mod checkpoint;
pub mod conv_learner;
pub mod conv_net;
pub mod conv_train;
pub mod dataset;
pub mod disentanglement;
pub mod evidence;
pub mod external;
pub mod gaussian_projection;
pub mod host_ops;
pub mod host_train;
pub mod isomap;
pub mod model_file;
pub mod nets;
pub mod neural;
pub mod neural_config;
pub mod neural_encoder;
pub mod neural_model;
pub mod params;
pub mod pca;
pub mod quality;
pub mod registry;
pub mod rfvae;
pub mod sparse;
pub mod target_blur;
pub mod total_correlation;
pub mod trainer;
pub mod training_loop;
pub mod vae;

use std::path::PathBuf;

use thiserror::Error;

use crate::seed::Stream;
use evidence::TrainingEvidence;

/// A set of images, row-major `n x dim` (dim = 4900 for the 70x70 renderer, pixel (x, y) of
/// image i at `i * dim + x * 70 + y`), values in [0,1].
#[derive(Clone, Debug, PartialEq)]
pub struct ImageSet {
    pub n: usize,
    pub dim: usize,
    pub data: Vec<f32>,
}

impl ImageSet {
    /// Wrap row-major data; `data.len()` must be `n * dim`.
    pub fn new(n: usize, dim: usize, data: Vec<f32>) -> Result<Self, ReprError> {
        if data.len() != n * dim {
            return Err(ReprError::InvalidInput(format!(
                "image data has {} values, expected {n} x {dim}",
                data.len()
            )));
        }
        Ok(ImageSet { n, dim, data })
    }

    /// Image `i` as a slice of `dim` pixels.
    pub fn row(&self, i: usize) -> &[f32] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// The first `min(n, self.n)` images, copied.
    pub fn head(&self, n: usize) -> ImageSet {
        let n = n.min(self.n);
        ImageSet {
            n,
            dim: self.dim,
            data: self.data[..n * self.dim].to_vec(),
        }
    }
}

/// Latent vectors, row-major `n x latents`.
#[derive(Clone, Debug, PartialEq)]
pub struct Latents {
    pub n: usize,
    pub latents: usize,
    pub data: Vec<f64>,
}

impl Latents {
    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.latents..(i + 1) * self.latents]
    }
}

/// Errors of learners and encoders.
#[derive(Debug, Error)]
pub enum ReprError {
    /// Bad input (shape, empty set, latents out of range...).
    #[error("{0}")]
    InvalidInput(String),
    /// The fit failed numerically (disconnected graph, NaN, no convergence...).
    #[error("{0}")]
    Numerical(String),
    /// The model cache could not be written.
    #[error("model cache: {0}")]
    Cache(String),
    /// An external learner program failed or broke the protocol.
    #[error("external learner: {0}")]
    External(String),
    /// I/O.
    #[error("{0}")]
    Io(String),
}

/// A Gaussian prior over the latent space (for Gaussian-prior goal sampling, "-GP").
#[derive(Clone, Debug, PartialEq)]
pub struct GaussianPrior {
    pub mean: Vec<f64>,
    pub std: Vec<f64>,
}

/// Maps images to latent vectors.
pub trait Encoder: Send {
    /// Latent dimension.
    fn latents(&self) -> usize;
    /// Encode a batch of images.
    fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError>;
    /// Encode one image (`dim` pixels) into `out` (`latents` values). The default wraps
    /// [`Encoder::encode`]; learners with a cheaper single-image path override it.
    fn encode_one(&mut self, image: &[f32], out: &mut [f64]) -> Result<(), ReprError> {
        let set = ImageSet::new(1, image.len(), image.to_vec())?;
        let z = self.encode(&set)?;
        out.copy_from_slice(&z.data);
        Ok(())
    }
    /// The reconstruction of an image (pixel values in [0, 1]) by a model with a decoder, from
    /// the image's noise-free code; None for learners without one (PCA, Isomap, external).
    fn reconstruct(&mut self, image: &[f32]) -> Option<Result<Vec<f32>, ReprError>> {
        let _ = image;
        None
    }
    /// The model's prior over latents, where it has one (VAE-type models).
    fn prior(&self) -> Option<GaussianPrior> {
        None
    }
    /// Start encoding for a new run: a stochastic encoder (one that draws noise when it
    /// encodes) takes all its noise from `rng` from now on. The harness calls it before every
    /// run with the run's own stream ([`crate::seed::Component::Encoding`]), so a run's
    /// encodings depend on its identity only, never on which runs used the encoder before it.
    /// Deterministic encoders ignore it (the default).
    fn begin_run(&mut self, rng: Stream) {
        let _ = rng;
    }
    /// Per latent, the mean KL divergence of the posterior from the prior N(0, 1) over
    /// `images`, in nats, for encoders with a Gaussian posterior that expose it (the follow-up's
    /// convolutional networks); None for the others.
    fn per_latent_kl(&mut self, images: &ImageSet) -> Option<Result<Vec<f64>, ReprError>> {
        let _ = images;
        None
    }
    /// The fit time the learner measured itself, where it reports one (an external program's
    /// `READY fit_s=...`: its fit without interpreter start-up, imports and file I/O).
    fn reported_fit_s(&self) -> Option<f64> {
        None
    }
    /// The latents of the training images the goal samplers are fitted on (the KDE); by
    /// default their encodings. A model whose training latents are samples (the faithful
    /// RFVAE's z0) overrides it; it must return what [`RepresentationLearner::fit`] returned,
    /// for an encoder loaded from the model cache as well.
    fn training_latents(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        self.encode(images)
    }
    /// The encoder as bytes for the model cache, under `key` (checked again when it is loaded
    /// with [`RepresentationLearner::load`]); None for encoders that are not kept.
    fn save(&self, key: &str) -> Option<Vec<u8>> {
        let _ = key;
        None
    }
    /// How a trained network got here (its loss curve, and its reconstruction loss against the
    /// mean-image plateau on the first [`evidence::EVIDENCE_IMAGES`] of `images`), recorded in
    /// the manifests; None for learners that are not trained by iterations.
    fn training_outcome(&self, images: &ImageSet) -> Option<TrainingOutcome> {
        let _ = images;
        None
    }
}

/// The training of an iteratively trained encoder ([`Encoder::training_outcome`]).
#[derive(Clone, Debug)]
pub struct TrainingOutcome {
    /// The recorded loss curve, `(iteration, mini-batch loss)`.
    pub losses: Vec<(usize, f64)>,
    /// The iterations trained (more than configured where the plateau rule trained on).
    pub iterations: usize,
    /// The reconstruction loss against the plateau, and whether the network left it.
    pub evidence: TrainingEvidence,
}

/// What the harness offers one fit: where to report, where to checkpoint, how many threads (the
/// campaign's `Harness::fit_context` derives it from the one declaration of these services). A
/// learner uses what applies to it and ignores the rest (the default
/// [`RepresentationLearner::fit_in`] ignores all of it).
#[derive(Clone, Default)]
pub struct FitContext {
    /// Progress of a training, after every iteration.
    pub progress: Option<neural::ProgressFn>,
    /// Mid-training checkpoints of a long training (resumed bit-identically after a kill).
    pub checkpoint: Option<neural::CheckpointSpec>,
    /// Threads of a training: 0 = the calling pool's.
    pub threads: usize,
    /// A file the learner's own messages are appended to (an external program's stderr).
    pub log_file: Option<PathBuf>,
    /// The learner's messages, line by line as they come.
    pub messages: Option<external::LineSink>,
    /// The shape of the pictures (the environment's), for learners that need more than their
    /// values (an external program is told it as `UGL_IMAGE`).
    pub image: Option<ugl_types::ImageShape>,
}

/// How the threads of a training pool treat subnormal numbers ([`FitContext::in_pool_with`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Subnormals {
    /// IEEE arithmetic (the dense networks, and PyTorch's CPU default).
    Kept,
    /// Flushed to zero, operands and results (x86-64 FTZ and DAZ, set on every thread of the
    /// pool; [`ugl_kernels::flushing_pool`]); an error on other architectures.
    Flushed,
}

impl FitContext {
    /// Run `f` on the context's threads (a pool of [`FitContext::threads`]; 0: the calling
    /// pool's), with IEEE subnormals.
    pub fn in_pool<T: Send>(
        &self,
        f: impl FnOnce() -> Result<T, ReprError> + Send,
    ) -> Result<T, ReprError> {
        self.in_pool_with(Subnormals::Kept, f)
    }

    /// Run `f` on the context's threads, treating subnormals as `subnormals` says. The one
    /// place a training pool is built: a flushing pool is always a pool of its own (0 threads:
    /// as many as the calling pool's), since the calling pool's threads must stay IEEE.
    pub fn in_pool_with<T: Send>(
        &self,
        subnormals: Subnormals,
        f: impl FnOnce() -> Result<T, ReprError> + Send,
    ) -> Result<T, ReprError> {
        match subnormals {
            Subnormals::Kept if self.threads == 0 => f(),
            Subnormals::Kept => rayon::ThreadPoolBuilder::new()
                .num_threads(self.threads)
                .build()
                .map_err(|e| ReprError::InvalidInput(format!("training pool: {e}")))?
                .install(f),
            Subnormals::Flushed => ugl_kernels::flushing_pool(self.threads)
                .map_err(|e| ReprError::InvalidInput(e.to_string()))?
                .install(f),
        }
    }
}

impl std::fmt::Debug for FitContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FitContext")
            .field("progress", &self.progress.is_some())
            .field("checkpoint", &self.checkpoint)
            .field("threads", &self.threads)
            .field("log_file", &self.log_file)
            .field("messages", &self.messages.is_some())
            .field("image", &self.image)
            .finish()
    }
}

/// A representation learner (the UGL stage).
pub trait RepresentationLearner: Send + Sync {
    /// Name in results and on the command line (`pca`, `isomap`, ...).
    fn name(&self) -> &str;
    /// Fit on `images` with `latents` output dimensions. `rng` is the learner's own stream
    /// (initialisation, mini-batches, randomized solvers): same stream, same encoder.
    /// Returns the encoder and the encodings of the training images.
    fn fit(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError>;
    /// [`RepresentationLearner::fit`] with the harness's support ([`FitContext`]: progress,
    /// checkpoints, threads, a log). Same stream, same encoder, whatever the context. The
    /// default ignores the context.
    fn fit_in(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
        ctx: &FitContext,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        let _ = ctx;
        self.fit(images, latents, rng)
    }
    /// Whether its encoders are kept in the model cache ([`Encoder::save`] gives their bytes,
    /// [`RepresentationLearner::load`] reads them back). Learners whose fit is cheap or whose
    /// encoder is larger than a fit is slow (Isomap keeps the n x n geodesic matrix) say no.
    fn persists(&self) -> bool {
        false
    }
    /// An encoder from the bytes [`Encoder::save`] wrote under `key`; `Err` says why the bytes
    /// cannot be trusted (the harness fits again and overwrites them). A loaded encoder must
    /// encode bit-identically to the one that was saved.
    fn load(
        &self,
        key: &str,
        bytes: &[u8],
    ) -> Result<Box<dyn Encoder>, model_file::ModelFileError> {
        let _ = (key, bytes);
        Err(model_file::ModelFileError::NotKept {
            learner: self.name().to_string(),
        })
    }
    /// Whether its trainings save mid-training checkpoints ([`FitContext::checkpoint`]) that
    /// [`RepresentationLearner::load_checkpoint`] reads.
    fn saves_checkpoints(&self) -> bool {
        false
    }
    /// An encoder of a mid-training checkpoint's weights (`ugl embed --checkpoint`), with the
    /// loss curve so far; `Err` says why the weights cannot be read. The default: the learner's
    /// trainings save no checkpoints.
    fn load_checkpoint(
        &self,
        key: &str,
        checkpoint: &checkpoint::Inspected,
    ) -> Result<Box<dyn Encoder>, model_file::ModelFileError> {
        let _ = (key, checkpoint);
        Err(model_file::ModelFileError::NoCheckpoints {
            learner: self.name().to_string(),
        })
    }
}

/// Check the common preconditions of a fit.
pub fn check_fit_input(images: &ImageSet, latents: usize) -> Result<(), ReprError> {
    if latents == 0 {
        return Err(ReprError::InvalidInput("latents must be at least 1".into()));
    }
    if images.n < 2 {
        return Err(ReprError::InvalidInput(format!(
            "need at least 2 training images, got {}",
            images.n
        )));
    }
    if latents > images.dim || latents >= images.n {
        return Err(ReprError::InvalidInput(format!(
            "latents = {latents} must be below the number of images ({}) and at most the image size ({})",
            images.n, images.dim
        )));
    }
    if images.data.iter().any(|v| !v.is_finite()) {
        return Err(ReprError::InvalidInput(
            "training images contain a non-finite value".into(),
        ));
    }
    Ok(())
}

/// Check an encoder's output: right shape, finite.
/// Refuses training latents with a dimension that is the same for every training image: the
/// goal space has fewer dimensions than asked, and a KDE of the goals degenerates in it (an
/// external program's constant output; Isomap asked for more dimensions than its geodesic
/// kernel has positive eigenvalues).
pub fn check_no_constant_latent(z: &Latents, who: &str) -> Result<(), ReprError> {
    if z.n < 2 {
        return Ok(());
    }
    let constant: Vec<usize> = (0..z.latents)
        .filter(|&c| {
            let first = z.data[c];
            (1..z.n).all(|i| z.data[i * z.latents + c] == first)
        })
        .collect();
    if constant.is_empty() {
        return Ok(());
    }
    Err(ReprError::Numerical(format!(
        "{who}: {} of the {} latents are the same for all {} training images (dimension{} {}): \
         the goal space has only {} dimensions; ask for fewer latents",
        constant.len(),
        z.latents,
        z.n,
        if constant.len() == 1 { "" } else { "s" },
        constant
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        z.latents - constant.len()
    )))
}

pub fn check_latents(z: &Latents, who: &str) -> Result<(), ReprError> {
    if z.data.len() != z.n * z.latents {
        return Err(ReprError::Numerical(format!(
            "{who}: latents have {} values, expected {} x {}",
            z.data.len(),
            z.n,
            z.latents
        )));
    }
    if let Some(i) = z.data.iter().position(|v| !v.is_finite()) {
        return Err(ReprError::Numerical(format!(
            "{who}: non-finite latent (image {}, dimension {})",
            i / z.latents.max(1),
            i % z.latents.max(1)
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_latent_is_refused_and_named() {
        let varying = Latents {
            n: 3,
            latents: 2,
            data: vec![0.0, 1.0, 0.5, 2.0, 1.0, 3.0],
        };
        assert!(check_no_constant_latent(&varying, "x").is_ok());
        let constant = Latents {
            n: 3,
            latents: 2,
            data: vec![0.0, 7.0, 0.5, 7.0, 1.0, 7.0],
        };
        let e = check_no_constant_latent(&constant, "x")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("1 of the 2 latents") && e.contains("dimension 1"),
            "{e}"
        );
    }
}
