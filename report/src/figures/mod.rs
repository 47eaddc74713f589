//! SVG figures (plotters' SVG backend, deterministic bytes): shared styles and helpers.
//!
//! Every condition gets a colour (Okabe–Ito, colour-blind safe), a marker shape and a dash
//! pattern, so the curves stay apart on a greyscale print as well.

pub mod klc_curves;
pub mod outcomes;

use std::path::{Path, PathBuf};

use plotters::element::ComposedElement;
use plotters::prelude::*;
use plotters::style::RGBColor;

use crate::ReportError;
use crate::load::rank;

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

/// Known algorithms, in the report's order; they index [`ALGO_COLOURS`] and the marker shapes.
pub const ALGOS: [&str; 7] = [
    "rpe",
    "rge-efr",
    "rge-pca",
    "rge-isomap",
    "rge-ae",
    "rge-vae",
    "rge-rfvae",
];

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
    match env {
        "armball" => "ArmBall".into(),
        "armarrow" => "ArmArrow".into(),
        other => other.to_string(),
    }
}

/// Display name of an algorithm (`rge-vae` → `RGE-VAE`).
pub fn algo_name(algo: &str) -> String {
    match algo {
        "rge-isomap" => "RGE-Isomap".into(),
        "rge-pca-centred" => "RGE-PCA (centred)".into(),
        "rge-external" => "RGE-external".into(),
        other => other.to_uppercase(),
    }
}

/// The fixed KLC axis range of an environment: 0 .. ln(number of achievable cells), which is the
/// KLC of outcomes all in one cell (PAPER-NOTES section 4). `None` for unknown environments.
pub fn klc_max(env: &str) -> Option<f64> {
    match env {
        "armball" => Some(756f64.ln()),
        "armarrow" => Some(22680f64.ln()),
        _ => None,
    }
}

/// Colour and marker slot of an algorithm: its position among the known ones; unknown algorithms
/// take the following slots in the order given by `unknown_index`.
pub fn algo_slot(algo: &str, unknown_index: usize) -> usize {
    let r = rank(algo, &ALGOS);
    if r < ALGOS.len() {
        r
    } else {
        ALGOS.len() + unknown_index
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
