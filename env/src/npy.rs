//! The one NPY codec of the project (numpy's `.npy` format, version 1.0 written; 1.0, 2.0 and
//! 3.0 read): two-dimensional float arrays, what the external-learner protocol, `ugl render`
//! and `ugl embed` exchange. Written: `<f4` or `<f8`, C order, the header padded so that the
//! data start at a multiple of 64 bytes (as numpy writes it). Read: `f4` or `f8` of either byte
//! order, C or Fortran order, from a file or a stream (an external program's stdout), with a
//! bounded header and errors that say what came instead. The tests cross-check it with `npyz`.

use std::fs::File;
use std::io::{self, BufReader, BufWriter, Read, Write};
use std::path::Path;

/// Longest npy header accepted (protection against garbage).
const NPY_HEADER_MAX: usize = 1 << 20;

pub const NPY_MAGIC: &[u8; 6] = b"\x93NUMPY";

/// Append a complete npy array (float32, shape (rows, cols), C order) to `buf`.
pub fn push_npy_f32(buf: &mut Vec<u8>, rows: usize, cols: usize, data: &[f32]) {
    debug_assert_eq!(data.len(), rows * cols);
    push_npy_header(buf, "<f4", rows, cols);
    buf.reserve(data.len() * 4);
    for v in data {
        buf.extend_from_slice(&v.to_le_bytes());
    }
}

pub fn push_npy_header(buf: &mut Vec<u8>, descr: &str, rows: usize, cols: usize) {
    push_npy_header_shape(buf, descr, &[rows, cols]);
}

/// The header of an array of any shape (C order).
pub fn push_npy_header_shape(buf: &mut Vec<u8>, descr: &str, shape: &[usize]) {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape = match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    // Total length (10-byte preamble + header + '\n') a multiple of 64, as numpy writes it.
    let unpadded = 10 + header.len() + 1;
    header.extend(std::iter::repeat_n(
        ' ',
        unpadded.next_multiple_of(64) - unpadded,
    ));
    header.push('\n');
    buf.extend_from_slice(NPY_MAGIC);
    buf.extend_from_slice(&[1, 0]);
    buf.extend_from_slice(&(header.len() as u16).to_le_bytes());
    buf.extend_from_slice(header.as_bytes());
}

pub fn write_npy_f32_file(path: &Path, rows: usize, cols: usize, data: &[f32]) -> io::Result<()> {
    write_npy_f32_shape_file(path, &[rows, cols], data)
}

/// Write a float32 array of any shape (C order) as .npy.
pub fn write_npy_f32_shape_file(path: &Path, shape: &[usize], data: &[f32]) -> io::Result<()> {
    debug_assert_eq!(data.len(), shape.iter().product::<usize>());
    let mut w = BufWriter::with_capacity(1 << 20, File::create(path)?);
    let mut header = Vec::new();
    push_npy_header_shape(&mut header, "<f4", shape);
    w.write_all(&header)?;
    let mut chunk = Vec::with_capacity(64 * 1024);
    for block in data.chunks(16 * 1024) {
        chunk.clear();
        for v in block {
            chunk.extend_from_slice(&v.to_le_bytes());
        }
        w.write_all(&chunk)?;
    }
    w.flush()
}

/// A read error: the message (prefixed with what was read), and whether the stream ended.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct NpyError {
    pub message: String,
    /// The stream ended (the program probably exited).
    pub eof: bool,
}

fn npy_err(what: &str, msg: impl std::fmt::Display) -> NpyError {
    NpyError {
        message: format!("{what}: {msg}"),
        eof: false,
    }
}

fn io_err(what: &str, e: io::Error) -> NpyError {
    let eof = e.kind() == io::ErrorKind::UnexpectedEof;
    let msg = if eof {
        "stream ended in the middle of an npy array (program exited?)".to_string()
    } else {
        e.to_string()
    };
    NpyError {
        message: format!("{what}: {msg}"),
        eof,
    }
}

/// Read the npy file `path`: one array of shape (rows, cols) (rows checked when given), and
/// nothing after it.
pub fn read_npy_file(path: &Path, rows: Option<usize>, cols: usize) -> Result<Vec<f64>, NpyError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let file = File::open(path)
        .map_err(|e| npy_err(&format!("cannot open {name} ({})", path.display()), e))?;
    let mut r = BufReader::new(file);
    let mut out = Vec::new();
    read_npy(&mut r, &mut Vec::new(), &mut out, rows, cols, &name)?;
    let mut probe = [0u8; 1];
    if r.read(&mut probe).map_err(|e| npy_err(&name, e))? != 0 {
        return Err(npy_err(&name, "trailing bytes after the array"));
    }
    Ok(out)
}

/// Read one npy array of shape (rows, cols) (rows checked when given) into `out` as f64.
/// `raw` is a reusable byte buffer. Returns the number of rows.
pub fn read_npy<R: Read>(
    r: &mut BufReader<R>,
    raw: &mut Vec<u8>,
    out: &mut Vec<f64>,
    rows: Option<usize>,
    cols: usize,
    what: &str,
) -> Result<usize, NpyError> {
    let mut magic = [0u8; 6];
    let mut got = 0;
    while got < 6 {
        match r.read(&mut magic[got..]) {
            Ok(0) if got == 0 => {
                return Err(NpyError {
                    message: format!(
                        "{what}: stream closed (program exited?) instead of an npy array"
                    ),
                    eof: true,
                });
            }
            Ok(0) => return Err(io_err(what, io::ErrorKind::UnexpectedEof.into())),
            Ok(k) => got += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(io_err(what, e)),
        }
    }
    if &magic != NPY_MAGIC {
        // Show what came instead: the 6 bytes plus whatever is already buffered (no blocking).
        let mut seen = magic.to_vec();
        seen.extend_from_slice(&r.buffer()[..r.buffer().len().min(200)]);
        return Err(npy_err(
            what,
            format!(
                "not an npy array: starts with {:?} (stdout is reserved for the protocol: log to stderr)",
                String::from_utf8_lossy(&seen)
            ),
        ));
    }
    let mut version = [0u8; 2];
    r.read_exact(&mut version).map_err(|e| io_err(what, e))?;
    let header_len = match version[0] {
        1 => {
            let mut b = [0u8; 2];
            r.read_exact(&mut b).map_err(|e| io_err(what, e))?;
            u16::from_le_bytes(b) as usize
        }
        2 | 3 => {
            let mut b = [0u8; 4];
            r.read_exact(&mut b).map_err(|e| io_err(what, e))?;
            u32::from_le_bytes(b) as usize
        }
        v => {
            return Err(npy_err(
                what,
                format!("unsupported npy version {v}.{}", version[1]),
            ));
        }
    };
    if header_len > NPY_HEADER_MAX {
        return Err(npy_err(
            what,
            format!("npy header of {header_len} bytes is too long"),
        ));
    }
    raw.clear();
    raw.resize(header_len, 0);
    r.read_exact(raw).map_err(|e| io_err(what, e))?;
    let text = std::str::from_utf8(raw).map_err(|_| npy_err(what, "npy header is not UTF-8"))?;
    let header = parse_header(text)
        .map_err(|m| npy_err(what, format!("bad npy header {:?}: {m}", text.trim_end())))?;
    let (size, big) = match header.descr.as_str() {
        "<f4" | "f4" => (4, false),
        "<f8" | "f8" => (8, false),
        ">f4" => (4, true),
        ">f8" => (8, true),
        "=f4" => (4, cfg!(target_endian = "big")),
        "=f8" => (8, cfg!(target_endian = "big")),
        d => {
            return Err(npy_err(
                what,
                format!("dtype {d:?} not supported (use float32 '<f4' or float64 '<f8')"),
            ));
        }
    };
    let shape_ok = header.shape.len() == 2
        && header.shape[1] == cols
        && rows.is_none_or(|m| header.shape[0] == m);
    if !shape_ok {
        let expected = match rows {
            Some(m) => format!("({m}, {cols})"),
            None => format!("(n, {cols})"),
        };
        return Err(npy_err(
            what,
            format!("shape {:?}, expected {expected}", header.shape),
        ));
    }
    let m = header.shape[0];
    let count = m
        .checked_mul(cols)
        .ok_or_else(|| npy_err(what, "shape overflows"))?;
    let bytes = count
        .checked_mul(size)
        .ok_or_else(|| npy_err(what, "shape overflows"))?;
    raw.clear();
    raw.resize(bytes, 0);
    r.read_exact(raw).map_err(|e| io_err(what, e))?;
    out.clear();
    out.resize(count, 0.0);
    let value = |k: usize| -> f64 {
        let b = &raw[k * size..(k + 1) * size];
        match (size, big) {
            (4, false) => f32::from_le_bytes(b.try_into().expect("4 bytes")) as f64,
            (4, true) => f32::from_be_bytes(b.try_into().expect("4 bytes")) as f64,
            (_, false) => f64::from_le_bytes(b.try_into().expect("8 bytes")),
            (_, true) => f64::from_be_bytes(b.try_into().expect("8 bytes")),
        }
    };
    if header.fortran_order {
        for k in 0..count {
            out[(k % m.max(1)) * cols + k / m.max(1)] = value(k);
        }
    } else {
        for (k, o) in out.iter_mut().enumerate() {
            *o = value(k);
        }
    }
    Ok(m)
}

struct NpyHeader {
    descr: String,
    fortran_order: bool,
    shape: Vec<usize>,
}

/// Parse the Python dict literal of an npy header.
fn parse_header(text: &str) -> Result<NpyHeader, String> {
    let b = text.as_bytes();
    let mut i = 0;
    let skip = |i: &mut usize| {
        while *i < b.len() && b[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    let string = |i: &mut usize| -> Result<String, String> {
        let q = b[*i];
        let start = *i + 1;
        let end = b[start..]
            .iter()
            .position(|&c| c == q)
            .ok_or("unterminated string")?
            + start;
        *i = end + 1;
        Ok(text[start..end].to_string())
    };
    skip(&mut i);
    if b.get(i) != Some(&b'{') {
        return Err("expected '{'".into());
    }
    i += 1;
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    loop {
        skip(&mut i);
        match b.get(i) {
            Some(b'}') => {
                i += 1;
                break;
            }
            Some(b'\'' | b'"') => {}
            _ => return Err("expected a quoted key or '}'".into()),
        }
        let key = string(&mut i)?;
        skip(&mut i);
        if b.get(i) != Some(&b':') {
            return Err(format!("expected ':' after {key:?}"));
        }
        i += 1;
        skip(&mut i);
        match (key.as_str(), b.get(i)) {
            ("descr", Some(b'\'' | b'"')) => descr = Some(string(&mut i)?),
            ("fortran_order", _) if b[i..].starts_with(b"True") => {
                fortran = Some(true);
                i += 4;
            }
            ("fortran_order", _) if b[i..].starts_with(b"False") => {
                fortran = Some(false);
                i += 5;
            }
            ("shape", Some(b'(')) => {
                let end = b[i..]
                    .iter()
                    .position(|&c| c == b')')
                    .ok_or("unterminated shape")?
                    + i;
                let dims = text[i + 1..end]
                    .split(',')
                    .map(|s| s.trim().trim_end_matches('L'))
                    .filter(|s| !s.is_empty())
                    .map(|s| {
                        s.parse::<usize>()
                            .map_err(|_| format!("bad dimension {s:?}"))
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                shape = Some(dims);
                i = end + 1;
            }
            (k, _) => return Err(format!("unexpected key or value for {k:?}")),
        }
        skip(&mut i);
        if b.get(i) == Some(&b',') {
            i += 1;
        }
    }
    skip(&mut i);
    if i != b.len() {
        return Err("trailing characters after the header dict".into());
    }
    Ok(NpyHeader {
        descr: descr.ok_or("missing 'descr'")?,
        fortran_order: fortran.ok_or("missing 'fortran_order'")?,
        shape: shape.ok_or("missing 'shape'")?,
    })
}

/// Write a float64 `rows x cols` array (C order) as an .npy file.
pub fn write_npy_f64_file(path: &Path, rows: usize, cols: usize, data: &[f64]) -> io::Result<()> {
    if data.len() != rows * cols {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} values for a {rows} x {cols} array", data.len()),
        ));
    }
    let mut w = BufWriter::new(File::create(path)?);
    let mut header = Vec::new();
    push_npy_header(&mut header, "<f8", rows, cols);
    w.write_all(&header)?;
    for v in data {
        w.write_all(&v.to_le_bytes())?;
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roundtrip_bytes(bytes: &[u8], rows: Option<usize>, cols: usize) -> Result<Vec<f64>, String> {
        let mut r = BufReader::new(bytes);
        let mut out = Vec::new();
        read_npy(&mut r, &mut Vec::new(), &mut out, rows, cols, "test")
            .map(|_| out)
            .map_err(|e| e.message)
    }

    #[test]
    fn npy_written_header_is_aligned_and_reads_back() {
        let data: Vec<f32> = (0..6).map(|v| v as f32 * 0.5).collect();
        let mut buf = Vec::new();
        push_npy_f32(&mut buf, 2, 3, &data);
        assert_eq!(
            (buf.len() - 24) % 64,
            0,
            "preamble + header is a multiple of 64"
        );
        let back = roundtrip_bytes(&buf, Some(2), 3).unwrap();
        assert_eq!(back, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5]);
        assert!(
            roundtrip_bytes(&buf, Some(3), 3)
                .unwrap_err()
                .contains("shape [2, 3], expected (3, 3)")
        );
        assert!(roundtrip_bytes(&buf, None, 2).is_err());
    }

    /// What we write, `npyz` (an independent implementation) reads, and the other way round.
    #[test]
    fn npyz_agrees_with_this_codec() {
        use npyz::WriterBuilder;
        let dir = tempfile::tempdir().unwrap();
        let f32s: Vec<f32> = (0..12).map(|v| v as f32 * 0.25 - 1.0).collect();
        let f64s: Vec<f64> = (0..12).map(|v| (v as f64).sqrt() - 1.5).collect();
        let a = dir.path().join("a.npy");
        write_npy_f32_file(&a, 3, 4, &f32s).unwrap();
        let bytes = std::fs::read(&a).unwrap();
        let arr = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(arr.shape(), &[3, 4]);
        assert_eq!(arr.order(), npyz::Order::C);
        assert_eq!(arr.into_vec::<f32>().unwrap(), f32s);
        let b = dir.path().join("b.npy");
        write_npy_f64_file(&b, 4, 3, &f64s).unwrap();
        let bytes = std::fs::read(&b).unwrap();
        let arr = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(arr.shape(), &[4, 3]);
        assert_eq!(arr.into_vec::<f64>().unwrap(), f64s);
        assert!(write_npy_f64_file(&b, 5, 3, &f64s).is_err());
        // npyz writes, we read.
        let c = dir.path().join("c.npy");
        let mut w = npyz::WriteOptions::<f64>::new()
            .default_dtype()
            .shape(&[2, 6])
            .writer(std::io::BufWriter::new(File::create(&c).unwrap()))
            .begin_nd()
            .unwrap();
        w.extend(f64s.iter().copied()).unwrap();
        w.finish().unwrap();
        assert_eq!(read_npy_file(&c, Some(2), 6).unwrap(), f64s);
    }

    #[test]
    fn npy_reads_fortran_big_endian_and_v2() {
        // (2, 3) float64 big-endian, Fortran order, version 2.0, double-quoted keys.
        let header = "{\"descr\": \">f8\", \"fortran_order\": True, \"shape\": (2L, 3L)}\n";
        let mut buf = NPY_MAGIC.to_vec();
        buf.extend_from_slice(&[2, 0]);
        buf.extend_from_slice(&(header.len() as u32).to_le_bytes());
        buf.extend_from_slice(header.as_bytes());
        // Column-major: (0,0) (1,0) (0,1) (1,1) (0,2) (1,2) with value 10 r + c.
        for v in [0.0f64, 10.0, 1.0, 11.0, 2.0, 12.0] {
            buf.extend_from_slice(&v.to_be_bytes());
        }
        assert_eq!(
            roundtrip_bytes(&buf, Some(2), 3).unwrap(),
            vec![0.0, 1.0, 2.0, 10.0, 11.0, 12.0]
        );
    }

    #[test]
    fn npy_rejects_garbage_and_other_dtypes() {
        let e = roundtrip_bytes(b"hello world\n", Some(1), 1).unwrap_err();
        assert!(
            e.contains("not an npy array") && e.contains("hello world"),
            "{e}"
        );
        let mut buf = Vec::new();
        push_npy_header(&mut buf, "<i8", 1, 1);
        buf.extend_from_slice(&[0; 8]);
        assert!(
            roundtrip_bytes(&buf, Some(1), 1)
                .unwrap_err()
                .contains("dtype")
        );
        let mut short = Vec::new();
        push_npy_f32(&mut short, 1, 2, &[1.0, 2.0]);
        short.truncate(short.len() - 1);
        assert!(
            roundtrip_bytes(&short, Some(1), 2)
                .unwrap_err()
                .contains("middle")
        );
        assert!(parse_header("{'descr': '<f4', 'shape': (1, 2), }").is_err());
    }
}
