//! Helpers of the tests that extend the registries and call the command line in their own
//! process (`ugl::main_with`), so that what they registered is known to it.

use std::path::Path;
use std::process::ExitCode;

use ugl_types::Manifest;

/// `ugl ARGS` in this process.
pub fn ugl(args: &[&str]) -> ExitCode {
    ugl::main_with(std::iter::once("ugl").chain(args.iter().copied()))
}

/// `ugl ARGS` in this process, which must succeed.
pub fn ok(args: &[&str]) {
    assert_eq!(ugl(args), ExitCode::SUCCESS, "ugl {}", args.join(" "));
}

/// A path as a command-line argument.
pub fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A run's manifest.
pub fn manifest(path: &Path) -> Manifest {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}
