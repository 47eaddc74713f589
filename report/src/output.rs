//! The report's output directory: every file a render writes is recorded here, and the list is
//! kept beside them ([`FILE_LIST`]). A file of the previous render's list that this render did
//! not write is stale and removed; nothing else in the directory is ever touched.
//!
//! A render writes into a staging directory inside the output directory and moves its files into
//! place only when every section has succeeded ([`Output::finish`]): a render that fails (a full
//! disk, a damaged run file) leaves the previous render as it was, never a mixture of two.

use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};

use crate::error::ReportError;
use crate::figures::FigureFile;

/// The list of the files the last render wrote, relative to the output directory, one per line.
pub const FILE_LIST: &str = "files.txt";

const HEADER: &str = "# The files the last `ugl report` wrote into this directory, one per line. \
The next render removes those it no longer writes.\n";

/// Where a render writes, and what it wrote.
#[derive(Debug)]
pub struct Output {
    root: PathBuf,
    /// Where this render writes until [`Output::finish`] (removed when dropped).
    staging: PathBuf,
    /// Relative paths written by this render.
    written: BTreeSet<PathBuf>,
    /// Relative paths the previous render listed.
    previous: BTreeSet<PathBuf>,
}

impl Output {
    /// Creates `root` and `root/figures` if missing, and reads the previous render's list (none:
    /// a first render, which removes nothing).
    pub fn open(root: &Path) -> Result<Self, ReportError> {
        create_dir(root)?;
        let staging = root.join(format!("{STAGING_PREFIX}{}", std::process::id()));
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(|source| ReportError::Io {
                path: staging.clone(),
                source,
            })?;
        }
        remove_abandoned_staging(root);
        create_dir(&staging.join(crate::figures::DIR))?;
        let list = root.join(FILE_LIST);
        let previous = match std::fs::read_to_string(&list) {
            Ok(text) => parse_list(&text),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => BTreeSet::new(),
            Err(source) => return Err(ReportError::Io { path: list, source }),
        };
        Ok(Output {
            root: root.to_path_buf(),
            staging,
            written: BTreeSet::new(),
            previous,
        })
    }

    /// The output directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Where figures are drawn (`figures/` of the staging directory).
    pub fn figures_dir(&self) -> PathBuf {
        self.staging.join(crate::figures::DIR)
    }

    /// Writes `bytes` to `rel` (relative to the output directory; staged until
    /// [`Output::finish`]) and records it. Returns the path it will have after `finish`.
    pub fn write(&mut self, rel: impl AsRef<Path>, bytes: &[u8]) -> Result<PathBuf, ReportError> {
        let path = self.staging.join(rel.as_ref());
        if let Some(dir) = path.parent() {
            create_dir(dir)?;
        }
        std::fs::write(&path, bytes).map_err(|source| ReportError::Io {
            path: path.clone(),
            source,
        })?;
        self.record(&path)?;
        Ok(self.root.join(rel.as_ref()))
    }

    /// Records a file a drawing backend wrote itself (`path` under [`Output::figures_dir`]).
    pub fn record(&mut self, path: &Path) -> Result<(), ReportError> {
        let rel = path
            .strip_prefix(&self.staging)
            .ok()
            .filter(|rel| is_plain_relative(rel))
            .ok_or_else(|| ReportError::Invalid {
                path: path.to_path_buf(),
                problem: format!(
                    "not a file under the output directory {}",
                    self.root.display()
                ),
            })?;
        self.written.insert(rel.to_path_buf());
        Ok(())
    }

    /// Records drawn figures and hands them back.
    pub fn figures(&mut self, figs: Vec<FigureFile>) -> Result<Vec<FigureFile>, ReportError> {
        for f in &figs {
            self.record(&f.path)?;
        }
        Ok(figs)
    }

    /// Records an optional figure and hands it back.
    pub fn figure(&mut self, fig: Option<FigureFile>) -> Result<Option<FigureFile>, ReportError> {
        if let Some(f) = &fig {
            self.record(&f.path)?;
        }
        Ok(fig)
    }

    /// Moves the staged files into place (one rename each), removes the previous render's files
    /// this one did not write, writes the new list, and returns every file written (the list
    /// included), as full paths in sorted order.
    pub fn finish(mut self) -> Result<Vec<PathBuf>, ReportError> {
        for rel in &self.written {
            let (from, to) = (self.staging.join(rel), self.root.join(rel));
            if let Some(dir) = to.parent() {
                create_dir(dir)?;
            }
            std::fs::rename(&from, &to).map_err(|source| ReportError::Io { path: to, source })?;
        }
        let stale: Vec<&PathBuf> = self.previous.difference(&self.written).collect();
        for rel in stale {
            let path = self.root.join(rel);
            if path.is_file() {
                tracing::info!(path = %path.display(), "removing a file the previous render wrote and this one did not");
                std::fs::remove_file(&path).map_err(|source| ReportError::Io { path, source })?;
            }
        }
        let mut text = HEADER.to_string();
        for rel in &self.written {
            text.push_str(&rel.to_string_lossy());
            text.push('\n');
        }
        let (staged, list) = (self.staging.join(FILE_LIST), self.root.join(FILE_LIST));
        std::fs::write(&staged, text).map_err(|source| ReportError::Io {
            path: staged.clone(),
            source,
        })?;
        std::fs::rename(&staged, &list).map_err(|source| ReportError::Io {
            path: list.clone(),
            source,
        })?;
        self.written.insert(PathBuf::from(FILE_LIST));
        Ok(self.written.iter().map(|rel| self.root.join(rel)).collect())
    }
}

impl Drop for Output {
    /// A render that did not finish leaves nothing behind.
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.staging);
    }
}

/// The staging directory's name, before the process id.
pub const STAGING_PREFIX: &str = ".rendering-";

/// Removes the staging directories of renders whose process is gone (killed, or stopped by
/// Ctrl-C, so that [`Output`]'s drop never ran). A render still running keeps its own. Where
/// the system has no `/proc` to ask, nothing is removed. Best effort: a failure here only
/// leaves an old directory behind. (Processes are this machine's: two machines rendering into
/// one shared directory at once are not supported, as they would also overwrite each other.)
fn remove_abandoned_staging(root: &Path) {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(root) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(STAGING_PREFIX))
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !proc.join(pid.to_string()).exists() {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// The entries of a list: comment lines skipped, and only plain relative paths (no `..`, no
/// absolute path), so that a damaged list can never reach outside the output directory.
fn parse_list(text: &str) -> BTreeSet<PathBuf> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(PathBuf::from)
        .filter(|p| is_plain_relative(p) && p != Path::new(FILE_LIST))
        .collect()
}

fn is_plain_relative(p: &Path) -> bool {
    p.components().count() > 0 && p.components().all(|c| matches!(c, Component::Normal(_)))
}

fn create_dir(dir: &Path) -> Result<(), ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_files_are_the_previous_list_minus_this_render() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        let mut out = Output::open(root).unwrap();
        out.write("a.md", b"a").unwrap();
        out.write("figures/b.svg", b"b").unwrap();
        let files = out.finish().unwrap();
        assert_eq!(
            files,
            [
                root.join("a.md"),
                root.join("figures/b.svg"),
                root.join(FILE_LIST)
            ]
        );
        std::fs::write(root.join("notes.txt"), "mine").unwrap();
        let mut out = Output::open(root).unwrap();
        out.write("a.md", b"a2").unwrap();
        out.finish().unwrap();
        assert!(!root.join("figures/b.svg").exists(), "stale figure kept");
        assert!(
            root.join("notes.txt").exists(),
            "a file never written was removed"
        );
        let list = std::fs::read_to_string(root.join(FILE_LIST)).unwrap();
        assert!(list.ends_with("\na.md\n"), "{list}");
    }

    #[test]
    fn an_interrupted_render_is_cleaned_by_the_next() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        // A pid above the kernel's limit (2^22) belongs to no process; this one does.
        let gone = root.join(format!("{STAGING_PREFIX}4194305"));
        let alive = root.join(format!("{STAGING_PREFIX}1"));
        let mine = root.join(format!("{STAGING_PREFIX}notapid"));
        for d in [&gone, &alive, &mine] {
            std::fs::create_dir_all(d.join("figures")).unwrap();
        }
        Output::open(root).unwrap().finish().unwrap();
        if Path::new("/proc/self").exists() {
            assert!(!gone.exists(), "a dead render's staging was kept");
        }
        assert!(alive.exists(), "a running process's staging was removed");
        assert!(
            mine.exists(),
            "a directory that is not a staging one was removed"
        );
    }

    #[test]
    fn a_damaged_list_cannot_reach_outside() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path().join("out");
        std::fs::create_dir_all(&root).unwrap();
        let outside = tmp.path().join("precious.txt");
        std::fs::write(&outside, "keep").unwrap();
        std::fs::write(
            root.join(FILE_LIST),
            format!("../precious.txt\n{}\n/etc/hostname\n", outside.display()),
        )
        .unwrap();
        Output::open(&root).unwrap().finish().unwrap();
        assert!(outside.exists());
    }

    #[test]
    fn a_failed_render_leaves_the_previous_one_intact() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        let mut out = Output::open(root).unwrap();
        out.write("REPORT.md", b"old").unwrap();
        out.write("figures/a.svg", b"old a").unwrap();
        out.finish().unwrap();
        let mut out = Output::open(root).unwrap();
        out.write("REPORT.md", b"new").unwrap();
        out.write("figures/b.svg", b"new b").unwrap();
        drop(out); // a section failed: no finish
        assert_eq!(std::fs::read(root.join("REPORT.md")).unwrap(), b"old");
        assert_eq!(std::fs::read(root.join("figures/a.svg")).unwrap(), b"old a");
        assert!(!root.join("figures/b.svg").exists());
        let left: Vec<_> = std::fs::read_dir(root)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with(STAGING_PREFIX))
            .collect();
        assert!(left.is_empty(), "staging left behind: {left:?}");
    }

    #[test]
    fn recording_a_file_outside_is_an_error() {
        let tmp = tempfile::tempdir().unwrap();
        let mut out = Output::open(&tmp.path().join("out")).unwrap();
        assert!(out.record(&tmp.path().join("elsewhere.svg")).is_err());
    }
}
