//! Statistics over runs: mean, sample standard deviation and the confidence interval of the
//! mean, Student's t interval at [`CONFIDENCE`] ([`interval`] says why t and not the percentile
//! bootstrap the paper's notebooks drew with `seaborn.tsplot(ci=90)`: at 5 seeds the bootstrap
//! under-covers).
//!
//! KL-coverage can be `+inf`. A mean over values that include `+inf` is `+inf` (and says so through
//! [`Summary::n_inf`]); it is never turned into NaN. The standard deviation and the interval are
//! `None` then.
//!
//! The rliable statistics (interquartile mean, stratified bootstrap, probability of improvement,
//! area under a curve) live in [`rliable`] and are re-exported here.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub mod components;
pub mod correlation;
#[cfg(test)]
pub(crate) mod coverage;
pub mod interval;
pub mod rliable;
pub use interval::{
    IntervalError, SampleSummary, TInterval, prediction_interval, student_t_quantile, t_interval,
    welch_interval, welch_interval_of,
};
pub use rliable::{
    AucError, area_under_curve, exact_bound_at_extreme, improvement_counts, iqm,
    per_task_mean_bootstrap, percentile_ci, probability_of_improvement,
    probability_of_improvement_ci, stratified_bootstrap_ci,
};

/// The confidence level of every interval of the report: the tables, the figures' bands, the
/// claims (`settings.confidence` of the claims files) and the leaderboard.
pub const CONFIDENCE: f64 = 0.95;

/// Summary of one sample (one value per run).
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Number of values.
    pub n: usize,
    /// Arithmetic mean; `+inf` when any value is `+inf` (and none is `-inf`).
    pub mean: f64,
    /// Sample standard deviation (ddof = 1); `None` with fewer than 2 values or any infinite value.
    pub std: Option<f64>,
    /// Student's t interval of the mean at [`CONFIDENCE`], `(lo, hi)`; `None` ("no interval")
    /// with fewer than 2 values or any infinite value.
    pub ci: Option<(f64, f64)>,
    /// How many values are infinite.
    pub n_inf: usize,
}

/// Arithmetic mean. Empty input gives NaN; any `+inf` gives `+inf` (a mix of `+inf` and `-inf`
/// has no mean and gives NaN).
pub fn mean(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let pos_inf = xs.contains(&f64::INFINITY);
    let neg_inf = xs.contains(&f64::NEG_INFINITY);
    match (pos_inf, neg_inf) {
        (true, true) => f64::NAN,
        (true, false) => f64::INFINITY,
        (false, true) => f64::NEG_INFINITY,
        (false, false) => xs.iter().sum::<f64>() / xs.len() as f64,
    }
}

/// Sample standard deviation (ddof = 1); `None` for fewer than 2 values or non-finite values.
pub fn std_sample(xs: &[f64]) -> Option<f64> {
    if xs.len() < 2 || xs.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let m = mean(xs);
    let ss: f64 = xs.iter().map(|x| (x - m) * (x - m)).sum();
    Some((ss / (xs.len() - 1) as f64).sqrt())
}

/// Percentile `q` (0..=100) of an ascending-sorted slice with numpy's default ("linear")
/// interpolation: position `q/100 * (n-1)`, interpolated between its two neighbours.
/// Neighbours that are equal (both `inf` included) give that value exactly; a position that falls
/// exactly on an element gives that element.
pub fn percentile_sorted(sorted: &[f64], q: f64) -> f64 {
    assert!(!sorted.is_empty(), "percentile of an empty sample");
    assert!((0.0..=100.0).contains(&q), "percentile {q} outside 0..=100");
    let pos = q / 100.0 * (sorted.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    let (a, b) = (sorted[lo], sorted[hi]);
    let frac = pos - lo as f64;
    if a == b || frac == 0.0 {
        a
    } else if frac == 1.0 {
        b
    } else {
        a + (b - a) * frac
    }
}

/// Uniform indices in `0..n` drawn from a ChaCha8 stream with as few random bits as possible:
/// `k`-bit chunks of `next_u64` outputs with rejection (a chunk `c` is accepted when it is below
/// the largest multiple of `n` that fits in `k` bits, and gives `c % n`), so every index is exactly
/// equally likely. `k` minimises the expected bits per index (4 bits, 94% accepted, for 5 seeds).
/// The generator is the cost of the bootstrap (ChaCha at the dev profile's opt-level 0 costs
/// ~50 ns per byte); `random_range` would spend 32 bits per index.
#[derive(Debug, Clone)]
pub struct IndexSampler {
    n: u64,
    k: u32,
    zone: u64,
    bits: u64,
    left: u32,
}

impl IndexSampler {
    pub fn new(n: usize) -> Self {
        assert!(n > 0, "no index to draw");
        let n = n as u64;
        let k_min = (64 - (n - 1).leading_zeros()).max(1);
        let k_max = k_min.clamp(16, 63);
        let (mut best_k, mut best_cost) = (k_min, f64::INFINITY);
        for k in k_min..=k_max {
            let span = 1u64 << k;
            let zone = span - span % n;
            let cost = k as f64 * span as f64 / zone as f64;
            if cost < best_cost {
                (best_k, best_cost) = (k, cost);
            }
        }
        let span = 1u64 << best_k;
        IndexSampler {
            n,
            k: best_k,
            zone: span - span % n,
            bits: 0,
            left: 0,
        }
    }

    /// The next index in `0..n`.
    pub fn next(&mut self, rng: &mut ChaCha8Rng) -> usize {
        loop {
            if self.left < self.k {
                self.bits = rng.next_u64();
                self.left = 64;
            }
            let c = self.bits & ((1u64 << self.k) - 1);
            self.bits >>= self.k;
            self.left -= self.k;
            if c < self.zone {
                return (c % self.n) as usize;
            }
        }
    }
}

/// Mean, std and the [`CONFIDENCE`] t interval of the mean of `xs` ([`t_interval`]).
pub fn summarize(xs: &[f64]) -> Summary {
    Summary {
        n: xs.len(),
        mean: mean(xs),
        std: std_sample(xs),
        ci: t_interval(xs, CONFIDENCE).ok().map(|i| (i.lo, i.hi)),
        n_inf: xs.iter().filter(|x| x.is_infinite()).count(),
    }
}

/// Pairs two samples by key (the seed: runs with the same seed share their initial weights and
/// batches) and returns `(key, b − a)` for every key present in both, sorted by key. Keys present
/// in only one sample are left out; each key must appear at most once per sample.
pub fn paired_differences(a: &[(i64, f64)], b: &[(i64, f64)]) -> Vec<(i64, f64)> {
    let a: std::collections::BTreeMap<i64, f64> = a.iter().copied().collect();
    let mut out: Vec<(i64, f64)> = b
        .iter()
        .filter_map(|&(k, vb)| a.get(&k).map(|&va| (k, vb - va)))
        .collect();
    out.sort_by_key(|&(k, _)| k);
    out
}

/// Summary of the paired differences `b − a` (see [`paired_differences`]): their mean, sd and
/// the paired t interval of the mean difference ([`summarize`] of the differences; no interval
/// with fewer than 2 pairs). `None` when no key is in both samples.
pub fn paired_summary(a: &[(i64, f64)], b: &[(i64, f64)]) -> Option<Summary> {
    let d: Vec<f64> = paired_differences(a, b)
        .into_iter()
        .map(|(_, d)| d)
        .collect();
    (!d.is_empty()).then(|| summarize(&d))
}

/// A stable 64-bit seed for one bootstrap stream, from the report's seed and a label (condition
/// and epoch). FNV-1a over the bytes, then the splitmix64 finaliser: fixed by this code, not by
/// `std`'s hasher, so it never changes between Rust versions; adding a condition never shifts
/// the stream of another.
pub fn derive_seed(base: u64, label: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in base.to_le_bytes().iter().chain(label.as_bytes()) {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h = h.wrapping_add(0x9e37_79b9_7f4a_7c15);
    h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^ (h >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn mean_and_std_known_values() {
        assert_eq!(mean(&[1.0, 2.0, 3.0, 4.0]), 2.5);
        let s = std_sample(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]).unwrap();
        assert!((s - 2.138_089_935_299_395).abs() < 1e-12);
        assert_eq!(std_sample(&[1.0]), None);
        assert!(mean(&[]).is_nan());
    }

    #[test]
    fn percentile_matches_numpy_linear() {
        let v = [1.0, 2.0, 3.0, 4.0, 10.0];
        // numpy.percentile([1,2,3,4,10], [5, 50, 95]) = [1.2, 3.0, 8.8]
        assert!((percentile_sorted(&v, 5.0) - 1.2).abs() < 1e-12);
        assert_eq!(percentile_sorted(&v, 50.0), 3.0);
        assert!((percentile_sorted(&v, 95.0) - 8.8).abs() < 1e-12);
        assert_eq!(percentile_sorted(&v, 0.0), 1.0);
        assert_eq!(percentile_sorted(&v, 100.0), 10.0);
        let w = [1.0, f64::INFINITY, f64::INFINITY];
        assert_eq!(percentile_sorted(&w, 75.0), f64::INFINITY);
        assert_eq!(percentile_sorted(&w, 0.0), 1.0);
        assert_eq!(percentile_sorted(&w, 25.0), f64::INFINITY);
    }

    #[test]
    fn identical_runs_give_zero_width_interval_and_one_run_none() {
        let s = summarize(&[4.25, 4.25, 4.25, 4.25, 4.25]);
        assert_eq!(s.mean, 4.25);
        assert_eq!(s.ci, Some((4.25, 4.25)));
        assert_eq!(s.std, Some(0.0));
        let one = summarize(&[3.0]);
        assert_eq!((one.mean, one.ci, one.std), (3.0, None, None));
    }

    #[test]
    fn summary_interval_is_the_t_interval() {
        // mean 3, sd √2.5, n 5: 3 ± t(0.975; 4) · √0.5.
        let s = summarize(&[1.0, 2.0, 3.0, 4.0, 5.0]);
        let (lo, hi) = s.ci.unwrap();
        let half = 2.776_445_105_198 * 0.5f64.sqrt();
        assert!((lo - (3.0 - half)).abs() < 1e-10 && (hi - (3.0 + half)).abs() < 1e-10);
        // Shifting the data shifts the interval.
        let t = summarize(&[2.5, 3.5, 4.5, 5.5, 6.5]).ci.unwrap();
        assert!((t.0 - lo - 1.5).abs() < 1e-12 && (t.1 - hi - 1.5).abs() < 1e-12);
    }

    #[test]
    fn infinite_values_give_infinite_mean_and_no_interval() {
        let s = summarize(&[4.0, f64::INFINITY, 5.0]);
        assert_eq!(s.mean, f64::INFINITY);
        assert_eq!(s.n_inf, 1);
        assert_eq!((s.std, s.ci), (None, None));
        let all = summarize(&[f64::INFINITY, f64::INFINITY]);
        assert_eq!((all.mean, all.ci), (f64::INFINITY, None));
    }

    #[test]
    fn index_sampler_is_uniform_and_in_range() {
        for n in [2usize, 3, 5, 7, 10, 17, 100, 1000] {
            let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
            let mut s = IndexSampler::new(n);
            let draws = 2_000 * n;
            let mut counts = vec![0usize; n];
            for _ in 0..draws {
                counts[s.next(&mut rng)] += 1;
            }
            // Chi-square with n-1 degrees of freedom: mean n-1, sd sqrt(2(n-1)); allow 6 sd.
            let e = draws as f64 / n as f64;
            let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
            let df = (n - 1) as f64;
            assert!(chi2 < df + 6.0 * (2.0 * df).sqrt(), "n={n}: chi2 {chi2}");
        }
        assert_eq!(IndexSampler::new(5).k, 4);
        assert_eq!(IndexSampler::new(2).k, 1);
        assert_eq!(IndexSampler::new(1).k, 1);
    }

    #[test]
    fn paired_differences_match_by_seed() {
        let a = [(0, 4.0), (1, 5.0), (2, 6.0), (4, 1.0)];
        let b = [(2, 6.5), (0, 3.0), (1, 5.25), (3, 9.0)];
        assert_eq!(
            paired_differences(&a, &b),
            vec![(0, -1.0), (1, 0.25), (2, 0.5)]
        );
        assert_eq!(paired_summary(&a, &[(7, 1.0)]), None);
        // One pair: a difference, no interval.
        let one = paired_summary(&a, &[(4, 2.0)]).unwrap();
        assert_eq!((one.mean, one.ci), (1.0, None));
    }

    #[test]
    fn constant_paired_differences_give_a_zero_width_ci_on_the_difference() {
        // Every corrected run is 0.5 below its faithful pair, whatever the spread of the runs.
        let faithful = [(0, 4.75), (1, 5.5), (2, 3.25), (3, 6.0), (4, 4.0)];
        let corrected: Vec<(i64, f64)> = faithful.iter().map(|&(s, v)| (s, v - 0.5)).collect();
        let d = paired_summary(&faithful, &corrected).unwrap();
        assert_eq!((d.n, d.mean, d.ci), (5, -0.5, Some((-0.5, -0.5))));
        assert_eq!(d.std, Some(0.0));
        // The unpaired interval of a mean is wide; the paired one is not.
        let fa: Vec<f64> = faithful.iter().map(|p| p.1).collect();
        let (lo, hi) = summarize(&fa).ci.unwrap();
        assert!(hi - lo > 0.5);
    }

    /// Pinned values, computed independently (FNV-1a over the base's little-endian bytes and the
    /// label, then splitmix64's finaliser, in Python's arbitrary-precision integers masked to 64
    /// bits): a change of the derivation, or of what it hashes, shows here.
    #[test]
    fn derived_seeds_are_stable_and_distinct() {
        assert_eq!(derive_seed(0, "a"), 0x263d_d4e1_0afb_da9a);
        assert_eq!(derive_seed(1, "a"), 0x9c0b_4f54_7ca2_1095);
        assert_eq!(derive_seed(0, "b"), 0xbb93_bebb_28b0_5074);
        assert_eq!(
            derive_seed(12345, "leaderboard/armball/10"),
            0xbc5f_d951_4da5_655f
        );
    }
}
