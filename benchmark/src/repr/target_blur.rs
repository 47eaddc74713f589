//! A blurred reconstruction target (ours, off by default; `[learners.conv-*] blur`,
//! `blur_until`): the convolutional networks learn to reconstruct each picture blurred by a
//! Gaussian of σ pixels, σ falling linearly from `blur` at iteration 0 to 0 at `blur_until`,
//! then the picture itself. The encoder always sees the picture itself.
//!
//! Why (`docs/neural.md`, "Eleventh round"): on pictures whose only change is where a small
//! object is drawn, two places more than a diameter apart are equally far apart in pixels, so
//! the reconstruction does not order them and the code may fold. Blurred, the picture of an
//! object at p differs from the one at p' more the farther p' is, up to the blur's width.
//!
//! Deterministic: the kernel's weights are computed in f64 with `libm` and rounded once; the
//! two passes (rows, then columns) add in a fixed order with no fused multiply-add, and the
//! picture is then scaled so that its largest value is the sharp picture's (the authors'
//! pictures are min-max normalised; a wide blur would otherwise leave a faint glow).

/// The blur's σ in pixels at iteration `step`: `sigma0 (1 − step / until)` before `until`,
/// then none.
pub fn sigma_at(sigma0: f64, until: usize, step: usize) -> Option<f64> {
    (step < until).then(|| sigma0 * (1.0 - step as f64 / until as f64))
}

/// The normalised weights of a Gaussian of `sigma` pixels, truncated at 3 σ (at least one
/// neighbour on each side): `2 r + 1` weights, the centre at `r`.
pub fn kernel(sigma: f64) -> Vec<f32> {
    let r = (3.0 * sigma).ceil().max(1.0) as i64;
    let w: Vec<f64> = (-r..=r)
        .map(|i| libm::exp(-((i * i) as f64) / (2.0 * sigma * sigma)))
        .collect();
    let total: f64 = w.iter().sum();
    w.iter().map(|v| (v / total) as f32).collect()
}

/// Blur each of the `n` pictures of `x` (`NCHW`, `channels` planes of `side` x `side`) by a
/// Gaussian of `sigma` pixels, outside the picture black (0), into `out`; then scale each
/// picture so that its largest value is the sharp picture's.
pub fn blur(x: &[f32], n: usize, channels: usize, side: usize, sigma: f64, out: &mut Vec<f32>) {
    let plane = side * side;
    let image = channels * plane;
    assert_eq!(
        x.len(),
        n * image,
        "a batch of {n} pictures of {image} values"
    );
    let k = kernel(sigma);
    let r = (k.len() / 2) as isize;
    out.clear();
    out.resize(x.len(), 0.0);
    let mut rows = vec![0.0f32; plane];
    for (src, dst) in x.chunks_exact(image).zip(out.chunks_exact_mut(image)) {
        for (sp, dp) in src.chunks_exact(plane).zip(dst.chunks_exact_mut(plane)) {
            along_rows(sp, &mut rows, side, &k, r);
            along_columns(&rows, dp, side, &k, r);
        }
        let sharp = src.iter().fold(0.0f32, |m, &v| m.max(v));
        let blurred = dst.iter().fold(0.0f32, |m, &v| m.max(v));
        if blurred > 0.0 {
            let scale = sharp / blurred;
            for v in dst.iter_mut() {
                *v = (*v * scale).min(sharp);
            }
        }
    }
}

/// The kernel along each row: `dst[a][b] = sum_j k[j] src[a][b + j − r]`, the terms in the
/// order of `j`, each a whole stretch of a row at once (so the compiler may use vectors; a
/// multiply then an add, never fused, in every lane alike).
fn along_rows(src: &[f32], dst: &mut [f32], side: usize, k: &[f32], r: isize) {
    for (s, d) in src.chunks_exact(side).zip(dst.chunks_exact_mut(side)) {
        d.fill(0.0);
        for (j, &w) in k.iter().enumerate() {
            let off = j as isize - r;
            let lo = (-off).max(0) as usize;
            let hi = (side as isize - off).min(side as isize).max(0) as usize;
            if lo >= hi {
                continue;
            }
            let from = (lo as isize + off) as usize;
            for (o, &v) in d[lo..hi].iter_mut().zip(&s[from..from + hi - lo]) {
                *o += w * v;
            }
        }
    }
}

/// The kernel along each column: `dst[a] = sum_j k[j] src[a + j − r]` for whole rows, the
/// terms in the order of `j`.
fn along_columns(src: &[f32], dst: &mut [f32], side: usize, k: &[f32], r: isize) {
    for (a, d) in dst.chunks_exact_mut(side).enumerate() {
        d.fill(0.0);
        for (j, &w) in k.iter().enumerate() {
            let t = a as isize + j as isize - r;
            if !(0..side as isize).contains(&t) {
                continue;
            }
            let row = &src[t as usize * side..(t as usize + 1) * side];
            for (o, &v) in d.iter_mut().zip(row) {
                *o += w * v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A picture with one bright pixel at (row, col) in the channel `c`.
    fn dot(channels: usize, side: usize, c: usize, row: usize, col: usize) -> Vec<f32> {
        let mut x = vec![0.0; channels * side * side];
        x[c * side * side + row * side + col] = 1.0;
        x
    }

    #[test]
    fn the_schedule_falls_linearly_to_none() {
        assert_eq!(sigma_at(8.0, 100, 0), Some(8.0));
        assert_eq!(sigma_at(8.0, 100, 50), Some(4.0));
        assert!((sigma_at(8.0, 100, 99).unwrap() - 0.08).abs() < 1e-12);
        assert_eq!(sigma_at(8.0, 100, 100), None);
        assert_eq!(sigma_at(8.0, 100, 1000), None);
    }

    #[test]
    fn the_kernel_is_a_normalised_gaussian() {
        let k = kernel(2.0);
        assert_eq!(k.len(), 13);
        let total: f32 = k.iter().sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
        for i in 0..6 {
            assert_eq!(k[i], k[12 - i]);
            assert!(k[i] < k[i + 1]);
        }
        // exp(−1/8) between neighbours of the centre.
        assert!((k[7] / k[6] - (-0.125f32).exp()).abs() < 1e-6);
        // A tiny σ keeps one neighbour on each side, almost nothing in it.
        let k = kernel(0.05);
        assert_eq!(k.len(), 3);
        assert!(k[1] > 0.999_999);
    }

    /// A dot away from the edges spreads into the Gaussian's profile, separable and symmetric,
    /// in its own channel only, and its peak keeps the sharp picture's value.
    #[test]
    fn a_dot_becomes_a_gaussian_with_the_same_peak() {
        let (c, side) = (3, 32);
        let x = dot(c, side, 1, 16, 10);
        let mut out = Vec::new();
        blur(&x, 1, c, side, 2.0, &mut out);
        let at = |ch: usize, r: usize, col: usize| out[ch * side * side + r * side + col];
        assert!((at(1, 16, 10) - 1.0).abs() < 1e-6);
        for d in 1..6 {
            let expected = (-((d * d) as f32) / 8.0).exp();
            for v in [
                at(1, 16 + d, 10),
                at(1, 16 - d, 10),
                at(1, 16, 10 + d),
                at(1, 16, 10 - d),
            ] {
                assert!((v - expected).abs() < 1e-5, "{d}: {v} against {expected}");
            }
            let diagonal = (-((2 * d * d) as f32) / 8.0).exp();
            assert!((at(1, 16 + d, 10 + d) - diagonal).abs() < 1e-5);
        }
        assert!(out[..side * side].iter().all(|&v| v == 0.0));
        assert!(out[2 * side * side..].iter().all(|&v| v == 0.0));
    }

    /// The known-good case the blur is for: after it, the picture of a dot differs from the
    /// picture of a dot 12 pixels away more than from one 6 pixels away; sharp, both differ
    /// alike.
    #[test]
    fn blurred_pictures_order_distances_that_sharp_ones_do_not() {
        let (c, side) = (1, 64);
        let distance =
            |a: &[f32], b: &[f32]| -> f32 { a.iter().zip(b).map(|(u, v)| (u - v) * (u - v)).sum() };
        let pictures = [20, 26, 32].map(|col| dot(c, side, 0, 32, col));
        assert_eq!(
            distance(&pictures[0], &pictures[1]),
            distance(&pictures[0], &pictures[2])
        );
        let blurred = pictures.map(|p| {
            let mut out = Vec::new();
            blur(&p, 1, c, side, 6.0, &mut out);
            out
        });
        let near = distance(&blurred[0], &blurred[1]);
        let far = distance(&blurred[0], &blurred[2]);
        assert!(far > 1.2 * near, "{far} against {near}");
    }

    /// Black outside the picture: a dot in a corner loses mass off the edge, and each
    /// picture of a batch is blurred and scaled on its own.
    #[test]
    fn edges_are_black_and_pictures_are_scaled_apart() {
        let (c, side) = (1, 16);
        let mut x = dot(c, side, 0, 0, 0);
        let mut second = dot(c, side, 0, 8, 8);
        for v in &mut second {
            *v *= 0.5;
        }
        x.extend(second);
        let mut out = Vec::new();
        blur(&x, 2, c, side, 1.5, &mut out);
        let (first, second) = out.split_at(side * side);
        assert!((first[0] - 1.0).abs() < 1e-6);
        assert!((second[8 * side + 8] - 0.5).abs() < 1e-6);
        assert!(first.iter().chain(second).all(|&v| v <= 1.0));
        assert_eq!(first[1], first[side]);
        let mut alone = Vec::new();
        blur(&x[side * side..], 1, c, side, 1.5, &mut alone);
        assert_eq!(alone, second);
        // An empty picture stays empty.
        blur(&vec![0.0; side * side], 1, c, side, 1.5, &mut alone);
        assert!(alone.iter().all(|&v| v == 0.0));
    }
}
