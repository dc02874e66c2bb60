//! Per-sample render parameters: the uniform block of `shaders/common.wgsl` (`Params`),
//! read by both backends.

use crate::Strategy;
use crate::scene::Camera;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct Params {
    pub cam_position: [f32; 3],
    pub film_width: u32,
    pub cam_right: [f32; 3],
    pub film_height: u32,
    pub cam_up: [f32; 3],
    pub sample_index: u32,
    pub cam_forward: [f32; 3],
    pub seed: u32,
    pub environment: [f32; 3],
    pub max_depth: u32,
    pub strategy: u32,
    pub light_count: u32,
    pub rr_depth: u32,
    pub image_width: u32,
    pub image_height: u32,
    pub tile_x: u32,
    pub tile_y: u32,
    pub pad: u32,
}

/// Russian roulette starts once a path has this many segments.
pub const RR_DEPTH: u32 = 3;

impl Params {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        camera: &Camera,
        image: (u32, u32),
        tile: crate::Tile,
        seed: u32,
        max_depth: u32,
        strategy: Strategy,
        environment: Vec3,
        light_count: u32,
    ) -> Params {
        let (w, h) = image;
        let tan_half = (0.5 * camera.yfov).tan();
        let aspect = w as f32 / h as f32;
        Params {
            cam_position: camera.position.into(),
            film_width: tile.width,
            cam_right: (camera.right * tan_half * aspect).into(),
            film_height: tile.height,
            cam_up: (camera.up * tan_half).into(),
            sample_index: 0,
            cam_forward: camera.forward.into(),
            seed,
            environment: environment.into(),
            max_depth,
            strategy: strategy as u32,
            light_count,
            rr_depth: RR_DEPTH,
            image_width: w,
            image_height: h,
            tile_x: tile.x,
            tile_y: tile.y,
            pad: 0,
        }
    }
}
