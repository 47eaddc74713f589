//! What the goal spaces look like (the paper's argument that
//! a good learned space lays the object's positions out smoothly): for seed 0 of each learned
//! cell, the campaign stores (`DIR/goal_spaces/`, written by the benchmark's
//! `campaign::goal_space`) the latents of a 21 x 21 lattice of object positions over
//! [-1, 1]^2 (ArmArrow: angle 0) and, for networks, reconstructions of held-out images.
//!
//! - `goal_space_<env>_l<d>.svg`: one panel per learner: the lattice's latents (projected on
//!   their top two principal axes when d > 2), drawn as a mesh: lines of constant x coloured by
//!   x (light to dark red), lines of constant y coloured by y (light to dark blue). Only the
//!   lattice points the object can reach (inside the arm's unit disk) are drawn and projected:
//!   the data sets hold no image outside it, and what an encoder makes of an image it can never
//!   see says nothing about its goal space. The first panel is the key: the same mesh in the
//!   object's own coordinates. An unfolded, even mesh is a goal space that keeps the object's
//!   position; a crumpled or collapsed one loses it.
//! - `recon_<label>.png`: the stored reconstruction grids, copied (held-out images above, the
//!   network's reconstructions below).

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{FONT, FigureFile, condition_name, env_name, file_safe, write_svg};
use crate::error::ReportError;

/// One representation's figure data, as the campaign writes it.
pub use ugl_types::{GOAL_SPACE_DIR as DIR_NAME, GoalSpaceSample as Sample};

const PANEL: u32 = 240;
const TITLE_H: u32 = 36;
const COLS: usize = 4;

/// The samples of a campaign directory (none without `goal_spaces/`), sorted by label.
pub fn load(campaign_dir: &Path) -> Result<Vec<Sample>, ReportError> {
    let dir = campaign_dir.join(DIR_NAME);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Ok(Vec::new());
    };
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    let mut out = Vec::new();
    for p in paths {
        let bytes = std::fs::read(&p).map_err(|source| ReportError::Io {
            path: p.clone(),
            source,
        })?;
        let s: Sample = serde_json::from_slice(&bytes).map_err(|e| ReportError::Plot {
            path: p.clone(),
            message: format!("goal-space sample: {e}"),
        })?;
        let n = s.grid * s.grid;
        if s.grid < 2
            || s.positions.len() != n
            || s.grid_latents.len() != n
            || s.grid_latents.iter().any(|z| z.len() != s.latents)
        {
            return Err(ReportError::Plot {
                path: p,
                message: "goal-space sample: the lattice and its latents do not match".into(),
            });
        }
        out.push(s);
    }
    Ok(out)
}

/// The report's order of environments.
fn env_order(env: &str) -> usize {
    ugl_types::EnvSpec::order(env)
}

/// The report's order of learners in a figure.
fn order(s: &Sample) -> (usize, String) {
    let algo = ugl_types::LearnerInfo::paper_algos()
        .position(|a| a == s.algo)
        .unwrap_or(usize::MAX);
    (algo, s.variant.clone())
}

/// 2-D coordinates of the lattice: the latents themselves when d <= 2 (a single latent is drawn
/// against 0), else their projection on the top two principal axes (power iteration with
/// deflation on the d x d covariance; each axis signed so that its largest component is
/// positive).
pub fn project(z: &[Vec<f32>]) -> Vec<(f64, f64)> {
    let d = z.first().map_or(0, |r| r.len());
    if d <= 2 {
        return z
            .iter()
            .map(|r| (f64::from(r[0]), r.get(1).map_or(0.0, |&v| f64::from(v))))
            .collect();
    }
    let n = z.len() as f64;
    let mean: Vec<f64> = (0..d)
        .map(|j| z.iter().map(|r| f64::from(r[j])).sum::<f64>() / n)
        .collect();
    let mut cov = vec![0.0; d * d];
    for r in z {
        for a in 0..d {
            for b in 0..d {
                cov[a * d + b] += (f64::from(r[a]) - mean[a]) * (f64::from(r[b]) - mean[b]) / n;
            }
        }
    }
    let mut axes: Vec<Vec<f64>> = Vec::new();
    for _ in 0..2 {
        let mut v: Vec<f64> = (0..d).map(|j| 1.0 + j as f64 * 0.1).collect();
        for _ in 0..500 {
            let mut w: Vec<f64> = (0..d)
                .map(|a| (0..d).map(|b| cov[a * d + b] * v[b]).sum())
                .collect();
            for u in &axes {
                let dot: f64 = w.iter().zip(u).map(|(x, y)| x * y).sum();
                w.iter_mut().zip(u).for_each(|(x, y)| *x -= dot * y);
            }
            let norm = w.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm == 0.0 {
                break;
            }
            v = w.into_iter().map(|x| x / norm).collect();
        }
        let big = v
            .iter()
            .copied()
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(1.0);
        if big < 0.0 {
            v.iter_mut().for_each(|x| *x = -*x);
        }
        axes.push(v);
    }
    z.iter()
        .map(|r| {
            let c = |u: &[f64]| {
                (0..d)
                    .map(|j| (f64::from(r[j]) - mean[j]) * u[j])
                    .sum::<f64>()
            };
            (c(&axes[0]), c(&axes[1]))
        })
        .collect()
}

/// Light to dark shades of one hue, for a value in [-1, 1]; the lightest is still 30% of the
/// hue (no line fades into the white page).
fn shade(base: (u8, u8, u8), v: f64) -> RGBColor {
    let t = 0.3 + 0.7 * ((v + 1.0) / 2.0).clamp(0.0, 1.0);
    let mix = |c: u8| (230.0 * (1.0 - t) + f64::from(c) * t).round() as u8;
    RGBColor(mix(base.0), mix(base.1), mix(base.2))
}

const X_HUE: (u8, u8, u8) = (0xB2, 0x18, 0x2B);
const Y_HUE: (u8, u8, u8) = (0x21, 0x66, 0xAC);

fn panel_title(s: &Sample) -> String {
    condition_name(&s.algo, &s.variant)
}

/// Draw the mesh figures and copy the reconstruction images. Returns (meshes, reconstructions).
pub fn draw_all(
    samples: &[Sample],
    campaign_dir: &Path,
    fig_dir: &Path,
) -> Result<(Vec<FigureFile>, Vec<FigureFile>), ReportError> {
    let mut cells: Vec<(String, usize)> =
        samples.iter().map(|s| (s.env.clone(), s.latents)).collect();
    cells.sort_by_key(|(env, d)| (env_order(env), env.clone(), *d));
    cells.dedup();
    let mut meshes = Vec::new();
    for (env, d) in &cells {
        let mut panel: Vec<&Sample> = samples
            .iter()
            .filter(|s| s.env == *env && s.latents == *d)
            .collect();
        panel.sort_by_key(|s| order(s));
        let name = format!("goal_space_{}_l{d}.svg", file_safe(env));
        let path = fig_dir.join(&name);
        // The key, then one panel per learner.
        let cols = COLS.min(panel.len() + 1).max(1);
        let rows = (panel.len() + 1).div_ceil(cols);
        let title = format!(
            "{}, {d} latents: a 21 x 21 lattice of object positions in each goal space (seed 0){}",
            env_name(env),
            if *d > 2 {
                ", top two principal axes"
            } else {
                ""
            }
        );
        write_svg(
            &path,
            (PANEL * cols as u32, PANEL * rows as u32 + TITLE_H),
            |root| {
                let area = root.titled(&title, (FONT, 16))?;
                let areas = area.split_evenly((rows, cols));
                if let (Some(a), Some(first)) = (areas.first(), panel.first()) {
                    draw_key(a, first)?;
                }
                for (s, a) in panel.iter().zip(areas.iter().skip(1)) {
                    draw_mesh(a, s)?;
                }
                Ok(())
            },
        )?;
        meshes.push(FigureFile {
            path,
            link: format!("figures/{name}"),
            caption: format!(
                "{}, {d} latents: the lattice of reachable object positions (first panel, the key: \
                 lines of constant x red, of constant y blue, darker towards +1) in each goal \
                 space of seed 0{}",
                env_name(env),
                if *d > 2 {
                    ", projected on the top two principal axes of its latents (a flat projection \
                     can fold a mesh that the latents keep apart: the latent-quality table's \
                     trustworthiness and continuity measure the whole space)"
                } else {
                    ""
                }
            ),
            env: env.clone(),
        });
    }
    let mut recon = Vec::new();
    let mut with_recon: Vec<&Sample> = samples
        .iter()
        .filter(|s| s.reconstructions.is_some())
        .collect();
    with_recon.sort_by_key(|s| (env_order(&s.env), s.env.clone(), s.latents, order(s)));
    for s in with_recon {
        let file = s.reconstructions.as_ref().expect("filtered");
        let src = campaign_dir.join(DIR_NAME).join(file);
        let name = format!("recon_{}.png", file_safe(&s.representation));
        let path = fig_dir.join(&name);
        let bytes = std::fs::read(&src).map_err(|source| ReportError::Io {
            path: src.clone(),
            source,
        })?;
        crate::figures::write_file(&path, &bytes)?;
        recon.push(FigureFile {
            path,
            link: format!("figures/{name}"),
            caption: format!(
                "{}, {}, {} latents (seed {}): held-out images (top) and their reconstructions \
                 (bottom)",
                env_name(&s.env),
                panel_title(s),
                s.latents,
                s.seed
            ),
            env: s.env.clone(),
        });
    }
    Ok((meshes, recon))
}

/// Whether a lattice position is one the object can reach: inside the arm's unit disk.
pub fn reachable(p: [f64; 2]) -> bool {
    p[0] * p[0] + p[1] * p[1] < 1.0
}

/// The key: the lattice in the object's own coordinates, with the disk it can reach.
fn draw_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    s: &Sample,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let p: Vec<(f64, f64)> = s.positions.iter().map(|q| (q[0], q[1])).collect();
    draw_lattice(
        area,
        "key: object position",
        ("object x", "object y"),
        s,
        &p,
        true,
    )
}

fn draw_mesh<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    s: &Sample,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    // Project the reachable points only; the others get a placeholder they are never drawn at.
    let inside: Vec<Vec<f32>> = s
        .positions
        .iter()
        .zip(&s.grid_latents)
        .filter(|(q, _)| reachable(**q))
        .map(|(_, z)| z.clone())
        .collect();
    let mut projected = project(&inside).into_iter();
    let p: Vec<(f64, f64)> = s
        .positions
        .iter()
        .map(|q| {
            if reachable(*q) {
                projected
                    .next()
                    .expect("one projection per reachable point")
            } else {
                (f64::NAN, f64::NAN)
            }
        })
        .collect();
    let axes = if s.latents > 2 {
        ("principal axis 1", "principal axis 2")
    } else {
        ("latent 1", "latent 2")
    };
    draw_lattice(area, &panel_title(s), axes, s, &p, false)
}

/// The mesh of the lattice points `p` (the positions' order) that the object can reach.
fn draw_lattice<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    (x_desc, y_desc): (&str, &str),
    s: &Sample,
    p: &[(f64, f64)],
    disk: bool,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (&(x, y), q) in p.iter().zip(&s.positions) {
        if reachable(*q) && x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if disk {
        (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    // A collapsed space (all latents equal) still gets a visible frame.
    let pad = |a: f64, b: f64| ((b - a) * 0.05).max(1e-6);
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 14))
        .margin(6)
        .x_label_area_size(28)
        .y_label_area_size(34)
        .build_cartesian_2d((x0 - px)..(x1 + px), (y0 - py)..(y1 + py))?;
    let fmt = |lo: f64, hi: f64| {
        let dec = super::tick_decimals(lo, hi, 3);
        move |v: &f64| format!("{v:.dec$}")
    };
    let (fx, fy) = (fmt(x0, x1), fmt(y0, y1));
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(3)
        .y_labels(3)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .label_style((FONT, 10))
        .axis_desc_style((FONT, 11))
        .draw()?;
    if disk {
        let circle: Vec<(f64, f64)> = super::unit_circle();
        chart.draw_series(std::iter::once(PathElement::new(
            circle,
            RGBColor(0x88, 0x88, 0x88).stroke_width(1),
        )))?;
    }
    let g = s.grid;
    let ok = |k: usize| reachable(s.positions[k]) && p[k].0.is_finite() && p[k].1.is_finite();
    // Runs of consecutive reachable points along a lattice line.
    let pieces = |idx: Vec<usize>| -> Vec<Vec<(f64, f64)>> {
        let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for k in idx {
            if ok(k) {
                out.last_mut().expect("non-empty").push(p[k]);
            } else if !out.last().expect("non-empty").is_empty() {
                out.push(Vec::new());
            }
        }
        out.retain(|l| l.len() > 1);
        out
    };
    // Positions are x-major: index i * g + j holds (x_i, y_j).
    for i in 0..g {
        let x = s.positions[i * g][0];
        for line in pieces((0..g).map(|j| i * g + j).collect()) {
            chart.draw_series(std::iter::once(PathElement::new(line, shade(X_HUE, x))))?;
        }
    }
    for j in 0..g {
        let y = s.positions[j][1];
        for line in pieces((0..g).map(|i| i * g + j).collect()) {
            chart.draw_series(std::iter::once(PathElement::new(line, shade(Y_HUE, y))))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_keeps_two_latents_and_finds_the_principal_plane() {
        let two = vec![vec![1.0f32, 2.0], vec![3.0, -1.0]];
        assert_eq!(project(&two), vec![(1.0, 2.0), (3.0, -1.0)]);
        // Points in a plane spanned by (1,1,0)/sqrt2 (spread 3) and (0,0,1) (spread 1), plus an
        // unused direction: the projection recovers the spreads.
        let z: Vec<Vec<f32>> = (0..50)
            .map(|k| {
                let a = 3.0 * ((k as f64) * 0.7).sin();
                let b = ((k as f64) * 1.3).cos();
                let s = (a / 2f64.sqrt()) as f32;
                vec![s, s, b as f32]
            })
            .collect();
        let p = project(&z);
        let var = |f: &dyn Fn(&(f64, f64)) -> f64| {
            let m = p.iter().map(f).sum::<f64>() / p.len() as f64;
            p.iter().map(|q| (f(q) - m).powi(2)).sum::<f64>() / p.len() as f64
        };
        let (va, vb) = (var(&|q| q.0), var(&|q| q.1));
        let za: Vec<f64> = (0..50).map(|k| 3.0 * ((k as f64) * 0.7).sin()).collect();
        let m = za.iter().sum::<f64>() / 50.0;
        let want = za.iter().map(|v| (v - m).powi(2)).sum::<f64>() / 50.0;
        assert!((va - want).abs() < 1e-3 * want, "{va} vs {want}");
        assert!(vb < va && vb > 0.1, "{vb}");
    }
}
