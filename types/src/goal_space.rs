//! The goal-space figure data a campaign writes beside its runs, in `DIR/goal_spaces/`: for
//! seed 0 of every learned cell, the latents of a lattice of object positions (what `ugl embed
//! --grid 21` prints) and, for learners with a decoder, a reconstruction figure.

use serde::{Deserialize, Serialize};

/// The directory of the samples in a results store.
pub const GOAL_SPACE_DIR: &str = "goal_spaces";

/// The goal-space figure data of one representation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GoalSpaceSample {
    /// `armball.rge-vae.faithful.l10.s0`.
    pub representation: String,
    pub env: String,
    pub algo: String,
    /// `faithful`, `corrected` or `none`.
    pub variant: String,
    pub latents: usize,
    pub seed: u64,
    /// Positions per side of the lattice.
    pub grid: usize,
    /// The lattice's object positions (x, y), x-major.
    pub positions: Vec<[f64; 2]>,
    /// Their latents, one row per position (f32: figure data).
    pub grid_latents: Vec<Vec<f32>>,
    /// File name (in the same directory) of the reconstruction figure, if the learner has a
    /// decoder.
    pub reconstructions: Option<String>,
}
