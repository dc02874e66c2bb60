//! Twin of `shaders/integrator.wgsl`: the path tracer, sample for sample.

use super::bsdf::{bsdf_albedo, bsdf_eval, bsdf_is_delta, bsdf_pdf, bsdf_sample};
use super::bvh::{NO_HIT, intersect_closest, occluded, offset_ray};
use super::camera::camera_sample;
use super::common::{INF, Ray};
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
use glam::{UVec2, Vec3};

/// A path's colour channel before it meets a dispersive surface: all three.
pub const ALL_CHANNELS: u32 = 3;

fn same_side(wi: Vec3, ng: Vec3, wi_local: Vec3) -> bool {
    (wi.dot(ng) > 0.0) == (wi_local.z > 0.0)
}

fn spawn_point(point: Vec3, ng: Vec3, wi: Vec3) -> Vec3 {
    offset_ray(point, if wi.dot(ng) > 0.0 { ng } else { -ng })
}

/// Twin of `connect` in the shader: f · |cos θ| · L, or 0 (blocked, zero BSDF, no density).
#[allow(clippy::too_many_arguments)]
fn connect(
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
    if ls.dist == INF {
        return !occluded(scene, &Ray { origin, dir: ls.wi }, INF);
    }
    let target = offset_ray(ls.point, ls.normal);
    !occluded(scene, &Ray { origin, dir: target - origin }, 1.0)
}

/// Twin of `clamp_contribution`: firefly control, a contribution carried by a path of
/// `segments` segments scaled so that its components sum to at most the limit of its kind
/// (direct light: seen directly or after one bounce).
pub fn clamp_contribution(params: &Params, c: Vec3, segments: u32) -> Vec3 {
    let limit = if segments <= 2 { params.clamp_direct } else { params.clamp_indirect };
    let sum = c.x + c.y + c.z;
    if sum > limit { c * (limit / sum) } else { c }
}

/// Radiance arriving along a camera ray; with AOVs on (`params.aov_base`), what the ray saw of
/// the first visible surface goes into `aov` (`src/aov.rs`).
pub fn li(scene: &PackedScene, params: &Params, camera_ray: Ray, sampler: &mut Sampler, aov: &mut AovSample) -> Vec3 {
    let strategy = Strategy::try_from(params.strategy).unwrap_or(Strategy::MisPower);
    let mut radiance = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    let mut ray = camera_ray;
    let mut depth = 0u32;
    let mut prev_pdf = 0.0f32;
    let mut prev_delta = true;
    // The previous vertex as light selection saw it (for the tree's probability on a hit).
    let mut prev_ctx = LightContext { point: Vec3::ZERO, normal: Vec3::Z, reflect_only: false };
    // The AOVs look through Dirac surfaces, weighted by the path's own throughput there.
    let mut aov_open = params.aov_base > 0;
    let mut aov_weight = Vec3::ONE;
    let mut channel = ALL_CHANNELS;
    loop {
        let hit = intersect_closest(scene, &ray);
        depth += 1;
        if hit.tri == NO_HIT {
            let mut w = 1.0;
            if depth > 1 && !prev_delta && params.env_select > 0.0 {
                match strategy {
                    Strategy::Light => w = 0.0,
                    Strategy::Bsdf => {}
                    _ => w = mis_weight(strategy, prev_pdf, environment_pdf(scene, params, ray.dir)),
                }
            }
            radiance += clamp_contribution(params, beta * environment_radiance(scene, params, ray.dir) * w, depth);
            break;
        }
        let tri = &world_triangle(scene, hit.tri, hit.instance);
        let uv = triangle_uv(scene, hit.tri, hit.u, hit.v);
        let color = vertex_color(scene, hit.tri, hit.u, hit.v);
        let mut mat = material_at(scene, &scene.materials[tri.material as usize], uv, color);
        let m = &mat;
        let (e1, e2) = (Vec3::from(tri.e1), Vec3::from(tri.e2));
        let point = Vec3::from(tri.p0) + hit.u * e1 + hit.v * e2;
        let ng_cross = e1.cross(e2).normalize();
        let ng_raw = if tri.flags & TRI_MIRRORED != 0 { -ng_cross } else { ng_cross };
        let cos_hit = ray.dir.dot(ng_raw);
        let attenuation = Vec3::from(m.attenuation);
        if cos_hit > 0.0 && attenuation.max_element() > 0.0 {
            beta *= (-attenuation * hit.t).exp();
        }
        let emission = Vec3::from(m.emission);

        if cos_hit < 0.0 && emission.max_element() > 0.0 {
            let mut w = 1.0;
            if depth > 1 && !prev_delta {
                match strategy {
                    Strategy::Light => w = 0.0,
                    Strategy::Bsdf => {}
                    _ => {
                        w = mis_weight(
                            strategy,
                            prev_pdf,
                            light_pdf(scene, params, &prev_ctx, tri, ray.dir, hit.t * hit.t, cos_hit),
                        )
                    }
                }
            }
            radiance += clamp_contribution(params, beta * emission * w, depth);
        }
        let last = params.max_depth != 0 && depth >= params.max_depth;
        if last && !aov_open {
            break;
        }

        // KHR_materials_dispersion: a refracting solid bends each colour its own way. From its
        // first such surface on, the path follows one channel, chosen uniformly and weighted
        // 3× (the others dropped): an unbiased estimate of every channel.
        if mat.dispersion > 0.0 && mat.transmission > 0.0 && mat.flags & MAT_THIN_WALLED == 0 {
            if channel == ALL_CHANNELS {
                channel = ((sample_1d(sampler) * 3.0) as u32).min(2);
                let mut mask = Vec3::ZERO;
                mask[channel as usize] = 3.0;
                beta *= mask;
            }
            mat.ior = dispersed_ior(mat.ior, mat.dispersion, channel);
        }
        let m = &mat;
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
            mat.coat_normal = to_local(&frame, nc).into();
        }
        // Anisotropy turns with the tangent frame; without tangents the lobe stays isotropic.
        if mat.anisotropy > 0.0 {
            let d =
                to_local(&frame, anisotropy_direction(scene, tri, hit.tri, hit.instance, hit.u, hit.v, ns, &mat, uv));
            let len = (d.x * d.x + d.y * d.y).sqrt();
            if len > 1e-6 {
                mat.anisotropy_tangent = [d.x / len, d.y / len];
            } else {
                mat.anisotropy = 0.0;
            }
        }
        let m = &mat;
        if aov_open {
            if depth == 1 {
                aov.depth = hit.t;
            }
            aov.albedo = (aov_weight * bsdf_albedo(m, wo, eta)).clamp(Vec3::ZERO, Vec3::ONE);
            aov.normal = ns;
            aov_open = bsdf_is_delta(m, wo, eta);
        }
        if last {
            break;
        }

        let ctx =
            LightContext { point, normal: ns, reflect_only: m.transmission <= 0.0 && m.diffuse_transmission <= 0.0 };
        // Next-event estimation: one light sample. With the BSDF strategy alone it still
        // runs for the tree's Dirac lights, which nothing else can find.
        let nee_lights =
            if params.light_sampler == LIGHT_SAMPLER_TREE { params.tree_emitters } else { params.light_count };
        let nee = if strategy == Strategy::Bsdf {
            params.light_sampler == LIGHT_SAMPLER_TREE && params.tree_emitters > params.light_count
        } else {
            nee_lights > 0 || params.env_select > 0.0
        };
        if nee {
            let u0 = sample_1d(sampler);
            let u12 = sample_2d(sampler);
            let ls = sample_light(scene, params, &ctx, Vec3::new(u0, u12.x, u12.y));
            if ls.delta || strategy != Strategy::Bsdf {
                let c = connect(scene, m, &frame, wo, eta, point, ng, &ls);
                if c.max_element() > 0.0 {
                    let w = if strategy == Strategy::Light || ls.delta {
                        1.0
                    } else {
                        mis_weight(strategy, ls.pdf, bsdf_pdf(m, wo, to_local(&frame, ls.wi), eta))
                    };
                    radiance += clamp_contribution(params, beta * c * (w / ls.pdf), depth + 1);
                }
            }
        }
        if params.separate_punctuals > 0 {
            let ls = sample_punctual(scene, params, point, sample_1d(sampler));
            let c = beta * connect(scene, m, &frame, wo, eta, point, ng, &ls) / ls.pdf.max(1e-30);
            radiance += clamp_contribution(params, c, depth + 1);
        }

        let u0 = sample_1d(sampler);
        let u12 = sample_2d(sampler);
        let bs = bsdf_sample(m, wo, Vec3::new(u0, u12.x, u12.y), eta);
        if bs.pdf <= 0.0 {
            break;
        }
        let wi = from_local(&frame, bs.wi);
        if !same_side(wi, ng, bs.wi) {
            break;
        }
        beta *= bs.weight;
        if aov_open {
            aov_weight *= bs.weight;
        }
        if beta.max_element() <= 0.0 {
            break;
        }
        prev_pdf = bs.pdf;
        prev_delta = bs.delta;
        prev_ctx = ctx;
        ray = Ray { origin: spawn_point(point, ng, wi), dir: wi };

        if depth >= params.rr_depth {
            let q = beta.max_element().min(0.95);
            if sample_1d(sampler) >= q {
                break;
            }
            beta /= q;
        }
    }
    radiance
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
