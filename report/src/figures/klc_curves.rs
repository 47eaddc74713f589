//! KL-coverage against exploration epochs, like the paper's Figure 2: one figure per environment,
//! one panel per latent size of the learned goal spaces (the baselines RPE and RGE-EFR, which have
//! no latent size, appear in every panel, as in the paper), one curve per condition: the mean over
//! seeds with its shaded 95% t-interval band ([`crate::stats::CONFIDENCE`]). The paper's final value is a hollow star at the
//! condition's last epoch.
//!
//! As the paper's figure (its notebook filtered `sampling != 'normal'`), the Gaussian-goal runs are
//! left out: they have their own figure ([`super::sampler_compare`], the paper's Figure 4).
//! Colour and marker shape identify the algorithm; the corrected variant is dashed with hollow
//! markers, the faithful one solid with filled markers.

use std::collections::BTreeMap;
use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::{
    FONT, FigureFile, Icon, SOLID, algo_slot, colour, condition_name, dash_pattern, dedup_legend,
    env_name, file_safe, fmt_epoch, klc_max, legend_height, legend_strip, marker, marker_points,
    paper_star_item, sampler_name, star_points, write_svg,
};
use crate::ReportError;
use crate::aggregate::{ConditionSummary, CurveStat};

const PANEL_W: u32 = 620;
const PANEL_H: u32 = 520;
const TITLE_H: u32 = 36;

/// Whether a condition belongs in this figure: every goal sampler but the Gaussian prior.
pub fn in_figure(c: &ConditionSummary) -> bool {
    c.key.sampler != "gaussian"
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
                "{}: {}, mean over seeds with 95% t interval",
                env_name(env),
                metric.name()
            );
            let area = root.titled(&title, (FONT, 18))?;
            let (plots, strip) = area.split_vertically(PANEL_H);
            let areas = plots.split_evenly((1, panels.len()));
            for (panel, a) in panels.iter().zip(areas.iter()) {
                draw_panel(a, env, panel, metric)?;
            }
            legend_strip(&strip, &legend, 13)?;
            Ok(())
        })?;
        let panel_list: Vec<&str> = panels.iter().map(|p| p.title.as_str()).collect();
        out.push(FigureFile {
            path,
            link: format!("figures/{name}"),
            caption: format!(
                "{}: {} vs exploration epochs ({})",
                env_name(env),
                metric.name(),
                panel_list.join("; ")
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
        .filter(|a| !super::algos().contains(a))
        .collect();
    unknown.sort_unstable();
    unknown.dedup();
    let mut used: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    members
        .iter()
        .map(|c| {
            let ui = unknown.iter().position(|a| *a == c.key.algo).unwrap_or(0);
            let slot = algo_slot(&c.key.algo, ui);
            let corrected = c.key.variant == "corrected";
            let wanted = usize::from(corrected) + if c.key.sampler == "gaussian" { 2 } else { 0 };
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
    if !matches!(c.key.sampler.as_str(), "none" | "uniform" | "kde") {
        s.push_str(&format!(", {} goals", sampler_name(&c.key.sampler)));
    }
    s.push_str(&format!(", n={}", c.seeds.len()));
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

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    env: &str,
    panel: &Panel<'_>,
    metric: Metric,
) -> Result<(), Box<dyn std::error::Error>> {
    let x_last = panel
        .members
        .iter()
        .map(|c| c.last_epoch())
        .max()
        .unwrap_or(1)
        .max(1) as f64;
    let data_max = || {
        let m = panel
            .members
            .iter()
            .flat_map(|c| {
                metric
                    .curve(c)
                    .iter()
                    .map(|p| p.ci.map_or(p.mean, |ci| ci.1))
                    .chain(metric.paper(c))
            })
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        if m > 0.0 { m * 1.05 } else { 1.0 }
    };
    let y_max = match metric {
        Metric::Klc => klc_max(env).unwrap_or_else(data_max),
        Metric::Coverage => data_max(),
    };
    let x_range = -0.01 * x_last..x_last * 1.04;
    // The y axis spans the data (bands and the paper's values), down to the next 0.5 below
    // their smallest value, not from 0: the differences between conditions are a few tenths.
    let y_min = panel
        .members
        .iter()
        .flat_map(|c| {
            metric
                .curve(c)
                .iter()
                .map(|p| p.ci.map_or(p.mean, |ci| ci.0.min(p.mean)))
                .chain(metric.paper(c))
        })
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    let y_min = if y_min.is_finite() {
        ((y_min - 0.1) * 2.0).floor().max(0.0) / 2.0
    } else {
        0.0
    };
    let y_min = match metric {
        Metric::Klc => y_min.min(y_max - 0.5).max(0.0),
        // Coverage is a fraction: from 0.
        Metric::Coverage => 0.0,
    };

    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FONT, 17))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(56)
        .build_cartesian_2d(x_range, y_min..y_max)?;
    chart
        .configure_mesh()
        .x_desc("exploration epochs")
        .y_desc(metric.y_desc())
        .x_label_formatter(&fmt_epoch)
        .y_label_formatter(&|v| match metric {
            Metric::Klc => format!("{v:.1}"),
            Metric::Coverage => format!("{:.0}%", v * 100.0),
        })
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

    // Bands first, so that every line is drawn over every band.
    for (c, &(slot, _, _)) in panel.members.iter().zip(&styles) {
        // Epochs without an interval (one run, an infinite value) have no band.
        let pts: Vec<(f64, f64, f64)> = metric
            .curve(c)
            .iter()
            .filter_map(|p| p.ci.map(|(lo, hi)| (p.epoch as f64, lo, hi)))
            .collect();
        if pts.len() < 2 || pts.iter().all(|p| p.1 == p.2) {
            continue;
        }
        let mut poly: Vec<(f64, f64)> = pts.iter().map(|p| (p.0, clamp(p.2))).collect();
        poly.extend(pts.iter().rev().map(|p| (p.0, clamp(p.1))));
        chart.draw_series(std::iter::once(Polygon::new(
            poly,
            colour(slot).mix(0.14).filled(),
        )))?;
    }

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

    // The paper's single-run values, at the last epoch of each condition.
    let star = star_points(8.0, 3.5);
    for (c, &(slot, _, _)) in panel.members.iter().zip(&styles) {
        if let Some(p) = metric.paper(c) {
            let at = (c.last_epoch() as f64, clamp(p));
            chart.draw_series(std::iter::once(marker(at, &star, false, colour(slot), 2)))?;
        }
    }
    Ok(())
}
