//! Slurm job scripts for a campaign (`ugl slurm`), written into one job directory:
//!
//! - `submit.sh` builds `ugl` once where it runs (the login node), copies the binary to
//!   `bin/ugl` in the job directory, submits the array job and then the report step;
//! - `array.sh`: task `i` runs shard `i/n` of the campaign with that binary (shards are disjoint
//!   and deterministic, every task writes into the same results directory atomically, and a
//!   task run again resumes its shard); no `cargo` runs on a compute node;
//! - `report.sh` runs after every task succeeded (`afterok`; a task that fails or is cancelled
//!   cancels it, `--kill-on-invalid-dep=yes`), refuses to render unless `ugl status` finds every
//!   run complete, and writes the report next to the results (`<out>/report` unless told),
//!   never into the checkout.
//!
//! Every option is checked before anything is written ([`SlurmJob::check`]): the time syntax,
//! the shard count against the campaign's runs, the CPUs, the extra `sbatch` options, and that
//! no output directory is the checkout or above it.

use std::path::{Component, Path, PathBuf};

use thiserror::Error;

/// Why the scripts could not be made.
#[derive(Debug, Error)]
pub enum SlurmError {
    #[error(
        "--shards {shards}: must be between 1 and {groups}, the campaign's {runs} runs in \
         {groups} groups that share a fit (more shards would be empty tasks)"
    )]
    Shards {
        shards: usize,
        groups: usize,
        runs: usize,
    },
    #[error("--cpus {0}: must be between 1 and {MAX_CPUS}")]
    Cpus(usize),
    #[error("--throttle {throttle}: must be between 1 and the {shards} shards")]
    Throttle { throttle: usize, shards: usize },
    #[error("{option} '{value}': {why}")]
    Time {
        option: &'static str,
        value: String,
        why: String,
    },
    #[error("--sbatch-arg '{arg}': {why}")]
    SbatchArg { arg: String, why: String },
    #[error("{option} {path}: {why}")]
    Path {
        option: &'static str,
        path: PathBuf,
        why: String,
    },
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// The most CPUs a task may ask for: more than any node has today (the largest have a few
/// hundred cores), so a larger number is a typo.
pub const MAX_CPUS: usize = 1024;

/// Options `ugl slurm` writes itself: an `--sbatch-arg` may not set them.
const OWN_OPTIONS: [&str; 11] = [
    "array",
    "chdir",
    "cpus-per-task",
    "dependency",
    "error",
    "job-name",
    "kill-on-invalid-dep",
    "output",
    "parsable",
    "time",
    "wrap",
];

/// What the scripts run: every path absolute (tasks start in other directories).
#[derive(Clone, Debug)]
pub struct SlurmJob<'a> {
    /// The campaign's name, its number of runs and of fit groups (the most non-empty shards,
    /// [`super::plan::shard_groups`]).
    pub name: &'a str,
    pub n_runs: usize,
    pub n_groups: usize,
    /// The repository checkout the tasks `cd` into (for the campaign's git revision) and whose
    /// `data/paper` the report reads.
    pub checkout: &'a Path,
    /// The campaign file and its results directory.
    pub config: &'a Path,
    pub out: &'a Path,
    /// Where the report step writes the report.
    pub report_out: &'a Path,
    /// The job directory (scripts, `bin/ugl`, `logs/`).
    pub dir: &'a Path,
    pub shards: usize,
    /// CPUs per task (and `--jobs` of each task's campaign).
    pub cpus: usize,
    /// Slurm's `--time` of each task and of the report step.
    pub time: &'a str,
    pub report_time: &'a str,
    /// At most this many tasks at once (`--array=0-N%T`).
    pub throttle: Option<usize>,
    /// Extra `#SBATCH` options of both jobs (`--partition=NAME`, `--account=NAME`, ...).
    pub sbatch_args: &'a [String],
    /// The tasks' `ugl campaign` may write into a checkout with uncommitted changes
    /// (`--allow-dirty`).
    pub allow_dirty: bool,
}

/// The three scripts' texts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SlurmScripts {
    /// `array.sh`
    pub array: String,
    /// `report.sh`
    pub report: String,
    /// `submit.sh`
    pub submit: String,
}

/// A path as one POSIX shell word (single-quoted; a `'` becomes `'\''`). Inside single quotes
/// nothing is special to the shell (`$`, backticks, backslashes, newlines), so any path is safe.
pub fn sh_quote(p: &Path) -> String {
    sh_quote_str(&p.to_string_lossy())
}

/// A text as one POSIX shell word (see [`sh_quote`]).
pub fn sh_quote_str(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

/// A path as it may appear in a script's comment: on one line, with a newline or any other
/// control character escaped (`\n`), so that it cannot end the comment.
fn in_comment(p: &Path) -> String {
    p.to_string_lossy().escape_debug().to_string()
}

/// Checks a Slurm time limit (`sbatch --time`): `MM`, `MM:SS`, `HH:MM:SS`, `D-HH`, `D-HH:MM`,
/// `D-HH:MM:SS`, or `UNLIMITED` / `INFINITE`; at least one second. Returns the text as Slurm
/// reads it; anything else (a newline, a word, an empty string) is refused.
pub fn check_time(option: &'static str, s: &str) -> Result<String, SlurmError> {
    let bad = |why: &str| SlurmError::Time {
        option,
        value: s.escape_debug().to_string(),
        why: format!(
            "{why}; a Slurm time is MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS (e.g. 04:00:00, 1-12)"
        ),
    };
    if s.eq_ignore_ascii_case("unlimited") || s.eq_ignore_ascii_case("infinite") {
        return Ok(s.to_string());
    }
    let field = |t: &str| -> Result<u64, SlurmError> {
        if t.is_empty() || t.len() > 6 || !t.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad("not a time"));
        }
        t.parse().map_err(|_| bad("not a time"))
    };
    let (days, rest) = match s.split_once('-') {
        Some((d, r)) => (Some(field(d)?), r),
        None => (None, s),
    };
    let parts: Vec<u64> = rest.split(':').map(field).collect::<Result<_, _>>()?;
    let below = |v: u64, limit: u64, what: &str| {
        if v < limit {
            Ok(v)
        } else {
            Err(bad(&format!("{what} must be below {limit}")))
        }
    };
    let seconds = match (days, parts.as_slice()) {
        (None, [m]) => m * 60,
        (None, [m, sec]) => m * 60 + below(*sec, 60, "seconds")?,
        (None, [h, m, sec]) => {
            h * 3600 + below(*m, 60, "minutes")? * 60 + below(*sec, 60, "seconds")?
        }
        (Some(d), [h]) => d * 86400 + below(*h, 24, "hours")? * 3600,
        (Some(d), [h, m]) => {
            d * 86400 + below(*h, 24, "hours")? * 3600 + below(*m, 60, "minutes")? * 60
        }
        (Some(d), [h, m, sec]) => {
            d * 86400
                + below(*h, 24, "hours")? * 3600
                + below(*m, 60, "minutes")? * 60
                + below(*sec, 60, "seconds")?
        }
        _ => return Err(bad("not a time")),
    };
    if seconds == 0 {
        return Err(bad("a zero time limit"));
    }
    Ok(s.to_string())
}

/// Checks an extra `sbatch` option: the long form `--name` or `--name=value`, a value of
/// letters, digits and `_ . , : @ % + / = -` only (so it cannot break out of its `#SBATCH`
/// line), and none of the options `ugl slurm` sets itself.
pub fn check_sbatch_arg(arg: &str) -> Result<(), SlurmError> {
    let bad = |why: &str| SlurmError::SbatchArg {
        arg: arg.escape_debug().to_string(),
        why: why.to_string(),
    };
    let Some(body) = arg.strip_prefix("--") else {
        return Err(bad(
            "give the long form with '=', e.g. --partition=gpu, --account=NAME, --qos=NAME, --mem=8G",
        ));
    };
    let (name, value) = match body.split_once('=') {
        Some((n, v)) => (n, Some(v)),
        None => (body, None),
    };
    let name_ok = name.bytes().next().is_some_and(|b| b.is_ascii_lowercase())
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-');
    if !name_ok {
        return Err(bad(
            "not an sbatch option name (lower-case letters, digits and '-')",
        ));
    }
    if let Some(v) = value
        && (v.is_empty()
            || !v
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"_.,:@%+/=-".contains(&b)))
    {
        return Err(bad(
            "the value may use only letters, digits and _ . , : @ % + / = - (no spaces, quotes or newlines)",
        ));
    }
    if OWN_OPTIONS.contains(&name) {
        return Err(bad(&format!(
            "--{name} is written by ugl slurm itself (see --shards, --throttle, --cpus, --time, --scripts)"
        )));
    }
    Ok(())
}

/// `path` made absolute against `cwd`, with `.` and `..` resolved and symbolic links followed
/// as far as the path exists (the rest may not exist yet).
pub fn resolve(path: &Path, cwd: &Path) -> PathBuf {
    let abs = if path.is_absolute() {
        path.to_path_buf()
    } else {
        cwd.join(path)
    };
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::ParentDir => {
                out = out.canonicalize().unwrap_or(out);
                out.pop();
            }
            Component::CurDir => {}
            c => out.push(c),
        }
    }
    out.canonicalize().unwrap_or(out)
}

impl SlurmJob<'_> {
    /// Every check of the options, before a script is written.
    pub fn check(&self) -> Result<(), SlurmError> {
        if self.shards == 0 || self.shards > self.n_groups.max(1) {
            return Err(SlurmError::Shards {
                shards: self.shards,
                groups: self.n_groups,
                runs: self.n_runs,
            });
        }
        if self.cpus == 0 || self.cpus > MAX_CPUS {
            return Err(SlurmError::Cpus(self.cpus));
        }
        if let Some(t) = self.throttle
            && (t == 0 || t > self.shards)
        {
            return Err(SlurmError::Throttle {
                throttle: t,
                shards: self.shards,
            });
        }
        check_time("--time", self.time)?;
        check_time("--report-time", self.report_time)?;
        for a in self.sbatch_args {
            check_sbatch_arg(a)?;
        }
        let checkout = self
            .checkout
            .canonicalize()
            .unwrap_or_else(|_| self.checkout.to_path_buf());
        for (option, path) in [
            ("--out", self.out),
            ("--report-out", self.report_out),
            ("--scripts", self.dir),
        ] {
            if checkout.starts_with(path) {
                return Err(SlurmError::Path {
                    option,
                    path: path.to_path_buf(),
                    why: format!(
                        "is the checkout {} or a directory above it; give a directory of its own",
                        checkout.display()
                    ),
                });
            }
        }
        for (option, path) in [
            ("--config", self.config),
            ("--out", self.out),
            ("--report-out", self.report_out),
            ("--scripts", self.dir),
            ("the checkout", self.checkout),
        ] {
            if path.to_str().is_none() {
                return Err(SlurmError::Path {
                    option,
                    path: path.to_path_buf(),
                    why: "is not valid UTF-8; the scripts could not name it exactly".into(),
                });
            }
        }
        if self.out.parent().is_none() {
            return Err(SlurmError::Path {
                option: "--out",
                path: self.out.to_path_buf(),
                why: "the results directory needs a parent (the report reads its campaigns)".into(),
            });
        }
        Ok(())
    }
}

/// The `#SBATCH` lines of the extra options.
fn extra_lines(args: &[String]) -> String {
    args.iter().map(|a| format!("#SBATCH {a}\n")).collect()
}

/// The scripts of a job (after [`SlurmJob::check`]).
pub fn scripts(job: &SlurmJob<'_>) -> Result<SlurmScripts, SlurmError> {
    job.check()?;
    let (name, n_runs, shards, cpus) = (job.name, job.n_runs, job.shards, job.cpus);
    let (time, report_time) = (job.time, job.report_time);
    let results = job.out.parent().unwrap_or(job.out);
    // The report step draws its figures from this campaign (the store may hold others), with
    // the paper's reference values of this checkout.
    let main_name = job
        .out
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let q = |p: &Path| sh_quote(p);
    let (cwd_q, config_q, out_q) = (q(job.checkout), q(job.config), q(job.out));
    let bin_q = q(&job.dir.join("bin/ugl"));
    let report_q = q(job.report_out);
    let throttle = job.throttle.map(|t| format!("%{t}")).unwrap_or_default();
    let extra = extra_lines(job.sbatch_args);
    let array = format!(
        "#!/usr/bin/env bash\n\
         # Generated by `ugl slurm` for campaign '{name}' ({n_runs} runs in {shards} shards).\n\
         # Task i runs shard i/{shards}: disjoint, deterministic, written atomically into one results\n\
         # directory; a task run again resumes its shard. It runs the binary submit.sh copied to\n\
         # bin/ugl (no cargo on the compute node). Submit from this directory (submit.sh does).\n\
         #SBATCH --job-name=ugl-{name}\n#SBATCH --array=0-{last}{throttle}\n#SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --time={time}\n#SBATCH --output=logs/ugl-{name}-%A_%a.log\n{extra}\
         set -euo pipefail\ncd {cwd_q}\n\
         exec {bin_q} campaign --config {config_q} --out {out_q} --jobs {cpus} --quiet{dirty} \\\n  \
         --shard \"${{SLURM_ARRAY_TASK_ID}}/{shards}\"\n",
        last = shards - 1,
        dirty = if job.allow_dirty {
            " --allow-dirty"
        } else {
            ""
        },
    );
    let report = format!(
        "#!/usr/bin/env bash\n\
         # Generated by `ugl slurm`: once every task succeeded, check that the campaign is complete\n\
         # and render its report into {report_c}.\n\
         #SBATCH --job-name=ugl-{name}-report\n#SBATCH --cpus-per-task=1\n#SBATCH --time={report_time}\n\
         #SBATCH --output=logs/ugl-{name}-report-%j.log\n{extra}\
         set -euo pipefail\ncd {cwd_q}\n\
         # Exits non-zero unless every run is complete: the report never draws on partial results.\n\
         {bin_q} status --config {config_q} --out {out_q} --require-complete\n\
         exec {bin_q} report --results {results} --main {main} --paper {paper} --out {report_q}\n",
        report_c = in_comment(job.report_out),
        results = q(results),
        main = q(Path::new(&main_name)),
        paper = q(&job.checkout.join("data/paper")),
    );
    let array_opt = if throttle.is_empty() {
        "--array=\"$tasks\"".to_string()
    } else {
        format!("--array=\"$tasks{throttle}\"")
    };
    let submit = format!(
        "#!/usr/bin/env bash\n\
         # Generated by `ugl slurm` for campaign '{name}': build ugl once here (the login node),\n\
         # copy it to bin/ugl, submit the array job, then its report step, which runs once every\n\
         # task succeeded and is cancelled if one fails or is cancelled.\n\
         #   bash submit.sh          submit every task (finished runs are kept: a task whose runs\n\
         #                           are all complete ends at once)\n\
         #   bash submit.sh 3,5      resubmit tasks 3 and 5 only (Slurm's --array syntax)\n\
         # Both submit a new report step.\n\
         set -euo pipefail\ncd \"$(dirname \"$0\")\"\ntasks=${{1:-}}\n\
         if [ -n \"$tasks\" ] && ! [[ $tasks =~ ^[0-9]+(-[0-9]+)?(,[0-9]+(-[0-9]+)?)*$ ]]; then\n  \
         echo \"usage: submit.sh [TASKS]  (e.g. 3,5 or 0-2; tasks 0-{last})\" >&2; exit 2\nfi\n\
         exe=$(cd {cwd_q} && cargo build --quiet --bin ugl --message-format=json-render-diagnostics \\\n  \
         | sed -n 's/.*\"executable\":\"\\([^\"]*\\/ugl\\)\".*/\\1/p' | tail -n 1)\n\
         if [ -z \"$exe\" ] || [ ! -x \"$exe\" ]; then echo \"submit.sh: cargo build did not report the ugl binary\" >&2; exit 1; fi\n\
         mkdir -p bin logs\ncp \"$exe\" bin/ugl.partial && mv -f bin/ugl.partial bin/ugl\n\
         jid=$(sbatch --parsable ${{tasks:+{array_opt}}} array.sh)\njid=${{jid%%;*}}\n\
         rid=$(sbatch --parsable --dependency=afterok:\"$jid\" --kill-on-invalid-dep=yes report.sh)\nrid=${{rid%%;*}}\n\
         printf '%s\\n' \\\n  \
         \"submitted array job $jid (${{tasks:-0-{last}}} of {shards} tasks) and its report step $rid\" \\\n  \
         \"  progress:  squeue -j $jid,$rid\" \\\n  \
         {msg}\n",
        last = shards - 1,
        // The rest of the message is fixed text, one single-quoted word per line: no path in it
        // is ever read by the shell (a `$(...)` in a path stays text).
        msg = [
            format!("             or, without Slurm: {bin_q} status --config {config_q} --out {out_q} --shards {shards}"),
            format!("  logs:      {}", q(&job.dir.join("logs"))),
            "  a task that fails or is cancelled cancels the report step; fix the cause, then resubmit".to_string(),
            format!("             the tasks that did not finish (finished runs are kept): bash {} TASKS", q(&job.dir.join("submit.sh"))),
            format!("  report:    {}", q(&job.report_out.join("REPORT.md"))),
        ]
        .iter()
        .map(|l| sh_quote_str(l))
        .collect::<Vec<_>>()
        .join(" \\\n  "),
    );
    Ok(SlurmScripts {
        array,
        report,
        submit,
    })
}

/// Write `array.sh`, `report.sh` and `submit.sh` into `dir` (executable).
pub fn write_scripts(dir: &Path, s: &SlurmScripts) -> Result<(), SlurmError> {
    for (file, text) in [
        ("array.sh", &s.array),
        ("report.sh", &s.report),
        ("submit.sh", &s.submit),
    ] {
        let path = dir.join(file);
        let write_err = |source| SlurmError::Write {
            path: path.clone(),
            source,
        };
        std::fs::write(&path, text).map_err(write_err)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755))
                .map_err(write_err)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const ARGS: [String; 0] = [];

    fn job<'a>(shards: usize, cpus: usize, time: &'a str, extra: &'a [String]) -> SlurmJob<'a> {
        SlurmJob {
            name: "paper",
            n_runs: 240,
            n_groups: 120,
            checkout: Path::new("/home/me/ugl bench"),
            config: Path::new("/home/me/ugl bench/data/campaigns/paper.toml"),
            out: Path::new("/scratch/it's/paper"),
            report_out: Path::new("/scratch/it's/paper/report"),
            dir: Path::new("/scratch/it's/paper/slurm"),
            shards,
            cpus,
            time,
            report_time: "00:30:00",
            throttle: None,
            sbatch_args: extra,
            allow_dirty: false,
        }
    }

    #[test]
    fn scripts_quote_paths_and_name_every_shard() {
        let extra = ["--partition=gpu".to_string(), "--mem=8G".to_string()];
        let s = scripts(&job(16, 2, "04:00:00", &extra)).unwrap();
        assert!(s.array.contains("#SBATCH --array=0-15\n"), "{}", s.array);
        assert!(s.array.contains("--shard \"${SLURM_ARRAY_TASK_ID}/16\""));
        assert!(s.array.contains("cd '/home/me/ugl bench'\n"));
        assert!(s.array.contains("--out '/scratch/it'\\''s/paper' --jobs 2"));
        assert!(
            s.array
                .contains("exec '/scratch/it'\\''s/paper/slurm/bin/ugl' campaign")
        );
        assert!(
            s.array
                .lines()
                .all(|l| l.starts_with('#') || !l.contains("cargo")),
            "no cargo on a compute node"
        );
        assert!(
            s.array
                .contains("#SBATCH --partition=gpu\n#SBATCH --mem=8G\n")
        );
        assert!(s.report.contains("#SBATCH --partition=gpu\n"));
        assert!(
            s.report
                .contains("--results '/scratch/it'\\''s' --main 'paper'")
        );
        assert!(
            s.report
                .contains("--out '/scratch/it'\\''s/paper/report'\n")
        );
        assert!(s.report.contains("status --config"));
        assert!(s.submit.contains(
            "sbatch --parsable --dependency=afterok:\"$jid\" --kill-on-invalid-dep=yes report.sh"
        ));
        // Every #SBATCH line comes before the first command (Slurm ignores the later ones).
        for text in [&s.array, &s.report] {
            let first_cmd = text.find("set -euo").unwrap();
            assert!(!text[first_cmd..].contains("#SBATCH"), "{text}");
        }
    }

    #[test]
    fn a_throttle_limits_the_tasks_at_once() {
        let mut j = job(16, 2, "1-00", &ARGS);
        j.throttle = Some(4);
        let s = scripts(&j).unwrap();
        assert!(s.array.contains("#SBATCH --array=0-15%4\n"));
        assert!(s.submit.contains("--array=\"$tasks%4\""));
        j.throttle = Some(17);
        assert!(matches!(scripts(&j), Err(SlurmError::Throttle { .. })));
    }

    #[test]
    fn bad_options_are_refused() {
        assert!(matches!(
            scripts(&job(0, 2, "04:00:00", &ARGS)),
            Err(SlurmError::Shards { .. })
        ));
        assert!(matches!(
            scripts(&job(121, 2, "04:00:00", &ARGS)),
            Err(SlurmError::Shards { groups: 120, .. })
        ));
        assert!(matches!(
            scripts(&job(4, 0, "04:00:00", &ARGS)),
            Err(SlurmError::Cpus(0))
        ));
        assert!(matches!(
            scripts(&job(4, 100_000_000, "04:00:00", &ARGS)),
            Err(SlurmError::Cpus(_))
        ));
        for t in [
            "04:00:00\ntouch PWNED",
            "banana",
            "",
            "0",
            "00:61:00",
            "1-24",
            "1:2:3:4",
            "-5",
        ] {
            assert!(
                matches!(scripts(&job(4, 2, t, &ARGS)), Err(SlurmError::Time { .. })),
                "{t:?}"
            );
        }
        for t in [
            "90",
            "30:00",
            "04:00:00",
            "2-12",
            "2-12:30",
            "2-12:30:15",
            "UNLIMITED",
        ] {
            assert!(check_time("--time", t).is_ok(), "{t}");
        }
        for a in [
            "-p gpu",
            "--partition gpu",
            "--partition=gpu\ntouch PWNED",
            "--account='x'",
            "--qos=$(id)",
            "--array=0-3",
            "--output=x",
            "--Partition=x",
            "--mem=",
        ] {
            let extra = [a.to_string()];
            assert!(
                matches!(
                    scripts(&job(4, 2, "04:00:00", &extra)),
                    Err(SlurmError::SbatchArg { .. })
                ),
                "{a:?}"
            );
        }
        for a in [
            "--partition=gpu",
            "--exclusive",
            "--gres=gpu:1",
            "--mail-user=me@x.org",
        ] {
            assert!(check_sbatch_arg(a).is_ok(), "{a}");
        }
    }

    #[test]
    fn no_output_is_the_checkout_or_above_it() {
        let extra = ARGS;
        for (out, report, dir) in [
            ("/home/me/ugl bench", "/r", "/d"),
            ("/home/me", "/r", "/d"),
            ("/x/paper", "/home/me/ugl bench", "/d"),
            ("/x/paper", "/r", "/"),
        ] {
            let mut j = job(4, 2, "04:00:00", &extra);
            j.out = Path::new(out);
            j.report_out = Path::new(report);
            j.dir = Path::new(dir);
            assert!(
                matches!(scripts(&j), Err(SlurmError::Path { .. })),
                "{out} {report} {dir}"
            );
        }
        // Inside the checkout is allowed (data/results/NAME is where committed results live).
        let mut j = job(4, 2, "04:00:00", &extra);
        j.out = Path::new("/home/me/ugl bench/data/results/paper");
        assert!(scripts(&j).is_ok());
    }

    #[test]
    fn resolve_follows_dots() {
        let cwd = Path::new("/nonexistent-ugl/a/b");
        assert_eq!(
            resolve(Path::new(".."), cwd),
            Path::new("/nonexistent-ugl/a")
        );
        assert_eq!(
            resolve(Path::new("./c/../d"), cwd),
            Path::new("/nonexistent-ugl/a/b/d")
        );
        assert_eq!(resolve(Path::new("/x/./y"), cwd), Path::new("/x/y"));
    }
}
