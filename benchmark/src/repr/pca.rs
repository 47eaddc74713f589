//! PCA learners (docs/original-code.md section 5, "PCA").
//!
//! - [`TruncatedSvd`] (`pca`): what the paper's code used, `sklearn.decomposition.TruncatedSVD`
//!   — **not mean-centred** — with its randomized solver (10 oversamples, 5 power iterations).
//!   Encoding = `x V` (V: the top right singular vectors). Works on sparse rows, so a 10,000 x
//!   4900 image set costs O(non-zeros).
//! - [`TruncatedSvd`] with `centre = true` (`pca-centred`, [`TruncatedSvd::centred`]):
//!   ordinary (mean-centred) PCA, by the same randomized solver with the centring applied implicitly (the data stay sparse). `linfa-reduction`'s
//!   PCA was the first choice, but it took 426 s and 1.4 GB for 10,000 images (measured with
//!   `ugl run --algo rge-pca-centred`); it remains the reference of a cross-check test.

use crate::seed::standard_normal;
use ugl_kernels::SymmetricEigen;

use super::model_file::ModelFileError;
use super::neural_model::Variant;
use super::params::{LearnerParams, ParamError, ParamGuard};
use super::sparse::SparseRows;
use super::{
    Encoder, ImageSet, Latents, ReprError, RepresentationLearner, check_fit_input, check_latents,
};
use crate::seed::Stream;

/// Non-centred truncated SVD with the randomized range finder (Halko et al. 2011), as
/// scikit-learn's `TruncatedSVD(algorithm="randomized", n_iter=5)`.
#[derive(Clone, Debug)]
pub struct TruncatedSvd {
    /// Extra random directions of the range finder (sklearn: 10).
    pub n_oversamples: usize,
    /// Power iterations (sklearn: 5).
    pub n_iter: usize,
    /// Subtract the training mean (ordinary PCA) instead of the paper's raw SVD.
    pub centre: bool,
}

/// `[learners.pca]` (`CENTRE = false`) and `[learners.pca-centred]` (`true`): neither has
/// parameters (sklearn's defaults); the table must be empty.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PcaConfig<const CENTRE: bool> {}

impl<const CENTRE: bool> ParamGuard for PcaConfig<CENTRE> {
    type Checked = PcaConfig<CENTRE>;
    fn check(self) -> Result<PcaConfig<CENTRE>, ParamError> {
        Ok(self)
    }
}

impl<const CENTRE: bool> LearnerParams for PcaConfig<CENTRE> {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn identity(&self, _variant: Option<Variant>) -> serde_json::Value {
        serde_json::Value::Null
    }
    fn build(&self, _variant: Option<Variant>) -> Box<dyn RepresentationLearner> {
        Box::new(if CENTRE {
            TruncatedSvd::centred()
        } else {
            TruncatedSvd::default()
        })
    }
}

impl TruncatedSvd {
    /// Ordinary (mean-centred) PCA (`pca-centred`): the same solver, centred.
    pub fn centred() -> Self {
        TruncatedSvd {
            centre: true,
            ..TruncatedSvd::default()
        }
    }
}

impl Default for TruncatedSvd {
    fn default() -> Self {
        TruncatedSvd {
            n_oversamples: 10,
            n_iter: 5,
            centre: false,
        }
    }
}

/// The fitted projection: `z = x V`.
#[derive(Clone, Debug)]
pub struct ProjectionEncoder {
    /// p x d, row-major.
    pub components: Vec<f64>,
    pub dim: usize,
    pub latents: usize,
    /// Singular values, descending.
    pub singular_values: Vec<f64>,
    /// `mean V` (1 x d), subtracted from every encoding when the model is centred.
    pub offset: Vec<f64>,
}

/// The model-cache header of a [`ProjectionEncoder`] (its payload: the components, the
/// singular values and the offset, as `f64`).
#[derive(serde::Serialize, serde::Deserialize)]
struct ProjectionHeader {
    key: String,
    encoder: String,
    dim: usize,
    latents: usize,
    singular_values: usize,
}

impl ProjectionEncoder {
    /// The encoder from the bytes of [`Encoder::save`]; `Err` says why they cannot be trusted.
    pub fn from_bytes(key: &str, bytes: &[u8]) -> Result<ProjectionEncoder, ModelFileError> {
        let (header, payload) = super::cache::unseal(bytes)?;
        let h: ProjectionHeader =
            serde_json::from_slice(header).map_err(|e| ModelFileError::Header(e.to_string()))?;
        if h.key != key {
            return Err(ModelFileError::Key { found: h.key });
        }
        if h.encoder != "projection" {
            return Err(ModelFileError::Content(format!(
                "a {} encoder, not a projection",
                h.encoder
            )));
        }
        let values = super::cache::f64s(payload)?;
        let (nc, ns) = (h.dim * h.latents, h.singular_values);
        if values.len() != nc + ns + h.latents {
            return Err(ModelFileError::Content(format!(
                "{} values, the shapes need {}",
                values.len(),
                nc + ns + h.latents
            )));
        }
        Ok(ProjectionEncoder {
            components: values[..nc].to_vec(),
            dim: h.dim,
            latents: h.latents,
            singular_values: values[nc..nc + ns].to_vec(),
            offset: values[nc + ns..].to_vec(),
        })
    }
}

impl Encoder for ProjectionEncoder {
    fn latents(&self) -> usize {
        self.latents
    }
    fn save(&self, key: &str) -> Option<Vec<u8>> {
        let header = ProjectionHeader {
            key: key.to_string(),
            encoder: "projection".into(),
            dim: self.dim,
            latents: self.latents,
            singular_values: self.singular_values.len(),
        };
        let header = serde_json::to_vec(&header).expect("header serialises");
        let mut values = self.components.clone();
        values.extend_from_slice(&self.singular_values);
        values.extend_from_slice(&self.offset);
        Some(super::cache::seal(
            &header,
            &super::cache::f64_bytes(&values),
        ))
    }
    fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        if images.dim != self.dim {
            return Err(ReprError::InvalidInput(format!(
                "images have {} pixels, the model {}",
                images.dim, self.dim
            )));
        }
        let mut z = SparseRows::from_images(images).mul_dense(&self.components, self.latents);
        for row in z.chunks_exact_mut(self.latents) {
            for (v, o) in row.iter_mut().zip(&self.offset) {
                *v -= o;
            }
        }
        let z = Latents {
            n: images.n,
            latents: self.latents,
            data: z,
        };
        check_latents(&z, "pca")?;
        Ok(z)
    }
    fn encode_one(&mut self, image: &[f32], out: &mut [f64]) -> Result<(), ReprError> {
        if image.len() != self.dim || out.len() != self.latents {
            return Err(ReprError::InvalidInput(
                "encode_one: wrong image or output size".into(),
            ));
        }
        for (o, off) in out.iter_mut().zip(&self.offset) {
            *o = -off;
        }
        for (j, &v) in image.iter().enumerate() {
            if v != 0.0 {
                let row = &self.components[j * self.latents..(j + 1) * self.latents];
                for (o, c) in out.iter_mut().zip(row) {
                    *o += v as f64 * c;
                }
            }
        }
        Ok(())
    }
}

impl RepresentationLearner for TruncatedSvd {
    fn name(&self) -> &str {
        if self.centre { "pca-centred" } else { "pca" }
    }

    fn persists(&self) -> bool {
        true
    }

    fn load(&self, key: &str, bytes: &[u8]) -> Result<Box<dyn Encoder>, ModelFileError> {
        Ok(Box::new(ProjectionEncoder::from_bytes(key, bytes)?))
    }

    fn fit(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        check_fit_input(images, latents)?;
        let x = SparseRows::from_images(images);
        let (n, p) = (images.n, images.dim);
        let k = (latents + self.n_oversamples).min(n).min(p);
        // Column means; the centred matrix X - 1 m^T is never formed.
        let mean: Vec<f64> = if self.centre {
            x.tmul_dense(&vec![1.0 / n as f64; n], 1)
        } else {
            vec![0.0; p]
        };
        // (X - 1 m^T) B = X B - 1 (m^T B)
        let mul = |b: &[f64]| {
            let mut out = x.mul_dense(b, k);
            if self.centre {
                let mb: Vec<f64> = (0..k)
                    .map(|t| (0..p).map(|j| mean[j] * b[j * k + t]).sum())
                    .collect();
                for row in out.chunks_exact_mut(k) {
                    row.iter_mut().zip(&mb).for_each(|(v, m)| *v -= m);
                }
            }
            out
        };
        // (X - 1 m^T)^T B = X^T B - m (1^T B)
        let tmul = |b: &[f64]| {
            let mut out = x.tmul_dense(b, k);
            if self.centre {
                let sb: Vec<f64> = (0..k).map(|t| (0..n).map(|i| b[i * k + t]).sum()).collect();
                for (j, row) in out.chunks_exact_mut(k).enumerate() {
                    row.iter_mut().zip(&sb).for_each(|(v, s)| *v -= mean[j] * s);
                }
            }
            out
        };
        let omega: Vec<f64> = (0..p * k).map(|_| standard_normal(rng)).collect();
        let mut y = mul(&omega);
        orthonormalize(&mut y, n, k);
        for _ in 0..self.n_iter {
            let mut z = tmul(&y);
            orthonormalize(&mut z, p, k);
            y = mul(&z);
            orthonormalize(&mut y, n, k);
        }
        // B^T = X^T Q (p x k); B B^T = (B^T)^T B^T (k x k).
        let bt = tmul(&y);
        let mut c = vec![0.0; k * k];
        for r in 0..p {
            let row = &bt[r * k..(r + 1) * k];
            for a in 0..k {
                for b in 0..k {
                    c[a * k + b] += row[a] * row[b];
                }
            }
        }
        // Eigenpairs of the small k x k problem, decreasing (plain arithmetic: the same bits on
        // every CPU).
        let eig = SymmetricEigen::new(&c, k)
            .map_err(|e| ReprError::Numerical(format!("PCA: eigen-decomposition failed: {e}")))?;
        let vals: Vec<(f64, usize)> = (0..k).rev().map(|j| (eig.values[j], j)).collect();
        let vecs = eig.vectors;
        let mut components = vec![0.0; p * latents];
        let mut singular_values = Vec::with_capacity(latents);
        for (t, &(lambda, col)) in vals.iter().take(latents).enumerate() {
            let sigma = lambda.max(0.0).sqrt();
            singular_values.push(sigma);
            if sigma <= f64::EPSILON * vals[0].0.max(1.0).sqrt() {
                continue; // rank-deficient data: this component is zero
            }
            // Sign: the largest |u| entry positive (sklearn's svd_flip, u-based); u = Q w.
            let w: Vec<f64> = (0..k).map(|a| vecs[a * k + col]).collect();
            let mut best = (0.0f64, 1.0f64);
            for i in 0..n {
                let u: f64 = (0..k).map(|a| y[i * k + a] * w[a]).sum();
                if u.abs() > best.0 {
                    best = (u.abs(), u.signum());
                }
            }
            for r in 0..p {
                let v: f64 = (0..k).map(|a| bt[r * k + a] * w[a]).sum();
                components[r * latents + t] = best.1 * v / sigma;
            }
        }
        let offset: Vec<f64> = (0..latents)
            .map(|t| (0..p).map(|j| mean[j] * components[j * latents + t]).sum())
            .collect();
        let mut enc = ProjectionEncoder {
            components,
            dim: p,
            latents,
            singular_values,
            offset,
        };
        let z = enc.encode(images)?;
        Ok((Box::new(enc), z))
    }
}

/// Modified Gram-Schmidt, twice, on the k columns of a row-major m x k matrix. A column that
/// vanishes relative to its norm before projection (rank deficiency) is set to zero.
fn orthonormalize(a: &mut [f64], m: usize, k: usize) {
    let mut before = vec![0.0; k];
    for (j, b) in before.iter_mut().enumerate() {
        *b = (0..m)
            .map(|i| a[i * k + j] * a[i * k + j])
            .sum::<f64>()
            .sqrt();
    }
    for pass in 0..2 {
        for j in 0..k {
            for q in 0..j {
                let dot: f64 = (0..m).map(|i| a[i * k + j] * a[i * k + q]).sum();
                for i in 0..m {
                    a[i * k + j] -= dot * a[i * k + q];
                }
            }
            let norm = (0..m)
                .map(|i| a[i * k + j] * a[i * k + j])
                .sum::<f64>()
                .sqrt();
            let dead = norm <= 1e-300 || (pass == 0 && norm <= 1e-10 * before[j]);
            let inv = if dead { 0.0 } else { 1.0 / norm };
            for i in 0..m {
                a[i * k + j] *= inv;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    /// A hand-computable case: rows (3,0), (0,1), (3,0), (0,1) (plus a zero pixel). X^T X =
    /// diag(18, 2): singular values sqrt(18), sqrt(2), right singular vectors e1, e2.
    fn toy() -> ImageSet {
        ImageSet::new(
            4,
            3,
            vec![3.0, 0.0, 0.0, 0.0, 1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        )
        .unwrap()
    }

    #[test]
    fn truncated_svd_hand_case_is_not_centred() {
        let (mut enc, z) = TruncatedSvd::default()
            .fit(&toy(), 2, &mut stream_named(0, "t"))
            .unwrap();
        // Non-centred: the first latent of row 0 is its projection on e1 = 3 (sign fixed positive).
        let expected = [3.0, 0.0, 0.0, 1.0, 3.0, 0.0, 0.0, 1.0];
        for (a, b) in z.data.iter().zip(expected) {
            assert!((a - b).abs() < 1e-9, "{:?}", z.data);
        }
        let mut out = [0.0; 2];
        enc.encode_one(&[0.0, 2.0, 0.0], &mut out).unwrap();
        assert!(
            (out[0]).abs() < 1e-9 && (out[1] - 2.0).abs() < 1e-9,
            "{out:?}"
        );
    }

    #[test]
    fn centred_pca_hand_case() {
        // Centred data: rows (1.5,-0.5), (-1.5,0.5) ... all variance along (3,-1)/sqrt(10).
        let (_, z) = TruncatedSvd::centred()
            .fit(&toy(), 1, &mut stream_named(0, "t"))
            .unwrap();
        let s = 1.5f64.hypot(0.5);
        for (i, v) in z.data.iter().enumerate() {
            assert!((v.abs() - s).abs() < 1e-9, "{:?}", z.data);
            // Rows 0 and 2 are equal, 1 and 3 opposite to them.
            let sign0 = z.data[0].signum();
            let want = if i % 2 == 0 { sign0 } else { -sign0 };
            assert_eq!(v.signum(), want);
        }
    }

    #[test]
    fn centred_pca_agrees_with_linfa() {
        use linfa::traits::{Fit, Predict};
        let mut rng = stream_named(4, "t");
        let data: Vec<f32> = (0..80 * 30)
            .map(|i| {
                let v = standard_normal(&mut rng);
                (v * (1.0 + (i % 30) as f64 / 5.0)).max(0.0) as f32
            })
            .collect();
        let set = ImageSet::new(80, 30, data).unwrap();
        let (_, ours) = TruncatedSvd::centred()
            .fit(&set, 3, &mut stream_named(5, "t"))
            .unwrap();
        let arr = ndarray::Array2::from_shape_fn((80, 30), |(i, j)| set.data[i * 30 + j] as f64);
        let model = linfa_reduction::Pca::params(3)
            .fit(&linfa::DatasetBase::from(arr.clone()))
            .unwrap();
        let theirs: ndarray::Array2<f64> = model.predict(&arr);
        for t in 0..3 {
            // Same component up to sign.
            let dot: f64 = (0..80).map(|i| ours.row(i)[t] * theirs[[i, t]]).sum();
            let n1: f64 = (0..80).map(|i| ours.row(i)[t].powi(2)).sum::<f64>().sqrt();
            let n2: f64 = (0..80).map(|i| theirs[[i, t]].powi(2)).sum::<f64>().sqrt();
            assert!(
                (dot.abs() / (n1 * n2) - 1.0).abs() < 1e-6,
                "component {t}: cos {}",
                dot / (n1 * n2)
            );
            assert!(
                (n1 - n2).abs() < 1e-6 * n2,
                "component {t}: norms {n1} {n2}"
            );
        }
    }

    #[test]
    fn randomized_matches_exact_on_low_rank_data() {
        // 60 images that are mixtures of 3 fixed patterns: the top-3 subspace is exact.
        let mut rng = stream_named(3, "t");
        let pats: Vec<Vec<f32>> = (0..3)
            .map(|k| {
                (0..50)
                    .map(|j| if j % (k + 2) == 0 { 1.0 } else { 0.0 })
                    .collect()
            })
            .collect();
        let mut data = Vec::new();
        for _ in 0..60 {
            let w: Vec<f64> = (0..3).map(|_| standard_normal(&mut rng)).collect();
            for j in 0..50 {
                data.push((0..3).map(|k| w[k] * pats[k][j] as f64).sum::<f64>() as f32);
            }
        }
        let set = ImageSet::new(60, 50, data).unwrap();
        let (enc, z) = TruncatedSvd::default()
            .fit(&set, 3, &mut stream_named(1, "t"))
            .unwrap();
        let _ = enc;
        // Energy is preserved: ||X||_F^2 == ||Z||_F^2 for rank-3 data.
        let ex: f64 = set.data.iter().map(|v| (*v as f64).powi(2)).sum();
        let ez: f64 = z.data.iter().map(|v| v * v).sum();
        assert!((ex - ez).abs() < 1e-6 * ex, "{ex} {ez}");
        // Deterministic for a stream.
        let (_, z2) = TruncatedSvd::default()
            .fit(&set, 3, &mut stream_named(1, "t"))
            .unwrap();
        assert_eq!(z, z2);
    }
}
