//! The exploration strategies that are not a learned goal space (paper Section 3): random
//! parameter exploration and goal exploration in the engineered features. A learned goal space
//! is the strategy `rge-<learner>` of a [`crate::LearnerInfo`]; the two together name every
//! algorithm of the results.

use crate::sampler::{self, SamplerInfo};

/// One exploration strategy without a learned goal space.
#[derive(Debug, PartialEq)]
pub struct StrategyInfo {
    /// Name in campaign files and results (`rge-efr`).
    pub algo: &'static str,
    /// Name in the report (`RGE-EFR`).
    pub display: &'static str,
    /// One line for `--help` and the docs.
    pub description: &'static str,
    /// The goal sampler its runs record.
    pub sampler: &'static SamplerInfo,
    /// Whether the paper evaluated it (the paper's algorithms come first, with fixed styles).
    pub in_paper: bool,
    /// Its style slot in the report's figures: the colour and marker it has in every figure.
    /// Fixed per entry (never its position in a list), so that adding an entry moves no other;
    /// the slots of all strategies and learners are distinct and run from 0 without a gap
    /// (`Algo::styled`).
    pub style: usize,
}

/// Random parameter exploration: the floor.
pub static RPE: StrategyInfo = StrategyInfo {
    algo: "rpe",
    display: "RPE",
    description: "random parameter exploration: motor parameters uniform in their box",
    sampler: &sampler::NONE,
    in_paper: true,
    style: 0,
};
/// Random goal exploration in the engineered features (the object's true state).
pub static RGE_EFR: StrategyInfo = StrategyInfo {
    algo: "rge-efr",
    display: "RGE-EFR",
    description: "random goal exploration in the engineered features (the object's state)",
    sampler: &sampler::UNIFORM,
    in_paper: true,
    style: 1,
};
/// RGE-EFR with the object's position alone (ArmArrow without its angle).
pub static RGE_EFR_POSITION: StrategyInfo = StrategyInfo {
    algo: "rge-efr-position",
    display: "RGE-EFR (position only)",
    description: "RGE-EFR on the object's position alone, without the angle (ArmArrow)",
    sampler: &sampler::UNIFORM,
    in_paper: false,
    style: 7,
};

/// RGE in the engineered features through a fixed rotation of all their coordinates: the same
/// information, no coordinate for one object alone (the follow-up's entangled control).
pub static RGE_EFR_MIXED: StrategyInfo = StrategyInfo {
    algo: "rge-efr-mixed",
    display: "RGE-EFR (mixed)",
    description: "RGE in the engineered features through a fixed rotation of all their coordinates (an entangled control)",
    sampler: &sampler::UNIFORM,
    in_paper: false,
    style: 8,
};

/// Every strategy without a learned goal space, in the report's order.
pub static STRATEGIES: [&StrategyInfo; 4] = [&RPE, &RGE_EFR, &RGE_EFR_POSITION, &RGE_EFR_MIXED];

impl StrategyInfo {
    /// Every strategy, in the registry's order.
    pub fn all() -> impl Iterator<Item = &'static StrategyInfo> {
        STRATEGIES.iter().copied()
    }

    /// The strategy whose algorithm is `algo`.
    pub fn by_algo(algo: &str) -> Option<&'static StrategyInfo> {
        StrategyInfo::all().find(|s| s.algo == algo)
    }
}

/// A learner's variant: the original code's behaviour, or its defects fixed
/// (docs/original-code.md section 5).
#[derive(Debug, PartialEq)]
pub struct VariantInfo {
    /// Name in campaign files and results (`corrected`).
    pub name: &'static str,
    /// One line for `--help` and the docs.
    pub description: &'static str,
    /// Whether a figure that compares variants draws it dashed with hollow markers.
    pub dashed: bool,
}

/// A learner without variants.
pub static NO_VARIANT: VariantInfo = VariantInfo {
    name: "none",
    description: "a learner without variants",
    dashed: false,
};
/// The original code's behaviour, defects included.
pub static FAITHFUL: VariantInfo = VariantInfo {
    name: "faithful",
    description: "the original code's behaviour, defects included",
    dashed: false,
};
/// The original code's defects fixed.
pub static CORRECTED: VariantInfo = VariantInfo {
    name: "corrected",
    description: "the original code's defects fixed",
    dashed: true,
};

/// Every variant, in the report's order.
pub static VARIANTS: [&VariantInfo; 3] = [&NO_VARIANT, &FAITHFUL, &CORRECTED];

impl VariantInfo {
    /// Every variant, in the registry's order.
    pub fn all() -> impl Iterator<Item = &'static VariantInfo> {
        VARIANTS.iter().copied()
    }

    /// The variant called `name`.
    pub fn by_name(name: &str) -> Option<&'static VariantInfo> {
        VariantInfo::all().find(|v| v.name == name)
    }
}

/// How modular goal exploration (the follow-up paper) chooses the module of a goal: its
/// algorithms are `mge-<space>-<choice>`, the space `efr` ([`ENGINEERED_SPACE`]) or a learner's.
#[derive(Debug, PartialEq)]
pub struct ModuleChoiceInfo {
    /// Name in algorithm names (`lp`).
    pub name: &'static str,
    /// The follow-up's name of the strategy: `RGE` for one module holding every coordinate,
    /// `MGE` otherwise.
    pub strategy: &'static str,
    /// Name in the report (`LP`).
    pub display: &'static str,
    /// One line for `--help` and the docs.
    pub description: &'static str,
}

/// One module holding every coordinate: the follow-up's RGE.
pub static FLAT: ModuleChoiceInfo = ModuleChoiceInfo {
    name: "flat",
    strategy: "RGE",
    display: "flat",
    description: "one module holding every coordinate (the follow-up's RGE)",
};
/// A module chosen uniformly.
pub static RANDOM_MODULE: ModuleChoiceInfo = ModuleChoiceInfo {
    name: "random",
    strategy: "MGE",
    display: "random",
    description: "a module chosen uniformly",
};
/// A module chosen by learning progress.
pub static LEARNING_PROGRESS: ModuleChoiceInfo = ModuleChoiceInfo {
    name: "lp",
    strategy: "MGE",
    display: "LP",
    description: "a module chosen by learning progress (epsilon-greedy on the interests)",
};

/// Every module choice, in the report's order.
pub static MODULE_CHOICES: [&ModuleChoiceInfo; 3] = [&FLAT, &RANDOM_MODULE, &LEARNING_PROGRESS];

/// The engineered features as a modular goal space's name (`mge-efr-lp`), and its display name.
pub const ENGINEERED_SPACE: (&str, &str) = ("efr", "EFR");

/// The mixed engineered space of modular algorithms (`mge-efr-mixed-lp`), and its report name.
pub const MIXED_SPACE: (&str, &str) = ("efr-mixed", "EFR (mixed)");

/// The prefix of the modular algorithms' names (`mge-vae-lp`).
pub const MODULAR_PREFIX: &str = "mge-";

impl ModuleChoiceInfo {
    /// The module choice called `name`.
    pub fn by_name(name: &str) -> Option<&'static ModuleChoiceInfo> {
        MODULE_CHOICES.iter().copied().find(|c| c.name == name)
    }
}
