//! `veach bench`: a fixed set of scenes rendered with fixed settings on each backend, with
//! load and BVH-build times, device memory per triangle, and the BVH's traversal throughput
//! for primary, shadow and diffuse-bounce rays. Timing only: nothing here asserts.

use crate::cpu::bvh::{Ray, intersect_closest, occluded, offset_ray};
use crate::cpu::frame::{frame_from_normal, from_local};
use crate::cpu::rng::{rng_init, rng_next2};
use crate::cpu::sampling::{sample_cosine_hemisphere, sample_uniform_triangle};
use crate::packed::PackedScene;
use crate::{Backend, Error, Renderer, Settings, gpu};
use glam::Vec3;
use rayon::prelude::*;
use std::time::Instant;

pub const CORNELL_BOX: &[u8] = include_bytes!("../assets/cornell-box.gltf");
pub const VEACH_MIS: &[u8] = include_bytes!("../assets/veach-mis.gltf");

#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchOptions {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    /// Spheres per side of the generated large scene's grid (each 128 × 64 segments, ~16k
    /// triangles): 4 gives ~262k triangles, Sponza-class.
    pub large_grid: u32,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct RenderResult {
    pub backend: String,
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
    pub renders: Vec<RenderResult>,
    /// Traversal on the CPU reference's BVH walk (same nodes and order as the GPU's).
    pub rays: Vec<RayResult>,
    /// Traversal in the GPU kernel (`shaders/trace.wgsl`), when the GPU backend was run.
    pub gpu_rays: Vec<RayResult>,
    /// The same rays on the CPU through obvhs's compressed 8-wide BVH (Ylitie et al. 2017)
    /// and its own (SIMD) traversal, for comparison with our walk (scenes without instances).
    pub cwbvh_rays: Vec<RayResult>,
    pub cwbvh_build_seconds: f64,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchReport {
    pub options: BenchOptions,
    pub machine: String,
    pub cores: usize,
    pub scenes: Vec<SceneResult>,
}

/// Runs the benchmark; `progress` gets one line per step.
pub fn run(opts: &BenchOptions, backends: &[Backend], progress: &mut dyn FnMut(&str)) -> Result<BenchReport, Error> {
    let large = large_scene_glb(opts.large_grid);
    let scenes: [(&str, &[u8]); 3] =
        [("cornell-box", CORNELL_BOX), ("veach-mis", VEACH_MIS), ("spheres-large", &large)];
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
        let mut result = SceneResult {
            scene: name.to_string(),
            triangles: scene.triangles.len(),
            load_seconds,
            bvh_build_seconds: packed.bvh_build_seconds,
            pack_seconds,
            bvh_nodes: packed.bvh_nodes,
            bvh_depth: packed.bvh_depth,
            geometry_bytes_per_triangle: geometry as f64 / tris as f64,
            renders: Vec::new(),
            rays: Vec::new(),
            gpu_rays: Vec::new(),
            cwbvh_rays: Vec::new(),
            cwbvh_build_seconds: 0.0,
        };
        let settings =
            Settings { width: opts.width, height: opts.height, max_depth: opts.max_depth, ..Settings::default() };
        for &backend in backends {
            progress(&format!("{name}: rendering on {backend:?}"));
            let mut r = match (backend, &ctx) {
                (Backend::Gpu, Some(ctx)) => Renderer::with_context(packed.clone(), &camera, &settings, ctx.clone())?,
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
                backend: format!("{backend:?}").to_lowercase(),
                adapter: r.adapter_name(),
                seconds,
                msamples_per_second: samples / seconds / 1e6,
            });
        }
        progress(&format!("{name}: tracing ray batches"));
        let r = Renderer::new(packed, &camera, &settings, Backend::Cpu)?;
        let (rays, batches) = ray_throughput(r.scene(), r.params());
        result.rays = rays;
        if r.scene().instance_count == 0 {
            match cwbvh_ray_throughput(r.scene(), &batches) {
                Ok((rays, seconds)) => (result.cwbvh_rays, result.cwbvh_build_seconds) = (rays, seconds),
                Err(why) => progress(&format!("{name}: CWBVH comparison left out: {why}")),
            }
        }
        if let Some(ctx) = &ctx {
            let mut g = gpu::GpuRenderer::new(ctx.clone(), r.scene(), *r.params())?;
            result.gpu_rays = gpu_ray_throughput(&mut g)?;
        }
        results.push(result);
    }
    Ok(BenchReport {
        options: opts.clone(),
        machine: machine_name(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        scenes: results,
    })
}

/// Primary rays through every pixel; shadow rays from their hits to a point on a light
/// (or straight up when the scene has none); cosine-distributed bounce rays from the hits.
fn ray_throughput(scene: &PackedScene, params: &crate::params::Params) -> (Vec<RayResult>, [Vec<Ray>; 3]) {
    let (w, h) = (params.image_width, params.image_height);
    let first = crate::params::Params { sample_index: 0, seed: 1, ..*params };
    let primary: Vec<Ray> =
        (0..w * h).map(|i| crate::cpu::camera::camera_sample(&first, glam::UVec2::new(i % w, i / w)).0).collect();
    let hits: Vec<_> = primary.par_iter().map(|r| intersect_closest(scene, r)).collect();
    let primary_result = RayResult::new(
        "primary",
        primary.len(),
        best_of(|| {
            std::hint::black_box(primary.par_iter().map(|r| intersect_closest(scene, r).t).sum::<f32>());
        }),
    );
    // Surface points and their normals, facing the camera.
    let surface: Vec<(Vec3, Vec3)> = primary
        .iter()
        .zip(&hits)
        .filter(|(_, hit)| hit.tri != crate::cpu::bvh::NO_HIT)
        .map(|(ray, hit)| {
            let tri = crate::cpu::instance::world_triangle(scene, hit.tri, hit.instance);
            let (e1, e2) = (Vec3::from(tri.e1), Vec3::from(tri.e2));
            let n = e1.cross(e2).normalize();
            let n = if n.dot(ray.dir) > 0.0 { -n } else { n };
            let p = Vec3::from(tri.p0) + hit.u * e1 + hit.v * e2;
            (offset_ray(p, n), n)
        })
        .collect();
    let light = scene.lights.first().map(|l| scene.triangles[l.triangle as usize]);
    let shadow: Vec<Ray> = surface
        .iter()
        .enumerate()
        .map(|(i, &(p, n))| {
            let mut rng = rng_init(i as u32, 1, 1);
            match light {
                Some(tri) => {
                    let b = sample_uniform_triangle(rng_next2(&mut rng));
                    let q = Vec3::from(tri.p0) + b.x * Vec3::from(tri.e1) + b.y * Vec3::from(tri.e2);
                    Ray { origin: p, dir: q - p }
                }
                None => Ray { origin: p, dir: n },
            }
        })
        .collect();
    let shadow_result = RayResult::new(
        "shadow",
        shadow.len(),
        best_of(|| {
            std::hint::black_box(shadow.par_iter().filter(|r| occluded(scene, r, 0.999)).count());
        }),
    );
    let diffuse: Vec<Ray> = surface
        .iter()
        .enumerate()
        .map(|(i, &(p, n))| {
            let mut rng = rng_init(i as u32, 2, 1);
            Ray { origin: p, dir: from_local(&frame_from_normal(n), sample_cosine_hemisphere(rng_next2(&mut rng))) }
        })
        .collect();
    let diffuse_result = RayResult::new(
        "diffuse",
        diffuse.len(),
        best_of(|| {
            std::hint::black_box(diffuse.par_iter().map(|r| intersect_closest(scene, r).t).sum::<f32>());
        }),
    );
    (vec![primary_result, shadow_result, diffuse_result], [primary, shadow, diffuse])
}

/// The batches of `ray_throughput` through a CWBVH that obvhs builds from the packed triangles
/// (same build settings as ours) and walks with its own SIMD traversal, with our triangle
/// test; an error when the two walks do not find the same hits (then the rates would compare
/// different work).
fn cwbvh_ray_throughput(scene: &PackedScene, batches: &[Vec<Ray>; 3]) -> Result<(Vec<RayResult>, f64), String> {
    use obvhs::ray::{Ray as ORay, RayHit};
    let tris: Vec<obvhs::triangle::Triangle> = scene
        .triangles
        .iter()
        .map(|t| {
            let (p0, e1, e2) = (Vec3::from(t.p0), Vec3::from(t.e1), Vec3::from(t.e2));
            obvhs::triangle::Triangle { v0: p0.into(), v1: (p0 + e1).into(), v2: (p0 + e2).into() }
        })
        .collect();
    let t = Instant::now();
    let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
        &tris,
        obvhs::BvhBuildParams::medium_build(),
        &mut std::time::Duration::default(),
    );
    let build_seconds = t.elapsed().as_secs_f64();
    let intersect = |ray: &ORay, id: usize| {
        let tri = &scene.triangles[bvh.primitive_indices[id] as usize];
        let r = crate::cpu::bvh::intersect_triangle(&Ray { origin: ray.origin.into(), dir: ray.direction.into() }, tri);
        if r.x >= crate::cpu::bvh::INF { f32::INFINITY } else { r.x }
    };
    let closest = |rays: &[Ray]| {
        rays.par_iter()
            .map(|r| {
                let mut hit = RayHit::none();
                bvh.ray_traverse(ORay::new_inf(r.origin.into(), r.dir.into()), &mut hit, intersect);
                hit.t.min(1e30)
            })
            .sum::<f32>()
    };
    let result = |kind: &'static str, rays: &[Ray], seconds: f64| RayResult::new(kind, rays.len(), seconds);
    let [primary, shadow, diffuse] = batches;
    // The comparison is only meaningful if both walks find the same hits.
    for rays in [primary, diffuse] {
        let differ = rays
            .par_iter()
            .filter(|r| {
                let mut hit = RayHit::none();
                bvh.ray_traverse(ORay::new_inf(r.origin.into(), r.dir.into()), &mut hit, intersect);
                let ours = intersect_closest(scene, r);
                let ours = if ours.tri == crate::cpu::bvh::NO_HIT { f32::INFINITY } else { ours.t };
                ours != hit.t && (ours - hit.t).abs() > 1e-4 * ours.abs().max(1.0)
            })
            .count();
        if differ * 1000 > rays.len() {
            return Err(format!("obvhs's CWBVH walk and ours disagree on {differ} of {} rays", rays.len()));
        }
    }
    let rates = vec![
        result(
            "primary",
            primary,
            best_of(|| {
                std::hint::black_box(closest(primary));
            }),
        ),
        result(
            "shadow",
            shadow,
            best_of(|| {
                let blocked = shadow
                    .par_iter()
                    .filter(|r| !bvh.ray_traverse_miss(ORay::new(r.origin.into(), r.dir.into(), 0.0, 0.999), intersect))
                    .count();
                std::hint::black_box(blocked);
            }),
        ),
        result(
            "diffuse",
            diffuse,
            best_of(|| {
                std::hint::black_box(closest(diffuse));
            }),
        ),
    ];
    Ok((rates, build_seconds))
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
    let primary_seconds = best(g, 0)?;
    // The film still holds the last primary-only run: each primary ray that hit something left
    // a 1 there and spawns one secondary ray in the other kernels.
    let film = g.read_film()?;
    let hits = (0..film.pixel_count()).map(|i| film.sum(i).x).sum::<f64>() as usize;
    let primary = film.pixel_count() * PASSES as usize;
    let shadow_seconds = best(g, 1)? - primary_seconds;
    let diffuse_seconds = best(g, 2)? - primary_seconds;
    Ok(vec![
        RayResult::new("primary", primary, primary_seconds),
        RayResult::new("shadow", hits, shadow_seconds),
        RayResult::new("diffuse", hits, diffuse_seconds),
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
        "{:<14} {:>9} {:>9} {:>9} {:>9} {:>8}  {:<8} {:>10} {:>9}\n",
        "scene", "triangles", "load s", "BVH s", "nodes", "B/tri", "backend", "Msamples/s", "seconds"
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
            s += &format!("{head}  {:<8} {:>10.3} {:>9.2}\n", run.backend, run.msamples_per_second, run.seconds);
        }
    }
    let rates = |rays: &[RayResult]| rays.iter().map(|x| format!("{:.2}", x.mrays_per_second)).collect::<Vec<_>>();
    s += "\nBVH traversal (M rays/s): primary / shadow / diffuse bounce\n";
    s += &format!("{:<14} {:<24} {:<24} {}\n", "scene", "CPU reference", "GPU kernel", "CPU, obvhs's CWBVH walk");
    for sc in &r.scenes {
        s += &format!(
            "{:<14} {:<24} {:<24} {}\n",
            sc.scene,
            rates(&sc.rays).join(" / "),
            rates(&sc.gpu_rays).join(" / "),
            rates(&sc.cwbvh_rays).join(" / ")
        );
    }
    s
}
