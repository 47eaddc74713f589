//! Which PyTorch default initialisation draws the follow-up's convolutional networks (the
//! `init` key of `[learners.conv-vae]` and `[learners.conv-bvae]`), declared once for the runner
//! that draws the weights and the report that names a recorded setting.

use serde::{Deserialize, Serialize};

/// Which PyTorch's default initialisation draws a convolutional network (`docs/neural.md`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ConvInit {
    /// The authors' PyTorch 0.4.0: a transposed convolution's fan-in is `in x k x k`.
    #[default]
    #[serde(rename = "torch-0.4")]
    Torch04,
    /// Today's PyTorch: a transposed convolution's fan-in is `out x k x k` (ours before the
    /// `init` key; the sweep's first networks).
    #[serde(rename = "torch")]
    Torch,
}

impl ConvInit {
    /// The initialisation of a configuration recorded before the `init` key existed.
    pub const BEFORE_THE_KEY: ConvInit = ConvInit::Torch;

    /// The key's value in configuration files and manifests.
    pub fn name(self) -> &'static str {
        match self {
            ConvInit::Torch04 => "torch-0.4",
            ConvInit::Torch => "torch",
        }
    }

    /// The initialisation a recorded training configuration's `init` value names: absent,
    /// [`ConvInit::BEFORE_THE_KEY`]; a value that names none is an error.
    pub fn of_record(value: Option<&serde_json::Value>) -> Result<ConvInit, serde_json::Error> {
        value.map_or(Ok(ConvInit::BEFORE_THE_KEY), ConvInit::deserialize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_serde_names_and_an_absent_key_is_todays() {
        for init in [ConvInit::Torch04, ConvInit::Torch] {
            assert_eq!(serde_json::to_value(init).unwrap(), init.name());
            let v = serde_json::json!(init.name());
            assert_eq!(ConvInit::of_record(Some(&v)).unwrap(), init);
        }
        assert_eq!(ConvInit::default().name(), "torch-0.4");
        assert_eq!(ConvInit::of_record(None).unwrap(), ConvInit::Torch);
        assert!(ConvInit::of_record(Some(&serde_json::json!("torch-2"))).is_err());
    }
}
