//! The report's error type: every variant names the file (and column or line) at fault.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("results directory {0} does not exist or is not a directory")]
    NoResultsDir(PathBuf),

    #[error(
        "no runs found in {0}: expected <run_id>.parquet, <run_id>.outcomes.parquet and \
         <run_id>.json at its top level or in its sub-directories (one per campaign)"
    )]
    EmptyResults(PathBuf),

    #[error(
        "no complete run in {dir}: {incomplete} run(s) lack one of their three files \
         (<run_id>.parquet, <run_id>.outcomes.parquet, <run_id>.json); is the campaign still running?"
    )]
    NoCompleteRuns { dir: PathBuf, incomplete: usize },

    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    #[error("{path}: not a readable parquet file: {message}")]
    Parquet { path: PathBuf, message: String },

    #[error("{path}: column `{column}`: {problem}")]
    Column {
        path: PathBuf,
        column: String,
        problem: String,
    },

    #[error("{path}: {problem}")]
    Invalid { path: PathBuf, problem: String },

    #[error("{path}: not a valid JSON manifest: {source}")]
    Manifest {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },

    #[error(
        "main campaign `{main}` not found in {dir}: campaigns found: {}; choose one with \
         --main NAME",
        if found.is_empty() { "none".to_string() } else { found.join(", ") }
    )]
    MissingMainCampaign {
        dir: PathBuf,
        main: String,
        /// Campaigns holding run files, sorted (`(top level)` for runs directly in `dir`).
        found: Vec<String>,
    },

    #[error("run `{run_id}` appears twice in one campaign: {first} and {second}")]
    DuplicateRun {
        run_id: String,
        first: PathBuf,
        second: PathBuf,
    },

    #[error("{path}, line {line}: {problem}")]
    Paper {
        path: PathBuf,
        line: usize,
        problem: String,
    },

    #[error("{path}: drawing failed: {message}")]
    Plot { path: PathBuf, message: String },

    #[error("invalid report options: {0}")]
    Options(String),
}
