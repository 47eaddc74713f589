//! Recorded training losses (`training_loss.svg`): for each environment (rows) and neural learner
//! (columns), the mean loss over the trainings of the main campaign against the iteration, one
//! curve per latent size and variant (faithful solid, corrected dashed). The loss is the one each
//! learner minimises (docs/original-code.md section 5: pixel-summed Bernoulli cross-entropy, in
//! nats per image, plus the KL for the VAE; the RFVAE's is annealed and minus the flows'
//! log-determinant), so levels differ between learners. The y axis spans every point unless the
//! first recorded one is far above the rest: then that point is an arrow at the top edge with its
//! value printed, never a marker clamped to the edge as if it were data.
//! A dotted grey line marks the mean-image loss of the training images (the *plateau*, the loss of
//! the best constant prediction): a network whose loss stays on it learned nothing. The RFVAE's
//! panels have no plateau line: its loss weights the cross-entropy and the KL by an annealing
//! factor (0.01 at the start) and subtracts the flows' log-determinant, so it is not on the
//! plateau's scale; its evidence of training is the reconstruction loss ("Did the goal spaces
//! learn?").

use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::{
    FONT, FigureFile, Icon, LineStyle, draw_curve, env_name, learner_name, legend_height,
    legend_strip, marker_points, variant_dash, variant_filled, write_svg,
};
use crate::error::ReportError;
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

/// The style of a curve: colour and marker by latent size, dash and fill by variant.
fn curve_style(env: &str, latents: i64, variant: &str) -> LineStyle {
    let slot = if Some(latents) == super::true_latents(env) {
        2
    } else {
        0
    };
    let (mpts, _) = marker_points(slot, 4.0);
    LineStyle {
        colour: latents_colour(env, latents),
        dash: variant_dash(variant),
        marker: (mpts, variant_filled(variant)),
        width: 2,
    }
}

/// The legend label of a latent size: `10 latents`, `true dimension`.
fn size_label(env: &str, latents: i64) -> String {
    if Some(latents) == super::true_latents(env) {
        "true dimension".to_string()
    } else {
        format!("{latents} latents")
    }
}

/// Whether a learner's loss is on the plateau's scale: not the RFVAE's, which is annealed (its
/// cross-entropy and KL weighted by min(1, 0.01 + step/1e4)) and minus the flows' log-determinant.
fn has_plateau(learner: &str) -> bool {
    learner != ugl_types::learners::RFVAE.name
}

/// The legend: one entry per drawn style. The AE has no variant (`none`) and is drawn as the
/// faithful variant of the others (solid, filled): one entry says both. Ordered by latent size
/// (as the curves' colours), then faithful before corrected.
fn legend_items(curves: &[LossCurve]) -> Vec<(Icon, String)> {
    let mut groups: Vec<(LineStyle, String, i64, bool, Vec<&str>)> = Vec::new();
    for c in curves {
        let style = curve_style(&c.env, c.latents, &c.variant);
        match groups.iter_mut().find(|g| g.0 == style) {
            Some(g) => {
                if !g.4.contains(&c.variant.as_str()) {
                    g.4.push(&c.variant);
                }
            }
            None => groups.push((
                style,
                size_label(&c.env, c.latents),
                c.latents,
                c.variant == ugl_types::Variant::CORRECTED,
                vec![&c.variant],
            )),
        }
    }
    groups.sort_by(|a, b| {
        (a.1 == "true dimension", a.2, a.3).cmp(&(b.1 == "true dimension", b.2, b.3))
    });
    groups
        .into_iter()
        .map(|(style, size, _, _, variants)| {
            let none = variants.iter().any(|v| *v == ugl_types::Variant::NONE);
            let named: Vec<&str> = variants
                .iter()
                .copied()
                .filter(|v| *v != ugl_types::Variant::NONE)
                .collect();
            let label = match (named.is_empty(), none) {
                (true, _) => size,
                (false, false) => format!("{size}, {}", named.join(", ")),
                (false, true) => format!("{size}, {} (and the AE, no variant)", named.join(", ")),
            };
            style.legend_item(label)
        })
        .collect()
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
    let mut legend = legend_items(curves);
    let with_plateau = curves
        .iter()
        .any(|c| c.plateau.is_some() && has_plateau(&c.learner));
    if with_plateau {
        legend.push((
            Icon::Line {
                colour: PLATEAU_GREY,
                dash: Some((3, 4)),
                width: 1,
                marker: None,
            },
            "mean-image loss (the plateau; its value in each panel's title; none for the RFVAE, \
             whose loss is annealed and minus the flows' log-determinant)"
                .into(),
        ));
    }
    let off_scale = envs.iter().any(|env| {
        learners.iter().any(|l| {
            let of: Vec<&LossCurve> = curves
                .iter()
                .filter(|c| c.env == *env && c.learner == *l)
                .collect();
            let (lo, hi) = y_bounds(&of, plateau_of(&of, l)).0;
            of.iter()
                .flat_map(|c| c.points.iter())
                .any(|p| p.1.is_finite() && (p.1 < lo || p.1 > hi))
        })
    });
    if off_scale {
        legend.push((
            Icon::Marker {
                colour: RGBColor(0x44, 0x44, 0x44),
                points: super::off_scale_arrow(true),
                filled: true,
                stroke: 1,
            },
            "a mean above the axis (iteration 0): an arrow at the top edge, its value beside it"
                .into(),
        ));
    }
    let mut trainings: Vec<usize> = curves.iter().map(|c| c.trainings).collect();
    trainings.sort_unstable();
    trainings.dedup();
    let per_curve = match (trainings.first(), trainings.last()) {
        (Some(a), Some(b)) if a == b => format!("{a}"),
        (Some(a), Some(b)) => format!("{a}-{b}"),
        _ => "0".into(),
    };
    let legend_h = legend_height(width, &legend, 13);
    write_svg(
        &path,
        (width, PANEL_H * rows as u32 + TITLE_H + legend_h),
        |root| {
            let area = root.titled(
                &format!(
                    "Training loss of the neural learners, mean over {} trainings per curve",
                    per_curve
                ),
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
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{FILE}"),
        caption: format!(
            "Training loss of the AE, VAE and RFVAE (nats per image) against the training \
             iteration (mean over the main campaign's trainings, {per_curve} per curve; no \
             interval drawn)"
        ),
        env: String::new(),
    }))
}

/// The plateau a panel draws: the mean of its curves' plateaus, for a learner whose loss is on
/// its scale.
fn plateau_of(curves: &[&LossCurve], learner: &str) -> Option<f64> {
    let plateaus: Vec<f64> = curves.iter().filter_map(|c| c.plateau).collect();
    (has_plateau(learner) && !plateaus.is_empty())
        .then(|| plateaus.iter().sum::<f64>() / plateaus.len() as f64)
        .filter(|v| v.is_finite())
}

/// The y axis of a panel, `((lo, hi), (y_min, y_max))`: the data's span and the padded axis. It
/// spans every point and the plateau, except a curve's first point when it lies far above the
/// rest (more than half their span above their top): that one is drawn off scale.
fn y_bounds(curves: &[&LossCurve], plateau: Option<f64>) -> ((f64, f64), (f64, f64)) {
    let finite = |v: &f64| v.is_finite();
    let rest: Vec<f64> = curves
        .iter()
        .flat_map(|c| c.points.iter().skip(1).map(|p| p.1))
        .chain(plateau)
        .filter(finite)
        .collect();
    let firsts: Vec<f64> = curves
        .iter()
        .filter_map(|c| c.points.first().map(|p| p.1))
        .filter(finite)
        .collect();
    let span = |v: &[f64]| {
        v.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            })
    };
    let (mut lo, mut hi) = span(&rest);
    if rest.len() >= 2 && hi > lo {
        let reach = hi + 0.5 * (hi - lo);
        for &f in &firsts {
            if f <= reach {
                hi = hi.max(f);
            }
            lo = lo.min(f);
        }
    } else {
        let (a, b) = span(&firsts);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    let (lo, hi) = if lo.is_finite() && hi.is_finite() && hi > lo {
        (lo, hi)
    } else if lo.is_finite() {
        (lo - 1.0, lo + 1.0)
    } else {
        (0.0, 1.0)
    };
    let pad = (hi - lo) * 0.06;
    ((lo, hi), (lo - pad, hi + pad))
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
    let plateau = plateau_of(curves, learner);
    match plateau {
        Some(p) => title.push_str(&format!(" (plateau {p:.0})")),
        None if !has_plateau(learner) => title.push_str(" (annealed, minus log-det; no plateau)"),
        None => {}
    }
    let (_, (y_min, y_max)) = y_bounds(curves, plateau);
    let decimals = super::tick_decimals(y_min, y_max, 7);
    let x_decimals = super::tick_decimals(0.0, x_hi, 6);
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 16))
        .margin(10)
        .margin_right(super::right_margin(&format!("{x_hi:.x_decimals$}"), 12))
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.01 * x_hi..x_hi * 1.03, y_min..y_max)?;
    chart
        .configure_mesh()
        .x_desc("training iteration (batches of 100 images)")
        .y_desc("loss (nats per image)")
        .x_label_formatter(&|v| format!("{v:.x_decimals$}"))
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
    let mut off = super::OffScaleMarks::default();
    for (i, c) in curves.iter().enumerate() {
        let style = curve_style(env, c.latents, &c.variant);
        let pts: Vec<(f64, f64)> = c.points.iter().map(|&(it, v)| (it as f64, v)).collect();
        off.extend(draw_curve(
            &mut chart,
            &pts,
            &style,
            i as f64 / n as f64,
            None,
        )?);
    }
    super::draw_off_scale(&mut chart, &off)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(learner: &str, variant: &str, latents: i64, points: Vec<(i64, f64)>) -> LossCurve {
        LossCurve {
            env: "armball".into(),
            learner: learner.into(),
            variant: variant.into(),
            latents,
            trainings: 5,
            points,
            plateau: Some(440.0),
        }
    }

    fn all_curves() -> Vec<LossCurve> {
        let pts = vec![(0, 4000.0), (100, 400.0), (200, 100.0), (300, 90.0)];
        let mut v = Vec::new();
        for latents in [10, 2] {
            v.push(curve("ae", "none", latents, pts.clone()));
            for learner in ["vae", "rfvae"] {
                for variant in ["faithful", "corrected"] {
                    v.push(curve(learner, variant, latents, pts.clone()));
                }
            }
        }
        v
    }

    /// One entry per drawn style: the AE (no variant) and the faithful variants share a style, so
    /// they share one entry, never two entries that look the same.
    #[test]
    fn every_style_has_one_legend_entry_drawn_as_its_curves() {
        let curves = all_curves();
        let legend = legend_items(&curves);
        assert_eq!(legend.len(), 4, "{legend:?}");
        for (i, (icon, _)) in legend.iter().enumerate() {
            assert!(!legend[..i].iter().any(|(j, _)| j == icon), "{legend:?}");
        }
        for c in &curves {
            let icon = curve_style(&c.env, c.latents, &c.variant).icon();
            assert!(
                legend.iter().any(|(i, _)| *i == icon),
                "{} {}",
                c.learner,
                c.variant
            );
        }
        let labels: Vec<&str> = legend.iter().map(|l| l.1.as_str()).collect();
        assert_eq!(
            labels,
            [
                "10 latents, faithful (and the AE, no variant)",
                "10 latents, corrected",
                "true dimension, faithful (and the AE, no variant)",
                "true dimension, corrected",
            ]
        );
    }

    /// The first iteration far above the rest is off scale (drawn as an arrow at the edge), not
    /// inside the axis; near the rest, it is inside.
    #[test]
    fn a_far_first_point_is_off_the_axis_and_a_near_one_on_it() {
        let far = curve(
            "ae",
            "none",
            10,
            vec![(0, 4000.0), (100, 400.0), (200, 100.0)],
        );
        let ((_, hi), (_, y_max)) = y_bounds(&[&far], Some(440.0));
        assert_eq!(hi, 440.0);
        assert!(y_max < 4000.0);
        let near = curve(
            "ae",
            "none",
            10,
            vec![(0, 466.0), (100, 400.0), (200, 100.0)],
        );
        let ((_, hi), _) = y_bounds(&[&near], Some(440.0));
        assert_eq!(hi, 466.0);
        // The RFVAE's panel has no plateau.
        let rf = curve("rfvae", "faithful", 10, vec![(0, 100.0), (100, 200.0)]);
        assert_eq!(plateau_of(&[&rf], "rfvae"), None);
        assert_eq!(plateau_of(&[&far], "ae"), Some(440.0));
    }
}
