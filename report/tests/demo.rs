//! A paper-sized synthetic store (every condition of the `paper` campaign's matrix: 48 conditions
//! with the VAE / RFVAE variants and Gaussian goals, 5 seeds, 5000 epochs; and four `budget-vae-*`
//! campaigns), rendered with the default options: checks that a full report renders in reasonable time and
//! gives something to look at. Ignored by default (a few seconds in an optimised build):
//!
//! `UGL_REPORT_DEMO_OUT=/tmp/demo cargo test -p ugl-report --test demo -- --ignored`
//! keeps the store and the report under that directory.

mod common;

use std::fs::File;
use std::path::{Path, PathBuf};

use polars::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ugl_report::{ReportOptions, render_report};

struct Cond {
    env: &'static str,
    algo: &'static str,
    sampler: &'static str,
    latents: i64,
    variant: &'static str,
    final_klc: f64,
}

fn conditions() -> Vec<Cond> {
    let mut v = Vec::new();
    for (env, lats, rpe, efr) in [
        ("armball", [2, 10], 6.51, 4.58),
        ("armarrow", [3, 10], 9.91, 7.46),
    ] {
        v.push(Cond {
            env,
            algo: "rpe",
            sampler: "none",
            latents: 0,
            variant: "none",
            final_klc: rpe,
        });
        v.push(Cond {
            env,
            algo: "rge-efr",
            sampler: "uniform",
            latents: 0,
            variant: "none",
            final_klc: efr,
        });
        for (k, l) in lats.into_iter().enumerate() {
            for (j, algo) in ["rge-pca", "rge-isomap", "rge-ae", "rge-vae", "rge-rfvae"]
                .into_iter()
                .enumerate()
            {
                let variants: &[&'static str] = if matches!(algo, "rge-vae" | "rge-rfvae") {
                    &["faithful", "corrected"]
                } else {
                    &["none"]
                };
                let samplers: &[&'static str] = if matches!(algo, "rge-vae" | "rge-rfvae") {
                    &["kde", "gaussian"]
                } else {
                    &["kde"]
                };
                for (iv, &variant) in variants.iter().enumerate() {
                    for (is, &sampler) in samplers.iter().enumerate() {
                        let f = efr - 0.3 + 0.15 * j as f64 + 0.2 * k as f64
                            - 0.2 * iv as f64
                            - 0.1 * is as f64;
                        v.push(Cond {
                            env,
                            algo,
                            sampler,
                            latents: l,
                            variant,
                            final_klc: f,
                        });
                    }
                }
            }
        }
    }
    v
}

fn write(path: &Path, df: &mut DataFrame) {
    let mut f = File::create(path).unwrap();
    ParquetWriter::new(&mut f).finish(df).unwrap();
}

fn iterations(algo: &str) -> Option<i64> {
    match algo {
        "rge-ae" => Some(2000),
        "rge-vae" => Some(1000),
        "rge-rfvae" => Some(500),
        _ => None,
    }
}

fn write_store(root: &Path) {
    write_campaign(&root.join("paper"), &conditions(), 5, None);
    // The budget campaigns: RGE-VAE faithful, KDE, 10 latents on ArmBall, 3 seeds, better with
    // more iterations.
    for (it, d) in [(300, 0.4), (1000, 0.0), (3000, -0.2), (10000, -0.3)] {
        let c = Cond {
            env: "armball",
            algo: "rge-vae",
            sampler: "kde",
            latents: 10,
            variant: "faithful",
            final_klc: 4.73 + d,
        };
        write_campaign(&root.join(format!("budget-vae-{it}")), &[c], 3, Some(it));
    }
}

fn write_campaign(dir: &Path, conds: &[Cond], reps: i64, budget: Option<i64>) {
    std::fs::create_dir_all(dir).unwrap();
    for c in conds {
        let kmax = if c.env == "armball" {
            756f64.ln()
        } else {
            22680f64.ln()
        };
        for seed in 0..reps {
            let id = format!(
                "{}.{}.{}.{}.{}.s{seed}",
                c.env, c.algo, c.sampler, c.latents, c.variant
            );
            let mut rng = ChaCha8Rng::seed_from_u64(seed as u64 * 7919 + id.len() as u64);
            let off: f64 = rng.random_range(-0.15..0.15);
            let epochs: Vec<i64> = (0..=50).map(|i| i * 100).collect();
            let rge = c.algo != "rpe";
            let n = epochs.len();
            let klc: Vec<f64> = epochs
                .iter()
                .map(|&e| {
                    let f = c.final_klc + off;
                    f + (kmax - f) * (-(e as f64) / 700.0).exp()
                })
                .collect();
            let n_out: Vec<i64> = epochs.iter().map(|&e| e + i64::from(rge)).collect();
            let moved_frac = if rge { 0.35 } else { 0.02 };
            let n_moved: Vec<i64> = n_out
                .iter()
                .map(|&o| (o as f64 * moved_frac) as i64)
                .collect();
            let cov: Vec<f64> = klc.iter().map(|k| (1.0 - k / kmax).max(0.0)).collect();
            let mut df = df!(
                "run_id" => vec![id.as_str(); n],
                "env" => vec![c.env; n],
                "algo" => vec![c.algo; n],
                "sampler" => vec![c.sampler; n],
                "latents" => vec![c.latents; n],
                "variant" => vec![c.variant; n],
                "seed" => vec![seed; n],
                "epoch" => epochs,
                "n_outcomes" => n_out,
                "klc" => klc,
                "n_moved" => n_moved,
                "coverage" => cov,
            )
            .unwrap();
            write(&dir.join(format!("{id}.parquet")), &mut df);

            let oe: Vec<i64> = if rge {
                (0..=5000).collect()
            } else {
                (1..=5000).collect()
            };
            let m = oe.len();
            let (mut x, mut y, mut mv, mut ang) = (vec![], vec![], vec![], vec![]);
            for _ in 0..m {
                let moved = rng.random_range(0.0..1.0) < moved_frac;
                if moved {
                    let r: f64 = rng.random_range(0.0f64..1.0).sqrt() * 0.98;
                    let a: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                    x.push(r * a.cos());
                    y.push(r * a.sin());
                } else {
                    x.push(0.6);
                    y.push(0.6);
                }
                mv.push(moved);
                ang.push((c.env == "armarrow").then(|| rng.random_range(-1.0..1.0)));
            }
            let mut odf = df!(
                "run_id" => vec![id.as_str(); m],
                "index" => (0..m as i64).collect::<Vec<_>>(),
                "epoch" => oe,
                "x" => x,
                "y" => y,
                "angle" => ang,
                "moved" => mv,
            )
            .unwrap();
            write(&dir.join(format!("{id}.outcomes.parquet")), &mut odf);
            let mut manifest = serde_json::json!({
                "run_id": id, "profile": "demo", "git_revision": "0000000", "toolchain": "rustc 1.95.0",
                "threads": 2, "host": "demo", "wall_s": 600.0 + 10.0 * seed as f64,
                "reduced_budget": false, "variant": c.variant,
            });
            if let Some(it) = budget.or_else(|| iterations(c.algo)) {
                let l = c.algo.trim_start_matches("rge-");
                let losses: Vec<(i64, f64)> = (0..=it / 100)
                    .map(|i| (i * 100, 400.0 + 3000.0 * (-(i as f64) / 3.0).exp()))
                    .collect();
                manifest.as_object_mut().unwrap().insert(
                    "train".into(),
                    serde_json::json!({
                        "config": {"iterations": it, "hidden": [512, 256], "batch": 100,
                                   "lr": 0.001, "log_every": 100, "warmup": 100},
                        "losses": losses,
                        "key": format!("{}-{l}-{}-{}-{seed}", c.env, c.latents, c.variant),
                    }),
                );
                manifest
                    .as_object_mut()
                    .unwrap()
                    .insert("learner".into(), l.into());
                manifest
                    .as_object_mut()
                    .unwrap()
                    .insert("reduced_budget".into(), true.into());
            }
            manifest["env"] = c.env.into();
            common::complete_manifest(&mut manifest, dir);
            common::write_conventional_record(dir);
            std::fs::write(dir.join(format!("{id}.json")), manifest.to_string()).unwrap();
        }
    }
}

#[test]
#[ignore = "paper-sized demo; run with --ignored (set UGL_REPORT_DEMO_OUT to keep the output)"]
fn paper_sized_demo_renders() {
    let tmp = tempfile::tempdir().unwrap();
    let root: PathBuf = std::env::var_os("UGL_REPORT_DEMO_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| tmp.path().to_path_buf());
    let results = root.join("results");
    write_store(&results);
    let mut opts = ReportOptions::new(results, root.join("report"));
    opts.paper_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper");
    let t = std::time::Instant::now();
    let s = render_report(&opts).unwrap();
    eprintln!(
        "rendered {} runs, {} files in {:?}",
        s.n_runs,
        s.files.len(),
        t.elapsed()
    );
    assert_eq!(s.n_main_runs, 48 * 5);
    assert_eq!(s.n_runs, 48 * 5 + 4 * 3);
}
