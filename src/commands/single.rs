//! `ugl run` and `ugl embed`: one run, or one fitted representation, outside a campaign.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use indicatif::MultiProgress;

use ugl_bench::campaign::config::{CampaignConfig, resolve_profile};
use ugl_bench::campaign::fit::Source;
use ugl_bench::campaign::single::{self, RunRequest};
use ugl_bench::campaign::{Harness, RunContext, RunSpec};
use ugl_bench::explore::{Algo, SamplerKind};
use ugl_bench::repr::cache::ModelCache;

use crate::cli::{CacheArgs, EmbedArgs};
use crate::output::outln;
use crate::progress::{learner_lines, progress_area, training_bars};

pub(crate) fn run(
    a: RunRequest,
    profile: &str,
    out: &Path,
    cache: &CacheArgs,
    allow_dirty: bool,
) -> Result<()> {
    let path = resolve_profile(profile)?;
    let mut cfg = CampaignConfig::load(&path)?;
    let spec = a.resolve(&mut cfg, &path).map_err(anyhow::Error::msg)?;
    if !allow_dirty {
        check_clean_tree(out)?;
    }
    check_out_dir(out)?;
    let model_cache = cache.resolve(out);
    let mp = progress_area();
    let ctx = single_context(&cfg, profile, model_cache.as_ref(), cache, out, &mp);
    ugl_bench::campaign::check_single_run(&cfg, &spec.run_id(), &ctx.config_hash(&spec), out)?;
    let summary = ugl_bench::campaign::execute(&spec, &ctx, out, None)?;
    outln!("{}", serde_json::to_string(&summary)?)?;
    Ok(())
}

/// The context of one run or one representation (`ugl run`, `ugl embed`): the whole machine's
/// threads, training bars and learner lines in `mp`, learner logs and the model cache in `out`.
pub(crate) fn single_context<'a>(
    cfg: &'a CampaignConfig,
    profile: &'a str,
    model_cache: Option<&'a ModelCache>,
    cache: &CacheArgs,
    out: &'a Path,
    mp: &MultiProgress,
) -> RunContext<'a> {
    let harness = Harness {
        profile,
        cache: model_cache,
        checkpoint_every: cache.checkpoint_every,
        keep_checkpoints: cache.keep_checkpoints,
        train_progress: Some(training_bars(mp, None)),
        learner_messages: Some(learner_lines(mp, None)),
        log_dir: Some(out),
        train_threads: 0,
    };
    RunContext::new(cfg, rayon::current_num_threads(), harness)
}

/// An output directory must be a directory (created if missing).
pub(crate) fn check_out_dir(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        bail!("--out {}: exists and is not a directory", out.display());
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))
}

/// Results written into a checkout's `data/` are the ones that get committed: refused while
/// tracked files of that checkout (the one holding `out`'s real path, symlinks followed, whose
/// revision every manifest written there records) have uncommitted changes, since the manifests
/// would record a `-dirty` revision that no commit reproduces. `--allow-dirty` overrides;
/// results written outside a checkout's `data/` are never refused.
pub(crate) fn check_clean_tree(out: &Path) -> Result<()> {
    use ugl_bench::campaign::provenance::{checkout_of, real_path, revision_of};
    let real = real_path(out);
    let Some(top) = checkout_of(&real) else {
        return Ok(());
    };
    if !real.starts_with(top.join("data")) {
        return Ok(());
    }
    let revision = revision_of(Some(&top));
    if revision.ends_with("-dirty") {
        bail!(
            "--out {}: the checkout {} has uncommitted changes to tracked files, and runs written \
             into its data/ would record the revision {revision}, which no commit reproduces: \
             commit or stash the changes, write elsewhere with --out, or pass --allow-dirty",
            out.display(),
            top.display(),
        );
    }
    Ok(())
}

/// `ugl embed`: the latents of one fitted goal space.
pub(crate) fn embed(a: EmbedArgs) -> Result<()> {
    single::check_seed(a.seed).map_err(anyhow::Error::msg)?;
    let path = resolve_profile(&a.profile)?;
    let mut cfg = CampaignConfig::load(&path)?;
    single::set_images(&mut cfg, a.images).map_err(anyhow::Error::msg)?;
    let learner = single::resolve_learner(&a.learner, a.command.as_deref(), &mut cfg)
        .map_err(anyhow::Error::msg)?;
    single::check_learner_variant(learner, a.variant).map_err(anyhow::Error::msg)?;
    single::check_latents(a.latents, cfg.ugl.images).map_err(anyhow::Error::msg)?;
    if a.grid < 2 {
        bail!("--grid must be at least 2, got {}", a.grid);
    }
    // Before anything is fitted or allocated: GRID^2 images must fit in memory.
    ugl_bench::limits::check_grid(a.grid, cfg.ugl.images, a.env.spec().image.len())
        .map_err(anyhow::Error::msg)?;
    if a.out.extension().and_then(|e| e.to_str()) != Some("npy") {
        bail!("--out {}: the file name must end in .npy", a.out.display());
    }
    let dir = a
        .out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    check_out_dir(dir)?;
    let spec = RunSpec::learned(
        a.env,
        Algo::rge(learner),
        SamplerKind::KDE,
        a.latents,
        a.variant.unwrap_or_default(),
        a.seed,
    );
    let model_cache = a.cache.resolve(dir);
    let mp = progress_area();
    let ctx = single_context(&cfg, &a.profile, model_cache.as_ref(), &a.cache, dir, &mp);
    let source = a.checkpoint.map_or(Source::Fit, Source::Checkpoint);
    let e = ugl_bench::campaign::embed::embed(&spec, &ctx, a.grid, source)?;
    let stem = a.out.with_extension("");
    let sibling = |suffix: &str| PathBuf::from(format!("{}.{suffix}.npy", stem.display()));
    let files = [
        (a.out.clone(), e.train.n, e.train.latents, &e.train.data),
        (sibling("states"), e.train.n, e.state_dim, &e.train_states),
        (sibling("grid"), e.grid.n, e.grid.latents, &e.grid.data),
        (
            sibling("grid_states"),
            e.grid.n,
            e.state_dim,
            &e.grid_states,
        ),
    ];
    // All four files or none: the latents and their states never come from two embeddings.
    let paths: Vec<&std::path::Path> = files.iter().map(|f| f.0.as_path()).collect();
    ugl_bench::fsio::write_set_atomic(&paths, &|i, tmp| {
        let (_, rows, cols, data) = &files[i];
        ugl_bench::campaign::embed::write_npy_f64(tmp, *rows, *cols, data)
    })
    .with_context(|| format!("cannot write {}", a.out.display()))?;
    outln!(
        "{}",
        serde_json::json!({
            "representation": ugl_bench::campaign::fit::representation_label(&spec),
            "files": files.iter().map(|f| f.0.display().to_string()).collect::<Vec<_>>(),
            "latent_quality": e.quality,
            "checkpoint": a.checkpoint,
            "training": e.training.as_ref().map(|t| serde_json::json!({
                "key": t.key,
                "iterations": t.iterations,
                "evidence": t.evidence,
            })),
        })
    )?;
    Ok(())
}
