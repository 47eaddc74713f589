//! SVG figures (plotters' SVG backend, deterministic bytes): shared styles and helpers.
//!
//! Every condition gets a colour (Okabe–Ito, colour-blind safe), a marker shape and a dash
//! pattern, so the curves stay apart on a greyscale print as well.

pub mod budget;
/// The environment illustrations (Figures 1 and 6) run the environment itself: they need the
/// science crate, behind the `environment-figures` feature (on in the `ugl` binary).
#[cfg(feature = "environment-figures")]
pub mod environment;
pub mod final_strip;
pub mod goal_space;
pub mod klc_curves;
pub mod lines;
pub mod outcomes;
pub mod radial_flow;
pub mod sampler_compare;
pub mod training_loss;
pub mod variants;

/// The figures' directory inside the report's output directory (markdown links start with it).
pub const DIR: &str = "figures";

/// Figure 1: the environments and their rendered images (`environment-figures`).
pub const FIG1: &str = "fig1_environments.svg";
/// Figure 6: one DMP episode on ArmBall (`environment-figures`).
pub const FIG6: &str = "fig6_dmp_episode.svg";

use std::path::{Path, PathBuf};

use plotters::element::ComposedElement;
use plotters::prelude::*;
use plotters::style::RGBColor;

use crate::error::ReportError;
use crate::load::rank;
pub use crate::names::{
    algo_name, algos, condition_name, env_name, klc_max, learner_name, panel_order,
    sampler_marker_slot, sampler_name, style_algos, true_latents,
};

/// A figure written by the report, with what the markdown needs to show it.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureFile {
    /// Absolute or `out`-relative path of the SVG, as written.
    pub path: PathBuf,
    /// `figures/<name>.svg`, for the markdown link.
    pub link: String,
    /// Alt text / caption.
    pub caption: String,
    /// The environment the figure is about.
    pub env: String,
}

/// A pixel offset.
pub type Px = (i32, i32);
/// A marker: its filled polygon and its outline, at a point.
pub type MarkerElement<C, DB> = ComposedElement<C, DB, Polygon<Px>, PathElement<Px>>;

pub const FONT: &str = "sans-serif";

/// Okabe–Ito without its yellow (too pale on white), one per algorithm of [`style_algos`].
pub const ALGO_COLOURS: [RGBColor; 16] = [
    RGBColor(0x00, 0x00, 0x00), // rpe: black
    RGBColor(0xE6, 0x9F, 0x00), // efr: orange
    RGBColor(0x56, 0xB4, 0xE9), // pca: sky blue
    RGBColor(0x00, 0x9E, 0x73), // isomap: bluish green
    RGBColor(0x00, 0x72, 0xB2), // ae: blue
    RGBColor(0xD5, 0x5E, 0x00), // vae: vermillion
    RGBColor(0xCC, 0x79, 0xA7), // rfvae: reddish purple
    RGBColor(0x8C, 0x51, 0x0A), // efr, position only: brown
    RGBColor(0xEE, 0x33, 0x77), // efr, mixed (a control): magenta
    RGBColor(0x33, 0x22, 0x88), // pca-centred: indigo
    RGBColor(0x88, 0x22, 0x55), // bvae: wine
    RGBColor(0xCC, 0x66, 0x77), // conv-vae: rose
    RGBColor(0xDD, 0xCC, 0x77), // conv-bvae: sand
    RGBColor(0x77, 0x77, 0x77), // gaussian-projection (a control): grey
    RGBColor(0x44, 0xAA, 0x99), // external: teal
    RGBColor(0x99, 0x99, 0x33), // others: olive
];

/// Colours of the goal samplers where they are what a figure compares: KDE blue, Gaussian
/// vermillion (Okabe–Ito; 30% and 45% luminance, apart in greyscale too).
pub fn sampler_colour(sampler: &str) -> RGBColor {
    let [r, g, b] = crate::names::sampler_rgb(sampler);
    RGBColor(r, g, b)
}

/// Line style of a variant where variants are compared: faithful (and `none`) solid, corrected
/// dashed.
pub fn variant_dash(variant: &str) -> Option<(i32, i32)> {
    if crate::names::variant_dashed(variant) {
        Some((8, 5))
    } else {
        None
    }
}

/// Markers of the corrected variant are hollow, the others filled.
pub fn variant_filled(variant: &str) -> bool {
    !crate::names::variant_dashed(variant)
}

/// A dash this long never ends within a panel: a solid line drawn by the dashed-path element.
pub const SOLID: i32 = 1_000_000;

/// A chart with linear f64 axes on the SVG backend.
pub type Chart2d<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// How one mean curve is drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct LineStyle {
    pub colour: RGBColor,
    /// (dash, gap) in pixels; `None` solid.
    pub dash: Option<(i32, i32)>,
    /// Marker outline (see [`marker_points`]) and whether it is filled.
    pub marker: (Vec<(i32, i32)>, bool),
    pub width: u32,
}

impl LineStyle {
    /// The legend icon of a curve drawn in this style: the same colour, dash, width and marker,
    /// so that a legend entry always looks like its series.
    pub fn icon(&self) -> Icon {
        Icon::Line {
            colour: self.colour,
            dash: self.dash,
            width: self.width,
            marker: Some(self.marker.clone()),
        }
    }

    /// The legend entry of a curve drawn in this style.
    pub fn legend_item(&self, label: impl Into<String>) -> (Icon, String) {
        (self.icon(), label.into())
    }
}

/// What a series asks of its line style; [`assign_styles`] turns the requests of one figure into
/// styles that are all different in (colour, dash).
#[derive(Debug, Clone, PartialEq)]
pub struct StyleRequest {
    /// Series of one family share their colour (an algorithm, a goal space, a variant campaign).
    pub family: String,
    /// The family's own colour, if it has one; a family without one, or whose colour an earlier
    /// family took, gets the first free colour of [`EXTRA_COLOURS`].
    pub colour: Option<RGBColor>,
    /// The wanted dash: an index into [`DASHES`] (the series' kind within its family).
    pub dash: usize,
    /// Marker shape slot ([`marker_points`]) and whether the marker is filled.
    pub marker: usize,
    pub filled: bool,
}

/// The dash patterns, (dash, gap) in pixels: solid, dashed, dotted, long-dashed.
pub const DASHES: [Option<(i32, i32)>; 4] = [None, Some((8, 5)), Some((2, 4)), Some((14, 4))];

/// Colours for families without their own (variant campaigns, unknown algorithms), in the order
/// they are handed out: the rest of Okabe–Ito, then Tol's muted scheme, dark to light.
pub const EXTRA_COLOURS: [RGBColor; 12] = [
    RGBColor(0xCC, 0x79, 0xA7), // reddish purple
    RGBColor(0x88, 0x22, 0x55), // wine
    RGBColor(0x44, 0xAA, 0x99), // teal
    RGBColor(0xE6, 0x9F, 0x00), // orange
    RGBColor(0x56, 0xB4, 0xE9), // sky blue
    RGBColor(0x33, 0x22, 0x88), // indigo
    RGBColor(0x99, 0x99, 0x33), // olive
    RGBColor(0xAA, 0x44, 0x99), // purple
    RGBColor(0x11, 0x77, 0x33), // green
    RGBColor(0x77, 0x77, 0x77), // grey
    RGBColor(0x00, 0x9E, 0x73), // bluish green
    RGBColor(0xD5, 0x5E, 0x00), // vermillion
];

/// The k-th fallback colour: [`EXTRA_COLOURS`], then distinct greys (never reached in practice,
/// but the styles stay unique however many series a figure has).
fn extra_colour(k: usize) -> RGBColor {
    match EXTRA_COLOURS.get(k) {
        Some(&c) => c,
        None => {
            let g = ((k - EXTRA_COLOURS.len()) % 200) as u8;
            RGBColor(g, g, g)
        }
    }
}

/// The styles of a figure's series, in the order of `requests`: each family keeps one colour (its
/// own, else the first free extra colour) and each series its wanted dash when no earlier series
/// of that colour has it, else the next free one; a colour whose four dashes are all taken hands
/// the series on to the next free colour. No two series get the same (colour, dash); markers are
/// `marker_size` pixels, lines `width`. Deterministic: the same requests give the same styles.
pub fn assign_styles(requests: &[StyleRequest], marker_size: f64, width: u32) -> Vec<LineStyle> {
    let mut family_colour: Vec<(&str, RGBColor)> = Vec::new();
    let mut taken: Vec<(RGBColor, usize)> = Vec::new();
    let mut next_extra = 0;
    let mut fresh_colour = |family_colour: &Vec<(&str, RGBColor)>| loop {
        let c = extra_colour(next_extra);
        next_extra += 1;
        if family_colour.iter().all(|f| f.1 != c) {
            break c;
        }
    };
    requests
        .iter()
        .map(|r| {
            let mut colour = match family_colour.iter().find(|f| f.0 == r.family) {
                Some(f) => f.1,
                None => {
                    let c = match r.colour {
                        Some(c) if family_colour.iter().all(|f| f.1 != c) => c,
                        _ => fresh_colour(&family_colour),
                    };
                    family_colour.push((&r.family, c));
                    c
                }
            };
            let dash = loop {
                let free = (0..DASHES.len())
                    .map(|i| (r.dash + i) % DASHES.len())
                    .find(|d| !taken.contains(&(colour, *d)));
                match free {
                    Some(d) => break d,
                    None => {
                        colour = fresh_colour(&family_colour);
                        family_colour.push(("", colour));
                    }
                }
            };
            taken.push((colour, dash));
            let (pts, _) = marker_points(r.marker, marker_size);
            LineStyle {
                colour,
                dash: DASHES[dash],
                marker: (pts, r.filled),
                width,
            }
        })
        .collect()
}

/// A curve cut to the y range of its chart: what is drawn of it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClippedCurve {
    /// The pieces of line inside the range: a non-finite y breaks the line, and a step that
    /// leaves the range ends at the frame (at `crossing(a, b, edge)`), so that nothing is drawn
    /// beyond it.
    pub segments: Vec<Vec<(f64, f64)>>,
    /// The data points inside the range (where markers go).
    pub inside: Vec<(f64, f64)>,
    /// The points outside it: drawn as an arrow at the frame with their value, never clamped as
    /// if they were data.
    pub off_scale: Vec<OffScale>,
}

/// A data point outside the y range of its chart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OffScale {
    pub x: f64,
    pub y: f64,
    /// Above the range (else below).
    pub above: bool,
}

/// Cuts `pts` to `lo..=hi` in y. `crossing(a, b, edge)` is where the step from the inside point
/// `a` to the outside point `b` meets the edge value (linear interpolation in data space for a
/// linear axis; [`draw_curve`] interpolates in pixels, which is right for any axis).
pub fn clip_curve(
    pts: &[(f64, f64)],
    (lo, hi): (f64, f64),
    crossing: impl Fn((f64, f64), (f64, f64), f64) -> (f64, f64),
) -> ClippedCurve {
    let mut out = ClippedCurve::default();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let inside = |y: f64| y >= lo && y <= hi;
    let mut prev: Option<(f64, f64)> = None;
    for &(x, y) in pts {
        if !y.is_finite() {
            if !current.is_empty() {
                out.segments.push(std::mem::take(&mut current));
            }
            prev = None;
            continue;
        }
        let edge = |y: f64| if y > hi { hi } else { lo };
        match prev {
            Some(p) if inside(p.1) && inside(y) => current.push((x, y)),
            Some(p) if inside(p.1) => {
                // Leaving the range: the line goes on to the frame and stops there.
                current.push(crossing(p, (x, y), edge(y)));
                out.segments.push(std::mem::take(&mut current));
            }
            Some(p) if inside(y) => {
                // Coming back: the line starts at the frame.
                current.push(crossing((x, y), p, edge(p.1)));
                current.push((x, y));
            }
            Some(p) if (p.1 > hi) != (y > hi) => {
                // Across the whole range in one step.
                let a = crossing(p, (x, y), edge(p.1));
                let b = crossing((x, y), p, edge(y));
                out.segments.push(vec![a, b]);
            }
            Some(_) => {}
            None if inside(y) => current.push((x, y)),
            None => {}
        }
        if inside(y) {
            out.inside.push((x, y));
        } else {
            out.off_scale.push(OffScale {
                x,
                y,
                above: y > hi,
            });
        }
        prev = Some((x, y));
    }
    if !current.is_empty() {
        out.segments.push(current);
    }
    out
}

/// The value of an off-scale point as printed beside its arrow: 3 significant digits.
pub fn fmt_off_scale(v: f64) -> String {
    let a = v.abs();
    if a >= 1e5 || (a > 0.0 && a < 1e-3) {
        format!("{v:.2e}")
    } else {
        let decimals = (2 - a.log10().floor().max(-3.0) as i32).clamp(0, 6) as usize;
        format!("{v:.decimals$}")
    }
}

/// The arrow of an off-scale point, in pixels around the point where it meets the frame: a
/// triangle pointing out of the plot.
pub fn off_scale_arrow(above: bool) -> Vec<(i32, i32)> {
    if above {
        vec![(0, -1), (5, 8), (-5, 8)]
    } else {
        vec![(0, 1), (5, -8), (-5, -8)]
    }
}

/// Draws a curve (its finite points; a non-finite y breaks the line) with about 8 markers,
/// staggered by `stagger` in `0..1` so that markers of overlapping curves do not coincide, and
/// a legend entry `label` (line and marker, [`LineStyle::icon`]'s look) when given. Points
/// outside the chart's y range are not clamped: the line runs to the frame and stops (see
/// [`clip_curve`]); the points are returned, for [`draw_off_scale`] to mark at the frame with
/// their values once every curve of the panel is drawn.
pub fn draw_curve<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    pts: &[(f64, f64)],
    style: &LineStyle,
    stagger: f64,
    label: Option<String>,
) -> Result<OffScaleMarks, Box<dyn std::error::Error>>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    use plotters::element::DashedPathElement;
    let y_range = chart.y_range();
    let (lo, hi) = (
        y_range.start.min(y_range.end),
        y_range.start.max(y_range.end),
    );
    // Where a step leaves the range, in pixels (exact on a linear or a logarithmic axis).
    let crossing = |a: (f64, f64), b: (f64, f64), edge: f64| {
        let (pa, pb) = (chart.backend_coord(&a), chart.backend_coord(&b));
        let pe = chart.backend_coord(&(a.0, edge));
        let t = if pb.1 != pa.1 {
            ((pe.1 - pa.1) as f64 / (pb.1 - pa.1) as f64).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a.0 + t * (b.0 - a.0), edge)
    };
    let clipped = clip_curve(pts, (lo, hi), crossing);
    let (dash_len, gap) = style.dash.unwrap_or((SOLID, 0));
    let line_style = style.colour.stroke_width(style.width);
    let (mpts, filled) = style.marker.clone();
    let col = style.colour;
    let mut label = label;
    for seg in &clipped.segments {
        let series = chart.draw_series(std::iter::once(DashedPathElement::new(
            seg.clone(),
            dash_len,
            gap,
            line_style,
        )))?;
        if let Some(l) = label.take() {
            let lpts = mpts.clone();
            series.label(l).legend(move |(x, y)| {
                let (fill, outline) = icon_parts(&lpts, 13, filled, col, 1);
                EmptyElement::at((x, y))
                    + DashedPathElement::new(vec![(0, 0), (26, 0)], dash_len, gap, line_style)
                    + fill
                    + outline
            });
        }
    }
    let finite = &clipped.inside;
    let step = (finite.len() / 8).max(1);
    let offset = ((stagger.clamp(0.0, 0.999) * step as f64) as usize).min(step - 1);
    chart.draw_series(
        finite
            .iter()
            .skip(offset)
            .step_by(step)
            .map(|&pt| marker(pt, &mpts, filled, col, 1)),
    )?;
    Ok(OffScaleMarks(
        clipped.off_scale.into_iter().map(|o| (o, col)).collect(),
    ))
}

/// The points of curves that fell outside their chart's y range, with their curves' colours:
/// [`draw_off_scale`] draws them once every curve of a panel is drawn.
#[must_use = "off-scale points are drawn by draw_off_scale"]
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OffScaleMarks(pub Vec<(OffScale, RGBColor)>);

impl OffScaleMarks {
    pub fn extend(&mut self, other: OffScaleMarks) {
        self.0.extend(other.0);
    }
}

/// Draws the off-scale points of a panel: at the frame, above or below the point's x, an arrow
/// pointing out of the plot in the curve's colour, and the value printed beside it on a white
/// ground; points sharing an x are put side by side and their values one under the other.
pub fn draw_off_scale<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    marks: &OffScaleMarks,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let y_range = chart.y_range();
    let (lo, hi) = (
        y_range.start.min(y_range.end),
        y_range.start.max(y_range.end),
    );
    // (x, above, [(value, colour)]) of the points sharing an x and a side.
    type Group = (f64, bool, Vec<(f64, RGBColor)>);
    let mut groups: Vec<Group> = Vec::new();
    for (o, c) in &marks.0 {
        match groups.iter_mut().find(|g| g.0 == o.x && g.1 == o.above) {
            Some(g) => g.2.push((o.y, *c)),
            None => groups.push((o.x, o.above, vec![(o.y, *c)])),
        }
    }
    for (x, above, items) in &groups {
        let edge = if *above { hi } else { lo };
        let k = items.len() as i32;
        for (j, (y, c)) in items.iter().enumerate() {
            let j = j as i32;
            let arrow_dx = 12 * j;
            let text = fmt_off_scale(*y);
            let text_dx = 12 * k;
            let text_dy = if *above {
                3 + 13 * j
            } else {
                -15 - 13 * (k - 1 - j)
            };
            let w = (text.chars().count() as f64 * 6.2).ceil() as i32 + 4;
            chart.draw_series(std::iter::once(
                EmptyElement::at((*x, edge))
                    + Polygon::new(
                        off_scale_arrow(*above)
                            .into_iter()
                            .map(|(a, b)| (a + arrow_dx, b))
                            .collect::<Vec<_>>(),
                        c.filled(),
                    )
                    + Rectangle::new(
                        [(text_dx - 2, text_dy - 1), (text_dx + w, text_dy + 12)],
                        WHITE.mix(0.85).filled(),
                    )
                    + Text::new(text, (text_dx, text_dy), (FONT, 13).into_font().color(c)),
            ))?;
        }
    }
    Ok(())
}

/// Colour and marker slot of an algorithm: its position among the known ones; unknown algorithms
/// take the following slots in the order given by `unknown_index`.
pub fn algo_slot(algo: &str, unknown_index: usize) -> usize {
    let known = style_algos();
    let r = rank(algo, &known);
    if r < known.len() {
        r
    } else {
        known.len() + unknown_index
    }
}

/// The colour of a slot ([`algo_slot`]): [`ALGO_COLOURS`], then, for algorithms outside the
/// registry (external learners), colours none of the registry's algorithms has.
pub fn colour(slot: usize) -> RGBColor {
    const MORE: [RGBColor; 6] = [
        RGBColor(0xAA, 0x44, 0x99), // purple
        RGBColor(0x11, 0x77, 0x33), // green
        RGBColor(0x66, 0x11, 0x00), // dark red
        RGBColor(0x66, 0x99, 0xCC), // pale blue
        RGBColor(0xDD, 0xAA, 0x33), // ochre
        RGBColor(0x55, 0x55, 0x55), // dark grey
    ];
    match ALGO_COLOURS.get(slot) {
        Some(&c) => c,
        None => MORE[(slot - ALGO_COLOURS.len()) % MORE.len()],
    }
}

/// Marker outlines, in pixels around (0, 0): circle, square, triangle up, diamond, triangle down,
/// plus, x, triangle left, triangle right, pentagon, hexagon, bar, then again; always filled
/// (stars are kept for the paper's values; hollow markers mark the corrected variants, which
/// the caller decides).
pub fn marker_points(slot: usize, size: f64) -> (Vec<(i32, i32)>, bool) {
    const N_SHAPES: usize = 12;
    let shape = slot % N_SHAPES;
    // Filled: a hollow marker is the corrected variants' (the caller decides).
    let filled = true;
    let s = size;
    let poly = |pts: &[(f64, f64)]| -> Vec<(i32, i32)> {
        pts.iter()
            .map(|&(x, y)| ((x * s).round() as i32, (y * s).round() as i32))
            .collect()
    };
    let pts = match shape {
        0 => (0..12)
            .map(|i| {
                let a = i as f64 * std::f64::consts::PI / 6.0;
                ((a.cos() * s).round() as i32, (a.sin() * s).round() as i32)
            })
            .collect(),
        1 => poly(&[(-0.85, -0.85), (0.85, -0.85), (0.85, 0.85), (-0.85, 0.85)]),
        2 => poly(&[(0.0, -1.15), (1.0, 0.75), (-1.0, 0.75)]),
        3 => poly(&[(0.0, -1.25), (1.0, 0.0), (0.0, 1.25), (-1.0, 0.0)]),
        4 => poly(&[(0.0, 1.15), (1.0, -0.75), (-1.0, -0.75)]),
        7 => poly(&[(-1.15, 0.0), (0.75, -1.0), (0.75, 1.0)]),
        8 => poly(&[(1.15, 0.0), (-0.75, -1.0), (-0.75, 1.0)]),
        9 | 10 => {
            let n = if shape == 9 { 5 } else { 6 };
            let ring: Vec<(f64, f64)> = (0..n)
                .map(|i| {
                    let a = -std::f64::consts::FRAC_PI_2
                        + i as f64 * 2.0 * std::f64::consts::PI / n as f64;
                    (1.1 * a.cos(), 1.1 * a.sin())
                })
                .collect();
            poly(&ring)
        }
        11 => poly(&[(-0.45, -1.15), (0.45, -1.15), (0.45, 1.15), (-0.45, 1.15)]),
        5 | 6 => {
            // A plus; rotated by 45 degrees it is the "x" of slot 6.
            let plus = [
                (-0.35, -1.1),
                (0.35, -1.1),
                (0.35, -0.35),
                (1.1, -0.35),
                (1.1, 0.35),
                (0.35, 0.35),
                (0.35, 1.1),
                (-0.35, 1.1),
                (-0.35, 0.35),
                (-1.1, 0.35),
                (-1.1, -0.35),
                (-0.35, -0.35),
            ];
            if shape == 5 {
                poly(&plus)
            } else {
                let r = std::f64::consts::FRAC_1_SQRT_2;
                let rotated: Vec<(f64, f64)> = plus
                    .iter()
                    .map(|&(x, y)| (r * (x - y), r * (x + y)))
                    .collect();
                poly(&rotated)
            }
        }
        _ => unreachable!("shape < N_SHAPES"),
    };
    (pts, filled)
}

/// A five-pointed star, pointing up, in pixels around (0, 0).
pub fn star_points(outer: f64, inner: f64) -> Vec<(i32, i32)> {
    (0..10)
        .map(|i| {
            let r = if i % 2 == 0 { outer } else { inner };
            let a = -std::f64::consts::FRAC_PI_2 + i as f64 * std::f64::consts::PI / 5.0;
            ((a.cos() * r).round() as i32, (a.sin() * r).round() as i32)
        })
        .collect()
}

/// A marker as a plotters element at `at` (any coordinate system): a polygon filled with the
/// colour (or white when hollow) and outlined with it.
pub fn marker<C, DB: DrawingBackend>(
    at: C,
    pts: &[(i32, i32)],
    filled: bool,
    col: RGBColor,
    stroke: u32,
) -> MarkerElement<C, DB> {
    let fill = if filled { col.filled() } else { WHITE.filled() };
    let mut outline = pts.to_vec();
    if let Some(&first) = pts.first() {
        outline.push(first);
    }
    EmptyElement::at(at)
        + Polygon::new(pts.to_vec(), fill)
        + PathElement::new(outline, col.stroke_width(stroke))
}

/// The two parts of a marker for a legend icon, shifted right by `dx` pixels.
pub fn icon_parts(
    pts: &[(i32, i32)],
    dx: i32,
    filled: bool,
    col: RGBColor,
    stroke: u32,
) -> (Polygon<Px>, PathElement<Px>) {
    let shifted: Vec<(i32, i32)> = pts.iter().map(|&(a, b)| (a + dx, b)).collect();
    let fill = if filled { col.filled() } else { WHITE.filled() };
    let mut outline = shifted.clone();
    if let Some(&first) = shifted.first() {
        outline.push(first);
    }
    (
        Polygon::new(shifted, fill),
        PathElement::new(outline, col.stroke_width(stroke)),
    )
}

/// Dash pattern of the k-th condition sharing an algorithm in one panel: (dash, gap) in pixels,
/// `None` for a solid line.
pub fn dash_pattern(k: usize) -> Option<(i32, i32)> {
    match k % 4 {
        0 => None,
        1 => Some((8, 5)),
        2 => Some((2, 4)),
        _ => Some((14, 4)),
    }
}

/// A chart with f64 axes on any backend.
pub type PanelChart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A square panel without grid lines over `[lo, hi]^2`, with `labels` ticks per axis (as
/// precise as their step needs) and the axes' names `(x, y)`: the illustrations' (Figures 1, 5,
/// 6) common frame.
pub fn plain_panel<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    (lo, hi): (f64, f64),
    labels: usize,
    (x_desc, y_desc): (&str, &str),
) -> Result<PanelChart<'a, DB>, Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let decimals = tick_decimals(lo, hi, labels);
    let fmt = move |v: &f64| format!("{v:.decimals$}");
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 14))
        .margin(8)
        .margin_right(right_margin(&fmt(&hi), 11))
        .x_label_area_size(38)
        .y_label_area_size(46)
        .build_cartesian_2d(lo..hi, lo..hi)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(labels)
        .y_labels(labels)
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, 11))
        .axis_desc_style((FONT, 12))
        .draw()?;
    Ok(chart)
}

/// The unit circle (the boundary of the reachable disk), as a closed path of 181 points.
pub fn unit_circle() -> Vec<(f64, f64)> {
    (0..=180)
        .map(|i| {
            let a = i as f64 * std::f64::consts::PI / 90.0;
            (a.cos(), a.sin())
        })
        .collect()
}

/// Renders into a string with the SVG backend, then writes the file. `draw` gets the root area.
pub fn write_svg(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(
        &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>,
) -> Result<(), ReportError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let plot_err = |e: &dyn std::fmt::Display| ReportError::Plot {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        root.fill(&WHITE).map_err(|e| plot_err(&e))?;
        draw(&root).map_err(|e| plot_err(&e))?;
        root.present().map_err(|e| plot_err(&e))?;
    }
    crate::figures::write_file(path, compact_svg(&svg).as_bytes())
}

/// Drops attributes plotters writes with their SVG default values (`opacity="1"`, and the stroke
/// width of an element without stroke): the same picture in a third fewer bytes for scatters.
pub fn compact_svg(svg: &str) -> String {
    svg.replace(" stroke=\"none\" stroke-width=\"1\"", " stroke=\"none\"")
        .replace(" opacity=\"1\" ", " ")
}

/// Characters safe in a file name; anything else becomes `-`.
pub fn file_safe(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// Tick labels for epochs: integers, without the ".0" plotters prints for f64 by default.
pub fn fmt_epoch(v: &f64) -> String {
    format!("{:.0}", v)
}

/// The fewest decimals (at most 6) that print exactly every tick plotters puts on a linear axis
/// over `lo..hi` asked for `labels` labels: none for ticks at whole numbers (so `5000`, never
/// `5000.0` or, cut at the frame, `5000.`), one for ticks at 0.5 steps, two for 0.25 or 0.05...
pub fn tick_decimals(lo: f64, hi: f64, labels: usize) -> usize {
    use plotters::coord::ranged1d::Ranged;
    if !(lo.is_finite() && hi.is_finite()) || lo == hi {
        return 0;
    }
    let ticks = plotters::coord::types::RangedCoordf64::from(lo.min(hi)..lo.max(hi))
        .key_points(labels.max(1));
    (0..=6)
        .find(|&d| {
            let scale = 10f64.powi(d as i32);
            ticks
                .iter()
                .all(|t| ((t * scale) - (t * scale).round()).abs() < 1e-6 * scale.max(1.0))
        })
        .unwrap_or(6)
}

/// A tick label of a logarithmic axis, in one format for every tick: `1e-3`, `2e-3`, `1e0`.
pub fn fmt_log_tick(v: f64) -> String {
    if v > 0.0 && v.is_finite() {
        let e = v.log10().floor() as i32;
        let m = v / 10f64.powi(e);
        // Mantissas like 0.9999 from the division are rounded back to 1.
        let m = (m * 10.0).round() / 10.0;
        if (m - m.round()).abs() < 1e-9 {
            format!("{}e{e}", m.round() as i64)
        } else {
            format!("{m:.1}e{e}")
        }
    } else {
        String::new()
    }
}

/// The room (pixels) right of a plot that the last x tick label, centred on the frame's edge,
/// needs: half its estimated width and a few pixels.
pub fn right_margin(last_label: &str, font_size: u32) -> u32 {
    let half = (last_label.chars().count() as f64 * font_size as f64 * 0.3).ceil() as u32;
    (half + 6).max(12)
}

/// A linear f64 axis whose ticks are exactly `keys` (e.g. the centres of categories), labelled by
/// the chart's `x_label_formatter`. (plotters' `with_key_points` on an f64 range has no value
/// formatter, so its mesh cannot be configured.)
#[derive(Debug, Clone)]
pub struct KeyedAxis {
    pub range: std::ops::Range<f64>,
    pub keys: Vec<f64>,
}

impl plotters::coord::ranged1d::Ranged for KeyedAxis {
    type FormatOption = plotters::coord::ranged1d::NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        plotters::coord::types::RangedCoordf64::from(self.range.clone()).map(value, limit)
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            Vec::new()
        } else {
            self.keys.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.range.clone()
    }
}

impl plotters::coord::ranged1d::ValueFormatter<f64> for KeyedAxis {
    fn format(value: &f64) -> String {
        format!("{value}")
    }
}

/// The icon of a legend entry drawn outside the plots (see [`legend_strip`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Icon {
    /// A line segment, optionally dashed, optionally with a marker in its middle.
    Line {
        colour: RGBColor,
        dash: Option<(i32, i32)>,
        width: u32,
        marker: Option<(Vec<(i32, i32)>, bool)>,
    },
    /// A marker alone.
    Marker {
        colour: RGBColor,
        points: Vec<(i32, i32)>,
        filled: bool,
        stroke: u32,
    },
    /// A vertical whisker with caps (a confidence interval).
    Whisker { colour: RGBColor },
    /// A shaded box (a band).
    Band { colour: RGBColor },
}

/// The legend entry of the paper's final values: a hollow black star, as the plots draw them.
pub fn paper_star_item(label: &str) -> (Icon, String) {
    (
        Icon::Marker {
            colour: BLACK,
            points: star_points(8.0, 3.5),
            filled: false,
            stroke: 2,
        },
        label.to_string(),
    )
}

/// Width of the icon column of a legend entry, in pixels: room for two periods of the longest
/// dash on either side of the marker in its middle, so that no dashed line looks solid.
const ICON_W: i32 = 40;

/// Lays out `items` left to right, wrapping to a new row when the area is full, in a strip drawn
/// under the panels (so that no legend hides data). Text widths are estimated from the character
/// count, deterministically. Returns the height used.
pub fn legend_strip(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    items: &[(Icon, String)],
    font_size: u32,
) -> Result<i32, Box<dyn std::error::Error>> {
    use plotters::element::DashedPathElement;
    let (w, _) = area.dim_in_pixel();
    let (places, height) = legend_layout(w, items, font_size);
    for ((icon, label), &(x, y)) in items.iter().zip(&places) {
        match icon {
            Icon::Line {
                colour,
                dash,
                width,
                marker: m,
            } => {
                let (d, g) = dash.unwrap_or((SOLID, 0));
                area.draw(&DashedPathElement::new(
                    vec![(x, y), (x + ICON_W, y)],
                    d,
                    g,
                    colour.stroke_width(*width),
                ))?;
                if let Some((pts, filled)) = m {
                    area.draw(&marker((x + ICON_W / 2, y), pts, *filled, *colour, 1))?;
                }
            }
            Icon::Marker {
                colour,
                points,
                filled,
                stroke,
            } => {
                area.draw(&marker(
                    (x + ICON_W / 2, y),
                    points,
                    *filled,
                    *colour,
                    *stroke,
                ))?;
            }
            Icon::Whisker { colour } => {
                // As the plots draw an interval: a vertical bar with caps, in one colour.
                let c = x + ICON_W / 2;
                for path in [
                    vec![(c, y - 8), (c, y + 8)],
                    vec![(c - 5, y - 8), (c + 5, y - 8)],
                    vec![(c - 5, y + 8), (c + 5, y + 8)],
                ] {
                    area.draw(&PathElement::new(path, colour.stroke_width(2)))?;
                }
            }
            Icon::Band { colour } => {
                area.draw(&Rectangle::new(
                    [(x, y - 6), (x + ICON_W, y + 6)],
                    colour.mix(0.25).filled(),
                ))?;
            }
        }
        area.draw(&Text::new(
            label.clone(),
            (x + ICON_W + 8, y - font_size as i32 / 2 - 1),
            (FONT, font_size),
        ))?;
    }
    Ok(height)
}

/// Where [`legend_strip`] puts each item (the icon's left end and the row's centre line) in a
/// strip `width` pixels wide, and the height it needs.
fn legend_layout(width: u32, items: &[(Icon, String)], font_size: u32) -> (Vec<(i32, i32)>, i32) {
    let row_h = font_size as i32 + 10;
    let (mut x, mut y) = (16, row_h / 2 + 2);
    let mut places = Vec::with_capacity(items.len());
    for (_, label) in items {
        let text_w = (label.chars().count() as f64 * font_size as f64 * 0.56).ceil() as i32;
        let item_w = ICON_W + 8 + text_w + 22;
        if x > 16 && x + item_w > width as i32 {
            x = 16;
            y += row_h;
        }
        places.push((x, y));
        x += item_w;
    }
    (places, y + row_h / 2 + 2)
}

/// The height (pixels) that [`legend_strip`] needs for `items` in a strip `width` pixels wide.
pub fn legend_height(width: u32, items: &[(Icon, String)], font_size: u32) -> u32 {
    if items.is_empty() {
        return 0;
    }
    legend_layout(width, items, font_size).1.max(0) as u32
}

/// `items` without repeated labels (the first of each kept): the legend of a figure whose
/// panels share their entries.
pub fn dedup_legend(items: Vec<(Icon, String)>) -> Vec<(Icon, String)> {
    let mut seen = std::collections::BTreeSet::new();
    items
        .into_iter()
        .filter(|(_, l)| seen.insert(l.clone()))
        .collect()
}

/// Writes a file (figures are drawn into memory, then written here and recorded by their
/// section through [`output::Output`]).
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    std::fs::write(path, bytes).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every algorithm with a fixed style (the paper's, the position-only EFR and every learner
    /// of the registry) has its own colour and its own marker shape, drawn filled: an algorithm
    /// looks the same in every figure, and hollow markers are left to the corrected variants.
    #[test]
    fn every_known_algorithm_has_its_own_colour_and_a_filled_marker() {
        let known = style_algos();
        assert!(known.contains(&"rge-gaussian-projection") && known.contains(&"rge-bvae"));
        assert!(known.len() <= ALGO_COLOURS.len(), "a colour per algorithm");
        let mut seen = Vec::new();
        for (slot, a) in known.iter().enumerate() {
            assert_eq!(algo_slot(a, 7), slot, "{a}");
            let (pts, filled) = marker_points(slot, 4.0);
            assert!(filled, "{a}: hollow marker on a solid line");
            assert!(!seen.contains(&(colour(slot), pts.clone())), "{a}");
            assert!(
                known[..slot]
                    .iter()
                    .all(|b| colour(algo_slot(b, 0)) != colour(slot)),
                "{a} shares a colour"
            );
            seen.push((colour(slot), pts));
        }
        // An algorithm outside the registry takes the slots after them, filled, in colours of
        // its own.
        assert_eq!(algo_slot("rge-new", 0), known.len());
        for k in 0..4 {
            let slot = algo_slot("rge-new", k);
            assert!(marker_points(slot, 4.0).1);
            assert!(
                (0..known.len()).all(|s| colour(s) != colour(slot)),
                "external learner {k} shares a colour with a registry algorithm"
            );
        }
    }

    /// Linear interpolation in data space, as on a linear axis.
    fn linear(a: (f64, f64), b: (f64, f64), edge: f64) -> (f64, f64) {
        let t = (edge - a.1) / (b.1 - a.1);
        (a.0 + t * (b.0 - a.0), edge)
    }

    #[test]
    fn an_off_scale_point_is_never_clamped_as_if_it_were_data() {
        // Iteration 0 far above the rest, as in the training losses.
        let pts = [
            (0.0, 4000.0),
            (100.0, 400.0),
            (200.0, 200.0),
            (300.0, 100.0),
        ];
        let c = clip_curve(&pts, (0.0, 500.0), linear);
        assert_eq!(
            c.off_scale,
            vec![OffScale {
                x: 0.0,
                y: 4000.0,
                above: true
            }]
        );
        // No marker at the frame: markers go on the data inside only.
        assert_eq!(c.inside, pts[1..].to_vec());
        assert!(c.inside.iter().all(|p| p.1 != 500.0));
        // The line starts where the step from iteration 0 crosses the top edge.
        assert_eq!(c.segments.len(), 1);
        let start = c.segments[0][0];
        assert_eq!(start.1, 500.0);
        assert!(
            (start.0 - 100.0 * 3500.0 / 3600.0).abs() < 1e-9,
            "{start:?}"
        );
        // Leaving and coming back, crossing the whole range, and a NaN break.
        let pts = [
            (0.0, 1.0),
            (1.0, 3.0),
            (2.0, 1.0),
            (3.0, f64::NAN),
            (4.0, 1.0),
            (5.0, -1.0),
            (6.0, 3.0),
        ];
        let c = clip_curve(&pts, (0.0, 2.0), linear);
        assert_eq!(
            c.segments,
            vec![
                vec![(0.0, 1.0), (0.5, 2.0)],
                vec![(1.5, 2.0), (2.0, 1.0)],
                vec![(4.0, 1.0), (4.5, 0.0)],
                vec![(5.25, 0.0), (5.75, 2.0)],
            ]
        );
        assert_eq!(c.off_scale.len(), 3);
        assert!(c.off_scale[1].y == -1.0 && !c.off_scale[1].above);
    }

    #[test]
    fn off_scale_values_print_three_significant_digits() {
        assert_eq!(fmt_off_scale(4258.3), "4258");
        assert_eq!(fmt_off_scale(466.04), "466");
        assert_eq!(fmt_off_scale(1.2345), "1.23");
        assert_eq!(fmt_off_scale(-0.01234), "-0.0123");
        assert_eq!(fmt_off_scale(2.5e6), "2.50e6");
    }

    #[test]
    fn ticks_print_as_many_decimals_as_their_step_needs() {
        // Whole-number ticks: "5000", never "5000.0" (cut at the frame into "5000.").
        assert_eq!(tick_decimals(0.0, 5000.0, 6), 0);
        // plotters puts 0, 0.1, ..., 0.4 here (1 decimal), and 0, 0.05, ..., 0.4 with 10 labels.
        assert_eq!(tick_decimals(0.0, 0.43, 7), 1);
        assert_eq!(tick_decimals(0.0, 0.43, 10), 2);
        assert_eq!(tick_decimals(-4.0, 4.0, 9), 0);
        assert_eq!(tick_decimals(3.5, 3.5, 5), 0);
        assert_eq!(fmt_log_tick(1e-3), "1e-3");
        assert_eq!(fmt_log_tick(0.002), "2e-3");
        assert_eq!(fmt_log_tick(1.0), "1e0");
        assert_eq!(fmt_log_tick(0.0), "");
        assert!(right_margin("5000", 12) >= 4 * 12 * 3 / 10);
    }

    #[test]
    fn a_legend_icon_is_its_line_style() {
        let (pts, _) = marker_points(3, 4.0);
        let style = LineStyle {
            colour: RGBColor(1, 2, 3),
            dash: DASHES[2],
            marker: (pts, false),
            width: 2,
        };
        assert_eq!(
            style.legend_item("x"),
            (
                Icon::Line {
                    colour: style.colour,
                    dash: style.dash,
                    width: 2,
                    marker: Some(style.marker.clone()),
                },
                "x".to_string()
            )
        );
        // The legend's icon is wide enough to show a gap of every dash beside its marker.
        for (d, g) in DASHES.iter().flatten() {
            assert!(ICON_W >= 2 * (d + g), "{d} {g}");
        }
    }
}
