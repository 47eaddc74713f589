//! The follow-up's names for the algorithms, their order, and number formats.

//!
//! A condition of the page is `ALGO[@TAG][~SAMPLER~LATENTS]`: the algorithm, the tag of the
//! variant campaign its runs come from (`mge-efr-flat@still`), and, when the campaigns ran one
//! algorithm with several goal samplers or latent sizes, which one (`mge-vae-lp~kde~4`).

use crate::names::{learner_name, sampler_name};

/// `ALGO[@TAG]` and the `(sampler, latents)` suffix of a condition, if any.
pub(super) fn split_condition(cond: &str) -> (&str, Option<(&str, &str)>) {
    match cond.split_once('~') {
        Some((base, rest)) => (base, rest.split_once('~')),
        None => (cond, None),
    }
}

/// The variant campaign's tag of a condition (`still` in `mge-efr-flat@still`), or "".
pub(super) fn tag(cond: &str) -> &str {
    let (base, _) = split_condition(cond);
    base.split_once('@').map(|t| t.1).unwrap_or("")
}

/// `mge-<space>-<choice>[@tag][~…]` → (space, choice); `rpe` → ("", "").
pub(super) fn parts(algo: &str) -> (&str, &str) {
    let algo = algo.split(['@', '~']).next().unwrap_or(algo);
    match algo.strip_prefix("mge-").and_then(|r| r.rsplit_once('-')) {
        Some((space, choice)) => (space, choice),
        None => ("", ""),
    }
}

pub(super) fn algo_order(algo: &str) -> (String, usize, String, usize, String) {
    let tag = tag(algo).to_string();
    let suffix = split_condition(algo)
        .1
        .map(|(s, l)| format!("{s}~{l:0>6}"))
        .unwrap_or_default();
    let (space, choice) = parts(algo);
    let s = match space {
        "" => 0,
        "efr" => 1,
        "vae" => 2,
        "bvae" => 3,
        _ => 4,
    };
    let c = ["flat", "random", "lp"]
        .iter()
        .position(|x| *x == choice)
        .unwrap_or(3);
    (tag, s, space.to_string(), c, suffix)
}

/// `, KDE goals, 4 latents` for a condition that names its sampler and latent size, else "".
pub(super) fn suffix_label(cond: &str) -> String {
    match split_condition(cond).1 {
        Some((sampler, latents)) => format!(", {} goals, {latents} latents", sampler_name(sampler)),
        None => String::new(),
    }
}

/// The follow-up's names: `RGE-EFR` (flat), `MGE-β-VAE (LP)`, `MGE-VAE (random)`, `RPE`; a
/// variant's conditions (`ALGO@TAG`) keep their tag ([`display`] gives its declared label).
pub fn label(algo: &str) -> String {
    if let (base, Some(_)) = split_condition(algo) {
        return format!("{}{}", label(base), suffix_label(algo));
    }
    if let Some((base, tag)) = algo.split_once('@') {
        return format!("{}, {tag}", label(base));
    }
    if algo == "rpe" {
        return "RPE".into();
    }
    let (space, choice) = parts(algo);
    let space = if space == "efr" {
        "EFR".to_string()
    } else {
        learner_name(space)
    };
    match choice {
        "flat" => format!("RGE-{space} (flat)"),
        "random" => format!("MGE-{space} (random)"),
        "lp" => format!("MGE-{space} (LP)"),
        _ => algo.to_string(),
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

    #[test]
    fn labels_follow_the_follow_up() {
        assert_eq!(label("rpe"), "RPE");
        assert_eq!(label("mge-efr-flat"), "RGE-EFR (flat)");
        assert_eq!(label("mge-vae-lp"), "MGE-VAE (LP)");
        assert!(label("mge-bvae-random").starts_with("MGE-"));
        assert!(algo_order("mge-efr-lp") < algo_order("mge-vae-flat"));
        assert_eq!(label("mge-efr-flat@still"), "RGE-EFR (flat), still");
        assert_eq!(
            label("mge-vae-lp~kde~4"),
            "MGE-VAE (LP), KDE goals, 4 latents"
        );
        assert_eq!(tag("mge-vae-lp@still~kde~4"), "still");
        assert_eq!(parts("mge-vae-lp@still~kde~4"), ("vae", "lp"));
        assert!(algo_order("mge-vae-lp~kde~4") < algo_order("mge-vae-lp~kde~10"));
    }
}
