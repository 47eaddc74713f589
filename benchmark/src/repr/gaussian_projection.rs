//! A Gaussian random projection of the pixels (`gaussian-projection`): an *untrained* control
//! goal space, and the worked example of adding a learner (this file + one entry in
//! [`super::registry::LEARNERS`]).
//!
//! The projection is `z = x W` with `W` a `dim x latents` matrix of independent `N(0, std^2)`
//! entries drawn from the learner's stream, `std = 1/sqrt(latents)` by default (scikit-learn's
//! `GaussianRandomProjection`, and `scripts/external_learners/random_projection.py`, which runs
//! the same model through the external-learner protocol). Nothing is learned from the images,
//! so a learned goal space that does not beat it has learned nothing the exploration can use
//! (untrained networks rank with it: the report's controls).

use crate::seed::standard_normal;

use super::neural_model::Variant;
use super::params::{LearnerParams, ParamError, ParamGuard};
use super::pca::ProjectionEncoder;
use super::{Encoder, ImageSet, Latents, ReprError, RepresentationLearner, check_fit_input};
use crate::seed::Stream;

/// `[learners.gaussian-projection]`, unchecked: every key is optional.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaussianProjectionConfig {
    /// Standard deviation of the entries of `W` (default: `1/sqrt(latents)`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
}

impl ParamGuard for GaussianProjectionConfig {
    type Checked = GaussianProjection;
    fn check(self) -> Result<GaussianProjection, ParamError> {
        if let Some(s) = self.std
            && !(s.is_finite() && s > 0.0)
        {
            return Err(ParamError::at(
                "std",
                format!("must be a positive number, got {s}"),
            ));
        }
        Ok(GaussianProjection { std: self.std })
    }
}

/// The checked learner.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GaussianProjection {
    /// Standard deviation of the entries of `W` (None: `1/sqrt(latents)`).
    pub std: Option<f64>,
}

impl LearnerParams for GaussianProjection {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn identity(&self, _variant: Option<Variant>) -> serde_json::Value {
        match self.std {
            None => serde_json::Value::Null,
            Some(s) => serde_json::json!({ "std": s }),
        }
    }
    fn build(&self, _variant: Option<Variant>) -> Box<dyn RepresentationLearner> {
        Box::new(self.clone())
    }
}

impl RepresentationLearner for GaussianProjection {
    fn name(&self) -> &str {
        "gaussian-projection"
    }

    fn fit(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        check_fit_input(images, latents)?;
        let std = self.std.unwrap_or(1.0 / (latents as f64).sqrt());
        if !(std.is_finite() && std >= 0.0) {
            return Err(ReprError::InvalidInput(format!(
                "gaussian projection: std must be finite and non-negative, got {std}"
            )));
        }
        // Row-major dim x latents, drawn row by row: the same stream gives the same W.
        let components: Vec<f64> = (0..images.dim * latents)
            .map(|_| std * standard_normal(rng))
            .collect();
        let mut encoder = ProjectionEncoder {
            components,
            dim: images.dim,
            latents,
            singular_values: Vec::new(),
            offset: vec![0.0; latents],
        };
        let z = encoder.encode(images)?;
        Ok((Box::new(encoder), z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    fn images() -> ImageSet {
        let data = (0..5 * 8).map(|i| ((i * 7) % 11) as f32 / 10.0).collect();
        ImageSet::new(5, 8, data).unwrap()
    }

    #[test]
    fn encodes_x_times_w_with_the_seeded_matrix() {
        let set = images();
        let learner = GaussianProjection::default();
        let (mut enc, z) = learner.fit(&set, 3, &mut stream_named(1, "t")).unwrap();
        // W again from the same stream: z = x W exactly, on the training set and per image.
        use rand_distr::{Distribution, Normal};
        let normal = Normal::new(0.0, 1.0 / 3f64.sqrt()).unwrap();
        let mut rng = stream_named(1, "t");
        let w: Vec<f64> = (0..8 * 3).map(|_| normal.sample(&mut rng)).collect();
        for i in 0..set.n {
            let mut one = [0.0; 3];
            enc.encode_one(set.row(i), &mut one).unwrap();
            for k in 0..3 {
                let want: f64 = (0..8).map(|j| set.row(i)[j] as f64 * w[j * 3 + k]).sum();
                assert!((z.row(i)[k] - want).abs() < 1e-12);
                assert!((one[k] - want).abs() < 1e-12);
            }
        }
        // Another stream, another projection.
        let (_, other) = learner.fit(&set, 3, &mut stream_named(2, "t")).unwrap();
        assert_ne!(other.data, z.data);
    }

    #[test]
    fn params_are_checked() {
        let bad = GaussianProjectionConfig { std: Some(0.0) }
            .check()
            .unwrap_err();
        assert_eq!(bad.key.as_deref(), Some("std"), "{bad}");
        let ok = GaussianProjectionConfig { std: Some(0.5) }.check().unwrap();
        assert_eq!(ok.identity(None), serde_json::json!({ "std": 0.5 }));
        assert_eq!(
            GaussianProjectionConfig::default()
                .check()
                .unwrap()
                .identity(None),
            serde_json::Value::Null
        );
    }
}
