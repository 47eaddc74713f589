//! SVG figures (plotters' SVG backend, deterministic bytes): shared styles and helpers.
//!
//! Every condition gets a colour (Okabe–Ito, colour-blind safe), a marker shape and a dash
//! pattern, so the curves stay apart on a greyscale print as well.

pub mod budget;
/// The environment illustrations (Figures 1 and 6) run the environment itself: they need the
/// science crate, behind the `environment-figures` feature (on in the `ugl` binary).
#[cfg(feature = "environment-figures")]
pub mod environment;
pub mod goal_space;
pub mod klc_curves;
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

use crate::ReportError;
use crate::load::rank;
use ugl_types::LearnerInfo;

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

/// The paper's algorithms, in the report's order: RPE, RGE-EFR, then the registry's learners
/// that the paper evaluated (PCA, Isomap, AE, VAE, RFVAE). They index [`ALGO_COLOURS`] and the
/// marker shapes; every other algorithm takes the following slots.
pub fn algos() -> Vec<&'static str> {
    let mut v = vec!["rpe", "rge-efr"];
    v.extend(LearnerInfo::paper_algos());
    v
}

/// Okabe–Ito without its yellow (too pale on white), one per known algorithm, then extra colours.
pub const ALGO_COLOURS: [RGBColor; 10] = [
    RGBColor(0x00, 0x00, 0x00), // rpe: black
    RGBColor(0xE6, 0x9F, 0x00), // efr: orange
    RGBColor(0x56, 0xB4, 0xE9), // pca: sky blue
    RGBColor(0x00, 0x9E, 0x73), // isomap: bluish green
    RGBColor(0x00, 0x72, 0xB2), // ae: blue
    RGBColor(0xD5, 0x5E, 0x00), // vae: vermillion
    RGBColor(0xCC, 0x79, 0xA7), // rfvae: reddish purple
    RGBColor(0x88, 0x22, 0x55), // others: wine
    RGBColor(0x44, 0xAA, 0x99), // teal
    RGBColor(0x77, 0x77, 0x77), // grey
];

/// Display name of an environment.
pub fn env_name(env: &str) -> String {
    ugl_types::EnvSpec::display_of(env)
}

/// Display name of an algorithm (`rge-vae` → `RGE-VAE`): `RGE-` and the registry's display
/// name of the learner; unknown names in capitals.
pub fn algo_name(algo: &str) -> String {
    match algo {
        "rpe" => "RPE".into(),
        "rge-efr" => "RGE-EFR".into(),
        "rge-efr-position" => "RGE-EFR (position only)".into(),
        other => match LearnerInfo::by_algo(other) {
            Some(l) => format!("RGE-{}", l.display),
            None => other.to_uppercase(),
        },
    }
}

/// An algorithm with its variant: `RGE-VAE (corrected)`; `RGE-AE` for variant `none`.
/// *faithful* is the original code's behaviour, defects included (docs/original-code.md section 5);
/// *corrected* has those defects fixed.
pub fn condition_name(algo: &str, variant: &str) -> String {
    let a = algo_name(algo);
    match variant {
        "" | "none" => a,
        v => format!("{a} ({v})"),
    }
}

/// Display name of a goal sampler: `KDE`, `Gaussian` (the VAE's isotropic prior), `uniform`
/// (EFR), `none` (RPE).
pub fn sampler_name(sampler: &str) -> String {
    match sampler {
        "kde" => "KDE".into(),
        "gaussian" => "Gaussian".into(),
        other => other.to_string(),
    }
}

/// Display name of a learner (`vae` → `VAE`): the registry's, else in capitals.
pub fn learner_name(learner: &str) -> String {
    match LearnerInfo::by_name(learner) {
        Some(l) => l.display.to_string(),
        None => learner.to_uppercase(),
    }
}

/// The environment's true latent dimension (the paper's "complete" representation): 2 for
/// ArmBall (ball x, y), 3 for ArmArrow (x, y, angle).
pub fn true_latents(env: &str) -> Option<i64> {
    ugl_types::EnvSpec::by_name(env).map(|e| e.true_latents as i64)
}

/// The paper's panel order for one algorithm's conditions: environments in the report's order,
/// then the over-complete 10 latents before the true dimension (larger latents first).
pub fn panel_order(env: &str, latents: i64) -> impl Ord + use<> {
    (
        ugl_types::EnvSpec::order(env),
        env.to_string(),
        std::cmp::Reverse(latents),
    )
}

/// Colours of the goal samplers where they are what a figure compares: KDE blue, Gaussian
/// vermillion (Okabe–Ito; 30% and 45% luminance, apart in greyscale too).
pub fn sampler_colour(sampler: &str) -> RGBColor {
    match sampler {
        "kde" => RGBColor(0x00, 0x72, 0xB2),
        "gaussian" => RGBColor(0xD5, 0x5E, 0x00),
        _ => RGBColor(0x77, 0x77, 0x77),
    }
}

/// Marker slot of a goal sampler where samplers are compared: KDE circle, Gaussian triangle.
pub fn sampler_marker_slot(sampler: &str) -> usize {
    match sampler {
        "kde" => 0,
        "gaussian" => 2,
        _ => 3,
    }
}

/// Line style of a variant where variants are compared: faithful (and `none`) solid, corrected
/// dashed.
pub fn variant_dash(variant: &str) -> Option<(i32, i32)> {
    if variant == "corrected" {
        Some((8, 5))
    } else {
        None
    }
}

/// Markers of the corrected variant are hollow, the others filled.
pub fn variant_filled(variant: &str) -> bool {
    variant != "corrected"
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
#[derive(Debug, Clone)]
pub struct LineStyle {
    pub colour: RGBColor,
    /// (dash, gap) in pixels; `None` solid.
    pub dash: Option<(i32, i32)>,
    /// Marker outline (see [`marker_points`]) and whether it is filled.
    pub marker: (Vec<(i32, i32)>, bool),
    pub width: u32,
}

/// Draws a curve (its finite points; a non-finite y breaks the line) with about 8 markers,
/// staggered by `stagger` in `0..1` so that markers of overlapping curves do not coincide, and
/// a legend entry `label` (line and marker) when given.
pub fn draw_curve<'a, 'b: 'a>(
    chart: &mut Chart2d<'a, 'b>,
    pts: &[(f64, f64)],
    style: &LineStyle,
    stagger: f64,
    label: Option<String>,
) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::element::DashedPathElement;
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for &(x, y) in pts {
        if y.is_finite() {
            segments.last_mut().expect("one segment").push((x, y));
        } else if !segments.last().expect("one segment").is_empty() {
            segments.push(Vec::new());
        }
    }
    segments.retain(|s| !s.is_empty());
    let (dash_len, gap) = style.dash.unwrap_or((SOLID, 0));
    let line_style = style.colour.stroke_width(style.width);
    let (mpts, filled) = style.marker.clone();
    let col = style.colour;
    let mut label = label;
    for seg in &segments {
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
    let finite: Vec<(f64, f64)> = segments.iter().flatten().copied().collect();
    let step = (finite.len() / 8).max(1);
    let offset = ((stagger.clamp(0.0, 0.999) * step as f64) as usize).min(step - 1);
    chart.draw_series(
        finite
            .iter()
            .skip(offset)
            .step_by(step)
            .map(|&pt| marker(pt, &mpts, filled, col, 1)),
    )?;
    Ok(())
}

/// The fixed KLC axis range of an environment: 0 .. ln(number of achievable cells), which is the
/// KLC of outcomes all in one cell (docs/original-code.md section 4). `None` for unknown environments.
pub fn klc_max(env: &str) -> Option<f64> {
    ugl_types::EnvSpec::by_name(env).map(|e| e.klc.max_klc())
}

/// Colour and marker slot of an algorithm: its position among the known ones; unknown algorithms
/// take the following slots in the order given by `unknown_index`.
pub fn algo_slot(algo: &str, unknown_index: usize) -> usize {
    let known = algos();
    let r = rank(algo, &known);
    if r < known.len() {
        r
    } else {
        known.len() + unknown_index
    }
}

pub fn colour(slot: usize) -> RGBColor {
    ALGO_COLOURS[slot % ALGO_COLOURS.len()]
}

/// Marker outlines, in pixels around (0, 0): circle, square, triangle up, diamond, triangle down,
/// plus, x; then the same shapes hollow. (Stars are kept for the paper's values.)
pub fn marker_points(slot: usize, size: f64) -> (Vec<(i32, i32)>, bool) {
    const N_SHAPES: usize = 7;
    let shape = slot % N_SHAPES;
    let filled = (slot / N_SHAPES).is_multiple_of(2);
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

/// A square panel without grid lines over `[lo, hi]^2`, with `labels` ticks per axis: the
/// illustrations' (Figures 1, 5, 6) common frame.
pub fn plain_panel<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    (lo, hi): (f64, f64),
    labels: usize,
) -> Result<PanelChart<'a, DB>, Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 14))
        .margin(8)
        .x_label_area_size(26)
        .y_label_area_size(30)
        .build_cartesian_2d(lo..hi, lo..hi)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(labels)
        .y_labels(labels)
        .label_style((FONT, 11))
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
    crate::write_file(path, compact_svg(&svg).as_bytes())
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
#[derive(Debug, Clone)]
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

/// Width of the icon column of a legend entry, in pixels.
const ICON_W: i32 = 30;

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
