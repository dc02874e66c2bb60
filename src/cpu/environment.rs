//! Twin of `shaders/environment.wgsl`.

use super::common::luminance;
use super::sampling::{UNIFORM_SPHERE_PDF, sample_uniform_sphere};
use crate::packed::PackedScene;
use crate::params::Params;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

pub fn env_direction(uv: Vec2) -> Vec3 {
    let phi = 2.0 * PI * (uv.x - 0.5);
    let theta = PI * uv.y;
    let s = theta.sin();
    Vec3::new(s * phi.sin(), theta.cos(), -s * phi.cos())
}

pub fn env_uv(dir: Vec3) -> Vec2 {
    let phi = dir.x.atan2(-dir.z);
    let theta = dir.y.clamp(-1.0, 1.0).acos();
    Vec2::new(phi * (0.5 * FRAC_1_PI) + 0.5, theta * FRAC_1_PI)
}

pub fn env_texel_index(params: &Params, uv: Vec2) -> u32 {
    let (w, h) = (params.env_width, params.env_height);
    let j = ((uv.x.max(0.0) * w as f32) as u32).min(w - 1);
    let i = ((uv.y.max(0.0) * h as f32) as u32).min(h - 1);
    i * w + j
}

pub fn environment_radiance(scene: &PackedScene, params: &Params, dir: Vec3) -> Vec3 {
    if params.env_width == 0 {
        return params.environment.into();
    }
    let t = scene.light_data[env_texel_index(params, env_uv(dir)) as usize];
    Vec3::new(t[0], t[1], t[2]) * Vec3::from(params.environment)
}

pub fn environment_pdf(scene: &PackedScene, params: &Params, dir: Vec3) -> f32 {
    if params.env_width == 0 {
        return params.env_select * UNIFORM_SPHERE_PDF;
    }
    let (w, h) = (params.env_width, params.env_height);
    let index = env_texel_index(params, env_uv(dir));
    let i = index / w;
    let sin_centre = (PI * (i as f32 + 0.5) / h as f32).sin();
    let t = scene.light_data[index as usize];
    let func = luminance(Vec3::new(t[0], t[1], t[2])) * sin_centre;
    let sin_dir = Vec2::new(dir.x, dir.z).length();
    if sin_dir <= 0.0 || params.env_total <= 0.0 {
        return 0.0;
    }
    let pdf_uv = func / params.env_total * (w * h) as f32;
    params.env_select * pdf_uv / (2.0 * PI * PI * sin_dir)
}

/// Twin of `env_sample_cdf`: inverts the CDF in `scene.light_data[base .. base + n]` (component 0 for
/// the marginal, 3 for a row), returning the entry and `u`'s place inside it.
pub fn env_sample_cdf(scene: &PackedScene, base: u32, n: u32, u: f32, marginal: bool) -> Vec2 {
    let cdf = |k: u32| scene.light_data[(base + k) as usize][if marginal { 0 } else { 3 }];
    let (mut lo, mut hi) = (0u32, n - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if cdf(mid) > u {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let c0 = if lo > 0 { cdf(lo - 1) } else { 0.0 };
    let c1 = cdf(lo);
    Vec2::new(lo as f32, ((u - c0) / (c1 - c0).max(1e-30)).clamp(0.0, 0.99999))
}

pub fn sample_environment(scene: &PackedScene, params: &Params, u: Vec2) -> Vec3 {
    if params.env_width == 0 {
        return sample_uniform_sphere(u);
    }
    let (w, h) = (params.env_width, params.env_height);
    let row = env_sample_cdf(scene, w * h, h, u.x, true);
    let column = env_sample_cdf(scene, row.x as u32 * w, w, u.y, false);
    env_direction(Vec2::new((column.x + column.y) / w as f32, (row.x + row.y) / h as f32))
}
