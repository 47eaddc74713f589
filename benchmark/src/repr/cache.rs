//! The model cache: fitted representations on disk, keyed by the hash of everything they
//! depend on (see [`crate::campaign::runner::model_key`]), so the samplers of a cell and a
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

use serde::{Deserialize, Serialize};

use super::ReprError;
use super::nets::{HostLayer, HostNet};
use super::neural::{Model, NeuralEncoder, Variant};

const MAGIC: &[u8; 10] = b"UGL-MODEL\0";
/// Bumped when the file layout changes.
pub const FORMAT_VERSION: u32 = 1;

#[derive(Serialize, Deserialize)]
struct Header {
    key: String,
    model: Model,
    variant: Variant,
    dim: usize,
    hidden: [usize; 2],
    latents: usize,
    /// `(inp, out)` of enc1, enc2, head, dec1, dec2, dec_out.
    layers: Vec<(usize, usize)>,
    losses: Vec<(usize, f64)>,
    encode_seed: String,
}

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

/// Frame a header and a payload: magic, version, header length, header, payload, BLAKE3.
pub fn seal(header: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(MAGIC.len() + 12 + header.len() + payload.len() + 32);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(header.len() as u64).to_le_bytes());
    out.extend_from_slice(header);
    out.extend_from_slice(payload);
    let sum = blake3::hash(&out);
    out.extend_from_slice(sum.as_bytes());
    out
}

/// The header and payload of framed bytes, after checking the magic, checksum, version and
/// lengths; `Err` says why the bytes cannot be trusted.
pub fn unseal(bytes: &[u8]) -> Result<(&[u8], &[u8]), String> {
    let n = bytes.len();
    if n < MAGIC.len() + 12 + 32 || &bytes[..MAGIC.len()] != MAGIC {
        return Err("not a model file (bad magic or too short)".into());
    }
    let (body, sum) = bytes.split_at(n - 32);
    if blake3::hash(body).as_bytes() != sum {
        return Err("checksum mismatch (truncated or corrupted)".into());
    }
    let mut at = MAGIC.len();
    let version = u32::from_le_bytes(body[at..at + 4].try_into().expect("4 bytes"));
    at += 4;
    if version != FORMAT_VERSION {
        return Err(format!(
            "format version {version}, this build reads {FORMAT_VERSION}"
        ));
    }
    let hlen = u64::from_le_bytes(body[at..at + 8].try_into().expect("8 bytes")) as usize;
    at += 8;
    let hend = at
        .checked_add(hlen)
        .filter(|&e| e <= body.len())
        .ok_or("header length out of range")?;
    Ok((&body[at..hend], &body[hend..]))
}

/// Little-endian `f64`s.
pub fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// The `f64`s of [`f64_bytes`]; `Err` if the length is not a multiple of 8.
pub fn f64s(bytes: &[u8]) -> Result<Vec<f64>, String> {
    if bytes.len() % 8 != 0 {
        return Err(format!("{} payload bytes are not f64 values", bytes.len()));
    }
    Ok(bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect())
}

/// Serialise a neural encoder under `key`.
pub fn to_bytes(key: &str, enc: &NeuralEncoder) -> Vec<u8> {
    let net = &enc.net;
    let header = Header {
        key: key.into(),
        model: enc.model,
        variant: enc.variant,
        dim: net.dim,
        hidden: net.hidden,
        latents: net.latents,
        layers: net.layers().iter().map(|l| (l.inp, l.out)).collect(),
        losses: enc.losses.clone(),
        encode_seed: hex(&enc.encode_seed),
    };
    let header = serde_json::to_vec(&header).expect("header serialises");
    let mut payload = Vec::with_capacity(4 * net.num_params());
    for l in net.layers() {
        for v in l.w.iter().chain(&l.b) {
            payload.extend_from_slice(&v.to_le_bytes());
        }
    }
    seal(&header, &payload)
}

/// Parse and check a neural encoder's bytes; `Err` says why they cannot be trusted.
pub fn from_bytes(key: &str, bytes: &[u8]) -> Result<NeuralEncoder, String> {
    let (header, payload) = unseal(bytes)?;
    let h: Header = serde_json::from_slice(header).map_err(|e| format!("bad header: {e}"))?;
    if h.key != key {
        return Err(format!("key mismatch (file holds {})", h.key));
    }
    let [h1, h2] = h.hidden;
    let p: usize = h.model.head_blocks(h.latents).iter().sum();
    let expect = vec![
        (h.dim, h1),
        (h1, h2),
        (h2, p),
        (h.latents, h2),
        (h2, h1),
        (h1, h.dim),
    ];
    if h.layers != expect {
        return Err("layer shapes do not match the model".into());
    }
    let values: usize = expect.iter().map(|(i, o)| i * o + o).sum();
    if payload.len() != 4 * values {
        return Err(format!(
            "weights have {} bytes, the shapes need {}",
            payload.len(),
            4 * values
        ));
    }
    let mut floats = payload
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")));
    let mut take = |k: usize| -> Vec<f32> { floats.by_ref().take(k).collect() };
    let mut layer = |(inp, out): (usize, usize)| HostLayer {
        inp,
        out,
        w: take(inp * out),
        b: take(out),
    };
    let net = HostNet {
        dim: h.dim,
        hidden: h.hidden,
        latents: h.latents,
        enc1: layer(expect[0]),
        enc2: layer(expect[1]),
        head: layer(expect[2]),
        dec1: layer(expect[3]),
        dec2: layer(expect[4]),
        dec_out: layer(expect[5]),
    };
    let seed = unhex(&h.encode_seed).ok_or("bad encoder seed")?;
    Ok(NeuralEncoder::new(h.model, h.variant, net, h.losses, seed))
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

fn unhex(s: &str) -> Option<[u8; 32]> {
    if s.len() != 64 {
        return None;
    }
    let mut out = [0u8; 32];
    for (i, o) in out.iter_mut().enumerate() {
        *o = u8::from_str_radix(s.get(2 * i..2 * i + 2)?, 16).ok()?;
    }
    Some(out)
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
        decode: impl FnOnce(&[u8]) -> Result<T, String>,
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
    use crate::repr::neural::{Model, NeuralConfig, init_net};
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
            assert!(
                from_bytes("k2", &bytes)
                    .unwrap_err()
                    .contains("key mismatch")
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
