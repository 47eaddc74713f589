//! The words of `REPORT.md`, one function per part (the sections of [`crate::sections`] call
//! them in order): what was run, the figures, the table of final KL-coverage against the paper,
//! the deviations. Pure functions of their inputs (sorted iteration everywhere, no clock):
//! rendering twice gives the same bytes.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use crate::aggregate::ConditionSummary;
use crate::context::Context;
use crate::figures::FigureFile;
use crate::load::{Run, campaign_display};
use crate::names::{algo_name, describe_key, env_name};
use crate::options::ReportOptions;
use ugl_types::CampaignRole;

pub mod claims;
pub mod compare;
pub mod discovery;
pub mod findings;
pub mod neural;
pub mod predicts;
pub mod quality;
pub mod recipe;

/// The text of the epoch-label note (docs/original-code.md section 4).
pub const EPOCH_NOTE: &str = "The paper's notebooks labelled the snapshot holding 100i+12 outcomes as \
epoch 100(i+1), i.e. shifted by ~90 epochs, and never plotted the last ~190 outcomes; our epochs are \
exact counts of exploration iterations (`docs/original-code.md` section 4).";

/// KLC with 3 decimals; `inf` spelled out.
pub fn fmt_klc(v: f64) -> String {
    if v.is_nan() {
        "n/a".into()
    } else if v == f64::INFINITY {
        "inf".into()
    } else if v == f64::NEG_INFINITY {
        "-inf".into()
    } else {
        format!("{v:.3}")
    }
}

/// An interval of a mean, `[lo, hi]`; `—` for none.
pub fn fmt_ci(ci: Option<(f64, f64)>) -> String {
    match ci {
        Some((lo, hi)) => format!("[{}, {}]", fmt_klc(lo), fmt_klc(hi)),
        None => "—".into(),
    }
}

/// A duration in seconds, in the most readable unit.
pub fn fmt_duration(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.1} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.2} h", s / 3600.0)
    }
}

/// Distinct values with their counts: `a (3), b (1)`; `not recorded (n)` for missing ones.
fn distinct(values: impl Iterator<Item = Option<String>>) -> String {
    let mut m: BTreeMap<String, usize> = BTreeMap::new();
    let mut missing = 0;
    for v in values {
        match v {
            Some(v) => *m.entry(v).or_default() += 1,
            None => missing += 1,
        }
    }
    let mut parts: Vec<String> = m
        .into_iter()
        .map(|(v, n)| format!("`{}` ({n} run{})", v.replace('`', "'"), plural(n)))
        .collect();
    if missing > 0 {
        parts.push(format!("not recorded ({missing} run{})", plural(missing)));
    }
    parts.join(", ")
}

/// Distinct values, compactly: `4` when all agree, `3 (240), 4 (12)` when they do not, `—` for
/// none; missing ones count as `?`.
fn compact(values: impl Iterator<Item = Option<String>>) -> String {
    let mut m: BTreeMap<String, usize> = BTreeMap::new();
    for v in values {
        *m.entry(v.unwrap_or_else(|| "?".into())).or_default() += 1;
    }
    match m.len() {
        0 => "—".into(),
        1 => m.into_keys().next().unwrap_or_default(),
        _ => m
            .into_iter()
            .map(|(v, n)| format!("{v} ({n})"))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

pub(crate) fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

fn campaign_name(c: &str) -> String {
    campaign_display(c)
}

/// Seeds as a compact list: `0–4` when contiguous, else `0, 2, 7`.
pub(crate) fn fmt_seeds(seeds: &[i64]) -> String {
    let mut s = seeds.to_vec();
    s.sort_unstable();
    s.dedup();
    match (s.first(), s.last()) {
        (Some(a), Some(b)) if s.len() > 2 && (b - a) as usize + 1 == s.len() => format!("{a}–{b}"),
        _ => s.iter().map(i64::to_string).collect::<Vec<_>>().join(", "),
    }
}

fn fmt_epochs(e: &[i64]) -> String {
    e.iter().map(i64::to_string).collect::<Vec<_>>().join(", ")
}

/// What holds of the runs' bytes across machines, by their results version: from version 5 a
/// run's bytes are the same on every x86-64 CPU and kernel path; before, within one SIMD level.
fn reproducibility(runs: &[crate::load::Run]) -> &'static str {
    let cross_machine = |r: &crate::load::Run| r.manifest.results_version().is_some_and(|v| v >= 5);
    if runs.iter().all(cross_machine) {
        "Results are bit-for-bit the same on every x86-64 CPU, whatever its SIMD level"
    } else if runs.iter().any(cross_machine) {
        "Results of version 5 on are bit-for-bit the same on every x86-64 CPU, whatever its SIMD \
         level; earlier ones within one SIMD level"
    } else {
        "Results are bit-for-bit reproducible within one SIMD level"
    }
}

/// The campaign's compute: exploration plus representation fits, a shared fit (the KDE and
/// Gaussian runs of a neural cell share one training, identified by `train.key`) counted once.
fn compute_line(w: &mut String, runs: &[crate::load::Run]) {
    let explore: f64 = runs
        .iter()
        .map(|r| r.manifest.wall_s + r.manifest.encode_s.unwrap_or(0.0))
        .sum();
    let mut fits: BTreeMap<String, f64> = BTreeMap::new();
    for r in runs {
        if let Some(f) = r.manifest.fit_s {
            // A fit is shared by the runs that differ only in their goal sampler or exploration
            // replicate: a network's training key, or the condition and repetition otherwise.
            let key = crate::neural::training(&r.manifest)
                .and_then(|t| t.key)
                .unwrap_or_else(|| {
                    format!(
                        "{}/{}/{}/{}/{}/{}",
                        r.campaign, r.key.env, r.key.algo, r.key.latents, r.key.variant, r.seed
                    )
                });
            let e = fits.entry(key).or_insert(0.0);
            *e = e.max(f);
        }
    }
    if fits.is_empty() && explore == 0.0 {
        return;
    }
    let fit: f64 = fits.values().sum();
    let total = explore + fit;
    let _ = writeln!(
        w,
        "- **Compute:** {} of worker time, the sum of the manifests' times (a campaign may run \
         in several resumed chunks): {} fitting {} representation{} (rendering the UGL data set \
         and training; a fit shared by several runs counted once) and {} exploring and encoding. \
         With one worker per core, that is about {} of wall time on 2 cores.",
        fmt_duration(total),
        fmt_duration(fit),
        fits.len(),
        plural(fits.len()),
        fmt_duration(explore),
        fmt_duration(total / 2.0)
    );
}

/// The title, the reduced-budget warning, the claims' headline and a missing paper table.
pub fn header(w: &mut String, inp: &Context<'_>) {
    let _ = writeln!(w, "# ugl-bench: replication report\n");
    let _ = writeln!(
        w,
        "Reproduction of Péré, Forestier, Sigaud and Oudeyer, *Unsupervised Learning of Goal Spaces \
         for Intrinsically Motivated Goal Exploration* (ICLR 2018). Generated by `ugl report` from \
         the results store `{}`; the paper's reference values come from `{}`. *Provenance of \
         those values*: the paper's Figure 2 gives means over 5 runs with 90% confidence \
         intervals and its Figure 4 means and standard deviations over 5 runs, but as plots \
         without numbers; the only numbers we could read are those of the authors' notebooks, \
         which are **single runs**. Our reference values are read off those (±0.03), so they \
         carry no interval, and one of our runs, not our mean, is their yardstick \
         (`data/paper/README.md`).\n",
        inp.opts.results.display(),
        inp.paper.looked_at.display()
    );

    // --- Reduced budget: one line here, the table under "What was run".
    let (used, reduced) = budget_runs(inp);
    if !reduced.is_empty() {
        let _ = writeln!(
            w,
            "> **⚠ Reduced budget.** {} of the {} runs in this report (every campaign it renders) \
             were run with a budget reduced relative to the paper's; their numbers are not \
             directly comparable with the paper's. Conditions with such runs are marked † in the \
             tables; [What was run](#{}) lists the reductions by algorithm.\n",
            reduced.len(),
            used.len(),
            what_was_run_anchor(&inp.campaigns.main.name)
        );
    }
    let mixed: Vec<String> = inp
        .campaigns
        .used()
        .filter(|c| c.configurations > 1)
        .map(|c| {
            format!(
                "`{}` ({} configurations)",
                campaign_name(&c.name),
                c.configurations
            )
        })
        .collect();
    if !mixed.is_empty() {
        let _ = writeln!(
            w,
            "> **⚠ Mixed configurations.** The runs of {} were run with different \
             configurations (campaign seed, `[explore]`, `[env]` or `[ugl]` differ between \
             their manifests), and the statistics below pool them. Rerun such a campaign into \
             a store of its own.\n",
            mixed.join(", ")
        );
    }
    claims::summary_line(w, inp);
    if inp.paper.path.is_none() {
        let _ = writeln!(
            w,
            "> **Paper reference values not found** at `{}`: the comparison columns are empty.\n",
            inp.paper.looked_at.display()
        );
    }
}

/// The runs of every campaign the report renders, and those of them with a budget reduced from
/// the paper's.
fn budget_runs<'a>(inp: &'a Context<'_>) -> (Vec<&'a Run>, Vec<&'a Run>) {
    let used: Vec<&Run> = inp
        .campaigns
        .used()
        .flat_map(|c| c.store.runs.iter())
        .collect();
    let reduced = used
        .iter()
        .copied()
        .filter(|r| r.manifest.reduced_budget)
        .collect();
    (used, reduced)
}

/// The anchor of the "What was run" heading for the main campaign `main`.
fn what_was_run_anchor(main: &str) -> String {
    format!(
        "what-was-run-main-campaign-{}",
        campaign_name(main).to_lowercase()
    )
}

/// The runs with a budget reduced from the paper's, by algorithm and reduction.
fn reduced_table(w: &mut String, inp: &Context<'_>) {
    let (_, reduced) = budget_runs(inp);
    if reduced.is_empty() {
        return;
    }
    // (algorithm, note) -> (runs, campaigns)
    let mut notes: BTreeMap<(String, String), (usize, BTreeSet<String>)> = BTreeMap::new();
    for r in &reduced {
        let e = notes
            .entry((algo_name(&r.key.algo), r.manifest.budget_note.clone()))
            .or_default();
        e.0 += 1;
        e.1.insert(campaign_name(&r.campaign));
    }
    let _ = writeln!(
        w,
        "**Reduced budgets** (marked † in the tables), from the manifests:\n\n\
         | algorithm | reduced relative to the paper | runs | campaigns |\n|---|---|---:|---|"
    );
    for ((algo, note), (n, camps)) in &notes {
        let camps: Vec<&str> = camps.iter().map(String::as_str).collect();
        let _ = writeln!(w, "| {algo} | {note} | {n} | {} |", camps.join(", "));
    }
    let _ = writeln!(w);
}

/// Slugs of the main campaign's conditions with a reduced-budget run (marked † in the tables).
fn reduced_keys(inp: &Context<'_>) -> BTreeSet<String> {
    budget_runs(inp)
        .1
        .iter()
        .filter(|r| r.campaign == inp.campaigns.main.name)
        .map(|r| r.key.slug())
        .collect()
}

fn dagger(reduced_keys: &BTreeSet<String>, c: &ConditionSummary) -> &'static str {
    if reduced_keys.contains(&c.key.slug()) {
        " †"
    } else {
        ""
    }
}

/// The main campaign's environments, in the order of its conditions.
fn envs<'a>(inp: &'a Context<'_>) -> Vec<&'a str> {
    let mut envs: Vec<&str> = Vec::new();
    for c in inp.conditions {
        if !envs.contains(&c.key.env.as_str()) {
            envs.push(&c.key.env);
        }
    }
    envs
}

/// The distinct last epochs of the main campaign's conditions.
fn last_epochs(inp: &Context<'_>) -> Vec<i64> {
    let mut last_epochs: BTreeSet<i64> = BTreeSet::new();
    for c in inp.conditions {
        last_epochs.extend(c.final_epochs.iter().copied());
    }
    last_epochs.into_iter().collect()
}

/// Every campaign the report renders, one row each, from its record and its manifests: role,
/// runs, design (repetitions x exploration replicates), results version, exploration budget,
/// neural training, reduced-budget runs and whether its runs came from a committed tree.
fn campaigns_table(w: &mut String, inp: &Context<'_>) {
    let _ = writeln!(
        w,
        "Every campaign this report renders (its role says what the report does with it; \
         *repetitions x replicates*: distinct repetition seeds x exploration replicates per \
         repetition; *training*: the neural learners' iterations and hidden layers, from the manifests; *tree*: \
         runs whose manifest records a git revision with uncommitted changes (`-dirty`), which no \
         commit reproduces exactly; the command of each campaign is under *How to reproduce*):\n"
    );
    let _ = writeln!(
        w,
        "| campaign | role | runs | conditions | repetitions x replicates | results version | \
         epochs | training | reduced budget | tree |"
    );
    let _ = writeln!(w, "|---|---|---:|---:|---|---|---|---|---:|---|");
    for c in inp.campaigns.used() {
        let runs = &c.store.runs;
        let conditions: BTreeSet<String> = runs.iter().map(|r| r.key.slug()).collect();
        let seeds: BTreeSet<i64> = runs.iter().map(|r| r.seed).collect();
        let replicates: BTreeSet<u32> = runs.iter().map(|r| r.manifest.exploration).collect();
        let versions = compact(
            runs.iter()
                .map(|r| r.manifest.results_version().map(|v| v.to_string())),
        );
        let epochs = compact(runs.iter().map(|r| {
            r.manifest
                .explore
                .get("epochs")
                .and_then(|e| e.as_u64())
                .map(|e| e.to_string())
        }));
        // learner -> distinct (iterations, hidden layers)
        let mut training: BTreeMap<String, BTreeSet<(u64, String)>> = BTreeMap::new();
        for r in runs {
            let Some(config) = r.manifest.train.as_ref().map(|t| &t.config) else {
                continue;
            };
            if let Some(it) = config.get("iterations").and_then(|i| i.as_u64()) {
                let hidden = config
                    .get("hidden")
                    .and_then(|h| h.as_array())
                    .map(|h| {
                        let h: Vec<String> = h.iter().map(|v| v.to_string()).collect();
                        h.join("-")
                    })
                    .unwrap_or_else(|| "?".into());
                training
                    .entry(algo_name(&r.key.algo))
                    .or_default()
                    .insert((it, hidden));
            }
        }
        let training: Vec<String> = training
            .iter()
            .map(|(a, its)| {
                let its: Vec<String> = its
                    .iter()
                    .map(|(it, hidden)| format!("{it} it., {hidden}"))
                    .collect();
                format!("{a} {}", its.join(" / "))
            })
            .collect();
        let reduced = runs.iter().filter(|r| r.manifest.reduced_budget).count();
        let dirty = runs
            .iter()
            .filter(|r| r.manifest.git_revision.ends_with("-dirty"))
            .count();
        let tree = if dirty == 0 {
            "committed".to_string()
        } else {
            format!("**{dirty} `-dirty`**")
        };
        let _ = writeln!(
            w,
            "| `{}` | {} | {} | {} | {} x {} | {} | {} | {} | {} | {} |",
            campaign_name(&c.name),
            c.decl.role.name(),
            runs.len(),
            conditions.len(),
            seeds.len(),
            replicates.len(),
            versions,
            epochs,
            if training.is_empty() {
                "—".to_string()
            } else {
                training.join("; ")
            },
            reduced,
            tree
        );
    }
    let _ = writeln!(w);
    discovery_checks(w, inp);
}

/// How the discovery measures of the runs above were checked (`ugl_types::verify_files` and the
/// loader): how many carry the hash of their record, how many were compared with their kept
/// outcomes file, how many were measured from it, and how many rest on their record alone.
fn discovery_checks(w: &mut String, inp: &Context<'_>) {
    let runs: Vec<&crate::load::Run> = inp
        .campaigns
        .used()
        .flat_map(|c| c.store.runs.iter())
        .collect();
    let recorded = |r: &&&crate::load::Run| r.manifest.discovery.is_some();
    let hashed = runs
        .iter()
        .filter(|r| r.manifest.discovery_blake3.is_some())
        .count();
    let recomputed = runs
        .iter()
        .filter(recorded)
        .filter(|r| r.has_outcomes())
        .count();
    let record_only = runs
        .iter()
        .filter(recorded)
        .filter(|r| !r.has_outcomes())
        .count();
    let measured = runs
        .iter()
        .filter(|r| r.manifest.discovery.is_none())
        .count();
    let _ = writeln!(
        w,
        "The discovery measures of these {} runs (goal-reaching error, cells reached, moved-only \
         KL-coverage): {measured} measured here from their outcomes files (no record); \
         {recomputed} recorded and checked against the same measures recomputed from their kept \
         outcomes files; {record_only} read from their record alone, checked for range and \
         against the run's summary and curve (their outcomes files are not committed). \
         {hashed} of the records carry the hash that detects an edited record (written by the runs \
         of this code on; [`data/results/README.md`](../../data/results/README.md)).\n",
        runs.len()
    );
}

/// What was run: campaigns, runs, seeds, epochs, compute and provenance, the table of conditions.
pub fn what_was_run(w: &mut String, inp: &Context<'_>) {
    let store = inp.store;
    let runs = &store.runs;
    let main = campaign_name(&inp.campaigns.main.name);
    let reduced_keys = reduced_keys(inp);
    let _ = writeln!(w, "## What was run (main campaign `{main}`)\n");
    campaigns_table(w, inp);
    reduced_table(w, inp);
    neural::campaigns_line(w, inp);
    let _ = writeln!(
        w,
        "- **Runs:** {} complete runs of {} conditions in the main campaign `{main}`{}.",
        runs.len(),
        inp.conditions.len(),
        if store.incomplete.is_empty() {
            String::new()
        } else {
            format!(
                "; {} more incomplete (still running or interrupted; listed at the end)",
                store.incomplete.len()
            )
        }
    );
    let mut seed_counts: BTreeMap<usize, usize> = BTreeMap::new();
    for c in inp.conditions {
        *seed_counts.entry(c.seeds.len()).or_default() += 1;
    }
    let seed_counts: Vec<String> = seed_counts
        .iter()
        .rev()
        .map(|(s, n)| format!("{s} seed{} ({n} condition{})", plural(*s), plural(*n)))
        .collect();
    let _ = writeln!(
        w,
        "- **Seeds per condition:** {} (the *seeds* column below and *n* in every table say \
         which).",
        seed_counts.join(", ")
    );
    let _ = writeln!(
        w,
        "- **Exploration epochs:** {} (the paper: 5000).",
        fmt_epochs(&last_epochs(inp))
    );
    let _ = writeln!(
        w,
        "- **Profile:** {}.",
        distinct(runs.iter().map(|r| Some(r.manifest.profile.clone())))
    );
    let walls: Vec<f64> = runs.iter().map(|r| r.manifest.wall_s).collect();
    if walls.is_empty() {
        let _ = writeln!(w, "- **Exploration wall time:** not recorded.");
    } else {
        let total: f64 = walls.iter().sum();
        let min = walls.iter().copied().fold(f64::INFINITY, f64::min);
        let max = walls.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let missing = runs.len() - walls.len();
        let _ = writeln!(
            w,
            "- **Exploration wall time:** {} in total; per run {} on average (min {}, max {}){}.",
            fmt_duration(total),
            fmt_duration(total / walls.len() as f64),
            fmt_duration(min),
            fmt_duration(max),
            if missing > 0 {
                format!("; not recorded for {missing} run{}", plural(missing))
            } else {
                String::new()
            }
        );
    }
    compute_line(w, runs);
    let _ = writeln!(
        w,
        "- **Host:** {}.",
        distinct(runs.iter().map(|r| Some(r.manifest.host.clone())))
    );
    let _ = writeln!(
        w,
        "- **Results version:** {} (`RESULTS_VERSION` of the code that wrote them; a campaign \
         resumed with code of another version reruns those runs).",
        distinct(
            runs.iter()
                .map(|r| r.manifest.results_version().map(|v| v.to_string()))
        )
    );
    let _ = writeln!(
        w,
        "- **CPU (SIMD level):** {}. {} (README, Reproducibility).",
        distinct(runs.iter().map(|r| r.manifest.cpu_label())),
        reproducibility(runs)
    );
    let _ = writeln!(
        w,
        "- **Threads:** {}.",
        distinct(runs.iter().map(|r| Some(r.manifest.threads.to_string())))
    );
    let _ = writeln!(
        w,
        "- **Git revision:** {}.",
        distinct(runs.iter().map(|r| Some(r.manifest.git_revision.clone())))
    );
    let _ = writeln!(
        w,
        "- **Toolchain:** {}.\n",
        distinct(runs.iter().map(|r| Some(r.manifest.toolchain.clone())))
    );

    let _ = writeln!(
        w,
        "| env | algorithm | goal sampler | latents | variant | seeds (× replicates) | epochs | exploration wall time per run (mean; fits apart) |"
    );
    let _ = writeln!(w, "|---|---|---|---:|---|---|---:|---:|");
    for c in inp.conditions {
        let ws: Vec<f64> = c.runs.iter().map(|&i| runs[i].manifest.wall_s).collect();
        let wall = if ws.is_empty() {
            "—".to_string()
        } else {
            fmt_duration(ws.iter().sum::<f64>() / ws.len() as f64)
        };
        let _ = writeln!(
            w,
            "| {} | {}{} | {} | {} | {} | {} ({}) | {} | {} |",
            env_name(&c.key.env),
            crate::names::algo_name(&c.key.algo),
            dagger(&reduced_keys, c),
            c.key.sampler,
            if c.key.latents == 0 {
                "—".to_string()
            } else {
                c.key.latents.to_string()
            },
            c.key.variant,
            c.n_label(),
            fmt_seeds(&c.seeds),
            fmt_epochs(&c.final_epochs),
            wall
        );
    }
    let _ = writeln!(w);
    neural::training_budgets(w, inp);
}

/// The KL-coverage curves (the paper's Figure 2) and the cell-coverage curves.
pub fn klc_curves(
    w: &mut String,
    inp: &Context<'_>,
    klc_figures: &[FigureFile],
    coverage_figures: &[FigureFile],
) {
    let _ = writeln!(w, "## KL-coverage during exploration\n");
    let _ = writeln!(
        w,
        "Lines: the mean over the repetitions (each repetition the mean of its exploration \
         replicates), without bands: overlapping bands around every curve hid one another. Right of each \
         panel, one column per condition: the final value's mean and its {:.0}% Student t \
         interval over the repetitions (mean ± t(n − 1) · sd / √n; none where a value is \
         infinite), and the paper's final value (hollow star: a single run, read off its plots \
         at the point labelled 4900) in the same column. The paper's Figure 2 drew 90% bands \
         over 5 runs (`seaborn.tsplot(ci=90)` in the authors' code, a percentile bootstrap, \
         which is too narrow at 5 seeds: \"The paper's claims\" gives the measured coverage); \
         the notebooks we read its values from hold one run each. Lower is better; the y axis \
         spans what is drawn, up to the KL-coverage of outcomes all in one cell ({}), not from \
         0. The baselines appear in every panel of their environment, as in the paper. As in \
         the paper's figure, only KDE goals for the learned spaces: the Gaussian-goal runs are \
         in the Figure 4 section. Colour and marker shape identify the algorithm; the \
         *faithful* variant is solid with filled markers, the *corrected* one dashed with \
         hollow markers. *n* in the legend: repetitions × exploration replicates.\n",
        crate::stats::CONFIDENCE * 100.0,
        paper_envs(|e| format!(
            "ln {} = {:.2} for {}",
            e.klc.achievable_cells,
            e.klc.max_klc(),
            e.display
        ))
    );
    if !inp.campaigns.compare.is_empty() {
        let names: Vec<String> = inp
            .campaigns
            .compare
            .iter()
            .map(|c| format!("`{}`", c.name))
            .collect();
        let _ = writeln!(
            w,
            "**Not in the paper:** these figures also draw the learners of the `compare-*` \
             campaigns ({}), marked \"not in the paper\" in the legends; the paper's text \
             says nothing about them (the leaderboard and their one-page summaries do).\n",
            names.join(", ")
        );
    }
    for f in klc_figures {
        let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
    }
    if !coverage_figures.is_empty() {
        let _ = writeln!(
            w,
            "### Cell coverage during exploration (not in the paper)
"
        );
        let _ = writeln!(
            w,
            "The same runs and styles, with the fraction of the achievable histogram cells \
             (`docs/original-code.md` section 4; the arrow's angle is a dimension of ArmArrow's cells) that \
             the outcomes have reached, higher is better. KL-coverage also rewards moving the \
             object often (every episode that leaves it in place adds to one cell), so a \
             condition can lower its KL-coverage without reaching new cells; this figure shows \
             the diversity alone.\n"
        );
        for f in coverage_figures {
            let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
        }
    }
}

/// The table of final KL-coverage against the paper's values.
pub fn final_table(w: &mut String, inp: &Context<'_>) {
    let reduced_keys = reduced_keys(inp);
    let _ = writeln!(w, "## Final KL-coverage\n");
    let _ = writeln!(
        w,
        "At each run's last epoch. *n*: repetitions (seeds), × exploration replicates where a \
         repetition has several; *mean ± sd* over the repetitions, each the mean of its \
         replicates (sample sd); *{level:.0}% CI*: \
         Student's t interval of the mean (— with fewer than 2 seeds or an infinite value; in a \
         seeded simulation it covers 0.94-0.96 on normal samples, but only 0.91 on skewed ones at \
         5 seeds, 0.83 when a seed may be stuck at RPE level); \
         *moved*: mean number of episodes that moved the object, of the mean \
         number of outcomes; *coverage*: mean fraction of the achievable histogram cells reached; \
         *at RPE level*: runs that moved the object fewer than {} times RPE's mean (a failed \
         exploration; the leaderboard's IQM trims such runs, so they are counted here); \
         *paper*: the paper's value (one run, ±0.03) and *Δ* = our mean − paper. The paper's \
         value is one run, so the yardstick for it is the spread of one of our runs, not the \
         interval of our mean: *percentile* is the share of our runs of the condition below it \
         (ties half), and *in PI* says whether it lies in our {level:.0}% prediction interval for \
         one run (mean ± t(n − 1) · s · √(1 + 1/n) over the condition's runs, pooling its \
         repetitions and replicates; normal theory).\n",
        crate::aggregate::RPE_LEVEL_FACTOR,
        level = crate::stats::CONFIDENCE * 100.0
    );
    let envs = envs(inp);
    for env in &envs {
        let _ = writeln!(w, "### {}\n", env_name(env));
        let _ = writeln!(
            w,
            "| condition | n | epochs | KLC mean ± sd | {:.0}% CI | moved | coverage | at RPE level | paper | Δ | percentile | in PI |",
            crate::stats::CONFIDENCE * 100.0
        );
        let _ = writeln!(
            w,
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"
        );
        for c in inp.conditions.iter().filter(|c| c.key.env == *env) {
            let s = &c.final_klc;
            let mean_sd = match s.std {
                Some(sd) => format!("{} ± {sd:.3}", fmt_klc(s.mean)),
                None if s.n_inf > 0 => {
                    format!("{} ({} of {} runs inf)", fmt_klc(s.mean), s.n_inf, s.n)
                }
                None => fmt_klc(s.mean),
            };
            let (paper, delta) = match &c.paper {
                Some(p) => {
                    let d = s.mean - p.klc;
                    let d = if d.is_finite() {
                        format!("{d:+.3}")
                    } else {
                        fmt_klc(d)
                    };
                    (format!("{:.2}", p.klc), d)
                }
                None => ("—".into(), "—".into()),
            };
            let (percentile, in_pi) = match (&c.paper, one_run(inp, c)) {
                (Some(p), Some(o)) => {
                    let pi = match o.interval {
                        Some((lo, hi)) if p.klc > lo && p.klc < hi => "yes".to_string(),
                        Some(_) if p.klc < o.min => {
                            format!("**no**: below all {} runs", o.n)
                        }
                        Some(_) if p.klc > o.max => {
                            format!("**no**: above all {} runs", o.n)
                        }
                        Some(_) => "**no**".to_string(),
                        None => "—".to_string(),
                    };
                    (format!("{:.0}%", o.percentile(p.klc)), pi)
                }
                _ => ("—".into(), "—".into()),
            };
            let _ = writeln!(
                w,
                "| {}{} | {} | {} | {} | {} | {:.0} / {:.0} | {:.1} % | {} | {} | {} | {percentile} | {in_pi} |",
                describe_key(&c.key),
                dagger(&reduced_keys, c),
                c.n_label(),
                fmt_epochs(&c.final_epochs),
                mean_sd,
                fmt_ci(s.ci),
                c.final_moved_mean,
                c.final_outcomes_mean,
                100.0 * c.final_coverage_mean,
                match c.at_rpe_level {
                    Some(k) => format!("{k} / {}", c.runs.len()),
                    None => "—".into(),
                },
                paper,
                delta
            );
        }
        let min_n = inp
            .conditions
            .iter()
            .filter(|c| c.key.env == *env)
            .map(|c| c.final_klc.n)
            .min()
            .unwrap_or(0);
        if let Some(line) = paper_outside(inp, env) {
            let _ = writeln!(w, "\n{line}");
        }
        if min_n <= neural::SMALL_N {
            let _ = writeln!(w, "\n{}", neural::small_n_warning(min_n));
        }
        let _ = writeln!(w);
    }
}

/// The final KLC of one condition's runs, as the yardstick of a single run.
struct OneRun {
    sorted: Vec<f64>,
    n: usize,
    min: f64,
    max: f64,
    /// The 95% prediction interval for one run (None with fewer than 2 finite runs).
    interval: Option<(f64, f64)>,
}

impl OneRun {
    /// The share of the runs below `v`, ties counted half, in percent.
    fn percentile(&self, v: f64) -> f64 {
        let below = self.sorted.iter().filter(|&&x| x < v).count() as f64;
        let ties = self.sorted.iter().filter(|&&x| x == v).count() as f64;
        100.0 * (below + ties / 2.0) / self.n as f64
    }
}

/// The final KLC of every run of `c` (None without runs).
fn one_run(inp: &Context<'_>, c: &ConditionSummary) -> Option<OneRun> {
    let mut sorted: Vec<f64> = c
        .runs
        .iter()
        .map(|&i| inp.store.runs[i].final_point().klc)
        .collect();
    sorted.sort_by(f64::total_cmp);
    Some(OneRun {
        n: sorted.len(),
        min: *sorted.first()?,
        max: *sorted.last()?,
        interval: crate::stats::prediction_interval(&sorted, crate::stats::CONFIDENCE).ok(),
        sorted,
    })
}

/// The paper's single-run values outside our 95% prediction interval for one run, in words.
fn paper_outside(inp: &Context<'_>, env: &str) -> Option<String> {
    let mut with = 0;
    let mut outside = Vec::new();
    for c in inp.conditions.iter().filter(|c| c.key.env == env) {
        let (Some(p), Some(o)) = (&c.paper, one_run(inp, c)) else {
            continue;
        };
        let Some((lo, hi)) = o.interval else {
            continue;
        };
        with += 1;
        if !(p.klc > lo && p.klc < hi) {
            outside.push(format!(
                "{} (paper {:.2}, our prediction interval [{lo:.2}, {hi:.2}], percentile {:.0}%)",
                describe_key(&c.key),
                p.klc,
                o.percentile(p.klc)
            ));
        }
    }
    (with > 0).then(|| {
        format!(
            "**The paper's values against one of our runs:** {} of {with} lie outside our {:.0}% \
             prediction interval for one run{}",
            outside.len(),
            crate::stats::CONFIDENCE * 100.0,
            if outside.is_empty() {
                ".".to_string()
            } else {
                format!(": {}.", outside.join("; "))
            }
        )
    })
}

/// The page of the outcome scatters the paper did not draw.
pub const OUTCOMES_PAGE: &str = "outcomes.md";

/// What an outcome scatter shows, for REPORT.md and the page of the others.
const OUTCOMES_METHOD: &str = "For each condition, the outcomes of its median run (by final \
KL-coverage, among the runs whose outcomes file the store keeps; the title names its seed) at three \
epochs: every episode that moved the object is a dot at the object's final (x, y), for ArmArrow a \
short stroke from the arrow's position to its tip, with a barb at the tip (angles grouped in 30° \
sectors); the circle is the reachable unit disk and the red mark the initial position (0.6, 0.6), \
where every other episode ends. Panel titles count the episodes that moved the object. The pool \
the median run is taken from differs between conditions (the store keeps every run's outcomes file \
for its first runs, then those of repetitions 0-2, first replicate): each caption says how many runs \
it is.";

/// The outcome scatters of the paper's Figures 3, 8 and 9 (`figures`), and a link to the page
/// of the `others`.
pub fn outcome_scatters(w: &mut String, inp: &Context<'_>, figures: &[FigureFile], others: usize) {
    let _ = writeln!(
        w,
        "## Object positions reached
"
    );
    let _ = writeln!(
        w,
        "The conditions of the paper's Figures 3, 8 and 9 (ArmBall, the paper's variants, KDE \
         goals). {OUTCOMES_METHOD}{}\n",
        if others > 0 {
            format!(
                " The other {others} conditions (ArmArrow, Gaussian goals, corrected variants, \
                 controls): [`{OUTCOMES_PAGE}`]({OUTCOMES_PAGE})."
            )
        } else {
            String::new()
        }
    );
    for env in &envs(inp) {
        for f in figures.iter().filter(|f| f.env == *env) {
            let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
        }
    }
}

/// The page of the outcome scatters the paper did not draw.
pub fn other_outcome_scatters(w: &mut String, inp: &Context<'_>, figures: &[FigureFile]) {
    let _ = writeln!(
        w,
        "# Object positions reached: the conditions the paper did not draw\n\n\
         Beside [REPORT.md](REPORT.md#object-positions-reached), which keeps the conditions of the \
         paper's Figures 3, 8 and 9. {OUTCOMES_METHOD}\n"
    );
    for env in &envs(inp) {
        let these: Vec<&FigureFile> = figures.iter().filter(|f| f.env == *env).collect();
        if these.is_empty() {
            continue;
        }
        let _ = writeln!(w, "## {}\n", env_name(env));
        for f in these {
            let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
        }
    }
}

/// The paper's appendix figures that need no results.
pub fn illustrations(w: &mut String, figures: &[FigureFile]) {
    if !figures.is_empty() {
        let _ = writeln!(w, "## The paper's illustrations\n");
        let _ = writeln!(
            w,
            "Drawn from the benchmark's own code, not from results. Figure 1: the arm at rest \
             (7 links summing to 1: the reachable set is the unit disk) with the ball at its \
             initial position, and the 70 x 70 images the learners see. Figure 5: one radial \
             flow (Rezende & Mohamed 2015), the transformation the RFVAE stacks ten of, \
             `z' = z + beta h(a, r) (z - c)` with `h = 1 / (a + r)` and `r = |z - c|` \
             (invertible for `beta >= -a`), on 1000 seeded samples of an isotropic Gaussian. \
             Figure 6: one DMP episode on ArmBall, the first seeded uniform parameter vector (as \
             RPE samples them) that catches the ball: the arm every 7 steps (light to dark), the \
             hand's path (blue), the ball's start (pale) and end, and the seven joint commands as the \
             DMP outputs them (units of π; the arm clips them to [-1, 1], dashed lines).\n"
        );
        for f in figures {
            let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
        }
    }
}

/// Deviations from the paper and notes on the data.
pub fn deviations(w: &mut String, inp: &Context<'_>) {
    let store = inp.store;
    let _ = writeln!(w, "## Deviations and notes\n");
    let _ = writeln!(w, "- {EPOCH_NOTE}");
    let _ = writeln!(
        w,
        "- **Where the paper's text and its authors' code differ, we follow the code** \
         (`docs/original-code.md`, `docs/fidelity.md`): images of 70 x 70 pixels (the text says \
         50 x 50); dense networks on the 4900 pixels, 4900-1200-1200-latents with a mirrored \
         decoder (the appendix's figure of layers, after Higgins et al. 2016, is convolutional); \
         no KL warm-up for the VAE (the text describes a deterministic warm-up of 10^4 \
         iterations; the code's RFVAE has one, which we keep, scaled to our budget); 10 *radial* \
         flows in the RFVAE (the text says planar flows)."
    );
    neural::deviations(w, inp);
    let _ = writeln!(
        w,
        "- The paper's curves are **single runs** (one per condition, no seeds, no confidence band); \
         its values here were **read off the notebooks' plots** at the point labelled 4900 \
         (holding 4812 outcomes), to about ±0.03, and orderings within about 0.05 are uncertain \
         (`data/paper/README.md`). A difference Δ smaller than the spread of our seeds is no \
         disagreement."
    );
    let _ = writeln!(
        w,
        "- Our whiskers beside the KL-coverage curves and our table intervals are {:.0}% \
         Student t intervals of the mean over seeds (a single run has none; the curves carry no \
         bands); the whiskers of the Figure 4 and RGE-RFVAE sampler figures are ± 1 standard \
         deviation, as the paper's Figure 4. The paper's Figure 2 drew 90% percentile-bootstrap \
         bands, which understate the uncertainty at 5 seeds. Every confidence interval of the \
         report is at this level, the leaderboard's stratified bootstrap included; a range (min \
         to max) is never written as one.",
        crate::stats::CONFIDENCE * 100.0
    );
    let _ = writeln!(
        w,
        "- KL-coverage is computed for every algorithm on the engineered outcome (object x, y; and \
         the arrow's angle for ArmArrow), 30 bins per dimension over [-1, 1], against the uniform \
         distribution on the achievable cells ({}).",
        paper_envs(|e| format!("{} for {}", e.klc.achievable_cells, e.display))
    );
    if last_epochs(inp).iter().any(|&e| e != 5000) {
        let _ = writeln!(
            w,
            "- Our last epoch ({}) differs from the paper's 5000 exploration epochs: the paper's \
             stars are placed at our last epoch, but they were reached after ~4812 outcomes.",
            fmt_epochs(&last_epochs(inp))
        );
    }
    let infinite: Vec<String> = inp
        .conditions
        .iter()
        .filter(|c| c.final_klc.n_inf > 0)
        .map(|c| format!("{} {}", env_name(&c.key.env), describe_key(&c.key)))
        .collect();
    if !infinite.is_empty() {
        let _ = writeln!(
            w,
            "- **Infinite KL-coverage** (an outcome outside the achievable cells) in the final values \
             of: {}. Their means are reported as `inf`.",
            infinite.join("; ")
        );
    }
    let mixed: Vec<String> = inp
        .conditions
        .iter()
        .filter(|c| c.final_epochs.len() > 1)
        .map(|c| {
            format!(
                "{} {} ({})",
                env_name(&c.key.env),
                describe_key(&c.key),
                fmt_epochs(&c.final_epochs)
            )
        })
        .collect();
    if !mixed.is_empty() {
        let _ = writeln!(
            w,
            "- Runs of one condition end at different epochs (their final values are mixed): {}.",
            mixed.join("; ")
        );
    }
    let no_paper: Vec<String> = inp
        .conditions
        .iter()
        .filter(|c| c.paper.is_none())
        .map(|c| format!("{} {}", env_name(&c.key.env), describe_key(&c.key)))
        .collect();
    if !no_paper.is_empty() && inp.paper.path.is_some() {
        let _ = writeln!(w, "- No paper value for: {}.", no_paper.join("; "));
    }
    let not_run: Vec<String> = inp
        .paper
        .values
        .iter()
        .filter(|p| {
            !inp.conditions.iter().any(|c| {
                c.key.env == p.env
                    && c.key.algo == p.algo
                    && c.key.sampler == p.sampler
                    && p.latents.is_none_or(|l| l == c.key.latents)
            })
        })
        .map(|p| {
            let lat = p
                .latents
                .map(|l| format!(", {l} latents"))
                .unwrap_or_default();
            format!("{} {} ({}{lat})", env_name(&p.env), p.algo, p.sampler)
        })
        .collect();
    if !not_run.is_empty() {
        let _ = writeln!(
            w,
            "- Paper conditions not in these results ({}): {}.",
            not_run.len(),
            not_run.join("; ")
        );
    }
    if !store.incomplete.is_empty() {
        let _ = writeln!(
            w,
            "- **Incomplete runs skipped** ({}; a campaign still running or interrupted):",
            store.incomplete.len()
        );
        for (stem, missing) in &store.incomplete {
            let rel = stem.strip_prefix(&inp.opts.results).unwrap_or(stem);
            let _ = writeln!(w, "  - `{}`: missing {}", rel.display(), missing.join(", "));
        }
    }
}

/// How to regenerate every campaign this report used, then the report.
pub fn reproduce(w: &mut String, inp: &Context<'_>) {
    let _ = writeln!(w, "\n## How to reproduce\n");
    let _ = writeln!(
        w,
        "From a clone of the repository, with Rust 1.95 or newer (each campaign is resumable: \
         rerunning it after an interruption redoes only the runs that did not finish):\n"
    );
    let _ = writeln!(w, "```sh");
    let profile = |name: &str| {
        if name.is_empty() {
            "# (top-level runs: see their manifests' `profile`)".to_string()
        } else {
            format!("make campaign PROFILE={name}")
        }
    };
    let _ = writeln!(w, "{}", profile(&inp.campaigns.main.name));
    // Every other role's campaigns by their profile, but the `ugl compare` ones (below).
    for role in CampaignRole::ALL {
        if matches!(role, CampaignRole::Main | CampaignRole::Compare) {
            continue;
        }
        for c in inp.campaigns.of_role(role) {
            let _ = writeln!(w, "{}", profile(&c.name));
        }
    }
    for c in &inp.campaigns.compare {
        // The learner its runs recorded (`ugl compare --learner NAME` wrote them).
        let Some(learner) = c.store.runs.iter().find_map(|r| r.manifest.learner.clone()) else {
            let _ = writeln!(w, "{}", profile(&c.name));
            continue;
        };
        // An external program's command, as its runs' manifests recorded it.
        let command = c.store.runs.iter().find_map(|r| {
            let cmd = r.manifest.external_command()?;
            Some(cmd.replace('\'', "'\\''"))
        });
        let _ = writeln!(
            w,
            "cargo run --bin ugl -- compare --learner {learner}{}",
            match command {
                Some(cmd) => format!(" --command '{cmd}'"),
                None => String::new(),
            }
        );
    }
    let _ = writeln!(
        w,
        "make report{}",
        if inp.campaigns.main.name == ReportOptions::DEFAULT_MAIN_CAMPAIGN {
            String::new()
        } else {
            format!(" MAIN={}", inp.campaigns.main.name)
        }
    );
    let _ = writeln!(w, "```\n");
    let _ = writeln!(
        w,
        "Every random draw comes from a seeded stream derived from the run's identity. From \
         results version 5 a run's result files are byte-identical on every machine, kernel path \
         and thread count (`make verify` reruns the `smoke` profile on every kernel path the CPU \
         has against one committed checksum file); runs of earlier versions are identical only on \
         the same SIMD level (the version-4 `paper` store mixes AVX2 and AVX-512 runs, so no one \
         machine regenerates all of it byte for byte). The leaderboard's bootstrap is \
         seeded too and the other intervals draw nothing, so rendering the same results gives the \
         same bytes. A campaign reruns the runs written at another results version than the \
         code's (version {} here; *What was run* gives each campaign's): to reproduce older runs \
         byte for byte, check out the git revision their manifests record.",
        ugl_types::RESULTS_VERSION
    );
}

/// `f` of each environment of the paper, joined by commas (prose numbers come from the
/// environment registry).
pub(crate) fn paper_envs(f: impl Fn(&ugl_types::EnvSpec) -> String) -> String {
    ugl_types::environments()
        .into_iter()
        .filter(|e| e.in_paper)
        .map(f)
        .collect::<Vec<_>>()
        .join(", ")
}
