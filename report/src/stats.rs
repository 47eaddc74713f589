//! Statistics over runs: mean, sample standard deviation and the percentile-bootstrap confidence
//! interval of the mean, as seaborn's `tsplot(..., ci=90)` drew it in the paper's notebooks:
//! resample the runs with replacement `n_boot` times, take the mean of each resample, and report
//! the 5th and 95th percentiles (numpy's default linear interpolation) of those means.
//!
//! KL-coverage can be `+inf`. A mean over values that include `+inf` is `+inf` (and says so through
//! [`Summary::n_inf`]); it is never turned into NaN. The standard deviation is `None` then.
//!
//! The rliable statistics (interquartile mean, stratified bootstrap, probability of improvement,
//! area under a curve) live in [`rliable`] and are re-exported here.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub mod rliable;
pub use rliable::{
    AucError, area_under_curve, difference_of_means_ci, iqm, probability_of_improvement,
    probability_of_improvement_ci, stratified_bootstrap_ci,
};

/// Summary of one sample (one value per run).
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Number of values.
    pub n: usize,
    /// Arithmetic mean; `+inf` when any value is `+inf` (and none is `-inf`).
    pub mean: f64,
    /// Sample standard deviation (ddof = 1); `None` with fewer than 2 values or any infinite value.
    pub std: Option<f64>,
    /// Lower bound of the percentile-bootstrap CI of the mean.
    pub ci_lo: f64,
    /// Upper bound of the percentile-bootstrap CI of the mean.
    pub ci_hi: f64,
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

/// Percentile-bootstrap CI of the mean at confidence `level` (e.g. 0.90 → 5th and 95th
/// percentiles of `n_boot` resampled means). One value gives a zero-width interval on it.
pub fn bootstrap_mean_ci(
    xs: &[f64],
    level: f64,
    n_boot: usize,
    rng: &mut ChaCha8Rng,
) -> (f64, f64) {
    assert!(!xs.is_empty(), "bootstrap of an empty sample");
    assert!(n_boot > 0, "n_boot must be positive");
    assert!(
        level > 0.0 && level < 1.0,
        "confidence level {level} outside (0, 1)"
    );
    let n = xs.len();
    if n == 1 || xs.iter().all(|&x| x == xs[0]) {
        return (xs[0], xs[0]);
    }
    let mut means = Vec::with_capacity(n_boot);
    let mut buf = vec![0.0; n];
    let mut draw = IndexSampler::new(n);
    for _ in 0..n_boot {
        for b in buf.iter_mut() {
            *b = xs[draw.next(rng)];
        }
        means.push(mean(&buf));
    }
    // total_cmp: -inf < finite < +inf; NaN (mixed infinities only) sorts last.
    means.sort_by(f64::total_cmp);
    let tail = (1.0 - level) / 2.0 * 100.0;
    (
        percentile_sorted(&means, tail),
        percentile_sorted(&means, 100.0 - tail),
    )
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

/// Mean, std and 90% bootstrap CI of `xs`, with the bootstrap stream seeded by `seed`.
pub fn summarize(xs: &[f64], n_boot: usize, seed: u64) -> Summary {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (ci_lo, ci_hi) = bootstrap_mean_ci(xs, 0.90, n_boot, &mut rng);
    Summary {
        n: xs.len(),
        mean: mean(xs),
        std: std_sample(xs),
        ci_lo,
        ci_hi,
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
/// 90% percentile-bootstrap CI of the mean difference (the pairs are resampled), seeded by `seed`.
/// `None` when no key is in both samples.
pub fn paired_summary(
    a: &[(i64, f64)],
    b: &[(i64, f64)],
    n_boot: usize,
    seed: u64,
) -> Option<Summary> {
    let d: Vec<f64> = paired_differences(a, b)
        .into_iter()
        .map(|(_, d)| d)
        .collect();
    (!d.is_empty()).then(|| summarize(&d, n_boot, seed))
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

    fn ci(xs: &[f64], n_boot: usize, seed: u64) -> (f64, f64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        bootstrap_mean_ci(xs, 0.90, n_boot, &mut rng)
    }

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
    fn identical_runs_give_zero_width_band_on_the_value() {
        let s = summarize(&[4.25, 4.25, 4.25, 4.25, 4.25], 10_000, 7);
        assert_eq!(s.mean, 4.25);
        assert_eq!((s.ci_lo, s.ci_hi), (4.25, 4.25));
        assert_eq!(s.std, Some(0.0));
        let one = summarize(&[3.0], 100, 0);
        assert_eq!(
            (one.mean, one.ci_lo, one.ci_hi, one.std),
            (3.0, 3.0, 3.0, None)
        );
    }

    #[test]
    fn two_point_case_is_exact() {
        // Resampled means of {0, 1}: 0 (p=1/4), 1/2 (p=1/2), 1 (p=1/4). With 10,000 resamples
        // the 5th percentile lies deep inside the block of zeros and the 95th inside the ones.
        for seed in 0..5 {
            assert_eq!(ci(&[0.0, 1.0], 10_000, seed), (0.0, 1.0));
        }
    }

    #[test]
    fn three_point_case_is_exact() {
        // Means of 3 draws from {0, 0, 1}: k/3 with k ~ Binomial(3, 1/3):
        // P(0)=8/27, P(1/3)=12/27, P(2/3)=6/27, P(1)=1/27. Cumulative: 0.296, 0.741, 0.963, 1.
        // So the 5th percentile is 0 and the 95th is 2/3 (0.963 is ~7 sd above 0.95).
        for seed in 0..5 {
            let (lo, hi) = ci(&[0.0, 0.0, 1.0], 10_000, seed);
            assert_eq!(lo, 0.0);
            assert_eq!(hi, mean(&[0.0, 1.0, 1.0]));
        }
    }

    #[test]
    fn ci_is_equivariant_and_monotone() {
        let xs = [4.1, 4.6, 4.3, 5.0, 4.4];
        let (lo, hi) = ci(&xs, 2_000, 3);
        assert!(lo <= mean(&xs) && mean(&xs) <= hi && lo < hi);
        // Shifting the data shifts the interval (same seed: same resampling indices).
        let shifted: Vec<f64> = xs.iter().map(|x| x + 1.5).collect();
        let (lo2, hi2) = ci(&shifted, 2_000, 3);
        assert!((lo2 - lo - 1.5).abs() < 1e-12 && (hi2 - hi - 1.5).abs() < 1e-12);
        // Increasing every value never lowers either bound.
        let bigger: Vec<f64> = xs
            .iter()
            .enumerate()
            .map(|(i, x)| x + 0.1 * i as f64)
            .collect();
        let (lo3, hi3) = ci(&bigger, 2_000, 3);
        assert!(lo3 >= lo && hi3 >= hi);
        // The interval lies within the data range.
        assert!(lo >= 4.1 && hi <= 5.0);
    }

    #[test]
    fn seeded_and_reproducible() {
        let xs = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(ci(&xs, 1_000, 11), ci(&xs, 1_000, 11));
        assert_eq!(summarize(&xs, 1_000, 5), summarize(&xs, 1_000, 5));
    }

    #[test]
    fn infinite_values_give_infinite_mean_not_nan() {
        let s = summarize(&[4.0, f64::INFINITY, 5.0], 2_000, 1);
        assert_eq!(s.mean, f64::INFINITY);
        assert_eq!(s.n_inf, 1);
        assert_eq!(s.std, None);
        assert!(!s.ci_lo.is_nan() && !s.ci_hi.is_nan());
        // P(no inf among 3 draws) = 8/27 = 0.30 > 0.05: the lower bound is finite, the upper is inf.
        assert!(s.ci_lo.is_finite());
        assert_eq!(s.ci_hi, f64::INFINITY);
        let all = summarize(&[f64::INFINITY, f64::INFINITY], 100, 1);
        assert_eq!(
            (all.mean, all.ci_lo, all.ci_hi),
            (f64::INFINITY, f64::INFINITY, f64::INFINITY)
        );
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
        assert_eq!(paired_summary(&a, &[(7, 1.0)], 100, 0), None);
    }

    #[test]
    fn constant_paired_differences_give_a_zero_width_ci_on_the_difference() {
        // Every corrected run is 0.5 below its faithful pair, whatever the spread of the runs.
        let faithful = [(0, 4.75), (1, 5.5), (2, 3.25), (3, 6.0), (4, 4.0)];
        let corrected: Vec<(i64, f64)> = faithful.iter().map(|&(s, v)| (s, v - 0.5)).collect();
        let d = paired_summary(&faithful, &corrected, 10_000, 3).unwrap();
        assert_eq!((d.n, d.mean, d.ci_lo, d.ci_hi), (5, -0.5, -0.5, -0.5));
        assert_eq!(d.std, Some(0.0));
        // The unpaired CIs of the two means are wide; the paired one is not.
        let fa: Vec<f64> = faithful.iter().map(|p| p.1).collect();
        let s = summarize(&fa, 10_000, 3);
        assert!(s.ci_hi - s.ci_lo > 0.5);
    }

    #[test]
    fn paired_ci_on_a_two_value_case_is_exact() {
        // Differences {0, 1}: as `two_point_case_is_exact`, the 90% CI is [0, 1], mean 0.5.
        let a = [(0, 2.0), (1, 3.0)];
        let b = [(0, 2.0), (1, 4.0)];
        let d = paired_summary(&a, &b, 10_000, 9).unwrap();
        assert_eq!((d.mean, d.ci_lo, d.ci_hi), (0.5, 0.0, 1.0));
    }

    #[test]
    fn derived_seeds_are_stable_and_distinct() {
        assert_eq!(derive_seed(0, "a"), derive_seed(0, "a"));
        assert_ne!(derive_seed(0, "a"), derive_seed(1, "a"));
        assert_ne!(derive_seed(0, "a"), derive_seed(0, "b"));
    }
}
