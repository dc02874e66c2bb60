// Warps from the unit square to the domains we sample. Twin: src/cpu/sampling.rs.
#include "common.wgsl"

// Cosine-weighted direction around +z (Malley's method on a uniform disk).
fn sample_cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    return max(cos_theta, 0.0) * INV_PI;
}

// Uniform point on a triangle as barycentrics (b1, b2) of vertices 1 and 2.
fn sample_uniform_triangle(u: vec2<f32>) -> vec2<f32> {
    let su = sqrt(u.x);
    return vec2<f32>(1.0 - su, u.y * su);
}
