//! Per-sample render parameters: the uniform block of `shaders/common.wgsl` (`Params`),
//! read by both backends.

use crate::packed::PackedScene;
use crate::scene::Camera;
use crate::settings::{LightSampler, Settings, Tile};
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
    /// Probability that light sampling picks the environment (the rest goes to triangles).
    pub env_select: f32,
    /// Environment map size (0 × 0: the environment is the constant `environment`).
    pub env_width: u32,
    pub env_height: u32,
    pub env_total: f32,
    /// Thin-lens radius in scene units (0: a pinhole).
    pub aperture: f32,
    /// Distance of the plane in focus, along the view direction.
    pub focus_distance: f32,
    /// First film row of this dispatch (the viewer renders a sample in bands of rows).
    pub row_offset: u32,
    /// Punctual lights: first row in `PackedScene::env`, and how many.
    pub punctual_base: u32,
    pub punctual_count: u32,
    /// First instance record in the node array (when the scene has instances).
    pub instance_base: u32,
    /// How samples are generated: a `SamplerKind` id.
    pub sampler: u32,
    /// How emitters are picked: a `LightSampler` id (power when the scene has no tree).
    pub light_sampler: u32,
    /// Emitters in the light tree: emissive triangles (the first `light_count`, in alias
    /// table order), then point and spot lights.
    pub tree_emitters: u32,
    /// Rows of the `lights` buffer where the tree's nodes and its emitters' trails start.
    pub tree_base: u32,
    pub trail_base: u32,
    /// The first punctual lights, sampled in an estimate of their own: all of them with the
    /// power sampler, the directional ones with the tree (they come first).
    pub separate_punctuals: u32,
    /// Firefly control: a contribution to the pixel whose components sum above the limit is
    /// scaled down to it; direct light (paths of ≤ 2 segments) and indirect light have their
    /// own limits (`f32::MAX`: off).
    pub clamp_direct: f32,
    pub clamp_indirect: f32,
    /// Adaptive sampling (`src/adaptive.rs`): a pixel stops once its error estimate is below
    /// this (0: off), tested after `adaptive_min_samples` samples and then every
    /// `adaptive_step`.
    pub noise_threshold: f32,
    pub adaptive_min_samples: u32,
    pub adaptive_step: u32,
    /// First row of the sheen albedo table in the light-data buffer (`src/sheen.rs`).
    pub sheen_base: u32,
    /// First film row (vec4) of the AOV region (`src/aov.rs`); 0: no AOVs.
    pub aov_base: u32,
    /// PROJECTION_PERSPECTIVE, or PROJECTION_ORTHOGRAPHIC (then `cam_right` and `cam_up` are
    /// the half extents of the view in scene units).
    pub projection: u32,
    /// First `attributes` record of the triangles' COLOR_0 and TEXCOORD_1 (0: none).
    pub extras_base: u32,
    /// Light candidates resampled at a glossy vertex (`LightSampler::Ris`); 1: one light
    /// sample, no resampling.
    pub light_candidates: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

/// Camera projections (`Params::projection`; PROJECTION_* in shaders/common.wgsl).
pub const PROJECTION_PERSPECTIVE: u32 = 0;
pub const PROJECTION_ORTHOGRAPHIC: u32 = 1;

/// Light candidates per glossy vertex with `LightSampler::Ris` (measured in BENCHMARKS.md).
pub const RIS_CANDIDATES: u32 = 4;

/// Russian roulette starts once a path has this many segments: 4 measured best at equal time
/// on the Cornell box and the glass box among 3–6 while keeping the README's render within its
/// time (BENCHMARKS.md session 27; Mitsuba's default is 5).
pub const RR_DEPTH: u32 = 4;

/// The environment is a light when it is not black: all of light sampling when the scene has
/// no emissive triangles, else half of it.
pub fn env_select_probability(environment: Vec3, has_map: bool, map_total: f32, light_count: u32) -> f32 {
    if environment.max_element() <= 0.0 || (has_map && map_total <= 0.0) {
        0.0
    } else if light_count == 0 {
        1.0
    } else {
        0.5
    }
}

impl Params {
    /// The film a render with these parameters accumulates into.
    pub fn film_layout(&self) -> crate::film::FilmLayout {
        crate::film::FilmLayout { adaptive: self.noise_threshold > 0.0, aovs: self.aov_base > 0 }
    }

    /// The parameters of `settings` for `camera` over the window `tile`, before the lens is
    /// set up (a pinhole).
    pub fn new(camera: &Camera, settings: &Settings, tile: Tile, scene: &PackedScene) -> Params {
        let light_count = scene.lights.len() as u32;
        let tree = settings.light_sampler != LightSampler::Power && scene.tree_emitters > 0;
        let lights = if tree { scene.tree_emitters } else { light_count };
        let (w, h) = (settings.width, settings.height);
        let environment = scene.environment;
        // Half the view's height at distance 1 (perspective), or in scene units (orthographic).
        let tan_half = camera.ortho.unwrap_or((0.5 * camera.yfov).tan());
        let aspect = w as f32 / h as f32;
        Params {
            cam_position: camera.position.into(),
            film_width: tile.width,
            cam_right: (camera.right * tan_half * aspect).into(),
            film_height: tile.height,
            cam_up: (camera.up * tan_half).into(),
            sample_index: 0,
            cam_forward: camera.forward.into(),
            seed: settings.seed,
            environment: environment.into(),
            max_depth: settings.max_depth,
            strategy: settings.strategy as u32,
            light_count,
            rr_depth: RR_DEPTH,
            image_width: w,
            image_height: h,
            tile_x: tile.x,
            tile_y: tile.y,
            env_select: env_select_probability(environment, scene.env_width > 0, scene.env_total, lights),
            env_width: scene.env_width,
            env_height: scene.env_height,
            env_total: scene.env_total,
            aperture: 0.0,
            focus_distance: 1.0,
            row_offset: 0,
            punctual_base: scene.punctual_base,
            punctual_count: scene.punctual_count,
            instance_base: scene.instance_base,
            sampler: settings.sampler as u32,
            light_sampler: if tree { LightSampler::Tree } else { LightSampler::Power } as u32,
            tree_emitters: if tree { scene.tree_emitters } else { 0 },
            tree_base: scene.tree_base,
            trail_base: scene.trail_base,
            separate_punctuals: if tree { scene.directional_count } else { scene.punctual_count },
            clamp_direct: settings.clamp_direct.unwrap_or(f32::MAX),
            clamp_indirect: settings.clamp_indirect.unwrap_or(f32::MAX),
            noise_threshold: settings.noise_threshold.unwrap_or(0.0),
            adaptive_min_samples: settings.adaptive_min_samples(),
            adaptive_step: crate::settings::ADAPTIVE_STEP,
            sheen_base: scene.sheen_base,
            aov_base: if settings.aovs.is_empty() {
                0
            } else {
                (settings.film_layout().aov_base(tile.width as usize * tile.height as usize) / 4) as u32
            },
            projection: if camera.ortho.is_some() { PROJECTION_ORTHOGRAPHIC } else { PROJECTION_PERSPECTIVE },
            extras_base: scene.extras_base,
            light_candidates: if settings.light_sampler == LightSampler::Ris { RIS_CANDIDATES } else { 1 },
            pad0: 0,
            pad1: 0,
            pad2: 0,
        }
    }
}
pub const LIGHT_SAMPLER_TREE: u32 = crate::LightSampler::Tree as u32;
