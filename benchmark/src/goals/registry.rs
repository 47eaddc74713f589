//! The goal-sampler registry: each entry pairs a sampler's description (`ugl_types::SamplerInfo`,
//! which the report reads) with how to build it over a learned goal space. A new sampler is one
//! file (its `GoalSampler` and its entry) plus one line in [`BUILT_IN`], or [`register`] at run
//! time; `tests/toy_sampler.rs` does that and takes a sampler through `ugl run`, a campaign and
//! the report. [`SamplerKind`] is a handle on an entry: the command line, campaign files and
//! the run identities name it by its name.

use std::cmp::Ordering;
use std::hash::{Hash, Hasher};
use std::sync::RwLock;

use serde::{Deserialize, Serialize};
use ugl_types::{SamplerInfo, SamplerInfoError, samplers};

use super::GoalSampler;
use crate::repr::{GaussianPrior, Latents, ReprError};

/// What a sampler of a learned goal space draws from: the training encodings (restricted to a
/// module's latents where goals are drawn per module) and the goal space's prior, if any.
pub struct TrainingLatents<'a> {
    /// The training images' latents.
    pub latents: &'a Latents,
    /// The goal space's prior, over the same latents (None: the learner declares none).
    pub prior: Option<&'a GaussianPrior>,
    /// The algorithm that explores the goal space (for messages).
    pub algo: &'a str,
}

/// Builds a sampler over a learned goal space.
pub type BuildLearned = fn(&TrainingLatents<'_>) -> Result<Box<dyn GoalSampler>, ReprError>;

/// One goal sampler: its description and its code.
pub struct SamplerEntry {
    pub info: &'static SamplerInfo,
    /// How to build it over a learned goal space; None for the samplers of the other strategies
    /// (RPE's none, RGE-EFR's uniform box), which their explorers hold themselves.
    pub learned: Option<BuildLearned>,
}

/// The samplers of this crate, in the report's order (`ugl_types::SAMPLERS`).
pub static BUILT_IN: [SamplerEntry; 4] = [
    SamplerEntry {
        info: &samplers::NONE,
        learned: None,
    },
    SamplerEntry {
        info: &samplers::UNIFORM,
        learned: None,
    },
    SamplerEntry {
        info: &samplers::KDE,
        learned: Some(super::kde::for_learned),
    },
    SamplerEntry {
        info: &samplers::GAUSSIAN,
        learned: Some(super::prior::for_learned),
    },
];

/// The samplers registered at run time, in registration order.
static REGISTERED: RwLock<Vec<&'static SamplerEntry>> = RwLock::new(Vec::new());

/// Why a sampler cannot be registered.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RegisterError {
    /// The description is refused by `ugl-types`' registry.
    #[error(transparent)]
    Info(#[from] SamplerInfoError),
    /// The description says it samples learned goal spaces and the entry cannot build it there,
    /// or the other way round.
    #[error(
        "goal sampler '{0}': `info.learned` must say whether the entry builds it over a learned \
         goal space"
    )]
    Learned(&'static str),
}

/// Add a sampler to the registry, so that campaign files and the command line know it by name.
pub fn register(entry: &'static SamplerEntry) -> Result<SamplerKind, RegisterError> {
    if entry.info.learned != entry.learned.is_some() {
        return Err(RegisterError::Learned(entry.info.name));
    }
    SamplerInfo::register(entry.info)?;
    let mut registered = REGISTERED.write().unwrap_or_else(|e| e.into_inner());
    if !registered.iter().any(|e| std::ptr::eq(*e, entry)) {
        registered.push(entry);
    }
    Ok(SamplerKind(entry))
}

/// How goals are drawn: a handle on a registry entry. Compared, hashed and written by name
/// (`kde`); ordered as the registry lists them.
#[derive(Clone, Copy)]
pub struct SamplerKind(&'static SamplerEntry);

impl SamplerKind {
    /// No goals (RPE).
    pub const NONE: SamplerKind = SamplerKind(&BUILT_IN[0]);
    /// Uniform in the engineered box (RGE-EFR).
    pub const UNIFORM: SamplerKind = SamplerKind(&BUILT_IN[1]);
    /// Gaussian KDE of the training latents (the paper's default for learned goal spaces).
    pub const KDE: SamplerKind = SamplerKind(&BUILT_IN[2]);
    /// Isotropic standard Gaussian, N(0, I) (the paper's "GP" / `--sampling=normal`).
    pub const GAUSSIAN: SamplerKind = SamplerKind(&BUILT_IN[3]);

    /// Every sampler of the registry, in its order.
    pub fn all() -> Vec<SamplerKind> {
        let registered = REGISTERED.read().unwrap_or_else(|e| e.into_inner());
        BUILT_IN
            .iter()
            .chain(registered.iter().copied())
            .map(SamplerKind)
            .collect()
    }

    /// The samplers of learned goal spaces, in the registry's order.
    pub fn learned() -> Vec<SamplerKind> {
        SamplerKind::all()
            .into_iter()
            .filter(|s| s.is_learned())
            .collect()
    }

    /// Name in results.
    pub fn name(self) -> &'static str {
        self.0.info.name
    }

    /// Its description.
    pub fn info(self) -> &'static SamplerInfo {
        self.0.info
    }

    /// Whether it samples learned goal spaces.
    pub fn is_learned(self) -> bool {
        self.0.learned.is_some()
    }

    /// Whether it needs the goal space's prior.
    pub fn needs_prior(self) -> bool {
        self.0.info.needs_prior
    }

    /// The sampler over a learned goal space.
    pub fn build(self, space: &TrainingLatents<'_>) -> Result<Box<dyn GoalSampler>, ReprError> {
        match self.0.learned {
            Some(build) => build(space),
            None => Err(ReprError::InvalidInput(format!(
                "sampler {self} is not for learned goal spaces"
            ))),
        }
    }

    fn position(self) -> usize {
        SamplerKind::all()
            .iter()
            .position(|s| s.name() == self.name())
            .unwrap_or(usize::MAX)
    }

    /// The names of the samplers of learned goal spaces, for messages (`kde, gaussian`).
    pub fn learned_names() -> String {
        let names: Vec<&str> = SamplerKind::learned().iter().map(|s| s.name()).collect();
        names.join(", ")
    }
}

impl PartialEq for SamplerKind {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}
impl Eq for SamplerKind {}
impl Hash for SamplerKind {
    fn hash<H: Hasher>(&self, h: &mut H) {
        self.name().hash(h);
    }
}
impl PartialOrd for SamplerKind {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for SamplerKind {
    fn cmp(&self, other: &Self) -> Ordering {
        (self.position(), self.name()).cmp(&(other.position(), other.name()))
    }
}

impl std::fmt::Debug for SamplerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SamplerKind({})", self.name())
    }
}

impl std::fmt::Display for SamplerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SamplerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        SamplerKind::all()
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown goal sampler '{s}' (expected {})",
                    SamplerKind::learned_names().replace(", ", " or ")
                )
            })
    }
}

impl Serialize for SamplerKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for SamplerKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_entries_are_the_shared_descriptions_in_order() {
        let ours: Vec<&str> = SamplerKind::all().iter().map(|s| s.name()).collect();
        let theirs: Vec<&str> = ugl_types::SAMPLERS.iter().map(|s| s.name).collect();
        assert_eq!(ours[..theirs.len()], theirs[..]);
        for e in &BUILT_IN {
            assert_eq!(e.info.learned, e.learned.is_some(), "{}", e.info.name);
        }
        assert_eq!(SamplerKind::learned_names(), "kde, gaussian");
        assert!(SamplerKind::KDE < SamplerKind::GAUSSIAN && SamplerKind::NONE < SamplerKind::KDE);
        assert_eq!("gaussian".parse::<SamplerKind>(), Ok(SamplerKind::GAUSSIAN));
        let e = "kd".parse::<SamplerKind>().unwrap_err();
        assert!(e.contains("expected kde or gaussian"), "{e}");
    }
}
