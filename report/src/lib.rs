//! `ugl-report`: reads the ugl-bench results store, computes statistics over seeds, draws the
//! paper's figures as SVG and writes `REPORT.md`.
//!
//! The report never re-runs science: its only inputs are the run files of the results store
//! (`data/results/README.md` documents them) and the paper's reference values in `data/paper/`.
//! Rendering twice from the same inputs gives byte-identical files: every iteration is sorted,
//! the bootstrap is seeded, and nothing depends on the clock or the host.

pub mod aggregate;
pub mod armballs;
pub mod campaigns;
pub mod claims;
pub mod context;
pub mod data;
pub mod discovery;
pub mod error;
pub mod figures;
pub mod leaderboard;
pub mod load;
pub mod markdown;
pub mod names;
pub mod neural;
pub mod options;
pub mod output;
pub mod paper;
pub mod predicts;
pub mod render;
pub mod sections;
pub mod stats;

pub use error::ReportError;
pub use options::ReportOptions;
pub use render::{LEADERBOARD_CONFIDENCE, REPORT_FILE, ReportSummary, compare_page, render_report};
