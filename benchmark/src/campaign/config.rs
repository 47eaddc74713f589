//! Campaign configuration (TOML; `data/campaigns/NAME.toml`). Every budget lives here, never in
//! code; the defaults of the `explore` and `env` sections are the paper's values.

use crate::invalid::InvalidValue;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;
use ugl_types::{CampaignDecl, CampaignRole};

use crate::env::{EnvConfig, EnvKind};
use crate::explore::{Algo, ExploreConfig, SamplerKind};
pub use crate::repr::external::ExternalConfig;
use crate::repr::external::ExternalParams;
pub use crate::repr::isomap::IsomapConfig;
use crate::repr::neural::Variant;
use crate::repr::registry::{self, Learner, LearnerParamError, LearnerParams, ParamError};

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

fn one() -> usize {
    1
}

fn is_one(n: &usize) -> bool {
    *n == 1
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
    /// Repetitions (seeds) per cell of the matrix: each has its own data set, fitted goal
    /// space and exploration streams.
    pub reps: usize,
    /// Exploration runs per repetition (default 1): each explores the repetition's fitted goal
    /// space with its own streams, so that the spread due to the fit and the spread due to
    /// exploration can be told apart. Not part of any run's identity beyond its replicate index.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub explorations: usize,
    /// Free text shown in the report.
    #[serde(default)]
    pub description: String,
    /// What the campaign is for in the report (`main`, `budget`, `compare`, `recipe`,
    /// `followup`; default `main`). Recorded beside the runs and in their manifests; not part
    /// of any run's identity or config hash.
    #[serde(default)]
    pub role: CampaignRole,
    /// The campaign this one is a variant of (recipe and compare campaigns: the main campaign
    /// whose cells and seeds they share; follow-up variants: the follow-up campaign).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant_of: Option<String>,
    /// A short name for its conditions beside the campaign it varies (`still`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tag: Option<String>,
    /// How the report names the variant (`still distractor`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

impl CampaignSection {
    /// The campaign's declaration of its role.
    pub fn decl(&self) -> CampaignDecl {
        CampaignDecl {
            role: self.role,
            variant_of: self.variant_of.clone(),
            tag: self.tag.clone(),
            label: self.label.clone(),
        }
    }
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
    /// Variants of the VAE and RFVAE (`faithful`, `corrected`; docs/original-code.md section 5).
    /// The other learners have one behaviour and ignore this list.
    #[serde(default = "default_variants")]
    pub variants: Vec<Variant>,
}

fn default_variants() -> Vec<Variant> {
    vec![Variant::Faithful]
}

fn default_samplers() -> Vec<SamplerKind> {
    vec![SamplerKind::KDE]
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

impl LatentSize {
    /// The number of latents in `env`.
    pub fn size(self, env: EnvKind) -> usize {
        match self {
            LatentSize::N(n) => n,
            LatentSize::TrueDim => env.spec().true_latents,
        }
    }
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

/// The `[learners]` section: one free-form `[learners.NAME]` table per learner of the registry
/// ([`crate::repr::registry`]), parsed and checked by the learner's own entry. Missing tables take
/// the learner's defaults (the paper's values).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(transparent)]
pub struct LearnersConfig {
    tables: BTreeMap<String, toml::Value>,
}

impl LearnersConfig {
    /// The checked parameters of `learner`; the error names the learner and the key
    /// (`learners.vae.warmup: ...`).
    pub fn params(&self, learner: Learner) -> Result<Box<dyn LearnerParams>, LearnerParamError> {
        (learner.entry().params)(self.tables.get(learner.name())).map_err(|error| {
            LearnerParamError {
                learner: learner.name().to_string(),
                error,
            }
        })
    }

    /// Set the `[learners.NAME]` table (e.g. an external program given on the command line).
    pub fn set_table(&mut self, name: &str, table: toml::Value) {
        self.tables.insert(name.to_string(), table);
    }

    /// The `[learners.external]` program, if the section is there and valid.
    pub fn external(&self) -> Option<ExternalConfig> {
        let l = Learner::all().find(|l| l.is_external())?;
        let p = self.params(l).ok()?;
        let e = p.as_any().downcast_ref::<ExternalParams>()?;
        Some(e.config().clone())
    }

    /// Set `[learners.external]`.
    pub fn set_external(&mut self, e: &ExternalConfig) {
        let l = Learner::all()
            .find(|l| l.is_external())
            .expect("registered");
        self.set_table(
            l.name(),
            toml::Value::try_from(e).expect("an external config serialises"),
        );
    }

    /// The part of the configuration a learner depends on (hashed into its runs' config hash,
    /// so changing the VAE budget reruns only the VAE's runs): `{name: identity}`, with a null
    /// identity where the table does not parse (validation rejects such a campaign first).
    pub fn hash_value(&self, learner: Learner, variant: Option<Variant>) -> serde_json::Value {
        let v = self
            .params(learner)
            .map(|p| p.identity(variant))
            .unwrap_or(serde_json::Value::Null);
        serde_json::json!({ learner.name(): v })
    }

    /// Check every table present, and that each names a registered learner.
    pub fn validate(&self) -> Result<(), LearnerParamError> {
        for name in self.tables.keys() {
            let l = Learner::by_name(name).ok_or_else(|| LearnerParamError {
                learner: name.clone(),
                error: ParamError::table(format!(
                    "no learner is called '{name}' (registered: {})",
                    registry::names().join(", ")
                )),
            })?;
            self.params(l)?;
        }
        Ok(())
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
    /// Modular goal exploration (`mge-*` algorithms; follow-up paper).
    #[serde(default)]
    pub mge: crate::explore::MgeConfig,
}

impl CampaignConfig {
    /// The hash of the campaign's configuration: every constant but the matrix (campaign seed,
    /// `[explore]`, `[env]`, `[ugl]`, `[learners]`, `[mge]`). Runs of two configurations never
    /// share a store ([`super::runner::write_campaign_record`]); adding seeds or cells to the
    /// matrix keeps it, and so does a new results version (its runs supersede the older ones:
    /// their config hashes differ, so a resumed campaign recomputes them).
    pub fn configuration_hash(&self) -> String {
        let input = serde_json::json!({
            "campaign_seed": self.campaign.seed,
            "explore": self.explore,
            "env": self.env,
            "ugl": self.ugl,
            "learners": self.learners,
            "mge": self.mge,
        });
        let json = serde_json::to_vec(&input).expect("a campaign config serialises");
        blake3::hash(&json).to_hex().to_string()
    }

    /// Parse and validate TOML text; `path` is only used in error messages.
    pub fn from_toml(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let cfg: CampaignConfig = toml::from_str(text).map_err(|e| ConfigError::Parse {
            path: path.to_path_buf(),
            message: one_line(&e.to_string()),
        })?;
        // The learners' tables are checked after parsing, without positions: their errors
        // carry the key, and the message gains the line that sets it.
        cfg.learners.validate().map_err(|e| ConfigError::Invalid {
            path: path.to_path_buf(),
            message: with_learner_line(text, &e),
        })?;
        cfg.validate().map_err(|e| ConfigError::Invalid {
            path: path.to_path_buf(),
            message: e.message,
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
    pub fn validate(&self) -> Result<(), InvalidValue> {
        if self.campaign.name.is_empty()
            || !self
                .campaign
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(InvalidValue::new(
                "campaign.name",
                format!(
                    "campaign.name must be non-empty and use only letters, digits, '-' and '_', got '{}'",
                    self.campaign.name
                ),
            ));
        }
        if self.campaign.reps == 0 {
            return Err(InvalidValue::new(
                "campaign.reps",
                "campaign.reps must be at least 1",
            ));
        }
        if self.campaign.explorations == 0 || self.campaign.explorations > u32::MAX as usize {
            return Err(InvalidValue::new(
                "campaign.explorations",
                format!(
                    "campaign.explorations must be between 1 and {}, got {}",
                    u32::MAX,
                    self.campaign.explorations
                ),
            ));
        }
        if self.matrix.envs.is_empty() {
            return Err(InvalidValue::new(
                "matrix.envs",
                "matrix.envs must name at least one environment",
            ));
        }
        if self.matrix.algos.is_empty() {
            return Err(InvalidValue::new(
                "matrix.algos",
                "matrix.algos must name at least one algorithm",
            ));
        }
        for (k, list) in [
            ("matrix.envs", dup(&self.matrix.envs)),
            ("matrix.algos", dup(&self.matrix.algos)),
            ("matrix.samplers", dup(&self.matrix.samplers)),
            ("matrix.variants", dup(&self.matrix.variants)),
        ] {
            if let Some(d) = list {
                return Err(InvalidValue::new(k, format!("{k} lists '{d}' twice")));
            }
        }
        if self.matrix.samplers.is_empty() {
            return Err(InvalidValue::new(
                "matrix.samplers",
                "matrix.samplers must name at least one goal sampler",
            ));
        }
        if let Some(s) = self.matrix.samplers.iter().find(|s| !s.is_learned()) {
            return Err(InvalidValue::new(
                "matrix.samplers",
                format!(
                    "matrix.samplers: '{s}' is not a sampler of learned goal spaces ({})",
                    SamplerKind::learned_names()
                ),
            ));
        }
        if self.matrix.latents.is_empty() {
            return Err(InvalidValue::new(
                "matrix.latents",
                "matrix.latents must list at least one latent size",
            ));
        }
        crate::limits::check_runs(&[
            ("envs", self.matrix.envs.len()),
            ("algos", self.matrix.algos.len()),
            ("samplers", self.matrix.samplers.len()),
            ("latent sizes", self.matrix.latents.len()),
            ("variants", self.matrix.variants.len()),
            ("reps", self.campaign.reps),
            ("explorations", self.campaign.explorations),
        ])
        .map_err(|e| InvalidValue::new("campaign.reps", e.to_string()))?;
        if self.matrix.variants.is_empty() {
            return Err(InvalidValue::new(
                "matrix.variants",
                "matrix.variants must list at least one variant (faithful, corrected)",
            ));
        }
        self.learners
            .validate()
            .map_err(|e| InvalidValue::new("learners", e.to_string()))?;
        self.mge.validate()?;
        // Every size, "true" resolved per environment, before anything is trained.
        for a in self.matrix.algos.iter().filter(|a| a.modules().is_some()) {
            if a.learner().is_some()
                && a.modules() != Some(crate::explore::Modules::Flat)
                && let Some((l, env)) = self.matrix.latents.iter().find_map(|l| {
                    let env = self
                        .matrix
                        .envs
                        .iter()
                        .find(|e| l.size(**e) % self.mge.module_size != 0)?;
                    Some((*l, *env))
                })
            {
                let has = match l {
                    LatentSize::N(n) => n.to_string(),
                    LatentSize::TrueDim => {
                        format!("\"true\" ({} latents in {env})", l.size(env))
                    }
                };
                return Err(InvalidValue::new(
                    "matrix.algos",
                    format!(
                        "matrix.algos has {a}, whose modules take mge.module_size = {} latents, \
                     but matrix.latents has {has}",
                        self.mge.module_size
                    ),
                ));
            }
        }
        for l in self.matrix.algos.iter().filter_map(|a| a.learner()) {
            self.learners.params(l).map_err(|e| {
                InvalidValue::new(
                    "matrix.algos",
                    format!("matrix.algos has {}, but {e}", l.entry().algo),
                )
            })?;
        }
        // A learner built for one kind of picture runs only where the environment renders it.
        for l in self.matrix.algos.iter().filter_map(|a| a.learner()) {
            if let Some(shape) = l.entry().image
                && let Some(env) = self.matrix.envs.iter().find(|e| e.spec().image != shape)
            {
                let pictures = |s: ugl_types::ImageShape| {
                    format!("{} x {} x {}", s.width, s.height, s.channels)
                };
                return Err(InvalidValue::new(
                    "matrix.envs",
                    format!(
                        "matrix.envs has {env}, which renders {} pictures, but matrix.algos has {}, \
                         which takes {} pictures only (give it a campaign of its own)",
                        pictures(env.spec().image),
                        l.entry().algo,
                        pictures(shape)
                    ),
                ));
            }
        }
        let learned = self.matrix.algos.iter().any(|a| a.learner().is_some());
        if learned && self.ugl.images < 2 {
            return Err(InvalidValue::new(
                "ugl.images",
                format!("ugl.images must be at least 2, got {}", self.ugl.images),
            ));
        }
        if learned {
            crate::limits::check_images(
                self.ugl.images,
                crate::limits::image_values(&self.matrix.envs),
            )
            .map_err(|e| InvalidValue::new("ugl.images", e.to_string()))?;
        }
        if let Some(LatentSize::N(n)) = self
            .matrix
            .latents
            .iter()
            .find(|l| matches!(l, LatentSize::N(n) if *n >= self.ugl.images))
        {
            return Err(InvalidValue::new(
                "matrix.latents",
                format!(
                    "matrix.latents: {n} must be below ugl.images ({})",
                    self.ugl.images
                ),
            ));
        }
        self.explore.validate()?;
        self.explore.check_goal_epochs(
            self.matrix
                .algos
                .iter()
                .any(|a| a.strategy() != crate::explore::Strategy::Rpe),
        )?;
        if self.matrix.algos.iter().any(|a| a.space().is_engineered()) {
            self.mge
                .engineered_explore(&self.explore)
                .check_goal_epochs(true)
                .map_err(|e| {
                    InvalidValue::new(
                        "mge.engineered_bootstrap_epochs",
                        format!("mge.engineered_bootstrap_epochs: {e}"),
                    )
                })?;
        }
        self.env.validate()
    }
}

fn dup<T: PartialEq + std::fmt::Display>(v: &[T]) -> Option<String> {
    v.iter()
        .enumerate()
        .find(|(i, a)| v[..*i].contains(a))
        .map(|(_, a)| a.to_string())
}

/// A learner's error with the line of `text` that sets its key: `... (line 9: `init = 1`)`.
fn with_learner_line(text: &str, e: &LearnerParamError) -> String {
    let message = e.to_string();
    let Some(key) = e.error.key.as_deref() else {
        return message;
    };
    // The table's own key (`hidden` of `hidden[1]`).
    let key = key.split(['.', '[']).next().unwrap_or(key);
    match learner_key_line(text, &e.learner, key) {
        Some(at) if !message.contains("(line ") => format!("{message} ({at})"),
        _ => message,
    }
}

/// Where `learners.NAME.KEY` is set in `text`: `line N: `the line``.
fn learner_key_line(text: &str, name: &str, key: &str) -> Option<String> {
    use toml::de::{DeTable, DeValue};
    fn get<'t, 'i>(t: &'t DeTable<'i>, k: &str) -> Option<&'t toml::Spanned<DeValue<'i>>> {
        t.iter().find(|(n, _)| n.get_ref() == k).map(|(_, v)| v)
    }
    let root = DeTable::parse(text).ok()?;
    let DeValue::Table(learners) = get(root.get_ref(), "learners")?.get_ref() else {
        return None;
    };
    let DeValue::Table(table) = get(learners, name)?.get_ref() else {
        return None;
    };
    let (k, _) = table.iter().find(|(n, _)| n.get_ref() == key)?;
    let line = text[..k.span().start].matches('\n').count() + 1;
    let source = text.lines().nth(line - 1)?.trim();
    Some(format!("line {line}: `{source}`"))
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
epochs = 500
"#;

    #[test]
    fn parses_with_paper_defaults() {
        let c = CampaignConfig::from_toml(GOOD, Path::new("t.toml")).unwrap();
        assert_eq!(c.explore.epochs, 500);
        assert_eq!(c.explore.bootstrap_epochs, 100);
        assert_eq!(c.explore.random_ratio, 0.2);
        assert_eq!(c.env, EnvConfig::default());
    }

    #[test]
    fn errors_name_the_key() {
        let cases = [
            (GOOD.replace("reps = 2", "reps = 0"), "campaign.reps"),
            (
                GOOD.replace("epochs = 500", "epochs = 500\nbogus = 1"),
                "bogus",
            ),
            (GOOD.replace("\"rpe\"", "\"rge-foo\""), "rge-foo"),
            (GOOD.replace("epochs = 500", "epochs = -5"), "epochs"),
            (GOOD.replace("epochs = 500", "epochs = \"many\""), "epochs"),
            (
                GOOD.replace("epochs = 500", "random_ratio = 1.5"),
                "explore.random_ratio",
            ),
            (GOOD.replace("\"rpe\", ", "\"rge-efr\", "), "matrix.algos"),
            (
                GOOD.replace("\"rpe\", ", "\"rge-conv-bvae\", "),
                "matrix.envs",
            ),
            (
                format!("{GOOD}[mge]\nengineered_bootstrap_epochs = 500\n"),
                "mge.engineered_bootstrap_epochs",
            ),
        ];
        for (text, key) in cases {
            let e = CampaignConfig::from_toml(&text, Path::new("t.toml"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(key), "{e} should name {key}");
            assert!(!e.contains('\n'), "one line: {e}");
        }
        // The convolutional networks run where the pictures are theirs.
        let corl = GOOD
            .replace("\"armball\"", "\"armballs-corl\"")
            .replace("\"rpe\", ", "\"rge-conv-bvae\", ");
        CampaignConfig::from_toml(&corl, Path::new("t.toml")).unwrap();
    }
}
