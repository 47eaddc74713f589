//! The `[env]` table. What the arm environments share (`arm`, `dmp`, `object_size`) is declared
//! here; what one environment owns (a ball's start, the distractor's walk) is declared in its
//! own file, as a struct implementing [`OwnConstants`], and reached through its registry entry
//! ([`crate::EnvEntry::constants`]). A campaign sets an environment's constant in its table,
//! `[env.armballs] distractor_noise = 0.0`, or for every environment that has the key in
//! `[env]` itself (`distractor_noise = 0.0`: ArmBalls and the follow-up's ArmBalls), as
//! campaign files have done since the start. A new constant of one environment is an edit of
//! that environment's file alone.
//!
//! Two written forms, both kept byte for byte from results version 4, when every constant was a
//! field of one struct:
//! - the configuration's ([`EnvConfig`]'s `Serialize`: manifests, model-cache keys, the campaign
//!   configuration hash): the shared constants, then each own key set in `[env]` (or left at its
//!   default), then the tables that differ from it;
//! - a run's ([`EnvConfig::relevant_to`], its config hash): only what the run's environment
//!   reads.

use std::collections::BTreeMap;

use serde::de::DeserializeOwned;
use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize};
use toml::Value;

use crate::invalid::{InvalidValue, within};
use crate::{ArmConfig, DmpConfig, EnvKind, MAX_TIMESTEPS, PARAMS, dmp};

/// Constants as a TOML table (whose numbers, unlike JSON's, may be NaN or infinite: such a
/// value is refused by the range checks, naming its key, rather than lost on the way).
pub type Table = toml::Table;

/// The own keys that every configuration and every run record has written since results
/// version 4 (when they were fields of the one struct), set or not, in this order: the hashes
/// of the committed stores depend on them. Other own keys are written only when they differ
/// from their default.
const RECORDED_ALWAYS: [&str; 2] = ["ball_initial", "arrow_initial"];

/// The constants one environment owns: a struct of its file, every field defaulted, that
/// serialises to a JSON object (its `[env.NAME]` table).
pub trait OwnConstants: Serialize + DeserializeOwned + Default {
    /// Check every value against its range. `key("ball_initial[0]")` spells a key as the
    /// campaign file set it (`env.armball.ball_initial[0]`, or `env.ball_initial[0]` when it
    /// was set for every environment); the error's key and message use that spelling.
    fn check(&self, key: &dyn Fn(&str) -> String) -> Result<(), InvalidValue>;
}

/// An environment without constants of its own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoConstants {}

impl OwnConstants for NoConstants {
    fn check(&self, _key: &dyn Fn(&str) -> String) -> Result<(), InvalidValue> {
        Ok(())
    }
}

/// How the registry reaches an environment's own constants: [`OwnTable::of`] its struct.
#[derive(Clone, Copy, Debug)]
pub struct OwnTable {
    /// Every key at its default.
    defaults: fn() -> Table,
    /// Parse a whole table (every key present) as the struct, and write it back: the table
    /// in its normal form (a number as the struct's type writes it).
    parse: fn(Table) -> Result<Table, String>,
    /// Check a parsed table's values.
    check: fn(Table, &dyn Fn(&str) -> String) -> Result<(), InvalidValue>,
}

impl OwnTable {
    /// The table of the constants struct `T`.
    pub const fn of<T: OwnConstants>() -> OwnTable {
        OwnTable {
            defaults: defaults_of::<T>,
            parse: parse_of::<T>,
            check: check_of::<T>,
        }
    }

    /// No constants of its own.
    pub const NONE: OwnTable = OwnTable::of::<NoConstants>();
}

fn defaults_of<T: OwnConstants>() -> Table {
    Table::try_from(T::default())
        .unwrap_or_else(|e| panic!("an environment's own constants must write as a table: {e}"))
}

/// A deserialisation error in one line.
fn line(e: impl std::fmt::Display) -> String {
    e.to_string().trim().replace('\n', " ")
}

/// A reading error's message, without the key path `toml` appends (the caller names the key).
fn message(e: toml::de::Error) -> String {
    line(e.message())
}

/// The message `message` about `key`: a message that names its key already is kept, one that
/// continues a sentence (`must have 2 numbers`) follows the key.
fn keyed(key: &str, message: &str) -> String {
    if message.starts_with("env.") {
        message.to_string()
    } else if message.starts_with("must ") {
        format!("{key} {message}")
    } else {
        format!("{key}: {message}")
    }
}

fn parse_of<T: OwnConstants>(t: Table) -> Result<Table, String> {
    let own: T = Value::Table(t).try_into().map_err(message)?;
    Table::try_from(own).map_err(line)
}

fn check_of<T: OwnConstants>(t: Table, key: &dyn Fn(&str) -> String) -> Result<(), InvalidValue> {
    own_of::<T>(t).check(key)
}

fn own_of<T: OwnConstants>(t: Table) -> T {
    Value::Table(t)
        .try_into()
        .unwrap_or_else(|e| panic!("environment constants checked when set no longer parse: {e}"))
}

/// Constants of the environments; the defaults are the paper's code's (docs/original-code.md
/// section 1). Read from a campaign file's `[env]` table, checked by [`EnvConfig::validate`].
#[derive(Clone, Debug, PartialEq)]
pub struct EnvConfig {
    /// Arm geometry (the arm environments').
    pub arm: ArmConfig,
    /// Motor primitive (the arm environments').
    pub dmp: DmpConfig,
    /// Catch radius: the object is caught when the squared hand-object distance is below its
    /// square. In (0, 1].
    pub object_size: f64,
    /// Own keys set in `[env]` itself: for every environment that has them.
    every: Table,
    /// Own keys set in an environment's `[env.NAME]` table, by its name.
    tables: BTreeMap<String, Table>,
}

impl Default for EnvConfig {
    fn default() -> Self {
        EnvConfig {
            arm: ArmConfig::default(),
            dmp: DmpConfig::default(),
            object_size: 0.1,
            every: Table::new(),
            tables: BTreeMap::new(),
        }
    }
}

/// The environments that own `key`, in the registry's order.
fn owners(key: &str) -> Vec<EnvKind> {
    EnvKind::all()
        .into_iter()
        .filter(|k| k.defaults().contains_key(key))
        .collect()
}

/// A key's default: its first owner's.
fn default_of(key: &str) -> Option<Value> {
    owners(key).first().and_then(|k| k.defaults().remove(key))
}

/// Every own key of the registry, each once, in the order in which the environments declare
/// them (the recorded-always ones first).
fn own_keys() -> Vec<String> {
    let mut keys: Vec<String> = RECORDED_ALWAYS.iter().map(|k| k.to_string()).collect();
    for kind in EnvKind::all() {
        for k in kind.defaults().keys() {
            if !keys.contains(k) {
                keys.push(k.clone());
            }
        }
    }
    keys.retain(|k| !owners(k).is_empty());
    keys
}

impl EnvKind {
    fn defaults(self) -> Table {
        (self.0.constants.defaults)()
    }
}

impl EnvConfig {
    /// The own constants of `kind` as the table it reads: its defaults, then the keys set in
    /// `[env]`, then its own table.
    pub fn table(&self, kind: EnvKind) -> Table {
        let mut t = kind.defaults();
        for (k, v) in &self.every {
            if t.contains_key(k) {
                t.insert(k.clone(), v.clone());
            }
        }
        if let Some(own) = self.tables.get(kind.name()) {
            t.extend(own.iter().map(|(k, v)| (k.clone(), v.clone())));
        }
        t
    }

    /// The own constants of `kind`, as its struct `T` (the one its registry entry declares:
    /// another struct is a bug of the caller and panics). Every value was checked when it was
    /// set.
    pub fn own<T: OwnConstants>(&self, kind: EnvKind) -> T {
        own_of(self.table(kind))
    }

    /// Set an own constant: `key` is `NAME.KEY` for environment NAME's table, or `KEY` for
    /// every environment that has it. A key no environment has, or a value of the wrong type,
    /// is refused; ranges are [`EnvConfig::validate`]'s.
    pub fn with(mut self, key: &str, value: impl Serialize) -> Result<Self, String> {
        let value = Value::try_from(value).map_err(line)?;
        match key.split_once('.') {
            Some((name, k)) => {
                let kind: EnvKind = name.parse()?;
                self.set_table(kind, k, value)?;
            }
            None => self.set_every(key, value)?,
        }
        self.check_types()?;
        Ok(self)
    }

    fn set_table(&mut self, kind: EnvKind, key: &str, value: Value) -> Result<(), String> {
        let defaults = kind.defaults();
        if !defaults.contains_key(key) {
            let keys: Vec<&str> = defaults.keys().map(String::as_str).collect();
            return Err(format!(
                "env.{name}.{key} is not a constant of {display} ({its}; arm, dmp and \
                 object_size are shared: they go in [env] itself)",
                name = kind.name(),
                display = kind.spec().display,
                its = if keys.is_empty() {
                    "it has none of its own".to_string()
                } else {
                    format!("its own: {}", keys.join(", "))
                },
            ));
        }
        self.tables
            .entry(kind.name().to_string())
            .or_default()
            .insert(key.to_string(), value);
        Ok(())
    }

    fn set_every(&mut self, key: &str, value: Value) -> Result<(), String> {
        if owners(key).is_empty() {
            let names: Vec<String> = EnvKind::all()
                .iter()
                .map(|k| format!("[env.{}]", k.name()))
                .collect();
            return Err(format!(
                "unknown key env.{key}: [env] takes arm, dmp, object_size, an environment's own \
                 constant for every environment that has it ({}), and one table per \
                 environment ({})",
                own_keys().join(", "),
                names.join(", ")
            ));
        }
        self.every.insert(key.to_string(), value);
        Ok(())
    }

    /// Every set own constant parses as its environment's struct (the error names the key as
    /// it was set), and is kept in its normal form (`0` set for a real number is `0.0`).
    fn check_types(&mut self) -> Result<(), String> {
        for kind in EnvKind::all() {
            let table = self.table(kind);
            let own: Vec<String> = self
                .tables
                .get(kind.name())
                .map(|t| t.keys().cloned().collect())
                .unwrap_or_default();
            let every: Vec<String> = self
                .every
                .keys()
                .filter(|k| table.contains_key(*k) && !own.contains(k))
                .cloned()
                .collect();
            for (key, in_table) in own
                .iter()
                .map(|k| (k, true))
                .chain(every.iter().map(|k| (k, false)))
            {
                let mut one = kind.defaults();
                one.insert(key.clone(), table[key].clone());
                let normal = (kind.0.constants.parse)(one)
                    .map_err(|e| keyed(&self.spelling(kind, key), &e))?;
                let slot = if in_table {
                    self.tables
                        .get_mut(kind.name())
                        .and_then(|t| t.get_mut(key))
                } else {
                    self.every.get_mut(key)
                };
                if let (Some(slot), Some(v)) = (slot, normal.get(key)) {
                    *slot = v.clone();
                }
            }
        }
        Ok(())
    }

    /// How a campaign file spelt the own key `key` of `kind`.
    fn spelling(&self, kind: EnvKind, key: &str) -> String {
        let root = key.split('[').next().unwrap_or(key);
        if self
            .tables
            .get(kind.name())
            .is_some_and(|t| t.contains_key(root))
        {
            format!("env.{}.{key}", kind.name())
        } else {
            format!("env.{key}")
        }
    }

    /// Read a `[env]` table (a campaign file's, or the Python package's `config`).
    pub fn from_table(table: Table) -> Result<Self, String> {
        let mut cfg = EnvConfig::default();
        let shared = |key: &str, e: toml::de::Error| keyed(&format!("env.{key}"), &message(e));
        for (key, value) in table {
            match key.as_str() {
                "arm" => cfg.arm = value.try_into().map_err(|e| shared("arm", e))?,
                "dmp" => cfg.dmp = value.try_into().map_err(|e| shared("dmp", e))?,
                "object_size" => {
                    cfg.object_size = value.try_into().map_err(|e| shared("object_size", e))?
                }
                name => match name.parse::<EnvKind>() {
                    Ok(kind) => {
                        let Value::Table(own) = value else {
                            return Err(format!(
                                "env.{name} must be a table of {}'s own constants",
                                kind.spec().display
                            ));
                        };
                        for (k, v) in own {
                            cfg.set_table(kind, &k, v)?;
                        }
                    }
                    Err(_) => cfg.set_every(name, value)?,
                },
            }
        }
        cfg.check_types()?;
        Ok(cfg)
    }

    /// The constants a run in `kind` depends on, in the order its config hash has written them
    /// since results version 4: the arm's and the motor primitive's (their defaults for an
    /// environment with its own arm, the follow-up's ArmBalls), the catch radius, the
    /// recorded-always keys (the environment's value, or the key's default when it does not
    /// have it), then its other own keys that differ from their default.
    pub fn relevant_to(&self, kind: EnvKind) -> RunConstants {
        let arm_body = kind.0.uses_arm;
        let table = self.table(kind);
        let defaults = kind.defaults();
        let mut own = Vec::new();
        for key in RECORDED_ALWAYS {
            if let Some(v) = table.get(key).cloned().or_else(|| default_of(key)) {
                own.push((key.to_string(), v));
            }
        }
        for (k, v) in &table {
            if !RECORDED_ALWAYS.contains(&k.as_str()) && defaults.get(k) != Some(v) {
                own.push((k.clone(), v.clone()));
            }
        }
        RunConstants {
            arm: if arm_body {
                self.arm.clone()
            } else {
                ArmConfig::default()
            },
            dmp: if arm_body {
                self.dmp.clone()
            } else {
                DmpConfig::default()
            },
            object_size: self.object_size,
            own,
        }
    }

    /// Check every value against its range (the fields' documentation and each environment's
    /// [`OwnConstants::check`]); the message names the key. Ranges keep each value finite and
    /// meaningful: an object starts in the scene, the arm's reach fits in it, and the motor
    /// primitive's movement is finite for every motor command (checked on the extreme
    /// commands, where a linear movement is largest).
    pub fn validate(&self) -> Result<(), InvalidValue> {
        let a = &self.arm;
        if let Some(l) = a.lengths.iter().find(|l| !(l.is_finite() && **l >= 0.0)) {
            return Err(InvalidValue::new(
                "env.arm.lengths",
                format!("env.arm.lengths must be finite and >= 0, got {l}"),
            ));
        }
        let reach: f64 = a.lengths.iter().sum();
        if !(reach > 0.0 && reach <= 1.0 + 1e-9) {
            return Err(InvalidValue::new(
                "env.arm.lengths",
                format!(
                    "env.arm.lengths must add up to a reach in (0, 1] (the scene), got {reach}"
                ),
            ));
        }
        within("env.arm.angle_shift", a.angle_shift, -2.0, 2.0)?;
        let d = &self.dmp;
        if !(1..=MAX_TIMESTEPS).contains(&d.timesteps) {
            return Err(InvalidValue::new(
                "env.dmp.timesteps",
                format!(
                    "env.dmp.timesteps must be between 1 and {MAX_TIMESTEPS}, got {}",
                    d.timesteps
                ),
            ));
        }
        for (k, v, lo, hi) in [
            ("env.dmp.run_time", d.run_time, f64::MIN_POSITIVE, 1e3),
            ("env.dmp.ay", d.ay, f64::MIN_POSITIVE, 1e4),
            ("env.dmp.ax", d.ax, f64::MIN_POSITIVE, 1e4),
            ("env.dmp.max_params", d.max_params, 0.0, 1e6),
            ("env.object_size", self.object_size, f64::MIN_POSITIVE, 1.0),
        ] {
            within(k, v, lo, hi)?;
        }
        // The joint angles are linear in the 3 weights of their joint, so their largest
        // magnitude over [-1, 1]^21 is reached at a vertex: the 8 sign patterns, shared by all
        // joints, cover every vertex of every joint.
        for signs in 0..8u32 {
            let theta: [f64; PARAMS] =
                std::array::from_fn(|k| if signs >> (k % 3) & 1 == 1 { 1.0 } else { -1.0 });
            if dmp::trajectory(d, &theta)
                .iter()
                .any(|q| q.iter().any(|v| !v.is_finite()))
            {
                return Err(InvalidValue::new(
                    "env.dmp",
                    format!(
                        "env.dmp: the movement is not finite with these constants (timesteps = {}, \
                     run_time = {}, ay = {}, ax = {}, max_params = {})",
                        d.timesteps, d.run_time, d.ay, d.ax, d.max_params
                    ),
                ));
            }
        }
        for kind in EnvKind::all() {
            (kind.0.constants.check)(self.table(kind), &|key| self.spelling(kind, key))?;
        }
        Ok(())
    }
}

impl<'de> Deserialize<'de> for EnvConfig {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        EnvConfig::from_table(Table::deserialize(d)?).map_err(serde::de::Error::custom)
    }
}

/// The configuration's written form: the shared constants; each own key as set in `[env]`
/// (or its default), written when it differs from its default or is recorded always; then,
/// under the environment's name, the keys of a table that differ from what `[env]` gives.
impl Serialize for EnvConfig {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("arm", &self.arm)?;
        m.serialize_entry("dmp", &self.dmp)?;
        m.serialize_entry("object_size", &self.object_size)?;
        for key in own_keys() {
            let default = default_of(&key);
            let value = self.every.get(&key).cloned().or_else(|| default.clone());
            if RECORDED_ALWAYS.contains(&key.as_str()) || value != default {
                m.serialize_entry(&key, &value)?;
            }
        }
        for kind in EnvKind::all() {
            let Some(own) = self.tables.get(kind.name()) else {
                continue;
            };
            // What the environment would read without its table: `[env]`'s key, else its own
            // default (not the key's first owner's, which another environment may declare apart).
            let defaults = kind.defaults();
            let differs: Table = own
                .iter()
                .filter(|(k, v)| self.every.get(*k).or_else(|| defaults.get(*k)) != Some(*v))
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect();
            if !differs.is_empty() {
                m.serialize_entry(kind.name(), &differs)?;
            }
        }
        m.end()
    }
}

/// The constants one run depends on ([`EnvConfig::relevant_to`]), written into its config hash.
#[derive(Clone, Debug, PartialEq)]
pub struct RunConstants {
    arm: ArmConfig,
    dmp: DmpConfig,
    object_size: f64,
    own: Vec<(String, Value)>,
}

impl Serialize for RunConstants {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(3 + self.own.len()))?;
        m.serialize_entry("arm", &self.arm)?;
        m.serialize_entry("dmp", &self.dmp)?;
        m.serialize_entry("object_size", &self.object_size)?;
        for (k, v) in &self.own {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn shared() -> String {
        format!(
            r#""arm":{},"dmp":{},"object_size":0.1"#,
            serde_json::to_string(&ArmConfig::default()).unwrap(),
            serde_json::to_string(&DmpConfig::default()).unwrap()
        )
    }

    fn toml(text: &str) -> Result<EnvConfig, String> {
        toml::from_str::<EnvConfig>(text).map_err(|e| e.to_string())
    }

    /// The written forms are results version 4's, when every constant was a field of one
    /// struct: the committed stores' configuration and config hashes depend on them.
    #[test]
    fn the_written_forms_keep_their_bytes() {
        let legacy = format!(
            r#"{{{},"ball_initial":[0.6,0.6],"arrow_initial":[0.6,0.6,0.6]"#,
            shared()
        );
        let d = EnvConfig::default();
        assert_eq!(serde_json::to_string(&d).unwrap(), format!("{legacy}}}"));
        for kind in [EnvKind::ARMBALL, EnvKind::ARMARROW, EnvKind::ARMBALLS] {
            let run = serde_json::to_string(&d.relevant_to(kind)).unwrap();
            assert_eq!(run, format!("{legacy}}}"), "{kind}");
        }
        // A still distractor, as `armballs-still` sets it (`[env] distractor_noise = 0.0`).
        let still = toml("distractor_noise = 0").unwrap();
        assert_eq!(
            serde_json::to_string(&still).unwrap(),
            format!(r#"{legacy},"distractor_noise":0.0}}"#)
        );
        let run = |c: &EnvConfig, k| serde_json::to_string(&c.relevant_to(k)).unwrap();
        assert_eq!(
            run(&still, EnvKind::ARMBALLS),
            format!(r#"{legacy},"distractor_noise":0.0}}"#)
        );
        assert_eq!(run(&still, EnvKind::ARMBALL), format!("{legacy}}}"));
        // The follow-up's ArmBalls has its own arm: the shared one does not enter its hash.
        let arm = toml("[arm]\nlengths = [0.3, 0.2, 0.2, 0.1, 0.1, 0.05, 0.0]\nangle_shift = 0.5")
            .unwrap();
        assert_eq!(
            run(&arm, EnvKind::ARMBALLS_CORL),
            run(&d, EnvKind::ARMBALLS_CORL)
        );
        assert_ne!(run(&arm, EnvKind::ARMBALLS), run(&d, EnvKind::ARMBALLS));
        // One environment's own constant enters only its runs' hashes.
        let ball = toml("[armball]\nball_initial = [0.5, 0.6]").unwrap();
        assert_ne!(run(&ball, EnvKind::ARMBALL), run(&d, EnvKind::ARMBALL));
        for kind in [EnvKind::ARMARROW, EnvKind::ARMBALLS, EnvKind::ARMBALLS_CORL] {
            assert_eq!(run(&ball, kind), run(&d, kind), "{kind}");
        }
    }

    /// A table's key wins over `[env]`'s, which wins over the default; the written form tells
    /// apart configurations that run differently, and not those that run the same.
    #[test]
    fn a_table_overrides_env_which_overrides_the_default() {
        let c = toml("distractor_noise = 0.0\n[armballs-corl]\ndistractor_noise = 0.3").unwrap();
        assert_eq!(
            c.own::<crate::cdge::Constants>(EnvKind::ARMBALLS_CORL)
                .distractor_noise,
            0.3
        );
        assert_eq!(
            c.own::<crate::cdge::Constants>(EnvKind::ARMBALLS)
                .distractor_noise,
            0.0
        );
        let written = |c: &EnvConfig| serde_json::to_value(c).unwrap();
        assert_eq!(
            written(&c)["armballs-corl"],
            json!({"distractor_noise": 0.3})
        );
        let one = toml("[armballs]\ndistractor_noise = 0.0").unwrap();
        let every = toml("distractor_noise = 0.0").unwrap();
        assert_ne!(written(&one), written(&every));
        // Setting a key to what it already is changes nothing.
        let same = toml("[armball]\nball_initial = [0.6, 0.6]").unwrap();
        assert_eq!(written(&same), written(&EnvConfig::default()));
        // The same through `with`.
        let with = EnvConfig::default()
            .with("armballs.distractor_noise", 0.0)
            .unwrap();
        assert_eq!(written(&with), written(&one));
    }

    /// Each mistake is one line naming the key as it was written.
    #[test]
    fn mistakes_name_the_key() {
        let err = |text: &str| toml(text).unwrap_err();
        for (text, says) in [
            ("speed = 1", "unknown key env.speed"),
            (
                "[armball]\narrow_initial = [0, 0, 0]",
                "env.armball.arrow_initial is not a constant of ArmBall (its own: ball_initial",
            ),
            (
                "[armball]\nobject_size = 0.2",
                "shared: they go in [env] itself",
            ),
            (
                "ball_initial = [0.1, 0.2, 0.9]",
                "env.ball_initial must have 2 numbers, got 3",
            ),
            (
                "[armballs]\ndistractor_initial = [0.1]",
                "env.armballs.distractor_initial must have 2 numbers, got 1",
            ),
            (
                "[armballs]\ndistractor_noise = \"a\"",
                "env.armballs.distractor_noise: invalid type",
            ),
            (
                "armball = 3",
                "env.armball must be a table of ArmBall's own constants",
            ),
            (
                "[arm]\nlengths = [0.5, 0.5]\nangle_shift = 0.5",
                "env.arm.lengths must have 7 numbers, got 2",
            ),
        ] {
            let e = err(text);
            assert!(e.contains(says), "{text}: {e}");
        }
        assert!(
            EnvConfig::default()
                .with("nowhere.x", 1.0)
                .unwrap_err()
                .contains("unknown environment")
        );
        // A number that JSON cannot hold reaches the range check, which names it.
        let nan = toml("[armballs]\ndistractor_noise = nan")
            .unwrap()
            .validate()
            .unwrap_err();
        assert_eq!(nan.key, "env.armballs.distractor_noise");
        assert!(nan.message.ends_with("got NaN"), "{nan}");
    }
}
