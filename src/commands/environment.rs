//! `ugl rollout`, `ugl klc`, `ugl render`: the environments and the measure, one call each.

use std::path::Path;

use anyhow::{Context, Result, bail};
use serde::Serialize;

use ugl_bench::env::render::{Image70, write_npy, write_png};
use ugl_bench::env::{EnvConfig, EnvKind, cdge, make_env};
use ugl_bench::metrics::KlCoverage;
use ugl_bench::metrics::csv::read_outcomes_csv;

use crate::output::outln;

#[derive(Serialize)]
pub(crate) struct RolloutOut {
    object: Vec<f64>,
    moved: bool,
    hand: [f64; 2],
}

pub(crate) fn rollout(kind: EnvKind, params: &Path, seed: u64) -> Result<()> {
    let text = std::fs::read_to_string(params)
        .with_context(|| format!("cannot read {}", params.display()))?;
    let env = make_env(kind, &EnvConfig::default());
    let n = env.param_dim();
    let v: Vec<Vec<f64>> = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: expected a JSON array of arrays of {n} numbers",
            params.display()
        )
    })?;
    let mut noise = ugl_bench::seed::stream(seed, ugl_bench::seed::Component::Distractor);
    let mut out = Vec::with_capacity(v.len());
    for (i, theta) in v.iter().enumerate() {
        if theta.len() != n {
            bail!(
                "{}: entry {i} has {} numbers, {kind} takes {n}",
                params.display(),
                theta.len()
            );
        }
        if theta.iter().any(|x| !x.is_finite()) {
            bail!("{}: entry {i} has a non-finite number", params.display());
        }
        let r = env.rollout(theta, &mut noise);
        out.push(RolloutOut {
            object: r.outcome().to_vec(),
            moved: r.caught,
            hand: r.hand,
        });
    }
    outln!("{}", serde_json::to_string(&out)?)?;
    Ok(())
}

pub(crate) fn klc(kind: EnvKind, path: &Path) -> Result<()> {
    // Measured on the controllable object (armballs: the ball's x, y).
    let spec = kind.spec();
    let columns = &spec.outcome_columns[spec.metric_dims()];
    let dim = columns.len();
    let pts = read_outcomes_csv(path, columns)?;
    let k = KlCoverage::new(dim)?;
    let v = k.evaluate(pts.iter().map(|p| &p[..]))?;
    if v.is_infinite() {
        outln!("inf")?
    } else {
        outln!("{v}")?
    }
    Ok(())
}

pub(crate) fn render(kind: EnvKind, state: &str, out: &Path) -> Result<()> {
    let vals: Vec<f64> = state
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| anyhow::anyhow!("--state: '{s}' is not a number"))
        })
        .collect::<Result<_>>()?;
    if vals.len() != kind.state_dim() {
        bail!(
            "--state for {kind} needs {} comma-separated values, got {}",
            kind.state_dim(),
            vals.len()
        );
    }
    if let Some(v) = vals.iter().find(|v| !(-1.0..=1.0).contains(*v)) {
        bail!("--state: {v} is outside [-1,1]");
    }
    let env = make_env(kind, &EnvConfig::default());
    let mut buf = vec![0f32; env.image_len()];
    env.render_into(&vals, &mut buf);
    let shape = kind.spec().image;
    let (gray, rgb) = (shape == ugl_types::GRAY70, shape == ugl_types::RGB64);
    if !(gray || rgb) {
        bail!(
            "{kind}: no writer for {}x{}x{} pictures (70x70 gray and 64x64 RGB have one)",
            shape.width,
            shape.height,
            shape.channels
        );
    }
    match out.extension().and_then(|e| e.to_str()) {
        Some("npy") if gray => write_npy(&Image70(buf), out)?,
        Some("png") if gray => write_png(&Image70(buf), out)?,
        Some("npy") => cdge::write_npy(&buf, out)?,
        Some("png") => cdge::write_png(&buf, out)?,
        _ => bail!(
            "--out {}: the extension must be .npy or .png",
            out.display()
        ),
    }
    Ok(())
}
