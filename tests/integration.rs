//! The integration tests of the `ugl` command line, in one test binary. Each file below was its
//! own binary, and each binary links burn and polars (about 165 MB on disk, and a link step
//! each): one binary keeps a cold build's disk and time down (a CI machine with little free disk
//! failed to link the twelfth). Three stay binaries of their own (Cargo.toml, `[[test]]`):
//! `verify_smoke` (`make verify` runs it alone), and `toy_environment` and `toy_sampler`, which
//! register a new environment or sampler in their process, as a program that extends ugl-bench
//! would.

mod common;

mod campaign_engine;
mod cli;
mod committed_configurations;
mod deterministic_math;
mod links;
mod order_independence;
mod readme_facts;
mod report_committed;
mod verify_store;
