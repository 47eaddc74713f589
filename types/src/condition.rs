//! A condition of the results: everything that identifies a curve, except the repetition.
//! Its parts are typed names ([`Algo`], [`Sampler`], [`Variant`]) that know their registry
//! entries, so that code asks a name for its description instead of spelling it; a name outside
//! the registries (an external learner's algorithm) is kept as it is and ordered after the
//! known ones.

use std::borrow::{Borrow, Cow};
use std::fmt;
use std::ops::Deref;

use crate::env::EnvSpec;
use crate::learner::{self, LearnerInfo};
use crate::manifest::Manifest;
use crate::sampler::{self, SamplerInfo};
use crate::strategy::{self, MODULAR_PREFIX, ModuleChoiceInfo, StrategyInfo, VariantInfo};

macro_rules! name_type {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name(Cow<'static, str>);

        impl $name {
            /// The name as written in results.
            pub fn as_str(&self) -> &str {
                &self.0
            }
        }
        impl Deref for $name {
            type Target = str;
            fn deref(&self) -> &str {
                &self.0
            }
        }
        impl Borrow<str> for $name {
            fn borrow(&self) -> &str {
                &self.0
            }
        }
        impl AsRef<str> for $name {
            fn as_ref(&self) -> &str {
                &self.0
            }
        }
        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(&self.0)
            }
        }
        impl From<&str> for $name {
            fn from(s: &str) -> Self {
                $name(Cow::Owned(s.to_string()))
            }
        }
        impl From<String> for $name {
            fn from(s: String) -> Self {
                $name(Cow::Owned(s))
            }
        }
        impl From<&String> for $name {
            fn from(s: &String) -> Self {
                $name(Cow::Owned(s.clone()))
            }
        }
        impl PartialEq<str> for $name {
            fn eq(&self, other: &str) -> bool {
                *self.0 == *other
            }
        }
        impl PartialEq<&str> for $name {
            fn eq(&self, other: &&str) -> bool {
                *self.0 == **other
            }
        }
        impl PartialEq<String> for $name {
            fn eq(&self, other: &String) -> bool {
                *self.0 == **other
            }
        }
        impl PartialEq<$name> for str {
            fn eq(&self, other: &$name) -> bool {
                *self == *other.0
            }
        }
        impl PartialEq<$name> for &str {
            fn eq(&self, other: &$name) -> bool {
                **self == *other.0
            }
        }
        impl PartialEq<$name> for String {
            fn eq(&self, other: &$name) -> bool {
                **self == *other.0
            }
        }
        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(&self.0)
            }
        }
    };
}

name_type!(
    /// An algorithm: a strategy of [`StrategyInfo`] (`rpe`, `rge-efr`) or a learned goal space
    /// `rge-<learner>` of [`LearnerInfo`].
    Algo
);
name_type!(
    /// A goal sampler of [`SamplerInfo`].
    Sampler
);
name_type!(
    /// A learner's variant of [`VariantInfo`].
    Variant
);

/// What an algorithm is, from the registries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlgoInfo {
    /// A strategy without a learned goal space.
    Strategy(&'static StrategyInfo),
    /// A learned goal space.
    Learner(&'static LearnerInfo),
}

impl Algo {
    /// Random parameter exploration.
    pub const RPE: Algo = Algo(Cow::Borrowed(strategy::RPE.algo));
    /// Random goal exploration in the engineered features.
    pub const RGE_EFR: Algo = Algo(Cow::Borrowed(strategy::RGE_EFR.algo));
    /// RGE-EFR on the position alone.
    pub const RGE_EFR_POSITION: Algo = Algo(Cow::Borrowed(strategy::RGE_EFR_POSITION.algo));
    /// The faithful VAE's goal space (the paper's Figure 4).
    pub const RGE_VAE: Algo = Algo(Cow::Borrowed(learner::VAE.algo));
    /// The radial-flow VAE's goal space.
    pub const RGE_RFVAE: Algo = Algo(Cow::Borrowed(learner::RFVAE.algo));

    /// The algorithm that explores a learner's goal space.
    pub const fn of_learner(l: &'static LearnerInfo) -> Algo {
        Algo(Cow::Borrowed(l.algo))
    }

    /// Its registry entry; None for a name outside the registries.
    pub fn info(&self) -> Option<AlgoInfo> {
        StrategyInfo::by_algo(self)
            .map(AlgoInfo::Strategy)
            .or_else(|| LearnerInfo::by_algo(self).map(AlgoInfo::Learner))
    }

    /// The learner whose goal space it explores (None for RPE, RGE-EFR and unknown names).
    pub fn learner(&self) -> Option<&'static LearnerInfo> {
        LearnerInfo::by_algo(self)
    }

    /// Whether its goal space is learned, with latents (false for RPE and the engineered
    /// features; true for names outside the registries, which come from learners).
    pub fn has_latents(&self) -> bool {
        StrategyInfo::by_algo(self).is_none()
    }

    /// A modular algorithm's goal space (`efr` or a learner's name) and module choice
    /// (`mge-vae-lp` → (`vae`, LP)); None for the other algorithms.
    pub fn modular(&self) -> Option<(&str, &'static ModuleChoiceInfo)> {
        let (space, choice) = self.strip_prefix(MODULAR_PREFIX)?.rsplit_once('-')?;
        Some((space, ModuleChoiceInfo::by_name(choice)?))
    }

    /// The paper's algorithms, in the report's order: its strategies (RPE, RGE-EFR), then the
    /// registry's learners that the paper evaluated.
    pub fn paper() -> Vec<Algo> {
        Algo::paper_names()
            .into_iter()
            .map(Algo::borrowed)
            .collect()
    }

    /// [`Algo::paper`], as names.
    pub fn paper_names() -> Vec<&'static str> {
        StrategyInfo::all()
            .filter(|s| s.in_paper)
            .map(|s| s.algo)
            .chain(LearnerInfo::all().filter(|l| l.in_paper).map(|l| l.algo))
            .collect()
    }

    /// [`Algo::styled`], as names: every strategy and learner in the order of its entry's
    /// `style` slot (slot `i` at index `i`).
    pub fn styled_names() -> Vec<&'static str> {
        let mut v: Vec<(usize, &'static str)> = StrategyInfo::all()
            .map(|s| (s.style, s.algo))
            .chain(LearnerInfo::all().map(|l| (l.style, l.algo)))
            .collect();
        v.sort();
        v.into_iter().map(|(_, a)| a).collect()
    }

    const fn borrowed(name: &'static str) -> Algo {
        Algo(Cow::Borrowed(name))
    }

    /// Its name in the report: the strategy's (`RGE-EFR`), `RGE-` and the learner's
    /// (`RGE-VAE`), or the name in capitals outside the registries.
    pub fn display(&self) -> String {
        match self.info() {
            Some(AlgoInfo::Strategy(s)) => s.display.to_string(),
            Some(AlgoInfo::Learner(l)) => format!("RGE-{}", l.display),
            None => self.to_uppercase(),
        }
    }

    /// The algorithms with a fixed style, in slot order (each entry's `style`: the paper's
    /// first, as [`Algo::paper`] lists them). An algorithm looks the same in every figure, and
    /// adding an entry moves no other's style; one outside the registries takes the following
    /// slots.
    pub fn styled() -> Vec<Algo> {
        Algo::styled_names()
            .into_iter()
            .map(Algo::borrowed)
            .collect()
    }
}

impl Sampler {
    /// No goals (RPE).
    pub const NONE: Sampler = Sampler(Cow::Borrowed(sampler::NONE.name));
    /// Uniform in the engineered box.
    pub const UNIFORM: Sampler = Sampler(Cow::Borrowed(sampler::UNIFORM.name));
    /// The KDE of the training latents.
    pub const KDE: Sampler = Sampler(Cow::Borrowed(sampler::KDE.name));
    /// The prior N(0, I).
    pub const GAUSSIAN: Sampler = Sampler(Cow::Borrowed(sampler::GAUSSIAN.name));

    /// The sampler of a registry entry.
    pub const fn of(s: &'static SamplerInfo) -> Sampler {
        Sampler(Cow::Borrowed(s.name))
    }

    /// Its registry entry.
    pub fn info(&self) -> Option<&'static SamplerInfo> {
        SamplerInfo::by_name(self)
    }

    /// Its name in the report (`KDE`); a name outside the registry as it is.
    pub fn display(&self) -> &str {
        self.info().map_or(self.as_str(), |s| s.display)
    }

    /// Whether it samples a learned goal space (KDE, prior): the report names it with the
    /// condition. Unknown names are taken as learned.
    pub fn is_learned(&self) -> bool {
        self.info().is_none_or(|s| s.learned)
    }
}

impl Variant {
    /// A learner without variants.
    pub const NONE: Variant = Variant(Cow::Borrowed(strategy::NO_VARIANT.name));
    /// The original code's behaviour.
    pub const FAITHFUL: Variant = Variant(Cow::Borrowed(strategy::FAITHFUL.name));
    /// The original code's defects fixed.
    pub const CORRECTED: Variant = Variant(Cow::Borrowed(strategy::CORRECTED.name));

    /// The variant of a registry entry.
    pub const fn of(v: &'static VariantInfo) -> Variant {
        Variant(Cow::Borrowed(v.name))
    }

    /// Its registry entry.
    pub fn info(&self) -> Option<&'static VariantInfo> {
        VariantInfo::by_name(self)
    }

    /// Whether a figure that compares variants draws it dashed, with hollow markers.
    pub fn is_dashed(&self) -> bool {
        self.info().is_some_and(|v| v.dashed)
    }
}

/// A condition: everything that identifies a curve in the figures, except the repetition.
///
/// Its derived order (by spelling) only keys maps; the report's order is [`Self::order_key`].
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ConditionKey {
    /// The environment ([`EnvSpec`]).
    pub env: String,
    pub algo: Algo,
    pub sampler: Sampler,
    /// Latent dimension of the goal space (0 without latents).
    pub latents: i64,
    pub variant: Variant,
    /// The tag of the campaign that varies the main one on its repetitions (`untrained` for
    /// `paper-untrained`'s twins, `still` for the follow-up's still distractor); None for the
    /// main campaign's conditions.
    pub tag: Option<String>,
}

impl ConditionKey {
    /// The condition of a run, from its manifest (untagged: its campaign tags it).
    pub fn of_manifest(m: &Manifest) -> ConditionKey {
        ConditionKey {
            env: m.env.clone(),
            algo: m.algo.as_str().into(),
            sampler: m.sampler.as_str().into(),
            latents: m.latents as i64,
            variant: m.variant.as_str().into(),
            tag: None,
        }
    }

    /// The same condition in the campaign tagged `tag`.
    pub fn tagged(&self, tag: Option<&str>) -> ConditionKey {
        ConditionKey {
            tag: tag.map(str::to_string),
            ..self.clone()
        }
    }

    /// The algorithm as a claims file selects it: `ALGO`, or `ALGO@TAG` for a tagged campaign's
    /// condition (`rge-vae@untrained`).
    pub fn tagged_algo(&self) -> String {
        match &self.tag {
            Some(t) => format!("{}@{t}", self.algo),
            None => self.algo.to_string(),
        }
    }

    /// A stable canonical string, used for file names and bootstrap seeds.
    pub fn slug(&self) -> String {
        format!(
            "{}_{}_{}_{}_{}",
            self.env,
            self.tagged_algo(),
            self.sampler,
            self.latents,
            self.variant
        )
    }

    /// The order of conditions everywhere in the report: environments, then latent sizes, then
    /// the paper's algorithm order, the samplers' and the variants' registry order; unknown
    /// names after known ones, alphabetically.
    pub fn order_key(&self) -> impl Ord + use<> {
        let algo_rank = {
            let paper = Algo::paper_names();
            rank(paper.into_iter(), &self.algo)
        };
        (
            EnvSpec::order(&self.env),
            self.env.clone(),
            self.latents,
            algo_rank,
            self.algo.clone(),
            rank(
                SamplerInfo::all()
                    .map(|s| s.name)
                    .collect::<Vec<_>>()
                    .into_iter(),
                &self.sampler,
            ),
            self.sampler.clone(),
            rank(strategy::VARIANTS.iter().map(|v| v.name), &self.variant),
            self.variant.clone(),
            self.tag.clone(),
        )
    }
}

/// Position of `name` among `known`, or their number for an unknown name.
fn rank<'a>(known: impl ExactSizeIterator<Item = &'a str>, name: &str) -> usize {
    let n = known.len();
    known.into_iter().position(|k| k == name).unwrap_or(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every strategy and learner has its own style slot, the slots run from 0 without a gap,
    /// and the paper's algorithms hold the first ones in the paper's order: a new entry takes
    /// the next free slot and moves no other algorithm's colour or marker.
    #[test]
    fn style_slots_are_distinct_contiguous_and_the_papers_first() {
        let mut slots: Vec<usize> = StrategyInfo::all()
            .map(|s| s.style)
            .chain(LearnerInfo::all().map(|l| l.style))
            .collect();
        slots.sort();
        assert_eq!(slots, (0..slots.len()).collect::<Vec<_>>());
        let styled = Algo::styled_names();
        let paper = Algo::paper_names();
        assert_eq!(&styled[..paper.len()], &paper[..]);
        assert_eq!(styled.len(), slots.len());
    }

    #[test]
    fn names_know_their_registry_entries() {
        assert_eq!(Algo::RPE.info(), Some(AlgoInfo::Strategy(&strategy::RPE)));
        assert_eq!(Algo::RGE_VAE.learner(), Some(&learner::VAE));
        assert!(Algo::from("rge-mine").info().is_none());
        assert!(Algo::from("rge-mine").has_latents() && !Algo::RGE_EFR.has_latents());
        assert_eq!(Sampler::KDE.info().map(|s| s.display), Some("KDE"));
        assert!(Sampler::GAUSSIAN.is_learned() && !Sampler::UNIFORM.is_learned());
        assert!(Variant::CORRECTED.is_dashed() && !Variant::FAITHFUL.is_dashed());
        let paper: Vec<String> = Algo::paper().iter().map(|a| a.to_string()).collect();
        assert_eq!(
            paper,
            [
                "rpe",
                "rge-efr",
                "rge-pca",
                "rge-isomap",
                "rge-ae",
                "rge-vae",
                "rge-rfvae"
            ]
        );
    }

    #[test]
    fn the_order_follows_the_registries_with_unknown_names_last() {
        let key = |algo: &str, sampler: &str, variant: &str| ConditionKey {
            env: "armball".into(),
            algo: algo.into(),
            sampler: sampler.into(),
            latents: 10,
            variant: variant.into(),
            tag: None,
        };
        let mut keys = [
            key("rge-mine", "kde", "none"),
            key("rge-vae", "gaussian", "corrected"),
            key("rge-vae", "kde", "corrected"),
            key("rge-vae", "kde", "faithful"),
            key("rge-ae", "kde", "none"),
        ];
        keys.sort_by_key(|k| k.order_key());
        let got: Vec<String> = keys.iter().map(|k| k.slug()).collect();
        assert_eq!(
            got,
            [
                "armball_rge-ae_kde_10_none",
                "armball_rge-vae_kde_10_faithful",
                "armball_rge-vae_kde_10_corrected",
                "armball_rge-vae_gaussian_10_corrected",
                "armball_rge-mine_kde_10_none",
            ]
        );
    }
}
