//! Twin of `shaders/lights.wgsl`.

use super::bvh::INF;
use super::environment::{environment_pdf, environment_radiance, sample_environment};
use super::material::{material_at, triangle_uv};
use super::sampling::sample_uniform_triangle;
use crate::packed::{NO_TEXTURE, PUNCTUAL_POINT, PUNCTUAL_SPOT, PackedScene, Punctual, Triangle};
use crate::params::Params;
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub wi: Vec3,
    pub dist: f32,
    pub point: Vec3,
    pub normal: Vec3,
    pub radiance: Vec3,
    pub pdf: f32,
}

pub fn sample_light(scene: &PackedScene, params: &Params, ref_point: Vec3, u: Vec3) -> LightSample {
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
        };
    }
    let n = params.light_count;
    let scaled = (u.x - env_select) / (1.0 - env_select) * n as f32;
    let slot = (scaled as u32).min(n - 1);
    let mut entry = scene.lights[slot as usize];
    if scaled - slot as f32 >= entry.prob {
        entry = scene.lights[entry.alias_slot as usize];
    }
    let tri = &scene.triangles[entry.triangle as usize];
    let b = sample_uniform_triangle(Vec2::new(u.y, u.z));
    let (e1, e2) = (Vec3::from(tri.e1), Vec3::from(tri.e2));
    let point = Vec3::from(tri.p0) + b.x * e1 + b.y * e2;
    let normal = e1.cross(e2).normalize();
    let to_light = point - ref_point;
    let dist2 = to_light.dot(to_light);
    let dist = dist2.sqrt();
    let wi = to_light / dist;
    let cos_light = -wi.dot(normal);
    let m = &scene.materials[tri.material as usize];
    let radiance = if m.emissive_texture.layer != NO_TEXTURE {
        material_at(scene, m, triangle_uv(scene, entry.triangle, b.x, b.y)).emission.into()
    } else {
        m.emission.into()
    };
    if cos_light <= 0.0 || dist2 <= 0.0 {
        return LightSample { wi, dist, point, normal, radiance, pdf: 0.0 };
    }
    LightSample { wi, dist, point, normal, radiance, pdf: light_pdf(params, tri, dist2, cos_light) }
}

pub fn light_pdf(params: &Params, tri: &Triangle, dist2: f32, cos_light: f32) -> f32 {
    (1.0 - params.env_select) * tri.light_pdf_area * dist2 / cos_light.abs()
}

pub fn punctual_light(scene: &PackedScene, params: &Params, index: u32) -> Punctual {
    let base = (params.punctual_base + 4 * index) as usize;
    bytemuck::cast_slice::<[f32; 4], Punctual>(&scene.light_data[base..base + 4])[0]
}

pub fn sample_punctual(scene: &PackedScene, params: &Params, ref_point: Vec3, u: f32) -> LightSample {
    let n = params.punctual_count;
    let index = ((u * n as f32) as u32).min(n - 1);
    let l = punctual_light(scene, params, index);
    let pdf = 1.0 / n as f32;
    let (position, direction, intensity) = (Vec3::from(l.position), Vec3::from(l.direction), Vec3::from(l.intensity));
    if l.kind != PUNCTUAL_POINT && l.kind != PUNCTUAL_SPOT {
        let wi = -direction;
        return LightSample { wi, dist: INF, point: ref_point, normal: direction, radiance: intensity, pdf };
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
    if dist2 <= 0.0 || scale <= 0.0 {
        return LightSample { wi, dist, point: position, normal: -wi, radiance: Vec3::ZERO, pdf: 0.0 };
    }
    LightSample { wi, dist, point: position, normal: -wi, radiance: intensity * scale, pdf }
}
