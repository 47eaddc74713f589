//! `ugl-report`: reads the ugl-bench results store, computes statistics over seeds, draws the
//! paper's figures as SVG and writes `REPORT.md`.
//!
//! The report never re-runs science: its only inputs are the run files of the results store
//! (`data/results/README.md` documents them) and the paper's reference values in `data/paper/`.
//! Rendering twice from the same inputs gives byte-identical files: every iteration is sorted,
//! the bootstrap is seeded, and nothing depends on the clock or the host.

pub mod aggregate;
pub mod error;
pub mod figures;
pub mod load;
pub mod markdown;
pub mod paper;
pub mod stats;

use std::path::{Path, PathBuf};

pub use error::ReportError;

/// What to render, from where, to where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportOptions {
    /// The results store: run files at the top level and/or one sub-directory down (one per campaign).
    pub results: PathBuf,
    /// Where `REPORT.md` and `figures/*.svg` are written (created if missing).
    pub out: PathBuf,
    /// The paper's reference values (`klc_final.csv`); a missing directory is reported, not fatal.
    pub paper_dir: PathBuf,
    /// Seed of the bootstrap (each condition and epoch derives its own stream from it).
    pub bootstrap_seed: u64,
    /// Bootstrap resamples per confidence interval.
    pub n_boot: usize,
}

impl ReportOptions {
    /// Defaults: `paper_dir` = `data/paper`, bootstrap seed 0, 10,000 resamples.
    pub fn new(results: PathBuf, out: PathBuf) -> Self {
        ReportOptions {
            results,
            out,
            paper_dir: PathBuf::from("data/paper"),
            bootstrap_seed: 0,
            n_boot: 10_000,
        }
    }
}

/// What `render_report` did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportSummary {
    /// Complete runs read from the store.
    pub n_runs: usize,
    /// Files written (`REPORT.md` first, then the figures), sorted, under `opts.out`.
    pub files: Vec<PathBuf>,
}

/// Reads the store, computes the statistics, writes `out/REPORT.md` and `out/figures/*.svg`.
pub fn render_report(opts: &ReportOptions) -> Result<ReportSummary, ReportError> {
    if opts.n_boot == 0 {
        return Err(ReportError::Options("n_boot must be at least 1".into()));
    }
    let store = load::load_store(&opts.results)?;
    let paper = paper::load_paper(&opts.paper_dir)?;
    let conditions = aggregate::aggregate(&store, &paper, opts.bootstrap_seed, opts.n_boot);

    let fig_dir = opts.out.join("figures");
    create_dir(&fig_dir)?;

    let mut figure_files = Vec::new();
    let klc_figs = figures::klc_curves::draw_all(&conditions, &fig_dir)?;
    let outcome_figs = figures::outcomes::draw_all(&store, &conditions, &fig_dir)?;
    for f in klc_figs.iter().chain(outcome_figs.iter()) {
        figure_files.push(f.path.clone());
    }
    remove_stale_figures(&fig_dir, &figure_files)?;

    let md = markdown::render(&markdown::Inputs {
        opts,
        store: &store,
        paper: &paper,
        conditions: &conditions,
        klc_figures: &klc_figs,
        outcome_figures: &outcome_figs,
    });
    let report_path = opts.out.join("REPORT.md");
    write_file(&report_path, md.as_bytes())?;

    figure_files.sort();
    let mut files = vec![report_path];
    files.extend(figure_files);
    Ok(ReportSummary {
        n_runs: store.runs.len(),
        files,
    })
}

fn create_dir(dir: &Path) -> Result<(), ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    std::fs::write(path, bytes).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Figures of an earlier render whose condition is gone would otherwise linger (and be committed):
/// remove our own figure files (`klc_*.svg`, `outcomes_*.svg`) that this render did not write.
fn remove_stale_figures(fig_dir: &Path, written: &[PathBuf]) -> Result<(), ReportError> {
    let entries = std::fs::read_dir(fig_dir).map_err(|source| ReportError::Io {
        path: fig_dir.to_path_buf(),
        source,
    })?;
    let mut stale = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        let ours =
            name.ends_with(".svg") && (name.starts_with("klc_") || name.starts_with("outcomes_"));
        if ours && !written.contains(&path) {
            stale.push(path);
        }
    }
    stale.sort();
    for path in stale {
        tracing::info!(path = %path.display(), "removing stale figure");
        std::fs::remove_file(&path).map_err(|source| ReportError::Io { path, source })?;
    }
    Ok(())
}
