//! Training-budget sensitivity (`budget_<learner>.svg`, e.g. `budget_vae.svg`): the final
//! KL-coverage of a neural condition against its training iterations (log axis), from the
//! `budget-*` campaigns. Every run is a dot, filled when its network left the mean-image plateau
//! and hollow when it stayed there; the median over the seeds is a diamond on a line (the values
//! are often bimodal, trained and untrained networks, where a mean and its interval describe no
//! run; the report's table gives them). The main campaign's runs of the same condition are grey
//! dots and a star (their median) at their own budget; RGE-EFR and RPE of the main campaign on the same environment are horizontal
//! reference lines (their mean final KL-coverage). The paper trained the VAE for 100,000
//! iterations (docs/original-code.md section 5), far right of what a CPU campaign affords.

use std::path::Path;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::{
    FONT, FigureFile, Icon, algo_name, colour, condition_name, env_name, legend_height,
    legend_strip, marker, marker_points, sampler_name, star_points, write_svg,
};
use crate::error::ReportError;
use crate::load::campaign_display;
use crate::neural::{BudgetPoint, BudgetSeries};

const PANEL_W: u32 = 760;
const PANEL_H: u32 = 440;
const TITLE_H: u32 = 36;

fn slot(algo: &str) -> usize {
    super::algo_slot(algo, 0)
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
                        algo_name(algo)
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
                "{}: final KL-coverage vs training iterations (budget campaigns): one dot per run \
                 (hollow: the network stayed on the plateau), the median over the seeds (n in \
                 the legend and the table; no interval drawn: the table gives the 95% t \
                 intervals), the main campaign and the RGE-EFR / RPE levels",
                algo_name(algo)
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
    if k.sampler != ugl_types::Sampler::NONE {
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
    let statuses: Vec<Option<bool>> = s.points.iter().flat_map(|p| p.trained.clone()).collect();
    let mut items = Vec::new();
    for (status, what) in [
        (Some(true), "network left the plateau"),
        (Some(false), "network stayed on the plateau"),
        (None, "not recorded whether its network trained"),
    ] {
        if statuses.contains(&status) {
            let (points, filled) = run_marker(status);
            items.push((
                Icon::Marker {
                    colour: col,
                    points,
                    filled,
                    stroke: 1,
                },
                format!("budget campaigns: one run, {what}"),
            ));
        }
    }
    items.push((
        Icon::Line {
            colour: col,
            dash: None,
            width: 2,
            marker: Some((diamond, true)),
        },
        "budget campaigns: median over seeds".to_string(),
    ));
    if let Some(m) = s.main.first() {
        let main = campaign_display(main_campaign);
        items.extend([
            (
                Icon::Marker {
                    colour: MAIN_GREY,
                    points: circle,
                    filled: true,
                    stroke: 1,
                },
                format!("main campaign {main}: one run (hollow: stayed on the plateau)"),
            ),
            (
                Icon::Marker {
                    colour: BLACK,
                    points: star_points(8.0, 3.5),
                    filled: false,
                    stroke: 2,
                },
                format!(
                    "main campaign {main}: median over seeds (n={})",
                    m.summary.n
                ),
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
                algo_name(&r.algo),
                r.summary.n
            ),
        ));
    }
    items
}

/// The dot of a run: a filled circle when its network left the plateau, hollow when it stayed
/// there, a hollow square when its manifest does not say (results version 1).
fn run_marker(trained: Option<bool>) -> (Vec<(i32, i32)>, bool) {
    match trained {
        Some(t) => (marker_points(0, 3.0).0, t),
        None => (marker_points(1, 3.5).0, false),
    }
}

/// The main campaign's seeds.
const MAIN_GREY: RGBColor = RGBColor(0x55, 0x55, 0x55);

fn reference_dash(algo: &str) -> (i32, i32) {
    if algo == ugl_types::Algo::RPE {
        (3, 4)
    } else {
        (10, 6)
    }
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
        vals.push(p.median);
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
                .zip(&p.trained)
                .enumerate()
                .filter(|(_, (v, _))| v.1.is_finite())
                .map(|(r, (v, trained))| {
                    let (points, filled) = run_marker(*trained);
                    marker(
                        (seed_x(p.iterations as f64, r, n), clamp(v.1)),
                        &points,
                        filled,
                        col,
                        1,
                    )
                }),
        )?;
    }
    // Medians.
    let medians: Vec<(f64, f64)> = s
        .points
        .iter()
        .filter(|p| p.median.is_finite())
        .map(|p| (p.iterations as f64, clamp(p.median)))
        .collect();
    chart.draw_series(std::iter::once(PathElement::new(
        medians.clone(),
        col.stroke_width(2),
    )))?;
    chart.draw_series(medians.iter().map(|&pt| marker(pt, &diamond, true, col, 1)))?;
    for p in &s.main {
        if p.median.is_finite() {
            chart.draw_series(std::iter::once(marker(
                (p.iterations as f64, clamp(p.median)),
                &star,
                false,
                BLACK,
                2,
            )))?;
        }
    }
    Ok(())
}
