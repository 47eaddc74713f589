//! `ugl verify`: a store's runs rerun from their profile give the same bytes, and a run whose
//! data differs from what the code computes is reported (even when its manifest's digests were
//! forged to match the forged data).

use std::path::Path;
use std::process::{Command, Output};

fn ugl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ugl"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

/// `ugl verify` of `out` with the profile `cfg`: (success, stdout and stderr).
fn verify(out: &str, cfg: &str, sample: &str) -> (bool, String) {
    let o = ugl(&[
        "verify",
        "--results",
        out,
        "--config",
        cfg,
        "--sample",
        sample,
    ]);
    (o.status.success(), text(&o))
}

fn write_file(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Replace `run`'s curve with `other`'s and forge its manifest's digest to match.
fn forge(out: &Path, run: &str, other: &str) {
    let bytes = std::fs::read(out.join(format!("{other}.parquet"))).unwrap();
    std::fs::write(out.join(format!("{run}.parquet")), &bytes).unwrap();
    let path = out.join(format!("{run}.json"));
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for f in m["files"].as_array_mut().unwrap() {
        if f["name"] == format!("{run}.parquet") {
            f["bytes"] = (bytes.len() as u64).into();
            f["blake3"] = blake3::hash(&bytes).to_hex().to_string().into();
        }
    }
    std::fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
}

#[test]
fn verify_reruns_a_stratified_sample_and_finds_a_forged_run() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write_file(
        dir.path(),
        "tiny.toml",
        "[campaign]\nname = \"tiny\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-efr\", \"rge-pca\", \"rge-vae\"]\nsamplers = [\"kde\"]\n\
         latents = [2, 3]\nvariants = [\"faithful\"]\n[ugl]\nimages = 300\n\
         [explore]\nepochs = 150\neval_every = 50\n\
         [learners.vae]\niterations = 10\nhidden = [16, 8]\n",
    );
    let out = dir.path().join("res");
    let (cfg, out_s) = (cfg.to_str().unwrap(), out.to_str().unwrap());
    let o = ugl(&[
        "campaign", "--config", cfg, "--out", out_s, "--quiet", "--jobs", "2",
    ]);
    assert!(o.status.success(), "{}", text(&o));

    // Six conditions (RGE-EFR, PCA-2, PCA-3, VAE-2, VAE-3, RPE); two evenly spaced ones are
    // RGE-EFR and PCA-3, so the second is replaced by the cheapest trained network.
    let (ok, t) = verify(out_s, cfg, "2");
    assert!(ok, "{t}");
    assert!(t.contains("12 runs match their recorded digests"), "{t}");
    let same: Vec<&str> = t.lines().filter(|l| l.starts_with("same bytes")).collect();
    assert_eq!(same.len(), 2, "{t}");
    assert!(same[0].contains("armball.rge-efr."), "{t}");
    assert!(same[1].contains("armball.rge-vae."), "{t}");
    // Without networks: the four network-free conditions, no VAE.
    let o = ugl(&[
        "verify",
        "--results",
        out_s,
        "--config",
        cfg,
        "--sample",
        "100",
        "--without-networks",
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let same: Vec<&str> = t.lines().filter(|l| l.starts_with("same bytes")).collect();
    assert_eq!(same.len(), 4, "{t}");
    assert!(!same.iter().any(|l| l.contains(".rge-vae.")), "{t}");

    // Every condition once; then one run's curve swapped for another's, digests forged.
    let (ok, t) = verify(out_s, cfg, "100");
    assert!(ok, "{t}");
    let reran: Vec<String> = t
        .lines()
        .filter_map(|l| l.strip_prefix("same bytes  "))
        .map(|l| l.split_whitespace().next().unwrap().to_string())
        .collect();
    assert_eq!(reran.len(), 6, "{t}");
    let victim = reran
        .iter()
        .find(|r| r.starts_with("armball.rge-pca.kde.l2"))
        .unwrap();
    let other = if victim.ends_with(".s0") {
        "armball.rge-pca.kde.l2.s1"
    } else {
        "armball.rge-pca.kde.l2.s0"
    };
    forge(&out, victim, other);
    let (ok, t) = verify(out_s, cfg, "100");
    assert!(!ok, "{t}");
    assert!(t.contains(&format!("DIFFERENT   {victim}")), "{t}");
    assert!(t.contains(&format!("{victim}.parquet: BLAKE3")), "{t}");
    assert!(t.contains("1 of 6 rerun runs differ"), "{t}");

    // A damaged file is caught before anything is rerun; a profile of another configuration
    // is refused.
    std::fs::write(out.join(format!("{victim}.parquet")), b"damaged").unwrap();
    let (ok, t) = verify(out_s, cfg, "4");
    assert!(!ok && t.contains("the committed files"), "{t}");
    let other_cfg = write_file(
        dir.path(),
        "other.toml",
        "[campaign]\nname = \"tiny\"\nreps = 3\n[matrix]\nenvs = [\"armball\"]\nalgos = [\"rpe\"]\n",
    );
    let (ok, t) = verify(out_s, other_cfg.to_str().unwrap(), "4");
    assert!(!ok && t.contains("configuration hash"), "{t}");
}

/// A store of `ugl compare` has no profile of its own: `ugl verify` rebuilds the campaign that
/// `ugl compare` ran from its record (the base campaign it varies, the learner of its name) and
/// reruns it to the same bytes.
#[test]
fn verify_reruns_a_compare_store_from_its_base_profile() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("compare-pca-centred");
    let out_s = out.to_str().unwrap();
    let o = ugl(&[
        "compare",
        "--learner",
        "pca-centred",
        "--config",
        "data/campaigns/smoke.toml",
        "--out",
        out_s,
        "--quiet",
        "--jobs",
        "2",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let o = ugl(&["verify", "--results", out_s, "--sample", "2"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert_eq!(
        t.lines().filter(|l| l.starts_with("same bytes")).count(),
        2,
        "{t}"
    );
    assert!(t.contains(".rge-pca-centred."), "{t}");
    // `ugl status` counts it from its record alone, as the compare campaign it was.
    let o = ugl(&["status", "--out", out_s, "--require-complete"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("campaign compare-pca-centred"), "{t}");
}
