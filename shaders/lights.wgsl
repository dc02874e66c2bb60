// Lights: emissive triangles, point and spot lights, and the environment. Light sampling
// picks the environment with probability params.env_select, else an emitter: by power
// (area × luminance) through an alias table, or by the light tree (light_tree.wgsl); then a
// point uniformly on the triangle; the area pdf becomes a solid-angle pdf
// r² / (|cos θ_light| · area). Triangles emit from their front face. Punctual lights are
// Dirac lights (no MIS): in the tree with the tree sampler (directional ones apart), else
// `sample_punctual` picks one uniformly for a separate estimate.
// Twin: src/cpu/lights.rs.
#include "bindings.wgsl"
#include "sampling.wgsl"
#include "environment.wgsl"
#include "material.wgsl"
#include "light_tree.wgsl"
#include "spherical_triangle.wgsl"

struct LightSample {
    // Unit direction from the shading point to the light.
    wi: vec3<f32>,
    // Distance to the light point; INF for the environment.
    dist: f32,
    point: vec3<f32>,
    // Unit geometric normal of the light (its emitting side).
    normal: vec3<f32>,
    radiance: vec3<f32>,
    // Solid-angle density at the shading point (the selection probability of a Dirac light);
    // 0 when the point sees the back face.
    pdf: f32,
    // A Dirac light: no BSDF sample can find it, so no MIS.
    delta: bool,
}

fn light_entry(slot: u32) -> LightEntry {
    let r = lights[slot];
    return LightEntry(r.x, r.y, bitcast<f32>(r.z), bitcast<f32>(r.w));
}

// Emitted radiance at barycentrics `b` of triangle `index`.
fn emitted(tri: Triangle, index: u32, b: vec2<f32>) -> vec3<f32> {
    if (TEXTURES && materials[tri.material].emissive_texture.atlas != NO_TEXTURE) {
        // (COLOR_0 tints the base colour, not the emission.)
        return material_at(materials[tri.material], triangle_uv(index, b.x, b.y), vec4<f32>(1.0)).emission;
    }
    return materials[tri.material].emission;
}

// Barycentrics (of vertices 1 and 2) of the point `v` (relative to vertex 0) in the plane of
// edges `e1`, `e2`, clamped onto the triangle.
fn barycentrics(v: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>) -> vec2<f32> {
    let d00 = dot(e1, e1);
    let d01 = dot(e1, e2);
    let d11 = dot(e2, e2);
    let d20 = dot(v, e1);
    let d21 = dot(v, e2);
    let denom = d00 * d11 - d01 * d01;
    let b1 = clamp((d11 * d20 - d01 * d21) / denom, 0.0, 1.0);
    let b2 = clamp((d00 * d21 - d01 * d20) / denom, 0.0, 1.0);
    let s = b1 + b2;
    return select(vec2<f32>(b1, b2), vec2<f32>(b1 / s, b2 / s), s > 1.0);
}

// The solid angle of `tri` from `p` when the tree's light sampling samples it by solid
// angle (p in front, the angle within [SOLID_ANGLE_MIN, SOLID_ANGLE_MAX]), else 0 (by area).
fn triangle_solid_angle(p: vec3<f32>, tri: Triangle) -> f32 {
    if (dot(cross(tri.e1, tri.e2), p - tri.p0) <= 0.0 || surely_below_solid_angle_min(p, tri.p0, tri.e1, tri.e2)) {
        return 0.0;
    }
    let omega = spherical_triangle_area(p, tri.p0, tri.p0 + tri.e1, tri.p0 + tri.e2);
    return select(0.0, omega, omega >= SOLID_ANGLE_MIN && omega <= SOLID_ANGLE_MAX);
}

// The receiver-cosine warp: |cos| between the shading normal and the directions to the
// triangle's corners as bilinear weights over the spherical sample square (corners (0, 0)
// and (1, 0) map to vertex 1, (0, 1) to vertex 0, (1, 1) to vertex 2), floored at 0.01.
fn receiver_cosine_weights(ctx: LightContext, tri: Triangle) -> vec4<f32> {
    let c0 = max(abs(dot(ctx.normal, normalize_or_zero(tri.p0 - ctx.point))), 0.01);
    let c1 = max(abs(dot(ctx.normal, normalize_or_zero(tri.p0 + tri.e1 - ctx.point))), 0.01);
    let c2 = max(abs(dot(ctx.normal, normalize_or_zero(tri.p0 + tri.e2 - ctx.point))), 0.01);
    return vec4<f32>(c1, c1, c0, c2);
}

fn triangle_area(tri: Triangle) -> f32 {
    return 0.5 * length(cross(tri.e1, tri.e2));
}

fn sample_light(ctx: LightContext, u: vec3<f32>) -> LightSample {
    let ref_point = ctx.point;
    let env_select = params.env_select;
    if (u.x < env_select) {
        let wi = sample_environment(u.yz);
        return LightSample(wi, INF, ref_point, -wi, environment_radiance(wi), environment_pdf(wi), false);
    }
    let u_select = (u.x - env_select) / (1.0 - env_select);
    var triangle = 0u;
    var select_pmf = 0.0;
    if (params.light_sampler == LIGHT_SAMPLER_TREE) {
        let choice = sample_light_tree(ctx, min(u_select, ONE_MINUS_EPSILON));
        select_pmf = (1.0 - env_select) * choice.pmf;
        if (select_pmf <= 0.0) {
            return LightSample(ctx.normal, INF, ref_point, -ctx.normal, vec3<f32>(0.0), 0.0, false);
        }
        if (choice.emitter >= params.light_count) {
            let l = punctual_light(params.separate_punctuals + choice.emitter - params.light_count);
            return punctual_sample(l, ref_point, select_pmf);
        }
        triangle = light_entry(choice.emitter).triangle;
    } else {
        let n = params.light_count;
        let scaled = u_select * f32(n);
        let slot = min(u32(scaled), n - 1u);
        var entry = light_entry(slot);
        if (scaled - f32(slot) >= entry.prob) {
            entry = light_entry(entry.alias_slot);
        }
        triangle = entry.triangle;
    }
    let tri = load_triangle(triangle);
    let normal = normalize(cross(tri.e1, tri.e2));
    let tree = params.light_sampler == LIGHT_SAMPLER_TREE;
    var omega = 0.0;
    if (tree) {
        omega = triangle_solid_angle(ref_point, tri);
    }
    if (omega > 0.0) {
        // In the solid angle, warped towards the receiver's cosine; the point is where the
        // sampled direction meets the plane.
        let weights = receiver_cosine_weights(ctx, tri);
        let us = sample_bilinear(u.yz, weights);
        let warp_pdf = bilinear_pdf(us, weights);
        let s = sample_spherical_triangle(ref_point, tri.p0, tri.p0 + tri.e1, tri.p0 + tri.e2, us.x, us.y);
        if (!s.ok) {
            return LightSample(normal, INF, ref_point, normal, vec3<f32>(0.0), 0.0, false);
        }
        let t = dot(tri.p0 - ref_point, normal) / dot(s.w, normal);
        let bs = barycentrics(ref_point + t * s.w - tri.p0, tri.e1, tri.e2);
        let point_s = tri.p0 + bs.x * tri.e1 + bs.y * tri.e2;
        let to_point = point_s - ref_point;
        let dist_s = length(to_point);
        let wi_s = to_point / dist_s;
        var pdf_s = 0.0;
        if (t > 0.0 && dist_s > 0.0) {
            pdf_s = select_pmf * warp_pdf / omega;
        }
        return LightSample(wi_s, dist_s, point_s, normal, emitted(tri, triangle, bs), pdf_s, false);
    }
    let b = sample_uniform_triangle(u.yz);
    let point = tri.p0 + b.x * tri.e1 + b.y * tri.e2;
    let to_light = point - ref_point;
    let dist2 = dot(to_light, to_light);
    let dist = sqrt(dist2);
    let wi = to_light / dist;
    let cos_light = -dot(wi, normal);
    let radiance = emitted(tri, triangle, b);
    if (cos_light <= 0.0 || dist2 <= 0.0) {
        return LightSample(wi, dist, point, normal, radiance, 0.0, false);
    }
    var pdf = (1.0 - env_select) * tri.light_pdf_area * dist2 / cos_light;
    if (tree) {
        pdf = select_pmf * dist2 / (cos_light * triangle_area(tri));
    }
    return LightSample(wi, dist, point, normal, radiance, pdf, false);
}

// Solid-angle density with which `sample_light` from `ctx` finds the point of `tri` a ray in
// direction `wi` reached at distance² `dist2` with cosine `cos_light` to the light's normal.
fn light_pdf(ctx: LightContext, tri: Triangle, wi: vec3<f32>, dist2: f32, cos_light: f32) -> f32 {
    if (params.light_sampler != LIGHT_SAMPLER_TREE) {
        return (1.0 - params.env_select) * tri.light_pdf_area * dist2 / abs(cos_light);
    }
    let emitter = tri.flags >> TRI_EMITTER_SHIFT;
    if (emitter == 0u) {
        return 0.0;
    }
    let pmf = (1.0 - params.env_select) * light_tree_pmf(ctx, emitter - 1u);
    let omega = triangle_solid_angle(ctx.point, tri);
    if (omega > 0.0) {
        let us = invert_spherical_triangle_sample(ctx.point, tri.p0, tri.p0 + tri.e1, tri.p0 + tri.e2, wi);
        return pmf * bilinear_pdf(us, receiver_cosine_weights(ctx, tri)) / omega;
    }
    return pmf * dist2 / (abs(cos_light) * triangle_area(tri));
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

// One of the first `separate_punctuals` punctual lights, chosen uniformly.
fn sample_punctual(ref_point: vec3<f32>, u: f32) -> LightSample {
    let n = params.separate_punctuals;
    let index = min(u32(u * f32(n)), n - 1u);
    return punctual_sample(punctual_light(index), ref_point, 1.0 / f32(n));
}

// Light from punctual light `l` chosen with probability `pdf`: `radiance` is the irradiance
// factor I/r² (point, spot) or E (directional), glTF's window for `range`, spot cone falloff
// t² with t = clamp((cos θ − cos outer) / (cos inner − cos outer)).
fn punctual_sample(l: Punctual, ref_point: vec3<f32>, pdf: f32) -> LightSample {
    if (l.kind != PUNCTUAL_POINT && l.kind != PUNCTUAL_SPOT) {
        let wi = -l.direction;
        return LightSample(wi, INF, ref_point, l.direction, l.intensity, pdf, true);
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
    if (dist2 <= 0.0 || scale <= 0.0 || pdf <= 0.0) {
        return LightSample(wi, dist, l.position, -wi, vec3<f32>(0.0), 0.0, true);
    }
    return LightSample(wi, dist, l.position, -wi, l.intensity * scale, pdf, true);
}
