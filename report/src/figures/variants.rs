//! Faithful vs corrected (`variants.svg`): the paired comparison of RGE-VAE and RGE-RFVAE in
//! their two variants, one panel per environment and latent size, one group per (algorithm, goal
//! sampler; colour by algorithm as in the curve figures). The two runs of a seed share their
//! initial weights, batches and exploration streams, so the figure draws what the paired test
//! looks at: every seed's difference of final KL-coverage, *corrected − faithful* (a dot; below 0
//! the corrected variant covers better), their mean (a black bar) and its 95% paired t interval
//! ([`crate::stats::CONFIDENCE`], Student's t on the differences; whiskers), against a dashed
//! line at 0. (Whiskers of the two variants' own means, side by side, overlap even where the
//! paired interval excludes 0: the seeds' shared part of the variance cancels in the
//! differences.) The number of pairs and the interval are printed over each group.

use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::{
    FONT, FigureFile, Icon, KeyedAxis, algo_name, colour, env_name, legend_height, legend_strip,
    marker, marker_points, panel_order, sampler_name, write_svg,
};
use crate::error::ReportError;
use crate::neural::VariantPair;
use crate::stats::CONFIDENCE;

pub const FILE: &str = "variants.svg";
const PANEL_W: u32 = 620;
const PANEL_H: u32 = 430;
const TITLE_H: u32 = 36;
/// Spread of the seeds' dots, in groups.
const SEED_SPREAD: f64 = 0.035;
/// Offset of the mean and interval from the group centre (right of the dots), in groups.
const SUMMARY_DX: f64 = 0.2;
const ZERO_GREY: RGBColor = RGBColor(0x55, 0x55, 0x55);
const DARK: RGBColor = RGBColor(0x44, 0x44, 0x44);

/// Colour and marker slot of an algorithm, as in the curve figures.
fn slot(algo: &str) -> usize {
    super::algo_slot(algo, 0)
}

/// The pairs of each (env, latents) panel, in the paper's panel order.
pub fn panels<'p, 'a>(pairs: &'p [VariantPair<'a>]) -> Vec<Vec<&'p VariantPair<'a>>> {
    let mut keys: Vec<(String, i64)> = pairs.iter().map(|p| (p.env.clone(), p.latents)).collect();
    keys.sort_by_key(|(e, l)| panel_order(e, *l));
    keys.dedup();
    keys.iter()
        .map(|(e, l)| {
            pairs
                .iter()
                .filter(|p| &p.env == e && p.latents == *l)
                .collect()
        })
        .collect()
}

/// Draws `variants.svg` (2 panels a row); `None` when there is no pair.
pub fn draw(pairs: &[VariantPair<'_>], fig_dir: &Path) -> Result<Option<FigureFile>, ReportError> {
    if pairs.is_empty() {
        return Ok(None);
    }
    let panels = panels(pairs);
    let cols = panels.len().min(2);
    let rows = panels.len().div_ceil(2);
    let width = PANEL_W * cols as u32;
    let legend = legend();
    let legend_h = legend_height(width, &legend, 13);
    let level = CONFIDENCE * 100.0;
    let path = fig_dir.join(FILE);
    write_svg(
        &path,
        (width, PANEL_H * rows as u32 + TITLE_H + legend_h),
        |root| {
            let area = root.titled(
                &format!(
                    "Corrected − faithful, final KL-coverage per seed: mean and {level:.0}% \
                     paired t interval"
                ),
                (FONT, 17),
            )?;
            let (area, strip) = area.split_vertically(PANEL_H * rows as u32);
            legend_strip(&strip, &legend, 13)?;
            let areas = area.split_evenly((rows, cols));
            for (p, a) in panels.iter().zip(areas.iter()) {
                draw_panel(a, p)?;
            }
            Ok(())
        },
    )?;
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{FILE}"),
        caption: format!(
            "Faithful vs corrected RGE-VAE and RGE-RFVAE: the per-seed difference of final \
             KL-coverage (corrected − faithful; below 0 the corrected variant covers better), \
             with the mean and its {level:.0}% paired t interval; n pairs over each group"
        ),
        env: String::new(),
    }))
}

/// The legend, once for all panels, in a strip under them.
fn legend() -> Vec<(Icon, String)> {
    let (circle, _) = marker_points(0, 4.5);
    vec![
        (
            Icon::Marker {
                colour: DARK,
                points: circle,
                filled: true,
                stroke: 1,
            },
            "one seed: corrected − faithful (colour: algorithm)".into(),
        ),
        (
            Icon::Line {
                colour: BLACK,
                dash: None,
                width: 3,
                marker: None,
            },
            "mean difference".into(),
        ),
        (
            Icon::Whisker { colour: DARK },
            format!("{:.0}% paired t interval of the mean", CONFIDENCE * 100.0),
        ),
        (
            Icon::Line {
                colour: ZERO_GREY,
                dash: Some((6, 4)),
                width: 1,
                marker: None,
            },
            "0: no difference".into(),
        ),
    ]
}

/// `RGE-VAE, KDE`.
fn group_label(p: &VariantPair<'_>) -> String {
    format!("{}, {}", algo_name(&p.algo), sampler_name(&p.sampler))
}

/// x of a seed's dot: left of the group centre, spread by the seed's rank among `n`.
fn seed_x(centre: f64, rank: usize, n: usize) -> f64 {
    centre - 0.05 + (rank as f64 - (n as f64 - 1.0) / 2.0) * SEED_SPREAD
}

/// `+0.251`: a signed difference.
fn signed(v: f64) -> String {
    format!("{v:+.3}")
}

/// The values a panel's y axis spans: every difference, mean and interval end, and 0.
fn panel_values(pairs: &[&VariantPair<'_>]) -> Vec<f64> {
    let mut vals = vec![0.0];
    for p in pairs {
        vals.extend(p.differences.iter().map(|d| d.1));
        if let Some(d) = &p.diff {
            vals.push(d.mean);
            vals.extend(d.ci.into_iter().flat_map(|(a, b)| [a, b]));
        }
    }
    vals.retain(|v| v.is_finite());
    vals
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    pairs: &[&VariantPair<'_>],
) -> Result<(), Box<dyn std::error::Error>> {
    let Some(first) = pairs.first() else {
        return Ok(());
    };
    let title = format!("{}, {} latents", env_name(&first.env), first.latents);
    let vals = panel_values(pairs);
    let (lo, hi) = vals
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let pad = ((hi - lo) * 0.08).max(0.05);
    // Room at the top for the counts and intervals.
    let (y_min, y_max) = (lo - pad, hi + 3.2 * pad);
    let g = pairs.len();
    let labels: Vec<String> = pairs.iter().map(|p| group_label(p)).collect();
    let x_range = KeyedAxis {
        range: -0.5..g as f64 - 0.5,
        keys: (0..g).map(|i| i as f64).collect(),
    };
    let decimals = super::tick_decimals(y_min, y_max, 8);

    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 17))
        .margin(12)
        .x_label_area_size(38)
        .y_label_area_size(62)
        .build_cartesian_2d(x_range, y_min..y_max)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .y_desc("Δ final KL-coverage, corrected − faithful (nats)")
        .x_label_formatter(&|v| {
            let i = v.round();
            if (v - i).abs() < 1e-9 && i >= 0.0 && (i as usize) < labels.len() {
                labels[i as usize].clone()
            } else {
                String::new()
            }
        })
        .y_label_formatter(&|v| {
            let s = format!("{v:+.decimals$}");
            // No sign on zero.
            if s.trim_start_matches(['+', '-'])
                .chars()
                .all(|c| c == '0' || c == '.')
            {
                s[1..].to_string()
            } else {
                s
            }
        })
        .y_labels(8)
        .max_light_lines(1)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .light_line_style(RGBColor(0xF0, 0xF0, 0xF0))
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;
    chart.draw_series(std::iter::once(DashedPathElement::new(
        vec![(-0.5, 0.0), (g as f64 - 0.5, 0.0)],
        6,
        4,
        ZERO_GREY.stroke_width(1),
    )))?;
    let grey_text = (FONT, 12).into_font().color(&RGBColor(0x33, 0x33, 0x33));
    let row = |k: f64| y_max - (0.02 + 0.055 * k) * (y_max - y_min);
    for (gi, p) in pairs.iter().enumerate() {
        let centre = gi as f64;
        let col = colour(slot(&p.algo));
        let (mpts, _) = marker_points(0, 4.5);
        let n = p.differences.len();
        chart.draw_series(
            p.differences
                .iter()
                .enumerate()
                .filter(|(_, d)| d.1.is_finite())
                .map(|(r, d)| marker((seed_x(centre, r, n), d.1), &mpts, true, col, 1)),
        )?;
        let xm = centre + SUMMARY_DX;
        let (count, interval) = match &p.diff {
            Some(d) => {
                if let Some((a, b)) = d.ci {
                    chart.draw_series([
                        PathElement::new(vec![(xm, a), (xm, b)], col.stroke_width(2)),
                        PathElement::new(vec![(xm - 0.03, a), (xm + 0.03, a)], col.stroke_width(2)),
                        PathElement::new(vec![(xm - 0.03, b), (xm + 0.03, b)], col.stroke_width(2)),
                    ])?;
                }
                if d.mean.is_finite() {
                    chart.draw_series(std::iter::once(PathElement::new(
                        vec![(xm - 0.06, d.mean), (xm + 0.06, d.mean)],
                        BLACK.stroke_width(3),
                    )))?;
                }
                let interval = match d.ci {
                    Some((a, b)) => format!("[{}, {}]", signed(a), signed(b)),
                    None => "no interval".into(),
                };
                (format!("n={n} pairs, {}", signed(d.mean)), interval)
            }
            None => ("no pair".into(), String::new()),
        };
        chart.draw_series([
            Text::new(count, (centre - 0.42, row(0.0)), grey_text.clone()),
            Text::new(interval, (centre - 0.42, row(1.0)), grey_text.clone()),
        ])?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::paired_summary;

    /// The figure draws the paired differences and the paired interval, as the table reports
    /// them: an interval that excludes 0 is drawn excluding 0 (the axis spans it and 0).
    #[test]
    fn the_panel_spans_the_differences_their_interval_and_zero() {
        let faithful = [(0, 4.3), (1, 4.1), (2, 4.5), (3, 4.0), (4, 4.4)];
        let corrected = [(0, 4.7), (1, 4.4), (2, 4.95), (3, 4.35), (4, 4.8)];
        let diff = paired_summary(&faithful, &corrected).unwrap();
        let (lo, hi) = diff.ci.unwrap();
        assert!(lo > 0.0, "the paired interval excludes 0: {lo} {hi}");
        let pair = VariantPair {
            env: "armball".into(),
            algo: "rge-rfvae".into(),
            sampler: "gaussian".into(),
            latents: 2,
            faithful: None,
            corrected: None,
            differences: crate::stats::paired_differences(&faithful, &corrected),
            diff: Some(diff),
        };
        let vals = panel_values(&[&pair]);
        assert!(vals.contains(&0.0) && vals.contains(&lo) && vals.contains(&hi));
        assert_eq!(pair.differences.len(), 5);
        assert!(
            pair.differences
                .iter()
                .all(|d| vals.contains(&d.1) && d.1 > 0.0)
        );
        assert_eq!(signed(0.389), "+0.389");
    }
}
