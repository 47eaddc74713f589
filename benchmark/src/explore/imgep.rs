//! Random goal exploration (RGE; paper Appendix D, Algorithm 3, with the code's details of
//! docs/original-code.md section 3).
//!
//! One warm-up random episode, then `epochs` iterations. An iteration uses random parameters
//! while no stored outcome differs from the initial state in every coordinate, while fewer than
//! two distinct outcome encodings are stored, during the first `bootstrap_epochs` iterations, or
//! with probability `random_ratio` (drawn only when the previous tests are false, a short-circuit
//! `or` as in the original); otherwise it samples a goal, takes the parameters of the nearest
//! stored outcome encoding, and perturbs them.

use super::history::{ExplorationLog, Metrics, Recorder};
use super::meta_policy::{perturb, random_params};
use super::nn::NnIndex;
use super::{ExploreConfig, ExploreError, Explorer};
use crate::env::Environment;
use crate::goals::GoalSampler;
use crate::repr::{Encoder, ReprError};
use crate::seed::{Component, stream};
use rand::RngExt;

/// Maps an episode's final object state to its encoding in the goal space.
pub trait OutcomeSpace {
    /// Goal-space dimension.
    fn dim(&self) -> usize;
    /// Encode the engineered outcome `state` into `out` (length `dim`).
    fn encode(&mut self, state: &[f64], out: &mut [f64]);
    /// A distance of this space in the units of the follow-up's code, whose competence caps
    /// distances at 2 (`explore::interest`): the engineered features there are the state in
    /// [-1, 1], while [`EngineeredSpace`] holds `(s + 1) / 2` and so halves distances (2); a
    /// learned space's latents and the mixed features are in the same units as theirs (1).
    fn competence_scale(&self) -> f64 {
        1.0
    }
}

/// The engineered goal space of RGE-EFR: z = (s + 1) / 2 in [0,1]^d, over every outcome
/// coordinate or over some of them (the position-only space).
#[derive(Clone, Debug)]
pub struct EngineeredSpace {
    /// The outcome coordinates kept, in order.
    dims: Vec<usize>,
}

impl EngineeredSpace {
    /// For outcomes of dimension `dim`.
    pub fn new(dim: usize) -> Self {
        EngineeredSpace::of((0..dim).collect())
    }

    /// Over the outcome coordinates `dims` only.
    pub fn of(dims: Vec<usize>) -> Self {
        EngineeredSpace { dims }
    }
}

impl OutcomeSpace for EngineeredSpace {
    fn dim(&self) -> usize {
        self.dims.len()
    }
    fn competence_scale(&self) -> f64 {
        2.0
    }
    fn encode(&mut self, state: &[f64], out: &mut [f64]) {
        for (o, &k) in out.iter_mut().zip(&self.dims) {
            *o = (state[k] + 1.0) / 2.0;
        }
    }
}

/// A learned goal space (RGE-REP, docs/original-code.md section 3): the outcome is encoded as
/// `encoder(render(final state))`. Measures the time spent encoding.
pub struct LearnedSpace<'a> {
    env: &'a dyn Environment,
    encoder: &'a mut dyn Encoder,
    image: Vec<f32>,
    /// Seconds spent rendering and encoding outcomes.
    pub encode_s: f64,
    /// The first encoder error, if any (the run is then reported as failed).
    pub error: Option<ReprError>,
}

impl<'a> LearnedSpace<'a> {
    /// Encode outcomes of `env` with `encoder`.
    pub fn new(env: &'a dyn Environment, encoder: &'a mut dyn Encoder) -> Self {
        LearnedSpace {
            env,
            encoder,
            image: vec![0.0; env.image_len()],
            encode_s: 0.0,
            error: None,
        }
    }
}

impl OutcomeSpace for LearnedSpace<'_> {
    fn dim(&self) -> usize {
        self.encoder.latents()
    }
    fn encode(&mut self, state: &[f64], out: &mut [f64]) {
        let t0 = std::time::Instant::now();
        self.env.render_into(state, &mut self.image);
        let r = self.encoder.encode_one(&self.image, out).and_then(|_| {
            if out.iter().all(|v| v.is_finite()) {
                Ok(())
            } else {
                Err(ReprError::Numerical(format!(
                    "encoder returned a non-finite latent for state {state:?}"
                )))
            }
        });
        if let Err(e) = r {
            // Keep the explorer running on a defined value; the caller reports the error.
            out.fill(0.0);
            self.error.get_or_insert(e);
        }
        self.encode_s += t0.elapsed().as_secs_f64();
    }
}

/// Run RGE in the goal space `space` with goals from `sampler`.
pub fn run_rge(
    env: &dyn Environment,
    space: &mut dyn OutcomeSpace,
    sampler: &mut dyn GoalSampler,
    cfg: &ExploreConfig,
    run_seed: u64,
) -> ExplorationLog {
    assert_eq!(
        space.dim(),
        sampler.dim(),
        "goal sampler and outcome space dimensions differ"
    );
    let metrics = Metrics::for_env(env);
    let mut rec = Recorder::new(
        &metrics,
        env.initial_state(),
        cfg.eval_epochs(),
        cfg.epochs + 1,
    );
    let mut params_rng = stream(run_seed, Component::Params);
    let mut choice_rng = stream(run_seed, Component::ExploreChoice);
    let mut goal_rng = stream(run_seed, Component::Goals);
    let mut noise_rng = stream(run_seed, Component::Noise);

    let mut h = History::new(env, space.dim(), cfg.epochs + 1, run_seed);
    let mut goal = vec![0.0; space.dim()];

    // Warm-up episode.
    let theta = random_params(&mut params_rng, env.param_dim());
    h.store(env, space, &mut rec, theta, 0, true);
    rec.end_epoch(0);

    for i in 0..cfg.epochs {
        let epoch = i + 1;
        let random = !h.ever_moved
            || h.index.n_distinct() < 2
            || i < cfg.bootstrap_epochs
            || choice_rng.random::<f64>() < cfg.random_ratio;
        let theta = if random {
            random_params(&mut params_rng, env.param_dim())
        } else {
            sampler.sample(&mut goal_rng, &mut goal);
            let (j, _) = h.index.nearest(&goal).expect("history is not empty");
            perturb(h.theta(j), cfg.noise_sigma, &mut noise_rng)
        };
        h.store(env, space, &mut rec, theta, epoch, random);
        rec.end_epoch(epoch);
    }
    rec.finish()
}

/// RGE as an [`Explorer`]: in `space`, with goals from `sampler`.
pub struct Rge<'a> {
    pub space: &'a mut dyn OutcomeSpace,
    pub sampler: Box<dyn GoalSampler>,
}

impl Explorer for Rge<'_> {
    fn explore(
        &mut self,
        env: &dyn Environment,
        cfg: &ExploreConfig,
        run_seed: u64,
    ) -> Result<ExplorationLog, ExploreError> {
        Ok(run_rge(
            env,
            self.space,
            self.sampler.as_mut(),
            cfg,
            run_seed,
        ))
    }
}

/// The explorer's memory: parameters and outcome encodings, with the nearest-neighbour index
/// (also the base of modular exploration's memory, `mge.rs`).
pub(crate) struct History {
    pub index: NnIndex,
    /// The motor parameters of every episode, one after the other ([`History::theta`]).
    thetas: Vec<f64>,
    /// Motor parameters per episode.
    param_dim: usize,
    /// The encoding of the last stored outcome.
    pub z: Vec<f64>,
    /// The controllable object's initial state ([`crate::env::EnvKind::metric_dims`]).
    initial: Vec<f64>,
    /// Some outcome differs from the initial state in every coordinate of the controllable
    /// object.
    pub ever_moved: bool,
    /// The environment's own stream (ArmBalls' distractor).
    env_rng: crate::seed::Stream,
}

impl History {
    /// An empty memory for a goal space of dimension `dim`.
    pub fn new(env: &dyn Environment, dim: usize, capacity: usize, run_seed: u64) -> Self {
        History {
            index: NnIndex::new(dim),
            thetas: Vec::with_capacity(capacity * env.param_dim()),
            param_dim: env.param_dim(),
            z: vec![0.0; dim],
            initial: env.initial_state()[env.kind().metric_dims()].to_vec(),
            ever_moved: false,
            env_rng: stream(run_seed, Component::Distractor),
        }
    }

    /// The motor parameters of episode `j`.
    pub fn theta(&self, j: usize) -> &[f64] {
        &self.thetas[j * self.param_dim..(j + 1) * self.param_dim]
    }

    /// Run `theta`, encode and store its outcome (its encoding is then in `z`).
    pub fn store(
        &mut self,
        env: &dyn Environment,
        space: &mut dyn OutcomeSpace,
        rec: &mut Recorder,
        theta: Vec<f64>,
        epoch: usize,
        random: bool,
    ) {
        let r = env.rollout(&theta, &mut self.env_rng);
        let s = r.outcome();
        self.ever_moved |= s[env.kind().metric_dims()]
            .iter()
            .zip(&self.initial)
            .all(|(a, b)| a != b);
        space.encode(s, &mut self.z);
        self.index.insert(&self.z);
        self.thetas.extend_from_slice(&theta);
        rec.push(epoch, &r, random);
    }
}
