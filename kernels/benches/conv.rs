//! The follow-up's convolution stack (its encoder's four convolutions and its decoder's four
//! transposed ones, 64x64 RGB, batch 64), forward and backward: what `scripts/conv_side_by_side.sh`
//! times against PyTorch's same layers.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
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

/// Which operations of a layer to run.
#[derive(Clone, Copy)]
struct Ops {
    forward: bool,
    input: bool,
    weight: bool,
}

/// A layer of the stack: a convolution or a transposed one (the same calls).
trait Layer {
    fn lens(&self) -> (usize, usize, usize, usize);
    fn flop(&self) -> u64;
    fn fwd(&self, x: &[f32], w: &[f32], y: &mut [f32]);
    fn bwd_input(&self, dy: &[f32], w: &[f32], dx: &mut [f32]);
    fn bwd_weight(&self, x: &[f32], dy: &[f32], dw: &mut [f32], db: &mut [f32]);
}

macro_rules! layer {
    ($t:ty) => {
        impl Layer for $t {
            fn lens(&self) -> (usize, usize, usize, usize) {
                (
                    self.in_len(),
                    self.out_len(),
                    self.weight_len(),
                    self.channels_out,
                )
            }
            fn flop(&self) -> u64 {
                self.flops(BATCH)
            }
            fn fwd(&self, x: &[f32], w: &[f32], y: &mut [f32]) {
                self.forward(BATCH, x, w, None, y)
            }
            fn bwd_input(&self, dy: &[f32], w: &[f32], dx: &mut [f32]) {
                self.backward_input(BATCH, dy, w, dx)
            }
            fn bwd_weight(&self, x: &[f32], dy: &[f32], dw: &mut [f32], db: &mut [f32]) {
                self.backward_weight(BATCH, x, dy, dw, Some(db))
            }
        }
    };
}
layer!(Conv2d);
layer!(ConvTranspose2d);

/// The outputs, reused from layer to layer.
#[derive(Default)]
struct Buffers {
    y: Vec<f32>,
    dx: Vec<f32>,
    dw: Vec<f32>,
    db: Vec<f32>,
}

impl Buffers {
    fn layer(&mut self, l: &impl Layer, ops: Ops, x: &[f32], dy: &[f32], w: &[f32]) {
        let (inl, outl, wl, co) = l.lens();
        if ops.forward {
            self.y.resize(BATCH * outl, 0.0);
            l.fwd(x, w, &mut self.y);
        }
        if ops.input {
            self.dx.resize(BATCH * inl, 0.0);
            l.bwd_input(dy, w, &mut self.dx);
        }
        if ops.weight {
            self.dw.resize(wl, 0.0);
            self.db.resize(co, 0.0);
            l.bwd_weight(x, dy, &mut self.dw, &mut self.db);
        }
    }
}

/// Inputs, output gradients and weights of every layer of a stack.
fn tensors(layers: &[impl Layer]) -> (Vec<Vec<f32>>, Vec<Vec<f32>>, Vec<Vec<f32>>) {
    let mut out = (vec![], vec![], vec![]);
    for l in layers {
        let (inl, outl, wl, _) = l.lens();
        out.0.push(filled(BATCH * inl, 1.0));
        out.1.push(filled(BATCH * outl, 1.0));
        out.2.push(filled(wl, 0.1));
    }
    out
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("conv_stack");
    g.sample_size(10);
    let enc = encoder();
    let dec = decoder();
    // Activations and gradients of every layer, allocated once.
    let (xs, ys, ws) = tensors(&enc);
    let (txs, tys, tws) = tensors(&dec);
    let mut bufs = Buffers::default();
    let mut run = |ops: Ops| {
        for (i, l) in enc.iter().enumerate() {
            bufs.layer(l, ops, &xs[i], &ys[i], &ws[i]);
        }
        for (i, l) in dec.iter().enumerate() {
            bufs.layer(l, ops, &txs[i], &tys[i], &tws[i]);
        }
        black_box(&bufs.y);
    };
    let all = Ops {
        forward: true,
        input: true,
        weight: true,
    };
    let none = Ops {
        forward: false,
        input: false,
        weight: false,
    };
    // Throughput in floating-point operations (criterion's "elem/s" are FLOP/s): one pass over
    // the stack, forward or a gradient, does `pass` of them.
    let pass: u64 =
        enc.iter().map(Layer::flop).sum::<u64>() + dec.iter().map(Layer::flop).sum::<u64>();
    g.throughput(Throughput::Elements(3 * pass));
    g.bench_function("encoder_decoder_forward_backward", |b| b.iter(|| run(all)));
    g.throughput(Throughput::Elements(pass));
    // Each operation alone, over the whole stack (where the time goes).
    for (name, ops) in [
        (
            "forward",
            Ops {
                forward: true,
                ..none
            },
        ),
        (
            "backward_input",
            Ops {
                input: true,
                ..none
            },
        ),
        (
            "backward_weight",
            Ops {
                weight: true,
                ..none
            },
        ),
    ] {
        g.bench_function(name, |b| b.iter(|| run(ops)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
