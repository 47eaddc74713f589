//! With subnormals flushed to zero ([`flushing_pool`]), every path and thread count still gives
//! the same bits, on operands chosen so that the flush matters: products and sums that fall in
//! the subnormal range, and subnormal operands.
#![cfg(target_arch = "x86_64")]

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ugl_kernels::{Conv2d, MatRef, SimdPath, flushing_pool, matmul_on};

/// Values of magnitude 2^-80 .. 2^-60 (products on both sides of the normal range's bottom, 2^-126),
/// every 17th a subnormal.
fn tiny(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|i| {
            if i % 17 == 0 {
                return f32::from_bits(rng.random_range(1u32..0x0080_0000));
            }
            let m: f32 = rng.random_range(1.0f32..2.0);
            let e: i32 = rng.random_range(-80..-60);
            let s = if rng.random_range(0..2) == 0 {
                1.0
            } else {
                -1.0
            };
            s * m * 2f32.powi(e)
        })
        .collect()
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|f| f.to_bits()).collect()
}

fn paths() -> Vec<SimdPath> {
    SimdPath::ALL
        .into_iter()
        .filter(|p| p.available())
        .collect()
}

/// The products of the operands on `path`, in a flushing pool of `threads` (or, with
/// `flush == false`, a plain one).
fn product(
    path: SimdPath,
    threads: usize,
    flush: bool,
    (a, b): (&[f32], &[f32]),
    (m, n, k): (usize, usize, usize),
) -> Vec<u32> {
    let run = || {
        let mut out = vec![0.0f32; m * n];
        matmul_on(
            path,
            &mut out,
            MatRef::row_major(a, m, k),
            MatRef::row_major(b, k, n),
            false,
        );
        bits(&out)
    };
    if flush {
        flushing_pool(threads).unwrap().install(run)
    } else {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(run)
    }
}

#[test]
fn flushed_products_agree_on_every_path_and_thread_count() {
    for (m, n, k) in [(7, 33, 257), (100, 50, 300), (121, 20, 40)] {
        let a = tiny(m * k, 1);
        let b = tiny(k * n, 2);
        let reference = product(SimdPath::Scalar, 1, true, (&a, &b), (m, n, k));
        // The flush took effect: no subnormal result, and the unflushed product differs (it has
        // subnormal results, so the known-bad case is detectable).
        assert!(reference.iter().all(|&u| !f32::from_bits(u).is_subnormal()));
        let plain = product(SimdPath::Scalar, 1, false, (&a, &b), (m, n, k));
        assert!(plain.iter().any(|&u| f32::from_bits(u).is_subnormal()));
        assert_ne!(plain, reference, "{m}x{n}x{k}: the flush changed nothing");
        for path in paths() {
            for threads in [1, 2, 3] {
                assert!(
                    product(path, threads, true, (&a, &b), (m, n, k)) == reference,
                    "{m}x{n}x{k}: {path} with {threads} threads differs from the flushed scalar path"
                );
            }
        }
    }
}

#[test]
fn flushed_convolutions_agree_on_every_path() {
    // The adjoint of the decoder's last layer, where the black pixels' tiny gradients enter
    // (the transposed convolutions are built on these three products).
    let c = Conv2d {
        channels_in: 3,
        channels_out: 32,
        kernel: 4,
        stride: 2,
        padding: 1,
        height: 32,
        width: 32,
    };
    let n = 3;
    let x = tiny(n * c.in_len(), 3);
    let w = tiny(c.weight_len(), 4);
    let g = tiny(n * c.out_len(), 5);
    let compute = |path: SimdPath| {
        let mut y = vec![0.0; n * c.out_len()];
        c.forward_on(path, n, &x, &w, None, &mut y);
        let mut dx = vec![0.0; n * c.in_len()];
        c.backward_input_on(path, n, &g, &w, &mut dx);
        let mut dw = vec![0.0; c.weight_len()];
        c.backward_weight_on(path, n, &x, &g, &mut dw, None);
        [bits(&y), bits(&dx), bits(&dw)]
    };
    let run =
        |path: SimdPath, threads: usize| flushing_pool(threads).unwrap().install(|| compute(path));
    let reference = run(SimdPath::Scalar, 1);
    // Not a comparison of zeros: each output has non-zero values, none subnormal, and IEEE
    // arithmetic gives other bits for each (so a path that ignored the flush would show).
    let plain = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| compute(SimdPath::Scalar));
    for (k, (flushed, ieee)) in reference.iter().zip(&plain).enumerate() {
        assert!(
            flushed.iter().any(|&u| f32::from_bits(u) != 0.0),
            "output {k}: all zero"
        );
        assert!(
            flushed.iter().all(|&u| !f32::from_bits(u).is_subnormal()),
            "output {k}"
        );
        assert_ne!(flushed, ieee, "output {k}: the flush changed nothing");
    }
    for path in paths() {
        for threads in [1, 2] {
            assert!(
                run(path, threads) == reference,
                "{path} with {threads} threads differs from the flushed scalar path"
            );
        }
    }
}
