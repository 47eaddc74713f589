//! The follow-up's claims (`data/paper/followup_claims.toml`), evaluated by the one claims
//! engine ([`crate::claims`]) on the follow-up's runs: each algorithm of the campaigns is a
//! condition, its runs' final ball ratio or ball-module share of goals the per-seed values.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use super::authors::{self, Authors};
use super::labels::{Condition, f3};
use super::runs::{CodeKind, FollowupRun, display, one_run_per_network};
use crate::claims::{ClaimResult, Observations, Premise, PremiseCheck, Statistic, Verdict};
use crate::load::ConditionKey;
use crate::names::learner_name;
use crate::stats::SampleSummary;

/// The claims file of the follow-up, in the paper directory.
pub const FILE: &str = "followup_claims.toml";

/// The follow-up's runs as the claims engine sees them, with the authors' published runs
/// where they are of the same environment (conditions tagged `authors`: `mge-efr-lp@authors`,
/// known by their summaries only).
pub struct FollowupObservations<'a> {
    pub runs: &'a [FollowupRun],
    pub authors: Option<&'a Authors>,
}

/// A run's condition as the engine sees it: the environment, the algorithm with its campaign's
/// tag, the goal sampler and the latent size (selectors and `pair_on` work on these).
fn key(r: &FollowupRun) -> ConditionKey {
    ConditionKey {
        // The follow-up's conditions have no variant.
        variant: String::new().into(),
        ..r.key.clone()
    }
}

/// The page's name of the condition `k`.
fn name(runs: &[FollowupRun], k: &ConditionKey) -> String {
    if k.tag.as_deref() == Some(authors::TAG) {
        return format!(
            "{}, the authors' runs",
            Condition::of(&k.tagged(None), false).algo_label()
        );
    }
    runs.iter()
        .find(|r| key(r) == *k)
        .map(|r| display(runs, &r.cond))
        .unwrap_or_else(|| k.tagged_algo())
}

impl FollowupObservations<'_> {
    /// The authors' curves, where some of our runs are of their environment.
    pub(super) fn comparable_authors(&self) -> Option<&Authors> {
        self.authors
            .filter(|a| self.runs.iter().any(|r| r.key.env == a.env))
    }

    /// The ball's ratio of a run as the claims compare it: at the authors' last point where the
    /// run is of their environment (our last evaluation at or before it: their runs end there),
    /// else at the run's last epoch.
    fn ratio(&self, r: &FollowupRun) -> f64 {
        match self.comparable_authors() {
            Some(a) if r.key.env == a.env => r.ratio_before(a.last_rollouts),
            _ => r.final_ratio(),
        }
    }
}

impl Observations for FollowupObservations<'_> {
    fn keys(&self) -> Vec<ConditionKey> {
        let mut keys: Vec<ConditionKey> = Vec::new();
        for r in self.runs {
            let k = key(r);
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
        if let Some(a) = self.comparable_authors() {
            for c in &a.curves {
                // Their condition is ours of the same algorithm, goal sampler and latent size.
                let ours = keys
                    .iter()
                    .find(|k| k.env == a.env && k.algo == c.algo && k.tag.is_none())
                    .cloned();
                let k = ConditionKey {
                    tag: Some(authors::TAG.into()),
                    ..ours.unwrap_or_else(|| ConditionKey {
                        env: a.env.clone(),
                        algo: c.algo.clone(),
                        sampler: String::new().into(),
                        latents: 0,
                        variant: String::new().into(),
                        tag: None,
                    })
                };
                keys.push(k);
            }
        }
        keys
    }

    fn summary(&self, k: &ConditionKey, statistic: Statistic) -> Option<SampleSummary> {
        let a = self.comparable_authors()?;
        if k.tag.as_deref() != Some(authors::TAG) || statistic != Statistic::BallRatio {
            return None;
        }
        a.of(&k.algo)?.at(a.last_rollouts)
    }

    fn values(&self, k: &ConditionKey, statistic: Statistic) -> Vec<(i64, f64)> {
        let runs: Vec<&FollowupRun> = self.runs.iter().filter(|r| key(r) == *k).collect();
        let mut v: Vec<(i64, f64)> = match statistic {
            Statistic::BallRatio => runs.iter().map(|r| (r.seed, self.ratio(r))).collect(),
            Statistic::GoalError => runs
                .iter()
                .filter_map(|r| Some((r.seed, r.goal_error?)))
                .collect(),
            Statistic::BallModuleGoals => runs
                .iter()
                .filter_map(|r| Some((r.seed, ball_module_goals(r)?)))
                .collect(),
            _ => Vec::new(),
        };
        v.sort_by_key(|x| x.0);
        v
    }

    fn premise(&self, premise: &Premise) -> Option<PremiseCheck> {
        // Each part of the premise: its learner and the kind of code its network must have.
        let wanted = [
            (&premise.disentangled, CodeKind::Disentangled),
            (&premise.entangled, CodeKind::Entangled),
        ];
        // Per part, the repetitions whose network meets it, and the count in words; and every
        // repetition with a network of a part's learner (those that could be compared).
        let mut parts: Vec<(BTreeSet<(Option<String>, i64)>, String)> = Vec::new();
        let mut all: BTreeSet<(Option<String>, i64)> = BTreeSet::new();
        for (learner, kind) in wanted {
            let Some(learner) = learner else { continue };
            let networks = networks(self.runs, learner);
            let yes: BTreeSet<_> = networks
                .iter()
                .filter(|n| n.1 == kind)
                .map(|n| n.0.clone())
                .collect();
            let counted = format!(
                "{} networks {}: {} of {}",
                learner_name(learner),
                kind.criterion(),
                yes.len(),
                networks.len()
            );
            all.extend(networks.into_iter().map(|n| n.0));
            parts.push((yes, counted));
        }
        let (first, _) = parts.first()?;
        let repetitions: BTreeSet<(Option<String>, i64)> = first
            .iter()
            .filter(|r| parts.iter().all(|(p, _)| p.contains(r)))
            .cloned()
            .collect();
        let yes = repetitions.len();
        let mut counted: Vec<String> = parts.into_iter().map(|(_, c)| c).collect();
        if yes > 0 && yes < all.len() {
            counted.push(format!("compared on the {yes} repetitions that meet it"));
        }
        Some(PremiseCheck {
            met: yes > 0,
            counted: counted.join("; "),
            // None meets it: the difference on every repetition is still shown, marked.
            repetitions: (yes > 0).then_some(repetitions),
        })
    }
}

/// The share of a modular run's goals drawn in the module that encodes the ball best: the
/// module named `ball` (engineered features), else the one with the largest ball R² −
/// distractor R² (a learned space). None for a run without modules.
fn ball_module_goals(r: &FollowupRun) -> Option<f64> {
    let fin = r.final_interest();
    let total: i64 = fin.values().map(|v| v.1).sum();
    if total == 0 {
        return None;
    }
    let by_name = r
        .modules
        .iter()
        .find(|(_, (name, _))| name == "ball")
        .map(|(m, _)| *m);
    let ball = by_name.or_else(|| {
        r.modules
            .keys()
            .filter_map(|m| r.module_objects(*m).map(|(b, d)| (*m, b - d)))
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
            .map(|(m, _)| m)
    })?;
    Some(fin.get(&ball).map_or(0, |v| v.1) as f64 / total as f64)
}

/// The learned networks of `learner`, one per variant campaign's tag and seed (its flat and
/// modular runs share it): its repetition and what its code is ([`CodeKind`]).
fn networks(runs: &[FollowupRun], learner: &str) -> Vec<((Option<String>, i64), CodeKind)> {
    one_run_per_network(runs)
        .into_iter()
        .filter(|r| r.learner.as_deref() == Some(learner))
        .filter_map(|r| Some(((r.key.tag.clone(), r.seed), CodeKind::of(r)?)))
        .collect()
}

/// A claim's verdict in words: the engine's, or "premise not met" with it.
pub fn verdict(r: &ClaimResult) -> String {
    let v = if let (true, Some(envs)) = (r.comparisons.is_empty(), &r.claim.subject.env) {
        format!("not run (no {} runs in these results)", envs.join(", "))
    } else if r.comparisons.is_empty() {
        let missing: Vec<String> = r
            .claim
            .subject
            .algo
            .iter()
            .chain(r.claim.reference.algo.iter())
            .flatten()
            .cloned()
            .collect();
        format!("not run ({})", missing.join(", "))
    } else {
        r.verdict.label().to_string()
    };
    match &r.premise {
        Some(p) if !p.met => format!("premise not met (difference: {v})"),
        _ => v,
    }
}

/// The page's *Findings*: one sentence per claim that was run, generated from its verdict and
/// comparisons (nothing written per result), the claims that decide first (not reproduced,
/// reproduced), then the inconclusive ones, those whose premise is not met, and a list of those
/// not run.
pub fn findings(runs: &[FollowupRun], results: &[ClaimResult]) -> String {
    let mut w = String::new();
    let _ = writeln!(
        w,
        "## Findings\n\n\
         Generated from the verdicts of [the follow-up's claims](#the-follow-ups-claims) (nothing \
         here is written by hand per result). Δ is subject − reference of the means over \
         repetitions; an interval is the claim engine's, after its correction.\n"
    );
    let premise_not_met = |r: &ClaimResult| r.premise.as_ref().is_some_and(|p| !p.met);
    let rank = |r: &ClaimResult| match (premise_not_met(r), r.verdict) {
        (true, _) => 3,
        (false, Verdict::NotReproduced) => 0,
        (false, Verdict::Reproduced) => 1,
        (false, Verdict::Inconclusive) => 2,
    };
    let (mut run, not_run): (Vec<&ClaimResult>, Vec<&ClaimResult>) =
        results.iter().partition(|r| !r.comparisons.is_empty());
    run.sort_by_key(|r| rank(r));
    if run.is_empty() {
        let _ = writeln!(w, "No claim could be evaluated on these results.\n");
    }
    for r in run {
        let excluding = r
            .comparisons
            .iter()
            .filter(|c| c.bounds().is_some_and(|(lo, hi)| lo > 0.0 || hi < 0.0))
            .count();
        let detail = match r.comparisons.as_slice() {
            [c] => format!(
                "{} − {}: Δ {} {}",
                name(runs, &c.subject),
                name(runs, &c.reference),
                f3(c.diff),
                c.bounds()
                    .map_or("(no interval)".into(), |(lo, hi)| format!(
                        "[{}, {}]",
                        f3(lo),
                        f3(hi)
                    ))
            ),
            cs => {
                let lo = cs.iter().map(|c| c.diff).fold(f64::INFINITY, f64::min);
                let hi = cs.iter().map(|c| c.diff).fold(f64::NEG_INFINITY, f64::max);
                format!(
                    "Δ from {} to {} over {} comparisons, {excluding} of them with an interval \
                     that excludes 0",
                    f3(lo),
                    f3(hi),
                    cs.len()
                )
            }
        };
        let premise = match &r.premise {
            Some(p) if !p.met => format!(" The premise is not met: {}.", p.counted),
            _ => String::new(),
        };
        let _ = writeln!(
            w,
            "- **{}** ({}, on {}): **{}**; {detail}.{premise}",
            r.claim.statement,
            r.claim.id,
            r.claim.statistic.label(),
            verdict(r)
        );
    }
    if !not_run.is_empty() {
        let ids: Vec<&str> = not_run.iter().map(|r| r.claim.id.as_str()).collect();
        let _ = writeln!(
            w,
            "- Not run (their conditions are not in these results): {}.",
            ids.join(", ")
        );
    }
    w
}

/// The claims table: claim, source, our test, what was measured, the verdict.
pub fn table(runs: &[FollowupRun], results: &[ClaimResult]) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "| claim | source | our test | measured | verdict |\n|---|---|---|---|---|"
    );
    for r in results {
        let several = r.comparisons.len() > 1;
        let mut measured: Vec<String> = r
            .comparisons
            .iter()
            .map(|c| {
                let mut m = format!(
                    "{} {} − {} {} = {} {}",
                    name(runs, &c.subject),
                    f3(c.subject_mean),
                    name(runs, &c.reference),
                    f3(c.reference_mean),
                    f3(c.diff),
                    match c.bounds() {
                        Some((lo, hi)) => format!("[{}, {}]", f3(lo), f3(hi)),
                        None => "(no interval)".into(),
                    }
                );
                if r.claim.relative_margin.is_some() {
                    let _ = write!(m, ", margin ±{}", f3(c.margin));
                }
                if several {
                    let _ = write!(m, " ({})", c.verdict.label());
                }
                if c.verdict != c.uncorrected {
                    let _ = write!(m, " ({} uncorrected)", c.uncorrected.label());
                }
                m
            })
            .collect();
        if measured.is_empty() {
            measured.push("n/a".into());
        }
        if let Some(p) = &r.premise {
            measured.push(p.counted.clone());
        }
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | **{}** |",
            r.claim.id,
            r.claim.source,
            r.claim.statement,
            measured.join("; "),
            verdict(r)
        );
    }
    t
}

/// How many claims are reproduced, not reproduced, inconclusive (premise not met counts apart).
/// How many claims are reproduced, not reproduced, inconclusive, have their premise not met,
/// and were not run (no comparison: their conditions are not in these results).
pub fn counts(results: &[ClaimResult]) -> (usize, usize, usize, usize, usize) {
    let premise_not_met = |r: &&ClaimResult| r.premise.as_ref().is_some_and(|p| !p.met);
    let n = |v: Verdict| {
        results
            .iter()
            .filter(|r| !premise_not_met(r) && !r.comparisons.is_empty() && r.verdict == v)
            .count()
    };
    (
        n(Verdict::Reproduced),
        n(Verdict::NotReproduced),
        n(Verdict::Inconclusive),
        results.iter().filter(premise_not_met).count(),
        results
            .iter()
            .filter(|r| !premise_not_met(r) && r.comparisons.is_empty())
            .count(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::armballs::runs::ball_cells;
    use crate::claims::{evaluate_on, parse_claims};

    fn run(algo: &str, seed: i64, ratio: f64) -> FollowupRun {
        let (name, tag) = match algo.split_once('@') {
            Some((a, t)) => (a, Some(t.to_string())),
            None => (algo, None),
        };
        let key = ConditionKey {
            env: "armballs".into(),
            algo: name.into(),
            sampler: if algo == "rpe" { "none" } else { "gaussian" }.into(),
            latents: if algo.contains("efr") || algo == "rpe" {
                0
            } else {
                10
            },
            variant: "none".into(),
            tag,
        };
        FollowupRun {
            variant_label: algo.contains('@').then(|| "still distractor".into()),
            ..FollowupRun::test_run(key, seed, ratio)
        }
    }

    fn committed() -> crate::claims::ClaimsFile {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../data/paper")
            .join(FILE);
        let text = std::fs::read_to_string(&path).unwrap();
        parse_claims(&text, &path).unwrap()
    }

    /// Every condition a committed follow-up claim names (but the authors' own) is run by a
    /// committed campaign of the follow-up (`followup` and its tagged variants): a claim retargeted
    /// to an algorithm no campaign runs would print "not run" for ever.
    #[test]
    fn the_committed_claims_name_conditions_the_followup_campaigns_run() {
        let campaigns = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/campaigns");
        let mut run = BTreeSet::new();
        for name in ["followup", "followup-still"] {
            let text = std::fs::read_to_string(campaigns.join(format!("{name}.toml"))).unwrap();
            let t: toml::Table = toml::from_str(&text).unwrap();
            let tag = t["campaign"].get("tag").and_then(|v| v.as_str());
            for algo in t["matrix"]["algos"].as_array().unwrap() {
                let algo = algo.as_str().unwrap();
                run.insert(tag.map_or(algo.to_string(), |t| format!("{algo}@{t}")));
            }
        }
        let file = committed();
        assert!(file.claims.len() >= 17, "{} claims", file.claims.len());
        for c in &file.claims {
            for sel in [&c.subject, &c.reference] {
                for algo in sel.algo.iter().flatten() {
                    if algo.ends_with(&format!("@{}", authors::TAG)) {
                        continue;
                    }
                    assert!(
                        run.contains(algo),
                        "{}: no follow-up campaign runs {algo}",
                        c.id
                    );
                }
            }
        }
        // Each claim on the exploration ratio has its twin on the goal-reaching error.
        for c in file
            .claims
            .iter()
            .filter(|c| c.statistic == Statistic::BallRatio && !c.ours)
        {
            let twin = format!("{}-goal-error", c.id);
            let t = file.claims.iter().find(|t| t.id == twin);
            assert!(
                t.is_some_and(|t| t.statistic == Statistic::GoalError),
                "{}: no {twin}",
                c.id
            );
        }
    }

    #[test]
    fn verdicts_follow_the_intervals() {
        let mut runs = Vec::new();
        for s in 0..5 {
            runs.push(run("rpe", s, 0.10 + 0.001 * s as f64));
            runs.push(run("mge-efr-flat", s, 0.20 + 0.002 * s as f64));
            runs.push(run("mge-efr-lp", s, 0.30 + 0.002 * s as f64));
            runs.push(run("mge-efr-flat@still", s, 0.35 + 0.002 * s as f64));
        }
        let still = runs.iter().find(|r| r.cond.tag() == "still").unwrap();
        assert_eq!(
            display(&runs, &still.cond),
            "RGE-EFR (flat), still distractor"
        );
        let file = committed();
        let c = evaluate_on(
            &file,
            &FollowupObservations {
                runs: &runs,
                authors: None,
            },
        );
        let get = |id: &str| c.iter().find(|c| c.claim.id == id).unwrap();
        assert_eq!(verdict(get("C4")), "reproduced");
        assert_eq!(get("C4").comparisons.len(), 2);
        assert_eq!(verdict(get("C6")), "reproduced");
        // Variant campaigns are not goal explorers of C6.
        assert!(
            get("C6")
                .comparisons
                .iter()
                .all(|c| c.subject.tag.is_none())
        );
        assert!(
            verdict(get("C1")).contains("not run"),
            "{}",
            verdict(get("C1"))
        );
        assert!(verdict(get("C1")).starts_with("premise not met"));
        // Swap: the flat one wins.
        for r in &mut runs {
            if r.key.algo == "mge-efr-flat" && r.key.tag.is_none() {
                r.ball_coverage[0] *= 3.0;
            }
        }
        let c = evaluate_on(
            &file,
            &FollowupObservations {
                runs: &runs,
                authors: None,
            },
        );
        let c4 = c.iter().find(|c| c.claim.id == "C4").unwrap();
        assert_eq!(verdict(c4), "not reproduced");

        // The findings state each verdict, the decided ones first, and list the claims not run.
        let f = findings(&runs, &c);
        let line = |id: &str| {
            f.lines()
                .position(|l| l.contains(&format!("({id}, on ")))
                .unwrap_or_else(|| panic!("no finding for {id}:\n{f}"))
        };
        assert!(
            f.lines()
                .nth(line("C4"))
                .unwrap()
                .contains("**not reproduced**"),
            "{f}"
        );
        assert!(
            f.lines()
                .nth(line("C6"))
                .unwrap()
                .contains("**reproduced**")
        );
        assert!(line("C4") < line("C6"), "{f}");
        let not_run = f.lines().find(|l| l.starts_with("- Not run")).unwrap();
        assert!(not_run.contains("C1"), "{not_run}");
    }

    /// Our runs in the authors' environment are compared with their published summary at their
    /// last point (9666 rollouts): our ratio at the last evaluation before it, Welch's interval
    /// from their n, mean and sd; a run of another environment is not compared with them.
    #[test]
    fn runs_are_compared_with_the_authors_at_their_last_point() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper");
        let authors = authors::load(&dir).unwrap().unwrap();
        let theirs = authors.of(&"mge-efr-lp".into()).unwrap().at(9666).unwrap();
        let claims = parse_claims(
            "[settings]\nconfidence = 0.95\nmargin = 0.0\n[[claim]]\nid = \"A\"\nsource = \"s\"\n\
             quote = \"q\"\nstatement = \"s\"\nstatistic = \"ball_ratio\"\n\
             relation = \"similar\"\nrelative_margin = 0.1\n\
             subject = { algo = [\"mge-efr-lp\"] }\nreference = { algo = [\"mge-efr-lp@authors\"] }\n\
             pair_on = [\"learner\"]\n",
            std::path::Path::new("t.toml"),
        )
        .unwrap();
        let (reachable, all) = ball_cells();
        let corl = |seed: i64, at_9657: f64| {
            let mut r = run("mge-efr-lp", seed, 0.0);
            r.key.env = "armballs-corl".into();
            r.epochs = vec![333, 9657, 9990];
            // The last evaluation (after their last point) must not be the one compared.
            r.ball_coverage = vec![0.01, at_9657, 0.99]
                .into_iter()
                .map(|v| v * all / reachable)
                .collect();
            r
        };
        let near: Vec<FollowupRun> = (0..20)
            .map(|s| corl(s, theirs.mean + 0.002 * (s % 5) as f64 - 0.004))
            .collect();
        let obs = FollowupObservations {
            runs: &near,
            authors: Some(&authors),
        };
        let c = evaluate_on(&claims, &obs);
        let cmp = &c[0].comparisons;
        assert_eq!(cmp.len(), 1, "{cmp:?}");
        assert_eq!(cmp[0].n_reference, theirs.n);
        assert!((cmp[0].reference_mean - theirs.mean).abs() < 1e-15);
        assert!(
            (cmp[0].subject_mean - theirs.mean).abs() < 1e-9,
            "{}",
            cmp[0].subject_mean
        );
        assert_eq!(verdict(&c[0]), "reproduced");
        assert!(name(&near, &cmp[0].reference).ends_with("the authors' runs"));
        // Far below theirs: not reproduced.
        let far: Vec<FollowupRun> = (0..20).map(|s| corl(s, 0.3 + 0.001 * s as f64)).collect();
        let obs = FollowupObservations {
            runs: &far,
            authors: Some(&authors),
        };
        assert_eq!(verdict(&evaluate_on(&claims, &obs)[0]), "not reproduced");
        // Runs of another environment: the authors' conditions are not there to compare with.
        let dmp: Vec<FollowupRun> = (0..5).map(|s| run("mge-efr-lp", s, 0.5)).collect();
        let obs = FollowupObservations {
            runs: &dmp,
            authors: Some(&authors),
        };
        assert!(evaluate_on(&claims, &obs)[0].comparisons.is_empty());
    }

    /// The premise is checked per network: a claim about a disentangled space compares the
    /// repetitions whose β-VAE has an active ball-only and an active distractor-only latent, and
    /// a latent that collapsed (KL below 0.5 nats) does not count even where its mean still
    /// follows the distractor.
    #[test]
    fn the_premise_is_checked_per_network() {
        // Seeds 0-3: the β-VAE is disentangled and explores more than the VAE; seeds 4-5: its
        // distractor latent collapsed (its mean still follows the distractor) and it explores less.
        let networks = |kl_distractor: &dyn Fn(i64) -> Option<f64>| -> Vec<FollowupRun> {
            let mut runs = Vec::new();
            for s in 0..6 {
                let good = s < 4;
                let mut b = run(
                    "mge-conv-bvae-lp",
                    s,
                    if good { 0.5 + 0.01 * s as f64 } else { 0.1 },
                );
                b.learner = Some("conv-bvae".into());
                b.per_latent = Some((vec![0.9, 0.02, 0.0], vec![0.01, 0.8, 0.0]));
                b.kl_per_latent = kl_distractor(s).map_or(Vec::new(), |k| vec![3.0, k, 0.0]);
                let mut v = run(
                    "mge-conv-vae-lp",
                    s,
                    if good { 0.3 + 0.005 * s as f64 } else { 0.6 },
                );
                v.learner = Some("conv-vae".into());
                v.per_latent = Some((vec![0.5, 0.4, 0.3], vec![0.4, 0.5, 0.3]));
                (v.knn_ball, v.knn_distractor) = (Some(0.95), Some(0.7));
                runs.extend([b, v]);
            }
            runs
        };
        let file = committed();
        let c1 = |runs: &[FollowupRun]| {
            let obs = FollowupObservations {
                runs,
                authors: None,
            };
            let c = evaluate_on(&file, &obs);
            c.into_iter().find(|c| c.claim.id == "C1").unwrap()
        };
        let c = c1(&networks(&|s| Some(if s < 4 { 3.0 } else { 0.01 })));
        let p = c.premise.as_ref().unwrap();
        assert!(p.met);
        assert!(
            p.counted.contains("none of both: 4 of 6; ")
                && p.counted.contains("not disentangled: 6 of 6; ")
                && p.counted
                    .ends_with("compared on the 4 repetitions that meet it"),
            "{}",
            p.counted
        );
        assert_eq!(c.comparisons.len(), 1);
        assert_eq!(
            (c.comparisons[0].n_subject, c.comparisons[0].n_reference),
            (4, 4)
        );
        assert!(c.comparisons[0].paired);
        assert_eq!(verdict(&c), "reproduced");
        // Without the per-latent KL every latent counts: all six repetitions are compared, and
        // there the difference is not shown (the two entangled β-VAEs explore far less).
        let c = c1(&networks(&|_| None));
        assert!(c.premise.as_ref().unwrap().counted.contains("6 of 6"));
        assert_eq!(c.comparisons[0].n_subject, 6);
        assert_eq!(verdict(&c), "inconclusive");
        // No network disentangled: the premise is not met, and the difference on all six
        // repetitions is shown beside it.
        let c = c1(&networks(&|_| Some(0.0)));
        assert!(!c.premise.as_ref().unwrap().met);
        assert_eq!(c.comparisons[0].n_subject, 6);
        assert!(verdict(&c).starts_with("premise not met"));
    }

    /// The entangled control is checked per network too: a VAE whose code holds one object
    /// only (distractor-blind) or that happens to be disentangled is not the control, so its
    /// repetition is left out of the claims that compare with it (C1 with the β-VAE's part, C7
    /// alone).
    #[test]
    fn the_entangled_control_is_checked_per_network() {
        let mut runs = Vec::new();
        for s in 0..6 {
            let mut b = run("mge-conv-bvae-lp", s, 0.5 + 0.01 * s as f64);
            b.learner = Some("conv-bvae".into());
            b.per_latent = Some((vec![0.9, 0.02, 0.0], vec![0.01, 0.8, 0.0]));
            b.kl_per_latent = vec![3.0, 3.0, 0.0];
            // Seeds 0-3 the control; seed 4 blind to the distractor; seed 5 disentangled.
            let mut v = run("mge-conv-vae-lp", s, 0.3 + 0.005 * s as f64);
            v.learner = Some("conv-vae".into());
            v.per_latent = Some(if s == 5 {
                (vec![0.9, 0.0, 0.0], vec![0.0, 0.9, 0.0])
            } else {
                (vec![0.5, 0.4, 0.3], vec![0.4, 0.5, 0.3])
            });
            (v.knn_ball, v.knn_distractor) = (Some(0.95), Some(if s == 4 { -0.1 } else { 0.7 }));
            let mut f = run("mge-conv-vae-flat", s, 0.4 + 0.005 * s as f64);
            f.learner = v.learner.clone();
            (f.per_latent, f.knn_ball, f.knn_distractor) =
                (v.per_latent.clone(), v.knn_ball, v.knn_distractor);
            runs.extend([b, v, f]);
        }
        let file = committed();
        let obs = FollowupObservations {
            runs: &runs,
            authors: None,
        };
        let results = evaluate_on(&file, &obs);
        let get = |id: &str| results.iter().find(|c| c.claim.id == id).unwrap();
        for id in ["C1", "C7"] {
            let c = get(id);
            let p = c.premise.as_ref().unwrap();
            assert!(p.met, "{id}");
            assert!(
                p.counted.contains("not disentangled: 4 of 6"),
                "{id}: {}",
                p.counted
            );
            assert!(
                p.counted
                    .ends_with("compared on the 4 repetitions that meet it"),
                "{id}: {}",
                p.counted
            );
            assert_eq!(
                (c.comparisons[0].n_subject, c.comparisons[0].n_reference),
                (4, 4),
                "{id}"
            );
            assert_eq!(verdict(c), "reproduced", "{id}");
        }
        // Every control blind to the distractor: C7's premise is not met.
        for r in runs
            .iter_mut()
            .filter(|r| r.learner.as_deref() == Some("conv-vae"))
        {
            r.knn_distractor = Some(0.05);
        }
        let obs = FollowupObservations {
            runs: &runs,
            authors: None,
        };
        let c7 = evaluate_on(&file, &obs)
            .into_iter()
            .find(|c| c.claim.id == "C7")
            .unwrap();
        assert!(!c7.premise.as_ref().unwrap().met);
        assert!(verdict(&c7).starts_with("premise not met"));
    }

    /// A premise names at least one part, and never one learner as both.
    #[test]
    fn a_premise_is_checked_when_the_file_is_read() {
        let file = |premise: &str| {
            parse_claims(
                &format!(
                    "[settings]\nconfidence = 0.95\nmargin = 0.0\n[[claim]]\nid = \"A\"\n\
                     source = \"s\"\nquote = \"q\"\nstatement = \"s\"\n\
                     statistic = \"ball_ratio\"\nrelation = \"greater\"\n\
                     subject = {{ algo = [\"a\"] }}\nreference = {{ algo = [\"b\"] }}\n\
                     premise = {premise}\n"
                ),
                std::path::Path::new("t.toml"),
            )
        };
        assert!(file("{ entangled = \"conv-vae\" }").is_ok());
        let e = file("{}").unwrap_err().to_string();
        assert!(e.contains("names `disentangled` or `entangled`"), "{e}");
        let e = file("{ disentangled = \"x\", entangled = \"x\" }")
            .unwrap_err()
            .to_string();
        assert!(e.contains("both disentangled and entangled"), "{e}");
    }

    #[test]
    fn ball_module_share_picks_the_ball_module() {
        let mut r = run("mge-efr-lp", 0, 0.3);
        r.modules.insert(0, ("ball".into(), vec![0, 1]));
        r.modules.insert(1, ("distractor".into(), vec![2, 3]));
        r.interest = vec![(100, 0, 0.5, 80), (100, 1, 0.1, 20), (50, 0, 0.5, 1)];
        assert_eq!(ball_module_goals(&r), Some(0.8));
        // A learned space: the module whose latents encode the ball best.
        let mut l = run("mge-bvae-lp", 0, 0.3);
        l.modules.insert(0, ("0".into(), vec![0]));
        l.modules.insert(1, ("1".into(), vec![1]));
        l.per_latent = Some((vec![0.1, 0.9], vec![0.8, 0.0]));
        l.interest = vec![(100, 0, 0.5, 70), (100, 1, 0.1, 30)];
        assert_eq!(ball_module_goals(&l), Some(0.3));
        assert_eq!(ball_module_goals(&run("rpe", 0, 0.1)), None);
    }
}
