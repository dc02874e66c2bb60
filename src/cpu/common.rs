//! Twin of `shaders/common.wgsl`: the ray, the constants and the small helpers every other
//! twin uses, defined once here so that the twins import them from where they are defined
//! (and no two of them import each other).

use glam::Vec3;

pub use crate::packed::luminance;
pub use crate::packed::oct_decode;

pub const INF: f32 = 3.4e38;

/// The largest f32 below 1: rescaled numbers stay in [0, 1).
pub const ONE_MINUS_EPSILON: f32 = 0.99999994;

#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}
