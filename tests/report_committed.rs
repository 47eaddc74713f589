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

/// `ugl compare`'s page, computed without rendering the report, is the committed report's page.
#[test]
fn the_compare_page_without_a_render_is_the_reports() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut opts = ugl_report::ReportOptions::new(root.join("data/results"), Default::default());
    opts.paper_dir = root.join("data/paper");
    let mut pages = 0;
    for p in files(&root.join("report/out")) {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let Some(campaign) = name
            .strip_prefix("compare_")
            .and_then(|n| n.strip_suffix(".md"))
        else {
            continue;
        };
        let page = ugl_report::compare_page(&opts, campaign)
            .unwrap()
            .expect("a page");
        assert!(
            page.as_bytes() == std::fs::read(&p).unwrap(),
            "{name} differs from the page `ugl compare` prints"
        );
        pages += 1;
    }
    assert!(pages >= 2, "the committed report has {pages} compare pages");
    let err = ugl_report::compare_page(&opts, "paper").unwrap_err();
    assert!(err.to_string().contains("not a compare campaign"), "{err}");
}
