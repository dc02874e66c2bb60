// The environment: a constant radiance, or an equirectangular map importance-sampled in
// proportion to luminance × sin θ with marginal (rows) and conditional (within a row) CDFs,
// piecewise constant over texels. Twin: src/cpu/environment.rs.
#include "bindings.wgsl"
#include "sampling.wgsl"

// Map coordinates (u, v) ∈ [0,1)² → direction: θ = π v from +Y, φ = 2π (u − ½) from −Z.
fn env_direction(uv: vec2<f32>) -> vec3<f32> {
    let phi = 2.0 * PI * (uv.x - 0.5);
    let theta = PI * uv.y;
    let s = sin(theta);
    return vec3<f32>(s * sin(phi), cos(theta), -s * cos(phi));
}

fn env_uv(dir: vec3<f32>) -> vec2<f32> {
    let phi = atan2(dir.x, -dir.z);
    let theta = acos(clamp(dir.y, -1.0, 1.0));
    return vec2<f32>(phi * (0.5 * INV_PI) + 0.5, theta * INV_PI);
}

fn env_texel_index(uv: vec2<f32>) -> u32 {
    let w = params.env_width;
    let h = params.env_height;
    let j = min(u32(max(uv.x, 0.0) * f32(w)), w - 1u);
    let i = min(u32(max(uv.y, 0.0) * f32(h)), h - 1u);
    return i * w + j;
}

fn environment_radiance(dir: vec3<f32>) -> vec3<f32> {
    if (params.env_width == 0u) {
        return params.environment;
    }
    return light_data[env_texel_index(env_uv(dir))].xyz * params.environment;
}

// Solid-angle density with which light sampling produces direction `dir` from the environment.
fn environment_pdf(dir: vec3<f32>) -> f32 {
    if (params.env_width == 0u) {
        return params.env_select * UNIFORM_SPHERE_PDF;
    }
    let w = params.env_width;
    let h = params.env_height;
    let index = env_texel_index(env_uv(dir));
    let i = index / w;
    let sin_centre = sin(PI * (f32(i) + 0.5) / f32(h));
    let func = luminance(light_data[index].xyz) * sin_centre;
    let sin_dir = length(dir.xz);
    if (sin_dir <= 0.0 || params.env_total <= 0.0) {
        return 0.0;
    }
    let pdf_uv = func / params.env_total * f32(w * h);
    return params.env_select * pdf_uv / (2.0 * PI * PI * sin_dir);
}

// Inverts a piecewise-constant CDF stored in light_data[base .. base + n] (the marginal CDF in
// .x, a row's conditional CDF in .w): the first entry above u, and u's place inside it.
fn env_sample_cdf(base: u32, n: u32, u: f32, marginal: bool) -> vec2<f32> {
    var lo = 0u;
    var hi = n - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        let t = light_data[base + mid];
        if (select(t.w, t.x, marginal) > u) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    let before = light_data[base + max(lo, 1u) - 1u];
    let c0 = select(0.0, select(before.w, before.x, marginal), lo > 0u);
    let t = light_data[base + lo];
    let c1 = select(t.w, t.x, marginal);
    return vec2<f32>(f32(lo), clamp((u - c0) / max(c1 - c0, 1e-30), 0.0, 0.99999));
}

// A direction drawn with density ∝ environment_pdf: a row from the marginal CDF, then a
// column from that row's conditional CDF, then uniformly inside the texel.
fn sample_environment(u: vec2<f32>) -> vec3<f32> {
    if (params.env_width == 0u) {
        return sample_uniform_sphere(u);
    }
    let w = params.env_width;
    let h = params.env_height;
    let row = env_sample_cdf(w * h, h, u.x, true);
    let column = env_sample_cdf(u32(row.x) * w, w, u.y, false);
    return env_direction(vec2<f32>((column.x + column.y) / f32(w), (row.x + row.y) / f32(h)));
}
