//! A new environment is one file plus one registry entry: this file declares ArmReach (the
//! outcome is where the hand ends; no object) and its own constant (`[env.armreach] clip`),
//! registers it, and runs it through the command line (`ugl run`, `ugl campaign`, `ugl
//! report`) in this process, as a program that adds its own environment would. Nothing outside
//! this file knows it.

#[path = "common/in_process.rs"]
mod in_process;

use std::process::ExitCode;

use in_process::{manifest, ok, p, ugl};
use serde::{Deserialize, Serialize};
use ugl_bench::env::invalid::{InvalidValue, within};
use ugl_bench::env::render::render_ball_into;
use ugl_bench::env::{
    EnvConfig, EnvEntry, EnvKind, Environment, OwnConstants, OwnTable, PARAMS, Rollout, dmp,
    register,
};
use ugl_bench::seed::Stream;
use ugl_types::{DISK, EnvSpec, GRAY70, ObjectSpec};

/// The declaration the report and the command line read.
static SPEC: EnvSpec = EnvSpec {
    name: "armreach",
    display: "ArmReach",
    description: "where the hand ends (2-D outcome: x, y); a test environment",
    in_paper: false,
    objects: &[ObjectSpec {
        name: "hand",
        start: 0,
        end: 2,
        controllable: true,
    }],
    state_dim: 2,
    true_latents: 2,
    outcome_columns: &["x", "y"],
    klc: DISK,
    params: PARAMS,
    image: GRAY70,
};

/// Its own constant, `[env.armreach] clip`: the outcome is clipped to [-clip, clip]².
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct Constants {
    /// In (0, 1].
    clip: f64,
}

impl Default for Constants {
    fn default() -> Self {
        Constants { clip: 1.0 }
    }
}

impl OwnConstants for Constants {
    fn check(&self, key: &dyn Fn(&str) -> String) -> Result<(), InvalidValue> {
        within(&key("clip"), self.clip, f64::MIN_POSITIVE, 1.0)
    }
}

/// Its registry entry.
static ENTRY: EnvEntry = EnvEntry {
    spec: &SPEC,
    constants: OwnTable::of::<Constants>(),
    uses_arm: true,
    build: |cfg| Box::new(ArmReach::new(cfg)),
};

/// The dynamics: the arm's movement, the hand's last position.
struct ArmReach {
    cfg: EnvConfig,
    rest: [f64; 2],
    clip: f64,
}

impl ArmReach {
    fn new(cfg: &EnvConfig) -> Self {
        let rest = cfg.arm.forward(&[0.0; ugl_bench::env::JOINTS]).hand;
        ArmReach {
            cfg: cfg.clone(),
            rest,
            clip: cfg.own::<Constants>(EnvKind::of(&ENTRY)).clip,
        }
    }
}

impl Environment for ArmReach {
    fn kind(&self) -> EnvKind {
        EnvKind::of(&ENTRY)
    }

    fn initial_state(&self) -> &[f64] {
        &self.rest
    }

    fn rollout(&self, theta: &[f64], _noise: &mut Stream) -> Rollout {
        let theta: [f64; PARAMS] = std::array::from_fn(|k| theta[k].clamp(-1.0, 1.0));
        let path = dmp::trajectory(&self.cfg.dmp, &theta);
        let hand = path
            .last()
            .map_or(self.rest, |q| self.cfg.arm.forward(q).hand);
        Rollout {
            state: [
                hand[0].clamp(-self.clip, self.clip),
                hand[1].clamp(-self.clip, self.clip),
                0.0,
                0.0,
            ],
            dim: 2,
            caught: hand != self.rest,
            hand,
        }
    }

    fn render_into(&self, state: &[f64], out: &mut [f32]) {
        render_ball_into(state[0], state[1], out);
    }
}

#[test]
fn an_environment_added_in_one_file_runs_in_a_campaign_and_the_report() {
    // Before registration the command line does not know it.
    let dir = tempfile::tempdir().unwrap();
    let rollout_params = dir.path().join("params.json");
    std::fs::write(&rollout_params, format!("[{:?}]", [0.5; PARAMS])).unwrap();
    let rollout = [
        "rollout",
        "--env",
        "armreach",
        "--params",
        p(&rollout_params),
    ];
    assert_eq!(ugl(&rollout), ExitCode::from(2));

    let kind = register(&ENTRY).unwrap();
    assert_eq!(
        register(&ENTRY).unwrap(),
        kind,
        "registering twice is a no-op"
    );
    assert_eq!("armreach".parse::<EnvKind>().unwrap(), kind);
    assert!(EnvKind::all().last() == Some(&kind) && kind > EnvKind::ARMBALLS);
    ok(&rollout);

    // A declaration whose grid is not the measure's is refused, with the reason.
    static WRONG_GRID: EnvSpec = EnvSpec {
        name: "armreach-square",
        klc: ugl_types::KlcGrid {
            achievable_cells: 900,
            ..DISK
        },
        ..SPEC
    };
    static WRONG: EnvEntry = EnvEntry {
        spec: &WRONG_GRID,
        constants: OwnTable::NONE,
        uses_arm: true,
        build: |cfg| Box::new(ArmReach::new(cfg)),
    };
    let e = register(&WRONG).unwrap_err().to_string();
    assert!(e.contains("armreach-square") && e.contains("756"), "{e}");
    assert!("armreach-square".parse::<EnvKind>().is_err());

    // `ugl run`, in the engineered space and in a learned one.
    let profile = dir.path().join("reach.toml");
    std::fs::write(
        &profile,
        "[campaign]\nname = \"reach\"\nrole = \"main\"\nreps = 2\n[matrix]\nenvs = [\"armreach\"]\n\
         algos = [\"rpe\", \"rge-efr\", \"rge-pca\"]\nsamplers = [\"kde\"]\nlatents = [\"true\"]\n\
         [ugl]\nimages = 200\n[explore]\nepochs = 150\neval_every = 50\n",
    )
    .unwrap();
    let single = dir.path().join("single");
    for algo in ["rge-efr", "rge-pca"] {
        ok(&[
            "run",
            "--env",
            "armreach",
            "--algo",
            algo,
            "--latents",
            "2",
            "--seed",
            "1",
            "--profile",
            p(&profile),
            "--out",
            p(&single),
        ]);
    }
    let m = manifest(&single.join("armreach.rge-pca.kde.l2.s1.json"));
    assert_eq!((m.env.as_str(), m.latents), ("armreach", 2));
    assert!(m.summary.final_klc > 0.0 && m.summary.final_klc <= DISK.max_klc());

    // Its own constant, set in its table: the outcomes obey it, and its range is checked.
    let clipped = dir.path().join("clipped.toml");
    let with_clip = |clip: &str| {
        std::fs::read_to_string(&profile).unwrap() + &format!("[env.armreach]\nclip = {clip}\n")
    };
    std::fs::write(&clipped, with_clip("0.25")).unwrap();
    let clip_out = dir.path().join("clip");
    let clip_run = [
        "run",
        "--env",
        "armreach",
        "--algo",
        "rpe",
        "--profile",
        p(&clipped),
        "--out",
        p(&clip_out),
    ];
    ok(&clip_run);
    let run = ugl_report::load::load_run(&clip_out.join("armreach.rpe.s0"), String::new()).unwrap();
    let coords = || run.outcomes.iter().flat_map(|o| [o.x, o.y]);
    assert!(coords().all(|v| v.abs() <= 0.25), "clip = 0.25 not obeyed");
    assert!(
        coords().any(|v| v.abs() == 0.25),
        "no outcome reaches the clip"
    );
    std::fs::write(&clipped, with_clip("2.0")).unwrap();
    assert_eq!(
        ugl(&clip_run),
        ExitCode::from(2),
        "env.armreach.clip = 2 must be refused"
    );

    // A campaign: the same bytes as `ugl run` for the same identity.
    let results = dir.path().join("results");
    ok(&[
        "campaign",
        "--config",
        p(&profile),
        "--out",
        p(&results.join("reach")),
        "--quiet",
    ]);
    for f in [
        "armreach.rge-efr.s1.parquet",
        "armreach.rge-pca.kde.l2.s1.parquet",
        "armreach.rge-pca.kde.l2.s1.outcomes.parquet",
    ] {
        assert_eq!(
            std::fs::read(results.join("reach").join(f)).unwrap(),
            std::fs::read(single.join(f)).unwrap(),
            "{f}"
        );
    }

    // The report names it from its declaration and bounds its KL-coverage by its grid.
    let report = dir.path().join("report");
    ok(&[
        "report",
        "--results",
        p(&results),
        "--out",
        p(&report),
        "--main",
        "reach",
    ]);
    let md = std::fs::read_to_string(report.join("REPORT.md")).unwrap();
    for needle in [
        "| ArmReach | RGE-PCA † | kde | 2 |",
        "![ArmReach: KL-coverage vs exploration epochs (ArmReach, 2 latents); curves: the mean over repetitions",
        "](figures/klc_armreach.svg)",
        "### ArmReach",
    ] {
        assert!(md.contains(needle), "no `{needle}` in:\n{md}");
    }
    assert!(report.join("figures/klc_armreach.svg").is_file());
    let finals = std::fs::read_to_string(report.join("data/final_by_seed.csv")).unwrap();
    assert_eq!(
        finals.lines().filter(|l| l.contains("armreach")).count(),
        6,
        "{finals}"
    );
}
