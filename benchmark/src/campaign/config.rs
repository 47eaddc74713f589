//! Campaign configuration (TOML; `data/campaigns/NAME.toml`). Every budget lives here, never in
//! code; the defaults of the `explore` and `env` sections are the paper's values.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::env::{EnvConfig, EnvKind};
use crate::explore::{Algo, ExploreConfig, Learner, SamplerKind};
use crate::repr::isomap::Disconnected;
use crate::repr::neural::{Model, NeuralConfig, NeuralSection, Variant};

/// Errors reading or validating a configuration.
#[derive(Debug, Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read config {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// TOML syntax or schema error (unknown key, wrong type...).
    #[error("invalid config {path}: {message}")]
    Parse { path: PathBuf, message: String },
    /// A value is out of range or contradictory.
    #[error("invalid config {path}: {message}")]
    Invalid { path: PathBuf, message: String },
    /// A profile name that matches no file.
    #[error("unknown profile '{name}': no file {tried}")]
    UnknownProfile { name: String, tried: PathBuf },
}

/// The `[campaign]` section.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignSection {
    /// Name of the campaign (also the default results sub-directory).
    pub name: String,
    /// The campaign seed; every run seed derives from it and the run identity.
    #[serde(default)]
    pub seed: u64,
    /// Repetitions (seeds) per cell of the matrix.
    pub reps: usize,
    /// Free text shown in the report.
    #[serde(default)]
    pub description: String,
}

/// The `[matrix]` section: which cells to run. Learned goal spaces (`rge-*` except `rge-efr`)
/// are crossed with `samplers` and `latents`; the baselines ignore those two lists.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Matrix {
    /// Environments.
    pub envs: Vec<EnvKind>,
    /// Algorithms.
    pub algos: Vec<Algo>,
    /// Goal samplers of the learned goal spaces (`kde`, `gaussian`).
    #[serde(default = "default_samplers")]
    pub samplers: Vec<SamplerKind>,
    /// Latent sizes: numbers, or `"true"` for the environment's true dimension (2 / 3).
    #[serde(default = "default_latents")]
    pub latents: Vec<LatentSize>,
    /// Variants of the VAE and RFVAE (`faithful`, `corrected`; PAPER-NOTES.md section 5).
    /// The other learners have one behaviour and ignore this list.
    #[serde(default = "default_variants")]
    pub variants: Vec<Variant>,
}

fn default_variants() -> Vec<Variant> {
    vec![Variant::Faithful]
}

fn default_samplers() -> Vec<SamplerKind> {
    vec![SamplerKind::Kde]
}

fn default_latents() -> Vec<LatentSize> {
    vec![LatentSize::N(10)]
}

/// A latent size in the matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LatentSize {
    /// A fixed size.
    N(usize),
    /// The environment's true dimension: 2 (ArmBall) or 3 (ArmArrow).
    TrueDim,
}

impl Serialize for LatentSize {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            LatentSize::N(n) => s.serialize_u64(*n as u64),
            LatentSize::TrueDim => s.serialize_str("true"),
        }
    }
}

impl<'de> Deserialize<'de> for LatentSize {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            N(i64),
            S(String),
        }
        match Raw::deserialize(d)? {
            Raw::N(n) if n >= 1 => Ok(LatentSize::N(n as usize)),
            Raw::N(n) => Err(serde::de::Error::custom(format!(
                "matrix.latents: {n} must be at least 1"
            ))),
            Raw::S(s) if s == "true" => Ok(LatentSize::TrueDim),
            Raw::S(s) => Err(serde::de::Error::custom(format!(
                "matrix.latents: '{s}' is neither a number nor \"true\""
            ))),
        }
    }
}

/// The `[ugl]` section: the unsupervised goal-space learning stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct UglConfig {
    /// Images in the passive observation data set (the paper: 10,000).
    pub images: usize,
}

impl Default for UglConfig {
    fn default() -> Self {
        UglConfig { images: 10_000 }
    }
}

/// The `[learners]` section: hyperparameters of each learner.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct LearnersConfig {
    pub isomap: IsomapConfig,
    pub external: Option<ExternalConfig>,
    /// `[learners.ae]`: training budget and architecture; missing keys take the paper's values.
    pub ae: NeuralSection,
    /// `[learners.vae]`.
    pub vae: NeuralSection,
    /// `[learners.rfvae]`.
    pub rfvae: NeuralSection,
}

impl LearnersConfig {
    /// The configuration section of a neural model.
    pub fn neural(&self, model: Model) -> &NeuralSection {
        match model {
            Model::Ae => &self.ae,
            Model::Vae => &self.vae,
            Model::Rfvae => &self.rfvae,
        }
    }

    /// The complete training configuration of a neural model and variant.
    pub fn neural_config(&self, model: Model, variant: Variant) -> NeuralConfig {
        self.neural(model).resolve(model, variant)
    }

    /// The part of the configuration a learner depends on (hashed into its runs' config hash,
    /// so changing the VAE budget reruns only the VAE's runs).
    pub fn hash_value(&self, learner: Learner, variant: Option<Variant>) -> serde_json::Value {
        let v = match learner {
            Learner::Pca | Learner::PcaCentred => serde_json::Value::Null,
            Learner::Isomap => serde_json::to_value(&self.isomap).expect("serialisable"),
            Learner::External => {
                serde_json::to_value(self.external.as_ref().map(ExternalConfig::identity))
                    .expect("serialisable")
            }
            Learner::Ae | Learner::Vae | Learner::Rfvae => {
                let model = learner.model().expect("neural");
                serde_json::to_value(self.neural_config(model, variant.unwrap_or_default()))
                    .expect("serialisable")
            }
        };
        serde_json::json!({ learner.name(): v })
    }
}

/// `[learners.isomap]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IsomapConfig {
    /// Neighbours of the kNN graph (sklearn's default, used by the paper: 5).
    pub n_neighbors: usize,
    /// What to do when the kNN graph is disconnected: `connect-closest-pairs` (sklearn >= 1.0;
    /// the default) or `error`. With 10,000 ArmBall images it always is: positions are
    /// truncated to pixels, so groups of 6+ identical images are each other's only neighbours.
    /// The paper's sklearn (< 1.0) silently set the distances between pieces to 0, a defect we
    /// do not reproduce.
    pub disconnected: Disconnected,
}

impl Default for IsomapConfig {
    fn default() -> Self {
        IsomapConfig {
            n_neighbors: 5,
            disconnected: Disconnected::ConnectClosestPairs,
        }
    }
}

/// `[learners.external]`: a learner program speaking the protocol of `docs/external-learners.md`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalConfig {
    /// A short name for results and the report.
    pub name: String,
    /// The command line (run with `sh -c`).
    pub command: String,
    /// Seconds allowed from the program's start to its `READY` line, i.e. its whole fit
    /// (default 3600). Not part of the runs' identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ready_timeout_s: Option<f64>,
    /// Seconds allowed for each encode answer (default 300). Not part of the runs' identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub answer_timeout_s: Option<f64>,
}

impl ExternalConfig {
    /// What the runs depend on: the name and the command (not the timeouts).
    pub fn identity(&self) -> ExternalConfig {
        ExternalConfig {
            name: self.name.clone(),
            command: self.command.clone(),
            ready_timeout_s: None,
            answer_timeout_s: None,
        }
    }
}

/// A whole campaign configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignConfig {
    pub campaign: CampaignSection,
    pub matrix: Matrix,
    #[serde(default)]
    pub explore: ExploreConfig,
    #[serde(default)]
    pub env: EnvConfig,
    #[serde(default)]
    pub ugl: UglConfig,
    #[serde(default)]
    pub learners: LearnersConfig,
}

impl CampaignConfig {
    /// Parse and validate TOML text; `path` is only used in error messages.
    pub fn from_toml(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let cfg: CampaignConfig = toml::from_str(text).map_err(|e| ConfigError::Parse {
            path: path.to_path_buf(),
            message: one_line(&e.to_string()),
        })?;
        cfg.validate().map_err(|message| ConfigError::Invalid {
            path: path.to_path_buf(),
            message,
        })?;
        Ok(cfg)
    }

    /// Read and validate a file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml(&text, path)
    }

    /// Check every value; the message names the key.
    pub fn validate(&self) -> Result<(), String> {
        if self.campaign.name.is_empty()
            || !self
                .campaign
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(format!(
                "campaign.name must be non-empty and use only letters, digits, '-' and '_', got '{}'",
                self.campaign.name
            ));
        }
        if self.campaign.reps == 0 {
            return Err("campaign.reps must be at least 1".into());
        }
        if self.matrix.envs.is_empty() {
            return Err("matrix.envs must name at least one environment".into());
        }
        if self.matrix.algos.is_empty() {
            return Err("matrix.algos must name at least one algorithm".into());
        }
        for (k, list) in [
            ("matrix.envs", dup(&self.matrix.envs)),
            ("matrix.algos", dup(&self.matrix.algos)),
            ("matrix.samplers", dup(&self.matrix.samplers)),
            ("matrix.variants", dup(&self.matrix.variants)),
        ] {
            if let Some(d) = list {
                return Err(format!("{k} lists '{d}' twice"));
            }
        }
        if self.matrix.samplers.is_empty() {
            return Err("matrix.samplers must name at least one goal sampler".into());
        }
        if let Some(s) = self
            .matrix
            .samplers
            .iter()
            .find(|s| !matches!(s, SamplerKind::Kde | SamplerKind::Gaussian))
        {
            return Err(format!(
                "matrix.samplers: '{s}' is not a sampler of learned goal spaces (kde, gaussian)"
            ));
        }
        if self.matrix.latents.is_empty() {
            return Err("matrix.latents must list at least one latent size".into());
        }
        crate::limits::check_runs(&[
            ("envs", self.matrix.envs.len()),
            ("algos", self.matrix.algos.len()),
            ("samplers", self.matrix.samplers.len()),
            ("latent sizes", self.matrix.latents.len()),
            ("variants", self.matrix.variants.len()),
            ("reps", self.campaign.reps),
        ])?;
        if self.matrix.variants.is_empty() {
            return Err(
                "matrix.variants must list at least one variant (faithful, corrected)".into(),
            );
        }
        for model in Model::ALL {
            if model != Model::Rfvae && self.learners.neural(model).warmup.is_some() {
                return Err(format!(
                    "learners.{}.warmup: only the rfvae has a KL warm-up",
                    model.name()
                ));
            }
            self.learners
                .neural_config(model, Variant::Faithful)
                .validate(model, &format!("learners.{}", model.name()))
                .map_err(|e| match e {
                    crate::repr::ReprError::InvalidInput(m) => m,
                    other => other.to_string(),
                })?;
        }
        let learned = self.matrix.algos.iter().any(|a| a.learner().is_some());
        if learned && self.ugl.images < 2 {
            return Err(format!(
                "ugl.images must be at least 2, got {}",
                self.ugl.images
            ));
        }
        if learned {
            crate::limits::check_images(self.ugl.images)?;
        }
        if let Some(LatentSize::N(n)) = self
            .matrix
            .latents
            .iter()
            .find(|l| matches!(l, LatentSize::N(n) if *n >= self.ugl.images))
        {
            return Err(format!(
                "matrix.latents: {n} must be below ugl.images ({})",
                self.ugl.images
            ));
        }
        if self.learners.isomap.n_neighbors == 0 {
            return Err("learners.isomap.n_neighbors must be at least 1".into());
        }
        if self.matrix.algos.contains(&Algo::Rge(Learner::External))
            && self.learners.external.is_none()
        {
            return Err("matrix.algos has rge-external but there is no [learners.external] section (name, command)".into());
        }
        if let Some(e) = &self.learners.external {
            if e.command.trim().is_empty() || e.name.trim().is_empty() {
                return Err(
                    "learners.external.name and learners.external.command must not be empty".into(),
                );
            }
            for (key, v) in [
                ("ready_timeout_s", e.ready_timeout_s),
                ("answer_timeout_s", e.answer_timeout_s),
            ] {
                if let Some(v) = v
                    && !(v.is_finite() && v > 0.0 && v <= 1e7)
                {
                    return Err(format!(
                        "learners.external.{key} must be a positive number of seconds (at most 1e7), got {v}"
                    ));
                }
            }
        }
        self.explore.validate()?;
        validate_env(&self.env)
    }
}

fn dup<T: PartialEq + std::fmt::Display>(v: &[T]) -> Option<String> {
    v.iter()
        .enumerate()
        .find(|(i, a)| v[..*i].contains(a))
        .map(|(_, a)| a.to_string())
}

fn validate_env(e: &EnvConfig) -> Result<(), String> {
    if e.arm.lengths.iter().any(|l| !(l.is_finite() && *l >= 0.0)) {
        return Err("env.arm.lengths must be finite and >= 0".into());
    }
    if !(e.object_size.is_finite() && e.object_size > 0.0) {
        return Err(format!(
            "env.object_size must be > 0, got {}",
            e.object_size
        ));
    }
    if e.dmp.timesteps == 0 {
        return Err("env.dmp.timesteps must be at least 1".into());
    }
    if !(e.dmp.run_time.is_finite() && e.dmp.run_time > 0.0) {
        return Err("env.dmp.run_time must be > 0".into());
    }
    for (k, v) in [
        ("env.dmp.ay", e.dmp.ay),
        ("env.dmp.ax", e.dmp.ax),
        ("env.dmp.max_params", e.dmp.max_params),
    ] {
        if !v.is_finite() {
            return Err(format!("{k} must be finite"));
        }
    }
    let inside = |p: &[f64]| p.iter().all(|v| (-1.0..=1.0).contains(v));
    if !inside(&e.ball_initial) || !inside(&e.arrow_initial) {
        return Err("env.ball_initial / env.arrow_initial must lie in [-1,1]".into());
    }
    Ok(())
}

/// A (possibly multi-line) TOML error as one line: the reason, the position and the offending
/// source line (which names the key), e.g.
/// `invalid value: integer `-5`, expected usize (line 9, column 10: `epochs = -5`)`.
pub(crate) fn one_line(s: &str) -> String {
    let lines: Vec<&str> = s.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    let Some(first) = lines.first() else {
        return String::new();
    };
    let Some(pos) = first.strip_prefix("TOML parse error at ") else {
        return first.to_string();
    };
    // The snippet line looks like "9 | epochs = -5"; the reason is the last line that is not
    // part of the snippet.
    let source = lines.iter().find_map(|l| {
        let (num, text) = l.split_once('|')?;
        (!num.trim().is_empty() && num.trim().chars().all(|c| c.is_ascii_digit()))
            .then(|| text.trim())
    });
    let reason = lines
        .iter()
        .rev()
        .find(|l| !l.starts_with('|') && !l.contains(" | ") && !l.starts_with("TOML parse error"));
    match (reason, source) {
        (Some(r), Some(src)) => format!("{r} ({pos}: `{src}`)"),
        (Some(r), None) => format!("{r} ({pos})"),
        _ => first.to_string(),
    }
}

/// Where profiles live: `data/campaigns/` under the current directory if it exists, else under
/// the source checkout this binary was built from.
pub fn campaigns_dir() -> PathBuf {
    let local = PathBuf::from("data/campaigns");
    if local.is_dir() {
        return local;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/campaigns")
}

/// Resolve `--profile NAME` (a name in `data/campaigns/` or a path to a .toml file).
pub fn resolve_profile(name: &str) -> Result<PathBuf, ConfigError> {
    let p = Path::new(name);
    if name.ends_with(".toml") || name.contains('/') {
        return Ok(p.to_path_buf());
    }
    let path = campaigns_dir().join(format!("{name}.toml"));
    if path.is_file() {
        Ok(path)
    } else {
        Err(ConfigError::UnknownProfile {
            name: name.into(),
            tried: path,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[campaign]
name = "t"
reps = 2
[matrix]
envs = ["armball"]
algos = ["rpe", "rge-efr"]
[explore]
epochs = 50
"#;

    #[test]
    fn parses_with_paper_defaults() {
        let c = CampaignConfig::from_toml(GOOD, Path::new("t.toml")).unwrap();
        assert_eq!(c.explore.epochs, 50);
        assert_eq!(c.explore.bootstrap_epochs, 100);
        assert_eq!(c.explore.random_ratio, 0.2);
        assert_eq!(c.env, EnvConfig::default());
    }

    #[test]
    fn errors_name_the_key() {
        let cases = [
            (GOOD.replace("reps = 2", "reps = 0"), "campaign.reps"),
            (
                GOOD.replace("epochs = 50", "epochs = 50\nbogus = 1"),
                "bogus",
            ),
            (GOOD.replace("\"rpe\"", "\"rge-foo\""), "rge-foo"),
            (GOOD.replace("epochs = 50", "epochs = -5"), "epochs"),
            (GOOD.replace("epochs = 50", "epochs = \"many\""), "epochs"),
            (
                GOOD.replace("epochs = 50", "random_ratio = 1.5"),
                "explore.random_ratio",
            ),
            (GOOD.replace("\"rpe\", ", "\"rge-efr\", "), "matrix.algos"),
        ];
        for (text, key) in cases {
            let e = CampaignConfig::from_toml(&text, Path::new("t.toml"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(key), "{e} should name {key}");
            assert!(!e.contains('\n'), "one line: {e}");
        }
    }
}
