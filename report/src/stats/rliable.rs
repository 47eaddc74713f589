//! rliable-style aggregate statistics (Agarwal et al. 2021, "Deep reinforcement learning at the
//! edge of the statistical precipice"): the interquartile mean, the stratified percentile
//! bootstrap, the probability of improvement and the normalised area under a curve.
//!
//! Conventions of this project:
//!
//! * Scores are final KL-coverage (KLC) values: **lower is better**. A *task* is one
//!   (environment, latent size) cell; the *runs* of an algorithm on a task are its seeds. Inputs
//!   shaped `&[Vec<f64>]` hold one `Vec` of runs per task, tasks in the same order for every
//!   algorithm.
//! * KLC can be `+inf`. Every function says what an infinite value does; none turns `+inf` into
//!   NaN silently. NaN is never a valid score: each function states what it does with one.
//! * Nothing here panics on empty or malformed input: [`iqm`] returns NaN (it has to fit the
//!   `Fn(&[f64]) -> f64` shape of a bootstrap statistic, like [`mean`]); the others return
//!   `Option` or `Result`.
//! * Bootstraps are seeded: a [`ChaCha8Rng`] seeded with `seed_from_u64(seed)` (use
//!   [`super::derive_seed`] to make the seed) drives an [`IndexSampler`], and percentiles use
//!   numpy's linear interpolation ([`percentile_sorted`]), so a result is byte-for-byte
//!   reproducible from its seed.
//! * These percentile intervals pool many runs (the leaderboard's 20 per algorithm over 4 tasks).
//!   Intervals over the few seeds of one condition are t intervals ([`super::interval`]): the
//!   percentile bootstrap under-covers there.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::{IndexSampler, mean, percentile_sorted};

/// Interquartile mean, as rliable computes it (`scipy.stats.trim_mean(x, 0.25)`): sort the
/// values, drop the `floor(n / 4)` lowest and the `floor(n / 4)` highest, and take the mean of
/// the rest.
///
/// * Empty input gives NaN (as [`mean`] does).
/// * `n < 4` drops nothing: the IQM is the plain mean (`floor(n / 4) = 0`, as scipy does).
/// * Any NaN gives NaN.
/// * Infinite values are sorted to the ends (`+inf` above every finite value) and trimmed like
///   any other value: with at most `floor(n / 4)` runs at `+inf` the IQM stays finite (this
///   robustness is the point of the IQM); an infinite value among the kept ones makes the IQM
///   infinite as [`mean`] does (a mix of `+inf` and `-inf` kept gives NaN).
pub fn iqm(values: &[f64]) -> f64 {
    if values.is_empty() || values.iter().any(|v| v.is_nan()) {
        return f64::NAN;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let cut = sorted.len() / 4;
    mean(&sorted[cut..sorted.len() - cut])
}

/// Stratified percentile bootstrap of a statistic over the pooled runs of several tasks.
///
/// The point estimate is `stat` of the pool of every run (tasks in order, runs in order). Each of
/// the `n_boot` replicates resamples, **within each task independently**, as many runs as that
/// task has, with replacement; the resampled runs of all tasks are pooled (tasks in order) and
/// `stat` is applied to the pool. So every replicate keeps each task's run count, and a task with
/// a single run contributes exactly that run to every replicate. The interval is the
/// `100 * alpha / 2` and `100 * (1 - alpha / 2)` percentiles of the replicates (numpy's linear
/// interpolation): `alpha = 0.05` gives rliable's default 95% interval.
///
/// Returns `Some((point, lo, hi))`, or `None` when no task has a run, `n_boot == 0`, or `alpha` is
/// not in `(0, 1)`. Tasks with no runs contribute nothing to the pool (the result is the same as
/// without them).
///
/// The values are passed to `stat` as they are (`+inf` included): what an infinite value does is
/// `stat`'s policy (see [`iqm`], [`mean`]). Replicates are sorted with [`f64::total_cmp`]
/// (`-inf` < finite < `+inf` < NaN), so a statistic that returns NaN on some replicates pushes the
/// upper bound, then the lower, towards NaN; it never panics.
///
/// Deterministic for a `seed`: the stream is `ChaCha8Rng::seed_from_u64(seed)`, drawn replicate by
/// replicate, task by task, run by run (a single-run task draws nothing).
pub fn stratified_bootstrap_ci(
    runs: &[Vec<f64>],
    stat: impl Fn(&[f64]) -> f64,
    n_boot: usize,
    alpha: f64,
    seed: u64,
) -> Option<(f64, f64, f64)> {
    if n_boot == 0 || !(alpha > 0.0 && alpha < 1.0) {
        return None;
    }
    let pool: Vec<f64> = runs.iter().flatten().copied().collect();
    if pool.is_empty() {
        return None;
    }
    let point = stat(&pool);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut samplers: Vec<IndexSampler> = runs
        .iter()
        .map(|r| IndexSampler::new(r.len().max(1)))
        .collect();
    let mut buf = vec![0.0; pool.len()];
    let mut reps = Vec::with_capacity(n_boot);
    for _ in 0..n_boot {
        let mut at = 0;
        for (task, sampler) in runs.iter().zip(samplers.iter_mut()) {
            resample_into(task, sampler, &mut rng, &mut buf[at..at + task.len()]);
            at += task.len();
        }
        reps.push(stat(&buf));
    }
    let (lo, hi) = percentile_interval(&mut reps, alpha);
    Some((point, lo, hi))
}

/// The mean over tasks of a per-task statistic (`stat` of each task's runs), which does not
/// pool tasks whose scores sit at different floors, and `n_boot` bootstrap replicates of it
/// (runs resampled within each task): `(point, replicates in draw order)`. None when a task has
/// no run or `n_boot == 0`. Deterministic for a `seed`, drawn replicate by replicate, task by task.
pub fn per_task_mean_bootstrap(
    runs: &[Vec<f64>],
    stat: impl Fn(&[f64]) -> f64,
    n_boot: usize,
    seed: u64,
) -> Option<(f64, Vec<f64>)> {
    if n_boot == 0 || runs.is_empty() || runs.iter().any(Vec::is_empty) {
        return None;
    }
    let mean_of =
        |tasks: &[Vec<f64>]| tasks.iter().map(|t| stat(t)).sum::<f64>() / tasks.len() as f64;
    let point = mean_of(runs);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut samplers: Vec<IndexSampler> = runs.iter().map(|r| IndexSampler::new(r.len())).collect();
    let mut buf: Vec<Vec<f64>> = runs.to_vec();
    let mut reps = Vec::with_capacity(n_boot);
    for _ in 0..n_boot {
        for ((task, sampler), out) in runs.iter().zip(samplers.iter_mut()).zip(buf.iter_mut()) {
            resample_into(task, sampler, &mut rng, out);
        }
        reps.push(mean_of(&buf));
    }
    Some((point, reps))
}

/// The `1 − alpha` percentile interval of bootstrap replicates (`alpha` in (0, 1), `reps`
/// non-empty).
pub fn percentile_ci(reps: &[f64], alpha: f64) -> (f64, f64) {
    let mut r = reps.to_vec();
    percentile_interval(&mut r, alpha)
}

/// Pairwise wins of `x` over `y` on a lower-is-better score (ties half) and the number of
/// pairs, summed over tasks: the counts behind [`probability_of_improvement`] (which averages the
/// per-task fractions).
pub fn improvement_counts(x: &[Vec<f64>], y: &[Vec<f64>]) -> (f64, usize) {
    let (mut wins, mut pairs) = (0.0, 0);
    for (a, b) in x.iter().zip(y) {
        for &u in a {
            for &v in b {
                wins += if u < v {
                    1.0
                } else if u == v {
                    0.5
                } else {
                    0.0
                };
                pairs += 1;
            }
        }
    }
    (wins, pairs)
}

/// The exact (Clopper-Pearson) two-sided `1 − alpha` bound for a proportion observed at 0 or
/// at 1 in `n` independent trials: `(0, 1 − (alpha/2)^(1/n))` or `((alpha/2)^(1/n), 1)`; None
/// otherwise or with `n = 0`.
pub fn exact_bound_at_extreme(successes: f64, n: usize, alpha: f64) -> Option<(f64, f64)> {
    if n == 0 {
        return None;
    }
    let b = (alpha / 2.0).powf(1.0 / n as f64);
    if successes == 0.0 {
        Some((0.0, 1.0 - b))
    } else if successes == n as f64 {
        Some((b, 1.0))
    } else {
        None
    }
}

/// Probability of improvement of algorithm X over algorithm Y for a lower-is-better score:
/// `P(X < Y)`, averaged over tasks (rliable's `probability_of_improvement`, with the comparison
/// flipped because lower KLC is better).
///
/// Per task, with `n` runs of X and `m` runs of Y, it is the Mann-Whitney U statistic divided by
/// `n * m`: the fraction of the `n * m` pairs `(x, y)` with `x < y`, a tie counting 1/2. The result
/// is the unweighted mean of the per-task values, in `[0, 1]`; 0.5 means no difference, and
/// `P(X < Y) + P(Y < X) = 1`.
///
/// Infinite values compare as numbers: a finite run beats a `+inf` run, and two `+inf` runs tie.
/// Returns `None` when `x` and `y` do not have the same number of tasks, when there is no task,
/// when some task has no run of X or no run of Y (the mean over tasks would silently change its
/// weights), or when any value is NaN.
pub fn probability_of_improvement(x: &[Vec<f64>], y: &[Vec<f64>]) -> Option<f64> {
    if !comparable(x, y) {
        return None;
    }
    Some(poi_unchecked(x, y))
}

/// [`probability_of_improvement`] with a stratified percentile-bootstrap interval: each replicate
/// resamples, with replacement, the runs of X and, independently, the runs of Y within each task
/// (rliable's `StratifiedIndependentBootstrap`), keeping every run count. The interval is the
/// `100 * alpha / 2` and `100 * (1 - alpha / 2)` percentiles of the replicates.
///
/// Returns `Some((point, lo, hi))`; `None` when [`probability_of_improvement`] would, when
/// `n_boot == 0`, or when `alpha` is not in `(0, 1)`. Infinite values are handled as in
/// [`probability_of_improvement`].
///
/// Deterministic for a `seed`: the stream is `ChaCha8Rng::seed_from_u64(seed)`, drawn replicate by
/// replicate, task by task, X's runs then Y's (a single-run side draws nothing).
pub fn probability_of_improvement_ci(
    x: &[Vec<f64>],
    y: &[Vec<f64>],
    n_boot: usize,
    alpha: f64,
    seed: u64,
) -> Option<(f64, f64, f64)> {
    if n_boot == 0 || !(alpha > 0.0 && alpha < 1.0) || !comparable(x, y) {
        return None;
    }
    let point = poi_unchecked(x, y);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut sx: Vec<IndexSampler> = x.iter().map(|r| IndexSampler::new(r.len())).collect();
    let mut sy: Vec<IndexSampler> = y.iter().map(|r| IndexSampler::new(r.len())).collect();
    let mut bx: Vec<Vec<f64>> = x.to_vec();
    let mut by: Vec<Vec<f64>> = y.to_vec();
    let mut reps = Vec::with_capacity(n_boot);
    for _ in 0..n_boot {
        for t in 0..x.len() {
            resample_into(&x[t], &mut sx[t], &mut rng, &mut bx[t]);
            resample_into(&y[t], &mut sy[t], &mut rng, &mut by[t]);
        }
        reps.push(poi_unchecked(&bx, &by));
    }
    let (lo, hi) = percentile_interval(&mut reps, alpha);
    Some((point, lo, hi))
}

/// Why [`area_under_curve`] could not compute an area.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AucError {
    /// `epochs` and `values` differ in length.
    #[error("{epochs} epochs but {values} values")]
    LengthMismatch { epochs: usize, values: usize },
    /// Fewer than two points: the epoch span is zero, so the normalised area is undefined.
    #[error("{0} point(s): a curve needs at least two to have an area")]
    TooFewPoints(usize),
    /// An epoch is NaN or infinite.
    #[error("epoch #{index} is not finite")]
    NonFiniteEpoch { index: usize },
    /// `epochs[index] <= epochs[index - 1]`: epochs must be strictly increasing.
    #[error("epochs are not strictly increasing at #{index}")]
    NotIncreasing { index: usize },
    /// A value is NaN.
    #[error("value #{index} is NaN")]
    NanValue { index: usize },
    /// The values hold both `+inf` and `-inf`: the area has no value.
    #[error("the values hold both +inf and -inf")]
    MixedInfinities,
}

/// Trapezoidal area under a KLC curve, divided by the epoch span `epochs[last] - epochs[0]`: the
/// time-average of the curve over the exploration, in KLC units. Lower means the run explored
/// faster (a curve that drops early has a smaller area than one that drops late to the same final
/// value). A constant curve gives that constant; a linear ramp from `a` to `b` gives `(a + b) / 2`.
///
/// Epochs need not be evenly spaced but must be finite and strictly increasing. Errors (never a
/// panic): [`AucError::LengthMismatch`], [`AucError::TooFewPoints`] (empty or a single point),
/// [`AucError::NonFiniteEpoch`], [`AucError::NotIncreasing`], [`AucError::NanValue`],
/// [`AucError::MixedInfinities`].
///
/// A `+inf` value at any epoch gives `+inf` (the curve was infinite on a segment of positive
/// length); likewise `-inf` gives `-inf`.
pub fn area_under_curve(epochs: &[f64], values: &[f64]) -> Result<f64, AucError> {
    if epochs.len() != values.len() {
        return Err(AucError::LengthMismatch {
            epochs: epochs.len(),
            values: values.len(),
        });
    }
    if epochs.len() < 2 {
        return Err(AucError::TooFewPoints(epochs.len()));
    }
    if let Some(index) = epochs.iter().position(|e| !e.is_finite()) {
        return Err(AucError::NonFiniteEpoch { index });
    }
    if let Some(index) = (1..epochs.len()).find(|&i| epochs[i] <= epochs[i - 1]) {
        return Err(AucError::NotIncreasing { index });
    }
    if let Some(index) = values.iter().position(|v| v.is_nan()) {
        return Err(AucError::NanValue { index });
    }
    let pos_inf = values.contains(&f64::INFINITY);
    let neg_inf = values.contains(&f64::NEG_INFINITY);
    match (pos_inf, neg_inf) {
        (true, true) => return Err(AucError::MixedInfinities),
        (true, false) => return Ok(f64::INFINITY),
        (false, true) => return Ok(f64::NEG_INFINITY),
        (false, false) => {}
    }
    let area: f64 = epochs
        .windows(2)
        .zip(values.windows(2))
        .map(|(e, v)| 0.5 * (v[0] + v[1]) * (e[1] - e[0]))
        .sum();
    Ok(area / (epochs[epochs.len() - 1] - epochs[0]))
}

/// Fills `out` (same length as `src`) with a with-replacement resample of `src`. A single value is
/// copied without drawing; an empty `src` draws nothing.
fn resample_into(src: &[f64], sampler: &mut IndexSampler, rng: &mut ChaCha8Rng, out: &mut [f64]) {
    if src.len() <= 1 {
        out.copy_from_slice(src);
        return;
    }
    for o in out.iter_mut() {
        *o = src[sampler.next(rng)];
    }
}

/// The `100 * alpha / 2` and `100 * (1 - alpha / 2)` percentiles of `reps` (sorted in place with
/// `total_cmp`; `reps` is non-empty and `alpha` in `(0, 1)`).
fn percentile_interval(reps: &mut [f64], alpha: f64) -> (f64, f64) {
    reps.sort_by(f64::total_cmp);
    let tail = alpha / 2.0 * 100.0;
    (
        percentile_sorted(reps, tail),
        percentile_sorted(reps, 100.0 - tail),
    )
}

/// Same number of tasks, at least one, every task with runs on both sides, no NaN.
fn comparable(x: &[Vec<f64>], y: &[Vec<f64>]) -> bool {
    !x.is_empty()
        && x.len() == y.len()
        && x.iter().chain(y).all(|r| !r.is_empty())
        && !x.iter().chain(y).flatten().any(|v| v.is_nan())
}

/// Mean over tasks of the per-task `P(X < Y)` (ties 1/2); inputs checked by [`comparable`].
fn poi_unchecked(x: &[Vec<f64>], y: &[Vec<f64>]) -> f64 {
    let per_task = x.iter().zip(y).map(|(xs, ys)| {
        // Twice the U statistic, in integers: exact for any run count that fits in memory.
        let mut twice_u: u64 = 0;
        for a in xs {
            for b in ys {
                twice_u += if a < b {
                    2
                } else if a == b {
                    1
                } else {
                    0
                };
            }
        }
        twice_u as f64 / (2 * xs.len() * ys.len()) as f64
    });
    per_task.sum::<f64>() / x.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    const INF: f64 = f64::INFINITY;

    fn v(xs: &[f64]) -> Vec<f64> {
        xs.to_vec()
    }

    #[test]
    fn iqm_known_values() {
        let one_to_eight: Vec<f64> = (1..=8).map(f64::from).collect();
        assert_eq!(iqm(&one_to_eight), 4.5);
        assert_eq!(iqm(&[1.0, 2.0, 3.0, 4.0]), 2.5);
        // Order does not matter; n = 5 trims one value each side: mean(2, 3, 4).
        assert_eq!(iqm(&[5.0, 1.0, 4.0, 2.0, 3.0]), 3.0);
        // scipy.stats.trim_mean([1, 2, 3, 4, 5, 6, 7, 100, 1000], 0.25): trims 2 each side,
        // mean(3, 4, 5, 6, 7) = 5.
        assert_eq!(
            iqm(&[1000.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 100.0]),
            5.0
        );
    }

    #[test]
    fn iqm_small_empty_nan_and_inf() {
        // n < 4 trims nothing: the plain mean.
        assert_eq!(iqm(&[7.0]), 7.0);
        assert_eq!(iqm(&[1.0, 2.0]), 1.5);
        assert_eq!(iqm(&[1.0, 2.0, 6.0]), 3.0);
        assert!(iqm(&[]).is_nan());
        assert!(iqm(&[1.0, f64::NAN, 2.0, 3.0]).is_nan());
        // One +inf run in four is trimmed; two are not.
        assert_eq!(iqm(&[1.0, 2.0, 3.0, INF]), 2.5);
        assert_eq!(iqm(&[1.0, 2.0, INF, INF]), INF);
        assert_eq!(iqm(&[1.0, INF, 3.0]), INF);
    }

    #[test]
    fn stratified_bootstrap_is_seeded_and_reproducible() {
        let runs = vec![
            v(&[4.1, 4.6, 4.3, 5.0, 4.4]),
            v(&[3.0, 3.5, 2.8]),
            v(&[6.0]),
        ];
        let a = stratified_bootstrap_ci(&runs, iqm, 2_000, 0.05, 42).unwrap();
        let b = stratified_bootstrap_ci(&runs, iqm, 2_000, 0.05, 42).unwrap();
        assert_eq!(a, b);
        assert_eq!(
            (a.0.to_bits(), a.1.to_bits(), a.2.to_bits()),
            (b.0.to_bits(), b.1.to_bits(), b.2.to_bits())
        );
        let c = stratified_bootstrap_ci(&runs, iqm, 2_000, 0.05, 43).unwrap();
        assert_eq!(a.0, c.0);
        assert_ne!((a.1, a.2), (c.1, c.2));
    }

    #[test]
    fn stratified_bootstrap_identical_values_give_zero_width() {
        let runs = vec![v(&[2.5; 5]), v(&[2.5; 3]), v(&[2.5])];
        for stat in [iqm as fn(&[f64]) -> f64, mean] {
            assert_eq!(
                stratified_bootstrap_ci(&runs, stat, 5_000, 0.05, 1),
                Some((2.5, 2.5, 2.5))
            );
        }
    }

    #[test]
    fn stratified_bootstrap_interval_contains_point() {
        let runs = vec![
            v(&[4.1, 4.6, 4.3, 5.0, 4.4]),
            v(&[3.0, 3.5, 2.8, 3.1, 3.3]),
            v(&[6.0, 5.5, 6.4, 5.9, 6.1]),
        ];
        for seed in 0..5 {
            for stat in [iqm as fn(&[f64]) -> f64, mean] {
                let (p, lo, hi) = stratified_bootstrap_ci(&runs, stat, 2_000, 0.05, seed).unwrap();
                assert!(lo <= p && p <= hi && lo < hi, "{lo} {p} {hi}");
            }
        }
    }

    #[test]
    fn stratified_bootstrap_keeps_per_task_counts() {
        // Task 0 has one run (1000): every replicate holds it exactly once. Task 1 has two runs
        // from {1, 2}: every replicate holds exactly two values from it, in task order.
        let runs = vec![v(&[1000.0]), v(&[1.0, 2.0])];
        let check = |pool: &[f64]| {
            assert_eq!(pool.len(), 3);
            assert_eq!(pool[0], 1000.0);
            assert!(pool[1..].iter().all(|&x| x == 1.0 || x == 2.0));
            pool.iter().sum::<f64>()
        };
        let (p, lo, hi) = stratified_bootstrap_ci(&runs, check, 10_000, 0.1, 3).unwrap();
        assert_eq!(p, 1003.0);
        // Sums 1002 (p=1/4), 1003 (1/2), 1004 (1/4): 5th percentile 1002, 95th 1004.
        assert_eq!((lo, hi), (1002.0, 1004.0));
        // Only single-run tasks: the interval is the point.
        let singles = vec![v(&[1.0]), v(&[INF]), v(&[3.0])];
        assert_eq!(
            stratified_bootstrap_ci(
                &singles,
                |p: &[f64]| p.iter().filter(|x| x.is_finite()).sum(),
                100,
                0.05,
                0
            ),
            Some((4.0, 4.0, 4.0))
        );
    }

    #[test]
    fn stratified_bootstrap_two_point_case_is_exact() {
        // One task {0, 1}, statistic mean: as in `stats::tests::two_point_case_is_exact`.
        for seed in 0..5 {
            assert_eq!(
                stratified_bootstrap_ci(&[v(&[0.0, 1.0])], mean, 10_000, 0.1, seed),
                Some((0.5, 0.0, 1.0))
            );
        }
    }

    #[test]
    fn stratified_bootstrap_rejects_bad_input_without_panicking() {
        assert_eq!(stratified_bootstrap_ci(&[], iqm, 100, 0.05, 0), None);
        assert_eq!(
            stratified_bootstrap_ci(&[vec![], vec![]], iqm, 100, 0.05, 0),
            None
        );
        let runs = vec![v(&[1.0, 2.0])];
        assert_eq!(stratified_bootstrap_ci(&runs, iqm, 0, 0.05, 0), None);
        assert_eq!(stratified_bootstrap_ci(&runs, iqm, 100, 0.0, 0), None);
        assert_eq!(stratified_bootstrap_ci(&runs, iqm, 100, 1.0, 0), None);
        assert_eq!(stratified_bootstrap_ci(&runs, iqm, 100, f64::NAN, 0), None);
        // Empty tasks contribute nothing: same result as without them.
        let with_empty = vec![vec![], v(&[1.0, 2.0]), vec![]];
        assert_eq!(
            stratified_bootstrap_ci(&with_empty, iqm, 500, 0.05, 9),
            stratified_bootstrap_ci(&runs, iqm, 500, 0.05, 9)
        );
        // A NaN-producing statistic does not panic.
        assert!(stratified_bootstrap_ci(&runs, |_: &[f64]| f64::NAN, 10, 0.05, 0).is_some());
    }

    #[test]
    fn stratified_bootstrap_with_inf_runs() {
        // The IQM of the 4 runs trims the one +inf, so the point is finite; a replicate may draw
        // +inf twice (then its IQM is +inf), so the upper bound may be +inf. Nothing is NaN.
        let runs = vec![v(&[1.0, 2.0, 3.0, INF])];
        let (p, lo, hi) = stratified_bootstrap_ci(&runs, iqm, 2_000, 0.05, 5).unwrap();
        assert_eq!(p, 2.5);
        assert!(lo.is_finite() && !hi.is_nan() && lo <= p && p <= hi);
    }

    #[test]
    fn probability_of_improvement_known_values() {
        // Clearly separated: X always lower (better) gives 1, always higher gives 0.
        let lo = vec![v(&[1.0, 2.0, 3.0])];
        let hi = vec![v(&[4.0, 5.0])];
        assert_eq!(probability_of_improvement(&lo, &hi), Some(1.0));
        assert_eq!(probability_of_improvement(&hi, &lo), Some(0.0));
        // Identical samples: 0.5.
        assert_eq!(probability_of_improvement(&lo, &lo), Some(0.5));
        // Ties count 1/2: x = [1, 2], y = [2, 3] -> (1 + 1 + 0.5 + 1) / 4.
        let x = vec![v(&[1.0, 2.0])];
        let y = vec![v(&[2.0, 3.0])];
        assert_eq!(probability_of_improvement(&x, &y), Some(0.875));
        assert_eq!(probability_of_improvement(&y, &x), Some(0.125));
        // Mean over tasks (unweighted): (1 + 0.875) / 2.
        let x2 = vec![v(&[1.0, 2.0, 3.0]), v(&[1.0, 2.0])];
        let y2 = vec![v(&[4.0, 5.0]), v(&[2.0, 3.0])];
        assert_eq!(probability_of_improvement(&x2, &y2), Some(0.9375));
    }

    #[test]
    fn probability_of_improvement_inf_and_bad_input() {
        // Finite beats +inf; +inf ties +inf.
        assert_eq!(
            probability_of_improvement(&[v(&[5.0])], &[v(&[INF])]),
            Some(1.0)
        );
        assert_eq!(
            probability_of_improvement(&[v(&[INF])], &[v(&[INF])]),
            Some(0.5)
        );
        assert_eq!(
            probability_of_improvement(&[v(&[1.0, INF])], &[v(&[2.0, INF])]),
            Some((1.0 + 1.0 + 0.0 + 0.5) / 4.0)
        );
        assert_eq!(probability_of_improvement(&[], &[]), None);
        assert_eq!(probability_of_improvement(&[v(&[1.0])], &[]), None);
        assert_eq!(probability_of_improvement(&[v(&[1.0])], &[vec![]]), None);
        assert_eq!(
            probability_of_improvement(&[v(&[f64::NAN])], &[v(&[1.0])]),
            None
        );
    }

    #[test]
    fn probability_of_improvement_ci_behaves() {
        let lo = vec![v(&[1.0, 2.0, 3.0]), v(&[0.5])];
        let hi = vec![v(&[4.0, 5.0]), v(&[0.9, 1.0])];
        // Separated in every task: every replicate is 1.
        assert_eq!(
            probability_of_improvement_ci(&lo, &hi, 1_000, 0.05, 0),
            Some((1.0, 1.0, 1.0))
        );
        assert_eq!(
            probability_of_improvement_ci(&hi, &lo, 1_000, 0.05, 0),
            Some((0.0, 0.0, 0.0))
        );
        // All values equal: every replicate is 0.5.
        let same = vec![v(&[3.0; 4]), v(&[3.0])];
        assert_eq!(
            probability_of_improvement_ci(&same, &same, 1_000, 0.05, 0),
            Some((0.5, 0.5, 0.5))
        );
        // Overlapping samples: seeded, reproducible, the interval holds the point.
        let x = vec![v(&[1.0, 2.0, 3.5, 2.2]), v(&[4.0, 4.4, 3.9])];
        let y = vec![v(&[2.0, 3.0, 2.5, 4.0]), v(&[4.1, 4.2, 5.0])];
        let a = probability_of_improvement_ci(&x, &y, 2_000, 0.05, 7).unwrap();
        assert_eq!(
            a,
            probability_of_improvement_ci(&x, &y, 2_000, 0.05, 7).unwrap()
        );
        assert_eq!(Some(a.0), probability_of_improvement(&x, &y));
        assert!(a.1 <= a.0 && a.0 <= a.2 && a.1 < a.2 && a.1 >= 0.0 && a.2 <= 1.0);
        // Bad input.
        assert_eq!(
            probability_of_improvement_ci(&x, &y[..1], 100, 0.05, 0),
            None
        );
        assert_eq!(probability_of_improvement_ci(&x, &y, 0, 0.05, 0), None);
        assert_eq!(probability_of_improvement_ci(&x, &y, 100, 1.5, 0), None);
    }

    #[test]
    fn area_under_curve_known_values() {
        // Constant curve: the constant, evenly or unevenly spaced.
        assert_eq!(area_under_curve(&[0.0, 1.0, 2.0, 3.0], &[2.5; 4]), Ok(2.5));
        let c = area_under_curve(&[0.0, 0.3, 1.7, 10.0], &[4.2; 4]).unwrap();
        assert!((c - 4.2).abs() < 1e-12);
        // Linear ramp 0 -> 1: 0.5, whatever the sampling and the epoch offset.
        assert_eq!(area_under_curve(&[0.0, 1.0], &[0.0, 1.0]), Ok(0.5));
        let e: Vec<f64> = (0..=10).map(|i| 5.0 + 2.0 * i as f64).collect();
        let r: Vec<f64> = (0..=10).map(|i| i as f64 / 10.0).collect();
        assert!((area_under_curve(&e, &r).unwrap() - 0.5).abs() < 1e-12);
        // A curve that drops early has a smaller area than one that drops late.
        let epochs = [0.0, 1.0, 2.0, 3.0];
        let early = area_under_curve(&epochs, &[5.0, 1.0, 1.0, 1.0]).unwrap();
        let late = area_under_curve(&epochs, &[5.0, 5.0, 5.0, 1.0]).unwrap();
        assert!(early < late);
        assert_eq!(early, (3.0 + 1.0 + 1.0) / 3.0);
    }

    #[test]
    fn area_under_curve_errors_and_inf() {
        assert_eq!(area_under_curve(&[], &[]), Err(AucError::TooFewPoints(0)));
        assert_eq!(
            area_under_curve(&[1.0], &[1.0]),
            Err(AucError::TooFewPoints(1))
        );
        assert_eq!(
            area_under_curve(&[0.0, 1.0], &[1.0]),
            Err(AucError::LengthMismatch {
                epochs: 2,
                values: 1
            })
        );
        assert_eq!(
            area_under_curve(&[0.0, 1.0, 1.0], &[1.0; 3]),
            Err(AucError::NotIncreasing { index: 2 })
        );
        assert_eq!(
            area_under_curve(&[0.0, 2.0, 1.0], &[1.0; 3]),
            Err(AucError::NotIncreasing { index: 2 })
        );
        assert_eq!(
            area_under_curve(&[0.0, f64::NAN], &[1.0; 2]),
            Err(AucError::NonFiniteEpoch { index: 1 })
        );
        assert_eq!(
            area_under_curve(&[0.0, INF], &[1.0; 2]),
            Err(AucError::NonFiniteEpoch { index: 1 })
        );
        assert_eq!(
            area_under_curve(&[0.0, 1.0], &[f64::NAN, 1.0]),
            Err(AucError::NanValue { index: 0 })
        );
        assert_eq!(
            area_under_curve(&[0.0, 1.0], &[INF, f64::NEG_INFINITY]),
            Err(AucError::MixedInfinities)
        );
        assert_eq!(
            area_under_curve(&[0.0, 1.0, 2.0], &[INF, 3.0, 2.0]),
            Ok(INF)
        );
    }
}
