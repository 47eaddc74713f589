//! The one list of representation learners ([`LEARNERS`]). An entry names a learner, says how it
//! is shown, what its goal space offers (variants, a prior) and how its `[learners.NAME]` table
//! of a campaign file becomes a checked learner.
//!
//! Adding a learner = one module implementing [`RepresentationLearner`] (with its parameters,
//! [`ParamGuard`] and [`LearnerParams`]) + one entry here. The command line (`--algo rge-NAME`,
//! `ugl compare --learner NAME`), campaign files, the conformance suite
//! (`benchmark/tests/learner_conformance.rs`) and the report (display names, colours, the
//! paper's rows) all read this list; nothing else in the workspace names a concrete learner.
//!
//! Parameters follow linfa's `ParamGuard` pattern: the table is deserialised into *unchecked*
//! parameters (missing keys take the defaults, unknown keys are errors), [`ParamGuard::check`]
//! validates them and returns the *checked* parameters, which alone can build a learner.

use std::fmt::Debug;

use serde::de::DeserializeOwned;

use super::conv_learner::{ConvModel, ConvSection};
use super::external::ExternalConfig;
use super::isomap::IsomapConfig;
use super::neural::{Model, NeuralConfig, NeuralSection};
pub use super::params::{LearnerParamError, LearnerParams, ParamError, ParamGuard};
use super::pca::PcaConfig;
use ugl_types::learners;

/// How the harness fits a learner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// In this process, through [`RepresentationLearner::fit`].
    InProcess,
    /// A dense network trained with the model cache, checkpoints and training evidence.
    Neural(Model),
    /// One of the follow-up's convolutional networks (the same services as a dense one).
    Convolutional(ConvModel),
    /// A program outside this project (the external-learner protocol): its stderr is logged.
    External,
}

pub use ugl_types::{LearnerInfo, Prior};

/// One learner of the registry: its description (names, display name, variants, prior, the
/// paper's training: `ugl_types::LearnerInfo`, which the report reads too) and how this build
/// fits it. The description's fields read through the entry (`entry.algo`).
#[derive(Debug)]
pub struct LearnerEntry {
    pub info: &'static LearnerInfo,
    /// How it is fitted.
    pub kind: Kind,
    /// Parse and check its `[learners.NAME]` table (None: the campaign file has none).
    pub params: fn(Option<&toml::Value>) -> Result<Box<dyn LearnerParams>, ParamError>,
}

impl std::ops::Deref for LearnerEntry {
    type Target = LearnerInfo;
    fn deref(&self) -> &LearnerInfo {
        self.info
    }
}

impl LearnerEntry {
    /// The paper's training of a neural learner (docs/original-code.md section 5).
    pub fn paper_training(&self) -> Option<NeuralConfig> {
        match self.kind {
            Kind::Neural(model) => Some(NeuralConfig::paper(model)),
            _ => None,
        }
    }
}

/// Every learner of this build, in the report's order.
pub static LEARNERS: [LearnerEntry; 11] = [
    LearnerEntry {
        info: &learners::PCA,
        kind: Kind::InProcess,
        params: parse::<PcaConfig<false>>,
    },
    LearnerEntry {
        info: &learners::PCA_CENTRED,
        kind: Kind::InProcess,
        params: parse::<PcaConfig<true>>,
    },
    LearnerEntry {
        info: &learners::ISOMAP,
        kind: Kind::InProcess,
        params: parse::<IsomapConfig>,
    },
    LearnerEntry {
        info: &learners::AE,
        kind: Kind::Neural(Model::Ae),
        params: neural::<AE>,
    },
    LearnerEntry {
        info: &learners::VAE,
        kind: Kind::Neural(Model::Vae),
        params: neural::<Vae>,
    },
    LearnerEntry {
        info: &learners::RFVAE,
        kind: Kind::Neural(Model::Rfvae),
        params: neural::<Rfvae>,
    },
    LearnerEntry {
        info: &learners::BVAE,
        kind: Kind::Neural(Model::Bvae),
        params: neural::<Bvae>,
    },
    LearnerEntry {
        info: &learners::CONV_VAE,
        kind: Kind::Convolutional(ConvModel::ConvVae),
        params: convolutional::<ConvVae>,
    },
    LearnerEntry {
        info: &learners::CONV_BVAE,
        kind: Kind::Convolutional(ConvModel::ConvBvae),
        params: convolutional::<ConvBvae>,
    },
    LearnerEntry {
        info: &learners::GAUSSIAN_PROJECTION,
        kind: Kind::InProcess,
        params: parse::<super::gaussian_projection::GaussianProjectionConfig>,
    },
    LearnerEntry {
        info: &learners::EXTERNAL,
        kind: Kind::External,
        params: external,
    },
];

/// A learner of the registry: a small copyable handle ([`LEARNERS`]`[i]`), ordered as the list.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Learner(u8);

impl Learner {
    /// Every learner, in the registry's order.
    pub fn all() -> impl Iterator<Item = Learner> {
        (0..LEARNERS.len()).map(|i| Learner(i as u8))
    }

    /// The learner called `name` (`vae`).
    pub fn by_name(name: &str) -> Option<Learner> {
        Learner::all().find(|l| l.name() == name)
    }

    /// The learner whose algorithm is `algo` (`rge-vae`).
    pub fn by_algo(algo: &str) -> Option<Learner> {
        Learner::all().find(|l| l.entry().algo == algo)
    }

    /// Position in the registry.
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// The learner's registry entry.
    pub fn entry(self) -> &'static LearnerEntry {
        &LEARNERS[self.0 as usize]
    }

    /// Name in campaign files, results and on the command line (`vae`).
    pub fn name(self) -> &'static str {
        self.entry().name
    }

    /// The network of a neural learner.
    pub fn model(self) -> Option<Model> {
        match self.entry().kind {
            Kind::Neural(m) => Some(m),
            _ => None,
        }
    }

    /// The network of a convolutional learner.
    pub fn conv_model(self) -> Option<ConvModel> {
        match self.entry().kind {
            Kind::Convolutional(m) => Some(m),
            _ => None,
        }
    }

    /// Whether it is an external program.
    pub fn is_external(self) -> bool {
        self.entry().kind == Kind::External
    }

    /// Whether its runs are crossed with the variants (faithful, corrected).
    pub fn has_variants(self) -> bool {
        self.entry().has_variants
    }

    /// Whether its goal space may have a prior to sample goals from.
    pub fn may_have_prior(self) -> bool {
        self.entry().prior != Prior::None
    }
}

impl Debug for Learner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Learner({})", self.name())
    }
}

impl std::fmt::Display for Learner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The names of every learner, for error messages.
pub fn names() -> Vec<&'static str> {
    LEARNERS.iter().map(|e| e.name).collect()
}

/// Deserialise a table (absent: the defaults) into `U` and check it.
fn parse<U>(table: Option<&toml::Value>) -> Result<Box<dyn LearnerParams>, ParamError>
where
    U: DeserializeOwned + Default + ParamGuard,
    U::Checked: LearnerParams + 'static,
{
    let unchecked: U = match table {
        None => U::default(),
        Some(t) => typed(t)?,
    };
    Ok(Box::new(unchecked.check()?))
}

/// The model of a neural entry, as a type (the registry's entries are `fn` pointers).
trait ModelOf {
    const MODEL: Model;
}
struct AE;
struct Vae;
struct Rfvae;
struct Bvae;
impl ModelOf for Bvae {
    const MODEL: Model = Model::Bvae;
}
impl ModelOf for AE {
    const MODEL: Model = Model::Ae;
}
impl ModelOf for Vae {
    const MODEL: Model = Model::Vae;
}
impl ModelOf for Rfvae {
    const MODEL: Model = Model::Rfvae;
}

fn neural<M: ModelOf>(table: Option<&toml::Value>) -> Result<Box<dyn LearnerParams>, ParamError> {
    let section: NeuralSection = match table {
        None => NeuralSection::default(),
        Some(t) => typed(t)?,
    };
    Ok(Box::new((M::MODEL, section).check()?))
}

/// The network of a convolutional entry, as a type.
trait ConvModelOf {
    const MODEL: ConvModel;
}
struct ConvVae;
struct ConvBvae;
impl ConvModelOf for ConvVae {
    const MODEL: ConvModel = ConvModel::ConvVae;
}
impl ConvModelOf for ConvBvae {
    const MODEL: ConvModel = ConvModel::ConvBvae;
}

fn convolutional<M: ConvModelOf>(
    table: Option<&toml::Value>,
) -> Result<Box<dyn LearnerParams>, ParamError> {
    let section: ConvSection = match table {
        None => ConvSection::default(),
        Some(t) => typed(t)?,
    };
    Ok(Box::new((M::MODEL, section).check()?))
}

fn external(table: Option<&toml::Value>) -> Result<Box<dyn LearnerParams>, ParamError> {
    let Some(t) = table else {
        return Err(ParamError::table(
            "there is no [learners.external] section (name, command)",
        ));
    };
    let unchecked: ExternalConfig = typed(t)?;
    Ok(Box::new(unchecked.check()?))
}

/// A `[learners.NAME]` table as `U`; the error names the key that does not deserialise (its
/// path inside the table, as `serde_path_to_error` tracks it).
fn typed<U: DeserializeOwned>(t: &toml::Value) -> Result<U, ParamError> {
    serde_path_to_error::deserialize(t.clone()).map_err(|e| {
        let key = e.path().to_string();
        let message = one_line(e.inner());
        if key.is_empty() || key == "." {
            ParamError::table(message)
        } else {
            ParamError::at(key, message)
        }
    })
}

fn one_line(e: &toml::de::Error) -> String {
    e.message()
        .lines()
        .next()
        .unwrap_or_default()
        .trim()
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shared description (`ugl_types::LEARNERS`) is this build's registry, in the same
    /// order, and its paper training is what the neural learners train with by default.
    #[test]
    fn the_shared_description_is_the_registry() {
        assert_eq!(LEARNERS.len(), ugl_types::LEARNERS.len());
        for (e, info) in LEARNERS.iter().zip(ugl_types::LEARNERS) {
            assert!(std::ptr::eq(e.info, info), "{}", e.name);
            assert_eq!(
                e.info.is_neural(),
                matches!(e.kind, Kind::Neural(_)),
                "{}",
                e.name
            );
            if let Kind::Neural(model) = e.kind {
                let ours = NeuralConfig::paper(model);
                let shared = e.info.paper_training.unwrap();
                assert_eq!(ours.iterations, shared.iterations, "{}", e.name);
                assert_eq!(ours.hidden, shared.hidden, "{}", e.name);
                assert_eq!(ours.batch, shared.batch, "{}", e.name);
                assert_eq!(ours.lr, shared.lr, "{}", e.name);
                assert_eq!(ours.code_at(model, 0).warmup, shared.warmup, "{}", e.name);
                let opt = format!("{:?}", model.spec().optimiser());
                assert_eq!(opt, shared.optimiser, "{}", e.name);
            }
        }
    }

    #[test]
    fn names_are_unique_and_algos_are_rge_name() {
        for (i, e) in LEARNERS.iter().enumerate() {
            assert_eq!(e.algo, format!("rge-{}", e.name));
            assert!(
                LEARNERS[..i].iter().all(|o| o.name != e.name),
                "{} twice",
                e.name
            );
            assert_eq!(Learner::by_name(e.name).unwrap().entry().name, e.name);
        }
        assert!(Learner::by_name("nope").is_none());
    }

    #[test]
    fn every_entry_but_external_has_default_params() {
        for l in Learner::all() {
            let p = (l.entry().params)(None);
            assert_eq!(p.is_ok(), !l.is_external(), "{l}");
        }
    }

    /// A model's own knobs live in its file: another model's table refuses them, naming the
    /// owner; their values are checked and recorded as the model records them; and every dense
    /// network still records `warmup` (0 where it has none), so configuration hashes hold.
    #[test]
    fn model_knobs_are_owned_checked_and_recorded() {
        let params = |learner: &str, toml: &str| {
            let t: toml::Value = toml::from_str(toml).unwrap();
            (Learner::by_name(learner).unwrap().entry().params)(Some(&t))
        };
        let e = params("vae", "warmup = 5").unwrap_err();
        assert_eq!(e.key.as_deref(), Some("warmup"));
        assert!(e.to_string().contains("only the rfvae"), "{e}");
        let e = params("ae", "capacity = 5.0").unwrap_err();
        assert!(e.to_string().contains("only the bvae"), "{e}");
        let e = params("rfvae", "warmup = 0").unwrap_err();
        assert!(e.to_string().contains("at least 1"), "{e}");
        let e = params("bvae", "beta = -1").unwrap_err();
        assert_eq!(e.key.as_deref(), Some("beta"));
        let e = params("vae", "iteration = 5").unwrap_err();
        assert!(e.to_string().contains("not a key of [learners.vae]"), "{e}");
        // An integer β is recorded as the float it was before (4.0, not 4).
        let bvae = params("bvae", "beta = 4\ncapacity = 12").unwrap();
        let id = bvae.identity(None);
        assert_eq!(id["beta"], serde_json::json!(4.0));
        assert!(id["beta"].is_f64() && id["capacity"].is_f64(), "{id}");
        assert_eq!(id["warmup"], serde_json::json!(0));
        let vae = params("vae", "iterations = 10").unwrap().identity(None);
        assert_eq!(vae["warmup"], serde_json::json!(0));
        assert!(
            vae.get("beta").is_none() && vae.get("capacity").is_none(),
            "{vae}"
        );
        let rfvae = params("rfvae", "warmup = 120").unwrap().identity(None);
        assert_eq!(rfvae["warmup"], serde_json::json!(120));
    }

    #[test]
    fn unknown_keys_and_bad_values_are_named() {
        let t: toml::Value = toml::from_str("iteration = 5").unwrap();
        let e = (Learner::by_name("vae").unwrap().entry().params)(Some(&t)).unwrap_err();
        assert!(e.to_string().contains("iteration"), "{e}");
        let key = |learner: &str, toml: &str| {
            let t: toml::Value = toml::from_str(toml).unwrap();
            let e = (Learner::by_name(learner).unwrap().entry().params)(Some(&t)).unwrap_err();
            e.key
        };
        // The key is data: from the learner's check, and from serde's path for a value of the
        // wrong type (no message is parsed).
        assert_eq!(
            key("isomap", "n_neighbors = 0").as_deref(),
            Some("n_neighbors")
        );
        assert_eq!(key("ae", "warmup = 5").as_deref(), Some("warmup"));
        assert_eq!(key("vae", "lr = \"fast\"").as_deref(), Some("lr"));
        assert_eq!(
            key("vae", "hidden = [1200, \"x\"]").as_deref(),
            Some("hidden[1]")
        );
        let t: toml::Value = toml::from_str("n_iter = 5").unwrap();
        assert!((Learner::by_name("pca").unwrap().entry().params)(Some(&t)).is_err());
    }

    #[test]
    fn neural_entries_resolve_the_paper_budget() {
        let vae = Learner::by_name("vae").unwrap();
        let p = (vae.entry().params)(None).unwrap();
        let c = p
            .as_any()
            .downcast_ref::<crate::repr::neural::NeuralParams>()
            .unwrap()
            .config(Some(crate::repr::neural::Variant::Corrected));
        assert_eq!(c.iterations, 100_000);
        assert_eq!(c.variant, crate::repr::neural::Variant::Corrected);
        assert_eq!(
            vae.entry().paper_training().unwrap().iterations,
            c.iterations
        );
    }
}
