//! Coverage of the nominal 95% interval of a difference of means, by deterministic simulation.
//!
//! Each case draws two independent samples (subject `x`, reference `y`) from seeded ChaCha8
//! streams, with the spread measured on the committed results: a condition's final KLC has a
//! median sd of 0.27 nats over seeds (0.12-0.57), and a seed stuck at RPE level sits about
//! 2.2 nats above the others (ArmBall: RPE 6.5, learners about 4.3). The coverage is the fraction
//! of `REPS` replicates whose interval holds the true difference of the population means; with
//! 4000 replicates its Monte-Carlo sd is `√(0.95 · 0.05 / 4000) ≈ 0.0035`.
//!
//! [`welch_interval_covers_at_the_seed_counts_used`] is the proof the report relies on;
//! [`compare_interval_methods`] (`cargo test -p ugl-report compare_interval_methods --
//! --ignored --nocapture`) measures the candidates the choice was made from (percentile
//! bootstrap, BCa, studentized bootstrap, Welch's t) and prints the table quoted in
//! [`super::interval`].

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::interval::{t_interval, welch_interval};
use super::{IndexSampler, derive_seed, percentile_sorted};

const REPS: usize = 4000;
const LEVEL: f64 = 0.95;
/// The median sd over seeds of a condition's final KLC (nats).
const SD: f64 = 0.27;
/// How far above the others a seed stuck at RPE level ends (nats).
const RPE_SHIFT: f64 = 2.2;

/// The population of one side.
#[derive(Debug, Clone, Copy)]
enum Population {
    /// `N(0, sd²)`.
    Normal(f64),
    /// A lognormal with log-sd `sigma`, standardised to mean 0 and sd `sd` (skewness 1.75 at
    /// `sigma` = 0.5, 6.2 at 1).
    LogNormal { sigma: f64, sd: f64 },
    /// `N(0, SD²)`, plus [`RPE_SHIFT`] with probability `p` (a seed stuck at RPE level).
    Outlier { p: f64 },
}

impl Population {
    fn mean(self) -> f64 {
        match self {
            Population::Normal(_) | Population::LogNormal { .. } => 0.0,
            Population::Outlier { p } => p * RPE_SHIFT,
        }
    }

    fn draw(self, rng: &mut ChaCha8Rng) -> f64 {
        match self {
            Population::Normal(sd) => sd * normal(rng),
            Population::LogNormal { sigma, sd } => {
                let m = (sigma * sigma / 2.0).exp();
                let s = ((sigma * sigma).exp_m1() * (sigma * sigma).exp()).sqrt();
                sd * (((sigma * normal(rng)).exp() - m) / s)
            }
            Population::Outlier { p } => {
                let stuck = uniform(rng) < p;
                SD * normal(rng) + if stuck { RPE_SHIFT } else { 0.0 }
            }
        }
    }
}

/// A uniform draw in [0, 1) with 53 random bits.
fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A standard normal draw (Box-Muller, one of the pair).
pub(crate) fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - uniform(rng); // (0, 1]
    let u2 = uniform(rng);
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// One simulated comparison: the populations of `x` and `y`.
#[derive(Debug, Clone, Copy)]
struct Case {
    name: &'static str,
    x: Population,
    y: Population,
}

const CASES: [Case; 7] = [
    Case {
        name: "normal, sd 0.27 vs 0.27",
        x: Population::Normal(SD),
        y: Population::Normal(SD),
    },
    Case {
        name: "normal, sd 0.57 vs 0.12",
        x: Population::Normal(0.57),
        y: Population::Normal(0.12),
    },
    Case {
        name: "lognormal (skew 1.75) vs normal",
        x: Population::LogNormal { sigma: 0.5, sd: SD },
        y: Population::Normal(SD),
    },
    Case {
        name: "lognormal (skew 6.2) vs normal",
        x: Population::LogNormal { sigma: 1.0, sd: SD },
        y: Population::Normal(SD),
    },
    Case {
        name: "lognormal (skew 1.75), both sides",
        x: Population::LogNormal { sigma: 0.5, sd: SD },
        y: Population::LogNormal { sigma: 0.5, sd: SD },
    },
    Case {
        name: "outlier seed (p = 0.1) vs normal",
        x: Population::Outlier { p: 0.1 },
        y: Population::Normal(SD),
    },
    Case {
        name: "outlier seed (p = 0.3) vs normal",
        x: Population::Outlier { p: 0.3 },
        y: Population::Normal(SD),
    },
];

impl Case {
    /// The name of the subject's population alone.
    fn x_name(&self) -> &'static str {
        self.name
            .split(" vs ")
            .next()
            .unwrap_or(self.name)
            .trim_end_matches(", both sides")
    }
}

/// Fills `x` and `y` with one replicate of `case`.
fn draw(case: &Case, rng: &mut ChaCha8Rng, x: &mut [f64], y: &mut [f64]) {
    for v in x.iter_mut() {
        *v = case.x.draw(rng);
    }
    for v in y.iter_mut() {
        *v = case.y.draw(rng);
    }
}

fn stream(case: &Case, n: usize) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(derive_seed(2026, &format!("coverage|{}|n={n}", case.name)))
}

/// Coverage of the t interval for `case` at `n` per side, over [`REPS`] replicates: Welch's
/// interval of `mean(x) − mean(y)` when `two`, else Student's interval of `mean(x)`.
fn t_coverage(case: &Case, n: usize, two: bool) -> f64 {
    let truth = case.x.mean() - if two { case.y.mean() } else { 0.0 };
    let mut rng = stream(case, n);
    let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
    let mut hits = 0;
    for _ in 0..REPS {
        draw(case, &mut rng, &mut x, &mut y);
        let i = if two {
            welch_interval(&x, &y, LEVEL)
        } else {
            t_interval(&x, LEVEL)
        }
        .expect("n >= 2, finite samples");
        hits += usize::from(i.lo <= truth && truth <= i.hi);
    }
    hits as f64 / REPS as f64
}

/// Cases where no interval computed from so few seeds covers as it says (every candidate of
/// [`compare_interval_methods`] falls short too): `(case, n, two-sample, measured coverage)`.
/// Reported, not claimed; held within 0.02 (about 5 Monte-Carlo sd) of the measured value so
/// that a regression shows.
const SHORT: [(&str, usize, bool, f64); 9] = [
    ("outlier seed (p = 0.1) vs normal", 5, true, 0.891),
    ("outlier seed (p = 0.1) vs normal", 20, true, 0.914),
    ("outlier seed (p = 0.3) vs normal", 5, true, 0.828),
    // One sample (the tables' interval of a condition's mean): the skew of one side is not
    // diluted by the other's symmetric spread.
    ("lognormal (skew 1.75)", 5, false, 0.913),
    ("lognormal (skew 6.2)", 5, false, 0.821),
    ("lognormal (skew 6.2)", 20, false, 0.874),
    ("outlier seed (p = 0.1)", 5, false, 0.830),
    ("outlier seed (p = 0.1)", 20, false, 0.893),
    ("outlier seed (p = 0.3)", 5, false, 0.816),
];

/// The claims' interval covers as it says at 5 seeds per side (the committed campaigns) and 20
/// (the rerun's design), on normal samples with equal and unequal spread and on skewed
/// (lognormal) samples, skewed on one side or both: the coverage of the nominal 95% Welch
/// interval lies in [0.93, 0.97]. So does the tables' one-sample t interval on normal samples
/// and on moderately skewed ones at n = 20. The cases of [`SHORT`] are printed with their
/// coverage and not claimed.
#[test]
fn welch_interval_covers_at_the_seed_counts_used() {
    let mut failures = Vec::new();
    for two in [true, false] {
        for case in &CASES {
            if !two && case.name.ends_with("both sides") {
                continue; // the same x as another case
            }
            for n in [5, 20] {
                let c = t_coverage(case, n, two);
                let (what, name) = if two {
                    ("x − y", case.name)
                } else {
                    ("x", case.x_name())
                };
                let short = SHORT.iter().find(|s| s.0 == name && s.1 == n && s.2 == two);
                println!(
                    "{what:<5} {name:<36} n = {n:>2}: coverage {c:.4}{}",
                    if short.is_some() {
                        " (not claimed)"
                    } else {
                        ""
                    }
                );
                match short {
                    Some(&(_, _, _, measured)) if c < measured - 0.02 => failures.push(format!(
                        "{what} {name} at n = {n}: {c:.4}, measured {measured}"
                    )),
                    Some(_) => {}
                    None if !(0.93..=0.97).contains(&c) => {
                        failures.push(format!("{what} {name} at n = {n}: {c:.4}"))
                    }
                    None => {}
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "coverage outside its bounds: {failures:?}"
    );
}

/// The two-level design of the campaigns: `reps` repetitions (each its own data set and fit)
/// of `explorations` replicates (the same fit explored with other streams), on two conditions
/// of one campaign. A repetition's fit effect is shared by the two sides with correlation
/// `rho` (the learners of a repetition fit the same data set); every run adds its own
/// exploration noise, normal or skewed (`skewed`: lognormal with skewness 1.75). The claims'
/// interval of this design: the paired t interval of the per-repetition differences of the
/// replicate means ([`crate::claims::is_paired`]).
fn paired_two_level_coverage(
    reps: usize,
    explorations: usize,
    (sd_fit, sd_explore, rho): (f64, f64, f64),
    skewed: bool,
) -> f64 {
    let label = format!("paired|{reps}|{explorations}|{sd_fit}|{sd_explore}|{rho}|{skewed}");
    let mut rng = ChaCha8Rng::seed_from_u64(derive_seed(2026, &label));
    let noise = if skewed {
        Population::LogNormal {
            sigma: 0.5,
            sd: sd_explore,
        }
    } else {
        Population::Normal(sd_explore)
    };
    let mut d = vec![0.0; reps];
    let mut hits = 0;
    for _ in 0..REPS {
        for di in d.iter_mut() {
            let shared = normal(&mut rng);
            let fit_x = sd_fit * shared;
            let fit_y = sd_fit * (rho * shared + (1.0 - rho * rho).sqrt() * normal(&mut rng));
            let (mut mx, mut my) = (0.0, 0.0);
            for _ in 0..explorations {
                mx += fit_x + noise.draw(&mut rng);
                my += fit_y + noise.draw(&mut rng);
            }
            *di = (mx - my) / explorations as f64;
        }
        let i = t_interval(&d, LEVEL).expect("n >= 2, finite samples");
        hits += usize::from(i.lo <= 0.0 && 0.0 <= i.hi);
    }
    hits as f64 / REPS as f64
}

/// The paired interval of the two-level design covers as it says at the committed design (5
/// repetitions, 1 replicate) and at the rerun's (10 x 3), with the spread the noise campaign
/// measured (fit sd 0-0.18, exploration sd 0.22-0.34 nats; learners' fits correlated about
/// 0.7, a baseline's not at all), on normal and skewed exploration noise: in [0.93, 0.97].
#[test]
fn paired_interval_covers_on_the_two_level_design() {
    let mut failures = Vec::new();
    for (reps, explorations) in [(5, 1), (10, 3)] {
        for spread in [(0.15, 0.3, 0.7), (0.18, 0.22, 0.0), (0.0, 0.34, 0.0)] {
            for skewed in [false, true] {
                let c = paired_two_level_coverage(reps, explorations, spread, skewed);
                println!(
                    "paired, {reps} x {explorations}, (sd fit, sd explore, rho) = {spread:?}, \
                     skewed {skewed}: coverage {c:.4}"
                );
                if !(0.93..=0.97).contains(&c) {
                    failures.push(format!(
                        "{reps} x {explorations} {spread:?} {skewed}: {c:.4}"
                    ));
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "coverage outside [0.93, 0.97]: {failures:?}"
    );
}

// ---- The candidates the choice was made from (measured by the ignored test below). ----

/// Standard normal CDF (erfc of Numerical Recipes' Chebyshev fit, |error| < 1.2e-7: enough for
/// the BCa level adjustment of a measurement).
fn phi(x: f64) -> f64 {
    let z = (x / std::f64::consts::SQRT_2).abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let erfc = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

/// Standard normal quantile (Acklam's rational approximation, relative error < 1.2e-9).
fn phi_inv(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p = p.clamp(1e-300, 1.0 - 1e-16);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

fn mean_var(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let m = xs.iter().sum::<f64>() / n;
    (
        m,
        xs.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0),
    )
}

/// The three bootstrap intervals of `mean(x) − mean(y)` (of `mean(x)` when `y` is empty) from
/// one set of `n_boot` resamples (each side resampled independently): percentile, BCa (Efron
/// 1987; acceleration from the empirical influence values of the samples) and studentized
/// (bootstrap-t with the Welch / Student standard error).
fn bootstrap_intervals(
    x: &[f64],
    y: &[f64],
    n_boot: usize,
    rng: &mut ChaCha8Rng,
) -> [(f64, f64); 3] {
    let alpha = 1.0 - LEVEL;
    let two = !y.is_empty();
    let stat = |x: &[f64], y: &[f64]| {
        let (mx, vx) = mean_var(x);
        let (my, vy) = if two { mean_var(y) } else { (0.0, 0.0) };
        let se2 = vx / x.len() as f64 + if two { vy / y.len() as f64 } else { 0.0 };
        (mx - my, se2.sqrt())
    };
    let (d, se) = stat(x, y);
    let (mut sx, mut sy) = (
        IndexSampler::new(x.len()),
        IndexSampler::new(y.len().max(1)),
    );
    let (mut bx, mut by) = (x.to_vec(), y.to_vec());
    let mut reps = Vec::with_capacity(n_boot);
    let mut ts = Vec::with_capacity(n_boot);
    for _ in 0..n_boot {
        for v in bx.iter_mut() {
            *v = x[sx.next(rng)];
        }
        for v in by.iter_mut() {
            *v = y[sy.next(rng)];
        }
        let (ds, ses) = stat(&bx, &by);
        reps.push(ds);
        ts.push(if ses > 0.0 {
            (ds - d) / ses
        } else if ds == d {
            0.0
        } else {
            (ds - d).signum() * f64::INFINITY
        });
    }
    reps.sort_by(f64::total_cmp);
    ts.sort_by(f64::total_cmp);
    let pct = |q: f64| percentile_sorted(&reps, 100.0 * q);
    let percentile = (pct(alpha / 2.0), pct(1.0 - alpha / 2.0));
    // BCa.
    let below = reps.iter().filter(|&&r| r < d).count() as f64;
    let ties = reps.iter().filter(|&&r| r == d).count() as f64;
    let z0 = phi_inv(((below + 0.5 * ties) / n_boot as f64).clamp(0.5 / n_boot as f64, 1.0));
    let (mx, my) = (mean_var(x).0, if two { mean_var(y).0 } else { 0.0 });
    let infl: Vec<f64> = x
        .iter()
        .map(|v| (v - mx) / x.len() as f64)
        .chain(y.iter().map(|v| -(v - my) / y.len() as f64))
        .collect();
    let s2: f64 = infl.iter().map(|u| u * u).sum();
    let s3: f64 = infl.iter().map(|u| u * u * u).sum();
    let a = if s2 > 0.0 {
        s3 / (6.0 * s2.powf(1.5))
    } else {
        0.0
    };
    let adj = |z: f64| phi(z0 + (z0 + z) / (1.0 - a * (z0 + z)));
    let bca = (
        pct(adj(phi_inv(alpha / 2.0))),
        pct(adj(phi_inv(1.0 - alpha / 2.0))),
    );
    let tq = |q: f64| percentile_sorted(&ts, 100.0 * q);
    let student = (d - tq(1.0 - alpha / 2.0) * se, d - tq(alpha / 2.0) * se);
    [percentile, bca, student]
}

/// Prints coverage and median width of the four candidates on every case, at n = 5 and 20: the
/// difference of means `x − y`, then the mean of `x` alone (the tables' per-condition interval).
#[test]
#[ignore = "a measurement (about a minute): run with --ignored --nocapture"]
fn compare_interval_methods() {
    const N_BOOT: usize = 1999;
    for two in [true, false] {
        println!(
            "\n{}\n\n| case | n | percentile | BCa | bootstrap-t | t | median width (pct / BCa / boot-t / t) |",
            if two {
                "Difference of means x − y"
            } else {
                "Mean of x"
            }
        );
        println!("|---|---:|---:|---:|---:|---:|---|");
        for case in &CASES {
            if !two
                && CASES
                    .iter()
                    .take_while(|c| c.name != case.name)
                    .any(|c| c.x_name() == case.x_name())
            {
                continue;
            }
            for n in [5, 20] {
                let truth = case.x.mean() - if two { case.y.mean() } else { 0.0 };
                let mut rng = stream(case, n);
                let mut boot = ChaCha8Rng::seed_from_u64(derive_seed(7, case.name));
                let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
                let mut hits = [0usize; 4];
                let mut widths: [Vec<f64>; 4] = Default::default();
                for _ in 0..REPS {
                    draw(case, &mut rng, &mut x, &mut y);
                    let (w, ys) = if two {
                        (welch_interval(&x, &y, LEVEL).unwrap(), &y[..])
                    } else {
                        (t_interval(&x, LEVEL).unwrap(), &[][..])
                    };
                    let [p, b, s] = bootstrap_intervals(&x, ys, N_BOOT, &mut boot);
                    for (k, (lo, hi)) in [p, b, s, (w.lo, w.hi)].into_iter().enumerate() {
                        hits[k] += usize::from(lo <= truth && truth <= hi);
                        widths[k].push(hi - lo);
                    }
                }
                let cov: Vec<String> = hits
                    .iter()
                    .map(|&h| format!("{:.3}", h as f64 / REPS as f64))
                    .collect();
                let med: Vec<String> = widths
                    .iter_mut()
                    .map(|w| {
                        w.sort_by(f64::total_cmp);
                        format!("{:.2}", percentile_sorted(w, 50.0))
                    })
                    .collect();
                println!(
                    "| {} | {n} | {} | {} |",
                    if two { case.name } else { case.x_name() },
                    cov.join(" | "),
                    med.join(" / ")
                );
            }
        }
    }
}
