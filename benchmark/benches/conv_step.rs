//! One training iteration of the follow-up's convolutional β-VAE (`repr/conv_train.rs`): batch
//! 64 of 64x64 RGB pictures of the follow-up's ArmBalls, forward, the capacity-annealed loss,
//! backward and the Adam step. `scripts/conv_side_by_side.sh step` times it against PyTorch's
//! same iteration (`scripts/torch_conv_vae_step.py`).
//! Run: `cargo bench -p ugl-bench --profile dev --bench conv_step`
//! (threads: `RAYON_NUM_THREADS=1` for a single-thread run).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::RngExt;
use ugl_bench::env::cdge::{VALUES, normalise, render_rgb};
use ugl_bench::repr::conv_net::{ConvArch, ConvInit, ConvNet};
use ugl_bench::repr::conv_train::{ConvConfig, ConvTrainer};
use ugl_bench::seed::stream_named;

const BATCH: usize = 64;

/// `n` pictures of the ball and the distractor at random places, channel-major (`NCHW`).
fn pictures(n: usize) -> Vec<f32> {
    let mut rng = stream_named(1, "bench-pictures");
    let (mut raw, mut hwc) = (vec![0u8; VALUES], vec![0.0f32; VALUES]);
    let mut out = vec![0.0f32; n * VALUES];
    let pixels = VALUES / 3;
    for img in out.chunks_exact_mut(VALUES) {
        let mut at = || [rng.random_range(-0.9..0.9), rng.random_range(-0.9..0.9)];
        render_rgb(at(), at(), 0.17, 0.15, &mut raw);
        normalise(&raw, &mut hwc);
        for p in 0..pixels {
            for c in 0..3 {
                img[c * pixels + p] = hwc[p * 3 + c];
            }
        }
    }
    out
}

fn bench(c: &mut Criterion) {
    let x = pictures(BATCH);
    let cfg = ConvConfig {
        iterations: 100_000,
        warmup: 10_000,
        beta: 4.0,
        capacity: Some(12.0),
        batch: BATCH,
        ..ConvConfig::followup_bvae()
    };
    let mut g = c.benchmark_group("conv_step");
    g.sample_size(10);
    // Criterion's "elem/s" are FLOP/s (`ConvArch::step_flops`).
    g.throughput(Throughput::Elements(
        ConvArch::followup(10).step_flops(BATCH),
    ));
    g.warm_up_time(Duration::from_secs(2));
    g.measurement_time(Duration::from_secs(8));
    let mut rng = stream_named(1, "learner");
    let mut trainer = ConvTrainer::new(ConvNet::init(
        &mut rng,
        ConvArch::followup(10),
        ConvInit::default(),
    ));
    let mut step = 0;
    g.bench_function("followup-bvae/batch64", |b| {
        b.iter(|| {
            step += 1;
            black_box(trainer.step(&cfg, &x, BATCH, step, &mut rng).unwrap())
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
