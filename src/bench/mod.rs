//! `veach bench`: a fixed set of scenes rendered with fixed settings on each backend, with
//! load and BVH-build times, device memory per triangle, and the BVH's traversal throughput
//! for primary, shadow and diffuse-bounce rays. Timing only: nothing here asserts.

use crate::cpu::bvh::{intersect_closest, intersect_closest_batch, occluded_batch, offset_ray};
use crate::cpu::common::Ray;
use crate::cpu::frame::{frame_from_normal, from_local};
use crate::cpu::sampling::sample_cosine_hemisphere;
use crate::packed::PackedScene;
use crate::{Backend, Error, Renderer, Settings, gpu};
use glam::Vec3;
use rayon::prelude::*;
use std::time::Instant;

mod scenes;
pub use scenes::{glossy_hall_gltf, many_lights_gltf};

pub const CORNELL_BOX: &[u8] = include_bytes!("../../assets/cornell-box.gltf");
pub const VEACH_MIS: &[u8] = include_bytes!("../../assets/veach-mis.gltf");
/// Lamps of the generated many-light scene.
pub const MANY_LIGHTS: u32 = 300;

#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchOptions {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    /// Spheres per side of the generated large scene's grid (each 128 × 64 segments, ~16k
    /// triangles): 4 gives ~262k triangles, Sponza-class.
    pub large_grid: u32,
    /// Emitters of the generated light-tree build test (small triangles over a volume).
    pub tree_emitters: usize,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct RenderResult {
    pub backend: String,
    pub light_sampler: &'static str,
    pub adapter: String,
    pub seconds: f64,
    pub msamples_per_second: f64,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct RayResult {
    pub kind: &'static str,
    pub rays: usize,
    pub seconds: f64,
    pub mrays_per_second: f64,
}

impl RayResult {
    fn new(kind: &'static str, rays: usize, seconds: f64) -> RayResult {
        RayResult { kind, rays, seconds, mrays_per_second: rays as f64 / seconds.max(1e-9) / 1e6 }
    }
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct SceneResult {
    pub scene: String,
    pub triangles: usize,
    /// glTF parsing and flattening.
    pub load_seconds: f64,
    pub bvh_build_seconds: f64,
    /// Packing the scene, BVH build included.
    pub pack_seconds: f64,
    pub bvh_nodes: usize,
    /// Levels of the deepest mesh BVH.
    pub bvh_depth: u32,
    /// Geometry, attributes and BVH as uploaded (nodes + triangles + vertex attributes).
    pub geometry_bytes_per_triangle: f64,
    /// Emitters in the light tree (triangles, point and spot lights), its nodes and depth.
    pub light_tree_emitters: u32,
    pub light_tree_nodes: usize,
    pub light_tree_depth: u32,
    pub light_tree_build_seconds: f64,
    /// The light tree's nodes and trails as uploaded, per emitter.
    pub light_tree_bytes_per_emitter: f64,
    pub renders: Vec<RenderResult>,
    /// Traversal on the CPU reference's BVH walk (same nodes and order as the GPU's).
    pub rays: Vec<RayResult>,
    /// Traversal in the GPU kernel (`shaders/trace.wgsl`), when the GPU backend was run.
    pub gpu_rays: Vec<RayResult>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchReport {
    pub options: BenchOptions,
    pub machine: String,
    pub cores: usize,
    pub scenes: Vec<SceneResult>,
    pub light_tree_scale: TreeScale,
}

/// Building the light tree over many emitters (no rendering).
#[derive(Clone, Debug, serde::Serialize)]
pub struct TreeScale {
    pub emitters: usize,
    pub nodes: usize,
    pub depth: u32,
    pub build_seconds: f64,
    pub bytes_per_emitter: f64,
}

/// The light tree over `n` small one-sided triangles scattered through a unit cube, facing
/// random ways, of powers spanning three decades.
pub fn light_tree_scale(n: usize) -> TreeScale {
    use crate::accel::light_bvh::LightBounds;
    let mut state = 0x853c_49e6_748f_ea9bu64;
    let mut f = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let emitters: Vec<LightBounds> = (0..n)
        .map(|_| {
            let p = Vec3::new(f(), f(), f());
            let axis = Vec3::new(f() - 0.5, f() - 0.5, f() - 0.5).normalize_or(Vec3::Z);
            LightBounds {
                lo: p,
                hi: p + 1e-3,
                phi: 10f32.powf(3.0 * f()),
                axis,
                cos_o: 1.0,
                cos_e: 0.0,
                two_sided: false,
            }
        })
        .collect();
    let t = crate::packed::pack_light_tree_for_bench(&emitters);
    TreeScale {
        emitters: n,
        nodes: t.0,
        depth: t.1,
        build_seconds: t.2,
        bytes_per_emitter: t.3 as f64 / n.max(1) as f64,
    }
}

/// Runs the benchmark; `progress` gets one line per step.
pub fn run(opts: &BenchOptions, backends: &[Backend], progress: &mut dyn FnMut(&str)) -> Result<BenchReport, Error> {
    let large = large_scene_glb(opts.large_grid);
    let lights = many_lights_gltf(MANY_LIGHTS);
    let scenes: [(&str, &[u8]); 4] =
        [("cornell-box", CORNELL_BOX), ("veach-mis", VEACH_MIS), ("spheres-large", &large), ("many-lights", &lights)];
    let ctx = if backends.contains(&Backend::Gpu) { Some(gpu::GpuContext::new()?) } else { None };
    let mut results = Vec::new();
    for (name, bytes) in scenes {
        progress(&format!("{name}: loading"));
        let t = Instant::now();
        let scene = crate::scene::gltf::load_bytes(bytes, None).map_err(|e| Error::Input(format!("{name}: {e}")))?;
        let load_seconds = t.elapsed().as_secs_f64();
        let camera = scene.camera(None).map_err(Error::Input)?;
        let t = Instant::now();
        let packed = PackedScene::new(&scene);
        let pack_seconds = t.elapsed().as_secs_f64();
        let tris = scene.triangles.len().max(1);
        let geometry = std::mem::size_of_val(&packed.nodes[..])
            + std::mem::size_of_val(&packed.triangles[..])
            + std::mem::size_of_val(&packed.attributes[..]);
        let tree_bytes = (packed.light_rows.len() - packed.tree_base as usize) * 16;
        let emitters = packed.tree_emitters;
        let mut result = SceneResult {
            scene: name.to_string(),
            triangles: scene.triangles.len(),
            load_seconds,
            bvh_build_seconds: packed.bvh_build_seconds,
            pack_seconds,
            bvh_nodes: packed.bvh_nodes,
            bvh_depth: packed.bvh_depth,
            geometry_bytes_per_triangle: geometry as f64 / tris as f64,
            light_tree_emitters: emitters,
            light_tree_nodes: packed.light_tree_nodes,
            light_tree_depth: packed.light_tree_depth,
            light_tree_build_seconds: packed.light_tree_seconds,
            light_tree_bytes_per_emitter: if emitters > 0 { tree_bytes as f64 / emitters as f64 } else { 0.0 },
            renders: Vec::new(),
            rays: Vec::new(),
            gpu_rays: Vec::new(),
        };
        let settings =
            Settings { width: opts.width, height: opts.height, max_depth: opts.max_depth, ..Settings::default() };
        for &backend in backends {
            for light_sampler in crate::LightSampler::ALL {
                progress(&format!("{name}: rendering on {backend:?}, {} light sampler", light_sampler.label()));
                let settings = Settings { light_sampler, ..settings.clone() };
                let mut r = match (backend, &ctx) {
                    (Backend::Gpu, Some(ctx)) => {
                        Renderer::with_context(packed.clone(), &camera, &settings, ctx.clone())?
                    }
                    _ => Renderer::new(packed.clone(), &camera, &settings, backend)?,
                };
                // One warm-up sample (shader compilation, first-touch allocations) is not timed.
                r.render_samples(0, 1)?;
                let t = Instant::now();
                r.render_samples(1, opts.spp)?;
                r.film()?;
                let seconds = t.elapsed().as_secs_f64();
                let samples = opts.width as f64 * opts.height as f64 * opts.spp as f64;
                result.renders.push(RenderResult {
                    backend: format!("{:?}", r.backend()).to_lowercase(),
                    light_sampler: light_sampler.label(),
                    adapter: r.adapter_name(),
                    seconds,
                    msamples_per_second: samples / seconds / 1e6,
                });
            }
        }
        progress(&format!("{name}: tracing ray batches"));
        let r = Renderer::new(packed, &camera, &settings, Backend::Cpu)?;
        result.rays = ray_throughput(r.scene(), r.params());
        if let Some(ctx) = &ctx {
            let mut g = gpu::GpuRenderer::new(ctx.clone(), r.scene(), *r.params())?;
            result.gpu_rays = gpu_ray_throughput(&mut g)?;
        }
        results.push(result);
    }
    progress(&format!("light tree over {} emitters", opts.tree_emitters));
    let light_tree_scale = light_tree_scale(opts.tree_emitters);
    Ok(BenchReport {
        options: opts.clone(),
        machine: machine_name(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        scenes: results,
        light_tree_scale,
    })
}

/// The rays `shaders/trace.wgsl` traces, on the CPU reference's walk: a primary ray per
/// pixel (sample 0 of the render's sampler), then from each hit a shadow ray to a light sample
/// (`sample_light`, `unoccluded`, as the integrator connects) and a cosine-distributed bounce
/// ray, each drawn from the sampler right after the camera ray, as each trace kernel does.
fn ray_throughput(scene: &PackedScene, params: &crate::params::Params) -> Vec<RayResult> {
    use crate::cpu::integrator::shadow_ray;
    use crate::cpu::sampler::{sample_1d, sample_2d};
    let (w, h) = (params.image_width, params.image_height);
    let first = crate::params::Params { sample_index: 0, ..*params };
    let primary: Vec<_> =
        (0..w * h).map(|i| crate::cpu::camera::camera_sample(&first, glam::UVec2::new(i % w, i / w))).collect();
    let hits: Vec<_> = primary.par_iter().map(|(r, _)| intersect_closest(scene, r)).collect();
    let primary_rays: Vec<Ray> = primary.iter().map(|(r, _)| *r).collect();
    let primary_result = RayResult::new("primary", primary.len(), best_of(|| closest_batches(scene, &primary_rays)));
    // Surface points and their normals facing the camera, and each path's sampler.
    let surface: Vec<_> = primary
        .iter()
        .zip(&hits)
        .filter(|(_, hit)| hit.tri != crate::cpu::bvh::NO_HIT)
        .map(|((ray, sampler), hit)| {
            let tri = crate::cpu::instance::world_triangle(scene, hit.tri, hit.instance);
            let (e1, e2) = (Vec3::from(tri.e1), Vec3::from(tri.e2));
            let n = e1.cross(e2).normalize();
            let ng = if n.dot(ray.dir) > 0.0 { -n } else { n };
            (Vec3::from(tri.p0) + hit.u * e1 + hit.v * e2, ng, *sampler)
        })
        .collect();
    let lit = params.light_count > 0 || params.tree_emitters > 0 || params.env_select > 0.0;
    let shadow: Vec<_> = if lit {
        surface
            .iter()
            .map(|(p, ng, sampler)| {
                let mut sampler = *sampler;
                let u0 = sample_1d(&mut sampler);
                let u12 = sample_2d(&mut sampler);
                let ctx = crate::cpu::light_tree::LightContext { point: *p, normal: *ng, reflect_only: false };
                (
                    offset_ray(*p, *ng),
                    crate::cpu::lights::sample_light(scene, params, &ctx, Vec3::new(u0, u12.x, u12.y)),
                )
            })
            .filter(|(_, ls)| ls.pdf > 0.0)
            .collect()
    } else {
        Vec::new()
    };
    let (shadow_rays, shadow_ends): (Vec<Ray>, Vec<f32>) = shadow.iter().map(|(o, ls)| shadow_ray(*o, ls)).unzip();
    let shadow_result = RayResult::new(
        "shadow",
        shadow.len(),
        best_of(|| {
            let blocked: usize = shadow_rays
                .par_chunks(BATCH)
                .zip(shadow_ends.par_chunks(BATCH))
                .map(|(rays, ends)| {
                    let mut blocked = [false; BATCH];
                    occluded_batch(scene, rays, ends, &mut blocked[..rays.len()]);
                    blocked.iter().filter(|&&b| b).count()
                })
                .sum();
            std::hint::black_box(blocked);
        }),
    );
    let diffuse: Vec<Ray> = surface
        .iter()
        .map(|(p, ng, sampler)| {
            let mut sampler = *sampler;
            let wi = from_local(&frame_from_normal(*ng), sample_cosine_hemisphere(sample_2d(&mut sampler)));
            Ray { origin: offset_ray(*p, *ng), dir: wi }
        })
        .collect();
    let diffuse_result = RayResult::new("diffuse", diffuse.len(), best_of(|| closest_batches(scene, &diffuse)));
    vec![primary_result, shadow_result, diffuse_result]
}

/// Rays per batch query in the throughput measure.
const BATCH: usize = 256;

/// The closest hits of `rays` through the batch query, batches in parallel.
fn closest_batches(scene: &PackedScene, rays: &[Ray]) {
    let t: f32 = rays
        .par_chunks(BATCH)
        .map(|rays| {
            let mut hits = [crate::cpu::bvh::Hit { t: 0.0, tri: 0, u: 0.0, v: 0.0, instance: 0 }; BATCH];
            intersect_closest_batch(scene, rays, &mut hits[..rays.len()]);
            hits[..rays.len()].iter().map(|h| h.t).sum::<f32>()
        })
        .sum();
    std::hint::black_box(t);
}

/// Seconds of one run of `f`: the fastest of at least 5 runs and 0.3 s (a batch of ~65k rays
/// takes milliseconds, and one run alone is mostly timer and scheduling noise).
fn best_of(mut f: impl FnMut()) -> f64 {
    let (mut best, mut total, mut runs) = (f64::INFINITY, 0.0, 0);
    while runs < 5 || total < 0.3 {
        let t = Instant::now();
        f();
        let s = t.elapsed().as_secs_f64();
        best = best.min(s);
        total += s;
        runs += 1;
    }
    best
}

/// The GPU twin of `ray_throughput`: the same three kinds of rays, generated in the kernel
/// (`shaders/trace.wgsl`). Shadow and bounce rays are timed as the difference between the
/// kernel that traces them after the primary ray and the one that traces the primary ray only.
fn gpu_ray_throughput(g: &mut gpu::GpuRenderer) -> Result<Vec<RayResult>, Error> {
    const PASSES: u32 = 16;
    // Fastest of three runs of each kernel, as for the CPU batches.
    let best = |g: &mut gpu::GpuRenderer, kind: u32| -> Result<f64, Error> {
        let mut t = f64::INFINITY;
        for _ in 0..3 {
            t = t.min(g.trace_rays(kind, PASSES)?);
        }
        Ok(t)
    };
    // The film holds the last run's counts: a pixel adds 1 to its green channel for each
    // secondary ray the kernel traced.
    let traced = |g: &gpu::GpuRenderer| -> Result<usize, Error> {
        let film = g.read_film()?;
        Ok((0..film.pixel_count()).map(|i| film.sum(i).y).sum::<f64>() as usize)
    };
    let primary_seconds = best(g, 0)?;
    let primary = g.read_film()?.pixel_count() * PASSES as usize;
    let shadow_seconds = best(g, 1)? - primary_seconds;
    let shadow = traced(g)?;
    let diffuse_seconds = best(g, 2)? - primary_seconds;
    let diffuse = traced(g)?;
    Ok(vec![
        RayResult::new("primary", primary, primary_seconds),
        RayResult::new("shadow", shadow, shadow_seconds),
        RayResult::new("diffuse", diffuse, diffuse_seconds),
    ])
}

fn machine_name() -> String {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    cpuinfo
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split(':').nth(1))
        .map_or_else(|| std::env::consts::ARCH.to_string(), |s| s.trim().to_string())
}

/// The Cornell box's light, walls and floor with a grid × grid array of UV spheres (128 × 64
/// segments each) standing on the floor: a generated scene of Sponza's size, as a GLB.
pub fn large_scene_glb(grid: u32) -> Vec<u8> {
    let mut doc: serde_json::Value = serde_json::from_slice(CORNELL_BOX).expect("bundled scene");
    // Keep the box; replace its two blocks by the spheres.
    let keep: Vec<serde_json::Value> = doc["scenes"][0]["nodes"]
        .as_array()
        .expect("nodes")
        .iter()
        .filter(|&n| {
            let name = doc["nodes"][n.as_u64().unwrap_or(0) as usize]["name"].as_str().unwrap_or("");
            !name.contains("block")
        })
        .cloned()
        .collect();
    let (nu, nv) = (128u32, 64u32);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut indices = Vec::new();
    let spacing = 500.0 / grid as f32;
    let radius = 0.4 * spacing;
    for gz in 0..grid {
        for gx in 0..grid {
            let centre = Vec3::new(28.0 + spacing * (gx as f32 + 0.5), radius, 28.0 + spacing * (gz as f32 + 0.5));
            let base = positions.len() as u32;
            for j in 0..=nv {
                let theta = std::f32::consts::PI * j as f32 / nv as f32;
                for i in 0..=nu {
                    let phi = 2.0 * std::f32::consts::PI * i as f32 / nu as f32;
                    let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
                    positions.push(centre + radius * n);
                    normals.push(n);
                }
            }
            for j in 0..nv {
                for i in 0..nu {
                    let a = base + j * (nu + 1) + i;
                    let b = a + nu + 1;
                    if j > 0 {
                        indices.extend([a, a + 1, b]);
                    }
                    if j + 1 < nv {
                        indices.extend([a + 1, b + 1, b]);
                    }
                }
            }
        }
    }
    let mut bin: Vec<u8> = Vec::new();
    let mut view = |bytes: &[u8]| {
        let offset = bin.len();
        bin.extend_from_slice(bytes);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        (offset, bytes.len())
    };
    let pos_bytes: Vec<u8> = positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
    let nrm_bytes: Vec<u8> = normals.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
    let idx_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let views = [view(&pos_bytes), view(&nrm_bytes), view(&idx_bytes)];
    let min = positions.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
    let max = positions.iter().fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
    // The bundled file's own buffers stay (embedded); the spheres' buffer is the GLB's BIN
    // chunk, which must be buffer 0: the others move up by one.
    let buffer = 0;
    for v in doc["bufferViews"].as_array_mut().expect("views") {
        v["buffer"] = serde_json::json!(v["buffer"].as_u64().unwrap_or(0) + 1);
    }
    let view0 = doc["bufferViews"].as_array().map_or(0, |b| b.len());
    let acc0 = doc["accessors"].as_array().map_or(0, |b| b.len());
    doc["buffers"].as_array_mut().expect("buffers").insert(0, serde_json::json!({"byteLength": bin.len()}));
    for (offset, len) in views {
        doc["bufferViews"]
            .as_array_mut()
            .expect("views")
            .push(serde_json::json!({"buffer": buffer, "byteOffset": offset, "byteLength": len}));
    }
    let accessors = doc["accessors"].as_array_mut().expect("accessors");
    accessors.push(serde_json::json!({"bufferView": view0, "componentType": 5126, "count": positions.len(),
        "type": "VEC3", "min": min.to_array(), "max": max.to_array()}));
    accessors.push(
        serde_json::json!({"bufferView": view0 + 1, "componentType": 5126, "count": normals.len(), "type": "VEC3"}),
    );
    accessors.push(
        serde_json::json!({"bufferView": view0 + 2, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}),
    );
    let materials = doc["materials"].as_array_mut().expect("materials");
    materials
        .push(serde_json::json!({"name": "spheres", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
        "metallicFactor": 0.0, "roughnessFactor": 0.5}}));
    let material = materials.len() - 1;
    let meshes = doc["meshes"].as_array_mut().expect("meshes");
    meshes.push(
        serde_json::json!({"name": "spheres", "primitives": [{"attributes": {"POSITION": acc0, "NORMAL": acc0 + 1},
        "indices": acc0 + 2, "material": material}]}),
    );
    let mesh = meshes.len() - 1;
    let nodes = doc["nodes"].as_array_mut().expect("nodes");
    nodes.push(serde_json::json!({"name": "spheres", "mesh": mesh}));
    let mut roots = keep;
    roots.push(serde_json::json!(nodes.len() - 1));
    doc["scenes"][0]["nodes"] = serde_json::Value::Array(roots);
    let mut json = serde_json::to_vec(&doc).expect("json");
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::with_capacity(total);
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&(total as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(&0x4E4F534Au32.to_le_bytes());
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(&0x004E4942u32.to_le_bytes());
    glb.extend_from_slice(&bin);
    glb
}

/// The report as an aligned text table.
pub fn format_report(r: &BenchReport) -> String {
    let o = &r.options;
    let mut s = format!(
        "veach bench: {}x{}, {} spp, max depth {}; {} ({} cores)\n\n",
        o.width, o.height, o.spp, o.max_depth, r.machine, r.cores
    );
    s += &format!(
        "{:<14} {:>9} {:>9} {:>9} {:>9} {:>8}  {:<8} {:<6} {:>10} {:>9}\n",
        "scene", "triangles", "load s", "BVH s", "nodes", "B/tri", "backend", "lights", "Msamples/s", "seconds"
    );
    for sc in &r.scenes {
        for (i, run) in sc.renders.iter().enumerate() {
            let head = if i == 0 {
                format!(
                    "{:<14} {:>9} {:>9.3} {:>9.3} {:>9} {:>8.1}",
                    sc.scene,
                    sc.triangles,
                    sc.load_seconds,
                    sc.bvh_build_seconds,
                    sc.bvh_nodes,
                    sc.geometry_bytes_per_triangle
                )
            } else {
                format!("{:<14} {:>9} {:>9} {:>9} {:>9} {:>8}", "", "", "", "", "", "")
            };
            s += &format!(
                "{head}  {:<8} {:<6} {:>10.3} {:>9.2}\n",
                run.backend, run.light_sampler, run.msamples_per_second, run.seconds
            );
        }
    }
    let rates = |rays: &[RayResult]| rays.iter().map(|x| format!("{:.2}", x.mrays_per_second)).collect::<Vec<_>>();
    s += "\nBVH traversal (M rays/s): primary / shadow / diffuse bounce\n";
    s += &format!("{:<14} {:<24} {}\n", "scene", "CPU reference", "GPU kernel (the same rays)");
    for sc in &r.scenes {
        s += &format!("{:<14} {:<24} {}\n", sc.scene, rates(&sc.rays).join(" / "), rates(&sc.gpu_rays).join(" / "));
    }
    s += "\nLight tree: emitters, nodes, depth, build s, bytes per emitter\n";
    for sc in &r.scenes {
        s += &format!(
            "{:<14} {:>9} {:>9} {:>5} {:>9.3} {:>8.1}\n",
            sc.scene,
            sc.light_tree_emitters,
            sc.light_tree_nodes,
            sc.light_tree_depth,
            sc.light_tree_build_seconds,
            sc.light_tree_bytes_per_emitter
        );
    }
    let t = &r.light_tree_scale;
    s += &format!(
        "{:<14} {:>9} {:>9} {:>5} {:>9.3} {:>8.1}\n",
        "generated", t.emitters, t.nodes, t.depth, t.build_seconds, t.bytes_per_emitter
    );
    s
}
