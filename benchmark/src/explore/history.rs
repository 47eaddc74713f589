//! What an exploration run records: every outcome in order, and the KL-coverage curve.

use crate::env::Rollout;
use crate::metrics::{CoverageHistogram, KlCoverage, moved};

/// One point of the exploration curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checkpoint {
    /// Exploration iterations done.
    pub epoch: usize,
    /// Outcomes stored so far.
    pub n_outcomes: usize,
    /// KL-coverage of those outcomes.
    pub klc: f64,
    /// Outcomes in which the object moved.
    pub n_moved: usize,
    /// Fraction of achievable cells reached.
    pub coverage: f64,
}

/// Everything a run produced.
#[derive(Clone, Debug, PartialEq)]
pub struct ExplorationLog {
    /// Engineered outcome dimension.
    pub dim: usize,
    /// Engineered outcomes, in order (first `dim` entries meaningful).
    pub outcomes: Vec<[f64; 3]>,
    /// The iteration that produced each outcome (0 = warm-up).
    pub epochs: Vec<usize>,
    /// Whether each outcome moved the object (‖s − s₀‖ > 1e-3).
    pub moved: Vec<bool>,
    /// The curve.
    pub checkpoints: Vec<Checkpoint>,
    /// Iterations that used random parameters / goal babbling.
    pub n_random: usize,
    pub n_goal: usize,
}

/// Accumulates outcomes and evaluates the curve at the configured epochs.
pub(crate) struct Recorder<'k> {
    hist: CoverageHistogram<'k>,
    initial: Vec<f64>,
    log: ExplorationLog,
    n_moved: usize,
    eval_at: Vec<usize>,
    next_eval: usize,
}

impl<'k> Recorder<'k> {
    pub fn new(klc: &'k KlCoverage, initial: &[f64], eval_at: Vec<usize>, capacity: usize) -> Self {
        Recorder {
            hist: klc.histogram(),
            initial: initial.to_vec(),
            log: ExplorationLog {
                dim: initial.len(),
                outcomes: Vec::with_capacity(capacity),
                epochs: Vec::with_capacity(capacity),
                moved: Vec::with_capacity(capacity),
                checkpoints: Vec::with_capacity(eval_at.len()),
                n_random: 0,
                n_goal: 0,
            },
            n_moved: 0,
            eval_at,
            next_eval: 0,
        }
    }

    /// Store the outcome of the episode run at `epoch`.
    pub fn push(&mut self, epoch: usize, r: &Rollout, random: bool) {
        let s = r.outcome();
        // Outcomes are clipped rollouts: finite and of the right dimension by construction.
        self.hist
            .add(s)
            .expect("rollout outcome is finite and of the environment's dimension");
        let m = moved(s, &self.initial);
        self.n_moved += m as usize;
        self.log.outcomes.push(r.state);
        self.log.epochs.push(epoch);
        self.log.moved.push(m);
        if epoch > 0 {
            if random {
                self.log.n_random += 1;
            } else {
                self.log.n_goal += 1;
            }
        }
    }

    /// Call after the iteration `epoch` has been stored.
    pub fn end_epoch(&mut self, epoch: usize) {
        while self.next_eval < self.eval_at.len() && self.eval_at[self.next_eval] == epoch {
            self.log.checkpoints.push(Checkpoint {
                epoch,
                n_outcomes: self.log.outcomes.len(),
                klc: self
                    .hist
                    .klc()
                    .expect("at least one outcome at an evaluation epoch"),
                n_moved: self.n_moved,
                coverage: self.hist.coverage(),
            });
            self.next_eval += 1;
        }
    }

    /// Whether some stored outcome differs from the initial state in every coordinate (the
    /// original's bootstrap test).
    pub fn finish(self) -> ExplorationLog {
        self.log
    }
}
