//! The 7-joint planar arm of explauto's `SimpleArmEnvironment` as configured by the paper's code
//! (docs/original-code.md section 1, "Forward kinematics").

use serde::{Deserialize, Serialize};

/// Number of joints.
pub const JOINTS: usize = 7;

/// Geometry of the arm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmConfig {
    /// Link lengths, base to hand (they sum to 1, so the reachable set is the closed unit disk).
    /// Each finite and >= 0, their sum in (0, 1] (the arm's reach fits in the scene).
    #[serde(deserialize_with = "lengths")]
    pub lengths: [f64; JOINTS],
    /// Offset added to the first joint, in units of pi (0.5: the arm points straight up at q = 0).
    /// In [-2, 2].
    pub angle_shift: f64,
}

fn lengths<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; JOINTS], D::Error> {
    crate::invalid::exactly_as(d, "env.arm.lengths")
}

impl Default for ArmConfig {
    fn default() -> Self {
        ArmConfig {
            lengths: [0.3, 0.2, 0.2, 0.1, 0.1, 0.05, 0.05],
            angle_shift: 0.5,
        }
    }
}

/// The pose of the arm for one joint command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmPose {
    /// Hand (end-effector) position.
    pub hand: [f64; 2],
    /// Absolute orientation of the last link in units of pi: `shift + q_1 + ... + q_7`.
    pub last_link: f64,
}

impl ArmConfig {
    /// Forward kinematics for a joint command `q` (units of pi, clipped to [-1,1] first, as
    /// explauto's `compute_motor_command` does).
    ///
    /// The absolute angle of link k is `pi * (shift + (q_1 + ... + q_k))` (the original adds the
    /// shift to the cumulative sum, `a = 0.5 + cumsum(q)`); the hand is the sum of
    /// `L_k (cos, sin)` of those angles, accumulated base to hand.
    #[inline]
    pub fn forward(&self, q: &[f64; JOINTS]) -> ArmPose {
        let mut cum = 0.0f64;
        let (mut x, mut y) = (0.0f64, 0.0f64);
        let mut angle_std = 0.0;
        for k in 0..JOINTS {
            cum += q[k].clamp(-1.0, 1.0);
            let a = self.angle_shift + cum;
            angle_std = a;
            let (s, c) = libm::sincos(std::f64::consts::PI * a);
            x += c * self.lengths[k];
            y += s * self.lengths[k];
        }
        ArmPose {
            hand: [x, y],
            last_link: angle_std,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_command_points_straight_up() {
        let p = ArmConfig::default().forward(&[0.0; JOINTS]);
        assert!(p.hand[0].abs() < 1e-15, "{:?}", p);
        assert!((p.hand[1] - 1.0).abs() < 1e-15, "{:?}", p);
        assert_eq!(p.last_link, 0.5);
    }

    #[test]
    fn first_joint_rotates_the_whole_arm() {
        // q_1 = -0.5 turns the straight arm by -pi/2: it points along +x.
        let mut q = [0.0; JOINTS];
        q[0] = -0.5;
        let p = ArmConfig::default().forward(&q);
        assert!(
            (p.hand[0] - 1.0).abs() < 1e-12 && p.hand[1].abs() < 1e-12,
            "{:?}",
            p
        );
    }

    #[test]
    fn folded_arm_and_clipping() {
        // The first link up, the second folded back (q_2 = 1): hand at (0, 0.3 - 0.7).
        let mut q = [0.0; JOINTS];
        q[1] = 1.0;
        let p = ArmConfig::default().forward(&q);
        assert!(
            p.hand[0].abs() < 1e-12 && (p.hand[1] + 0.4).abs() < 1e-12,
            "{:?}",
            p
        );
        // Commands beyond [-1,1] are clipped.
        q[1] = 3.7;
        assert_eq!(ArmConfig::default().forward(&q), p);
    }

    #[test]
    fn hand_stays_in_unit_disk() {
        let cfg = ArmConfig::default();
        let mut q = [0.0; JOINTS];
        for i in 0..1000 {
            for (k, v) in q.iter_mut().enumerate() {
                *v = (((i * 7 + k) as f64) * 0.7548776662466927).fract() * 2.0 - 1.0;
            }
            let h = cfg.forward(&q).hand;
            assert!(h[0] * h[0] + h[1] * h[1] <= 1.0 + 1e-12);
        }
    }
}
