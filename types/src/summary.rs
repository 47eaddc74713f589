//! The final numbers of a run: what `ugl run` prints last and its manifest records.

use serde::{Deserialize, Serialize};

/// The final numbers of a run, also printed by `ugl run` as its last line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub run: String,
    /// Final KL-coverage; JSON has no infinity, so +inf is written as the string "inf".
    #[serde(with = "crate::summary::inf_as_string")]
    pub final_klc: f64,
    pub n_moved: usize,
    pub coverage: f64,
}

/// +inf as the string "inf" in JSON (which has no infinity); other numbers as numbers.
pub(crate) mod inf_as_string {
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_infinite() && *v > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_f64(*v)
        }
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum V {
            N(f64),
            S(String),
        }
        match V::deserialize(d)? {
            V::N(x) => Ok(x),
            V::S(s) if s == "inf" => Ok(f64::INFINITY),
            V::S(s) => Err(serde::de::Error::custom(format!(
                "expected a number or \"inf\", got {s:?}"
            ))),
        }
    }
}

/// An optional f64 that may be +inf, written as `inf_as_string` writes it; None is `null`.
pub(crate) mod opt_inf_as_string {
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(x) => super::inf_as_string::serialize(x, s),
            None => s.serialize_none(),
        }
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        #[derive(Deserialize)]
        struct W(#[serde(with = "super::inf_as_string")] f64);
        Ok(Option::<W>::deserialize(d)?.map(|W(x)| x))
    }
}
