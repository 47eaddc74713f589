//! Goal-space figure data (what the trained goal spaces look like). The paper argues that a learned
//! goal space is good when it lays the object's positions out smoothly, and shows what its
//! networks reconstruct. For the first repetition (seed 0) of every learned cell, a campaign
//! writes beside its runs, in `DIR/goal_spaces/`:
//! - `<label>.json` ([`GoalSpaceSample`]): the latents of a [`GRID`] x [`GRID`] lattice of
//!   object positions over [-1, 1]^2 (ArmArrow: angle 0), exactly what `ugl embed --grid 21`
//!   prints for that cell and seed;
//! - `<label>.reconstructions.png` (learners with a decoder): [`RECONSTRUCTIONS`] held-out
//!   images (top row) above their reconstructions from the noise-free code (bottom row).
//!
//! The report draws them. None of it changes a run: the encoder is reset before every run
//! ([`crate::repr::Encoder::begin_run`]).

use std::path::{Path, PathBuf};

use super::context::RunContext;
use super::embed::grid_images;
use super::fit::{Representation, representation_label};
use super::plan::RunSpec;
use super::store;
use crate::env::{cdge, make_env, render};
use crate::repr::ReprError;
use crate::repr::dataset::{dataset_identity, generate};
use crate::seed::{Component, run_seed, stream};

/// Positions per side of the lattice.
pub const GRID: usize = 21;
/// Held-out images reconstructed.
pub const RECONSTRUCTIONS: usize = 8;
/// The directory of the samples in a results store.
pub const DIR_NAME: &str = ugl_types::GOAL_SPACE_DIR;

pub use ugl_types::GoalSpaceSample;

/// A writer of a grid of pictures as one PNG (pictures, columns, upscaling, path).
type GridWriter = fn(&[&[f32]], usize, usize, &Path) -> Result<(), render::RenderError>;

/// Whether a campaign keeps figure data for this run's representation: seed 0 of learned cells.
pub fn wanted(spec: &RunSpec) -> bool {
    spec.seed == 0 && spec.algo.learner().is_some()
}

/// The sample's path in a results directory.
pub fn sample_path(out: &Path, spec: &RunSpec) -> PathBuf {
    out.join(DIR_NAME)
        .join(format!("{}.json", representation_label(spec)))
}

/// Whether the sample of `spec` is in `out` (and parses).
pub fn exists(out: &Path, spec: &RunSpec) -> bool {
    std::fs::read(sample_path(out, spec))
        .ok()
        .and_then(|b| serde_json::from_slice::<GoalSpaceSample>(&b).ok())
        .is_some()
}

/// Encode the lattice (and reconstruct held-out images) with a fitted representation and write
/// the sample of `spec` into `out`.
pub fn write(
    out: &Path,
    spec: &RunSpec,
    ctx: &RunContext,
    repr: &mut Representation,
) -> Result<GoalSpaceSample, ReprError> {
    let io = |p: &Path, e: &dyn std::fmt::Display| {
        ReprError::InvalidInput(format!("goal-space sample {}: {e}", p.display()))
    };
    let env = make_env(spec.env, ctx.env);
    let ds_seed = run_seed(
        ctx.campaign_seed,
        &dataset_identity(spec.env, ctx.ugl.images, spec.seed),
    );
    let (states, images) = grid_images(env.as_ref(), GRID)?;
    // As `ugl embed`: a stochastic encoder draws from the data set's encoding stream.
    repr.encoder.begin_run(stream(ds_seed, Component::Encoding));
    let z = repr.encoder.encode(&images)?;
    let d = env.state_dim();
    let label = representation_label(spec);
    let dir = out.join(DIR_NAME);
    std::fs::create_dir_all(&dir).map_err(|e| io(&dir, &e))?;
    let heldout = generate(
        env.as_ref(),
        RECONSTRUCTIONS,
        &mut stream(ds_seed, Component::HeldOut),
    )?;
    let mut recon = Vec::new();
    for i in 0..heldout.images.n {
        match repr.encoder.reconstruct(heldout.images.row(i)) {
            Some(r) => recon.push(r?),
            None => break,
        }
    }
    // The reconstruction figure draws the 70x70 gray pictures and the follow-up's 64x64 RGB ones.
    let image = env.kind().spec().image;
    let write_grid = match image {
        ugl_types::GRAY70 => Some(render::write_png_grid as GridWriter),
        ugl_types::RGB64 => Some(cdge::write_png_grid as GridWriter),
        _ => None,
    };
    let reconstructions = match write_grid {
        Some(write_grid) if !recon.is_empty() => {
            let name = format!("{label}.reconstructions.png");
            let path = dir.join(&name);
            let tmp = dir.join(format!(".{name}.tmp"));
            let cells: Vec<&[f32]> = (0..heldout.images.n)
                .map(|i| heldout.images.row(i))
                .chain(recon.iter().map(|r| &r[..]))
                .collect();
            write_grid(&cells, RECONSTRUCTIONS, 2, &tmp).map_err(|e| io(&tmp, &e))?;
            std::fs::rename(&tmp, &path).map_err(|e| io(&path, &e))?;
            Some(name)
        }
        _ => None,
    };
    let sample = GoalSpaceSample {
        representation: label,
        env: spec.env.name().into(),
        algo: spec.algo.name().into(),
        variant: spec.variant.map(|v| v.name()).unwrap_or("none").into(),
        latents: spec.latents,
        seed: spec.seed,
        grid: GRID,
        positions: states.chunks_exact(d).map(|s| [s[0], s[1]]).collect(),
        grid_latents: (0..z.n)
            .map(|i| z.row(i).iter().map(|&v| v as f32).collect())
            .collect(),
        reconstructions,
    };
    let path = sample_path(out, spec);
    let mut json = serde_json::to_vec(&sample).expect("serialisable");
    json.push(b'\n');
    store::write_atomic(&path, &json).map_err(|e| io(&path, &e))?;
    Ok(sample)
}
