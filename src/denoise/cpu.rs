//! The CPU twin of the network (and the oracle the WGSL passes are tested against).
//!
//! Activations are kept row-major, channels last, with a one-pixel zero border: a 3×3
//! convolution is then nine matrix products, one per kernel tap, each reading the input
//! matrix shifted by that tap's offset in the flattened padded image (pixels × channels)
//! times the tap's (input × output) weight matrix. No im2col copy is made; the products run
//! on `gemm`'s SIMD kernels over bands of rows in parallel. Pixels of the border columns get
//! garbage from the shifted reads and are zeroed again after each layer.

use super::network::{Network, Source, UNET_STEPS};
use super::transfer::{Images, output_value};
use rayon::prelude::*;

/// An activation: `height`×`width` pixels of `channels` floats inside a zero border.
#[derive(Clone, Debug)]
pub struct Activation {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    pub data: Vec<f32>,
}

impl Activation {
    pub fn zeros(width: usize, height: usize, channels: usize) -> Activation {
        Activation { width, height, channels, data: vec![0.0; (width + 2) * (height + 2) * channels] }
    }

    /// Flattened padded index of pixel (x, y).
    #[inline]
    pub fn index(&self, x: usize, y: usize) -> usize {
        ((y + 1) * (self.width + 2) + x + 1) * self.channels
    }

    /// The value of channel `c` at (x, y).
    pub fn at(&self, x: usize, y: usize, c: usize) -> f32 {
        self.data[self.index(x, y) + c]
    }
}

/// A layer's weights as one (input × output) matrix per tap, for each of its sources.
#[derive(Clone, Debug)]
pub struct TapWeights {
    /// `[tap][input][output]` for the first source, then the same for the skip source.
    pub taps: Vec<Vec<f32>>,
    pub bias: Vec<f32>,
    pub outputs: usize,
}

/// Rearranges OIHW weights into per-tap matrices, split at input channel `split`.
pub fn tap_weights(weight: &[f32], bias: &[f32], inputs: usize, outputs: usize, split: usize) -> TapWeights {
    let mut taps = Vec::new();
    for (lo, hi) in [(0, split), (split, inputs)] {
        if lo == hi {
            continue;
        }
        let n = hi - lo;
        for tap in 0..9 {
            let mut m = vec![0.0; n * outputs];
            for i in 0..n {
                for o in 0..outputs {
                    m[i * outputs + o] = weight[(o * inputs + lo + i) * 9 + tap];
                }
            }
            taps.push(m);
        }
    }
    TapWeights { taps, bias: bias.to_vec(), outputs }
}

/// Rows of the flattened padded image one task multiplies at a time.
const BAND_ROWS: usize = 1024;

/// out = ReLU(bias + conv3x3(a ‖ b)); `b` is the skip tensor concatenated after `a`.
pub fn conv3x3(a: &Activation, b: Option<&Activation>, w: &TapWeights) -> Activation {
    let (width, height) = (a.width, a.height);
    let stride = width + 2;
    let outputs = w.outputs;
    let mut out = Activation::zeros(width, height, outputs);
    // Output rows from pixel (0, 0) to pixel (width − 1, height − 1), flattened.
    let first = stride + 1;
    let last = height * stride + width + 1;
    let sources: Vec<&Activation> = std::iter::once(a).chain(b).collect();
    out.data[first * outputs..last * outputs].par_chunks_mut(BAND_ROWS * outputs).enumerate().for_each(
        |(band, dst)| {
            let q0 = first + band * BAND_ROWS;
            let rows = dst.len() / outputs;
            for row in dst.chunks_exact_mut(outputs) {
                row.copy_from_slice(&w.bias);
            }
            for (s, src) in sources.iter().enumerate() {
                let c = src.channels;
                for tap in 0..9 {
                    let (dy, dx) = (tap / 3, tap % 3);
                    // Input row of output row q for this tap: q + (dy − 1)·stride + dx − 1.
                    let start = q0 + dy * stride + dx - stride - 1;
                    let lhs = &src.data[start * c..(start + rows) * c];
                    matmul_add(dst, lhs, &w.taps[s * 9 + tap], rows, c, outputs);
                }
            }
            for (k, row) in dst.chunks_exact_mut(outputs).enumerate() {
                let x = (q0 + k) % stride;
                if x == 0 || x == stride - 1 {
                    row.fill(0.0);
                } else {
                    row.iter_mut().for_each(|v| *v = v.max(0.0));
                }
            }
        },
    );
    out
}

/// dst (m×n) += lhs (m×k) · rhs (k×n), all row-major and contiguous.
fn matmul_add(dst: &mut [f32], lhs: &[f32], rhs: &[f32], m: usize, k: usize, n: usize) {
    debug_assert!(dst.len() == m * n && lhs.len() == m * k && rhs.len() == k * n);
    // SAFETY: the slices hold exactly the m×n, m×k and k×n row-major matrices described by
    // these strides (checked above in debug builds; sizes come from the caller's shapes).
    unsafe {
        gemm::gemm(
            m,
            n,
            k,
            dst.as_mut_ptr(),
            1,
            n as isize,
            true,
            lhs.as_ptr(),
            1,
            k as isize,
            rhs.as_ptr(),
            1,
            n as isize,
            1.0,
            1.0,
            false,
            false,
            false,
            gemm::Parallelism::None,
        );
    }
}

/// 2×2 max pooling (sides are even: images are padded to a multiple of 16).
pub fn pool(a: &Activation) -> Activation {
    let (w, h, c) = (a.width / 2, a.height / 2, a.channels);
    let mut out = Activation::zeros(w, h, c);
    let stride = (w + 2) * c;
    out.data[stride..(h + 1) * stride].par_chunks_mut(stride).enumerate().for_each(|(y, row)| {
        for x in 0..w {
            let dst = &mut row[(x + 1) * c..(x + 2) * c];
            for (ch, d) in dst.iter_mut().enumerate() {
                let v = |dx: usize, dy: usize| a.at(2 * x + dx, 2 * y + dy, ch);
                *d = v(0, 0).max(v(1, 0)).max(v(0, 1)).max(v(1, 1));
            }
        }
    });
    out
}

/// Nearest-neighbour 2× upsampling.
pub fn upsample(a: &Activation) -> Activation {
    let (w, h, c) = (a.width * 2, a.height * 2, a.channels);
    let mut out = Activation::zeros(w, h, c);
    let stride = (w + 2) * c;
    out.data[stride..(h + 1) * stride].par_chunks_mut(stride).enumerate().for_each(|(y, row)| {
        for x in 0..w {
            let src = a.index(x / 2, y / 2);
            row[(x + 1) * c..(x + 2) * c].copy_from_slice(&a.data[src..src + c]);
        }
    });
    out
}

/// The network's input tensor for the window (x0, y0, w, h) of the images (the window may
/// reach past the image: those pixels are zero, as the alignment padding is).
pub fn input_tensor(images: &Images, x0: usize, y0: usize, w: usize, h: usize, input_scale: f32) -> Activation {
    let channels = images.channels();
    let mut t = Activation::zeros(w, h, channels);
    let stride = (w + 2) * channels;
    t.data[stride..(h + 1) * stride].par_chunks_mut(stride).enumerate().for_each(|(y, row)| {
        let iy = y0 + y;
        if iy >= images.height {
            return;
        }
        for x in 0..w.min(images.width.saturating_sub(x0)) {
            for c in 0..channels {
                row[(x + 1) * channels + c] = images.input_value(x0 + x, iy, c, input_scale);
            }
        }
    });
    t
}

/// The network's weights rearranged for `conv3x3`.
pub struct CpuNetwork {
    layers: Vec<TapWeights>,
}

impl CpuNetwork {
    pub fn new(net: &Network) -> CpuNetwork {
        let layers = UNET_STEPS
            .iter()
            .zip(&net.convs)
            .map(|(s, c)| {
                let split = if s.skip.is_some() { net.channels(s.input) } else { c.inputs };
                tap_weights(&c.weight, &c.bias, c.inputs, c.outputs, split)
            })
            .collect();
        CpuNetwork { layers }
    }

    /// Runs the U-Net on an input tensor whose sides are multiples of 16; returns the
    /// 3-channel output tensor (before the output transform).
    pub fn run(&self, input: Activation) -> Activation {
        let mut outputs: Vec<Option<Activation>> = vec![None; UNET_STEPS.len()];
        for (k, s) in UNET_STEPS.iter().enumerate() {
            let get = |src: Source| match src {
                Source::Input => &input,
                Source::Step(j) => outputs[j].as_ref().expect("the graph reads earlier steps only"),
            };
            let upsampled = s.upsample.then(|| upsample(get(s.input)));
            let a = upsampled.as_ref().unwrap_or_else(|| get(s.input));
            let y = conv3x3(a, s.skip.map(get), &self.layers[k]);
            let y = if s.pool { pool(&y) } else { y };
            outputs[k] = Some(y);
            // Free what no later step reads.
            for (j, out) in outputs.iter_mut().enumerate().take(k) {
                let later =
                    UNET_STEPS[k + 1..].iter().any(|t| [Some(t.input), t.skip].contains(&Some(Source::Step(j))));
                if !later {
                    *out = None;
                }
            }
        }
        outputs.pop().flatten().expect("the last step ran")
    }
}

/// Writes the interior `(wx, wy, ww, wh)` (image coordinates) of a tile's output, whose
/// tensor starts at image pixel (x0, y0), into the RGB image `out`.
#[allow(clippy::too_many_arguments)]
pub fn write_output(
    out: &mut [f32],
    width: usize,
    tile: &Activation,
    (x0, y0): (usize, usize),
    (wx, wy, ww, wh): (usize, usize, usize, usize),
    input_scale: f32,
) {
    for y in wy..wy + wh {
        for x in wx..wx + ww {
            for c in 0..3 {
                out[(y * width + x) * 3 + c] = output_value(tile.at(x - x0, y - y0, c), input_scale);
            }
        }
    }
}
