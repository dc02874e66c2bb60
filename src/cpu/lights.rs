//! Twin of `shaders/lights.wgsl`.

use super::bvh::INF;
use super::environment::{environment_pdf, environment_radiance, sample_environment};
use super::sampling::sample_uniform_triangle;
use crate::packed::{PackedScene, PackedTriangle};
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
    let radiance = scene.materials[tri.material as usize].emission.into();
    if cos_light <= 0.0 || dist2 <= 0.0 {
        return LightSample { wi, dist, point, normal, radiance, pdf: 0.0 };
    }
    LightSample { wi, dist, point, normal, radiance, pdf: light_pdf(params, tri, dist2, cos_light) }
}

pub fn light_pdf(params: &Params, tri: &PackedTriangle, dist2: f32, cos_light: f32) -> f32 {
    (1.0 - params.env_select) * tri.light_pdf_area * dist2 / cos_light.abs()
}
