//! Isomap, as the paper's UGL stage uses it (PAPER-NOTES.md section 5, "Isomap"):
//! `sklearn.manifold.Isomap(n_components=d, n_jobs=8)` with all defaults, i.e. **n_neighbors = 5**,
//! Euclidean metric, `path_method='auto'` (Dijkstra) and KernelPCA on the geodesic kernel
//! (`eigen_solver='auto'`). The reproduced sklearn behaviour, step by step:
//!
//! 1. **kNN graph** = `kneighbors_graph(X, n_neighbors, mode='distance')`: for each training image
//!    its `n_neighbors` nearest *other* training images (the sample itself is excluded, duplicates
//!    are not), Euclidean distance computed as `sqrt(max(0, |a|^2 + |b|^2 - 2 a.b))` in f64
//!    (sklearn's `euclidean_distances` formula). Ties are broken by the lower image index
//!    (sklearn's brute force uses an unstable `argpartition`: an unspecified order). Exact ties
//!    are common in rendered images (all pairs of non-overlapping balls are at the same
//!    distance, and identical images at distance 0); distances that are equal mathematically but
//!    rounded differently are ordered by their computed values, deterministically.
//!    The rendered images are sparse (a ball lights 97 of 4900 pixels), so the dot products go
//!    through an inverted index pixel -> images, with a dense fallback (blocked faer products,
//!    chosen when the sparse work `sum_p c_p^2` is not 80x below `n^2 dim`). Both paths give
//!    identical neighbour lists whenever the arithmetic is exact (tested).
//! 2. **Geodesic distances** = `shortest_path(kng, method='D', directed=False)`: the graph is
//!    made undirected (an edge i-j when j is a neighbour of i or i of j; weight the smaller of
//!    the two computed distances) and Dijkstra (CSR adjacency, radix heap over the bits of the
//!    f64 keys) runs from every node in parallel. Nodes joined by exact zero-weight edges
//!    (identical images) are merged first, which changes no distance (adding 0.0 is exact) and
//!    shrinks the all-pairs problem (10,000 ball images sit on ~4,300 distinct pixel positions).
//!    Distances are accumulated in f64 and stored as **f32** (n x n, 400 MB for n = 10,000), then
//!    symmetrised (`min(G_ij, G_ji)`); the kernel is built from the stored f32 values so that fit
//!    and out-of-sample transform see the same geodesics.
//!
//!    **Disconnected graphs**: sklearn < 1.0 (`utils.graph_shortest_path`, the paper's era)
//!    silently set the distance between unreachable points to 0 (scikit-learn issue #14010);
//!    sklearn >= 1.0 joins every pair of components by its closest pair of points (PR #20531).
//!    By default ([`Disconnected::Error`]) we do neither: the fit fails with
//!    [`ReprError::Numerical`] naming the number of components and suggesting more neighbours or
//!    more images. **This happens on the paper's own data**: 10,000 ball images at states uniform
//!    on [-1,1]^2 fall on only 4900 pixel positions, so ~90 positions hold 6 or more identical
//!    images whose 5 neighbours are each other at distance 0; measured, the 5-NN graph of such a
//!    set had 5 components (sizes 9935, 40, 13, 6, 6). [`Disconnected::ConnectClosestPairs`]
//!    reproduces sklearn >= 1.0 instead.
//! 3. **Classical MDS** = `KernelPCA(n_components=d, kernel='precomputed')` on `K = -0.5 G^2`,
//!    centred by `KernelCenterer` (double centring with the column means of K). The top-d
//!    eigenpairs (largest *algebraic* eigenvalues, as ARPACK `which='LA'`) come from a partial
//!    solver: block Krylov (block Lanczos with full reorthogonalisation, Rayleigh-Ritz after
//!    every block, explicit restarts) from a random block drawn from the learner's stream, until
//!    every wanted Ritz pair has residual `|K y - theta y| <= 1e-10 |K|` (each eigenvalue is then
//!    within 1e-10 |K| of an exact one). Small problems (n <= 256) use a full dense decomposition. The
//!    sign of each eigenvector is fixed as sklearn's `svd_flip` (largest-|component| entry
//!    positive, the first such on ties). The training embedding is `alphas * sqrt(lambdas)`
//!    (`fit_transform`). Eigenvalues <= 0 are clamped to 0 as sklearn's
//!    `_check_psd_eigenvalues` does: the corresponding latent is then identically 0.
//! 4. **Out-of-sample** = `Isomap.transform`: the `n_neighbors` nearest training images of the new
//!    image (itself included if it is a training image), `G_x[j] = min_a (d(x, a) + G[a, j])`,
//!    `K_x = -0.5 G_x^2`, centred with the training statistics (`KernelCenterer.transform`: minus
//!    the training column means, minus the row mean of `K_x`, plus the training overall mean),
//!    projected on `alphas / sqrt(lambdas)`. After the kNN this costs O(n d) and allocates
//!    nothing (the encoder keeps its scratch buffers).
//!
//! Checked against scikit-learn 1.9.1 (`Isomap(n_components=2, n_neighbors=5,
//! eigen_solver='dense')`, one-off, outside the test suite): swiss roll (1000 points) embedding
//! and transform within 2e-8 relative; three separated clusters (joined components) within 5e-8;
//! 500 ball images within 2e-8 once sklearn's kNN ties are broken by index as here (with
//! sklearn's own tie order the graphs differ and the embeddings by ~5%).
//!
//! Determinism: every parallel loop writes disjoint outputs computed sequentially, and every
//! matrix product is split into fixed-size blocks run with `Par::Seq`, so a fit is a pure
//! function of (images, latents, n_neighbors, stream) on a given CPU, independent of the
//! number of threads.

use std::cmp::Ordering;

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::SelfAdjointEigen;
use faer::{Accum, MatMut, MatRef, Par, Side};
use rand::RngExt;
use rayon::prelude::*;

use super::{
    Encoder, ImageSet, Latents, ReprError, RepresentationLearner, check_fit_input, check_latents,
};
use crate::seed::Stream;

/// Isomap learner (PAPER-NOTES.md section 5): sklearn `Isomap(n_components=latents)` defaults.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Isomap {
    /// Number of neighbours of the kNN graph (sklearn default 5).
    pub n_neighbors: usize,
    /// What to do with a disconnected kNN graph (default: error).
    pub disconnected: Disconnected,
}

impl Default for Isomap {
    fn default() -> Self {
        Isomap {
            n_neighbors: 5,
            disconnected: Disconnected::Error,
        }
    }
}

impl RepresentationLearner for Isomap {
    fn name(&self) -> &str {
        "isomap"
    }

    fn fit(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        let (enc, z) = self.fit_isomap(images, latents, rng)?;
        Ok((Box::new(enc), z))
    }
}

/// What a fit does when the kNN graph is disconnected (PAPER-NOTES.md section 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Disconnected {
    /// Fail with [`ReprError::Numerical`] naming the number of components (the default).
    #[default]
    Error,
    /// sklearn >= 1.0 (`utils.graph._fix_connected_components`, PR #20531): for every pair of
    /// components, add an edge between their closest pair of points (Euclidean; the first pair
    /// in index order on ties) weighted by its distance, then proceed.
    ConnectClosestPairs,
}

impl Isomap {
    /// Fit and return the concrete encoder (with its eigenvalues and phase timings) and the
    /// training embedding.
    pub fn fit_isomap(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(IsomapEncoder, Latents), ReprError> {
        self.fit_with(images, latents, rng, KnnPath::Auto)
    }

    fn fit_with(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
        path: KnnPath,
    ) -> Result<(IsomapEncoder, Latents), ReprError> {
        check_fit_input(images, latents)?;
        let (n, dim, k) = (images.n, images.dim, self.n_neighbors);
        if k == 0 {
            return Err(ReprError::InvalidInput(
                "isomap: n_neighbors must be at least 1".into(),
            ));
        }
        if k >= n {
            return Err(ReprError::InvalidInput(format!(
                "isomap: n_neighbors = {k} needs at least {} training images, got {n}",
                k + 1
            )));
        }
        if n > u32::MAX as usize - 2 {
            return Err(ReprError::InvalidInput(format!(
                "isomap: too many training images ({n})"
            )));
        }

        let t0 = std::time::Instant::now();
        // 1. kNN graph (training images against themselves, self excluded).
        let norms: Vec<f64> = images.data.par_chunks(dim).map(sq_norm).collect();
        let use_sparse = match path {
            KnnPath::Sparse => true,
            KnnPath::Dense => false,
            KnnPath::Auto => sparse_is_cheaper(images),
        };
        let (index, knn) = if use_sparse {
            let idx = SparseIndex::build(images, norms);
            let knn = idx.knn_train(k);
            (TrainIndex::Sparse(idx), knn)
        } else {
            let knn = dense_knn(
                &images.data,
                n,
                dim,
                &norms,
                &images.data,
                n,
                &norms,
                k,
                true,
            );
            (
                TrainIndex::Dense {
                    data: images.data.clone(),
                    norms,
                },
                knn,
            )
        };
        let mut graph = Csr::from_knn(n, k, &knn);
        let t_knn = t0.elapsed();

        // 2. Geodesic distances.
        let (labels, sizes) = graph.components();
        if sizes.len() > 1 {
            match self.disconnected {
                Disconnected::Error => {
                    let mut sorted = sizes.clone();
                    sorted.sort_unstable_by(|a, b| b.cmp(a));
                    let shown: Vec<String> = sorted.iter().take(6).map(|s| s.to_string()).collect();
                    let more = if sorted.len() > 6 { ", ..." } else { "" };
                    return Err(ReprError::Numerical(format!(
                        "isomap: the {k}-nearest-neighbour graph of the {n} training images has {} connected components \
                         (sizes {}{more}), so geodesic distances between them are infinite; use more neighbours \
                         (n_neighbors > {k}) or more images",
                        sizes.len(),
                        shown.join(", ")
                    )));
                }
                Disconnected::ConnectClosestPairs => {
                    let mut edges = graph.edges();
                    for (a, b, d2) in closest_pairs(&index, images, &labels, sizes.len()) {
                        let w = d2.sqrt();
                        edges.push((a, b, w));
                        edges.push((b, a, w));
                    }
                    graph = Csr::from_edges(n, edges);
                    tracing::debug!(
                        components = sizes.len(),
                        "isomap: joined the components of the kNN graph"
                    );
                }
            }
        }
        drop(knn);
        let mut geo = graph.all_pairs();
        drop(graph);
        symmetrise_min(&mut geo, n);

        let t_geo = t0.elapsed();

        // 3. Classical MDS: double-centred K = -0.5 G^2, top eigenpairs.
        let mut kc: Vec<f64> = vec![0.0; n * n];
        // Column means of K = row means (K is symmetric), summed in index order.
        let col_mean: Vec<f64> = kc
            .par_chunks_mut(n)
            .zip(geo.par_chunks(n))
            .map(|(kr, gr)| {
                let mut sum = 0.0;
                for (kv, &g) in kr.iter_mut().zip(gr) {
                    let g = g as f64;
                    *kv = -0.5 * g * g;
                    sum += *kv;
                }
                sum / n as f64
            })
            .collect();
        let all_mean = col_mean.iter().sum::<f64>() / n as f64;
        if !all_mean.is_finite() {
            return Err(ReprError::Numerical(
                "isomap: non-finite geodesic kernel".into(),
            ));
        }
        kc.par_chunks_mut(n).enumerate().for_each(|(i, row)| {
            let ci = col_mean[i];
            for (v, &cj) in row.iter_mut().zip(&col_mean) {
                *v = *v - (ci + cj) + all_mean;
            }
        });
        let t_kernel = t0.elapsed();
        let (lambdas, mut alphas) = top_eigenpairs(&kc, n, latents, rng)?;
        drop(kc);
        let timings = FitTimings {
            knn: t_knn,
            geodesics: t_geo - t_knn,
            kernel: t_kernel - t_geo,
            eigen: t0.elapsed() - t_kernel,
        };
        tracing::debug!(n, sparse = use_sparse, ?timings, "isomap fit phases");
        flip_signs(&mut alphas, n, latents);

        let mut z = vec![0.0; n * latents];
        let mut proj = vec![0.0; n * latents];
        for c in 0..latents {
            let lam = lambdas[c].max(0.0);
            let (s, inv) = if lam > 0.0 {
                (lam.sqrt(), 1.0 / lam.sqrt())
            } else {
                (0.0, 0.0)
            };
            for i in 0..n {
                let a = alphas[c * n + i];
                z[i * latents + c] = a * s;
                proj[i * latents + c] = a * inv;
            }
        }
        let z = Latents {
            n,
            latents,
            data: z,
        };
        check_latents(&z, "isomap")?;
        let enc = IsomapEncoder {
            n_neighbors: k,
            latents,
            n,
            dim,
            index,
            geodesic: geo,
            col_mean,
            all_mean,
            proj,
            eigenvalues: lambdas,
            timings,
            scratch: Scratch::new(n),
        };
        Ok((enc, z))
    }
}

/// Wall-clock time of the phases of a fit (for measurements).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FitTimings {
    /// kNN graph (index, queries, undirected graph).
    pub knn: std::time::Duration,
    /// Components check, all-pairs Dijkstra, symmetrisation.
    pub geodesics: std::time::Duration,
    /// Kernel `-0.5 G^2` and its double centring.
    pub kernel: std::time::Duration,
    /// Top eigenpairs.
    pub eigen: std::time::Duration,
}

/// The fitted Isomap: training geodesics, centring statistics and projection (sklearn
/// `Isomap.transform`, PAPER-NOTES.md section 5).
pub struct IsomapEncoder {
    n_neighbors: usize,
    latents: usize,
    n: usize,
    dim: usize,
    index: TrainIndex,
    /// Geodesic distances between training images, n x n, symmetric.
    geodesic: Vec<f32>,
    /// Column means of the uncentred training kernel `-0.5 G^2`.
    col_mean: Vec<f64>,
    /// Mean of `col_mean`.
    all_mean: f64,
    /// `alphas / sqrt(lambdas)`, n x latents row-major (0 where lambda <= 0).
    proj: Vec<f64>,
    eigenvalues: Vec<f64>,
    timings: FitTimings,
    scratch: Scratch,
}

impl IsomapEncoder {
    /// The top `latents` eigenvalues of the centred geodesic kernel, in decreasing order
    /// (sklearn `kernel_pca_.eigenvalues_`, before clamping negative ones to 0).
    pub fn eigenvalues(&self) -> &[f64] {
        &self.eigenvalues
    }

    /// Time spent in each phase of the fit.
    pub fn fit_timings(&self) -> FitTimings {
        self.timings
    }

    /// Number of training images.
    pub fn n_train(&self) -> usize {
        self.n
    }

    /// Whether the kNN queries use the sparse inverted index (else dense blocked products).
    pub fn uses_sparse_index(&self) -> bool {
        matches!(self.index, TrainIndex::Sparse(_))
    }

    /// Geodesic distance between training images `i` and `j`.
    pub fn geodesic(&self, i: usize, j: usize) -> f32 {
        self.geodesic[i * self.n + j]
    }

    /// Images to encode must have the training size and finite pixels.
    fn check_images(&self, dim: usize, data: &[f32]) -> Result<(), ReprError> {
        if dim != self.dim {
            return Err(ReprError::InvalidInput(format!(
                "isomap: image has {dim} pixels, the encoder expects {}",
                self.dim
            )));
        }
        if data.iter().any(|v| !v.is_finite()) {
            return Err(ReprError::InvalidInput(
                "isomap: image to encode contains a non-finite value".into(),
            ));
        }
        Ok(())
    }

    /// Geodesic row, centring and projection of one image whose neighbours are `nbrs`
    /// (squared distance, index), sorted. `g` is an n-sized scratch buffer.
    fn project(&self, nbrs: &[(f64, u32)], g: &mut [f64], out: &mut [f64]) {
        let n = self.n;
        let (d2, a) = nbrs[0];
        let d = d2.sqrt();
        let row = &self.geodesic[a as usize * n..(a as usize + 1) * n];
        for (gv, &gr) in g.iter_mut().zip(row) {
            *gv = d + gr as f64;
        }
        for &(d2, a) in &nbrs[1..] {
            let d = d2.sqrt();
            let row = &self.geodesic[a as usize * n..(a as usize + 1) * n];
            for (gv, &gr) in g.iter_mut().zip(row) {
                *gv = gv.min(d + gr as f64);
            }
        }
        let mut sum = 0.0;
        for gv in g.iter_mut() {
            *gv = -0.5 * *gv * *gv;
            sum += *gv;
        }
        let row_mean = sum / n as f64;
        let l = self.latents;
        out.fill(0.0);
        for (j, &kv) in g.iter().enumerate() {
            let kc = kv - (self.col_mean[j] + row_mean) + self.all_mean;
            for (o, &p) in out.iter_mut().zip(&self.proj[j * l..(j + 1) * l]) {
                *o += kc * p;
            }
        }
    }
}

impl Encoder for IsomapEncoder {
    fn latents(&self) -> usize {
        self.latents
    }

    fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        self.check_images(images.dim, &images.data)?;
        let (m, k, l, n) = (images.n, self.n_neighbors, self.latents, self.n);
        let mut z = vec![0.0; m * l];
        if m == 0 {
            return Ok(Latents {
                n: 0,
                latents: l,
                data: z,
            });
        }
        let this = &*self;
        match &this.index {
            TrainIndex::Sparse(idx) => {
                z.par_chunks_mut(l).enumerate().for_each_init(
                    || (KnnScratch::new(n), Vec::new(), vec![0.0; n]),
                    |(ks, nb, g), (i, out)| {
                        let x = images.row(i);
                        idx.knn_one(x, sq_norm(x), k, None, ks, nb);
                        this.project(nb, g, out);
                    },
                );
            }
            TrainIndex::Dense { data, norms } => {
                let qn: Vec<f64> = images.data.par_chunks(images.dim).map(sq_norm).collect();
                let knn = dense_knn(data, n, this.dim, norms, &images.data, m, &qn, k, false);
                z.par_chunks_mut(l)
                    .zip(knn.par_chunks(k))
                    .for_each_init(|| vec![0.0; n], |g, (out, nb)| this.project(nb, g, out));
            }
        }
        let z = Latents {
            n: m,
            latents: l,
            data: z,
        };
        check_latents(&z, "isomap")?;
        Ok(z)
    }

    fn encode_one(&mut self, image: &[f32], out: &mut [f64]) -> Result<(), ReprError> {
        self.check_images(image.len(), image)?;
        if out.len() != self.latents {
            return Err(ReprError::InvalidInput(format!(
                "isomap: output has {} values, expected {}",
                out.len(),
                self.latents
            )));
        }
        let k = self.n_neighbors;
        let mut s = std::mem::replace(&mut self.scratch, Scratch::new(0));
        match &self.index {
            TrainIndex::Sparse(idx) => {
                idx.knn_one(image, sq_norm(image), k, None, &mut s.knn, &mut s.nbrs)
            }
            TrainIndex::Dense { data, norms } => {
                let q = [sq_norm(image)];
                s.nbrs = dense_knn(data, self.n, self.dim, norms, image, 1, &q, k, false);
            }
        }
        self.project(&s.nbrs, &mut s.g, out);
        self.scratch = s;
        if let Some(c) = out.iter().position(|v| !v.is_finite()) {
            return Err(ReprError::Numerical(format!(
                "isomap: non-finite latent (dimension {c})"
            )));
        }
        Ok(())
    }
}

/// Reusable buffers of `encode_one` (O(n), allocated once per encoder).
struct Scratch {
    knn: KnnScratch,
    nbrs: Vec<(f64, u32)>,
    g: Vec<f64>,
}

impl Scratch {
    fn new(n: usize) -> Self {
        Scratch {
            knn: KnnScratch::new(n),
            nbrs: Vec::new(),
            g: vec![0.0; n],
        }
    }
}

// ---------------------------------------------------------------------------------------------
// k nearest neighbours
// ---------------------------------------------------------------------------------------------

/// Which kNN implementation a fit uses (tests force one or the other).
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum KnnPath {
    Auto,
    Sparse,
    Dense,
}

/// Training images as a kNN index.
enum TrainIndex {
    Sparse(SparseIndex),
    Dense { data: Vec<f32>, norms: Vec<f64> },
}

/// Squared Euclidean norm in f64, summed in pixel order (zero pixels add exactly nothing, so
/// this equals the sum over the non-zero pixels only).
fn sq_norm(x: &[f32]) -> f64 {
    x.iter().map(|&v| (v as f64) * (v as f64)).sum()
}

/// `max(0, d2)` with -0.0 and NaN mapped to +0.0 (so that `total_cmp` orders ties as equal).
#[inline]
fn clamp0(d2: f64) -> f64 {
    if d2 > 0.0 { d2 } else { 0.0 }
}

/// Order of neighbours: squared distance, then index (lower first).
#[inline]
fn nbr_cmp(a: &(f64, u32), b: &(f64, u32)) -> Ordering {
    a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
}

/// Relative cost of a scattered sparse multiply-add against a dense GEMM one. Measured on the
/// 2-core development machine (3000 random images x 4900 pixels, k = 5): 2.0 ns against
/// 0.023 ns at 10% density (ratio 87; both paths about 1 s there), 83 at 20%, 114 at 5%.
const SPARSE_COST_RATIO: f64 = 80.0;

/// Whether the inverted-index kNN costs less than the dense blocked products: the sparse work
/// of all-pairs dot products is `sum_p c_p^2` (c_p = images lighting pixel p), the dense work
/// `n^2 dim`.
fn sparse_is_cheaper(images: &ImageSet) -> bool {
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
struct SparseIndex {
    n: usize,
    dim: usize,
    norms: Vec<f64>,
    /// Image indices sorted by (norm, index): the order of the images that share no pixel with
    /// a query (their squared distance is `|x|^2 + |y|^2`).
    by_norm: Vec<u32>,
    post_start: Vec<usize>,
    post_img: Vec<u32>,
    post_val: Vec<f32>,
    /// Non-zero pixels of each training image (CSR), for the all-pairs queries of the fit.
    row_start: Vec<usize>,
    row_pix: Vec<u32>,
    row_val: Vec<f32>,
}

/// Per-thread buffers of a sparse kNN query.
struct KnnScratch {
    acc: Vec<f64>,
    stamp: Vec<u32>,
    epoch: u32,
    touched: Vec<u32>,
    cands: Vec<(f64, u32)>,
}

impl KnnScratch {
    fn new(n: usize) -> Self {
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
    fn build(images: &ImageSet, norms: Vec<f64>) -> Self {
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
    fn knn_train(&self, k: usize) -> Vec<(f64, u32)> {
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
    fn knn_one(
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
    fn dots(&self, pixels: impl Iterator<Item = (usize, f32)>, s: &mut KnnScratch) {
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
    fn knn_sparse_query(
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
fn select_k(c: &mut Vec<(f64, u32)>, k: usize) {
    if c.len() > k {
        c.select_nth_unstable_by(k - 1, nbr_cmp);
        c.truncate(k);
    }
    c.sort_unstable_by(nbr_cmp);
}

/// Training chunk (columns) and query block sizes of the dense kNN.
const DENSE_TRAIN_CHUNK: usize = 512;
const DENSE_QUERY_BLOCK: usize = 64;

/// Dense kNN by blocked Gram products (faer, f64): for each of the `m` queries, its k nearest
/// of the `n` training rows, sorted by (squared distance, index); `exclude_self` drops training
/// row i from query i's candidates (queries = training set). Memory: one f64 training chunk
/// (dim x 512) and per-thread blocks, never an n x n matrix.
#[allow(clippy::too_many_arguments)]
fn dense_knn(
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
        let tmat = MatRef::from_column_major_slice(&tbuf[..dim * tn], dim, tn);
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
                    let qmat = MatRef::from_column_major_slice(&qbuf[..dim * qn], dim, qn);
                    let gram = MatMut::from_column_major_slice_mut(&mut gbuf[..qn * tn], qn, tn);
                    matmul(gram, Accum::Replace, qmat.transpose(), tmat, 1.0, Par::Seq);
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
fn insert_top(top: &mut [(f64, u32)], cand: (f64, u32)) {
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

// ---------------------------------------------------------------------------------------------
// Graph and geodesics
// ---------------------------------------------------------------------------------------------

/// sklearn >= 1.0 `_fix_connected_components`: for every pair of components (ci > cj), the
/// closest pair (a in ci, b in cj) as (a, b, squared distance); ties go to the first pair in
/// (a, b) index order, like `argmin` over the row-major distance block. Work: every point of a
/// component against every point of the components before it.
fn closest_pairs(
    index: &TrainIndex,
    images: &ImageSet,
    labels: &[u32],
    ncomp: usize,
) -> Vec<(u32, u32, f64)> {
    let n = images.n;
    // For each point a, the closest point of each earlier component (squared distance, b).
    let per_point: Vec<Vec<(f64, u32)>> = (0..n)
        .into_par_iter()
        .map_init(
            || (KnnScratch::new(n), vec![0.0f64; n]),
            |(s, d2), a| {
                let ca = labels[a] as usize;
                if ca == 0 {
                    return Vec::new();
                }
                distances_to_all(index, images, a, s, d2);
                let mut best = vec![(f64::INFINITY, u32::MAX); ca];
                for (b, &v) in d2.iter().enumerate() {
                    let cb = labels[b] as usize;
                    if cb < ca && v < best[cb].0 {
                        best[cb] = (v, b as u32);
                    }
                }
                best
            },
        )
        .collect();
    let mut best = vec![(f64::INFINITY, u32::MAX, u32::MAX); ncomp * ncomp];
    for (a, row) in per_point.iter().enumerate() {
        let ca = labels[a] as usize;
        for (cb, &(v, b)) in row.iter().enumerate() {
            // Points a come in increasing order: strict < keeps the first a on ties.
            if v < best[ca * ncomp + cb].0 {
                best[ca * ncomp + cb] = (v, a as u32, b);
            }
        }
    }
    let mut out = Vec::new();
    for ci in 0..ncomp {
        for cj in 0..ci {
            let (v, a, b) = best[ci * ncomp + cj];
            out.push((a, b, v));
        }
    }
    out
}

/// Squared distances from training image `a` to every training image.
fn distances_to_all(
    index: &TrainIndex,
    images: &ImageSet,
    a: usize,
    s: &mut KnnScratch,
    d2: &mut [f64],
) {
    match index {
        TrainIndex::Sparse(idx) => {
            let x = images.row(a);
            let xn = idx.norms[a];
            idx.dots(
                x.iter()
                    .enumerate()
                    .filter(|(_, v)| **v != 0.0)
                    .map(|(p, &v)| (p, v)),
                s,
            );
            for (b, o) in d2.iter_mut().enumerate() {
                let dot = if s.stamp[b] == s.epoch { s.acc[b] } else { 0.0 };
                *o = clamp0((xn + idx.norms[b]) - 2.0 * dot);
            }
        }
        TrainIndex::Dense { data, norms } => {
            let dim = images.dim;
            let x = &data[a * dim..(a + 1) * dim];
            for (b, o) in d2.iter_mut().enumerate() {
                let y = &data[b * dim..(b + 1) * dim];
                let dot: f64 = x.iter().zip(y).map(|(&p, &q)| p as f64 * q as f64).sum();
                *o = clamp0((norms[a] + norms[b]) - 2.0 * dot);
            }
        }
    }
}

/// Undirected weighted graph in CSR form.
struct Csr {
    n: usize,
    start: Vec<usize>,
    adj: Vec<u32>,
    w: Vec<f64>,
}

impl Csr {
    /// The undirected kNN graph (scipy `shortest_path(directed=False)` on sklearn's
    /// `kneighbors_graph(mode='distance')`): edge i-j when j is among i's neighbours or i among
    /// j's, weight the smaller of the two distances.
    fn from_knn(n: usize, k: usize, knn: &[(f64, u32)]) -> Self {
        let mut edges: Vec<(u32, u32, f64)> = Vec::with_capacity(2 * n * k);
        for (i, nb) in knn.chunks(k).enumerate() {
            for &(d2, j) in nb {
                let w = d2.sqrt();
                edges.push((i as u32, j, w));
                edges.push((j, i as u32, w));
            }
        }
        Self::from_edges(n, edges)
    }

    /// From directed edge triples (both directions must be present for an undirected graph);
    /// parallel edges keep the smallest weight.
    fn from_edges(n: usize, mut edges: Vec<(u32, u32, f64)>) -> Self {
        edges.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.total_cmp(&b.2)));
        edges.dedup_by(|later, first| later.0 == first.0 && later.1 == first.1);
        let mut start = vec![0usize; n + 1];
        for e in &edges {
            start[e.0 as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let adj = edges.iter().map(|e| e.1).collect();
        let w = edges.iter().map(|e| e.2).collect();
        Csr { n, start, adj, w }
    }

    /// Component label of every node (components numbered in order of their smallest node, as
    /// scipy's `connected_components`) and the component sizes.
    fn components(&self) -> (Vec<u32>, Vec<usize>) {
        let mut label = vec![u32::MAX; self.n];
        let mut sizes = Vec::new();
        let mut stack = Vec::new();
        for s in 0..self.n {
            if label[s] != u32::MAX {
                continue;
            }
            let c = sizes.len() as u32;
            label[s] = c;
            stack.push(s as u32);
            let mut size = 0;
            while let Some(u) = stack.pop() {
                size += 1;
                for &v in &self.adj[self.start[u as usize]..self.start[u as usize + 1]] {
                    if label[v as usize] == u32::MAX {
                        label[v as usize] = c;
                        stack.push(v);
                    }
                }
            }
            sizes.push(size);
        }
        (label, sizes)
    }

    /// The directed edge triples (each undirected edge twice).
    fn edges(&self) -> Vec<(u32, u32, f64)> {
        let mut e = Vec::with_capacity(self.adj.len());
        for i in 0..self.n {
            for q in self.start[i]..self.start[i + 1] {
                e.push((i as u32, self.adj[q], self.w[q]));
            }
        }
        e
    }

    /// Geodesic distances from every node, n x n row-major, accumulated in f64 and stored as
    /// f32. Nodes joined by exact zero-weight edges (identical images) are first merged: their
    /// distances to everything are equal (adding 0.0 is exact), so Dijkstra runs once per
    /// merged node on the merged graph (for 10,000 ball images at 4900 pixel positions, about
    /// 4,300 nodes: a 5x smaller all-pairs problem), and the rows are then expanded.
    fn all_pairs(&self) -> Vec<f32> {
        let n = self.n;
        let (class, m) = self.zero_classes();
        let mut out = vec![0.0f32; n * n];
        if m == n {
            out.par_chunks_mut(n).enumerate().for_each_init(
                || (vec![0.0f64; n], vec![false; n], RadixHeap::new()),
                |(dist, done, heap), (s, row)| {
                    self.dijkstra(s, dist, done, heap);
                    for (o, &d) in row.iter_mut().zip(dist.iter()) {
                        *o = d as f32;
                    }
                },
            );
            return out;
        }
        let mut edges: Vec<(u32, u32, f64)> = Vec::with_capacity(self.adj.len());
        for i in 0..n {
            for q in self.start[i]..self.start[i + 1] {
                let (a, b) = (class[i], class[self.adj[q] as usize]);
                if a != b {
                    edges.push((a, b, self.w[q]));
                }
            }
        }
        let merged = Csr::from_edges(m, edges);
        let mut small = vec![0.0f32; m * m];
        small.par_chunks_mut(m).enumerate().for_each_init(
            || (vec![0.0f64; m], vec![false; m], RadixHeap::new()),
            |(dist, done, heap), (s, row)| {
                merged.dijkstra(s, dist, done, heap);
                for (o, &d) in row.iter_mut().zip(dist.iter()) {
                    *o = d as f32;
                }
            },
        );
        out.par_chunks_mut(n).enumerate().for_each(|(i, row)| {
            let src = &small[class[i] as usize * m..(class[i] as usize + 1) * m];
            for (o, &c) in row.iter_mut().zip(&class) {
                *o = src[c as usize];
            }
        });
        out
    }

    /// Classes of nodes joined by exact zero-weight edges: (class of each node, numbered in
    /// order of first node; number of classes).
    fn zero_classes(&self) -> (Vec<u32>, usize) {
        let n = self.n;
        let mut class = vec![u32::MAX; n];
        let mut m = 0u32;
        let mut stack = Vec::new();
        for s in 0..n {
            if class[s] != u32::MAX {
                continue;
            }
            class[s] = m;
            stack.push(s);
            while let Some(u) = stack.pop() {
                for q in self.start[u]..self.start[u + 1] {
                    let v = self.adj[q] as usize;
                    if self.w[q] == 0.0 && class[v] == u32::MAX {
                        class[v] = m;
                        stack.push(v);
                    }
                }
            }
            m += 1;
        }
        (class, m as usize)
    }

    /// Single-source shortest paths into `dist` (infinite where unreachable), radix heap with
    /// lazy deletion.
    fn dijkstra(&self, s: usize, dist: &mut [f64], done: &mut [bool], heap: &mut RadixHeap) {
        dist.fill(f64::INFINITY);
        done.fill(false);
        heap.reset();
        dist[s] = 0.0;
        heap.push(0.0, s as u32);
        while let Some((d, u)) = heap.pop() {
            if done[u as usize] || d > dist[u as usize] {
                continue;
            }
            done[u as usize] = true;
            let (a, b) = (self.start[u as usize], self.start[u as usize + 1]);
            for (&v, &w) in self.adj[a..b].iter().zip(&self.w[a..b]) {
                let nd = d + w;
                if nd < dist[v as usize] {
                    dist[v as usize] = nd;
                    heap.push(nd, v);
                }
            }
        }
    }
}

/// Radix heap (monotone priority queue) over the bits of non-negative f64 keys, with lazy
/// deletion: Dijkstra pops keys in non-decreasing order, which is all a radix heap needs.
struct RadixHeap {
    buckets: Vec<Vec<(u64, u32)>>,
    last: u64,
    len: usize,
}

impl RadixHeap {
    fn new() -> Self {
        RadixHeap {
            buckets: (0..65).map(|_| Vec::new()).collect(),
            last: 0,
            len: 0,
        }
    }

    fn reset(&mut self) {
        for b in &mut self.buckets {
            b.clear();
        }
        self.last = 0;
        self.len = 0;
    }

    #[inline]
    fn bucket(&self, key: u64) -> usize {
        (64 - (key ^ self.last).leading_zeros()) as usize
    }

    #[inline]
    fn push(&mut self, key: f64, v: u32) {
        let k = key.to_bits();
        debug_assert!(k >= self.last);
        let b = self.bucket(k);
        self.buckets[b].push((k, v));
        self.len += 1;
    }

    #[inline]
    fn pop(&mut self) -> Option<(f64, u32)> {
        if self.len == 0 {
            return None;
        }
        if self.buckets[0].is_empty() {
            let i = (1..65)
                .find(|&i| !self.buckets[i].is_empty())
                .expect("non-empty");
            let mut moved = std::mem::take(&mut self.buckets[i]);
            self.last = moved.iter().map(|e| e.0).min().expect("non-empty");
            for &e in &moved {
                let b = self.bucket(e.0);
                self.buckets[b].push(e);
            }
            moved.clear();
            self.buckets[i] = moved;
        }
        self.len -= 1;
        self.buckets[0].pop().map(|(k, v)| (f64::from_bits(k), v))
    }
}

/// `G_ij = G_ji = min(G_ij, G_ji)` (the two Dijkstra runs may differ in the last bit), tiled.
fn symmetrise_min(g: &mut [f32], n: usize) {
    const T: usize = 64;
    for bi in (0..n).step_by(T) {
        for bj in (bi..n).step_by(T) {
            for i in bi..(bi + T).min(n) {
                for j in bj.max(i + 1)..(bj + T).min(n) {
                    let m = g[i * n + j].min(g[j * n + i]);
                    g[i * n + j] = m;
                    g[j * n + i] = m;
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Top eigenpairs of a symmetric matrix
// ---------------------------------------------------------------------------------------------

/// Below this size the eigenpairs come from a full dense decomposition.
const DENSE_EIGEN_MAX: usize = 256;
/// Residual tolerance of the Ritz pairs, relative to the spectral norm estimate.
const EIGEN_TOL: f64 = 1e-10;
/// Most Krylov blocks per restart cycle (convergence is checked after every block).
const KRYLOV_STEPS: usize = 16;
/// Maximum restart cycles.
const MAX_CYCLES: usize = 200;
/// Rows per block of the parallel symmetric product.
const MUL_ROWS: usize = 256;

/// The `d` largest (algebraic) eigenvalues of the symmetric n x n matrix `a` (column-major; by
/// symmetry also row-major), decreasing, with orthonormal eigenvectors (n x d column-major).
fn top_eigenpairs(
    a: &[f64],
    n: usize,
    d: usize,
    rng: &mut Stream,
) -> Result<(Vec<f64>, Vec<f64>), ReprError> {
    if n <= DENSE_EIGEN_MAX {
        return dense_top_eigenpairs(a, n, d);
    }
    let b = (d + d.max(8)).min(n);
    let cap = (b * KRYLOV_STEPS).min(n);
    let mut q = vec![0.0f64; n * cap];
    let mut aq = vec![0.0f64; n * cap];
    let mut x: Vec<f64> = (0..n * b).map(|_| rng.random_range(-1.0..1.0)).collect();
    let mut xcols = b;
    for _cycle in 0..MAX_CYCLES {
        // Grow the block Krylov basis Q (orthonormal) and AQ = A Q one block at a time, with a
        // Rayleigh-Ritz convergence check after every block from the second on.
        let mut m = 0;
        let mut steps = 0;
        let rr = loop {
            let kept = orthonormalise_into(&mut q, n, m, &mut x, xcols, cap - m);
            if kept > 0 {
                sym_mul(
                    a,
                    n,
                    &q[m * n..(m + kept) * n],
                    kept,
                    &mut aq[m * n..(m + kept) * n],
                );
                x.clear();
                x.extend_from_slice(&aq[m * n..(m + kept) * n]);
                xcols = kept;
                m += kept;
                steps += 1;
            }
            let exhausted = kept == 0 || m >= cap;
            if m > 0 && (exhausted || steps >= 2) {
                let rr = rayleigh_ritz(&q[..n * m], &aq[..n * m], n, m, b.min(m), d)?;
                if rr.converged || exhausted {
                    break rr;
                }
            }
            if m == 0 {
                return Err(ReprError::Numerical(
                    "isomap: the eigen-solver's start block vanished".into(),
                ));
            }
        };
        if rr.converged {
            let (mut th, mut y) = (rr.theta, rr.y);
            y.truncate(n * d);
            th.truncate(d);
            return Ok((th, y));
        }
        // Restart from the top Ritz vectors.
        x = rr.y;
        xcols = rr.theta.len();
    }
    Err(ReprError::Numerical(format!(
        "isomap: the block Krylov eigen-solver did not converge in {MAX_CYCLES} cycles (n = {n}, d = {d})"
    )))
}

/// Ritz pairs of a Rayleigh-Ritz step.
struct Ritz {
    /// Top Ritz values, decreasing.
    theta: Vec<f64>,
    /// Their Ritz vectors, n x keep column-major.
    y: Vec<f64>,
    /// Whether the top d pairs have residual `<= EIGEN_TOL * |A|` (or the basis is complete).
    converged: bool,
}

/// Rayleigh-Ritz on the orthonormal basis `q` (n x m) with `aq = A q`: the top `keep` Ritz
/// pairs and whether the top `d` have converged.
fn rayleigh_ritz(
    q: &[f64],
    aq: &[f64],
    n: usize,
    m: usize,
    keep: usize,
    d: usize,
) -> Result<Ritz, ReprError> {
    let qm = MatRef::from_column_major_slice(q, n, m);
    let aqm = MatRef::from_column_major_slice(aq, n, m);
    let mut t = vec![0.0f64; m * m];
    matmul(
        MatMut::from_column_major_slice_mut(&mut t, m, m),
        Accum::Replace,
        qm.transpose(),
        aqm,
        1.0,
        Par::Seq,
    );
    for i in 0..m {
        for j in 0..i {
            let s = 0.5 * (t[i + j * m] + t[j + i * m]);
            t[i + j * m] = s;
            t[j + i * m] = s;
        }
    }
    let eig = SelfAdjointEigen::new(MatRef::from_column_major_slice(&t, m, m), Side::Lower)
        .map_err(|e| {
            ReprError::Numerical(format!("isomap: Rayleigh-Ritz eigen-solver failed: {e:?}"))
        })?;
    let all: Vec<f64> = eig.S().column_vector().iter().copied().collect();
    let u = eig.U();
    // Top `keep` Ritz vectors, decreasing eigenvalue.
    let mut s = vec![0.0f64; m * keep];
    let mut theta = vec![0.0f64; keep];
    for c in 0..keep {
        let src = m - 1 - c;
        theta[c] = all[src];
        for r in 0..m {
            s[r + c * m] = u[(r, src)];
        }
    }
    let smat = MatRef::from_column_major_slice(&s, m, keep);
    let mut y = vec![0.0f64; n * keep];
    let mut ay = vec![0.0f64; n * keep];
    matmul(
        MatMut::from_column_major_slice_mut(&mut y, n, keep),
        Accum::Replace,
        qm,
        smat,
        1.0,
        Par::Seq,
    );
    matmul(
        MatMut::from_column_major_slice_mut(&mut ay, n, keep),
        Accum::Replace,
        aqm,
        smat,
        1.0,
        Par::Seq,
    );
    let norm_est = all.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
    let converged = keep >= d
        && (m == n
            || (0..d).all(|c| {
                let r: f64 = (0..n)
                    .map(|i| (ay[i + c * n] - theta[c] * y[i + c * n]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                r <= EIGEN_TOL * norm_est
            }));
    Ok(Ritz {
        theta,
        y,
        converged,
    })
}

/// Full dense eigendecomposition (small n).
fn dense_top_eigenpairs(a: &[f64], n: usize, d: usize) -> Result<(Vec<f64>, Vec<f64>), ReprError> {
    let eig = SelfAdjointEigen::new(MatRef::from_column_major_slice(a, n, n), Side::Lower)
        .map_err(|e| ReprError::Numerical(format!("isomap: eigen-solver failed: {e:?}")))?;
    let s = eig.S().column_vector();
    let u = eig.U();
    let mut vals = Vec::with_capacity(d);
    let mut vecs = vec![0.0; n * d];
    for c in 0..d {
        let src = n - 1 - c;
        vals.push(s[src]);
        for r in 0..n {
            vecs[r + c * n] = u[(r, src)];
        }
    }
    Ok((vals, vecs))
}

/// Orthogonalise the `xcols` columns of `x` (n rows, column-major) against the first `m`
/// columns of `q` (two passes of block classical Gram-Schmidt), orthonormalise them among
/// themselves (modified Gram-Schmidt, twice), dropping numerically dependent columns, and
/// append at most `room` of them to `q`. Returns the number appended.
fn orthonormalise_into(
    q: &mut [f64],
    n: usize,
    m: usize,
    x: &mut [f64],
    xcols: usize,
    room: usize,
) -> usize {
    let x = &mut x[..n * xcols];
    let orig: Vec<f64> = (0..xcols).map(|c| norm(&x[c * n..(c + 1) * n])).collect();
    if m > 0 {
        let (qb, _) = q.split_at(n * m);
        let qm = MatRef::from_column_major_slice(qb, n, m);
        let mut coef = vec![0.0f64; m * xcols];
        for _ in 0..2 {
            matmul(
                MatMut::from_column_major_slice_mut(&mut coef, m, xcols),
                Accum::Replace,
                qm.transpose(),
                MatRef::from_column_major_slice(x, n, xcols),
                1.0,
                Par::Seq,
            );
            matmul(
                MatMut::from_column_major_slice_mut(x, n, xcols),
                Accum::Add,
                qm,
                MatRef::from_column_major_slice(&coef, m, xcols),
                -1.0,
                Par::Seq,
            );
        }
    }
    let mut kept = 0;
    for c in 0..xcols {
        if kept == room {
            break;
        }
        let dst = m + kept;
        let (done, rest) = q.split_at_mut(dst * n);
        let col = &mut x[c * n..(c + 1) * n];
        for _ in 0..2 {
            for p in m..dst {
                let qp = &done[p * n..(p + 1) * n];
                let h = dot(qp, col);
                for (v, &qv) in col.iter_mut().zip(qp) {
                    *v -= h * qv;
                }
            }
        }
        let nv = norm(col);
        // Dependent (or NaN) column: drop it.
        if nv.is_nan() || nv <= 1e-10 * orig[c] || nv == 0.0 {
            continue;
        }
        for (d, &v) in rest[..n].iter_mut().zip(col.iter()) {
            *d = v / nv;
        }
        kept += 1;
    }
    kept
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `y = A x` for the symmetric n x n `a` and x with `cols` columns (column-major), in
/// fixed-size row blocks (`A[rows, :] = A[:, rows]^T` by symmetry), each a sequential product.
fn sym_mul(a: &[f64], n: usize, x: &[f64], cols: usize, y: &mut [f64]) {
    let amat = MatRef::from_column_major_slice(a, n, n);
    let xmat = MatRef::from_column_major_slice(x, n, cols);
    let blocks: Vec<Vec<f64>> = (0..n.div_ceil(MUL_ROWS))
        .into_par_iter()
        .map(|bi| {
            let r0 = bi * MUL_ROWS;
            let rn = MUL_ROWS.min(n - r0);
            let mut out = vec![0.0f64; rn * cols];
            let ablk = amat.subcols(r0, rn);
            matmul(
                MatMut::from_column_major_slice_mut(&mut out, rn, cols),
                Accum::Replace,
                ablk.transpose(),
                xmat,
                1.0,
                Par::Seq,
            );
            out
        })
        .collect();
    for (bi, blk) in blocks.iter().enumerate() {
        let r0 = bi * MUL_ROWS;
        let rn = blk.len() / cols;
        for c in 0..cols {
            y[c * n + r0..c * n + r0 + rn].copy_from_slice(&blk[c * rn..(c + 1) * rn]);
        }
    }
}

/// sklearn `svd_flip` (u-based): make the largest-|.| entry of each column positive (the first
/// such entry on ties).
fn flip_signs(v: &mut [f64], n: usize, d: usize) {
    for c in 0..d {
        let col = &mut v[c * n..(c + 1) * n];
        let mut best = 0;
        for i in 1..n {
            if col[i].abs() > col[best].abs() {
                best = i;
            }
        }
        if col[best] < 0.0 {
            for x in col.iter_mut() {
                *x = -*x;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    /// Random sparse images with dyadic values (all arithmetic exact) and many ties: few lit
    /// pixels, values in {0.5, 1}, some duplicates, some empty images.
    fn tie_data(n: usize, dim: usize, seed: u64) -> ImageSet {
        let mut rng = stream_named(seed, "isomap-test");
        let mut data = vec![0.0f32; n * dim];
        for i in 0..n {
            let r = rng.random_range(0..10u32);
            if r == 0 {
                continue; // empty image
            }
            if r == 1 && i > 0 {
                let j = rng.random_range(0..i);
                let (a, b) = data.split_at_mut(i * dim);
                b[..dim].copy_from_slice(&a[j * dim..(j + 1) * dim]);
                continue;
            }
            let lit = rng.random_range(1..5usize);
            for _ in 0..lit {
                let p = rng.random_range(0..dim);
                data[i * dim + p] = if rng.random_range(0..2u32) == 0 {
                    0.5
                } else {
                    1.0
                };
            }
        }
        ImageSet::new(n, dim, data).unwrap()
    }

    fn brute_knn(
        train: &ImageSet,
        queries: &ImageSet,
        k: usize,
        exclude_self: bool,
    ) -> Vec<(f64, u32)> {
        let mut out = Vec::new();
        for i in 0..queries.n {
            let x = queries.row(i);
            let xn = sq_norm(x);
            let mut all: Vec<(f64, u32)> = (0..train.n)
                .filter(|&j| !(exclude_self && j == i))
                .map(|j| {
                    let y = train.row(j);
                    let dot: f64 = x.iter().zip(y).map(|(&a, &b)| a as f64 * b as f64).sum();
                    (clamp0((xn + sq_norm(y)) - 2.0 * dot), j as u32)
                })
                .collect();
            all.sort_by(nbr_cmp);
            out.extend_from_slice(&all[..k]);
        }
        out
    }

    #[test]
    fn knn_sparse_dense_and_brute_force_agree_with_ties() {
        for (n, dim, k, seed) in [
            (300, 40, 5, 1u64),
            (150, 7, 7, 2),
            (600, 64, 3, 3),
            (40, 3, 10, 4),
        ] {
            let set = tie_data(n, dim, seed);
            let norms: Vec<f64> = set.data.chunks(dim).map(sq_norm).collect();
            let brute = brute_knn(&set, &set, k, true);
            let idx = SparseIndex::build(&set, norms.clone());
            assert_eq!(idx.knn_train(k), brute, "sparse train n={n}");
            let dense = dense_knn(&set.data, n, dim, &norms, &set.data, n, &norms, k, true);
            assert_eq!(dense, brute, "dense train n={n}");
            // Out-of-sample queries (no exclusion), including training images themselves.
            let q = tie_data(50, dim, seed + 100);
            let brute_q = brute_knn(&set, &q, k, false);
            let mut s = KnnScratch::new(n);
            let mut nb = Vec::new();
            for i in 0..q.n {
                idx.knn_one(q.row(i), sq_norm(q.row(i)), k, None, &mut s, &mut nb);
                assert_eq!(&nb[..], &brute_q[i * k..(i + 1) * k], "sparse query {i}");
            }
            let qn: Vec<f64> = q.data.chunks(dim).map(sq_norm).collect();
            assert_eq!(
                dense_knn(&set.data, n, dim, &norms, &q.data, q.n, &qn, k, false),
                brute_q
            );
            // Ties really occur: some query has equal distances among its neighbours.
            assert!(
                brute
                    .chunks(k)
                    .any(|c| c.windows(2).any(|w| w[0].0 == w[1].0))
            );
        }
    }

    #[test]
    fn sparse_and_dense_fits_are_identical_on_exact_data() {
        // Dyadic pixel values on a 1-D "ball" sliding along a line: exact arithmetic, so both
        // kNN paths give the same graph and the whole fit the same bits.
        let (n, dim) = (300, 64);
        let mut data = vec![0.0f32; n * dim];
        for i in 0..n {
            let c = (i * 7) % (dim - 4);
            data[i * dim + c..i * dim + c + 4].copy_from_slice(&[0.5, 1.0, 1.0, 0.5]);
            data[i * dim + (i * 13) % dim] += 0.25;
        }
        let set = ImageSet::new(n, dim, data).unwrap();
        let iso = Isomap {
            n_neighbors: 8,
            ..Default::default()
        };
        let (mut es, zs) = iso
            .fit_with(&set, 2, &mut stream_named(1, "l"), KnnPath::Sparse)
            .unwrap();
        let (mut ed, zd) = iso
            .fit_with(&set, 2, &mut stream_named(1, "l"), KnnPath::Dense)
            .unwrap();
        assert!(es.uses_sparse_index() && !ed.uses_sparse_index());
        assert_eq!(zs, zd);
        assert_eq!(es.encode(&set).unwrap(), ed.encode(&set).unwrap());
        let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
        es.encode_one(set.row(3), &mut a).unwrap();
        ed.encode_one(set.row(3), &mut b).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn dijkstra_on_a_known_graph() {
        // 0 -1- 1 -1- 2 -1- 3, shortcut 0 -2.5- 3, pendant 4 -0.5- 2, zero edge 5 -0- 4.
        let und = [
            (0u32, 1u32, 1.0),
            (1, 2, 1.0),
            (2, 3, 1.0),
            (0, 3, 2.5),
            (4, 2, 0.5),
            (5, 4, 0.0),
            (0, 1, 3.0),
        ];
        let mut e = Vec::new();
        for &(a, b, w) in &und {
            e.push((a, b, w));
            e.push((b, a, w));
        }
        let g = Csr::from_edges(6, e);
        assert_eq!(g.components(), (vec![0; 6], vec![6]));
        let d = g.all_pairs();
        let expect = [
            [0.0, 1.0, 2.0, 2.5, 2.5, 2.5],
            [1.0, 0.0, 1.0, 2.0, 1.5, 1.5],
            [2.0, 1.0, 0.0, 1.0, 0.5, 0.5],
            [2.5, 2.0, 1.0, 0.0, 1.5, 1.5],
            [2.5, 1.5, 0.5, 1.5, 0.0, 0.0],
            [2.5, 1.5, 0.5, 1.5, 0.0, 0.0],
        ];
        for i in 0..6 {
            for j in 0..6 {
                assert_eq!(d[i * 6 + j], expect[i][j] as f32, "({i},{j})");
            }
        }
        // Disconnected: two components.
        let g2 = Csr::from_edges(4, vec![(0, 1, 1.0), (1, 0, 1.0), (2, 3, 1.0), (3, 2, 1.0)]);
        assert_eq!(g2.components(), (vec![0, 0, 1, 1], vec![2, 2]));
    }

    #[test]
    fn dijkstra_matches_floyd_warshall_on_random_graph() {
        let mut rng = stream_named(7, "isomap-test");
        let n = 60;
        let mut e = Vec::new();
        let mut fw = vec![f64::INFINITY; n * n];
        for i in 0..n {
            fw[i * n + i] = 0.0;
            // chain for connectivity + random edges
            let mut add = |a: usize, b: usize, w: f64, e: &mut Vec<(u32, u32, f64)>| {
                e.push((a as u32, b as u32, w));
                e.push((b as u32, a as u32, w));
                fw[a * n + b] = fw[a * n + b].min(w);
                fw[b * n + a] = fw[b * n + a].min(w);
            };
            if i > 0 {
                add(i - 1, i, rng.random_range(0.0..10.0), &mut e);
            }
            for _ in 0..3 {
                let j = rng.random_range(0..n);
                if j != i {
                    add(i, j, rng.random_range(0.0..10.0), &mut e);
                }
            }
            // Some zero-weight edges (identical images), merged before Dijkstra.
            if i % 7 == 3 {
                add(i, (i * 5) % n, 0.0, &mut e);
            }
        }
        for kk in 0..n {
            for i in 0..n {
                for j in 0..n {
                    let v = fw[i * n + kk] + fw[kk * n + j];
                    if v < fw[i * n + j] {
                        fw[i * n + j] = v;
                    }
                }
            }
        }
        let g = Csr::from_edges(n, e);
        assert!(g.zero_classes().1 < n);
        let d = g.all_pairs();
        for i in 0..n * n {
            assert!(
                (d[i] as f64 - fw[i]).abs() <= 1e-5 * fw[i].max(1.0),
                "{i}: {} vs {}",
                d[i],
                fw[i]
            );
        }
    }

    #[test]
    fn krylov_matches_dense_eigen_with_negative_eigenvalues() {
        // Symmetric matrix with a known spectrum including large negative eigenvalues (the
        // top *algebraic* ones must be found) and a near-degenerate pair.
        let n = 400;
        let mut rng = stream_named(9, "isomap-test");
        let mut q: Vec<f64> = (0..n * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        // Orthonormalise the columns (Gram-Schmidt) to get an orthogonal basis.
        for c in 0..n {
            for _ in 0..2 {
                for p in 0..c {
                    let h: f64 = (0..n).map(|i| q[p * n + i] * q[c * n + i]).sum();
                    for i in 0..n {
                        q[c * n + i] -= h * q[p * n + i];
                    }
                }
            }
            let nv: f64 = (0..n).map(|i| q[c * n + i].powi(2)).sum::<f64>().sqrt();
            for i in 0..n {
                q[c * n + i] /= nv;
            }
        }
        let spec: Vec<f64> = (0..n)
            .map(|i| match i {
                0 => 100.0,
                1 => 60.0,
                2 => 60.0 * (1.0 - 1e-6),
                3..=9 => 30.0 / i as f64,
                10..=14 => -150.0 + i as f64,
                _ => 1.0 / i as f64 - 0.5,
            })
            .collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i + j * n] = (0..n).map(|c| q[c * n + i] * spec[c] * q[c * n + j]).sum();
            }
        }
        for i in 0..n {
            for j in 0..i {
                let s = 0.5 * (a[i + j * n] + a[j + i * n]);
                a[i + j * n] = s;
                a[j + i * n] = s;
            }
        }
        let d = 6;
        let (vals, vecs) = top_eigenpairs(&a, n, d, &mut stream_named(1, "x")).unwrap();
        let mut sorted = spec.clone();
        sorted.sort_by(|a, b| b.total_cmp(a));
        for c in 0..d {
            assert!(
                (vals[c] - sorted[c]).abs() <= 1e-10 * 150.0,
                "eigenvalue {c}: {} vs {}",
                vals[c],
                sorted[c]
            );
            // Residual of the returned vector.
            let v = &vecs[c * n..(c + 1) * n];
            let r: f64 = (0..n)
                .map(|i| {
                    ((0..n).map(|j| a[i + j * n] * v[j]).sum::<f64>() - vals[c] * v[i]).powi(2)
                })
                .sum::<f64>()
                .sqrt();
            assert!(r <= 1e-9 * 150.0, "residual {c}: {r}");
        }
        // Same as the dense solver on the eigenvalues.
        let (dv, _) = dense_top_eigenpairs(&a, n, d).unwrap();
        for c in 0..d {
            assert!((vals[c] - dv[c]).abs() <= 1e-10 * 150.0);
        }
    }
}
