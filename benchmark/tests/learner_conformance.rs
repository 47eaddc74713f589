//! The plug-in conformance suite: every registered representation learner must fit
//! deterministically for a seed, return (n, latents) finite encodings, and encode its training
//! images stably (batch and single-image paths agree with the fitted encodings), fit the same
//! with the harness's context, and, where its encoders persist in the model cache, load them
//! back bit-identical.
//!
//! A new learner is covered by its entry in the registry (`repr/registry.rs`); the external
//! learner runs with the example program when python3 + numpy are present. The neural learners
//! run with tiny networks and budgets, in their corrected variant: the faithful RFVAE encodes
//! outcomes stochastically in another space than its training latents (the original code's
//! defect, which it reproduces on purpose; `neural.rs` tests it).

use ugl_bench::campaign::config::LearnersConfig;
use ugl_bench::campaign::fit::make_learner;
use ugl_bench::env::{EnvConfig, EnvKind, make_env};
use ugl_bench::explore::Learner;
use ugl_bench::repr::dataset::generate;
use ugl_bench::repr::neural::Variant;
use ugl_bench::repr::{FitContext, ImageSet};
use ugl_bench::seed::{Component, stream, stream_named};

fn images(kind: EnvKind, n: usize) -> ImageSet {
    let env = make_env(kind, &EnvConfig::default());
    generate(env.as_ref(), n, &mut stream(11, Component::Dataset))
        .unwrap()
        .images
}

fn python_numpy() -> bool {
    std::process::Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

fn learners_config() -> LearnersConfig {
    let mut text = format!(
        "[external]\nname = \"random-projection\"\n\
         command = \"python3 {}/../scripts/external_learners/random_projection.py\"\n",
        env!("CARGO_MANIFEST_DIR")
    );
    // Every neural learner of the registry, with a tiny network and budget (a new one too).
    for model in Learner::all().filter_map(Learner::model) {
        text.push_str(&format!("[{}]\n{TINY}", model.name()));
        if model.spec().paper_warmup() > 0 {
            text.push_str("warmup = 10\n");
        }
    }
    // And every convolutional one.
    for model in Learner::all().filter_map(Learner::conv_model) {
        text.push_str(&format!("[{}]\n{TINY_CONV}", model.name()));
    }
    let cfg: LearnersConfig = toml::from_str(&text).unwrap();
    cfg.validate().unwrap();
    cfg
}

/// Tiny networks and budgets.
const TINY: &str = "iterations = 20\nhidden = [32, 16]\n";
const TINY_CONV: &str = "iterations = 6\nfilters = 4\nhidden = 16\nbatch = 8\n";

/// The environments a learner is tried on: those that render the pictures it is built for,
/// else ArmBall and ArmArrow.
fn environments(learner: Learner) -> Vec<(EnvKind, usize)> {
    match learner.entry().image {
        Some(shape) => EnvKind::all()
            .into_iter()
            .filter(|k| k.spec().image == shape)
            .flat_map(|k| [(k, 2), (k, 10)])
            .collect(),
        None => vec![(EnvKind::ARMBALL, 2), (EnvKind::ARMARROW, 10)],
    }
}

#[test]
fn every_registered_learner_conforms() {
    let cfg = learners_config();
    for learner in Learner::all() {
        if learner.is_external() && !python_numpy() {
            eprintln!("SKIPPED: external learner conformance (python3 with numpy not found)");
            continue;
        }
        let envs = environments(learner);
        assert!(
            !envs.is_empty(),
            "{learner}: no environment renders its pictures"
        );
        for (kind, latents) in envs {
            let set = images(kind, 300);
            let l = make_learner(learner, &cfg, Some(Variant::Corrected)).unwrap();
            let who = format!("{} on {kind} with {latents} latents", learner.name());
            let (mut enc, z) = l
                .fit(&set, latents, &mut stream_named(1, "learner"))
                .unwrap_or_else(|e| panic!("{who}: {e}"));
            assert_eq!(
                (z.n, z.latents, z.data.len()),
                (300, latents, 300 * latents),
                "{who}: shape"
            );
            assert!(z.data.iter().all(|v| v.is_finite()), "{who}: finite");
            assert_eq!(enc.latents(), latents, "{who}");
            // Deterministic for a stream.
            let (_, z2) = l
                .fit(&set, latents, &mut stream_named(1, "learner"))
                .unwrap();
            assert_eq!(
                z.data, z2.data,
                "{who}: two fits with the same stream differ"
            );
            // Encoding the training images reproduces the fitted encodings.
            let again = enc.encode(&set).unwrap();
            let scale = z.data.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
            let worst = again
                .data
                .iter()
                .zip(&z.data)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                worst <= 1e-6 * scale,
                "{who}: batch re-encoding differs by {worst:e} (scale {scale})"
            );
            let mut one = vec![0.0; latents];
            for i in [0, 17, 299] {
                enc.encode_one(set.row(i), &mut one).unwrap();
                for (a, b) in one.iter().zip(z.row(i)) {
                    assert!(
                        (a - b).abs() <= 1e-6 * scale,
                        "{who}: encode_one of image {i}: {a} vs {b}"
                    );
                }
            }
            // The harness's fit (with a context) is the plain fit.
            let (_, z3) = l
                .fit_in(
                    &set,
                    latents,
                    &mut stream_named(1, "learner"),
                    &FitContext::default(),
                )
                .unwrap();
            assert_eq!(z.data, z3.data, "{who}: fit_in differs from fit");
            // A learner whose encoders persist loads them back bit-identical: same training
            // latents (what the KDE is fitted on), same encodings; other keys and damaged
            // bytes are refused.
            if l.persists() {
                let bytes = enc
                    .save("k")
                    .unwrap_or_else(|| panic!("{who}: persists but saves nothing"));
                let mut back = l.load("k", &bytes).unwrap_or_else(|e| panic!("{who}: {e}"));
                assert_eq!(back.training_latents(&set).unwrap().data, z.data, "{who}");
                assert_eq!(back.encode(&set).unwrap().data, again.data, "{who}");
                assert!(l.load("other", &bytes).is_err(), "{who}: key");
                let mut bad = bytes.clone();
                let at = bad.len() / 2;
                bad[at] ^= 1;
                assert!(l.load("k", &bad).is_err(), "{who}: flipped byte");
                assert!(
                    l.load("k", &bytes[..bytes.len() - 1]).is_err(),
                    "{who}: cut"
                );
            }
            // Bad input is an error, never a panic.
            assert!(
                l.fit(&set, 0, &mut stream_named(1, "learner")).is_err(),
                "{who}: latents = 0"
            );
            assert!(
                enc.encode_one(&[0.0; 10], &mut one).is_err(),
                "{who}: wrong image size"
            );
        }
    }
}
