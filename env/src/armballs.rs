//! ArmBalls (the follow-up paper's environment, Laversanne-Finot, Péré & Oudeyer, CoRL 2018;
//! `docs/followup-paper-sources.md` sections 1 and 10): our ArmBall body and ball, plus a
//! **distractor** ball that the arm cannot move. The distractor starts every episode at
//! `distractor_initial` (0.7, -0.45) and at every step of the movement takes a Gaussian step
//! `N(0, distractor_noise² I)` (0.1), clipped to [-0.95, 0.95]² (CDGE `ArmBalls.act`).
//!
//! The engineered outcome is 4-D: (ball x, ball y, distractor x, distractor y) at the last step.
//! Exploration is measured on the controllable ball (the first two coordinates,
//! [`EnvKind::metric_dims`]); the distractor is the control ([`EnvKind::control_dims`]).
//! Its noise comes from the run's own `distractor` stream, two normal draws (x, then y) per step,
//! so an episode's distractor path depends only on the run's identity and the episode's place in
//! the run, never on the explorer's other draws.

use crate::seed::standard_normal;

use super::{Body, EnvConfig, EnvKind, Environment, Rollout};
use crate::seed::Stream;

/// ArmBalls' own constants (its `[env.armballs]` table): the follow-up's scene, declared with
/// its ArmBalls ([`crate::cdge::Constants`]: the ball's start, the distractor's start and step).
pub type Constants = crate::cdge::Constants;

/// The distractor's walk is clipped to this box (CDGE `np.clip(…, -.95, 0.95)`).
pub use crate::cdge::DISTRACTOR_BOUND;

pub use super::render::DISTRACTOR_GRAY;

/// The ArmBalls environment.
#[derive(Clone, Debug)]
pub struct ArmBalls {
    body: Body,
    initial: [f64; 4],
    noise: f64,
}

impl ArmBalls {
    /// Build from the environment constants.
    pub fn new(cfg: &EnvConfig) -> Self {
        let own = cfg.own::<Constants>(EnvKind::ARMBALLS);
        let [bx, by] = own.ball_initial;
        let [dx, dy] = own.distractor_initial;
        ArmBalls {
            body: Body::new(cfg),
            initial: [bx, by, dx, dy],
            noise: own.distractor_noise,
        }
    }

    /// The distractor's position after one episode of `steps` steps, drawn from `rng`.
    pub fn walk(&self, rng: &mut Stream) -> [f64; 2] {
        let mut p = [self.initial[2], self.initial[3]];
        for _ in 0..self.body.table.x.len() {
            for v in &mut p {
                let n = standard_normal(rng);
                *v = (*v + n * self.noise).clamp(-DISTRACTOR_BOUND, DISTRACTOR_BOUND);
            }
        }
        p
    }
}

impl Environment for ArmBalls {
    fn kind(&self) -> EnvKind {
        EnvKind::ARMBALLS
    }

    fn initial_state(&self) -> &[f64] {
        &self.initial
    }

    fn draws_noise(&self) -> bool {
        true
    }

    fn rollout(&self, theta: &[f64], noise: &mut Stream) -> Rollout {
        let theta = super::dmp_params(theta);
        let (caught, pose) = self.body.run(theta, [self.initial[0], self.initial[1]]);
        let ball = if caught {
            pose.hand
        } else {
            [self.initial[0], self.initial[1]]
        };
        let [dx, dy] = self.walk(noise);
        Rollout {
            state: [ball[0].clamp(-1.0, 1.0), ball[1].clamp(-1.0, 1.0), dx, dy],
            dim: 4,
            caught,
            hand: pose.hand,
        }
    }

    fn render_into(&self, state: &[f64], out: &mut [f32]) {
        super::render::render_balls_into(state[0], state[1], state[2], state[3], out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PARAMS;
    use crate::seed::{Component, stream};
    use rand::RngExt;

    fn env(noise: f64) -> ArmBalls {
        ArmBalls::new(
            &EnvConfig::default()
                .with("armballs.distractor_noise", noise)
                .unwrap(),
        )
    }

    #[test]
    fn the_distractor_walks_within_its_box_and_is_reset_every_episode() {
        let e = env(0.1);
        let mut rng = stream(3, Component::Distractor);
        let (mut s1, mut s2) = ([0.0; 2], [0.0; 2]);
        let n = 2000;
        for _ in 0..n {
            let r = e.rollout(&[0.0; PARAMS], &mut rng);
            // Rest pose: the ball stays, the distractor moves (from the same start every time).
            assert_eq!(&r.state[..2], &[0.6, 0.6]);
            for k in 0..2 {
                let v = r.state[2 + k];
                assert!(v.abs() <= DISTRACTOR_BOUND, "{v}");
                s1[k] += v;
                s2[k] += v * v;
            }
        }
        // 50 steps of std 0.1: std ~0.7 before clipping; the mean stays near the start
        // (clipping pulls it inwards).
        for k in 0..2 {
            let m = s1[k] / n as f64;
            let sd = (s2[k] / n as f64 - m * m).sqrt();
            assert!((0.4..0.75).contains(&sd), "sd {sd}");
            assert!((m - e.initial[2 + k]).abs() < 0.3, "mean {m}");
        }
    }

    #[test]
    fn zero_noise_keeps_the_distractor_still_and_the_ball_is_armball() {
        let e = env(0.0);
        let ball = super::super::ArmBall::new(&EnvConfig::default());
        let mut rng = stream(4, Component::Params);
        let mut caught = 0;
        for _ in 0..3000 {
            let theta = (0..PARAMS)
                .map(|_| rng.random_range(-1.0..1.0))
                .collect::<Vec<f64>>();
            let mut noise = stream(1, Component::Distractor);
            let r = e.rollout(&theta, &mut noise);
            let b = ball.rollout(&theta, &mut noise);
            assert_eq!(&r.state[..2], b.outcome());
            assert_eq!(&r.state[2..], &[0.7, -0.45]);
            assert_eq!(r.caught, b.caught);
            caught += r.caught as usize;
        }
        assert!(caught > 5, "{caught}");
    }

    #[test]
    fn both_balls_are_rendered_the_ball_white_and_the_distractor_gray() {
        use crate::render::{PIXELS, SIDE, render_ball_into};
        let e = env(0.1);
        let mut img = vec![0f32; PIXELS];
        e.render_into(&[0.5, 0.5, -0.5, -0.5], &mut img);
        // Pixel centres: int((s + 1) / 2 * 70), x-major.
        let at = |img: &[f32], x: usize, y: usize| img[x * SIDE + y];
        assert_eq!(at(&img, 52, 52), 1.0);
        assert_eq!(at(&img, 17, 17), DISTRACTOR_GRAY);
        let mut ball = vec![0f32; PIXELS];
        render_ball_into(0.5, 0.5, &mut ball);
        let lit = |v: &[f32]| v.iter().filter(|p| **p > 0.0).count();
        // Apart: the two footprints add up; the distractor's pixels are at most 0.5.
        assert_eq!(lit(&img), 2 * lit(&ball));
        assert!(img.iter().all(|v| (0.0..=1.0).contains(v)));
        // On top of each other: the distractor hides the ball, except where its anti-aliased
        // edge lets some through (coverage a: a (1 - a) + 0.5 a <= 0.5625).
        e.render_into(&[0.2, 0.2, 0.2, 0.2], &mut img);
        assert_eq!(at(&img, 42, 42), DISTRACTOR_GRAY);
        assert!(img.iter().all(|v| *v <= 0.5625 + 1e-6), "{img:?}");
    }

    #[test]
    fn same_stream_same_paths() {
        let e = env(0.1);
        let a: Vec<_> = {
            let mut rng = stream(9, Component::Distractor);
            (0..5).map(|_| e.walk(&mut rng)).collect()
        };
        let mut rng = stream(9, Component::Distractor);
        let b: Vec<_> = (0..5).map(|_| e.walk(&mut rng)).collect();
        assert_eq!(a, b);
        assert_ne!(a[0], a[1]);
    }
}
