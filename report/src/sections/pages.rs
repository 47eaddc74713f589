//! Files beside `REPORT.md`: one page per new learner, and the data behind the figures.

use ugl_types::CampaignRole;

use super::{Context, Section};
use crate::error::ReportError;
use crate::markdown::compare;
use crate::output::Output;

/// One page per `compare` campaign (`compare_<campaign>.md`).
pub struct ComparePages;
impl Section for ComparePages {
    fn name(&self) -> &'static str {
        "new-learner pages"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Compare]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        for c in &ctx.campaigns.compare {
            if let Some(page) = compare::page(
                &c.name,
                &c.store,
                ctx.leaderboard,
                &ctx.campaigns.main.name,
                ctx.opts.bootstrap_seed,
            ) {
                out.write(compare::file_name(&c.name), page.as_bytes())?;
            }
        }
        Ok(String::new())
    }
}

/// `data/final_by_seed.csv` and `data/curves.csv` (main and `compare` campaigns).
pub struct DataFiles;
impl Section for DataFiles {
    fn name(&self) -> &'static str {
        "data files"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Compare]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        crate::data::write(out, ctx.campaigns)?;
        Ok(String::new())
    }
}
