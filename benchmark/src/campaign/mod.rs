//! Campaigns: configuration, the run matrix, running and storing results
//! (DESIGN.md: `config -> plan -> runner -> store`).

pub mod config;
pub mod embed;
pub mod goal_space;
pub mod machine;
pub mod merge;
pub mod plan;
pub mod remeasure;
pub mod runner;
pub mod single;
pub mod slurm;
pub mod store;

pub use config::{CampaignConfig, ConfigError};
pub use plan::{RunSpec, plan};
pub use runner::{CampaignOptions, Progress, RunContext, RunError, execute, explore, run_campaign};
pub use store::{Manifest, Summary};
