//! Beyond the paper: the follow-up's question (Laversanne-Finot, Péré & Oudeyer, CoRL 2018,
//! "Curiosity Driven Exploration of Learned Disentangled Goal Spaces"), on the `followup`
//! campaigns: exploration of the controllable ball when the scene holds a distractor, the
//! interest (learning progress) of each goal module over time, how disentangled each learned goal
//! space is, and the follow-up's claims (`data/paper/followup_claims.toml`, evaluated by the one
//! claims engine; `docs/armballs.md` says how each is formalised).
//!
//! Inputs: the runs of the follow-up campaign and its variants: their curves (ball and distractor
//! coverage), their `<run>.interest.parquet` (modular runs) and their manifests'
//! `latent_quality.per_latent`. Output: the page `armballs.md`, two figures, and a summary for
//! `REPORT.md`. One module per concern: `runs` (reading), `labels` (names and order), `claims`
//! (the engine's view of the runs, and the claims table), `figures`, `page`.

mod authors;
mod claims;
mod figures;
mod labels;
mod page;
mod runs;
pub mod sweep;

use std::path::Path;

pub use claims::{FILE as CLAIMS_FILE, FollowupObservations};
pub use labels::Condition;
pub use runs::{FollowupRun, load};

use crate::campaigns::Campaign;
use crate::claims::ClaimResult;
use crate::error::ReportError;
use crate::figures::FigureFile;

/// The page this section writes.
pub const PAGE: &str = "armballs.md";
/// Its figures.
pub const COVERAGE_FIGURE: &str = "armballs_coverage.svg";
pub const INTEREST_FIGURE: &str = "armballs_interest.svg";

/// What the section produced.
pub struct Section {
    /// The page `armballs.md`.
    pub page: String,
    /// The section of `REPORT.md` (claims and a link to the page).
    pub summary: String,
    pub figures: Vec<FigureFile>,
}

/// The follow-up's claims, as the page shows them.
pub enum FollowupClaims<'a> {
    /// Evaluated from this file.
    Evaluated {
        path: &'a Path,
        confidence: f64,
        results: Vec<ClaimResult>,
        /// Where the ball's ratio is read when some runs are of the authors' environment: our
        /// last evaluation at or before their last point, these rollouts (None: the last
        /// epoch).
        ratio_at: Option<i64>,
    },
    /// No claims file where the report looked.
    Missing(&'a Path),
}

/// Renders the section; `None` when the campaigns have no run. `paper_dir` holds the claims
/// file.
pub fn render(
    campaign: &Campaign,
    variants: &[&Campaign],
    fig_dir: &Path,
    paper_dir: &Path,
) -> Result<Option<Section>, ReportError> {
    let mut runs = load(campaign)?;
    for v in variants {
        runs.extend(load(v)?);
    }
    runs::separate_conditions(&mut runs);
    runs.sort_by(|a, b| {
        a.cond
            .order()
            .cmp(&b.cond.order())
            .then(a.seed.cmp(&b.seed))
    });
    if runs.is_empty() {
        return Ok(None);
    }
    let published = authors::load(paper_dir)?;
    let mut figures = vec![figures::draw_coverage(&runs, published.as_ref(), fig_dir)?];
    figures.extend(figures::draw_interest(&runs, fig_dir)?);
    let path = paper_dir.join(CLAIMS_FILE);
    let followup_claims = if path.exists() {
        let file = crate::claims::load_claims(&path)?;
        let obs = FollowupObservations {
            runs: &runs,
            authors: published.as_ref(),
        };
        let results = crate::claims::evaluate_on(&file, &obs);
        FollowupClaims::Evaluated {
            path: &path,
            confidence: file.settings.confidence,
            results,
            ratio_at: obs.comparable_authors().map(|a| a.last_rollouts),
        }
    } else {
        FollowupClaims::Missing(&path)
    };
    let (page, summary) = page::write(campaign, variants, &runs, &figures, &followup_claims);
    Ok(Some(Section {
        page,
        summary,
        figures,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::Store;

    /// A campaign of no runs named `name` (the page reads the runs it is given).
    fn empty_campaign(name: &str) -> Campaign {
        Campaign {
            name: name.into(),
            path: name.into(),
            decl: Default::default(),
            configurations: 1,
            store: Store {
                runs: Vec::new(),
                incomplete: Vec::new(),
            },
        }
    }

    fn run(algo: &str, sampler: &str, latents: i64, seed: i64, ratio: f64) -> FollowupRun {
        let key = ugl_types::ConditionKey {
            env: "armballs".into(),
            algo: algo.into(),
            sampler: sampler.into(),
            latents,
            variant: "none".into(),
            tag: None,
        };
        FollowupRun {
            learner: (latents > 0).then(|| "vae".into()),
            ..FollowupRun::test_run(key, seed, ratio)
        }
    }

    /// In the authors' environment the coverage figure draws their mean curves beside ours
    /// (thin, in the condition's colour); elsewhere it does not.
    #[test]
    fn the_authors_curves_are_drawn_in_their_environment_only() {
        let dir = tempfile::tempdir().unwrap();
        let paper = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper");
        let published = authors::load(&paper).unwrap().unwrap();
        let mut rs: Vec<FollowupRun> = (0..2)
            .map(|s| run("mge-efr-lp", "uniform", 0, s, 0.5))
            .collect();
        let svg = |rs: &[FollowupRun]| {
            let f = figures::draw_coverage(rs, Some(&published), dir.path()).unwrap();
            std::fs::read_to_string(&f.path).unwrap()
        };
        assert!(!svg(&rs).contains("the authors"));
        for r in &mut rs {
            r.key.env = "armballs-corl".into();
        }
        let text = svg(&rs);
        assert!(
            text.contains("the authors&apos; mean, n=15")
                || text.contains("the authors' mean, n=15"),
            "no authors' curve"
        );
        assert!(text.contains("Thin lines: the authors"));
    }

    /// The claims' section says where the ball's ratio is read: at the authors' last point
    /// where some runs are of their environment, else at the last epoch.
    #[test]
    fn the_claims_say_where_the_ratio_is_read() {
        let campaign = empty_campaign("followup");
        let r = run("rpe", "none", 0, 0, 0.2);
        let page_at = |ratio_at| {
            let claims = FollowupClaims::Evaluated {
                path: Path::new("claims.toml"),
                confidence: 0.95,
                results: Vec::new(),
                ratio_at,
            };
            page::write(&campaign, &[], std::slice::from_ref(&r), &[], &claims).0
        };
        let page = page_at(Some(9666));
        assert!(page.contains("their last point (9666 rollouts)"), "{page}");
        let page = page_at(None);
        assert!(!page.contains("their last point"), "{page}");
        assert!(
            page.contains("exploration ratio and the goal-reaching error are read at the last"),
            "{page}"
        );
    }

    /// The disentanglement table gives MIG, SAP and the active latents with their kinds where
    /// the networks record them, and keeps its columns otherwise.
    #[test]
    fn the_disentanglement_table_shows_mig_sap_and_active_latents() {
        let campaign = empty_campaign("followup");
        let claims = FollowupClaims::Missing(Path::new("none.toml"));
        let mut r = run("mge-conv-bvae-lp", "gaussian", 3, 0, 0.4);
        r.learner = Some("conv-bvae".into());
        r.per_latent = Some((vec![0.9, 0.01, 0.02], vec![0.0, 0.8, 0.01]));
        let (page, _) = page::write(&campaign, &[], std::slice::from_ref(&r), &[], &claims);
        assert!(
            !page.contains("| MIG |"),
            "no MIG column without the measure"
        );
        r.mig = Some(0.45);
        r.sap = Some(0.3);
        r.kl_per_latent = vec![3.1, 2.9, 0.004];
        let (page, _) = page::write(&campaign, &[], &[r], &[], &claims);
        assert!(page.contains("| MIG | SAP | active latents |"), "{page}");
        assert!(
            page.contains("| 0.45 | 0.30 | 2 (ball, distractor) |"),
            "{page}"
        );
    }

    /// One algorithm run with two goal samplers and two latent sizes is four conditions of the
    /// page, never one pooled row (the page used to average them and count 4 seeds).
    #[test]
    fn samplers_and_latent_sizes_are_never_pooled() {
        let mut rs = Vec::new();
        for seed in 0..2 {
            rs.push(run("rpe", "none", 0, seed, 0.05));
            for (sampler, latents, ratio) in [
                ("kde", 4, 0.1),
                ("kde", 10, 0.2),
                ("gaussian", 4, 0.3),
                ("gaussian", 10, 0.4),
            ] {
                rs.push(run("mge-vae-lp", sampler, latents, seed, ratio));
            }
        }
        runs::separate_conditions(&mut rs);
        rs.sort_by_key(|r| r.cond.order());
        assert_eq!(runs::algos(&rs).len(), 5, "{:?}", runs::algos(&rs));
        assert!(
            rs.iter()
                .any(|r| r.cond.algo == "rpe" && r.cond.split.is_none()),
            "an algorithm run one way keeps its name"
        );
        let campaign = empty_campaign("armballs");
        let claims = FollowupClaims::Missing(Path::new("none.toml"));
        let (page, _) = page::write(&campaign, &[], &rs, &[], &claims);
        assert!(page.contains("(10 runs, 2 seeds)"), "{page}");
        assert!(page.contains("VAE, 4 and 10 latents"), "{page}");
        let row = |name: &str| {
            page.lines()
                .find(|l| l.starts_with(&format!("| {name} |")))
                .unwrap_or_else(|| panic!("no row {name} in\n{page}"))
                .to_string()
        };
        let r = row("MGE-VAE (LP), Gaussian goals, 10 latents");
        assert!(
            r.starts_with("| MGE-VAE (LP), Gaussian goals, 10 latents | 2 | 0.400"),
            "{r}"
        );
        let r = row("MGE-VAE (LP), KDE goals, 4 latents");
        assert!(r.contains("| 2 | 0.100"), "{r}");
    }
}
