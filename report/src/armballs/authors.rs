//! The follow-up's authors' exploration-ratio curves (`data/paper/followup_authors_curves.csv`)
//! and which of our conditions each of their algorithms is (`data/paper/followup_authors.toml`;
//! `data/paper/README.md` says where the numbers come from). The page draws their mean curves
//! beside ours; the claims compare our runs with their summary at their last point (Welch's
//! interval from their number of runs, mean and standard deviation).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::error::ReportError;
use crate::stats::SampleSummary;
use ugl_types::Algo;

/// The curves' file, in the paper directory.
pub const CURVES_FILE: &str = "followup_authors_curves.csv";
/// The correspondence's file, in the paper directory.
pub const MAP_FILE: &str = "followup_authors.toml";
/// The tag of the authors' conditions among ours (`mge-efr-lp@authors`).
pub const TAG: &str = "authors";

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    env: String,
    last_rollouts: i64,
    algorithms: BTreeMap<String, String>,
}

/// One algorithm of theirs: its name in their figure, our algorithm, and per point (rollouts,
/// bootstrap counted) the summary of their runs' exploration ratios.
#[derive(Debug, Clone, PartialEq)]
pub struct AuthorsCurve {
    pub name: String,
    pub algo: Algo,
    pub points: Vec<(i64, SampleSummary)>,
}

impl AuthorsCurve {
    /// Their summary at `rollouts` (None where they have no point).
    pub fn at(&self, rollouts: i64) -> Option<SampleSummary> {
        self.points
            .iter()
            .find(|(r, _)| *r == rollouts)
            .map(|(_, s)| *s)
    }
}

/// The authors' curves of one environment.
#[derive(Debug, Clone, PartialEq)]
pub struct Authors {
    /// The environment their runs are ours of (`armballs-corl`).
    pub env: String,
    /// Their last point (rollouts, bootstrap counted).
    pub last_rollouts: i64,
    pub curves: Vec<AuthorsCurve>,
}

impl Authors {
    /// Their curve of our algorithm `algo`.
    pub fn of(&self, algo: &Algo) -> Option<&AuthorsCurve> {
        self.curves.iter().find(|c| &c.algo == algo)
    }
}

fn invalid(path: &Path, problem: String) -> ReportError {
    ReportError::Invalid {
        path: path.to_path_buf(),
        problem,
    }
}

fn read(path: &Path) -> Result<String, ReportError> {
    std::fs::read_to_string(path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads the two files from `paper_dir`; None when either is missing (the page then shows no
/// curve of theirs and the claims against them have no reference: said where shown).
pub fn load(paper_dir: &Path) -> Result<Option<Authors>, ReportError> {
    let (map_path, curves_path): (PathBuf, PathBuf) =
        (paper_dir.join(MAP_FILE), paper_dir.join(CURVES_FILE));
    if !map_path.is_file() || !curves_path.is_file() {
        return Ok(None);
    }
    let map: MapFile =
        toml::from_str(&read(&map_path)?).map_err(|e| invalid(&map_path, e.to_string()))?;
    let mut curves = parse_curves(&read(&curves_path)?, &curves_path, &map.algorithms)?;
    for name in map.algorithms.keys() {
        if !curves.iter().any(|c| &c.name == name) {
            return Err(invalid(
                &map_path,
                format!("algorithm `{name}` has no curve in {CURVES_FILE}"),
            ));
        }
    }
    for c in &mut curves {
        c.points.sort_by_key(|p| p.0);
        if c.at(map.last_rollouts).is_none() {
            return Err(invalid(
                &curves_path,
                format!(
                    "`{}` has no point at last_rollouts = {}",
                    c.name, map.last_rollouts
                ),
            ));
        }
    }
    Ok(Some(Authors {
        env: map.env,
        last_rollouts: map.last_rollouts,
        curves,
    }))
}

/// Parses the curves' CSV (`algorithm,epoch,count,mean,std`), keeping the algorithms of `map`.
fn parse_curves(
    text: &str,
    path: &Path,
    map: &BTreeMap<String, String>,
) -> Result<Vec<AuthorsCurve>, ReportError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let header: Vec<&str> = lines
        .next()
        .map(|(_, l)| l.split(',').map(str::trim).collect())
        .unwrap_or_default();
    let want = ["algorithm", "epoch", "count", "mean", "std"];
    if header != want {
        return Err(invalid(
            path,
            format!("header {header:?}, expected {want:?}"),
        ));
    }
    let mut curves: Vec<AuthorsCurve> = Vec::new();
    for (i, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        let bad = |what: &str| invalid(path, format!("line {}: {what}: `{line}`", i + 1));
        if f.len() != want.len() {
            return Err(bad("5 fields expected"));
        }
        let Some(ours) = map.get(f[0]) else {
            continue;
        };
        let epoch: f64 = f[1].parse().map_err(|_| bad("epoch is not a number"))?;
        let n: usize = f[2].parse().map_err(|_| bad("count is not an integer"))?;
        let mean: f64 = f[3].parse().map_err(|_| bad("mean is not a number"))?;
        let sd: f64 = f[4].parse().map_err(|_| bad("std is not a number"))?;
        if !(epoch.fract() == 0.0 && mean.is_finite() && sd.is_finite() && sd >= 0.0) {
            return Err(bad("epoch, mean or std out of range"));
        }
        let point = (epoch as i64, SampleSummary { n, mean, sd });
        match curves.iter_mut().find(|c| c.name == f[0]) {
            Some(c) => c.points.push(point),
            None => curves.push(AuthorsCurve {
                name: f[0].to_string(),
                algo: Algo::from(ours.as_str()),
                points: vec![point],
            }),
        }
    }
    Ok(curves)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed files load: seven algorithms, each with its last point; their RPE is the
    /// value the environment test checks against (0.163 from 40 runs).
    #[test]
    fn the_committed_files_load() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper");
        let a = load(&dir).unwrap().expect("both files are committed");
        assert_eq!(a.curves.len(), 7);
        assert_eq!(a.last_rollouts, 9666);
        let rpe = a.of(&Algo::from("rpe")).unwrap().at(9666).unwrap();
        assert_eq!(rpe.n, 40);
        assert!((rpe.mean - 0.163).abs() < 5e-4, "{rpe:?}");
        assert!(a.curves.iter().all(|c| c.points.len() == 30));
    }

    #[test]
    fn malformed_curves_are_errors_naming_the_line() {
        let map: BTreeMap<String, String> = [("RPE".to_string(), "rpe".to_string())].into();
        let p = Path::new("x.csv");
        let e = parse_curves(
            "algorithm,epoch,count,mean,std\nRPE,333,x,0.1,0.01\n",
            p,
            &map,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("line 2") && e.contains("count"), "{e}");
        assert!(parse_curves("a,b\n", p, &map).is_err());
        // Algorithms outside the map are skipped.
        let c = parse_curves(
            "algorithm,epoch,count,mean,std\nRPE,0,3,0,0\nOTHER,0,3,0,0\n",
            p,
            &map,
        )
        .unwrap();
        assert_eq!(c.len(), 1);
    }
}
