//! What the whole project knows about each representation learner besides its code: names,
//! how the report shows it, what its goal space offers, and the paper's training of the neural
//! ones. The science crate's registry (`ugl_bench::repr::registry`) pairs each entry with its
//! implementation; the report reads this table alone.

use crate::env::{ImageShape, RGB64};

/// Whether a learner's goal space has a prior to sample goals from (`--sampler gaussian`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prior {
    /// Never.
    None,
    /// Always (N(0, I) of a VAE).
    Always,
    /// When the fitted model declares one (an external program writing `prior.npy`).
    Declared,
}

/// The paper's training of a dense neural learner (Péré et al., appendix; the authors' code).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperTraining {
    /// Optimiser steps.
    pub iterations: usize,
    /// Hidden sizes `[H1, H2]`.
    pub hidden: [usize; 2],
    pub batch: usize,
    pub lr: f64,
    /// `Adagrad` or `Adam`.
    pub optimiser: &'static str,
    /// Iterations of the KL warm-up (0: none).
    pub warmup: usize,
}

/// One learner.
#[derive(Debug, PartialEq)]
pub struct LearnerInfo {
    /// Name in campaign files, results and on the command line (`vae`).
    pub name: &'static str,
    /// The algorithm that explores its goal space (`rge-vae`): `rge-` + name.
    pub algo: &'static str,
    /// Name in the report (`VAE`).
    pub display: &'static str,
    /// One line for `--help` and the docs.
    pub description: &'static str,
    /// Whether its runs are crossed with the variants faithful / corrected (the original
    /// code had defects there).
    pub has_variants: bool,
    /// Whether its goal space has a prior.
    pub prior: Prior,
    /// Whether the paper evaluated it: the report gives the paper's learners fixed colours and
    /// markers, in the registry's order, and compares them with the paper's numbers.
    pub in_paper: bool,
    /// The paper's training, for the dense neural learners (None: not a dense network).
    pub paper_training: Option<PaperTraining>,
    /// The pictures it is built for (None: any vector of pixels); its runs need an environment
    /// that renders them.
    pub image: Option<ImageShape>,
    /// Its style slot in the report's figures: the colour and marker its algorithm has in every
    /// figure. Fixed per entry (never its position in the registry), so that adding a learner
    /// moves no other; the slots of all strategies and learners are distinct and run from 0
    /// without a gap (`Algo::styled`).
    pub style: usize,
    /// The learner whose random stream this one draws (None: its own). A learner that differs
    /// from another only in its objective draws the other's stream, so that a repetition's two
    /// networks start from the same weights and draw the same batches and noise: a paired
    /// comparison of the objectives (the follow-up's VAE draws its β-VAE's).
    pub shares_stream_with: Option<&'static LearnerInfo>,
}

const fn dense(iterations: usize, optimiser: &'static str, warmup: usize) -> PaperTraining {
    PaperTraining {
        iterations,
        hidden: [1200, 1200],
        batch: 100,
        lr: 1e-3,
        optimiser,
        warmup,
    }
}

pub static PCA: LearnerInfo = LearnerInfo {
    name: "pca",
    algo: "rge-pca",
    display: "PCA",
    description: "the paper's PCA: non-centred truncated SVD (randomized, as sklearn's TruncatedSVD)",
    has_variants: false,
    prior: Prior::None,
    in_paper: true,
    paper_training: None,
    image: None,
    style: 2,
    shares_stream_with: None,
};
pub static PCA_CENTRED: LearnerInfo = LearnerInfo {
    name: "pca-centred",
    algo: "rge-pca-centred",
    display: "PCA (centred)",
    description: "ordinary mean-centred PCA (the same randomized solver, centred implicitly)",
    has_variants: false,
    prior: Prior::None,
    in_paper: false,
    paper_training: None,
    image: None,
    style: 9,
    shares_stream_with: None,
};
pub static ISOMAP: LearnerInfo = LearnerInfo {
    name: "isomap",
    algo: "rge-isomap",
    display: "Isomap",
    description: "Isomap (kNN graph, geodesics, classical MDS; sklearn's defaults)",
    has_variants: false,
    prior: Prior::None,
    in_paper: true,
    paper_training: None,
    image: None,
    style: 3,
    shares_stream_with: None,
};
pub static AE: LearnerInfo = LearnerInfo {
    name: "ae",
    algo: "rge-ae",
    display: "AE",
    description: "dense auto-encoder, sigmoid latents, Adagrad",
    has_variants: false,
    prior: Prior::None,
    in_paper: true,
    paper_training: Some(dense(200_000, "Adagrad", 0)),
    image: None,
    style: 4,
    shares_stream_with: None,
};
pub static VAE: LearnerInfo = LearnerInfo {
    name: "vae",
    algo: "rge-vae",
    display: "VAE",
    description: "dense variational auto-encoder (encoding: the mean), Adam",
    has_variants: true,
    prior: Prior::Always,
    in_paper: true,
    paper_training: Some(dense(100_000, "Adam", 0)),
    image: None,
    style: 5,
    shares_stream_with: None,
};
pub static RFVAE: LearnerInfo = LearnerInfo {
    name: "rfvae",
    algo: "rge-rfvae",
    display: "RFVAE",
    description: "the VAE with 10 radial flows and a KL warm-up, Adam",
    has_variants: true,
    prior: Prior::Always,
    in_paper: true,
    paper_training: Some(dense(50_000, "Adam", 10_000)),
    image: None,
    style: 6,
    shares_stream_with: None,
};
pub static BVAE: LearnerInfo = LearnerInfo {
    name: "bvae",
    algo: "rge-bvae",
    display: "β-VAE",
    description: "the dense VAE with its KL weighted by beta ([learners.bvae] beta, default 4; beta = 1 is the VAE), Adam",
    has_variants: false,
    prior: Prior::Always,
    in_paper: false,
    paper_training: Some(dense(100_000, "Adam", 0)),
    image: None,
    style: 10,
    shares_stream_with: None,
};
pub static CONV_VAE: LearnerInfo = LearnerInfo {
    name: "conv-vae",
    algo: "rge-conv-vae",
    display: "conv VAE",
    description: "the follow-up's convolutional VAE (64x64 RGB pictures; encoding: the mean), Adam",
    has_variants: false,
    prior: Prior::Always,
    in_paper: false,
    paper_training: None,
    image: Some(RGB64),
    style: 11,
    shares_stream_with: Some(&CONV_BVAE),
};
pub static CONV_BVAE: LearnerInfo = LearnerInfo {
    name: "conv-bvae",
    algo: "rge-conv-bvae",
    display: "conv β-VAE",
    description: "the follow-up's convolutional β-VAE, capacity-annealed (64x64 RGB pictures; encoding: the mean), Adam",
    has_variants: false,
    prior: Prior::Always,
    in_paper: false,
    paper_training: None,
    image: Some(RGB64),
    style: 12,
    shares_stream_with: None,
};
pub static GAUSSIAN_PROJECTION: LearnerInfo = LearnerInfo {
    name: "gaussian-projection",
    algo: "rge-gaussian-projection",
    display: "Gaussian projection",
    description: "a seeded Gaussian random projection of the pixels: an untrained control",
    has_variants: false,
    prior: Prior::None,
    in_paper: false,
    paper_training: None,
    image: None,
    style: 13,
    shares_stream_with: None,
};
pub static EXTERNAL: LearnerInfo = LearnerInfo {
    name: "external",
    algo: "rge-external",
    display: "external",
    description: "a program outside this project, through the external-learner protocol (docs/external-learners.md)",
    has_variants: false,
    prior: Prior::Declared,
    in_paper: false,
    paper_training: None,
    image: None,
    style: 14,
    shares_stream_with: None,
};

/// Every learner, in the report's order.
pub static LEARNERS: [&LearnerInfo; 11] = [
    &PCA,
    &PCA_CENTRED,
    &ISOMAP,
    &AE,
    &VAE,
    &RFVAE,
    &BVAE,
    &CONV_VAE,
    &CONV_BVAE,
    &GAUSSIAN_PROJECTION,
    &EXTERNAL,
];

impl LearnerInfo {
    /// The name the learner's random stream derives from ([`Self::shares_stream_with`]).
    pub fn stream_name(&self) -> &'static str {
        self.shares_stream_with.map_or(self.name, |l| l.name)
    }

    /// Every learner, in the registry's order.
    pub fn all() -> impl Iterator<Item = &'static LearnerInfo> {
        LEARNERS.iter().copied()
    }

    /// The learner called `name` (`vae`).
    pub fn by_name(name: &str) -> Option<&'static LearnerInfo> {
        LearnerInfo::all().find(|l| l.name == name)
    }

    /// The learner whose algorithm is `algo` (`rge-vae`).
    pub fn by_algo(algo: &str) -> Option<&'static LearnerInfo> {
        LearnerInfo::all().find(|l| l.algo == algo)
    }

    /// The algorithms of the learners the paper evaluated, in the registry's order (`rge-pca`,
    /// `rge-isomap`, `rge-ae`, `rge-vae`, `rge-rfvae`).
    pub fn paper_algos() -> impl Iterator<Item = &'static str> {
        LearnerInfo::all().filter(|l| l.in_paper).map(|l| l.algo)
    }

    /// Whether it is a dense neural network (trained with the model cache and evidence).
    pub fn is_neural(&self) -> bool {
        self.paper_training.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_algorithms_follow_them() {
        for (i, l) in LEARNERS.iter().enumerate() {
            assert_eq!(l.algo, format!("rge-{}", l.name));
            assert_eq!(LearnerInfo::by_name(l.name), Some(*l));
            assert_eq!(LearnerInfo::by_algo(l.algo), Some(*l));
            assert!(LEARNERS[..i].iter().all(|o| o.name != l.name));
        }
        let neural: Vec<&str> = LearnerInfo::all()
            .filter(|l| l.is_neural())
            .map(|l| l.name)
            .collect();
        assert_eq!(neural, ["ae", "vae", "rfvae", "bvae"]);
        let paper: Vec<&str> = LearnerInfo::paper_algos().collect();
        assert_eq!(
            paper,
            ["rge-pca", "rge-isomap", "rge-ae", "rge-vae", "rge-rfvae"]
        );
    }
}
