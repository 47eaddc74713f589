//! 2-D convolutions and their transposes on the deterministic products ([`crate::matmul`]).
//!
//! Images are `f32`, batch-major and channel-major (`NCHW`): value `(n, c, y, x)` at
//! `((n * C + c) * H + y) * W + x`. A convolution is lowered to a product with the `im2col`
//! matrix, whose rows are ordered `(c, ky, kx)` and whose columns are the output pixels: every
//! output is then one FMA chain over `(c, ky, kx)` in that order, starting from its bias, and
//! the bits depend only on the inputs, whatever the SIMD path and the thread count (the products'
//! contract). The weight gradient is one chain per weight over `(n, output pixel)`, in that
//! order. The input gradient scatters the columns back (`col2im`) in a fixed order, with plain
//! additions.
//!
//! The transposed convolution (the decoders' `ConvTranspose2d`) is the adjoint of a convolution:
//! its forward pass is a convolution's input gradient, its input gradient a convolution's forward
//! pass, and its weight gradient a convolution's weight gradient with the roles of input and
//! output gradient exchanged. The weights keep PyTorch's layouts: `[out, in, k, k]` for a
//! convolution, `[in, out, k, k]` for a transposed one.

use crate::conv_direct;
pub use crate::conv_shape::Conv2d;
use crate::matmul::{MatRef, matmul_on};
use crate::path::{SimdPath, active_path};
use rayon::prelude::*;

/// The output positions `lo..hi` (of `n`) whose input column `o * stride + off` lies inside
/// `0..len`.
fn inside(off: isize, stride: usize, n: usize, len: usize) -> (usize, usize) {
    let st = stride as isize;
    let lo = if off >= 0 { 0 } else { (-off + st - 1) / st };
    let last = len as isize - 1 - off;
    let hi = if last < 0 { 0 } else { last / st + 1 };
    let hi = (hi as usize).min(n);
    let lo = (lo as usize).min(hi);
    (lo, hi)
}

/// The bias gradient `db` (overwritten) of output gradients `dy` (`[image][channel][pixel]`,
/// `pix` pixels, `db.len()` channels): each channel's sum from 0 over `(image, pixel)` in that
/// order, plain additions. Eight channels' sums advance side by side (each its own chain, so
/// the same bits), which hides the additions' latency.
fn bias_gradient(dy: &[f32], pix: usize, db: &mut [f32]) {
    const SIDE: usize = 8;
    let co = db.len();
    for o0 in (0..co).step_by(SIDE) {
        let m = SIDE.min(co - o0);
        let mut s = [0.0f32; SIDE];
        for img in dy.chunks_exact(co * pix) {
            if m == SIDE {
                let rows: [&[f32]; SIDE] = std::array::from_fn(|k| &img[(o0 + k) * pix..][..pix]);
                for p in 0..pix {
                    for k in 0..SIDE {
                        s[k] += rows[k][p];
                    }
                }
            } else {
                for p in 0..pix {
                    for (k, sk) in s[..m].iter_mut().enumerate() {
                        *sk += img[(o0 + k) * pix + p];
                    }
                }
            }
        }
        db[o0..o0 + m].copy_from_slice(&s[..m]);
    }
}

impl Conv2d {
    /// Row `r = (c, ky, kx)` of the `im2col` matrix of one image, `[patch, pixels]`: the input
    /// value under kernel position `r` for every output pixel (0 in the padding).
    fn im2col_row(&self, x: &[f32], r: usize, row: &mut [f32]) {
        let (k, s, p) = (self.kernel, self.stride, self.padding as isize);
        let (oh, ow) = (self.out_height(), self.out_width());
        let (c, ky, kx) = (r / (k * k), r / k % k, r % k);
        let plane = &x[c * self.height * self.width..][..self.height * self.width];
        let dst = &mut row[..oh * ow];
        for oy in 0..oh {
            let y = (oy * s + ky) as isize - p;
            let line = &mut dst[oy * ow..][..ow];
            if y < 0 || y >= self.height as isize {
                line.fill(0.0);
                continue;
            }
            let src = &plane[y as usize * self.width..][..self.width];
            let off = kx as isize - p;
            let (lo, hi) = inside(off, s, ow, self.width);
            line[..lo].fill(0.0);
            line[hi..].fill(0.0);
            if lo < hi {
                let first = ((lo * s) as isize + off) as usize;
                let src = &src[first..];
                let line = &mut line[lo..hi];
                if s == 2 && src.len() >= 2 * line.len() {
                    // The follow-up's stride: every other value, in pairs (vectorised).
                    for (v, pair) in line.iter_mut().zip(src.chunks_exact(2)) {
                        *v = pair[0];
                    }
                } else {
                    for (j, v) in line.iter_mut().enumerate() {
                        *v = src[j * s];
                    }
                }
            }
        }
    }

    /// Columns `segs.start * k .. segs.end * k` of the `im2row` matrix of one image,
    /// `[pixels, patch]`: row `(oy, ox)` holds the input values under the kernel at output pixel
    /// `(oy, ox)`, ordered `(c, ky, kx)` (0 in the padding). A segment is one `(c, ky)`: `k`
    /// consecutive columns. `out` is `[pixels, segs.len() * k]`.
    fn im2row(&self, img: &[f32], segs: std::ops::Range<usize>, out: &mut [f32]) {
        let (k, s, p) = (self.kernel, self.stride, self.padding as isize);
        let (oh, ow) = (self.out_height(), self.out_width());
        let (h, w) = (self.height as isize, self.width as isize);
        let width = segs.len() * k;
        let (c0, ky0) = (segs.start / k, segs.start % k);
        for oy in 0..oh {
            for ox in 0..ow {
                let dst = &mut out[(oy * ow + ox) * width..][..width];
                let x0 = (ox * s) as isize - p;
                let inside = x0 >= 0 && x0 + k as isize <= w;
                // Segment j is (c, ky), counted on from the first without a division.
                let (mut c, mut ky) = (c0, ky0);
                for j in 0..segs.len() {
                    if j > 0 {
                        ky += 1;
                        if ky == k {
                            ky = 0;
                            c += 1;
                        }
                    }
                    let seg = &mut dst[j * k..][..k];
                    let y = (oy * s + ky) as isize - p;
                    if y < 0 || y >= h {
                        seg.fill(0.0);
                        continue;
                    }
                    let line = &img[(c * self.height + y as usize) * self.width..][..self.width];
                    if inside && k == 4 {
                        // The follow-up's kernel: a fixed-size move, not a call to memcpy.
                        let src: [f32; 4] = line[x0 as usize..][..4].try_into().expect("4");
                        let dst: &mut [f32; 4] = seg.try_into().expect("4");
                        *dst = src;
                    } else if inside {
                        seg.copy_from_slice(&line[x0 as usize..][..k]);
                    } else {
                        for (kx, v) in seg.iter_mut().enumerate() {
                            let xx = x0 + kx as isize;
                            *v = if xx < 0 || xx >= w {
                                0.0
                            } else {
                                line[xx as usize]
                            };
                        }
                    }
                }
            }
        }
    }

    /// Add columns `i * pixels ..` of an `im2col`-shaped gradient (`[patch, n * pixels]`) back
    /// into image `i`'s gradient, in the order `(c, ky, kx, oy, ox)`.
    fn col2im_add(&self, cols: &[f32], wide: usize, i: usize, dx: &mut [f32]) {
        let (k, s, p) = (self.kernel, self.stride, self.padding as isize);
        let (oh, ow) = (self.out_height(), self.out_width());
        for c in 0..self.channels_in {
            let plane = &mut dx[c * self.height * self.width..][..self.height * self.width];
            for ky in 0..k {
                for kx in 0..k {
                    let r = (c * k + ky) * k + kx;
                    let src = &cols[r * wide + i * oh * ow..][..oh * ow];
                    for oy in 0..oh {
                        let y = (oy * s + ky) as isize - p;
                        if y < 0 || y >= self.height as isize {
                            continue;
                        }
                        let line = &mut plane[y as usize * self.width..][..self.width];
                        let off = kx as isize - p;
                        let (lo, hi) = inside(off, s, ow, self.width);
                        if lo == hi {
                            continue;
                        }
                        let first = ((lo * s) as isize + off) as usize;
                        let line = &mut line[first..];
                        let src = &src[oy * ow + lo..oy * ow + hi];
                        if s == 2 && line.len() >= 2 * src.len() {
                            for (pair, &g) in line.chunks_exact_mut(2).zip(src) {
                                pair[0] += g;
                            }
                        } else {
                            for (j, &g) in src.iter().enumerate() {
                                line[j * s] += g;
                            }
                        }
                    }
                }
            }
        }
    }

    /// `y = conv(x, w) + b` for a batch of `n` images; `y` is overwritten. Runs on the
    /// process's path ([`active_path`]).
    ///
    /// # Panics
    /// If a slice has the wrong length.
    pub fn forward(&self, n: usize, x: &[f32], w: &[f32], b: Option<&[f32]>, y: &mut [f32]) {
        self.forward_on(active_path(), n, x, w, b, y)
    }

    /// [`Self::forward`] on a given path (the tests compare the paths with it).
    pub fn forward_on(
        &self,
        path: SimdPath,
        n: usize,
        x: &[f32],
        w: &[f32],
        b: Option<&[f32]>,
        y: &mut [f32],
    ) {
        self.check();
        assert_eq!(x.len(), n * self.in_len(), "conv2d: input length");
        assert_eq!(w.len(), self.weight_len(), "conv2d: weight length");
        assert_eq!(y.len(), n * self.out_len(), "conv2d: output length");
        let (patch, pix, co) = (self.patch(), self.pixels_out(), self.channels_out);
        if let Some(b) = b {
            assert_eq!(b.len(), co, "conv2d: bias length");
        }
        if n == 0 {
            return;
        }
        let start = |out: &mut [f32]| match b {
            Some(b) => {
                for (row, bias) in out.chunks_exact_mut(pix).zip(b) {
                    row.fill(*bias);
                }
            }
            None => out.fill(0.0),
        };
        // Image by image, in parallel: every output a chain over (c, ky, kx) from its bias.
        if conv_direct::forward_applies(self, path) {
            // The follow-up's shape on a SIMD path: the same chains without the im2col matrix.
            let packed = conv_direct::pack_forward_weights(self, path, w);
            y.par_chunks_mut(self.out_len())
                .zip(x.par_chunks(self.in_len()))
                .for_each_init(Vec::new, |phases, (out, img)| {
                    start(out);
                    conv_direct::forward_image(self, path, img, &packed, phases, out);
                });
            return;
        }
        let wm = MatRef::row_major(w, co, patch);
        y.par_chunks_mut(self.out_len())
            .zip(x.par_chunks(self.in_len()))
            .for_each_init(
                || vec![0.0f32; patch * pix],
                |cols, (out, img)| {
                    for (r, row) in cols.chunks_exact_mut(pix).enumerate() {
                        self.im2col_row(img, r, row);
                    }
                    start(out);
                    matmul_on(path, out, wm, MatRef::row_major(cols, patch, pix), true);
                },
            );
    }

    /// The input gradient `dx` (overwritten) of a batch, from the output gradient `dy`.
    pub fn backward_input(&self, n: usize, dy: &[f32], w: &[f32], dx: &mut [f32]) {
        self.backward_input_on(active_path(), n, dy, w, dx)
    }

    /// [`Self::backward_input`] on a given path.
    pub fn backward_input_on(
        &self,
        path: SimdPath,
        n: usize,
        dy: &[f32],
        w: &[f32],
        dx: &mut [f32],
    ) {
        self.check();
        assert_eq!(
            dy.len(),
            n * self.out_len(),
            "conv2d: output-gradient length"
        );
        assert_eq!(w.len(), self.weight_len(), "conv2d: weight length");
        assert_eq!(dx.len(), n * self.in_len(), "conv2d: input-gradient length");
        if n == 0 {
            return;
        }
        if conv_direct::input_applies(self, path) {
            // The follow-up's shape on a SIMD path: the same chains and sums without the
            // im2col-shaped matrix and its scatter.
            let packed = conv_direct::pack_input_weights(self, path, w);
            dx.par_chunks_mut(self.in_len())
                .zip(dy.par_chunks(self.out_len()))
                .for_each_init(
                    || (Vec::new(), Vec::new()),
                    |(padded, sums), (d, g)| {
                        conv_direct::input_image(self, path, g, &packed, padded, sums, d);
                    },
                );
            return;
        }
        dx.fill(0.0);
        let (patch, pix, co) = (self.patch(), self.pixels_out(), self.channels_out);
        // Image by image, in parallel: every value a chain over the output channels.
        let wt = MatRef::row_major(w, co, patch).t();
        dx.par_chunks_mut(self.in_len())
            .zip(dy.par_chunks(self.out_len()))
            .for_each_init(
                || vec![0.0f32; patch * pix],
                |cols, (d, g)| {
                    matmul_on(path, cols, wt, MatRef::row_major(g, co, pix), false);
                    self.col2im_add(cols, pix, 0, d);
                },
            );
    }

    /// The weight gradient `dw` (`[out, in, k, k]`) and the bias gradient `db` of a batch
    /// (both overwritten).
    pub fn backward_weight(
        &self,
        n: usize,
        x: &[f32],
        dy: &[f32],
        dw: &mut [f32],
        db: Option<&mut [f32]>,
    ) {
        self.backward_weight_on(active_path(), n, x, dy, dw, db)
    }

    /// [`Self::backward_weight`] on a given path.
    pub fn backward_weight_on(
        &self,
        path: SimdPath,
        n: usize,
        x: &[f32],
        dy: &[f32],
        dw: &mut [f32],
        db: Option<&mut [f32]>,
    ) {
        self.check();
        assert_eq!(x.len(), n * self.in_len(), "conv2d: input length");
        assert_eq!(
            dy.len(),
            n * self.out_len(),
            "conv2d: output-gradient length"
        );
        assert_eq!(
            dw.len(),
            self.weight_len(),
            "conv2d: weight-gradient length"
        );
        let (pix, co) = (self.pixels_out(), self.channels_out);
        if n > 0 && conv_direct::weight_applies(self, path) {
            // The follow-up's shape on a SIMD path: the same chains without the im2row matrices.
            conv_direct::weight_gradient(self, path, n, x, dy, dw);
        } else {
            self.weight_gradient_by_products(path, n, x, dy, dw);
        }
        if let Some(db) = db {
            assert_eq!(db.len(), co, "conv2d: bias-gradient length");
            bias_gradient(dy, pix, db);
        }
    }

    /// The weight gradient by `im2row` products (every shape and path).
    fn weight_gradient_by_products(
        &self,
        path: SimdPath,
        n: usize,
        x: &[f32],
        dy: &[f32],
        dw: &mut [f32],
    ) {
        let (patch, pix, co) = (self.patch(), self.pixels_out(), self.channels_out);
        // Every weight's gradient is one chain over (image, pixel): image after image, each
        // product continuing the chains where the previous one stored them. The threads share
        // the weights, not the images: each takes a block of `(c, ky)` segments (columns of
        // `dw`), builds those columns of every image's `im2row` matrix `[pixels, columns]` and
        // reads it in place in its product. Which thread computes a weight never changes how.
        let k = self.kernel;
        let segs = self.channels_in * k;
        let parts = rayon::current_num_threads().clamp(1, segs);
        let per = segs.div_ceil(parts);
        let blocks: Vec<(usize, Vec<f32>)> = (0..segs)
            .step_by(per)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|s0| {
                let range = s0..(s0 + per).min(segs);
                let cols = range.len() * k;
                let mut local = vec![0.0f32; co * cols];
                let mut rows = vec![0.0f32; pix * cols];
                for i in 0..n {
                    self.im2row(
                        &x[i * self.in_len()..][..self.in_len()],
                        range.clone(),
                        &mut rows,
                    );
                    matmul_on(
                        path,
                        &mut local,
                        MatRef::row_major(&dy[i * self.out_len()..][..self.out_len()], co, pix),
                        MatRef::row_major(&rows, pix, cols),
                        i > 0,
                    );
                }
                (s0 * k, local)
            })
            .collect();
        for (c0, local) in blocks {
            let cols = local.len() / co;
            for (o, row) in local.chunks_exact(cols).enumerate() {
                dw[o * patch + c0..][..cols].copy_from_slice(row);
            }
        }
    }
}

/// A transposed convolution (`ConvTranspose2d`): the adjoint of the convolution [`Self::adjoint`]
/// from its output back to its input. Its input is `channels_in x height x width`; its weight is
/// `[in, out, k, k]` (PyTorch's layout); its output side is
/// `(side - 1) stride - 2 padding + kernel`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConvTranspose2d {
    /// Input channels.
    pub channels_in: usize,
    /// Output channels.
    pub channels_out: usize,
    /// Kernel side.
    pub kernel: usize,
    /// Stride.
    pub stride: usize,
    /// Padding (removed from each side of the full output).
    pub padding: usize,
    /// Input rows.
    pub height: usize,
    /// Input columns.
    pub width: usize,
}

impl ConvTranspose2d {
    /// Output rows.
    ///
    /// # Panics
    /// If a size is 0 or the padding removes the whole output.
    pub fn out_height(&self) -> usize {
        self.out_side(self.height)
    }

    /// Output columns.
    ///
    /// # Panics
    /// As [`Self::out_height`].
    pub fn out_width(&self) -> usize {
        self.out_side(self.width)
    }

    fn out_side(&self, side: usize) -> usize {
        assert!(
            side >= 1
                && self.kernel >= 1
                && self.stride >= 1
                && self.channels_in >= 1
                && self.channels_out >= 1,
            "conv-transpose: channels, sides, kernel and stride must be at least 1: {self:?}"
        );
        ((side - 1) * self.stride + self.kernel)
            .checked_sub(2 * self.padding)
            .filter(|s| *s >= 1)
            .unwrap_or_else(|| panic!("conv-transpose: the padding removes the output: {self:?}"))
    }

    /// Values of one input image.
    pub fn in_len(&self) -> usize {
        self.channels_in * self.height * self.width
    }

    /// Values of one output image.
    pub fn out_len(&self) -> usize {
        self.channels_out * self.out_height() * self.out_width()
    }

    /// Values of the weight, `[in, out, k, k]`.
    pub fn weight_len(&self) -> usize {
        self.channels_in * self.channels_out * self.kernel * self.kernel
    }

    /// Floating-point operations of the forward pass on `n` images (its adjoint's,
    /// [`Conv2d::flops`]); each gradient does as many.
    pub fn flops(&self, n: usize) -> u64 {
        self.adjoint().flops(n)
    }

    /// The convolution whose adjoint this is: from this output's shape to this input's, with the
    /// same weight read as `[out, in, k, k]` of that convolution.
    pub fn adjoint(&self) -> Conv2d {
        let c = Conv2d {
            channels_in: self.channels_out,
            channels_out: self.channels_in,
            kernel: self.kernel,
            stride: self.stride,
            padding: self.padding,
            height: self.out_height(),
            width: self.out_width(),
        };
        assert_eq!(
            (c.out_height(), c.out_width()),
            (self.height, self.width),
            "conv-transpose: no convolution maps {}x{} back to {}x{}",
            c.height,
            c.width,
            self.height,
            self.width
        );
        c
    }

    /// `y = conv_transpose(x, w) + b`; `y` is overwritten.
    pub fn forward(&self, n: usize, x: &[f32], w: &[f32], b: Option<&[f32]>, y: &mut [f32]) {
        let conv = self.adjoint();
        conv.backward_input(n, x, w, y);
        if let Some(b) = b {
            assert_eq!(b.len(), self.channels_out, "conv-transpose: bias length");
            let pix = self.out_height() * self.out_width();
            for img in y.chunks_exact_mut(self.out_len()) {
                for (o, bias) in b.iter().enumerate() {
                    for v in &mut img[o * pix..][..pix] {
                        *v += bias;
                    }
                }
            }
        }
    }

    /// The input gradient `dx` (overwritten) from the output gradient `dy`.
    pub fn backward_input(&self, n: usize, dy: &[f32], w: &[f32], dx: &mut [f32]) {
        self.adjoint().forward(n, dy, w, None, dx);
    }

    /// The weight gradient (`[in, out, k, k]`) and bias gradient (both overwritten).
    pub fn backward_weight(
        &self,
        n: usize,
        x: &[f32],
        dy: &[f32],
        dw: &mut [f32],
        db: Option<&mut [f32]>,
    ) {
        // For y = conv^T(x): dL/dw = the convolution's weight gradient with its input dy and
        // its output gradient x.
        self.adjoint().backward_weight(n, dy, x, dw, None);
        if let Some(db) = db {
            assert_eq!(
                db.len(),
                self.channels_out,
                "conv-transpose: bias-gradient length"
            );
            bias_gradient(dy, self.out_height() * self.out_width(), db);
        }
    }
}
