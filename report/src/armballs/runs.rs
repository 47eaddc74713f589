//! The follow-up campaigns' runs, as the ArmBalls page reads them: the ball's and the
//! distractor's curves, the interest of each goal module, and how each latent of a learned space
//! relates to the two objects.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use super::labels::Condition;
use crate::campaigns::Campaign;
use crate::error::ReportError;
use crate::load::{Cols, ConditionKey, INTEREST_SUFFIX, read_parquet};
use crate::stats::mean;
use ugl_types::columns::{curve, interest};

/// ArmBalls' ball's KL-coverage grid (the registry's).
pub(super) fn ball_grid() -> ugl_types::KlcGrid {
    ugl_types::EnvSpec::by_name(ugl_types::ARMBALLS.name)
        .expect("armballs is registered")
        .klc
}

/// ArmBalls' ball: the cells it can reach, of all cells of its grid.
pub(super) fn ball_cells() -> (f64, f64) {
    let grid = ball_grid();
    (
        grid.achievable_cells as f64,
        (grid.bins as f64).powi(grid.dims as i32),
    )
}

/// A latent "encodes" an object when the object's position explains at least this much of its
/// variance (k-NN R²), and "ignores" it below [`IGNORES`].
pub(super) const ENCODES: f64 = 0.5;
pub(super) const IGNORES: f64 = 0.1;

/// A latent is active when its posterior's mean KL divergence from the prior is above this many
/// nats (the follow-up's criterion: the authors' β-VAE has 4 latents at 3.1-3.3 nats and 6 below
/// 0.01; the sweep's table, [`super::sweep::table`], uses it too).
pub(super) const ACTIVE_NATS: f64 = 0.5;

/// One run of the campaign, as this section reads it.
#[derive(Debug, Clone)]
pub struct FollowupRun {
    /// The run's condition, tagged with its variant campaign's tag.
    pub key: ConditionKey,
    /// The page's condition: the key pooled over samplers and latent sizes, unless the
    /// campaigns ran this algorithm with several ([`separate_conditions`]).
    pub cond: Condition,
    pub seed: i64,
    pub epochs: Vec<i64>,
    /// The controllable ball: cell coverage (of the 756 reachable cells) and KL-coverage.
    pub ball_coverage: Vec<f64>,
    pub ball_klc: Vec<f64>,
    /// The distractor (control): cell coverage (of all 900 cells) and KL-coverage.
    pub distractor_coverage: Vec<Option<f64>>,
    pub distractor_klc: Vec<Option<f64>>,
    /// Modular runs: per module, its name and goal-space coordinates.
    pub modules: BTreeMap<i64, (String, Vec<usize>)>,
    /// Modular runs: (epoch, module, interest, goals chosen so far).
    pub interest: Vec<(i64, i64, f64, i64)>,
    /// Learned goal spaces: the learner, its loss against the plateau, the held-out k-NN R² of
    /// the ball's and the distractor's positions, and per latent the R² of each object.
    pub learner: Option<String>,
    pub loss_fraction: Option<f64>,
    pub knn_ball: Option<f64>,
    pub knn_distractor: Option<f64>,
    pub per_latent: Option<(Vec<f64>, Vec<f64>)>,
    /// MIG and SAP against the four coordinates of the two objects, and the per-latent KL
    /// from the prior (nats), where the manifest records them (the convolutional networks).
    pub mig: Option<f64>,
    pub sap: Option<f64>,
    pub kl_per_latent: Vec<f64>,
    /// The goal-reaching error at the last epoch (the manifest's discovery record; None in
    /// records written before it was kept).
    pub goal_error: Option<f64>,
    /// A variant campaign's declared label (`[campaign] label`).
    pub variant_label: Option<String>,
}

impl FollowupRun {
    pub(super) fn final_ratio(&self) -> f64 {
        let (reachable, all) = ball_cells();
        self.ball_coverage.last().copied().unwrap_or(f64::NAN) * reachable / all
    }

    /// The ratio at the last evaluation before `rollouts` episodes (the warm-up episode is
    /// epoch 0, so epoch `e` has run `e + 1`): where a published curve ends. NaN before the
    /// first evaluation.
    pub(super) fn ratio_before(&self, rollouts: i64) -> f64 {
        let (reachable, all) = ball_cells();
        self.epochs
            .iter()
            .zip(&self.ball_coverage)
            .rfind(|(e, _)| **e < rollouts)
            .map_or(f64::NAN, |(_, c)| c * reachable / all)
    }

    /// Per module: (ball R², distractor R²), the means over the module's latents.
    pub(super) fn module_objects(&self, module: i64) -> Option<(f64, f64)> {
        let (_, dims) = self.modules.get(&module)?;
        let (b, d) = self.per_latent.as_ref()?;
        let pick = |v: &Vec<f64>| mean(&dims.iter().map(|&k| v[k]).collect::<Vec<_>>());
        Some((pick(b), pick(d)))
    }

    /// The run's modules in the order the page aligns them across repetitions: a learned
    /// space's by ball R² − distractor R² (the most ball-selective first: its module `k` holds
    /// other latents in every repetition, so the index means nothing across them); modules named
    /// by what they hold (the engineered features' `ball`, `distractor`), or without the per-latent
    /// measure, by index.
    pub(super) fn aligned_modules(&self) -> Vec<i64> {
        let mut ms: Vec<i64> = self.modules.keys().copied().collect();
        let selectivity = |m: i64| self.module_objects(m).map(|(b, d)| b - d);
        if !ms.is_empty() && ms.iter().all(|&m| selectivity(m).is_some()) {
            ms.sort_by(|&a, &b| {
                let (sa, sb) = (selectivity(a).unwrap_or(0.0), selectivity(b).unwrap_or(0.0));
                sb.total_cmp(&sa).then(a.cmp(&b))
            });
        }
        ms
    }

    /// Whether [`FollowupRun::aligned_modules`] ranks this run's modules (a learned space with
    /// the per-latent measure) rather than keeping their indices.
    pub(super) fn modules_ranked(&self) -> bool {
        !self.modules.is_empty()
            && self
                .modules
                .keys()
                .all(|&m| self.module_objects(m).is_some())
    }

    /// Final interest and goals chosen, per module.
    pub(super) fn final_interest(&self) -> BTreeMap<i64, (f64, i64)> {
        let last = self.interest.iter().map(|p| p.0).max();
        self.interest
            .iter()
            .filter(|p| Some(p.0) == last)
            .map(|p| (p.1, (p.2, p.3)))
            .collect()
    }
}

/// Reads the campaign's runs. The runs of a variant campaign (`[campaign] variant_of`, e.g.
/// `armballs-still`, a distractor that does not move, tag `still`) are tagged, and get the
/// label the campaign declares.
pub fn load(campaign: &Campaign) -> Result<Vec<FollowupRun>, ReportError> {
    let mut out = Vec::new();
    let decl = &campaign.decl;
    let tag = decl
        .variant_of
        .as_ref()
        .map(|_| decl.tag.clone().unwrap_or_else(|| campaign.name.clone()));
    let tag = tag.as_deref();
    for run in &campaign.store.runs {
        let df = read_parquet(&run.curve_path)?;
        let c = Cols {
            df: &df,
            path: &run.curve_path,
        };
        let has = |name: &str| df.get_column_names().iter().any(|n| n.as_str() == name);
        let (dcov, dklc) = if has(curve::CONTROL_COVERAGE) {
            (
                c.f64s_nullable(curve::CONTROL_COVERAGE)?,
                c.f64s_nullable(curve::CONTROL_KLC)?,
            )
        } else {
            (vec![None; df.height()], vec![None; df.height()])
        };
        let epochs = c.i64s(curve::EPOCH)?;
        let mut order: Vec<usize> = (0..epochs.len()).collect();
        order.sort_by_key(|&i| epochs[i]);
        let quality = run.manifest.latent_quality.as_ref();
        let group = |name: &str| quality.and_then(|q| q.group(name)).map(|g| g.knn_r2);
        let per_latent = quality.and_then(|q| {
            // A constant latent explains nothing.
            let r2 = |name: &str| -> Option<Vec<f64>> {
                Some(
                    q.object(name)?
                        .r2
                        .iter()
                        .map(|v| v.unwrap_or(0.0))
                        .collect(),
                )
            };
            Some((r2("ball")?, r2("distractor")?))
        });
        let (modules, interest) = load_interest(&run.curve_path)?;
        let key = run.key.tagged(tag);
        out.push(FollowupRun {
            cond: Condition::of(&key, false),
            key,
            seed: run.seed,
            epochs: order.iter().map(|&i| epochs[i]).collect(),
            ball_coverage: run.curve.iter().map(|p| p.coverage).collect(),
            ball_klc: run.curve.iter().map(|p| p.klc).collect(),
            distractor_coverage: order.iter().map(|&i| dcov[i]).collect(),
            distractor_klc: order.iter().map(|&i| dklc[i]).collect(),
            modules,
            interest,
            learner: run.manifest.learner.clone(),
            loss_fraction: run.manifest.training_evidence().map(|e| e.loss_fraction),
            knn_ball: group("position"),
            knn_distractor: group("distractor"),
            per_latent,
            mig: quality
                .and_then(|q| q.disentanglement.as_ref())
                .map(|d| d.mig),
            sap: quality
                .and_then(|q| q.disentanglement.as_ref())
                .map(|d| d.sap),
            kl_per_latent: quality.map(|q| q.kl_per_latent.clone()).unwrap_or_default(),
            goal_error: run
                .manifest
                .discovery
                .as_ref()
                .map(|d| d.at_end.goal_error_mean),
            variant_label: decl.label.clone(),
        });
    }
    Ok(out)
}

#[cfg(test)]
impl FollowupRun {
    /// A run of `key` and `seed` with one evaluation (epoch 100) at the ball ratio `ratio`, the
    /// distractor at 0.3, and nothing else recorded (the tests' runs).
    pub(super) fn test_run(key: ConditionKey, seed: i64, ratio: f64) -> FollowupRun {
        let (reachable, all) = ball_cells();
        FollowupRun {
            cond: Condition::of(&key, false),
            key,
            seed,
            epochs: vec![100],
            ball_coverage: vec![ratio * all / reachable],
            ball_klc: vec![1.0],
            distractor_coverage: vec![Some(0.3)],
            distractor_klc: vec![Some(2.0)],
            modules: BTreeMap::new(),
            interest: Vec::new(),
            learner: None,
            loss_fraction: None,
            knn_ball: None,
            knn_distractor: None,
            per_latent: None,
            mig: None,
            sap: None,
            kl_per_latent: Vec::new(),
            goal_error: None,
            variant_label: None,
        }
    }
}

type Interest = (
    BTreeMap<i64, (String, Vec<usize>)>,
    Vec<(i64, i64, f64, i64)>,
);

/// `<run>.interest.parquet` next to the curve file, if any.
pub(super) fn load_interest(curve: &Path) -> Result<Interest, ReportError> {
    let name = curve
        .file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.strip_suffix(".parquet"))
        .unwrap_or_default();
    let path = curve.with_file_name(format!("{name}{INTEREST_SUFFIX}"));
    if !path.is_file() {
        return Ok((BTreeMap::new(), Vec::new()));
    }
    let df = read_parquet(&path)?;
    let c = Cols {
        df: &df,
        path: &path,
    };
    let (epoch, module, interest, chosen) = (
        c.i64s(interest::EPOCH)?,
        c.i64s(interest::MODULE)?,
        c.f64s(interest::INTEREST)?,
        c.i64s(interest::N_CHOSEN)?,
    );
    let (names, dims) = (c.strs(interest::MODULE_NAME)?, c.strs(interest::DIMS)?);
    let mut modules = BTreeMap::new();
    for i in 0..df.height() {
        let d: Vec<usize> = dims[i]
            .split(',')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse())
            .collect::<Result<_, _>>()
            .map_err(|_| ReportError::Invalid {
                path: path.clone(),
                problem: format!("column `dims`: `{}` is not a list of indices", dims[i]),
            })?;
        modules.insert(module[i], (names[i].clone(), d));
    }
    let points = (0..df.height())
        .map(|i| (epoch[i], module[i], interest[i], chosen[i]))
        .collect();
    Ok((modules, points))
}

/// The name of a condition among `runs`: [`Condition::label`], with a variant campaign's tag
/// replaced by the label its campaign declares (`[campaign] label`: `still distractor`).
pub(super) fn display(runs: &[FollowupRun], cond: &Condition) -> String {
    let Some(tag) = &cond.tag else {
        return cond.label();
    };
    let declared = runs
        .iter()
        .find(|r| r.cond == *cond)
        .and_then(|r| r.variant_label.clone());
    format!(
        "{}, {}{}",
        cond.algo_label(),
        declared.as_deref().unwrap_or(tag),
        cond.suffix_label()
    )
}

/// Runs of one algorithm (and campaign) with several goal samplers or latent sizes are separate
/// conditions, never pooled: their condition names the sampler and the latent size.
pub(super) fn separate_conditions(runs: &mut [FollowupRun]) {
    let mut variants: BTreeMap<Condition, BTreeSet<(String, i64)>> = BTreeMap::new();
    for r in runs.iter() {
        variants
            .entry(Condition::of(&r.key, false))
            .or_default()
            .insert((r.key.sampler.to_string(), r.key.latents));
    }
    for r in runs.iter_mut() {
        let split = variants[&Condition::of(&r.key, false)].len() > 1;
        r.cond = Condition::of(&r.key, split);
    }
}

/// The conditions of `runs`, each once, in the order of their first run.
pub(super) fn algos(runs: &[FollowupRun]) -> Vec<Condition> {
    let mut v: Vec<Condition> = Vec::new();
    for r in runs {
        if !v.contains(&r.cond) {
            v.push(r.cond.clone());
        }
    }
    v
}

pub(super) fn of<'a>(runs: &'a [FollowupRun], cond: &Condition) -> Vec<&'a FollowupRun> {
    runs.iter().filter(|r| r.cond == *cond).collect()
}

pub(super) fn ratios(runs: &[FollowupRun], cond: &Condition) -> Vec<f64> {
    of(runs, cond).iter().map(|r| r.final_ratio()).collect()
}

/// What one latent encodes, from the k-NN R² of each object's position ([`role`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum LatentRole {
    /// The ball alone (its R² at least [`ENCODES`], the distractor's below [`IGNORES`]).
    Ball,
    /// The distractor alone.
    Distractor,
    /// Both objects (entangled: both R² at least [`IGNORES`]).
    Both,
    /// Neither (both below [`IGNORES`]; collapsed).
    Neither,
    MostlyBall,
    MostlyDistractor,
}

impl LatentRole {
    /// The word the page and the sweep table print.
    pub(super) fn label(self) -> &'static str {
        match self {
            LatentRole::Ball => "ball",
            LatentRole::Distractor => "distractor",
            LatentRole::Both => "both",
            LatentRole::Neither => "none",
            LatentRole::MostlyBall => "mostly ball",
            LatentRole::MostlyDistractor => "mostly distractor",
        }
    }
}

impl std::fmt::Display for LatentRole {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// A latent's role from its two R² (`b` the ball's, `d` the distractor's).
pub(super) fn role(b: f64, d: f64) -> LatentRole {
    match (b >= ENCODES && d < IGNORES, d >= ENCODES && b < IGNORES) {
        (true, _) => LatentRole::Ball,
        (_, true) => LatentRole::Distractor,
        _ if b >= IGNORES && d >= IGNORES => LatentRole::Both,
        _ if b < IGNORES && d < IGNORES => LatentRole::Neither,
        _ if b > d => LatentRole::MostlyBall,
        _ => LatentRole::MostlyDistractor,
    }
}

/// How many of `roles` are `role`.
pub(super) fn count_role(roles: &[LatentRole], role: LatentRole) -> usize {
    roles.iter().filter(|r| **r == role).count()
}

/// One run per learned network: the first of each (variant campaign's tag, learner, seed,
/// latent count), since a network's flat and modular runs share it. Runs without a learned
/// goal space (no per-latent measure) are left out. The page's disentanglement table and the
/// claims' premise both count networks through it.
pub(super) fn one_run_per_network(runs: &[FollowupRun]) -> Vec<&FollowupRun> {
    let mut seen = BTreeSet::new();
    runs.iter()
        .filter(|r| r.per_latent.is_some())
        .filter(|r| seen.insert((r.key.tag.clone(), r.learner.clone(), r.seed, r.key.latents)))
        .collect()
}

/// The kind ([`role`]) of every active latent of a network, in latent order: a latent whose
/// posterior's mean KL from the prior is above [`ACTIVE_NATS`]. A collapsed latent is left out
/// even where its mean still follows an object (the R² is blind to a latent's scale, so a latent
/// of 0.00 nats can have a ball R² of 0.98). A network without the per-latent KL (`kl` empty:
/// no posterior, e.g. an autoencoder) has every latent counted. `ball` and `distractor` are the
/// per-latent R² of each object's position.
pub(super) fn active_roles(kl: &[f64], ball: &[f64], distractor: &[f64]) -> Vec<LatentRole> {
    ball.iter()
        .zip(distractor)
        .enumerate()
        .filter(|(j, _)| kl.is_empty() || kl.get(*j).is_some_and(|k| *k > ACTIVE_NATS))
        .map(|(_, (b, d))| role(*b, *d))
        .collect()
}

/// Whether a network's code is disentangled in the follow-up's sense, "a representation where
/// each latent variable is sensitive to a single degree of freedom" (its abstract): one of its
/// active latents ([`active_roles`]) encodes the ball alone, another the distractor alone, and
/// none encodes both. An active latent of both objects entangles the modules that hold it (a
/// plain VAE can have an active ball-only and an active distractor-only latent beside four or
/// five active latents of both).
fn is_disentangled(kl: &[f64], ball: &[f64], distractor: &[f64]) -> bool {
    let roles = active_roles(kl, ball, distractor);
    roles.contains(&LatentRole::Ball)
        && roles.contains(&LatentRole::Distractor)
        && !roles.contains(&LatentRole::Both)
}

/// Whether a network's whole code holds both objects: the held-out k-NN R² of each object's
/// position at least [`ENCODES`] (None: not measured, so not).
fn holds_both(knn_ball: Option<f64>, knn_distractor: Option<f64>) -> bool {
    knn_ball.is_some_and(|b| b >= ENCODES) && knn_distractor.is_some_and(|d| d >= ENCODES)
}

/// What a learned network's code is, for the follow-up's claims (their premises) and page.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum CodeKind {
    /// [`is_disentangled`].
    Disentangled,
    /// Holds both objects ([`holds_both`]) and is not disentangled: the entangled control.
    Entangled,
    /// Holds one object or neither: blind to the other, neither of the follow-up's spaces.
    Partial,
}

impl CodeKind {
    /// The network of run `r`, where its per-latent measure is recorded.
    pub(super) fn of(r: &FollowupRun) -> Option<CodeKind> {
        let (b, d) = r.per_latent.as_ref()?;
        Some(CodeKind::from_measures(
            &r.kl_per_latent,
            b,
            d,
            r.knn_ball,
            r.knn_distractor,
        ))
    }

    /// A network's kind from its measures: the per-latent KL, the per-latent R² of each
    /// object ([`is_disentangled`]) and the whole code's k-NN R² of each ([`holds_both`]).
    pub(super) fn from_measures(
        kl: &[f64],
        ball: &[f64],
        distractor: &[f64],
        knn_ball: Option<f64>,
        knn_distractor: Option<f64>,
    ) -> CodeKind {
        if is_disentangled(kl, ball, distractor) {
            CodeKind::Disentangled
        } else if holds_both(knn_ball, knn_distractor) {
            CodeKind::Entangled
        } else {
            CodeKind::Partial
        }
    }

    /// What a network of this kind has, in words (the claims' premise counts them).
    pub(super) fn criterion(self) -> String {
        match self {
            CodeKind::Disentangled => "with an active ball-only and an active distractor-only \
                                       latent and none of both"
                .into(),
            CodeKind::Entangled => format!(
                "holding both objects (k-NN R² of each position at least {ENCODES}), not \
                 disentangled"
            ),
            CodeKind::Partial => "holding one object or neither".into(),
        }
    }

    /// The word the page prints.
    pub(super) fn label(self) -> &'static str {
        match self {
            CodeKind::Disentangled => "disentangled",
            CodeKind::Entangled => "entangled",
            CodeKind::Partial => "not both objects",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A learned space's modules are aligned by ball R² − distractor R², most ball-selective
    /// first; named modules without the per-latent measure keep their order.
    #[test]
    fn modules_align_by_ball_selectivity() {
        let key = ConditionKey {
            env: "armballs".into(),
            algo: "mge-bvae-lp".into(),
            sampler: "gaussian".into(),
            latents: 4,
            variant: "none".into(),
            tag: None,
        };
        let mut r = FollowupRun::test_run(key, 0, 0.3);
        r.modules = [
            (0, ("z0,z1".into(), vec![0, 1])),
            (1, ("z2,z3".into(), vec![2, 3])),
        ]
        .into();
        assert_eq!(r.aligned_modules(), [0, 1]);
        assert!(!r.modules_ranked());
        // Module 1 holds the ball's latents: it comes first.
        r.per_latent = Some((vec![0.1, 0.0, 0.9, 0.8], vec![0.7, 0.9, 0.0, 0.05]));
        assert_eq!(r.aligned_modules(), [1, 0]);
        assert!(r.modules_ranked());
    }

    /// Only active latents count: a collapsed latent whose mean follows the distractor does not
    /// make a network disentangled; without the per-latent KL every latent counts.
    #[test]
    fn a_network_is_disentangled_by_its_active_latents() {
        let ball = [0.9, 0.02, 0.4];
        let distractor = [0.01, 0.8, 0.4];
        assert_eq!(
            active_roles(&[3.1, 3.0, 2.0], &ball, &distractor),
            [LatentRole::Ball, LatentRole::Distractor, LatentRole::Both]
        );
        // An active latent of both objects: entangled, whatever else the code holds.
        assert!(!is_disentangled(&[3.1, 3.0, 2.0], &ball, &distractor));
        assert!(is_disentangled(&[3.1, 3.0, 0.2], &ball, &distractor));
        // The distractor's latent collapsed (0.01 nats): its mean still follows the distractor.
        assert_eq!(
            active_roles(&[3.1, 0.01, 2.0], &ball, &distractor),
            [LatentRole::Ball, LatentRole::Both]
        );
        assert!(!is_disentangled(&[3.1, 0.01, 0.2], &ball, &distractor));
        assert!(!is_disentangled(
            &[3.1, ACTIVE_NATS, 0.2],
            &ball,
            &distractor
        ));
        assert!(is_disentangled(&[], &ball[..2], &distractor[..2]));
        assert!(!is_disentangled(&[], &ball, &distractor));
        assert!(!is_disentangled(&[], &ball[..1], &distractor[..1]));
    }

    /// A network's code is disentangled, the entangled control (both objects, some latent of
    /// both), or neither of the follow-up's spaces (one object only).
    #[test]
    fn code_kinds() {
        let key = ConditionKey {
            env: "armballs-corl".into(),
            algo: "mge-conv-vae-lp".into(),
            sampler: "gaussian".into(),
            latents: 3,
            variant: "none".into(),
            tag: None,
        };
        let mut r = FollowupRun::test_run(key, 0, 0.3);
        assert_eq!(CodeKind::of(&r), None);
        r.kl_per_latent = vec![3.0, 3.0, 2.0];
        r.per_latent = Some((vec![0.9, 0.02, 0.4], vec![0.01, 0.8, 0.4]));
        (r.knn_ball, r.knn_distractor) = (Some(0.99), Some(0.97));
        assert_eq!(CodeKind::of(&r), Some(CodeKind::Entangled));
        r.kl_per_latent[2] = 0.1;
        assert_eq!(CodeKind::of(&r), Some(CodeKind::Disentangled));
        // The ball alone: blind to the distractor.
        r.per_latent = Some((vec![0.9, 0.8, 0.4], vec![0.01, 0.0, 0.05]));
        r.knn_distractor = Some(-0.1);
        assert_eq!(CodeKind::of(&r), Some(CodeKind::Partial));
        r.knn_distractor = None;
        assert_eq!(CodeKind::of(&r), Some(CodeKind::Partial));
    }

    #[test]
    fn latent_roles() {
        assert_eq!(role(0.9, 0.01), LatentRole::Ball);
        assert_eq!(role(0.02, 0.8), LatentRole::Distractor);
        assert_eq!(role(0.5, 0.2), LatentRole::Both);
        assert_eq!(role(0.01, 0.05), LatentRole::Neither);
        assert_eq!(role(0.3, 0.05), LatentRole::MostlyBall);
        assert_eq!(role(0.05, 0.3), LatentRole::MostlyDistractor);
        assert_eq!(LatentRole::Neither.to_string(), "none");
    }
}
