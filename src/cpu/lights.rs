//! Twin of `shaders/lights.wgsl`.

use super::common::{INF, ONE_MINUS_EPSILON};
use super::environment::{environment_pdf, environment_radiance, sample_environment};
use super::light_tree::{LightContext, light_tree_pmf, sample_light_tree};
use super::material::{material_at, triangle_uv};
use super::sampling::{bilinear_pdf, sample_bilinear, sample_uniform_triangle};
use super::spherical_triangle::{
    SOLID_ANGLE_MAX, SOLID_ANGLE_MIN, invert_spherical_triangle_sample, sample_spherical_triangle,
    spherical_triangle_area, surely_below_solid_angle_min,
};
use crate::packed::{
    LightEntry, NO_TEXTURE, PUNCTUAL_POINT, PUNCTUAL_SPOT, PackedScene, Punctual, TRI_EMITTER_SHIFT, Triangle,
};
use crate::params::{LIGHT_SAMPLER_TREE, Params};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub wi: Vec3,
    pub dist: f32,
    pub point: Vec3,
    pub normal: Vec3,
    pub radiance: Vec3,
    pub pdf: f32,
    /// A Dirac light (point, spot): no BSDF sample can find it, so no MIS.
    pub delta: bool,
}

/// One light sample for next-event estimation: the environment with probability
/// `env_select`, else an emitter (by power, or by the light tree from `ctx`), then a point
/// on it. `pdf` is the solid-angle density (the selection probability for Dirac lights).
pub fn sample_light(scene: &PackedScene, params: &Params, ctx: &LightContext, u: Vec3) -> LightSample {
    let walk = match tree_u(params, u.x) {
        Some(u_tree) => sample_light_tree(scene, params, ctx, u_tree),
        None => (0, 0.0),
    };
    sample_light_chosen(scene, params, ctx, u, walk)
}

/// The number the light tree's walk takes when light sampling draws `u_x` (None: the
/// environment or the power sampler chooses, not the tree).
#[inline(always)]
pub fn tree_u(params: &Params, u_x: f32) -> Option<f32> {
    let env_select = params.env_select;
    if u_x < env_select || params.light_sampler != LIGHT_SAMPLER_TREE {
        return None;
    }
    Some(((u_x - env_select) / (1.0 - env_select)).min(ONE_MINUS_EPSILON))
}

/// `sample_light` once the tree's walk (emitter, probability) for `tree_u(u.x)` is known
/// (unused when that is None): the walks of many paths can run side by side first.
pub fn sample_light_chosen(
    scene: &PackedScene,
    params: &Params,
    ctx: &LightContext,
    u: Vec3,
    walk: (u32, f32),
) -> LightSample {
    let ref_point = ctx.point;
    let env_select = params.env_select;
    if u.x < env_select {
        let wi = sample_environment(scene, params, Vec2::new(u.y, u.z));
        return LightSample {
            wi,
            dist: INF,
            point: ref_point,
            normal: -wi,
            radiance: environment_radiance(scene, params, wi),
            pdf: environment_pdf(scene, params, wi),
            delta: false,
        };
    }
    let u_select = (u.x - env_select) / (1.0 - env_select);
    let (triangle, select_pmf) = if params.light_sampler == LIGHT_SAMPLER_TREE {
        let (emitter, pmf) = walk;
        let pmf = (1.0 - env_select) * pmf;
        if pmf <= 0.0 {
            return LightSample {
                wi: ctx.normal,
                dist: INF,
                point: ref_point,
                normal: -ctx.normal,
                radiance: Vec3::ZERO,
                pdf: 0.0,
                delta: false,
            };
        }
        if emitter >= params.light_count {
            let l = punctual_light(scene, params, params.separate_punctuals + emitter - params.light_count);
            return punctual_sample(&l, ref_point, pmf);
        }
        (light_entry(scene, emitter).triangle, pmf)
    } else {
        let n = params.light_count;
        let scaled = u_select * n as f32;
        let slot = (scaled as u32).min(n - 1);
        let mut entry = light_entry(scene, slot);
        if scaled - slot as f32 >= entry.prob {
            entry = light_entry(scene, entry.alias_slot);
        }
        (entry.triangle, 0.0)
    };
    let tri = &scene.triangles[triangle as usize];
    let (p0, e1, e2) = (Vec3::from(tri.p0), Vec3::from(tri.e1), Vec3::from(tri.e2));
    let normal = e1.cross(e2).normalize();
    let tree = params.light_sampler == LIGHT_SAMPLER_TREE;
    let omega = if tree { triangle_solid_angle(ref_point, tri) } else { 0.0 };
    if omega > 0.0 {
        // In the solid angle, warped towards the receiver's cosine; the point is where the
        // sampled direction meets the plane.
        let weights = receiver_cosine_weights(ctx, tri);
        let us = sample_bilinear(Vec2::new(u.y, u.z), weights);
        let warp_pdf = bilinear_pdf(us, weights);
        let Some(w) = sample_spherical_triangle(ref_point, p0, p0 + e1, p0 + e2, us.x, us.y) else {
            return LightSample {
                wi: normal,
                dist: INF,
                point: ref_point,
                normal,
                radiance: Vec3::ZERO,
                pdf: 0.0,
                delta: false,
            };
        };
        let t = (p0 - ref_point).dot(normal) / w.dot(normal);
        let b = barycentrics(ref_point + t * w - p0, e1, e2);
        let point = p0 + b.x * e1 + b.y * e2;
        let to_light = point - ref_point;
        let dist = to_light.length();
        let wi = to_light / dist;
        let radiance = emitted(scene, tri, triangle, b);
        let pdf = if t > 0.0 && dist > 0.0 { select_pmf * warp_pdf / omega } else { 0.0 };
        return LightSample { wi, dist, point, normal, radiance, pdf, delta: false };
    }
    let b = sample_uniform_triangle(Vec2::new(u.y, u.z));
    let point = p0 + b.x * e1 + b.y * e2;
    let to_light = point - ref_point;
    let dist2 = to_light.dot(to_light);
    let dist = dist2.sqrt();
    let wi = to_light / dist;
    let cos_light = -wi.dot(normal);
    let radiance = emitted(scene, tri, triangle, b);
    let mut ls = LightSample { wi, dist, point, normal, radiance, pdf: 0.0, delta: false };
    if cos_light <= 0.0 || dist2 <= 0.0 {
        return ls;
    }
    ls.pdf = if tree {
        select_pmf * dist2 / (cos_light * triangle_area(tri))
    } else {
        (1.0 - env_select) * tri.light_pdf_area * dist2 / cos_light
    };
    ls
}

/// Emitted radiance at barycentrics `b` of triangle `index`.
fn emitted(scene: &PackedScene, tri: &Triangle, index: u32, b: Vec2) -> Vec3 {
    let m = &scene.materials[tri.material as usize];
    if m.emissive_texture.atlas != NO_TEXTURE {
        // (COLOR_0 tints the base colour, not the emission.)
        material_at(scene, m, triangle_uv(scene, index, b.x, b.y), glam::Vec4::ONE).emission.into()
    } else {
        m.emission.into()
    }
}

/// Barycentrics (of vertices 1 and 2) of the point `v` (relative to vertex 0) in the plane
/// of edges `e1`, `e2`, clamped onto the triangle.
pub fn barycentrics(v: Vec3, e1: Vec3, e2: Vec3) -> Vec2 {
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d20, d21) = (v.dot(e1), v.dot(e2));
    let denom = d00 * d11 - d01 * d01;
    let b1 = ((d11 * d20 - d01 * d21) / denom).clamp(0.0, 1.0);
    let b2 = ((d00 * d21 - d01 * d20) / denom).clamp(0.0, 1.0);
    let s = b1 + b2;
    if s > 1.0 { Vec2::new(b1 / s, b2 / s) } else { Vec2::new(b1, b2) }
}

/// The solid angle of `tri` from `p` when the tree's light sampling samples it by solid
/// angle (p in front of it, the angle within [SOLID_ANGLE_MIN, SOLID_ANGLE_MAX]), else 0
/// (sampled by area).
pub fn triangle_solid_angle(p: Vec3, tri: &Triangle) -> f32 {
    let (p0, e1, e2) = (Vec3::from(tri.p0), Vec3::from(tri.e1), Vec3::from(tri.e2));
    if e1.cross(e2).dot(p - p0) <= 0.0 || surely_below_solid_angle_min(p, p0, e1, e2) {
        return 0.0;
    }
    let omega = spherical_triangle_area(p, p0, p0 + e1, p0 + e2);
    if (SOLID_ANGLE_MIN..=SOLID_ANGLE_MAX).contains(&omega) { omega } else { 0.0 }
}

/// The receiver-cosine warp (pbrt-v4's): |cos| between the shading normal and the directions
/// to the triangle's corners, as bilinear weights over the spherical sample square, whose
/// corners (0, 0) and (1, 0) map to vertex 1, (0, 1) to vertex 0 and (1, 1) to vertex 2.
/// Floored at 0.01 so that no part of the triangle becomes unreachable.
pub fn receiver_cosine_weights(ctx: &LightContext, tri: &Triangle) -> [f32; 4] {
    let p0 = Vec3::from(tri.p0);
    let cosine = |v: Vec3| ctx.normal.dot((v - ctx.point).normalize_or_zero()).abs().max(0.01);
    let (c0, c1, c2) = (cosine(p0), cosine(p0 + Vec3::from(tri.e1)), cosine(p0 + Vec3::from(tri.e2)));
    [c1, c1, c0, c2]
}

/// Alias-table entry `slot` (its row of the `lights` buffer).
pub fn light_entry(scene: &PackedScene, slot: u32) -> LightEntry {
    bytemuck::cast(scene.light_rows[slot as usize])
}

pub fn triangle_area(tri: &Triangle) -> f32 {
    0.5 * Vec3::from(tri.e1).cross(Vec3::from(tri.e2)).length()
}

/// Solid-angle density with which `sample_light` from `ctx` finds the point of `tri` that a
/// ray in direction `wi` reached at distance² `dist2` with cosine `cos_light` to the light's
/// normal.
pub fn light_pdf(
    scene: &PackedScene,
    params: &Params,
    ctx: &LightContext,
    tri: &Triangle,
    wi: Vec3,
    dist2: f32,
    cos_light: f32,
) -> f32 {
    if params.light_sampler != LIGHT_SAMPLER_TREE {
        return (1.0 - params.env_select) * tri.light_pdf_area * dist2 / cos_light.abs();
    }
    let emitter = tri.flags >> TRI_EMITTER_SHIFT;
    if emitter == 0 {
        return 0.0;
    }
    let pmf = (1.0 - params.env_select) * light_tree_pmf(scene, params, ctx, emitter - 1);
    let omega = triangle_solid_angle(ctx.point, tri);
    if omega > 0.0 {
        let (p0, e1, e2) = (Vec3::from(tri.p0), Vec3::from(tri.e1), Vec3::from(tri.e2));
        let us = invert_spherical_triangle_sample(ctx.point, p0, p0 + e1, p0 + e2, wi);
        return pmf * bilinear_pdf(us, receiver_cosine_weights(ctx, tri)) / omega;
    }
    pmf * dist2 / (cos_light.abs() * triangle_area(tri))
}

pub fn punctual_light(scene: &PackedScene, params: &Params, index: u32) -> Punctual {
    let base = (params.punctual_base + 4 * index) as usize;
    bytemuck::cast_slice::<[f32; 4], Punctual>(&scene.light_data[base..base + 4])[0]
}

/// One of the first `separate_punctuals` punctual lights, chosen uniformly.
pub fn sample_punctual(scene: &PackedScene, params: &Params, ref_point: Vec3, u: f32) -> LightSample {
    let n = params.separate_punctuals;
    let index = ((u * n as f32) as u32).min(n - 1);
    punctual_sample(&punctual_light(scene, params, index), ref_point, 1.0 / n as f32)
}

/// Light from punctual light `l` at `ref_point`, chosen with probability `pdf`: `radiance` is
/// the irradiance factor I/r² (point, spot) or E (directional), glTF's window for `range`,
/// spot cone falloff t² with t = clamp((cos θ − cos outer) / (cos inner − cos outer)).
pub fn punctual_sample(l: &Punctual, ref_point: Vec3, pdf: f32) -> LightSample {
    let (position, direction, intensity) = (Vec3::from(l.position), Vec3::from(l.direction), Vec3::from(l.intensity));
    if l.kind != PUNCTUAL_POINT && l.kind != PUNCTUAL_SPOT {
        let wi = -direction;
        return LightSample {
            wi,
            dist: INF,
            point: ref_point,
            normal: direction,
            radiance: intensity,
            pdf,
            delta: true,
        };
    }
    let to_light = position - ref_point;
    let dist2 = to_light.dot(to_light);
    let dist = dist2.sqrt();
    let wi = to_light / dist;
    let mut scale = 1.0 / dist2;
    if l.range > 0.0 {
        let x = dist / l.range;
        let window = (1.0 - x * x * x * x).clamp(0.0, 1.0);
        scale *= window * window;
    }
    if l.kind == PUNCTUAL_SPOT {
        let cos_axis = (-wi).dot(direction);
        let t = ((cos_axis - l.cos_outer) / (l.cos_inner - l.cos_outer).max(1e-4)).clamp(0.0, 1.0);
        scale *= t * t;
    }
    if dist2 <= 0.0 || scale <= 0.0 || pdf <= 0.0 {
        return LightSample { wi, dist, point: position, normal: -wi, radiance: Vec3::ZERO, pdf: 0.0, delta: true };
    }
    LightSample { wi, dist, point: position, normal: -wi, radiance: intensity * scale, pdf, delta: true }
}
