//! The markdown sections about campaigns and the neural learners: the campaigns line, the training
//! budgets against the paper's, the paper's Figure 4 (RGE-VAE with KDE vs Gaussian goals),
//! faithful vs corrected, the training-budget sensitivity, the training losses, and their lines in
//! the deviations.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::{fmt_klc, fmt_seeds, plural};
use crate::aggregate::ConditionSummary;
use crate::context::Context;
use crate::figures::FigureFile;
use crate::figures::budget::series_title;
use crate::figures::sampler_compare::{self, SAMPLERS};
use crate::load::campaign_display;
use crate::names::{algo_name, env_name, learner_name, sampler_name};
use crate::neural::{self, BudgetPoint, paper_training};
use crate::stats::{self, Summary};
use ugl_types::CampaignRole;

/// What faithful and corrected mean, for the report's readers.
pub const VARIANT_NOTE: &str = "*Faithful* reproduces the original code's behaviour, defects \
included: the VAE's reparameterisation noise is one draw shared by the whole batch; the RFVAE \
shares that noise, broadcasts its log-determinant term to a batch × batch matrix, and encodes \
outcomes as the flow output of a freshly sampled z0 while its KDE is fitted on flow-less z0 samples \
(goals and outcomes in different spaces). *Corrected* fixes these defects (per-sample noise, \
per-sample log-determinant, deterministic encoding of the mean through the flows, for both); from \
results version 4 the corrected RFVAE also puts its prior N(0, I) on the flow output z_K, where its \
outcomes are encoded, so that its Gaussian goals are drawn in that space (up to version 3 the prior \
was on z0). The AE has no documented defect and runs once (`docs/original-code.md` section 5).";

fn campaign(name: &str) -> String {
    format!("`{}`", campaign_display(name))
}

/// What the campaigns of a role are, in the campaigns line.
fn role_words(role: CampaignRole) -> &'static str {
    match role {
        CampaignRole::Main => "main",
        CampaignRole::Budget => "training-budget sensitivity",
        CampaignRole::Compare => "new learners (`ugl compare`)",
        CampaignRole::Recipe => "training recipes",
        CampaignRole::Followup => "the follow-up paper's setting",
        CampaignRole::Validation => "the validity check's held-out repetitions",
    }
}

/// `- **Campaigns:** ...`: the main one, those of every other role the report reads, and those
/// present but not used.
pub fn campaigns_line(w: &mut String, inp: &Context<'_>) {
    let c = inp.campaigns;
    let n = c.main.store.runs.len();
    let mut parts = vec![format!(
        "main {} ({n} run{}: the paper's figures and table)",
        campaign(&c.main.name),
        plural(n)
    )];
    // `name (n runs), ...` of a group of campaigns that were read.
    let listed = |group: &[crate::campaigns::Campaign]| -> String {
        group
            .iter()
            .map(|g| {
                let n = g.store.runs.len();
                format!("{} ({n} run{})", campaign(&g.name), plural(n))
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    for role in CampaignRole::ALL {
        let group = c.of_role(role);
        if role != CampaignRole::Main && !group.is_empty() {
            parts.push(format!("{} {}", role_words(role), listed(group)));
        }
    }
    if !c.unused.is_empty() {
        let u: Vec<String> = c
            .unused
            .iter()
            .map(|u| {
                format!(
                    "{} ({} run{})",
                    campaign(&u.name),
                    u.complete,
                    plural(u.complete)
                )
            })
            .collect();
        parts.push(format!("present but not used: {}", u.join(", ")));
    }
    let _ = writeln!(w, "- **Campaigns:** {}.", parts.join("; "));
}

/// Distinct values with run counts, numbers in numeric order: `1000` or `300 (3 runs), 1000 (2 runs)`.
fn values(m: &BTreeMap<String, usize>) -> String {
    let mut v: Vec<(&String, &usize)> = m.iter().collect();
    v.sort_by(|a, b| {
        let (x, y) = (a.0.parse::<f64>().ok(), b.0.parse::<f64>().ok());
        match (x, y) {
            (Some(x), Some(y)) => x.total_cmp(&y),
            _ => a.0.cmp(b.0),
        }
    });
    if v.len() == 1 {
        return v[0].0.clone();
    }
    v.iter()
        .map(|(k, n)| format!("{k} ({n} run{})", plural(**n)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The training budgets actually used by the main campaign, next to the paper's.
pub fn training_budgets(w: &mut String, inp: &Context<'_>) {
    let used = neural::budgets_used(inp.store);
    let _ = writeln!(w, "### Neural training budgets\n");
    if used.is_empty() {
        let _ = writeln!(
            w,
            "No run of the main campaign trained a neural representation (AE, VAE, RFVAE).\n"
        );
        return;
    }
    let _ = writeln!(
        w,
        "What the main campaign's neural learners were trained with, read from each run's manifest \
         (`train.config`), under the paper's settings (`docs/original-code.md` section 5; dense networks on the \
         4900 pixels, batch 100). A training is shared by the runs that differ only in their goal \
         sampler; *trainings* counts distinct ones, and the fit time (data set and training) is \
         their mean.\n"
    );
    let _ = writeln!(
        w,
        "| learner | | iterations | hidden layers | batch | learning rate | warm-up | runs (trainings) | fit time (mean) |"
    );
    let _ = writeln!(w, "|---|---|---:|---|---:|---:|---:|---:|---:|");
    for b in &used {
        let rfvae = b.learner == ugl_types::learners::RFVAE.name;
        let fit = b
            .mean_fit_s
            .map(super::fmt_duration)
            .unwrap_or_else(|| "—".into());
        let _ = writeln!(
            w,
            "| {} | ours | {} | {} | {} | {} | {} | {} ({}) | {} |",
            learner_name(&b.learner),
            values(&b.iterations),
            values(&b.hidden),
            values(&b.batch),
            values(&b.lr),
            if rfvae {
                values(&b.warmup)
            } else {
                "—".into()
            },
            b.runs,
            b.trainings,
            fit
        );
        if b.unrecorded > 0 {
            let _ = writeln!(
                w,
                "| | (no `train` record: {} run{}) | | | | | | | |",
                b.unrecorded,
                plural(b.unrecorded)
            );
        }
        if !b.plateau_rules.is_empty() {
            let used: Vec<i64> = b.extended.values().map(|&(_, u)| u).collect();
            let _ = writeln!(
                w,
                "| | plateau rule ({}): {} of {} trainings trained on past their iterations{} | | | | | | | |",
                b.plateau_rules
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join("; "),
                b.extended.len(),
                b.trainings,
                match (used.iter().min(), used.iter().max()) {
                    (Some(lo), Some(hi)) if lo == hi => format!(", to {lo}"),
                    (Some(lo), Some(hi)) => format!(", to {lo}-{hi}"),
                    _ => String::new(),
                }
            );
        }
        if let Some(p) = paper_training(&b.learner) {
            let _ = writeln!(
                w,
                "| | paper | {} | [{}, {}] | {} | {:e} ({}) | {} | 1 per condition | |",
                p.iterations,
                p.hidden[0],
                p.hidden[1],
                p.batch,
                p.lr,
                p.optimiser,
                p.warmup
                    .map(|v| v.to_string())
                    .unwrap_or_else(|| "—".into()),
            );
        }
    }
    let _ = writeln!(w);
}

/// One-line summary of the budgets for the deviations: `RGE-AE 2000 of the paper's 200000
/// iterations (1.0%)`, plus the hidden layers where they differ.
fn budget_deviation(inp: &Context<'_>) -> Option<String> {
    let used = neural::budgets_used(inp.store);
    let mut parts = Vec::new();
    let mut hidden = Vec::new();
    let mut inits: Vec<String> = Vec::new();
    for b in &used {
        for i in b.init.keys().filter(|i| *i != "paper") {
            let s = format!("{} {i}", learner_name(&b.learner));
            if !inits.contains(&s) {
                inits.push(s);
            }
        }
        let Some(p) = paper_training(&b.learner) else {
            continue;
        };
        let its: Vec<i64> = b.iterations.keys().filter_map(|k| k.parse().ok()).collect();
        if its.iter().any(|&i| i != p.iterations) {
            let pct: Vec<String> = its
                .iter()
                .map(|&i| format!("{i} ({:.1}%)", 100.0 * i as f64 / p.iterations as f64))
                .collect();
            parts.push(format!(
                "{} {} of the paper's {} iterations",
                learner_name(&b.learner),
                pct.join(", "),
                p.iterations
            ));
        }
        let paper_hidden = format!("[{}, {}]", p.hidden[0], p.hidden[1]);
        for h in b.hidden.keys() {
            if *h != paper_hidden && !hidden.contains(h) {
                hidden.push(h.clone());
            }
        }
    }
    if !inits.is_empty() {
        parts.push(format!(
            "weight init {} instead of the paper's truncated normal (std 0.001)",
            inits.join(", ")
        ));
    }
    if parts.is_empty() && hidden.is_empty() {
        return None;
    }
    let mut s = format!(
        "**Neural training budgets differ from the paper's** (main campaign, from the manifests): {}",
        parts.join("; ")
    );
    if !hidden.is_empty() {
        let paper_layers = neural::learners()
            .first()
            .and_then(|l| paper_training(l))
            .map_or([1200, 1200], |p| p.hidden);
        let _ = write!(
            s,
            "{}hidden layers {} instead of [{}, {}]",
            if parts.is_empty() { "" } else { "; " },
            hidden.join(", "),
            paper_layers[0],
            paper_layers[1]
        );
    }
    s.push_str(
        ". Conclusions about RGE-AE, RGE-VAE and RGE-RFVAE hold for these budgets; the \
         training-budget section measures how RGE-VAE's final KL-coverage depends on it.",
    );
    Some(s)
}

/// `4.123 ± 0.100 (n=5)`; `—` when absent.
fn cell(c: Option<&ConditionSummary>) -> String {
    match c {
        None => "—".into(),
        Some(c) => summary_cell(&c.final_klc),
    }
}

fn summary_cell(s: &Summary) -> String {
    match s.std {
        Some(sd) => format!("{} ± {sd:.3} (n={})", fmt_klc(s.mean), s.n),
        None => format!("{} (n={})", fmt_klc(s.mean), s.n),
    }
}

fn signed(v: f64) -> String {
    if v.is_finite() {
        format!("{v:+.3}")
    } else {
        fmt_klc(v)
    }
}

/// The paper's Figure 4 (RGE-VAE, KDE vs Gaussian goals), and the same for RGE-RFVAE if drawn.
pub fn figure4(w: &mut String, inp: &Context<'_>, sampler_figures: &[FigureFile]) {
    let _ = writeln!(
        w,
        "## RGE-VAE: KDE vs Gaussian goals (the paper's Figure 4)\n"
    );
    let _ = writeln!(
        w,
        "The paper compared goals sampled from a KDE of the training latents with goals from the \
         VAE's isotropic Gaussian prior N(0, I), and found no significant difference (its Figure \
         4, mean and standard deviation over 5 runs; its notebook's single run on ArmBall with 10 \
         latents ends at 4.25 with KDE and 3.84 with Gaussian goals). Curves: the mean over the \
         repetitions, without bands; right of each panel, the final mean ± 1 sd over the \
         repetitions (the paper's statistic); KDE blue circles, Gaussian vermillion triangles; \
         faithful solid with filled markers, corrected dashed with hollow markers. Table: final \
         KL-coverage, mean ± sd over the repetitions (*n* repetitions, each the mean of its \
         exploration replicates).\n"
    );
    for (algo, name) in crate::names::SAMPLER_FIGURES {
        let fig = sampler_figures
            .iter()
            .find(|f| f.link == format!("figures/{name}"));
        // The paper plotted the first; the others are drawn where their runs exist.
        let in_paper = algo == crate::names::SAMPLER_FIGURES[0].0;
        if !in_paper && fig.is_none() {
            continue;
        }
        if !in_paper {
            let _ = writeln!(w, "### {} (not in the paper)\n", algo.display());
        }
        let Some(fig) = fig else {
            let _ = writeln!(
                w,
                "No {} run with Gaussian goals in the main campaign {}: no figure.\n",
                algo_name(&algo),
                campaign(&inp.campaigns.main.name)
            );
            continue;
        };
        let _ = writeln!(w, "![{}]({})\n", fig.caption, fig.link);
        let panels = sampler_compare::panels(inp.conditions, &algo);
        let _ = writeln!(
            w,
            "| panel | KDE, faithful | KDE, corrected | Gaussian, faithful | Gaussian, corrected | paper (KDE / Gaussian) |"
        );
        let _ = writeln!(w, "|---|---:|---:|---:|---:|---:|");
        for p in &panels {
            let paper: Vec<String> = SAMPLERS
                .iter()
                .map(|s| {
                    p.members
                        .iter()
                        .find(|m| m.0 == *s)
                        .and_then(|m| m.2.paper.as_ref())
                        .map(|v| format!("{:.2}", v.klc))
                        .unwrap_or_else(|| "—".into())
                })
                .collect();
            // A learner without variants (none) fills the faithful column.
            let get = |s: ugl_types::Sampler, v: ugl_types::Variant| {
                p.get(&s, &v).or_else(|| {
                    (v == ugl_types::Variant::FAITHFUL)
                        .then(|| p.get(&s, &ugl_types::Variant::NONE))
                        .flatten()
                })
            };
            let _ = writeln!(
                w,
                "| {} | {} | {} | {} | {} | {} |",
                p.title(),
                cell(get(ugl_types::Sampler::KDE, ugl_types::Variant::FAITHFUL)),
                cell(get(ugl_types::Sampler::KDE, ugl_types::Variant::CORRECTED)),
                cell(get(
                    ugl_types::Sampler::GAUSSIAN,
                    ugl_types::Variant::FAITHFUL
                )),
                cell(get(
                    ugl_types::Sampler::GAUSSIAN,
                    ugl_types::Variant::CORRECTED
                )),
                paper.join(" / ")
            );
        }
        let _ = writeln!(w);
    }
}

/// Faithful vs corrected: the figure and the paired-difference table.
pub fn variants(w: &mut String, inp: &Context<'_>, figure: Option<&FigureFile>) {
    let _ = writeln!(w, "## Faithful vs corrected variants\n");
    let _ = writeln!(w, "{VARIANT_NOTE}\n");
    let Some(fig) = figure else {
        let _ = writeln!(
            w,
            "No RGE-VAE or RGE-RFVAE run with a faithful or corrected variant in the main campaign \
             {}: nothing to compare.\n",
            campaign(&inp.campaigns.main.name)
        );
        return;
    };
    let _ = writeln!(
        w,
        "The two runs of a seed share their initial weights, their training batches and their \
         exploration streams, so the comparison is paired: *corrected − faithful* is the mean over \
         seeds of the per-seed difference of final KL-coverage (negative: the corrected variant \
         covers better), with its {:.0}% paired t interval (Student's t on the per-seed \
         differences; — with fewer than 2 pairs). An interval that excludes 0 is a difference at \
         this training budget; the rows are not corrected for multiple comparisons.\n",
        stats::CONFIDENCE * 100.0
    );
    let _ = writeln!(w, "![{}]({})\n", fig.caption, fig.link);
    let _ = writeln!(
        w,
        "| panel | algorithm | goals | faithful: mean (n) | corrected: mean (n) | corrected − faithful | {:.0}% CI | pairs (seeds) |",
        stats::CONFIDENCE * 100.0
    );
    let _ = writeln!(w, "|---|---|---|---:|---:|---:|---:|---:|");
    let mean_n = |c: Option<&ConditionSummary>| match c {
        Some(c) => format!("{} ({})", fmt_klc(c.final_klc.mean), c.final_klc.n),
        None => "— (0)".into(),
    };
    for p in inp.variant_pairs {
        let (diff, dci) = match &p.diff {
            Some(d) => (
                signed(d.mean),
                d.ci.map(|(lo, hi)| format!("[{}, {}]", signed(lo), signed(hi)))
                    .unwrap_or_else(|| "—".into()),
            ),
            None => ("—".into(), "—".into()),
        };
        let seeds: Vec<i64> = p.differences.iter().map(|d| d.0).collect();
        let _ = writeln!(
            w,
            "| {}, {} latents | {} | {} | {} | {} | {} | {} | {} ({}) |",
            env_name(&p.env),
            p.latents,
            algo_name(&p.algo),
            sampler_name(&p.sampler),
            mean_n(p.faithful),
            mean_n(p.corrected),
            diff,
            dci,
            p.differences.len(),
            if seeds.is_empty() {
                "—".into()
            } else {
                fmt_seeds(&seeds)
            }
        );
    }
    let _ = writeln!(w);
}

fn budget_row(w: &mut String, p: &BudgetPoint, origin: &str, efr: Option<&[f64]>) {
    let seeds: Vec<i64> = p.values.iter().map(|v| v.0).collect();
    let xs: Vec<f64> = crate::aggregate::seed_means(&p.values)
        .into_iter()
        .map(|v| v.1)
        .collect();
    let delta = match efr {
        None => "—".into(),
        Some(ys) => match stats::welch_interval(&xs, ys, stats::CONFIDENCE) {
            Ok(i) => format!(
                "{} [{}, {}]",
                signed(i.estimate),
                signed(i.lo),
                signed(i.hi)
            ),
            Err(_) if xs.is_empty() || ys.is_empty() => "—".into(),
            Err(_) => format!(
                "{} (no interval)",
                signed(stats::mean(&xs) - stats::mean(ys))
            ),
        },
    };
    let runs = p.values.len();
    let untrained = if p.networks == 0 {
        "—".to_string()
    } else {
        format!("{} of {}", p.untrained, p.networks)
    };
    let at_rpe = p.at_rpe_level.map_or("—".to_string(), |k| {
        format!("{k} of {runs} run{}", plural(runs))
    });
    let _ = writeln!(
        w,
        "| {} | {} | {} ({}) | {} | {} | {} | {untrained} | {at_rpe} | {delta} |",
        p.iterations,
        origin,
        p.summary.n,
        fmt_seeds(&seeds),
        summary_cell(&p.summary)
            .split(" (n=")
            .next()
            .unwrap_or_default(),
        super::fmt_klc(p.median),
        super::fmt_ci(p.summary.ci)
    );
}

/// Training-budget sensitivity: the `budget-*` campaigns.
/// At or below this many seeds a statistic gets [`small_n_warning`].
pub const SMALL_N: usize = 5;

/// The warning under a table whose smallest sample has `n` seeds.
pub fn small_n_warning(n: usize) -> String {
    format!(
        "⚠ **Small samples**: as few as {n} seed{} per value. The t intervals cover as they \
         say on normal samples; at so few seeds they cover less on skewed ones, and not when a \
         rare outlying run (a seed stuck at RPE level) is missing from the sample, while one \
         such run moves a mean a lot: a difference is real only when it is large.",
        if n == 1 { "" } else { "s" }
    )
}

pub fn budget(w: &mut String, inp: &Context<'_>, figures: &[FigureFile]) {
    let _ = writeln!(w, "## Training-budget sensitivity\n");
    let camps = &inp.campaigns.budget;
    if camps.is_empty() {
        let _ = writeln!(
            w,
            "No `budget-*` campaign in the store: the dependence of the results on the neural \
             training budget is not measured here (no figure).\n"
        );
        return;
    }
    let list: Vec<String> = camps
        .iter()
        .map(|c| {
            let n = c.store.runs.len();
            let mut s = format!("{} ({n} run{}", campaign(&c.name), plural(n));
            if !c.store.incomplete.is_empty() {
                let _ = write!(s, ", {} incomplete", c.store.incomplete.len());
            }
            s.push(')');
            s
        })
        .collect();
    let _ = writeln!(
        w,
        "The same condition trained for different numbers of iterations (read from each run's \
         `train.config.iterations`), from the campaigns {}. The seeds are the main campaign's: a \
         seed starts from the same weights and draws the same batches at every budget of these \
         campaigns (the main campaign's network may have another recipe: see the list under the \
         figure). Each dot \
         is a run's final KL-coverage, filled when its network left the mean-image plateau and \
         hollow when it stayed there; diamonds on a line the median over the seeds (the values \
         are often bimodal: a mean would describe no run); the star the median of the main \
         campaign {} at its own budget; horizontal lines the mean final KL-coverage of \
         RGE-EFR and RPE in the main campaign. The table gives the mean with its {level:.0}% t \
         interval as well, the networks that stayed on the plateau and the runs at RPE level \
         (fewer object moves than twice RPE's mean). The paper trained the VAE for 100,000 iterations. \
         *Δ vs RGE-EFR*: the mean final KL-coverage minus RGE-EFR's (main campaign), with its \
         {level:.0}% Welch t interval: whether the paper's main claim for this learner (no worse \
         than RGE-EFR) depends on the budget.\n",
        list.join(", "),
        campaign(&inp.campaigns.main.name),
        level = stats::CONFIDENCE * 100.0
    );
    for f in figures {
        let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
    }
    let budget_runs: Vec<crate::load::Run> = inp
        .campaigns
        .budget
        .iter()
        .flat_map(|c| c.store.runs.iter().cloned())
        .collect();
    let _ = writeln!(
        w,
        "The budget campaigns' recipe besides the iterations, read from the manifests:\n"
    );
    super::recipe::recipe_lines(
        w,
        &budget_runs,
        &inp.campaigns.main.store.runs,
        &inp.campaigns.main.name,
        false,
    );
    let _ = writeln!(w);
    for s in &inp.budget.series {
        let _ = writeln!(w, "### {}\n", series_title(s));
        let _ = writeln!(
            w,
            "| training iterations | campaign | n seeds | final KLC mean ± sd | median | {level:.0}% CI | networks on the plateau | at RPE level | Δ vs RGE-EFR [{level:.0}% CI] |",
            level = stats::CONFIDENCE * 100.0
        );
        let _ = writeln!(w, "|---:|---|---:|---:|---:|---:|---:|---:|---:|");
        let efr = s
            .references
            .iter()
            .find(|r| r.algo == ugl_types::Algo::RGE_EFR)
            .map(|r| r.values.as_slice());
        for p in &s.points {
            let names: Vec<String> = p.campaigns.iter().map(|c| campaign(c)).collect();
            budget_row(w, p, &names.join(", "), efr);
        }
        for p in &s.main {
            budget_row(
                w,
                p,
                &format!("{} (main)", campaign(&inp.campaigns.main.name)),
                efr,
            );
        }
        let min_n = s
            .points
            .iter()
            .chain(&s.main)
            .map(|p| p.values.len())
            .min()
            .unwrap_or(0);
        if min_n <= SMALL_N {
            let _ = writeln!(w, "\n{}", small_n_warning(min_n));
        }
        if !s.references.is_empty() {
            let refs: Vec<String> = s
                .references
                .iter()
                .map(|r| {
                    format!(
                        "{} {} (n={})",
                        algo_name(&r.algo),
                        fmt_klc(r.summary.mean),
                        r.summary.n
                    )
                })
                .collect();
            let _ = writeln!(
                w,
                "\nReference levels on {} (main campaign, mean final KL-coverage): {}.",
                env_name(&s.key.env),
                refs.join(", ")
            );
        }
        let _ = writeln!(w);
    }
    if !inp.budget.unrecorded.is_empty() {
        let _ = writeln!(
            w,
            "Left out, no `train.config.iterations` in the manifest ({}): {}.\n",
            inp.budget.unrecorded.len(),
            inp.budget
                .unrecorded
                .iter()
                .map(|r| format!("`{r}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}

/// The training-loss figure, if any run recorded its loss.
pub fn training_loss(w: &mut String, figure: Option<&FigureFile>) {
    let Some(f) = figure else {
        return;
    };
    let _ = writeln!(w, "## Training losses\n");
    let _ = writeln!(
        w,
        "The loss each neural learner minimised, as recorded during training (`train.losses` in \
         the manifests), averaged over the main campaign's distinct trainings: blue the 10-latent \
         spaces, orange the true dimension; faithful (and the AE) solid, corrected dashed. The \
         y axis spans every point unless the untrained network's first loss is far above the \
         rest; such a point is an arrow at the top edge with its value. Loss in nats per image. \
         The dotted line is the plateau (mean-image loss); the RFVAE panels have none (annealed \
         loss minus the flows' log-determinant). Levels differ between learners (the VAE adds its KL term, the RFVAE \
         subtracts its flows' log-determinant and anneals the rest), not their quality.\n"
    );
    let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
}

/// The neural learners' lines in the deviations.
pub fn deviations(w: &mut String, inp: &Context<'_>) {
    if let Some(s) = budget_deviation(inp) {
        let _ = writeln!(w, "- {s}");
    }
    if !inp.variant_pairs.is_empty() {
        let _ = writeln!(
            w,
            "- The paper ran its original code only, i.e. our *faithful* variant; the *corrected* \
             variant is ours. Its final values are compared with the same paper value in the table."
        );
    }
    let max = inp
        .conditions
        .iter()
        .map(|c| c.seeds.len())
        .max()
        .unwrap_or(0);
    let fewer: Vec<String> = inp
        .conditions
        .iter()
        .filter(|c| c.seeds.len() < max)
        .map(|c| {
            format!(
                "{} {} ({})",
                env_name(&c.key.env),
                crate::names::describe_key(&c.key),
                c.seeds.len()
            )
        })
        .collect();
    if !fewer.is_empty() {
        let _ = writeln!(
            w,
            "- Conditions with fewer seeds than the others ({max}): {}.",
            fewer.join("; ")
        );
    }
}
