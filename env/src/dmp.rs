//! The discrete DMP of explauto 1.3.0 (`models/dmp.py` + `models/pydmps`), exactly as the paper's
//! code used it (docs/original-code.md section 1, "DMP"): 7 joints, 3 basis functions per joint, 50
//! steps of dt = 0.04, start and goal fixed at 0, only the weights controlled.
//!
//! The canonical state `x_t = 0.96^t` does not depend on the parameters, so the basis
//! activations of every step are computed once ([`DmpTable`]) with the same floating-point
//! operations the original performs at each step; a rollout then only integrates.

use serde::{Deserialize, Serialize};

use super::arm::JOINTS;

/// Basis functions per joint.
pub const BASIS: usize = 3;
/// Number of motor parameters: 7 joints x 3 weights.
pub const PARAMS: usize = JOINTS * BASIS;

/// Which basis-function widths to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DmpWidths {
    /// PyPI `explauto==1.3.0`: h = 3^1.5 / c. Reproduces the published results.
    Explauto130,
    /// explauto git HEAD (commit 2d2ec8a, 2017-06-29): h = 8 * 3^2 / c^1.5.
    ExplautoHead,
}

/// DMP constants. The defaults are the paper's code's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DmpConfig {
    /// Number of integration steps (joint commands per episode), 1 to 10,000.
    pub timesteps: usize,
    /// Duration of the movement in seconds (dt = run_time / timesteps), in (0, 1000].
    pub run_time: f64,
    /// Spring gain a_y (b_y = a_y / 4), in (0, 1e4].
    pub ay: f64,
    /// Canonical system decay a_x, in (0, 1e4].
    pub ax: f64,
    /// Parameters in [-1,1] are multiplied by this to give the DMP weights; in [0, 1e6]. The
    /// campaign check also runs the extreme commands and refuses constants whose movement is
    /// not finite (a step too coarse for the gain).
    pub max_params: f64,
    /// Basis widths.
    pub widths: DmpWidths,
}

impl Default for DmpConfig {
    fn default() -> Self {
        DmpConfig {
            timesteps: 50,
            run_time: 2.0,
            ay: 25.0,
            ax: 1.0,
            max_params: 1000.0,
            widths: DmpWidths::Explauto130,
        }
    }
}

/// Per-step constants of the DMP: canonical state and basis activations.
#[derive(Clone, Debug)]
pub struct DmpTable {
    /// Canonical state at each step (after its update).
    pub x: Vec<f64>,
    /// Basis activations psi_b(x_t).
    pub psi: Vec<[f64; BASIS]>,
    /// Sum of the activations.
    pub psi_sum: Vec<f64>,
    /// Time step.
    pub dt: f64,
    /// Spring gains.
    pub ay: f64,
    pub by: f64,
    /// Weight scale.
    pub max_params: f64,
}

impl DmpConfig {
    /// Basis centres: c = -ln(linspace(0.4, 0.8, 3)) (compared directly with x: a quirk of the original).
    pub fn centres(&self) -> [f64; BASIS] {
        // np.linspace(0.4, 0.8, 3): start + i * step, step = 0.4 / 2; the last is exactly 0.8.
        let step = (0.8 - 0.4) / 2.0;
        [
            -libm::log(0.4),
            -libm::log(1.0 * step + 0.4),
            -libm::log(0.8),
        ]
    }

    /// Basis widths h_b.
    pub fn widths(&self) -> [f64; BASIS] {
        let c = self.centres();
        match self.widths {
            DmpWidths::Explauto130 => c.map(|c| libm::pow(3.0, 1.5) / c),
            DmpWidths::ExplautoHead => c.map(|c| 8.0 * 3f64.powi(2) / libm::pow(c, 1.5)),
        }
    }

    /// Precompute the per-step constants.
    pub fn table(&self) -> DmpTable {
        let dt = self.run_time / self.timesteps as f64;
        let (c, h) = (self.centres(), self.widths());
        let mut x = 1.0f64;
        let mut xs = Vec::with_capacity(self.timesteps);
        let mut psis = Vec::with_capacity(self.timesteps);
        let mut sums = Vec::with_capacity(self.timesteps);
        for _ in 0..self.timesteps {
            // cs.step: x += (-ax * x * error_coupling) * tau * dt, before the state is used.
            x += (-self.ax * x) * dt;
            let psi: [f64; BASIS] = std::array::from_fn(|b| libm::exp(-h[b] * (x - c[b]).powi(2)));
            xs.push(x);
            sums.push(psi[0] + psi[1] + psi[2]);
            psis.push(psi);
        }
        DmpTable {
            x: xs,
            psi: psis,
            psi_sum: sums,
            dt,
            ay: self.ay,
            by: self.ay / 4.0,
            max_params: self.max_params,
        }
    }
}

/// Integrates the DMP of all joints for one parameter vector.
#[derive(Clone, Debug)]
pub struct DmpState {
    w: [[f64; BASIS]; JOINTS],
    y: [f64; JOINTS],
    dy: [f64; JOINTS],
}

impl DmpState {
    /// Start a movement: parameters clipped to [-1,1] and scaled to weights
    /// w[j][b] = max_params * theta[3j + b]; y = dy = 0.
    pub fn new(table: &DmpTable, theta: &[f64; PARAMS]) -> Self {
        let w = std::array::from_fn(|j| {
            std::array::from_fn(|b| theta[BASIS * j + b].clamp(-1.0, 1.0) * table.max_params)
        });
        DmpState {
            w,
            y: [0.0; JOINTS],
            dy: [0.0; JOINTS],
        }
    }

    /// Advance one step and return the joint command (before the environment's clipping).
    #[inline]
    pub fn step(&mut self, table: &DmpTable, t: usize) -> &[f64; JOINTS] {
        let x = table.x[t];
        let psi = &table.psi[t];
        let sum = table.psi_sum[t];
        for j in 0..JOINTS {
            let w = &self.w[j];
            // f = x * dot(psi, w) / sum(psi); goal = y0 = 0, tau = 1, no error coupling.
            let f = x * (psi[0] * w[0] + psi[1] * w[1] + psi[2] * w[2]) / sum;
            let ddy = table.ay * (table.by * (0.0 - self.y[j]) - self.dy[j]) + f;
            self.dy[j] += ddy * table.dt;
            self.y[j] += self.dy[j] * table.dt;
        }
        &self.y
    }
}

/// The whole joint-command trajectory (timesteps x 7), before clipping.
pub fn trajectory(cfg: &DmpConfig, theta: &[f64; PARAMS]) -> Vec<[f64; JOINTS]> {
    let table = cfg.table();
    let mut s = DmpState::new(&table, theta);
    (0..cfg.timesteps).map(|t| *s.step(&table, t)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_match_the_notes() {
        let w = DmpConfig::default().widths();
        let expected = [5.670856, 10.172067, 23.286142];
        for (a, b) in w.iter().zip(expected) {
            assert!((a - b).abs() < 1e-6, "{w:?}");
        }
        let head = DmpConfig {
            widths: DmpWidths::ExplautoHead,
            ..Default::default()
        }
        .widths();
        for (a, b) in head.iter().zip([82.08854, 197.20753, 683.05549]) {
            assert!((a - b).abs() < 1e-4, "{head:?}");
        }
        let c = DmpConfig::default().centres();
        for (a, b) in c.iter().zip([0.9162907, 0.5108256, 0.2231436]) {
            assert!((a - b).abs() < 1e-7);
        }
    }

    #[test]
    fn canonical_state_decays_geometrically() {
        let t = DmpConfig::default().table();
        assert_eq!(t.x.len(), 50);
        assert!((t.x[0] - 0.96).abs() < 1e-15);
        assert!((t.x[49] - 0.96f64.powi(50)).abs() < 1e-12);
        assert_eq!(t.dt, 0.04);
    }

    #[test]
    fn zero_weights_stay_at_rest() {
        let traj = trajectory(&DmpConfig::default(), &[0.0; PARAMS]);
        assert!(traj.iter().all(|q| q.iter().all(|&v| v == 0.0)));
    }

    #[test]
    fn joints_are_independent_and_linear_in_weights() {
        let cfg = DmpConfig::default();
        let mut th = [0.0; PARAMS];
        th[3] = 0.5; // joint 1, basis 0
        let a = trajectory(&cfg, &th);
        assert!(a.iter().all(|q| q[0] == 0.0 && q[2] == 0.0));
        assert!(a.iter().any(|q| q[1] != 0.0));
        th[3] = 0.25;
        let b = trajectory(&cfg, &th);
        for (qa, qb) in a.iter().zip(&b) {
            assert!((qa[1] - 2.0 * qb[1]).abs() < 1e-12);
        }
    }

    #[test]
    fn parameters_are_clipped() {
        let cfg = DmpConfig::default();
        let mut a = [0.3; PARAMS];
        a[0] = 1.0;
        let mut b = a;
        b[0] = 5.0;
        assert_eq!(trajectory(&cfg, &a), trajectory(&cfg, &b));
    }
}
