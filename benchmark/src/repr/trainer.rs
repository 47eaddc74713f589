//! The training loop of the dense neural learners: batches drawn from the learner stream, one
//! optimiser step per iteration, on burn's engine or the host engine; resumable from a
//! checkpoint.

use std::path::Path;
use std::sync::Arc;

use burn::module::Module as _;
use burn::optim::{GradientsParams, ModuleOptimizer};
use burn::tensor::Device;
use rand::RngExt;

use super::host_train::{HostOptimizer, HostTrainer};
use super::nets::{DenseNet, HostNet, TfAdagrad, TfAdam};
use super::neural_config::{Engine, Model, NeuralConfig, training_device};
use super::neural_model::{LatentInput, Optimiser, StepInput, tensor2};
use super::{ImageSet, ReprError, check_fit_input};
use crate::seed::Stream;

/// Progress of a training run, reported after every iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrainProgress {
    /// Iterations done (1-based).
    pub iteration: usize,
    /// Iterations in all.
    pub total: usize,
    /// The loss of this iteration's mini-batch.
    pub loss: f64,
}

/// A progress callback (e.g. driving an indicatif bar).
pub type ProgressFn = Arc<dyn Fn(TrainProgress) + Send + Sync>;

/// The initial weights of `model` (a function of the stream only; the variant plays no part).
pub fn init_net(
    model: Model,
    cfg: &NeuralConfig,
    dim: usize,
    latents: usize,
    rng: &mut Stream,
) -> HostNet {
    HostNet::init(
        rng,
        cfg.init,
        dim,
        cfg.hidden,
        latents,
        &model.head_blocks(latents),
    )
}

/// Draw the mini-batch: the first `k` entries of a fresh uniform permutation of `perm`'s
/// contents (partial Fisher-Yates; `perm` keeps the shuffled order between calls, which does not
/// bias the next draw).
pub fn draw_batch(perm: &mut [usize], k: usize, rng: &mut Stream) {
    let n = perm.len();
    for i in 0..k.min(n) {
        let j = rng.random_range(i..n);
        perm.swap(i, j);
    }
}

/// The engine-specific part of a [`Trainer`]: the weights and the optimiser state.
pub(crate) enum EngineState {
    Burn(Box<BurnState>),
    Host(Box<HostTrainer>),
}

/// burn's module and optimiser on its device.
pub(crate) struct BurnState {
    device: Device,
    net: Option<DenseNet>,
    opt: ModuleOptimizer,
}

/// A training run in progress: the weights, their optimiser and the batch sampler. [`train`]
/// drives it; the `train_step` bench times [`Trainer::step`].
pub struct Trainer<'a> {
    pub model: Model,
    pub cfg: NeuralConfig,
    images: &'a ImageSet,
    latents: usize,
    state: EngineState,
    perm: Vec<usize>,
    xbuf: Vec<f32>,
    /// Iterations done.
    pub step: usize,
}

impl<'a> Trainer<'a> {
    /// Validate, draw the initial weights from `rng` and set up the engine.
    pub fn new(
        model: Model,
        cfg: &NeuralConfig,
        images: &'a ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<Self, ReprError> {
        cfg.validate(model, model.name())?;
        check_fit_input(images, latents)?;
        let host = init_net(model, cfg, images.dim, latents, rng);
        let state = match cfg.engine {
            Engine::Burn => {
                let device = training_device();
                EngineState::Burn(Box::new(BurnState {
                    net: Some(host.to_module(&device)),
                    device,
                    opt: optimizer(model),
                }))
            }
            Engine::Host => {
                let opt = HostOptimizer::new(model, &host);
                EngineState::Host(Box::new(HostTrainer::new(host, opt)))
            }
        };
        Ok(Self::assemble(
            model,
            cfg,
            images,
            latents,
            state,
            (0..images.n).collect(),
            0,
        ))
    }

    fn assemble(
        model: Model,
        cfg: &NeuralConfig,
        images: &'a ImageSet,
        latents: usize,
        state: EngineState,
        perm: Vec<usize>,
        step: usize,
    ) -> Self {
        let k = cfg.batch.min(images.n);
        Trainer {
            model,
            cfg: cfg.clone(),
            images,
            latents,
            state,
            perm,
            xbuf: vec![0.0; k * images.dim],
            step,
        }
    }

    /// One iteration: batch, noise, forward, loss, backward, optimiser step. Returns the
    /// mini-batch loss (checked finite).
    pub fn step(&mut self, rng: &mut Stream) -> Result<f64, ReprError> {
        let dim = self.images.dim;
        let k = self.xbuf.len() / dim;
        draw_batch(&mut self.perm, k, rng);
        for (row, &i) in self.xbuf.chunks_exact_mut(dim).zip(&self.perm[..k]) {
            row.copy_from_slice(self.images.row(i));
        }
        let value = match &mut self.state {
            EngineState::Host(host) => {
                host.step(self.model, &self.cfg, &self.xbuf, k, self.step, rng)?
            }
            EngineState::Burn(burn) => {
                let BurnState { device, net, opt } = &mut **burn;
                let x = tensor2(self.xbuf.clone(), k, dim, device);
                let module = net.take().expect("the module is present between steps");
                let code = self.cfg.code_at(self.model, self.step);
                let input = StepInput {
                    x,
                    latent: LatentInput {
                        batch: k,
                        latents: self.latents,
                        step: self.step,
                        code,
                        device,
                    },
                };
                let loss = self.model.spec().loss(&module, input, rng);
                let value = f64::from(loss.clone().into_scalar::<f32>());
                if value.is_finite() {
                    let grads = GradientsParams::from_grads(loss.backward(), &module);
                    *net = Some(opt.step(self.cfg.lr, module, grads));
                } else {
                    *net = Some(module);
                }
                value
            }
        };
        if !value.is_finite() {
            return Err(ReprError::Numerical(format!(
                "{} training diverged at iteration {}: loss = {value}",
                self.model.name(),
                self.step
            )));
        }
        self.step += 1;
        Ok(value)
    }

    /// The state a checkpoint keeps besides the weights and the optimiser: parameter ids (the
    /// burn optimiser's state is keyed by them; zeros on the host engine) and the batch
    /// permutation.
    pub fn resume_state(&self) -> ([u64; 12], &[usize]) {
        let ids = match &self.state {
            EngineState::Burn(burn) => burn
                .net
                .as_ref()
                .expect("the module is present between steps")
                .param_ids(),
            EngineState::Host(_) => [0; 12],
        };
        (ids, &self.perm)
    }

    /// Save the optimiser's state (burn's record format, or [`HostOptimizer::to_bytes`]).
    pub fn save_optimizer(&self, path: &Path) -> Result<(), ReprError> {
        let fail =
            |e: String| ReprError::Io(format!("saving optimiser state {}: {e}", path.display()));
        match &self.state {
            EngineState::Burn(burn) => burn.opt.save(path).map_err(|e| fail(format!("{e:?}"))),
            EngineState::Host(host) => crate::fsio::write_atomic(path, &host.opt.to_bytes())
                .map_err(|e| fail(e.to_string())),
        }
    }

    /// A trainer continuing from a checkpoint: weights `net` with parameter ids `ids`, the
    /// optimiser state in `optimizer`, the batch permutation and the iterations done. The
    /// caller restores the stream's position.
    pub fn resume(
        model: Model,
        cfg: &NeuralConfig,
        images: &'a ImageSet,
        latents: usize,
        state: ResumeState<'_>,
    ) -> Result<Self, ReprError> {
        cfg.validate(model, model.name())?;
        check_fit_input(images, latents)?;
        if state.perm.len() != images.n
            || state.net.dim != images.dim
            || state.net.latents != latents
            || state.net.hidden != cfg.hidden
        {
            return Err(ReprError::InvalidInput(
                "checkpoint does not match the training".into(),
            ));
        }
        let fail = |e: String| {
            ReprError::Io(format!(
                "loading optimiser state {}: {e}",
                state.optimizer.display()
            ))
        };
        let engine = match cfg.engine {
            Engine::Burn => {
                let device = training_device();
                let net = state.net.to_module_with_ids(&device, state.ids);
                let opt = optimizer(model)
                    .load(state.optimizer)
                    .map_err(|e| fail(format!("{e:?}")))?;
                EngineState::Burn(Box::new(BurnState {
                    device,
                    net: Some(net),
                    opt,
                }))
            }
            Engine::Host => {
                let bytes = std::fs::read(state.optimizer).map_err(|e| fail(e.to_string()))?;
                let opt = HostOptimizer::from_bytes(model, state.net, &bytes)
                    .map_err(|e| fail(e.to_string()))?;
                EngineState::Host(Box::new(HostTrainer::new(state.net.clone(), opt)))
            }
        };
        Ok(Self::assemble(
            model,
            cfg,
            images,
            latents,
            engine,
            state.perm.to_vec(),
            state.step,
        ))
    }

    /// The current weights on the host.
    pub fn host_net(&self) -> Result<HostNet, ReprError> {
        match &self.state {
            EngineState::Burn(burn) => {
                let net = burn
                    .net
                    .as_ref()
                    .expect("the module is present between steps")
                    .valid();
                HostNet::from_module(&net, self.images.dim, self.cfg.hidden, self.latents)
            }
            EngineState::Host(host) => Ok(host.net.clone()),
        }
    }
}

/// The original's optimiser of `model`: Adagrad for the AE, Adam for the VAE and RFVAE.
pub(crate) fn optimizer(model: Model) -> ModuleOptimizer {
    match model.spec().optimiser() {
        Optimiser::Adagrad => TfAdagrad::default().into(),
        Optimiser::Adam => TfAdam::default().into(),
    }
}

/// What [`Trainer::resume`] continues from.
pub struct ResumeState<'s> {
    pub net: &'s HostNet,
    pub ids: &'s [u64; 12],
    pub optimizer: &'s Path,
    pub perm: &'s [usize],
    pub step: usize,
}
