//! The paper's claims (`data/paper/claims.toml`) as testable statements, evaluated on the
//! main campaign's results with the intervals of [`crate::stats`].
//!
//! A claim compares *subject* conditions with *reference* conditions, paired on some fields (the
//! same environment, say). Each comparison is the difference `subject - reference` of the mean
//! over seeds of a statistic (final KLC, area under the KLC curve, episodes that moved the
//! object), taken per repetition (the mean over its exploration replicates: [`seed_values`]).
//! Two conditions with the same repetitions are compared with the paired t interval of the
//! per-repetition differences, others with Welch's t interval (Welch 1947); the simulations
//! of `report/src/stats/coverage.rs` show that both cover at the designs used, where the percentile
//! bootstrap does not. Fewer than two repetitions on a side, or an infinite value, give no
//! interval and an inconclusive comparison. The claim's relation is a set of differences
//! (`d < 0`, `|d| < margin`, ...): a comparison is reproduced when its whole interval lies inside
//! the set, not reproduced when it lies entirely outside, inconclusive otherwise.
//!
//! **Multiple comparisons.** A claim's verdict combines its comparisons by its [`Quantifier`].
//! Where a verdict follows from *some* of them holding or failing (a union of tests), one
//! comparison in `k` would reach it by chance far more often than the level says; there the
//! comparisons' tests are corrected with Holm's step-down procedure (Holm 1979), which keeps the
//! family-wise error of the claim's verdict at `1 − confidence`:
//!
//! | quantifier | *not reproduced* when | correction | *reproduced* when | correction |
//! |---|---|---|---|---|
//! | `all` | any comparison is not | Holm | every comparison is | none needed |
//! | `most` | at least half are not | Holm | more than half are | Holm |
//! | `any` | every comparison is not | none needed | at least one is | Holm |
//!
//! "Every comparison" is an intersection-union test: each at level α makes the whole one at
//! level α, with no correction (Berger 1982). Each comparison's test is the interval's: its
//! p-value `p` is at most α exactly when the `1 − α` interval lies outside (or inside) the set
//! ([`p_outside`], [`p_inside`]); Holm compares the `j`-th smallest of the `k` p-values with
//! `α / (k − j + 1)`. A comparison whose interval lies outside the set but does not survive the
//! correction is inconclusive, and shown so ([`Comparison::uncorrected`]).
//!
//! The file format is documented at the top of `data/paper/claims.toml`.

use std::collections::BTreeSet;
use std::path::Path;

use serde::Deserialize;

use crate::aggregate::ConditionSummary;
use crate::error::ReportError;
use crate::load::{ConditionKey, Store};
use crate::stats::{self, TInterval, area_under_curve};

/// Where the claims come from, as the report shows it.
pub enum ClaimsInput<'a> {
    /// Evaluated from this file.
    Evaluated {
        path: &'a std::path::Path,
        confidence: f64,
        margin: f64,
        /// [`Settings::target_half_width`].
        target_half_width: Option<f64>,
        /// [`Settings::validated`].
        validated: Option<&'a Validated>,
        results: &'a [ClaimResult],
    },
    /// No claims file where the report looked.
    Missing(&'a std::path::Path),
}

/// The claims file name inside the paper directory.
pub const FILE: &str = "claims.toml";

/// `claims.toml`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClaimsFile {
    pub settings: Settings,
    #[serde(rename = "claim", default)]
    pub claims: Vec<Claim>,
}

/// How every claim is evaluated.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// Level of the comparisons' intervals, in (0, 1); `1 −` it is the family-wise error of
    /// a claim's verdict.
    pub confidence: f64,
    /// Default margin of `much_less`, `at_most`, `at_least` and `similar`.
    pub margin: f64,
    /// The precision the main campaign was designed for: the median half-width of the paper's
    /// claims' KL-coverage comparisons, in nats. The report says whether the results meet it.
    #[serde(default)]
    pub target_half_width: Option<f64>,
    /// The measures of discovery that pass the validity check, on which each claim of the paper
    /// stated on the final KLC or the episodes moved is tested again (its *twin*).
    #[serde(default)]
    pub validated: Option<Validated>,
}

/// `[settings.validated]`: the statistics of the twins and their margins.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Validated {
    /// The statistics a twin is tested on (each comparison of the claim, on each of them).
    pub statistics: Vec<Statistic>,
    /// Margin per environment and statistic (`margin.armball.goal_error = 0.02`), in the
    /// statistic's units; a comparison in an environment without margins is not made.
    pub margin: std::collections::BTreeMap<String, std::collections::BTreeMap<String, f64>>,
}

impl Validated {
    /// The margin of `statistic` in `env`.
    pub fn margin(&self, env: &str, statistic: Statistic) -> Option<f64> {
        self.margin.get(env)?.get(statistic.key()).copied()
    }
}

/// One claim.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Claim {
    pub id: String,
    /// Where in the paper.
    pub source: String,
    /// The paper's words.
    pub quote: String,
    /// The testable statement, in words, matching the fields below.
    pub statement: String,
    pub statistic: Statistic,
    pub relation: Relation,
    pub subject: Selector,
    pub reference: Selector,
    /// Fields on which a reference condition must agree with the subject condition.
    #[serde(default)]
    pub pair_on: Vec<Field>,
    /// Overrides `settings.margin` for this claim.
    #[serde(default)]
    pub margin: Option<f64>,
    /// A finding of ours, not a claim of the paper (e.g. a claim re-tested on the corrected
    /// variants): listed apart, and not counted in the headline.
    #[serde(default)]
    pub ours: bool,
    /// How many comparisons must hold: `all` (the default), `most` ("for most runs") or `any`
    /// ("can be beneficial").
    #[serde(default)]
    pub quantifier: Quantifier,
    /// The margin as a fraction of each comparison's reference mean ("within 10% of"), instead
    /// of `margin`.
    #[serde(default)]
    pub relative_margin: Option<f64>,
    /// What must hold of the results for the claim to be about them at all (the follow-up's
    /// claims about a disentangled space); the verdict is shown with it.
    #[serde(default)]
    pub premise: Option<Premise>,
    /// Which of the report's generated findings this claim feeds (None: none).
    #[serde(default)]
    pub finding: Option<Finding>,
}

/// A finding of the report's *Findings* section, read from the claims marked with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Finding {
    /// Learned goal spaces against random parameter exploration.
    LearnedVsRpe,
    /// Learned goal spaces against the engineered one (the paper's main claim), per environment.
    LearnedVsEfr,
    /// Learned goal spaces against the controls (random projection, untrained twins).
    LearnedVsControls,
    /// Goals from the KDE against goals from the prior (the paper's Figure 4).
    GoalSamplers,
    /// Goals that hold the arrow's angle against goals on its position only.
    Angle,
}

/// A condition on the results that a claim presupposes, checked per network: the claim is
/// evaluated on the repetitions that meet every part given (at least one).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Premise {
    /// The repetition's network of this learner is disentangled: it has an active latent that
    /// encodes only the controllable object, one that encodes only the distractor, and none
    /// that encodes both (ArmBalls).
    #[serde(default)]
    pub disentangled: Option<String>,
    /// The repetition's network of this learner is the entangled control: its code holds both
    /// objects (the held-out k-NN R² of each object's position from the whole code), and it is
    /// not disentangled. A network that holds one object only is blind to the other, not
    /// entangled.
    #[serde(default)]
    pub entangled: Option<String>,
}

impl Premise {
    /// The premise in words, for a verdict that cannot check it.
    pub fn describe(&self) -> String {
        let parts: Vec<String> = [
            self.disentangled
                .as_ref()
                .map(|l| format!("a {l} network is disentangled")),
            self.entangled
                .as_ref()
                .map(|l| format!("a {l} network holds both objects, entangled")),
        ]
        .into_iter()
        .flatten()
        .collect();
        parts.join(" and ")
    }
}

/// A premise checked on the results.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PremiseCheck {
    /// Whether any repetition meets it.
    pub met: bool,
    /// What was counted, in words.
    pub counted: String,
    /// The repetitions that meet it, as (the condition's tag, seed): a claim with this premise
    /// compares the values of these repetitions only, in every condition. None: all of them.
    pub repetitions: Option<BTreeSet<(Option<String>, i64)>>,
}

/// `obs` restricted to the repetitions of a premise ([`PremiseCheck::repetitions`]): a
/// condition's values are those of its repetitions that meet it. The published summaries are
/// kept whole (they are not ours to select from).
struct OnRepetitions<'a> {
    obs: &'a dyn Observations,
    repetitions: &'a BTreeSet<(Option<String>, i64)>,
}

impl Observations for OnRepetitions<'_> {
    fn keys(&self) -> Vec<ConditionKey> {
        self.obs.keys()
    }

    fn values(&self, key: &ConditionKey, statistic: Statistic) -> Vec<(i64, f64)> {
        let mut v = self.obs.values(key, statistic);
        v.retain(|(seed, _)| self.repetitions.contains(&(key.tag.clone(), *seed)));
        v
    }

    fn premise(&self, premise: &Premise) -> Option<PremiseCheck> {
        self.obs.premise(premise)
    }

    fn summary(&self, key: &ConditionKey, statistic: Statistic) -> Option<stats::SampleSummary> {
        self.obs.summary(key, statistic)
    }
}

/// What a claims file is evaluated on: conditions and, per condition, the per-seed values of a
/// statistic. The main campaign is one ([`CampaignObservations`]); the follow-up's campaigns
/// are another (`crate::armballs`).
pub trait Observations {
    /// The conditions, in report order.
    fn keys(&self) -> Vec<ConditionKey>;
    /// The values of `statistic` for the condition `key`, one per repetition: `(seed, value)` in
    /// seed order, the value the mean over the repetition's exploration replicates (empty when
    /// the statistic is not measured there).
    fn values(&self, key: &ConditionKey, statistic: Statistic) -> Vec<(i64, f64)>;
    /// Whether `premise` holds on these results (None: it cannot be checked on them).
    fn premise(&self, premise: &Premise) -> Option<PremiseCheck> {
        let _ = premise;
        None
    }
    /// A condition known only by a published summary of `statistic` (the follow-up's
    /// authors' runs: their number, mean and standard deviation), for a condition without
    /// [`Observations::values`]: a claim compares with it by Welch's interval from the
    /// summaries. None (the default): no such condition.
    fn summary(&self, key: &ConditionKey, statistic: Statistic) -> Option<stats::SampleSummary> {
        let _ = (key, statistic);
        None
    }
}

/// The conditions of one campaign, with the runs of its store.
pub struct CampaignObservations<'a> {
    pub conditions: &'a [ConditionSummary],
    pub store: &'a Store,
}

impl Observations for CampaignObservations<'_> {
    fn keys(&self) -> Vec<ConditionKey> {
        self.conditions.iter().map(|c| c.key.clone()).collect()
    }
    fn values(&self, key: &ConditionKey, statistic: Statistic) -> Vec<(i64, f64)> {
        self.conditions
            .iter()
            .find(|c| &c.key == key)
            .map(|c| seed_values(self.store, c, statistic))
            .unwrap_or_default()
    }
}

/// The main campaign's conditions and, tagged `ALGO@TAG`, those of the campaigns that vary it
/// on its repetitions (the `recipe` campaigns: `paper-untrained`'s twins are `rge-vae@untrained`,
/// ...). A claim selects a variant's conditions by the tagged name and pairs a condition with
/// its variant by [`Field::Learner`].
pub struct TaggedObservations<'a> {
    /// `(tag, conditions, the store holding their runs)`; the main campaign's tag is None.
    pub parts: Vec<(Option<String>, &'a [ConditionSummary], &'a Store)>,
}

impl Observations for TaggedObservations<'_> {
    fn keys(&self) -> Vec<ConditionKey> {
        self.parts
            .iter()
            .flat_map(|(tag, conds, _)| conds.iter().map(|c| c.key.tagged(tag.as_deref())))
            .collect()
    }
    fn values(&self, key: &ConditionKey, statistic: Statistic) -> Vec<(i64, f64)> {
        let plain = key.tagged(None);
        self.parts
            .iter()
            .filter(|(t, _, _)| *t == key.tag)
            .find_map(|(_, conds, store)| {
                let c = conds.iter().find(|c| c.key == plain)?;
                Some(seed_values(store, c, statistic))
            })
            .unwrap_or_default()
    }
}

/// How a claim's verdict follows from its comparisons' verdicts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantifier {
    /// Reproduced when every comparison is; not reproduced when any is not.
    #[default]
    All,
    /// Reproduced when more than half of the comparisons are; not reproduced when at least half
    /// are not.
    Most,
    /// Reproduced when at least one comparison is; not reproduced when every one is not.
    Any,
}

impl Quantifier {
    /// A claim's verdict from its comparisons' (none at all: inconclusive).
    pub fn combine(self, vs: &[Verdict]) -> Verdict {
        if vs.is_empty() {
            return Verdict::Inconclusive;
        }
        let n = vs.len();
        let count = |v: Verdict| vs.iter().filter(|&&x| x == v).count();
        let (yes, no) = (count(Verdict::Reproduced), count(Verdict::NotReproduced));
        match self {
            Quantifier::All => Verdict::combine(vs.iter().copied()),
            Quantifier::Most if 2 * yes > n => Verdict::Reproduced,
            Quantifier::Most if 2 * no >= n => Verdict::NotReproduced,
            Quantifier::Any if yes > 0 => Verdict::Reproduced,
            Quantifier::Any if no == n => Verdict::NotReproduced,
            _ => Verdict::Inconclusive,
        }
    }

    /// Whether a claim holds on single values (the paper's), from whether each comparison does.
    pub fn holds(self, each: &[bool]) -> bool {
        let yes = each.iter().filter(|&&h| h).count();
        match self {
            Quantifier::All => yes == each.len(),
            Quantifier::Most => 2 * yes > each.len(),
            Quantifier::Any => yes > 0,
        }
    }

    /// In words, for the report ("" for `all`).
    pub fn label(self) -> &'static str {
        match self {
            Quantifier::All => "",
            Quantifier::Most => "most comparisons",
            Quantifier::Any => "at least one comparison",
        }
    }
}

/// What is compared between conditions (one value per seed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Statistic {
    /// KL-coverage at the run's last epoch (lower is better).
    FinalKlc,
    /// Area under the KLC curve divided by the epoch span (lower is faster exploration).
    Auc,
    /// Episodes in which the object moved, at the last epoch.
    Moved,
    /// Fraction of the achievable histogram cells the outcomes reached, at the last epoch: how
    /// diverse the outcomes are (KLC also rewards moving the object often).
    Coverage,
    /// Mean distance from the origin (the centre of the disk of reachable positions) of the
    /// object's final positions in the episodes that moved it: larger is nearer the boundary.
    Boundary,
    /// KL-coverage of the outcomes of the episodes that moved the object only, at the last
    /// epoch (lower is better; [`crate::discovery`]): KLC without the repeats of the resting
    /// position.
    MovedKlc,
    /// Goal-reaching error: the mean distance from a fixed grid of test goals (spread over the
    /// achievable outcomes) to the nearest outcome reached, at the last epoch (lower is better;
    /// [`crate::discovery`]).
    GoalError,
    /// The 90th percentile of those distances (lower is better).
    GoalErrorP90,
    /// ArmBalls: the follow-up's exploration ratio of the controllable ball at the last epoch
    /// (ball cells visited, of all cells of its grid).
    BallRatio,
    /// ArmBalls, modular exploration: the share of goals drawn in the module that encodes the
    /// ball best (engineered features: the ball's module; a learned space: the module with the
    /// largest ball R² − distractor R²).
    BallModuleGoals,
}

impl Statistic {
    /// Whether a higher value is the better (or the "more") one: episodes moved, cells
    /// reached, distance from the centre, the ball's ratio and module share; KL-coverage and
    /// errors are better lower.
    pub fn higher_is_better(self) -> bool {
        matches!(
            self,
            Statistic::Moved
                | Statistic::Coverage
                | Statistic::Boundary
                | Statistic::BallRatio
                | Statistic::BallModuleGoals
        )
    }

    /// Its name in `claims.toml`.
    pub fn key(self) -> &'static str {
        match self {
            Statistic::FinalKlc => "final_klc",
            Statistic::Auc => "auc",
            Statistic::Moved => "moved",
            Statistic::Coverage => "coverage",
            Statistic::Boundary => "boundary",
            Statistic::MovedKlc => "moved_klc",
            Statistic::GoalError => "goal_error",
            Statistic::GoalErrorP90 => "goal_error_p90",
            Statistic::BallRatio => "ball_ratio",
            Statistic::BallModuleGoals => "ball_module_goals",
        }
    }

    /// Whether a claim on this statistic has a twin on the validated measures
    /// ([`Validated`]): the final KL-coverage and the episodes that moved the object, the
    /// paper's measures of what was discovered at the end. The area under the KLC curve is
    /// the paper's measure of speed, and the validated measures are recorded at the last epoch
    /// only: such a claim has no twin.
    pub fn has_twin(self) -> bool {
        matches!(self, Statistic::FinalKlc | Statistic::Moved)
    }

    /// The validity check's line that judges this statistic ([`crate::discovery::validity`]):
    /// the area under the KLC curve is judged by the final KLC's (both count repeated outcomes
    /// alike); None where the check has no line (episodes moved, distance from the centre, the
    /// follow-up's statistics).
    pub fn checked_as(self) -> Option<crate::discovery::Measure> {
        use crate::discovery::Measure;
        match self {
            Statistic::FinalKlc | Statistic::Auc => Some(Measure::FinalKlc),
            Statistic::MovedKlc => Some(Measure::MovedKlc),
            Statistic::Coverage => Some(Measure::Coverage),
            Statistic::GoalError => Some(Measure::GoalErrorMean),
            Statistic::GoalErrorP90 => Some(Measure::GoalErrorP90),
            Statistic::Moved
            | Statistic::Boundary
            | Statistic::BallRatio
            | Statistic::BallModuleGoals => None,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Statistic::FinalKlc => "final KLC",
            Statistic::Auc => "area under the KLC curve",
            Statistic::Moved => "episodes that moved the object",
            Statistic::Boundary => "mean distance of the moved object from the centre",
            Statistic::Coverage => "fraction of the achievable cells reached",
            Statistic::MovedKlc => "final KLC of the episodes that moved the object",
            Statistic::GoalError => "goal-reaching error (mean)",
            Statistic::GoalErrorP90 => "goal-reaching error (90th percentile)",
            Statistic::BallRatio => "exploration ratio of the ball",
            Statistic::BallModuleGoals => "share of goals in the ball's module",
        }
    }
}

/// The set of differences `d = subject - reference` for which a comparison holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Relation {
    /// `d < 0`.
    Less,
    /// `d > 0`.
    Greater,
    /// `d < -margin`.
    MuchLess,
    /// `d > margin`.
    MuchGreater,
    /// `d < margin`.
    AtMost,
    /// `d > -margin`.
    AtLeast,
    /// `-margin < d < margin`.
    Similar,
}

impl Relation {
    /// The open interval of differences that satisfy the relation.
    pub fn interval(self, margin: f64) -> (f64, f64) {
        match self {
            Relation::Less => (f64::NEG_INFINITY, 0.0),
            Relation::Greater => (0.0, f64::INFINITY),
            Relation::MuchLess => (f64::NEG_INFINITY, -margin),
            Relation::MuchGreater => (margin, f64::INFINITY),
            Relation::AtMost => (f64::NEG_INFINITY, margin),
            Relation::AtLeast => (-margin, f64::INFINITY),
            Relation::Similar => (-margin, margin),
        }
    }

    /// The same statement about a statistic whose better direction is the other one (a claim
    /// on the final KLC, lower is better, re-stated on the cells reached, higher is better):
    /// `less` ↔ `greater`, `much_less` ↔ `much_greater`, `at_most` ↔ `at_least`; `similar`
    /// stays.
    pub fn mirrored(self) -> Relation {
        match self {
            Relation::Less => Relation::Greater,
            Relation::Greater => Relation::Less,
            Relation::MuchLess => Relation::MuchGreater,
            Relation::MuchGreater => Relation::MuchLess,
            Relation::AtMost => Relation::AtLeast,
            Relation::AtLeast => Relation::AtMost,
            Relation::Similar => Relation::Similar,
        }
    }

    /// Its name in `claims.toml`.
    pub fn key(self) -> &'static str {
        match self {
            Relation::Less => "less",
            Relation::Greater => "greater",
            Relation::MuchLess => "much_less",
            Relation::MuchGreater => "much_greater",
            Relation::AtMost => "at_most",
            Relation::AtLeast => "at_least",
            Relation::Similar => "similar",
        }
    }

    /// The set in words, e.g. `d < 0.2`.
    pub fn describe(self, margin: f64) -> String {
        match self {
            Relation::Less => "Δ < 0".into(),
            Relation::Greater => "Δ > 0".into(),
            Relation::MuchLess => format!("Δ < −{margin}"),
            Relation::MuchGreater => format!("Δ > {margin}"),
            Relation::AtMost => format!("Δ < {margin}"),
            Relation::AtLeast => format!("Δ > −{margin}"),
            Relation::Similar => format!("|Δ| < {margin}"),
        }
    }
}

/// A field of a condition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Field {
    Env,
    Algo,
    Sampler,
    Latents,
    Variant,
    /// The learner: the algorithm without a variant campaign's tag (`rge-vae` of
    /// `rge-vae@untrained`), to pair a condition with its control.
    Learner,
}

/// A latent-size selector: a number, or `"true"` for the environment's true dimension.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum LatentsSelector {
    Size(i64),
    Named(String),
}

/// Which conditions a side of a claim covers; a missing field matches anything.
#[derive(Debug, Clone, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Selector {
    pub env: Option<Vec<String>>,
    pub algo: Option<Vec<String>>,
    pub sampler: Option<Vec<String>>,
    pub variant: Option<Vec<String>>,
    pub latents: Option<LatentsSelector>,
}

/// The true dimension of an environment's outcome space (2 for ArmBall, 3 for ArmArrow).
pub fn true_dimension(env: &str) -> Option<i64> {
    ugl_types::EnvSpec::by_name(env).map(|e| e.true_latents as i64)
}

impl Selector {
    pub fn matches(&self, key: &ConditionKey) -> bool {
        let within = |set: &Option<Vec<String>>, v: &str| {
            set.as_ref().is_none_or(|s| s.iter().any(|x| x == v))
        };
        within(&self.env, &key.env)
            && within(&self.algo, &key.tagged_algo())
            && within(&self.sampler, &key.sampler)
            && within(&self.variant, &key.variant)
            && match &self.latents {
                None => true,
                Some(LatentsSelector::Size(n)) => key.latents == *n,
                Some(LatentsSelector::Named(_)) => true_dimension(&key.env) == Some(key.latents),
            }
    }
}

fn same_on(fields: &[Field], a: &ConditionKey, b: &ConditionKey) -> bool {
    fields.iter().all(|f| match f {
        Field::Env => a.env == b.env,
        Field::Algo => a.algo == b.algo && a.tag == b.tag,
        Field::Sampler => a.sampler == b.sampler,
        Field::Latents => a.latents == b.latents,
        Field::Variant => a.variant == b.variant,
        Field::Learner => a.algo == b.algo,
    })
}

/// Reads and validates `claims.toml`: any problem is a [`ReportError::Invalid`] naming the file
/// and the claim or key.
pub fn load_claims(path: &Path) -> Result<ClaimsFile, ReportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_claims(&text, path)
}

/// [`load_claims`] on a string (`path` is only for messages).
pub fn parse_claims(text: &str, path: &Path) -> Result<ClaimsFile, ReportError> {
    let invalid = |problem: String| ReportError::Invalid {
        path: path.to_path_buf(),
        problem,
    };
    let file: ClaimsFile =
        toml::from_str(text).map_err(|e| invalid(e.to_string().trim().replace('\n', " ")))?;
    let s = &file.settings;
    if !(s.confidence > 0.0 && s.confidence < 1.0) {
        return Err(invalid(format!(
            "settings.confidence must be in (0, 1), got {}",
            s.confidence
        )));
    }
    check_margin(s.margin).map_err(|m| invalid(format!("settings.margin {m}")))?;
    if let Some(v) = &s.validated {
        if v.statistics.is_empty() {
            return Err(invalid("settings.validated.statistics is empty".into()));
        }
        if v.margin.is_empty() {
            return Err(invalid(
                "settings.validated.margin names no environment".into(),
            ));
        }
        for (env, margins) in &v.margin {
            for st in &v.statistics {
                let m = margins.get(st.key()).ok_or_else(|| {
                    invalid(format!(
                        "settings.validated.margin.{env} has no margin for `{}`",
                        st.key()
                    ))
                })?;
                check_margin(*m).map_err(|m| {
                    invalid(format!("settings.validated.margin.{env}.{} {m}", st.key()))
                })?;
            }
            if let Some(k) = margins
                .keys()
                .find(|k| !v.statistics.iter().any(|st| st.key() == k.as_str()))
            {
                return Err(invalid(format!(
                    "settings.validated.margin.{env}.{k} is not one of settings.validated.statistics"
                )));
            }
        }
    }
    let mut ids = BTreeSet::new();
    for c in &file.claims {
        if c.id.trim().is_empty() {
            return Err(invalid("a claim has an empty id".into()));
        }
        if !ids.insert(c.id.as_str()) {
            return Err(invalid(format!("claim id `{}` appears twice", c.id)));
        }
        if let Some(m) = c.margin {
            check_margin(m).map_err(|m| invalid(format!("claim `{}`: margin {m}", c.id)))?;
        }
        if let Some(p) = &c.premise {
            if p.disentangled.is_none() && p.entangled.is_none() {
                return Err(invalid(format!(
                    "claim `{}`: a premise names `disentangled` or `entangled` (a learner)",
                    c.id
                )));
            }
            if p.disentangled.is_some() && p.disentangled == p.entangled {
                return Err(invalid(format!(
                    "claim `{}`: the premise names one learner both disentangled and entangled",
                    c.id
                )));
            }
        }
        if let Some(m) = c.relative_margin {
            check_margin(m)
                .map_err(|m| invalid(format!("claim `{}`: relative_margin {m}", c.id)))?;
            if c.margin.is_some() {
                return Err(invalid(format!(
                    "claim `{}`: give `margin` or `relative_margin`, not both",
                    c.id
                )));
            }
        }
        for (side, sel) in [("subject", &c.subject), ("reference", &c.reference)] {
            if let Some(LatentsSelector::Named(n)) = &sel.latents
                && n != "true"
            {
                return Err(invalid(format!(
                    "claim `{}`: {side}.latents must be a number or \"true\", got \"{n}\"",
                    c.id
                )));
            }
            for (name, set) in [
                ("env", &sel.env),
                ("algo", &sel.algo),
                ("sampler", &sel.sampler),
                ("variant", &sel.variant),
            ] {
                if set.as_ref().is_some_and(|s| s.is_empty()) {
                    return Err(invalid(format!(
                        "claim `{}`: {side}.{name} is an empty list (it would match nothing)",
                        c.id
                    )));
                }
            }
        }
    }
    Ok(file)
}

fn check_margin(m: f64) -> Result<(), String> {
    if m.is_finite() && m >= 0.0 {
        Ok(())
    } else {
        Err(format!("must be a finite number >= 0, got {m}"))
    }
}

/// The outcome of a comparison or of a claim.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verdict {
    Reproduced,
    Inconclusive,
    NotReproduced,
}

impl Verdict {
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::Inconclusive => "inconclusive",
            Verdict::NotReproduced => "not reproduced",
        }
    }

    /// Where the interval `[lo, hi]` lies relative to the open set `(a, b)`.
    pub fn of_interval(lo: f64, hi: f64, (a, b): (f64, f64)) -> Verdict {
        if lo.is_nan() || hi.is_nan() {
            Verdict::Inconclusive
        } else if lo > a && hi < b {
            Verdict::Reproduced
        } else if hi <= a || lo >= b {
            Verdict::NotReproduced
        } else {
            Verdict::Inconclusive
        }
    }

    /// A claim's verdict from its comparisons': any not reproduced wins, then any inconclusive;
    /// no comparison at all is inconclusive.
    pub fn combine(vs: impl IntoIterator<Item = Verdict>) -> Verdict {
        vs.into_iter().max().unwrap_or(Verdict::Inconclusive)
    }
}

/// One subject condition against one reference condition.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    pub subject: ConditionKey,
    pub reference: ConditionKey,
    /// The statistic compared (the claim's, or one of the validated measures in a twin).
    pub statistic: Statistic,
    /// The relation tested (the claim's, [`Relation::mirrored`] in a twin where the
    /// statistic's better direction is the other one).
    pub relation: Relation,
    pub n_subject: usize,
    pub n_reference: usize,
    /// Whether the interval is the paired t interval over the repetitions both sides ran
    /// ([`is_paired`]); otherwise it is Welch's.
    pub paired: bool,
    pub subject_mean: f64,
    pub reference_mean: f64,
    /// `subject_mean - reference_mean`.
    pub diff: f64,
    /// Its t interval at the claims' confidence (paired or Welch's); `None` (no interval) with
    /// fewer than two seeds on a side or an infinite value.
    pub interval: Option<TInterval>,
    /// The margin of this comparison's relation (the claim's, or its `relative_margin` times
    /// the reference mean).
    pub margin: f64,
    /// Where the interval lies relative to the relation's set, before any correction for the
    /// claim's other comparisons.
    pub uncorrected: Verdict,
    /// The verdict the claim's verdict is formed from: [`Comparison::uncorrected`] where it survives
    /// Holm's correction (or needs none; see the module docs), inconclusive otherwise.
    pub verdict: Verdict,
}

impl Comparison {
    /// Bounds of the interval, if any.
    pub fn bounds(&self) -> Option<(f64, f64)> {
        self.interval.map(|i| (i.lo, i.hi))
    }

    /// Whether its estimate lies inside its relation's set (an undecided comparison then leans
    /// reproduced).
    pub fn leans_reproduced(&self) -> bool {
        let (a, b) = self.relation.interval(self.margin);
        self.diff > a && self.diff < b
    }

    /// A power statement for an undecided comparison: the repetitions per side at which its
    /// interval at family-wise level `alpha` (the `1 − alpha` interval: `alpha` is
    /// `1 − confidence`, or smaller where Holm's correction applies) would exclude the nearest
    /// boundary of `set`, if the difference and the spread stayed as observed. The half-width
    /// shrinks as `1/√n`, and is widened by the ratio of the t quantiles at `alpha` and at the
    /// interval's own level (both at the observed degrees of freedom, so the estimate errs on
    /// the large side). None without an interval or with a difference on the boundary itself.
    pub fn repetitions_to_decide(&self, (a, b): (f64, f64), alpha: f64) -> Option<f64> {
        let i = self.interval?;
        let widen = if i.se > 0.0 && i.df > 0.0 {
            stats::student_t_quantile(1.0 - alpha / 2.0, i.df)
                / stats::student_t_quantile(0.5 + i.level / 2.0, i.df)
        } else {
            1.0
        };
        let half = widen * (i.hi - i.lo) / 2.0;
        let gap = [a, b]
            .into_iter()
            .filter(|x| x.is_finite())
            .map(|x| (i.estimate - x).abs())
            .fold(f64::INFINITY, f64::min);
        if !(gap.is_finite() && gap > 0.0) {
            return None;
        }
        let n = self.n_subject.min(self.n_reference) as f64;
        Some((n * (half / gap).powi(2)).ceil().max(n))
    }
}

/// p-value of the test "the difference lies outside the open set `(a, b)`" (null: it lies
/// inside): twice the smaller one-sided p-value, `d ≥ b` or `d ≤ a`, capped at 1. It is at most
/// `α` exactly when the two-sided `1 − α` interval lies outside the set.
pub fn p_outside(i: &TInterval, (a, b): (f64, f64)) -> f64 {
    (2.0 * i.p_above(b).min(i.p_below(a))).min(1.0)
}

/// p-value of the test "the difference lies inside the open set `(a, b)`" (null: outside): twice
/// the larger one-sided p-value, `d > a` and `d < b` (an intersection-union test, as for
/// equivalence), capped at 1. It is at most `α` exactly when the `1 − α` interval lies inside.
pub fn p_inside(i: &TInterval, (a, b): (f64, f64)) -> f64 {
    (2.0 * i.p_above(a).max(i.p_below(b))).min(1.0)
}

/// Holm's step-down procedure (Holm 1979) at family-wise level `alpha`: which of the hypotheses
/// with p-values `ps` are rejected. The `j`-th smallest p-value (1-based) is compared with
/// `alpha / (k − j + 1)`; the first that fails stops the procedure (ties keep input order).
/// NaN p-values are never rejected and count in `k`.
pub fn holm(ps: &[f64], alpha: f64) -> Vec<bool> {
    let k = ps.len();
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&i, &j| ps[i].total_cmp(&ps[j]).then(i.cmp(&j)));
    let mut rejected = vec![false; k];
    for (j, &i) in order.iter().enumerate() {
        if ps[i] <= alpha / (k - j) as f64 {
            rejected[i] = true;
        } else {
            break;
        }
    }
    rejected
}

impl Quantifier {
    /// Whether this quantifier's *reproduced* and *not reproduced* verdicts are union tests
    /// (some comparisons suffice), which need Holm's correction: `(reproduced, not_reproduced)`.
    pub fn corrected(self) -> (bool, bool) {
        match self {
            Quantifier::All => (false, true),
            Quantifier::Most => (true, true),
            Quantifier::Any => (true, false),
        }
    }
}

/// Applies Holm's correction to the comparisons of one claim where its quantifier needs it
/// (module docs): sets each [`Comparison::verdict`] from [`Comparison::uncorrected`] at level
/// `alpha`, the family being the claim's comparisons that have an interval (each tested against
/// its own relation and margin).
pub fn correct(comparisons: &mut [Comparison], quantifier: Quantifier, alpha: f64) {
    let (yes_corrected, no_corrected) = quantifier.corrected();
    // The family: (index, p inside, p outside) of every comparison with an interval.
    let tested: Vec<(usize, f64, f64)> = comparisons
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            let set = c.relation.interval(c.margin);
            c.interval
                .as_ref()
                .map(|iv| (i, p_inside(iv, set), p_outside(iv, set)))
        })
        .collect();
    let yes = holm(&tested.iter().map(|t| t.1).collect::<Vec<_>>(), alpha);
    let no = holm(&tested.iter().map(|t| t.2).collect::<Vec<_>>(), alpha);
    for c in comparisons.iter_mut() {
        c.verdict = c.uncorrected;
    }
    for (t, &(i, _, _)) in tested.iter().enumerate() {
        let c = &mut comparisons[i];
        let survives = match c.uncorrected {
            Verdict::Reproduced => !yes_corrected || yes[t],
            Verdict::NotReproduced => !no_corrected || no[t],
            Verdict::Inconclusive => true,
        };
        if !survives {
            c.verdict = Verdict::Inconclusive;
        }
    }
}

/// A claim with its comparisons.
#[derive(Debug, Clone, PartialEq)]
pub struct ClaimResult {
    pub claim: Claim,
    pub margin: f64,
    pub comparisons: Vec<Comparison>,
    pub verdict: Verdict,
    /// The same claim on the paper's own reference values ([`check_on_paper`]); set by
    /// [`attach_paper_checks`].
    pub paper: Option<PaperCheck>,
    /// The claim's premise, checked on the results (None: it has none).
    pub premise: Option<PremiseCheck>,
    /// The same statement on the validated measures ([`Validated`]), for a claim of the paper
    /// whose statistic [`Statistic::has_twin`] (None otherwise, or without validated measures).
    pub twin: Option<Twin>,
}

/// A claim of the paper tested again on the validated measures: each of its comparisons on each
/// measure, with the measure's margin and the claim's relation (mirrored where the measure is
/// better higher and the claim's statistic lower, or the reverse). One family: the claim's
/// quantifier and Holm's correction run over all its comparisons on all the measures.
#[derive(Debug, Clone, PartialEq)]
pub struct Twin {
    pub comparisons: Vec<Comparison>,
    pub verdict: Verdict,
}

impl ClaimResult {
    /// The verdict on the measures that pass the validity check: the claim's own where its
    /// statistic is one of them, its twin's where it has one, None where it has neither (a claim
    /// on the speed of exploration, or without validated measures).
    pub fn validated(&self, validated: Option<&Validated>) -> Option<(Verdict, &[Comparison])> {
        if let Some(t) = &self.twin {
            return Some((t.verdict, &t.comparisons));
        }
        validated
            .is_some_and(|v| v.statistics.contains(&self.claim.statistic))
            .then_some((self.verdict, self.comparisons.as_slice()))
    }
}

/// Which way an undecided set of comparisons leans: the verdict the claim's quantifier gives when
/// each comparison is judged by where its estimate lies (inside its relation's set: it leans
/// reproduced). None without comparisons.
pub fn lean(comparisons: &[Comparison], quantifier: Quantifier) -> Option<Verdict> {
    if comparisons.is_empty() {
        return None;
    }
    let each: Vec<bool> = comparisons
        .iter()
        .map(Comparison::leans_reproduced)
        .collect();
    Some(if quantifier.holds(&each) {
        Verdict::Reproduced
    } else {
        Verdict::NotReproduced
    })
}

/// How many repetitions per condition would decide an undecided claim the way it leans
/// ([`lean`]), if every difference and spread stayed as observed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToDecide {
    /// About this many repetitions per condition.
    Repetitions(f64),
    /// A difference sits on a boundary of its set: no number of repetitions decides it.
    Never,
    /// A comparison has no interval (fewer than 2 repetitions on a side).
    Unknown,
}

/// [`ToDecide`] for a claim (or a twin) whose comparisons are `comparisons`, at family-wise
/// level `alpha`. The comparisons that must be decided are the undecided ones leaning the
/// claim's way: all of them where the verdict needs every one (leaning reproduced under `all`
/// or `most`, leaning not reproduced under `any` or `most`), the nearest one where one suffices
/// (leaning not reproduced under `all`, leaning reproduced under `any`). Each is decided at the
/// level its verdict is tested at: `alpha / k` where Holm's correction applies to that verdict
/// (Holm's first step, its strictest, with `k` the comparisons that have an interval), `alpha`
/// otherwise ([`Comparison::repetitions_to_decide`]).
pub fn to_decide(comparisons: &[Comparison], quantifier: Quantifier, alpha: f64) -> ToDecide {
    let Some(way) = lean(comparisons, quantifier) else {
        return ToDecide::Unknown;
    };
    let yes = way == Verdict::Reproduced;
    let (yes_corrected, no_corrected) = quantifier.corrected();
    let k = comparisons
        .iter()
        .filter(|c| c.interval.is_some())
        .count()
        .max(1);
    let level = if (yes && yes_corrected) || (!yes && no_corrected) {
        alpha / k as f64
    } else {
        alpha
    };
    let pending: Vec<&Comparison> = comparisons
        .iter()
        .filter(|c| c.verdict == Verdict::Inconclusive && c.leans_reproduced() == yes)
        .collect();
    let one_suffices = match quantifier {
        Quantifier::All => !yes,
        Quantifier::Any => yes,
        Quantifier::Most => false,
    };
    let mut ns = Vec::new();
    for c in pending {
        match (
            c.interval,
            c.repetitions_to_decide(c.relation.interval(c.margin), level),
        ) {
            (None, _) => return ToDecide::Unknown,
            (Some(_), None) if !one_suffices => return ToDecide::Never,
            (Some(_), None) => {}
            (Some(_), Some(n)) => ns.push(n),
        }
    }
    let pick = if one_suffices {
        ns.iter().copied().reduce(f64::min)
    } else {
        ns.iter().copied().reduce(f64::max)
    };
    match pick {
        Some(n) => ToDecide::Repetitions(n),
        None => ToDecide::Never,
    }
}

/// One comparison of a claim on the paper's own values (single runs, so no interval).
#[derive(Debug, Clone, PartialEq)]
pub struct PaperComparison {
    pub subject: ConditionKey,
    pub reference: ConditionKey,
    /// `subject - reference` of the paper's final KLC values.
    pub diff: f64,
    /// Whether `diff` lies in the claim's set.
    pub holds: bool,
}

/// A claim evaluated on the paper's reference values (`data/paper/klc_final.csv`, read from
/// its figures): do the paper's own numbers satisfy the statement we test?
#[derive(Debug, Clone, PartialEq)]
pub struct PaperCheck {
    /// The comparisons of the claim whose two conditions the paper reports.
    pub comparisons: Vec<PaperComparison>,
    /// `Some(true)`: every such comparison holds; `Some(false)`: at least one does not (the
    /// paper's own figure contradicts the statement); `None`: the paper gives no value for any
    /// comparison (another statistic, or conditions it did not run, e.g. corrected variants).
    pub holds: Option<bool>,
}

/// Evaluates `claim` on the paper's values over the conditions `keys` (each subject condition
/// against each reference condition, as [`evaluate`] pairs them). Only final-KLC claims can be
/// checked (the table holds final KLC values); corrected variants are not the paper's and are
/// skipped; a condition the paper does not report is skipped.
pub fn check_on_paper(
    claim: &Claim,
    margin: f64,
    keys: &[ConditionKey],
    paper: &crate::paper::PaperTable,
) -> PaperCheck {
    let (a, b) = claim.relation.interval(margin);
    let mut comparisons = Vec::new();
    if claim.statistic == Statistic::FinalKlc {
        let paper_value = |k: &ConditionKey| {
            (k.variant != ugl_types::Variant::CORRECTED)
                .then(|| paper.lookup(k).map(|v| v.klc))
                .flatten()
        };
        for s in keys.iter().filter(|k| claim.subject.matches(k)) {
            for r in keys
                .iter()
                .filter(|k| *k != s && claim.reference.matches(k) && same_on(&claim.pair_on, s, k))
            {
                if let (Some(x), Some(y)) = (paper_value(s), paper_value(r)) {
                    let diff = x - y;
                    comparisons.push(PaperComparison {
                        subject: s.clone(),
                        reference: r.clone(),
                        diff,
                        holds: diff > a && diff < b,
                    });
                }
            }
        }
    }
    let each: Vec<bool> = comparisons.iter().map(|c| c.holds).collect();
    let holds = (!comparisons.is_empty()).then(|| claim.quantifier.holds(&each));
    PaperCheck { comparisons, holds }
}

/// Sets [`ClaimResult::paper`] of every result, over the conditions `keys`.
pub fn attach_paper_checks(
    results: &mut [ClaimResult],
    keys: &[ConditionKey],
    paper: &crate::paper::PaperTable,
) {
    for r in results {
        r.paper = Some(check_on_paper(&r.claim, r.margin, keys, paper));
    }
}

/// The precision of the paper's claims: the median half-width of the intervals of their
/// comparisons on KL-coverage (`final_klc`, `auc`; nats), and how many comparisons have one.
/// None when no such comparison has an interval. Our own claims are left out: the target is
/// the paper's.
pub fn precision(results: &[ClaimResult]) -> Option<(f64, usize)> {
    let halves: Vec<f64> = results
        .iter()
        .filter(|r| {
            !r.claim.ours && matches!(r.claim.statistic, Statistic::FinalKlc | Statistic::Auc)
        })
        .flat_map(|r| &r.comparisons)
        .filter_map(|c| c.bounds())
        .map(|(lo, hi)| (hi - lo) / 2.0)
        .filter(|h| h.is_finite())
        .collect();
    ugl_types::median(&halves).map(|m| (m, halves.len()))
}

/// Whether two conditions' values pair up: the same repetitions (seeds), at least two. The
/// learners of a repetition share its data set and, replicate by replicate, its exploration
/// streams, so their paired differences are less spread than independent samples (the noise
/// campaign measured about half the spread); the baselines' streams are their own, and pairing
/// them by repetition is still a valid pairing of independent repetitions. Paired by design,
/// not chosen by the data: any two conditions of one campaign with the same repetitions pair.
pub fn is_paired(x: &[(i64, f64)], y: &[(i64, f64)]) -> bool {
    x.len() >= 2 && x.len() == y.len() && x.iter().zip(y).all(|(a, b)| a.0 == b.0)
}

/// The values of `statistic` per repetition of a condition: `(seed, mean over the seed's
/// exploration replicates)`, in seed order. The repetition is the unit of the analysis: each
/// has its own data set and fit, its replicates share them, so the replicates' mean is one
/// independent observation (a two-level design analysed on its cluster means, which is exact
/// for the balanced design the campaigns run).
pub fn seed_values(
    store: &Store,
    cond: &ConditionSummary,
    statistic: Statistic,
) -> Vec<(i64, f64)> {
    let runs: Vec<i64> = cond.runs.iter().map(|&i| store.runs[i].seed).collect();
    let measured: Vec<(i64, f64)> = runs
        .into_iter()
        .zip(run_values(store, cond, statistic))
        .filter_map(|(seed, v)| v.map(|v| (seed, v)))
        .collect();
    crate::aggregate::seed_means(&measured)
}

/// The values of `statistic` per repetition, without the seeds ([`seed_values`]).
pub fn values(store: &Store, cond: &ConditionSummary, statistic: Statistic) -> Vec<f64> {
    seed_values(store, cond, statistic)
        .into_iter()
        .map(|v| v.1)
        .collect()
}

/// The value of `statistic` of each run of a condition (the condition's run order; None where
/// it is not measured). Runs whose curve has no area (fewer than two points) have no `auc`.
pub fn run_values(
    store: &Store,
    cond: &ConditionSummary,
    statistic: Statistic,
) -> Vec<Option<f64>> {
    cond.runs
        .iter()
        .map(|&i| {
            let run = &store.runs[i];
            match statistic {
                Statistic::FinalKlc => Some(run.final_point().klc),
                Statistic::Moved => Some(run.final_point().n_moved as f64),
                Statistic::Coverage => Some(run.final_point().coverage),
                Statistic::MovedKlc | Statistic::GoalError | Statistic::GoalErrorP90 => {
                    let d = crate::discovery::measure_run(run).ok().flatten()?;
                    match statistic {
                        Statistic::MovedKlc => d.moved_klc,
                        Statistic::GoalError => Some(d.goal_error_mean),
                        _ => Some(d.goal_error_p90),
                    }
                }
                Statistic::Boundary => run.discovery().ok().flatten()?.moved_radius_mean,
                Statistic::Auc => {
                    let e: Vec<f64> = run.curve.iter().map(|p| p.epoch as f64).collect();
                    let v: Vec<f64> = run.curve.iter().map(|p| p.klc).collect();
                    area_under_curve(&e, &v).ok()
                }
                // Measured on the follow-up's campaigns only (`crate::armballs`).
                Statistic::BallRatio | Statistic::BallModuleGoals => None,
            }
        })
        .collect()
}

/// Evaluates every claim on the conditions of one campaign (`store` holds their runs).
pub fn evaluate(
    file: &ClaimsFile,
    conditions: &[ConditionSummary],
    store: &Store,
) -> Vec<ClaimResult> {
    evaluate_on(file, &CampaignObservations { conditions, store })
}

/// Evaluates every claim of `file` on `obs`. Each subject condition is compared with every
/// reference condition that agrees with it on `pair_on` (a side without values, or with a NaN,
/// gives no comparison); the comparisons of a claim are then corrected ([`correct`]). A claim
/// of the paper whose statistic [`Statistic::has_twin`] is evaluated again on the validated
/// measures of `settings.validated` ([`Twin`]).
pub fn evaluate_on(file: &ClaimsFile, obs: &dyn Observations) -> Vec<ClaimResult> {
    let alpha = 1.0 - file.settings.confidence;
    let keys = obs.keys();
    file.claims
        .iter()
        .map(|claim| {
            let margin = claim.margin.unwrap_or(file.settings.margin);
            let premise = claim.premise.as_ref().map(|p| {
                obs.premise(p).unwrap_or_else(|| PremiseCheck {
                    met: false,
                    counted: format!(
                        "whether {} cannot be checked on these results",
                        p.describe()
                    ),
                    repetitions: None,
                })
            });
            let restricted = premise
                .as_ref()
                .and_then(|p| p.repetitions.as_ref())
                .map(|repetitions| OnRepetitions { obs, repetitions });
            let obs: &dyn Observations = match &restricted {
                Some(r) => r,
                None => obs,
            };
            let mut comparisons = compare(
                claim,
                &keys,
                obs,
                claim.statistic,
                file.settings.confidence,
                &|_, reference_mean| {
                    Some(match claim.relative_margin {
                        Some(f) => f * reference_mean.abs(),
                        None => margin,
                    })
                },
            );
            correct(&mut comparisons, claim.quantifier, alpha);
            let verdicts: Vec<Verdict> = comparisons.iter().map(|c| c.verdict).collect();
            let twin = file
                .settings
                .validated
                .as_ref()
                .filter(|_| !claim.ours && claim.statistic.has_twin())
                .map(|v| {
                    let mut comparisons: Vec<Comparison> = v
                        .statistics
                        .iter()
                        .flat_map(|&st| {
                            compare(claim, &keys, obs, st, file.settings.confidence, &|s, _| {
                                v.margin(&s.env, st)
                            })
                        })
                        .collect();
                    correct(&mut comparisons, claim.quantifier, alpha);
                    let verdicts: Vec<Verdict> = comparisons.iter().map(|c| c.verdict).collect();
                    Twin {
                        verdict: claim.quantifier.combine(&verdicts),
                        comparisons,
                    }
                });
            ClaimResult {
                verdict: claim.quantifier.combine(&verdicts),
                claim: claim.clone(),
                margin,
                comparisons,
                paper: None,
                premise,
                twin,
            }
        })
        .collect()
}

/// A claim of the paper evaluated twice on one cell, on the repetitions both ran: with the main
/// campaign's networks and with a recipe campaign's (its conditions tagged `tag`). It answers
/// whether the training recipe changes the claim's verdict there.
#[derive(Debug, Clone)]
pub struct CellVerdict {
    /// The recipe campaign's tag.
    pub tag: String,
    /// The cell: the main campaign's condition (untagged).
    pub cell: ConditionKey,
    /// The repetitions both ran, the only ones either side is evaluated on.
    pub repetitions: Vec<i64>,
    /// The claim, its subject narrowed to the main campaign's cell.
    pub main: ClaimResult,
    /// The same claim with the recipe's condition as its subject.
    pub recipe: ClaimResult,
}

/// The claims of the paper (not ours, without a premise) whose subject covers a cell of
/// `cells` (main-campaign keys), each evaluated on that cell alone with the main campaign's
/// networks and with those of the recipe campaign tagged `tag` ([`CellVerdict`]). Both sides
/// are restricted to the repetitions both ran, so the two verdicts rest on the same data sets,
/// exploration streams and references; a claim none of whose comparisons can be made on both
/// sides (a reference that must agree with the subject on its campaign) is left out.
pub fn cell_verdicts(
    file: &ClaimsFile,
    obs: &dyn Observations,
    tag: &str,
    cells: &[ConditionKey],
) -> Vec<CellVerdict> {
    let exact = |k: &ConditionKey| Selector {
        env: Some(vec![k.env.to_string()]),
        algo: Some(vec![k.tagged_algo()]),
        sampler: Some(vec![k.sampler.to_string()]),
        variant: Some(vec![k.variant.to_string()]),
        latents: Some(LatentsSelector::Size(k.latents)),
    };
    let mut out = Vec::new();
    for cell in cells {
        let tagged = cell.tagged(Some(tag));
        let seeds = |k: &ConditionKey| -> BTreeSet<i64> {
            obs.values(k, Statistic::FinalKlc)
                .into_iter()
                .map(|v| v.0)
                .collect()
        };
        let repetitions: Vec<i64> = seeds(cell).intersection(&seeds(&tagged)).copied().collect();
        if repetitions.len() < 2 {
            continue;
        }
        let allowed: BTreeSet<(Option<String>, i64)> = repetitions
            .iter()
            .flat_map(|&s| [(None, s), (Some(tag.to_string()), s)])
            .collect();
        let restricted = OnRepetitions {
            obs,
            repetitions: &allowed,
        };
        for claim in file.claims.iter().filter(|c| {
            !c.ours && c.premise.is_none() && c.subject.matches(cell) && !c.reference.matches(cell)
        }) {
            let narrowed = |k: &ConditionKey| Claim {
                subject: exact(k),
                ..claim.clone()
            };
            let both = ClaimsFile {
                settings: file.settings.clone(),
                claims: vec![narrowed(cell), narrowed(&tagged)],
            };
            let mut results = evaluate_on(&both, &restricted).into_iter();
            let (Some(main), Some(recipe)) = (results.next(), results.next()) else {
                continue;
            };
            if main.comparisons.is_empty() || recipe.comparisons.is_empty() {
                continue;
            }
            out.push(CellVerdict {
                tag: tag.to_string(),
                cell: cell.clone(),
                repetitions: repetitions.clone(),
                main,
                recipe,
            });
        }
    }
    out
}

/// The comparisons of `claim` on `statistic` (uncorrected): the claim's relation, mirrored
/// where `statistic` is better in the other direction than the claim's own statistic. `margin`
/// gives a comparison's margin from its subject condition and its reference mean (None: the
/// comparison is not made).
fn compare(
    claim: &Claim,
    keys: &[ConditionKey],
    obs: &dyn Observations,
    statistic: Statistic,
    confidence: f64,
    margin: &dyn Fn(&ConditionKey, f64) -> Option<f64>,
) -> Vec<Comparison> {
    let relation = if statistic.higher_is_better() == claim.statistic.higher_is_better() {
        claim.relation
    } else {
        claim.relation.mirrored()
    };
    let mut comparisons = Vec::new();
    for s in keys.iter().filter(|k| claim.subject.matches(k)) {
        let sx = obs.values(s, statistic);
        for r in keys
            .iter()
            .filter(|k| *k != s && claim.reference.matches(k) && same_on(&claim.pair_on, s, k))
        {
            let sy = obs.values(r, statistic);
            let unusable = |v: &[(i64, f64)]| v.is_empty() || v.iter().any(|x| x.1.is_nan());
            let published = if sy.is_empty() {
                obs.summary(r, statistic)
            } else {
                None
            };
            if unusable(&sx) || (unusable(&sy) && published.is_none()) {
                continue;
            }
            let xs: Vec<f64> = sx.iter().map(|v| v.1).collect();
            let ys: Vec<f64> = sy.iter().map(|v| v.1).collect();
            let subject_mean = stats::mean(&xs);
            let (reference_mean, n_reference) = match published {
                Some(p) => (p.mean, p.n),
                None => (stats::mean(&ys), ys.len()),
            };
            let Some(margin) = margin(s, reference_mean) else {
                continue;
            };
            let paired = published.is_none() && is_paired(&sx, &sy);
            let interval = if let Some(p) = published {
                stats::SampleSummary::of_values(&xs)
                    .and_then(|x| stats::welch_interval_of(x, p, confidence))
                    .ok()
            } else if paired {
                let d: Vec<f64> = xs.iter().zip(&ys).map(|(x, y)| x - y).collect();
                stats::t_interval(&d, confidence).ok()
            } else {
                stats::welch_interval(&xs, &ys, confidence).ok()
            };
            let uncorrected = match interval {
                Some(i) => Verdict::of_interval(i.lo, i.hi, relation.interval(margin)),
                None => Verdict::Inconclusive,
            };
            comparisons.push(Comparison {
                subject: s.clone(),
                reference: r.clone(),
                statistic,
                relation,
                n_subject: xs.len(),
                n_reference,
                paired,
                subject_mean,
                reference_mean,
                diff: subject_mean - reference_mean,
                interval,
                margin,
                uncorrected,
                verdict: uncorrected,
            });
        }
    }
    comparisons
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Every claim of `data/paper/claims.toml` on the paper's own values
    /// (`data/paper/klc_final.csv`), over the paper's matrix: exactly these are contradicted by
    /// the paper's own figures (each checked by hand against the CSV).
    #[test]
    fn every_claim_on_the_papers_own_numbers() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper");
        let file = load_claims(&dir.join(FILE)).unwrap();
        let paper = crate::paper::load_paper(&dir).unwrap();
        assert!(!paper.values.is_empty());
        let k = |env: &str, algo: &str, sampler: &str, latents: i64, variant: &str| ConditionKey {
            env: env.into(),
            algo: algo.into(),
            sampler: sampler.into(),
            latents,
            variant: variant.into(),
            tag: None,
        };
        let mut keys = Vec::new();
        for (env, true_dim) in [("armball", 2), ("armarrow", 3)] {
            keys.push(k(env, "rpe", "none", 0, "none"));
            keys.push(k(env, "rge-efr", "uniform", 0, "none"));
            for l in [true_dim, 10] {
                for algo in ["rge-pca", "rge-isomap", "rge-ae"] {
                    keys.push(k(env, algo, "kde", l, "none"));
                }
                for algo in ["rge-vae", "rge-rfvae"] {
                    for sampler in ["kde", "gaussian"] {
                        for variant in ["faithful", "corrected"] {
                            keys.push(k(env, algo, sampler, l, variant));
                        }
                    }
                }
            }
        }
        let mut contradicted = Vec::new();
        let mut unchecked = Vec::new();
        for c in &file.claims {
            let check = check_on_paper(c, c.margin.unwrap_or(file.settings.margin), &keys, &paper);
            match check.holds {
                Some(false) => contradicted.push(c.id.as_str()),
                None => unchecked.push(c.id.as_str()),
                Some(true) => {}
            }
        }
        assert_eq!(
            contradicted,
            [
                "armball-ae-true-dim",  // AE 4.39 at 2 latents vs 4.77 at 10: |Δ| > 0.2
                "armball-pca-true-dim", // PCA 4.09 at 2 < 4.28 at 10 (claimed higher)
                "armball-true-isomap-ae-like-efr", // Isomap-2 4.33 vs EFR 4.58: |Δ| = 0.25
                "armarrow-10-beats-efr", // AE-10 7.54 > EFR 7.46
                "armarrow-true-others-not-better", // AE-3 6.82, Isomap-3 6.85 beat EFR 7.46 by > 0.2
                "vae-gaussian-vs-kde",             // ArmBall-10 Gaussian 3.84 vs KDE 4.25
            ],
            "claims the paper's own numbers contradict"
        );
        // Claims on other statistics, only on our corrected variants, or on a condition the
        // paper ran but reported no value for (RFVAE-GP), cannot be checked.
        // Our controls (untrained twins, the random projection, the position-only EFR) are
        // not in the paper.
        let paper_unchecked: Vec<&str> = unchecked
            .iter()
            .copied()
            .filter(|id| {
                !file
                    .claims
                    .iter()
                    .any(|c| c.id == *id && c.source.contains("a control of ours"))
            })
            .collect();
        assert_eq!(unchecked.len() - paper_unchecked.len(), 14);
        let unchecked = paper_unchecked;
        assert_eq!(
            unchecked,
            [
                "ugl-vs-efr-speed",         // area under the curve
                "rfvae-worse-corrected",    // our corrected variant
                "vae-moves-more",           // episodes moved
                "more-latents-more-moves",  // episodes moved
                "more-latents-boundary",    // distance from the centre
                "rpe-few-moves",            // episodes moved
                "rfvae-few-moves",          // episodes moved
                "rpe-rfvae-small-coverage", // cell coverage
                "rfvae-gp-worse",           // no RFVAE-GP value in the paper
            ]
        );
        for id in &unchecked {
            let c = file.claims.iter().find(|c| c.id == *id).unwrap();
            let no_gp_value = c.subject.sampler.as_deref() == Some(&["gaussian".to_string()])
                && c.subject.algo.as_deref() == Some(&["rge-rfvae".to_string()]);
            assert!(
                c.statistic != Statistic::FinalKlc
                    || no_gp_value
                    || c.subject
                        .variant
                        .as_ref()
                        .is_some_and(|v| v == &["corrected".to_string()]),
                "{id} should be checkable on the paper's values"
            );
        }
    }

    #[test]
    fn verdict_of_interval_against_open_sets() {
        let less = Relation::Less.interval(0.2);
        assert_eq!(Verdict::of_interval(-0.5, -0.1, less), Verdict::Reproduced);
        assert_eq!(Verdict::of_interval(0.1, 0.5, less), Verdict::NotReproduced);
        assert_eq!(Verdict::of_interval(-0.1, 0.1, less), Verdict::Inconclusive);
        // Touching the boundary is not inside the open set.
        assert_eq!(Verdict::of_interval(-0.5, 0.0, less), Verdict::Inconclusive);
        assert_eq!(Verdict::of_interval(0.0, 0.5, less), Verdict::NotReproduced);
        let sim = Relation::Similar.interval(0.2);
        assert_eq!(Verdict::of_interval(-0.1, 0.15, sim), Verdict::Reproduced);
        assert_eq!(Verdict::of_interval(0.25, 0.4, sim), Verdict::NotReproduced);
        assert_eq!(
            Verdict::of_interval(-0.4, -0.3, sim),
            Verdict::NotReproduced
        );
        assert_eq!(Verdict::of_interval(-0.3, 0.0, sim), Verdict::Inconclusive);
        let much = Relation::MuchLess.interval(0.2);
        assert_eq!(Verdict::of_interval(-0.5, -0.25, much), Verdict::Reproduced);
        assert_eq!(
            Verdict::of_interval(-0.15, -0.05, much),
            Verdict::NotReproduced
        );
        assert_eq!(
            Verdict::of_interval(f64::NAN, 0.0, much),
            Verdict::Inconclusive
        );
        assert_eq!(
            Verdict::of_interval(1.0, f64::INFINITY, Relation::AtMost.interval(0.2)),
            Verdict::NotReproduced
        );
    }

    #[test]
    fn combining_verdicts() {
        use Verdict::*;
        assert_eq!(Verdict::combine([Reproduced, Reproduced]), Reproduced);
        assert_eq!(Verdict::combine([Reproduced, Inconclusive]), Inconclusive);
        assert_eq!(
            Verdict::combine([Inconclusive, NotReproduced, Reproduced]),
            NotReproduced
        );
        assert_eq!(Verdict::combine([]), Inconclusive);
    }

    /// A key; `ALGO@TAG` is the condition `ALGO` of the campaign tagged `TAG`.
    fn key(env: &str, algo: &str, sampler: &str, latents: i64, variant: &str) -> ConditionKey {
        let (algo, tag) = match algo.split_once('@') {
            Some((a, t)) => (a, Some(t.to_string())),
            None => (algo, None),
        };
        ConditionKey {
            env: env.into(),
            algo: algo.into(),
            sampler: sampler.into(),
            latents,
            variant: variant.into(),
            tag,
        }
    }

    #[test]
    fn selectors_and_true_dimension() {
        let sel = Selector {
            algo: Some(vec!["rge-vae".into()]),
            latents: Some(LatentsSelector::Named("true".into())),
            ..Selector::default()
        };
        assert!(sel.matches(&key("armball", "rge-vae", "kde", 2, "faithful")));
        assert!(sel.matches(&key("armarrow", "rge-vae", "kde", 3, "faithful")));
        assert!(!sel.matches(&key("armarrow", "rge-vae", "kde", 2, "faithful")));
        assert!(!sel.matches(&key("armball", "rge-ae", "kde", 2, "none")));
        assert!(Selector::default().matches(&key("x", "y", "z", 0, "none")));
        let ten = Selector {
            latents: Some(LatentsSelector::Size(10)),
            ..Selector::default()
        };
        assert!(ten.matches(&key("armball", "rge-ae", "kde", 10, "none")));
        assert!(!ten.matches(&key("armball", "rge-ae", "kde", 2, "none")));
    }

    const GOOD: &str = r#"
[settings]
confidence = 0.95
margin = 0.2

[[claim]]
id = "a"
source = "s"
quote = "q"
statement = "t"
statistic = "final_klc"
relation = "less"
subject = { algo = ["rge-vae"], latents = "true" }
reference = { algo = ["rge-efr"] }
pair_on = ["env"]
"#;

    #[test]
    fn parses_the_documented_format() {
        let f = parse_claims(GOOD, Path::new("c.toml")).unwrap();
        assert_eq!(f.claims.len(), 1);
        assert_eq!(f.claims[0].relation, Relation::Less);
        assert_eq!(f.claims[0].pair_on, vec![Field::Env]);
    }

    #[test]
    fn bad_claims_files_name_the_problem() {
        let cases = [
            (GOOD.replace("0.95", "1.5"), "settings.confidence"),
            (
                GOOD.replace("margin = 0.2", "margin = 0.2\nn_boot = 100"),
                "n_boot",
            ),
            (GOOD.replace("margin = 0.2", "margin = -1.0"), "margin"),
            (GOOD.replace("\"less\"", "\"smaller\""), "smaller"),
            (GOOD.replace("\"true\"", "\"ten\""), "latents"),
            (GOOD.replace("pair_on", "pair_with"), "pair_with"),
            (GOOD.replace("\"rge-efr\"", ""), "reference.algo"),
            (
                format!("{GOOD}{}", &GOOD[GOOD.find("[[claim]]").unwrap()..]),
                "twice",
            ),
        ];
        for (text, needle) in cases {
            let err = parse_claims(&text, Path::new("c.toml"))
                .unwrap_err()
                .to_string();
            assert!(err.contains(needle), "{needle:?} not in {err}");
            assert!(err.starts_with("c.toml"), "{err}");
        }
    }

    #[test]
    fn the_committed_claims_file_is_valid() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper/claims.toml");
        let f = load_claims(&path).unwrap();
        assert!(f.claims.len() >= 10);
    }

    /// A store with one condition per `(algo, latents, final KLC per seed)`, on ArmBall; every
    /// run's curve goes linearly from ln 756 at epoch 0 to its final value at epoch 100.
    pub(crate) fn synthetic(conds: &[(&str, i64, &[f64])]) -> (Store, Vec<ConditionSummary>) {
        use crate::load::CurvePoint;
        let mut runs = Vec::new();
        for (algo, latents, finals) in conds {
            for (seed, &f) in finals.iter().enumerate() {
                let start = 756f64.ln();
                let curve = (0..=10)
                    .map(|i| CurvePoint {
                        epoch: i * 10,
                        n_outcomes: i * 10,
                        klc: start + (f - start) * i as f64 / 10.0,
                        n_moved: (100.0 * (start - f)) as i64,
                        coverage: 0.0,
                    })
                    .collect();
                let sampler = if *latents == 0 { "uniform" } else { "kde" };
                runs.push(crate::load::test_run(
                    format!("{algo}.l{latents}.s{seed}"),
                    key("armball", algo, sampler, *latents, "none"),
                    seed as i64,
                    curve,
                ));
            }
        }
        let store = Store {
            runs,
            incomplete: Vec::new(),
        };
        let conditions = crate::aggregate::aggregate(&store, &crate::paper::PaperTable::default());
        (store, conditions)
    }

    fn claim(relation: &str, subject: &str, reference: &str, pair_on: &str) -> String {
        format!(
            "[settings]\nconfidence = 0.95\nmargin = 0.2\n\n[[claim]]\n\
             id = \"c\"\nsource = \"s\"\nquote = \"q\"\nstatement = \"t\"\n\
             statistic = \"final_klc\"\nrelation = \"{relation}\"\nsubject = {subject}\n\
             reference = {reference}\npair_on = {pair_on}\n"
        )
    }

    fn verdict_of(text: &str, store: &Store, conds: &[ConditionSummary]) -> ClaimResult {
        let f = parse_claims(text, Path::new("c.toml")).unwrap();
        evaluate(&f, conds, store).remove(0)
    }

    /// The precision line: the median half-width over the paper's KL-coverage comparisons; our
    /// own claims and other statistics are left out.
    #[test]
    fn precision_is_the_median_half_width_of_the_papers_klc_comparisons() {
        let (store, conds) = synthetic(&[
            ("rge-efr", 0, &[4.5, 4.6, 4.4, 4.55, 4.45]),
            ("rge-pca", 10, &[4.0, 4.1, 3.9, 4.05, 3.95]),
            ("rge-ae", 10, &[3.0, 6.0, 3.2, 5.8, 4.5]),
            ("rge-vae", 10, &[4.0, 4.4, 3.6, 4.2, 3.8]),
        ]);
        let text = claim(
            "less",
            "{ algo = [\"rge-pca\", \"rge-ae\", \"rge-vae\"] }",
            "{ algo = [\"rge-efr\"] }",
            "[\"env\"]",
        );
        let f = parse_claims(&text, Path::new("c.toml")).unwrap();
        let mut results = evaluate(&f, &conds, &store);
        let mut halves: Vec<f64> = results[0]
            .comparisons
            .iter()
            .map(|c| c.bounds().map(|(lo, hi)| (hi - lo) / 2.0).unwrap())
            .collect();
        halves.sort_by(f64::total_cmp);
        assert_eq!(halves.len(), 3);
        assert_eq!(precision(&results), Some((halves[1], 3)));
        results[0].claim.ours = true;
        assert_eq!(precision(&results), None);
        results[0].claim.ours = false;
        results[0].claim.statistic = Statistic::Moved;
        assert_eq!(precision(&results), None);
    }

    #[test]
    fn evaluator_on_synthetic_results_with_known_verdicts() {
        let efr: &[f64] = &[4.5, 4.6, 4.4, 4.55, 4.45];
        let (store, conds) = synthetic(&[
            ("rge-efr", 0, efr),
            // Clearly better than EFR (by ~0.5).
            ("rge-pca", 10, &[4.0, 4.1, 3.9, 4.05, 3.95]),
            // Clearly worse (by ~1).
            ("rge-rfvae", 10, &[5.5, 5.6, 5.4, 5.55, 5.45]),
            // Same mean as EFR, tiny spread: similar within the margin.
            ("rge-ae", 10, &[4.5, 4.52, 4.48, 4.51, 4.49]),
            // Wild spread around EFR: no interval can decide.
            ("rge-vae", 10, &[3.0, 6.0, 3.2, 5.8, 4.5]),
            ("rge-pca", 2, &[4.0, 4.1, 3.9, 4.05, 3.95]),
        ]);
        let efr_sel = "{ algo = [\"rge-efr\"] }";
        let on_env = "[\"env\"]";
        let v = |rel: &str, algo: &str| {
            let subject = format!("{{ algo = [\"{algo}\"] }}");
            verdict_of(&claim(rel, &subject, efr_sel, on_env), &store, &conds)
        };
        assert_eq!(v("less", "rge-pca").verdict, Verdict::Reproduced);
        assert_eq!(v("much_less", "rge-pca").verdict, Verdict::Reproduced);
        assert_eq!(v("greater", "rge-pca").verdict, Verdict::NotReproduced);
        assert_eq!(v("greater", "rge-rfvae").verdict, Verdict::Reproduced);
        assert_eq!(v("at_most", "rge-rfvae").verdict, Verdict::NotReproduced);
        assert_eq!(v("similar", "rge-ae").verdict, Verdict::Reproduced);
        assert_eq!(v("similar", "rge-pca").verdict, Verdict::NotReproduced);
        assert_eq!(v("less", "rge-vae").verdict, Verdict::Inconclusive);
        assert_eq!(v("similar", "rge-vae").verdict, Verdict::Inconclusive);
        // PCA has two conditions (2 and 10 latents): two comparisons, both reproduced.
        let r = v("less", "rge-pca");
        assert_eq!(r.comparisons.len(), 2);
        assert!((r.comparisons[0].diff - -0.5).abs() < 1e-9);
        assert_eq!(
            (r.comparisons[0].n_subject, r.comparisons[0].n_reference),
            (5, 5)
        );
        // One failing comparison among passing ones makes the claim not reproduced.
        let any = "{ algo = [\"rge-pca\", \"rge-rfvae\"] }";
        let r = verdict_of(&claim("less", any, efr_sel, on_env), &store, &conds);
        assert_eq!(r.verdict, Verdict::NotReproduced);
        // Pairing on latents: PCA 10 against PCA 2, identical values, similar.
        let r = verdict_of(
            &claim(
                "similar",
                "{ algo = [\"rge-pca\"], latents = 10 }",
                "{ latents = \"true\" }",
                "[\"env\", \"algo\", \"sampler\", \"variant\"]",
            ),
            &store,
            &conds,
        );
        assert_eq!(r.comparisons.len(), 1);
        assert_eq!(r.comparisons[0].reference.latents, 2);
        assert_eq!(r.verdict, Verdict::Reproduced);
        // Nothing matches: inconclusive, with no comparison.
        let r = verdict_of(
            &claim("less", "{ algo = [\"rge-nothing\"] }", efr_sel, on_env),
            &store,
            &conds,
        );
        assert!(r.comparisons.is_empty());
        assert_eq!(r.verdict, Verdict::Inconclusive);
        // Same inputs, same result (no resampling).
        assert_eq!(v("less", "rge-vae"), v("less", "rge-vae"));
    }

    #[test]
    fn holm_step_down_known_case() {
        // Sorted: 0.005 <= 0.05/4, 0.01 <= 0.05/3, 0.03 > 0.05/2: stop.
        assert_eq!(
            holm(&[0.01, 0.04, 0.03, 0.005], 0.05),
            vec![true, false, false, true]
        );
        // One hypothesis: the uncorrected test.
        assert_eq!(holm(&[0.05], 0.05), vec![true]);
        assert_eq!(holm(&[0.02, 0.04], 0.05), vec![true, true]);
        assert_eq!(holm(&[f64::NAN, 0.001], 0.05), vec![false, true]);
        assert!(holm(&[], 0.05).is_empty());
    }

    #[test]
    fn p_values_agree_with_the_interval() {
        let i =
            stats::welch_interval(&[1.0, 1.4, 1.2, 1.5], &[0.2, 0.5, 0.1, 0.3, 0.4], 0.95).unwrap();
        // The 95% interval's bounds are where the tests' p-values reach 0.05.
        assert!((p_outside(&i, (f64::NEG_INFINITY, i.lo)) - 0.05).abs() < 1e-9);
        assert!((p_inside(&i, (i.lo, f64::INFINITY)) - 0.05).abs() < 1e-9);
        assert!((p_inside(&i, (i.lo, i.hi + 1.0)) - 0.05).abs() < 1e-9);
        assert_eq!(p_outside(&i, (f64::NEG_INFINITY, f64::INFINITY)), 1.0);
    }

    /// A constructed case: one of three comparisons has its 95% interval just above 0 (p ≈ 0.03)
    /// and the other two are undecided. Uncorrected, "every subject is lower than RGE-EFR"
    /// would be *not reproduced*; Holm's threshold for the smallest of three p-values is
    /// 0.05 / 3, so it is inconclusive. Alone, the same comparison decides.
    #[test]
    fn holm_correction_changes_a_verdict() {
        let efr: &[f64] = &[4.5, 4.6, 4.4, 4.55, 4.45];
        // Paired (same seeds): the differences 0.13, 0.03, 0.23, 0.08, 0.18 (t = 3.68, 4 df).
        let shifted: Vec<f64> = efr
            .iter()
            .zip([0.13, 0.03, 0.23, 0.08, 0.18])
            .map(|(v, d)| v + d)
            .collect();
        let (store, conds) = synthetic(&[
            ("rge-efr", 0, efr),
            ("rge-pca", 10, &shifted),
            ("rge-ae", 10, &[4.3, 4.7, 4.5, 4.6, 4.4]),
            ("rge-isomap", 10, &[4.35, 4.65, 4.5, 4.55, 4.45]),
        ]);
        let efr_sel = "{ algo = [\"rge-efr\"] }";
        let three = "{ algo = [\"rge-pca\", \"rge-ae\", \"rge-isomap\"] }";
        let r = verdict_of(&claim("less", three, efr_sel, "[\"env\"]"), &store, &conds);
        assert_eq!(r.comparisons.len(), 3);
        let pca = r
            .comparisons
            .iter()
            .find(|c| c.subject.algo == "rge-pca")
            .unwrap();
        let (lo, _) = pca.bounds().unwrap();
        assert!(lo > 0.0, "the interval lies above 0: {lo}");
        let p = p_outside(pca.interval.as_ref().unwrap(), Relation::Less.interval(0.2));
        assert!(p > 0.05 / 3.0 && p < 0.05, "p = {p}");
        assert_eq!(pca.uncorrected, Verdict::NotReproduced);
        assert_eq!(pca.verdict, Verdict::Inconclusive);
        let uncorrected: Vec<Verdict> = r.comparisons.iter().map(|c| c.uncorrected).collect();
        assert_eq!(
            Quantifier::All.combine(&uncorrected),
            Verdict::NotReproduced
        );
        assert_eq!(r.verdict, Verdict::Inconclusive);
        // The same comparison alone: one test, nothing to correct.
        let one = "{ algo = [\"rge-pca\"] }";
        let r = verdict_of(&claim("less", one, efr_sel, "[\"env\"]"), &store, &conds);
        assert_eq!(r.verdict, Verdict::NotReproduced);
    }

    /// Which direction is corrected follows the quantifier: "any" corrects *reproduced* (one
    /// success of k is a union test) but not *not reproduced* (all k must fail).
    #[test]
    fn correction_follows_the_quantifier() {
        let iv = |estimate: f64| TInterval {
            estimate,
            se: 0.2,
            df: 8.0,
            level: 0.95,
            lo: estimate - 2.306_004_135_204 * 0.2,
            hi: estimate + 2.306_004_135_204 * 0.2,
        };
        let k = |algo: &str| key("armball", algo, "kde", 10, "none");
        let comparison = |algo: &str, estimate: f64| {
            let i = iv(estimate);
            let v = Verdict::of_interval(i.lo, i.hi, Relation::Less.interval(0.2));
            Comparison {
                subject: k(algo),
                reference: k("rge-efr"),
                statistic: Statistic::FinalKlc,
                relation: Relation::Less,
                n_subject: 5,
                n_reference: 5,
                paired: false,
                subject_mean: 0.0,
                reference_mean: 0.0,
                diff: estimate,
                interval: Some(i),
                margin: 0.2,
                uncorrected: v,
                verdict: v,
            }
        };
        // Δ = −0.5 with se 0.2: below 0 with p ≈ 0.037; the others undecided.
        let mut cs = vec![
            comparison("a", -0.5),
            comparison("b", 0.0),
            comparison("c", 0.05),
        ];
        assert_eq!(cs[0].uncorrected, Verdict::Reproduced);
        correct(&mut cs, Quantifier::All, 0.05);
        assert_eq!(
            cs[0].verdict,
            Verdict::Reproduced,
            "all: reproduced needs every one"
        );
        correct(&mut cs, Quantifier::Any, 0.05);
        assert_eq!(
            cs[0].verdict,
            Verdict::Inconclusive,
            "any: one of three is a union"
        );
        // Every comparison fails: "any" is not reproduced without correction.
        let mut fail = vec![comparison("a", 0.5), comparison("b", 0.5)];
        correct(&mut fail, Quantifier::Any, 0.05);
        assert!(fail.iter().all(|c| c.verdict == Verdict::NotReproduced));
        let vs: Vec<Verdict> = fail.iter().map(|c| c.verdict).collect();
        assert_eq!(Quantifier::Any.combine(&vs), Verdict::NotReproduced);
        // ...while "all" corrects them (two at p ≈ 0.037 > 0.05 / 2 for the first).
        correct(&mut fail, Quantifier::All, 0.05);
        assert!(fail.iter().all(|c| c.verdict == Verdict::Inconclusive));
    }

    #[test]
    fn one_seed_on_a_side_gives_no_interval() {
        let (store, conds) =
            synthetic(&[("rge-efr", 0, &[4.5, 4.6, 4.4]), ("rge-pca", 10, &[3.0])]);
        let r = verdict_of(
            &claim(
                "less",
                "{ algo = [\"rge-pca\"] }",
                "{ algo = [\"rge-efr\"] }",
                "[\"env\"]",
            ),
            &store,
            &conds,
        );
        assert_eq!(r.comparisons.len(), 1);
        assert_eq!(r.comparisons[0].interval, None);
        assert!((r.comparisons[0].diff - -1.5).abs() < 1e-12);
        assert_eq!(r.verdict, Verdict::Inconclusive);
    }

    #[test]
    fn quantifiers_weaken_all_where_the_paper_does() {
        use Verdict::{Inconclusive, NotReproduced, Reproduced};
        let mixed = [Reproduced, NotReproduced, Inconclusive];
        assert_eq!(Quantifier::All.combine(&mixed), NotReproduced);
        assert_eq!(Quantifier::Any.combine(&mixed), Reproduced);
        assert_eq!(Quantifier::Most.combine(&mixed), Inconclusive);
        assert_eq!(
            Quantifier::Most.combine(&[Reproduced, Reproduced, NotReproduced]),
            Reproduced
        );
        assert_eq!(
            Quantifier::Most.combine(&[Reproduced, NotReproduced]),
            NotReproduced
        );
        assert_eq!(
            Quantifier::Any.combine(&[NotReproduced, NotReproduced]),
            NotReproduced
        );
        assert_eq!(
            Quantifier::Any.combine(&[NotReproduced, Inconclusive]),
            Inconclusive
        );
        for q in [Quantifier::All, Quantifier::Most, Quantifier::Any] {
            assert_eq!(q.combine(&[]), Inconclusive);
        }
        assert!(Quantifier::Any.holds(&[false, true]));
        assert!(!Quantifier::All.holds(&[false, true]));
        assert!(!Quantifier::Most.holds(&[false, true]));
        assert!(Quantifier::Most.holds(&[true, true, false]));
    }

    #[test]
    fn boundary_is_the_mean_distance_of_the_moved_outcomes() {
        use crate::load::Outcome;
        let (mut store, conds) = synthetic(&[("rge-efr", 0, &[4.5])]);
        let o = |x: f64, y: f64, moved: bool| Outcome {
            index: 0,
            epoch: 1,
            x,
            y,
            angle: None,
            moved,
        };
        store.runs[0].outcomes = vec![o(0.6, 0.6, false), o(0.3, 0.4, true), o(0.0, -1.0, true)];
        let efr = &conds[0];
        assert_eq!(values(&store, efr, Statistic::Boundary), vec![0.75]);
        // A run that never moved the object has no value (its measures computed again: a
        // run's are computed once, from the outcomes it was loaded with).
        store.runs[0].outcomes.truncate(1);
        store.runs[0].measured = Default::default();
        assert!(values(&store, efr, Statistic::Boundary).is_empty());
    }

    #[test]
    fn auc_and_moved_statistics() {
        let (store, conds) =
            synthetic(&[("rge-efr", 0, &[4.5, 4.6]), ("rge-pca", 10, &[4.0, 4.1])]);
        let efr = conds.iter().find(|c| c.key.algo == "rge-efr").unwrap();
        // A linear ramp from ln 756 to f has area (ln 756 + f) / 2.
        let auc = values(&store, efr, Statistic::Auc);
        assert!((auc[0] - (756f64.ln() + 4.5) / 2.0).abs() < 1e-9);
        assert_eq!(values(&store, efr, Statistic::FinalKlc), vec![4.5, 4.6]);
        assert_eq!(
            values(&store, efr, Statistic::Moved),
            vec![
                (100.0 * (756f64.ln() - 4.5)) as i64 as f64,
                (100.0 * (756f64.ln() - 4.6)) as i64 as f64
            ]
        );
    }

    /// Observations given directly: per condition and statistic, values per repetition.
    struct Given(Vec<(ConditionKey, Statistic, Vec<f64>)>);

    impl Observations for Given {
        fn keys(&self) -> Vec<ConditionKey> {
            let mut keys: Vec<ConditionKey> = Vec::new();
            for (k, _, _) in &self.0 {
                if !keys.contains(k) {
                    keys.push(k.clone());
                }
            }
            keys
        }
        fn values(&self, key: &ConditionKey, statistic: Statistic) -> Vec<(i64, f64)> {
            self.0
                .iter()
                .find(|(k, s, _)| k == key && *s == statistic)
                .map(|(_, _, v)| v.iter().enumerate().map(|(i, &x)| (i as i64, x)).collect())
                .unwrap_or_default()
        }
    }

    const VALIDATED: &str = "[settings.validated]\nstatistics = [\"goal_error\", \"coverage\"]\n\
        [settings.validated.margin.armball]\ngoal_error = 0.02\ncoverage = 0.05\n";

    /// A claim file with the validated measures, one claim `c` (`ours` optional).
    fn twin_file(statistic: &str, relation: &str, ours: bool) -> ClaimsFile {
        let text = format!(
            "[settings]\nconfidence = 0.95\nmargin = 0.2\n{VALIDATED}\n[[claim]]\nid = \"c\"\n\
             source = \"s\"\nquote = \"q\"\nstatement = \"t\"\nstatistic = \"{statistic}\"\n\
             relation = \"{relation}\"\nours = {ours}\n\
             subject = {{ algo = [\"rge-pca\"] }}\nreference = {{ algo = [\"rge-efr\"] }}\n\
             pair_on = [\"env\"]\n"
        );
        parse_claims(&text, Path::new("c.toml")).unwrap()
    }

    /// RGE-PCA against RGE-EFR on ArmBall (and ArmArrow, which has no validated margins): PCA's
    /// final KLC is better; its goal error and cells reached are as given.
    fn pca_vs_efr(goal: [f64; 2], cells: [f64; 2]) -> Given {
        let jitter = [0.0, 0.004, -0.004, 0.002, -0.002, 0.001];
        let around = |m: f64| -> Vec<f64> { jitter.iter().map(|j| m + j).collect() };
        let mut v = Vec::new();
        for env in ["armball", "armarrow"] {
            let pca = key(env, "rge-pca", "kde", 10, "none");
            let efr = key(env, "rge-efr", "uniform", 0, "none");
            v.push((pca.clone(), Statistic::FinalKlc, around(4.0)));
            v.push((efr.clone(), Statistic::FinalKlc, around(4.5)));
            v.push((pca.clone(), Statistic::GoalError, around(goal[0])));
            v.push((efr.clone(), Statistic::GoalError, around(goal[1])));
            v.push((pca, Statistic::Coverage, around(cells[0])));
            v.push((efr, Statistic::Coverage, around(cells[1])));
        }
        Given(v)
    }

    /// The twin of a final-KLC claim on known data, in both directions: a learner better on
    /// KL-coverage but worse on the validated measures is reproduced on the one and not on the
    /// other; one as good on them is reproduced on both. The relation is mirrored for the
    /// cells reached (higher is better), and an environment without margins gives no comparison.
    #[test]
    fn twins_on_the_validated_measures_in_both_directions() {
        let file = twin_file("final_klc", "at_most", false);
        // Worse: goal error 0.10 vs 0.05 (margin 0.02), cells 0.30 vs 0.55 (margin 0.05).
        let r = evaluate_on(&file, &pca_vs_efr([0.10, 0.05], [0.30, 0.55])).remove(0);
        assert_eq!(r.verdict, Verdict::Reproduced, "final KLC: 4.0 vs 4.5");
        assert_eq!(
            r.comparisons.len(),
            2,
            "both environments on the claim's statistic"
        );
        let t = r
            .twin
            .as_ref()
            .expect("a paper claim on final_klc has a twin");
        assert_eq!(t.verdict, Verdict::NotReproduced);
        assert_eq!(
            t.comparisons.len(),
            2,
            "ArmBall only (ArmArrow has no margins)"
        );
        assert!(t.comparisons.iter().all(|c| c.subject.env == "armball"));
        let by = |st: Statistic| t.comparisons.iter().find(|c| c.statistic == st).unwrap();
        assert_eq!(by(Statistic::GoalError).relation, Relation::AtMost);
        assert_eq!(by(Statistic::Coverage).relation, Relation::AtLeast);
        assert_eq!(by(Statistic::GoalError).margin, 0.02);
        assert_eq!(by(Statistic::Coverage).margin, 0.05);
        assert!(
            t.comparisons
                .iter()
                .all(|c| c.verdict == Verdict::NotReproduced)
        );
        assert_eq!(
            r.validated(file.settings.validated.as_ref()).unwrap().0,
            Verdict::NotReproduced
        );
        // As good: within the margins on both measures.
        let r = evaluate_on(&file, &pca_vs_efr([0.055, 0.05], [0.54, 0.55])).remove(0);
        assert_eq!(r.twin.as_ref().unwrap().verdict, Verdict::Reproduced);
        // Better on cells by a lot: `at_least` holds (mirrored), goal error too.
        let r = evaluate_on(&file, &pca_vs_efr([0.03, 0.05], [0.80, 0.55])).remove(0);
        assert_eq!(r.twin.as_ref().unwrap().verdict, Verdict::Reproduced);
        // `much_less` on KLC becomes `much_greater` on cells: 0.80 vs 0.55 by more than 0.05.
        let much = twin_file("final_klc", "much_less", false);
        let r = evaluate_on(&much, &pca_vs_efr([0.035, 0.05], [0.80, 0.55])).remove(0);
        let t = r.twin.unwrap();
        let cells = t
            .comparisons
            .iter()
            .find(|c| c.statistic == Statistic::Coverage)
            .unwrap();
        assert_eq!(cells.relation, Relation::MuchGreater);
        assert_eq!(cells.verdict, Verdict::Reproduced);
        // Goal error 0.035 vs 0.05 is lower, but not by more than the 0.02 margin.
        let goal = t
            .comparisons
            .iter()
            .find(|c| c.statistic == Statistic::GoalError)
            .unwrap();
        assert_eq!(goal.verdict, Verdict::NotReproduced);
        assert_eq!(t.verdict, Verdict::NotReproduced);
    }

    /// A paper claim evaluated on one cell with the main campaign's networks and with a recipe
    /// campaign's: both on the repetitions both ran (paired with the reference's), each with its
    /// own verdicts; a claim of ours is not evaluated there.
    #[test]
    fn a_claim_on_one_cell_with_either_network() {
        let file = twin_file("final_klc", "at_most", false);
        // The main networks are worse than EFR on the validated measures, the recipe's as good.
        let mut given = pca_vs_efr([0.10, 0.05], [0.30, 0.55]).0;
        let pca = key("armball", "rge-pca", "kde", 10, "none");
        let long = pca.tagged(Some("long"));
        let near = |m: f64| vec![m, m + 0.003, m - 0.002, m + 0.001];
        given.push((long.clone(), Statistic::FinalKlc, near(4.0)));
        given.push((long.clone(), Statistic::GoalError, near(0.05)));
        given.push((long, Statistic::Coverage, near(0.55)));
        let obs = Given(given);
        let v = cell_verdicts(&file, &obs, "long", std::slice::from_ref(&pca));
        assert_eq!(v.len(), 1, "one claim on one cell");
        let v = &v[0];
        assert_eq!(v.repetitions, vec![0, 1, 2, 3], "the recipe ran 4 of the 6");
        assert_eq!((v.tag.as_str(), &v.cell), ("long", &pca));
        for r in [&v.main, &v.recipe] {
            let t = r.twin.as_ref().unwrap();
            for c in r.comparisons.iter().chain(&t.comparisons) {
                assert_eq!(
                    (c.n_subject, c.n_reference, c.paired),
                    (4, 4, true),
                    "{c:?}"
                );
                assert_eq!(c.subject.env, "armball");
                assert_eq!(c.reference.algo, "rge-efr");
            }
        }
        assert_eq!(v.main.comparisons[0].subject.tag, None);
        assert_eq!(v.recipe.comparisons[0].subject.tag.as_deref(), Some("long"));
        assert_eq!(
            v.main.twin.as_ref().unwrap().verdict,
            Verdict::NotReproduced
        );
        assert_eq!(v.recipe.twin.as_ref().unwrap().verdict, Verdict::Reproduced);
        // A claim of ours is left out; so is a cell the recipe did not run twice.
        assert!(
            cell_verdicts(
                &twin_file("final_klc", "at_most", true),
                &obs,
                "long",
                std::slice::from_ref(&pca)
            )
            .is_empty()
        );
        assert!(cell_verdicts(&file, &obs, "other", &[pca]).is_empty());
    }

    /// Which claims get a twin: the paper's, on final KLC or episodes moved; not ours, not the
    /// speed of exploration; a claim on a validated measure is its own validated verdict.
    #[test]
    fn only_the_papers_klc_and_moves_claims_have_twins() {
        let data = pca_vs_efr([0.10, 0.05], [0.30, 0.55]);
        assert!(
            evaluate_on(&twin_file("final_klc", "at_most", true), &data)[0]
                .twin
                .is_none()
        );
        let auc = twin_file("auc", "at_most", false);
        let r = evaluate_on(&auc, &data).remove(0);
        assert!(r.twin.is_none());
        assert!(r.validated(auc.settings.validated.as_ref()).is_none());
        let goal = twin_file("goal_error", "at_most", false);
        let r = evaluate_on(&goal, &data).remove(0);
        assert!(r.twin.is_none());
        assert_eq!(
            r.validated(goal.settings.validated.as_ref()).unwrap().0,
            r.verdict,
            "a claim on a validated measure is its own validated verdict"
        );
    }

    #[test]
    fn bad_validated_settings_name_the_problem() {
        let err = |validated: &str| {
            let text = format!("[settings]\nconfidence = 0.95\nmargin = 0.2\n{validated}");
            parse_claims(&text, Path::new("c.toml"))
                .unwrap_err()
                .to_string()
        };
        let missing = err(
            "[settings.validated]\nstatistics = [\"goal_error\", \"coverage\"]\n\
             [settings.validated.margin.armball]\ngoal_error = 0.02\n",
        );
        assert!(
            missing.contains("settings.validated.margin.armball has no margin for `coverage`"),
            "{missing}"
        );
        let extra = err("[settings.validated]\nstatistics = [\"goal_error\"]\n\
             [settings.validated.margin.armball]\ngoal_error = 0.02\ncoverage = 0.05\n");
        assert!(extra.contains("armball.coverage is not one of"), "{extra}");
        let negative = err("[settings.validated]\nstatistics = [\"goal_error\"]\n\
             [settings.validated.margin.armball]\ngoal_error = -1\n");
        assert!(
            negative.contains("must be a finite number >= 0"),
            "{negative}"
        );
        let unknown = err("[settings.validated]\nstatistics = [\"goal_eror\"]\nmargin = {}\n");
        assert!(unknown.contains("goal_eror"), "{unknown}");
    }

    /// An undecided comparison of known interval: its lean and the repetitions that would decide
    /// it, at the claim's level and at Holm's first step.
    fn undecided(estimate: f64, se: f64, relation: Relation) -> Comparison {
        // A hand-made interval: estimate ± t(9) se.
        let t9 = crate::stats::student_t_quantile(0.975, 9.0);
        let i = TInterval {
            estimate,
            se,
            df: 9.0,
            level: 0.95,
            lo: estimate - t9 * se,
            hi: estimate + t9 * se,
        };
        let v = Verdict::of_interval(i.lo, i.hi, relation.interval(0.2));
        Comparison {
            subject: key("armball", "rge-pca", "kde", 10, "none"),
            reference: key("armball", "rge-efr", "uniform", 0, "none"),
            statistic: Statistic::FinalKlc,
            relation,
            n_subject: 10,
            n_reference: 10,
            paired: true,
            subject_mean: estimate,
            reference_mean: 0.0,
            diff: estimate,
            interval: Some(i),
            margin: 0.2,
            uncorrected: v,
            verdict: v,
        }
    }

    #[test]
    fn undecided_claims_lean_and_say_how_many_repetitions_would_decide_them() {
        let t9 = crate::stats::student_t_quantile(0.975, 9.0);
        // Δ = 0.1 on `less`: outside the set, half-width 0.2 → leans not reproduced; at the
        // same level it would clear 0 at 10 · (0.2 / 0.1)² = 40 repetitions.
        let c = undecided(0.1, 0.2 / t9, Relation::Less);
        assert_eq!(c.verdict, Verdict::Inconclusive);
        assert!(!c.leans_reproduced());
        assert_eq!(
            c.repetitions_to_decide(Relation::Less.interval(0.2), 0.05),
            Some(40.0)
        );
        // Holm's first step at k = 2 asks for a wider interval: more repetitions.
        let holm = c
            .repetitions_to_decide(Relation::Less.interval(0.2), 0.025)
            .unwrap();
        let widen = crate::stats::student_t_quantile(0.9875, 9.0) / t9;
        assert_eq!(holm, (40.0 * widen * widen).ceil());
        // One comparison leaning each way under `all`: the claim leans not reproduced, and one
        // failing comparison suffices, decided at Holm's α / 2.
        let yes = undecided(-0.05, 0.2 / t9, Relation::Less);
        assert!(yes.leans_reproduced());
        let pair = [yes.clone(), c.clone()];
        assert_eq!(lean(&pair, Quantifier::All), Some(Verdict::NotReproduced));
        assert_eq!(
            to_decide(&pair, Quantifier::All, 0.05),
            ToDecide::Repetitions(holm)
        );
        // Both leaning reproduced under `all`: every one must be decided, no correction.
        let far = undecided(-0.02, 0.2 / t9, Relation::Less);
        let both = [yes.clone(), far.clone()];
        assert_eq!(lean(&both, Quantifier::All), Some(Verdict::Reproduced));
        let need = |x: &Comparison| {
            x.repetitions_to_decide(Relation::Less.interval(0.2), 0.05)
                .unwrap()
        };
        assert_eq!(
            to_decide(&both, Quantifier::All, 0.05),
            ToDecide::Repetitions(need(&yes).max(need(&far)))
        );
        // `any` leaning reproduced: one suffices, corrected at α / 2.
        let any = to_decide(&both, Quantifier::Any, 0.05);
        let holm_min = [&yes, &far]
            .iter()
            .map(|x| {
                x.repetitions_to_decide(Relation::Less.interval(0.2), 0.025)
                    .unwrap()
            })
            .fold(f64::INFINITY, f64::min);
        assert_eq!(any, ToDecide::Repetitions(holm_min));
        // An estimate on the boundary never decides.
        let edge = undecided(0.0, 0.1, Relation::Less);
        assert_eq!(
            to_decide(std::slice::from_ref(&edge), Quantifier::All, 0.05),
            ToDecide::Never
        );
        assert_eq!(lean(&[], Quantifier::All), None);
    }
}
