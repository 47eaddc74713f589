//! One run, one representation or one more learner from command-line choices (`ugl run`,
//! `ugl embed`, `ugl compare`): the checks and the changes they make to a profile, so that the
//! command line only parses arguments, shows progress and prints. Every error is one line that
//! names the flag.

use crate::invalid::InvalidValue;
use std::path::Path;

use super::config::{CampaignConfig, ExternalConfig};
use super::plan::RunSpec;
use crate::env::EnvKind;
use crate::explore::{Algo, Learner, SamplerKind};
use crate::repr::neural::Variant;

/// The choices of `ugl run`.
#[derive(Clone, Debug)]
pub struct RunRequest {
    pub env: EnvKind,
    pub algo: Algo,
    pub sampler: SamplerKind,
    pub variant: Option<Variant>,
    pub latents: usize,
    /// Override of the profile's number of UGL training images.
    pub images: Option<usize>,
    pub seed: u64,
    /// Exploration replicate of the repetition.
    pub exploration: u32,
    /// Override of the profile's number of exploration epochs.
    pub epochs: Option<usize>,
    /// `rge-external`: the program's command line (replaces the profile's).
    pub command: Option<String>,
    /// `rge-external`: the program's name in results.
    pub name: Option<String>,
}

impl RunRequest {
    /// Check the request against the profile `cfg` (read from `profile`), apply its
    /// overrides to `cfg`, and return the run.
    pub fn resolve(
        &self,
        cfg: &mut CampaignConfig,
        profile: &Path,
    ) -> Result<RunSpec, InvalidValue> {
        check_seed(self.seed)?;
        if let Some(e) = self.epochs {
            cfg.explore.epochs = e;
            cfg.explore
                .validate()
                .map_err(|m| InvalidValue::new("--epochs", format!("--epochs: {m}")))?;
        }
        let goal_directed = self.algo.strategy() != crate::explore::Strategy::Rpe;
        cfg.explore
            .check_goal_epochs(goal_directed)
            .map_err(|m| match self.epochs {
                Some(e) => InvalidValue::new("--epochs", format!("--epochs {e}: {m}")),
                None => m,
            })?;
        if goal_directed && self.algo.space().is_engineered() {
            cfg.mge
                .engineered_explore(&cfg.explore)
                .check_goal_epochs(true)
                .map_err(|m| {
                    InvalidValue::new(
                        "mge.engineered_bootstrap_epochs",
                        format!("mge.engineered_bootstrap_epochs: {m}"),
                    )
                })?;
        }
        if self.algo.space() == crate::explore::GoalSpaceKind::EngineeredPosition
            && !self.env.spec().has_orientation()
        {
            return Err(InvalidValue::new(
                "--algo",
                format!(
                    "--algo {}: the outcome of {} is the objects' positions already, so its \
                 position-only goal space is rge-efr's (use --algo rge-efr)",
                    self.algo,
                    self.env.name()
                ),
            ));
        }
        set_images(cfg, self.images)?;
        let spec = match self.algo.learner() {
            None => RunSpec::baseline(self.env, self.algo, self.seed),
            Some(_) => {
                if !self.sampler.is_learned() {
                    return Err(InvalidValue::new(
                        "--sampler",
                        format!(
                            "--sampler must be {} for {}",
                            SamplerKind::learned_names().replace(", ", " or "),
                            self.algo
                        ),
                    ));
                }
                check_latents(self.latents, cfg.ugl.images)?;
                check_modules(self.algo, self.latents, cfg.mge.module_size)?;
                RunSpec::learned(
                    self.env,
                    self.algo,
                    self.sampler,
                    self.latents,
                    self.variant.unwrap_or_default(),
                    self.seed,
                )
            }
        };
        let spec = spec.with_exploration(self.exploration);
        check_variant(self.algo, self.variant)?;
        if self.sampler.needs_prior() && !self.algo.learner().is_some_and(|l| l.may_have_prior()) {
            let with_prior: Vec<&str> = Learner::all()
                .filter(|l| l.may_have_prior())
                .map(|l| l.entry().algo)
                .collect();
            return Err(InvalidValue::new(
                "--sampler",
                format!(
                    "--sampler gaussian needs a goal-space prior: {}, not {} (use kde)",
                    with_prior.join(", "),
                    self.algo
                ),
            ));
        }
        let external = self.algo.learner().is_some_and(Learner::is_external);
        if !external && (self.command.is_some() || self.name.is_some()) {
            return Err(InvalidValue::new(
                "--command",
                format!(
                    "--command and --name apply to the external learner's algorithms only \
                 (rge-external, mge-external-*), not {}",
                    self.algo
                ),
            ));
        }
        if external {
            self.set_external(cfg, profile)?;
        }
        Ok(spec)
    }

    /// `--command` / `--name` of an external run, over the profile's `[learners.external]`.
    fn set_external(&self, cfg: &mut CampaignConfig, profile: &Path) -> Result<(), InvalidValue> {
        if let Some(cmd) = &self.command {
            if cmd.trim().is_empty() {
                return Err(InvalidValue::new(
                    "--command",
                    "--command must not be empty",
                ));
            }
            let configured = cfg.learners.external();
            let name = self
                .name
                .clone()
                .or_else(|| configured.as_ref().map(|e| e.name.clone()))
                .unwrap_or_else(|| "external".into());
            cfg.learners.set_external(&ExternalConfig {
                name,
                command: cmd.clone(),
                ready_timeout_s: configured.as_ref().and_then(|e| e.ready_timeout_s),
                answer_timeout_s: configured.as_ref().and_then(|e| e.answer_timeout_s),
            });
        } else if let (Some(name), Some(mut e)) = (&self.name, cfg.learners.external()) {
            e.name = name.clone();
            cfg.learners.set_external(&e);
        }
        if cfg.learners.external().is_none() {
            return Err(InvalidValue::new(
                "--algo",
                format!(
                    "--algo {} needs --command (a program speaking the external-learner protocol) or a [learners.external] section (name, command) in the profile {}",
                    self.algo,
                    profile.display()
                ),
            ));
        }
        cfg.validate()
            .map_err(|m| InvalidValue::new("--name", format!("--name/--command: {m}")))
    }
}

/// The results store keeps repetition indices as signed 64-bit integers (parquet `seed`).
pub fn check_seed(seed: u64) -> Result<(), InvalidValue> {
    if seed > i64::MAX as u64 {
        return Err(InvalidValue::new(
            "--seed",
            format!(
                "--seed must be below 2^63 = {} (the results store keeps it as a signed 64-bit integer), got {seed}",
                i64::MAX as u64 + 1
            ),
        ));
    }
    Ok(())
}

/// `--images`: override the profile's number of UGL training images.
pub fn set_images(cfg: &mut CampaignConfig, images: Option<usize>) -> Result<(), InvalidValue> {
    if let Some(n) = images {
        if n < 2 {
            return Err(InvalidValue::new(
                "--images",
                format!("--images must be at least 2, got {n}"),
            ));
        }
        crate::limits::check_images(n, crate::limits::image_values(&cfg.matrix.envs))
            .map_err(|e| InvalidValue::new("--images", format!("--images: {e}")))?;
        cfg.ugl.images = n;
    }
    Ok(())
}

/// `--latents` of a learned goal space fitted on `images` images.
pub fn check_latents(latents: usize, images: usize) -> Result<(), InvalidValue> {
    if images < 2 {
        return Err(InvalidValue::new(
            "--images",
            format!(
                "a learned goal space needs at least 2 training images ([ugl] images or \
                 --images), got {images}"
            ),
        ));
    }
    if latents == 0 || latents >= images {
        return Err(InvalidValue::new(
            "--latents",
            format!(
                "--latents must be between 1 and the number of images - 1 ({}), got {latents}",
                images - 1
            ),
        ));
    }
    Ok(())
}

/// `--latents` of a modular exploration of a learned goal space: its modules take
/// `module_size` latents each (`[mge] module_size`), checked before anything is trained.
pub fn check_modules(algo: Algo, latents: usize, module_size: usize) -> Result<(), InvalidValue> {
    let modular = algo.learner().is_some()
        && algo
            .modules()
            .is_some_and(|m| m != crate::explore::Modules::Flat);
    if modular && module_size > 0 && !latents.is_multiple_of(module_size) {
        return Err(InvalidValue::new(
            "--latents",
            format!(
                "--latents {latents}: {algo} splits its latents into modules of \
             mge.module_size = {module_size}, and {latents} is not a multiple of {module_size}"
            ),
        ));
    }
    Ok(())
}

/// `--variant` applies to the algorithms whose learner has variants only (the registry says
/// which).
pub fn check_variant(algo: Algo, variant: Option<Variant>) -> Result<(), InvalidValue> {
    variant_applies(
        algo.learner(),
        variant,
        |l| l.entry().algo,
        &algo.to_string(),
    )
}

/// [`check_variant`] for a command that names learners (`ugl embed --learner`).
pub fn check_learner_variant(
    learner: Learner,
    variant: Option<Variant>,
) -> Result<(), InvalidValue> {
    variant_applies(Some(learner), variant, Learner::name, learner.name())
}

fn variant_applies(
    learner: Option<Learner>,
    variant: Option<Variant>,
    name: fn(Learner) -> &'static str,
    given: &str,
) -> Result<(), InvalidValue> {
    if variant.is_some() && !learner.is_some_and(|l| l.has_variants()) {
        let with_variants: Vec<&str> = Learner::all()
            .filter(|l| l.has_variants())
            .map(name)
            .collect();
        return Err(InvalidValue::new(
            "--variant",
            format!(
                "--variant applies to {} only (the others have one behaviour), not {given}",
                with_variants.join(" and ")
            ),
        ));
    }
    Ok(())
}

/// The learner named `name`: a registered one, or with `command` an external program (set in
/// `cfg.learners.external`).
pub fn resolve_learner(
    name: &str,
    command: Option<&str>,
    cfg: &mut CampaignConfig,
) -> Result<Learner, InvalidValue> {
    let registered: Vec<Learner> = Learner::all().filter(|l| !l.is_external()).collect();
    match (registered.iter().find(|l| l.name() == name), command) {
        (Some(l), None) => Ok(*l),
        (Some(_), Some(_)) => Err(InvalidValue::new(
            "--learner",
            format!(
                "--learner {name} is a registered learner: drop --command, or give the external program another name"
            ),
        )),
        (None, Some(cmd)) => {
            if cmd.trim().is_empty() {
                return Err(InvalidValue::new(
                    "--command",
                    "--command must not be empty",
                ));
            }
            // The profile's timeouts still apply to the program given here.
            let configured = cfg.learners.external();
            cfg.learners.set_external(&ExternalConfig {
                name: name.to_string(),
                command: cmd.to_string(),
                ready_timeout_s: configured.as_ref().and_then(|e| e.ready_timeout_s),
                answer_timeout_s: configured.as_ref().and_then(|e| e.answer_timeout_s),
            });
            Learner::all()
                .find(|l| l.is_external())
                .ok_or_else(|| InvalidValue::new("--command", "this build has no external learner"))
        }
        (None, None) => {
            let names: Vec<&str> = registered.iter().map(|l| l.name()).collect();
            Err(InvalidValue::new(
                "--learner",
                format!(
                    "--learner {name} is not a registered learner ({}); for a program speaking the external-learner protocol add --command",
                    names.join(", ")
                ),
            ))
        }
    }
}

/// `ugl compare`: the campaign `compare-NAME` that runs one more learner on the cells, seeds,
/// reps and budgets of `cfg` (so its runs pair with the base campaign's: same run seeds and
/// UGL data sets). Returns it and the base campaign's name. An external program gets
/// Gaussian-prior goals only with `gaussian` (it must write a prior).
pub fn compare_campaign(
    mut cfg: CampaignConfig,
    learner: &str,
    command: Option<&str>,
    gaussian: bool,
) -> Result<(CampaignConfig, String), InvalidValue> {
    let name = learner.trim().to_string();
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-' || c == '_')
    {
        return Err(InvalidValue::new(
            "--learner",
            format!(
                "--learner must be a short name of lowercase letters, digits, '-' and '_', got '{name}'"
            ),
        ));
    }
    let algo = Algo::rge(resolve_learner(&name, command, &mut cfg)?);
    let base = std::mem::replace(&mut cfg.campaign.name, format!("compare-{name}"));
    cfg.campaign.description = format!("{name} on the cells and seeds of campaign '{base}'");
    cfg.campaign.role = ugl_types::CampaignRole::Compare;
    cfg.campaign.variant_of = Some(base.clone());
    cfg.campaign.tag = None;
    cfg.campaign.label = None;
    cfg.matrix.algos = vec![algo];
    if algo.learner().is_some_and(Learner::is_external) && !gaussian {
        cfg.matrix.samplers.retain(|s| !s.needs_prior());
        if cfg.matrix.samplers.is_empty() {
            cfg.matrix.samplers = vec![SamplerKind::KDE];
        }
    }
    Ok((cfg, base))
}

#[cfg(test)]
mod tests {
    use super::*;

    const PROFILE: &str = "[campaign]\nname = \"base\"\nreps = 2\n[matrix]\nenvs = [\"armball\"]\n\
        algos = [\"rpe\", \"rge-pca\", \"rge-vae\"]\nsamplers = [\"kde\", \"gaussian\"]\n\
        latents = [\"true\"]\n[ugl]\nimages = 200\n";

    fn cfg() -> CampaignConfig {
        CampaignConfig::from_toml(PROFILE, Path::new("base.toml")).unwrap()
    }

    /// Fewer than 2 images (a profile without learned algorithms may say 0) is a clear error,
    /// not an overflow.
    #[test]
    fn too_few_images_for_a_learned_space_is_an_error() {
        for images in [0, 1] {
            let e = check_latents(1, images).unwrap_err().to_string();
            assert!(e.contains("at least 2 training images"), "{e}");
        }
        assert!(check_latents(1, 2).is_ok());
        let e = check_latents(2, 2).unwrap_err().to_string();
        assert!(
            e.contains("between 1 and the number of images - 1 (1)"),
            "{e}"
        );
    }

    fn request(algo: &str) -> RunRequest {
        RunRequest {
            env: EnvKind::ARMBALL,
            algo: algo.parse().unwrap(),
            sampler: SamplerKind::KDE,
            variant: None,
            latents: 2,
            images: None,
            seed: 0,
            exploration: 0,
            epochs: None,
            command: None,
            name: None,
        }
    }

    #[test]
    fn a_run_request_is_checked_and_applied() {
        let mut c = cfg();
        let spec = RunRequest {
            images: Some(300),
            epochs: Some(150),
            ..request("rge-pca")
        }
        .resolve(&mut c, Path::new("base.toml"))
        .unwrap();
        assert_eq!(spec.run_id(), "armball.rge-pca.kde.l2.s0");
        assert_eq!((c.ugl.images, c.explore.epochs), (300, 150));
        let err = |r: RunRequest| {
            let e = r.resolve(&mut cfg(), Path::new("base.toml")).unwrap_err();
            // The key is data, and the message names it.
            assert!(e.message.contains(&e.key), "{e:?}");
            e.message
        };
        assert!(
            err(RunRequest {
                variant: Some(Variant::Corrected),
                ..request("rge-pca")
            })
            .contains("--variant applies to rge-vae and rge-rfvae")
        );
        assert!(
            err(RunRequest {
                sampler: SamplerKind::GAUSSIAN,
                ..request("rge-isomap")
            })
            .contains("prior")
        );
        assert!(
            err(RunRequest {
                latents: 200,
                ..request("rge-pca")
            })
            .contains("--latents")
        );
        assert!(
            err(RunRequest {
                seed: u64::MAX,
                ..request("rpe")
            })
            .contains("--seed")
        );
        assert!(
            err(RunRequest {
                images: Some(1),
                ..request("rge-pca")
            })
            .contains("--images")
        );
        assert!(
            err(RunRequest {
                command: Some("x".into()),
                ..request("rge-pca")
            })
            .contains("--command and --name")
        );
        assert!(err(request("rge-external")).contains("[learners.external]"));
        let mut c = cfg();
        RunRequest {
            command: Some("python3 x.py".into()),
            ..request("rge-external")
        }
        .resolve(&mut c, Path::new("base.toml"))
        .unwrap();
        assert_eq!(c.learners.external().unwrap().name, "external");
    }

    /// `--command` replaces the program, not the profile's timeouts (compare and embed dropped
    /// them, and waited on a hanging learner past the configured limit).
    #[test]
    fn a_command_keeps_the_profiles_external_timeouts() {
        let text = format!(
            "{PROFILE}[learners.external]\nname = \"slow\"\ncommand = \"false\"\n\
             ready_timeout_s = 3.0\nanswer_timeout_s = 2.0\n"
        );
        let mut c = CampaignConfig::from_toml(&text, Path::new("base.toml")).unwrap();
        resolve_learner("mine", Some("python3 m.py"), &mut c).unwrap();
        let e = c.learners.external().unwrap();
        assert_eq!(
            (e.name.as_str(), e.command.as_str()),
            ("mine", "python3 m.py")
        );
        assert_eq!(
            (e.ready_timeout_s, e.answer_timeout_s),
            (Some(3.0), Some(2.0))
        );
    }

    #[test]
    fn a_compare_campaign_keeps_the_cells_and_seeds() {
        let (c, base) = compare_campaign(cfg(), "pca-centred", None, false).unwrap();
        assert_eq!(base, "base");
        assert_eq!(c.campaign.name, "compare-pca-centred");
        assert_eq!(c.campaign.seed, cfg().campaign.seed);
        assert_eq!(c.matrix.algos, vec!["rge-pca-centred".parse().unwrap()]);
        // An external program: no Gaussian goals unless asked.
        let (c, _) = compare_campaign(cfg(), "mine", Some("python3 m.py"), false).unwrap();
        assert_eq!(c.matrix.samplers, vec![SamplerKind::KDE]);
        assert_eq!(c.learners.external().unwrap().name, "mine");
        let (c, _) = compare_campaign(cfg(), "mine", Some("python3 m.py"), true).unwrap();
        assert_eq!(c.matrix.samplers.len(), 2);
        assert!(compare_campaign(cfg(), "Bad Name", None, false).is_err());
        assert!(
            compare_campaign(cfg(), "nosuch", None, false)
                .unwrap_err()
                .message
                .contains("not a registered learner")
        );
        assert!(
            compare_campaign(cfg(), "pca", Some("true"), false)
                .unwrap_err()
                .message
                .contains("registered learner")
        );
    }
}
