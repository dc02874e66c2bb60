// KHR_materials_clearcoat's coat: a GGX dielectric interface (ior 1.5, F0 = 0.04) with its
// own roughness and normal, mixed over the material under it by the coat's strength times
// its Fresnel reflectance toward the viewer (the extension's fresnel_coat). Directions are
// in the base's local shading frame, and so is the coat's normal m.coat_normal.
// Twin: src/cpu/clearcoat.rs.
#include "common.wgsl"
#include "frame.wgsl"
#include "microfacet.wgsl"

const CLEARCOAT_F0: f32 = 0.04;

fn schlick_scalar(f0: f32, cos_theta: f32) -> f32 {
    let m = clamp(1.0 - cos_theta, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (1.0 - f0) * (m2 * m2 * m);
}

// The coat's share of the mix seen from wo; the layers under it get 1 − this.
fn coat_weight(m: Material, wo: vec3<f32>) -> f32 {
    let c = dot(m.coat_normal, wo);
    if (!CLEARCOAT || m.clearcoat <= 0.0 || c <= 0.0) {
        return 0.0;
    }
    return m.clearcoat * schlick_scalar(CLEARCOAT_F0, c);
}

fn coat_alpha(m: Material) -> f32 {
    return m.clearcoat_roughness * m.clearcoat_roughness;
}

// D·G2/(4 (n_c·wo)(n_c·wi)) × (n_c·wi)/(n·wi): the integrator multiplies by the base's
// cosine, the coat scatters by its own. Fresnel is in the mix weight; Dirac coats give 0.
fn coat_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let d = coat_directions(m, wo, wi);
    if (!d.found) {
        return 0.0;
    }
    let alpha = coat_alpha(m);
    return ggx_d(normalize(d.o + d.i), alpha) * ggx_g2(d.o, d.i, alpha) / (4.0 * d.o.z * wi.z);
}

fn coat_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let d = coat_directions(m, wo, wi);
    if (!d.found) {
        return 0.0;
    }
    return ggx_reflection_pdf(d.o, normalize(d.o + d.i), coat_alpha(m));
}

struct CoatDirections {
    o: vec3<f32>,
    i: vec3<f32>,
    found: bool,
}

// wo and wi in the coat's frame, when the coat is rough and both are above it and the base.
fn coat_directions(m: Material, wo: vec3<f32>, wi: vec3<f32>) -> CoatDirections {
    let none = CoatDirections(vec3<f32>(0.0), vec3<f32>(0.0), false);
    if (coat_alpha(m) < DELTA_ALPHA || wi.z <= 0.0) {
        return none;
    }
    let frame = frame_from_normal(m.coat_normal);
    let o = to_local(frame, wo);
    let i = to_local(frame, wi);
    if (o.z <= 0.0 || i.z <= 0.0) {
        return none;
    }
    return CoatDirections(o, i, true);
}

// The mirror direction of a Dirac coat, else a reflection about a visible GGX normal;
// (0, 0, 0) below either horizon.
fn coat_sample(m: Material, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let nc = m.coat_normal;
    let alpha = coat_alpha(m);
    var wi: vec3<f32>;
    if (alpha < DELTA_ALPHA) {
        wi = 2.0 * dot(wo, nc) * nc - wo;
    } else {
        let frame = frame_from_normal(nc);
        let o = to_local(frame, wo);
        if (o.z <= 0.0) {
            return vec3<f32>(0.0);
        }
        let h = ggx_sample_vndf(o, alpha, u);
        wi = from_local(frame, 2.0 * dot(o, h) * h - o);
    }
    if (wi.z <= 0.0 || dot(wi, nc) <= 0.0) {
        return vec3<f32>(0.0);
    }
    return wi;
}
