//! Reading engineered outcomes from CSV (`ugl klc --outcomes FILE`): a header naming the
//! environment's measured coordinates (`x,y` for ArmBall, `x,y,angle` for ArmArrow: the
//! registry's `outcome_columns` of its controllable objects), then one outcome per line.

use std::path::{Path, PathBuf};

use thiserror::Error;

/// Errors reading an outcomes CSV; each names the file and, where relevant, the line.
#[derive(Debug, Error)]
pub enum CsvError {
    #[error("cannot read {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: header must be '{expected}', got '{got}'")]
    Header {
        path: PathBuf,
        expected: String,
        got: String,
    },
    #[error("{path}:{line}: expected {expected} comma-separated numbers, got '{text}'")]
    Fields {
        path: PathBuf,
        line: usize,
        expected: usize,
        text: String,
    },
    #[error("{path}:{line}: '{field}' is not a finite number")]
    Number {
        path: PathBuf,
        line: usize,
        field: String,
    },
    #[error("{path}: no outcomes after the header")]
    Empty { path: PathBuf },
}

/// Read outcomes from `path`, whose header must be `columns` in that order.
pub fn read_outcomes_csv(path: &Path, columns: &[&str]) -> Result<Vec<Vec<f64>>, CsvError> {
    let dim = columns.len();
    let text = std::fs::read_to_string(path).map_err(|source| CsvError::Io {
        path: path.into(),
        source,
    })?;
    let expected = columns.join(",");
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let header = lines.next().map(|(_, l)| l).unwrap_or("");
    let got: Vec<&str> = header
        .split(',')
        .map(|s| s.trim().trim_start_matches('\u{feff}'))
        .collect();
    if got.join(",") != expected {
        return Err(CsvError::Header {
            path: path.into(),
            expected,
            got: header.trim().into(),
        });
    }
    let mut out = Vec::new();
    for (i, l) in lines {
        let fields: Vec<&str> = l.split(',').map(str::trim).collect();
        if fields.len() != dim {
            return Err(CsvError::Fields {
                path: path.into(),
                line: i + 1,
                expected: dim,
                text: l.trim().into(),
            });
        }
        let row = fields
            .iter()
            .map(|f| match f.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(CsvError::Number {
                    path: path.into(),
                    line: i + 1,
                    field: (*f).into(),
                }),
            })
            .collect::<Result<Vec<f64>, _>>()?;
        out.push(row);
    }
    if out.is_empty() {
        return Err(CsvError::Empty { path: path.into() });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const XY: &[&str] = &["x", "y"];

    #[test]
    fn reads_and_rejects() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("o.csv");
        std::fs::write(&p, "x,y\n0.1,0.2\n\n-0.5, 0.25\n").unwrap();
        assert_eq!(
            read_outcomes_csv(&p, XY).unwrap(),
            vec![vec![0.1, 0.2], vec![-0.5, 0.25]]
        );
        assert!(matches!(
            read_outcomes_csv(&p, &["x", "y", "angle"]),
            Err(CsvError::Header { .. })
        ));
        std::fs::write(&p, "x,y\n0.1\n").unwrap();
        assert!(
            read_outcomes_csv(&p, XY)
                .unwrap_err()
                .to_string()
                .contains(":2:")
        );
        std::fs::write(&p, "x,y\n0.1,abc\n").unwrap();
        assert!(matches!(
            read_outcomes_csv(&p, XY),
            Err(CsvError::Number { .. })
        ));
        std::fs::write(&p, "x,y\n0.1,nan\n").unwrap();
        assert!(matches!(
            read_outcomes_csv(&p, XY),
            Err(CsvError::Number { .. })
        ));
        // Another environment's coordinates are its own header, not `x,y`.
        std::fs::write(&p, "a,b\n0.1,0.2\n").unwrap();
        assert_eq!(
            read_outcomes_csv(&p, &["a", "b"]).unwrap(),
            vec![vec![0.1, 0.2]]
        );
        assert!(matches!(
            read_outcomes_csv(&p, XY),
            Err(CsvError::Header { .. })
        ));
        std::fs::write(&p, "x,y\n").unwrap();
        assert!(matches!(
            read_outcomes_csv(&p, XY),
            Err(CsvError::Empty { .. })
        ));
    }
}
