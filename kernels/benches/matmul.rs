//! The training step's biggest products (batch 100, 1200 hidden units, 4900 pixels) on each
//! path the machine has: `cargo bench -p ugl-kernels --bench matmul`.

use criterion::{Criterion, criterion_group, criterion_main};
use ugl_kernels::{MatRef, SimdPath, matmul_on};

fn products(c: &mut Criterion) {
    let shapes = [
        (100usize, 4900usize, 1200usize),
        (1200, 4900, 100),
        (100, 1200, 4900),
    ];
    let mut group = c.benchmark_group("matmul_f32");
    group.sample_size(20);
    for path in SimdPath::available_paths()
        .into_iter()
        .filter(|&p| p != SimdPath::Scalar)
    {
        for &(m, n, k) in &shapes {
            let a: Vec<f32> = (0..m * k).map(|i| (i % 97) as f32 * 0.01).collect();
            let b: Vec<f32> = (0..k * n).map(|i| (i % 89) as f32 * 0.01).collect();
            let mut out = vec![0.0f32; m * n];
            group.bench_function(format!("{path}/{m}x{n}x{k}"), |bench| {
                bench.iter(|| {
                    matmul_on(
                        path,
                        &mut out,
                        MatRef::row_major(&a, m, k),
                        MatRef::row_major(&b, k, n),
                        false,
                    )
                })
            });
        }
    }
    for &(m, n, k) in &shapes {
        let a: Vec<f32> = (0..m * k).map(|i| (i % 97) as f32 * 0.01).collect();
        let b: Vec<f32> = (0..k * n).map(|i| (i % 89) as f32 * 0.01).collect();
        let mut out = vec![0.0f32; m * n];
        group.bench_function(format!("gemm-crate/{m}x{n}x{k}"), |bench| {
            bench.iter(|| unsafe {
                gemm::gemm(
                    m,
                    n,
                    k,
                    out.as_mut_ptr(),
                    1,
                    n as isize,
                    false,
                    a.as_ptr(),
                    1,
                    k as isize,
                    b.as_ptr(),
                    1,
                    n as isize,
                    1.0,
                    1.0,
                    false,
                    false,
                    false,
                    gemm::Parallelism::None,
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, products);
criterion_main!(benches);
