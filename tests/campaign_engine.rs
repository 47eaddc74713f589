//! The campaign engine: bad configurations, worker-count independence, resume after kill -9.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn ugl() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ugl"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn run(args: &[&str]) -> Output {
    ugl().args(args).output().expect("ugl runs")
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn every_bad_config_gives_a_one_line_error_naming_the_key_and_touches_nothing() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_configs");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert!(files.len() >= 20, "the corpus has {} configs", files.len());
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results");
    std::fs::create_dir(&out).unwrap();
    let sentinel = out.join("existing.parquet");
    std::fs::write(&sentinel, b"an existing result").unwrap();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let expect = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{} lacks '# expect:'", f.display()));
        // `ugl run` reads the same file as a profile and checks all of it first.
        for cmd in ["plan", "campaign", "run"] {
            let o = match cmd {
                "plan" => run(&[cmd, "--config", p(&f)]),
                "campaign" => run(&[cmd, "--config", p(&f), "--out", p(&out)]),
                _ => run(&[
                    cmd,
                    "--profile",
                    p(&f),
                    "--env",
                    "armball",
                    "--algo",
                    "rpe",
                    "--out",
                    p(&out),
                ]),
            };
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{} ({cmd}): {err}", f.display());
            assert_eq!(
                err.trim_end().lines().count(),
                1,
                "{}: one line: {err}",
                f.display()
            );
            assert!(
                err.contains(expect),
                "{}: {err:?} should mention {expect:?}",
                f.display()
            );
        }
    }
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        1,
        "nothing was written"
    );
    assert_eq!(std::fs::read(&sentinel).unwrap(), b"an existing result");
}

#[test]
fn bad_output_locations() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let o = run(&[
        "campaign",
        "--config",
        "data/campaigns/baselines.toml",
        "--out",
        p(&file),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a directory"));
    // A location nobody can create (even root): /proc is read-only.
    let o = run(&[
        "campaign",
        "--config",
        "data/campaigns/baselines.toml",
        "--out",
        "/proc/ugl-bench-test/results",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("/proc/ugl-bench-test/results") && err.trim_end().lines().count() == 1,
        "{err}"
    );
}

fn write_config(dir: &Path, reps: usize) -> PathBuf {
    let cfg = dir.join("engine.toml");
    std::fs::write(
        &cfg,
        format!(
            "[campaign]\nname = \"engine\"\nreps = {reps}\n[matrix]\nenvs = [\"armball\", \"armarrow\"]\n\
             algos = [\"rpe\", \"rge-efr\", \"rge-pca\", \"rge-vae\"]\nsamplers = [\"kde\", \"gaussian\"]\n\
             latents = [\"true\"]\nvariants = [\"faithful\", \"corrected\"]\n\
             [ugl]\nimages = 300\n[explore]\nepochs = 1500\neval_every = 100\n\
             [learners.vae]\niterations = 20\nhidden = [16, 8]\n"
        ),
    )
    .unwrap();
    cfg
}

#[test]
fn results_do_not_depend_on_the_worker_count() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_config(dir.path(), 2);
    let (a, b) = (dir.path().join("one"), dir.path().join("two"));
    assert!(
        run(&[
            "campaign",
            "--config",
            p(&cfg),
            "--out",
            p(&a),
            "--jobs",
            "1",
            "--quiet"
        ])
        .status
        .success()
    );
    assert!(
        run(&[
            "campaign",
            "--config",
            p(&cfg),
            "--out",
            p(&b),
            "--jobs",
            "2",
            "--quiet"
        ])
        .status
        .success()
    );
    let (ra, rb) = (common::parquet_files(&a), common::parquet_files(&b));
    // Per env: rpe, rge-efr, rge-pca (kde; no prior for gaussian goals), rge-vae x 2 variants
    // x 2 samplers; 2 reps; 2 files per run. With 1 worker the VAE trains on 2 threads, with 2
    // workers on 1 thread each: the bytes must not differ.
    assert_eq!(ra.len(), 2 * 7 * 2 * 2);
    assert!(ra == rb, "1 and 2 workers give different result files");
}

#[test]
fn a_campaign_killed_mid_way_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_config(dir.path(), 6);
    let reference = dir.path().join("reference");
    assert!(
        run(&[
            "campaign",
            "--config",
            p(&cfg),
            "--out",
            p(&reference),
            "--quiet"
        ])
        .status
        .success()
    );
    let expected = common::parquet_files(&reference);

    let out = dir.path().join("killed");
    let mut child = ugl()
        .args([
            "campaign",
            "--config",
            p(&cfg),
            "--out",
            p(&out),
            "--quiet",
            "--jobs",
            "2",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill -9 as soon as some, but not all, runs are stored (whenever that is: the assertions
    // below hold for any kill time).
    let t0 = Instant::now();
    loop {
        let done = std::fs::read_dir(&out)
            .map(|d| {
                d.filter(|e| {
                    e.as_ref()
                        .unwrap()
                        .path()
                        .extension()
                        .is_some_and(|x| x == "json")
                })
                .count()
            })
            .unwrap_or(0);
        if done >= 3
            || child.try_wait().unwrap().is_some()
            || t0.elapsed() > Duration::from_secs(120)
        {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let _ = child.kill();
    let _ = child.wait();
    let partial = common::parquet_files(&out);
    // Whatever was stored is complete and correct.
    for (name, bytes) in &partial {
        let reference = expected
            .iter()
            .find(|(n, _)| n == name)
            .expect("a planned run");
        assert!(
            &reference.1 == bytes,
            "{name} differs from the uninterrupted campaign"
        );
    }
    let o = run(&["campaign", "--config", p(&cfg), "--out", p(&out), "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        common::parquet_files(&out) == expected,
        "resumed campaign differs from the uninterrupted one"
    );
    // A changed configuration never reuses (nor mixes with) the stored runs: it is refused
    // here, and runs in a store of its own.
    let text = std::fs::read_to_string(&cfg)
        .unwrap()
        .replace("epochs = 1500", "epochs = 1400");
    std::fs::write(&cfg, text).unwrap();
    let o = run(&["campaign", "--config", p(&cfg), "--out", p(&out), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("another configuration"),
        "{err}"
    );
    assert!(
        common::parquet_files(&out) == expected,
        "a refused campaign touched the store"
    );
    let elsewhere = dir.path().join("elsewhere");
    let o = run(&[
        "campaign",
        "--config",
        p(&cfg),
        "--out",
        p(&elsewhere),
        "--quiet",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("{} runs executed", expected.len() / 2)),
        "{err}"
    );
}

/// A full disk: a 64 KiB tmpfs (mounted in a private user + mount namespace with `unshare`, so
/// no root is needed) fills up after a few runs. The campaign must stop with a one-line error
/// naming the path, leave no temporary files behind, and not touch the existing result. Where
/// user and mount namespaces are not available (`unshare -rm` fails, e.g. a container without
/// them) it passes without checking anything and prints SKIPPED (`-- --nocapture` shows it); on
/// the machines this project's sessions run on, as root or not, it runs.
#[test]
fn a_full_disk_gives_a_clear_error_and_touches_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "disk.toml",
        "[campaign]\nname = \"disk\"\nreps = 20\n[matrix]\nenvs = [\"armball\", \"armarrow\"]\n\
         algos = [\"rpe\", \"rge-efr\"]\n[explore]\nepochs = 2000\n",
    );
    let mnt = dir.path().join("tiny");
    std::fs::create_dir(&mnt).unwrap();
    let script = format!(
        "mount -t tmpfs -o size=64k tmpfs {m} || exit 77; mkdir {m}/results && \
         printf 'an existing result' > {m}/results/existing.parquet && \
         {ugl} campaign --config {cfg} --out {m}/results --jobs 2 --quiet; code=$?; \
         ls -a {m}/results > {d}/listing; cat {m}/results/existing.parquet > {d}/existing; exit $code",
        m = p(&mnt),
        d = p(dir.path()),
        ugl = env!("CARGO_BIN_EXE_ugl"),
        cfg = p(&cfg),
    );
    let skip = || eprintln!("SKIPPED: cannot mount a tmpfs in a user namespace here (unshare -rm)");
    let o = match Command::new("unshare")
        .args(["-rm", "sh", "-c", &script])
        .output()
    {
        Err(_) => return skip(),
        Ok(o)
            if o.status.code() == Some(77)
                || String::from_utf8_lossy(&o.stderr).contains("unshare:") =>
        {
            return skip();
        }
        Ok(o) => o,
    };
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err:?}");
    assert!(
        err.contains("No space left on device") && err.contains("/results/"),
        "{err}"
    );
    let listing = std::fs::read_to_string(dir.path().join("listing")).unwrap();
    assert!(
        !listing.contains(".tmp"),
        "temporary files left behind: {listing}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("existing")).unwrap(),
        "an existing result"
    );
}

/// `--refresh-diagnostics` brings an older store up to date (latent-quality measure, goal-space
/// figure data) to exactly what a fresh campaign writes, without touching a run's data files;
/// a second refresh has nothing to do.
#[test]
fn refresh_diagnostics_rebuilds_old_measures_and_figure_data_without_touching_runs() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "diag.toml",
        "[campaign]\nname = \"diag\"\nreps = 2\n[matrix]\nenvs = [\"armball\", \"armarrow\"]\n\
         algos = [\"rge-pca\", \"rge-vae\"]\nsamplers = [\"kde\"]\nlatents = [\"true\"]\n\
         variants = [\"corrected\"]\n[ugl]\nimages = 300\n[explore]\nbootstrap_epochs = 10\nepochs = 100\n\
         eval_every = 50\n[learners.vae]\niterations = 20\nhidden = [16, 8]\n",
    );
    let out = dir.path().join("res");
    let campaign = |extra: &[&str]| {
        let mut args = vec!["campaign", "--config", p(&cfg), "--out", p(&out), "--quiet"];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    campaign(&[]);
    // Seed 0 of each learned cell has figure data; the VAE has a reconstruction grid.
    let gs = out.join("goal_spaces");
    let mut names: Vec<String> = std::fs::read_dir(&gs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "armarrow.rge-pca.l3.s0.json",
            "armarrow.rge-vae.corrected.l3.s0.json",
            "armarrow.rge-vae.corrected.l3.s0.reconstructions.png",
            "armball.rge-pca.l2.s0.json",
            "armball.rge-vae.corrected.l2.s0.json",
            "armball.rge-vae.corrected.l2.s0.reconstructions.png",
        ]
    );
    let sample: serde_json::Value = serde_json::from_slice(
        &std::fs::read(gs.join("armarrow.rge-vae.corrected.l3.s0.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(sample["grid_latents"].as_array().unwrap().len(), 21 * 21);
    assert_eq!(sample["grid_latents"][0].as_array().unwrap().len(), 3);
    let manifests = |dir: &Path| -> Vec<(PathBuf, serde_json::Value)> {
        let mut v: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .map(|p| {
                let m = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
                (p, m)
            })
            .collect();
        v.sort_by(|a, b| a.0.cmp(&b.0));
        v
    };
    let fresh = manifests(&out);
    assert_eq!(fresh.len(), 8);
    for (_, m) in &fresh {
        assert_eq!(m["latent_quality"]["version"], 3, "{m}");
        let groups = m["latent_quality"]["groups"].as_array().unwrap().len();
        assert_eq!(groups, if m["env"] == "armarrow" { 3 } else { 1 });
        // Trustworthiness and continuity against the position (and the arrow's whole state).
        let spaces = m["latent_quality"]["neighbourhoods"]
            .as_array()
            .unwrap()
            .len();
        assert_eq!(spaces, if m["env"] == "armarrow" { 2 } else { 1 });
    }
    let samples: Vec<(String, Vec<u8>)> = names
        .iter()
        .map(|n| (n.clone(), std::fs::read(gs.join(n)).unwrap()))
        .collect();
    let data = common::parquet_files(&out);

    // An older store: measure version 1 (no version, no groups), no figure data.
    for (path, m) in &fresh {
        let mut old = m.clone();
        let q = old["latent_quality"].as_object_mut().unwrap();
        q.remove("version");
        q.remove("groups");
        q.remove("neighbourhoods");
        std::fs::write(path, serde_json::to_vec_pretty(&old).unwrap()).unwrap();
    }
    std::fs::remove_dir_all(&gs).unwrap();
    let old = manifests(&out);
    let log = campaign(&["--refresh-diagnostics", "--jobs", "2"]);
    assert!(
        log.contains("8 representations refreshed: 8 runs")
            && log.contains("4 figure samples written"),
        "{log}"
    );
    // Manifests are never rewritten: the new measure is in each run's diagnostics sidecar, and
    // it is exactly what a fresh campaign measures.
    assert!(manifests(&out) == old, "a manifest was rewritten");
    for (path, m) in &fresh {
        let run_id = m["run_id"].as_str().unwrap();
        let d = ugl_types::Diagnostics::read(&out, run_id)
            .unwrap()
            .unwrap_or_else(|| panic!("no diagnostics for {}", path.display()));
        assert_eq!(
            serde_json::to_value(&d.latent_quality).unwrap(),
            m["latent_quality"],
            "{run_id}"
        );
        assert_eq!(d.crate_versions, m["crate_versions"], "{run_id}");
    }
    for (name, bytes) in &samples {
        assert!(
            std::fs::read(gs.join(name)).unwrap() == *bytes,
            "{name} differs from the fresh campaign's"
        );
    }
    assert!(common::parquet_files(&out) == data, "run data touched");
    let log = campaign(&["--refresh-diagnostics"]);
    assert!(
        log.contains("0 representations refreshed: 0 runs")
            && log.contains("(8 already had it), 0 figure samples"),
        "{log}"
    );
}

fn small_config(dir: &Path, file: &str, name: &str, epochs: usize) -> PathBuf {
    let cfg = dir.join(file);
    std::fs::write(
        &cfg,
        format!(
            "[campaign]\nname = \"{name}\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
             algos = [\"rpe\", \"rge-efr\"]\n[explore]\nepochs = {epochs}\neval_every = 100\n"
        ),
    )
    .unwrap();
    cfg
}

/// One store holds one campaign with one configuration: another configuration (or another
/// campaign) is refused before any run, also when the record predates the configuration hash,
/// and of two campaigns started together on one store exactly one runs.
#[test]
fn a_store_refuses_another_configuration_or_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("store");
    let a = small_config(dir.path(), "a.toml", "small", 200);
    let b = small_config(dir.path(), "b.toml", "small", 300);
    let other = small_config(dir.path(), "c.toml", "other", 200);
    let campaign =
        |cfg: &Path, out: &Path| run(&["campaign", "--config", p(cfg), "--out", p(out), "--quiet"]);
    assert!(campaign(&a, &out).status.success());
    assert!(
        campaign(&a, &out).status.success(),
        "the same campaign again resumes"
    );
    let before = common::parquet_files(&out);
    let o = campaign(&b, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("another configuration"),
        "{err}"
    );
    let o = campaign(&other, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("holds campaign `small`"),
        "{err}"
    );
    assert_eq!(
        common::parquet_files(&out),
        before,
        "a refused campaign touched the store"
    );
    // A record written before the configuration hash: the manifests decide.
    let record = out.join("campaign.toml");
    let text = std::fs::read_to_string(&record).unwrap();
    let legacy: String = text
        .lines()
        .filter(|l| !l.starts_with("configuration"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(legacy, text);
    std::fs::write(&record, &legacy).unwrap();
    let o = campaign(&b, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("[explore]"), "{err}");
    assert!(
        campaign(&a, &out).status.success(),
        "the matching configuration upgrades the record"
    );
    assert!(
        std::fs::read_to_string(&record)
            .unwrap()
            .contains("configuration = ")
    );
    // Two campaigns of different configurations started together: one runs, one is refused.
    let fresh = dir.path().join("fresh");
    let start = |cfg: &Path| {
        ugl()
            .args([
                "campaign",
                "--config",
                p(cfg),
                "--out",
                p(&fresh),
                "--quiet",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (x, y) = (start(&a), start(&b));
    let (x, y) = (x.wait_with_output().unwrap(), y.wait_with_output().unwrap());
    assert_eq!(
        [x.status.success(), y.status.success()]
            .iter()
            .filter(|s| **s)
            .count(),
        1,
        "{} / {}",
        String::from_utf8_lossy(&x.stderr),
        String::from_utf8_lossy(&y.stderr)
    );
}

/// The distractor's constants enter the config hash of ArmBalls runs only: an ArmBall run's
/// bytes do not depend on them, so neither does its hash (it used to change, and the run was
/// recomputed for nothing).
#[test]
fn distractor_constants_enter_only_the_hash_of_armballs_runs() {
    let dir = tempfile::tempdir().unwrap();
    let hash = |env: &str, noise: &str| {
        let name = format!("{env}-{noise}");
        let profile = dir.path().join(format!("{name}.toml"));
        std::fs::write(
            &profile,
            format!(
                "[campaign]\nname = \"h\"\nreps = 1\n[matrix]\nenvs = [\"{env}\"]\nalgos = [\"rpe\"]\n\
                 [explore]\nepochs = 120\neval_every = 60\n[env]\ndistractor_noise = {noise}\n"
            ),
        )
        .unwrap();
        let out = dir.path().join(&name);
        let o = run(&[
            "run",
            "--env",
            env,
            "--algo",
            "rpe",
            "--profile",
            p(&profile),
            "--out",
            p(&out),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let m: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join(format!("{env}.rpe.s0.json"))).unwrap(),
        )
        .unwrap();
        m["config_hash"].as_str().unwrap().to_string()
    };
    assert_eq!(hash("armball", "0.1"), hash("armball", "0.2"));
    assert_ne!(hash("armballs", "0.1"), hash("armballs", "0.2"));
}

/// The follow-up's convolutional networks get the reconstruction figure too, in colour: seed 0's
/// goal-space data holds an RGB grid of eight held-out 64 x 64 pictures above their
/// reconstructions (4x upscaled, 2-pixel gaps), which the report's goal-space section shows.
#[test]
fn a_convolutional_network_writes_an_rgb_reconstruction_grid() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "conv.toml",
        "[campaign]\nname = \"conv\"\nreps = 1\n[matrix]\nenvs = [\"armballs-corl\"]\n\
         algos = [\"rge-conv-vae\"]\nsamplers = [\"kde\"]\nlatents = [2]\n[ugl]\nimages = 64\n\
         [explore]\nbootstrap_epochs = 10\nepochs = 30\neval_every = 30\n\
         [learners.conv-vae]\niterations = 2\nbatch = 8\nfilters = 4\nhidden = 8\n",
    );
    let out = dir.path().join("res");
    let o = run(&["campaign", "--config", p(&cfg), "--out", p(&out), "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let gs = out.join("goal_spaces");
    let sample: serde_json::Value = serde_json::from_slice(
        &std::fs::read(gs.join("armballs-corl.rge-conv-vae.l2.s0.json")).unwrap(),
    )
    .unwrap();
    let name = sample["reconstructions"]
        .as_str()
        .expect("a reconstruction grid");
    // The PNG header (IHDR, the first chunk): width and height, then bit depth 8 and colour
    // type 2 (RGB).
    let png = std::fs::read(gs.join(name)).unwrap();
    let be = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&png[12..16], b"IHDR");
    let cell = 64 * 2;
    assert_eq!((be(16), be(20)), (8 * cell + 7 * 2, 2 * cell + 2));
    assert_eq!((png[24], png[25]), (8, 2), "8-bit RGB");
}
