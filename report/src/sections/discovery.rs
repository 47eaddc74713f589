//! Measures of what the exploration discovered that do not count repeats, and their validity
//! check ([`crate::discovery`]): a part of `REPORT.md` and `data/discovery_by_run.csv`.

use ugl_types::CampaignRole;

use super::{Context, Section};
use crate::ReportError;
use crate::discovery;
use crate::output::Output;

/// The discovery measures of every run, and whether each ranks position-encoding goal spaces
/// ahead of the controls.
pub struct Discovery;
impl Section for Discovery {
    fn name(&self) -> &'static str {
        "discovery measures"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Compare, CampaignRole::Recipe]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let rows = discovery::measure_all(ctx.campaigns)?;
        discovery::write_csv(out, &rows)?;
        let mut w = String::new();
        discovery::section(&mut w, &rows, &discovery::validity(&rows));
        Ok(w)
    }
}
