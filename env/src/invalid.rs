//! The typed error of a value out of range or contradictory, in a campaign file or on the
//! command line: the key (a configuration key such as `explore.epochs`, or a flag such as
//! `--latents`) as data, and the message for people, which names it too.

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
