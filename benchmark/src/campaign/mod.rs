//! Campaigns: configuration, the run matrix, running and storing results.
