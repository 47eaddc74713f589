//! The committed report is exactly what `make report` renders from the committed results.

use std::path::Path;
use std::process::Command;

fn files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            v.extend(files(&p));
        } else {
            v.push(p);
        }
    }
    v.sort();
    v
}

#[test]
fn committed_report_regenerates_byte_identically() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let committed = root.join("report/out");
    let tmp = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args(["report", "--results", "data/results", "--out"])
        .arg(tmp.path())
        .current_dir(root)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ours: Vec<_> = files(tmp.path())
        .iter()
        .map(|p| p.strip_prefix(tmp.path()).unwrap().to_path_buf())
        .collect();
    let theirs: Vec<_> = files(&committed)
        .iter()
        .map(|p| p.strip_prefix(&committed).unwrap().to_path_buf())
        .collect();
    assert_eq!(
        ours, theirs,
        "the set of report files differs: run `make report` and commit report/out"
    );
    for rel in ours {
        assert!(
            std::fs::read(tmp.path().join(&rel)).unwrap()
                == std::fs::read(committed.join(&rel)).unwrap(),
            "{} differs from a fresh render: run `make report` and commit report/out",
            rel.display()
        );
    }
}
