//! `ugl campaign --refresh-diagnostics`: bring a campaign's goal-space diagnostics up to date
//! without rerunning its explorations: the latent-quality measure of finished runs (up to
//! [`MEASURE_VERSION`]) and the goal-space figure data of seed 0 ([`goal_space`]).
//!
//! The diagnostics are not results: no run's data depend on them. When the measure improves,
//! or figure data are missing, the finished runs keep their data files: each representation
//! concerned is fitted again exactly as for its runs (a neural one is loaded from the model
//! cache when it is there), measured once, its new measure written beside each run that shares
//! it ([`Diagnostics`], `DIR/diagnostics/<run_id>.json`, with this code's revision: manifests
//! are never rewritten), and its figure data written. What is already current is left alone,
//! so an interrupted refresh resumes where it stopped.

use std::path::Path;
use std::sync::atomic::Ordering;

use super::config::CampaignConfig;
use super::error::RunError;
use super::fit::fit_representation;
use super::goal_space;
use super::plan::{RunSpec, plan, shard};
use super::provenance::{crate_versions, git_revision};
use super::runner::{CampaignOptions, campaign_context, for_each_group};
use super::store::{self, Manifest};
use crate::repr::ReprError;
use crate::repr::quality::MEASURE_VERSION;
use ugl_types::Diagnostics;

/// What a remeasure did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Remeasured {
    /// Representations fitted (or loaded) and measured now.
    pub representations: usize,
    /// Runs whose diagnostics sidecar was written.
    pub runs: usize,
    /// Finished learned-space runs that already held the current measure.
    pub current: usize,
    /// Learned-space runs of the plan that are not finished (run the campaign first).
    pub unfinished: usize,
    /// Goal-space figure samples written.
    pub samples: usize,
}

/// The measure version a run holds: its diagnostics sidecar's, else its manifest's (1 when it
/// predates versioning; 0 when it has none).
pub fn measure_version(m: &Manifest, sidecar: Option<&Diagnostics>) -> u64 {
    if let Some(d) = sidecar {
        return d.measure_version();
    }
    match &m.latent_quality {
        None => 0,
        Some(q) => u64::from(q.version),
    }
}

/// Re-measure the latent quality of every finished learned-space run of `cfg` in `out` whose
/// manifest holds an older measure, and write the missing goal-space figure data.
/// `on_measured` receives each representation's label when it is done. Honours `opts.jobs`,
/// `opts.shard`, the harness's model cache and `opts.stop` (stops after the representations in
/// flight; rerun to finish).
pub fn refresh_diagnostics(
    cfg: &CampaignConfig,
    out: &Path,
    opts: &CampaignOptions,
    on_measured: &(dyn Fn(&str) + Sync),
) -> Result<Remeasured, RunError> {
    let ctx = campaign_context(cfg, out, opts);
    let all = match opts.shard {
        None => plan(cfg),
        Some((i, n)) => shard(&plan(cfg), cfg.ugl.images, i, n),
    };
    let mut done = Remeasured::default();
    // Per representation: its finished runs, each with its manifest when the measure is old.
    let mut entries: Vec<(&RunSpec, Option<Manifest>)> = Vec::new();
    for spec in all.iter().filter(|s| s.algo.learner().is_some()) {
        if !store::is_complete(out, &spec.run_id(), &ctx.config_hash(spec)) {
            done.unfinished += 1;
            continue;
        }
        let manifest = store::read_manifest(&store::run_paths(out, &spec.run_id()).manifest)?;
        let sidecar = Diagnostics::read(out, &spec.run_id()).unwrap_or_else(|e| {
            tracing::warn!("{e}: measured again");
            None
        });
        let stale = measure_version(&manifest, sidecar.as_ref()) < u64::from(MEASURE_VERSION);
        done.current += usize::from(!stale);
        entries.push((spec, stale.then_some(manifest)));
    }
    let mut groups = super::plan::representation_groups(entries, |e| e.0, cfg.ugl.images);
    // Only the representations with something to do.
    groups.retain(|(_, runs)| {
        let first = runs[0].0;
        runs.iter().any(|(_, m)| m.is_some())
            || (goal_space::wanted(first) && !goal_space::exists(out, first))
    });
    let results = for_each_group(opts.jobs, groups.len(), &|g| -> Option<
        Result<(usize, usize), RunError>,
    > {
        if opts.stop.load(Ordering::SeqCst) {
            return None;
        }
        let runs = &groups[g].1;
        let first = runs[0].0;
        let refresh = || -> Result<(usize, usize), RunError> {
            let repr_err = |source| RunError::Repr {
                run: first.run_id(),
                source,
            };
            let mut repr = fit_representation(first, &ctx).map_err(repr_err)?;
            let mut samples = 0;
            if goal_space::wanted(first) && !goal_space::exists(out, first) {
                goal_space::write(out, first, &ctx, &mut repr).map_err(repr_err)?;
                samples += 1;
            }
            let stale: Vec<&Manifest> = runs.iter().filter_map(|(_, m)| m.as_ref()).collect();
            if !stale.is_empty() {
                let quality = repr.quality.as_ref().ok_or_else(|| {
                    repr_err(ReprError::Numerical(
                        "the latent quality could not be measured (the log says why)".into(),
                    ))
                })?;
                for manifest in &stale {
                    store::write_diagnostics(
                        out,
                        &Diagnostics {
                            run_id: manifest.run_id.clone(),
                            git_revision: git_revision().into(),
                            crate_versions: crate_versions(),
                            latent_quality: quality.clone(),
                        },
                    )?;
                }
            }
            on_measured(&super::fit::representation_label(first));
            Ok((stale.len(), samples))
        };
        Some(refresh())
    })?;
    let mut interrupted = false;
    for r in results {
        match r {
            Some(Ok((n, samples))) => {
                done.representations += 1;
                done.runs += n;
                done.samples += samples;
            }
            Some(Err(e)) => return Err(e),
            None => interrupted = true,
        }
    }
    if interrupted {
        let stale: usize = groups
            .iter()
            .flat_map(|g| &g.1)
            .filter(|(_, m)| m.is_some())
            .count();
        return Err(RunError::Interrupted {
            done: done.current + done.runs,
            total: done.current + stale,
        });
    }
    Ok(done)
}
