//! Twin of `shaders/bsdf.wgsl`.

use super::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::packed::PackedMaterial;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
    pub delta: bool,
}

pub fn bsdf_eval(m: &PackedMaterial, wo: Vec3, wi: Vec3) -> Vec3 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return Vec3::ZERO;
    }
    Vec3::from(m.base_color) * FRAC_1_PI
}

pub fn bsdf_pdf(_m: &PackedMaterial, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    cosine_hemisphere_pdf(wi.z)
}

pub fn bsdf_sample(m: &PackedMaterial, wo: Vec3, u: Vec3) -> BsdfSample {
    let wi = sample_cosine_hemisphere(Vec2::new(u.y, u.z));
    let pdf = cosine_hemisphere_pdf(wi.z);
    if wo.z <= 0.0 || pdf <= 0.0 {
        return BsdfSample { wi, weight: Vec3::ZERO, pdf: 0.0, delta: false };
    }
    BsdfSample { wi, weight: m.base_color.into(), pdf, delta: false }
}
