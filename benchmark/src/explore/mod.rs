//! The explorers (paper Section 3 and Appendix D, Algorithm 3; PAPER-NOTES.md section 3):
//! random parameter exploration (RPE) and random goal exploration (RGE) with a nearest-neighbour
//! meta-policy, in an engineered (EFR) or learned goal space.

pub mod history;
pub mod imgep;
pub mod meta_policy;
pub mod nn;
pub mod rpe;

use serde::{Deserialize, Serialize};

use crate::repr::neural::Model;
pub use history::{Checkpoint, ExplorationLog};
pub use imgep::{EngineeredSpace, LearnedSpace, OutcomeSpace, run_rge};
pub use rpe::run_rpe;

/// Constants of the exploration loop; the defaults are the paper's code's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExploreConfig {
    /// Exploration iterations after the warm-up episode (5000).
    pub epochs: usize,
    /// The first iterations are random parameter exploration (100).
    pub bootstrap_epochs: usize,
    /// After the bootstrap, an iteration is random with this probability (Gamma = 0.2).
    pub random_ratio: f64,
    /// Standard deviation of the meta-policy's Gaussian noise per parameter, in the [-1,1]
    /// parameter space (0.05 * (max - min) = 0.1).
    pub noise_sigma: f64,
    /// Record the KL-coverage every this many epochs (and at the last one).
    pub eval_every: usize,
}

impl Default for ExploreConfig {
    fn default() -> Self {
        ExploreConfig {
            epochs: 5000,
            bootstrap_epochs: 100,
            random_ratio: 0.2,
            noise_sigma: 0.1,
            eval_every: 100,
        }
    }
}

impl ExploreConfig {
    /// Check the values; the error names the offending key.
    pub fn validate(&self) -> Result<(), String> {
        if self.epochs == 0 {
            return Err("explore.epochs must be at least 1".into());
        }
        crate::limits::check_epochs(self.epochs)?;
        if self.eval_every == 0 {
            return Err("explore.eval_every must be at least 1".into());
        }
        if !(0.0..=1.0).contains(&self.random_ratio) {
            return Err(format!(
                "explore.random_ratio must be in [0, 1], got {}",
                self.random_ratio
            ));
        }
        if !(self.noise_sigma.is_finite() && self.noise_sigma >= 0.0) {
            return Err(format!(
                "explore.noise_sigma must be finite and >= 0, got {}",
                self.noise_sigma
            ));
        }
        Ok(())
    }

    /// The epochs at which the curve is evaluated: every `eval_every`, and the last.
    pub fn eval_epochs(&self) -> Vec<usize> {
        let mut v: Vec<usize> = (1..=self.epochs / self.eval_every)
            .map(|k| k * self.eval_every)
            .collect();
        if v.last() != Some(&self.epochs) {
            v.push(self.epochs);
        }
        v
    }
}

/// The representation learners of IMGEP-UGL (PAPER-NOTES.md section 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Learner {
    /// The paper's PCA: non-centred truncated SVD.
    Pca,
    /// Ordinary mean-centred PCA.
    PcaCentred,
    /// Isomap (5 neighbours).
    Isomap,
    /// The dense auto-encoder (sigmoid latents).
    Ae,
    /// The dense variational auto-encoder (encoding = mu; prior N(0, I)).
    Vae,
    /// The VAE with 10 radial flows (prior N(0, I)).
    Rfvae,
    /// A program outside this project, through the external-learner protocol.
    External,
}

impl Learner {
    /// All learners of this build.
    pub const ALL: [Learner; 7] = [
        Learner::Pca,
        Learner::PcaCentred,
        Learner::Isomap,
        Learner::Ae,
        Learner::Vae,
        Learner::Rfvae,
        Learner::External,
    ];

    /// Name of the learner (`pca`, `pca-centred`, `isomap`, `ae`, `vae`, `rfvae`, `external`).
    pub fn name(self) -> &'static str {
        match self {
            Learner::Pca => "pca",
            Learner::PcaCentred => "pca-centred",
            Learner::Isomap => "isomap",
            Learner::Ae => "ae",
            Learner::Vae => "vae",
            Learner::Rfvae => "rfvae",
            Learner::External => "external",
        }
    }

    /// The network of a neural learner.
    pub fn model(self) -> Option<Model> {
        match self {
            Learner::Ae => Some(Model::Ae),
            Learner::Vae => Some(Model::Vae),
            Learner::Rfvae => Some(Model::Rfvae),
            _ => None,
        }
    }

    /// The variants this learner's runs are crossed with: faithful and corrected for the VAE
    /// and RFVAE (the original code had defects there); one for the others (the AE's two
    /// variants train identically, so it runs once).
    pub fn has_variants(self) -> bool {
        matches!(self, Learner::Vae | Learner::Rfvae)
    }

    /// Whether the goal space has a prior to sample goals from (`--sampler gaussian`): the
    /// VAE and RFVAE (N(0, I)), and an external program that writes `prior.npy`.
    pub fn may_have_prior(self) -> bool {
        matches!(self, Learner::Vae | Learner::Rfvae | Learner::External)
    }
}

/// Which exploration algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Algo {
    /// Random parameter exploration.
    Rpe,
    /// Random goal exploration with engineered features.
    RgeEfr,
    /// Random goal exploration in a goal space learned from images (IMGEP-UGL, RGE-REP).
    Rge(Learner),
}

impl Algo {
    /// All algorithms known to this build.
    pub fn all() -> Vec<Algo> {
        let mut v = vec![Algo::Rpe, Algo::RgeEfr];
        v.extend(Learner::ALL.iter().map(|&l| Algo::Rge(l)));
        v
    }

    /// Name on the command line and in results (`rpe`, `rge-efr`, `rge-pca`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Algo::Rpe => "rpe",
            Algo::RgeEfr => "rge-efr",
            Algo::Rge(Learner::Pca) => "rge-pca",
            Algo::Rge(Learner::PcaCentred) => "rge-pca-centred",
            Algo::Rge(Learner::Isomap) => "rge-isomap",
            Algo::Rge(Learner::Ae) => "rge-ae",
            Algo::Rge(Learner::Vae) => "rge-vae",
            Algo::Rge(Learner::Rfvae) => "rge-rfvae",
            Algo::Rge(Learner::External) => "rge-external",
        }
    }

    /// The learner, for RGE-REP algorithms.
    pub fn learner(self) -> Option<Learner> {
        match self {
            Algo::Rge(l) => Some(l),
            _ => None,
        }
    }
}

impl Serialize for Algo {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Algo {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl std::fmt::Display for Algo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Algo {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Algo::all()
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Algo::all().iter().map(|a| a.name()).collect();
                format!(
                    "unknown algorithm '{s}' (expected one of: {})",
                    names.join(", ")
                )
            })
    }
}

/// How goals are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerKind {
    /// No goals (RPE).
    None,
    /// Uniform in the engineered box (RGE-EFR).
    Uniform,
    /// Gaussian KDE of the training latents (the paper's default for RGE-REP).
    Kde,
    /// Isotropic standard Gaussian, N(0, I) (the paper's "GP" / `--sampling=normal`).
    Gaussian,
}

impl SamplerKind {
    /// Name in results.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::None => "none",
            SamplerKind::Uniform => "uniform",
            SamplerKind::Kde => "kde",
            SamplerKind::Gaussian => "gaussian",
        }
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
        match s {
            "kde" => Ok(SamplerKind::Kde),
            "gaussian" => Ok(SamplerKind::Gaussian),
            "uniform" => Ok(SamplerKind::Uniform),
            "none" => Ok(SamplerKind::None),
            _ => Err(format!(
                "unknown goal sampler '{s}' (expected kde or gaussian)"
            )),
        }
    }
}
