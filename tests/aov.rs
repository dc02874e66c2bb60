//! The AOVs (albedo, normal and depth of the first visible surface): what they read on
//! surfaces whose values are known, that they look through smooth glass, that they leave
//! the image alone, agree across engines and resume and merge exactly.

mod common;

use common::build::{GltfBuilder, MeshData};
use glam::Vec3;
use serde_json::json;
use std::path::PathBuf;
use veach::aov::Aov;
use veach::gpu::GpuContext;
use veach::{Film, Settings};

const SIZE: u32 = 24;

/// A quad of base colour `color` at z = 0 filling the view of a camera at z = `distance`,
/// lit by a constant sky; with `glass`, a smooth thin-walled pane at z = 0.5 in front.
fn scene(name: &str, color: [f32; 3], metallic: f32, glass: bool, distance: f32) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("veach-aov-{}-{name}", std::process::id()));
    let mut b = GltfBuilder::new(&dir, name);
    let wall = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [color[0], color[1], color[2], 1.0],
        "metallicFactor": metallic, "roughnessFactor": 0.5}}));
    let quad = b.mesh(&MeshData::quad(-4.0, -4.0, 4.0, 4.0, 0.0, MeshData::UPRIGHT), wall);
    b.node(json!({"mesh": quad}));
    if glass {
        b.use_extension("KHR_materials_transmission");
        let pane = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
            "roughnessFactor": 0}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}}));
        let m = b.mesh(&MeshData::quad(-4.0, -4.0, 4.0, 4.0, 0.5, MeshData::UPRIGHT), pane);
        b.node(json!({"mesh": m}));
    }
    b.camera(0.5, 1.0, [0.0, 0.0, distance]);
    b.write()
}

fn settings(seed: u32) -> Settings {
    Settings {
        width: SIZE,
        height: SIZE,
        seed,
        env_color: Some([1.0, 1.0, 1.0]),
        aovs: Aov::ALL.to_vec(),
        ..Settings::default()
    }
}

fn mean3(v: &[f32]) -> Vec3 {
    let n = (v.len() / 3) as f32;
    v.chunks_exact(3).fold(Vec3::ZERO, |a, c| a + Vec3::from_slice(c)) / n
}

/// A rough metal of colour c reflects c at normal incidence (Schlick's F0), so its albedo AOV
/// is c where the camera looks almost straight at it; its normal faces the camera; depth is
/// the distance along each pixel's ray to the plane (independent pinhole geometry here).
fn read_a_known_surface(ctx: Option<GpuContext>) {
    let c = [0.7, 0.3, 0.1];
    let d = 3.0;
    let engine = if ctx.is_some() { "gpu" } else { "cpu" };
    let path = scene(&format!("metal-{engine}"), c, 1.0, false, d);
    let film = common::render(&path, &settings(1), 4, ctx);
    let albedo = film.aov_image(Aov::Albedo).expect("albedo");
    let normal = film.aov_image(Aov::Normal).expect("normal");
    let depth = film.aov_image(Aov::Depth).expect("depth");
    // Rays leave the camera at most 0.25·√2 rad off axis: Schlick's term (1 − cos)^5 < 1e-6.
    for (i, a) in albedo.chunks_exact(3).enumerate() {
        assert!((Vec3::from_slice(a) - Vec3::from(c)).abs().max_element() < 1e-4, "{engine} albedo {i}: {a:?}");
    }
    for n in normal.chunks_exact(3) {
        assert!((Vec3::from_slice(n) - Vec3::Z).length() < 1e-5, "{engine} normal {n:?}");
    }
    let tan = (0.5f32 / 2.0).tan();
    for (i, z) in depth.iter().enumerate() {
        let (x, y) = ((i as u32 % SIZE) as f32 + 0.5, (i as u32 / SIZE) as f32 + 0.5);
        let (u, v) = ((2.0 * x / SIZE as f32 - 1.0) * tan, (1.0 - 2.0 * y / SIZE as f32) * tan);
        // Samples jitter inside the pixel: the mean distance is within the pixel's range.
        let centre = d * (1.0 + u * u + v * v).sqrt();
        assert!((z - centre).abs() < d * 2e-3, "{engine} depth {i}: {z} vs {centre}");
    }
}

#[test]
fn aovs_read_a_known_surface() {
    read_a_known_surface(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn aovs_read_a_known_surface_on_the_gpu() {
    let Some(ctx) = common::gpu("aovs_read_a_known_surface_on_the_gpu") else { return };
    read_a_known_surface(Some(ctx));
}

/// Behind a smooth thin pane the AOVs are those of the wall seen through it, blended with the
/// pane's own (albedo 1) by the path's Fresnel choice: T·c + R·1 with R = 0.04 (ior 1.5 at
/// normal incidence), within the choice's binomial noise over the image.
#[test]
fn aovs_look_through_smooth_glass() {
    let c = [0.2, 0.6, 0.3];
    let path = scene("glass", c, 0.0, true, 3.0);
    let mut s = settings(2);
    s.sampler = veach::SamplerKind::Independent;
    let film = common::render(&path, &s, 64, None);
    let albedo = mean3(&film.aov_image(Aov::Albedo).unwrap());
    // The wall's albedo seen straight on: its diffuse colour under 1 − F plus F (dielectric
    // F0 = 0.04), as bsdf_albedo defines it.
    let wall = Vec3::from(c) * 0.96 + Vec3::splat(0.04);
    let expected = wall * 0.96 + Vec3::splat(0.04);
    let n = (SIZE * SIZE * 64) as f32;
    let sigma = (0.04f32 * 0.96 / n).sqrt() * 1.0;
    assert!((albedo - expected).abs().max_element() < 5.0 * sigma + 2e-3, "{albedo} vs {expected} (σ {sigma})");
    let depth = film.aov_image(Aov::Depth).unwrap();
    assert!(depth.iter().all(|z| (2.5..2.7).contains(z)), "depth is the pane's, the first hit");
}

/// The film with AOVs of one engine, checked to hold the same image words as the film
/// without them.
fn aovs_leave_the_image_alone(ctx: Option<GpuContext>) -> Film {
    let path = common::asset("cornell-glass.gltf");
    let with = Settings { max_depth: 8, ..settings(9) };
    let without = Settings { aovs: Vec::new(), ..with.clone() };
    let gpu = ctx.is_some();
    let a = common::render(&path, &with, 3, ctx.clone());
    let b = common::render(&path, &without, 3, ctx);
    let pixels = a.pixel_count() * veach::film::WORDS_PER_PIXEL;
    assert_eq!(a.data[..pixels], b.data[..pixels], "gpu = {gpu}: the image changed with AOVs");
    a
}

/// AOVs take no random numbers: the image's words are the same with and without them, on
/// both engines, and the engines' AOVs agree.
#[test]
fn aovs_leave_the_image_alone_and_agree_across_engines() {
    aovs_leave_the_image_alone(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn aovs_leave_the_image_alone_and_agree_across_engines_on_the_gpu() {
    let Some(ctx) = common::gpu("aovs_leave_the_image_alone_and_agree_across_engines_on_the_gpu") else { return };
    let gpu = aovs_leave_the_image_alone(Some(ctx));
    let cpu = aovs_leave_the_image_alone(None);
    for aov in Aov::ALL {
        let (x, y) = (cpu.aov_image(aov).unwrap(), gpu.aov_image(aov).unwrap());
        let close = x.iter().zip(&y).filter(|(a, b)| (*a - *b).abs() <= 1e-4 * a.abs().max(1.0) || a == b).count();
        assert!(close as f32 >= 0.98 * x.len() as f32, "{aov:?}: {close} of {} values agree", x.len());
    }
}

/// Films with AOVs merge and resume exactly: two sample ranges merged are the film of one
/// render, word for word, and an EXR round trip keeps every word.
#[test]
fn aovs_merge_and_resume_exactly() {
    let path = common::asset("cornell-box.gltf");
    let s = Settings { width: 16, height: 16, ..settings(4) };
    let (scene, camera) = common::load_pair(&path, None).unwrap();
    let render = |start: u32, count: u32| -> Film {
        let mut r = veach::Renderer::new(veach::PackedScene::new(&scene), &camera, &s, veach::Backend::Cpu).unwrap();
        r.render_samples(start, count).unwrap();
        r.film().unwrap()
    };
    let whole = render(0, 6);
    let job = |a: u32, b: u32| veach::Job { scene: path.clone(), settings: s.clone(), sample_start: a, sample_end: b };
    let parts = vec![
        veach::Part { film: render(0, 2), job: job(0, 2), path: "a".into() },
        veach::Part { film: render(2, 4), job: job(2, 6), path: "b".into() },
    ];
    // The exact words: the radiance's sums and counts (its f32 sums of squares are not
    // exact under merging and are not saved) and every AOV word.
    let exact = |f: &Film| -> Vec<u32> {
        let w = veach::film::WORDS_PER_PIXEL;
        (0..f.pixel_count()).flat_map(|i| f.data[i * w..i * w + 8].iter().chain(f.aov_words(i)).copied()).collect()
    };
    let (merged, _) = veach::merge(&parts).unwrap();
    assert_eq!(merged.layout, whole.layout);
    assert!(exact(&merged) == exact(&whole), "merged parts are the whole render, AOVs included");
    let dir = common::cli::temp_dir("aov-exr");
    let exr = dir.path().join("f.exr");
    veach::output::write(&whole, &exr, 0.0, Some(&job(0, 6))).unwrap();
    let (back, _) = veach::output::read_film(&exr).unwrap();
    assert!(exact(&back) == exact(&whole), "the EXR keeps every AOV word");
    assert_eq!(back.aov_image(Aov::Depth), whole.aov_image(Aov::Depth));
    // Without AOVs the same parts do not merge with these.
    let plain = Settings { aovs: Vec::new(), ..s.clone() };
    let other =
        veach::Part { film: Film::new(16, 16), job: veach::Job { settings: plain, ..job(6, 8) }, path: "c".into() };
    let parts = vec![veach::Part { film: render(0, 2), job: job(0, 2), path: "a".into() }, other];
    assert!(veach::merge(&parts).is_err(), "AOV layers differ");
}
