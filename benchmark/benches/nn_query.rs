//! Nearest-neighbour query of the meta-policy in a history of 5001 outcomes (2-D, 3-D, 10-D).

use criterion::{Criterion, criterion_group, criterion_main};
use rand::RngExt;
use std::hint::black_box;
use ugl_bench::explore::nn::NnIndex;
use ugl_bench::seed::stream_named;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("nn_query");
    for dim in [2usize, 3, 10] {
        let mut rng = stream_named(dim as u64, "bench");
        let mut idx = NnIndex::new(dim);
        for i in 0..5001 {
            // Like a real history: many episodes leave the object where it was.
            let p: Vec<f64> = if i % 4 == 0 {
                vec![0.8; dim]
            } else {
                (0..dim).map(|_| rng.random_range(0.0..1.0)).collect()
            };
            idx.insert(&p);
        }
        let queries: Vec<Vec<f64>> = (0..256)
            .map(|_| (0..dim).map(|_| rng.random_range(0.0..1.0)).collect())
            .collect();
        g.bench_function(format!("{dim}d_5001pts_x256"), |b| {
            b.iter(|| {
                queries
                    .iter()
                    .map(|q| idx.nearest(black_box(q)).unwrap().0)
                    .sum::<usize>()
            })
        });
        g.bench_function(format!("{dim}d_build_5001"), |b| {
            let pts: Vec<Vec<f64>> = (0..5001)
                .map(|_| (0..dim).map(|_| rng.random_range(0.0..1.0)).collect())
                .collect();
            b.iter(|| {
                let mut idx = NnIndex::new(dim);
                for p in &pts {
                    idx.insert(p);
                }
                idx.len()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
