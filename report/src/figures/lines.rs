//! Line figures: a grid of panels of curves, each curve in a style of its own (no two curves of
//! a figure share colour and dash, [`super::assign_styles`]), with the legend in a strip under
//! the panels (so that no legend hides a curve) whose every entry is drawn with its curve's line,
//! dash and marker ([`super::LineStyle::icon`]). Tick labels are as precise as their step needs
//! (`5000`, not `5000.0`), the frame leaves room for the last one, and a logarithmic axis labels
//! every tick in one format (`1e-3`).
//!
//! The ArmBalls page's figures (`armballs_coverage.svg`, `armballs_interest.svg`) are drawn with
//! it; [`followup_request`] gives their conditions' styles.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::{
    FONT, Icon, LineStyle, OffScaleMarks, StyleRequest, draw_curve, draw_off_scale, fmt_log_tick,
    legend_height, legend_strip, right_margin, tick_decimals, write_svg,
};
use crate::error::ReportError;

/// One curve: its legend label, its style, its points and, optionally, a shaded interval
/// `(x, lo, hi)` under it.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    pub label: String,
    pub style: LineStyle,
    pub points: Vec<(f64, f64)>,
    pub band: Vec<(f64, f64, f64)>,
}

impl Curve {
    /// The curve's legend entry: its label, drawn with its own style.
    pub fn legend_item(&self) -> (Icon, String) {
        self.style.legend_item(self.label.clone())
    }
}

/// The y axis of a panel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum YScale {
    /// Linear, from 0 (a count, a share) to above the largest value.
    FromZero,
    /// Logarithmic over the positive values; values ≤ 0 are left out (the line breaks there) and
    /// the panel says so.
    Log,
}

/// One panel: a title, the axes' names (with units) and the curves.
#[derive(Debug, Clone, PartialEq)]
pub struct LinePanel {
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub y_scale: YScale,
    pub curves: Vec<Curve>,
}

impl LinePanel {
    /// The panel's legend entries, in its curves' order.
    pub fn legend(&self) -> Vec<(Icon, String)> {
        self.curves.iter().map(Curve::legend_item).collect()
    }
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LegendPlace {
    /// One strip under all panels (the panels show the same series).
    Shared,
    /// A strip under each panel (the panels show different series).
    PerPanel,
}

/// A figure of line panels.
#[derive(Debug, Clone, PartialEq)]
pub struct LineFigure {
    /// The figure's title, over the panels.
    pub title: Option<String>,
    pub panels: Vec<LinePanel>,
    /// Panels per row.
    pub cols: usize,
    /// Size of one panel's plot (pixels), legend strips not counted.
    pub panel_size: (u32, u32),
    pub legend: LegendPlace,
    /// Lines of text under everything (what is drawn, n, intervals), wrapped to the width.
    pub notes: Vec<String>,
    /// Font size of the tick labels and legends; titles are 3 points larger.
    pub font: u32,
}

const TITLE_H: u32 = 34;

/// The legend of a figure with one shared strip: every panel's entries, each (label, icon) once.
pub fn shared_legend(panels: &[LinePanel]) -> Vec<(Icon, String)> {
    let mut out: Vec<(Icon, String)> = Vec::new();
    for item in panels.iter().flat_map(LinePanel::legend) {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

/// `text` cut into lines of at most about `width` pixels at `font_size` (words kept whole).
fn wrap(text: &str, width: u32, font_size: u32) -> Vec<String> {
    // plotters draws a font of size s at s / 1.24 pixels; an average character is about half
    // that wide.
    let max_chars = ((width as f64 - 32.0) / (font_size as f64 * 0.47)).max(20.0) as usize;
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > max_chars {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// Draws `fig` into `path`.
pub fn draw_line_figure(path: &Path, fig: &LineFigure) -> Result<(), ReportError> {
    let cols = fig.cols.clamp(1, fig.panels.len().max(1));
    let rows = fig.panels.len().div_ceil(cols).max(1);
    let (pw, ph) = fig.panel_size;
    let width = pw * cols as u32;
    let legend_font = fig.font;
    let shared = shared_legend(&fig.panels);
    let (cell_legend_h, shared_h) = match fig.legend {
        LegendPlace::Shared => (0, legend_height(width, &shared, legend_font)),
        LegendPlace::PerPanel => (
            fig.panels
                .iter()
                .map(|p| legend_height(pw, &p.legend(), legend_font))
                .max()
                .unwrap_or(0),
            0,
        ),
    };
    let note_lines: Vec<String> = fig
        .notes
        .iter()
        .flat_map(|n| wrap(n, width, fig.font))
        .collect();
    let line_h = fig.font + 6;
    let notes_h = if note_lines.is_empty() {
        0
    } else {
        line_h * note_lines.len() as u32 + 8
    };
    let title_h = if fig.title.is_some() { TITLE_H } else { 0 };
    let cell_h = ph + cell_legend_h;
    let height = title_h + cell_h * rows as u32 + shared_h + notes_h;
    write_svg(path, (width, height), |root| {
        let area = match &fig.title {
            Some(t) => root.titled(t, (FONT, fig.font + 5))?,
            None => root.clone(),
        };
        let (grid, rest) = area.split_vertically(cell_h * rows as u32);
        let (strip, notes) = rest.split_vertically(shared_h);
        let cells = grid.split_evenly((rows, cols));
        for (panel, cell) in fig.panels.iter().zip(cells.iter()) {
            let (plot, legend) = cell.split_vertically(ph);
            draw_panel(&plot, panel, fig.font)?;
            if fig.legend == LegendPlace::PerPanel {
                legend_strip(&legend, &panel.legend(), legend_font)?;
            }
        }
        if fig.legend == LegendPlace::Shared {
            legend_strip(&strip, &shared, legend_font)?;
        }
        for (i, line) in note_lines.iter().enumerate() {
            notes.draw(&Text::new(
                line.clone(),
                (16, 4 + (i as u32 * line_h) as i32),
                (FONT, fig.font)
                    .into_font()
                    .color(&RGBColor(0x33, 0x33, 0x33)),
            ))?;
        }
        Ok(())
    })
}

/// The y range of a panel: from 0 (linear) or the smallest positive value (log) to a little above
/// the largest, bands included.
fn y_range(panel: &LinePanel) -> (f64, f64) {
    let log = panel.y_scale == YScale::Log;
    let vals: Vec<f64> = panel
        .curves
        .iter()
        .flat_map(|c| {
            c.points
                .iter()
                .map(|p| p.1)
                .chain(c.band.iter().flat_map(|b| [b.1, b.2]))
        })
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .collect();
    let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
    if log {
        if hi.is_finite() && lo > 0.0 {
            // A little room at both ends; at least a decade, so that a tick shows.
            let (lo, hi) = (lo / 1.3, hi * 1.3);
            let mid = (lo * hi).sqrt();
            (lo.min(mid / 10f64.sqrt()), hi.max(mid * 10f64.sqrt()))
        } else {
            (1e-3, 1.0)
        }
    } else if hi.is_finite() && hi > 0.0 {
        (lo.min(0.0), hi * 1.06)
    } else {
        (0.0, 1.0)
    }
}

/// The x range of a panel: from 0 (or the smallest x, if negative) to the largest x.
fn x_range(panel: &LinePanel) -> (f64, f64) {
    let xs = panel
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.0));
    let (lo, hi) = xs.fold((0.0f64, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if hi.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (lo, lo + 1.0)
    }
}

const X_LABELS: usize = 6;
const Y_LABELS: usize = 7;

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    panel: &LinePanel,
    font: u32,
) -> Result<(), Box<dyn std::error::Error>> {
    let (x0, x1) = x_range(panel);
    let (y0, y1) = y_range(panel);
    let xd = tick_decimals(x0, x1, X_LABELS);
    let x_fmt = move |v: &f64| format!("{v:.xd$}");
    let last = x_fmt(&x1);
    let log = panel.y_scale == YScale::Log;
    let dropped = panel
        .curves
        .iter()
        .flat_map(|c| c.points.iter())
        .filter(|p| log && p.1.is_finite() && p.1 <= 0.0)
        .count();
    let title = if dropped > 0 {
        format!("{} ({dropped} values ≤ 0 not drawn)", panel.title)
    } else {
        panel.title.clone()
    };
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(&title, (FONT, font + 3))
        .margin(10)
        .margin_right(right_margin(&last, font))
        .x_label_area_size(font * 3 + 4)
        .y_label_area_size(font * 5);
    if log {
        let chart = builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?;
        finish(chart, panel, font, &x_fmt, &|v: &f64| fmt_log_tick(*v))
    } else {
        let yd = tick_decimals(y0, y1, Y_LABELS);
        let chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
        finish(chart, panel, font, &x_fmt, &move |v: &f64| {
            format!("{v:.yd$}")
        })
    }
}

/// Mesh, bands and curves on a chart with a linear x axis.
fn finish<'a, 'b: 'a, Y>(
    mut chart: ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, Y>>,
    panel: &LinePanel,
    font: u32,
    x_fmt: &dyn Fn(&f64) -> String,
    y_fmt: &dyn Fn(&f64) -> String,
) -> Result<(), Box<dyn std::error::Error>>
where
    Y: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(panel.x_desc.as_str())
        .y_desc(panel.y_desc.as_str())
        .x_labels(X_LABELS)
        .y_labels(Y_LABELS)
        .x_label_formatter(x_fmt)
        .y_label_formatter(y_fmt)
        .label_style((FONT, font))
        .axis_desc_style((FONT, font + 1))
        .max_light_lines(1)
        .light_line_style(RGBColor(0xF2, 0xF2, 0xF2))
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;
    let log = panel.y_scale == YScale::Log;
    let keep = |v: f64| if log && v <= 0.0 { f64::NAN } else { v };
    for c in &panel.curves {
        let band: Vec<(f64, f64, f64)> = c
            .band
            .iter()
            .copied()
            .filter(|b| b.1.is_finite() && b.2.is_finite() && (!log || b.1 > 0.0))
            .collect();
        if band.len() >= 2 {
            let mut poly: Vec<(f64, f64)> = band.iter().map(|b| (b.0, b.2)).collect();
            poly.extend(band.iter().rev().map(|b| (b.0, b.1)));
            chart.draw_series(std::iter::once(Polygon::new(
                poly,
                c.style.colour.mix(0.12).filled(),
            )))?;
        }
    }
    let n = panel.curves.len().max(1);
    let mut off = OffScaleMarks::default();
    for (i, c) in panel.curves.iter().enumerate() {
        let pts: Vec<(f64, f64)> = c.points.iter().map(|&(x, y)| (x, keep(y))).collect();
        off.extend(draw_curve(
            &mut chart,
            &pts,
            &c.style,
            i as f64 / n as f64,
            None,
        )?);
    }
    draw_off_scale(&mut chart, &off)
}

/// The style request of a condition of the follow-up (ArmBalls): `space` (`efr`, `vae`, `bvae`,
/// or "" for RPE), module `choice` (`flat`, `random`, `lp`, or "" for RPE) and the `tag` of its
/// variant campaign ("" for the main campaign).
///
/// Colour is the family: the goal space in the main campaign (RPE black, EFR bluish green, VAE
/// blue, β-VAE vermillion, other spaces the next free colour), one colour per variant campaign
/// (its conditions are compared with each other and with their main-campaign twins). Dash is the
/// module choice: LP solid, flat dashed, random dotted, RPE long-dashed. Marker is the space
/// (RPE x, EFR square, VAE triangle, β-VAE diamond, others circle), hollow in a variant campaign.
/// [`super::assign_styles`] resolves what is left (two conditions of one variant campaign with
/// the same choice, runs split by goal sampler or latent size).
pub fn followup_request(space: &str, choice: &str, tag: &str) -> StyleRequest {
    // (goal space, colour, marker): none (RPE), the engineered features, the VAE, the β-VAE.
    let spaces = [
        ("", RGBColor(0x00, 0x00, 0x00), 6),
        (ugl_types::ENGINEERED_SPACE.0, RGBColor(0x00, 0x9E, 0x73), 1),
        (ugl_types::learners::VAE.name, RGBColor(0x00, 0x72, 0xB2), 2),
        (
            ugl_types::learners::BVAE.name,
            RGBColor(0xD5, 0x5E, 0x00),
            3,
        ),
    ];
    let known = spaces.iter().find(|s| s.0 == space);
    let own = known.map(|s| s.1);
    let marker = known.map_or(0, |s| s.2);
    // Module choices: learning progress solid, flat dashed, random dotted, others long-dashed.
    let dash = [
        ugl_types::LEARNING_PROGRESS.name,
        ugl_types::FLAT.name,
        ugl_types::RANDOM_MODULE.name,
    ]
    .iter()
    .position(|c| *c == choice)
    .unwrap_or(3);
    let family = if tag.is_empty() {
        format!("space:{space}")
    } else {
        format!("tag:{tag}")
    };
    StyleRequest {
        family,
        colour: if tag.is_empty() { own } else { None },
        dash,
        marker,
        filled: tag.is_empty(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::{DASHES, assign_styles};

    /// The follow-up's conditions as the committed campaigns hold them (`armballs`,
    /// `armballs-capacity`, `armballs-still`), in the page's order.
    const FOLLOWUP: [(&str, &str, &str); 16] = [
        ("", "", ""),
        ("efr", "flat", ""),
        ("efr", "random", ""),
        ("efr", "lp", ""),
        ("vae", "flat", ""),
        ("vae", "random", ""),
        ("vae", "lp", ""),
        ("bvae", "flat", ""),
        ("bvae", "random", ""),
        ("bvae", "lp", ""),
        ("bvae", "flat", "capacity"),
        ("bvae", "random", "capacity"),
        ("bvae", "lp", "capacity"),
        ("", "", "still"),
        ("efr", "flat", "still"),
        ("efr", "lp", "still"),
    ];

    fn pairs(styles: &[LineStyle]) -> Vec<(RGBColor, Option<(i32, i32)>)> {
        styles.iter().map(|s| (s.colour, s.dash)).collect()
    }

    fn assert_unique(styles: &[LineStyle]) {
        let p = pairs(styles);
        for (i, a) in p.iter().enumerate() {
            assert!(
                !p[..i].contains(a),
                "series {i} shares colour and dash {a:?} with an earlier one: {p:?}"
            );
        }
    }

    #[test]
    fn followup_conditions_get_unique_styles_that_keep_their_meaning() {
        let reqs: Vec<StyleRequest> = FOLLOWUP
            .iter()
            .map(|(s, c, t)| followup_request(s, c, t))
            .collect();
        let styles = assign_styles(&reqs, 4.0, 2);
        assert_unique(&styles);
        // Dash is the choice wherever a family has it free: flat dashed, random dotted, LP solid.
        for ((_, choice, _), s) in FOLLOWUP.iter().zip(&styles) {
            let want = match *choice {
                "lp" => DASHES[0],
                "flat" => DASHES[1],
                "random" => DASHES[2],
                _ => DASHES[3],
            };
            assert_eq!(s.dash, want, "{choice}");
        }
        // The main campaign keeps the goal spaces' colours; each variant campaign has one colour
        // of its own, used by none of the main campaign's families; variants' markers are hollow.
        assert_eq!(styles[3].colour, RGBColor(0x00, 0x9E, 0x73));
        assert_eq!(styles[15].colour, styles[13].colour);
        assert_ne!(styles[10].colour, styles[13].colour);
        for v in 10..16 {
            assert!(styles[..10].iter().all(|m| m.colour != styles[v].colour));
            assert!(!styles[v].marker.1);
        }
        // RPE is never hidden under another condition: its style is its own.
        assert!(styles[1..].iter().all(|s| *s != styles[0]));
    }

    #[test]
    fn assigned_styles_are_unique_however_crowded_and_deterministic() {
        // 40 series of one family, all asking for the solid line; then families that all ask
        // for the same colour.
        let crowd: Vec<StyleRequest> = (0..40)
            .map(|i| StyleRequest {
                family: if i < 20 {
                    "a".into()
                } else {
                    format!("f{}", i % 7)
                },
                colour: Some(RGBColor(0, 0x72, 0xB2)),
                dash: 0,
                marker: i % 7,
                filled: true,
            })
            .collect();
        let styles = assign_styles(&crowd, 4.0, 2);
        assert_eq!(styles.len(), 40);
        assert_unique(&styles);
        assert_eq!(styles, assign_styles(&crowd, 4.0, 2));
        // The first series gets exactly what it asked for.
        assert_eq!(styles[0].colour, RGBColor(0, 0x72, 0xB2));
        assert_eq!(styles[0].dash, None);
    }

    fn panel(curves: Vec<Curve>) -> LinePanel {
        LinePanel {
            title: "t".into(),
            x_desc: "x".into(),
            y_desc: "y".into(),
            y_scale: YScale::FromZero,
            curves,
        }
    }

    #[test]
    fn every_legend_entry_is_drawn_in_its_curves_style() {
        let reqs: Vec<StyleRequest> = FOLLOWUP
            .iter()
            .map(|(s, c, t)| followup_request(s, c, t))
            .collect();
        let styles = assign_styles(&reqs, 4.0, 2);
        let curves: Vec<Curve> = styles
            .iter()
            .enumerate()
            .map(|(i, s)| Curve {
                label: format!("c{i}"),
                style: s.clone(),
                points: vec![(0.0, 0.0), (1.0, i as f64)],
                band: Vec::new(),
            })
            .collect();
        let panels = vec![panel(curves.clone()), panel(curves.clone())];
        let legend = shared_legend(&panels);
        assert_eq!(legend.len(), curves.len(), "each entry once");
        for (c, (icon, label)) in curves.iter().zip(&legend) {
            assert_eq!(label, &c.label);
            match icon {
                Icon::Line {
                    colour,
                    dash,
                    width,
                    marker: Some(m),
                } => {
                    assert_eq!(*colour, c.style.colour);
                    assert_eq!(*dash, c.style.dash, "{label}: the legend's dash");
                    assert_eq!(*width, c.style.width);
                    assert_eq!(m, &c.style.marker, "{label}: the legend's marker");
                }
                other => panic!("{label}: {other:?}"),
            }
        }
    }

    #[test]
    fn the_figure_is_deterministic_and_its_ticks_are_whole_numbers() {
        let reqs: Vec<StyleRequest> = FOLLOWUP[..4]
            .iter()
            .map(|(s, c, t)| followup_request(s, c, t))
            .collect();
        let styles = assign_styles(&reqs, 4.0, 2);
        let curves: Vec<Curve> = styles
            .iter()
            .enumerate()
            .map(|(i, s)| Curve {
                label: format!("series {i}"),
                style: s.clone(),
                points: (0..=50)
                    .map(|k| (k as f64 * 100.0, (k * (i + 1)) as f64 / 400.0))
                    .collect(),
                band: Vec::new(),
            })
            .collect();
        let mut log = panel(curves.clone());
        log.y_scale = YScale::Log;
        let fig = LineFigure {
            title: Some("a title".into()),
            panels: vec![panel(curves), log],
            cols: 2,
            panel_size: (400, 300),
            legend: LegendPlace::PerPanel,
            notes: vec!["a note".into()],
            font: 13,
        };
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.svg"), dir.path().join("b.svg"));
        draw_line_figure(&a, &fig).unwrap();
        draw_line_figure(&b, &fig).unwrap();
        let svg = std::fs::read_to_string(&a).unwrap();
        assert_eq!(svg, std::fs::read_to_string(&b).unwrap());
        let tick = |t: &str| svg.contains(&format!(">\n{t}\n</text>"));
        assert!(tick("5000"), "whole-number ticks");
        assert!(!svg.contains("5000.0") && !tick("5000."));
        assert!(
            tick("0.1") && !tick("0.10"),
            "no trailing zeros on the y axis"
        );
        // One format on the log axis: 1e-3 style (no "0.001" beside "1e-5").
        assert!(tick("1e-2") && tick("1e-1"), "{svg}");
        assert!(!tick("0.01"));
    }
}
