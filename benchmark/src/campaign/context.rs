//! The context of a run: everything a run depends on besides its identity, and the config
//! hash that fingerprints it.

use std::path::Path;
use std::sync::Arc;

use serde::Serialize;

use super::config::{LearnersConfig, UglConfig};
use super::plan::RunSpec;
use crate::env::EnvConfig;
use crate::explore::{ExploreConfig, MgeConfig};
use crate::repr::cache::ModelCache;
use crate::repr::neural::TrainProgress;
use ugl_types::CampaignDecl;

use ugl_types::RESULTS_VERSION;

/// What a run depends on, hashed into its config hash.
#[derive(Serialize)]
struct HashInput<'a> {
    results_version: u32,
    identity: &'a str,
    campaign_seed: u64,
    explore: &'a ExploreConfig,
    /// Only the constants the run's environment uses ([`EnvConfig::relevant_to`]).
    env: EnvConfig,
    #[serde(skip_serializing_if = "Option::is_none")]
    ugl: Option<&'a UglConfig>,
    #[serde(skip_serializing_if = "Option::is_none")]
    learner: Option<serde_json::Value>,
    /// Modular explorations only.
    #[serde(skip_serializing_if = "Option::is_none")]
    mge: Option<&'a MgeConfig>,
}

/// Receives the training progress of neural representations: the representation's label
/// (`armball.rge-vae.faithful.l10.s0`) and the progress.
pub type TrainSink = dyn Fn(&str, TrainProgress) + Send + Sync;

/// Receives the stderr lines of external learners while they fit: the representation's label,
/// then `Some(line)` for each line and `None` when the fit is over.
pub type MessageSink = dyn Fn(&str, Option<&str>) + Send + Sync;

/// Everything needed to execute one run.
#[derive(Clone)]
pub struct RunContext<'a> {
    pub campaign: &'a str,
    pub campaign_seed: u64,
    pub profile: &'a str,
    pub explore: &'a ExploreConfig,
    pub env: &'a EnvConfig,
    pub ugl: &'a UglConfig,
    pub learners: &'a LearnersConfig,
    /// Modular goal exploration's constants (`mge-*` algorithms).
    pub mge: &'a MgeConfig,
    pub threads: usize,
    /// Where trained neural models are kept (None: always train).
    pub cache: Option<&'a ModelCache>,
    /// Training progress of neural representations.
    pub train_progress: Option<Arc<TrainSink>>,
    /// Threads of a neural training: 0 = the calling pool's (a campaign's workers each have a
    /// pool of `cores / jobs` threads: two 1-thread trainings side by side beat one 2-thread
    /// training on 2 cores; STACK-NOTES.md).
    pub train_threads: usize,
    /// Where an external learner's stderr is kept: `<log_dir>/<representation label>.learner.log`
    /// (the results directory; None: not kept).
    pub log_dir: Option<&'a Path>,
    /// External learners' stderr lines, as they come.
    pub learner_messages: Option<Arc<MessageSink>>,
    /// Neural trainings save a checkpoint in the model cache every this many iterations
    /// (0: never); a killed training resumes from its latest one, bit-identically.
    pub checkpoint_every: usize,
    /// The campaign's declared role, recorded in every manifest (None: a single `ugl run`).
    pub role: Option<CampaignDecl>,
}

impl RunContext<'_> {
    /// The config hash of a run: BLAKE3 of its identity, campaign seed and every constant.
    pub fn config_hash(&self, spec: &RunSpec) -> String {
        let identity = spec.identity();
        let input = HashInput {
            results_version: RESULTS_VERSION,
            identity: &identity,
            campaign_seed: self.campaign_seed,
            explore: self.explore,
            env: self.env.relevant_to(spec.env),
            // Learned goal spaces also depend on the UGL stage; baseline hashes do not.
            ugl: spec.algo.learner().map(|_| self.ugl),
            learner: spec
                .algo
                .learner()
                .map(|l| self.learners.hash_value(l, spec.variant)),
            mge: spec.algo.modules().map(|_| self.mge),
        };
        let json = serde_json::to_vec(&input).expect("config serialises");
        blake3::hash(&json).to_hex().to_string()
    }
}
