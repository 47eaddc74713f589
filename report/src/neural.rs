//! The neural learners (AE, VAE, RFVAE; docs/original-code.md section 5): their training budgets as recorded
//! in the manifests (`train.config`), the faithful-vs-corrected comparison of the VAE and RFVAE
//! (paired by seed), the training-budget sensitivity of RGE-VAE (the `budget-*` campaigns) and
//! the recorded training losses.
//!
//! *Faithful* reproduces the original code, defects included (the VAE's reparameterisation noise
//! shared by the whole batch; the RFVAE's shared noise, log-det broadcast and encoding mismatch);
//! *corrected* fixes them. The AE has no documented defect and runs once (variant `none`).
//! Runs of the two variants with the same seed start from the same weights and draw the same
//! batches, so their difference is measured per seed.

use std::collections::{BTreeMap, BTreeSet};

use serde_json::Value;

use crate::aggregate::ConditionSummary;
use crate::campaigns::Campaign;
use crate::load::{ConditionKey, Manifest, Run, Store, rank};
use crate::stats::{self, Summary};
use ugl_types::LearnerInfo;

/// The neural learners, in the registry's order (`ae`, `vae`, `rfvae`).
pub fn learners() -> Vec<&'static str> {
    LearnerInfo::all()
        .filter(|l| l.is_neural())
        .map(|l| l.name)
        .collect()
}

/// The algorithms compared faithful vs corrected: the learners with variants.
pub fn variant_algos() -> Vec<&'static str> {
    LearnerInfo::all()
        .filter(|l| l.has_variants)
        .map(|l| l.algo)
        .collect()
}

/// The paper's training of one learner (docs/original-code.md section 5; the original `src/network.py`).
#[derive(Debug, Clone, PartialEq)]
pub struct PaperTraining {
    pub learner: &'static str,
    pub iterations: i64,
    pub hidden: [i64; 2],
    pub batch: i64,
    pub lr: f64,
    pub optimiser: String,
    /// RFVAE: iterations of the warm-up `min(1, 0.01 + step / 10⁴)` on KL and reconstruction.
    pub warmup: Option<i64>,
}

/// The paper's training of a neural learner, from the registry: AE 200,000 iterations
/// (Adagrad), VAE 100,000 (Adam), RFVAE 50,000 (Adam, 10,000 warm-up); all 4900-1200-1200
/// dense networks, batch 100, learning rate 1e-3.
pub fn paper_training(learner: &str) -> Option<PaperTraining> {
    let l = LearnerInfo::by_name(learner)?;
    let c = l.paper_training?;
    Some(PaperTraining {
        learner: l.name,
        iterations: c.iterations as i64,
        hidden: [c.hidden[0] as i64, c.hidden[1] as i64],
        batch: c.batch as i64,
        lr: c.lr,
        optimiser: c.optimiser.to_string(),
        warmup: (c.warmup > 0).then_some(c.warmup as i64),
    })
}

/// What a manifest's `train` object records (every field optional: the schema belongs to the
/// runner).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Training {
    pub iterations: Option<i64>,
    pub hidden: Option<Vec<i64>>,
    pub batch: Option<i64>,
    pub lr: Option<f64>,
    pub warmup: Option<i64>,
    /// Weight initialisation (`paper`, `he`, `glorot`); absent in manifests written before it
    /// was configurable, which all used the paper's.
    pub init: Option<String>,
    /// Model-cache status: `hit`, `miss`, `rebuilt` or `off`.
    pub cache: Option<String>,
    /// Hash of the training configuration and data: runs with the same key share one training
    /// (e.g. the KDE and Gaussian-goal runs of a cell).
    pub key: Option<String>,
    /// (iteration, loss), as recorded, sorted by iteration.
    pub losses: Vec<(i64, f64)>,
    /// The iterations trained (`train.iterations`, results version 5 on): more than
    /// `iterations` where the plateau rule trained on.
    pub iterations_used: Option<i64>,
    /// The plateau rule (`train.config.plateau`): iterations per extension and the cap.
    pub plateau: Option<(i64, i64)>,
}

/// The `train` object of a manifest, if the run trained a neural representation.
pub fn training(m: &Manifest) -> Option<Training> {
    let t = m.train.as_ref()?;
    let mut losses: Vec<(i64, f64)> = t.losses.iter().map(|&(i, l)| (i as i64, l)).collect();
    losses.sort_by_key(|&(i, _)| i);
    Some(Training {
        iterations: t.config_int("iterations"),
        hidden: t
            .config_field("hidden")
            .and_then(Value::as_array)
            .map(|a| a.iter().filter_map(Value::as_i64).collect()),
        batch: t.config_int("batch"),
        lr: t.config_f64("lr"),
        warmup: t.config_int("warmup"),
        init: t.config_str("init").map(str::to_string),
        cache: t.cache.map(|c| c.as_str().to_string()),
        key: (!t.key.is_empty()).then(|| t.key.clone()),
        losses,
        iterations_used: t.iterations.map(|i| i as i64),
        plateau: t
            .config_field("plateau")
            .and_then(Value::as_object)
            .and_then(|p| Some((p.get("chunk")?.as_i64()?, p.get("cap")?.as_i64()?))),
    })
}

/// The neural learner of a run: the manifest's `learner`, else derived from the algorithm
/// (`rge-vae` → `vae`); `None` for runs without a neural representation.
pub fn learner(run: &Run) -> Option<String> {
    if let Some(l) = run.manifest.learner.as_deref()
        && learners().contains(&l)
    {
        return Some(l.to_string());
    }
    let l = run.key.algo.strip_prefix("rge-")?;
    learners().contains(&l).then(|| l.to_string())
}

/// Training iterations of a run, from `train.config.iterations`.
pub fn iterations(run: &Run) -> Option<i64> {
    training(&run.manifest).and_then(|t| t.iterations)
}

/// The training budget of one learner in one campaign: each recorded value with its run count.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BudgetUsed {
    pub learner: String,
    pub runs: usize,
    /// Runs whose manifest has no `train` record.
    pub unrecorded: usize,
    pub iterations: BTreeMap<String, usize>,
    pub hidden: BTreeMap<String, usize>,
    pub batch: BTreeMap<String, usize>,
    pub lr: BTreeMap<String, usize>,
    pub warmup: BTreeMap<String, usize>,
    pub init: BTreeMap<String, usize>,
    /// Distinct trainings (training keys; a training is shared by the samplers of a cell).
    pub trainings: usize,
    /// Mean `fit_s` (data set + training) over distinct trainings, seconds.
    pub mean_fit_s: Option<f64>,
    /// Runs per plateau rule, `chunk N, cap M` (none without the rule).
    pub plateau_rules: BTreeMap<String, usize>,
    /// The distinct trainings the plateau rule trained on past their iterations: training key
    /// -> (configured, used) iterations.
    pub extended: BTreeMap<String, (i64, i64)>,
}

/// The learners' budgets actually used by `store`'s runs, in the paper's learner order.
pub fn budgets_used(store: &Store) -> Vec<BudgetUsed> {
    let mut by: BTreeMap<String, BudgetUsed> = BTreeMap::new();
    let mut keys: BTreeMap<String, BTreeMap<String, Option<f64>>> = BTreeMap::new();
    for r in &store.runs {
        let Some(l) = learner(r) else { continue };
        let b = by.entry(l.clone()).or_insert_with(|| BudgetUsed {
            learner: l.clone(),
            ..Default::default()
        });
        b.runs += 1;
        let Some(t) = training(&r.manifest) else {
            b.unrecorded += 1;
            continue;
        };
        let count = |m: &mut BTreeMap<String, usize>, v: Option<String>| {
            *m.entry(v.unwrap_or_else(|| "not recorded".into()))
                .or_default() += 1;
        };
        count(&mut b.iterations, t.iterations.map(|v| v.to_string()));
        count(
            &mut b.hidden,
            t.hidden.as_ref().map(|h| {
                let s: Vec<String> = h.iter().map(i64::to_string).collect();
                format!("[{}]", s.join(", "))
            }),
        );
        count(&mut b.batch, t.batch.map(|v| v.to_string()));
        count(&mut b.lr, t.lr.map(|v| format!("{v:e}")));
        count(&mut b.warmup, t.warmup.map(|v| v.to_string()));
        count(
            &mut b.init,
            Some(t.init.clone().unwrap_or_else(|| "paper".into())),
        );
        let key = t.key.clone().unwrap_or_else(|| r.run_id.clone());
        if let Some((chunk, cap)) = t.plateau {
            *b.plateau_rules
                .entry(format!("chunk {chunk}, cap {cap}"))
                .or_default() += 1;
        }
        if let (Some(configured), Some(used)) = (t.iterations, t.iterations_used)
            && used > configured
        {
            b.extended.insert(key.clone(), (configured, used));
        }
        keys.entry(l).or_default().insert(key, r.manifest.fit_s);
    }
    for (l, ks) in keys {
        let b = by.get_mut(&l).expect("learner seen");
        b.trainings = ks.len();
        let fits: Vec<f64> = ks.values().flatten().copied().collect();
        b.mean_fit_s = (!fits.is_empty()).then(|| fits.iter().sum::<f64>() / fits.len() as f64);
    }
    let mut out: Vec<BudgetUsed> = by.into_values().collect();
    out.sort_by_key(|b| (rank(&b.learner, &learners()), b.learner.clone()));
    out
}

/// The faithful and corrected variants of one (env, algo, sampler, latents) cell.
#[derive(Debug, Clone)]
pub struct VariantPair<'a> {
    pub env: String,
    pub algo: crate::load::Algo,
    pub sampler: crate::load::Sampler,
    pub latents: i64,
    pub faithful: Option<&'a ConditionSummary>,
    pub corrected: Option<&'a ConditionSummary>,
    /// corrected − faithful per seed, for the seeds both have.
    pub differences: Vec<(i64, f64)>,
    /// Mean paired difference with its paired t interval ([`stats::paired_summary`]); `None`
    /// without a pair.
    pub diff: Option<Summary>,
}

/// Every cell of [`variant_algos`] with a faithful or corrected condition, in the report's order.
pub fn variant_pairs(conditions: &[ConditionSummary]) -> Vec<VariantPair<'_>> {
    type Cell = (String, crate::load::Algo, crate::load::Sampler, i64);
    let mut cells: BTreeMap<Cell, (Option<&ConditionSummary>, Option<&ConditionSummary>)> =
        BTreeMap::new();
    for c in conditions {
        let k = &c.key;
        if !variant_algos().contains(&k.algo.as_str()) {
            continue;
        }
        let cell = (k.env.clone(), k.algo.clone(), k.sampler.clone(), k.latents);
        let e = cells.entry(cell).or_default();
        if k.variant == ugl_types::Variant::FAITHFUL {
            e.0 = Some(c);
        } else if k.variant == ugl_types::Variant::CORRECTED {
            e.1 = Some(c);
        }
    }
    let mut out: Vec<VariantPair<'_>> = cells
        .into_iter()
        .filter(|(_, (f, c))| f.is_some() || c.is_some())
        .map(|((env, algo, sampler, latents), (f, c))| {
            let (differences, diff) = match (f, c) {
                (Some(f), Some(c)) => (
                    stats::paired_differences(&f.final_by_seed, &c.final_by_seed),
                    stats::paired_summary(&f.final_by_seed, &c.final_by_seed),
                ),
                _ => (Vec::new(), None),
            };
            VariantPair {
                env,
                algo,
                sampler,
                latents,
                faithful: f,
                corrected: c,
                differences,
                diff,
            }
        })
        .collect();
    out.sort_by_key(|p| {
        (
            crate::names::panel_order(&p.env, p.latents),
            rank(&p.algo, &variant_algos()),
            rank(
                &p.sampler,
                &ugl_types::SamplerInfo::learned()
                    .map(|s| s.name)
                    .collect::<Vec<_>>(),
            ),
            p.sampler.clone(),
        )
    });
    out
}

/// The final KLC of one group of runs at one training budget.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetPoint {
    /// Training iterations (`train.config.iterations`).
    pub iterations: i64,
    /// Campaigns the runs came from, sorted.
    pub campaigns: Vec<String>,
    /// (seed, final KLC) of each run, in seed order.
    pub values: Vec<(i64, f64)>,
    /// Whether each run's network left the mean-image plateau (`train.evidence.trained`), in
    /// the order of `values`; None where the manifest does not record it.
    pub trained: Vec<Option<bool>>,
    /// Over the repetitions' means (a repetition's exploration replicates share its network).
    pub summary: Summary,
    /// The median of the repetitions' means: the data are often bimodal (networks that trained
    /// and networks that stayed on the plateau), where a mean describes no run.
    pub median: f64,
    /// Networks (repetitions: a repetition's exploration replicates share its network) whose
    /// manifests record the evidence of training, and those of them that stayed on the plateau.
    pub networks: usize,
    pub untrained: usize,
    /// Runs at RPE level (fewer object moves than [`crate::aggregate::RPE_LEVEL_FACTOR`] x the
    /// main campaign's RPE mean); None without RPE runs there.
    pub at_rpe_level: Option<usize>,
}

/// A reference level from the main campaign (RGE-EFR, RPE on the same environment).
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    pub algo: String,
    pub summary: Summary,
    /// Its final KLC per seed.
    pub values: Vec<f64>,
}

/// Final KLC against training iterations for one condition of the budget campaigns.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetSeries {
    pub key: ConditionKey,
    /// The budget campaigns' points, by iterations.
    pub points: Vec<BudgetPoint>,
    /// The same condition in the main campaign, at its own budget(s).
    pub main: Vec<BudgetPoint>,
    /// RGE-EFR and RPE of the main campaign on the same environment (those present).
    pub references: Vec<Reference>,
}

/// The budget-sensitivity analysis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BudgetAnalysis {
    pub series: Vec<BudgetSeries>,
    /// Budget-campaign runs without `train.config.iterations`, left out.
    pub unrecorded: Vec<String>,
}

/// `rpe_moves`: the object moves below which a run is at RPE level (None: no RPE runs).
fn point(iterations: i64, runs: &[&Run], rpe_moves: Option<f64>) -> BudgetPoint {
    let mut rows: Vec<(i64, f64, Option<bool>, i64)> = runs
        .iter()
        .map(|r| {
            let f = r.final_point();
            (r.seed, f.klc, r.manifest.trained(), f.n_moved)
        })
        .collect();
    rows.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let values: Vec<(i64, f64)> = rows.iter().map(|r| (r.0, r.1)).collect();
    let means: Vec<f64> = crate::aggregate::seed_means(&values)
        .into_iter()
        .map(|v| v.1)
        .collect();
    let campaigns: BTreeSet<String> = runs.iter().map(|r| r.campaign.clone()).collect();
    let networks: BTreeMap<i64, bool> = rows
        .iter()
        .filter_map(|r| r.2.map(|trained| (r.0, trained)))
        .collect();
    BudgetPoint {
        iterations,
        campaigns: campaigns.into_iter().collect(),
        trained: rows.iter().map(|r| r.2).collect(),
        networks: networks.len(),
        untrained: networks.values().filter(|trained| !**trained).count(),
        at_rpe_level: rpe_moves.map(|t| rows.iter().filter(|r| (r.3 as f64) < t).count()),
        median: ugl_types::median(&means).unwrap_or(f64::NAN),
        summary: stats::summarize(&means),
        values,
    }
}

/// Groups the budget campaigns' runs by condition and training iterations; adds the main
/// campaign's runs of the same condition and its RGE-EFR / RPE levels.
pub fn budget_analysis(
    budget: &[Campaign],
    main: &Store,
    main_conditions: &[ConditionSummary],
) -> BudgetAnalysis {
    let mut groups: BTreeMap<ConditionKey, BTreeMap<i64, Vec<&Run>>> = BTreeMap::new();
    let mut unrecorded = Vec::new();
    for c in budget {
        for r in &c.store.runs {
            match iterations(r) {
                Some(it) => groups
                    .entry(r.key.clone())
                    .or_default()
                    .entry(it)
                    .or_default()
                    .push(r),
                None => unrecorded.push(format!("{}/{}", c.name, r.run_id)),
            }
        }
    }
    let mut series: Vec<BudgetSeries> = groups
        .into_iter()
        .map(|(key, by_it)| {
            let rpe_moves = main_conditions
                .iter()
                .find(|c| c.key.env == key.env && c.key.algo == ugl_types::Algo::RPE)
                .map(|c| crate::aggregate::RPE_LEVEL_FACTOR * c.final_moved_mean);
            let points = by_it
                .iter()
                .map(|(&it, runs)| point(it, runs, rpe_moves))
                .collect();
            let mut main_by_it: BTreeMap<i64, Vec<&Run>> = BTreeMap::new();
            for r in main.runs.iter().filter(|r| r.key == key) {
                if let Some(it) = iterations(r) {
                    main_by_it.entry(it).or_default().push(r);
                }
            }
            let main_points = main_by_it
                .iter()
                .map(|(&it, runs)| point(it, runs, rpe_moves))
                .collect();
            let references = [ugl_types::Algo::RGE_EFR, ugl_types::Algo::RPE]
                .iter()
                .filter_map(|algo| {
                    main_conditions
                        .iter()
                        .find(|c| c.key.env == key.env && c.key.algo == *algo)
                        .map(|c| Reference {
                            algo: algo.to_string(),
                            summary: c.final_klc.clone(),
                            values: c.final_by_seed.iter().map(|v| v.1).collect(),
                        })
                })
                .collect();
            BudgetSeries {
                key,
                points,
                main: main_points,
                references,
            }
        })
        .collect();
    series.sort_by_key(|s| s.key.order_key());
    unrecorded.sort();
    BudgetAnalysis { series, unrecorded }
}

/// The mean recorded training loss of one (env, learner, variant, latents) group.
#[derive(Debug, Clone, PartialEq)]
pub struct LossCurve {
    pub env: String,
    pub learner: String,
    /// The runs' variant (`none` for the AE).
    pub variant: String,
    pub latents: i64,
    /// Distinct trainings averaged (runs sharing a training key count once).
    pub trainings: usize,
    /// (iteration, mean loss over the trainings that recorded it).
    pub points: Vec<(i64, f64)>,
    /// The mean-image loss of the training images (the plateau), mean over the trainings that
    /// record it (`train.evidence.plateau_loss`).
    pub plateau: Option<f64>,
}

/// Mean training-loss curves of `store`'s neural runs, one training counted once.
pub fn loss_curves(store: &Store) -> Vec<LossCurve> {
    type Group = (String, String, String, i64);
    type Recorded = (Vec<(i64, f64)>, Option<f64>);
    let mut groups: BTreeMap<Group, BTreeMap<String, Recorded>> = BTreeMap::new();
    for r in &store.runs {
        let (Some(l), Some(t)) = (learner(r), training(&r.manifest)) else {
            continue;
        };
        if t.losses.is_empty() {
            continue;
        }
        let key = t.key.clone().unwrap_or_else(|| r.run_id.clone());
        let plateau = r.manifest.training_evidence().map(|e| e.plateau_loss);
        groups
            .entry((
                r.key.env.clone(),
                l,
                r.key.variant.to_string(),
                r.key.latents,
            ))
            .or_default()
            .entry(key)
            .or_insert((t.losses, plateau));
    }
    let mut out: Vec<LossCurve> = groups
        .into_iter()
        .map(|((env, learner, variant, latents), trainings)| {
            let mut by_it: BTreeMap<i64, Vec<f64>> = BTreeMap::new();
            for (losses, _) in trainings.values() {
                for &(i, v) in losses {
                    by_it.entry(i).or_default().push(v);
                }
            }
            let plateaus: Vec<f64> = trainings.values().filter_map(|t| t.1).collect();
            LossCurve {
                env,
                learner,
                variant,
                latents,
                trainings: trainings.len(),
                points: by_it
                    .into_iter()
                    .map(|(i, vs)| (i, stats::mean(&vs)))
                    .collect(),
                plateau: (!plateaus.is_empty()).then(|| stats::mean(&plateaus)),
            }
        })
        .collect();
    out.sort_by_key(|c| {
        (
            ugl_types::EnvSpec::order(&c.env),
            c.env.clone(),
            rank(&c.learner, &learners()),
            c.learner.clone(),
            std::cmp::Reverse(c.latents),
            rank(&c.variant, &ugl_types::VARIANTS.map(|v| v.name)),
            c.variant.clone(),
        )
    });
    out
}
