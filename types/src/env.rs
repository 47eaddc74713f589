//! The environment registry: what every part of the project needs to know about an
//! environment, declared once. The science crate builds the environment itself (its dynamics
//! and renderer, keyed by [`EnvSpec::name`]); the command line's help, config validation, the
//! report's names, panel order and KL-coverage bounds read this table.

/// An object of the scene and its coordinates in the engineered outcome.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObjectSpec {
    /// `ball`, `arrow`, `distractor`.
    pub name: &'static str,
    /// First outcome coordinate of the object.
    pub start: usize,
    /// One past its last coordinate.
    pub end: usize,
    /// Whether the arm can move it. An object it cannot move is measured as a control
    /// (exploration cannot help there).
    pub controllable: bool,
}

impl ObjectSpec {
    /// Its outcome coordinates.
    pub fn dims(&self) -> std::ops::Range<usize> {
        self.start..self.end
    }
}

/// The KL-coverage grid of an environment (paper Section 4.2): 30 bins per measured dimension
/// over [-1, 1]; the achievable cells are the (x, y) bins meeting the open unit disk (756 of
/// 900), times every angle bin where the angle is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KlcGrid {
    /// Outcome coordinates measured (the controllable object's).
    pub dims: usize,
    /// Bins per dimension.
    pub bins: usize,
    /// Cells the object can reach; the largest KLC (every outcome in one cell) is its log.
    pub achievable_cells: usize,
}

impl KlcGrid {
    /// The largest possible KL-coverage, `ln(achievable cells)`.
    pub fn max_klc(&self) -> f64 {
        (self.achievable_cells as f64).ln()
    }
}

/// One environment of the registry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvSpec {
    /// Name on the command line, in campaign files and results (`armball`).
    pub name: &'static str,
    /// Name in the report (`ArmBall`).
    pub display: &'static str,
    /// One line for `--help` and the docs.
    pub description: &'static str,
    /// Whether the paper evaluated it (the report's paper sections draw these).
    pub in_paper: bool,
    /// The objects of the scene, in outcome order.
    pub objects: &'static [ObjectSpec],
    /// Dimension of the engineered outcome (every object's coordinates).
    pub state_dim: usize,
    /// The true latent size (`latents = "true"`): the paper's "complete" representation.
    pub true_latents: usize,
    /// Names of the outcome coordinates (`x,y,angle` for `ugl klc --outcomes`).
    pub outcome_columns: &'static [&'static str],
    /// The KL-coverage grid of the controllable object.
    pub klc: KlcGrid,
}

/// The 30 x 30 grid over the arm's disk: 756 achievable cells.
const DISK: KlcGrid = KlcGrid {
    dims: 2,
    bins: 30,
    achievable_cells: 756,
};

/// Every environment, in the report's order (the paper's first).
pub static ENVIRONMENTS: [EnvSpec; 3] = [
    EnvSpec {
        name: "armball",
        display: "ArmBall",
        description: "a ball the arm can catch and move (2-D outcome: x, y)",
        in_paper: true,
        objects: &[ObjectSpec {
            name: "ball",
            start: 0,
            end: 2,
            controllable: true,
        }],
        state_dim: 2,
        true_latents: 2,
        outcome_columns: &["x", "y"],
        klc: DISK,
    },
    EnvSpec {
        name: "armarrow",
        display: "ArmArrow",
        description: "an arrow the arm can catch, move and orient (3-D outcome: x, y, angle)",
        in_paper: true,
        objects: &[ObjectSpec {
            name: "arrow",
            start: 0,
            end: 3,
            controllable: true,
        }],
        state_dim: 3,
        true_latents: 3,
        outcome_columns: &["x", "y", "angle"],
        klc: KlcGrid {
            dims: 3,
            bins: 30,
            achievable_cells: 756 * 30,
        },
    },
    EnvSpec {
        name: "armballs",
        display: "ArmBalls",
        description: "the ball and a distractor ball on a random walk (follow-up paper; 4-D outcome)",
        in_paper: false,
        objects: &[
            ObjectSpec {
                name: "ball",
                start: 0,
                end: 2,
                controllable: true,
            },
            ObjectSpec {
                name: "distractor",
                start: 2,
                end: 4,
                controllable: false,
            },
        ],
        state_dim: 4,
        true_latents: 4,
        outcome_columns: &["x", "y", "distractor_x", "distractor_y"],
        klc: DISK,
    },
];

impl EnvSpec {
    /// The environment called `name`.
    pub fn by_name(name: &str) -> Option<&'static EnvSpec> {
        ENVIRONMENTS.iter().find(|e| e.name == name)
    }

    /// Every environment's name, `a, b or c`, for help texts and errors.
    pub fn names_sentence() -> String {
        let names: Vec<&str> = ENVIRONMENTS.iter().map(|e| e.name).collect();
        match names.split_last() {
            Some((last, [])) => last.to_string(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        }
    }

    /// Position of the environment `name` in the report's order; unknown names after every
    /// known one.
    pub fn order(name: &str) -> usize {
        ENVIRONMENTS
            .iter()
            .position(|e| e.name == name)
            .unwrap_or(ENVIRONMENTS.len())
    }

    /// The display name of `name`, or `name` itself for an environment this build lacks.
    pub fn display_of(name: &str) -> String {
        EnvSpec::by_name(name).map_or_else(|| name.to_string(), |e| e.display.to_string())
    }

    /// The outcome coordinates exploration is measured on: the controllable objects'.
    pub fn metric_dims(&self) -> std::ops::Range<usize> {
        let c: Vec<_> = self.objects.iter().filter(|o| o.controllable).collect();
        c.first().map_or(0, |o| o.start)..c.last().map_or(0, |o| o.end)
    }

    /// The coordinates of an object the agent cannot move, measured as a control.
    pub fn control_dims(&self) -> Option<std::ops::Range<usize>> {
        let c: Vec<_> = self.objects.iter().filter(|o| !o.controllable).collect();
        Some(c.first()?.start..c.last()?.end)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_registry_is_consistent() {
        for e in &ENVIRONMENTS {
            assert_eq!(EnvSpec::by_name(e.name), Some(e));
            assert_eq!(e.objects.last().unwrap().end, e.state_dim, "{}", e.name);
            assert_eq!(e.outcome_columns.len(), e.state_dim, "{}", e.name);
            assert_eq!(e.metric_dims().len(), e.klc.dims, "{}", e.name);
        }
        assert_eq!(EnvSpec::names_sentence(), "armball, armarrow or armballs");
        assert_eq!(EnvSpec::order("armarrow"), 1);
        assert_eq!(EnvSpec::order("nope"), ENVIRONMENTS.len());
        let balls = EnvSpec::by_name("armballs").unwrap();
        assert_eq!(
            (balls.metric_dims(), balls.control_dims()),
            (0..2, Some(2..4))
        );
        assert_eq!(EnvSpec::by_name("armball").unwrap().control_dims(), None);
        assert!((DISK.max_klc() - 756f64.ln()).abs() < 1e-15);
    }
}
