//! The ArmBalls figures: the ball's and the distractor's exploration ratio against the
//! iterations, and the interest of each goal module. Both are line figures of the shared
//! [`crate::figures::lines`]: every condition in a style of its own (colour: goal space, or the
//! variant campaign; dash: module choice; marker: goal space, hollow in a variant campaign;
//! [`followup_request`]), the legends in strips under the panels, drawn with the curves' styles.

use std::collections::BTreeMap;
use std::path::Path;

use plotters::style::RGBColor;

use super::authors::Authors;
use super::labels::Condition;
use super::runs::{FollowupRun, algos, ball_cells, display, of};
use super::{COVERAGE_FIGURE, INTEREST_FIGURE};
use crate::error::ReportError;
use crate::figures::lines::{
    Curve, LegendPlace, LineFigure, LinePanel, YScale, draw_line_figure, followup_request,
};
use crate::figures::{FigureFile, StyleRequest, assign_styles};
use crate::stats::{CONFIDENCE, mean};

/// Mean curve over the runs of `algo` (epochs of the first run).
fn mean_curve(
    runs: &[&FollowupRun],
    value: impl Fn(&FollowupRun, usize) -> Option<f64>,
) -> Vec<(f64, f64)> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    (0..first.epochs.len())
        .filter_map(|i| {
            let v: Vec<f64> = runs.iter().filter_map(|r| value(r, i)).collect();
            (!v.is_empty()).then(|| (first.epochs[i] as f64, mean(&v)))
        })
        .collect()
}

/// `1 seed`, `5 seeds`, `3-5 seeds`: the seeds per condition of a figure.
fn seeds_text(counts: &[usize]) -> String {
    let lo = counts.iter().copied().min().unwrap_or(0);
    let hi = counts.iter().copied().max().unwrap_or(0);
    let n = if lo == hi {
        format!("{lo}")
    } else {
        format!("{lo}-{hi}")
    };
    format!("{n} seed{}", if hi == 1 { "" } else { "s" })
}

/// The authors' mean curves of the conditions of `runs` in their environment, each in its
/// condition's style drawn thin (their `x` is rollouts with the bootstrap counted: one more than
/// our epoch, whose 0 is the warm-up episode).
fn authors_curves(
    runs: &[FollowupRun],
    conditions: &[Condition],
    styles: &[crate::figures::LineStyle],
    authors: Option<&Authors>,
) -> Vec<Curve> {
    let Some(a) = authors else {
        return Vec::new();
    };
    conditions
        .iter()
        .zip(styles)
        .filter(|(c, _)| c.tag.is_none() && of(runs, c).iter().any(|r| r.key.env == a.env))
        .filter_map(|(c, style)| {
            let theirs = a.of(&c.algo)?;
            let n = theirs.at(a.last_rollouts)?.n;
            Some(Curve {
                label: format!("{}, the authors' mean, n={n}", display(runs, c)),
                style: crate::figures::LineStyle {
                    width: 1,
                    ..style.clone()
                },
                points: theirs
                    .points
                    .iter()
                    .map(|(r, s)| (((*r - 1).max(0)) as f64, s.mean))
                    .collect(),
                band: Vec::new(),
            })
        })
        .collect()
}

/// Ball (left) and distractor (right) exploration ratio against the iterations, mean over seeds;
/// in the authors' environment, their mean curves of the same algorithms beside ours.
pub(super) fn draw_coverage(
    runs: &[FollowupRun],
    authors: Option<&Authors>,
    fig_dir: &Path,
) -> Result<FigureFile, ReportError> {
    let path = fig_dir.join(COVERAGE_FIGURE);
    let conditions = algos(runs);
    let requests: Vec<StyleRequest> = conditions
        .iter()
        .map(|a| {
            let (space, choice) = a.parts();
            followup_request(space, choice.map_or("", |c| c.name), a.tag())
        })
        .collect();
    let styles = assign_styles(&requests, 4.0, 2);
    let counts: Vec<usize> = conditions.iter().map(|a| of(runs, a).len()).collect();
    // One mean curve per condition of the value `value(run, checkpoint)`.
    let curves = |value: &dyn Fn(&FollowupRun, usize) -> Option<f64>| -> Vec<Curve> {
        conditions
            .iter()
            .zip(&styles)
            .zip(&counts)
            .map(|((a, style), n)| Curve {
                label: format!("{}, n={n}", display(runs, a)),
                style: style.clone(),
                points: mean_curve(&of(runs, a), value),
                band: Vec::new(),
            })
            .collect()
    };
    let (reachable, all) = ball_cells();
    let mut ball = curves(&|r, i| r.ball_coverage.get(i).map(|c| c * reachable / all));
    let theirs = authors_curves(
        runs,
        &conditions,
        &ball.iter().map(|c| c.style.clone()).collect::<Vec<_>>(),
        authors,
    );
    let with_authors = !theirs.is_empty();
    ball.extend(theirs);
    let distractor = curves(&|r, i| r.distractor_coverage.get(i).copied().flatten());
    let y_desc = format!("exploration ratio (cells visited / {all:.0})");
    let panel = |title: &str, curves: Vec<Curve>| LinePanel {
        title: title.into(),
        x_desc: "exploration iterations".into(),
        y_desc: y_desc.clone(),
        y_scale: YScale::FromZero,
        curves,
    };
    let seeds = seeds_text(&counts);
    let fig = LineFigure {
        title: Some(format!(
            "ArmBalls: exploration ratio of the ball and of the distractor, mean over {seeds} \
             per condition"
        )),
        panels: vec![
            panel("controllable ball", ball),
            panel("distractor (control: no policy moves it)", distractor),
        ],
        cols: 2,
        panel_size: (600, 440),
        legend: LegendPlace::Shared,
        notes: vec![format!(
            "Lines: the mean over the seeds (n in the legend); no interval is drawn. The table \
             above gives each condition's final ball ratio with its {:.0}% t interval. The ball \
             can reach {reachable:.0} of the {all:.0} cells (ratio at most {:.2}).{}",
            CONFIDENCE * 100.0,
            reachable / all,
            if with_authors {
                " Thin lines: the authors' mean over their runs (their figure's data)."
            } else {
                ""
            }
        )],
        font: 15,
    };
    draw_line_figure(&path, &fig)?;
    Ok(FigureFile {
        path,
        link: format!("figures/{COVERAGE_FIGURE}"),
        caption: format!(
            "ArmBalls: exploration ratio of the ball and of the distractor, mean over {seeds} \
             per condition (no interval drawn)"
        ),
        env: "armballs".into(),
    })
}

/// The colours of the modules (module k: the k-th, cycling).
const MODULE_COLOURS: [RGBColor; 6] = [
    RGBColor(0xD5, 0x5E, 0x00),
    RGBColor(0x00, 0x72, 0xB2),
    RGBColor(0x00, 0x9E, 0x73),
    RGBColor(0xCC, 0x79, 0xA7),
    RGBColor(0xE6, 0x9F, 0x00),
    RGBColor(0x55, 0x55, 0x55),
];

/// One panel per modular algorithm: the mean interest of each module against the iterations.
pub(super) fn draw_interest(
    runs: &[FollowupRun],
    fig_dir: &Path,
) -> Result<Option<FigureFile>, ReportError> {
    let modular: Vec<Condition> = algos(runs)
        .into_iter()
        .filter(|a| a.chooses(&ugl_types::LEARNING_PROGRESS))
        .collect();
    if modular.is_empty() {
        return Ok(None);
    }
    let mut counts = Vec::new();
    let panels: Vec<LinePanel> = modular
        .iter()
        .map(|a| {
            let rs = of(runs, a);
            counts.push(rs.len());
            // Aligned across seeds (`FollowupRun::aligned_modules`): slot k is module k where
            // modules are named by what they hold, the k-th most ball-selective in a learned space.
            let slots = rs.iter().map(|r| r.modules.len()).max().unwrap_or(0);
            let ranked = rs.iter().any(|r| r.modules_ranked());
            let modules: Vec<i64> = (0..slots as i64).collect();
            let requests: Vec<StyleRequest> = modules
                .iter()
                .map(|&m| StyleRequest {
                    family: format!("module {m}"),
                    colour: Some(MODULE_COLOURS[m as usize % MODULE_COLOURS.len()]),
                    dash: 0,
                    marker: m as usize,
                    filled: true,
                })
                .collect();
            let styles = assign_styles(&requests, 4.0, 2);
            let curves = modules
                .iter()
                .zip(styles)
                .map(|(&m, style)| {
                    let label = if ranked {
                        format!("module of ball-selectivity rank {}", m + 1)
                    } else {
                        rs.iter()
                            .find_map(|r| r.modules.get(&m))
                            .filter(|_| a.engineered())
                            .map(|(n, _)| format!("module {m} ({n})"))
                            .unwrap_or_else(|| format!("module {m}"))
                    };
                    let mut pts: BTreeMap<i64, Vec<f64>> = BTreeMap::new();
                    for r in &rs {
                        let Some(&module) = r.aligned_modules().get(m as usize) else {
                            continue;
                        };
                        for p in r.interest.iter().filter(|p| p.1 == module) {
                            pts.entry(p.0).or_default().push(p.2);
                        }
                    }
                    Curve {
                        label,
                        style,
                        points: pts.into_iter().map(|(e, v)| (e as f64, mean(&v))).collect(),
                        band: Vec::new(),
                    }
                })
                .collect();
            LinePanel {
                title: format!("{}, n={}", display(runs, a), rs.len()),
                x_desc: "exploration iterations".into(),
                y_desc: "interest (|learning progress|)".into(),
                y_scale: YScale::Log,
                curves,
            }
        })
        .collect();
    let seeds = seeds_text(&counts);
    let cols = if panels.len() <= 4 { 2 } else { 3 };
    let path = fig_dir.join(INTEREST_FIGURE);
    let fig = LineFigure {
        title: Some(format!(
            "ArmBalls: interest of each goal module (learning-progress choice), mean over \
             {seeds}, log scale"
        )),
        panels,
        cols,
        panel_size: (460, 340),
        legend: LegendPlace::PerPanel,
        notes: vec![
            "Lines: the mean over the seeds (n in each panel's title); no interval is drawn."
                .into(),
        ],
        font: 15,
    };
    draw_line_figure(&path, &fig)?;
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{INTEREST_FIGURE}"),
        caption: format!(
            "ArmBalls: interest per module (learning-progress choice), mean over {seeds}, log \
             scale"
        ),
        env: "armballs".into(),
    }))
}
