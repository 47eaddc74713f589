//! The explorers (paper Section 3 and Appendix D, Algorithm 3; docs/original-code.md section 3):
//! random parameter exploration (RPE) and random goal exploration (RGE) with a nearest-neighbour
//! meta-policy, in an engineered (EFR) or learned goal space; and the follow-up paper's modular
//! goal exploration (MGE, `mge.rs`) with curiosity-driven module choice (`interest.rs`).
//!
//! An [`Algo`] is a [`Strategy`] in a [`GoalSpaceKind`]; the strategy builds the run's
//! [`Explorer`] from the goal space's outcome encoding ([`OutcomeSpace`]) and goals
//! ([`GoalSource`]).

pub mod goal_source;
pub mod history;
pub mod imgep;
pub mod interest;
pub mod meta_policy;
pub mod mge;
pub mod mixed;
/// The k-d tree (in `ugl-types`, shared with the discovery measures).
pub use ugl_types::nn;
pub mod rpe;

use crate::invalid::InvalidValue;
use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use crate::env::Environment;
use crate::repr::ReprError;

pub use crate::repr::registry::Learner;
pub use goal_source::{EngineeredGoals, GoalSource};
pub use history::{Checkpoint, ExplorationLog};
pub use imgep::{EngineeredSpace, LearnedSpace, OutcomeSpace, Rge, run_rge};
pub use mge::{GoalModule, Mge, MgeConfig, Modules, goal_modules, run_mge};
pub use rpe::{Rpe, run_rpe};

/// What refuses an algorithm or stops an exploration (modular exploration's modules and
/// interests; the other loops cannot fail).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExploreError {
    #[error("random parameter exploration has no goal space")]
    RpeInGoalSpace,
    #[error("goal exploration needs a goal space")]
    NoGoalSpace,
    #[error(
        "modular exploration with engineered features already has one module per object; the \
         position-only space is for random goal exploration"
    )]
    ModularPositionOnly,
    #[error("{dim} latents cannot be split into modules of {module_size} (mge.module_size)")]
    ModuleSplit { dim: usize, module_size: usize },
    #[error("{modules} modules and {samplers} goal samplers")]
    ModuleCount { modules: usize, samplers: usize },
    #[error(
        "module {name} ({dims:?}) does not fit its sampler (dim {sampler}) or the goal space \
         (dim {space})"
    )]
    ModuleFit {
        name: String,
        dims: Vec<usize>,
        sampler: usize,
        space: usize,
    },
    #[error("a goal module needs at least one dimension")]
    EmptyModule,
    #[error("the interest window must be at least 1, got {0}")]
    InterestWindow(f64),
    #[error("a goal space's competence scale must be positive and finite, got {0}")]
    CompetenceScale(f64),
    #[error("goal and outcome must have {dim} values, got {goal} and {reached}")]
    GoalLength {
        dim: usize,
        goal: usize,
        reached: usize,
    },
    #[error("goal or outcome has a non-finite value")]
    NonFinite,
    #[error("no module to choose from")]
    NoModule,
    #[error("interests must be finite and non-negative, got {0}")]
    Interest(f64),
    #[error("eps must be in [0, 1], got {0}")]
    Eps(f64),
}

/// An exploration loop (RPE, RGE or MGE), built for one run ([`Strategy::explorer`]).
pub trait Explorer {
    /// Explore `env` for `cfg.epochs` iterations, drawing from the streams of `run_seed`.
    fn explore(
        &mut self,
        env: &dyn Environment,
        cfg: &ExploreConfig,
        run_seed: u64,
    ) -> Result<ExplorationLog, ExploreError>;
}

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
    pub fn validate(&self) -> Result<(), InvalidValue> {
        if self.epochs == 0 {
            return Err(InvalidValue::new(
                "explore.epochs",
                "explore.epochs must be at least 1",
            ));
        }
        crate::limits::check_epochs(self.epochs)
            .map_err(|e| InvalidValue::new("explore.epochs", e.to_string()))?;
        if self.eval_every == 0 {
            return Err(InvalidValue::new(
                "explore.eval_every",
                "explore.eval_every must be at least 1",
            ));
        }
        if !(0.0..=1.0).contains(&self.random_ratio) {
            return Err(InvalidValue::new(
                "explore.random_ratio",
                format!(
                    "explore.random_ratio must be in [0, 1], got {}",
                    self.random_ratio
                ),
            ));
        }
        if !(self.noise_sigma.is_finite() && self.noise_sigma >= 0.0) {
            return Err(InvalidValue::new(
                "explore.noise_sigma",
                format!(
                    "explore.noise_sigma must be finite and >= 0, got {}",
                    self.noise_sigma
                ),
            ));
        }
        Ok(())
    }

    /// For goal exploration (`goal_directed`): at least one epoch after the bootstrap, else
    /// every epoch is random and the run is RPE under another label.
    pub fn check_goal_epochs(&self, goal_directed: bool) -> Result<(), InvalidValue> {
        if goal_directed && self.bootstrap_epochs >= self.epochs {
            return Err(InvalidValue::new(
                "explore.bootstrap_epochs",
                format!(
                    "explore.bootstrap_epochs = {} leaves none of the {} epochs to goal exploration \
                 (every epoch would be random: an RPE run under a goal-exploration label); \
                 give more epochs than bootstrap_epochs",
                    self.bootstrap_epochs, self.epochs
                ),
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

/// How an explorer chooses the next parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// Random parameter exploration (RPE): no goals.
    Rpe,
    /// Random goal exploration (RGE; paper Appendix D, Algorithm 3).
    Rge,
    /// Modular goal exploration (follow-up paper, `mge.rs`) with this module choice.
    Mge(Modules),
}

impl Strategy {
    /// The explorer of this strategy, encoding outcomes in `space` and drawing goals from
    /// `goals` (RPE uses neither).
    pub fn explorer<'a>(
        self,
        space: &'a mut dyn OutcomeSpace,
        goals: &dyn GoalSource,
        mge: &'a MgeConfig,
    ) -> Result<Box<dyn Explorer + 'a>, ReprError> {
        Ok(match self {
            Strategy::Rpe => Box::new(Rpe),
            Strategy::Rge => Box::new(Rge {
                space,
                sampler: goals.sampler(None)?,
            }),
            Strategy::Mge(choice) => {
                let modules = goals.modules(choice, mge.module_size)?;
                let samplers = modules
                    .iter()
                    .map(|m| goals.sampler(Some(&m.dims)))
                    .collect::<Result<_, _>>()?;
                Box::new(Mge {
                    space,
                    modules,
                    samplers,
                    choice,
                    config: mge,
                })
            }
        })
    }

    /// Rank in [`Algo`]'s order: RPE, RGE, MGE.
    fn rank(self) -> u8 {
        match self {
            Strategy::Rpe => 0,
            Strategy::Rge => 1,
            Strategy::Mge(_) => 2,
        }
    }
}

/// The goal space an explorer draws its goals in (paper Section 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum GoalSpaceKind {
    /// No goal space (RPE only).
    None,
    /// Engineered features (EFR): the scene's object state.
    Engineered,
    /// The engineered features without orientation: each object's position (x, y) only
    /// ([`ugl_types::EnvSpec::position_dims`]). On ArmArrow it is the control that tells what
    /// exploring the angle adds; elsewhere it is EFR itself.
    EngineeredPosition,
    /// The engineered features through a fixed rotation of all their coordinates
    /// ([`mixed`]): the same information, no coordinate for one object alone (the follow-up's
    /// entangled control without a network).
    EngineeredMixed,
    /// A space learned from images (IMGEP-UGL, RGE-REP).
    Learned(Learner),
}

impl GoalSpaceKind {
    /// Engineered features, whole, positions only or mixed.
    pub fn is_engineered(self) -> bool {
        matches!(
            self,
            GoalSpaceKind::Engineered
                | GoalSpaceKind::EngineeredPosition
                | GoalSpaceKind::EngineeredMixed
        )
    }
}

/// An exploration algorithm: a strategy in a goal space. Only the valid pairs exist (RPE has no
/// goal space, goal exploration has one; [`Algo::new`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Algo {
    strategy: Strategy,
    space: GoalSpaceKind,
}

impl Algo {
    /// Random parameter exploration (`rpe`).
    pub const RPE: Algo = Algo {
        strategy: Strategy::Rpe,
        space: GoalSpaceKind::None,
    };

    /// Random goal exploration with engineered features (`rge-efr`).
    pub const RGE_EFR: Algo = Algo {
        strategy: Strategy::Rge,
        space: GoalSpaceKind::Engineered,
    };

    /// Random goal exploration in the position-only engineered space (`rge-efr-position`).
    pub const RGE_EFR_POSITION: Algo = Algo {
        strategy: Strategy::Rge,
        space: GoalSpaceKind::EngineeredPosition,
    };

    /// Random goal exploration in the mixed engineered space (`rge-efr-mixed`).
    pub const RGE_EFR_MIXED: Algo = Algo {
        strategy: Strategy::Rge,
        space: GoalSpaceKind::EngineeredMixed,
    };

    /// `strategy` in `space`; `Err` for RPE in a goal space or goal exploration without one.
    pub fn new(strategy: Strategy, space: GoalSpaceKind) -> Result<Algo, ExploreError> {
        match (strategy, space) {
            (Strategy::Rpe, GoalSpaceKind::None) => Ok(Algo::RPE),
            (Strategy::Rpe, _) => Err(ExploreError::RpeInGoalSpace),
            (_, GoalSpaceKind::None) => Err(ExploreError::NoGoalSpace),
            (Strategy::Mge(_), GoalSpaceKind::EngineeredPosition) => {
                Err(ExploreError::ModularPositionOnly)
            }
            _ => Ok(Algo { strategy, space }),
        }
    }

    /// Random goal exploration in the goal space `learner` learns (`rge-vae`).
    pub const fn rge(learner: Learner) -> Algo {
        Algo {
            strategy: Strategy::Rge,
            space: GoalSpaceKind::Learned(learner),
        }
    }

    /// How it chooses parameters.
    pub fn strategy(self) -> Strategy {
        self.strategy
    }

    /// Where its goals are drawn.
    pub fn space(self) -> GoalSpaceKind {
        self.space
    }

    /// All algorithms known to this build, in their order (`Ord`).
    pub fn all() -> Vec<Algo> {
        let goal = |strategy, space| Algo { strategy, space };
        let mut v = vec![
            Algo::RPE,
            Algo::RGE_EFR,
            Algo::RGE_EFR_POSITION,
            Algo::RGE_EFR_MIXED,
        ];
        v.extend(Learner::all().map(Algo::rge));
        v.extend(Modules::ALL.map(|m| goal(Strategy::Mge(m), GoalSpaceKind::Engineered)));
        v.extend(Modules::ALL.map(|m| goal(Strategy::Mge(m), GoalSpaceKind::EngineeredMixed)));
        for l in Learner::all() {
            v.extend(Modules::ALL.map(|m| goal(Strategy::Mge(m), GoalSpaceKind::Learned(l))));
        }
        v
    }

    /// Name on the command line and in results (`rpe`, `rge-efr`, `rge-pca`, `mge-efr-lp`,
    /// `mge-vae-random`, ...).
    pub fn name(self) -> Cow<'static, str> {
        let space = match self.space {
            GoalSpaceKind::None => "",
            GoalSpaceKind::Engineered => ugl_types::ENGINEERED_SPACE.0,
            GoalSpaceKind::EngineeredPosition => "efr-position",
            GoalSpaceKind::EngineeredMixed => ugl_types::MIXED_SPACE.0,
            GoalSpaceKind::Learned(l) => l.name(),
        };
        match (self.strategy, self.space) {
            (Strategy::Rpe, _) => "rpe".into(),
            (Strategy::Rge, GoalSpaceKind::Learned(l)) => l.entry().algo.into(),
            (Strategy::Rge, GoalSpaceKind::EngineeredPosition) => "rge-efr-position".into(),
            (Strategy::Rge, GoalSpaceKind::EngineeredMixed) => ugl_types::RGE_EFR_MIXED.algo.into(),
            (Strategy::Rge, _) => "rge-efr".into(),
            (Strategy::Mge(m), _) => {
                format!("{}{space}-{}", ugl_types::MODULAR_PREFIX, m.name()).into()
            }
        }
    }

    /// The algorithm whose exploration streams a baseline run draws: its own, except the
    /// position-only EFR, which draws RGE-EFR's (same run seed), so that the two are paired
    /// and differ only in the goal space.
    pub fn stream_algo(self) -> Algo {
        match self.space {
            GoalSpaceKind::EngineeredPosition => Algo::RGE_EFR,
            _ => self,
        }
    }

    /// The learner, for algorithms in a learned goal space.
    pub fn learner(self) -> Option<Learner> {
        match self.space {
            GoalSpaceKind::Learned(l) => Some(l),
            _ => None,
        }
    }

    /// The module choice of a modular exploration.
    pub fn modules(self) -> Option<Modules> {
        match self.strategy {
            Strategy::Mge(m) => Some(m),
            _ => None,
        }
    }

    /// The order of [`Algo::all`]: RPE, RGE (engineered, then each learner), MGE (engineered,
    /// then each learner; each with every module choice).
    fn order_key(self) -> (u8, GoalSpaceKind, Option<Modules>) {
        (self.strategy.rank(), self.space, self.modules())
    }
}

impl Ord for Algo {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.order_key().cmp(&other.order_key())
    }
}

impl PartialOrd for Algo {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Serialize for Algo {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
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
        f.write_str(&self.name())
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

/// How goals are drawn (the goal-sampler registry's handle).
pub use crate::goals::SamplerKind;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn algorithm_names_order_and_parsing_are_stable() {
        let mut names = vec![
            "rpe".to_string(),
            "rge-efr".into(),
            "rge-efr-position".into(),
            "rge-efr-mixed".into(),
        ];
        names.extend(Learner::all().map(|l| format!("rge-{}", l.name())));
        names.extend(["mge-efr-flat", "mge-efr-random", "mge-efr-lp"].map(String::from));
        names.extend(
            [
                "mge-efr-mixed-flat",
                "mge-efr-mixed-random",
                "mge-efr-mixed-lp",
            ]
            .map(String::from),
        );
        for l in Learner::all() {
            for m in ["flat", "random", "lp"] {
                names.push(format!("mge-{}-{m}", l.name()));
            }
        }
        let all = Algo::all();
        assert_eq!(all.iter().map(|a| a.to_string()).collect::<Vec<_>>(), names);
        // `Ord` is the order of `all` (the order of the former enum's variants).
        assert!(all.windows(2).all(|w| w[0] < w[1]));
        for a in &all {
            assert_eq!(a.name().parse::<Algo>(), Ok(*a));
            assert_eq!(Algo::new(a.strategy(), a.space()), Ok(*a));
            assert_eq!(serde_json::to_string(a).unwrap(), format!("\"{a}\""));
        }
        assert!("mge-efr".parse::<Algo>().is_err());
    }

    #[test]
    fn only_valid_strategy_and_space_pairs_are_built() {
        let vae = Learner::by_name("vae").unwrap();
        assert!(Algo::new(Strategy::Rpe, GoalSpaceKind::Learned(vae)).is_err());
        assert!(Algo::new(Strategy::Rpe, GoalSpaceKind::Engineered).is_err());
        assert!(Algo::new(Strategy::Rge, GoalSpaceKind::None).is_err());
        assert!(
            Algo::new(
                Strategy::Mge(Modules::Progress),
                GoalSpaceKind::EngineeredPosition
            )
            .is_err()
        );
        assert_eq!(Algo::RGE_EFR_POSITION.stream_algo(), Algo::RGE_EFR);
        assert!(Algo::new(Strategy::Mge(Modules::Progress), GoalSpaceKind::None).is_err());
        let a = Algo::new(Strategy::Mge(Modules::Random), GoalSpaceKind::Learned(vae)).unwrap();
        assert_eq!(a.to_string(), "mge-vae-random");
        assert_eq!(
            (a.learner(), a.modules()),
            (Some(vae), Some(Modules::Random))
        );
    }
}
