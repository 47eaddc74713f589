//! Reproducibility check (`make verify`): the `smoke` campaign (every environment, algorithm,
//! learner, sampler and variant, tiny budget), compared byte for byte with the checksums in
//! `data/checksums/smoke.sha256`, on **every kernel path this CPU has** (`UGL_SIMD=scalar`,
//! `avx2`, `avx512`). One checksum file holds for every machine: the float kernels compute the
//! same bits on every path (README "Reproducibility"), so a difference is a change of results,
//! never of the machine.
//!
//! `make verify-update` (`UGL_VERIFY_UPDATE=1`) records the checksums instead of comparing.

use std::path::Path;
use std::process::Command;

use ugl_bench::kernels::{SIMD_VAR, SimdPath};

/// Run the smoke campaign on `path` and return `sha256sum`'s lines for its result files.
fn smoke_checksums(root: &Path, path: SimdPath) -> String {
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
        .env(SIMD_VAR, path.name())
        .current_dir(root)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{path}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let mut files: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".parquet"))
        .collect();
    files.sort();
    assert!(
        files.len() > 100,
        "{path}: only {} result files",
        files.len()
    );
    // Every manifest records the path it ran on.
    let manifest = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "json") && !p.ends_with("campaign.json"))
        .expect("a manifest");
    let text = std::fs::read_to_string(&manifest).unwrap();
    assert!(
        text.contains(&format!("\"kernels\": \"{}\"", path.name())),
        "{} does not record the kernel path {path}",
        manifest.display()
    );
    let sums = Command::new("sha256sum")
        .args(&files)
        .current_dir(dir.path())
        .output()
        .expect("sha256sum (coreutils) is installed");
    assert!(sums.status.success());
    String::from_utf8(sums.stdout).unwrap()
}

#[test]
fn smoke_campaign_matches_the_recorded_bytes_on_every_kernel_path() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sums_path = root.join("data/checksums/smoke.sha256");
    let best = SimdPath::best();
    let got = smoke_checksums(root, best);
    if std::env::var_os("UGL_VERIFY_UPDATE").is_some() {
        std::fs::write(&sums_path, &got).unwrap();
        eprintln!(
            "wrote {} ({} files, {best} path)",
            sums_path.display(),
            got.lines().count()
        );
        return;
    }
    let expected = std::fs::read_to_string(&sums_path).expect("committed smoke checksums");
    let mut paths = vec![best];
    paths.extend(
        SimdPath::available_paths()
            .into_iter()
            .filter(|&p| p != best),
    );
    for path in paths {
        let got = if path == best {
            got.clone()
        } else {
            smoke_checksums(root, path)
        };
        let exp: Vec<&str> = expected.lines().collect();
        let differing: Vec<&str> = got.lines().filter(|l| !exp.contains(l)).collect();
        assert_eq!(
            exp.len(),
            got.lines().count(),
            "{path} path: the number of result files changed"
        );
        assert!(
            differing.is_empty(),
            "{path} path: results changed for {} of {} files, e.g. {:?}; if intended, run \
             `make verify-update` and commit",
            differing.len(),
            exp.len(),
            differing.first()
        );
        eprintln!("{path} path: {} files identical to the record", exp.len());
    }
}
