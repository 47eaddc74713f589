//! The report's pipeline: read the store, compute every statistic once, then let each section
//! of [`crate::sections::SECTIONS`] render from that one [`crate::sections::Context`].

use std::path::PathBuf;

use crate::error::ReportError;
use crate::options::ReportOptions;
use crate::{
    aggregate, campaigns, claims, discovery, leaderboard, neural, output, paper, sections, stats,
};

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
    on_report_pool(|| render_report_on_pool(opts))
}

/// Runs `f` on the report's threads (see [`render_report`]).
fn on_report_pool<T>(f: impl FnOnce() -> Result<T, ReportError> + Send) -> Result<T, ReportError>
where
    T: Send,
{
    let pool = rayon::ThreadPoolBuilder::new()
        .stack_size(REPORT_STACK)
        .build()
        .map_err(|e| ReportError::Options(format!("cannot start the report's threads: {e}")))?;
    pool.install(f)
}

/// The page of one `compare` campaign (`compare_<campaign>.md`, what [`render_report`] writes),
/// computed from the main and `compare` campaigns alone, without rendering the report: what
/// `ugl compare` prints when its runs are done. None when the campaign has no leaderboard entry;
/// an error when it is not a `compare` campaign of the store.
pub fn compare_page(opts: &ReportOptions, campaign: &str) -> Result<Option<String>, ReportError> {
    if opts.n_boot == 0 {
        return Err(ReportError::Options("n_boot must be at least 1".into()));
    }
    on_report_pool(|| {
        let roles = [ugl_types::CampaignRole::Compare].into_iter().collect();
        let camps = campaigns::load_campaigns(&opts.results, &opts.main_campaign, &roles)?;
        let Some(mine) = camps.compare.iter().find(|c| c.name == campaign) else {
            return Err(ReportError::Options(format!(
                "`{campaign}` is not a compare campaign of {}",
                opts.results.display()
            )));
        };
        let paper = paper::load_paper(&opts.paper_dir)?;
        let conditions = aggregate::aggregate(&camps.main.store, &paper);
        let (_, board) = compare_leaderboard(&camps, &conditions, &paper, opts);
        Ok(crate::markdown::compare::page(
            campaign,
            &mine.store,
            &board,
            &camps.main.name,
            opts.bootstrap_seed,
        ))
    })
}

/// New learners (`compare` campaigns): aggregated like the main campaign, ranked with it in the
/// leaderboard (and drawn with it in the KL-coverage figures).
fn compare_leaderboard(
    camps: &campaigns::Campaigns,
    conditions: &[aggregate::ConditionSummary],
    paper: &paper::PaperTable,
    opts: &ReportOptions,
) -> (
    Vec<Vec<aggregate::ConditionSummary>>,
    leaderboard::Leaderboard,
) {
    let store = &camps.main.store;
    let compare_conditions: Vec<Vec<aggregate::ConditionSummary>> = camps
        .compare
        .iter()
        .map(|c| {
            let mut conds = aggregate::aggregate(&c.store, paper);
            aggregate::mark_rpe_level_against(&c.store, &mut conds, conditions);
            conds
        })
        .collect();
    let mut sources = vec![leaderboard::Source {
        campaign: &camps.main.name,
        store,
        conditions,
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
    (compare_conditions, board)
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
        .map(|c| (c.tag(), aggregate::aggregate(&c.store, &paper)))
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
    // The paper's claims on each recipe cell, with the main campaign's networks and the recipe's.
    let recipe_verdicts: Vec<claims::CellVerdict> = claims_file
        .as_ref()
        .map(|f| {
            recipe_conditions
                .iter()
                .flat_map(|(tag, conds)| {
                    let cells: Vec<_> = conds.iter().map(|c| c.key.clone()).collect();
                    claims::cell_verdicts(f, &observations, tag, &cells)
                })
                .collect()
        })
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

    let (compare_conditions, board) = compare_leaderboard(&camps, &conditions, &paper, opts);
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
        recipe_verdicts: &recipe_verdicts,
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
