//! ArmBall (paper Section 4.1): the arm can catch a ball of radius 0.1 at (0.6, 0.6) and move it.
//! The engineered outcome is the ball's final (x, y).

use serde::{Deserialize, Serialize};

use super::{Body, EnvConfig, EnvKind, Environment, Rollout};
use crate::config::OwnConstants;
use crate::invalid::{InvalidValue, exactly, within_each};

/// ArmBall's own constants (its `[env.armball]` table).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Constants {
    /// Initial ball position, in [-1, 1]² (the scene).
    #[serde(deserialize_with = "exactly")]
    pub ball_initial: [f64; 2],
}

impl Default for Constants {
    fn default() -> Self {
        Constants {
            ball_initial: [0.6, 0.6],
        }
    }
}

impl OwnConstants for Constants {
    fn check(&self, key: &dyn Fn(&str) -> String) -> Result<(), InvalidValue> {
        within_each(key, "ball_initial", &self.ball_initial, -1.0, 1.0)
    }
}

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
            initial: cfg.own::<Constants>(EnvKind::ARMBALL).ball_initial,
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
