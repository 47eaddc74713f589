//! Does latent quality predict exploration once the number of moves is accounted for?
//!
//! KL-coverage mostly counts how often the object moved, and a goal space whose latents encode
//! the object's position well may simply move it more often. Over the learned-goal-space runs
//! of the main campaign and its `recipe` campaigns (the untrained twins of `paper-init`, ...),
//! per environment and per measure of discovery ([`crate::discovery::Measure`]), this section
//! correlates the held-out k-NN R² of the position from the latents with the measure, raw and
//! partial given ln(1 + moves), and asks how much R² position quality adds to a regression of
//! the measure on ln(1 + moves): a part of `REPORT.md` and `data/latent_quality_vs_moves.csv`.
//!
//! Everything is closed-form (least squares, Pearson, Fisher's z): no resampling, so the
//! numbers are deterministic.

use ugl_types::EnvSpec;

use crate::campaigns::Campaigns;
use crate::discovery::{Measure, RunRow};
use crate::load::Run;
use crate::stats::correlation::{fisher_ci, partial_r, pearson};
use crate::stats::{self, CONFIDENCE};

/// The measures of discovery the table reads, in its order, with their names in the data file.
pub const MEASURES: [(Measure, &str); 4] = [
    (Measure::FinalKlc, "final_klc"),
    (Measure::MovedKlc, "moved_klc"),
    (Measure::Coverage, "coverage"),
    (Measure::GoalErrorMean, "goal_error_mean"),
];

/// Goal spaces without latents (no latent quality): random parameter exploration and the
/// engineered features.
pub const WITHOUT_LATENTS: [ugl_types::Algo; 2] = [ugl_types::Algo::RPE, ugl_types::Algo::RGE_EFR];

// ---------------------------------------------------------------------------------------------
// Least squares, correlation, Fisher's z.

/// One line of the table: a measure `y` against latent quality `x`, controlling for
/// `z` = ln(1 + moves). Every statistic is None where it is undefined (too few points, a
/// constant sample).
#[derive(Debug, Clone, PartialEq)]
pub struct Association {
    pub n: usize,
    /// Pearson's r of `x` with `y`, and its Fisher-z interval (n − 3).
    pub r: Option<f64>,
    pub r_ci: Option<(f64, f64)>,
    /// The partial r given `z`, and its Fisher-z interval (n − 4).
    pub partial: Option<f64>,
    pub partial_ci: Option<(f64, f64)>,
    /// R² of the regression of `y` on `z` alone.
    pub r2_moves: Option<f64>,
    /// R² of `y` on `z` and `x`: `r2_moves + gain`.
    pub r2_both: Option<f64>,
    /// What adding `x` adds: `(1 − r2_moves) · partial²` (the identity of least squares).
    pub gain: Option<f64>,
}

impl Association {
    /// The statistics of `y` against `x` given `z` at [`CONFIDENCE`]; None with fewer than 4
    /// points or differing lengths.
    pub fn compute(x: &[f64], y: &[f64], z: &[f64]) -> Option<Association> {
        let n = y.len();
        if n < 4 || x.len() != n || z.len() != n {
            return None;
        }
        let r = pearson(x, y);
        let partial = partial_r(x, y, z);
        let r2_moves = pearson(z, y).map(|r| r * r);
        let gain = r2_moves.zip(partial).map(|(r2, p)| (1.0 - r2) * p * p);
        Some(Association {
            n,
            r,
            r_ci: r.and_then(|r| fisher_ci(r, n, 0, CONFIDENCE)),
            partial,
            partial_ci: partial.and_then(|p| fisher_ci(p, n, 1, CONFIDENCE)),
            r2_moves,
            r2_both: r2_moves.zip(gain).map(|(a, g)| a + g),
            gain,
        })
    }

    /// Whether `x` still predicts `y` beyond `z`: the partial r's interval excludes 0 (None:
    /// untestable).
    pub fn predicts_beyond_moves(&self) -> Option<bool> {
        self.partial_ci.map(|(lo, hi)| lo > 0.0 || hi < 0.0)
    }
}

// ---------------------------------------------------------------------------------------------
// The observations.

/// One observation: a learned-goal-space run (or the mean of the exploration replicates of one
/// fit with one goal sampler, where a campaign holds several).
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    pub campaign: String,
    pub env: String,
    pub algo: String,
    pub variant: String,
    pub sampler: String,
    pub latents: i64,
    pub seed: i64,
    /// How many runs it averages.
    pub n_runs: usize,
    /// Held-out k-NN R² of the object's position from the latents.
    pub position_knn_r2: f64,
    /// ln(1 + episodes that moved the object).
    pub ln_moves: f64,
    /// The value of each of [`MEASURES`] (None: not measured, or not finite).
    pub values: [Option<f64>; MEASURES.len()],
}

/// Whether a run is in a learned goal space with a recorded position R².
fn has_latents(run: &Run) -> bool {
    !WITHOUT_LATENTS.contains(&run.key.algo) && run.manifest.group_r2("position").is_some()
}

/// The observations of the main campaign and its `recipe` campaigns: every learned-goal-space
/// run with a position R² and outcomes measured, replicates of one fit and sampler averaged; in
/// campaign order, then the report's condition order and seed. `measured` is every run the
/// report reads, measured ([`discovery::measure_all`]).
pub fn observations(camps: &Campaigns, measured: &[RunRow<'_>]) -> Vec<Observation> {
    let read: Vec<&str> = std::iter::once(&camps.main)
        .chain(&camps.recipe)
        .map(|c| c.name.as_str())
        .collect();
    let rows: Vec<&RunRow<'_>> = measured
        .iter()
        .filter(|r| read.contains(&r.campaign.name.as_str()) && has_latents(r.run))
        .filter(|r| r.discovery.is_some())
        .collect();
    // `measure_all` lists a campaign's runs in condition order, then seed: the runs of one fit
    // and sampler are adjacent.
    let same = |a: &RunRow<'_>, b: &RunRow<'_>| {
        a.campaign.name == b.campaign.name && a.run.key == b.run.key && a.run.seed == b.run.seed
    };
    let mut out = Vec::new();
    let mut i = 0;
    while i < rows.len() {
        let j = i + rows[i..].iter().take_while(|r| same(r, rows[i])).count();
        out.push(observe(&rows[i..j]));
        i = j;
    }
    out
}

/// The mean over the replicates `reps` (one fit, one sampler; at least one, every one measured
/// and with a position R²); a mean is None where a replicate lacks the value or it is not finite.
fn observe(reps: &[&RunRow<'_>]) -> Observation {
    let mean_of = |f: &dyn Fn(&RunRow<'_>) -> Option<f64>| -> Option<f64> {
        let v: Option<Vec<f64>> = reps
            .iter()
            .map(|r| f(r).filter(|v| v.is_finite()))
            .collect();
        v.map(|v| stats::mean(&v))
    };
    let first = &reps[0];
    let key = &first.run.key;
    Observation {
        campaign: first.campaign.name.clone(),
        env: key.env.clone(),
        algo: key.algo.to_string(),
        variant: key.variant.to_string(),
        sampler: key.sampler.to_string(),
        latents: key.latents,
        seed: first.run.seed,
        n_runs: reps.len(),
        position_knn_r2: mean_of(&|r| r.run.manifest.group_r2("position").map(|g| g.1))
            .unwrap_or(f64::NAN),
        ln_moves: mean_of(&|r| r.discovery.as_ref().map(|d| (1.0 + d.n_moved as f64).ln()))
            .unwrap_or(f64::NAN),
        values: MEASURES.map(|(m, _)| mean_of(&|r| m.value(r))),
    }
}

/// One line of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    pub env: String,
    pub measure: Measure,
    /// None: fewer than 4 observations with the measure.
    pub stats: Option<Association>,
}

/// The environments of the observations, in the report's order.
pub fn envs(obs: &[Observation]) -> Vec<String> {
    let mut envs: Vec<String> = obs.iter().map(|o| o.env.clone()).collect();
    envs.sort_by_key(|e| (EnvSpec::order(e), e.clone()));
    envs.dedup();
    envs
}

/// The table: per environment and measure, position R² against the measure given ln(1 + moves).
pub fn table(obs: &[Observation]) -> Vec<Line> {
    let mut out = Vec::new();
    for env in envs(obs) {
        for (k, (m, _)) in MEASURES.into_iter().enumerate() {
            let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
            for o in obs.iter().filter(|o| o.env == env) {
                if let Some(v) = o.values[k]
                    && o.position_knn_r2.is_finite()
                    && o.ln_moves.is_finite()
                {
                    x.push(o.position_knn_r2);
                    y.push(v);
                    z.push(o.ln_moves);
                }
            }
            out.push(Line {
                env: env.clone(),
                measure: m,
                stats: Association::compute(&x, &y, &z),
            });
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// The data file and the words.

#[cfg(test)]
mod tests {
    use super::*;
    use crate::markdown::predicts::section;
    use crate::stats::correlation::{normal_quantile, residuals};
    use std::path::Path;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// Three mutually orthogonal, centred contrasts of 8 points.
    const Z: [f64; 8] = [1.0, 1.0, 1.0, 1.0, -1.0, -1.0, -1.0, -1.0];
    const E: [f64; 8] = [1.0, 1.0, -1.0, -1.0, 1.0, 1.0, -1.0, -1.0];
    const U: [f64; 8] = [1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0];

    fn combine(a: f64, p: &[f64; 8], b: f64, q: &[f64; 8], c: f64) -> Vec<f64> {
        p.iter().zip(q).map(|(p, q)| a * p + b * q + c).collect()
    }

    /// y = [1, 2, 2, 5] on x = [0, 1, 2, 3]: slope 6/5, intercept 0.7, fitted
    /// [0.7, 1.9, 3.1, 4.3], residuals [0.3, 0.1, -1.1, 0.7] (by hand).
    #[test]
    fn residuals_of_a_hand_computed_regression() {
        let r = residuals(&[1.0, 2.0, 2.0, 5.0], &[0.0, 1.0, 2.0, 3.0]).unwrap();
        for (a, b) in r.iter().zip([0.3, 0.1, -1.1, 0.7]) {
            assert!(close(*a, b, 1e-12), "{r:?}");
        }
        assert!(close(r.iter().sum::<f64>(), 0.0, 1e-12));
        // Pearson of the same: 6 / √(5 · 9).
        let p = pearson(&[0.0, 1.0, 2.0, 3.0], &[1.0, 2.0, 2.0, 5.0]).unwrap();
        assert!(close(p, 6.0 / 45f64.sqrt(), 1e-12), "{p}");
    }

    /// moves z, quality x = z + e/2, y = 3z + u/2 (e, u orthogonal to z and each other): y
    /// depends on the moves only. Raw r = 24 / √(10 · 74) ≈ 0.88, partial r = 0.
    #[test]
    fn a_measure_that_depends_on_moves_only_has_no_partial_correlation() {
        let z: Vec<f64> = Z.iter().map(|v| v + 3.0).collect();
        let x = combine(1.0, &Z, 0.5, &E, 0.9);
        let y = combine(3.0, &Z, 0.5, &U, 10.0);
        let a = Association::compute(&x, &y, &z).unwrap();
        let r = a.r.unwrap();
        assert!(close(r, 24.0 / (10.0f64 * 74.0).sqrt(), 1e-12), "{r}");
        assert!(r > 0.85);
        assert!(close(a.partial.unwrap(), 0.0, 1e-12), "{a:?}");
        assert_eq!(a.predicts_beyond_moves(), Some(false));
        assert!(close(a.r2_moves.unwrap(), 72.0 / 74.0, 1e-12));
        assert!(close(a.gain.unwrap(), 0.0, 1e-12));
    }

    /// y = −2x + 5z exactly: given z, y is a function of x, partial r = −1 (and the gain is
    /// everything the moves leave).
    #[test]
    fn a_measure_that_depends_on_quality_has_partial_correlation_minus_one() {
        let z: Vec<f64> = Z.iter().map(|v| v + 3.0).collect();
        let x = combine(1.0, &Z, 0.5, &E, 0.9);
        let y: Vec<f64> = x.iter().zip(&z).map(|(x, z)| -2.0 * x + 5.0 * z).collect();
        let a = Association::compute(&x, &y, &z).unwrap();
        assert!(close(a.partial.unwrap(), -1.0, 1e-12), "{a:?}");
        let (lo, hi) = a.partial_ci.unwrap();
        assert!(close(lo, -1.0, 1e-6) && close(hi, -1.0, 1e-6), "{a:?}");
        assert_eq!(a.predicts_beyond_moves(), Some(true));
        assert!(close(a.r2_both.unwrap(), 1.0, 1e-12), "{a:?}");
        // y = 3Z − E + 13.2: R² on z alone 72 / (72 + 8).
        assert!(close(a.r2_moves.unwrap(), 0.9, 1e-12), "{a:?}");
        assert!(close(a.gain.unwrap(), 0.1, 1e-12), "{a:?}");
    }

    /// The gain equals the R² of a direct two-predictor least-squares fit, solved here by the
    /// normal equations on centred data (Cramer's rule).
    #[test]
    fn the_gain_matches_a_two_predictor_fit() {
        let z = [0.0, 1.0, 1.0, 2.0, 3.0, 5.0, 8.0, 13.0, 21.0];
        let x = [0.9, 0.1, 0.5, 0.3, 0.8, 0.2, 0.95, 0.6, 0.7];
        let y = [3.0, 1.0, 4.0, 1.0, 5.0, 9.0, 2.0, 6.0, 5.0];
        let a = Association::compute(&x, &y, &z).unwrap();
        let c = |v: &[f64]| {
            let m = stats::mean(v);
            v.iter().map(|x| x - m).collect::<Vec<_>>()
        };
        let (cz, cx, cy) = (c(&z), c(&x), c(&y));
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
        let (szz, sxx, szx) = (dot(&cz, &cz), dot(&cx, &cx), dot(&cz, &cx));
        let (szy, sxy, syy) = (dot(&cz, &cy), dot(&cx, &cy), dot(&cy, &cy));
        let det = szz * sxx - szx * szx;
        let bz = (szy * sxx - sxy * szx) / det;
        let bx = (sxy * szz - szy * szx) / det;
        let r2 = (bz * szy + bx * sxy) / syy;
        assert!(close(a.r2_both.unwrap(), r2, 1e-12), "{a:?} vs {r2}");
        assert!(close(a.r2_moves.unwrap(), szy * szy / (szz * syy), 1e-12));
    }

    /// r = 0.5 over n = 28: z = atanh 0.5 ± 1.959964 / 5, [0.156028, 0.735818] (Python's
    /// `statistics.NormalDist` and `math`).
    #[test]
    fn fisher_interval_of_a_known_value() {
        assert!(close(normal_quantile(0.975), 1.959_963_984_540_054, 1e-15));
        assert!(close(normal_quantile(0.025), -1.959_963_984_540_054, 1e-15));
        assert!(close(normal_quantile(0.5), 0.0, 0.0));
        assert!(close(normal_quantile(1e-10), -6.361_340_902_404_056, 1e-12));
        let (lo, hi) = fisher_ci(0.5, 28, 0, 0.95).unwrap();
        assert!(close(lo, 0.156_028_362_529_086_03, 1e-12), "{lo}");
        assert!(close(hi, 0.735_818_479_443_937_6, 1e-12), "{hi}");
        // The partial r of 29 points has the same 25 degrees of freedom.
        assert_eq!(fisher_ci(0.5, 29, 1, 0.95), Some((lo, hi)));
        assert_eq!(fisher_ci(0.0, 28, 0, 0.95).map(|c| c.0 == -c.1), Some(true));
    }

    /// Too few points, constant samples, a predictor that is a linear function of the moves:
    /// None, never NaN or a panic.
    #[test]
    fn degenerate_inputs_give_none() {
        assert_eq!(
            Association::compute(&[1.0, 2.0, 3.0], &[1.0, 0.0, 2.0], &[0.0, 1.0, 1.0]),
            None
        );
        assert_eq!(Association::compute(&[], &[], &[]), None);
        assert_eq!(Association::compute(&[1.0; 4], &[1.0; 5], &[1.0; 5]), None);
        assert_eq!(pearson(&[1.0, 2.0], &[2.0, 1.0]), None);
        assert_eq!(residuals(&[1.0], &[1.0]), None);
        assert_eq!(
            partial_r(&[1.0, 2.0, 3.0], &[1.0, 0.0, 2.0], &[0.0, 1.0, 1.0]),
            None
        );
        assert_eq!(fisher_ci(0.3, 3, 0, 0.95), None);
        assert_eq!(fisher_ci(0.3, 4, 1, 0.95), None);
        assert_eq!(fisher_ci(f64::NAN, 30, 0, 0.95), None);
        assert!(normal_quantile(0.0).is_nan() && normal_quantile(1.0).is_nan());

        let z = [0.0, 1.0, 2.0, 3.0, 4.0];
        let y = [1.0, 3.0, 2.0, 5.0, 4.0];
        // A constant quality (0.9 five times: rounding leaves a tiny spread): no r, no partial.
        let a = Association::compute(&[0.9; 5], &y, &z).unwrap();
        assert_eq!(
            (a.r, a.partial, a.gain, a.r2_both),
            (None, None, None, None)
        );
        assert!(a.r2_moves.is_some());
        // A constant measure: nothing.
        let a = Association::compute(&[0.1, 0.5, 0.2, 0.9, 0.4], &[2.0; 5], &z).unwrap();
        assert_eq!((a.r, a.partial, a.r2_moves), (None, None, None));
        // Constant moves: no partial.
        let a = Association::compute(&[0.1, 0.5, 0.2, 0.9, 0.4], &y, &[3.0; 5]).unwrap();
        assert!(a.r.is_some());
        assert_eq!((a.partial, a.r2_moves, a.gain), (None, None, None));
        // Quality a linear function of the moves: its residual is rounding noise.
        let x: Vec<f64> = z.iter().map(|z| 0.1 * z + 0.3).collect();
        let a = Association::compute(&x, &y, &z).unwrap();
        assert!(close(a.r.unwrap(), a.r2_moves.unwrap().sqrt(), 1e-12));
        assert_eq!(a.partial, None);
        // Nothing non-finite anywhere.
        let a = Association::compute(&[0.1, 0.5, f64::INFINITY, 0.9], &y[..4], &z[..4]).unwrap();
        assert_eq!((a.r, a.partial), (None, None));
    }

    /// The words: a sentence per environment naming what latent quality predicts beyond the
    /// moves, from the numbers only.
    #[test]
    fn the_sentence_names_what_is_and_is_not_predicted() {
        let z: Vec<f64> = Z.iter().map(|v| v + 3.0).collect();
        let x = combine(1.0, &Z, 0.5, &E, 0.9);
        let only_moves = combine(3.0, &Z, 0.5, &U, 10.0);
        let quality: Vec<f64> = x.iter().zip(&z).map(|(x, z)| -2.0 * x + 5.0 * z).collect();
        let obs: Vec<Observation> = (0..8)
            .map(|i| Observation {
                campaign: if i < 6 { "paper" } else { "paper-init" }.into(),
                env: "armball".into(),
                algo: "rge-vae".into(),
                variant: "faithful".into(),
                sampler: "kde".into(),
                latents: 10,
                seed: i,
                n_runs: 1,
                position_knn_r2: x[i as usize],
                ln_moves: z[i as usize],
                values: [
                    Some(only_moves[i as usize]),
                    Some(quality[i as usize]),
                    None,
                    Some(only_moves[i as usize]),
                ],
            })
            .collect();
        let lines = table(&obs);
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[2].stats, None);
        let mut w = String::new();
        section(&mut w, &obs, &lines, "paper");
        assert!(
            w.contains("ArmBall 6 from `paper` and 2 from `paper-init`"),
            "{w}"
        );
        assert!(
            w.contains(
                "**ArmBall.** Beyond the number of moves (the 95% interval of the partial r \
                 excluding 0), position R² still predicts KLC of moved outcomes (partial r \
                 -1.00 [-1.00, -1.00]); it does not predict final KLC (all outcomes) (partial r \
                 0.00 [-0.75, 0.75]) or goal error, mean (partial r 0.00 [-0.75, 0.75]); it \
                 cannot be tested on cells reached (too few observations or no variance)."
            ),
            "{w}"
        );
        assert!(!w.contains("NaN") && !w.contains("inf"), "{w}");
    }

    /// The table on the committed results: one observation per learned goal space, sampler and
    /// repetition of `paper` and its recipe campaigns (ArmBall 240 + 180 untrained twins + 5
    /// of `paper-long`, ArmArrow 240 + 180), averaging the 3 exploration replicates of each,
    /// and the moves alone explain most of the final KL-coverage.
    #[test]
    fn the_table_on_the_committed_results() {
        let results = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/results");
        let camps = crate::campaigns::load_campaigns(
            &results,
            "paper",
            &crate::sections::wanted_roles(crate::sections::SECTIONS),
        )
        .unwrap();
        let measured = crate::discovery::measure_all(&camps).unwrap();
        let obs = observations(&camps, &measured);
        let count = |env: &str| obs.iter().filter(|o| o.env == env).count();
        assert_eq!([count("armball"), count("armarrow")], [425, 420]);
        for o in &obs {
            assert_eq!(o.n_runs, 3, "{o:?}");
        }
        assert!(
            obs.iter()
                .all(|o| !WITHOUT_LATENTS.iter().any(|a| *a == o.algo))
        );
        let lines = table(&obs);
        let mut w = String::new();
        section(&mut w, &obs, &lines, "paper");
        println!("{w}");
        assert_eq!(lines.len(), 8);
        for l in &lines {
            let a = l.stats.as_ref().unwrap();
            assert!(a.r.is_some() && a.partial_ci.is_some(), "{l:?}");
            if l.measure == Measure::FinalKlc {
                assert!(a.r2_moves.unwrap() > 0.5, "{l:?}");
            }
        }
        assert!(!w.contains("NaN"), "{w}");
    }
}
