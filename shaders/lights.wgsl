// Lights: emissive triangles and the environment. Light sampling picks the environment with
// probability params.env_select, else a triangle in proportion to its power (area ×
// luminance) through an alias table, then a point uniformly on it; the area pdf becomes a
// solid-angle pdf r² / (|cos θ_light| · area). Triangles emit from their front face.
// Punctual lights (KHR_lights_punctual) are Dirac lights: `sample_punctual` picks one
// uniformly for a separate next-event estimate with no MIS, as nothing else can find them.
// Twin: src/cpu/lights.rs.
#include "bindings.wgsl"
#include "sampling.wgsl"
#include "environment.wgsl"
#include "material.wgsl"

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
    let tri = load_triangle(entry.triangle);
    let b = sample_uniform_triangle(u.yz);
    let point = tri.p0 + b.x * tri.e1 + b.y * tri.e2;
    let normal = normalize(cross(tri.e1, tri.e2));
    let to_light = point - ref_point;
    let dist2 = dot(to_light, to_light);
    let dist = sqrt(dist2);
    let wi = to_light / dist;
    let cos_light = -dot(wi, normal);
    var radiance = materials[tri.material].emission;
    if (TEXTURES && materials[tri.material].emissive_texture.layer != NO_TEXTURE) {
        radiance = material_at(materials[tri.material], triangle_uv(entry.triangle, b.x, b.y)).emission;
    }
    if (cos_light <= 0.0 || dist2 <= 0.0) {
        return LightSample(wi, dist, point, normal, radiance, 0.0);
    }
    return LightSample(wi, dist, point, normal, radiance, light_pdf(tri, dist2, cos_light));
}

// Solid-angle density of sampling `tri` from a point at squared distance `dist2`.
fn light_pdf(tri: Triangle, dist2: f32, cos_light: f32) -> f32 {
    return (1.0 - params.env_select) * tri.light_pdf_area * dist2 / abs(cos_light);
}

const PUNCTUAL_POINT: f32 = 0.0;
const PUNCTUAL_SPOT: f32 = 1.0;
// Any other kind is directional (the else branches below).
const PUNCTUAL_DIRECTIONAL: f32 = 2.0;

fn punctual_light(index: u32) -> Punctual {
    let base = params.punctual_base + 4u * index;
    let r0 = light_data[base];
    let r1 = light_data[base + 1u];
    let r2 = light_data[base + 2u];
    let r3 = light_data[base + 3u];
    return Punctual(r0.xyz, r0.w, r1.xyz, r1.w, r2.xyz, r2.w, r3.x, 0.0, 0.0, 0.0);
}

// One punctual light chosen uniformly: `radiance` is the irradiance factor I/r² (point,
// spot) or E (directional), glTF's window for `range`, spot cone falloff t² with
// t = clamp((cos θ − cos outer) / (cos inner − cos outer)); `pdf` is the selection
// probability.
fn sample_punctual(ref_point: vec3<f32>, u: f32) -> LightSample {
    let n = params.punctual_count;
    let index = min(u32(u * f32(n)), n - 1u);
    let l = punctual_light(index);
    let pdf = 1.0 / f32(n);
    if (l.kind != PUNCTUAL_POINT && l.kind != PUNCTUAL_SPOT) {
        let wi = -l.direction;
        return LightSample(wi, INF, ref_point, l.direction, l.intensity, pdf);
    }
    let to_light = l.position - ref_point;
    let dist2 = dot(to_light, to_light);
    let dist = sqrt(dist2);
    let wi = to_light / dist;
    var scale = 1.0 / dist2;
    if (l.range > 0.0) {
        let x = dist / l.range;
        let window = clamp(1.0 - x * x * x * x, 0.0, 1.0);
        scale *= window * window;
    }
    if (l.kind == PUNCTUAL_SPOT) {
        let cos_axis = dot(-wi, l.direction);
        let t = clamp((cos_axis - l.cos_outer) / max(l.cos_inner - l.cos_outer, 1e-4), 0.0, 1.0);
        scale *= t * t;
    }
    if (dist2 <= 0.0 || scale <= 0.0) {
        return LightSample(wi, dist, l.position, -wi, vec3<f32>(0.0), 0.0);
    }
    return LightSample(wi, dist, l.position, -wi, l.intensity * scale, pdf);
}
