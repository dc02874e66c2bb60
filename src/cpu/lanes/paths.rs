//! A packet's paths with their state in lanes (structure of arrays), and the integrator's loop
//! over them. Each bounce, the lanes whose surface the lanes cover ("plain": `plain_material`)
//! go through `bounce_plain`, which is `path_surface`, `path_next_event` and `path_scatter`
//! written over lanes, operation for operation; every other lane (textures, layers, glass,
//! instances, AOVs, vertex colours, separately sampled punctual lights, environment hits) is
//! taken out of the lanes as a `PathState`, advanced by the scalar stages, and put back. What
//! stays per lane inside `bounce_plain` is what branches per path: the BVH walks, light
//! selection and the light sample, an emitter hit's light density, the shadow test.

use super::bsdf::{BaseLanes, base_eval, base_pdf, base_sample, is_plain};
use super::camera::camera_samples;
use super::lane::{F8, M8, U8, V3, per_lane};
use super::light_tree::{MAX_CANDIDATES, sample_light_tree_candidates, sample_light_tree_lanes};
use super::lights::{LightSampleLanes, sample_lights};
use super::sampler::SamplerLanes;
use super::{LANES, lanes_of};
use crate::Strategy;
use crate::aov::AovSample;
use crate::cpu::bvh::{Hit, NO_HIT, intersect_closest, occluded, trace_pair};
use crate::cpu::common::{INF, ONE_MINUS_EPSILON, Ray};
use crate::cpu::integrator::{
    GLOSSY_ROUGHNESS, PathState, candidate_pdf_scale, next_event_wanted, path_escaped, path_next_event, path_scatter,
    path_strategy, path_surface,
};
use crate::cpu::light_tree::LightContext;
use crate::cpu::lights::{light_pdf, tree_u};
use crate::cpu::material::shading_normal;
use crate::cpu::microfacet::DELTA_ALPHA;
use crate::cpu::sampler::sampler_init;
use crate::packed::{Material, PackedScene, TRI_HAS_NORMALS, TRI_MIRRORED};
use crate::params::Params;
use glam::{UVec2, Vec3, Vec4};

/// `PathState` of a packet, lane by lane.
#[derive(Clone, Copy, Debug)]
pub struct Paths {
    pub origin: V3,
    pub dir: V3,
    pub radiance: V3,
    pub beta: V3,
    pub eta_scale: F8,
    pub depth: U8,
    pub prev_pdf: F8,
    pub prev_delta: M8,
    pub prev_point: V3,
    pub prev_normal: V3,
    pub prev_reflect_only: M8,
    pub aov_open: M8,
    pub aov_weight: V3,
    pub aov: [AovSample; LANES],
    pub channel: U8,
    pub sampler: SamplerLanes,
}

impl Paths {
    pub fn from_states(s: &[PathState; LANES]) -> Paths {
        let mask = |f: &dyn Fn(&PathState) -> bool| M8::from_fn(|i| f(&s[i]));
        Paths {
            origin: V3::from_fn(|i| s[i].ray.origin),
            dir: V3::from_fn(|i| s[i].ray.dir),
            radiance: V3::from_fn(|i| s[i].radiance),
            beta: V3::from_fn(|i| s[i].beta),
            eta_scale: F8::from_fn(|i| s[i].eta_scale),
            depth: U8::from_fn(|i| s[i].depth),
            prev_pdf: F8::from_fn(|i| s[i].prev_pdf),
            prev_delta: mask(&|p| p.prev_delta),
            prev_point: V3::from_fn(|i| s[i].prev_ctx.point),
            prev_normal: V3::from_fn(|i| s[i].prev_ctx.normal),
            prev_reflect_only: mask(&|p| p.prev_ctx.reflect_only),
            aov_open: mask(&|p| p.aov_open),
            aov_weight: V3::from_fn(|i| s[i].aov_weight),
            aov: per_lane(|i| s[i].aov),
            channel: U8::from_fn(|i| s[i].channel),
            sampler: SamplerLanes::from_samplers(&per_lane(|i| s[i].sampler)),
        }
    }

    /// Lane i as a scalar path.
    pub fn lane(&self, i: usize) -> PathState {
        PathState {
            ray: Ray { origin: self.origin.lane(i), dir: self.dir.lane(i) },
            radiance: self.radiance.lane(i),
            beta: self.beta.lane(i),
            eta_scale: self.eta_scale.0[i],
            depth: self.depth.0[i],
            prev_pdf: self.prev_pdf.0[i],
            prev_delta: self.prev_delta.lane(i),
            prev_ctx: LightContext {
                point: self.prev_point.lane(i),
                normal: self.prev_normal.lane(i),
                reflect_only: self.prev_reflect_only.lane(i),
            },
            aov_open: self.aov_open.lane(i),
            aov_weight: self.aov_weight.lane(i),
            aov: self.aov[i],
            channel: self.channel.0[i],
            sampler: self.sampler.lane(i),
        }
    }

    /// Lane i becomes the scalar path `p`.
    pub fn set_lane(&mut self, i: usize, p: &PathState) {
        self.origin.set_lane(i, p.ray.origin);
        self.dir.set_lane(i, p.ray.dir);
        self.radiance.set_lane(i, p.radiance);
        self.beta.set_lane(i, p.beta);
        self.eta_scale.0[i] = p.eta_scale;
        self.depth.0[i] = p.depth;
        self.prev_pdf.0[i] = p.prev_pdf;
        self.prev_delta.set_lane(i, p.prev_delta);
        self.prev_point.set_lane(i, p.prev_ctx.point);
        self.prev_normal.set_lane(i, p.prev_ctx.normal);
        self.prev_reflect_only.set_lane(i, p.prev_ctx.reflect_only);
        self.aov_open.set_lane(i, p.aov_open);
        self.aov_weight.set_lane(i, p.aov_weight);
        self.aov[i] = p.aov;
        self.channel.0[i] = p.channel;
        self.sampler.set_lane(i, &p.sampler);
    }
}

/// Where a packet's lanes find new paths and leave ended ones: a lane whose path ends takes
/// the next path at once, so the packet's arithmetic keeps its lanes busy instead of running
/// for the longest of eight paths while the others idle.
pub trait PathQueue {
    /// Lane `i`'s path has ended: its radiance and AOV sample in `paths` are final.
    fn finished(&mut self, i: usize, paths: &Paths);
    /// A path for the idle lane `i`, if one may start now: its sample index and pixel (film
    /// coordinates).
    fn next(&mut self, i: usize) -> Option<(u32, UVec2)>;
    /// Are paths left to start?
    fn pending(&self) -> bool;
}

/// Runs the paths `queue` gives, eight at a time in the lanes of a packet, each lane taking
/// the next path as its own ends. On x86-64 only on CPUs with AVX2 (`lanes::available`), compiled
/// for AVX2, so the lanes' arithmetic is one instruction for the packet; each path's bits are
/// the same whatever lane it runs in.
pub fn trace_paths<Q: PathQueue>(scene: &PackedScene, params: &Params, queue: &mut Q) {
    #[cfg(target_arch = "x86_64")]
    {
        assert!(super::available(), "the lanes kernel needs AVX2 on x86-64 (`lanes::available`)");
        // SAFETY: the CPU has AVX2 (checked just above).
        unsafe { trace_paths_avx2(scene, params, queue) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    trace_paths_loop(scene, params, queue)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn trace_paths_avx2<Q: PathQueue>(scene: &PackedScene, params: &Params, queue: &mut Q) {
    trace_paths_loop(scene, params, queue)
}

/// Can `bounce_plain` take a hit on material `m` (its index `index`) in this scene?
#[inline(always)]
fn plain_material(scene: &PackedScene, params: &Params, m: &Material, index: usize) -> bool {
    // (A material is the stored one at every point without textures or vertex colours.)
    scene.instance_count == 0
        && scene.extras_base == 0
        && params.separate_punctuals == 0
        && !scene.material_textured[index]
        && is_plain(m)
        && Vec3::from(m.attenuation).max_element() <= 0.0
}

#[inline(always)]
fn trace_paths_loop<Q: PathQueue>(scene: &PackedScene, params: &Params, queue: &mut Q) {
    if !queue.pending() {
        return;
    }
    // A path as it starts, but for its ray and sampler (idle lanes hold copies).
    let start = PathState::new(params, Ray { origin: Vec3::ZERO, dir: Vec3::Z }, sampler_init(params.sampler, 0, 0, 0));
    let paths = &mut Paths::from_states(&[start; LANES]);
    let mut alive = 0u32;
    let mut hits = [Hit { t: INF, tri: NO_HIT, u: 0.0, v: 0.0, instance: 0 }; LANES];
    loop {
        // Idle lanes take new paths (the first refusal holds for the rest), except when every
        // path in flight is about to take its last segment: that bounce is emission alone and
        // skips the surface stages, which new paths beside it would run for a few lanes (with
        // depth 2, every second bounce; measured, BENCHMARKS.md session 28).
        let finishing =
            alive != 0 && params.max_depth != 0 && lanes_of(alive).all(|i| paths.depth.0[i] + 1 >= params.max_depth);
        if queue.pending() && !finishing {
            let (mut sample, mut x, mut y) = (U8::splat(0), U8::splat(0), U8::splat(0));
            let mut starting = 0u32;
            for i in lanes_of(!alive & ((1 << LANES) - 1)) {
                let Some((s, pixel)) = queue.next(i) else { break };
                (sample.0[i], x.0[i], y.0[i]) = (s, pixel.x, pixel.y);
                paths.set_lane(i, &start);
                starting |= 1 << i;
            }
            if starting != 0 {
                // The new paths' camera rays and samplers, together.
                let m = M8::from_bits(starting);
                let (origin, dir) = camera_samples(params, sample, x, y, &mut paths.sampler, m);
                paths.origin = V3::select(m, origin, paths.origin);
                paths.dir = V3::select(m, dir, paths.dir);
                alive |= starting;
            }
        }
        if alive == 0 {
            // (Nothing in flight, so nothing holds a path back: the queue is empty.)
            break;
        }
        let before = alive;
        let ray = |i: usize| Ray { origin: paths.origin.lane(i), dir: paths.dir.lane(i) };
        // Two walks in step (`trace_pair`: one hides the other's latencies), the odd one alone.
        let mut lanes = lanes_of(alive);
        while let Some(i) = lanes.next() {
            match lanes.next() {
                Some(j) => [hits[i], hits[j]] = trace_pair(scene, [&ray(i), &ray(j)], [INF; 2], false),
                None => hits[i] = intersect_closest(scene, &ray(i)),
            }
        }
        for i in lanes_of(alive) {
            paths.depth.0[i] += 1;
        }
        let mut plain = 0u32;
        for i in lanes_of(alive) {
            let hit = &hits[i];
            if hit.tri == NO_HIT {
                let mut p = paths.lane(i);
                path_escaped(scene, params, &mut p);
                paths.set_lane(i, &p);
                alive &= !(1 << i);
                continue;
            }
            let mi = scene.triangles[hit.tri as usize].material as usize;
            if !paths.aov_open.lane(i) && plain_material(scene, params, &scene.materials[mi], mi) {
                plain |= 1 << i;
                continue;
            }
            // The scalar stages, for this lane's whole bounce.
            let mut p = paths.lane(i);
            let goes_on = match path_surface(scene, params, &mut p, hit) {
                Some(sv) => {
                    path_next_event(scene, params, &mut p, &sv);
                    path_scatter(params, &mut p, &sv)
                }
                None => false,
            };
            paths.set_lane(i, &p);
            if !goes_on {
                alive &= !(1 << i);
            }
        }
        if plain != 0 {
            let survivors = bounce_plain(scene, params, paths, &hits, plain);
            alive = (alive & !plain) | survivors;
        }
        for i in lanes_of(before & !alive) {
            queue.finished(i, paths);
        }
    }
}

/// `clamp_contribution` in lanes, `segments` per lane.
#[inline(always)]
fn clamp_contribution(params: &Params, c: V3, segments: U8) -> V3 {
    let limit = F8::from_fn(|i| if segments.0[i] <= 2 { params.clamp_direct } else { params.clamp_indirect });
    let sum = c.x + c.y + c.z;
    V3::select(sum.gt(limit), c * (limit / sum), c)
}

/// `mis_weight` in lanes.
#[inline(always)]
fn mis_weight(strategy: Strategy, pdf_f: F8, pdf_g: F8) -> F8 {
    let w = match strategy {
        Strategy::MisBalance => 1.0 / (1.0 + pdf_g / pdf_f),
        _ => {
            let r = pdf_g / pdf_f;
            1.0 / (1.0 + r * r)
        }
    };
    F8::select(pdf_f.le(F8::splat(0.0)), F8::splat(0.0), w)
}

/// `glossy_lobe` in lanes.
#[inline(always)]
fn glossy_lobe(r: F8) -> M8 {
    r.lt(F8::splat(GLOSSY_ROUGHNESS)) & (r * r).ge(F8::splat(DELTA_ALPHA))
}

/// `offset_ray` in lanes: `p` moved off its surface along `n` by a few ulps (a fixed step
/// near the origin), the scalar's operations lane by lane.
#[inline(always)]
fn offset_ray(p: V3, n: V3) -> V3 {
    V3::new(offset_axis(p.x, n.x), offset_axis(p.y, n.y), offset_axis(p.z, n.z))
}

/// One axis of `offset_ray` (a function: a closure left out of line would be compiled without
/// AVX, `lights::receiver_cosine`).
#[inline(always)]
fn offset_axis(pc: F8, nc: F8) -> F8 {
    // The scalar's integer step: `(256 n) as i32`, negated where p < 0 (wrapping, as the
    // scalar's `-o` wherever it is defined; lanes not in use may hold anything), added to p's
    // bits.
    let o = (256.0 * nc).to_i32();
    let o = U8::select(pc.lt(F8::splat(0.0)), U8::splat(0).wrapping_sub(o), o);
    let pi = F8::from_bits(pc.to_bits().wrapping_add(o));
    F8::select(pc.abs().lt(F8::splat(1.0 / 32.0)), pc + (1.0 / 65536.0) * nc, pi)
}

/// `spawn_point` in lanes: the origin of a ray leaving `point` towards `wi`.
#[inline(always)]
fn spawn_point(point: V3, ng: V3, wi: V3) -> V3 {
    offset_ray(point, V3::select(wi.dot(ng).gt(F8::splat(0.0)), ng, -ng))
}

/// `connect_evaluated` in the lanes of `m` (light samples with a density): the side test,
/// then one shadow ray per lane still open; f · |cos θ| · L where unblocked, else 0.
#[inline(always)]
fn connect_evaluated(scene: &PackedScene, point: V3, ng: V3, ls: &LightSampleLanes, wi_local: V3, f: V3, m: M8) -> V3 {
    let zero = F8::splat(0.0);
    let (above, local_above) = (ls.wi.dot(ng).gt(zero), wi_local.z.gt(zero));
    let same_side = (above & local_above) | (!above & !local_above);
    let mut open = m & same_side & !f.max_element().le(zero);
    if open.bits() == 0 {
        return V3::splat(Vec3::ZERO);
    }
    open = unoccluded(scene, offset_ray(point, V3::select(above, ng, -ng)), ls, open);
    V3::select(open, f * wi_local.z.abs() * ls.radiance, V3::splat(Vec3::ZERO))
}

/// `unoccluded` in the lanes of `m`: the lanes whose shadow ray from `origin` (`shadow_ray`:
/// to an emitter's point moved off its surface, extent 1, else along wi) is unblocked.
#[inline(always)]
fn unoccluded(scene: &PackedScene, origin: V3, ls: &LightSampleLanes, m: M8) -> M8 {
    let mut open = m;
    let infinite = ls.dist.eq(F8::splat(INF));
    let dir = V3::select(infinite, ls.wi, offset_ray(ls.point, ls.normal) - origin);
    let ray = |i: usize| Ray { origin: origin.lane(i), dir: dir.lane(i) };
    let t_max = |i: usize| if infinite.lane(i) { INF } else { 1.0 };
    // Two walks in step (`trace_pair`: one hides the other's latencies), the odd one alone.
    let mut lanes = lanes_of(m.bits());
    while let Some(i) = lanes.next() {
        match lanes.next() {
            Some(j) => {
                let hits = trace_pair(scene, [&ray(i), &ray(j)], [t_max(i), t_max(j)], true);
                open.set_lane(i, hits[0].tri == NO_HIT);
                open.set_lane(j, hits[1].tri == NO_HIT);
            }
            None => open.set_lane(i, !occluded(scene, &ray(i), t_max(i))),
        }
    }
    open
}

/// `sample_light` for the lanes of `m` from their contexts, with the next three numbers of
/// each lane's sampler: the tree's walks side by side, then the emitters' samples.
#[inline(always)]
fn sample_light(
    scene: &PackedScene,
    params: &Params,
    contexts: &[LightContext; LANES],
    sampler: &mut SamplerLanes,
    m: M8,
) -> LightSampleLanes {
    let u0 = sampler.sample_1d(m);
    let (u1, u2) = sampler.sample_2d(m);
    let (u_tree, walking) = tree_numbers(params, u0, m);
    let walks = sample_light_tree_lanes(scene, params, contexts, &u_tree, walking);
    sample_lights(scene, params, contexts, (u0, u1, u2), &walks, m.bits())
}

/// `tree_u` of the first numbers `u0` in the lanes of `m`, and the lanes that walk the tree.
#[inline(always)]
fn tree_numbers(params: &Params, u0: F8, m: M8) -> ([f32; LANES], u32) {
    let mut walking = 0u32;
    let mut u_tree = [0.0f32; LANES];
    for i in lanes_of(m.bits()) {
        if let Some(x) = tree_u(params, u0.0[i]) {
            u_tree[i] = x;
            walking |= 1 << i;
        }
    }
    (u_tree, walking)
}

/// The surface vertex of a packet's plain lanes, as next-event estimation reads it.
struct VertexLanes<'a> {
    point: V3,
    ng: V3,
    frame: [V3; 3],
    wo: V3,
    base: &'a BaseLanes,
    contexts: &'a [LightContext; LANES],
}

/// Weighted reservoir sampling of light candidates in lanes: `path_resample_lights`'s stream
/// (each candidate weighed by its MIS weight times its target over its density, one kept in
/// proportion to its weight), the scalar's operations lane by lane.
struct Reservoir {
    u_pick: F8,
    w_sum: F8,
    kept: LightSampleLanes,
    kept_c: V3,
    kept_target: F8,
    kept_any: M8,
}

impl Reservoir {
    #[inline(always)]
    fn new(u_pick: F8) -> Reservoir {
        let zero = F8::splat(0.0);
        Reservoir {
            u_pick,
            w_sum: zero,
            kept: LightSampleLanes::zero(),
            kept_c: V3::splat(Vec3::ZERO),
            kept_target: zero,
            kept_any: M8::splat(false),
        }
    }

    /// The candidate `ls`, one of `count`, in the lanes of `m`.
    #[inline(always)]
    fn stream(&mut self, strategy: Strategy, sv: &VertexLanes, ls: &LightSampleLanes, count: u32, m: M8) {
        let zero = F8::splat(0.0);
        let mut open = m & ls.pdf.gt(zero) & (ls.delta | M8::splat(strategy != Strategy::Bsdf));
        let wi_local = to_local(&sv.frame, ls.wi);
        let (above, local_above) = (ls.wi.dot(sv.ng).gt(zero), wi_local.z.gt(zero));
        open = open & ((above & local_above) | (!above & !local_above));
        if open.bits() == 0 {
            return;
        }
        let c = base_eval(sv.base, sv.wo, wi_local) * wi_local.z.abs() * ls.radiance;
        let target = luminance(c);
        open = open & target.gt(zero);
        let share = F8::splat(1.0 / count as f32);
        let pdf_b = base_pdf(sv.base, sv.wo, wi_local) / candidate_pdf_scale(strategy, count);
        let unweighed = M8::splat(strategy == Strategy::Light) | ls.delta;
        let mis = F8::select(unweighed, share, share * mis_weight(strategy, ls.pdf, pdf_b));
        let w = mis * target / ls.pdf;
        open = open & w.gt(zero);
        if open.bits() == 0 {
            return;
        }
        self.w_sum = F8::select(open, self.w_sum + w, self.w_sum);
        // One number picks among the candidates as they stream by, rescaled after each.
        let p = w / self.w_sum;
        let pick = open & self.u_pick.lt(p);
        let u = self.u_pick;
        let rescaled = F8::select(pick, u / p, (u - p) / (1.0 - p)).min_num(F8::splat(ONE_MINUS_EPSILON));
        self.u_pick = F8::select(open, rescaled, u);
        self.kept = LightSampleLanes::select(pick, ls, &self.kept);
        self.kept_c = V3::select(pick, c, self.kept_c);
        self.kept_target = F8::select(pick, target, self.kept_target);
        self.kept_any = self.kept_any | pick;
    }

    /// The kept candidate connected (one shadow ray per lane), its contribution scaled by the
    /// weights' sum over its target.
    #[inline(always)]
    fn connect(&self, scene: &PackedScene, params: &Params, paths: &mut Paths, sv: &VertexLanes) {
        if self.kept_any.bits() == 0 {
            return;
        }
        let lit = unoccluded(scene, spawn_point(sv.point, sv.ng, self.kept.wi), &self.kept, self.kept_any);
        if lit.bits() != 0 {
            let depth1 = paths.depth.map(|d| d + 1);
            let c = paths.beta * self.kept_c * (self.w_sum / self.kept_target);
            paths.radiance = V3::select(lit, paths.radiance + clamp_contribution(params, c, depth1), paths.radiance);
        }
    }
}

/// `path_resample_lights` in the lanes of `m` (glossy surfaces, `params.light_candidates`
/// candidates each): the candidates drawn, weighed and one kept per lane as the scalar streams
/// them, then one shadow ray per lane. Out of line, so that the packet kernel, which most
/// bounces run without it, stays as it was (and quick to compile); compiled for AVX2 where the
/// CPU has it (checked at run time, a cached load), as `trace_paths`.
#[inline(never)]
fn resample_lights(scene: &PackedScene, params: &Params, paths: &mut Paths, sv: &VertexLanes, m: M8) {
    #[cfg(target_arch = "x86_64")]
    {
        assert!(super::available(), "the lanes kernel needs AVX2 on x86-64 (`lanes::available`)");
        // SAFETY: the CPU has AVX2 (checked just above).
        unsafe { resample_lights_avx2(scene, params, paths, sv, m) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    resample_lights_loop(scene, params, paths, sv, m)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn resample_lights_avx2(scene: &PackedScene, params: &Params, paths: &mut Paths, sv: &VertexLanes, m: M8) {
    resample_lights_loop(scene, params, paths, sv, m)
}

#[inline(always)]
fn resample_lights_loop(scene: &PackedScene, params: &Params, paths: &mut Paths, sv: &VertexLanes, m: M8) {
    let strategy = path_strategy(params);
    let count = params.light_candidates;
    let zero = F8::splat(0.0);
    let mut reservoir = Reservoir::new(zero);
    // Up to MAX_CANDIDATES candidates at a time: their numbers first, then their tree walks
    // together (a path's candidates share the steps they take from the same groups), then
    // their samples, streamed in order.
    let mut first = 0;
    while first < count {
        let batch = ((count - first) as usize).min(MAX_CANDIDATES);
        let mut draws = [(zero, zero, zero); MAX_CANDIDATES];
        let mut u_tree = [0.0f32; MAX_CANDIDATES * LANES];
        let mut walking = 0u32;
        for (j, draw) in draws.iter_mut().enumerate().take(batch) {
            // Each lane's draws in the scalar's order: candidate 0, the picking number, the rest.
            let u0 = paths.sampler.sample_1d(m);
            let (u1, u2) = paths.sampler.sample_2d(m);
            if first == 0 && j == 0 {
                reservoir.u_pick = paths.sampler.sample_1d(m);
            }
            *draw = (u0, u1, u2);
            let (u, walks) = tree_numbers(params, u0, m);
            u_tree[j * LANES..(j + 1) * LANES].copy_from_slice(&u);
            walking |= walks << (j * LANES);
        }
        let walks = sample_light_tree_candidates(scene, params, sv.contexts, &u_tree, walking);
        for (j, &draw) in draws.iter().enumerate().take(batch) {
            let mut of_candidate = [(0u32, 0.0f32); LANES];
            of_candidate.copy_from_slice(&walks[j * LANES..(j + 1) * LANES]);
            let ls = sample_lights(scene, params, sv.contexts, draw, &of_candidate, m.bits());
            reservoir.stream(strategy, sv, &ls, count, m);
        }
        first += batch as u32;
    }
    reservoir.connect(scene, params, paths, sv);
}

/// `path_connect_light` in the lanes of `m`: the light sample connected by a shadow ray and
/// weighted by MIS.
#[inline(always)]
fn connect_light(
    scene: &PackedScene,
    params: &Params,
    paths: &mut Paths,
    sv: &VertexLanes,
    ls: &LightSampleLanes,
    m: M8,
) {
    let strategy = path_strategy(params);
    let zero = F8::splat(0.0);
    let connecting = m & (ls.delta | M8::splat(strategy != Strategy::Bsdf));
    if connecting.bits() == 0 {
        return;
    }
    let wi_local = to_local(&sv.frame, ls.wi);
    let f = base_eval(sv.base, sv.wo, wi_local);
    let pdf_b = base_pdf(sv.base, sv.wo, wi_local);
    let c = connect_evaluated(scene, sv.point, sv.ng, ls, wi_local, f, connecting & ls.pdf.gt(zero));
    let add = connecting & c.max_element().gt(zero);
    if add.bits() != 0 {
        let w = F8::select(
            M8::splat(strategy == Strategy::Light) | ls.delta,
            F8::splat(1.0),
            mis_weight(strategy, ls.pdf, pdf_b),
        );
        let depth1 = paths.depth.map(|d| d + 1);
        let contribution = clamp_contribution(params, paths.beta * c * (w / ls.pdf), depth1);
        paths.radiance = V3::select(add, paths.radiance + contribution, paths.radiance);
    }
}

/// `frame_from_normal` in lanes: (t, b, n).
#[inline(always)]
fn frame_from_normal(n: V3) -> [V3; 3] {
    let one = F8::splat(1.0);
    let s = F8::select(n.z.ge(F8::splat(0.0)), one, F8::splat(-1.0));
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = V3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = V3::new(b, s + n.y * n.y * a, -n.y);
    [t, bt, n]
}

#[inline(always)]
fn to_local(f: &[V3; 3], v: V3) -> V3 {
    V3::new(v.dot(f[0]), v.dot(f[1]), v.dot(f[2]))
}

#[inline(always)]
fn from_local(f: &[V3; 3], v: V3) -> V3 {
    f[0] * v.x + f[1] * v.y + f[2] * v.z
}

#[inline(always)]
fn luminance(c: V3) -> F8 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// `lobe_probabilities` of plain materials (`bsdf::lobe_weights` with their transmission and
/// diffuse transmission, both without a lobe).
#[inline(always)]
fn lobe_probabilities(m: &BaseLanes, cos_o: F8, eta: F8) -> [F8; 4] {
    use super::bsdf::{bsdf_fresnel, dielectric_fresnel, diffuse_albedo};
    let zero = F8::splat(0.0);
    let one = V3::splat(Vec3::ONE);
    let alpha = m.roughness * m.roughness;
    let transmitted = (1.0 - m.metallic) * m.transmission * m.base_color * (one - dielectric_fresnel(m, cos_o));
    let mut wt = luminance(transmitted);
    let rough = (alpha * (1.0 - 1.0 / eta).abs()).ge(F8::splat(crate::cpu::microfacet::DELTA_ALPHA));
    let floor = 0.1 * (1.0 - m.metallic) * m.transmission * luminance(m.base_color);
    wt = F8::select(rough, wt.max_num(floor), wt);
    // luminance(0) of the absent diffuse transmission.
    let w = [luminance(bsdf_fresnel(m, cos_o)), luminance(diffuse_albedo(m, cos_o)), wt, zero * 0.2126];
    let total = w[0] + w[1] + w[2] + w[3];
    let none = total.le(zero);
    let p = |k: usize| F8::select(none, zero, w[k] / total);
    [p(0), p(1), p(2), p(3)]
}

/// One bounce of the lanes of `lanes` (plain surfaces hit): `path_surface`, `path_next_event`
/// and `path_scatter` of `integrator.rs`, the same operations lane by lane. Returns the lanes
/// that go on.
#[inline(always)]
fn bounce_plain(scene: &PackedScene, params: &Params, paths: &mut Paths, hits: &[Hit; LANES], lanes: u32) -> u32 {
    let strategy = path_strategy(params);
    let on = M8::from_bits(lanes);
    let zero = F8::splat(0.0);
    let index = |i: usize| if lanes >> i & 1 != 0 { hits[i].tri as usize } else { 0 };
    let tri = |i: usize| &scene.triangles[index(i)];
    let mat = |i: usize| &scene.materials[tri(i).material as usize];

    // The surface: the triangle's point and normals, the material.
    let p0 = V3::from_fn(|i| Vec3::from(tri(i).p0));
    let e1 = V3::from_fn(|i| Vec3::from(tri(i).e1));
    let e2 = V3::from_fn(|i| Vec3::from(tri(i).e2));
    let (u, v, t) = (F8::from_fn(|i| hits[i].u), F8::from_fn(|i| hits[i].v), F8::from_fn(|i| hits[i].t));
    let point = p0 + u * e1 + v * e2;
    let ng_cross = e1.cross(e2).normalize();
    let mirrored = M8::from_fn(|i| tri(i).flags & TRI_MIRRORED != 0);
    let ng_raw = V3::select(mirrored, -ng_cross, ng_cross);
    let dir = paths.dir;
    let cos_hit = dir.dot(ng_raw);
    let base = BaseLanes::gather(|i| (lanes >> i & 1 != 0).then(|| mat(i)), |_| Vec4::ZERO);
    let emission = V3::from_fn(|i| Vec3::from(mat(i).emission));

    // Emission found by the previous vertex's BSDF sample (or the camera ray).
    let emits = on & cos_hit.lt(zero) & emission.max_element().gt(zero);
    if emits.bits() != 0 {
        let weighed = emits & paths.depth.gt(1) & !paths.prev_delta;
        let mut w = F8::splat(1.0);
        match strategy {
            Strategy::Light => w = F8::select(weighed, zero, w),
            Strategy::Bsdf => {}
            _ => {
                let mut light = [0.0f32; LANES];
                for i in lanes_of(weighed.bits()) {
                    let ctx = LightContext {
                        point: paths.prev_point.lane(i),
                        normal: paths.prev_normal.lane(i),
                        reflect_only: paths.prev_reflect_only.lane(i),
                    };
                    let (d, ti) = (dir.lane(i), t.0[i]);
                    light[i] = light_pdf(scene, params, &ctx, tri(i), d, ti * ti, cos_hit.0[i]);
                }
                w = F8::select(weighed, mis_weight(strategy, paths.prev_pdf, F8(light)), w);
            }
        }
        let c = clamp_contribution(params, paths.beta * emission * w, paths.depth);
        paths.radiance = V3::select(emits, paths.radiance + c, paths.radiance);
    }
    let last = M8::splat(params.max_depth != 0) & paths.depth.ge(params.max_depth);
    let live = on & !last;
    if live.bits() == 0 {
        return 0;
    }

    let ng = V3::select(cos_hit.gt(zero), -ng_raw, ng_raw);
    let ior = F8::from_fn(|i| mat(i).ior);
    let eta = F8::select(cos_hit.lt(zero), ior, 1.0 / ior);
    let mut ns = ng_raw;
    for i in lanes_of(live.bits()) {
        if tri(i).flags & TRI_HAS_NORMALS != 0 {
            let n =
                shading_normal(scene, tri(i), index(i) as u32, 0, u.0[i], v.0[i], ng_raw.lane(i), mat(i), Vec4::ZERO);
            ns.set_lane(i, n);
        }
    }
    ns = V3::select(ns.dot(dir).gt(zero), -ns, ns);
    let frame = frame_from_normal(ns);
    let wo = to_local(&frame, -dir);
    let mut base = base;
    base.p = lobe_probabilities(&base, wo.z, eta);

    // Next-event estimation: one light sample, or at glossy surfaces the one kept of several.
    let count = params.light_candidates;
    // `light_candidates(params, m) > 1`: a plain material has no coat, so glossy = its base's
    // lobe is (`material_glossy`).
    let resampled = if params.light_candidates > 1 && strategy != Strategy::Bsdf {
        live & glossy_lobe(base.roughness)
    } else {
        M8::splat(false)
    };
    if next_event_wanted(params) {
        let contexts = per_lane(|i| LightContext { point: point.lane(i), normal: ns.lane(i), reflect_only: true });
        let sv = VertexLanes { point, ng, frame, wo, base: &base, contexts: &contexts };
        let single = live & !resampled;
        if single.bits() != 0 {
            let ls = sample_light(scene, params, &contexts, &mut paths.sampler, single);
            connect_light(scene, params, paths, &sv, &ls, single);
        }
        if resampled.bits() != 0 {
            resample_lights(scene, params, paths, &sv, resampled);
        }
    }

    // The BSDF sample that continues the path, then Russian roulette.
    let u0 = paths.sampler.sample_1d(live);
    let (u1, u2) = paths.sampler.sample_2d(live);
    let bs = base_sample(&base, wo, V3::new(u0, u1, u2));
    let mut go = live & bs.pdf.gt(zero);
    let wi = from_local(&frame, bs.wi);
    let (above, local_above) = (wi.dot(ng).gt(zero), bs.wi.z.gt(zero));
    go = go & ((above & local_above) | (!above & !local_above));
    paths.beta = V3::select(go, paths.beta * bs.weight, paths.beta);
    go = go & paths.beta.max_element().gt(zero);
    // Against several light candidates MIS sees the BSDF's density scaled down.
    let mut pdf = bs.pdf;
    if resampled.bits() != 0 {
        pdf = F8::select(resampled, bs.pdf / F8::splat(candidate_pdf_scale(strategy, count)), pdf);
    }
    paths.prev_pdf = F8::select(go, pdf, paths.prev_pdf);
    paths.prev_delta = (go & bs.delta) | (!go & paths.prev_delta);
    paths.prev_point = V3::select(go, point, paths.prev_point);
    paths.prev_normal = V3::select(go, ns, paths.prev_normal);
    paths.prev_reflect_only = paths.prev_reflect_only | go;
    paths.origin = V3::select(go, spawn_point(point, ng, wi), paths.origin);
    paths.dir = V3::select(go, wi, paths.dir);
    let roulette = go & paths.depth.ge(params.rr_depth);
    if roulette.bits() != 0 {
        // (Plain surfaces do not refract: `eta_scale` is what the path brought here.)
        let q = (paths.beta * paths.eta_scale).max_element().min_num(F8::splat(0.95));
        let x = paths.sampler.sample_1d(roulette);
        let ends = roulette & x.ge(q);
        go = go & !ends;
        paths.beta = V3::select(roulette & !ends, paths.beta / q, paths.beta);
    }
    go.bits()
}
