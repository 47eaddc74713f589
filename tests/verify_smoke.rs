//! Reproducibility check (`make verify`): the `smoke` campaign (every algorithm, tiny budget),
//! compared with what was recorded.
//!
//! Results are bit-for-bit reproducible within one SIMD level (README "Reproducibility": the
//! float kernels dispatch on the CPU's features), so the checksums are kept per level:
//! - on a level with a file `data/checksums/smoke.<level>.sha256`, every result file's SHA-256
//!   must equal the recorded one;
//! - on any other level, the baselines' files (RPE, RGE-EFR: scalar code, no run-time
//!   dispatch) must still match the recorded checksums exactly, and the mean final KL-coverage
//!   and ball-move count over all runs must agree with `data/checksums/smoke.summary.csv`
//!   within a tolerance (below), so a real change of results still fails there.
//!
//! `make verify-update` (`UGL_VERIFY_UPDATE=1`) records this machine's level file and the
//! summaries instead of comparing.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use ugl_bench::campaign::machine::simd_level;

/// Largest difference of the mean final KL-coverage over all runs, on a level without
/// checksums. A different SIMD level that rounds differently makes a run diverge like another
/// seed (exploration is chaotic: one flipped nearest neighbour changes the rest of the run).
/// Between the two seeds of a smoke condition the final KLC differs by 0.68 nats (median; 0.61
/// sd), so the mean of 104 such runs moves by about 0.06 sd: 0.25 is four of those.
const MEAN_KLC_TOLERANCE: f64 = 0.25;
/// Largest relative difference of the mean ball-move count, likewise.
const MEAN_MOVED_TOLERANCE: f64 = 0.25;
const TOLERANCE_NOTE: &str = "README, Reproducibility";

/// The baselines (RPE, RGE-EFR) run scalar f64 code with no run-time SIMD dispatch: their
/// files must match the recorded checksums exactly on every x86-64 level.
fn level_independent(file: &str) -> bool {
    file.contains(".rpe.") || file.contains(".rge-efr.")
}

struct RunSummary {
    final_klc: f64,
    n_moved: u64,
}

fn summaries(dir: &Path) -> BTreeMap<String, RunSummary> {
    let mut m = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|x| x != "json") {
            continue;
        }
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let s = &v["summary"];
        let klc = match &s["final_klc"] {
            serde_json::Value::String(t) if t == "inf" => f64::INFINITY,
            x => x.as_f64().unwrap(),
        };
        m.insert(
            s["run"].as_str().unwrap().to_string(),
            RunSummary {
                final_klc: klc,
                n_moved: s["n_moved"].as_u64().unwrap(),
            },
        );
    }
    m
}

fn summary_csv(m: &BTreeMap<String, RunSummary>) -> String {
    let mut out = String::from("run,final_klc,n_moved\n");
    for (run, s) in m {
        out.push_str(&format!("{run},{:?},{}\n", s.final_klc, s.n_moved));
    }
    out
}

fn parse_summary_csv(text: &str) -> BTreeMap<String, RunSummary> {
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].to_string(),
                RunSummary {
                    final_klc: f[1].parse().unwrap(),
                    n_moved: f[2].parse().unwrap(),
                },
            )
        })
        .collect()
}

/// The summary check of a level without checksums; returns the problems found.
fn compare_summaries(
    expected: &BTreeMap<String, RunSummary>,
    got: &BTreeMap<String, RunSummary>,
) -> Vec<String> {
    let mut problems = Vec::new();
    if expected.keys().ne(got.keys()) {
        problems.push(format!(
            "the runs differ: {} recorded, {} now",
            expected.len(),
            got.len()
        ));
        return problems;
    }
    let (mut klc_e, mut klc_g, mut n) = (0.0, 0.0, 0usize);
    let (mut moved_e, mut moved_g) = (0.0, 0.0);
    for (run, e) in expected {
        let g = &got[run];
        if e.final_klc.is_finite() != g.final_klc.is_finite() {
            problems.push(format!(
                "{run}: final KLC {} vs recorded {}",
                g.final_klc, e.final_klc
            ));
        } else if e.final_klc.is_finite() {
            klc_e += e.final_klc;
            klc_g += g.final_klc;
            n += 1;
        }
        moved_e += e.n_moved as f64;
        moved_g += g.n_moved as f64;
    }
    let (mean_e, mean_g) = (klc_e / n as f64, klc_g / n as f64);
    if (mean_e - mean_g).abs() > MEAN_KLC_TOLERANCE {
        problems.push(format!(
            "mean final KLC {mean_g:.4} vs recorded {mean_e:.4} (tolerance {MEAN_KLC_TOLERANCE})"
        ));
    }
    if (moved_g - moved_e).abs() > MEAN_MOVED_TOLERANCE * moved_e {
        problems.push(format!(
            "ball moves {moved_g} in all vs recorded {moved_e} (tolerance {}%)",
            100.0 * MEAN_MOVED_TOLERANCE
        ));
    }
    problems
}

/// The checksum lines of every recorded level, for the level-independent files.
fn recorded_level_independent(dir: &Path) -> Vec<String> {
    let mut lines = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if name.starts_with("smoke.") && name.ends_with(".sha256") {
            for l in std::fs::read_to_string(&path).unwrap().lines() {
                if level_independent(l) && !lines.iter().any(|x| x == l) {
                    lines.push(l.to_string());
                }
            }
        }
    }
    lines.sort();
    lines
}

#[test]
fn smoke_campaign_matches_the_recorded_results() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let level = simd_level();
    let sums_path = root.join(format!("data/checksums/smoke.{level}.sha256"));
    let summary_path = root.join("data/checksums/smoke.summary.csv");
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args([
            "campaign",
            "--config",
            "data/campaigns/smoke.toml",
            "--quiet",
            "--jobs",
            "2",
            "--out",
        ])
        .arg(dir.path())
        .current_dir(root)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut files: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".parquet"))
        .collect();
    files.sort();
    let sums = Command::new("sha256sum")
        .args(&files)
        .current_dir(dir.path())
        .output()
        .expect("sha256sum (coreutils) is installed");
    assert!(sums.status.success());
    let got = String::from_utf8(sums.stdout).unwrap();
    let got_summaries = summaries(dir.path());
    if std::env::var_os("UGL_VERIFY_UPDATE").is_some() {
        // `make verify-update`: record this level's checksums and the summaries.
        std::fs::create_dir_all(sums_path.parent().unwrap()).unwrap();
        std::fs::write(&sums_path, &got).unwrap();
        std::fs::write(&summary_path, summary_csv(&got_summaries)).unwrap();
        eprintln!(
            "wrote {} ({} files) and {}",
            sums_path.display(),
            files.len(),
            summary_path.display()
        );
        return;
    }
    match std::fs::read_to_string(&sums_path) {
        Ok(expected) => {
            let (exp, got): (Vec<&str>, Vec<&str>) =
                (expected.lines().collect(), got.lines().collect());
            let differing: Vec<&&str> = got.iter().filter(|l| !exp.contains(l)).collect();
            assert_eq!(exp.len(), got.len(), "number of result files changed");
            assert!(
                differing.is_empty(),
                "results changed on {level} for {} files, e.g. {:?}; if intended, run \
                 `make verify-update` and commit",
                differing.len(),
                differing.first()
            );
        }
        Err(_) => {
            eprintln!(
                "note: no checksums for SIMD level {level} ({} is missing): comparing every \
                 run's final KL-coverage and ball moves with {} within a tolerance ({TOLERANCE_NOTE})",
                sums_path.display(),
                summary_path.display()
            );
            let expected = parse_summary_csv(
                &std::fs::read_to_string(&summary_path).expect("committed summaries"),
            );
            let mut problems = compare_summaries(&expected, &got_summaries);
            let recorded = recorded_level_independent(sums_path.parent().unwrap());
            let mut mine: Vec<String> = got
                .lines()
                .filter(|l| level_independent(l))
                .map(String::from)
                .collect();
            mine.sort();
            assert!(
                !recorded.is_empty(),
                "no recorded checksums of the baselines"
            );
            if mine != recorded {
                problems.push(format!(
                    "the baselines (RPE, RGE-EFR), which use no run-time SIMD dispatch, changed: \
                     {} of {} files differ",
                    mine.iter().filter(|l| !recorded.contains(l)).count(),
                    recorded.len()
                ));
            }
            let identical = expected
                .iter()
                .filter(|(k, e)| {
                    let g = &got_summaries[k.as_str()];
                    g.final_klc == e.final_klc && g.n_moved == e.n_moved
                })
                .count();
            eprintln!(
                "note: {identical} of {} runs have the recorded final KLC and ball moves exactly",
                expected.len()
            );
            assert!(
                problems.is_empty(),
                "results on {level} differ from the recorded ones beyond the tolerance: {}",
                problems.join("; ")
            );
        }
    }
}

#[test]
fn the_summary_check_catches_a_real_change() {
    let run = |klc: f64, moved: u64| RunSummary {
        final_klc: klc,
        n_moved: moved,
    };
    let base: BTreeMap<String, RunSummary> = (0..40)
        .map(|i| (format!("r{i}"), run(4.0 + i as f64 * 0.01, 100 + i)))
        .collect();
    let with = |f: &dyn Fn(usize, &RunSummary) -> RunSummary| -> BTreeMap<String, RunSummary> {
        base.iter()
            .enumerate()
            .map(|(i, (k, s))| (k.clone(), f(i, s)))
            .collect()
    };
    assert!(compare_summaries(&base, &with(&|_, s| run(s.final_klc, s.n_moved))).is_empty());
    // Chaotic divergence: runs change both ways, the means stay.
    let noisy = with(&|i, s| run(s.final_klc + if i % 2 == 0 { 0.6 } else { -0.6 }, s.n_moved));
    assert!(compare_summaries(&base, &noisy).is_empty());
    // Every run shifted by 0.3 nats: the mean moves beyond the tolerance.
    assert!(!compare_summaries(&base, &with(&|_, s| run(s.final_klc + 0.3, s.n_moved))).is_empty());
    // Far fewer ball moves.
    assert!(!compare_summaries(&base, &with(&|_, s| run(s.final_klc, s.n_moved / 2))).is_empty());
    // A run that now ends at +inf, and a missing run.
    assert!(
        !compare_summaries(
            &base,
            &with(&|i, s| run(if i == 3 { f64::INFINITY } else { s.final_klc }, s.n_moved))
        )
        .is_empty()
    );
    let mut missing = with(&|_, s| run(s.final_klc, s.n_moved));
    missing.remove("r0");
    assert!(!compare_summaries(&base, &missing).is_empty());
    assert!(level_independent("abc  armball.rge-efr.s0.parquet"));
    assert!(!level_independent(
        "abc  armball.rge-vae.faithful.kde.l2.s0.parquet"
    ));
}
