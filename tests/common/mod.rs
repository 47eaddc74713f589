//! Helpers shared by the integration tests of the `ugl` binary.

use std::path::Path;

/// The parquet result files of a results directory (curves and outcomes), as (file name, bytes),
/// sorted by name: what two campaigns must agree on byte for byte.
pub fn parquet_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_str().unwrap().ends_with(".parquet"))
        .map(|p| {
            (
                p.file_name().unwrap().to_str().unwrap().to_string(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// Writes `text` to `dir/name` (a campaign file, a profile) and returns its path.
pub fn write_file(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}
