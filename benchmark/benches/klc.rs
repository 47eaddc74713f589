//! KL-coverage of 5001 outcomes (ArmBall 2-D, ArmArrow 3-D), from scratch and incrementally.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::RngExt;
use std::hint::black_box;
use ugl_bench::metrics::KlCoverage;
use ugl_bench::seed::stream_named;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("klc");
    for dim in [2usize, 3] {
        let k = KlCoverage::new(dim).unwrap();
        let mut rng = stream_named(1, "bench");
        let pts: Vec<Vec<f64>> = (0..5001)
            .map(|_| {
                loop {
                    let p: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
                    if p[0] * p[0] + p[1] * p[1] < 1.0 {
                        break p;
                    }
                }
            })
            .collect();
        g.bench_function(format!("{dim}d_5001pts"), |b| {
            b.iter(|| k.evaluate(pts.iter().map(|p| &p[..])).unwrap())
        });
        let mut h = k.histogram();
        for p in &pts {
            h.add(p).unwrap();
        }
        g.bench_function(format!("{dim}d_read_incremental"), |b| {
            b.iter(|| black_box(&h).klc().unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
