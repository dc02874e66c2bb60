//! OIDN's RT U-Net: its layers read from a weight archive, and the order the twins run them.
//!
//! Every layer is a 3×3 convolution (stride 1, zero padding 1) with a bias and a ReLU. The
//! encoder halves the resolution four times by 2×2 max pooling; the decoder doubles it by
//! nearest-neighbour upsampling and concatenates the encoder's tensor of the same resolution
//! after the upsampled one (channels in that order), the last time the network's input
//! itself. The base and the small networks share this graph and differ in channel counts,
//! which are read from the tensors' shapes.

use super::tza::Tensor;

/// One convolution: weights in OIHW order (output, input, row, column) and biases.
#[derive(Clone, Debug)]
pub struct Conv {
    pub name: &'static str,
    pub inputs: usize,
    pub outputs: usize,
    pub weight: Vec<f32>,
    pub bias: Vec<f32>,
}

/// Where a layer reads from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The network's input tensor (transformed colour, albedo, normal).
    Input,
    /// The output of step `k` (of `UNET_STEPS`).
    Step(usize),
}

/// One layer of the graph: convolve `input` (upsampled 2× first when `upsample`), with
/// `skip` concatenated after it, then pool 2×2 when `pool`.
#[derive(Clone, Copy, Debug)]
pub struct Step {
    pub conv: &'static str,
    pub input: Source,
    pub upsample: bool,
    pub skip: Option<Source>,
    pub pool: bool,
}

const fn step(conv: &'static str, input: Source, upsample: bool, skip: Option<Source>, pool: bool) -> Step {
    Step { conv, input, upsample, skip, pool }
}

use Source::{Input, Step as S};

/// The U-Net in execution order; the last step's output is the network's.
pub const UNET_STEPS: [Step; 16] = [
    step("enc_conv0", Input, false, None, false),
    step("enc_conv1", S(0), false, None, true),
    step("enc_conv2", S(1), false, None, true),
    step("enc_conv3", S(2), false, None, true),
    step("enc_conv4", S(3), false, None, true),
    step("enc_conv5a", S(4), false, None, false),
    step("enc_conv5b", S(5), false, None, false),
    step("dec_conv4a", S(6), true, Some(S(3)), false),
    step("dec_conv4b", S(7), false, None, false),
    step("dec_conv3a", S(8), true, Some(S(2)), false),
    step("dec_conv3b", S(9), false, None, false),
    step("dec_conv2a", S(10), true, Some(S(1)), false),
    step("dec_conv2b", S(11), false, None, false),
    step("dec_conv1a", S(12), true, Some(Input), false),
    step("dec_conv1b", S(13), false, None, false),
    step("dec_conv0", S(14), false, None, false),
];

/// Image sides are padded to a multiple of this (four 2× poolings).
pub const ALIGNMENT: usize = 16;

/// The network's receptive field in pixels (OIDN's figure for the base and small networks):
/// an output pixel depends on inputs at most half of it away.
pub const RECEPTIVE_FIELD: usize = 174;

/// The overlap tiles read beyond the part they write: half the receptive field, rounded up
/// to the alignment.
pub const TILE_OVERLAP: usize = (RECEPTIVE_FIELD / 2).next_multiple_of(ALIGNMENT);

/// A network ready to run: its convolutions in `UNET_STEPS` order.
#[derive(Clone, Debug)]
pub struct Network {
    pub convs: Vec<Conv>,
    /// Channels of the input: 3 (colour), 6 (+ albedo) or 9 (+ normal).
    pub input_channels: usize,
}

impl Network {
    /// The network of a weight archive, with every shape checked against the graph.
    pub fn from_tensors(tensors: &[Tensor]) -> Result<Network, String> {
        if tensors.iter().any(|t| t.name == "enc_conv1b.weight") {
            return Err("the large U-Net (high quality, `_large` weights) is not supported".into());
        }
        let find = |name: String| tensors.iter().find(|t| t.name == name).ok_or(format!("missing tensor {name}"));
        let mut convs: Vec<Conv> = Vec::with_capacity(UNET_STEPS.len());
        for (k, s) in UNET_STEPS.iter().enumerate() {
            let w = find(format!("{}.weight", s.conv))?;
            let b = find(format!("{}.bias", s.conv))?;
            if w.dims.len() != 4 || w.dims[2] != 3 || w.dims[3] != 3 || w.layout != "oihw" {
                return Err(format!("{}.weight: expected a 3x3 oihw kernel, found {:?} {}", s.conv, w.dims, w.layout));
            }
            let (outputs, inputs) = (w.dims[0], w.dims[1]);
            if b.dims != [outputs] {
                return Err(format!("{}.bias: expected {outputs} values, found {:?}", s.conv, b.dims));
            }
            // Input channels must equal what the graph feeds this layer.
            let channels = |src: Source| match src {
                Source::Input => None,
                Source::Step(j) => Some(convs[j].outputs),
            };
            let expected = match (k, channels(s.input), s.skip.map(channels)) {
                (0, _, _) => None,
                (_, Some(a), None) => Some(a),
                (_, Some(a), Some(Some(b))) => Some(a + b),
                (_, Some(a), Some(None)) => inputs.checked_sub(a).filter(|c| [3, 6, 9].contains(c)).map(|_| inputs),
                _ => None,
            };
            if k > 0 && expected != Some(inputs) {
                return Err(format!("{}.weight: {inputs} input channels do not fit the U-Net", s.conv));
            }
            if k == 0 && ![3, 6, 9].contains(&inputs) {
                return Err(format!("enc_conv0.weight: {inputs} input channels (expected 3, 6 or 9)"));
            }
            convs.push(Conv { name: s.conv, inputs, outputs, weight: w.data.clone(), bias: b.data.clone() });
        }
        let input_channels = convs[0].inputs;
        if convs[13].inputs != convs[12].outputs + input_channels || convs[15].outputs != 3 {
            return Err("the decoder's shapes do not fit the U-Net".into());
        }
        Ok(Network { convs, input_channels })
    }

    /// Channels of a source.
    pub fn channels(&self, source: Source) -> usize {
        match source {
            Source::Input => self.input_channels,
            Source::Step(k) => self.convs[k].outputs,
        }
    }

    /// Multiply-adds per pixel of the full-resolution input.
    pub fn macs_per_pixel(&self) -> f64 {
        // The fraction of the input's pixels a layer runs at.
        let mut fraction = 1.0;
        let mut total = 0.0;
        for (s, c) in UNET_STEPS.iter().zip(&self.convs) {
            if s.upsample {
                fraction *= 4.0;
            }
            total += (c.inputs * c.outputs * 9) as f64 * fraction;
            if s.pool {
                fraction /= 4.0;
            }
        }
        total
    }
}

/// The resolution level (0 = full, k = 1/2^k) of each step's output.
pub fn levels() -> [u32; 16] {
    let mut out = [0; 16];
    let mut level = 0;
    for (k, s) in UNET_STEPS.iter().enumerate() {
        if s.upsample {
            level -= 1;
        }
        if s.pool {
            level += 1;
        }
        out[k] = level;
    }
    out
}
