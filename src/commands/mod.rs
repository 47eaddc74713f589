//! The subcommands' implementations, one file per family.

pub(crate) mod campaign;
pub(crate) mod compare;
pub(crate) mod environment;
pub(crate) mod record;
pub(crate) mod single;
pub(crate) mod verify;
