//! The results store (`data/results/README.md` documents the schema): per run a curve parquet,
//! an outcomes parquet and a JSON manifest, each written to a temporary file and renamed.
//! A run is complete when its manifest exists (it is written last) and its two data files have
//! the lengths and BLAKE3 hashes the manifest records ([`Manifest::files`]; manifests written
//! before results version 3 do not record them, and their files are taken as they are).

use std::path::{Path, PathBuf};

use polars::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::plan::RunSpec;
use crate::explore::ExplorationLog;

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
}

/// The final numbers of a run, also printed by `ugl run` as its last line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub run: String,
    /// Final KL-coverage; JSON has no infinity, so +inf is written as the string "inf".
    #[serde(with = "inf_as_string")]
    pub final_klc: f64,
    pub n_moved: usize,
    pub coverage: f64,
}

/// Everything about a run that is not its data (DESIGN.md "Results store").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub run_id: String,
    pub identity: String,
    pub env: String,
    pub algo: String,
    pub sampler: String,
    /// Latent size of a learned goal space (0 for RPE and EFR).
    #[serde(default)]
    pub latents: usize,
    /// `none`, or `faithful` / `corrected` for the neural learners.
    #[serde(default = "none_string")]
    pub variant: String,
    /// Name of the representation learner (the program's name for external learners).
    #[serde(default)]
    pub learner: Option<String>,
    pub seed: u64,
    /// The seed of the run's exploration streams, derived from (campaign seed,
    /// [`super::RunSpec::exploration_identity`]).
    pub run_seed: u64,
    pub campaign: String,
    pub campaign_seed: u64,
    pub profile: String,
    /// BLAKE3 of everything the run's results depend on.
    pub config_hash: String,
    /// The exploration budget and constants actually used.
    pub explore: serde_json::Value,
    pub env_config: serde_json::Value,
    /// The UGL-stage settings (learned goal spaces only).
    #[serde(default)]
    pub ugl: Option<serde_json::Value>,
    /// Whether the budget is below the paper's, and how.
    pub reduced_budget: bool,
    pub budget_note: String,
    pub git_revision: String,
    pub crate_versions: serde_json::Value,
    pub toolchain: String,
    pub threads: usize,
    /// Seconds of exploration (excluding the representation's fit).
    pub wall_s: f64,
    /// Seconds to generate the UGL data set and fit the representation (shared between the
    /// samplers of a cell in a campaign).
    #[serde(default)]
    pub fit_s: Option<f64>,
    /// External learners: the fit time the program reported itself (`READY fit_s=...`),
    /// without its start-up, imports and file I/O, which `fit_s` includes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub learner_fit_s: Option<f64>,
    /// Seconds spent rendering and encoding outcomes during exploration.
    #[serde(default)]
    pub encode_s: Option<f64>,
    /// Training of a neural representation: configuration, loss curve, model-cache status.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub train: Option<serde_json::Value>,
    /// The external learner program (`[learners.external]`: name, command) of an `rge-external`
    /// run, so that the run can be reproduced from its manifest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub external: Option<serde_json::Value>,
    pub host: String,
    /// The CPU model and SIMD level (absent in manifests written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu: Option<super::machine::CpuInfo>,
    /// Learned goal spaces: held-out R² of a linear and a k-NN map from latents to the true
    /// object state (`repr::quality::LatentQuality`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latent_quality: Option<serde_json::Value>,
    pub summary: Summary,
    /// The run's data files as written: name, length and BLAKE3 hash. A run is complete only
    /// if its files still match (checked on resume, merge and report). Absent in manifests
    /// written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub files: Option<Vec<FileDigest>>,
}

/// A data file of a run as its manifest records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FileDigest {
    /// File name, in the run's directory.
    pub name: String,
    pub bytes: u64,
    pub blake3: String,
}

impl FileDigest {
    /// The digest of `bytes` written as `name`.
    pub fn of(name: &str, bytes: &[u8]) -> FileDigest {
        FileDigest {
            name: name.to_string(),
            bytes: bytes.len() as u64,
            blake3: blake3::hash(bytes).to_hex().to_string(),
        }
    }
}

/// Check the data files of a run in `dir` against its manifest: each must exist with the
/// recorded length and hash. The error says which file and how it differs. Manifests without
/// digests (written before they were recorded) pass if the files exist.
pub fn verify_files(dir: &Path, manifest: &Manifest) -> Result<(), String> {
    let Some(files) = &manifest.files else {
        let paths = run_paths(dir, &manifest.run_id);
        return match paths.data().into_iter().find(|p| !p.is_file()) {
            Some(p) => Err(format!("{} is missing", p.display())),
            None => Ok(()),
        };
    };
    for f in files {
        let path = dir.join(&f.name);
        let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        if bytes.len() as u64 != f.bytes {
            return Err(format!(
                "{} has {} bytes, its manifest records {} (truncated or replaced)",
                path.display(),
                bytes.len(),
                f.bytes
            ));
        }
        if blake3::hash(&bytes).to_hex().as_str() != f.blake3 {
            return Err(format!(
                "{} does not match the BLAKE3 hash its manifest records (damaged)",
                path.display()
            ));
        }
    }
    Ok(())
}

fn none_string() -> String {
    "none".into()
}

mod inf_as_string {
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_infinite() && *v > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_f64(*v)
        }
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum V {
            N(f64),
            S(String),
        }
        match V::deserialize(d)? {
            V::N(x) => Ok(x),
            V::S(s) if s == "inf" => Ok(f64::INFINITY),
            V::S(s) => Err(serde::de::Error::custom(format!(
                "expected a number or \"inf\", got {s:?}"
            ))),
        }
    }
}

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
        curve: dir.join(format!("{run_id}.parquet")),
        outcomes: dir.join(format!("{run_id}.outcomes.parquet")),
        interest: dir.join(format!("{run_id}.interest.parquet")),
        manifest: dir.join(format!("{run_id}.json")),
    }
}

/// The curve table of a run. Where the scene has an object the agent cannot control
/// (ArmBalls), its KL-coverage and cell coverage follow as `control_klc`, `control_coverage`.
pub fn curve_frame(spec: &RunSpec, log: &ExplorationLog) -> PolarsResult<DataFrame> {
    let n = log.checkpoints.len();
    let c = &log.checkpoints;
    let mut df = df!(
        "run_id" => vec![spec.run_id(); n],
        "env" => vec![spec.env.name(); n],
        "algo" => vec![spec.algo.name(); n],
        "sampler" => vec![spec.sampler.name(); n],
        "latents" => vec![spec.latents as i64; n],
        "variant" => vec![spec.variant.map(|v| v.name()).unwrap_or("none"); n],
        "seed" => vec![spec.seed as i64; n],
        "epoch" => c.iter().map(|p| p.epoch as i64).collect::<Vec<_>>(),
        "n_outcomes" => c.iter().map(|p| p.n_outcomes as i64).collect::<Vec<_>>(),
        "klc" => c.iter().map(|p| p.klc).collect::<Vec<_>>(),
        "n_moved" => c.iter().map(|p| p.n_moved as i64).collect::<Vec<_>>(),
        "coverage" => c.iter().map(|p| p.coverage).collect::<Vec<_>>(),
    )?;
    if c.iter().any(|p| p.control.is_some()) {
        let control = |f: fn((f64, f64)) -> f64| {
            c.iter()
                .map(|p| p.control.map(f))
                .collect::<Vec<Option<f64>>>()
        };
        df.with_column(Column::new("control_klc".into(), control(|v| v.0)))?;
        df.with_column(Column::new("control_coverage".into(), control(|v| v.1)))?;
    }
    Ok(df)
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
        "run_id" => vec![spec.run_id(); n],
        "index" => (0..n as i64).collect::<Vec<_>>(),
        "epoch" => log.epochs.iter().map(|&e| e as i64).collect::<Vec<_>>(),
        "x" => log.outcomes.iter().map(|s| s[0]).collect::<Vec<_>>(),
        "y" => log.outcomes.iter().map(|s| s[1]).collect::<Vec<_>>(),
        "angle" => angle,
        "moved" => log.moved.clone(),
    )?;
    if log.dim == 4 {
        for (name, k) in [("distractor_x", 2), ("distractor_y", 3)] {
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
        "run_id" => vec![spec.run_id(); n],
        "epoch" => p.iter().map(|q| q.epoch as i64).collect::<Vec<_>>(),
        "module" => p.iter().map(|q| q.module as i64).collect::<Vec<_>>(),
        "module_name" => p.iter().map(|q| name(q.module)).collect::<Vec<_>>(),
        "dims" => p.iter().map(|q| dims(q.module)).collect::<Vec<_>>(),
        "interest" => p.iter().map(|q| q.interest).collect::<Vec<_>>(),
        "n_chosen" => p.iter().map(|q| q.n_chosen as i64).collect::<Vec<_>>(),
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
