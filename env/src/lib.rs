//! The environments of the paper (Section 4.1; docs/original-code.md section 1), the follow-up's
//! ArmBalls (a distractor ball; `armballs.rs`) and the renderer (docs/original-code.md section 2).
//!
//! A rollout runs one 50-step DMP movement of the 7-joint arm from rest; the object (ball or
//! arrow) is caught, stickily, as soon as the hand comes within `object_size` of it, and then
//! follows the hand. The outcome is the object state at the last step, clipped to [-1,1].
//!
//! This crate is the light part of ugl-bench: the environments, their renderers, the seeded
//! random streams (`seed`) and the `.npy` codec, with no training stack, so that the Python
//! package (`python/`) and the benchmark (`ugl-bench`, which re-exports it as `ugl_bench::env`)
//! share one implementation.

pub mod arm;
pub mod armarrow;
pub mod armball;
pub mod armballs;
pub mod cdge;
pub mod config;
pub mod dmp;
pub mod render;

pub mod invalid;
pub mod npy;
pub mod seed;
mod ziggurat_tables;

use std::fmt;
use std::str::FromStr;
use std::sync::RwLock;

use serde::{Deserialize, Serialize};

use crate::seed::Stream;
pub use ugl_types::EnvSpec;

pub use arm::{ArmConfig, ArmPose, JOINTS};
pub use armarrow::ArmArrow;
pub use armball::ArmBall;
pub use armballs::ArmBalls;
pub use config::{EnvConfig, NoConstants, OwnConstants, OwnTable, RunConstants};
pub use dmp::{DmpConfig, DmpTable, DmpWidths, PARAMS};

/// One environment of the registry: its declaration (names, objects, KL-coverage grid; shared
/// with the report through `ugl-types`) and how to build it from the `[env]` constants.
///
/// A new environment is one file holding its [`Environment`] implementation and a
/// `static` `EnvEntry`, plus one registry entry: a line of [`BUILT_IN`] for this crate's,
/// or a call of [`register`] before the command line runs for anyone else's.
#[derive(Debug)]
pub struct EnvEntry {
    /// Its declaration.
    pub spec: &'static EnvSpec,
    /// Its own constants (its `[env.NAME]` table): `OwnTable::of::<S>()` of the struct `S` of
    /// its file, or [`OwnTable::NONE`].
    pub constants: OwnTable,
    /// Whether it moves the shared arm with the shared motor primitive (`[env]`'s `arm` and
    /// `dmp`): when not, they do not enter its runs' config hashes.
    pub uses_arm: bool,
    /// Build it.
    pub build: fn(&EnvConfig) -> Box<dyn Environment>,
}

/// This crate's environments, in the report's order (the registry's built-in declarations).
pub static BUILT_IN: [EnvEntry; 4] = [
    EnvEntry {
        spec: &ugl_types::ARMBALL,
        constants: OwnTable::of::<armball::Constants>(),
        uses_arm: true,
        build: |cfg| Box::new(ArmBall::new(cfg)),
    },
    EnvEntry {
        spec: &ugl_types::ARMARROW,
        constants: OwnTable::of::<armarrow::Constants>(),
        uses_arm: true,
        build: |cfg| Box::new(ArmArrow::new(cfg)),
    },
    EnvEntry {
        spec: &ugl_types::ARMBALLS,
        constants: OwnTable::of::<armballs::Constants>(),
        uses_arm: true,
        build: |cfg| Box::new(ArmBalls::new(cfg)),
    },
    EnvEntry {
        spec: &ugl_types::ARMBALLS_CORL,
        constants: OwnTable::of::<cdge::Constants>(),
        uses_arm: false,
        build: |cfg| Box::new(cdge::CdgeArmBalls::new(cdge::Scene::of(cfg))),
    },
];

/// The environments added with [`register`], in registration order.
static REGISTERED: RwLock<Vec<&'static EnvEntry>> = RwLock::new(Vec::new());

/// Why an environment cannot be registered.
#[derive(Debug, thiserror::Error)]
pub enum RegisterError {
    /// Its declaration is inconsistent or its name is taken.
    #[error(transparent)]
    Spec(#[from] ugl_types::EnvSpecError),
    /// Its KL-coverage grid is not the measure's (30 bins per dimension, the cells of the arm's
    /// disk).
    #[error(
        "environment '{name}': its KL-coverage grid ({dims} dimensions, {cells} achievable \
         cells) is not the measure's ({measured})"
    )]
    Grid {
        /// The environment.
        name: &'static str,
        /// Its grid's dimensions.
        dims: usize,
        /// Its grid's achievable cells.
        cells: usize,
        /// What the measure has for that many dimensions.
        measured: String,
    },
    /// Its outcome has more coordinates than a [`Rollout`] holds.
    #[error("environment '{name}': {dim} outcome coordinates (at most {MAX_STATE_DIM})")]
    TooLarge {
        /// The environment.
        name: &'static str,
        /// Its outcome's dimension.
        dim: usize,
    },
}

/// Add an environment to the registry: `ugl run --env NAME`, campaigns (`envs = ["NAME"]`),
/// the command line's help and the report know it from then on. Its declaration is checked
/// (objects, outcome names, a KL-coverage grid the measure computes); registering the same
/// entry twice is a no-op.
pub fn register(entry: &'static EnvEntry) -> Result<EnvKind, RegisterError> {
    let spec = entry.spec;
    if spec.state_dim > MAX_STATE_DIM {
        return Err(RegisterError::TooLarge {
            name: spec.name,
            dim: spec.state_dim,
        });
    }
    let measured = ugl_types::klc::KlCoverage::new(spec.klc.dims).map(|m| m.n_achievable());
    if spec.klc.bins != ugl_types::klc::BINS
        || measured.as_ref().ok() != Some(&spec.klc.achievable_cells)
    {
        return Err(RegisterError::Grid {
            name: spec.name,
            dims: spec.klc.dims,
            cells: spec.klc.achievable_cells,
            measured: match measured {
                Ok(n) => format!("{n} cells of {} bins", ugl_types::klc::BINS),
                Err(e) => e.to_string(),
            },
        });
    }
    EnvSpec::register(spec)?;
    let mut registered = REGISTERED.write().unwrap_or_else(|e| e.into_inner());
    if !registered.iter().any(|e| std::ptr::eq(*e, entry)) {
        registered.push(entry);
    }
    Ok(EnvKind(entry))
}

/// Which environment: a handle on its registry entry. Compared, hashed and written by name
/// (`armball`); ordered as the registry lists them (the built-in ones first).
#[derive(Clone, Copy)]
pub struct EnvKind(&'static EnvEntry);

impl EnvKind {
    /// ArmBall (paper Section 4.1).
    pub const ARMBALL: EnvKind = EnvKind(&BUILT_IN[0]);
    /// ArmArrow (paper Section 4.1).
    pub const ARMARROW: EnvKind = EnvKind(&BUILT_IN[1]);
    /// ArmBalls (the follow-up paper), our DMP variant.
    pub const ARMBALLS: EnvKind = EnvKind(&BUILT_IN[2]);
    /// ArmBalls as the follow-up's code has it ([`cdge`]).
    pub const ARMBALLS_CORL: EnvKind = EnvKind(&BUILT_IN[3]);

    /// The handle of an entry; [`register`] it to make it known by name.
    pub const fn of(entry: &'static EnvEntry) -> EnvKind {
        EnvKind(entry)
    }

    /// Every environment of the registry, in the report's order.
    pub fn all() -> Vec<EnvKind> {
        let registered = REGISTERED.read().unwrap_or_else(|e| e.into_inner());
        BUILT_IN
            .iter()
            .chain(registered.iter().copied())
            .map(EnvKind)
            .collect()
    }

    /// The paper's environments, in the report's order.
    pub fn paper() -> Vec<EnvKind> {
        EnvKind::all()
            .into_iter()
            .filter(|k| k.spec().in_paper)
            .collect()
    }

    /// The environment's declaration: names, objects, true latent size and KL-coverage grid
    /// are declared there, once.
    pub fn spec(self) -> &'static EnvSpec {
        self.0.spec
    }

    /// The name used on the command line and in results.
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// Dimension of the engineered outcome (and of the object state).
    pub fn state_dim(self) -> usize {
        self.spec().state_dim
    }

    /// The outcome coordinates that exploration is measured on (KL-coverage, cell coverage,
    /// moves): the controllable object's. All of them except in ArmBalls, where the distractor
    /// is left out.
    pub fn metric_dims(self) -> std::ops::Range<usize> {
        self.spec().metric_dims()
    }

    /// The outcome coordinates of an object the agent cannot control, measured the same way
    /// as a control (exploration cannot help there): ArmBalls' distractor.
    pub fn control_dims(self) -> Option<std::ops::Range<usize>> {
        self.spec().control_dims()
    }

    /// The objects of the scene and their outcome coordinates (the modules of modular
    /// exploration with engineered features): one object, or ArmBalls' ball and distractor.
    pub fn objects(self) -> Vec<(&'static str, std::ops::Range<usize>)> {
        self.spec()
            .objects
            .iter()
            .map(|o| (o.name, o.dims()))
            .collect()
    }

    /// Its position in the registry.
    fn position(self) -> usize {
        EnvSpec::order(self.name())
    }
}

impl PartialEq for EnvKind {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for EnvKind {}

impl std::hash::Hash for EnvKind {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.name().hash(state)
    }
}

impl PartialOrd for EnvKind {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for EnvKind {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        (self.position(), self.name()).cmp(&(other.position(), other.name()))
    }
}

impl fmt::Debug for EnvKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.spec().display)
    }
}

impl fmt::Display for EnvKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for EnvKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        EnvKind::all()
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown environment '{s}' (expected {})",
                    EnvSpec::names_sentence()
                )
            })
    }
}

impl Serialize for EnvKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for EnvKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

/// At most this many DMP steps per episode (the paper: 50).
pub const MAX_TIMESTEPS: usize = 10_000;

/// The most outcome coordinates an environment has ([`Rollout::state`]).
pub const MAX_STATE_DIM: usize = 4;

/// The result of one episode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rollout {
    /// Final object state (engineered outcome), clipped to [-1,1]; only the first
    /// `state_dim` entries are meaningful.
    pub state: [f64; MAX_STATE_DIM],
    /// Number of meaningful entries in `state`.
    pub dim: usize,
    /// The object was caught (and so moved with the hand) during the episode.
    pub caught: bool,
    /// Hand position at the last step.
    pub hand: [f64; 2],
}

impl Rollout {
    /// The engineered outcome.
    pub fn outcome(&self) -> &[f64] {
        &self.state[..self.dim]
    }
}

/// An environment of the benchmark (docs/architecture.md, "Adding things").
pub trait Environment: Send + Sync {
    /// Which environment this is.
    fn kind(&self) -> EnvKind;
    /// Number of motor parameters (the declaration's: 21 DMP weights in the paper's
    /// environments).
    fn param_dim(&self) -> usize {
        self.kind().spec().params
    }
    /// Dimension of the engineered outcome.
    fn state_dim(&self) -> usize {
        self.kind().state_dim()
    }
    /// The object's initial state.
    fn initial_state(&self) -> &[f64];
    /// Run one episode with motor parameters `theta` ([`Environment::param_dim`] of them, each
    /// clipped to [-1,1]; another length is a caller's bug and panics). `noise` is the run's
    /// environment stream ([`crate::seed::Component::Distractor`]), consumed episode after
    /// episode by the environments that move on their own (ArmBalls' distractor); ArmBall and
    /// ArmArrow draw nothing from it.
    fn rollout(&self, theta: &[f64], noise: &mut Stream) -> Rollout;
    /// Whether [`Environment::rollout`] draws from `noise` (an object that moves on its own):
    /// then episodes must run in order, each continuing the stream where the last left it;
    /// otherwise they may run in parallel (the Python package's batched rollout).
    fn draws_noise(&self) -> bool {
        false
    }
    /// Values of one picture (the declaration's: 70 x 70 gray, 4900, in the paper's).
    fn image_len(&self) -> usize {
        self.kind().spec().image.len()
    }
    /// Render an object state (engineered coordinates) into a picture of
    /// [`Environment::image_len`] values (70x70 gray, x-major, in the paper's environments).
    fn render_into(&self, state: &[f64], out: &mut [f32]);
}

/// The 21 DMP parameters of an episode of the paper's environments (a caller passing another
/// number has a bug: [`Environment::rollout`]).
pub(crate) fn dmp_params(theta: &[f64]) -> &[f64; PARAMS] {
    theta.try_into().unwrap_or_else(|_| {
        panic!(
            "{} motor parameters given to a DMP environment, which takes {PARAMS}",
            theta.len()
        )
    })
}

/// Build an environment.
pub fn make_env(kind: EnvKind, cfg: &EnvConfig) -> Box<dyn Environment> {
    (kind.0.build)(cfg)
}

/// What the arm and its motor primitive share between the two environments.
#[derive(Clone, Debug)]
pub(crate) struct Body {
    pub arm: ArmConfig,
    pub table: DmpTable,
    pub size_sq: f64,
}

impl Body {
    pub fn new(cfg: &EnvConfig) -> Self {
        Body {
            arm: cfg.arm.clone(),
            table: cfg.dmp.table(),
            size_sq: cfg.object_size * cfg.object_size,
        }
    }

    /// Run the movement; the object at `object_xy` is caught the first step the squared
    /// hand-object distance is below `size^2` (that step already moves it). Returns whether it
    /// was caught and the arm pose at the last step.
    ///
    /// Exact shortcut: the forward kinematics is skipped at a step when a rigorous lower bound
    /// on the hand-object distance exceeds the catch radius. Since `|u(a) - u(b)| <= pi |a - b|`
    /// for unit vectors at angles `pi a`, `pi b`, the hand has moved at most
    /// `pi * sum_k L_k |A_k - A'_k|` (A = cumulative joint angles, units of pi) since the last
    /// pose computed exactly; the catch decisions are those of the step-by-step computation.
    #[inline]
    pub fn run(&self, theta: &[f64; PARAMS], object_xy: [f64; 2]) -> (bool, ArmPose) {
        const MARGIN: f64 = 1e-9;
        let mut dmp = dmp::DmpState::new(&self.table, theta);
        let steps = self.table.x.len();
        let size = self.size_sq.sqrt();
        let mut caught = false;
        // Cumulative angles and hand-object distance at the last exactly computed pose.
        let mut ref_cum = [f64::NAN; JOINTS];
        let mut ref_dist = 0.0;
        for t in 0..steps {
            let q = dmp.step(&self.table, t);
            if t + 1 == steps {
                let pose = self.arm.forward(q);
                if !caught {
                    caught = self.within(&pose, object_xy);
                }
                return (caught, pose);
            }
            if caught {
                continue;
            }
            let mut cum = [0.0; JOINTS];
            let mut acc = 0.0;
            let mut moved = 0.0;
            for k in 0..JOINTS {
                acc += q[k].clamp(-1.0, 1.0);
                cum[k] = acc;
                moved += self.arm.lengths[k] * (acc - ref_cum[k]).abs();
            }
            // NaN (no reference yet) fails the comparison and forces the exact computation.
            if ref_dist - std::f64::consts::PI * moved > size + MARGIN {
                continue;
            }
            let pose = self.arm.forward(q);
            caught = self.within(&pose, object_xy);
            ref_cum = cum;
            let (dx, dy) = (pose.hand[0] - object_xy[0], pose.hand[1] - object_xy[1]);
            ref_dist = (dx * dx + dy * dy).sqrt();
        }
        // Zero steps: the arm never moves.
        (false, self.arm.forward(&[0.0; JOINTS]))
    }

    /// The catch test of the original: squared hand-object distance strictly below size^2.
    #[inline]
    fn within(&self, pose: &ArmPose, object_xy: [f64; 2]) -> bool {
        let dx = pose.hand[0] - object_xy[0];
        let dy = pose.hand[1] - object_xy[1];
        dx * dx + dy * dy < self.size_sq
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `draws_noise` tells the truth: an environment that says no leaves the stream where it
    /// was (its episodes may run in parallel), one that says yes moves it.
    #[test]
    fn draws_noise_says_whether_the_stream_moves() {
        use rand::RngExt;
        for kind in EnvKind::all() {
            let env = make_env(kind, &EnvConfig::default());
            let theta = vec![0.3; env.param_dim()];
            let mut noise = crate::seed::stream(7, crate::seed::Component::Distractor);
            env.rollout(&theta, &mut noise);
            let mut fresh = crate::seed::stream(7, crate::seed::Component::Distractor);
            let moved = noise.random::<u64>() != fresh.random::<u64>();
            assert_eq!(moved, env.draws_noise(), "{kind}");
        }
    }

    #[test]
    fn the_paper_constants_pass_the_checks_and_each_range_is_enforced() {
        let ok = EnvConfig::default();
        ok.validate().unwrap();
        let mut head = EnvConfig::default();
        head.dmp.widths = DmpWidths::ExplautoHead;
        head.validate().unwrap();
        let still = EnvConfig::default().with("distractor_noise", 0.0).unwrap();
        still.validate().unwrap();
        let own = |key: &str, v: serde_json::Value| EnvConfig::default().with(key, v).unwrap();
        for (e, key) in [
            (
                own("distractor_noise", (-0.1).into()),
                "env.distractor_noise",
            ),
            (
                own("armballs-corl.distractor_noise", 1.5.into()),
                "env.armballs-corl.distractor_noise",
            ),
            (
                own("distractor_initial", serde_json::json!([0.0, 0.96])),
                "env.distractor_initial[1]",
            ),
            (
                own("armball.ball_initial", serde_json::json!([1.5, 0.0])),
                "env.armball.ball_initial[0]",
            ),
            (
                own(
                    "armarrow.arrow_initial",
                    serde_json::json!([0.0, 0.0, -1.5]),
                ),
                "env.armarrow.arrow_initial[2]",
            ),
        ] {
            let m = e.validate().unwrap_err();
            assert_eq!(m.key, key, "{m}");
            assert!(m.message.starts_with(key), "{m} should start with {key}");
        }
        let bad: [(fn(&mut EnvConfig), &str); 4] = [
            (|e| e.arm.lengths[6] = 0.5, "env.arm.lengths"),
            (|e| e.dmp.timesteps = MAX_TIMESTEPS + 1, "env.dmp.timesteps"),
            (|e| e.dmp.ay = -1.0, "env.dmp.ay"),
            (|e| e.object_size = 2.0, "env.object_size"),
        ];
        for (change, key) in bad {
            let mut e = EnvConfig::default();
            change(&mut e);
            let m = e.validate().unwrap_err();
            assert_eq!(m.key, key, "{m}");
            assert!(m.message.starts_with(key), "{m} should start with {key}");
        }
    }

    #[test]
    fn env_names_round_trip() {
        for k in EnvKind::all() {
            assert_eq!(k.name().parse::<EnvKind>().unwrap(), k);
            let json = serde_json::to_string(&k).unwrap();
            assert_eq!(json, format!("\"{}\"", k.name()));
            assert_eq!(serde_json::from_str::<EnvKind>(&json).unwrap(), k);
        }
        assert!("armbal".parse::<EnvKind>().is_err());
        // Every declaration of the registry is an environment of this build, and the other
        // way round; the built-in ones keep the order of the closed enumeration they replace.
        let names = |v: Vec<&'static str>| v;
        assert_eq!(
            names(EnvKind::all().iter().map(|k| k.name()).collect()),
            names(ugl_types::environments().iter().map(|e| e.name).collect())
        );
        assert!(EnvKind::ARMBALL < EnvKind::ARMARROW && EnvKind::ARMARROW < EnvKind::ARMBALLS);
    }

    /// The registry's KL-coverage grid is the measure's: same dimension, same achievable cells.
    #[test]
    fn registry_klc_grids_are_the_measures() {
        for k in EnvKind::all() {
            let grid = k.spec().klc;
            let m = ugl_types::klc::KlCoverage::new(grid.dims).unwrap();
            assert_eq!(m.n_achievable(), grid.achievable_cells, "{k}");
            assert_eq!(ugl_types::klc::BINS, grid.bins, "{k}");
            assert_eq!(m.max_klc(), grid.max_klc(), "{k}");
            assert_eq!(k.metric_dims().len(), grid.dims, "{k}");
        }
    }

    /// The step-by-step computation of the original, without the distance-bound shortcut.
    fn naive(body: &Body, theta: &[f64; PARAMS], obj: [f64; 2]) -> (bool, ArmPose) {
        let mut dmp = dmp::DmpState::new(&body.table, theta);
        let mut caught = false;
        let mut pose = body.arm.forward(&[0.0; JOINTS]);
        for t in 0..body.table.x.len() {
            pose = body.arm.forward(dmp.step(&body.table, t));
            caught = caught || body.within(&pose, obj);
        }
        (caught, pose)
    }

    #[test]
    fn shortcut_gives_the_exact_catch_decisions() {
        use rand::RngExt;
        let cfg = EnvConfig::default();
        let body = Body::new(&cfg);
        let mut rng = crate::seed::stream_named(5, "test");
        let mut catches = 0;
        for i in 0..20_000 {
            // Random parameters, and small ones that keep the hand near the object for long.
            let scale = if i % 2 == 0 { 1.0 } else { 0.05 };
            let theta: [f64; PARAMS] = std::array::from_fn(|_| scale * rng.random_range(-1.0..1.0));
            for obj in [[0.6, 0.6], [0.0, 0.95], [0.3, -0.2]] {
                let fast = body.run(&theta, obj);
                assert_eq!(
                    fast,
                    naive(&body, &theta, obj),
                    "theta {theta:?} object {obj:?}"
                );
                catches += fast.0 as usize;
            }
        }
        assert!(catches > 500, "the test must exercise catches: {catches}");
    }

    #[test]
    fn rest_pose_no_catch() {
        for k in EnvKind::paper() {
            let env = make_env(k, &EnvConfig::default());
            let r = env.rollout(
                &[0.0; PARAMS],
                &mut crate::seed::stream(0, crate::seed::Component::Distractor),
            );
            assert!(!r.caught);
            assert!(r.hand[0].abs() < 1e-15 && (r.hand[1] - 1.0).abs() < 1e-15);
            assert_eq!(r.outcome(), env.initial_state());
        }
    }
}
