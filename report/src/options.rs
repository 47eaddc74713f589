//! What to render, from where, to where.

use std::path::PathBuf;

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
