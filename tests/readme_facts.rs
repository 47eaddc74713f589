//! The numbers the README states about the committed results are those of the committed data
//! and of the committed report: each sentence is found by its wording, its numbers are read and
//! compared with what the manifests and `report/out/REPORT.md` say. A README edited without the
//! data, or data committed without the README, fails here. The same holds for the tables the
//! docs generate from committed data (the convolutional sweep's, in `docs/neural.md`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The README with its line breaks folded into spaces (a sentence may wrap anywhere).
fn readme() -> String {
    read("README.md")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// The words standing for the `{}` of `template` where `text` holds it: the template's first
/// literal part must occur exactly once in `text`, and each `{}` takes everything up to the next
/// literal part (a template ending in `{}` takes the rest of the line).
fn captures(text: &str, template: &str) -> Vec<String> {
    let parts: Vec<&str> = template.split("{}").collect();
    let head = parts[0];
    assert_eq!(
        text.matches(head).count(),
        1,
        "{head:?} should occur once in the text"
    );
    let mut rest = &text[text.find(head).unwrap() + head.len()..];
    let mut out = Vec::new();
    for part in &parts[1..] {
        let end = if part.is_empty() {
            rest.find('\n').unwrap_or(rest.len())
        } else {
            rest.find(part)
                .unwrap_or_else(|| panic!("{part:?} not found after {head:?}"))
        };
        out.push(rest[..end].to_string());
        rest = &rest[end + part.len()..];
    }
    out
}

fn number(word: &str) -> usize {
    match word {
        "none" | "no" => 0,
        w => w.parse().unwrap_or_else(|_| panic!("not a number: {w}")),
    }
}

/// The manifests of a campaign directory (every `*.json` but the campaign's own files).
fn manifests(dir: &str) -> Vec<serde_json::Value> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(root().join(dir)).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if p.extension().is_some_and(|x| x == "json") && name != "campaign.json" {
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            if v.get("run_id").is_some() {
                out.push(v);
            }
        }
    }
    out
}

#[test]
fn the_main_campaigns_size_version_and_training_are_those_of_its_manifests() {
    let text = readme();
    let c = captures(
        &text,
        "`data/results/paper`**, what `make report` renders: the paper's matrix with its controls \
         ({} conditions), {} repetitions x {} exploration replicates, {} runs at **results \
         version {}**, with trained 4900-1200-1200 networks ({} of the {} trainings left the \
         mean-image plateau;",
    );
    let runs = manifests("data/results/paper");
    assert_eq!(runs.len(), number(&c[3]), "runs");
    let conditions: BTreeSet<String> = runs
        .iter()
        .map(|m| {
            format!(
                "{}/{}/{}/{}/{}",
                m["env"], m["algo"], m["sampler"], m["latents"], m["variant"]
            )
        })
        .collect();
    assert_eq!(conditions.len(), number(&c[0]), "conditions");
    let seeds: BTreeSet<String> = runs.iter().map(|m| m["seed"].to_string()).collect();
    assert_eq!(seeds.len(), number(&c[1]), "repetitions");
    assert_eq!(runs.len(), conditions.len() * seeds.len() * number(&c[2]));
    for m in &runs {
        assert_eq!(
            m["crate_versions"]["results_version"].as_u64(),
            Some(number(&c[4]) as u64),
            "{}",
            m["run_id"]
        );
    }
    // A training is shared by the runs that differ only in their goal sampler or exploration
    // replicate.
    let mut trainings: BTreeMap<String, bool> = BTreeMap::new();
    for m in &runs {
        if let Some(trained) = m["train"]["evidence"]["trained"].as_bool() {
            let key = format!(
                "{}/{}/{}/{}/{}",
                m["env"], m["algo"], m["latents"], m["variant"], m["seed"]
            );
            let before = trainings.insert(key, trained);
            assert!(before.is_none_or(|b| b == trained), "{}", m["run_id"]);
        }
    }
    let left = trainings.values().filter(|t| **t).count();
    assert_eq!(left, number(&c[5]), "trainings that left the plateau");
    assert_eq!(trainings.len(), number(&c[6]), "trainings");
}

#[test]
fn the_claims_counts_are_those_of_the_committed_report() {
    let text = readme();
    let v = captures(
        &text,
        "on the validated measures: {} of the {} claims reproduced, {} not reproduced, {} \
         undecided, {} with no validated measure.",
    );
    let c = captures(
        &text,
        "On the paper's own measures: {} reproduced, {} not reproduced, {} inconclusive at {} \
         repetitions.",
    );
    let report = read("report/out/REPORT.md");
    let r = captures(
        &report,
        "**The paper's claims** ([details](#the-papers-claims)), {} evaluated on these results ({}). \
         On the measures of discovery that pass the validity check ({}): {} reproduced, {} not \
         reproduced, {} undecided ({}); {} claims have no validated measure ({}). On the \
         paper's own measures (KL-coverage, episodes that moved the object){}: {} reproduced, {} \
         not reproduced, {} undecided (",
    );
    assert_eq!(number(&v[1]), number(&r[0]), "claims");
    assert_eq!(
        number(&v[0]),
        number(&r[3]),
        "reproduced on the validated measures"
    );
    assert_eq!(
        number(&v[2]),
        number(&r[4]),
        "not reproduced on the validated measures"
    );
    assert_eq!(
        number(&v[3]),
        number(&r[5]),
        "undecided on the validated measures"
    );
    assert_eq!(number(&v[4]), number(&r[7]), "no validated measure");
    assert_eq!(number(&c[0]), number(&r[10]), "reproduced");
    assert_eq!(number(&c[1]), number(&r[11]), "not reproduced");
    assert_eq!(number(&c[2]), number(&r[12]), "inconclusive");
    // The main claim on ArmBall: the README's verdicts are the Findings'.
    let main = captures(
        &text,
        "is **{}** on ArmBall on the validated measures, while final KL-coverage calls it {}.",
    );
    let f = captures(
        &report,
        "- **Learned goal spaces vs RGE-EFR on ArmBall (the paper's main claim)** \
         ([`ugl-vs-efr-armball`](#the-papers-claims)): **{}** on the measures that pass the \
         validity check: {}The same claim is **{}** on the final KLC",
    );
    assert_eq!(
        main[0], f[0],
        "the main claim on ArmBall, validated measures"
    );
    assert_eq!(main[1], f[2], "the main claim on ArmBall, final KLC");
    let seeds: BTreeSet<String> = manifests("data/results/paper")
        .iter()
        .map(|m| m["seed"].to_string())
        .collect();
    assert_eq!(number(&c[3]), seeds.len(), "repetitions");

    let contradicted = captures(&text, "which contradict {} of them");
    let line = captures(
        &report,
        "gives no value for these comparisons. Contradicted: {}.\n",
    );
    let ids = if line[0] == "none" {
        0
    } else {
        line[0].matches('`').count() / 2
    };
    assert_eq!(number(&contradicted[0]), ids, "contradicted by the paper");
}

#[test]
fn the_runs_discovery_records_and_kept_outcomes_are_counted_right() {
    let text = readme();
    let c = captures(
        &text,
        "exploration replicate 0: {} of the {} runs; all {} record their measures)",
    );
    let runs = manifests("data/results/paper");
    assert_eq!(runs.len(), number(&c[1]), "runs");
    let recorded = runs.iter().filter(|m| m.get("discovery").is_some()).count();
    assert_eq!(recorded, number(&c[2]), "runs with a discovery record");
    let kept: Vec<&serde_json::Value> = runs
        .iter()
        .filter(|m| {
            let id = m["run_id"].as_str().unwrap();
            root()
                .join("data/results/paper")
                .join(format!("{id}.outcomes.parquet"))
                .exists()
        })
        .collect();
    assert_eq!(kept.len(), number(&c[0]), "kept outcomes files");
    for m in kept {
        assert!(
            // Replicate 0 is written without its `exploration` (its identity predates replicates).
            m["seed"].as_u64().unwrap() <= 2 && m["exploration"].as_u64().unwrap_or(0) == 0,
            "{}: an outcomes file outside repetitions 0-2, replicate 0",
            m["run_id"]
        );
    }
    // A run without its record needs its outcomes file.
    for m in runs.iter().filter(|m| m.get("discovery").is_none()) {
        let id = m["run_id"].as_str().unwrap();
        assert!(
            root()
                .join("data/results/paper")
                .join(format!("{id}.outcomes.parquet"))
                .exists(),
            "{id}: no discovery record and no outcomes file"
        );
    }
}

#[test]
fn the_validity_check_says_what_the_readme_says() {
    let text = readme();
    let said = captures(
        &text,
        "On the committed runs the final KL-coverage fails the check in both environments \
         (against the random projection a position-encoding run wins less than a {} of the \
         time), while cell coverage, the goal-reaching error and the KLC of moved outcomes pass \
         it.",
    );
    assert_eq!(said[0], "third");
    let report = read("report/out/REPORT.md");
    // The per-measure verdict line, and the rows
    // `| measure | env | better | control | encodes | control | repetitions | P [CI] | check |`.
    let verdicts = captures(
        &report,
        "**Per measure and environment** (every kind of control): {}",
    );
    let rows = |measure: &str, env: &str| -> Vec<(String, f64)> {
        let prefix = format!("| {measure} | {env} |");
        let rows: Vec<(String, f64)> = report
            .lines()
            .filter(|l| l.starts_with(&prefix))
            .map(|line| {
                let cells: Vec<&str> = line.split('|').map(str::trim).collect();
                let p = cells[8].split(' ').next().unwrap().parse().unwrap();
                (cells[4].to_string(), p)
            })
            .collect();
        assert!(!rows.is_empty(), "no validity row {prefix}");
        rows
    };
    for env in ["ArmBall", "ArmArrow"] {
        assert!(
            verdicts[0].contains(&format!("final KLC (all outcomes) in {env}: **fails**")),
            "{}",
            verdicts[0]
        );
        let projection = rows("final KLC (all outcomes)", env)
            .into_iter()
            .find(|r| r.0 == "random projection")
            .unwrap();
        assert!(
            projection.1 < 1.0 / 3.0,
            "final KLC on {env}: {projection:?}"
        );
    }
    for measure in [
        "KLC of moved outcomes",
        "cells reached",
        "goal error, mean",
        "goal error, 90th pct",
    ] {
        for env in ["ArmBall", "ArmArrow"] {
            assert!(
                verdicts[0].contains(&format!("{measure} in {env}: passes")),
                "{measure} on {env}: {}",
                verdicts[0]
            );
        }
    }
}

/// The README's list of verdicts that changed from results version 4 to 5 states each claim's
/// verdict now as the committed report's `data/claims.csv` has it (version 4's side is in the
/// history, not in the tree), and its precision as the report's.
#[test]
fn the_changed_verdicts_are_those_of_the_committed_claims() {
    let text = readme();
    let claims = read("report/out/data/claims.csv");
    let verdict_of = |id: &str| -> BTreeSet<String> {
        let mut lines = claims.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let (c, e, v) = (col("claim"), col("evaluation"), col("evaluation_verdict"));
        lines
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|f| f[c] == id && f[e] == "claim")
            .map(|f| f[v].to_string())
            .collect()
    };
    let word = |w: &str| {
        if w == "undecided" {
            "inconclusive".to_string()
        } else {
            w.to_string()
        }
    };
    let few = captures(
        &text,
        "`rfvae-few-moves` went from {} to {} on the paper's own measure",
    );
    assert_eq!(
        verdict_of("rfvae-few-moves"),
        BTreeSet::from([word(&few[1])])
    );
    let rp = captures(
        &text,
        "`learners-beat-random-projection-armarrow-goal-error` (on the goal-reaching error) from {} \
         to {}.",
    );
    assert_eq!(
        verdict_of("learners-beat-random-projection-armarrow-goal-error"),
        BTreeSet::from([word(&rp[1])])
    );
    let precision = captures(&text, "KL-coverage intervals is now {} nats");
    let report = read("report/out/REPORT.md");
    assert!(
        report.contains(&format!(
            "on KL-coverage is {} nats, **wider than",
            precision[0]
        )),
        "the README's precision {} is not the report's",
        precision[0]
    );
}

/// The sweep table of `docs/neural.md` (between its `<!-- sweep-table DIR` and
/// `<!-- end sweep-table -->` lines) is `ugl sweep-table DIR`'s output on the committed sweep,
/// and that sweep holds a network on each side of the acceptance's question: the VAE encodes
/// both objects (distractor k-NN R² above 0.5) and at least one β-VAE does not (below 0.1), so a
/// table that lost its distractor column, or a sweep whose manifests all read alike, fails.
#[test]
fn the_docs_sweep_table_is_that_of_the_committed_sweep() {
    use ugl_types::learners::{CONV_BVAE, CONV_VAE};
    let doc = read("docs/neural.md");
    let start = doc
        .find("<!-- sweep-table ")
        .expect("docs/neural.md has a <!-- sweep-table DIR --> marker");
    let head_end = start + doc[start..].find("-->").expect("the marker is closed") + 3;
    let dir = doc[start + "<!-- sweep-table ".len()..head_end - 3].trim();
    let end = head_end
        + doc[head_end..]
            .find("<!-- end sweep-table -->")
            .expect("the table has its end marker");
    let in_docs = doc[head_end..end].trim();
    let generated = ugl_report::armballs::sweep::table(&root().join(dir))
        .unwrap_or_else(|e| panic!("{dir}: {e}"));
    assert_eq!(
        in_docs,
        generated.trim(),
        "docs/neural.md's sweep table is not `ugl sweep-table {dir}`'s output: regenerate it"
    );
    let cells = |l: &str| -> Vec<String> { l.split('|').map(|c| c.trim().to_string()).collect() };
    let header = cells(generated.lines().next().expect("the table has a header"));
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("the sweep table has no column '{name}': {header:?}"))
    };
    let (setting, distractor) = (column("setting"), column("distractor k-NN R²"));
    let distractor_r2: Vec<(String, f64)> = generated
        .lines()
        .skip(2)
        .map(|l| {
            let row = cells(l);
            (
                row[setting].clone(),
                row[distractor].parse().unwrap_or(f64::NAN),
            )
        })
        .collect();
    assert!(
        distractor_r2
            .iter()
            .any(|(s, r)| s.starts_with(&format!("{},", CONV_VAE.display)) && *r > 0.5),
        "no VAE of the sweep encodes the distractor: {distractor_r2:?}"
    );
    assert!(
        distractor_r2
            .iter()
            .any(|(s, r)| s.starts_with(&format!("{},", CONV_BVAE.display)) && *r < 0.1),
        "{distractor_r2:?}"
    );
}

/// The README's account of `paper-long` is the committed store's: its networks and runs, all
/// results version 5 from the `paper` store's one revision, every network trained the paper's
/// 100,000 iterations.
#[test]
fn the_paper_long_store_is_the_papers_budget() {
    let text = readme();
    let c = captures(
        &text,
        "10 latents, the paper's init and 100,000 iterations, where `paper` trains 600): {} \
         networks and their {} runs, results version 5 from the same revision",
    );
    let word = |w: &str| match w {
        "one" => 1,
        "two" => 2,
        "three" => 3,
        "four" => 4,
        "five" => 5,
        w => number(w),
    };
    let runs = manifests("data/results/paper-long");
    assert_eq!(runs.len(), number(&c[1]), "runs");
    let networks: BTreeSet<String> = runs.iter().map(|m| m["seed"].to_string()).collect();
    assert_eq!(networks.len(), word(&c[0]), "networks");
    let paper: BTreeSet<String> = manifests("data/results/paper")
        .iter()
        .map(|m| m["git_revision"].to_string())
        .collect();
    assert_eq!(paper.len(), 1, "`paper` comes from one revision");
    for m in &runs {
        assert_eq!(m["crate_versions"]["results_version"].as_u64(), Some(5));
        assert!(
            paper.contains(&m["git_revision"].to_string()),
            "{}",
            m["run_id"]
        );
        assert_eq!(
            m["train"]["iterations"].as_u64(),
            Some(100_000),
            "{}",
            m["run_id"]
        );
    }
}
