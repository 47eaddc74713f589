//! Integration tests of the `ugl` command line: the contract other tools depend on.

use crate::common;

use std::path::Path;
use std::process::{Command, Output};

fn ugl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("ugl runs")
}

/// The words of `line`, each `{}` replaced by the next of `values` (one argument each).
fn argv<'a>(line: &'a str, values: &[&'a str]) -> Vec<&'a str> {
    let mut values = values.iter();
    let args: Vec<&str> = line
        .split_whitespace()
        .map(|w| {
            if w == "{}" {
                values.next().expect("a value per {}")
            } else {
                w
            }
        })
        .collect();
    assert!(values.next().is_none(), "more values than {{}} in {line:?}");
    args
}

/// `ugl campaign --config CFG --out OUT --quiet` and `extra`.
fn campaign(cfg: &str, out: &str, extra: &[&str]) -> Output {
    let mut args = vec!["campaign", "--config", cfg, "--out", out, "--quiet"];
    args.extend_from_slice(extra);
    ugl(&args)
}

/// Write `to` as a copy of `from` with `what` replaced by `with`.
fn replaced(from: &Path, to: &Path, what: &str, with: &str) {
    let text = std::fs::read_to_string(from).unwrap();
    assert!(text.contains(what), "{} has no {what:?}", from.display());
    std::fs::write(to, text.replace(what, with)).unwrap();
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A usage or input error: exit code 2 and exactly one line on stderr.
fn assert_one_line_error(o: &Output, needle: &str) {
    assert_eq!(o.status.code(), Some(2), "stderr: {}", stderr(o));
    let err = stderr(o);
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err:?}");
    assert!(err.contains(needle), "{err:?} should mention {needle:?}");
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn rollout_contract() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("params.json");
    std::fs::write(
        &f,
        format!(
            "[{z}, {o}]",
            z = serde_json::to_string(&[0.0; 21]).unwrap(),
            o = serde_json::to_string(&[0.3; 21]).unwrap()
        ),
    )
    .unwrap();
    for env in ["armball", "armarrow"] {
        let o = ugl(&["rollout", "--env", env, "--params", p(&f)]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
        let first = &v[0];
        assert_eq!(first["moved"], false);
        let hand: Vec<f64> = serde_json::from_value(first["hand"].clone()).unwrap();
        assert!(hand[0].abs() < 1e-12 && (hand[1] - 1.0).abs() < 1e-12);
        let object: Vec<f64> = serde_json::from_value(first["object"].clone()).unwrap();
        let expected: &[f64] = if env == "armball" {
            &[0.6, 0.6]
        } else {
            &[0.6, 0.6, 0.6]
        };
        assert_eq!(object, expected);
        assert_eq!(v.as_array().unwrap().len(), 2);
    }
    std::fs::write(&f, "[[0.1, 0.2]]").unwrap();
    assert_one_line_error(
        &ugl(&["rollout", "--env", "armball", "--params", p(&f)]),
        "21",
    );
    std::fs::write(&f, "not json").unwrap();
    assert_one_line_error(
        &ugl(&["rollout", "--env", "armball", "--params", p(&f)]),
        "params.json",
    );
    assert_one_line_error(
        &ugl(&[
            "rollout",
            "--env",
            "armball",
            "--params",
            "/nonexistent/x.json",
        ]),
        "/nonexistent/x.json",
    );
    assert_one_line_error(
        &ugl(&["rollout", "--env", "armbal", "--params", p(&f)]),
        "armbal",
    );
}

/// The follow-up's own ArmBalls (`armballs-corl`): 49 parameters an episode, 64x64 RGB pictures,
/// and the whole pipeline (an explorer in an engineered space, a learner on its pictures) runs on
/// it, to the same bytes twice.
#[test]
fn the_followups_own_armballs_takes_49_parameters_draws_rgb_and_runs() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("params.json");
    std::fs::write(
        &f,
        serde_json::to_string(&[vec![0.0; 49], vec![0.2; 49]]).unwrap(),
    )
    .unwrap();
    let o = ugl(&[
        "rollout",
        "--env",
        "armballs-corl",
        "--params",
        p(&f),
        "--seed",
        "4",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    // At rest the arm points along +x (no angle shift in the authors' arm).
    let hand: Vec<f64> = serde_json::from_value(v[0]["hand"].clone()).unwrap();
    assert_eq!(hand, [1.0, 0.0]);
    let object: Vec<f64> = serde_json::from_value(v[0]["object"].clone()).unwrap();
    assert_eq!(object[..2], [0.6, 0.6]);
    assert!(object[2..].iter().all(|d| d.abs() <= 0.95) && object[2..] != [0.7, -0.45]);
    std::fs::write(&f, serde_json::to_string(&[vec![0.0; 21]]).unwrap()).unwrap();
    assert_one_line_error(
        &ugl(&["rollout", "--env", "armballs-corl", "--params", p(&f)]),
        "armballs-corl takes 49",
    );
    let npy = dir.path().join("a.npy");
    let o = ugl(&[
        "render",
        "--env",
        "armballs-corl",
        "--state",
        "0.6,0.6,-0.5,0.3",
        "--out",
        p(&npy),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&npy).unwrap();
    let header = String::from_utf8_lossy(&bytes[..128]);
    assert!(header.contains("'shape': (64, 64, 3)"), "{header}");
    let run = |out: &Path, algo: &str| {
        let o = ugl(&argv(
            "run --env armballs-corl --algo {} --latents 4 --images 200 --epochs 150 --out {} --no-cache",
            &[algo, p(out)],
        ));
        assert!(o.status.success(), "{algo}: {}", stderr(&o));
        let summary: serde_json::Value =
            serde_json::from_str(stdout(&o).lines().last().unwrap()).unwrap();
        assert!(
            summary["n_moved"].as_u64().unwrap() > 0,
            "{algo}: {summary}"
        );
    };
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for algo in ["rge-efr", "rge-pca"] {
        run(&a, algo);
        run(&b, algo);
    }
    let (ra, rb) = (common::parquet_files(&a), common::parquet_files(&b));
    assert_eq!(ra.len(), 4);
    assert!(ra == rb, "the same runs, the same bytes");
}

#[test]
fn klc_contract() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("o.csv");
    std::fs::write(&f, "x,y\n0.62,0.62\n0.63,0.63\n").unwrap();
    let o = ugl(&["klc", "--env", "armball", "--outcomes", p(&f)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: f64 = stdout(&o).trim().parse().unwrap();
    assert!((v - 756f64.ln()).abs() < 1e-12);
    std::fs::write(&f, "x,y\n0.99,0.99\n").unwrap();
    assert_eq!(
        stdout(&ugl(&["klc", "--env", "armball", "--outcomes", p(&f)])).trim(),
        "inf"
    );
    std::fs::write(&f, "x,y,angle\n0.1,0.1,0.5\n").unwrap();
    let o = ugl(&["klc", "--env", "armarrow", "--outcomes", p(&f)]);
    assert!((stdout(&o).trim().parse::<f64>().unwrap() - 22680f64.ln()).abs() < 1e-12);
    assert_one_line_error(
        &ugl(&["klc", "--env", "armball", "--outcomes", p(&f)]),
        "header",
    );
    std::fs::write(&f, "x,y\n0.1,zz\n").unwrap();
    assert_one_line_error(
        &ugl(&["klc", "--env", "armball", "--outcomes", p(&f)]),
        "zz",
    );
}

#[test]
fn render_contract() {
    let dir = tempfile::tempdir().unwrap();
    let npy = dir.path().join("ball.npy");
    let o = ugl(&argv(
        "render --env armball --state 0.2,-0.4 --out {}",
        &[p(&npy)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&npy).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    assert!(bytes.len() >= 4900 * 4 + 64);
    let png = dir.path().join("arrow.png");
    let o = ugl(&argv(
        "render --env armarrow --state -0.3,0.1,0.5 --out {}",
        &[p(&png)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    assert_one_line_error(
        &ugl(&argv(
            "render --env armball --state 0.2 --out {}",
            &[p(&npy)],
        )),
        "2 comma-separated",
    );
    assert_one_line_error(
        &ugl(&argv(
            "render --env armball --state 1.2,0 --out {}",
            &[p(&npy)],
        )),
        "outside",
    );
    assert_one_line_error(
        &ugl(&argv("render --env armball --state 0,0 --out x.jpg", &[])),
        ".npy or .png",
    );
}

#[test]
fn run_contract_and_determinism() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let args = |out: &Path, seed: &str| {
        ugl(&argv(
            "run --env armarrow --algo rge-efr --seed {} --epochs 400 --out {}",
            &[seed, p(out)],
        ))
    };
    let o = args(&a, "1");
    assert!(o.status.success(), "{}", stderr(&o));
    let last = stdout(&o).lines().last().unwrap().to_string();
    let s: serde_json::Value = serde_json::from_str(&last).unwrap();
    assert_eq!(s["run"], "armarrow.rge-efr.s1");
    for key in ["final_klc", "n_moved", "coverage"] {
        assert!(s[key].is_number(), "{key} in {last}");
    }
    // Same inputs -> byte-identical result files.
    assert!(args(&b, "1").status.success());
    for f in [
        "armarrow.rge-efr.s1.parquet",
        "armarrow.rge-efr.s1.outcomes.parquet",
    ] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    // A different seed gives different results.
    assert!(args(&b, "2").status.success());
    assert_ne!(
        std::fs::read(a.join("armarrow.rge-efr.s1.outcomes.parquet")).unwrap(),
        std::fs::read(b.join("armarrow.rge-efr.s2.outcomes.parquet")).unwrap()
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("armarrow.rge-efr.s1.json")).unwrap())
            .unwrap();
    assert_eq!(m["reduced_budget"], true);
    assert_eq!(m["explore"]["epochs"], 400);
}

/// A run measures what it discovered when it ends and records it in its manifest: the same
/// numbers the report computes from its outcomes file. So the outcomes file may be left out of
/// a store (the report and a resumed campaign accept the run without it), but not when the
/// manifest records no measures, and a present outcomes file must still match its digest.
#[test]
fn a_run_records_its_discovery_and_its_outcomes_file_may_be_left_out() {
    let dir = tempfile::tempdir().unwrap();
    for (env, algo, id) in [
        ("armarrow", "rge-efr", "armarrow.rge-efr.s1"),
        ("armball", "rpe", "armball.rpe.s1"),
    ] {
        let out = dir.path().join(env);
        let o = ugl(&argv(
            "run --env {} --algo {} --seed 1 --epochs 300 --out {}",
            &[env, algo, p(&out)],
        ));
        assert!(o.status.success(), "{}", stderr(&o));
        let stem = out.join(id);
        let run = ugl_report::load::load_run(&stem, String::new()).unwrap();
        let recorded = run
            .manifest
            .discovery
            .clone()
            .expect("the manifest records discovery");
        let spec = ugl_types::EnvSpec::by_name(env).unwrap();
        let measured = ugl_types::RunDiscovery::measure(spec, &run.outcomes)
            .unwrap()
            .unwrap();
        assert_eq!(
            recorded, measured,
            "{id}: recorded = measured from the outcomes file"
        );
        assert_eq!(recorded.at_end.klc, run.manifest.summary.final_klc, "{id}");
        assert_eq!(recorded.at_end.n_outcomes, run.outcomes.len(), "{id}");
        assert!(
            recorded.error_at_rest.is_some(),
            "{id}: some episode left the object"
        );

        // Without its outcomes file the run is still complete, with the same measures.
        let outcomes = out.join(format!("{id}.outcomes.parquet"));
        let bytes = std::fs::read(&outcomes).unwrap();
        std::fs::remove_file(&outcomes).unwrap();
        let kept = ugl_report::load::load_run(&stem, String::new()).unwrap();
        assert!(kept.outcomes.is_empty());
        assert_eq!(kept.discovery().unwrap(), Some(recorded.clone()));
        ugl_types::verify_files(&out, &kept.manifest).unwrap();
        // A present outcomes file must match its digest.
        std::fs::write(&outcomes, &bytes[..bytes.len() / 2]).unwrap();
        assert!(ugl_types::verify_files(&out, &kept.manifest).is_err());
        assert!(ugl_report::load::load_run(&stem, String::new()).is_err());
        // A manifest without measures needs its outcomes file: refused, naming it.
        std::fs::remove_file(&outcomes).unwrap();
        let json_path = out.join(format!("{id}.json"));
        let mut m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
        m.as_object_mut().unwrap().remove("discovery");
        std::fs::write(&json_path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        let err = ugl_report::load::load_run(&stem, String::new()).unwrap_err();
        assert!(
            err.to_string().contains(&format!("{id}.outcomes.parquet")),
            "{err}"
        );
    }
}

/// The audit's forged discovery records: a manifest's record is covered by the hash beside it,
/// checked for range and against the summary, and recomputed where the outcomes file is kept.
/// `ugl status --require-complete` and `ugl report` name the damaged run, and the report refuses
/// it, for each of: a better goal error and coverage written in (hash kept, or dropped as in an
/// older manifest), a coverage of -5, an error of 1e300, a moved count that disagrees with the
/// summary.
#[test]
fn a_forged_discovery_record_is_detected() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "tiny.toml",
        "[campaign]\nname = \"tiny\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-efr\"]\n[explore]\nepochs = 200\neval_every = 100\n",
    );
    let store = dir.path().join("res");
    let out = store.join("tiny");
    let campaign = ugl(&argv(
        "campaign --config {} --out {} --jobs 1 --quiet",
        &[p(&cfg), p(&out)],
    ));
    assert!(campaign.status.success(), "{}", stderr(&campaign));
    let id = "armball.rge-efr.s0";
    let json_path = out.join(format!("{id}.json"));
    let outcomes = out.join(format!("{id}.outcomes.parquet"));
    let (original, outcome_bytes) = (
        std::fs::read_to_string(&json_path).unwrap(),
        std::fs::read(&outcomes).unwrap(),
    );
    let status = || {
        ugl(&argv(
            "status --config {} --out {} --require-complete",
            &[p(&cfg), p(&out)],
        ))
    };
    let report = || {
        ugl(&argv(
            "report --results {} --main tiny --out {}",
            &[p(&store), p(&dir.path().join("report"))],
        ))
    };
    assert!(status().status.success(), "{}", stderr(&status()));
    assert!(report().status.success(), "{}", stderr(&report()));
    // A forgery: fields set to values (a path into the manifest's JSON), with or without the
    // record's hash, with or without the outcomes file.
    let forge = |edits: &[(&[&str], serde_json::Value)], drop_hash: bool, keep_outcomes: bool| {
        let mut m: serde_json::Value = serde_json::from_str(&original).unwrap();
        for (path, value) in edits {
            let mut at = &mut m;
            for key in *path {
                at = &mut at[*key];
            }
            *at = value.clone();
        }
        if drop_hash {
            m.as_object_mut().unwrap().remove("discovery_blake3");
        }
        std::fs::write(&json_path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        if keep_outcomes {
            std::fs::write(&outcomes, &outcome_bytes).unwrap();
        } else if outcomes.exists() {
            std::fs::remove_file(&outcomes).unwrap();
        }
    };
    let n_moved =
        serde_json::from_str::<serde_json::Value>(&original).unwrap()["summary"]["n_moved"]
            .as_u64()
            .unwrap();
    let error: &[&str] = &["discovery", "final", "goal_error_mean"];
    let coverage: &[&str] = &["discovery", "final", "coverage"];
    type Edits<'a> = Vec<(&'a [&'a str], serde_json::Value)>;
    // (what the report names, the edits, drop the hash, keep the outcomes file)
    let cases: Vec<(&str, Edits, bool, bool)> = vec![
        (
            "hash",
            vec![
                (error, 0.001.into()),
                (coverage, 0.5.into()),
                (&["summary", "coverage"], 0.5.into()),
            ],
            false,
            false,
        ),
        (
            "the outcomes file gives",
            vec![(error, 0.001.into())],
            true,
            true,
        ),
        (
            "final.coverage",
            vec![(coverage, (-5.0).into())],
            true,
            false,
        ),
        (
            "final.goal_error_mean",
            vec![(error, 1e300.into())],
            true,
            false,
        ),
        (
            "final.n_moved",
            vec![(&["summary", "n_moved"], (n_moved + 1).into())],
            true,
            false,
        ),
    ];
    assert!(
        serde_json::from_str::<serde_json::Value>(&original).unwrap()["discovery_blake3"]
            .is_string(),
        "a run records the hash of its record"
    );
    for (why, edits, drop_hash, keep) in &cases {
        forge(edits, *drop_hash, *keep);
        // `ugl status` reads manifests, not data files: a record without its hash that only the
        // outcomes file contradicts is the report's to find.
        let st = status();
        if *why != "the outcomes file gives" {
            assert!(
                !st.status.success(),
                "{why}: status counts the run complete"
            );
            let text = format!("{}{}", stdout(&st), stderr(&st));
            assert!(text.contains(id), "{why}: status names the run: {text}");
        }
        let r = report();
        assert!(!r.status.success(), "{why}: the report renders");
        assert!(
            stderr(&r).contains(id) && stderr(&r).contains(why),
            "{why}: the report names the run and the field: {}",
            stderr(&r)
        );
    }
    // The record without its hash, untouched, is still read (an older manifest).
    forge(&[], true, false);
    assert!(status().status.success(), "{}", stdout(&status()));
    assert!(report().status.success(), "{}", stderr(&report()));
}

/// The audit's refusals, each one line and exit 2, nothing run: a position-only goal space where
/// the outcome is the position already (the run would be RGE-EFR's under another label); a
/// bootstrap that leaves no epoch to goal exploration (an RPE run under a goal label), in `ugl
/// run` and in a campaign file; a shard count beyond the campaign's groups (it once allocated
/// until the OOM killer came); an exploration count too large; an `init` that is a number; a
/// grid that needs more memory than the address-space limit (it once aborted on allocation).
#[test]
fn the_audit_refusals_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x");
    let run = |extra: &[&str]| {
        let mut a = vec!["run", "--env", "armball", "--out", p(&out)];
        a.extend_from_slice(extra);
        ugl(&a)
    };
    assert_one_line_error(
        &run(&["--algo", "rge-efr-position", "--epochs", "300"]),
        "use --algo rge-efr",
    );
    assert_one_line_error(
        &run(&["--algo", "rge-efr", "--epochs", "100"]),
        "--epochs 100: explore.bootstrap_epochs = 100",
    );
    assert!(!out.join("armball.rge-efr.s0.json").exists());
    let file = |name: &str, text: &str| {
        let f = dir.path().join(name);
        std::fs::write(&f, text).unwrap();
        f
    };
    let short = file(
        "short.toml",
        "[campaign]\nname = \"short\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rge-efr\"]\n[explore]\nepochs = 60\n",
    );
    assert_one_line_error(&ugl(&["plan", "--config", p(&short)]), "bootstrap_epochs");
    assert_one_line_error(
        &ugl(&argv(
            "status --config data/campaigns/baselines.toml --out {} --shards 18446744073709551615",
            &[p(&out)],
        )),
        "--shards 18446744073709551615: must be between 1 and",
    );
    let many = file(
        "many.toml",
        "[campaign]\nname = \"many\"\nreps = 1\nexplorations = 18446744073709551615\n\
         [matrix]\nenvs = [\"armball\"]\nalgos = [\"rpe\"]\n",
    );
    assert_one_line_error(
        &ugl(&["plan", "--config", p(&many)]),
        "must be between 1 and 4294967295, got 18446744073709551615",
    );
    let init = file(
        "init.toml",
        "[campaign]\nname = \"init\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rge-vae\"]\n[learners.vae]\ninit = 1\n",
    );
    assert_one_line_error(
        &ugl(&["plan", "--config", p(&init)]),
        "learners.vae.init: invalid type: integer `1`, expected one of \"paper\", \"he\", \"glorot\"",
    );
    let o = Command::new("bash")
        .arg("-c")
        .arg(format!(
            "ulimit -v 2097152 && exec \"$0\" embed --env armball --learner pca --latents 2 \
             --profile data/campaigns/smoke.toml --grid 600 --out {}",
            dir.path().join("e.npy").display()
        ))
        .arg(env!("CARGO_BIN_EXE_ugl"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert_one_line_error(&o, "address-space limit");
}

/// `ugl run` honours a store's one configuration: into a campaign's store it adds a run only
/// with the campaign's profile and options; a run of another configuration is never replaced
/// (the audit's 301-epoch run over a finished 300-epoch one); the same run again is fine.
#[test]
fn ugl_run_keeps_a_store_to_one_configuration() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "tiny.toml",
        "[campaign]\nname = \"tiny\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\"]\n[explore]\nepochs = 200\neval_every = 100\n",
    );
    let store = dir.path().join("tiny");
    let o = ugl(&argv(
        "campaign --config {} --out {} --jobs 1 --quiet",
        &[p(&cfg), p(&store)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let manifest = store.join("armball.rpe.s0.json");
    let before = std::fs::read(&manifest).unwrap();
    let run = |out: &Path, epochs: &str| {
        ugl(&argv(
            "run --env armball --algo rpe --profile {} --epochs {} --out {}",
            &[p(&cfg), epochs, p(out)],
        ))
    };
    assert_one_line_error(&run(&store, "201"), "another configuration");
    assert_eq!(std::fs::read(&manifest).unwrap(), before, "the run is kept");
    // Another campaign's profile.
    let o = ugl(&argv(
        "run --env armball --algo rpe --profile smoke --out {}",
        &[p(&store)],
    ));
    assert_one_line_error(&o, "holds campaign `tiny`");
    // A directory of single runs: the same run again is fine, another configuration is not.
    let single = dir.path().join("single");
    assert!(run(&single, "200").status.success());
    assert!(run(&single, "200").status.success());
    assert_one_line_error(
        &run(&single, "300"),
        "holds run armball.rpe.s0 of another configuration",
    );
    assert!(
        !single.join(ugl_types::RECORD_FILE).exists(),
        "ugl run records no campaign"
    );
}

/// Results written into a checkout's data/ are the committed ones: a campaign refuses to write
/// there while tracked files have uncommitted changes (one line, exit 2, nothing written),
/// unless `--allow-dirty`, which the runs then record as a `-dirty` revision. Elsewhere it
/// writes whatever the tree's state.
#[cfg(unix)]
#[test]
fn a_campaign_refuses_a_dirty_checkout_for_its_data() {
    let repo = tempfile::tempdir().unwrap();
    let git = |args: &[&str]| {
        let o = Command::new("git")
            .args([
                "-c",
                "user.name=t",
                "-c",
                "user.email=t@t",
                "-c",
                "commit.gpgsign=false",
            ])
            .args(args)
            .current_dir(repo.path())
            .output()
            .expect("git runs");
        assert!(o.status.success(), "git {args:?}: {}", stderr(&o));
    };
    git(&["init", "-q"]);
    std::fs::write(
        repo.path().join("tiny.toml"),
        "[campaign]\nname = \"tiny\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rpe\"]\n[explore]\nbootstrap_epochs = 10\nepochs = 50\neval_every = 50\n",
    )
    .unwrap();
    git(&["add", "tiny.toml"]);
    git(&["commit", "-q", "-m", "tiny"]);
    let campaign = |out: &str, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_ugl"))
            .args(["campaign", "--config", "tiny.toml", "--out", out, "--quiet"])
            .args(extra)
            .current_dir(repo.path())
            .output()
            .expect("ugl runs")
    };
    let revision = |out: &str| {
        manifest(&repo.path().join(out).join("armball.rpe.s0.json"))["git_revision"]
            .as_str()
            .unwrap()
            .to_string()
    };
    // Clean: allowed, and the revision is the commit's.
    let o = campaign("data/results/clean", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!revision("data/results/clean").ends_with("-dirty"));
    // A tracked file changed: refused before anything is written, naming the way out.
    std::fs::write(
        repo.path().join("tiny.toml"),
        "# changed\n".to_string()
            + &std::fs::read_to_string(repo.path().join("tiny.toml")).unwrap(),
    )
    .unwrap();
    let o = campaign("data/results/dirty", &[]);
    assert_one_line_error(&o, "--allow-dirty");
    assert!(!repo.path().join("data/results/dirty").exists());
    // Told to: allowed, recorded as dirty.
    let o = campaign("data/results/dirty", &["--allow-dirty"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(revision("data/results/dirty").ends_with("-dirty"));
    // Outside the checkout's data/: allowed.
    let o = campaign("elsewhere", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The audit's bypasses: a working directory outside the checkout, a symlink into its data/,
    // and `ugl run`, which had no check. Refused alike; allowed, the revision recorded is the
    // checkout's, never `unknown`.
    let outside = tempfile::tempdir().unwrap();
    let config = repo.path().join("tiny.toml");
    let from_outside = |out: &Path, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_ugl"))
            .args([
                "campaign",
                "--config",
                p(&config),
                "--out",
                p(out),
                "--quiet",
            ])
            .args(extra)
            .current_dir(outside.path())
            .output()
            .expect("ugl runs")
    };
    let h = repo.path().join("data/results/h");
    assert_one_line_error(&from_outside(&h, &[]), "--allow-dirty");
    std::fs::create_dir_all(repo.path().join("data/results")).unwrap();
    let link = outside.path().join("link");
    std::os::unix::fs::symlink(repo.path().join("data/results"), &link).unwrap();
    assert_one_line_error(&from_outside(&link.join("h"), &[]), "--allow-dirty");
    let single = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_ugl"))
            .args([
                "run", "--env", "armball", "--algo", "rpe", "--epochs", "50", "--out",
            ])
            .arg(repo.path().join("data/results/single"))
            .args(extra)
            .current_dir(outside.path())
            .output()
            .expect("ugl runs")
    };
    assert_one_line_error(&single(&[]), "--allow-dirty");
    let o = from_outside(&h, &["--allow-dirty"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(revision("data/results/h").ends_with("-dirty"));
    assert!(single(&["--allow-dirty"]).status.success());
    assert!(revision("data/results/single").ends_with("-dirty"));
}

#[test]
fn run_errors() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("f");
    std::fs::write(&file, "").unwrap();
    let out = p(dir.path());
    assert_one_line_error(
        &ugl(&argv("run --env armball --algo rge-nope --out {}", &[out])),
        "rge-nope",
    );
    assert_one_line_error(
        &ugl(&argv(
            "run --env armball --algo rpe --epochs 0 --out {}",
            &[out],
        )),
        "epochs",
    );
    assert_one_line_error(
        &ugl(&argv(
            "run --env armball --algo rpe --epochs -3 --out {}",
            &[out],
        )),
        "-3",
    );
    assert_one_line_error(
        &ugl(&argv(
            "run --env armball --algo rpe --profile nosuch --out {}",
            &[out],
        )),
        "nosuch",
    );
    assert_one_line_error(
        &ugl(&argv("run --env armball --algo rpe --out {}", &[p(&file)])),
        "not a directory",
    );
    assert_one_line_error(
        &ugl(&argv(
            "run --env armball --algo rpe --bogus --out {}",
            &[out],
        )),
        "--bogus",
    );
    assert_one_line_error(&ugl(&["frobnicate"]), "frobnicate");
}

#[test]
fn campaign_plan_and_resume() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "tiny.toml",
        "[campaign]\nname = \"tiny\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rpe\", \"rge-efr\"]\n[explore]\nepochs = 150\neval_every = 50\n",
    );
    let o = ugl(&["plan", "--config", p(&cfg)]);
    assert_eq!(
        stdout(&o).lines().collect::<Vec<_>>(),
        [
            "armball.rpe.s0",
            "armball.rpe.s1",
            "armball.rge-efr.s0",
            "armball.rge-efr.s1"
        ]
    );
    let out = dir.path().join("res");
    let o = campaign(p(&cfg), p(&out), &["--jobs", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Three files for each of the four runs, the campaign's record and the store's lock file.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 14);
    assert!(out.join(".ugl-store.lock").is_file());
    let record = std::fs::read_to_string(out.join("campaign.toml")).unwrap();
    assert!(record.contains("role = \"main\""), "{record}");
    // The campaign's run equals the single run with the same seed.
    let single = dir.path().join("single");
    let prof = p(&cfg);
    assert!(
        ugl(&argv(
            "run --env armball --algo rge-efr --seed 1 --profile {} --out {}",
            &[prof, p(&single)]
        ))
        .status
        .success()
    );
    assert_eq!(
        std::fs::read(out.join("armball.rge-efr.s1.outcomes.parquet")).unwrap(),
        std::fs::read(single.join("armball.rge-efr.s1.outcomes.parquet")).unwrap()
    );
    // A rerun skips everything.
    let o = campaign(p(&cfg), p(&out), &[]);
    assert!(stderr(&o).contains("0 runs executed"), "{}", stderr(&o));
    std::fs::write(&cfg, "[campaign]\nname = \"tiny\"\nreps = 0\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rpe\"]\n").unwrap();
    assert_one_line_error(&ugl(&["campaign", "--config", p(&cfg)]), "campaign.reps");
}

#[test]
fn run_with_an_external_learner() {
    let numpy = Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !numpy {
        eprintln!("SKIPPED: rge-external end to end (python3 with numpy not found)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "ext.toml",
        "[campaign]\nname = \"ext\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rge-external\"]\n\
         [ugl]\nimages = 200\n[explore]\nepochs = 200\n\
         [learners.external]\nname = \"random-projection\"\ncommand = \"python3 scripts/external_learners/random_projection.py\"\n",
    );
    let out = dir.path().join("res");
    let o = ugl(&argv(
        "run --env armball --algo rge-external --latents 3 --profile {} --out {}",
        &[p(&cfg), p(&out)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_str(stdout(&o).lines().last().unwrap()).unwrap();
    assert_eq!(s["run"], "armball.rge-external.kde.l3.s0");
    let m: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("armball.rge-external.kde.l3.s0.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(m["learner"], "random-projection");
    assert_eq!(m["reduced_budget"], true);
    // The program's own fit time, and its stderr kept beside the run.
    assert!(m["learner_fit_s"].as_f64().is_some_and(|t| t >= 0.0), "{m}");
    let log = std::fs::read_to_string(out.join("armball.rge-external.l3.s0.learner.log")).unwrap();
    assert!(
        log.contains("random projection: 200 images -> 3 dims"),
        "{log}"
    );
    assert!(m["latent_quality"]["linear_r2_mean"].is_f64(), "{m}");

    // `--command` / `--name` instead of the section; paired with a built-in learner of the
    // same cell: the same exploration seed.
    let o = ugl(&[
        "run",
        "--env",
        "armball",
        "--algo",
        "rge-external",
        "--latents",
        "3",
        "--command",
        "python3 scripts/external_learners/random_projection.py",
        "--name",
        "rp-cli",
        "--seed",
        "1",
        "--epochs",
        "150",
        "--images",
        "200",
        "--profile",
        "smoke",
        "--out",
        p(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = ugl(&argv(
        "run --env armball --algo rge-pca --latents 3 --seed 1 --epochs 150 --images 200 --profile smoke --out {}",
        &[p(&out)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let ext = manifest(&out.join("armball.rge-external.kde.l3.s1.json"));
    let pca = manifest(&out.join("armball.rge-pca.kde.l3.s1.json"));
    assert_eq!(ext["learner"], "rp-cli");
    assert_eq!(
        ext["external"]["command"],
        "python3 scripts/external_learners/random_projection.py"
    );
    assert_eq!(
        ext["run_seed"], pca["run_seed"],
        "paired exploration streams"
    );
    assert_ne!(ext["identity"], pca["identity"]);

    // Without the [learners.external] section or --command: a one-line error.
    let o = ugl(&argv(
        "run --env armball --algo rge-external --out {}",
        &[p(&out)],
    ));
    assert_one_line_error(&o, "--command");
    // --command is for rge-external only; an empty one is refused.
    let o = ugl(&argv(
        "run --env armball --algo rge-pca --command x --out {}",
        &[p(&out)],
    ));
    assert_one_line_error(&o, "apply to the external learner's algorithms only");
    let o = ugl(&[
        "run",
        "--env",
        "armball",
        "--algo",
        "rge-external",
        "--command",
        " ",
        "--out",
        p(&out),
    ]);
    assert_one_line_error(&o, "must not be empty");
}

#[test]
fn shards_merge_into_the_whole_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "sh.toml",
        "[campaign]\nname = \"sh\"\nreps = 2\n[matrix]\nenvs = [\"armball\", \"armarrow\"]\nalgos = [\"rpe\", \"rge-efr\", \"rge-pca\"]\n\
         samplers = [\"kde\", \"gaussian\"]\nlatents = [3]\n[ugl]\nimages = 100\n[explore]\nepochs = 120\neval_every = 40\n",
    );
    let whole = dir.path().join("whole");
    assert!(campaign(p(&cfg), p(&whole), &[]).status.success());
    // Three machines, three shards, three stores; merged into one.
    let mut parts = Vec::new();
    for i in 0..3 {
        let d = dir.path().join(format!("part{i}"));
        let o = campaign(
            p(&cfg),
            p(&d),
            &["--jobs", "1", "--shard", &format!("{i}/3")],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        parts.push(d);
    }
    let merged = dir.path().join("merged");
    let mut args = vec!["merge", "--into", p(&merged)];
    args.extend(parts.iter().map(|d| p(d)));
    let o = ugl(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        common::parquet_files(&whole),
        common::parquet_files(&merged),
        "the union of the shards equals the whole campaign"
    );
    // Merging again is a no-op; a conflicting run is refused; a damaged source run too.
    assert!(ugl(&args).status.success());
    let name = std::fs::read_dir(&parts[0])
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .find(|n| n.ends_with(".outcomes.parquet"))
        .unwrap();
    let (source, dest) = (parts[0].join(&name), merged.join(&name));
    let good = std::fs::read(&dest).unwrap();
    std::fs::write(&dest, b"another run's data").unwrap();
    assert_one_line_error(&ugl(&args), "refusing to overwrite");
    std::fs::write(&dest, &good).unwrap();
    std::fs::write(&source, b"corrupt").unwrap();
    assert_one_line_error(&ugl(&args), "is incomplete or damaged");
    assert_one_line_error(
        &ugl(&argv(
            "campaign --config {} --out {} --shard 3/3",
            &[p(&cfg), p(&whole)],
        )),
        "--shard",
    );
    // More shards than groups of runs sharing a fit: refused, as `status` and `slurm` do.
    assert_one_line_error(
        &ugl(&argv(
            "campaign --config {} --out {} --shard 0/1000",
            &[p(&cfg), p(&whole)],
        )),
        "groups of runs that share a fit",
    );
}

/// `ugl status` says what a resumed campaign would compute: complete, missing and damaged runs,
/// overall and per shard; `--require-complete` fails until every run is there.
#[test]
fn status_counts_complete_missing_and_damaged_runs() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "st.toml",
        "[campaign]\nname = \"st\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rpe\", \"rge-efr\"]\n\
         [explore]\nbootstrap_epochs = 10\nepochs = 60\neval_every = 20\n",
    );
    let out = dir.path().join("st");
    let status = |extra: &[&str]| {
        let mut args = vec!["status", "--config", p(&cfg), "--out", p(&out)];
        args.extend_from_slice(extra);
        ugl(&args)
    };
    let o = status(&["--shards", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("4 runs: 0 complete, 4 missing"), "{text}");
    assert_one_line_error(&status(&["--require-complete"]), "is not complete");
    let o = campaign(p(&cfg), p(&out), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = status(&["--shards", "2", "--require-complete"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains(": 4 runs: 4 complete\n"), "{text}");
    assert!(text.contains("shard 0/2: 2 runs: 2 complete"), "{text}");
    assert!(text.contains("shard 1/2: 2 runs: 2 complete"), "{text}");
    std::fs::remove_file(out.join("armball.rpe.s0.json")).unwrap();
    std::fs::write(out.join("armball.rge-efr.s1.parquet"), b"damaged").unwrap();
    let o = status(&[]);
    let text = stdout(&o);
    assert!(
        text.contains("4 runs: 2 complete, 1 missing, 1 damaged"),
        "{text}"
    );
    assert!(text.contains("missing: armball.rpe.s0\n"), "{text}");
    assert!(text.contains("damaged: armball.rge-efr.s1 ("), "{text}");
    assert_one_line_error(&status(&["--require-complete"]), "1 missing, 1 damaged");
}

#[test]
fn slurm_scripts() {
    let dir = tempfile::tempdir().unwrap();
    let scripts = dir.path().join("slurm");
    // `--allow-dirty` (passed on to the tasks): the default results directory is in this
    // checkout's data/, which a developer's tree may have changed.
    let o = ugl(&argv(
        "slurm --config data/campaigns/baselines.toml --shards 4 --scripts {} --allow-dirty",
        &[p(&scripts)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let array = std::fs::read_to_string(scripts.join("array.sh")).unwrap();
    assert!(array.contains("#SBATCH --array=0-3"), "{array}");
    assert!(array.contains(" --quiet --allow-dirty "), "{array}");
    assert!(
        array.contains("--shard \"${SLURM_ARRAY_TASK_ID}/4\""),
        "{array}"
    );
    let submit = std::fs::read_to_string(scripts.join("submit.sh")).unwrap();
    assert!(
        submit.contains("--dependency=afterok:\"$jid\" --kill-on-invalid-dep=yes report.sh"),
        "{submit}"
    );
    assert!(
        array
            .lines()
            .all(|l| l.starts_with('#') || !l.contains("cargo")),
        "no cargo on a compute node: {array}"
    );
    for f in ["array.sh", "report.sh", "submit.sh"] {
        let st = Command::new("bash")
            .args(["-n", p(&scripts.join(f))])
            .status()
            .unwrap();
        assert!(st.success(), "{f} is valid bash");
    }
    assert_one_line_error(
        &ugl(&argv(
            "slurm --config data/campaigns/baselines.toml --shards 0 --scripts {}",
            &[p(&scripts)],
        )),
        "--shards",
    );
}

/// Every option of `ugl slurm` is checked before a script is written: the hostile audit's cases
/// (a newline in --time that would run a command, nonsense shard and CPU counts, an --out above
/// the checkout, an sbatch option that breaks its line) are one line and exit 2, and leave no
/// script behind.
#[test]
fn slurm_refuses_bad_options_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let scripts = dir.path().join("job");
    // `--allow-dirty`: the default results directory is in this checkout's data/, which a
    // developer's tree may have changed (`a_campaign_refuses_a_dirty_checkout_for_its_data`).
    let base = [
        "slurm",
        "--config",
        "data/campaigns/baselines.toml",
        "--scripts",
        p(&scripts),
        "--allow-dirty",
    ];
    let cases: [(&[&str], &str); 12] = [
        (
            &["--shards", "2", "--time", "04:00:00\ntouch PWNED"],
            "--time",
        ),
        (&["--shards", "2", "--time", "banana"], "--time"),
        (&["--shards", "2", "--time", ""], "--time"),
        (
            &["--shards", "2", "--report-time", "25:99:00"],
            "--report-time",
        ),
        (
            &["--shards", "5000"],
            "--shards 5000: must be between 1 and 20",
        ),
        (&["--shards", "18446744073709551615"], "--shards"),
        (&["--shards", "0"], "--shards 0"),
        (
            &["--shards", "2", "--cpus", "100000000"],
            "--cpus 100000000",
        ),
        (&["--shards", "2", "--out", ".."], "is the checkout"),
        (&["--shards", "2", "--report-out", "."], "is the checkout"),
        (&["--shards", "2", "--throttle", "3"], "--throttle 3"),
        (
            &[
                "--shards",
                "2",
                "--sbatch-arg",
                "--partition=x\ntouch PWNED",
            ],
            "--sbatch-arg",
        ),
    ];
    for (extra, expected) in cases {
        let mut args: Vec<&str> = base.to_vec();
        args.extend_from_slice(extra);
        assert_one_line_error(&ugl(&args), expected);
        assert!(!scripts.exists(), "{extra:?} wrote no script");
    }
    // Extra sbatch options reach both jobs; a throttle the array.
    let mut args: Vec<&str> = base.to_vec();
    args.extend_from_slice(&[
        "--shards",
        "4",
        "--throttle",
        "2",
        "--sbatch-arg=--partition=short",
        "--sbatch-arg",
        "--mem=2G",
    ]);
    let o = ugl(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let array = std::fs::read_to_string(scripts.join("array.sh")).unwrap();
    let report = std::fs::read_to_string(scripts.join("report.sh")).unwrap();
    assert!(array.contains("#SBATCH --array=0-3%2\n"), "{array}");
    for text in [&array, &report] {
        assert!(
            text.contains("#SBATCH --partition=short\n#SBATCH --mem=2G\n"),
            "{text}"
        );
    }
}

/// A tiny profile with the neural learners.
fn neural_profile(dir: &Path) -> std::path::PathBuf {
    common::write_file(
        dir,
        "tiny-neural.toml",
        "[campaign]\nname = \"tiny\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rge-vae\"]\n\
         [ugl]\nimages = 200\n[explore]\nepochs = 300\neval_every = 100\n\
         [learners.ae]\niterations = 15\nhidden = [16, 8]\n\
         [learners.vae]\niterations = 15\nhidden = [16, 8]\n\
         [learners.rfvae]\niterations = 15\nhidden = [16, 8]\nwarmup = 5\n",
    )
}

fn manifest(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn neural_runs_share_the_model_cache_and_rebuild_a_corrupted_one() {
    let dir = tempfile::tempdir().unwrap();
    let profile = neural_profile(dir.path());
    let cache = dir.path().join("cache");
    let run = |out: &Path, sampler: &str, variant: &str| {
        ugl(&argv(
            "run --env armball --algo rge-rfvae --variant {} --sampler {} --latents 2 --profile {} --cache {} --out {}",
            &[variant, sampler, p(&profile), p(&cache), p(out)],
        ))
    };
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    let id = "armball.rge-rfvae.faithful.kde.l2.s0";
    let o = run(&a, "kde", "faithful");
    assert!(o.status.success(), "{}", stderr(&o));
    let m = manifest(&a.join(format!("{id}.json")));
    assert_eq!(m["train"]["cache"], "miss");
    assert_eq!(m["variant"], "faithful");
    assert_eq!(m["train"]["config"]["iterations"], 15);
    assert_eq!(m["reduced_budget"], true);
    let models: Vec<_> = std::fs::read_dir(&cache).unwrap().collect();
    assert_eq!(models.len(), 1, "one model stored");
    // The Gaussian sampler uses the same model: no training.
    let o = run(&a, "gaussian", "faithful");
    assert!(o.status.success(), "{}", stderr(&o));
    let g = manifest(&a.join("armball.rge-rfvae.faithful.gaussian.l2.s0.json"));
    assert_eq!(g["train"]["cache"], "hit");
    assert_eq!(g["train"]["key"], m["train"]["key"]);
    // A second run loads the model and gives the same bytes.
    assert!(run(&b, "kde", "faithful").status.success());
    assert_eq!(
        manifest(&b.join(format!("{id}.json")))["train"]["cache"],
        "hit"
    );
    let same = |x: &Path, y: &Path| {
        for suffix in [".parquet", ".outcomes.parquet"] {
            assert_eq!(
                std::fs::read(x.join(format!("{id}{suffix}"))).unwrap(),
                std::fs::read(y.join(format!("{id}{suffix}"))).unwrap(),
                "{id}{suffix}"
            );
        }
    };
    same(&a, &b);
    // Corrupt the model (flip one byte of the weights): detected, retrained, same results.
    let model = std::fs::read_dir(&cache)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let mut bytes = std::fs::read(&model).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    std::fs::write(&model, &bytes).unwrap();
    assert!(run(&c, "kde", "faithful").status.success());
    assert_eq!(
        manifest(&c.join(format!("{id}.json")))["train"]["cache"],
        "rebuilt"
    );
    same(&a, &c);
    // Truncated (a partial write): also rebuilt.
    let bytes = std::fs::read(&model).unwrap();
    std::fs::write(&model, &bytes[..bytes.len() / 3]).unwrap();
    std::fs::remove_dir_all(&c).unwrap();
    assert!(run(&c, "kde", "faithful").status.success());
    assert_eq!(
        manifest(&c.join(format!("{id}.json")))["train"]["cache"],
        "rebuilt"
    );
    same(&a, &c);
    // The corrected variant is another model.
    assert!(run(&c, "kde", "corrected").status.success());
    let k = manifest(&c.join("armball.rge-rfvae.corrected.kde.l2.s0.json"));
    assert_eq!(k["train"]["cache"], "miss");
    assert_ne!(k["train"]["key"], m["train"]["key"]);
}

/// The one fit path caches every learner whose encoders persist, PCA included: a second run
/// loads the model (the file is not rewritten) and gives the same bytes; a damaged file is
/// refitted and rewritten.
#[test]
fn pca_runs_share_the_model_cache_too() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let id = "armball.rge-pca.kde.l3.s0";
    let run = |out: &Path| {
        let o = ugl(&argv(
            "run --env armball --algo rge-pca --latents 3 --images 300 --epochs 200 --profile smoke --cache {} --out {}",
            &[p(&cache), p(out)],
        ));
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(out.join(format!("{id}.parquet"))).unwrap()
    };
    let first = run(&dir.path().join("a"));
    let models: Vec<_> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(models.len(), 1, "one model stored");
    let stored = std::fs::read(&models[0]).unwrap();
    let mtime = || std::fs::metadata(&models[0]).unwrap().modified().unwrap();
    let before = mtime();
    std::thread::sleep(std::time::Duration::from_millis(20));
    assert_eq!(run(&dir.path().join("b")), first, "loaded model, same run");
    assert_eq!(mtime(), before, "a hit does not rewrite the model");
    let mut bad = stored.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0x40;
    std::fs::write(&models[0], &bad).unwrap();
    assert_eq!(run(&dir.path().join("c")), first, "refitted, same run");
    assert_eq!(std::fs::read(&models[0]).unwrap(), stored, "rewritten");
}

#[test]
fn neural_run_errors() {
    let dir = tempfile::tempdir().unwrap();
    let profile = neural_profile(dir.path());
    let out = p(dir.path());
    let args = |extra: &[&str]| {
        let mut v = vec![
            "run",
            "--env",
            "armball",
            "--profile",
            p(&profile),
            "--out",
            out,
        ];
        v.extend_from_slice(extra);
        ugl(&v)
    };
    assert_one_line_error(
        &args(&["--algo", "rge-pca", "--variant", "corrected"]),
        "--variant applies to rge-vae and rge-rfvae",
    );
    assert_one_line_error(
        &args(&["--algo", "rge-ae", "--variant", "faithful"]),
        "--variant",
    );
    assert_one_line_error(&args(&["--algo", "rge-vae", "--variant", "fixed"]), "fixed");
    assert_one_line_error(
        &args(&["--algo", "rge-isomap", "--sampler", "gaussian"]),
        "prior",
    );
    assert_one_line_error(
        &args(&["--algo", "rge-ae", "--sampler", "gaussian"]),
        "prior",
    );
    assert_one_line_error(
        &args(&["--algo", "rge-vae", "--no-cache", "--cache", out]),
        "--cache",
    );
}

#[test]
fn compare_runs_a_new_learner_on_the_campaign_cells_and_seeds() {
    let dir = tempfile::tempdir().unwrap();
    let base = common::write_file(
        dir.path(),
        "base.toml",
        "[campaign]\nname = \"base\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-pca\", \"rge-vae\"]\nsamplers = [\"kde\", \"gaussian\"]\nlatents = [\"true\"]\n\
         [ugl]\nimages = 200\n[explore]\nepochs = 200\n",
    );
    let out = dir.path().join("cmp");
    let o = ugl(&argv(
        "compare --learner pca-centred --config {} --out {} --quiet",
        &[p(&base), p(&out)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    // No main campaign `base` in the results directory yet: no ranking page, said so.
    assert!(stderr(&o).contains("no summary page"), "{}", stderr(&o));
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".json"))
        .collect();
    names.sort();
    // The base campaign's cells (armball, true latents, kde; no prior for gaussian) and seeds.
    assert_eq!(
        names,
        [
            "armball.rge-pca-centred.kde.l2.s0.json",
            "armball.rge-pca-centred.kde.l2.s1.json"
        ]
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join(&names[0])).unwrap()).unwrap();
    assert_eq!(m["campaign"], "compare-pca-centred");
    // The same run as `ugl run` with the base campaign's seed.
    let single = dir.path().join("single");
    assert!(
        ugl(&argv(
            "run --env armball --algo rge-pca-centred --latents 2 --profile {} --out {}",
            &[p(&base), p(&single)]
        ))
        .status
        .success()
    );
    assert_eq!(
        std::fs::read(out.join("armball.rge-pca-centred.kde.l2.s0.parquet")).unwrap(),
        std::fs::read(single.join("armball.rge-pca-centred.kde.l2.s0.parquet")).unwrap()
    );
    let args = |extra: &[&str]| {
        let mut v = vec!["compare", "--config", p(&base), "--out", p(&out)];
        v.extend_from_slice(extra);
        ugl(&v)
    };
    assert_one_line_error(&args(&["--learner", "nosuch"]), "not a registered learner");
    assert_one_line_error(
        &args(&["--learner", "pca", "--command", "true"]),
        "registered learner",
    );
    assert_one_line_error(&args(&["--learner", "Bad Name"]), "--learner");
}

/// The registry's promise: a learner added in one file and one registry entry
/// (`repr/gaussian_projection.rs`, no other code names it) runs with `ugl run`, is ranked by
/// `ugl compare`, and appears in the report's leaderboard.
#[test]
fn a_learner_added_in_one_file_runs_is_compared_and_ranked() {
    let dir = tempfile::tempdir().unwrap();
    let base = common::write_file(
        dir.path(),
        "base.toml",
        "[campaign]\nname = \"base\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-efr\", \"rge-pca\"]\nsamplers = [\"kde\"]\nlatents = [\"true\"]\n\
         [ugl]\nimages = 200\n[explore]\nepochs = 150\n\
         [learners.gaussian-projection]\nstd = 0.5\n",
    );
    let o = ugl(&["learners"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("rge-gaussian-projection"),
        "{}",
        stdout(&o)
    );
    let single = dir.path().join("single");
    let o = ugl(&argv(
        "run --env armball --algo rge-gaussian-projection --latents 2 --profile {} --out {}",
        &[p(&base), p(&single)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let m = manifest(&single.join("armball.rge-gaussian-projection.kde.l2.s0.json"));
    assert_eq!(m["learner"], "gaussian-projection");
    // Its [learners.NAME] table is checked: a bad value is a one-line error naming the key.
    let bad = dir.path().join("bad.toml");
    replaced(&base, &bad, "std = 0.5", "std = -1.0");
    assert_one_line_error(
        &ugl(&["plan", "--config", p(&bad)]),
        "learners.gaussian-projection.std: must be a positive number",
    );
    let results = dir.path().join("results");
    let o = campaign(p(&base), p(&results.join("base")), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = ugl(&argv(
        "compare --learner gaussian-projection --config {} --out {} --quiet",
        &[p(&base), p(&results.join("compare-gaussian-projection"))],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    // The same run as `ugl run`, and a ranking page against the base campaign.
    assert_eq!(
        std::fs::read(
            results
                .join("compare-gaussian-projection")
                .join("armball.rge-gaussian-projection.kde.l2.s0.parquet")
        )
        .unwrap(),
        std::fs::read(single.join("armball.rge-gaussian-projection.kde.l2.s0.parquet")).unwrap()
    );
    let page = stdout(&o);
    assert!(
        page.contains("## RGE-Gaussian projection, KDE goals"),
        "{page}"
    );
    assert!(page.contains("rank "), "{page}");
    let report = dir.path().join("report");
    let o = ugl(&argv(
        "report --results {} --out {} --main base",
        &[p(&results), p(&report)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(report.join("REPORT.md")).unwrap();
    let row = md
        .lines()
        .find(|l| l.contains("| compare-gaussian-projection |"))
        .unwrap_or_else(|| panic!("no leaderboard row for the new learner:\n{md}"));
    assert!(row.contains("RGE-Gaussian projection"), "{row}");
}

#[test]
fn embed_writes_the_latents_of_the_training_set_and_a_grid() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("emb").join("pca.npy");
    let o = ugl(&argv(
        "embed --env armarrow --learner pca --latents 3 --grid 4 --images 300 --profile smoke --out {}",
        &[p(&out)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_str(stdout(&o).lines().last().unwrap()).unwrap();
    assert_eq!(s["representation"], "armarrow.rge-pca.l3.s0");
    assert_eq!(s["latent_quality"]["targets"].as_array().unwrap().len(), 6);
    // npy v1 headers: (n, d) of the training set, (grid^2, d) of the grid, and their states.
    let header = |name: &str| {
        let b = std::fs::read(dir.path().join("emb").join(name)).unwrap();
        let len = u16::from_le_bytes([b[8], b[9]]) as usize;
        // Either spelling of a 2-tuple: numpy's `(n, d)` or `(n, d, )`.
        String::from_utf8_lossy(&b[10..10 + len]).replace(", )", ")")
    };
    assert!(
        header("pca.npy").contains("'shape': (300, 3)"),
        "{}",
        header("pca.npy")
    );
    assert!(header("pca.states.npy").contains("'shape': (300, 3)"));
    assert!(header("pca.grid.npy").contains("'shape': (16, 3)"));
    assert!(header("pca.grid_states.npy").contains("'<f8'"));
    // The training latents are the ones a run of the same cell fits: same bytes twice.
    let first = std::fs::read(&out).unwrap();
    assert!(
        ugl(&argv("embed --env armarrow --learner pca --latents 3 --grid 4 --images 300 --profile smoke --out {}", &[p(&out)]))
        .status
        .success()
    );
    assert_eq!(first, std::fs::read(&out).unwrap());
    // Errors: one line each.
    let bad = |args: &[&str], needle: &str| {
        let mut a = vec!["embed", "--env", "armball", "--profile", "smoke"];
        a.extend_from_slice(args);
        assert_one_line_error(&ugl(&a), needle);
    };
    bad(
        &["--learner", "umap", "--out", p(&out)],
        "not a registered learner",
    );
    bad(
        &["--learner", "pca", "--out", "/tmp/x.csv"],
        "must end in .npy",
    );
    bad(
        &["--learner", "pca", "--grid", "1", "--out", p(&out)],
        "--grid",
    );
    bad(
        &[
            "--learner",
            "pca",
            "--variant",
            "corrected",
            "--out",
            p(&out),
        ],
        "vae and rfvae only",
    );
}

/// `kill -9` of `ugl run` in the middle of a neural training: the rerun resumes from the
/// latest checkpoint (in the model cache) and gives the bytes of an uninterrupted run.
#[test]
fn a_training_killed_mid_way_resumes_from_its_checkpoint() {
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "ckpt.toml",
        "[campaign]\nname = \"ckpt\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rge-vae\"]\n\
         [ugl]\nimages = 300\n[explore]\nbootstrap_epochs = 10\nepochs = 100\n\
         [learners.vae]\niterations = 600\nhidden = [32, 16]\ninit = \"he\"\n",
    );
    let args = |out: &Path| -> Vec<String> {
        [
            "run",
            "--env",
            "armball",
            "--algo",
            "rge-vae",
            "--latents",
            "2",
            "--profile",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([p(&cfg).to_string(), "--out".into(), p(out).to_string()])
        .chain(["--checkpoint-every".into(), "50".into()])
        .collect()
    };
    let reference = dir.path().join("reference");
    let a = args(&reference);
    let o = ugl(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));

    let out = dir.path().join("killed");
    let a = args(&out);
    let mut child = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args(&a)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let models = out.join("models");
    let t0 = Instant::now();
    let checkpointed = loop {
        let found = std::fs::read_dir(&models)
            .map(|d| {
                d.flatten().any(|e| {
                    e.file_name().to_string_lossy().contains(".ckpt.")
                        && e.path().join("state.json").exists()
                })
            })
            .unwrap_or(false);
        if found || child.try_wait().unwrap().is_some() || t0.elapsed() > Duration::from_secs(120) {
            break found;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let _ = child.kill();
    let _ = child.wait();
    assert!(
        checkpointed,
        "no checkpoint appeared before the training ended"
    );
    let o = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args(&a)
        .env("UGL_LOG", "info")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("resuming"), "{}", stderr(&o));
    assert!(
        common::parquet_files(&out) == common::parquet_files(&reference),
        "the resumed run differs from the uninterrupted one"
    );
    let leftovers = std::fs::read_dir(&models)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains(".ckpt."))
        .count();
    assert_eq!(
        leftovers, 0,
        "checkpoints are removed once the training is done"
    );
}

/// `--keep-checkpoints` keeps every checkpoint after the training, and `ugl embed --checkpoint
/// N` reads the network after N iterations without training: its latents differ from the
/// finished network's, its training record says N; a checkpoint not there, a learner that saves
/// none and a run without a model cache are refused in one line.
#[test]
fn embed_reads_a_kept_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "keep.toml",
        "[campaign]\nname = \"keep\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rge-vae\"]\n\
         [ugl]\nimages = 300\n[explore]\nbootstrap_epochs = 10\nepochs = 100\n\
         [learners.vae]\niterations = 300\nhidden = [32, 16]\ninit = \"he\"\n",
    );
    let out = dir.path().join("run");
    let o = ugl(&argv(
        "run --env armball --algo rge-vae --latents 2 --profile {} --out {} --checkpoint-every 100 --keep-checkpoints",
        &[p(&cfg), p(&out)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let models = out.join("models");
    let kept = std::fs::read_dir(&models)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains(".ckpt."))
        .count();
    assert_eq!(
        kept, 2,
        "the checkpoints after 100 and 200 iterations are kept"
    );
    let embed = |extra: &str, name: &str| {
        let npy = dir.path().join(name);
        ugl(&argv(
            &format!(
                "embed --env armball --learner vae --latents 2 --profile {{}} --cache {{}} --out {{}} --grid 3 {extra}"
            ),
            &[p(&cfg), p(&models), p(&npy)],
        ))
    };
    let summary = |o: &std::process::Output| -> serde_json::Value {
        assert!(o.status.success(), "{}", stderr(o));
        serde_json::from_str(stdout(o).lines().last().unwrap()).unwrap()
    };
    let end = summary(&embed("", "end.npy"));
    assert_eq!(end["training"]["iterations"], 300);
    let part = summary(&embed("--checkpoint 100", "part.npy"));
    assert_eq!(part["checkpoint"], 100);
    assert_eq!(part["training"]["iterations"], 100);
    assert!(part["latent_quality"]["knn_r2"].is_array(), "{part}");
    assert_ne!(
        std::fs::read(dir.path().join("part.npy")).unwrap(),
        std::fs::read(dir.path().join("end.npy")).unwrap(),
        "the network after 100 iterations is not the finished one"
    );
    assert_one_line_error(
        &embed("--checkpoint 150", "x.npy"),
        "after 100, 200 iterations",
    );
    let o = ugl(&argv(
        "embed --env armball --learner pca --latents 2 --profile {} --cache {} --out {} --checkpoint 100",
        &[p(&cfg), p(&models), p(&dir.path().join("pca.npy"))],
    ));
    assert_one_line_error(&o, "pca trainings save no checkpoints");
    let o = ugl(&argv(
        "embed --env armball --learner vae --latents 2 --profile {} --no-cache --out {} --checkpoint 100",
        &[p(&cfg), p(&dir.path().join("none.npy"))],
    ));
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--no-cache"), "{}", stderr(&o));
}

/// Arguments are checked before anything touches the disk; seeds the store cannot hold are
/// refused (they were stored as -1).
#[test]
fn bad_arguments_touch_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never-created");
    let o = ugl(&argv(
        "campaign --config data/campaigns/baselines.toml --jobs 0 --out {}",
        &[p(&out)],
    ));
    assert_one_line_error(&o, "--jobs must be at least 1");
    assert!(!out.exists(), "--out was created before --jobs was checked");
    for cmd in [
        vec![
            "run",
            "--env",
            "armball",
            "--algo",
            "rpe",
            "--seed",
            "18446744073709551615",
        ],
        vec![
            "embed",
            "--env",
            "armball",
            "--learner",
            "pca",
            "--seed",
            "9223372036854775808",
        ],
    ] {
        let mut args = cmd.clone();
        args.extend(["--out", p(&out)]);
        if cmd[0] == "embed" {
            args.pop();
            args.pop();
            args.extend(["--out", "/tmp/never-written.npy"]);
        }
        assert_one_line_error(&ugl(&args), "--seed must be below 2^63");
        assert!(!out.exists());
    }
    // The largest seed the store holds still runs.
    let o = ugl(&argv(
        "run --env armball --algo rpe --seed 9223372036854775807 --epochs 50 --profile baselines --out {}",
        &[p(&out)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
}

/// An error's cause is printed once (a library error that already shows its source is not
/// followed by the source again), and sizes that cannot fit in memory are refused before
/// anything is allocated.
#[test]
fn errors_are_one_line_each_cause_once_and_huge_sizes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let o = ugl(&[
        "campaign",
        "--config",
        "/nonexistent/profile.toml",
        "--out",
        p(&dir.path().join("out")),
    ]);
    assert_one_line_error(&o, "/nonexistent/profile.toml");
    assert_eq!(
        stderr(&o).matches("os error 2").count(),
        1,
        "{}",
        stderr(&o)
    );
    let out = dir.path().join("run");
    for (args, needle) in [
        (
            vec!["--algo", "rpe", "--epochs", "9223372036854775808"],
            "explore.epochs = 9223372036854775808 needs about",
        ),
        (
            vec![
                "--algo",
                "rge-pca",
                "--latents",
                "2",
                "--images",
                "100000000000",
            ],
            "--images: ugl.images = 100000000000 needs about",
        ),
    ] {
        let mut a = vec!["run", "--env", "armball", "--out", p(&out)];
        a.extend(args);
        let o = ugl(&a);
        assert_one_line_error(&o, needle);
    }
    assert!(!out.exists(), "nothing was written");
}

/// `ugl report`: a missing `--paper` directory is an error, and the store's top level can be
/// named as the listing names it, `(top level)`.
#[test]
fn report_paper_and_top_level_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("store");
    let o = campaign("data/campaigns/baselines.toml", p(&store), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = dir.path().join("report");
    let o = ugl(&argv(
        "report --results {} --paper /nonexistent/paper --out {}",
        &[p(&store), p(&report)],
    ));
    assert_one_line_error(&o, "--paper /nonexistent/paper: not a directory");
    let o = ugl(&["report", "--results", p(&store), "--out", p(&report)]);
    assert_one_line_error(&o, "(top level)");
    let o = ugl(&[
        "report",
        "--results",
        p(&store),
        "--main",
        "(top level)",
        "--out",
        p(&report),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(report.join("REPORT.md").is_file());
}

/// The scripts of `ugl slurm` run end to end, with a fake `sbatch` (runs each array task, then
/// the dependent step) and a fake `cargo` (runs this `ugl`), for a campaign that is not `paper`,
/// with spaces in every path.
#[cfg(unix)]
#[test]
fn slurm_scripts_run_end_to_end_with_spaces_and_another_campaign() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().join("has space");
    let (bin, work, scripts) = (
        root.join("bin"),
        root.join("work dir"),
        root.join("slurm jobs"),
    );
    for d in [&bin, &work] {
        std::fs::create_dir_all(d).unwrap();
    }
    // The checkout the scripts run in: its paper reference values.
    std::fs::create_dir_all(work.join("data")).unwrap();
    std::os::unix::fs::symlink(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/paper"),
        work.join("data/paper"),
    )
    .unwrap();
    let config = root.join("tiny camp.toml");
    std::fs::write(
        &config,
        "[campaign]\nname = \"tiny-camp\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-efr\"]\n[explore]\nbootstrap_epochs = 10\nepochs = 60\neval_every = 20\n",
    )
    .unwrap();
    let exe = |name: &str, text: &str| {
        let f = bin.join(name);
        std::fs::write(&f, text).unwrap();
        std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o755)).unwrap();
    };
    exe(
        "cargo",
        "#!/usr/bin/env bash\n# fake cargo: `build` reports the test's ugl binary as cargo's JSON does\n\
         [ \"$1\" = build ] || exit 1\n\
         echo '{\"reason\":\"compiler-artifact\",\"executable\":\"'\"$UGL_BIN\"'\",\"fresh\":true}'\n",
    );
    exe(
        "sbatch",
        "#!/usr/bin/env bash\n# fake sbatch: runs the script now (every array task in turn)\n\
         parsable=0; script=\"\"; last=\"\"\nfor a in \"$@\"; do case \"$a\" in --parsable) parsable=1;; \
         --array=*) last=${a#--array=0-}; last=${last%%%*};; --*) ;; *) script=\"$a\";; esac; done\n\
         [ -n \"$last\" ] || last=$(sed -n 's/^#SBATCH --array=0-\\([0-9]*\\).*$/\\1/p' \"$script\")\n\
         if [ -n \"$last\" ]; then for i in $(seq 0 \"$last\"); do \
         SLURM_ARRAY_TASK_ID=$i bash \"$script\" || exit 1; done; else bash \"$script\" || exit 1; fi\n\
         [ $parsable = 1 ] && echo 42\nexit 0\n",
    );
    let results = root.join("my results");
    let out = results.join("tiny-camp");
    let o = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args([
            "slurm",
            "--config",
            p(&config),
            "--shards",
            "2",
            "--scripts",
        ])
        .arg(&scripts)
        .arg("--out")
        .arg(&out)
        .current_dir(&work)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let o = Command::new("bash")
        .arg(scripts.join("submit.sh"))
        .env("PATH", path)
        .env("UGL_BIN", env!("CARGO_BIN_EXE_ugl"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    let n = std::fs::read_dir(&out)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "json")
        })
        .count();
    assert_eq!(n, 4, "every run of the campaign");
    let report = std::fs::read_to_string(out.join("report/REPORT.md")).unwrap();
    assert!(
        report.contains("tiny-camp"),
        "the report draws on the campaign"
    );
    assert!(
        !work.join("report").exists(),
        "the report step writes next to the results, not into the checkout"
    );
    assert!(
        scripts.join("bin/ugl").is_file(),
        "the tasks run the binary submit.sh copied"
    );
}

/// The audit's injection cases: every path `ugl slurm` writes into its scripts (the checkout,
/// the campaign file, `--out`, `--scripts`, `--report-out`) holds `$(...)`, backticks, quotes, a
/// backslash and a newline followed by an `#SBATCH` line and a command. The three scripts run (a
/// fake `sbatch` and `cargo`, a `ugl` that records its arguments): no command in a path runs,
/// every `#SBATCH` line is the scripts' own and comes before the first command, and `ugl` gets
/// each path exactly.
#[cfg(unix)]
#[test]
fn slurm_scripts_are_safe_for_hostile_paths() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let hostile = |tag: &str| {
        format!(
            "x $(touch {t}/PWNED-{tag}-a) `touch {t}/PWNED-{tag}-b` \\ \" ' ;\n\
             #SBATCH --wrap=x\ntouch {t}/PWNED-{tag}-c ; y",
            t = t.display()
        )
    };
    let root = t.join(hostile("root"));
    let (bin, work) = (t.join("bin"), root.join(hostile("work")));
    for d in [&bin, &work.join("data")] {
        std::fs::create_dir_all(d).unwrap();
    }
    std::os::unix::fs::symlink(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/paper"),
        work.join("data/paper"),
    )
    .unwrap();
    // A hostile name holds `/` (its `touch` paths): its directories are made.
    let config = root.join(format!("{}.toml", hostile("config")));
    std::fs::create_dir_all(config.parent().unwrap()).unwrap();
    std::fs::write(
        &config,
        "[campaign]\nname = \"tiny\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-efr\"]\n[explore]\nbootstrap_epochs = 10\nepochs = 60\neval_every = 20\n",
    )
    .unwrap();
    let exe = |f: &Path, text: &str| {
        std::fs::write(f, text).unwrap();
        std::fs::set_permissions(f, std::fs::Permissions::from_mode(0o755)).unwrap();
    };
    exe(
        &bin.join("cargo"),
        "#!/usr/bin/env bash\n[ \"$1\" = build ] || exit 1\n\
         echo '{\"reason\":\"compiler-artifact\",\"executable\":\"'\"$UGL_BIN\"'\",\"fresh\":true}'\n",
    );
    // Runs task 0 of an array, or the script; prints a job id.
    exe(
        &bin.join("sbatch"),
        "#!/usr/bin/env bash\nscript=\"${@: -1}\"\nSLURM_ARRAY_TASK_ID=0 bash \"$script\" || exit 1\necho 42\n",
    );
    // The `ugl` the tasks run: records its arguments, NUL-separated, one call per record.
    let recorder = t.join("ugl");
    exe(
        &recorder,
        "#!/usr/bin/env bash\nfor a in \"$@\"; do printf '%s\\0' \"$a\"; done >> \"$RECORD\"\n\
         printf 'END\\0' >> \"$RECORD\"\n",
    );
    let results = root.join(hostile("results"));
    let (out, scripts, report) = (
        results.join("tiny"),
        root.join(hostile("scripts")),
        root.join(hostile("report")),
    );
    let o = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args(["slurm", "--config"])
        .arg(&config)
        .args(["--shards", "2", "--scripts"])
        .arg(&scripts)
        .arg("--out")
        .arg(&out)
        .arg("--report-out")
        .arg(&report)
        .current_dir(&work)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["array.sh", "report.sh"] {
        let text = std::fs::read_to_string(scripts.join(f)).unwrap();
        let (head, body) = text.split_at(text.find("set -euo").unwrap());
        assert!(
            head.lines().all(|l| l.starts_with('#')),
            "{f}: only comments and directives before the first command:\n{head}"
        );
        assert!(
            !head
                .lines()
                .any(|l| l.starts_with("#SBATCH") && l.contains("--wrap")),
            "{f}: no directive from a path:\n{head}"
        );
        // (After the first command, a line of a quoted path that reads `#SBATCH` is text, and
        // Slurm reads no directive there.)
        assert!(body.starts_with("set -euo"), "{f}");
    }
    let record = t.join("record");
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let o = Command::new("bash")
        .arg(scripts.join("submit.sh"))
        .env("PATH", path)
        .env("UGL_BIN", &recorder)
        .env("RECORD", &record)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).starts_with("submitted array job 42 (0-1 of 2 tasks)"),
        "{}",
        stdout(&o)
    );
    let pwned: Vec<_> = std::fs::read_dir(t)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("PWNED"))
        .collect();
    assert!(pwned.is_empty(), "a path ran as a command: {pwned:?}");
    let record = std::fs::read(&record).unwrap();
    let args: Vec<String> = record
        .strip_suffix(b"\0")
        .unwrap()
        .split(|&b| b == 0)
        .map(|a| String::from_utf8(a.to_vec()).unwrap())
        .collect();
    let calls: Vec<&[String]> = args
        .split(|a| a == "END")
        .filter(|c| !c.is_empty())
        .collect();
    let value = |call: &[String], flag: &str| {
        let i = call.iter().position(|a| a == flag).unwrap();
        call[i + 1].clone()
    };
    let s = |p: &Path| p.to_str().unwrap().to_string();
    assert_eq!(
        calls.len(),
        3,
        "campaign (task 0), status, report: {calls:?}"
    );
    assert_eq!(calls[0][0], "campaign");
    assert_eq!(value(calls[0], "--config"), s(&config));
    assert_eq!(value(calls[0], "--out"), s(&out));
    assert_eq!(calls[1][0], "status");
    assert_eq!(value(calls[1], "--out"), s(&out));
    assert_eq!(calls[2][0], "report");
    assert_eq!(value(calls[2], "--results"), s(&results));
    assert_eq!(value(calls[2], "--paper"), s(&work.join("data/paper")));
    assert_eq!(value(calls[2], "--out"), s(&report));
}

/// An external learner whose fit fails is started once per cell, not once per run, and the
/// campaign reports that one failure (one line).
#[test]
fn a_failing_external_fit_is_started_once_per_cell() {
    let dir = tempfile::tempdir().unwrap();
    let starts = dir.path().join("starts");
    let cfg = dir.path().join("ext.toml");
    std::fs::write(
        &cfg,
        format!(
            "[campaign]\nname = \"ext-fail\"\nreps = 3\n[matrix]\nenvs = [\"armball\"]\n\
             algos = [\"rge-external\"]\nsamplers = [\"kde\", \"gaussian\"]\nlatents = [2]\n\
             [ugl]\nimages = 50\n[explore]\nbootstrap_epochs = 10\nepochs = 20\n\
             [learners.external]\nname = \"broken\"\ncommand = \"sh -c 'echo start >> {}; echo boom >&2; exit 3'\"\n",
            starts.display()
        ),
    )
    .unwrap();
    let o = ugl(&argv(
        "campaign --config {} --out {} --jobs 1 --quiet",
        &[p(&cfg), p(&dir.path().join("res"))],
    ));
    assert_one_line_error(&o, "armball.rge-external");
    assert!(
        !stderr(&o).contains("not run:"),
        "the real error: {}",
        stderr(&o)
    );
    let n = std::fs::read_to_string(&starts).unwrap().lines().count();
    assert_eq!(n, 1, "started once for 6 runs in 3 groups");
}

/// Several failed fits (one per cell) are counted in the campaign's one-line error, with the
/// first, not dropped.
#[test]
fn several_failures_are_counted() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("ext.toml");
    std::fs::write(
        &cfg,
        "[campaign]\nname = \"ext-fail2\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-external\"]\nsamplers = [\"kde\"]\nlatents = [2, 3]\n\
         [ugl]\nimages = 50\n[explore]\nbootstrap_epochs = 10\nepochs = 20\n\
         [learners.external]\nname = \"broken\"\ncommand = \"sh -c 'exit 3'\"\n",
    )
    .unwrap();
    let o = ugl(&argv(
        "campaign --config {} --out {} --jobs 1 --quiet",
        &[p(&cfg), p(&dir.path().join("res"))],
    ));
    assert_one_line_error(&o, "2 runs failed (0 more not run");
    assert!(
        stderr(&o).contains("1 finished and stored"),
        "{}",
        stderr(&o)
    );
}

/// A run whose data file was truncated after its manifest was written is not complete: `ugl
/// report` and `ugl merge` refuse it with one line naming the file, and a resumed campaign
/// recomputes exactly that run, to the same bytes.
#[test]
fn a_truncated_run_file_is_detected_and_recomputed() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("store");
    let campaign = |extra: &[&str]| {
        let mut a = vec![
            "campaign",
            "--config",
            "data/campaigns/baselines.toml",
            "--out",
            p(&store),
            "--quiet",
        ];
        a.extend(extra);
        ugl(&a)
    };
    assert!(campaign(&[]).status.success());
    let victim = store.join("armball.rpe.s0.parquet");
    let original = std::fs::read(&victim).unwrap();
    std::fs::write(&victim, &original[..original.len() / 2]).unwrap();

    let report = ugl(&argv(
        "report --results {} --main . --out {}",
        &[p(&store), p(&dir.path().join("report"))],
    ));
    assert_one_line_error(&report, "armball.rpe.s0.parquet");
    assert!(
        stderr(&report).contains("truncated or damaged"),
        "{}",
        stderr(&report)
    );
    let merge = ugl(&["merge", "--into", p(&dir.path().join("merged")), p(&store)]);
    assert_one_line_error(&merge, "run armball.rpe.s0 is incomplete or damaged");

    let o = campaign(&[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("1 runs executed"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&victim).unwrap(),
        original,
        "recomputed to the same bytes"
    );
    let m = manifest(&store.join("armball.rpe.s0.json"));
    assert_eq!(m["files"][0]["name"], "armball.rpe.s0.parquet");
    assert_eq!(m["files"][0]["bytes"], original.len());
}

/// An external learner cannot outlive `ugl`: after a `kill -9` of `ugl` mid-fit, the learner's
/// whole process group (here a shell and its background `sleep`) is killed and its work
/// directory removed by the watchdog; and a configured READY timeout is honoured.
#[cfg(unix)]
#[test]
fn a_killed_harness_leaves_no_learner_behind_and_the_ready_timeout_is_configurable() {
    let dir = tempfile::tempdir().unwrap();
    let info = dir.path().join("learner-info");
    let hang = format!(
        "echo \"$$ $UGL_WORKDIR\" > {}; sleep 1000 & sleep 1000",
        info.display()
    );
    let mut child = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args([
            "run",
            "--env",
            "armball",
            "--algo",
            "rge-external",
            "--latents",
            "2",
            "--images",
            "60",
            "--command",
            &hang,
            "--out",
        ])
        .arg(dir.path().join("out"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    let text = loop {
        if let Ok(t) = std::fs::read_to_string(&info)
            && t.ends_with('\n')
        {
            break t;
        }
        // A guard against a hang, not a speed check.
        assert!(t0.elapsed().as_secs() < 300, "the learner never started");
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    let (pgid, workdir) = text.trim().split_once(' ').unwrap();
    let group_alive = || {
        Command::new("sh")
            .args(["-c", &format!("kill -0 -{pgid} 2>/dev/null")])
            .status()
            .unwrap()
            .success()
    };
    assert!(group_alive() && Path::new(workdir).is_dir());
    child.kill().unwrap(); // SIGKILL: no handler, no destructor runs
    child.wait().unwrap();
    let t0 = std::time::Instant::now();
    while group_alive() || Path::new(workdir).exists() {
        // A guard against a hang, not a speed check.
        assert!(
            t0.elapsed().as_secs() < 300,
            "the learner's group {pgid} or its work directory {workdir} outlived ugl"
        );
        std::thread::sleep(std::time::Duration::from_millis(100));
    }

    let cfg = common::write_file(
        dir.path(),
        "timeout.toml",
        "[campaign]\nname = \"t\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rge-external\"]\n\
         [ugl]\nimages = 60\n[explore]\nbootstrap_epochs = 10\nepochs = 20\n\
         [learners.external]\nname = \"slow\"\ncommand = \"sleep 1000\"\nready_timeout_s = 1.5\n",
    );
    let o = ugl(&argv(
        "run --env armball --algo rge-external --latents 2 --profile {} --out {}",
        &[p(&cfg), p(&dir.path().join("out2"))],
    ));
    // The configured timeout's message (`sleep 1000` would otherwise end the wait): no clock.
    assert_one_line_error(&o, "no READY line within the ready timeout (1.5s)");
}

#[test]
fn armballs_campaign_records_interest_and_the_report_gives_the_follow_up_section() {
    // A tiny follow-up campaign: RPE, flat and learning-progress goal exploration with
    // engineered features, and the same in a learned (PCA) goal space, 3 seeds.
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write_file(
        dir.path(),
        "armballs.toml",
        "[campaign]\nname = \"armballs\"\nreps = 3\nrole = \"followup\"\n[matrix]\nenvs = [\"armballs\"]\n\
         algos = [\"rpe\", \"mge-efr-flat\", \"mge-efr-lp\", \"mge-pca-lp\"]\n\
         samplers = [\"kde\"]\nlatents = [4]\n[ugl]\nimages = 300\n\
         [explore]\nepochs = 400\nbootstrap_epochs = 50\n[mge]\ninterest_window = 20.0\n",
    );
    // Modules of 2 latents need an even latent count: a one-line error naming the keys.
    let odd = dir.path().join("odd.toml");
    replaced(&cfg, &odd, "latents = [4]", "latents = [3]");
    assert_one_line_error(
        &ugl(&["plan", "--config", p(&odd)]),
        "mge.module_size = 2 latents, but matrix.latents has 3",
    );
    let results = dir.path().join("results");
    let o = campaign(p(&cfg), p(&results.join("armballs")), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let ab = results.join("armballs");
    // Modular runs write their interest; the others do not.
    assert!(ab.join("armballs.mge-efr-lp.s0.interest.parquet").is_file());
    assert!(
        ab.join("armballs.mge-pca-lp.kde.l4.s1.interest.parquet")
            .is_file()
    );
    assert!(!ab.join("armballs.rpe.s0.interest.parquet").exists());
    let m = manifest(&ab.join("armballs.mge-efr-lp.s0.json"));
    let files: Vec<&str> = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["name"].as_str().unwrap())
        .collect();
    assert!(
        files.contains(&"armballs.mge-efr-lp.s0.interest.parquet"),
        "{files:?}"
    );
    // Per-latent R² per object in a learned space's manifest.
    let m = manifest(&ab.join("armballs.mge-pca-lp.kde.l4.s0.json"));
    let per = m["latent_quality"]["per_latent"].as_array().unwrap();
    assert_eq!(per.len(), 2);
    assert_eq!(per[1]["object"], "distractor");
    assert_eq!(per[0]["r2"].as_array().unwrap().len(), 4);
    // `ugl run` gives the same bytes as the campaign.
    let single = dir.path().join("single");
    let o = ugl(&argv(
        "run --env armballs --algo mge-efr-lp --seed 2 --profile {} --out {}",
        &[p(&cfg), p(&single)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    // And in a learned space, where the campaign shared one fitted PCA between runs and
    // `ugl run` fits its own.
    let o = ugl(&argv(
        "run --env armballs --algo mge-pca-lp --latents 4 --seed 1 --profile {} --out {}",
        &[p(&cfg), p(&single)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    for f in [
        "armballs.mge-efr-lp.s2.parquet",
        "armballs.mge-efr-lp.s2.interest.parquet",
        "armballs.mge-pca-lp.kde.l4.s1.parquet",
        "armballs.mge-pca-lp.kde.l4.s1.outcomes.parquet",
        "armballs.mge-pca-lp.kde.l4.s1.interest.parquet",
    ] {
        assert_eq!(
            std::fs::read(ab.join(f)).unwrap(),
            std::fs::read(single.join(f)).unwrap(),
            "{f}"
        );
    }
    // The report needs a main campaign: a tiny ArmBall one.
    let main = common::write_file(
        dir.path(),
        "main.toml",
        "[campaign]\nname = \"base\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-efr\"]\nsamplers = [\"kde\"]\nlatents = [\"true\"]\n\
         [explore]\nepochs = 150\n",
    );
    let o = campaign(p(&main), p(&results.join("base")), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = dir.path().join("report");
    let o = ugl(&argv(
        "report --results {} --out {} --main base",
        &[p(&results), p(&report)],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(report.join("REPORT.md")).unwrap();
    assert!(
        md.contains("## Beyond the paper: a distractor (ArmBalls)"),
        "{md}"
    );
    let page = std::fs::read_to_string(report.join("armballs.md")).unwrap();
    for needle in [
        "| RPE | 3 |",
        "| RGE-EFR (flat) | 3 |",
        "| MGE-EFR (LP) | 0 (ball) |",
        "| MGE-EFR (LP) | 1 (distractor) |",
        "| C4 |",
        "| C6 |",
        "## Disentanglement of the learned goal spaces",
    ] {
        assert!(page.contains(needle), "no `{needle}` in:\n{page}");
    }
    assert!(report.join("figures/armballs_coverage.svg").is_file());
    assert!(report.join("figures/armballs_interest.svg").is_file());
}

/// A closed stdout ends a command quietly with exit 0, as `ls | head` does (the reader has what
/// it wanted); a full one (`/dev/full`) is one line on stderr and exit 2. Both used to panic
/// ("failed printing to stdout", exit 101).
#[test]
fn a_closed_stdout_ends_quietly_and_a_full_one_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let commands: [&[&str]; 4] = [
        &["learners"],
        &["plan", "--config", "data/campaigns/paper.toml"],
        &[
            "run",
            "--env",
            "armball",
            "--algo",
            "rpe",
            "--epochs",
            "20",
            "--profile",
            "smoke",
            "--out",
            p(&out),
        ],
        &["--help"],
    ];
    let with_stdout = |args: &[&str], stdout: std::process::Stdio| {
        Command::new(env!("CARGO_BIN_EXE_ugl"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(stdout)
            .stderr(std::process::Stdio::piped())
            .output()
            .expect("ugl runs")
    };
    for args in commands {
        // The reading end is closed before the command starts: its first write fails.
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = with_stdout(args, writer.into());
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o), "", "{args:?}: quiet");
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = with_stdout(args, full.into());
        assert_one_line_error(&o, "No space left on device");
        assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
    }
    // The run itself was done and stored before its summary could not be printed.
    assert!(out.join("armball.rpe.s0.json").is_file());
}

/// `ugl embed --grid N` is checked against the machine's memory before anything is fitted, as
/// `--images` is: `--grid 1000` allocated 19.6 GB of images after the fit and aborted.
#[test]
fn embed_grid_is_checked_against_memory_before_fitting() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("emb").join("pca.npy");
    let embed = |grid: &str| {
        ugl(&argv(
            "embed --env armball --learner pca --latents 2 --images 300 --profile smoke --grid {} --out {}",
            &[grid, p(&out)],
        ))
    };
    assert_one_line_error(&embed("100000"), "--grid = 100000 needs about");
    let mem_gib = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|m| {
            let kib: f64 = m.lines().next()?.split_whitespace().nth(1)?.parse().ok()?;
            Some(kib / (1024.0 * 1024.0))
        })
        .unwrap_or(f64::INFINITY);
    // 10^6 images of 70x70: about 55 GiB with an encoder's f64 copy.
    if mem_gib < 50.0 {
        assert_one_line_error(&embed("1000"), "--grid = 1000 needs about");
    }
    assert!(
        !dir.path().join("emb").exists(),
        "nothing was fitted or written"
    );
}

/// A modular exploration of a learned goal space whose latents do not split into modules of
/// `mge.module_size` is refused before any training: `ugl run --algo mge-vae-lp --latents 3`
/// trained for seconds and then failed.
#[test]
fn modular_latent_sizes_are_checked_before_training() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let o = ugl(&argv(
        "run --env armarrow --algo mge-vae-lp --latents 3 --profile smoke --out {}",
        &[p(&out)],
    ));
    assert_one_line_error(
        &o,
        "--latents 3: mge-vae-lp splits its latents into modules of mge.module_size = 2",
    );
    assert!(!out.exists(), "nothing was trained or written");
}

/// Messages name what the user wrote: the algorithm given, the command-line flag (not the
/// library's option), the key of a learner's table and its line.
#[test]
fn messages_name_the_algorithm_the_flag_and_the_key_given() {
    let dir = tempfile::tempdir().unwrap();
    let o = ugl(&argv(
        "run --env armball --algo mge-external-lp --latents 2 --out {}",
        &[p(&dir.path().join("run"))],
    ));
    assert_one_line_error(&o, "--algo mge-external-lp needs --command");
    let o = ugl(&argv(
        "report --results data/results --main nosuch --out {}",
        &[p(&dir.path().join("report"))],
    ));
    assert_one_line_error(&o, "choose one with --main NAME");
    assert!(!stderr(&o).contains("ReportOptions"), "{}", stderr(&o));
    let cfg = common::write_file(
        dir.path(),
        "bvae.toml",
        "[campaign]\nname = \"t\"\nreps = 1\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rge-bvae\"]\n[learners.bvae]\nbeta = 4.0\ninit = 1\n",
    );
    let o = ugl(&["plan", "--config", p(&cfg)]);
    assert_one_line_error(&o, "learners.bvae.init: invalid type");
    assert!(
        stderr(&o).contains("(line 9: `init = 1`)"),
        "{}",
        stderr(&o)
    );
}

/// The position-only EFR draws RGE-EFR's exploration streams (paired): on ArmArrow it explores
/// without the angle and the runs differ. On ArmBall, whose outcome is the position, it would be
/// RGE-EFR itself under another label: refused.
#[test]
fn the_position_only_efr_is_paired_with_efr_and_drops_only_the_angle() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs");
    let run = |env: &str, algo: &str| {
        ugl(&argv(
            "run --env {} --algo {} --epochs 300 --profile smoke --out {}",
            &[env, algo, p(&out)],
        ))
    };
    for algo in ["rge-efr", "rge-efr-position"] {
        let o = run("armarrow", algo);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_one_line_error(&run("armball", "rge-efr-position"), "use --algo rge-efr");
    let m = |id: &str| manifest(&out.join(format!("{id}.json")));
    let (arrow, arrow_pos) = (m("armarrow.rge-efr.s0"), m("armarrow.rge-efr-position.s0"));
    assert_eq!(arrow["run_seed"], arrow_pos["run_seed"]);
    assert_ne!(
        arrow["summary"]["final_klc"],
        arrow_pos["summary"]["final_klc"]
    );
    assert_ne!(arrow["config_hash"], arrow_pos["config_hash"]);
}

/// The lock a campaign, compare or run leaves in its results directory is never committed: git
/// ignores it in every results directory of the checkout (the audit found it untracked).
#[test]
fn the_store_lock_is_git_ignored() {
    let root = env!("CARGO_MANIFEST_DIR");
    let in_repo = Command::new("git")
        .args(["-C", root, "rev-parse", "--is-inside-work-tree"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !in_repo {
        eprintln!("SKIPPED: {root} is not a git checkout");
        return;
    }
    for path in [
        "data/results/paper/.ugl-store.lock",
        "data/results/compare-x/.ugl-store.lock",
        "data/results-pending/x/.ugl-store.lock",
    ] {
        let o = Command::new("git")
            .args(["-C", root, "check-ignore", "-q", "--no-index", path])
            .status()
            .unwrap();
        assert!(o.success(), "{path} is not git-ignored");
    }
}
