//! Evidence that a neural representation learned something (the report's "Did the goal spaces learn?").
//!
//! A network that has learned nothing about the object outputs the data set's **mean image**,
//! the best constant predictor. Its Bernoulli loss (summed over the 4900 pixels, averaged over
//! images), the *plateau*, is the summed binary entropy of the mean image's pixels: exact,
//! computed here. After training, the network's **reconstruction loss** (the decoder applied to
//! each image's noise-free code, no KL term and no flow log-determinant:
//! `neural::reconstruction_loss`) is measured on the same images and compared with it; a run
//! whose reconstruction is not clearly better than the mean image is flagged *untrained*: its
//! goal space is an untrained random projection. (The training loss itself is not comparable:
//! the VAE adds its KL term, and the faithful RFVAE's broadcast log-determinant makes its loss
//! meaningless as a level.)

use super::ImageSet;

/// A run is *untrained* when its reconstruction loss is above this fraction of the plateau,
/// and the evidence recorded in its manifest (declared in `ugl-types`, read by the report).
pub use ugl_types::{TrainingEvidence, UNTRAINED_FRACTION};

/// The number of training images (the first ones) on which the plateau and the reconstruction
/// loss are measured.
pub const EVIDENCE_IMAGES: usize = 2000;

/// The loss of the mean image on `images`: `sum_p H(m_p)` in nats, `m_p` the mean of pixel `p`
/// and `H` the binary entropy (`0 log 0 = 0`). Exact for any pixel values in [0, 1], since the
/// Bernoulli log-likelihood is linear in the targets.
pub fn mean_image_loss(images: &ImageSet) -> f64 {
    let n = images.n as f64;
    let mut sums = vec![0.0f64; images.dim];
    for i in 0..images.n {
        for (s, &v) in sums.iter_mut().zip(images.row(i)) {
            *s += v as f64;
        }
    }
    sums.iter()
        .map(|&s| {
            let m = s / n;
            let mut h = 0.0;
            if m > 0.0 {
                h -= m * libm::log(m);
            }
            if m < 1.0 {
                h -= (1.0 - m) * libm::log(1.0 - m);
            }
            h
        })
        .sum()
}

/// How a training ended, compared with the plateau.
/// The Bernoulli cross-entropy of a pixel value `t` under the logit `l`, `softplus(l) - t l`,
/// computed stably in `f64` (the reconstruction losses of every network).
pub fn bce_of_logit(l: f32, t: f32) -> f64 {
    let l = f64::from(l);
    l.max(0.0) + libm::log1p(libm::exp(-l.abs())) - f64::from(t) * l
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(rows: &[&[f32]]) -> ImageSet {
        ImageSet::new(
            rows.len(),
            rows[0].len(),
            rows.iter().flat_map(|r| r.iter().copied()).collect(),
        )
        .unwrap()
    }

    /// Direct definition: the average over images of the summed BCE of the mean image.
    fn brute(images: &ImageSet) -> f64 {
        let n = images.n;
        let mean: Vec<f64> = (0..images.dim)
            .map(|p| (0..n).map(|i| images.row(i)[p] as f64).sum::<f64>() / n as f64)
            .collect();
        let mut total = 0.0;
        for i in 0..n {
            for (p, &x) in images.row(i).iter().enumerate() {
                let (x, m) = (x as f64, mean[p]);
                if x > 0.0 {
                    total -= x * libm::log(m);
                }
                if x < 1.0 {
                    total -= (1.0 - x) * libm::log(1.0 - m);
                }
            }
        }
        total / n as f64
    }

    #[test]
    fn mean_image_loss_is_the_constant_predictors_loss() {
        // Constant pixels cost nothing; a pixel on in half the images costs ln 2.
        let s = set(&[&[0.0, 1.0, 1.0, 0.0], &[0.0, 1.0, 0.0, 0.0]]);
        assert!((mean_image_loss(&s) - 2f64.ln()).abs() < 1e-12);
        let s = set(&[
            &[0.2, 1.0, 0.0, 0.7],
            &[0.9, 0.0, 0.0, 0.1],
            &[0.0, 1.0, 0.5, 0.3],
        ]);
        assert!((mean_image_loss(&s) - brute(&s)).abs() < 1e-9);
    }

    #[test]
    fn evidence_flags_a_run_on_the_plateau() {
        let e = TrainingEvidence::new(440.0, 436.0, 2000);
        assert!(!e.trained && (e.loss_fraction - 436.0 / 440.0).abs() < 1e-12);
        let e = TrainingEvidence::new(440.0, 88.0, 2000);
        assert!(e.trained && (e.loss_fraction - 0.2).abs() < 1e-12);
    }
}
