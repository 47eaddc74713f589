//! The follow-up's own ArmBalls, as its authors' code has it (Laversanne-Finot, Péré & Oudeyer,
//! CoRL 2018; package `latentgoalexplo` of `flowersteam/Curiosity_Driven_Goal_Exploration`,
//! "CDGE" below; what it does is in `docs/followup-paper-sources.md` section 1). Nothing of that
//! code is copied here (it is GPL-3.0): this module re-expresses what it computes, and
//! `benchmark/tests/original_code.rs` checks it against outputs of that code (fixtures written by
//! `scripts/followup_fixtures.py`).
//!
//! It differs from our [`super::ArmBalls`] in the controller and the picture:
//! * **controller**: 7 radial basis functions per joint, 49 parameters in [-1, 1]; the joint
//!   command at step `t` is `clip(sum_k basis[t][k] theta[j][k], -1, 1)` and *is* the pose
//!   (position control, angles `pi * cumsum`), over 50 steps ([`RbfTable`]);
//! * **picture**: the final frame, 64 x 64 RGB, the ball yellow and the distractor blue on black,
//!   no arm ([`render_rgb`]).
//!
//! The body (7 joints, lengths 0.3 ... 0.05), the sticky catch (`|hand - ball| < object size`,
//! from the first step on), and the distractor's walk (reset every episode to (0.7, -0.45), a
//! step of `N(0, noise^2)` per coordinate and time step, clipped to +-0.95) are the same as ours.

use serde::{Deserialize, Serialize};

use super::{EnvConfig, EnvKind, Environment, Rollout};
use crate::config::OwnConstants;
use crate::invalid::{InvalidValue, exactly, within, within_each};
use crate::seed::{Stream, standard_normal};

/// Joints of the arm.
pub const JOINTS: usize = 7;
/// Radial basis functions per joint (CDGE `--n_rbf`, default 7).
pub const BASES: usize = 7;
/// Motor parameters: one weight per joint and basis function, joint-major (`theta[j * 7 + k]`,
/// CDGE `action.reshape(7, n_rbf)`).
pub const PARAMS: usize = JOINTS * BASES;
/// Steps of an episode (CDGE `n_timesteps`).
pub const STEPS: usize = 50;
/// The basis functions' standard deviation, in steps (CDGE `--sdev`, default 10).
pub const SDEV: f64 = 10.0;
/// The arm's segment lengths (CDGE `arm_lengths`).
pub const LENGTHS: [f64; JOINTS] = [0.3, 0.2, 0.2, 0.1, 0.1, 0.05, 0.05];
/// The distractor's walk is clipped to this box.
pub const DISTRACTOR_BOUND: f64 = 0.95;
/// Side of the picture, in pixels (CDGE `width`, `height`).
pub const SIDE: usize = 64;
/// Colour channels of the picture.
pub const CHANNELS: usize = 3;
/// Values of one picture: row-major (`y`, then `x`), channels last.
pub const VALUES: usize = SIDE * SIDE * CHANNELS;
/// The ball's drawn radius in the observer's pictures, whatever its physical size (CDGE
/// `MyArmBallsObserved`: `object_size=0.17`).
pub const BALL_RADIUS: f64 = 0.17;
/// The distractor's drawn radius.
pub const DISTRACTOR_RADIUS: f64 = 0.15;

/// The radial basis table: `basis[t][k]`, the weight of basis function `k` at step `t`.
///
/// CDGE `RbfController`: an indicator at the centre of each function, on an array 1.25 times
/// as long as the episode, filtered by a Gaussian of `sdev` steps (scipy's `gaussian_filter1d`,
/// zero padding, kernel truncated at `int(4 sdev + 0.5)` steps), divided by its largest value,
/// then cut to the episode. The centres are `width * (k + 1) + width / 4` with
/// `width = steps / bases` (integer division): steps 8, 15, ..., 50 for 50 steps and 7 functions,
/// so the last function contributes only its rising tail.
#[derive(Clone, Debug, PartialEq)]
pub struct RbfTable {
    /// `basis[t][k]`.
    pub basis: Vec<[f64; BASES]>,
}

impl RbfTable {
    /// The table for `steps` steps and a Gaussian of `sdev` steps.
    pub fn new(steps: usize, sdev: f64) -> RbfTable {
        let radius = (4.0 * sdev + 0.5) as i64;
        let kernel = gaussian_kernel(sdev, radius);
        // Every centre lies inside the longer array, so its peak, kernel[radius], is the
        // largest value of the filtered array.
        let peak = kernel[radius as usize];
        let width = (steps / BASES) as i64;
        let centres: [i64; BASES] = std::array::from_fn(|k| width * (k as i64 + 1) + width / 4);
        let basis = (0..steps as i64)
            .map(|t| {
                std::array::from_fn(|k| {
                    let d = t - centres[k];
                    if d.abs() <= radius {
                        kernel[(d + radius) as usize] / peak
                    } else {
                        0.0
                    }
                })
            })
            .collect();
        RbfTable { basis }
    }

    /// The joint commands of every step, clipped to [-1, 1] (CDGE: `einsum('ijk,jk->ij')`,
    /// then `np.clip`).
    pub fn commands(&self, theta: &[f64; PARAMS]) -> Vec<[f64; JOINTS]> {
        self.basis
            .iter()
            .map(|b| {
                std::array::from_fn(|j| {
                    let mut s = 0.0;
                    for k in 0..BASES {
                        s += b[k] * theta[j * BASES + k];
                    }
                    s.clamp(-1.0, 1.0)
                })
            })
            .collect()
    }
}

/// scipy's `_gaussian_kernel1d(sigma, 0, radius)`: `exp(-0.5 / sigma^2 * x^2)` for
/// `x = -radius ..= radius`, divided by its sum (numpy's pairwise sum, which for fewer than 128
/// values runs eight interleaved partial sums).
fn gaussian_kernel(sdev: f64, radius: i64) -> Vec<f64> {
    let c = -0.5 / (sdev * sdev);
    let phi: Vec<f64> = (-radius..=radius)
        .map(|x| libm::exp(c * (x * x) as f64))
        .collect();
    let sum = numpy_sum(&phi);
    phi.iter().map(|p| p / sum).collect()
}

/// numpy's float64 `sum` of a short contiguous array (its `pairwise_sum` below 128 values).
fn numpy_sum(a: &[f64]) -> f64 {
    let n = a.len();
    if n < 8 {
        return a.iter().fold(-0.0, |s, v| s + v);
    }
    assert!(n <= 128, "numpy_sum covers the unblocked case only");
    let mut r: [f64; 8] = std::array::from_fn(|j| a[j]);
    let mut i = 8;
    while i + 8 <= n {
        for j in 0..8 {
            r[j] += a[i + j];
        }
        i += 8;
    }
    let mut res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    while i < n {
        res += a[i];
        i += 1;
    }
    res
}

/// The follow-up's ArmBalls' own constants (its `[env.armballs-corl]` table; our DMP ArmBalls
/// has the same, in its own `[env.armballs]`): CDGE's defaults for the plotted runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Constants {
    /// The ball's start, in [-1, 1]² (the scene).
    #[serde(deserialize_with = "exactly")]
    pub ball_initial: [f64; 2],
    /// The distractor's position at the start of every episode (CDGE
    /// `distract_initial_pose`), inside the square [-0.95, 0.95]² it walks in.
    #[serde(deserialize_with = "exactly")]
    pub distractor_initial: [f64; 2],
    /// Standard deviation of the distractor's step per time step (CDGE `--distract_noise`; 0
    /// keeps it still), in [0, 1] (a step the size of the scene's half-width already jumps
    /// across the distractor's square).
    pub distractor_noise: f64,
}

impl Default for Constants {
    fn default() -> Self {
        Constants {
            ball_initial: [0.6, 0.6],
            distractor_initial: [0.7, -0.45],
            distractor_noise: 0.1,
        }
    }
}

impl OwnConstants for Constants {
    fn check(&self, key: &dyn Fn(&str) -> String) -> Result<(), InvalidValue> {
        within_each(key, "ball_initial", &self.ball_initial, -1.0, 1.0)?;
        let b = DISTRACTOR_BOUND;
        within_each(key, "distractor_initial", &self.distractor_initial, -b, b)?;
        within(&key("distractor_noise"), self.distractor_noise, 0.0, 1.0)
    }
}

/// The constants of an episode. In a campaign they come from the `[env]` table's shared
/// `object_size` and the environment's own [`Constants`]; the shared arm and DMP constants do
/// not apply.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Catch radius (CDGE `--object_size`; the plotted runs: 0.1).
    pub object_size: f64,
    /// The ball's start.
    pub ball_initial: [f64; 2],
    /// The distractor's start, every episode.
    pub distractor_initial: [f64; 2],
    /// The distractor's step standard deviation (CDGE `--distract_noise`).
    pub distractor_noise: f64,
}

impl Scene {
    /// The scene of an `[env]` table.
    pub fn of(cfg: &EnvConfig) -> Scene {
        let own = cfg.own::<Constants>(EnvKind::ARMBALLS_CORL);
        Scene {
            object_size: cfg.object_size,
            ball_initial: own.ball_initial,
            distractor_initial: own.distractor_initial,
            distractor_noise: own.distractor_noise,
        }
    }
}

impl Default for Scene {
    fn default() -> Self {
        Scene::of(&EnvConfig::default())
    }
}

/// The end of an episode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Episode {
    /// The ball's final position (the outcome the exploration is measured on).
    pub ball: [f64; 2],
    /// The distractor's final position.
    pub distractor: [f64; 2],
    /// The hand's final position.
    pub hand: [f64; 2],
    /// The last joint command (the final pose).
    pub pose: [f64; JOINTS],
    /// The ball was caught during the episode.
    pub caught: bool,
}

/// The follow-up's ArmBalls: its scene and its controller's table.
#[derive(Clone, Debug)]
pub struct CdgeArmBalls {
    /// The episode's constants.
    pub scene: Scene,
    table: RbfTable,
    /// Ball, then distractor, at the start of every episode.
    initial: [f64; 4],
}

impl CdgeArmBalls {
    /// The environment with the plotted runs' scene, 50 steps and basis functions of 10 steps.
    pub fn new(scene: Scene) -> Self {
        let [bx, by] = scene.ball_initial;
        let [dx, dy] = scene.distractor_initial;
        CdgeArmBalls {
            scene,
            table: RbfTable::new(STEPS, SDEV),
            initial: [bx, by, dx, dy],
        }
    }

    /// The controller's table.
    pub fn table(&self) -> &RbfTable {
        &self.table
    }

    /// One episode, the distractor's steps drawn from the run's stream (two standard normal
    /// draws per step, x then y).
    pub fn episode(&self, theta: &[f64; PARAMS], noise: &mut Stream) -> Episode {
        self.rollout_with(theta, || standard_normal(noise))
    }

    /// One episode, the distractor's standard normal draws taken from `normal` (x, then y, at
    /// every step after the arm has moved), as CDGE's `ArmBalls.act` takes them from numpy.
    pub fn rollout_with(&self, theta: &[f64; PARAMS], mut normal: impl FnMut() -> f64) -> Episode {
        let s = &self.scene;
        let mut ball = s.ball_initial;
        let mut distractor = s.distractor_initial;
        let mut caught = false;
        let mut hand = [0.0; 2];
        let mut pose = [0.0; JOINTS];
        for command in self.table.commands(theta) {
            pose = command;
            hand = hand_position(&pose);
            let (dx, dy) = (hand[0] - ball[0], hand[1] - ball[1]);
            if (dx * dx + dy * dy).sqrt() < s.object_size {
                caught = true;
            }
            if caught {
                ball = hand;
            }
            for v in &mut distractor {
                let step = normal() * s.distractor_noise;
                *v = (*v + step).clamp(-DISTRACTOR_BOUND, DISTRACTOR_BOUND);
            }
        }
        Episode {
            ball,
            distractor,
            hand,
            pose,
            caught,
        }
    }
}

impl Environment for CdgeArmBalls {
    fn kind(&self) -> EnvKind {
        EnvKind::ARMBALLS_CORL
    }

    fn initial_state(&self) -> &[f64] {
        &self.initial
    }

    fn draws_noise(&self) -> bool {
        true
    }

    /// The outcome: ball (x, y), then distractor (x, y), at the last step.
    fn rollout(&self, theta: &[f64], noise: &mut Stream) -> Rollout {
        let theta: &[f64; PARAMS] = theta.try_into().unwrap_or_else(|_| {
            panic!(
                "{} motor parameters given to {}, which takes {PARAMS}",
                theta.len(),
                self.kind()
            )
        });
        let theta: [f64; PARAMS] = std::array::from_fn(|k| theta[k].clamp(-1.0, 1.0));
        let e = self.episode(&theta, noise);
        Rollout {
            state: [
                e.ball[0].clamp(-1.0, 1.0),
                e.ball[1].clamp(-1.0, 1.0),
                e.distractor[0],
                e.distractor[1],
            ],
            dim: 4,
            caught: e.caught,
            hand: e.hand,
        }
    }

    /// The observer's picture of an outcome (ball drawn with radius 0.17, distractor 0.15),
    /// min-max normalised.
    fn render_into(&self, state: &[f64], out: &mut [f32]) {
        let mut raw = vec![0u8; VALUES];
        render_rgb(
            [state[0], state[1]],
            [state[2], state[3]],
            BALL_RADIUS,
            DISTRACTOR_RADIUS,
            &mut raw,
        );
        normalise(&raw, out);
    }
}

/// The hand of a pose: angles `pi * cumsum(pose)`, then the sums of `cos * length` and
/// `sin * length` over the joints, in joint order (as numpy sums seven values).
pub fn hand_position(pose: &[f64; JOINTS]) -> [f64; 2] {
    let mut angle = 0.0;
    let (mut x, mut y) = (-0.0, -0.0);
    for (a, l) in pose.iter().zip(LENGTHS) {
        angle += a;
        let r = std::f64::consts::PI * angle;
        x += libm::cos(r) * l;
        y += libm::sin(r) * l;
    }
    [x, y]
}

/// Draw the final frame: the ball, then the distractor over it, as filled anti-aliased discs of
/// radius `ball_radius` and `distractor_radius` (world units) on black. 32 pixels per world unit,
/// the world's origin at pixel (32, 32), `y` growing downwards as the rows do (CDGE
/// `ArmBallsRenderer` through gizeh and cairo). The values are 8-bit, row-major, RGB.
///
/// The discs are drawn as cairo 1.16 draws them ([`disc_outline`]): Bézier arcs, flattened to a
/// polygon in 24.8 fixed point, whose coverage of a pixel is its covered length on 15
/// horizontal sub-rows. The fixture test finds at most 2 levels of 255 between these pictures and
/// cairo's own.
pub fn render_rgb(
    ball: [f64; 2],
    distractor: [f64; 2],
    ball_radius: f64,
    distractor_radius: f64,
    out: &mut [u8],
) {
    assert_eq!(out.len(), VALUES, "a picture holds {VALUES} values");
    out.fill(0);
    let scale = (SIDE as f64) / 2.0;
    let centre = (SIDE as f64 / 2.0).ceil();
    for (p, radius, colour) in [
        (ball, ball_radius, [255, 255, 0]),
        (distractor, distractor_radius, [0, 0, 255]),
    ] {
        let outline = disc_outline(centre + p[0] * scale, centre + p[1] * scale, radius * scale);
        for_each_covered(&outline, |row, col, a| {
            let px = &mut out[(row * SIDE + col) * CHANNELS..][..CHANNELS];
            for (v, c) in px.iter_mut().zip(colour) {
                *v = over(c, a, *v);
            }
        });
    }
}

/// pixman's `x * y / 255`, rounded as it rounds (`MUL_UN8`).
fn mul_un8(x: u8, y: u8) -> u8 {
    let t = x as u32 * y as u32 + 0x80;
    (((t >> 8) + t) >> 8) as u8
}

/// An opaque colour channel `c` drawn with coverage `a` over `dst` (premultiplied OVER).
fn over(c: u8, a: u8, dst: u8) -> u8 {
    mul_un8(c, a).saturating_add(mul_un8(dst, 255 - a))
}

/// cairo's flattening tolerance, in pixels (its default).
const TOLERANCE: f64 = 0.1;

/// The largest angle of one Bézier arc whose relative radial error is below a tolerance (cairo's
/// `_arc_max_angle_for_tolerance_normalized`, the first entries of its table: they cover radii
/// up to about 23,000 pixels).
fn max_arc_angle(tolerance: f64) -> f64 {
    use std::f64::consts::PI;
    let table = [
        (PI / 1.0, 0.018_518_518_518_518_5),
        (PI / 2.0, 0.000_272_567_143_730_18),
        (PI / 3.0, 2.386_470_436_514_610_5e-5),
        (PI / 4.0, 4.245_537_744_322_244e-6),
    ];
    table
        .iter()
        .find(|(_, error)| *error < tolerance)
        .unwrap_or(&table[3])
        .0
}

/// A point in cairo's 24.8 fixed point.
type Fixed = (i32, i32);

/// `_cairo_fixed_from_double`: the nearest 1/256, ties to even.
fn fixed(x: f64, y: f64) -> Fixed {
    let f = |v: f64| (v * 256.0).round_ties_even() as i32;
    (f(x), f(y))
}

/// The outline cairo fills for `cairo_arc(xc, yc, r, 0, 2 pi)` (gizeh's `circle`), in pixels:
/// the full turn split in two half turns, each into `ceil(pi / max angle)` Bézier arcs
/// (`_cairo_arc_segment`), each flattened by de Casteljau halving in fixed point until both
/// control points lie within the tolerance of the chord (`_cairo_spline_decompose`).
pub fn disc_outline(xc: f64, yc: f64, r: f64) -> Vec<(f64, f64)> {
    use std::f64::consts::PI;
    let mut points: Vec<Fixed> = Vec::new();
    if !(xc.is_finite() && yc.is_finite() && r > 0.0 && r.is_finite()) {
        return Vec::new();
    }
    let segments = (PI / max_arc_angle(TOLERANCE / r)).ceil() as usize;
    for half in 0..2 {
        let (a0, a1) = (half as f64 * PI, (half + 1) as f64 * PI);
        let step = (a1 - a0) / segments as f64;
        let mut a = a0;
        for _ in 0..segments {
            let b = a + step;
            let (rsa, rca) = (r * libm::sin(a), r * libm::cos(a));
            let (rsb, rcb) = (r * libm::sin(b), r * libm::cos(b));
            let h = 4.0 / 3.0 * libm::tan((b - a) / 4.0);
            // User space is centred on the disc (gizeh translates); the device point adds the
            // centre after the arc's own sums, as cairo's matrix does.
            let knots = [
                fixed(rca + xc, rsa + yc),
                fixed(rca - h * rsa + xc, rsa + h * rca + yc),
                fixed(rcb + h * rsb + xc, rsb - h * rcb + yc),
                fixed(rcb + xc, rsb + yc),
            ];
            flatten(knots, TOLERANCE * TOLERANCE, &mut points);
            a += step;
        }
    }
    points
        .into_iter()
        .map(|(x, y)| (x as f64 / 256.0, y as f64 / 256.0))
        .collect()
}

/// `_cairo_spline_decompose_into`: keep the start of a Bézier flat enough, halve the others.
fn flatten(k: [Fixed; 4], tolerance_sq: f64, out: &mut Vec<Fixed>) {
    if spline_error_sq(&k) < tolerance_sq {
        if out.last() != Some(&k[0]) {
            out.push(k[0]);
        }
        return;
    }
    let half = |p: Fixed, q: Fixed| (p.0 + ((q.0 - p.0) >> 1), p.1 + ((q.1 - p.1) >> 1));
    let ab = half(k[0], k[1]);
    let bc = half(k[1], k[2]);
    let cd = half(k[2], k[3]);
    let abbc = half(ab, bc);
    let bccd = half(bc, cd);
    let mid = half(abbc, bccd);
    flatten([k[0], ab, abbc, mid], tolerance_sq, out);
    flatten([mid, bccd, cd, k[3]], tolerance_sq, out);
}

/// `_cairo_spline_error_squared`: the larger squared distance of the two control points from
/// the segment between the end points.
fn spline_error_sq(k: &[Fixed; 4]) -> f64 {
    let d = |p: Fixed, q: Fixed| ((q.0 - p.0) as f64 / 256.0, (q.1 - p.1) as f64 / 256.0);
    let (a, dd) = (k[0], k[3]);
    let off = |p: Fixed| {
        let (mut px, mut py) = d(a, p);
        if a != dd {
            let (dx, dy) = d(a, dd);
            let v = dx * dx + dy * dy;
            let u = px * dx + py * dy;
            if u <= 0.0 {
            } else if u >= v {
                px -= dx;
                py -= dy;
            } else {
                px -= u / v * dx;
                py -= u / v * dy;
            }
        }
        px * px + py * py
    };
    off(k[1]).max(off(k[2]))
}

/// Sub-rows per pixel row in the coverage measure (cairo's scan converter: 15).
const SUB_ROWS: usize = 15;

/// Call `f(row, col, alpha)` for every pixel a convex outline covers, alpha in 1..=255: the
/// covered length of each of the 15 sub-rows (at their middles), averaged, times 255, rounded.
fn for_each_covered(outline: &[(f64, f64)], mut f: impl FnMut(usize, usize, u8)) {
    let n = outline.len();
    if n < 3 {
        return;
    }
    let top = outline.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let bottom = outline
        .iter()
        .map(|p| p.1)
        .fold(f64::NEG_INFINITY, f64::max);
    let row0 = top.floor().max(0.0) as usize;
    let row1 = (bottom.ceil().min(SIDE as f64)).max(0.0) as usize;
    let mut cover = [0.0f64; SIDE];
    for row in row0..row1 {
        cover.fill(0.0);
        for k in 0..SUB_ROWS {
            let y = row as f64 + (k as f64 + 0.5) / SUB_ROWS as f64;
            let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
            for i in 0..n {
                let (p, q) = (outline[i], outline[(i + 1) % n]);
                if (p.1 <= y && y < q.1) || (q.1 <= y && y < p.1) {
                    let x = p.0 + (y - p.1) / (q.1 - p.1) * (q.0 - p.0);
                    x0 = x0.min(x);
                    x1 = x1.max(x);
                }
            }
            if x0 >= x1 {
                continue;
            }
            let c0 = x0.floor().max(0.0) as usize;
            let c1 = (x1.ceil().min(SIDE as f64)).max(0.0) as usize;
            for (col, c) in cover.iter_mut().enumerate().take(c1).skip(c0) {
                let (a, b) = (col as f64, col as f64 + 1.0);
                *c += (x1.min(b) - x0.max(a)).max(0.0);
            }
        }
        for (col, c) in cover.iter().enumerate() {
            let a = (c / SUB_ROWS as f64 * 255.0).round_ties_even();
            if a >= 1.0 {
                f(row, col, a.min(255.0) as u8);
            }
        }
    }
}

/// The picture as the networks see it: `(v - min) / max` of the shifted values, in `f32`, as
/// CDGE normalises every frame (`rendering -= min; rendering /= rendering.max()`). A blank
/// picture stays zero (CDGE would divide by zero).
pub fn normalise(raw: &[u8], out: &mut [f32]) {
    assert_eq!(raw.len(), out.len());
    let lo = raw.iter().copied().min().unwrap_or(0) as f32;
    let hi = raw.iter().copied().max().unwrap_or(0) as f32 - lo;
    for (o, v) in out.iter_mut().zip(raw) {
        *o = if hi > 0.0 { (*v as f32 - lo) / hi } else { 0.0 };
    }
}

/// Write a picture ([`VALUES`] values in [0, 1]) as .npy: float32, shape (64, 64, 3), rows
/// first, as CDGE's frames are.
pub fn write_npy(values: &[f32], path: &std::path::Path) -> Result<(), super::render::RenderError> {
    check_picture(values, path)?;
    crate::npy::write_npy_f32_shape_file(path, &[SIDE, SIDE, CHANNELS], values).map_err(|source| {
        super::render::RenderError::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// Upscaling factor of [`write_png`].
const PNG_SCALE: usize = 4;

/// Write a picture as an RGB PNG a person can look at: 4x nearest-neighbour upscaling, rows
/// flipped so that larger y is higher, as in the world (CDGE's frames put y downwards).
pub fn write_png(values: &[f32], path: &std::path::Path) -> Result<(), super::render::RenderError> {
    check_picture(values, path)?;
    write_png_grid(&[values], 1, PNG_SCALE, path)
}

/// Write pictures ([`VALUES`] values in [0, 1] each, rows first, channels last) as one RGB PNG:
/// `cols` per row, each upscaled `scale` times and oriented like [`write_png`], separated by a
/// gray gap ([`super::render::grid_bytes`]). For figures (reconstructions: inputs above
/// outputs), as [`super::render::write_png_grid`] draws the 70 x 70 gray pictures.
pub fn write_png_grid(
    pictures: &[&[f32]],
    cols: usize,
    scale: usize,
    path: &std::path::Path,
) -> Result<(), super::render::RenderError> {
    if pictures.is_empty() || cols == 0 || scale == 0 {
        return Err(super::render::RenderError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "a PNG grid needs pictures, columns and a scale",
            ),
        });
    }
    for p in pictures {
        check_picture(p, path)?;
    }
    let (width, height, data) =
        super::render::grid_bytes(pictures.len(), cols, scale, SIDE, CHANNELS, |k, x, y, c| {
            pictures[k][(y * SIDE + x) * CHANNELS + c]
        });
    super::render::write_png_bytes(path, width, height, png::ColorType::Rgb, &data)
}

fn check_picture(values: &[f32], path: &std::path::Path) -> Result<(), super::render::RenderError> {
    if values.len() != VALUES {
        return Err(super::render::RenderError::BadLength {
            path: path.to_path_buf(),
            len: values.len(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three pictures on a grid of two columns: each cell is its picture (rows flipped, the
    /// channels in order), the gaps and the empty fourth cell are gray, and a picture of
    /// another size is refused.
    #[test]
    fn the_png_grid_places_the_pictures_with_gaps() {
        let picture = |seed: usize| -> Vec<f32> {
            (0..VALUES)
                .map(|i| ((i * 7 + seed * 13) % 256) as f32 / 255.0)
                .collect()
        };
        let (a, b, c) = (picture(0), picture(1), picture(2));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("grid.png");
        write_png_grid(&[&a, &b, &c], 2, 1, &p).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&p).unwrap()));
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0u8; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        use crate::render::GRID_GAP;
        let w = 2 * SIDE + GRID_GAP;
        assert_eq!((info.width as usize, info.height as usize), (w, w));
        let px = |r: usize, col: usize| &buf[(r * w + col) * CHANNELS..][..CHANNELS];
        assert_eq!(px(10, SIDE), [128; 3], "the gap");
        assert_eq!(
            px(SIDE + GRID_GAP + 5, SIDE + GRID_GAP + 5),
            [128; 3],
            "no fourth picture"
        );
        for (r0, c0, pic) in [
            (0, 0, &a),
            (0, SIDE + GRID_GAP, &b),
            (SIDE + GRID_GAP, 0, &c),
        ] {
            for (x, y) in [(0, 0), (5, 60), (63, 63), (31, 2)] {
                let want: Vec<u8> = pic[(y * SIDE + x) * CHANNELS..][..CHANNELS]
                    .iter()
                    .map(|v| (v * 255.0).round() as u8)
                    .collect();
                assert_eq!(px(r0 + SIDE - 1 - y, c0 + x), &want[..], "({x}, {y})");
            }
        }
        assert!(write_png_grid(&[&a[..10]], 1, 1, &p).is_err());
        assert!(write_png_grid(&[], 1, 1, &p).is_err());
    }

    #[test]
    fn the_basis_peaks_at_its_centres_and_the_last_function_is_only_a_tail() {
        let t = RbfTable::new(STEPS, SDEV);
        assert_eq!(t.basis.len(), STEPS);
        for (k, c) in [8usize, 15, 22, 29, 36, 43].iter().enumerate() {
            assert_eq!(t.basis[*c][k], 1.0, "function {k} peaks at step {c}");
        }
        // Centre 50 lies past the last step: its largest weight is at step 49.
        assert!(t.basis[49][6] < 1.0 && t.basis[49][6] > t.basis[48][6]);
        // 42 steps from centre 50: beyond the kernel's 40-step radius.
        assert_eq!(t.basis[8][6], 0.0);
        assert!(t.basis[10][6] > 0.0);
    }

    #[test]
    fn the_rest_pose_points_the_arm_right_and_leaves_the_ball() {
        let env = CdgeArmBalls::new(Scene::default());
        let e = env.rollout_with(&[0.0; PARAMS], || 0.0);
        assert_eq!(e.hand, [1.0, 0.0]);
        assert!(!e.caught);
        assert_eq!(e.ball, [0.6, 0.6]);
        assert_eq!(e.distractor, [0.7, -0.45]);
    }

    #[test]
    fn a_disc_is_drawn_where_its_centre_is_with_its_area() {
        let mut img = vec![0u8; VALUES];
        // The distractor far off the picture: only the ball.
        render_rgb([0.0, 0.0], [9.0, 9.0], 0.17, 0.15, &mut img);
        let r = 0.17 * 32.0;
        let (mut area, mut mx, mut my) = (0.0, 0.0, 0.0);
        for row in 0..SIDE {
            for col in 0..SIDE {
                let px = &img[(row * SIDE + col) * CHANNELS..][..CHANNELS];
                assert_eq!(px[0], px[1], "yellow");
                assert_eq!(px[2], 0);
                let a = px[0] as f64 / 255.0;
                area += a;
                mx += a * (col as f64 + 0.5);
                my += a * (row as f64 + 0.5);
            }
        }
        // The pixels hold the outline's area (the flattened outline lies inside the circle,
        // within cairo's 0.1-pixel tolerance of it).
        let o = disc_outline(32.0, 32.0, r);
        let polygon = (0..o.len())
            .map(|i| {
                let (p, q) = (o[i], o[(i + 1) % o.len()]);
                p.0 * q.1 - q.0 * p.1
            })
            .sum::<f64>()
            .abs()
            / 2.0;
        assert!((area - polygon).abs() < 0.05, "{area} vs {polygon}");
        let circle = std::f64::consts::PI * r * r;
        assert!(polygon < circle && polygon > std::f64::consts::PI * (r - 0.1) * (r - 0.1));
        let (mx, my) = (mx / area, my / area);
        assert!(
            (mx - 32.0).abs() < 0.02 && (my - 32.0).abs() < 0.02,
            "{mx} {my}"
        );
        let mut norm = vec![0f32; VALUES];
        normalise(&img, &mut norm);
        assert_eq!(norm.iter().cloned().fold(0.0, f32::max), 1.0);
    }

    #[test]
    fn the_distractor_covers_the_ball() {
        let mut img = vec![0u8; VALUES];
        render_rgb([0.0, 0.0], [0.0, 0.0], 0.17, 0.15, &mut img);
        let centre = &img[(32 * SIDE + 32) * CHANNELS..][..CHANNELS];
        assert_eq!(centre, &[0, 0, 255]);
    }
}
