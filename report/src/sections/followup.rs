//! The follow-up paper's setting (ArmBalls, `followup` campaigns): its own page, and its claims
//! at the end of `REPORT.md`.

use ugl_types::CampaignRole;

use super::{Context, Section};
use crate::armballs;
use crate::error::ReportError;
use crate::output::Output;

/// What the report says without a follow-up campaign: where the follow-up stands.
const NO_FOLLOWUP: &str = "\n## Beyond the paper: a distractor (ArmBalls)\n\n\
    No campaign of these results has the role `followup`, so the follow-up paper's page \
    (`armballs.md`) and claims are not rendered. The page is being rebuilt for the follow-up's own \
    setup (the environment `armballs-corl`, campaign `followup`); the `armballs*` campaigns it \
    showed before, results version 3 of our DMP variant of the experiment, were retired with \
    results version 5 ([docs/armballs.md](../../docs/armballs.md)).\n";

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
            return Ok(NO_FOLLOWUP.to_string());
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
