//! How far a campaign's results directory is (`ugl status`): for every planned run, whether it is
//! complete (its manifest matches this configuration and its data files match the manifest),
//! missing, damaged, or stored with another configuration; per shard when the campaign is split
//! ([`super::plan::shard`]). It reads the store the way a resumed campaign does
//! ([`super::store::is_complete`]), so "complete" here is what a campaign would skip.

use std::collections::BTreeSet;
use std::path::Path;

use super::config::CampaignConfig;
use super::context::{Harness, RunContext};
use super::plan::{plan, shard_groups};
use super::store::{StoreError, read_manifest, run_paths, verify_files};
use ugl_types::MANIFEST_SUFFIX;

/// The state of one planned run in a results directory.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RunState {
    /// What a resumed campaign would skip.
    Complete,
    /// No manifest (the run never finished; its data files, if any, are left-overs).
    Missing,
    /// A manifest that does not parse, or data files that do not match it (the reason).
    Damaged(String),
    /// A manifest of another configuration (another results version, seed or constant).
    OtherConfiguration,
}

impl RunState {
    /// Whether a resumed campaign would compute the run again.
    pub fn is_complete(&self) -> bool {
        matches!(self, RunState::Complete)
    }
}

/// One planned run: its id, its shard and its state.
#[derive(Clone, Debug)]
pub struct RunStatus {
    pub run_id: String,
    pub shard: usize,
    pub state: RunState,
}

/// The state of a campaign's results directory.
#[derive(Clone, Debug)]
pub struct StoreStatus {
    /// Every planned run, in plan order.
    pub runs: Vec<RunStatus>,
    /// The shard count the runs were dealt into (1: unsharded).
    pub shards: usize,
    /// Manifests in the directory that are no run of this campaign's plan.
    pub unplanned: Vec<String>,
}

/// Counts of the four states.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub total: usize,
    pub complete: usize,
    pub missing: usize,
    pub damaged: usize,
    pub other_configuration: usize,
}

impl Counts {
    fn add(&mut self, s: &RunState) {
        self.total += 1;
        match s {
            RunState::Complete => self.complete += 1,
            RunState::Missing => self.missing += 1,
            RunState::Damaged(_) => self.damaged += 1,
            RunState::OtherConfiguration => self.other_configuration += 1,
        }
    }

    /// `12 runs: 10 complete, 1 missing, 1 damaged` (zero counts left out).
    pub fn describe(&self) -> String {
        let mut parts = vec![format!("{} complete", self.complete)];
        for (n, what) in [
            (self.missing, "missing"),
            (self.damaged, "damaged"),
            (self.other_configuration, "of another configuration"),
        ] {
            if n > 0 {
                parts.push(format!("{n} {what}"));
            }
        }
        format!("{} runs: {}", self.total, parts.join(", "))
    }
}

impl StoreStatus {
    /// Counts over every run.
    pub fn counts(&self) -> Counts {
        let mut c = Counts::default();
        self.runs.iter().for_each(|r| c.add(&r.state));
        c
    }

    /// Counts of shard `index`.
    pub fn shard_counts(&self, index: usize) -> Counts {
        let mut c = Counts::default();
        self.runs
            .iter()
            .filter(|r| r.shard == index)
            .for_each(|r| c.add(&r.state));
        c
    }

    /// Whether every planned run is complete.
    pub fn is_complete(&self) -> bool {
        self.runs.iter().all(|r| r.state.is_complete())
    }
}

/// The state of `out` for campaign `cfg`, its runs dealt into `shards` shards (1: unsharded).
/// A directory that does not exist holds no run: every run is missing.
pub fn store_status(
    cfg: &CampaignConfig,
    out: &Path,
    shards: usize,
) -> Result<StoreStatus, StoreError> {
    let shards = shards.max(1);
    let runs = plan(cfg);
    let groups = shard_groups(&runs, cfg.ugl.images);
    let ctx = RunContext::new(cfg, 1, Harness::default());
    let mut planned = BTreeSet::new();
    let mut statuses = Vec::with_capacity(runs.len());
    for (spec, group) in runs.iter().zip(groups) {
        let run_id = spec.run_id();
        let manifest_path = run_paths(out, &run_id).manifest;
        let state = if !manifest_path.exists() {
            RunState::Missing
        } else {
            match read_manifest(&manifest_path) {
                Err(e) => RunState::Damaged(e.to_string()),
                Ok(m) if m.config_hash != ctx.config_hash(spec) => RunState::OtherConfiguration,
                Ok(m) => match verify_files(out, &m) {
                    Ok(()) => RunState::Complete,
                    Err(e) => RunState::Damaged(e.to_string()),
                },
            }
        };
        planned.insert(run_id.clone());
        statuses.push(RunStatus {
            run_id,
            shard: group % shards,
            state,
        });
    }
    let mut unplanned = Vec::new();
    if out.is_dir() {
        let entries = std::fs::read_dir(out).map_err(|e| StoreError::Read {
            path: out.to_path_buf(),
            message: e.to_string(),
        })?;
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if let Some(id) = name.strip_suffix(MANIFEST_SUFFIX)
                && !name.starts_with('.')
                && !id.is_empty()
                && !planned.contains(id)
                && entry.path().is_file()
            {
                unplanned.push(id.to_string());
            }
        }
    }
    unplanned.sort();
    Ok(StoreStatus {
        runs: statuses,
        shards,
        unplanned,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_describe_only_what_is_there() {
        let mut c = Counts::default();
        for s in [
            RunState::Complete,
            RunState::Complete,
            RunState::Missing,
            RunState::Damaged("x".into()),
        ] {
            c.add(&s);
        }
        assert_eq!(c.describe(), "4 runs: 2 complete, 1 missing, 1 damaged");
        assert_eq!(Counts::default().describe(), "0 runs: 0 complete");
    }
}
