// Lights: emissive triangles and the environment. Light sampling picks the environment with
// probability params.env_select, else a triangle in proportion to its power (area ×
// luminance) through an alias table, then a point uniformly on it; the area pdf becomes a
// solid-angle pdf r² / (|cos θ_light| · area). Triangles emit from their front face.
// Twin: src/cpu/lights.rs.
#include "bindings.wgsl"
#include "sampling.wgsl"
#include "environment.wgsl"

struct LightSample {
    // Unit direction from the shading point to the light.
    wi: vec3<f32>,
    // Distance to the light point; INF for the environment.
    dist: f32,
    point: vec3<f32>,
    // Unit geometric normal of the light (its emitting side).
    normal: vec3<f32>,
    radiance: vec3<f32>,
    // Solid-angle density at the shading point; 0 when the point sees the back face.
    pdf: f32,
}

fn sample_light(ref_point: vec3<f32>, u: vec3<f32>) -> LightSample {
    let env_select = params.env_select;
    if (u.x < env_select) {
        let wi = sample_environment(u.yz);
        return LightSample(wi, INF, ref_point, -wi, environment_radiance(wi), environment_pdf(wi));
    }
    let n = params.light_count;
    let scaled = (u.x - env_select) / (1.0 - env_select) * f32(n);
    let slot = min(u32(scaled), n - 1u);
    var entry = lights[slot];
    if (scaled - f32(slot) >= entry.prob) {
        entry = lights[entry.alias_slot];
    }
    let tri = triangles[entry.triangle];
    let b = sample_uniform_triangle(u.yz);
    let point = tri.p0 + b.x * tri.e1 + b.y * tri.e2;
    let normal = normalize(cross(tri.e1, tri.e2));
    let to_light = point - ref_point;
    let dist2 = dot(to_light, to_light);
    let dist = sqrt(dist2);
    let wi = to_light / dist;
    let cos_light = -dot(wi, normal);
    let radiance = materials[tri.material].emission;
    if (cos_light <= 0.0 || dist2 <= 0.0) {
        return LightSample(wi, dist, point, normal, radiance, 0.0);
    }
    return LightSample(wi, dist, point, normal, radiance, light_pdf(tri, dist2, cos_light));
}

// Solid-angle density of sampling `tri` from a point at squared distance `dist2`.
fn light_pdf(tri: Triangle, dist2: f32, cos_light: f32) -> f32 {
    return (1.0 - params.env_select) * tri.light_pdf_area * dist2 / abs(cos_light);
}
