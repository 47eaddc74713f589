//! The host training engine (`engine = "host"`, the default): one training iteration of the
//! paper's dense networks written on the project's deterministic matrix products
//! ([`ugl_kernels::matmul`]), with the structure of the data exploited. Measured against PyTorch: `docs/neural.md`,
//! "Speed, side by side with PyTorch".
//!
//! What differs from the burn engine ([`super::neural::Engine::Burn`]), and why it is faster:
//! - **The input is sparse.** A rendered 70x70 image lights ~1-2% of its pixels, so the first
//!   layer's forward pass `x W1` and its weight gradient `x^T dH1` only touch the rows of `W1`
//!   of lit pixels (exactly: the skipped terms are products with 0). No input gradient is
//!   computed (the images are not trained).
//! - **No copies, no graph for the big layers.** The six dense layers run forward and backward
//!   as matrix products on row-major buffers, with transposes expressed as strides; the workspace
//!   is allocated once. The gradient of the pixel loss is fused with the loss
//!   (`sigmoid(l) - x`, one pass).
//! - **The optimiser runs in place** on the host weights (the same TF update rules,
//!   [`super::nets::adam_update`] / [`super::nets::adagrad_update`]).
//!
//! The small model-specific middle (head outputs -> latent code, and the KL and flow terms:
//! `ae::latent`, `vae::latent`, `rfvae::latent`) still runs on burn's autodiff, on `[B, P]`
//! tensors: its backward gets the host's gradient of the reconstruction with respect to the code
//! through the surrogate `sum(z * dz) + extra`, whose gradient with respect to the heads is the
//! true one.
//!
//! Determinism: every sum runs in a fixed order that depends neither on the thread count nor on
//! the CPU (the products are one FMA chain per output, identical on the scalar, AVX2 and
//! AVX-512 paths; the sparse products and the bias sums run over pixels / batch rows in order,
//! unfused), so the weights after `n` iterations are a function of the stream alone (tested
//! with 1 and 2 threads). They differ from the burn engine's in the
//! last bits (other summation orders); a test checks that both engines compute the same loss and
//! the same update to float precision.

use burn::tensor::{Device, Tensor};
use rayon::prelude::*;
use ugl_kernels::MatRef;

use super::ReprError;
use super::model_file::ModelFileError;
use super::nets::{HostLayer, HostNet, OPT_CHUNK, TfAdagrad, TfAdam, adagrad_update, adam_update};
use super::neural_config::{Model, NeuralConfig};
use super::neural_model::{CodeSettings, Latent, LatentInput, Optimiser, tensor2};
use crate::seed::Stream;

type View<'a> = MatRef<'a, f32>;

/// `out = a b` (or `out += a b` with `accumulate`), `out` row-major `a.rows x b.cols`: one fused
/// multiply-add chain per output in a fixed order, the same bits on every CPU path
/// ([`ugl_kernels::matmul`]).
fn matmul(out: &mut [f32], a: View<'_>, b: View<'_>, accumulate: bool) {
    ugl_kernels::matmul(out, a, b, accumulate);
}

/// `out[r, :] = bias` for every row.
fn fill_bias(out: &mut [f32], bias: &[f32]) {
    for row in out.chunks_exact_mut(bias.len()) {
        row.copy_from_slice(bias);
    }
}

/// `x W + b` of a dense layer on a `rows`-row batch.
pub(super) fn dense_forward(layer: &HostLayer, x: &[f32], rows: usize, out: &mut [f32]) {
    fill_bias(out, &layer.b);
    matmul(
        out,
        View::row_major(x, rows, layer.inp),
        View::row_major(&layer.w, layer.inp, layer.out),
        true,
    );
}

pub(super) fn relu_in_place(v: &mut [f32]) {
    v.iter_mut().for_each(|x| *x = x.max(0.0));
}

/// `grad *= [act > 0]` (the ReLU's derivative, from its output).
pub(super) fn relu_backward(grad: &mut [f32], act: &[f32]) {
    for (g, &a) in grad.iter_mut().zip(act) {
        if a <= 0.0 {
            *g = 0.0;
        }
    }
}

/// Column sums of a row-major `rows x cols` matrix, row by row in order.
pub(super) fn col_sums(m: &[f32], cols: usize, out: &mut [f32]) {
    out.iter_mut().for_each(|v| *v = 0.0);
    for row in m.chunks_exact(cols) {
        for (o, &v) in out.iter_mut().zip(row) {
            *o += v;
        }
    }
}

/// The weight and bias gradients of a dense layer, `dW = x^T dy`, `db = colsum(dy)`, and (if
/// asked) the input gradient `dx = dy W^T`.
pub(super) fn dense_backward(
    layer: &HostLayer,
    x: &[f32],
    dy: &[f32],
    rows: usize,
    dw: &mut [f32],
    db: &mut [f32],
    dx: Option<&mut [f32]>,
) {
    matmul(
        dw,
        View::row_major(x, rows, layer.inp).t(),
        View::row_major(dy, rows, layer.out),
        false,
    );
    col_sums(dy, layer.out, db);
    if let Some(dx) = dx {
        matmul(
            dx,
            View::row_major(dy, rows, layer.out),
            View::row_major(&layer.w, layer.inp, layer.out).t(),
            false,
        );
    }
}

/// A batch of images by pixel (compressed sparse columns): for every lit pixel, the batch rows
/// where it is lit and their values, rows in increasing order.
#[derive(Default)]
struct SparseBatch {
    /// Lit pixels, increasing.
    pixels: Vec<usize>,
    /// `ptr[k]..ptr[k + 1]`: the entries of `pixels[k]`.
    ptr: Vec<usize>,
    rows: Vec<usize>,
    vals: Vec<f32>,
    /// Whether each pixel is lit in the batch.
    lit: Vec<bool>,
}

impl SparseBatch {
    fn fill(&mut self, x: &[f32], rows: usize, dim: usize) {
        // Count per pixel (row-major scan), then place the entries row by row: each pixel's
        // rows come out in increasing order.
        let mut count = vec![0usize; dim + 1];
        for row in x.chunks_exact(dim).take(rows) {
            for (p, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    count[p + 1] += 1;
                }
            }
        }
        for p in 0..dim {
            count[p + 1] += count[p];
        }
        let nnz = count[dim];
        self.rows.clear();
        self.rows.resize(nnz, 0);
        self.vals.clear();
        self.vals.resize(nnz, 0.0);
        let mut next = count.clone();
        for (r, row) in x.chunks_exact(dim).take(rows).enumerate() {
            for (p, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    self.rows[next[p]] = r;
                    self.vals[next[p]] = v;
                    next[p] += 1;
                }
            }
        }
        self.pixels.clear();
        self.ptr.clear();
        self.lit.clear();
        self.lit.resize(dim, false);
        for p in 0..dim {
            if count[p + 1] > count[p] {
                self.pixels.push(p);
                self.ptr.push(count[p]);
                self.lit[p] = true;
            }
        }
        self.ptr.push(nnz);
    }

    fn entries(&self, k: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
        let range = self.ptr[k]..self.ptr[k + 1];
        self.rows[range.clone()]
            .iter()
            .copied()
            .zip(self.vals[range].iter().copied())
    }
}

/// Columns per parallel task of the sparse first layer.
const SPARSE_COL_CHUNK: usize = 128;

/// `out = x W1 + b1` with `x` sparse: each output adds the products of its lit pixels, in
/// increasing pixel order (the order of a dense product; skipped terms are exact zeros).
/// Parallel over column blocks, so the sums do not depend on the thread count.
fn sparse_forward(layer: &HostLayer, xs: &SparseBatch, rows: usize, out: &mut [f32]) {
    let cols = layer.out;
    let blocks: Vec<(usize, Vec<f32>)> = (0..cols.div_ceil(SPARSE_COL_CHUNK))
        .into_par_iter()
        .map(|blk| {
            let c0 = blk * SPARSE_COL_CHUNK;
            let w = SPARSE_COL_CHUNK.min(cols - c0);
            let mut local = vec![0.0f32; rows * w];
            for r in 0..rows {
                local[r * w..(r + 1) * w].copy_from_slice(&layer.b[c0..c0 + w]);
            }
            for (k, &p) in xs.pixels.iter().enumerate() {
                let wrow = &layer.w[p * cols + c0..p * cols + c0 + w];
                for (r, v) in xs.entries(k) {
                    for (o, &wv) in local[r * w..(r + 1) * w].iter_mut().zip(wrow) {
                        *o += v * wv;
                    }
                }
            }
            (c0, local)
        })
        .collect();
    for (c0, local) in blocks {
        let w = local.len() / rows;
        for r in 0..rows {
            out[r * cols + c0..r * cols + c0 + w].copy_from_slice(&local[r * w..(r + 1) * w]);
        }
    }
}

/// `dW1 = x^T dy` with `x` sparse, on the rows of lit pixels only (the others are 0 and left
/// untouched: the optimiser reads them as zeros through `SparseBatch::lit`); batch rows summed
/// in order.
fn sparse_weight_grad(xs: &SparseBatch, dy: &[f32], cols: usize, dw: &mut [f32]) {
    let lit_rows: Vec<(usize, &[usize], &[f32])> = (0..xs.pixels.len())
        .map(|k| {
            let range = xs.ptr[k]..xs.ptr[k + 1];
            (xs.pixels[k], &xs.rows[range.clone()], &xs.vals[range])
        })
        .collect();
    // Disjoint rows of dW: split the matrix at the lit pixels.
    let mut rows_out: Vec<&mut [f32]> = Vec::with_capacity(lit_rows.len());
    let mut rest = dw;
    let mut at = 0;
    for &(p, _, _) in &lit_rows {
        let (_, tail) = rest.split_at_mut((p - at) * cols);
        let (row, tail) = tail.split_at_mut(cols);
        rows_out.push(row);
        rest = tail;
        at = p + 1;
    }
    rows_out
        .into_par_iter()
        .zip(lit_rows.par_iter())
        .for_each(|(out, &(_, rows, vals))| {
            out.iter_mut().for_each(|v| *v = 0.0);
            for (&r, &v) in rows.iter().zip(vals) {
                for (o, &g) in out.iter_mut().zip(&dy[r * cols..(r + 1) * cols]) {
                    *o += v * g;
                }
            }
        });
}

/// The pixel loss and its gradient in one pass: for each row, the Bernoulli cross-entropy of
/// the logits summed over the pixels (`softplus(l) - t l`, accumulated in f64), and
/// `grad = scale (sigmoid(l) - t)`.
pub(super) fn bce_and_grad(
    logits: &[f32],
    x: &[f32],
    dim: usize,
    scale: f32,
    grad: &mut [f32],
) -> Vec<f64> {
    logits
        .par_chunks(dim)
        .zip(x.par_chunks(dim))
        .zip(grad.par_chunks_mut(dim))
        .map(|((l, t), g)| {
            let mut sum = 0.0f64;
            for ((&l, &t), g) in l.iter().zip(t).zip(g.iter_mut()) {
                let e = libm::expf(-l.abs());
                let sig = if l >= 0.0 {
                    1.0 / (1.0 + e)
                } else {
                    e / (1.0 + e)
                };
                sum += f64::from(l.max(0.0) - t * l + libm::log1pf(e));
                *g = scale * (sig - t);
            }
            sum
        })
        .collect()
}

/// The optimiser state of the host engine (TF Adam for the VAE and RFVAE, TF Adagrad for the
/// AE), one buffer per parameter in [`HostNet::layers`] order, weight then bias.
#[derive(Clone, Debug, PartialEq)]
pub enum HostOptimizer {
    Adam {
        rule: TfAdam,
        time: usize,
        m: Vec<Vec<f32>>,
        v: Vec<Vec<f32>>,
    },
    Adagrad {
        rule: TfAdagrad,
        acc: Vec<Vec<f32>>,
    },
}

/// Magic of the host optimiser's state file.
const OPT_MAGIC: &[u8; 8] = b"UGL-OPT1";

impl HostOptimizer {
    /// The original's optimiser of `model`, fresh, for the parameters of `net`.
    pub fn new(model: Model, net: &HostNet) -> HostOptimizer {
        let sizes = param_sizes(net);
        match model.spec().optimiser() {
            Optimiser::Adagrad => {
                let rule = TfAdagrad::default();
                let a0 = rule.initial_accumulator as f32;
                HostOptimizer::Adagrad {
                    acc: sizes.iter().map(|&n| vec![a0; n]).collect(),
                    rule,
                }
            }
            Optimiser::Adam => HostOptimizer::Adam {
                rule: TfAdam::default(),
                time: 0,
                m: sizes.iter().map(|&n| vec![0.0; n]).collect(),
                v: sizes.iter().map(|&n| vec![0.0; n]).collect(),
            },
        }
    }

    /// Fresh Adam state with the update rule `rule`, for parameter buffers of `sizes`.
    pub fn adam(rule: TfAdam, sizes: &[usize]) -> HostOptimizer {
        HostOptimizer::Adam {
            rule,
            time: 0,
            m: sizes.iter().map(|&n| vec![0.0; n]).collect(),
            v: sizes.iter().map(|&n| vec![0.0; n]).collect(),
        }
    }

    /// One update of every parameter buffer in `params` with the gradients `grads` (same order,
    /// every gradient dense). Each element is updated alone, so the result does not depend on the
    /// thread count.
    pub fn step_all(&mut self, lr: f64, params: Vec<&mut [f32]>, grads: &[Vec<f32>]) {
        match self {
            HostOptimizer::Adam { rule, time, m, v } => {
                *time += 1;
                let k = rule.constants(lr, *time);
                for ((p, g), (m, v)) in params.into_iter().zip(grads).zip(m.iter_mut().zip(v)) {
                    par_chunks(p, g, (m, v), |p, g, (m, v)| {
                        adam_update(p, Some(g), m, v, &k)
                    });
                }
            }
            HostOptimizer::Adagrad { rule, acc } => {
                let (lr, clip) = (lr as f32, rule.clip);
                for ((p, g), acc) in params.into_iter().zip(grads).zip(acc.iter_mut()) {
                    p.par_chunks_mut(OPT_CHUNK)
                        .zip(g.par_chunks(OPT_CHUNK))
                        .zip(acc.par_chunks_mut(OPT_CHUNK))
                        .for_each(|((p, g), acc)| adagrad_update(p, g, acc, lr, clip));
                }
            }
        }
    }

    /// The state as bytes: magic, kind (0 Adam, 1 Adagrad), time (u64), then every buffer as a
    /// u64 length and little-endian f32 values.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = OPT_MAGIC.to_vec();
        let (kind, time, bufs): (u8, usize, Vec<&Vec<f32>>) = match self {
            HostOptimizer::Adam { time, m, v, .. } => (0, *time, m.iter().chain(v).collect()),
            HostOptimizer::Adagrad { acc, .. } => (1, 0, acc.iter().collect()),
        };
        out.push(kind);
        out.extend_from_slice(&(time as u64).to_le_bytes());
        for b in bufs {
            out.extend_from_slice(&(b.len() as u64).to_le_bytes());
            for v in b {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        out
    }

    /// Read back a state written by [`HostOptimizer::to_bytes`] for `model` and `net`'s shapes.
    pub fn from_bytes(model: Model, net: &HostNet, bytes: &[u8]) -> Result<Self, ModelFileError> {
        HostOptimizer::new(model, net).read(bytes)
    }

    /// This fresh state (its kind, rule and buffer sizes) with the values of a state written by
    /// [`HostOptimizer::to_bytes`]; `Err` if the bytes hold another kind or other sizes.
    pub fn read(self, bytes: &[u8]) -> Result<Self, ModelFileError> {
        let bad = |why: &str| ModelFileError::Content(why.to_string());
        let mut fresh = self;
        let mut at = 0usize;
        let mut take = |n: usize| -> Result<&[u8], ModelFileError> {
            let s = bytes
                .get(at..at + n)
                .ok_or_else(|| bad("optimiser state truncated"))?;
            at += n;
            Ok(s)
        };
        if take(8)? != OPT_MAGIC {
            return Err(bad("not an optimiser state"));
        }
        let kind = take(1)?[0];
        let time = u64::from_le_bytes(take(8)?.try_into().expect("8 bytes")) as usize;
        let bufs: Vec<&mut Vec<f32>> = match &mut fresh {
            HostOptimizer::Adam { time: t, m, v, .. } if kind == 0 => {
                *t = time;
                m.iter_mut().chain(v.iter_mut()).collect()
            }
            HostOptimizer::Adagrad { acc, .. } if kind == 1 => acc.iter_mut().collect(),
            _ => return Err(bad("optimiser state of another model")),
        };
        for b in bufs {
            let n = u64::from_le_bytes(take(8)?.try_into().expect("8 bytes")) as usize;
            if n != b.len() {
                return Err(bad("optimiser state of another network shape"));
            }
            for (v, c) in b.iter_mut().zip(take(4 * n)?.chunks_exact(4)) {
                *v = f32::from_le_bytes(c.try_into().expect("4 bytes"));
            }
        }
        if at != bytes.len() {
            return Err(bad("trailing bytes after the optimiser state"));
        }
        Ok(fresh)
    }

    /// One update of every parameter of `net` with the gradients `grads` (same order). The
    /// rows of the first weight matrix whose pixel is not `lit` have a zero gradient (not
    /// read).
    fn step(&mut self, lr: f64, net: &mut HostNet, grads: &[Vec<f32>], lit: &[bool]) {
        let first_cols = net.enc1.out;
        let params = params_mut(net);
        match self {
            HostOptimizer::Adam { rule, time, m, v } => {
                *time += 1;
                let k = rule.constants(lr, *time);
                for (i, ((p, g), (m, v))) in params
                    .into_iter()
                    .zip(grads)
                    .zip(m.iter_mut().zip(v.iter_mut()))
                    .enumerate()
                {
                    if i == 0 {
                        by_rows(p, g, first_cols, lit, (m, v), |p, g, (m, v)| {
                            adam_update(p, g, m, v, &k)
                        });
                    } else {
                        par_chunks(p, g, (m, v), |p, g, (m, v)| {
                            adam_update(p, Some(g), m, v, &k)
                        });
                    }
                }
            }
            HostOptimizer::Adagrad { rule, acc } => {
                let (lr, clip) = (lr as f32, rule.clip);
                for (i, ((p, g), acc)) in params
                    .into_iter()
                    .zip(grads)
                    .zip(acc.iter_mut())
                    .enumerate()
                {
                    if i == 0 {
                        // A zero gradient leaves Adagrad's accumulator and parameter unchanged:
                        // unlit rows are skipped.
                        p.par_chunks_mut(first_cols)
                            .zip(g.par_chunks(first_cols))
                            .zip(acc.par_chunks_mut(first_cols))
                            .zip(lit.par_iter())
                            .filter(|(_, lit)| **lit)
                            .for_each(|(((p, g), acc), _)| adagrad_update(p, g, acc, lr, clip));
                    } else {
                        p.par_chunks_mut(OPT_CHUNK)
                            .zip(g.par_chunks(OPT_CHUNK))
                            .zip(acc.par_chunks_mut(OPT_CHUNK))
                            .for_each(|((p, g), acc)| adagrad_update(p, g, acc, lr, clip));
                    }
                }
            }
        }
    }
}

fn par_chunks(
    p: &mut [f32],
    g: &[f32],
    (m, v): (&mut Vec<f32>, &mut Vec<f32>),
    f: impl Fn(&mut [f32], &[f32], (&mut [f32], &mut [f32])) + Sync,
) {
    p.par_chunks_mut(OPT_CHUNK)
        .zip(g.par_chunks(OPT_CHUNK))
        .zip(m.par_chunks_mut(OPT_CHUNK).zip(v.par_chunks_mut(OPT_CHUNK)))
        .for_each(|((p, g), (m, v))| f(p, g, (m, v)));
}

fn by_rows(
    p: &mut [f32],
    g: &[f32],
    cols: usize,
    lit: &[bool],
    (m, v): (&mut Vec<f32>, &mut Vec<f32>),
    f: impl Fn(&mut [f32], Option<&[f32]>, (&mut [f32], &mut [f32])) + Sync,
) {
    p.par_chunks_mut(cols)
        .zip(g.par_chunks(cols))
        .zip(m.par_chunks_mut(cols).zip(v.par_chunks_mut(cols)))
        .zip(lit.par_iter())
        .for_each(|(((p, g), (m, v)), &lit)| f(p, lit.then_some(g), (m, v)));
}

fn param_sizes(net: &HostNet) -> Vec<usize> {
    net.layers()
        .iter()
        .flat_map(|l| [l.w.len(), l.b.len()])
        .collect()
}

fn params_mut(net: &mut HostNet) -> Vec<&mut [f32]> {
    net.layers_mut()
        .into_iter()
        .flat_map(|l| [l.w.as_mut_slice(), l.b.as_mut_slice()])
        .collect()
}

/// Buffers of one iteration, allocated once.
#[derive(Default)]
struct Workspace {
    xs: SparseBatch,
    h1: Vec<f32>,
    h2: Vec<f32>,
    heads: Vec<f32>,
    z: Vec<f32>,
    g1: Vec<f32>,
    g2: Vec<f32>,
    logits: Vec<f32>,
    dlogits: Vec<f32>,
    dg2: Vec<f32>,
    dg1: Vec<f32>,
    dz: Vec<f32>,
    dh2: Vec<f32>,
    dh1: Vec<f32>,
    /// Gradients of the parameters, [`HostNet::layers`] order, weight then bias.
    grads: Vec<Vec<f32>>,
}

pub(super) fn sized(v: &mut Vec<f32>, n: usize) -> &mut Vec<f32> {
    v.resize(n, 0.0);
    v
}

/// The middle of one iteration of a host engine (the dense and the convolutional trainers): the
/// model's code of the encoder's head outputs, on burn's autodiff
/// ([`super::neural_model::NeuralModel::latent`]: one implementation per model).
pub(super) struct Middle {
    heads: Tensor<2>,
    latent: Latent,
    /// The latent code fed to the decoder, `[rows, d]`.
    pub z: Vec<f32>,
}

impl Middle {
    /// The code of the head outputs `heads` (`[rows, P]`) at iteration `step`, with the KL
    /// term's settings `code` of that iteration.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn forward(
        model: Model,
        code: &CodeSettings,
        heads: &[f32],
        rows: usize,
        latents: usize,
        step: usize,
        device: &Device,
        rng: &mut Stream,
    ) -> Result<Middle, ReprError> {
        let width = heads.len() / rows.max(1);
        let heads = tensor2(heads.to_vec(), rows, width, device).require_grad();
        let input = LatentInput {
            batch: rows,
            latents,
            step,
            code: *code,
            device,
        };
        let latent = model.spec().latent(heads.clone(), &input, rng);
        let z = latent
            .z
            .clone()
            .into_data()
            .try_into_vec::<f32>()
            .map_err(|e| ReprError::Numerical(format!("reading the latent code: {e:?}")))?;
        Ok(Middle { heads, latent, z })
    }

    /// How the loss scales the batch's summed reconstruction: `rec_scale / rows`.
    pub(super) fn rec_scale(&self) -> f64 {
        self.latent.rec_scale
    }

    /// The gradient of the head outputs from the decoder's gradient `dz` of the code, through
    /// the surrogate `sum(z * dz) + extra` whose gradient is the true one; and the value of the
    /// model's extra loss terms (the KL and flow terms; 0 for the AE).
    pub(super) fn backward(
        self,
        dz: &[f32],
        device: &Device,
    ) -> Result<(Vec<f32>, f64), ReprError> {
        let [rows, d] = self.latent.z.dims();
        let dz = tensor2(dz.to_vec(), rows, d, device);
        let mut surrogate = (self.latent.z * dz).sum();
        let mut extra_value = 0.0;
        if let Some(extra) = self.latent.extra {
            extra_value = f64::from(extra.clone().into_scalar::<f32>());
            surrogate = surrogate + extra;
        }
        let grads = surrogate.backward();
        let dheads = self
            .heads
            .grad(&grads)
            .ok_or_else(|| ReprError::Numerical("no gradient for the encoder heads".into()))?
            .into_data()
            .try_into_vec::<f32>()
            .map_err(|e| ReprError::Numerical(format!("reading head gradients: {e:?}")))?;
        Ok((dheads, extra_value))
    }
}

/// A training in progress on the host engine: weights, optimiser state, workspace.
pub struct HostTrainer {
    pub net: HostNet,
    pub opt: HostOptimizer,
    ws: Workspace,
    device: Device,
}

impl HostTrainer {
    pub fn new(net: HostNet, opt: HostOptimizer) -> HostTrainer {
        let grads = param_sizes(&net).iter().map(|&n| vec![0.0; n]).collect();
        HostTrainer {
            net,
            opt,
            ws: Workspace {
                grads,
                ..Workspace::default()
            },
            device: Device::flex().autodiff(),
        }
    }

    /// One iteration on the batch `x` (`rows x dim`, row-major): forward, loss, backward and
    /// the optimiser step. `rng` gives the model's noise (drawn exactly as the burn engine
    /// draws it). Returns the mini-batch loss (not yet checked for finiteness).
    pub fn step(
        &mut self,
        model: Model,
        cfg: &NeuralConfig,
        x: &[f32],
        rows: usize,
        step: usize,
        rng: &mut Stream,
    ) -> Result<f64, ReprError> {
        let loss = self.forward_backward(model, cfg, x, rows, step, rng)?;
        self.opt
            .step(cfg.lr, &mut self.net, &self.ws.grads, &self.ws.xs.lit);
        Ok(loss)
    }

    /// The gradients of the last [`HostTrainer::forward_backward`], one dense buffer per
    /// parameter ([`HostNet::layers`] order, weight then bias).
    pub fn gradients(&self) -> Vec<Vec<f32>> {
        let mut g = self.ws.grads.clone();
        let cols = self.net.enc1.out;
        for (row, &lit) in g[0].chunks_exact_mut(cols).zip(&self.ws.xs.lit) {
            if !lit {
                row.iter_mut().for_each(|v| *v = 0.0);
            }
        }
        g
    }

    /// Forward pass, loss and gradients of one batch (kept in the workspace), without the
    /// optimiser step. Returns the mini-batch loss.
    pub fn forward_backward(
        &mut self,
        model: Model,
        cfg: &NeuralConfig,
        x: &[f32],
        rows: usize,
        step: usize,
        rng: &mut Stream,
    ) -> Result<f64, ReprError> {
        let net = &self.net;
        let (dim, [h1, h2], d) = (net.dim, net.hidden, net.latents);
        let p = net.head.out;
        let ws = &mut self.ws;
        // Encoder forward.
        ws.xs.fill(x, rows, dim);
        sparse_forward(&net.enc1, &ws.xs, rows, sized(&mut ws.h1, rows * h1));
        relu_in_place(&mut ws.h1);
        dense_forward(&net.enc2, &ws.h1, rows, sized(&mut ws.h2, rows * h2));
        relu_in_place(&mut ws.h2);
        dense_forward(&net.head, &ws.h2, rows, sized(&mut ws.heads, rows * p));

        // The model's middle on burn's autodiff.
        let middle = Middle::forward(
            model,
            &cfg.code_at(model, step),
            &ws.heads,
            rows,
            d,
            step,
            &self.device,
            rng,
        )?;
        ws.z.clone_from(&middle.z);

        // Decoder forward, the pixel loss and its gradient.
        dense_forward(&net.dec1, &ws.z, rows, sized(&mut ws.g1, rows * h2));
        relu_in_place(&mut ws.g1);
        dense_forward(&net.dec2, &ws.g1, rows, sized(&mut ws.g2, rows * h1));
        relu_in_place(&mut ws.g2);
        dense_forward(
            &net.dec_out,
            &ws.g2,
            rows,
            sized(&mut ws.logits, rows * dim),
        );
        let scale = middle.rec_scale() / rows as f64;
        let per_row = bce_and_grad(
            &ws.logits,
            x,
            dim,
            scale as f32,
            sized(&mut ws.dlogits, rows * dim),
        );
        let rec: f64 = per_row.iter().sum();

        // Decoder backward.
        let [
            gw_e1,
            gb_e1,
            gw_e2,
            gb_e2,
            gw_h,
            gb_h,
            gw_d1,
            gb_d1,
            gw_d2,
            gb_d2,
            gw_o,
            gb_o,
        ] = &mut ws.grads[..]
        else {
            unreachable!("twelve parameters")
        };
        dense_backward(
            &net.dec_out,
            &ws.g2,
            &ws.dlogits,
            rows,
            gw_o,
            gb_o,
            Some(sized(&mut ws.dg2, rows * h1)),
        );
        relu_backward(&mut ws.dg2, &ws.g2);
        dense_backward(
            &net.dec2,
            &ws.g1,
            &ws.dg2,
            rows,
            gw_d2,
            gb_d2,
            Some(sized(&mut ws.dg1, rows * h2)),
        );
        relu_backward(&mut ws.dg1, &ws.g1);
        dense_backward(
            &net.dec1,
            &ws.z,
            &ws.dg1,
            rows,
            gw_d1,
            gb_d1,
            Some(sized(&mut ws.dz, rows * d)),
        );

        let (dheads, extra_value) = middle.backward(&ws.dz, &self.device)?;

        // Encoder backward.
        dense_backward(
            &net.head,
            &ws.h2,
            &dheads,
            rows,
            gw_h,
            gb_h,
            Some(sized(&mut ws.dh2, rows * h2)),
        );
        relu_backward(&mut ws.dh2, &ws.h2);
        dense_backward(
            &net.enc2,
            &ws.h1,
            &ws.dh2,
            rows,
            gw_e2,
            gb_e2,
            Some(sized(&mut ws.dh1, rows * h1)),
        );
        relu_backward(&mut ws.dh1, &ws.h1);
        sparse_weight_grad(&ws.xs, &ws.dh1, h1, gw_e1);
        col_sums(&ws.dh1, h1, gb_e1);
        Ok(scale * rec + extra_value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    fn rand_mat(rows: usize, cols: usize, seed: u64) -> Vec<f32> {
        super::super::neural::normals(&mut stream_named(seed, "mat"), rows * cols)
    }

    fn naive(a: &[f32], b: &[f32], m: usize, k: usize, n: usize) -> Vec<f32> {
        let mut out = vec![0.0f32; m * n];
        for i in 0..m {
            for j in 0..n {
                out[i * n + j] = (0..k).map(|l| a[i * k + l] * b[l * n + j]).sum();
            }
        }
        out
    }

    fn transpose(a: &[f32], rows: usize, cols: usize) -> Vec<f32> {
        let mut t = vec![0.0; a.len()];
        for i in 0..rows {
            for j in 0..cols {
                t[j * rows + i] = a[i * cols + j];
            }
        }
        t
    }

    fn close(a: &[f32], b: &[f32]) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-4 * (1.0 + y.abs()), "{x} vs {y}");
        }
    }

    #[test]
    fn matmul_views_and_transposes() {
        let (m, k, n) = (7, 5, 3);
        let a = rand_mat(m, k, 1);
        let b = rand_mat(k, n, 2);
        let want = naive(&a, &b, m, k, n);
        let mut out = vec![0.0; m * n];
        matmul(
            &mut out,
            View::row_major(&a, m, k),
            View::row_major(&b, k, n),
            false,
        );
        close(&out, &want);
        // Through transposed storage.
        let at = transpose(&a, m, k);
        let bt = transpose(&b, k, n);
        matmul(
            &mut out,
            View::row_major(&at, k, m).t(),
            View::row_major(&bt, n, k).t(),
            false,
        );
        close(&out, &want);
        // Accumulate.
        let mut acc = vec![1.0; m * n];
        matmul(
            &mut acc,
            View::row_major(&a, m, k),
            View::row_major(&b, k, n),
            true,
        );
        close(&acc, &want.iter().map(|v| v + 1.0).collect::<Vec<_>>());
    }

    #[test]
    fn sparse_first_layer_equals_the_dense_product() {
        let (rows, dim, out) = (6, 300, 200);
        let mut x = vec![0.0f32; rows * dim];
        for (i, v) in x.iter_mut().enumerate() {
            if (i * 37) % 23 == 0 {
                *v = 0.25 + (i % 3) as f32 * 0.25;
            }
        }
        let mut layer = HostLayer {
            inp: dim,
            out,
            w: rand_mat(dim, out, 3),
            b: rand_mat(1, out, 4),
        };
        layer.b.truncate(out);
        let mut xs = SparseBatch::default();
        xs.fill(&x, rows, dim);
        let mut got = vec![0.0; rows * out];
        sparse_forward(&layer, &xs, rows, &mut got);
        let mut want = vec![0.0; rows * out];
        dense_forward(&layer, &x, rows, &mut want);
        close(&got, &want);
        // Weight gradient: lit rows as the dense x^T dy, unlit rows untouched.
        let dy = rand_mat(rows, out, 5);
        let mut dw = vec![f32::NAN; dim * out];
        sparse_weight_grad(&xs, &dy, out, &mut dw);
        let dense = naive(&transpose(&x, rows, dim), &dy, dim, rows, out);
        for p in 0..dim {
            let row = &dw[p * out..(p + 1) * out];
            if xs.lit[p] {
                close(row, &dense[p * out..(p + 1) * out]);
            } else {
                assert!(row.iter().all(|v| v.is_nan()));
                assert!(dense[p * out..(p + 1) * out].iter().all(|&v| v == 0.0));
            }
        }
    }

    #[test]
    fn optimiser_state_round_trips_and_rejects_other_shapes() {
        for model in Model::ALL {
            let cfg = NeuralConfig {
                hidden: [6, 5],
                ..NeuralConfig::paper(model)
            };
            let net = super::super::neural::init_net(model, &cfg, 12, 2, &mut stream_named(1, "o"));
            let mut opt = HostOptimizer::new(model, &net);
            if let HostOptimizer::Adam { time, m, .. } = &mut opt {
                *time = 7;
                m[3][1] = 0.5;
            }
            let bytes = opt.to_bytes();
            assert_eq!(HostOptimizer::from_bytes(model, &net, &bytes).unwrap(), opt);
            assert!(HostOptimizer::from_bytes(model, &net, &bytes[..bytes.len() - 1]).is_err());
            let other =
                super::super::neural::init_net(model, &cfg, 13, 2, &mut stream_named(1, "o"));
            assert!(HostOptimizer::from_bytes(model, &other, &bytes).is_err());
        }
    }
}
