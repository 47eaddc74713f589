//! The follow-up paper's setting (ArmBalls, `followup` campaigns): its own page, and its claims
//! at the end of `REPORT.md`.

use ugl_types::CampaignRole;

use super::{Context, Section};
use crate::armballs;
use crate::error::ReportError;
use crate::output::Output;

/// `armballs.md` and the follow-up claims.
pub struct Followup;
impl Section for Followup {
    fn name(&self) -> &'static str {
        "follow-up (ArmBalls)"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Followup]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let Some((lead, variants)) = ctx.campaigns.followup_lead() else {
            return Ok(String::new());
        };
        let Some(section) =
            armballs::render(lead, &variants, &out.figures_dir(), &ctx.opts.paper_dir)?
        else {
            return Ok(String::new());
        };
        out.figures(section.figures)?;
        out.write(armballs::PAGE, section.page.as_bytes())?;
        Ok(format!("\n{}", section.summary))
    }
}
