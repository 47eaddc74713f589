//! Where a run's code came from, as recorded in its manifest.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use ugl_types::RESULTS_VERSION;

/// `git rev-parse HEAD` of the working directory, with `-dirty` if there are uncommitted
/// changes; `unknown` outside a repository.
pub fn git_revision() -> &'static str {
    static REV: OnceLock<String> = OnceLock::new();
    REV.get_or_init(|| revision_of(None))
}

/// The revision a run written into `out` records: that of the checkout holding `out` (its real
/// path: symlinks followed), so that results written into a checkout's `data/` name that
/// checkout's revision whatever the working directory; else the working directory's
/// ([`git_revision`]). Computed once per results directory (a campaign writes hundreds of runs
/// into one).
pub fn git_revision_for(out: &Path) -> String {
    static REVS: OnceLock<Mutex<HashMap<PathBuf, String>>> = OnceLock::new();
    let mut revs = REVS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    revs.entry(out.to_path_buf())
        .or_insert_with(|| match checkout_of(out) {
            Some(top) => revision_of(Some(&top)),
            None => git_revision().to_string(),
        })
        .clone()
}

/// The real path of `p` (relative to the working directory): its nearest existing ancestor with
/// every symlink resolved, then the components that do not exist yet.
pub fn real_path(p: &Path) -> PathBuf {
    let cwd = std::env::current_dir().unwrap_or_default();
    let abs = super::slurm::resolve(p, &cwd);
    let mut existing = abs.as_path();
    let mut rest = Vec::new();
    while !existing.exists() {
        match (existing.parent(), existing.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_os_string());
                existing = parent;
            }
            _ => return abs,
        }
    }
    let mut real = existing
        .canonicalize()
        .unwrap_or_else(|_| existing.to_path_buf());
    real.extend(rest.iter().rev());
    real
}

/// The top directory of the git checkout that holds `p` (its real path), if any.
pub fn checkout_of(p: &Path) -> Option<PathBuf> {
    let real = real_path(p);
    let dir = real.ancestors().find(|a| a.is_dir())?;
    git(Some(dir), &["rev-parse", "--show-toplevel"])
        .and_then(|t| PathBuf::from(t).canonicalize().ok())
}

/// HEAD of the checkout at `top` (the working directory's for None), `-dirty` if tracked files
/// have uncommitted changes; `unknown` outside a repository.
pub fn revision_of(top: Option<&Path>) -> String {
    match git(top, &["rev-parse", "HEAD"]) {
        Some(rev) => {
            let dirty = git(top, &["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty { format!("{rev}-dirty") } else { rev }
        }
        None => "unknown".into(),
    }
}

fn git(dir: Option<&Path>, args: &[&str]) -> Option<String> {
    let mut cmd = std::process::Command::new("git");
    if let Some(d) = dir {
        cmd.arg("-C").arg(d);
    }
    cmd.args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

/// The crate versions and results version of this code, as a manifest records them.
pub fn crate_versions() -> serde_json::Value {
    serde_json::json!({
        "ugl-bench": env!("CARGO_PKG_VERSION"),
        "results_version": RESULTS_VERSION,
    })
}
