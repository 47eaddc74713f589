//! Mid-training checkpoints of the neural learners (long trainings survive a `kill -9`).
//!
//! A checkpoint of the training keyed `KEY` (the model-cache key) after `S` iterations is the
//! directory `<dir>/KEY.ckpt.S/` with:
//! - `net.model`: the weights, in the model cache's checksummed format;
//! - `optim.bin` (host engine) or `optim.bpk` (burn engine, burn's record format, keyed by
//!   parameter ids): the optimiser's state;
//! - `state.json`, written last (atomically): the iteration count, the loss curve so far, the
//!   learner stream's seed and word position, the batch permutation, the parameter ids, and the
//!   BLAKE3 hashes of the two other files.
//!
//! On start, the latest checkpoint whose `state.json` parses and whose files match their hashes
//! is resumed; a damaged one is ignored (and an older one used). Resuming restores everything
//! the next iterations depend on, so the result is bit-identical to an uninterrupted training.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::neural_config::{Engine, Model, NeuralConfig};
use super::neural_encoder::{self, NeuralEncoder};
use super::trainer::{ResumeState, Trainer};
use super::{ImageSet, ReprError};
use crate::seed::Stream;

/// Mid-training checkpoints: where, under which key, and how often.
#[derive(Clone, Debug)]
pub struct CheckpointSpec {
    pub dir: PathBuf,
    pub key: String,
    /// Save every this many iterations (and never at the end: the model cache keeps that).
    pub every: usize,
}

#[derive(Serialize, Deserialize)]
struct State {
    key: String,
    step: usize,
    losses: Vec<(usize, f64)>,
    rng_seed: String,
    /// `u128` as a decimal string (JSON numbers are not that wide).
    rng_word_pos: String,
    perm: Vec<usize>,
    param_ids: [u64; 12],
    net_blake3: String,
    optim_blake3: String,
}

/// The optimiser state's file: burn's record format (burn engine) or the host engine's.
fn optim_file(cfg: &NeuralConfig) -> &'static str {
    match cfg.engine {
        Engine::Burn => "optim.bpk",
        Engine::Host => "optim.bin",
    }
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

fn dir_of(c: &CheckpointSpec, step: usize) -> PathBuf {
    c.dir.join(format!("{}.ckpt.{step}", c.key))
}

/// The checkpoint directories of `c.key`, newest first: (iterations, path).
fn existing(c: &CheckpointSpec) -> Vec<(usize, PathBuf)> {
    let prefix = format!("{}.ckpt.", c.key);
    let mut v: Vec<(usize, PathBuf)> = std::fs::read_dir(&c.dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().to_string();
            let step = name.strip_prefix(&prefix)?.parse().ok()?;
            Some((step, e.path()))
        })
        .collect();
    v.sort_by(|a, b| b.0.cmp(&a.0));
    v
}

fn io(what: &str, p: &Path, e: impl std::fmt::Display) -> ReprError {
    ReprError::Cache(format!("checkpoint: cannot {what} {}: {e}", p.display()))
}

/// Save the trainer's state; older checkpoints of the same key are removed afterwards.
pub fn save(
    c: &CheckpointSpec,
    trainer: &Trainer<'_>,
    rng: &Stream,
    losses: &[(usize, f64)],
) -> Result<(), ReprError> {
    let dir = dir_of(c, trainer.step);
    std::fs::create_dir_all(&dir).map_err(|e| io("create", &dir, e))?;
    let net = trainer.host_net()?;
    let enc = NeuralEncoder::new(
        trainer.model,
        trainer.cfg.variant,
        net,
        losses.to_vec(),
        [0; 32],
    );
    let net_bytes = neural_encoder::to_bytes(&c.key, &enc);
    let net_path = dir.join("net.model");
    crate::fsio::write_atomic(&net_path, &net_bytes).map_err(|e| io("write", &net_path, e))?;
    let optim_path = dir.join(optim_file(&trainer.cfg));
    trainer.save_optimizer(&optim_path)?;
    let optim_bytes = std::fs::read(&optim_path).map_err(|e| io("read", &optim_path, e))?;
    let (ids, perm) = trainer.resume_state();
    let state = State {
        key: c.key.clone(),
        step: trainer.step,
        losses: losses.to_vec(),
        rng_seed: hex(&rng.get_seed()),
        rng_word_pos: rng.get_word_pos().to_string(),
        perm: perm.to_vec(),
        param_ids: ids,
        net_blake3: blake3::hash(&net_bytes).to_hex().to_string(),
        optim_blake3: blake3::hash(&optim_bytes).to_hex().to_string(),
    };
    let json = serde_json::to_vec(&state).expect("state serialises");
    let state_path = dir.join("state.json");
    crate::fsio::write_atomic(&state_path, &json).map_err(|e| io("write", &state_path, e))?;
    for (step, old) in existing(c) {
        if step < trainer.step {
            let _ = std::fs::remove_dir_all(old);
        }
    }
    Ok(())
}

/// Remove every checkpoint of `c.key` (the training finished).
pub fn remove_all(c: &CheckpointSpec) {
    for (_, d) in existing(c) {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// The latest valid checkpoint of `c.key` as a trainer and its loss curve so far, with `rng`
/// moved to the saved position; None if there is none (or none that can be trusted).
pub fn load_latest<'a>(
    c: &CheckpointSpec,
    model: Model,
    cfg: &NeuralConfig,
    images: &'a ImageSet,
    latents: usize,
    rng: &mut Stream,
) -> Result<Option<(Trainer<'a>, Vec<(usize, f64)>)>, ReprError> {
    for (_, dir) in existing(c) {
        match try_load(c, &dir, model, cfg, images, latents, rng) {
            Ok(r) => {
                tracing::info!("resuming {} from {}", c.key, dir.display());
                return Ok(Some(r));
            }
            Err(why) => tracing::warn!("ignoring checkpoint {}: {why}", dir.display()),
        }
    }
    Ok(None)
}

fn try_load<'a>(
    c: &CheckpointSpec,
    dir: &Path,
    model: Model,
    cfg: &NeuralConfig,
    images: &'a ImageSet,
    latents: usize,
    rng: &mut Stream,
) -> Result<(Trainer<'a>, Vec<(usize, f64)>), String> {
    let text = std::fs::read(dir.join("state.json")).map_err(|e| e.to_string())?;
    let state: State = serde_json::from_slice(&text).map_err(|e| e.to_string())?;
    if state.key != c.key || state.rng_seed != hex(&rng.get_seed()) {
        return Err("written for another training".into());
    }
    if state.step == 0 || state.step >= cfg.iterations {
        return Err(format!("iteration {} out of range", state.step));
    }
    let net_bytes = std::fs::read(dir.join("net.model")).map_err(|e| e.to_string())?;
    if blake3::hash(&net_bytes).to_hex().as_str() != state.net_blake3 {
        return Err("net.model does not match its hash".into());
    }
    let optim_path = dir.join(optim_file(cfg));
    let optim_bytes = std::fs::read(&optim_path).map_err(|e| e.to_string())?;
    if blake3::hash(&optim_bytes).to_hex().as_str() != state.optim_blake3 {
        return Err(format!("{} does not match its hash", optim_path.display()));
    }
    let enc = neural_encoder::from_bytes(&c.key, &net_bytes)?;
    let word_pos: u128 = state
        .rng_word_pos
        .parse()
        .map_err(|_| "bad word position")?;
    let trainer = Trainer::resume(
        model,
        cfg,
        images,
        latents,
        ResumeState {
            net: &enc.net,
            ids: &state.param_ids,
            optimizer: &optim_path,
            perm: &state.perm,
            step: state.step,
        },
    )
    .map_err(|e| e.to_string())?;
    rng.set_word_pos(word_pos);
    Ok((trainer, state.losses))
}
