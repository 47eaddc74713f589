//! Reproducibility check (`make verify`): the `smoke` campaign (every algorithm, tiny budget),
//! compared with what was recorded.
//!
//! Results are bit-for-bit reproducible within one SIMD level (README "Reproducibility": the
//! float kernels dispatch on the CPU's features), so the checksums are kept per level:
//! - on a level with a file `data/checksums/smoke.<level>.sha256`, every result file's SHA-256
//!   must equal the recorded one;
//! - on any other level, every run's final KL-coverage and ball-move count must agree with
//!   `data/checksums/smoke.summary.csv` within a tolerance (below), so a real change of results
//!   still fails there.
//!
//! `make verify-update` (`UGL_VERIFY_UPDATE=1`) records this machine's level file and the
//! summaries instead of comparing.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use ugl_bench::campaign::machine::simd_level;

/// Largest difference of one run's final KL-coverage (nats) accepted on a level without
/// checksums. Measured between x86-64-v4 and x86-64-v3 (emulated with `qemu-x86_64 -cpu max`):
/// see `TOLERANCE_NOTE`.
const KLC_TOLERANCE: f64 = 0.5;
/// Largest difference of the mean final KL-coverage over all runs.
const MEAN_KLC_TOLERANCE: f64 = 0.05;
const TOLERANCE_NOTE: &str = "README, Reproducibility";

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
    let (mut sum_e, mut sum_g, mut n) = (0.0, 0.0, 0usize);
    for (run, e) in expected {
        let g = &got[run];
        let d = (g.final_klc - e.final_klc).abs();
        if !(d <= KLC_TOLERANCE || g.final_klc == e.final_klc) {
            problems.push(format!(
                "{run}: final KLC {} vs recorded {} (tolerance {KLC_TOLERANCE})",
                g.final_klc, e.final_klc
            ));
        }
        let moved_tol = (e.n_moved as f64 * 0.5).max(20.0);
        if (g.n_moved as f64 - e.n_moved as f64).abs() > moved_tol {
            problems.push(format!(
                "{run}: {} ball moves vs recorded {} (tolerance {moved_tol})",
                g.n_moved, e.n_moved
            ));
        }
        if e.final_klc.is_finite() && g.final_klc.is_finite() {
            sum_e += e.final_klc;
            sum_g += g.final_klc;
            n += 1;
        }
    }
    let (mean_e, mean_g) = (sum_e / n as f64, sum_g / n as f64);
    if (mean_e - mean_g).abs() > MEAN_KLC_TOLERANCE {
        problems.push(format!(
            "mean final KLC {mean_g:.4} vs recorded {mean_e:.4} (tolerance {MEAN_KLC_TOLERANCE})"
        ));
    }
    problems
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
            let problems = compare_summaries(&expected, &got_summaries);
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
    let same: BTreeMap<String, RunSummary> = base
        .iter()
        .map(|(k, s)| (k.clone(), run(s.final_klc, s.n_moved)))
        .collect();
    assert!(compare_summaries(&base, &same).is_empty());
    // Every run shifted by 0.1 nats: each within the per-run tolerance, the mean is not.
    let shifted: BTreeMap<String, RunSummary> = base
        .iter()
        .map(|(k, s)| (k.clone(), run(s.final_klc + 0.1, s.n_moved)))
        .collect();
    assert!(!compare_summaries(&base, &shifted).is_empty());
    // One run far off.
    let mut one = same;
    one.insert("r3".into(), run(9.0, 103));
    assert!(!compare_summaries(&base, &one).is_empty());
    // A missing run.
    let mut missing: BTreeMap<String, RunSummary> = base
        .iter()
        .map(|(k, s)| (k.clone(), run(s.final_klc, s.n_moved)))
        .collect();
    missing.remove("r0");
    assert!(!compare_summaries(&base, &missing).is_empty());
}
