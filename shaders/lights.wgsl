// Area lights: emissive triangles chosen in proportion to power (area × luminance) by an
// alias_slot table, a point sampled uniformly on the triangle, its area pdf turned into a
// solid-angle pdf r² / (|cos θ_light| · area). Front faces emit. Twin: src/cpu/lights.rs.
#include "bindings.wgsl"
#include "sampling.wgsl"

struct LightSample {
    point: vec3<f32>,
    // Unit geometric normal of the light (its emitting side).
    normal: vec3<f32>,
    radiance: vec3<f32>,
    // Solid-angle density at the shading point; 0 when the point sees the back face.
    pdf: f32,
}

fn sample_light(ref_point: vec3<f32>, u: vec3<f32>) -> LightSample {
    let n = params.light_count;
    let scaled = u.x * f32(n);
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
    let cos_light = -dot(to_light, normal) * inverseSqrt(dist2);
    let radiance = materials[tri.material].emission;
    if (cos_light <= 0.0 || dist2 <= 0.0) {
        return LightSample(point, normal, radiance, 0.0);
    }
    return LightSample(point, normal, radiance, light_pdf(tri, dist2, cos_light));
}

// Solid-angle density of sampling `tri` from a point at squared distance `dist2`.
fn light_pdf(tri: Triangle, dist2: f32, cos_light: f32) -> f32 {
    return tri.light_pdf_area * dist2 / abs(cos_light);
}
