//! What the network sees and gives back: OIDN's HDR transfer (a perceptually uniform curve),
//! its automatic exposure, and the packing of colour, albedo and normal into the input
//! tensor. Twin: `shaders/denoise/transfer.wgsl`.

// The PU curve's constants (OIDN `TransferFunction::PU`), fitted to the perceptual
// uniformity of luminance in 100 cd/m² units; written as OIDN prints them (f32 rounds them
// the same way).
#![allow(clippy::excessive_precision)]
const PU_A: f32 = 1.41283765e+03;
const PU_B: f32 = 1.64593172e+00;
const PU_C: f32 = 4.31384981e-01;
const PU_D: f32 = -2.94139609e-03;
const PU_E: f32 = 1.92653254e-01;
const PU_F: f32 = 6.26026094e-03;
const PU_G: f32 = 9.98620152e-01;
const PU_Y0: f32 = 1.57945760e-06;
const PU_Y1: f32 = 3.22087631e-02;
const PU_X0: f32 = 2.23151711e-03;
const PU_X1: f32 = 3.70974749e-01;

/// The largest value the transfer maps (the largest f16), and the scale that maps its
/// encoding to 1.
pub const HDR_MAX: f32 = 65504.0;

/// The PU curve.
pub fn pu_forward(y: f32) -> f32 {
    if y <= PU_Y0 {
        PU_A * y
    } else if y <= PU_Y1 {
        PU_B * y.powf(PU_C) + PU_D
    } else {
        PU_E * (y + PU_F).ln() + PU_G
    }
}

/// The inverse of the PU curve.
pub fn pu_inverse(x: f32) -> f32 {
    if x <= PU_X0 {
        x / PU_A
    } else if x <= PU_X1 {
        ((x - PU_D) / PU_B).powf(1.0 / PU_C)
    } else {
        ((x - PU_G) / PU_E).exp() - PU_F
    }
}

/// 1 / PU(HDR_MAX): the encoded colour lies in [0, 1].
pub fn norm_scale() -> f32 {
    1.0 / pu_forward(HDR_MAX)
}

/// NaN → 0, then clamped: what every input goes through first.
#[inline]
fn sanitize(v: f32, lo: f32, hi: f32) -> f32 {
    if v.is_nan() { 0.0 } else { v.clamp(lo, hi) }
}

/// Rec. 709 luminance, as OIDN's autoexposure weighs colour.
#[inline]
fn luminance(r: f32, g: f32, b: f32) -> f32 {
    0.212671 * r + 0.715160 * g + 0.072169 * b
}

/// Side of the square bins the exposure is measured over.
pub const EXPOSURE_BIN: usize = 16;

/// OIDN's automatic exposure: the scale that brings the geometric mean of the luminance of
/// 16×16-pixel bins (bins with luminance above 1e-8) to 0.18; 1 when no bin has light.
/// Bin edges are at i·H/nH and j·W/nW (integer division), so bins cover the image exactly.
pub fn autoexposure(color: &[f32], width: usize, height: usize) -> f32 {
    let (nh, nw) = (height.div_ceil(EXPOSURE_BIN), width.div_ceil(EXPOSURE_BIN));
    let mut log_sum = 0.0f64;
    let mut count = 0usize;
    for i in 0..nh {
        let (y0, y1) = (i * height / nh, (i + 1) * height / nh);
        for j in 0..nw {
            let (x0, x1) = (j * width / nw, (j + 1) * width / nw);
            let mut sum = 0.0f32;
            for y in y0..y1 {
                for x in x0..x1 {
                    let p = &color[(y * width + x) * 3..][..3];
                    let c = |v: f32| sanitize(v, 0.0, f32::MAX);
                    sum += luminance(c(p[0]), c(p[1]), c(p[2]));
                }
            }
            let l = sum / ((y1 - y0) * (x1 - x0)) as f32;
            if l > 1e-8 {
                log_sum += (l as f64).log2();
                count += 1;
            }
        }
    }
    if count == 0 { 1.0 } else { 0.18 / ((log_sum / count as f64).exp2() as f32) }
}

/// The images a denoise reads: linear HDR colour, and optionally albedo (in [0, 1]) and the
/// shading normal (in [−1, 1]), each three floats a pixel, row-major.
#[derive(Clone, Copy, Debug)]
pub struct Images<'a> {
    pub width: usize,
    pub height: usize,
    pub color: &'a [f32],
    pub albedo: Option<&'a [f32]>,
    pub normal: Option<&'a [f32]>,
}

impl Images<'_> {
    /// Channels of the network input these images make: 3, 6 or 9.
    pub fn channels(&self) -> usize {
        3 + if self.albedo.is_some() { 3 } else { 0 } + if self.normal.is_some() { 3 } else { 0 }
    }

    /// Checks the sizes of the images and that a normal comes with an albedo (OIDN has no
    /// network for colour and normal alone).
    pub fn validate(&self) -> Result<(), String> {
        let n = self.width.checked_mul(self.height).and_then(|n| n.checked_mul(3)).ok_or("image too large")?;
        if self.width == 0 || self.height == 0 {
            return Err("an empty image has nothing to denoise".into());
        }
        for (name, img) in [("color", Some(self.color)), ("albedo", self.albedo), ("normal", self.normal)] {
            if let Some(img) = img
                && img.len() != n
            {
                return Err(format!("the {name} image has {} floats, expected {n}", img.len()));
            }
        }
        if self.normal.is_some() && self.albedo.is_none() {
            return Err("a normal image needs an albedo image too".into());
        }
        Ok(())
    }

    /// Input channel `c` of pixel (x, y), transformed as the network expects: colour scaled
    /// by `input_scale`, sanitised and PU-encoded; albedo clamped to [0, 1]; the normal
    /// clamped to [−1, 1] and mapped to [0, 1]. Twin of `input_value`.
    pub fn input_value(&self, x: usize, y: usize, c: usize, input_scale: f32) -> f32 {
        let i = (y * self.width + x) * 3;
        match c {
            0..3 => pu_forward(sanitize(self.color[i + c] * input_scale, 0.0, f32::MAX)) * norm_scale(),
            3..6 => match self.albedo {
                Some(a) => sanitize(a[i + c - 3], 0.0, 1.0),
                None => self.normal_value(i, c - 3),
            },
            _ => self.normal_value(i, c - 6),
        }
    }

    fn normal_value(&self, i: usize, c: usize) -> f32 {
        self.normal.map_or(0.0, |n| sanitize(n[i + c], -1.0, 1.0) * 0.5 + 0.5)
    }
}

/// The network's output value back to linear HDR colour: sanitised, PU-decoded and
/// unscaled. Twin of `output_value`.
pub fn output_value(v: f32, input_scale: f32) -> f32 {
    let x = sanitize(v, 0.0, f32::MAX);
    pu_inverse(x / norm_scale()).max(0.0) / input_scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pu_inverts_and_is_continuous() {
        for &y in &[0.0f32, 1e-7, PU_Y0, 1e-4, PU_Y1, 0.5, 1.0, 100.0, HDR_MAX] {
            let x = pu_forward(y);
            assert!((pu_inverse(x) - y).abs() <= 1e-4 * y.max(1e-3), "{y} -> {x} -> {}", pu_inverse(x));
        }
        // The pieces meet at their joints.
        for (y, x) in [(PU_Y0, PU_X0), (PU_Y1, PU_X1)] {
            assert!((pu_forward(y) - x).abs() < 2e-5, "joint at {y}: {} vs {x}", pu_forward(y));
        }
        assert!((pu_forward(HDR_MAX) * norm_scale() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn autoexposure_maps_a_uniform_grey_to_middle_grey() {
        let (w, h) = (37, 21);
        let color = vec![2.0f32; w * h * 3];
        assert!((autoexposure(&color, w, h) - 0.09).abs() < 1e-6);
        assert_eq!(autoexposure(&vec![0.0; w * h * 3], w, h), 1.0);
    }
}
