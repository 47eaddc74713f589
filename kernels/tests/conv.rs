//! The convolutions against direct loops (in f64), their adjoint identities, and the same bits
//! on every SIMD path and thread count.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ugl_kernels::{Conv2d, ConvTranspose2d, SimdPath};

fn random(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.random_range(-1.0f32..1.0)).collect()
}

/// The follow-up's first encoder layer, a decoder-sized one, and odd shapes (no padding, stride
/// 1, a kernel that does not tile the image), then the follow-up's second and third encoder
/// layers (their outputs 16 and 8 pixels wide: the direct kernels of the SIMD paths, or the
/// im2col product where a row is narrower than a vector).
const SHAPES: [Conv2d; 6] = [
    Conv2d {
        channels_in: 3,
        channels_out: 32,
        kernel: 4,
        stride: 2,
        padding: 1,
        height: 64,
        width: 64,
    },
    Conv2d {
        channels_in: 32,
        channels_out: 32,
        kernel: 4,
        stride: 2,
        padding: 1,
        height: 8,
        width: 8,
    },
    Conv2d {
        channels_in: 2,
        channels_out: 5,
        kernel: 3,
        stride: 1,
        padding: 0,
        height: 7,
        width: 5,
    },
    Conv2d {
        channels_in: 3,
        channels_out: 4,
        kernel: 4,
        stride: 3,
        padding: 2,
        height: 11,
        width: 9,
    },
    Conv2d {
        channels_in: 32,
        channels_out: 32,
        kernel: 4,
        stride: 2,
        padding: 1,
        height: 32,
        width: 32,
    },
    Conv2d {
        channels_in: 32,
        channels_out: 32,
        kernel: 4,
        stride: 2,
        padding: 1,
        height: 16,
        width: 16,
    },
];

/// `x` at (n, c, y, x) with zero padding.
fn at(c: &Conv2d, x: &[f32], n: usize, ch: usize, y: isize, xx: isize) -> f64 {
    if y < 0 || xx < 0 || y >= c.height as isize || xx >= c.width as isize {
        return 0.0;
    }
    x[((n * c.channels_in + ch) * c.height + y as usize) * c.width + xx as usize] as f64
}

/// The convolution written out.
fn direct(c: &Conv2d, n: usize, x: &[f32], w: &[f32], b: &[f32]) -> Vec<f64> {
    let (oh, ow, k) = (c.out_height(), c.out_width(), c.kernel);
    let mut y = vec![0.0; n * c.out_len()];
    for i in 0..n {
        for o in 0..c.channels_out {
            for oy in 0..oh {
                for ox in 0..ow {
                    let mut s = b[o] as f64;
                    for ch in 0..c.channels_in {
                        for ky in 0..k {
                            for kx in 0..k {
                                let yy = (oy * c.stride + ky) as isize - c.padding as isize;
                                let xx = (ox * c.stride + kx) as isize - c.padding as isize;
                                s += w[((o * c.channels_in + ch) * k + ky) * k + kx] as f64
                                    * at(c, x, i, ch, yy, xx);
                            }
                        }
                    }
                    y[((i * c.channels_out + o) * oh + oy) * ow + ox] = s;
                }
            }
        }
    }
    y
}

fn dot(a: &[f32], b: &[f32]) -> f64 {
    a.iter().zip(b).map(|(a, b)| *a as f64 * *b as f64).sum()
}

/// The size of the terms of `dot(a, b)`: what its f32 rounding errors scale with.
fn dot_abs(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (*a as f64 * *b as f64).abs())
        .sum()
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-5 * scale.max(1.0)
}

#[test]
fn the_convolution_is_the_direct_sum_and_its_gradients_are_its_adjoints() {
    let n = 3;
    for (s, c) in SHAPES.iter().enumerate() {
        let seed = 100 * s as u64;
        let x = random(n * c.in_len(), seed);
        let w = random(c.weight_len(), seed + 1);
        let b = random(c.channels_out, seed + 2);
        let g = random(n * c.out_len(), seed + 3);
        let mut y = vec![0.0; n * c.out_len()];
        c.forward(n, &x, &w, Some(&b), &mut y);
        let want = direct(c, n, &x, &w, &b);
        let scale = (c.channels_in * c.kernel * c.kernel) as f64;
        for (i, (a, d)) in y.iter().zip(&want).enumerate() {
            assert!(close(*a as f64, *d, scale), "{c:?} output {i}: {a} vs {d}");
        }
        // The input gradient is the adjoint: <conv(x), g> = <x, conv'(g)> (no bias).
        c.forward(n, &x, &w, None, &mut y);
        let mut dx = vec![0.0; n * c.in_len()];
        c.backward_input(n, &g, &w, &mut dx);
        let (lhs, rhs) = (dot(&y, &g), dot(&x, &dx));
        let size = dot_abs(&y, &g);
        assert!(close(lhs, rhs, size), "{c:?}: {lhs} vs {rhs}");
        // The weight gradient: <conv_w(x), g> is linear in w, so <dw, w> = <conv(x), g>.
        let mut dw = vec![0.0; c.weight_len()];
        let mut db = vec![0.0; c.channels_out];
        c.backward_weight(n, &x, &g, &mut dw, Some(&mut db));
        let by_w = dot(&dw, &w);
        assert!(close(lhs, by_w, size), "{c:?}: {lhs} vs {by_w}");
        // The bias gradient: the sum of each channel's output gradient.
        let pix = c.out_height() * c.out_width();
        for (o, d) in db.iter().enumerate() {
            let want: f64 = (0..n)
                .flat_map(|i| &g[i * c.out_len() + o * pix..][..pix])
                .map(|v| *v as f64)
                .sum();
            assert!(close(*d as f64, want, want.abs()), "{c:?} bias {o}");
        }
        // And one weight by a finite difference of the loss <conv(x), g>.
        let j = w.len() / 2;
        let mut w2 = w.clone();
        w2[j] += 1.0;
        let mut y2 = vec![0.0; n * c.out_len()];
        c.forward(n, &x, &w2, None, &mut y2);
        let fd = dot(&y2, &g) - lhs;
        assert!(
            (fd - dw[j] as f64).abs() < 1e-3 * fd.abs().max(1.0),
            "{fd} vs {}",
            dw[j]
        );
    }
}

#[test]
fn the_transposed_convolution_is_the_adjoint_of_the_convolution() {
    // The follow-up's decoder layers: 4 -> 8 -> ... -> 64 pixels, 32 channels, then 3.
    let shapes = [
        ConvTranspose2d {
            channels_in: 32,
            channels_out: 32,
            kernel: 4,
            stride: 2,
            padding: 1,
            height: 4,
            width: 4,
        },
        ConvTranspose2d {
            channels_in: 32,
            channels_out: 3,
            kernel: 4,
            stride: 2,
            padding: 1,
            height: 32,
            width: 32,
        },
    ];
    let n = 2;
    for (s, t) in shapes.iter().enumerate() {
        assert_eq!(t.out_height(), 2 * t.height);
        let seed = 1000 + 10 * s as u64;
        let x = random(n * t.in_len(), seed);
        let w = random(t.weight_len(), seed + 1);
        let b = random(t.channels_out, seed + 2);
        let g = random(n * t.out_len(), seed + 3);
        let mut y = vec![0.0; n * t.out_len()];
        t.forward(n, &x, &w, None, &mut y);
        // <convT(x), g> = <x, conv(g)>: its input gradient is the convolution.
        let mut dx = vec![0.0; n * t.in_len()];
        t.backward_input(n, &g, &w, &mut dx);
        let (lhs, rhs) = (dot(&y, &g), dot(&x, &dx));
        let size = dot_abs(&y, &g);
        assert!(close(lhs, rhs, size), "{t:?}: {lhs} vs {rhs}");
        let mut dw = vec![0.0; t.weight_len()];
        let mut db = vec![0.0; t.channels_out];
        t.backward_weight(n, &x, &g, &mut dw, Some(&mut db));
        assert!(close(lhs, dot(&dw, &w), size));
        // The bias adds to every output pixel of its channel.
        let mut yb = vec![0.0; n * t.out_len()];
        t.forward(n, &x, &w, Some(&b), &mut yb);
        let shift: Vec<f32> = yb.iter().zip(&y).map(|(a, b)| a - b).collect();
        let (by_bias, want) = (dot(&shift, &g), dot(&db, &b));
        assert!(
            close(by_bias, want, dot_abs(&shift, &g)),
            "{by_bias} vs {want}"
        );
        // One output value written out: y[0, o, oy, ox] = sum over the inputs that reach it.
        let (o, oy, ox) = (t.channels_out - 1, 5, 6);
        let mut want = 0.0;
        for c in 0..t.channels_in {
            for iy in 0..t.height {
                for ix in 0..t.width {
                    let ky = oy as isize + t.padding as isize - (iy * t.stride) as isize;
                    let kx = ox as isize + t.padding as isize - (ix * t.stride) as isize;
                    let k = t.kernel as isize;
                    if (0..k).contains(&ky) && (0..k).contains(&kx) {
                        let wi = ((c * t.channels_out + o) * t.kernel + ky as usize) * t.kernel
                            + kx as usize;
                        want += w[wi] as f64 * x[(c * t.height + iy) * t.width + ix] as f64;
                    }
                }
            }
        }
        let got = y[(o * t.out_height() + oy) * t.out_width() + ox] as f64;
        assert!(close(got, want, 1.0), "{got} vs {want}");
    }
}

#[test]
fn every_path_and_thread_count_gives_the_same_bits() {
    let paths: Vec<SimdPath> = SimdPath::ALL
        .into_iter()
        .filter(|p| p.available())
        .collect();
    let n = 4;
    for (s, c) in SHAPES.iter().enumerate() {
        let seed = 7 + s as u64;
        let x = random(n * c.in_len(), seed);
        let w = random(c.weight_len(), seed + 1);
        let b = random(c.channels_out, seed + 2);
        let g = random(n * c.out_len(), seed + 3);
        let run = |path: SimdPath, threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let mut y = vec![0.0; n * c.out_len()];
                    c.forward_on(path, n, &x, &w, Some(&b), &mut y);
                    let mut dx = vec![0.0; n * c.in_len()];
                    c.backward_input_on(path, n, &g, &w, &mut dx);
                    let mut dw = vec![0.0; c.weight_len()];
                    let mut db = vec![0.0; c.channels_out];
                    c.backward_weight_on(path, n, &x, &g, &mut dw, Some(&mut db));
                    [y, dx, dw, db].map(|v| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>())
                })
        };
        let reference = run(SimdPath::Scalar, 1);
        for &path in &paths {
            for threads in [1, 2, 3] {
                assert!(
                    run(path, threads) == reference,
                    "{c:?}: {path} with {threads} threads differs from the scalar path"
                );
            }
        }
    }
}

/// The contract, bit for bit: every output is one `mul_add` chain from its bias over
/// `(c, ky, kx)`, and every weight's gradient one chain from 0 over `(image, oy, ox)` (10 images:
/// more than one group of `im2row` matrices), padding values included as zeros.
#[test]
fn the_outputs_and_weight_gradients_are_the_documented_chains() {
    let n = 10;
    for (s, c) in SHAPES.iter().enumerate().skip(1) {
        let seed = 40 + s as u64;
        let x = random(n * c.in_len(), seed);
        let w = random(c.weight_len(), seed + 1);
        let b = random(c.channels_out, seed + 2);
        let g = random(n * c.out_len(), seed + 3);
        let (oh, ow, k, ci) = (c.out_height(), c.out_width(), c.kernel, c.channels_in);
        let value = |i: usize, ch: usize, oy: usize, ox: usize, ky: usize, kx: usize| {
            let y = (oy * c.stride + ky) as isize - c.padding as isize;
            let xx = (ox * c.stride + kx) as isize - c.padding as isize;
            at(c, &x, i, ch, y, xx) as f32
        };
        let mut y = vec![0.0; n * c.out_len()];
        c.forward(n, &x, &w, Some(&b), &mut y);
        let mut dw = vec![0.0; c.weight_len()];
        c.backward_weight(n, &x, &g, &mut dw, None);
        for o in 0..c.channels_out {
            for (r, (ch, ky, kx)) in (0..ci)
                .flat_map(|ch| (0..k).flat_map(move |ky| (0..k).map(move |kx| (ch, ky, kx))))
                .enumerate()
            {
                let mut acc = 0.0f32;
                for i in 0..n {
                    for oy in 0..oh {
                        for ox in 0..ow {
                            let gv = g[((i * c.channels_out + o) * oh + oy) * ow + ox];
                            acc = gv.mul_add(value(i, ch, oy, ox, ky, kx), acc);
                        }
                    }
                }
                let got = dw[o * ci * k * k + r];
                assert_eq!(got.to_bits(), acc.to_bits(), "{c:?}: dw[{o}, {r}]");
            }
            for i in [0, n - 1] {
                for (oy, ox) in [(0, 0), (oh / 2, ow - 1)] {
                    let mut acc = b[o];
                    for ch in 0..ci {
                        for ky in 0..k {
                            for kx in 0..k {
                                let wv = w[((o * ci + ch) * k + ky) * k + kx];
                                acc = wv.mul_add(value(i, ch, oy, ox, ky, kx), acc);
                            }
                        }
                    }
                    let got = y[((i * c.channels_out + o) * oh + oy) * ow + ox];
                    assert_eq!(
                        got.to_bits(),
                        acc.to_bits(),
                        "{c:?}: y[{i}, {o}, {oy}, {ox}]"
                    );
                }
            }
        }
    }
}

/// The operation counts the benches report throughput with: the follow-up's first encoder
/// layer (3 -> 32 channels, 64 -> 32 pixels a side) does 32 x 3 x 16 multiply-adds for each of
/// its 32 x 32 outputs per image, and the decoder's last (its adjoint) as many.
#[test]
fn the_operation_count_is_two_per_multiply_add() {
    let first = Conv2d {
        channels_in: 3,
        channels_out: 32,
        kernel: 4,
        stride: 2,
        padding: 1,
        height: 64,
        width: 64,
    };
    assert_eq!(first.flops(64), 2 * 32 * 3 * 16 * 32 * 32 * 64);
    let last = ConvTranspose2d {
        channels_in: 32,
        channels_out: 3,
        kernel: 4,
        stride: 2,
        padding: 1,
        height: 32,
        width: 32,
    };
    assert_eq!(last.flops(64), first.flops(64));
}
