//! ugl-types: what the runner (`ugl-bench`) writes and the report (`ugl-report`) reads, declared
//! once, with no dependency on the numeric stack (burn, faer, gemm, polars).
//!
//! - [`Manifest`]: the typed, versioned manifest of a run (older results versions read through
//!   serde defaults), with its [`Summary`] and the [`FileDigest`]s of its data files;
//! - [`RunPaths`]: the files of a run in a results directory, and [`verify_files`], the one
//!   check of those files against their manifest;
//! - [`EnvSpec`]: the environment registry (names, objects, true latent size, KL-coverage grid);
//! - [`CampaignRole`] and [`CampaignRecord`]: what a campaign is for, declared in its TOML and
//!   recorded beside its runs, so that the report never infers it from a directory name;
//! - [`LearnerInfo`]: the representation learners' names, display names and paper training;
//! - [`SamplerInfo`], [`StrategyInfo`], [`VariantInfo`]: the goal samplers, the strategies
//!   without a learned goal space (RPE, RGE-EFR) and the learners' variants;
//! - [`ConditionKey`]: a condition of the results, of typed names ([`Algo`], [`Sampler`],
//!   [`Variant`]) that know their registry entries;
//! - [`Diagnostics`]: measures taken after a run, beside it (manifests are immutable);
//! - [`RunDiscovery`]: what a run discovered (KL-coverage, cells, goal-reaching error), measured
//!   from its [`Outcome`]s by [`EnvMeasures`], recorded in its manifest;
//! - [`GoalSpaceSample`]: the goal-space figure data a campaign writes beside its runs;
//! - [`TrainingRecord`]: how a run's trained network was obtained (its manifest's `train`).
//! - [`ConvInit`]: which PyTorch initialisation drew a convolutional network.
//!
//! ```
//! let ball = ugl_types::EnvSpec::by_name("armball").unwrap();
//! assert_eq!((ball.display, ball.true_latents, ball.klc.achievable_cells), ("ArmBall", 2, 756));
//! assert_eq!(ugl_types::EnvSpec::by_name("armarrow").unwrap().klc.achievable_cells, 22_680);
//! ```

mod campaign;
pub mod columns;
mod condition;
mod conv_init;
mod diagnostics;
mod discovery;
mod env;
mod goal_space;
pub mod klc;
mod learner;
mod manifest;
pub mod nn;
mod paths;
mod quality;
mod sampler;
mod strategy;
mod summary;
mod training;

pub use campaign::{CampaignDecl, CampaignRecord, CampaignRole, RECORD_FILE, RecordError};
pub use condition::{Algo, AlgoInfo, ConditionKey, Sampler, Variant};
pub use conv_init::ConvInit;
pub use diagnostics::{DIAGNOSTICS_DIR, Diagnostics};
pub use discovery::{
    Discovery, DiscoveryError, EnvMeasures, GOAL_OTHER_BINS, GOAL_POSITION_BINS, GoalGrid, Outcome,
    RecordMismatch, RunDiscovery, median, quantile_sorted,
};
pub use env::{
    ARMARROW, ARMBALL, ARMBALLS, ARMBALLS_CORL, BUILT_IN, DISK, DMP_PARAMS, EnvSpec, EnvSpecError,
    GRAY70, ImageShape, KlcGrid, ObjectSpec, RGB64, environments,
};
pub use goal_space::{GOAL_SPACE_DIR, GoalSpaceSample};
pub use learner::{LEARNERS, LearnerInfo, PaperTraining, Prior};
/// Each learner's entry, by name (`ugl_types::learners::VAE`).
pub mod learners {
    pub use crate::learner::{
        AE, BVAE, CONV_BVAE, CONV_VAE, EXTERNAL, GAUSSIAN_PROJECTION, ISOMAP, PCA, PCA_CENTRED,
        RFVAE, VAE,
    };
}
pub use quality::{Disentanglement, GroupR2, LatentQuality, Neighbourhoods, ObjectR2};
pub use sampler::{SAMPLERS, SamplerInfo, SamplerInfoError};
/// Each goal sampler's entry, by name (`ugl_types::samplers::KDE`).
pub mod samplers {
    pub use crate::sampler::{GAUSSIAN, KDE, NONE, UNIFORM};
}
pub use manifest::{CpuInfo, FileDigest, FutureResults, Manifest, RESULTS_VERSION, Summary};
pub use paths::{
    CURVE_SUFFIX, DigestError, INTEREST_SUFFIX, MANIFEST_SUFFIX, OUTCOMES_SUFFIX, RunPaths,
    run_paths, verify_files,
};
pub use strategy::{
    CORRECTED, ENGINEERED_SPACE, FAITHFUL, FLAT, LEARNING_PROGRESS, MIXED_SPACE, MODULAR_PREFIX,
    MODULE_CHOICES, ModuleChoiceInfo, NO_VARIANT, RANDOM_MODULE, RGE_EFR, RGE_EFR_MIXED,
    RGE_EFR_POSITION, RPE, STRATEGIES, StrategyInfo, VARIANTS, VariantInfo,
};
pub use training::{CacheStatus, TrainingEvidence, TrainingRecord, UNTRAINED_FRACTION};
