//! The machine's fused multiply-add ceiling on one thread, per SIMD path: independent FMA chains
//! on registers, nothing loaded or stored, so nothing but the FMA units limits them. Criterion's
//! "elem/s" are FLOP/s (a multiply-add counts 2), the yardstick of the `conv` and `matmul`
//! benches: `cargo bench -p ugl-kernels --profile dev --bench peak`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

/// Multiply-adds per chain per call.
const STEPS: usize = 1 << 16;
/// Independent chains, enough to cover the FMA latency on two pipes.
const CHAINS: usize = 12;

#[cfg(target_arch = "x86_64")]
macro_rules! fma_loop {
    ($name:ident, $feature:literal, $lanes:literal, $set1:ident, $fma:ident, $sum:expr) => {
        /// # Safety
        /// On a CPU with the target feature.
        #[target_feature(enable = $feature)]
        unsafe fn $name(a: f32, b: f32) -> f32 {
            use std::arch::x86_64::*;
            let (va, vb) = ($set1(a), $set1(b));
            let mut acc = [$set1(0.0); CHAINS];
            for (i, v) in acc.iter_mut().enumerate() {
                *v = $set1(i as f32);
            }
            for _ in 0..STEPS {
                for v in acc.iter_mut() {
                    *v = $fma(va, *v, vb);
                }
            }
            let mut lanes = [0.0f32; $lanes];
            let mut out = 0.0;
            for v in acc {
                // SAFETY: `lanes` holds one vector.
                unsafe { $sum(lanes.as_mut_ptr(), v) };
                out += lanes.iter().sum::<f32>();
            }
            out
        }
    };
}

#[cfg(target_arch = "x86_64")]
fma_loop!(
    avx2,
    "avx2,fma",
    8,
    _mm256_set1_ps,
    _mm256_fmadd_ps,
    _mm256_storeu_ps
);
#[cfg(target_arch = "x86_64")]
fma_loop!(
    avx512,
    "avx512f",
    16,
    _mm512_set1_ps,
    _mm512_fmadd_ps,
    _mm512_storeu_ps
);

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("fma_peak");
    g.sample_size(20);
    #[cfg(target_arch = "x86_64")]
    {
        // (name, lanes, whether the CPU has it, the loop)
        let paths: [(&str, usize, bool, unsafe fn(f32, f32) -> f32); 2] = [
            (
                "avx2",
                8,
                is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"),
                avx2,
            ),
            ("avx512", 16, is_x86_feature_detected!("avx512f"), avx512),
        ];
        for (name, lanes, has, f) in paths {
            if !has {
                continue;
            }
            g.throughput(Throughput::Elements((2 * STEPS * CHAINS * lanes) as u64));
            // SAFETY: the CPU has the path's features (checked above).
            g.bench_function(name, |b| {
                b.iter(|| unsafe { f(black_box(0.999), black_box(1e-3)) })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
