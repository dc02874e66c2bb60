//! Twin of `shaders/integrator.wgsl`: the path tracer, sample for sample.

use super::bsdf::{
    BsdfSample, DELTA_ALPHA, LobeChoice, bsdf_albedo, bsdf_eval, bsdf_is_delta, bsdf_pdf_chosen, bsdf_sample_chosen,
    lobe_choice, refracted,
};
use super::bvh::{Hit, NO_HIT, intersect_closest, occluded, offset_ray};
use super::camera::camera_sample;
use super::common::{INF, ONE_MINUS_EPSILON, Ray, luminance};
use super::environment::{environment_pdf, environment_radiance};
use super::frame::{Frame, frame_from_normal, from_local, to_local};
use super::instance::world_triangle;
use super::light_tree::LightContext;
use super::lights::{LightSample, light_pdf, sample_light, sample_punctual};
use super::material::{
    anisotropy_direction, coat_normal, dispersed_ior, material_at, shading_normal, triangle_uv, vertex_color,
};
use super::mis::mis_weight;
use super::sampler::{Sampler, sample_1d, sample_2d};
use crate::Strategy;
use crate::aov::AovSample;
use crate::packed::{MAT_THIN_WALLED, Material, NO_TEXTURE, PackedScene, TRI_MIRRORED};
use crate::params::{LIGHT_SAMPLER_TREE, Params};
use glam::{UVec2, Vec3, Vec4};
use std::borrow::Cow;

/// A path's colour channel before it meets a dispersive surface: all three.
pub const ALL_CHANNELS: u32 = 3;

pub fn same_side(wi: Vec3, ng: Vec3, wi_local: Vec3) -> bool {
    (wi.dot(ng) > 0.0) == (wi_local.z > 0.0)
}

pub fn spawn_point(point: Vec3, ng: Vec3, wi: Vec3) -> Vec3 {
    offset_ray(point, if wi.dot(ng) > 0.0 { ng } else { -ng })
}

/// Twin of `connect` in the shader: f · |cos θ| · L, or 0 (blocked, zero BSDF, no density).
#[allow(clippy::too_many_arguments)]
pub fn connect(
    scene: &PackedScene,
    m: &Material,
    frame: &Frame,
    wo: Vec3,
    eta: f32,
    point: Vec3,
    ng: Vec3,
    ls: &LightSample,
) -> Vec3 {
    if ls.pdf <= 0.0 {
        return Vec3::ZERO;
    }
    let wi_local = to_local(frame, ls.wi);
    let f = bsdf_eval(m, wo, wi_local, eta);
    connect_evaluated(scene, point, ng, ls, wi_local, f)
}

/// `connect` once the BSDF's value `f` for the light sample (`wi_local` in the shading
/// frame, `ls.pdf` > 0) is known: the side test, then the shadow ray.
#[inline(always)]
pub fn connect_evaluated(
    scene: &PackedScene,
    point: Vec3,
    ng: Vec3,
    ls: &LightSample,
    wi_local: Vec3,
    f: Vec3,
) -> Vec3 {
    if !same_side(ls.wi, ng, wi_local)
        || f.max_element() <= 0.0
        || !unoccluded(scene, spawn_point(point, ng, ls.wi), ls)
    {
        return Vec3::ZERO;
    }
    f * wi_local.z.abs() * ls.radiance
}

/// Whether nothing blocks the segment from `origin` to the light sample (twin of `unoccluded`).
pub fn unoccluded(scene: &PackedScene, origin: Vec3, ls: &LightSample) -> bool {
    let (ray, t_max) = shadow_ray(origin, ls);
    !occluded(scene, &ray, t_max)
}

/// The shadow ray from `origin` to the light sample and its extent: towards an environment
/// or a distant light without end; to an emitter's point, moved just off its surface, as the
/// segment's parameter 1.
#[inline(always)]
pub fn shadow_ray(origin: Vec3, ls: &LightSample) -> (Ray, f32) {
    if ls.dist == INF {
        return (Ray { origin, dir: ls.wi }, INF);
    }
    let target = offset_ray(ls.point, ls.normal);
    (Ray { origin, dir: target - origin }, 1.0)
}

/// Twin of `clamp_contribution`: firefly control, a contribution carried by a path of
/// `segments` segments scaled so that its components sum to at most the limit of its kind
/// (direct light: seen directly or after one bounce).
pub fn clamp_contribution(params: &Params, c: Vec3, segments: u32) -> Vec3 {
    let limit = if segments <= 2 { params.clamp_direct } else { params.clamp_indirect };
    let sum = c.x + c.y + c.z;
    if sum > limit { c * (limit / sum) } else { c }
}

/// A path between its vertices: everything the path tracer carries from one bounce to the
/// next. The stages below (`path_escaped`, `path_surface`, `path_next_event`, `path_scatter`)
/// each advance it by one step of `li`, so a scalar loop over them is the reference integrator
/// and an engine running paths in lanes can run each stage over many paths.
#[derive(Clone, Copy, Debug)]
pub struct PathState {
    pub ray: Ray,
    pub radiance: Vec3,
    pub beta: Vec3,
    /// The product of η² over the refractions so far: `beta · eta_scale` is the throughput
    /// without the 1/η² that radiance gains entering a denser medium, which leaving undoes, so
    /// Russian roulette does not end paths inside glass for it (pbrt-v4's and Mitsuba's rule).
    pub eta_scale: f32,
    /// Path segments so far (Mitsuba's depth): 1 after the camera ray's hit.
    pub depth: u32,
    /// The previous vertex's BSDF sample: its density (divided by `candidate_pdf_scale` where
    /// next-event estimation resampled several light candidates) and whether it was a Dirac one.
    pub prev_pdf: f32,
    pub prev_delta: bool,
    /// The previous vertex as light selection saw it (for the tree's probability on a hit).
    pub prev_ctx: LightContext,
    /// The AOVs look through Dirac surfaces, weighted by the path's own throughput there.
    pub aov_open: bool,
    pub aov_weight: Vec3,
    pub aov: AovSample,
    /// The colour channel a dispersive surface chose (ALL_CHANNELS before one).
    pub channel: u32,
    pub sampler: Sampler,
}

impl PathState {
    /// A path starting along `camera_ray`, drawing from `sampler`.
    pub fn new(params: &Params, camera_ray: Ray, sampler: Sampler) -> PathState {
        PathState {
            ray: camera_ray,
            radiance: Vec3::ZERO,
            beta: Vec3::ONE,
            eta_scale: 1.0,
            depth: 0,
            prev_pdf: 0.0,
            prev_delta: true,
            prev_ctx: LightContext { point: Vec3::ZERO, normal: Vec3::Z, reflect_only: false },
            aov_open: params.aov_base > 0,
            aov_weight: Vec3::ONE,
            aov: AovSample::default(),
            channel: ALL_CHANNELS,
            sampler,
        }
    }
}

/// The surface at a path's vertex, as `path_surface` prepares it for light and BSDF sampling.
#[derive(Clone, Debug)]
pub struct SurfaceVertex<'a> {
    /// The material at the point (textures applied, the path's dispersion ior, the coat
    /// normal and anisotropy direction in the local frame): borrowed from the scene when
    /// none of these changes it, the common case, else a copy (~740 bytes).
    pub mat: Cow<'a, Material>,
    pub point: Vec3,
    /// Geometric normal on the side the ray arrived from.
    pub ng: Vec3,
    /// Relative ior across the surface from the arriving side.
    pub eta: f32,
    pub frame: Frame,
    pub wo: Vec3,
    pub ctx: LightContext,
    /// The BSDF's lobe probabilities from `wo`, for both of the vertex's samples.
    pub lobes: LobeChoice,
}

/// The strategy of the direct-lighting estimator (`params.strategy`).
pub fn path_strategy(params: &Params) -> Strategy {
    Strategy::try_from(params.strategy).unwrap_or(Strategy::MisPower)
}

/// The path's ray left the scene: the environment, weighted by MIS against the environment's
/// light sample when the previous vertex could have sampled it.
#[inline(always)]
pub fn path_escaped(scene: &PackedScene, params: &Params, path: &mut PathState) {
    let strategy = path_strategy(params);
    let mut w = 1.0;
    if path.depth > 1 && !path.prev_delta && params.env_select > 0.0 {
        match strategy {
            Strategy::Light => w = 0.0,
            Strategy::Bsdf => {}
            _ => w = mis_weight(strategy, path.prev_pdf, environment_pdf(scene, params, path.ray.dir)),
        }
    }
    path.radiance +=
        clamp_contribution(params, path.beta * environment_radiance(scene, params, path.ray.dir) * w, path.depth);
}

/// The path's ray hit a surface: absorption inside a volume it leaves, emission (MIS-weighted
/// against the previous vertex's light sample), the dispersion channel, the shading frame and
/// the AOVs. None when the path ends here (its last segment).
#[inline(always)]
pub fn path_surface<'a>(
    scene: &'a PackedScene,
    params: &Params,
    path: &mut PathState,
    hit: &Hit,
) -> Option<SurfaceVertex<'a>> {
    let strategy = path_strategy(params);
    let ray = path.ray;
    let depth = path.depth;
    let tri = &world_triangle(scene, hit.tri, hit.instance);
    let stored = &scene.materials[tri.material as usize];
    // UVs only matter to textures; without textures or vertex colours the material at the
    // point is the stored one (what material_at would copy).
    let textured = scene.material_textured[tri.material as usize];
    let uv = if textured { triangle_uv(scene, hit.tri, hit.u, hit.v) } else { Vec4::ZERO };
    let color = vertex_color(scene, hit.tri, hit.u, hit.v);
    let mut mat = if textured || color != Vec4::ONE {
        Cow::Owned(material_at(scene, stored, uv, color))
    } else {
        Cow::Borrowed(stored)
    };
    let m = &*mat;
    let (e1, e2) = (Vec3::from(tri.e1), Vec3::from(tri.e2));
    let point = Vec3::from(tri.p0) + hit.u * e1 + hit.v * e2;
    let ng_cross = e1.cross(e2).normalize();
    let ng_raw = if tri.flags & TRI_MIRRORED != 0 { -ng_cross } else { ng_cross };
    let cos_hit = ray.dir.dot(ng_raw);
    let attenuation = Vec3::from(m.attenuation);
    if cos_hit > 0.0 && attenuation.max_element() > 0.0 {
        path.beta *= (-attenuation * hit.t).exp();
    }
    let emission = Vec3::from(m.emission);

    if cos_hit < 0.0 && emission.max_element() > 0.0 {
        let mut w = 1.0;
        if depth > 1 && !path.prev_delta {
            match strategy {
                Strategy::Light => w = 0.0,
                Strategy::Bsdf => {}
                _ => {
                    w = mis_weight(
                        strategy,
                        path.prev_pdf,
                        light_pdf(scene, params, &path.prev_ctx, tri, ray.dir, hit.t * hit.t, cos_hit),
                    )
                }
            }
        }
        path.radiance += clamp_contribution(params, path.beta * emission * w, depth);
    }
    let last = params.max_depth != 0 && depth >= params.max_depth;
    if last && !path.aov_open {
        return None;
    }

    // KHR_materials_dispersion: a refracting solid bends each colour its own way. From its
    // first such surface on, the path follows one channel, chosen uniformly and weighted
    // 3× (the others dropped): an unbiased estimate of every channel.
    if mat.dispersion > 0.0 && mat.transmission > 0.0 && mat.flags & MAT_THIN_WALLED == 0 {
        if path.channel == ALL_CHANNELS {
            path.channel = ((sample_1d(&mut path.sampler) * 3.0) as u32).min(2);
            let mut mask = Vec3::ZERO;
            mask[path.channel as usize] = 3.0;
            path.beta *= mask;
        }
        let ior = dispersed_ior(mat.ior, mat.dispersion, path.channel);
        mat.to_mut().ior = ior;
    }
    let m = &*mat;
    let ng = if cos_hit > 0.0 { -ng_raw } else { ng_raw };
    // A thin wall has air on both sides.
    let eta = if cos_hit < 0.0 || m.flags & MAT_THIN_WALLED != 0 { m.ior } else { 1.0 / m.ior };
    let mut ns = shading_normal(scene, tri, hit.tri, hit.instance, hit.u, hit.v, ng_raw, m, uv);
    if ns.dot(ray.dir) > 0.0 {
        ns = -ns;
    }
    let frame = frame_from_normal(ns);
    let wo = to_local(&frame, -ray.dir);
    // A coat follows its own normal map, or the interpolated normal when the base's is mapped.
    if mat.clearcoat > 0.0
        && (mat.normal_texture.atlas != NO_TEXTURE || mat.clearcoat_normal_texture.atlas != NO_TEXTURE)
    {
        let mut nc = coat_normal(scene, tri, hit.tri, hit.instance, hit.u, hit.v, ng_raw, &mat, uv);
        if nc.dot(ray.dir) > 0.0 {
            nc = -nc;
        }
        mat.to_mut().coat_normal = to_local(&frame, nc).into();
    }
    // Anisotropy turns with the tangent frame; without tangents the lobe stays isotropic.
    if mat.anisotropy > 0.0 {
        let d = to_local(&frame, anisotropy_direction(scene, tri, hit.tri, hit.instance, hit.u, hit.v, ns, &mat, uv));
        let len = (d.x * d.x + d.y * d.y).sqrt();
        if len > 1e-6 {
            mat.to_mut().anisotropy_tangent = [d.x / len, d.y / len];
        } else {
            mat.to_mut().anisotropy = 0.0;
        }
    }
    let m = &*mat;
    if path.aov_open {
        if depth == 1 {
            path.aov.depth = hit.t;
        }
        path.aov.albedo = (path.aov_weight * bsdf_albedo(m, wo, eta)).clamp(Vec3::ZERO, Vec3::ONE);
        path.aov.normal = ns;
        path.aov_open = bsdf_is_delta(m, wo, eta);
    }
    if last {
        return None;
    }
    let ctx = LightContext { point, normal: ns, reflect_only: m.transmission <= 0.0 && m.diffuse_transmission <= 0.0 };
    let lobes = lobe_choice(m, wo, eta);
    Some(SurfaceVertex { mat, point, ng, eta, frame, wo, ctx, lobes })
}

/// Whether next-event estimation runs at a vertex. With the BSDF strategy alone it still runs
/// for the tree's Dirac lights, which nothing else can find.
#[inline(always)]
pub fn next_event_wanted(params: &Params) -> bool {
    let nee_lights = if params.light_sampler == LIGHT_SAMPLER_TREE { params.tree_emitters } else { params.light_count };
    if path_strategy(params) == Strategy::Bsdf {
        params.light_sampler == LIGHT_SAMPLER_TREE && params.tree_emitters > params.light_count
    } else {
        nee_lights > 0 || params.env_select > 0.0
    }
}

/// Perceptual roughness below which a reflection lobe counts as glossy: narrow enough that a
/// light chosen without the BSDF rarely falls inside it (GGX α < 0.25).
pub const GLOSSY_ROUGHNESS: f32 = 0.5;

/// Is a GGX lobe of perceptual roughness `r` glossy (narrow, but not a Dirac one)? The lanes
/// kernel's twin takes the same test lane by lane.
#[inline(always)]
pub fn glossy_lobe(r: f32) -> bool {
    r < GLOSSY_ROUGHNESS && r * r >= DELTA_ALPHA
}

/// Has the material a glossy reflection lobe (in the base or the coat)? A function of the
/// material alone, so that the lanes kernel can tell too.
#[inline(always)]
pub fn material_glossy(m: &Material) -> bool {
    glossy_lobe(m.roughness) || (m.clearcoat > 0.0 && glossy_lobe(m.clearcoat_roughness))
}

/// Light candidates next-event estimation resamples at a vertex of material `m`: the
/// sampler's count at glossy surfaces, else 1 (one light sample, as the tree alone).
#[inline(always)]
pub fn light_candidates(params: &Params, m: &Material) -> u32 {
    if params.light_candidates > 1 && path_strategy(params) != Strategy::Bsdf && material_glossy(m) {
        params.light_candidates
    } else {
        1
    }
}

/// MIS weighs `count` light candidates of density p against the BSDF's one sample as one
/// sample of density count·p (balance heuristic) or √count·p (power heuristic, whose weights
/// go by squares); the BSDF's density divided by this factor keeps the two-strategy weight.
#[inline(always)]
pub fn candidate_pdf_scale(strategy: Strategy, count: u32) -> f32 {
    if count <= 1 {
        1.0
    } else if strategy == Strategy::MisBalance {
        count as f32
    } else {
        (count as f32).sqrt()
    }
}

/// Next-event estimation at the vertex: one light sample (or the one kept of several
/// candidates at a glossy surface, `path_resample_lights`), and one of the separately sampled
/// punctual lights, each connected by a shadow ray and weighted by MIS.
#[inline(always)]
pub fn path_next_event(scene: &PackedScene, params: &Params, path: &mut PathState, sv: &SurfaceVertex) {
    let strategy = path_strategy(params);
    let m = &sv.mat;
    if next_event_wanted(params) {
        let u0 = sample_1d(&mut path.sampler);
        let u12 = sample_2d(&mut path.sampler);
        let ls = sample_light(scene, params, &sv.ctx, Vec3::new(u0, u12.x, u12.y));
        let count = light_candidates(params, m);
        if count > 1 {
            path_resample_lights(scene, params, strategy, path, sv, ls, count);
        } else {
            path_connect_light(scene, params, strategy, path, sv, &ls);
        }
    }
    if params.separate_punctuals > 0 {
        let ls = sample_punctual(scene, params, sv.point, sample_1d(&mut path.sampler));
        let c = path.beta * connect(scene, m, &sv.frame, sv.wo, sv.eta, sv.point, sv.ng, &ls) / ls.pdf.max(1e-30);
        path.radiance += clamp_contribution(params, c, path.depth + 1);
    }
}

/// Resampled next-event estimation (RIS with MIS-weighted candidates): `count` light samples
/// (`first`, then more from the sampler), each weighed by its unshadowed contribution's
/// luminance (f · |cos θ| · L, the target) over its density, times its MIS weight among the
/// candidates and the BSDF sample; one is kept in proportion to its weight and connected by one
/// shadow ray, its contribution scaled by the weights' sum over its target. Unbiased: each
/// candidate contributes m · f · L · V / p in expectation, the `count` weights m and the BSDF
/// sample's (its density divided by `candidate_pdf_scale`) sum to 1.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub fn path_resample_lights(
    scene: &PackedScene,
    params: &Params,
    strategy: Strategy,
    path: &mut PathState,
    sv: &SurfaceVertex,
    first: LightSample,
    count: u32,
) {
    let m = &*sv.mat;
    let scale = candidate_pdf_scale(strategy, count);
    let share = 1.0 / count as f32;
    let mut u_pick = sample_1d(&mut path.sampler);
    let mut w_sum = 0.0;
    let mut kept: Option<(LightSample, Vec3, f32)> = None;
    for k in 0..count {
        let ls = if k == 0 {
            first
        } else {
            let u0 = sample_1d(&mut path.sampler);
            let u12 = sample_2d(&mut path.sampler);
            sample_light(scene, params, &sv.ctx, Vec3::new(u0, u12.x, u12.y))
        };
        if ls.pdf <= 0.0 || !(ls.delta || strategy != Strategy::Bsdf) {
            continue;
        }
        let wi_local = to_local(&sv.frame, ls.wi);
        if !same_side(ls.wi, sv.ng, wi_local) {
            continue;
        }
        let c = bsdf_eval(m, sv.wo, wi_local, sv.eta) * wi_local.z.abs() * ls.radiance;
        let target = luminance(c);
        if target <= 0.0 {
            continue;
        }
        let mis = if strategy == Strategy::Light || ls.delta {
            share
        } else {
            share * mis_weight(strategy, ls.pdf, bsdf_pdf_chosen(m, &sv.lobes, sv.wo, wi_local, sv.eta) / scale)
        };
        let w = mis * target / ls.pdf;
        if w <= 0.0 {
            continue;
        }
        w_sum += w;
        // One number picks among the candidates as they stream by, rescaled after each.
        let p = w / w_sum;
        if u_pick < p {
            kept = Some((ls, c, target));
            u_pick = (u_pick / p).min(ONE_MINUS_EPSILON);
        } else {
            u_pick = ((u_pick - p) / (1.0 - p)).min(ONE_MINUS_EPSILON);
        }
    }
    if let Some((ls, c, target)) = kept
        && unoccluded(scene, spawn_point(sv.point, sv.ng, ls.wi), &ls)
    {
        path.radiance += clamp_contribution(params, path.beta * c * (w_sum / target), path.depth + 1);
    }
}

/// The light sample `ls` of next-event estimation, connected and weighted into the path's
/// radiance.
#[inline(always)]
pub fn path_connect_light(
    scene: &PackedScene,
    params: &Params,
    strategy: Strategy,
    path: &mut PathState,
    sv: &SurfaceVertex,
    ls: &LightSample,
) {
    if ls.delta || strategy != Strategy::Bsdf {
        let m = &*sv.mat;
        let c = connect(scene, m, &sv.frame, sv.wo, sv.eta, sv.point, sv.ng, ls);
        path_add_light(params, strategy, path, ls, c, || {
            bsdf_pdf_chosen(m, &sv.lobes, sv.wo, to_local(&sv.frame, ls.wi), sv.eta)
        });
    }
}

/// Adds a connected light sample's contribution `c`, weighted by MIS against the BSDF's
/// density for its direction (`bsdf_pdf`, asked only when the weight needs it).
#[inline(always)]
pub fn path_add_light(
    params: &Params,
    strategy: Strategy,
    path: &mut PathState,
    ls: &LightSample,
    c: Vec3,
    bsdf_pdf: impl FnOnce() -> f32,
) {
    if c.max_element() > 0.0 {
        let w = if strategy == Strategy::Light || ls.delta { 1.0 } else { mis_weight(strategy, ls.pdf, bsdf_pdf()) };
        path.radiance += clamp_contribution(params, path.beta * c * (w / ls.pdf), path.depth + 1);
    }
}

/// The BSDF sample that continues the path, then Russian roulette. False when the path ends.
#[inline(always)]
pub fn path_scatter(params: &Params, path: &mut PathState, sv: &SurfaceVertex) -> bool {
    let bs = bsdf_sample_chosen(&sv.mat, &sv.lobes, sv.wo, path_scatter_u(path), sv.eta);
    path_continue(params, path, sv, &bs)
}

/// The numbers of the vertex's BSDF sample.
#[inline(always)]
pub fn path_scatter_u(path: &mut PathState) -> Vec3 {
    let u0 = sample_1d(&mut path.sampler);
    let u12 = sample_2d(&mut path.sampler);
    Vec3::new(u0, u12.x, u12.y)
}

/// The path continues along the BSDF sample `bs`, then Russian roulette. False when it ends.
#[inline(always)]
pub fn path_continue(params: &Params, path: &mut PathState, sv: &SurfaceVertex, bs: &BsdfSample) -> bool {
    if bs.pdf <= 0.0 {
        return false;
    }
    let wi = from_local(&sv.frame, bs.wi);
    if !same_side(wi, sv.ng, bs.wi) {
        return false;
    }
    path.beta *= bs.weight;
    if path.aov_open {
        path.aov_weight *= bs.weight;
    }
    if path.beta.max_element() <= 0.0 {
        return false;
    }
    if refracted(&sv.mat, bs.wi) {
        path.eta_scale *= sv.eta * sv.eta;
    }
    // Against several light candidates MIS sees the BSDF's density scaled down.
    let count = light_candidates(params, &sv.mat);
    path.prev_pdf = if count > 1 { bs.pdf / candidate_pdf_scale(path_strategy(params), count) } else { bs.pdf };
    path.prev_delta = bs.delta;
    path.prev_ctx = sv.ctx;
    path.ray = Ray { origin: spawn_point(sv.point, sv.ng, wi), dir: wi };

    if path.depth >= params.rr_depth {
        let q = (path.beta * path.eta_scale).max_element().min(0.95);
        if sample_1d(&mut path.sampler) >= q {
            return false;
        }
        path.beta /= q;
    }
    true
}

/// Runs `path` to its end through the stages: the scalar reference integrator. On x86-64
/// CPUs with AVX2 (checked at run time) the stages run compiled for it: the same operations,
/// so the same bits, in VEX encoding.
pub fn trace_path(scene: &PackedScene, params: &Params, path: &mut PathState) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above).
        return unsafe { trace_path_avx2(scene, params, path) };
    }
    trace_path_stages(scene, params, path)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn trace_path_avx2(scene: &PackedScene, params: &Params, path: &mut PathState) {
    trace_path_stages(scene, params, path)
}

#[inline(always)]
fn trace_path_stages(scene: &PackedScene, params: &Params, path: &mut PathState) {
    loop {
        let hit = intersect_closest(scene, &path.ray);
        path.depth += 1;
        if hit.tri == NO_HIT {
            path_escaped(scene, params, path);
            return;
        }
        let Some(sv) = path_surface(scene, params, path, &hit) else { return };
        path_next_event(scene, params, path, &sv);
        if !path_scatter(params, path, &sv) {
            return;
        }
    }
}

/// Radiance arriving along a camera ray; with AOVs on (`params.aov_base`), what the ray saw of
/// the first visible surface goes into `aov` (`src/aov.rs`).
pub fn li(scene: &PackedScene, params: &Params, camera_ray: Ray, sampler: &mut Sampler, aov: &mut AovSample) -> Vec3 {
    let mut path = PathState::new(params, camera_ray, *sampler);
    trace_path(scene, params, &mut path);
    *sampler = path.sampler;
    *aov = path.aov;
    path.radiance
}

/// Sample `params.sample_index` of one film pixel; returns the radiance (possibly non-finite)
/// and, with AOVs on, what it saw of the first visible surface.
pub fn render_sample(scene: &PackedScene, params: &Params, x: u32, y: u32) -> (Vec3, AovSample) {
    let pixel = UVec2::new(x + params.tile_x, y + params.tile_y);
    let (ray, mut sampler) = camera_sample(params, pixel);
    let mut aov = AovSample::default();
    let l = li(scene, params, ray, &mut sampler, &mut aov);
    (l, aov)
}
