//! Reading the results store (`data/results/README.md`): the curve and outcome parquet files of
//! every run through polars, and the JSON manifests through serde_json.
//!
//! Every column is checked against the schema (presence, type, no nulls where none are allowed,
//! constant identity columns within a file); any problem is a [`ReportError`] naming the file and
//! the column. A run whose three files are not all present is *incomplete* (a campaign still
//! running, or one that was killed): it is skipped and listed in the report, not an error.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};

use polars::prelude::*;
use ugl_types::columns::{curve, outcomes};

use crate::error::ReportError;

/// Modular explorations' interest per module (`armballs.rs` reads it; not a run of its own).
pub use ugl_types::INTEREST_SUFFIX;
use ugl_types::{CURVE_SUFFIX, MANIFEST_SUFFIX, OUTCOMES_SUFFIX};

/// A condition: everything that identifies a curve in the figures, except the seed
/// (`ugl-types`' typed key, ordered by its registries).
pub use ugl_types::{Algo, ConditionKey, Sampler, Variant};

/// Position of `name` in `known`, or `known.len()` for unknown names.
pub fn rank(name: &str, known: &[&str]) -> usize {
    known.iter().position(|k| *k == name).unwrap_or(known.len())
}

/// One row of `<run_id>.parquet`.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePoint {
    pub epoch: i64,
    pub n_outcomes: i64,
    pub klc: f64,
    pub n_moved: i64,
    pub coverage: f64,
}

/// One row of `<run_id>.outcomes.parquet` (`ugl-types`' type, which the measures read).
pub use ugl_types::Outcome;

/// The manifest of a run: the runner's own type (`ugl-types`), read through serde.
pub use ugl_types::Manifest;

/// A manifest for the report's tests: `fields` over a complete version-3 manifest of an
/// ArmBall RPE run.
#[cfg(test)]
pub(crate) fn test_manifest(fields: serde_json::Value) -> Manifest {
    let mut base = serde_json::json!({
        "run_id": "armball.rpe.s0", "identity": "env=armball/algo=rpe/seed=0",
        "env": "armball", "algo": "rpe", "sampler": "none", "latents": 0, "variant": "none",
        "learner": null, "seed": 0, "run_seed": 0, "campaign": "test", "campaign_seed": 0,
        "profile": "test", "config_hash": "", "explore": {}, "env_config": {}, "ugl": null,
        "reduced_budget": false, "budget_note": "", "git_revision": "", "crate_versions":
        {"results_version": 3}, "toolchain": "", "threads": 1, "wall_s": 0.0, "fit_s": null,
        "encode_s": null, "host": "",
        "summary": {"run": "armball.rpe.s0", "final_klc": 0.0, "n_moved": 0, "coverage": 0.0}
    });
    for (k, v) in fields.as_object().expect("an object of fields") {
        base[k] = v.clone();
    }
    serde_json::from_value(base).expect("a complete manifest")
}

/// A run for the report's tests: `curve` under `key`, with [`test_manifest`]'s manifest and no
/// outcomes or files.
#[cfg(test)]
pub(crate) fn test_run(
    run_id: String,
    key: ConditionKey,
    seed: i64,
    curve: Vec<CurvePoint>,
) -> Run {
    Run {
        run_id,
        campaign: "paper".into(),
        key,
        seed,
        curve,
        outcomes: Vec::new(),
        diagnostics: None,
        manifest: test_manifest(serde_json::json!({})),
        curve_path: Default::default(),
        outcomes_path: Default::default(),
        manifest_path: Default::default(),
        measured: Default::default(),
    }
}

/// One complete run.
#[derive(Debug, Clone)]
pub struct Run {
    pub run_id: String,
    /// Sub-directory of the store holding the run ("" for the top level).
    pub campaign: String,
    pub key: ConditionKey,
    /// Repetition index (`seed` column).
    pub seed: i64,
    /// Sorted by epoch, epochs distinct.
    pub curve: Vec<CurvePoint>,
    /// In history order; empty when the outcomes file is not kept (then the manifest records
    /// what the run discovered, [`Manifest::discovery`]).
    pub outcomes: Vec<Outcome>,
    /// The manifest as the run wrote it, except `latent_quality`, which is its diagnostics
    /// sidecar's where there is one ([`ugl_types::Diagnostics`]: a later measure).
    pub manifest: Manifest,
    /// The later diagnostics of the run, with the code revision that measured them.
    pub diagnostics: Option<ugl_types::Diagnostics>,
    /// The curve file (`<run_id>.parquet`).
    pub curve_path: PathBuf,
    pub outcomes_path: PathBuf,
    pub manifest_path: PathBuf,
    /// [`Run::discovery`], computed once (a run without a record is measured from its outcomes
    /// file: the claims, the leaderboard and the validity check each ask for it).
    pub(crate) measured:
        std::sync::OnceLock<Result<Option<ugl_types::RunDiscovery>, ugl_types::DiscoveryError>>,
}

impl Run {
    pub fn final_point(&self) -> &CurvePoint {
        self.curve.last().expect("curves are never empty")
    }

    /// What the run discovered: as its manifest records it (results version 4 on), else
    /// measured from its outcomes with the same code ([`ugl_types::RunDiscovery::measure`]).
    /// None for a run without outcomes.
    pub fn discovery(&self) -> Result<Option<ugl_types::RunDiscovery>, ugl_types::DiscoveryError> {
        if let Some(d) = &self.manifest.discovery {
            return Ok(Some(d.clone()));
        }
        self.measured
            .get_or_init(|| {
                let spec = ugl_types::EnvSpec::by_name(&self.key.env)
                    .ok_or_else(|| ugl_types::DiscoveryError::UnknownEnv(self.key.env.clone()))?;
                ugl_types::RunDiscovery::measure(spec, &self.outcomes)
            })
            .clone()
    }

    /// Whether its outcomes were read (the outcomes file is kept).
    pub fn has_outcomes(&self) -> bool {
        !self.outcomes.is_empty()
    }
}

/// The whole store, or one campaign of it.
#[derive(Debug, Clone)]
pub struct Store {
    /// Sorted by condition order, then seed, then campaign.
    pub runs: Vec<Run>,
    /// Runs missing one of their three files: (stem path without suffix, missing file names).
    pub incomplete: Vec<(PathBuf, Vec<String>)>,
}

/// Display name of a campaign: its directory name, `(top level)` for runs directly in the store.
pub fn campaign_display(name: &str) -> String {
    if name.is_empty() {
        "(top level)".into()
    } else {
        name.to_string()
    }
}

/// One campaign of the store: a directory holding run files (the store itself, campaign `""`,
/// or one of its sub-directories), with the file stems found in it.
#[derive(Debug, Clone)]
pub struct CampaignDir {
    /// Sub-directory name; `""` for the store's top level.
    pub name: String,
    pub path: PathBuf,
    /// stem path -> which of the three files (curve, outcomes, manifest) exist.
    stems: BTreeMap<PathBuf, [bool; 3]>,
}

/// Whether a run's files make it complete: its curve and its manifest (written last). The
/// outcomes file may be left out of a store when the manifest records what the run
/// discovered; whether it may is the manifest's to say ([`ugl_types::verify_files`]).
fn complete([curve, _, manifest]: [bool; 3]) -> bool {
    curve && manifest
}

impl CampaignDir {
    /// Runs whose curve and manifest are present.
    pub fn n_complete(&self) -> usize {
        self.stems.values().filter(|&&p| complete(p)).count()
    }

    /// Runs missing their curve or manifest (a run being written, or a damaged one).
    pub fn n_incomplete(&self) -> usize {
        self.stems.len() - self.n_complete()
    }

    /// Reads every complete run; lists the incomplete ones. A run id twice within the campaign is
    /// an error (the same run in two campaigns is not: campaigns are separate experiments).
    pub fn load(&self) -> Result<Store, ReportError> {
        let mut runs = Vec::new();
        let mut incomplete = Vec::new();
        let mut stems = Vec::new();
        for (stem, present) in &self.stems {
            let [curve, _, manifest] = *present;
            if !complete(*present) {
                let missing: Vec<String> = [(curve, CURVE_SUFFIX), (manifest, MANIFEST_SUFFIX)]
                    .iter()
                    .filter(|(p, _)| !p)
                    .map(|(_, s)| format!("{}{s}", stem_name(stem)))
                    .collect();
                tracing::warn!(run = %stem.display(), ?missing, "incomplete run skipped");
                incomplete.push((stem.clone(), missing));
                continue;
            }
            stems.push(stem);
        }
        // Every run is read (and its files and discovery record checked) on its own, on every
        // core; the first error in stem order is the one reported, whatever the threads.
        use rayon::prelude::*;
        let loaded: Vec<Result<Run, ReportError>> = stems
            .par_iter()
            .map(|stem| load_run(stem, self.name.clone()))
            .collect();
        for run in loaded {
            runs.push(run?);
        }
        check_unique_run_ids(
            runs.iter()
                .map(|r| (r.run_id.as_str(), r.curve_path.as_path())),
        )?;
        sort_runs(&mut runs);
        Ok(Store { runs, incomplete })
    }
}

/// Within one campaign every run id is unique: the first repeated one is a
/// [`ReportError::DuplicateRun`] naming both files.
pub fn check_unique_run_ids<'a>(
    runs: impl IntoIterator<Item = (&'a str, &'a Path)>,
) -> Result<(), ReportError> {
    let mut seen: BTreeMap<&str, &Path> = BTreeMap::new();
    for (id, path) in runs {
        if let Some(first) = seen.get(id) {
            return Err(ReportError::DuplicateRun {
                run_id: id.to_string(),
                first: first.to_path_buf(),
                second: path.to_path_buf(),
            });
        }
        seen.insert(id, path);
    }
    Ok(())
}

fn sort_runs(runs: &mut [Run]) {
    runs.sort_by(|a, b| {
        (a.key.order_key(), a.seed, &a.campaign).cmp(&(b.key.order_key(), b.seed, &b.campaign))
    });
}

/// The campaigns of the store `dir` (its top level and its sub-directories), sorted by name,
/// keeping only those that hold at least one run file (a directory of cached models is none).
pub fn scan_store(dir: &Path) -> Result<Vec<CampaignDir>, ReportError> {
    if !dir.is_dir() {
        return Err(ReportError::NoResultsDir(dir.to_path_buf()));
    }
    let mut dirs = vec![(String::new(), dir.to_path_buf())];
    for entry in sorted_entries(dir)? {
        if entry.is_dir() {
            let name = entry
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            if !name.starts_with('.') {
                dirs.push((name, entry));
            }
        }
    }
    let mut out = Vec::new();
    for (name, d) in dirs {
        let mut stems: BTreeMap<PathBuf, [bool; 3]> = BTreeMap::new();
        for path in sorted_entries(&d)? {
            if !path.is_file() {
                continue;
            }
            let Some(file) = path.file_name().and_then(|n| n.to_str()) else {
                continue;
            };
            if file.starts_with('.') || file.ends_with(INTEREST_SUFFIX) {
                continue; // temporary files of the atomic writer, editor files; interest tables
            }
            let (stem, slot) = if let Some(s) = file.strip_suffix(OUTCOMES_SUFFIX) {
                (s, 1)
            } else if let Some(s) = file.strip_suffix(CURVE_SUFFIX) {
                (s, 0)
            } else if let Some(s) = file.strip_suffix(MANIFEST_SUFFIX) {
                (s, 2)
            } else {
                continue;
            };
            if stem.is_empty() {
                continue;
            }
            stems.entry(d.join(stem)).or_insert([false; 3])[slot] = true;
        }
        if !stems.is_empty() {
            out.push(CampaignDir {
                name,
                path: d,
                stems,
            });
        }
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(out)
}

/// Reads every run under `dir` (top level and one sub-directory down), all campaigns together.
/// Run ids are unique within each campaign; the report itself reads campaigns separately
/// ([`crate::campaigns::load_campaigns`]).
pub fn load_store(dir: &Path) -> Result<Store, ReportError> {
    let mut runs = Vec::new();
    let mut incomplete = Vec::new();
    for c in scan_store(dir)? {
        let s = c.load()?;
        runs.extend(s.runs);
        incomplete.extend(s.incomplete);
    }
    if runs.is_empty() {
        if !incomplete.is_empty() {
            return Err(ReportError::NoCompleteRuns {
                dir: dir.to_path_buf(),
                incomplete: incomplete.len(),
            });
        }
        return Err(ReportError::EmptyResults(dir.to_path_buf()));
    }
    sort_runs(&mut runs);
    incomplete.sort();
    Ok(Store { runs, incomplete })
}

fn stem_name(stem: &Path) -> String {
    stem.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

pub(crate) fn sorted_entries(dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    let io = |source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    };
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        out.push(entry.map_err(io)?.path());
    }
    out.sort();
    Ok(out)
}

/// Reads a run's manifest, then checks its data files against the lengths and BLAKE3 hashes it
/// records ([`ugl_types::verify_files`]; manifests written before results version 3 have none
/// and pass). A truncated or damaged file is an error naming it, before polars tries to parse it.
pub(crate) fn read_manifest(manifest_path: &Path) -> Result<Manifest, ReportError> {
    let text = std::fs::read_to_string(manifest_path).map_err(|source| ReportError::Io {
        path: manifest_path.to_path_buf(),
        source,
    })?;
    let manifest = Manifest::from_json(&text).map_err(|source| ReportError::Manifest {
        path: manifest_path.to_path_buf(),
        source,
    })?;
    manifest
        .check_results_version()
        .map_err(|e| ReportError::Invalid {
            path: manifest_path.to_path_buf(),
            problem: e.to_string(),
        })?;
    let dir = manifest_path.parent().unwrap_or(Path::new("."));
    ugl_types::verify_files(dir, &manifest).map_err(|e| match e {
        ugl_types::DigestError::Io { path, source } => ReportError::Io { path, source },
        e => ReportError::Invalid {
            path: e.path().to_path_buf(),
            problem: format!(
                "does not match its manifest, truncated or damaged ({e}); resume the campaign \
                 to recompute the run"
            ),
        },
    })?;
    Ok(manifest)
}

/// Reads one run from its three files.
pub fn load_run(stem: &Path, campaign: String) -> Result<Run, ReportError> {
    let curve_path = with_suffix(stem, CURVE_SUFFIX);
    let outcomes_path = with_suffix(stem, OUTCOMES_SUFFIX);
    let manifest_path = with_suffix(stem, MANIFEST_SUFFIX);
    let manifest = read_manifest(&manifest_path)?;

    let df = read_parquet(&curve_path)?;
    let c = Cols {
        df: &df,
        path: &curve_path,
    };
    let run_id = c.constant_str(curve::RUN_ID)?;
    let key = ConditionKey {
        env: c.constant_str(curve::ENV)?,
        algo: c.constant_str(curve::ALGO)?.into(),
        sampler: c.constant_str(curve::SAMPLER)?.into(),
        latents: c.constant_i64(curve::LATENTS)?,
        variant: c.constant_str(curve::VARIANT)?.into(),
        tag: None,
    };
    let seed = c.constant_i64(curve::SEED)?;
    let epoch = c.i64s(curve::EPOCH)?;
    let n_outcomes = c.i64s(curve::N_OUTCOMES)?;
    let klc = c.f64s(curve::KLC)?;
    let n_moved = c.i64s(curve::N_MOVED)?;
    let coverage = c.f64s(curve::COVERAGE)?;
    if let Some(i) = klc.iter().position(|k| k.is_nan()) {
        return Err(column_error(
            &curve_path,
            curve::KLC,
            format!("NaN at row {i}"),
        ));
    }
    let mut curve: Vec<CurvePoint> = (0..df.height())
        .map(|i| CurvePoint {
            epoch: epoch[i],
            n_outcomes: n_outcomes[i],
            klc: klc[i],
            n_moved: n_moved[i],
            coverage: coverage[i],
        })
        .collect();
    curve.sort_by_key(|p| p.epoch);
    if let Some(w) = curve.windows(2).find(|w| w[0].epoch == w[1].epoch) {
        return Err(column_error(
            &curve_path,
            curve::EPOCH,
            format!("epoch {} appears twice", w[0].epoch),
        ));
    }
    let expected_stem = stem_name(stem);
    if run_id != expected_stem {
        return Err(column_error(
            &curve_path,
            curve::RUN_ID,
            format!("holds `{run_id}` but the file is named `{expected_stem}`"),
        ));
    }

    let outcomes = if outcomes_path.is_file() {
        read_outcomes(&outcomes_path, &run_id)?
    } else if manifest.discovery.is_some() {
        Vec::new()
    } else {
        return Err(ReportError::Invalid {
            path: outcomes_path,
            problem: "is missing, and the run's manifest records no discovery measures (written \
                      before results version 4): restore the file, or resume the campaign to \
                      recompute the run"
                .into(),
        });
    };

    let mut key = key;
    reconcile_identity(&mut key, seed, &manifest, &manifest_path)?;
    if let Some(recorded) = &manifest.discovery {
        check_discovery(recorded, &key.env, &curve, &outcomes, &manifest_path)?;
    }
    let dir = manifest_path.parent().unwrap_or(Path::new("."));
    let diagnostics =
        ugl_types::Diagnostics::read(dir, &run_id).map_err(|e| ReportError::Invalid {
            path: ugl_types::Diagnostics::path(dir, &run_id),
            problem: e.to_string(),
        })?;
    let mut manifest = manifest;
    if let Some(d) = &diagnostics {
        manifest.latent_quality = Some(d.latent_quality.clone());
    }

    let run = Run {
        run_id,
        campaign,
        key,
        seed,
        curve,
        outcomes,
        manifest,
        diagnostics,
        curve_path,
        outcomes_path,
        manifest_path,
        measured: Default::default(),
    };
    // A run without a record is measured here, on the loader's thread (every core).
    if run.manifest.discovery.is_none() {
        let _ = run.discovery();
    }
    Ok(run)
}

/// A manifest's discovery record (already checked against its hash and the summary,
/// [`ugl_types::verify_files`]) against the run's data files: its counts, KL-coverage and
/// coverage against the curve's last point, and, where the outcomes file is kept, every measure
/// against the same measures recomputed from it. A record that differs is an error naming the
/// manifest and the field: the leaderboard and the validity check rank runs by these numbers.
fn check_discovery(
    recorded: &ugl_types::RunDiscovery,
    env: &str,
    curve: &[CurvePoint],
    outcomes: &[Outcome],
    manifest_path: &Path,
) -> Result<(), ReportError> {
    let invalid = |why: String| ReportError::Invalid {
        path: manifest_path.to_path_buf(),
        problem: format!("{why}; resume the campaign to recompute the run"),
    };
    let a = &recorded.at_end;
    if let Some(last) = curve.last() {
        let same = i64::try_from(a.n_moved).is_ok_and(|n| n == last.n_moved)
            && (a.klc == last.klc || (a.klc - last.klc).abs() <= 1e-9 * a.klc.abs())
            && (a.coverage - last.coverage).abs() <= 1e-9;
        if !same {
            return Err(invalid(format!(
                "its discovery record (n_moved {}, klc {}, coverage {}) is not the curve's last \
                 point (n_moved {}, klc {}, coverage {})",
                a.n_moved, a.klc, a.coverage, last.n_moved, last.klc, last.coverage
            )));
        }
    }
    if outcomes.is_empty() {
        return Ok(());
    }
    let spec = ugl_types::EnvSpec::by_name(env)
        .ok_or_else(|| invalid(format!("unknown environment {env}")))?;
    match ugl_types::RunDiscovery::measure(spec, outcomes) {
        Ok(Some(computed)) => recorded
            .check_against(&computed)
            .map_err(|e| invalid(e.to_string())),
        Ok(None) => Ok(()),
        Err(e) => Err(invalid(e.to_string())),
    }
}

/// Reads a run's outcomes file, whose `run_id` column must be the curve file's `run_id`.
fn read_outcomes(path: &Path, run_id: &str) -> Result<Vec<Outcome>, ReportError> {
    let odf = read_parquet(path)?;
    let o = Cols { df: &odf, path };
    if odf.height() > 0 {
        let orun = o.constant_str(outcomes::RUN_ID)?;
        if orun != *run_id {
            return Err(column_error(
                path,
                outcomes::RUN_ID,
                format!("holds `{orun}`, the curve file holds `{run_id}`"),
            ));
        }
    } else {
        o.require(outcomes::RUN_ID)?;
    }
    let index = o.i64s(outcomes::INDEX)?;
    let oepoch = o.i64s(outcomes::EPOCH)?;
    let x = o.f64s(outcomes::X)?;
    let y = o.f64s(outcomes::Y)?;
    let angle = o.f64s_nullable(outcomes::ANGLE)?;
    let moved = o.bools(outcomes::MOVED)?;
    Ok((0..odf.height())
        .map(|i| Outcome {
            index: index[i],
            epoch: oepoch[i],
            x: x[i],
            y: y[i],
            angle: angle[i],
            moved: moved[i],
        })
        .collect())
}

/// Checks the curve file's identity columns against the manifest's fields of the same name
/// (those present): a disagreement is an error naming the manifest and the field.
///
/// One exception, a known defect of the writer: ugl-bench's curve files wrote `variant = none` for
/// every run, also for the faithful and corrected variants of the VAE and RFVAE, whose manifests
/// (and run ids) carry the variant. A curve file's `none` therefore gives way to the manifest's
/// variant; without this the two variants would be merged into one condition.
pub fn reconcile_identity(
    key: &mut ConditionKey,
    seed: i64,
    manifest: &Manifest,
    manifest_path: &Path,
) -> Result<(), ReportError> {
    let mismatch = |field: &str, curve: String, man: String| ReportError::Invalid {
        path: manifest_path.to_path_buf(),
        problem: format!("field `{field}` is `{man}` but the curve file's column holds `{curve}`"),
    };
    for (field, value, m) in [
        ("env", key.env.as_str(), manifest.env.as_str()),
        ("algo", key.algo.as_str(), manifest.algo.as_str()),
        ("sampler", key.sampler.as_str(), manifest.sampler.as_str()),
    ] {
        if m != value {
            return Err(mismatch(field, value.to_string(), m.to_string()));
        }
    }
    for (field, value, m) in [
        ("latents", key.latents, manifest.latents as i64),
        ("seed", seed, manifest.seed as i64),
    ] {
        if m != value {
            return Err(mismatch(field, value.to_string(), m.to_string()));
        }
    }
    if manifest.variant != key.variant {
        if key.variant == ugl_types::Variant::NONE {
            key.variant = manifest.variant.clone().into();
        } else {
            return Err(mismatch(
                "variant",
                key.variant.to_string(),
                manifest.variant.clone(),
            ));
        }
    }
    Ok(())
}

/// Reads a parquet file into a DataFrame. Errors (and panics inside the reader, which a corrupt
/// file can trigger) become a [`ReportError::Parquet`] naming the file.
pub fn read_parquet(path: &Path) -> Result<DataFrame, ReportError> {
    let file = File::open(path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        ParquetReader::new(file)
            .read_parallel(ParallelStrategy::None)
            .finish()
    }));
    match result {
        Ok(Ok(df)) => Ok(df),
        Ok(Err(e)) => Err(ReportError::Parquet {
            path: path.to_path_buf(),
            message: e.to_string(),
        }),
        Err(_) => Err(ReportError::Parquet {
            path: path.to_path_buf(),
            message: "the parquet reader panicked (corrupt file?)".into(),
        }),
    }
}

fn column_error(path: &Path, column: &str, problem: impl Into<String>) -> ReportError {
    ReportError::Column {
        path: path.to_path_buf(),
        column: column.to_string(),
        problem: problem.into(),
    }
}

/// Typed, checked access to the columns of one file.
pub(crate) struct Cols<'a> {
    pub(crate) df: &'a DataFrame,
    pub(crate) path: &'a Path,
}

impl Cols<'_> {
    pub(crate) fn require(&self, name: &str) -> Result<&Column, ReportError> {
        self.df.column(name).map_err(|_| {
            let mut present: Vec<String> = self
                .df
                .get_column_names()
                .iter()
                .map(|n| n.to_string())
                .collect();
            present.sort();
            column_error(
                self.path,
                name,
                format!("missing (columns present: {})", present.join(", ")),
            )
        })
    }

    fn typed<'c, T>(
        &self,
        name: &str,
        col: &'c Column,
        expected: &str,
        get: impl Fn(&'c Column) -> PolarsResult<&'c T>,
    ) -> Result<&'c T, ReportError> {
        get(col).map_err(|_| {
            column_error(
                self.path,
                name,
                format!("has type {}, expected {expected}", col.dtype()),
            )
        })
    }

    fn no_nulls(&self, name: &str, col: &Column) -> Result<(), ReportError> {
        let nulls = col.null_count();
        if nulls > 0 {
            return Err(column_error(
                self.path,
                name,
                format!("{nulls} null value(s)"),
            ));
        }
        Ok(())
    }

    pub(crate) fn strs(&self, name: &str) -> Result<Vec<String>, ReportError> {
        let col = self.require(name)?;
        let ca = self.typed(name, col, "str", Column::str)?;
        self.no_nulls(name, col)?;
        Ok(ca
            .iter()
            .map(|v| v.unwrap_or_default().to_string())
            .collect())
    }

    pub(crate) fn i64s(&self, name: &str) -> Result<Vec<i64>, ReportError> {
        let col = self.require(name)?;
        let ca = self.typed(name, col, "i64", Column::i64)?;
        self.no_nulls(name, col)?;
        Ok(ca.iter().map(|v| v.unwrap_or_default()).collect())
    }

    pub(crate) fn f64s(&self, name: &str) -> Result<Vec<f64>, ReportError> {
        let col = self.require(name)?;
        let ca = self.typed(name, col, "f64", Column::f64)?;
        self.no_nulls(name, col)?;
        Ok(ca.iter().map(|v| v.unwrap_or_default()).collect())
    }

    pub(crate) fn f64s_nullable(&self, name: &str) -> Result<Vec<Option<f64>>, ReportError> {
        let col = self.require(name)?;
        // An all-null column may have been written with the Null type.
        if col.dtype() == &DataType::Null {
            return Ok(vec![None; col.len()]);
        }
        let ca = self.typed(name, col, "f64", Column::f64)?;
        Ok(ca.iter().collect())
    }

    fn bools(&self, name: &str) -> Result<Vec<bool>, ReportError> {
        let col = self.require(name)?;
        let ca = self.typed(name, col, "bool", Column::bool)?;
        self.no_nulls(name, col)?;
        Ok(ca.iter().map(|v| v.unwrap_or_default()).collect())
    }

    fn constant_str(&self, name: &str) -> Result<String, ReportError> {
        let v = self.strs(name)?;
        let Some(first) = v.first() else {
            return Err(column_error(self.path, name, "the file has no rows"));
        };
        if let Some(other) = v.iter().find(|s| *s != first) {
            return Err(column_error(
                self.path,
                name,
                format!("not constant within the run (`{first}` and `{other}`)"),
            ));
        }
        Ok(first.clone())
    }

    fn constant_i64(&self, name: &str) -> Result<i64, ReportError> {
        let v = self.i64s(name)?;
        let Some(&first) = v.first() else {
            return Err(column_error(self.path, name, "the file has no rows"));
        };
        if let Some(other) = v.iter().find(|s| **s != first) {
            return Err(column_error(
                self.path,
                name,
                format!("not constant within the run ({first} and {other})"),
            ));
        }
        Ok(first)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_id_twice_in_one_campaign_is_an_error_naming_both_files() {
        let (a, b, c) = (
            Path::new("p/x.parquet"),
            Path::new("q/x.parquet"),
            Path::new("p/y.parquet"),
        );
        assert!(check_unique_run_ids([("x", a), ("y", c)]).is_ok());
        let err = check_unique_run_ids([("x", a), ("y", c), ("x", b)]).unwrap_err();
        match &err {
            ReportError::DuplicateRun {
                run_id,
                first,
                second,
            } => {
                assert_eq!(run_id, "x");
                assert_eq!((first.as_path(), second.as_path()), (a, b));
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(err.to_string().contains("twice in one campaign"), "{err}");
    }

    fn key(variant: &str) -> ConditionKey {
        ConditionKey {
            env: "armball".into(),
            algo: "rge-vae".into(),
            sampler: "kde".into(),
            latents: 10,
            variant: variant.into(),
            tag: None,
        }
    }

    #[test]
    fn the_manifest_variant_replaces_a_curve_file_none() {
        let p = Path::new("m.json");
        let m = test_manifest(serde_json::json!({"env": "armball", "algo": "rge-vae",
            "sampler": "kde", "latents": 10, "seed": 3, "variant": "corrected"}));
        let mut k = key("none");
        reconcile_identity(&mut k, 3, &m, p).unwrap();
        assert_eq!(k.variant, "corrected");
        // Agreement, or no field, changes nothing.
        let mut k = key("corrected");
        reconcile_identity(&mut k, 3, &m, p).unwrap();
        assert_eq!(k, key("corrected"));
        // A real disagreement is an error naming the field.
        let mut k = key("faithful");
        let e = reconcile_identity(&mut k, 3, &m, p).unwrap_err();
        assert!(e.to_string().contains("`variant`"), "{e}");
        let e = reconcile_identity(&mut key("corrected"), 4, &m, p).unwrap_err();
        assert!(
            e.to_string().contains("`seed`") && e.to_string().contains("m.json"),
            "{e}"
        );
    }

    #[test]
    fn campaign_display_names_the_top_level() {
        assert_eq!(campaign_display(""), "(top level)");
        assert_eq!(campaign_display("paper"), "paper");
    }
}
