//! Isomap's k nearest neighbours: a sparse index over the lit pixels or a dense blocked
//! search, whichever is cheaper, with sklearn's tie order.

use super::*;

/// Which kNN implementation a fit uses (tests force one or the other).
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum KnnPath {
    Auto,
    Sparse,
    Dense,
}

/// Training images as a kNN index.
pub(super) enum TrainIndex {
    Sparse(SparseIndex),
    Dense { data: Vec<f32>, norms: Vec<f64> },
}

/// Squared Euclidean norm in f64, summed in pixel order (zero pixels add exactly nothing, so
/// this equals the sum over the non-zero pixels only).
pub(super) fn sq_norm(x: &[f32]) -> f64 {
    x.iter().map(|&v| (v as f64) * (v as f64)).sum()
}

/// `max(0, d2)` with -0.0 and NaN mapped to +0.0 (so that `total_cmp` orders ties as equal).
#[inline]
pub(super) fn clamp0(d2: f64) -> f64 {
    if d2 > 0.0 { d2 } else { 0.0 }
}

/// Order of neighbours: squared distance, then index (lower first).
#[inline]
pub(super) fn nbr_cmp(a: &(f64, u32), b: &(f64, u32)) -> Ordering {
    a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
}

/// Relative cost of a scattered sparse multiply-add against a dense GEMM one. Measured on the
/// 2-core development machine (3000 random images x 4900 pixels, k = 5): 2.0 ns against
/// 0.023 ns at 10% density (ratio 87; both paths about 1 s there), 83 at 20%, 114 at 5%.
pub(super) const SPARSE_COST_RATIO: f64 = 80.0;

/// Whether the inverted-index kNN costs less than the dense blocked products: the sparse work
/// of all-pairs dot products is `sum_p c_p^2` (c_p = images lighting pixel p), the dense work
/// `n^2 dim`.
pub(super) fn sparse_is_cheaper(images: &ImageSet) -> bool {
    let mut counts = vec![0u64; images.dim];
    for row in images.data.chunks(images.dim) {
        for (c, &v) in counts.iter_mut().zip(row) {
            *c += (v != 0.0) as u64;
        }
    }
    let sparse: f64 = counts.iter().map(|&c| (c as f64) * (c as f64)).sum();
    let dense = (images.n as f64) * (images.n as f64) * images.dim as f64;
    sparse * SPARSE_COST_RATIO < dense
}

/// Inverted index pixel -> (image, value) of the training images, with their squared norms.
pub(super) struct SparseIndex {
    pub(super) n: usize,
    pub(super) dim: usize,
    pub(super) norms: Vec<f64>,
    /// Image indices sorted by (norm, index): the order of the images that share no pixel with
    /// a query (their squared distance is `|x|^2 + |y|^2`).
    pub(super) by_norm: Vec<u32>,
    pub(super) post_start: Vec<usize>,
    pub(super) post_img: Vec<u32>,
    pub(super) post_val: Vec<f32>,
    /// Non-zero pixels of each training image (CSR), for the all-pairs queries of the fit.
    pub(super) row_start: Vec<usize>,
    pub(super) row_pix: Vec<u32>,
    pub(super) row_val: Vec<f32>,
}

/// Per-thread buffers of a sparse kNN query.
pub(super) struct KnnScratch {
    pub(super) acc: Vec<f64>,
    pub(super) stamp: Vec<u32>,
    pub(super) epoch: u32,
    pub(super) touched: Vec<u32>,
    pub(super) cands: Vec<(f64, u32)>,
}

impl KnnScratch {
    pub(super) fn new(n: usize) -> Self {
        KnnScratch {
            acc: vec![0.0; n],
            stamp: vec![0; n],
            epoch: 0,
            touched: Vec::new(),
            cands: Vec::new(),
        }
    }
}

impl SparseIndex {
    pub(super) fn build(images: &ImageSet, norms: Vec<f64>) -> Self {
        let (n, dim) = (images.n, images.dim);
        let mut counts = vec![0usize; dim + 1];
        let mut row_start = Vec::with_capacity(n + 1);
        let mut row_pix = Vec::new();
        let mut row_val = Vec::new();
        row_start.push(0);
        for row in images.data.chunks(dim) {
            for (p, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    counts[p + 1] += 1;
                    row_pix.push(p as u32);
                    row_val.push(v);
                }
            }
            row_start.push(row_pix.len());
        }
        for p in 0..dim {
            counts[p + 1] += counts[p];
        }
        let post_start = counts.clone();
        let mut fill = counts;
        let nnz = row_pix.len();
        let mut post_img = vec![0u32; nnz];
        let mut post_val = vec![0f32; nnz];
        for i in 0..n {
            let (a, b) = (row_start[i], row_start[i + 1]);
            for (&p, &v) in row_pix[a..b].iter().zip(&row_val[a..b]) {
                let q = fill[p as usize];
                post_img[q] = i as u32;
                post_val[q] = v;
                fill[p as usize] += 1;
            }
        }
        let mut by_norm: Vec<u32> = (0..n as u32).collect();
        by_norm.sort_unstable_by(|&a, &b| {
            norms[a as usize]
                .total_cmp(&norms[b as usize])
                .then(a.cmp(&b))
        });
        SparseIndex {
            n,
            dim,
            norms,
            by_norm,
            post_start,
            post_img,
            post_val,
            row_start,
            row_pix,
            row_val,
        }
    }

    /// All-pairs kNN of the training images (self excluded): n x k (squared distance, index).
    pub(super) fn knn_train(&self, k: usize) -> Vec<(f64, u32)> {
        let mut out = vec![(0.0, 0u32); self.n * k];
        out.par_chunks_mut(k).enumerate().for_each_init(
            || (KnnScratch::new(self.n), Vec::new()),
            |(s, nb), (i, dst)| {
                let (a, b) = (self.row_start[i], self.row_start[i + 1]);
                let vals = self.row_pix[a..b]
                    .iter()
                    .zip(&self.row_val[a..b])
                    .map(|(&p, &v)| (p as usize, v));
                self.knn_sparse_query(vals, self.norms[i], k, Some(i), s, nb);
                dst.copy_from_slice(nb);
            },
        );
        out
    }

    /// kNN of a dense query image `x` (no exclusion unless `exclude`).
    pub(super) fn knn_one(
        &self,
        x: &[f32],
        x_norm: f64,
        k: usize,
        exclude: Option<usize>,
        s: &mut KnnScratch,
        out: &mut Vec<(f64, u32)>,
    ) {
        debug_assert_eq!(x.len(), self.dim);
        let vals = x
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(p, &v)| (p, v));
        self.knn_sparse_query(vals, x_norm, k, exclude, s, out);
    }

    /// Dot products of a query (non-zero pixels in increasing pixel order) with every training
    /// image that shares a pixel with it: afterwards `s.acc[j]` holds the dot product for the
    /// images with `s.stamp[j] == s.epoch` (listed in `s.touched`), the others are 0.
    pub(super) fn dots(&self, pixels: impl Iterator<Item = (usize, f32)>, s: &mut KnnScratch) {
        s.epoch = s.epoch.wrapping_add(1);
        if s.epoch == 0 {
            s.stamp.fill(0);
            s.epoch = 1;
        }
        let ep = s.epoch;
        s.touched.clear();
        for (p, v) in pixels {
            let v = v as f64;
            let (a, b) = (self.post_start[p], self.post_start[p + 1]);
            for (&j, &w) in self.post_img[a..b].iter().zip(&self.post_val[a..b]) {
                let j = j as usize;
                if s.stamp[j] != ep {
                    s.stamp[j] = ep;
                    s.acc[j] = 0.0;
                    s.touched.push(j as u32);
                }
                s.acc[j] += v * w as f64;
            }
        }
    }

    /// The k nearest training images of a query given by its non-zero pixels in increasing
    /// pixel order, sorted by (squared distance, index).
    pub(super) fn knn_sparse_query(
        &self,
        pixels: impl Iterator<Item = (usize, f32)>,
        x_norm: f64,
        k: usize,
        exclude: Option<usize>,
        s: &mut KnnScratch,
        out: &mut Vec<(f64, u32)>,
    ) {
        self.dots(pixels, s);
        let ep = s.epoch;
        let excl = exclude.map_or(u32::MAX, |e| e as u32);
        s.cands.clear();
        for &j in &s.touched {
            if j != excl {
                let d2 = clamp0((x_norm + self.norms[j as usize]) - 2.0 * s.acc[j as usize]);
                s.cands.push((d2, j));
            }
        }
        // Images sharing no pixel with the query: d2 = |x|^2 + |y|^2, non-decreasing along
        // `by_norm`; take the first k and every later one tied with the k-th.
        let mut taken = 0usize;
        let mut kth = f64::INFINITY;
        for &j in &self.by_norm {
            if j == excl || s.stamp[j as usize] == ep {
                continue;
            }
            let d2 = clamp0((x_norm + self.norms[j as usize]) - 2.0 * 0.0);
            if taken >= k && d2 > kth {
                break;
            }
            s.cands.push((d2, j));
            taken += 1;
            if taken == k {
                kth = d2;
            }
        }
        select_k(&mut s.cands, k);
        out.clear();
        out.extend_from_slice(&s.cands);
    }
}

/// Keep the k smallest candidates under `nbr_cmp`, sorted.
pub(super) fn select_k(c: &mut Vec<(f64, u32)>, k: usize) {
    if c.len() > k {
        c.select_nth_unstable_by(k - 1, nbr_cmp);
        c.truncate(k);
    }
    c.sort_unstable_by(nbr_cmp);
}

/// Training chunk (columns) and query block sizes of the dense kNN.
pub(super) const DENSE_TRAIN_CHUNK: usize = 512;
pub(super) const DENSE_QUERY_BLOCK: usize = 64;

/// Dense kNN by blocked Gram products (f64, [`ugl_kernels::matmul`]): for each of the `m` queries, its k nearest
/// of the `n` training rows, sorted by (squared distance, index); `exclude_self` drops training
/// row i from query i's candidates (queries = training set). Memory: one f64 training chunk
/// (dim x 512) and per-thread blocks, never an n x n matrix.
#[allow(clippy::too_many_arguments)]
pub(super) fn dense_knn(
    train: &[f32],
    n: usize,
    dim: usize,
    train_norms: &[f64],
    queries: &[f32],
    m: usize,
    query_norms: &[f64],
    k: usize,
    exclude_self: bool,
) -> Vec<(f64, u32)> {
    let mut best = vec![(f64::INFINITY, u32::MAX); m * k];
    let mut tbuf = vec![0.0f64; dim * DENSE_TRAIN_CHUNK.min(n)];
    for t0 in (0..n).step_by(DENSE_TRAIN_CHUNK) {
        let tn = DENSE_TRAIN_CHUNK.min(n - t0);
        tbuf[..dim * tn]
            .par_chunks_mut(dim)
            .enumerate()
            .for_each(|(c, col)| {
                for (d, &s) in col
                    .iter_mut()
                    .zip(&train[(t0 + c) * dim..(t0 + c + 1) * dim])
                {
                    *d = s as f64;
                }
            });
        let tmat = MatRef::col_major(&tbuf[..dim * tn], dim, tn);
        best.par_chunks_mut(DENSE_QUERY_BLOCK * k)
            .enumerate()
            .for_each_init(
                || {
                    (
                        vec![0.0f64; dim * DENSE_QUERY_BLOCK],
                        vec![0.0f64; DENSE_QUERY_BLOCK * DENSE_TRAIN_CHUNK],
                    )
                },
                |(qbuf, gbuf), (b, slots)| {
                    let q0 = b * DENSE_QUERY_BLOCK;
                    let qn = slots.len() / k;
                    for (d, &s) in qbuf[..dim * qn]
                        .iter_mut()
                        .zip(&queries[q0 * dim..(q0 + qn) * dim])
                    {
                        *d = s as f64;
                    }
                    let qmat = MatRef::col_major(&qbuf[..dim * qn], dim, qn);
                    matmul_cm(&mut gbuf[..qn * tn], qmat.t(), tmat, false);
                    for a in 0..qn {
                        let qi = q0 + a;
                        let top = &mut slots[a * k..(a + 1) * k];
                        for c in 0..tn {
                            let j = t0 + c;
                            if exclude_self && j == qi {
                                continue;
                            }
                            let d2 =
                                clamp0((query_norms[qi] + train_norms[j]) - 2.0 * gbuf[a + c * qn]);
                            insert_top(top, (d2, j as u32));
                        }
                    }
                },
            );
    }
    best
}

/// Insert a candidate into a sorted top-k list (dropping the last) if it beats the last.
#[inline]
pub(super) fn insert_top(top: &mut [(f64, u32)], cand: (f64, u32)) {
    let k = top.len();
    if nbr_cmp(&cand, &top[k - 1]) != Ordering::Less {
        return;
    }
    let mut pos = k - 1;
    while pos > 0 && nbr_cmp(&cand, &top[pos - 1]) == Ordering::Less {
        top[pos] = top[pos - 1];
        pos -= 1;
    }
    top[pos] = cand;
}
