//! Faithful vs corrected (`variants.svg`): the final KL-coverage of RGE-VAE and RGE-RFVAE in their
//! two variants, one panel per environment and latent size. Within a panel, one group per
//! (algorithm, goal sampler; colour by algorithm as in the curve figures); in a group the faithful
//! runs on the left (filled circles) and the corrected ones on the right (hollow circles), every seed a dot, a thin grey line joining the two runs
//! of a seed (they share initial weights and batches), and the mean with its 95% t interval
//! ([`crate::stats::CONFIDENCE`]) as a bar with whiskers.

use std::path::Path;

use plotters::prelude::*;

use super::{
    FONT, FigureFile, KeyedAxis, algo_name, colour, env_name, marker, marker_points, panel_order,
    sampler_name, write_svg,
};
use crate::ReportError;
use crate::aggregate::ConditionSummary;
use crate::neural::VariantPair;

pub const FILE: &str = "variants.svg";
const PANEL_W: u32 = 620;
const PANEL_H: u32 = 430;
const TITLE_H: u32 = 36;
const LEGEND_H: u32 = 34;
/// Offset of the faithful (−) and corrected (+) columns from the group centre, in groups.
const COLUMN: f64 = 0.2;
/// Spread of the seeds within a column, in groups.
const SEED_SPREAD: f64 = 0.025;
const GREY: RGBColor = RGBColor(0xAA, 0xAA, 0xAA);

/// Colour and marker slot of an algorithm, as in the curve figures.
fn slot(algo: &str) -> usize {
    let known = super::algos();
    known.iter().position(|a| *a == algo).unwrap_or(known.len())
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
    let path = fig_dir.join(FILE);
    write_svg(
        &path,
        (
            PANEL_W * cols as u32,
            PANEL_H * rows as u32 + TITLE_H + LEGEND_H,
        ),
        |root| {
            let area = root.titled(
                "Final KL-coverage, faithful vs corrected: every seed, mean and 95% t interval",
                (FONT, 17),
            )?;
            let (area, strip) = area.split_vertically(PANEL_H * rows as u32);
            draw_legend(&strip)?;
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
        caption: "Final KL-coverage of the faithful and corrected variants of RGE-VAE and \
                  RGE-RFVAE, per seed, with the mean and its 95% t interval"
            .into(),
        env: String::new(),
    }))
}

/// The legend, once for all panels, in a strip under them.
fn draw_legend(
    strip: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
) -> Result<(), Box<dyn std::error::Error>> {
    let dark = RGBColor(0x44, 0x44, 0x44);
    let (circle, _) = marker_points(0, 4.5);
    let y = (LEGEND_H / 2) as i32;
    let text = |s: &str, x: i32| Text::new(s.to_string(), (x, y - 7), (FONT, 13));
    let mut x = 20;
    for (label, filled) in [
        ("faithful: left, filled markers", true),
        ("corrected: right, hollow markers", false),
    ] {
        strip.draw(&marker((x, y), &circle, filled, dark, 1))?;
        strip.draw(&text(label, x + 12))?;
        x += 250;
    }
    strip.draw(&PathElement::new(
        vec![(x - 6, y), (x + 6, y)],
        BLACK.stroke_width(3),
    ))?;
    strip.draw(&PathElement::new(
        vec![(x + 14, y - 8), (x + 14, y + 8)],
        dark.stroke_width(2),
    ))?;
    strip.draw(&text("mean (black bar), 95% t CI (whiskers)", x + 24))?;
    x += 280;
    strip.draw(&PathElement::new(
        vec![(x - 8, y + 5), (x + 8, y - 5)],
        GREY.stroke_width(1),
    ))?;
    strip.draw(&text("the two runs of one seed", x + 16))?;
    Ok(())
}

/// `RGE-VAE, KDE`.
fn group_label(p: &VariantPair<'_>) -> String {
    format!("{}, {}", algo_name(&p.algo), sampler_name(&p.sampler))
}

/// x of a seed's dot: the column, spread by the seed's rank among `n`.
fn seed_x(centre: f64, rank: usize, n: usize) -> f64 {
    centre + (rank as f64 - (n as f64 - 1.0) / 2.0) * SEED_SPREAD
}

/// The faithful and corrected conditions of a pair.
fn sides<'a>(p: &VariantPair<'a>) -> [Option<&'a ConditionSummary>; 2] {
    [p.faithful, p.corrected]
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    pairs: &[&VariantPair<'_>],
) -> Result<(), Box<dyn std::error::Error>> {
    let Some(first) = pairs.first() else {
        return Ok(());
    };
    let title = format!("{}, {} latents", env_name(&first.env), first.latents);
    let mut vals: Vec<f64> = Vec::new();
    for p in pairs {
        for c in sides(p).into_iter().flatten() {
            vals.extend(c.final_by_seed.iter().map(|v| v.1));
            vals.extend(c.final_klc.ci.into_iter().flat_map(|(a, b)| [a, b]));
        }
    }
    vals.retain(|v| v.is_finite());
    let (lo, hi) = vals
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let pad = ((hi - lo) * 0.1).max(0.05);
    // Room at the top for the run counts.
    let (y_min, y_max) = (lo - pad, hi + 1.8 * pad);
    let g = pairs.len();
    let labels: Vec<String> = pairs.iter().map(|p| group_label(p)).collect();
    let x_range = KeyedAxis {
        range: -0.5..g as f64 - 0.5,
        keys: (0..g).map(|i| i as f64).collect(),
    };

    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 17))
        .margin(12)
        .x_label_area_size(38)
        .y_label_area_size(56)
        .build_cartesian_2d(x_range, y_min..y_max)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .y_desc("final KL-coverage (nats, lower is better)")
        .x_label_formatter(&|v| {
            let i = v.round();
            if (v - i).abs() < 1e-9 && i >= 0.0 && (i as usize) < labels.len() {
                labels[i as usize].clone()
            } else {
                String::new()
            }
        })
        .y_label_formatter(&|v| format!("{v:.2}"))
        .y_labels(8)
        .max_light_lines(1)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .light_line_style(RGBColor(0xF0, 0xF0, 0xF0))
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;

    let clamp = |v: f64| v.clamp(y_min, y_max);
    for (gi, p) in pairs.iter().enumerate() {
        let centre = gi as f64;
        let col = colour(slot(&p.algo));
        let (mpts, _) = marker_points(0, 4.5);
        // Paired lines first, under the dots.
        if let (Some(f), Some(c)) = (p.faithful, p.corrected) {
            let (nf, nc) = (f.final_by_seed.len(), c.final_by_seed.len());
            for (rf, &(seed, vf)) in f.final_by_seed.iter().enumerate() {
                if let Some(rc) = c.final_by_seed.iter().position(|x| x.0 == seed) {
                    let vc = c.final_by_seed[rc].1;
                    if vf.is_finite() && vc.is_finite() {
                        chart.draw_series(std::iter::once(PathElement::new(
                            vec![
                                (seed_x(centre - COLUMN, rf, nf), vf),
                                (seed_x(centre + COLUMN, rc, nc), vc),
                            ],
                            GREY.stroke_width(1),
                        )))?;
                    }
                }
            }
        }
        for (side, c) in sides(p).into_iter().enumerate() {
            let Some(c) = c else { continue };
            let filled = side == 0;
            let x = centre + if side == 0 { -COLUMN } else { COLUMN };
            let n = c.final_by_seed.len();
            chart.draw_series(
                c.final_by_seed
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| v.1.is_finite())
                    .map(|(r, v)| marker((seed_x(x, r, n), clamp(v.1)), &mpts, filled, col, 1)),
            )?;
            // Mean and CI, beside the dots (outside the group).
            let s = &c.final_klc;
            let xm = x + if side == 0 { -0.11 } else { 0.11 };
            if let Some((a, b)) = s.ci {
                let (a, b) = (clamp(a), clamp(b));
                chart.draw_series([
                    PathElement::new(vec![(xm, a), (xm, b)], col.stroke_width(2)),
                    PathElement::new(vec![(xm - 0.025, a), (xm + 0.025, a)], col.stroke_width(2)),
                    PathElement::new(vec![(xm - 0.025, b), (xm + 0.025, b)], col.stroke_width(2)),
                ])?;
            }
            if s.mean.is_finite() {
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(xm - 0.05, s.mean), (xm + 0.05, s.mean)],
                    BLACK.stroke_width(3),
                )))?;
            }
            chart.draw_series(std::iter::once(Text::new(
                format!("n={n}"),
                (x - 0.06, y_max - 0.02 * (y_max - y_min)),
                (FONT, 11).into_font().color(&RGBColor(0x55, 0x55, 0x55)),
            )))?;
        }
    }

    Ok(())
}
