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
    return env_texels[env_texel_index(env_uv(dir))].xyz * params.environment;
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
    let func = luminance(env_texels[index].xyz) * sin_centre;
    let sin_dir = length(dir.xz);
    if (sin_dir <= 0.0 || params.env_total <= 0.0) {
        return 0.0;
    }
    let pdf_uv = func / params.env_total * f32(w * h);
    return params.env_select * pdf_uv / (2.0 * PI * PI * sin_dir);
}

// A direction drawn with density ∝ environment_pdf.
fn sample_environment(u: vec2<f32>) -> vec3<f32> {
    if (params.env_width == 0u) {
        return sample_uniform_sphere(u);
    }
    let w = params.env_width;
    let h = params.env_height;
    // Row from the marginal CDF: the first row whose CDF exceeds u.x.
    let base = w * h;
    var lo = 0u;
    var hi = h - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (env_texels[base + mid].x > u.x) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    let i = lo;
    let r0 = select(0.0, env_texels[base + i - 1u].x, i > 0u);
    let r1 = env_texels[base + i].x;
    let dv = clamp((u.x - r0) / max(r1 - r0, 1e-30), 0.0, 0.99999);
    // Column from the row's conditional CDF.
    let row = i * w;
    lo = 0u;
    hi = w - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (env_texels[row + mid].w > u.y) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    let j = lo;
    let c0 = select(0.0, env_texels[row + j - 1u].w, j > 0u);
    let c1 = env_texels[row + j].w;
    let du = clamp((u.y - c0) / max(c1 - c0, 1e-30), 0.0, 0.99999);
    return env_direction(vec2<f32>((f32(j) + du) / f32(w), (f32(i) + dv) / f32(h)));
}
