//! Paths in lanes: the CPU engine's default kernel (`cpu::Kernel::Lanes`). A packet of
//! `LANES` paths (consecutive pixels of a film row, the same sample index) keeps its state in
//! SIMD lanes (`paths.rs`, types in `lane.rs`) and goes through the integrator's stages
//! together; on plain surfaces (`paths::plain_material`) the surface, next-event and BSDF
//! stages are arithmetic over lanes (the BSDF in `bsdf.rs`), and what branches per path — the
//! BVH walks, light selection (the tree's walks side by side, `light_tree.rs`), the light
//! sample, the shadow test — runs lane by lane. Every path draws the same numbers and does the
//! same operations in the same order as the scalar reference (`integrator.rs`), so the films
//! are the same bits (tests/lanes.rs holds the two to that).

pub mod bsdf;
pub mod lane;
pub mod light_tree;
pub mod lights;
pub mod paths;
pub mod sampler;
pub mod trig;

use super::camera::camera_sample;
use super::integrator::PathState;
use crate::aov::AovSample;
use crate::packed::PackedScene;
use crate::params::Params;
use glam::{UVec2, Vec3};
use paths::{Paths, trace_paths};

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
        super::sampler::sampler_init(params.sampler, 0, params.sample_index, 0),
    );
    let mut states = [placeholder; LANES];
    for i in lanes_of(mask) {
        let pixel = UVec2::new(x0 + i as u32 + params.tile_x, y + params.tile_y);
        let (ray, sampler) = camera_sample(params, pixel);
        states[i] = PathState::new(params, ray, sampler);
    }
    let mut paths = Paths::from_states(&states);
    trace_paths(scene, params, &mut paths, mask);
    lane::per_lane(|i| (paths.radiance.lane(i), paths.aov[i]))
}
