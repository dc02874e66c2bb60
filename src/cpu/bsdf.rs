//! Twin of `shaders/bsdf.wgsl`: glTF metallic-roughness (GGX specular over Lambert).

use super::microfacet::{ggx_d, ggx_g2, ggx_reflection_pdf, ggx_sample_vndf};
use super::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::packed::{PackedMaterial, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

pub const DELTA_ALPHA: f32 = 1e-4;

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
    pub delta: bool,
}

pub fn fresnel_schlick(f0: Vec3, f90: Vec3, cos_theta: f32) -> Vec3 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (f90 - f0) * (m2 * m2 * m)
}

pub fn bsdf_fresnel(m: &PackedMaterial, cos_theta: f32) -> Vec3 {
    let dielectric = fresnel_schlick(m.dielectric_f0.into(), Vec3::splat(m.dielectric_f90), cos_theta);
    let metal = fresnel_schlick(m.base_color.into(), Vec3::ONE, cos_theta);
    dielectric.lerp(metal, m.metallic)
}

pub fn diffuse_albedo(m: &PackedMaterial, cos_o: f32) -> Vec3 {
    let f = fresnel_schlick(m.dielectric_f0.into(), Vec3::splat(m.dielectric_f90), cos_o);
    (1.0 - m.metallic) * Vec3::from(m.base_color) * (Vec3::ONE - f)
}

pub fn specular_probability(m: &PackedMaterial, cos_o: f32) -> f32 {
    let ws = luminance(bsdf_fresnel(m, cos_o));
    let wd = luminance(diffuse_albedo(m, cos_o));
    if ws + wd <= 0.0 {
        return 0.0;
    }
    ws / (ws + wd)
}

pub fn bsdf_eval(m: &PackedMaterial, wo: Vec3, wi: Vec3) -> Vec3 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return Vec3::ZERO;
    }
    let mut f = diffuse_albedo(m, wo.z) * FRAC_1_PI;
    let alpha = m.roughness * m.roughness;
    if alpha >= DELTA_ALPHA {
        let h = (wo + wi).normalize();
        let spec = ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
        f += bsdf_fresnel(m, wo.dot(h)) * spec;
    }
    f
}

pub fn bsdf_pdf(m: &PackedMaterial, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let ps = specular_probability(m, wo.z);
    let mut pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi.z);
    let alpha = m.roughness * m.roughness;
    if alpha >= DELTA_ALPHA && ps > 0.0 {
        pdf += ps * ggx_reflection_pdf(wo, (wo + wi).normalize(), alpha);
    }
    pdf
}

pub fn bsdf_sample(m: &PackedMaterial, wo: Vec3, u: Vec3) -> BsdfSample {
    let none = BsdfSample { wi: Vec3::Z, weight: Vec3::ZERO, pdf: 0.0, delta: false };
    if wo.z <= 0.0 {
        return none;
    }
    let ps = specular_probability(m, wo.z);
    let alpha = m.roughness * m.roughness;
    let wi = if u.x < ps {
        if alpha < DELTA_ALPHA {
            let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
            return BsdfSample { wi: mirror, weight: bsdf_fresnel(m, wo.z) / ps, pdf: ps, delta: true };
        }
        let h = ggx_sample_vndf(wo, alpha, Vec2::new(u.y, u.z));
        2.0 * wo.dot(h) * h - wo
    } else {
        sample_cosine_hemisphere(Vec2::new(u.y, u.z))
    };
    let pdf = bsdf_pdf(m, wo, wi);
    if wi.z <= 0.0 || pdf <= 0.0 {
        return none;
    }
    BsdfSample { wi, weight: bsdf_eval(m, wo, wi) * (wi.z / pdf), pdf, delta: false }
}
