//! `ugl embed`: the latents of a fitted goal space, for figures and for comparing embeddings
//! (the paper's Figure 3 argument: a good goal space lays the object's positions out smoothly).
//!
//! The representation is fitted exactly as for a run of the same cell and seed (same data set,
//! same learner stream, same model cache), then encodes:
//! - the training images (the UGL data set), with their true states;
//! - a `grid x grid` lattice of object positions over [-1, 1]^2 (ArmArrow: angle 0), with its
//!   states.

use std::path::Path;

use super::context::RunContext;
use super::fit::{Source, fit_with_data};
use super::plan::RunSpec;
use crate::env::{Environment, make_env};
use crate::repr::quality::LatentQuality;
use crate::repr::{ImageSet, Latents, ReprError};
use crate::seed::{Component, stream};
use ugl_types::TrainingRecord;

/// What `ugl embed` writes.
pub struct Embedding {
    pub state_dim: usize,
    /// Encodings of the training images, and their states (row-major `n x state_dim`).
    pub train: Latents,
    pub train_states: Vec<f64>,
    /// Encodings of the grid images, and their states.
    pub grid: Latents,
    pub grid_states: Vec<f64>,
    /// The representation's held-out latent quality, if measured.
    pub quality: Option<LatentQuality>,
    /// A neural network's training: its iterations, loss curve and evidence.
    pub training: Option<TrainingRecord>,
}

/// Fit (or load) the representation of `spec`, or read it from `source`'s checkpoint, and
/// encode its training images and a grid of `grid x grid` object positions. A stochastic
/// encoder draws its noise from the data set's encoding stream.
pub fn embed(
    spec: &RunSpec,
    ctx: &RunContext,
    grid: usize,
    source: Source,
) -> Result<Embedding, ReprError> {
    if grid < 2 {
        return Err(ReprError::InvalidInput(format!(
            "the grid needs at least 2 x 2 positions, got {grid}"
        )));
    }
    crate::limits::check_grid(grid, ctx.ugl.images, spec.env.spec().image.len())
        .map_err(|e| ReprError::InvalidInput(e.to_string()))?;
    let (mut repr, data, ds_seed) = fit_with_data(spec, ctx, source)?;
    let env = make_env(spec.env, ctx.env);
    let d = env.state_dim();
    repr.encoder.begin_run(stream(ds_seed, Component::Encoding));
    let train = repr.encoder.encode(&data.images)?;
    let (grid_states, grid_images) = grid_images(env.as_ref(), grid)?;
    let grid_latents = repr.encoder.encode(&grid_images)?;
    Ok(Embedding {
        state_dim: d,
        train,
        train_states: data.states,
        grid: grid_latents,
        grid_states,
        quality: repr.quality,
        training: repr.training,
    })
}

/// The `grid x grid` lattice of object positions over [-1, 1]^2 (other state coordinates 0: the
/// arrow's angle), x-major: its states (row-major `grid^2 x state_dim`) and rendered images.
pub fn grid_images(env: &dyn Environment, grid: usize) -> Result<(Vec<f64>, ImageSet), ReprError> {
    let d = env.state_dim();
    let mut states = Vec::with_capacity(grid * grid * d);
    let values = env.image_len();
    let mut pixels = vec![0f32; grid * grid * values];
    for (k, img) in pixels.chunks_exact_mut(values).enumerate() {
        let (i, j) = (k / grid, k % grid);
        let at = |t: usize| -1.0 + 2.0 * t as f64 / (grid - 1) as f64;
        let mut s = vec![at(i), at(j)];
        s.resize(d, 0.0);
        env.render_into(&s, img);
        states.extend_from_slice(&s);
    }
    Ok((states, ImageSet::new(grid * grid, values, pixels)?))
}

/// Write a float64 `rows x cols` array as .npy (C order): [`crate::npy::write_npy_f64_file`].
pub fn write_npy_f64(path: &Path, rows: usize, cols: usize, data: &[f64]) -> std::io::Result<()> {
    crate::npy::write_npy_f64_file(path, rows, cols, data)
}
