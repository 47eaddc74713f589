//! The goal spaces' quality section: did each learned goal space learn (training loss against
//! the mean-image plateau), and how well can the true object state be read off its latents
//! (held-out R² of a linear and a k-NN map; `repr::quality` in the benchmark crate).

use std::fmt::Write;

use super::{Inputs, env_name, plural};
use crate::load::Manifest;

/// A condition's row.
struct Row {
    env: String,
    algo: String,
    variant: String,
    latents: i64,
    runs: usize,
    /// Runs whose manifest records training evidence / latent quality.
    with_evidence: usize,
    untrained: usize,
    loss_fractions: Vec<f64>,
    linear: Vec<f64>,
    knn: Vec<f64>,
}

fn evidence(m: &Manifest) -> Option<(f64, bool)> {
    let e = m.raw.get("train")?.get("evidence")?;
    Some((e.get("loss_fraction")?.as_f64()?, m.trained()?))
}

fn quality(m: &Manifest) -> Option<(f64, f64)> {
    let q = m.raw.get("latent_quality")?;
    Some((
        q.get("linear_r2_mean")?.as_f64()?,
        q.get("knn_r2_mean")?.as_f64()?,
    ))
}

fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    Some(if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    })
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// Rows of the main campaign's learned goal spaces, one per (env, algo, variant, latents): the
/// KDE and Gaussian runs of a cell share one representation, so the KDE runs are counted (each
/// representation once).
fn rows(inp: &Inputs<'_>) -> Vec<Row> {
    let mut out: Vec<Row> = Vec::new();
    for c in inp.conditions.iter().filter(|c| c.key.latents > 0) {
        if c.key.sampler != "kde" {
            continue;
        }
        let mut r = Row {
            env: c.key.env.clone(),
            algo: c.key.algo.clone(),
            variant: c.key.variant.clone(),
            latents: c.key.latents,
            runs: c.runs.len(),
            with_evidence: 0,
            untrained: 0,
            loss_fractions: Vec::new(),
            linear: Vec::new(),
            knn: Vec::new(),
        };
        for &i in &c.runs {
            let m = &inp.store.runs[i].manifest;
            if let Some((f, trained)) = evidence(m) {
                r.with_evidence += 1;
                r.loss_fractions.push(f);
                r.untrained += usize::from(!trained);
            }
            if let Some((l, k)) = quality(m) {
                r.linear.push(l);
                r.knn.push(k);
            }
        }
        out.push(r);
    }
    out
}

/// The section (nothing when the campaign has no learned goal space).
pub fn section(w: &mut String, inp: &Inputs<'_>) {
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
        "For each learned goal space of the main campaign (one representation per cell and seed; \
         the Gaussian-goal runs share the KDE runs' representation):\n\n\
         - **untrained**: neural runs whose reconstruction loss after training (the decoder \
         applied to each image's noise-free code, on 2000 training images; no KL or flow term) is \
         not below 0.8 x the *plateau*, the loss of those images' mean image (the best constant \
         prediction, computed exactly); such a goal space is an untrained random projection. \
         **loss / plateau** is the median of that ratio;\n\
         - **R² linear / k-NN**: how well the true object state (ball x, y; arrow x, y and its \
         angle as cos, sin) is predicted from the latents of 1000 held-out images, by a linear \
         map and by 10-nearest-neighbour regression fitted on 2000 training images (mean over \
         the state's coordinates and over seeds). 1 is perfect, 0 is no better than the mean.\n"
    );
    let recorded = rows
        .iter()
        .any(|r| r.with_evidence > 0 || !r.linear.is_empty());
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
        "| env | algorithm | variant | latents | runs | untrained | loss / plateau | R² linear | R² k-NN |"
    );
    let _ = writeln!(w, "|---|---|---|---:|---:|---:|---:|---:|---:|");
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
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            env_name(&r.env),
            crate::figures::algo_name(&r.algo),
            r.variant,
            r.latents,
            r.runs,
            untrained,
            fmt(median(&r.loss_fractions), 2),
            fmt(mean(&r.linear), 3),
            fmt(mean(&r.knn), 3)
        );
    }
    let n_untrained: usize = rows.iter().map(|r| r.untrained).sum();
    let n_evidence: usize = rows.iter().map(|r| r.with_evidence).sum();
    let _ = writeln!(
        w,
        "\n{n_untrained} of {n_evidence} neural representation{} did not leave the plateau.\n",
        plural(n_evidence)
    );
}
