//! Criterion bench of the 70x70 renderer (docs/original-code.md section 2): one image per call of
//! `render_ball_into` / `render_arrow_into`, into a reused buffer (no allocation).
//!
//! `cargo bench -p ugl-bench --bench render`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use ugl_bench::env::render::{PIXELS, render_arrow_into, render_ball_into};

/// A fixed set of states spread over [-1, 1]^3 (a simple LCG, so the bench needs no RNG crate).
fn states(n: usize) -> Vec<[f64; 3]> {
    let mut z: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = move || {
        z = z
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n).map(|_| [next(), next(), next()]).collect()
}

fn bench_render(c: &mut Criterion) {
    let states = states(256);
    let mut out = vec![0.0f32; PIXELS];
    let mut group = c.benchmark_group("render");

    group.bench_function("ball_into", |b| {
        let mut i = 0;
        b.iter(|| {
            let s = &states[i % states.len()];
            i += 1;
            render_ball_into(black_box(s[0]), black_box(s[1]), &mut out);
            black_box(&out);
        })
    });

    group.bench_function("arrow_into", |b| {
        let mut i = 0;
        b.iter(|| {
            let s = &states[i % states.len()];
            i += 1;
            render_arrow_into(black_box(s[0]), black_box(s[1]), black_box(s[2]), &mut out);
            black_box(&out);
        })
    });

    group.finish();
}

criterion_group!(benches, bench_render);
criterion_main!(benches);
