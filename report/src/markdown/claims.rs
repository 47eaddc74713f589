//! The claims table and the leaderboard of `REPORT.md`.

use std::fmt::Write as _;

use super::{fmt_klc, plural};
use crate::claims::{
    ClaimResult, ClaimsInput, Comparison, Quantifier, Statistic, ToDecide, Verdict, lean, to_decide,
};
use crate::context::Context;
use crate::leaderboard::Entry;
use crate::names::describe_key;
use crate::names::{condition_name, env_name, sampler_name};

/// The symbol of a verdict.
fn mark(v: Verdict) -> &'static str {
    match v {
        Verdict::Reproduced => "✅",
        Verdict::NotReproduced => "❌",
        Verdict::Inconclusive => "❔",
    }
}

/// The symbol and the verdict in words: `✅ reproduced`.
fn verdict_mark(v: Verdict) -> String {
    format!("{} {}", mark(v), v.label())
}

fn value(statistic: Statistic, v: f64) -> String {
    match statistic {
        Statistic::Moved if v.is_finite() => format!("{v:.0}"),
        Statistic::Coverage if v.is_finite() => format!("{:.1}%", 100.0 * v),
        _ => fmt_klc(v),
    }
}

fn signed(statistic: Statistic, v: f64) -> String {
    let s = value(statistic, v);
    if v > 0.0 && !s.starts_with('+') {
        format!("+{s}")
    } else {
        s
    }
}

/// One comparison on one line: `ArmBall: RGE-VAE (faithful), KDE goals, 2 latents vs RGE-EFR:
/// Δ = −0.52 [−0.71, −0.33] ✅`; a mark the multiple-comparison correction changed is followed
/// by the uncorrected one (`❔ (❌ uncorrected)`); no interval is said in words.
fn comparison_line(c: &Comparison) -> String {
    let statistic = c.statistic;
    let interval = match c.bounds() {
        Some((lo, hi)) => format!("[{}, {}]", signed(statistic, lo), signed(statistic, hi)),
        None if c.n_subject < 2 || c.n_reference < 2 => {
            "(no interval: fewer than 2 seeds on a side)".into()
        }
        None => "(no interval: an infinite value)".into(),
    };
    let correction = if c.verdict == c.uncorrected {
        String::new()
    } else {
        format!(" ({} uncorrected)", mark(c.uncorrected))
    };
    format!(
        "{}: {} vs {}: Δ = {} {interval} {}{correction}",
        env_name(&c.subject.env),
        describe_key(&c.subject),
        describe_key(&c.reference),
        signed(statistic, c.diff),
        mark(c.verdict),
    )
}

/// How a measure fared in the validity check, over the environments of some comparisons.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Validity {
    /// It passes in every environment it is used in.
    Passes,
    /// It fails in these environments (display names).
    Fails(Vec<String>),
    /// The check has no line for it (or for one of its environments).
    Unchecked,
}

/// The validity check's verdict on `statistic` in the environments of `comparisons`.
pub(crate) fn validity_of(
    statistic: Statistic,
    comparisons: &[Comparison],
    checks: &[crate::discovery::Check],
) -> Validity {
    let Some(measure) = statistic.checked_as() else {
        return Validity::Unchecked;
    };
    let mut envs: Vec<&str> = comparisons.iter().map(|c| c.subject.env.as_str()).collect();
    envs.sort_by_key(|e| (ugl_types::EnvSpec::order(e), e.to_string()));
    envs.dedup();
    let mut fails = Vec::new();
    for env in envs {
        match crate::discovery::passes(checks, measure, env) {
            Some(true) => {}
            Some(false) => fails.push(env_name(env)),
            None => return Validity::Unchecked,
        }
    }
    if fails.is_empty() {
        Validity::Passes
    } else {
        Validity::Fails(fails)
    }
}

/// The label of a verdict on a measure the validity check does not pass.
fn validity_note(v: &Validity) -> &'static str {
    match v {
        Validity::Passes => "",
        Validity::Fails(_) => " ⚠ fails the validity check",
        Validity::Unchecked => " ⚠ not in the validity check",
    }
}

/// A verdict with, where undecided, the way it leans and the repetitions that would decide it
/// that way: `❔ leans ❌, ~37 repetitions`.
fn verdict_cell(v: Verdict, comparisons: &[Comparison], q: Quantifier, alpha: f64) -> String {
    if v != Verdict::Inconclusive || comparisons.is_empty() {
        return verdict_mark(v);
    }
    let Some(way) = lean(comparisons, q) else {
        return verdict_mark(v);
    };
    let have = comparisons
        .iter()
        .map(|c| c.n_subject.min(c.n_reference))
        .min()
        .unwrap_or(0);
    let reps = match to_decide(comparisons, q, alpha) {
        ToDecide::Repetitions(n) if n > 1000.0 => "over 1000 repetitions".to_string(),
        ToDecide::Repetitions(n) => format!("~{n:.0} repetitions"),
        ToDecide::Never => "a Δ on a boundary: never".to_string(),
        ToDecide::Unknown => "repetitions unknown".to_string(),
    };
    format!(
        "{} leans {}, {reps} to decide ({have} run)",
        mark(v),
        mark(way)
    )
}

/// How the claims' intervals and verdicts are computed, for the claims sections of the report
/// and of the follow-up's page (`confidence` in (0, 1)).
pub fn method_text(confidence: f64) -> String {
    let level = confidence * 100.0;
    format!(
        "Each comparison is Δ = subject − reference of the mean over repetitions. A repetition \
         (seed) has its own data set and fit, and its exploration replicates share them, so a \
         condition's value per repetition is the mean over its replicates and the repetitions \
         are the independent observations. When both sides ran the same repetitions (any two \
         conditions of one campaign), the interval is the {level:.0}% paired t interval of the \
         per-repetition differences (Student 1908): the learners of a repetition share its data \
         set and exploration streams, so the pairing removes what they share. Otherwise it is \
         Welch's t interval (Welch 1947: independent sides, variances not assumed equal). No \
         interval with fewer than 2 repetitions on a side. In a seeded simulation at the \
         measured spread (`report/src/stats/coverage.rs`: 4000 replicates per case) the nominal \
         95% intervals cover 0.93-0.97: Welch's at 5 and 20 seeds per side, on normal samples \
         and on skewed (lognormal) ones, and the paired one on the two-level design at 5 x 1 \
         and 10 x 3 (repetitions x replicates), with correlated or independent fits; the \
         percentile \
         bootstrap used before covered 0.85-0.88 at 5 seeds, and BCa no better. No interval \
         computed from 5 seeds covers a rare outlier (a seed stuck at RPE level with \
         probability 0.1: 0.89; 0.91 at 20 seeds). A comparison is *reproduced* (✅) when its \
         whole interval lies in the set of differences the claim requires, *not reproduced* \
         (❌) when the interval lies entirely outside it, and *inconclusive* (❔) otherwise: too \
         few seeds to tell. A claim is reproduced when every comparison is, not reproduced when \
         any is not (or as its *most* / *at least one* quantifier says). **Multiple \
         comparisons:** where a verdict follows from *some* of a claim's comparisons (*not \
         reproduced* of an every-comparison claim; both verdicts of a *most* claim; \
         *reproduced* of an *at least one* claim), their tests are corrected with Holm's \
         step-down procedure (Holm 1979), so that the chance of that verdict being wrong stays \
         at {:.0}% for the claim; a comparison that does not survive the correction is ❔, \
         followed by its uncorrected mark. A verdict that needs every comparison needs no \
         correction (an intersection-union test, Berger 1982). Each claim is its own family: \
         across claims nothing is corrected.",
        100.0 - level
    )
}

/// Counts of verdicts: reproduced, not reproduced, undecided leaning reproduced, undecided
/// leaning not reproduced.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Counts {
    pub yes: usize,
    pub no: usize,
    pub lean_yes: usize,
    pub lean_no: usize,
}

impl Counts {
    fn add(&mut self, v: Verdict, comparisons: &[Comparison], q: Quantifier) {
        match (v, lean(comparisons, q)) {
            (Verdict::Reproduced, _) => self.yes += 1,
            (Verdict::NotReproduced, _) => self.no += 1,
            (Verdict::Inconclusive, Some(Verdict::Reproduced)) => self.lean_yes += 1,
            (Verdict::Inconclusive, _) => self.lean_no += 1,
        }
    }

    fn words(&self) -> String {
        format!(
            "{} reproduced, {} not reproduced, {} undecided ({} leaning ✅, {} leaning ❌)",
            self.yes,
            self.no,
            self.lean_yes + self.lean_no,
            self.lean_yes,
            self.lean_no
        )
    }
}

/// The paper's claims counted on the validated measures (`validated`) and on the paper's own
/// measures (`own`), and the claims without a validated verdict.
pub(crate) fn counts(
    results: &[ClaimResult],
    validated: Option<&crate::claims::Validated>,
) -> (Counts, Counts, Vec<Statistic>) {
    let (mut on_validated, mut own, mut none) = (Counts::default(), Counts::default(), Vec::new());
    for r in results.iter().filter(|r| !r.claim.ours) {
        own.add(r.verdict, &r.comparisons, r.claim.quantifier);
        match r.validated(validated) {
            Some((v, cs)) => on_validated.add(v, cs, r.claim.quantifier),
            None => none.push(r.claim.statistic),
        }
    }
    (on_validated, own, none)
}

/// The names of the validated measures, in words.
fn validated_names(validated: Option<&crate::claims::Validated>) -> String {
    validated
        .map(|v| {
            v.statistics
                .iter()
                .map(|s| s.label())
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default()
}

/// The count of verdicts for the top of the report, if claims were evaluated: first on the
/// measures that pass the validity check, then on the paper's own.
pub fn summary_line(w: &mut String, inp: &Context<'_>) {
    if let ClaimsInput::Evaluated {
        results, validated, ..
    } = inp.claims
    {
        let papers = results.iter().filter(|r| !r.claim.ours).count();
        let ours = match results.len() - papers {
            0 => String::new(),
            1 => " (1 finding of ours is listed apart)".to_string(),
            n => format!(" ({n} findings of ours are listed apart)"),
        };
        let (on_validated, own, none) = counts(results, *validated);
        let own_fails = results.iter().filter(|r| !r.claim.ours).any(|r| {
            validity_of(r.claim.statistic, &r.comparisons, inp.validity) != Validity::Passes
        });
        if validated.is_some() {
            let _ = writeln!(
                w,
                "**The paper's claims** ([details](#the-papers-claims)), {papers} evaluated on \
                 these results{ours}. On the measures of discovery that pass the validity check \
                 ({}): {}; {} claim{} no validated measure ({}). \
                 On the paper's own measures (KL-coverage, episodes that moved the object){}: \
                 {}.\n",
                validated_names(*validated),
                on_validated.words(),
                none.len(),
                if none.len() == 1 { " has" } else { "s have" },
                {
                    let mut labels: Vec<&str> = Vec::new();
                    for l in none.iter().map(|s| s.label()) {
                        if !labels.contains(&l) {
                            labels.push(l);
                        }
                    }
                    labels.join(", ")
                },
                if own_fails {
                    ", which fail the validity check or are not in it"
                } else {
                    ""
                },
                own.words(),
            );
        } else {
            let _ = writeln!(
                w,
                "**The paper's claims** ([details](#the-papers-claims)), {papers} evaluated on \
                 these results{ours}: {}.\n",
                own.words()
            );
        }
    }
}

/// The claims section.
pub fn claims(w: &mut String, inp: &Context<'_>) {
    let _ = writeln!(w, "## The paper's claims\n");
    let (path, confidence, margin, target, validated, results) = match inp.claims {
        ClaimsInput::Missing(p) => {
            let _ = writeln!(
                w,
                "No claims file at `{}`: nothing evaluated.\n",
                p.display()
            );
            return;
        }
        ClaimsInput::Evaluated {
            path,
            confidence,
            margin,
            target_half_width,
            validated,
            results,
        } => (
            path,
            *confidence,
            *margin,
            *target_half_width,
            *validated,
            *results,
        ),
    };
    let _ = writeln!(
        w,
        "Each claim of the paper's Sections 4 and 5, written as a testable statement in `{}` and \
         evaluated on the main campaign (no verdict is written by hand). A claim compares \
         *subject* conditions with *reference* conditions on a statistic (final KLC, area under \
         the KLC curve divided by the epoch span, or episodes that moved the object). {} \
         \"No worse\" and \"similar\" allow a margin of {margin} (KLC nats unless the claim \
         sets its own).",
        path.display(),
        method_text(confidence)
    );
    if let Some(v) = validated {
        let margins: Vec<String> = v
            .margin
            .keys()
            .map(|env| {
                let each: Vec<String> = v
                    .statistics
                    .iter()
                    .filter_map(|&st| {
                        v.margin(env, st)
                            .map(|m| format!("{} {}", st.label(), value(st, m)))
                    })
                    .collect();
                format!("{}: {}", env_name(env), each.join(", "))
            })
            .collect();
        let _ = writeln!(
            w,
            "\n**Two verdicts per claim.** The paper measures exploration with KL-coverage, \
             which fails the validity check of [What the exploration discovered]\
             (#what-the-exploration-discovered-without-counting-repeats) (it rewards moving the \
             object often, not discovering much). So each claim of the paper stated on the final \
             KLC or on the episodes moved is tested again, with the same conditions, relation \
             and quantifier, on the measures that pass the check ({}), each with its own margin \
             (one tenth of the gap between RGE-EFR and RPE on the measure; the claims file says \
             how it was chosen): {}. All its comparisons on all those measures form one family \
             (quantifier and Holm's correction over them together). A claim on the speed of \
             exploration (the area under the KLC curve) has no such twin: the validated \
             measures are recorded at the last epoch only. ⚠ marks a verdict on a measure \
             that fails the validity check, or that the check does not cover. An undecided \
             verdict says which way its estimates lean (the verdict if each comparison were \
             judged by its estimate alone) and how many repetitions per condition would \
             decide it that way if the differences and spread held: the interval's \
             half-width shrinks as 1/√n, at the level the verdict is tested at (Holm's \
             strictest step, α/k, where the correction applies). Every comparison, with both \
             verdicts: [`data/{}`](data/{}).",
            validated_names(Some(v)),
            margins.join("; "),
            crate::data::claims::CSV_FILE,
            crate::data::claims::CSV_FILE,
        );
        let status: Vec<String> = v
            .statistics
            .iter()
            .filter_map(|&st| {
                let m = st.checked_as()?;
                let mut envs: Vec<String> = Vec::new();
                for c in inp.validity.iter().filter(|c| c.measure == m) {
                    let line = format!(
                        "{} {}",
                        env_name(&c.env),
                        match crate::discovery::passes(inp.validity, m, &c.env) {
                            Some(true) => "passes",
                            _ => "**fails**",
                        }
                    );
                    if !envs.contains(&line) {
                        envs.push(line);
                    }
                }
                (!envs.is_empty()).then(|| format!("{} ({})", st.label(), envs.join(", ")))
            })
            .collect();
        if !status.is_empty() {
            let _ = writeln!(
                w,
                "\nIn the validity check: {}. {}",
                status.join("; "),
                crate::markdown::discovery::data_used(inp.campaigns)
            );
        }
    }
    if let Some((half, n)) = crate::claims::precision(results) {
        let _ = writeln!(
            w,
            "\n**Precision:** the median half-width of the {level:.0}% intervals of the {n} \
             comparisons of the paper's claims on KL-coverage is {half:.3} nats{}.",
            match target {
                Some(t) if half <= t => format!(
                    ", within the {t} nats the main campaign was designed for \
                     (`target_half_width` in the claims file)"
                ),
                Some(t) => format!(
                    ", **wider than the {t} nats the main campaign was designed for** \
                     (`target_half_width` in the claims file)"
                ),
                None => String::new(),
            },
            level = confidence * 100.0
        );
    }
    if let Some(line) = design_measured(inp) {
        let _ = writeln!(w, "\n{line}");
    }
    // Untrained networks: counted, never silently part of a verdict.
    let flags: Vec<bool> = inp
        .store
        .runs
        .iter()
        .filter_map(|r| r.manifest.trained())
        .collect();
    let neural = inp
        .store
        .runs
        .iter()
        .filter(|r| {
            ugl_types::LearnerInfo::by_algo(&r.key.algo)
                .is_some_and(|l| l.in_paper && l.is_neural())
        })
        .count();
    let untrained = flags.iter().filter(|t| !**t).count();
    let _ = writeln!(
        w,
        "\n{}",
        if neural == 0 {
            String::new()
        } else if flags.is_empty() {
            format!(
                "**Training evidence not recorded** for the {neural} AE, VAE and RFVAE runs of \
                 these results (written before results version 2): verdicts on those learners \
                 may rest on networks that never left the mean-image plateau."
            )
        } else {
            format!(
                "**{untrained} of {} AE, VAE and RFVAE runs** did not leave the mean-image \
                 plateau (\"Did the goal spaces learn?\"); the verdicts include them.",
                flags.len()
            )
        }
    );
    if inp.conditions.iter().any(|c| {
        c.runs
            .iter()
            .any(|&i| inp.store.runs[i].manifest.reduced_budget)
    }) {
        let _ = writeln!(
            w,
            "Verdicts on the neural learners (AE, VAE, RFVAE) hold for the reduced training \
             budgets of this campaign (†), not necessarily for the paper's."
        );
    }
    let _ = writeln!(w);
    let contradicted: Vec<&str> = results
        .iter()
        .filter(|r| r.paper.as_ref().and_then(|p| p.holds) == Some(false))
        .map(|r| r.claim.id.as_str())
        .collect();
    let _ = writeln!(
        w,
        "*The paper's own numbers*: each claim is also evaluated on the paper's reference values \
         (`data/paper/klc_final.csv`, read from its figures; single runs, so Δ without an \
         interval). ✅: they satisfy the statement; ❌: **contradicted by the paper's own \
         figure** (a verdict against it says little about our reproduction); —: the paper \
         gives no value for these comparisons. Contradicted: {}.",
        if contradicted.is_empty() {
            "none".to_string()
        } else {
            contradicted
                .iter()
                .map(|c| format!("`{c}`"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    let _ = writeln!(w);
    let alpha = 1.0 - confidence;
    let (papers, ours): (Vec<&ClaimResult>, Vec<&ClaimResult>) =
        results.iter().partition(|r| !r.claim.ours);
    claims_table(w, &papers, validated, inp.validity, alpha);
    if !ours.is_empty() {
        let _ = writeln!(
            w,
            "### Our findings (not claims of the paper)\n\nStatements of ours, tested the same \
             way (e.g. a claim of the paper re-tested on the corrected variants, or a learner \
             against its controls), each on the measure it names; not counted in the \
             headline.{}\n",
            if inp.campaigns.validation.is_empty() {
                " The claims that a trained network beats its untrained twin, or a learned \
                 space the random projection, rest on the runs the validity check also uses: \
                 they are not independent of it."
            } else {
                " The validity check runs on held-out repetitions: the claims against the \
                 controls are independent of it."
            }
        );
        claims_table(w, &ours, validated, inp.validity, alpha);
    }
}

fn claims_table(
    w: &mut String,
    results: &[&ClaimResult],
    validated: Option<&crate::claims::Validated>,
    checks: &[crate::discovery::Check],
    alpha: f64,
) {
    let _ = writeln!(
        w,
        "| claim | testable statement | on the paper's measure | on the validated measures | the paper's own numbers |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|");
    for r in results {
        let q = r.claim.quantifier;
        let own_validity = validity_of(r.claim.statistic, &r.comparisons, checks);
        let own = format!(
            "{}<br>{}{}",
            verdict_cell(r.verdict, &r.comparisons, q, alpha),
            r.claim.statistic.label(),
            validity_note(&own_validity)
        );
        let on_validated = match r.validated(validated) {
            Some((v, cs)) if r.twin.is_some() => verdict_cell(v, cs, q, alpha),
            Some(_) => "(the same: its measure is validated)".to_string(),
            None if r.claim.statistic == Statistic::Auc => {
                "— (speed: no validated measure)".to_string()
            }
            None => "—".to_string(),
        };
        let _ = writeln!(
            w,
            "| `{}` | {} | {own} | {on_validated} | {} |",
            r.claim.id,
            cell(&r.claim.statement),
            paper_cell(r.paper.as_ref()),
        );
    }
    let _ = writeln!(w);
    // The evidence, folded: the paper's words, what the statement requires, every comparison.
    let _ = writeln!(
        w,
        "<details><summary>Evidence: the paper's words and every comparison of these {} \
         claims</summary>\n",
        results.len()
    );
    for r in results {
        let requires = match r.claim.quantifier.label() {
            "" => r.claim.relation.describe(r.margin),
            q => format!("{} in {q}", r.claim.relation.describe(r.margin)),
        };
        let _ = writeln!(
            w,
            "**`{}`**: *“{}”* ({}). Requires {requires}, Δ of the {}.\n",
            r.claim.id,
            r.claim.quote,
            r.claim.source,
            r.claim.statistic.label()
        );
        if r.comparisons.is_empty() {
            let _ = writeln!(w, "- no condition of the main campaign matches");
        }
        for c in &r.comparisons {
            let _ = writeln!(w, "- {}", comparison_line(c));
        }
        if let Some(t) = &r.twin {
            let _ = writeln!(
                w,
                "\nOn the validated measures ({}):\n",
                verdict_mark(t.verdict)
            );
            if t.comparisons.is_empty() {
                let _ = writeln!(w, "- no condition with a validated measure and a margin");
            }
            for c in &t.comparisons {
                let _ = writeln!(
                    w,
                    "- {}, requires {}: {}",
                    c.statistic.label(),
                    c.relation.describe(c.margin),
                    comparison_line(c)
                );
            }
        }
        if let Some(p) = &r.paper
            && p.holds == Some(false)
        {
            let _ = writeln!(w, "\nThe paper's own values that contradict it:\n");
            for c in p.comparisons.iter().filter(|c| !c.holds) {
                let _ = writeln!(
                    w,
                    "- {}: {} vs {}: Δ = {}",
                    env_name(&c.subject.env),
                    describe_key(&c.subject),
                    describe_key(&c.reference),
                    signed(r.claim.statistic, c.diff)
                );
            }
        }
        let _ = writeln!(w);
    }
    let _ = writeln!(w, "</details>\n");
}

/// The paper's-own-numbers cell: the verdict and how many comparisons it rests on (the failing
/// ones are in the evidence).
fn paper_cell(check: Option<&crate::claims::PaperCheck>) -> String {
    let Some(check) = check else {
        return "—".into();
    };
    match check.holds {
        None => "— not reported".into(),
        Some(true) => format!(
            "✅ satisfy ({} comparison{})",
            check.comparisons.len(),
            plural(check.comparisons.len())
        ),
        Some(false) => format!(
            "**❌ contradicted** ({} of {} comparison{})",
            check.comparisons.iter().filter(|c| !c.holds).count(),
            check.comparisons.len(),
            plural(check.comparisons.len())
        ),
    }
}

/// Text safe inside a table cell.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn ci3(t: (f64, f64, f64)) -> String {
    format!("{:.3} [{:.3}, {:.3}]", t.0, t.1, t.2)
}

fn tasks_cell(e: &Entry, all: usize) -> String {
    if e.tasks.len() == all {
        format!("all {all}")
    } else {
        let names: Vec<String> = e
            .tasks
            .iter()
            .map(|(env, l)| format!("{} {l}", env_name(env)))
            .collect();
        format!("{} of {all}: {}", e.tasks.len(), names.join(", "))
    }
}

/// The probability of improvement over RGE-EFR with its counts: the bootstrap interval, or at
/// 0 or 1 (every pair one way, where the bootstrap interval is degenerate) the exact bound.
fn poi_cell(e: &Entry, alpha: f64) -> String {
    let (Some((p, lo, hi)), Some((wins, pairs, units))) = (e.poi_vs_efr, e.poi_counts) else {
        return "—".into();
    };
    let counts = format!("{wins} of {pairs} pairs");
    // At an extreme, every pair goes one way: so does every repetition.
    let extreme = if wins == 0.0 {
        Some(0.0)
    } else if wins == pairs as f64 {
        Some(units as f64)
    } else {
        None
    };
    match extreme.and_then(|k| crate::stats::exact_bound_at_extreme(k, units, alpha)) {
        Some((0.0, b)) => format!("{p:.3}, {counts}; exact bound ≤ {b:.3} ({units} repetitions)"),
        Some((b, _)) => format!("{p:.3}, {counts}; exact bound ≥ {b:.3} ({units} repetitions)"),
        None => format!("{p:.3} [{lo:.3}, {hi:.3}], {counts}"),
    }
}

/// The leaderboard section.
pub fn leaderboard(w: &mut String, inp: &Context<'_>) {
    let lb = inp.leaderboard;
    if lb.entries.is_empty() {
        return;
    }
    let alpha = 1.0 - lb.confidence;
    let _ = writeln!(w, "## Leaderboard (rliable statistics)\n");
    let tasks: Vec<String> = lb
        .tasks
        .iter()
        .map(|(env, l)| format!("{} with {l} latents", env_name(env)))
        .collect();
    let _ = writeln!(
        w,
        "Every algorithm of the main campaign, and every learner added with `ugl compare` \
         (campaigns `compare-*`, run on the same cells and seeds), over the {} tasks ({}), with \
         the statistics of Agarwal et al. (2021, *rliable*). A value is a repetition's (the mean \
         over its exploration replicates). **Ranked by the goal-reaching error**, which passes \
         the validity check: per task, the interquartile mean (IQM) of the normalised error (the \
         mean distance from a fixed grid of test goals to the nearest outcome, divided by the \
         error of an exploration that never moved the object: 0 reaches every goal, 1 never \
         moved it), then the **mean of the per-task IQMs**, which does not pool tasks whose \
         errors sit at different floors (RGE-EFR's is lower on ArmBall than on ArmArrow). \
         *Rank*: with its {level:.0}% interval over the bootstrap replicates (every entry's \
         replicate ranked together; entries whose intervals overlap are not told apart). \
         *Final*: IQM of the final KLC normalised by the KLC of outcomes all in one cell ({}; \
         0 a perfect cover, 1 the object never moved), pooled over the tasks; *speed*: likewise \
         for the area under the KLC curve; KL-coverage fails the validity check, so neither \
         ranks. *P(better than EFR)*: the probability that a repetition of the entry beats one \
         of RGE-EFR on the same task, on the goal error (the final KLC for an entry without \
         it), averaged over tasks, with the pairs it counts; where every pair goes one way the \
         bootstrap interval is degenerate, and the exact (Clopper-Pearson) bound is given over \
         the independent repetitions (the smaller side's, summed over tasks) instead. Brackets: \
         {level:.0}% stratified bootstrap intervals ({} resamples, repetitions resampled within \
         each task, seeded). *Coverage*: the mean fraction of the achievable cells reached, per \
         environment (each run once). *Untrained*: runs whose network did not leave the \
         mean-image plateau, counted in; *at RPE level*: runs that moved the object fewer than \
         twice as often as RPE. *Paper*: the mean of the paper's normalised single-run final \
         values on the same tasks, where it gives all of them (never for the corrected variants, \
         which the paper did not run). Baselines do not depend on the latent size: their runs \
         serve both tasks of an environment. †: trained or explored below the paper's budget \
         (\"What was run\"); entries missing a task come last. Every number: \
         [`data/{}`](data/{}).\n",
        lb.tasks.len(),
        tasks.join(", "),
        super::paper_envs(|e| format!("ln {} on {}", e.klc.achievable_cells, e.display)),
        lb.n_boot,
        crate::data::leaderboard::CSV_FILE,
        crate::data::leaderboard::CSV_FILE,
        level = lb.confidence * 100.0,
    );
    let envs: Vec<&str> = {
        let mut v: Vec<&str> = lb.tasks.iter().map(|t| t.0.as_str()).collect();
        v.dedup();
        v
    };
    let _ = writeln!(
        w,
        "| rank | algorithm | goal sampler | campaign | tasks | repetitions | untrained | at RPE level | goal error (mean of task IQMs) | final (IQM) | speed (IQM) | coverage ({}) | P(better than EFR) | paper |",
        envs.iter()
            .map(|e| env_name(e))
            .collect::<Vec<_>>()
            .join(" / ")
    );
    let _ = writeln!(
        w,
        "|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|"
    );
    let n = lb.tasks.len();
    for (i, e) in lb.entries.iter().enumerate() {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            match (e.is_complete(n), e.rank_interval) {
                (true, Some((lo, hi))) => format!("{} [{lo}, {hi}]", i + 1),
                (true, None) => (i + 1).to_string(),
                (false, _) => "—".into(),
            },
            entry_name(e, inp),
            sampler_name(&e.sampler),
            super::campaign_name(&e.campaign),
            tasks_cell(e, n),
            e.n_reps,
            match e.untrained {
                Some(0) => "0".to_string(),
                Some(k) => format!("**{k}**"),
                None => "—".into(),
            },
            match e.at_rpe_level {
                Some(0) => "0".to_string(),
                Some(k) => format!("**{k}**"),
                None => "—".into(),
            },
            e.goal_task_mean.map(ci3).unwrap_or_else(|| "—".into()),
            ci3(e.final_iqm),
            e.auc_iqm.map(ci3).unwrap_or_else(|| "—".into()),
            envs.iter()
                .map(|env| {
                    e.coverage_by_env
                        .iter()
                        .find(|(x, _)| x == env)
                        .map(|(_, c)| format!("{:.1}%", 100.0 * c))
                        .unwrap_or_else(|| "—".into())
                })
                .collect::<Vec<_>>()
                .join(" / "),
            poi_cell(e, alpha),
            e.paper
                .map(|p| format!("{p:.3}"))
                .unwrap_or_else(|| "—".into())
        );
    }
    // Per task: the IQM of the normalised goal error and the rank within the task.
    let _ = writeln!(
        w,
        "\n**Per task**: the IQM of the normalised goal-reaching error, and (in brackets) the \
         entry's rank among the entries with that task.\n"
    );
    let _ = writeln!(
        w,
        "| algorithm | goal sampler | campaign | {} |\n|---|---|---|{}",
        tasks.join(" | "),
        "---:|".repeat(lb.tasks.len())
    );
    let value = |e: &Entry, t: &crate::leaderboard::Task| -> Option<f64> {
        let i = e.tasks.iter().position(|x| x == t)?;
        e.goal_task_iqm.get(i).copied().flatten()
    };
    for e in &lb.entries {
        let cells: Vec<String> = lb
            .tasks
            .iter()
            .map(|t| match value(e, t) {
                Some(v) => {
                    let rank = 1 + lb
                        .entries
                        .iter()
                        .filter(|o| value(o, t).is_some_and(|x| x < v))
                        .count();
                    format!("{v:.3} ({rank})")
                }
                None => "—".into(),
            })
            .collect();
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} |",
            entry_name(e, inp),
            sampler_name(&e.sampler),
            super::campaign_name(&e.campaign),
            cells.join(" | ")
        );
    }
    let new = inp.campaigns.compare.len();
    let _ = writeln!(
        w,
        "\n{}",
        if new == 0 {
            "No `compare-*` campaign in the store: to rank a new learner, run `ugl compare \
             --learner NAME [--command CMD]` (README, *Add your own learner*) and re-render."
                .to_string()
        } else {
            format!(
                "{new} `compare-*` campaign{} in the store; new learners are in **bold**. One \
                 page each (rank, probability of improvement over every algorithm, failures, \
                 coverage, latent R²): {}.",
                plural(new),
                inp.campaigns
                    .compare
                    .iter()
                    .map(|c| {
                        let f = super::compare::file_name(&c.name);
                        format!("[`{f}`]({f})")
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    );
    let _ = writeln!(w);
}

/// An entry's name in the leaderboard: † for a reduced budget, bold and "(new)" for a
/// `compare-*` learner.
fn entry_name(e: &Entry, inp: &Context<'_>) -> String {
    let name = condition_name(&e.algo, &e.variant);
    let name = if e.reduced_budget {
        format!("{name} †")
    } else {
        name
    };
    if e.campaign != inp.campaigns.main.name {
        format!("**{name}** (new)")
    } else {
        name
    }
}

/// The design's two levels measured on the main campaign's own runs: the median over its
/// conditions of the final KLC's spread due to the repetition (data set and fit) and due to the
/// exploration streams ([`crate::stats::components::one_way`]); None without exploration
/// replicates.
fn design_measured(inp: &Context<'_>) -> Option<String> {
    let mut fitted: Vec<(f64, f64)> = Vec::new();
    let mut baselines: Vec<(f64, f64)> = Vec::new();
    let mut baseline_names: Vec<String> = Vec::new();
    let (mut reps, mut replicates) = (0, 0);
    for c in inp.conditions.iter().filter(|c| c.replicates >= 2) {
        let groups: Vec<Vec<f64>> = c
            .seeds
            .iter()
            .map(|&seed| {
                c.runs
                    .iter()
                    .map(|&i| &inp.store.runs[i])
                    .filter(|r| r.seed == seed)
                    .map(|r| r.final_point().klc)
                    .collect()
            })
            .collect();
        let Some(k) = crate::stats::components::one_way(&groups) else {
            continue;
        };
        reps = reps.max(c.seeds.len());
        replicates = replicates.max(c.replicates);
        if ugl_types::LearnerInfo::by_algo(&c.key.algo).is_some() {
            fitted.push((k.between_sd, k.within_sd));
        } else {
            baselines.push((k.between_sd, k.within_sd));
            let name = condition_name(&c.key.algo, &c.key.variant);
            if !baseline_names.contains(&name) {
                baseline_names.push(name);
            }
        }
    }
    if fitted.is_empty() {
        return None;
    }
    let medians = |v: &[(f64, f64)]| {
        let b: Vec<f64> = v.iter().map(|x| x.0).collect();
        let e: Vec<f64> = v.iter().map(|x| x.1).collect();
        Some((ugl_types::median(&b)?, ugl_types::median(&e)?))
    };
    let (fb, fe) = medians(&fitted)?;
    let mut line = format!(
        "**The design, measured on these runs** (`docs/statistics.md`): over the {} conditions \
         of fitted goal spaces (the learners and the random projection) with {reps} repetitions x {replicates} exploration replicates, \
         the final KLC's standard deviation due to the repetition (its data set and fit) has a \
         median of {fb:.2} nats, and the part due to the exploration streams {fe:.2} \
         (one-way random-effects analysis per condition, method of moments)",
        fitted.len()
    );
    if let Some((bb, be)) = medians(&baselines) {
        let _ = write!(
            line,
            "; for the {} conditions without a fitted goal space ({}), where a repetition \
             changes only the exploration streams, {bb:.2} and {be:.2}",
            baselines.len(),
            baseline_names.join(", ")
        );
    }
    line.push_str(
        ". Exploration replicates shrink the exploration part of a condition's mean; only more \
         repetitions shrink the fit's, and pairing two conditions on the same repetitions \
         removes what they share.",
    );
    Some(line)
}
