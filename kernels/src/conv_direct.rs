//! Direct kernels for the follow-up's convolution shape (kernel 4, stride 2, padding 1, even
//! sides) on the SIMD paths: the same fused multiply-add chains as the `im2col` products of
//! [`crate::conv`], in the same order, so the same bits, without building the `im2col` matrix
//! (`kernels/tests/conv.rs` compares both on every path).
//!
//! Forward: output `(o, oy, ox)` is the chain over `(c, ky, kx)` of `w[o, c, ky, kx]` times the
//! input at `(c, 2 oy + ky - 1, 2 ox + kx - 1)` (0 in the padding), from the bias. The input is
//! first split by column parity into a padded layout ([`Phases`]) in which the inputs of
//! consecutive output columns for one `(c, ky, kx)` are consecutive values: one vector load. A
//! tile of `MR` output channels by `NV` vectors of `LANES` output pixels then runs its chains
//! with one broadcast weight per channel and one load per vector, step after step.
//!
//! Input gradient ([`input_image`]): each input pixel is reached by two kernel rows and two
//! kernel columns (by the parities of its row and column); each term is a chain over the output
//! channels from 0, added to the pixel's sum in increasing `(ky, kx)`, and a position past dy's
//! edge is left out, as the `col2im` scatter does. Weight gradient ([`weight_gradient`]): each
//! weight is one chain over `(image, oy, ox)`; a vector holds one input channel's 4 x 4 window
//! (AVX2: two rows of it) under an output pixel, and dy is broadcast.

use crate::conv_shape::Conv2d;
use crate::path::SimdPath;

/// The kernel side, stride and padding the direct kernels are written for.
const KERNEL: usize = 4;
const STRIDE: usize = 2;
const PADDING: usize = 1;

/// A direct kernel's tile: `MR` channels by `NV` vectors of `LANES` values.
#[derive(Clone, Copy)]
struct Tile {
    mr: usize,
    nv: usize,
    lanes: usize,
}

/// The vector widths a path's direct kernels may use, widest first: AVX-512 also runs the
/// 8-lane (AVX2) kernels where a 16-lane vector does not fit an output row (8 pixels wide).
/// Lanes compute what `mul_add` computes at any width, so the width never changes a bit.
fn widths(path: SimdPath) -> &'static [usize] {
    match path {
        SimdPath::Scalar => &[],
        SimdPath::Avx2 => &[8],
        SimdPath::Avx512 if SimdPath::Avx2.available() => &[16, 8],
        SimdPath::Avx512 => &[16],
    }
}

/// Whether the direct kernels are written for this convolution's kernel, stride, padding and
/// sides.
fn direct_shape(conv: &Conv2d) -> bool {
    conv.kernel == KERNEL
        && conv.stride == STRIDE
        && conv.padding == PADDING
        && conv.height.is_multiple_of(2)
        && conv.width.is_multiple_of(2)
}

/// The forward tile of `path` for this convolution (None: the `im2col` product): 4 output
/// channels by 4 vectors of 16 pixels, or by 2 vectors of 8; a vector lies in one output row.
fn forward_tile(conv: &Conv2d, path: SimdPath) -> Option<Tile> {
    let (ow, pix) = (conv.out_width(), conv.out_height() * conv.out_width());
    widths(path)
        .iter()
        .map(|&lanes| Tile {
            mr: 4,
            nv: if lanes == 16 { 4 } else { 2 },
            lanes,
        })
        .find(|t| {
            direct_shape(conv)
                && ow.is_multiple_of(t.lanes)
                && conv.channels_out.is_multiple_of(t.mr)
                && (pix / t.lanes).is_multiple_of(t.nv)
        })
}

/// The padded, parity-split layout of one image: `[c][row + 1][parity][j]` for rows `-1..=H`
/// and `j` in `0..=W/2`, holding the input at `(c, row, 2 j + parity - 1)` (0 outside the
/// image). The input under kernel position `(ky, kx)` for output `(oy, ox)` is at row
/// `2 oy + ky`, parity `kx % 2`, `j = ox + kx / 2` of the padded rows.
struct Phases {
    /// Values of one channel.
    channel: usize,
    /// Values of one padded row (both parities).
    row: usize,
    /// Values of one parity of a row.
    parity: usize,
}

impl Phases {
    fn of(conv: &Conv2d) -> Phases {
        let parity = conv.width / 2 + 1;
        let row = 2 * parity;
        Phases {
            channel: (conv.height + 2) * row,
            row,
            parity,
        }
    }

    /// Writes image `img` (`[c][y][x]`) into `out` (`channels_in * channel` values).
    /// Every value of `out` is written: the image's, and zeros in the padding.
    fn fill(&self, conv: &Conv2d, img: &[f32], out: &mut [f32]) {
        let (h, w) = (conv.height, conv.width);
        for (c, plane) in out.chunks_exact_mut(self.channel).enumerate() {
            plane[..self.row].fill(0.0);
            plane[(h + 1) * self.row..].fill(0.0);
            for y in 0..h {
                let src = &img[(c * h + y) * w..][..w];
                let dst = &mut plane[(y + 1) * self.row..][..self.row];
                let (even, odd) = dst.split_at_mut(self.parity);
                // Input column x is padded column x + 1: odd x to parity 0 at (x + 1) / 2, even
                // x to parity 1 at x / 2; padded columns 0 and w + 1 are zeros.
                even[0] = 0.0;
                odd[self.parity - 1] = 0.0;
                for (j, pair) in src.chunks_exact(2).enumerate() {
                    odd[j] = pair[0];
                    even[j + 1] = pair[1];
                }
            }
        }
    }
}

/// Whether the direct forward kernel of `path` computes this convolution.
pub(crate) fn forward_applies(conv: &Conv2d, path: SimdPath) -> bool {
    forward_tile(conv, path).is_some()
}

/// The weights `[out, in, k, k]` packed for the forward tiles: block `b` of `MR` output
/// channels holds, for every `(c, ky, kx)` in order, the `MR` weights of its channels.
pub(crate) fn pack_forward_weights(conv: &Conv2d, path: SimdPath, w: &[f32]) -> Vec<f32> {
    let t = forward_tile(conv, path).expect("a direct shape");
    let patch = conv.channels_in * KERNEL * KERNEL;
    let mut out = Vec::with_capacity(w.len());
    for o0 in (0..conv.channels_out).step_by(t.mr) {
        for r in 0..patch {
            for i in 0..t.mr {
                out.push(w[(o0 + i) * patch + r]);
            }
        }
    }
    out
}

/// The forward pass of one image: `out` (`[o][oy][ox]`, holding the bias or 0) gets every
/// chain; `phases` is scratch for [`Phases`]. Only where [`forward_applies`].
pub(crate) fn forward_image(
    conv: &Conv2d,
    path: SimdPath,
    img: &[f32],
    packed: &[f32],
    phases: &mut Vec<f32>,
    out: &mut [f32],
) {
    let t = forward_tile(conv, path).expect("a direct shape");
    let layout = Phases::of(conv);
    phases.resize(conv.channels_in * layout.channel, 0.0);
    layout.fill(conv, img, phases);
    let (oh, ow) = (conv.out_height(), conv.out_width());
    let pix = oh * ow;
    let steps = conv.channels_in * KERNEL * KERNEL;
    let vectors = pix / t.lanes;
    for (b, o0) in (0..conv.channels_out).step_by(t.mr).enumerate() {
        let wp = &packed[b * steps * t.mr..][..steps * t.mr];
        for q0 in (0..vectors).step_by(t.nv) {
            // Vector q: output row q * lanes / ow, columns from q * lanes % ow.
            let at = |v: usize| {
                let p = (q0 + v) * t.lanes;
                (p / ow, p % ow)
            };
            let xs: [usize; 4] = std::array::from_fn(|v| {
                let (oy, ox) = at(v.min(t.nv - 1));
                2 * oy * layout.row + ox
            });
            let outs: [usize; 4] = std::array::from_fn(|v| {
                let (oy, ox) = at(v.min(t.nv - 1));
                o0 * pix + oy * ow + ox
            });
            // Every read and write of the tile inside its slice.
            let last_read = (conv.channels_in - 1) * layout.channel
                + (KERNEL - 1) * layout.row
                + layout.parity
                + 1
                + t.lanes;
            assert!(
                wp.len() == steps * t.mr
                    && (0..t.nv).all(|v| xs[v] + last_read <= phases.len())
                    && (0..t.nv).all(|v| outs[v] + (t.mr - 1) * pix + t.lanes <= out.len()),
                "conv2d: a direct tile outside its buffers: {conv:?}"
            );
            let args = ForwardArgs {
                channels: conv.channels_in,
                channel: layout.channel,
                row: layout.row,
                parity: layout.parity,
                pix,
            };
            match t.lanes {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: the CPU runs the width (`widths`); every offset lies inside `phases`,
                // `wp` and `out` (asserted above).
                16 => unsafe { forward_avx512(&args, phases, &xs, wp, out, &outs) },
                #[cfg(target_arch = "x86_64")]
                // SAFETY: as above.
                8 => unsafe { forward_avx2(&args, phases, &xs, wp, out, &outs) },
                _ => unreachable!("no direct kernel of {} lanes", t.lanes),
            }
        }
    }
}

/// The sizes a forward tile walks with.
struct ForwardArgs {
    channels: usize,
    channel: usize,
    row: usize,
    parity: usize,
    pix: usize,
}

#[cfg(target_arch = "x86_64")]
macro_rules! forward_kernel {
    ($name:ident, $feature:literal, $mr:literal, $nv:literal, $lanes:literal,
     $zero:ident, $load:ident, $store:ident, $set1:ident, $fma:ident) => {
        /// One tile of the forward pass: `$mr` output channels by `$nv` vectors.
        ///
        /// # Safety
        /// On a CPU with the target feature; the tile's reads and writes inside the slices.
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            a: &ForwardArgs,
            phases: &[f32],
            xs: &[usize; 4],
            wp: &[f32],
            out: &mut [f32],
            outs: &[usize; 4],
        ) {
            use std::arch::x86_64::*;
            debug_assert_eq!(wp.len(), a.channels * KERNEL * KERNEL * $mr);
            let xp = phases.as_ptr();
            let op = out.as_mut_ptr();
            let mut acc = [[$zero(); $nv]; $mr];
            for i in 0..$mr {
                for v in 0..$nv {
                    // SAFETY: inside the image's output (the caller).
                    acc[i][v] = unsafe { $load(op.add(outs[v] + i * a.pix)) };
                }
            }
            // The four kernel columns: parity kx % 2, shift kx / 2.
            let cols = [0, a.parity, 1, a.parity + 1];
            let mut w = wp.as_ptr();
            for c in 0..a.channels {
                for ky in 0..KERNEL {
                    let base = c * a.channel + ky * a.row;
                    for col in cols {
                        let mut x = [$zero(); $nv];
                        for v in 0..$nv {
                            // SAFETY: inside `phases` (the caller).
                            x[v] = unsafe { $load(xp.add(xs[v] + base + col)) };
                        }
                        for i in 0..$mr {
                            // SAFETY: `wp` holds a weight per channel and step.
                            let wi = $set1(unsafe { *w.add(i) });
                            for v in 0..$nv {
                                acc[i][v] = $fma(wi, x[v], acc[i][v]);
                            }
                        }
                        // SAFETY: the next step's weights (or one past the end).
                        w = unsafe { w.add($mr) };
                    }
                }
            }
            for i in 0..$mr {
                for v in 0..$nv {
                    // SAFETY: as the loads.
                    unsafe { $store(op.add(outs[v] + i * a.pix), acc[i][v]) };
                }
            }
        }
    };
}

#[cfg(target_arch = "x86_64")]
forward_kernel!(
    forward_avx512,
    "avx512f",
    4,
    4,
    16,
    _mm512_setzero_ps,
    _mm512_loadu_ps,
    _mm512_storeu_ps,
    _mm512_set1_ps,
    _mm512_fmadd_ps
);
#[cfg(target_arch = "x86_64")]
forward_kernel!(
    forward_avx2,
    "avx2,fma",
    4,
    2,
    8,
    _mm256_setzero_ps,
    _mm256_loadu_ps,
    _mm256_storeu_ps,
    _mm256_set1_ps,
    _mm256_fmadd_ps
);

/// The input-gradient tile of `path` for this convolution (None: the `im2col` product and
/// its scatter): the largest of 4, 3 and 1 input channels that divides them (the follow-up's
/// RGB decoder layer has 3), by 4 vectors of 16 pixels or 2 of 8; a vector lies in one row.
fn input_tile(conv: &Conv2d, path: SimdPath) -> Option<Tile> {
    let mr = [4, 3, 1]
        .into_iter()
        .find(|m| conv.channels_in.is_multiple_of(*m))
        .expect("1 divides");
    let (ow, pix) = (conv.out_width(), conv.out_height() * conv.out_width());
    widths(path)
        .iter()
        .map(|&lanes| Tile {
            mr,
            nv: if lanes == 16 { 4 } else { 2 },
            lanes,
        })
        .find(|t| {
            direct_shape(conv) && ow.is_multiple_of(t.lanes) && (pix / t.lanes).is_multiple_of(t.nv)
        })
}

/// Whether the direct input-gradient kernel of `path` computes this convolution's input
/// gradient (the transposed convolution's forward pass).
pub(crate) fn input_applies(conv: &Conv2d, path: SimdPath) -> bool {
    input_tile(conv, path).is_some()
}

/// The weights `[out, in, k, k]` packed for the input-gradient tiles: block `b` of `MR` input
/// channels holds, for every `(ky, kx)` and then every output channel `o` in order, the `MR`
/// weights of its channels.
pub(crate) fn pack_input_weights(conv: &Conv2d, path: SimdPath, w: &[f32]) -> Vec<f32> {
    let t = input_tile(conv, path).expect("a direct shape");
    let k2 = KERNEL * KERNEL;
    let mut out = Vec::with_capacity(w.len());
    for c0 in (0..conv.channels_in).step_by(t.mr) {
        for r in 0..k2 {
            for o in 0..conv.channels_out {
                for i in 0..t.mr {
                    out.push(w[(o * conv.channels_in + c0 + i) * k2 + r]);
                }
            }
        }
    }
    out
}

/// The kernel rows (or columns) that reach output row (column) parity `q`, in increasing
/// order: an even output row `2 i` is reached by kernel rows 1 and 3, an odd one by 0 and 2.
fn taps(q: usize) -> [usize; 2] {
    if q == 0 { [1, 3] } else { [0, 2] }
}

/// The input gradient of one image, `dx` (`[c][y][x]`, overwritten), from its output gradient
/// `dy` (`[o][oy][ox]`): for every input value, the terms of the kernel positions that reach
/// it, in increasing `(ky, kx)`, each one chain over the output channels from 0, added from 0
/// (what the im2col product and its `col2im` scatter compute; a position past dy's edge adds
/// nothing). `padded` and `sums` are scratch. Only where [`input_applies`].
pub(crate) fn input_image(
    conv: &Conv2d,
    path: SimdPath,
    dy: &[f32],
    packed: &[f32],
    padded: &mut Vec<f32>,
    sums: &mut Vec<f32>,
    dx: &mut [f32],
) {
    let t = input_tile(conv, path).expect("a direct shape");
    let (oh, ow, co) = (conv.out_height(), conv.out_width(), conv.channels_out);
    let (h, w) = (conv.height, conv.width);
    // The output gradient with a border of zeros: a kernel position past the edge reads 0 and
    // its lanes are left out of the sums.
    let prow = ow + 2;
    let plane = (oh + 2) * prow;
    padded.resize(co * plane, 0.0);
    for (o, pl) in padded.chunks_exact_mut(plane).enumerate() {
        pl[..prow].fill(0.0);
        pl[(oh + 1) * prow..].fill(0.0);
        for oy in 0..oh {
            let row = &mut pl[(oy + 1) * prow..][..prow];
            row[0] = 0.0;
            row[prow - 1] = 0.0;
            row[1..=ow].copy_from_slice(&dy[(o * oh + oy) * ow..][..ow]);
        }
    }
    // The sums by column parity: [c][y][parity][j] for x = 2 j + parity.
    let cstride = h * w;
    sums.clear();
    sums.resize(conv.channels_in * cstride, 0.0);
    let per_row = ow / t.lanes;
    let vectors = oh * per_row;
    for (b, c0) in (0..conv.channels_in).step_by(t.mr).enumerate() {
        for q in 0..2 {
            for p in 0..2 {
                for g0 in (0..vectors).step_by(t.nv) {
                    // Vector g: row pair i = g / per_row (output row 2 i + q), columns
                    // j0 = (g % per_row) * lanes.
                    let at = |v: usize| {
                        let g = g0 + v.min(t.nv - 1);
                        (g / per_row, (g % per_row) * t.lanes)
                    };
                    let sout: [usize; 4] = std::array::from_fn(|v| {
                        let (i, j0) = at(v);
                        c0 * cstride + (2 * i + q) * w + p * ow + j0
                    });
                    for ky in taps(q) {
                        for kx in taps(p) {
                            // dy's padded row and column for this kernel position.
                            let (dr, dc) = ((q + 3 - ky) / 2, (p + 3 - kx) / 2);
                            let dys: [usize; 4] = std::array::from_fn(|v| {
                                let (i, j0) = at(v);
                                (i + dr) * prow + j0 + dc
                            });
                            // The lanes whose kernel position lies inside dy: a position
                            // past its edge is skipped, not added as a zero (with subnormals
                            // flushed, a sum can be -0, which adding +0 would turn to +0).
                            let valid: [u32; 4] = std::array::from_fn(|v| {
                                let (i, j0) = at(v);
                                if i + dr == 0 || i + dr > oh {
                                    return 0;
                                }
                                // Lanes l with 1 <= j0 + l + dc <= ow: a contiguous run.
                                let start = j0 + dc;
                                let lo = 1usize.saturating_sub(start);
                                let hi = (ow + 1 - start).min(t.lanes);
                                ((1u32 << hi) - 1) & !((1u32 << lo) - 1)
                            });
                            let r = ky * KERNEL + kx;
                            let wp = &packed[(b * KERNEL * KERNEL + r) * co * t.mr..][..co * t.mr];
                            assert!(
                                (0..t.nv)
                                    .all(|v| dys[v] + (co - 1) * plane + t.lanes <= padded.len()
                                        && sout[v] + (t.mr - 1) * cstride + t.lanes <= sums.len()),
                                "conv2d: a direct tile outside its buffers: {conv:?}"
                            );
                            let args = InputArgs {
                                chain: co,
                                plane,
                                cstride,
                            };
                            input_tile_call(t, &args, padded, &dys, &valid, wp, sums, &sout);
                        }
                    }
                }
            }
        }
    }
    // Interleave the parities back into rows.
    for (row, out) in sums.chunks_exact(w).zip(dx.chunks_exact_mut(w)) {
        let (even, odd) = row.split_at(ow);
        for (pair, (e, o)) in out.chunks_exact_mut(2).zip(even.iter().zip(odd)) {
            pair[0] = *e;
            pair[1] = *o;
        }
    }
}

/// The sizes an input-gradient tile walks with.
struct InputArgs {
    /// Output channels: the chain's length.
    chain: usize,
    /// Values of one padded output-gradient channel.
    plane: usize,
    /// Values of one channel of the sums.
    cstride: usize,
}

/// One input-gradient term of tile `t`.
#[allow(clippy::too_many_arguments)]
fn input_tile_call(
    t: Tile,
    a: &InputArgs,
    padded: &[f32],
    dys: &[usize; 4],
    valid: &[u32; 4],
    wp: &[f32],
    sums: &mut [f32],
    sout: &[usize; 4],
) {
    // SAFETY (every arm): the CPU runs the width (`widths`) and the tile lies inside the
    // slices (asserted by the caller).
    match (t.lanes, t.mr) {
        #[cfg(target_arch = "x86_64")]
        (16, 4) => unsafe { input_avx512_4(a, padded, dys, valid, wp, sums, sout) },
        #[cfg(target_arch = "x86_64")]
        (16, 3) => unsafe { input_avx512_3(a, padded, dys, valid, wp, sums, sout) },
        #[cfg(target_arch = "x86_64")]
        (16, 1) => unsafe { input_avx512_1(a, padded, dys, valid, wp, sums, sout) },
        #[cfg(target_arch = "x86_64")]
        (8, 4) => unsafe { input_avx2_4(a, padded, dys, valid, wp, sums, sout) },
        #[cfg(target_arch = "x86_64")]
        (8, 3) => unsafe { input_avx2_3(a, padded, dys, valid, wp, sums, sout) },
        #[cfg(target_arch = "x86_64")]
        (8, 1) => unsafe { input_avx2_1(a, padded, dys, valid, wp, sums, sout) },
        (lanes, mr) => unreachable!("no direct kernel of {lanes} lanes and {mr} channels"),
    }
}

#[cfg(target_arch = "x86_64")]
macro_rules! input_kernel {
    ($name:ident, $feature:literal, $mr:literal, $nv:literal, $lanes:literal,
     $zero:ident, $load:ident, $store:ident, $set1:ident, $fma:ident, $add:ident) => {
        /// One term of an input-gradient tile: `$mr` channels by `$nv` vectors, each a chain
        /// over the output channels from 0, then added to its sum in the lanes of `valid`.
        ///
        /// # Safety
        /// On a CPU with the target feature; the tile's reads and writes inside the slices.
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            a: &InputArgs,
            padded: &[f32],
            dys: &[usize; 4],
            valid: &[u32; 4],
            wp: &[f32],
            sums: &mut [f32],
            sout: &[usize; 4],
        ) {
            use std::arch::x86_64::*;
            debug_assert_eq!(wp.len(), a.chain * $mr);
            let dp = padded.as_ptr();
            let sp = sums.as_mut_ptr();
            let mut acc = [[$zero(); $nv]; $mr];
            let mut w = wp.as_ptr();
            for o in 0..a.chain {
                let mut d = [$zero(); $nv];
                for v in 0..$nv {
                    // SAFETY: inside `padded` (the caller).
                    d[v] = unsafe { $load(dp.add(dys[v] + o * a.plane)) };
                }
                for i in 0..$mr {
                    // SAFETY: `wp` holds a weight per channel and chain step.
                    let wi = $set1(unsafe { *w.add(i) });
                    for v in 0..$nv {
                        acc[i][v] = $fma(wi, d[v], acc[i][v]);
                    }
                }
                // SAFETY: the next step's weights (or one past the end).
                w = unsafe { w.add($mr) };
            }
            for i in 0..$mr {
                for v in 0..$nv {
                    // SAFETY: inside `sums` (the caller).
                    unsafe {
                        let s = sp.add(sout[v] + i * a.cstride);
                        $store(s, $add($load(s), acc[i][v], valid[v]));
                    }
                }
            }
        }
    };
}

/// `s + t` in the lanes of `mask`, `s` elsewhere.
///
/// # Safety
/// On a CPU with AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
unsafe fn masked_add_avx512(
    s: std::arch::x86_64::__m512,
    t: std::arch::x86_64::__m512,
    mask: u32,
) -> std::arch::x86_64::__m512 {
    use std::arch::x86_64::*;
    _mm512_mask_add_ps(s, mask as __mmask16, s, t)
}

/// `s + t` in the lanes of `mask`, `s` elsewhere.
///
/// # Safety
/// On a CPU with AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn masked_add_avx2(
    s: std::arch::x86_64::__m256,
    t: std::arch::x86_64::__m256,
    mask: u32,
) -> std::arch::x86_64::__m256 {
    use std::arch::x86_64::*;
    let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let on = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bit), bit);
    _mm256_blendv_ps(s, _mm256_add_ps(s, t), _mm256_castsi256_ps(on))
}

#[cfg(target_arch = "x86_64")]
macro_rules! input_kernels {
    ($feature:literal, $nv:literal, $lanes:literal, $zero:ident, $load:ident, $store:ident,
     $set1:ident, $fma:ident, $add:ident, $($name:ident = $mr:literal),+) => {
        $(input_kernel!($name, $feature, $mr, $nv, $lanes, $zero, $load, $store, $set1, $fma, $add);)+
    };
}

#[cfg(target_arch = "x86_64")]
input_kernels!(
    "avx512f",
    4,
    16,
    _mm512_setzero_ps,
    _mm512_loadu_ps,
    _mm512_storeu_ps,
    _mm512_set1_ps,
    _mm512_fmadd_ps,
    masked_add_avx512,
    input_avx512_4 = 4,
    input_avx512_3 = 3,
    input_avx512_1 = 1
);
#[cfg(target_arch = "x86_64")]
input_kernels!(
    "avx2,fma",
    2,
    8,
    _mm256_setzero_ps,
    _mm256_loadu_ps,
    _mm256_storeu_ps,
    _mm256_set1_ps,
    _mm256_fmadd_ps,
    masked_add_avx2,
    input_avx2_4 = 4,
    input_avx2_3 = 3,
    input_avx2_1 = 1
);

/// The weight-gradient tile of `path` for `channels` input channels: `MR` output channels by
/// `NV` vectors, a vector holding `LANES` of one input channel's 16 kernel positions (AVX-512:
/// all of them; AVX2: two kernel rows). `NV` is the largest of 3, 2 and 1 (AVX-512) or of 2 and
/// 1 (AVX2) that divides the channel's vectors.
fn weight_tile(path: SimdPath, channels: usize) -> Option<Tile> {
    let (mr, lanes, nvs): (usize, usize, &[usize]) = match path {
        SimdPath::Scalar => return None,
        SimdPath::Avx2 => (4, 8, &[2, 1]),
        SimdPath::Avx512 => (8, 16, &[3, 2, 1]),
    };
    let vectors = channels * KERNEL * KERNEL / lanes;
    let nv = *nvs
        .iter()
        .find(|v| vectors.is_multiple_of(**v))
        .expect("1 divides");
    Some(Tile { mr, nv, lanes })
}

/// Whether the direct weight-gradient kernel of `path` computes this convolution's weight
/// gradient.
pub(crate) fn weight_applies(conv: &Conv2d, path: SimdPath) -> bool {
    weight_tile(path, conv.channels_in)
        .is_some_and(|t| direct_shape(conv) && conv.channels_out.is_multiple_of(t.mr))
}

/// The weight gradient `dw` (`[out, in, k, k]`, overwritten) of a batch of `n` images: every
/// weight one chain from 0 over `(image, oy, ox)` in that order of the output gradient times
/// the input under the weight (0 in the padding), what the `im2row` products compute. The
/// threads share the weights (tiles of output channels by kernel-position vectors), never a
/// chain. Only where [`weight_applies`].
pub(crate) fn weight_gradient(
    conv: &Conv2d,
    path: SimdPath,
    n: usize,
    x: &[f32],
    dy: &[f32],
    dw: &mut [f32],
) {
    use rayon::prelude::*;
    let t = weight_tile(path, conv.channels_in).expect("a SIMD path");
    let (h, w, ci, co) = (conv.height, conv.width, conv.channels_in, conv.channels_out);
    let pix = conv.out_height() * conv.out_width();
    // The input with a border of zeros: [image][c][h + 2][w + 2].
    let (prow, pplane) = (w + 2, (h + 2) * (w + 2));
    let mut padded = vec![0.0f32; n * ci * pplane];
    padded
        .par_chunks_mut(ci * pplane)
        .zip(x.par_chunks(ci * h * w))
        .for_each(|(dst, img)| {
            for c in 0..ci {
                for y in 0..h {
                    dst[c * pplane + (y + 1) * prow + 1..][..w]
                        .copy_from_slice(&img[(c * h + y) * w..][..w]);
                }
            }
        });
    let blocks = co / t.mr;
    let per_channel = KERNEL * KERNEL / t.lanes;
    let vectors = ci * per_channel;
    let tiles: Vec<(usize, usize)> = (0..blocks)
        .flat_map(|b| (0..vectors).step_by(t.nv).map(move |u| (b, u)))
        .collect();
    let args = WeightArgs {
        n,
        oh: conv.out_height(),
        ow: conv.out_width(),
        image: ci * pplane,
        prow,
        co,
    };
    let results: Vec<Vec<f32>> = tiles
        .par_iter()
        .map(|&(b, u0)| {
            // Vector u: channel u / per_channel, kernel rows from (u % per_channel) * rows.
            let rows = t.lanes / KERNEL;
            let xs: [usize; 3] = std::array::from_fn(|v| {
                let u = u0 + v.min(t.nv - 1);
                (u / per_channel) * pplane + (u % per_channel) * rows * prow
            });
            // The block's first output channel in dy; the tile reads MR channel rows of every
            // image from there.
            let g0 = b * t.mr * pix;
            assert!(
                (n - 1) * co * pix + g0 + t.mr * pix <= dy.len(),
                "conv2d: a direct tile outside its buffers: {conv:?}"
            );
            let mut out = vec![0.0f32; t.mr * t.nv * t.lanes];
            // The last read of the tile inside `padded`.
            let last = (n - 1) * args.image
                + xs[t.nv - 1]
                + (rows - 1 + 2 * (args.oh - 1)) * prow
                + 2 * (args.ow - 1)
                + KERNEL;
            assert!(
                last <= padded.len(),
                "conv2d: a direct tile outside its buffers: {conv:?}"
            );
            weight_tile_call(path, t.nv, &args, &padded, &xs, &dy[g0..], &mut out);
            out
        })
        .collect();
    // out[i][v][lane] is the weight (o = b MR + i, u = u0 + v, lane): kernel position
    // (u % per_channel) * lanes + lane of channel u / per_channel.
    let k2 = KERNEL * KERNEL;
    for (&(b, u0), out) in tiles.iter().zip(&results) {
        for i in 0..t.mr {
            for v in 0..t.nv {
                let u = u0 + v;
                let (c, first) = (u / per_channel, (u % per_channel) * t.lanes);
                dw[((b * t.mr + i) * ci + c) * k2 + first..][..t.lanes]
                    .copy_from_slice(&out[(i * t.nv + v) * t.lanes..][..t.lanes]);
            }
        }
    }
}

/// The sizes a weight-gradient tile walks with.
struct WeightArgs {
    /// Images.
    n: usize,
    oh: usize,
    ow: usize,
    /// Values of one padded image.
    image: usize,
    /// Values of one padded row.
    prow: usize,
    /// Output channels (dy's channels per image).
    co: usize,
}

/// One weight-gradient tile of `nv` vectors on `path`.
fn weight_tile_call(
    path: SimdPath,
    nv: usize,
    a: &WeightArgs,
    padded: &[f32],
    xs: &[usize; 3],
    dys: &[f32],
    out: &mut [f32],
) {
    // SAFETY (every arm): the CPU runs the path (the caller checked `weight_applies` on the
    // active or a checked path) and the tile lies inside the slices (asserted by the caller).
    match (path, nv) {
        #[cfg(target_arch = "x86_64")]
        (SimdPath::Avx512, 3) => unsafe { weight_avx512_3(a, padded, xs, dys, out) },
        #[cfg(target_arch = "x86_64")]
        (SimdPath::Avx512, 2) => unsafe { weight_avx512_2(a, padded, xs, dys, out) },
        #[cfg(target_arch = "x86_64")]
        (SimdPath::Avx512, 1) => unsafe { weight_avx512_1(a, padded, xs, dys, out) },
        #[cfg(target_arch = "x86_64")]
        (SimdPath::Avx2, 2) => unsafe { weight_avx2_2(a, padded, xs, dys, out) },
        #[cfg(target_arch = "x86_64")]
        (SimdPath::Avx2, 1) => unsafe { weight_avx2_1(a, padded, xs, dys, out) },
        _ => unreachable!("no direct kernel on the {path} path with {nv} vectors"),
    }
}

#[cfg(target_arch = "x86_64")]
macro_rules! weight_kernel {
    ($name:ident, $feature:literal, $mr:literal, $nv:literal, $lanes:literal,
     $zero:ident, $storeu:ident, $set1:ident, $fma:ident, $window:ident) => {
        /// A weight-gradient tile: `$mr` output channels by `$nv` vectors of kernel positions,
        /// each lane one chain over every image's pixels.
        ///
        /// # Safety
        /// On a CPU with the target feature; the tile's reads inside the slices.
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            a: &WeightArgs,
            padded: &[f32],
            xs: &[usize; 3],
            dys: &[f32],
            out: &mut [f32],
        ) {
            use std::arch::x86_64::*;
            let xp = padded.as_ptr();
            let pix = a.oh * a.ow;
            let mut acc = [[$zero(); $nv]; $mr];
            for img in 0..a.n {
                // SAFETY: this image's first channel row of the tile (the caller).
                let mut g = unsafe { dys.as_ptr().add(img * a.co * pix) };
                for oy in 0..a.oh {
                    for ox in 0..a.ow {
                        let at = img * a.image + 2 * oy * a.prow + 2 * ox;
                        let mut win = [$zero(); $nv];
                        for v in 0..$nv {
                            // SAFETY: inside `padded` (the caller).
                            win[v] = unsafe { $window(xp.add(at + xs[v]), a.prow) };
                        }
                        for i in 0..$mr {
                            // SAFETY: channel row i of the tile, this pixel (the caller).
                            let gi = $set1(unsafe { *g.add(i * pix) });
                            for v in 0..$nv {
                                acc[i][v] = $fma(gi, win[v], acc[i][v]);
                            }
                        }
                        // SAFETY: the next pixel (or one past the row's end).
                        g = unsafe { g.add(1) };
                    }
                }
            }
            let op = out.as_mut_ptr();
            for i in 0..$mr {
                for v in 0..$nv {
                    // SAFETY: `out` holds MR x NV vectors.
                    unsafe { $storeu(op.add((i * $nv + v) * $lanes), acc[i][v]) };
                }
            }
        }
    };
}

/// Four rows of four values from `p` (row stride `stride`), as one vector.
///
/// # Safety
/// On a CPU with AVX-512F; the four rows readable.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
unsafe fn window_avx512(p: *const f32, stride: usize) -> std::arch::x86_64::__m512 {
    use std::arch::x86_64::*;
    // SAFETY: the caller's.
    unsafe {
        let v = _mm512_castps128_ps512(_mm_loadu_ps(p));
        let v = _mm512_insertf32x4::<1>(v, _mm_loadu_ps(p.add(stride)));
        let v = _mm512_insertf32x4::<2>(v, _mm_loadu_ps(p.add(2 * stride)));
        _mm512_insertf32x4::<3>(v, _mm_loadu_ps(p.add(3 * stride)))
    }
}

/// Two rows of four values from `p` (row stride `stride`), as one vector.
///
/// # Safety
/// On a CPU with AVX2; the two rows readable.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn window_avx2(p: *const f32, stride: usize) -> std::arch::x86_64::__m256 {
    use std::arch::x86_64::*;
    // SAFETY: the caller's.
    unsafe {
        let v = _mm256_castps128_ps256(_mm_loadu_ps(p));
        _mm256_insertf128_ps::<1>(v, _mm_loadu_ps(p.add(stride)))
    }
}

#[cfg(target_arch = "x86_64")]
macro_rules! weight_kernels {
    ($feature:literal, $mr:literal, $lanes:literal, $zero:ident, $storeu:ident, $set1:ident,
     $fma:ident, $window:ident, $($name:ident = $nv:literal),+) => {
        $(weight_kernel!($name, $feature, $mr, $nv, $lanes, $zero, $storeu, $set1, $fma, $window);)+
    };
}

#[cfg(target_arch = "x86_64")]
weight_kernels!(
    "avx512f",
    8,
    16,
    _mm512_setzero_ps,
    _mm512_storeu_ps,
    _mm512_set1_ps,
    _mm512_fmadd_ps,
    window_avx512,
    weight_avx512_3 = 3,
    weight_avx512_2 = 2,
    weight_avx512_1 = 1
);
#[cfg(target_arch = "x86_64")]
weight_kernels!(
    "avx2,fma",
    4,
    8,
    _mm256_setzero_ps,
    _mm256_storeu_ps,
    _mm256_set1_ps,
    _mm256_fmadd_ps,
    window_avx2,
    weight_avx2_2 = 2,
    weight_avx2_1 = 1
);
