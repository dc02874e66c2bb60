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

fn sample_uniform_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(max(0.0, 1.0 - u.x * u.x));
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), u.x);
}

const UNIFORM_HEMISPHERE_PDF: f32 = 0.15915494309189535;

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

// A sample of the linear density on [0, 1] from `a` at 0 to `b` at 1.
fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if (u == 0.0 && a == 0.0) {
        return 0.0;
    }
    let x = u * (a + b) / (a + sqrt((1.0 - u) * a * a + u * b * b));
    return min(x, ONE_MINUS_EPSILON);
}

// A sample of the bilinear density on the unit square with corner weights w at (0, 0),
// (1, 0), (0, 1), (1, 1): y from the marginal, then x from the conditional.
fn sample_bilinear(u: vec2<f32>, w: vec4<f32>) -> vec2<f32> {
    let y = sample_linear(u.y, w.x + w.y, w.z + w.w);
    let x = sample_linear(u.x, (1.0 - y) * w.x + y * w.z, (1.0 - y) * w.y + y * w.w);
    return vec2<f32>(x, y);
}

fn bilinear_pdf(p: vec2<f32>, w: vec4<f32>) -> f32 {
    if (p.x < 0.0 || p.x > 1.0 || p.y < 0.0 || p.y > 1.0) {
        return 0.0;
    }
    let sum = w.x + w.y + w.z + w.w;
    if (sum == 0.0) {
        return 1.0;
    }
    let x = p.x;
    let y = p.y;
    return 4.0 * ((1.0 - x) * (1.0 - y) * w.x + x * (1.0 - y) * w.y + (1.0 - x) * y * w.z + x * y * w.w) / sum;
}
