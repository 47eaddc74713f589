//! The latent-quality measure of a learned goal space, as a run records it (a manifest's
//! `latent_quality`, or a diagnostics sidecar's): how well the true object state can be read
//! off the latents. The science crate measures it (`ugl_bench::repr::quality`); the report reads
//! it through these types.

use serde::{Deserialize, Serialize};

fn version_one() -> u32 {
    1
}

/// R² of the two regressions, per target and on average.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LatentQuality {
    /// The measure's version (`ugl_bench::repr::quality::MEASURE_VERSION` of the code that
    /// measured it; 1 in records that predate versioning).
    #[serde(default = "version_one")]
    pub version: u32,
    /// Target names (`x`, `y`; arrow: `cos_angle`, `sin_angle`, `cos_3angle`, `sin_3angle`).
    pub targets: Vec<String>,
    /// Held-out R² of the linear map, per target.
    pub linear_r2: Vec<f64>,
    /// Held-out R² of the k-NN regression, per target.
    pub knn_r2: Vec<f64>,
    /// Means over the targets.
    pub linear_r2_mean: f64,
    pub knn_r2_mean: f64,
    /// Means per target group (the target groups): linear and k-NN R² of the position, and (arrow)
    /// of the angle and of the angle modulo 120°.
    #[serde(default)]
    pub groups: Vec<GroupR2>,
    /// Trustworthiness and continuity per state space (version 3 and later; empty before).
    #[serde(default)]
    pub neighbourhoods: Vec<Neighbourhoods>,
    /// Scenes with several objects (ArmBalls): per object, how much of each latent its
    /// position explains ; empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_latent: Vec<ObjectR2>,
    /// Scenes with several objects: MIG and SAP against the objects' coordinates, on the
    /// held-out images (None: one object, or not measurable; the reason is logged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub disentanglement: Option<Disentanglement>,
    /// Scenes with several objects, encoders with a Gaussian posterior: per latent, the mean KL
    /// divergence of its posterior from the prior N(0, 1) on the held-out images, in nats (the
    /// follow-up's criterion of an active latent, which orders its modules); empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub kl_per_latent: Vec<f64>,
    /// Training and held-out set sizes, and `k`.
    pub n_train: usize,
    pub n_heldout: usize,
    pub k: usize,
}

/// Disentanglement (follow-up paper): for one object, the held-out R² of a k-NN regression
/// (`k` neighbours) from the object's (x, y) to each latent, fitted on the training images. A
/// latent that encodes only the ball scores high for the ball and about 0 for the
/// distractor; an entangled latent scores in between for both.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectR2 {
    /// `ball` or `distractor`.
    pub object: String,
    /// Per latent, in the encoder's order; None for a constant (collapsed) latent.
    pub r2: Vec<Option<f64>>,
}

/// Disentanglement of a goal space against the scene's factors, the objects' coordinates
/// (`ugl_bench::repr::disentanglement`): 1 when each factor is captured by one latent alone.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Disentanglement {
    /// The factors, in order (`ball x`, `ball y`, `distractor x`, `distractor y`).
    pub factors: Vec<String>,
    /// The mutual information gap (Chen et al. 2018), averaged over the factors.
    pub mig: f64,
    /// Per factor: the gap between its two most informative latents, over its entropy.
    pub mig_per_factor: Vec<f64>,
    /// Per factor: the latent that shares the most information with it.
    pub mig_best_latent: Vec<usize>,
    /// The separated attribute predictability (Kumar et al. 2018), averaged over the factors.
    pub sap: f64,
    /// Per factor: the gap between the R² of its two most predictive latents.
    pub sap_per_factor: Vec<f64>,
}

/// The mean R² of one group of targets.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroupR2 {
    /// `position`, `angle` or `angle_mod_120`.
    pub group: String,
    pub linear_r2: f64,
    pub knn_r2: f64,
}

/// Neighbourhood preservation between one state space and the latents, on the held-out images.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Neighbourhoods {
    /// `position` (x, y) or `state` (arrow: x, y, cos a, sin a).
    pub space: String,
    pub trustworthiness: f64,
    pub continuity: f64,
}

impl LatentQuality {
    /// The (linear, k-NN) R² of a group of targets (`position`, `angle`, `angle_mod_120`).
    pub fn group(&self, name: &str) -> Option<&GroupR2> {
        self.groups.iter().find(|g| g.group == name)
    }

    /// Per latent, the R² of an object's position (ArmBalls: `ball`, `distractor`).
    pub fn object(&self, name: &str) -> Option<&ObjectR2> {
        self.per_latent.iter().find(|o| o.object == name)
    }
}
