//! Least squares, correlation, Fisher's z: Pearson's r, the partial r given a covariate, the
//! residuals of a simple regression, and the normal quantile behind Fisher's interval.

use crate::stats;

/// A sum of squares about the mean this small, relative to the sum of squares of the values, is
/// zero variance (rounding leaves ~1e-32 on a constant sample).
const ZERO_VARIANCE: f64 = 1e-20;

/// Mean and sum of squared deviations; None for an empty, non-finite or constant sample.
fn centred(xs: &[f64]) -> Option<(f64, f64)> {
    if xs.is_empty() || xs.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let m = stats::mean(xs);
    let ss: f64 = xs.iter().map(|x| (x - m) * (x - m)).sum();
    let scale: f64 = xs.iter().map(|x| x * x).sum();
    (ss > ZERO_VARIANCE * scale).then_some((m, ss))
}

/// The residuals of the least-squares regression of `y` on `x` with an intercept,
/// `y − (a + b·x)`. None when the lengths differ, with fewer than 2 points, a non-finite
/// value, or `x` constant.
pub fn residuals(y: &[f64], x: &[f64]) -> Option<Vec<f64>> {
    if y.len() != x.len() || y.len() < 2 || y.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let (mx, sxx) = centred(x)?;
    let my = stats::mean(y);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let slope = sxy / sxx;
    Some(
        x.iter()
            .zip(y)
            .map(|(a, b)| (b - my) - slope * (a - mx))
            .collect(),
    )
}

/// Pearson's correlation; None with fewer than 3 points, differing lengths, a non-finite value
/// or a constant sample. Clamped to [-1, 1].
pub fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.len() != y.len() || x.len() < 3 {
        return None;
    }
    let (mx, sxx) = centred(x)?;
    let (my, syy) = centred(y)?;
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    Some((sxy / (sxx * syy).sqrt()).clamp(-1.0, 1.0))
}

/// The partial correlation of `x` and `y` given `z`: both residualised on `z` by least squares
/// ([`residuals`]), the residuals correlated. None with fewer than 4 points, `z` constant, or a
/// residual without variance (`x` or `y` a linear function of `z`).
pub fn partial_r(x: &[f64], y: &[f64], z: &[f64]) -> Option<f64> {
    if x.len() < 4 {
        return None;
    }
    let (rx, ry) = (residuals(x, z)?, residuals(y, z)?);
    // A residual that is rounding noise: zero variance relative to what it was residualised from.
    let (_, sx) = centred(x)?;
    let (_, sy) = centred(y)?;
    let ss = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    if ss(&rx) <= ZERO_VARIANCE * sx || ss(&ry) <= ZERO_VARIANCE * sy {
        return None;
    }
    pearson(&rx, &ry)
}

/// The standard normal quantile, Wichura's algorithm AS241 (PPND16, relative error ~1e-16;
/// the coefficients as in CPython's `statistics.NormalDist.inv_cdf`). NaN outside (0, 1).
#[allow(clippy::excessive_precision)]
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180625 - q * q;
        let num = (((((((2.5090809287301226727e+3 * r + 3.3430575583588128105e+4) * r
            + 6.7265770927008700853e+4)
            * r
            + 4.5921953931549871457e+4)
            * r
            + 1.3731693765509461125e+4)
            * r
            + 1.9715909503065514427e+3)
            * r
            + 1.3314166789178437745e+2)
            * r
            + 3.3871328727963666080e+0)
            * q;
        let den = ((((((5.2264952788528545610e+3 * r + 2.8729085735721942674e+4) * r
            + 3.9307895800092710610e+4)
            * r
            + 2.1213794301586595867e+4)
            * r
            + 5.3941960214247511077e+3)
            * r
            + 6.8718700749205790830e+2)
            * r
            + 4.2313330701600911252e+1)
            * r
            + 1.0;
        return num / den;
    }
    let r = if q <= 0.0 { p } else { 1.0 - p };
    let r = (-r.ln()).sqrt();
    let x = if r <= 5.0 {
        let r = r - 1.6;
        let num = ((((((7.74545014278341407640e-4 * r + 2.27238449892691845833e-2) * r
            + 2.41780725177450611770e-1)
            * r
            + 1.27045825245236838258e+0)
            * r
            + 3.64784832476320460504e+0)
            * r
            + 5.76949722146069140550e+0)
            * r
            + 4.63033784615654529590e+0)
            * r
            + 1.42343711074968357734e+0;
        let den = ((((((1.05075007164441684324e-9 * r + 5.47593808499534494600e-4) * r
            + 1.51986665636164571966e-2)
            * r
            + 1.48103976427480074590e-1)
            * r
            + 6.89767334985100004550e-1)
            * r
            + 1.67638483018380384940e+0)
            * r
            + 2.05319162663775882187e+0)
            * r
            + 1.0;
        num / den
    } else {
        let r = r - 5.0;
        let num = ((((((2.01033439929228813265e-7 * r + 2.71155556874348757815e-5) * r
            + 1.24266094738807843860e-3)
            * r
            + 2.65321895265761230930e-2)
            * r
            + 2.96560571828504891230e-1)
            * r
            + 1.78482653991729133580e+0)
            * r
            + 5.46378491116411436990e+0)
            * r
            + 6.65790464350110377720e+0;
        let den = ((((((2.04426310338993978564e-15 * r + 1.42151175831644588870e-7) * r
            + 1.84631831751005468180e-5)
            * r
            + 7.86869131145613259100e-4)
            * r
            + 1.48753612908506148525e-2)
            * r
            + 1.36929880922735805310e-1)
            * r
            + 5.99832206555887937690e-1)
            * r
            + 1.0;
        num / den
    };
    if q < 0.0 { -x } else { x }
}

/// The confidence interval of a correlation `r` over `n` points, `controls` variables partialled
/// out (0: Pearson's r), by Fisher's z: `tanh(atanh r ± z_{(1+level)/2} / √(n − 3 − controls))`.
/// None when `n − 3 − controls < 1`, `r` is not in [-1, 1] or the level not in (0, 1); `r = ±1`
/// gives the point `(r, r)`.
pub fn fisher_ci(r: f64, n: usize, controls: usize, level: f64) -> Option<(f64, f64)> {
    let df = n.checked_sub(3 + controls).filter(|&d| d >= 1)? as f64;
    if !((-1.0..=1.0).contains(&r) && level > 0.0 && level < 1.0) {
        return None;
    }
    if r.abs() == 1.0 {
        return Some((r, r));
    }
    let half = normal_quantile(0.5 + level / 2.0) / df.sqrt();
    let z = r.atanh();
    Some(((z - half).tanh(), (z + half).tanh()))
}
