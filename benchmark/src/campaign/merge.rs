//! Merging results stores (`ugl merge`): the shards of a campaign run on several machines
//! (`--shard i/n`, or `ugl slurm`) come back as separate directories and are merged into one.
//!
//! A run is copied data files first, manifest last (a run is complete when its manifest exists),
//! each file written atomically. A run already in the destination is left as it is when it is
//! the same run (same config hash, byte-identical data); anything else is refused, never
//! overwritten. A damaged or incomplete run in a source is refused with what is wrong with it.

use std::path::{Path, PathBuf};

use thiserror::Error;

use super::store::{self, StoreError};
use ugl_types::CampaignRecord;

/// Why a merge stopped.
#[derive(Debug, Error)]
pub enum MergeError {
    #[error("{0}: not a directory")]
    NotADirectory(PathBuf),
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{source_dir}: run {run_id} is incomplete or damaged ({why}); resume its campaign there to \
         recompute it, then merge again"
    )]
    Damaged {
        source_dir: PathBuf,
        run_id: String,
        why: store::DigestError,
    },
    #[error("run {run_id} exists in {into} with different {what}: refusing to overwrite")]
    Conflict {
        run_id: String,
        into: PathBuf,
        /// `config hash`, `data` or `goal-space sample`.
        what: &'static str,
    },
    #[error("{path}: {source}")]
    Future {
        path: PathBuf,
        source: ugl_types::FutureResults,
    },
    #[error(transparent)]
    Store(#[from] StoreError),
    #[error(transparent)]
    Record(#[from] ugl_types::RecordError),
    #[error(
        "{} and {} record different campaigns ({} / {}): refusing to merge them",
        source_dir.display(), into.display(), theirs, ours
    )]
    RecordConflict {
        source_dir: PathBuf,
        into: PathBuf,
        theirs: String,
        ours: String,
    },
}

/// What a merge did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MergeSummary {
    /// Runs copied into the destination.
    pub copied: usize,
    /// Runs already there, identical.
    pub already_present: usize,
}

/// Merge the runs of every store in `sources` into `into` (created if needed).
pub fn merge_stores(into: &Path, sources: &[PathBuf]) -> Result<MergeSummary, MergeError> {
    let mut done = MergeSummary::default();
    for src in sources {
        if !src.is_dir() {
            return Err(MergeError::NotADirectory(src.clone()));
        }
        let read = |source| MergeError::Read {
            path: src.clone(),
            source,
        };
        let mut manifests: Vec<PathBuf> = std::fs::read_dir(src)
            .map_err(read)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "json"))
            .collect();
        manifests.sort();
        // The campaign record travels with the runs; two different records do not mix.
        if let Some(record) = CampaignRecord::read(src)? {
            match CampaignRecord::read(into)? {
                Some(theirs) if !theirs.same_campaign(&record) => {
                    return Err(MergeError::RecordConflict {
                        source_dir: src.clone(),
                        into: into.to_path_buf(),
                        theirs: describe(&record),
                        ours: describe(&theirs),
                    });
                }
                Some(theirs)
                    if theirs.configuration.is_some() || record.configuration.is_none() => {}
                // A record without its configuration (older) learns it from the source's.
                _ => {
                    std::fs::create_dir_all(into).map_err(|source| MergeError::Read {
                        path: into.to_path_buf(),
                        source,
                    })?;
                    store::write_atomic(&CampaignRecord::path(into), record.to_text().as_bytes())?
                }
            }
        }
        for m in manifests {
            let manifest = store::read_manifest(&m)?;
            manifest
                .check_results_version()
                .map_err(|source| MergeError::Future {
                    path: m.clone(),
                    source,
                })?;
            let from = store::run_paths(src, &manifest.run_id);
            if let Err(why) = store::verify_files(src, &manifest) {
                return Err(MergeError::Damaged {
                    source_dir: src.clone(),
                    run_id: manifest.run_id,
                    why,
                });
            }
            let to = store::run_paths(into, &manifest.run_id);
            if to.manifest.exists() {
                let theirs = store::read_manifest(&to.manifest)?;
                let identical_data = from.data().len() == to.data().len()
                    && from
                        .data()
                        .iter()
                        .zip(to.data())
                        .all(|(a, b)| std::fs::read(a).ok() == std::fs::read(b).ok());
                if theirs.config_hash != manifest.config_hash || !identical_data {
                    return Err(MergeError::Conflict {
                        run_id: manifest.run_id,
                        into: into.to_path_buf(),
                        what: if theirs.config_hash != manifest.config_hash {
                            "config hash"
                        } else {
                            "data"
                        },
                    });
                }
                copy_diagnostics(src, into, &manifest.run_id)?;
                done.already_present += 1;
                continue;
            }
            // Data files first, manifest last.
            for a in from.data().into_iter().chain([from.manifest.as_path()]) {
                let b = &into.join(a.file_name().expect("a run file has a name"));
                let bytes = std::fs::read(a).map_err(|source| MergeError::Read {
                    path: a.to_path_buf(),
                    source,
                })?;
                store::write_atomic(b, &bytes)?;
            }
            copy_diagnostics(src, into, &manifest.run_id)?;
            done.copied += 1;
        }
        copy_beside_runs(src, into)?;
    }
    Ok(done)
}

/// What a store holds beside its runs travels too: the goal-space samples of the figures
/// (`goal_spaces/`; the same name with other bytes is a conflict) and external learners' logs
/// (`*.learner.log`; the destination's copy is kept).
fn copy_beside_runs(src: &Path, into: &Path) -> Result<(), MergeError> {
    let files = |dir: &Path| -> Result<Vec<PathBuf>, MergeError> {
        if !dir.is_dir() {
            return Ok(Vec::new());
        }
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|source| MergeError::Read {
                path: dir.to_path_buf(),
                source,
            })?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_file())
            .collect();
        v.sort();
        Ok(v)
    };
    let read = |p: &Path| {
        std::fs::read(p).map_err(|source| MergeError::Read {
            path: p.to_path_buf(),
            source,
        })
    };
    let samples = files(&src.join(ugl_types::GOAL_SPACE_DIR))?;
    if !samples.is_empty() {
        let to_dir = into.join(ugl_types::GOAL_SPACE_DIR);
        std::fs::create_dir_all(&to_dir).map_err(|source| MergeError::Read {
            path: to_dir.clone(),
            source,
        })?;
        for a in samples {
            let b = to_dir.join(a.file_name().expect("a listed file has a name"));
            let bytes = read(&a)?;
            if b.exists() {
                if read(&b)? != bytes {
                    return Err(MergeError::Conflict {
                        run_id: format!(
                            "{}/{}",
                            ugl_types::GOAL_SPACE_DIR,
                            b.file_name().unwrap_or_default().to_string_lossy()
                        ),
                        into: into.to_path_buf(),
                        what: "goal-space sample",
                    });
                }
            } else {
                store::write_atomic(&b, &bytes)?;
            }
        }
    }
    for a in files(src)? {
        let name = a
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        if name.ends_with(".learner.log") && !into.join(&name).exists() {
            store::write_atomic(&into.join(&name), &read(&a)?)?;
        }
    }
    Ok(())
}

/// A record in an error message: `paper (main)`, with its configuration hash's first digits.
fn describe(r: &CampaignRecord) -> String {
    match &r.configuration {
        Some(c) => format!(
            "{} ({}, configuration {})",
            r.name,
            r.decl.role.name(),
            &c[..c.len().min(12)]
        ),
        None => format!("{} ({})", r.name, r.decl.role.name()),
    }
}

/// A run's diagnostics sidecar travels with it (where the destination has none).
fn copy_diagnostics(src: &Path, into: &Path, run_id: &str) -> Result<(), MergeError> {
    if let Some(d) = store::Diagnostics::read(src, run_id)?
        && store::Diagnostics::read(into, run_id)?.is_none()
    {
        store::write_diagnostics(into, &d)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ugl_types::{CampaignDecl, CampaignRole};

    fn with_record(dir: &Path, name: &str, role: CampaignRole) {
        std::fs::create_dir_all(dir).unwrap();
        let decl = CampaignDecl {
            role,
            ..CampaignDecl::default()
        };
        let text = CampaignRecord::new(name, &decl).to_text();
        std::fs::write(CampaignRecord::path(dir), text).unwrap();
    }

    /// Goal-space samples and learner logs travel with the runs (they were dropped, and the
    /// merged store's report lost its goal-space figures without a word).
    #[test]
    fn goal_space_samples_and_learner_logs_are_carried() {
        let t = tempfile::tempdir().unwrap();
        let (src, into) = (t.path().join("src"), t.path().join("into"));
        std::fs::create_dir_all(src.join(ugl_types::GOAL_SPACE_DIR)).unwrap();
        std::fs::write(src.join("goal_spaces/armball.rge-vae.l2.s0.json"), "{}").unwrap();
        std::fs::write(src.join("armball.rge-external.l2.s0.learner.log"), "hello").unwrap();
        merge_stores(&into, std::slice::from_ref(&src)).unwrap();
        assert_eq!(
            std::fs::read_to_string(into.join("goal_spaces/armball.rge-vae.l2.s0.json")).unwrap(),
            "{}"
        );
        assert!(
            into.join("armball.rge-external.l2.s0.learner.log")
                .is_file()
        );
        // Merging again is fine; another sample under the same name is a conflict.
        merge_stores(&into, std::slice::from_ref(&src)).unwrap();
        std::fs::write(
            src.join("goal_spaces/armball.rge-vae.l2.s0.json"),
            "{\"x\":1}",
        )
        .unwrap();
        let e = merge_stores(&into, &[src]).unwrap_err().to_string();
        assert!(e.contains("goal-space sample"), "{e}");
    }

    /// A run written by a newer build is refused, not merged silently.
    #[test]
    fn a_manifest_of_a_future_results_version_is_refused() {
        let t = tempfile::tempdir().unwrap();
        let (src, into) = (t.path().join("src"), t.path().join("into"));
        std::fs::create_dir_all(&src).unwrap();
        let committed =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/results/paper/armball.rpe.s0.json");
        let mut m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(committed).unwrap()).unwrap();
        m["crate_versions"]["results_version"] = 99.into();
        std::fs::write(src.join("armball.rpe.s0.json"), m.to_string()).unwrap();
        let e = merge_stores(&into, &[src]).unwrap_err().to_string();
        assert!(
            e.contains("armball.rpe.s0.json") && e.contains("newer ugl-bench"),
            "{e}"
        );
    }

    /// The campaign record travels with the runs, and two different campaigns do not mix.
    #[test]
    fn the_record_is_carried_and_a_different_one_refused() {
        let t = tempfile::tempdir().unwrap();
        let (a, b, into) = (
            t.path().join("a"),
            t.path().join("b"),
            t.path().join("into"),
        );
        with_record(&a, "paper", CampaignRole::Main);
        merge_stores(&into, std::slice::from_ref(&a)).unwrap();
        assert_eq!(
            CampaignRecord::read(&into).unwrap(),
            CampaignRecord::read(&a).unwrap()
        );
        // The same record again is fine; another campaign's is refused, naming both.
        merge_stores(&into, std::slice::from_ref(&a)).unwrap();
        with_record(&b, "paper-long", CampaignRole::Recipe);
        let e = merge_stores(&into, &[b]).unwrap_err().to_string();
        assert!(
            e.contains("paper-long (recipe)") && e.contains("paper (main)"),
            "{e}"
        );
    }
}
