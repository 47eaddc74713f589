//! Inspect a cached neural model: encode a fresh UGL data set of ball (or arrow) images and print
//! the spread of each latent dimension and how well a linear map from the latents recovers the
//! object's state (R^2 per state coordinate). A collapsed encoder shows tiny spreads / low R^2.
//!
//! `cargo run -p ugl-bench --profile dev --example inspect_model -- MODEL_FILE armball|armarrow [N]`

use ugl_bench::env::{EnvConfig, EnvKind, make_env};
use ugl_bench::repr::Encoder;
use ugl_bench::repr::cache::from_bytes;
use ugl_bench::repr::dataset::generate;
use ugl_bench::seed::{Component, stream};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: inspect_model MODEL_FILE armball|armarrow [N]".into());
    }
    let path = std::path::Path::new(&args[1]);
    let key = path
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or("bad model file name")?;
    let kind: EnvKind = args[2].parse()?;
    let n: usize = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(2000);
    let mut enc = from_bytes(key, &std::fs::read(path)?)?;
    let env = make_env(kind, &EnvConfig::default());
    let data = generate(env.as_ref(), n, &mut stream(12345, Component::Dataset))?;
    let z = enc.encode(&data.images)?;
    let d = z.latents;
    println!("{:?} {:?}: {n} images, {d} latents", enc.model, enc.variant);
    let zd = &z.data;
    let col = |j: usize| (0..n).map(move |i| zd[i * d + j]);
    for j in 0..d {
        let mean = col(j).sum::<f64>() / n as f64;
        let sd = (col(j).map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        println!("latent {j}: mean {mean:+.4} sd {sd:.4}");
    }
    // Least squares state ~ [latents, 1] via normal equations (small d).
    let p = d + 1;
    let row = |i: usize| {
        let mut r: Vec<f64> = z.data[i * d..(i + 1) * d].to_vec();
        r.push(1.0);
        r
    };
    let sdim = data.states.len() / n;
    for s in 0..sdim {
        let mut a = vec![0.0; p * p];
        let mut b = vec![0.0; p];
        for i in 0..n {
            let r = row(i);
            let y = data.states[i * sdim + s];
            for u in 0..p {
                b[u] += r[u] * y;
                for v in 0..p {
                    a[u * p + v] += r[u] * r[v];
                }
            }
        }
        for u in 0..p {
            a[u * p + u] += 1e-9;
        }
        // Gaussian elimination.
        for c in 0..p {
            let piv = (c..p)
                .max_by(|&x, &y| a[x * p + c].abs().total_cmp(&a[y * p + c].abs()))
                .unwrap();
            for k in 0..p {
                a.swap(c * p + k, piv * p + k);
            }
            b.swap(c, piv);
            for r2 in c + 1..p {
                let f = a[r2 * p + c] / a[c * p + c];
                for k in c..p {
                    a[r2 * p + k] -= f * a[c * p + k];
                }
                b[r2] -= f * b[c];
            }
        }
        let mut w = vec![0.0; p];
        for c in (0..p).rev() {
            let s2: f64 = (c + 1..p).map(|k| a[c * p + k] * w[k]).sum();
            w[c] = (b[c] - s2) / a[c * p + c];
        }
        let ys: Vec<f64> = (0..n).map(|i| data.states[i * sdim + s]).collect();
        let ym = ys.iter().sum::<f64>() / n as f64;
        let (mut ss_res, mut ss_tot) = (0.0, 0.0);
        for i in 0..n {
            let pred: f64 = row(i).iter().zip(&w).map(|(x, y)| x * y).sum();
            ss_res += (ys[i] - pred).powi(2);
            ss_tot += (ys[i] - ym).powi(2);
        }
        println!(
            "state {s}: linear R^2 from the latents = {:.3}",
            1.0 - ss_res / ss_tot
        );
    }
    Ok(())
}
