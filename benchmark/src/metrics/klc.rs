//! KL-coverage (paper Section 4.2; docs/original-code.md section 4). The one implementation is
//! [`ugl_types::klc`], shared with the discovery measures and the report; re-exported here for
//! the explorer and the command line.

pub use ugl_types::klc::{BINS, CoverageHistogram, KlCoverage, KlcError, bin_in_open_disk};
