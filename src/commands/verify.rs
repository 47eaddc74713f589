//! `ugl verify`: rerun a sample of a store's runs from their campaign profile and compare bytes.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use ugl_bench::campaign::plan::{RunSpec, plan};
use ugl_bench::campaign::store::read_manifest;
use ugl_bench::campaign::{Harness, RunContext};
use ugl_types::{CampaignRole, Manifest, RESULTS_VERSION, verify_files};

use super::record::{campaign_of, read_record};

use crate::output::outln;
use crate::progress::{learner_lines, progress_area, stop_on_ctrl_c, training_bars};

/// One committed run chosen for a rerun.
struct Pick {
    spec: RunSpec,
    manifest: Manifest,
}

/// The iterations a run's network trained (0: not a trained network).
fn trained_iterations(m: &Manifest) -> u64 {
    m.train
        .as_ref()
        .and_then(|t| t.iterations)
        .map_or(0, |i| i as u64)
}

/// The condition of a run: its id with the repetition and replicate set to 0.
fn condition(spec: &RunSpec) -> String {
    RunSpec {
        seed: 0,
        exploration: 0,
        ..spec.clone()
    }
    .run_id()
}

/// Which conditions a sample may draw from.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Networks {
    /// Every condition, with a trained network among the picks where the store has one.
    Included,
    /// Only the conditions whose runs train no network (a cheap check of a store whose
    /// networks take long to retrain).
    Excluded,
}

/// `n` runs stratified over the conditions: conditions evenly spaced in their sorted order, one
/// run each (the repetition and replicate from a hash of the condition, so the same runs every
/// time); with networks included, if none of them is a trained network and `n >= 2`, the last
/// is replaced by the trained network with the fewest iterations (the cheapest to retrain).
fn sample(runs: Vec<Pick>, n: usize, networks: Networks) -> Vec<Pick> {
    let mut by_condition: BTreeMap<String, Vec<Pick>> = BTreeMap::new();
    for p in runs {
        by_condition.entry(condition(&p.spec)).or_default().push(p);
    }
    let trained = |g: &Vec<Pick>| g.iter().map(|p| trained_iterations(&p.manifest)).max();
    let mut groups: Vec<Vec<Pick>> = by_condition
        .into_values()
        .filter(|g| networks == Networks::Included || trained(g) == Some(0))
        .collect();
    let n = n.min(groups.len());
    let mut chosen: Vec<usize> = (0..n).map(|i| i * groups.len() / n).collect();
    if networks == Networks::Included
        && n >= 2
        && !chosen.iter().any(|&i| trained(&groups[i]).unwrap_or(0) > 0)
    {
        let cheapest = (0..groups.len())
            .filter_map(|i| trained(&groups[i]).filter(|&it| it > 0).map(|it| (it, i)))
            .min();
        if let Some((_, i)) = cheapest {
            chosen[n - 1] = i;
        }
    }
    chosen.sort_unstable();
    chosen.dedup();
    chosen
        .into_iter()
        .map(|i| {
            let mut g = std::mem::take(&mut groups[i]);
            g.sort_by_key(|p| (p.spec.seed, p.spec.exploration));
            let hash = blake3::hash(condition(&g[0].spec).as_bytes());
            let k = u64::from_le_bytes(hash.as_bytes()[..8].try_into().expect("8 bytes"));
            g.swap_remove((k % g.len() as u64) as usize)
        })
        .collect()
}

/// The differences between a committed run and its rerun (empty: the same bytes).
fn differences(committed: &Manifest, rerun: &Manifest) -> Vec<String> {
    let mut out = Vec::new();
    if committed.config_hash != rerun.config_hash {
        out.push("the configuration hash differs (the profile or the code changed)".into());
    }
    let files = |m: &Manifest| {
        m.files
            .iter()
            .flatten()
            .map(|f| (f.name.clone(), f.blake3.clone()))
            .collect::<BTreeMap<_, _>>()
    };
    let (a, b) = (files(committed), files(rerun));
    for (name, hash) in &a {
        match b.get(name) {
            Some(h) if h == hash => {}
            Some(h) => out.push(format!("{name}: BLAKE3 {hash} committed, {h} rerun")),
            None => out.push(format!("{name}: not written by the rerun")),
        }
    }
    for name in b.keys().filter(|n| !a.contains_key(*n)) {
        out.push(format!(
            "{name}: written by the rerun, not in the committed manifest"
        ));
    }
    if committed.discovery_blake3 != rerun.discovery_blake3 {
        out.push("the discovery record differs".into());
    }
    if serde_json::to_value(&committed.summary).ok() != serde_json::to_value(&rerun.summary).ok() {
        out.push("the summary differs".into());
    }
    out
}

pub(crate) fn verify(
    results: &Path,
    profile: Option<&Path>,
    n: usize,
    networks: Networks,
) -> Result<()> {
    if n == 0 {
        bail!("--sample must be at least 1");
    }
    let record = read_record(results, "--results", "")?;
    let (cfg, path) = campaign_of(&record, results, profile)?;
    let hash = cfg.configuration_hash();
    if record.configuration.as_deref() != Some(hash.as_str()) {
        bail!(
            "{}: its configuration hash is not the one {} was run with; pass the campaign's \
             profile with --config",
            path.display(),
            results.display()
        );
    }
    // Every committed run's files against its manifest, and the runs of this results version.
    let mut runs = Vec::new();
    let mut older = 0;
    for spec in plan(&cfg) {
        let file = results.join(format!("{}.json", spec.run_id()));
        if !file.is_file() {
            continue;
        }
        let manifest = read_manifest(&file)?;
        verify_files(results, &manifest)
            .with_context(|| format!("{}: the committed files", spec.run_id()))?;
        if manifest.results_version() == Some(u64::from(RESULTS_VERSION)) {
            runs.push(Pick { spec, manifest });
        } else {
            older += 1;
        }
    }
    let checked = runs.len() + older;
    if checked == 0 {
        bail!(
            "{}: no run of the plan of {} is in it",
            results.display(),
            path.display()
        );
    }
    if runs.is_empty() {
        bail!(
            "{}: none of its {checked} runs is of this code's results version ({RESULTS_VERSION}): \
             they cannot be reproduced by it",
            results.display()
        );
    }
    let of_version = runs.len();
    let picks = sample(runs, n, networks);
    if picks.is_empty() {
        bail!(
            "{}: every condition of its {of_version} runs of version {RESULTS_VERSION} trains a \
             network, and --without-networks leaves none to rerun",
            results.display()
        );
    }
    outln!(
        "{}: {checked} runs match their recorded digests ({older} of an older results version); \
         rerunning {} of the {of_version} of version {RESULTS_VERSION} (at most one per condition)",
        results.display(),
        picks.len(),
    )?;
    let scratch = Scratch(std::env::temp_dir().join(format!("ugl-verify-{}", std::process::id())));
    // What `ugl campaign` and `ugl compare` record as the profile.
    let profile_name = match record.decl.role {
        CampaignRole::Compare if profile.is_none() => cfg.campaign.name.clone(),
        _ => path.display().to_string(),
    };
    let stop = stop_on_ctrl_c("the rerun in flight")?;
    let mp = progress_area();
    let ctx = RunContext::new(
        &cfg,
        rayon::current_num_threads(),
        Harness {
            profile: &profile_name,
            train_progress: Some(training_bars(&mp, None)),
            learner_messages: Some(learner_lines(&mp, None)),
            ..Harness::default()
        },
    );
    let mut failed = 0;
    let mut done = 0;
    for p in &picks {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        done += 1;
        let dir = scratch.0.join(p.spec.run_id());
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create {}", dir.display()))?;
        let t0 = Instant::now();
        ugl_bench::campaign::execute(&p.spec, &ctx, &dir, None)?;
        let rerun = read_manifest(&dir.join(format!("{}.json", p.spec.run_id())))?;
        let diff = differences(&p.manifest, &rerun);
        let files = rerun.files.as_ref().map_or(0, Vec::len);
        if diff.is_empty() {
            outln!(
                "same bytes  {}  ({files} files, {:.0} s)",
                p.spec.run_id(),
                t0.elapsed().as_secs_f64()
            )?;
        } else {
            failed += 1;
            outln!("DIFFERENT   {}", p.spec.run_id())?;
            for d in diff {
                outln!("    {d}")?;
            }
        }
        // Best effort: a scratch copy left behind is harmless.
        let _ = std::fs::remove_dir_all(&dir);
    }
    if failed > 0 {
        bail!("{failed} of {done} rerun runs differ from the committed ones");
    }
    if done < picks.len() {
        bail!(
            "interrupted: {done} of the {} sampled runs rerun, all with the same bytes",
            picks.len()
        );
    }
    Ok(())
}

/// The scratch directory of the reruns, removed however `verify` ends (an error, an interrupt)
/// but a second Ctrl-C, which exits at once.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        // Best effort: a scratch copy left behind is harmless.
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
