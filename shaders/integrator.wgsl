// The path tracer: one sample per pixel per dispatch, next-event estimation at every vertex
// combined with BSDF sampling by MIS (or either strategy alone). Twin: src/cpu/integrator.rs.
#include "bindings.wgsl"
#include "sampler.wgsl"
#include "frame.wgsl"
#include "bvh.wgsl"
#include "camera.wgsl"
#include "bsdf.wgsl"
#include "lights.wgsl"
#include "mis.wgsl"
#include "film.wgsl"
#include "adaptive.wgsl"
#include "aov.wgsl"
#include "material.wgsl"

// Do the geometric and the shading normal agree on which side `wi` leaves?
fn same_side(wi: vec3<f32>, ng: vec3<f32>, wi_local: vec3<f32>) -> bool {
    return (dot(wi, ng) > 0.0) == (wi_local.z > 0.0);
}

// The surface point moved off the surface to the side `wi` leaves through.
fn spawn_point(point: vec3<f32>, ng: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    return offset_ray(point, select(-ng, ng, dot(wi, ng) > 0.0));
}

// f · |cos θ| · L for a light sample seen from the shading point, or 0 when the sample has no
// density, the BSDF is zero, the two normals disagree on its side, or something blocks it
// (tested last: it is the expensive part).
fn connect(
    m: Material, frame: Frame, wo: vec3<f32>, eta: f32, point: vec3<f32>, ng: vec3<f32>, ls: LightSample
) -> vec3<f32> {
    if (ls.pdf <= 0.0) {
        return vec3<f32>(0.0);
    }
    let wi_local = to_local(frame, ls.wi);
    let f = bsdf_eval(m, wo, wi_local, eta);
    if (!same_side(ls.wi, ng, wi_local) || max_component(f) <= 0.0 || !unoccluded(spawn_point(point, ng, ls.wi), ls)) {
        return vec3<f32>(0.0);
    }
    return f * abs(wi_local.z) * ls.radiance;
}

// Is the light sample visible from `origin`? Segments end just off the light's surface.
fn unoccluded(origin: vec3<f32>, ls: LightSample) -> bool {
    if (ls.dist == INF) {
        return !occluded(Ray(origin, ls.wi), INF);
    }
    let target_point = offset_ray(ls.point, ls.normal);
    return !occluded(Ray(origin, target_point - origin), 1.0);
}

// Firefly control: a contribution carried by a path of `segments` segments, scaled so that
// its components sum to at most the limit of its kind (direct light: seen directly or after
// one bounce). Contributions are never negative.
fn clamp_contribution(c: vec3<f32>, segments: u32) -> vec3<f32> {
    let limit = select(params.clamp_indirect, params.clamp_direct, segments <= 2u);
    let sum = c.x + c.y + c.z;
    return select(c, c * (limit / sum), sum > limit);
}

// A path's colour channel before it meets a dispersive surface: all three.
const ALL_CHANNELS: u32 = 3u;

// A path between its vertices: everything the path tracer carries from one bounce to the
// next. Each stage below advances it by one step of `li` (twin: PathState in integrator.rs).
struct PathState {
    ray: Ray,
    radiance: vec3<f32>,
    beta: vec3<f32>,
    // The product of η² over the refractions so far: beta · eta_scale is the throughput without
    // the 1/η² that leaving a denser medium undoes, for Russian roulette.
    eta_scale: f32,
    // Path segments so far (Mitsuba's depth): 1 after the camera ray's hit.
    depth: u32,
    // The previous vertex's BSDF sample: its density (divided by candidate_pdf_scale where
    // next-event estimation resampled several light candidates) and whether it was a Dirac one.
    prev_pdf: f32,
    prev_delta: bool,
    // The previous vertex as light selection saw it (for the tree's probability on a hit).
    prev_ctx: LightContext,
    // The AOVs look through Dirac surfaces, weighted by the path's own throughput there.
    aov_open: bool,
    aov_weight: vec3<f32>,
    aov: AovSample,
    // The colour channel a dispersive surface chose (ALL_CHANNELS before one).
    channel: u32,
    // (The path's sampler is a parameter of its own beside it: a pointer argument must name a
    // whole variable, not a member, before WGSL's unrestricted_pointer_parameters.)
}

// The surface at a path's vertex, as `path_surface` prepares it for light and BSDF sampling.
struct SurfaceVertex {
    // The material at the point (textures applied, the path's dispersion ior, the coat
    // normal and anisotropy direction in the local frame).
    mat: Material,
    point: vec3<f32>,
    // Geometric normal on the side the ray arrived from.
    ng: vec3<f32>,
    // Relative ior across the surface from the arriving side.
    eta: f32,
    frame: Frame,
    wo: vec3<f32>,
    ctx: LightContext,
}

// A path starting along `camera_ray`.
fn path_new(camera_ray: Ray) -> PathState {
    return PathState(camera_ray, vec3<f32>(0.0), vec3<f32>(1.0), 1.0, 0u, 0.0, true,
        LightContext(vec3<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0), false), AOVS, vec3<f32>(1.0), aov_none(),
        ALL_CHANNELS);
}

// The path's ray left the scene: the environment, weighted by MIS against the environment's
// light sample when the previous vertex could have sampled it.
fn path_escaped(path: ptr<function, PathState>) {
    let strategy = params.strategy;
    let dir = (*path).ray.dir;
    var w = 1.0;
    if ((*path).depth > 1u && !(*path).prev_delta && params.env_select > 0.0) {
        if (strategy == STRATEGY_LIGHT) {
            w = 0.0;
        } else if (strategy != STRATEGY_BSDF) {
            w = mis_weight(strategy, (*path).prev_pdf, environment_pdf(dir));
        }
    }
    (*path).radiance += clamp_contribution((*path).beta * environment_radiance(dir) * w, (*path).depth);
}

// The path's ray hit a surface: absorption inside a volume it leaves, emission (MIS-weighted
// against the previous vertex's light sample), the dispersion channel, the shading frame and
// the AOVs, into `sv`. False when the path ends here (its last segment).
fn path_surface(
    path: ptr<function, PathState>, sampler: ptr<function, Sampler>, hit: Hit, sv: ptr<function, SurfaceVertex>
) -> bool {
    let strategy = params.strategy;
    let ray = (*path).ray;
    let depth = (*path).depth;
    let tri = world_triangle(hit.tri, hit.instance);
    let uv = triangle_uv(hit.tri, hit.u, hit.v);
    var m = material_at(materials[tri.material], uv, vertex_color(hit.tri, hit.u, hit.v));
    let point = tri.p0 + hit.u * tri.e1 + hit.v * tri.e2;
    let ng_cross = normalize(cross(tri.e1, tri.e2));
    let ng_raw = select(ng_cross, -ng_cross, (tri.flags & TRI_MIRRORED) != 0u);
    let cos_hit = dot(ray.dir, ng_raw);
    // Leaving a volume through its back face: Beer–Lambert over the segment inside.
    if (TRANSMISSION && cos_hit > 0.0 && max_component(m.attenuation) > 0.0) {
        (*path).beta *= exp(-m.attenuation * hit.t);
    }

    // Emission found by the BSDF sample of the previous vertex (or the camera ray).
    if (cos_hit < 0.0 && max_component(m.emission) > 0.0) {
        var w = 1.0;
        if (depth > 1u && !(*path).prev_delta) {
            if (strategy == STRATEGY_LIGHT) {
                w = 0.0;
            } else if (strategy != STRATEGY_BSDF) {
                w = mis_weight(strategy, (*path).prev_pdf,
                    light_pdf((*path).prev_ctx, tri, ray.dir, hit.t * hit.t, cos_hit));
            }
        }
        (*path).radiance += clamp_contribution((*path).beta * m.emission * w, depth);
    }
    let last = params.max_depth != 0u && depth >= params.max_depth;
    if (last && !(*path).aov_open) {
        return false;
    }

    // KHR_materials_dispersion: a refracting solid bends each colour its own way. From its
    // first such surface on, the path follows one channel, chosen uniformly and weighted 3×
    // (the others dropped): an unbiased estimate of every channel.
    if (TRANSMISSION && DISPERSION && m.dispersion > 0.0 && m.transmission > 0.0
        && (m.flags & MAT_THIN_WALLED) == 0u) {
        if ((*path).channel == ALL_CHANNELS) {
            (*path).channel = min(u32(sample_1d(sampler) * 3.0), 2u);
            var mask = vec3<f32>(0.0);
            mask[(*path).channel] = 3.0;
            (*path).beta *= mask;
        }
        m.ior = dispersed_ior(m.ior, m.dispersion, (*path).channel);
    }
    // Surfaces are two-sided: face both normals towards the incoming ray. `eta` is the
    // relative index of refraction for light crossing from the ray's side.
    let ng = select(ng_raw, -ng_raw, cos_hit > 0.0);
    // A thin wall has air on both sides.
    let eta = select(1.0 / m.ior, m.ior, cos_hit < 0.0 || (m.flags & MAT_THIN_WALLED) != 0u);
    var ns = shading_normal(tri, hit.tri, hit.instance, hit.u, hit.v, ng_raw, m, uv);
    ns = select(ns, -ns, dot(ns, ray.dir) > 0.0);
    let frame = frame_from_normal(ns);
    let wo = to_local(frame, -ray.dir);
    // A coat follows its own normal map, or the interpolated normal when the base's is mapped.
    if (CLEARCOAT && TEXTURES && m.clearcoat > 0.0
        && (m.normal_texture.atlas != NO_TEXTURE || m.clearcoat_normal_texture.atlas != NO_TEXTURE)) {
        var nc = coat_normal(tri, hit.tri, hit.instance, hit.u, hit.v, ng_raw, m, uv);
        nc = select(nc, -nc, dot(nc, ray.dir) > 0.0);
        m.coat_normal = to_local(frame, nc);
    }
    // Anisotropy turns with the tangent frame; without tangents the lobe stays isotropic.
    if (ANISOTROPY && m.anisotropy > 0.0) {
        let d = to_local(frame, anisotropy_direction(tri, hit.tri, hit.instance, hit.u, hit.v, ns, m, uv));
        let len = sqrt(d.x * d.x + d.y * d.y);
        if (len > 1e-6) {
            m.anisotropy_tangent = d.xy / len;
        } else {
            m.anisotropy = 0.0;
        }
    }

    if ((*path).aov_open) {
        if (depth == 1u) {
            (*path).aov.depth = hit.t;
        }
        (*path).aov.albedo = clamp((*path).aov_weight * bsdf_albedo(m, wo, eta), vec3<f32>(0.0), vec3<f32>(1.0));
        (*path).aov.normal = ns;
        (*path).aov_open = bsdf_is_delta(m, wo, eta);
    }
    if (last) {
        return false;
    }
    let ctx = LightContext(point, ns, m.transmission <= 0.0 && m.diffuse_transmission <= 0.0);
    *sv = SurfaceVertex(m, point, ng, eta, frame, wo, ctx);
    return true;
}

// Whether next-event estimation runs at a vertex. With the BSDF strategy alone it still runs
// for the tree's Dirac lights, which nothing else can find.
fn next_event_wanted() -> bool {
    let tree = params.light_sampler == LIGHT_SAMPLER_TREE;
    let nee_lights = select(params.light_count, params.tree_emitters, tree);
    if (params.strategy == STRATEGY_BSDF) {
        return tree && params.tree_emitters > params.light_count;
    }
    return nee_lights > 0u || params.env_select > 0.0;
}

// Perceptual roughness below which a reflection lobe counts as glossy: narrow enough that a
// light chosen without the BSDF rarely falls inside it (GGX alpha < 0.25).
const GLOSSY_ROUGHNESS: f32 = 0.5;

fn roughness_glossy(r: f32) -> bool {
    return r < GLOSSY_ROUGHNESS && r * r >= DELTA_ALPHA;
}

// Has the material a glossy reflection lobe (a GGX lobe, not a Dirac one, in the base or the
// coat)?
fn material_glossy(m: Material) -> bool {
    return roughness_glossy(m.roughness) || (m.clearcoat > 0.0 && roughness_glossy(m.clearcoat_roughness));
}

// Light candidates next-event estimation resamples at a vertex of material `m`: the
// sampler's count at glossy surfaces, else 1 (one light sample, as the tree alone).
fn light_candidates(m: Material) -> u32 {
    if (params.light_candidates > 1u && params.strategy != STRATEGY_BSDF && material_glossy(m)) {
        return params.light_candidates;
    }
    return 1u;
}

// MIS weighs `count` light candidates of density p against the BSDF's one sample as one
// sample of density count * p (balance heuristic) or sqrt(count) * p (power heuristic, whose
// weights go by squares); the BSDF's density divided by this factor keeps the two-strategy
// weight.
fn candidate_pdf_scale(strategy: u32, count: u32) -> f32 {
    if (count <= 1u) {
        return 1.0;
    }
    if (strategy == STRATEGY_MIS_BALANCE) {
        return f32(count);
    }
    return sqrt(f32(count));
}

// Next-event estimation at the vertex: one light sample (or the one kept of several
// candidates at a glossy surface, path_resample_lights), and one of the separately sampled
// punctual lights, each connected by a shadow ray and weighted by MIS.
fn path_next_event(path: ptr<function, PathState>, sampler: ptr<function, Sampler>, sv: SurfaceVertex) {
    if (next_event_wanted()) {
        let u_light = vec3<f32>(sample_1d(sampler), sample_2d(sampler));
        let ls = sample_light(sv.ctx, u_light);
        let count = light_candidates(sv.mat);
        if (count > 1u) {
            path_resample_lights(path, sampler, sv, ls, count);
        } else {
            path_connect_light(path, sv, ls);
        }
    }
    // Punctual lights outside the tree: only next-event estimation can reach them.
    if (PUNCTUAL_LIGHTS && params.separate_punctuals > 0u) {
        let ls = sample_punctual(sv.point, sample_1d(sampler));
        let c = (*path).beta * connect(sv.mat, sv.frame, sv.wo, sv.eta, sv.point, sv.ng, ls) / max(ls.pdf, 1e-30);
        (*path).radiance += clamp_contribution(c, (*path).depth + 1u);
    }
}

// Resampled next-event estimation (RIS with MIS-weighted candidates): `count` light samples
// (`first`, then more from the sampler), each weighed by its unshadowed contribution's
// luminance (f |cos| L, the target) over its density, times its MIS weight among the
// candidates and the BSDF sample; one is kept in proportion to its weight and connected by one
// shadow ray, its contribution scaled by the weights' sum over its target. Unbiased: each
// candidate contributes m f L V / p in expectation, and the `count` weights m and the BSDF
// sample's (its density divided by candidate_pdf_scale) sum to 1.
fn path_resample_lights(
    path: ptr<function, PathState>, sampler: ptr<function, Sampler>, sv: SurfaceVertex, first: LightSample, count: u32
) {
    let strategy = params.strategy;
    let scale = candidate_pdf_scale(strategy, count);
    let share = 1.0 / f32(count);
    var u_pick = sample_1d(sampler);
    var w_sum = 0.0;
    var kept = first;
    var kept_c = vec3<f32>(0.0);
    var kept_target = 0.0;
    for (var k = 0u; k < count; k++) {
        var ls = first;
        if (k > 0u) {
            let u_light = vec3<f32>(sample_1d(sampler), sample_2d(sampler));
            ls = sample_light(sv.ctx, u_light);
        }
        if (ls.pdf <= 0.0 || !(ls.delta || strategy != STRATEGY_BSDF)) {
            continue;
        }
        let wi_local = to_local(sv.frame, ls.wi);
        if (!same_side(ls.wi, sv.ng, wi_local)) {
            continue;
        }
        let c = bsdf_eval(sv.mat, sv.wo, wi_local, sv.eta) * abs(wi_local.z) * ls.radiance;
        let target_value = luminance(c);
        if (target_value <= 0.0) {
            continue;
        }
        var mis = share;
        if (strategy != STRATEGY_LIGHT && !ls.delta) {
            mis = share * mis_weight(strategy, ls.pdf, bsdf_pdf(sv.mat, sv.wo, wi_local, sv.eta) / scale);
        }
        let w = mis * target_value / ls.pdf;
        if (w <= 0.0) {
            continue;
        }
        w_sum += w;
        // One number picks among the candidates as they stream by, rescaled after each.
        let p = w / w_sum;
        if (u_pick < p) {
            kept = ls;
            kept_c = c;
            kept_target = target_value;
            u_pick = min(u_pick / p, ONE_MINUS_EPSILON);
        } else {
            u_pick = min((u_pick - p) / (1.0 - p), ONE_MINUS_EPSILON);
        }
    }
    if (kept_target > 0.0 && unoccluded(spawn_point(sv.point, sv.ng, kept.wi), kept)) {
        (*path).radiance += clamp_contribution((*path).beta * kept_c * (w_sum / kept_target), (*path).depth + 1u);
    }
}

// The light sample `ls` of next-event estimation, connected and weighted into the path's
// radiance.
fn path_connect_light(path: ptr<function, PathState>, sv: SurfaceVertex, ls: LightSample) {
    let strategy = params.strategy;
    if (ls.delta || strategy != STRATEGY_BSDF) {
        let c = connect(sv.mat, sv.frame, sv.wo, sv.eta, sv.point, sv.ng, ls);
        if (max_component(c) > 0.0) {
            var w = 1.0;
            if (strategy != STRATEGY_LIGHT && !ls.delta) {
                w = mis_weight(strategy, ls.pdf, bsdf_pdf(sv.mat, sv.wo, to_local(sv.frame, ls.wi), sv.eta));
            }
            (*path).radiance += clamp_contribution((*path).beta * c * (w / ls.pdf), (*path).depth + 1u);
        }
    }
}

// The BSDF sample that continues the path (and finds emitters for the MIS estimator), then
// Russian roulette. False when the path ends.
fn path_scatter(path: ptr<function, PathState>, sampler: ptr<function, Sampler>, sv: SurfaceVertex) -> bool {
    let u_bsdf = vec3<f32>(sample_1d(sampler), sample_2d(sampler));
    let bs = bsdf_sample(sv.mat, sv.wo, u_bsdf, sv.eta);
    if (bs.pdf <= 0.0) {
        return false;
    }
    let wi = from_local(sv.frame, bs.wi);
    // A direction that the shading normal allows but the geometry does not would leak light.
    if (!same_side(wi, sv.ng, bs.wi)) {
        return false;
    }
    (*path).beta *= bs.weight;
    if ((*path).aov_open) {
        (*path).aov_weight *= bs.weight;
    }
    if (max_component((*path).beta) <= 0.0) {
        return false;
    }
    if (refracted(sv.mat, bs.wi)) {
        (*path).eta_scale *= sv.eta * sv.eta;
    }
    // Against several light candidates MIS sees the BSDF's density scaled down.
    let count = light_candidates(sv.mat);
    (*path).prev_pdf = select(bs.pdf, bs.pdf / candidate_pdf_scale(params.strategy, count), count > 1u);
    (*path).prev_delta = bs.delta;
    (*path).prev_ctx = sv.ctx;
    (*path).ray = Ray(spawn_point(sv.point, sv.ng, wi), wi);

    if ((*path).depth >= params.rr_depth) {
        let q = min(max_component((*path).beta * (*path).eta_scale), 0.95);
        if (sample_1d(sampler) >= q) {
            return false;
        }
        (*path).beta /= q;
    }
    return true;
}

// Runs `path` to its end through the stages. Path depth counts segments (Mitsuba's max_depth).
fn trace_path(path: ptr<function, PathState>, sampler: ptr<function, Sampler>) {
    var sv: SurfaceVertex;
    loop {
        let hit = intersect_closest((*path).ray);
        (*path).depth += 1u;
        if (hit.tri == NO_HIT) {
            path_escaped(path);
            return;
        }
        if (!path_surface(path, sampler, hit, &sv)) {
            return;
        }
        path_next_event(path, sampler, sv);
        if (!path_scatter(path, sampler, sv)) {
            return;
        }
    }
}

// Radiance arriving along a camera ray. With AOVS, what the ray saw of the first visible
// surface goes into `aov` (aov.wgsl).
fn li(camera_ray: Ray, sampler: ptr<function, Sampler>, aov: ptr<function, AovSample>) -> vec3<f32> {
    var path = path_new(camera_ray);
    trace_path(&path, sampler);
    *aov = path.aov;
    return path.radiance;
}

@compute @workgroup_size(8, 8, 1)
fn render_sample(@builtin(global_invocation_id) gid: vec3<u32>) {
    let at = film_pixel(gid);
    if (!at.inside) {
        return;
    }
    let adaptive = params.noise_threshold > 0.0;
    if (adaptive && adaptive_converged(at.slot)) {
        return;
    }
    var sampler: Sampler;
    let ray = camera_sample(at.pixel, &sampler);
    var aov = aov_none();
    let l = li(ray, &sampler, &aov);
    film_add_sample(at.slot, l);
    if (adaptive) {
        adaptive_add_sample(at.slot, l);
    }
    if (AOVS) {
        aov_add_sample(at.slot, aov);
    }
}
