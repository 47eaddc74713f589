//! Campaigns and the neural sections, end to end on small synthetic stores written with polars:
//! the main campaign against the `budget-*` ones and the unused ones, the missing-main-campaign
//! error, the faithful-vs-corrected paired differences, the budget section's iterations (read from
//! the manifests), and byte-identical renders.

mod common;

use std::fs::File;
use std::path::{Path, PathBuf};

use polars::prelude::*;
use ugl_report::{ReportError, ReportOptions, render_report};

const EPOCHS: [i64; 6] = [0, 100, 200, 300, 400, 500];

/// One synthetic run.
#[derive(Debug, Clone)]
struct Spec {
    env: &'static str,
    algo: &'static str,
    sampler: &'static str,
    latents: i64,
    variant: &'static str,
    seed: i64,
    /// Final KLC = kmax − drop (falls linearly over the epochs).
    drop: f64,
    /// `train.config.iterations` (neural runs only).
    iterations: Option<i64>,
    /// What the curve file's `variant` column holds; `None`: the variant (ugl-bench wrote `none`).
    curve_variant: Option<&'static str>,
}

fn spec(env: &'static str, algo: &'static str, seed: i64, drop: f64) -> Spec {
    let (sampler, latents) = match algo {
        "rpe" => ("none", 0),
        "rge-efr" => ("uniform", 0),
        _ => ("kde", 10),
    };
    Spec {
        env,
        algo,
        sampler,
        latents,
        variant: "none",
        seed,
        drop,
        iterations: None,
        curve_variant: None,
    }
}

#[allow(clippy::too_many_arguments)]
fn neural(
    env: &'static str,
    algo: &'static str,
    sampler: &'static str,
    latents: i64,
    variant: &'static str,
    seed: i64,
    drop: f64,
    iterations: i64,
) -> Spec {
    Spec {
        env,
        algo,
        sampler,
        latents,
        variant,
        seed,
        drop,
        iterations: Some(iterations),
        curve_variant: None,
    }
}

fn kmax(env: &str) -> f64 {
    if env == "armball" {
        756f64.ln()
    } else {
        22680f64.ln()
    }
}

/// The run id as ugl-bench spells it: `armball.rge-vae.faithful.kde.l10.s3`.
fn run_id(s: &Spec) -> String {
    let mut id = format!("{}.{}", s.env, s.algo);
    if s.variant != "none" {
        id.push_str(&format!(".{}", s.variant));
    }
    if s.latents != 0 {
        id.push_str(&format!(".{}.l{}", s.sampler, s.latents));
    }
    format!("{id}.s{}", s.seed)
}

fn write_parquet(path: &Path, df: &mut DataFrame) {
    let mut f = File::create(path).unwrap();
    ParquetWriter::new(&mut f).finish(df).unwrap();
}

fn learner(algo: &str) -> Option<&str> {
    algo.strip_prefix("rge-")
        .filter(|l| ["ae", "vae", "rfvae"].contains(l))
}

fn write_run(dir: &Path, s: &Spec) {
    std::fs::create_dir_all(dir).unwrap();
    let id = run_id(s);
    let n = EPOCHS.len();
    let rge = s.algo != "rpe";
    let n_outcomes: Vec<i64> = EPOCHS.iter().map(|&e| e + i64::from(rge)).collect();
    let mut curve = df!(
        "run_id" => vec![id.as_str(); n],
        "env" => vec![s.env; n],
        "algo" => vec![s.algo; n],
        "sampler" => vec![s.sampler; n],
        "latents" => vec![s.latents; n],
        "variant" => vec![s.curve_variant.unwrap_or(s.variant); n],
        "seed" => vec![s.seed; n],
        "epoch" => EPOCHS.to_vec(),
        "n_outcomes" => n_outcomes.clone(),
        "klc" => EPOCHS.iter().map(|&e| kmax(s.env) - s.drop * e as f64 / 500.0).collect::<Vec<f64>>(),
        "n_moved" => n_outcomes.iter().map(|o| o / 3).collect::<Vec<i64>>(),
        "coverage" => EPOCHS.iter().map(|&e| e as f64 / 1000.0).collect::<Vec<f64>>(),
    )
    .unwrap();
    write_parquet(&dir.join(format!("{id}.parquet")), &mut curve);

    let epochs: Vec<i64> = if rge {
        (0..=500).collect()
    } else {
        (1..=500).collect()
    };
    let m = epochs.len();
    let x: Vec<f64> = (0..m)
        .map(|i| ((i * 37) % 200) as f64 / 100.0 - 1.0)
        .collect();
    let y: Vec<f64> = (0..m)
        .map(|i| ((i * 53 + s.seed as usize) % 140) as f64 / 100.0 - 0.7)
        .collect();
    let mut outcomes = df!(
        "run_id" => vec![id.as_str(); m],
        "index" => (0..m as i64).collect::<Vec<i64>>(),
        "epoch" => epochs,
        "x" => x,
        "y" => y,
        "angle" => (0..m).map(|i| (s.env == "armarrow").then_some((i % 20) as f64 / 10.0 - 1.0)).collect::<Vec<Option<f64>>>(),
        "moved" => (0..m).map(|i| i % 3 == 2).collect::<Vec<bool>>(),
    )
    .unwrap();
    write_parquet(&dir.join(format!("{id}.outcomes.parquet")), &mut outcomes);

    let mut manifest = serde_json::json!({
        "run_id": id, "env": s.env, "algo": s.algo, "sampler": s.sampler,
        "latents": s.latents, "variant": s.variant, "seed": s.seed,
        "campaign": dir.file_name().unwrap().to_string_lossy(),
        "profile": "test", "git_revision": "abc1234", "toolchain": "rustc 1.95.0",
        "threads": 1, "host": "testhost", "wall_s": 10.0, "reduced_budget": false,
        "budget_note": "",
    });
    if let (Some(l), Some(it)) = (learner(s.algo), s.iterations) {
        let m = manifest.as_object_mut().unwrap();
        m.insert("learner".into(), l.into());
        m.insert("reduced_budget".into(), true.into());
        m.insert(
            "budget_note".into(),
            format!("{it} training iterations; hidden layers [512, 256]").into(),
        );
        m.insert("fit_s".into(), 60.0.into());
        m.insert(
            "train".into(),
            serde_json::json!({
                "config": {"iterations": it, "hidden": [512, 256], "batch": 100, "lr": 0.001,
                           "variant": if s.variant == "corrected" { "corrected" } else { "faithful" },
                           "log_every": 100, "warmup": 100,
                           "init": if l == "ae" { "he" } else { "paper" }},
                "losses": [[0, 3400.0], [100, 600.0 + s.seed as f64], [200, 450.0], [300, 420.0]],
                "cache": "miss",
                // One training per (env, learner, latents, variant, seed): shared by the samplers.
                "key": format!("{}-{l}-{}-{}-{}-{it}", s.env, s.latents, s.variant, s.seed),
                // Seed 0 stays on the plateau, the others learn.
                "evidence": {"images": 2000, "plateau_loss": 440.0,
                             "reconstruction_loss": if s.seed == 0 { 430.0 } else { 88.0 },
                             "loss_fraction": if s.seed == 0 { 430.0 / 440.0 } else { 0.2 },
                             "trained": s.seed != 0, "untrained_fraction": 0.8},
            }),
        );
    }
    if s.latents > 0 {
        let linear = 0.5 + 0.1 * s.seed as f64;
        let mut q = serde_json::json!({"version": 2, "targets": ["x", "y"],
                               "linear_r2": [linear, linear], "knn_r2": [0.9, 0.9],
                               "linear_r2_mean": linear, "knn_r2_mean": 0.9,
                               "groups": [{"group": "position", "linear_r2": linear,
                                           "knn_r2": 0.9}],
                               "n_train": 100, "n_heldout": 50, "k": 10});
        // Seed 0 holds measure version 2, the others version 3 (trustworthiness 0.8 + 0.05 x
        // seed, continuity 0.95, against the position).
        if s.seed > 0 {
            q["version"] = 3.into();
            q["neighbourhoods"] = serde_json::json!([{"space": "position",
                "trustworthiness": 0.8 + 0.05 * s.seed as f64, "continuity": 0.95}]);
        }
        manifest
            .as_object_mut()
            .unwrap()
            .insert("latent_quality".into(), q);
    }
    common::complete_manifest(&mut manifest, dir);
    common::write_conventional_record(dir);
    std::fs::write(dir.join(format!("{id}.json")), manifest.to_string()).unwrap();
}

fn paper_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper")
}

fn opts(results: &Path, out: &Path) -> ReportOptions {
    let mut o = ReportOptions::new(results.to_path_buf(), out.to_path_buf());
    o.paper_dir = paper_dir();
    o.n_boot = 2_000;
    o
}

/// The faithful final KLC drop of a VAE run, and the corrected one: exactly 0.25 lower KLC.
fn vae_drop(seed: i64) -> f64 {
    [1.5, 2.0, 1.75][seed as usize]
}

/// A main campaign `paper` with baselines, RGE-AE, and RGE-VAE / RGE-RFVAE in both variants with
/// KDE and Gaussian goals on ArmBall (10 and 2 latents), 3 seeds; two budget campaigns and an
/// unused one.
fn neural_store(root: &Path) {
    let main = root.join("paper");
    // Goal-space figure data of one cell: a 3 x 3 lattice of positions inside the reachable
    // disk and its 2 latents (the middle column folded onto the first), and a reconstruction
    // image (copied as it is).
    let gs = main.join("goal_spaces");
    std::fs::create_dir_all(&gs).unwrap();
    let positions: Vec<[f64; 2]> = (0..9)
        .map(|k| [-0.5 + 0.5 * (k / 3) as f64, -0.5 + 0.5 * (k % 3) as f64])
        .collect();
    let latents: Vec<[f32; 2]> = positions
        .iter()
        .map(|p| [p[0].abs() as f32, p[1] as f32])
        .collect();
    std::fs::write(
        gs.join("armball.rge-vae.faithful.l2.s0.json"),
        serde_json::json!({
            "representation": "armball.rge-vae.faithful.l2.s0", "env": "armball",
            "algo": "rge-vae", "variant": "faithful", "latents": 2, "seed": 0, "grid": 3,
            "positions": positions, "grid_latents": latents,
            "reconstructions": "armball.rge-vae.faithful.l2.s0.reconstructions.png"
        })
        .to_string(),
    )
    .unwrap();
    std::fs::write(
        gs.join("armball.rge-vae.faithful.l2.s0.reconstructions.png"),
        b"not decoded by the report",
    )
    .unwrap();
    for seed in 0..3 {
        write_run(&main, &spec("armball", "rpe", seed, 0.2));
        write_run(
            &main,
            &spec("armball", "rge-efr", seed, 1.5 + 0.1 * seed as f64),
        );
        write_run(
            &main,
            &neural("armball", "rge-ae", "kde", 10, "none", seed, 1.6, 2000),
        );
        for latents in [10, 2] {
            for sampler in ["kde", "gaussian"] {
                for algo in ["rge-vae", "rge-rfvae"] {
                    let it = if algo == "rge-vae" { 1000 } else { 500 };
                    let d = vae_drop(seed) + if sampler == "gaussian" { 0.1 } else { 0.0 };
                    write_run(
                        &main,
                        &neural("armball", algo, sampler, latents, "faithful", seed, d, it),
                    );
                    write_run(
                        &main,
                        &neural(
                            "armball",
                            algo,
                            sampler,
                            latents,
                            "corrected",
                            seed,
                            d + 0.25,
                            it,
                        ),
                    );
                }
            }
        }
    }
    // Budget campaigns: the directory name says 300 / 3000, the manifests 1234 / 4321.
    for (dir, it, extra) in [
        ("budget-vae-300", 1234, 0.0),
        ("budget-vae-3000", 4321, 0.5),
    ] {
        for seed in 0..3 {
            write_run(
                &root.join(dir),
                &neural(
                    "armball",
                    "rge-vae",
                    "kde",
                    10,
                    "faithful",
                    seed,
                    vae_drop(seed) + extra,
                    it,
                ),
            );
        }
    }
    // An old campaign holding a run with the same id as one of the main campaign's.
    write_run(&root.join("baselines"), &spec("armball", "rpe", 0, 0.9));
    // A training-recipe campaign: three runs that pair with the main campaign's (0.3 lower final
    // KLC each) and one (seed 7) that does not.
    for seed in [0, 1, 2, 7] {
        write_run(
            &root.join("paper-long"),
            &neural(
                "armball",
                "rge-vae",
                "kde",
                10,
                "faithful",
                seed,
                vae_drop(seed.min(2)) + 0.3,
                4000,
            ),
        );
    }
}

fn read(out: &Path) -> String {
    std::fs::read_to_string(out.join("REPORT.md")).unwrap()
}

fn line<'a>(md: &'a str, starts: &str, contains: &str) -> &'a str {
    md.lines()
        .find(|l| l.starts_with(starts) && l.contains(contains))
        .unwrap_or_else(|| panic!("no line starting `{starts}` containing `{contains}` in\n{md}"))
}

#[test]
fn campaigns_are_separated_and_the_neural_sections_are_drawn() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    neural_store(&results);
    let out = tmp.path().join("out");
    let s = render_report(&opts(&results, &out)).unwrap();
    let n_main = 3 * (3 + 2 * 2 * 2 * 2);
    assert_eq!(s.n_main_runs, n_main);
    assert_eq!(s.n_runs, n_main + 6 + 4);
    assert_eq!(s.budget_campaigns, ["budget-vae-300", "budget-vae-3000"]);
    assert_eq!(s.unused_campaigns, ["baselines"]);
    assert_eq!(s.recipe_campaigns, ["paper-long"]);
    // 27 distinct trainings of 60 s (the KDE and Gaussian runs of a cell share one) and 57 runs
    // of 10 s exploration.
    let md = read(&out);
    let compute = line(&md, "- **Compute:**", "worker time");
    assert!(
        compute.contains("36.5 min of worker time")
            && compute.contains("27.0 min fitting 27 representations")
            && compute.contains("and 9.5 min exploring"),
        "{compute}"
    );
    // The leaderboard counts untrained runs (seed 0 of every neural cell), the claims say so.
    let lb = &md[md.find("## Leaderboard").expect("leaderboard")..];
    let row = lb
        .lines()
        .find(|l| l.contains("RGE-VAE (faithful)") && l.contains("| KDE |"))
        .expect("a VAE entry");
    assert!(row.contains("| **"), "{row}");
    let efr = lb.lines().find(|l| l.contains("| RGE-EFR |")).expect("EFR");
    assert!(efr.contains("| — |"), "{efr}");
    assert!(md.contains("AE, VAE and RFVAE runs** did not leave the mean-image plateau"));
    // The numbers behind the report, as CSV: one row per main-campaign run; every curve point.
    let finals = std::fs::read_to_string(out.join("data/final_by_seed.csv")).unwrap();
    let mut lines = finals.lines();
    assert!(
        lines.next().unwrap().starts_with(
            "campaign,env,algo,sampler,latents,variant,seed,exploration,epoch,final_klc"
        )
    );
    assert_eq!(lines.count(), n_main);
    let curves = std::fs::read_to_string(out.join("data/curves.csv")).unwrap();
    assert!(curves.lines().count() > 2 * n_main, "whole curves");
    // Three seeds per condition: the final tables and the budget tables warn.
    let budget = &md[md.find("## Training-budget sensitivity").unwrap()..];
    assert!(
        budget.contains("⚠ **Small samples**: as few as 3 seeds"),
        "{budget}"
    );
    let finals = &md[md.find("## Final KL-coverage").unwrap()..];
    let finals = &finals[..finals[3..].find("\n## ").unwrap()];
    assert!(finals.contains("⚠ **Small samples**"));
    // A non-paper init is a listed deviation.
    assert!(
        md.contains("weight init AE he instead of the paper's truncated normal"),
        "{}",
        &md[md.find("## Deviations").unwrap()..]
    );
    // The goal-space quality table: seed 0 of every neural cell is untrained.
    let q = &md[md
        .find("## Did the goal spaces learn?")
        .expect("quality section")..];
    let row = q
        .lines()
        .find(|l| l.starts_with("| ArmBall | RGE-VAE | faithful |"))
        .expect("a VAE row");
    // T / C: the mean over seeds 1 and 2 (seed 0 has no neighbourhoods).
    assert!(
        row.contains("**1 of 3**") && row.contains("| 0.600 | 0.900 | — | — | 0.875 / 0.950 |"),
        "{row}"
    );
    // Nine learned cells (AE-10; VAE and RFVAE, two variants, two sizes), seed 0 of each.
    assert!(
        q.contains("9 representations hold version 2 of the latent-quality measure"),
        "{q}"
    );
    assert!(q.contains("did not leave the plateau"), "{q}");
    let fig = |n: &str| out.join("figures").join(n);
    for name in [
        "klc_armball.svg",
        "fig4_vae_kde_vs_gaussian.svg",
        "rfvae_kde_vs_gaussian.svg",
        "variants.svg",
        "budget_vae.svg",
        "training_loss.svg",
        "outcomes_armball_rge-vae_kde_10_faithful.svg",
        "outcomes_armball_rge-vae_kde_10_corrected.svg",
        "outcomes_armball_rge-vae_gaussian_2_corrected.svg",
        "goal_space_armball_l2.svg",
        "recon_armball.rge-vae.faithful.l2.s0.png",
    ] {
        assert!(fig(name).is_file(), "{name}");
        assert!(s.files.contains(&fig(name)), "{name}");
    }
    assert_eq!(
        std::fs::read(fig("recon_armball.rge-vae.faithful.l2.s0.png")).unwrap(),
        b"not decoded by the report"
    );
    // The training-loss panels mark the plateau (the fixture's mean-image loss, 440).
    let loss = std::fs::read_to_string(fig("training_loss.svg")).unwrap();
    assert!(loss.contains("(plateau 440)"), "no plateau value");
    assert!(
        loss.contains("mean-image loss (the plateau"),
        "no plateau line in the legend"
    );
    // The lattice: 3 lines of constant x and 3 of constant y, in the key and in the goal space
    // (the axes and the key's disk are black and grey).
    let mesh = std::fs::read_to_string(fig("goal_space_armball_l2.svg")).unwrap();
    let lattice = mesh
        .lines()
        .filter(|l| {
            l.contains("<polyline")
                && !l.contains("stroke=\"#000000\"")
                && !l.contains("stroke=\"#888888\"")
        })
        .count();
    assert_eq!(lattice, 12, "{mesh}");
    assert!(md.contains("![ArmBall, 2 latents: the lattice of reachable object positions (first panel, the key: lines of constant x red, of constant y blue, darker towards +1) in each goal space of seed 0](figures/goal_space_armball_l2.svg)"));
    assert!(md.contains("| ArmBall, RGE-VAE (faithful), 2 latents (seed 0) | ![ArmBall, RGE-VAE (faithful), 2 latents (seed 0): held-out images (top) and their reconstructions (bottom)](figures/recon_armball.rge-vae.faithful.l2.s0.png) |"), "{}", &md[md.find("### What the goal spaces").unwrap()..]);

    let md = read(&out);
    assert!(
        md.contains(
            "- **Campaigns:** main `paper` (57 runs: the paper's figures and table); \
             training-budget sensitivity `budget-vae-300` (3 runs), `budget-vae-3000` (3 runs); \
             training recipes `paper-long` (4 runs); present but not used: `baselines` (1 run)."
        ),
        "{md}"
    );
    // The training-recipe section: the recipe against the main campaign's, and the paired cell
    // (seed 0 untrained on both sides; every training loss above 0.8 x 440 after the warm-up;
    // each recipe run 0.3 lower, i.e. better).
    let recipe = &md[md.find("## Training recipes").expect("recipe section")..];
    assert!(
        recipe.contains("4 complete runs; 1 without a `paper` run to pair with."),
        "{recipe}"
    );
    assert!(
        recipe.contains(
            "- **RGE-VAE**: 4900-512-256, init `paper`, 4000 iterations, learning rate 0.001, \
             warm-up 100 (`paper`: 4900-512-256, init `paper`, 1000 iterations, learning rate \
             0.001, warm-up 100)."
        ),
        "{recipe}"
    );
    let row = line(recipe, "| ArmBall | RGE-VAE | kde | faithful | 10 |", "");
    assert_eq!(
        row,
        "| ArmBall | RGE-VAE | kde | faithful | 10 | 3 | 1/3 / 1/3 | 0.20 / 0.20 | never (3) / \
         never (3) | 0.90 / 0.90 | 4.578 / 4.878 | -0.300 (-0.300 to -0.300) | 3/3 | \
         0.051 / 0.051 | 0.500 / 0.500 | inf / inf |",
        "final KLC: ln 756 minus the mean over seeds 0-2 of vae_drop (+ 0.3); the validated \
         measures of the synthetic runs (their moved outcomes too few for a finite KLC)"
    );
    assert!(recipe.contains("Over all 3 pairs: untrained 1 of 3 `paper-long` runs against 1 of 3 `paper` runs; mean paired Δ final KLC -0.300; the `paper-long` run ends with the lower (better) KL-coverage in 3 of 3."), "{recipe}");
    // Display names with variants; 3 seeds on every row.
    assert!(
        md.contains("| RGE-VAE (corrected), Gaussian goals, 2 latents † | 3 |"),
        "{md}"
    );
    assert!(
        md.contains("| RGE-AE, KDE goals, 10 latents † | 3 |"),
        "{md}"
    );
    // The main RPE is the main campaign's (drop 0.2), not the unused campaign's copy (drop 0.9).
    let rpe = line(&md, "| RPE", "± 0.000");
    assert!(
        rpe.contains(&format!("{:.3}", kmax("armball") - 0.2)),
        "{rpe}"
    );

    // Faithful vs corrected: the corrected runs cover exactly 0.25 better on every seed.
    let row = line(&md, "| ArmBall, 10 latents | RGE-VAE | KDE |", "");
    assert!(
        row.contains("| -0.250 | [-0.250, -0.250] | 3 (0–2) |"),
        "{row}"
    );
    let row = line(&md, "| ArmBall, 2 latents | RGE-RFVAE | Gaussian |", "");
    assert!(
        row.contains("| -0.250 | [-0.250, -0.250] | 3 (0–2) |"),
        "{row}"
    );
    assert!(md.contains("*Faithful* reproduces the original code's behaviour, defects included"));

    // Figure 4 table: ArmBall 10 latents, the paper's 4.25 / 3.84.
    let f4 = line(&md, "| ArmBall, 10 latents |", "4.25 / 3.84");
    let mean = kmax("armball") - (1.5 + 2.0 + 1.75) / 3.0;
    assert!(f4.contains(&format!("| {mean:.3} ± 0.250 (n=3) |")), "{f4}");

    // Budgets from the manifests, not the directory names.
    assert!(md.contains("| 1234 | `budget-vae-300` | 3 (0–2) |"), "{md}");
    // VAE drops 1.5, 2.0, 1.75 against RGE-EFR's 1.5, 1.6, 1.7: 0.15 lower KLC on average.
    let row = line(&md, "| 1234 |", "budget-vae-300");
    assert!(
        row.trim_end().ends_with("|") && row.contains("| -0.150 ["),
        "{row}"
    );
    assert!(
        md.contains("| 4321 | `budget-vae-3000` | 3 (0–2) |"),
        "{md}"
    );
    assert!(md.contains("| 1000 | `paper` (main) | 3 (0–2) |"), "{md}");
    assert!(!md.contains("| 300 |") && !md.contains("| 3000 |"));
    assert!(
        md.contains("Reference levels on ArmBall (main campaign, mean final KL-coverage): RGE-EFR")
    );

    // Training budgets table and the deviation line.
    assert!(
        md.contains("| VAE | ours | 1000 | [512, 256] | 100 | 1e-3 | — | 24 (12) | 60.0 s |"),
        "{md}"
    );
    assert!(
        md.contains(
            "| | paper | 100000 | [1200, 1200] | 100 | 1e-3 (Adam) | — | 1 per condition | |"
        ),
        "{md}"
    );
    assert!(
        md.contains("| RFVAE | ours | 500 | [512, 256] | 100 | 1e-3 | 100 | 24 (12) |"),
        "{md}"
    );
    assert!(md.contains("**Neural training budgets differ from the paper's**"));
    assert!(
        md.contains("VAE 1000 (1.0%) of the paper's 100000 iterations"),
        "{md}"
    );
    assert!(md.contains("(figures/training_loss.svg)"));
}

#[test]
fn rendering_the_neural_store_twice_gives_identical_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    neural_store(&results);
    let read_all = |dir: &Path| {
        let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir.join("figures"))
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                (p.display().to_string(), std::fs::read(&p).unwrap())
            })
            .map(|(p, b)| (p.rsplit('/').next().unwrap().to_string(), b))
            .collect();
        for f in [
            "REPORT.md",
            "data/final_by_seed.csv",
            "data/curves.csv",
            "data/discovery_by_run.csv",
            "data/claims.csv",
            "data/validity.csv",
            "data/leaderboard.csv",
            "outcomes.md",
            "files.txt",
        ] {
            v.push((f.into(), std::fs::read(dir.join(f)).unwrap()));
        }
        v.sort();
        v
    };
    let (o1, o2) = (tmp.path().join("o1"), tmp.path().join("o2"));
    let s1 = render_report(&opts(&results, &o1)).unwrap();
    render_report(&opts(&results, &o2)).unwrap();
    let a = read_all(&o1);
    assert_eq!(a.len(), s1.files.len());
    assert_eq!(a, read_all(&o2));
    if let Some(keep) = std::env::var_os("UGL_REPORT_TEST_KEEP") {
        // UGL_REPORT_TEST_KEEP=/tmp/neural cargo test -p ugl-report --test campaigns
        render_report(&opts(&results, Path::new(&keep))).unwrap();
    }
}

#[test]
fn a_missing_main_campaign_is_an_error_listing_the_campaigns_found() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    write_run(
        &results.join("budget-vae-300"),
        &spec("armball", "rpe", 0, 0.2),
    );
    write_run(&results.join("baselines"), &spec("armball", "rpe", 0, 0.2));
    write_run(&results, &spec("armball", "rge-efr", 0, 1.0));
    std::fs::create_dir_all(results.join("models")).unwrap(); // no run files: not a campaign
    let err = render_report(&opts(&results, &tmp.path().join("out"))).unwrap_err();
    match &err {
        ReportError::MissingMainCampaign { main, found, .. } => {
            assert_eq!(main, "paper");
            assert_eq!(found, &["(top level)", "baselines", "budget-vae-300"]);
        }
        other => panic!("unexpected {other:?}"),
    }
    let msg = err.to_string();
    assert!(
        msg.contains("main campaign `paper` not found")
            && msg.contains("campaigns found: (top level), baselines, budget-vae-300"),
        "{msg}"
    );
    // Another main campaign works, and the top level can be one.
    let mut o = opts(&results, &tmp.path().join("out"));
    o.main_campaign = "baselines".into();
    let s = render_report(&o).unwrap();
    assert_eq!(s.unused_campaigns, [""]);
    assert_eq!(s.budget_campaigns, ["budget-vae-300"]);
    o.main_campaign = String::new();
    assert_eq!(render_report(&o).unwrap().n_main_runs, 1);
}

#[test]
fn the_variant_comes_from_the_manifest_when_the_curve_file_says_none() {
    // ugl-bench's curve files wrote `variant = none` for every run: the faithful and corrected
    // runs must still be two conditions of 2 seeds each, not one of 4 runs with repeated seeds.
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let main = results.join("paper");
    for seed in 0..2 {
        write_run(&main, &spec("armball", "rge-efr", seed, 1.5));
        for (variant, d) in [("faithful", 1.0), ("corrected", 1.5)] {
            let mut s = neural("armball", "rge-vae", "kde", 10, variant, seed, d, 1000);
            s.curve_variant = Some("none");
            write_run(&main, &s);
        }
    }
    let out = tmp.path().join("out");
    render_report(&opts(&results, &out)).unwrap();
    let md = read(&out);
    assert!(
        md.contains("| RGE-VAE (faithful), KDE goals, 10 latents † | 2 |"),
        "{md}"
    );
    assert!(
        md.contains("| RGE-VAE (corrected), KDE goals, 10 latents † | 2 |"),
        "{md}"
    );
    let row = line(&md, "| ArmBall, 10 latents | RGE-VAE | KDE |", "");
    assert!(
        row.contains("| -0.500 | [-0.500, -0.500] | 2 (0, 1) |"),
        "{row}"
    );
    // No budget campaign and no Gaussian goals: said so, no figure.
    assert!(md.contains("No `budget-*` campaign in the store"));
    assert!(
        md.contains("No RGE-VAE run with Gaussian goals in the main campaign `paper`: no figure.")
    );
    assert!(!out.join("figures/budget_vae.svg").exists());
    assert!(!out.join("figures/fig4_vae_kde_vs_gaussian.svg").exists());
}

#[test]
fn stale_neural_figures_are_removed() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    neural_store(&results);
    let out = tmp.path().join("out");
    render_report(&opts(&results, &out)).unwrap();
    assert!(out.join("figures/budget_vae.svg").is_file());
    for dir in ["budget-vae-300", "budget-vae-3000"] {
        std::fs::remove_dir_all(results.join(dir)).unwrap();
    }
    render_report(&opts(&results, &out)).unwrap();
    assert!(!out.join("figures/budget_vae.svg").exists());
    assert!(out.join("figures/variants.svg").is_file());
}

/// A `compare-*` campaign (what `ugl compare --learner NAME --command ...` writes): its
/// `rge-external` runs are ranked in the leaderboard under the learner's name and drawn in the
/// KL-coverage figure; the main campaign's claims are evaluated and counted at the top.
#[test]
fn a_compare_campaign_is_ranked_in_the_leaderboard_and_drawn() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    neural_store(&results);
    let cmp = results.join("compare-random-projection");
    for (seed, latents) in (0..3).flat_map(|s| [(s, 10), (s, 2)]) {
        let mut s = spec("armball", "rge-external", seed, 2.5);
        s.latents = latents;
        write_run(&cmp, &s);
        // The learner's name, as the runner records it for an external program.
        let id = run_id(&s);
        let path = cmp.join(format!("{id}.json"));
        let mut m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        m["learner"] = "random-projection".into();
        std::fs::write(&path, m.to_string()).unwrap();
    }
    let out = tmp.path().join("out");
    let s = render_report(&opts(&results, &out)).unwrap();
    assert_eq!(s.unused_campaigns, ["baselines"]);
    let md = read(&out);
    // The largest drop of the store: ranked first, marked new, with its campaign.
    let row = line(&md, "| 1 [", "RGE-RANDOM-PROJECTION");
    assert!(
        row.contains("(new)") && row.contains("compare-random-projection"),
        "{row}"
    );
    // A compare campaign has no RPE of its own: "at RPE level" uses the main campaign's.
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    assert_eq!(cells[8], "**6**", "at RPE level: {row}");
    assert!(cells[12].ends_with('%'), "coverage per environment: {row}");
    // Its rank comes with an interval; its per-task IQMs are in their own table.
    assert!(cells[1].starts_with("1 [1, "), "rank interval: {row}");
    assert!(md.contains("**Per task**"));
    assert!(md.contains("1 `compare-*` campaign in the store"));
    // Its one-page summary: rank, failures, coverage, latent R², PoI against each algorithm.
    let page_path = out.join("compare_compare-random-projection.md");
    assert!(s.files.contains(&page_path));
    let page = std::fs::read_to_string(&page_path).unwrap();
    assert!(page.contains("**rank 1 of "), "{page}");
    assert!(
        page.contains("failed explorations (fewer than twice RPE's object moves): 6 runs"),
        "{page}"
    );
    assert!(
        page.contains("  - ArmBall, 10 latents: position 0.900"),
        "{page}"
    );
    let efr = page
        .lines()
        .find(|l| l.starts_with("| RGE-EFR |"))
        .expect("PoI vs EFR");
    assert!(efr.ends_with("| 2 |"), "{efr}");
    assert!(page.lines().any(|l| l.starts_with("| RPE |")), "{page}");
    assert!(md.contains(
        "[`compare_compare-random-projection.md`](compare_compare-random-projection.md)"
    ));
    let svg = std::fs::read_to_string(out.join("figures/klc_armball.svg")).unwrap();
    assert!(
        svg.contains("RGE-RANDOM-PROJECTION"),
        "the new learner is not in the figure"
    );
    // Claims: the committed claims file is evaluated, and the verdicts are counted.
    assert!(md.contains("## The paper's claims"));
    // 22 of the paper's claims in the headline, counted on the validated measures first; our
    // 15 findings apart.
    let summary = line(
        &md,
        "**The paper's claims**",
        "22 evaluated on these results",
    );
    assert!(summary.contains("reproduced"), "{summary}");
    assert!(
        summary.find("On the measures of discovery that pass the validity check")
            < summary.find("On the paper's own measures"),
        "{summary}"
    );
    assert!(
        summary.contains("(15 findings of ours are listed apart)"),
        "{summary}"
    );
    assert!(md.contains("| `rfvae-worse` |"));
    let ours = md
        .find("### Our findings (not claims of the paper)")
        .unwrap();
    assert!(md[ours..].contains("| `rfvae-worse-corrected` |"));
    // Each claim is checked on the paper's own values.
    assert!(md.contains("*The paper's own numbers*") && md.contains("| the paper's own numbers |"));
}

#[test]
fn a_malformed_claims_file_is_an_error_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    write_run(&results.join("paper"), &spec("armball", "rpe", 0, 0.2));
    let paper = tmp.path().join("paper");
    std::fs::create_dir_all(&paper).unwrap();
    std::fs::write(
        paper.join("claims.toml"),
        "[settings]\nconfidence = 2.0\nmargin = 0.2\n",
    )
    .unwrap();
    let mut o = opts(&results, &tmp.path().join("out"));
    o.paper_dir = paper.clone();
    let msg = render_report(&o).unwrap_err().to_string();
    assert!(
        msg.contains("claims.toml") && msg.contains("settings.confidence"),
        "{msg}"
    );
    // No claims file at all: the report says so and renders.
    std::fs::remove_file(paper.join("claims.toml")).unwrap();
    render_report(&o).unwrap();
    let md = read(&tmp.path().join("out"));
    assert!(md.contains("No claims file at"), "{md}");
}

/// A `validation` campaign (held-out repetitions) replaces the claims' runs in the validity
/// check, and the report says so; without one, it says the check uses the claims' runs.
#[test]
fn a_validation_campaign_is_what_the_validity_check_reads() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    neural_store(&results);
    let out = tmp.path().join("out");
    render_report(&opts(&results, &out)).unwrap();
    let md = read(&out);
    assert!(md.contains("**the same runs carry the claims**"), "{md}");
    let before = std::fs::read_to_string(out.join("data/validity.csv")).unwrap();
    // The main campaign's runs, copied as a held-out campaign of their own.
    let val = results.join("paper-validation");
    std::fs::create_dir_all(&val).unwrap();
    for e in std::fs::read_dir(results.join("paper")).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() && p.file_name().unwrap() != ugl_types::RECORD_FILE {
            std::fs::copy(&p, val.join(p.file_name().unwrap())).unwrap();
        }
    }
    common::write_record(&val, ugl_types::CampaignRole::Validation, Some("paper"));
    let out2 = tmp.path().join("out2");
    let s = render_report(&opts(&results, &out2)).unwrap();
    assert!(!s.unused_campaigns.contains(&"paper-validation".to_string()));
    let md = read(&out2);
    assert!(
        md.contains("Runs of the held-out validation campaign `paper-validation`"),
        "{md}"
    );
    assert!(!md.contains("**the same runs carry the claims**"));
    // It is listed among the campaigns read, and under *How to reproduce*.
    assert!(
        md.contains("the validity check's held-out repetitions `paper-validation` ("),
        "{md}"
    );
    assert!(
        md.contains("make campaign PROFILE=paper-validation\n"),
        "{md}"
    );
    // Only the validation campaign's runs are checked: the main campaign's copies give the same
    // lines, without the recipe and compare campaigns' runs.
    let after = std::fs::read_to_string(out2.join("data/validity.csv")).unwrap();
    assert_eq!(before.lines().next(), after.lines().next());
    let runs = |csv: &str, col: usize| -> usize {
        csv.lines()
            .skip(1)
            .map(|l| l.split(',').nth(col).unwrap().parse::<usize>().unwrap())
            .sum()
    };
    assert!(runs(&after, 3) > 0 && runs(&after, 4) > 0, "{after}");
    // Every row has the same 13 fields (no comma inside a field).
    assert!(after.lines().all(|l| l.split(',').count() == 13), "{after}");
    // The recipe campaign's untrained twins are no longer read: fewer control runs.
    assert!(runs(&after, 4) < runs(&before, 4), "{before}\n{after}");
}
