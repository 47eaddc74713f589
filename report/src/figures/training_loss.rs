//! Recorded training losses (`training_loss.svg`): for each environment (rows) and neural learner
//! (columns), the mean loss over the trainings of the main campaign against the iteration, one
//! curve per latent size and variant (faithful solid, corrected dashed). The loss is the one each
//! learner minimises (PAPER-NOTES section 5: pixel-summed Bernoulli cross-entropy, plus the KL
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
    FONT, FigureFile, LineStyle, draw_curve, env_name, learner_name, marker_points, variant_dash,
    variant_filled, write_svg,
};
use crate::ReportError;
use crate::load::rank;
use crate::neural::{LEARNERS, LossCurve};

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
    learners.sort_by_key(|l| (rank(l, &LEARNERS), l.to_string()));
    let path = fig_dir.join(FILE);
    let (rows, cols) = (envs.len(), learners.len());
    write_svg(
        &path,
        (PANEL_W * cols as u32, PANEL_H * rows as u32 + TITLE_H),
        |root| {
            let area = root.titled(
                "Training loss of the neural learners, mean over trainings",
                (FONT, 18),
            )?;
            let areas = area.split_evenly((rows, cols));
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
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{FILE}"),
        caption: "Training loss of the AE, VAE and RFVAE against the iteration (mean over the \
                  main campaign's trainings)"
            .into(),
        env: String::new(),
    }))
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    env: &str,
    learner: &str,
    curves: &[&LossCurve],
) -> Result<(), Box<dyn std::error::Error>> {
    let title = format!("{}, {}", env_name(env), learner_name(learner));
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
        chart
            .draw_series(std::iter::once(DashedPathElement::new(
                vec![(0.0, p), (x_hi, p)],
                3,
                4,
                RGBColor(0x77, 0x77, 0x77).stroke_width(1),
            )))?
            .label(format!("mean-image loss (plateau) {p:.0}"))
            .legend(|(x, y)| {
                DashedPathElement::new(
                    vec![(x, y), (x + 20, y)],
                    3,
                    4,
                    RGBColor(0x77, 0x77, 0x77).stroke_width(1),
                )
            });
    }
    let n = curves.len().max(1);
    for (i, c) in curves.iter().enumerate() {
        let slot = if Some(c.latents) == super::true_latents(env) {
            2
        } else {
            0
        };
        let (mpts, _) = marker_points(slot, 4.0);
        let style = LineStyle {
            colour: latents_colour(env, c.latents),
            dash: variant_dash(&c.variant),
            marker: (mpts, variant_filled(&c.variant)),
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
        let mut label = format!("{} latents", c.latents);
        if c.variant != "none" {
            label.push_str(&format!(", {}", c.variant));
        }
        label.push_str(&format!(
            " ({} training{})",
            c.trainings,
            if c.trainings == 1 { "" } else { "s" }
        ));
        draw_curve(&mut chart, &pts, &style, i as f64 / n as f64, Some(label))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .legend_area_size(30)
        .margin(6)
        .label_font((FONT, 12))
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(0x99, 0x99, 0x99))
        .draw()?;
    Ok(())
}
