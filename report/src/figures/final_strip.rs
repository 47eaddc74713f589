//! The final-value strip beside a panel of curves: one column per curve, in the legend's order,
//! with the curve's final mean (its marker), an interval as a whisker with caps and, where the
//! paper gives one, the paper's value as a hollow star beside it. It shares the panel's y axis.
//! Bands around every curve of a crowded panel run into one mass; the strip keeps the
//! intervals, and the comparison with the paper, readable.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{FONT, marker, star_points};

/// One column of the strip.
#[derive(Debug, Clone, PartialEq)]
pub struct FinalColumn {
    pub colour: RGBColor,
    /// Marker outline ([`super::marker_points`]) and whether it is filled.
    pub marker: (Vec<(i32, i32)>, bool),
    /// The final mean; not finite: nothing drawn but the paper's star.
    pub mean: f64,
    /// The interval drawn as a whisker (the caption says which).
    pub interval: Option<(f64, f64)>,
    /// The paper's value.
    pub paper: Option<f64>,
}

/// Draws the strip on `area` over `y_min..y_max` (the panel's range; values outside are held at
/// the frame, which the whisker's missing cap shows), titled `title` with `x_desc` under it. The
/// top margin and the x label area match a panel built with margin 12, a 17 px caption and a
/// 42 px x label area, so that the two y axes line up.
pub fn draw_final_strip(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    columns: &[FinalColumn],
    (y_min, y_max): (f64, f64),
    title: &str,
    x_desc: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let n = columns.len().max(1) as f64;
    let mut strip = ChartBuilder::on(area)
        .caption(title, (FONT, 17))
        .margin(12)
        .margin_left(2)
        .x_label_area_size(42)
        .y_label_area_size(6)
        .build_cartesian_2d(0.0..n, y_min..y_max)?;
    strip
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_labels(8)
        .y_label_formatter(&|_| String::new())
        .x_desc(x_desc)
        .axis_desc_style((FONT, 14))
        .max_light_lines(0)
        .bold_line_style(RGBColor(0xDD, 0xDD, 0xDD))
        .draw()?;
    let inside = |v: f64| v.clamp(y_min, y_max);
    let star = star_points(7.0, 3.0);
    for (i, c) in columns.iter().enumerate() {
        let x = i as f64 + 0.35;
        if c.mean.is_finite() {
            if let Some((lo, hi)) = c
                .interval
                .filter(|(lo, hi)| lo.is_finite() && hi.is_finite())
            {
                strip.draw_series(std::iter::once(PathElement::new(
                    vec![(x, inside(lo)), (x, inside(hi))],
                    c.colour.stroke_width(2),
                )))?;
                for v in [lo, hi].into_iter().filter(|v| (y_min..=y_max).contains(v)) {
                    strip.draw_series(std::iter::once(PathElement::new(
                        vec![(x - 0.2, v), (x + 0.2, v)],
                        c.colour.stroke_width(2),
                    )))?;
                }
            }
            strip.draw_series(std::iter::once(marker(
                (x, inside(c.mean)),
                &c.marker.0,
                c.marker.1,
                c.colour,
                1,
            )))?;
        }
        if let Some(p) = c.paper {
            strip.draw_series(std::iter::once(marker(
                (i as f64 + 0.75, inside(p)),
                &star,
                false,
                c.colour,
                2,
            )))?;
        }
    }
    Ok(())
}
