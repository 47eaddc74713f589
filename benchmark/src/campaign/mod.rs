//! Campaigns: configuration, the run matrix, running and storing results
//! (DESIGN.md: `config -> plan -> runner -> store`).

pub mod config;
pub mod plan;
pub mod runner;
pub mod store;

pub use config::{CampaignConfig, ConfigError};
pub use plan::{plan, RunSpec};
pub use runner::{execute, explore, run_campaign, CampaignOptions, Progress, RunContext, RunError};
pub use store::{Manifest, Summary};
