//! The film: per-pixel sums (never a running mean) so films merge exactly, plus the sums of
//! squares that give each pixel's sample variance. Layout = the GPU buffer's: per pixel
//! `[Σr, Σg, Σb, n, Σr², Σg², Σb², dropped non-finite samples]`.

use glam::Vec3;

pub const FLOATS_PER_PIXEL: usize = 8;

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub data: Vec<f32>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        Film { width, height, data: vec![0.0; width as usize * height as usize * FLOATS_PER_PIXEL] }
    }

    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    fn px(&self, i: usize) -> &[f32] {
        &self.data[i * FLOATS_PER_PIXEL..(i + 1) * FLOATS_PER_PIXEL]
    }

    /// Adds one sample; non-finite samples are dropped and counted.
    pub fn add_sample(&mut self, i: usize, l: Vec3) {
        let p = &mut self.data[i * FLOATS_PER_PIXEL..(i + 1) * FLOATS_PER_PIXEL];
        if l.is_finite() {
            p[0] += l.x;
            p[1] += l.y;
            p[2] += l.z;
            p[3] += 1.0;
            p[4] += l.x * l.x;
            p[5] += l.y * l.y;
            p[6] += l.z * l.z;
        } else {
            p[7] += 1.0;
        }
    }

    pub fn count(&self, i: usize) -> f32 {
        self.px(i)[3]
    }

    /// Mean radiance of pixel `i` (0 with no samples).
    pub fn mean(&self, i: usize) -> Vec3 {
        let p = self.px(i);
        if p[3] > 0.0 { Vec3::new(p[0], p[1], p[2]) / p[3] } else { Vec3::ZERO }
    }

    /// Unbiased sample variance of one sample of pixel `i`.
    pub fn sample_variance(&self, i: usize) -> Vec3 {
        let p = self.px(i);
        let n = p[3];
        if n < 2.0 {
            return Vec3::ZERO;
        }
        let mean = Vec3::new(p[0], p[1], p[2]) / n;
        let sq = Vec3::new(p[4], p[5], p[6]) / n;
        ((sq - mean * mean) * (n / (n - 1.0))).max(Vec3::ZERO)
    }

    /// Variance of the pixel's mean estimate (sample variance / n).
    pub fn variance_of_mean(&self, i: usize) -> Vec3 {
        let n = self.count(i).max(1.0);
        self.sample_variance(i) / n
    }

    pub fn means(&self) -> Vec<Vec3> {
        (0..self.pixel_count()).map(|i| self.mean(i)).collect()
    }

    /// Samples per pixel (the minimum over pixels; all pixels agree unless samples were dropped).
    pub fn spp(&self) -> u32 {
        (0..self.pixel_count()).map(|i| self.count(i) + self.px(i)[7]).fold(f32::INFINITY, f32::min) as u32
    }

    pub fn nonfinite_samples(&self) -> u64 {
        (0..self.pixel_count()).map(|i| self.px(i)[7] as u64).sum()
    }

    /// Adds another film of the same size (sample ranges rendered separately).
    pub fn merge(&mut self, other: &Film) {
        for (a, b) in self.data.iter_mut().zip(&other.data) {
            *a += b;
        }
    }
}
