# Sourced by the sweep scripts (scripts/conv_sweep.sh, scripts/conv_trajectory.sh), from the
# caller's directory: `enter_repository` reads UGL (the binary: a path from the caller's
# directory, or a command on PATH) before moving to the repository's root, then sets `ugl` to it,
# or to target/debug/ugl, built first, when UGL is not set.
enter_repository() {
  case "${UGL:-}" in
    */*) UGL="$(cd "$(dirname "$UGL")" && pwd)/$(basename "$UGL")" ;;
  esac
  cd "$(dirname "${BASH_SOURCE[0]}")/.."
  ugl="${UGL:-target/debug/ugl}"
  if [ -z "${UGL:-}" ]; then cargo build --quiet --bin ugl; fi
}
