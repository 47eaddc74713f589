//! The model cache: fitted representations on disk, keyed by the hash of everything they
//! depend on (see [`crate::campaign::fit::model_key`]), so the samplers of a cell and a
//! rerun of a campaign do not fit again. Every learner whose encoders persist
//! ([`super::RepresentationLearner::persists`]) is kept: the neural networks, PCA, the Gaussian
//! projection.
//!
//! File framing (`<dir>/<key>.model`, little-endian), written atomically (temp + rename):
//! `b"UGL-MODEL\0"`, format version `u32`, header length `u64`, the header (JSON, with the
//! key), the payload, then the BLAKE3 hash (32 bytes) of everything before it ([`seal`],
//! [`unseal`]). The header and payload belong to the learner: a neural network's header holds
//! the model, variant, shapes, loss curve and encoder seed, its payload every layer's weights
//! and biases as `f32` in the header's order ([`to_bytes`]).
//!
//! A file is trusted only if its magic, version, length, checksum, key and shapes all match;
//! anything else (truncated, corrupted, written by another version, a key collision) is
//! reported as [`CacheEntry::Invalid`] and the caller fits again and overwrites it.

use std::path::{Path, PathBuf};

use super::ReprError;

pub use super::model_file::FORMAT_VERSION;
pub use super::model_file::{ModelFileError, f64_bytes, f64s, seal, unseal};
pub use super::neural_encoder::{from_bytes, to_bytes};

/// What [`ModelCache::load`] found.
pub enum CacheEntry<T> {
    /// A valid model.
    Hit(T),
    /// No file.
    Miss,
    /// A file that cannot be trusted; the reason.
    Invalid(String),
}

/// A directory of trained models.
#[derive(Clone, Debug)]
pub struct ModelCache {
    pub dir: PathBuf,
}

impl ModelCache {
    /// A cache in `dir` (created on the first store).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        ModelCache { dir: dir.into() }
    }

    /// The file of `key`.
    pub fn path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.model"))
    }

    /// Look `key` up; `decode` turns trusted-looking bytes into the model (`Err`: why not).
    pub fn load<T>(
        &self,
        key: &str,
        decode: impl FnOnce(&[u8]) -> Result<T, ModelFileError>,
    ) -> CacheEntry<T> {
        let path = self.path(key);
        match std::fs::read(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => CacheEntry::Miss,
            Err(e) => CacheEntry::Invalid(format!("cannot read {}: {e}", path.display())),
            Ok(bytes) => match decode(&bytes) {
                Ok(model) => CacheEntry::Hit(model),
                Err(why) => CacheEntry::Invalid(format!("{}: {why}", path.display())),
            },
        }
    }

    /// Check, before a training, that the cache can be written: its directory exists or can be
    /// created, and a file can be created in it (and is removed). A training whose model could
    /// not be stored would be lost.
    pub fn check_writable(&self) -> Result<(), ReprError> {
        let fail = |what: &str, p: &Path, e: std::io::Error| {
            ReprError::Cache(format!(
                "model cache {}: cannot {what} {} ({e}); choose another with --cache DIR or \
                 train without it (--no-cache)",
                self.dir.display(),
                p.display()
            ))
        };
        std::fs::create_dir_all(&self.dir).map_err(|e| fail("create", &self.dir, e))?;
        let probe = self
            .dir
            .join(format!(".write-probe-{}.tmp", std::process::id()));
        std::fs::write(&probe, b"").map_err(|e| fail("write", &probe, e))?;
        let _ = std::fs::remove_file(&probe);
        Ok(())
    }

    /// Store a model's bytes under `key` (atomically: temp file + rename).
    pub fn store(&self, key: &str, bytes: &[u8]) -> Result<(), ReprError> {
        let io = |what: &str, p: &Path, e: std::io::Error| {
            ReprError::Cache(format!("cannot {what} {}: {e}", p.display()))
        };
        std::fs::create_dir_all(&self.dir).map_err(|e| io("create", &self.dir, e))?;
        let path = self.path(key);
        crate::fsio::write_atomic(&path, bytes).map_err(|e| io("write", &path, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repr::neural::{Model, NeuralConfig, NeuralEncoder, Variant, init_net};
    use crate::seed::stream_named;

    fn encoder(model: Model) -> NeuralEncoder {
        let cfg = NeuralConfig {
            hidden: [6, 5],
            ..NeuralConfig::paper(model)
        };
        let net = init_net(model, &cfg, 12, 3, &mut stream_named(1, "cache-test"));
        NeuralEncoder::new(
            model,
            Variant::Corrected,
            net,
            vec![(0, 1.5), (9, 0.25)],
            [7; 32],
        )
    }

    #[test]
    fn round_trip_and_every_defect_is_detected() {
        for model in Model::ALL {
            let enc = encoder(model);
            let bytes = to_bytes("k1", &enc);
            let back = from_bytes("k1", &bytes).unwrap();
            assert_eq!(back.net, enc.net);
            assert_eq!(back.losses, enc.losses);
            assert_eq!(back.encode_seed, enc.encode_seed);
            assert_eq!((back.model, back.variant), (enc.model, enc.variant));
            assert_eq!(
                from_bytes("k2", &bytes).unwrap_err(),
                ModelFileError::Key { found: "k1".into() }
            );
            for cut in [0, 5, 40, bytes.len() / 2, bytes.len() - 1] {
                assert!(from_bytes("k1", &bytes[..cut]).is_err(), "cut at {cut}");
            }
            for at in [3, 12, 30, bytes.len() / 2, bytes.len() - 1] {
                let mut bad = bytes.clone();
                bad[at] ^= 1;
                assert!(from_bytes("k1", &bad).is_err(), "flip at {at}");
            }
        }
    }

    #[test]
    fn the_cache_directory() {
        let dir = tempfile::tempdir().unwrap();
        let cache = ModelCache::new(dir.path().join("models"));
        let decode = |b: &[u8]| from_bytes("abc", b);
        assert!(matches!(cache.load("abc", decode), CacheEntry::Miss));
        cache
            .store("abc", &to_bytes("abc", &encoder(Model::Vae)))
            .unwrap();
        assert!(matches!(cache.load("abc", decode), CacheEntry::Hit(_)));
        std::fs::write(cache.path("abc"), b"junk").unwrap();
        assert!(matches!(cache.load("abc", decode), CacheEntry::Invalid(_)));
        // A directory where the cache should be is an error, not a panic.
        let blocked = ModelCache::new(dir.path().join("file"));
        std::fs::write(&blocked.dir, b"").unwrap();
        assert!(
            blocked
                .store("abc", &to_bytes("abc", &encoder(Model::Ae)))
                .is_err()
        );
    }
}
