//! The report's vocabulary: display names, orders and bounds of environments, algorithms,
//! learners, samplers and variants, read from `ugl-types`' registries. Analysis, figures and
//! prose all name things through here, so that a name is spelt once.

use ugl_types::LearnerInfo;

use crate::load::ConditionKey;

/// The KDE-vs-Gaussian figures: the paper's Figure 4 (RGE-VAE), and the same for RGE-RFVAE,
/// which the paper did not plot (drawn when its Gaussian-goal runs exist).
pub const SAMPLER_FIGURES: [(&str, &str); 2] = [
    ("rge-vae", "fig4_vae_kde_vs_gaussian.svg"),
    ("rge-rfvae", "rfvae_kde_vs_gaussian.svg"),
];

/// The paper's algorithms, in the report's order: RPE, RGE-EFR, then the registry's learners
/// that the paper evaluated (PCA, Isomap, AE, VAE, RFVAE).
pub fn algos() -> Vec<&'static str> {
    let mut v = vec!["rpe", "rge-efr"];
    v.extend(LearnerInfo::paper_algos());
    v
}

/// The algorithms with a fixed colour and marker, in slot order: the paper's ([`algos`]), the
/// position-only EFR, then the registry's other learners in its order (the β-VAE, the random
/// projection, ...). They index the figures' colours and the marker shapes, so that an algorithm
/// looks the same in every figure and environment; an algorithm outside the registry takes the
/// following slots.
pub fn style_algos() -> Vec<&'static str> {
    let mut v = algos();
    v.push("rge-efr-position");
    v.extend(LearnerInfo::all().filter(|l| !l.in_paper).map(|l| l.algo));
    v
}

/// Display name of an environment.
pub fn env_name(env: &str) -> String {
    ugl_types::EnvSpec::display_of(env)
}

/// Display name of an algorithm (`rge-vae` → `RGE-VAE`): `RGE-` and the registry's display
/// name of the learner; unknown names in capitals.
pub fn algo_name(algo: &str) -> String {
    match algo {
        "rpe" => "RPE".into(),
        "rge-efr" => "RGE-EFR".into(),
        "rge-efr-position" => "RGE-EFR (position only)".into(),
        other => match LearnerInfo::by_algo(other) {
            Some(l) => format!("RGE-{}", l.display),
            None => other.to_uppercase(),
        },
    }
}

/// An algorithm with its variant: `RGE-VAE (corrected)`; `RGE-AE` for variant `none`.
/// *faithful* is the original code's behaviour, defects included (docs/original-code.md section 5);
/// *corrected* has those defects fixed.
pub fn condition_name(algo: &str, variant: &str) -> String {
    let a = algo_name(algo);
    match variant {
        "" | "none" => a,
        v => format!("{a} ({v})"),
    }
}

/// Display name of a goal sampler: `KDE`, `Gaussian` (the VAE's isotropic prior), `uniform`
/// (EFR), `none` (RPE).
pub fn sampler_name(sampler: &str) -> String {
    match sampler {
        "kde" => "KDE".into(),
        "gaussian" => "Gaussian".into(),
        other => other.to_string(),
    }
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

/// `RGE-VAE (faithful), KDE goals, 10 latents` etc.; RPE and RGE-EFR are named alone.
pub fn describe_key(k: &ConditionKey) -> String {
    let mut s = condition_name(&k.algo, &k.variant);
    if !matches!(k.sampler.as_str(), "none" | "uniform") {
        s.push_str(&format!(", {} goals", sampler_name(&k.sampler)));
    }
    if k.latents != 0 {
        s.push_str(&format!(", {} latents", k.latents));
    }
    s
}
