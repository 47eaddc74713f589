//! What an exploration discovered, measured from its outcomes without counting repeats (the
//! report's "exploration measures"; `docs/statistics.md`).
//!
//! KL-coverage (paper Section 4.2) compares the histogram of *every* outcome with the uniform
//! distribution over the achievable cells, so each episode that leaves the object where it lay
//! adds weight to one cell: a run that moves the object more often scores better whatever it
//! found. Beside it:
//!
//! - **KL-coverage of all outcomes**, the explorer's own measure ([`crate::klc`]: numpy
//!   `histogramdd` bins over [-1, 1], achievable cells = the (x, y) bins meeting the open unit
//!   disk times every other bin; KLC = Σ p ln(p / q), +inf when an outcome lies outside the
//!   achievable set), computed again from the outcomes: it equals the runs' recorded `klc` at
//!   every evaluation epoch (the report's tests).
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
//!   ([`crate::EnvSpec::metric_dims`]), the angle in units of π like the KL-coverage bins
//!   it (not wrapped around).
//!
//! A run measures itself when it ends and records the result in its manifest
//! ([`RunDiscovery`], `Manifest::discovery`, results version 4 on), so that its outcomes file,
//! the largest of its files, need not be kept; the report measures older runs from their
//! outcomes files with the same code.
//!
//! Everything is defined from the environment registry ([`crate::EnvSpec`]: its objects and
//! KL-coverage grid), not from environment names, and a nearest-neighbour query goes through a
//! k-d tree, so a whole store is measured in seconds.

use serde::{Deserialize, Serialize};

use crate::env::EnvSpec;
use crate::klc::{KlCoverage, KlcError};
use crate::nn::NnIndex;

/// One outcome of an exploration (a row of `<run_id>.outcomes.parquet`): the controllable
/// object's state at the end of an episode.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    pub index: i64,
    pub epoch: i64,
    pub x: f64,
    pub y: f64,
    pub angle: Option<f64>,
    pub moved: bool,
}

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

/// The KL-coverage grid of `spec` ([`KlCoverage::disk`]), checked against the number of
/// achievable cells the registry declares.
fn grid_for_env(spec: &EnvSpec) -> Result<KlCoverage, DiscoveryError> {
    let grid =
        KlCoverage::disk(spec.klc.dims, spec.klc.bins).map_err(|e| DiscoveryError::Grid {
            env: spec.name.to_string(),
            why: e.to_string(),
        })?;
    if grid.n_achievable() != spec.klc.achievable_cells {
        return Err(DiscoveryError::Grid {
            env: spec.name.to_string(),
            why: format!(
                "the disk grid has {} achievable cells, the registry declares {}",
                grid.n_achievable(),
                spec.klc.achievable_cells
            ),
        });
    }
    Ok(grid)
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

/// The measures of one environment: its grid, its goals and which outcome fields it measures.
#[derive(Debug, Clone)]
pub struct EnvMeasures {
    coords: Vec<Coord>,
    grid: KlCoverage,
    goals: GoalGrid,
}

/// What a run discovered up to an epoch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Discovery {
    /// Outcomes up to the epoch.
    pub n_outcomes: usize,
    /// Those in which the object moved.
    pub n_moved: usize,
    /// KL-coverage of every outcome (the runs' own `klc`, recomputed); +inf is written "inf".
    #[serde(with = "crate::summary::inf_as_string")]
    pub klc: f64,
    /// KL-coverage of the moved outcomes only; None when the object never moved.
    #[serde(with = "crate::summary::opt_inf_as_string")]
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
        let grid = grid_for_env(spec)?;
        if coords.len() != grid.dim() {
            return Err(DiscoveryError::Grid {
                env: spec.name.to_string(),
                why: format!(
                    "the grid measures {} coordinates, the controllable objects have {}",
                    grid.dim(),
                    coords.len()
                ),
            });
        }
        let goals = GoalGrid::new(grid.dim());
        Ok(EnvMeasures {
            coords,
            grid,
            goals,
        })
    }

    /// The same measures on the position (the first two measured coordinates) alone: the
    /// disk grid of the environment's bins per axis and the position goals. None where the
    /// environment measures nothing beyond the position.
    pub fn position(&self, spec: &EnvSpec) -> Result<Option<Self>, DiscoveryError> {
        if self.coords.len() <= 2 {
            return Ok(None);
        }
        Ok(Some(EnvMeasures {
            coords: self.coords[..2].to_vec(),
            grid: KlCoverage::disk(2, spec.klc.bins).map_err(|e| DiscoveryError::Grid {
                env: spec.name.to_string(),
                why: e.to_string(),
            })?,
            goals: GoalGrid::new(2),
        }))
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
    pub fn grid(&self) -> &KlCoverage {
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
        let mut all = self.grid.histogram();
        let mut moved = self.grid.histogram();
        // The coordinates are checked above (no NaN, as many as the grid's): the histogram
        // cannot refuse them.
        let klc_error = |e: KlcError| DiscoveryError::Grid {
            env: "?".into(),
            why: e.to_string(),
        };
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
            all.add(&p).map_err(klc_error)?;
            if o.moved {
                moved.add(&p).map_err(klc_error)?;
            }
            points.extend_from_slice(&p);
        }
        let klc = match all.klc() {
            Ok(k) => k,
            Err(KlcError::Empty) => return Ok(None),
            Err(e) => return Err(klc_error(e)),
        };
        // No NaN reaches the tree: KL-coverage refused it above.
        let mut tree = NnIndex::new(d);
        for p in points.chunks_exact(d) {
            tree.insert(p);
        }
        let mut errors: Vec<f64> = self
            .goals
            .goals()
            .filter_map(|g| tree.nearest(g).map(|(_, d2)| d2.sqrt()))
            .collect();
        errors.sort_by(f64::total_cmp);
        Ok(Some(Discovery {
            n_outcomes: all.total() as usize,
            n_moved: moved.total() as usize,
            klc,
            moved_klc: moved.klc().ok(),
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

/// What a run discovered by its end, as its manifest records it (`Manifest::discovery`): the
/// measures of every outcome ([`Discovery`]) and the two numbers the report derives from the
/// outcomes beside them. Computed by [`RunDiscovery::measure`] from the outcomes in memory when
/// the run ends, or by the report from an older run's outcomes file: the same code, the same
/// numbers (the outcomes file stores the f64 values exactly).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunDiscovery {
    /// The measures of every outcome, at the run's last epoch.
    #[serde(rename = "final")]
    pub at_end: Discovery,
    /// The goal-reaching error of an exploration that never moved the object: every outcome at
    /// the object's resting position (that of the first outcome that did not move it). The
    /// leaderboard's unit for the error, as `ln(cells)` is KL-coverage's. None when every
    /// outcome moved the object.
    pub error_at_rest: Option<f64>,
    /// Mean distance from the origin of the positions (x, y) of the outcomes that moved the
    /// object (how far out the exploration pushed it); None when none did.
    pub moved_radius_mean: Option<f64>,
    /// Where the environment measures more than the object's position (ArmArrow's angle): the
    /// same measures on the position alone (2-D cells of the disk, the position goals), so that
    /// what an exploration found of the position and of the rest can be told apart. Absent
    /// (None) for the other environments, and in records written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<Discovery>,
}

impl RunDiscovery {
    /// The measures of a run's `outcomes` (in history order) in the environment `spec`; None
    /// for a run without outcomes.
    pub fn measure(spec: &EnvSpec, outcomes: &[Outcome]) -> Result<Option<Self>, DiscoveryError> {
        let env = EnvMeasures::new(spec)?;
        let Some(at_end) = env.measure(outcomes, None)? else {
            return Ok(None);
        };
        let error_at_rest = match outcomes.iter().find(|o| !o.moved) {
            Some(rest) => env
                .measure(std::slice::from_ref(rest), None)?
                .map(|d| d.goal_error_mean),
            None => None,
        };
        let radii: Vec<f64> = outcomes
            .iter()
            .filter(|o| o.moved)
            .map(|o| libm::hypot(o.x, o.y))
            .collect();
        let moved_radius_mean =
            (!radii.is_empty()).then(|| radii.iter().sum::<f64>() / radii.len() as f64);
        let position = match env.position(spec)? {
            Some(p) => p.measure(outcomes, None)?,
            None => None,
        };
        Ok(Some(RunDiscovery {
            at_end,
            error_at_rest,
            moved_radius_mean,
            position,
        }))
    }
}

/// Why a recorded [`RunDiscovery`] cannot be what the run measured: a value out of its range, a
/// count or measure that disagrees with the run's summary or with itself, or, where the outcomes
/// file is kept, with the measures recomputed from it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("its discovery record is not what the run measured: {field} {why}")]
pub struct RecordMismatch {
    /// The record's field (`final.coverage`, `error_at_rest`, ...).
    pub field: String,
    pub why: String,
}

/// Relative tolerance of a recorded measure against the same measure computed again (the
/// summary's, or the outcomes file's): the same code gives the same bits, this only absorbs a
/// last-bit difference of an older build.
const RECORD_TOLERANCE: f64 = 1e-9;

fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= RECORD_TOLERANCE * a.abs().max(b.abs())
}

impl Discovery {
    /// Each field in its range: counts ordered, KL-coverages non-negative (+inf allowed),
    /// coverage a fraction, goal errors finite, non-negative and at most `max_error`, a moved-only
    /// KL-coverage exactly when the object moved.
    fn check_ranges(&self, at: &str, max_error: f64) -> Result<(), RecordMismatch> {
        let bad = |field: &str, why: String| {
            Err(RecordMismatch {
                field: format!("{at}.{field}"),
                why,
            })
        };
        if self.n_outcomes == 0 || self.n_moved > self.n_outcomes {
            return bad(
                "n_moved",
                format!("{} of {} outcomes", self.n_moved, self.n_outcomes),
            );
        }
        if self.klc.is_nan() || self.klc < 0.0 {
            return bad("klc", format!("= {} is not a KL-coverage (>= 0)", self.klc));
        }
        match self.moved_klc {
            Some(k) if k.is_nan() || k < 0.0 || self.n_moved == 0 => {
                return bad(
                    "moved_klc",
                    format!("= {k} with {} moved outcomes", self.n_moved),
                );
            }
            None if self.n_moved > 0 => {
                return bad(
                    "moved_klc",
                    format!("is missing with {} moved outcomes", self.n_moved),
                );
            }
            _ => {}
        }
        if !(0.0..=1.0).contains(&self.coverage) {
            return bad(
                "coverage",
                format!("= {} is not a fraction of the cells", self.coverage),
            );
        }
        for (field, e) in [
            ("goal_error_mean", self.goal_error_mean),
            ("goal_error_p90", self.goal_error_p90),
        ] {
            if !(0.0..=max_error).contains(&e) {
                return bad(
                    field,
                    format!("= {e} is not a distance in the goal space (0 to {max_error:.3})"),
                );
            }
        }
        Ok(())
    }

    /// Field by field equal to `other` (within [`RECORD_TOLERANCE`]); the first that differs.
    fn mismatch(&self, other: &Discovery, at: &str) -> Option<RecordMismatch> {
        let field = |name: &str, recorded: String, computed: String| {
            Some(RecordMismatch {
                field: format!("{at}.{name}"),
                why: format!("= {recorded}, the outcomes file gives {computed}"),
            })
        };
        if (self.n_outcomes, self.n_moved) != (other.n_outcomes, other.n_moved) {
            return field(
                "n_outcomes/n_moved",
                format!("{}/{}", self.n_outcomes, self.n_moved),
                format!("{}/{}", other.n_outcomes, other.n_moved),
            );
        }
        let pairs = [
            ("klc", Some(self.klc), Some(other.klc)),
            ("moved_klc", self.moved_klc, other.moved_klc),
            ("coverage", Some(self.coverage), Some(other.coverage)),
            (
                "goal_error_mean",
                Some(self.goal_error_mean),
                Some(other.goal_error_mean),
            ),
            (
                "goal_error_p90",
                Some(self.goal_error_p90),
                Some(other.goal_error_p90),
            ),
        ];
        for (name, a, b) in pairs {
            let same = match (a, b) {
                (Some(a), Some(b)) => close(a, b),
                (None, None) => true,
                _ => false,
            };
            if !same {
                return field(name, format!("{a:?}"), format!("{b:?}"));
            }
        }
        None
    }
}

impl RunDiscovery {
    /// The BLAKE3 hash (hex) of the record as JSON, which the manifest keeps beside it
    /// (`Manifest::discovery_blake3`) so that an edited record is detected like a damaged data
    /// file. JSON writes an f64 in its shortest exact form, so the hash of a record read back is
    /// the hash of the record written.
    pub fn digest(&self) -> String {
        let json = serde_json::to_vec(self).expect("a discovery record serialises");
        blake3::hash(&json).to_hex().to_string()
    }

    /// Checks the record against itself and the run's summary, without its outcomes: every
    /// field in its range; the counts, KL-coverage and coverage equal to the summary's (the same
    /// measures of the same outcomes); the goal-reaching error at most that of the resting
    /// position (the resting outcome is one of the outcomes, so no goal is farther from them
    /// than from it); the error at rest present exactly when an outcome did not move the object,
    /// the moved radius exactly when one did. `env` bounds the distances (its goal space's
    /// diameter); an environment not in this build's registry is bounded by the summary only.
    pub fn check(
        &self,
        env: &str,
        summary: &crate::summary::Summary,
    ) -> Result<(), RecordMismatch> {
        let bad = |field: &str, why: String| {
            Err(RecordMismatch {
                field: field.into(),
                why,
            })
        };
        // Every measured coordinate lies in [-1, 1] (ArmArrow's angle is scaled to it), so no
        // two points of the goal space are farther apart than 2 sqrt(d).
        let dims = EnvSpec::by_name(env).map_or(3, |s| s.metric_dims().count());
        let diameter = 2.0 * (dims as f64).sqrt();
        let a = &self.at_end;
        a.check_ranges("final", diameter)?;
        if let Some(p) = &self.position {
            p.check_ranges("position", 2.0 * 2f64.sqrt())?;
            if (p.n_outcomes, p.n_moved) != (a.n_outcomes, a.n_moved) {
                return bad(
                    "position.n_moved",
                    format!(
                        "{} of {} outcomes, the final record {} of {}",
                        p.n_moved, p.n_outcomes, a.n_moved, a.n_outcomes
                    ),
                );
            }
        }
        if a.n_moved != summary.n_moved {
            return bad(
                "final.n_moved",
                format!("= {}, the summary's = {}", a.n_moved, summary.n_moved),
            );
        }
        if !close(a.klc, summary.final_klc) {
            return bad(
                "final.klc",
                format!(
                    "= {}, the summary's final_klc = {}",
                    a.klc, summary.final_klc
                ),
            );
        }
        if !close(a.coverage, summary.coverage) {
            return bad(
                "final.coverage",
                format!("= {}, the summary's = {}", a.coverage, summary.coverage),
            );
        }
        let rests = a.n_moved < a.n_outcomes;
        match self.error_at_rest {
            Some(e) if !rests || !(0.0..=diameter).contains(&e) => {
                return bad(
                    "error_at_rest",
                    format!(
                        "= {e} with {} of {} outcomes moved",
                        a.n_moved, a.n_outcomes
                    ),
                );
            }
            Some(e) if a.goal_error_mean > e * (1.0 + RECORD_TOLERANCE) => {
                return bad(
                    "final.goal_error_mean",
                    format!(
                        "= {} exceeds the error at rest {e}, which no exploration can",
                        a.goal_error_mean
                    ),
                );
            }
            None if rests => {
                return bad(
                    "error_at_rest",
                    format!(
                        "is missing with {} of {} outcomes moved",
                        a.n_moved, a.n_outcomes
                    ),
                );
            }
            _ => {}
        }
        match self.moved_radius_mean {
            Some(r) if a.n_moved == 0 || !(0.0..=2f64.sqrt()).contains(&r) => bad(
                "moved_radius_mean",
                format!("= {r} with {} moved outcomes", a.n_moved),
            ),
            None if a.n_moved > 0 => bad(
                "moved_radius_mean",
                format!("is missing with {} moved outcomes", a.n_moved),
            ),
            _ => Ok(()),
        }
    }

    /// Where the outcomes file is kept: the record against the measures recomputed from it
    /// (`computed`, by [`RunDiscovery::measure`]); the first field that differs. A record written
    /// before the position measures were kept is compared on the rest.
    pub fn check_against(&self, computed: &RunDiscovery) -> Result<(), RecordMismatch> {
        if let Some(m) = self.at_end.mismatch(&computed.at_end, "final") {
            return Err(m);
        }
        if let (Some(a), Some(b)) = (&self.position, &computed.position)
            && let Some(m) = a.mismatch(b, "position")
        {
            return Err(m);
        }
        for (field, a, b) in [
            ("error_at_rest", self.error_at_rest, computed.error_at_rest),
            (
                "moved_radius_mean",
                self.moved_radius_mean,
                computed.moved_radius_mean,
            ),
        ] {
            let same = match (a, b) {
                (Some(a), Some(b)) => close(a, b),
                (None, None) => true,
                _ => false,
            };
            if !same {
                return Err(RecordMismatch {
                    field: field.into(),
                    why: format!("= {a:?}, the outcomes file gives {b:?}"),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            klc: crate::env::KlcGrid {
                dims: 2,
                bins: 30,
                achievable_cells: 900,
            },
            ..crate::env::ARMBALL
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
    fn a_record_is_checked_against_its_summary_and_its_outcomes() {
        let mut outcomes = vec![outcome(0, 0.0, 0.5, false)];
        outcomes.extend((1..40).map(|i| outcome(i, 0.9 - 0.04 * i as f64, 0.1, true)));
        let spec = EnvSpec::by_name("armball").unwrap();
        let d = RunDiscovery::measure(spec, &outcomes).unwrap().unwrap();
        let summary = crate::summary::Summary {
            run: "r".into(),
            final_klc: d.at_end.klc,
            n_moved: d.at_end.n_moved,
            coverage: d.at_end.coverage,
        };
        d.check("armball", &summary).unwrap();
        d.check_against(&d.clone()).unwrap();
        // The hash survives a round trip through JSON, and changes with any field.
        let back: RunDiscovery = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
        assert_eq!(back.digest(), d.digest());
        let mut better = d.clone();
        better.at_end.goal_error_mean *= 0.5;
        assert_ne!(better.digest(), d.digest());
        // Without outcomes, a smaller error passes the checks; the outcomes file refutes it.
        better.check("armball", &summary).unwrap();
        let e = better.check_against(&d).unwrap_err();
        assert_eq!(e.field, "final.goal_error_mean");
        let field = |f: &dyn Fn(&mut RunDiscovery), s: &crate::summary::Summary| {
            let mut x = d.clone();
            f(&mut x);
            x.check("armball", s).unwrap_err().field
        };
        assert_eq!(
            field(&|x| x.at_end.coverage = -5.0, &summary),
            "final.coverage"
        );
        assert_eq!(
            field(&|x| x.at_end.goal_error_mean = 1e300, &summary),
            "final.goal_error_mean"
        );
        assert_eq!(
            field(
                &|x| x.at_end.goal_error_mean = x.error_at_rest.unwrap() * 1.01,
                &summary
            ),
            "final.goal_error_mean"
        );
        assert_eq!(field(&|x| x.at_end.klc = f64::NAN, &summary), "final.klc");
        assert_eq!(
            field(&|x| x.moved_radius_mean = None, &summary),
            "moved_radius_mean"
        );
        assert_eq!(
            field(&|x| x.error_at_rest = None, &summary),
            "error_at_rest"
        );
        let other = crate::summary::Summary {
            n_moved: summary.n_moved + 1,
            ..summary.clone()
        };
        assert_eq!(field(&|_| {}, &other), "final.n_moved");
        let other = crate::summary::Summary {
            coverage: 0.5,
            ..summary
        };
        assert_eq!(field(&|_| {}, &other), "final.coverage");
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
        // A small xorshift stream: the test needs spread points, not a particular generator.
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut uniform = |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for dims in [2, 3] {
            for n in [1, 2, 5, 300] {
                let pts: Vec<f64> = (0..n * dims).map(|_| uniform(-1.0, 1.0)).collect();
                let mut tree = NnIndex::new(dims);
                for p in pts.chunks_exact(dims) {
                    tree.insert(p);
                }
                for _ in 0..200 {
                    let q: Vec<f64> = (0..dims).map(|_| uniform(-1.2, 1.2)).collect();
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
                    assert_eq!(tree.nearest(&q).map(|(_, d2)| d2.sqrt()), Some(brute));
                }
            }
        }
        assert_eq!(NnIndex::new(2).nearest(&[0.0, 0.0]), None);
    }

    #[test]
    fn quantiles_interpolate_like_numpy() {
        let v = [1.0, 2.0, 3.0, 4.0, 10.0];
        assert_eq!(quantile_sorted(&v, 0.5), Some(3.0));
        assert!((quantile_sorted(&v, 0.9).unwrap() - 7.6).abs() < 1e-12);
        assert_eq!(quantile_sorted(&[], 0.9), None);
        assert_eq!(median(&[4.0, 1.0]), Some(2.5));
    }

    /// ArmArrow's position measures are ArmBall's measures of the same positions (same disk
    /// grid and position goals): the angle left out. ArmBall has none.
    #[test]
    fn armarrow_measures_its_position_apart() {
        let arrow = EnvSpec::by_name("armarrow").unwrap();
        let ball = EnvSpec::by_name("armball").unwrap();
        let with_angle = |index: i64, x: f64, y: f64, a: f64, moved: bool| Outcome {
            angle: Some(a),
            ..outcome(index, x, y, moved)
        };
        let run = vec![
            with_angle(0, 0.6, 0.6, 0.0, false),
            with_angle(1, 0.3, 0.4, 0.5, true),
            with_angle(2, 0.3, 0.4, -0.5, true),
            with_angle(3, -0.2, 0.1, 0.9, true),
        ];
        let d = RunDiscovery::measure(arrow, &run).unwrap().unwrap();
        let flat: Vec<Outcome> = run
            .iter()
            .map(|o| Outcome {
                angle: None,
                ..o.clone()
            })
            .collect();
        let as_ball = RunDiscovery::measure(ball, &flat).unwrap().unwrap();
        assert_eq!(d.position.as_ref(), Some(&as_ball.at_end));
        assert_eq!(as_ball.position, None);
        // Two angles in one position cell: one position cell, two full cells.
        let p = d.position.unwrap();
        assert!(d.at_end.coverage * 22_680.0 > p.coverage * 756.0 + 0.5);
        assert!(p.goal_error_mean <= d.at_end.goal_error_mean);
    }

    #[test]
    fn a_run_discovery_has_its_rest_error_and_moved_radius_and_round_trips() {
        let ball = EnvSpec::by_name("armball").unwrap();
        let env = EnvMeasures::new(ball).unwrap();
        let rest = outcome(0, 0.6, 0.6, false);
        let run = vec![
            rest.clone(),
            outcome(1, 0.3, 0.4, true),
            outcome(2, 0.0, -0.5, true),
        ];
        let d = RunDiscovery::measure(ball, &run).unwrap().unwrap();
        assert_eq!(d.at_end, env.measure(&run, None).unwrap().unwrap());
        assert_eq!(d.moved_radius_mean, Some(0.5));
        let at_rest = env
            .measure(std::slice::from_ref(&rest), None)
            .unwrap()
            .unwrap();
        assert_eq!(d.error_at_rest, Some(at_rest.goal_error_mean));
        // Never moved: no radius; always moved: no rest error; nothing: None.
        let still = RunDiscovery::measure(ball, &[rest]).unwrap().unwrap();
        assert_eq!(
            (still.moved_radius_mean, still.at_end.moved_klc),
            (None, None)
        );
        assert_eq!(
            RunDiscovery::measure(ball, &run[1..])
                .unwrap()
                .unwrap()
                .error_at_rest,
            None
        );
        assert_eq!(RunDiscovery::measure(ball, &[]).unwrap(), None);
        // JSON round trip, +inf included (an outcome outside the disk).
        let outside = RunDiscovery::measure(ball, &[outcome(0, 0.99, 0.99, true)])
            .unwrap()
            .unwrap();
        assert_eq!(outside.at_end.klc, f64::INFINITY);
        assert_eq!(outside.at_end.moved_klc, Some(f64::INFINITY));
        for x in [d, still, outside] {
            let j = serde_json::to_string(&x).unwrap();
            assert_eq!(serde_json::from_str::<RunDiscovery>(&j).unwrap(), x, "{j}");
        }
    }
}
