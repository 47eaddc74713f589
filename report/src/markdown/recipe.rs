//! The training-recipe section: campaigns named `<main>-*` (e.g. `paper-init`, `paper-long`)
//! rerun cells of the main campaign with another training recipe for the neural learners. Their
//! runs have the main campaign's run seeds (same data set, same exploration streams), so each
//! pairs with the main run of the same cell and seed, and only the network differs.
//!
//! Per recipe campaign: what its recipe is (from the manifests' `train.config`, beside the main
//! campaign's), and per cell the evidence of training (untrained runs, reconstruction loss as a
//! fraction of the mean-image plateau, the iteration where the training loss left the plateau),
//! the latent quality (k-NN R² of the object's position) and the paired final KL-coverage.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use super::quality::{evidence, group_r2, median};
use super::{fmt_klc, plural};
use crate::campaigns::Campaign;
use crate::claims::{CellVerdict, ClaimResult, Comparison, Verdict};
use crate::context::Context;
use crate::load::{ConditionKey, Run};
use crate::names::{algo_name, describe_key, env_name};
use crate::neural::{learner, training};

/// The first logged iteration whose training loss is below `fraction` of the plateau, skipping
/// the RFVAE's KL warm-up (its loss is annealed, hence small, during the warm-up). `None` when
/// the run records no losses or no plateau, `Some(None)` when the loss never got there.
pub fn left_plateau_at(run: &Run) -> Option<Option<i64>> {
    let t = training(&run.manifest)?;
    let e = run.manifest.training_evidence()?;
    let (plateau, fraction) = (e.plateau_loss, e.untrained_fraction);
    if t.losses.is_empty() {
        return None;
    }
    let warmup = t.warmup.unwrap_or(0);
    Some(
        t.losses
            .iter()
            .find(|&&(i, l)| i >= warmup && l < fraction * plateau)
            .map(|&(i, _)| i),
    )
}

/// One line per neural learner of `runs`: its recipe (network, init, iterations when
/// `with_iterations`, learning rate, warm-up), and the main campaign's where it differs.
pub(crate) fn recipe_lines(
    w: &mut String,
    runs: &[Run],
    main_runs: &[Run],
    main_name: &str,
    with_iterations: bool,
) {
    let describe = |runs: &[Run], l: &str| -> Option<String> {
        let mut seen: BTreeMap<String, usize> = BTreeMap::new();
        for r in runs.iter().filter(|r| learner(r).as_deref() == Some(l)) {
            let t = training(&r.manifest)?;
            let hidden = t
                .hidden
                .as_ref()
                .map(|h| h.iter().map(i64::to_string).collect::<Vec<_>>().join("-"))
                .unwrap_or_else(|| "?".into());
            // The network's input is the environment's picture (4900 gray values in the
            // paper's).
            let input = ugl_types::EnvSpec::by_name(&r.manifest.env)
                .map_or_else(|| "?".into(), |e| e.image.len().to_string());
            let mut s = format!(
                "{input}-{hidden}, init `{}`",
                t.init.as_deref().unwrap_or("paper")
            );
            if with_iterations {
                let _ = write!(
                    s,
                    ", {} iterations",
                    t.iterations.map_or("?".into(), |i| i.to_string())
                );
            }
            let _ = write!(
                s,
                ", learning rate {}",
                t.lr.map_or("?".into(), |v| format!("{v}"))
            );
            if let Some(wu) = t.warmup.filter(|&w| w > 0) {
                let _ = write!(s, ", warm-up {wu}");
            }
            *seen.entry(s).or_default() += 1;
        }
        (!seen.is_empty()).then(|| seen.into_keys().collect::<Vec<_>>().join(" / "))
    };
    for l in crate::neural::learners() {
        let Some(ours) = describe(runs, l) else {
            continue;
        };
        let theirs = describe(main_runs, l);
        let _ = writeln!(
            w,
            "- **{}**: {ours}{}.",
            algo_name(&format!("rge-{l}")),
            match theirs {
                Some(t) if t != ours => format!(" (`{main_name}`: {t})"),
                Some(_) => format!(" (as `{main_name}`)"),
                None => String::new(),
            }
        );
    }
}

/// The values of one side (recipe or main) of a cell.
#[derive(Default)]
struct Side {
    untrained: usize,
    with_evidence: usize,
    loss_fractions: Vec<f64>,
    left_at: Vec<i64>,
    never_left: usize,
    position_knn: Vec<f64>,
    klc: Vec<f64>,
    /// The validated measures ([`crate::discovery`]): goal-reaching error (mean), the fraction
    /// of the achievable cells reached, KLC of the episodes that moved the object.
    goal_error: Vec<f64>,
    coverage: Vec<f64>,
    moved_klc: Vec<f64>,
}

impl Side {
    fn add(&mut self, r: &Run) {
        if let Some((f, trained)) = evidence(&r.manifest) {
            self.with_evidence += 1;
            self.untrained += usize::from(!trained);
            self.loss_fractions.push(f);
        }
        match left_plateau_at(r) {
            Some(Some(i)) => self.left_at.push(i),
            Some(None) => self.never_left += 1,
            None => {}
        }
        if let Some((_, k)) = group_r2(&r.manifest, "position") {
            self.position_knn.push(k);
        }
        self.klc.push(r.final_point().klc);
        self.coverage.push(r.final_point().coverage);
        if let Ok(Some(d)) = crate::discovery::measure_run(r) {
            self.goal_error.push(d.goal_error_mean);
            self.moved_klc.extend(d.moved_klc);
        }
    }

    fn untrained_cell(&self) -> String {
        if self.with_evidence == 0 {
            "—".into()
        } else {
            format!("{}/{}", self.untrained, self.with_evidence)
        }
    }

    fn left_cell(&self) -> String {
        let m = median(&self.left_at.iter().map(|&i| i as f64).collect::<Vec<_>>());
        match (m, self.never_left) {
            (None, 0) => "—".into(),
            (None, n) => format!("never ({n})"),
            (Some(m), 0) => format!("{m:.0}"),
            (Some(m), n) => format!("{m:.0}; never ({n})"),
        }
    }
}

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// A cell of the table: its key, and the pairs (recipe run, main run) of the same repetition and
/// exploration replicate.
struct Cell<'a> {
    key: ConditionKey,
    pairs: Vec<(&'a Run, &'a Run)>,
}

fn cells<'a>(camp: &'a Campaign, main: &'a Campaign) -> (Vec<Cell<'a>>, usize) {
    // A run's identity in its cell: repetition and exploration replicate (the replicates of a
    // repetition share its data set and fit, not their exploration streams).
    let by_id: BTreeMap<(&ConditionKey, i64, u32), &Run> = main
        .store
        .runs
        .iter()
        .map(|r| ((&r.key, r.seed, r.manifest.exploration), r))
        .collect();
    let mut cells: BTreeMap<_, Cell<'a>> = BTreeMap::new();
    let mut unpaired = 0;
    for r in &camp.store.runs {
        let Some(m) = by_id.get(&(&r.key, r.seed, r.manifest.exploration)) else {
            unpaired += 1;
            continue;
        };
        cells
            .entry(r.key.order_key())
            .or_insert_with(|| Cell {
                key: r.key.clone(),
                pairs: Vec::new(),
            })
            .pairs
            .push((r, m));
    }
    (cells.into_values().collect(), unpaired)
}

/// The section (nothing when there is no recipe campaign).
pub fn section(w: &mut String, inp: &Context<'_>) {
    let main = &inp.campaigns.main;
    if inp.campaigns.recipe.is_empty() {
        return;
    }
    let _ = writeln!(w, "## Training recipes\n");
    let _ = writeln!(
        w,
        "Campaigns named `{m}-*` rerun cells of `{m}` with another training recipe for the \
         neural learners. Their runs have `{m}`'s run seeds (the same data set and the same \
         exploration streams), so each pairs with the `{m}` run of its cell, repetition and \
         exploration replicate, and only the network differs. In the tables each entry is *recipe / `{m}`*: **untrained** counts \
         the runs whose reconstruction loss is not below 0.8 of the mean-image plateau (the \
         quality section); **loss / plateau** is its median; **left the plateau** is the median \
         first logged iteration whose *training* loss is below 0.8 of the plateau (after the \
         RFVAE's warm-up; the training loss includes the KL and the flows' log-det, so this is \
         indicative), *never (k)* counting the runs that did not; **position R²** is the median \
         held-out k-NN R² of the object's position from the latents; **final KLC** is the mean \
         over the pairs, **Δ** the mean paired difference (recipe − `{m}`) with the range of the per-pair \
         differences (*min to max*: a range, not a confidence interval), and \
         **recipe better** the pairs where the recipe's run ends with the lower (better) \
         KL-coverage; **goal error**, **cells reached** and **moved KLC** are the means of the \
         validated measures (the goal-reaching error, the fraction of the achievable cells \
         reached, the KLC of the episodes that moved the object: the validity check's). n ≤ 5 \
         pairs: read the differences as indications, not tests; the paper's claims on each cell \
         are then evaluated with either network, with their intervals.\n",
        m = main.name
    );
    for camp in &inp.campaigns.recipe {
        let (cells, unpaired) = cells(camp, main);
        let n_runs = camp.store.runs.len();
        let _ = writeln!(w, "### `{}`\n", camp.name);
        let _ = writeln!(
            w,
            "{n_runs} complete run{}{}{}. The recipe, read from the manifests:\n",
            plural(n_runs),
            if camp.store.incomplete.is_empty() {
                String::new()
            } else {
                format!(
                    " ({} more incomplete: the campaign is still running or was interrupted)",
                    camp.store.incomplete.len()
                )
            },
            if unpaired > 0 {
                format!("; {unpaired} without a `{}` run to pair with", main.name)
            } else {
                String::new()
            }
        );
        // A pairing across results versions, or with runs no commit reproduces, is flagged.
        let versions = |c: &Campaign| -> BTreeSet<u64> {
            c.store
                .runs
                .iter()
                .filter_map(|r| r.manifest.results_version())
                .collect()
        };
        let (theirs, ours) = (versions(camp), versions(main));
        let dirty = camp
            .store
            .runs
            .iter()
            .filter(|r| r.manifest.git_revision.ends_with("-dirty"))
            .count();
        if theirs != ours || dirty > 0 {
            let list =
                |v: &BTreeSet<u64>| v.iter().map(u64::to_string).collect::<Vec<_>>().join(", ");
            let _ = writeln!(
                w,
                "⚠ **Not a clean pairing**: these runs are results version {} against `{}`'s {}{}; \
                 the pairing assumes the data sets and streams of a seed did not change between \
                 versions, which a version change does not guarantee.\n",
                list(&theirs),
                main.name,
                list(&ours),
                if dirty > 0 {
                    format!(
                        ", and {dirty} of them come from trees with uncommitted changes \
                         (`-dirty`), which no commit reproduces"
                    )
                } else {
                    String::new()
                }
            );
        }
        recipe_lines(w, &camp.store.runs, &main.store.runs, &main.name, true);
        let _ = writeln!(w);
        if cells.is_empty() {
            let _ = writeln!(w, "No run pairs with a `{}` run yet.\n", main.name);
            continue;
        }
        let _ = writeln!(
            w,
            "| env | algorithm | goals | variant | latents | pairs | untrained | loss / plateau | \
             left the plateau | position R² | final KLC | Δ | recipe better | goal error | \
             cells reached | moved KLC |"
        );
        let _ = writeln!(
            w,
            "|---|---|---|---|---:|---:|---|---|---|---|---|---|---:|---|---|---|"
        );
        let mut all_delta: Vec<f64> = Vec::new();
        let mut untrained = [0usize; 2];
        let mut with_evidence = [0usize; 2];
        for c in &cells {
            let mut ours = Side::default();
            let mut theirs = Side::default();
            for (a, b) in &c.pairs {
                ours.add(a);
                theirs.add(b);
            }
            untrained[0] += ours.untrained;
            untrained[1] += theirs.untrained;
            with_evidence[0] += ours.with_evidence;
            with_evidence[1] += theirs.with_evidence;
            let deltas: Vec<f64> = c
                .pairs
                .iter()
                .map(|(a, b)| a.final_point().klc - b.final_point().klc)
                .filter(|d| d.is_finite())
                .collect();
            all_delta.extend(&deltas);
            let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
            let lo = deltas.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = deltas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let delta = match mean(&deltas) {
                Some(d) => format!("{d:+.3} ({lo:+.3} to {hi:+.3})"),
                None => "—".into(),
            };
            let better = deltas.iter().filter(|d| **d < 0.0).count();
            let pair = |a: String, b: String| format!("{a} / {b}");
            let _ = writeln!(
                w,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {}/{} | {} | {} | {} |",
                env_name(&c.key.env),
                algo_name(&c.key.algo),
                c.key.sampler,
                c.key.variant,
                c.key.latents,
                c.pairs.len(),
                pair(ours.untrained_cell(), theirs.untrained_cell()),
                pair(
                    fmt_opt(median(&ours.loss_fractions), 2),
                    fmt_opt(median(&theirs.loss_fractions), 2)
                ),
                pair(ours.left_cell(), theirs.left_cell()),
                pair(
                    fmt_opt(median(&ours.position_knn), 2),
                    fmt_opt(median(&theirs.position_knn), 2)
                ),
                pair(
                    mean(&ours.klc).map_or("—".into(), fmt_klc),
                    mean(&theirs.klc).map_or("—".into(), fmt_klc)
                ),
                delta,
                better,
                deltas.len(),
                pair(
                    fmt_opt(mean(&ours.goal_error), 3),
                    fmt_opt(mean(&theirs.goal_error), 3)
                ),
                pair(
                    fmt_opt(mean(&ours.coverage), 3),
                    fmt_opt(mean(&theirs.coverage), 3)
                ),
                pair(
                    fmt_opt(mean(&ours.moved_klc), 2),
                    fmt_opt(mean(&theirs.moved_klc), 2)
                ),
            );
        }
        let n = all_delta.len();
        if n > 0 {
            let mean = all_delta.iter().sum::<f64>() / n as f64;
            let better = all_delta.iter().filter(|d| **d < 0.0).count();
            let _ = writeln!(
                w,
                "\nOver all {n} pair{}: untrained {} of {} `{}` runs against {} of {} `{}` \
                 runs; mean paired Δ final KLC {mean:+.3}; the `{}` run ends with the lower (better) \
                 KL-coverage in {better} of {n}.\n",
                plural(n),
                untrained[0],
                with_evidence[0],
                camp.name,
                untrained[1],
                with_evidence[1],
                main.name,
                camp.name
            );
        } else {
            let _ = writeln!(w);
        }
        let tag = camp.tag();
        let verdicts: Vec<&CellVerdict> = inp
            .recipe_verdicts
            .iter()
            .filter(|v| v.tag == tag)
            .collect();
        cell_verdicts(w, &verdicts, &camp.name, &main.name, cells.len());
    }
}

/// At most this many cells get the table of the paper's claims on each; a campaign with more
/// (the untrained twins of every cell) gets the count of changed verdicts only.
const CELLS_WITH_CLAIM_TABLES: usize = 4;

/// Whether the recipe changes the verdicts of the paper's claims on its cells: a table of every
/// claim's comparisons with either network (few cells), and the verdicts that changed.
fn cell_verdicts(
    w: &mut String,
    verdicts: &[&CellVerdict],
    recipe: &str,
    main: &str,
    n_cells: usize,
) {
    if verdicts.is_empty() {
        return;
    }
    let validated = |r: &ClaimResult| -> (Verdict, Vec<Comparison>) {
        match &r.twin {
            Some(t) => (t.verdict, t.comparisons.clone()),
            None => (r.verdict, Vec::new()),
        }
    };
    let reps = |v: &CellVerdict| {
        let r = &v.repetitions;
        match (r.first(), r.last()) {
            (Some(a), Some(b)) if (b - a) as usize + 1 == r.len() => format!("{a}-{b}"),
            _ => r.iter().map(i64::to_string).collect::<Vec<_>>().join(", "),
        }
    };
    let _ = writeln!(
        w,
        "**The paper's claims on {}**, evaluated on each cell with `{main}`'s networks and with \
         `{recipe}`'s, on the repetitions both ran (the references are `{main}`'s runs of those \
         repetitions, paired by repetition; intervals as in the claims section, Holm's \
         correction over the claim's comparisons on the cell). A claim on the final KLC or the \
         episodes moved is also judged on the validated measures.\n",
        if n_cells == 1 {
            "this cell"
        } else {
            "these cells"
        }
    );
    if n_cells <= CELLS_WITH_CLAIM_TABLES {
        let _ = writeln!(
            w,
            "| cell | repetitions | claim | measure | reference | `{main}`: Δ (interval) → verdict | \
             `{recipe}`: Δ (interval) → verdict |"
        );
        let _ = writeln!(w, "|---|---|---|---|---|---|---|");
        for v in verdicts {
            let (_, main_twin) = validated(&v.main);
            let (_, recipe_twin) = validated(&v.recipe);
            // Each comparison with `main`'s networks, beside the recipe's of the same reference
            // and measure.
            let theirs: Vec<&Comparison> =
                v.recipe.comparisons.iter().chain(&recipe_twin).collect();
            let rows = v.main.comparisons.iter().chain(&main_twin).filter_map(|m| {
                let r = theirs
                    .iter()
                    .find(|r| r.reference == m.reference && r.statistic == m.statistic)?;
                Some((m, *r))
            });
            for (m, r) in rows {
                let cmp = |c: &Comparison| {
                    let i = c.bounds().map_or("no interval".into(), |(lo, hi)| {
                        format!("{lo:+.3} to {hi:+.3}")
                    });
                    format!("{:+.3} ({i}) → {}", c.diff, c.verdict.label())
                };
                let _ = writeln!(
                    w,
                    "| {} | {} | `{}` | {} | {} | {} | {} |",
                    describe_key(&v.cell),
                    reps(v),
                    v.main.claim.id,
                    m.statistic.label(),
                    describe_key(&m.reference),
                    cmp(m),
                    cmp(r)
                );
            }
        }
        let _ = writeln!(w);
    }
    // What changes: the claim's verdict on its own statistic and on the validated measures.
    let mut changed = Vec::new();
    let mut same = 0;
    for v in verdicts {
        let pairs = [
            ("its own statistic", v.main.verdict, v.recipe.verdict, true),
            (
                "the validated measures",
                validated(&v.main).0,
                validated(&v.recipe).0,
                v.main.twin.is_some(),
            ),
        ];
        for (on, a, b, present) in pairs {
            if !present {
                continue;
            }
            if a == b {
                same += 1;
            } else {
                changed.push(format!(
                    "`{}` on {} ({}), {on}: {} with `{main}`'s networks, {} with `{recipe}`'s",
                    v.main.claim.id,
                    describe_key(&v.cell),
                    reps(v),
                    a.label(),
                    b.label()
                ));
            }
        }
    }
    let total = same + changed.len();
    if changed.is_empty() {
        let _ = writeln!(
            w,
            "**The recipe changes none of the {total} verdicts** (claim x cell, on the claim's own \
             statistic and on the validated measures): each is the same with `{main}`'s networks \
             and with `{recipe}`'s.\n"
        );
    } else {
        let _ = writeln!(
            w,
            "**The recipe changes {} of the {total} verdicts** (claim x cell, on the claim's own \
             statistic and on the validated measures){}\n",
            changed.len(),
            if n_cells <= CELLS_WITH_CLAIM_TABLES {
                ":"
            } else {
                ". Which:\n\n<details><summary>the changed verdicts</summary>"
            }
        );
        for (i, c) in changed.iter().enumerate() {
            let end = if i + 1 == changed.len() { '.' } else { ';' };
            let _ = writeln!(w, "- {c}{end}");
        }
        if n_cells > CELLS_WITH_CLAIM_TABLES {
            let _ = writeln!(w, "\n</details>");
        }
        let _ = writeln!(w);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::CurvePoint;
    use serde_json::json;
    use std::path::PathBuf;

    fn run(losses: &[(i64, f64)], warmup: i64) -> Run {
        Run {
            run_id: "r".into(),
            campaign: "c".into(),
            key: ConditionKey {
                env: "armball".into(),
                algo: "rge-rfvae".into(),
                sampler: "kde".into(),
                latents: 10,
                variant: "faithful".into(),
                tag: None,
            },
            seed: 0,
            curve: vec![CurvePoint {
                epoch: 0,
                n_outcomes: 1,
                klc: 1.0,
                n_moved: 0,
                coverage: 0.0,
            }],
            outcomes: Vec::new(),
            diagnostics: None,
            manifest: crate::load::test_manifest(json!({"train": {
                "config": {"warmup": warmup, "iterations": 1000},
                "evidence": {"images": 2000, "loss_fraction": 0.25, "plateau_loss": 400.0,
                             "reconstruction_loss": 100.0, "trained": true,
                             "untrained_fraction": 0.8},
                "losses": losses,
            }})),
            curve_path: PathBuf::new(),
            outcomes_path: PathBuf::new(),
            manifest_path: PathBuf::new(),
            measured: Default::default(),
        }
    }

    /// With exploration replicates, a recipe run pairs with the main run of its repetition *and*
    /// replicate (the replicates' exploration streams differ), never with another replicate.
    #[test]
    fn recipe_runs_pair_by_repetition_and_replicate() {
        let with = |campaign: &str, seed: i64, exploration: u32| {
            let mut r = run(&[], 0);
            r.campaign = campaign.into();
            r.seed = seed;
            r.manifest.exploration = exploration;
            r.run_id = format!("{campaign}.s{seed}.e{exploration}");
            r
        };
        let campaign = |name: &str, runs: Vec<Run>| Campaign {
            name: name.into(),
            path: PathBuf::new(),
            decl: Default::default(),
            store: crate::load::Store {
                runs,
                incomplete: Vec::new(),
            },
            configurations: 1,
        };
        let main = campaign(
            "paper",
            (0..2)
                .flat_map(|s| (0..3).map(move |e| (s, e)))
                .map(|(s, e)| with("paper", s, e))
                .collect(),
        );
        let recipe = campaign(
            "paper-long",
            vec![
                with("paper-long", 1, 2),
                with("paper-long", 1, 0),
                with("paper-long", 4, 0),
            ],
        );
        let (cells, unpaired) = cells(&recipe, &main);
        assert_eq!(unpaired, 1, "repetition 4 has no main run");
        assert_eq!(cells.len(), 1);
        let ids: Vec<(&str, &str)> = cells[0]
            .pairs
            .iter()
            .map(|(a, b)| (a.run_id.as_str(), b.run_id.as_str()))
            .collect();
        assert_eq!(
            ids,
            [
                ("paper-long.s1.e2", "paper.s1.e2"),
                ("paper-long.s1.e0", "paper.s1.e0")
            ]
        );
    }

    #[test]
    fn left_the_plateau_is_the_first_logged_loss_below_the_threshold_after_the_warm_up() {
        // 0.8 * 400 = 320: iteration 200 is the first below it.
        let r = run(&[(0, 3000.0), (100, 450.0), (200, 300.0), (300, 100.0)], 0);
        assert_eq!(left_plateau_at(&r), Some(Some(200)));
        // During a warm-up the annealed loss is small: not counted.
        let r = run(&[(0, 30.0), (100, 4.0), (200, 400.0), (300, 310.0)], 200);
        assert_eq!(left_plateau_at(&r), Some(Some(300)));
        let r = run(&[(0, 3000.0), (100, 450.0)], 0);
        assert_eq!(left_plateau_at(&r), Some(None));
        let r = run(&[], 0);
        assert_eq!(left_plateau_at(&r), None);
    }
}
