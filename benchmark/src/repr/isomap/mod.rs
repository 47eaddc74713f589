//! Isomap, as the paper's UGL stage uses it (docs/original-code.md section 5, "Isomap"):
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
//!    through an inverted index pixel -> images, with a dense fallback (blocked deterministic products,
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
//! Determinism: every parallel loop writes disjoint outputs computed sequentially, every matrix
//! product is one FMA chain per output ([`ugl_kernels::matmul`]) and the dense eigen-solver is
//! plain arithmetic ([`ugl_kernels::SymmetricEigen`]), so a fit is a pure function of (images,
//! latents, n_neighbors, stream), independent of the number of threads and of the CPU.

use std::cmp::Ordering;

use ugl_kernels::{MatRef, SymmetricEigen};

/// `out = a b` (or `out += a b`) with `out` column-major `a.rows() x b.cols()`: the row-major
/// `out^T = b^T a^T`.
fn matmul_cm(out: &mut [f64], a: MatRef<'_, f64>, b: MatRef<'_, f64>, accumulate: bool) {
    ugl_kernels::matmul(out, b.t(), a.t(), accumulate);
}
use rand::RngExt;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{
    Encoder, ImageSet, Latents, ReprError, RepresentationLearner, check_fit_input, check_latents,
    check_no_constant_latent,
};
use crate::repr::neural_model::Variant;
use crate::repr::params::{LearnerParams, ParamError, ParamGuard};
use crate::seed::Stream;

mod eigen;
mod geodesics;
mod knn;

use eigen::*;
use geodesics::*;
use knn::*;

/// `[learners.isomap]`: the unchecked parameters of Isomap ([`ParamGuard`] → [`Isomap`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IsomapConfig {
    /// Neighbours of the kNN graph (sklearn's default, used by the paper: 5).
    pub n_neighbors: usize,
    /// What to do when the kNN graph is disconnected: `connect-closest-pairs` (sklearn >= 1.0;
    /// the default) or `error`. With 10,000 ArmBall images it always is: positions are
    /// truncated to pixels, so groups of 6+ identical images are each other's only neighbours.
    /// The paper's sklearn (< 1.0) silently set the distances between pieces to 0, a defect we
    /// do not reproduce.
    pub disconnected: Disconnected,
}

impl Default for IsomapConfig {
    fn default() -> Self {
        IsomapConfig {
            n_neighbors: 5,
            disconnected: Disconnected::ConnectClosestPairs,
        }
    }
}

impl ParamGuard for IsomapConfig {
    type Checked = Isomap;
    fn check(self) -> Result<Isomap, ParamError> {
        if self.n_neighbors == 0 {
            return Err(ParamError::at("n_neighbors", "must be at least 1"));
        }
        Ok(Isomap {
            n_neighbors: self.n_neighbors,
            disconnected: self.disconnected,
        })
    }
}

impl LearnerParams for Isomap {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn identity(&self, _variant: Option<Variant>) -> serde_json::Value {
        serde_json::to_value(IsomapConfig {
            n_neighbors: self.n_neighbors,
            disconnected: self.disconnected,
        })
        .expect("serialisable")
    }
    fn build(&self, _variant: Option<Variant>) -> Box<dyn RepresentationLearner> {
        Box::new(self.clone())
    }
}

/// Isomap learner (docs/original-code.md section 5): sklearn `Isomap(n_components=latents)` defaults.
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

/// What a fit does when the kNN graph is disconnected (docs/original-code.md section 5).
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
        check_no_constant_latent(&z, "isomap")?;
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
/// `Isomap.transform`, docs/original-code.md section 5).
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
