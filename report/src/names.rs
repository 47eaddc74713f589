//! The report's vocabulary: display names, orders and bounds of environments, algorithms,
//! learners, samplers and variants, read from `ugl-types`' registries. Analysis, figures and
//! prose all name things through here, so that a name is spelt once.

use ugl_types::{LearnerInfo, SamplerInfo, VariantInfo};

use crate::load::{Algo, ConditionKey, Variant};

/// The KDE-vs-Gaussian figures: the paper's Figure 4 (RGE-VAE), and the same for RGE-RFVAE,
/// which the paper did not plot (drawn when its Gaussian-goal runs exist).
pub const SAMPLER_FIGURES: [(Algo, &str); 2] = [
    (Algo::RGE_VAE, "fig4_vae_kde_vs_gaussian.svg"),
    (Algo::RGE_RFVAE, "rfvae_kde_vs_gaussian.svg"),
];

/// The paper's algorithms, in the report's order: RPE, RGE-EFR, then the registry's learners
/// that the paper evaluated (PCA, Isomap, AE, VAE, RFVAE).
pub fn algos() -> Vec<&'static str> {
    Algo::paper_names()
}

/// The algorithms with a fixed colour and marker, in slot order: the paper's ([`algos`]), the
/// position-only EFR, then the registry's other learners in its order (the β-VAE, the random
/// projection, ...). They index the figures' colours and the marker shapes, so that an algorithm
/// looks the same in every figure and environment; an algorithm outside the registry takes the
/// following slots.
pub fn style_algos() -> Vec<&'static str> {
    Algo::styled_names()
}

/// Display name of an environment.
pub fn env_name(env: &str) -> String {
    ugl_types::EnvSpec::display_of(env)
}

/// Display name of an algorithm (`rge-vae` → `RGE-VAE`): `RGE-` and the registry's display
/// name of the learner; unknown names in capitals.
pub fn algo_name(algo: &str) -> String {
    Algo::from(algo).display()
}

/// An algorithm with its variant: `RGE-VAE (corrected)`; `RGE-AE` for variant `none`.
/// *faithful* is the original code's behaviour, defects included (docs/original-code.md section 5);
/// *corrected* has those defects fixed.
pub fn condition_name(algo: &str, variant: &str) -> String {
    let a = algo_name(algo);
    if variant.is_empty() || variant == Variant::NONE {
        a
    } else {
        format!("{a} ({variant})")
    }
}

/// Display name of a goal sampler: `KDE`, `Gaussian` (the VAE's isotropic prior), `uniform`
/// (EFR), `none` (RPE).
pub fn sampler_name(sampler: &str) -> String {
    SamplerInfo::by_name(sampler).map_or_else(|| sampler.to_string(), |s| s.display.to_string())
}

/// Display name of a learner (`vae` → `VAE`): the registry's, else in capitals.
pub fn learner_name(learner: &str) -> String {
    match LearnerInfo::by_name(learner) {
        Some(l) => l.display.to_string(),
        None => learner.to_uppercase(),
    }
}

/// The environment's true latent dimension (the paper's "complete" representation): 2 for
/// ArmBall (ball x, y), 3 for ArmArrow (x, y, angle).
pub fn true_latents(env: &str) -> Option<i64> {
    ugl_types::EnvSpec::by_name(env).map(|e| e.true_latents as i64)
}

/// The paper's panel order for one algorithm's conditions: environments in the report's order,
/// then the over-complete 10 latents before the true dimension (larger latents first).
pub fn panel_order(env: &str, latents: i64) -> impl Ord + use<> {
    (
        ugl_types::EnvSpec::order(env),
        env.to_string(),
        std::cmp::Reverse(latents),
    )
}

/// The fixed KLC axis range of an environment: 0 .. ln(number of achievable cells), which is the
/// KLC of outcomes all in one cell (docs/original-code.md section 4). `None` for unknown environments.
pub fn klc_max(env: &str) -> Option<f64> {
    ugl_types::EnvSpec::by_name(env).map(|e| e.klc.max_klc())
}

/// What the object is called in titles (the registry's controllable object).
pub fn object_word(env: &str) -> &'static str {
    ugl_types::EnvSpec::by_name(env).map_or("object", |e| e.controllable_object())
}

/// [`condition_name`] of a key, with its campaign's tag: `RGE-VAE (faithful), untrained`.
pub fn tagged_condition_name(k: &ConditionKey) -> String {
    let s = condition_name(&k.algo, &k.variant);
    match &k.tag {
        Some(t) => format!("{s}, {t}"),
        None => s,
    }
}

/// `RGE-VAE (faithful), KDE goals, 10 latents` etc.; RPE and RGE-EFR are named alone.
pub fn describe_key(k: &ConditionKey) -> String {
    let mut s = tagged_condition_name(k);
    if k.sampler.is_learned() {
        s.push_str(&format!(", {} goals", sampler_name(&k.sampler)));
    }
    if k.latents != 0 {
        s.push_str(&format!(", {} latents", k.latents));
    }
    s
}

/// Colour (RGB) of a goal sampler where samplers are what a figure compares (the registry's;
/// grey outside it).
pub fn sampler_rgb(sampler: &str) -> [u8; 3] {
    SamplerInfo::by_name(sampler).map_or([0x77, 0x77, 0x77], |s| s.colour)
}

/// Marker slot of a goal sampler where samplers are compared (the registry's; 3 outside it).
pub fn sampler_marker_slot(sampler: &str) -> usize {
    SamplerInfo::by_name(sampler).map_or(3, |s| s.marker)
}

/// Whether a figure that compares variants draws this one dashed, with hollow markers.
pub fn variant_dashed(variant: &str) -> bool {
    VariantInfo::by_name(variant).is_some_and(|v| v.dashed)
}
