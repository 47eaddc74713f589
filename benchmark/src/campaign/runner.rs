//! Executes runs: environment + explorer, then the results store.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;
use thiserror::Error;

use super::config::CampaignConfig;
use super::plan::{plan, RunSpec};
use super::store::{self, Manifest, StoreError, Summary};
use crate::env::{make_env, EnvConfig};
use crate::explore::{run_rge, run_rpe, Algo, EngineeredSpace, ExplorationLog, ExploreConfig};
use crate::goals::UniformGoals;
use crate::seed::run_seed;

/// Bumped whenever a change alters results for the same configuration.
pub const RESULTS_VERSION: u32 = 1;

/// Errors of a run or campaign.
#[derive(Debug, Error)]
pub enum RunError {
    #[error(transparent)]
    Store(#[from] StoreError),
    #[error("cannot start the worker pool: {0}")]
    Pool(String),
    #[error("interrupted: {done} of {total} runs finished and stored; rerun the same command to resume")]
    Interrupted { done: usize, total: usize },
}

/// What a run depends on, hashed into its config hash.
#[derive(Serialize)]
struct HashInput<'a> {
    results_version: u32,
    identity: &'a str,
    campaign_seed: u64,
    explore: &'a ExploreConfig,
    env: &'a EnvConfig,
}

/// Everything needed to execute one run.
#[derive(Clone, Debug)]
pub struct RunContext<'a> {
    pub campaign: &'a str,
    pub campaign_seed: u64,
    pub profile: &'a str,
    pub explore: &'a ExploreConfig,
    pub env: &'a EnvConfig,
    pub threads: usize,
}

impl RunContext<'_> {
    /// The config hash of a run: BLAKE3 of its identity, campaign seed and every constant.
    pub fn config_hash(&self, spec: &RunSpec) -> String {
        let identity = spec.identity();
        let input = HashInput {
            results_version: RESULTS_VERSION,
            identity: &identity,
            campaign_seed: self.campaign_seed,
            explore: self.explore,
            env: self.env,
        };
        let json = serde_json::to_vec(&input).expect("config serialises");
        blake3::hash(&json).to_hex().to_string()
    }
}

/// Run the exploration of one spec (no I/O).
pub fn explore(spec: &RunSpec, explore: &ExploreConfig, env_cfg: &EnvConfig, campaign_seed: u64) -> ExplorationLog {
    let seed = run_seed(campaign_seed, &spec.identity());
    let env = make_env(spec.env, env_cfg);
    match spec.algo {
        Algo::Rpe => run_rpe(env.as_ref(), explore, seed),
        Algo::RgeEfr => {
            let d = env.state_dim();
            run_rge(env.as_ref(), &mut EngineeredSpace::new(d), &mut UniformGoals::unit(d), explore, seed)
        }
    }
}

/// The summary of a finished log.
pub fn summarize(spec: &RunSpec, log: &ExplorationLog) -> Summary {
    let last = log.checkpoints.last().expect("at least one checkpoint");
    Summary { run: spec.run_id(), final_klc: last.klc, n_moved: last.n_moved, coverage: last.coverage }
}

/// Execute one run and store it in `out`; returns its summary.
pub fn execute(spec: &RunSpec, ctx: &RunContext, out: &Path) -> Result<Summary, RunError> {
    let t0 = Instant::now();
    let log = explore(spec, ctx.explore, ctx.env, ctx.campaign_seed);
    let wall_s = t0.elapsed().as_secs_f64();
    let summary = summarize(spec, &log);
    let paper = ExploreConfig::default();
    let reduced = ctx.explore.epochs < paper.epochs;
    let manifest = Manifest {
        run_id: spec.run_id(),
        identity: spec.identity(),
        env: spec.env.name().into(),
        algo: spec.algo.name().into(),
        sampler: spec.sampler().into(),
        seed: spec.seed,
        run_seed: run_seed(ctx.campaign_seed, &spec.identity()),
        campaign: ctx.campaign.into(),
        campaign_seed: ctx.campaign_seed,
        profile: ctx.profile.into(),
        config_hash: ctx.config_hash(spec),
        explore: serde_json::to_value(ctx.explore).expect("serialisable"),
        env_config: serde_json::to_value(ctx.env).expect("serialisable"),
        reduced_budget: reduced,
        budget_note: if reduced {
            format!("{} exploration epochs instead of the paper's {}", ctx.explore.epochs, paper.epochs)
        } else {
            String::new()
        },
        git_revision: git_revision().into(),
        crate_versions: serde_json::json!({
            "ugl-bench": env!("CARGO_PKG_VERSION"),
            "results_version": RESULTS_VERSION,
        }),
        toolchain: env!("UGL_RUSTC_VERSION").into(),
        threads: ctx.threads,
        wall_s,
        host: host_name().into(),
        summary: summary.clone(),
    };
    store::write_run(out, spec, &log, &manifest)?;
    Ok(summary)
}

/// Progress events of a campaign.
#[derive(Clone, Debug)]
pub enum Progress {
    /// The plan: total runs and how many are already complete (skipped).
    Planned { total: usize, skipped: usize },
    /// A run finished.
    Finished(Summary),
}

/// Options of a campaign execution.
pub struct CampaignOptions<'a> {
    /// Worker threads (runs in parallel; each run is single-threaded).
    pub jobs: usize,
    /// Profile name recorded in manifests.
    pub profile: &'a str,
    /// Set to stop after the runs in flight (Ctrl-C).
    pub stop: &'a AtomicBool,
}

/// Run every run of the campaign that is not complete in `out` (resumable: complete runs with a
/// matching config hash are skipped). Returns the summaries of the runs executed now.
pub fn run_campaign(
    cfg: &CampaignConfig,
    out: &Path,
    opts: &CampaignOptions,
    on_progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Summary>, RunError> {
    let ctx = RunContext {
        campaign: &cfg.campaign.name,
        campaign_seed: cfg.campaign.seed,
        profile: opts.profile,
        explore: &cfg.explore,
        env: &cfg.env,
        threads: opts.jobs,
    };
    let all = plan(cfg);
    let todo: Vec<&RunSpec> =
        all.iter().filter(|s| !store::is_complete(out, &s.run_id(), &ctx.config_hash(s))).collect();
    on_progress(Progress::Planned { total: all.len(), skipped: all.len() - todo.len() });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.max(1))
        .build()
        .map_err(|e| RunError::Pool(e.to_string()))?;
    let results: Vec<Option<Result<Summary, RunError>>> = pool.install(|| {
        todo.par_iter()
            .map(|spec| {
                if opts.stop.load(Ordering::SeqCst) {
                    return None;
                }
                let r = execute(spec, &ctx, out);
                if let Ok(s) = &r {
                    on_progress(Progress::Finished(s.clone()));
                }
                Some(r)
            })
            .collect()
    });
    let mut done = Vec::new();
    let mut skipped_now = 0;
    for r in results {
        match r {
            Some(r) => done.push(r?),
            None => skipped_now += 1,
        }
    }
    if skipped_now > 0 {
        return Err(RunError::Interrupted { done: all.len() - todo.len() + done.len(), total: all.len() });
    }
    Ok(done)
}

/// `git rev-parse HEAD` of the working directory, with `-dirty` if there are uncommitted
/// changes; `unknown` outside a repository.
pub fn git_revision() -> &'static str {
    static REV: OnceLock<String> = OnceLock::new();
    REV.get_or_init(|| {
        let run = |args: &[&str]| {
            std::process::Command::new("git")
                .args(args)
                .output()
                .ok()
                .filter(|o| o.status.success())
                .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        };
        match run(&["rev-parse", "HEAD"]) {
            Some(rev) => {
                let dirty = run(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
                if dirty { format!("{rev}-dirty") } else { rev }
            }
            None => "unknown".into(),
        }
    })
}

/// The host name (from /etc/hostname or $HOSTNAME).
pub fn host_name() -> &'static str {
    static HOST: OnceLock<String> = OnceLock::new();
    HOST.get_or_init(|| {
        std::fs::read_to_string("/etc/hostname")
            .ok()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .or_else(|| std::env::var("HOSTNAME").ok())
            .unwrap_or_else(|| "unknown".into())
    })
}
