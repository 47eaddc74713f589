//! End-to-end tests of `render_report` on a synthetic results store written with polars, following
//! `data/results/README.md` exactly: 2 envs x 2 algos x 3 seeds, epochs 0, 100, ..., 500, in the
//! main campaign `paper` (`tests/campaigns.rs` covers the other campaigns and the neural sections).

mod common;

use std::fs::File;
use std::path::{Path, PathBuf};

use polars::prelude::*;
use ugl_report::{ReportError, ReportOptions, render_report};

const EPOCHS: [i64; 6] = [0, 100, 200, 300, 400, 500];
const ENVS: [&str; 2] = ["armball", "armarrow"];
const ALGOS: [&str; 2] = ["rpe", "rge-efr"];
const SEEDS: [i64; 3] = [0, 1, 2];

fn paper_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper")
}

fn kmax(env: &str) -> f64 {
    if env == "armball" {
        756f64.ln()
    } else {
        22680f64.ln()
    }
}

/// The synthetic KLC of a run at an epoch: falls linearly from the maximum.
fn klc(env: &str, algo: &str, seed: i64, epoch: i64) -> f64 {
    let drop = if algo == "rpe" { 0.2 } else { 2.0 } + 0.1 * seed as f64;
    kmax(env) - drop * epoch as f64 / 500.0
}

fn sampler(algo: &str) -> &'static str {
    if algo == "rpe" { "none" } else { "uniform" }
}

/// Every run in the main campaign's directory.
fn dir_of(root: &Path, _env: &str) -> PathBuf {
    root.join("paper")
}

fn run_id(env: &str, algo: &str, seed: i64) -> String {
    format!("{env}.{algo}.s{seed}")
}

fn write_parquet(path: &Path, df: &mut DataFrame) {
    let mut f = File::create(path).unwrap();
    ParquetWriter::new(&mut f).finish(df).unwrap();
}

fn curve_frame(env: &str, algo: &str, seed: i64) -> DataFrame {
    let n = EPOCHS.len();
    let id = run_id(env, algo, seed);
    let rge = algo != "rpe";
    let n_outcomes: Vec<i64> = EPOCHS.iter().map(|&e| e + i64::from(rge)).collect();
    let n_moved: Vec<i64> = n_outcomes.iter().map(|&o| o / 3).collect();
    df!(
        "run_id" => vec![id.as_str(); n],
        "env" => vec![env; n],
        "algo" => vec![algo; n],
        "sampler" => vec![sampler(algo); n],
        "latents" => vec![0i64; n],
        "variant" => vec!["none"; n],
        "seed" => vec![seed; n],
        "epoch" => EPOCHS.to_vec(),
        "n_outcomes" => n_outcomes,
        "klc" => EPOCHS.iter().map(|&e| klc(env, algo, seed, e)).collect::<Vec<f64>>(),
        "n_moved" => n_moved,
        "coverage" => EPOCHS.iter().map(|&e| e as f64 / 1000.0).collect::<Vec<f64>>(),
    )
    .unwrap()
}

fn outcomes_frame(env: &str, algo: &str, seed: i64) -> DataFrame {
    let rge = algo != "rpe";
    let epochs: Vec<i64> = if rge {
        (0..=500).collect()
    } else {
        (1..=500).collect()
    };
    let n = epochs.len();
    let mut x = Vec::with_capacity(n);
    let mut y = Vec::with_capacity(n);
    let mut moved = Vec::with_capacity(n);
    for i in 0..n {
        let m = i % 3 == 2;
        let (px, py) = if m {
            let r = 0.95 * ((i * 37 + seed as usize * 11) % 100) as f64 / 100.0;
            let a = (i * 53) as f64 * 0.1;
            (r * a.cos(), r * a.sin())
        } else {
            (0.6, 0.6)
        };
        x.push(px);
        y.push(py);
        moved.push(m);
    }
    let angle: Vec<Option<f64>> = (0..n)
        .map(|i| (env == "armarrow").then(|| ((i % 20) as f64 / 10.0) - 1.0))
        .collect();
    let id = run_id(env, algo, seed);
    df!(
        "run_id" => vec![id.as_str(); n],
        "index" => (0..n as i64).collect::<Vec<i64>>(),
        "epoch" => epochs,
        "x" => x,
        "y" => y,
        "angle" => angle,
        "moved" => moved,
    )
    .unwrap()
}

fn manifest(dir: &Path, env: &str, algo: &str, seed: i64) -> String {
    let reduced = env == "armball";
    let mut m = serde_json::json!({
        "run_id": run_id(env, algo, seed),
        "env": env, "algo": algo, "seed": seed, "sampler": sampler(algo),
        "profile": "test",
        "git_revision": "abc1234",
        "toolchain": "rustc 1.95.0",
        "threads": 2,
        "host": "testhost",
        "wall_s": 10.0 + seed as f64,
        "reduced_budget": reduced,
        "budget_note": if reduced { "500 epochs instead of 5000" } else { "" },
    });
    common::complete_manifest(&mut m, dir);
    m["summary"]["final_klc"] = klc(env, algo, seed, 500).into();
    m.to_string()
}

fn write_run(root: &Path, env: &str, algo: &str, seed: i64) {
    let dir = dir_of(root, env);
    std::fs::create_dir_all(&dir).unwrap();
    let id = run_id(env, algo, seed);
    write_parquet(
        &dir.join(format!("{id}.parquet")),
        &mut curve_frame(env, algo, seed),
    );
    write_parquet(
        &dir.join(format!("{id}.outcomes.parquet")),
        &mut outcomes_frame(env, algo, seed),
    );
    std::fs::write(
        dir.join(format!("{id}.json")),
        manifest(&dir, env, algo, seed),
    )
    .unwrap();
}

fn synthetic_store(root: &Path) {
    for env in ENVS {
        for algo in ALGOS {
            for seed in SEEDS {
                write_run(root, env, algo, seed);
            }
        }
    }
}

fn opts(results: &Path, out: &Path) -> ReportOptions {
    let mut o = ReportOptions::new(results.to_path_buf(), out.to_path_buf());
    o.paper_dir = paper_dir();
    o.n_boot = 2_000;
    o
}

fn read_all(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn renders_report_and_figures_with_the_right_numbers() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let out = tmp.path().join("out");
    synthetic_store(&results);
    let summary = render_report(&opts(&results, &out)).unwrap();
    assert_eq!(summary.n_runs, 12);
    if let Some(keep) = std::env::var_os("UGL_REPORT_TEST_KEEP") {
        // To look at the output: UGL_REPORT_TEST_KEEP=/tmp/small cargo test -p ugl-report --test render
        render_report(&opts(&results, Path::new(&keep))).unwrap();
    }

    let report = out.join("REPORT.md");
    assert_eq!(summary.files[0], report);
    for name in [
        "klc_armball.svg",
        "klc_armarrow.svg",
        "coverage_armball.svg",
        "coverage_armarrow.svg",
    ] {
        assert!(out.join("figures").join(name).is_file(), "{name}");
    }
    for env in ENVS {
        for algo in ALGOS {
            let name = format!("outcomes_{env}_{algo}_{}_0_none.svg", sampler(algo));
            assert!(out.join("figures").join(&name).is_file(), "{name}");
        }
    }
    // REPORT.md, 2 KLC and 2 coverage figures, 4 outcome scatters, the paper's 3 illustrations
    // (Figures 1, 5, 6; Figures 1 and 6 need the `environment-figures` feature), 5 CSV files
    // (final values, curves, discovery measures, the validity check, the claims' comparisons;
    // no leaderboard without a learned goal space), the page of the outcome scatters the paper
    // did not draw (ArmArrow's here), the list of files.
    let env_figures = cfg!(feature = "environment-figures");
    let illustrations = if env_figures { 3 } else { 1 };
    assert_eq!(
        summary.files.len(),
        1 + 2 + 2 + 4 + illustrations + 5 + 1 + 1
    );
    assert!(!out.join("data/leaderboard.csv").exists());
    for (name, drawn) in [
        ("fig1_environments.svg", env_figures),
        ("fig5_radial_flow.svg", true),
        ("fig6_dmp_episode.svg", env_figures),
    ] {
        assert_eq!(out.join("figures").join(name).is_file(), drawn, "{name}");
    }
    for f in &summary.files {
        assert!(f.is_file(), "{}", f.display());
    }
    let svg = std::fs::read_to_string(out.join("figures/klc_armball.svg")).unwrap();
    assert!(
        svg.contains("exploration epochs") && svg.contains("KL-coverage (nats, lower is better)")
    );
    assert!(
        !svg.contains("100.0<") && !svg.contains(">500.0"),
        "epoch ticks printed as floats"
    );

    let md = std::fs::read_to_string(&report).unwrap();
    // Final means over seeds 0, 1, 2: drop = base + 0.1 * seed, mean drop = base + 0.1.
    for env in ENVS {
        for (algo, base) in [("rpe", 0.2), ("rge-efr", 2.0)] {
            let mean = kmax(env) - (base + 0.1);
            let _ = algo;
            let cell = format!("{mean:.3} ± 0.100");
            assert!(md.contains(&cell), "missing `{cell}` in\n{md}");
        }
    }
    // Paper comparison: ArmBall RPE 6.51.
    let rpe_mean = kmax("armball") - 0.3;
    let rpe_row = md
        .lines()
        .find(|l| l.starts_with("| RPE †") && l.contains(&format!("{rpe_mean:.3}")))
        .unwrap_or_else(|| panic!("no ArmBall RPE row in\n{md}"));
    assert!(rpe_row.contains("| 6.51 |"), "{rpe_row}");
    assert!(
        rpe_row.contains(&format!("{:+.3}", rpe_mean - 6.51)),
        "{rpe_row}"
    );
    // moved: n_moved = n_outcomes / 3 at epoch 500: RPE 500/3 = 166, EFR 501/3 = 167.
    assert!(rpe_row.contains("| 166 / 500 |"), "{rpe_row}");
    assert!(md.contains("| 167 / 501 |"));
    assert!(md.contains("| 50.0 % |"));
    // What was run, links, notes, the reduced budget.
    assert!(md.contains("Reduced budget"));
    // The warning counts every reduced run of every campaign rendered; the table under "What
    // was run" names the algorithm.
    assert!(md.contains("6 of the 12 runs in this report"), "{md}");
    assert!(
        md.contains("| RPE | 500 epochs instead of 5000 | 3 | paper |"),
        "{md}"
    );
    assert!(
        md.contains("| RGE-EFR | 500 epochs instead of 5000 | 3 | paper |"),
        "{md}"
    );
    // One row per campaign: role, runs, conditions, design, reduced runs, a committed tree.
    let row = md
        .lines()
        .find(|l| l.starts_with("| `paper` | main |"))
        .unwrap_or_else(|| panic!("no campaign row in\n{md}"));
    assert!(
        row.starts_with("| `paper` | main | 12 | 4 | 3 x 1 |"),
        "{row}"
    );
    assert!(row.ends_with("| — | 6 | committed |"), "{row}");
    assert!(
        md.contains("- **Campaigns:** main `paper` (12 runs"),
        "{md}"
    );
    assert!(md.contains("No `budget-*` campaign in the store"));
    assert!(!out.join("figures/budget_vae.svg").exists());
    assert!(md.contains("(figures/klc_armball.svg)"));
    // ArmArrow's scatters are not the paper's Figures 3, 8, 9: on their own page, linked.
    assert!(!md.contains("(figures/outcomes_armarrow_rge-efr_uniform_0_none.svg)"));
    assert!(md.contains("[`outcomes.md`](outcomes.md)"));
    let page = std::fs::read_to_string(out.join("outcomes.md")).unwrap();
    assert!(page.contains("(figures/outcomes_armarrow_rge-efr_uniform_0_none.svg)"));
    assert!(md.contains(ugl_report::markdown::EPOCH_NOTE));
    assert!(md.contains("single runs"));
    assert!(md.contains("`abc1234` (12 runs)"));
    assert!(md.contains("`testhost` (12 runs)"));
    assert!(md.contains(
        "- **Exploration wall time:** 2.2 min in total; per run 11.0 s on average (min 10.0 s, max 12.0 s)."
    ));
    assert!(md.contains("| 3 (0–2) |"));
    // Paper conditions not run are listed.
    assert!(md.contains("Paper conditions not in these results (21)"));
}

#[test]
fn rendering_twice_gives_identical_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let out1 = tmp.path().join("out1");
    let out2 = tmp.path().join("out2");
    let s1 = render_report(&opts(&results, &out1)).unwrap();
    render_report(&opts(&results, &out2)).unwrap();
    let (a, b) = (read_all(&out1), read_all(&out2));
    assert_eq!(a.len(), s1.files.len());
    assert_eq!(a, b);
    // And again into the same directory.
    render_report(&opts(&results, &out1)).unwrap();
    assert_eq!(read_all(&out1), a);
}

#[test]
fn stale_figures_are_removed_but_other_files_kept() {
    // A render removes exactly the files of the previous render's list (`files.txt`) that it no
    // longer writes: here the figures of a condition whose runs left the store.
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let out = tmp.path().join("out");
    synthetic_store(&results);
    render_report(&opts(&results, &out)).unwrap();
    let gone = out.join("figures/outcomes_armarrow_rge-efr_uniform_0_none.svg");
    assert!(gone.is_file());
    std::fs::write(out.join("figures/notes.txt"), "x").unwrap();
    std::fs::write(out.join("figures/klc_mine.svg"), "x").unwrap();
    for e in std::fs::read_dir(results.join("paper")).unwrap() {
        let p = e.unwrap().path();
        if p.file_name()
            .unwrap()
            .to_str()
            .unwrap()
            .starts_with("armarrow.rge-efr.")
        {
            std::fs::remove_file(p).unwrap();
        }
    }
    let s = render_report(&opts(&results, &out)).unwrap();
    assert!(
        !gone.exists(),
        "a figure of the previous render that this one did not write"
    );
    assert!(out.join("figures/notes.txt").exists());
    assert!(
        out.join("figures/klc_mine.svg").exists(),
        "a file no render wrote was removed"
    );
    let listed = std::fs::read_to_string(out.join(ugl_report::output::FILE_LIST)).unwrap();
    assert!(!listed.contains("armarrow_rge-efr"), "{listed}");
    assert!(s.files.iter().all(|f| f.is_file()));
}

#[test]
fn every_file_written_is_recorded() {
    // Every file under the output directory of a fresh render is in its list (a section that
    // forgot to record a file would leave it behind forever).
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let out = tmp.path().join("out");
    synthetic_store(&results);
    let s = render_report(&opts(&results, &out)).unwrap();
    let mut on_disk: Vec<String> = read_all(&out).into_iter().map(|(p, _)| p).collect();
    on_disk.sort();
    let mut listed: Vec<String> = s
        .files
        .iter()
        .map(|f| f.strip_prefix(&out).unwrap().display().to_string())
        .collect();
    listed.sort();
    assert_eq!(on_disk, listed);
}

#[test]
fn a_manifest_of_a_future_results_version_is_an_error() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let path = results.join("paper/armball.rpe.s1.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    m["crate_versions"]["results_version"] = 99.into();
    std::fs::write(&path, m.to_string()).unwrap();
    let err = render_report(&opts(&results, &tmp.path().join("out")))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("armball.rpe.s1.json") && err.contains("newer ugl-bench"),
        "{err}"
    );
}

#[test]
fn a_campaign_of_two_configurations_is_flagged() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let out = tmp.path().join("out");
    render_report(&opts(&results, &out)).unwrap();
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(!md.contains("Mixed configurations"), "{md}");
    // One run explored with another budget: the campaign now pools two configurations.
    let path = results.join("paper/armball.rpe.s1.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    m["explore"]["noise_sigma"] = 0.3.into();
    std::fs::write(&path, m.to_string()).unwrap();
    render_report(&opts(&results, &out)).unwrap();
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(
        md.contains("**⚠ Mixed configurations.** The runs of `paper` (2 configurations)"),
        "{md}"
    );
}

#[test]
fn missing_column_names_the_file_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let path = results.join("paper/armarrow.rpe.s1.parquet");
    let mut df = curve_frame("armarrow", "rpe", 1).drop("coverage").unwrap();
    write_parquet(&path, &mut df);
    let err = render_report(&opts(&results, &tmp.path().join("out"))).unwrap_err();
    match &err {
        ReportError::Column {
            path: p, column, ..
        } => {
            assert_eq!(p, &path);
            assert_eq!(column, "coverage");
        }
        other => panic!("unexpected error {other:?}"),
    }
    let msg = err.to_string();
    assert!(
        msg.contains("armarrow.rpe.s1.parquet") && msg.contains("coverage"),
        "{msg}"
    );
}

#[test]
fn wrong_column_type_names_the_file_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let path = results.join("paper/armball.rge-efr.s2.outcomes.parquet");
    let mut df = outcomes_frame("armball", "rge-efr", 2);
    let moved_as_int = df.column("moved").unwrap().cast(&DataType::Int64).unwrap();
    df.with_column(moved_as_int).unwrap();
    write_parquet(&path, &mut df);
    let err = render_report(&opts(&results, &tmp.path().join("out"))).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("armball.rge-efr.s2.outcomes.parquet")
            && msg.contains("`moved`")
            && msg.contains("bool"),
        "{msg}"
    );
}

#[test]
fn corrupt_parquet_is_an_error_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let path = results.join("paper/armball.rpe.s0.outcomes.parquet");
    std::fs::write(&path, b"PAR1 this is not parquet at all PAR1").unwrap();
    let err = render_report(&opts(&results, &tmp.path().join("out"))).unwrap_err();
    assert!(matches!(err, ReportError::Parquet { .. }), "{err:?}");
    eprintln!("{err}");
    assert!(
        err.to_string().contains("armball.rpe.s0.outcomes.parquet"),
        "{err}"
    );
}

#[test]
fn corrupt_manifest_is_an_error_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    std::fs::write(results.join("paper/armarrow.rge-efr.s0.json"), "{ not json").unwrap();
    let err = render_report(&opts(&results, &tmp.path().join("out"))).unwrap_err();
    assert!(
        err.to_string().contains("armarrow.rge-efr.s0.json"),
        "{err}"
    );
}

#[test]
fn empty_or_missing_results_dir_is_a_clear_error() {
    let tmp = tempfile::tempdir().unwrap();
    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(empty.join("some-campaign")).unwrap();
    let err = render_report(&opts(&empty, &tmp.path().join("out"))).unwrap_err();
    assert!(matches!(err, ReportError::EmptyResults(_)), "{err:?}");
    assert!(err.to_string().contains("no runs found"), "{err}");

    let err = render_report(&opts(&tmp.path().join("nope"), &tmp.path().join("out"))).unwrap_err();
    assert!(matches!(err, ReportError::NoResultsDir(_)), "{err:?}");

    // Only an incomplete run: a campaign that has not finished its first run.
    let partial = tmp.path().join("partial");
    std::fs::create_dir_all(partial.join("paper")).unwrap();
    write_parquet(
        &partial.join("paper/armball.rpe.s0.parquet"),
        &mut curve_frame("armball", "rpe", 0),
    );
    let err = render_report(&opts(&partial, &tmp.path().join("out"))).unwrap_err();
    assert!(
        matches!(err, ReportError::NoCompleteRuns { incomplete: 1, .. }),
        "{err:?}"
    );
}

/// Runs written from a tree with uncommitted changes are counted in their campaign's row.
#[test]
fn runs_from_a_dirty_tree_are_flagged() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let path = results.join("paper/armball.rpe.s2.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("\"abc1234\"", "\"abc1234-dirty\"")).unwrap();
    let out = tmp.path().join("out");
    render_report(&opts(&results, &out)).unwrap();
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    let row = md
        .lines()
        .find(|l| l.starts_with("| `paper` | main |"))
        .unwrap_or_else(|| panic!("no campaign row in\n{md}"));
    assert!(row.ends_with("| **1 `-dirty`** |"), "{row}");
}

#[test]
fn incomplete_runs_are_skipped_and_listed() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    std::fs::remove_file(results.join("paper/armball.rpe.s2.json")).unwrap();
    let out = tmp.path().join("out");
    let s = render_report(&opts(&results, &out)).unwrap();
    assert_eq!(s.n_runs, 11);
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(md.contains("Incomplete runs skipped"), "{md}");
    assert!(
        md.contains("`paper/armball.rpe.s2`: missing armball.rpe.s2.json"),
        "{md}"
    );
}

#[test]
fn the_same_run_in_another_campaign_is_no_duplicate_and_is_not_used() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    // The same ArmArrow run copied into a second campaign directory, and one at the top level.
    let other = results.join("camp-b");
    std::fs::create_dir_all(&other).unwrap();
    for suffix in [".parquet", ".outcomes.parquet", ".json"] {
        let name = format!("armarrow.rpe.s0{suffix}");
        std::fs::copy(results.join("paper").join(&name), other.join(&name)).unwrap();
        std::fs::copy(results.join("paper").join(&name), results.join(&name)).unwrap();
    }
    let out = tmp.path().join("out");
    let s = render_report(&opts(&results, &out)).unwrap();
    assert_eq!((s.n_runs, s.n_main_runs), (12, 12));
    assert_eq!(
        s.unused_campaigns,
        vec!["".to_string(), "camp-b".to_string()]
    );
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(
        md.contains("present but not used: `(top level)` (1 run), `camp-b` (1 run)"),
        "{md}"
    );
    // Seeds stay 0-2: the copies are not merged into the main campaign's conditions.
    assert!(md.contains("| 3 (0–2) |"));
    assert!(!md.contains("| 4 ("));
}

#[test]
fn infinite_klc_is_reported_as_inf_not_nan() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let mut df = curve_frame("armarrow", "rge-efr", 1);
    let mut k: Vec<f64> = EPOCHS
        .iter()
        .map(|&e| klc("armarrow", "rge-efr", 1, e))
        .collect();
    *k.last_mut().unwrap() = f64::INFINITY;
    df.with_column(Column::new("klc".into(), k)).unwrap();
    write_parquet(&results.join("paper/armarrow.rge-efr.s1.parquet"), &mut df);
    let out = tmp.path().join("out");
    render_report(&opts(&results, &out)).unwrap();
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(md.contains("| inf (1 of 3 runs inf) |"), "{md}");
    assert!(md.contains("Infinite KL-coverage"));
    assert!(!md.contains("NaN") && !md.contains("n/a"), "{md}");
}

#[test]
fn missing_paper_dir_is_reported_not_fatal() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let out = tmp.path().join("out");
    let mut o = opts(&results, &out);
    o.paper_dir = tmp.path().join("no-paper");
    render_report(&o).unwrap();
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(md.contains("Paper reference values not found"));
}

#[test]
fn damaged_parquet_pages_are_an_error_not_a_panic() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    synthetic_store(&results);
    let path = results.join("paper/armarrow.rge-efr.s2.outcomes.parquet");
    let mut bytes = std::fs::read(&path).unwrap();
    // Overwrite the data pages but keep the magic bytes and the footer.
    let n = bytes.len();
    for b in &mut bytes[8..n / 2] {
        *b = 0xFF;
    }
    std::fs::write(&path, &bytes).unwrap();
    let err = render_report(&opts(&results, &tmp.path().join("out"))).unwrap_err();
    eprintln!("{err}");
    assert!(
        err.to_string()
            .contains("armarrow.rge-efr.s2.outcomes.parquet"),
        "{err}"
    );
}
