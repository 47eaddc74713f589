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
    /// The distinct repetitions (seeds), sorted: the independent observations.
    pub seeds: Vec<i64>,
    /// Exploration replicates per repetition (the most of any repetition; 1 in the paper's
    /// design).
    pub replicates: usize,
    /// Distinct store sub-directories the runs came from, sorted.
    pub campaigns: Vec<String>,
    /// Sorted by epoch: every epoch any run of the condition evaluated, summarised over the
    /// repetitions' means (each repetition's exploration replicates share its data set and fit:
    /// the repetition is the independent observation, as in the claims).
    pub curve: Vec<CurveStat>,
    /// The fraction of the achievable cells reached, per epoch, with the same statistics.
    pub coverage_curve: Vec<CurveStat>,
    /// Distinct last epochs of the runs, sorted (one value unless budgets differ).
    pub final_epochs: Vec<i64>,
    /// KL-coverage at the runs' last epoch, summarised over the repetitions' means.
    pub final_klc: Summary,
    /// (seed, mean KL-coverage of the seed's runs at their last epoch), in seed order, one entry
    /// per seed: the values of `final_klc`.
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

    /// The sample size for a label: `10` repetitions, or `10×3` with exploration replicates.
    pub fn n_label(&self) -> String {
        if self.replicates > 1 {
            format!("{}×{}", self.seeds.len(), self.replicates)
        } else {
            self.seeds.len().to_string()
        }
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
        .filter(|c| c.key.algo == ugl_types::Algo::RPE)
        .map(|c| (c.key.env.clone(), RPE_LEVEL_FACTOR * c.final_moved_mean))
        .collect()
}

fn apply_rpe_level(
    store: &Store,
    conditions: &mut [ConditionSummary],
    thresholds: &[(String, f64)],
) {
    for c in conditions
        .iter_mut()
        .filter(|c| c.key.algo != ugl_types::Algo::RPE)
    {
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

/// `(seed, mean of the seed's values)`, one per seed, in seed order.
pub fn seed_means(xs: &[(i64, f64)]) -> Vec<(i64, f64)> {
    let mut per: BTreeMap<i64, (f64, usize)> = BTreeMap::new();
    for &(seed, v) in xs {
        let e = per.entry(seed).or_insert((0.0, 0));
        e.0 += v;
        e.1 += 1;
    }
    per.into_iter()
        .map(|(s, (t, n))| (s, t / n as f64))
        .collect()
}

fn summarize_condition(
    store: &Store,
    paper: &PaperTable,
    key: ConditionKey,
    runs: Vec<usize>,
) -> ConditionSummary {
    let rs: Vec<&crate::load::Run> = runs.iter().map(|&i| &store.runs[i]).collect();

    // Per epoch: a value of each run's curve, averaged over a seed's replicates, summarised
    // over the seeds.
    let curve_of = |value: fn(&crate::load::CurvePoint) -> f64| {
        let mut by_epoch: BTreeMap<i64, Vec<(i64, f64)>> = BTreeMap::new();
        for r in &rs {
            for p in &r.curve {
                by_epoch
                    .entry(p.epoch)
                    .or_default()
                    .push((r.seed, value(p)));
            }
        }
        by_epoch
            .iter()
            .map(|(&epoch, xs)| {
                let means: Vec<f64> = seed_means(xs).into_iter().map(|v| v.1).collect();
                let s = stats::summarize(&means);
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
    let final_by_seed = seed_means(
        &rs.iter()
            .zip(&finals)
            .map(|(r, p)| (r.seed, p.klc))
            .collect::<Vec<_>>(),
    );
    let mut final_epochs: Vec<i64> = finals.iter().map(|p| p.epoch).collect();
    final_epochs.sort_unstable();
    final_epochs.dedup();
    // With one last epoch, the same values as the curve's last point: figure and table agree.
    let klcs: Vec<f64> = final_by_seed.iter().map(|v| v.1).collect();
    let final_klc = stats::summarize(&klcs);
    let n = finals.len() as f64;
    let final_moved_mean = finals.iter().map(|p| p.n_moved as f64).sum::<f64>() / n;
    let final_outcomes_mean = finals.iter().map(|p| p.n_outcomes as f64).sum::<f64>() / n;
    let final_coverage_mean = finals.iter().map(|p| p.coverage).sum::<f64>() / n;

    let mut campaigns: Vec<String> = rs.iter().map(|r| r.campaign.clone()).collect();
    campaigns.sort();
    campaigns.dedup();

    let mut per_seed: BTreeMap<i64, usize> = BTreeMap::new();
    for r in &rs {
        *per_seed.entry(r.seed).or_default() += 1;
    }
    ConditionSummary {
        paper: paper.lookup(&key).cloned(),
        replicates: per_seed.values().copied().max().unwrap_or(1),
        seeds: per_seed.into_keys().collect(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::{CurvePoint, Run, Store};

    fn run(seed: i64, klc: f64) -> Run {
        let key = ConditionKey {
            env: "armball".into(),
            algo: "rge-vae".into(),
            sampler: "kde".into(),
            latents: 10,
            variant: "faithful".into(),
            tag: None,
        };
        let point = CurvePoint {
            epoch: 100,
            n_outcomes: 101,
            klc,
            n_moved: 10,
            coverage: 0.1,
        };
        crate::load::test_run(format!("r.s{seed}.{klc}"), key, seed, vec![point])
    }

    /// Two repetitions with three exploration replicates each: the repetition is the unit. The
    /// statistics are over the repetitions' means (n = 2), not over the six runs (which would
    /// treat replicates sharing a fit as independent and narrow the interval).
    #[test]
    fn replicates_are_averaged_within_their_repetition() {
        let runs = [(0, 4.0), (0, 4.3), (0, 4.2), (1, 5.0), (1, 5.4), (1, 5.2)]
            .iter()
            .map(|&(s, k)| run(s, k))
            .collect();
        let store = Store {
            runs,
            incomplete: Vec::new(),
        };
        let c = &aggregate(&store, &crate::paper::PaperTable::default())[0];
        assert_eq!(c.seeds, vec![0, 1]);
        assert_eq!(c.replicates, 3);
        assert_eq!(c.n_label(), "2×3");
        let means: Vec<f64> = c.final_by_seed.iter().map(|v| v.1).collect();
        assert!((means[0] - 12.5 / 3.0).abs() < 1e-12, "{means:?}");
        assert!((means[1] - 15.6 / 3.0).abs() < 1e-12, "{means:?}");
        assert_eq!(c.final_klc.n, 2);
        let expect = stats::summarize(&means);
        assert_eq!(c.final_klc, expect);
        assert_eq!(c.curve[0].n, 2);
        assert_eq!(c.curve[0].ci, expect.ci);
        assert_eq!(c.runs.len(), 6);
    }

    #[test]
    fn seed_means_keep_one_value_per_seed_in_order() {
        let m = seed_means(&[(2, 1.0), (0, 3.0), (2, 2.0)]);
        assert_eq!(m, vec![(0, 3.0), (2, 1.5)]);
    }
}
