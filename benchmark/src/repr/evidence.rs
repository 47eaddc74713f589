//! Evidence that a neural representation learned something (issue: trained goal spaces).
//!
//! The networks' loss is the Bernoulli negative log-likelihood of the pixels, summed over the
//! 4900 pixels and averaged over images (plus the KL term for the VAE and RFVAE). A network that
//! has learned nothing about the object outputs the data set's **mean image**, the best constant
//! predictor; its loss, the *plateau*, is the summed binary entropy of the mean image's pixels
//! (exact, computed here). A run whose final training loss is not clearly below the plateau is
//! flagged *untrained*: its goal space is an untrained random projection.

use serde::{Deserialize, Serialize};

use super::ImageSet;

/// A run is *untrained* when its final loss is above this fraction of the plateau. Trained
/// networks end far below it (loss 60-150 against a plateau of 443 on ArmBall, README), and
/// networks on the plateau end at 0.99-1.2 x it (the VAE adds its KL term).
pub const UNTRAINED_FRACTION: f64 = 0.8;

/// The fraction of the iterations at the end of training whose recorded losses are averaged
/// into the final loss (the mini-batch loss is noisy).
pub const FINAL_WINDOW: f64 = 0.1;

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
                h -= m * m.ln();
            }
            if m < 1.0 {
                h -= (1.0 - m) * (1.0 - m).ln();
            }
            h
        })
        .sum()
}

/// How a training ended, compared with the plateau.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainingEvidence {
    /// The mean-image loss of the training set (the plateau level).
    pub plateau_loss: f64,
    /// Mean of the losses recorded in the last [`FINAL_WINDOW`] of the iterations.
    pub final_loss: f64,
    /// `final_loss / plateau_loss`.
    pub loss_fraction: f64,
    /// `loss_fraction < UNTRAINED_FRACTION`.
    pub trained: bool,
    /// The threshold used ([`UNTRAINED_FRACTION`]).
    pub untrained_fraction: f64,
}

impl TrainingEvidence {
    /// From the recorded loss curve `(iteration, loss)` of a training of `iterations` steps.
    pub fn new(images: &ImageSet, losses: &[(usize, f64)], iterations: usize) -> Self {
        let plateau_loss = mean_image_loss(images);
        let from = iterations as f64 * (1.0 - FINAL_WINDOW);
        let tail: Vec<f64> = losses
            .iter()
            .filter(|(i, _)| *i as f64 >= from)
            .map(|&(_, l)| l)
            .collect();
        let final_loss = if tail.is_empty() {
            losses.last().map_or(f64::NAN, |&(_, l)| l)
        } else {
            tail.iter().sum::<f64>() / tail.len() as f64
        };
        let loss_fraction = final_loss / plateau_loss;
        TrainingEvidence {
            plateau_loss,
            final_loss,
            loss_fraction,
            trained: loss_fraction < UNTRAINED_FRACTION,
            untrained_fraction: UNTRAINED_FRACTION,
        }
    }
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
                    total -= x * m.ln();
                }
                if x < 1.0 {
                    total -= (1.0 - x) * (1.0 - m).ln();
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
        let s = set(&[&[0.0, 1.0], &[1.0, 0.0]]);
        let plateau = 2.0 * 2f64.ln();
        let flat: Vec<(usize, f64)> = (0..100).map(|i| (i, plateau * 1.01)).collect();
        let e = TrainingEvidence::new(&s, &flat, 100);
        assert!(!e.trained && (e.loss_fraction - 1.01).abs() < 1e-9);
        // Only the last 10% count: a curve that drops at the end is trained.
        let drop: Vec<(usize, f64)> = (0..100)
            .map(|i| (i, if i >= 90 { 0.1 * plateau } else { plateau }))
            .collect();
        let e = TrainingEvidence::new(&s, &drop, 100);
        assert!(e.trained && (e.final_loss - 0.1 * plateau).abs() < 1e-12);
    }
}
