//! The store's campaigns and what the report does with each.
//!
//! A campaign is a sub-directory of the store (`data/results/<campaign>/`; runs directly in the
//! store form the campaign `""`, shown as "(top level)"). Campaigns are separate experiments: the
//! same run id may appear in two of them (the `paper` campaign and a `budget-vae-3000` campaign
//! share their seeds), and conditions are never merged across campaigns.
//!
//! - The **main** campaign ([`crate::ReportOptions::main_campaign`], default `paper`) feeds the
//!   sections that reproduce the paper: the KL-coverage curves (its Figure 2), the outcome
//!   scatters (Figure 3), Figure 4 (RGE-VAE with KDE vs Gaussian goals), the faithful-vs-corrected
//!   comparison and the final table against the paper's values.
//! - Campaigns named `budget-*` feed the training-budget sensitivity section.
//! - Campaigns named `compare-*` (written by `ugl compare --learner NAME`) hold a new learner run
//!   on the main campaign's cells and seeds: the leaderboard ranks it against the paper's
//!   algorithms and the KL-coverage figures draw it. Their runs of the external learner are
//!   labelled `rge-<NAME>` (the learner's name from the manifest), not `rge-external`.
//! - Campaigns named `<main>-*` (e.g. `paper-init`, `paper-long`) rerun cells of the main
//!   campaign with another training recipe for the neural learners, on the main campaign's run
//!   seeds: the training-recipes section pairs each of their runs with the main run of the same
//!   cell and seed.
//! - Any other campaign is listed as present but not used (its runs are not even read).

use std::path::{Path, PathBuf};

use crate::ReportError;
use crate::load::{Store, campaign_display, scan_store};

/// The prefix of the training-budget campaigns.
pub const BUDGET_PREFIX: &str = "budget-";

/// The prefix of the campaigns `ugl compare` writes.
pub const COMPARE_PREFIX: &str = "compare-";

/// A campaign that was read.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// Directory name (`""` for the store's top level).
    pub name: String,
    pub path: PathBuf,
    /// Its runs; may be empty (only incomplete runs so far) for a budget campaign.
    pub store: Store,
}

/// A campaign present in the store that the report does not use.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unused {
    pub name: String,
    pub complete: usize,
    pub incomplete: usize,
}

/// The store, split by campaign.
#[derive(Debug, Clone)]
pub struct Campaigns {
    pub main: Campaign,
    /// `budget-*` campaigns, sorted by name with numbers in numeric order (`budget-vae-300`
    /// before `budget-vae-1000`).
    pub budget: Vec<Campaign>,
    /// `compare-*` campaigns, sorted by name, external learners relabelled `rge-<name>`.
    pub compare: Vec<Campaign>,
    /// `<main>-*` campaigns (training-recipe variants of the main campaign), sorted by name.
    pub recipe: Vec<Campaign>,
    /// The follow-up paper's campaigns (`armballs`, `armballs-*`), sorted by name.
    pub followup: Vec<Campaign>,
    /// Everything else, sorted by name.
    pub unused: Vec<Unused>,
}

impl Campaigns {
    /// Runs the report uses (main, budget and compare campaigns).
    pub fn n_used_runs(&self) -> usize {
        self.main.store.runs.len()
            + self
                .budget
                .iter()
                .chain(&self.compare)
                .chain(&self.recipe)
                .chain(&self.followup)
                .map(|c| c.store.runs.len())
                .sum::<usize>()
    }
}

/// Sort key of a name with numbers in numeric order: its runs of digits compare as numbers.
pub fn natural_key(name: &str) -> Vec<(String, u128)> {
    let mut out = Vec::new();
    let mut text = String::new();
    let mut chars = name.chars().peekable();
    while let Some(c) = chars.next() {
        if c.is_ascii_digit() {
            let mut digits = c.to_string();
            while let Some(&d) = chars.peek().filter(|d| d.is_ascii_digit()) {
                digits.push(d);
                chars.next();
            }
            out.push((
                std::mem::take(&mut text),
                digits.parse().unwrap_or(u128::MAX),
            ));
        } else {
            text.push(c);
        }
    }
    out.push((text, 0));
    out
}

/// Whether a campaign holds a new learner to rank (`ugl compare`).
pub fn is_compare_campaign(name: &str) -> bool {
    name.starts_with(COMPARE_PREFIX)
}

/// Gives the runs of the external learner their learner's name: `rge-external` becomes
/// `rge-<learner>` (the manifest's `learner`), so that two compared programs stay apart.
pub fn relabel_external(store: &mut Store) {
    for run in &mut store.runs {
        if run.key.algo == "rge-external"
            && let Some(name) = run.manifest.get(&["learner"]).and_then(|v| v.as_str())
            && !name.is_empty()
        {
            run.key.algo = format!("rge-{name}");
        }
    }
}

/// Whether a campaign is a training-recipe variant of the main campaign `main`: named
/// `<main>-<something>`.
pub fn is_recipe_campaign(name: &str, main: &str) -> bool {
    !main.is_empty()
        && name
            .strip_prefix(main)
            .and_then(|rest| rest.strip_prefix('-'))
            .is_some_and(|rest| !rest.is_empty())
}

/// Whether a campaign feeds the budget-sensitivity section.
pub fn is_budget_campaign(name: &str) -> bool {
    name.starts_with(BUDGET_PREFIX)
}

/// Reads the main campaign `main` and the budget campaigns of the store `dir`; counts the others.
///
/// Errors: the store missing or empty as for [`crate::load::load_store`]; the main campaign
/// absent ([`ReportError::MissingMainCampaign`], listing the campaigns found) or without a
/// complete run ([`ReportError::NoCompleteRuns`]); any schema problem in a run that is read.
pub fn load_campaigns(dir: &Path, main: &str) -> Result<Campaigns, ReportError> {
    let dirs = scan_store(dir)?;
    if dirs.is_empty() {
        return Err(ReportError::EmptyResults(dir.to_path_buf()));
    }
    let Some(main_dir) = dirs.iter().find(|d| d.name == main) else {
        return Err(ReportError::MissingMainCampaign {
            dir: dir.to_path_buf(),
            main: campaign_display(main),
            found: dirs.iter().map(|d| campaign_display(&d.name)).collect(),
        });
    };
    let store = main_dir.load()?;
    if store.runs.is_empty() {
        return Err(ReportError::NoCompleteRuns {
            dir: main_dir.path.clone(),
            incomplete: store.incomplete.len(),
        });
    }
    let main_campaign = Campaign {
        name: main_dir.name.clone(),
        path: main_dir.path.clone(),
        store,
    };
    let mut budget = Vec::new();
    let mut compare = Vec::new();
    let mut recipe = Vec::new();
    let mut followup = Vec::new();
    let mut unused = Vec::new();
    for d in &dirs {
        if d.name == main {
            continue;
        }
        if is_budget_campaign(&d.name) {
            budget.push(Campaign {
                name: d.name.clone(),
                path: d.path.clone(),
                store: d.load()?,
            });
        } else if is_compare_campaign(&d.name) {
            let mut store = d.load()?;
            relabel_external(&mut store);
            compare.push(Campaign {
                name: d.name.clone(),
                path: d.path.clone(),
                store,
            });
        } else if crate::armballs::is_followup_campaign(&d.name) {
            followup.push(Campaign {
                name: d.name.clone(),
                path: d.path.clone(),
                store: d.load()?,
            });
        } else if is_recipe_campaign(&d.name, main) {
            recipe.push(Campaign {
                name: d.name.clone(),
                path: d.path.clone(),
                store: d.load()?,
            });
        } else {
            unused.push(Unused {
                name: d.name.clone(),
                complete: d.n_complete(),
                incomplete: d.n_incomplete(),
            });
        }
    }
    budget.sort_by_key(|c| natural_key(&c.name));
    // Variants (`armballs-*`) are drawn next to `armballs` only: without it they are unused.
    if !followup.iter().any(|c| c.name == crate::armballs::CAMPAIGN) {
        for c in followup.drain(..) {
            unused.push(Unused {
                complete: c.store.runs.len(),
                incomplete: c.store.incomplete.len(),
                name: c.name,
            });
        }
        unused.sort_by(|a, b| a.name.cmp(&b.name));
    }
    Ok(Campaigns {
        main: main_campaign,
        budget,
        compare,
        recipe,
        followup,
        unused,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_order_puts_numbers_in_numeric_order() {
        let mut v = vec![
            "budget-vae-10000",
            "budget-vae-300",
            "budget-vae-3000",
            "budget-vae-1000",
            "budget-ae-50",
        ];
        v.sort_by_key(|n| natural_key(n));
        assert_eq!(
            v,
            [
                "budget-ae-50",
                "budget-vae-300",
                "budget-vae-1000",
                "budget-vae-3000",
                "budget-vae-10000"
            ]
        );
        assert!(is_budget_campaign("budget-vae-300") && !is_budget_campaign("paper"));
        assert!(is_recipe_campaign("paper-init", "paper"));
        assert!(!is_recipe_campaign("paper", "paper"));
        assert!(!is_recipe_campaign("paper-", "paper"));
        assert!(!is_recipe_campaign("paperback", "paper"));
        assert!(!is_recipe_campaign("quick-init", "paper"));
    }
}
