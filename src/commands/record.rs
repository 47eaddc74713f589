//! A store's campaign record (`campaign.toml`, beside its runs) read back as the campaign it was
//! run with: for the commands that take `--out` or `--results` without `--config` (`ugl status`,
//! `ugl verify`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use ugl_bench::campaign::config::{CampaignConfig, resolve_profile};
use ugl_bench::campaign::single::compare_campaign;
use ugl_bench::campaign::store::read_manifest;
use ugl_bench::goals::SamplerKind;
use ugl_types::{CampaignRecord, CampaignRole};

/// The campaign a store was run with, and the profile it comes from: `--config`, or the
/// profile of the record's name; for a store of `ugl compare` (role `compare`, no `--config`),
/// the campaign `ugl compare` built on its base profile (`variant_of`), with the learner of its
/// name (`compare-NAME`), and an external program's command and whether it drew Gaussian goals
/// as its runs' manifests recorded them.
pub(crate) fn campaign_of(
    record: &CampaignRecord,
    results: &Path,
    profile: Option<&Path>,
) -> Result<(CampaignConfig, PathBuf)> {
    if let Some(p) = profile {
        return Ok((CampaignConfig::load(p)?, p.to_path_buf()));
    }
    if record.decl.role != CampaignRole::Compare {
        let path = resolve_profile(&record.name)?;
        return Ok((CampaignConfig::load(&path)?, path));
    }
    let base = record.decl.variant_of.as_deref().with_context(|| {
        format!(
            "{}: a compare campaign's record without the campaign it varies",
            results.display()
        )
    })?;
    let learner = record.name.strip_prefix("compare-").with_context(|| {
        format!(
            "{}: a compare campaign not named compare-<learner> ({}); pass its profile with \
             --config",
            results.display(),
            record.name
        )
    })?;
    let mut command = None;
    let mut gaussian = false;
    let entries =
        std::fs::read_dir(results).with_context(|| format!("cannot read {}", results.display()))?;
    for e in entries {
        let file = e
            .with_context(|| format!("cannot read {}", results.display()))?
            .path();
        if file.extension().is_none_or(|x| x != "json") {
            continue;
        }
        let m = read_manifest(&file)?;
        if command.is_none() {
            command = m.external_command().map(str::to_string);
        }
        gaussian |= m
            .sampler
            .parse::<SamplerKind>()
            .is_ok_and(SamplerKind::needs_prior);
    }
    let path = resolve_profile(base)?;
    let (cfg, _) = compare_campaign(
        CampaignConfig::load(&path)?,
        learner,
        command.as_deref(),
        gaussian,
    )
    .map_err(anyhow::Error::msg)?;
    Ok((cfg, path))
}

/// The campaign a store's record (campaign.toml) names, as [`campaign_of`] rebuilds it without
/// `--config` (`ugl status --out DIR`).
pub(crate) fn recorded_campaign(results: &Path) -> Result<CampaignConfig> {
    let record = read_record(results, "--out", "; pass --config")?;
    Ok(campaign_of(&record, results, None)?.0)
}

/// The record (campaign.toml) of the results directory given by `flag`; an error, ending with
/// `hint`, where there is none.
pub(crate) fn read_record(results: &Path, flag: &str, hint: &str) -> Result<CampaignRecord> {
    CampaignRecord::read(results)
        .with_context(|| format!("{flag} {}", results.display()))?
        .with_context(|| {
            format!(
                "{flag} {}: no campaign.toml (not a campaign's results directory){hint}",
                results.display()
            )
        })
}
