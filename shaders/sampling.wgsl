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

fn sample_uniform_sphere(u: vec2<f32>) -> vec3<f32> {
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), z);
}

const UNIFORM_SPHERE_PDF: f32 = 0.07957747154594767;

// Uniform point on the unit disk.
fn sample_uniform_disk(u: vec2<f32>) -> vec2<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec2<f32>(r * cos(phi), r * sin(phi));
}

// Uniform point on a triangle as barycentrics (b1, b2) of vertices 1 and 2.
fn sample_uniform_triangle(u: vec2<f32>) -> vec2<f32> {
    let su = sqrt(u.x);
    return vec2<f32>(1.0 - su, u.y * su);
}
