//! What an exploration run records: every outcome in order, the KL-coverage curve, and, for
//! modular exploration, the interest of every module over time.

use std::ops::Range;

use crate::env::{Environment, Rollout};
use crate::metrics::{CoverageHistogram, KlCoverage, moved};

/// The coverage measures of an environment: on the controllable object's outcome coordinates
/// ([`crate::env::EnvKind::metric_dims`]) and, where the scene has one, on the object the agent
/// cannot control ([`crate::env::EnvKind::control_dims`]). The controlled object lives in the
/// arm's reach (the paper's disk of 756 cells); the uncontrolled one, ArmBalls' distractor, walks
/// in [-0.95, 0.95]², so its measure counts all 900 cells of the square
/// ([`KlCoverage::whole_square`]): its cell coverage is the follow-up's exploration ratio.
pub(crate) struct Metrics {
    object: KlCoverage,
    object_dims: Range<usize>,
    control: Option<(KlCoverage, Range<usize>)>,
}

impl Metrics {
    pub fn for_env(env: &dyn Environment) -> Self {
        let kind = env.kind();
        let klc = |dims: &Range<usize>| {
            KlCoverage::new(dims.len()).expect("an object has 2 or 3 outcome coordinates")
        };
        let object_dims = kind.metric_dims();
        Metrics {
            object: klc(&object_dims),
            control: kind.control_dims().map(|d| (KlCoverage::whole_square(), d)),
            object_dims,
        }
    }
}

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
    /// KL-coverage and cell coverage of the uncontrollable object's outcomes (ArmBalls'
    /// distractor), a control; None where the scene has none.
    pub control: Option<(f64, f64)>,
    /// The follow-up's exploration ratios of the controlled object ([`FollowupRatios`]): the
    /// fraction of the cells of a 30 x 30 and of a 50 x 50 grid over the whole square [-1, 1]²
    /// that hold an outcome. Scenes with an uncontrollable object (ArmBalls) only; None
    /// elsewhere.
    pub ratios: Option<(f64, f64)>,
    /// The goal-reaching error of the controlled object's outcomes so far ([`GoalReach`]), the
    /// validated measure the report ranks by; scenes with an uncontrollable object (ArmBalls)
    /// only, None elsewhere.
    pub goal_error: Option<f64>,
}

/// The goal-reaching error along the curve: per test goal of [`ugl_types::GoalGrid`] (the
/// controlled object's position), the least squared distance to an outcome so far, updated
/// outcome by outcome. [`GoalReach::error`] is then the mean distance from a goal to its nearest
/// outcome, with the same arithmetic as `ugl_types::EnvMeasures::measure` (squared distances
/// summed coordinate by coordinate, the distances sorted before they are summed), so that it
/// equals the discovery measure of the outcomes up to that epoch bit for bit.
#[derive(Clone, Debug)]
pub(crate) struct GoalReach {
    goals: Vec<[f64; 2]>,
    best: Vec<f64>,
}

impl GoalReach {
    pub fn new() -> Self {
        let goals: Vec<[f64; 2]> = ugl_types::GoalGrid::new(2)
            .goals()
            .map(|g| [g[0], g[1]])
            .collect();
        GoalReach {
            best: vec![f64::INFINITY; goals.len()],
            goals,
        }
    }

    pub fn add(&mut self, x: f64, y: f64) {
        for (g, best) in self.goals.iter().zip(&mut self.best) {
            let (dx, dy) = (x - g[0], y - g[1]);
            let d2 = dx * dx + dy * dy;
            if d2 < *best {
                *best = d2;
            }
        }
    }

    /// The mean distance from a test goal to its nearest outcome (infinite before any).
    pub fn error(&self) -> f64 {
        let mut d: Vec<f64> = self.best.iter().map(|b| b.sqrt()).collect();
        d.sort_by(f64::total_cmp);
        d.iter().sum::<f64>() / d.len().max(1) as f64
    }
}

/// The follow-up paper's measure of exploration (Laversanne-Finot et al., CoRL 2018; its
/// `exploration_30`, and the 50-bin one beside it): the fraction of the cells of a `G x G` grid
/// over the whole square [-1, 1]² that hold at least one final position of the controlled
/// object, its cell `min(floor((v + 1) / 2 * G), G - 1)` per coordinate (clipped at 0). Unlike
/// [`Checkpoint::coverage`], every cell counts, also those outside the arm's disk that a pushed
/// ball reaches.
#[derive(Clone, Debug)]
pub(crate) struct FollowupRatios {
    grids: [(usize, Vec<bool>, usize); 2],
}

impl FollowupRatios {
    /// The grid sizes: 30 (the follow-up's figures) and 50.
    pub const BINS: [usize; 2] = [30, 50];

    pub fn new() -> Self {
        FollowupRatios {
            grids: Self::BINS.map(|g| (g, vec![false; g * g], 0)),
        }
    }

    /// The cell of `v` on a grid of `g` bins over [-1, 1].
    fn bin(v: f64, g: usize) -> usize {
        (((v + 1.0) / 2.0 * g as f64).floor().max(0.0) as usize).min(g - 1)
    }

    pub fn add(&mut self, x: f64, y: f64) {
        for (g, seen, n) in &mut self.grids {
            let cell = Self::bin(x, *g) * *g + Self::bin(y, *g);
            if !seen[cell] {
                seen[cell] = true;
                *n += 1;
            }
        }
    }

    /// The two ratios, 30 then 50 bins.
    pub fn ratios(&self) -> (f64, f64) {
        let r = |(g, _, n): &(usize, Vec<bool>, usize)| *n as f64 / (g * g) as f64;
        (r(&self.grids[0]), r(&self.grids[1]))
    }
}

/// The interest of one module at one point of a modular exploration (`explore::mge`).
#[derive(Clone, Debug, PartialEq)]
pub struct InterestPoint {
    /// Exploration iterations done.
    pub epoch: usize,
    /// Module index (0-based).
    pub module: usize,
    /// Its interest (|learning progress|; `explore::interest`).
    pub interest: f64,
    /// How many goals were chosen in it so far.
    pub n_chosen: usize,
}

/// Everything a run produced.
#[derive(Clone, Debug, PartialEq)]
pub struct ExplorationLog {
    /// Engineered outcome dimension.
    pub dim: usize,
    /// Engineered outcomes, in order (first `dim` entries meaningful).
    pub outcomes: Vec<[f64; 4]>,
    /// The iteration that produced each outcome (0 = warm-up).
    pub epochs: Vec<usize>,
    /// Whether each outcome moved the object (‖s − s₀‖ > 1e-3).
    pub moved: Vec<bool>,
    /// The curve.
    pub checkpoints: Vec<Checkpoint>,
    /// Iterations that used random parameters / goal babbling.
    pub n_random: usize,
    pub n_goal: usize,
    /// Modular exploration: the modules (name and goal-space coordinates) and their interest
    /// at every evaluation epoch; empty otherwise.
    pub modules: Vec<(String, Vec<usize>)>,
    pub interest: Vec<InterestPoint>,
}

/// Accumulates outcomes and evaluates the curve at the configured epochs.
pub(crate) struct Recorder<'k> {
    hist: CoverageHistogram<'k>,
    dims: Range<usize>,
    control: Option<(CoverageHistogram<'k>, Range<usize>)>,
    ratios: Option<FollowupRatios>,
    reach: Option<GoalReach>,
    initial: Vec<f64>,
    log: ExplorationLog,
    n_moved: usize,
    eval_at: Vec<usize>,
    next_eval: usize,
}

impl<'k> Recorder<'k> {
    pub fn new(
        metrics: &'k Metrics,
        initial: &[f64],
        eval_at: Vec<usize>,
        capacity: usize,
    ) -> Self {
        Recorder {
            hist: metrics.object.histogram(),
            dims: metrics.object_dims.clone(),
            control: metrics
                .control
                .as_ref()
                .map(|(k, d)| (k.histogram(), d.clone())),
            ratios: metrics.control.as_ref().map(|_| FollowupRatios::new()),
            reach: metrics.control.as_ref().map(|_| GoalReach::new()),
            initial: initial.to_vec(),
            log: ExplorationLog {
                dim: initial.len(),
                outcomes: Vec::with_capacity(capacity),
                epochs: Vec::with_capacity(capacity),
                moved: Vec::with_capacity(capacity),
                checkpoints: Vec::with_capacity(eval_at.len()),
                n_random: 0,
                n_goal: 0,
                modules: Vec::new(),
                interest: Vec::new(),
            },
            n_moved: 0,
            eval_at,
            next_eval: 0,
        }
    }

    /// Store the outcome of the episode run at `epoch`.
    pub fn push(&mut self, epoch: usize, r: &Rollout, random: bool) {
        let s = &r.outcome()[self.dims.clone()];
        // Outcomes are clipped rollouts: finite and of the right dimension by construction.
        self.hist
            .add(s)
            .expect("rollout outcome is finite and of the environment's dimension");
        if let Some((h, d)) = &mut self.control {
            h.add(&r.outcome()[d.clone()])
                .expect("rollout outcome is finite and of the environment's dimension");
        }
        if let Some(f) = &mut self.ratios {
            f.add(s[0], s[1]);
        }
        if let Some(g) = &mut self.reach {
            g.add(s[0], s[1]);
        }
        let m = moved(s, &self.initial[self.dims.clone()]);
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
                control: self.control.as_ref().map(|(h, _)| {
                    (
                        h.klc()
                            .expect("at least one outcome at an evaluation epoch"),
                        h.coverage(),
                    )
                }),
                ratios: self.ratios.as_ref().map(FollowupRatios::ratios),
                goal_error: self.reach.as_ref().map(GoalReach::error),
            });
            self.next_eval += 1;
        }
    }

    /// Whether the next [`Self::end_epoch`] of `epoch` evaluates the curve.
    pub fn evaluates_at(&self, epoch: usize) -> bool {
        self.eval_at.get(self.next_eval) == Some(&epoch)
    }

    /// Record the modules of a modular exploration.
    pub fn set_modules(&mut self, modules: Vec<(String, Vec<usize>)>) {
        self.log.modules = modules;
    }

    /// Record one module's interest.
    pub fn push_interest(&mut self, point: InterestPoint) {
        self.log.interest.push(point);
    }

    /// The log.
    pub fn finish(self) -> ExplorationLog {
        self.log
    }
}

#[cfg(test)]
mod tests {
    use super::{FollowupRatios, GoalReach};

    /// The error along the curve is the discovery measure of the outcomes so far, bit for bit:
    /// after each outcome of a spread, uneven set (pushed balls outside the disk included).
    #[test]
    fn the_goal_error_along_the_curve_is_the_discovery_measure() {
        let env = ugl_types::EnvMeasures::by_name("armballs-corl").unwrap();
        let mut reach = GoalReach::new();
        assert_eq!(reach.error(), f64::INFINITY);
        let mut outcomes = Vec::new();
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.4 - 1.2
        };
        for index in 0..300 {
            let (x, y) = (next(), 0.5 * next());
            reach.add(x, y);
            outcomes.push(ugl_types::Outcome {
                index,
                epoch: index,
                x,
                y,
                angle: None,
                moved: true,
            });
            if index % 37 == 0 || index == 299 {
                let d = env.measure(&outcomes, None).unwrap().unwrap();
                assert_eq!(
                    reach.error().to_bits(),
                    d.goal_error_mean.to_bits(),
                    "{index}"
                );
            }
        }
    }

    /// The follow-up's ratios count the cells of the whole square, each once, with the edges
    /// clipped into the grid: the same cells as `scripts/exploration_ratio.py`, which reproduces
    /// the authors' RPE ratio.
    #[test]
    fn followup_ratios_count_each_cell_of_the_whole_square_once() {
        let mut f = FollowupRatios::new();
        assert_eq!(f.ratios(), (0.0, 0.0));
        // The corners (outside the arm's disk, still cells of the square), twice each.
        for _ in 0..2 {
            f.add(-1.0, -1.0);
            f.add(1.0, 1.0);
            f.add(-1.2, 1.3);
        }
        assert_eq!(f.ratios(), (3.0 / 900.0, 3.0 / 2500.0));
        // 0.0 and 0.05 share a 30-bin cell ([0, 1/15)) but not a 50-bin one ([0, 0.04)).
        f.add(0.0, 0.0);
        f.add(0.05, 0.0);
        assert_eq!(f.ratios(), (4.0 / 900.0, 5.0 / 2500.0));
        assert_eq!(FollowupRatios::bin(-1.0, 30), 0);
        assert_eq!(FollowupRatios::bin(1.0, 30), 29);
        assert_eq!(FollowupRatios::bin(0.0, 30), 15);
        assert_eq!(FollowupRatios::bin(-0.01, 50), 24);
    }
}
