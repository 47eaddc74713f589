//! Latent quality: how well the true object state can be read off a goal space (of trained
//! goal spaces and controls; the original code's `src/measures.py` measured embeddings too).
//!
//! For a fitted representation, the targets are the engineered states of its training images
//! (ball x, y; arrow x, y and the angle as cos / sin, since the angle wraps around) and of a
//! held-out set of freshly rendered images.
//!
//! **The arrow's angle modulo 120°.** The rendered arrow (`env::render`) is a dart whose three
//! outer vertices lie 120° apart on a circle of radius 10 px; only the notch at its centre tells
//! the tip from the two other corners. In pixel distance the shape is therefore close to
//! three-fold symmetric: nearest neighbours among raw ArmArrow images agree on the angle modulo
//! 120° (k-NN R² of cos 3a, sin 3a from raw pixels 0.85 at 10,000 images) far more than on the
//! angle itself (0.15; 0.45 at 39,000 images). So the arrow also gets the targets cos 3a and
//! sin 3a, and the means are given per group: position (x, y), angle (cos a, sin a) and angle
//! modulo 120° (cos 3a, sin 3a). Measure version 1 (results written before this) fitted the maps
//! on 2000 training latents and had no modulo-120° targets; at 2000 images even raw pixels give
//! R² ≈ 0 on every angle target. Two regressions from latents to targets are fitted on
//! the training latents and scored on the held-out latents:
//! - **linear**: least squares with an intercept on standardised latents (a tiny ridge, 1e-9 of
//!   the trace, keeps collapsed latents solvable);
//! - **k-NN**: the mean target of the `k` nearest training latents (Euclidean), `k` =
//!   [`KNN_K`], with every latent tied with the k-th nearest included.
//!
//! Each reports R² = 1 - SSE / SST per target and their mean. An untrained random projection
//! scores well on the linear map only when it keeps the object's position; a collapsed encoder
//! scores about 0.
//!
//! **Neighbourhoods** (measure version 3): the R² says whether the state can be read off the
//! latents, not whether the goal space keeps the state's neighbourhoods (a goal space folded
//! onto itself can score a high k-NN R² and still put far-apart states side by side). So the
//! measure also gives the co-ranking measures of the original code's `src/measures.py`,
//! trustworthiness and continuity (Venna & Kaski 2001), between the object's state and the
//! latents of the held-out images, with `k` = [`KNN_K`] neighbours and Euclidean distances:
//! - **trustworthiness** `T(k) = 1 - 2 / (n k (2n - 3k - 1)) * sum_i sum_{j in U_k(i)} (r(i, j) - k)`,
//!   `U_k(i)` the latent neighbours of `i` that are not among its state neighbours and `r(i, j)`
//!   the rank of `j` among `i`'s neighbours in the state space: 1 when every latent neighbour
//!   is a true neighbour;
//! - **continuity** `C(k)`: the same with the spaces swapped (state neighbours missing from the
//!   latent neighbourhood, ranked in the latent space).
//!
//! Ranks break ties by index (a collapsed encoder gets chance-level values, about 0.5). Spaces:
//! `position` (x, y) and, for the arrow, `state` (x, y, cos a, sin a).

use ugl_kernels::{MatRef, cholesky_solve};

use super::{Latents, ReprError};

/// Neighbours of the k-NN regression.
pub const KNN_K: usize = 10;

/// Version of the measure recorded with it (1: maps fitted on 2000 training latents, no
/// modulo-120° targets; 2: on the whole training set, with them; 3: with trustworthiness and
/// continuity).
pub const MEASURE_VERSION: u32 = 3;

/// The measure's record, declared in `ugl-types` (a manifest's `latent_quality`).
pub use ugl_types::{GroupR2, LatentQuality, Neighbourhoods, ObjectR2};

/// The state spaces of the neighbourhood measures: name and target columns.
const NEIGHBOURHOOD_SPACES: [(&str, &[&str]); 2] = [
    ("position", &["x", "y"]),
    ("state", &["x", "y", "cos_angle", "sin_angle"]),
];

/// The groups of targets, by name prefix: what a reader asks of a goal space.
const GROUPS: [(&str, &[&str]); 4] = [
    ("position", &["x", "y"]),
    ("distractor", &["distractor_x", "distractor_y"]),
    ("angle", &["cos_angle", "sin_angle"]),
    ("angle_mod_120", &["cos_3angle", "sin_3angle"]),
];

/// The regression targets of engineered states (`state_dim` 2: ball x, y; 3: arrow x, y, and
/// the angle a (in units of pi) as cos a, sin a, cos 3a, sin 3a; 4: ball x, y, distractor x,
/// y): row-major `n x targets`, and the names.
pub fn targets(states: &[f64], state_dim: usize) -> (Vec<f64>, Vec<String>) {
    let mut out = Vec::new();
    for s in states.chunks_exact(state_dim) {
        out.extend_from_slice(&s[..2]);
        if state_dim == 3 {
            let a = s[2] * std::f64::consts::PI;
            out.extend([
                libm::cos(a),
                libm::sin(a),
                libm::cos(3.0 * a),
                libm::sin(3.0 * a),
            ]);
        }
        if state_dim == 4 {
            out.extend_from_slice(&s[2..4]);
        }
    }
    let mut names = vec!["x", "y"];
    if state_dim == 3 {
        names.extend(["cos_angle", "sin_angle", "cos_3angle", "sin_3angle"]);
    }
    if state_dim == 4 {
        names.extend(["distractor_x", "distractor_y"]);
    }
    (out, names.into_iter().map(String::from).collect())
}

/// Score `train` / `heldout` latents against their targets (row-major `n x t`).
pub fn latent_quality(
    train: &Latents,
    train_targets: &[f64],
    heldout: &Latents,
    heldout_targets: &[f64],
    names: Vec<String>,
) -> Result<LatentQuality, ReprError> {
    let t = names.len();
    let d = train.latents;
    if train.n < 2 || heldout.n < 2 || heldout.latents != d {
        return Err(ReprError::InvalidInput(format!(
            "latent quality needs at least 2 training and 2 held-out latents of one dimension, \
             got {} x {d} and {} x {}",
            train.n, heldout.n, heldout.latents
        )));
    }
    if train_targets.len() != train.n * t || heldout_targets.len() != heldout.n * t {
        return Err(ReprError::InvalidInput(
            "latent quality: targets do not match the latents".into(),
        ));
    }
    let linear = linear_predictions(train, train_targets, heldout, t)?;
    let knn = knn_predictions(train, train_targets, heldout, t);
    let linear_r2 = r2(&linear, heldout_targets, t);
    let knn_r2 = r2(&knn, heldout_targets, t);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let groups = GROUPS
        .iter()
        .filter_map(|(group, members)| {
            let idx: Vec<usize> = (0..t)
                .filter(|&j| members.contains(&names[j].as_str()))
                .collect();
            let pick = |v: &[f64]| mean(&idx.iter().map(|&j| v[j]).collect::<Vec<_>>());
            (!idx.is_empty()).then(|| GroupR2 {
                group: group.to_string(),
                linear_r2: pick(&linear_r2),
                knn_r2: pick(&knn_r2),
            })
        })
        .collect();
    let neighbourhoods = NEIGHBOURHOOD_SPACES
        .iter()
        .filter_map(|(space, members)| {
            let idx: Vec<usize> = members
                .iter()
                .map(|m| names.iter().position(|n| n == m))
                .collect::<Option<_>>()?;
            let points: Vec<f64> = (0..heldout.n)
                .flat_map(|i| idx.iter().map(move |&j| heldout_targets[i * t + j]))
                .collect();
            let (trustworthiness, continuity) =
                trustworthiness_continuity(&points, idx.len(), heldout, KNN_K);
            Some(Neighbourhoods {
                space: space.to_string(),
                trustworthiness,
                continuity,
            })
        })
        .collect();
    Ok(LatentQuality {
        version: MEASURE_VERSION,
        per_latent: Vec::new(),
        disentanglement: None,
        kl_per_latent: Vec::new(),
        neighbourhoods,
        targets: names,
        linear_r2_mean: mean(&linear_r2),
        knn_r2_mean: mean(&knn_r2),
        groups,
        linear_r2,
        knn_r2,
        n_train: train.n,
        n_heldout: heldout.n,
        k: KNN_K.min(train.n),
    })
}

/// Per object (name and its coordinates among the `state_dim` state columns), the held-out R²
/// of each latent predicted from that object's coordinates ([`ObjectR2`]). `*_states` are
/// row-major `n x state_dim`.
pub fn per_latent_r2(
    train_states: &[f64],
    train: &Latents,
    heldout_states: &[f64],
    heldout: &Latents,
    state_dim: usize,
    objects: &[(&str, std::ops::Range<usize>)],
) -> Vec<ObjectR2> {
    let d = train.latents;
    let coords = |states: &[f64], dims: &std::ops::Range<usize>| Latents {
        n: states.len() / state_dim,
        latents: dims.len(),
        data: states
            .chunks_exact(state_dim)
            .flat_map(|s| s[dims.clone()].to_vec())
            .collect(),
    };
    objects
        .iter()
        .map(|(object, dims)| {
            let pred = knn_predictions(
                &coords(train_states, dims),
                &train.data,
                &coords(heldout_states, dims),
                d,
            );
            ObjectR2 {
                object: object.to_string(),
                r2: r2(&pred, &heldout.data, d)
                    .into_iter()
                    .map(|v| v.is_finite().then_some(v))
                    .collect(),
            }
        })
        .collect()
}

/// For each point, the ranks of all points by distance from it (itself rank 0, its nearest
/// neighbour 1; ties broken by index), row-major `n x n`, from row-major `n x dim` coordinates.
fn ranks(points: &[f64], dim: usize) -> Vec<u32> {
    use rayon::prelude::*;
    let n = points.len() / dim;
    let row = |i: usize| &points[i * dim..(i + 1) * dim];
    let mut out = vec![0u32; n * n];
    out.par_chunks_mut(n).enumerate().for_each(|(i, r)| {
        let d: Vec<f64> = (0..n)
            .map(|j| {
                row(i)
                    .iter()
                    .zip(row(j))
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum()
            })
            .collect();
        let mut order: Vec<usize> = (0..n).filter(|&j| j != i).collect();
        order.sort_by(|&a, &b| d[a].total_cmp(&d[b]).then(a.cmp(&b)));
        r[i] = 0;
        for (rank, &j) in order.iter().enumerate() {
            r[j] = rank as u32 + 1;
        }
    });
    out
}

/// Trustworthiness and continuity (module docs) of `latents` against the row-major
/// `n x dim` state coordinates `state`, with `k` neighbours (clamped to keep the normaliser
/// positive).
pub fn trustworthiness_continuity(
    state: &[f64],
    dim: usize,
    latents: &Latents,
    k: usize,
) -> (f64, f64) {
    let n = latents.n;
    let k = k.min((2 * n).saturating_sub(2) / 3).max(1);
    if n < 3 || state.len() != n * dim {
        return (f64::NAN, f64::NAN);
    }
    let high = ranks(state, dim);
    let low = ranks(&latents.data, latents.latents);
    let k32 = k as u32;
    // Sum over i of (rank in `a` - k) for the points within k of i in `b` but not in `a`.
    let penalty = |a: &[u32], b: &[u32]| -> f64 {
        (0..n)
            .map(|i| {
                let (ra, rb) = (&a[i * n..(i + 1) * n], &b[i * n..(i + 1) * n]);
                (0..n)
                    .filter(|&j| j != i && rb[j] <= k32 && ra[j] > k32)
                    .map(|j| f64::from(ra[j] - k32))
                    .sum::<f64>()
            })
            .sum()
    };
    let (nf, kf) = (n as f64, k as f64);
    let norm = 2.0 / (nf * kf * (2.0 * nf - 3.0 * kf - 1.0));
    (
        1.0 - norm * penalty(&high, &low),
        1.0 - norm * penalty(&low, &high),
    )
}

/// Per-column mean and standard deviation (infinite where the column is constant up to
/// rounding, [`CONSTANT_SPREAD`], so that its standardised values are 0).
fn standardiser(z: &Latents) -> (Vec<f64>, Vec<f64>) {
    let (n, d) = (z.n as f64, z.latents);
    let mut mean = vec![0.0; d];
    for i in 0..z.n {
        for (m, v) in mean.iter_mut().zip(z.row(i)) {
            *m += v / n;
        }
    }
    let mut sd = vec![0.0; d];
    for i in 0..z.n {
        for ((s, v), m) in sd.iter_mut().zip(z.row(i)).zip(&mean) {
            *s += (v - m).powi(2) / n;
        }
    }
    let sd = sd
        .into_iter()
        .zip(&mean)
        .map(|(v, m)| {
            let sd = v.sqrt();
            // Constant up to rounding: an infinite scale makes its standardised column 0.
            if sd > CONSTANT_SPREAD * m.abs().max(1.0) {
                sd
            } else {
                f64::INFINITY
            }
        })
        .collect();
    (mean, sd)
}

/// A latent whose spread over the training codes is at most this fraction of its size (or of 1,
/// the prior's scale, where it is smaller) is constant up to rounding: an `f32` code's rounding
/// is about 6e-8 of its size, and a dead encoder's codes differ by that alone (seen: a spread of
/// 3e-10 on codes of 0.01). Standardised, its rounding would be read as signal, and codes 1e-6
/// away from it extrapolated without bound (a linear R² of -6e7), so it is left out of the
/// linear map.
const CONSTANT_SPREAD: f64 = 1e-6;

fn linear_predictions(
    train: &Latents,
    y: &[f64],
    heldout: &Latents,
    t: usize,
) -> Result<Vec<f64>, ReprError> {
    let d = train.latents;
    let (mean, sd) = standardiser(train);
    let p = d + 1;
    // The standardised design matrix with an intercept column, row-major n x (d + 1).
    let design = |z: &Latents| -> Vec<f64> {
        let mut x = Vec::with_capacity(z.n * p);
        for i in 0..z.n {
            let r = z.row(i);
            x.extend((0..d).map(|j| (r[j] - mean[j]) / sd[j]));
            x.push(1.0);
        }
        x
    };
    let x = design(train);
    let xm = MatRef::row_major(&x, train.n, p);
    // Ridge-stabilised normal equations (X^T X + 1e-9 tr I) beta = X^T y, by Cholesky.
    let mut gram = vec![0.0; p * p];
    ugl_kernels::matmul(&mut gram, xm.t(), xm, false);
    let trace: f64 = (0..p).map(|j| gram[j * p + j]).sum();
    for j in 0..p {
        gram[j * p + j] += 1e-9 * trace;
    }
    let mut beta = vec![0.0; p * t];
    ugl_kernels::matmul(&mut beta, xm.t(), MatRef::row_major(y, train.n, t), false);
    cholesky_solve(&gram, p, &mut beta, t).ok_or_else(|| {
        ReprError::Numerical(
            "latent quality: the normal equations are not positive definite".into(),
        )
    })?;
    let xh = design(heldout);
    let mut pred = vec![0.0; heldout.n * t];
    ugl_kernels::matmul(
        &mut pred,
        MatRef::row_major(&xh, heldout.n, p),
        MatRef::row_major(&beta, p, t),
        false,
    );
    Ok(pred)
}

fn knn_predictions(train: &Latents, y: &[f64], heldout: &Latents, t: usize) -> Vec<f64> {
    use rayon::prelude::*;
    let k = KNN_K.min(train.n);
    let mut out = vec![0.0; heldout.n * t];
    out.par_chunks_mut(t).enumerate().for_each(|(q, o)| {
        let zq = heldout.row(q);
        let dist: Vec<f64> = (0..train.n)
            .map(|i| {
                train
                    .row(i)
                    .iter()
                    .zip(zq)
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum()
            })
            .collect();
        // The k-th smallest distance; every training latent within it counts, ties included,
        // so the prediction does not depend on the order of the training set (a collapsed
        // encoder: all tied).
        let mut sorted = dist.clone();
        let (_, &mut radius, _) = sorted.select_nth_unstable_by(k - 1, f64::total_cmp);
        let mut count = 0usize;
        for (i, _) in dist.iter().enumerate().filter(|(_, d)| **d <= radius) {
            count += 1;
            for (o, v) in o.iter_mut().zip(&y[i * t..(i + 1) * t]) {
                *o += v;
            }
        }
        o.iter_mut().for_each(|v| *v /= count as f64);
    });
    out
}

/// R² per target column.
fn r2(pred: &[f64], truth: &[f64], t: usize) -> Vec<f64> {
    let n = truth.len() / t;
    (0..t)
        .map(|j| {
            let mean = (0..n).map(|i| truth[i * t + j]).sum::<f64>() / n as f64;
            let sst: f64 = (0..n).map(|i| (truth[i * t + j] - mean).powi(2)).sum();
            let sse: f64 = (0..n)
                .map(|i| (truth[i * t + j] - pred[i * t + j]).powi(2))
                .sum();
            if sst > 0.0 { 1.0 - sse / sst } else { f64::NAN }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;
    use rand::RngExt;

    #[test]
    fn per_latent_r2_tells_which_object_a_latent_encodes() {
        // Latent 0 = ball x, latent 1 = distractor y, latent 2 = their sum, latent 3 constant.
        let mut rng = stream_named(11, "test");
        let mut draw = |n: usize| {
            let s: Vec<f64> = (0..n * 4).map(|_| rng.random_range(-1.0..1.0)).collect();
            let z: Vec<f64> = s
                .chunks(4)
                .flat_map(|s| [s[0], s[3], s[0] + s[3], 0.5])
                .collect();
            (s, latents(n, 4, z))
        };
        let (s_tr, z_tr) = draw(3000);
        let (s_te, z_te) = draw(500);
        let objects = [("ball", 0..2), ("distractor", 2..4)];
        let r = per_latent_r2(&s_tr, &z_tr, &s_te, &z_te, 4, &objects);
        assert_eq!(r[0].object, "ball");
        let (ball, distractor) = (&r[0].r2, &r[1].r2);
        assert!(
            ball[0].unwrap() > 0.95 && distractor[0].unwrap() < 0.05,
            "{r:?}"
        );
        assert!(
            distractor[1].unwrap() > 0.95 && ball[1].unwrap() < 0.05,
            "{r:?}"
        );
        for v in [ball[2], distractor[2]] {
            assert!((0.3..0.7).contains(&v.unwrap()), "{r:?}");
        }
        assert_eq!((ball[3], distractor[3]), (None, None));
    }

    fn latents(n: usize, d: usize, data: Vec<f64>) -> Latents {
        Latents {
            n,
            latents: d,
            data,
        }
    }

    /// Latents = a linear map of the state, a non-linear one, and constants: the scores say so.
    #[test]
    fn scores_know_linear_nonlinear_and_collapsed_latents() {
        let mut rng = stream_named(5, "quality-test");
        let mut states =
            |n: usize| -> Vec<f64> { (0..2 * n).map(|_| rng.random_range(-1.0..1.0)).collect() };
        let (s_tr, s_te) = (states(2000), states(500));
        let (y_tr, names) = targets(&s_tr, 2);
        let (y_te, _) = targets(&s_te, 2);
        let map = |s: &[f64], f: &dyn Fn(f64, f64) -> Vec<f64>, d: usize| {
            let data: Vec<f64> = s.chunks(2).flat_map(|p| f(p[0], p[1])).collect();
            latents(s.len() / 2, d, data)
        };
        let lin = |x: f64, y: f64| vec![2.0 * x - y + 3.0, x + 0.5 * y, 7.0];
        let q = latent_quality(
            &map(&s_tr, &lin, 3),
            &y_tr,
            &map(&s_te, &lin, 3),
            &y_te,
            names.clone(),
        )
        .unwrap();
        assert!(q.linear_r2_mean > 0.999999, "{q:?}");
        assert!(q.knn_r2_mean > 0.98, "{q:?}");
        // A non-linear but invertible map: k-NN recovers it, the linear map does not fully.
        let nonlin = |x: f64, y: f64| vec![x.powi(3), y.powi(3)];
        let q = latent_quality(
            &map(&s_tr, &nonlin, 2),
            &y_tr,
            &map(&s_te, &nonlin, 2),
            &y_te,
            names.clone(),
        )
        .unwrap();
        assert!(q.knn_r2_mean > 0.97 && q.linear_r2_mean < 0.9, "{q:?}");
        // Collapsed: constant latents explain nothing.
        let flat = |_: f64, _: f64| vec![1.0, 1.0];
        let q = latent_quality(
            &map(&s_tr, &flat, 2),
            &y_tr,
            &map(&s_te, &flat, 2),
            &y_te,
            names.clone(),
        )
        .unwrap();
        assert!(
            q.linear_r2_mean.abs() < 0.02 && q.knn_r2_mean.abs() < 0.05,
            "{q:?}"
        );
        // Collapsed up to rounding (a dead encoder: every training code the same but for a
        // few one or two rounding steps away, the held-out codes 1e-6 away): nothing either,
        // never the rounding noise read as signal (a network of the sweep had a linear R² of
        // -6e7; this case gave -1.3e6).
        let dead = |n: usize, shift: f64, bumps: &[(usize, usize, f64)]| {
            let mut data: Vec<f64> = (0..n).flat_map(|_| [0.01 + shift, -0.02 + shift]).collect();
            for &(row, col, by) in bumps {
                data[row * 2 + col] += by;
            }
            latents(n, 2, data)
        };
        let n_tr = y_tr.len() / 2;
        let q = latent_quality(
            &dead(n_tr, 0.0, &[(7, 0, 1e-9), (50, 1, -1e-9), (30, 0, 2e-9)]),
            &y_tr,
            &dead(y_te.len() / 2, 1e-6, &[]),
            &y_te,
            names,
        )
        .unwrap();
        assert!(q.linear_r2_mean.abs() < 0.02, "{q:?}");
    }

    /// Trustworthiness and continuity on known answers: an isometry keeps every neighbourhood
    /// (1, 1); a fold (x -> |x|) puts mirrored states side by side (trustworthiness falls) but
    /// keeps true neighbours close (continuity stays high); constant latents are at chance
    /// (about 0.5); and a hand-checked tiny case.
    #[test]
    fn neighbourhood_measures_know_isometries_folds_and_collapse() {
        let mut rng = stream_named(7, "quality-neighbourhoods");
        let n = 600;
        let s: Vec<f64> = (0..2 * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let map = |f: &dyn Fn(f64, f64) -> Vec<f64>, d: usize| {
            latents(n, d, s.chunks(2).flat_map(|p| f(p[0], p[1])).collect())
        };
        let (t, c) = trustworthiness_continuity(&s, 2, &map(&|x, y| vec![3.0 - y, x], 2), 10);
        assert!(
            (t - 1.0).abs() < 1e-12 && (c - 1.0).abs() < 1e-12,
            "{t} {c}"
        );
        let (t, c) = trustworthiness_continuity(&s, 2, &map(&|x, y| vec![x.abs(), y], 2), 10);
        assert!(t < 0.97 && c > 0.99 && c > t, "{t} {c}");
        let (t, c) = trustworthiness_continuity(&s, 2, &map(&|_, _| vec![1.0], 1), 10);
        assert!((t - 0.5).abs() < 0.1 && (c - 0.5).abs() < 0.1, "{t} {c}");
        // 4 states on a line at 0, 1, 3, 7 (no tied distances); latents 0, 3, 1, 7 swap the
        // middle two. With k = 1 every point's latent neighbour is its state rank-2 point
        // (penalty 1 each: 0 -> 2, 1 -> 2, 2 -> 0, 3 -> 1), and every state neighbour is its
        // latent rank-2 point: T = C = 1 - 2 / (4 (8 - 3 - 1)) * 4 = 0.5.
        let line = [0.0, 1.0, 3.0, 7.0];
        let swapped = latents(4, 1, vec![0.0, 3.0, 1.0, 7.0]);
        let (t, c) = trustworthiness_continuity(&line, 1, &swapped, 1);
        assert!(
            (t - 0.5).abs() < 1e-12 && (c - 0.5).abs() < 1e-12,
            "{t} {c}"
        );
    }

    #[test]
    fn arrow_targets_wrap_the_angle() {
        let (y, names) = targets(&[0.1, 0.2, 1.0, 0.0, 0.0, -1.0], 3);
        assert_eq!(
            names,
            [
                "x",
                "y",
                "cos_angle",
                "sin_angle",
                "cos_3angle",
                "sin_3angle"
            ]
        );
        // angle 1 and -1 (in units of pi) are the same direction.
        for j in 2..6 {
            assert!((y[j] - y[6 + j]).abs() < 1e-12, "target {j}");
        }
        // cos 3a, sin 3a do not change under a turn of 120° (2/3 in units of pi).
        let (z, _) = targets(&[0.0, 0.0, 0.3, 0.0, 0.0, 0.3 + 2.0 / 3.0], 3);
        assert!((z[4] - z[10]).abs() < 1e-12 && (z[5] - z[11]).abs() < 1e-12);
        assert!((z[2] - z[8]).abs() > 0.5);
    }

    /// An encoding of the angle modulo 120° only: the groups say so (angle ≈ 0, modulo 120° ≈ 1).
    #[test]
    fn groups_separate_the_full_angle_from_the_angle_modulo_120() {
        let mut rng = stream_named(6, "quality-groups");
        let mut states =
            |n: usize| -> Vec<f64> { (0..3 * n).map(|_| rng.random_range(-1.0..1.0)).collect() };
        let (s_tr, s_te) = (states(3000), states(500));
        let (y_tr, names) = targets(&s_tr, 3);
        let (y_te, _) = targets(&s_te, 3);
        let encode = |s: &[f64]| {
            let data: Vec<f64> = s
                .chunks(3)
                .flat_map(|p| {
                    let a = 3.0 * p[2] * std::f64::consts::PI;
                    [p[0], p[1], a.cos(), a.sin()]
                })
                .collect();
            latents(s.len() / 3, 4, data)
        };
        let q = latent_quality(&encode(&s_tr), &y_tr, &encode(&s_te), &y_te, names).unwrap();
        let g = |name: &str| q.groups.iter().find(|g| g.group == name).unwrap().clone();
        assert_eq!(q.version, MEASURE_VERSION);
        assert!(g("position").knn_r2 > 0.9, "{q:?}");
        assert!(g("angle_mod_120").knn_r2 > 0.9, "{q:?}");
        assert!(g("angle").knn_r2.abs() < 0.2, "{q:?}");
    }
}
