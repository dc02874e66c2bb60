// The GGX (Trowbridge–Reitz) microfacet distribution with height-correlated Smith masking,
// sampled through its visible normals (Heitz 2018). Local frame, normal = +z.
// Twin: src/cpu/microfacet.rs.
#include "common.wgsl"

// Below this α a GGX lobe is a Dirac lobe (mirror, smooth glass).
const DELTA_ALPHA: f32 = 1e-4;

// D(h) = α² / (π (cos²θ (α² − 1) + 1)²), with the denominator written as α² cos²θ + sin²θ:
// the textbook form cancels to 0 when α² is below f32's epsilon (roughness < 0.016), making
// D infinite and the sample NaN.
fn ggx_d(h: vec3<f32>, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = a2 * h.z * h.z + (h.x * h.x + h.y * h.y);
    return a2 / (PI * d * d);
}

// Smith's Λ for GGX: G1 = 1 / (1 + Λ).
fn ggx_lambda(w: vec3<f32>, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    if (c2 <= 0.0) {
        return INF;
    }
    let t2 = max(1.0 - c2, 0.0) / c2;
    return 0.5 * (sqrt(1.0 + alpha * alpha * t2) - 1.0);
}

fn ggx_g1(w: vec3<f32>, alpha: f32) -> f32 {
    return 1.0 / (1.0 + ggx_lambda(w, alpha));
}

// Height-correlated masking-shadowing.
fn ggx_g2(wo: vec3<f32>, wi: vec3<f32>, alpha: f32) -> f32 {
    return 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}

// A microfacet normal drawn with density D_wo(h) = G1(wo)·max(0, wo·h)·D(h) / wo.z.
fn ggx_sample_vndf(wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(-vh.y, vh.x, 0.0) * inverseSqrt(len2), len2 > 0.0);
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sin(phi);
    let nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3<f32>(alpha * nh.x, alpha * nh.y, max(1e-7, nh.z)));
}

// Solid-angle density of the reflected direction wi when h is drawn by ggx_sample_vndf.
fn ggx_reflection_pdf(wo: vec3<f32>, h: vec3<f32>, alpha: f32) -> f32 {
    return ggx_g1(wo, alpha) * ggx_d(h, alpha) / (4.0 * wo.z);
}

// Anisotropic GGX (KHR_materials_anisotropy): α along x and y of a frame whose x is the
// anisotropy direction. Beside the isotropic functions so that those stay bit for bit.
fn ggx_d_aniso(h: vec3<f32>, ax: f32, ay: f32) -> f32 {
    let x = h.x / ax;
    let y = h.y / ay;
    let d = x * x + y * y + h.z * h.z;
    return 1.0 / (PI * ax * ay * d * d);
}

fn ggx_lambda_aniso(w: vec3<f32>, ax: f32, ay: f32) -> f32 {
    let c2 = w.z * w.z;
    if (c2 <= 0.0) {
        return INF;
    }
    let t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / c2;
    return 0.5 * (sqrt(1.0 + t2) - 1.0);
}

fn ggx_g1_aniso(w: vec3<f32>, ax: f32, ay: f32) -> f32 {
    return 1.0 / (1.0 + ggx_lambda_aniso(w, ax, ay));
}

fn ggx_g2_aniso(wo: vec3<f32>, wi: vec3<f32>, ax: f32, ay: f32) -> f32 {
    return 1.0 / (1.0 + ggx_lambda_aniso(wo, ax, ay) + ggx_lambda_aniso(wi, ax, ay));
}

fn ggx_sample_vndf_aniso(wo: vec3<f32>, ax: f32, ay: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(ax * wo.x, ay * wo.y, wo.z));
    let len2 = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if (len2 > 0.0) {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) * inverseSqrt(len2);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sin(phi);
    let nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3<f32>(ax * nh.x, ay * nh.y, max(nh.z, 1e-7)));
}

fn ggx_reflection_pdf_aniso(wo: vec3<f32>, h: vec3<f32>, ax: f32, ay: f32) -> f32 {
    return ggx_g1_aniso(wo, ax, ay) * ggx_d_aniso(h, ax, ay) / (4.0 * wo.z);
}
