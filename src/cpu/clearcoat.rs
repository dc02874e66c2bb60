//! Twin of `shaders/clearcoat.wgsl`: KHR_materials_clearcoat's coat, a GGX dielectric
//! interface (ior 1.5, F0 = 0.04) with its own roughness and normal, mixed over the material
//! under it by the coat's strength times its Fresnel reflectance toward the viewer, as the
//! extension's `fresnel_coat` specifies. Directions are in the base's local shading frame; the
//! coat's normal `coat_normal` is in that frame too.

use super::frame::{frame_from_normal, from_local, to_local};
use super::microfacet::{DELTA_ALPHA, ggx_d, ggx_g2, ggx_reflection_pdf, ggx_sample_vndf};
use crate::packed::Material;
use glam::{Vec2, Vec3};

/// Normal-incidence reflectance of the coat: ((1.5 − 1)/(1.5 + 1))².
pub const CLEARCOAT_F0: f32 = 0.04;

pub fn schlick_scalar(f0: f32, cos_theta: f32) -> f32 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (1.0 - f0) * (m2 * m2 * m)
}

/// The coat's share of the mix seen from wo: strength × Schlick(F0, n_c · wo). The layers under
/// it get 1 − this. Zero when wo is behind the coat's normal.
pub fn coat_weight(m: &Material, wo: Vec3) -> f32 {
    let c = Vec3::from(m.coat_normal).dot(wo);
    if m.clearcoat <= 0.0 || c <= 0.0 {
        return 0.0;
    }
    m.clearcoat * schlick_scalar(CLEARCOAT_F0, c)
}

pub fn coat_alpha(m: &Material) -> f32 {
    m.clearcoat_roughness * m.clearcoat_roughness
}

/// The coat's specular BRDF D·G2/(4 (n_c·wo)(n_c·wi)), times (n_c·wi)/(n·wi): the integrator
/// multiplies by the base's cosine, and the coat scatters by its own. Without Fresnel: the
/// mix weight carries it. Dirac coats (α < DELTA_ALPHA) evaluate to 0.
pub fn coat_eval(m: &Material, wo: Vec3, wi: Vec3) -> f32 {
    let alpha = coat_alpha(m);
    match coat_directions(m, wo, wi) {
        Some((o, i)) => ggx_d((o + i).normalize(), alpha) * ggx_g2(o, i, alpha) / (4.0 * o.z * wi.z),
        None => 0.0,
    }
}

/// Solid-angle density of `coat_sample` (visible normals of the coat's GGX).
pub fn coat_pdf(m: &Material, wo: Vec3, wi: Vec3) -> f32 {
    match coat_directions(m, wo, wi) {
        Some((o, i)) => ggx_reflection_pdf(o, (o + i).normalize(), coat_alpha(m)),
        None => 0.0,
    }
}

/// wo and wi in the coat's frame, when the coat is rough and both are above it and the base.
pub fn coat_directions(m: &Material, wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
    if coat_alpha(m) < DELTA_ALPHA || wi.z <= 0.0 {
        return None;
    }
    let frame = frame_from_normal(Vec3::from(m.coat_normal));
    let (o, i) = (to_local(&frame, wo), to_local(&frame, wi));
    (o.z > 0.0 && i.z > 0.0).then_some((o, i))
}

/// A direction reflected by the coat: its mirror direction when it is a Dirac coat, else a
/// reflection about a visible GGX normal. (0, 0, 0) when it falls below either horizon.
pub fn coat_sample(m: &Material, wo: Vec3, u: Vec2) -> Vec3 {
    let nc = Vec3::from(m.coat_normal);
    let alpha = coat_alpha(m);
    let wi = if alpha < DELTA_ALPHA {
        2.0 * wo.dot(nc) * nc - wo
    } else {
        let frame = frame_from_normal(nc);
        let o = to_local(&frame, wo);
        if o.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = ggx_sample_vndf(o, alpha, u);
        from_local(&frame, 2.0 * o.dot(h) * h - o)
    };
    if wi.z <= 0.0 || wi.dot(nc) <= 0.0 { Vec3::ZERO } else { wi }
}
