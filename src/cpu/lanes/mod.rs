//! Paths in lanes: the CPU engine's fast path. A packet of `LANES` paths (consecutive pixels
//! of a film row, the same sample index) goes through the integrator's stages together —
//! camera, closest hits, escape or surface, next-event estimation, BSDF sample — so that the
//! stages can run over all of its paths at once: side by side where the work is a long
//! dependent chain (the light tree's walk), in SIMD lanes where it is arithmetic
//! (`lane.rs`). Every path draws the same numbers and does the same operations in the same
//! order as the scalar reference (`integrator.rs`), so the films are the same bits
//! (tests/lanes.rs holds the two to that).

pub mod lane;
pub mod light_tree;

use super::bvh::{Hit, NO_HIT, intersect_closest};
use super::camera::camera_sample;
use super::common::INF;
use super::integrator::{
    PathState, SurfaceVertex, clamp_contribution, connect, next_event_wanted, path_connect_light, path_escaped,
    path_scatter, path_strategy, path_surface,
};
use super::lights::{LightSample, sample_light_chosen, sample_punctual, tree_u};
use super::sampler::{sample_1d, sample_2d};
use crate::aov::AovSample;
use crate::packed::PackedScene;
use crate::params::Params;
use glam::{UVec2, Vec3};
use light_tree::sample_light_tree_lanes;

/// Paths in a packet.
pub const LANES: usize = 8;

/// The lanes of `mask`, lowest first.
#[inline(always)]
pub fn lanes_of(mask: u32) -> impl Iterator<Item = usize> {
    let mut m = mask;
    std::iter::from_fn(move || {
        if m == 0 {
            return None;
        }
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        Some(i)
    })
}

/// What a packet's sample gave each of its pixels: radiance and the AOV sample.
pub type PacketResult = [(Vec3, AovSample); LANES];

/// Sample `params.sample_index` of the film pixels `x0 + i` of row `y` for the lanes `i` in
/// `mask`: each lane's radiance and AOV sample, as `render_sample` gives them one by one.
pub fn render_packet(scene: &PackedScene, params: &Params, x0: u32, y: u32, mask: u32) -> PacketResult {
    let placeholder = PathState::new(
        params,
        super::common::Ray { origin: Vec3::ZERO, dir: Vec3::Z },
        super::sampler::sampler_init(params.sampler, 0, 0, 0),
    );
    let mut paths = [placeholder; LANES];
    for i in lanes_of(mask) {
        let pixel = UVec2::new(x0 + i as u32 + params.tile_x, y + params.tile_y);
        let (ray, sampler) = camera_sample(params, pixel);
        paths[i] = PathState::new(params, ray, sampler);
    }
    trace_paths(scene, params, &mut paths, mask);
    std::array::from_fn(|i| (paths[i].radiance, paths[i].aov))
}

/// Runs the paths of `alive` to their ends, stage by stage over the packet: `trace_path`'s
/// loop with the lanes inside each stage.
pub fn trace_paths(scene: &PackedScene, params: &Params, paths: &mut [PathState; LANES], mut alive: u32) {
    let mut hits = [Hit { t: INF, tri: NO_HIT, u: 0.0, v: 0.0, instance: 0 }; LANES];
    let mut vertices: [Option<SurfaceVertex>; LANES] = std::array::from_fn(|_| None);
    while alive != 0 {
        for i in lanes_of(alive) {
            hits[i] = intersect_closest(scene, &paths[i].ray);
            paths[i].depth += 1;
        }
        for i in lanes_of(alive) {
            if hits[i].tri == NO_HIT {
                path_escaped(scene, params, &mut paths[i]);
                alive &= !(1 << i);
                continue;
            }
            vertices[i] = path_surface(scene, params, &mut paths[i], &hits[i]);
            if vertices[i].is_none() {
                alive &= !(1 << i);
            }
        }
        next_event_lanes(scene, params, paths, &vertices, alive);
        for i in lanes_of(alive) {
            let Some(sv) = &vertices[i] else { continue };
            if !path_scatter(params, &mut paths[i], sv) {
                alive &= !(1 << i);
            }
        }
    }
}

/// `path_next_event` over the packet: every lane draws its light sample's numbers, the light
/// tree's walks run side by side, then each lane samples its light and connects.
fn next_event_lanes(
    scene: &PackedScene,
    params: &Params,
    paths: &mut [PathState; LANES],
    vertices: &[Option<SurfaceVertex>; LANES],
    alive: u32,
) {
    let strategy = path_strategy(params);
    if next_event_wanted(params) {
        let mut u = [Vec3::ZERO; LANES];
        let mut walking = 0u32;
        let mut u_tree = [0.0f32; LANES];
        for i in lanes_of(alive) {
            let path = &mut paths[i];
            let u0 = sample_1d(&mut path.sampler);
            let u12 = sample_2d(&mut path.sampler);
            u[i] = Vec3::new(u0, u12.x, u12.y);
            if let Some(t) = tree_u(params, u0) {
                u_tree[i] = t;
                walking |= 1 << i;
            }
        }
        let ctx = std::array::from_fn(|i| vertices[i].as_ref().map_or(Default::default(), |sv| sv.ctx));
        let walks = sample_light_tree_lanes(scene, params, &ctx, &u_tree, walking);
        for i in lanes_of(alive) {
            let Some(sv) = &vertices[i] else { continue };
            let ls: LightSample = sample_light_chosen(scene, params, &sv.ctx, u[i], walks[i]);
            path_connect_light(scene, params, strategy, &mut paths[i], sv, &ls);
        }
    }
    if params.separate_punctuals > 0 {
        for i in lanes_of(alive) {
            let Some(sv) = &vertices[i] else { continue };
            let path = &mut paths[i];
            let ls = sample_punctual(scene, params, sv.point, sample_1d(&mut path.sampler));
            let c =
                path.beta * connect(scene, &sv.mat, &sv.frame, sv.wo, sv.eta, sv.point, sv.ng, &ls) / ls.pdf.max(1e-30);
            path.radiance += clamp_contribution(params, c, path.depth + 1);
        }
    }
}
