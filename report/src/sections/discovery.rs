//! Measures of what the exploration discovered that do not count repeats, and their validity
//! check ([`crate::discovery`]): a part of `REPORT.md` and `data/discovery_by_run.csv`.

use ugl_types::CampaignRole;

use super::{Context, Section};
use crate::error::ReportError;
use crate::output::Output;
use crate::{data, markdown, predicts};

/// The discovery measures of every run, and whether each ranks position-encoding goal spaces
/// ahead of the controls.
pub struct Discovery;
impl Section for Discovery {
    fn name(&self) -> &'static str {
        "discovery measures"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[
            CampaignRole::Compare,
            CampaignRole::Recipe,
            CampaignRole::Validation,
        ]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        data::discovery::write_csv(out, ctx.discovery)?;
        data::discovery::write_validity_csv(out, ctx.validity)?;
        let mut w = String::new();
        markdown::discovery::section(&mut w, ctx.discovery, ctx.validity, ctx.campaigns);
        Ok(w)
    }
}

/// The section: after the discovery measures, whether latent quality predicts them beyond the
/// number of moves. Nothing (no words, no data file) where no environment has a line with
/// numbers (no learned goal space with a varying position R²).
pub struct Predicts;
impl Section for Predicts {
    fn name(&self) -> &'static str {
        "latent quality beyond moves"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Recipe]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let obs = predicts::observations(ctx.campaigns, ctx.discovery);
        let lines = predicts::table(&obs);
        if !lines
            .iter()
            .any(|l| l.stats.as_ref().is_some_and(|a| a.r.is_some()))
        {
            return Ok(String::new());
        }
        data::predicts::write_csv(out, &lines)?;
        let mut w = String::new();
        markdown::predicts::section(&mut w, &obs, &lines, &ctx.campaigns.main.name);
        Ok(w)
    }
}
