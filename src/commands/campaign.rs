//! `ugl campaign` (and `--refresh-diagnostics`), `ugl slurm`, `ugl merge`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use ugl_bench::campaign::config::CampaignConfig;
use ugl_bench::campaign::plan::{parse_shard, shard_groups};
use ugl_bench::campaign::{CampaignOptions, Harness, Progress, plan, run_campaign};

use crate::cli::{CacheArgs, SlurmArgs};
use crate::commands::single::{check_clean_tree, check_out_dir};
use crate::progress::{learner_lines, stop_on_ctrl_c, training_bars};

/// How a campaign runs (`ugl campaign`, `ugl compare`): the options of the command line.
pub(crate) struct RunOptions<'a> {
    /// Results directory (default: `data/results/<campaign name>`).
    pub(crate) out: Option<PathBuf>,
    /// Runs in parallel (default: the number of cores).
    pub(crate) jobs: Option<usize>,
    /// No progress bar.
    pub(crate) quiet: bool,
    /// `--shard i/n`.
    pub(crate) shard: Option<&'a str>,
    /// Write into a checkout's `data/` with uncommitted changes.
    pub(crate) allow_dirty: bool,
    pub(crate) cache: &'a CacheArgs,
}

/// `ugl campaign`: run the campaign, or with `--refresh-diagnostics` refresh its diagnostics.
pub(crate) fn campaign(
    config: &Path,
    refresh_diagnostics: bool,
    opts: RunOptions<'_>,
) -> Result<()> {
    let cfg = CampaignConfig::load(config)?;
    let profile = config
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("custom")
        .to_string();
    if refresh_diagnostics {
        refresh_config(&cfg, &profile, opts.out, opts.jobs, opts.shard, opts.cache)
    } else {
        run_config(&cfg, &profile, opts)
    }
}

/// `--refresh-diagnostics` of a loaded campaign (`ugl campaign`, `ugl compare`).
pub(crate) fn refresh_config(
    cfg: &CampaignConfig,
    profile: &str,
    out: Option<PathBuf>,
    jobs: Option<usize>,
    shard: Option<&str>,
    cache: &CacheArgs,
) -> Result<()> {
    let (shard, out, jobs) = campaign_args(cfg, shard, out, jobs)?;
    if !out.is_dir() {
        bail!("--out {}: no results directory to refresh", out.display());
    }
    check_out_dir(&out)?;
    let stop = stop_on_ctrl_c("the representations in flight")?;
    let t0 = std::time::Instant::now();
    let model_cache = cache.resolve(&out);
    let opts = CampaignOptions {
        jobs,
        stop: &stop,
        shard,
        harness: Harness {
            profile,
            cache: model_cache.as_ref(),
            checkpoint_every: cache.checkpoint_every,
            keep_checkpoints: cache.keep_checkpoints,
            ..Harness::default()
        },
    };
    let r = ugl_bench::campaign::remeasure::refresh_diagnostics(cfg, &out, &opts, &|label| {
        eprintln!("refreshed {label} ({:.0} s)", t0.elapsed().as_secs_f64())
    })?;
    eprintln!(
        "goal-space diagnostics: {} representations refreshed: {} runs given the latent \
         quality measure version {} in diagnostics/ ({} already had it), {} figure samples \
         written; {} learned-space runs not finished; in {:.1} s -> {}",
        r.representations,
        r.runs,
        ugl_bench::repr::quality::MEASURE_VERSION,
        r.current,
        r.samples,
        r.unfinished,
        t0.elapsed().as_secs_f64(),
        out.display()
    );
    Ok(())
}

/// The number of groups of runs that share a fit: the most non-empty shards of a campaign.
fn fit_groups(cfg: &CampaignConfig) -> usize {
    shard_groups(&plan(cfg), cfg.ugl.images)
        .into_iter()
        .max()
        .map_or(1, |g| g + 1)
}

/// The checked `--shard`, `--out` (default `data/results/<campaign>`) and `--jobs` (default: the
/// number of cores) of a campaign command.
pub(crate) fn campaign_args(
    cfg: &CampaignConfig,
    shard: Option<&str>,
    out: Option<PathBuf>,
    jobs: Option<usize>,
) -> Result<(Option<(usize, usize)>, PathBuf, usize)> {
    let shard = shard
        .map(parse_shard)
        .transpose()
        .map_err(|e| anyhow::anyhow!(e))?;
    if let Some((_, n)) = shard {
        // As `ugl status` and `ugl slurm`: a shard beyond the groups would run nothing.
        let groups = fit_groups(cfg);
        if n > groups {
            bail!(
                "--shard: {n} shards, but the campaign has {groups} groups of runs that share a \
                 fit (more shards would be empty)"
            );
        }
    }
    let out = out.unwrap_or_else(|| PathBuf::from("data/results").join(&cfg.campaign.name));
    let jobs = jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    if jobs == 0 {
        bail!("--jobs must be at least 1");
    }
    Ok((shard, out, jobs))
}

pub(crate) fn run_config(cfg: &CampaignConfig, profile: &str, opts: RunOptions<'_>) -> Result<()> {
    let RunOptions {
        out,
        jobs,
        quiet,
        shard,
        allow_dirty,
        cache,
    } = opts;
    // Every argument is checked before anything touches the disk.
    let (shard, out, jobs) = campaign_args(cfg, shard, out, jobs)?;
    if !allow_dirty {
        check_clean_tree(&out)?;
    }
    check_out_dir(&out)?;
    let stop = stop_on_ctrl_c("the runs in flight")?;
    let mp = MultiProgress::new();
    if quiet || !std::io::stderr().is_terminal() {
        mp.set_draw_target(ProgressDrawTarget::hidden());
    }
    let bar = mp.add(ProgressBar::new(0));
    let (checkpoint_every, keep_checkpoints) = (cache.checkpoint_every, cache.keep_checkpoints);
    let cache = cache.resolve(&out);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} runs  {elapsed_precise} elapsed, ETA {eta}  {msg}",
        )
        .expect("valid template"),
    );
    let t0 = std::time::Instant::now();
    let on = |p: Progress| match p {
        Progress::Planned { total, skipped } => {
            bar.set_length(total as u64);
            bar.set_position(skipped as u64);
            if skipped > 0 {
                bar.println(format!(
                    "{skipped} of {total} runs already complete in {}; resuming",
                    out.display()
                ));
            }
        }
        Progress::Finished(s) => {
            bar.inc(1);
            bar.set_message(format!("{} klc={:.3}", s.run, s.final_klc));
        }
        Progress::Failed { error, .. } => {
            // On a terminal each failure is shown as it happens; the campaign's error at the end
            // counts them all and gives the first (one line in a log).
            bar.inc(1);
            bar.println(format!("failed: {error}"));
        }
    };
    let opts = CampaignOptions {
        jobs,
        stop: &stop,
        shard,
        harness: Harness {
            profile,
            cache: cache.as_ref(),
            checkpoint_every,
            keep_checkpoints,
            train_progress: Some(training_bars(&mp, Some(&bar))),
            learner_messages: Some(learner_lines(&mp, Some(&bar))),
            ..Harness::default()
        },
    };
    let done = run_campaign(cfg, &out, &opts, &on)?;
    bar.finish_and_clear();
    eprintln!(
        "campaign {}: {} runs executed in {:.1} s ({} jobs) -> {}",
        cfg.campaign.name,
        done.len(),
        t0.elapsed().as_secs_f64(),
        jobs,
        out.display()
    );
    Ok(())
}

pub(crate) fn slurm(a: SlurmArgs) -> Result<()> {
    use ugl_bench::campaign::slurm::{SlurmJob, resolve, scripts as slurm_scripts, write_scripts};
    let cfg = CampaignConfig::load(&a.config)?;
    let cwd = std::env::current_dir().context("cannot read the current directory")?;
    let checkout = resolve(&cwd, &cwd);
    let out = a
        .out
        .unwrap_or_else(|| PathBuf::from("data/results").join(&cfg.campaign.name));
    let out = resolve(&out, &cwd);
    let dir = resolve(&a.scripts.unwrap_or_else(|| out.join("slurm")), &cwd);
    let report_out = resolve(&a.report_out.unwrap_or_else(|| out.join("report")), &cwd);
    let config = resolve(&a.config, &cwd);
    if !checkout.join("data/paper").is_dir() {
        bail!(
            "run ugl slurm from the repository's root: the report step reads the paper's \
             reference values from {}/data/paper, which is not there",
            checkout.display()
        );
    }
    let runs = plan(&cfg);
    let n_groups = shard_groups(&runs, cfg.ugl.images)
        .into_iter()
        .max()
        .map_or(0, |g| g + 1);
    let job = SlurmJob {
        name: &cfg.campaign.name,
        n_runs: runs.len(),
        n_groups,
        checkout: &checkout,
        config: &config,
        out: &out,
        report_out: &report_out,
        dir: &dir,
        shards: a.shards,
        cpus: a.cpus,
        time: &a.time,
        report_time: &a.report_time,
        throttle: a.throttle,
        sbatch_args: &a.sbatch_args,
        allow_dirty: a.allow_dirty,
    };
    let texts = slurm_scripts(&job)?;
    if !a.allow_dirty {
        check_clean_tree(&out)?;
    }
    check_out_dir(&dir)?;
    write_scripts(&dir, &texts)?;
    eprintln!(
        "wrote {}/{{array,report,submit}}.sh: {} runs in {} shards; run: bash {}/submit.sh",
        dir.display(),
        job.n_runs,
        a.shards,
        dir.display()
    );
    Ok(())
}

/// `ugl status`: the state of a campaign's results directory, overall and per shard.
pub(crate) fn status(
    config: Option<&Path>,
    out: Option<PathBuf>,
    shards: usize,
    require_complete: bool,
) -> Result<()> {
    use ugl_bench::campaign::status::{RunState, store_status};
    let cfg = match (config, &out) {
        (Some(config), _) => CampaignConfig::load(config)?,
        (None, Some(out)) => super::record::recorded_campaign(out)?,
        (None, None) => bail!("give --config, or --out of a store that holds its campaign.toml"),
    };
    // At most one shard per group of runs that share a fit, as `ugl slurm` writes them (a huge
    // count would only allocate empty shards).
    let n_groups = fit_groups(&cfg);
    if shards == 0 || shards > n_groups {
        bail!(
            "--shards {shards}: must be between 1 and {n_groups}, the campaign's groups of runs \
             that share a fit"
        );
    }
    let out = out.unwrap_or_else(|| PathBuf::from("data/results").join(&cfg.campaign.name));
    let st = store_status(&cfg, &out, shards)?;
    let mut text = format!(
        "campaign {} in {}: {}\n",
        cfg.campaign.name,
        out.display(),
        st.counts().describe()
    );
    if shards > 1 {
        for i in 0..shards {
            text.push_str(&format!(
                "  shard {i}/{shards}: {}\n",
                st.shard_counts(i).describe()
            ));
        }
    }
    const SHOWN: usize = 10;
    let mut list = |what: &str, ids: Vec<String>| {
        if ids.is_empty() {
            return;
        }
        let more = ids.len().saturating_sub(SHOWN);
        let mut line = format!("  {what}: {}", ids[..ids.len().min(SHOWN)].join(", "));
        if more > 0 {
            line.push_str(&format!(" (and {more} more)"));
        }
        text.push_str(&line);
        text.push('\n');
    };
    let ids = |f: &dyn Fn(&RunState) -> bool| -> Vec<String> {
        st.runs
            .iter()
            .filter(|r| f(&r.state))
            .map(|r| match &r.state {
                RunState::Damaged(why) => format!("{} ({why})", r.run_id),
                _ => r.run_id.clone(),
            })
            .collect()
    };
    list("missing", ids(&|s| *s == RunState::Missing));
    list("damaged", ids(&|s| matches!(s, RunState::Damaged(_))));
    list(
        "of another configuration",
        ids(&|s| *s == RunState::OtherConfiguration),
    );
    list("not in this campaign's plan", st.unplanned.clone());
    if !st.is_complete() {
        text.push_str("  (a resumed campaign computes the runs that are not complete)\n");
    }
    crate::output::outln!("{}", text.trim_end())?;
    if require_complete && !st.is_complete() {
        bail!(
            "campaign {} in {} is not complete ({}): nothing rendered from partial results",
            cfg.campaign.name,
            out.display(),
            st.counts().describe()
        );
    }
    Ok(())
}

pub(crate) fn merge(into: &Path, sources: &[PathBuf]) -> Result<()> {
    check_out_dir(into)?;
    let done = ugl_bench::campaign::merge::merge_stores(into, sources)?;
    eprintln!(
        "merge: {} runs copied, {} already present and identical -> {}",
        done.copied,
        done.already_present,
        into.display()
    );
    Ok(())
}
