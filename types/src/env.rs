//! The environment registry: what every part of the project needs to know about an
//! environment, declared once. The science crate builds the environment itself (its dynamics
//! and renderer, keyed by [`EnvSpec::name`]); the command line's help, config validation, the
//! report's names, panel order and KL-coverage bounds read this table. The built-in
//! environments are declared here; another one is added at run time with
//! [`EnvSpec::register`] (by the science crate's `env::register`, which also gives it its
//! dynamics).

use std::sync::RwLock;

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
        libm::log(self.achievable_cells as f64)
    }
}

/// The picture an environment renders: what a goal-space learner sees of an outcome.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageShape {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Values per pixel (1: gray, 3: RGB).
    pub channels: usize,
}

impl ImageShape {
    /// Values of one picture.
    pub const fn len(&self) -> usize {
        self.width * self.height * self.channels
    }

    /// Whether a picture holds no value.
    pub const fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The paper's pictures: 70 x 70 gray, stored x-major (pixel (x, y) at x * 70 + y).
pub const GRAY70: ImageShape = ImageShape {
    width: 70,
    height: 70,
    channels: 1,
};

/// The paper's motor parameters: a DMP of 3 weights per joint of the 7-joint arm.
pub const DMP_PARAMS: usize = 21;

/// One environment of the registry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
    /// Motor parameters of an episode, each in [-1, 1].
    pub params: usize,
    /// The picture of an outcome.
    pub image: ImageShape,
}

/// The 30 x 30 grid over the arm's disk: 756 achievable cells.
pub const DISK: KlcGrid = KlcGrid {
    dims: 2,
    bins: 30,
    achievable_cells: 756,
};

/// ArmBall (paper Section 4.1).
pub static ARMBALL: EnvSpec = EnvSpec {
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
    params: DMP_PARAMS,
    image: GRAY70,
};

/// ArmArrow (paper Section 4.1).
pub static ARMARROW: EnvSpec = EnvSpec {
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
    params: DMP_PARAMS,
    image: GRAY70,
};

/// ArmBalls (the follow-up paper): the ball and a distractor the arm cannot move.
pub static ARMBALLS: EnvSpec = EnvSpec {
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
    params: DMP_PARAMS,
    image: GRAY70,
};

/// The follow-up's pictures: 64 x 64 RGB, row-major, channels last.
pub const RGB64: ImageShape = ImageShape {
    width: 64,
    height: 64,
    channels: 3,
};

/// The follow-up's ArmBalls as its authors' code has it: a radial-basis controller of 49
/// parameters and 64 x 64 RGB pictures (the science crate's `env::cdge`).
pub static ARMBALLS_CORL: EnvSpec = EnvSpec {
    name: "armballs-corl",
    display: "ArmBalls (CoRL 2018)",
    description: "the follow-up's own ArmBalls: 49 radial-basis parameters, 64x64 RGB pictures",
    in_paper: false,
    params: 49,
    image: RGB64,
    ..ARMBALLS
};

/// The environments of this crate, in the report's order (the paper's first). Others are
/// added at run time with [`EnvSpec::register`] and come after them.
pub static BUILT_IN: [&EnvSpec; 4] = [&ARMBALL, &ARMARROW, &ARMBALLS, &ARMBALLS_CORL];

/// The registry: the built-in environments, then the registered ones in registration order.
static REGISTRY: RwLock<Vec<&'static EnvSpec>> = RwLock::new(Vec::new());

/// Why an environment cannot be registered.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EnvSpecError {
    /// Its name is taken by another environment.
    #[error("environment '{0}' is already registered")]
    Duplicate(&'static str),
    /// Its declaration contradicts itself.
    #[error("environment '{name}': {why}")]
    Invalid {
        /// The environment.
        name: &'static str,
        /// What is wrong.
        why: String,
    },
}

/// Every environment of the registry, in the report's order.
pub fn environments() -> Vec<&'static EnvSpec> {
    let registered = REGISTRY.read().unwrap_or_else(|e| e.into_inner());
    BUILT_IN
        .iter()
        .copied()
        .chain(registered.iter().copied())
        .collect()
}

impl EnvSpec {
    /// The environment called `name`.
    pub fn by_name(name: &str) -> Option<&'static EnvSpec> {
        environments().into_iter().find(|e| e.name == name)
    }

    /// Add an environment to the registry (after the built-in ones), once its declaration is
    /// checked ([`EnvSpec::check`]). Registering the same declaration twice is a no-op; another
    /// one under a taken name is refused.
    pub fn register(spec: &'static EnvSpec) -> Result<(), EnvSpecError> {
        spec.check()?;
        let mut registered = REGISTRY.write().unwrap_or_else(|e| e.into_inner());
        match BUILT_IN
            .iter()
            .chain(registered.iter())
            .find(|e| e.name == spec.name)
        {
            Some(e) if *e == spec => Ok(()),
            Some(_) => Err(EnvSpecError::Duplicate(spec.name)),
            None => {
                registered.push(spec);
                Ok(())
            }
        }
    }

    /// Check that the declaration is consistent: a name fit for file names, objects that tile
    /// the outcome in order, one name per outcome coordinate, a KL-coverage grid over the
    /// controllable objects' coordinates, and a true latent size of at least one.
    pub fn check(&self) -> Result<(), EnvSpecError> {
        let bad = |why: String| EnvSpecError::Invalid {
            name: self.name,
            why,
        };
        if self.name.is_empty()
            || !self
                .name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
        {
            return Err(bad(
                "the name must be lowercase letters, digits and '-' (it names files)".into(),
            ));
        }
        let mut next = 0;
        for o in self.objects {
            if o.start != next || o.end <= o.start {
                return Err(bad(format!(
                    "object '{}' must cover coordinates {next}.. (got {}..{})",
                    o.name, o.start, o.end
                )));
            }
            next = o.end;
        }
        if next != self.state_dim || self.state_dim == 0 {
            return Err(bad(format!(
                "the objects cover {next} coordinates, the outcome has {}",
                self.state_dim
            )));
        }
        if self.outcome_columns.len() != self.state_dim {
            return Err(bad(format!(
                "{} outcome column names for {} coordinates",
                self.outcome_columns.len(),
                self.state_dim
            )));
        }
        if self.metric_dims().len() != self.klc.dims || self.klc.dims == 0 {
            return Err(bad(format!(
                "the KL-coverage grid measures {} coordinates, the controllable objects have {}",
                self.klc.dims,
                self.metric_dims().len()
            )));
        }
        if self.true_latents == 0 {
            return Err(bad("the true latent size must be at least 1".into()));
        }
        if self.params == 0 {
            return Err(bad("an episode needs at least 1 motor parameter".into()));
        }
        if self.image.is_empty() {
            return Err(bad("the picture must hold at least 1 value".into()));
        }
        Ok(())
    }

    /// Every environment's name, `a, b or c`, for help texts and errors.
    pub fn names_sentence() -> String {
        let names: Vec<&str> = environments().iter().map(|e| e.name).collect();
        match names.split_last() {
            Some((last, [])) => last.to_string(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        }
    }

    /// Position of the environment `name` in the report's order; unknown names after every
    /// known one.
    pub fn order(name: &str) -> usize {
        let all = environments();
        all.iter().position(|e| e.name == name).unwrap_or(all.len())
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

    /// Each object's position coordinates (its first two, x and y), in outcome order: the
    /// engineered features without orientation (`rge-efr-position`).
    pub fn position_dims(&self) -> Vec<usize> {
        self.objects
            .iter()
            .flat_map(|o| o.start..o.end.min(o.start + 2))
            .collect()
    }

    /// Whether the engineered outcome holds more than the objects' positions (ArmArrow's angle):
    /// only then is the position-only goal space (`rge-efr-position`) a condition of its own.
    pub fn has_orientation(&self) -> bool {
        self.position_dims().len() < self.state_dim
    }

    /// The controllable object's name (`ball`, `arrow`), or `object` when several are.
    pub fn controllable_object(&self) -> &'static str {
        let mut c = self.objects.iter().filter(|o| o.controllable);
        match (c.next(), c.next()) {
            (Some(o), None) => o.name,
            _ => "object",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_registry_is_consistent() {
        for e in environments() {
            e.check().unwrap();
            assert_eq!(EnvSpec::by_name(e.name), Some(e));
            assert_eq!(e.objects.last().unwrap().end, e.state_dim, "{}", e.name);
            assert_eq!(e.outcome_columns.len(), e.state_dim, "{}", e.name);
            assert_eq!(e.metric_dims().len(), e.klc.dims, "{}", e.name);
        }
        // Other tests may register environments after the built-in ones.
        assert!(EnvSpec::names_sentence().starts_with("armball, armarrow"));
        assert_eq!(EnvSpec::order("armarrow"), 1);
        assert!(EnvSpec::order("nope") >= BUILT_IN.len());
        let balls = EnvSpec::by_name("armballs").unwrap();
        assert_eq!(
            (balls.metric_dims(), balls.control_dims()),
            (0..2, Some(2..4))
        );
        assert_eq!(EnvSpec::by_name("armball").unwrap().control_dims(), None);
        assert_eq!(ARMARROW.position_dims(), [0, 1]);
        assert_eq!(ARMBALLS.position_dims(), [0, 1, 2, 3]);
        assert!((DISK.max_klc() - 756f64.ln()).abs() < 1e-15);
    }

    static TOY: EnvSpec = EnvSpec {
        name: "toy-registry-test",
        display: "Toy",
        description: "a test",
        in_paper: false,
        objects: &[ObjectSpec {
            name: "dot",
            start: 0,
            end: 2,
            controllable: true,
        }],
        state_dim: 2,
        true_latents: 2,
        outcome_columns: &["x", "y"],
        klc: DISK,
        params: DMP_PARAMS,
        image: GRAY70,
    };

    #[test]
    fn an_environment_is_registered_once_after_the_built_in_ones_and_checked() {
        EnvSpec::register(&TOY).unwrap();
        EnvSpec::register(&TOY).unwrap();
        assert_eq!(EnvSpec::by_name("toy-registry-test"), Some(&TOY));
        assert!(EnvSpec::order("toy-registry-test") >= BUILT_IN.len());
        assert_eq!(
            environments().iter().filter(|e| e.name == TOY.name).count(),
            1
        );
        static TAKEN: EnvSpec = EnvSpec {
            display: "Another ArmBall",
            ..ARMBALL
        };
        assert_eq!(
            EnvSpec::register(&TAKEN),
            Err(EnvSpecError::Duplicate("armball"))
        );
        static UNTILED: EnvSpec = EnvSpec {
            name: "untiled",
            state_dim: 3,
            ..ARMBALL
        };
        let e = EnvSpec::register(&UNTILED).unwrap_err().to_string();
        assert!(e.contains("the objects cover 2 coordinates"), "{e}");
        static BAD_NAME: EnvSpec = EnvSpec {
            name: "Arm Ball",
            ..ARMBALL
        };
        assert!(EnvSpec::register(&BAD_NAME).is_err());
        assert_eq!(EnvSpec::by_name("untiled"), None);
    }
}
