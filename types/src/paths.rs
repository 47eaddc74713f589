//! The files of a run in a results directory, and the one check of its data files against the
//! lengths and BLAKE3 hashes its manifest records (used on resume, merge and report).

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::manifest::Manifest;

/// `<run_id>.parquet`: the exploration curve.
pub const CURVE_SUFFIX: &str = ".parquet";
/// `<run_id>.outcomes.parquet`: every outcome.
pub const OUTCOMES_SUFFIX: &str = ".outcomes.parquet";
/// `<run_id>.interest.parquet`: modular exploration's interest per module (only those runs).
pub const INTEREST_SUFFIX: &str = ".interest.parquet";
/// `<run_id>.json`: the manifest, written last (a run is complete when it exists).
pub const MANIFEST_SUFFIX: &str = ".json";

/// The files of a run in a results directory.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunPaths {
    /// `<run_id>.parquet`: the exploration curve.
    pub curve: PathBuf,
    /// `<run_id>.outcomes.parquet`: every outcome.
    pub outcomes: PathBuf,
    /// `<run_id>.interest.parquet`: modular exploration's interest per module (only those runs).
    pub interest: PathBuf,
    /// `<run_id>.json`: the manifest, written last (a run is complete when it exists).
    pub manifest: PathBuf,
}

impl RunPaths {
    /// The data files present, in the order they are written (the manifest comes after them):
    /// the curve, the outcomes and, for a modular exploration, the interest.
    pub fn data(&self) -> Vec<&Path> {
        let mut v = vec![self.curve.as_path(), self.outcomes.as_path()];
        if self.interest.is_file() {
            v.push(&self.interest);
        }
        v
    }
}

/// Paths of a run's files in a results directory.
pub fn run_paths(dir: &Path, run_id: &str) -> RunPaths {
    RunPaths {
        curve: dir.join(format!("{run_id}{CURVE_SUFFIX}")),
        outcomes: dir.join(format!("{run_id}{OUTCOMES_SUFFIX}")),
        interest: dir.join(format!("{run_id}{INTEREST_SUFFIX}")),
        manifest: dir.join(format!("{run_id}{MANIFEST_SUFFIX}")),
    }
}

/// How a run's data files differ from what its manifest records.
#[derive(Debug, Error)]
pub enum DigestError {
    #[error("{} is missing", path.display())]
    Missing { path: PathBuf },
    #[error("cannot read {}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{} has {actual} bytes, its manifest records {recorded} (truncated or replaced)", path.display())]
    Length {
        path: PathBuf,
        actual: u64,
        recorded: u64,
    },
    #[error("{} does not match the BLAKE3 hash its manifest records (damaged)", path.display())]
    Hash { path: PathBuf },
    /// The manifest's discovery record (`path` is the manifest) does not match the hash beside
    /// it, or is not what the run measured ([`crate::RunDiscovery::check`]).
    #[error("{}: {why}", path.display())]
    Discovery { path: PathBuf, why: String },
}

impl DigestError {
    /// The file that differs.
    pub fn path(&self) -> &Path {
        match self {
            DigestError::Missing { path }
            | DigestError::Io { path, .. }
            | DigestError::Length { path, .. }
            | DigestError::Hash { path }
            | DigestError::Discovery { path, .. } => path,
        }
    }
}

/// Checks the data files of a run in `dir` against its manifest: each must exist with the
/// recorded length and hash. Manifests without digests (written before results version 3)
/// pass if the curve and outcome files exist. The outcomes file may be absent when the
/// manifest records the run's discovery measures ([`Manifest::discovery`]: nothing else is
/// read from it); present, it must still match.
pub fn verify_files(dir: &Path, manifest: &Manifest) -> Result<(), DigestError> {
    let Some(files) = &manifest.files else {
        let paths = run_paths(dir, &manifest.run_id);
        return match paths.data().into_iter().find(|p| !p.is_file()) {
            Some(p) => Err(DigestError::Missing {
                path: p.to_path_buf(),
            }),
            None => Ok(()),
        };
    };
    for f in files {
        let path = dir.join(&f.name);
        if manifest.discovery.is_some() && f.name.ends_with(OUTCOMES_SUFFIX) && !path.exists() {
            continue;
        }
        let bytes = std::fs::read(&path).map_err(|source| match source.kind() {
            std::io::ErrorKind::NotFound => DigestError::Missing { path: path.clone() },
            _ => DigestError::Io {
                path: path.clone(),
                source,
            },
        })?;
        if bytes.len() as u64 != f.bytes {
            return Err(DigestError::Length {
                path,
                actual: bytes.len() as u64,
                recorded: f.bytes,
            });
        }
        if blake3::hash(&bytes).to_hex().as_str() != f.blake3 {
            return Err(DigestError::Hash { path });
        }
    }
    verify_discovery(dir, manifest)
}

/// The manifest's discovery record against the hash recorded beside it, and against itself and
/// the run's summary ([`crate::RunDiscovery::check`]).
fn verify_discovery(dir: &Path, manifest: &Manifest) -> Result<(), DigestError> {
    let Some(d) = &manifest.discovery else {
        return Ok(());
    };
    let path = || run_paths(dir, &manifest.run_id).manifest;
    if let Some(h) = &manifest.discovery_blake3
        && d.digest() != *h
    {
        return Err(DigestError::Discovery {
            path: path(),
            why: "its discovery record does not match the BLAKE3 hash recorded beside it (edited)"
                .into(),
        });
    }
    d.check(&manifest.env, &manifest.summary)
        .map_err(|e| DigestError::Discovery {
            path: path(),
            why: e.to_string(),
        })
}
