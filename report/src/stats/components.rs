//! How a condition's spread splits between its two levels of randomness (repetitions x
//! exploration replicates, `docs/statistics.md`): the one-way random-effects analysis of a
//! balanced design, by the method of moments (ANOVA estimators; e.g. Searle, Casella and
//! McCulloch 1992, Section 3.5).

/// The two standard deviations of a balanced two-level sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Components {
    /// Between repetitions beyond what the replicates explain: the part of a run's value due to
    /// the repetition (its data set and fit), `sqrt(max(0, (MSB - MSW) / k))`.
    pub between_sd: f64,
    /// Within a repetition: the part due to the exploration streams, `sqrt(MSW)`.
    pub within_sd: f64,
}

/// The components of `groups` (one group per repetition, the values of its replicates); `None`
/// unless there are at least two groups, all of the same size `k >= 2`, and every value is
/// finite.
pub fn one_way(groups: &[Vec<f64>]) -> Option<Components> {
    let n = groups.len();
    let k = groups.first()?.len();
    if n < 2
        || k < 2
        || groups
            .iter()
            .any(|g| g.len() != k || g.iter().any(|v| !v.is_finite()))
    {
        return None;
    }
    let means: Vec<f64> = groups
        .iter()
        .map(|g| g.iter().sum::<f64>() / k as f64)
        .collect();
    let grand = means.iter().sum::<f64>() / n as f64;
    let ss_within: f64 = groups
        .iter()
        .zip(&means)
        .map(|(g, m)| g.iter().map(|v| (v - m).powi(2)).sum::<f64>())
        .sum();
    let ms_within = ss_within / (n * (k - 1)) as f64;
    let ms_between =
        k as f64 * means.iter().map(|m| (m - grand).powi(2)).sum::<f64>() / (n - 1) as f64;
    Some(Components {
        between_sd: ((ms_between - ms_within) / k as f64).max(0.0).sqrt(),
        within_sd: ms_within.sqrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_spread_within_repetitions() {
        // Equal repetition means: nothing is due to the repetition.
        let c = one_way(&[vec![1.0, 3.0], vec![1.0, 3.0], vec![3.0, 1.0]]).unwrap();
        assert_eq!(c.between_sd, 0.0);
        assert!((c.within_sd - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn all_spread_between_repetitions() {
        // Identical replicates: everything is due to the repetition. MSB = 2 * (1 + 1) / 1 = 4,
        // so the between variance is 4 / 2 = 2.
        let c = one_way(&[vec![0.0, 0.0], vec![2.0, 2.0]]).unwrap();
        assert_eq!(c.within_sd, 0.0);
        assert!((c.between_sd - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn recovers_known_components_from_a_seeded_sample() {
        use crate::stats::coverage::normal;
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let groups: Vec<Vec<f64>> = (0..2000)
            .map(|_| {
                let f = 0.2 * normal(&mut rng);
                (0..3).map(|_| 4.0 + f + 0.3 * normal(&mut rng)).collect()
            })
            .collect();
        let c = one_way(&groups).unwrap();
        assert!((c.between_sd - 0.2).abs() < 0.02, "{c:?}");
        assert!((c.within_sd - 0.3).abs() < 0.01, "{c:?}");
    }

    #[test]
    fn unbalanced_short_or_infinite_samples_have_none() {
        assert_eq!(one_way(&[vec![1.0, 2.0]]), None);
        assert_eq!(one_way(&[vec![1.0], vec![2.0]]), None);
        assert_eq!(one_way(&[vec![1.0, 2.0], vec![2.0]]), None);
        assert_eq!(one_way(&[vec![1.0, f64::INFINITY], vec![2.0, 3.0]]), None);
    }
}
