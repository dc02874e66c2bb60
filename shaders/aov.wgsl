// AOVs of the first visible surface (albedo, shading normal, camera distance), accumulated
// beside the radiance as Open Image Denoise's auxiliary images. The definitions and the word
// layout are in the twin, src/aov.rs: four rows a pixel from params.aov_base,
// (albedo hi, depth hi), (albedo lo, depth lo), ((normal + 1) hi, surfaces hit),
// ((normal + 1) lo, 0).
#include "bindings.wgsl"
#include "film.wgsl"


struct AovSample {
    albedo: vec3<f32>,
    normal: vec3<f32>,
    // Camera distance of the first hit; negative when the camera ray left the scene.
    depth: f32,
}

fn aov_none() -> AovSample {
    return AovSample(vec3<f32>(0.0), vec3<f32>(0.0), -1.0);
}

// Adds v (≥ 0; non-finite counts 0) to the fixed-point sums of rows `hi` and `hi + 1`.
fn aov_add_fixed(hi: u32, v: vec4<f32>, add_w: bool) {
    let finite = vec4<bool>(is_finite_f32(v.x), is_finite_f32(v.y), is_finite_f32(v.z), is_finite_f32(v.w));
    let c = clamp(select(vec4<f32>(0.0), v, finite), vec4<f32>(0.0), vec4<f32>(MAX_SAMPLE));
    let whole = floor(c);
    let add_hi = vec4<u32>(whole);
    let add_lo = vec4<u32>((c - whole) * 4294967296.0);
    let mask = vec4<u32>(1u, 1u, 1u, select(0u, 1u, add_w));
    let sum_lo = film[hi + 1u];
    let lo = sum_lo + add_lo * mask;
    let carry = select(vec4<u32>(0u), vec4<u32>(1u), lo < sum_lo);
    film[hi] = film[hi] + add_hi * mask + carry;
    film[hi + 1u] = lo;
}

fn aov_add_sample(slot: u32, a: AovSample) {
    let base = params.aov_base + AOV_ROWS * slot;
    let hit = a.depth >= 0.0;
    aov_add_fixed(base, vec4<f32>(a.albedo, max(a.depth, 0.0)), hit);
    aov_add_fixed(base + 2u, vec4<f32>(a.normal + 1.0, 0.0), false);
    if (hit) {
        film[base + 2u].w += 1u;
    }
}
