//! The sealed file format of fitted models: a magic, a JSON header and a payload, with a BLAKE3
//! digest over both, so that a damaged file is detected before it is used.

pub(crate) const MAGIC: &[u8; 10] = b"UGL-MODEL\0";

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
    if !bytes.len().is_multiple_of(8) {
        return Err(format!("{} payload bytes are not f64 values", bytes.len()));
    }
    Ok(bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect())
}

/// Bumped when the file layout changes.
pub const FORMAT_VERSION: u32 = 1;
