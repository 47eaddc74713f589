//! Rollout throughput: one 50-step episode of the 7-joint arm (the paper's DMP environments:
//! target >= 100,000/s/core), in every built-in environment.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use ugl_bench::env::{EnvConfig, EnvKind, make_env};
use ugl_bench::explore::meta_policy::random_params;
use ugl_bench::seed::{Component, stream};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("rollout");
    g.throughput(Throughput::Elements(1024));
    for kind in EnvKind::all() {
        let env = make_env(kind, &EnvConfig::default());
        let mut rng = stream(0, Component::Params);
        let thetas: Vec<_> = (0..1024)
            .map(|_| random_params(&mut rng, env.param_dim()))
            .collect();
        let mut noise = stream(0, Component::Distractor);
        g.bench_function(format!("{kind}_x1024"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for t in &thetas {
                    acc += env.rollout(black_box(t), &mut noise).hand[0];
                }
                acc
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
