//! Recorded training losses (`training_loss.svg`): for each environment (rows) and neural learner
//! (columns), the mean loss over the trainings of the main campaign against the iteration, one
//! curve per latent size and variant (faithful solid, corrected dashed). The loss is the one each
//! learner minimises (docs/original-code.md section 5: pixel-summed Bernoulli cross-entropy, plus the KL
//! for the VAE, minus the flows' log-determinant for the RFVAE), so levels differ between
//! learners; the y axis starts after the first recorded point, which can be far above the rest.
//! A dotted grey line marks the mean-image loss of the training images (the *plateau*, the loss of
//! the best constant prediction): a network whose loss stays on it learned nothing. (The RFVAE's
//! loss subtracts the flows' log-determinant, so it can sit below the plateau without having
//! learned; its evidence of training is the reconstruction loss, "Did the goal spaces learn?".)

use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::{
    FONT, FigureFile, Icon, LineStyle, dedup_legend, draw_curve, env_name, learner_name,
    legend_height, legend_strip, marker_points, variant_dash, variant_filled, write_svg,
};
use crate::ReportError;
use crate::load::rank;
use crate::neural::{self, LossCurve};

pub const FILE: &str = "training_loss.svg";
const PANEL_W: u32 = 480;
const PANEL_H: u32 = 380;
const TITLE_H: u32 = 36;

/// Colour of a latent size: the over-complete 10 (and any other) blue, the true dimension orange.
fn latents_colour(env: &str, latents: i64) -> RGBColor {
    if Some(latents) == super::true_latents(env) {
        RGBColor(0xE6, 0x9F, 0x00)
    } else {
        RGBColor(0x00, 0x72, 0xB2)
    }
}

/// The plateau's reference line.
const PLATEAU_GREY: RGBColor = RGBColor(0x77, 0x77, 0x77);

/// (colour, marker points, dash, filled marker) of a curve: colour and marker by latent size,
/// dash and fill by variant.
fn curve_style(
    env: &str,
    latents: i64,
    variant: &str,
) -> (RGBColor, Vec<(i32, i32)>, Option<(i32, i32)>, bool) {
    let slot = if Some(latents) == super::true_latents(env) {
        2
    } else {
        0
    };
    let (mpts, _) = marker_points(slot, 4.0);
    (
        latents_colour(env, latents),
        mpts,
        variant_dash(variant),
        variant_filled(variant),
    )
}

/// The legend label of a curve's style: `10 latents, corrected`, `true dimension, faithful`.
fn curve_label(env: &str, latents: i64, variant: &str) -> String {
    let mut label = if Some(latents) == super::true_latents(env) {
        "true dimension".to_string()
    } else {
        format!("{latents} latents")
    };
    if variant != "none" {
        label.push_str(&format!(", {variant}"));
    }
    label
}

/// Draws the figure; `None` when no run recorded a loss.
pub fn draw(curves: &[LossCurve], fig_dir: &Path) -> Result<Option<FigureFile>, ReportError> {
    if curves.is_empty() {
        return Ok(None);
    }
    let mut envs: Vec<&str> = Vec::new();
    let mut learners: Vec<&str> = Vec::new();
    for c in curves {
        if !envs.contains(&c.env.as_str()) {
            envs.push(&c.env);
        }
        if !learners.contains(&c.learner.as_str()) {
            learners.push(&c.learner);
        }
    }
    let order = neural::learners();
    learners.sort_by_key(|l| (rank(l, &order), l.to_string()));
    let path = fig_dir.join(FILE);
    let (rows, cols) = (envs.len(), learners.len());
    let width = PANEL_W * cols as u32;
    // One legend for all panels, under them (no legend hides a curve).
    let mut legend: Vec<(Icon, String)> = curves
        .iter()
        .map(|c| {
            let (colour, mpts, dash, filled) = curve_style(&c.env, c.latents, &c.variant);
            (
                Icon::Line {
                    colour,
                    dash,
                    width: 2,
                    marker: Some((mpts, filled)),
                },
                curve_label(&c.env, c.latents, &c.variant),
            )
        })
        .collect();
    legend.sort_by(|a, b| a.1.cmp(&b.1));
    let mut legend = dedup_legend(legend);
    legend.push((
        Icon::Line {
            colour: PLATEAU_GREY,
            dash: Some((3, 4)),
            width: 1,
            marker: None,
        },
        "mean-image loss (the plateau; its value in each panel's title)".into(),
    ));
    let legend_h = legend_height(width, &legend, 13);
    write_svg(
        &path,
        (width, PANEL_H * rows as u32 + TITLE_H + legend_h),
        |root| {
            let area = root.titled(
                "Training loss of the neural learners, mean over trainings",
                (FONT, 18),
            )?;
            let (plots, strip) = area.split_vertically(PANEL_H * rows as u32);
            legend_strip(&strip, &legend, 13)?;
            let areas = plots.split_evenly((rows, cols));
            for (i, env) in envs.iter().enumerate() {
                for (j, l) in learners.iter().enumerate() {
                    let of: Vec<&LossCurve> = curves
                        .iter()
                        .filter(|c| c.env == *env && c.learner == *l)
                        .collect();
                    draw_panel(&areas[i * cols + j], env, l, &of)?;
                }
            }
            Ok(())
        },
    )?;
    let mut trainings: Vec<usize> = curves.iter().map(|c| c.trainings).collect();
    trainings.sort_unstable();
    trainings.dedup();
    let per_curve = match (trainings.first(), trainings.last()) {
        (Some(a), Some(b)) if a == b => format!("{a}"),
        (Some(a), Some(b)) => format!("{a}-{b}"),
        _ => "0".into(),
    };
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{FILE}"),
        caption: format!(
            "Training loss of the AE, VAE and RFVAE against the iteration (mean over the main \
             campaign's trainings, {per_curve} per curve)"
        ),
        env: String::new(),
    }))
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    env: &str,
    learner: &str,
    curves: &[&LossCurve],
) -> Result<(), Box<dyn std::error::Error>> {
    let mut title = format!("{}, {}", env_name(env), learner_name(learner));
    if curves.is_empty() {
        area.draw(&Text::new(
            format!("{title}: no recorded loss"),
            (20, 30),
            (FONT, 14),
        ))?;
        return Ok(());
    }
    let x_hi = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.0))
        .max()
        .unwrap_or(1)
        .max(1) as f64;
    // Cut the first recorded point only where each curve has a body after it.
    let skip = usize::from(curves.iter().all(|c| c.points.len() >= 3));
    let body: Vec<f64> = curves
        .iter()
        .flat_map(|c| c.points.iter().skip(skip).map(|p| p.1))
        .filter(|v| v.is_finite())
        .collect();
    let plateaus: Vec<f64> = curves.iter().filter_map(|c| c.plateau).collect();
    let plateau = (!plateaus.is_empty())
        .then(|| plateaus.iter().sum::<f64>() / plateaus.len() as f64)
        .filter(|v| v.is_finite());
    let all: Vec<f64> = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.1))
        .chain(plateau)
        .filter(|v| v.is_finite())
        .collect();
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = if body.is_empty() { &all } else { &body }
        .iter()
        .copied()
        .chain(plateau)
        .fold(f64::NEG_INFINITY, f64::max);
    if let Some(p) = plateau {
        title.push_str(&format!(" (plateau {p:.0})"));
    }
    let (lo, hi) = if lo.is_finite() && hi.is_finite() && hi > lo {
        (lo, hi)
    } else if lo.is_finite() {
        (lo - 1.0, lo + 1.0)
    } else {
        (0.0, 1.0)
    };
    let pad = (hi - lo) * 0.06;
    let (y_min, y_max) = (lo - pad, hi + pad);
    // Enough decimals to tell the ticks apart.
    let decimals = (-((y_max - y_min) / 7.0).log10()).ceil().clamp(0.0, 6.0) as usize;
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 16))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.01 * x_hi..x_hi * 1.03, y_min..y_max)?;
    chart
        .configure_mesh()
        .x_desc("training iteration")
        .y_desc("loss")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.decimals$}"))
        .x_labels(6)
        .y_labels(7)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .max_light_lines(2)
        .light_line_style(RGBColor(0xF0, 0xF0, 0xF0))
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;
    if let Some(p) = plateau {
        chart.draw_series(std::iter::once(DashedPathElement::new(
            vec![(0.0, p), (x_hi, p)],
            3,
            4,
            PLATEAU_GREY.stroke_width(1),
        )))?;
    }
    let n = curves.len().max(1);
    for (i, c) in curves.iter().enumerate() {
        let (colour, mpts, dash, filled) = curve_style(env, c.latents, &c.variant);
        let style = LineStyle {
            colour,
            dash,
            marker: (mpts, filled),
            width: 2,
        };
        let pts: Vec<(f64, f64)> = c
            .points
            .iter()
            .map(|&(it, v)| {
                (
                    it as f64,
                    if v.is_finite() {
                        v.clamp(y_min, y_max)
                    } else {
                        v
                    },
                )
            })
            .collect();
        draw_curve(&mut chart, &pts, &style, i as f64 / n as f64, None)?;
    }
    Ok(())
}
