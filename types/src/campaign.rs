//! What a campaign is for. Each campaign TOML declares it (`[campaign] role`, and for a variant
//! what it varies and how the report labels it); `ugl campaign` records the declaration beside
//! the runs ([`RECORD_FILE`]) and in every manifest, and the report reads it from there. Nothing
//! infers a role from a directory name.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The campaign record's file name in a campaign's results directory.
pub const RECORD_FILE: &str = "campaign.toml";

/// The role of a campaign in the report.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum CampaignRole {
    /// A matrix that stands on its own: the report's main campaign is one (`--main`).
    #[default]
    Main,
    /// A training-budget variant of the neural learners (the budget-sensitivity section).
    Budget,
    /// A new learner on the main campaign's cells and seeds (`ugl compare`; the leaderboard).
    Compare,
    /// A training-recipe variant of the main campaign, on its run seeds (paired with it).
    Recipe,
    /// The follow-up paper's setting (ArmBalls, modular goal exploration).
    Followup,
    /// Held-out repetitions of the main campaign's matrix and controls (another campaign seed),
    /// on which the report runs the validity check of its measures of discovery, so that the
    /// runs that validate a measure are not those the claims use.
    Validation,
}

impl CampaignRole {
    pub const ALL: [CampaignRole; 6] = [
        CampaignRole::Main,
        CampaignRole::Budget,
        CampaignRole::Compare,
        CampaignRole::Recipe,
        CampaignRole::Followup,
        CampaignRole::Validation,
    ];

    pub fn name(self) -> &'static str {
        match self {
            CampaignRole::Main => "main",
            CampaignRole::Budget => "budget",
            CampaignRole::Compare => "compare",
            CampaignRole::Recipe => "recipe",
            CampaignRole::Followup => "followup",
            CampaignRole::Validation => "validation",
        }
    }
}

/// A campaign's declaration of what it is (the role keys of its `[campaign]` table).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignDecl {
    #[serde(default)]
    pub role: CampaignRole,
    /// The campaign it is a variant of (a recipe or compare campaign: the main campaign whose
    /// cells and seeds it shares; a follow-up variant: the follow-up campaign it is drawn with).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant_of: Option<String>,
    /// A short name for its conditions beside those of the campaign it varies (`still`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tag: Option<String>,
    /// How the report names the variant in prose and legends (`still distractor`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

/// The record of a campaign in its results directory ([`RECORD_FILE`]): its name and its
/// declaration, as a TOML table (`name = ...`, then the declaration's keys).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CampaignRecord {
    /// The campaign's name (`[campaign] name`).
    pub name: String,
    pub decl: CampaignDecl,
    /// The hash of the configuration its runs were run with (every constant of the campaign
    /// TOML but its matrix: seeds, exploration, environment, learners); a campaign with another
    /// configuration does not write into this store. None in records written before it was kept.
    pub configuration: Option<String>,
}

/// Errors reading a campaign record or a run's diagnostics.
#[derive(Debug, Error)]
pub enum RecordError {
    #[error("cannot read {}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: cannot be read: {message}", path.display())]
    Parse { path: PathBuf, message: String },
}

impl CampaignRecord {
    /// The record of the campaign `name` declared as `decl`.
    pub fn new(name: &str, decl: &CampaignDecl) -> CampaignRecord {
        CampaignRecord {
            name: name.to_string(),
            decl: decl.clone(),
            configuration: None,
        }
    }

    /// The same record, with its configuration hash.
    pub fn with_configuration(mut self, hash: &str) -> CampaignRecord {
        self.configuration = Some(hash.to_string());
        self
    }

    /// Whether two records describe one campaign: the same name and declaration, and the same
    /// configuration where both record one.
    pub fn same_campaign(&self, other: &CampaignRecord) -> bool {
        self.name == other.name
            && self.decl == other.decl
            && match (&self.configuration, &other.configuration) {
                (Some(a), Some(b)) => a == b,
                _ => true,
            }
    }

    /// The record file of the campaign directory `dir`.
    pub fn path(dir: &Path) -> PathBuf {
        dir.join(RECORD_FILE)
    }

    /// The record of `dir`; `Ok(None)` where there is none (a store written before records).
    pub fn read(dir: &Path) -> Result<Option<CampaignRecord>, RecordError> {
        let path = CampaignRecord::path(dir);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(source) => return Err(RecordError::Io { path, source }),
        };
        CampaignRecord::parse(&text)
            .map(Some)
            .map_err(|message| RecordError::Parse { path, message })
    }

    /// Parses a record's text; the error says what is wrong.
    pub fn parse(text: &str) -> Result<CampaignRecord, String> {
        let mut table: toml::Table = toml::from_str(text).map_err(|e| e.message().to_string())?;
        let name = match table.remove("name") {
            Some(toml::Value::String(name)) => name,
            Some(_) => return Err("`name` is not a string".into()),
            None => return Err("missing `name`".into()),
        };
        let configuration = match table.remove("configuration") {
            Some(toml::Value::String(c)) => Some(c),
            Some(_) => return Err("`configuration` is not a string".into()),
            None => None,
        };
        let decl = toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| e.message().to_string())?;
        Ok(CampaignRecord {
            name,
            decl,
            configuration,
        })
    }

    /// The record's text: a comment line, then the TOML.
    pub fn to_text(&self) -> String {
        let decl = toml::to_string(&self.decl).expect("a campaign declaration serialises");
        let configuration = match &self.configuration {
            Some(c) => format!("configuration = {}\n", toml::Value::String(c.clone())),
            None => String::new(),
        };
        format!(
            "# What this campaign is, from the [campaign] table of its TOML (written by `ugl campaign`).\nname = {}\n{configuration}{decl}",
            toml::Value::String(self.name.clone())
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_round_trips_and_rejects_unknown_roles() {
        let decl = CampaignDecl {
            role: CampaignRole::Followup,
            variant_of: Some("armballs".into()),
            tag: Some("still".into()),
            label: Some("still distractor".into()),
        };
        let r = CampaignRecord::new("armballs-still", &decl);
        let text = r.to_text();
        assert_eq!(CampaignRecord::parse(&text).unwrap(), r);
        assert!(
            text.contains("\nname = \"armballs-still\"\nrole = \"followup\"\n"),
            "{text}"
        );
        let with = r.clone().with_configuration("abc");
        assert_eq!(CampaignRecord::parse(&with.to_text()).unwrap(), with);
        assert!(with.same_campaign(&r) && r.same_campaign(&with));
        assert!(!with.same_campaign(&r.clone().with_configuration("abd")));
        let bad = text.replace("followup", "sequel");
        assert!(CampaignRecord::parse(&bad).is_err());
        assert!(CampaignRecord::parse(&text.replace("tag", "tags")).is_err());
        assert!(CampaignRecord::parse("role = \"main\"\n").is_err());
        for role in CampaignRole::ALL {
            let t = format!("name = \"x\"\nrole = \"{}\"\n", role.name());
            assert_eq!(CampaignRecord::parse(&t).unwrap().decl.role, role);
        }
    }
}
