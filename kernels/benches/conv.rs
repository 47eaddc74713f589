//! The follow-up's convolution stack (its encoder's four convolutions and its decoder's four
//! transposed ones, 64x64 RGB, batch 64), forward and backward: what `scripts/conv_side_by_side.sh`
//! times against PyTorch's same layers.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use ugl_kernels::{Conv2d, ConvTranspose2d};

const BATCH: usize = 64;

fn encoder() -> Vec<Conv2d> {
    [(3, 64), (32, 32), (32, 16), (32, 8)]
        .map(|(c, side)| Conv2d {
            channels_in: c,
            channels_out: 32,
            kernel: 4,
            stride: 2,
            padding: 1,
            height: side,
            width: side,
        })
        .to_vec()
}

fn decoder() -> Vec<ConvTranspose2d> {
    [(32, 4), (32, 8), (32, 16), (3, 32)]
        .map(|(c, side)| ConvTranspose2d {
            channels_in: 32,
            channels_out: c,
            kernel: 4,
            stride: 2,
            padding: 1,
            height: side,
            width: side,
        })
        .to_vec()
}

fn filled(n: usize, v: f32) -> Vec<f32> {
    (0..n).map(|i| v * ((i % 97) as f32 / 97.0 - 0.5)).collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("conv_stack");
    g.sample_size(10);
    let enc = encoder();
    let dec = decoder();
    // Activations and gradients of every layer, allocated once.
    let xs: Vec<Vec<f32>> = enc
        .iter()
        .map(|l| filled(BATCH * l.in_len(), 1.0))
        .collect();
    let ys: Vec<Vec<f32>> = enc
        .iter()
        .map(|l| filled(BATCH * l.out_len(), 1.0))
        .collect();
    let ws: Vec<Vec<f32>> = enc.iter().map(|l| filled(l.weight_len(), 0.1)).collect();
    let txs: Vec<Vec<f32>> = dec
        .iter()
        .map(|l| filled(BATCH * l.in_len(), 1.0))
        .collect();
    let tys: Vec<Vec<f32>> = dec
        .iter()
        .map(|l| filled(BATCH * l.out_len(), 1.0))
        .collect();
    let tws: Vec<Vec<f32>> = dec.iter().map(|l| filled(l.weight_len(), 0.1)).collect();
    g.bench_function("encoder_decoder_forward_backward", |b| {
        let (mut y, mut dx, mut dw) = (Vec::new(), Vec::new(), Vec::new());
        let mut db = [0.0f32; 32];
        b.iter(|| {
            for (i, l) in enc.iter().enumerate() {
                y.resize(BATCH * l.out_len(), 0.0);
                l.forward(BATCH, &xs[i], &ws[i], None, &mut y);
                dx.resize(BATCH * l.in_len(), 0.0);
                l.backward_input(BATCH, &ys[i], &ws[i], &mut dx);
                dw.resize(l.weight_len(), 0.0);
                l.backward_weight(
                    BATCH,
                    &xs[i],
                    &ys[i],
                    &mut dw,
                    Some(&mut db[..l.channels_out]),
                );
            }
            for (i, l) in dec.iter().enumerate() {
                y.resize(BATCH * l.out_len(), 0.0);
                l.forward(BATCH, &txs[i], &tws[i], None, &mut y);
                dx.resize(BATCH * l.in_len(), 0.0);
                l.backward_input(BATCH, &tys[i], &tws[i], &mut dx);
                dw.resize(l.weight_len(), 0.0);
                l.backward_weight(
                    BATCH,
                    &txs[i],
                    &tys[i],
                    &mut dw,
                    Some(&mut db[..l.channels_out]),
                );
            }
            black_box(&y);
        })
    });
    // Each operation alone, over the whole stack (where the time goes).
    g.bench_function("forward", |b| {
        let mut y = Vec::new();
        b.iter(|| {
            for (i, l) in enc.iter().enumerate() {
                y.resize(BATCH * l.out_len(), 0.0);
                l.forward(BATCH, &xs[i], &ws[i], None, &mut y);
            }
            for (i, l) in dec.iter().enumerate() {
                y.resize(BATCH * l.out_len(), 0.0);
                l.forward(BATCH, &txs[i], &tws[i], None, &mut y);
            }
        })
    });
    g.bench_function("backward_input", |b| {
        let mut dx = Vec::new();
        b.iter(|| {
            for (i, l) in enc.iter().enumerate() {
                dx.resize(BATCH * l.in_len(), 0.0);
                l.backward_input(BATCH, &ys[i], &ws[i], &mut dx);
            }
            for (i, l) in dec.iter().enumerate() {
                dx.resize(BATCH * l.in_len(), 0.0);
                l.backward_input(BATCH, &tys[i], &tws[i], &mut dx);
            }
        })
    });
    g.bench_function("backward_weight", |b| {
        let mut dw = Vec::new();
        b.iter(|| {
            for (i, l) in enc.iter().enumerate() {
                dw.resize(l.weight_len(), 0.0);
                l.backward_weight(BATCH, &xs[i], &ys[i], &mut dw, None);
            }
            for (i, l) in dec.iter().enumerate() {
                dw.resize(l.weight_len(), 0.0);
                l.backward_weight(BATCH, &txs[i], &tys[i], &mut dw, None);
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
