//! The follow-up's names for the algorithms, their order, and number formats.

use crate::figures::learner_name;

/// The variant campaign's tag of an algorithm (`still` in `mge-efr-flat@still`), or "".
pub(super) fn tag(algo: &str) -> &str {
    algo.split_once('@').map(|t| t.1).unwrap_or("")
}

/// `mge-<space>-<choice>[@tag]` → (space, choice); `rpe` → ("", "").
pub(super) fn parts(algo: &str) -> (&str, &str) {
    let algo = algo.split('@').next().unwrap_or(algo);
    match algo.strip_prefix("mge-").and_then(|r| r.rsplit_once('-')) {
        Some((space, choice)) => (space, choice),
        None => ("", ""),
    }
}

pub(super) fn algo_order(algo: &str) -> (String, usize, String, usize) {
    let tag = algo.split_once('@').map(|t| t.1).unwrap_or("").to_string();
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
    (tag, s, space.to_string(), c)
}

/// The follow-up's names: `RGE-EFR` (flat), `MGE-β-VAE (LP)`, `MGE-VAE (random)`, `RPE`; a
/// variant's conditions (`ALGO@TAG`) keep their tag ([`display`] gives its declared label).
pub fn label(algo: &str) -> String {
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
    }
}
