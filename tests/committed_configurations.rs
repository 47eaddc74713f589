//! A change of code that must not change results keeps every committed campaign's configuration:
//! for each campaign of the code's results version in `data/results/` or `data/results-pending/`
//! (a rerun under way, committed in chunks) with its profile in `data/campaigns/`, the profile's
//! configuration hash is the one its record holds, and, in `data/results/`, `ugl status` finds
//! every run complete (each run's own configuration hash, with its learner's parameters, is the
//! one it was run with). A campaign of an older results version is stale by design until it is
//! rerun, and its profile may change for the rerun (results version 5 added the plateau rule).

use std::path::Path;
use std::process::Command;

use ugl_bench::campaign::config::CampaignConfig;
use ugl_types::{CampaignRecord, Manifest, RESULTS_VERSION};

/// The results version of a campaign's runs (the first manifest's), if it has any.
fn results_version(dir: &Path) -> Option<u64> {
    let manifest = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .min()?;
    let m: Manifest = serde_json::from_str(&std::fs::read_to_string(manifest).unwrap()).unwrap();
    m.results_version()
}

#[test]
fn the_committed_campaigns_keep_their_configuration() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut checked = Vec::new();
    let mut hashed = Vec::new();
    let mut stale = Vec::new();
    let mut dirs = Vec::new();
    for place in ["data/results", "data/results-pending"] {
        let Ok(entries) = std::fs::read_dir(root.join(place)) else {
            continue;
        };
        dirs.extend(
            entries
                .map(|e| e.unwrap().path())
                .filter(|p| p.is_dir())
                .map(|p| (place == "data/results", p)),
        );
    }
    dirs.sort();
    for (complete, dir) in dirs {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let profile = root.join("data/campaigns").join(format!("{name}.toml"));
        if !profile.is_file() {
            continue;
        }
        if results_version(&dir) != Some(u64::from(RESULTS_VERSION)) {
            stale.push(name);
            continue;
        }
        let record = CampaignRecord::read(&dir)
            .unwrap()
            .expect("a campaign record");
        let cfg = CampaignConfig::load(&profile).unwrap();
        let Some(recorded) = record.configuration.as_deref() else {
            continue;
        };
        assert_eq!(
            recorded,
            cfg.configuration_hash().as_str(),
            "{name}: the profile's configuration hash is not the record's"
        );
        hashed.push(name.clone());
        if !complete {
            continue;
        }
        let o = Command::new(env!("CARGO_BIN_EXE_ugl"))
            .args(["status", "--require-complete", "--config"])
            .arg(&profile)
            .arg("--out")
            .arg(&dir)
            .current_dir(root)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{name}: {}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        checked.push(name);
    }
    assert!(
        hashed.len() + stale.len() >= 6 && hashed.iter().chain(&stale).any(|n| n == "paper"),
        "hashes checked {hashed:?}, complete {checked:?}, stale {stale:?}"
    );
}
