//! Exploration measures (paper Section 4.2; docs/original-code.md section 4).

pub mod csv;
pub mod klc;
pub mod moved;

pub use klc::{CoverageHistogram, KlCoverage};
pub use moved::moved;
