//! The typed error of a value out of range or contradictory, in a campaign file or on the
//! command line: the key (a configuration key such as `explore.epochs`, or a flag such as
//! `--latents`) as data, and the message for people, which names it too; and the checks of the
//! `[env]` table's values that build it.

use serde::Deserialize;

/// A value out of range or contradictory.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct InvalidValue {
    /// The configuration key or command-line flag at fault.
    pub key: String,
    /// What is wrong, in one line.
    pub message: String,
}

impl InvalidValue {
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        InvalidValue {
            key: key.into(),
            message: message.into(),
        }
    }
}

/// `key` must be a finite number in `[lo, hi]` (`(0, hi]` when `lo` is the smallest positive
/// number): the error names the key.
pub fn within(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), InvalidValue> {
    if v.is_finite() && v >= lo && v <= hi {
        return Ok(());
    }
    let lo = if lo == f64::MIN_POSITIVE {
        "(0".to_string()
    } else {
        format!("[{lo}")
    };
    Err(InvalidValue::new(
        key,
        format!(
            "{key} must be a finite number in {lo}, {hi}], got {}",
            num(v)
        ),
    ))
}

/// Every coordinate of the point `key` within `[lo, hi]`.
pub fn within_each(
    key: &dyn Fn(&str) -> String,
    name: &str,
    point: &[f64],
    lo: f64,
    hi: f64,
) -> Result<(), InvalidValue> {
    for (i, v) in point.iter().enumerate() {
        within(&key(&format!("{name}[{i}]")), *v, lo, hi)?;
    }
    Ok(())
}

/// A number as a person writes it: `1e300`, not three hundred digits.
fn num(v: f64) -> String {
    if v.is_finite() && v != 0.0 && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// Exactly `N` numbers: serde's fixed-size arrays read the first `N` elements of a longer
/// TOML array and silently drop the rest (`#[serde(deserialize_with = "exactly")]`). The message
/// continues the key the caller names (`must have 2 numbers, got 3`).
pub fn exactly<'de, D, const N: usize>(d: D) -> Result<[f64; N], D::Error>
where
    D: serde::Deserializer<'de>,
{
    exactly_as(d, "")
}

/// [`exactly`], the message naming the key `name` (`env.arm.lengths`).
pub fn exactly_as<'de, D, const N: usize>(d: D, name: &str) -> Result<[f64; N], D::Error>
where
    D: serde::Deserializer<'de>,
{
    let v = Vec::<f64>::deserialize(d)?;
    let n = v.len();
    let gap = if name.is_empty() { "" } else { " " };
    v.try_into()
        .map_err(|_| serde::de::Error::custom(format!("{name}{gap}must have {N} numbers, got {n}")))
}
