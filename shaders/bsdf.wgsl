// BSDFs in the local shading frame (normal = +z, wo.z > 0). Each provides eval, pdf and
// sample, which agree with each other. Twin: src/cpu/bsdf.rs.
#include "common.wgsl"
#include "sampling.wgsl"

struct BsdfSample {
    wi: vec3<f32>,
    // f · |cos θi| / pdf
    weight: vec3<f32>,
    pdf: f32,
    // A Dirac lobe: no light sampling can find it, so no MIS.
    delta: bool,
}

// f(wo, wi), without the cosine.
fn bsdf_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return m.base_color * INV_PI;
}

fn bsdf_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    return cosine_hemisphere_pdf(wi.z);
}

fn bsdf_sample(m: Material, wo: vec3<f32>, u: vec3<f32>) -> BsdfSample {
    let wi = sample_cosine_hemisphere(u.yz);
    let pdf = cosine_hemisphere_pdf(wi.z);
    if (wo.z <= 0.0 || pdf <= 0.0) {
        return BsdfSample(wi, vec3<f32>(0.0), 0.0, false);
    }
    return BsdfSample(wi, m.base_color, pdf, false);
}
