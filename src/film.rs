//! The film: per-pixel sums of samples, never a running mean. Twin: `shaders/film.wgsl`.
//!
//! Radiance sums are 64-bit fixed point (32 integer bits, 32 fraction bits, kept as two u32
//! words): integer addition is associative, so films of disjoint sample ranges or tiles,
//! rendered anywhere, merge into exactly the film of one uninterrupted render. Each sample is
//! converted exactly unless it is below 2^-9 (then it is truncated to a multiple of 2^-32)
//! or above 2^31 (clamped). Sums of squares (for per-pixel variance) are plain f32.
//!
//! Per pixel, 12 words: `[hi.r, hi.g, hi.b, count, lo.r, lo.g, lo.b, dropped non-finite
//! samples, Σr² (f32 bits), Σg², Σb², 0]`.
//!
//! A film of an adaptive render (`src/adaptive.rs`) appends two regions after the pixels:
//! per pixel `ADAPTIVE_WORDS` words `[Σr, Σg, Σb of its odd-numbered samples (the half
//! buffer, f32 bits), 1 if it passed its last convergence test]`, then one word per pixel,
//! 1 once it has converged (padded to a multiple of 4 words: the kernel reads vec4 rows).
//!
//! A film with AOVs (`src/aov.rs`) appends `AOV_WORDS` words per pixel after those: the sums
//! of the albedo and the (biased) shading normal of the first visible surface and of its
//! camera distance, in the same fixed point as the radiance.

use glam::{DVec3, Vec3};

pub const WORDS_PER_PIXEL: usize = 12;

/// Words per pixel of an adaptive film's half-buffer region.
pub const ADAPTIVE_WORDS: usize = 4;

/// Words per pixel of a film's AOV region (`src/aov.rs`).
pub const AOV_WORDS: usize = 16;

/// Largest radiance one sample may add (the largest f32 below 2^31).
pub const MAX_SAMPLE: f32 = 2147483520.0;

/// Which optional regions a film carries after its pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FilmLayout {
    /// Adaptive sampling's half buffer and convergence flags.
    pub adaptive: bool,
    /// The albedo, normal and depth AOVs.
    pub aovs: bool,
}

impl FilmLayout {
    /// Words of the regions before the AOVs (pixels, then adaptive sampling's).
    pub fn aov_base(self, pixels: usize) -> usize {
        pixels * WORDS_PER_PIXEL + if self.adaptive { pixels * ADAPTIVE_WORDS + pixels.next_multiple_of(4) } else { 0 }
    }

    /// Words of a film of `pixels` pixels.
    pub fn words(self, pixels: usize) -> usize {
        self.aov_base(pixels) + if self.aovs { pixels * AOV_WORDS } else { 0 }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u32>,
    pub layout: FilmLayout,
}

/// A sample's value as 32.32 fixed point: (integer part, fraction × 2^32).
#[inline]
pub fn to_fixed(x: f32) -> (u32, u32) {
    let c = x.clamp(0.0, MAX_SAMPLE);
    // floor(c) by conversion (c ≥ 0, and an f32's integer part below 2^32 converts to u32
    // and back exactly): the kernel's `floor`, without a call to floorf on baseline x86-64.
    let hi = c as u32;
    (hi, ((c - hi as f32) * 4294967296.0) as u32)
}

/// Adds one sample to the 12 words of a pixel; non-finite samples are dropped and counted.
/// Twin of `film_add_sample`.
#[inline]
pub fn film_add_sample(p: &mut [u32], l: Vec3) {
    if !l.is_finite() {
        p[7] = p[7].wrapping_add(1);
        return;
    }
    for c in 0..3 {
        let (hi, lo) = to_fixed(l[c]);
        let (sum_lo, carry) = p[4 + c].overflowing_add(lo);
        p[4 + c] = sum_lo;
        p[c] = p[c].wrapping_add(hi).wrapping_add(carry as u32);
        p[8 + c] = (f32::from_bits(p[8 + c]) + l[c] * l[c]).to_bits();
    }
    p[3] = p[3].wrapping_add(1);
}

/// Σ L of a pixel's 12 words in f32, as the kernel computes it (twin of `film_sum`).
pub fn film_sum(p: &[u32]) -> Vec3 {
    let ch = |c: usize| p[c] as f32 + p[4 + c] as f32 * (1.0 / 4294967296.0);
    Vec3::new(ch(0), ch(1), ch(2))
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        Film::with_layout(width, height, FilmLayout::default())
    }

    /// An empty film with the optional regions of `layout`.
    pub fn with_layout(width: u32, height: u32, layout: FilmLayout) -> Film {
        let n = width as usize * height as usize;
        Film { width, height, data: vec![0; layout.words(n)], layout }
    }

    /// A film of one sample a pixel holding `rgb` (three floats a pixel, row-major): an image
    /// made elsewhere (a denoised one) as the display pass reads films.
    pub fn from_rgb(width: u32, height: u32, rgb: &[f32]) -> Film {
        let mut film = Film::new(width, height);
        for (i, c) in rgb.chunks_exact(3).enumerate().take(film.pixel_count()) {
            film.add_sample(i, Vec3::new(c[0], c[1], c[2]));
        }
        film
    }

    /// Bytes of a `width`×`height` film.
    pub fn bytes(width: u32, height: u32, layout: FilmLayout) -> u64 {
        layout.words(width as usize * height as usize) as u64 * 4
    }

    /// Whether the film carries adaptive sampling's half buffer and convergence flags.
    pub fn is_adaptive(&self) -> bool {
        self.layout.adaptive
    }

    /// Whether the film carries the albedo, normal and depth AOVs.
    pub fn has_aovs(&self) -> bool {
        self.layout.aovs
    }

    /// Index of pixel `i`'s AOV record in `data` (films with AOVs).
    pub fn aov_record(&self, i: usize) -> usize {
        self.layout.aov_base(self.pixel_count()) + i * AOV_WORDS
    }

    /// Pixel `i`'s AOV words (films with AOVs).
    pub fn aov_words(&self, i: usize) -> &[u32] {
        let at = self.aov_record(i);
        &self.data[at..at + AOV_WORDS]
    }

    /// Index of pixel `i`'s half-buffer record in `data` (adaptive films).
    pub fn adaptive_record(&self, i: usize) -> usize {
        self.pixel_count() * WORDS_PER_PIXEL + i * ADAPTIVE_WORDS
    }

    /// Index of pixel `i`'s convergence flag in `data` (adaptive films).
    pub fn converged_flag(&self, i: usize) -> usize {
        self.pixel_count() * (WORDS_PER_PIXEL + ADAPTIVE_WORDS) + i
    }

    /// Whether pixel `i` stopped taking samples (false on a film that is not adaptive).
    pub fn converged(&self, i: usize) -> bool {
        self.is_adaptive() && self.data[self.converged_flag(i)] != 0
    }

    /// The fraction of pixels that converged (None: not an adaptive film).
    pub fn converged_fraction(&self) -> Option<f64> {
        self.is_adaptive().then(|| {
            (0..self.pixel_count()).filter(|&i| self.converged(i)).count() as f64 / self.pixel_count().max(1) as f64
        })
    }

    /// Samples pixel `i` took (accumulated or dropped).
    pub fn taken(&self, i: usize) -> u32 {
        self.count(i).wrapping_add(self.nonfinite(i))
    }

    /// The mean number of samples a pixel took.
    pub fn mean_spp(&self) -> f64 {
        (0..self.pixel_count()).map(|i| self.taken(i) as f64).sum::<f64>() / self.pixel_count().max(1) as f64
    }

    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    fn px(&self, i: usize) -> &[u32] {
        &self.data[i * WORDS_PER_PIXEL..(i + 1) * WORDS_PER_PIXEL]
    }

    /// Adds one sample; non-finite samples are dropped and counted.
    pub fn add_sample(&mut self, i: usize, l: Vec3) {
        film_add_sample(&mut self.data[i * WORDS_PER_PIXEL..(i + 1) * WORDS_PER_PIXEL], l);
    }

    pub fn count(&self, i: usize) -> u32 {
        self.px(i)[3]
    }

    pub fn nonfinite(&self, i: usize) -> u32 {
        self.px(i)[7]
    }

    /// Σ L of pixel `i`, exactly (as f64).
    pub fn sum(&self, i: usize) -> DVec3 {
        let p = self.px(i);
        let ch = |c: usize| p[c] as f64 + p[4 + c] as f64 * (1.0 / 4294967296.0);
        DVec3::new(ch(0), ch(1), ch(2))
    }

    /// Mean radiance of pixel `i` (0 with no samples).
    pub fn mean(&self, i: usize) -> Vec3 {
        let n = self.count(i);
        if n == 0 { Vec3::ZERO } else { (self.sum(i) / n as f64).as_vec3() }
    }

    /// Unbiased sample variance of one sample of pixel `i`.
    pub fn sample_variance(&self, i: usize) -> Vec3 {
        let n = self.count(i) as f64;
        if n < 2.0 {
            return Vec3::ZERO;
        }
        let p = self.px(i);
        let sq = DVec3::new(f32::from_bits(p[8]) as f64, f32::from_bits(p[9]) as f64, f32::from_bits(p[10]) as f64);
        let mean = self.sum(i) / n;
        ((sq / n - mean * mean) * (n / (n - 1.0))).max(DVec3::ZERO).as_vec3()
    }

    /// Variance of the pixel's mean estimate (sample variance / n).
    pub fn variance_of_mean(&self, i: usize) -> Vec3 {
        self.sample_variance(i) / self.count(i).max(1) as f32
    }

    /// The image: each pixel's mean as linear RGB, row-major, three floats a pixel.
    pub fn to_rgb32f(&self) -> Vec<f32> {
        (0..self.pixel_count()).flat_map(|i| self.mean(i).to_array()).collect()
    }

    /// The variance of each pixel's mean, per channel (row-major, three floats a pixel).
    pub fn variance(&self) -> Vec<f32> {
        (0..self.pixel_count()).flat_map(|i| self.variance_of_mean(i).to_array()).collect()
    }

    /// Samples accumulated in each pixel (row-major).
    pub fn counts(&self) -> Vec<u32> {
        (0..self.pixel_count()).map(|i| self.count(i)).collect()
    }

    /// Samples per pixel taken (accumulated or dropped): the same for every pixel, or on an
    /// adaptive film the most any pixel took (those still sampling).
    pub fn samples(&self) -> u32 {
        let taken = (0..self.pixel_count()).map(|i| self.taken(i));
        if self.is_adaptive() { taken.max() } else { taken.min() }.unwrap_or(0)
    }

    pub fn nonfinite_samples(&self) -> u64 {
        (0..self.pixel_count()).map(|i| self.nonfinite(i) as u64).sum()
    }

    /// Adds a film covering the window at (x, y) of this one, exactly; refuses a window
    /// outside this film.
    pub fn merge_at(&mut self, other: &Film, x: u32, y: u32) -> Result<(), String> {
        if self.is_adaptive() || other.is_adaptive() {
            return Err("films of adaptive renders do not merge (each pixel stopped on its own)".into());
        }
        if self.layout != other.layout {
            return Err("a film with AOVs does not merge with one without".into());
        }
        let tile = crate::tile::Tile { x, y, width: other.width, height: other.height };
        if !tile.fits(self.width, self.height) || other.data.len() != other.layout.words(other.pixel_count()) {
            return Err(format!(
                "a {}x{} film at {x},{y} does not fit in the {}x{} image",
                other.width, other.height, self.width, self.height
            ));
        }
        for oy in 0..other.height {
            for ox in 0..other.width {
                let src = other.px((oy * other.width + ox) as usize).to_vec();
                let i = ((y + oy) * self.width + x + ox) as usize;
                let p = &mut self.data[i * WORDS_PER_PIXEL..(i + 1) * WORDS_PER_PIXEL];
                for c in 0..3 {
                    let (lo, carry) = p[4 + c].overflowing_add(src[4 + c]);
                    p[4 + c] = lo;
                    p[c] = p[c].wrapping_add(src[c]).wrapping_add(carry as u32);
                    p[8 + c] = (f32::from_bits(p[8 + c]) + f32::from_bits(src[8 + c])).to_bits();
                }
                p[3] = p[3].wrapping_add(src[3]);
                p[7] = p[7].wrapping_add(src[7]);
                if self.layout.aovs {
                    let src = other.aov_words((oy * other.width + ox) as usize).to_vec();
                    let at = self.aov_record(i);
                    let dst = &mut self.data[at..at + AOV_WORDS];
                    // Seven fixed-point sums (high, low words) and a count (src/aov.rs).
                    for (hi, lo) in [(0, 4), (1, 5), (2, 6), (3, 7), (8, 12), (9, 13), (10, 14)] {
                        let (sum, carry) = dst[lo].overflowing_add(src[lo]);
                        dst[lo] = sum;
                        dst[hi] = dst[hi].wrapping_add(src[hi]).wrapping_add(carry as u32);
                    }
                    dst[11] = dst[11].wrapping_add(src[11]);
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_point_is_exact_and_merges_associatively() {
        for x in [0.0f32, 1.0, 0.5, 17.25, 1e-3, 123456.78, 3.0e9] {
            let (hi, lo) = to_fixed(x);
            let back = hi as f64 + lo as f64 / 4294967296.0;
            let expect = x.min(MAX_SAMPLE) as f64;
            assert!((back - expect).abs() <= 2.4e-10, "{x}: {back}");
        }
        let samples: Vec<Vec3> = (0..64)
            .map(|k| Vec3::new(k as f32 * 0.37 + 0.001, (k as f32).sin().abs() * 9.0, 1e-4 * k as f32))
            .collect();
        let mut whole = Film::new(1, 1);
        samples.iter().for_each(|s| whole.add_sample(0, *s));
        let (mut a, mut b) = (Film::new(1, 1), Film::new(1, 1));
        samples[..23].iter().for_each(|s| a.add_sample(0, *s));
        samples[23..].iter().for_each(|s| b.add_sample(0, *s));
        b.merge_at(&a, 0, 0).unwrap();
        assert_eq!(whole.data[..8], b.data[..8], "sums and counts merge bit-exactly in any order");
        assert_eq!(whole.count(0), 64);
        let mean: Vec3 = samples.iter().sum::<Vec3>() / 64.0;
        assert!((whole.mean(0) - mean).abs().max_element() < 1e-5);
    }

    #[test]
    fn fixed_point_words_are_the_kernels_floor_split() {
        // `to_fixed` truncates where the kernel (film.wgsl) floors: the same words for every
        // value a sample can take, edges of f32's integer range included.
        let floored = |x: f32| {
            let c = x.clamp(0.0, MAX_SAMPLE);
            let hi = c.floor();
            (hi as u32, ((c - hi) * 4294967296.0) as u32)
        };
        let mut values = vec![0.0f32, -0.0, -1.5, 0.5, 1.0, 8388607.5, 8388608.0, 16777217.0, MAX_SAMPLE, 3.0e9];
        values.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MIN_POSITIVE, 1.0 - f32::EPSILON / 2.0]);
        let mut bits = 0x3f80_0000u32;
        for _ in 0..20_000 {
            // Values spread over many binades (a fixed LCG over the bit patterns).
            bits = bits.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            values.push(f32::from_bits(bits & 0x4fff_ffff));
        }
        for x in values {
            assert_eq!(to_fixed(x), floored(x), "{x:e}");
        }
    }

    #[test]
    fn non_finite_samples_are_dropped_and_counted() {
        let mut f = Film::new(2, 1);
        f.add_sample(1, Vec3::new(f32::NAN, 0.0, 0.0));
        f.add_sample(1, Vec3::new(1.0, f32::INFINITY, 0.0));
        f.add_sample(1, Vec3::ONE);
        assert_eq!((f.count(1), f.nonfinite(1), f.nonfinite_samples()), (1, 2, 2));
        assert_eq!(f.mean(1), Vec3::ONE);
    }
}
