//! The sections that reproduce the paper and extend it on the main campaign, in the order of
//! `REPORT.md`. Each draws its own figures ([`crate::figures`]) and writes its words
//! ([`crate::markdown`]).

use ugl_types::CampaignRole;

use super::{Context, Section};
use crate::error::ReportError;
use crate::figures;
use crate::markdown::{self, claims, neural, quality, recipe};
use crate::output::Output;

/// Runs `f` on a fresh string.
fn words(f: impl FnOnce(&mut String)) -> Result<String, ReportError> {
    let mut w = String::new();
    f(&mut w);
    Ok(w)
}

/// The title, the reduced-budget warning, the claims' headline.
pub struct Header;
impl Section for Header {
    fn name(&self) -> &'static str {
        "header"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Budget]
    }
    fn render(&self, ctx: &Context<'_>, _: &mut Output) -> Result<String, ReportError> {
        words(|w| markdown::header(w, ctx))
    }
}

/// Campaigns, runs, compute, provenance and the table of conditions.
pub struct WhatWasRun;
impl Section for WhatWasRun {
    fn name(&self) -> &'static str {
        "what was run"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[
            CampaignRole::Budget,
            CampaignRole::Compare,
            CampaignRole::Recipe,
        ]
    }
    fn render(&self, ctx: &Context<'_>, _: &mut Output) -> Result<String, ReportError> {
        words(|w| markdown::what_was_run(w, ctx))
    }
}

/// KL-coverage and cell coverage during exploration (the paper's Figure 2).
pub struct KlcCurves;
impl Section for KlcCurves {
    fn name(&self) -> &'static str {
        "KL-coverage curves"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Compare]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let dir = out.figures_dir();
        let klc = out.figures(figures::klc_curves::draw_all(ctx.curve_conditions, &dir)?)?;
        let coverage = out.figures(figures::klc_curves::draw_metric(
            ctx.curve_conditions,
            &dir,
            figures::klc_curves::Metric::Coverage,
        )?)?;
        words(|w| markdown::klc_curves(w, ctx, &klc, &coverage))
    }
}

/// Final KL-coverage against the paper's values.
pub struct FinalTable;
impl Section for FinalTable {
    fn name(&self) -> &'static str {
        "final KL-coverage"
    }
    fn render(&self, ctx: &Context<'_>, _: &mut Output) -> Result<String, ReportError> {
        words(|w| markdown::final_table(w, ctx))
    }
}

/// The paper's claims and their verdicts.
pub struct Claims;
impl Section for Claims {
    fn name(&self) -> &'static str {
        "claims"
    }
    /// Our claims compare learners with their untrained twins (a `recipe` campaign).
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Recipe]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        if let crate::claims::ClaimsInput::Evaluated { results, .. } = ctx.claims {
            crate::data::claims::write_csv(out, results)?;
        }
        words(|w| claims::claims(w, ctx))
    }
}

/// The findings, generated from the claims, the validity check and the budget campaigns.
pub struct Findings;
impl Section for Findings {
    fn name(&self) -> &'static str {
        "findings"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[
            CampaignRole::Budget,
            CampaignRole::Compare,
            CampaignRole::Recipe,
        ]
    }
    fn render(&self, ctx: &Context<'_>, _: &mut Output) -> Result<String, ReportError> {
        words(|w| markdown::findings::findings(w, ctx))
    }
}

/// The leaderboard of the main and `compare` campaigns.
pub struct Leaderboard;
impl Section for Leaderboard {
    fn name(&self) -> &'static str {
        "leaderboard"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Compare]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        if !ctx.leaderboard.entries.is_empty() {
            crate::data::leaderboard::write_csv(out, ctx.leaderboard)?;
        }
        words(|w| claims::leaderboard(w, ctx))
    }
}

/// KDE vs Gaussian goals (the paper's Figure 4, and the same for RGE-RFVAE).
pub struct Figure4;
impl Section for Figure4 {
    fn name(&self) -> &'static str {
        "figure 4"
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let dir = out.figures_dir();
        let mut figs = Vec::new();
        for (algo, name) in crate::names::SAMPLER_FIGURES {
            let fig = figures::sampler_compare::draw(ctx.conditions, &algo, name, &dir)?;
            figs.extend(out.figure(fig)?);
        }
        words(|w| neural::figure4(w, ctx, &figs))
    }
}

/// Faithful vs corrected variants.
pub struct Variants;
impl Section for Variants {
    fn name(&self) -> &'static str {
        "variants"
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let fig = out.figure(figures::variants::draw(
            ctx.variant_pairs,
            &out.figures_dir(),
        )?)?;
        words(|w| neural::variants(w, ctx, fig.as_ref()))
    }
}

/// Training-budget sensitivity (`budget` campaigns).
pub struct Budget;
impl Section for Budget {
    fn name(&self) -> &'static str {
        "training budget"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Budget]
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let figs = figures::budget::draw_all(
            &ctx.budget.series,
            &ctx.opts.main_campaign,
            &out.figures_dir(),
        )?;
        let figs = out.figures(figs)?;
        words(|w| neural::budget(w, ctx, &figs))
    }
}

/// The neural learners' training losses.
pub struct TrainingLoss;
impl Section for TrainingLoss {
    fn name(&self) -> &'static str {
        "training losses"
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let fig = out.figure(figures::training_loss::draw(
            ctx.losses,
            &out.figures_dir(),
        )?)?;
        words(|w| neural::training_loss(w, fig.as_ref()))
    }
}

/// Latent quality, goal-space lattices and reconstructions.
pub struct Quality;
impl Section for Quality {
    fn name(&self) -> &'static str {
        "latent quality"
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let main = &ctx.campaigns.main.path;
        let samples = figures::goal_space::load(main)?;
        let (mesh, recon) = figures::goal_space::draw_all(&samples, main, &out.figures_dir())?;
        let (mesh, recon) = (out.figures(mesh)?, out.figures(recon)?);
        words(|w| quality::section(w, ctx, &mesh, &recon))
    }
}

/// Training recipes (`recipe` campaigns, paired with the main campaign's runs).
pub struct Recipes;
impl Section for Recipes {
    fn name(&self) -> &'static str {
        "training recipes"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Recipe]
    }
    fn render(&self, ctx: &Context<'_>, _: &mut Output) -> Result<String, ReportError> {
        words(|w| recipe::section(w, ctx))
    }
}

/// Object positions reached (the paper's Figure 3).
pub struct Outcomes;
impl Section for Outcomes {
    fn name(&self) -> &'static str {
        "outcome scatters"
    }
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let figs = figures::outcomes::draw_all(ctx.store, ctx.conditions, &out.figures_dir())?;
        let figs = out.figures(figs)?;
        // REPORT.md keeps the conditions of the paper's Figures 3, 8 and 9 (ArmBall, the
        // paper's variants with KDE goals: those the paper gives a value for); the others are
        // on a page of their own.
        let in_paper: Vec<String> = ctx
            .conditions
            .iter()
            .filter(|c| {
                c.key.env == ugl_types::ARMBALL.name
                    && c.paper.is_some()
                    && c.key.sampler != ugl_types::Sampler::GAUSSIAN
            })
            .map(|c| format!("figures/outcomes_{}.svg", figures::file_safe(&c.key.slug())))
            .collect();
        let (paper, rest): (Vec<_>, Vec<_>) =
            figs.into_iter().partition(|f| in_paper.contains(&f.link));
        if !rest.is_empty() {
            let mut page = String::new();
            markdown::other_outcome_scatters(&mut page, ctx, &rest);
            out.write(markdown::OUTCOMES_PAGE, page.as_bytes())?;
        }
        words(|w| markdown::outcome_scatters(w, ctx, &paper, rest.len()))
    }
}

/// The paper's illustrations that need no results (Figures 1, 5 and 6).
pub struct Illustrations;
impl Section for Illustrations {
    fn name(&self) -> &'static str {
        "illustrations"
    }
    fn render(&self, _: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let dir = out.figures_dir();
        // Room for all three, so the build without the environment figures pushes fewer.
        let mut figs = Vec::with_capacity(3);
        #[cfg(feature = "environment-figures")]
        figs.push(figures::environment::draw_environments(&dir)?);
        figs.push(figures::radial_flow::draw(&dir)?);
        #[cfg(feature = "environment-figures")]
        figs.extend(figures::environment::draw_dmp_episode(&dir)?);
        let figs = out.figures(figs)?;
        words(|w| markdown::illustrations(w, &figs))
    }
}

/// Deviations from the paper and notes on the data.
pub struct Deviations;
impl Section for Deviations {
    fn name(&self) -> &'static str {
        "deviations"
    }
    fn render(&self, ctx: &Context<'_>, _: &mut Output) -> Result<String, ReportError> {
        words(|w| markdown::deviations(w, ctx))
    }
}

/// How to regenerate every campaign the report used.
pub struct Reproduce;
impl Section for Reproduce {
    fn name(&self) -> &'static str {
        "how to reproduce"
    }
    fn wants(&self) -> &'static [CampaignRole] {
        &[CampaignRole::Budget, CampaignRole::Compare]
    }
    fn render(&self, ctx: &Context<'_>, _: &mut Output) -> Result<String, ReportError> {
        words(|w| markdown::reproduce(w, ctx))
    }
}
