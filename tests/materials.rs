//! glTF as users bring it, checked against expectations computed here, independently of
//! veach's code: textures (orientation, sRGB, wrap, KHR_texture_transform), alpha MASK and
//! BLEND, normal maps through generated and supplied tangents, punctual lights against the
//! analytic irradiance, glass in a furnace. Each scene is built in code (tests/common/build.rs)
//! and rendered on the CPU reference and, in a test of its own (`…_on_the_gpu`), on the GPU.

mod common;

use common::build::{GltfBuilder, MeshData};
use common::{agreement, film_stats, gpu};
use glam::{Quat, Vec3};
use serde_json::json;
use std::path::{Path, PathBuf};
use veach::Settings;
use veach::film::Film;
use veach::gpu::GpuContext;

const CLAMP: u32 = 33071;
const REPEAT: u32 = 10497;

fn dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("veach-materials-{}-{name}", std::process::id()))
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// The engine a context selects: "gpu" with one, else "cpu" (the CPU reference).
fn engine(ctx: &Option<GpuContext>) -> &'static str {
    if ctx.is_some() { "gpu" } else { "cpu" }
}

/// Renders on the CPU reference or, given a context, on the GPU: (backend name, film).
fn render_on(path: &Path, settings: &Settings, spp: u32, ctx: Option<GpuContext>) -> (&'static str, Film) {
    let (scene, camera) = common::load_pair(path, None).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let packed = veach::packed::PackedScene::new(&scene);
    let backend = engine(&ctx);
    let mut r = common::renderer(packed, &camera, settings, ctx).unwrap();
    r.render_samples(0, spp).unwrap();
    (backend, r.film().unwrap())
}

/// The GPU's film agrees with the CPU reference's pixel by pixel within 5 standard errors.
fn assert_films_agree(what: &str, gpu: &Film, cpu: &Film) {
    let (gm, gv) = film_stats(gpu);
    let (cm, cv) = film_stats(cpu);
    let a = agreement(&gm, &gv, &cm, &cv);
    assert!(a.mean_z.abs().max_element() < 5.0, "{what}: GPU vs CPU {a:?}");
}

fn settings(width: u32, height: u32, max_depth: u32) -> Settings {
    Settings { width, height, max_depth, env_color: Some([0.0; 3]), ..Settings::default() }
}

/// A camera at z = `d` looking down −z whose view spans y ∈ [−half, half] on the plane z = 0.
fn camera_for(b: &mut GltfBuilder, d: f32, half: f32, aspect: f32) {
    b.camera(2.0 * (half / d).atan(), aspect, [0.0, 0.0, d]);
}

/// 4×4 texels in 2×2 blocks: A top-left, B top-right, C bottom-left, D bottom-right (sRGB).
const BLOCKS: [[u8; 3]; 4] = [[200, 30, 30], [30, 200, 30], [30, 30, 200], [220, 220, 60]];

fn block_texture() -> image::RgbaImage {
    image::RgbaImage::from_fn(4, 4, |x, y| {
        let c = BLOCKS[(y / 2 * 2 + x / 2) as usize];
        image::Rgba([c[0], c[1], c[2], 255])
    })
}

fn emissive_textures_on(ctx: Option<GpuContext>) {
    let d = dir(&format!("textures-{}", engine(&ctx)));
    let mut b = GltfBuilder::new(&d, "textures");
    b.use_extension("KHR_texture_transform");
    let clamp = b.texture(&block_texture(), CLAMP);
    let repeat = b.texture(&block_texture(), REPEAT);
    let black = json!({"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0});
    let plain = b.material(json!({"pbrMetallicRoughness": black, "emissiveFactor": [1, 1, 1],
        "emissiveTexture": {"index": clamp}}));
    let shifted = b.material(json!({"pbrMetallicRoughness": black, "emissiveFactor": [1, 1, 1],
        "emissiveTexture": {"index": repeat, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.0]}}}}));
    let left = b.mesh(&MeshData::quad(-2.0, -1.0, 0.0, 1.0, 0.0, MeshData::UPRIGHT), plain);
    let right = b.mesh(&MeshData::quad(0.0, -1.0, 2.0, 1.0, 0.0, MeshData::UPRIGHT), shifted);
    b.node(json!({"mesh": left}));
    b.node(json!({"mesh": right}));
    camera_for(&mut b, 3.0, 1.0, 2.0);
    let path = b.write();
    // Pixel centres at u, v ≈ 0.26 or 0.76 sit inside one block even after bilinear filtering.
    // Right quad: u + 0.5 with repeat swaps the left and right blocks.
    let expect = [
        ((16, 16), 0),
        ((48, 16), 1),
        ((16, 48), 2),
        ((48, 48), 3),
        ((80, 16), 1),
        ((112, 16), 0),
        ((80, 48), 3),
        ((112, 48), 2),
    ];
    let (backend, film) = render_on(&path, &settings(128, 64, 1), 4, ctx);
    for ((x, y), block) in expect {
        let got = film.mean(y * 128 + x);
        let want = Vec3::from(BLOCKS[block].map(srgb_to_linear));
        assert!(
            (got - want).abs().max_element() < 2e-3 + 2e-3 * want.max_element(),
            "{backend}: pixel ({x}, {y}) is {got}, expected block {block} = {want}"
        );
    }
}

#[test]
fn emissive_textures_show_upright_in_linear_rgb_with_wrap_and_transform() {
    emissive_textures_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn emissive_textures_show_upright_in_linear_rgb_with_wrap_and_transform_on_the_gpu() {
    let Some(ctx) = gpu("emissive_textures_show_upright_in_linear_rgb_with_wrap_and_transform_on_the_gpu") else {
        return;
    };
    emissive_textures_on(Some(ctx));
}

/// KHR_materials_unlit: a surface shows its base color (factor × sRGB texture) whatever the
/// light: under a bright point light the pixels read the base color itself, textured or not.
fn unlit_materials_on(ctx: Option<GpuContext>) {
    let d = dir(&format!("unlit-{}", engine(&ctx)));
    let mut b = GltfBuilder::new(&d, "unlit");
    b.use_extension("KHR_materials_unlit");
    let blocks = b.texture(&block_texture(), CLAMP);
    let unlit = json!({"KHR_materials_unlit": {}});
    let textured =
        b.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": blocks}}, "extensions": unlit}));
    let flat =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.5, 0.8, 1.0]}, "extensions": unlit}));
    let left = b.mesh(&MeshData::quad(-2.0, -1.0, 0.0, 1.0, 0.0, MeshData::UPRIGHT), textured);
    let right = b.mesh(&MeshData::quad(0.0, -1.0, 2.0, 1.0, 0.0, MeshData::UPRIGHT), flat);
    b.node(json!({"mesh": left}));
    b.node(json!({"mesh": right}));
    b.light(json!({"type": "point", "intensity": 200.0, "color": [1, 1, 1]}), json!({"translation": [0.0, 0.0, 1.5]}));
    camera_for(&mut b, 3.0, 1.0, 2.0);
    let path = b.write();
    // Required, as exporters mark it: the file loads (the gltf crate alone refuses it).
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    doc["extensionsRequired"] = json!(["KHR_materials_unlit"]);
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let loaded = veach::load(&path, None).unwrap();
    assert!(loaded.warnings.iter().all(|w| !w.contains("unlit")), "{:?}", loaded.warnings);
    let expect =
        [((16, 16), Vec3::from(BLOCKS[0].map(srgb_to_linear))), ((48, 48), Vec3::from(BLOCKS[3].map(srgb_to_linear)))];
    let (backend, film) = render_on(&path, &settings(128, 64, 8), 4, ctx);
    for ((x, y), want) in expect.into_iter().chain([((96, 32), Vec3::new(0.2, 0.5, 0.8))]) {
        let got = film.mean(y * 128 + x);
        assert!(
            (got - want).abs().max_element() < 2e-3 + 2e-3 * want.max_element(),
            "{backend}: pixel ({x}, {y}) is {got}, expected the base color {want}"
        );
    }
}

#[test]
fn unlit_materials_show_their_base_color_whatever_the_light() {
    unlit_materials_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn unlit_materials_show_their_base_color_whatever_the_light_on_the_gpu() {
    let Some(ctx) = gpu("unlit_materials_show_their_base_color_whatever_the_light_on_the_gpu") else { return };
    unlit_materials_on(Some(ctx));
}

fn alpha_on(ctx: Option<GpuContext>) {
    let d = dir(&format!("alpha-{}", engine(&ctx)));
    let mut b = GltfBuilder::new(&d, "alpha");
    // Left half of the mask texture transparent, right half opaque.
    let mask = image::RgbaImage::from_fn(4, 4, |x, _| image::Rgba([255, 255, 255, if x < 2 { 0 } else { 255 }]));
    let mask = b.texture(&mask, CLAMP);
    let light =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "emissiveFactor": [1, 1, 1]}));
    let masked = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1],
        "baseColorTexture": {"index": mask}}, "alphaMode": "MASK", "alphaCutoff": 0.5}));
    let blended =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 0.25]}, "alphaMode": "BLEND"}));
    let back = b.mesh(&MeshData::quad(-10.0, -10.0, 10.0, 10.0, -1.0, MeshData::UPRIGHT), light);
    let left = b.mesh(&MeshData::quad(-2.0, -1.0, 0.0, 1.0, 0.0, MeshData::UPRIGHT), masked);
    let right = b.mesh(&MeshData::quad(0.0, -1.0, 2.0, 1.0, 0.0, MeshData::UPRIGHT), blended);
    for m in [back, left, right] {
        b.node(json!({"mesh": m}));
    }
    camera_for(&mut b, 3.0, 1.0, 2.0);
    let path = b.write();
    let spp = 64;
    let (backend, film) = render_on(&path, &settings(128, 64, 1), spp, ctx);
    let region = |x0: usize, x1: usize| {
        let mut sum = 0.0f64;
        let mut n = 0;
        for y in 4..60 {
            for x in x0..x1 {
                sum += film.mean(y * 128 + x).y as f64;
                n += 1;
            }
        }
        sum / n as f64
    };
    // Mask: the transparent half shows the light behind, the opaque half is black.
    assert!((region(4, 28) - 1.0).abs() < 1e-4, "{backend}: masked-out half {}", region(4, 28));
    assert!(region(36, 60) < 1e-4, "{backend}: opaque half {}", region(36, 60));
    // Blend, α = 0.25: a quarter of the rays stop at the black quad. The region holds
    // 56 × 56 pixels × 64 samples; the binomial standard error of the mean is < 0.001.
    let seen = region(68, 124);
    assert!((seen - 0.75).abs() < 0.005, "{backend}: blended region {seen}, expected 0.75");
}

#[test]
fn alpha_mask_cuts_and_blend_lets_light_through_in_proportion() {
    alpha_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn alpha_mask_cuts_and_blend_lets_light_through_in_proportion_on_the_gpu() {
    let Some(ctx) = gpu("alpha_mask_cuts_and_blend_lets_light_through_in_proportion_on_the_gpu") else { return };
    alpha_on(Some(ctx));
}

/// A hemisphere bump in tangent space, in the image convention glTF uses (+X right, +Y up).
fn bump_normal_map() -> image::RgbaImage {
    image::RgbaImage::from_fn(64, 64, |x, y| {
        let dx = (x as f32 + 0.5) / 64.0 - 0.5;
        let dy = 0.5 - (y as f32 + 0.5) / 64.0;
        let r2 = dx * dx + dy * dy;
        let n = if r2 < 0.16 { Vec3::new(dx, dy, (0.16 - r2).sqrt()).normalize() } else { Vec3::Z };
        let e = |v: f32| ((v * 0.5 + 0.5) * 255.0).round() as u8;
        image::Rgba([e(n.x), e(n.y), e(n.z), 255])
    })
}

fn normal_maps_on(ctx: Option<GpuContext>) {
    let d = dir(&format!("normals-{}", engine(&ctx)));
    let mut b = GltfBuilder::new(&d, "normals");
    let map = b.texture(&bump_normal_map(), REPEAT);
    // Lambertian (no specular layer), so the view direction, different per tile, cannot matter.
    b.use_extension("KHR_materials_specular");
    let material = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1],
        "metallicFactor": 0, "roughnessFactor": 1}, "normalTexture": {"index": map},
        "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}));
    // Corner UVs (bottom-left, bottom-right, top-right, top-left): upright, mirrored in u,
    // rotated 90°, rotated 180°; then mirrored again with supplied tangents (w = −1).
    let layouts: [[[f32; 2]; 4]; 5] = [
        MeshData::UPRIGHT,
        [[1.0, 1.0], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0]],
        [[1.0, 1.0], [1.0, 0.0], [0.0, 0.0], [0.0, 1.0]],
        [[1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [1.0, 1.0]],
        [[1.0, 1.0], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0]],
    ];
    for (k, uvs) in layouts.iter().enumerate() {
        let x0 = -2.5 + k as f32;
        let mut quad = MeshData::quad(x0, -0.5, x0 + 1.0, 0.5, 0.0, *uvs);
        if k == 4 {
            // u runs along −x: T = −x, and the map's +Y is +y = cross(N, T)·w, so w = −1.
            quad.tangents = vec![[-1.0, 0.0, 0.0, -1.0]; 4];
        }
        let mesh = b.mesh(&quad, material);
        b.node(json!({"mesh": mesh}));
    }
    // A directional light from the upper left, travelling along (1, −1, −1).
    let travel = Vec3::new(1.0, -1.0, -1.0).normalize();
    let q = Quat::from_rotation_arc(Vec3::NEG_Z, travel);
    b.light(json!({"type": "directional", "intensity": 3.0}), json!({"rotation": q.to_array()}));
    camera_for(&mut b, 4.0, 0.5, 5.0);
    let path = b.write();
    let (backend, film) = render_on(&path, &settings(320, 64, 2), 8, ctx);
    // Mean brightness of the bump's upper-left and lower-right quadrants on each tile.
    let quadrants = |k: u32| {
        let (mut ul, mut lr, mut n) = (0.0f32, 0.0f32, 0);
        for y in 0..64 {
            for x in 0..64 {
                let dx = (x as f32 + 0.5) / 64.0 - 0.5;
                let dy = 0.5 - (y as f32 + 0.5) / 64.0;
                let r2 = dx * dx + dy * dy;
                if !(0.01..0.12).contains(&r2) || dx.abs() < 0.05 || dy.abs() < 0.05 {
                    continue;
                }
                let v = film.mean((y * 320 + 64 * k + x) as usize).y;
                if dx < 0.0 && dy > 0.0 {
                    ul += v;
                    n += 1;
                } else if dx > 0.0 && dy < 0.0 {
                    lr += v;
                }
            }
        }
        (ul / n as f32, lr / n as f32)
    };
    let (ul0, lr0) = quadrants(0);
    for k in 0..5 {
        let (ul, lr) = quadrants(k);
        assert!(ul > 2.0 * lr, "{backend} tile {k}: the lit side of the bump is dark ({ul} vs {lr})");
        assert!(
            (ul - ul0).abs() < 0.05 * ul0 && (lr - lr0).abs() < 0.05 * ul0,
            "{backend} tile {k}: shades differently from the upright tile ({ul}, {lr} vs {ul0}, {lr0})"
        );
    }
}

#[test]
fn normal_maps_light_bumps_from_the_light_side_for_every_uv_layout() {
    normal_maps_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn normal_maps_light_bumps_from_the_light_side_for_every_uv_layout_on_the_gpu() {
    let Some(ctx) = gpu("normal_maps_light_bumps_from_the_light_side_for_every_uv_layout_on_the_gpu") else { return };
    normal_maps_on(Some(ctx));
}

/// A white Lambertian plane z = 0 spanning [−2, 2]², seen from above, lit by one light.
fn lit_plane(name: &str, light: serde_json::Value, node: serde_json::Value) -> PathBuf {
    let mut b = GltfBuilder::new(&dir(name), name);
    b.use_extension("KHR_materials_specular");
    let white = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1],
        "metallicFactor": 0, "roughnessFactor": 1}, "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}));
    let plane = b.mesh(&MeshData::quad(-2.0, -2.0, 2.0, 2.0, 0.0, MeshData::UPRIGHT), white);
    b.node(json!({"mesh": plane}));
    b.light(light, node);
    camera_for(&mut b, 3.0, 2.0, 1.0);
    b.write()
}

/// Checks every pixel of a 64×64 render of `lit_plane` against L = E(p) / π averaged over
/// the pixel (the only randomness left at depth 2 is where in the pixel a sample lands).
fn check_irradiance(name: &str, path: &Path, irradiance: impl Fn(Vec3) -> f32, ctx: Option<GpuContext>) {
    let (backend, film) = render_on(path, &settings(64, 64, 2), 256, ctx);
    let mut worst = 0.0f32;
    for y in 0..64u32 {
        for x in 0..64u32 {
            let mut want = 0.0;
            for k in 0..256 {
                let (sx, sy) = ((k % 16) as f32 + 0.5, (k / 16) as f32 + 0.5);
                let p = Vec3::new(
                    -2.0 + 4.0 * (x as f32 + sx / 16.0) / 64.0,
                    2.0 - 4.0 * (y as f32 + sy / 16.0) / 64.0,
                    0.0,
                );
                want += irradiance(p) / std::f32::consts::PI / 256.0;
            }
            let i = (y * 64 + x) as usize;
            let got = film.mean(i).x;
            // Where the light varies within a pixel, where the sample lands matters: allow
            // 4.5 standard errors of the pixel mean on top of 1 %.
            let sigma = film.variance_of_mean(i).x.sqrt();
            let err = (got - want).abs() / (0.01 * want + 4.5 * sigma + 1e-6);
            worst = worst.max((got - want).abs() / want.max(1e-3));
            assert!(err < 1.0, "{name} {backend}: pixel ({x}, {y}) {got} ± {sigma} vs analytic {want}");
        }
    }
    eprintln!("{name} {backend}: worst relative error {worst:.4} (lit pixels)");
}

fn punctual_lights_on(ctx: Option<GpuContext>) {
    let pos = Vec3::new(0.3, 0.2, 1.0);
    let point = |p: Vec3| {
        let d = pos - p;
        5.0 * (d.z / d.length()) / d.length_squared()
    };
    let path = lit_plane(
        &format!("point-{}", engine(&ctx)),
        json!({"type": "point", "intensity": 5.0}),
        json!({"translation": pos.to_array()}),
    );
    check_irradiance("point light", &path, point, ctx.clone());

    // A spot pointing straight down: full intensity inside 0.3 rad, none outside 0.6 rad,
    // glTF's smooth falloff between.
    let (inner, outer) = (0.3f32, 0.6f32);
    let down = Quat::from_rotation_arc(Vec3::NEG_Z, Vec3::NEG_Z); // the spot's node looks down −z
    let path = lit_plane(
        &format!("spot-{}", engine(&ctx)),
        json!({"type": "spot", "intensity": 5.0, "spot": {"innerConeAngle": inner, "outerConeAngle": outer}}),
        json!({"translation": pos.to_array(), "rotation": down.to_array()}),
    );
    let spot = |p: Vec3| {
        let d = (p - pos).normalize();
        let t = ((d.dot(Vec3::NEG_Z) - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0);
        point(p) * t * t
    };
    check_irradiance("spot light", &path, spot, ctx.clone());

    // Directional, lux: E = I cos θ everywhere.
    let travel = Vec3::new(0.5, 0.0, -1.0).normalize();
    let q = Quat::from_rotation_arc(Vec3::NEG_Z, travel);
    let path = lit_plane(
        &format!("sun-{}", engine(&ctx)),
        json!({"type": "directional", "intensity": 2.0}),
        json!({"rotation": q.to_array()}),
    );
    check_irradiance("directional light", &path, |_| 2.0 * travel.z.abs(), ctx);
}

#[test]
fn punctual_lights_match_the_analytic_irradiance() {
    punctual_lights_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn punctual_lights_match_the_analytic_irradiance_on_the_gpu() {
    let Some(ctx) = gpu("punctual_lights_match_the_analytic_irradiance_on_the_gpu") else { return };
    punctual_lights_on(Some(ctx));
}

/// The white-furnace sphere (assets/furnace-a100.gltf) with another material.
fn furnace_of(name: &str, material: serde_json::Value, extensions: &[&str]) -> PathBuf {
    let src = std::fs::read(common::asset("furnace-a100.gltf")).unwrap();
    let mut doc: serde_json::Value = serde_json::from_slice(&src).unwrap();
    doc["materials"][0] = material;
    doc["extensionsUsed"] = json!(extensions);
    doc["extensionsRequired"] = json!(extensions);
    let d = dir(name);
    std::fs::create_dir_all(&d).unwrap();
    let path = d.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    path
}

/// The furnace sphere turned into glass of a roughness and ior (in a directory of its own per
/// `engine`).
fn glass_furnace(roughness: f32, ior: f32, engine: &str) -> PathBuf {
    furnace_of(
        &format!("glass-{roughness}-{ior}-{engine}"),
        json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
        "roughnessFactor": roughness}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_ior": {"ior": ior}, "KHR_materials_volume": {"thicknessFactor": 1.0}}}),
        &["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"],
    )
}

/// The furnace's image mean and its standard error (luminance channel y).
fn furnace_mean(film: &Film) -> (f64, f64) {
    let (mean, var) = film_stats(film);
    let n = mean.len() as f64;
    let m: f64 = mean.iter().map(|v| v.y as f64).sum::<f64>() / n;
    (m, (var.iter().map(|v| v.y as f64).sum::<f64>()).sqrt() / n)
}

/// Clearcoat and sheen over a white Lambertian sphere (specular 0) in a white furnace, all
/// bounces: the layers may lose what their model loses, never gain. A smooth coat loses
/// nothing (Fresnel splits between the mirror and the base); a rough one the energy of its
/// single-scattering GGX lobe times its Fresnel weight (a few %, tests/bsdf.rs); a white
/// sheen what the albedo scaling's smaller direction withholds; diffuse transmission nothing
/// (white, it splits the Lambertian lobe between the two sides). The GPU agrees with the CPU
/// within error bars.
fn layered_materials_on(ctx: Option<GpuContext>) {
    let white = |ext: serde_json::Value| {
        let mut e = ext;
        e["KHR_materials_specular"] = json!({"specularFactor": 0.0});
        json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 1},
            "extensions": e})
    };
    let cases = [
        ("smooth-coat", json!({"KHR_materials_clearcoat": {"clearcoatFactor": 1.0}}), 0.995),
        (
            "rough-coat",
            json!({"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.5}}),
            0.97,
        ),
        ("sheen", json!({"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.5}}), 0.9),
        (
            "iridescent",
            json!({"KHR_materials_iridescence": {"iridescenceFactor": 1.0, "iridescenceThicknessMaximum": 350.0}}),
            0.9,
        ),
        (
            "coat-and-sheen",
            json!({"KHR_materials_clearcoat": {"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.3},
                "KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.6, 0.3], "sheenRoughnessFactor": 0.3}}),
            0.88,
        ),
        (
            "diffuse-transmission",
            json!({"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0.7}}),
            0.995,
        ),
        (
            "coat-over-diffuse-transmission",
            json!({"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.3},
                "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0}}),
            0.97,
        ),
    ];
    for (name, ext, min_mean) in cases {
        let path = furnace_of(
            &format!("{name}-{}", engine(&ctx)),
            white(ext),
            &[
                "KHR_materials_specular",
                "KHR_materials_clearcoat",
                "KHR_materials_sheen",
                "KHR_materials_iridescence",
                "KHR_materials_diffuse_transmission",
            ],
        );
        let loaded = veach::load(&path, None).unwrap();
        assert!(loaded.warnings.is_empty(), "{name}: {:?}", loaded.warnings);
        let s = Settings { width: 48, height: 48, max_depth: 0, env_color: Some([1.0; 3]), ..Settings::default() };
        let (backend, film) = render_on(&path, &s, 32, ctx.clone());
        assert_eq!(film.nonfinite_samples(), 0);
        let (m, se) = furnace_mean(&film);
        eprintln!("{name} {backend}: image mean {m:.4} ± {se:.4}");
        assert!(m <= 1.0 + 4.0 * se + 1e-4, "{name} {backend}: energy gain, mean {m} ± {se}");
        assert!(m >= min_mean - 4.0 * se, "{name} {backend}: mean {m} ± {se} below {min_mean}");
        if ctx.is_some() {
            assert_films_agree(name, &film, &render_on(&path, &s, 32, None).1);
        }
    }
}

#[test]
fn layered_materials_in_a_furnace_gain_nothing_and_agree_across_engines() {
    layered_materials_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn layered_materials_in_a_furnace_gain_nothing_and_agree_across_engines_on_the_gpu() {
    let Some(ctx) = gpu("layered_materials_in_a_furnace_gain_nothing_and_agree_across_engines_on_the_gpu") else {
        return;
    };
    layered_materials_on(Some(ctx));
}

/// KHR_materials_pbrSpecularGlossiness converts to metallic-roughness at load: a sphere of
/// diffuse d, specular 0.04 and glossiness g renders as the non-metal of base color d and
/// roughness 1 − g (its equivalent by the extension's own definitions: F0 = specular, here
/// the 0.04 of ior 1.5) within error bars; a glossiness texture becomes a roughness texture
/// 1 − g·alpha, and the file may require the extension.
#[test]
fn specular_glossiness_renders_as_its_metallic_roughness_equivalent() {
    let sg = furnace_of(
        "spec-gloss",
        json!({"extensions": {"KHR_materials_pbrSpecularGlossiness": {"diffuseFactor": [0.5, 0.4, 0.3, 1.0],
            "specularFactor": [0.04, 0.04, 0.04], "glossinessFactor": 0.6}}}),
        &["KHR_materials_pbrSpecularGlossiness"],
    );
    let mr = furnace_of(
        "metal-rough",
        json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.4, 0.3, 1.0], "metallicFactor": 0.0,
            "roughnessFactor": 0.4}}),
        &[],
    );
    let s = Settings { width: 32, height: 32, max_depth: 4, env_color: Some([1.0; 3]), ..Settings::default() };
    let a = common::render(&sg, &s, 64, None);
    let b = common::render(&mr, &s, 64, None);
    let (am, av) = film_stats(&a);
    let (bm, bv) = film_stats(&b);
    let agree = agreement(&am, &av, &bm, &bv);
    assert!(agree.mean_z.abs().max_element() < 4.0, "spec-gloss vs metal-rough: {agree:?}");
    let (ma, _) = furnace_mean(&a);
    assert!(ma > 0.3 && ma < 0.95, "spec-gloss sphere mean {ma}: the sphere is not in the image");

    // Textured: the glossiness in the specular-glossiness texture's alpha.
    let d = dir("spec-gloss-texture");
    let mut builder = GltfBuilder::new(&d, "sgt");
    builder.use_extension("KHR_materials_pbrSpecularGlossiness");
    let image = image::RgbaImage::from_fn(4, 4, |x, _| image::Rgba([60, 60, 60, (x * 80) as u8]));
    let t = builder.texture(&image, CLAMP);
    let m = builder.material(json!({"extensions": {"KHR_materials_pbrSpecularGlossiness": {
        "glossinessFactor": 0.5, "specularGlossinessTexture": {"index": t}}}}));
    let quad = builder.mesh(&MeshData::quad(-1.0, -1.0, 1.0, 1.0, 0.0, MeshData::UPRIGHT), m);
    builder.node(json!({"mesh": quad}));
    camera_for(&mut builder, 3.0, 1.0, 1.0);
    let loaded = veach::load(&builder.write(), None).unwrap();
    let mat = &loaded.scene.materials[0];
    assert_eq!((mat.metallic, mat.roughness), (0.0, 1.0));
    let rough = &loaded.scene.textures[mat.metallic_roughness_texture.expect("a roughness texture").texture as usize];
    for x in 0..4usize {
        let want = ((1.0 - 0.5 * (x * 80) as f32 / 255.0) * 255.0).round() as u8;
        assert_eq!(
            rough.rgba[x * 4 + 1],
            want,
            "texel {x}: roughness {} for glossiness alpha {}",
            rough.rgba[x * 4 + 1],
            x * 80
        );
    }
    assert!(mat.specular_color_texture.is_some(), "the specular color comes from the texture's RGB");
}

/// Clearcoat and sheen with every texture the extensions define load from a file that
/// requires them, with their factors and textures (the normal texture's scale too), no
/// warnings, and render finite on both engines.
fn clearcoat_and_sheen_on(ctx: Option<GpuContext>) {
    let d = dir(&format!("layers-{}", engine(&ctx)));
    let mut b = GltfBuilder::new(&d, "layers");
    for e in ["KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_transmission", "KHR_materials_specular"]
    {
        b.use_extension(e);
    }
    let t = b.texture(&block_texture(), REPEAT);
    let n = b.texture(&bump_normal_map(), REPEAT);
    let m = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.3, 0.2, 1], "metallicFactor": 0},
        "normalTexture": {"index": n},
        "extensions": {
        "KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatTexture": {"index": t},
            "clearcoatRoughnessFactor": 0.25, "clearcoatRoughnessTexture": {"index": t},
            "clearcoatNormalTexture": {"index": n, "scale": 0.5}},
        "KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.4, 0.3], "sheenColorTexture": {"index": t},
            "sheenRoughnessFactor": 0.6, "sheenRoughnessTexture": {"index": t}},
        "KHR_materials_transmission": {"transmissionFactor": 0.5, "transmissionTexture": {"index": t}},
        "KHR_materials_specular": {"specularTexture": {"index": t}, "specularColorTexture": {"index": t}}}}));
    let quad = b.mesh(&MeshData::quad(-1.0, -1.0, 1.0, 1.0, 0.0, MeshData::UPRIGHT), m);
    b.node(json!({"mesh": quad}));
    b.light(json!({"type": "point", "intensity": 20.0}), json!({"translation": [0.3, 0.2, 1.5]}));
    camera_for(&mut b, 3.0, 1.0, 1.0);
    let path = b.write();
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    doc["extensionsRequired"] = json!(["KHR_materials_clearcoat", "KHR_materials_sheen"]);
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let loaded = veach::load(&path, None).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let mat = &loaded.scene.materials[0];
    assert_eq!((mat.clearcoat, mat.clearcoat_roughness, mat.clearcoat_normal_scale), (0.8, 0.25, 0.5));
    assert_eq!((mat.sheen_color, mat.sheen_roughness), (Vec3::new(0.5, 0.4, 0.3), 0.6));
    for (what, tex) in [
        ("clearcoatTexture", mat.clearcoat_texture),
        ("clearcoatRoughnessTexture", mat.clearcoat_roughness_texture),
        ("clearcoatNormalTexture", mat.clearcoat_normal_texture),
        ("sheenColorTexture", mat.sheen_color_texture),
        ("sheenRoughnessTexture", mat.sheen_roughness_texture),
        ("transmissionTexture", mat.transmission_texture),
        ("specularTexture", mat.specular_texture),
        ("specularColorTexture", mat.specular_color_texture),
    ] {
        assert!(tex.is_some(), "{what} was not read");
    }
    let (backend, film) = render_on(&path, &settings(32, 32, 4), 4, ctx);
    assert_eq!(film.nonfinite_samples(), 0, "{backend}");
    let (m, _) = furnace_mean(&film);
    assert!(m > 0.0 && m.is_finite(), "{backend}: mean {m}");
}

#[test]
fn clearcoat_and_sheen_load_with_their_textures() {
    clearcoat_and_sheen_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn clearcoat_and_sheen_load_with_their_textures_on_the_gpu() {
    let Some(ctx) = gpu("clearcoat_and_sheen_load_with_their_textures_on_the_gpu") else { return };
    clearcoat_and_sheen_on(Some(ctx));
}

/// KHR_materials_diffuse_transmission: a sheet (specular 0, so no Fresnel) filling the view in
/// a white environment shows (1 − share)·base colour reflected plus share·transmission colour
/// from behind, channel by channel, on both engines (the GPU also agrees with the CPU); the
/// extension's textures load.
fn diffuse_transmission_on(ctx: Option<GpuContext>) {
    let d = dir(&format!("diffuse-transmission-{}", engine(&ctx)));
    let mut b = GltfBuilder::new(&d, "translucent");
    for e in ["KHR_materials_diffuse_transmission", "KHR_materials_specular"] {
        b.use_extension(e);
    }
    let (base, color, share) = (Vec3::new(0.2, 0.6, 0.9), Vec3::new(0.9, 0.5, 0.1), 0.3);
    let m = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [base.x, base.y, base.z, 1],
        "metallicFactor": 0, "roughnessFactor": 0.5}, "extensions": {
        "KHR_materials_specular": {"specularFactor": 0.0},
        "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": share,
            "diffuseTransmissionColorFactor": [color.x, color.y, color.z]}}}));
    let quad = b.mesh(&MeshData::quad(-3.0, -3.0, 3.0, 3.0, 0.0, MeshData::UPRIGHT), m);
    b.node(json!({"mesh": quad}));
    camera_for(&mut b, 3.0, 1.0, 1.0);
    let path = b.write();
    let loaded = veach::load(&path, None).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let mat = &loaded.scene.materials[0];
    assert_eq!((mat.diffuse_transmission, mat.diffuse_transmission_color), (share, color));
    let s = Settings { width: 24, height: 24, max_depth: 0, env_color: Some([1.0; 3]), ..Settings::default() };
    let (backend, film) = render_on(&path, &s, 16, ctx.clone());
    assert_eq!(film.nonfinite_samples(), 0, "{backend}");
    let (mean, var) = film_stats(&film);
    let n = mean.len() as f64;
    let m: glam::DVec3 = mean.iter().map(|v| v.as_dvec3()).sum::<glam::DVec3>() / n;
    let se = var.iter().map(|v| v.as_dvec3()).sum::<glam::DVec3>().max(glam::DVec3::ZERO).sqrt() / n;
    let want = ((1.0 - share) * base + share * color).as_dvec3();
    for c in 0..3 {
        assert!((m[c] - want[c]).abs() <= 4.0 * se[c] + 1e-3, "{backend}: mean {m} ± {se}, want {want}");
    }
    if ctx.is_some() {
        assert_films_agree("diffuse transmission", &film, &render_on(&path, &s, 16, None).1);
    } else {
        // The textures: the share in alpha, the colour in sRGB RGB.
        let d = dir("diffuse-transmission-textures");
        let mut b = GltfBuilder::new(&d, "textured");
        b.use_extension("KHR_materials_diffuse_transmission");
        let t = b.texture(&block_texture(), REPEAT);
        let m = b.material(json!({"extensions": {"KHR_materials_diffuse_transmission": {
            "diffuseTransmissionFactor": 1.0, "diffuseTransmissionTexture": {"index": t},
            "diffuseTransmissionColorTexture": {"index": t}}}}));
        let quad = b.mesh(&MeshData::quad(-1.0, -1.0, 1.0, 1.0, 0.0, MeshData::UPRIGHT), m);
        b.node(json!({"mesh": quad}));
        camera_for(&mut b, 3.0, 1.0, 1.0);
        let loaded = veach::load(&b.write(), None).unwrap();
        let mat = &loaded.scene.materials[0];
        assert!(mat.diffuse_transmission_texture.is_some() && mat.diffuse_transmission_color_texture.is_some());
    }
}

#[test]
fn diffuse_transmission_shows_its_colour_from_behind() {
    diffuse_transmission_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn diffuse_transmission_shows_its_colour_from_behind_on_the_gpu() {
    let Some(ctx) = gpu("diffuse_transmission_shows_its_colour_from_behind_on_the_gpu") else { return };
    diffuse_transmission_on(Some(ctx));
}

/// KHR_materials_dispersion's ior at wavelength `l` (nm) from the extension's definitions:
/// Cauchy's n = A + B/λ² through n_d at 587.6 nm with (n_d − 1)/(n_F − n_C) = 20 / dispersion
/// (F = 486.1 nm, C = 656.3 nm), at least 1.
fn cauchy_ior(nd: f64, dispersion: f64, l: f64) -> f64 {
    if dispersion == 0.0 {
        return nd;
    }
    let vd = 20.0 / dispersion;
    let b = (nd - 1.0) / (vd * (486.1f64.powi(-2) - 656.3f64.powi(-2)));
    let a = nd - b / (587.6 * 587.6);
    (a + b / (l * l)).max(1.0)
}

/// Unpolarised Fresnel reflectance entering a dielectric of index n at incidence cos_i.
fn fresnel_entering(cos_i: f64, n: f64) -> f64 {
    let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (n * n)).sqrt();
    let rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    let rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// KHR_materials_dispersion: an orthographic view through one tilted interface of smooth glass
/// (60° incidence, ior 1.5, a solid: thickness 1) onto a lamp of radiance 1 covering x < −13.8
/// of a plane 30 below (where the middle of the view lands through ior 1.5). Snell's law with each channel's Cauchy ior (red at 656.3 nm, green 587.6,
/// blue 486.1) moves the lamp's edge in the image, so each channel's image mean is the lit
/// fraction of the view times (1 − F)/n² (radiance entering a denser medium), all computed
/// here. Without dispersion the three channels are the same sample for sample.
fn dispersion_on(ctx: Option<GpuContext>) {
    let tilt = 60f64.to_radians();
    let (depth, half_width, edge) = (30.0f64, 2.0f64, -13.8f64);
    let predict = |n: f64| {
        // The refracted direction of (0, 0, −1) through the normal (sin, 0, cos).
        let (cos_i, normal) = (tilt.cos(), glam::DVec3::new(tilt.sin(), 0.0, tilt.cos()));
        let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (n * n)).sqrt();
        let t = glam::DVec3::new(0.0, 0.0, -1.0) / n + (cos_i / n - cos_t) * normal;
        let steps = 100_000;
        let lit = (0..steps)
            .filter(|&i| {
                let x0 = -half_width + 2.0 * half_width * (i as f64 + 0.5) / steps as f64;
                let z_hit = -x0 * tilt.tan();
                x0 + t.x * (-depth - z_hit) / t.z < edge
            })
            .count();
        lit as f64 / steps as f64 * (1.0 - fresnel_entering(cos_i, n)) / (n * n)
    };
    for dispersion in [0.0f32, 3.0] {
        let d = dir(&format!("dispersion-{dispersion}-{}", engine(&ctx)));
        let mut b = GltfBuilder::new(&d, "prism");
        for e in ["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_dispersion"] {
            b.use_extension(e);
        }
        let glass = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
            "roughnessFactor": 0}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
            "KHR_materials_volume": {"thicknessFactor": 1.0}, "KHR_materials_dispersion": {"dispersion": dispersion}}}));
        let lamp = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
            "emissiveFactor": [1, 1, 1]}));
        let pane = b.mesh(&MeshData::quad(-30.0, -30.0, 30.0, 30.0, 0.0, MeshData::UPRIGHT), glass);
        let half = (tilt / 2.0) as f32;
        b.node(json!({"mesh": pane, "rotation": [0.0, half.sin(), 0.0, half.cos()]}));
        let backdrop =
            b.mesh(&MeshData::quad(-100.0, -60.0, edge as f32, 60.0, -depth as f32, MeshData::UPRIGHT), lamp);
        b.node(json!({"mesh": backdrop}));
        b.orthographic_camera(0.25, 0.25, [0.0, 0.0, 5.0]);
        let path = b.write();
        let loaded = veach::load(&path, None).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        assert_eq!(loaded.scene.materials[0].dispersion, dispersion);
        let s = Settings { width: 64, height: 8, max_depth: 3, env_color: Some([0.0; 3]), ..Settings::default() };
        let (backend, film) = render_on(&path, &s, 256, ctx.clone());
        assert_eq!(film.nonfinite_samples(), 0, "{backend}");
        let (mean, var) = film_stats(&film);
        let n = mean.len() as f64;
        let m: glam::DVec3 = mean.iter().map(|v| v.as_dvec3()).sum::<glam::DVec3>() / n;
        let se = var.iter().map(|v| v.as_dvec3()).sum::<glam::DVec3>().max(glam::DVec3::ZERO).sqrt() / n;
        let want =
            glam::DVec3::from_array([656.3, 587.6, 486.1].map(|l| predict(cauchy_ior(1.5, dispersion as f64, l))));
        eprintln!("dispersion {dispersion} {backend}: mean {m:.4} ± {se:.4}, predicted {want:.4}");
        for c in 0..3 {
            assert!(
                (m[c] - want[c]).abs() <= 4.0 * se[c] + 1e-3,
                "dispersion {dispersion} {backend}: mean {m} ± {se}, predicted {want}"
            );
        }
        if dispersion == 0.0 {
            assert!(mean.iter().all(|v| v.x == v.y && v.y == v.z), "{backend}: colour without dispersion");
        } else {
            // The test tells dispersion from none: red and blue are far apart for its error.
            assert!((want.x - want.z).abs() > 10.0 * (se.x + se.z), "predicted {want}, error {se}");
        }
        if ctx.is_some() {
            assert_films_agree(&format!("dispersion {dispersion}"), &film, &render_on(&path, &s, 256, None).1);
        }
    }
}

#[test]
fn dispersion_moves_each_colour_by_its_own_ior() {
    dispersion_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn dispersion_moves_each_colour_by_its_own_ior_on_the_gpu() {
    let Some(ctx) = gpu("dispersion_moves_each_colour_by_its_own_ior_on_the_gpu") else { return };
    dispersion_on(Some(ctx));
}

fn glass_furnace_on(ctx: Option<GpuContext>) {
    // Environment 1 everywhere: every pixel's expected value is 1 for smooth glass (Fresnel
    // splits, refraction's 1/η² and η² cancel on the way in and out). Rough glass may lose
    // the energy of single-scattering microfacets, never gain. Unlimited depth (roulette).
    for (roughness, min_mean) in [(0.0, 0.995), (0.3, 0.93)] {
        let path = glass_furnace(roughness, 1.5, engine(&ctx));
        let s = Settings { width: 48, height: 48, max_depth: 0, env_color: Some([1.0; 3]), ..Settings::default() };
        let (backend, film) = render_on(&path, &s, 32, ctx.clone());
        assert_eq!(film.nonfinite_samples(), 0);
        let (m, se) = furnace_mean(&film);
        eprintln!("glass r={roughness} {backend}: image mean {m:.4} ± {se:.4}");
        assert!(m <= 1.0 + 4.0 * se + 1e-4, "glass r={roughness} {backend}: energy gain, mean {m} ± {se}");
        assert!(m >= min_mean - 4.0 * se, "glass r={roughness} {backend}: mean {m} ± {se} below {min_mean}");
        if ctx.is_some() {
            assert_films_agree(&format!("glass r={roughness}"), &film, &render_on(&path, &s, 32, None).1);
        }
    }
}

/// Rough glass of ior 1 (and within 1e-4 of it, from both sides) bends no light: in a white
/// furnace the sphere is invisible, every pixel 1 whatever its roughness. The generalised half
/// vector of refraction, ωo + η ωi, vanishes at η = 1: the sphere rendered black before.
fn index_matched_glass_on(ctx: Option<GpuContext>) {
    let s = Settings { width: 32, height: 32, max_depth: 0, env_color: Some([1.0; 3]), ..Settings::default() };
    let mut films = Vec::new();
    for (roughness, ior) in [(0.5, 1.0), (1.0, 1.0), (0.5, 1.0001), (0.5, 0.9999)] {
        let path = glass_furnace(roughness, ior, engine(&ctx));
        let (backend, film) = render_on(&path, &s, 8, ctx.clone());
        assert_eq!(film.nonfinite_samples(), 0);
        let worst = (0..(s.width * s.height) as usize)
            .map(|i| (film.mean(i) - glam::Vec3::ONE).abs().max_element())
            .fold(0.0f32, f32::max);
        eprintln!("glass r={roughness} ior={ior} {backend}: worst pixel off by {worst:.2e}");
        assert!(worst < 1e-3, "glass r={roughness} ior={ior} {backend}: a pixel {worst} away from 1: the sphere shows");
        films.push((format!("r={roughness} ior={ior}"), path, film));
    }
    // GPU = CPU pixel by pixel (both are 1 up to rounding, so no variance to scale by).
    if ctx.is_some() {
        for (what, path, film) in &films {
            let cpu = render_on(path, &s, 8, None).1;
            for i in 0..(s.width * s.height) as usize {
                let d = (film.mean(i) - cpu.mean(i)).abs().max_element();
                assert!(d < 1e-3, "{what}: pixel {i} GPU {} vs CPU {}", film.mean(i), cpu.mean(i));
            }
        }
    }
}

#[test]
fn rough_glass_of_ior_one_is_invisible_in_a_furnace() {
    index_matched_glass_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn rough_glass_of_ior_one_is_invisible_in_a_furnace_on_the_gpu() {
    let Some(ctx) = gpu("rough_glass_of_ior_one_is_invisible_in_a_furnace_on_the_gpu") else { return };
    index_matched_glass_on(Some(ctx));
}

#[test]
fn glass_in_a_furnace_neither_creates_nor_loses_energy() {
    glass_furnace_on(None);
}

/// Russian roulette weighs a path by its throughput without refraction's 1/η² (pbrt-v4's and
/// Mitsuba's rule): through white smooth glass every BSDF sample's weight is 1 but for that
/// factor, so `beta · eta_scale` stays 1 and every roulette keeps the path with probability
/// 0.95 and divides by it. Without the rule a roulette inside the glass (beta 1/η²) would keep
/// the path with probability 1/η², and it would leave the glass weighing η². The scalar
/// stages (the lanes and the WGSL kernel follow the same rule: tests/films.rs, tests/lanes.rs).
#[test]
fn roulette_sees_the_throughput_without_the_eta_squared_of_refraction() {
    use veach::cpu::bvh::{NO_HIT, intersect_closest};
    use veach::cpu::camera::camera_sample;
    use veach::cpu::integrator::{PathState, path_scatter, path_surface};
    let path = glass_furnace(0.0, 1.5, "stages");
    let (scene, camera) = common::load_pair(&path, None).unwrap();
    let packed = veach::PackedScene::new(&scene);
    let s = Settings { width: 32, height: 32, max_depth: 0, env_color: Some([1.0; 3]), ..Settings::default() };
    let params = veach::params::Params::new(&camera, &s, s.window(), &packed);
    let mut rouletted_inside = 0;
    for pixel in 0..32 * 32 {
        let (ray, sampler) = camera_sample(&params, glam::UVec2::new(pixel % 32, pixel / 32));
        let mut p = PathState::new(&params, ray, sampler);
        let mut rouletted = 0;
        while p.depth < 64 {
            let hit = intersect_closest(&packed, &p.ray);
            p.depth += 1;
            if hit.tri == NO_HIT {
                break;
            }
            let Some(sv) = path_surface(&packed, &params, &mut p, &hit) else { break };
            if !path_scatter(&params, &mut p, &sv) {
                break;
            }
            if p.depth >= params.rr_depth {
                rouletted += 1;
                // In the glass after this vertex: its eta_scale is η².
                rouletted_inside += usize::from(p.eta_scale > 2.0);
            }
            let unscaled = p.beta * p.eta_scale * 0.95f32.powi(rouletted);
            assert!(
                (unscaled - Vec3::ONE).abs().max_element() < 1e-4,
                "pixel {pixel}, depth {}: beta {} eta_scale {} after {rouletted} roulettes",
                p.depth,
                p.beta,
                p.eta_scale
            );
        }
    }
    // Not vacuous: roulette met paths inside the glass.
    assert!(rouletted_inside > 50, "{rouletted_inside} roulettes inside the glass");
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn glass_in_a_furnace_neither_creates_nor_loses_energy_on_the_gpu() {
    let Some(ctx) = gpu("glass_in_a_furnace_neither_creates_nor_loses_energy_on_the_gpu") else { return };
    glass_furnace_on(Some(ctx));
}

/// KHR_materials_transmission without KHR_materials_volume is thin-walled: an emitter's edge
/// seen through a smooth pane turned 45° stays where it is (a solid slab would shift it), and
/// the light through is the emitter's times 1 − F(45°) of ior 1.5, computed here.
fn thin_walled_panes_on(ctx: Option<GpuContext>) {
    let d = dir(&format!("pane-{}", engine(&ctx)));
    let mut b = GltfBuilder::new(&d, "pane");
    b.use_extension("KHR_materials_transmission");
    let glow =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "emissiveFactor": [1, 1, 1]}));
    let pane = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
        "roughnessFactor": 0}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}}));
    let backdrop = b.mesh(&MeshData::quad(-5.0, -5.0, 0.0, 5.0, -2.0, MeshData::UPRIGHT), glow);
    let sheet = b.mesh(&MeshData::quad(-1.0, -1.0, 1.0, 1.0, 0.0, MeshData::UPRIGHT), pane);
    b.node(json!({"mesh": backdrop}));
    b.node(json!({"mesh": sheet, "rotation": Quat::from_rotation_y(std::f32::consts::FRAC_PI_4).to_array()}));
    camera_for(&mut b, 3.0, 0.15, 2.0);
    let path = b.write();
    let (scene, _) = common::load_pair(&path, None).unwrap();
    assert!(scene.materials[1].thin_walled, "no volume: thin-walled");
    let c = std::f64::consts::FRAC_1_SQRT_2;
    let (n, eta) = (1.5f64, 1.5f64);
    let ct = (1.0 - (1.0 - c * c) / (eta * eta)).sqrt();
    let rs = ((c - n * ct) / (c + n * ct)).powi(2);
    let rp = ((n * c - ct) / (n * c + ct)).powi(2);
    let through = 1.0 - 0.5 * (rs + rp);
    let (w, h) = (64u32, 32u32);
    let (backend, film) = render_on(&path, &settings(w, h, 4), 16, ctx);
    let column = |x: u32| (0..h).map(|y| film.mean((y * w + x) as usize).y as f64).sum::<f64>() / h as f64;
    // The edge is between columns 31 and 32; two columns each side away from it.
    for x in [24, 28, 29] {
        let v = column(x);
        assert!((v - through).abs() < 0.01, "{backend}: column {x} is {v}, expected 1 − F = {through}");
    }
    for x in [34, 35, 40] {
        let v = column(x);
        assert!(v < 1e-3, "{backend}: column {x} is {v}: the edge moved right");
    }
}

#[test]
fn thin_walled_panes_do_not_bend_light() {
    thin_walled_panes_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn thin_walled_panes_do_not_bend_light_on_the_gpu() {
    let Some(ctx) = gpu("thin_walled_panes_do_not_bend_light_on_the_gpu") else { return };
    thin_walled_panes_on(Some(ctx));
}

/// KHR_materials_anisotropy on a brushed-metal quad under a point light: loaded from a file
/// that requires it, the highlight is stretched along the rotated tangent (wider along
/// x than along y in the image for rotation 0, the reverse for 90°), and the GPU agrees with
/// the CPU within error bars.
fn anisotropy_on(ctx: Option<GpuContext>) {
    let spread = |rotation: f32| {
        let d = dir(&format!("aniso-{rotation}-{}", engine(&ctx)));
        let mut b = GltfBuilder::new(&d, "aniso");
        b.use_extension("KHR_materials_anisotropy");
        let m = b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1], "metallicFactor": 1,
            "roughnessFactor": 0.25}, "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0.8,
            "anisotropyRotation": rotation}}}));
        let quad = b.mesh(&MeshData::quad(-1.0, -1.0, 1.0, 1.0, 0.0, MeshData::UPRIGHT), m);
        b.node(json!({"mesh": quad}));
        b.light(json!({"type": "point", "intensity": 5.0}), json!({"translation": [0.0, 0.0, 2.0]}));
        camera_for(&mut b, 2.0, 1.0, 1.0);
        let path = b.write();
        let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        doc["extensionsRequired"] = json!(["KHR_materials_anisotropy"]);
        std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
        let loaded = veach::load(&path, None).unwrap();
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        // The CPU film's highlight is measured; the GPU's must agree with it.
        let (_, film) = render_on(&path, &settings(48, 48, 2), 16, None);
        if ctx.is_some() {
            let (_, gpu) = render_on(&path, &settings(48, 48, 2), 16, ctx.clone());
            assert_films_agree(&format!("rotation {rotation}"), &gpu, &film);
        }
        // Second moments of the highlight about the image centre, weighted by luminance.
        let (mut sx, mut sy, mut total) = (0.0f64, 0.0f64, 0.0f64);
        for y in 0..48u32 {
            for x in 0..48u32 {
                let l = film.mean((y * 48 + x) as usize).y as f64;
                let (dx, dy) = (x as f64 - 23.5, y as f64 - 23.5);
                sx += l * dx * dx;
                sy += l * dy * dy;
                total += l;
            }
        }
        (sx / total, sy / total)
    };
    let (x0, y0) = spread(0.0);
    assert!(x0 > 1.5 * y0, "rotation 0: spread x {x0} vs y {y0}: not stretched along the tangent (+x)");
    let (x1, y1) = spread(std::f32::consts::FRAC_PI_2);
    assert!(y1 > 1.5 * x1, "rotation 90°: spread x {x1} vs y {y1}: not stretched along the bitangent");
}

#[test]
fn anisotropic_highlights_stretch_along_the_rotated_tangent() {
    anisotropy_on(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn anisotropic_highlights_stretch_along_the_rotated_tangent_on_the_gpu() {
    let Some(ctx) = gpu("anisotropic_highlights_stretch_along_the_rotated_tangent_on_the_gpu") else { return };
    anisotropy_on(Some(ctx));
}
