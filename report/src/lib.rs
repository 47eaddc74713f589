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
pub mod data;
pub mod error;
pub mod figures;
pub mod leaderboard;
pub mod load;
pub mod markdown;
pub mod neural;
pub mod paper;
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
    /// Seed of the bootstrap (each condition and epoch derives its own stream from it).
    pub bootstrap_seed: u64,
    /// Bootstrap resamples per confidence interval.
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

/// Reads the store, computes the statistics, writes `out/REPORT.md` and `out/figures/*.svg`.
pub fn render_report(opts: &ReportOptions) -> Result<ReportSummary, ReportError> {
    if opts.n_boot == 0 {
        return Err(ReportError::Options("n_boot must be at least 1".into()));
    }
    let camps = campaigns::load_campaigns(&opts.results, &opts.main_campaign)?;
    let store = &camps.main.store;
    let paper = paper::load_paper(&opts.paper_dir)?;
    let conditions = aggregate::aggregate(store, &paper, opts.bootstrap_seed, opts.n_boot);
    let pairs = neural::variant_pairs(&conditions, opts.bootstrap_seed, opts.n_boot);
    let budget = neural::budget_analysis(
        &camps.budget,
        store,
        &conditions,
        opts.bootstrap_seed,
        opts.n_boot,
    );
    let losses = neural::loss_curves(store);

    let claims_path = opts.paper_dir.join(claims::FILE);
    let claims_file = if claims_path.exists() {
        Some(claims::load_claims(&claims_path)?)
    } else {
        None
    };
    let mut claim_results = claims_file
        .as_ref()
        .map(|f| claims::evaluate(f, &conditions, store, opts.bootstrap_seed))
        .unwrap_or_default();
    let keys: Vec<_> = conditions.iter().map(|c| c.key.clone()).collect();
    claims::attach_paper_checks(&mut claim_results, &keys, &paper);
    let claims_input = match &claims_file {
        Some(f) => markdown::claims::ClaimsInput::Evaluated {
            path: &claims_path,
            confidence: f.settings.confidence,
            n_boot: f.settings.n_boot,
            margin: f.settings.margin,
            results: &claim_results,
        },
        None => markdown::claims::ClaimsInput::Missing(&claims_path),
    };

    // New learners (`compare-*` campaigns): aggregated like the main campaign, ranked with it in
    // the leaderboard and drawn with it in the KL-coverage figures.
    let compare_conditions: Vec<Vec<aggregate::ConditionSummary>> = camps
        .compare
        .iter()
        .map(|c| {
            let mut conds =
                aggregate::aggregate(&c.store, &paper, opts.bootstrap_seed, opts.n_boot);
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

    let fig_dir = opts.out.join("figures");
    create_dir(&fig_dir)?;

    let klc_figs = figures::klc_curves::draw_all(&curve_conditions, &fig_dir)?;
    let coverage_figs = figures::klc_curves::draw_metric(
        &curve_conditions,
        &fig_dir,
        figures::klc_curves::Metric::Coverage,
    )?;
    let outcome_figs = figures::outcomes::draw_all(store, &conditions, &fig_dir)?;
    let mut sampler_figs = Vec::new();
    for (algo, name) in SAMPLER_FIGURES {
        if let Some(f) = figures::sampler_compare::draw(&conditions, algo, name, &fig_dir)? {
            sampler_figs.push(f);
        }
    }
    let variants_fig = figures::variants::draw(&pairs, &fig_dir)?;
    let budget_figs = figures::budget::draw_all(&budget.series, &opts.main_campaign, &fig_dir)?;
    let loss_fig = figures::training_loss::draw(&losses, &fig_dir)?;
    let mut appendix_figs = Vec::new();
    #[cfg(feature = "environment-figures")]
    appendix_figs.push(figures::environment::draw_environments(&fig_dir)?);
    appendix_figs.push(figures::radial_flow::draw(&fig_dir)?);
    #[cfg(feature = "environment-figures")]
    appendix_figs.extend(figures::environment::draw_dmp_episode(&fig_dir)?);
    let samples = figures::goal_space::load(&camps.main.path)?;
    let (mesh_figs, recon_figs) =
        figures::goal_space::draw_all(&samples, &camps.main.path, &fig_dir)?;

    let mut figure_files: Vec<PathBuf> = klc_figs
        .iter()
        .chain(&coverage_figs)
        .chain(&outcome_figs)
        .chain(&sampler_figs)
        .chain(&variants_fig)
        .chain(&budget_figs)
        .chain(&loss_fig)
        .chain(&mesh_figs)
        .chain(&recon_figs)
        .chain(&appendix_figs)
        .map(|f| f.path.clone())
        .collect();
    // The follow-up paper's campaign and its variants: one page.
    let mut followup = None;
    if let Some((main, variants)) = camps.followup_lead() {
        if let Some(section) =
            armballs::render(main, &variants, &fig_dir, opts.n_boot, opts.bootstrap_seed)?
        {
            figure_files.extend(section.figures.iter().map(|f| f.path.clone()));
            followup = Some(section);
        }
    }
    remove_stale_figures(&fig_dir, &figure_files)?;

    let md = markdown::render(&markdown::Inputs {
        opts,
        campaigns: &camps,
        store,
        paper: &paper,
        conditions: &conditions,
        klc_figures: &klc_figs,
        coverage_figures: &coverage_figs,
        outcome_figures: &outcome_figs,
        sampler_figures: &sampler_figs,
        variant_pairs: &pairs,
        variants_figure: variants_fig.as_ref(),
        budget: &budget,
        budget_figures: &budget_figs,
        loss_figure: loss_fig.as_ref(),
        goal_space_figures: &mesh_figs,
        reconstruction_figures: &recon_figs,
        appendix_figures: &appendix_figs,
        claims: &claims_input,
        leaderboard: &board,
    });
    // The follow-up paper's section: its own page, its claims in REPORT.md.
    let mut md = md;
    let mut followup_pages = Vec::new();
    if let Some(section) = &followup {
        let page = opts.out.join(armballs::PAGE);
        write_file(&page, section.page.as_bytes())?;
        followup_pages.push(page);
        md.push('\n');
        md.push_str(&section.summary);
    }
    remove_stale_page(&opts.out.join(armballs::PAGE), &followup_pages)?;
    let report_path = opts.out.join("REPORT.md");
    write_file(&report_path, md.as_bytes())?;
    // One page per new learner.
    let mut compare_pages = Vec::new();
    for c in &camps.compare {
        if let Some(page) = markdown::compare::page(
            &c.name,
            &c.store,
            &board,
            &camps.main.name,
            opts.bootstrap_seed,
        ) {
            let path = opts.out.join(markdown::compare::file_name(&c.name));
            write_file(&path, page.as_bytes())?;
            compare_pages.push(path);
        }
    }
    remove_stale_pages(&opts.out, &compare_pages)?;
    let data_files = data::write(&opts.out.join(data::DIR), &camps)?;

    figure_files.sort();
    let mut files = vec![report_path];
    files.extend(compare_pages);
    files.extend(followup_pages);
    files.extend(figure_files);
    files.extend(data_files);
    Ok(ReportSummary {
        n_runs: camps.n_used_runs(),
        n_main_runs: store.runs.len(),
        budget_campaigns: camps.budget.iter().map(|c| c.name.clone()).collect(),
        unused_campaigns: camps.unused.iter().map(|c| c.name.clone()).collect(),
        recipe_campaigns: camps.recipe.iter().map(|c| c.name.clone()).collect(),
        files,
    })
}

/// Level of the leaderboard's stratified bootstrap intervals (rliable's default).
pub const LEADERBOARD_CONFIDENCE: f64 = 0.95;

/// The KDE-vs-Gaussian figures: the paper's Figure 4 (RGE-VAE), and the same for RGE-RFVAE,
/// which the paper did not plot (drawn when its Gaussian-goal runs exist).
pub const SAMPLER_FIGURES: [(&str, &str); 2] = [
    ("rge-vae", "fig4_vae_kde_vs_gaussian.svg"),
    ("rge-rfvae", "rfvae_kde_vs_gaussian.svg"),
];

/// File names of figures this crate writes besides the per-condition ones: a stale copy of any
/// of them is removed when a render no longer writes it.
const OWN_FIGURES: [&str; 7] = [
    figures::variants::FILE,
    figures::training_loss::FILE,
    figures::radial_flow::FILE,
    figures::FIG1,
    figures::FIG6,
    "fig4_vae_kde_vs_gaussian.svg",
    "rfvae_kde_vs_gaussian.svg",
];

/// `compare_*.md` pages of campaigns no longer in the store.
fn remove_stale_pages(out: &Path, written: &[PathBuf]) -> Result<(), ReportError> {
    let entries = std::fs::read_dir(out).map_err(|source| ReportError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    for path in entries.flatten().map(|e| e.path()) {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with("compare_") && name.ends_with(".md") && !written.contains(&path) {
            std::fs::remove_file(&path).map_err(|source| ReportError::Io { path, source })?;
        }
    }
    Ok(())
}

/// An earlier render's page at `path` that this render did not write.
fn remove_stale_page(path: &Path, written: &[PathBuf]) -> Result<(), ReportError> {
    if path.is_file() && !written.iter().any(|w| w == path) {
        std::fs::remove_file(path).map_err(|source| ReportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    }
    Ok(())
}

fn create_dir(dir: &Path) -> Result<(), ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    std::fs::write(path, bytes).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Figures of an earlier render whose condition is gone would otherwise linger (and be committed):
/// remove our own figure files (`klc_*.svg`, `outcomes_*.svg`, `budget_*.svg` and the fixed
/// names of [`OWN_FIGURES`]) that this render did not write.
fn remove_stale_figures(fig_dir: &Path, written: &[PathBuf]) -> Result<(), ReportError> {
    let entries = std::fs::read_dir(fig_dir).map_err(|source| ReportError::Io {
        path: fig_dir.to_path_buf(),
        source,
    })?;
    let mut stale = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        let ours = (name.ends_with(".svg")
            && (name.starts_with("klc_")
                || name.starts_with("coverage_")
                || name.starts_with("outcomes_")
                || name.starts_with("budget_")
                || name.starts_with("goal_space_")
                || name.starts_with("armballs_")
                || OWN_FIGURES.contains(&name)))
            || (name.ends_with(".png") && name.starts_with("recon_"));
        if ours && !written.contains(&path) {
            stale.push(path);
        }
    }
    stale.sort();
    for path in stale {
        tracing::info!(path = %path.display(), "removing stale figure");
        std::fs::remove_file(&path).map_err(|source| ReportError::Io { path, source })?;
    }
    Ok(())
}
