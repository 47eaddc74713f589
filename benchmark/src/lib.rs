//! ugl-bench: the science of the benchmark.
//!
//! Reproduces Péré et al. (ICLR 2018), *Unsupervised Learning of Goal Spaces for
//! Intrinsically Motivated Goal Exploration*: the ArmBall / ArmArrow environments,
//! the 70x70 renderer, the explorers (RPE, RGE-EFR), the KL-coverage metric and
//! the campaign machinery that writes the results store.

pub mod campaign;
/// The environments, renderers, seeded streams and `.npy` codec (the light `ugl-env` crate,
/// which the Python package shares).
pub use ugl_env as env;
pub use ugl_env::{invalid, npy, seed};
/// The deterministic float kernels and their paths (`UGL_SIMD`).
pub use ugl_kernels as kernels;
pub mod explore;
pub mod fsio;
pub mod goals;
pub mod limits;
pub mod metrics;
pub mod repr;
