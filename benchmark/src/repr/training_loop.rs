//! The training loop shared by the networks (the dense [`Trainer`], the convolutional
//! trainings of `conv_learner.rs`): iterations until a target, the loss curve, checkpoints and
//! progress.

use super::ReprError;
use super::checkpoint::CheckpointSpec;
use super::trainer::{ProgressFn, TrainProgress, Trainer};
use crate::seed::Stream;

/// A training that advances one iteration at a time and can be checkpointed (the dense
/// networks' [`Trainer`], the convolutional ones'): what [`run_until`] drives.
pub(crate) trait Iterations {
    /// Iterations done.
    fn done(&self) -> usize;
    /// One iteration; its mini-batch loss, checked finite.
    fn iterate(&mut self, rng: &mut Stream) -> Result<f64, ReprError>;
    /// Save a checkpoint of the state after [`Iterations::done`] iterations.
    fn checkpoint(
        &self,
        c: &CheckpointSpec,
        rng: &Stream,
        losses: &[(usize, f64)],
    ) -> Result<(), ReprError>;
}

impl Iterations for Trainer<'_> {
    fn done(&self) -> usize {
        self.step
    }
    fn iterate(&mut self, rng: &mut Stream) -> Result<f64, ReprError> {
        self.step(rng)
    }
    fn checkpoint(
        &self,
        c: &CheckpointSpec,
        rng: &Stream,
        losses: &[(usize, f64)],
    ) -> Result<(), ReprError> {
        super::checkpoint::save(c, self, rng, losses)
    }
}

/// Train until `target` iterations are done: the loss recorded every `log_every` iterations
/// and at the last, a checkpoint every `ckpt.every` iterations (never at `target`: what
/// follows keeps that), the progress after every iteration.
pub(crate) fn run_until(
    training: &mut impl Iterations,
    target: usize,
    log_every: usize,
    rng: &mut Stream,
    losses: &mut Vec<(usize, f64)>,
    ckpt: Option<&CheckpointSpec>,
    progress: Option<&ProgressFn>,
) -> Result<(), ReprError> {
    for step in training.done()..target {
        let value = training.iterate(rng)?;
        if step % log_every == 0 || step + 1 == target {
            losses.push((step, value));
        }
        if let Some(c) = ckpt
            && c.every > 0
            && (step + 1) % c.every == 0
            && step + 1 < target
        {
            training.checkpoint(c, rng, losses)?;
        }
        if let Some(p) = progress {
            p(TrainProgress {
                iteration: step + 1,
                total: target,
                loss: value,
            });
        }
    }
    Ok(())
}
