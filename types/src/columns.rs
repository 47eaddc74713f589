//! The column names of a run's parquet files, declared once: the runner writes them
//! (`ugl_bench::campaign::store`) and the report reads them (`ugl_report::load`) through these
//! constants, so a renamed column is one edit and a typo does not compile. The schema, with what
//! each column means: `data/results/README.md`.

/// `<run_id>.parquet`: the KL-coverage curve, one row per evaluation epoch.
pub mod curve {
    pub const RUN_ID: &str = "run_id";
    pub const ENV: &str = "env";
    pub const ALGO: &str = "algo";
    pub const SAMPLER: &str = "sampler";
    pub const LATENTS: &str = "latents";
    pub const VARIANT: &str = "variant";
    pub const SEED: &str = "seed";
    pub const EPOCH: &str = "epoch";
    pub const N_OUTCOMES: &str = "n_outcomes";
    pub const KLC: &str = "klc";
    pub const N_MOVED: &str = "n_moved";
    pub const COVERAGE: &str = "coverage";
    /// Scenes with an object the agent cannot control (ArmBalls): its KL-coverage and cell
    /// coverage over the whole square.
    pub const CONTROL_KLC: &str = "control_klc";
    pub const CONTROL_COVERAGE: &str = "control_coverage";
    /// The same scenes: the follow-up's exploration ratios of the controlled object, the
    /// fraction of the cells of a 30 x 30 and of a 50 x 50 grid over the whole square that
    /// hold an outcome.
    pub const RATIO_30: &str = "ratio_30";
    pub const RATIO_50: &str = "ratio_50";
    /// The same scenes: the goal-reaching error of the controlled object's outcomes so far (the
    /// mean distance from a test goal to its nearest outcome; the manifest's
    /// `discovery.final.goal_error_mean` at the last epoch).
    pub const GOAL_ERROR: &str = "goal_error";
}

/// `<run_id>.outcomes.parquet`: every outcome, in history order.
pub mod outcomes {
    pub const RUN_ID: &str = "run_id";
    pub const INDEX: &str = "index";
    pub const EPOCH: &str = "epoch";
    pub const X: &str = "x";
    pub const Y: &str = "y";
    /// ArmArrow's angle; null elsewhere.
    pub const ANGLE: &str = "angle";
    pub const MOVED: &str = "moved";
    /// ArmBalls' distractor.
    pub const DISTRACTOR_X: &str = "distractor_x";
    pub const DISTRACTOR_Y: &str = "distractor_y";
}

/// `<run_id>.interest.parquet` (modular explorations): per evaluation epoch and module.
pub mod interest {
    pub const RUN_ID: &str = "run_id";
    pub const EPOCH: &str = "epoch";
    pub const MODULE: &str = "module";
    pub const MODULE_NAME: &str = "module_name";
    pub const DIMS: &str = "dims";
    pub const INTEREST: &str = "interest";
    pub const N_CHOSEN: &str = "n_chosen";
}
