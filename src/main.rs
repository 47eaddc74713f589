//! `ugl`: the command line of ugl-bench. Thin: parses arguments and calls the crates.
//!
//! Every error is one line on stderr and exit code 2.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use ugl_bench::campaign::config::{CampaignConfig, resolve_profile};
use ugl_bench::campaign::context::{MessageSink, TrainSink};
use ugl_bench::campaign::plan::parse_shard;
use ugl_bench::campaign::single::{self, RunRequest};
use ugl_bench::campaign::{CampaignOptions, Progress, RunContext, RunSpec, plan, run_campaign};
use ugl_bench::env::render::{Image70, PIXELS, write_npy, write_png};
use ugl_bench::env::{EnvConfig, EnvKind, PARAMS, make_env};
use ugl_bench::explore::{Algo, Learner, SamplerKind};
use ugl_bench::metrics::KlCoverage;
use ugl_bench::metrics::csv::read_outcomes_csv;
use ugl_bench::repr::cache::ModelCache;
use ugl_bench::repr::neural::Variant;

/// ugl-bench: reproduce "Unsupervised Learning of Goal Spaces for Intrinsically Motivated Goal
/// Exploration" (Péré et al., ICLR 2018) deterministically on a CPU.
#[derive(Parser, Debug)]
#[command(name = "ugl", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run episodes: prints a JSON array with, per parameter vector, the final object state,
    /// whether the object was caught, and the hand position.
    Rollout {
        #[arg(long, help = env_help())]
        env: EnvKind,
        /// JSON file: an array of arrays of 21 numbers (motor parameters; clipped to [-1,1]).
        #[arg(long)]
        params: PathBuf,
        /// armballs: the distractor's random walk draws from this seed's `distractor` stream,
        /// episode after episode (the other environments draw nothing).
        #[arg(long, default_value_t = 0)]
        seed: u64,
    },
    /// KL-coverage of a set of engineered outcomes (prints the value, or `inf`).
    Klc {
        #[arg(long, help = klc_env_help())]
        env: EnvKind,
        /// CSV file of outcomes in [-1,1].
        #[arg(long)]
        outcomes: PathBuf,
    },
    /// Render an object state as the 70x70 image the learners see.
    Render {
        #[arg(long, help = env_help())]
        env: EnvKind,
        #[arg(long, allow_hyphen_values = true, help = state_help())]
        state: String,
        /// Output file: `.npy` (float32 70x70 indexed [x][y]) or `.png` (for people).
        #[arg(long)]
        out: PathBuf,
    },
    /// One exploration run; writes DIR/<run-id>.parquet (+ .outcomes.parquet, .json) and prints
    /// a JSON summary as its last line.
    Run {
        #[arg(long, help = env_help())]
        env: EnvKind,
        #[arg(long, help = algo_help())]
        algo: Algo,
        /// Goal sampler of a learned goal space: kde (the paper's default) or gaussian (the
        /// prior N(0, I); VAE, RFVAE, or an external learner that writes a prior).
        #[arg(long, default_value = "kde")]
        sampler: SamplerKind,
        /// rge-vae / rge-rfvae: `faithful` (the original code, defects included) or `corrected`.
        #[arg(long)]
        variant: Option<Variant>,
        /// Latent size of a learned goal space.
        #[arg(long, default_value_t = 10)]
        latents: usize,
        /// Override the profile's number of UGL training images.
        #[arg(long)]
        images: Option<usize>,
        /// Repetition index; the RNG seed derives from it, the run identity and the campaign seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Override the profile's number of exploration epochs.
        #[arg(long)]
        epochs: Option<usize>,
        /// Budget profile: a name in data/campaigns/ or a path to a .toml file.
        #[arg(long, default_value = "paper")]
        profile: String,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// rge-external: the command line of a program speaking the external-learner protocol
        /// (docs/external-learners.md), run with `sh -c`; replaces the profile's
        /// [learners.external] command.
        #[arg(long)]
        command: Option<String>,
        /// rge-external: the program's name in results and the report (default: the profile's
        /// [learners.external] name, else `external`).
        #[arg(long)]
        name: Option<String>,
        #[command(flatten)]
        cache: CacheArgs,
    },
    /// Export a goal space: fit (or load from the model cache) the representation of one cell
    /// and seed, as a run would, and write the latents of its training images and of a grid of
    /// object positions as .npy files. Prints a JSON summary (files, latent quality).
    Embed(EmbedArgs),
    /// List the run ids of a campaign, one per line.
    Plan {
        /// Campaign file (data/campaigns/NAME.toml).
        #[arg(long)]
        config: PathBuf,
    },
    /// Run a campaign matrix in parallel; resumable (finished runs are skipped).
    Campaign {
        /// Campaign file (data/campaigns/NAME.toml).
        #[arg(long)]
        config: PathBuf,
        /// Results directory (default: data/results/<campaign name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Runs in parallel (default: the number of cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// No progress bar (also automatic when stderr is not a terminal).
        #[arg(long)]
        quiet: bool,
        /// Run only the deterministic slice i of n (0-based, `0/4` .. `3/4`); the union of the n
        /// shards is the whole campaign, and runs sharing a trained representation stay together.
        #[arg(long)]
        shard: Option<String>,
        /// Run nothing: bring the goal-space diagnostics of the finished runs up to date: the
        /// latent quality where a manifest holds an older measure, and the missing goal-space
        /// figure data of seed 0 (each representation concerned is fitted again, or loaded from
        /// the model cache, once). Runs are not touched: the new measure goes to
        /// OUT/diagnostics/<run_id>.json.
        #[arg(long)]
        refresh_diagnostics: bool,
        #[command(flatten)]
        cache: CacheArgs,
    },
    /// List the registered representation learners: name, algorithm, what its goal space
    /// offers (variants, a prior), whether the paper evaluated it, and a description.
    Learners,
    /// Run one more representation learner on the cells and seeds of a campaign (default: the
    /// paper's), into data/results/compare-NAME; the report ranks it against the paper's
    /// algorithms with the same statistics.
    Compare(CompareArgs),
    /// Write a Slurm array job (one task per shard) and a merge step for a campaign.
    Slurm {
        /// Campaign file (data/campaigns/NAME.toml).
        #[arg(long)]
        config: PathBuf,
        /// Number of array tasks (shards).
        #[arg(long)]
        shards: usize,
        /// Results directory the tasks write to (on a shared file system).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Directory for the generated scripts.
        #[arg(long, default_value = "slurm")]
        scripts: PathBuf,
        /// CPUs per task (each task runs that many runs in parallel).
        #[arg(long, default_value_t = 2)]
        cpus: usize,
        /// Wall-time limit per task (Slurm syntax).
        #[arg(long, default_value = "04:00:00")]
        time: String,
    },
    /// Merge run files from several results directories (e.g. one per machine) into one store.
    Merge {
        /// Destination results directory.
        #[arg(long)]
        into: PathBuf,
        /// Source results directories.
        #[arg(required = true)]
        sources: Vec<PathBuf>,
    },
    /// Render the report (markdown + SVG figures) from a results store.
    Report {
        /// Results directory (run files, or one sub-directory per campaign).
        #[arg(long, default_value = "data/results")]
        results: PathBuf,
        /// Output directory for REPORT.md and figures/.
        #[arg(long, default_value = "report/out")]
        out: PathBuf,
        /// The paper's reference values.
        #[arg(long, default_value = "data/paper")]
        paper: PathBuf,
        /// The campaign (sub-directory of --results) the figures and tables are drawn from;
        /// `budget-*` campaigns feed the training-budget section. `(top level)` or `.`: the
        /// runs directly in --results.
        #[arg(long = "main", default_value = "paper")]
        main_campaign: String,
    },
}

#[derive(clap::Args, Debug)]
struct EmbedArgs {
    #[arg(long, help = env_help())]
    env: EnvKind,
    #[arg(long, help = learner_help())]
    learner: String,
    /// External learners: the command line of the program (docs/external-learners.md).
    #[arg(long)]
    command: Option<String>,
    /// vae / rfvae: faithful (default) or corrected.
    #[arg(long)]
    variant: Option<Variant>,
    /// Latent size.
    #[arg(long, default_value_t = 10)]
    latents: usize,
    /// Repetition index (the data set and the learner's stream derive from it).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Override the profile's number of UGL training images.
    #[arg(long)]
    images: Option<usize>,
    /// Budget profile: a name in data/campaigns/ or a path to a .toml file.
    #[arg(long, default_value = "paper")]
    profile: String,
    /// The grid of object positions: GRID x GRID over [-1, 1]^2 (ArmArrow: angle 0).
    #[arg(long, default_value_t = 21)]
    grid: usize,
    /// The training latents' file (.npy, float64, (n, latents)); beside it OUT-stem.states.npy
    /// (n, state dim), OUT-stem.grid.npy (GRID^2, latents) and OUT-stem.grid_states.npy.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    cache: CacheArgs,
}

#[derive(clap::Args, Debug)]
struct CompareArgs {
    #[arg(long, help = learner_help())]
    learner: String,
    /// Command line of a program speaking the external-learner protocol
    /// (docs/external-learners.md), run with `sh -c`.
    #[arg(long)]
    command: Option<String>,
    /// External learners: also run Gaussian-prior goals (the program must write prior.npy).
    #[arg(long)]
    gaussian: bool,
    /// The campaign whose cells, seeds and budgets to use.
    #[arg(long, default_value = "data/campaigns/paper.toml")]
    config: PathBuf,
    /// Results directory (default: data/results/compare-NAME).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Runs in parallel (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// No progress bars.
    #[arg(long)]
    quiet: bool,
    /// Run nothing: bring the goal-space diagnostics of the finished runs up to date (as
    /// `ugl campaign --refresh-diagnostics`).
    #[arg(long)]
    refresh_diagnostics: bool,
    #[command(flatten)]
    cache: CacheArgs,
}

/// Where trained neural models are kept.
#[derive(clap::Args, Debug)]
struct CacheArgs {
    /// Model cache directory for fitted representations that persist: trained networks, PCA
    /// (default: OUT/models). A model is keyed by the hash of everything it depends on; an
    /// invalid file is refitted.
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Do not read or write the model cache (always fit).
    #[arg(long, conflicts_with = "cache")]
    no_cache: bool,
    /// Save a checkpoint of each neural training every N iterations in the model cache (0:
    /// never). A training killed mid-way resumes from its latest checkpoint and ends
    /// bit-identical to an uninterrupted one.
    #[arg(long, default_value_t = 1000)]
    checkpoint_every: usize,
}

impl CacheArgs {
    fn resolve(&self, out: &Path) -> Option<ModelCache> {
        if self.no_cache {
            return None;
        }
        Some(ModelCache::new(
            self.cache.clone().unwrap_or_else(|| out.join("models")),
        ))
    }
}

/// Progress bars for neural trainings, one per representation, above `main` (if any).
fn training_bars(mp: &MultiProgress, main: Option<&ProgressBar>) -> Arc<TrainSink> {
    let bars: std::sync::Mutex<std::collections::HashMap<String, ProgressBar>> = Default::default();
    let mp = mp.clone();
    let main = main.cloned();
    Arc::new(move |label: &str, p| {
        let mut bars = bars.lock().expect("progress bars");
        let bar = bars.entry(label.to_string()).or_insert_with(|| {
            let b = ProgressBar::new(p.total as u64);
            let b = match &main {
                Some(m) => mp.insert_before(m, b),
                None => mp.add(b),
            };
            b.set_style(
                ProgressStyle::with_template(
                    "  train {prefix:32} {bar:25} {pos}/{len} it  {rate}  ETA {eta}  loss {msg}",
                )
                .expect("valid template")
                .with_key(
                    "rate",
                    |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{:.1} it/s", s.per_sec());
                    },
                ),
            );
            b.set_prefix(label.to_string());
            b
        });
        bar.set_position(p.iteration as u64);
        bar.set_message(format!("{:.2}", p.loss));
        if p.iteration >= p.total {
            bar.finish_and_clear();
            mp.remove(bar);
            bars.remove(label);
        }
    })
}

/// One line per external learner while it fits, above `main` (if any): its label and the last
/// line it wrote to stderr (the whole stderr is in `OUT/<label>.learner.log`).
fn learner_lines(mp: &MultiProgress, main: Option<&ProgressBar>) -> Arc<MessageSink> {
    let bars: std::sync::Mutex<std::collections::HashMap<String, ProgressBar>> = Default::default();
    let mp = mp.clone();
    let main = main.cloned();
    Arc::new(move |label: &str, line: Option<&str>| {
        let mut bars = bars.lock().expect("progress bars");
        match line {
            Some(line) => {
                let bar = bars.entry(label.to_string()).or_insert_with(|| {
                    let b = ProgressBar::new_spinner();
                    let b = match &main {
                        Some(m) => mp.insert_before(m, b),
                        None => mp.add(b),
                    };
                    b.set_style(
                        ProgressStyle::with_template(
                            "  fit   {prefix:32} {elapsed:>5}  {wide_msg}",
                        )
                        .expect("valid template"),
                    );
                    b.set_prefix(label.to_string());
                    b.enable_steady_tick(std::time::Duration::from_millis(500));
                    b
                });
                bar.set_message(line.to_string());
            }
            None => {
                if let Some(bar) = bars.remove(label) {
                    bar.finish_and_clear();
                    mp.remove(&bar);
                }
            }
        }
    })
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_env("UGL_LOG"))
        .with_writer(std::io::stderr)
        .init();
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::from(2)
                } else {
                    ExitCode::SUCCESS
                };
            }
            let text = e.render().to_string();
            let first = text
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("error: invalid arguments");
            eprintln!("{} (see 'ugl --help')", first.trim());
            return ExitCode::from(2);
        }
    };
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::from(2)
        }
    }
}

/// An error and its causes on one line, each cause once: a cause whose text an outer message
/// already contains (a library error that prints its source) is not repeated.
fn one_line(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        let text = text.trim();
        if text.is_empty() || out.contains(text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(text);
    }
    out.replace('\n', " ")
}

fn dispatch(cmd: Command) -> Result<()> {
    match cmd {
        Command::Rollout { env, params, seed } => rollout(env, &params, seed),
        Command::Klc { env, outcomes } => klc(env, &outcomes),
        Command::Render { env, state, out } => render(env, &state, &out),
        Command::Run {
            env,
            algo,
            sampler,
            variant,
            latents,
            images,
            seed,
            epochs,
            profile,
            out,
            command,
            name,
            cache,
        } => run(
            RunRequest {
                env,
                algo,
                sampler,
                variant,
                latents,
                images,
                seed,
                epochs,
                command,
                name,
            },
            &profile,
            &out,
            &cache,
        ),
        Command::Plan { config } => {
            let cfg = CampaignConfig::load(&config)?;
            for spec in plan(&cfg) {
                println!("{}", spec.run_id());
            }
            Ok(())
        }
        Command::Campaign {
            config,
            out,
            jobs,
            quiet,
            shard,
            refresh_diagnostics,
            cache,
        } => campaign(
            &config,
            out,
            jobs,
            quiet,
            shard.as_deref(),
            refresh_diagnostics,
            &cache,
        ),
        Command::Slurm {
            config,
            shards,
            out,
            scripts,
            cpus,
            time,
        } => slurm(&config, shards, out, &scripts, cpus, &time),
        Command::Merge { into, sources } => merge(&into, &sources),
        Command::Learners => {
            learners();
            Ok(())
        }
        Command::Compare(a) => compare(a),
        Command::Embed(a) => embed(a),
        Command::Report {
            results,
            out,
            paper,
            main_campaign,
        } => {
            if !paper.is_dir() {
                bail!(
                    "--paper {}: not a directory (the paper's reference values, data/paper in \
                     the repository)",
                    paper.display()
                );
            }
            let mut opts = ugl_report::ReportOptions::new(results, out);
            opts.paper_dir = paper;
            // The store's top level is listed as "(top level)"; accept that spelling too.
            opts.main_campaign = match main_campaign.as_str() {
                "(top level)" | "." => String::new(),
                _ => main_campaign,
            };
            let s = ugl_report::render_report(&opts)?;
            eprintln!(
                "report: {} runs -> {} files in {}",
                s.n_runs,
                s.files.len(),
                opts.out.display()
            );
            Ok(())
        }
    }
}

#[derive(Serialize)]
struct RolloutOut {
    object: Vec<f64>,
    moved: bool,
    hand: [f64; 2],
}

fn rollout(kind: EnvKind, params: &Path, seed: u64) -> Result<()> {
    let text = std::fs::read_to_string(params)
        .with_context(|| format!("cannot read {}", params.display()))?;
    let v: Vec<Vec<f64>> = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: expected a JSON array of arrays of {PARAMS} numbers",
            params.display()
        )
    })?;
    let env = make_env(kind, &EnvConfig::default());
    let mut noise = ugl_bench::seed::stream(seed, ugl_bench::seed::Component::Distractor);
    let mut out = Vec::with_capacity(v.len());
    for (i, theta) in v.iter().enumerate() {
        let theta: [f64; PARAMS] = theta.as_slice().try_into().map_err(|_| {
            anyhow::anyhow!(
                "{}: entry {i} has {} numbers, expected {PARAMS}",
                params.display(),
                theta.len()
            )
        })?;
        if theta.iter().any(|x| !x.is_finite()) {
            bail!("{}: entry {i} has a non-finite number", params.display());
        }
        let r = env.rollout(&theta, &mut noise);
        out.push(RolloutOut {
            object: r.outcome().to_vec(),
            moved: r.caught,
            hand: r.hand,
        });
    }
    println!("{}", serde_json::to_string(&out)?);
    Ok(())
}

fn klc(kind: EnvKind, path: &Path) -> Result<()> {
    // Measured on the controllable object (armballs: the ball's x, y).
    let dim = kind.metric_dims().len();
    let pts = read_outcomes_csv(path, dim)?;
    let k = KlCoverage::new(dim)?;
    let v = k.evaluate(pts.iter().map(|p| &p[..]))?;
    if v.is_infinite() {
        println!("inf")
    } else {
        println!("{v}")
    }
    Ok(())
}

fn render(kind: EnvKind, state: &str, out: &Path) -> Result<()> {
    let vals: Vec<f64> = state
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| anyhow::anyhow!("--state: '{s}' is not a number"))
        })
        .collect::<Result<_>>()?;
    if vals.len() != kind.state_dim() {
        bail!(
            "--state for {kind} needs {} comma-separated values, got {}",
            kind.state_dim(),
            vals.len()
        );
    }
    if let Some(v) = vals.iter().find(|v| !(-1.0..=1.0).contains(*v)) {
        bail!("--state: {v} is outside [-1,1]");
    }
    let env = make_env(kind, &EnvConfig::default());
    let mut buf = vec![0f32; PIXELS];
    env.render_into(&vals, &mut buf);
    let img = Image70(buf);
    match out.extension().and_then(|e| e.to_str()) {
        Some("npy") => write_npy(&img, out)?,
        Some("png") => write_png(&img, out)?,
        _ => bail!(
            "--out {}: the extension must be .npy or .png",
            out.display()
        ),
    }
    Ok(())
}

fn run(a: RunRequest, profile: &str, out: &Path, cache: &CacheArgs) -> Result<()> {
    let path = resolve_profile(profile)?;
    let mut cfg = CampaignConfig::load(&path)?;
    let spec = a.resolve(&mut cfg, &path).map_err(anyhow::Error::msg)?;
    check_out_dir(out)?;
    let model_cache = cache.resolve(out);
    let mp = progress_area();
    let ctx = single_context(&cfg, profile, model_cache.as_ref(), cache, out, &mp);
    let summary = ugl_bench::campaign::execute(&spec, &ctx, out, None)?;
    println!("{}", serde_json::to_string(&summary)?);
    Ok(())
}

/// Progress bars on stderr, hidden when it is not a terminal.
fn progress_area() -> MultiProgress {
    let mp = MultiProgress::new();
    if !std::io::stderr().is_terminal() {
        mp.set_draw_target(ProgressDrawTarget::hidden());
    }
    mp
}

/// The context of one run or one representation (`ugl run`, `ugl embed`): the whole machine's
/// threads, training bars and learner lines in `mp`, learner logs and the model cache in `out`.
fn single_context<'a>(
    cfg: &'a CampaignConfig,
    profile: &'a str,
    model_cache: Option<&'a ModelCache>,
    cache: &CacheArgs,
    out: &'a Path,
    mp: &MultiProgress,
) -> RunContext<'a> {
    RunContext {
        campaign: &cfg.campaign.name,
        campaign_seed: cfg.campaign.seed,
        profile,
        explore: &cfg.explore,
        env: &cfg.env,
        ugl: &cfg.ugl,
        learners: &cfg.learners,
        mge: &cfg.mge,
        threads: rayon::current_num_threads(),
        cache: model_cache,
        train_progress: Some(training_bars(mp, None)),
        train_threads: 0,
        log_dir: Some(out),
        learner_messages: Some(learner_lines(mp, None)),
        checkpoint_every: cache.checkpoint_every,
        role: None,
    }
}

/// An output directory must be a directory (created if missing).
fn check_out_dir(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        bail!("--out {}: exists and is not a directory", out.display());
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))
}

/// `ugl campaign`: run the campaign, or with `--refresh-diagnostics` refresh its diagnostics.
fn campaign(
    config: &Path,
    out: Option<PathBuf>,
    jobs: Option<usize>,
    quiet: bool,
    shard: Option<&str>,
    refresh_diagnostics: bool,
    cache: &CacheArgs,
) -> Result<()> {
    let cfg = CampaignConfig::load(config)?;
    let profile = config
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("custom")
        .to_string();
    if refresh_diagnostics {
        refresh_config(&cfg, &profile, out, jobs, shard, cache)
    } else {
        run_config(&cfg, &profile, out, jobs, quiet, shard, cache)
    }
}

/// `--refresh-diagnostics` of a loaded campaign (`ugl campaign`, `ugl compare`).
fn refresh_config(
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
        profile,
        stop: &stop,
        shard,
        cache: model_cache.as_ref(),
        train_progress: None,
        learner_messages: None,
        checkpoint_every: cache.checkpoint_every,
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

/// `ugl embed`: the latents of one fitted goal space.
fn embed(a: EmbedArgs) -> Result<()> {
    single::check_seed(a.seed).map_err(anyhow::Error::msg)?;
    let path = resolve_profile(&a.profile)?;
    let mut cfg = CampaignConfig::load(&path)?;
    single::set_images(&mut cfg, a.images).map_err(anyhow::Error::msg)?;
    let learner = single::resolve_learner(&a.learner, a.command.as_deref(), &mut cfg)
        .map_err(anyhow::Error::msg)?;
    single::check_learner_variant(learner, a.variant).map_err(anyhow::Error::msg)?;
    single::check_latents(a.latents, cfg.ugl.images).map_err(anyhow::Error::msg)?;
    if !(2..=1000).contains(&a.grid) {
        bail!("--grid must be between 2 and 1000, got {}", a.grid);
    }
    if a.out.extension().and_then(|e| e.to_str()) != Some("npy") {
        bail!("--out {}: the file name must end in .npy", a.out.display());
    }
    let dir = a
        .out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    check_out_dir(dir)?;
    let spec = RunSpec::learned(
        a.env,
        Algo::Rge(learner),
        SamplerKind::Kde,
        a.latents,
        a.variant.unwrap_or_default(),
        a.seed,
    );
    let model_cache = a.cache.resolve(dir);
    let mp = progress_area();
    let ctx = single_context(&cfg, &a.profile, model_cache.as_ref(), &a.cache, dir, &mp);
    let e = ugl_bench::campaign::embed::embed(&spec, &ctx, a.grid)?;
    let stem = a.out.with_extension("");
    let sibling = |suffix: &str| PathBuf::from(format!("{}.{suffix}.npy", stem.display()));
    let files = [
        (a.out.clone(), e.train.n, e.train.latents, &e.train.data),
        (sibling("states"), e.train.n, e.state_dim, &e.train_states),
        (sibling("grid"), e.grid.n, e.grid.latents, &e.grid.data),
        (
            sibling("grid_states"),
            e.grid.n,
            e.state_dim,
            &e.grid_states,
        ),
    ];
    for (path, rows, cols, data) in &files {
        ugl_bench::campaign::embed::write_npy_f64(path, *rows, *cols, data)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    println!(
        "{}",
        serde_json::json!({
            "representation": ugl_bench::campaign::fit::representation_label(&spec),
            "files": files.iter().map(|f| f.0.display().to_string()).collect::<Vec<_>>(),
            "latent_quality": e.quality,
        })
    );
    Ok(())
}

/// `--algo`'s help, from the registry.
fn algo_help() -> String {
    let algos: Vec<&str> = Learner::all().map(|l| l.entry().algo).collect();
    format!(
        "rpe, rge-efr, or a learned goal space rge-NAME: {} (parameters in the profile's \
         [learners.NAME]; `ugl learners` describes them); the follow-up paper's modular goal \
         exploration (docs/armballs.md): mge-efr-CHOICE or mge-NAME-CHOICE, CHOICE = flat (one \
         module), random or lp (learning progress), constants in the profile's [mge]",
        algos.join(", ")
    )
}

/// `--learner`'s help, from the registry.
/// `--env`: every environment of the registry, with its description.
fn env_help() -> String {
    let envs: Vec<String> = ugl_types::ENVIRONMENTS
        .iter()
        .map(|e| format!("{}: {}", e.name, e.description))
        .collect();
    format!("The environment: {}", envs.join("; "))
}

/// `ugl klc --env`: the CSV header of each environment, the measured coordinates.
fn klc_env_help() -> String {
    let envs: Vec<String> = ugl_types::ENVIRONMENTS
        .iter()
        .map(|e| {
            format!(
                "{} (CSV header `{}`)",
                e.name,
                e.outcome_columns[e.metric_dims()].join(",")
            )
        })
        .collect();
    format!(
        "The environment: {}; only the controllable object is measured",
        envs.join(", ")
    )
}

/// `ugl render --state`: the engineered state of each environment.
fn state_help() -> String {
    let envs: Vec<String> = ugl_types::ENVIRONMENTS
        .iter()
        .map(|e| format!("`{}` ({})", e.outcome_columns.join(","), e.name))
        .collect();
    format!(
        "Engineered state, each coordinate in [-1,1]: {}",
        envs.join(", ")
    )
}

fn learner_help() -> String {
    let names: Vec<&str> = Learner::all()
        .filter(|l| !l.is_external())
        .map(Learner::name)
        .collect();
    format!(
        "A registered learner ({}), or with --command the name of an external program",
        names.join(", ")
    )
}

/// `ugl learners`: the registry as a table.
fn learners() {
    println!(
        "{:<22} {:<26} {:<9} {:<9} {:<6} description",
        "name", "algorithm", "variants", "prior", "paper"
    );
    for l in Learner::all() {
        let e = l.entry();
        let prior = match e.prior {
            ugl_bench::repr::registry::Prior::None => "no",
            ugl_bench::repr::registry::Prior::Always => "yes",
            ugl_bench::repr::registry::Prior::Declared => "declared",
        };
        println!(
            "{:<22} {:<26} {:<9} {:<9} {:<6} {}",
            e.name,
            e.algo,
            if e.has_variants { "yes" } else { "no" },
            prior,
            if e.in_paper { "yes" } else { "no" },
            e.description
        );
    }
}

/// `ugl compare`: the paper's matrix cells and seeds for one more learner.
fn compare(a: CompareArgs) -> Result<()> {
    let (cfg, base) = single::compare_campaign(
        CampaignConfig::load(&a.config)?,
        &a.learner,
        a.command.as_deref(),
        a.gaussian,
    )
    .map_err(anyhow::Error::msg)?;
    cfg.validate()
        .map_err(|m| anyhow::anyhow!("{}: {m}", a.config.display()))?;
    let out = a
        .out
        .unwrap_or_else(|| PathBuf::from("data/results").join(&cfg.campaign.name));
    if a.refresh_diagnostics {
        let profile = cfg.campaign.name.clone();
        return refresh_config(&cfg, &profile, Some(out), a.jobs, None, &a.cache);
    }
    run_config(
        &cfg,
        &cfg.campaign.name.clone(),
        Some(out.clone()),
        a.jobs,
        a.quiet,
        None,
        &a.cache,
    )?;
    print_compare_page(&out, &cfg.campaign.name, &base);
    Ok(())
}

/// After `ugl compare`: the new learner's one-page summary (what `ugl report` writes as
/// `compare_<campaign>.md`), from a report rendered into a temporary directory.
fn print_compare_page(out: &Path, campaign: &str, main_campaign: &str) {
    let results = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let tmp = std::env::temp_dir().join(format!("ugl-compare-{}", std::process::id()));
    let mut opts = ugl_report::ReportOptions::new(results.to_path_buf(), tmp.clone());
    opts.main_campaign = main_campaign.to_string();
    let page = ugl_report::render_report(&opts)
        .map_err(|e| e.to_string())
        .and_then(|_| {
            let p = tmp.join(ugl_report::markdown::compare::file_name(campaign));
            std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))
        });
    let _ = std::fs::remove_dir_all(&tmp);
    match page {
        Ok(text) => println!("{text}"),
        Err(e) => eprintln!(
            "no summary page ({e}); `ugl report` ranks the learner once the main campaign \
             `{main_campaign}` is in {}",
            results.display()
        ),
    }
}

/// The checked `--shard`, `--out` (default `data/results/<campaign>`) and `--jobs` (default: the
/// number of cores) of a campaign command.
fn campaign_args(
    cfg: &CampaignConfig,
    shard: Option<&str>,
    out: Option<PathBuf>,
    jobs: Option<usize>,
) -> Result<(Option<(usize, usize)>, PathBuf, usize)> {
    let shard = shard
        .map(parse_shard)
        .transpose()
        .map_err(|e| anyhow::anyhow!(e))?;
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

/// The stop flag of a campaign command: the first Ctrl-C sets it (and stops external learners
/// still fitting), so the work in flight (`what`) finishes and is stored; a second one exits.
fn stop_on_ctrl_c(what: &'static str) -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        // External learners still fitting are stopped now, not waited for.
        ugl_bench::repr::external::interrupt();
        eprintln!("\ninterrupt: finishing {what} (Ctrl-C again to abort now)");
    })
    .context("cannot install the Ctrl-C handler")?;
    Ok(stop)
}

fn run_config(
    cfg: &CampaignConfig,
    profile: &str,
    out: Option<PathBuf>,
    jobs: Option<usize>,
    quiet: bool,
    shard: Option<&str>,
    cache: &CacheArgs,
) -> Result<()> {
    // Every argument is checked before anything touches the disk.
    let (shard, out, jobs) = campaign_args(cfg, shard, out, jobs)?;
    check_out_dir(&out)?;
    let stop = stop_on_ctrl_c("the runs in flight")?;
    let mp = MultiProgress::new();
    if quiet || !std::io::stderr().is_terminal() {
        mp.set_draw_target(ProgressDrawTarget::hidden());
    }
    let bar = mp.add(ProgressBar::new(0));
    let checkpoint_every = cache.checkpoint_every;
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
    };
    let opts = CampaignOptions {
        jobs,
        profile,
        stop: &stop,
        shard,
        cache: cache.as_ref(),
        train_progress: Some(training_bars(&mp, Some(&bar))),
        learner_messages: Some(learner_lines(&mp, Some(&bar))),
        checkpoint_every,
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

fn slurm(
    config: &Path,
    shards: usize,
    out: Option<PathBuf>,
    scripts: &Path,
    cpus: usize,
    time: &str,
) -> Result<()> {
    use ugl_bench::campaign::slurm::{SlurmJob, scripts as slurm_scripts, write_scripts};
    let cfg = CampaignConfig::load(config)?;
    let out = out.unwrap_or_else(|| PathBuf::from("data/results").join(&cfg.campaign.name));
    let cwd = std::env::current_dir().context("cannot read the current directory")?;
    let (config_abs, out_abs) = (cwd.join(config), cwd.join(&out));
    let job = SlurmJob {
        name: &cfg.campaign.name,
        n_runs: plan(&cfg).len(),
        checkout: &cwd,
        config: &config_abs,
        out: &out_abs,
        shards,
        cpus,
        time,
    };
    let texts = slurm_scripts(&job)?;
    check_out_dir(scripts)?;
    write_scripts(scripts, &texts)?;
    eprintln!(
        "wrote {}/{{array,report,submit}}.sh: {} runs in {shards} shards; run {}/submit.sh",
        scripts.display(),
        job.n_runs,
        scripts.display()
    );
    Ok(())
}

fn merge(into: &Path, sources: &[PathBuf]) -> Result<()> {
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
