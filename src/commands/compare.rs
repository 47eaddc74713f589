//! `ugl learners` and `ugl compare`: the registry, and a new learner on the paper's cells.

use std::path::{Path, PathBuf};

use anyhow::Result;

use ugl_bench::campaign::config::CampaignConfig;
use ugl_bench::campaign::single::{self};
use ugl_bench::explore::Learner;

use crate::cli::CompareArgs;
use crate::commands::campaign::{RunOptions, refresh_config, run_config};
use crate::output::outln;

/// `ugl learners`: the registry as a table.
pub(crate) fn learners() -> Result<()> {
    outln!(
        "{:<22} {:<26} {:<9} {:<9} {:<6} description",
        "name",
        "algorithm",
        "variants",
        "prior",
        "paper"
    )?;
    for l in Learner::all() {
        let e = l.entry();
        let prior = match e.prior {
            ugl_bench::repr::registry::Prior::None => "no",
            ugl_bench::repr::registry::Prior::Always => "yes",
            ugl_bench::repr::registry::Prior::Declared => "declared",
        };
        outln!(
            "{:<22} {:<26} {:<9} {:<9} {:<6} {}",
            e.name,
            e.algo,
            if e.has_variants { "yes" } else { "no" },
            prior,
            if e.in_paper { "yes" } else { "no" },
            e.description
        )?;
    }
    Ok(())
}

/// `ugl compare`: the paper's matrix cells and seeds for one more learner.
pub(crate) fn compare(a: CompareArgs) -> Result<()> {
    let (cfg, base) = single::compare_campaign(
        CampaignConfig::load(&a.config)?,
        &a.learner,
        a.command.as_deref(),
        a.gaussian,
    )
    .map_err(anyhow::Error::msg)?;
    cfg.validate()
        .map_err(|m| anyhow::anyhow!("{}: {m}", a.config.display()))?;
    let out = a
        .out
        .unwrap_or_else(|| PathBuf::from("data/results").join(&cfg.campaign.name));
    if a.refresh_diagnostics {
        let profile = cfg.campaign.name.clone();
        return refresh_config(&cfg, &profile, Some(out), a.jobs, None, &a.cache);
    }
    run_config(
        &cfg,
        &cfg.campaign.name.clone(),
        RunOptions {
            out: Some(out.clone()),
            jobs: a.jobs,
            quiet: a.quiet,
            shard: None,
            allow_dirty: a.allow_dirty,
            cache: &a.cache,
        },
    )?;
    print_compare_page(&out, &cfg.campaign.name, &base)
}

/// After `ugl compare`: the new learner's one-page summary (what `ugl report` writes as
/// `compare_<campaign>.md`), computed by the report from the main and `compare` campaigns
/// without rendering the report.
pub(crate) fn print_compare_page(out: &Path, campaign: &str, main_campaign: &str) -> Result<()> {
    let results = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut opts = ugl_report::ReportOptions::new(results.to_path_buf(), PathBuf::new());
    opts.main_campaign = main_campaign.to_string();
    let page = match ugl_report::compare_page(&opts, campaign) {
        Ok(Some(text)) => Ok(text),
        Ok(None) => Err(format!(
            "the campaign `{campaign}` has no leaderboard entry"
        )),
        Err(e) => Err(e.to_string()),
    };
    match page {
        Ok(text) => outln!("{text}")?,
        Err(e) => eprintln!(
            "no summary page ({e}); `ugl report` ranks the learner once the main campaign \
             `{main_campaign}` is in {}",
            results.display()
        ),
    }
    Ok(())
}
