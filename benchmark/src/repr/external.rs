//! External representation learners: a model written in anything (PyTorch, JAX, ...) competes
//! through a small process protocol (protocol v1, specified in `docs/external-learners.md`).
//!
//! One long-running process per fitted model:
//!
//! 1. The harness creates a work directory, writes `train.npy` (float32, shape `(n, dim)`,
//!    C order; dim = 4900 = 70 x 70, pixel (x, y) at `x * 70 + y`) and starts the configured
//!    command with `sh -c` in its own process group, with the caller's working directory and
//!    environment plus `UGL_PROTOCOL=1`, `UGL_TRAIN`, `UGL_TRAIN_LATENTS`, `UGL_PRIOR`,
//!    `UGL_LATENTS`, `UGL_SEED` (drawn from the learner stream given to `fit`), `UGL_WORKDIR`
//!    and `UGL_HARNESS_PID`.
//! 2. The program fits, writes `train_latents.npy` (float32 or float64, shape `(n, latents)`),
//!    optionally `UGL_PRIOR` (shape `(2, latents)`: mean row, std row), and prints the line
//!    `READY` on stdout. Its stderr is forwarded to `tracing` and its last lines are kept for
//!    error messages.
//! 3. Encode requests: the harness writes one npy array (float32, `(m, dim)`, C order,
//!    `1 <= m <=` [`MAX_ROWS_PER_REQUEST`]) to the program's stdin; the program answers with
//!    one npy array (float32 or float64, `(m, latents)`) on stdout. npy frames itself (magic,
//!    header length, header with dtype and shape), so no other framing is needed.
//! 4. Closing stdin means shutdown: the program exits with status 0.
//!
//! Every answer is validated (magic, dtype, shape, finite values); a failure, a timeout or a
//! premature exit becomes [`ReprError::External`] with the exit status and the last lines of
//! the program's stderr, after which the process group is killed and the encoder refuses
//! further requests. Dropping the encoder closes stdin, waits a short grace period and kills
//! the process group; the child is always reaped and the work directory removed. A bad end
//! seen on drop (non-zero exit, a signal, the kill) is a warning, not an error: the latents
//! were all received and checked, so the runs that used them stand.
//!
//! Only the process group is killed: a program that leaves it (`setsid`, a daemonizing double
//! fork) is out of reach and survives (docs/external-learners.md, "Processes").

use crate::npy::{push_npy_f32, read_npy, read_npy_file, write_npy_f32_file};
use std::collections::{HashMap, VecDeque};
use std::fs::{self, File};
use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStderr, ChildStdin, ChildStdout, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use rand::Rng;

use super::neural_model::Variant;
use super::params::{LearnerParams, ParamError, ParamGuard};
use super::{
    Encoder, GaussianPrior, ImageSet, Latents, ReprError, RepresentationLearner, check_fit_input,
    check_latents, check_no_constant_latent,
};
use crate::seed::Stream;

/// The protocol version, passed to the program as `UGL_PROTOCOL`.
pub const PROTOCOL_VERSION: u32 = 1;
/// Largest number of images in one encode request; bigger batches are split.
pub const MAX_ROWS_PER_REQUEST: usize = 1024;
/// Default time allowed from the start of the program to its `READY` line (the whole fit).
pub const DEFAULT_READY_TIMEOUT: Duration = Duration::from_secs(3600);
/// Default time allowed for each encode request (write the request, read the answer).
pub const DEFAULT_ANSWER_TIMEOUT: Duration = Duration::from_secs(300);
/// How long a dropped encoder waits for the program to exit after closing its stdin.
const SHUTDOWN_GRACE: Duration = Duration::from_secs(5);
/// After the program closed its stdout, how long to wait for its exit status.
const EXIT_WAIT_ON_EOF: Duration = Duration::from_secs(2);
/// After the process exited or was killed, how long to wait for the rest of its stderr.
const STDERR_DRAIN: Duration = Duration::from_millis(500);
/// Lines of stderr kept for error messages, and the longest line kept.
const STDERR_TAIL_LINES: usize = 20;
const STDERR_LINE_MAX: usize = 1000;
/// Longest `READY` line accepted (protection against garbage).
const READY_LINE_MAX: u64 = 4096;

/// `[learners.external]`: a learner program speaking the protocol of
/// `docs/external-learners.md` (unchecked: [`ParamGuard::check`] validates it).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalConfig {
    /// A short name for results and the report.
    pub name: String,
    /// The command line (run with `sh -c`).
    pub command: String,
    /// Seconds allowed from the program's start to its `READY` line, i.e. its whole fit
    /// (default 3600). Not part of the runs' identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ready_timeout_s: Option<f64>,
    /// Seconds allowed for each encode answer (default 300). Not part of the runs' identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub answer_timeout_s: Option<f64>,
}

impl ExternalConfig {
    /// What the runs depend on: the name and the command (not the timeouts).
    pub fn identity(&self) -> ExternalConfig {
        ExternalConfig {
            name: self.name.clone(),
            command: self.command.clone(),
            ready_timeout_s: None,
            answer_timeout_s: None,
        }
    }
}

/// A checked [`ExternalConfig`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalParams(ExternalConfig);

impl ExternalParams {
    /// The configuration.
    pub fn config(&self) -> &ExternalConfig {
        &self.0
    }
}

impl ParamGuard for ExternalConfig {
    type Checked = ExternalParams;
    fn check(self) -> Result<ExternalParams, ParamError> {
        if self.command.trim().is_empty() || self.name.trim().is_empty() {
            return Err(ParamError::table("name and command must not be empty"));
        }
        for (key, v) in [
            ("ready_timeout_s", self.ready_timeout_s),
            ("answer_timeout_s", self.answer_timeout_s),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0 && v <= 1e7)
            {
                return Err(ParamError::at(
                    key,
                    format!("must be a positive number of seconds (at most 1e7), got {v}"),
                ));
            }
        }
        Ok(ExternalParams(self))
    }
}

impl ExternalParams {
    /// The learner, with the configured timeouts.
    pub fn learner(&self) -> ExternalLearner {
        let e = &self.0;
        let mut l = ExternalLearner::new(e.name.clone(), e.command.clone());
        if let Some(t) = e.ready_timeout_s {
            l.ready_timeout = Duration::from_secs_f64(t);
        }
        if let Some(t) = e.answer_timeout_s {
            l.answer_timeout = Duration::from_secs_f64(t);
        }
        l
    }
}

impl LearnerParams for ExternalParams {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn identity(&self, _variant: Option<Variant>) -> serde_json::Value {
        serde_json::to_value(self.0.identity()).expect("serialisable")
    }
    fn build(&self, _variant: Option<Variant>) -> Box<dyn RepresentationLearner> {
        Box::new(self.learner())
    }
}

/// A representation learner run as an external program (protocol v1).
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalLearner {
    /// Name in results and on the command line.
    pub name: String,
    /// The command line, run with `sh -c` (so quoting, `cd dir && ...` and variables work).
    pub command: String,
    /// Time allowed from the start of the program to `READY` (fit included).
    pub ready_timeout: Duration,
    /// Time allowed for each encode request.
    pub answer_timeout: Duration,
    /// Every line the program writes to stderr is appended to this file (created), besides
    /// going to `tracing` (level INFO) and to [`Self::on_stderr`].
    pub log_file: Option<PathBuf>,
    /// Called with each stderr line (e.g. to show the last one under a progress bar).
    pub on_stderr: Option<LineSink>,
    /// The pictures' shape, told to the program as `UGL_IMAGE=WIDTHxHEIGHTxCHANNELS` (None:
    /// not told; the harness sets it from the environment, [`super::FitContext::image`]).
    pub image: Option<ugl_types::ImageShape>,
}

/// A callback receiving the lines of a learner's stderr.
#[derive(Clone)]
pub struct LineSink(pub Arc<dyn Fn(&str) + Send + Sync>);

impl std::fmt::Debug for LineSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LineSink")
    }
}

impl PartialEq for LineSink {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl ExternalLearner {
    /// A learner with the default timeouts ([`DEFAULT_READY_TIMEOUT`], [`DEFAULT_ANSWER_TIMEOUT`]).
    pub fn new(name: impl Into<String>, command: impl Into<String>) -> Self {
        ExternalLearner {
            name: name.into(),
            command: command.into(),
            ready_timeout: DEFAULT_READY_TIMEOUT,
            answer_timeout: DEFAULT_ANSWER_TIMEOUT,
            log_file: None,
            on_stderr: None,
            image: None,
        }
    }
}

impl RepresentationLearner for ExternalLearner {
    fn name(&self) -> &str {
        &self.name
    }

    fn fit(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        let (encoder, z) = self.fit_external(images, latents, rng)?;
        Ok((Box::new(encoder), z))
    }

    /// The fit with the program's stderr also going to the context's log file and message
    /// sink (where given; else this learner's own).
    fn fit_in(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
        ctx: &super::FitContext,
    ) -> Result<(Box<dyn Encoder>, Latents), ReprError> {
        let mut l = self.clone();
        l.log_file = ctx.log_file.clone().or(l.log_file);
        l.on_stderr = ctx.messages.clone().or(l.on_stderr);
        l.image = ctx.image.or(l.image);
        l.fit(images, latents, rng)
    }
}

impl ExternalLearner {
    /// [`RepresentationLearner::fit`] with the concrete encoder type (for
    /// [`ExternalEncoder::shutdown`] and [`ExternalEncoder::process_id`]).
    pub fn fit_external(
        &self,
        images: &ImageSet,
        latents: usize,
        rng: &mut Stream,
    ) -> Result<(ExternalEncoder, Latents), ReprError> {
        check_fit_input(images, latents)?;
        let seed = rng.next_u64();
        let workdir = WorkDir::create()?;
        let train = workdir.path.join("train.npy");
        let train_latents = workdir.path.join("train_latents.npy");
        let prior_path = workdir.path.join("prior.npy");
        write_npy_f32_file(&train, images.n, images.dim, &images.data)
            .map_err(|e| ReprError::Io(format!("writing {}: {e}", train.display())))?;

        let mut cmd = Command::new("sh");
        cmd.args(["-c", START_GATE, "ugl-learner"])
            .arg(&self.command)
            .env("UGL_PROTOCOL", PROTOCOL_VERSION.to_string())
            .env("UGL_TRAIN", &train)
            .env("UGL_TRAIN_LATENTS", &train_latents)
            .env("UGL_LATENTS", latents.to_string())
            .env("UGL_SEED", seed.to_string())
            .env("UGL_PRIOR", &prior_path)
            .env("UGL_WORKDIR", &workdir.path)
            .env("UGL_HARNESS_PID", std::process::id().to_string());
        if let Some(s) = self.image {
            cmd.env(
                "UGL_IMAGE",
                format!("{}x{}x{}", s.width, s.height, s.channels),
            );
        }
        tracing::info!(learner = %self.name, command = %self.command, n = images.n, latents, seed,
            workdir = %workdir.path.display(), "starting external learner");
        let mut session = Session::spawn(self, cmd, workdir)?;
        session.wait_ready(self.ready_timeout)?;

        let z = match read_npy_file(&train_latents, Some(images.n), latents) {
            Ok(data) => Latents {
                n: images.n,
                latents,
                data,
            },
            Err(e) => return Err(session.fail(format!("after READY: {e}"), false)),
        };
        let who = format!("external learner '{}' (train_latents.npy)", self.name);
        if let Err(e) = check_latents(&z, &who).and_then(|()| check_no_constant_latent(&z, &who)) {
            let _ = session.fail(e.to_string(), false);
            return Err(e);
        }
        let prior = if prior_path.exists() {
            match read_npy_file(&prior_path, Some(2), latents)
                .map_err(|e| e.to_string())
                .and_then(|p| {
                    prior_from(&p, latents).ok_or_else(|| {
                        "prior.npy: values must be finite and the std row (row 1) positive"
                            .to_string()
                    })
                }) {
                Ok(p) => Some(p),
                Err(e) => return Err(session.fail(format!("after READY: {e}"), false)),
            }
        } else {
            None
        };
        let encoder = ExternalEncoder {
            session,
            dim: images.dim,
            latents,
            prior,
            request: Vec::new(),
            answer: Vec::new(),
            seen: HashMap::new(),
            cache_hits: 0,
            requests_sent: 0,
        };
        Ok((encoder, z))
    }
}

/// The prior of `prior.npy` (row 0 the mean, row 1 the std); None if a value is not finite or
/// a std not positive.
fn prior_from(p: &[f64], latents: usize) -> Option<GaussianPrior> {
    let (mean, std) = p.split_at(latents);
    if p.iter().any(|v| !v.is_finite()) || std.iter().any(|&s| s <= 0.0) {
        return None;
    }
    Some(GaussianPrior {
        mean: mean.to_vec(),
        std: std.to_vec(),
    })
}

/// The encoder of an [`ExternalLearner`]: the running program, asked through its stdin/stdout.
pub struct ExternalEncoder {
    session: Session,
    dim: usize,
    latents: usize,
    prior: Option<GaussianPrior>,
    /// Reused request bytes (npy header + little-endian float32 pixels).
    request: Vec<u8>,
    /// Reused answer values.
    answer: Vec<f64>,
    /// The latents of the images already asked for in this run, keyed by the BLAKE3 hash of
    /// the image's bytes: most outcomes of a run are exact repeats (the unmoved object), and a
    /// learner is required to encode deterministically (docs/external-learners.md), so each
    /// distinct image is sent once. Cleared at the start of every run ([`Encoder::begin_run`]).
    seen: HashMap<[u8; 32], Vec<f64>>,
    /// Requests answered from `seen` / sent to the program, over the encoder's life.
    pub cache_hits: u64,
    pub requests_sent: u64,
}

impl ExternalEncoder {
    /// The process id of the program (`sh`, leader of the program's process group).
    pub fn process_id(&self) -> u32 {
        self.session.child.id()
    }

    /// Close the program's stdin and wait (up to the answer timeout) for it to exit; an exit
    /// status other than 0 is an error. Dropping the encoder (what the campaigns, `ugl run`
    /// and `ugl embed` do) waits 5 s and logs a bad end as a warning (see the module doc).
    pub fn shutdown(mut self) -> Result<(), ReprError> {
        if let Some(b) = &self.session.broken {
            return Err(ReprError::External(b.clone()));
        }
        let grace = self.session.answer_timeout;
        let status = self.session.close(grace);
        match self.session.exit_report(status, grace) {
            None => Ok(()),
            Some(msg) => Err(ReprError::External(msg)),
        }
    }

    /// One request of `rows` images (`pixels.len() == rows * dim`); the answer lands in `self.answer`.
    fn round_trip(&mut self, rows: usize, pixels: &[f32]) -> Result<(), ReprError> {
        self.request.clear();
        push_npy_f32(&mut self.request, rows, self.dim, pixels);
        self.session
            .round_trip(rows, self.latents, &mut self.request, &mut self.answer)?;
        if let Some(i) = self.answer.iter().position(|v| !v.is_finite()) {
            let msg = format!(
                "answer has a non-finite latent (image {} of the request, dimension {})",
                i / self.latents,
                i % self.latents
            );
            return Err(self.session.fail(msg, false));
        }
        Ok(())
    }
}

impl Encoder for ExternalEncoder {
    fn latents(&self) -> usize {
        self.latents
    }

    fn encode(&mut self, images: &ImageSet) -> Result<Latents, ReprError> {
        if images.dim != self.dim {
            return Err(ReprError::InvalidInput(format!(
                "images have {} pixels, the learner was fitted on {}",
                images.dim, self.dim
            )));
        }
        if images.data.len() != images.n * images.dim {
            return Err(ReprError::InvalidInput(
                "image data does not match n x dim".into(),
            ));
        }
        let mut data = Vec::with_capacity(images.n * self.latents);
        for start in (0..images.n).step_by(MAX_ROWS_PER_REQUEST) {
            let rows = MAX_ROWS_PER_REQUEST.min(images.n - start);
            self.round_trip(
                rows,
                &images.data[start * self.dim..(start + rows) * self.dim],
            )?;
            data.extend_from_slice(&self.answer);
        }
        let z = Latents {
            n: images.n,
            latents: self.latents,
            data,
        };
        check_latents(&z, &format!("external learner '{}'", self.session.name))?;
        Ok(z)
    }

    fn encode_one(&mut self, image: &[f32], out: &mut [f64]) -> Result<(), ReprError> {
        if image.len() != self.dim || out.len() != self.latents {
            return Err(ReprError::InvalidInput(format!(
                "encode_one: image has {} pixels (expected {}), output {} values (expected {})",
                image.len(),
                self.dim,
                out.len(),
                self.latents
            )));
        }
        let bytes: Vec<u8> = image.iter().flat_map(|v| v.to_le_bytes()).collect();
        let key = *blake3::hash(&bytes).as_bytes();
        if let Some(z) = self.seen.get(&key) {
            self.cache_hits += 1;
            out.copy_from_slice(z);
            return Ok(());
        }
        self.round_trip(1, image)?;
        self.requests_sent += 1;
        out.copy_from_slice(&self.answer);
        self.seen.insert(key, self.answer.clone());
        Ok(())
    }

    fn begin_run(&mut self, _rng: Stream) {
        self.seen.clear();
    }

    fn reported_fit_s(&self) -> Option<f64> {
        self.session.reported_fit_s
    }

    fn prior(&self) -> Option<GaussianPrior> {
        self.prior.clone()
    }
}

// ---------------------------------------------------------------------------------------------
// The process and its three I/O threads.

/// A request to the stdout thread: read one answer of `rows x cols` into `buf`.
struct ReadRequest {
    rows: usize,
    cols: usize,
    buf: Vec<f64>,
}

enum FromReader {
    /// `READY`, with the fit time the program reported (`READY fit_s=12.5`), if any.
    Ready(Option<f64>),
    Answer(Vec<f64>),
    /// Protocol violation or end of stdout; the thread has stopped.
    Failed(String, bool),
}

#[derive(Default)]
struct StderrTail {
    lines: VecDeque<String>,
    closed: bool,
}

/// The temporary work directory, removed on drop.
struct WorkDir {
    path: PathBuf,
}

/// Set by the command line on an interrupt (the first Ctrl-C): a learner still fitting is
/// stopped and killed instead of being waited for (its READY wait ends with an error).
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Stop waiting for external learners that are still fitting (see [`INTERRUPTED`]).
pub fn interrupt() {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

/// Work directories are named `ugl-external-<harness pid>-...`: remove those whose harness is
/// no longer running (left behind by a `kill -9` before the watchdog existed, or by a machine
/// that went down). Once per process; Linux only (`/proc`).
fn sweep_stale_work_dirs(base: &Path) {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        if !Path::new("/proc/self").exists() {
            return;
        }
        let Ok(entries) = fs::read_dir(base) else {
            return;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            let Some(pid) = name
                .strip_prefix("ugl-external-")
                .and_then(|r| r.split('-').next())
                .and_then(|p| p.parse::<u32>().ok())
            else {
                continue;
            };
            if pid != std::process::id() && !Path::new("/proc").join(pid.to_string()).exists() {
                tracing::info!(
                    "removing the stale learner work directory {}",
                    e.path().display()
                );
                let _ = fs::remove_dir_all(e.path());
            }
        }
    });
}

/// The learner's shell: it waits for one line on its standard input, which the harness writes
/// once the watchdog ([`spawn_watchdog`]) runs, then becomes the learner's command (`exec`, so
/// its process, group and `$$` stay the same). Without the gate the program could run, and a
/// `kill -9` of `ugl` land, before the watchdog exists: a heavily loaded machine widened that
/// window enough to leave a learner behind. If the harness dies first, the read meets the end of
/// its input and the shell exits without starting the program.
const START_GATE: &str = "IFS= read -r _ || exit 1; exec sh -c \"$1\"";

/// A process that outlives `ugl` however it ends (Ctrl-C twice, SIGTERM, SIGKILL): every
/// second it checks that the harness is alive; once the harness is gone it kills the learner's
/// process group and removes its work directory. It exits by itself when the group is gone. It
/// runs in its own process group, so neither the learner's end nor a terminal Ctrl-C stops it.
#[cfg(unix)]
fn spawn_watchdog(pgid: u32, workdir: &Path) -> Option<Child> {
    use std::os::unix::process::CommandExt;
    const SCRIPT: &str = "h=$1; g=$2; d=$3\n\
        while kill -0 \"$h\" 2>/dev/null; do\n\
          kill -0 -\"$g\" 2>/dev/null || exit 0\n\
          sleep 1\n\
        done\n\
        kill -9 -\"$g\" 2>/dev/null\n\
        rm -rf \"$d\"\n";
    let mut cmd = Command::new("sh");
    cmd.args(["-c", SCRIPT, "ugl-learner-watchdog"])
        .arg(std::process::id().to_string())
        .arg(pgid.to_string())
        .arg(workdir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .process_group(0);
    match cmd.spawn() {
        Ok(c) => Some(c),
        Err(e) => {
            tracing::warn!("no watchdog for the learner's process group {pgid}: {e}");
            None
        }
    }
}

impl WorkDir {
    fn create() -> Result<Self, ReprError> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let base = std::env::temp_dir();
        sweep_stale_work_dirs(&base);
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let mut last_err = None;
        for _ in 0..16 {
            let k = COUNTER.fetch_add(1, Ordering::Relaxed);
            let path = base.join(format!(
                "ugl-external-{}-{k}-{nanos:08x}",
                std::process::id()
            ));
            match fs::create_dir(&path) {
                Ok(()) => return Ok(WorkDir { path }),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_err = Some(e),
                Err(e) => return Err(ReprError::Io(format!("creating {}: {e}", path.display()))),
            }
        }
        Err(ReprError::Io(format!(
            "creating a work directory in {}: {last_err:?}",
            base.display()
        )))
    }
}

impl Drop for WorkDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.path);
    }
}

struct Session {
    name: String,
    command: String,
    answer_timeout: Duration,
    child: Child,
    to_writer: Option<Sender<Vec<u8>>>,
    from_writer: Receiver<Result<Vec<u8>, std::io::Error>>,
    to_reader: Option<Sender<ReadRequest>>,
    from_reader: Receiver<FromReader>,
    stderr: Arc<Mutex<StderrTail>>,
    /// Exit status once reaped.
    status: Option<ExitStatus>,
    /// Set after a failure: the message, returned for every later request.
    broken: Option<String>,
    /// The fit time the program reported on its READY line.
    reported_fit_s: Option<f64>,
    /// Whether it said READY (before that, every way out returns an error of its own).
    ready: bool,
    /// Kills the program's group if `ugl` dies first ([`spawn_watchdog`]).
    watchdog: Option<Child>,
    /// Where its stderr is kept, named in the messages.
    log_file: Option<PathBuf>,
    // Dropped last, after the process is gone.
    _workdir: WorkDir,
}

fn spawn_thread<F: FnOnce() + Send + 'static>(name: &str, f: F) -> Result<(), ReprError> {
    thread::Builder::new()
        .name(name.into())
        .spawn(f)
        .map(|_| ())
        .map_err(|e| ReprError::Io(format!("spawning thread {name}: {e}")))
}

impl Session {
    fn spawn(
        learner: &ExternalLearner,
        mut cmd: Command,
        workdir: WorkDir,
    ) -> Result<Session, ReprError> {
        cmd.stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        #[cfg(unix)]
        {
            use std::os::unix::process::CommandExt;
            cmd.process_group(0);
        }
        let mut child = cmd.spawn().map_err(|e| {
            ReprError::External(format!(
                "learner '{}': could not start `sh -c {:?}`: {e}",
                learner.name, learner.command
            ))
        })?;
        #[cfg(unix)]
        let watchdog = spawn_watchdog(child.id(), &workdir.path);
        #[cfg(not(unix))]
        let watchdog = None;
        let mut stdin = child.stdin.take().expect("piped stdin");
        // Open the gate (START_GATE): the watchdog runs, so the program may start. A learner
        // that is already gone shows in the READY wait, with its status and stderr.
        let _ = stdin.write_all(b"\n").and_then(|()| stdin.flush());
        let stdout = child.stdout.take().expect("piped stdout");
        let stderr = child.stderr.take().expect("piped stderr");
        let (to_writer, writer_rx) = mpsc::channel();
        let (writer_tx, from_writer) = mpsc::channel();
        let (to_reader, reader_rx) = mpsc::channel();
        let (reader_tx, from_reader) = mpsc::channel();
        let tail = Arc::new(Mutex::new(StderrTail::default()));
        let session = Session {
            name: learner.name.clone(),
            command: learner.command.clone(),
            answer_timeout: learner.answer_timeout,
            child,
            to_writer: Some(to_writer),
            from_writer,
            to_reader: Some(to_reader),
            from_reader,
            stderr: tail.clone(),
            status: None,
            broken: None,
            reported_fit_s: None,
            ready: false,
            watchdog,
            log_file: learner.log_file.clone(),
            _workdir: workdir,
        };
        // On a thread-spawn failure the session drops here, which kills and reaps the child.
        let name = learner.name.clone();
        let log = match &learner.log_file {
            Some(path) => Some(
                fs::OpenOptions::new()
                    .create(true)
                    .append(true)
                    .open(path)
                    .map_err(|e| ReprError::Io(format!("learner log {}: {e}", path.display())))?,
            ),
            None => None,
        };
        let sink = learner.on_stderr.clone();
        spawn_thread("ugl-ext-stderr", move || {
            stderr_loop(stderr, tail, name, log, sink)
        })?;
        spawn_thread("ugl-ext-stdin", move || {
            writer_loop(stdin, writer_rx, writer_tx)
        })?;
        spawn_thread("ugl-ext-stdout", move || {
            reader_loop(stdout, reader_rx, reader_tx)
        })?;
        Ok(session)
    }

    fn wait_ready(&mut self, timeout: Duration) -> Result<(), ReprError> {
        // In slices, so that an interrupt stops the wait.
        let start = Instant::now();
        let got = loop {
            let left = timeout.saturating_sub(start.elapsed());
            match self
                .from_reader
                .recv_timeout(left.min(Duration::from_millis(200)))
            {
                Err(RecvTimeoutError::Timeout) if !left.is_zero() => {
                    if INTERRUPTED.load(Ordering::SeqCst) {
                        return Err(self.fail(
                            "interrupted while the program was fitting; it was stopped".into(),
                            false,
                        ));
                    }
                }
                other => break other,
            }
        };
        match got {
            Ok(FromReader::Ready(fit_s)) => {
                self.reported_fit_s = fit_s;
                self.ready = true;
                Ok(())
            }
            Ok(FromReader::Failed(m, eof)) => Err(self.fail(m, eof)),
            Ok(FromReader::Answer(_)) => {
                Err(self.fail("unexpected answer before READY".into(), false))
            }
            Err(RecvTimeoutError::Timeout) => Err(self.fail(
                format!("no READY line within the ready timeout ({timeout:?})"),
                false,
            )),
            Err(RecvTimeoutError::Disconnected) => {
                Err(self.fail("stdout reader stopped".into(), true))
            }
        }
    }

    /// Send `request` (a complete npy array of `rows` images) and read a `rows x cols` answer
    /// into `answer`. Both buffers are lent to the I/O threads and come back.
    fn round_trip(
        &mut self,
        rows: usize,
        cols: usize,
        request: &mut Vec<u8>,
        answer: &mut Vec<f64>,
    ) -> Result<(), ReprError> {
        if let Some(b) = &self.broken {
            return Err(ReprError::External(format!(
                "unusable after an earlier failure: {b}"
            )));
        }
        let start = Instant::now();
        let deadline = start + self.answer_timeout;
        let req = ReadRequest {
            rows,
            cols,
            buf: std::mem::take(answer),
        };
        let sent = self.to_reader.as_ref().is_some_and(|t| t.send(req).is_ok())
            && self
                .to_writer
                .as_ref()
                .is_some_and(|t| t.send(std::mem::take(request)).is_ok());
        if !sent {
            return Err(self.fail("the I/O threads have stopped".into(), true));
        }
        let remaining = |now: Instant| deadline.saturating_duration_since(now);
        match self.from_reader.recv_timeout(remaining(Instant::now())) {
            Ok(FromReader::Answer(buf)) => *answer = buf,
            Ok(FromReader::Failed(m, eof)) => return Err(self.fail(m, eof)),
            Ok(FromReader::Ready(_)) => unreachable!("READY is sent once"),
            Err(RecvTimeoutError::Timeout) => {
                let what = match self.from_writer.try_recv() {
                    Err(TryRecvError::Empty) => "did not read the whole request",
                    _ => "did not answer",
                };
                let msg = format!(
                    "{what} within the answer timeout ({:?}; request of {rows} images)",
                    self.answer_timeout
                );
                return Err(self.fail(msg, false));
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(self.fail("stdout reader stopped".into(), true));
            }
        }
        match self.from_writer.recv_timeout(remaining(Instant::now())) {
            Ok(Ok(buf)) => *request = buf,
            Ok(Err(e)) => {
                return Err(self.fail(format!("writing the request to its stdin: {e}"), true));
            }
            Err(_) => {
                return Err(self.fail("answered before reading the whole request".into(), false));
            }
        }
        Ok(())
    }

    /// Record a failure: wait briefly for the exit status if the program closed its stdout
    /// (`eof`), else kill it at once; reap it; return the error with status and stderr tail.
    fn fail(&mut self, what: String, eof: bool) -> ReprError {
        let mut killed = false;
        if self.status.is_none() {
            let grace = if eof {
                EXIT_WAIT_ON_EOF
            } else {
                Duration::ZERO
            };
            killed = self.terminate(grace);
        }
        let msg = self.describe(&what, self.status, killed);
        tracing::debug!(learner = %self.name, "external learner failed: {msg}");
        self.broken = Some(msg.clone());
        ReprError::External(msg)
    }

    /// The error text: who, what, exit status, last stderr lines.
    fn describe(&self, what: &str, status: Option<ExitStatus>, killed: bool) -> String {
        // Let the stderr thread catch the program's last words.
        let until = Instant::now() + STDERR_DRAIN;
        while !self.stderr.lock().map(|t| t.closed).unwrap_or(true) && Instant::now() < until {
            thread::sleep(Duration::from_millis(2));
        }
        let mut msg = format!(
            "learner '{}' (command `{}`): {what}",
            self.name, self.command
        );
        match status {
            _ if killed => msg.push_str("; the harness killed the program"),
            Some(s) => {
                msg.push_str(&format!("; the program exited with {s}"));
                if s.code() == Some(127) {
                    msg.push_str(" (command not found?)");
                } else if s.code() == Some(126) {
                    msg.push_str(" (command not executable?)");
                }
            }
            None => {}
        }
        let lines: Vec<String> = self
            .stderr
            .lock()
            .map(|t| t.lines.iter().cloned().collect())
            .unwrap_or_default();
        if lines.is_empty() {
            msg.push_str("; its stderr was empty");
        } else {
            msg.push_str("; last lines of its stderr:");
            for l in lines {
                msg.push_str("\n  | ");
                msg.push_str(&l);
            }
        }
        msg
    }

    /// The message for an end after stdin was closed (`status` from [`Self::close`] with
    /// `grace`); None for exit status 0.
    fn exit_report(&self, status: Option<ExitStatus>, grace: Duration) -> Option<String> {
        let mut msg = match status {
            Some(s) if s.success() => return None,
            Some(s) => self.describe("bad exit after stdin was closed", Some(s), false),
            None => self.describe(
                &format!("did not exit within {grace:?} after stdin was closed; killed"),
                None,
                true,
            ),
        };
        if let Some(log) = &self.log_file {
            msg.push_str(&format!("\n  (its whole stderr: {})", log.display()));
        }
        Some(msg)
    }

    /// Close stdin, wait up to `grace` for the program to exit, else kill its process group.
    /// Reaps the child. Returns the exit status if it exited by itself.
    fn close(&mut self, grace: Duration) -> Option<ExitStatus> {
        if self.status.is_none() {
            let killed = self.terminate(grace);
            if killed {
                return None;
            }
        }
        self.status
    }

    /// Stop the I/O (closing stdin), wait up to `grace`, kill the group if still running, reap.
    /// Returns whether it had to kill.
    fn terminate(&mut self, grace: Duration) -> bool {
        self.to_writer = None; // the stdin thread ends and closes the pipe
        self.to_reader = None;
        let until = Instant::now() + grace;
        loop {
            match self.child.try_wait() {
                Ok(Some(s)) => {
                    // Exited by itself. Anything it left behind in its group (background jobs,
                    // data-loader workers) goes too. The group id is safe to use: Linux does not
                    // reuse a pid while a process group of that id has members, and an empty
                    // group's id is only reused after the pid space wraps around.
                    self.status = Some(s);
                    kill_group(self.child.id());
                    return false;
                }
                Ok(None) if Instant::now() < until => thread::sleep(Duration::from_millis(2)),
                _ => break,
            }
        }
        // The leader is not reaped yet, so the group id is still ours.
        kill_group(self.child.id());
        let _ = self.child.kill();
        self.status = self.child.wait().ok();
        true
    }
}

impl Drop for Session {
    /// Ends a session that [`ExternalEncoder::shutdown`] or a failure (both report) did not:
    /// a bad end is logged as a warning only (module doc).
    fn drop(&mut self) {
        if self.status.is_none() {
            let status = self.close(SHUTDOWN_GRACE);
            if self.ready
                && self.broken.is_none()
                && let Some(msg) = self.exit_report(status, SHUTDOWN_GRACE)
            {
                tracing::warn!(learner = %self.name,
                    "external learner ended badly after its encoder was dropped (a warning \
                     only: every answer it gave had been received and checked): {msg}");
            }
        }
        if let Some(mut w) = self.watchdog.take() {
            let _ = w.kill();
            let _ = w.wait();
        }
    }
}

/// Kill the process group `pgid` (the program was started as a group leader), so that
/// programs started by the shell die too. Errors (group already gone) are ignored. A process
/// that left the group (`setsid`) is not reached: a documented limitation, since tracking it
/// would take a process-wide child subreaper (`prctl`) or a cgroup.
fn kill_group(pgid: u32) {
    #[cfg(unix)]
    {
        let target = format!("-{pgid}");
        let quiet = |c: &mut Command| {
            c.stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
        };
        if quiet(Command::new("kill").args(["-9", "--", &target])).is_err() {
            // No `kill` executable: the shell builtin (dash does not accept `--`).
            let _ = quiet(Command::new("sh").args(["-c", &format!("kill -9 {target}")]));
        }
    }
    #[cfg(not(unix))]
    let _ = pgid;
}

fn writer_loop(
    mut stdin: ChildStdin,
    rx: Receiver<Vec<u8>>,
    tx: Sender<Result<Vec<u8>, std::io::Error>>,
) {
    while let Ok(buf) = rx.recv() {
        match stdin.write_all(&buf).and_then(|()| stdin.flush()) {
            Ok(()) => {
                if tx.send(Ok(buf)).is_err() {
                    return;
                }
            }
            Err(e) => {
                let _ = tx.send(Err(e));
                return;
            }
        }
    }
    // Dropping `stdin` closes the pipe: the program's shutdown signal.
}

/// The `READY` line: `READY`, or `READY fit_s=SECONDS` (the program's own fit time). None: not
/// a READY line; Some(Err): a READY line with a bad field.
fn parse_ready(line: &str) -> Option<Result<Option<f64>, String>> {
    let mut words = line.split_whitespace();
    if words.next() != Some("READY") {
        return None;
    }
    let mut fit_s = None;
    for w in words {
        match w.split_once('=') {
            Some(("fit_s", v)) => match v.parse::<f64>() {
                Ok(x) if x.is_finite() && x >= 0.0 => fit_s = Some(x),
                _ => {
                    return Some(Err(format!(
                        "READY line: fit_s must be a number of seconds >= 0, got {v:?}"
                    )));
                }
            },
            _ => {
                return Some(Err(format!(
                    "READY line: unknown field {:?} (allowed: fit_s=SECONDS)",
                    truncate(w, 100)
                )));
            }
        }
    }
    Some(Ok(fit_s))
}

fn reader_loop(stdout: ChildStdout, rx: Receiver<ReadRequest>, tx: Sender<FromReader>) {
    let mut r = BufReader::with_capacity(1 << 16, stdout);
    let mut line = Vec::new();
    let msg = match (&mut r).take(READY_LINE_MAX).read_until(b'\n', &mut line) {
        Ok(0) => Err((
            "closed its stdout (exited?) before printing READY".to_string(),
            true,
        )),
        Ok(_) => {
            let text = String::from_utf8_lossy(&line);
            match parse_ready(&text) {
                Some(Ok(fit_s)) => Ok(fit_s),
                Some(Err(m)) => Err((m, false)),
                None => Err((
                    format!(
                        "expected the line READY on stdout, got {:?} (stdout is reserved for the \
                         protocol: log to stderr)",
                        truncate(&text, 200)
                    ),
                    false,
                )),
            }
        }
        Err(e) => Err((format!("reading stdout: {e}"), true)),
    };
    match msg {
        Ok(fit_s) => {
            if tx.send(FromReader::Ready(fit_s)).is_err() {
                return;
            }
        }
        Err((m, eof)) => {
            let _ = tx.send(FromReader::Failed(m, eof));
            return;
        }
    }
    let mut raw = Vec::new();
    while let Ok(req) = rx.recv() {
        let mut buf = req.buf;
        match read_npy(
            &mut r,
            &mut raw,
            &mut buf,
            Some(req.rows),
            req.cols,
            "answer",
        ) {
            Ok(_) => {
                if tx.send(FromReader::Answer(buf)).is_err() {
                    return;
                }
            }
            Err(e) => {
                let _ = tx.send(FromReader::Failed(e.message, e.eof));
                return;
            }
        }
    }
}

fn stderr_loop(
    stderr: ChildStderr,
    tail: Arc<Mutex<StderrTail>>,
    name: String,
    mut log: Option<File>,
    sink: Option<LineSink>,
) {
    let mut r = BufReader::new(stderr);
    let mut line = Vec::new();
    loop {
        line.clear();
        match (&mut r).take(64 * 1024).read_until(b'\n', &mut line) {
            Ok(0) | Err(_) => break,
            Ok(_) => {
                let text = String::from_utf8_lossy(&line);
                let text = text.trim_end();
                tracing::info!(learner = %name, "{text}");
                if let Some(f) = &mut log
                    && writeln!(f, "{text}").is_err()
                {
                    log = None;
                }
                if let Some(s) = &sink {
                    (s.0)(text);
                }
                if let Ok(mut t) = tail.lock() {
                    if t.lines.len() == STDERR_TAIL_LINES {
                        t.lines.pop_front();
                    }
                    t.lines.push_back(truncate(text, STDERR_LINE_MAX));
                }
            }
        }
    }
    if let Ok(mut t) = tail.lock() {
        t.closed = true;
    }
}

fn truncate(s: &str, max: usize) -> String {
    match s.char_indices().nth(max) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::START_GATE;
    use std::io::Write;
    use std::path::Path;
    use std::process::{Command, ExitStatus, Stdio};

    /// The learner's shell as `Session::spawn` starts it, with a command that leaves `marker`;
    /// `open`: the harness writes the gate's line, otherwise it closes the shell's input unwritten
    /// (the harness died before its watchdog ran).
    fn gated(marker: &Path, open: bool) -> ExitStatus {
        let mut child = Command::new("sh")
            .args(["-c", START_GATE, "ugl-learner"])
            .arg(format!("touch '{}'", marker.display()))
            .stdin(Stdio::piped())
            .spawn()
            .expect("sh starts");
        let mut stdin = child.stdin.take().expect("piped stdin");
        if open {
            stdin.write_all(b"\n").expect("the gate's line");
        }
        drop(stdin);
        child.wait().expect("sh ends")
    }

    /// The program starts only once the harness opens the gate: a harness gone before it (its
    /// input closed) leaves nothing running. Without the gate the program would run at once.
    #[test]
    fn the_learner_starts_only_once_the_gate_opens() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let marker = dir.path().join("started");
        let status = gated(&marker, false);
        assert!(!status.success(), "the shell exits with an error");
        assert!(!marker.exists(), "the program ran without the gate's line");
        let status = gated(&marker, true);
        assert!(status.success());
        assert!(
            marker.exists(),
            "the program did not run once the gate opened"
        );
    }
}
