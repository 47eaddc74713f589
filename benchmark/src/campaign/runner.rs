//! Scheduling a campaign: the runs not yet complete, grouped by shared representation, on a
//! pool of workers; the failure and interruption policy.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use super::config::CampaignConfig;
use super::goal_space;
use super::plan::{RunSpec, plan};
use super::store::{self, StoreError, Summary};
use crate::explore::Learner;
use ugl_types::CampaignRecord;

use super::context::{Harness, RunContext};
use super::error::RunError;
use super::execute::execute;
use super::fit::fit_representation;
/// Bumped whenever a change alters results for the same configuration (its history is on the
/// definition, in `ugl-types`).
pub use ugl_types::RESULTS_VERSION;

/// Progress events of a campaign.
#[derive(Clone, Debug)]
pub enum Progress {
    /// The plan: total runs and how many are already complete (skipped).
    Planned { total: usize, skipped: usize },
    /// A run finished.
    Finished(Summary),
    /// A run failed (its fit or its exploration; not the runs skipped because a fit they share
    /// failed before); the campaign goes on with the other groups and returns an error at the
    /// end.
    Failed { run: String, error: String },
}

/// The outcome of each run of a group (None: skipped after a stop request).
type GroupResult = Vec<Option<Result<Summary, RunError>>>;

/// Options of a campaign execution.
pub struct CampaignOptions<'a> {
    /// Worker threads (runs in parallel; each run is single-threaded).
    pub jobs: usize,
    /// Set to stop after the runs in flight (Ctrl-C).
    pub stop: &'a AtomicBool,
    /// Run only this slice `(index, count)` of the plan (`--shard i/n`).
    pub shard: Option<(usize, usize)>,
    /// The services of its runs; their learner logs go to the results directory and their
    /// trainings use their worker's pool, whatever `log_dir` and `train_threads` say.
    pub harness: Harness<'a>,
}

/// The run context of a campaign's runs.
pub(crate) fn campaign_context<'a>(
    cfg: &'a CampaignConfig,
    out: &'a Path,
    opts: &CampaignOptions<'a>,
) -> RunContext<'a> {
    let harness = Harness {
        log_dir: Some(out),
        // Each worker's own pool is the training's ([`for_each_group`]).
        train_threads: 0,
        ..opts.harness.clone()
    };
    RunContext {
        role: Some(cfg.campaign.decl()),
        ..RunContext::new(cfg, opts.jobs, harness)
    }
}

/// The lock file that serialises campaigns starting on one results directory.
pub const STORE_LOCK: &str = ".ugl-store.lock";

/// Claims the results directory `out` for this campaign and records what it is
/// ([`CampaignRecord`]: its name, role and configuration hash), where the report reads its
/// role. One store holds one campaign run with one configuration: a campaign of another name,
/// or of the same name with another configuration (`CampaignConfig::configuration_hash`), is
/// refused, so that the runs of two configurations never mix (shards of one campaign share it).
/// The check and the write happen under an exclusive lock on `out/.ugl-store.lock`, so two
/// campaigns started together cannot both pass. A store whose record predates the configuration
/// hash is checked against its manifests of the current results version instead.
pub fn write_campaign_record(cfg: &CampaignConfig, out: &Path) -> Result<(), StoreError> {
    let _lock = lock_store(out)?;
    let configuration = cfg.configuration_hash();
    let refused = |message| refused(out, message);
    let advice = "use another --out (or remove that store to start over)";
    let ours = read_record(out)?;
    if let Some(theirs) = &ours {
        if theirs.name != cfg.campaign.name {
            return Err(refused(format!(
                "holds campaign `{}`, not `{}`: {advice}",
                theirs.name, cfg.campaign.name
            )));
        }
        match &theirs.configuration {
            Some(c) if *c != configuration => {
                return Err(refused(format!(
                    "holds the runs of campaign `{}` with another configuration (recorded {}, this one {}): the results of two configurations would mix; {advice}",
                    theirs.name,
                    &c[..12.min(c.len())],
                    &configuration[..12]
                )));
            }
            Some(_) => {}
            None => {
                check_legacy_manifests(cfg, out).map_err(|m| refused(format!("{m}; {advice}")))?
            }
        }
    } else {
        check_legacy_manifests(cfg, out).map_err(|m| refused(format!("{m}; {advice}")))?;
    }
    let record = CampaignRecord::new(&cfg.campaign.name, &cfg.campaign.decl())
        .with_configuration(&configuration);
    store::write_atomic(&CampaignRecord::path(out), record.to_text().as_bytes())
}

/// The campaign record of the store `out`, if it has one.
fn read_record(out: &Path) -> Result<Option<CampaignRecord>, StoreError> {
    CampaignRecord::read(out).map_err(|e| StoreError::Read {
        path: CampaignRecord::path(out),
        message: e.to_string(),
    })
}

/// The store `out` refuses this campaign or run, saying why.
fn refused(out: &Path, message: String) -> StoreError {
    StoreError::Refused {
        path: out.to_path_buf(),
        message,
    }
}

/// Creates `out` and takes the exclusive lock on `out/.ugl-store.lock` (released when the file
/// is dropped).
fn lock_store(out: &Path) -> Result<std::fs::File, StoreError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| StoreError::Io { path, source }
    };
    std::fs::create_dir_all(out).map_err(io(out))?;
    let lock_path = out.join(STORE_LOCK);
    let lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(io(&lock_path))?;
    lock.lock().map_err(io(&lock_path))?;
    Ok(lock)
}

/// `ugl run` into `out`, under the store's lock: where `out` is a campaign's store (it holds a
/// [`CampaignRecord`]), the run's profile must be that campaign with its configuration (the
/// overrides of `ugl run` included), so that one store never mixes two configurations; and a run
/// of the same id already there must be of this run's configuration (`config_hash`), never
/// replaced by another's. Nothing is recorded: a directory of single runs stays one.
pub fn check_single_run(
    cfg: &CampaignConfig,
    run_id: &str,
    config_hash: &str,
    out: &Path,
) -> Result<(), StoreError> {
    let _lock = lock_store(out)?;
    let refused = |message| refused(out, message);
    let advice = "use another --out";
    let record = read_record(out)?;
    if let Some(theirs) = &record {
        if theirs.name != cfg.campaign.name {
            return Err(refused(format!(
                "holds campaign `{}`, and this run's profile is campaign `{}`: {advice}",
                theirs.name, cfg.campaign.name
            )));
        }
        if let Some(c) = &theirs.configuration
            && *c != cfg.configuration_hash()
        {
            return Err(refused(format!(
                "holds campaign `{}` with another configuration than this run's profile and \
                 options: the results of two configurations would mix; {advice}",
                theirs.name
            )));
        }
    }
    let manifest = store::run_paths(out, run_id).manifest;
    if let Ok(m) = store::read_manifest(&manifest)
        && m.config_hash != config_hash
    {
        return Err(refused(format!(
            "holds run {run_id} of another configuration, which this run would replace: {advice} \
             (or remove {})",
            manifest.display()
        )));
    }
    Ok(())
}

/// A store without a configuration hash: its runs of the current results version must have
/// been run with this campaign's seed, `[explore]` and `[env]` (older versions are superseded
/// and rerun anyway).
fn check_legacy_manifests(cfg: &CampaignConfig, out: &Path) -> Result<(), String> {
    let explore = serde_json::to_value(&cfg.explore).expect("explore serialises");
    let env = serde_json::to_value(&cfg.env).expect("env serialises");
    let entries = std::fs::read_dir(out).map_err(|e| format!("cannot list it: {e}"))?;
    let mut names: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    names.sort();
    for path in names {
        let Ok(m) = store::read_manifest(&path) else {
            continue;
        };
        if m.results_version() != Some(u64::from(ugl_types::RESULTS_VERSION)) {
            continue;
        }
        let differs = if m.campaign_seed != cfg.campaign.seed {
            Some("the campaign seed")
        } else if m.explore != explore {
            Some("[explore]")
        } else if m.env_config != env {
            Some("[env]")
        } else {
            None
        };
        if let Some(what) = differs {
            return Err(format!(
                "holds runs of another configuration ({what} of {} differs from this campaign's)",
                path.file_name().unwrap_or_default().to_string_lossy()
            ));
        }
    }
    Ok(())
}

/// Run `work(g)` for every group index `g < n`: `jobs` plain worker threads pull indexes from a
/// shared counter, and each worker owns a rayon pool of `cores / jobs` threads for the parallel
/// parts of a fit (Isomap's searches, the training kernels). Not a rayon `par_iter` over
/// groups: a rayon worker waiting inside a fit steals other groups and starts their fits too,
/// so dozens of fits (and their memory) pile up. Returns the results in index order.
pub(crate) fn for_each_group<T: Send>(
    jobs: usize,
    n: usize,
    work: &(dyn Fn(usize) -> T + Sync),
) -> Result<Vec<T>, RunError> {
    let jobs = jobs.max(1);
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let inner = (cores / jobs).max(1);
    let next = AtomicUsize::new(0);
    let slots: Vec<Mutex<Option<T>>> = (0..n).map(|_| Mutex::new(None)).collect();
    let pools = (0..jobs.min(n))
        .map(|_| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(inner)
                .build()
                .map_err(|e| RunError::Pool(e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    std::thread::scope(|scope| {
        let handles: Vec<_> = pools
            .iter()
            .map(|pool| {
                scope.spawn(|| {
                    loop {
                        let g = next.fetch_add(1, Ordering::SeqCst);
                        if g >= n {
                            break;
                        }
                        let r = pool.install(|| work(g));
                        *slots[g].lock().expect("result slot") = Some(r);
                    }
                })
            })
            .collect();
        for h in handles {
            if let Err(panic) = h.join() {
                std::panic::resume_unwind(panic);
            }
        }
    });
    Ok(slots
        .into_iter()
        .map(|m| {
            m.into_inner()
                .expect("result slot")
                .expect("every group ran")
        })
        .collect())
}

/// Run every run of the campaign that is not complete in `out` (resumable: complete runs with a
/// matching config hash are skipped). Returns the summaries of the runs executed now.
pub fn run_campaign(
    cfg: &CampaignConfig,
    out: &Path,
    opts: &CampaignOptions,
    on_progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Summary>, RunError> {
    let ctx = campaign_context(cfg, out, opts);
    write_campaign_record(cfg, out)?;
    let all = match opts.shard {
        None => plan(cfg),
        Some((i, n)) => super::plan::shard(&plan(cfg), cfg.ugl.images, i, n),
    };
    let todo: Vec<&RunSpec> = all
        .iter()
        .filter(|s| !store::is_complete(out, &s.run_id(), &ctx.config_hash(s)))
        .collect();
    on_progress(Progress::Planned {
        total: all.len(),
        skipped: all.len() - todo.len(),
    });
    // Runs sharing a representation form one group: fitted once, then run one after the other.
    let n_todo = todo.len();
    let mut groups = super::plan::representation_groups(todo, |s| *s, cfg.ugl.images);
    // Expensive groups (learned representations) first, for a better load balance.
    groups.sort_by_key(|(k, _)| k.is_none());
    // External-learner cells whose fit failed: (env, learner, latents) -> the failed run.
    let failed_external: Mutex<HashMap<String, String>> = Mutex::new(HashMap::new());
    let external_cell = |spec: &RunSpec| {
        spec.algo
            .learner()
            .is_some_and(Learner::is_external)
            .then(|| format!("{}/{}", spec.env.name(), spec.latents))
    };
    let failed_event = |e: &RunError| {
        let run = match e {
            RunError::Repr { run, .. }
            | RunError::Explore { run, .. }
            | RunError::FitFailedBefore { run, .. } => run.clone(),
            _ => String::new(),
        };
        on_progress(Progress::Failed {
            run,
            error: e.to_string(),
        });
    };
    let run_group = |key: &Option<String>, specs: &[&RunSpec]| -> GroupResult {
        let mut out_v = Vec::with_capacity(specs.len());
        let mut repr = None;
        let mut failed: Option<String> = None;
        for spec in specs {
            if opts.stop.load(Ordering::SeqCst) {
                out_v.push(None);
                continue;
            }
            if key.is_some() && repr.is_none() {
                let cell = external_cell(spec);
                let before = failed.clone().or_else(|| {
                    let seen = failed_external.lock().unwrap_or_else(|e| e.into_inner());
                    cell.as_ref().and_then(|c| seen.get(c).cloned())
                });
                if let Some(first) = before {
                    out_v.push(Some(Err(RunError::FitFailedBefore {
                        run: spec.run_id(),
                        first,
                    })));
                    continue;
                }
                match fit_representation(spec, &ctx) {
                    Ok(mut r) => {
                        if goal_space::wanted(spec)
                            && let Err(e) = goal_space::write(out, spec, &ctx, &mut r)
                        {
                            tracing::warn!(
                                "{}: goal-space figure data not written: {e}",
                                spec.run_id()
                            );
                        }
                        repr = Some(r)
                    }
                    Err(source) => {
                        failed = Some(spec.run_id());
                        if let Some(c) = cell {
                            failed_external
                                .lock()
                                .unwrap_or_else(|e| e.into_inner())
                                .entry(c)
                                .or_insert_with(|| spec.run_id());
                        }
                        let e = RunError::Repr {
                            run: spec.run_id(),
                            source,
                        };
                        failed_event(&e);
                        out_v.push(Some(Err(e)));
                        continue;
                    }
                }
            }
            let r = execute(spec, &ctx, out, repr.as_mut());
            match &r {
                Ok(s) => on_progress(Progress::Finished(s.clone())),
                Err(e) => failed_event(e),
            }
            out_v.push(Some(r));
        }
        out_v
    };
    let results: Vec<GroupResult> = for_each_group(opts.jobs, groups.len(), &|g| {
        let (key, specs) = &groups[g];
        run_group(key, specs)
    })?;
    let mut done = Vec::new();
    let mut skipped_now = 0;
    let mut first_err: Option<RunError> = None;
    let (mut failed, mut not_run) = (0, 0);
    for r in results.into_iter().flatten() {
        match r {
            Some(Ok(r)) => done.push(r),
            // The error to report: the first real one (a run skipped because of an earlier
            // failed fit only points to it).
            Some(Err(e)) => {
                match e {
                    RunError::FitFailedBefore { .. } => not_run += 1,
                    _ => failed += 1,
                }
                match (&first_err, &e) {
                    (None, _) | (Some(RunError::FitFailedBefore { .. }), RunError::Repr { .. }) => {
                        first_err = Some(e)
                    }
                    _ => {}
                }
            }
            None => skipped_now += 1,
        }
    }
    if let Some(e) = first_err {
        if failed <= 1 {
            return Err(e);
        }
        return Err(RunError::Failed {
            failed,
            not_run,
            stored: done.len(),
            first: Box::new(e),
        });
    }
    if skipped_now > 0 {
        return Err(RunError::Interrupted {
            done: all.len() - n_todo + done.len(),
            total: all.len(),
        });
    }
    Ok(done)
}
