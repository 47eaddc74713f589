//! How much of an ArmArrow image the arrow's angle explains, against its position (why no
//! learner encodes the angle). Over states drawn like the UGL data set (uniform in [-1, 1]^3):
//! - the squared pixel distance between an image and the same image with another angle, with
//!   another position, and for a small change (0.1) of each;
//! - the share of the data set's pixel variance explained by the position (the variance of the
//!   images averaged over angles at a fixed position) and by the angle (averaged over
//!   positions at a fixed angle);
//! - the distance after a rotation of 60, 120 and 180 degrees (a rotational symmetry of the
//!   drawn arrow would make it vanish).
//!
//! `cargo run --example arrow_angle_signal -p ugl-bench` (seeded: the same numbers every time).

use rand::RngExt;
use ugl_bench::env::render::{PIXELS, render_arrow_into};
use ugl_bench::seed::stream_named;

fn render(s: [f64; 3], out: &mut [f32]) {
    render_arrow_into(s[0], s[1], s[2], out);
}

fn dist2(a: &[f32], b: &[f32]) -> f64 {
    a.iter().zip(b).map(|(x, y)| f64::from(x - y).powi(2)).sum()
}

/// Variance of a set of images around their mean, summed over pixels, per image.
fn total_variance(images: &[Vec<f32>]) -> f64 {
    let n = images.len() as f64;
    let mut mean = vec![0f64; PIXELS];
    for im in images {
        for (m, v) in mean.iter_mut().zip(im) {
            *m += f64::from(*v) / n;
        }
    }
    images
        .iter()
        .map(|im| {
            im.iter()
                .zip(&mean)
                .map(|(v, m)| (f64::from(*v) - m).powi(2))
                .sum::<f64>()
        })
        .sum::<f64>()
        / n
}

fn main() {
    let mut rng = stream_named(0, "arrow-angle-signal");
    let u = |rng: &mut ugl_bench::seed::Stream| rng.random_range(-1.0..1.0);
    let n = 2000;
    let (mut a, mut b) = (vec![0f32; PIXELS], vec![0f32; PIXELS]);
    let (mut d_angle, mut d_pos, mut d_angle_small, mut d_x_small, mut lit) =
        (0.0, 0.0, 0.0, 0.0, 0.0);
    for _ in 0..n {
        let s = [u(&mut rng), u(&mut rng), u(&mut rng)];
        render(s, &mut a);
        lit += a.iter().filter(|v| **v > 0.0).count() as f64 / n as f64;
        render([s[0], s[1], u(&mut rng)], &mut b);
        d_angle += dist2(&a, &b) / n as f64;
        render([u(&mut rng), u(&mut rng), s[2]], &mut b);
        d_pos += dist2(&a, &b) / n as f64;
        render([s[0], s[1], (s[2] + 0.1).min(1.0)], &mut b);
        d_angle_small += dist2(&a, &b) / n as f64;
        render([(s[0] + 0.1).min(1.0), s[1], s[2]], &mut b);
        d_x_small += dist2(&a, &b) / n as f64;
    }
    println!("lit pixels per image (mean): {lit:.1} of {PIXELS}");
    println!("squared pixel distance, mean over {n} pairs:");
    println!("  another angle, same position:   {d_angle:.2}");
    println!("  another position, same angle:   {d_pos:.2}");
    println!("  angle + 0.1 (18 degrees):        {d_angle_small:.2}");
    println!("  x + 0.1 (3.5 pixels):            {d_x_small:.2}");
    // Rotations of the arrow at a fixed position: a shape with a rotational symmetry looks
    // the same after it (the angle is in units of pi, wrapped into [-1, 1)).
    for (label, turn) in [("60", 1.0 / 3.0), ("120", 2.0 / 3.0), ("180", 1.0)] {
        let mut d = 0.0;
        for _ in 0..n {
            let s = [u(&mut rng), u(&mut rng), u(&mut rng)];
            render(s, &mut a);
            let turned = ugl_bench::env::armarrow::wrap_angle(s[2] + turn);
            render([s[0], s[1], turned], &mut b);
            d += dist2(&a, &b) / n as f64;
        }
        println!(
            "  angle + {label} degrees:{:>w$}{d:.2}",
            "",
            w = 17 - label.len()
        );
    }

    // Variance decomposition on a P x K design: P positions, K angles.
    let (p, k) = (120, 24);
    let positions: Vec<[f64; 2]> = (0..p).map(|_| [u(&mut rng), u(&mut rng)]).collect();
    let angles: Vec<f64> = (0..k).map(|_| u(&mut rng)).collect();
    let mut all = Vec::with_capacity(p * k);
    for pos in &positions {
        for &ang in &angles {
            let mut im = vec![0f32; PIXELS];
            render([pos[0], pos[1], ang], &mut im);
            all.push(im);
        }
    }
    let mean_over = |pick: &dyn Fn(usize, usize) -> usize, groups: usize, per: usize| {
        (0..groups)
            .map(|g| {
                let mut m = vec![0f32; PIXELS];
                for j in 0..per {
                    for (acc, v) in m.iter_mut().zip(&all[pick(g, j)]) {
                        *acc += v / per as f32;
                    }
                }
                m
            })
            .collect::<Vec<_>>()
    };
    let total = total_variance(&all);
    let by_position = total_variance(&mean_over(&|g, j| g * k + j, p, k));
    let by_angle = total_variance(&mean_over(&|g, j| j * k + g, k, p));
    println!("pixel variance of {p} positions x {k} angles: {total:.2} per image");
    println!(
        "  explained by the position: {:.1}%, by the angle: {:.1}%, by their interaction: {:.1}%",
        100.0 * by_position / total,
        100.0 * by_angle / total,
        100.0 * (total - by_position - by_angle) / total
    );
}
