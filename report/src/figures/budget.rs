//! Training-budget sensitivity (`budget_<learner>.svg`, e.g. `budget_vae.svg`): the final
//! KL-coverage of a neural condition against its training iterations (log axis), from the
//! `budget-*` campaigns. Every seed is a dot; the mean over seeds, with its 95% t interval
//! ([`crate::stats::CONFIDENCE`]; none with one seed), is a diamond on a line. The main campaign's runs of the same condition are a star
//! at their own budget; RGE-EFR and RPE of the main campaign on the same environment are horizontal
//! reference lines (their mean final KL-coverage). The paper trained the VAE for 100,000
//! iterations (docs/original-code.md section 5), far right of what a CPU campaign affords.

use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::{
    FONT, FigureFile, Icon, colour, condition_name, env_name, legend_height, legend_strip, marker,
    marker_points, sampler_name, star_points, write_svg,
};
use crate::ReportError;
use crate::load::campaign_display;
use crate::neural::{BudgetPoint, BudgetSeries};

const PANEL_W: u32 = 760;
const PANEL_H: u32 = 440;
const TITLE_H: u32 = 36;

fn slot(algo: &str) -> usize {
    let known = super::algos();
    known.iter().position(|a| *a == algo).unwrap_or(known.len())
}

/// The file of a learner's budget figure: `budget_vae.svg` for `rge-vae`.
pub fn file_name(algo: &str) -> String {
    format!(
        "budget_{}.svg",
        super::file_safe(algo.strip_prefix("rge-").unwrap_or(algo))
    )
}

/// Draws one figure per algorithm among `series` (one panel per condition, one panel a row).
pub fn draw_all(
    series: &[BudgetSeries],
    main_campaign: &str,
    fig_dir: &Path,
) -> Result<Vec<FigureFile>, ReportError> {
    let mut algos: Vec<&str> = series.iter().map(|s| s.key.algo.as_str()).collect();
    algos.dedup();
    let mut out = Vec::new();
    for algo in algos {
        let of: Vec<&BudgetSeries> = series.iter().filter(|s| s.key.algo == algo).collect();
        let name = file_name(algo);
        let path = fig_dir.join(&name);
        let rows = of.len() as u32;
        let legend_h = of
            .iter()
            .map(|s| legend_height(PANEL_W, &legend(s, main_campaign), 13))
            .max()
            .unwrap_or(0);
        write_svg(
            &path,
            (PANEL_W, rows * (PANEL_H + legend_h) + TITLE_H),
            |root| {
                let area = root.titled(
                    &format!(
                        "{}: final KL-coverage vs training iterations",
                        condition_name(algo, "none")
                    ),
                    (FONT, 18),
                )?;
                let areas = area.split_evenly((of.len(), 1));
                for (s, a) in of.iter().zip(areas.iter()) {
                    let (plot, strip) = a.split_vertically(PANEL_H);
                    draw_panel(&plot, s)?;
                    legend_strip(&strip, &legend(s, main_campaign), 13)?;
                }
                Ok(())
            },
        )?;
        out.push(FigureFile {
            path,
            link: format!("figures/{name}"),
            caption: format!(
                "{}: final KL-coverage vs training iterations (budget campaigns), with the main \
                 campaign and the RGE-EFR / RPE levels",
                condition_name(algo, "none")
            ),
            env: String::new(),
        });
    }
    Ok(out)
}

/// `ArmBall, RGE-VAE (faithful), KDE goals, 10 latents`.
pub fn series_title(s: &BudgetSeries) -> String {
    let k = &s.key;
    let mut t = format!(
        "{}, {}",
        env_name(&k.env),
        condition_name(&k.algo, &k.variant)
    );
    if k.sampler != "none" {
        t.push_str(&format!(", {} goals", sampler_name(&k.sampler)));
    }
    if k.latents != 0 {
        t.push_str(&format!(", {} latents", k.latents));
    }
    t
}

fn legend(s: &BudgetSeries, main_campaign: &str) -> Vec<(Icon, String)> {
    let col = colour(slot(&s.key.algo));
    let (diamond, _) = marker_points(3, 5.0);
    let (circle, _) = marker_points(0, 3.0);
    let mut items = vec![
        (
            Icon::Marker {
                colour: col,
                points: circle.clone(),
                filled: false,
                stroke: 1,
            },
            "budget campaigns: one seed".to_string(),
        ),
        (
            Icon::Line {
                colour: col,
                dash: None,
                width: 2,
                marker: Some((diamond, true)),
            },
            "budget campaigns: mean over seeds".to_string(),
        ),
        (
            Icon::Whisker { colour: col },
            "budget campaigns: 95% t interval".to_string(),
        ),
    ];
    if let Some(m) = s.main.first() {
        let main = campaign_display(main_campaign);
        items.extend([
            (
                Icon::Marker {
                    colour: MAIN_GREY,
                    points: circle,
                    filled: false,
                    stroke: 1,
                },
                format!("main campaign {main}: one seed"),
            ),
            (
                Icon::Marker {
                    colour: BLACK,
                    points: star_points(8.0, 3.5),
                    filled: false,
                    stroke: 2,
                },
                format!("main campaign {main}: mean over seeds (n={})", m.summary.n),
            ),
            (
                Icon::Whisker { colour: BLACK },
                format!("main campaign {main}: 95% t interval"),
            ),
        ]);
    }
    for r in &s.references {
        items.push((
            Icon::Line {
                colour: colour(slot(&r.algo)),
                dash: Some(reference_dash(&r.algo)),
                width: 2,
                marker: None,
            },
            format!(
                "{} mean, main campaign (n={})",
                condition_name(&r.algo, "none"),
                r.summary.n
            ),
        ));
    }
    items
}

/// The main campaign's seeds.
const MAIN_GREY: RGBColor = RGBColor(0x55, 0x55, 0x55);

fn reference_dash(algo: &str) -> (i32, i32) {
    if algo == "rpe" { (3, 4) } else { (10, 6) }
}

/// x of a seed's dot on the log axis: the budget times a small factor by the seed's rank.
fn seed_x(it: f64, rank: usize, n: usize) -> f64 {
    it * 10f64.powf((rank as f64 - (n as f64 - 1.0) / 2.0) * 0.012)
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    s: &BudgetSeries,
) -> Result<(), Box<dyn std::error::Error>> {
    let all: Vec<&BudgetPoint> = s.points.iter().chain(&s.main).collect();
    let mut its: Vec<i64> = all.iter().map(|p| p.iterations).collect();
    its.sort_unstable();
    its.dedup();
    let x_lo = its.first().copied().unwrap_or(1).max(1) as f64 / 1.6;
    let x_hi = its.last().copied().unwrap_or(10).max(1) as f64 * 1.6;
    let mut vals: Vec<f64> = Vec::new();
    for p in &all {
        vals.extend(p.values.iter().map(|v| v.1));
        vals.extend(p.summary.ci.into_iter().flat_map(|(a, b)| [a, b]));
    }
    vals.extend(s.references.iter().map(|r| r.summary.mean));
    vals.retain(|v| v.is_finite());
    let (lo, hi) = vals
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let pad = ((hi - lo) * 0.08).max(0.05);
    let (y_min, y_max) = (lo - pad, hi + pad);
    let clamp = |v: f64| v.clamp(y_min, y_max);
    let y_decimals = super::tick_decimals(y_min, y_max, 8);

    let key_points: Vec<f64> = its.iter().map(|&i| i as f64).collect();
    let mut chart = ChartBuilder::on(area)
        .caption(series_title(s), (FONT, 16))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(56)
        .build_cartesian_2d(
            (x_lo..x_hi).log_scale().with_key_points(key_points),
            y_min..y_max,
        )?;
    chart
        .configure_mesh()
        .x_desc("training iterations (log scale)")
        .y_desc("final KL-coverage (nats, lower is better)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.y_decimals$}"))
        .y_labels(8)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .light_line_style(RGBColor(0xF0, 0xF0, 0xF0))
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;

    for r in &s.references {
        if r.summary.mean.is_finite() {
            let (d, g) = reference_dash(&r.algo);
            chart.draw_series(std::iter::once(DashedPathElement::new(
                vec![(x_lo, clamp(r.summary.mean)), (x_hi, clamp(r.summary.mean))],
                d,
                g,
                colour(slot(&r.algo)).stroke_width(2),
            )))?;
        }
    }

    let col = colour(slot(&s.key.algo));
    let (circle, _) = marker_points(0, 3.0);
    let (diamond, _) = marker_points(3, 5.0);
    let star = star_points(8.0, 3.5);
    // Seeds: the budget campaigns' in the condition's colour, the main campaign's in grey.
    let main_grey = MAIN_GREY;
    for (p, col) in s
        .points
        .iter()
        .map(|p| (p, col))
        .chain(s.main.iter().map(|p| (p, main_grey)))
    {
        let n = p.values.len();
        chart.draw_series(
            p.values
                .iter()
                .enumerate()
                .filter(|(_, v)| v.1.is_finite())
                .map(|(r, v)| {
                    marker(
                        (seed_x(p.iterations as f64, r, n), clamp(v.1)),
                        &circle,
                        false,
                        col,
                        1,
                    )
                }),
        )?;
    }
    // Whiskers, at a small offset to the right of the dots.
    let whisker = |p: &BudgetPoint, (a, b): (f64, f64), c: RGBColor, offset: f64| {
        let x = p.iterations as f64 * 10f64.powf(offset);
        let (a, b) = (clamp(a), clamp(b));
        let cap = 10f64.powf(0.01);
        vec![
            PathElement::new(vec![(x, a), (x, b)], c.stroke_width(2)),
            PathElement::new(vec![(x / cap, a), (x * cap, a)], c.stroke_width(2)),
            PathElement::new(vec![(x / cap, b), (x * cap, b)], c.stroke_width(2)),
        ]
    };
    for p in &s.points {
        if let Some(ci) = p.summary.ci {
            chart.draw_series(whisker(p, ci, col, 0.04))?;
        }
    }
    for p in &s.main {
        if let Some(ci) = p.summary.ci {
            chart.draw_series(whisker(p, ci, BLACK, 0.075))?;
        }
    }
    // Means.
    let means: Vec<(f64, f64)> = s
        .points
        .iter()
        .filter(|p| p.summary.mean.is_finite())
        .map(|p| (p.iterations as f64, clamp(p.summary.mean)))
        .collect();
    chart.draw_series(std::iter::once(PathElement::new(
        means.clone(),
        col.stroke_width(2),
    )))?;
    chart.draw_series(means.iter().map(|&pt| marker(pt, &diamond, true, col, 1)))?;
    for p in &s.main {
        if p.summary.mean.is_finite() {
            chart.draw_series(std::iter::once(marker(
                (p.iterations as f64, clamp(p.summary.mean)),
                &star,
                false,
                BLACK,
                2,
            )))?;
        }
    }
    Ok(())
}
