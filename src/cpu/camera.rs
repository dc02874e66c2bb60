//! Twin of `shaders/camera.wgsl`.

use super::bvh::Ray;
use crate::params::Params;
use glam::{UVec2, Vec2, Vec3};

pub fn generate_ray(params: &Params, pixel: UVec2, u: Vec2) -> Ray {
    let x = (pixel.x as f32 + u.x) / params.image_width as f32 * 2.0 - 1.0;
    let y = 1.0 - (pixel.y as f32 + u.y) / params.image_height as f32 * 2.0;
    let dir = Vec3::from(params.cam_forward) + x * Vec3::from(params.cam_right) + y * Vec3::from(params.cam_up);
    Ray { origin: params.cam_position.into(), dir: dir.normalize() }
}
