//! What every report section reads: the campaigns, and the statistics computed once from them
//! ([`crate::render::render_report`] builds it; [`crate::sections`] and [`crate::markdown`] read it).

use crate::aggregate::ConditionSummary;
use crate::campaigns::Campaigns;
use crate::claims::ClaimsInput;
use crate::discovery::{Check, RunRow};
use crate::leaderboard::Leaderboard;
use crate::load::Store;
use crate::neural::{BudgetAnalysis, LossCurve, VariantPair};
use crate::options::ReportOptions;
use crate::paper::PaperTable;

/// What every section reads: the campaigns and the statistics computed once from them.
pub struct Context<'a> {
    pub opts: &'a ReportOptions,
    pub campaigns: &'a Campaigns,
    /// The main campaign's runs.
    pub store: &'a Store,
    pub paper: &'a PaperTable,
    /// The main campaign's conditions.
    pub conditions: &'a [ConditionSummary],
    /// The main campaign's conditions and the `compare` campaigns' new ones, in report order
    /// (the curves draw them together).
    pub curve_conditions: &'a [ConditionSummary],
    pub variant_pairs: &'a [VariantPair<'a>],
    pub budget: &'a BudgetAnalysis,
    /// The main campaign's training-loss curves.
    pub losses: &'a [LossCurve],
    /// The paper's claims, evaluated on the main campaign.
    pub claims: &'a ClaimsInput<'a>,
    /// The paper's claims on the cells of the recipe campaigns, with the main campaign's
    /// networks and the recipe's ([`crate::claims::cell_verdicts`]).
    pub recipe_verdicts: &'a [crate::claims::CellVerdict],
    /// Main and `compare` campaigns, ranked.
    pub leaderboard: &'a Leaderboard,
    /// Every run the report reads, with its discovery measures at the final epoch.
    pub discovery: &'a [RunRow<'a>],
    /// The validity check of the discovery measures, per environment.
    pub validity: &'a [Check],
}
