//! The engineered features through a fixed rotation of all their coordinates (`efr-mixed`): the
//! follow-up's "entangled" control without a network (issue 44, item 5). The goal space holds
//! exactly the information of the engineered features (a rotation loses none), but no
//! coordinate, and so no module of consecutive coordinates, belongs to one object: "a
//! disentangled space explores better than an entangled one" can be tested on it without any
//! learned representation.
//!
//! - Outcome: `y = R s`, `s` the scene's state (each coordinate in [-1, 1]), `R` the fixed
//!   rotation of [`mixing_rotation`].
//! - Goals: `R u`, `u` uniform in [-1, 1]^d (the engineered goals, rotated); a module's goals are
//!   its coordinates of such a draw.
//! - Modules: consecutive groups of `mge.module_size` coordinates.

use rand::RngExt;

use super::imgep::OutcomeSpace;
use super::mge::{GoalModule, Modules, goal_modules};
use crate::goals::GoalSampler;
use crate::repr::ReprError;
use crate::seed::{Stream, standard_normal, stream_named};

/// The fixed rotation of a `d`-dimensional state whose `objects` own the coordinate ranges given
/// (row-major `d x d`, orthonormal rows): the first of a sequence of random rotations (modified
/// Gram-Schmidt on standard normals from a stream of its own, the same on every run and machine:
/// `sqrt`, products and sums only) in which every mixed coordinate puts at least half of an
/// even share of its weight on each object (between 1/4 and 3/4 with two objects). A random
/// rotation alone can leave a coordinate nearly one object's (93% on the ball, measured), which
/// would not be the entangled control it is meant to be.
pub fn mixing_rotation(d: usize, objects: &[std::ops::Range<usize>]) -> Vec<f64> {
    let mut rng = stream_named(0, "efr-mixed-rotation");
    loop {
        let r = random_rotation(d, &mut rng);
        let fair = 0.5 / objects.len().max(1) as f64;
        let mixes = (0..d).all(|i| {
            objects.len() < 2
                || objects
                    .iter()
                    .all(|o| o.clone().map(|k| r[i * d + k] * r[i * d + k]).sum::<f64>() >= fair)
        });
        if mixes {
            return r;
        }
    }
}

/// A random rotation: modified Gram-Schmidt on `d x d` standard normals.
fn random_rotation(d: usize, rng: &mut Stream) -> Vec<f64> {
    let mut r: Vec<f64> = (0..d * d).map(|_| standard_normal(rng)).collect();
    for i in 0..d {
        for j in 0..i {
            let dot: f64 = (0..d).map(|k| r[i * d + k] * r[j * d + k]).sum();
            for k in 0..d {
                r[i * d + k] -= dot * r[j * d + k];
            }
        }
        let norm = (0..d)
            .map(|k| r[i * d + k] * r[i * d + k])
            .sum::<f64>()
            .sqrt();
        for k in 0..d {
            r[i * d + k] /= norm;
        }
    }
    r
}

/// `R x` for a row-major `d x d` matrix `R`.
fn rotate(r: &[f64], x: &[f64], out: &mut [f64]) {
    let d = x.len();
    for (i, o) in out.iter_mut().enumerate() {
        *o = (0..d).map(|k| r[i * d + k] * x[k]).sum();
    }
}

/// The outcome space `y = R s`.
#[derive(Clone, Debug)]
pub struct MixedSpace {
    rotation: Vec<f64>,
    dim: usize,
}

impl MixedSpace {
    /// For states of dimension `dim` holding `objects` ([`mixing_rotation`]).
    pub fn new(dim: usize, objects: &[std::ops::Range<usize>]) -> Self {
        MixedSpace {
            rotation: mixing_rotation(dim, objects),
            dim,
        }
    }
}

impl OutcomeSpace for MixedSpace {
    fn dim(&self) -> usize {
        self.dim
    }
    fn encode(&mut self, state: &[f64], out: &mut [f64]) {
        rotate(&self.rotation, &state[..self.dim], out);
    }
}

/// The goals of the mixed space: rotated uniform draws, modules of consecutive coordinates.
#[derive(Clone, Debug)]
pub struct MixedGoals {
    rotation: Vec<f64>,
    dim: usize,
}

impl MixedGoals {
    /// For states of dimension `dim` holding `objects` ([`mixing_rotation`]).
    pub fn new(dim: usize, objects: &[std::ops::Range<usize>]) -> Self {
        MixedGoals {
            rotation: mixing_rotation(dim, objects),
            dim,
        }
    }
}

impl super::goal_source::GoalSource for MixedGoals {
    fn modules(&self, choice: Modules, module_size: usize) -> Result<Vec<GoalModule>, ReprError> {
        let mut modules = goal_modules(choice, self.dim, None, &vec![1.0; self.dim], module_size)
            .map_err(|e| ReprError::InvalidInput(e.to_string()))?;
        // Named by the mixed coordinates `y = R s` they hold (`y0,y1`), not as latents.
        for m in modules.iter_mut().filter(|m| m.name != "all") {
            m.name = m
                .dims
                .iter()
                .map(|k| format!("y{k}"))
                .collect::<Vec<_>>()
                .join(",");
        }
        Ok(modules)
    }
    fn sampler(&self, dims: Option<&[usize]>) -> Result<Box<dyn GoalSampler>, ReprError> {
        Ok(Box::new(MixedSampler {
            rotation: self.rotation.clone(),
            dims: dims.map_or_else(|| (0..self.dim).collect(), <[usize]>::to_vec),
            u: vec![0.0; self.dim],
            y: vec![0.0; self.dim],
        }))
    }
}

/// Goals `(R u)[dims]`, `u` uniform in [-1, 1]^d.
struct MixedSampler {
    rotation: Vec<f64>,
    dims: Vec<usize>,
    u: Vec<f64>,
    y: Vec<f64>,
}

impl GoalSampler for MixedSampler {
    fn dim(&self) -> usize {
        self.dims.len()
    }
    fn sample(&mut self, rng: &mut Stream, out: &mut [f64]) {
        for v in self.u.iter_mut() {
            *v = rng.random_range(-1.0..1.0);
        }
        rotate(&self.rotation, &self.u, &mut self.y);
        for (o, &k) in out.iter_mut().zip(&self.dims) {
            *o = self.y[k];
        }
    }
    fn name(&self) -> &'static str {
        ugl_types::samplers::UNIFORM.name
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::goal_source::GoalSource;

    /// The rotation is orthonormal (no information lost) and, on ArmBalls' four coordinates,
    /// every mixed coordinate draws on both objects: none is the ball's or the distractor's alone.
    const BALLS: [std::ops::Range<usize>; 2] = [0..2, 2..4];

    #[test]
    fn the_rotation_keeps_the_information_and_mixes_the_objects() {
        let d = 4;
        let r = mixing_rotation(d, &BALLS);
        for i in 0..d {
            for j in 0..d {
                let dot: f64 = (0..d).map(|k| r[i * d + k] * r[j * d + k]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((dot - want).abs() < 1e-12, "rows {i}, {j}: {dot}");
            }
            let ball = r[i * d] * r[i * d] + r[i * d + 1] * r[i * d + 1];
            assert!(
                (0.25..=0.75).contains(&ball),
                "coordinate {i}: {ball} of its weight on the ball"
            );
        }
        assert_eq!(r, mixing_rotation(d, &BALLS), "fixed");
        // The first random rotation of the stream does not mix (the known-bad case the rule
        // rejects): one coordinate is nearly the ball's alone.
        let first = random_rotation(d, &mut stream_named(0, "efr-mixed-rotation"));
        assert_ne!(first, r);
    }

    /// A goal is a rotated point of the box, its modules consecutive pairs.
    #[test]
    fn goals_are_rotated_box_points_in_pairs() {
        let goals = MixedGoals::new(4, &BALLS);
        let m = goals.modules(Modules::Progress, 2).unwrap();
        assert_eq!(
            m.iter().map(|m| m.dims.clone()).collect::<Vec<_>>(),
            [vec![0, 1], vec![2, 3]]
        );
        // Named by the mixed coordinates they hold, not as latents.
        assert_eq!(
            m.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(),
            ["y0,y1", "y2,y3"]
        );
        assert_eq!(goals.modules(Modules::Flat, 2).unwrap()[0].name, "all");
        let mut all = goals.sampler(None).unwrap();
        let mut g = [0.0; 4];
        let mut rng = stream_named(1, "goals");
        all.sample(&mut rng, &mut g);
        // Back through the transpose: a point of the box.
        let r = mixing_rotation(4, &BALLS);
        let u: Vec<f64> = (0..4)
            .map(|k| (0..4).map(|i| r[i * 4 + k] * g[i]).sum())
            .collect();
        assert!(u.iter().all(|v| (-1.0..1.0).contains(v)), "{u:?}");
        let mut second = goals.sampler(Some(&[2, 3])).unwrap();
        let mut h = [0.0; 2];
        second.sample(&mut stream_named(1, "goals"), &mut h);
        assert_eq!(h, [g[2], g[3]]);
        // The space encodes a state as the same rotation.
        let mut space = MixedSpace::new(4, &BALLS);
        let mut y = [0.0; 4];
        space.encode(&u, &mut y);
        for (a, b) in y.iter().zip(&g) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}
