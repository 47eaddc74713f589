//! A run's bytes depend on its identity only (seed.rs: order-independent results).
//!
//! Every algorithm of the smoke matrix (both samplers, both variants) is run four ways, and the
//! result files must be byte-identical:
//! 1. a campaign in plan order, 1 worker;
//! 2. the same campaign with every matrix list reversed (so the runs sharing a fitted
//!    representation execute in the other order), 2 workers;
//! 3. each run alone with `ugl run --no-cache` (its own fit, nothing shared);
//! 4. the first campaign's store with the second run of every cell deleted (the state a
//!    `kill -9` between the two runs of a cell leaves), resumed: the representation comes from
//!    the model cache, and the deleted runs run again after nothing else.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn ugl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("ugl runs")
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

const ENVS: [&str; 2] = ["armball", "armarrow"];
const ALGOS: [&str; 8] = [
    "rpe",
    "rge-efr",
    "rge-pca",
    "rge-pca-centred",
    "rge-isomap",
    "rge-ae",
    "rge-vae",
    "rge-rfvae",
];
const SAMPLERS: [&str; 2] = ["kde", "gaussian"];
const VARIANTS: [&str; 2] = ["faithful", "corrected"];

fn list(items: &[&str], reverse: bool) -> String {
    let mut v: Vec<String> = items.iter().map(|s| format!("\"{s}\"")).collect();
    if reverse {
        v.reverse();
    }
    v.join(", ")
}

fn write_config(dir: &Path, name: &str, reverse: bool) -> PathBuf {
    let text = format!(
        "[campaign]\nname = \"order\"\nreps = 1\n[matrix]\nenvs = [{}]\nalgos = [{}]\n\
         samplers = [{}]\nlatents = [\"true\"]\nvariants = [{}]\n\
         [ugl]\nimages = 300\n[explore]\nepochs = 400\neval_every = 100\n\
         [learners.ae]\niterations = 20\nhidden = [16, 8]\n\
         [learners.vae]\niterations = 20\nhidden = [16, 8]\n\
         [learners.rfvae]\niterations = 20\nhidden = [16, 8]\nwarmup = 5\n",
        list(&ENVS, reverse),
        list(&ALGOS, reverse),
        list(&SAMPLERS, reverse),
        list(&VARIANTS, reverse),
    );
    common::write_file(dir, &format!("{name}.toml"), &text)
}

/// `ugl run` arguments of a run id (`armball.rge-vae.faithful.kde.l2.s0`, `armball.rpe.s0`).
fn run_args(run_id: &str) -> Vec<String> {
    let parts: Vec<&str> = run_id.split('.').collect();
    let mut args = vec![
        "--env".to_string(),
        parts[0].to_string(),
        "--algo".into(),
        parts[1].into(),
    ];
    let rest = &parts[2..];
    let rest = if VARIANTS.contains(&rest[0]) {
        args.extend(["--variant".into(), rest[0].into()]);
        &rest[1..]
    } else {
        rest
    };
    if rest.len() == 3 {
        args.extend(["--sampler".into(), rest[0].into()]);
        args.extend(["--latents".into(), rest[1].trim_start_matches('l').into()]);
    }
    let seed = rest.last().unwrap().trim_start_matches('s');
    args.extend(["--seed".into(), seed.into()]);
    args
}

/// The parquet files of `dir` are `expected`, byte for byte; the message names those that differ.
fn assert_same(expected: &[(String, Vec<u8>)], dir: &Path, what: &str) {
    let got = common::parquet_files(dir);
    let differing: Vec<&String> = expected
        .iter()
        .zip(&got)
        .filter(|(x, y)| x != y)
        .map(|(x, _)| &x.0)
        .collect();
    assert!(
        differing.is_empty() && got.len() == expected.len(),
        "{what} {differing:?} ({} files, {} expected)",
        got.len(),
        expected.len()
    );
}

#[test]
fn results_depend_on_the_run_identity_only() {
    let dir = tempfile::tempdir().unwrap();
    let forward = write_config(dir.path(), "forward", false);
    let reverse = write_config(dir.path(), "reverse", true);

    let plan = String::from_utf8(ok(ugl(&["plan", "--config", p(&forward)])).stdout).unwrap();
    let ids: Vec<&str> = plan.lines().collect();
    // Per env: rpe, efr, pca, pca-centred, isomap, ae (kde only), vae and rfvae (2 variants x
    // 2 samplers).
    assert_eq!(ids.len(), 2 * (6 + 4 + 4), "{plan}");
    let reverse_plan =
        String::from_utf8(ok(ugl(&["plan", "--config", p(&reverse)])).stdout).unwrap();
    let mut a: Vec<&str> = reverse_plan.lines().collect();
    assert_ne!(a, ids, "the reversed matrix runs in another order");
    a.sort();
    let mut b = ids.clone();
    b.sort();
    assert_eq!(a, b, "the same runs");

    // 1. Plan order, one worker.
    let one = dir.path().join("forward");
    ok(ugl(&[
        "campaign",
        "--config",
        p(&forward),
        "--out",
        p(&one),
        "--jobs",
        "1",
        "--quiet",
    ]));
    let expected = common::parquet_files(&one);
    assert_eq!(expected.len(), 2 * ids.len());

    // 2. Every list reversed, two workers.
    let two = dir.path().join("reverse");
    ok(ugl(&[
        "campaign",
        "--config",
        p(&reverse),
        "--out",
        p(&two),
        "--jobs",
        "2",
        "--quiet",
    ]));
    assert_same(&expected, &two, "reversed order changes");

    // 3. Each run alone, its representation fitted for it alone.
    let alone = dir.path().join("alone");
    for id in &ids {
        let mut args = vec!["run".to_string()];
        args.extend(run_args(id));
        args.extend(["--profile", p(&forward), "--out", p(&alone), "--no-cache"].map(String::from));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        ok(ugl(&args));
    }
    assert_same(&expected, &alone, "a lone run differs from the campaign's:");

    // 4. Killed between the two runs of every cell (the gaussian runs come second in plan
    // order), then resumed.
    let mut deleted = 0;
    for e in std::fs::read_dir(&one).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        if name.contains(".gaussian.") {
            std::fs::remove_file(&path).unwrap();
            deleted += 1;
        }
    }
    assert_eq!(
        deleted,
        3 * 8,
        "2 envs x 2 learners x 2 variants, 3 files each"
    );
    let o = ok(ugl(&[
        "campaign",
        "--config",
        p(&forward),
        "--out",
        p(&one),
        "--jobs",
        "2",
    ]));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("8 runs executed"), "{err}");
    assert!(
        common::parquet_files(&one) == expected,
        "a resumed cell differs from the uninterrupted one"
    );
}
