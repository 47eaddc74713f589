//! Writing files so that a file that exists is complete: the one place the workspace writes
//! results, models and checkpoints (the results store, the model cache, mid-training
//! checkpoints), below every module that uses it.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Write `bytes` to `path` atomically: a temporary file in the same directory (named after the
/// process, so concurrent writers never share one), synced, then renamed over `path`. On error
/// the temporary file is removed and `path` is left as it was.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = tmp_path(path);
    let written = File::create(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()
    });
    let renamed = written.and_then(|()| std::fs::rename(&tmp, path));
    if renamed.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    renamed
}

/// Writes several files as one: each through `write(tmp, path)` to a temporary name beside it,
/// then, only if every one succeeded, each renamed into place. On error every temporary file is
/// removed and no `path` is touched (`ugl embed`'s latents and their states never disagree).
pub fn write_set_atomic(
    paths: &[&Path],
    write: &dyn Fn(usize, &Path) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let tmps: Vec<PathBuf> = paths.iter().map(|p| tmp_path(p)).collect();
    let cleanup = |tmps: &[PathBuf]| {
        for t in tmps {
            let _ = std::fs::remove_file(t);
        }
    };
    for (i, t) in tmps.iter().enumerate() {
        if let Err(e) = write(i, t) {
            cleanup(&tmps);
            return Err(e);
        }
    }
    for (t, p) in tmps.iter().zip(paths) {
        if let Err(e) = std::fs::rename(t, p) {
            cleanup(&tmps);
            return Err(e);
        }
    }
    Ok(())
}

/// `<name>.<pid>.tmp` beside `path`.
fn tmp_path(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(".{}.tmp", std::process::id()));
    path.with_file_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_is_written_whole_or_not_at_all() {
        let t = tempfile::tempdir().unwrap();
        let (a, b) = (t.path().join("a.npy"), t.path().join("b.npy"));
        std::fs::write(&a, "old").unwrap();
        let fail_second = |i: usize, p: &Path| {
            std::fs::write(p, "new")?;
            if i == 1 {
                return Err(std::io::Error::other("disk full"));
            }
            Ok(())
        };
        assert!(write_set_atomic(&[&a, &b], &fail_second).is_err());
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        assert!(!b.exists());
        assert_eq!(
            std::fs::read_dir(t.path()).unwrap().count(),
            1,
            "a temporary file is left"
        );
        write_set_atomic(&[&a, &b], &|_, p| std::fs::write(p, "new")).unwrap();
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new");
    }

    #[test]
    fn writes_replace_whole_files_and_leave_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.json");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // Into a missing directory: an error, and nothing left behind.
        let q = dir.path().join("missing").join("b.json");
        assert!(write_atomic(&q, b"x").is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
