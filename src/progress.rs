//! Progress on the terminal: one bar per neural training, external learners' lines, and the
//! Ctrl-C stop flag of long commands.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use anyhow::{Context, Result};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use ugl_bench::campaign::context::{MessageSink, TrainSink};

/// Progress bars for neural trainings, one per representation, above `main` (if any).
pub(crate) fn training_bars(mp: &MultiProgress, main: Option<&ProgressBar>) -> Arc<TrainSink> {
    let bars: std::sync::Mutex<std::collections::HashMap<String, ProgressBar>> = Default::default();
    let mp = mp.clone();
    let main = main.cloned();
    Arc::new(move |label: &str, p| {
        let mut bars = bars.lock().expect("progress bars");
        let bar = bars.entry(label.to_string()).or_insert_with(|| {
            let b = ProgressBar::new(p.total as u64);
            let b = match &main {
                Some(m) => mp.insert_before(m, b),
                None => mp.add(b),
            };
            b.set_style(
                ProgressStyle::with_template(
                    "  train {prefix:32} {bar:25} {pos}/{len} it  {rate}  ETA {eta}  loss {msg}",
                )
                .expect("valid template")
                .with_key(
                    "rate",
                    |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{:.1} it/s", s.per_sec());
                    },
                ),
            );
            b.set_prefix(label.to_string());
            b
        });
        bar.set_position(p.iteration as u64);
        bar.set_message(format!("{:.2}", p.loss));
        if p.iteration >= p.total {
            bar.finish_and_clear();
            mp.remove(bar);
            bars.remove(label);
        }
    })
}

/// One line per external learner while it fits, above `main` (if any): its label and the last
/// line it wrote to stderr (the whole stderr is in `OUT/<label>.learner.log`).
pub(crate) fn learner_lines(mp: &MultiProgress, main: Option<&ProgressBar>) -> Arc<MessageSink> {
    let bars: std::sync::Mutex<std::collections::HashMap<String, ProgressBar>> = Default::default();
    let mp = mp.clone();
    let main = main.cloned();
    Arc::new(move |label: &str, line: Option<&str>| {
        let mut bars = bars.lock().expect("progress bars");
        match line {
            Some(line) => {
                let bar = bars.entry(label.to_string()).or_insert_with(|| {
                    let b = ProgressBar::new_spinner();
                    let b = match &main {
                        Some(m) => mp.insert_before(m, b),
                        None => mp.add(b),
                    };
                    b.set_style(
                        ProgressStyle::with_template(
                            "  fit   {prefix:32} {elapsed:>5}  {wide_msg}",
                        )
                        .expect("valid template"),
                    );
                    b.set_prefix(label.to_string());
                    b.enable_steady_tick(std::time::Duration::from_millis(500));
                    b
                });
                bar.set_message(line.to_string());
            }
            None => {
                if let Some(bar) = bars.remove(label) {
                    bar.finish_and_clear();
                    mp.remove(&bar);
                }
            }
        }
    })
}

/// Progress bars on stderr, hidden when it is not a terminal.
pub(crate) fn progress_area() -> MultiProgress {
    let mp = MultiProgress::new();
    if !std::io::stderr().is_terminal() {
        mp.set_draw_target(ProgressDrawTarget::hidden());
    }
    mp
}

/// The stop flag of a campaign command: the first Ctrl-C sets it (and stops external learners
/// still fitting), so the work in flight (`what`) finishes and is stored; a second one exits.
/// The handler is installed once per process; a later command (of a program that runs the
/// command line several times) gets the same flag, cleared.
pub(crate) fn stop_on_ctrl_c(what: &'static str) -> Result<Arc<AtomicBool>> {
    static HANDLER: OnceLock<(Arc<AtomicBool>, Arc<Mutex<&'static str>>)> = OnceLock::new();
    let (stop, doing) = match HANDLER.get() {
        Some(h) => h.clone(),
        None => {
            let stop = Arc::new(AtomicBool::new(false));
            let doing = Arc::new(Mutex::new(what));
            let (flag, label) = (stop.clone(), doing.clone());
            ctrlc::set_handler(move || {
                if flag.swap(true, Ordering::SeqCst) {
                    std::process::exit(130);
                }
                // External learners still fitting are stopped now, not waited for.
                ugl_bench::repr::external::interrupt();
                let what = *label.lock().unwrap_or_else(|e| e.into_inner());
                eprintln!("\ninterrupt: finishing {what} (Ctrl-C again to abort now)");
            })
            .context("cannot install the Ctrl-C handler")?;
            HANDLER.get_or_init(|| (stop, doing)).clone()
        }
    };
    stop.store(false, Ordering::SeqCst);
    *doing.lock().unwrap_or_else(|e| e.into_inner()) = what;
    Ok(stop)
}
