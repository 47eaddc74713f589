//! The training record: how a run's trained network was obtained (the `train` object of its
//! manifest), written by the runner (`ugl_bench::campaign::fit`) and read by the report, through
//! this one type.
//!
//! The fields are declared in alphabetical order, the order in which the runner wrote them when
//! it built the object as a JSON map (results versions 1 to 5), so a manifest's bytes do not
//! depend on which of the two wrote it; `config` stays the learner's own serialised parameters
//! (each learner owns its configuration), read through [`TrainingRecord::config_int`] and its
//! siblings.

use serde::{Deserialize, Serialize};

/// A run is *untrained* when its network's reconstruction loss is above this fraction of the
/// mean-image loss (the plateau). Trained networks end far below it (a VAE's training loss, KL
/// included, of 60-150 against a plateau of 443 on ArmBall), networks on the plateau at about 1.
pub const UNTRAINED_FRACTION: f64 = 0.8;

/// Where a trained network came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CacheStatus {
    /// Loaded from the model cache.
    Hit,
    /// Trained and stored in the cache.
    Miss,
    /// A cache file was invalid: trained again and overwritten.
    Rebuilt,
    /// No cache: trained.
    Off,
}

impl CacheStatus {
    /// The spelling in manifests (`hit`, `miss`, `rebuilt`, `off`).
    pub fn as_str(self) -> &'static str {
        match self {
            CacheStatus::Hit => "hit",
            CacheStatus::Miss => "miss",
            CacheStatus::Rebuilt => "rebuilt",
            CacheStatus::Off => "off",
        }
    }
}

/// Evidence that a network learned something: its reconstruction loss against the loss of the
/// data set's mean image (the best constant predictor, the *plateau*), on the same images.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainingEvidence {
    /// The evaluation images: the first `images` of the training set.
    pub images: usize,
    /// `reconstruction_loss / plateau_loss`.
    pub loss_fraction: f64,
    /// The mean-image loss of the evaluation images (the plateau level).
    pub plateau_loss: f64,
    /// The trained network's reconstruction loss on the same images.
    pub reconstruction_loss: f64,
    /// `loss_fraction < untrained_fraction`.
    pub trained: bool,
    /// The threshold used ([`UNTRAINED_FRACTION`]).
    pub untrained_fraction: f64,
}

impl TrainingEvidence {
    /// From the mean-image loss and the reconstruction loss measured on the same `images`.
    pub fn new(plateau_loss: f64, reconstruction_loss: f64, images: usize) -> Self {
        let loss_fraction = reconstruction_loss / plateau_loss;
        TrainingEvidence {
            images,
            loss_fraction,
            plateau_loss,
            reconstruction_loss,
            trained: loss_fraction < UNTRAINED_FRACTION,
            untrained_fraction: UNTRAINED_FRACTION,
        }
    }
}

/// The `train` object of a manifest. Every committed manifest of a trained network has all of
/// it but `iterations` (results version 5 on); the report's test fixtures write less, hence the
/// defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainingRecord {
    /// Whether the network was trained or loaded from the model cache.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cache: Option<CacheStatus>,
    /// The complete training configuration: the learner's parameters, resolved, as the learner
    /// serialises them.
    #[serde(default)]
    pub config: serde_json::Value,
    /// The reconstruction loss against the plateau, and whether the network left it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evidence: Option<TrainingEvidence>,
    /// The iterations trained: `config.iterations`, or more where the plateau rule
    /// (`config.plateau`) trained on. Absent before results version 5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iterations: Option<usize>,
    /// The model-cache key (BLAKE3 of everything the model depends on): runs with the same key
    /// share one training (e.g. the KDE and Gaussian-goal runs of a cell).
    #[serde(default)]
    pub key: String,
    /// The recorded loss curve, `(iteration, mini-batch loss)`, in iteration order.
    #[serde(default)]
    pub losses: Vec<(usize, f64)>,
}

impl TrainingRecord {
    /// A field of the configuration.
    pub fn config_field(&self, name: &str) -> Option<&serde_json::Value> {
        self.config.get(name)
    }

    /// An integer field of the configuration (written as an integer or, by hand, a float).
    pub fn config_int(&self, name: &str) -> Option<i64> {
        let v = self.config_field(name)?;
        v.as_i64().or_else(|| v.as_f64().map(|f| f as i64))
    }

    /// A float field of the configuration.
    pub fn config_f64(&self, name: &str) -> Option<f64> {
        self.config_field(name)?.as_f64()
    }

    /// A string field of the configuration.
    pub fn config_str(&self, name: &str) -> Option<&str> {
        self.config_field(name)?.as_str()
    }

    /// Whether the network left the plateau (None where not recorded).
    pub fn trained(&self) -> Option<bool> {
        self.evidence.as_ref().map(|e| e.trained)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The record serialises as the runner's JSON map did: keys in alphabetical order, so the
    /// manifests of results versions 1 to 5 keep their bytes.
    #[test]
    fn serialises_in_the_committed_key_order() {
        let r = TrainingRecord {
            cache: Some(CacheStatus::Miss),
            config: serde_json::json!({"lr": 0.001, "iterations": 600, "batch": 100}),
            evidence: Some(TrainingEvidence::new(400.0, 100.0, 2000)),
            iterations: Some(600),
            key: "k".into(),
            losses: vec![(0, 3.5), (100, 2.25)],
        };
        let typed = serde_json::to_string(&r).unwrap();
        let as_map = serde_json::to_string(&serde_json::to_value(&r).unwrap()).unwrap();
        assert_eq!(typed, as_map);
        assert!(
            typed.starts_with(r#"{"cache":"miss","config":{"batch":100,"#),
            "{typed}"
        );
        assert_eq!(serde_json::from_str::<TrainingRecord>(&typed).unwrap(), r);
        assert_eq!(r.config_int("iterations"), Some(600));
        assert_eq!(r.trained(), Some(true));
        let plateau = TrainingEvidence::new(400.0, 400.0, 2000);
        assert!(!plateau.trained && plateau.loss_fraction == 1.0);
    }

    /// A fixture's partial object reads, with what is missing absent.
    #[test]
    fn reads_a_partial_object() {
        let r: TrainingRecord =
            serde_json::from_str(r#"{"config": {"iterations": 5.0}, "losses": [[0, 1.0]]}"#)
                .unwrap();
        assert_eq!(
            (r.cache, r.trained(), r.config_int("iterations")),
            (None, None, Some(5))
        );
        assert_eq!(CacheStatus::Rebuilt.as_str(), "rebuilt");
    }
}
