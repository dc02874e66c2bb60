// glTF's metallic-roughness material as a path tracer reads it: a GGX specular lobe
// (α = roughness²) whose Fresnel term blends the dielectric F0 (KHR_materials_specular/_ior)
// and the base color by metallic, over a Lambertian lobe for the non-metal part weighted by
// 1 − F so energy is conserved. α below DELTA_ALPHA is a perfect mirror (a Dirac lobe).
// Everything in the local shading frame (normal = +z, wo.z > 0); eval, pdf and sample agree.
// Twin: src/cpu/bsdf.rs.
#include "common.wgsl"
#include "sampling.wgsl"
#include "microfacet.wgsl"

const DELTA_ALPHA: f32 = 1e-4;

struct BsdfSample {
    wi: vec3<f32>,
    // f · |cos θi| / pdf
    weight: vec3<f32>,
    pdf: f32,
    // Drawn from a Dirac lobe: light sampling cannot find it, so no MIS.
    delta: bool,
}

fn fresnel_schlick(f0: vec3<f32>, f90: vec3<f32>, cos_theta: f32) -> vec3<f32> {
    let m = clamp(1.0 - cos_theta, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (f90 - f0) * (m2 * m2 * m);
}

fn bsdf_fresnel(m: Material, cos_theta: f32) -> vec3<f32> {
    let dielectric = fresnel_schlick(m.dielectric_f0, vec3<f32>(m.dielectric_f90), cos_theta);
    let metal = fresnel_schlick(m.base_color, vec3<f32>(1.0), cos_theta);
    return mix(dielectric, metal, m.metallic);
}

// Albedo of the Lambertian lobe seen from wo.
fn diffuse_albedo(m: Material, cos_o: f32) -> vec3<f32> {
    let f = fresnel_schlick(m.dielectric_f0, vec3<f32>(m.dielectric_f90), cos_o);
    return (1.0 - m.metallic) * m.base_color * (vec3<f32>(1.0) - f);
}

// Probability of sampling the specular lobe, from the lobes' estimated albedos.
fn specular_probability(m: Material, cos_o: f32) -> f32 {
    let ws = luminance(bsdf_fresnel(m, cos_o));
    let wd = luminance(diffuse_albedo(m, cos_o));
    if (ws + wd <= 0.0) {
        return 0.0;
    }
    return ws / (ws + wd);
}

// f(wo, wi) without the cosine; the Dirac lobe is not included.
fn bsdf_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    var f = diffuse_albedo(m, wo.z) * INV_PI;
    let alpha = m.roughness * m.roughness;
    if (alpha >= DELTA_ALPHA) {
        let h = normalize(wo + wi);
        let spec = ggx_d(h, alpha) * ggx_g2(wo, wi, alpha) / (4.0 * wo.z * wi.z);
        f += bsdf_fresnel(m, dot(wo, h)) * spec;
    }
    return f;
}

fn bsdf_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let ps = specular_probability(m, wo.z);
    var pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi.z);
    let alpha = m.roughness * m.roughness;
    if (alpha >= DELTA_ALPHA && ps > 0.0) {
        pdf += ps * ggx_reflection_pdf(wo, normalize(wo + wi), alpha);
    }
    return pdf;
}

fn bsdf_sample(m: Material, wo: vec3<f32>, u: vec3<f32>) -> BsdfSample {
    let none = BsdfSample(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0), 0.0, false);
    if (wo.z <= 0.0) {
        return none;
    }
    let ps = specular_probability(m, wo.z);
    let alpha = m.roughness * m.roughness;
    var wi: vec3<f32>;
    if (u.x < ps) {
        if (alpha < DELTA_ALPHA) {
            let mirror = vec3<f32>(-wo.x, -wo.y, wo.z);
            return BsdfSample(mirror, bsdf_fresnel(m, wo.z) / ps, ps, true);
        }
        let h = ggx_sample_vndf(wo, alpha, u.yz);
        wi = 2.0 * dot(wo, h) * h - wo;
    } else {
        wi = sample_cosine_hemisphere(u.yz);
    }
    let pdf = bsdf_pdf(m, wo, wi);
    if (wi.z <= 0.0 || pdf <= 0.0) {
        return none;
    }
    return BsdfSample(wi, bsdf_eval(m, wo, wi) * (wi.z / pdf), pdf, false);
}
