//! The table of a convolutional-network sweep (`scripts/conv_sweep.sh OUT SETTING...`, which
//! trains each setting with `ugl run` into `OUT/<setting>/`): one row per trained network, read
//! from its run's manifest. It is how the follow-up's β-VAE settings were chosen (issue 44,
//! `docs/neural.md`, "The sweep"), and the table there is this function's output on the
//! committed sweep (`data/sweeps/conv`), checked by a test.
//!
//! The columns use the ArmBalls page's rules ([`ACTIVE_NATS`], [`active_roles`], [`CodeKind`]),
//! so that a network is called disentangled by one definition wherever it is shown.

use std::fmt::Write as _;
use std::path::Path;

use ugl_types::{ConvInit, Manifest};

use super::labels::f2;
use super::runs::{ACTIVE_NATS, CodeKind, LatentRole, active_roles, count_role};
use crate::error::ReportError;

/// The header of [`table`]: what each column holds.
const HEADER: &str = "| setting | seed | trained | loss fraction | KL total | per-latent KL, sorted | \
                      active | ball | distractor | both | code | ball k-NN R² | distractor k-NN R² | \
                      ball linear R² | distractor linear R² | MIG | SAP |";

/// A network's setting in words, from the training configuration its manifest records: the
/// learner's display name (the registry's), then β where it is not 1 (and the later β it moves
/// to, with its iterations, where the configuration sets one), the capacity C and how it
/// is ramped, the KL delay (and its weight), the warm-up and a blurred reconstruction target
/// where there are; then the learning
/// rate, the batch, the iterations, and whether subnormals were flushed.
fn setting(m: &Manifest) -> String {
    let learner = m.learner.as_deref().map(|name| {
        ugl_types::LEARNERS
            .iter()
            .find(|l| l.name == name)
            .map_or(name, |l| l.display)
    });
    let mut parts = vec![learner.unwrap_or(&m.algo).to_string()];
    let Some(train) = &m.train else {
        return parts.join(", ");
    };
    let num = |k: &str| train.config_field(k).and_then(|v| v.as_f64());
    let int = |k: &str| train.config_field(k).and_then(|v| v.as_u64());
    if let Some(b) = num("beta").filter(|b| *b != 1.0) {
        parts.push(format!("β {b}"));
    }
    if let (Some(last), Some(from)) = (num("beta_final"), int("beta_from")) {
        parts.push(match int("beta_until").filter(|u| *u > from) {
            Some(until) => format!("then β {last} reached from {from} to {until}"),
            None => format!("then β {last} from {from}"),
        });
    }
    if let Some(w) = num("tc") {
        parts.push(format!("TC weight {w}"));
    }
    if let Some(c) = num("capacity") {
        parts.push(match int("capacity_iterations") {
            // |KL − 0| is the KL: the plain β-VAE objective.
            _ if c == 0.0 => "C 0 (the plain β-VAE)".to_string(),
            Some(1) => format!("C {c} from the start"),
            Some(t) => format!("C {c} reached at {t}"),
            None => format!("C {c} reached at the end"),
        });
    }
    if let Some(d) = int("kl_delay").filter(|d| *d > 0) {
        parts.push(match num("delay_factor") {
            Some(f) => {
                let weight = (f * num("beta").unwrap_or(1.0) * 1e6).round() / 1e6;
                format!("KL delayed {d} at weight {weight}")
            }
            None => format!("KL delayed {d}"),
        });
    }
    if let Some(w) = int("warmup").filter(|w| *w > 0) {
        parts.push(format!("warm-up {w}"));
    }
    if let (Some(s), Some(until)) = (num("blur"), int("blur_until")) {
        parts.push(format!("target blurred σ {s} px to 0 at {until}"));
    }
    if let Some(lr) = num("lr") {
        parts.push(format!("lr {lr}"));
    }
    if let Some(batch) = int("batch") {
        parts.push(format!("batch {batch}"));
    }
    parts.push(format!(
        "{} it",
        train
            .iterations
            .or(int("iterations").map(|i| i as usize))
            .map_or("?".into(), |i| i.to_string())
    ));
    if train
        .config_field("flush_subnormals")
        .and_then(|v| v.as_bool())
        != Some(true)
    {
        parts.push("subnormals kept".into());
    }
    // Recorded before the key existed: today's PyTorch initialisation.
    match ConvInit::of_record(train.config_field("init")) {
        Ok(ConvInit::Torch04) => {}
        Ok(ConvInit::Torch) => parts.push("init of today's PyTorch".into()),
        Err(_) => parts.push("an init this build does not know".into()),
    }
    parts.join(", ")
}

/// One row of [`table`], as its setting ([`setting`]) and the cells after it (from the seed on).
fn row(m: &Manifest) -> (String, String) {
    let evidence = m.training_evidence();
    let q = m.latent_quality.as_ref();
    let kl: Vec<f64> = q.map(|q| q.kl_per_latent.clone()).unwrap_or_default();
    let r2 = |object: &str| -> Vec<f64> {
        q.and_then(|q| q.object(object))
            .map(|o| o.r2.iter().map(|v| v.unwrap_or(0.0)).collect())
            .unwrap_or_default()
    };
    let (ball, distractor) = (r2("ball"), r2("distractor"));
    let roles = active_roles(&kl, &ball, &distractor);
    let active = kl.iter().filter(|k| **k > ACTIVE_NATS).count();
    let count = |kind| count_role(&roles, kind);
    let mut sorted = kl.clone();
    sorted.sort_by(|a, b| b.total_cmp(a));
    let knn_r2 = |group: &str| q.and_then(|q| q.group(group)).map(|g| g.knn_r2);
    let knn = |group: &str| knn_r2(group).map_or("n/a".into(), f2);
    // The linear R² beside the k-NN one: a code that holds an object's position folded (each
    // latent non-monotone in it) has the second near 1 and the first well below.
    let linear = |group: &str| {
        q.and_then(|q| q.group(group))
            .map_or("n/a".into(), |g| f2(g.linear_r2))
    };
    let dis = q.and_then(|q| q.disentanglement.as_ref());
    let cells = format!(
        "{} | {} | {} | {} | {} | {active} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
        m.seed,
        match evidence.map(|e| e.trained) {
            Some(true) => "yes",
            Some(false) => "no",
            None => "n/a",
        },
        evidence.map_or("n/a".into(), |e| format!("{:.3}", e.loss_fraction)),
        if kl.is_empty() {
            "n/a".into()
        } else {
            format!("{:.1}", kl.iter().sum::<f64>())
        },
        sorted
            .iter()
            .map(|k| format!("{k:.2}"))
            .collect::<Vec<_>>()
            .join(" "),
        count(LatentRole::Ball),
        count(LatentRole::Distractor),
        count(LatentRole::Both),
        if q.is_some() {
            CodeKind::from_measures(
                &kl,
                &ball,
                &distractor,
                knn_r2("position"),
                knn_r2("distractor"),
            )
            .label()
        } else {
            "n/a"
        },
        knn("position"),
        knn("distractor"),
        linear("position"),
        linear("distractor"),
        dis.map_or("n/a".into(), |d| format!("{:.3}", d.mig)),
        dis.map_or("n/a".into(), |d| format!("{:.3}", d.sap)),
    );
    (setting(m), cells)
}

/// The markdown table of the sweep under `dir`: one row per run manifest in each setting's
/// sub-directory (the model cache, `models/`, is skipped), settings in directory order and runs
/// in file order; a row whose setting is the row above's leaves its setting cell empty, so that
/// each setting is written once above its seeds. Each manifest is read as the report reads a
/// run's (its data files checked against their recorded hashes). An error if `dir` holds no run.
pub fn table(dir: &Path) -> Result<String, ReportError> {
    let mut settings = crate::load::sorted_entries(dir)?;
    settings.retain(|p| p.is_dir() && p.file_name().is_some_and(|n| n != "models"));
    let mut out = format!(
        "{HEADER}\n|{}\n",
        "---|".repeat(HEADER.matches(" | ").count() + 1)
    );
    let mut rows = 0;
    let mut above = None;
    for s in settings {
        let manifests = crate::load::sorted_entries(&s)?;
        for path in manifests
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
        {
            let (setting, cells) = row(&crate::load::read_manifest(path)?);
            let shown = if above.as_ref() == Some(&setting) {
                ""
            } else {
                &setting
            };
            let _ = writeln!(out, "| {shown} | {cells}");
            above = Some(setting);
            rows += 1;
        }
    }
    if rows == 0 {
        return Err(ReportError::Invalid {
            path: dir.to_path_buf(),
            problem: "holds no sweep run (expected SETTING/<run>.json manifests, as \
                      scripts/conv_sweep.sh writes them)"
                .into(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A directory without runs (only a model cache) is an error that says what was expected,
    /// not an empty table.
    #[test]
    fn a_sweep_without_runs_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("models")).unwrap();
        std::fs::create_dir(dir.path().join("beta-4")).unwrap();
        let e = table(dir.path()).unwrap_err().to_string();
        assert!(e.contains("holds no sweep run"), "{e}");
    }

    /// A setting trained on three seeds is written once, above its three rows, and the next
    /// setting again: the table copies two committed settings and counts.
    #[test]
    fn each_setting_is_written_once_above_its_seeds() {
        let sweep = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/sweeps/conv");
        let dir = tempfile::tempdir().unwrap();
        let three = "beta-10_capacity-12_capacity_iterations-5000_iterations-20000_init-torch";
        let one = "beta-16_capacity-0_kl_delay-2000_delay_factor-0.0625_warmup-0_iterations-\
                   6000_init-torch";
        for name in [three, one] {
            let to = dir.path().join(name);
            std::fs::create_dir(&to).unwrap();
            for f in std::fs::read_dir(Path::new(sweep).join(name)).unwrap() {
                let f = f.unwrap().path();
                std::fs::copy(&f, to.join(f.file_name().unwrap())).unwrap();
            }
        }
        let out = table(dir.path()).unwrap();
        let rows: Vec<&str> = out.lines().skip(2).collect();
        assert_eq!(rows.len(), 4, "{out}");
        let first_cell = |r: &str| {
            r.split(" | ")
                .next()
                .unwrap()
                .trim_start_matches("| ")
                .to_string()
        };
        assert!(
            first_cell(rows[0]).starts_with("conv β-VAE, β 10, C 12"),
            "{out}"
        );
        assert!(
            rows[1].starts_with("|  | 1001 |") && rows[2].starts_with("|  | 1002 |"),
            "{out}"
        );
        assert!(first_cell(rows[3]).starts_with("conv β-VAE, β 16"), "{out}");
    }

    /// The code column is the follow-up page's rule ([`CodeKind`]): the chosen β-VAE's five
    /// networks are disentangled, the blurred VAE entangled, the sharp β 30 on the plateau
    /// neither (its code holds neither object).
    #[test]
    fn the_code_column_is_the_pages_rule() {
        let sweep = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../data/sweeps/conv"));
        let dir = tempfile::tempdir().unwrap();
        for name in [
            "beta-30_capacity-12_capacity_iterations-5000_blur-16_blur_until-6000_iterations-\
             10000_init-torch",
            "beta-30_capacity-12_capacity_iterations-5000_iterations-8000_init-torch",
            "vae_blur-16_blur_until-6000_iterations-12000_init-torch",
        ] {
            let to = dir.path().join(name);
            std::fs::create_dir(&to).unwrap();
            for f in std::fs::read_dir(sweep.join(name)).unwrap() {
                let f = f.unwrap().path();
                std::fs::copy(&f, to.join(f.file_name().unwrap())).unwrap();
            }
        }
        let out = table(dir.path()).unwrap();
        let column = HEADER.split(" | ").position(|c| c == "code").unwrap();
        let codes: Vec<&str> = out
            .lines()
            .skip(2)
            .map(|r| r.split(" | ").nth(column).unwrap())
            .collect();
        assert_eq!(
            codes,
            [
                "disentangled",
                "disentangled",
                "disentangled",
                "disentangled",
                "disentangled",
                "not both objects",
                "entangled"
            ],
            "{out}"
        );
    }

    /// The setting names the KL delay, the phase's KL weight (its factor times β) where the
    /// configuration sets the factor, the learning rate and the batch.
    #[test]
    fn the_setting_names_the_delay_and_its_weight() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../data/sweeps/conv/beta-100_capacity-12_capacity_iterations-1_kl_delay-3000_\
             warmup-1000_iterations-8000/armballs-corl.rge-conv-bvae.kde.l10.s1000.json"
        );
        let mut m = crate::load::read_manifest(std::path::Path::new(path)).unwrap();
        assert!(
            setting(&m).contains(", KL delayed 3000, warm-up 1000, lr 0.001, batch 64, 8000 it"),
            "{}",
            setting(&m)
        );
        let train = m.train.as_mut().unwrap();
        train.config["delay_factor"] = serde_json::json!(0.0004);
        assert!(
            setting(&m).contains(", KL delayed 3000 at weight 0.04, warm-up"),
            "{}",
            setting(&m)
        );
        // Trained before the `init` key: today's PyTorch initialisation, said; the authors'
        // (the default since) is not.
        assert!(
            setting(&m).ends_with(", init of today's PyTorch"),
            "{}",
            setting(&m)
        );
        // The authors' is not said; a value no build of ours wrote is said, not read as ours.
        for (init, end) in [
            ("torch-2", ", an init this build does not know"),
            (ConvInit::Torch04.name(), ", 8000 it"),
        ] {
            m.train.as_mut().unwrap().config["init"] = serde_json::json!(init);
            assert!(setting(&m).ends_with(end), "{}", setting(&m));
        }
        // A later β is said after β, with its schedule.
        let config = &mut m.train.as_mut().unwrap().config;
        config["beta_final"] = serde_json::json!(400.0);
        config["beta_from"] = serde_json::json!(5000);
        assert!(
            setting(&m).contains(", β 100, then β 400 from 5000, C 12"),
            "{}",
            setting(&m)
        );
        m.train.as_mut().unwrap().config["beta_until"] = serde_json::json!(6000);
        assert!(
            setting(&m).contains(", β 100, then β 400 reached from 5000 to 6000, C 12"),
            "{}",
            setting(&m)
        );
        // A total-correlation weight is said before the capacity.
        m.train.as_mut().unwrap().config["tc"] = serde_json::json!(10.0);
        assert!(
            setting(&m).contains(" to 6000, TC weight 10, C 12"),
            "{}",
            setting(&m)
        );
        // A blurred target is said after the warm-up.
        m.train.as_mut().unwrap().config["blur"] = serde_json::json!(16.0);
        m.train.as_mut().unwrap().config["blur_until"] = serde_json::json!(6000);
        assert!(
            setting(&m).contains("target blurred σ 16 px to 0 at 6000, lr"),
            "{}",
            setting(&m)
        );
        let config = m.train.as_mut().unwrap().config.as_object_mut().unwrap();
        for key in [
            "beta_final",
            "beta_from",
            "beta_until",
            "tc",
            "blur",
            "blur_until",
        ] {
            config.remove(key);
        }
        // A capacity of 0 is the plain β-VAE objective, and says so.
        let train = m.train.as_mut().unwrap();
        train.config["capacity"] = serde_json::json!(0.0);
        assert!(
            setting(&m).contains(", β 100, C 0 (the plain β-VAE), KL delayed"),
            "{}",
            setting(&m)
        );
    }
}
