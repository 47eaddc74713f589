//! The goal spaces' quality section: did each learned goal space learn (training loss against
//! the mean-image plateau), and how well can the true object state be read off its latents
//! (held-out R² of a linear and a k-NN map; `repr::quality` in the benchmark crate).

use std::fmt::Write;

use super::{env_name, plural};
use crate::context::Context;
use crate::figures::FigureFile;
use crate::load::Manifest;

/// A condition's row.
struct Row {
    env: String,
    algo: String,
    variant: String,
    latents: i64,
    representations: usize,
    /// Representations whose manifest records training evidence / latent quality.
    with_evidence: usize,
    untrained: usize,
    loss_fractions: Vec<f64>,
    /// Per run with the current measure: position R² (linear, k-NN), angle and angle modulo
    /// 120° R² (k-NN; arrow only).
    position_linear: Vec<f64>,
    position_knn: Vec<f64>,
    angle_knn: Vec<f64>,
    angle_mod_120_knn: Vec<f64>,
    /// Trustworthiness and continuity of the latents against the object's position (measure
    /// version 3 and later).
    trustworthiness: Vec<f64>,
    continuity: Vec<f64>,
    /// Runs whose manifest holds the first version of the measure (no groups).
    old_measure: usize,
    /// Runs whose measure has groups but no neighbourhoods (version 2).
    no_neighbourhoods: usize,
}

/// (trustworthiness, continuity) of a manifest's latents against a state space (`position`,
/// `state`), measure version 3 and later.
pub fn neighbourhoods(m: &Manifest, space: &str) -> Option<(f64, f64)> {
    let n = m
        .latent_quality
        .as_ref()?
        .neighbourhoods
        .iter()
        .find(|n| n.space == space)?;
    Some((n.trustworthiness, n.continuity))
}

pub(crate) fn evidence(m: &Manifest) -> Option<(f64, bool)> {
    let e = m.training_evidence()?;
    Some((e.loss_fraction, e.trained))
}

/// The (linear, k-NN) R² of a group of targets ([`Manifest::group_r2`]).
pub fn group_r2(m: &Manifest, group: &str) -> Option<(f64, f64)> {
    m.group_r2(group)
}

/// The median (None when empty): the one of `ugl_types`, the runner's and the report's.
pub(crate) use ugl_types::median;

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// Rows of the main campaign's learned goal spaces, one per (env, algo, variant, latents): the
/// KDE and Gaussian runs of a cell, and the exploration replicates of a repetition, share one
/// representation, so the KDE runs of replicate 0 are counted (each representation once).
fn rows(inp: &Context<'_>) -> Vec<Row> {
    let mut out: Vec<Row> = Vec::new();
    for c in inp.conditions.iter().filter(|c| c.key.latents > 0) {
        if c.key.sampler != ugl_types::Sampler::KDE {
            continue;
        }
        let mut r = Row {
            env: c.key.env.clone(),
            algo: c.key.algo.to_string(),
            variant: c.key.variant.to_string(),
            latents: c.key.latents,
            representations: 0,
            with_evidence: 0,
            untrained: 0,
            loss_fractions: Vec::new(),
            position_linear: Vec::new(),
            position_knn: Vec::new(),
            angle_knn: Vec::new(),
            angle_mod_120_knn: Vec::new(),
            trustworthiness: Vec::new(),
            continuity: Vec::new(),
            old_measure: 0,
            no_neighbourhoods: 0,
        };
        for &i in &c.runs {
            let m = &inp.store.runs[i].manifest;
            if m.exploration != 0 {
                continue;
            }
            r.representations += 1;
            if let Some((f, trained)) = evidence(m) {
                r.with_evidence += 1;
                r.loss_fractions.push(f);
                r.untrained += usize::from(!trained);
            }
            match group_r2(m, "position") {
                Some((l, k)) => {
                    r.position_linear.push(l);
                    r.position_knn.push(k);
                    if let Some((_, k)) = group_r2(m, "angle") {
                        r.angle_knn.push(k);
                    }
                    if let Some((_, k)) = group_r2(m, "angle_mod_120") {
                        r.angle_mod_120_knn.push(k);
                    }
                }
                None => r.old_measure += usize::from(m.latent_quality.is_some()),
            }
            match neighbourhoods(m, "position") {
                Some((t, c)) => {
                    r.trustworthiness.push(t);
                    r.continuity.push(c);
                }
                None => {
                    r.no_neighbourhoods += usize::from(group_r2(m, "position").is_some());
                }
            }
        }
        out.push(r);
    }
    out
}

/// The section (nothing when the campaign has no learned goal space).
pub fn section(
    w: &mut String,
    inp: &Context<'_>,
    goal_space_figures: &[FigureFile],
    reconstruction_figures: &[FigureFile],
) {
    let rows = rows(inp);
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        w,
        "## Did the goal spaces learn? Training and latent quality\n"
    );
    let _ = writeln!(
        w,
        "For each learned goal space of the main campaign (one representation per cell and \
         repetition, counted once: the Gaussian-goal runs and the exploration replicates share \
         it):\n\n\
         - **untrained**: neural representations whose reconstruction loss after training (the decoder \
         applied to each image's noise-free code, on 2000 training images; no KL or flow term) is \
         not below 0.8 x the *plateau*, the loss of those images' mean image (the best constant \
         prediction, computed exactly); such a goal space is an untrained random projection. \
         **loss / plateau** is the median of that ratio;\n\
         - **R²**: how well the true object state is predicted from the latents of 1000 \
         held-out images, by a linear map and by 10-nearest-neighbour regression, both fitted on \
         the whole training set (mean over seeds). **position**: ball or arrow x, y; **angle**: \
         the arrow's angle a as cos a, sin a; **angle mod 120°**: cos 3a, sin 3a. 1 is \
         perfect, 0 is no better than the mean;\n\
         - **T / C**: trustworthiness and continuity (Venna & Kaski 2001; the co-ranking \
         measures of the original code's `measures.py`) between the object's position and the \
         latents of the same held-out images, with 10 neighbours (mean over seeds). \
         *Trustworthiness* is 1 when every latent neighbour of an image is one of its nearest \
         positions (a goal space folded onto itself brings far-apart positions together and \
         loses it), *continuity* when every near position stays a latent neighbour (a goal \
         space torn apart loses it); chance level is about 0.5. R² says whether the position \
         can be read off the latents, T and C whether the latents keep its neighbourhoods, \
         which is what a goal sampled near another asks for.\n\n\
         Why the angle modulo 120°: the rendered arrow is a dart whose three outer corners lie \
         120° apart, and only the notch at its centre tells the tip from the other two. In \
         pixel distance the shape is nearly three-fold symmetric. From raw pixels (no learner), \
         10-NN regression on 9,000 ArmArrow images predicts cos 3a and sin 3a with R² 0.85 but \
         cos a and sin a with only 0.15 (0.45 at 38,000 images): the full angle is barely in \
         the pixels' neighbourhoods at the paper's 10,000 images, and a learner that misses it \
         is not broken. (Measured once outside the report: 10-NN regression with numpy on images \
         written by `ugl embed`; not rerun by `make report`.)\n"
    );
    let recorded = rows
        .iter()
        .any(|r| r.with_evidence > 0 || !r.position_knn.is_empty() || r.old_measure > 0);
    if !recorded {
        let _ = writeln!(
            w,
            "Not recorded: these results were written before the manifests recorded training \
             evidence and latent quality (results version 2). Rerun the campaign to fill this \
             table.\n"
        );
        return;
    }
    let _ = writeln!(
        w,
        "| env | algorithm | variant | latents | representations | untrained | loss / plateau | \
         position R² linear | position R² k-NN | angle R² k-NN | angle mod 120° R² k-NN | \
         position T / C |"
    );
    let _ = writeln!(
        w,
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in &rows {
        let untrained = if r.with_evidence == 0 {
            "—".to_string()
        } else if r.untrained > 0 {
            format!("**{} of {}**", r.untrained, r.with_evidence)
        } else {
            format!("0 of {}", r.with_evidence)
        };
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            env_name(&r.env),
            crate::names::algo_name(&r.algo),
            r.variant,
            r.latents,
            r.representations,
            untrained,
            fmt(median(&r.loss_fractions), 2),
            fmt(mean(&r.position_linear), 3),
            fmt(mean(&r.position_knn), 3),
            fmt(mean(&r.angle_knn), 3),
            fmt(mean(&r.angle_mod_120_knn), 3),
            match (mean(&r.trustworthiness), mean(&r.continuity)) {
                (Some(t), Some(c)) => format!("{t:.3} / {c:.3}"),
                _ => "—".into(),
            }
        );
    }
    let old: usize = rows.iter().map(|r| r.old_measure).sum();
    if old > 0 {
        let _ = writeln!(
            w,
            "\n{old} representation{} the first version of the latent-quality measure (fitted on 2000 \
             images, no groups) and show{} \"—\": `ugl campaign --config ... --refresh-diagnostics` \
             brings them up to date without rerunning them.",
            if old == 1 { " holds" } else { "s hold" },
            if old == 1 { "s" } else { "" }
        );
    }
    let v2: usize = rows.iter().map(|r| r.no_neighbourhoods).sum();
    if v2 > 0 {
        let _ = writeln!(
            w,
            "\n{v2} representation{} version 2 of the latent-quality measure (no trustworthiness or \
             continuity) and show{} \"—\" under T / C: `ugl campaign --config ... \
             --refresh-diagnostics` brings them up to date without rerunning them.",
            if v2 == 1 { " holds" } else { "s hold" },
            if v2 == 1 { "s" } else { "" }
        );
    }
    let n_untrained: usize = rows.iter().map(|r| r.untrained).sum();
    let n_evidence: usize = rows.iter().map(|r| r.with_evidence).sum();
    let _ = writeln!(
        w,
        "\n{n_untrained} of {n_evidence} neural representation{} did not leave the plateau.\n",
        plural(n_evidence)
    );
    figures(w, goal_space_figures, reconstruction_figures);
}

/// The goal-space lattices and the reconstruction grids.
fn figures(
    w: &mut String,
    goal_space_figures: &[FigureFile],
    reconstruction_figures: &[FigureFile],
) {
    if goal_space_figures.is_empty() && reconstruction_figures.is_empty() {
        let _ = writeln!(
            w,
            "No goal-space figure data in this campaign (`goal_spaces/`): \
             `ugl campaign --config ... --refresh-diagnostics` writes it for finished runs.\n"
        );
        return;
    }
    let _ = writeln!(w, "### What the goal spaces look like\n");
    let _ = writeln!(
        w,
        "A 21 x 21 lattice of object positions over [-1, 1]² (ArmArrow: angle 0), encoded by \
         the goal space of seed 0 of each learned cell (10 latents: their top two principal \
         axes). Lines of constant x are red, lines of constant y blue, darker for larger \
         values. An even, unfolded mesh keeps the object's position the way the engineered \
         features do; a folded or collapsed one loses it. The goal spaces' latents are the \
         same `ugl embed --grid 21` writes.\n"
    );
    for f in goal_space_figures {
        let _ = writeln!(w, "![{}]({})\n", f.caption, f.link);
    }
    if !reconstruction_figures.is_empty() {
        let _ = writeln!(
            w,
            "Reconstructions (seed 0): eight held-out images (top row) and what the network \
             makes of them from their noise-free code (bottom row).\n"
        );
        let _ = writeln!(w, "| goal space | held-out images / reconstructions |");
        let _ = writeln!(w, "|---|---|");
        for f in reconstruction_figures {
            let label = f
                .caption
                .split(':')
                .next()
                .unwrap_or(&f.caption)
                .to_string();
            let _ = writeln!(w, "| {label} | ![{}]({}) |", f.caption, f.link);
        }
        let _ = writeln!(w);
    }
}
