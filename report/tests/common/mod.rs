//! What the report tests' synthetic stores share: complete manifests and campaign records, as
//! `ugl campaign` writes them.

#![allow(dead_code)]

use std::path::Path;

use serde_json::{Value, json};
use ugl_types::{CampaignDecl, CampaignRecord, CampaignRole};

/// Fills the fields of a version-3 manifest that a fixture leaves out (the report reads
/// manifests through the runner's type, which requires them), from those it gives.
pub fn complete_manifest(m: &mut Value, dir: &Path) {
    let o = m.as_object_mut().expect("a manifest is an object");
    let s = |o: &serde_json::Map<String, Value>, k: &str, d: &str| {
        o.get(k).and_then(Value::as_str).unwrap_or(d).to_string()
    };
    let (env, algo) = (s(o, "env", "armball"), s(o, "algo", "rpe"));
    let seed = o.get("seed").and_then(Value::as_u64).unwrap_or(0);
    let run_id = s(o, "run_id", &format!("{env}.{algo}.s{seed}"));
    let campaign = dir
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let defaults = json!({
        "run_id": run_id, "identity": format!("env={env}/algo={algo}/seed={seed}"),
        "env": env, "algo": algo, "sampler": "none", "seed": seed, "run_seed": 0,
        "campaign": campaign, "campaign_seed": 0, "profile": "test", "config_hash": "",
        "explore": {}, "env_config": {}, "reduced_budget": false, "budget_note": "",
        "git_revision": "", "crate_versions": {"results_version": 3}, "toolchain": "",
        "threads": 1, "wall_s": 0.0, "host": "",
        "summary": {"run": run_id, "final_klc": 0.0, "n_moved": 0, "coverage": 0.0},
    });
    for (k, v) in defaults.as_object().unwrap() {
        if o.get(k).is_none_or(Value::is_null) {
            o.insert(k.clone(), v.clone());
        }
    }
}

/// Writes the campaign record of `dir` as `ugl campaign` would: `role`, varying `variant_of`.
pub fn write_record(dir: &Path, role: CampaignRole, variant_of: Option<&str>) {
    std::fs::create_dir_all(dir).unwrap();
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    let decl = CampaignDecl {
        role,
        variant_of: variant_of.map(str::to_string),
        ..CampaignDecl::default()
    };
    std::fs::write(
        CampaignRecord::path(dir),
        CampaignRecord::new(&name, &decl).to_text(),
    )
    .unwrap();
}

/// The record the fixtures' campaigns declare, by their (conventional) names: `budget-*`,
/// `compare-*` and `paper-*` vary `paper`; anything else stands on its own.
pub fn write_conventional_record(dir: &Path) {
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    let (role, of) = if name.starts_with("budget-") {
        (CampaignRole::Budget, Some("paper"))
    } else if name.starts_with("compare-") {
        (CampaignRole::Compare, Some("paper"))
    } else if name.starts_with("paper-") {
        (CampaignRole::Recipe, Some("paper"))
    } else {
        (CampaignRole::Main, None)
    };
    write_record(dir, role, of);
}
