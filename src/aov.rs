//! AOVs (arbitrary output variables) of the first visible surface, as Open Image Denoise
//! defines its auxiliary images: its albedo and shading normal, and its camera distance
//! (depth). Twin: `shaders/aov.wgsl`.
//!
//! The surface is the first one the camera ray hits, except that perfect mirrors and smooth
//! glass (materials whose every lobe is a Dirac one) are looked through: the path's own BSDF
//! sample continues to the next surface, and its weight (the Fresnel reflectance or
//! transmittance) multiplies that surface's albedo, so the pixel's mean is the Fresnel blend
//! of what is reflected and what is transmitted. The albedo is the material's directional
//! albedo seen from the ray, textures included (`bsdf_albedo`); the normal is the shading
//! normal (normal maps included), facing the ray, in world space. Depth is the distance along
//! the camera ray to its first hit, whatever the surface. A ray that leaves the scene adds an
//! albedo and a normal of 0 and no depth. AOVs take no random number of their own: a render
//! with AOVs accumulates the same radiance, bit for bit.
//!
//! Per pixel, `AOV_WORDS` words of 64-bit fixed-point sums (as the radiance's, so films merge
//! and resume exactly): `[albedo hi r, g, b, depth hi, albedo lo r, g, b, depth lo,
//! (normal + 1) hi x, y, z, surfaces hit, (normal + 1) lo x, y, z, 0]`. The normal is stored
//! biased by 1 so its sums stay non-negative.

use crate::film::{Film, to_fixed};
use glam::Vec3;

/// What one sample saw of the first visible surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AovSample {
    pub albedo: Vec3,
    pub normal: Vec3,
    /// Camera distance of the first hit; negative when the camera ray left the scene.
    pub depth: f32,
}

impl Default for AovSample {
    fn default() -> AovSample {
        AovSample { albedo: Vec3::ZERO, normal: Vec3::ZERO, depth: -1.0 }
    }
}

pub use crate::settings::Aov;

/// Adds `v` (finite, ≥ 0) to the fixed-point sum whose high word is `hi` and low word `lo`.
#[inline]
fn add_fixed(record: &mut [u32], hi: usize, lo: usize, v: f32) {
    let v = if v.is_finite() { v } else { 0.0 };
    let (h, l) = to_fixed(v);
    let (sum, carry) = record[lo].overflowing_add(l);
    record[lo] = sum;
    record[hi] = record[hi].wrapping_add(h).wrapping_add(carry as u32);
}

/// Adds one sample's AOVs to a pixel's record. Twin of `aov_add_sample`.
pub fn aov_add_sample(record: &mut [u32], a: &AovSample) {
    for c in 0..3 {
        add_fixed(record, c, 4 + c, a.albedo[c]);
        add_fixed(record, 8 + c, 12 + c, a.normal[c] + 1.0);
    }
    if a.depth >= 0.0 {
        add_fixed(record, 3, 7, a.depth);
        record[11] = record[11].wrapping_add(1);
    }
}

/// The (high, low) word pairs of the record's fixed-point sums; word 11 is a count.
pub const AOV_FIXED_PAIRS: [(usize, usize); 7] = [(0, 4), (1, 5), (2, 6), (3, 7), (8, 12), (9, 13), (10, 14)];

fn sum(record: &[u32], hi: usize, lo: usize) -> f64 {
    record[hi] as f64 + record[lo] as f64 * (1.0 / 4294967296.0)
}

/// The mean albedo of a pixel's `samples` samples.
pub fn aov_albedo(record: &[u32], samples: u32) -> Vec3 {
    let n = samples.max(1) as f64;
    Vec3::new((sum(record, 0, 4) / n) as f32, (sum(record, 1, 5) / n) as f32, (sum(record, 2, 6) / n) as f32)
}

/// The mean shading normal (not renormalised: OIDN wants the mean, in [−1, 1]).
pub fn aov_normal(record: &[u32], samples: u32) -> Vec3 {
    if samples == 0 {
        return Vec3::ZERO;
    }
    let n = samples as f64;
    let c = |hi, lo| ((sum(record, hi, lo) / n) - 1.0).clamp(-1.0, 1.0) as f32;
    Vec3::new(c(8, 12), c(9, 13), c(10, 14))
}

/// The mean camera distance of the samples that hit a surface (infinite when none did).
pub fn aov_depth(record: &[u32]) -> f32 {
    if record[11] == 0 { f32::INFINITY } else { (sum(record, 3, 7) / record[11] as f64) as f32 }
}

impl Film {
    /// An AOV image (row-major): three floats a pixel for the albedo and the normal, one for
    /// the depth; None when the film has no AOVs.
    pub fn aov_image(&self, aov: Aov) -> Option<Vec<f32>> {
        self.has_aovs().then(|| {
            let pixels = 0..self.pixel_count();
            match aov {
                Aov::Albedo => pixels.flat_map(|i| aov_albedo(self.aov_words(i), self.taken(i)).to_array()).collect(),
                Aov::Normal => pixels.flat_map(|i| aov_normal(self.aov_words(i), self.taken(i)).to_array()).collect(),
                Aov::Depth => pixels.map(|i| aov_depth(self.aov_words(i))).collect(),
            }
        })
    }
}
