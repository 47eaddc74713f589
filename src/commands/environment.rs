//! `ugl rollout`, `ugl klc`, `ugl render`: the environments and the measure, one call each.

use std::path::Path;

use anyhow::{Context, Result, bail};
use serde::Serialize;

use ugl_bench::env::render::{Image70, PIXELS, write_npy, write_png};
use ugl_bench::env::{EnvConfig, EnvKind, PARAMS, make_env};
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
    let v: Vec<Vec<f64>> = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: expected a JSON array of arrays of {PARAMS} numbers",
            params.display()
        )
    })?;
    let env = make_env(kind, &EnvConfig::default());
    let mut noise = ugl_bench::seed::stream(seed, ugl_bench::seed::Component::Distractor);
    let mut out = Vec::with_capacity(v.len());
    for (i, theta) in v.iter().enumerate() {
        let theta: [f64; PARAMS] = theta.as_slice().try_into().map_err(|_| {
            anyhow::anyhow!(
                "{}: entry {i} has {} numbers, expected {PARAMS}",
                params.display(),
                theta.len()
            )
        })?;
        if theta.iter().any(|x| !x.is_finite()) {
            bail!("{}: entry {i} has a non-finite number", params.display());
        }
        let r = env.rollout(&theta, &mut noise);
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
    let dim = kind.metric_dims().len();
    let pts = read_outcomes_csv(path, dim)?;
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
    let mut buf = vec![0f32; PIXELS];
    env.render_into(&vals, &mut buf);
    let img = Image70(buf);
    match out.extension().and_then(|e| e.to_str()) {
        Some("npy") => write_npy(&img, out)?,
        Some("png") => write_png(&img, out)?,
        _ => bail!(
            "--out {}: the extension must be .npy or .png",
            out.display()
        ),
    }
    Ok(())
}
