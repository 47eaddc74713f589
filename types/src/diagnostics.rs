//! Diagnostics measured after a run, kept beside it: a manifest is never rewritten once its run
//! is stored. `ugl campaign --refresh-diagnostics` writes a newer latent-quality measure to
//! `DIR/diagnostics/<run_id>.json`, with the revision of the code that measured it; the report
//! reads the manifest and, where there is one, the sidecar's measure in place of the manifest's.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::campaign::RecordError;

/// The directory of the sidecars in a campaign's results directory.
pub const DIAGNOSTICS_DIR: &str = "diagnostics";

/// Later diagnostics of one run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Diagnostics {
    pub run_id: String,
    /// `git rev-parse HEAD` of the code that measured them (the manifest keeps its run's).
    pub git_revision: String,
    /// The crate versions and results version of that code.
    pub crate_versions: serde_json::Value,
    /// The latent-quality measure, as a manifest's `latent_quality`.
    pub latent_quality: crate::quality::LatentQuality,
}

impl Diagnostics {
    /// The sidecar of `run_id` in the campaign directory `dir`.
    pub fn path(dir: &Path, run_id: &str) -> PathBuf {
        dir.join(DIAGNOSTICS_DIR).join(format!("{run_id}.json"))
    }

    /// The sidecar of `run_id`, `Ok(None)` where there is none.
    pub fn read(dir: &Path, run_id: &str) -> Result<Option<Diagnostics>, RecordError> {
        let path = Diagnostics::path(dir, run_id);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(source) => return Err(RecordError::Io { path, source }),
        };
        let d: Diagnostics = serde_json::from_str(&text).map_err(|e| RecordError::Parse {
            path: path.clone(),
            message: e.to_string(),
        })?;
        if d.run_id != run_id {
            return Err(RecordError::Parse {
                path,
                message: format!("holds the diagnostics of `{}`", d.run_id),
            });
        }
        Ok(Some(d))
    }

    /// The measure version it holds (1 when unversioned).
    pub fn measure_version(&self) -> u64 {
        u64::from(self.latent_quality.version)
    }
}
