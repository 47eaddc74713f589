//! `ugl-report`: reads the ugl-bench results store, computes statistics over seeds, draws the
//! paper's figures as SVG and writes `REPORT.md`.
//!
//! The report never re-runs science: its only inputs are the run files of the results store
//! (`data/results/README.md` documents them) and the paper's reference values in `data/paper/`.
//! Rendering twice from the same inputs gives byte-identical files: every iteration is sorted,
//! the bootstrap is seeded, and nothing depends on the clock or the host.

pub mod aggregate;
pub mod armballs;
pub mod campaigns;
pub mod claims;
pub mod context;
pub mod data;
pub mod discovery;
pub mod error;
pub mod figures;
pub mod leaderboard;
pub mod load;
pub mod markdown;
pub mod neural;
pub mod output;
pub mod paper;
pub mod predicts;
pub mod sections;
pub mod stats;

use std::path::{Path, PathBuf};

pub use error::ReportError;

/// What to render, from where, to where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportOptions {
    /// The results store: one sub-directory per campaign (run files directly in it form the
    /// campaign `""`).
    pub results: PathBuf,
    /// The campaign that reproduces the paper (curves, scatters, Figure 4, variants, the table
    /// against the paper). Campaigns named `budget-*` feed the training-budget section,
    /// `compare-*` ones the leaderboard and the KL-coverage figures; others
    /// are listed as unused. `""` selects the runs at the store's top level.
    pub main_campaign: String,
    /// Where `REPORT.md` and `figures/*.svg` are written (created if missing).
    pub out: PathBuf,
    /// The paper's reference values (`klc_final.csv`); a missing directory is reported, not fatal.
    pub paper_dir: PathBuf,
    /// Seed of the leaderboard's and the comparison pages' stratified bootstrap (each
    /// statistic derives its own stream from it). The intervals over one condition's seeds
    /// (tables, bands, claims) are t intervals and draw nothing.
    pub bootstrap_seed: u64,
    /// Resamples per stratified-bootstrap interval.
    pub n_boot: usize,
}

impl ReportOptions {
    /// The default main campaign.
    pub const DEFAULT_MAIN_CAMPAIGN: &'static str = "paper";

    /// Defaults: main campaign `paper`, `paper_dir` = `data/paper`, bootstrap seed 0, 10,000
    /// resamples.
    pub fn new(results: PathBuf, out: PathBuf) -> Self {
        ReportOptions {
            results,
            main_campaign: Self::DEFAULT_MAIN_CAMPAIGN.to_string(),
            out,
            paper_dir: PathBuf::from("data/paper"),
            bootstrap_seed: 0,
            n_boot: 10_000,
        }
    }
}

/// What `render_report` did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportSummary {
    /// Complete runs the report used (main, budget, compare and training-recipe campaigns).
    pub n_runs: usize,
    /// Complete runs of the main campaign.
    pub n_main_runs: usize,
    /// The budget campaigns used, sorted.
    pub budget_campaigns: Vec<String>,
    /// Campaigns present in the store but not used, sorted.
    pub unused_campaigns: Vec<String>,
    /// Training-recipe campaigns (`<main>-*`), sorted by name.
    pub recipe_campaigns: Vec<String>,
    /// Files written (`REPORT.md` first, then the figures), sorted, under `opts.out`.
    pub files: Vec<PathBuf>,
}

/// Reads the store, computes the statistics once, and renders every section of
/// [`sections::SECTIONS`] into `out` (`REPORT.md`, its pages, `figures/`, `data/`); files of the
/// previous render that this one did not write are removed ([`output::Output`]).
pub fn render_report(opts: &ReportOptions) -> Result<ReportSummary, ReportError> {
    // The runs are read and measured on every core. Reading a parquet file (polars, built
    // without optimisation in the one dev profile) needs more stack than a rayon worker's
    // default 2 MiB; the stack is reserved, not committed.
    let pool = rayon::ThreadPoolBuilder::new()
        .stack_size(REPORT_STACK)
        .build()
        .map_err(|e| ReportError::Options(format!("cannot start the report's threads: {e}")))?;
    pool.install(|| render_report_on_pool(opts))
}

/// Stack of the report's worker threads.
const REPORT_STACK: usize = 64 << 20;

fn render_report_on_pool(opts: &ReportOptions) -> Result<ReportSummary, ReportError> {
    if opts.n_boot == 0 {
        return Err(ReportError::Options("n_boot must be at least 1".into()));
    }
    let list = sections::SECTIONS;
    let camps = campaigns::load_campaigns(
        &opts.results,
        &opts.main_campaign,
        &sections::wanted_roles(list),
    )?;
    let store = &camps.main.store;
    let paper = paper::load_paper(&opts.paper_dir)?;
    let conditions = aggregate::aggregate(store, &paper);
    let pairs = neural::variant_pairs(&conditions);
    let budget = neural::budget_analysis(&camps.budget, store, &conditions);
    let losses = neural::loss_curves(store);

    let claims_path = opts.paper_dir.join(claims::FILE);
    let claims_file = if claims_path.exists() {
        Some(claims::load_claims(&claims_path)?)
    } else {
        None
    };
    // The recipe campaigns (the untrained twins, ...) on the main campaign's repetitions,
    // tagged for the claims that compare a learner with its variant.
    let recipe_conditions: Vec<(String, Vec<aggregate::ConditionSummary>)> = camps
        .recipe
        .iter()
        .map(|c| {
            let tag = c.decl.tag.clone().unwrap_or_else(|| c.name.clone());
            (tag, aggregate::aggregate(&c.store, &paper))
        })
        .collect();
    let mut parts = vec![(None, conditions.as_slice(), store)];
    for ((tag, conds), c) in recipe_conditions.iter().zip(&camps.recipe) {
        parts.push((Some(tag.clone()), conds.as_slice(), &c.store));
    }
    let observations = claims::TaggedObservations { parts };
    let mut claim_results = claims_file
        .as_ref()
        .map(|f| claims::evaluate_on(f, &observations))
        .unwrap_or_default();
    let keys: Vec<_> = conditions.iter().map(|c| c.key.clone()).collect();
    claims::attach_paper_checks(&mut claim_results, &keys, &paper);
    let claims_input = match &claims_file {
        Some(f) => claims::ClaimsInput::Evaluated {
            path: &claims_path,
            confidence: f.settings.confidence,
            margin: f.settings.margin,
            target_half_width: f.settings.target_half_width,
            validated: f.settings.validated.as_ref(),
            results: &claim_results,
        },
        None => claims::ClaimsInput::Missing(&claims_path),
    };

    // New learners (`compare` campaigns): aggregated like the main campaign, ranked with it in
    // the leaderboard and drawn with it in the KL-coverage figures.
    let compare_conditions: Vec<Vec<aggregate::ConditionSummary>> = camps
        .compare
        .iter()
        .map(|c| {
            let mut conds = aggregate::aggregate(&c.store, &paper);
            aggregate::mark_rpe_level_against(&c.store, &mut conds, &conditions);
            conds
        })
        .collect();
    let mut sources = vec![leaderboard::Source {
        campaign: &camps.main.name,
        store,
        conditions: &conditions,
    }];
    for (c, conds) in camps.compare.iter().zip(&compare_conditions) {
        sources.push(leaderboard::Source {
            campaign: &c.name,
            store: &c.store,
            conditions: conds,
        });
    }
    let board = leaderboard::build(
        &sources,
        LEADERBOARD_CONFIDENCE,
        opts.n_boot,
        opts.bootstrap_seed,
    );
    let mut curve_conditions = conditions.clone();
    for conds in &compare_conditions {
        curve_conditions.extend(
            conds
                .iter()
                .filter(|c| !conditions.iter().any(|m| m.key == c.key))
                .cloned(),
        );
    }
    curve_conditions.sort_by_key(|c| c.key.order_key());

    let measured = discovery::measure_all(&camps)?;
    let validity = discovery::validity(&measured);
    let ctx = sections::Context {
        opts,
        campaigns: &camps,
        store,
        paper: &paper,
        conditions: &conditions,
        curve_conditions: &curve_conditions,
        variant_pairs: &pairs,
        budget: &budget,
        losses: &losses,
        claims: &claims_input,
        leaderboard: &board,
        discovery: &measured,
        validity: &validity,
    };
    let mut out = output::Output::open(&opts.out)?;
    let md = sections::render(list, &ctx, &mut out)?;
    let report_path = out.write(REPORT_FILE, md.as_bytes())?;
    let mut files = out.finish()?;
    files.retain(|f| f != &report_path);
    files.insert(0, report_path);
    Ok(ReportSummary {
        n_runs: camps.n_used_runs(),
        n_main_runs: store.runs.len(),
        budget_campaigns: camps.budget.iter().map(|c| c.name.clone()).collect(),
        unused_campaigns: camps.unused.iter().map(|c| c.name.clone()).collect(),
        recipe_campaigns: camps.recipe.iter().map(|c| c.name.clone()).collect(),
        files,
    })
}

/// The report's main page inside the output directory.
pub const REPORT_FILE: &str = "REPORT.md";

/// Level of the leaderboard's stratified bootstrap intervals: the report's one level
/// ([`stats::CONFIDENCE`], also rliable's default).
pub const LEADERBOARD_CONFIDENCE: f64 = stats::CONFIDENCE;

/// The KDE-vs-Gaussian figures: the paper's Figure 4 (RGE-VAE), and the same for RGE-RFVAE,
/// which the paper did not plot (drawn when its Gaussian-goal runs exist).
pub const SAMPLER_FIGURES: [(&str, &str); 2] = [
    ("rge-vae", "fig4_vae_kde_vs_gaussian.svg"),
    ("rge-rfvae", "rfvae_kde_vs_gaussian.svg"),
];

/// Writes a file (figures are drawn into memory, then written here and recorded by their
/// section through [`output::Output`]).
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    std::fs::write(path, bytes).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })
}
