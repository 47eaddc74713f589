//! The *Findings* at the top of `REPORT.md`: a few sentences, each generated from the verdicts
//! and numbers of the sections below (the claims marked with a [`Finding`] in the claims file,
//! the validity check, the training-budget campaigns) and linking to the section that backs it.
//! Nothing is written per result: change a number below and the sentence that states it changes.

use std::fmt::Write as _;

use super::claims::{Validity, validity_of};
use crate::claims::{ClaimResult, ClaimsInput, Comparison, Finding, Statistic};
use crate::context::Context;
use crate::discovery::{Check, Measure};
use crate::names::env_name;
use crate::stats;

/// Anchors of the sections the findings link to.
const CLAIMS: &str = "#the-papers-claims";
const OURS: &str = "#our-findings-not-claims-of-the-paper";
const VALIDITY: &str = "#what-the-exploration-discovered-without-counting-repeats";
const BUDGET: &str = "#training-budget-sensitivity";

/// A difference with its sign, in the statistic's units (cells reached in percentage points,
/// said once after a range by [`unit`]).
fn signed(statistic: Statistic, v: f64) -> String {
    match statistic {
        Statistic::Coverage => format!("{:+.1}", 100.0 * v),
        Statistic::Moved => format!("{v:+.0}"),
        _ => format!("{v:+.3}"),
    }
}

/// The unit said after a difference or a range of them.
fn unit(statistic: Statistic) -> &'static str {
    match statistic {
        Statistic::Coverage => " points",
        _ => "",
    }
}

/// A value in the statistic's units.
fn plain(statistic: Statistic, v: f64) -> String {
    match statistic {
        Statistic::Coverage => format!("{:.1}%", 100.0 * v),
        Statistic::Moved => format!("{v:.0}"),
        _ => format!("{v:.3}"),
    }
}

/// Whether the subject is worse (`Some(true)`) or better (`Some(false)`) than the reference in
/// a comparison whose interval excludes 0; None where it does not (or there is none).
fn direction(c: &Comparison) -> Option<bool> {
    let (lo, hi) = c.bounds()?;
    let higher = if lo > 0.0 {
        true
    } else if hi < 0.0 {
        false
    } else {
        return None;
    };
    Some(higher != c.statistic.higher_is_better())
}

/// `goal-reaching error (mean) Δ +0.020 to +0.072, worse in 8 of 8 (intervals excluding 0)`,
/// per statistic of `comparisons`, in order of appearance.
fn per_statistic(comparisons: &[Comparison]) -> String {
    let mut order: Vec<Statistic> = Vec::new();
    for c in comparisons {
        if !order.contains(&c.statistic) {
            order.push(c.statistic);
        }
    }
    order
        .into_iter()
        .map(|st| {
            let these: Vec<&Comparison> =
                comparisons.iter().filter(|c| c.statistic == st).collect();
            let lo = these.iter().map(|c| c.diff).fold(f64::INFINITY, f64::min);
            let hi = these
                .iter()
                .map(|c| c.diff)
                .fold(f64::NEG_INFINITY, f64::max);
            let range = if these.len() == 1 {
                format!("Δ {}{}", signed(st, lo), unit(st))
            } else {
                format!("Δ {} to {}{}", signed(st, lo), signed(st, hi), unit(st))
            };
            let worse = these.iter().filter(|c| direction(c) == Some(true)).count();
            let better = these.iter().filter(|c| direction(c) == Some(false)).count();
            format!(
                "{} {range}: worse in {worse}, better in {better} of {} (intervals excluding 0)",
                st.label(),
                these.len()
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The reference condition's mean of each statistic, where every comparison has one reference
/// condition: `RGE-EFR 0.054 (goal-reaching error (mean))`.
fn reference_levels(comparisons: &[Comparison]) -> String {
    let Some(first) = comparisons.first() else {
        return String::new();
    };
    if comparisons.iter().any(|c| {
        c.reference.tagged_algo() != first.reference.tagged_algo()
            || c.reference.env != first.reference.env
    }) {
        return String::new();
    }
    let mut seen: Vec<Statistic> = Vec::new();
    let mut parts = Vec::new();
    for c in comparisons {
        if !seen.contains(&c.statistic) {
            seen.push(c.statistic);
            parts.push(format!(
                "{} {}",
                c.statistic.label(),
                plain(c.statistic, c.reference_mean)
            ));
        }
    }
    format!(
        " ({}: {})",
        crate::names::tagged_condition_name(&first.reference),
        parts.join(", ")
    )
}

/// The verdict on the claim's own measure, labelled with the validity check's judgement of it.
fn own_verdict(r: &ClaimResult, checks: &[Check]) -> String {
    let label = match validity_of(r.claim.statistic, &r.comparisons, checks) {
        Validity::Passes => String::new(),
        Validity::Fails(envs) => {
            format!(", which fails the validity check on {}", envs.join(" and "))
        }
        Validity::Unchecked => ", which the validity check does not cover".to_string(),
    };
    format!(
        "**{}** on the {}{label}",
        r.verdict.label(),
        r.claim.statistic.label()
    )
}

/// One claim of the paper with a twin: the validated verdict and its numbers first, then the
/// verdict on the paper's measure.
fn paper_claim(w: &mut String, title: &str, r: &ClaimResult, checks: &[Check], anchor: &str) {
    match &r.twin {
        Some(t) => {
            let _ = writeln!(
                w,
                "- **{title}** ([`{}`]({anchor})): **{}** on the measures that pass the validity \
                 check: {}{}. The same claim is {}.",
                r.claim.id,
                t.verdict.label(),
                per_statistic(&t.comparisons),
                reference_levels(&t.comparisons),
                own_verdict(r, checks)
            );
        }
        None => {
            let _ = writeln!(
                w,
                "- **{title}** ([`{}`]({anchor})): {}: {}{}.",
                r.claim.id,
                own_verdict(r, checks),
                per_statistic(&r.comparisons),
                reference_levels(&r.comparisons),
            );
        }
    }
}

/// Claims of ours on one measure each: one clause per claim.
fn our_claims(w: &mut String, title: &str, rs: &[&ClaimResult], checks: &[Check]) {
    if rs.is_empty() {
        return;
    }
    let parts: Vec<String> = rs
        .iter()
        .map(|r| {
            format!(
                "`{}` {}: {}",
                r.claim.id,
                own_verdict(r, checks),
                per_statistic(&r.comparisons)
            )
        })
        .collect();
    let _ = writeln!(w, "- **{title}** ([ours]({OURS})): {}.", parts.join("; "));
}

/// The training-budget sentence: each budget series' goal-reaching error per budget, against
/// RGE-EFR's on the same environment (Welch's interval at the largest budget); then, where a
/// recipe campaign trained the series' cell longer than every budget (`paper-long`, the paper's
/// own budget), its error beside the main campaign's on the same repetitions and the verdict of
/// the main claim on that cell with either network ([`recipe_budget`]).
fn budget(w: &mut String, inp: &Context<'_>) {
    for s in &inp.budget.series {
        let goal_by_seed = |campaign: &str, algo: &str| -> Vec<(i64, f64)> {
            let values: Vec<(i64, f64)> = inp
                .discovery
                .iter()
                .filter(|r| {
                    r.campaign.name == campaign
                        && r.run.key.env == s.key.env
                        && r.run.key.algo == algo
                        && (algo != s.key.algo || r.run.key == s.key)
                })
                .filter_map(|r| Some((r.run.seed, r.discovery.as_ref()?.goal_error_mean)))
                .collect();
            crate::aggregate::seed_means(&values)
        };
        let goal = |campaign: &str, algo: &str| -> Vec<f64> {
            goal_by_seed(campaign, algo)
                .into_iter()
                .map(|v| v.1)
                .collect()
        };
        let main = &inp.campaigns.main.name;
        let efr = goal(main, &ugl_types::Algo::RGE_EFR);
        let mut points: Vec<(i64, Vec<f64>)> = Vec::new();
        for p in s.points.iter().chain(&s.main) {
            for c in &p.campaigns {
                let v = goal(c, &s.key.algo);
                if !v.is_empty() {
                    points.push((p.iterations, v));
                }
            }
        }
        points.sort_by_key(|p| p.0);
        let (Some(last), false) = (points.last(), efr.is_empty()) else {
            continue;
        };
        let listed: Vec<String> = points
            .iter()
            .map(|(it, v)| format!("{:.3} at {it} iterations (n = {})", stats::mean(v), v.len()))
            .collect();
        let vs_efr = match stats::welch_interval(&last.1, &efr, stats::CONFIDENCE) {
            Ok(i) => format!(
                "; at {} iterations it is {:+.3} [{:+.3}, {:+.3}] from RGE-EFR's {:.3}",
                last.0,
                i.estimate,
                i.lo,
                i.hi,
                stats::mean(&efr)
            ),
            Err(_) => String::new(),
        };
        let longer = recipe_budget(inp, &s.key, last.0, &goal_by_seed);
        let _ = writeln!(
            w,
            "- **The training budget** ([budget]({BUDGET})): {}, {}: goal-reaching error {}{vs_efr} \
             ({:.0}% Welch interval){longer}.",
            env_name(&s.key.env),
            crate::names::describe_key(&s.key),
            listed.join(", "),
            stats::CONFIDENCE * 100.0
        );
    }
}

/// The clause on a recipe campaign that trained `cell` for more iterations than `beyond`: its
/// goal-reaching error beside the main campaign's on the repetitions both ran, and the verdict
/// of the main claim on this cell ([`Finding::LearnedVsEfr`]) on the validated measures with the
/// main campaign's networks and with the recipe's ([`crate::claims::cell_verdicts`]). Empty
/// where there is none.
fn recipe_budget(
    inp: &Context<'_>,
    cell: &crate::load::ConditionKey,
    beyond: i64,
    goal_by_seed: &dyn Fn(&str, &str) -> Vec<(i64, f64)>,
) -> String {
    let validated = match inp.claims {
        ClaimsInput::Evaluated { validated, .. } => *validated,
        ClaimsInput::Missing(_) => None,
    };
    let mut out = String::new();
    for v in inp
        .recipe_verdicts
        .iter()
        .filter(|v| &v.cell == cell && v.main.claim.finding == Some(Finding::LearnedVsEfr))
    {
        let Some(camp) = inp.campaigns.recipe.iter().find(|c| c.tag() == v.tag) else {
            continue;
        };
        let iterations: Option<i64> = camp
            .store
            .runs
            .iter()
            .filter(|r| &r.key == cell)
            .filter_map(|r| crate::neural::training(&r.manifest)?.iterations)
            .max();
        let Some(iterations) = iterations.filter(|&i| i > beyond) else {
            continue;
        };
        let on_reps = |campaign: &str| -> Vec<(i64, f64)> {
            goal_by_seed(campaign, &cell.algo)
                .into_iter()
                .filter(|(seed, _)| v.repetitions.contains(seed))
                .collect()
        };
        let (long, short) = (on_reps(&camp.name), on_reps(&inp.campaigns.main.name));
        // The difference paired by repetition (each pair shares its data set and streams).
        let paired = if crate::claims::is_paired(&long, &short) {
            let d: Vec<f64> = long.iter().zip(&short).map(|(a, b)| a.1 - b.1).collect();
            stats::t_interval(&d, stats::CONFIDENCE)
                .map(|i| {
                    format!(
                        " (Δ {:+.3} [{:+.3}, {:+.3}], {:.0}% t interval paired by repetition)",
                        i.estimate,
                        i.lo,
                        i.hi,
                        stats::CONFIDENCE * 100.0
                    )
                })
                .unwrap_or_default()
        } else {
            String::new()
        };
        let long: Vec<f64> = long.into_iter().map(|v| v.1).collect();
        let short: Vec<f64> = short.into_iter().map(|v| v.1).collect();
        let (Some((a, _)), Some((b, _))) =
            (v.main.validated(validated), v.recipe.validated(validated))
        else {
            continue;
        };
        if long.is_empty() || short.is_empty() {
            continue;
        }
        let reps = v.repetitions.len();
        let _ = write!(
            out,
            "; trained {iterations} iterations (`{}`, the same {reps} repetitions) it reaches \
             {:.3} against {:.3} with `{}`'s networks{paired}, and the main claim ([`{}`]({CLAIMS})) on \
             this cell is **{}** on the validated measures with the longer training, **{}** with \
             `{}`'s ([recipes](#training-recipes))",
            camp.name,
            stats::mean(&long),
            stats::mean(&short),
            inp.campaigns.main.name,
            v.main.claim.id,
            b.label(),
            a.label(),
            inp.campaigns.main.name,
        );
    }
    out
}

/// The validity sentence: per environment, the final KLC's and the goal error's P(better)
/// against the controls, and whether each passes.
fn validity(w: &mut String, checks: &[Check]) {
    let mut envs: Vec<&str> = checks.iter().map(|c| c.env.as_str()).collect();
    envs.dedup();
    if envs.is_empty() {
        return;
    }
    let line = |m: Measure, env: &str| -> Option<String> {
        let cs: Vec<&Check> = checks
            .iter()
            .filter(|c| c.measure == m && c.env == env)
            .collect();
        let lo = cs.iter().map(|c| c.p_better).fold(f64::INFINITY, f64::min);
        let hi = cs
            .iter()
            .map(|c| c.p_better)
            .fold(f64::NEG_INFINITY, f64::max);
        let passes = crate::discovery::passes(checks, m, env)?;
        Some(format!(
            "{} {lo:.2} to {hi:.2} ({})",
            m.label(),
            if passes { "passes" } else { "fails" }
        ))
    };
    let per_env: Vec<String> = envs
        .iter()
        .filter_map(|env| {
            let klc = line(Measure::FinalKlc, env)?;
            let goal = line(Measure::GoalErrorMean, env)?;
            Some(format!("{}: {klc}, {goal}", env_name(env)))
        })
        .collect();
    let _ = writeln!(
        w,
        "- **KL-coverage as a measure of discovery** ([validity check]({VALIDITY})): the \
         probability that a run of a goal space encoding the object's position beats a control \
         run, against each kind of control (random projection, untrained networks): {}. A \
         measure passes when the lower bound of every such interval is above {}; one that \
         ranks the controls level with or ahead of position-encoding goal spaces measures how \
         often the object moved, not what was discovered.",
        per_env.join("; "),
        crate::discovery::PASS_LOWER_BOUND
    );
}

/// The Findings section.
pub fn findings(w: &mut String, inp: &Context<'_>) {
    let ClaimsInput::Evaluated { results, .. } = inp.claims else {
        return;
    };
    let tagged = |f: Finding| -> Vec<&ClaimResult> {
        results
            .iter()
            .filter(|r| r.claim.finding == Some(f))
            .collect()
    };
    let _ = writeln!(w, "## Findings\n");
    let _ = writeln!(
        w,
        "Generated from the verdicts and numbers of the sections they link to (nothing here is \
         written by hand per result). Δ is subject − reference of the means over repetitions; \
         *worse* and *better* count the comparisons whose {:.0}% interval excludes 0.\n",
        stats::CONFIDENCE * 100.0
    );
    for r in tagged(Finding::LearnedVsRpe) {
        paper_claim(
            w,
            "Learned goal spaces vs random exploration",
            r,
            inp.validity,
            CLAIMS,
        );
    }
    for r in tagged(Finding::LearnedVsEfr) {
        let env = r
            .comparisons
            .first()
            .map(|c| env_name(&c.subject.env))
            .unwrap_or_default();
        let title = format!("Learned goal spaces vs RGE-EFR on {env} (the paper's main claim)");
        paper_claim(w, &title, r, inp.validity, CLAIMS);
    }
    our_claims(
        w,
        "Learned goal spaces vs the controls",
        &tagged(Finding::LearnedVsControls),
        inp.validity,
    );
    for r in tagged(Finding::GoalSamplers) {
        paper_claim(
            w,
            "KDE vs Gaussian-prior goals (the paper's Figure 4; subject: Gaussian)",
            r,
            inp.validity,
            CLAIMS,
        );
    }
    our_claims(
        w,
        "Goals in the arrow's angle",
        &tagged(Finding::Angle),
        inp.validity,
    );
    budget(w, inp);
    validity(w, inp.validity);
    let _ = writeln!(w);
}
