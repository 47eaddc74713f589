//! Mid-training checkpoints of the neural learners (long trainings survive a `kill -9`).
//!
//! A checkpoint of the training keyed `KEY` (the model-cache key) after `S` iterations is the
//! directory `<dir>/KEY.ckpt.S/` with:
//! - `net.model`: the weights, in the model cache's checksummed format;
//! - `optim.bin` (host engine) or `optim.bpk` (burn engine, burn's record format, keyed by
//!   parameter ids): the optimiser's state;
//! - `state.json`, written last (atomically): the iteration count, the loss curve so far, the
//!   learner stream's seed and word position, the batch permutation, the parameter ids, and the
//!   BLAKE3 hashes of the two other files; sealed by the BLAKE3 digest of all of it
//!   (`{"state": ..., "blake3": ...}`, the digest over the state's JSON as this module writes
//!   it), so that the state is as trusted as the weights and the optimiser.
//!
//! On start, the latest checkpoint whose `state.json` parses, matches its digest, fits the
//! training (a permutation of its images, an iteration inside it, a loss curve before it) and
//! whose files match their hashes is resumed; a damaged or inconsistent one is reported (one
//! warning) and ignored, and an older one used or the training started over. Resuming restores
//! everything the next iterations depend on, so the result is bit-identical to an
//! uninterrupted training (tested, with damaged checkpoints too).

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
    /// Keep every checkpoint, also after the training finished, to look at the network part-way
    /// (`ugl embed --checkpoint`); otherwise a checkpoint replaces the older ones and the
    /// finished training removes the last.
    pub keep: bool,
}

/// `state.json`: the state and the BLAKE3 digest of its JSON ([`digest`]).
#[derive(Serialize, Deserialize)]
struct Sealed {
    state: State,
    blake3: String,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
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

/// The digest sealing a state: BLAKE3 of its JSON (field order of [`State`], floats written
/// shortest-round-trip, so a state read back gives the same bytes).
fn digest(state: &State) -> String {
    let json = serde_json::to_vec(state).expect("state serialises");
    blake3::hash(&json).to_hex().to_string()
}

/// The state of a `state.json`, if it matches its digest and fits a training of `iterations`
/// iterations on `images` images; `Err` says why it cannot be trusted.
fn verify(bytes: &[u8], iterations: usize, images: usize) -> Result<State, String> {
    let sealed: Sealed = serde_json::from_slice(bytes).map_err(|e| e.to_string())?;
    let state = sealed.state;
    if digest(&state) != sealed.blake3 {
        return Err("state.json does not match its digest".into());
    }
    if state.step == 0 || state.step >= iterations {
        return Err(format!("iteration {} out of range", state.step));
    }
    let mut seen = vec![false; images];
    if state.perm.len() != images
        || !state
            .perm
            .iter()
            .all(|&i| i < images && !std::mem::replace(&mut seen[i], true))
    {
        return Err(format!(
            "the batch permutation is not one of the {images} images"
        ));
    }
    if !state.losses.windows(2).all(|w| w[0].0 < w[1].0)
        || state
            .losses
            .iter()
            .any(|&(i, l)| i >= state.step || !l.is_finite())
    {
        return Err("the loss curve does not fit the iterations done".into());
    }
    Ok(state)
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
    v.sort_by_key(|e| std::cmp::Reverse(e.0));
    v
}

fn io(what: &str, p: &Path, e: impl std::fmt::Display) -> ReprError {
    ReprError::Cache(format!("checkpoint: cannot {what} {}: {e}", p.display()))
}

/// A training's state at a checkpoint, besides the stream (any trainer: the dense networks',
/// the convolutional ones').
pub(crate) struct Snapshot<'s> {
    /// Iterations done.
    pub step: usize,
    pub losses: &'s [(usize, f64)],
    /// The batch permutation.
    pub perm: &'s [usize],
    /// burn's parameter ids (zeros where there are none).
    pub param_ids: [u64; 12],
    /// The weights, as a sealed model file.
    pub net: Vec<u8>,
    /// The optimiser state's file name in the checkpoint directory.
    pub optim_file: &'static str,
}

/// What a trusted checkpoint gives back to the trainer that resumes it.
pub(crate) struct Restored<'s> {
    pub step: usize,
    pub perm: &'s [usize],
    pub param_ids: &'s [u64; 12],
    /// The weights' model file (its hash checked).
    pub net: &'s [u8],
    /// The optimiser state's file (its hash checked).
    pub optim: &'s Path,
}

/// Save the trainer's state; older checkpoints of the same key are removed afterwards.
pub fn save(
    c: &CheckpointSpec,
    trainer: &Trainer<'_>,
    rng: &Stream,
    losses: &[(usize, f64)],
) -> Result<(), ReprError> {
    let net = trainer.host_net()?;
    let enc = NeuralEncoder::new(
        trainer.model,
        trainer.cfg.variant,
        net,
        losses.to_vec(),
        [0; 32],
    );
    let (ids, perm) = trainer.resume_state();
    let snapshot = Snapshot {
        step: trainer.step,
        losses,
        perm,
        param_ids: ids,
        net: neural_encoder::to_bytes(&c.key, &enc),
        optim_file: optim_file(&trainer.cfg),
    };
    save_snapshot(c, snapshot, rng, |path| trainer.save_optimizer(path))
}

/// Save a training's state: the weights, the optimiser's (`write_optim` writes its file), then
/// the sealed `state.json`; older checkpoints of the same key are removed afterwards.
pub(crate) fn save_snapshot(
    c: &CheckpointSpec,
    snapshot: Snapshot<'_>,
    rng: &Stream,
    write_optim: impl FnOnce(&Path) -> Result<(), ReprError>,
) -> Result<(), ReprError> {
    let dir = dir_of(c, snapshot.step);
    std::fs::create_dir_all(&dir).map_err(|e| io("create", &dir, e))?;
    let net_path = dir.join("net.model");
    crate::fsio::write_atomic(&net_path, &snapshot.net).map_err(|e| io("write", &net_path, e))?;
    let optim_path = dir.join(snapshot.optim_file);
    write_optim(&optim_path)?;
    let optim_bytes = std::fs::read(&optim_path).map_err(|e| io("read", &optim_path, e))?;
    let state = State {
        key: c.key.clone(),
        step: snapshot.step,
        losses: snapshot.losses.to_vec(),
        rng_seed: hex(&rng.get_seed()),
        rng_word_pos: rng.get_word_pos().to_string(),
        perm: snapshot.perm.to_vec(),
        param_ids: snapshot.param_ids,
        net_blake3: blake3::hash(&snapshot.net).to_hex().to_string(),
        optim_blake3: blake3::hash(&optim_bytes).to_hex().to_string(),
    };
    let sealed = Sealed {
        blake3: digest(&state),
        state,
    };
    let json = serde_json::to_vec(&sealed).expect("state serialises");
    let state_path = dir.join("state.json");
    crate::fsio::write_atomic(&state_path, &json).map_err(|e| io("write", &state_path, e))?;
    if !c.keep {
        for (step, old) in existing(c) {
            if step < snapshot.step {
                let _ = std::fs::remove_dir_all(old);
            }
        }
    }
    Ok(())
}

/// A checkpoint read back to be looked at, not resumed (`ugl embed --checkpoint`).
#[derive(Debug)]
pub struct Inspected {
    /// Iterations done.
    pub step: usize,
    /// The loss curve so far.
    pub losses: Vec<(usize, f64)>,
    /// The weights, as the trainer sealed them (the learner reads them:
    /// [`super::RepresentationLearner::load_checkpoint`]).
    pub net: Vec<u8>,
}

/// The checkpoint of the training keyed `key` after `step` iterations, in the model cache
/// `dir`, with the checks of a resume (its seal, its key, a batch permutation of `images`
/// images, the weights' hash); `Err` says what is missing, with the iterations of the
/// checkpoints `dir` holds of that training, or why the checkpoint cannot be trusted.
pub fn inspect(dir: &Path, key: &str, step: usize, images: usize) -> Result<Inspected, ReprError> {
    let c = CheckpointSpec {
        dir: dir.to_path_buf(),
        key: key.to_string(),
        every: 0,
        keep: true,
    };
    let at = dir_of(&c, step);
    let state_path = at.join("state.json");
    if !state_path.is_file() {
        let mut held: Vec<usize> = existing(&c).into_iter().map(|(s, _)| s).collect();
        held.sort_unstable();
        let held = if held.is_empty() {
            "none of this network".to_string()
        } else {
            let list: Vec<String> = held.iter().map(|s| s.to_string()).collect();
            format!("this network's after {} iterations", list.join(", "))
        };
        return Err(ReprError::InvalidInput(format!(
            "no checkpoint after {step} iterations in {} (it holds {held}; a finished training \
             removes its checkpoints unless they are kept: --keep-checkpoints)",
            dir.display()
        )));
    }
    let untrusted = |why: String| ReprError::Cache(format!("checkpoint {}: {why}", at.display()));
    let text = std::fs::read(&state_path).map_err(|e| io("read", &state_path, e))?;
    let state = verify(&text, usize::MAX, images).map_err(untrusted)?;
    if state.key != key || state.step != step {
        return Err(untrusted("written for another training".into()));
    }
    let net_path = at.join("net.model");
    let net = std::fs::read(&net_path).map_err(|e| io("read", &net_path, e))?;
    if blake3::hash(&net).to_hex().as_str() != state.net_blake3 {
        return Err(untrusted("net.model does not match its hash".into()));
    }
    Ok(Inspected {
        step,
        losses: state.losses,
        net,
    })
}

/// Remove every checkpoint of `c.key` (the training finished), unless they are kept.
pub fn remove_all(c: &CheckpointSpec) {
    if c.keep {
        return;
    }
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
    let optim = optim_file(cfg);
    load_latest_with(c, cfg.max_iterations(), images.n, optim, rng, |r| {
        let enc = neural_encoder::from_bytes(&c.key, r.net).map_err(|e| e.to_string())?;
        Trainer::resume(
            model,
            cfg,
            images,
            latents,
            ResumeState {
                net: &enc.net,
                ids: r.param_ids,
                optimizer: r.optim,
                perm: r.perm,
                step: r.step,
            },
        )
        .map_err(|e| e.to_string())
    })
}

/// The latest checkpoint of `c.key` that can be trusted (a training of at most `iterations`
/// iterations on `images` images, with the optimiser file `optim_file`), rebuilt by `resume`,
/// with its loss curve so far and `rng` moved to the saved position; None if there is none.
/// A damaged or inconsistent checkpoint is reported (one warning) and skipped.
pub(crate) fn load_latest_with<T>(
    c: &CheckpointSpec,
    iterations: usize,
    images: usize,
    optim_file: &str,
    rng: &mut Stream,
    mut resume: impl FnMut(&Restored<'_>) -> Result<T, String>,
) -> Result<Option<(T, Vec<(usize, f64)>)>, ReprError> {
    for (_, dir) in existing(c) {
        match try_load(c, &dir, iterations, images, optim_file, rng, &mut resume) {
            Ok(r) => {
                tracing::info!("resuming {} from {}", c.key, dir.display());
                return Ok(Some(r));
            }
            Err(why) => tracing::warn!("ignoring checkpoint {}: {why}", dir.display()),
        }
    }
    Ok(None)
}

fn try_load<T>(
    c: &CheckpointSpec,
    dir: &Path,
    iterations: usize,
    images: usize,
    optim_file: &str,
    rng: &mut Stream,
    resume: &mut impl FnMut(&Restored<'_>) -> Result<T, String>,
) -> Result<(T, Vec<(usize, f64)>), String> {
    let text = std::fs::read(dir.join("state.json")).map_err(|e| e.to_string())?;
    let state = verify(&text, iterations, images)?;
    if state.key != c.key || state.rng_seed != hex(&rng.get_seed()) {
        return Err("written for another training".into());
    }
    let net_bytes = std::fs::read(dir.join("net.model")).map_err(|e| e.to_string())?;
    if blake3::hash(&net_bytes).to_hex().as_str() != state.net_blake3 {
        return Err("net.model does not match its hash".into());
    }
    let optim_path = dir.join(optim_file);
    let optim_bytes = std::fs::read(&optim_path).map_err(|e| e.to_string())?;
    if blake3::hash(&optim_bytes).to_hex().as_str() != state.optim_blake3 {
        return Err(format!("{} does not match its hash", optim_path.display()));
    }
    let word_pos: u128 = state
        .rng_word_pos
        .parse()
        .map_err(|_| "bad word position")?;
    let trainer = resume(&Restored {
        step: state.step,
        perm: &state.perm,
        param_ids: &state.param_ids,
        net: &net_bytes,
        optim: &optim_path,
    })?;
    rng.set_word_pos(word_pos);
    Ok((trainer, state.losses))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> State {
        State {
            key: "k".into(),
            step: 40,
            losses: vec![(0, 3.5), (5, 0.1 + 0.2), (39, 1e-300)],
            rng_seed: "00".into(),
            rng_word_pos: "340282366920938463463374607431768211455".into(),
            perm: vec![2, 0, 3, 1],
            param_ids: [7; 12],
            net_blake3: "n".into(),
            optim_blake3: "o".into(),
        }
    }

    fn seal(state: State) -> Vec<u8> {
        serde_json::to_vec(&Sealed {
            blake3: digest(&state),
            state,
        })
        .unwrap()
    }

    /// A sealed state reads back (its digest survives the round trip through JSON); one whose
    /// digest is stale, or that is consistently sealed but does not fit the training (a
    /// hand-made or buggy writer), is refused with the reason.
    #[test]
    fn the_state_is_sealed_and_checked_against_the_training() {
        let good = seal(state());
        assert_eq!(verify(&good, 60, 4).unwrap().perm, [2, 0, 3, 1]);
        let stale = String::from_utf8(good)
            .unwrap()
            .replace("\"step\":40", "\"step\":39");
        assert!(
            verify(stale.as_bytes(), 60, 4)
                .unwrap_err()
                .contains("digest")
        );
        let bad: [(fn(&mut State), &str); 6] = [
            (|s| s.perm[0] = 4, "permutation"),
            (|s| s.perm[0] = 0, "permutation"),
            (
                |s| {
                    s.perm.pop();
                },
                "permutation",
            ),
            (|s| s.step = 60, "out of range"),
            (|s| s.step = 0, "out of range"),
            (|s| s.losses[1].0 = 45, "loss curve"),
        ];
        for (damage, why) in bad {
            let mut s = state();
            damage(&mut s);
            let e = verify(&seal(s), 60, 4).unwrap_err();
            assert!(e.contains(why), "{e} should say {why}");
        }
        let unsealed = serde_json::to_vec(&state()).unwrap();
        assert!(
            verify(&unsealed, 60, 4).is_err(),
            "a state without its digest"
        );
    }
}
