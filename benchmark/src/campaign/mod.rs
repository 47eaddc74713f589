//! Campaigns: configuration, the run matrix, running and storing results
//! (docs/architecture.md, "The science crate's layers": `config -> plan -> runner -> store`).

pub mod config;
pub mod context;
pub mod embed;
pub mod error;
pub mod execute;
pub mod fit;
pub mod goal_space;
pub mod machine;
pub mod merge;
pub mod plan;
pub mod provenance;
pub mod remeasure;
pub mod runner;
pub mod single;
pub mod slurm;
pub mod status;
pub mod store;

pub use config::{CampaignConfig, ConfigError};
pub use context::{Harness, RunContext};
pub use error::RunError;
pub use execute::{execute, explore};
pub use plan::{RunSpec, plan};
pub use runner::{CampaignOptions, Progress, check_single_run, run_campaign};
pub use store::{Manifest, Summary};
