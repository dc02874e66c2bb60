//! Twin of `shaders/sampling.wgsl`.

use super::common::ONE_MINUS_EPSILON;
use super::trig::turn;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let (cos_phi, sin_phi) = turn(u.y);
    Vec3::new(r * cos_phi, r * sin_phi, (1.0 - u.x).max(0.0).sqrt())
}

pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (cos_phi, sin_phi) = turn(u.y);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 0.079_577_47;

pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (cos_phi, sin_phi) = turn(u.y);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

/// 1 / 2π.
pub const UNIFORM_HEMISPHERE_PDF: f32 = 0.159_154_94;

pub fn sample_uniform_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let (cos_phi, sin_phi) = turn(u.y);
    Vec2::new(r * cos_phi, r * sin_phi)
}

pub fn sample_uniform_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(1.0 - su, u.y * su)
}

/// A sample of the linear density on [0, 1] that goes from `a` at 0 to `b` at 1.
pub fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + ((1.0 - u) * a * a + u * b * b).sqrt());
    x.min(ONE_MINUS_EPSILON)
}

/// A sample of the bilinear density on the unit square with corner weights `w` at (0, 0),
/// (1, 0), (0, 1), (1, 1): y from the marginal, then x from the conditional.
pub fn sample_bilinear(u: Vec2, w: [f32; 4]) -> Vec2 {
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(u.x, (1.0 - y) * w[0] + y * w[2], (1.0 - y) * w[1] + y * w[3]);
    Vec2::new(x, y)
}

/// The density of `sample_bilinear` at `p`.
pub fn bilinear_pdf(p: Vec2, w: [f32; 4]) -> f32 {
    if p.x < 0.0 || p.x > 1.0 || p.y < 0.0 || p.y > 1.0 {
        return 0.0;
    }
    let sum = w[0] + w[1] + w[2] + w[3];
    if sum == 0.0 {
        return 1.0;
    }
    let (x, y) = (p.x, p.y);
    4.0 * ((1.0 - x) * (1.0 - y) * w[0] + x * (1.0 - y) * w[1] + (1.0 - x) * y * w[2] + x * y * w[3]) / sum
}
