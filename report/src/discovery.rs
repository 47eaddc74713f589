//! Measures of what an exploration discovered that do not count repeats (issue 28, item 4).
//!
//! KL-coverage (paper Section 4.2) compares the histogram of *every* outcome with the uniform
//! distribution over the achievable cells, so each episode that leaves the object where it lay
//! adds weight to one cell: a run that moves the object more often scores better whatever it
//! found. Computed here from a run's outcomes file, next to it:
//!
//! - **KL-coverage of all outcomes**, re-implemented from `benchmark/src/metrics/klc.rs` (numpy
//!   `histogramdd` bins over [-1, 1], achievable cells = the (x, y) bins meeting the open unit
//!   disk times every other bin; KLC = Σ p ln(p / q), +inf when an outcome lies outside the
//!   achievable set). Its only role is to prove the re-implementation: it equals the runs' own
//!   `klc` (tests below).
//! - **KL-coverage of the moved outcomes only** (`moved`: the object moved in the episode), the
//!   same histogram and formula over the episodes that changed something.
//! - **Cell coverage**: the fraction of achievable cells holding at least one outcome (it
//!   equals the runs' `coverage`).
//! - **Goal-reaching error**: for a fixed grid of test goals spread over the achievable outcomes
//!   ([`GoalGrid`]), the distance from each goal to the nearest discovered outcome, i.e. the error
//!   of a nearest-neighbour inverse model on a deterministic environment (explauto's
//!   `Evaluation`, which tests an inverse model on a fixed set of goals; the original code's
//!   inverse-model error in `measures.py`). Mean and 90th percentile over the goals. Distances
//!   are Euclidean in the controllable object's outcome coordinates
//!   ([`ugl_types::EnvSpec::metric_dims`]), the angle in units of π like the KL-coverage bins
//!   it (not wrapped around).
//!
//! Everything is defined from the environment registry ([`ugl_types::EnvSpec`]: its objects and
//! KL-coverage grid), not from environment names, and a nearest-neighbour query goes through a
//! k-d tree, so the whole store is measured in seconds.

use std::fmt::Write as _;
use std::path::Path;

use ugl_types::EnvSpec;

use crate::ReportError;
use crate::campaigns::{Campaign, Campaigns};
use crate::load::{Outcome, Run};
use crate::output::Output;

/// Goal grid: position cells per axis over [-1, 1] (cells of 0.2; their centres inside the open
/// unit disk are the position goals: 80 of the 100).
pub const GOAL_POSITION_BINS: usize = 10;
/// Goal grid: cells per measured coordinate beyond the position (ArmArrow's angle: 6 angles,
/// the centres of cells of π/3).
pub const GOAL_OTHER_BINS: usize = 6;

/// Why a run cannot be measured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DiscoveryError {
    /// The run's environment is not in this build's registry.
    #[error("environment `{0}` is not in the registry")]
    UnknownEnv(String),
    /// A measured outcome coordinate is not one the outcomes file holds (`x`, `y`, `angle`).
    #[error(
        "environment `{env}`: outcome column `{column}` is not one of the outcomes file's x, y, angle"
    )]
    Column { env: String, column: String },
    /// The registry's grid is not of the form these measures know (the disk times full ranges).
    #[error("environment `{env}`: {why}")]
    Grid { env: String, why: String },
    /// An outcome lacks a measured coordinate (a null angle) or holds a NaN.
    #[error("outcome {index}: coordinate `{column}` is missing or NaN")]
    BadOutcome { index: i64, column: String },
}

/// Which field of an [`Outcome`] a measured coordinate is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Coord {
    X,
    Y,
    Angle,
}

impl Coord {
    fn name(self) -> &'static str {
        match self {
            Coord::X => "x",
            Coord::Y => "y",
            Coord::Angle => "angle",
        }
    }

    fn get(self, o: &Outcome) -> Option<f64> {
        match self {
            Coord::X => Some(o.x),
            Coord::Y => Some(o.y),
            Coord::Angle => o.angle,
        }
        .filter(|v| !v.is_nan())
    }
}

/// The KL-coverage histogram grid of an environment, as `benchmark/src/metrics/klc.rs` builds
/// it: `bins` per measured coordinate over [-1, 1]; the first two coordinates are the position,
/// whose achievable bins meet the open unit disk (exact integer test), every bin of the others
/// is achievable.
#[derive(Debug, Clone)]
pub struct Grid {
    dims: usize,
    bins: usize,
    edges: Vec<f64>,
    achievable: Vec<bool>,
    n_achievable: usize,
}

impl Grid {
    /// The grid of `spec`, checked against the number of achievable cells it declares.
    pub fn for_env(spec: &EnvSpec) -> Result<Self, DiscoveryError> {
        let bad = |why: String| DiscoveryError::Grid {
            env: spec.name.to_string(),
            why,
        };
        let (dims, bins) = (spec.klc.dims, spec.klc.bins);
        if dims < 2 || bins < 2 || bins % 2 != 0 {
            return Err(bad(format!(
                "a KL-coverage grid of {dims} coordinates and {bins} bins is not a disk grid"
            )));
        }
        let n_cells = bins
            .checked_pow(dims as u32)
            .filter(|&n| n <= 1 << 26)
            .ok_or_else(|| bad(format!("{bins}^{dims} cells is too many")))?;
        // np.linspace(-1, 1, bins + 1), as the runs' measure computes it.
        let step = 2.0 / bins as f64;
        let mut edges: Vec<f64> = (0..=bins).map(|i| i as f64 * step + -1.0).collect();
        edges[bins] = 1.0;
        let half = (bins / 2) as i64;
        let near = |i: usize| -> i64 {
            let (lo, hi) = (i as i64 - half, i as i64 - half + 1);
            if lo <= 0 && 0 <= hi {
                0
            } else {
                lo.abs().min(hi.abs())
            }
        };
        let per_pair = n_cells / (bins * bins);
        let mut achievable = Vec::with_capacity(n_cells);
        for ix in 0..bins {
            for iy in 0..bins {
                let (dx, dy) = (near(ix), near(iy));
                let ok = dx * dx + dy * dy < half * half;
                achievable.extend(std::iter::repeat_n(ok, per_pair));
            }
        }
        let n_achievable = achievable.iter().filter(|&&a| a).count();
        if n_achievable != spec.klc.achievable_cells {
            return Err(bad(format!(
                "the disk grid has {n_achievable} achievable cells, the registry declares {}",
                spec.klc.achievable_cells
            )));
        }
        Ok(Grid {
            dims,
            bins,
            edges,
            achievable,
            n_achievable,
        })
    }

    /// Achievable cells.
    pub fn n_achievable(&self) -> usize {
        self.n_achievable
    }

    /// Bin of one coordinate (numpy `histogramdd`: closed on the left, the last bin also on the
    /// right); None outside [-1, 1].
    fn bin(&self, v: f64) -> Option<usize> {
        if !(-1.0..=1.0).contains(&v) {
            return None;
        }
        if v == 1.0 {
            return Some(self.bins - 1);
        }
        Some(self.edges.partition_point(|&e| e <= v) - 1)
    }

    /// Cell of a point (C order); None outside [-1, 1]^dims.
    fn cell(&self, p: &[f64]) -> Option<usize> {
        let mut idx = 0;
        for &v in p {
            idx = idx * self.bins + self.bin(v)?;
        }
        Some(idx)
    }
}

/// A histogram of outcomes over a [`Grid`].
struct Histogram<'g> {
    grid: &'g Grid,
    counts: Vec<u32>,
    touched: Vec<usize>,
    total: u64,
    outside: u64,
    reached: usize,
}

impl<'g> Histogram<'g> {
    fn new(grid: &'g Grid) -> Self {
        Histogram {
            grid,
            counts: vec![0; grid.achievable.len()],
            touched: Vec::new(),
            total: 0,
            outside: 0,
            reached: 0,
        }
    }

    fn add(&mut self, p: &[f64]) {
        self.total += 1;
        match self.grid.cell(p) {
            None => self.outside += 1,
            Some(c) => {
                if !self.grid.achievable[c] {
                    self.outside += 1;
                }
                if self.counts[c] == 0 {
                    self.touched.push(c);
                    if self.grid.achievable[c] {
                        self.reached += 1;
                    }
                }
                self.counts[c] += 1;
            }
        }
    }

    /// KL(visited ‖ uniform on achievable), summed in cell order as the runs' measure does;
    /// +inf with an outcome outside the achievable set; None without outcomes.
    fn klc(&self) -> Option<f64> {
        if self.total == 0 {
            return None;
        }
        if self.outside > 0 {
            return Some(f64::INFINITY);
        }
        let n = self.total as f64;
        let q = 1.0 / self.grid.n_achievable as f64;
        let mut cells = self.touched.clone();
        cells.sort_unstable();
        Some(cells.iter().fold(0.0, |s, &c| {
            let p = self.counts[c] as f64 / n;
            s + p * (p / q).ln()
        }))
    }

    fn coverage(&self) -> f64 {
        self.reached as f64 / self.grid.n_achievable as f64
    }
}

/// The fixed test goals of an environment: the centres of a coarser grid's cells
/// ([`GOAL_POSITION_BINS`] per position axis, kept when inside the open unit disk, times
/// [`GOAL_OTHER_BINS`] centres per further measured coordinate), x-major. Deterministic, from
/// the registry's grid alone.
#[derive(Debug, Clone)]
pub struct GoalGrid {
    dims: usize,
    /// Flattened, `dims` per goal.
    goals: Vec<f64>,
}

impl GoalGrid {
    /// The goals of an environment whose KL-coverage grid measures `dims` coordinates (≥ 2).
    pub fn new(dims: usize) -> Self {
        let centre = |i: usize, n: usize| -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
        let mut goals = Vec::new();
        let others = GOAL_OTHER_BINS.pow(dims.saturating_sub(2) as u32);
        for ix in 0..GOAL_POSITION_BINS {
            for iy in 0..GOAL_POSITION_BINS {
                let (x, y) = (
                    centre(ix, GOAL_POSITION_BINS),
                    centre(iy, GOAL_POSITION_BINS),
                );
                if x * x + y * y >= 1.0 {
                    continue;
                }
                for mut k in 0..others {
                    goals.extend([x, y]);
                    let mut rest = vec![0.0; dims.saturating_sub(2)];
                    for r in rest.iter_mut().rev() {
                        *r = centre(k % GOAL_OTHER_BINS, GOAL_OTHER_BINS);
                        k /= GOAL_OTHER_BINS;
                    }
                    goals.extend(rest);
                }
            }
        }
        GoalGrid { dims, goals }
    }

    /// Number of goals.
    pub fn len(&self) -> usize {
        self.goals.len() / self.dims.max(1)
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.goals.is_empty()
    }

    /// The goals, `dims` coordinates each.
    pub fn goals(&self) -> impl Iterator<Item = &[f64]> {
        self.goals.chunks_exact(self.dims.max(1))
    }
}

/// A static k-d tree over points of `dims` coordinates (median splits, cycling axes), for the
/// nearest-neighbour distance of each goal.
struct KdTree<'p> {
    dims: usize,
    points: &'p [f64],
    /// Point indices in tree order: the node of `lo..hi` is its middle.
    order: Vec<usize>,
}

impl<'p> KdTree<'p> {
    fn new(points: &'p [f64], dims: usize) -> Self {
        let mut order: Vec<usize> = (0..points.len() / dims).collect();
        Self::build(points, dims, &mut order, 0);
        KdTree {
            dims,
            points,
            order,
        }
    }

    fn build(points: &[f64], dims: usize, idx: &mut [usize], depth: usize) {
        if idx.len() <= 1 {
            return;
        }
        let axis = depth % dims;
        let mid = idx.len() / 2;
        idx.select_nth_unstable_by(mid, |&a, &b| {
            points[a * dims + axis].total_cmp(&points[b * dims + axis])
        });
        let (left, right) = idx.split_at_mut(mid);
        Self::build(points, dims, left, depth + 1);
        Self::build(points, dims, &mut right[1..], depth + 1);
    }

    fn point(&self, i: usize) -> &[f64] {
        &self.points[i * self.dims..(i + 1) * self.dims]
    }

    /// Distance from `q` to the nearest point; None for an empty tree.
    fn nearest(&self, q: &[f64]) -> Option<f64> {
        if self.order.is_empty() {
            return None;
        }
        let mut best = f64::INFINITY;
        self.search(q, 0, self.order.len(), 0, &mut best);
        Some(best.sqrt())
    }

    fn search(&self, q: &[f64], lo: usize, hi: usize, depth: usize, best: &mut f64) {
        if lo >= hi {
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let p = self.point(self.order[mid]);
        let d2: f64 = p.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum();
        if d2 < *best {
            *best = d2;
        }
        let axis = depth % self.dims;
        let diff = q[axis] - p[axis];
        let (near, far) = if diff < 0.0 {
            ((lo, mid), (mid + 1, hi))
        } else {
            ((mid + 1, hi), (lo, mid))
        };
        self.search(q, near.0, near.1, depth + 1, best);
        if diff * diff < *best {
            self.search(q, far.0, far.1, depth + 1, best);
        }
    }
}

/// The measures of one environment: its grid, its goals and which outcome fields it measures.
#[derive(Debug, Clone)]
pub struct EnvMeasures {
    coords: Vec<Coord>,
    grid: Grid,
    goals: GoalGrid,
}

/// What a run discovered up to an epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct Discovery {
    /// Outcomes up to the epoch.
    pub n_outcomes: usize,
    /// Those in which the object moved.
    pub n_moved: usize,
    /// KL-coverage of every outcome (the runs' own `klc`, recomputed).
    pub klc: f64,
    /// KL-coverage of the moved outcomes only; None when the object never moved.
    pub moved_klc: Option<f64>,
    /// Fraction of the achievable cells reached.
    pub coverage: f64,
    /// Mean distance from a test goal to the nearest outcome.
    pub goal_error_mean: f64,
    /// 90th percentile of those distances (linear interpolation between order statistics).
    pub goal_error_p90: f64,
}

impl EnvMeasures {
    /// The measures of `spec`: its controllable object's coordinates, its KL-coverage grid and
    /// the goal grid of that many coordinates.
    pub fn new(spec: &EnvSpec) -> Result<Self, DiscoveryError> {
        let coords = spec
            .metric_dims()
            .map(|i| match spec.outcome_columns.get(i).copied() {
                Some("x") => Ok(Coord::X),
                Some("y") => Ok(Coord::Y),
                Some("angle") => Ok(Coord::Angle),
                other => Err(DiscoveryError::Column {
                    env: spec.name.to_string(),
                    column: other.unwrap_or("?").to_string(),
                }),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let grid = Grid::for_env(spec)?;
        if coords.len() != grid.dims {
            return Err(DiscoveryError::Grid {
                env: spec.name.to_string(),
                why: format!(
                    "the grid measures {} coordinates, the controllable objects have {}",
                    grid.dims,
                    coords.len()
                ),
            });
        }
        let goals = GoalGrid::new(grid.dims);
        Ok(EnvMeasures {
            coords,
            grid,
            goals,
        })
    }

    /// The measures of the environment called `env`.
    pub fn by_name(env: &str) -> Result<Self, DiscoveryError> {
        let spec = EnvSpec::by_name(env).ok_or_else(|| DiscoveryError::UnknownEnv(env.into()))?;
        Self::new(spec)
    }

    /// The test goals.
    pub fn goals(&self) -> &GoalGrid {
        &self.goals
    }

    /// The KL-coverage grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The measures of `outcomes` whose epoch is at most `epoch` (every outcome with None).
    /// None when there is no such outcome.
    pub fn measure(
        &self,
        outcomes: &[Outcome],
        epoch: Option<i64>,
    ) -> Result<Option<Discovery>, DiscoveryError> {
        let d = self.coords.len();
        let mut points = Vec::with_capacity(outcomes.len() * d);
        let mut all = Histogram::new(&self.grid);
        let mut moved = Histogram::new(&self.grid);
        let mut p = vec![0.0; d];
        for o in outcomes
            .iter()
            .filter(|o| epoch.is_none_or(|e| o.epoch <= e))
        {
            for (v, c) in p.iter_mut().zip(&self.coords) {
                *v = c.get(o).ok_or_else(|| DiscoveryError::BadOutcome {
                    index: o.index,
                    column: c.name().to_string(),
                })?;
            }
            all.add(&p);
            if o.moved {
                moved.add(&p);
            }
            points.extend_from_slice(&p);
        }
        let Some(klc) = all.klc() else {
            return Ok(None);
        };
        let tree = KdTree::new(&points, d);
        let mut errors: Vec<f64> = self.goals.goals().filter_map(|g| tree.nearest(g)).collect();
        errors.sort_by(f64::total_cmp);
        Ok(Some(Discovery {
            n_outcomes: all.total as usize,
            n_moved: moved.total as usize,
            klc,
            moved_klc: moved.klc(),
            coverage: all.coverage(),
            goal_error_mean: errors.iter().sum::<f64>() / errors.len().max(1) as f64,
            goal_error_p90: quantile_sorted(&errors, 0.9).unwrap_or(f64::NAN),
        }))
    }
}

/// The `q` quantile of sorted values, linear interpolation between order statistics (numpy's
/// default); None when empty.
pub fn quantile_sorted(sorted: &[f64], q: f64) -> Option<f64> {
    let n = sorted.len();
    if n == 0 {
        return None;
    }
    let pos = q.clamp(0.0, 1.0) * (n - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    Some(sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64))
}

/// The median of values (sorted copy); None when empty.
pub fn median(v: &[f64]) -> Option<f64> {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    quantile_sorted(&s, 0.5)
}

/// The measures of a run at its final epoch (None: a run without outcomes).
pub fn measure_run(run: &Run) -> Result<Option<Discovery>, DiscoveryError> {
    EnvMeasures::by_name(&run.key.env)?.measure(&run.outcomes, None)
}

/// The goal-reaching error of an exploration that never moved the object: every outcome at the
/// object's resting position (read from an outcome of `run` that did not move it). The
/// leaderboard's unit for the error, as `ln(cells)` is KL-coverage's: 1 is "never moved the
/// object", 0 "reached every test goal". None when every outcome of the run moved it.
pub fn error_at_rest(run: &Run) -> Option<f64> {
    let rest = run.outcomes.iter().find(|o| !o.moved)?;
    let d = EnvMeasures::by_name(&run.key.env)
        .ok()?
        .measure(std::slice::from_ref(rest), None)
        .ok()??;
    Some(d.goal_error_mean)
}

// ---------------------------------------------------------------------------------------------
// Every run of the report, measured; the validity check.

/// The validity check's threshold: a learned goal space *encodes the object's position* when
/// the held-out k-NN R² of the position from its latents (`latent_quality`, group `position`)
/// is at least this.
pub const POSITION_R2: f64 = 0.99;

/// Learners whose goal space is a random projection of the image (a control, whatever its
/// latent quality): the external random projection and the Rust `gaussian-projection`.
pub const RANDOM_PROJECTIONS: &[&str] = &["random-projection", "gaussian-projection"];

/// The side of the validity check a run is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Group {
    /// The goal space encodes the object's position: RGE-EFR, or a learned space with
    /// position k-NN R² ≥ [`POSITION_R2`] whose network (if any) left the plateau.
    Encodes,
    /// A control: a random projection, or a network that stayed on the plateau (`trained` is
    /// false in its training evidence: the untrained twins of `paper-init`).
    Control,
}

impl Group {
    /// Its name in the data file.
    pub fn name(self) -> &'static str {
        match self {
            Group::Encodes => "encodes-position",
            Group::Control => "control",
        }
    }
}

/// The group of a run, None for runs in neither (RPE, learned spaces below the threshold).
pub fn group_of(run: &Run) -> Option<Group> {
    let m = &run.manifest;
    if m.learner
        .as_deref()
        .is_some_and(|l| RANDOM_PROJECTIONS.contains(&l))
        || m.trained() == Some(false)
    {
        return Some(Group::Control);
    }
    if run.key.algo == "rge-efr" {
        return Some(Group::Encodes);
    }
    m.group_r2("position")
        .filter(|&(_, knn)| knn >= POSITION_R2)
        .map(|_| Group::Encodes)
}

/// One run, measured.
#[derive(Debug, Clone)]
pub struct RunRow<'a> {
    pub campaign: &'a Campaign,
    pub run: &'a Run,
    /// Its measures at the final epoch (None: no outcomes).
    pub discovery: Option<Discovery>,
    pub group: Option<Group>,
    /// Whether the validity check reads it: runs of the main, `compare` and `recipe`
    /// campaigns (the main campaign's cells and seeds); not the budget or follow-up ones.
    pub in_check: bool,
    /// ln(achievable cells): the moved-only KLC of a run that never moved the object.
    pub max_klc: f64,
}

/// Every run the report reads, measured at its final epoch: the main campaign, then by role
/// ([`Campaigns::used`]), runs in the report's condition order.
pub fn measure_all(camps: &Campaigns) -> Result<Vec<RunRow<'_>>, ReportError> {
    let checked: Vec<&str> = std::iter::once(&camps.main)
        .chain(&camps.compare)
        .chain(&camps.recipe)
        .map(|c| c.name.as_str())
        .collect();
    let mut rows = Vec::new();
    for camp in camps.used() {
        let mut runs: Vec<&Run> = camp.store.runs.iter().collect();
        runs.sort_by(|a, b| {
            (a.key.order_key(), a.seed, &a.run_id).cmp(&(b.key.order_key(), b.seed, &b.run_id))
        });
        for run in runs {
            let invalid = |e: DiscoveryError| ReportError::Invalid {
                path: run.outcomes_path.clone(),
                problem: e.to_string(),
            };
            let env = EnvMeasures::by_name(&run.key.env).map_err(invalid)?;
            rows.push(RunRow {
                campaign: camp,
                run,
                discovery: env.measure(&run.outcomes, None).map_err(invalid)?,
                group: group_of(run),
                in_check: checked.contains(&camp.name.as_str()),
                max_klc: (env.grid.n_achievable as f64).ln(),
            });
        }
    }
    Ok(rows)
}

/// A measure of the validity check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Measure {
    /// The runs' own final KL-coverage.
    FinalKlc,
    /// KL-coverage of the moved outcomes (ln N for a run that never moved the object).
    MovedKlc,
    /// Fraction of achievable cells reached.
    Coverage,
    /// Mean goal-reaching error.
    GoalErrorMean,
    /// 90th-percentile goal-reaching error.
    GoalErrorP90,
}

impl Measure {
    /// Every measure, in the table's order.
    pub const ALL: [Measure; 5] = [
        Measure::FinalKlc,
        Measure::MovedKlc,
        Measure::Coverage,
        Measure::GoalErrorMean,
        Measure::GoalErrorP90,
    ];

    /// Its name in the report.
    pub fn label(self) -> &'static str {
        match self {
            Measure::FinalKlc => "final KLC (all outcomes)",
            Measure::MovedKlc => "KLC of moved outcomes",
            Measure::Coverage => "cells reached",
            Measure::GoalErrorMean => "goal error, mean",
            Measure::GoalErrorP90 => "goal error, 90th pct",
        }
    }

    /// Whether less is better (KL-coverage, error) or more (cells).
    pub fn lower_is_better(self) -> bool {
        !matches!(self, Measure::Coverage)
    }

    /// Its value for a measured run.
    pub fn value(self, row: &RunRow<'_>) -> Option<f64> {
        let d = row.discovery.as_ref();
        match self {
            Measure::FinalKlc => Some(row.run.final_point().klc),
            Measure::MovedKlc => d.map(|d| d.moved_klc.unwrap_or(row.max_klc)),
            Measure::Coverage => d.map(|d| d.coverage),
            Measure::GoalErrorMean => d.map(|d| d.goal_error_mean),
            Measure::GoalErrorP90 => d.map(|d| d.goal_error_p90),
        }
    }
}

/// One line of the validity check: a measure in an environment, the position-encoding runs
/// against the controls.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    pub measure: Measure,
    pub env: String,
    /// Values of the position-encoding runs and of the controls.
    pub encodes: Vec<f64>,
    pub control: Vec<f64>,
    pub encodes_median: f64,
    pub control_median: f64,
    /// P(a random position-encoding run is better than a random control), ties counted half
    /// (the common-language effect size of the Mann-Whitney U).
    pub p_better: f64,
    /// The median of the position-encoding runs is strictly better than the controls'.
    pub passes: bool,
}

/// The validity check: per environment with runs in both groups, and per measure, whether the
/// median over the position-encoding runs beats the median over the controls.
pub fn validity(rows: &[RunRow<'_>]) -> Vec<Check> {
    let mut envs: Vec<&str> = rows
        .iter()
        .filter(|r| r.in_check && r.group.is_some())
        .map(|r| r.run.key.env.as_str())
        .collect();
    envs.sort_by_key(|e| (EnvSpec::order(e), e.to_string()));
    envs.dedup();
    let mut out = Vec::new();
    for env in envs {
        for m in Measure::ALL {
            let values = |g: Group| -> Vec<f64> {
                rows.iter()
                    .filter(|r| r.in_check && r.group == Some(g) && r.run.key.env == env)
                    .filter_map(|r| m.value(r))
                    .collect()
            };
            let (encodes, control) = (values(Group::Encodes), values(Group::Control));
            let (Some(em), Some(cm)) = (median(&encodes), median(&control)) else {
                continue;
            };
            let better = |a: f64, b: f64| {
                if m.lower_is_better() { a < b } else { a > b }
            };
            let mut wins = 0.0;
            for &a in &encodes {
                for &b in &control {
                    wins += if better(a, b) {
                        1.0
                    } else if a == b {
                        0.5
                    } else {
                        0.0
                    };
                }
            }
            out.push(Check {
                measure: m,
                env: env.to_string(),
                p_better: wins / (encodes.len() * control.len()) as f64,
                passes: better(em, cm),
                encodes,
                control,
                encodes_median: em,
                control_median: cm,
            });
        }
    }
    out
}

/// The data file, under the report's `data/`.
pub const FILE: &str = "discovery_by_run.csv";

/// A float as CSV: shortest round-trip form, `inf`; empty when absent.
fn num(v: Option<f64>) -> String {
    v.map(|v| format!("{v}")).unwrap_or_default()
}

/// `data/discovery_by_run.csv`: one row per measured run.
pub fn write_csv(out: &mut Output, rows: &[RunRow<'_>]) -> Result<(), ReportError> {
    let mut s = String::from(
        "campaign,run_id,env,algo,sampler,latents,variant,seed,trained,position_knn_r2,group,\
         n_outcomes,n_moved,final_klc,moved_klc,coverage,goal_error_mean,goal_error_p90\n",
    );
    for r in rows {
        let run = r.run;
        let d = r.discovery.as_ref();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            if r.campaign.name.is_empty() {
                "."
            } else {
                &r.campaign.name
            },
            run.run_id,
            run.key.env,
            run.key.algo,
            run.key.sampler,
            run.key.latents,
            run.key.variant,
            run.seed,
            run.manifest
                .trained()
                .map(|t| t.to_string())
                .unwrap_or_default(),
            num(run.manifest.group_r2("position").map(|g| g.1)),
            r.group.map(Group::name).unwrap_or_default(),
            d.map(|d| d.n_outcomes.to_string()).unwrap_or_default(),
            d.map(|d| d.n_moved.to_string()).unwrap_or_default(),
            num(Some(run.final_point().klc)),
            num(d.and_then(|d| d.moved_klc)),
            num(d.map(|d| d.coverage)),
            num(d.map(|d| d.goal_error_mean)),
            num(d.map(|d| d.goal_error_p90)),
        );
    }
    out.write(Path::new(crate::data::DIR).join(FILE), s.as_bytes())?;
    Ok(())
}

/// The report's section: what the measures are, and the validity table.
pub fn section(w: &mut String, rows: &[RunRow<'_>], checks: &[Check]) {
    let _ = writeln!(
        w,
        "\n## What the exploration discovered, without counting repeats\n\n\
         KL-coverage scores the histogram of *every* outcome, so each episode that leaves the \
         object in place adds weight to one cell, and a goal space that moves the object more \
         often scores better whatever it found. Three measures that do not count repeats, \
         computed from each run's outcomes file (`data/{FILE}`, one row per run):\n\n\
         - **KLC of moved outcomes**: the same 30-bin histogram and formula (paper Section 4.2) \
         over the episodes in which the object moved (ln N, every outcome in one cell, for a run \
         that never moved it). The re-implementation reproduces the runs' own KLC exactly on \
         all outcomes.\n\
         - **cells reached**: the fraction of achievable cells holding an outcome.\n\
         - **goal-reaching error**: the distance from each of a fixed grid of test goals to the \
         nearest outcome, the error of a nearest-neighbour inverse model on a deterministic \
         environment (explauto's `Evaluation`; the original code's inverse-model error); mean \
         and 90th percentile. The goals are the centres of a {GOAL_POSITION_BINS} × \
         {GOAL_POSITION_BINS} grid over [-1, 1]² inside the unit disk, times {GOAL_OTHER_BINS} \
         angles where the angle is measured ({} goals for ArmBall, {} for ArmArrow), in the \
         controllable object's coordinates (the angle in units of π, not wrapped).\n",
        GoalGrid::new(2).len(),
        GoalGrid::new(3).len(),
    );
    let n = |g: Group| {
        rows.iter()
            .filter(|r| r.in_check && r.group == Some(g))
            .count()
    };
    let _ = writeln!(
        w,
        "**Validity check.** A measure of discovery must rank goal spaces that encode the \
         object's position ({} runs: RGE-EFR, and learned spaces with held-out position k-NN \
         R² ≥ {POSITION_R2}) ahead of the controls ({} runs: the random projection, and \
         networks that stayed on the plateau, such as the untrained twins of the recipe \
         campaigns), in the main, compare and recipe campaigns, every goal sampler. A measure \
         passes in an environment when the median over the first group is better than the \
         median over the controls; *P(better)* is the probability that a random \
         position-encoding run beats a random control (ties half): near 0.5 the measure does not \
         tell the groups apart, even where its median passes. A measure that fails is no \
         measure of discovery, and no verdict should rest on it alone.\n",
        n(Group::Encodes),
        n(Group::Control),
    );
    let _ = writeln!(
        w,
        "| measure | env | better | encodes position: runs, median | controls: runs, median | \
         P(better) | check |\n|---|---|---|---|---|---|---|"
    );
    for c in checks {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {}, {:.3} | {}, {:.3} | {:.2} | {} |",
            c.measure.label(),
            EnvSpec::display_of(&c.env),
            if c.measure.lower_is_better() {
                "lower"
            } else {
                "higher"
            },
            c.encodes.len(),
            c.encodes_median,
            c.control.len(),
            c.control_median,
            c.p_better,
            if c.passes { "passes" } else { "**fails**" },
        );
    }
    w.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use std::path::PathBuf;

    fn results() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/results")
    }

    #[test]
    fn the_grids_follow_the_registry() {
        let ball = EnvMeasures::by_name("armball").unwrap();
        let arrow = EnvMeasures::by_name("armarrow").unwrap();
        let balls = EnvMeasures::by_name("armballs").unwrap();
        assert_eq!(ball.grid().n_achievable(), 756);
        assert_eq!(arrow.grid().n_achievable(), 22_680);
        assert_eq!(balls.coords, [Coord::X, Coord::Y], "the ball only");
        assert_eq!((ball.goals().len(), arrow.goals().len()), (80, 480));
        for g in arrow.goals().goals() {
            assert!(g[0] * g[0] + g[1] * g[1] < 1.0 && g[2].abs() < 1.0, "{g:?}");
        }
        assert!(matches!(
            EnvMeasures::by_name("nope"),
            Err(DiscoveryError::UnknownEnv(_))
        ));
        static ODD: EnvSpec = EnvSpec {
            name: "odd-grid",
            klc: ugl_types::KlcGrid {
                dims: 2,
                bins: 30,
                achievable_cells: 900,
            },
            ..ugl_types::ARMBALL
        };
        assert!(matches!(
            EnvMeasures::new(&ODD),
            Err(DiscoveryError::Grid { .. })
        ));
    }

    fn outcome(index: i64, x: f64, y: f64, moved: bool) -> Outcome {
        Outcome {
            index,
            epoch: index,
            x,
            y,
            angle: None,
            moved,
        }
    }

    #[test]
    fn repeats_weigh_on_klc_not_on_the_other_measures() {
        let env = EnvMeasures::by_name("armball").unwrap();
        let mut few = vec![outcome(0, 0.0, 0.5, false)];
        few.extend((1..10).map(|i| outcome(i, 0.5 - 0.1 * i as f64, 0.0, true)));
        let mut many = few.clone();
        many.extend((10..200).map(|i| outcome(i, 0.0, 0.5, false)));
        let (a, b) = (
            env.measure(&few, None).unwrap().unwrap(),
            env.measure(&many, None).unwrap().unwrap(),
        );
        assert!(b.klc > a.klc + 1.0, "{} {}", a.klc, b.klc);
        assert_eq!((a.moved_klc, a.coverage), (b.moved_klc, b.coverage));
        assert_eq!(
            (a.goal_error_mean, a.goal_error_p90),
            (b.goal_error_mean, b.goal_error_p90)
        );
        // An epoch cut keeps the outcomes up to it; none at all is None, no panic.
        assert_eq!(env.measure(&many, Some(0)).unwrap().unwrap().n_outcomes, 1);
        assert_eq!(env.measure(&[], None).unwrap(), None);
        assert_eq!(
            env.measure(&[outcome(0, 0.0, 0.0, false)], None)
                .unwrap()
                .unwrap()
                .moved_klc,
            None
        );
        let e = env
            .measure(&[outcome(3, f64::NAN, 0.0, true)], None)
            .unwrap_err();
        assert_eq!(
            e,
            DiscoveryError::BadOutcome {
                index: 3,
                column: "x".into()
            }
        );
        let arrow = EnvMeasures::by_name("armarrow").unwrap();
        assert!(arrow.measure(&few, None).is_err(), "a null angle");
        // Outside the disk: +inf, as the runs' measure.
        let out = env
            .measure(&[outcome(0, 0.99, 0.99, true)], None)
            .unwrap()
            .unwrap();
        assert_eq!(out.klc, f64::INFINITY);
    }

    #[test]
    fn the_kd_tree_finds_the_brute_force_nearest_point() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for dims in [2, 3] {
            for n in [1, 2, 5, 300] {
                let pts: Vec<f64> = (0..n * dims).map(|_| rng.random_range(-1.0..1.0)).collect();
                let tree = KdTree::new(&pts, dims);
                for _ in 0..200 {
                    let q: Vec<f64> = (0..dims).map(|_| rng.random_range(-1.2..1.2)).collect();
                    let brute = pts
                        .chunks_exact(dims)
                        .map(|p| {
                            p.iter()
                                .zip(&q)
                                .map(|(a, b)| (a - b) * (a - b))
                                .sum::<f64>()
                        })
                        .fold(f64::INFINITY, f64::min)
                        .sqrt();
                    assert_eq!(tree.nearest(&q), Some(brute));
                }
            }
        }
        assert_eq!(KdTree::new(&[], 2).nearest(&[0.0, 0.0]), None);
    }

    #[test]
    fn quantiles_interpolate_like_numpy() {
        let v = [1.0, 2.0, 3.0, 4.0, 10.0];
        assert_eq!(quantile_sorted(&v, 0.5), Some(3.0));
        assert!((quantile_sorted(&v, 0.9).unwrap() - 7.6).abs() < 1e-12);
        assert_eq!(quantile_sorted(&[], 0.9), None);
        assert_eq!(median(&[4.0, 1.0]), Some(2.5));
    }

    /// The re-implemented KL-coverage and cell coverage equal what the runs recorded, at every
    /// evaluation epoch and in the manifest's summary, on runs of every environment.
    #[test]
    fn the_klc_on_all_outcomes_equals_the_runs_own() {
        let stems = [
            "paper/armball.rge-efr.s0",
            "paper/armball.rpe.s1",
            "paper/armball.rge-vae.faithful.kde.l10.s2",
            "paper/armarrow.rge-efr.s3",
            "paper/armarrow.rge-pca.kde.l3.s4",
            "compare-random-projection/armarrow.rge-external.kde.l3.s0",
            "paper-init/armball.rge-ae.kde.l2.s0",
            "armballs/armballs.rpe.s0",
            "armballs/armballs.mge-bvae-flat.gaussian.l10.s0",
        ];
        for stem in stems {
            let path = results().join(stem);
            let camp = stem.split('/').next().unwrap_or_default().to_string();
            let run = crate::load::load_run(&path, camp).unwrap_or_else(|e| panic!("{stem}: {e}"));
            let env = EnvMeasures::by_name(&run.key.env).unwrap();
            let fin = measure_run(&run).unwrap().unwrap();
            let summary = &run.manifest.summary;
            assert_eq!(fin.klc, summary.final_klc, "{stem}");
            assert_eq!(fin.coverage, summary.coverage, "{stem}");
            assert_eq!(fin.n_moved, summary.n_moved, "{stem}");
            for p in &run.curve {
                let d = env.measure(&run.outcomes, Some(p.epoch)).unwrap().unwrap();
                assert_eq!(d.klc, p.klc, "{stem} epoch {}", p.epoch);
                assert_eq!(d.coverage, p.coverage, "{stem} epoch {}", p.epoch);
                assert_eq!(
                    d.n_outcomes as i64, p.n_outcomes,
                    "{stem} epoch {}",
                    p.epoch
                );
            }
            println!(
                "{stem}: klc {} moved-only {:?} coverage {} goal error {} / {}",
                fin.klc, fin.moved_klc, fin.coverage, fin.goal_error_mean, fin.goal_error_p90
            );
        }
    }

    /// The validity check on the committed results: every measure that does not count repeats
    /// ranks the position-encoding goal spaces ahead of the controls in both paper
    /// environments, with P(better) ≥ 0.8; the runs' own final KLC fails at ArmArrow and
    /// passes at ArmBall only by its median, at P(better) ≈ 0.5, a coin flip (issue 28: it
    /// mostly counts moves).
    #[test]
    fn the_validity_check_on_the_committed_results() {
        let camps = crate::campaigns::load_campaigns(
            &results(),
            "paper",
            &crate::sections::wanted_roles(crate::sections::SECTIONS),
        )
        .unwrap();
        let t = std::time::Instant::now();
        let rows = measure_all(&camps).unwrap();
        println!("measured {} runs in {:.2?}", rows.len(), t.elapsed());
        let checks = validity(&rows);
        let mut table = String::new();
        section(&mut table, &rows, &checks);
        println!("{table}");
        let verdict = |m: Measure, env: &str| {
            checks
                .iter()
                .find(|c| c.measure == m && c.env == env)
                .unwrap_or_else(|| panic!("no check of {m:?} in {env}"))
                .passes
        };
        for env in ["armball", "armarrow"] {
            for m in Measure::ALL {
                let expected = EXPECTED
                    .iter()
                    .find(|e| e.0 == m && e.1 == env)
                    .map(|e| e.2);
                assert_eq!(Some(verdict(m, env)), expected, "{m:?} in {env}");
            }
        }
        for c in &checks {
            if c.measure == Measure::FinalKlc {
                assert!((0.4..0.6).contains(&c.p_better), "{c:?}");
            } else {
                assert!(
                    c.p_better >= 0.8,
                    "{:?} in {}: {}",
                    c.measure,
                    c.env,
                    c.p_better
                );
            }
        }
        // The groups: ArmBall 76 position-encoding runs against 103 controls (10 random
        // projections, 93 networks on the plateau); ArmArrow 93 against 100.
        let count = |env: &str, g: Group| {
            rows.iter()
                .filter(|r| r.in_check && r.group == Some(g) && r.run.key.env == env)
                .count()
        };
        assert_eq!(
            [
                count("armball", Group::Encodes),
                count("armball", Group::Control),
                count("armarrow", Group::Encodes),
                count("armarrow", Group::Control)
            ],
            [76, 103, 93, 100]
        );
    }

    /// What the committed data show (measure, environment, passes).
    const EXPECTED: &[(Measure, &str, bool)] = &[
        (Measure::FinalKlc, "armball", true),
        (Measure::MovedKlc, "armball", true),
        (Measure::Coverage, "armball", true),
        (Measure::GoalErrorMean, "armball", true),
        (Measure::GoalErrorP90, "armball", true),
        (Measure::FinalKlc, "armarrow", false),
        (Measure::MovedKlc, "armarrow", true),
        (Measure::Coverage, "armarrow", true),
        (Measure::GoalErrorMean, "armarrow", true),
        (Measure::GoalErrorP90, "armarrow", true),
    ];
}
