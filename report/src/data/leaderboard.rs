//! `data/leaderboard.csv`: the leaderboard's entries with every number of both tables.

use crate::leaderboard::Leaderboard;

/// `data/leaderboard.csv`: one row per entry, in rank order, with every number of both tables.
pub fn write_csv(
    out: &mut crate::output::Output,
    lb: &Leaderboard,
) -> Result<(), crate::error::ReportError> {
    use crate::data::num;
    use std::fmt::Write as _;
    let task_cols: Vec<String> = lb
        .tasks
        .iter()
        .map(|(env, l)| format!("goal_iqm_{env}_{l}"))
        .collect();
    let mut s = format!(
        "rank,rank_lo,rank_hi,campaign,algo,sampler,variant,tasks,repetitions,untrained,\
         at_rpe_level,goal_task_mean,goal_task_mean_lo,goal_task_mean_hi,{},final_iqm,\
         final_iqm_lo,final_iqm_hi,auc_iqm,auc_iqm_lo,auc_iqm_hi,coverage_by_env,poi_vs_efr,\
         poi_lo,poi_hi,poi_wins,poi_pairs,poi_repetitions,paper\n",
        task_cols.join(",")
    );
    let n = lb.tasks.len();
    for (i, e) in lb.entries.iter().enumerate() {
        let per_task: Vec<String> = lb
            .tasks
            .iter()
            .map(|t| {
                num(e
                    .tasks
                    .iter()
                    .position(|x| x == t)
                    .and_then(|j| e.goal_task_iqm.get(j).copied().flatten()))
            })
            .collect();
        let triple = |t: Option<(f64, f64, f64)>| {
            format!(
                "{},{},{}",
                num(t.map(|x| x.0)),
                num(t.map(|x| x.1)),
                num(t.map(|x| x.2))
            )
        };
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            if e.is_complete(n) {
                (i + 1).to_string()
            } else {
                String::new()
            },
            e.rank_interval.map(|r| r.0.to_string()).unwrap_or_default(),
            e.rank_interval.map(|r| r.1.to_string()).unwrap_or_default(),
            e.campaign,
            e.algo,
            e.sampler,
            e.variant,
            e.tasks.len(),
            e.n_reps,
            e.untrained.map(|k| k.to_string()).unwrap_or_default(),
            e.at_rpe_level.map(|k| k.to_string()).unwrap_or_default(),
            triple(e.goal_task_mean),
            per_task.join(","),
            triple(Some(e.final_iqm)),
            triple(e.auc_iqm),
            e.coverage_by_env
                .iter()
                .map(|(env, c)| format!("{env}:{c}"))
                .collect::<Vec<_>>()
                .join(";"),
            triple(e.poi_vs_efr),
            e.poi_counts.map(|c| c.0.to_string()).unwrap_or_default(),
            e.poi_counts.map(|c| c.1.to_string()).unwrap_or_default(),
            e.poi_counts.map(|c| c.2.to_string()).unwrap_or_default(),
            num(e.paper),
        );
    }
    out.write(
        std::path::Path::new(crate::data::DIR).join(CSV_FILE),
        s.as_bytes(),
    )?;
    Ok(())
}

/// The leaderboard's data file, under the report's `data/`.
pub const CSV_FILE: &str = "leaderboard.csv";
