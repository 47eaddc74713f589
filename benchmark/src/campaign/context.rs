//! The context of a run: everything a run depends on besides its identity, and the config
//! hash that fingerprints it; and the harness, the services of an execution declared once.

use std::path::Path;
use std::sync::Arc;

use serde::Serialize;

use super::config::{CampaignConfig, LearnersConfig, UglConfig};
use super::plan::RunSpec;
use crate::env::{EnvConfig, RunConstants};
use crate::explore::{ExploreConfig, MgeConfig};
use crate::repr::FitContext;
use crate::repr::cache::ModelCache;
use crate::repr::external::LineSink;
use crate::repr::neural::{self, TrainProgress};
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
    env: RunConstants,
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

/// The services of an execution, declared once for a single run (`ugl run`, `ugl embed`), a
/// campaign and a diagnostics refresh: the model cache and its checkpoints, where training
/// progress, learner messages and logs go. A learner sees its part through
/// [`Harness::fit_context`].
#[derive(Clone, Default)]
pub struct Harness<'a> {
    /// Profile name recorded in manifests.
    pub profile: &'a str,
    /// Where trained neural models are kept (None: always train).
    pub cache: Option<&'a ModelCache>,
    /// Neural trainings save a checkpoint in the model cache every this many iterations
    /// (0: never); a killed training resumes from its latest one, bit-identically.
    pub checkpoint_every: usize,
    /// Keep every checkpoint ([`neural::CheckpointSpec::keep`]).
    pub keep_checkpoints: bool,
    /// Training progress of neural representations.
    pub train_progress: Option<Arc<TrainSink>>,
    /// External learners' stderr lines, as they come.
    pub learner_messages: Option<Arc<MessageSink>>,
    /// Where an external learner's stderr is kept: `<log_dir>/<representation label>.learner.log`
    /// (None: not kept; a campaign's is its results directory).
    pub log_dir: Option<&'a Path>,
    /// Threads of a neural training: 0 = the calling pool's (a campaign's workers each have a
    /// pool of `cores / jobs` threads: two 1-thread trainings side by side beat one 2-thread
    /// training on 2 cores: measured with burn's `flex` backend on a 70x70 conv VAE, two
    /// concurrent 1-thread jobs made 2.6 iterations/s in all, one 2-thread job 1.67).
    pub train_threads: usize,
}

impl Harness<'_> {
    /// What the fit of the representation `label` gets: its progress and messages under the
    /// label, its log file, checkpoints in the model cache under `key` when the learner's
    /// encoders are kept there (`persists`), the training's threads, the pictures' shape.
    pub fn fit_context(
        &self,
        label: &str,
        key: &str,
        persists: bool,
        image: ugl_types::ImageShape,
    ) -> FitContext {
        FitContext {
            progress: self.train_progress.as_ref().map(|sink| {
                let (sink, label) = (sink.clone(), label.to_string());
                Arc::new(move |p: TrainProgress| sink(&label, p)) as neural::ProgressFn
            }),
            checkpoint: self
                .cache
                .filter(|_| persists && self.checkpoint_every > 0)
                .map(|c| neural::CheckpointSpec {
                    dir: c.dir.clone(),
                    key: key.to_string(),
                    every: self.checkpoint_every,
                    keep: self.keep_checkpoints,
                }),
            threads: self.train_threads,
            log_file: self.log_dir.map(|d| d.join(format!("{label}.learner.log"))),
            messages: self.learner_messages.as_ref().map(|sink| {
                let (sink, label) = (sink.clone(), label.to_string());
                LineSink(Arc::new(move |line| sink(&label, Some(line))))
            }),
            image: Some(image),
        }
    }
}

/// Everything needed to execute one run: the configuration it depends on and the harness.
#[derive(Clone)]
pub struct RunContext<'a> {
    pub campaign: &'a str,
    pub campaign_seed: u64,
    pub explore: &'a ExploreConfig,
    pub env: &'a EnvConfig,
    pub ugl: &'a UglConfig,
    pub learners: &'a LearnersConfig,
    /// Modular goal exploration's constants (`mge-*` algorithms).
    pub mge: &'a MgeConfig,
    /// Threads recorded in manifests: a campaign's jobs, the machine's for a single run.
    pub threads: usize,
    /// The campaign's declared role, recorded in every manifest (None: a single `ugl run`).
    pub role: Option<CampaignDecl>,
    /// The services the run uses.
    pub harness: Harness<'a>,
}

impl<'a> RunContext<'a> {
    /// The context of a single run of `cfg` (no role) with `threads` and `harness`.
    pub fn new(cfg: &'a CampaignConfig, threads: usize, harness: Harness<'a>) -> Self {
        RunContext {
            campaign: &cfg.campaign.name,
            campaign_seed: cfg.campaign.seed,
            explore: &cfg.explore,
            env: &cfg.env,
            ugl: &cfg.ugl,
            learners: &cfg.learners,
            mge: &cfg.mge,
            threads,
            role: None,
            harness,
        }
    }
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
