//! Learning progress (interest) of goal modules, for modular goal exploration (MGE) of the
//! follow-up paper (Laversanne-Finot, Péré, Oudeyer, CoRL 2018). The definition is its code's
//! (`flowersteam/Curiosity_Driven_Goal_Exploration`, `interest_model.py`: `interest_xc`,
//! `update_interest`; module choice: explauto's `prop_choice`), written out with its sources in
//! `docs/learning-progress.md`:
//!
//! - competence of reaching `s` for goal `g`: `c(g, s) = -min(||g - s||, 2)` (explauto's
//!   `competence_dist` with `dist_min = 0` and `dist_max = 2`, as explauto has had it since
//!   June 2016; distances in the units of their code: [`ModuleInterest::new`]'s `scale`);
//! - progress of one (exploitation) episode with goal `g` and outcome `s`:
//!   `p = c(g, s) - c(g, s')`, where `s'` is the outcome reached for the module's earlier goal
//!   nearest to `g` (0 for the module's first episode);
//! - interest: `|q|`, `q` an exponential moving average of the progress with rate `1 / window`
//!   (`q <- q + (p - q) / window`, `q = 1e-5` at the start);
//! - module choice: uniform with probability `eps` (or when every interest is 0), else in
//!   proportion to the interests.
//!
//! Used by modular goal exploration (`explore::mge`).

use rand::RngExt;

use super::ExploreError;
use crate::seed::Stream;

/// The interest before any episode (the original's initial value).
pub const INITIAL_PROGRESS: f64 = 1e-5;

/// The distance beyond which competence stays at its floor (the original's `dist_max`).
pub const DIST_MAX: f64 = 2.0;

/// The interest of one goal module: its goals, the outcomes reached for them and the smoothed
/// progress.
#[derive(Clone, Debug, PartialEq)]
pub struct ModuleInterest {
    dim: usize,
    window: f64,
    /// A distance of the module's space in the original's units.
    scale: f64,
    /// Goals, row-major `n x dim`.
    goals: Vec<f64>,
    /// Outcomes reached for them (the module's dimensions), row-major `n x dim`.
    reached: Vec<f64>,
    progress: f64,
}

impl ModuleInterest {
    /// A module of `dim` goal dimensions whose progress is averaged with rate `1 / window`
    /// (the original: 1000), in a space whose distances are `scale` times the original's units
    /// ([`super::imgep::OutcomeSpace::competence_scale`]). `Err` for `dim = 0`, a window below 1
    /// or not finite, or a scale not positive and finite.
    pub fn new(dim: usize, window: f64, scale: f64) -> Result<Self, ExploreError> {
        if dim == 0 {
            return Err(ExploreError::EmptyModule);
        }
        if !(window.is_finite() && window >= 1.0) {
            return Err(ExploreError::InterestWindow(window));
        }
        if !(scale.is_finite() && scale > 0.0) {
            return Err(ExploreError::CompetenceScale(scale));
        }
        Ok(ModuleInterest {
            dim,
            window,
            scale,
            goals: Vec::new(),
            reached: Vec::new(),
            progress: INITIAL_PROGRESS,
        })
    }

    /// The competence of reaching `reached` for `goal`: `-min(||goal - reached||, 2)`, the
    /// distance in the original's units.
    pub fn competence(&self, goal: &[f64], reached: &[f64]) -> f64 {
        -(self.scale * distance(goal, reached)).min(DIST_MAX)
    }

    /// Record one episode with `goal` and its outcome `reached` (the module's dimensions) and
    /// return its progress. `Err` if a length is not the module's dimension or a value is not
    /// finite (a silent NaN would poison the interest for good).
    pub fn update(&mut self, goal: &[f64], reached: &[f64]) -> Result<f64, ExploreError> {
        if goal.len() != self.dim || reached.len() != self.dim {
            return Err(ExploreError::GoalLength {
                dim: self.dim,
                goal: goal.len(),
                reached: reached.len(),
            });
        }
        if goal.iter().chain(reached).any(|v| !v.is_finite()) {
            return Err(ExploreError::NonFinite);
        }
        let c = self.competence(goal, reached);
        let p = match self.nearest_goal(goal) {
            None => 0.0,
            Some(i) => c - self.competence(goal, &self.reached[i * self.dim..(i + 1) * self.dim]),
        };
        self.goals.extend_from_slice(goal);
        self.reached.extend_from_slice(reached);
        self.progress += (p - self.progress) / self.window;
        Ok(p)
    }

    /// The module's interest, `|q|`.
    pub fn interest(&self) -> f64 {
        self.progress.abs()
    }

    /// Episodes recorded.
    pub fn len(&self) -> usize {
        self.goals.len() / self.dim
    }

    /// Whether no episode was recorded.
    pub fn is_empty(&self) -> bool {
        self.goals.is_empty()
    }

    /// The earlier goal nearest to `goal` (Euclidean; the first of equals).
    fn nearest_goal(&self, goal: &[f64]) -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for (i, g) in self.goals.chunks_exact(self.dim).enumerate() {
            let d = distance(g, goal);
            if best.is_none_or(|(_, b)| d < b) {
                best = Some((i, d));
            }
        }
        best.map(|(i, _)| i)
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Choose a module: uniformly with probability `eps` or when every interest is 0, else in
/// proportion to `interests` (explauto's `prop_choice`; the same draws in the same order: a
/// uniform number only when some interest is positive, then the index). `Err` for no module, a
/// negative or non-finite interest, or `eps` outside [0, 1].
pub fn choose_module(interests: &[f64], eps: f64, rng: &mut Stream) -> Result<usize, ExploreError> {
    if interests.is_empty() {
        return Err(ExploreError::NoModule);
    }
    if let Some(v) = interests.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(ExploreError::Interest(*v));
    }
    if !(0.0..=1.0).contains(&eps) {
        return Err(ExploreError::Eps(eps));
    }
    let total: f64 = interests.iter().sum();
    if total == 0.0 || rng.random::<f64>() < eps {
        return Ok(rng.random_range(0..interests.len()));
    }
    let x = rng.random::<f64>() * total;
    let mut cum = 0.0;
    for (i, v) in interests.iter().enumerate() {
        cum += v;
        if x < cum {
            return Ok(i);
        }
    }
    // Rounding at the top end: the last module with a positive interest.
    Ok(interests.iter().rposition(|v| *v > 0.0).expect("total > 0"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    #[test]
    fn competence_is_minus_the_distance_capped_at_two() {
        let m = ModuleInterest::new(2, 10.0, 1.0).unwrap();
        assert_eq!(m.competence(&[0.0, 0.0], &[0.6, 0.8]), -1.0);
        assert_eq!(m.competence(&[0.3, -0.2], &[0.3, -0.2]), 0.0);
        assert_eq!(m.competence(&[0.0, 0.0], &[3.0, 4.0]), -2.0);
        // The engineered space's (s + 1) / 2 halves distances: 2 in the original's units.
        let e = ModuleInterest::new(2, 10.0, 2.0).unwrap();
        assert_eq!(e.competence(&[0.0, 0.0], &[0.3, 0.4]), -1.0);
        assert_eq!(e.competence(&[0.0, 0.0], &[0.6, 0.8]), -2.0);
        assert_eq!(e.competence(&[0.0, 0.0], &[1.0, 1.0]), -2.0);
    }

    /// A case computed by hand, window 2.
    #[test]
    fn progress_and_interest_by_hand() {
        let mut m = ModuleInterest::new(2, 2.0, 1.0).unwrap();
        assert_eq!(m.interest(), INITIAL_PROGRESS);
        // First episode: no earlier goal, progress 0; q = 1e-5 + (0 - 1e-5) / 2.
        assert_eq!(m.update(&[0.0, 0.0], &[1.0, 0.0]).unwrap(), 0.0);
        assert!((m.interest() - 5e-6).abs() < 1e-20);
        // Goal (0.1, 0) reached exactly: c = 0. Nearest earlier goal (0, 0), whose outcome
        // (1, 0) is 0.9 from this goal: c_old = -0.9, progress 0.9; q = 5e-6 + (0.9 - 5e-6) / 2.
        let p = m.update(&[0.1, 0.0], &[0.1, 0.0]).unwrap();
        assert!((p - 0.9).abs() < 1e-15, "{p}");
        assert!((m.interest() - (5e-6 + (0.9 - 5e-6) / 2.0)).abs() < 1e-15);
        // Worse than the neighbour's outcome: negative progress, and the interest is |q|.
        let p3 = m.update(&[0.1, 0.01], &[-1.0, 0.0]).unwrap();
        // Nearest earlier goal (0.1, 0), reached (0.1, 0): c_old = -0.01, c = -1.10004...
        let c = -((1.1f64).powi(2) + 0.0001).sqrt();
        assert!((p3 - (c + 0.01)).abs() < 1e-15, "{p3}");
        // Beyond the cap: an outcome 3 away from its goal counts as 2 away.
        let p = m.update(&[0.1, 0.02], &[3.1, 0.02]).unwrap();
        // Nearest earlier goal (0.1, 0.01), reached (-1, 0): c_old = -1.10004..., c = -2.
        let c_old = -((1.1f64).powi(2) + 0.0004).sqrt();
        assert!((p - (-2.0 - c_old)).abs() < 1e-15, "{p}");
        assert_eq!(m.len(), 4);
        let mut q = 5e-6 + (0.9 - 5e-6) / 2.0;
        q += (p3 - q) / 2.0;
        q += (p - q) / 2.0;
        assert!((m.interest() - q.abs()).abs() < 1e-15);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(ModuleInterest::new(0, 10.0, 1.0).is_err());
        assert!(ModuleInterest::new(2, 0.5, 1.0).is_err());
        assert!(ModuleInterest::new(2, f64::NAN, 1.0).is_err());
        assert!(ModuleInterest::new(2, 10.0, 0.0).is_err());
        let mut m = ModuleInterest::new(2, 10.0, 1.0).unwrap();
        assert!(m.update(&[0.0], &[0.0, 0.0]).is_err());
        assert!(m.update(&[0.0, f64::NAN], &[0.0, 0.0]).is_err());
        assert!(m.is_empty(), "a refused episode is not recorded");
        let mut rng = stream_named(1, "choice");
        assert!(choose_module(&[], 0.1, &mut rng).is_err());
        assert!(choose_module(&[1.0, -0.1], 0.1, &mut rng).is_err());
        assert!(choose_module(&[1.0], 1.5, &mut rng).is_err());
    }

    #[test]
    fn modules_are_chosen_in_proportion_to_interest() {
        let mut rng = stream_named(7, "choice");
        let n = 20_000;
        let mut counts = [0usize; 3];
        for _ in 0..n {
            counts[choose_module(&[0.0, 3.0, 1.0], 0.1, &mut rng).unwrap()] += 1;
        }
        // P = eps / 3 + (1 - eps) * interest / total: 0.0333, 0.7083, 0.2583.
        let expect = [0.1 / 3.0, 0.1 / 3.0 + 0.9 * 0.75, 0.1 / 3.0 + 0.9 * 0.25];
        for (c, e) in counts.iter().zip(expect) {
            let f = *c as f64 / n as f64;
            // 5 standard deviations of a binomial proportion at n = 20,000.
            let tol = 5.0 * (e * (1.0 - e) / n as f64).sqrt();
            assert!((f - e).abs() < tol, "{counts:?}: {f} vs {e}");
        }
        // No interest anywhere: uniform; eps = 0: only modules with interest.
        let mut seen = [false; 4];
        for _ in 0..200 {
            seen[choose_module(&[0.0; 4], 0.0, &mut rng).unwrap()] = true;
            assert_eq!(
                choose_module(&[0.0, 0.0, 2.0, 0.0], 0.0, &mut rng).unwrap(),
                2
            );
        }
        assert_eq!(seen, [true; 4]);
        // Same stream, same choices.
        let draw = |seed| {
            let mut r = stream_named(seed, "choice");
            (0..50)
                .map(|_| choose_module(&[0.5, 0.2, 0.3], 0.1, &mut r).unwrap())
                .collect::<Vec<_>>()
        };
        assert_eq!(draw(3), draw(3));
    }
}
