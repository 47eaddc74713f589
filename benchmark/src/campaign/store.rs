//! The results store (`data/results/README.md` documents the schema): per run a curve parquet,
//! an outcomes parquet and a JSON manifest, each written to a temporary file and renamed.
//! A run is complete when its manifest exists (it is written last) and its data files have
//! the lengths and BLAKE3 hashes the manifest records ([`Manifest::files`]; manifests written
//! before results version 3 do not record them, and their files are taken as they are). The
//! types of the schema ([`Manifest`], [`RunPaths`], [`verify_files`]) are `ugl-types`', shared
//! with the report.

use std::path::{Path, PathBuf};

use polars::prelude::*;
use thiserror::Error;

use super::plan::RunSpec;
use crate::explore::{Checkpoint, ExplorationLog};
use ugl_types::columns::{curve, interest, outcomes};
pub use ugl_types::{
    Diagnostics, DigestError, FileDigest, Manifest, Outcome, RunPaths, Summary, run_paths,
    verify_files,
};

/// Errors of the results store.
#[derive(Debug, Error)]
pub enum StoreError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot encode {path}: {message}")]
    Encode { path: PathBuf, message: String },
    #[error("cannot read {path}: {message}")]
    Read { path: PathBuf, message: String },
    /// The store belongs to another campaign or configuration.
    #[error("{path}: {message}")]
    Refused { path: PathBuf, message: String },
}

/// The curve table of a run. Where the scene has an object the agent cannot control
/// (ArmBalls), its KL-coverage and cell coverage follow as `control_klc`, `control_coverage`,
/// then the follow-up's exploration ratios of the controlled object, `ratio_30`, `ratio_50`,
/// and its goal-reaching error, `goal_error`.
pub fn curve_frame(spec: &RunSpec, log: &ExplorationLog) -> PolarsResult<DataFrame> {
    let n = log.checkpoints.len();
    let c = &log.checkpoints;
    let mut df = df!(
        curve::RUN_ID => vec![spec.run_id(); n],
        curve::ENV => vec![spec.env.name(); n],
        curve::ALGO => vec![spec.algo.to_string(); n],
        curve::SAMPLER => vec![spec.sampler.name(); n],
        curve::LATENTS => vec![spec.latents as i64; n],
        curve::VARIANT => vec![spec.variant.map(|v| v.name()).unwrap_or("none"); n],
        curve::SEED => vec![spec.seed as i64; n],
        curve::EPOCH => c.iter().map(|p| p.epoch as i64).collect::<Vec<_>>(),
        curve::N_OUTCOMES => c.iter().map(|p| p.n_outcomes as i64).collect::<Vec<_>>(),
        curve::KLC => c.iter().map(|p| p.klc).collect::<Vec<_>>(),
        curve::N_MOVED => c.iter().map(|p| p.n_moved as i64).collect::<Vec<_>>(),
        curve::COVERAGE => c.iter().map(|p| p.coverage).collect::<Vec<_>>(),
    )?;
    // The optional columns, each written where some checkpoint has it.
    let optional: [(&str, fn(&Checkpoint) -> Option<f64>); 5] = [
        (curve::CONTROL_KLC, |p| p.control.map(|c| c.0)),
        (curve::CONTROL_COVERAGE, |p| p.control.map(|c| c.1)),
        (curve::RATIO_30, |p| p.ratios.map(|r| r.0)),
        (curve::RATIO_50, |p| p.ratios.map(|r| r.1)),
        (curve::GOAL_ERROR, |p| p.goal_error),
    ];
    for (name, get) in optional {
        if c.iter().any(|p| get(p).is_some()) {
            let v: Vec<Option<f64>> = c.iter().map(get).collect();
            df.with_column(Column::new(name.into(), v))?;
        }
    }
    Ok(df)
}

/// A run's outcomes as the discovery measures read them ([`ugl_types::Outcome`]: the same
/// values as its outcomes table, `outcomes_frame`).
pub fn outcomes_of(log: &ExplorationLog) -> Vec<Outcome> {
    log.outcomes
        .iter()
        .zip(&log.epochs)
        .zip(&log.moved)
        .enumerate()
        .map(|(i, ((s, &epoch), &moved))| Outcome {
            index: i as i64,
            epoch: epoch as i64,
            x: s[0],
            y: s[1],
            angle: (log.dim == 3).then_some(s[2]),
            moved,
        })
        .collect()
}

/// The outcomes table of a run; ArmBalls' distractor adds `distractor_x`, `distractor_y`.
pub fn outcomes_frame(spec: &RunSpec, log: &ExplorationLog) -> PolarsResult<DataFrame> {
    let n = log.outcomes.len();
    let angle: Vec<Option<f64>> = log
        .outcomes
        .iter()
        .map(|s| if log.dim == 3 { Some(s[2]) } else { None })
        .collect();
    let mut df = df!(
        outcomes::RUN_ID => vec![spec.run_id(); n],
        outcomes::INDEX => (0..n as i64).collect::<Vec<_>>(),
        outcomes::EPOCH => log.epochs.iter().map(|&e| e as i64).collect::<Vec<_>>(),
        outcomes::X => log.outcomes.iter().map(|s| s[0]).collect::<Vec<_>>(),
        outcomes::Y => log.outcomes.iter().map(|s| s[1]).collect::<Vec<_>>(),
        outcomes::ANGLE => angle,
        outcomes::MOVED => log.moved.clone(),
    )?;
    if log.dim == 4 {
        for (name, k) in [(outcomes::DISTRACTOR_X, 2), (outcomes::DISTRACTOR_Y, 3)] {
            let v: Vec<f64> = log.outcomes.iter().map(|s| s[k]).collect();
            df.with_column(Column::new(name.into(), v))?;
        }
    }
    Ok(df)
}

/// The interest table of a modular exploration (`<run_id>.interest.parquet`): per evaluation
/// epoch and module, the module's goal-space coordinates, its interest and how many goals were
/// chosen in it so far. None for the other explorers.
pub fn interest_frame(spec: &RunSpec, log: &ExplorationLog) -> PolarsResult<Option<DataFrame>> {
    if log.interest.is_empty() {
        return Ok(None);
    }
    let p = &log.interest;
    let n = p.len();
    let name = |m: usize| {
        log.modules
            .get(m)
            .map(|(n, _)| n.clone())
            .unwrap_or_default()
    };
    let dims = |m: usize| {
        log.modules
            .get(m)
            .map(|(_, d)| {
                d.iter()
                    .map(|k| k.to_string())
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .unwrap_or_default()
    };
    df!(
        interest::RUN_ID => vec![spec.run_id(); n],
        interest::EPOCH => p.iter().map(|q| q.epoch as i64).collect::<Vec<_>>(),
        interest::MODULE => p.iter().map(|q| q.module as i64).collect::<Vec<_>>(),
        interest::MODULE_NAME => p.iter().map(|q| name(q.module)).collect::<Vec<_>>(),
        interest::DIMS => p.iter().map(|q| dims(q.module)).collect::<Vec<_>>(),
        interest::INTEREST => p.iter().map(|q| q.interest).collect::<Vec<_>>(),
        interest::N_CHOSEN => p.iter().map(|q| q.n_chosen as i64).collect::<Vec<_>>(),
    )
    .map(Some)
}

/// Write `bytes` to `path` atomically ([`crate::fsio::write_atomic`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), StoreError> {
    crate::fsio::write_atomic(path, bytes).map_err(|source| StoreError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Encode a frame as parquet bytes (deterministic for the same frame).
pub fn parquet_bytes(df: &mut DataFrame, path: &Path) -> Result<Vec<u8>, StoreError> {
    let mut buf = Vec::new();
    ParquetWriter::new(&mut buf)
        .finish(df)
        .map_err(|e| StoreError::Encode {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    Ok(buf)
}

/// Write a run's three files; the manifest last.
pub fn write_run(
    dir: &Path,
    spec: &RunSpec,
    log: &ExplorationLog,
    manifest: &Manifest,
) -> Result<(), StoreError> {
    std::fs::create_dir_all(dir).map_err(|source| StoreError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let RunPaths {
        curve: curve_p,
        outcomes: outcomes_p,
        interest: interest_p,
        ..
    } = run_paths(dir, &spec.run_id());
    let enc = |p: &Path, e: PolarsError| StoreError::Encode {
        path: p.to_path_buf(),
        message: e.to_string(),
    };
    let mut curve = curve_frame(spec, log).map_err(|e| enc(&curve_p, e))?;
    let mut outcomes = outcomes_frame(spec, log).map_err(|e| enc(&outcomes_p, e))?;
    let mut interest = interest_frame(spec, log).map_err(|e| enc(&interest_p, e))?;
    let mut digests = Vec::new();
    let mut frames = vec![(&curve_p, &mut curve), (&outcomes_p, &mut outcomes)];
    if let Some(frame) = interest.as_mut() {
        frames.push((&interest_p, frame));
    }
    for (path, frame) in frames {
        let bytes = parquet_bytes(frame, path)?;
        write_atomic(path, &bytes)?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        digests.push(FileDigest::of(&name, &bytes));
    }
    let manifest = Manifest {
        files: Some(digests),
        discovery_blake3: manifest.discovery.as_ref().map(|d| d.digest()),
        ..manifest.clone()
    };
    write_manifest(dir, &manifest)
}

/// Write (or replace, atomically) a run's manifest.
pub fn write_manifest(dir: &Path, manifest: &Manifest) -> Result<(), StoreError> {
    let manifest_p = run_paths(dir, &manifest.run_id).manifest;
    let mut json = serde_json::to_vec_pretty(manifest).map_err(|e| StoreError::Encode {
        path: manifest_p.clone(),
        message: e.to_string(),
    })?;
    json.push(b'\n');
    write_atomic(&manifest_p, &json)
}

/// Write (or replace, atomically) a run's diagnostics sidecar ([`Diagnostics`]).
pub fn write_diagnostics(dir: &Path, d: &Diagnostics) -> Result<(), StoreError> {
    let path = Diagnostics::path(dir, &d.run_id);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|source| StoreError::Io {
            path: parent.to_path_buf(),
            source,
        })?;
    }
    let mut json = serde_json::to_vec_pretty(d).map_err(|e| StoreError::Encode {
        path: path.clone(),
        message: e.to_string(),
    })?;
    json.push(b'\n');
    write_atomic(&path, &json)
}

/// Read a run's manifest, if it exists and parses.
pub fn read_manifest(path: &Path) -> Result<Manifest, StoreError> {
    let text = std::fs::read_to_string(path).map_err(|e| StoreError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    serde_json::from_str(&text).map_err(|e| StoreError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Whether a run is complete in `dir` with the given config hash: manifest present and
/// matching, and both data files as it records them ([`verify_files`]). A damaged run is not
/// complete: a resumed campaign recomputes it (and says so in the log).
pub fn is_complete(dir: &Path, run_id: &str, config_hash: &str) -> bool {
    match read_manifest(&run_paths(dir, run_id).manifest) {
        Ok(m) if m.config_hash == config_hash => match verify_files(dir, &m) {
            Ok(()) => true,
            Err(why) => {
                tracing::warn!("run {run_id} is damaged and will be recomputed: {why}");
                false
            }
        },
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::EnvKind;
    use crate::explore::Algo;

    fn log(checkpoints: Vec<Checkpoint>) -> ExplorationLog {
        ExplorationLog {
            dim: 4,
            outcomes: Vec::new(),
            epochs: Vec::new(),
            moved: Vec::new(),
            checkpoints,
            n_random: 0,
            n_goal: 0,
            modules: Vec::new(),
            interest: Vec::new(),
        }
    }

    /// The optional columns come after the fixed ones, in their order, each only where some
    /// checkpoint has it: none for a scene without an uncontrollable object, all five for
    /// ArmBalls, with each value in its own column.
    #[test]
    fn the_curve_writes_the_optional_columns_where_the_scene_has_them() {
        let point = Checkpoint {
            epoch: 10,
            n_outcomes: 11,
            klc: 3.0,
            n_moved: 4,
            coverage: 0.1,
            control: None,
            ratios: None,
            goal_error: None,
        };
        let plain = curve_frame(
            &RunSpec::baseline(EnvKind::ARMBALL, Algo::RPE, 0),
            &log(vec![point]),
        )
        .unwrap();
        assert_eq!(
            plain.get_column_names().last().unwrap().as_str(),
            curve::COVERAGE
        );
        let balls = Checkpoint {
            control: Some((1.0, 0.2)),
            ratios: Some((0.3, 0.4)),
            goal_error: Some(0.5),
            ..point
        };
        let df = curve_frame(
            &RunSpec::baseline(EnvKind::ARMBALLS, Algo::RPE, 0),
            &log(vec![balls]),
        )
        .unwrap();
        let names: Vec<&str> = df.get_column_names().iter().map(|n| n.as_str()).collect();
        let optional = [
            (curve::CONTROL_KLC, 1.0),
            (curve::CONTROL_COVERAGE, 0.2),
            (curve::RATIO_30, 0.3),
            (curve::RATIO_50, 0.4),
            (curve::GOAL_ERROR, 0.5),
        ];
        assert_eq!(names[names.len() - 5..], optional.map(|o| o.0));
        for (name, v) in optional {
            assert_eq!(df.column(name).unwrap().f64().unwrap().get(0), Some(v));
        }
    }
}
