//! A new goal sampler is one file plus one registry entry: this file declares `box` (goals
//! uniform in the bounding box of the training latents), registers it, and runs it through the
//! command line (`ugl run`, `ugl campaign`, `ugl report`) in this process, as a program that
//! adds its own sampler would. Nothing outside this file knows it.

#[path = "common/in_process.rs"]
mod in_process;

use std::process::ExitCode;

use in_process::{manifest, ok, p, ugl};
use rand::RngExt;
use ugl_bench::goals::{GoalSampler, SamplerEntry, TrainingLatents, register};
use ugl_bench::repr::ReprError;
use ugl_bench::seed::Stream;
use ugl_types::SamplerInfo;

/// The description the report and the command line read.
static INFO: SamplerInfo = SamplerInfo {
    name: "box",
    display: "box",
    description: "uniform in the bounding box of the training latents (a test sampler)",
    draws_goals: true,
    learned: true,
    needs_prior: false,
    colour: [0x11, 0x77, 0x33],
    marker: 4,
};

/// Its registry entry.
static ENTRY: SamplerEntry = SamplerEntry {
    info: &INFO,
    learned: Some(box_goals),
};

/// The sampler: each latent uniform between its least and its greatest training value.
struct BoxGoals {
    lo: Vec<f64>,
    hi: Vec<f64>,
}

fn box_goals(space: &TrainingLatents<'_>) -> Result<Box<dyn GoalSampler>, ReprError> {
    let z = space.latents;
    if z.n == 0 {
        return Err(ReprError::InvalidInput("box: no training latents".into()));
    }
    let column = |k: usize| (0..z.n).map(move |i| z.data[i * z.latents + k]);
    Ok(Box::new(BoxGoals {
        lo: (0..z.latents)
            .map(|k| column(k).fold(f64::INFINITY, f64::min))
            .collect(),
        hi: (0..z.latents)
            .map(|k| column(k).fold(f64::NEG_INFINITY, f64::max))
            .collect(),
    }))
}

impl GoalSampler for BoxGoals {
    fn dim(&self) -> usize {
        self.lo.len()
    }
    fn sample(&mut self, rng: &mut Stream, out: &mut [f64]) {
        for (k, g) in out.iter_mut().enumerate() {
            *g = self.lo[k] + (self.hi[k] - self.lo[k]) * rng.random::<f64>();
        }
    }
    fn name(&self) -> &'static str {
        INFO.name
    }
}

#[test]
fn a_goal_sampler_added_in_one_file_runs_in_a_campaign_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let profile = dir.path().join("toy.toml");
    std::fs::write(
        &profile,
        "[campaign]\nname = \"toy\"\nrole = \"main\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
         algos = [\"rpe\", \"rge-efr\", \"rge-pca\"]\nsamplers = [\"kde\", \"box\"]\n\
         latents = [\"true\"]\n[ugl]\nimages = 200\n[explore]\nepochs = 150\neval_every = 50\n",
    )
    .unwrap();
    let single = dir.path().join("single");
    let run = |sampler: &str| {
        ugl(&[
            "run",
            "--env",
            "armball",
            "--algo",
            "rge-pca",
            "--sampler",
            sampler,
            "--latents",
            "2",
            "--seed",
            "1",
            "--profile",
            p(&profile),
            "--out",
            p(&single),
        ])
    };

    // Before registration neither the command line nor a campaign file knows it.
    assert_eq!(run("box"), ExitCode::from(2));
    assert_ne!(
        ugl(&["plan", "--config", p(&profile)]),
        ExitCode::SUCCESS,
        "an unknown sampler in a campaign file"
    );

    // An entry whose description contradicts its code is refused.
    static WRONG_INFO: SamplerInfo = SamplerInfo {
        name: "box-wrong",
        learned: false,
        ..INFO
    };
    static WRONG: SamplerEntry = SamplerEntry {
        info: &WRONG_INFO,
        learned: Some(box_goals),
    };
    let e = register(&WRONG).unwrap_err().to_string();
    assert!(e.contains("box-wrong"), "{e}");

    let kind = register(&ENTRY).unwrap();
    assert_eq!((kind.name(), kind.is_learned()), ("box", true));
    assert_eq!(SamplerInfo::by_name("box"), Some(&INFO));

    // `ugl run` with it and with the KDE: the same goal space, other goals.
    assert_eq!(run("box"), ExitCode::SUCCESS);
    assert_eq!(run("kde"), ExitCode::SUCCESS);
    let m = manifest(&single.join("armball.rge-pca.box.l2.s1.json"));
    assert_eq!((m.sampler.as_str(), m.latents), ("box", 2));
    assert!(m.summary.final_klc > 0.0);
    assert_ne!(
        std::fs::read(single.join("armball.rge-pca.box.l2.s1.outcomes.parquet")).unwrap(),
        std::fs::read(single.join("armball.rge-pca.kde.l2.s1.outcomes.parquet")).unwrap(),
        "the box sampler drew the KDE's goals"
    );

    // A campaign: the same bytes as `ugl run` for the same identity.
    let results = dir.path().join("results");
    ok(&[
        "campaign",
        "--config",
        p(&profile),
        "--out",
        p(&results.join("toy")),
        "--quiet",
    ]);
    for f in [
        "armball.rge-pca.box.l2.s1.parquet",
        "armball.rge-pca.box.l2.s1.outcomes.parquet",
    ] {
        assert_eq!(
            std::fs::read(results.join("toy").join(f)).unwrap(),
            std::fs::read(single.join(f)).unwrap(),
            "{f}"
        );
    }

    // The report names it and places its conditions after the built-in samplers'.
    let report = dir.path().join("report");
    ok(&[
        "report",
        "--results",
        p(&results),
        "--out",
        p(&report),
        "--main",
        "toy",
    ]);
    let md = std::fs::read_to_string(report.join("REPORT.md")).unwrap();
    let kde = md.find("| ArmBall | RGE-PCA † | kde | 2 |");
    let boxed = md.find("| ArmBall | RGE-PCA † | box | 2 |");
    assert!(
        kde.is_some() && boxed.is_some() && kde < boxed,
        "no kde row before a box row in:\n{md}"
    );
    let finals = std::fs::read_to_string(report.join("data/final_by_seed.csv")).unwrap();
    assert_eq!(
        finals.lines().filter(|l| l.contains(",box,")).count(),
        2,
        "{finals}"
    );
}
