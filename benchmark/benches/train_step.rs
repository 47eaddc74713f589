//! One training iteration (batch 100: batch draw, forward, backward, optimiser step) of each of
//! the paper's networks (docs/original-code.md section 5), at the paper's architecture
//! (4900-1200-1200, d = 10) and a reduced one (4900-512-256, d = 10), on burn's flex CPU
//! backend and on the host engine (`repr/host_train.rs`); plus `encode_one` of a trained-shape
//! encoder.
//! Throughput is reported as FLOP/s ("elem/s"), counting `3 x 2 m n k` per dense layer.
//! Run: `cargo bench -p ugl-bench --profile dev --bench train_step`
//! (threads: `RAYON_NUM_THREADS=1` for a single-thread run).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::RngExt;
use ugl_bench::env::render::{PIXELS, render_ball_into};
use ugl_bench::repr::neural::{
    Engine, Model, NeuralConfig, NeuralEncoder, Trainer, Variant, flops_per_iteration, init_net,
};
use ugl_bench::repr::{Encoder, ImageSet};
use ugl_bench::seed::stream_named;

fn balls(n: usize, seed: u64) -> ImageSet {
    let mut rng = stream_named(seed, "bench-balls");
    let mut data = vec![0.0f32; n * PIXELS];
    for i in 0..n {
        let (x, y) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        render_ball_into(x, y, &mut data[i * PIXELS..(i + 1) * PIXELS]);
    }
    ImageSet::new(n, PIXELS, data).unwrap()
}

fn bench(c: &mut Criterion) {
    let train = balls(1000, 1);
    let latents = 10;
    for (arch, hidden) in [
        ("paper-1200-1200", [1200, 1200]),
        ("reduced-512-256", [512, 256]),
    ] {
        let mut g = c.benchmark_group(format!("train_step/{arch}"));
        g.sample_size(10);
        g.warm_up_time(Duration::from_secs(2));
        g.measurement_time(Duration::from_secs(8));
        for (model, engine) in Model::ALL
            .into_iter()
            .flat_map(|m| Engine::ALL.map(|e| (m, e)))
        {
            let cfg = NeuralConfig {
                hidden,
                engine,
                ..NeuralConfig::paper(model)
            };
            let mut rng = stream_named(1, "learner");
            let mut trainer = Trainer::new(model, &cfg, &train, latents, &mut rng).unwrap();
            g.throughput(Throughput::Elements(flops_per_iteration(
                model, PIXELS, hidden, latents, 100,
            ) as u64));
            g.bench_function(format!("{}/{}", model.name(), engine.name()), |b| {
                b.iter(|| black_box(trainer.step(&mut rng).unwrap()))
            });
        }
        g.finish();

        // encode_one on an untrained network of this shape (the cost does not depend on the
        // weights' values, only on the image's and the hidden layers' zeros).
        let mut g = c.benchmark_group(format!("encode_one/{arch}"));
        let probe = balls(64, 2);
        for (model, variant) in [
            (Model::Ae, Variant::Faithful),
            (Model::Rfvae, Variant::Corrected),
        ] {
            let cfg = NeuralConfig {
                hidden,
                ..NeuralConfig::paper(model)
            };
            let net = init_net(
                model,
                &cfg,
                PIXELS,
                latents,
                &mut stream_named(1, "learner"),
            );
            let mut enc = NeuralEncoder::new(model, variant, net, vec![], [0; 32]);
            let mut out = vec![0.0f64; latents];
            let mut i = 0;
            g.bench_function(model.name(), |b| {
                b.iter(|| {
                    i = (i + 1) % probe.n;
                    enc.encode_one(black_box(probe.row(i)), &mut out).unwrap();
                    out[0]
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
