//! ArmBall (paper Section 4.1): the arm can catch a ball of radius 0.1 at (0.6, 0.6) and move it.
//! The engineered outcome is the ball's final (x, y).

use super::{Body, EnvConfig, EnvKind, Environment, Rollout};

/// The ArmBall environment.
#[derive(Clone, Debug)]
pub struct ArmBall {
    body: Body,
    initial: [f64; 2],
}

impl ArmBall {
    /// Build from the environment constants.
    pub fn new(cfg: &EnvConfig) -> Self {
        ArmBall {
            body: Body::new(cfg),
            initial: cfg.ball_initial,
        }
    }
}

impl Environment for ArmBall {
    fn kind(&self) -> EnvKind {
        EnvKind::ARMBALL
    }

    fn initial_state(&self) -> &[f64] {
        &self.initial
    }

    fn rollout(&self, theta: &[f64], _noise: &mut crate::seed::Stream) -> Rollout {
        let theta = super::dmp_params(theta);
        let (caught, pose) = self.body.run(theta, self.initial);
        let ball = if caught { pose.hand } else { self.initial };
        Rollout {
            state: [ball[0].clamp(-1.0, 1.0), ball[1].clamp(-1.0, 1.0), 0.0, 0.0],
            dim: 2,
            caught,
            hand: pose.hand,
        }
    }

    fn render_into(&self, state: &[f64], out: &mut [f32]) {
        super::render::render_ball_into(state[0], state[1], out);
    }
}
