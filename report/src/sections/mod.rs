//! The report as a list of sections (criterion's `Report` / `Reports` pattern): each
//! [`Section`] declares the campaign roles it reads, draws its figures and writes its pages
//! through the one [`Output`], and returns its part of `REPORT.md`. [`SECTIONS`] is the list, in
//! the order of `REPORT.md`; [`crate::render::render_report`] computes the shared statistics once
//! ([`Context`]) and fans out over it.
//!
//! Adding a section: one type implementing [`Section`] and one entry in [`SECTIONS`].

mod discovery;
mod followup;
mod pages;
mod paper;

use std::collections::BTreeSet;

use ugl_types::CampaignRole;

pub use crate::context::Context;
use crate::error::ReportError;
use crate::output::Output;

/// One part of the report.
pub trait Section: Sync {
    /// A short name, for logs and errors.
    fn name(&self) -> &'static str;

    /// The roles of the campaigns it reads besides the main campaign's (which every report
    /// has); a campaign whose role no section wants is listed as unused and never read.
    fn wants(&self) -> &'static [CampaignRole] {
        &[]
    }

    /// Draws its figures and writes its own pages through `out`, and returns its part of
    /// `REPORT.md` (default: nothing).
    fn render(&self, ctx: &Context<'_>, out: &mut Output) -> Result<String, ReportError> {
        let _ = (ctx, out);
        Ok(String::new())
    }
}

/// The report's sections, in the order of `REPORT.md`.
pub static SECTIONS: &[&dyn Section] = &[
    &paper::Header,
    &paper::Findings,
    &paper::WhatWasRun,
    &paper::Claims,
    &discovery::Discovery,
    &discovery::Predicts,
    &paper::Leaderboard,
    &paper::KlcCurves,
    &paper::FinalTable,
    &paper::Figure4,
    &paper::Variants,
    &paper::Budget,
    &paper::TrainingLoss,
    &paper::Quality,
    &paper::Recipes,
    &paper::Outcomes,
    &paper::Illustrations,
    &paper::Deviations,
    &paper::Reproduce,
    &followup::Followup,
    &pages::ComparePages,
    &pages::DataFiles,
];

/// The campaign roles some section reads (the main campaign's always).
pub fn wanted_roles(sections: &[&dyn Section]) -> BTreeSet<CampaignRole> {
    sections
        .iter()
        .flat_map(|s| s.wants().iter().copied())
        .chain([CampaignRole::Main])
        .collect()
}

/// Every section in turn: their parts of `REPORT.md`, concatenated.
pub fn render(
    sections: &[&dyn Section],
    ctx: &Context<'_>,
    out: &mut Output,
) -> Result<String, ReportError> {
    let mut md = String::new();
    for s in sections {
        tracing::debug!(section = s.name(), "rendering");
        md.push_str(&s.render(ctx, out)?);
    }
    Ok(md)
}
