//! The neural learners (AE, VAE, RFVAE, β-VAE; `repr::neural`), on tiny networks (hidden [32, 16])
//! and ~200 rendered images, so the whole file runs in seconds on 2 cores.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use rand::RngExt;
use ugl_bench::env::{EnvConfig, EnvKind, make_env};
use ugl_bench::repr::dataset::generate;
use ugl_bench::repr::neural::{
    Model, NeuralConfig, NeuralEncoder, NeuralLearner, NeuralSection, Variant, init_net,
};
use ugl_bench::repr::rfvae::{flow_logdet_tensor, flow_step_host};
use ugl_bench::repr::{Encoder, ImageSet, Latents, ReprError, RepresentationLearner};
use ugl_bench::seed::{Component, stream, stream_named};

fn images(kind: EnvKind, n: usize) -> ImageSet {
    let env = make_env(kind, &EnvConfig::default());
    generate(env.as_ref(), n, &mut stream(11, Component::Dataset))
        .unwrap()
        .images
}

fn tiny(model: Model, variant: Variant, iterations: usize) -> NeuralConfig {
    NeuralConfig {
        iterations,
        hidden: [32, 16],
        batch: 100,
        lr: 1e-3,
        variant,
        log_every: 1,
        ..NeuralConfig::paper(model)
    }
}

/// `cfg` with the KL warm-up `w` where the model has one (the RFVAE's knob).
fn warmup(cfg: NeuralConfig, model: Model, w: usize) -> NeuralConfig {
    if model.spec().own_knobs().contains(&"warmup") {
        cfg.with_knob("warmup", w)
    } else {
        cfg
    }
}

fn learner(model: Model, cfg: NeuralConfig) -> Box<dyn RepresentationLearner> {
    Box::new(NeuralLearner::new(model, cfg))
}

fn fit_neural(
    model: Model,
    cfg: NeuralConfig,
    set: &ImageSet,
    latents: usize,
    seed: u64,
) -> (NeuralEncoder, Latents) {
    let mut rng = stream_named(seed, "learner");
    NeuralLearner::new(model, cfg)
        .fit_neural(set, latents, &mut rng)
        .unwrap_or_else(|e| panic!("{}: {e}", model.name()))
}

fn mean(v: &[(usize, f64)]) -> f64 {
    v.iter().map(|p| p.1).sum::<f64>() / v.len() as f64
}

#[test]
fn loss_decreases_for_every_model_and_variant() {
    let set = images(EnvKind::ARMBALL, 200);
    for model in Model::ALL {
        for variant in [Variant::Faithful, Variant::Corrected] {
            let cfg = NeuralConfig {
                lr: 5e-3,
                ..tiny(model, variant, 150)
            };
            let (enc, _) = fit_neural(model, cfg, &set, 2, 1);
            assert_eq!(enc.losses.len(), 150);
            let (first, last) = (mean(&enc.losses[..20]), mean(&enc.losses[130..]));
            eprintln!(
                "{} {}: mean loss of the first 20 iterations {first:.2}, last 20 {last:.2}",
                model.name(),
                variant.name()
            );
            assert!(
                last < first,
                "{} {}: loss did not decrease: {first} -> {last}",
                model.name(),
                variant.name()
            );
        }
    }
}

#[test]
fn encoders_have_the_right_shapes_and_priors() {
    let set = images(EnvKind::ARMARROW, 120);
    for model in Model::ALL {
        for variant in [Variant::Faithful, Variant::Corrected] {
            let l = learner(model, tiny(model, variant, 5));
            assert_eq!(l.name(), model.name());
            let (mut enc, z) = l.fit(&set, 3, &mut stream_named(2, "learner")).unwrap();
            assert_eq!((z.n, z.latents, z.data.len()), (120, 3, 360));
            assert!(z.data.iter().all(|v| v.is_finite()));
            assert_eq!(enc.latents(), 3);
            let again = enc.encode(&set).unwrap();
            assert_eq!((again.n, again.latents), (120, 3));
            assert!(again.data.iter().all(|v| v.is_finite()));
            let mut one = [0.0; 3];
            enc.encode_one(set.row(5), &mut one).unwrap();
            assert!(one.iter().all(|v| v.is_finite()));
            if model == Model::Ae {
                assert!(enc.prior().is_none());
                assert!(
                    z.data.iter().all(|&v| v > 0.0 && v < 1.0),
                    "AE latents are sigmoids"
                );
            } else {
                let p = enc.prior().expect("VAE-type models have a prior");
                assert_eq!((p.mean, p.std), (vec![0.0; 3], vec![1.0; 3]));
            }
        }
    }
}

#[test]
fn training_is_deterministic_for_a_stream() {
    let set = images(EnvKind::ARMBALL, 150);
    for model in Model::ALL {
        for variant in [Variant::Faithful, Variant::Corrected] {
            let cfg = tiny(model, variant, 12);
            let (mut a, za) = fit_neural(model, cfg.clone(), &set, 2, 3);
            let (mut b, zb) = fit_neural(model, cfg.clone(), &set, 2, 3);
            let bits = |z: &Latents| z.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&za),
                bits(&zb),
                "{} {}: training latents differ",
                model.name(),
                variant.name()
            );
            assert_eq!(
                a.net,
                b.net,
                "{} {}: weights differ",
                model.name(),
                variant.name()
            );
            assert_eq!(a.losses, b.losses);
            // Later encodings too (the faithful RFVAE's stochastic ones included).
            assert_eq!(
                bits(&a.encode(&set).unwrap()),
                bits(&b.encode(&set).unwrap())
            );
            // A different stream gives a different model.
            let (c, _) = fit_neural(model, cfg, &set, 2, 4);
            assert_ne!(a.net, c.net);
        }
    }
}

/// `log |det J|` of the host flow map at `z` by central differences.
fn fd_logdet(z: &[f64], c: &[f64], a: f64, b: f64) -> f64 {
    let d = z.len();
    let h = 1e-6;
    let mut jac = vec![vec![0.0; d]; d];
    for j in 0..d {
        let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
        zp[j] += h;
        zm[j] -= h;
        flow_step_host(&mut zp, c, a, b);
        flow_step_host(&mut zm, c, a, b);
        for i in 0..d {
            jac[i][j] = (zp[i] - zm[i]) / (2.0 * h);
        }
    }
    assert_eq!(d, 3);
    let det = jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1])
        - jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0])
        + jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]);
    det.abs().ln()
}

#[test]
fn radial_flow_logdet_matches_the_jacobian() {
    let d = 3;
    let n = 6;
    let mut rng = stream_named(5, "flow-points");
    let mut draw = |lo: f64, hi: f64, k: usize| {
        (0..k)
            .map(|_| rng.random_range(lo..hi))
            .collect::<Vec<f64>>()
    };
    let z = draw(-2.0, 2.0, n * d);
    let c = draw(-1.0, 1.0, n * d);
    let a = draw(-1.5, 1.5, n);
    let b = draw(-2.0, 2.0, n);
    let (zn, ld) = flow_logdet_tensor(&z, &c, &a, &b, d, Variant::Corrected);
    assert_eq!(ld.len(), n);
    for i in 0..n {
        let (zi, ci) = (&z[i * d..(i + 1) * d], &c[i * d..(i + 1) * d]);
        let fd = fd_logdet(zi, ci, a[i], b[i]);
        let mut host = zi.to_vec();
        let analytic = flow_step_host(&mut host, ci, a[i], b[i]);
        assert!(
            (analytic - fd).abs() < 1e-6,
            "point {i}: host log-det {analytic} vs finite differences {fd}"
        );
        assert!(
            (ld[i] - fd).abs() < 1e-4,
            "point {i}: tensor log-det {} vs finite differences {fd}",
            ld[i]
        );
        for j in 0..d {
            assert!(
                (zn[i * d + j] - host[j]).abs() < 1e-5,
                "point {i}: tensor flow output differs from the host's"
            );
        }
    }
    // The faithful broadcast: [i, j] = sample j's geometry with sample i's beta; the diagonal is
    // the true log-det.
    let (_, ldf) = flow_logdet_tensor(&z, &c, &a, &b, d, Variant::Faithful);
    assert_eq!(ldf.len(), n * n);
    let softplus = |x: f64| x.exp().ln_1p();
    for i in 0..n {
        assert!((ldf[i * n + i] - ld[i]).abs() < 1e-5, "diagonal {i}");
        let beta_i = softplus(b[i]) - a[i].abs();
        for j in 0..n {
            let (zj, cj) = (&z[j * d..(j + 1) * d], &c[j * d..(j + 1) * d]);
            let aj = a[j].abs();
            let beta_j = softplus(b[j]) - aj;
            let r = zj
                .iter()
                .zip(cj)
                .map(|(p, q)| (p - q) * (p - q))
                .sum::<f64>()
                .sqrt();
            let bh = beta_j / (aj + r);
            let t = (1.0 + bh).powi(d as i32 - 1) * (1.0 + bh - beta_i * r / ((aj + r) * (aj + r)));
            let expected = t.clamp(1e-4, 1e6).ln();
            assert!(
                (ldf[i * n + j] - expected).abs() < 1e-4,
                "[{i}, {j}]: {} vs {expected}",
                ldf[i * n + j]
            );
        }
    }
}

#[test]
fn variants_differ_exactly_where_documented() {
    let set = images(EnvKind::ARMBALL, 150);
    let d = 2;
    // Initial weights are a function of the stream only.
    for model in Model::ALL {
        let f = init_net(
            model,
            &tiny(model, Variant::Faithful, 1),
            set.dim,
            d,
            &mut stream_named(6, "learner"),
        );
        let c = init_net(
            model,
            &tiny(model, Variant::Corrected, 1),
            set.dim,
            d,
            &mut stream_named(6, "learner"),
        );
        assert_eq!(
            f,
            c,
            "{}: initial weights depend on the variant",
            model.name()
        );
    }
    // AE: no defect, the variants are identical.
    let (mut af, zf) = fit_neural(
        Model::Ae,
        tiny(Model::Ae, Variant::Faithful, 10),
        &set,
        d,
        6,
    );
    let (mut ac, zc) = fit_neural(
        Model::Ae,
        tiny(Model::Ae, Variant::Corrected, 10),
        &set,
        d,
        6,
    );
    assert_eq!(af.losses, ac.losses);
    assert_eq!(zf, zc);
    assert_eq!(af.encode(&set).unwrap(), ac.encode(&set).unwrap());
    // VAE: shared vs per-sample eps -> different losses from the first iteration; mu encoding
    // is deterministic in both.
    for model in [Model::Vae, Model::Rfvae] {
        let (mut f, _) = fit_neural(model, tiny(model, Variant::Faithful, 3), &set, d, 6);
        let (mut c, zc) = fit_neural(model, tiny(model, Variant::Corrected, 3), &set, d, 6);
        // (At the 0.001-std start the decoder barely sees z, so the very first f32 losses can
        // coincide; the curves and the weights cannot.)
        assert_ne!(
            f.losses,
            c.losses,
            "{}: the losses should differ",
            model.name()
        );
        assert_ne!(
            f.net,
            c.net,
            "{}: the trained weights should differ",
            model.name()
        );
        // Corrected encodings are deterministic and reproduce the training latents.
        assert_eq!(c.encode(&set).unwrap(), zc);
        assert_eq!(c.encode(&set).unwrap(), zc);
        let mut one = vec![0.0; d];
        let mut two = vec![0.0; d];
        f.encode_one(set.row(3), &mut one).unwrap();
        f.encode_one(set.row(3), &mut two).unwrap();
        match model {
            Model::Vae => assert_eq!(one, two, "the VAE encoding (mu) is deterministic"),
            _ => assert_ne!(one, two, "the faithful RFVAE encoding is stochastic"),
        }
        c.encode_one(set.row(3), &mut one).unwrap();
        c.encode_one(set.row(3), &mut two).unwrap();
        assert_eq!(
            one,
            two,
            "{} corrected encoding is deterministic",
            model.name()
        );
    }
    // RFVAE faithful: training latents (z0 samples) are not the encodings (z_K of fresh samples).
    let (mut f, zf) = fit_neural(
        Model::Rfvae,
        tiny(Model::Rfvae, Variant::Faithful, 3),
        &set,
        d,
        6,
    );
    assert!(f.is_stochastic());
    assert_ne!(f.encode(&set).unwrap(), zf);
}

#[test]
fn invalid_configurations_are_rejected() {
    let set = images(EnvKind::ARMBALL, 30);
    let base = tiny(Model::Vae, Variant::Faithful, 2);
    let cases: Vec<(&str, NeuralConfig)> = vec![
        (
            "batch",
            NeuralConfig {
                batch: 0,
                ..base.clone()
            },
        ),
        (
            "hidden",
            NeuralConfig {
                hidden: [0, 4],
                ..base.clone()
            },
        ),
        (
            "hidden",
            NeuralConfig {
                hidden: [4, 0],
                ..base.clone()
            },
        ),
        (
            "lr",
            NeuralConfig {
                lr: 0.0,
                ..base.clone()
            },
        ),
        (
            "lr",
            NeuralConfig {
                lr: f64::NAN,
                ..base.clone()
            },
        ),
        (
            "lr",
            NeuralConfig {
                lr: f64::INFINITY,
                ..base.clone()
            },
        ),
        (
            "log_every",
            NeuralConfig {
                log_every: 0,
                ..base.clone()
            },
        ),
    ];
    for model in Model::ALL {
        for (key, cfg) in &cases {
            match learner(model, cfg.clone()).fit(&set, 2, &mut stream_named(1, "learner")) {
                Err(ReprError::InvalidInput(msg)) => assert!(
                    msg.contains(key),
                    "{}: '{msg}' should name {key}",
                    model.name()
                ),
                Err(e) => panic!("{}: {key}: wrong error {e}", model.name()),
                Ok(_) => panic!("{}: {key}: accepted", model.name()),
            }
        }
        let l = learner(model, base.clone());
        assert!(matches!(
            l.fit(&set, 0, &mut stream_named(1, "learner")),
            Err(ReprError::InvalidInput(_))
        ));
        assert!(matches!(
            l.fit(&set, 30, &mut stream_named(1, "learner")),
            Err(ReprError::InvalidInput(_))
        ));
    }
}

#[test]
fn divergence_is_reported() {
    let set = images(EnvKind::ARMBALL, 50);
    let cfg = NeuralConfig {
        lr: 1e30,
        ..tiny(Model::Vae, Variant::Corrected, 50)
    };
    match NeuralLearner::new(Model::Vae, cfg).fit(&set, 2, &mut stream_named(1, "learner")) {
        Err(ReprError::Numerical(msg)) => assert!(
            msg.starts_with("vae training diverged at iteration"),
            "{msg}"
        ),
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("a learning rate of 1e30 should diverge"),
    }
}

#[test]
fn progress_is_reported_every_iteration() {
    let set = images(EnvKind::ARMBALL, 50);
    let calls = Arc::new(AtomicUsize::new(0));
    let seen = calls.clone();
    let l = NeuralLearner::new(
        Model::Ae,
        NeuralConfig {
            log_every: 4,
            ..tiny(Model::Ae, Variant::Faithful, 10)
        },
    )
    .with_progress(Arc::new(move |p| {
        assert_eq!(p.total, 10);
        assert!(p.loss.is_finite());
        assert_eq!(seen.fetch_add(1, Ordering::SeqCst) + 1, p.iteration);
    }));
    let (enc, _) = l
        .fit_neural(&set, 2, &mut stream_named(1, "learner"))
        .unwrap();
    assert_eq!(calls.load(Ordering::SeqCst), 10);
    let steps: Vec<usize> = enc.losses.iter().map(|p| p.0).collect();
    assert_eq!(steps, vec![0, 4, 8, 9]);
}

#[test]
fn configuration_serde() {
    for model in Model::ALL {
        let p = NeuralConfig::paper(model);
        assert_eq!(p.hidden, [1200, 1200]);
        assert_eq!((p.batch, p.lr, p.variant), (100, 1e-3, Variant::Faithful));
        let text = toml::to_string(&p).unwrap();
        assert_eq!(toml::from_str::<NeuralConfig>(&text).unwrap(), p);
        assert_eq!(
            NeuralSection::default().resolve(model, Variant::Faithful),
            p
        );
    }
    assert_eq!(NeuralConfig::paper(Model::Ae).iterations, 200_000);
    assert_eq!(NeuralConfig::paper(Model::Vae).iterations, 100_000);
    assert_eq!(NeuralConfig::paper(Model::Rfvae).iterations, 50_000);
    let s: NeuralSection = toml::from_str("iterations = 500\nhidden = [512, 256]").unwrap();
    let c = s.resolve(Model::Rfvae, Variant::Corrected);
    assert_eq!(
        (c.iterations, c.variant, c.hidden, c.batch),
        (500, Variant::Corrected, [512, 256], 100)
    );
    // Keys beyond the shared ones are the model's own knobs: the check refuses the others.
    let check = |t: &str| {
        use ugl_bench::repr::params::ParamGuard;
        (Model::Vae, toml::from_str::<NeuralSection>(t).unwrap()).check()
    };
    assert!(check("iteration = 5").is_err(), "unknown keys are rejected");
    assert!(
        check("variant = \"corrected\"").is_err(),
        "the variant is a matrix dimension, not a learner setting"
    );
    assert!(check("iterations = 5").is_ok());
    assert!(
        toml::from_str::<NeuralConfig>("iterations = 5").is_err(),
        "the complete form needs every key"
    );
}

/// The repository's plug-in conformance checks (`learner_conformance.rs`) on the three neural
/// learners with tiny configurations. The faithful RFVAE is stochastic by design: its encodings
/// are neither reproducible nor equal to its training latents (z0 samples), so it only gets the
/// shape, determinism-of-fit and bad-input checks.
#[test]
fn neural_learners_conform() {
    for (kind, latents) in [(EnvKind::ARMBALL, 2), (EnvKind::ARMARROW, 10)] {
        let set = images(kind, 150);
        for model in Model::ALL {
            for variant in [Variant::Faithful, Variant::Corrected] {
                let l = learner(model, tiny(model, variant, 8));
                let who = format!(
                    "{} {} on {kind} with {latents} latents",
                    model.name(),
                    variant.name()
                );
                let (mut enc, z) = l
                    .fit(&set, latents, &mut stream_named(1, "learner"))
                    .unwrap_or_else(|e| panic!("{who}: {e}"));
                assert_eq!(
                    (z.n, z.latents, z.data.len()),
                    (150, latents, 150 * latents),
                    "{who}: shape"
                );
                assert!(z.data.iter().all(|v| v.is_finite()), "{who}: finite");
                assert_eq!(enc.latents(), latents, "{who}");
                let (_, z2) = l
                    .fit(&set, latents, &mut stream_named(1, "learner"))
                    .unwrap();
                assert_eq!(
                    z.data, z2.data,
                    "{who}: two fits with the same stream differ"
                );
                let stochastic = model == Model::Rfvae && variant == Variant::Faithful;
                if !stochastic {
                    let again = enc.encode(&set).unwrap();
                    assert_eq!(again.data, z.data, "{who}: batch re-encoding differs");
                    let mut one = vec![0.0; latents];
                    for i in [0, 17, 149] {
                        enc.encode_one(set.row(i), &mut one).unwrap();
                        assert_eq!(one.as_slice(), z.row(i), "{who}: encode_one of image {i}");
                    }
                }
                let mut one = vec![0.0; latents];
                assert!(
                    l.fit(&set, 0, &mut stream_named(1, "learner")).is_err(),
                    "{who}: latents = 0"
                );
                assert!(
                    enc.encode_one(&[0.0; 10], &mut one).is_err(),
                    "{who}: wrong image size"
                );
                assert!(
                    enc.encode_one(set.row(0), &mut one[..1]).is_err() || latents == 1,
                    "{who}: wrong output size"
                );
                let bad = ImageSet::new(1, 10, vec![0.0; 10]).unwrap();
                assert!(enc.encode(&bad).is_err(), "{who}: wrong image size (batch)");
            }
        }
    }
}

/// The host engine's loss and gradients equal burn autodiff's on the same weights, batch and
/// noise, for every model and variant (the RFVAE inside its warm-up), to float precision: a
/// wrong term, scale or transpose in the hand-written backward fails it.
#[test]
fn host_engine_gradients_match_burn_autodiff() {
    use burn::module::ParamId;
    use burn::optim::GradientsParams;
    use ugl_bench::repr::host_train::{HostOptimizer, HostTrainer};
    use ugl_bench::repr::neural::{Init, LatentInput, StepInput, tensor2, training_device};
    let set = images(EnvKind::ARMBALL, 60);
    let (rows, d, step) = (40, 3, 3);
    let x: Vec<f32> = (0..rows).flat_map(|i| set.row(i).to_vec()).collect();
    for model in Model::ALL {
        for variant in [Variant::Faithful, Variant::Corrected] {
            let cfg = warmup(
                NeuralConfig {
                    init: Init::He,
                    ..tiny(model, variant, 5)
                },
                model,
                10,
            );
            let net = init_net(model, &cfg, set.dim, d, &mut stream_named(4, "grad"));
            let mut host = HostTrainer::new(net.clone(), HostOptimizer::new(model, &net));
            let host_loss = host
                .forward_backward(model, &cfg, &x, rows, step, &mut stream_named(5, "noise"))
                .unwrap();
            let host_grads = host.gradients();

            let device = training_device();
            let module = net.to_module(&device);
            let input = StepInput {
                x: tensor2(x.clone(), rows, set.dim, &device),
                latent: LatentInput {
                    batch: rows,
                    latents: d,
                    step,
                    code: cfg.code_at(model, step),
                    device: &device,
                },
            };
            let mut rng = stream_named(5, "noise");
            let loss = model.spec().loss(&module, input, &mut rng);
            let burn_loss = f64::from(loss.clone().into_scalar::<f32>());
            let grads = GradientsParams::from_grads(loss.backward(), &module);
            let what = format!("{} {}", model.name(), variant.name());
            assert!(
                (host_loss - burn_loss).abs() <= 1e-5 * burn_loss.abs().max(1.0),
                "{what}: loss {host_loss} vs {burn_loss}"
            );
            for (k, id) in module.param_ids().iter().enumerate() {
                let id = ParamId::from(*id);
                let data = if k % 2 == 0 {
                    grads.get::<2>(id).unwrap().into_data()
                } else {
                    grads.get::<1>(id).unwrap().into_data()
                };
                let want = data.try_into_vec::<f32>().unwrap();
                let got = &host_grads[k];
                assert_eq!(got.len(), want.len(), "{what}: parameter {k}");
                let scale = want.iter().fold(0f32, |m, v| m.max(v.abs()));
                let err = got
                    .iter()
                    .zip(&want)
                    .fold(0f32, |m, (a, b)| m.max((a - b).abs()));
                assert!(
                    scale > 0.0 && err <= 1e-3 * scale,
                    "{what}: parameter {k}: max error {err} for gradients up to {scale}"
                );
            }
        }
    }
}

/// The host engine's trained weights are bit-identical with 1 and 2 threads, at a size where
/// `gemm` and the sparse layer do run in parallel.
#[test]
fn host_engine_is_bit_identical_across_thread_counts() {
    use ugl_bench::repr::neural::{Engine, Init, train};
    let set = images(EnvKind::ARMBALL, 150);
    for model in Model::ALL {
        let cfg = warmup(
            NeuralConfig {
                hidden: [256, 128],
                init: Init::He,
                engine: Engine::Host,
                ..tiny(model, Variant::Corrected, 6)
            },
            model,
            4,
        );
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| train(model, &cfg, &set, 4, &mut stream_named(3, "threads"), None))
                .unwrap()
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one.net, two.net, "{model:?}");
        assert_eq!(one.losses, two.losses, "{model:?}");
    }
}

/// Prints a fingerprint of trained weights and latents per model, to compare runs under
/// different thread counts by hand (`RAYON_NUM_THREADS=1` vs `2`; `-- --ignored --nocapture`).
/// `UGL_FINGERPRINT_ARCH=H1,H2,iterations` sets the size (default `64,48,20`). It asserts
/// nothing: [`host_engine_is_bit_identical_across_thread_counts`] checks the property.
#[test]
#[ignore = "a diagnostic that prints fingerprints to compare by hand; the property is asserted by host_engine_is_bit_identical_across_thread_counts"]
fn fingerprint_for_thread_count_comparison() {
    let set = images(EnvKind::ARMBALL, 150);
    let arch: Vec<usize> = std::env::var("UGL_FINGERPRINT_ARCH")
        .unwrap_or_else(|_| "64,48,20".into())
        .split(',')
        .map(|v| {
            v.trim()
                .parse()
                .expect("UGL_FINGERPRINT_ARCH=H1,H2,iterations")
        })
        .collect();
    for model in Model::ALL {
        for variant in [Variant::Faithful, Variant::Corrected] {
            let cfg = NeuralConfig {
                hidden: [arch[0], arch[1]],
                ..tiny(model, variant, arch[2])
            };
            let (enc, z) = fit_neural(model, cfg, &set, 3, 9);
            let mut h = blake3::Hasher::new();
            for l in [
                &enc.net.enc1,
                &enc.net.enc2,
                &enc.net.head,
                &enc.net.dec1,
                &enc.net.dec2,
                &enc.net.dec_out,
            ] {
                l.w.iter().chain(&l.b).for_each(|v| {
                    h.update(&v.to_le_bytes());
                });
            }
            z.data.iter().for_each(|v| {
                h.update(&v.to_le_bytes());
            });
            eprintln!(
                "fingerprint {} {}: {}",
                model.name(),
                variant.name(),
                h.finalize().to_hex()
            );
        }
    }
}

/// A training killed after its second checkpoint (a panic in the progress callback stands for
/// the `kill -9`: nothing after it runs) resumes from that checkpoint and ends bit-identical to
/// an uninterrupted training: weights, loss curve and encoder seed.
#[test]
fn a_killed_training_resumes_from_its_checkpoint_to_the_same_bits() {
    use ugl_bench::repr::neural::{CheckpointSpec, Engine, train, train_with_checkpoints};
    let set = images(EnvKind::ARMBALL, 120);
    for (model, engine) in Model::ALL
        .into_iter()
        .flat_map(|m| Engine::ALL.map(|e| (m, e)))
    {
        let cfg = warmup(
            NeuralConfig {
                log_every: 5,
                engine,
                ..tiny(model, Variant::Faithful, 60)
            },
            model,
            10,
        );
        let learner_stream = || stream_named(9, "checkpoint-learner");
        let reference = train(model, &cfg, &set, 3, &mut learner_stream(), None).unwrap();

        let dir = tempfile::tempdir().unwrap();
        let spec = CheckpointSpec {
            dir: dir.path().to_path_buf(),
            key: format!("test-{}", model.name()),
            every: 20,
            keep: false,
        };
        let killer: ugl_bench::repr::neural::ProgressFn = Arc::new(|p| {
            if p.iteration == 47 {
                panic!("killed at iteration 47");
            }
        });
        let killed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            train_with_checkpoints(
                model,
                &cfg,
                &set,
                3,
                &mut learner_stream(),
                Some(&killer),
                Some(&spec),
            )
        }));
        assert!(killed.is_err(), "the training was interrupted");
        let left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        assert_eq!(
            left,
            [format!("test-{}.ckpt.40", model.name())],
            "only the latest"
        );

        // Resume: counts iterations from 41.
        let seen = Arc::new(AtomicUsize::new(usize::MAX));
        let first = seen.clone();
        let watch: ugl_bench::repr::neural::ProgressFn = Arc::new(move |p| {
            first.fetch_min(p.iteration, Ordering::SeqCst);
        });
        let resumed = train_with_checkpoints(
            model,
            &cfg,
            &set,
            3,
            &mut learner_stream(),
            Some(&watch),
            Some(&spec),
        )
        .unwrap();
        assert_eq!(
            seen.load(Ordering::SeqCst),
            41,
            "{model:?} resumed after iteration 40"
        );
        assert_eq!(resumed.net, reference.net, "{model:?}: weights differ");
        assert_eq!(
            resumed.losses, reference.losses,
            "{model:?}: loss curve differs"
        );
        assert_eq!(resumed.encode_seed, reference.encode_seed);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "checkpoints removed"
        );

        // A damaged checkpoint is ignored: training starts over, same result.
        let killed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            train_with_checkpoints(
                model,
                &cfg,
                &set,
                3,
                &mut learner_stream(),
                Some(&killer),
                Some(&spec),
            )
        }));
        assert!(killed.is_err());
        let ckpt = dir.path().join(format!("test-{}.ckpt.40", model.name()));
        let optim = ckpt.join(match engine {
            Engine::Burn => "optim.bpk",
            Engine::Host => "optim.bin",
        });
        let mut bytes = std::fs::read(&optim).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(&optim, bytes).unwrap();
        let again = train_with_checkpoints(
            model,
            &cfg,
            &set,
            3,
            &mut learner_stream(),
            None,
            Some(&spec),
        )
        .unwrap();
        assert_eq!(again.net, reference.net);
    }
}

/// A checkpoint whose `state.json` was changed (one value of the batch permutation, the
/// iteration count, the stream's position or the loss curve; an entry out of range; the digest
/// gone; the file cut short) is ignored with a warning: the training starts over, or resumes
/// from an older valid checkpoint, and ends bit-identical to an uninterrupted one. Before the
/// state was sealed, a swapped pair in `perm` resumed silently into another network, and an
/// out-of-range entry panicked on every rerun.
#[test]
fn a_damaged_or_inconsistent_checkpoint_state_is_ignored() {
    use serde_json::Value;
    use ugl_bench::repr::neural::{CheckpointSpec, Engine, train, train_with_checkpoints};
    let model = Model::Vae;
    let set = images(EnvKind::ARMBALL, 120);
    let cfg = NeuralConfig {
        log_every: 5,
        engine: Engine::Host,
        ..tiny(model, Variant::Faithful, 60)
    };
    let learner_stream = || stream_named(9, "checkpoint-state");
    let reference = train(model, &cfg, &set, 3, &mut learner_stream(), None).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let spec = CheckpointSpec {
        dir: dir.path().to_path_buf(),
        key: "state-test".into(),
        every: 20,
        keep: false,
    };
    let ckpt = |step: usize| dir.path().join(format!("state-test.ckpt.{step}"));
    // Train, killed after iteration `at`; returns the first iteration it ran (1-based).
    let train_until = |at: Option<usize>| {
        let first = Arc::new(AtomicUsize::new(usize::MAX));
        let seen = first.clone();
        let watch: ugl_bench::repr::neural::ProgressFn = Arc::new(move |p| {
            seen.fetch_min(p.iteration, Ordering::SeqCst);
            if Some(p.iteration) == at {
                panic!("killed at iteration {}", p.iteration);
            }
        });
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            train_with_checkpoints(
                model,
                &cfg,
                &set,
                3,
                &mut learner_stream(),
                Some(&watch),
                Some(&spec),
            )
        }));
        (r, first.load(Ordering::SeqCst))
    };
    let copy = |from: &std::path::Path, to: &std::path::Path| {
        let _ = std::fs::remove_dir_all(to);
        std::fs::create_dir_all(to).unwrap();
        for e in std::fs::read_dir(from).unwrap() {
            let e = e.unwrap();
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    };
    let saved = tempfile::tempdir().unwrap();
    let (saved20, saved40) = (saved.path().join("20"), saved.path().join("40"));
    assert!(train_until(Some(27)).0.is_err());
    copy(&ckpt(20), &saved20);
    assert!(train_until(Some(47)).0.is_err());
    assert!(!ckpt(20).exists(), "the older checkpoint was replaced");
    copy(&ckpt(40), &saved40);

    // The object holding the state's fields (the whole file, or its `state`).
    fn fields(v: &mut Value) -> &mut serde_json::Map<String, Value> {
        if v.get("perm").is_some() {
            v.as_object_mut().unwrap()
        } else {
            v["state"].as_object_mut().unwrap()
        }
    }
    let edit = |change: fn(&mut Value)| {
        move |path: &std::path::Path| {
            let mut v: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
            change(&mut v);
            std::fs::write(path, serde_json::to_vec(&v).unwrap()).unwrap();
        }
    };
    let damages: Vec<(&str, Box<dyn Fn(&std::path::Path)>)> = vec![
        (
            "two entries of perm swapped",
            Box::new(edit(|v| {
                fields(v)["perm"].as_array_mut().unwrap().swap(0, 1)
            })),
        ),
        (
            "an entry of perm out of range",
            Box::new(edit(|v| fields(v)["perm"][0] = 5000.into())),
        ),
        ("step", Box::new(edit(|v| fields(v)["step"] = 39.into()))),
        (
            "rng_word_pos",
            Box::new(edit(|v| {
                let f = fields(v);
                let pos: u128 = f["rng_word_pos"].as_str().unwrap().parse().unwrap();
                f["rng_word_pos"] = (pos + 1).to_string().into();
            })),
        ),
        (
            "a loss",
            Box::new(edit(|v| fields(v)["losses"][0][1] = 0.5.into())),
        ),
        (
            "the digest removed",
            Box::new(edit(|v| {
                if let Some(s) = v.get("state").cloned() {
                    *v = s;
                }
            })),
        ),
        (
            "cut short",
            Box::new(|p: &std::path::Path| {
                let b = std::fs::read(p).unwrap();
                std::fs::write(p, &b[..b.len() / 2]).unwrap();
            }),
        ),
    ];
    for (what, damage) in &damages {
        for older in [false, true] {
            for s in [20, 40] {
                let _ = std::fs::remove_dir_all(ckpt(s));
            }
            copy(&saved40, &ckpt(40));
            if older {
                copy(&saved20, &ckpt(20));
            }
            damage(&ckpt(40).join("state.json"));
            let (r, first) = train_until(None);
            let enc = r
                .unwrap_or_else(|_| panic!("{what}: the training panicked"))
                .unwrap();
            assert_eq!(
                first,
                if older { 21 } else { 1 },
                "{what}: resumed from the right place (older: {older})"
            );
            assert_eq!(enc.net, reference.net, "{what}: weights differ");
            assert_eq!(enc.losses, reference.losses, "{what}: loss curve differs");
            assert_eq!(enc.encode_seed, reference.encode_seed, "{what}");
        }
    }
}

/// The β-VAE (`bvae.rs`) with β = 1 is the corrected VAE, bit for bit, on both engines: same
/// loss curve, same encodings. β = 4 weighs the KL more: another training.
#[test]
fn a_beta_vae_with_beta_one_is_the_corrected_vae() {
    use ugl_bench::repr::neural::Engine;
    let set = images(EnvKind::ARMBALL, 150);
    for engine in [Engine::Host, Engine::Burn] {
        let vae = NeuralConfig {
            engine,
            ..tiny(Model::Vae, Variant::Corrected, 25)
        };
        let beta = |b: f64| {
            NeuralConfig {
                engine,
                ..tiny(Model::Bvae, Variant::Faithful, 25)
            }
            .with_knob("beta", b)
        };
        let (v, zv) = fit_neural(Model::Vae, vae, &set, 3, 4);
        let (b1, zb1) = fit_neural(Model::Bvae, beta(1.0), &set, 3, 4);
        assert_eq!(v.losses, b1.losses, "{engine:?}: loss curves");
        assert_eq!(zv.data, zb1.data, "{engine:?}: encodings");
        let (b4, zb4) = fit_neural(Model::Bvae, beta(4.0), &set, 3, 4);
        assert_ne!(zb4.data, zv.data, "{engine:?}");
        assert_ne!(b4.losses, v.losses, "{engine:?}");
    }
}

#[test]
fn capacity_annealing_is_the_beta_kl_against_a_rising_target() {
    use ugl_bench::repr::neural::Engine;
    let set = images(EnvKind::ARMBALL, 150);
    let cfg = |capacity: Option<f64>| {
        let c = NeuralConfig {
            engine: Engine::Host,
            ..tiny(Model::Bvae, Variant::Faithful, 25)
        }
        .with_knob("beta", 4.0);
        match capacity {
            Some(capacity) => c.with_knob("capacity", capacity),
            None => c,
        }
    };
    // C rises linearly to `capacity` over the training.
    let c = cfg(Some(20.0));
    let bvae = Model::Bvae;
    assert_eq!(c.capacity_at(bvae, 0), Some(0.0));
    assert_eq!(c.capacity_at(bvae, c.iterations / 5), Some(4.0));
    assert_eq!(c.capacity_at(bvae, c.iterations * 2), Some(20.0));
    assert_eq!(cfg(None).capacity_at(bvae, 3), None);
    // A target of 0 nats is the plain objective (β |KL - 0| = β KL: the same loss up to the
    // order of the sums); a rising target trains another network.
    let (plain, zp) = fit_neural(Model::Bvae, cfg(None), &set, 3, 4);
    let (zero, _) = fit_neural(Model::Bvae, cfg(Some(0.0)), &set, 3, 4);
    for ((i, a), (j, b)) in plain.losses.iter().zip(&zero.losses) {
        assert_eq!(i, j);
        assert!((a - b).abs() <= 1e-3 * a.abs(), "iteration {i}: {a} vs {b}");
    }
    let (_, z50) = fit_neural(Model::Bvae, cfg(Some(50.0)), &set, 3, 4);
    assert_ne!(zp.data, z50.data);
}

/// `iterations = 0` is the untrained twin: the initial weights of the same stream (the weights
/// a trained network starts from), no loss curve, and flagged as untrained by the evidence.
#[test]
fn zero_iterations_keep_the_initial_weights_and_are_flagged_untrained() {
    let set = images(EnvKind::ARMBALL, 200);
    for model in [Model::Ae, Model::Vae, Model::Rfvae] {
        let cfg = tiny(model, Variant::Corrected, 0);
        let mut twin = ugl_bench::repr::neural::train(
            model,
            &cfg,
            &set,
            2,
            &mut stream_named(5, "twin"),
            None,
        )
        .unwrap();
        let init = init_net(model, &cfg, set.dim, 2, &mut stream_named(5, "twin"));
        assert_eq!(twin.net, init, "{}", model.name());
        assert!(twin.losses.is_empty());
        let record = twin.training_outcome(&set).unwrap();
        assert!(
            !record.evidence.trained,
            "{}: {:?}",
            model.name(),
            record.evidence
        );
        let trained = ugl_bench::repr::neural::train(
            model,
            &tiny(model, Variant::Corrected, 30),
            &set,
            2,
            &mut stream_named(5, "twin"),
            None,
        )
        .unwrap();
        assert_ne!(trained.net, init);
        assert_ne!(twin.encode(&set).unwrap(), {
            let mut t = trained;
            t.encode(&set).unwrap()
        });
    }
}

/// The plateau rule: a network stopped on the mean-image plateau trains on, in chunks, until it
/// leaves it (or the cap); one that left it stops where it was told; the extension is recorded
/// in the loss curve and the training record, and a training killed in an extension resumes
/// from its checkpoint to the same bits.
#[test]
fn the_plateau_rule_trains_on_until_the_network_leaves_the_plateau() {
    use ugl_bench::repr::evidence::{EVIDENCE_IMAGES, UNTRAINED_FRACTION, mean_image_loss};
    use ugl_bench::repr::neural::{
        CheckpointSpec, Init, PlateauRule, reconstruction_loss, train, train_with_checkpoints,
    };
    let set = images(EnvKind::ARMBALL, 200);
    let model = Model::Vae;
    let head = set.head(EVIDENCE_IMAGES);
    let plateau = mean_image_loss(&head);
    let fraction = |enc: &ugl_bench::repr::neural::NeuralEncoder| {
        reconstruction_loss(model, &enc.net, &head, head.n) / plateau
    };
    let stream = || stream_named(4, "plateau-learner");
    // 3 iterations leave a small VAE on the plateau (He init, so that it can leave it soon).
    let short = NeuralConfig {
        init: Init::He,
        hidden: [128, 64],
        ..tiny(model, Variant::Corrected, 3)
    };
    let stuck = train(model, &short, &set, 2, &mut stream(), None).unwrap();
    assert!(
        fraction(&stuck) >= UNTRAINED_FRACTION,
        "{}",
        fraction(&stuck)
    );
    let rule = PlateauRule {
        chunk: 40,
        cap: 1200,
    };
    let cfg = NeuralConfig {
        plateau: Some(rule),
        log_every: 10,
        ..short
    };
    let trained = train(model, &cfg, &set, 2, &mut stream(), None).unwrap();
    let done = trained.losses.last().unwrap().0 + 1;
    assert!(
        fraction(&trained) < UNTRAINED_FRACTION,
        "{}",
        fraction(&trained)
    );
    assert!(
        done > 3 && done <= 1200 && (done - 3).is_multiple_of(40),
        "{done}"
    );
    // It stopped at the first boundary off the plateau: one chunk fewer stays on it.
    let fewer = NeuralConfig {
        iterations: done - 40,
        plateau: None,
        ..cfg.clone()
    };
    let before = train(model, &fewer, &set, 2, &mut stream(), None).unwrap();
    assert!(fraction(&before) >= UNTRAINED_FRACTION);
    assert_eq!(before.net, {
        // The same first `done - 40` iterations: the rule changes nothing before it acts.
        let capped = NeuralConfig {
            plateau: Some(PlateauRule {
                chunk: 40,
                cap: done - 40,
            }),
            ..cfg.clone()
        };
        train(model, &capped, &set, 2, &mut stream(), None)
            .unwrap()
            .net
    });
    // A network that left the plateau within its iterations is not trained on.
    let long = NeuralConfig {
        iterations: done,
        ..cfg.clone()
    };
    let at_once = train(model, &long, &set, 2, &mut stream(), None).unwrap();
    assert_eq!(at_once.losses.last().unwrap().0 + 1, done);
    assert_eq!(at_once.net, trained.net);

    // Killed inside an extension, resumed from the checkpoint: the same bits.
    let dir = tempfile::tempdir().unwrap();
    let spec = CheckpointSpec {
        dir: dir.path().to_path_buf(),
        key: "plateau".into(),
        every: 10,
        keep: false,
    };
    let kill_at = done - 5;
    let killer: ugl_bench::repr::neural::ProgressFn = Arc::new(move |p| {
        if p.iteration == kill_at {
            panic!("killed");
        }
    });
    let killed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        train_with_checkpoints(
            model,
            &cfg,
            &set,
            2,
            &mut stream(),
            Some(&killer),
            Some(&spec),
        )
    }));
    assert!(killed.is_err());
    let resumed =
        train_with_checkpoints(model, &cfg, &set, 2, &mut stream(), None, Some(&spec)).unwrap();
    assert_eq!(resumed.net, trained.net);
    assert_eq!(resumed.losses, trained.losses);
    assert_eq!(resumed.encode_seed, trained.encode_seed);
}
