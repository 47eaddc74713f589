//! The manifest of a run: everything about it that is not its data (the schema is documented in
//! `data/results/README.md`). The runner writes it last, through [`Manifest`]; the report reads it
//! back through the same type.

use serde::{Deserialize, Serialize};

use crate::campaign::CampaignDecl;

/// Bumped whenever a change alters results for the same configuration.
/// 2: exploration streams of learned goal spaces derive from the run's exploration identity
/// (paired across learners), and a stochastic encoder draws its noise from the run's own stream
/// (order-independent results); the KDE's square root of its covariance comes from faer's
/// symmetric eigen-solver (was: cyclic Jacobi).
/// 3: the neural learners train on the host engine by default (`engine = "host"`: other
/// summation orders than burn's), and gemm/faer use their AVX-512 kernels where the CPU has them.
/// 4: the corrected RFVAE puts its prior N(0, I) on `z_K`, the space its outcomes are encoded
/// in, so that its Gaussian goals are drawn where the outcomes live (its KDE runs change too:
/// the fitted network differs).
/// 5: the same bits on every CPU: the host engine's and Isomap's products are one FMA chain per
/// output (`ugl-kernels`, no gemm/faer), the dense symmetric eigen-solver and the latent-quality
/// solve are plain arithmetic, transcendental functions come from `libm`, and burn's `flex`
/// backend runs without its run-time SIMD dispatch.
pub const RESULTS_VERSION: u32 = 5;

pub use crate::summary::Summary;

/// The CPU of a run.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct CpuInfo {
    /// `model name` of /proc/cpuinfo (`unknown` where there is none).
    pub model: String,
    /// The SIMD level of the CPU (`x86-64-v3`, `x86-64-v4`, ...).
    pub simd: String,
    /// The path the float kernels ran on (`scalar`, `avx2`, `avx512`; `UGL_SIMD` forces one).
    /// Every path gives the same bits (results version 5 on); absent before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kernels: Option<String>,
}

/// Everything about a run that is not its data. Fields added after results version 1 have
/// serde defaults, so that every committed manifest reads through this one type.
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
    /// Exploration replicate of the repetition (0 in campaigns without replicates, and then
    /// not written).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub exploration: u32,
    /// The seed of the run's exploration streams, derived from (campaign seed, the run's
    /// exploration identity).
    pub run_seed: u64,
    pub campaign: String,
    /// What the campaign is for (`[campaign] role` of its TOML); absent in manifests written
    /// before roles were declared (the campaign's [`crate::CampaignRecord`] says it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub role: Option<CampaignDecl>,
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
    /// The crate versions and `results_version`.
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
    /// Training of a neural representation: configuration, loss curve, model-cache status,
    /// evidence that it left the plateau.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub train: Option<crate::TrainingRecord>,
    /// The external learner program (`[learners.external]`: name, command) of an `rge-external`
    /// run, so that the run can be reproduced from its manifest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub external: Option<serde_json::Value>,
    pub host: String,
    /// The CPU model and SIMD level (absent in manifests written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu: Option<CpuInfo>,
    /// Learned goal spaces: held-out R² of a linear and a k-NN map from latents to the true
    /// object state.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latent_quality: Option<crate::quality::LatentQuality>,
    pub summary: Summary,
    /// What the run discovered, measured from its outcomes when it ended (results version 4
    /// on; [`crate::discovery::RunDiscovery`]). A run that records it is complete without its outcomes
    /// file, which the committed stores keep only for some runs (`data/results/README.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub discovery: Option<crate::discovery::RunDiscovery>,
    /// [`crate::discovery::RunDiscovery::digest`] of `discovery` as written, so that an edited record is
    /// detected like a damaged data file ([`crate::verify_files`]). Absent in manifests written
    /// before it was recorded: their records are checked for range and against `summary` only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub discovery_blake3: Option<String>,
    /// The run's data files as written: name, length and BLAKE3 hash. A run is complete only
    /// if its files still match (checked on resume, merge and report). Absent in manifests
    /// written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub files: Option<Vec<FileDigest>>,
}

/// A manifest written by a newer ugl-bench than this one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "written by a newer ugl-bench (results version {found}; this build reads up to \
     {RESULTS_VERSION}): update ugl-bench to read it"
)]
pub struct FutureResults {
    pub found: u64,
}

impl Manifest {
    /// Parses a manifest; the error is serde's, with line and column.
    pub fn from_json(text: &str) -> Result<Manifest, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// The results version the run was written with (`crate_versions.results_version`).
    pub fn results_version(&self) -> Option<u64> {
        self.crate_versions.get("results_version")?.as_u64()
    }

    /// Refuses a manifest written by a newer build (a results version above
    /// [`RESULTS_VERSION`]): its fields may mean what this build does not know.
    pub fn check_results_version(&self) -> Result<(), FutureResults> {
        match self.results_version() {
            Some(found) if found > u64::from(RESULTS_VERSION) => Err(FutureResults { found }),
            _ => Ok(()),
        }
    }

    /// The evidence that the run's network left the mean-image plateau (`train.evidence`);
    /// None for other learners.
    pub fn training_evidence(&self) -> Option<&crate::TrainingEvidence> {
        self.train.as_ref()?.evidence.as_ref()
    }

    /// Whether the run's neural representation left the mean-image plateau
    /// (`train.evidence.trained`); None for other learners and older manifests.
    pub fn trained(&self) -> Option<bool> {
        self.train.as_ref()?.trained()
    }

    /// The (linear, k-NN) R² of a group of targets (`position`, `angle`, `angle_mod_120`) in
    /// the latent quality (measure version 2 and later).
    pub fn group_r2(&self, group: &str) -> Option<(f64, f64)> {
        let g = self.latent_quality.as_ref()?.group(group)?;
        Some((g.linear_r2, g.knn_r2))
    }

    /// `CPU model (SIMD level)`, and `, kernels PATH` where the manifest records the path.
    pub fn cpu_label(&self) -> Option<String> {
        self.cpu.as_ref().map(|c| match &c.kernels {
            Some(path) => format!("{} ({}, kernels {path})", c.model, c.simd),
            None => format!("{} ({})", c.model, c.simd),
        })
    }

    /// The command of an external learner (`external.command`).
    pub fn external_command(&self) -> Option<&str> {
        self.external.as_ref()?.get("command")?.as_str()
    }
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

fn none_string() -> String {
    "none".into()
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every committed manifest, of every results version, reads through the one type, and
    /// writing it back gives the same JSON value (no field is lost or invented).
    #[test]
    fn every_committed_manifest_reads_and_round_trips() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/results");
        let mut n = 0;
        for campaign in std::fs::read_dir(&root).unwrap() {
            let dir = campaign.unwrap().path();
            if !dir.is_dir() {
                continue;
            }
            for f in std::fs::read_dir(&dir).unwrap() {
                let p = f.unwrap().path();
                let name = p.file_name().unwrap().to_string_lossy().to_string();
                if !name.ends_with(".json")
                    || name.starts_with('.')
                    || name == crate::campaign::RECORD_FILE
                {
                    continue;
                }
                let text = std::fs::read_to_string(&p).unwrap();
                let m = Manifest::from_json(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
                let raw: serde_json::Value = serde_json::from_str(&text).unwrap();
                assert_eq!(serde_json::to_value(&m).unwrap(), raw, "{name}");
                n += 1;
            }
        }
        assert!(n > 500, "only {n} manifests found under {}", root.display());
    }

    #[test]
    fn infinite_klc_is_written_as_a_string() {
        let s = Summary {
            run: "r".into(),
            final_klc: f64::INFINITY,
            n_moved: 0,
            coverage: 0.0,
        };
        let j = serde_json::to_string(&s).unwrap();
        assert!(j.contains("\"inf\""), "{j}");
        assert_eq!(serde_json::from_str::<Summary>(&j).unwrap(), s);
        assert!(serde_json::from_str::<Summary>(&j.replace("inf", "nan")).is_err());
    }
}
