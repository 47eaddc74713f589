//! Seeding (docs/reproducibility.md): one campaign seed, a stable hash per run identity, and one
//! independent ChaCha stream per component, so that adding a draw in one component never shifts
//! another.
//!
//! Specification (fixed; changing it changes every result):
//! - run seed = first 8 bytes, little-endian, of
//!   `BLAKE3("ugl-bench/run-seed/v1\0" || campaign_seed as u64 LE || identity UTF-8)`, where
//!   the identity is the run's *exploration identity* (`RunSpec::exploration_identity`: for a
//!   learned goal space env, sampler, latents and repetition, not the learner, so that every
//!   learner of a cell draws the same exploration streams), the data set's identity, or the
//!   learner's (`RunSpec::learner_seed_identity`);
//! - stream seed for component `c` = `BLAKE3("ugl-bench/stream/v1\0" || run_seed LE || c UTF-8)`
//!   (all 32 bytes), used as the key of a `ChaCha8Rng`.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// A component's random stream.
pub type Stream = ChaCha8Rng;

/// The named components that draw random numbers. Each gets its own stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Component {
    /// Random motor parameters (RPE, bootstrap and random-ratio episodes, warm-up).
    Params,
    /// The draw that decides between random exploration and goal babbling.
    ExploreChoice,
    /// Goal sampling in the goal space.
    Goals,
    /// The meta-policy's Gaussian exploration noise.
    Noise,
    /// The passive observation data set of the UGL stage.
    Dataset,
    /// Learner initialisation and mini-batches.
    Learner,
    /// The sampling noise of a stochastic encoder while a run encodes its outcomes (the
    /// faithful RFVAE encodes with fresh noise). Drawn from the run's own seed, never from the
    /// fitted model, so that runs sharing an encoder do not depend on each other's order.
    Encoding,
    /// The held-out images on which a representation's latent quality is measured (states and,
    /// for a stochastic encoder, its encoding noise), drawn from the data set's seed.
    HeldOut,
    /// The environment's own motion (ArmBalls' distractor), consumed episode after episode.
    Distractor,
    /// Modular exploration's module choice (random or by learning progress).
    ModuleChoice,
}

impl Component {
    /// The component's name as it enters the stream hash.
    pub fn name(self) -> &'static str {
        match self {
            Component::Params => "params",
            Component::ExploreChoice => "explore-choice",
            Component::Goals => "goals",
            Component::Noise => "noise",
            Component::Dataset => "dataset",
            Component::Learner => "learner",
            Component::Encoding => "encoding",
            Component::HeldOut => "held-out",
            Component::Distractor => "distractor",
            Component::ModuleChoice => "module-choice",
        }
    }
}

/// The seed of a run, derived from the campaign seed and the run's canonical identity.
pub fn run_seed(campaign_seed: u64, identity: &str) -> u64 {
    let mut h = blake3::Hasher::new();
    h.update(b"ugl-bench/run-seed/v1\0");
    h.update(&campaign_seed.to_le_bytes());
    h.update(identity.as_bytes());
    let bytes = h.finalize();
    u64::from_le_bytes(bytes.as_bytes()[..8].try_into().expect("8 bytes"))
}

/// The random stream of one component of a run.
pub fn stream(run_seed: u64, component: Component) -> Stream {
    stream_named(run_seed, component.name())
}

/// A stream for a free-form component name (for plug-ins that need their own stream).
pub fn stream_named(run_seed: u64, component: &str) -> Stream {
    let mut h = blake3::Hasher::new();
    h.update(b"ugl-bench/stream/v1\0");
    h.update(&run_seed.to_le_bytes());
    h.update(component.as_bytes());
    ChaCha8Rng::from_seed(*h.finalize().as_bytes())
}

/// One standard normal draw: rand_distr 0.6's `StandardNormal` (the ZIGNOR ziggurat of Doornik
/// 2005), consuming the stream exactly as it does, with its `exp` and `ln` from `libm` instead of
/// the platform's libm, so a draw is the same on every CPU (README "Reproducibility").
pub fn standard_normal<R: rand::Rng + ?Sized>(rng: &mut R) -> f64 {
    use crate::ziggurat_tables::{ZIG_NORM_F, ZIG_NORM_R, ZIG_NORM_X};
    use rand::RngExt;
    loop {
        let bits = rng.next_u64();
        let i = (bits & 0xff) as usize;
        // 52 random bits as a float in [2, 4), minus 3: [-1, 1).
        let u = f64::from_bits((bits >> 12) | (1024u64 << 52)) - 3.0;
        let x = u * ZIG_NORM_X[i];
        if x.abs() < ZIG_NORM_X[i + 1] {
            return x;
        }
        if i == 0 {
            // The tail beyond R, by hand.
            let (mut tx, mut ty) = (1.0f64, 0.0f64);
            while -2.0 * ty < tx * tx {
                let x_: f64 = rng.sample(rand::distr::Open01);
                let y_: f64 = rng.sample(rand::distr::Open01);
                tx = libm::log(x_) / ZIG_NORM_R;
                ty = libm::log(y_);
            }
            return if u < 0.0 {
                tx - ZIG_NORM_R
            } else {
                ZIG_NORM_R - tx
            };
        }
        if ZIG_NORM_F[i + 1] + (ZIG_NORM_F[i] - ZIG_NORM_F[i + 1]) * rng.random::<f64>()
            < libm::exp(-x * x / 2.0)
        {
            return x;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    #[test]
    fn run_seed_is_stable_and_sensitive() {
        let a = run_seed(0, "env=armball/algo=rpe/seed=0");
        assert_eq!(a, run_seed(0, "env=armball/algo=rpe/seed=0"));
        assert_ne!(a, run_seed(1, "env=armball/algo=rpe/seed=0"));
        assert_ne!(a, run_seed(0, "env=armball/algo=rpe/seed=1"));
        // Pinned value: the hash is part of the specification; a change here changes every result.
        let expected = {
            let mut h = blake3::Hasher::new();
            h.update(b"ugl-bench/run-seed/v1\0");
            h.update(&0u64.to_le_bytes());
            h.update(b"env=armball/algo=rpe/seed=0");
            u64::from_le_bytes(h.finalize().as_bytes()[..8].try_into().unwrap())
        };
        assert_eq!(a, expected);
    }

    #[test]
    fn component_streams_are_independent() {
        let mut p = stream(7, Component::Params);
        let mut q = stream(7, Component::Noise);
        let mut p2 = stream(7, Component::Params);
        let a: u64 = p.next_u64();
        assert_eq!(a, p2.next_u64());
        assert_ne!(a, q.next_u64());
    }

    #[test]
    fn standard_normal_draws_what_rand_distr_draws() {
        use rand::Rng;
        use rand_distr::{Distribution, StandardNormal};
        // The same stream gives the same draws and leaves the stream at the same place: bit for
        // bit inside the ziggurat (the wedges' `exp` decided alike), and within an ulp or two in
        // the tail, where `libm`'s `log` and this platform's may round apart (they do: that is
        // the point of using `libm`).
        let (mut a, mut b) = (stream_named(7, "normal"), stream_named(7, "normal"));
        let (mut tail, mut tail_apart) = (0, 0);
        for _ in 0..1_000_000 {
            let x = standard_normal(&mut a);
            let y: f64 = StandardNormal.sample(&mut b);
            if x.abs() > crate::ziggurat_tables::ZIG_NORM_R {
                tail += 1;
                tail_apart += usize::from(x != y);
                assert!((x - y).abs() <= 4.0 * f64::EPSILON * y.abs(), "{x} vs {y}");
            } else {
                assert_eq!(x.to_bits(), y.to_bits());
            }
        }
        assert_eq!(a.next_u64(), b.next_u64(), "the streams moved apart");
        assert!(tail > 100, "the tail was drawn {tail} times");
        assert!(
            tail_apart < tail,
            "{tail_apart} of {tail} tail draws differ"
        );
    }
}
