//! `data/latent_quality_vs_moves.csv`: does latent quality predict exploration, per environment
//! and measure ([`crate::predicts`]).

use std::fmt::Write as _;
use std::path::Path;

use super::num;
use crate::error::ReportError;
use crate::output::Output;
use crate::predicts::{Line, MEASURES};

/// The data file, under the report's `data/`.
pub const FILE: &str = "latent_quality_vs_moves.csv";

/// `data/latent_quality_vs_moves.csv`: one row per line of the table.
pub fn write_csv(out: &mut Output, lines: &[Line]) -> Result<(), ReportError> {
    let mut s = String::from(
        "env,measure,n,r,r_lo,r_hi,partial_r,partial_lo,partial_hi,r2_moves,\
         r2_moves_and_quality,r2_gain\n",
    );
    for l in lines {
        let a = l.stats.as_ref();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{}",
            l.env,
            MEASURES
                .iter()
                .find(|(m, _)| *m == l.measure)
                .map_or("", |(_, s)| s),
            a.map(|a| a.n).unwrap_or(0),
            num(a.and_then(|a| a.r)),
            num(a.and_then(|a| a.r_ci).map(|c| c.0)),
            num(a.and_then(|a| a.r_ci).map(|c| c.1)),
            num(a.and_then(|a| a.partial)),
            num(a.and_then(|a| a.partial_ci).map(|c| c.0)),
            num(a.and_then(|a| a.partial_ci).map(|c| c.1)),
            num(a.and_then(|a| a.r2_moves)),
            num(a.and_then(|a| a.r2_both)),
            num(a.and_then(|a| a.gain)),
        );
    }
    out.write(Path::new(crate::data::DIR).join(FILE), s.as_bytes())?;
    Ok(())
}
