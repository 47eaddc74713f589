//! External learners (protocol v1, docs/external-learners.md).
//!
//! The Python example (`scripts/external_learners/random_projection.py`) runs when
//! `python3 -c "import numpy"` works; otherwise those tests print `SKIPPED: ...` and pass.
//! The error cases use `sh -c` one-liners and need no Python.
//!
//! Per-image round-trip time: `cargo test -p ugl-bench --test external_learner -- --ignored
//! --nocapture round_trip_timing`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use ugl_bench::env::render::render_ball_into;
use ugl_bench::repr::external::{ExternalEncoder, ExternalLearner};
use ugl_bench::repr::{Encoder, FitContext, ImageSet, Latents, ReprError, RepresentationLearner};
use ugl_bench::seed::stream_named;

const DIM: usize = 4900;

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/external_learners/random_projection.py")
}

fn python_learner() -> Option<ExternalLearner> {
    let ok = Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        eprintln!("SKIPPED: python3 with numpy not found");
        return None;
    }
    let mut l = ExternalLearner::new(
        "random-projection",
        format!("python3 '{}'", script().display()),
    );
    l.ready_timeout = Duration::from_secs(60);
    l.answer_timeout = Duration::from_secs(30);
    Some(l)
}

/// `n` ball images on a grid over [-0.9, 0.9]^2.
fn images(n: usize) -> ImageSet {
    let mut data = vec![0.0f32; n * DIM];
    for (i, img) in data.chunks_exact_mut(DIM).enumerate() {
        let x = -0.9 + 1.8 * (i % 7) as f64 / 6.0;
        let y = -0.9 + 1.8 * ((i / 7) % 8) as f64 / 7.0 + 0.01 * (i / 56) as f64;
        render_ball_into(x, y, img);
    }
    ImageSet::new(n, DIM, data).unwrap()
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-9 * (1.0 + x.abs().max(y.abs())))
}

fn fit_external(
    l: &ExternalLearner,
    set: &ImageSet,
    latents: usize,
    seed: u64,
) -> Result<(ExternalEncoder, Latents), ReprError> {
    l.fit_external(set, latents, &mut stream_named(seed, "learner"))
}

#[test]
fn python_random_projection_protocol() {
    let Some(learner) = python_learner() else {
        return;
    };
    let set = images(50);
    let (mut enc, z) = fit_external(&learner, &set, 5, 42).expect("fit");
    assert_eq!((z.n, z.latents, z.data.len()), (50, 5, 250));
    assert_eq!(enc.latents(), 5);
    assert!(enc.prior().is_none());

    // encode_one of a training image = its training latent (deterministic projection).
    let mut out = [0.0f64; 5];
    for i in [0, 7, 49] {
        enc.encode_one(set.row(i), &mut out).unwrap();
        assert!(
            close(&out, z.row(i)),
            "image {i}: {out:?} vs {:?}",
            z.row(i)
        );
    }
    // Batch encode agrees with the training latents.
    let again = enc.encode(&set).unwrap();
    assert_eq!((again.n, again.latents), (50, 5));
    assert!(close(&again.data, &z.data));
    // Wrong image size is refused on our side and does not break the encoder.
    assert!(matches!(
        enc.encode_one(&[0.0; 10], &mut out),
        Err(ReprError::InvalidInput(_))
    ));
    enc.encode_one(set.row(3), &mut out).unwrap();

    // The helper module reports the program's own fit time on the READY line.
    let fit_s = enc
        .reported_fit_s()
        .expect("ugl_protocol.serve reports fit_s");
    assert!((0.0..60.0).contains(&fit_s), "{fit_s}");

    // Repeated images are answered from the run's cache: one request per distinct image.
    enc.begin_run(stream_named(0, "encoding"));
    let sent = enc.requests_sent;
    for _ in 0..5 {
        enc.encode_one(set.row(11), &mut out).unwrap();
    }
    assert!(close(&out, z.row(11)));
    assert_eq!(
        enc.requests_sent,
        sent + 1,
        "one request for 5 identical images"
    );
    enc.begin_run(stream_named(1, "encoding"));
    enc.encode_one(set.row(11), &mut out).unwrap();
    assert_eq!(
        enc.requests_sent,
        sent + 2,
        "a new run starts with an empty cache"
    );

    // Same stream, same model; another stream, another model.
    let (enc2, z2) = fit_external(&learner, &set, 5, 42).unwrap();
    assert_eq!(z.data, z2.data, "same seed, same latents");
    let (_, z3) = fit_external(&learner, &set, 5, 43).unwrap();
    assert_ne!(z.data, z3.data, "another seed, another projection");

    // Clean shutdown (exit 0); dropping the other one reaps it too.
    enc.shutdown().expect("exit 0 on closed stdin");
    let pid = enc2.process_id();
    drop(enc2);
    assert!(gone(pid), "process {pid} still running after drop");
}

#[test]
fn python_through_the_trait_object() {
    let Some(learner) = python_learner() else {
        return;
    };
    let learner: Box<dyn RepresentationLearner> = Box::new(learner);
    assert_eq!(learner.name(), "random-projection");
    let set = images(12);
    let (mut enc, z) = learner
        .fit(&set, 3, &mut stream_named(1, "learner"))
        .unwrap();
    let big = images(1100); // more than one request (1024 rows per request)
    let all = enc.encode(&big).unwrap();
    assert_eq!((all.n, all.latents), (1100, 3));
    assert!(
        close(&all.data[..12 * 3], &z.data),
        "the first 12 images are the training set"
    );
    let mut out = [0.0; 3];
    enc.encode_one(big.row(1099), &mut out).unwrap();
    assert!(close(&out, all.row(1099)));
}

/// Not running any more (absent, or a zombie of a process we do not own).
fn gone(pid: u32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Err(_) => true,
        Ok(s) => s
            .rsplit(')')
            .next()
            .is_some_and(|rest| rest.trim_start().starts_with('Z')),
    }
}

fn sh(name: &str, command: &str) -> ExternalLearner {
    let mut l = ExternalLearner::new(name, command);
    l.ready_timeout = Duration::from_secs(10);
    l.answer_timeout = Duration::from_secs(10);
    l
}

fn external_msg(r: Result<impl Sized, ReprError>) -> String {
    match r {
        Err(ReprError::External(m)) => m,
        Err(e) => panic!("expected an External error, got {e:?}"),
        Ok(_) => panic!("expected an error"),
    }
}

/// An npy file (version 1.0, '<f8', C order).
fn npy_f64(rows: usize, cols: usize, data: &[f64]) -> Vec<u8> {
    let mut header =
        format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(header.len() as u16).to_le_bytes());
    b.extend_from_slice(header.as_bytes());
    for v in data {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

/// A scripted "learner": copies `train` to the train latents, says READY, then `after`.
fn scripted(dir: &Path, train: &[u8], after: &str) -> String {
    let t = dir.join("train_latents.npy");
    std::fs::write(&t, train).unwrap();
    format!(
        "cat '{}' > \"$UGL_TRAIN_LATENTS\"; echo READY; {after}",
        t.display()
    )
}

/// A program whose training latents are constant in a dimension is refused, naming it (its goal
/// space has fewer dimensions than asked; it was accepted).
#[test]
fn constant_train_latents_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let l = sh(
        "flat",
        &scripted(
            dir.path(),
            &npy_f64(3, 2, &[0.0, 5.0, 1.0, 5.0, 2.0, 5.0]),
            "cat > /dev/null",
        ),
    );
    let m = match l.fit(&images(3), 2, &mut stream_named(0, "learner")) {
        Err(ReprError::Numerical(m)) => m,
        Err(e) => panic!("expected a Numerical error, got {e:?}"),
        Ok(_) => panic!("constant latents accepted"),
    };
    assert!(
        m.contains("1 of the 2 latents are the same") && m.contains("dimension 1"),
        "{m}"
    );
}

#[test]
fn exit_with_message_before_ready() {
    let l = sh(
        "failing",
        "echo 'loading model... boom: CUDA out of memory' >&2; exit 1",
    );
    let m = external_msg(l.fit(&images(3), 2, &mut stream_named(0, "learner")));
    assert!(m.contains("boom: CUDA out of memory"), "{m}");
    assert!(m.contains("exit status: 1"), "{m}");
    assert!(m.contains("before printing READY"), "{m}");
}

#[test]
fn garbage_instead_of_ready_is_fast_and_kills_the_group() {
    let dir = tempfile::tempdir().unwrap();
    let pidfile = dir.path().join("pid");
    let cmd = format!(
        "sleep 30 & echo $! > '{}'; echo 'epoch 1 loss 0.3'; sleep 30",
        pidfile.display()
    );
    // Fast without a clock: with a ready timeout of an hour, only the garbage line can end the
    // wait before the program's own end (after 30 s, whose message says it exited, not that it
    // was killed).
    let mut l = sh("chatty", &cmd);
    l.ready_timeout = Duration::from_secs(3600);
    let m = external_msg(l.fit(&images(3), 2, &mut stream_named(0, "learner")));
    assert!(m.contains("epoch 1 loss 0.3") && m.contains("READY"), "{m}");
    assert!(m.contains("killed"), "{m}");
    let bg: u32 = std::fs::read_to_string(&pidfile)
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    // A guard against a hang, not a speed check.
    let until = Instant::now() + Duration::from_secs(60);
    while !gone(bg) && Instant::now() < until {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(gone(bg), "background process {bg} of the learner survived");
}

#[test]
fn command_not_found() {
    let l = sh("missing", "ugl-no-such-learner-program --fit");
    let m = external_msg(l.fit(&images(3), 2, &mut stream_named(0, "learner")));
    assert!(m.contains("127") && m.contains("not found"), "{m}");
}

#[test]
fn zero_latents_is_invalid_input_and_starts_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let marker = dir.path().join("started");
    let l = sh("zero", &format!("touch '{}'", marker.display()));
    let r = l.fit(&images(3), 0, &mut stream_named(0, "learner"));
    assert!(matches!(r, Err(ReprError::InvalidInput(_))));
    assert!(!marker.exists());
}

#[test]
fn ready_timeout() {
    let mut l = sh("slow", "sleep 30");
    l.ready_timeout = Duration::from_millis(200);
    // The message is the timeout's (the program would exit after 30 s without READY, which is
    // another message): no clock is read.
    let m = external_msg(l.fit(&images(3), 2, &mut stream_named(0, "learner")));
    assert!(m.contains("ready timeout"), "{m}");
}

#[test]
fn missing_or_wrong_train_latents() {
    let l = sh("no-latents", "echo READY; cat > /dev/null");
    let m = external_msg(l.fit(&images(3), 2, &mut stream_named(0, "learner")));
    assert!(m.contains("train_latents.npy"), "{m}");

    let dir = tempfile::tempdir().unwrap();
    let l = sh(
        "wrong-n",
        &scripted(dir.path(), &npy_f64(2, 2, &[0.0; 4]), "cat > /dev/null"),
    );
    let m = external_msg(l.fit(&images(3), 2, &mut stream_named(0, "learner")));
    assert!(m.contains("shape [2, 2], expected (3, 2)"), "{m}");

    let l = sh(
        "nan",
        &scripted(
            dir.path(),
            &npy_f64(3, 2, &[0.0, 1.0, f64::NAN, 0.0, 0.0, 0.0]),
            "cat > /dev/null",
        ),
    );
    let r = l.fit(&images(3), 2, &mut stream_named(0, "learner"));
    assert!(
        matches!(&r, Err(ReprError::Numerical(m)) if m.contains("non-finite")),
        "{:?}",
        r.err()
    );
}

#[test]
fn wrong_answer_shape_breaks_the_encoder_and_reaps_the_process() {
    let dir = tempfile::tempdir().unwrap();
    let wrong = dir.path().join("wrong.npy");
    std::fs::write(&wrong, npy_f64(1, 3, &[1.0, 2.0, 3.0])).unwrap();
    let cmd = scripted(
        dir.path(),
        &npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]),
        &format!("cat '{}'; cat > /dev/null", wrong.display()),
    );
    let (mut enc, z) = sh("wrong-shape", &cmd)
        .fit_external(&images(3), 2, &mut stream_named(0, "learner"))
        .unwrap();
    assert_eq!(z.data, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    let pid = enc.process_id();
    let mut out = [0.0; 2];
    let m = external_msg(enc.encode_one(images(1).row(0), &mut out));
    assert!(m.contains("shape [1, 3], expected (1, 2)"), "{m}");
    assert!(gone(pid), "process {pid} not reaped after the failure");
    let m = external_msg(enc.encode_one(images(1).row(0), &mut out));
    assert!(m.contains("earlier failure"), "{m}");
}

#[test]
fn non_finite_answer() {
    let dir = tempfile::tempdir().unwrap();
    let nan = dir.path().join("nan.npy");
    std::fs::write(&nan, npy_f64(1, 2, &[0.5, f64::INFINITY])).unwrap();
    let cmd = scripted(
        dir.path(),
        &npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]),
        &format!("cat '{}'; cat > /dev/null", nan.display()),
    );
    let (mut enc, _) = sh("inf", &cmd)
        .fit_external(&images(3), 2, &mut stream_named(0, "learner"))
        .unwrap();
    let m = external_msg(enc.encode_one(images(1).row(0), &mut [0.0; 2]));
    assert!(m.contains("non-finite"), "{m}");
}

#[test]
fn crash_during_encode_reports_status_and_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = scripted(
        dir.path(),
        &npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]),
        "head -c 10 > /dev/null; echo 'Segmentation fault in encoder' >&2; exit 3",
    );
    let (mut enc, _) = sh("crash", &cmd)
        .fit_external(&images(3), 2, &mut stream_named(0, "learner"))
        .unwrap();
    let m = external_msg(enc.encode(&images(2)));
    assert!(
        m.contains("exit status: 3") && m.contains("Segmentation fault in encoder"),
        "{m}"
    );
}

#[test]
fn answer_timeout() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = scripted(
        dir.path(),
        &npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]),
        "sleep 30",
    );
    let mut l = sh("mute", &cmd);
    l.answer_timeout = Duration::from_millis(300);
    let (mut enc, _) = l
        .fit_external(&images(3), 2, &mut stream_named(0, "learner"))
        .unwrap();
    let m = external_msg(enc.encode_one(images(1).row(0), &mut [0.0; 2]));
    assert!(m.contains("answer timeout"), "{m}");
}

#[test]
fn shutdown_reports_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = scripted(
        dir.path(),
        &npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]),
        "cat > /dev/null; echo 'bye' >&2; exit 4",
    );
    let (enc, _) = sh("bad-exit", &cmd)
        .fit_external(&images(3), 2, &mut stream_named(0, "learner"))
        .unwrap();
    let m = external_msg(enc.shutdown());
    assert!(m.contains("exit status: 4") && m.contains("bye"), "{m}");
}

/// The WARN (and higher) events `f` logs on this thread, formatted.
fn warnings_of(f: impl FnOnce()) -> String {
    use std::sync::{Arc, Mutex};
    #[derive(Clone, Default)]
    struct Buf(Arc<Mutex<Vec<u8>>>);
    impl std::io::Write for Buf {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let buf = Buf::default();
    let writer = buf.clone();
    let subscriber = tracing_subscriber::fmt()
        .with_max_level(tracing::Level::WARN)
        .with_ansi(false)
        .with_writer(move || writer.clone())
        .finish();
    tracing::subscriber::with_default(subscriber, f);
    String::from_utf8(buf.0.lock().unwrap().clone()).unwrap()
}

/// A dropped encoder whose program ends badly after stdin is closed (exit 3, a signal, no exit
/// within the grace period) is reported once, as a warning naming the learner, the status and
/// its log file (it was silent); a clean exit, a shutdown() or an earlier failure add nothing.
#[test]
fn a_bad_end_on_drop_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let z = npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    let fitted = |name: &str, after: &str, log: Option<PathBuf>| {
        let mut l = sh(name, &scripted(dir.path(), &z, after));
        l.log_file = log;
        let (mut enc, _) = fit_external(&l, &images(3), 2, 0).unwrap();
        enc.begin_run(stream_named(0, "encoding"));
        enc
    };
    let log = dir.path().join("x.learner.log");
    let w = warnings_of(|| {
        drop(fitted(
            "exit-3",
            "cat > /dev/null; echo 'bye, crashing' >&2; exit 3",
            Some(log.clone()),
        ))
    });
    assert_eq!(w.matches("ended badly").count(), 1, "{w}");
    assert!(
        w.contains("learner 'exit-3'") && w.contains("exit status: 3"),
        "{w}"
    );
    assert!(w.contains("bye, crashing"), "{w}");
    assert!(w.contains(&log.display().to_string()), "{w}");

    let w = warnings_of(|| drop(fitted("signal", "cat > /dev/null; kill -9 $$", None)));
    assert!(
        w.contains("learner 'signal'") && w.contains("SIGKILL"),
        "{w}"
    );

    // Killed, not waited for (the warning says so; no clock is read).
    let w = warnings_of(|| drop(fitted("deaf", "sleep 30", None)));
    assert!(w.contains("learner 'deaf'") && w.contains("killed"), "{w}");

    let w = warnings_of(|| drop(fitted("clean", "cat > /dev/null", None)));
    assert!(w.is_empty(), "{w}");
    let w = warnings_of(|| {
        let m = external_msg(fitted("explicit", "cat > /dev/null; exit 3", None).shutdown());
        assert!(m.contains("exit status: 3"), "{m}");
    });
    assert!(!w.contains("ended badly"), "reported twice: {w}");
    let w = warnings_of(|| {
        let mut enc = fitted("broken", "head -c 10 > /dev/null; exit 3", None);
        let _ = external_msg(enc.encode(&images(2)));
        drop(enc);
    });
    // The failure is reported once, by the error `encode` returned; dropping adds nothing.
    assert!(w.is_empty(), "reported twice: {w}");
}

#[test]
fn the_environment_of_the_program() {
    let dir = tempfile::tempdir().unwrap();
    let env = dir.path().join("env.txt");
    let cmd = scripted(
        dir.path(),
        &npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]),
        &format!(
            "echo \"$UGL_PROTOCOL $UGL_LATENTS $UGL_SEED $(basename \"$UGL_TRAIN\") $(basename \"$UGL_PRIOR\") $UGL_HARNESS_PID $(test -d \"$UGL_WORKDIR\" && echo dir) $(head -c 6 \"$UGL_TRAIN\" | tail -c 5)\" > '{}'; cat > /dev/null",
            env.display()
        ),
    );
    let (enc, _) = sh("env", &cmd)
        .fit_external(&images(3), 2, &mut stream_named(9, "learner"))
        .unwrap();
    enc.shutdown().unwrap();
    let got = std::fs::read_to_string(&env).unwrap();
    let seed = {
        use rand::Rng;
        stream_named(9, "learner").next_u64()
    };
    assert_eq!(
        got.trim(),
        format!(
            "1 2 {seed} train.npy prior.npy {} dir NUMPY",
            std::process::id()
        )
    );
}

#[test]
#[ignore = "timing; run with --ignored --nocapture"]
fn round_trip_timing() {
    let Some(learner) = python_learner() else {
        return;
    };
    let set = images(200);
    let (mut enc, _) = fit_external(&learner, &set, 10, 0).unwrap();
    let mut out = [0.0; 10];
    for i in 0..200 {
        enc.encode_one(set.row(i), &mut out).unwrap();
    }
    let reps = 5000;
    let t = Instant::now();
    for i in 0..reps {
        enc.encode_one(set.row(i % 200), &mut out).unwrap();
    }
    let one = t.elapsed() / reps as u32;
    let big = images(1000);
    let t = Instant::now();
    let _ = enc.encode(&big).unwrap();
    let batch = t.elapsed() / 1000;
    eprintln!(
        "external random projection (python3 + numpy), latents 10: encode_one round trip {one:?} per image ({reps} calls); batch encode of 1000 images {batch:?} per image"
    );
    enc.shutdown().unwrap();
}

#[test]
fn ready_line_may_carry_the_fit_time() {
    let dir = tempfile::tempdir().unwrap();
    let z = npy_f64(3, 2, &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    let t = dir.path().join("z.npy");
    std::fs::write(&t, &z).unwrap();
    let with = |ready: &str| {
        format!(
            "cat '{}' > \"$UGL_TRAIN_LATENTS\"; echo '{ready}'; cat > /dev/null",
            t.display()
        )
    };
    let (enc, _) =
        fit_external(&sh("timed", &with("READY fit_s=12.25")), &images(3), 2, 0).unwrap();
    assert_eq!(enc.reported_fit_s(), Some(12.25));
    let (enc, _) = fit_external(&sh("plain", &with("READY")), &images(3), 2, 0).unwrap();
    assert_eq!(enc.reported_fit_s(), None);
    let m = external_msg(fit_external(
        &sh("bad", &with("READY fit_s=soon")),
        &images(3),
        2,
        0,
    ));
    assert!(m.contains("fit_s must be a number"), "{m}");
    let m = external_msg(fit_external(
        &sh("bad", &with("READY loss=3")),
        &images(3),
        2,
        0,
    ));
    assert!(m.contains("unknown field") && m.contains("loss=3"), "{m}");
}

#[test]
fn identical_images_are_sent_once_per_run() {
    // A learner that answers every request with the number of requests answered so far: a
    // cached answer is visible as an unchanged count.
    if Command::new("python3")
        .arg("-c")
        .arg("pass")
        .status()
        .is_err()
    {
        eprintln!("SKIPPED: python3 not found");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let z = npy_f64(3, 1, &[0.0, 1.0, 2.0]);
    let t = dir.path().join("z.npy");
    std::fs::write(&t, &z).unwrap();
    let script = dir.path().join("count.py");
    std::fs::write(
        &script,
        r#"import struct, sys
inp, out = sys.stdin.buffer, sys.stdout.buffer
out.write(b"READY\n"); out.flush()
count = 0
while True:
    head = inp.read(10)
    if len(head) < 10:
        break
    hlen = int.from_bytes(head[8:10], "little")
    inp.read(hlen + 4900 * 4)
    count += 1
    h = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1), }"
    h = h + " " * (-(10 + len(h) + 1) % 64) + "\n"
    out.write(b"\x93NUMPY\x01\x00" + len(h).to_bytes(2, "little") + h.encode() + struct.pack("<d", count))
    out.flush()
"#,
    )
    .unwrap();
    let cmd = format!(
        "cat '{}' > \"$UGL_TRAIN_LATENTS\"; exec python3 '{}'",
        t.display(),
        script.display()
    );
    let (mut enc, _) = fit_external(&sh("counter", &cmd), &images(3), 1, 0).unwrap();
    let set = images(3);
    let mut out = [0.0];
    let mut got = Vec::new();
    for i in [0, 1, 0, 0, 2, 1] {
        enc.encode_one(set.row(i), &mut out).unwrap();
        got.push(out[0]);
    }
    assert_eq!(got, [1.0, 2.0, 1.0, 1.0, 3.0, 2.0]);
    assert_eq!((enc.requests_sent, enc.cache_hits), (3, 3));
    enc.begin_run(stream_named(0, "encoding"));
    enc.encode_one(set.row(0), &mut out).unwrap();
    assert_eq!(out[0], 4.0, "the cache is per run");
}

/// The harness tells the program the pictures' shape (`UGL_IMAGE`, from the environment through
/// the fit context); a fit without one does not set it.
#[test]
fn the_program_is_told_the_pictures_shape() {
    let dir = tempfile::tempdir().unwrap();
    let seen = dir.path().join("seen");
    let l = sh(
        "shape",
        &format!(
            "echo \"${{UGL_IMAGE-unset}}\" > '{}'; exit 1",
            seen.display()
        ),
    );
    let ctx = FitContext {
        image: Some(ugl_types::RGB64),
        ..FitContext::default()
    };
    assert!(
        l.fit_in(&images(3), 2, &mut stream_named(0, "learner"), &ctx)
            .is_err()
    );
    assert_eq!(std::fs::read_to_string(&seen).unwrap().trim(), "64x64x3");
    assert!(
        l.fit(&images(3), 2, &mut stream_named(0, "learner"))
            .is_err()
    );
    assert_eq!(std::fs::read_to_string(&seen).unwrap().trim(), "unset");
}
