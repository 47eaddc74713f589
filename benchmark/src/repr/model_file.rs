//! The sealed file format of fitted models: a magic, a JSON header and a payload, with a BLAKE3
//! digest over both, so that a damaged file is detected before it is used.

pub(crate) const MAGIC: &[u8; 10] = b"UGL-MODEL\0";

/// Why the bytes of a fitted model (or a training's optimiser state) cannot be trusted; the
/// harness then fits again and overwrites them.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ModelFileError {
    #[error("not a model file (bad magic or too short)")]
    NotAModel,
    #[error("checksum mismatch (truncated or corrupted)")]
    Checksum,
    #[error("format version {found}, this build reads {FORMAT_VERSION}")]
    Version { found: u32 },
    #[error("header length out of range")]
    HeaderLength,
    /// The header is not the reader's JSON.
    #[error("bad header: {0}")]
    Header(String),
    /// The file was written under another cache key.
    #[error("key mismatch (file holds {found})")]
    Key { found: String },
    /// The file is sound but holds something else than its reader needs: another kind of
    /// encoder, another model or variant, other shapes.
    #[error("{0}")]
    Content(String),
    /// The learner keeps no encoder in the model cache.
    #[error("{learner} encoders are not kept in the model cache")]
    NotKept { learner: String },
    /// The learner's trainings save no mid-training checkpoints.
    #[error("{learner} trainings save no checkpoints")]
    NoCheckpoints { learner: String },
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
pub fn unseal(bytes: &[u8]) -> Result<(&[u8], &[u8]), ModelFileError> {
    let n = bytes.len();
    if n < MAGIC.len() + 12 + 32 || &bytes[..MAGIC.len()] != MAGIC {
        return Err(ModelFileError::NotAModel);
    }
    let (body, sum) = bytes.split_at(n - 32);
    if blake3::hash(body).as_bytes() != sum {
        return Err(ModelFileError::Checksum);
    }
    let mut at = MAGIC.len();
    let version = u32::from_le_bytes(body[at..at + 4].try_into().expect("4 bytes"));
    at += 4;
    if version != FORMAT_VERSION {
        return Err(ModelFileError::Version { found: version });
    }
    let hlen = u64::from_le_bytes(body[at..at + 8].try_into().expect("8 bytes")) as usize;
    at += 8;
    let hend = at
        .checked_add(hlen)
        .filter(|&e| e <= body.len())
        .ok_or(ModelFileError::HeaderLength)?;
    Ok((&body[at..hend], &body[hend..]))
}

/// Little-endian `f64`s.
pub fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// The `f64`s of [`f64_bytes`]; `Err` if the length is not a multiple of 8.
pub fn f64s(bytes: &[u8]) -> Result<Vec<f64>, ModelFileError> {
    if !bytes.len().is_multiple_of(8) {
        return Err(ModelFileError::Content(format!(
            "{} payload bytes are not f64 values",
            bytes.len()
        )));
    }
    Ok(bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect())
}

/// Bumped when the file layout changes.
pub const FORMAT_VERSION: u32 = 1;
