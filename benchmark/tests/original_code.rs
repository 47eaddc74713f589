//! Our environments and KL-coverage against outputs of the original code (explauto 1.3.0 + the
//! UGSL environment logic), produced by `scripts/original_fixtures.py` (see
//! `scripts/README-fixtures.md`).

use serde_json::Value;
use ugl_bench::env::dmp::trajectory;
use ugl_bench::env::{DmpConfig, EnvConfig, EnvKind, PARAMS, make_env};
use ugl_bench::metrics::KlCoverage;

fn load(name: &str) -> Value {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(&path).expect("fixture present"))
        .expect("fixture parses")
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn theta(v: &Value) -> [f64; PARAMS] {
    floats(v).try_into().expect("21 parameters")
}

#[test]
fn rollouts_match_the_original_to_1e12() {
    let fx = load("orig_rollouts.json");
    for kind in EnvKind::paper() {
        let env = make_env(kind, &EnvConfig::default());
        let cases = fx[kind.name()].as_array().unwrap();
        assert!(cases.len() > 300);
        let (mut caught, mut worst) = (0, 0.0f64);
        for (i, c) in cases.iter().enumerate() {
            let r = env.rollout(
                &theta(&c["theta"]),
                &mut ugl_bench::seed::stream(0, ugl_bench::seed::Component::Distractor),
            );
            let moved = c["moved"].as_bool().unwrap();
            assert_eq!(r.caught, moved, "{} case {i}: catch decision", kind);
            caught += moved as usize;
            for (a, b) in r.outcome().iter().zip(floats(&c["object"])) {
                worst = worst.max((a - b).abs());
            }
            for (a, b) in r.hand.iter().zip(floats(&c["hand"])) {
                worst = worst.max((a - b).abs());
            }
        }
        assert!(worst < 1e-12, "{kind}: largest difference {worst:e}");
        assert!(
            caught >= 40,
            "{kind}: the fixture must exercise catches, got {caught}"
        );
    }
}

#[test]
fn dmp_trajectories_match_the_original() {
    let fx = load("orig_rollouts.json");
    for t in fx["trajectories"].as_array().unwrap() {
        let ours = trajectory(&DmpConfig::default(), &theta(&t["theta"]));
        let theirs = t["dmp_output"].as_array().unwrap();
        assert_eq!(ours.len(), theirs.len());
        for (row, trow) in ours.iter().zip(theirs) {
            for (a, b) in row.iter().zip(floats(trow)) {
                assert!((a - b).abs() < 1e-12 * b.abs().max(1.0), "{a} vs {b}");
            }
        }
    }
}

#[test]
fn klc_matches_numpy_scipy() {
    let fx = load("orig_klc.json");
    for (kind, dim) in [("armball", 2), ("armarrow", 3)] {
        let klc = KlCoverage::new(dim).unwrap();
        for c in fx[kind].as_array().unwrap() {
            let label = c["label"].as_str().unwrap();
            let pts: Vec<Vec<f64>> = c["points"].as_array().unwrap().iter().map(floats).collect();
            let ours = klc.evaluate(pts.iter().map(|p| &p[..])).unwrap();
            let n_points = c["n_points"].as_u64().unwrap();
            let n_in_range = c["n_in_range"].as_u64().unwrap();
            if n_in_range < n_points {
                // numpy's histogramdd silently drops points outside [-1,1]; they are outside the
                // achievable set, so we report +inf instead of a silently wrong number.
                assert_eq!(ours, f64::INFINITY, "{kind} {label}");
                continue;
            }
            match &c["klc"] {
                Value::String(s) => {
                    assert_eq!(s, "inf");
                    assert_eq!(ours, f64::INFINITY, "{kind} {label}");
                }
                v => {
                    let theirs = v.as_f64().unwrap();
                    assert!(
                        (ours - theirs).abs() < 1e-12,
                        "{kind} {label}: {ours} vs {theirs}"
                    );
                }
            }
            let mut h = klc.histogram();
            for p in &pts {
                h.add(p).unwrap();
            }
            assert_eq!(
                h.n_visited() as u64,
                c["nonempty_bins"].as_u64().unwrap(),
                "{kind} {label}"
            );
        }
    }
}
