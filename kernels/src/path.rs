//! Which instruction path the kernels run on: chosen once per process from the CPU, or forced
//! with the environment variable `UGL_SIMD` (`scalar`, `avx2` or `avx512`).
//!
//! Every path computes the same bits: each output of a product is one chain of fused
//! multiply-adds in a fixed order, and a vector lane computes exactly what the scalar
//! `mul_add` computes. The path changes the speed, never the result; forcing one is how the
//! tests prove it.

use std::fmt;
use std::str::FromStr;
use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

/// The environment variable that forces a path.
pub const SIMD_VAR: &str = "UGL_SIMD";

/// An instruction path of the kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SimdPath {
    /// Portable code: `f32::mul_add` / `f64::mul_add`, the reference.
    Scalar,
    /// AVX2 with FMA (x86-64-v3).
    Avx2,
    /// AVX-512F (x86-64-v4).
    Avx512,
}

impl SimdPath {
    /// All paths, slowest first.
    pub const ALL: [SimdPath; 3] = [SimdPath::Scalar, SimdPath::Avx2, SimdPath::Avx512];

    /// The name used by `UGL_SIMD` and recorded in manifests.
    pub fn name(self) -> &'static str {
        match self {
            SimdPath::Scalar => "scalar",
            SimdPath::Avx2 => "avx2",
            SimdPath::Avx512 => "avx512",
        }
    }

    /// Whether this CPU can run the path.
    pub fn available(self) -> bool {
        match self {
            SimdPath::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 => std::arch::is_x86_feature_detected!("avx512f"),
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The paths this CPU can run, slowest first.
    pub fn available_paths() -> Vec<SimdPath> {
        SimdPath::ALL
            .into_iter()
            .filter(|p| p.available())
            .collect()
    }

    /// The fastest path this CPU can run.
    pub fn best() -> SimdPath {
        SimdPath::ALL
            .into_iter()
            .rev()
            .find(|p| p.available())
            .unwrap_or(SimdPath::Scalar)
    }
}

impl fmt::Display for SimdPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A path that cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PathError {
    #[error("{SIMD_VAR}={0:?} is not a kernel path; use scalar, avx2 or avx512")]
    Unknown(String),
    #[error("{SIMD_VAR}={0} asks for a path this CPU cannot run (it can run: {1})")]
    Unavailable(SimdPath, String),
}

impl FromStr for SimdPath {
    type Err = PathError;
    fn from_str(s: &str) -> Result<Self, PathError> {
        SimdPath::ALL
            .into_iter()
            .find(|p| p.name() == s.trim().to_ascii_lowercase())
            .ok_or_else(|| PathError::Unknown(s.to_string()))
    }
}

/// The path named by `UGL_SIMD` (unset or empty: the fastest the CPU has), checked against the
/// CPU.
pub fn path_from_env() -> Result<SimdPath, PathError> {
    match std::env::var(SIMD_VAR) {
        Ok(v) if !v.trim().is_empty() => {
            let path: SimdPath = v.parse()?;
            if path.available() {
                Ok(path)
            } else {
                let can = SimdPath::available_paths()
                    .iter()
                    .map(|p| p.name())
                    .collect::<Vec<_>>()
                    .join(", ");
                Err(PathError::Unavailable(path, can))
            }
        }
        _ => Ok(SimdPath::best()),
    }
}

static ACTIVE: OnceLock<Result<SimdPath, PathError>> = OnceLock::new();

/// The path of this process: `UGL_SIMD`, read once, or the fastest the CPU has. An invalid
/// `UGL_SIMD` is an error here, which a program reports at start ([`check_active_path`]).
pub fn active_path() -> SimdPath {
    match ACTIVE.get_or_init(path_from_env) {
        Ok(p) => *p,
        // Unreachable after `check_active_path` at start; the reference path otherwise, which
        // gives the same bits.
        Err(_) => SimdPath::Scalar,
    }
}

/// Read `UGL_SIMD` now and fail if it names no path or one this CPU cannot run.
pub fn check_active_path() -> Result<SimdPath, PathError> {
    ACTIVE.get_or_init(path_from_env).clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for p in SimdPath::ALL {
            assert_eq!(p.name().parse::<SimdPath>().unwrap(), p);
        }
        assert_eq!("AVX2".parse::<SimdPath>().unwrap(), SimdPath::Avx2);
        let err = "sse".parse::<SimdPath>().unwrap_err();
        assert!(err.to_string().contains("scalar, avx2 or avx512"), "{err}");
    }

    #[test]
    fn the_scalar_path_is_always_available_and_best_is_available() {
        assert!(SimdPath::Scalar.available());
        assert!(SimdPath::best().available());
        assert!(SimdPath::available_paths().contains(&SimdPath::best()));
    }
}
