//! The follow-up's convolutional VAE and β-VAE (Laversanne-Finot, Péré, Oudeyer, CoRL 2018;
//! `docs/followup.md`), on the host engine: its weights, their initialisation, and the batched
//! forward passes that encode pictures and decode codes. Training is [`super::conv_train`].
//!
//! The architecture, as the authors' `representation_pytorch.py` has it (and the tensor shapes of
//! their released weights confirm):
//! - encoder: 4 x [Conv2d `filters` channels, kernel 4, stride 2, padding 1, ReLU]
//!   (3 -> 32 -> 32 -> 32 -> 32 channels, 64 -> 4 px), flattened channel-major (512 values),
//!   Linear 512 -> 256, ReLU, Linear 256 -> 256, ReLU, Linear 256 -> 2d (mean | log-variance);
//! - decoder: Linear d -> 256, ReLU, Linear 256 -> 512, ReLU, reshaped to 32 x 4 x 4,
//!   3 x [ConvTranspose2d 32 -> 32, kernel 4, stride 2, padding 1, ReLU], ConvTranspose2d
//!   32 -> 3 (the pixel logits).
//!
//! Layouts are PyTorch's for the convolutions (`[out, in, k, k]`, transposed `[in, out, k, k]`,
//! pictures `NCHW`); the dense layers are [`HostLayer`]s (`[in, out]`, as in the dense networks).
//! Every product runs on [`ugl_kernels`]' deterministic kernels, so a forward pass has the same
//! bits on every SIMD path and for every thread count.
//!
//! Initialisation ([`ConvInit`]): PyTorch's defaults, every weight and bias uniform in
//! `±1/sqrt(fan_in)`. The authors' PyTorch (0.4.0, [`ConvInit::Torch04`], the default) took the
//! fan-in as `in x k x k` for every convolution, transposed or not; today's
//! (`kaiming_uniform(a = sqrt(5))`, [`ConvInit::Torch`]) takes a transposed convolution's
//! weight's second dimension, `out x k x k`. The two differ only for the last transposed
//! convolution (32 -> 3), which the authors' draws 3.3 times smaller (`docs/neural.md`). The
//! draws come from the learner's stream, layer by layer in the order above, weight then bias,
//! the same draws for both (only that layer's bound differs).

use rand::RngExt;
use serde::{Deserialize, Serialize};
use ugl_kernels::{Conv2d, ConvTranspose2d};

use super::host_train::{dense_forward, relu_in_place};
use super::model_file::ModelFileError;
use super::nets::HostLayer;
use crate::seed::Stream;

/// Kernel side of every convolution.
pub const KERNEL: usize = 4;
/// Stride of every convolution.
pub const STRIDE: usize = 2;
/// Zero padding of every convolution.
pub const PADDING: usize = 1;
/// Stride-2 convolutions in the encoder (and transposed ones in the decoder).
pub const CONV_LAYERS: usize = 4;

pub use ugl_types::ConvInit;

/// The fan-in of a transposed convolution of this shape under `init`.
fn deconv_fan_in(init: ConvInit, shape: &ConvTranspose2d) -> usize {
    let k2 = shape.kernel * shape.kernel;
    match init {
        ConvInit::Torch04 => shape.channels_in * k2,
        ConvInit::Torch => shape.channels_out * k2,
    }
}

/// The sizes of a convolutional VAE. [`ConvArch::followup`] is the authors'.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvArch {
    /// Channels of a picture (3: RGB).
    pub channels: usize,
    /// Side of a (square) picture, a multiple of 16 (64).
    pub side: usize,
    /// Channels of every hidden convolution (32).
    pub filters: usize,
    /// Width of the dense layers (256).
    pub hidden: usize,
    /// Latent dimensions d (10).
    pub latents: usize,
}

impl ConvArch {
    /// The follow-up's network: 64x64 RGB pictures, 32 filters, 256 hidden units.
    pub fn followup(latents: usize) -> ConvArch {
        ConvArch {
            channels: 3,
            side: 64,
            filters: 32,
            hidden: 256,
            latents,
        }
    }

    /// Why these sizes cannot make a network, if they cannot.
    pub fn check(&self) -> Result<(), String> {
        let side_unit = 1 << CONV_LAYERS;
        if self.side == 0 || !self.side.is_multiple_of(side_unit) {
            return Err(format!(
                "the picture side must be a positive multiple of {side_unit} (four stride-2 \
                 convolutions), got {}",
                self.side
            ));
        }
        for (what, v) in [
            ("channels", self.channels),
            ("filters", self.filters),
            ("hidden", self.hidden),
            ("latents", self.latents),
        ] {
            if v == 0 {
                return Err(format!("{what} must be at least 1"));
            }
        }
        Ok(())
    }

    /// Values of one picture.
    pub fn image_len(&self) -> usize {
        self.channels * self.side * self.side
    }

    /// Side of the encoder's last feature map.
    pub fn bottom_side(&self) -> usize {
        self.side >> CONV_LAYERS
    }

    /// Values of the flattened last feature map (512).
    pub fn flat(&self) -> usize {
        self.filters * self.bottom_side() * self.bottom_side()
    }

    /// The shape of encoder convolution `i` (0: the picture's).
    pub fn conv(&self, i: usize) -> Conv2d {
        let side = self.side >> i;
        Conv2d {
            channels_in: if i == 0 { self.channels } else { self.filters },
            channels_out: self.filters,
            kernel: KERNEL,
            stride: STRIDE,
            padding: PADDING,
            height: side,
            width: side,
        }
    }

    /// Floating-point operations of one training step on `batch` pictures, two per
    /// multiply-add: every layer's forward pass, weight gradient and input gradient, but the
    /// first convolution's input gradient (its input is the picture). Biases, activations, the
    /// loss and Adam's update are left out (under 1% of it). The yardstick of the speed
    /// measurements against the machine's FMA ceiling (`docs/neural.md`).
    pub fn step_flops(&self, batch: usize) -> u64 {
        let convs: u64 = (0..CONV_LAYERS)
            .map(|i| 3 * (self.conv(i).flops(batch) + self.deconv(i).flops(batch)))
            .sum::<u64>()
            - self.conv(0).flops(batch);
        let (flat, hidden, d) = (self.flat(), self.hidden, self.latents);
        let dense = flat * hidden + hidden * hidden + hidden * 2 * d + d * hidden + hidden * flat;
        convs + (6 * dense * batch) as u64
    }

    /// The shape of decoder transposed convolution `i` (the last one: the picture's).
    pub fn deconv(&self, i: usize) -> ConvTranspose2d {
        let side = self.bottom_side() << i;
        ConvTranspose2d {
            channels_in: self.filters,
            channels_out: if i + 1 == CONV_LAYERS {
                self.channels
            } else {
                self.filters
            },
            kernel: KERNEL,
            stride: STRIDE,
            padding: PADDING,
            height: side,
            width: side,
        }
    }
}

/// A convolution's weights: `w` `[out, in, k, k]`, `b` `[out]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvLayer {
    pub shape: Conv2d,
    pub w: Vec<f32>,
    pub b: Vec<f32>,
}

/// A transposed convolution's weights: `w` `[in, out, k, k]`, `b` `[out]`.
#[derive(Clone, Debug, PartialEq)]
pub struct DeconvLayer {
    pub shape: ConvTranspose2d,
    pub w: Vec<f32>,
    pub b: Vec<f32>,
}

/// The whole convolutional VAE's weights on the host.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvNet {
    pub arch: ConvArch,
    /// Encoder convolutions, picture first.
    pub enc_conv: Vec<ConvLayer>,
    /// Encoder dense layers: flat -> hidden, hidden -> hidden.
    pub enc_fc: [HostLayer; 2],
    /// hidden -> 2d (mean | log-variance).
    pub head: HostLayer,
    /// Decoder dense layers: d -> hidden, hidden -> flat.
    pub dec_fc: [HostLayer; 2],
    /// Decoder transposed convolutions, picture last.
    pub dec_conv: Vec<DeconvLayer>,
}

/// `n` draws of PyTorch's default initialisation for a fan-in: `U(-1/sqrt(fan_in),
/// 1/sqrt(fan_in))`.
fn torch_uniform(rng: &mut Stream, n: usize, fan_in: usize) -> Vec<f32> {
    let bound = 1.0 / (fan_in as f64).sqrt();
    (0..n)
        .map(|_| (bound * (2.0 * rng.random::<f64>() - 1.0)) as f32)
        .collect()
}

fn dense(rng: &mut Stream, inp: usize, out: usize) -> HostLayer {
    HostLayer {
        inp,
        out,
        w: torch_uniform(rng, inp * out, inp),
        b: torch_uniform(rng, out, inp),
    }
}

impl ConvNet {
    /// Fresh weights from `rng` (PyTorch's default initialisation of version `init`; module
    /// docs).
    ///
    /// # Panics
    /// If `arch` does not pass [`ConvArch::check`] (the learner checks it first).
    pub fn init(rng: &mut Stream, arch: ConvArch, init: ConvInit) -> ConvNet {
        if let Err(e) = arch.check() {
            panic!("ConvNet::init: {e}");
        }
        let k2 = KERNEL * KERNEL;
        let enc_conv = (0..CONV_LAYERS)
            .map(|i| {
                let shape = arch.conv(i);
                let fan_in = shape.channels_in * k2;
                ConvLayer {
                    shape,
                    w: torch_uniform(rng, shape.weight_len(), fan_in),
                    b: torch_uniform(rng, shape.channels_out, fan_in),
                }
            })
            .collect();
        let enc_fc = [
            dense(rng, arch.flat(), arch.hidden),
            dense(rng, arch.hidden, arch.hidden),
        ];
        let head = dense(rng, arch.hidden, 2 * arch.latents);
        let dec_fc = [
            dense(rng, arch.latents, arch.hidden),
            dense(rng, arch.hidden, arch.flat()),
        ];
        let dec_conv = (0..CONV_LAYERS)
            .map(|i| {
                let shape = arch.deconv(i);
                let fan_in = deconv_fan_in(init, &shape);
                DeconvLayer {
                    shape,
                    w: torch_uniform(rng, shape.weight_len(), fan_in),
                    b: torch_uniform(rng, shape.channels_out, fan_in),
                }
            })
            .collect();
        ConvNet {
            arch,
            enc_conv,
            enc_fc,
            head,
            dec_fc,
            dec_conv,
        }
    }

    /// Every parameter buffer, in the order of [`ConvNet::init`] (weight then bias per layer).
    pub fn params(&self) -> Vec<&[f32]> {
        let mut out: Vec<&[f32]> = Vec::with_capacity(26);
        for l in &self.enc_conv {
            out.extend([l.w.as_slice(), l.b.as_slice()]);
        }
        for l in self.enc_fc.iter().chain([&self.head]).chain(&self.dec_fc) {
            out.extend([l.w.as_slice(), l.b.as_slice()]);
        }
        for l in &self.dec_conv {
            out.extend([l.w.as_slice(), l.b.as_slice()]);
        }
        out
    }

    /// [`ConvNet::params`], mutable.
    pub fn params_mut(&mut self) -> Vec<&mut [f32]> {
        let mut out: Vec<&mut [f32]> = Vec::with_capacity(26);
        for l in &mut self.enc_conv {
            out.extend([l.w.as_mut_slice(), l.b.as_mut_slice()]);
        }
        for l in self
            .enc_fc
            .iter_mut()
            .chain([&mut self.head])
            .chain(&mut self.dec_fc)
        {
            out.extend([l.w.as_mut_slice(), l.b.as_mut_slice()]);
        }
        for l in &mut self.dec_conv {
            out.extend([l.w.as_mut_slice(), l.b.as_mut_slice()]);
        }
        out
    }

    /// The number of weights and biases.
    pub fn num_params(&self) -> usize {
        self.params().iter().map(|p| p.len()).sum()
    }

    /// The encoder's head outputs (`[n, 2d]`: mean | log-variance) of `n` pictures (`NCHW`).
    pub fn encode_heads(&self, pictures: &[f32], n: usize) -> Vec<f32> {
        let mut acts = EncoderActivations::default();
        self.encoder_forward(pictures, n, &mut acts);
        acts.heads
    }

    /// The encoder's forward pass, keeping every activation (the trainer's backward reads them).
    pub(super) fn encoder_forward(&self, x: &[f32], n: usize, acts: &mut EncoderActivations) {
        acts.conv.resize_with(CONV_LAYERS, Vec::new);
        for (i, l) in self.enc_conv.iter().enumerate() {
            let (done, rest) = acts.conv.split_at_mut(i);
            let input = if i == 0 { x } else { &done[i - 1] };
            let out = &mut rest[0];
            out.resize(n * l.shape.out_len(), 0.0);
            l.shape.forward(n, input, &l.w, Some(&l.b), out);
            relu_in_place(out);
        }
        let h = self.arch.hidden;
        acts.h1.resize(n * h, 0.0);
        dense_forward(
            &self.enc_fc[0],
            &acts.conv[CONV_LAYERS - 1],
            n,
            &mut acts.h1,
        );
        relu_in_place(&mut acts.h1);
        acts.h2.resize(n * h, 0.0);
        dense_forward(&self.enc_fc[1], &acts.h1, n, &mut acts.h2);
        relu_in_place(&mut acts.h2);
        acts.heads.resize(n * 2 * self.arch.latents, 0.0);
        dense_forward(&self.head, &acts.h2, n, &mut acts.heads);
    }

    /// The pixel logits (`[n, C, S, S]`) of `n` codes (`[n, d]`).
    pub fn decode_logits(&self, z: &[f32], n: usize) -> Vec<f32> {
        let mut acts = DecoderActivations::default();
        self.decoder_forward(z, n, &mut acts);
        acts.logits
    }

    /// The decoder's forward pass, keeping every activation.
    pub(super) fn decoder_forward(&self, z: &[f32], n: usize, acts: &mut DecoderActivations) {
        let (h, flat) = (self.arch.hidden, self.arch.flat());
        acts.g1.resize(n * h, 0.0);
        dense_forward(&self.dec_fc[0], z, n, &mut acts.g1);
        relu_in_place(&mut acts.g1);
        acts.g2.resize(n * flat, 0.0);
        dense_forward(&self.dec_fc[1], &acts.g1, n, &mut acts.g2);
        relu_in_place(&mut acts.g2);
        acts.deconv.resize_with(CONV_LAYERS - 1, Vec::new);
        for (i, l) in self.dec_conv.iter().enumerate() {
            let out_len = n * l.shape.out_len();
            let last = i + 1 == CONV_LAYERS;
            let (done, rest) = acts.deconv.split_at_mut(i.min(CONV_LAYERS - 1));
            let input = if i == 0 { &acts.g2 } else { &done[i - 1] };
            let out = if last { &mut acts.logits } else { &mut rest[0] };
            out.resize(out_len, 0.0);
            l.shape.forward(n, input, &l.w, Some(&l.b), out);
            if !last {
                relu_in_place(out);
            }
        }
    }
}

/// What a convolutional network's model file says in its header.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConvFileHeader {
    /// Always [`CONV_FILE_KIND`].
    kind: String,
    arch: ConvArch,
}

/// The `kind` of a convolutional network's model file.
const CONV_FILE_KIND: &str = "conv-vae";

impl ConvNet {
    /// The weights as a sealed model file ([`super::model_file::seal`]): a JSON header with the
    /// architecture, then the payload ([`ConvNet::payload`]).
    pub fn to_model_bytes(&self) -> Vec<u8> {
        let header = serde_json::to_vec(&ConvFileHeader {
            kind: CONV_FILE_KIND.to_string(),
            arch: self.arch,
        })
        .expect("a header serialises");
        super::model_file::seal(&header, &self.payload())
    }

    /// Read back [`ConvNet::to_model_bytes`]; `Err` says why the bytes cannot be trusted
    /// (damaged, another kind of model, sizes that make no network, a payload of another
    /// length).
    pub fn from_model_bytes(bytes: &[u8]) -> Result<ConvNet, ModelFileError> {
        let (header, payload) = super::model_file::unseal(bytes)?;
        let header: ConvFileHeader =
            serde_json::from_slice(header).map_err(|e| ModelFileError::Header(e.to_string()))?;
        if header.kind != CONV_FILE_KIND {
            return Err(ModelFileError::Content(format!(
                "a {} model file, not a convolutional VAE's",
                header.kind
            )));
        }
        ConvNet::from_payload(header.arch, payload)
    }

    /// Every parameter buffer of [`ConvNet::params`] as little-endian `f32`.
    pub fn payload(&self) -> Vec<u8> {
        self.params()
            .iter()
            .flat_map(|p| p.iter().flat_map(|v| v.to_le_bytes()))
            .collect()
    }

    /// The network of architecture `arch` with the weights of `payload` ([`ConvNet::payload`]);
    /// `Err` if the architecture makes no network or the payload has another length.
    pub fn from_payload(arch: ConvArch, payload: &[u8]) -> Result<ConvNet, ModelFileError> {
        arch.check().map_err(ModelFileError::Content)?;
        // Shapes from the architecture; values from the payload.
        let mut net = ConvNet::init(
            &mut crate::seed::stream_named(0, "shapes"),
            arch,
            ConvInit::Torch04,
        );
        let want: usize = net.num_params() * 4;
        if payload.len() != want {
            return Err(ModelFileError::Content(format!(
                "the payload holds {} bytes; this architecture needs {want}",
                payload.len()
            )));
        }
        let mut values = payload
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")));
        for p in net.params_mut() {
            for v in p.iter_mut() {
                *v = values.next().expect("length checked");
            }
        }
        Ok(net)
    }
}

/// A picture stored rows first with its channels last (`HWC`, as `armballs-corl` renders and
/// the data sets store it) in the networks' channel-major layout (`CHW`).
pub fn channels_first(picture: &[f32], channels: usize, out: &mut [f32]) {
    assert_eq!(picture.len(), out.len(), "channels_first: lengths differ");
    let pixels = picture.len() / channels.max(1);
    for (p, px) in picture.chunks_exact(channels).enumerate() {
        for (c, &v) in px.iter().enumerate() {
            out[c * pixels + p] = v;
        }
    }
}

/// The encoder's activations of one batch (after each ReLU; the heads before any).
#[derive(Default)]
pub(super) struct EncoderActivations {
    /// After each convolution's ReLU.
    pub conv: Vec<Vec<f32>>,
    pub h1: Vec<f32>,
    pub h2: Vec<f32>,
    pub heads: Vec<f32>,
}

/// The decoder's activations of one batch.
#[derive(Default)]
pub(super) struct DecoderActivations {
    pub g1: Vec<f32>,
    /// The second dense layer's output after its ReLU: the first transposed convolution's input.
    pub g2: Vec<f32>,
    /// After each hidden transposed convolution's ReLU.
    pub deconv: Vec<Vec<f32>>,
    pub logits: Vec<f32>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream_named;

    /// The follow-up's step at batch 64, counted by hand: the eight convolutions do
    /// 28,311,552 operations per picture forward (3,145,728 + 8,388,608 + 2,097,152 + 524,288
    /// each way), as many for the weight gradients and for the input gradients but the first
    /// layer's; the dense layers 335,360 multiply-adds per pass.
    #[test]
    fn a_steps_operations_are_counted_layer_by_layer() {
        let per_picture: u64 = 3 * 28_311_552 - 3_145_728 + 6 * 335_360;
        assert_eq!(ConvArch::followup(10).step_flops(64), 64 * per_picture);
    }

    #[test]
    fn the_followups_network_has_its_authors_shapes() {
        let arch = ConvArch::followup(10);
        arch.check().unwrap();
        assert_eq!(arch.flat(), 512);
        let net = ConvNet::init(&mut stream_named(1, "conv"), arch, ConvInit::Torch04);
        // The tensor sizes of the authors' released weights: 4 convolutions (3->32, 3 x 32->32,
        // 4x4), 512-256-256-20 and 10-256-512 dense layers, 4 transposed convolutions.
        let conv = 32 * 3 * 16 + 32 + 3 * (32 * 32 * 16 + 32);
        let fc = (512 * 256 + 256) + (256 * 256 + 256) + (256 * 20 + 20);
        let dec_fc = (10 * 256 + 256) + (256 * 512 + 512);
        let deconv = 3 * (32 * 32 * 16 + 32) + (32 * 3 * 16 + 3);
        assert_eq!(net.num_params(), conv + fc + dec_fc + deconv);
        assert_eq!(net.dec_conv[3].shape.out_height(), 64);
        assert_eq!(net.enc_conv[3].shape.out_height(), 4);
        // PyTorch's bounds: the first convolution's fan-in is 3 x 16.
        let bound = 1.0 / 48f32.sqrt();
        assert!(net.enc_conv[0].w.iter().all(|w| w.abs() <= bound));
        assert!(net.enc_conv[0].w.iter().any(|w| w.abs() > 0.9 * bound));
        assert_eq!(
            net.encode_heads(&vec![0.5; 2 * arch.image_len()], 2).len(),
            40
        );
        assert_eq!(net.decode_logits(&[0.1; 20], 2).len(), 2 * 3 * 64 * 64);
    }

    #[test]
    fn the_authors_initialisation_draws_only_the_last_layer_smaller() {
        let arch = ConvArch::followup(10);
        let theirs = ConvNet::init(&mut stream_named(1, "conv"), arch, ConvInit::Torch04);
        let today = ConvNet::init(&mut stream_named(1, "conv"), arch, ConvInit::Torch);
        // The same draws: every layer but the last transposed convolution is identical.
        assert_eq!(theirs.enc_conv, today.enc_conv);
        assert_eq!(theirs.dec_conv[..3], today.dec_conv[..3]);
        assert_eq!(theirs.dec_fc, today.dec_fc);
        // The last one (32 -> 3): bound 1/sqrt(32 x 16) against 1/sqrt(3 x 16), draw by draw.
        let (a, b) = (&theirs.dec_conv[3], &today.dec_conv[3]);
        let ratio = (48f64 / 512.0).sqrt();
        for (x, y) in a.w.iter().chain(&a.b).zip(b.w.iter().chain(&b.b)) {
            assert!(
                (f64::from(*x) - ratio * f64::from(*y)).abs() < 1e-6,
                "{x} {y}"
            );
        }
        let bound = 1.0 / 512f32.sqrt();
        assert!(a.w.iter().all(|w| w.abs() <= bound));
        assert!(a.w.iter().any(|w| w.abs() > 0.9 * bound));
        assert_eq!(ConvInit::default(), ConvInit::Torch04);
    }

    #[test]
    fn sizes_that_make_no_network_are_refused() {
        let arch = ConvArch::followup(10);
        assert!(ConvArch { side: 60, ..arch }.check().is_err());
        assert!(ConvArch { side: 0, ..arch }.check().is_err());
        assert!(ConvArch { latents: 0, ..arch }.check().is_err());
        assert!(ConvArch { filters: 0, ..arch }.check().is_err());
    }

    #[test]
    fn a_model_file_round_trips_and_damage_is_refused() {
        let arch = ConvArch {
            channels: 2,
            side: 16,
            filters: 3,
            hidden: 5,
            latents: 2,
        };
        let net = ConvNet::init(&mut stream_named(4, "conv"), arch, ConvInit::Torch04);
        let bytes = net.to_model_bytes();
        assert_eq!(ConvNet::from_model_bytes(&bytes).unwrap(), net);
        let mut damaged = bytes.clone();
        let mid = damaged.len() / 2;
        damaged[mid] ^= 1;
        assert_eq!(
            ConvNet::from_model_bytes(&damaged).unwrap_err(),
            ModelFileError::Checksum
        );
        // A sound file of another payload length (a network of other sizes, same header).
        let other = ConvNet::init(
            &mut stream_named(4, "conv"),
            ConvArch { hidden: 6, ..arch },
            ConvInit::Torch04,
        );
        let (_, payload) = super::super::model_file::unseal(&other.to_model_bytes())
            .map(|(h, p)| (h.to_vec(), p.to_vec()))
            .unwrap();
        let (header, _) = super::super::model_file::unseal(&bytes).unwrap();
        let mixed = super::super::model_file::seal(header, &payload);
        let err = ConvNet::from_model_bytes(&mixed).unwrap_err();
        assert!(err.to_string().contains("payload holds"), "{err}");
        // Another kind of file.
        let alien = super::super::model_file::seal(
            br#"{"kind":"pca","arch":{"channels":2,"side":16,"filters":3,"hidden":5,"latents":2}}"#,
            &[],
        );
        assert!(ConvNet::from_model_bytes(&alien).is_err());
    }

    #[test]
    fn the_followups_pictures_go_channel_first() {
        use crate::env::cdge::{VALUES, normalise, render_rgb};
        let mut raw = vec![0u8; VALUES];
        // The yellow ball (red and green) left, the blue distractor right.
        render_rgb([-0.5, 0.0], [0.5, 0.0], 0.17, 0.15, &mut raw);
        let mut hwc = vec![0.0f32; VALUES];
        normalise(&raw, &mut hwc);
        let mut chw = vec![0.0f32; VALUES];
        channels_first(&hwc, 3, &mut chw);
        let plane = |c: usize| &chw[c * 4096..(c + 1) * 4096];
        // Row 32, the ball's centre column 16 and the distractor's 48.
        let at = |c: usize, x: usize| plane(c)[32 * 64 + x];
        assert_eq!([at(0, 16), at(1, 16), at(2, 16)], [1.0, 1.0, 0.0]);
        assert_eq!([at(0, 48), at(1, 48), at(2, 48)], [0.0, 0.0, 1.0]);
    }
}
