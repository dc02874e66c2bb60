//! Twin of `shaders/lights.wgsl`.

use super::sampling::sample_uniform_triangle;
use crate::packed::{PackedScene, PackedTriangle};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub point: Vec3,
    pub normal: Vec3,
    pub radiance: Vec3,
    pub pdf: f32,
}

pub fn sample_light(scene: &PackedScene, ref_point: Vec3, u: Vec3) -> LightSample {
    let n = scene.lights.len() as u32;
    let scaled = u.x * n as f32;
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
    let cos_light = -to_light.dot(normal) / dist2.sqrt();
    let radiance = scene.materials[tri.material as usize].emission.into();
    if cos_light <= 0.0 || dist2 <= 0.0 {
        return LightSample { point, normal, radiance, pdf: 0.0 };
    }
    LightSample { point, normal, radiance, pdf: light_pdf(tri, dist2, cos_light) }
}

pub fn light_pdf(tri: &PackedTriangle, dist2: f32, cos_light: f32) -> f32 {
    tri.light_pdf_area * dist2 / cos_light.abs()
}
