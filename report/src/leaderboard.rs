//! The leaderboard: every algorithm (with its goal sampler and variant) of the main campaign and
//! of the `compare-*` campaigns, ranked with rliable's aggregate statistics over the paper's four
//! tasks (ArmBall and ArmArrow, each with 10 latents and with the true dimension).
//!
//! Scores are normalised so that tasks can be pooled: a KL-coverage divided by the KL-coverage of
//! outcomes all in one cell (`ln 756` on ArmBall, `ln 22680` on ArmArrow), so 0 is a perfect
//! cover and 1 is "never moved the object". For each entry:
//!
//! * **IQM** of the normalised final KLC over the runs of all its tasks, with a stratified
//!   bootstrap interval (runs resampled within each task);
//! * **IQM** of the normalised area under the KLC curve (speed of exploration), likewise;
//! * **probability of improvement** over RGE-EFR, `P(X < EFR)` averaged over the tasks, with its
//!   stratified bootstrap interval;
//! * the paper's value where it has one for every task of the entry: the mean of its (single-run)
//!   normalised final KLC values.
//!
//! * the **mean over tasks of the per-task IQM** of the normalised goal-reaching error (the mean
//!   distance from a fixed grid of test goals to the nearest outcome, divided by that of an
//!   exploration that never moved the object), with a stratified bootstrap interval and a rank
//!   interval: the ranking statistic, since KL-coverage mostly counts the episodes that moved
//!   the object (`crate::discovery` checks which measures tell a goal space that encodes the
//!   object's position from an untrained one), and the tasks' errors sit at different floors.
//!
//! Baselines (RPE, RGE-EFR) do not depend on the latent size: their runs serve both tasks of an
//! environment. Entries are ranked by the mean of the per-task IQMs of the normalised goal
//! error (lower first); entries that miss some task are ranked after the complete ones. A value is a
//! repetition's: the mean over its exploration replicates.

use std::collections::BTreeMap;

use crate::aggregate::ConditionSummary;
use crate::claims::{self, Statistic};
use crate::load::Store;
use crate::names::klc_max;
use crate::stats::{self, iqm, probability_of_improvement_ci, stratified_bootstrap_ci};

/// A campaign's conditions with the store holding their runs.
pub struct Source<'a> {
    pub campaign: &'a str,
    pub store: &'a Store,
    pub conditions: &'a [ConditionSummary],
}

/// A task: an environment and a latent size (the size a learned goal space was given).
pub type Task = (String, i64);

/// One row of the leaderboard.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub campaign: String,
    pub algo: String,
    pub sampler: String,
    pub variant: String,
    /// The tasks it has runs on, in task order.
    pub tasks: Vec<Task>,
    pub n_reps: usize,
    /// (point, lo, hi) of the IQM of the normalised final KLC.
    pub final_iqm: (f64, f64, f64),
    /// (point, lo, hi) of the IQM of the normalised area under the curve.
    pub auc_iqm: Option<(f64, f64, f64)>,
    /// (point, lo, hi) of `P(X < RGE-EFR)` on the ranking statistic (the normalised
    /// goal-reaching error where both have it, else the normalised final KLC, as
    /// [`rank_value`]); `None` for EFR itself or without EFR runs.
    pub poi_vs_efr: Option<(f64, f64, f64)>,
    /// The paper's mean normalised final KLC over the same tasks.
    pub paper: Option<f64>,
    /// Runs whose neural representation did not leave the mean-image plateau; None when no
    /// run records it (other learners, older results).
    pub untrained: Option<usize>,
    /// Mean of the normalised final KLC over all its runs (the IQM trims a quarter at each
    /// end, silently dropping failed explorations; the mean does not).
    pub final_mean: f64,
    /// Runs that ended at RPE level ([`crate::aggregate::ConditionSummary::at_rpe_level`]),
    /// each run counted once; None for RPE.
    pub at_rpe_level: Option<usize>,
    /// Whether any of its runs ran below the paper's budget (manifest `reduced_budget`).
    pub reduced_budget: bool,
    /// Mean final cell coverage over its runs (each run once): how diverse its outcomes are.
    /// KLC also rewards moving the object often; an entry can rank high on KLC with little
    /// coverage.
    pub coverage_mean: f64,
    /// Its normalised final KLC values per task, aligned with `tasks` (a baseline's runs in
    /// each task of their environment): for pairwise probabilities of improvement.
    pub finals_by_task: Vec<Vec<f64>>,
    /// Its normalised goal-reaching errors per task, aligned with `tasks` (empty where not
    /// measured).
    pub goals_by_task: Vec<Vec<f64>>,
    /// The ranking statistic: the mean over its tasks of the per-task IQM of the normalised
    /// goal-reaching error, (point, lo, hi) with a stratified bootstrap interval. Unlike one IQM
    /// over all tasks, it does not pool tasks whose errors sit at different floors.
    pub goal_task_mean: Option<(f64, f64, f64)>,
    /// The IQM of the normalised goal-reaching error per task, aligned with `tasks`.
    pub goal_task_iqm: Vec<Option<f64>>,
    /// The bootstrap replicates of [`Entry::goal_task_mean`] (for the rank interval).
    pub goal_task_draws: Vec<f64>,
    /// Its rank's 95% interval over the bootstrap replicates (complete entries only).
    pub rank_interval: Option<(usize, usize)>,
    /// The counts behind `poi_vs_efr`: pairs won (ties half) of pairs, summed over tasks; and
    /// the independent units (the smaller side's repetitions, summed over tasks) for an exact
    /// bound where every pair goes one way.
    pub poi_counts: Option<(f64, usize, usize)>,
    /// Mean final cell coverage per environment (each run once), in environment order.
    pub coverage_by_env: Vec<(String, f64)>,
}

impl Entry {
    pub fn is_complete(&self, n_tasks: usize) -> bool {
        self.tasks.len() == n_tasks
    }

    /// The per-task values of the ranking statistic shared with `other` for a probability of
    /// improvement ([`on_goal_error`]).
    pub fn ranking_values<'a>(&'a self, other: &'a Entry) -> (&'a [Vec<f64>], &'a [Vec<f64>]) {
        if on_goal_error(&self.goals_by_task, &other.goals_by_task) {
            (&self.goals_by_task, &other.goals_by_task)
        } else {
            (&self.finals_by_task, &other.finals_by_task)
        }
    }
}

/// Whether a probability of improvement between two entries is on the normalised goal-reaching
/// error (both measured it on every task) rather than on the normalised final KLC.
fn on_goal_error(a: &[Vec<f64>], b: &[Vec<f64>]) -> bool {
    a.iter().chain(b).all(|g| !g.is_empty())
}

/// The leaderboard.
#[derive(Debug, Clone, PartialEq)]
pub struct Leaderboard {
    /// The tasks of the main campaign, in order (environment, then latent size).
    pub tasks: Vec<Task>,
    /// Ranked.
    pub entries: Vec<Entry>,
    pub confidence: f64,
    pub n_boot: usize,
}

type EntryKey = (String, String, String, String);

/// Builds the leaderboard. `sources[0]` is the main campaign: its learned conditions define the
/// tasks. Conditions of environments without a known KLC maximum are left out.
pub fn build(sources: &[Source<'_>], confidence: f64, n_boot: usize, seed: u64) -> Leaderboard {
    let mut tasks: Vec<Task> = Vec::new();
    if let Some(main) = sources.first() {
        for c in main.conditions {
            let t = (c.key.env.clone(), c.key.latents);
            if c.key.latents > 0 && klc_max(&c.key.env).is_some() && !tasks.contains(&t) {
                tasks.push(t);
            }
        }
    }
    tasks.sort_by_key(|(env, l)| (ugl_types::EnvSpec::order(env), env.clone(), -*l));
    let alpha = 1.0 - confidence;

    // The goal-reaching error of an exploration that never moved the object, per environment.
    let mut rest: BTreeMap<String, f64> = BTreeMap::new();
    for src in sources {
        for r in &src.store.runs {
            if !rest.contains_key(&r.key.env)
                && let Some(e) = crate::discovery::error_at_rest(r)
            {
                rest.insert(r.key.env.clone(), e);
            }
        }
    }
    // entry -> task -> (final values, auc values, paper value, final coverages, goal errors)
    type PerTask = BTreeMap<usize, (Vec<f64>, Vec<f64>, Option<f64>, Vec<f64>, Vec<f64>)>;
    let mut groups: BTreeMap<EntryKey, PerTask> = BTreeMap::new();
    let mut untrained: BTreeMap<EntryKey, usize> = BTreeMap::new();
    let mut at_rpe: BTreeMap<EntryKey, usize> = BTreeMap::new();
    // Entries whose runs serve every task of their environment (baselines, latents 0).
    let mut shared: std::collections::BTreeSet<EntryKey> = Default::default();
    let mut reduced: std::collections::BTreeSet<EntryKey> = Default::default();
    for src in sources {
        for c in src.conditions {
            let Some(max) = klc_max(&c.key.env) else {
                continue;
            };
            if let Some(k) = c.at_rpe_level {
                *at_rpe
                    .entry((
                        src.campaign.to_string(),
                        c.key.algo.to_string(),
                        c.key.sampler.to_string(),
                        c.key.variant.to_string(),
                    ))
                    .or_default() += k;
            }
            let flags: Vec<bool> = c
                .runs
                .iter()
                .filter_map(|&i| src.store.runs[i].manifest.trained())
                .collect();
            if !flags.is_empty() {
                *untrained
                    .entry((
                        src.campaign.to_string(),
                        c.key.algo.to_string(),
                        c.key.sampler.to_string(),
                        c.key.variant.to_string(),
                    ))
                    .or_default() += flags.iter().filter(|t| !**t).count();
            }
            let key: EntryKey = (
                src.campaign.to_string(),
                c.key.algo.to_string(),
                c.key.sampler.to_string(),
                c.key.variant.to_string(),
            );
            let finals: Vec<f64> = claims::values(src.store, c, Statistic::FinalKlc)
                .iter()
                .map(|v| v / max)
                .collect();
            let aucs: Vec<f64> = claims::values(src.store, c, Statistic::Auc)
                .iter()
                .map(|v| v / max)
                .collect();
            let coverages = claims::values(src.store, c, Statistic::Coverage);
            let goals: Vec<f64> = match rest.get(&c.key.env) {
                Some(&r) if r > 0.0 => claims::values(src.store, c, Statistic::GoalError)
                    .iter()
                    .map(|v| v / r)
                    .collect(),
                _ => Vec::new(),
            };
            if c.key.latents == 0 {
                shared.insert(key.clone());
            }
            if c.runs
                .iter()
                .any(|&i| src.store.runs[i].manifest.reduced_budget)
            {
                reduced.insert(key.clone());
            }
            let paper_value = c.paper.as_ref().map(|p| p.klc / max);
            for (ti, (env, l)) in tasks.iter().enumerate() {
                // A baseline (latents 0) serves every task of its environment.
                if *env == c.key.env && (c.key.latents == *l || c.key.latents == 0) {
                    groups.entry(key.clone()).or_default().insert(
                        ti,
                        (
                            finals.clone(),
                            aucs.clone(),
                            paper_value,
                            coverages.clone(),
                            goals.clone(),
                        ),
                    );
                }
            }
        }
    }

    // RGE-EFR of the main campaign, per task (final KLC, goal error), for the probability of
    // improvement.
    let efr: BTreeMap<usize, (Vec<f64>, Vec<f64>)> = groups
        .iter()
        .find(|((camp, algo, _, _), _)| {
            Some(camp.as_str()) == sources.first().map(|s| s.campaign)
                && *algo == ugl_types::Algo::RGE_EFR
        })
        .map(|(_, per)| {
            per.iter()
                .map(|(t, v)| (*t, (v.0.clone(), v.4.clone())))
                .collect()
        })
        .unwrap_or_default();

    let mut entries: Vec<Entry> = groups
        .into_iter()
        .filter_map(|(key, per)| {
            let (campaign, algo, sampler, variant) = key.clone();
            // A baseline's runs are the same in both tasks of an environment: in the pooled
            // statistics (IQM, mean, run count) they count once, one stratum per environment.
            let mut seen_envs: Vec<&str> = Vec::new();
            let strata: Vec<&(Vec<f64>, Vec<f64>, Option<f64>, Vec<f64>, Vec<f64>)> = per
                .iter()
                .filter(|(t, _)| {
                    let env = tasks[**t].0.as_str();
                    if !shared.contains(&key) || !seen_envs.contains(&env) {
                        seen_envs.push(env);
                        true
                    } else {
                        false
                    }
                })
                .map(|(_, v)| v)
                .collect();
            let finals: Vec<Vec<f64>> = strata.iter().map(|v| v.0.clone()).collect();
            let aucs: Vec<Vec<f64>> = strata.iter().map(|v| v.1.clone()).collect();
            // Probability of improvement: task by task (a baseline against EFR on each task).
            let finals_by_task: Vec<Vec<f64>> = per.values().map(|v| v.0.clone()).collect();
            let goals_by_task: Vec<Vec<f64>> = per.values().map(|v| v.4.clone()).collect();
            let label = format!("leaderboard|{campaign}|{algo}|{sampler}|{variant}");
            let final_iqm = stratified_bootstrap_ci(
                &finals,
                iqm,
                n_boot,
                alpha,
                stats::derive_seed(seed, &format!("{label}|final")),
            )?;
            let auc_iqm = stratified_bootstrap_ci(
                &aucs,
                iqm,
                n_boot,
                alpha,
                stats::derive_seed(seed, &format!("{label}|auc")),
            );
            // Against RGE-EFR on the ranking statistic: the goal error where both have it on
            // every task, else the final KLC. The probability with its interval, and its counts.
            let vs_efr: Option<(Vec<Vec<f64>>, Vec<Vec<f64>>)> = (algo != ugl_types::Algo::RGE_EFR
                && per.keys().all(|t| efr.contains_key(t)))
            .then(|| {
                let efr_goals: Vec<Vec<f64>> = per.keys().map(|t| efr[t].1.clone()).collect();
                if on_goal_error(&goals_by_task, &efr_goals) {
                    (goals_by_task.clone(), efr_goals)
                } else {
                    (
                        finals_by_task.clone(),
                        per.keys().map(|t| efr[t].0.clone()).collect(),
                    )
                }
            });
            let poi_vs_efr = vs_efr.as_ref().and_then(|(xs, ys)| {
                probability_of_improvement_ci(
                    xs,
                    ys,
                    n_boot,
                    alpha,
                    stats::derive_seed(seed, &format!("{label}|poi")),
                )
            });
            let poi_counts = vs_efr.as_ref().map(|(xs, ys)| {
                let (wins, pairs) = stats::improvement_counts(xs, ys);
                let units = xs.iter().zip(ys).map(|(a, b)| a.len().min(b.len())).sum();
                (wins, pairs, units)
            });
            let goal_task_iqm: Vec<Option<f64>> = goals_by_task
                .iter()
                .map(|g| (!g.is_empty()).then(|| iqm(g)))
                .collect();
            let (goal_task_mean, goal_task_draws) = match stats::per_task_mean_bootstrap(
                &goals_by_task,
                iqm,
                n_boot,
                stats::derive_seed(seed, &format!("{label}|goal-per-task")),
            ) {
                Some((point, draws)) => {
                    let (lo, hi) = stats::percentile_ci(&draws, alpha);
                    (Some((point, lo, hi)), draws)
                }
                None => (None, Vec::new()),
            };
            // Per environment, each run once (a baseline's runs serve both tasks of theirs).
            let mut coverage_by_env: Vec<(String, f64)> = Vec::new();
            for t in per.keys() {
                let env = &tasks[*t].0;
                if coverage_by_env.iter().any(|(e, _)| e == env) {
                    continue;
                }
                let values: Vec<f64> = per
                    .iter()
                    .filter(|(u, _)| tasks[**u].0 == *env && (!shared.contains(&key) || *u == t))
                    .flat_map(|(_, w)| w.3.iter().copied())
                    .collect();
                coverage_by_env.push((env.clone(), stats::mean(&values)));
            }
            let untrained = untrained.get(&key).copied();
            let at_rpe_level = at_rpe.get(&key).copied();
            let all: Vec<f64> = finals.iter().flatten().copied().collect();
            let final_mean = stats::mean(&all);
            let coverages: Vec<f64> = strata.iter().flat_map(|v| v.3.iter().copied()).collect();
            let coverage_mean = stats::mean(&coverages);
            let papers: Vec<f64> = per.values().filter_map(|v| v.2).collect();
            let paper = (papers.len() == per.len()).then(|| stats::mean(&papers));
            Some(Entry {
                campaign,
                algo,
                sampler,
                variant,
                tasks: per.keys().map(|&t| tasks[t].clone()).collect(),
                n_reps: finals.iter().map(Vec::len).sum(),
                final_iqm,
                auc_iqm,
                poi_vs_efr,
                paper,
                untrained,
                final_mean,
                at_rpe_level,
                reduced_budget: reduced.contains(&key),
                coverage_mean,
                finals_by_task,
                goals_by_task,
                goal_task_mean,
                goal_task_iqm,
                goal_task_draws,
                rank_interval: None,
                poi_counts,
                coverage_by_env,
            })
        })
        .collect();
    let n_tasks = tasks.len();
    entries.sort_by(|a, b| {
        b.is_complete(n_tasks)
            .cmp(&a.is_complete(n_tasks))
            .then(rank_value(a).total_cmp(&rank_value(b)))
            .then_with(|| {
                (&a.campaign, &a.algo, &a.sampler, &a.variant).cmp(&(
                    &b.campaign,
                    &b.algo,
                    &b.sampler,
                    &b.variant,
                ))
            })
    });
    rank_intervals(&mut entries, n_tasks, alpha);
    Leaderboard {
        tasks,
        entries,
        confidence,
        n_boot,
    }
}

/// Each complete entry's rank interval: its rank among the complete entries in every bootstrap
/// replicate of the ranking statistic (each entry's replicates drawn independently, replicate
/// `b` of every entry ranked together), and the `1 − alpha` percentiles of those ranks.
fn rank_intervals(entries: &mut [Entry], n_tasks: usize, alpha: f64) {
    let ranked: Vec<usize> = (0..entries.len())
        .filter(|&i| entries[i].is_complete(n_tasks) && !entries[i].goal_task_draws.is_empty())
        .collect();
    let Some(n_boot) = ranked
        .iter()
        .map(|&i| entries[i].goal_task_draws.len())
        .min()
    else {
        return;
    };
    let mut ranks: Vec<Vec<f64>> = vec![Vec::with_capacity(n_boot); ranked.len()];
    for b in 0..n_boot {
        for (a, &i) in ranked.iter().enumerate() {
            let v = entries[i].goal_task_draws[b];
            let better = ranked
                .iter()
                .filter(|&&j| entries[j].goal_task_draws[b] < v)
                .count();
            ranks[a].push((better + 1) as f64);
        }
    }
    for (a, &i) in ranked.iter().enumerate() {
        let (lo, hi) = stats::percentile_ci(&ranks[a], alpha);
        entries[i].rank_interval = Some((lo.floor() as usize, hi.ceil() as usize));
    }
}

/// What the leaderboard ranks by: the mean of the per-task IQMs of the normalised goal error, which does
/// not count repeated outcomes (entries without it, e.g. runs without outcomes, after those
/// with it, by final KLC).
fn rank_value(e: &Entry) -> f64 {
    match e.goal_task_mean {
        Some(g) => g.0,
        None => 10.0 + e.final_iqm.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::claims::tests::synthetic;

    #[test]
    fn ranks_by_normalised_iqm_and_compares_with_efr() {
        let (store, conds) = synthetic(&[
            ("rpe", 0, &[6.5, 6.5, 6.5, 6.5]),
            ("rge-efr", 0, &[4.5, 4.6, 4.4, 4.55]),
            ("rge-pca", 10, &[4.0, 4.1, 3.9, 4.05]),
            ("rge-pca", 2, &[4.0, 4.1, 3.9, 4.05]),
            ("rge-ae", 10, &[4.2, 4.3]),
        ]);
        let lb = build(
            &[Source {
                campaign: "paper",
                store: &store,
                conditions: &conds,
            }],
            0.95,
            500,
            0,
        );
        assert_eq!(
            lb.tasks,
            vec![("armball".to_string(), 10), ("armball".to_string(), 2)]
        );
        let names: Vec<&str> = lb.entries.iter().map(|e| e.algo.as_str()).collect();
        // AE lacks the 2-latent task: ranked last although its IQM beats EFR's.
        assert_eq!(names, ["rge-pca", "rge-efr", "rpe", "rge-ae"]);
        let pca = &lb.entries[0];
        let max = 756f64.ln();
        // IQM of the 8 pooled runs: drop the 2 lowest and the 2 highest.
        let mut v = [4.0, 4.1, 3.9, 4.05, 4.0, 4.1, 3.9, 4.05];
        v.sort_by(f64::total_cmp);
        let expect = v[2..6].iter().sum::<f64>() / 4.0 / max;
        assert!((pca.final_iqm.0 - expect).abs() < 1e-12);
        // Every PCA run beats every EFR run: P = 1 with a degenerate interval.
        assert_eq!(pca.poi_vs_efr, Some((1.0, 1.0, 1.0)));
        assert_eq!(lb.entries[2].poi_vs_efr, Some((0.0, 0.0, 0.0)));
        assert_eq!(lb.entries[1].poi_vs_efr, None);
        // EFR's runs serve both tasks, and count once in its pooled statistics.
        assert_eq!(lb.entries[1].n_reps, 4);
        assert_eq!(lb.entries[1].tasks.len(), 2);
        assert!(!lb.entries[3].is_complete(2));
    }
}
