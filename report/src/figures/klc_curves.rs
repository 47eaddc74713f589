//! KL-coverage against exploration epochs, like the paper's Figure 2: one figure per environment,
//! one panel per latent size of the learned goal spaces (the baselines RPE and RGE-EFR, which have
//! no latent size, appear in every panel, as in the paper), one curve per condition: the mean over
//! the repetitions (each the mean of its exploration replicates). Beside each panel, a strip with
//! one column per condition gives the final value: the mean with its 95% t interval over the
//! repetitions ([`crate::stats::CONFIDENCE`]) and, where the paper gives one, the paper's value as a
//! hollow star. (Bands around every curve ran into one mass; the strip keeps the intervals
//! readable.) The panels of a figure share their y axis.
//!
//! As the paper's figure (its notebook filtered `sampling != 'normal'`), the Gaussian-goal runs are
//! left out: they have their own figure ([`super::sampler_compare`], the paper's Figure 4).
//! Colour and marker shape identify the algorithm; the corrected variant is dashed with hollow
//! markers, the faithful one solid with filled markers.

use std::collections::BTreeMap;
use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::final_strip::{FinalColumn, draw_final_strip};
use super::{
    FONT, FigureFile, Icon, SOLID, algo_slot, colour, condition_name, dash_pattern, dedup_legend,
    env_name, file_safe, fmt_epoch, klc_max, legend_height, legend_strip, marker, marker_points,
    paper_star_item, sampler_name, write_svg,
};
use crate::aggregate::{ConditionSummary, CurveStat};
use crate::error::ReportError;

const PANEL_W: u32 = 820;
/// Width of a panel's final-value strip, out of [`PANEL_W`].
const STRIP_W: u32 = 250;
const PANEL_H: u32 = 520;
const TITLE_H: u32 = 36;

/// Whether a condition belongs in this figure: every goal sampler but the Gaussian prior.
pub fn in_figure(c: &ConditionSummary) -> bool {
    c.key.sampler != ugl_types::Sampler::GAUSSIAN
}

/// One panel: a title and the conditions drawn in it.
struct Panel<'a> {
    title: String,
    members: Vec<&'a ConditionSummary>,
}

/// What a figure of curves shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// KL-coverage (the paper's Figure 2), with the paper's final values.
    Klc,
    /// The fraction of the achievable histogram cells reached (not in the paper).
    Coverage,
}

impl Metric {
    fn curve(self, c: &ConditionSummary) -> &[CurveStat] {
        match self {
            Metric::Klc => &c.curve,
            Metric::Coverage => &c.coverage_curve,
        }
    }

    /// The paper's final value of a condition, where it gives one for this metric.
    fn paper(self, c: &ConditionSummary) -> Option<f64> {
        match self {
            Metric::Klc => c.paper.as_ref().map(|p| p.klc),
            Metric::Coverage => None,
        }
    }

    fn file(self, env: &str) -> String {
        match self {
            Metric::Klc => format!("klc_{}.svg", file_safe(env)),
            Metric::Coverage => format!("coverage_{}.svg", file_safe(env)),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Metric::Klc => "KL-coverage",
            Metric::Coverage => "cell coverage",
        }
    }

    fn y_desc(self) -> &'static str {
        match self {
            Metric::Klc => "KL-coverage (nats, lower is better)",
            Metric::Coverage => "achievable cells reached (higher is better)",
        }
    }
}

/// Draws `klc_<env>.svg` for every environment, in the report's order.
pub fn draw_all(
    conditions: &[ConditionSummary],
    fig_dir: &Path,
) -> Result<Vec<FigureFile>, ReportError> {
    draw_metric(conditions, fig_dir, Metric::Klc)
}

/// Draws `<metric>_<env>.svg` for every environment, in the report's order.
pub fn draw_metric(
    conditions: &[ConditionSummary],
    fig_dir: &Path,
    metric: Metric,
) -> Result<Vec<FigureFile>, ReportError> {
    let mut envs: Vec<&str> = Vec::new();
    for c in conditions {
        if !envs.contains(&c.key.env.as_str()) {
            envs.push(&c.key.env);
        }
    }
    let mut out = Vec::new();
    for env in envs {
        let of_env: Vec<&ConditionSummary> = conditions
            .iter()
            .filter(|c| c.key.env == env && in_figure(c))
            .collect();
        if of_env.is_empty() {
            continue;
        }
        let panels = panels_of(env, &of_env);
        let name = metric.file(env);
        let path = fig_dir.join(&name);
        let width = PANEL_W * panels.len() as u32;
        // One legend for all panels, in a strip under them (no legend hides a curve).
        let legend = dedup_legend(
            panels
                .iter()
                .flat_map(|p| panel_legend(p, metric))
                .collect(),
        );
        let legend_h = legend_height(width, &legend, 13);
        write_svg(&path, (width, PANEL_H + TITLE_H + legend_h), |root| {
            let title = format!(
                "{}: {}, mean over repetitions; right of each panel: final value with 95% t interval",
                env_name(env),
                metric.name()
            );
            let area = root.titled(&title, (FONT, 18))?;
            let (plots, strip) = area.split_vertically(PANEL_H);
            let areas = plots.split_evenly((1, panels.len()));
            let y = y_range(env, &panels, metric);
            for (panel, a) in panels.iter().zip(areas.iter()) {
                draw_panel(a, panel, metric, y)?;
            }
            legend_strip(&strip, &legend, 13)?;
            Ok(())
        })?;
        let panel_list: Vec<&str> = panels.iter().map(|p| p.title.as_str()).collect();
        out.push(FigureFile {
            path,
            link: format!("figures/{name}"),
            caption: format!(
                "{}: {} vs exploration epochs ({}); curves: the mean over repetitions (n in the \
                 legend: repetitions × exploration replicates); right of each panel: the final \
                 value, mean and 95% t interval over the repetitions{}",
                env_name(env),
                metric.name(),
                panel_list.join("; "),
                match metric {
                    Metric::Klc => ", and the paper's single-run value (star)",
                    Metric::Coverage =>
                        "; the axis ends above the data: 100% would be every achievable cell \
                         (on ArmArrow, every position cell with every angle bin)",
                }
            ),
            env: env.to_string(),
        });
    }
    Ok(out)
}

/// Baselines (latents 0) in every panel; one panel per latent size of the learned spaces.
fn panels_of<'a>(env: &str, conds: &[&'a ConditionSummary]) -> Vec<Panel<'a>> {
    let base: Vec<&ConditionSummary> = conds
        .iter()
        .copied()
        .filter(|c| c.key.latents == 0)
        .collect();
    let mut by_latents: BTreeMap<i64, Vec<&ConditionSummary>> = BTreeMap::new();
    for c in conds.iter().copied().filter(|c| c.key.latents != 0) {
        by_latents.entry(c.key.latents).or_default().push(c);
    }
    if by_latents.is_empty() {
        return vec![Panel {
            title: format!("{}, baselines", env_name(env)),
            members: base,
        }];
    }
    by_latents
        .into_iter()
        .map(|(l, learned)| {
            let mut members = base.clone();
            members.extend(learned);
            members.sort_by_key(|c| c.key.order_key());
            Panel {
                title: format!("{}, {l} latents", env_name(env)),
                members,
            }
        })
        .collect()
}

/// (colour/marker slot, dash pattern, filled marker).
type Style = (usize, Option<(i32, i32)>, bool);

/// Style of each member: (colour/marker slot, dash pattern, filled marker), stable within the
/// panel. The dash pattern follows the variant and sampler (faithful/none solid, corrected dashed,
/// Gaussian goals dotted), else the next one free for the algorithm.
fn styles(members: &[&ConditionSummary]) -> Vec<Style> {
    let mut unknown: Vec<&str> = members
        .iter()
        .map(|c| c.key.algo.as_str())
        .filter(|a| !super::style_algos().contains(a))
        .collect();
    unknown.sort_unstable();
    unknown.dedup();
    let mut used: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    members
        .iter()
        .map(|c| {
            let ui = unknown.iter().position(|a| *a == c.key.algo).unwrap_or(0);
            let slot = algo_slot(&c.key.algo, ui);
            let corrected = c.key.variant.is_dashed();
            let wanted = usize::from(corrected)
                + if c.key.sampler == ugl_types::Sampler::GAUSSIAN {
                    2
                } else {
                    0
                };
            let taken = used.entry(c.key.algo.as_str()).or_default();
            let k = (0..)
                .map(|i| wanted + i)
                .find(|k| !taken.contains(k))
                .expect("a free pattern");
            taken.push(k);
            let (_, filled) = marker_points(slot, 1.0);
            (slot, dash_pattern(k), filled && !corrected)
        })
        .collect()
}

/// The legend label of a condition within a panel: `RGE-VAE (corrected), n=5`. KDE goals are
/// the default of the learned spaces and not named; other samplers are.
fn label(c: &ConditionSummary) -> String {
    let mut s = condition_name(&c.key.algo, &c.key.variant);
    if c.key.sampler.is_learned() && c.key.sampler != ugl_types::Sampler::KDE {
        s.push_str(&format!(", {} goals", sampler_name(&c.key.sampler)));
    }
    s.push_str(&format!(", n={}", c.n_label()));
    if !super::algos().contains(&c.key.algo.as_str()) {
        s.push_str(" (not in the paper)");
    }
    s
}

/// The legend entries of a panel: one per condition with a finite mean somewhere, and the
/// paper's star when the panel shows a paper value.
fn panel_legend(panel: &Panel<'_>, metric: Metric) -> Vec<(Icon, String)> {
    let styles = styles(&panel.members);
    let mut items: Vec<(Icon, String)> = panel
        .members
        .iter()
        .zip(&styles)
        .filter(|(c, _)| metric.curve(c).iter().any(|p| p.mean.is_finite()))
        .map(|(c, &(slot, dash, filled))| {
            let (mpts, _) = marker_points(slot, 4.0);
            (
                Icon::Line {
                    colour: colour(slot),
                    dash,
                    width: 2,
                    marker: Some((mpts, filled)),
                },
                label(c),
            )
        })
        .collect();
    if panel.members.iter().any(|c| metric.paper(c).is_some()) {
        items.push(paper_star_item("paper: final value (1 run, read off plot)"));
    }
    items
}

/// The y range shared by the panels of a figure: what is drawn (the mean curves, the final
/// intervals and the paper's values), from the next 0.5 below its smallest value (KL-coverage;
/// the differences are a few tenths) or from 0 (coverage, a fraction), to the largest
/// KL-coverage possible or 5% above the data.
fn y_range(env: &str, panels: &[Panel<'_>], metric: Metric) -> (f64, f64) {
    let values = || {
        panels.iter().flat_map(|p| &p.members).flat_map(|c| {
            let curve = metric.curve(c);
            let last = curve
                .last()
                .and_then(|p| p.ci)
                .map_or([f64::NAN; 2], |ci| [ci.0, ci.1]);
            curve
                .iter()
                .map(|p| p.mean)
                .chain(last)
                .chain(metric.paper(c))
        })
    };
    let hi = values()
        .filter(|v| v.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    let lo = values()
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    let data_max = if hi.is_finite() && hi > 0.0 {
        hi * 1.05
    } else {
        1.0
    };
    match metric {
        Metric::Klc => {
            let y_max = klc_max(env).unwrap_or(data_max);
            let y_min = if lo.is_finite() {
                ((lo - 0.1) * 2.0).floor().max(0.0) / 2.0
            } else {
                0.0
            };
            (y_min.min(y_max - 0.5).max(0.0), y_max)
        }
        Metric::Coverage => (0.0, data_max),
    }
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    panel: &Panel<'_>,
    metric: Metric,
    (y_min, y_max): (f64, f64),
) -> Result<(), Box<dyn std::error::Error>> {
    let x_last = panel
        .members
        .iter()
        .map(|c| c.last_epoch())
        .max()
        .unwrap_or(1)
        .max(1) as f64;
    let x_range = -0.01 * x_last..x_last * 1.02;
    let (curves_area, strip_area) = area.split_horizontally(PANEL_W - STRIP_W);
    let y_fmt = |v: &f64| match metric {
        Metric::Klc => format!("{v:.1}"),
        Metric::Coverage => format!("{:.0}%", v * 100.0),
    };

    let mut chart = ChartBuilder::on(&curves_area)
        .caption(&panel.title, (FONT, 17))
        .margin(12)
        .margin_right(4)
        .x_label_area_size(42)
        .y_label_area_size(56)
        .build_cartesian_2d(x_range, y_min..y_max)?;
    chart
        .configure_mesh()
        .x_desc("exploration epochs")
        .y_desc(metric.y_desc())
        .x_label_formatter(&fmt_epoch)
        .y_label_formatter(&y_fmt)
        .x_labels(8)
        .y_labels(8)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .max_light_lines(4)
        .light_line_style(RGBColor(0xEE, 0xEE, 0xEE))
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;

    let clamp = |v: f64| {
        if v.is_nan() { v } else { v.clamp(y_min, y_max) }
    };
    let styles = styles(&panel.members);

    for (i, (c, &(slot, dash, filled))) in panel.members.iter().zip(&styles).enumerate() {
        let col = colour(slot);
        let (mpts, _) = marker_points(slot, 4.0);
        let (dash_len, gap) = dash.unwrap_or((SOLID, 0));
        let line_style = col.stroke_width(2);

        // Finite means only; an infinite mean breaks the line.
        let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for p in metric.curve(c) {
            if p.mean.is_finite() {
                segments
                    .last_mut()
                    .unwrap()
                    .push((p.epoch as f64, clamp(p.mean)));
            } else if !segments.last().unwrap().is_empty() {
                segments.push(Vec::new());
            }
        }
        segments.retain(|s| !s.is_empty());
        for seg in &segments {
            chart.draw_series(std::iter::once(DashedPathElement::new(
                seg.clone(),
                dash_len,
                gap,
                line_style,
            )))?;
        }

        // Markers on about 8 points per curve, staggered between curves.
        let finite: Vec<(f64, f64)> = segments.iter().flatten().copied().collect();
        let step = (finite.len() / 8).max(1);
        let offset = if step > 1 {
            (i * step / panel.members.len().max(1)) % step
        } else {
            0
        };
        chart.draw_series(
            finite
                .iter()
                .skip(offset)
                .step_by(step)
                .map(|&pt| marker(pt, &mpts, filled, col, 1)),
        )?;
    }

    // The final values: one column per condition, in the legend's order.
    let columns: Vec<FinalColumn> = panel
        .members
        .iter()
        .zip(&styles)
        .map(|(c, &(slot, _, filled))| {
            let last = metric.curve(c).last();
            FinalColumn {
                colour: colour(slot),
                marker: (marker_points(slot, 4.5).0, filled),
                mean: last.map_or(f64::NAN, |p| p.mean),
                interval: last.and_then(|p| p.ci),
                paper: metric.paper(c),
            }
        })
        .collect();
    draw_final_strip(
        &strip_area,
        &columns,
        (y_min, y_max),
        "final",
        &format!("epoch {}", fmt_epoch(&x_last)),
    )?;
    Ok(())
}
