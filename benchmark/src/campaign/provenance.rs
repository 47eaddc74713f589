//! Where a run's code came from, as recorded in its manifest.

use std::sync::OnceLock;

use ugl_types::RESULTS_VERSION;

/// `git rev-parse HEAD` of the working directory, with `-dirty` if there are uncommitted
/// changes; `unknown` outside a repository.
pub fn git_revision() -> &'static str {
    static REV: OnceLock<String> = OnceLock::new();
    REV.get_or_init(|| {
        let run = |args: &[&str]| {
            std::process::Command::new("git")
                .args(args)
                .output()
                .ok()
                .filter(|o| o.status.success())
                .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        };
        match run(&["rev-parse", "HEAD"]) {
            Some(rev) => {
                let dirty = run(&["status", "--porcelain", "--untracked-files=no"])
                    .is_some_and(|s| !s.is_empty());
                if dirty { format!("{rev}-dirty") } else { rev }
            }
            None => "unknown".into(),
        }
    })
}

/// The crate versions and results version of this code, as a manifest records them.
pub fn crate_versions() -> serde_json::Value {
    serde_json::json!({
        "ugl-bench": env!("CARGO_PKG_VERSION"),
        "results_version": RESULTS_VERSION,
    })
}
