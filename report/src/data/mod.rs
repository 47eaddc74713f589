//! The numbers behind the report as CSV, beside it (`out/data/`), for people who compare a new
//! learner or redo a statistic: one row per run (its final values, with its training evidence and
//! latent quality where recorded) and one row per run and evaluated epoch (the whole curves). The
//! main campaign and every `compare-*` campaign; rows in the report's condition order, then seed.

pub mod claims;
pub mod discovery;
pub mod leaderboard;
pub mod predicts;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::campaigns::{Campaign, Campaigns};
use crate::error::ReportError;
use crate::load::Run;
use crate::output::Output;

/// The directory under the report's output.
pub const DIR: &str = "data";
/// One row per run.
pub const FINAL_FILE: &str = "final_by_seed.csv";
/// One row per run and evaluated epoch.
pub const CURVES_FILE: &str = "curves.csv";

/// A run's key: its condition, its repetition (`seed`) and its exploration replicate
/// (`exploration`, 0 where a repetition has one).
const KEY_HEADER: &str = "campaign,env,algo,sampler,latents,variant,seed,exploration";

fn key_fields(camp: &Campaign, r: &Run) -> String {
    format!(
        "{},{},{},{},{},{},{},{}",
        if camp.name.is_empty() {
            "."
        } else {
            &camp.name
        },
        r.key.env,
        r.key.algo,
        r.key.sampler,
        r.key.latents,
        r.key.variant,
        r.seed,
        r.manifest.exploration
    )
}

/// A float as CSV: shortest round-trip form; `inf`; empty when absent.
pub(crate) fn num(v: Option<f64>) -> String {
    v.map(|v| format!("{v}")).unwrap_or_default()
}

fn runs_in_order(camp: &Campaign) -> Vec<&Run> {
    let mut runs: Vec<&Run> = camp.store.runs.iter().collect();
    runs.sort_by(|a, b| {
        (a.key.order_key(), a.seed, &a.run_id).cmp(&(b.key.order_key(), b.seed, &b.run_id))
    });
    runs
}

/// Write both files into `dir`; returns their paths.
pub fn write(out: &mut Output, camps: &Campaigns) -> Result<Vec<PathBuf>, ReportError> {
    let sources: Vec<&Campaign> = std::iter::once(&camps.main)
        .chain(camps.compare.iter())
        .collect();
    let mut finals = format!(
        "{KEY_HEADER},epoch,final_klc,n_moved,n_outcomes,coverage,trained,loss_fraction,\
         linear_r2_mean,knn_r2_mean,quality_version,position_knn_r2,angle_knn_r2,\
         angle_mod_120_knn_r2\n"
    );
    let mut curves = format!("{KEY_HEADER},epoch,n_outcomes,klc,n_moved,coverage\n");
    for camp in sources {
        for r in runs_in_order(camp) {
            let key = key_fields(camp, r);
            let f = r.final_point();
            let evidence = r.manifest.training_evidence();
            let quality = r.manifest.latent_quality.as_ref();
            let _ = writeln!(
                finals,
                "{key},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                f.epoch,
                num(Some(f.klc)),
                f.n_moved,
                f.n_outcomes,
                num(Some(f.coverage)),
                r.manifest
                    .trained()
                    .map(|t| t.to_string())
                    .unwrap_or_default(),
                num(evidence.map(|e| e.loss_fraction)),
                num(quality.map(|q| q.linear_r2_mean)),
                num(quality.map(|q| q.knn_r2_mean)),
                quality.map(|q| q.version.to_string()).unwrap_or_default(),
                num(r.manifest.group_r2("position").map(|g| g.1)),
                num(r.manifest.group_r2("angle").map(|g| g.1)),
                num(r.manifest.group_r2("angle_mod_120").map(|g| g.1)),
            );
            for p in &r.curve {
                let _ = writeln!(
                    curves,
                    "{key},{},{},{},{},{}",
                    p.epoch,
                    p.n_outcomes,
                    num(Some(p.klc)),
                    p.n_moved,
                    num(Some(p.coverage))
                );
            }
        }
    }
    let mut written = Vec::new();
    for (name, text) in [(CURVES_FILE, curves), (FINAL_FILE, finals)] {
        written.push(out.write(Path::new(DIR).join(name), text.as_bytes())?);
    }
    Ok(written)
}
