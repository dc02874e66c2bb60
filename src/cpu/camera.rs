//! Twin of `shaders/camera.wgsl`.

use super::common::Ray;
use super::sampler::{Sampler, sample_2d, sampler_init};
use super::sampling::sample_uniform_disk;
use crate::params::{PROJECTION_ORTHOGRAPHIC, Params};
use glam::{UVec2, Vec2, Vec3};

#[inline]
pub fn generate_ray(params: &Params, pixel: UVec2, u: Vec2, sampler: &mut Sampler) -> Ray {
    let x = (pixel.x as f32 + u.x) / params.image_width as f32 * 2.0 - 1.0;
    let y = 1.0 - (pixel.y as f32 + u.y) / params.image_height as f32 * 2.0;
    let (forward, right, up) =
        (Vec3::from(params.cam_forward), Vec3::from(params.cam_right), Vec3::from(params.cam_up));
    let position = Vec3::from(params.cam_position);
    // An orthographic camera's rays are parallel, from points across its view (no lens).
    if params.projection == PROJECTION_ORTHOGRAPHIC {
        return Ray { origin: position + x * right + y * up, dir: forward.normalize() };
    }
    let dir = (forward + x * right + y * up).normalize();
    if params.aperture <= 0.0 {
        return Ray { origin: position, dir };
    }
    let focus = position + dir * (params.focus_distance / dir.dot(forward));
    let lens = sample_uniform_disk(sample_2d(sampler)) * params.aperture;
    let origin = position + lens.x * right.normalize() + lens.y * up.normalize();
    Ray { origin, dir: (focus - origin).normalize() }
}

/// The camera ray of `pixel` for sample `params.sample_index`, with the sampler its path goes
/// on drawing from.
#[inline]
pub fn camera_sample(params: &Params, pixel: UVec2) -> (Ray, Sampler) {
    let mut sampler =
        sampler_init(params.sampler, pixel.y * params.image_width + pixel.x, params.sample_index, params.seed);
    let jitter = sample_2d(&mut sampler);
    (generate_ray(params, pixel, jitter, &mut sampler), sampler)
}

/// The distance in focus when only an aperture is given: what the image centre sees.
pub fn autofocus(scene: &crate::packed::PackedScene, params: &Params) -> f32 {
    let ray = Ray { origin: params.cam_position.into(), dir: Vec3::from(params.cam_forward).normalize() };
    let hit = super::bvh::intersect_closest(scene, &ray);
    if hit.tri != super::bvh::NO_HIT { hit.t } else { 0.5 * scene.extent }
}
