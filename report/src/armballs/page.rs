//! The page `armballs.md`: exploration of the ball per algorithm with the distractor control,
//! the interest of each module, the disentanglement of each network, the claims.

use std::fmt::Write as _;

use super::labels::{Condition, f2, f3};
use super::runs::{
    ACTIVE_NATS, CodeKind, ENCODES, FollowupRun, IGNORES, LatentRole, active_roles, algos,
    ball_cells, ball_grid, count_role, display, of, one_run_per_network, ratios, role,
};
use super::{COVERAGE_FIGURE, FollowupClaims, INTEREST_FIGURE, PAGE, claims};
use crate::campaigns::Campaign;
use crate::figures::FigureFile;
use crate::names::learner_name;
use crate::stats::{CONFIDENCE, mean, t_interval};

/// The page, and the section of `REPORT.md` (its claims and a link to the page).
pub(super) fn write(
    campaign: &Campaign,
    variants: &[&Campaign],
    runs: &[FollowupRun],
    figures: &[FigureFile],
    followup_claims: &FollowupClaims<'_>,
) -> (String, String) {
    let mut p = String::new();
    let name = std::iter::once(campaign.name.as_str())
        .chain(variants.iter().map(|v| v.name.as_str()))
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(" and ");
    let n_seeds = {
        let mut s: Vec<i64> = runs.iter().map(|r| r.seed).collect();
        s.sort();
        s.dedup();
        s.len()
    };
    // The learned spaces as run: their learners and latent sizes.
    let mut learners: Vec<String> = Vec::new();
    let mut sizes: Vec<i64> = Vec::new();
    for r in runs {
        if let Some(l) = &r.learner {
            let l = learner_name(l);
            if !learners.contains(&l) {
                learners.push(l);
            }
            if !sizes.contains(&r.key.latents) {
                sizes.push(r.key.latents);
            }
        }
    }
    sizes.sort();
    let several_sizes = sizes.len() > 1;
    let spaces = if learners.is_empty() {
        "none run here".to_string()
    } else {
        let sizes: Vec<String> = sizes.iter().map(|s| s.to_string()).collect();
        format!("{}, {} latents", learners.join(", "), sizes.join(" and "))
    };
    let _ = writeln!(
        p,
        "# Beyond the paper: a distractor (ArmBalls)\n\n\
         The follow-up of the same authors (Laversanne-Finot, Péré & Oudeyer, CoRL 2018, \
         *Curiosity Driven Exploration of Learned Disentangled Goal Spaces*) asks what happens \
         when the scene holds an object the agent cannot control. Campaigns {name} \
         ({} runs, {n_seeds} seeds): ArmBall's arm and ball plus a **distractor** ball that \
         follows a seeded random walk (`docs/armballs.md`); random parameters (RPE) and goal \
         exploration with engineered features (EFR: ball and distractor positions) or in goal \
         spaces learned from images of both balls ({spaces}), each **flat** (one \
         module, the follow-up's RGE) or **modular** (MGE: one module per object, or pairs of \
         latents), the module chosen at random or by **learning progress** (LP, curiosity). \
         Exploration is measured on the controllable ball; the distractor, which no policy \
         can move, is measured the same way as a control.\n",
        runs.len()
    );

    // 0. Findings first, from the claims' verdicts.
    if let FollowupClaims::Evaluated { results, .. } = followup_claims {
        let _ = writeln!(p, "{}", claims::findings(runs, results));
    }

    // 1. Exploration of the ball.
    let _ = writeln!(
        p,
        "## Exploration of the controllable ball\n\n\
         Final values after the last exploration iteration, mean over seeds with the \
         {:.0}% t interval of the mean (Student; — with fewer than 2 seeds). *Ratio* is the follow-up's exploration ratio \
         (ball cells visited on a {bins}x{bins} grid over [-1, 1]², divided by all {all} \
         cells; at most {most:.2}); *KLC* is the paper's KL-coverage (lower is better). The \
         distractor columns are \
         the control: its walk does not depend on the policy, so every algorithm should get \
         the same values there.\n",
        CONFIDENCE * 100.0,
        bins = ball_grid().bins,
        all = ball_cells().1,
        most = ball_cells().0 / ball_cells().1,
    );
    p.push_str(
        "| algorithm | seeds | ball ratio | ball KLC | distractor ratio (control) | distractor KLC (control) |\n|---|---|---|---|---|---|\n",
    );
    for a in algos(runs) {
        let rs = of(runs, &a);
        let r = ratios(runs, &a);
        let ratio = match t_interval(&r, CONFIDENCE) {
            Ok(i) => format!("{} [{}, {}]", f3(i.estimate), f3(i.lo), f3(i.hi)),
            Err(_) if r.is_empty() => "n/a".into(),
            Err(_) => format!("{} (—)", f3(mean(&r))),
        };
        let klc: Vec<f64> = rs
            .iter()
            .map(|r| r.ball_klc.last().copied().unwrap_or(f64::NAN))
            .collect();
        // The distractor's measure counts all 900 cells: its coverage is the ratio.
        let dratio: Vec<f64> = rs
            .iter()
            .filter_map(|r| r.distractor_coverage.last().copied().flatten())
            .collect();
        let dklc: Vec<f64> = rs
            .iter()
            .filter_map(|r| r.distractor_klc.last().copied().flatten())
            .collect();
        let _ = writeln!(
            p,
            "| {} | {} | {ratio} | {} | {} | {} |",
            display(runs, &a),
            rs.len(),
            f3(mean(&klc)),
            if dratio.is_empty() {
                "n/a".into()
            } else {
                f3(mean(&dratio))
            },
            if dklc.is_empty() {
                "n/a".into()
            } else {
                f3(mean(&dklc))
            },
        );
    }
    let _ = writeln!(
        p,
        "\n![Ball and distractor exploration ratio, mean over the seeds of each condition (n in \
         the legend; no interval drawn: the table above gives the final ball ratios with their \
         95% t intervals)](figures/{COVERAGE_FIGURE})\n"
    );

    // 2. Interest per module.
    let lp: Vec<Condition> = algos(runs)
        .into_iter()
        .filter(|a| {
            a.chooses(&ugl_types::LEARNING_PROGRESS) || a.chooses(&ugl_types::RANDOM_MODULE)
        })
        .collect();
    if !lp.is_empty() {
        let _ = writeln!(
            p,
            "## Interest per module\n\n\
             The follow-up's key figure: with learning-progress choice, interest (|learning \
             progress|, `docs/learning-progress.md`) should concentrate on the modules that \
             encode the controllable ball. Modules of a learned space are pairs of latents \
             (in decreasing order of their variance over the training images, or of their KL \
             where the network records it), so module k holds other latents in every seed: \
             they are aligned across seeds by their *ball R²* − *distractor R²* (*rank 1*: the \
             most ball-selective module of its seed), the mean, over the module's latents, of \
             the held-out k-NN R² of each latent from that object's position (section \
             *Disentanglement*). Values at the last iteration, mean over seeds; *goals* is the \
             share of goals drawn in the module.\n"
        );
        p.push_str(
            "| algorithm | module | final interest | goals | ball R² | distractor R² |\n|---|---|---|---|---|---|\n",
        );
        for a in &lp {
            let rs = of(runs, a);
            let slots = rs.iter().map(|r| r.modules.len()).max().unwrap_or(0);
            let ranked = rs.iter().any(|r| r.modules_ranked());
            for slot in 0..slots {
                let mut interest = Vec::new();
                let mut share = Vec::new();
                let mut objects = Vec::new();
                let mut name = String::new();
                let mut index = None;
                for r in &rs {
                    let Some(&m) = r.aligned_modules().get(slot) else {
                        continue;
                    };
                    index.get_or_insert(m);
                    let fin = r.final_interest();
                    let total: i64 = fin.values().map(|v| v.1).sum();
                    if let Some(&(i, n)) = fin.get(&m) {
                        interest.push(i);
                        share.push(if total > 0 {
                            n as f64 / total as f64
                        } else {
                            0.0
                        });
                    }
                    if let Some(o) = r.module_objects(m) {
                        objects.push(o);
                    }
                    if let Some((n, _)) = r.modules.get(&m)
                        && a.engineered()
                    {
                        name = n.clone();
                    }
                }
                let module = match (ranked, name.is_empty()) {
                    (true, _) => format!("rank {}", slot + 1),
                    (false, true) => format!("{}", index.unwrap_or(slot as i64)),
                    (false, false) => format!("{} ({name})", index.unwrap_or(slot as i64)),
                };
                let (b, d) = if objects.is_empty() {
                    ("n/a".to_string(), "n/a".to_string())
                } else {
                    (
                        f2(mean(&objects.iter().map(|o| o.0).collect::<Vec<_>>())),
                        f2(mean(&objects.iter().map(|o| o.1).collect::<Vec<_>>())),
                    )
                };
                let _ = writeln!(
                    p,
                    "| {} | {module} | {:.2e} | {} | {b} | {d} |",
                    display(runs, a),
                    mean(&interest),
                    f2(mean(&share)),
                );
            }
        }
        if figures.iter().any(|f| f.link.ends_with(INTEREST_FIGURE)) {
            let _ = writeln!(
                p,
                "\n![Interest per module, mean over the seeds (n in the legend; no interval \
                 drawn), log scale](figures/{INTEREST_FIGURE})\n"
            );
        }
    }

    // 3. Disentanglement.
    let learned = one_run_per_network(runs);
    if !learned.is_empty() {
        let _ = writeln!(
            p,
            "## Disentanglement of the learned goal spaces\n\n\
             One network per learner and seed (shared by its flat and modular runs). *Loss* is \
             the reconstruction loss against the mean-image plateau (below 1: the network \
             learned); *ball* / *distractor* k-NN R² say whether each object's position can be \
             read off the latents (held-out images). Per latent, the k-NN R² of the latent from \
             each object's position classifies it: **ball** (ball R² ≥ {ENCODES}, distractor \
             < {IGNORES}), **distractor** (the reverse), **both** (entangled: both ≥ {IGNORES}), \
             **none** (both below {IGNORES}; collapsed), otherwise *mostly* one. *Code*: \
             **disentangled** in the follow-up's sense (\"each latent variable is sensitive to a \
             single degree of freedom\") when an *active* latent encodes the ball alone, another \
             the distractor alone, and none encodes both (active: above {ACTIVE_NATS} nats; the \
             R² is blind to a latent's scale, so a collapsed latent can still follow an object); \
             **entangled** when the code holds both objects (k-NN R² of each at least \
             {ENCODES}) and is not disentangled; **not both objects** otherwise (blind to one). \
             The claims about a disentangled space compare the repetitions whose β-VAE is \
             disentangled, those about the entangled control the repetitions whose VAE is \
             entangled.\n"
        );
        // MIG, SAP and the active latents, where the networks record them.
        let measured = learned
            .iter()
            .any(|r| r.mig.is_some() || !r.kl_per_latent.is_empty());
        if measured {
            let _ = writeln!(
                p,
                "*MIG* (mutual information gap, Chen et al. 2018) and *SAP* (separated attribute \
                 predictability, Kumar et al. 2018) score the latents against the four \
                 coordinates of the two objects on the held-out images: 1 when each coordinate \
                 is captured by one latent alone. *Active*: latents whose posterior's mean KL \
                 divergence from the prior exceeds {ACTIVE_NATS} nats (the follow-up's \
                 criterion), with their kinds.\n"
            );
        }
        p.push_str(
            "| learner | seed | loss / plateau | ball k-NN R² | distractor k-NN R² | ball-only latents | distractor-only | both | none | code |",
        );
        p.push_str(if measured {
            " MIG | SAP | active latents |"
        } else {
            ""
        });
        p.push_str(
            " per latent: ball R² / distractor R² |\n|---|---|---|---|---|---|---|---|---|---|",
        );
        p.push_str(if measured { "---|---|---|" } else { "" });
        p.push_str("---|\n");
        for r in &learned {
            let (b, d) = r.per_latent.as_ref().expect("filtered");
            let roles: Vec<LatentRole> = b.iter().zip(d).map(|(b, d)| role(*b, *d)).collect();
            let count = |kind| count_role(&roles, kind);
            let per: Vec<String> = b
                .iter()
                .zip(d)
                .map(|(b, d)| format!("{b:.2}/{d:.2}"))
                .collect();
            let extra = if measured {
                let active = active_roles(&r.kl_per_latent, b, d);
                format!(
                    " {} | {} | {} |",
                    r.mig.map(f2).unwrap_or_else(|| "n/a".into()),
                    r.sap.map(f2).unwrap_or_else(|| "n/a".into()),
                    if r.kl_per_latent.is_empty() {
                        "n/a".to_string()
                    } else {
                        format!(
                            "{} ({})",
                            active.len(),
                            active
                                .iter()
                                .map(|r| r.label())
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    }
                )
            } else {
                String::new()
            };
            let _ = writeln!(
                p,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |{extra} {} |",
                match (r.learner.as_deref().map(learner_name), r.cond.tag()) {
                    (Some(l), "") => l,
                    (Some(l), t) => format!("{l}, {t}"),
                    (None, _) => String::new(),
                } + &if several_sizes {
                    format!(", {} latents", r.key.latents)
                } else {
                    String::new()
                },
                r.seed,
                r.loss_fraction.map(f2).unwrap_or_else(|| "n/a".into()),
                r.knn_ball.map(f2).unwrap_or_else(|| "n/a".into()),
                r.knn_distractor.map(f2).unwrap_or_else(|| "n/a".into()),
                count(LatentRole::Ball),
                count(LatentRole::Distractor),
                count(LatentRole::Both),
                count(LatentRole::Neither),
                CodeKind::of(r).map_or("n/a", CodeKind::label),
                per.join(" "),
            );
        }
        p.push('\n');
    }

    // 4. Claims.
    let (intro, table) = match followup_claims {
        FollowupClaims::Evaluated {
            path,
            confidence,
            results,
            ratio_at,
        } => {
            let (yes, no, open, premise, not_run) = claims::counts(results);
            let read_at = match ratio_at {
                Some(at) => format!(
                    " In the authors' ArmBalls the ball's exploration ratio is read at our last \
                     evaluation at or before their last point ({at} rollouts), where their \
                     curves end, so the claims' means sit a little below the final values of \
                     the table above; the goal-reaching error is read at the last epoch."
                ),
                None => " The ball's exploration ratio and the goal-reaching error are read at \
                         the last epoch."
                    .into(),
            };
            let not_run = if not_run > 0 {
                format!(", {not_run} not run (their conditions are not in these results)")
            } else {
                String::new()
            };
            (
                format!(
                    "The follow-up's text gives no number we could read \
                     (`docs/followup-paper-sources.md` section 5), so each claim is formalised \
                     here (our choice, `{}`, explained in `docs/armballs.md`) and evaluated by \
                     the same engine as the paper's claims.{read_at} {} **Premise not met** when the \
                     claim is about a disentangled space (or the entangled control) and no \
                     repetition's network here is one. Of {} \
                     claims: {yes} reproduced, {no} not reproduced, {open} inconclusive, \
                     {premise} with the premise not met{not_run}.",
                    path.display(),
                    crate::markdown::claims::method_text(*confidence),
                    results.len()
                ),
                claims::table(runs, results),
            )
        }
        FollowupClaims::Missing(path) => (
            format!(
                "No claims file at `{}`: the follow-up's claims are not evaluated.",
                path.display()
            ),
            String::new(),
        ),
    };
    let _ = writeln!(p, "## The follow-up's claims\n\n{intro}\n\n{table}");
    let summary = format!(
        "## Beyond the paper: a distractor (ArmBalls)\n\n\
         The follow-up paper's setting (a distractor ball, modular goal exploration, learning \
         progress, β-VAE) on campaigns {name} ({} runs): exploration, interest curves, \
         disentanglement and figures in [{PAGE}]({PAGE}). Its claims:\n\n{table}",
        runs.len()
    );
    (p, summary)
}
