//! Twin of `shaders/microfacet.wgsl`: GGX with height-correlated Smith masking and VNDF sampling.

use super::common::INF;
use super::trig::turn;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Below this α a GGX lobe is a Dirac lobe (mirror, smooth glass).
pub const DELTA_ALPHA: f32 = 1e-4;

/// D(h) = α² / (π (cos²θ (α² − 1) + 1)²), with the denominator written as α² cos²θ + sin²θ:
/// the textbook form cancels to 0 when α² is below f32's epsilon (roughness < 0.016), making
/// D infinite and the sample NaN.
pub fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = a2 * h.z * h.z + (h.x * h.x + h.y * h.y);
    a2 / (PI * d * d)
}

pub fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return INF;
    }
    let t2 = (1.0 - c2).max(0.0) / c2;
    0.5 * ((1.0 + alpha * alpha * t2).sqrt() - 1.0)
}

pub fn ggx_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

pub fn ggx_g2(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha))
}

pub fn ggx_sample_vndf(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let (cos_phi, sin_phi) = turn(u.y);
    let p1 = r * cos_phi;
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin_phi;
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-7)).normalize()
}

pub fn ggx_reflection_pdf(wo: Vec3, h: Vec3, alpha: f32) -> f32 {
    ggx_g1(wo, alpha) * ggx_d(h, alpha) / (4.0 * wo.z)
}

// Anisotropic GGX (KHR_materials_anisotropy): α along x and y of a frame whose x is the
// anisotropy direction. Kept beside the isotropic functions rather than replacing them: the
// isotropic arithmetic stays bit for bit what the films were made with.

pub fn ggx_d_aniso(h: Vec3, ax: f32, ay: f32) -> f32 {
    let (x, y) = (h.x / ax, h.y / ay);
    let d = x * x + y * y + h.z * h.z;
    1.0 / (PI * ax * ay * d * d)
}

pub fn ggx_lambda_aniso(w: Vec3, ax: f32, ay: f32) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return INF;
    }
    let t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / c2;
    0.5 * ((1.0 + t2).sqrt() - 1.0)
}

pub fn ggx_g1_aniso(w: Vec3, ax: f32, ay: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda_aniso(w, ax, ay))
}

pub fn ggx_g2_aniso(wo: Vec3, wi: Vec3, ax: f32, ay: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda_aniso(wo, ax, ay) + ggx_lambda_aniso(wi, ax, ay))
}

pub fn ggx_sample_vndf_aniso(wo: Vec3, ax: f32, ay: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(ax * wo.x, ay * wo.y, wo.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let (cos_phi, sin_phi) = turn(u.y);
    let p1 = r * cos_phi;
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin_phi;
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    Vec3::new(ax * nh.x, ay * nh.y, nh.z.max(1e-7)).normalize()
}

pub fn ggx_reflection_pdf_aniso(wo: Vec3, h: Vec3, ax: f32, ay: f32) -> f32 {
    ggx_g1_aniso(wo, ax, ay) * ggx_d_aniso(h, ax, ay) / (4.0 * wo.z)
}
