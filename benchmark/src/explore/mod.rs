//! The explorers (paper Section 3 and Appendix D, Algorithm 3; PAPER-NOTES.md section 3):
//! random parameter exploration (RPE) and random goal exploration (RGE) with a nearest-neighbour
//! meta-policy, in an engineered (EFR) or learned goal space; and the follow-up paper's modular
//! goal exploration (MGE, `mge.rs`) with curiosity-driven module choice (`interest.rs`).

pub mod history;
pub mod imgep;
pub mod interest;
pub mod meta_policy;
pub mod mge;
pub mod nn;
pub mod rpe;

use serde::{Deserialize, Serialize};

pub use crate::repr::registry::Learner;
pub use history::{Checkpoint, ExplorationLog};
pub use imgep::{EngineeredSpace, LearnedSpace, OutcomeSpace, run_rge};
pub use mge::{GoalModule, MgeConfig, Modules, goal_modules, run_mge};
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

/// Which exploration algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Algo {
    /// Random parameter exploration.
    Rpe,
    /// Random goal exploration with engineered features.
    RgeEfr,
    /// Random goal exploration in a goal space learned from images (IMGEP-UGL, RGE-REP).
    Rge(Learner),
    /// Modular goal exploration (follow-up paper, `mge.rs`) with engineered features, one
    /// module per object (`mge-efr-lp`, `mge-efr-random`; `mge-efr-flat`: one module).
    MgeEfr(Modules),
    /// Modular goal exploration in a learned goal space (`mge-vae-lp`, ...).
    Mge(Learner, Modules),
}

impl Algo {
    /// All algorithms known to this build.
    pub fn all() -> Vec<Algo> {
        let mut v = vec![Algo::Rpe, Algo::RgeEfr];
        v.extend(Learner::all().map(Algo::Rge));
        v.extend(Modules::ALL.map(Algo::MgeEfr));
        for l in Learner::all() {
            v.extend(Modules::ALL.map(|m| Algo::Mge(l, m)));
        }
        v
    }

    /// Name on the command line and in results (`rpe`, `rge-efr`, `rge-pca`, `mge-efr-lp`,
    /// `mge-vae-random`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Algo::Rpe => "rpe",
            Algo::RgeEfr => "rge-efr",
            Algo::Rge(l) => l.entry().algo,
            Algo::MgeEfr(m) => match m {
                Modules::Flat => "mge-efr-flat",
                Modules::Random => "mge-efr-random",
                Modules::Progress => "mge-efr-lp",
            },
            Algo::Mge(l, m) => mge_name(l, m),
        }
    }

    /// The learner, for algorithms in a learned goal space.
    pub fn learner(self) -> Option<Learner> {
        match self {
            Algo::Rge(l) | Algo::Mge(l, _) => Some(l),
            _ => None,
        }
    }

    /// The module choice of a modular exploration.
    pub fn modules(self) -> Option<Modules> {
        match self {
            Algo::MgeEfr(m) | Algo::Mge(_, m) => Some(m),
            _ => None,
        }
    }
}

/// `mge-<learner>-<modules>`, built once per learner (names must live as long as the registry).
fn mge_name(l: Learner, m: Modules) -> &'static str {
    use std::sync::OnceLock;
    static NAMES: OnceLock<Vec<[&'static str; 3]>> = OnceLock::new();
    let names = NAMES.get_or_init(|| {
        Learner::all()
            .map(|l| {
                Modules::ALL
                    .map(|m| &*Box::leak(format!("mge-{}-{}", l.name(), m.name()).into_boxed_str()))
            })
            .collect()
    });
    let k = Modules::ALL
        .iter()
        .position(|x| *x == m)
        .expect("every module choice is in ALL");
    names[l.index()][k]
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
