//! The paper's reference values (`data/paper/klc_final.csv`, documented in `data/paper/README.md`):
//! final KL-coverage read off the notebooks' plots at the point labelled 4900, ±0.03, single runs.
//!
//! The file is a plain comma-separated table without quoting, parsed here by hand so that every
//! malformed line is reported with its number.

use std::path::{Path, PathBuf};

use crate::error::ReportError;
use crate::load::ConditionKey;

pub const KLC_FILE: &str = "klc_final.csv";
const COLUMNS: [&str; 6] = ["env", "latents", "algo", "sampler", "klc", "source"];

/// One reference value.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperValue {
    pub env: String,
    /// `None`: any latent size (RPE and EFR, which appear in every panel).
    pub latents: Option<i64>,
    pub algo: String,
    pub sampler: String,
    pub klc: f64,
    /// The notebook figure it was read from.
    pub source: String,
}

/// All reference values, or none if the file is absent.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PaperTable {
    pub values: Vec<PaperValue>,
    /// Where they were read from; `None` when the file was not found.
    pub path: Option<PathBuf>,
    /// The path looked at, for the report's note when the file is missing.
    pub looked_at: PathBuf,
}

impl PaperTable {
    /// The paper's value for a condition: same env, algo and sampler, and the same latent size
    /// (or a row valid for any). The `faithful` variant is the paper's; the `corrected` one, whose
    /// implementation defects we fixed, the paper never ran, and it has no value.
    pub fn lookup(&self, key: &ConditionKey) -> Option<&PaperValue> {
        if key.variant == ugl_types::Variant::CORRECTED {
            return None;
        }
        self.values.iter().find(|v| {
            v.env == key.env
                && v.algo == key.algo
                && v.sampler == key.sampler
                && v.latents.is_none_or(|l| l == key.latents)
        })
    }
}

/// Reads `dir/klc_final.csv`. A missing file gives an empty table (the report says so); a
/// malformed one is an error naming the line.
pub fn load_paper(dir: &Path) -> Result<PaperTable, ReportError> {
    let path = dir.join(KLC_FILE);
    if !path.is_file() {
        tracing::warn!(path = %path.display(), "paper reference values not found");
        return Ok(PaperTable {
            values: Vec::new(),
            path: None,
            looked_at: path,
        });
    }
    let text = std::fs::read_to_string(&path).map_err(|source| ReportError::Io {
        path: path.clone(),
        source,
    })?;
    let values = parse_klc_csv(&text, &path)?;
    Ok(PaperTable {
        values,
        path: Some(path.clone()),
        looked_at: path,
    })
}

/// Parses the CSV text (`path` is only used in error messages).
pub fn parse_klc_csv(text: &str, path: &Path) -> Result<Vec<PaperValue>, ReportError> {
    let err = |line: usize, problem: String| ReportError::Paper {
        path: path.to_path_buf(),
        line,
        problem,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        return Err(err(1, "empty file".into()));
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let idx = |name: &str| {
        names.iter().position(|n| *n == name).ok_or_else(|| {
            err(
                hline,
                format!("header has no column `{name}` (expected {COLUMNS:?})"),
            )
        })
    };
    let [ienv, ilat, ialgo, isamp, iklc, isrc] = [
        idx("env")?,
        idx("latents")?,
        idx("algo")?,
        idx("sampler")?,
        idx("klc")?,
        idx("source")?,
    ];
    let mut out = Vec::new();
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != names.len() {
            return Err(err(
                n,
                format!("{} fields, the header has {}", f.len(), names.len()),
            ));
        }
        let latents = match f[ilat] {
            "" | "any" => None,
            s => Some(s.parse::<i64>().map_err(|_| {
                err(
                    n,
                    format!("latents `{s}` is not an integer, empty or `any`"),
                )
            })?),
        };
        let klc = f[iklc]
            .parse::<f64>()
            .map_err(|_| err(n, format!("klc `{}` is not a number", f[iklc])))?;
        for (i, what) in [(ienv, "env"), (ialgo, "algo"), (isamp, "sampler")] {
            if f[i].is_empty() {
                return Err(err(n, format!("empty {what}")));
            }
        }
        out.push(PaperValue {
            env: f[ienv].to_string(),
            latents,
            algo: f[ialgo].to_string(),
            sampler: f[isamp].to_string(),
            klc,
            source: f[isrc].to_string(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(env: &str, algo: &str, sampler: &str, latents: i64) -> ConditionKey {
        ConditionKey {
            env: env.into(),
            algo: algo.into(),
            sampler: sampler.into(),
            latents,
            variant: "none".into(),
            tag: None,
        }
    }

    #[test]
    fn committed_table_parses_and_matches() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper");
        let t = load_paper(&dir).unwrap();
        assert_eq!(t.values.len(), 25);
        let v = |k: &ConditionKey| t.lookup(k).map(|v| v.klc);
        assert_eq!(v(&key("armball", "rpe", "none", 0)), Some(6.51));
        assert_eq!(v(&key("armarrow", "rge-efr", "uniform", 0)), Some(7.46));
        assert_eq!(v(&key("armball", "rge-vae", "kde", 10)), Some(4.25));
        assert_eq!(v(&key("armball", "rge-vae", "gaussian", 10)), Some(3.84));
        assert_eq!(v(&key("armarrow", "rge-rfvae", "kde", 10)), Some(9.93));
        assert_eq!(v(&key("armball", "rge-pca", "kde", 3)), None);
    }

    #[test]
    fn malformed_lines_name_the_line() {
        let p = Path::new("x.csv");
        let e = parse_klc_csv(
            "env,latents,algo,sampler,klc,source\narmball,2,rpe,none,abc,s\n",
            p,
        )
        .unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
        let e = parse_klc_csv("env,algo\n", p).unwrap_err();
        assert!(e.to_string().contains("latents"), "{e}");
    }

    #[test]
    fn missing_dir_gives_empty_table() {
        let t = load_paper(Path::new("/nonexistent/paper")).unwrap();
        assert!(t.values.is_empty() && t.path.is_none());
    }
}
