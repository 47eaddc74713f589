//! The follow-up's conditions, their names and order, and number formats.
//!
//! A condition of the page is an algorithm, the tag of the variant campaign its runs come from
//! (`still`), and, when the campaigns ran one algorithm with several goal samplers or latent
//! sizes, which one: a [`Condition`], never a string to parse.

use ugl_types::{Algo, ConditionKey, ENGINEERED_SPACE, MODULE_CHOICES, ModuleChoiceInfo, Sampler};

use crate::names::{learner_name, sampler_name};

/// A condition of the follow-up's page.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Condition {
    pub algo: Algo,
    /// The variant campaign's tag (`still`), None for the main campaign's runs.
    pub tag: Option<String>,
    /// The goal sampler and latent size, where the campaigns ran this algorithm (and campaign)
    /// with several: those runs are separate conditions, never pooled.
    pub split: Option<(Sampler, i64)>,
}

impl Condition {
    /// The condition of a run's key: pooled over samplers and latent sizes unless `split`.
    pub fn of(key: &ConditionKey, split: bool) -> Condition {
        Condition {
            algo: key.algo.clone(),
            tag: key.tag.clone(),
            split: split.then(|| (key.sampler.clone(), key.latents)),
        }
    }

    /// The variant campaign's tag, or "".
    pub fn tag(&self) -> &str {
        self.tag.as_deref().unwrap_or("")
    }

    /// The modular goal space (`efr`, `vae`) and module choice; ("", None) for RPE.
    pub fn parts(&self) -> (&str, Option<&'static ModuleChoiceInfo>) {
        match self.algo.modular() {
            Some((space, choice)) => (space, Some(choice)),
            None => ("", None),
        }
    }

    /// Whether its module choice is `choice`.
    pub fn chooses(&self, choice: &ModuleChoiceInfo) -> bool {
        self.parts().1.is_some_and(|c| c == choice)
    }

    /// Whether its goal space is the engineered features.
    pub fn engineered(&self) -> bool {
        self.parts().0 == ENGINEERED_SPACE.0
    }

    /// The page's order: by campaign tag, goal space (none, the engineered features, the VAE,
    /// the β-VAE, others), module choice, then sampler and latent size.
    pub fn order(&self) -> impl Ord + use<> {
        let (space, choice) = self.parts();
        let spaces = [
            "",
            ENGINEERED_SPACE.0,
            ugl_types::learners::VAE.name,
            ugl_types::learners::BVAE.name,
        ];
        let s = spaces
            .iter()
            .position(|x| *x == space)
            .unwrap_or(spaces.len());
        let c = choice
            .and_then(|c| MODULE_CHOICES.iter().position(|x| *x == c))
            .unwrap_or(MODULE_CHOICES.len());
        (
            self.tag().to_string(),
            s,
            space.to_string(),
            c,
            self.split.clone(),
        )
    }

    /// The follow-up's name of the algorithm: `RGE-EFR (flat)`, `MGE-β-VAE (LP)`,
    /// `MGE-VAE (random)`, `RPE`.
    pub fn algo_label(&self) -> String {
        match self.parts() {
            (space, Some(choice)) => {
                let space = if space == ENGINEERED_SPACE.0 {
                    ENGINEERED_SPACE.1.to_string()
                } else if space == ugl_types::MIXED_SPACE.0 {
                    ugl_types::MIXED_SPACE.1.to_string()
                } else {
                    learner_name(space)
                };
                format!("{}-{space} ({})", choice.strategy, choice.display)
            }
            _ => self.algo.display(),
        }
    }

    /// `, KDE goals, 4 latents` for a condition that names its sampler and latent size, else "".
    pub fn suffix_label(&self) -> String {
        match &self.split {
            Some((sampler, latents)) => {
                format!(", {} goals, {latents} latents", sampler_name(sampler))
            }
            None => String::new(),
        }
    }

    /// Its name with the campaign's tag as the tag (`RGE-EFR (flat), still`); the page names a
    /// tag by the label its campaign declares ([`super::runs::display`]).
    pub fn label(&self) -> String {
        let tag = self
            .tag
            .as_ref()
            .map(|t| format!(", {t}"))
            .unwrap_or_default();
        format!("{}{tag}{}", self.algo_label(), self.suffix_label())
    }
}

pub(super) fn f3(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3}")
    } else {
        "n/a".into()
    }
}

pub(super) fn f2(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2}")
    } else {
        "n/a".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cond(algo: &str, tag: Option<&str>, split: Option<(&str, i64)>) -> Condition {
        Condition {
            algo: algo.into(),
            tag: tag.map(String::from),
            split: split.map(|(s, l)| (s.into(), l)),
        }
    }

    #[test]
    fn labels_follow_the_follow_up() {
        assert_eq!(cond("rpe", None, None).label(), "RPE");
        assert_eq!(cond("mge-efr-flat", None, None).label(), "RGE-EFR (flat)");
        assert_eq!(cond("mge-vae-lp", None, None).label(), "MGE-VAE (LP)");
        assert!(
            cond("mge-bvae-random", None, None)
                .label()
                .starts_with("MGE-")
        );
        assert!(cond("mge-efr-lp", None, None).order() < cond("mge-vae-flat", None, None).order());
        assert_eq!(
            cond("mge-efr-flat", Some("still"), None).label(),
            "RGE-EFR (flat), still"
        );
        assert_eq!(
            cond("mge-vae-lp", None, Some(("kde", 4))).label(),
            "MGE-VAE (LP), KDE goals, 4 latents"
        );
        let c = cond("mge-vae-lp", Some("still"), Some(("kde", 4)));
        assert_eq!((c.tag(), c.parts().0), ("still", "vae"));
        assert!(c.chooses(&ugl_types::LEARNING_PROGRESS));
        assert!(
            cond("mge-vae-lp", None, Some(("kde", 4))).order()
                < cond("mge-vae-lp", None, Some(("kde", 10))).order()
        );
    }
}
