//! Paths in lanes, the groundwork (`cpu::Kernel::Lanes`, opt-in: VEACH_CPU_KERNEL=lanes). A
//! packet of `LANES` paths (consecutive pixels of a film row, the same sample index) goes
//! through the integrator's stages together — camera, closest hits, escape or surface,
//! next-event estimation, BSDF sample — so that a stage can run over all of its paths at
//! once: side by side where the work is a long dependent chain (the light tree's walk), in
//! SIMD lanes where it is arithmetic (`lane.rs`; plain materials' BSDF in `bsdf.rs`). Every
//! path draws the same numbers and does the same operations in the same order as the scalar
//! reference (`integrator.rs`), so the films are the same bits (tests/lanes.rs).
//!
//! Measured (BENCHMARKS.md, session 18): 4–12 % slower than the reference kernel, because the
//! paths' state lives in per-path records (`PathState`, `SurfaceVertex`) that every SIMD stage
//! gathers into lanes and scatters back, and only the BSDF is in lanes yet. What pays is the
//! state in lanes from end to end, with light selection, the sampler and the surface setup in
//! lanes too; until then the reference kernel is the default.

pub mod bsdf;
pub mod lane;
pub mod light_tree;

use super::bsdf::{BsdfSample, bsdf_sample_chosen};
use super::bvh::{Hit, NO_HIT, intersect_closest};
use super::camera::camera_sample;
use super::common::INF;
use super::integrator::{
    PathState, SurfaceVertex, clamp_contribution, connect, connect_evaluated, next_event_wanted, path_add_light,
    path_connect_light, path_continue, path_escaped, path_scatter_u, path_strategy, path_surface,
};
use super::lights::{LightSample, sample_light_chosen, sample_punctual, tree_u};
use super::sampler::{sample_1d, sample_2d};
use crate::Strategy;
use crate::aov::AovSample;
use crate::packed::PackedScene;
use crate::params::Params;
use bsdf::{BaseLanes, base_eval, base_pdf, base_sample, is_plain};
use glam::{UVec2, Vec3, Vec4};
use lane::V3;
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
/// loop with the lanes inside each stage. On x86-64 CPUs with AVX2 (checked at run time) the
/// stages run compiled for it, so the lanes' arithmetic is one instruction for eight paths;
/// the operations, hence the bits, are the same either way.
pub fn trace_paths(scene: &PackedScene, params: &Params, paths: &mut [PathState; LANES], alive: u32) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above).
        return unsafe { trace_paths_avx2(scene, params, paths, alive) };
    }
    trace_paths_stages(scene, params, paths, alive)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn trace_paths_avx2(scene: &PackedScene, params: &Params, paths: &mut [PathState; LANES], alive: u32) {
    trace_paths_stages(scene, params, paths, alive)
}

#[inline(always)]
fn trace_paths_stages(scene: &PackedScene, params: &Params, paths: &mut [PathState; LANES], mut alive: u32) {
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
        let plain = plain_lanes(&vertices, alive);
        next_event_lanes(scene, params, paths, &vertices, alive, plain);
        alive = scatter_lanes(params, paths, &vertices, alive, plain);
    }
}

/// `path_scatter` over the packet, the plain lanes' BSDF samples in lanes: the paths of
/// `alive` that go on.
#[inline(always)]
fn scatter_lanes(
    params: &Params,
    paths: &mut [PathState; LANES],
    vertices: &[Option<SurfaceVertex>; LANES],
    alive: u32,
    plain: u32,
) -> u32 {
    let mut u = [Vec3::ZERO; LANES];
    for i in lanes_of(alive) {
        u[i] = path_scatter_u(&mut paths[i]);
    }
    // (Blocks, not closures: a closure would not be compiled for AVX2 with its caller.)
    let sampled = if plain != 0 {
        let (m, wo) = base_lanes(vertices, plain);
        Some(base_sample(&m, wo, V3::from_fn(|i| u[i]), plain))
    } else {
        None
    };
    let mut next = alive;
    for i in lanes_of(alive) {
        let Some(sv) = &vertices[i] else {
            next &= !(1 << i);
            continue;
        };
        let bs = match &sampled {
            Some(s) if plain >> i & 1 != 0 => {
                BsdfSample { wi: s.wi.lane(i), weight: s.weight.lane(i), pdf: s.pdf.0[i], delta: s.delta.lane(i) }
            }
            _ => bsdf_sample_chosen(&sv.mat, &sv.lobes, sv.wo, u[i], sv.eta),
        };
        if !path_continue(params, &mut paths[i], sv, &bs) {
            next &= !(1 << i);
        }
    }
    next
}

/// The lanes of `alive` whose material the lanes' BSDF covers (`bsdf::is_plain`).
#[inline(always)]
fn plain_lanes(vertices: &[Option<SurfaceVertex>; LANES], alive: u32) -> u32 {
    let mut plain = 0;
    for i in lanes_of(alive) {
        if vertices[i].as_ref().is_some_and(|sv| is_plain(&sv.mat)) {
            plain |= 1 << i;
        }
    }
    plain
}

/// The plain lanes' materials and lobe probabilities, and their wo.
#[inline(always)]
fn base_lanes(vertices: &[Option<SurfaceVertex>; LANES], plain: u32) -> (BaseLanes, V3) {
    let sv = |i: usize| vertices[i].as_ref().filter(|_| plain >> i & 1 != 0);
    let m = BaseLanes::gather(|i| sv(i).map(|v| &*v.mat), |i| sv(i).map_or(Vec4::ZERO, |v| v.lobes.base));
    (m, V3::from_fn(|i| sv(i).map_or(Vec3::Z, |v| v.wo)))
}

/// `path_next_event` over the packet: every lane draws its light sample's numbers, the light
/// tree's walks run side by side, then each lane samples its light and connects.
#[inline(always)]
fn next_event_lanes(
    scene: &PackedScene,
    params: &Params,
    paths: &mut [PathState; LANES],
    vertices: &[Option<SurfaceVertex>; LANES],
    alive: u32,
    plain: u32,
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
        let mut ls = [None::<LightSample>; LANES];
        for i in lanes_of(alive) {
            let Some(sv) = &vertices[i] else { continue };
            ls[i] = Some(sample_light_chosen(scene, params, &sv.ctx, u[i], walks[i]));
        }
        // The plain lanes' BSDF value and density for their light sample's direction, in
        // lanes; `connect` and its MIS weight from them, lane by lane.
        let evaluated = if plain != 0 {
            let (m, wo) = base_lanes(vertices, plain);
            let frame = |i: usize| vertices[i].as_ref().filter(|_| plain >> i & 1 != 0).map(|v| v.frame);
            let wi = V3::from_fn(|i| ls[i].map_or(Vec3::Z, |l| l.wi));
            let t = V3::from_fn(|i| frame(i).map_or(Vec3::X, |f| f.t));
            let b = V3::from_fn(|i| frame(i).map_or(Vec3::Y, |f| f.b));
            let n = V3::from_fn(|i| frame(i).map_or(Vec3::Z, |f| f.n));
            let wi_local = V3::new(wi.dot(t), wi.dot(b), wi.dot(n));
            Some((wi_local, base_eval(&m, wo, wi_local), base_pdf(&m, wo, wi_local)))
        } else {
            None
        };
        for i in lanes_of(alive) {
            let (Some(sv), Some(ls)) = (&vertices[i], &ls[i]) else { continue };
            match &evaluated {
                Some((wi_local, f, pdf)) if plain >> i & 1 != 0 => {
                    if ls.delta || strategy != Strategy::Bsdf {
                        let c = if ls.pdf <= 0.0 {
                            Vec3::ZERO
                        } else {
                            connect_evaluated(scene, sv.point, sv.ng, ls, wi_local.lane(i), f.lane(i))
                        };
                        path_add_light(params, strategy, &mut paths[i], ls, c, || pdf.0[i]);
                    }
                }
                _ => path_connect_light(scene, params, strategy, &mut paths[i], sv, ls),
            }
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
