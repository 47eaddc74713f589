//! The goal samplers: how an exploration draws its goals (paper Section 3, "goal sampling").
//! The science crate pairs each entry with its implementation (`ugl_bench::goals::registry`);
//! the report reads names, order and style from here. Others are added at run time with
//! [`SamplerInfo::register`] and come after the built-in ones.

use std::sync::RwLock;

/// One goal sampler.
#[derive(Debug, PartialEq)]
pub struct SamplerInfo {
    /// Name in campaign files, results and on the command line (`kde`).
    pub name: &'static str,
    /// Name in the report (`KDE`).
    pub display: &'static str,
    /// One line for `--help` and the docs.
    pub description: &'static str,
    /// Whether it draws goals (false for RPE's `none`).
    pub draws_goals: bool,
    /// Whether it samples a learned goal space (the KDE of its training latents, its prior);
    /// false for the engineered box and for no goals. The report names such a sampler with
    /// every learned condition ("KDE goals").
    pub learned: bool,
    /// Whether it needs the goal space's prior (a learner whose `Prior` may declare one).
    pub needs_prior: bool,
    /// Colour (RGB) where samplers are what a figure compares (Okabe–Ito; KDE and Gaussian
    /// differ in greyscale too).
    pub colour: [u8; 3],
    /// Marker slot where samplers are compared (the figures' marker shapes).
    pub marker: usize,
}

/// No goals: random parameter exploration.
pub static NONE: SamplerInfo = SamplerInfo {
    name: "none",
    display: "none",
    description: "no goals (random parameter exploration)",
    draws_goals: false,
    learned: false,
    needs_prior: false,
    colour: [0x77, 0x77, 0x77],
    marker: 3,
};
/// Uniform goals in the engineered features' box (RGE-EFR).
pub static UNIFORM: SamplerInfo = SamplerInfo {
    name: "uniform",
    display: "uniform",
    description: "uniform in the engineered features' box (RGE-EFR)",
    draws_goals: true,
    learned: false,
    needs_prior: false,
    colour: [0x77, 0x77, 0x77],
    marker: 3,
};
/// A Gaussian KDE of the training latents: the paper's default for learned goal spaces.
pub static KDE: SamplerInfo = SamplerInfo {
    name: "kde",
    display: "KDE",
    description: "a Gaussian kernel density estimate of the training latents (the paper's default)",
    draws_goals: true,
    learned: true,
    needs_prior: false,
    colour: [0x00, 0x72, 0xB2],
    marker: 0,
};
/// The isotropic prior N(0, I) of a VAE (the paper's Figure 4, "GP").
pub static GAUSSIAN: SamplerInfo = SamplerInfo {
    name: "gaussian",
    display: "Gaussian",
    description: "the isotropic prior N(0, I) of a goal space that has one (the VAE-type networks: VAE, RFVAE, β-VAE, conv VAE, conv β-VAE)",
    draws_goals: true,
    learned: true,
    needs_prior: true,
    colour: [0xD5, 0x5E, 0x00],
    marker: 2,
};

/// The goal samplers of this crate, in the report's order.
pub static SAMPLERS: [&SamplerInfo; 4] = [&NONE, &UNIFORM, &KDE, &GAUSSIAN];

/// The samplers registered at run time, in registration order.
static REGISTRY: RwLock<Vec<&'static SamplerInfo>> = RwLock::new(Vec::new());

/// Why a sampler cannot be registered.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SamplerInfoError {
    /// Its name is taken by another sampler.
    #[error("goal sampler '{0}' is already registered")]
    Duplicate(&'static str),
    /// Its name cannot be written in run ids and file names.
    #[error("goal sampler '{0}': a name is lower-case letters, digits and '-'")]
    BadName(&'static str),
}

impl SamplerInfo {
    /// Every sampler, in the registry's order: the built-in ones, then the registered ones.
    pub fn all() -> impl Iterator<Item = &'static SamplerInfo> {
        let registered = REGISTRY.read().unwrap_or_else(|e| e.into_inner()).clone();
        SAMPLERS.iter().copied().chain(registered)
    }

    /// Add a sampler to the registry (after the built-in ones). Registering the same
    /// declaration twice is a no-op; another one under a taken name is refused.
    pub fn register(info: &'static SamplerInfo) -> Result<(), SamplerInfoError> {
        if info.name.is_empty()
            || !info
                .name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
        {
            return Err(SamplerInfoError::BadName(info.name));
        }
        let mut registered = REGISTRY.write().unwrap_or_else(|e| e.into_inner());
        match SAMPLERS
            .iter()
            .chain(registered.iter())
            .find(|s| s.name == info.name)
        {
            Some(s) if std::ptr::eq(*s, info) => Ok(()),
            Some(_) => Err(SamplerInfoError::Duplicate(info.name)),
            None => {
                registered.push(info);
                Ok(())
            }
        }
    }

    /// The sampler called `name`.
    pub fn by_name(name: &str) -> Option<&'static SamplerInfo> {
        SamplerInfo::all().find(|s| s.name == name)
    }

    /// The samplers of learned goal spaces, in order (`kde`, `gaussian`).
    pub fn learned() -> impl Iterator<Item = &'static SamplerInfo> {
        SamplerInfo::all().filter(|s| s.learned)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found() {
        for (i, s) in SAMPLERS.iter().enumerate() {
            assert_eq!(SamplerInfo::by_name(s.name), Some(*s));
            assert!(SAMPLERS[..i].iter().all(|o| o.name != s.name));
        }
        let learned: Vec<&str> = SamplerInfo::learned().map(|s| s.name).collect();
        assert_eq!(learned, ["kde", "gaussian"]);
    }
}
