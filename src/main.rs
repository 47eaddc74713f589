//! `ugl`: the command line of ugl-bench. Thin: sets up logging (`UGL_LOG`) and runs
//! [`ugl::main_with`] on the process's arguments.

use std::process::ExitCode;

fn main() -> ExitCode {
    // `UGL_LOG` (tracing's filter syntax, e.g. `warn` or `debug`) chooses what is logged;
    // without it errors, and an external learner's bad end (a warning), are.
    let filter = tracing_subscriber::EnvFilter::try_from_env("UGL_LOG").unwrap_or_else(|_| {
        tracing_subscriber::EnvFilter::new("error,ugl_bench::repr::external=warn")
    });
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .init();
    ugl::main_with(std::env::args_os())
}
