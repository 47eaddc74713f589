//! Reproducibility check (`make verify`): the `smoke` campaign (every algorithm, tiny budget)
//! must produce result files whose SHA-256 checksums equal `data/checksums/smoke.sha256`. A change
//! that alters results fails here and shows in review as a change of that file
//! (`make verify-update`, which runs this test with `UGL_VERIFY_UPDATE=1` to record them).

use std::path::Path;
use std::process::Command;

#[test]
fn smoke_campaign_matches_the_committed_checksums() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let expected = std::fs::read_to_string(root.join("data/checksums/smoke.sha256"))
        .expect("committed checksums");
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args([
            "campaign",
            "--config",
            "data/campaigns/smoke.toml",
            "--quiet",
            "--jobs",
            "2",
            "--out",
        ])
        .arg(dir.path())
        .current_dir(root)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut files: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".parquet"))
        .collect();
    files.sort();
    let sums = Command::new("sha256sum")
        .args(&files)
        .current_dir(dir.path())
        .output()
        .expect("sha256sum (coreutils) is installed");
    assert!(sums.status.success());
    let got = String::from_utf8(sums.stdout).unwrap();
    if std::env::var_os("UGL_VERIFY_UPDATE").is_some() {
        // `make verify-update`: record the new checksums instead of comparing.
        std::fs::write(root.join("data/checksums/smoke.sha256"), &got).unwrap();
        eprintln!("wrote data/checksums/smoke.sha256 ({} files)", files.len());
        return;
    }
    let (exp, got): (Vec<&str>, Vec<&str>) = (expected.lines().collect(), got.lines().collect());
    let differing: Vec<&&str> = got.iter().filter(|l| !exp.contains(l)).collect();
    assert_eq!(exp.len(), got.len(), "number of result files changed");
    assert!(
        differing.is_empty(),
        "results changed for {} files, e.g. {:?}; if intended, run `make verify-update` and commit",
        differing.len(),
        differing.first()
    );
}
