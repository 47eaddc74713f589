//! `data/discovery_by_run.csv` and `data/validity.csv`: what each run discovered, and the
//! validity check of the measures ([`crate::discovery`]).

use std::fmt::Write as _;
use std::path::Path;

use super::num;
use crate::discovery::{Check, Group, PASS_LOWER_BOUND, RunRow};
use crate::error::ReportError;
use crate::output::Output;

/// The validity check's data file, under the report's `data/`.
pub const VALIDITY_FILE: &str = "validity.csv";

/// `data/validity.csv`: one row per line of the validity check.
pub fn write_validity_csv(out: &mut Output, checks: &[Check]) -> Result<(), ReportError> {
    let mut s = String::from(
        "env,measure,control,encodes_runs,control_runs,repetitions,encodes_median,control_median,\
         p_better,p_lo,p_hi,pass_lower_bound,passes\n",
    );
    for c in checks {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            c.env,
            c.measure.key(),
            c.control.label(),
            c.encodes.len(),
            c.controls.len(),
            c.repetitions,
            num(Some(c.encodes_median)),
            num(Some(c.control_median)),
            num(Some(c.p_better)),
            num(c.interval.map(|i| i.0)),
            num(c.interval.map(|i| i.1)),
            PASS_LOWER_BOUND,
            c.passes
        );
    }
    out.write(
        Path::new(crate::data::DIR).join(VALIDITY_FILE),
        s.as_bytes(),
    )?;
    Ok(())
}

/// The data file, under the report's `data/`.
pub const FILE: &str = "discovery_by_run.csv";

/// `data/discovery_by_run.csv`: one row per measured run.
pub fn write_csv(out: &mut Output, rows: &[RunRow<'_>]) -> Result<(), ReportError> {
    let mut s = String::from(
        "campaign,run_id,env,algo,sampler,latents,variant,seed,trained,position_knn_r2,group,\
         n_outcomes,n_moved,final_klc,moved_klc,coverage,goal_error_mean,goal_error_p90,\
         position_coverage,position_goal_error_mean,rest_cells_per_position_cell\n",
    );
    for r in rows {
        let run = r.run;
        let d = r.discovery.as_ref();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            if r.campaign.name.is_empty() {
                "."
            } else {
                &r.campaign.name
            },
            run.run_id,
            run.key.env,
            run.key.algo,
            run.key.sampler,
            run.key.latents,
            run.key.variant,
            run.seed,
            run.manifest
                .trained()
                .map(|t| t.to_string())
                .unwrap_or_default(),
            num(run.manifest.group_r2("position").map(|g| g.1)),
            r.group.map(Group::name).unwrap_or_default(),
            d.map(|d| d.n_outcomes.to_string()).unwrap_or_default(),
            d.map(|d| d.n_moved.to_string()).unwrap_or_default(),
            num(Some(run.final_point().klc)),
            num(d.and_then(|d| d.moved_klc)),
            num(d.map(|d| d.coverage)),
            num(d.map(|d| d.goal_error_mean)),
            num(d.map(|d| d.goal_error_p90)),
            num(r.position.as_ref().map(|p| p.coverage)),
            num(r.position.as_ref().map(|p| p.goal_error_mean)),
            num(r.rest_per_position_cell),
        );
    }
    out.write(Path::new(crate::data::DIR).join(FILE), s.as_bytes())?;
    Ok(())
}
