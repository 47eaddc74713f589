//! The section "What the exploration discovered, without counting repeats": the measures that do
//! not count repeats, the validity check that shows they measure, and where the position-encoding
//! goal spaces leave the object ([`crate::discovery`] computes them).

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use ugl_types::{EnvSpec, GOAL_OTHER_BINS, GOAL_POSITION_BINS, GoalGrid, median};

use crate::campaigns::Campaigns;
use crate::data::discovery::{FILE, VALIDITY_FILE};
use crate::discovery::{
    Check, Group, Measure, N_BOOT, PASS_LOWER_BOUND, POSITION_R2, RunRow, held_out_or_claimed,
    passes,
};

/// The report's section: what the measures are, and the validity table.
pub fn section(w: &mut String, rows: &[RunRow<'_>], checks: &[Check], camps: &Campaigns) {
    let _ = writeln!(
        w,
        "\n## What the exploration discovered, without counting repeats\n\n\
         KL-coverage scores the histogram of *every* outcome, so each episode that leaves the \
         object in place adds weight to one cell, and a goal space that moves the object more \
         often scores better whatever it found. Three measures that do not count repeats, \
         which each run records in its manifest when it ends (runs written before that are \
         measured from their outcomes files with the same code; `data/{FILE}`, one row per \
         run):\n\n\
         - **KLC of moved outcomes**: the same 30-bin histogram and formula (paper Section 4.2) \
         over the episodes in which the object moved (ln N, every outcome in one cell, for a run \
         that never moved it). The re-implementation reproduces the runs' own KLC exactly on \
         all outcomes.\n\
         - **cells reached**: the fraction of achievable cells holding an outcome.\n\
         - **goal-reaching error**: the distance from each of a fixed grid of test goals to the \
         nearest outcome, the error of a nearest-neighbour inverse model on a deterministic \
         environment (explauto's `Evaluation`; the original code's inverse-model error); mean \
         and 90th percentile. The goals are the centres of a {GOAL_POSITION_BINS} × \
         {GOAL_POSITION_BINS} grid over [-1, 1]² inside the unit disk, times {GOAL_OTHER_BINS} \
         angles where the angle is measured ({} goals for ArmBall, {} for ArmArrow), in the \
         controllable object's coordinates (the angle in units of π, not wrapped).\n",
        GoalGrid::new(2).len(),
        GoalGrid::new(3).len(),
    );
    let n = |g: Group| {
        rows.iter()
            .filter(|r| r.in_check && r.group == Some(g))
            .count()
    };
    // Which runs count as encoding the position, by condition.
    let mut encoding: BTreeMap<(usize, String), usize> = BTreeMap::new();
    let mut below: BTreeMap<(usize, String), (usize, f64, f64)> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.in_check) {
        let label = format!(
            "{} {}",
            EnvSpec::display_of(&r.run.key.env),
            crate::names::describe_key(&r.run.key)
        );
        let order = EnvSpec::order(&r.run.key.env);
        match r.group {
            Some(Group::Encodes) => *encoding.entry((order, label)).or_default() += 1,
            None if r.run.manifest.trained() != Some(false) => {
                if let Some((_, knn)) = r.run.manifest.group_r2("position") {
                    let e = below.entry((order, label)).or_insert((
                        0,
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                    ));
                    e.0 += 1;
                    e.1 = e.1.min(knn);
                    e.2 = e.2.max(knn);
                }
            }
            _ => {}
        }
    }
    let list = |m: Vec<String>| {
        if m.is_empty() {
            "none".to_string()
        } else {
            m.join("; ")
        }
    };
    let _ = writeln!(
        w,
        "**Validity check.** A measure of discovery must rank goal spaces that encode the \
         object's position ahead of goal spaces that do not: *position-encoding* are RGE-EFR \
         (its goals are the object's state) and the learned spaces whose held-out k-NN R² of the \
         position from their latents is at least {POSITION_R2} and whose network (if any) left \
         the mean-image plateau ({} runs); the *controls* are the random projections of the \
         pixels and the networks that stayed on the plateau (the untrained twins of the recipe \
         campaigns; {} runs). Learned spaces with a lower R² are in neither group: they encode \
         the position in part, so a measure may rank them either way. {} Per environment, measure and kind of control: *P(better)*, the \
         probability that a random position-encoding run beats a random control run (ties \
         half; 0.5: the measure does not tell them apart), with its {:.0}% interval from a \
         bootstrap that resamples repetitions ({N_BOOT} resamples, seeded; a repetition's runs \
         share its data set and fits), a t interval on the bootstrap's standard error with k − 1 \
         degrees of freedom (in a simulation of the two-level design at 10 repetitions it covers \
         0.94-0.95; the percentile interval covered 0.92). **Pass rule**, fixed before the check was run: the \
         interval's lower bound is above {PASS_LOWER_BOUND} against every kind of control. A \
         measure that fails is no measure of discovery, and no verdict should rest on it \
         alone. Every line: [`data/{VALIDITY_FILE}`](data/{VALIDITY_FILE}).\n",
        n(Group::Encodes),
        n(Group::Control),
        data_used(camps),
        crate::stats::CONFIDENCE * 100.0,
    );
    let _ = writeln!(
        w,
        "<details><summary>Which runs are in which group</summary>\n\n\
         Position-encoding (runs): {}.\n\n\
         In neither group, trained with a position R² below {POSITION_R2} (runs, R² range): {}.\n\n\
         </details>\n",
        list(
            encoding
                .iter()
                .map(|((_, l), n)| format!("{l} ({n})"))
                .collect()
        ),
        list(
            below
                .iter()
                .map(|((_, l), (n, lo, hi))| format!("{l} ({n}, {lo:.2}-{hi:.2})"))
                .collect()
        ),
    );
    let _ = writeln!(
        w,
        "| measure | env | better | control | encodes position: runs, median | control: runs, \
         median | repetitions | P(better) [{:.0}% CI] | check |\n|---|---|---|---|---|---|---:|---|---|",
        crate::stats::CONFIDENCE * 100.0
    );
    for c in checks {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {}, {:.3} | {}, {:.3} | {} | {:.2} {} | {} |",
            c.measure.label(),
            EnvSpec::display_of(&c.env),
            if c.measure.lower_is_better() {
                "lower"
            } else {
                "higher"
            },
            c.control.label(),
            c.encodes.len(),
            c.encodes_median,
            c.controls.len(),
            c.control_median,
            c.repetitions,
            c.p_better,
            c.interval
                .map(|(lo, hi)| format!("[{lo:.2}, {hi:.2}]"))
                .unwrap_or_else(|| "(no interval)".into()),
            if c.passes { "passes" } else { "**fails**" },
        );
    }
    let mut verdicts: Vec<String> = Vec::new();
    let mut seen: Vec<(Measure, String)> = Vec::new();
    for c in checks {
        let key = (c.measure, c.env.clone());
        if seen.contains(&key) {
            continue;
        }
        seen.push(key);
        if let Some(p) = passes(checks, c.measure, &c.env) {
            verdicts.push(format!(
                "{} in {}: {}",
                c.measure.label(),
                EnvSpec::display_of(&c.env),
                if p { "passes" } else { "**fails**" }
            ));
        }
    }
    if !verdicts.is_empty() {
        let _ = writeln!(
            w,
            "\n**Per measure and environment** (every kind of control): {}.",
            verdicts.join("; ")
        );
    }
    w.push('\n');
    position_and_rest(w, rows);
}

/// Which runs the validity check reads, in words.
pub fn data_used(camps: &Campaigns) -> String {
    let names: Vec<String> = held_out_or_claimed(camps)
        .iter()
        .map(|c| format!("`{}`", crate::load::campaign_display(&c.name)))
        .collect();
    if camps.validation.is_empty() {
        format!(
            "Runs of {}, every goal sampler; **the same runs carry the claims**, so the check \
             is not independent of the verdicts that use it (no held-out `validation` campaign \
             is in this store).",
            names.join(", ")
        )
    } else {
        format!(
            "Runs of the held-out validation campaign{} {} (repetitions no claim uses), every \
             goal sampler.",
            if names.len() == 1 { "" } else { "s" },
            names.join(", ")
        )
    }
}

/// Where an environment measures more than the position (ArmArrow's angle): per condition of
/// the main campaign, what its runs found of the position and of the rest, apart.
fn position_and_rest(w: &mut String, rows: &[RunRow<'_>]) {
    // Conditions in the rows' order (the report's), each with its values.
    type Cols = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);
    let mut by_cond: Vec<(String, String, Cols)> = Vec::new();
    let mut index: BTreeMap<String, usize> = BTreeMap::new();
    for r in rows {
        let (Some(p), Some(rest), Some(d)) = (&r.position, r.rest_per_position_cell, &r.discovery)
        else {
            continue;
        };
        if r.campaign.name != rows[0].campaign.name {
            continue; // the main campaign's conditions only
        }
        let i = *index.entry(r.run.key.slug()).or_insert_with(|| {
            by_cond.push((
                r.run.key.env.clone(),
                crate::names::describe_key(&r.run.key),
                Cols::default(),
            ));
            by_cond.len() - 1
        });
        let e = &mut by_cond[i].2;
        e.0.push(p.coverage * 100.0);
        e.1.push(rest);
        e.2.push(p.goal_error_mean);
        e.3.push(d.coverage * 100.0);
        e.4.push(d.goal_error_mean);
    }
    if by_cond.is_empty() {
        return;
    }
    let envs: BTreeSet<&str> = by_cond.iter().map(|k| k.0.as_str()).collect();
    let bins = envs
        .iter()
        .filter_map(|e| EnvSpec::by_name(e))
        .map(|s| {
            format!(
                "{} bins of each further coordinate in {}",
                s.klc.bins, s.display
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let _ = writeln!(
        w,
        "**The position and the rest, apart** ({}). The measures above bin the whole outcome; \
         here the position's part of it: *position cells* is the fraction of the disk's \
         position cells reached (the 30 x 30 grid, as ArmBall's), *angle bins per position \
         cell* the mean number of angle bins reached in a reached position cell ({bins}: \
         what the exploration found of the angle where it found the position), and the goal \
         errors on the position goals alone and on the position-angle goals. Medians over each \
         condition's runs of the main campaign.\n",
        envs.iter()
            .map(|e| EnvSpec::display_of(e))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        w,
        "| env | condition | runs | position cells | angle bins per position cell | goal error \
         (position) | all cells | goal error (position and angle) |\n|---|---|---:|---:|---:|---:|---:|---:|"
    );
    for (env, label, (pc, rest, pe, ac, ae)) in &by_cond {
        let m = |v: &[f64]| median(v).unwrap_or(f64::NAN);
        let _ = writeln!(
            w,
            "| {} | {label} | {} | {:.1}% | {:.2} | {:.3} | {:.2}% | {:.3} |",
            EnvSpec::display_of(env),
            pc.len(),
            m(pc),
            m(rest),
            m(pe),
            m(ac),
            m(ae),
        );
    }
    w.push('\n');
}
