//! The store's campaigns and what the report does with each.
//!
//! A campaign is a sub-directory of the store (`data/results/<campaign>/`; runs directly in the
//! store form the campaign `""`, shown as "(top level)"). Campaigns are separate experiments: the
//! same run id may appear in two of them (the `paper` campaign and a `budget-vae-3000` campaign
//! share their seeds), and conditions are never merged across campaigns.
//!
//! What each campaign is for is declared in its TOML (`[campaign] role`, `variant_of`, `tag`,
//! `label`) and recorded beside its runs (`campaign.toml`, [`ugl_types::CampaignRecord`]); the
//! report reads the record and never infers a role from a directory name.
//!
//! - The **main** campaign ([`crate::options::ReportOptions::main_campaign`], default `paper`) feeds the
//!   sections that reproduce the paper: the KL-coverage curves (its Figure 2), the outcome
//!   scatters (Figure 3), Figure 4 (RGE-VAE with KDE vs Gaussian goals), the faithful-vs-corrected
//!   comparison and the final table against the paper's values.
//! - Campaigns of role `budget` feed the training-budget sensitivity section.
//! - Campaigns of role `compare` (written by `ugl compare --learner NAME`) hold a new learner run
//!   on the main campaign's cells and seeds: the leaderboard ranks it against the paper's
//!   algorithms and the KL-coverage figures draw it. Their runs of the external learner are
//!   labelled `rge-<NAME>` (the learner's name from the manifest), not `rge-external`.
//! - Campaigns of role `recipe` with `variant_of` the main campaign (e.g. `paper-init`,
//!   `paper-long`) rerun its cells with another training recipe for the neural learners, on its
//!   run seeds: the training-recipes section pairs each of their runs with the main run of the
//!   same cell and seed.
//! - Campaigns of role `followup` feed the follow-up paper's page: the one without `variant_of`,
//!   and the variants of it, drawn with their tag and label.
//! - Any other campaign (another `main`, a recipe of another campaign, a store without a record)
//!   is listed as present but not used (its runs are not even read).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use ugl_types::{CampaignDecl, CampaignRecord, CampaignRole};

use crate::error::ReportError;
use crate::load::{CampaignDir, Store, campaign_display, scan_store};

/// A campaign that was read.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// Directory name (`""` for the store's top level).
    pub name: String,
    pub path: PathBuf,
    /// What it declares itself to be (the default, `main`, where it has no record).
    pub decl: CampaignDecl,
    /// Its runs; may be empty (only incomplete runs so far) for a budget campaign.
    pub store: Store,
    /// How many configurations its runs were run with ([`configurations`]): 1 for a sound
    /// campaign; more is flagged at the top of the report.
    pub configurations: usize,
}

impl Campaign {
    /// The name its conditions go by beside the campaign it varies (`rge-vae@untrained`): its
    /// declared tag, else its name.
    pub fn tag(&self) -> String {
        self.decl.tag.clone().unwrap_or_else(|| self.name.clone())
    }
}

/// The configurations of a campaign's runs: distinct (campaign seed, `[explore]`, `[env]`) of
/// its runs, and distinct `[ugl]` of those in a learned goal space; the larger count. The
/// runner refuses to mix configurations in one store; a store assembled by hand (or by an
/// older build) can still hold several, and its statistics would pool them.
pub fn configurations(store: &Store) -> usize {
    let mut base = BTreeSet::new();
    let mut ugl = BTreeSet::new();
    for r in &store.runs {
        let m = &r.manifest;
        base.insert(format!(
            "{}|{}|{}",
            m.campaign_seed, m.explore, m.env_config
        ));
        if let Some(u) = &m.ugl {
            ugl.insert(u.to_string());
        }
    }
    base.len().max(ugl.len())
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
    /// `budget` campaigns, sorted by name with numbers in numeric order (`budget-vae-300`
    /// before `budget-vae-1000`).
    pub budget: Vec<Campaign>,
    /// `compare` campaigns, sorted by name, external learners relabelled `rge-<name>`.
    pub compare: Vec<Campaign>,
    /// `recipe` campaigns varying the main campaign, sorted by name.
    pub recipe: Vec<Campaign>,
    /// The follow-up paper's campaign (the first `followup` campaign that varies no other) and
    /// its variants, sorted by name.
    pub followup: Vec<Campaign>,
    /// `validation` campaigns varying the main campaign (held-out repetitions for the validity
    /// check), sorted by name.
    pub validation: Vec<Campaign>,
    /// Everything else, sorted by name.
    pub unused: Vec<Unused>,
}

impl Campaigns {
    /// The campaigns of a role that the report reads (the main campaign alone for `Main`).
    pub fn of_role(&self, role: CampaignRole) -> &[Campaign] {
        match role {
            CampaignRole::Main => std::slice::from_ref(&self.main),
            CampaignRole::Budget => &self.budget,
            CampaignRole::Compare => &self.compare,
            CampaignRole::Recipe => &self.recipe,
            CampaignRole::Followup => &self.followup,
            CampaignRole::Validation => &self.validation,
        }
    }

    /// Every campaign the report reads: the main one first, then by role.
    pub fn used(&self) -> impl Iterator<Item = &Campaign> {
        std::iter::once(&self.main)
            .chain(&self.budget)
            .chain(&self.compare)
            .chain(&self.recipe)
            .chain(&self.followup)
            .chain(&self.validation)
    }

    /// Runs the report uses (main, budget and compare campaigns).
    pub fn n_used_runs(&self) -> usize {
        self.main.store.runs.len()
            + self
                .budget
                .iter()
                .chain(&self.compare)
                .chain(&self.recipe)
                .chain(&self.followup)
                .chain(&self.validation)
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

/// Gives the runs of the external learner their learner's name: `rge-external` becomes
/// `rge-<learner>` (the manifest's `learner`), so that two compared programs stay apart.
pub fn relabel_external(store: &mut Store) {
    for run in &mut store.runs {
        if run.key.algo == ugl_types::Algo::of_learner(&ugl_types::learners::EXTERNAL)
            && let Some(name) = run.manifest.learner.as_deref()
            && !name.is_empty()
        {
            run.key.algo = format!("rge-{name}").into();
        }
    }
}

/// Reads the main campaign `main` of the store `dir` and the campaigns whose role is `wanted`
/// (the roles the report's sections read, [`crate::sections::wanted_roles`]); counts the others.
///
/// Errors: the store missing or empty as for [`crate::load::load_store`]; the main campaign
/// absent ([`ReportError::MissingMainCampaign`], listing the campaigns found) or without a
/// complete run ([`ReportError::NoCompleteRuns`]); any schema problem in a run that is read.
pub fn load_campaigns(
    dir: &Path,
    main: &str,
    wanted: &BTreeSet<CampaignRole>,
) -> Result<Campaigns, ReportError> {
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
    let main_campaign = read(main_dir, record(main_dir)?.unwrap_or_default())?;
    if main_campaign.store.runs.is_empty() {
        return Err(ReportError::NoCompleteRuns {
            dir: main_dir.path.clone(),
            incomplete: main_campaign.store.incomplete.len(),
        });
    }
    let mut budget = Vec::new();
    let mut compare = Vec::new();
    let mut recipe = Vec::new();
    let mut followup = Vec::new();
    let mut validation = Vec::new();
    let mut unused = Vec::new();
    let varies_main = |decl: &CampaignDecl| decl.variant_of.as_deref().is_none_or(|v| v == main);
    for d in &dirs {
        if d.name == main {
            continue;
        }
        let decl = record(d)?;
        match decl
            .as_ref()
            .map(|decl| decl.role)
            .filter(|r| wanted.contains(r))
        {
            Some(CampaignRole::Budget) => budget.push(read(d, decl.unwrap_or_default())?),
            Some(CampaignRole::Compare) if decl.as_ref().is_some_and(varies_main) => {
                let mut c = read(d, decl.unwrap_or_default())?;
                relabel_external(&mut c.store);
                compare.push(c);
            }
            Some(CampaignRole::Recipe)
                if decl
                    .as_ref()
                    .is_some_and(|decl| decl.variant_of.as_deref() == Some(main)) =>
            {
                recipe.push(read(d, decl.unwrap_or_default())?)
            }
            Some(CampaignRole::Followup) => followup.push(read(d, decl.unwrap_or_default())?),
            Some(CampaignRole::Validation)
                if decl
                    .as_ref()
                    .is_some_and(|decl| decl.variant_of.as_deref() == Some(main)) =>
            {
                validation.push(read(d, decl.unwrap_or_default())?)
            }
            _ => unused.push(Unused {
                name: d.name.clone(),
                complete: d.n_complete(),
                incomplete: d.n_incomplete(),
            }),
        }
    }
    budget.sort_by_key(|c| natural_key(&c.name));
    // The follow-up's campaign is the first that varies no other; its variants are drawn next
    // to it, and without it they (and any other follow-up campaign) are unused.
    let lead = followup
        .iter()
        .find(|c| c.decl.variant_of.is_none())
        .map(|c| c.name.clone());
    let (kept, dropped): (Vec<Campaign>, Vec<Campaign>) = followup.into_iter().partition(|c| {
        lead.as_deref()
            .is_some_and(|lead| c.name == lead || c.decl.variant_of.as_deref() == Some(lead))
    });
    let followup = kept;
    if !dropped.is_empty() {
        for c in dropped {
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
        validation,
        unused,
    })
}

impl Campaigns {
    /// The follow-up paper's campaign and its variants, if the store has it.
    pub fn followup_lead(&self) -> Option<(&Campaign, Vec<&Campaign>)> {
        let lead = self.followup.iter().find(|c| c.decl.variant_of.is_none())?;
        let variants = self
            .followup
            .iter()
            .filter(|c| c.name != lead.name)
            .collect();
        Some((lead, variants))
    }
}

/// The declaration a campaign directory records ([`CampaignRecord`]); None without a record.
fn record(d: &CampaignDir) -> Result<Option<CampaignDecl>, ReportError> {
    CampaignRecord::read(&d.path)
        .map(|r| r.map(|r| r.decl))
        .map_err(|e| ReportError::Invalid {
            path: CampaignRecord::path(&d.path),
            problem: e.to_string(),
        })
}

/// Reads a campaign's runs.
fn read(d: &CampaignDir, decl: CampaignDecl) -> Result<Campaign, ReportError> {
    let store = d.load()?;
    Ok(Campaign {
        name: d.name.clone(),
        path: d.path.clone(),
        decl,
        configurations: configurations(&store),
        store,
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
    }
}
