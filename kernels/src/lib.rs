//! Floating-point kernels whose results depend only on their inputs, on any x86-64 machine
//! (scalar, AVX2+FMA or AVX-512) and any thread count: see [`matmul`] for the contract and
//! [`SimdPath`] for how the path is chosen or forced (`UGL_SIMD`). The convolutions
//! ([`Conv2d`], [`ConvTranspose2d`]) are built on the same products. [`flushing_pool`] runs
//! work with subnormal numbers flushed to zero, by x86-64 rules that every path obeys alike.

mod conv;
mod conv_direct;
mod conv_shape;
mod eigen;
mod flush;
mod matmul;
mod path;

pub use conv::{Conv2d, ConvTranspose2d};
pub use eigen::{EigenError, SymmetricEigen, cholesky_solve};
pub use flush::{FlushError, flushing_pool, this_thread_flushes};
pub use matmul::{Element, MatRef, matmul, matmul_on, matmul_reference};
pub use path::{PathError, SIMD_VAR, SimdPath, active_path, check_active_path, path_from_env};
