//! The command line's grammar (clap): every subcommand, its options and their help, the
//! lists in the help derived from the registries.

use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};

use ugl_bench::env::EnvKind;
use ugl_bench::explore::{Algo, Learner, SamplerKind};
use ugl_bench::repr::cache::ModelCache;
use ugl_bench::repr::neural::Variant;

/// ugl-bench: reproduce "Unsupervised Learning of Goal Spaces for Intrinsically Motivated Goal
/// Exploration" (Péré et al., ICLR 2018) deterministically on a CPU.
#[derive(Parser, Debug)]
#[command(name = "ugl", version, about, long_about = None, propagate_version = true)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand, Debug)]
pub(crate) enum Command {
    /// Run episodes: prints a JSON array with, per parameter vector, the final object state,
    /// whether the object was caught, and the hand position.
    Rollout {
        #[arg(long, help = env_help())]
        env: EnvKind,
        /// JSON file: an array of arrays of motor parameters, clipped to [-1,1] (21 per episode;
        /// armballs-corl: 49).
        #[arg(long)]
        params: PathBuf,
        /// armballs, armballs-corl: the distractor's random walk draws from this seed's
        /// `distractor` stream, episode after episode (the other environments draw nothing).
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
    /// Render an object state as the picture the learners see (70x70 gray; armballs-corl:
    /// 64x64 RGB).
    Render {
        #[arg(long, help = env_help())]
        env: EnvKind,
        #[arg(long, allow_hyphen_values = true, help = state_help())]
        state: String,
        /// Output file: `.npy` (float32 70x70 indexed [x][y]; armballs-corl: 64x64x3, rows
        /// first) or `.png` (for people).
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
        #[arg(long, default_value = ugl_types::samplers::KDE.name, help = sampler_help())]
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
        /// Exploration replicate of the repetition (`[campaign] explorations`): replicate J > 0
        /// explores the repetition's fitted goal space with its own streams.
        #[arg(long, default_value_t = 0)]
        exploration: u32,
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
        /// Write into the checkout's data/ although tracked files have uncommitted changes
        /// (the run then records a `-dirty` git revision, which no commit reproduces exactly).
        #[arg(long)]
        allow_dirty: bool,
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
        /// Write into the checkout's data/ although tracked files have uncommitted changes
        /// (the runs then record a `-dirty` git revision, which no commit reproduces exactly).
        #[arg(long)]
        allow_dirty: bool,
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
    /// Write a Slurm job for a campaign into a job directory: an array job (one task per
    /// shard), a report step that runs once every task succeeded, and `submit.sh`, which builds
    /// ugl once and submits both. Everything goes under OUT (default data/results/<name>, in
    /// the checkout, where git ignores the job directory and the report) unless --scripts and
    /// --report-out say otherwise.
    Slurm(SlurmArgs),
    /// How far a campaign's results directory is: runs complete, missing, damaged or of
    /// another configuration, overall and per shard (what a resumed campaign would compute).
    Status {
        /// Campaign file (data/campaigns/NAME.toml). Without it, the campaign `--out`'s record
        /// (campaign.toml) names: its profile, or for a store of `ugl compare` the campaign
        /// `ugl compare` built.
        #[arg(long)]
        config: Option<PathBuf>,
        /// Results directory (default: data/results/<campaign name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Also count per shard of this many (as `ugl slurm --shards` deals them).
        #[arg(long, default_value_t = 1)]
        shards: usize,
        /// Exit with an error unless every run is complete.
        #[arg(long)]
        require_complete: bool,
    },
    /// Check a store against the code: every run's files against its manifest's digests, then
    /// rerun a sample of its runs (stratified over the conditions, at least one trained
    /// network unless --without-networks) from the campaign's profile into a scratch directory, fitting afresh, and
    /// compare their bytes with the committed ones. Exits with an error on any difference.
    /// Each sampled run is recomputed whole: a trained network is retrained from scratch, with
    /// its progress on stderr (a `paper-long` network takes hours). The first Ctrl-C stops after
    /// the rerun in flight and reports the ones done. A store of `ugl compare` is rerun as
    /// `ugl compare` built it, from its base campaign's profile.
    Verify {
        /// A campaign's results directory (holding its campaign.toml).
        #[arg(long)]
        results: PathBuf,
        /// The campaign's profile (default: data/campaigns/<the record's name>.toml, or for a
        /// `ugl compare` store the campaign built on its base's); its configuration hash must
        /// be the record's.
        #[arg(long)]
        config: Option<PathBuf>,
        /// How many runs to rerun: at most one per condition, so at most the number of
        /// conditions.
        #[arg(long, default_value_t = 4)]
        sample: usize,
        /// Rerun only runs whose goal space trains no network (RPE, engineered features,
        /// PCA, ...): a quick check of a store whose networks take long to retrain. Its
        /// networks are then checked only against their manifests' digests.
        #[arg(long)]
        without_networks: bool,
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
    /// Tabulate a convolutional-network sweep (the OUT of scripts/conv_sweep.sh): one markdown
    /// row per trained network, read from its run's manifest: its setting, whether it left the
    /// mean-picture plateau, the per-latent KL, the active latents and which object each encodes,
    /// the k-NN R² of each object, MIG and SAP.
    SweepTable {
        /// The sweep's directory: one sub-directory per setting, holding its runs.
        dir: PathBuf,
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
        /// The campaign (sub-directory of --results) the figures and tables are drawn from; the
        /// campaigns whose recorded role ties them to it (budget, recipe, compare, follow-up,
        /// validation) feed their sections. `(top level)` or `.`: the runs directly in --results.
        #[arg(long = "main", default_value = "paper")]
        main_campaign: String,
    },
}

/// `ugl slurm`'s options.
#[derive(clap::Args, Debug)]
pub(crate) struct SlurmArgs {
    /// Campaign file (data/campaigns/NAME.toml).
    #[arg(long)]
    pub(crate) config: PathBuf,
    /// Number of array tasks (shards): 1 to the campaign's number of fit groups (runs sharing a
    /// trained representation stay in one shard).
    #[arg(long)]
    pub(crate) shards: usize,
    /// Results directory the tasks write to, on a file system every node sees (default:
    /// data/results/<campaign name>). Not the checkout or a directory above it.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Job directory: the scripts, bin/ugl and logs/ (default: OUT/slurm).
    #[arg(long)]
    pub(crate) scripts: Option<PathBuf>,
    /// Where the report step writes REPORT.md and its figures (default: OUT/report).
    #[arg(long)]
    pub(crate) report_out: Option<PathBuf>,
    /// CPUs per task (each task runs that many runs in parallel), 1 to 1024.
    #[arg(long, default_value_t = 2)]
    pub(crate) cpus: usize,
    /// Wall-time limit per task, in Slurm's syntax: MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM or
    /// D-HH:MM:SS.
    #[arg(long, default_value = "04:00:00")]
    pub(crate) time: String,
    /// Wall-time limit of the report step.
    #[arg(long, default_value = "00:30:00")]
    pub(crate) report_time: String,
    /// At most this many tasks at once (Slurm's `--array=...%N`).
    #[arg(long)]
    pub(crate) throttle: Option<usize>,
    /// An extra sbatch option for both jobs, long form with '=' (repeatable):
    /// --sbatch-arg=--partition=NAME --sbatch-arg=--account=NAME --sbatch-arg=--qos=NAME
    /// --sbatch-arg=--mem=8G.
    #[arg(long = "sbatch-arg", allow_hyphen_values = true)]
    pub(crate) sbatch_args: Vec<String>,
    /// Let the tasks write into the checkout's data/ although tracked files have uncommitted
    /// changes (passed on to each task's `ugl campaign`).
    #[arg(long)]
    pub(crate) allow_dirty: bool,
}

#[derive(clap::Args, Debug)]
pub(crate) struct EmbedArgs {
    #[arg(long, help = env_help())]
    pub(crate) env: EnvKind,
    #[arg(long, help = learner_help())]
    pub(crate) learner: String,
    /// External learners: the command line of the program (docs/external-learners.md).
    #[arg(long)]
    pub(crate) command: Option<String>,
    /// vae / rfvae: faithful (default) or corrected.
    #[arg(long)]
    pub(crate) variant: Option<Variant>,
    /// Latent size.
    #[arg(long, default_value_t = 10)]
    pub(crate) latents: usize,
    /// Repetition index (the data set and the learner's stream derive from it).
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// Override the profile's number of UGL training images.
    #[arg(long)]
    pub(crate) images: Option<usize>,
    /// Budget profile: a name in data/campaigns/ or a path to a .toml file.
    #[arg(long, default_value = "paper")]
    pub(crate) profile: String,
    /// The grid of object positions: GRID x GRID over [-1, 1]^2 (ArmArrow: angle 0).
    #[arg(long, default_value_t = 21)]
    pub(crate) grid: usize,
    /// The training latents' file (.npy, float64, (n, latents)); beside it OUT-stem.states.npy
    /// (n, state dim), OUT-stem.grid.npy (GRID^2, latents) and OUT-stem.grid_states.npy.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// Encode with the weights of the network's checkpoint after this many iterations, read from
    /// the model cache, instead of the finished network: the network part-way through its
    /// training (kept by a run with --keep-checkpoints). Nothing is trained.
    #[arg(long, value_name = "ITERATIONS", conflicts_with = "no_cache")]
    pub(crate) checkpoint: Option<usize>,
    #[command(flatten)]
    pub(crate) cache: CacheArgs,
}

#[derive(clap::Args, Debug)]
pub(crate) struct CompareArgs {
    #[arg(long, help = learner_help())]
    pub(crate) learner: String,
    /// Command line of a program speaking the external-learner protocol
    /// (docs/external-learners.md), run with `sh -c`.
    #[arg(long)]
    pub(crate) command: Option<String>,
    /// External learners: also run Gaussian-prior goals (the program must write prior.npy).
    #[arg(long)]
    pub(crate) gaussian: bool,
    /// The campaign whose cells, seeds and budgets to use.
    #[arg(long, default_value = "data/campaigns/paper.toml")]
    pub(crate) config: PathBuf,
    /// Results directory (default: data/results/compare-NAME).
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Runs in parallel (default: the number of cores).
    #[arg(long)]
    pub(crate) jobs: Option<usize>,
    /// No progress bars.
    #[arg(long)]
    pub(crate) quiet: bool,
    /// Run nothing: bring the goal-space diagnostics of the finished runs up to date (as
    /// `ugl campaign --refresh-diagnostics`).
    #[arg(long)]
    pub(crate) refresh_diagnostics: bool,
    /// Write into the checkout's data/ although tracked files have uncommitted changes.
    #[arg(long)]
    pub(crate) allow_dirty: bool,
    #[command(flatten)]
    pub(crate) cache: CacheArgs,
}

/// Where trained neural models are kept.
#[derive(clap::Args, Debug)]
pub(crate) struct CacheArgs {
    /// Model cache directory for fitted representations that persist: trained networks, PCA
    /// (default: OUT/models). A model is keyed by the hash of everything it depends on; an
    /// invalid file is refitted.
    #[arg(long)]
    pub(crate) cache: Option<PathBuf>,
    /// Do not read or write the model cache (always fit).
    #[arg(long, conflicts_with = "cache")]
    pub(crate) no_cache: bool,
    /// Save a checkpoint of each neural training every N iterations in the model cache (0:
    /// never). A training killed mid-way resumes from its latest checkpoint and ends
    /// bit-identical to an uninterrupted one.
    #[arg(long, default_value_t = 1000)]
    pub(crate) checkpoint_every: usize,
    /// Keep every checkpoint, also after the training finished (a few MB each), to look at the
    /// network part-way with `ugl embed --checkpoint`; by default a checkpoint replaces the older
    /// ones and the finished training removes the last.
    #[arg(long)]
    pub(crate) keep_checkpoints: bool,
}

impl CacheArgs {
    pub(crate) fn resolve(&self, out: &Path) -> Option<ModelCache> {
        if self.no_cache {
            return None;
        }
        Some(ModelCache::new(
            self.cache.clone().unwrap_or_else(|| out.join("models")),
        ))
    }
}

/// `--algo`'s help, from the registry.
pub(crate) fn algo_help() -> String {
    let algos: Vec<&str> = Learner::all().map(|l| l.entry().algo).collect();
    format!(
        "rpe, rge-efr, rge-efr-position (the engineered features without the angle, paired \
         with rge-efr: a control on ArmArrow), rge-efr-mixed (the engineered features through a \
         fixed rotation that mixes the objects: an entangled control), or a learned goal space \
         rge-NAME: {} (parameters in the profile's [learners.NAME]; `ugl learners` describes \
         them); the follow-up paper's modular goal exploration (docs/armballs.md): \
         mge-efr-CHOICE, mge-efr-mixed-CHOICE or mge-NAME-CHOICE, CHOICE = flat (one module), \
         random or lp (learning progress), constants in the profile's [mge]",
        algos.join(", ")
    )
}

/// `--sampler`: every sampler of learned goal spaces in the registry, with its description.
pub(crate) fn sampler_help() -> String {
    let samplers: Vec<String> = SamplerKind::learned()
        .into_iter()
        .map(|s| format!("{}: {}", s.name(), s.info().description))
        .collect();
    format!(
        "Goal sampler of a learned goal space: {}",
        samplers.join("; ")
    )
}

/// `--env`: every environment of the registry, with its description.
pub(crate) fn env_help() -> String {
    let envs: Vec<String> = ugl_types::environments()
        .into_iter()
        .map(|e| format!("{}: {}", e.name, e.description))
        .collect();
    format!("The environment: {}", envs.join("; "))
}

/// `ugl klc --env`: the CSV header of each environment, the measured coordinates.
pub(crate) fn klc_env_help() -> String {
    let envs: Vec<String> = ugl_types::environments()
        .into_iter()
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
pub(crate) fn state_help() -> String {
    let envs: Vec<String> = ugl_types::environments()
        .into_iter()
        .map(|e| format!("`{}` ({})", e.outcome_columns.join(","), e.name))
        .collect();
    format!(
        "Engineered state, each coordinate in [-1,1]: {}",
        envs.join(", ")
    )
}

pub(crate) fn learner_help() -> String {
    let names: Vec<&str> = Learner::all()
        .filter(|l| !l.is_external())
        .map(Learner::name)
        .collect();
    format!(
        "A registered learner ({}), or with --command the name of an external program",
        names.join(", ")
    )
}
