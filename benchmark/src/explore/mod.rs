//! The explorers (paper Section 3 and Appendix D, Algorithm 3; PAPER-NOTES.md section 3):
//! random parameter exploration (RPE) and random goal exploration (RGE) with a nearest-neighbour
//! meta-policy, in an engineered (EFR) or learned goal space.

pub mod history;
pub mod imgep;
pub mod meta_policy;
pub mod nn;
pub mod rpe;

use serde::{Deserialize, Serialize};

pub use history::{Checkpoint, ExplorationLog};
pub use imgep::{run_rge, EngineeredSpace, OutcomeSpace};
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
        ExploreConfig { epochs: 5000, bootstrap_epochs: 100, random_ratio: 0.2, noise_sigma: 0.1, eval_every: 100 }
    }
}

impl ExploreConfig {
    /// Check the values; the error names the offending key.
    pub fn validate(&self) -> Result<(), String> {
        if self.epochs == 0 {
            return Err("explore.epochs must be at least 1".into());
        }
        if self.eval_every == 0 {
            return Err("explore.eval_every must be at least 1".into());
        }
        if !(0.0..=1.0).contains(&self.random_ratio) {
            return Err(format!("explore.random_ratio must be in [0, 1], got {}", self.random_ratio));
        }
        if !(self.noise_sigma.is_finite() && self.noise_sigma >= 0.0) {
            return Err(format!("explore.noise_sigma must be finite and >= 0, got {}", self.noise_sigma));
        }
        Ok(())
    }

    /// The epochs at which the curve is evaluated: every `eval_every`, and the last.
    pub fn eval_epochs(&self) -> Vec<usize> {
        let mut v: Vec<usize> = (1..=self.epochs / self.eval_every).map(|k| k * self.eval_every).collect();
        if v.last() != Some(&self.epochs) {
            v.push(self.epochs);
        }
        v
    }
}

/// Which exploration algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Algo {
    /// Random parameter exploration.
    #[serde(rename = "rpe")]
    Rpe,
    /// Random goal exploration with engineered features.
    #[serde(rename = "rge-efr")]
    RgeEfr,
}

impl Algo {
    /// All algorithms known to this build.
    pub const ALL: [Algo; 2] = [Algo::Rpe, Algo::RgeEfr];

    /// Name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Algo::Rpe => "rpe",
            Algo::RgeEfr => "rge-efr",
        }
    }

    /// The goal sampler the algorithm uses (`none` for RPE).
    pub fn sampler(self) -> &'static str {
        match self {
            Algo::Rpe => "none",
            Algo::RgeEfr => "uniform",
        }
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
        Algo::ALL.into_iter().find(|a| a.name() == s).ok_or_else(|| {
            let names: Vec<_> = Algo::ALL.iter().map(|a| a.name()).collect();
            format!("unknown algorithm '{s}' (expected one of: {})", names.join(", "))
        })
    }
}
