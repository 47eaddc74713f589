//! `ugl`: the command line of ugl-bench, as a library: [`main_with`] parses arguments and runs
//! the command, so that a program (or a test) that registers its own environments
//! (`ugl_bench::env::register`) or learners runs the same command line with them.
//!
//! Every error is one line on stderr and exit code 2.

mod cli;
mod commands;
mod output;
mod progress;

use std::ffi::OsString;
use std::process::ExitCode;

use anyhow::{Result, bail};
use clap::Parser;

use ugl_bench::campaign::config::CampaignConfig;
use ugl_bench::campaign::plan;
use ugl_bench::campaign::single::RunRequest;

use crate::cli::{Cli, Command};
use crate::commands::campaign::{RunOptions, campaign, merge, slurm, status};
use crate::commands::compare::{compare, learners};
use crate::commands::environment::{klc, render, rollout};
use crate::commands::single::{embed, run};

/// Run the command line on `args` (the program's name first, as `std::env::args_os` gives
/// it): help and version on stdout, errors as one line on stderr; exit code 0, or 2 on any
/// error.
pub fn main_with<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                if let Err(err) = e.print() {
                    return stdout_failed(output::StdoutError(err));
                }
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::from(2)
                } else {
                    ExitCode::SUCCESS
                };
            }
            let text = e.render().to_string();
            let first = text
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("error: invalid arguments");
            eprintln!("{} (see 'ugl --help')", first.trim());
            return ExitCode::from(2);
        }
    };
    // A bad `UGL_SIMD` (no such kernel path, or one this CPU cannot run) stops every command
    // before it computes anything.
    if let Err(e) = ugl_bench::kernels::check_active_path() {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<output::StdoutError>().is_some() => {
            let e = e.downcast::<output::StdoutError>().expect("checked");
            stdout_failed(e)
        }
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::from(2)
        }
    }
}

/// Standard output failed: a closed pipe ends quietly (exit 0: the reader has what it wanted,
/// as with `ls | head`), any other failure (a full disk) is one line and exit 2.
fn stdout_failed(e: output::StdoutError) -> ExitCode {
    if e.is_closed_pipe() {
        ExitCode::SUCCESS
    } else {
        eprintln!("error: {e}");
        ExitCode::from(2)
    }
}

/// An error and its causes on one line, each cause once: a cause whose text an outer message
/// already contains (a library error that prints its source) is not repeated.
fn one_line(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        let text = text.trim();
        if text.is_empty() || out.contains(text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(text);
    }
    out.replace('\n', " ")
}

fn dispatch(cmd: Command) -> Result<()> {
    match cmd {
        Command::Rollout { env, params, seed } => rollout(env, &params, seed),
        Command::Klc { env, outcomes } => klc(env, &outcomes),
        Command::Render { env, state, out } => render(env, &state, &out),
        Command::Run {
            env,
            algo,
            sampler,
            variant,
            latents,
            images,
            seed,
            exploration,
            epochs,
            profile,
            out,
            command,
            name,
            allow_dirty,
            cache,
        } => run(
            RunRequest {
                env,
                algo,
                sampler,
                variant,
                latents,
                images,
                seed,
                exploration,
                epochs,
                command,
                name,
            },
            &profile,
            &out,
            &cache,
            allow_dirty,
        ),
        Command::Plan { config } => {
            let cfg = CampaignConfig::load(&config)?;
            for spec in plan(&cfg) {
                output::outln!("{}", spec.run_id())?;
            }
            Ok(())
        }
        Command::Campaign {
            config,
            out,
            jobs,
            quiet,
            shard,
            refresh_diagnostics,
            allow_dirty,
            cache,
        } => campaign(
            &config,
            refresh_diagnostics,
            RunOptions {
                out,
                jobs,
                quiet,
                shard: shard.as_deref(),
                allow_dirty,
                cache: &cache,
            },
        ),
        Command::Slurm(a) => slurm(a),
        Command::Status {
            config,
            out,
            shards,
            require_complete,
        } => status(config.as_deref(), out, shards, require_complete),
        Command::Merge { into, sources } => merge(&into, &sources),
        Command::Verify {
            results,
            config,
            sample,
            without_networks,
        } => commands::verify::verify(
            &results,
            config.as_deref(),
            sample,
            if without_networks {
                commands::verify::Networks::Excluded
            } else {
                commands::verify::Networks::Included
            },
        ),
        Command::Learners => learners(),
        Command::Compare(a) => compare(a),
        Command::Embed(a) => embed(a),
        Command::SweepTable { dir } => {
            let table = ugl_report::armballs::sweep::table(&dir)?;
            output::outln!("{}", table.trim_end())?;
            Ok(())
        }
        Command::Report {
            results,
            out,
            paper,
            main_campaign,
        } => {
            if !paper.is_dir() {
                bail!(
                    "--paper {}: not a directory (the paper's reference values, data/paper in \
                     the repository)",
                    paper.display()
                );
            }
            let mut opts = ugl_report::ReportOptions::new(results, out);
            opts.paper_dir = paper;
            // The store's top level is listed as "(top level)"; accept that spelling too.
            opts.main_campaign = match main_campaign.as_str() {
                "(top level)" | "." => String::new(),
                _ => main_campaign,
            };
            let s = ugl_report::render_report(&opts)?;
            eprintln!(
                "report: {} runs -> {} files in {}",
                s.n_runs,
                s.files.len(),
                opts.out.display()
            );
            Ok(())
        }
    }
}
