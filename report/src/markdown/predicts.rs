//! The section "Does latent quality predict exploration?" and its one-sentence summaries
//! ([`crate::predicts`] computes the table).

use std::fmt::Write as _;

use ugl_types::EnvSpec;

use crate::data::predicts::FILE;
use crate::predicts::{Line, Observation, envs};
use crate::stats::CONFIDENCE;
use crate::stats::correlation::normal_quantile;

/// `r [lo, hi]`, or a dash.
fn with_ci(r: Option<f64>, ci: Option<(f64, f64)>) -> String {
    match (r, ci) {
        (Some(r), Some((lo, hi))) => format!("{} [{}, {}]", two(r), two(lo), two(hi)),
        (Some(r), None) => two(r),
        _ => "—".into(),
    }
}

fn fixed(v: Option<f64>, digits: usize) -> String {
    v.map(|v| format!("{:.digits$}", v.max(0.0)))
        .unwrap_or_else(|| "—".into())
}

/// `a`, `a and b`, `a, b and c` (or `or`).
fn join(items: &[String], word: &str) -> String {
    match items {
        [] => String::new(),
        [a] => a.clone(),
        [rest @ .., last] => format!("{} {word} {last}", rest.join(", ")),
    }
}

/// Two decimals; a value that is zero up to rounding error is `0.00`, never `-0.00` (a small
/// negative value keeps its sign: an interval bound of `-0.00` excludes 0).
fn two(v: f64) -> String {
    if v.abs() < 1e-12 {
        "0.00".into()
    } else {
        format!("{v:.2}")
    }
}

fn campaign_name(name: &str) -> String {
    if name.is_empty() {
        "(top level)".into()
    } else {
        format!("`{name}`")
    }
}

/// The report's section: the method, the table, one sentence per environment.
pub fn section(w: &mut String, obs: &[Observation], lines: &[Line], main: &str) {
    let level = CONFIDENCE * 100.0;
    let z = normal_quantile(0.5 + CONFIDENCE / 2.0);
    let mut camps: Vec<&str> = Vec::new();
    for o in obs {
        if !camps.contains(&o.campaign.as_str()) {
            camps.push(&o.campaign);
        }
    }
    let counts: Vec<String> = envs(obs)
        .iter()
        .map(|env| {
            let per: Vec<String> = camps
                .iter()
                .filter_map(|c| {
                    let k = obs
                        .iter()
                        .filter(|o| o.env == *env && o.campaign == *c)
                        .count();
                    (k > 0).then(|| format!("{k} from {}", campaign_name(c)))
                })
                .collect();
            format!("{} {}", EnvSpec::display_of(env), join(&per, "and"))
        })
        .collect();
    let averaged = obs.iter().filter(|o| o.n_runs > 1).count();
    let recipes: Vec<String> = camps
        .iter()
        .filter(|c| **c != main)
        .map(|c| campaign_name(c))
        .collect();
    let _ = writeln!(
        w,
        "### Does latent quality predict discovery beyond the number of moves?\n\n\
         KL-coverage mostly counts how often the object moved, and a goal space that encodes the \
         object's position may only move it more often. Does the quality of a learned goal \
         space, the held-out k-NN R² of the object's position from its latents \
         (`latent_quality`, group `position`), still predict what the exploration discovered \
         once the number of episodes that moved the object is accounted for?\n\n\
         **Method.** Observations: the learned-goal-space runs with a recorded position R² \
         (RPE and RGE-EFR have no latents) of the main campaign {}{}: {}. Each run is one \
         observation: the runs of one fit with KDE and with Gaussian goals share their latents \
         (and so their R²) but explore differently, and count twice, so the observations are \
         not independent and the intervals below are somewhat too narrow. Exploration \
         replicates of one fit with one sampler would be averaged into one observation ({} \
         observation{} average{} several runs). For each measure Y: Pearson's r of position R² \
         with Y; the partial r given ln(1 + moves), both residualised on ln(1 + moves) by least \
         squares and the residuals correlated; their {level:.0}% intervals by Fisher's z, \
         tanh(atanh r ± {z:.3}/√(n − 3)), with n − 4 for the partial r; the R² of the \
         least-squares regression of Y on ln(1 + moves) alone, and the R² that adding position \
         R² to it gains, (1 − R²) · partial r². Latent quality predicts Y *beyond the moves* \
         where the partial r's interval excludes 0. The untrained twins sit at low R² and few \
         moves: the correlations mix the difference between trained and untrained goal spaces \
         with the differences among trained ones. Per-run inputs are in \
         `data/{}` (`position_knn_r2`, `n_moved`), this table in `data/{FILE}`.\n",
        campaign_name(main),
        if recipes.is_empty() {
            " (no recipe campaign has such runs)".to_string()
        } else {
            format!(" and its recipe campaigns {}", join(&recipes, "and"))
        },
        counts.join("; "),
        if averaged == 0 {
            "no".to_string()
        } else {
            averaged.to_string()
        },
        if averaged == 1 { "" } else { "s" },
        if averaged == 1 { "s" } else { "" },
        crate::data::discovery::FILE,
    );
    let _ = writeln!(
        w,
        "| env | measure | n | r with position R² [{level:.0}% CI] | partial r given \
         ln(1 + moves) [{level:.0}% CI] | R² on ln(1 + moves) | R² gain from position R² |\n\
         |---|---|---|---|---|---|---|"
    );
    for l in lines {
        let a = l.stats.as_ref();
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} |",
            EnvSpec::display_of(&l.env),
            l.measure.label(),
            a.map(|a| a.n).unwrap_or(0),
            with_ci(a.and_then(|a| a.r), a.and_then(|a| a.r_ci)),
            with_ci(a.and_then(|a| a.partial), a.and_then(|a| a.partial_ci)),
            fixed(a.and_then(|a| a.r2_moves), 2),
            fixed(a.and_then(|a| a.gain), 3),
        );
    }
    w.push('\n');
    for env in envs(obs) {
        w.push_str(&sentence(&env, lines));
        w.push_str("\n\n");
    }
}

/// The sentence of one environment: which measures position R² still predicts beyond the
/// moves (the partial r's interval excludes 0), which it does not, which cannot be tested.
pub fn sentence(env: &str, lines: &[Line]) -> String {
    let mine: Vec<&Line> = lines.iter().filter(|l| l.env == env).collect();
    let named = |want: Option<bool>| -> Vec<String> {
        mine.iter()
            .filter(|l| l.stats.as_ref().and_then(|a| a.predicts_beyond_moves()) == want)
            .map(|l| {
                let a = l.stats.as_ref();
                match a.and_then(|a| a.partial) {
                    Some(p) => format!(
                        "{} (partial r {})",
                        l.measure.label(),
                        with_ci(Some(p), a.and_then(|a| a.partial_ci))
                    ),
                    None => l.measure.label().to_string(),
                }
            })
            .collect()
    };
    let (yes, no, untestable) = (named(Some(true)), named(Some(false)), named(None));
    let mut parts = Vec::new();
    if !yes.is_empty() {
        parts.push(format!("still predicts {}", join(&yes, "and")));
    }
    if !no.is_empty() {
        parts.push(format!("does not predict {}", join(&no, "or")));
    }
    if !untestable.is_empty() {
        parts.push(format!(
            "cannot be tested on {} (too few observations or no variance)",
            join(&untestable, "or")
        ));
    }
    format!(
        "**{}.** Beyond the number of moves (the {:.0}% interval of the partial r excluding 0), \
         position R² {}.",
        EnvSpec::display_of(env),
        CONFIDENCE * 100.0,
        parts.join("; it ")
    )
}
