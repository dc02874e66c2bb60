//! Environment maps: importance sampling agrees with its pdf, the pdf is normalised, and maps
//! render the same on both backends (and a constant map is a white furnace).

mod common;

use common::rng::Lcg;
use common::*;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use veach::Tile;
use veach::cpu::environment::{env_direction, environment_pdf, environment_radiance, sample_environment};
use veach::packed::PackedScene;
use veach::params::Params;
use veach::scene::{EnvironmentMap, Scene};

/// A sky: a dim gradient, a bright small sun, and a black band (pdf 0 there).
fn sky(w: u32, h: u32) -> EnvironmentMap {
    let mut m = EnvironmentMap::constant(w, h, Vec3::ZERO);
    for i in 0..h {
        for j in 0..w {
            let v = (i as f32 + 0.5) / h as f32;
            let mut c = Vec3::new(0.2, 0.4, 1.0) * (1.0 - v) + Vec3::splat(0.05);
            if (i as i32 - h as i32 / 4).abs() <= 1 && (j as i32 - w as i32 / 3).abs() <= 1 {
                c = Vec3::new(400.0, 350.0, 300.0);
            }
            if i > h * 3 / 4 {
                c = Vec3::ZERO;
            }
            m.texels[(i * w + j) as usize] = c;
        }
    }
    m
}

fn setup(map: EnvironmentMap) -> (PackedScene, Params) {
    let scene = Scene { environment: veach::Environment::map(map, Vec3::ONE), ..Default::default() };
    let packed = PackedScene::new(&scene);
    let camera = scene.camera(None).expect("default camera");
    let tile = Tile { x: 0, y: 0, width: 4, height: 4 };
    let params = Params::new(&camera, &veach::Settings { width: 4, height: 4, ..Default::default() }, tile, &packed);
    (packed, params)
}

#[test]
fn environment_pdf_integrates_to_one() {
    let (scene, params) = setup(sky(64, 32));
    assert_eq!(params.env_select, 1.0, "no triangle lights: the environment is all of light sampling");
    let (nu, nv) = (1024, 512);
    let mut total = 0.0f64;
    for i in 0..nv {
        for j in 0..nu {
            let uv = Vec2::new((j as f32 + 0.5) / nu as f32, (i as f32 + 0.5) / nv as f32);
            let dir = env_direction(uv);
            let dw = 2.0 * PI * PI * (PI * uv.y).sin() / (nu * nv) as f32;
            total += (environment_pdf(&scene, &params, dir) * dw) as f64;
        }
    }
    assert!((total - 1.0).abs() < 2e-3, "∫ pdf dω = {total}");
}

#[test]
fn sampling_estimates_the_integral_of_the_map() {
    let map = sky(64, 32);
    let (scene, params) = setup(map.clone());
    // Exact: Σ texel × its solid angle (2π/W)(cos θ0 − cos θ1).
    let mut exact = Vec3::ZERO.as_dvec3();
    for i in 0..map.height {
        let t0 = PI * i as f32 / map.height as f32;
        let t1 = PI * (i + 1) as f32 / map.height as f32;
        let dw = 2.0 * PI / map.width as f32 * (t0.cos() - t1.cos());
        for j in 0..map.width {
            exact += (map.texels[(i * map.width + j) as usize] * dw).as_dvec3();
        }
    }
    let mut rng = Lcg(3);
    let n = 400_000;
    let (mut sum, mut sum2) = (Vec3::ZERO.as_dvec3(), Vec3::ZERO.as_dvec3());
    for _ in 0..n {
        let dir = sample_environment(&scene, &params, Vec2::new(rng.f(), rng.f()));
        let pdf = environment_pdf(&scene, &params, dir);
        assert!(pdf > 0.0, "sampled a direction of zero density: {dir}");
        let x = (environment_radiance(&scene, &params, dir) / pdf).as_dvec3();
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean) / n as f64).max(glam::DVec3::ZERO).sqrt();
    for c in 0..3 {
        assert!(
            (mean[c] - exact[c]).abs() < 4.0 * se[c] + 1e-3 * exact[c],
            "estimate {mean} vs exact {exact} (se {se})"
        );
    }
    // Importance sampling ∝ luminance: the luminance estimate is nearly constant.
    assert!(veach::packed::luminance(se.as_vec3()) < 0.01 * veach::packed::luminance(exact.as_vec3()));
}

fn furnace_with_map(map: EnvironmentMap, ctx: Option<veach::gpu::GpuContext>, seed: u32) -> veach::film::Film {
    let (mut scene, camera) = common::load_pair(&asset("furnace-a080.gltf"), None).expect("scene");
    scene.environment = veach::Environment::map(map, Vec3::ONE);
    let packed = PackedScene::new(&scene);
    let mut r = common::renderer(packed, &camera, &settings(48, 8, seed), ctx).expect("renderer");
    r.render_samples(0, 64).expect("render");
    r.film().expect("film")
}

#[test]
fn constant_map_is_a_constant_environment() {
    // The grey furnace lit by a constant map equals the same furnace lit by a constant color.
    let film = furnace_with_map(EnvironmentMap::constant(16, 8, Vec3::ONE), None, 1);
    let constant = render(&asset("furnace-a080.gltf"), &settings(48, 8, 2), 64, None);
    let (a, va) = film_stats(&film);
    let (b, vb) = film_stats(&constant);
    let agree = agreement(&a, &va, &b, &vb);
    assert!(agree.mean_z.abs().max_element() < 5.0 && agree.outliers < 0.005, "{agree:?}");
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn gpu_and_cpu_agree_under_a_sky() {
    let Some(ctx) = gpu("gpu_and_cpu_agree_under_a_sky") else { return };
    let g = furnace_with_map(sky(64, 32), Some(ctx), 3);
    let c = furnace_with_map(sky(64, 32), None, 4);
    let (gm, gv) = film_stats(&g);
    let (cm, cv) = film_stats(&c);
    let a = agreement(&gm, &gv, &cm, &cv);
    eprintln!("sky gpu vs cpu: {a:?}");
    assert!(a.mean_z.abs().max_element() < 5.0 && a.mean_rel.abs().max_element() < 0.02 && a.outliers < 0.01, "{a:?}");
}

/// A new sky through `Renderer::set_environment` (light data replaced, geometry and BVH
/// kept) renders exactly what a renderer built with that sky renders, on both engines.
fn a_new_sky_renders_as_built_with_it(ctx: Option<veach::gpu::GpuContext>) {
    let (scene, camera) = common::load_pair(&asset("furnace-a080.gltf"), None).expect("scene");
    let new_sky = veach::Environment::map(sky(16, 8), Vec3::splat(0.7));
    let mut with_sky = scene.clone();
    with_sky.environment = new_sky.clone();
    let s = settings(24, 4, 3);
    let mut swapped = common::renderer(PackedScene::new(&scene), &camera, &s, ctx.clone()).unwrap();
    swapped.render_samples(0, 2).unwrap();
    // Compared as bytes: CWBVH nodes in BvhNode-sized slots can read as NaN floats.
    let bytes = |r: &veach::Renderer| bytemuck::cast_slice::<_, u8>(&r.scene().nodes).to_vec();
    let nodes = bytes(&swapped);
    swapped.set_environment(&camera, &new_sky).unwrap();
    swapped.render_samples(0, 4).unwrap();
    let mut fresh = common::renderer(PackedScene::new(&with_sky), &camera, &s, ctx).unwrap();
    fresh.render_samples(0, 4).unwrap();
    assert!(swapped.film().unwrap().data == fresh.film().unwrap().data, "the swapped sky renders differently");
    assert!(bytes(&swapped) == nodes, "the BVH changed");
}

#[test]
fn a_new_sky_renders_as_a_renderer_built_with_it() {
    a_new_sky_renders_as_built_with_it(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn a_new_sky_renders_as_a_renderer_built_with_it_on_the_gpu() {
    let Some(ctx) = gpu("a_new_sky_renders_as_a_renderer_built_with_it_on_the_gpu") else { return };
    a_new_sky_renders_as_built_with_it(Some(ctx));
}

/// The stored default studio (`assets/studio.hdr`, what renders use) is its generator's
/// output to RGBE precision (an 8-bit mantissa: 1 % of the texel), grey, and a studio: its
/// softboxes are far brighter than the cyclorama around them.
#[test]
fn the_stored_studio_is_its_generator_s_output() {
    use veach::scene::studio::{STUDIO_HEIGHT, STUDIO_WIDTH, generate_studio};
    let stored = EnvironmentMap::studio();
    let made = generate_studio(STUDIO_WIDTH, STUDIO_HEIGHT);
    assert_eq!((stored.width, stored.height), (made.width, made.height));
    for (i, (a, b)) in stored.texels.iter().zip(&made.texels).enumerate() {
        let tolerance = 0.01 * a.max(*b).max_element() + 1e-6;
        assert!((*a - *b).abs().max_element() <= tolerance, "texel {i}: stored {a}, generated {b}");
        assert!(a.x == a.y && a.y == a.z, "texel {i} is not grey: {a}");
    }
    let (lo, hi) = stored.texels.iter().fold((f32::MAX, 0f32), |(lo, hi), t| (lo.min(t.x), hi.max(t.x)));
    assert!(lo > 0.0 && hi > 20.0 * lo, "radiance spans {lo}..{hi}");
}

/// A white diffuse quad facing the camera (+Z) and nothing else: a scene with no light of any
/// kind. By default the studio lights it, and it reads the studio's irradiance on +Z over π,
/// which the generator sets to 1 (a check of the map's orientation and of its sampling end to
/// end); `env_color` 0,0,0 keeps it black on purpose.
fn lit_by_the_studio_unless_asked_for_black(ctx: Option<veach::gpu::GpuContext>) {
    let engine = if ctx.is_some() { "gpu" } else { "cpu" };
    let dir = std::env::temp_dir().join(format!("veach-studio-{}-{engine}", std::process::id()));
    let mut b = common::build::GltfBuilder::new(&dir, "white-quad");
    b.use_extension("KHR_materials_specular");
    let white = b.material(serde_json::json!({
        "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}},
    }));
    let quad =
        b.mesh(&common::build::MeshData::quad(-1.0, -1.0, 1.0, 1.0, 0.0, common::build::MeshData::UPRIGHT), white);
    b.node(serde_json::json!({"mesh": quad}));
    b.camera(0.3, 1.0, [0.0, 0.0, 2.0]);
    let path = b.write();
    let (scene, camera) = common::load_pair(&path, None).expect("scene");
    let s = settings(16, 2, 1);
    let mut r = common::renderer(PackedScene::new(&scene), &camera, &s, ctx.clone()).unwrap();
    assert_eq!(r.environment_source(), veach::EnvironmentSource::Studio);
    r.render_samples(0, 256).unwrap();
    let film = r.film().unwrap();
    let n = film.pixel_count();
    let mean = (0..n).map(|i| film.mean(i)).sum::<Vec3>() / n as f32;
    assert!((mean - Vec3::ONE).abs().max_element() < 0.02, "the white quad reads {mean}, expected 1");

    let black = veach::Settings { env_color: Some([0.0; 3]), ..s.clone() };
    let mut r = common::renderer(PackedScene::new(&scene), &camera, &black, ctx).unwrap();
    assert_eq!(r.environment_source(), veach::EnvironmentSource::Settings);
    r.render_samples(0, 4).unwrap();
    assert!(r.film().unwrap().to_rgb32f().iter().all(|v| *v == 0.0), "asked for black");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scene_without_lights_is_lit_by_the_studio_unless_asked_for_black() {
    lit_by_the_studio_unless_asked_for_black(None);
    // A scene with lights of its own keeps its (black) environment.
    let (scene, camera) = common::load_pair(&asset("cornell-box.gltf"), None).unwrap();
    let r = common::renderer(PackedScene::new(&scene), &camera, &settings(16, 2, 1), None).unwrap();
    assert_eq!(r.environment_source(), veach::EnvironmentSource::Scene);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn a_scene_without_lights_is_lit_by_the_studio_unless_asked_for_black_on_the_gpu() {
    let Some(ctx) = gpu("a_scene_without_lights_is_lit_by_the_studio_unless_asked_for_black_on_the_gpu") else {
        return;
    };
    lit_by_the_studio_unless_asked_for_black(Some(ctx));
}
