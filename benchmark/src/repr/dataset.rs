//! The passive observation data set of the UGL stage (paper Section 3, Algorithm 1;
//! docs/original-code.md section 2, "UGL training set"): N images of the object at states drawn
//! uniformly over the whole square [-1,1]^2 (and the arrow's angle uniformly over [-1,1]),
//! rendered by the project's renderer. Generated on the fly from the data-set stream.

use rand::RngExt;

use super::{ImageSet, ReprError};
use crate::env::{EnvKind, Environment};
use crate::seed::Stream;

/// The states and images of a UGL data set.
#[derive(Clone, Debug)]
pub struct UglDataset {
    /// Engineered states, row-major n x state_dim.
    pub states: Vec<f64>,
    /// The rendered images.
    pub images: ImageSet,
}

/// Draw `n` states uniformly in [-1,1)^d and render them.
pub fn generate(
    env: &dyn Environment,
    n: usize,
    rng: &mut Stream,
) -> Result<UglDataset, ReprError> {
    if n == 0 {
        return Err(ReprError::InvalidInput(
            "the UGL data set needs at least 1 image".into(),
        ));
    }
    let d = env.state_dim();
    let mut states = Vec::with_capacity(n * d);
    let values = env.image_len();
    let mut data = vec![0f32; n * values];
    for (i, img) in data.chunks_exact_mut(values).enumerate() {
        let s: Vec<f64> = (0..d).map(|_| rng.random_range(-1.0..1.0)).collect();
        env.render_into(&s, img);
        states.extend_from_slice(&s);
        debug_assert_eq!(states.len(), (i + 1) * d);
    }
    Ok(UglDataset {
        states,
        images: ImageSet::new(n, values, data)?,
    })
}

/// The identity of a data set, hashed into its seed: shared by every learner of a repetition.
pub fn dataset_identity(env: EnvKind, n: usize, rep: u64) -> String {
    format!("dataset/env={env}/images={n}/seed={rep}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{EnvConfig, make_env};
    use crate::seed::{Component, stream};

    #[test]
    fn deterministic_and_covers_the_square() {
        let env = make_env(EnvKind::ARMBALL, &EnvConfig::default());
        let a = generate(env.as_ref(), 400, &mut stream(1, Component::Dataset)).unwrap();
        let b = generate(env.as_ref(), 400, &mut stream(1, Component::Dataset)).unwrap();
        assert_eq!(a.images, b.images);
        assert_eq!(a.images.n, 400);
        // States outside the unit disk are drawn too (the whole square, as the original).
        let outside = a
            .states
            .chunks(2)
            .filter(|s| s[0] * s[0] + s[1] * s[1] > 1.0)
            .count();
        assert!(outside > 40, "{outside}");
        assert!(a.images.data.iter().all(|v| (0.0..=1.0).contains(v)));
        let c = generate(env.as_ref(), 400, &mut stream(2, Component::Dataset)).unwrap();
        assert_ne!(a.images, c.images);
    }
}
