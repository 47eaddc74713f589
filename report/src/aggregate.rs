//! From runs to conditions: the mean KL-coverage curve over seeds with its t-interval band
//! ([`stats::CONFIDENCE`]), and the final values of the table.

use std::collections::BTreeMap;

use crate::load::{ConditionKey, Store};
use crate::paper::{PaperTable, PaperValue};
use crate::stats::{self, Summary};

/// The statistics of one condition at one epoch, over the runs that have that epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveStat {
    pub epoch: i64,
    pub n: usize,
    pub mean: f64,
    /// Sample standard deviation over the runs (`None` with one run or an infinite value).
    pub std: Option<f64>,
    /// Student's t interval of the mean at [`stats::CONFIDENCE`]; `None` with one run or an
    /// infinite value (no band drawn there).
    pub ci: Option<(f64, f64)>,
}

/// One condition (env, algo, sampler, latents, variant) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct ConditionSummary {
    pub key: ConditionKey,
    /// Indices into `Store::runs`, in seed order.
    pub runs: Vec<usize>,
    pub seeds: Vec<i64>,
    /// Distinct store sub-directories the runs came from, sorted.
    pub campaigns: Vec<String>,
    /// Sorted by epoch: every epoch any run of the condition evaluated.
    pub curve: Vec<CurveStat>,
    /// The fraction of the achievable cells reached, per epoch, with the same statistics.
    pub coverage_curve: Vec<CurveStat>,
    /// Distinct last epochs of the runs, sorted (one value unless budgets differ).
    pub final_epochs: Vec<i64>,
    /// KL-coverage at each run's last epoch.
    pub final_klc: Summary,
    /// (seed, KL-coverage at the run's last epoch), in seed order: the values of `final_klc`.
    pub final_by_seed: Vec<(i64, f64)>,
    pub final_moved_mean: f64,
    pub final_outcomes_mean: f64,
    pub final_coverage_mean: f64,
    pub paper: Option<PaperValue>,
    /// Runs that ended at RPE level: fewer object moves than [`RPE_LEVEL_FACTOR`] x RPE's mean
    /// in the same environment (a failed exploration; the IQM trims such runs, so they are
    /// counted apart). None for RPE itself, or without RPE runs.
    pub at_rpe_level: Option<usize>,
}

/// A run "ends at RPE level" when it moved the object fewer than this many times RPE's mean
/// number of moves (same environment).
pub const RPE_LEVEL_FACTOR: f64 = 2.0;

impl ConditionSummary {
    pub fn last_epoch(&self) -> i64 {
        *self.final_epochs.last().expect("a condition has runs")
    }
}

/// Groups the runs by condition (in the report's condition order) and computes the statistics.
pub fn aggregate(store: &Store, paper: &PaperTable) -> Vec<ConditionSummary> {
    let mut groups: BTreeMap<ConditionKey, Vec<usize>> = BTreeMap::new();
    for (i, run) in store.runs.iter().enumerate() {
        groups.entry(run.key.clone()).or_default().push(i);
    }
    let mut out: Vec<ConditionSummary> = groups
        .into_iter()
        .map(|(key, runs)| summarize_condition(store, paper, key, runs))
        .collect();
    out.sort_by_key(|c| c.key.order_key());
    mark_rpe_level(store, &mut out);
    out
}

/// Sets [`ConditionSummary::at_rpe_level`] from each environment's RPE condition.
fn mark_rpe_level(store: &Store, conditions: &mut [ConditionSummary]) {
    let thresholds = rpe_thresholds(conditions);
    apply_rpe_level(store, conditions, &thresholds);
}

/// Per environment: the object moves below which a run is "at RPE level" (RPE's mean times
/// [`RPE_LEVEL_FACTOR`]).
fn rpe_thresholds(conditions: &[ConditionSummary]) -> Vec<(String, f64)> {
    conditions
        .iter()
        .filter(|c| c.key.algo == "rpe")
        .map(|c| (c.key.env.clone(), RPE_LEVEL_FACTOR * c.final_moved_mean))
        .collect()
}

fn apply_rpe_level(
    store: &Store,
    conditions: &mut [ConditionSummary],
    thresholds: &[(String, f64)],
) {
    for c in conditions.iter_mut().filter(|c| c.key.algo != "rpe") {
        c.at_rpe_level = thresholds
            .iter()
            .find(|(env, _)| *env == c.key.env)
            .map(|&(_, t)| {
                c.runs
                    .iter()
                    .filter(|&&i| (store.runs[i].final_point().n_moved as f64) < t)
                    .count()
            });
    }
}

/// For a campaign without RPE runs of its own (a `compare-*` campaign): "at RPE level" against
/// the main campaign's RPE (`main`), environment by environment. A campaign's own RPE runs,
/// where it has them, take precedence.
pub fn mark_rpe_level_against(
    store: &Store,
    conditions: &mut [ConditionSummary],
    main: &[ConditionSummary],
) {
    let own = rpe_thresholds(conditions);
    let mut thresholds = rpe_thresholds(main);
    thresholds.retain(|(env, _)| !own.iter().any(|(e, _)| e == env));
    thresholds.extend(own);
    apply_rpe_level(store, conditions, &thresholds);
}

fn summarize_condition(
    store: &Store,
    paper: &PaperTable,
    key: ConditionKey,
    runs: Vec<usize>,
) -> ConditionSummary {
    let rs: Vec<&crate::load::Run> = runs.iter().map(|&i| &store.runs[i]).collect();

    // Per epoch over the runs: a value of each run's curve, summarised.
    let curve_of = |value: fn(&crate::load::CurvePoint) -> f64| {
        let mut by_epoch: BTreeMap<i64, Vec<f64>> = BTreeMap::new();
        for r in &rs {
            for p in &r.curve {
                by_epoch.entry(p.epoch).or_default().push(value(p));
            }
        }
        by_epoch
            .iter()
            .map(|(&epoch, xs)| {
                let s = stats::summarize(xs);
                CurveStat {
                    epoch,
                    n: s.n,
                    mean: s.mean,
                    std: s.std,
                    ci: s.ci,
                }
            })
            .collect::<Vec<_>>()
    };
    let curve = curve_of(|p| p.klc);
    let coverage_curve = curve_of(|p| p.coverage);

    let finals: Vec<_> = rs.iter().map(|r| r.final_point()).collect();
    let final_by_seed = rs
        .iter()
        .zip(&finals)
        .map(|(r, p)| (r.seed, p.klc))
        .collect();
    let mut final_epochs: Vec<i64> = finals.iter().map(|p| p.epoch).collect();
    final_epochs.sort_unstable();
    final_epochs.dedup();
    // With one last epoch, the same values as the curve's last point: figure and table agree.
    let klcs: Vec<f64> = finals.iter().map(|p| p.klc).collect();
    let final_klc = stats::summarize(&klcs);
    let n = finals.len() as f64;
    let final_moved_mean = finals.iter().map(|p| p.n_moved as f64).sum::<f64>() / n;
    let final_outcomes_mean = finals.iter().map(|p| p.n_outcomes as f64).sum::<f64>() / n;
    let final_coverage_mean = finals.iter().map(|p| p.coverage).sum::<f64>() / n;

    let mut campaigns: Vec<String> = rs.iter().map(|r| r.campaign.clone()).collect();
    campaigns.sort();
    campaigns.dedup();

    ConditionSummary {
        paper: paper.lookup(&key).cloned(),
        seeds: rs.iter().map(|r| r.seed).collect(),
        key,
        runs,
        campaigns,
        curve,
        coverage_curve,
        final_epochs,
        final_klc,
        final_by_seed,
        final_moved_mean,
        final_outcomes_mean,
        final_coverage_mean,
        at_rpe_level: None,
    }
}
