//! The shape of a 2-D convolution: its sizes, and nothing that computes (`crate::conv` computes
//! with it; `crate::conv_direct` reads it).

/// The shape of a convolution: `channels_in` images of `height x width`, a square kernel,
/// a stride and a zero padding on every side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Conv2d {
    /// Input channels.
    pub channels_in: usize,
    /// Output channels.
    pub channels_out: usize,
    /// Kernel side.
    pub kernel: usize,
    /// Stride.
    pub stride: usize,
    /// Zero padding on each side.
    pub padding: usize,
    /// Input rows.
    pub height: usize,
    /// Input columns.
    pub width: usize,
}

impl Conv2d {
    /// Output rows: `(height + 2 padding - kernel) / stride + 1`.
    pub fn out_height(&self) -> usize {
        (self.height + 2 * self.padding - self.kernel) / self.stride + 1
    }

    /// Output columns.
    pub fn out_width(&self) -> usize {
        (self.width + 2 * self.padding - self.kernel) / self.stride + 1
    }

    /// Values of one input image (all channels).
    pub fn in_len(&self) -> usize {
        self.channels_in * self.height * self.width
    }

    /// Values of one output image.
    pub fn out_len(&self) -> usize {
        self.channels_out * self.out_height() * self.out_width()
    }

    /// Values of the weight, `[out, in, k, k]`.
    pub fn weight_len(&self) -> usize {
        self.channels_out * self.patch()
    }

    /// Floating-point operations of the forward pass on `n` images, a multiply and an add per
    /// weight and output pixel (`2 out in k² pixels n`, biases left out). The input gradient
    /// and the weight gradient each do as many.
    pub fn flops(&self, n: usize) -> u64 {
        2 * (self.weight_len() * self.pixels_out() * n) as u64
    }

    /// Rows of the `im2col` matrix: `in * k * k`.
    pub(crate) fn patch(&self) -> usize {
        self.channels_in * self.kernel * self.kernel
    }

    pub(crate) fn pixels_out(&self) -> usize {
        self.out_height() * self.out_width()
    }

    pub(crate) fn check(&self) {
        assert!(
            self.kernel >= 1 && self.stride >= 1,
            "conv2d: kernel and stride must be at least 1: {self:?}"
        );
        assert!(
            self.channels_in >= 1 && self.channels_out >= 1 && self.height >= 1 && self.width >= 1,
            "conv2d: channels and image sides must be at least 1: {self:?}"
        );
        assert!(
            self.height + 2 * self.padding >= self.kernel
                && self.width + 2 * self.padding >= self.kernel,
            "conv2d: the kernel is larger than the padded image: {self:?}"
        );
    }
}
