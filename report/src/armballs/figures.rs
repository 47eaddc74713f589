//! The ArmBalls figures: the ball's and the distractor's exploration ratio against the
//! iterations, and the interest of each goal module.

use std::collections::BTreeMap;
use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::labels::parts;
use super::runs::{FollowupRun, algos, ball_cells, display, of};
use super::{COVERAGE_FIGURE, INTEREST_FIGURE};
use crate::ReportError;
use crate::figures::{FONT, FigureFile, write_svg};
use crate::stats::mean;

/// The colour of an algorithm: by goal space (EFR green, VAE blue, β-VAE vermillion, RPE grey),
/// lighter for flat and random choice.
fn colour(algo: &str) -> RGBColor {
    let (space, choice) = parts(algo);
    let base = match space {
        // Variant campaigns (`@still`): reddish purple.
        _ if algo.contains('@') => (0xCC, 0x79, 0xA7),
        "efr" => (0x00, 0x9E, 0x73),
        "vae" => (0x00, 0x72, 0xB2),
        "bvae" => (0xD5, 0x5E, 0x00),
        "" => (0x55, 0x55, 0x55),
        _ => (0xCC, 0x79, 0xA7),
    };
    let mix = match choice {
        "flat" => 0.55,
        "random" => 0.3,
        _ => 0.0,
    };
    let f = |c: u8| (c as f64 + (255.0 - c as f64) * mix) as u8;
    RGBColor(f(base.0), f(base.1), f(base.2))
}

fn dash(algo: &str) -> Option<(i32, i32)> {
    match parts(algo).1 {
        "flat" => Some((8, 5)),
        "random" => Some((3, 3)),
        _ => None,
    }
}

/// Mean curve over the runs of `algo` (epochs of the first run).
fn mean_curve(
    runs: &[&FollowupRun],
    value: impl Fn(&FollowupRun, usize) -> Option<f64>,
) -> Vec<(f64, f64)> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    (0..first.epochs.len())
        .filter_map(|i| {
            let v: Vec<f64> = runs.iter().filter_map(|r| value(r, i)).collect();
            (!v.is_empty()).then(|| (first.epochs[i] as f64, mean(&v)))
        })
        .collect()
}

fn draw_lines(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    title: &str,
    y_label: &str,
    series: &[(String, RGBColor, Option<(i32, i32)>, Vec<(f64, f64)>)],
    log_y: bool,
    legend: Option<SeriesLabelPosition>,
) -> Result<(), Box<dyn std::error::Error>> {
    let x_max = series
        .iter()
        .flat_map(|s| s.3.iter().map(|p| p.0))
        .fold(1.0, f64::max);
    let ys: Vec<f64> = series
        .iter()
        .flat_map(|s| s.3.iter().map(|p| p.1))
        .filter(|v| v.is_finite() && (!log_y || *v > 0.0))
        .collect();
    let y_hi = ys.iter().copied().fold(f64::MIN, f64::max).max(1e-12);
    let y_lo = ys.iter().copied().fold(f64::MAX, f64::min).min(y_hi);
    let mut chart = ChartBuilder::on(area);
    chart
        .caption(title, (FONT, 16))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(64);
    if log_y {
        // Zero (the initial interest decays towards it, never reaching it) has no place on a
        // log axis.
        let positive: Vec<_> = series
            .iter()
            .map(|(n, c, d, pts)| {
                (
                    n.clone(),
                    *c,
                    *d,
                    pts.iter().copied().filter(|p| p.1 > 0.0).collect(),
                )
            })
            .collect();
        let c = chart
            .build_cartesian_2d(0.0..x_max, (y_lo.max(1e-12) * 0.8..y_hi * 1.25).log_scale())?;
        plot_series(c, y_label, &positive, legend)
    } else {
        let c = chart.build_cartesian_2d(0.0..x_max, 0.0..y_hi * 1.08)?;
        plot_series(c, y_label, series, legend)
    }
}

/// Mesh, curves (dashed where a dash is given) and legend, on a linear or logarithmic y axis.
fn plot_series<'a, 'b: 'a, Y>(
    mut c: ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, Y>>,
    y_label: &str,
    series: &[(String, RGBColor, Option<(i32, i32)>, Vec<(f64, f64)>)],
    legend: Option<SeriesLabelPosition>,
) -> Result<(), Box<dyn std::error::Error>>
where
    Y: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    c.configure_mesh()
        .x_desc("exploration iterations")
        .y_desc(y_label)
        .label_style((FONT, 12))
        .draw()?;
    for (name, col, d, pts) in series {
        let style = ShapeStyle::from(col).stroke_width(2);
        match d {
            None => c.draw_series(LineSeries::new(pts.clone(), style))?,
            Some((a, b)) => c.draw_series(std::iter::once(
                plotters::element::DashedPathElement::new(pts.clone(), *a as u32, *b as u32, style),
            ))?,
        }
        .label(name.clone())
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
    }
    if let Some(pos) = legend {
        c.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .label_font((FONT, 11))
            .position(pos)
            .draw()?;
    }
    Ok(())
}

/// Ball (left) and distractor (right) exploration ratio against the iterations, mean over seeds.
pub(super) fn draw_coverage(
    runs: &[FollowupRun],
    fig_dir: &Path,
) -> Result<FigureFile, ReportError> {
    let path = fig_dir.join(COVERAGE_FIGURE);
    // One mean curve per algorithm of the value `value(run, checkpoint)`.
    let series = |value: &dyn Fn(&FollowupRun, usize) -> Option<f64>| -> Vec<_> {
        algos(runs)
            .iter()
            .map(|a| {
                (
                    display(runs, a),
                    colour(a),
                    dash(a),
                    mean_curve(&of(runs, a), value),
                )
            })
            .collect()
    };
    let ball = series(&|r, i| {
        r.ball_coverage.get(i).map(|c| {
            let (reachable, all) = ball_cells();
            c * reachable / all
        })
    });
    let distractor = series(&|r, i| r.distractor_coverage.get(i).copied().flatten());
    write_svg(&path, (1100, 460), |root| {
        let (l, r) = root.split_horizontally(550);
        draw_lines(
            &l,
            "controllable ball",
            "exploration ratio (cells / 900)",
            &ball,
            false,
            None,
        )?;
        draw_lines(
            &r,
            "distractor (control; legend for both panels)",
            "exploration ratio (cells / 900)",
            &distractor,
            false,
            Some(SeriesLabelPosition::LowerRight),
        )?;
        Ok(())
    })?;
    Ok(FigureFile {
        path,
        link: format!("figures/{COVERAGE_FIGURE}"),
        caption: "ArmBalls: exploration ratio of the ball and of the distractor".into(),
        env: "armballs".into(),
    })
}

/// One panel per modular algorithm: the mean interest of each module against the iterations.
pub(super) fn draw_interest(
    runs: &[FollowupRun],
    fig_dir: &Path,
) -> Result<Option<FigureFile>, ReportError> {
    let modular: Vec<String> = algos(runs)
        .into_iter()
        .filter(|a| parts(a).1 == "lp")
        .collect();
    if modular.is_empty() {
        return Ok(None);
    }
    const PALETTE: [RGBColor; 6] = [
        RGBColor(0xD5, 0x5E, 0x00),
        RGBColor(0x00, 0x72, 0xB2),
        RGBColor(0x00, 0x9E, 0x73),
        RGBColor(0xCC, 0x79, 0xA7),
        RGBColor(0xE6, 0x9F, 0x00),
        RGBColor(0x55, 0x55, 0x55),
    ];
    let panels: Vec<(String, Vec<_>)> = modular
        .iter()
        .map(|a| {
            let rs = of(runs, a);
            let mut modules: Vec<i64> = rs.iter().flat_map(|r| r.modules.keys().copied()).collect();
            modules.sort();
            modules.dedup();
            let series = modules
                .iter()
                .map(|&m| {
                    let name = rs
                        .iter()
                        .find_map(|r| r.modules.get(&m))
                        .filter(|_| parts(a).0 == "efr")
                        .map(|(n, _)| format!("module {m} ({n})"))
                        .unwrap_or_else(|| format!("module {m}"));
                    let mut pts: BTreeMap<i64, Vec<f64>> = BTreeMap::new();
                    for r in &rs {
                        for p in r.interest.iter().filter(|p| p.1 == m) {
                            pts.entry(p.0).or_default().push(p.2);
                        }
                    }
                    (
                        name,
                        PALETTE[m as usize % PALETTE.len()],
                        None,
                        pts.into_iter()
                            .map(|(e, v)| (e as f64, mean(&v)))
                            .collect::<Vec<_>>(),
                    )
                })
                .collect();
            (display(runs, a), series)
        })
        .collect();
    let path = fig_dir.join(INTEREST_FIGURE);
    let w = 480 * panels.len() as u32;
    write_svg(&path, (w, 420), |root| {
        let areas = root.split_evenly((1, panels.len()));
        for (area, (title, series)) in areas.iter().zip(&panels) {
            draw_lines(
                area,
                title,
                "interest (log scale)",
                series,
                true,
                Some(SeriesLabelPosition::LowerRight),
            )?;
        }
        Ok(())
    })?;
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{INTEREST_FIGURE}"),
        caption: "ArmBalls: interest per module (learning-progress choice)".into(),
        env: "armballs".into(),
    }))
}
