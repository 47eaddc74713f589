//! The paper's Figure 5 (appendix): the effect of a radial flow (Rezende & Mohamed 2015) on an
//! isotropic Gaussian, the transformation the RFVAE stacks ten of (docs/original-code.md section 5;
//! the benchmark's `repr::rfvae`): `z' = z + beta h(a, r) (z - c)`, `h = 1 / (a + r)`,
//! `r = |z - c|`, invertible for `beta >= -a`. Drawn from seeded samples, so the figure is the
//! same on every render.

use std::path::Path;

use plotters::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{FONT, FigureFile, plain_panel, write_svg};
use crate::error::ReportError;

pub const FILE: &str = "fig5_radial_flow.svg";
const SAMPLES: usize = 1000;
const PANEL: u32 = 330;
const TITLE_H: u32 = 36;

/// One radial flow: centre `c`, `a > 0`, `beta >= -a`.
pub fn radial_flow(z: (f64, f64), c: (f64, f64), a: f64, beta: f64) -> (f64, f64) {
    let (dx, dy) = (z.0 - c.0, z.1 - c.1);
    let r = dx.hypot(dy);
    let bh = beta / (a + r);
    (z.0 + bh * dx, z.1 + bh * dy)
}

/// Seeded standard normal pairs (Box-Muller).
fn gaussian_samples(n: usize) -> Vec<(f64, f64)> {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    (0..n)
        .map(|_| {
            let u: f64 = 1.0 - rng.random_range(0.0..1.0);
            let v: f64 = rng.random_range(0.0..1.0);
            let r = (-2.0 * u.ln()).sqrt();
            let t = std::f64::consts::TAU * v;
            (r * t.cos(), r * t.sin())
        })
        .collect()
}

/// Draws the figure: the Gaussian, then a contracting and an expanding flow around `c`.
pub fn draw(fig_dir: &Path) -> Result<FigureFile, ReportError> {
    let z = gaussian_samples(SAMPLES);
    let c = (1.0, 0.5);
    let panels: [(String, Vec<(f64, f64)>); 3] = [
        ("z ~ N(0, I)".into(), z.clone()),
        (
            "contraction: a = 1, beta = -0.9".into(),
            z.iter().map(|&p| radial_flow(p, c, 1.0, -0.9)).collect(),
        ),
        (
            "expansion: a = 1, beta = 3".into(),
            z.iter().map(|&p| radial_flow(p, c, 1.0, 3.0)).collect(),
        ),
    ];
    let path = fig_dir.join(FILE);
    write_svg(&path, (PANEL * 3, PANEL + TITLE_H), |root| {
        let area = root.titled(
            "A radial flow on an isotropic Gaussian (centre c = (1, 0.5), red cross)",
            (FONT, 16),
        )?;
        let areas = area.split_evenly((1, 3));
        for ((title, pts), a) in panels.iter().zip(areas.iter()) {
            let inside = |p: &&(f64, f64)| p.0.abs() < 4.0 && p.1.abs() < 4.0;
            let outside = pts.len() - pts.iter().filter(inside).count();
            let title = if outside > 0 {
                format!("{title} ({outside} of {} outside)", pts.len())
            } else {
                title.clone()
            };
            let mut chart = plain_panel(a, &title, (-4.0, 4.0), 5, ("z1", "z2"))?;
            chart.draw_series(
                pts.iter()
                    .filter(inside)
                    .map(|&p| Circle::new(p, 1, RGBColor(0x00, 0x72, 0xB2).mix(0.5).filled())),
            )?;
            chart.draw_series(std::iter::once(Cross::new(c, 5, RED.stroke_width(2))))?;
        }
        Ok(())
    })?;
    Ok(FigureFile {
        path,
        link: format!("figures/{FILE}"),
        caption: "A radial flow on an isotropic Gaussian: contraction and expansion around a \
                  centre"
            .into(),
        env: String::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radial_flow_moves_points_along_the_ray_from_the_centre() {
        let c = (1.0, 0.5);
        // r = 2 along x: z' = z + beta / (a + r) (z - c).
        let z = radial_flow((3.0, 0.5), c, 1.0, 3.0);
        assert!(
            (z.0 - 5.0).abs() < 1e-12 && (z.1 - 0.5).abs() < 1e-12,
            "{z:?}"
        );
        let z = radial_flow((3.0, 0.5), c, 1.0, -0.9);
        assert!((z.0 - 2.4).abs() < 1e-12, "{z:?}");
        // The centre is fixed; beta = 0 is the identity.
        assert_eq!(radial_flow(c, c, 1.0, 3.0), c);
        assert_eq!(radial_flow((0.3, -2.0), c, 1.0, 0.0), (0.3, -2.0));
        // The samples are standard normal (mean ~0, variance ~1).
        let s = gaussian_samples(20_000);
        let m = s.iter().map(|p| p.0).sum::<f64>() / s.len() as f64;
        let v = s.iter().map(|p| p.1 * p.1).sum::<f64>() / s.len() as f64;
        assert!(m.abs() < 0.03 && (v - 1.0).abs() < 0.03, "{m} {v}");
    }
}
