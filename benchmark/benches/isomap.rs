//! Isomap (docs/original-code.md section 5, sklearn `Isomap` defaults, n_neighbors = 5): fit on 2,000
//! rendered ball images with 2 latents, and `encode_one` of a new image on the fitted model.
//! Run: `cargo bench -p ugl-bench --profile dev --bench isomap`.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::RngExt;
use std::hint::black_box;
use ugl_bench::env::render::{PIXELS, render_ball_into};
use ugl_bench::repr::isomap::Isomap;
use ugl_bench::repr::{ImageSet, RepresentationLearner};
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
    let mut g = c.benchmark_group("isomap");
    g.sample_size(10);
    let train = balls(2000, 1);
    let learner = Isomap::default();
    g.bench_function("fit_2000_balls_2_latents", |b| {
        b.iter(|| {
            learner
                .fit(black_box(&train), 2, &mut stream_named(1, "learner"))
                .unwrap()
        })
    });
    let (mut enc, _) = learner
        .fit(&train, 2, &mut stream_named(1, "learner"))
        .unwrap();
    let probe = balls(64, 2);
    let mut out = [0.0f64; 2];
    let mut i = 0;
    g.sample_size(100);
    g.bench_function("encode_one_2000_train", |b| {
        b.iter(|| {
            i = (i + 1) % probe.n;
            enc.encode_one(black_box(probe.row(i)), &mut out).unwrap();
            out
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
