//! Every path the machine has computes the contract's bits: one FMA chain per output, in
//! increasing inner order, from the output (accumulate) or zero, whatever the shapes, strides,
//! blocking edges and thread count.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ugl_kernels::{Element, MatRef, SimdPath, matmul_on, matmul_reference};

fn random<T: From<f32>>(n: usize, seed: u64) -> Vec<T> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| T::from(rng.random_range(-1.0f32..1.0)))
        .collect()
}

fn in_pool<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Shapes chosen to cross the blocking edges: the inner block (256), the row block (120) and
/// every micro-tile's edges, and a product big enough to split across threads.
const SHAPES: [(usize, usize, usize); 10] = [
    (1, 1, 1),
    (3, 5, 7),
    (6, 16, 256),
    (7, 33, 257),
    (97, 65, 600),
    (121, 20, 300),
    (100, 50, 1200),
    (200, 300, 40),
    (13, 1, 513),
    (1, 70, 3),
];

fn check<T: Element + From<f32>>(path: SimdPath, threads: usize) {
    for (s, &(m, n, k)) in SHAPES.iter().enumerate() {
        let seed = s as u64 * 10;
        // a: m x k row-major, and its transpose; b: k x n row-major (read in place) and given
        // transposed (packed).
        let a = random::<T>(m * k, seed);
        let at = random::<T>(m * k, seed + 3);
        let bt = random::<T>(n * k, seed + 1);
        let init = random::<T>(m * n, seed + 2);
        let layouts = [
            (
                MatRef::row_major(&a, m, k),
                MatRef::row_major(&bt, n, k).t(),
            ),
            (
                MatRef::row_major(&at, k, m).t(),
                MatRef::row_major(&bt, k, n),
            ),
        ];
        for ((av, bv), accumulate) in layouts.into_iter().flat_map(|l| [(l, false), (l, true)]) {
            let mut want = init.clone();
            matmul_reference(&mut want, av, bv, accumulate);
            let mut got = init.clone();
            in_pool(threads, || matmul_on(path, &mut got, av, bv, accumulate));
            let same = want
                .iter()
                .zip(&got)
                .all(|(w, g)| format!("{w:?}") == format!("{g:?}"));
            assert!(
                same,
                "{path} path, {threads} threads, {m}x{n}x{k}, accumulate {accumulate}: not the reference's bits"
            );
        }
    }
}

#[test]
fn every_available_path_gives_the_reference_bits_f32() {
    for path in SimdPath::available_paths() {
        for threads in [1, 2, 3] {
            check::<f32>(path, threads);
        }
    }
}

#[test]
fn every_available_path_gives_the_reference_bits_f64() {
    for path in SimdPath::available_paths() {
        for threads in [1, 2] {
            check::<f64>(path, threads);
        }
    }
}

/// The bitwise check can fail: an unfused chain (`a * b + acc`, two roundings) or one split
/// into two partial sums at the inner block gives other bits on the same inputs.
#[test]
fn other_summation_orders_give_other_bits() {
    let (m, n, k) = (20, 20, 600);
    let a = random::<f32>(m * k, 1);
    let b = random::<f32>(k * n, 2);
    let mut want = vec![0.0f32; m * n];
    matmul_reference(
        &mut want,
        MatRef::row_major(&a, m, k),
        MatRef::row_major(&b, k, n),
        false,
    );
    let mut unfused = vec![0.0f32; m * n];
    let mut split = vec![0.0f32; m * n];
    for i in 0..m {
        for j in 0..n {
            let mut acc = 0.0f32;
            let (mut lo, mut hi) = (0.0f32, 0.0f32);
            for p in 0..k {
                acc += a[i * k + p] * b[p * n + j];
                if p < 256 {
                    lo = a[i * k + p].mul_add(b[p * n + j], lo);
                } else {
                    hi = a[i * k + p].mul_add(b[p * n + j], hi);
                }
            }
            unfused[i * n + j] = acc;
            split[i * n + j] = lo + hi;
        }
    }
    let differ = |x: &[f32]| x.iter().zip(&want).filter(|(p, q)| p != q).count();
    assert!(differ(&unfused) > 0 && differ(&split) > 0);
    // ... while every path agrees with the reference.
    for path in SimdPath::available_paths() {
        let mut got = vec![0.0f32; m * n];
        matmul_on(
            path,
            &mut got,
            MatRef::row_major(&a, m, k),
            MatRef::row_major(&b, k, n),
            false,
        );
        assert_eq!(differ(&got), 0, "{path}");
    }
}

#[test]
fn empty_inner_dimension_zeroes_or_keeps_the_output() {
    let a: Vec<f32> = vec![];
    let mut out = vec![1.5f32; 6];
    let av = MatRef::row_major(&a, 2, 0);
    let bv = MatRef::row_major(&a, 0, 3);
    matmul_on(SimdPath::Scalar, &mut out, av, bv, true);
    assert_eq!(out, vec![1.5; 6]);
    matmul_on(SimdPath::Scalar, &mut out, av, bv, false);
    assert_eq!(out, vec![0.0; 6]);
}

#[test]
#[should_panic(expected = "outside a slice")]
fn a_view_past_its_slice_is_refused() {
    let a = [0.0f32; 5];
    let _ = MatRef::row_major(&a, 2, 3);
}
