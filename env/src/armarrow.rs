//! ArmArrow (paper Section 4.1): the arm can catch an arrow at (0.6, 0.6), orientation 0.6 (units
//! of pi), and move it; while held the arrow takes the orientation of the last link, wrapped into
//! [-1, 1). The engineered outcome is (x, y, angle). The angle is a linear coordinate everywhere
//! (no wrap-around in distances or bins), as in the original code.

use serde::{Deserialize, Serialize};

use super::{Body, EnvConfig, EnvKind, Environment, Rollout};
use crate::config::OwnConstants;
use crate::invalid::{InvalidValue, exactly, within_each};

/// ArmArrow's own constants (its `[env.armarrow]` table).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Constants {
    /// Initial arrow pose (x, y, angle in units of pi), each in [-1, 1].
    #[serde(deserialize_with = "exactly")]
    pub arrow_initial: [f64; 3],
}

impl Default for Constants {
    fn default() -> Self {
        Constants {
            arrow_initial: [0.6, 0.6, 0.6],
        }
    }
}

impl OwnConstants for Constants {
    fn check(&self, key: &dyn Fn(&str) -> String) -> Result<(), InvalidValue> {
        within_each(key, "arrow_initial", &self.arrow_initial, -1.0, 1.0)
    }
}

/// The ArmArrow environment.
#[derive(Clone, Debug)]
pub struct ArmArrow {
    body: Body,
    initial: [f64; 3],
}

/// Wrap an absolute orientation (units of pi) into [-1, 1]: `mod(a + 1, 2) - 1` with numpy's
/// floor-mod semantics.
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    (a + 1.0).rem_euclid(2.0) - 1.0
}

impl ArmArrow {
    /// Build from the environment constants.
    pub fn new(cfg: &EnvConfig) -> Self {
        ArmArrow {
            body: Body::new(cfg),
            initial: cfg.own::<Constants>(EnvKind::ARMARROW).arrow_initial,
        }
    }
}

impl Environment for ArmArrow {
    fn kind(&self) -> EnvKind {
        EnvKind::ARMARROW
    }

    fn initial_state(&self) -> &[f64] {
        &self.initial
    }

    fn rollout(&self, theta: &[f64], _noise: &mut crate::seed::Stream) -> Rollout {
        let theta = super::dmp_params(theta);
        let (caught, pose) = self.body.run(theta, [self.initial[0], self.initial[1]]);
        let s = if caught {
            [pose.hand[0], pose.hand[1], wrap_angle(pose.last_link)]
        } else {
            self.initial
        };
        Rollout {
            state: [s[0], s[1], s[2], 0.0].map(|v| v.clamp(-1.0, 1.0)),
            dim: 3,
            caught,
            hand: pose.hand,
        }
    }

    fn render_into(&self, state: &[f64], out: &mut [f32]) {
        super::render::render_arrow_into(state[0], state[1], state[2], out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_wraps_like_numpy_mod() {
        assert_eq!(wrap_angle(0.5), 0.5);
        assert_eq!(wrap_angle(1.0), -1.0);
        assert_eq!(wrap_angle(1.5), -0.5);
        assert_eq!(wrap_angle(-1.5), 0.5);
        assert_eq!(wrap_angle(-1.0), -1.0);
        assert!((wrap_angle(7.25) - (-0.75)).abs() < 1e-12);
        for i in -100..100 {
            let w = wrap_angle(i as f64 * 0.37);
            assert!((-1.0..=1.0).contains(&w));
        }
    }
}
