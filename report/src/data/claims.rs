//! `data/claims.csv`: every comparison of every claim.

use std::path::Path;

use crate::claims::ClaimResult;
use crate::error::ReportError;

/// `data/claims.csv`: one row per comparison of every claim, on the claim's own statistic
/// (`evaluation` = `claim`) and on its twin's (`twin`), with the claim's and the twin's verdicts.
pub fn write_csv(
    out: &mut crate::output::Output,
    results: &[ClaimResult],
) -> Result<(), ReportError> {
    use crate::data::num;
    use std::fmt::Write as _;
    let mut s = String::from(
        "claim,ours,evaluation,evaluation_verdict,statistic,relation,margin,env,subject_algo,\
         subject_sampler,subject_latents,subject_variant,reference_algo,reference_sampler,\
         reference_latents,reference_variant,n_subject,n_reference,paired,subject_mean,\
         reference_mean,diff,lo,hi,uncorrected,verdict\n",
    );
    for r in results {
        let parts = std::iter::once(("claim", r.verdict, &r.comparisons))
            .chain(r.twin.as_ref().map(|t| ("twin", t.verdict, &t.comparisons)));
        for (evaluation, verdict, comparisons) in parts {
            for c in comparisons {
                let (lo, hi) = c.bounds().unzip();
                let _ = writeln!(
                    s,
                    "{},{},{evaluation},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    r.claim.id,
                    r.claim.ours,
                    verdict.label(),
                    c.statistic.key(),
                    c.relation.key(),
                    num(Some(c.margin)),
                    c.subject.env,
                    c.subject.tagged_algo(),
                    c.subject.sampler,
                    c.subject.latents,
                    c.subject.variant,
                    c.reference.tagged_algo(),
                    c.reference.sampler,
                    c.reference.latents,
                    c.reference.variant,
                    c.n_subject,
                    c.n_reference,
                    c.paired,
                    num(Some(c.subject_mean)),
                    num(Some(c.reference_mean)),
                    num(Some(c.diff)),
                    num(lo),
                    num(hi),
                    c.uncorrected.label(),
                    c.verdict.label(),
                );
            }
        }
    }
    out.write(Path::new(crate::data::DIR).join(CSV_FILE), s.as_bytes())?;
    Ok(())
}

/// The data file of the claims' comparisons, under the report's `data/`.
pub const CSV_FILE: &str = "claims.csv";
