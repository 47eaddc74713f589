//! The paper's Figure 4: RGE-VAE exploring with goals from a KDE of the training latents against
//! goals from the VAE's isotropic Gaussian prior N(0, I), in four panels (ArmBall 10 / 2 latents,
//! ArmArrow 10 / 3 latents). As in the paper ("mean and standard deviation over 5 independent
//! runs"), the spread shown is ±1 sd over the repetitions (not the t interval of the other curve
//! figures), at the final epoch in a strip beside each panel
//! ([`super::final_strip`]; bands around the four curves covered each other). Our two variants are both drawn: faithful solid with filled markers, corrected
//! dashed with hollow markers; KDE blue circles, Gaussian vermillion triangles.
//!
//! The same figure for another algorithm (RGE-RFVAE, which the paper did not plot) is drawn when
//! its Gaussian-goal runs exist.

use std::path::Path;

use plotters::prelude::*;

use super::final_strip::{FinalColumn, draw_final_strip};
use super::{
    FONT, FigureFile, Icon, LineStyle, dedup_legend, draw_curve, env_name, fmt_epoch, klc_max,
    legend_height, legend_strip, marker_points, panel_order, paper_star_item, sampler_colour,
    sampler_marker_slot, sampler_name, variant_dash, variant_filled, write_svg,
};
use crate::aggregate::ConditionSummary;
use crate::error::ReportError;
use crate::names::algo_name;

const PANEL_W: u32 = 720;
/// Width of a panel's final-value strip, out of [`PANEL_W`].
const STRIP_W: u32 = 130;
const PANEL_H: u32 = 440;
const TITLE_H: u32 = 36;
/// The samplers compared, in legend order.
pub const SAMPLERS: [ugl_types::Sampler; 2] =
    [ugl_types::Sampler::KDE, ugl_types::Sampler::GAUSSIAN];
/// The variants, in legend order (`none` for learners without variants).
pub const VARIANTS: [ugl_types::Variant; 3] = [
    ugl_types::Variant::NONE,
    ugl_types::Variant::FAITHFUL,
    ugl_types::Variant::CORRECTED,
];

/// One panel: an environment and latent size, with the conditions of the algorithm drawn there.
#[derive(Debug, Clone)]
pub struct SamplerPanel<'a> {
    pub env: String,
    pub latents: i64,
    /// (sampler, variant, condition), in [`SAMPLERS`] then [`VARIANTS`] order.
    pub members: Vec<(&'a str, &'a str, &'a ConditionSummary)>,
}

impl SamplerPanel<'_> {
    pub fn title(&self) -> String {
        format!("{}, {} latents", env_name(&self.env), self.latents)
    }

    /// The member with this sampler and variant.
    pub fn get(&self, sampler: &str, variant: &str) -> Option<&ConditionSummary> {
        self.members
            .iter()
            .find(|(s, v, _)| *s == sampler && *v == variant)
            .map(|m| m.2)
    }
}

/// The panels of `algo`: every (env, latents) where it ran with KDE or Gaussian goals, in the
/// paper's order (ArmBall before ArmArrow, 10 latents before the true dimension).
pub fn panels<'a>(conditions: &'a [ConditionSummary], algo: &str) -> Vec<SamplerPanel<'a>> {
    let mut out: Vec<SamplerPanel<'a>> = Vec::new();
    for c in conditions.iter().filter(|c| c.key.algo == algo) {
        if !SAMPLERS.contains(&c.key.sampler) || !VARIANTS.contains(&c.key.variant) {
            continue;
        }
        let (s, v) = (c.key.sampler.as_str(), c.key.variant.as_str());
        match out
            .iter_mut()
            .find(|p| p.env == c.key.env && p.latents == c.key.latents)
        {
            Some(p) => p.members.push((s, v, c)),
            None => out.push(SamplerPanel {
                env: c.key.env.clone(),
                latents: c.key.latents,
                members: vec![(s, v, c)],
            }),
        }
    }
    out.sort_by_key(|p| panel_order(&p.env, p.latents));
    for p in &mut out {
        p.members.sort_by_key(|(s, v, _)| {
            (
                SAMPLERS.iter().position(|x| x == s),
                VARIANTS.iter().position(|x| x == v),
            )
        });
    }
    out
}

/// Whether `algo` has Gaussian-goal runs (the figure is about nothing otherwise).
pub fn has_gaussian(conditions: &[ConditionSummary], algo: &str) -> bool {
    conditions
        .iter()
        .any(|c| c.key.algo == algo && c.key.sampler == ugl_types::Sampler::GAUSSIAN)
}

/// Draws `fig_dir/<name>` for `algo` if it has Gaussian-goal runs; 2 panels a row.
pub fn draw(
    conditions: &[ConditionSummary],
    algo: &str,
    name: &str,
    fig_dir: &Path,
) -> Result<Option<FigureFile>, ReportError> {
    if !has_gaussian(conditions, algo) {
        return Ok(None);
    }
    let panels = panels(conditions, algo);
    let cols = panels.len().min(2);
    let rows = panels.len().div_ceil(2);
    let path = fig_dir.join(name);
    let title = format!(
        "{}: KDE vs Gaussian goals, mean over repetitions; right: final value ± 1 sd",
        algo_name(algo)
    );
    let width = PANEL_W * cols as u32;
    // One legend for all panels, under them (no legend hides a curve).
    let legend = dedup_legend(panels.iter().flat_map(panel_legend).collect());
    let legend_h = legend_height(width, &legend, 13);
    write_svg(
        &path,
        (width, PANEL_H * rows as u32 + TITLE_H + legend_h),
        |root| {
            let area = root.titled(&title, (FONT, 18))?;
            let (plots, strip) = area.split_vertically(PANEL_H * rows as u32);
            let areas = plots.split_evenly((rows, cols));
            for (p, a) in panels.iter().zip(areas.iter()) {
                draw_panel(a, p)?;
            }
            legend_strip(&strip, &legend, 13)?;
            Ok(())
        },
    )?;
    let titles: Vec<String> = panels.iter().map(SamplerPanel::title).collect();
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{name}"),
        caption: format!(
            "{}: KL-coverage with KDE vs Gaussian goals, faithful solid, corrected dashed ({}); \
             curves: the mean over repetitions (n in the legend: repetitions × exploration \
             replicates); right of each panel: the final mean ± 1 sd over the repetitions, as the \
             paper's Figure 4, and the paper's single-run value of the faithful variant (star; the \
             KDE values of the panels its Figure 4 does not show are its Figure 2's)",
            algo_name(algo),
            titles.join("; ")
        ),
        env: String::new(),
    }))
}

/// The legend entries of a panel: one per curve, and the paper's star when the panel has one.
fn panel_legend(panel: &SamplerPanel<'_>) -> Vec<(Icon, String)> {
    let mut items: Vec<(Icon, String)> = panel
        .members
        .iter()
        .map(|&(sampler, variant, c)| {
            let (mpts, _) = marker_points(sampler_marker_slot(sampler), 4.5);
            (
                Icon::Line {
                    colour: sampler_colour(sampler),
                    dash: variant_dash(variant),
                    width: 2,
                    marker: Some((mpts, variant_filled(variant))),
                },
                label(sampler, variant, c),
            )
        })
        .collect();
    if panel.members.iter().any(|(_, _, c)| c.paper.is_some()) {
        items.push(paper_star_item(
            "paper: final value (1 run, read off its Figures 2 and 4)",
        ));
    }
    items
}

/// Legend label: `KDE goals, faithful, n=5`.
fn label(sampler: &str, variant: &str, c: &ConditionSummary) -> String {
    let mut s = format!("{} goals", sampler_name(sampler));
    if *variant != ugl_types::Variant::NONE {
        s.push_str(&format!(", {variant}"));
    }
    s.push_str(&format!(", n={}", c.n_label()));
    s
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    panel: &SamplerPanel<'_>,
) -> Result<(), Box<dyn std::error::Error>> {
    let x_last = panel
        .members
        .iter()
        .map(|m| m.2.last_epoch())
        .max()
        .unwrap_or(1)
        .max(1) as f64;
    let final_sd = |c: &ConditionSummary| {
        c.curve.last().and_then(|p| match p.std {
            Some(sd) if p.mean.is_finite() => Some((p.mean - sd, p.mean + sd)),
            _ => None,
        })
    };
    let finite = panel
        .members
        .iter()
        .flat_map(|m| {
            let (lo, hi) = final_sd(m.2).unwrap_or((f64::NAN, f64::NAN));
            m.2.curve
                .iter()
                .map(|p| p.mean)
                .chain([lo, hi])
                .chain(paper_value(m))
        })
        .filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let y_max = klc_max(&panel.env).unwrap_or(if hi.is_finite() { hi * 1.05 } else { 1.0 });
    // Zoom on the curves: the bottom of the axis just under the lowest value.
    let y_min = if lo.is_finite() {
        (lo - 0.08 * (y_max - lo)).max(0.0).min(y_max - 0.5)
    } else {
        0.0
    };
    let (curves_area, strip_area) = area.split_horizontally(PANEL_W - STRIP_W);
    let mut chart = ChartBuilder::on(&curves_area)
        .caption(panel.title(), (FONT, 17))
        .margin(12)
        .margin_right(4)
        .x_label_area_size(42)
        .y_label_area_size(56)
        .build_cartesian_2d(-0.01 * x_last..x_last * 1.02, y_min..y_max)?;
    chart
        .configure_mesh()
        .x_desc("exploration epochs")
        .y_desc("KL-coverage (nats, lower is better)")
        .x_label_formatter(&fmt_epoch)
        .y_label_formatter(&|v| format!("{v:.1}"))
        .x_labels(8)
        .y_labels(8)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .max_light_lines(4)
        .light_line_style(RGBColor(0xEE, 0xEE, 0xEE))
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;

    let n = panel.members.len().max(1);
    let mut off = super::OffScaleMarks::default();
    let mut columns = Vec::new();
    for (i, m) in panel.members.iter().enumerate() {
        let &(sampler, variant, c) = m;
        let (mpts, _) = marker_points(sampler_marker_slot(sampler), 4.5);
        let style = LineStyle {
            colour: sampler_colour(sampler),
            dash: variant_dash(variant),
            marker: (mpts, variant_filled(variant)),
            width: 2,
        };
        // Means are not clamped: one outside the axis is marked at the frame with its value.
        let pts: Vec<(f64, f64)> = c.curve.iter().map(|p| (p.epoch as f64, p.mean)).collect();
        off.extend(draw_curve(
            &mut chart,
            &pts,
            &style,
            i as f64 / n as f64,
            None,
        )?);
        columns.push(FinalColumn {
            colour: style.colour,
            marker: style.marker.clone(),
            mean: c.curve.last().map_or(f64::NAN, |p| p.mean),
            interval: final_sd(c),
            paper: paper_value(m),
        });
    }
    super::draw_off_scale(&mut chart, &off)?;
    draw_final_strip(
        &strip_area,
        &columns,
        (y_min, y_max),
        "final",
        &format!("epoch {}, ± 1 sd", fmt_epoch(&x_last)),
    )?;
    Ok(())
}

/// The paper's single-run value drawn beside a member: the paper ran its original code, our
/// faithful variant (or a learner without variants), so the corrected variant gets none.
fn paper_value(m: &(&str, &str, &ConditionSummary)) -> Option<f64> {
    let (_, variant, c) = m;
    (!crate::names::variant_dashed(variant))
        .then(|| c.paper.as_ref().map(|p| p.klc))
        .flatten()
}
