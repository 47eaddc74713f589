//! The paper's Figures 1 and 6, drawn from the benchmark's own environment code (the report reads
//! no results for them): the ArmBall environment with the images the learners see, and one DMP
//! episode (docs/original-code.md sections 1-2: a 7-joint planar arm whose links sum to 1, so the
//! reachable set is the unit disk; 21 DMP parameters; 50 steps).

use std::path::Path;

use plotters::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ugl_bench::env::render::{PIXELS, SIDE, render_arrow_into, render_ball_into};
use ugl_bench::env::{EnvConfig, EnvKind, JOINTS, PARAMS, dmp, make_env};

use super::{
    FIG1, FIG6, FONT, FigureFile, Icon, LineStyle, PanelChart, draw_curve, legend_height,
    legend_strip, marker_points, plain_panel, write_svg,
};
use crate::error::ReportError;

const PANEL: u32 = 340;
const TITLE_H: u32 = 36;
/// Figure 6's joint panel is wider than the square world panel.
const JOINTS_EXTRA_W: u32 = 120;
/// The clip lines of Figure 6.
const CLIP_GREY: RGBColor = RGBColor(0x66, 0x66, 0x66);

/// The joint positions (base, then the end of each link) for a joint command `q` (units of pi,
/// clipped to [-1, 1]), as the benchmark's forward kinematics accumulates them.
pub fn joints(cfg: &EnvConfig, q: &[f64; JOINTS]) -> Vec<(f64, f64)> {
    let mut pts = vec![(0.0, 0.0)];
    let (mut x, mut y, mut cum) = (0.0, 0.0, 0.0);
    for k in 0..JOINTS {
        cum += q[k].clamp(-1.0, 1.0);
        let a = std::f64::consts::PI * (cfg.arm.angle_shift + cum);
        x += a.cos() * cfg.arm.lengths[k];
        y += a.sin() * cfg.arm.lengths[k];
        pts.push((x, y));
    }
    pts
}

/// The world square with the reachable disk.
fn world<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
) -> Result<PanelChart<'a, DB>, Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let mut chart = plain_panel(area, title, (-1.1, 1.1), 5, ("x", "y"))?;
    chart.draw_series(std::iter::once(PathElement::new(
        super::unit_circle(),
        RGBColor(0x99, 0x99, 0x99),
    )))?;
    Ok(chart)
}

/// A 70x70 image (x-major, values in [0, 1]) as grey squares over [-1, 1]^2, y up.
fn draw_image<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    img: &[f32],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let mut chart = plain_panel(
        area,
        title,
        (0.0, SIDE as f64),
        8,
        ("pixel column", "pixel row"),
    )?;
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, 0.0), (SIDE as f64, SIDE as f64)],
        BLACK.filled(),
    )))?;
    chart.draw_series((0..PIXELS).filter(|&k| img[k] > 0.0).map(|k| {
        let (x, y) = ((k / SIDE) as f64, (k % SIDE) as f64);
        let v = (img[k].clamp(0.0, 1.0) * 255.0).round() as u8;
        // Each pixel overlaps its next neighbours by a quarter pixel: the backend rounds each
        // rectangle to whole screen pixels (4 or 5 of them per image pixel here), and abutting
        // rectangles left 1-px gaps that read as grid lines inside the lit pixels.
        const OVERLAP: f64 = 0.25;
        Rectangle::new(
            [(x, y), (x + 1.0 + OVERLAP, y + 1.0 + OVERLAP)],
            RGBColor(v, v, v).filled(),
        )
    }))?;
    Ok(())
}

/// The object's initial state in `kind` with the constants `cfg`.
fn initial(cfg: &EnvConfig, kind: EnvKind) -> Vec<f64> {
    make_env(kind, cfg).initial_state().to_vec()
}

/// Figure 1: the arm at rest with the ball at its initial position, and the rendered images of
/// both environments at their initial states.
pub fn draw_environments(fig_dir: &Path) -> Result<FigureFile, ReportError> {
    let cfg = EnvConfig::default();
    let path = fig_dir.join(FIG1);
    let mut ball = vec![0f32; PIXELS];
    let ball_initial = initial(&cfg, EnvKind::ARMBALL);
    render_ball_into(ball_initial[0], ball_initial[1], &mut ball);
    let a = initial(&cfg, EnvKind::ARMARROW);
    let mut arrow = vec![0f32; PIXELS];
    render_arrow_into(a[0], a[1], a[2], &mut arrow);
    write_svg(&path, (PANEL * 3, PANEL + TITLE_H), |root| {
        let area = root.titled(
            "The environments (paper Figure 1): the arm, and the 70 x 70 images the learners see",
            (FONT, 16),
        )?;
        let areas = area.split_evenly((1, 3));
        let mut chart = world(&areas[0], "ArmBall: the arm at rest (q = 0)")?;
        let arm = joints(&cfg, &[0.0; JOINTS]);
        chart.draw_series(std::iter::once(PathElement::new(
            arm.clone(),
            BLACK.stroke_width(3),
        )))?;
        chart.draw_series(arm.iter().map(|&p| Circle::new(p, 3, BLACK.filled())))?;
        let b = (ball_initial[0], ball_initial[1]);
        chart.draw_series(std::iter::once(Circle::new(
            b,
            6,
            RGBColor(0xD5, 0x5E, 0x00).filled(),
        )))?;
        draw_image(&areas[1], "ArmBall image, ball at (0.6, 0.6)", &ball)?;
        draw_image(
            &areas[2],
            "ArmArrow image, arrow at (0.6, 0.6, 0.6)",
            &arrow,
        )?;
        Ok(())
    })?;
    Ok(FigureFile {
        path,
        link: format!("figures/{FIG1}"),
        caption: "The ArmBall environment and the rendered images of both environments".into(),
        env: String::new(),
    })
}

/// The first seeded uniform parameter vector (the distribution RPE samples) whose ArmBall
/// episode catches the ball, with its seed.
pub fn catching_parameters(cfg: &EnvConfig) -> Option<(u64, [f64; PARAMS])> {
    let env = make_env(EnvKind::ARMBALL, cfg);
    (0..10_000u64).find_map(|seed| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let theta: [f64; PARAMS] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        env.rollout(
            &theta,
            &mut ugl_bench::seed::stream(0, ugl_bench::seed::Component::Distractor),
        )
        .caught
        .then_some((seed, theta))
    })
}

/// Figure 6: one DMP episode on ArmBall: the arm every few steps (light to dark), the hand's
/// path, and the ball's start and end.
pub fn draw_dmp_episode(fig_dir: &Path) -> Result<Option<FigureFile>, ReportError> {
    let cfg = EnvConfig::default();
    let Some((seed, theta)) = catching_parameters(&cfg) else {
        return Ok(None);
    };
    let traj = dmp::trajectory(&cfg.dmp, &theta);
    let end = make_env(EnvKind::ARMBALL, &cfg).rollout(
        &theta,
        &mut ugl_bench::seed::stream(0, ugl_bench::seed::Component::Distractor),
    );
    let path = fig_dir.join(FIG6);
    let steps = traj.len();
    let title = format!(
        "One DMP episode on ArmBall (paper Figure 6): uniform parameters, seed {seed}, {steps} steps"
    );
    // The joints' commands as the DMP produces them (units of pi), not clipped: the arm clips
    // them to [-1, 1] (dashed lines), so a stretch beyond is a saturated joint.
    let styles: Vec<LineStyle> = (0..JOINTS)
        .map(|j| {
            let (pts, filled) = marker_points(j, 3.5);
            LineStyle {
                colour: super::colour(j + 1),
                dash: None,
                marker: (pts, filled),
                width: 2,
            }
        })
        .collect();
    let mut legend: Vec<(Icon, String)> = styles
        .iter()
        .enumerate()
        .map(|(j, s)| s.legend_item(format!("joint {}", j + 1)))
        .collect();
    legend.push((
        Icon::Line {
            colour: CLIP_GREY,
            dash: Some((6, 4)),
            width: 1,
            marker: None,
        },
        "±1: the arm clips each command to [-1, 1]".into(),
    ));
    let width = PANEL * 2 + JOINTS_EXTRA_W;
    let legend_h = legend_height(width, &legend, 13);
    let peak = traj
        .iter()
        .flat_map(|q| q.iter())
        .map(|v| v.abs())
        .fold(1.0f64, f64::max);
    // Symmetric, to the next 0.5 above the largest command (at least 1.5, so that ±1 shows).
    let y_lim = ((peak * 1.04) * 2.0).ceil().max(3.0) / 2.0;
    let clipped = traj
        .iter()
        .flat_map(|q| q.iter())
        .filter(|v| v.abs() > 1.0)
        .count();
    write_svg(&path, (width, PANEL + TITLE_H + legend_h), |root| {
        let area = root.titled(&title, (FONT, 15))?;
        let (plots, strip) = area.split_vertically(PANEL);
        legend_strip(&strip, &legend, 13)?;
        let (left, right) = plots.split_horizontally(PANEL);
        let mut chart = world(&left, "the arm every 7 steps, and the hand's path")?;
        for (t, q) in traj
            .iter()
            .enumerate()
            .filter(|(t, _)| t % 7 == 0 || *t + 1 == steps)
        {
            let shade = (200.0 * (1.0 - t as f64 / (steps - 1) as f64)) as u8;
            chart.draw_series(std::iter::once(PathElement::new(
                joints(&cfg, q),
                RGBColor(shade, shade, shade).stroke_width(2),
            )))?;
        }
        let hand: Vec<(f64, f64)> = traj
            .iter()
            .map(|q| *joints(&cfg, q).last().expect("seven links"))
            .collect();
        chart.draw_series(std::iter::once(PathElement::new(
            hand,
            RGBColor(0x00, 0x72, 0xB2).stroke_width(2),
        )))?;
        let ball = initial(&cfg, EnvKind::ARMBALL);
        let b = (ball[0], ball[1]);
        chart.draw_series(std::iter::once(Circle::new(
            b,
            6,
            RGBColor(0xD5, 0x5E, 0x00).mix(0.4).filled(),
        )))?;
        chart.draw_series(std::iter::once(Circle::new(
            (end.state[0], end.state[1]),
            6,
            RGBColor(0xD5, 0x5E, 0x00).filled(),
        )))?;
        // The joint commands over time.
        let last = (steps - 1) as f64;
        let y_decimals = super::tick_decimals(-y_lim, y_lim, 9);
        let mut joints_chart = ChartBuilder::on(&right)
            .caption(
                format!(
                    "the 7 joint commands, as the DMP outputs them ({clipped} of {} beyond ±1)",
                    steps * JOINTS
                ),
                (FONT, 14),
            )
            .margin(8)
            .margin_right(super::right_margin(&format!("{last:.0}"), 11))
            .x_label_area_size(38)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..last, -y_lim..y_lim)?;
        joints_chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("DMP step")
            .y_desc("joint command (units of pi rad)")
            .x_labels(6)
            .y_labels(9)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.y_decimals$}"))
            .label_style((FONT, 11))
            .axis_desc_style((FONT, 12))
            .draw()?;
        for lim in [-1.0, 1.0] {
            joints_chart.draw_series(std::iter::once(
                plotters::element::DashedPathElement::new(
                    vec![(0.0, lim), (last, lim)],
                    6,
                    4,
                    CLIP_GREY.stroke_width(1),
                ),
            ))?;
        }
        let mut off = super::OffScaleMarks::default();
        for (j, style) in styles.iter().enumerate() {
            let line: Vec<(f64, f64)> = traj
                .iter()
                .enumerate()
                .map(|(t, q)| (t as f64, q[j]))
                .collect();
            off.extend(draw_curve(
                &mut joints_chart,
                &line,
                style,
                j as f64 / JOINTS as f64,
                None,
            )?);
        }
        super::draw_off_scale(&mut joints_chart, &off)?;
        Ok(())
    })?;
    Ok(Some(FigureFile {
        path,
        link: format!("figures/{FIG6}"),
        caption: "One DMP episode on ArmBall that catches the ball: the arm and the hand's path, \
                  and the 7 joint commands as the DMP outputs them (the arm clips them to ±1)"
            .into(),
        env: String::new(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_drawn_arm_is_the_benchmarks_forward_kinematics() {
        let cfg = EnvConfig::default();
        let q = [0.1, -0.3, 0.5, 0.2, -0.9, 0.4, 1.5];
        let hand = cfg.arm.forward(&q).hand;
        let last = *joints(&cfg, &q).last().unwrap();
        assert!((last.0 - hand[0]).abs() < 1e-12 && (last.1 - hand[1]).abs() < 1e-12);
        // At rest the arm points straight up and reaches (0, 1).
        let top = *joints(&cfg, &[0.0; JOINTS]).last().unwrap();
        assert!(top.0.abs() < 1e-12 && (top.1 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_episode_shown_catches_and_moves_the_ball() {
        let cfg = EnvConfig::default();
        let (_, theta) = catching_parameters(&cfg).expect("a catching episode among 10,000");
        let r = make_env(EnvKind::ARMBALL, &cfg).rollout(
            &theta,
            &mut ugl_bench::seed::stream(0, ugl_bench::seed::Component::Distractor),
        );
        assert!(r.caught);
        assert!((r.state[0] - 0.6).hypot(r.state[1] - 0.6) > 1e-3);
    }
}
